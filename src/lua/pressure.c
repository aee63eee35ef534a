/* pressure.c: w:pressure(body, {pressure = 1, compliance = 0}) and its handle. Pressure
 * constraints are never removed: a handle is the constraint's index plus a reference to
 * the world's userdata; it goes stale only when the world is closed. */
#include "util.h"

typedef struct wbl_pressure { int32_t index; uint32_t one; } wbl_pressure; /* one = 1: __eq compares bytes */

static wb_world *checkpr(lua_State *L, int arg, int32_t *k)
{
    wb_world *w;
    wbl_pressure *p = (wbl_pressure *)wbl_handle(L, arg, WBL_PRESSURE, &w);
    if (!w) luaL_error(L, "stale pressure handle (world closed)");
    *k = p->index;
    return w;
}

static const char *const pr_keys[] = { "pressure", "compliance", NULL };

/* an integer field of the body table at arg */
static lua_Integer body_field(lua_State *L, int arg, const char *key)
{
    lua_getfield(L, arg, key);
    if (!lua_isinteger(L, -1))
        luaL_argerror(L, arg, lua_pushfstring(L, "body expected (a table from w:from_mesh, w:lattice, ...; its '%s' "
                                                 "is %s)", key, luaL_typename(L, -1)));
    lua_Integer v = lua_tointeger(L, -1);
    lua_pop(L, 1);
    return v;
}

/* w:pressure(body, {pressure = 1, compliance = 0}) */
static int w_pressure(lua_State *L)
{
    wb_world *w = wbl_checkworld(L, 1);
    luaL_checktype(L, 2, LUA_TTABLE);
    wb_pressure_def d = wb_pressure_default_def();
    if (wbl_checkopts(L, 3, pr_keys, true)) {
        wbl_optreal(L, 3, "pressure", &d.pressure);
        wbl_optreal(L, 3, "compliance", &d.compliance);
    }
    /* the core decides (pressure.c); an error names the option */
    const wb_fault f = wb_pressure_def_fault(&d);
    wbl_fault_error(L, &f, 2, 2, 3);
    /* a body names its world: another world's body has a range that means other particles here */
    if (lua_getfield(L, 2, "world") != LUA_TNIL) {
        const wbl_world *bw = (const wbl_world *)luaL_testudata(L, -1, WBL_WORLD);
        if (bw && bw->w != w) return luaL_argerror(L, 2, "the body belongs to another world");
    }
    lua_pop(L, 1);
    const lua_Integer first = body_field(L, 2, "first"), count = body_field(L, 2, "count");
    if (first < 1 || count < 0 || first - 1 + count > wb_particle_count(w))
        return luaL_argerror(L, 2, "body expected (its particles are not in this world)");
    wb_body b = { (int32_t)first - 1, (int32_t)count, 0 };
    const int32_t s = wb_body_surface(w, b);
    if (s < 0)
        return luaL_argerror(L, 2, "the body has no surface (pressure needs a closed one: w:from_mesh of a closed "
                                   "mesh, or w:lattice)");
    wbl_pressure *h = (wbl_pressure *)lua_newuserdatauv(L, sizeof *h, 1); /* first: Lua may run out of memory */
    h->index = -1;
    h->one = 1;
    lua_pushvalue(L, 1);
    lua_setiuservalue(L, -2, 1);
    luaL_setmetatable(L, WBL_PRESSURE);
    const int32_t k = wb_pressure_add(w, s, &d);
    if (k < 0) return wbl_status_error(L, 2, (wb_status)k, "pressure");
    h->index = k;
    return 1;
}

static int p_volume(lua_State *L)
{
    int32_t k;
    wb_world *w = checkpr(L, 1, &k);
    lua_pushnumber(L, wb_pressure_volume(w, k));
    return 1;
}

static int p_rest_volume(lua_State *L)
{
    int32_t k;
    wb_world *w = checkpr(L, 1, &k);
    lua_pushnumber(L, wb_pressure_rest_volume(w, k));
    return 1;
}

static int p_pressure(lua_State *L)
{
    int32_t k;
    wb_world *w = checkpr(L, 1, &k);
    lua_pushnumber(L, wb_pressure_get_def(w, k).pressure);
    return 1;
}

static int p_set_pressure(lua_State *L)
{
    int32_t k;
    wb_world *w = checkpr(L, 1, &k);
    wb_pressure_def d = wb_pressure_get_def(w, k);
    d.pressure = wbl_checkreal(L, 2);
    const wb_fault f = wb_pressure_def_fault(&d); /* the core decides (pressure.c) */
    if (f.msg) return luaL_argerror(L, 2, f.msg);
    wb_pressure_set(w, k, d.pressure);
    return 0;
}

static int p_world(lua_State *L)
{
    luaL_checkudata(L, 1, WBL_PRESSURE);
    lua_getiuservalue(L, 1, 1);
    return 1;
}

static int p_tostring(lua_State *L)
{
    wb_world *w;
    wbl_pressure *p = (wbl_pressure *)wbl_handle(L, 1, WBL_PRESSURE, &w);
    if (!w || p->index < 0) lua_pushfstring(L, "wobble.pressure: %p (stale)", (void *)p);
    else lua_pushfstring(L, "wobble.pressure: %p (x%f of %f m^3)", (void *)p, (double)wb_pressure_get_def(w, p->index).pressure,
                         (double)wb_pressure_rest_volume(w, p->index));
    return 1;
}

static int p_eq(lua_State *L) { return wbl_handle_eq(L, WBL_PRESSURE, sizeof(wbl_pressure)); }

static const luaL_Reg pr_methods[] = {
    { "volume", p_volume },
    { "rest_volume", p_rest_volume },
    { "pressure", p_pressure },
    { "set_pressure", p_set_pressure },
    { "world", p_world },
    { NULL, NULL }
};

static const luaL_Reg pr_meta[] = {
    { "__index", NULL },
    { "__tostring", p_tostring },
    { "__eq", p_eq },
    { NULL, NULL }
};

static const luaL_Reg world_methods[] = {
    { "pressure", w_pressure },
    { NULL, NULL }
};

void wbl_open_pressure(lua_State *L)
{
    luaL_newmetatable(L, WBL_PRESSURE);
    luaL_setfuncs(L, pr_meta, 0);
    luaL_newlibtable(L, pr_methods);
    luaL_setfuncs(L, pr_methods, 0);
    lua_setfield(L, -2, "__index");
    lua_pop(L, 1);
    wbl_add_world_methods(L, world_methods);
}
