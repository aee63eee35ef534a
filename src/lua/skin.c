/* skin.c: w:skin(mesh, body_or_ids, {bones = 4}) and the skin handle: linear blend
 * skinning of a high-poly mesh over a coarse particle graph (skin.c does the work).
 *
 * A world keeps the skins made on it (a registry table with weak keys, so a skin never
 * keeps its world alive and the renderer can draw them all). After every frame a hook
 * brings each skin's bone rotations up to date, so the rotation extraction is always
 * warm-started from the frame before; the vertices themselves are blended only when
 * someone asks for them (s:vertex, s:mesh, the renderer, a recorder). */
#include <string.h>

#include "io/io.h"
#include "mesh.h"
#include "sandbox.h"

typedef struct wbl_skin {   /* user value 1: the world */
    wb_skin *s;
    size_t charged;            /* bytes charged to the memory budget for s */
} wbl_skin;

/* what wb_skin_create allocates for a mesh of nv vertices and nt triangles over n bones:
 * a copy of the mesh; influences and weights (nv x k); deformed vertices and normals; per
 * bone its particle, bind and current positions, up to 32 neighbours, a flag, a quaternion
 * and a matrix */
static size_t skin_bytes(const wb_mesh *m, int32_t n, const wb_skin_def *d)
{
    const size_t nv = (size_t)(m->nv > 0 ? m->nv : 1);
    return 256 + wbl_mesh_bytes(m->nv, m->nt) + nv * (size_t)d->bones * (sizeof(int32_t) + sizeof(wb_real)) +
           nv * 6 * sizeof(wb_real) + (size_t)n * (2 * sizeof(int32_t) + 32 * sizeof(int32_t) + 1 + 19 * sizeof(wb_real));
}

static const char skins_key = 0; /* registry: {[world] = {skin, ...}}, weak keys */
static const char hook_key = 0;  /* registry: the frame hook is installed */

/* ---- handles ------------------------------------------------------------------------------------ */
wb_skin *wbl_toskin(lua_State *L, int idx, wb_world **w)
{
    wbl_skin *u = (wbl_skin *)luaL_testudata(L, idx, WBL_SKIN);
    if (!u || !u->s) return NULL;
    lua_getiuservalue(L, idx, 1);
    wbl_world *wu = (wbl_world *)luaL_testudata(L, -1, WBL_WORLD);
    lua_pop(L, 1);
    if (!wu || !wu->w) return NULL;
    *w = wu->w;
    return u->s;
}

wb_skin *wbl_checkskin(lua_State *L, int arg, wb_world **w)
{
    wbl_skin *u = (wbl_skin *)luaL_checkudata(L, arg, WBL_SKIN);
    if (!u->s) luaL_argerror(L, arg, "skin is closed");
    wb_skin *s = wbl_toskin(L, arg, w);
    if (!s) luaL_error(L, "attempt to use a closed world");
    return s;
}

/* the world's skin list (created on demand) pushed */
static void push_list(lua_State *L, int world_index, int create)
{
    world_index = lua_absindex(L, world_index);
    if (lua_rawgetp(L, LUA_REGISTRYINDEX, &skins_key) != LUA_TTABLE) {
        lua_pop(L, 1);
        lua_newtable(L);
        lua_createtable(L, 0, 1);
        lua_pushliteral(L, "k");
        lua_setfield(L, -2, "__mode");
        lua_setmetatable(L, -2);
        lua_pushvalue(L, -1);
        lua_rawsetp(L, LUA_REGISTRYINDEX, &skins_key);
    }
    lua_pushvalue(L, world_index);
    if (lua_rawget(L, -2) == LUA_TNIL && create) {
        lua_pop(L, 1);
        lua_newtable(L);
        lua_pushvalue(L, world_index);
        lua_pushvalue(L, -2);
        lua_rawset(L, -4);
    }
    lua_remove(L, -2);
}

