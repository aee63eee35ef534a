/* util.h: helpers shared by the Lua binding files (lua_*.c).
 *
 * Argument checking follows one rule: check everything before changing anything,
 * and raise `bad argument #n to 'f' (...)` through luaL_argerror so the message
 * carries the script's file:line. Numbers are strict (a string "1" is refused, as
 * is NaN or an infinity); option tables are checked for unknown keys. */
#ifndef WB_LUA_UTIL_H
#define WB_LUA_UTIL_H

#include <stdbool.h>
#include <stdint.h>

#include "wobble_lua.h"

/* registry names of the userdata (and body table) metatables */
#define WBL_WORLD "wobble.world"
#define WBL_DISTANCE "wobble.distance"
#define WBL_COLLIDER "wobble.collider"
#define WBL_BODY "wobble.body"
#define WBL_SHAPE_MATCH "wobble.shape_match"
#define WBL_PRESSURE "wobble.pressure"
#define WBL_RIGID "wobble.rigid"

/* the world userdata: w is NULL once closed, so __gc/__close can run twice */
typedef struct wbl_world {
    wb_world *w;
    int warned;          /* the first numerical warning was printed */
} wbl_world;

/* ---- registration (one per binding file; luaopen_wobble calls them in order) ---- */
void wbl_open_world(lua_State *L);     /* world.c: must run first */
void wbl_open_distance(lua_State *L);  /* distance.c */
void wbl_open_bend(lua_State *L);      /* bend.c */
void wbl_open_collider(lua_State *L);  /* collider.c */
void wbl_open_body(lua_State *L);      /* body.c: builders + body metatable */
void wbl_open_volume(lua_State *L);    /* volume.c: volume constraints, tet bodies */
void wbl_open_shape_match(lua_State *L); /* shape_match.c: w:shape_match and its handle */
void wbl_open_pressure(lua_State *L);  /* pressure.c: w:pressure and its handle */
void wbl_open_attach(lua_State *L);    /* attach.c: w:attach, w:grab and their handles */
void wbl_open_rigid(lua_State *L);     /* rigid.c: w:rigid and its handle */
void wbl_open_tether(lua_State *L);    /* tether.c: w:tether, body:tether_to_pins (after body.c) */
int wbl_world_new(lua_State *L);       /* wobble.world{...} */
/* add methods to the world's method table (used by the per-type files) */
void wbl_add_world_methods(lua_State *L, const luaL_Reg *l);

/* ---- the world --------------------------------------------------------------- */
wbl_world *wbl_checkworld_ud(lua_State *L, int arg);  /* open or closed */
wb_world *wbl_checkworld(lua_State *L, int arg);      /* raises when closed */
/* handles (constraints, colliders): an id userdata whose user value is its world's
 * userdata. wbl_handle checks the type and gives the world (NULL once closed);
 * wbl_handle_eq is __eq for a handle type whose ids are `size` bytes. */
void *wbl_handle(lua_State *L, int arg, const char *tname, wb_world **w);
int wbl_handle_eq(lua_State *L, const char *tname, size_t size);

/* one frame of w, stoppable by the runtime's budgets (a spent budget raises its
 * error; the frame is then undone) */
void wbl_step(lua_State *L, wb_world *w);
/* after each frame: report the first warning once, then the runtime's frame hook */
void wbl_after_frame(lua_State *L, int world_index);

/* ---- numbers, ids, vectors ----------------------------------------------------- */
const char *wbl_numstr(char *buf, size_t n, double x);       /* "nan", "inf", "1.5" */
wb_real wbl_checkreal(lua_State *L, int arg);                /* a finite number */
lua_Integer wbl_checkint(lua_State *L, int arg);             /* an integral number */
int32_t wbl_checkparticle(lua_State *L, const wb_world *w, int arg); /* Lua id -> 0-based */
int32_t wbl_particle_id(lua_State *L, const wb_world *w, int arg, lua_Integer id); /* same, checked value */
void wbl_checkvec(lua_State *L, int arg, int n, wb_real *out); /* a table of exactly n finite numbers */
void wbl_checkreals(lua_State *L, int arg, int n, wb_real *out); /* n finite numbers at arg.. */
void wbl_pushreals(lua_State *L, const wb_real *v, int n);

/* ---- option tables (the table at `arg`) --------------------------------------- */
/* arg must be a table (or, when optional, nil/none: returns false); every key must be
 * a string in the NULL-terminated `keys`, else the error names it and lists the keys */
bool wbl_checkopts(lua_State *L, int arg, const char *const keys[], bool optional);
/* fields: return false when absent (nil), else check and store */
bool wbl_optreal(lua_State *L, int arg, const char *key, wb_real *out);
bool wbl_optinteger(lua_State *L, int arg, const char *key, lua_Integer lo, lua_Integer hi, lua_Integer *out);
bool wbl_optint(lua_State *L, int arg, const char *key, lua_Integer lo, lua_Integer hi, int *out);
bool wbl_optbool(lua_State *L, int arg, const char *key, bool *out);
bool wbl_optvec(lua_State *L, int arg, const char *key, int n, wb_real *out);
bool wbl_optivec(lua_State *L, int arg, const char *key, int n, lua_Integer lo, lua_Integer hi, int *out);
/* a string among `names` (NULL-terminated); returns its index, or -1 when absent */
int wbl_optenum(lua_State *L, int arg, const char *key, const char *what, const char *const names[]);
int wbl_enum_index(lua_State *L, int arg, const char *s, const char *what, const char *const names[]);
int wbl_fielderror(lua_State *L, int arg, const char *key, const char *fmt, ...);
/* the shapes' names in wb_shape's order, NULL-terminated (wb_shape_info), into names, for
 * wbl_optenum; returns names */
