/* distance.c: distance constraints: w:distance(p, q, {...}) and the constraint
 * handle. A handle is the core's (index, generation) id plus a reference to the
 * world's userdata (its user value), so the world outlives every handle. */
#include "util.h"

typedef struct wbl_distance { wb_distance_id id; } wbl_distance;

wb_distance_id *wbl_push_distance(lua_State *L, int world_index, wb_distance_id id)
{
    world_index = lua_absindex(L, world_index);
    wbl_distance *c = (wbl_distance *)lua_newuserdatauv(L, sizeof *c, 1);
    c->id = id;
    lua_pushvalue(L, world_index);
    lua_setiuservalue(L, -2, 1);
    luaL_setmetatable(L, WBL_DISTANCE);
    return &c->id;
}

/* the world of a live handle; raises for a removed constraint or a closed world */
static wb_world *checkdistance(lua_State *L, int arg, wb_distance_id *id)
{
    wb_world *w;
    wbl_distance *c = (wbl_distance *)wbl_handle(L, arg, WBL_DISTANCE, &w);
    if (!w || !wb_distance_valid(w, c->id)) luaL_error(L, "stale constraint handle (removed or world closed)");
    *id = c->id;
    return w;
}

static const char *const distance_keys[] = {
    "compliance", "rest", "damping", "yield", "creep", "break_strain", "break_force", NULL
};

static int w_distance(lua_State *L)
{
    wb_world *w = wbl_checkworld(L, 1);
    int32_t a = wbl_checkparticle(L, w, 2);
    int32_t b = wbl_checkparticle(L, w, 3);
    wb_distance_def d = wb_distance_default_def();
    if (wbl_checkopts(L, 4, distance_keys, true)) {
        wbl_read_link(L, 4, &d);
        /* nil (absent) means the current distance; an explicit value must be >= 0 */
        if (wbl_optreal(L, 4, "rest", &d.rest) && d.rest < 0)
            return wbl_fielderror(L, 4, "rest", "must be >= 0");
    }
    /* the core decides (wb_distance_check); an error names the option or the particle at
     * fault. Without positions: the message of their distance names the particles */
    const wb_fault f = wb_distance_check(wb_particle_count(w), NULL, a, b, &d);
    wbl_fault_error(L, &f, 2, 3, 4);
    wb_distance_id none = { 0, 0 };
    wb_distance_id *id = wbl_push_distance(L, 1, none); /* first: Lua may run out of memory */
    wb_status st = WB_OK;
    *id = wb_distance_add(w, a, b, &d, &st);
    if (st != WB_OK) return wbl_status_error(L, st == WB_ERR_ARG ? 3 : 4, st, "distance constraint");
    return 1;
}

/* w:breaks() -> the constraints broken during the last step, as handles */
static int w_breaks(lua_State *L)
{
    wb_world *w = wbl_checkworld(L, 1);
    int32_t n = wb_world_break_count(w);
    lua_createtable(L, n, 0);
    for (int32_t i = 0; i < n; i++) {
        wbl_push_distance(L, 1, wb_world_break_at(w, i));
        lua_rawseti(L, -2, i + 1);
    }
    return 1;
}

static int c_force(lua_State *L)
{
    wb_distance_id id;
    wb_world *w = checkdistance(L, 1, &id);
    lua_pushnumber(L, wb_distance_force(w, id));
    return 1;
}

static int c_rest(lua_State *L)
{
    wb_distance_id id;
    wb_world *w = checkdistance(L, 1, &id);
    lua_pushnumber(L, wb_distance_rest(w, id));
    return 1;
}

static int c_length(lua_State *L)
{
    wb_distance_id id;
    wb_world *w = checkdistance(L, 1, &id);
    lua_pushnumber(L, wb_distance_length(w, id));
    return 1;
}

static int c_strain(lua_State *L)
{
    wb_distance_id id;
    wb_world *w = checkdistance(L, 1, &id);
    wb_real rest = wb_distance_rest(w, id);
    lua_pushnumber(L, rest > 0 ? (wb_distance_length(w, id) - rest) / rest : 0);
    return 1;
}

static int c_broken(lua_State *L)
{
    wb_distance_id id;
    wb_world *w = checkdistance(L, 1, &id);
    lua_pushboolean(L, wb_distance_broken(w, id));
    return 1;
}

static int c_particles(lua_State *L)
{
    wb_distance_id id;
    wb_world *w = checkdistance(L, 1, &id);
    int32_t a, b;
    wb_distance_particles(w, id, &a, &b);
    lua_pushinteger(L, (lua_Integer)a + 1);
    lua_pushinteger(L, (lua_Integer)b + 1);
    return 2;
}

static int c_remove(lua_State *L)
{
    wb_distance_id id;
    wb_world *w = checkdistance(L, 1, &id);
    wb_distance_remove(w, id);
    return 0;
}

/* c:valid() -> false once removed or its world closed (never raises) */
static int c_valid(lua_State *L)
{
    wb_world *w;
    wbl_distance *c = (wbl_distance *)wbl_handle(L, 1, WBL_DISTANCE, &w);
    lua_pushboolean(L, w && wb_distance_valid(w, c->id));
    return 1;
}

static int c_world(lua_State *L)
{
    luaL_checkudata(L, 1, WBL_DISTANCE);
    lua_getiuservalue(L, 1, 1);
    return 1;
}

static int c_tostring(lua_State *L)
{
    wb_world *w;
    wbl_distance *c = (wbl_distance *)wbl_handle(L, 1, WBL_DISTANCE, &w);
    if (!w || !wb_distance_valid(w, c->id)) {
        lua_pushfstring(L, "wobble.distance: %p (stale)", (void *)c);
        return 1;
    }
    int32_t a, b;
    wb_distance_particles(w, c->id, &a, &b);
    lua_pushfstring(L, "wobble.distance: %p (%d-%d%s)", (void *)c, (int)a + 1, (int)b + 1,
                    wb_distance_broken(w, c->id) ? ", broken" : "");
    return 1;
}

/* two handles are equal when they name the same constraint of the same world */
static int c_eq(lua_State *L)
{
    return wbl_handle_eq(L, WBL_DISTANCE, sizeof(wb_distance_id));
}

static const luaL_Reg distance_methods[] = {
    { "force", c_force },
    { "rest", c_rest },
    { "length", c_length },
    { "strain", c_strain },
    { "broken", c_broken },
    { "particles", c_particles },
    { "remove", c_remove },
    { "valid", c_valid },
    { "world", c_world },
    { NULL, NULL }
};

static const luaL_Reg distance_meta[] = {
    { "__index", NULL },
    { "__tostring", c_tostring },
    { "__eq", c_eq },
    { NULL, NULL }
};

static const luaL_Reg world_methods[] = {
    { "distance", w_distance },
    { "breaks", w_breaks },
    { NULL, NULL }
};

void wbl_open_distance(lua_State *L)
{
    luaL_newmetatable(L, WBL_DISTANCE);
    luaL_setfuncs(L, distance_meta, 0);
    luaL_newlibtable(L, distance_methods);
    luaL_setfuncs(L, distance_methods, 0);
    lua_setfield(L, -2, "__index");
    lua_pop(L, 1);
    wbl_add_world_methods(L, world_methods);
}
