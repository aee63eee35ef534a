/* tether.c: tethers (long-range attachments, core/tether.c) from scripts:
 *   w:tether(p, q, {length, compliance}) -> index    w:tether_count()
 *   w:tether_info(i) -> p, q, length, distance, force
 *   body:tether_to_pins({compliance}) -> how many were made
 * Tethers are plain indices (1-based): they are never removed. */
#include <math.h>

#include "util.h"

static const char *const tether_keys[] = { "length", "compliance", NULL };

/* compliance (m/N, >= 0) of the options at arg, if any */
static void read_compliance(lua_State *L, int arg, wb_real *c)
{
    if (wbl_optreal(L, arg, "compliance", c) && !(*c >= 0)) wbl_fielderror(L, arg, "compliance", "must be >= 0");
}

static int w_tether(lua_State *L)
{
    wb_world *w = wbl_checkworld(L, 1);
    const int32_t p = wbl_checkparticle(L, w, 2), q = wbl_checkparticle(L, w, 3);
    wb_tether_def d = wb_tether_default_def();
    if (wbl_checkopts(L, 4, tether_keys, true)) {
        d.has_length = wbl_optreal(L, 4, "length", &d.length);
        wbl_optreal(L, 4, "compliance", &d.compliance);
    }
    /* the core decides (tether.c); an error names the option or the particle at fault */
    const wb_fault f = wb_tether_check(wb_particle_count(w), wb_particle_positions(w), p, q, &d);
    wbl_fault_error(L, &f, 2, 3, 4);
    const int32_t i = wb_tether_add(w, p, q, &d);
    if (i < 0) return wbl_status_error(L, 4, (wb_status)i, "tether");
    lua_pushinteger(L, (lua_Integer)i + 1);
    return 1;
}

static int w_tether_count(lua_State *L)
{
    lua_pushinteger(L, wb_tether_count(wbl_checkworld(L, 1)));
    return 1;
}

/* w:tether_info(i) -> p, q, length (m), their distance now (m), force (N, the last substep's) */
static int w_tether_info(lua_State *L)
{
    wb_world *w = wbl_checkworld(L, 1);
    const lua_Integer i = wbl_checkint(L, 2);
    if (i < 1 || i > wb_tether_count(w))
        return luaL_argerror(L, 2, lua_pushfstring(L, "tether %I out of range (1..%d)", i, (int)wb_tether_count(w)));
    int32_t pq[2];
    wb_tether_particles(w, (int32_t)i - 1, pq);
    wb_real a[3], b[3];
    wb_particle_position(w, pq[0], a);
    wb_particle_position(w, pq[1], b);
    lua_pushinteger(L, (lua_Integer)pq[0] + 1);
    lua_pushinteger(L, (lua_Integer)pq[1] + 1);
    lua_pushnumber(L, wb_tether_length(w, (int32_t)i - 1));
    lua_pushnumber(L, sqrt((a[0] - b[0]) * (a[0] - b[0]) + (a[1] - b[1]) * (a[1] - b[1]) + (a[2] - b[2]) * (a[2] - b[2])));
    lua_pushnumber(L, wb_tether_force(w, (int32_t)i - 1));
    return 5;
}

/* body:tether_to_pins({compliance}): each particle of the body that is not pinned to its
 * nearest pinned one, at their distance where the body was made */
static int body_tether_to_pins(lua_State *L)
{
    luaL_checktype(L, 1, LUA_TTABLE);
    wb_real compliance = 0;
    if (wbl_checkopts(L, 2, tether_keys + 1, true)) read_compliance(L, 2, &compliance);
    lua_getfield(L, 1, "world");
    wb_world *w = wbl_checkworld(L, lua_gettop(L));
    if (lua_getfield(L, 1, "particles") != LUA_TTABLE) return luaL_argerror(L, 1, "body expected (no 'particles' table)");
    const lua_Integer n = (lua_Integer)lua_rawlen(L, -1);
    int32_t *ids = lua_newuserdatauv(L, sizeof *ids * (size_t)(n > 0 ? n : 1), 0);
    for (lua_Integer k = 1; k <= n; k++) {
        lua_rawgeti(L, -2, k);
        ids[k - 1] = wbl_particle_id(L, w, 1, luaL_checkinteger(L, -1));
        lua_pop(L, 1);
    }
    const int32_t made = wb_tether_to_pins(w, ids, (int32_t)n, compliance);
    if (made < 0) return wbl_status_error(L, 1, (wb_status)made, "tethers");
    lua_pushinteger(L, made);
    return 1;
}

static const luaL_Reg world_methods[] = {
    { "tether", w_tether },
    { "tether_count", w_tether_count },
    { "tether_info", w_tether_info },
    { NULL, NULL }
};

static const luaL_Reg body_methods[] = {
    { "tether_to_pins", body_tether_to_pins },
    { NULL, NULL }
};

void wbl_open_tether(lua_State *L)
{
    wbl_add_world_methods(L, world_methods);
    /* the body's methods (body.c made its metatable) */
    luaL_getmetatable(L, WBL_BODY);
    lua_getfield(L, -1, "__index");
    luaL_setfuncs(L, body_methods, 0);
    lua_pop(L, 2);
}
