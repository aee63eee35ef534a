/* attach.c: w:attach(p, collider [, {compliance}]) and w:grab(p or rb, {x,y,z} [, {compliance, at}]),
 * with their handles (core: attach.c, grab.c). A handle is the core's (index, generation)
 * id plus a reference to the world's userdata (its user value), so the world outlives it;
 * once removed, released or the world closed, its methods raise and valid() is false. */
#include "util.h"

#define WBL_ATTACH "wobble.attach"
#define WBL_GRAB "wobble.grab"

typedef struct wbl_attach { wb_attach_id id; } wbl_attach;
typedef struct wbl_grab { wb_grab_id id; } wbl_grab;

static const char *const keys[] = { "compliance", NULL };
static const char *const grab_keys[] = { "compliance", "at", NULL };

/* the compliance option at arg (absent: 0), as the type's core rule (fault) allows it */
static wb_real read_compliance_keys(lua_State *L, int arg, const char *const *k, wb_fault (*fault)(wb_real))
{
    wb_real a = 0;
    if (wbl_checkopts(L, arg, k, true)) wbl_optreal(L, arg, "compliance", &a);
    const wb_fault f = fault(a);
    wbl_fault_error(L, &f, arg, arg, arg);
    return a;
}

static wb_real read_compliance(lua_State *L, int arg) { return read_compliance_keys(L, arg, keys, wb_attach_def_fault); }

/* ---- attachments ------------------------------------------------------------------ */
static wb_attach_id *push_attach(lua_State *L, int world_index)
{
    world_index = lua_absindex(L, world_index);
    wbl_attach *a = (wbl_attach *)lua_newuserdatauv(L, sizeof *a, 1);
    a->id.index = a->id.gen = 0;
    lua_pushvalue(L, world_index);
    lua_setiuservalue(L, -2, 1);
    luaL_setmetatable(L, WBL_ATTACH);
    return &a->id;
}

static wb_world *checkattach(lua_State *L, int arg, wb_attach_id *id)
{
    wb_world *w;
    wbl_attach *a = (wbl_attach *)wbl_handle(L, arg, WBL_ATTACH, &w);
    if (!w) luaL_error(L, "stale attachment handle (its world was closed)");
    if (!wb_attach_valid(w, a->id)) luaL_error(L, "attachment was removed (or its collider or body was)");
    *id = a->id;
    return w;
}

/* w:attach(p, collider or rigid body [, {compliance = 0}]) -> attachment */
static int w_attach(lua_State *L)
{
    wb_world *w = wbl_checkworld(L, 1);
    const int32_t p = wbl_checkparticle(L, w, 2);
    const int rigid = luaL_testudata(L, 3, WBL_RIGID) != NULL;
    if (!rigid && !luaL_testudata(L, 3, WBL_COLLIDER))
        return luaL_argerror(L, 3, lua_pushfstring(L, "collider or rigid body expected, got %s", luaL_typename(L, 3)));
    const char *what = rigid ? "rigid body" : "collider";
    wb_world *cw;
    const void *h = wbl_handle(L, 3, rigid ? WBL_RIGID : WBL_COLLIDER, &cw);
    const wb_collider_id c = rigid ? (wb_collider_id){ 0, 0 } : *(const wb_collider_id *)h;
    const wb_rigid_id r = rigid ? *(const wb_rigid_id *)h : (wb_rigid_id){ 0, 0 };
    if (cw != w)
        return luaL_argerror(L, 3, lua_pushfstring(L, "the %s belongs to another world (or its world was closed)", what));
    if (rigid ? !wb_rigid_valid(w, r) : !wb_collider_valid(w, c))
        return luaL_argerror(L, 3, lua_pushfstring(L, "the %s was removed", what));
    const wb_real alpha = read_compliance(L, 4);
    wb_attach_id *id = push_attach(L, 1); /* first: Lua may run out of memory */
    wb_status st = WB_OK;
    *id = rigid ? wb_attach_rigid(w, p, r, alpha, &st) : wb_attach_collider(w, p, c, alpha, &st);
    if (st != WB_OK) return wbl_status_error(L, 2, st, "attachment");
    return 1;
}

