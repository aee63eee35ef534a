/* io.c: files from scripts: JSON particle configs (w:load_particles), snapshots
 * (w:save, wobble.load) and exports for other tools (recorders for PC2 point caches and
 * VTK series, w:save_vtp). Every path goes through the sandbox (wb_sandbox_path).
 *
 * A file that cannot be read or written is an expected failure: nil and "file: reason"
 * (with line, column and key path for JSON), and the world is left as it was. */
#include <errno.h>
#include <fcntl.h>
#include <limits.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "io/io.h"
#include "mesh.h"
#include "sandbox.h"

#define WBL_CONFIG "wobble.config (scratch)"

static int fail_with(lua_State *L, const char *msg)
{
    luaL_pushfail(L);
    lua_pushstring(L, msg);
    return 2;
}

/* ---- configs -------------------------------------------------------------------------------------- */
/* a parsed config owned by a userdata, so a Lua error on the way cannot leak it */
static wbio_config *push_config(lua_State *L)
{
    wbio_config *c = (wbio_config *)lua_newuserdatauv(L, sizeof *c, 0);
    memset(c, 0, sizeof *c);
    luaL_setmetatable(L, WBL_CONFIG);
    return c;
}

/* read the config at path into c under the run's memory budget: a file too big for what
 * is left of it is a budget error (after one collection: configs and meshes that are
 * garbage give back their charges); 0, or -1 and err for a file that cannot be read */
static int read_config(lua_State *L, const char *path, const char *name, wbio_config *c, char *err, size_t n)
{
    wb_memory *mem = &wb_rt_get(L)->memory;
    bool over = false;
    int rc = wbio_read_config_within(path, name, c, mem, &over, err, n);
    if (rc && over) {
        lua_gc(L, LUA_GCCOLLECT);
        rc = wbio_read_config_within(path, name, c, mem, &over, err, n);
        if (rc && over) wb_rt_budget_error(L, "%s (--memory-limit MB)", err);
    }
    return rc;
}

static int config_gc(lua_State *L)
{
    wbio_config_free((wbio_config *)luaL_checkudata(L, 1, WBL_CONFIG));
    return 0;
}

/* load the meshes the config's skins name (relative to the config's folder) into a table
 * pushed on the stack; NULL on success, else the message (on the stack as well) */
static const char *load_skin_meshes(lua_State *L, const char *config_path, const wbio_config *c)
{
    lua_createtable(L, c->nskins, 0);
    const char *slash = strrchr(config_path, '/');
    const int dir_len = slash ? (int)(slash - config_path) : 0;
    for (int32_t i = 0; i < c->nskins; i++) {
        const wbio_skin_spec *k = &c->skins[i];
        char rel[PATH_MAX], path[PATH_MAX], err[1024];
        const char *perr = NULL;
        if (k->mesh[0] == '/') snprintf(rel, sizeof rel, "%s", k->mesh);
        else snprintf(rel, sizeof rel, "%.*s/%s", dir_len, config_path, k->mesh);
        if (!wb_sandbox_path(L, rel, 0, path, sizeof path, &perr))
            return lua_pushfstring(L, "%s: %s", k->where, perr ? perr : "refused");
        wbio_mesh_opts o = { k->scale, true, -1, 0 };
        /* under the run's budgets, as wobble.load_mesh */
        if (!wbl_import_mesh(L, path, k->mesh, &o, k->where, err, sizeof err))
            return lua_pushfstring(L, "%s: %s", k->where, err);
        lua_rawseti(L, -2, i + 1);
    }
    return NULL;
}

/* the config's skins on the world at world_index, particle ids shifted by first; the meshes
 * table at meshes; the skins go into the table on the top of the stack */
static void make_skins(lua_State *L, int world_index, int meshes, const wbio_config *c, int32_t first, int32_t count)
{
    for (int32_t i = 0; i < c->nskins; i++) {
        const wbio_skin_spec *k = &c->skins[i];
        const int32_t n = k->ids ? k->nids : count;
        int32_t *ids = (int32_t *)lua_newuserdatauv(L, sizeof *ids * (size_t)(n > 0 ? n : 1), 0);
        for (int32_t j = 0; j < n; j++) ids[j] = first + (k->ids ? k->ids[j] : j);
        lua_rawgeti(L, meshes, i + 1);
        wbl_new_skin(L, world_index, wbl_checkmesh(L, -1), ids, n, &k->def, 2);
        lua_rawseti(L, -4, i + 1);
        lua_pop(L, 2);
    }
}