const char *const *wbl_shape_names(const char *names[WB_SHAPE_COUNT + 1]);
/* the keys a shape takes: those of `first` (NULL-terminated), the words of fields (a
 * wb_shape_info list) that `only` also has (only NULL: every one), those of `last`; into
 * keys (room for 24 with the NULL), the words copied into buf (128 bytes) */
void wbl_shape_keys(const char *const first[], const char *fields, const char *only, const char *const last[],
                    const char *keys[24], char buf[128]);

/* distance constraint options shared by w:distance and the builders (rest excluded) */
extern const char *const wbl_link_keys[];   /* compliance, damping, yield, creep, break_strain */
void wbl_read_link(lua_State *L, int arg, wb_distance_def *d);

/* what a type's check found (wb_fault), raised as the script wrote it: an option's as
 * "field 'key': why" at opts, a particle's at its argument (first + corner; at together
 * when the particles are at fault together). Returns only when f has no fault */
int wbl_fault_error(lua_State *L, const wb_fault *f, int first, int together, int opts);

/* a failed core call: WB_ERR_ARG / WB_ERR_LIMIT -> argument error, NOMEM -> budget error */
int wbl_status_error(lua_State *L, int arg, wb_status st, const char *what);

/* ---- handles and bodies ------------------------------------------------------------ */
/* push a handle of the world at world_index; returns where its id is kept, so a
 * caller can push the handle before creating the object (no leak on memory error) */
wb_distance_id *wbl_push_distance(lua_State *L, int world_index, wb_distance_id id);
wb_collider_id *wbl_push_collider(lua_State *L, int world_index, wb_collider_id id);
/* push a body table {particles, first, count, world, constraint_count}; or in two
 * halves around the core's builder: begin allocates for `count` particles (pushes 2) */
void wbl_push_body(lua_State *L, int world_index, wb_body b, int32_t constraints);
void wbl_body_begin(lua_State *L, int64_t count);
void wbl_body_end(lua_State *L, int world_index, wb_body b, int32_t constraints);
/* tet bodies (volume.c), for w:load_tets and w:from_mesh{tets = true} (mesh.c): tetgen's
 * arrays owned by a scratch userdata pushed on the stack; a tet body's options at arg
 * (returns whether the radius is the default); the body built and pushed (raises) */
struct wbio_tets;
struct wbl_contact_opts;
struct wbio_tets *wbl_push_tets(lua_State *L);
bool wbl_read_tet_body(lua_State *L, int arg, wb_tet_body_def *d);
/* young and poisson of a tet solid's options (util.c); raises */
void wbl_read_neo(lua_State *L, int arg, wb_real *young, wb_real *poisson);
int wbl_push_tet_body(lua_State *L, wb_world *w, const struct wbio_tets *t, const int32_t *tri, int32_t ntri,
                      const wb_tet_body_def *d, bool auto_radius, const struct wbl_contact_opts *co, const char *what);
/* a preset's mass (rho x the tets' volume) and dashpots (eta x the mean tet edge) into d,
 * unless the options at arg give mass or damping (m may be NULL) */
void wbl_tet_preset(lua_State *L, int arg, const wb_material *m, const struct wbio_tets *t, wb_tet_body_def *d);
/* a builder's contact options (collide = true, self_collide = false, friction = 0) from
 * the options table at arg, and their application to the body it made */
typedef struct wbl_contact_opts { bool collide, self_collide; wb_real friction; } wbl_contact_opts;
void wbl_read_contact_opts(lua_State *L, int arg, wbl_contact_opts *o);
void wbl_apply_contact_opts(wb_world *w, wb_body b, const wbl_contact_opts *o);
/* the builders' default radius: half the spacing of the body's particles, so that
 * neighbouring particles' contact spheres touch and other bodies cannot pass between */
void wbl_default_radius(wb_world *w, wb_body b);
/* the preset's friction into co unless the options at arg give one (m may be NULL) */
void wbl_material_friction(lua_State *L, int arg, const wb_material *m, wbl_contact_opts *co);

/* material presets (material.c): the one named by field 'material' at arg (NULL when
 * absent; raises for an unknown name), and wobble.materials into the table on top */
const wb_material *wbl_opt_material(lua_State *L, int arg);
void wbl_open_materials(lua_State *L);
bool wbl_given(lua_State *L, int arg, const char *key);       /* field key of the table at arg is not nil */

/* a PNG of rgb written whole to path (a temporary renamed into place, a link at path
 * replaced, not followed); false with "cannot write path: reason" */
bool wbl_write_png(const char *path, const uint8_t *rgb, int w, int h, char *err, size_t n);

/* ---- what a run reports (result.c) ---------------------------------------------- */
void wbl_open_result(lua_State *L);   /* wobble.result, into the module table on top */
void wbl_result_after_frame(lua_State *L, int world_index);   /* counts the frame, keeps the world */
void wbl_result_world_closing(lua_State *L, const wbl_world *ud);  /* the last world's figures, kept */

#endif