static int a_remove(lua_State *L)
{
    wb_attach_id id;
    wb_world *w = checkattach(L, 1, &id);
    wb_attach_remove(w, id);
    return 0;
}

/* a:force() -> |F|, Fx, Fy, Fz: newtons on the particle, towards its point (last substep) */
static int a_force(lua_State *L)
{
    wb_attach_id id;
    wb_world *w = checkattach(L, 1, &id);
    wb_real f[3];
    lua_pushnumber(L, wb_attach_force(w, id, f));
    wbl_pushreals(L, f, 3);
    return 4;
}

static int a_particle(lua_State *L)
{
    wb_attach_id id;
    wb_world *w = checkattach(L, 1, &id);
    lua_pushinteger(L, (lua_Integer)wb_attach_particle(w, id) + 1);
    return 1;
}

/* a:point() -> x, y, z: where the collider holds its particle now */
static int a_point(lua_State *L)
{
    wb_attach_id id;
    wb_world *w = checkattach(L, 1, &id);
    wb_real x[3];
    wb_attach_point(w, id, x);
    wbl_pushreals(L, x, 3);
    return 3;
}

static int a_valid(lua_State *L)
{
    wb_world *w;
    wbl_attach *a = (wbl_attach *)wbl_handle(L, 1, WBL_ATTACH, &w);
    lua_pushboolean(L, w && wb_attach_valid(w, a->id));
    return 1;
}

static int a_tostring(lua_State *L)
{
    wb_world *w;
    wbl_attach *a = (wbl_attach *)wbl_handle(L, 1, WBL_ATTACH, &w);
    if (!w || !wb_attach_valid(w, a->id)) lua_pushfstring(L, "wobble.attach: %p (stale)", (void *)a);
    else lua_pushfstring(L, "wobble.attach: %p (particle %d)", (void *)a, (int)wb_attach_particle(w, a->id) + 1);
    return 1;
}

static int a_eq(lua_State *L) { return wbl_handle_eq(L, WBL_ATTACH, sizeof(wb_attach_id)); }

/* w:attachments() -> the live attachments as handles, in slot order */
static int w_attachments(lua_State *L)
{
    wb_world *w = wbl_checkworld(L, 1);
    const int32_t n = wb_attach_count(w);
    /* the ids in one pass (a scratch userdata: Lua's budget), not wb_attach_at each */
    wb_attach_id *ids = (wb_attach_id *)lua_newuserdatauv(L, sizeof *ids * (size_t)(n > 0 ? n : 1), 0);
    wb_attach_list(w, ids, n);
    lua_createtable(L, n, 0);
    for (int32_t i = 0; i < n; i++) {
        *push_attach(L, 1) = ids[i];
        lua_rawseti(L, -2, i + 1);
    }
    return 1;
}

/* ---- grabs ------------------------------------------------------------------------- */
static wb_grab_id *push_grab(lua_State *L, int world_index)
{
    world_index = lua_absindex(L, world_index);
    wbl_grab *g = (wbl_grab *)lua_newuserdatauv(L, sizeof *g, 1);
    g->id.index = g->id.gen = 0;
    lua_pushvalue(L, world_index);
    lua_setiuservalue(L, -2, 1);
    luaL_setmetatable(L, WBL_GRAB);
    return &g->id;
}

static wb_world *checkgrab(lua_State *L, int arg, wb_grab_id *id)
{
    wb_world *w;
    wbl_grab *g = (wbl_grab *)wbl_handle(L, arg, WBL_GRAB, &w);
    if (!w) luaL_error(L, "stale grab handle (its world was closed)");
    if (!wb_grab_valid(w, g->id)) luaL_error(L, "grab was released (or its rigid body removed)");
    *id = g->id;
    return w;
}

/* w:grab(p, {x,y,z} [, {compliance = 0}]) or w:grab(rb, {x,y,z} [, {compliance = 0,
 * at = {0,0,0}}]) -> grab; `at` is the body's point in its own frame */