void wbl_push_world_skins(lua_State *L, int world_index)
{
    push_list(L, world_index, 0);
    if (lua_isnil(L, -1)) {
        lua_pop(L, 1);
        lua_newtable(L);
    }
}

/* after every frame of any world: warm-started rotations of that world's skins */
static int skins_hook(lua_State *L)
{
    if (!luaL_testudata(L, 1, WBL_WORLD)) return 0;
    push_list(L, 1, 0);
    if (!lua_istable(L, -1)) return 0;
    const lua_Integer n = (lua_Integer)lua_rawlen(L, -1);
    for (lua_Integer i = 1; i <= n; i++) {
        wb_world *w;
        lua_rawgeti(L, -1, i);
        wb_skin *s = wbl_toskin(L, -1, &w);
        if (s) wb_skin_update_bones(s, w);
        lua_pop(L, 1);
    }
    return 0;
}

int32_t *wbl_checkids(lua_State *L, int arg, const wb_world *w, int32_t *n)
{
    arg = lua_absindex(L, arg);
    if (!lua_istable(L, arg)) luaL_typeerror(L, arg, "body or table of particle ids");
    int t = arg;
    /* a body names its world: another world's body has ids that mean other particles here */
    if (lua_getfield(L, arg, "world") != LUA_TNIL) {
        const wbl_world *bw = (const wbl_world *)luaL_testudata(L, -1, WBL_WORLD);
        if (bw && bw->w != w) luaL_argerror(L, arg, "the body belongs to another world");
    }
    lua_pop(L, 1);
    if (lua_getfield(L, arg, "particles") == LUA_TTABLE) t = lua_gettop(L);
    else lua_pop(L, 1);
    const size_t len = lua_rawlen(L, t);
    if (len == 0) luaL_argerror(L, arg, "no particles given");
    if (len > WB_MAX_PARTICLES) luaL_argerror(L, arg, "too many particles");
    int32_t *ids = (int32_t *)lua_newuserdatauv(L, len * sizeof *ids, 0);
    for (size_t i = 0; i < len; i++) {
        lua_rawgeti(L, t, (lua_Integer)i + 1);
        if (!lua_isinteger(L, -1))
            luaL_argerror(L, arg, lua_pushfstring(L, "particles[%d]: particle id expected, got %s", (int)i + 1, luaL_typename(L, -1)));
        ids[i] = wbl_particle_id(L, w, arg, lua_tointeger(L, -1));
        lua_pop(L, 1);
    }
    if (t != arg) lua_remove(L, t);
    *n = (int32_t)len;
    return ids;
}

void wbl_new_skin(lua_State *L, int world_index, const wb_mesh *m, const int32_t *ids, int32_t n,
                  const wb_skin_def *def, int arg)
{
    world_index = lua_absindex(L, world_index);
    wb_world *w = wbl_checkworld(L, world_index);
    /* the handle first: a Lua memory error cannot leak the skin */
    wbl_skin *u = (wbl_skin *)lua_newuserdatauv(L, sizeof *u, 1);
    u->s = NULL;
    u->charged = 0;
    luaL_setmetatable(L, WBL_SKIN);
    lua_pushvalue(L, world_index);
    lua_setiuservalue(L, -2, 1);
    const size_t bytes = skin_bytes(m, n, def);
    wbl_charge(L, bytes, "skin");
    u->charged = bytes;
    push_list(L, world_index, 1);
    wb_status st;
    u->s = wb_skin_create(w, m, ids, n, def, &st);
    if (!u->s) wbl_status_error(L, arg, st, "skin");
    lua_pushvalue(L, -2);
    lua_rawseti(L, -2, (lua_Integer)lua_rawlen(L, -2) + 1);
    lua_pop(L, 1);
    if (lua_rawgetp(L, LUA_REGISTRYINDEX, &hook_key) == LUA_TNIL) {
        lua_pushcfunction(L, skins_hook);
        wb_rt_add_frame_hook(L, -1);
        lua_pop(L, 1);
        lua_pushboolean(L, 1);
        lua_rawsetp(L, LUA_REGISTRYINDEX, &hook_key);
    }
    lua_pop(L, 1);
}

