/* rigid.c: rigid bodies: w:rigid{shape = ...} and the body handle (id + generation, the
 * world's userdata as its user value), w:rigids(). */
#include <math.h>

#include "util.h"

typedef struct wbl_rigid { wb_rigid_id id; } wbl_rigid;

/* the keys every body takes, then its shape's fields (wb_shape_info: those of a collider's
 * def that a rigid def has too, in that order): a key of another shape is an error, not
 * ignored */
static const char *const keys_first[] = { "shape", "mass", "pos", "rotation", "vel", "angular_velocity", "friction",
                                          "restitution", NULL };
static const char *const keys_last[] = { NULL };

static wb_rigid_id *push_rigid(lua_State *L, int world_index, wb_rigid_id id)
{
    world_index = lua_absindex(L, world_index);
    wbl_rigid *r = (wbl_rigid *)lua_newuserdatauv(L, sizeof *r, 1);
    r->id = id;
    lua_pushvalue(L, world_index);
    lua_setiuservalue(L, -2, 1);
    luaL_setmetatable(L, WBL_RIGID);
    return &r->id;
}

static wb_world *checkrigid(lua_State *L, int arg, wb_rigid_id *id)
{
    wb_world *w;
    wbl_rigid *r = (wbl_rigid *)wbl_handle(L, arg, WBL_RIGID, &w);
    if (!w || !wb_rigid_valid(w, r->id)) luaL_error(L, "stale rigid body handle (removed or world closed)");
    *id = r->id;
    return w;
}

/* w:rigid{shape = "box" | "sphere" | "capsule", half | radius | a, b, radius, mass = 1, pos,
 * rotation = {w,x,y,z}, vel, angular_velocity, friction = 0, restitution = 0} */
static int w_rigid(lua_State *L)
{
    wb_world *w = wbl_checkworld(L, 1);
    luaL_checktype(L, 2, LUA_TTABLE);
    const char *names[WB_SHAPE_COUNT + 1];
    int shape = wbl_optenum(L, 2, "shape", "shape", wbl_shape_names(names));
    if (shape < 0) return wbl_fielderror(L, 2, "shape", "missing (box, sphere or capsule)");
    const wb_shape_info *in = wb_shape_info_of((wb_shape)shape);
    if (!in->rigid_fields)
        return wbl_fielderror(L, 2, "shape", "must be box, sphere or capsule (a %s is a collider)", in->name);
    const char *keys[24];
    char kbuf[128];
    wbl_shape_keys(keys_first, in->fields, in->rigid_fields, keys_last, keys, kbuf);
    wbl_checkopts(L, 2, keys, false);
    wb_rigid_def d = wb_rigid_default_def((wb_shape)shape);
    wbl_optreal(L, 2, "radius", &d.radius);
    wbl_optvec(L, 2, "half", 3, d.half);
    wbl_optvec(L, 2, "a", 3, d.a);
    wbl_optvec(L, 2, "b", 3, d.b);
    wbl_optreal(L, 2, "mass", &d.mass);
    wbl_optvec(L, 2, "pos", 3, d.pos);
    wbl_optvec(L, 2, "rotation", 4, d.rotation);
    wbl_optvec(L, 2, "vel", 3, d.vel);
    wbl_optvec(L, 2, "angular_velocity", 3, d.angular_velocity);
    wbl_optreal(L, 2, "friction", &d.friction);
    wbl_optreal(L, 2, "restitution", &d.restitution);
    const char *err = wb_rigid_def_check(&d);
    if (err) return luaL_argerror(L, 2, err);
    wb_rigid_id none = { 0, 0 };
    wb_rigid_id *id = push_rigid(L, 1, none); /* first: Lua may run out of memory */
    wb_status st = WB_OK;
    *id = wb_rigid_add(w, &d, &st);
    if (st != WB_OK) return wbl_status_error(L, 2, st, "rigid");
    return 1;
}

#define GETTER(name, n, fn)                  \
    static int name(lua_State *L)            \
    {                                        \
        wb_rigid_id id;                      \
        wb_world *w = checkrigid(L, 1, &id); \
        wb_real v[4];                        \
        fn(w, id, v);                        \
        wbl_pushreals(L, v, n);              \
        return n;                            \
    }
GETTER(rb_position, 3, wb_rigid_position)
GETTER(rb_rotation, 4, wb_rigid_rotation)
GETTER(rb_velocity, 3, wb_rigid_velocity)
GETTER(rb_angular_velocity, 3, wb_rigid_angular_velocity)