static int w_grab(lua_State *L)
{
    wb_world *w = wbl_checkworld(L, 1);
    if (luaL_testudata(L, 2, WBL_RIGID)) {
        wb_world *rw;
        const wb_rigid_id r = *(const wb_rigid_id *)wbl_handle(L, 2, WBL_RIGID, &rw);
        if (rw != w) return luaL_argerror(L, 2, "the rigid body belongs to another world (or its world was closed)");
        if (!wb_rigid_valid(w, r)) return luaL_argerror(L, 2, "the rigid body was removed");
        wb_real t[3], at[3] = { 0, 0, 0 };
        wbl_checkvec(L, 3, 3, t);
        const wb_real alpha = read_compliance_keys(L, 4, grab_keys, wb_grab_def_fault);
        if (!lua_isnoneornil(L, 4)) wbl_optvec(L, 4, "at", 3, at);
        wb_grab_id *id = push_grab(L, 1);
        wb_status st = WB_OK;
        *id = wb_grab_rigid(w, r, at, t, alpha, &st);
        if (st != WB_OK) return wbl_status_error(L, 2, st, "grab");
        return 1;
    }
    if (lua_type(L, 2) != LUA_TNUMBER) return luaL_typeerror(L, 2, "particle id or rigid body");
    const int32_t p = wbl_checkparticle(L, w, 2);
    wb_real t[3];
    wbl_checkvec(L, 3, 3, t);
    const wb_real alpha = read_compliance_keys(L, 4, grab_keys, wb_grab_def_fault);
    if (lua_istable(L, 4) && lua_getfield(L, 4, "at") != LUA_TNIL)
        return wbl_fielderror(L, 4, "at", "is for a rigid body's grab (a particle is grabbed where it is)");
    lua_settop(L, 4);
    wb_grab_id *id = push_grab(L, 1);
    wb_status st = WB_OK;
    *id = wb_grab_add(w, p, t, alpha, &st);
    if (st != WB_OK) return wbl_status_error(L, 2, st, "grab");
    return 1;
}

/* g:move(x, y, z): the target, reached over the next step */
static int g_move(lua_State *L)
{
    wb_grab_id id;
    wb_world *w = checkgrab(L, 1, &id);
    wb_real t[3];
    wbl_checkreals(L, 2, 3, t);
    wb_grab_move(w, id, t);
    return 0;
}

static int g_release(lua_State *L)
{
    wb_grab_id id;
    wb_world *w = checkgrab(L, 1, &id);
    wb_grab_release(w, id);
    return 0;
}

static int g_force(lua_State *L)
{
    wb_grab_id id;
    wb_world *w = checkgrab(L, 1, &id);
    wb_real f[3];
    lua_pushnumber(L, wb_grab_force(w, id, f));
    wbl_pushreals(L, f, 3);
    return 4;
}

static int g_target(lua_State *L)
{
    wb_grab_id id;
    wb_world *w = checkgrab(L, 1, &id);
    wb_real t[3];
    wb_grab_target(w, id, t);
    wbl_pushreals(L, t, 3);
    return 3;
}

/* g:particle() -> the particle's id, nil for a rigid body's grab */
static int g_particle(lua_State *L)
{
    wb_grab_id id;
    wb_world *w = checkgrab(L, 1, &id);
    const int32_t p = wb_grab_particle(w, id);
    if (p < 0) lua_pushnil(L);
    else lua_pushinteger(L, (lua_Integer)p + 1);
    return 1;
}

/* g:body() -> the rigid body grabbed (a new handle to it), nil for a particle's grab */
static int g_body(lua_State *L)
{
    wb_grab_id id;
    wb_world *w = checkgrab(L, 1, &id);
    const wb_rigid_id r = wb_grab_body(w, id);
    if (r.index == 0) { lua_pushnil(L); return 1; }
    wb_rigid_id *h = (wb_rigid_id *)lua_newuserdatauv(L, sizeof *h, 1);
    *h = r;
    lua_getiuservalue(L, 1, 1); /* the world */
    lua_setiuservalue(L, -2, 1);
    luaL_setmetatable(L, WBL_RIGID);
    return 1;
}

