/* volume.c: volume constraints and tetrahedral solids from scripts:
 *   w:volume(p1, p2, p3, p4, {compliance, rest, yield, creep}) -> index    w:volume_count()
 *   w:volume_info(i) -> volume, rest, pressure               w:total_volume() -> volume, rest
 *   w:load_tets(path, {...}) -> body (tetgen's .node/.ele)   w:save_tets(path [, body])
 *   w:tet(p1, p2, p3, p4, {young, poisson, yield, creep}) -> index (Neo-Hookean, core/tet.c)
 *   w:tet_count()   w:tet_info(i) -> det F, energy, rest volume
 * and the helpers of the tets branch of w:from_mesh (lua/mesh.c: tetgen run on the mesh).
 * Volume constraints are plain indices (1-based): they are never removed. */
#include <limits.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "io/io.h"
#include "util.h"
#include "sandbox.h"

static const char *const volume_keys[] = { "compliance", "rest", "yield", "creep", NULL };

static int w_volume(lua_State *L)
{
    wb_world *w = wbl_checkworld(L, 1);
    int32_t p[4];
    for (int k = 0; k < 4; k++) p[k] = wbl_checkparticle(L, w, 2 + k);
    wb_volume_def d = wb_volume_default_def();
    if (wbl_checkopts(L, 6, volume_keys, true)) {
        wbl_optreal(L, 6, "compliance", &d.compliance);
        d.has_rest = wbl_optreal(L, 6, "rest", &d.rest);
        wbl_optreal(L, 6, "yield", &d.yield);
        wbl_optreal(L, 6, "creep", &d.creep);
    }
    /* the core decides (volume.c); an error names the option or the particle at fault */
    const wb_fault f = wb_volume_check(wb_particle_count(w), wb_particle_positions(w), p, &d);
    wbl_fault_error(L, &f, 2, 5, 6);
    const int32_t i = wb_volume_add(w, p, &d);
    if (i < 0) return wbl_status_error(L, 6, (wb_status)i, "volume constraint");
    lua_pushinteger(L, (lua_Integer)i + 1);
    return 1;
}

static int w_volume_count(lua_State *L)
{
    lua_pushinteger(L, wb_volume_count(wbl_checkworld(L, 1)));
    return 1;
}

static int32_t checkvolume(lua_State *L, const wb_world *w, int arg)
{
    const lua_Integer i = wbl_checkint(L, arg);
    if (i < 1 || i > wb_volume_count(w))
        luaL_argerror(L, arg, lua_pushfstring(L, "volume constraint %I out of range (1..%d)", i, (int)wb_volume_count(w)));
    return (int32_t)(i - 1);
}

/* w:volume_info(i) -> current signed volume, rest volume (m^3), pressure (Pa, > 0 compressed) */
static int w_volume_info(lua_State *L)
{
    wb_world *w = wbl_checkworld(L, 1);
    const int32_t i = checkvolume(L, w, 2);
    lua_pushnumber(L, wb_volume_current(w, i));
    lua_pushnumber(L, wb_volume_rest(w, i));
    lua_pushnumber(L, wb_volume_pressure(w, i));
    return 3;
}

static int w_total_volume(lua_State *L)
{
    wb_real cur, rest;
    wb_world_volume_total(wbl_checkworld(L, 1), &cur, &rest);
    lua_pushnumber(L, cur);
    lua_pushnumber(L, rest);
    return 2;
}

/* ---- Neo-Hookean tets ------------------------------------------------------------------------ */
static const char *const tet_keys[] = { "young", "poisson", "yield", "creep", NULL };

/* w:tet(p1, p2, p3, p4, {young = 1e5, poisson = 0.3, yield = 0, creep = 0}) -> index: rest
 * shape = the current one */