/* w:load_particles(path) -> body (with .parts, .skins and .colliders), or nil and "file:line:col: key: reason" */
static int w_load_particles(lua_State *L)
{
    wb_world *w = wbl_checkworld(L, 1);
    const char *name = wbl_checkfilename(L, 2);
    char path[PATH_MAX], err[1024];
    /* contact options for the whole body; without them the file's own settings stay
     * (radius: every particle's contact radius, e.g. a file made before contacts) */
    static const char *const keys[] = { "collide", "self_collide", "friction", "radius", "material", NULL };
    const bool given = wbl_checkopts(L, 3, keys, true);
    wbl_contact_opts co;
    wbl_read_contact_opts(L, 3, &co);
    /* a preset: its friction only (the file gives masses and constraints) */
    wbl_material_friction(L, 3, wbl_opt_material(L, 3), &co);
    wb_real radius = -1;
    if (given && wbl_optreal(L, 3, "radius", &radius) && !(radius >= 0 && isfinite(radius)))
        return wbl_fielderror(L, 3, "radius", "must be finite and >= 0");
    lua_settop(L, 2);
    wbl_path(L, name, 0, path, sizeof path);
    wbio_config *c = push_config(L); /* 3 */
    if (read_config(L, path, name, c, err, sizeof err)) return fail_with(L, err);
    const char *msg = load_skin_meshes(L, path, c); /* 4: meshes */
    if (msg) {
        luaL_pushfail(L);
        lua_pushstring(L, msg);
        return 2;
    }
    int32_t live = 0;
    for (int32_t i = 0; i < c->img.dist.n; i++) live += (int32_t)(c->img.dist.gen[i] & 1u);
    /* 5: the collider slots live before, so the new ones can be told apart after */
    uint32_t top = 0;
    for (int32_t i = 0; i < wb_collider_count(w); i++)
        if (wb_collider_at(w, i).index > top) top = wb_collider_at(w, i).index;
    unsigned char *was = (unsigned char *)lua_newuserdatauv(L, (size_t)top + 1, 0);
    memset(was, 0, (size_t)top + 1);
    for (int32_t i = 0; i < wb_collider_count(w); i++) was[wb_collider_at(w, i).index] = 1;
    wbl_body_begin(L, c->img.np);
    wb_body b;
    wb_status st = wb_world_append_image(w, &c->img, &b);
    if (st == WB_ERR_ARG) return fail_with(L, lua_pushfstring(L, "%s: %s", name, wb_last_error()));
    if (st != WB_OK) return wbl_status_error(L, 2, st, "load_particles");
    if (given) wbl_apply_contact_opts(w, b, &co);
    for (int32_t i = 0; radius >= 0 && i < b.count; i++) wb_particle_set_radius(w, b.first + i, radius);
    /* each part is a body of its own: its own group, so the parts (the logo's letters)
     * push each other; the particles of no part stay in the body's group */
    for (int32_t i = 0; i < c->nparts; i++) {
        const int32_t g = wb_group_new(w);
        for (int32_t k = 0; k < c->parts[i].count; k++) wb_particle_set_group(w, b.first + c->parts[i].first + k, g);
    }
    wbl_body_end(L, 1, b, live); /* 6: the body */
    /* body.colliders: the colliders the config made, in slot order (= the config's order:
     * free slots are reused lowest first, then new ones appended) */
    lua_newtable(L);
    for (int32_t i = 0, k = 0; i < wb_collider_count(w); i++) {
        const wb_collider_id id = wb_collider_at(w, i);
        if (id.index <= top && was[id.index]) continue;
        wbl_push_collider(L, 1, id);
        lua_rawseti(L, -2, ++k);
    }
    lua_setfield(L, 6, "colliders");
    /* body.parts: an array of part bodies, also indexed by name */
    lua_createtable(L, c->nparts, c->nparts);
    for (int32_t i = 0; i < c->nparts; i++) {
        const int32_t p0 = b.first + c->parts[i].first;
        wb_body pb = { p0, c->parts[i].count, c->parts[i].count > 0 ? wb_particle_group(w, p0) : 0 };
        wbl_push_body(L, 1, pb, 0);
        lua_pushstring(L, c->parts[i].name);
        lua_setfield(L, -2, "name");
        lua_pushvalue(L, -1);
        lua_setfield(L, -3, c->parts[i].name);
        lua_rawseti(L, -2, i + 1);
    }
    lua_setfield(L, 6, "parts");
    lua_createtable(L, c->nskins, 0);
    make_skins(L, 1, 4, c, b.first, b.count);
    lua_setfield(L, 6, "skins");
    wbio_config_free(c);   /* scratch: its charge goes back now, not at a collection */
    lua_settop(L, 6);
    return 1;
}