#define SETTER(name, fn)                     \
    static int name(lua_State *L)            \
    {                                        \
        wb_rigid_id id;                      \
        wb_world *w = checkrigid(L, 1, &id); \
        wb_real v[3];                        \
        wbl_checkreals(L, 2, 3, v);          \
        fn(w, id, v);                        \
        return 0;                            \
    }
SETTER(rb_set_position, wb_rigid_set_position)
SETTER(rb_set_velocity, wb_rigid_set_velocity)
SETTER(rb_set_angular_velocity, wb_rigid_set_angular_velocity)

static int rb_set_rotation(lua_State *L)
{
    wb_rigid_id id;
    wb_world *w = checkrigid(L, 1, &id);
    wb_real q[4];
    wbl_checkreals(L, 2, 4, q);
    /* the threshold w:rigid uses (wb_rigid_def_check): a denormal quaternion has no direction */
    if (!(fmax(fmax(fabs(q[0]), fabs(q[1])), fmax(fabs(q[2]), fabs(q[3]))) > 1e-12))
        return luaL_argerror(L, 2, "rotation must be a non-zero quaternion (w, x, y, z)");
    wb_rigid_set_rotation(w, id, q);
    return 0;
}

static int rb_mass(lua_State *L)
{
    wb_rigid_id id;
    wb_world *w = checkrigid(L, 1, &id);
    lua_pushnumber(L, wb_rigid_mass(w, id));
    return 1;
}

/* rb:apply_impulse({jx,jy,jz} [, {x,y,z} | {at = {x,y,z}}]): N s, at a world point
 * (default the centre of mass) */
static int rb_apply_impulse(lua_State *L)
{
    static const char *const keys[] = { "at", NULL };
    wb_rigid_id id;
    wb_world *w = checkrigid(L, 1, &id);
    wb_real J[3], at[3];
    wbl_checkvec(L, 2, 3, J);
    bool has_at = false;
    if (!lua_isnoneornil(L, 3)) {
        luaL_checktype(L, 3, LUA_TTABLE);
        if (lua_rawlen(L, 3) == 0) {
            wbl_checkopts(L, 3, keys, false);
            has_at = wbl_optvec(L, 3, "at", 3, at);
        } else {
            wbl_checkvec(L, 3, 3, at);
            has_at = true;
        }
    }
    /* finite J and point can still overflow (J / m, r x J): refuse and change nothing, or
     * every later frame would be undone for the non-finite body */
    wb_real v0[3], om0[3], v1[3], om1[3];
    wb_rigid_velocity(w, id, v0);
    wb_rigid_angular_velocity(w, id, om0);
    wb_rigid_apply_impulse(w, id, J, has_at ? at : NULL);
    wb_rigid_velocity(w, id, v1);
    wb_rigid_angular_velocity(w, id, om1);
    for (int i = 0; i < 3; i++)
        if (!isfinite(v1[i]) || !isfinite(om1[i])) {
            wb_rigid_set_velocity(w, id, v0);
            wb_rigid_set_angular_velocity(w, id, om0);
            return luaL_error(L, "apply_impulse: the impulse is too large (the velocity would not be finite)");
        }
    return 0;
}

static int rb_shape(lua_State *L)
{
    wb_rigid_id id;
    wb_world *w = checkrigid(L, 1, &id);
    wb_rigid_def d;
    wb_rigid_get_def(w, id, &d);
    lua_pushstring(L, wb_shape_info_of(d.shape)->name);
    return 1;
}

/* rb:distance(x,y,z): signed distance from the point to its surface (negative inside) */
static int rb_distance(lua_State *L)
{
    wb_rigid_id id;
    wb_world *w = checkrigid(L, 1, &id);
    wb_real p[3];
    wbl_checkreals(L, 2, 3, p);
    lua_pushnumber(L, wb_rigid_distance(w, id, p));
    return 1;
}

static int rb_remove(lua_State *L)
{
    wb_rigid_id id;
    wb_world *w = checkrigid(L, 1, &id);
    wb_rigid_remove(w, id);
    return 0;
}

static int rb_valid(lua_State *L)
{
    wb_world *w;
    wbl_rigid *r = (wbl_rigid *)wbl_handle(L, 1, WBL_RIGID, &w);
    lua_pushboolean(L, w && wb_rigid_valid(w, r->id));
    return 1;
}

