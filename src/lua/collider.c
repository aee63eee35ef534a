/* collider.c: kinematic colliders: w:collider{shape = ...} and the collider
 * handle (id + generation, the world's userdata as its user value). */
#include "mesh.h"
#include "util.h"

typedef struct wbl_collider { wb_collider_id id; } wbl_collider;

/* the keys every shape takes around its own fields (wb_shape_info): a key of another shape
 * is an error, not ignored */
static const char *const keys_first[] = { "shape", NULL };
static const char *const keys_last[] = { "friction", "restitution", NULL };

wb_collider_id *wbl_push_collider(lua_State *L, int world_index, wb_collider_id id)
{
    world_index = lua_absindex(L, world_index);
    wbl_collider *c = (wbl_collider *)lua_newuserdatauv(L, sizeof *c, 1);
    c->id = id;
    lua_pushvalue(L, world_index);
    lua_setiuservalue(L, -2, 1);
    luaL_setmetatable(L, WBL_COLLIDER);
    return &c->id;
}

static wb_world *checkcollider(lua_State *L, int arg, wb_collider_id *id)
{
    wb_world *w;
    wbl_collider *c = (wbl_collider *)wbl_handle(L, arg, WBL_COLLIDER, &w);
    if (!w || !wb_collider_valid(w, c->id)) luaL_error(L, "stale collider handle (removed or world closed)");
    *id = c->id;
    return w;
}

static int w_collider(lua_State *L)
{
    wb_world *w = wbl_checkworld(L, 1);
    luaL_checktype(L, 2, LUA_TTABLE);
    const char *names[WB_SHAPE_COUNT + 1];
    int shape = wbl_optenum(L, 2, "shape", "shape", wbl_shape_names(names));
    if (shape < 0) return wbl_fielderror(L, 2, "shape", "missing (plane, sphere, box, capsule or mesh)");
    const char *keys[24];
    char kbuf[128];
    wbl_shape_keys(keys_first, wb_shape_info_of((wb_shape)shape)->fields, NULL, keys_last, keys, kbuf);
    wbl_checkopts(L, 2, keys, false);
    wb_collider_def d = wb_collider_default_def((wb_shape)shape);
    wbl_optvec(L, 2, "normal", 3, d.normal);
    wbl_optreal(L, 2, "offset", &d.offset);
    wbl_optvec(L, 2, "center", 3, d.center);
    wbl_optreal(L, 2, "radius", &d.radius);
    wbl_optvec(L, 2, "half", 3, d.half);
    wbl_optvec(L, 2, "rotation", 4, d.rotation);
    wbl_optvec(L, 2, "a", 3, d.a);
    wbl_optvec(L, 2, "b", 3, d.b);
    wbl_optreal(L, 2, "friction", &d.friction);
    wbl_optreal(L, 2, "restitution", &d.restitution);
    if (wb_shape_takes(wb_shape_info_of((wb_shape)shape)->fields, "mesh")) {
        wbl_optreal(L, 2, "scale", &d.scale);
        lua_getfield(L, 2, "mesh");
        if (lua_isnil(L, -1)) return wbl_fielderror(L, 2, "mesh", "missing (a mesh from wobble.load_mesh or wobble.mesh)");
        if (!luaL_testudata(L, -1, WBL_MESH))
            return wbl_fielderror(L, 2, "mesh", "mesh expected, got %s", luaL_typename(L, -1));
        d.mesh = wbl_checkmesh(L, -1);
        if (d.mesh->nt <= 0) return wbl_fielderror(L, 2, "mesh", "is empty (no triangles)");
        lua_pop(L, 1); /* the table at 2 still holds the mesh: it lives through the add */
    }
    const char *err = wb_collider_def_check(&d);
    if (err) return luaL_argerror(L, 2, err);
    wb_collider_id none = { 0, 0 };
    wb_collider_id *id = wbl_push_collider(L, 1, none); /* first: Lua may run out of memory */
    wb_status st = WB_OK;
    *id = wb_collider_add(w, &d, &st);
    if (st != WB_OK) return wbl_status_error(L, 2, st, "collider");
    return 1;
}

static int col_set_position(lua_State *L)
{
    wb_collider_id id;
    wb_world *w = checkcollider(L, 1, &id);
    wb_real p[3];
    wbl_checkreals(L, 2, 3, p);
    wb_collider_set_position(w, id, p);
    return 0;
}

static int col_set_rotation(lua_State *L)
{
    wb_collider_id id;
    wb_world *w = checkcollider(L, 1, &id);
    wb_real q[4];
    wbl_checkreals(L, 2, 4, q);
    if (q[0] == 0 && q[1] == 0 && q[2] == 0 && q[3] == 0)
        return luaL_argerror(L, 2, "rotation must be a non-zero quaternion (w, x, y, z)");
    wb_collider_set_rotation(w, id, q);
    return 0;
}