/* wobble.load(path) -> world, exactly as w:save wrote it (or a new world holding a config) */
static int l_load(lua_State *L)
{
    const char *name = wbl_checkfilename(L, 1);
    char path[PATH_MAX], err[1024];
    lua_settop(L, 1);
    wbl_path(L, name, 0, path, sizeof path);
    wbio_config *c = push_config(L); /* 2 */
    if (read_config(L, path, name, c, err, sizeof err)) return fail_with(L, err);
    const char *msg = load_skin_meshes(L, path, c); /* 3 */
    if (msg) return fail_with(L, msg);
    if (!c->snapshot) {
        /* a plain config: the settings wobble.world{} would have */
        wb_runtime *rt = wb_rt_get(L);
        c->img.def = wb_world_default_def();
        if (rt && rt->threads > 0) c->img.def.threads = rt->threads;
        if (rt && rt->solver > 0) c->img.def.solver = (wb_solver)(rt->solver - 1);
    }
    c->img.def.memory = &wb_rt_get(L)->memory; /* a loaded world is charged like any other */
    wbl_world *ud = (wbl_world *)lua_newuserdatauv(L, sizeof *ud, 0); /* 4 */
    ud->w = NULL;
    ud->warned = 0;
    luaL_setmetatable(L, WBL_WORLD);
    wb_status st;
    ud->w = wb_world_from_image(&c->img, &st);
    if (!ud->w && st == WB_ERR_ARG) return fail_with(L, lua_pushfstring(L, "%s: %s", name, wb_last_error()));
    if (!ud->w) return wb_rt_budget_error(L, "out of memory loading %s", name);
    lua_createtable(L, c->nskins, 0);
    make_skins(L, 4, 3, c, 0, c->img.np);
    wbio_config_free(c);   /* scratch: its charge goes back now, not at a collection */
    lua_settop(L, 4);
    return 1;
}

/* w:colliders() / w:distances(): live handles in slot order (those of a loaded world too) */
static int w_colliders(lua_State *L)
{
    wb_world *w = wbl_checkworld(L, 1);
    const int32_t n = wb_collider_count(w);
    lua_createtable(L, n, 0);
    for (int32_t i = 0; i < n; i++) {
        wbl_push_collider(L, 1, wb_collider_at(w, i));
        lua_rawseti(L, -2, i + 1);
    }
    return 1;
}

static int w_distances(lua_State *L)
{
    wb_world *w = wbl_checkworld(L, 1);
    const int32_t n = wb_distance_count(w);
    /* the ids in a Lua-owned buffer: nothing leaks if pushing the handles fails */
    wb_distance_id *ids = (wb_distance_id *)lua_newuserdatauv(L, sizeof *ids * (size_t)(n > 0 ? n : 1), 0);
    wb_distance_ids(w, ids);
    lua_createtable(L, n, 0);
    for (int32_t i = 0; i < n; i++) {
        wbl_push_distance(L, 1, ids[i]);
        lua_rawseti(L, -2, i + 1);
    }
    return 1;
}

/* w:save(path) -> true, or nil and "file: reason" */
static int w_save(lua_State *L)
{
    wb_world *w = wbl_checkworld(L, 1);
    const char *name = wbl_checkfilename(L, 2);
    char path[PATH_MAX], err[1024];
    wbl_path(L, name, 1, path, sizeof path);
    if (wbio_write_snapshot(w, path, name, err, sizeof err)) return fail_with(L, err);
    lua_pushboolean(L, 1);
    return 1;
}