static int rb_world(lua_State *L)
{
    luaL_checkudata(L, 1, WBL_RIGID);
    lua_getiuservalue(L, 1, 1);
    return 1;
}

static int rb_tostring(lua_State *L)
{
    wb_world *w;
    wbl_rigid *r = (wbl_rigid *)wbl_handle(L, 1, WBL_RIGID, &w);
    if (!w || !wb_rigid_valid(w, r->id)) {
        lua_pushfstring(L, "wobble.rigid: %p (stale)", (void *)r);
        return 1;
    }
    wb_rigid_def d;
    wb_rigid_get_def(w, r->id, &d);
    lua_pushfstring(L, "wobble.rigid: %p (%s)", (void *)r, wb_shape_info_of(d.shape)->name);
    return 1;
}

static int rb_eq(lua_State *L) { return wbl_handle_eq(L, WBL_RIGID, sizeof(wb_rigid_id)); }

/* w:rigids(): live bodies in slot order (those of a loaded world too) */
static int w_rigids(lua_State *L)
{
    wb_world *w = wbl_checkworld(L, 1);
    const int32_t n = wb_rigid_count(w);
    /* the ids in one pass (Lua's heap, so the budget sees it): wb_rigid_at per body is n^2 */
    wb_rigid_id *ids = (wb_rigid_id *)lua_newuserdatauv(L, sizeof *ids * (size_t)(n > 0 ? n : 1), 0);
    const int32_t k = wb_rigid_list(w, ids, n);
    lua_createtable(L, k, 0);
    for (int32_t i = 0; i < k; i++) {
        push_rigid(L, 1, ids[i]);
        lua_rawseti(L, -2, i + 1);
    }
    return 1;
}

static const luaL_Reg rigid_methods[] = {
    { "position", rb_position },
    { "rotation", rb_rotation },
    { "velocity", rb_velocity },
    { "angular_velocity", rb_angular_velocity },
    { "mass", rb_mass },
    { "set_position", rb_set_position },
    { "set_rotation", rb_set_rotation },
    { "set_velocity", rb_set_velocity },
    { "set_angular_velocity", rb_set_angular_velocity },
    { "apply_impulse", rb_apply_impulse },
    { "shape", rb_shape },
    { "distance", rb_distance },
    { "remove", rb_remove },
    { "valid", rb_valid },
    { "world", rb_world },
    { NULL, NULL }
};

static const luaL_Reg rigid_meta[] = {
    { "__index", NULL },
    { "__tostring", rb_tostring },
    { "__eq", rb_eq },
    { NULL, NULL }
};

/* w:rigid_contacts() -> { {particle =, body =, normal = {x, y, z}, depth =, force =}, ... }:
 * the particle-rigid contacts that corrected positions in the last substep; force in N,
 * normal out of the body; particle ids from 1 */
static int w_rigid_contacts(lua_State *L)
{
    wb_world *w = wbl_checkworld(L, 1);
    const int32_t n = wb_world_rigid_contact_count(w);
    lua_createtable(L, n, 0);
    for (int32_t i = 0; i < n; i++) {
        const wb_rigid_contact c = wb_world_rigid_contact_at(w, i);
        lua_createtable(L, 0, 5);
        lua_pushinteger(L, (lua_Integer)c.particle + 1);
        lua_setfield(L, -2, "particle");
        push_rigid(L, 1, c.body);
        lua_setfield(L, -2, "body");
        lua_createtable(L, 3, 0);
        for (int k = 0; k < 3; k++) {
            lua_pushnumber(L, c.normal[k]);
            lua_rawseti(L, -2, k + 1);
        }
        lua_setfield(L, -2, "normal");
        lua_pushnumber(L, c.depth);
        lua_setfield(L, -2, "depth");
        lua_pushnumber(L, c.force);
        lua_setfield(L, -2, "force");
        lua_rawseti(L, -2, i + 1);
    }
    return 1;
}

static const luaL_Reg world_methods[] = {
    { "rigid", w_rigid },
    { "rigids", w_rigids },
    { "rigid_contacts", w_rigid_contacts },
    { NULL, NULL }
};

void wbl_open_rigid(lua_State *L)
{
    luaL_newmetatable(L, WBL_RIGID);
    luaL_setfuncs(L, rigid_meta, 0);
    luaL_newlibtable(L, rigid_methods);
    luaL_setfuncs(L, rigid_methods, 0);
    lua_setfield(L, -2, "__index");
    lua_pop(L, 1);
    wbl_add_world_methods(L, world_methods);
}