/* ---- w:skin(m, body_or_ids, {bones, neighbours, iterations}) ------------------------------------- */
static const char *const skin_keys[] = { "bones", "neighbours", "iterations", NULL };

static int w_skin(lua_State *L)
{
    wb_world *w = wbl_checkworld(L, 1);
    const wb_mesh *m = wbl_checkmesh(L, 2);
    wb_skin_def d = wb_skin_default_def();
    if (wbl_checkopts(L, 4, skin_keys, true)) {
        wbl_optint(L, 4, "bones", 1, 16, &d.bones);
        /* at least 2: a bone's neighbourhood of one other particle is collinear, and the
         * rotation of a collinear neighbourhood is not defined */
        wbl_optint(L, 4, "neighbours", 2, 32, &d.neighbours);
        wbl_optint(L, 4, "iterations", 1, 1000, &d.iterations);
    }
    lua_settop(L, 4);
    int32_t n;
    const int32_t *ids = wbl_checkids(L, 3, w, &n);
    wbl_new_skin(L, 1, m, ids, n, &d, 3);
    return 1;
}

static int w_skins(lua_State *L)
{
    wbl_checkworld(L, 1);
    wbl_push_world_skins(L, 1);
    /* a copy: the script may edit it without touching the world's list */
    lua_Integer n = (lua_Integer)lua_rawlen(L, -1);
    lua_createtable(L, (int)n, 0);
    for (lua_Integer i = 1; i <= n; i++) {
        lua_rawgeti(L, -2, i);
        lua_rawseti(L, -2, i);
    }
    return 1;
}

/* ---- methods ------------------------------------------------------------------------------------ */
static int32_t skin_vertex_id(lua_State *L, const wb_skin *s, int arg)
{
    const int32_t nv = wb_skin_rest(s)->nv;
    lua_Integer i = wbl_checkint(L, arg);
    if (i < 1 || i > nv) luaL_argerror(L, arg, lua_pushfstring(L, "vertex %I out of range (1..%d)", i, (int)nv));
    return (int32_t)(i - 1);
}

static int s_vertex(lua_State *L)
{
    wb_world *w;
    wb_skin *s = wbl_checkskin(L, 1, &w);
    const int32_t v = skin_vertex_id(L, s, 2);
    wbl_pushreals(L, &wb_skin_vertices(s, w)[3 * v], 3);
    return 3;
}

static int s_vertex_count(lua_State *L)
{
    wb_world *w;
    lua_pushinteger(L, wb_skin_rest(wbl_checkskin(L, 1, &w))->nv);
    return 1;
}

static int s_triangle_count(lua_State *L)
{
    wb_world *w;
    lua_pushinteger(L, wb_skin_rest(wbl_checkskin(L, 1, &w))->nt);
    return 1;
}

/* s:mesh(): the deformed mesh now, as a new mesh (a copy with fresh normals) */
static int s_mesh(lua_State *L)
{
    wb_world *w;
    wb_skin *s = wbl_checkskin(L, 1, &w);
    wb_mesh **slot = wbl_push_mesh_charged(L, wb_skin_rest(s)->nv, wb_skin_rest(s)->nt, "s:mesh()");
    wb_mesh *m = wb_mesh_copy(wb_skin_rest(s));
    if (!m) return wb_rt_budget_error(L, "out of memory copying a mesh");
    *slot = m;
    const wb_real *v = wb_skin_vertices(s, w), *n = wb_skin_normals(s, w);
    memcpy(m->v, v, sizeof *v * 3 * (size_t)m->nv);
    memcpy(m->n, n, sizeof *n * 3 * (size_t)m->nv);
    return 1;
}