/* ---- recorders ------------------------------------------------------------------------------------- */
enum { REC_PC2, REC_VTK };

typedef struct wbl_rec {
    int kind;
    wbio_pc2 *pc2;
    wbio_vtk *vtk;
    int every;
    int64_t seen;          /* frames stepped since it started */
    int32_t n;             /* PC2 of particles: their ids and a gather buffer */
    int32_t *ids;
    wb_real *buf;
    int closed;
    char name[256];        /* as the script named it, for messages */
} wbl_rec;                 /* user values: 1 the world, 2 the skin (PC2 of a skin) */

/* keep: the file takes its name (a PC2 grows aside until then); else an old file stays */
static int rec_finish(wbl_rec *r, int keep, char *err, size_t n)
{
    int rc = 0;
    if (!r->closed) {
        rc = r->kind == REC_PC2 ? wbio_pc2_close(r->pc2, keep, err, n) : wbio_vtk_close(r->vtk, err, n);
        r->closed = 1;
        r->pc2 = NULL;
        r->vtk = NULL;
    }
    free(r->ids);
    free(r->buf);
    r->ids = NULL;
    r->buf = NULL;
    return rc;
}

/* one sample now: the recorder at idx */
static int rec_write(lua_State *L, int idx, wbl_rec *r, char *err, size_t n)
{
    lua_getiuservalue(L, idx, 1);
    wb_world *w = wbl_checkworld(L, -1);
    lua_pop(L, 1);
    if (r->kind == REC_VTK) return wbio_vtk_write(r->vtk, w, err, n);
    const wb_real *pts = r->buf;
    if (lua_getiuservalue(L, idx, 2) != LUA_TNIL) {
        wb_world *sw;
        wb_skin *s = wbl_toskin(L, -1, &sw);
        lua_pop(L, 1);
        if (!s) return snprintf(err, n, "its skin was closed"), -1;
        pts = wb_skin_vertices(s, sw);
    } else {
        lua_pop(L, 1);
        const wb_real *x = wb_particle_positions(w);
        for (int32_t i = 0; i < r->n; i++) memcpy(&r->buf[3 * i], &x[3 * r->ids[i]], 3 * sizeof *x);
    }
    return wbio_pc2_write(r->pc2, pts, err, n);
}

/* the frame hook of one recorder (upvalue 1): a sample every `every` frames of its world */
static int rec_hook(lua_State *L)
{
    wbl_rec *r = (wbl_rec *)lua_touserdata(L, lua_upvalueindex(1));
    if (r->closed) return 0;
    lua_getiuservalue(L, lua_upvalueindex(1), 1);
    const int mine = lua_rawequal(L, -1, 1);
    lua_pop(L, 1);
    if (!mine || ++r->seen % r->every) return 0;
    char err[512];
    if (rec_write(L, lua_upvalueindex(1), r, err, sizeof err)) {
        char msg[800];
        snprintf(msg, sizeof msg, "recording %s: %s", r->name, err);
        rec_finish(r, 0, err, sizeof err);
        return luaL_error(L, "%s", msg);
    }
    return 0;
}

/* a new recorder on the world at world_idx (of the skin at skin_idx, or 0), pushed */
static wbl_rec *new_recorder(lua_State *L, int kind, int world_idx, int skin_idx, const char *name, int every)
{
    wbl_rec *r = (wbl_rec *)lua_newuserdatauv(L, sizeof *r, 2);
    memset(r, 0, sizeof *r);
    r->kind = kind;
    r->every = every;
    r->closed = 1; /* until its file is open */
    snprintf(r->name, sizeof r->name, "%s", name);
    luaL_setmetatable(L, WBL_RECORDER);
    lua_pushvalue(L, world_idx);
    lua_setiuservalue(L, -2, 1);
    if (skin_idx) {
        lua_pushvalue(L, skin_idx);
        lua_setiuservalue(L, -2, 2);
    }
    return r;
}

static void install(lua_State *L, int rec_idx)
{
    lua_pushvalue(L, rec_idx);
    lua_pushcclosure(L, rec_hook, 1);
    wb_rt_add_frame_hook(L, -1);
    lua_pop(L, 1);
}