static int col_set_velocity(lua_State *L)
{
    wb_collider_id id;
    wb_world *w = checkcollider(L, 1, &id);
    wb_real v[3];
    wbl_checkreals(L, 2, 3, v);
    wb_collider_set_velocity(w, id, v);
    return 0;
}

static int col_set_angular_velocity(lua_State *L)
{
    wb_collider_id id;
    wb_world *w = checkcollider(L, 1, &id);
    wb_real v[3];
    wbl_checkreals(L, 2, 3, v);
    wb_collider_set_angular_velocity(w, id, v);
    return 0;
}

static int col_position(lua_State *L)
{
    wb_collider_id id;
    wb_world *w = checkcollider(L, 1, &id);
    wb_real p[3];
    wb_collider_position(w, id, p);
    wbl_pushreals(L, p, 3);
    return 3;
}

static int col_rotation(lua_State *L)
{
    wb_collider_id id;
    wb_world *w = checkcollider(L, 1, &id);
    wb_real q[4];
    wb_collider_rotation(w, id, q);
    wbl_pushreals(L, q, 4);
    return 4;
}

static int col_velocity(lua_State *L)
{
    wb_collider_id id;
    wb_world *w = checkcollider(L, 1, &id);
    wb_real v[3];
    wb_collider_velocity(w, id, v);
    wbl_pushreals(L, v, 3);
    return 3;
}

static int col_shape(lua_State *L)
{
    wb_collider_id id;
    wb_world *w = checkcollider(L, 1, &id);
    wb_shape s = wb_collider_shape(w, id);
    lua_pushstring(L, wb_shape_info_of(s) ? wb_shape_info_of(s)->name : "?");
    return 1;
}

static int col_distance(lua_State *L)
{
    wb_collider_id id;
    wb_world *w = checkcollider(L, 1, &id);
    wb_real p[3];
    wbl_checkreals(L, 2, 3, p);
    lua_pushnumber(L, wb_collider_distance(w, id, p));
    return 1;
}

/* col:material() -> friction, restitution (as created) */
static int col_material(lua_State *L)
{
    wb_collider_id id;
    wb_world *w = checkcollider(L, 1, &id);
    wb_collider_def d;
    wb_collider_get_def(w, id, &d);
    lua_pushnumber(L, d.friction);
    lua_pushnumber(L, d.restitution);
    return 2;
}

static int col_remove(lua_State *L)
{
    wb_collider_id id;
    wb_world *w = checkcollider(L, 1, &id);
    wb_collider_remove(w, id);
    return 0;
}

static int col_valid(lua_State *L)
{
    wb_world *w;
    wbl_collider *c = (wbl_collider *)wbl_handle(L, 1, WBL_COLLIDER, &w);
    lua_pushboolean(L, w && wb_collider_valid(w, c->id));
    return 1;
}

static int col_world(lua_State *L)
{
    luaL_checkudata(L, 1, WBL_COLLIDER);
    lua_getiuservalue(L, 1, 1);
    return 1;
}

static int col_tostring(lua_State *L)
{
    wb_world *w;
    wbl_collider *c = (wbl_collider *)wbl_handle(L, 1, WBL_COLLIDER, &w);
    if (!w || !wb_collider_valid(w, c->id)) {
        lua_pushfstring(L, "wobble.collider: %p (stale)", (void *)c);
        return 1;
    }
    wb_shape s = wb_collider_shape(w, c->id);
    lua_pushfstring(L, "wobble.collider: %p (%s)", (void *)c,
                    wb_shape_info_of(s) ? wb_shape_info_of(s)->name : "?");
    return 1;
}

static int col_eq(lua_State *L)
{
    return wbl_handle_eq(L, WBL_COLLIDER, sizeof(wb_collider_id));
}

static const luaL_Reg collider_methods[] = {
    { "set_position", col_set_position },
    { "set_rotation", col_set_rotation },
    { "set_velocity", col_set_velocity },
    { "set_angular_velocity", col_set_angular_velocity },
    { "position", col_position },
    { "rotation", col_rotation },
    { "velocity", col_velocity },
    { "shape", col_shape },
    { "distance", col_distance },
    { "material", col_material },
    { "remove", col_remove },
    { "valid", col_valid },
    { "world", col_world },
    { NULL, NULL }
};

static const luaL_Reg collider_meta[] = {
    { "__index", NULL },
    { "__tostring", col_tostring },
    { "__eq", col_eq },
    { NULL, NULL }
};

static const luaL_Reg world_methods[] = {
    { "collider", w_collider },
    { NULL, NULL }
};

void wbl_open_collider(lua_State *L)
{
    luaL_newmetatable(L, WBL_COLLIDER);
    luaL_setfuncs(L, collider_meta, 0);
    luaL_newlibtable(L, collider_methods);
    luaL_setfuncs(L, collider_methods, 0);
    lua_setfield(L, -2, "__index");
    lua_pop(L, 1);
    wbl_add_world_methods(L, world_methods);
}
