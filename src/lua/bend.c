/* bend.c: dihedral bending constraints: w:bend(p1, p2, p3, p4, {...}), w:bends() and
 * the bend handle. As a distance handle: the core's id plus its world's userdata as
 * the user value, so the world outlives every handle. */
#include "util.h"

#define WBL_BEND "wobble.bend"

typedef struct wbl_bend { wb_bend_id id; } wbl_bend;

static void push_bend(lua_State *L, int world_index, wb_bend_id id)
{
    world_index = lua_absindex(L, world_index);
    wbl_bend *c = (wbl_bend *)lua_newuserdatauv(L, sizeof *c, 1);
    c->id = id;
    lua_pushvalue(L, world_index);
    lua_setiuservalue(L, -2, 1);
    luaL_setmetatable(L, WBL_BEND);
}

static wb_world *checkbend(lua_State *L, int arg, wb_bend_id *id)
{
    wb_world *w;
    wbl_bend *c = (wbl_bend *)wbl_handle(L, arg, WBL_BEND, &w);
    if (!w || !wb_bend_valid(w, c->id)) luaL_error(L, "stale bend handle (world closed)");
    *id = c->id;
    return w;
}

static const char *const bend_keys[] = { "compliance", "damping", "rest", "break_torque", NULL };

/* w:bend(p1, p2, p3, p4 [, {compliance = 0, damping = 0, rest = current angle, break_torque}]) */
static int w_bend(lua_State *L)
{
    wb_world *w = wbl_checkworld(L, 1);
    int32_t p[4];
    for (int i = 0; i < 4; i++) p[i] = wbl_checkparticle(L, w, 2 + i);
    wb_bend_def d = wb_bend_default_def();
    if (wbl_checkopts(L, 6, bend_keys, true)) {
        wbl_optreal(L, 6, "compliance", &d.compliance);
        wbl_optreal(L, 6, "damping", &d.damping);
        wbl_optreal(L, 6, "rest", &d.rest);
        wbl_optreal(L, 6, "break_torque", &d.break_torque);
    }
    /* the core decides (bend.c); an error names the option or the particle at fault */
    const wb_fault f = wb_bend_check(wb_particle_count(w), wb_particle_positions(w), p, &d);
    wbl_fault_error(L, &f, 2, 2, 6);
    push_bend(L, 1, (wb_bend_id){ 0, 0 }); /* first: Lua may run out of memory */
    wb_status st = WB_OK;
    wb_bend_id id = wb_bend_add(w, p, &d, &st);
    if (st != WB_OK) return wbl_status_error(L, 6, st, "bend constraint");
    ((wbl_bend *)lua_touserdata(L, -1))->id = id;
    return 1;
}

/* w:bends() -> every bend of the world, in creation order */
static int w_bends(lua_State *L)
{
    wb_world *w = wbl_checkworld(L, 1);
    const int32_t n = wb_bend_count(w);
    lua_createtable(L, n, 0);
    for (int32_t i = 0; i < n; i++) {
        push_bend(L, 1, wb_bend_at(w, i));
        lua_rawseti(L, -2, i + 1);
    }
    return 1;
}

static int b_force(lua_State *L)
{
    wb_bend_id id;
    wb_world *w = checkbend(L, 1, &id);
    lua_pushnumber(L, wb_bend_force(w, id));
    return 1;
}

static int b_broken(lua_State *L)
{
    wb_bend_id id;
    wb_world *w = checkbend(L, 1, &id);
    lua_pushboolean(L, wb_bend_broken(w, id));
    return 1;
}

/* w:bend_breaks() -> the bends broken (by break_torque) during the last step, as handles */
static int w_bend_breaks(lua_State *L)
{
    wb_world *w = wbl_checkworld(L, 1);
    const int32_t n = wb_world_bend_break_count(w);
    lua_createtable(L, n, 0);
    for (int32_t i = 0; i < n; i++) {
        push_bend(L, 1, wb_world_bend_break_at(w, i));
        lua_rawseti(L, -2, i + 1);
    }
    return 1;
}

static int b_angle(lua_State *L)
{
    wb_bend_id id;
    wb_world *w = checkbend(L, 1, &id);
    lua_pushnumber(L, wb_bend_angle(w, id));
    return 1;
}

static int b_rest(lua_State *L)
{
    wb_bend_id id;
    wb_world *w = checkbend(L, 1, &id);
    lua_pushnumber(L, wb_bend_rest(w, id));
    return 1;
}

static int b_particles(lua_State *L)
{
    wb_bend_id id;
    wb_world *w = checkbend(L, 1, &id);
    int32_t p[4];
    wb_bend_particles(w, id, p);
    for (int i = 0; i < 4; i++) lua_pushinteger(L, (lua_Integer)p[i] + 1);
    return 4;
}

static int b_valid(lua_State *L)
{
    wb_world *w;
    wbl_bend *c = (wbl_bend *)wbl_handle(L, 1, WBL_BEND, &w);
    lua_pushboolean(L, w && wb_bend_valid(w, c->id));
    return 1;
}

static int b_world(lua_State *L)
{
    luaL_checkudata(L, 1, WBL_BEND);
    lua_getiuservalue(L, 1, 1);
    return 1;
}

static int b_tostring(lua_State *L)
{
    wb_world *w;
    wbl_bend *c = (wbl_bend *)wbl_handle(L, 1, WBL_BEND, &w);
    if (!w || !wb_bend_valid(w, c->id)) {
        lua_pushfstring(L, "wobble.bend: %p (stale)", (void *)c);
        return 1;
    }
    int32_t p[4];
    wb_bend_particles(w, c->id, p);
    lua_pushfstring(L, "wobble.bend: %p (%d-%d, wings %d %d)", (void *)c, (int)p[0] + 1, (int)p[1] + 1, (int)p[2] + 1,
                    (int)p[3] + 1);
    return 1;
}

static int b_eq(lua_State *L) { return wbl_handle_eq(L, WBL_BEND, sizeof(wb_bend_id)); }

static const luaL_Reg bend_methods[] = {
    { "force", b_force },
    { "angle", b_angle },
    { "rest", b_rest },
    { "broken", b_broken },
    { "particles", b_particles },
    { "valid", b_valid },
    { "world", b_world },
    { NULL, NULL }
};

static const luaL_Reg bend_meta[] = {
    { "__index", NULL },
    { "__tostring", b_tostring },
    { "__eq", b_eq },
    { NULL, NULL }
};

static const luaL_Reg world_methods[] = {
    { "bend", w_bend },
    { "bends", w_bends },
    { "bend_breaks", w_bend_breaks },
    { NULL, NULL }
};

void wbl_open_bend(lua_State *L)
{
    luaL_newmetatable(L, WBL_BEND);
    luaL_setfuncs(L, bend_meta, 0);
    luaL_newlibtable(L, bend_methods);
    luaL_setfuncs(L, bend_methods, 0);
    lua_setfield(L, -2, "__index");
    lua_pop(L, 1);
    wbl_add_world_methods(L, world_methods);
}