/* "x.pc2" -> "x.obj": the rest mesh beside the cache */
static const char *rest_name(lua_State *L, const char *name, const char *ext)
{
    const char *dot = strrchr(name, '.'), *slash = strrchr(name, '/');
    const int stem = dot && (!slash || dot > slash) ? (int)(dot - name) : (int)strlen(name);
    return lua_pushfstring(L, "%s.%s", lua_pushlstring(L, name, (size_t)stem), ext);
}

static const char *const pc2_keys[] = { "particles", "rest", "every", NULL };
static const char *const rest_formats[] = { "obj", "ply", NULL };

/* common to w:record_pc2 and s:record_pc2: options at 3; mesh = the rest pose */
static int start_pc2(lua_State *L, wbl_rec *r, int rec_idx, const wb_mesh *rest, const char *name, int rest_fmt)
{
    char path[PATH_MAX], err[1024];
    if (rest_fmt >= 0) {
        const char *rn = rest_name(L, name, rest_formats[rest_fmt]);
        wbl_path(L, rn, 1, path, sizeof path);
        if (wbio_save_mesh(rest, NULL, path, rn, wbl_allow, L, err, sizeof err)) return fail_with(L, err);
    }
    wbl_path(L, name, 1, path, sizeof path);
    lua_getiuservalue(L, rec_idx, 1);
    const double start = (double)wb_world_frame(wbl_checkworld(L, -1));
    r->pc2 = wbio_pc2_open(path, name, rest->nv, start, (double)r->every, err, sizeof err);
    if (!r->pc2) return fail_with(L, err);
    r->closed = 0;
    if (rec_write(L, rec_idx, r, err, sizeof err)) { /* the pose now is the first sample */
        rec_finish(r, 0, err, sizeof err);
        return fail_with(L, lua_pushfstring(L, "%s: %s", name, err));
    }
    install(L, rec_idx);
    lua_pushvalue(L, rec_idx);
    return 1;
}

static void read_pc2_opts(lua_State *L, int arg, int *every, int *rest_fmt, int allow_particles)
{
    *every = 1;
    *rest_fmt = 0;
    if (!wbl_checkopts(L, arg, pc2_keys, true)) return;
    if (!allow_particles && lua_getfield(L, arg, "particles") != LUA_TNIL)
        wbl_fielderror(L, arg, "particles", "a skin records its own vertices");
    wbl_optint(L, arg, "every", 1, INT32_MAX, every);
    lua_getfield(L, arg, "rest");
    if (lua_isboolean(L, -1) && !lua_toboolean(L, -1)) *rest_fmt = -1;
    else if (!lua_isnil(L, -1)) *rest_fmt = wbl_optenum(L, arg, "rest", "rest-pose format", rest_formats);
    lua_pop(L, 1);
}

