/* wobble.c: the `wobble` module: registers every userdata type and pushes the
 * module table. The runtime preloads it as the global `wobble` (and adds its own
 * fields, such as wobble.args). */
#include "mesh.h"
#include "util.h"
#include "render/render.h"

static const luaL_Reg wobble_funcs[] = {
    { "world", wbl_world_new },
    { NULL, NULL }
};

int luaopen_wobble(lua_State *L)
{
    /* the world first: the other files add their methods to its method table */
    wbl_open_world(L);
    wbl_open_distance(L);
    wbl_open_bend(L);
    wbl_open_collider(L);
    wbl_open_body(L);
    wbl_open_volume(L);
    wbl_open_shape_match(L);
    wbl_open_pressure(L);
    wbl_open_attach(L);
    wbl_open_rigid(L);
    wbl_open_tether(L);

    luaL_newlib(L, wobble_funcs);
    wbl_open_mesh(L);       /* wobble.mesh, wobble.load_mesh; w:from_mesh */
    wbl_open_skin(L);       /* w:skin, w:skins and the skin handle */
    wbl_open_io(L);         /* wobble.load; w:load_particles, w:save, recorders (after skin) */
    wbl_open_renderer(L);   /* wobble.renderer, wobble.probe, wobble.read_png; w:run's plot */
    wbl_open_result(L);     /* wobble.result */
    wbl_open_materials(L);  /* wobble.materials */
    lua_pushliteral(L, WB_VERSION);
    lua_setfield(L, -2, "version");
    /* the core's hard limits, so scripts can size things without trial and error */
    lua_createtable(L, 0, 5);
    lua_pushinteger(L, WB_MAX_PARTICLES);
    lua_setfield(L, -2, "particles");
    lua_pushinteger(L, WB_MAX_CONSTRAINTS);
    lua_setfield(L, -2, "constraints");
    lua_pushinteger(L, WB_MAX_COLLIDERS);
    lua_setfield(L, -2, "colliders");
    lua_pushinteger(L, WB_MAX_SUBSTEPS);
    lua_setfield(L, -2, "substeps");
    lua_pushinteger(L, WB_MAX_THREADS);
    lua_setfield(L, -2, "threads");
    lua_setfield(L, -2, "limits");
    return 1;
}