static int w_tet(lua_State *L)
{
    wb_world *w = wbl_checkworld(L, 1);
    int32_t p[4];
    for (int k = 0; k < 4; k++) p[k] = wbl_checkparticle(L, w, 2 + k);
    wb_tet_def d = wb_tet_default_def();
    if (wbl_checkopts(L, 6, tet_keys, true)) {
        wbl_optreal(L, 6, "young", &d.young);
        wbl_optreal(L, 6, "poisson", &d.poisson);
        wbl_optreal(L, 6, "yield", &d.yield);
        wbl_optreal(L, 6, "creep", &d.creep);
    }
    /* the core decides (tet.c); an error names the option or the particle at fault */
    const wb_fault f = wb_tet_check(wb_particle_count(w), wb_particle_positions(w), p, &d);
    wbl_fault_error(L, &f, 2, 5, 6);
    const int32_t i = wb_tet_add(w, p, &d);
    if (i < 0) return wbl_status_error(L, 6, (wb_status)i, "tet");
    lua_pushinteger(L, (lua_Integer)i + 1);
    return 1;
}

static int w_tet_count(lua_State *L)
{
    lua_pushinteger(L, wb_tet_count(wbl_checkworld(L, 1)));
    return 1;
}

/* w:tet_info(i) -> det F (current / rest volume, < 0 inverted), energy (J), rest volume (m^3) */
static int w_tet_info(lua_State *L)
{
    wb_world *w = wbl_checkworld(L, 1);
    const lua_Integer i = wbl_checkint(L, 2);
    if (i < 1 || i > wb_tet_count(w))
        return luaL_argerror(L, 2, lua_pushfstring(L, "tet %I out of range (1..%d)", i, (int)wb_tet_count(w)));
    lua_pushnumber(L, wb_tet_volume_ratio(w, (int32_t)i - 1));
    lua_pushnumber(L, wb_tet_energy(w, (int32_t)i - 1));
    lua_pushnumber(L, wb_tet_rest_volume(w, (int32_t)i - 1));
    return 3;
}

/* ---- tet bodies ------------------------------------------------------------------------------- */
#define WBL_TETS "wobble.tets (scratch)"

/* tetgen's arrays owned by a userdata, so a Lua error on the way cannot leak them */
wbio_tets *wbl_push_tets(lua_State *L)
{
    wbio_tets *t = (wbio_tets *)lua_newuserdatauv(L, sizeof *t, 0);
    memset(t, 0, sizeof *t);
    luaL_setmetatable(L, WBL_TETS);
    return t;
}

static int tets_gc(lua_State *L)
{
    wbio_tets_free((wbio_tets *)luaL_checkudata(L, 1, WBL_TETS));
    return 0;
}

/* the options of a tet body (both builders), at arg; returns whether the radius is the default */
bool wbl_read_tet_body(lua_State *L, int arg, wb_tet_body_def *d)
{
    bool auto_radius = true;
    if (lua_type(L, arg) != LUA_TTABLE) return auto_radius;
    if (wbl_optreal(L, arg, "mass", &d->mass) && !(d->mass > 0)) wbl_fielderror(L, arg, "mass", "must be > 0");
    if (wbl_optreal(L, arg, "radius", &d->radius)) {
        if (d->radius < 0) wbl_fielderror(L, arg, "radius", "must be >= 0");
        auto_radius = false;
    }
    if (wbl_optreal(L, arg, "volume_compliance", &d->volume_compliance) && d->volume_compliance < 0)
        wbl_fielderror(L, arg, "volume_compliance", "must be >= 0");
    wbl_read_neo(L, arg, &d->young, &d->poisson);
    wbl_read_link(L, arg, &d->link);
    const char *e = wb_distance_def_check(&d->link);
    if (e) luaL_argerror(L, arg, e);
    return auto_radius;
}

/* build the body of t on the world at 1 and push it (with .tet_count); raises */
int wbl_push_tet_body(lua_State *L, wb_world *w, const wbio_tets *t, const int32_t *tri, int32_t ntri,
                         const wb_tet_body_def *d, bool auto_radius, const wbl_contact_opts *co, const char *what)
{
    const int32_t nd0 = wb_distance_count(w), nv0 = wb_volume_count(w) + wb_tet_count(w);
    wbl_body_begin(L, t->nv);
    wb_body b;
    wb_status st = wb_tet_body(w, t->v, t->nv, t->tet, t->nt, tri, ntri, d, &b);
    if (st == WB_ERR_ARG) return luaL_error(L, "%s: %s", what, wb_last_error());
    if (st != WB_OK) return wbl_status_error(L, 2, st, what);
    if (auto_radius) wbl_default_radius(w, b);
    wbl_apply_contact_opts(w, b, co);
    wbl_body_end(L, 1, b, wb_distance_count(w) - nd0);
    lua_pushinteger(L, wb_volume_count(w) + wb_tet_count(w) - nv0);
    lua_setfield(L, -2, "tet_count");
    return 1;
}