/* w:record_pc2(path, {particles = body_or_ids, rest = "obj"|"ply"|false, every = 1}) */
static int w_record_pc2(lua_State *L)
{
    wb_world *w = wbl_checkworld(L, 1);
    const char *name = wbl_checkfilename(L, 2);
    int every, fmt;
    read_pc2_opts(L, 3, &every, &fmt, 1);
    lua_settop(L, 3);
    int32_t n = wb_particle_count(w);
    const int32_t *given = NULL;
    if (lua_istable(L, 3) && lua_getfield(L, 3, "particles") != LUA_TNIL) given = wbl_checkids(L, 4, w, &n); /* 5 */
    lua_settop(L, 5);
    if (n == 0) return luaL_argerror(L, 1, "the world has no particles to record");
    wbl_rec *r = new_recorder(L, REC_PC2, 1, 0, name, every); /* 6 */
    r->n = n;
    r->ids = malloc(sizeof *r->ids * (size_t)n);
    r->buf = malloc(sizeof *r->buf * 3 * (size_t)n);
    if (!r->ids || !r->buf) return wb_rt_budget_error(L, "out of memory recording %s", name);
    for (int32_t i = 0; i < n; i++) r->ids[i] = given ? given[i] : i;
    /* the rest pose: the particles now, and the surfaces' triangles among them */
    int32_t *local = malloc(sizeof *local * (size_t)wb_particle_count(w)), ntri = 0, cap = 0;
    int32_t *tri = NULL;
    for (int32_t i = 0; local && i < wb_particle_count(w); i++) local[i] = -1;
    for (int32_t i = 0; local && i < n; i++) local[r->ids[i]] = i;
    for (int32_t s = 0; local && s < wb_surface_count(w); s++) {
        int32_t k;
        const int32_t *t = wb_surface_triangles(w, s, &k);
        for (int32_t j = 0; j < k; j++) {
            if (local[t[3 * j]] < 0 || local[t[3 * j + 1]] < 0 || local[t[3 * j + 2]] < 0) continue;
            if (ntri == cap) {
                int32_t *u = realloc(tri, sizeof *tri * 3 * (size_t)(cap = cap ? 2 * cap : 256));
                if (!u) { free(local); free(tri); return wb_rt_budget_error(L, "out of memory recording %s", name); }
                tri = u;
            }
            for (int c = 0; c < 3; c++) tri[3 * ntri + c] = local[t[3 * j + c]];
            ntri++;
        }
    }
    for (int32_t i = 0; i < n; i++) memcpy(&r->buf[3 * i], &wb_particle_positions(w)[3 * r->ids[i]], 3 * sizeof(wb_real));
    wb_mesh **rest = wbl_push_mesh_slot(L); /* 7: owned by Lua, so an error cannot leak it */
    *rest = local ? wb_mesh_create(r->buf, n, tri, ntri, NULL) : NULL;
    free(local);
    free(tri);
    if (!*rest) return wb_rt_budget_error(L, "out of memory recording %s", name);
    return start_pc2(L, r, 6, *rest, name, fmt);
}

/* s:record_pc2(path, {rest = "obj"|"ply"|false, every = 1}): the skinned vertices */
static int s_record_pc2(lua_State *L)
{
    wb_world *w;
    wb_skin *s = wbl_checkskin(L, 1, &w);
    const char *name = wbl_checkfilename(L, 2);
    int every, fmt;
    read_pc2_opts(L, 3, &every, &fmt, 0);
    lua_settop(L, 3);
    lua_getiuservalue(L, 1, 1); /* 4: the world the skin follows */
    wbl_rec *r = new_recorder(L, REC_PC2, 4, 1, name, every); /* 5 */
    return start_pc2(L, r, 5, wb_skin_rest(s), name, fmt);
}

/* w:record_vtk(path, {every = 1}): path.pvd and a folder path/ of frame_NNNNNN.vtp */
static const char *const vtk_keys[] = { "every", NULL };

static int w_record_vtk(lua_State *L)
{
    wbl_checkworld(L, 1);
    const char *name = wbl_checkfilename(L, 2);
    int every = 1;
    if (wbl_checkopts(L, 3, vtk_keys, true)) wbl_optint(L, 3, "every", 1, INT32_MAX, &every);
    lua_settop(L, 3);
    const size_t len = strlen(name);
    const char *stem = len > 4 && !strcmp(name + len - 4, ".pvd") ? lua_pushlstring(L, name, len - 4) : lua_pushstring(L, name);
    const char *pvd_name = lua_pushfstring(L, "%s.pvd", stem);
    char pvd[PATH_MAX], dir[PATH_MAX], err[1024];
    wbl_path(L, pvd_name, 1, pvd, sizeof pvd);
    /* the folder beside it, made by resolving it as a folder; its frames are written
     * each whole, a link among them replaced, never followed */
    wbl_path(L, lua_pushfstring(L, "%s/", stem), 1, dir, sizeof dir);
    for (size_t k = strlen(dir); k > 1 && dir[k - 1] == '/'; k--) dir[k - 1] = '\0';
    const char *base = strrchr(stem, '/');
    base = base ? base + 1 : stem;
    lua_settop(L, 3);
    wbl_rec *r = new_recorder(L, REC_VTK, 1, 0, name, every); /* 4 */
    r->vtk = wbio_vtk_open(pvd, dir, base, name, err, sizeof err);
    if (!r->vtk) return fail_with(L, err);
    r->closed = 0;
    if (rec_write(L, 4, r, err, sizeof err)) {
        rec_finish(r, 0, err, sizeof err);
        return fail_with(L, lua_pushfstring(L, "%s: %s", name, err));
    }
    install(L, 4);
    lua_settop(L, 4);
    return 1;
}

