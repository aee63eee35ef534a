/* shape_match.c: w:shape_match(ids, {stiffness, yield, creep}) and its handle. Clusters
 * are never removed, so a handle is the cluster's index plus a reference to the world's
 * userdata (its user value); it goes stale only when the world is closed. */
#include "mesh.h"
#include "util.h"

typedef struct wbl_smatch { int32_t index; uint32_t one; } wbl_smatch; /* one = 1: __eq compares bytes */

static wb_world *checksm(lua_State *L, int arg, int32_t *k)
{
    wb_world *w;
    wbl_smatch *s = (wbl_smatch *)wbl_handle(L, arg, WBL_SHAPE_MATCH, &w);
    if (!w) luaL_error(L, "stale shape_match handle (world closed)");
    *k = s->index;
    return w;
}

static const char *const sm_keys[] = { "stiffness", "yield", "creep", NULL };

/* w:shape_match(body_or_ids, {stiffness = 1, yield = nil, creep = nil}) */
static int w_shape_match(lua_State *L)
{
    wb_world *w = wbl_checkworld(L, 1);
    wb_shape_match_def d = wb_shape_match_default_def();
    if (wbl_checkopts(L, 3, sm_keys, true)) {
        wbl_optreal(L, 3, "stiffness", &d.stiffness);
        wbl_optreal(L, 3, "yield", &d.yield);
        /* plastic when yield is set: flow at creep per second, 1/s by default */
        if (!wbl_optreal(L, 3, "creep", &d.creep) && d.yield > 0) d.creep = 1;
    }
    /* the core decides (shape_match.c); an error names the option */
    const wb_fault f = wb_shape_match_def_fault(&d);
    wbl_fault_error(L, &f, 2, 2, 3);
    int32_t n;
    const int32_t *ids = wbl_checkids(L, 2, w, &n); /* a userdata on the stack: freed by Lua */
    wbl_smatch *h = (wbl_smatch *)lua_newuserdatauv(L, sizeof *h, 1); /* first: Lua may run out of memory */
    h->index = -1;
    h->one = 1;
    lua_pushvalue(L, 1);
    lua_setiuservalue(L, -2, 1);
    luaL_setmetatable(L, WBL_SHAPE_MATCH);
    const int32_t k = wb_shape_match_add(w, ids, n, &d);
    if (k < 0) return wbl_status_error(L, 2, (wb_status)k, "shape_match");
    h->index = k;
    return 1;
}

static int s_stiffness(lua_State *L)
{
    int32_t k;
    wb_world *w = checksm(L, 1, &k);
    lua_pushnumber(L, wb_shape_match_get_def(w, k).stiffness);
    return 1;
}

static int s_strain(lua_State *L)
{
    int32_t k;
    wb_world *w = checksm(L, 1, &k);
    lua_pushnumber(L, wb_shape_match_strain(w, k));
    return 1;
}

static int s_particles(lua_State *L)
{
    int32_t k;
    wb_world *w = checksm(L, 1, &k);
    const int32_t n = wb_shape_match_size(w, k);
    lua_createtable(L, n, 0);
    for (int32_t i = 0; i < n; i++) {
        lua_pushinteger(L, (lua_Integer)wb_shape_match_particle(w, k, i) + 1);
        lua_rawseti(L, -2, (lua_Integer)i + 1);
    }
    return 1;
}

/* s:rest(i) -> x, y, z: the rest position of its i-th particle about the rest mass centre */
static int s_rest(lua_State *L)
{
    int32_t k;
    wb_world *w = checksm(L, 1, &k);
    const lua_Integer i = wbl_checkint(L, 2), n = wb_shape_match_size(w, k);
    if (i < 1 || i > n) return luaL_argerror(L, 2, lua_pushfstring(L, "index %I out of range 1..%I", i, n));
    wb_real r[3];
    wb_shape_match_rest(w, k, (int32_t)i - 1, r);
    wbl_pushreals(L, r, 3);
    return 3;
}

static int s_world(lua_State *L)
{
    luaL_checkudata(L, 1, WBL_SHAPE_MATCH);
    lua_getiuservalue(L, 1, 1);
    return 1;
}

static int s_tostring(lua_State *L)
{
    wb_world *w;
    wbl_smatch *s = (wbl_smatch *)wbl_handle(L, 1, WBL_SHAPE_MATCH, &w);
    if (!w || s->index < 0) lua_pushfstring(L, "wobble.shape_match: %p (stale)", (void *)s);
    else lua_pushfstring(L, "wobble.shape_match: %p (%d particles)", (void *)s, (int)wb_shape_match_size(w, s->index));
    return 1;
}

static int s_eq(lua_State *L) { return wbl_handle_eq(L, WBL_SHAPE_MATCH, sizeof(wbl_smatch)); }

static const luaL_Reg sm_methods[] = {
    { "stiffness", s_stiffness },
    { "strain", s_strain },
    { "particles", s_particles },
    { "rest", s_rest },
    { "world", s_world },
    { NULL, NULL }
};

static const luaL_Reg sm_meta[] = {
    { "__index", NULL },
    { "__tostring", s_tostring },
    { "__eq", s_eq },
    { NULL, NULL }
};

static const luaL_Reg world_methods[] = {
    { "shape_match", w_shape_match },
    { NULL, NULL }
};

void wbl_open_shape_match(lua_State *L)
{
    luaL_newmetatable(L, WBL_SHAPE_MATCH);
    luaL_setfuncs(L, sm_meta, 0);
    luaL_newlibtable(L, sm_methods);
    luaL_setfuncs(L, sm_methods, 0);
    lua_setfield(L, -2, "__index");
    lua_pop(L, 1);
    wbl_add_world_methods(L, world_methods);
}