void wbl_tet_preset(lua_State *L, int arg, const wb_material *m, const wbio_tets *t, wb_tet_body_def *d)
{
    if (!m) return;
    double vol = 0, edges = 0;
    for (int32_t i = 0; i < t->nt; i++) {
        const int32_t *p = &t->tet[4 * i];
        vol += fabs(wb_tet_signed_volume(&t->v[3 * p[0]], &t->v[3 * p[1]], &t->v[3 * p[2]], &t->v[3 * p[3]]));
        for (int a = 0; a < 4; a++)
            for (int c = a + 1; c < 4; c++) {
                const wb_real *u = &t->v[3 * p[a]], *q = &t->v[3 * p[c]];
                edges += sqrt((u[0] - q[0]) * (u[0] - q[0]) + (u[1] - q[1]) * (u[1] - q[1]) + (u[2] - q[2]) * (u[2] - q[2]));
            }
    }
    if (!wbl_given(L, arg, "mass") && vol > 0) d->mass = m->density * vol;
    if (!wbl_given(L, arg, "damping") && t->nt > 0) d->link.damping = m->viscosity * edges / (6.0 * t->nt);
}

/* "solid", "solid.node" or "solid.ele" -> the two paths through the sandbox */
static void tet_paths(lua_State *L, const char *name, int write, char *node, char *ele, char *node_shown,
                      char *ele_shown)
{
    size_t n = strlen(name);
    if (n > 5 && (strcmp(name + n - 5, ".node") == 0)) n -= 5;
    else if (n > 4 && strcmp(name + n - 4, ".ele") == 0) n -= 4;
    if (n == 0 || n > PATH_MAX - 8) luaL_argerror(L, 2, "a file name expected");
    snprintf(node_shown, PATH_MAX, "%.*s.node", (int)n, name);
    snprintf(ele_shown, PATH_MAX, "%.*s.ele", (int)n, name);
    wbl_path(L, node_shown, write, node, PATH_MAX);
    wbl_path(L, ele_shown, write, ele, PATH_MAX);
}

static const char *const load_tets_keys[] = {
    "mass", "radius", "volume_compliance", "young", "poisson",
    "compliance", "damping", "yield", "creep", "break_strain", "break_force", "collide", "self_collide", "friction",
    "material", NULL
};

/* w:load_tets(path, {...}) -> body, or nil and "file:line: reason"; a preset as
 * w:from_mesh{tets = true} takes it: Neo-Hookean tets of its E and nu, rho x the tets'
 * volume, its dashpots and friction */
static int w_load_tets(lua_State *L)
{
    wb_world *w = wbl_checkworld(L, 1);
    const char *name = wbl_checkfilename(L, 2);
    wbl_checkopts(L, 3, load_tets_keys, true);
    wb_tet_body_def d = wb_tet_body_default_def();
    const wb_material *mat = lua_istable(L, 3) ? wbl_opt_material(L, 3) : NULL;
    if (mat) {
        d.young = mat->young;
        d.poisson = mat->poisson;
    }
    const bool auto_radius = wbl_read_tet_body(L, 3, &d);
    wbl_contact_opts co;
    wbl_read_contact_opts(L, 3, &co);
    wbl_material_friction(L, 3, mat, &co);
    char node[PATH_MAX], ele[PATH_MAX], node_shown[PATH_MAX], ele_shown[PATH_MAX], err[1024];
    tet_paths(L, name, 0, node, ele, node_shown, ele_shown);
    lua_settop(L, 3);
    wbio_tets *t = wbl_push_tets(L);
    if (wbio_read_tets(node, node_shown, ele, ele_shown, t, err, sizeof err)) {
        luaL_pushfail(L);
        lua_pushstring(L, err);
        return 2;
    }
    wbl_tet_preset(L, 3, mat, t, &d);
    /* a file's tets that the core refuses (flat ones): an expected failure as well */
    /* tet_count: volume constraints, or Neo-Hookean tets with young */
    const int32_t nd0 = wb_distance_count(w), nv0 = wb_volume_count(w) + wb_tet_count(w);
    wbl_body_begin(L, t->nv);
    wb_body b;
    wb_status st = wb_tet_body(w, t->v, t->nv, t->tet, t->nt, NULL, 0, &d, &b);
    if (st == WB_ERR_ARG) {
        luaL_pushfail(L);
        lua_pushfstring(L, "%s: %s", ele_shown, wb_last_error());
        return 2;
    }
    if (st != WB_OK) return wbl_status_error(L, 2, st, "load_tets");
    if (auto_radius) wbl_default_radius(w, b);
    wbl_apply_contact_opts(w, b, &co);
    wbl_body_end(L, 1, b, wb_distance_count(w) - nd0);
    lua_pushinteger(L, wb_volume_count(w) + wb_tet_count(w) - nv0);
    lua_setfield(L, -2, "tet_count");
    return 1;
}