/* w:save_vtp(path): this frame alone -> true, or nil and "file: reason" */
static int w_save_vtp(lua_State *L)
{
    wb_world *w = wbl_checkworld(L, 1);
    const char *name = wbl_checkfilename(L, 2);
    char path[PATH_MAX], err[PATH_MAX + 128];
    wbl_path(L, name, 1, path, sizeof path);
    wbio_out o;
    if (wbio_out_open(&o, AT_FDCWD, path, name, err, sizeof err)) return fail_with(L, err);
    if (wbio_write_vtp(o.f, w)) o.failed = errno ? errno : EIO;
    if (wbio_out_commit(&o, name, err, sizeof err)) return fail_with(L, err);
    lua_pushboolean(L, 1);
    return 1;
}

/* ---- recorder methods -------------------------------------------------------------------------------- */
static int r_close(lua_State *L)
{
    wbl_rec *r = (wbl_rec *)luaL_checkudata(L, 1, WBL_RECORDER);
    char err[512];
    if (rec_finish(r, 1, err, sizeof err)) return fail_with(L, lua_pushfstring(L, "%s: %s", r->name, err));
    lua_pushboolean(L, 1);
    return 1;
}

static int r_gc(lua_State *L)
{
    char err[512];
    rec_finish((wbl_rec *)luaL_checkudata(L, 1, WBL_RECORDER), 1, err, sizeof err);
    return 0;
}

/* samples written so far (the first one at the start) */
static int r_frames(lua_State *L)
{
    wbl_rec *r = (wbl_rec *)luaL_checkudata(L, 1, WBL_RECORDER);
    if (r->closed) lua_pushinteger(L, 0);
    else lua_pushinteger(L, r->kind == REC_PC2 ? wbio_pc2_samples(r->pc2) : wbio_vtk_frames(r->vtk));
    return 1;
}

static int r_closed(lua_State *L)
{
    lua_pushboolean(L, ((wbl_rec *)luaL_checkudata(L, 1, WBL_RECORDER))->closed);
    return 1;
}

static int r_tostring(lua_State *L)
{
    wbl_rec *r = (wbl_rec *)luaL_checkudata(L, 1, WBL_RECORDER);
    lua_pushfstring(L, "wobble.recorder: %p (%s %s%s)", (void *)r, r->kind == REC_PC2 ? "PC2" : "VTK", r->name,
                    r->closed ? ", closed" : "");
    return 1;
}

static const luaL_Reg rec_methods[] = {
    { "close", r_close },
    { "frames", r_frames },
    { "closed", r_closed },
    { NULL, NULL }
};

static const luaL_Reg rec_meta[] = {
    { "__index", NULL },
    { "__gc", r_gc },
    { "__close", r_gc },
    { "__tostring", r_tostring },
    { NULL, NULL }
};

static const luaL_Reg world_methods[] = {
    { "load_particles", w_load_particles },
    { "save", w_save },
    { "record_pc2", w_record_pc2 },
    { "record_vtk", w_record_vtk },
    { "save_vtp", w_save_vtp },
    { "colliders", w_colliders },
    { "distances", w_distances },
    { NULL, NULL }
};

void wbl_open_io(lua_State *L)
{
    luaL_newmetatable(L, WBL_CONFIG);
    lua_pushcfunction(L, config_gc);
    lua_setfield(L, -2, "__gc");
    lua_pop(L, 1);
    luaL_newmetatable(L, WBL_RECORDER);
    luaL_setfuncs(L, rec_meta, 0);
    luaL_newlibtable(L, rec_methods);
    luaL_setfuncs(L, rec_methods, 0);
    lua_setfield(L, -2, "__index");
    lua_pop(L, 1);
    lua_pushcfunction(L, l_load);
    lua_setfield(L, -2, "load"); /* into the module table at the top */
    wbl_add_world_methods(L, world_methods);
    /* s:record_pc2 joins the skin's methods (wbl_open_skin ran first) */
    luaL_getmetatable(L, WBL_SKIN);
    lua_getfield(L, -1, "__index");
    lua_pushcfunction(L, s_record_pc2);
    lua_setfield(L, -2, "record_pc2");
    lua_pop(L, 2);
}