/* g:point() -> x, y, z: the grabbed point now (the particle, or the body's point) */
static int g_point(lua_State *L)
{
    wb_grab_id id;
    wb_world *w = checkgrab(L, 1, &id);
    wb_real x[3];
    wb_grab_point(w, id, x);
    wbl_pushreals(L, x, 3);
    return 3;
}

static int g_valid(lua_State *L)
{
    wb_world *w;
    wbl_grab *g = (wbl_grab *)wbl_handle(L, 1, WBL_GRAB, &w);
    lua_pushboolean(L, w && wb_grab_valid(w, g->id));
    return 1;
}

static int g_tostring(lua_State *L)
{
    wb_world *w;
    wbl_grab *g = (wbl_grab *)wbl_handle(L, 1, WBL_GRAB, &w);
    if (!w || !wb_grab_valid(w, g->id)) lua_pushfstring(L, "wobble.grab: %p (released)", (void *)g);
    else if (wb_grab_particle(w, g->id) < 0)
        lua_pushfstring(L, "wobble.grab: %p (rigid body %d)", (void *)g, (int)wb_grab_body(w, g->id).index);
    else lua_pushfstring(L, "wobble.grab: %p (particle %d)", (void *)g, (int)wb_grab_particle(w, g->id) + 1);
    return 1;
}

static int g_eq(lua_State *L) { return wbl_handle_eq(L, WBL_GRAB, sizeof(wb_grab_id)); }

/* w:grabs() -> the live grabs as handles, in slot order */
static int w_grabs(lua_State *L)
{
    wb_world *w = wbl_checkworld(L, 1);
    const int32_t n = wb_grab_count(w);
    wb_grab_id *ids = (wb_grab_id *)lua_newuserdatauv(L, sizeof *ids * (size_t)(n > 0 ? n : 1), 0);
    wb_grab_list(w, ids, n);
    lua_createtable(L, n, 0);
    for (int32_t i = 0; i < n; i++) {
        *push_grab(L, 1) = ids[i];
        lua_rawseti(L, -2, i + 1);
    }
    return 1;
}

/* ---- registration ------------------------------------------------------------------ */
static const luaL_Reg attach_methods[] = {
    { "remove", a_remove }, { "force", a_force }, { "particle", a_particle }, { "point", a_point },
    { "valid", a_valid }, { NULL, NULL }
};
static const luaL_Reg attach_meta[] = { { "__index", NULL }, { "__tostring", a_tostring }, { "__eq", a_eq }, { NULL, NULL } };
static const luaL_Reg grab_methods[] = {
    { "move", g_move }, { "release", g_release }, { "force", g_force }, { "target", g_target },
    { "particle", g_particle }, { "body", g_body }, { "point", g_point }, { "valid", g_valid }, { NULL, NULL }
};
static const luaL_Reg grab_meta[] = { { "__index", NULL }, { "__tostring", g_tostring }, { "__eq", g_eq }, { NULL, NULL } };
static const luaL_Reg world_methods[] = {
    { "attach", w_attach }, { "attachments", w_attachments }, { "grab", w_grab }, { "grabs", w_grabs }, { NULL, NULL }
};

static void open_type(lua_State *L, const char *name, const luaL_Reg *meta, const luaL_Reg *methods)
{
    luaL_newmetatable(L, name);
    luaL_setfuncs(L, meta, 0);
    lua_newtable(L);
    luaL_setfuncs(L, methods, 0);
    lua_setfield(L, -2, "__index");
    lua_pop(L, 1);
}

void wbl_open_attach(lua_State *L)
{
    open_type(L, WBL_ATTACH, attach_meta, attach_methods);
    open_type(L, WBL_GRAB, grab_meta, grab_methods);
    wbl_add_world_methods(L, world_methods);
}