/* w:save_tets(path [, body]) -> true, or nil and a message: the tets (volume constraints and w:tet)
 * (of the body's particles only, renumbered, when a body is given) and their particles */
static int w_save_tets(lua_State *L)
{
    wb_world *w = wbl_checkworld(L, 1);
    const char *name = wbl_checkfilename(L, 2);
    const bool whole = lua_isnoneornil(L, 3); /* now: index 3 is taken by what is pushed below */
    int32_t first = 0, count = wb_particle_count(w);
    if (!whole) {
        luaL_checktype(L, 3, LUA_TTABLE);
        lua_getfield(L, 3, "first");
        lua_getfield(L, 3, "count");
        if (!lua_isinteger(L, -2) || !lua_isinteger(L, -1)) return luaL_argerror(L, 3, "body expected (first, count)");
        first = (int32_t)lua_tointeger(L, -2) - 1;
        count = (int32_t)lua_tointeger(L, -1);
        if (first < 0 || count < 0 || (int64_t)first + count > wb_particle_count(w))
            return luaL_argerror(L, 3, "body's particles out of range");
        lua_pop(L, 2);
    }
    char node[PATH_MAX], ele[PATH_MAX], node_shown[PATH_MAX], ele_shown[PATH_MAX], err[1024];
    tet_paths(L, name, 1, node, ele, node_shown, ele_shown);
    /* the volume constraints, then the Neo-Hookean tets (a body made with young has only those) */
    const int32_t nvol = wb_volume_count(w), nneo = wb_tet_count(w), nall = nvol + nneo;
    int32_t *tet = (int32_t *)lua_newuserdatauv(L, sizeof *tet * 4 * (size_t)(nall > 0 ? nall : 1), 0);
    int32_t nt = 0;
    for (int32_t i = 0; i < nall; i++) {
        int32_t p[4], in = 1;
        if (i < nvol) wb_volume_particles(w, i, p);
        else wb_tet_particles(w, i - nvol, p);
        for (int k = 0; k < 4; k++) in &= p[k] >= first && p[k] < first + count;
        if (!in) continue;
        for (int k = 0; k < 4; k++) tet[4 * nt + k] = p[k] - first;
        nt++;
    }
    if (nt == 0) return luaL_error(L, "save_tets: no tets (volume constraints or w:tet) %s", whole ? "in the world" : "in the body");
    const wb_real *x = wb_particle_positions(w) + 3 * (size_t)first;
    if (wbio_write_tets(node, node_shown, ele, ele_shown, x, count, tet, nt, err, sizeof err)) {
        luaL_pushfail(L);
        lua_pushstring(L, err);
        return 2;
    }
    lua_pushboolean(L, 1);
    return 1;
}

static const luaL_Reg world_methods[] = {
    { "volume", w_volume },
    { "volume_count", w_volume_count },
    { "volume_info", w_volume_info },
    { "total_volume", w_total_volume },
    { "load_tets", w_load_tets },
    { "save_tets", w_save_tets },
    { "tet", w_tet },
    { "tet_count", w_tet_count },
    { "tet_info", w_tet_info },
    { NULL, NULL }
};

void wbl_open_volume(lua_State *L)
{
    luaL_newmetatable(L, WBL_TETS);
    lua_pushcfunction(L, tets_gc);
    lua_setfield(L, -2, "__gc");
    lua_pop(L, 1);
    wbl_add_world_methods(L, world_methods);
}
