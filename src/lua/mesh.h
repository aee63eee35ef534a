/* mesh.h: the mesh, skin and recorder userdata of the Lua binding (mesh.c,
 * skin.c, io.c), shared with the other binding files: the renderer draws a
 * world's skins through wbl_push_world_skins and wbl_toskin. */
#ifndef WB_LUA_MESH_H
#define WB_LUA_MESH_H

#include "util.h"

#define WBL_MESH "wobble.mesh"
#define WBL_SKIN "wobble.skin"
#define WBL_RECORDER "wobble.recorder"

/* registration: the module table must be at the top of the stack */
void wbl_open_mesh(lua_State *L);   /* wobble.mesh{...}, wobble.load_mesh, w:from_mesh */
void wbl_open_skin(lua_State *L);   /* w:skin, w:skins, the skin methods */
void wbl_open_io(lua_State *L);     /* wobble.load, w:load_particles, w:save, exports */

/* ---- memory held outside the Lua heap (mesh.c) ----------------------------------------- */
/* charge `bytes` to the runtime's memory budget (wb_runtime.memory, the account of the Lua
 * heap and the worlds); past its limit, collect garbage once (the finalizers of unreachable
 * meshes, skins and renderers give back what they hold) and try again, then raise a budget
 * error: "<what> needs about N MB, over the memory budget of M MB (--memory-limit MB)" */
void wbl_charge(lua_State *L, size_t bytes, const char *what);
void wbl_release(lua_State *L, size_t bytes);     /* give a charge back */
size_t wbl_mesh_bytes(int64_t nv, int64_t nt);    /* what a wb_mesh of that size holds */

/* ---- meshes (mesh.c) ----------------------------------------------------------------- */
wb_mesh *wbl_checkmesh(lua_State *L, int arg);    /* raises when closed */
/* push a mesh userdata and return where to store the mesh it will own: allocate the
 * userdata before the mesh, so a Lua memory error cannot leak it. Not charged: see
 * wbl_push_mesh_charged */
wb_mesh **wbl_push_mesh_slot(lua_State *L);
/* the same, with a mesh of nv vertices and nt triangles charged to the memory budget
 * first (given back when the mesh is closed or collected); raises a budget error */
wb_mesh **wbl_push_mesh_charged(lua_State *L, int64_t nv, int64_t nt, const char *what);
/* import the file at path (shown as name) through assimp's child under the run's
 * budgets: what is left of the memory budget and the time limit stop it with a budget
 * error whose message starts with `who`; the mesh is pushed (charged) and returned, or
 * NULL with the file's failure in err (a slot holding NULL pushed all the same) */
struct wbio_mesh_opts;
wb_mesh *wbl_import_mesh(lua_State *L, const char *path, const char *name, const struct wbio_mesh_opts *o,
                         const char *who, char *err, size_t n);

/* ---- skins (skin.c) ------------------------------------------------------------------- */
/* the skin at idx and its world (NULL when not a skin or either is closed); vertices read
 * through it are up to date with the world's particles */
wb_skin *wbl_toskin(lua_State *L, int idx, wb_world **w);
wb_skin *wbl_checkskin(lua_State *L, int arg, wb_world **w);
/* push the array of the skins made on the world at world_index (empty when none) */
void wbl_push_world_skins(lua_State *L, int world_index);
/* bind mesh m to ids[0..n) of the world at world_index and push the skin handle; raises */
void wbl_new_skin(lua_State *L, int world_index, const wb_mesh *m, const int32_t *ids, int32_t n,
                  const wb_skin_def *def, int arg);
/* a body table or an array of particle ids at arg: the 0-based ids in a scratch userdata
 * pushed on the stack (collected with it); *n their count */
int32_t *wbl_checkids(lua_State *L, int arg, const wb_world *w, int32_t *n);

#endif