/* s:save_obj(path) / s:save(path): the deformed mesh now; true, or nil and "file: reason" */
static int save_as(lua_State *L, const char *ext)
{
    wb_world *w;
    wb_skin *s = wbl_checkskin(L, 1, &w);
    const char *name = wbl_checkfilename(L, 2), *dot = strrchr(name, '.');
    char path[4096], err[1024];
    if (ext && (!dot || strcmp(dot, ext))) return luaL_argerror(L, 2, lua_pushfstring(L, "a %s file name expected", ext));
    wbl_path(L, name, 1, path, sizeof path);
    const wb_mesh *r = wb_skin_rest(s);
    const wb_real *n = wb_skin_normals(s, w), *v = wb_skin_vertices(s, w);
    wb_mesh now = { r->nv, r->nt, (wb_real *)v, (wb_real *)n, r->tri }; /* borrowed, not copied */
    if (wbio_save_mesh(&now, NULL, path, name, wbl_allow, L, err, sizeof err)) {
        luaL_pushfail(L);
        lua_pushstring(L, err);
        return 2;
    }
    lua_pushboolean(L, 1);
    return 1;
}

static int s_save(lua_State *L) { return save_as(L, NULL); }
static int s_save_obj(lua_State *L) { return save_as(L, ".obj"); }

/* s:bounds() -> minx, miny, minz, maxx, maxy, maxz of the deformed mesh now */
static int s_bounds(lua_State *L)
{
    wb_world *w;
    wb_skin *s = wbl_checkskin(L, 1, &w);
    const wb_real *v = wb_skin_vertices(s, w);
    const int32_t nv = wb_skin_rest(s)->nv;
    if (nv == 0) {
        lua_pushnil(L);
        return 1;
    }
    wb_real lo[3] = { v[0], v[1], v[2] }, hi[3] = { v[0], v[1], v[2] };
    for (int32_t i = 1; i < nv; i++)
        for (int k = 0; k < 3; k++) {
            if (v[3 * i + k] < lo[k]) lo[k] = v[3 * i + k];
            if (v[3 * i + k] > hi[k]) hi[k] = v[3 * i + k];
        }
    wbl_pushreals(L, lo, 3);
    wbl_pushreals(L, hi, 3);
    return 6;
}

static int s_update(lua_State *L)
{
    wb_world *w;
    wb_skin *s = wbl_checkskin(L, 1, &w);
    wb_skin_vertices(s, w);
    return 0;
}

/* s:influences(v) -> {particle ids}, {weights} */
static int s_influences(lua_State *L)
{
    wb_world *w;
    wb_skin *s = wbl_checkskin(L, 1, &w);
    const int32_t v = skin_vertex_id(L, s, 2);
    int32_t ids[16];
    wb_real wt[16];
    const int n = wb_skin_influences(s, v, ids, wt);
    lua_createtable(L, n, 0);
    lua_createtable(L, n, 0);
    for (int i = 0; i < n; i++) {
        lua_pushinteger(L, (lua_Integer)ids[i] + 1);
        lua_rawseti(L, -3, i + 1);
        lua_pushnumber(L, wt[i]);
        lua_rawseti(L, -2, i + 1);
    }
    return 2;
}

static int s_bones(lua_State *L)
{
    wb_world *w;
    wb_skin *s = wbl_checkskin(L, 1, &w);
    const int32_t n = wb_skin_bone_count(s);
    lua_createtable(L, n, 0);
    for (int32_t b = 0; b < n; b++) {
        lua_pushinteger(L, (lua_Integer)wb_skin_bone_particle(s, b) + 1);
        lua_rawseti(L, -2, (lua_Integer)b + 1);
    }
    return 1;
}

/* s:bone_rotation(k) -> qw, qx, qy, qz of the k-th bone (s:bones() order), up to date */
static int s_bone_rotation(lua_State *L)
{
    wb_world *w;
    wb_skin *s = wbl_checkskin(L, 1, &w);
    const lua_Integer k = wbl_checkint(L, 2);
    if (k < 1 || k > wb_skin_bone_count(s))
        return luaL_argerror(L, 2, lua_pushfstring(L, "bone %I out of range (1..%d)", k, (int)wb_skin_bone_count(s)));
    wb_real q[4];
    wb_skin_update_bones(s, w);
    wb_skin_bone_rotation(s, (int32_t)(k - 1), q);
    wbl_pushreals(L, q, 4);
    return 4;
}

static int s_world(lua_State *L)
{
    luaL_checkudata(L, 1, WBL_SKIN);
    lua_getiuservalue(L, 1, 1);
    return 1;
}

/* s:close() (also __gc/__close): frees the skin and takes it off its world's list, so the
 * list (which holds its skins strongly, for the frame hook and the renderer) only ever
 * holds open skins */
static int s_close(lua_State *L)
{
    wbl_skin *u = (wbl_skin *)luaL_checkudata(L, 1, WBL_SKIN);
    wbl_release(L, u->charged);   /* also when creation failed after the charge */
    u->charged = 0;
    if (!u->s) return 0;
    wb_skin_destroy(u->s);
    u->s = NULL;
    lua_settop(L, 1);
    if (lua_getiuservalue(L, 1, 1) == LUA_TNIL) return 0; /* 2: the world */
    push_list(L, 2, 0);                                  /* 3 */
    if (!lua_istable(L, 3)) return 0;
    const lua_Integer n = (lua_Integer)lua_rawlen(L, 3);
    for (lua_Integer i = 1; i <= n; i++) {
        lua_rawgeti(L, 3, i);
        const int found = lua_rawequal(L, -1, 1);
        lua_pop(L, 1);
        if (!found) continue;
        for (lua_Integer j = i; j < n; j++) { /* shift the rest down: order kept */
            lua_rawgeti(L, 3, j + 1);
            lua_rawseti(L, 3, j);
        }
        lua_pushnil(L);
        lua_rawseti(L, 3, n);
        break;
    }
    return 0;
}

static int s_closed(lua_State *L)
{
    lua_pushboolean(L, ((wbl_skin *)luaL_checkudata(L, 1, WBL_SKIN))->s == NULL);
    return 1;
}

static int s_tostring(lua_State *L)
{
    wbl_skin *u = (wbl_skin *)luaL_checkudata(L, 1, WBL_SKIN);
    if (!u->s) lua_pushfstring(L, "wobble.skin: %p (closed)", (void *)u);
    else lua_pushfstring(L, "wobble.skin: %p (%d vertices on %d particles)", (void *)u, (int)wb_skin_rest(u->s)->nv,
                         (int)wb_skin_bone_count(u->s));
    return 1;
}

static const luaL_Reg skin_methods[] = {
    { "vertex", s_vertex },
    { "vertex_count", s_vertex_count },
    { "triangle_count", s_triangle_count },
    { "mesh", s_mesh },
    { "bounds", s_bounds },
    { "save", s_save },
    { "save_obj", s_save_obj },
    { "update", s_update },
    { "influences", s_influences },
    { "bones", s_bones },
    { "bone_rotation", s_bone_rotation },
    { "world", s_world },
    { "close", s_close },
    { "closed", s_closed },
    { NULL, NULL }
};

static const luaL_Reg skin_meta[] = {
    { "__index", NULL },
    { "__gc", s_close },
    { "__close", s_close },
    { "__tostring", s_tostring },
    { NULL, NULL }
};

static const luaL_Reg world_methods[] = {
    { "skin", w_skin },
    { "skins", w_skins },
    { NULL, NULL }
};

void wbl_open_skin(lua_State *L)
{
    luaL_newmetatable(L, WBL_SKIN);
    luaL_setfuncs(L, skin_meta, 0);
    luaL_newlibtable(L, skin_methods);
    luaL_setfuncs(L, skin_methods, 0);
    lua_setfield(L, -2, "__index");
    lua_pop(L, 1);
    wbl_add_world_methods(L, world_methods);
}
