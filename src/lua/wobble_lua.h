/* wobble_lua.h: what the Lua binding (lua_*.c), the runtime (sandbox, budgets,
 * paths) and the command line (main.c) share. Not part of the public core API. */
#ifndef WOBBLE_LUA_H
#define WOBBLE_LUA_H

#include <lua.h>
#include <lauxlib.h>
#include <stddef.h>
#include <stdint.h>

#include "wobble.h"

/* ---- the module (wobble.c) ---------------------------------------------------- */
int luaopen_wobble(lua_State *L);   /* pushes the `wobble` table; registers every userdata type */

/* ---- the runtime (lua/runtime.c): configuration of the running script ----------------- */
typedef struct wb_runtime {
    const char *scene_dir;     /* folder of the scene script (absolute) */
    const char *out_dir;       /* --out, default "out" (absolute once created) */
    const char *lib_dir;       /* folder holding wobble/<module>.lua */
    int unsafe;                /* --unsafe: no sandbox */
    int quiet;                 /* --quiet: no progress, no summaries */
    int threads;               /* --threads N, 0 when not given */
    int solver;                /* $WOBBLE_SOLVER: 1 + the wb_solver of new worlds that name none, 0 when not set */
    int64_t frame_cap;         /* --frames N: w:run stops after N frames; -1 = none */
    double time_budget;        /* seconds of wall time; 0 = none */
    size_t memory_budget;      /* bytes the Lua heap and the worlds' arrays may use together; 0 = none */
    wb_memory memory;          /* that budget's account: worlds are charged to it (wb_world_def.memory) */
    lua_CFunction open_module; /* opens the `wobble` table (luaopen_wobble): given by the caller, so the
                                  runtime, which the binding uses, does not depend on the binding */
    const char *script;        /* the script's path as given, named when the watchdog ends the run; may be NULL */
    void (*on_read)(void *ud, const char *path);  /* told of each existing file the script reads
                                                     (meshes, configs, modules: --watch); may be NULL */
    void *on_read_ud;
} wb_runtime;

wb_runtime *wb_rt_get(lua_State *L);   /* the runtime of this state (never NULL after wb_rt_open) */


/* the interrupt a world polls once per substep (wb_world_set_interrupt): it answers
 * true once a budget of this state is spent, so a long step cannot outrun
 * --time-limit. *fn is NULL for a state opened without the runtime. */
void wb_rt_interrupt(lua_State *L, int (**fn)(void *), void **ud);

/* raise the budget error that is due (time or memory), if any */
void wb_rt_check_budgets(lua_State *L);

/* raise a budget error: the command line exits with code 3, which tells a sweep's collect
 * (and the user) that a limit, not the scene, ended the run */
int wb_rt_budget_error(lua_State *L, const char *fmt, ...);

/* called by the binding after every simulated frame (w:step, each frame of w:run):
 * checks the time budget (raises a budget error) and runs frame hooks (recording) */
void wb_rt_after_frame(lua_State *L, int world_index);

/* life cycle and helpers for main.c (and embedders) */
lua_State *wb_rt_open(const wb_runtime *cfg); /* standard libraries, sandbox unless cfg->unsafe, budgets,
                                                 `wobble` global + package.loaded, wobble.args = {};
                                                 NULL (message on stderr) on failure */
/* lua_close (finalizers run under both budgets) + free the runtime; WB_RT_LATE_TIME when
 * the time limit ran out while it closed, WB_RT_LATE_MEMORY when a finalizer's allocation
 * was refused by the memory budget (not spent before), else 0 */
enum { WB_RT_LATE_TIME = 1, WB_RT_LATE_MEMORY = 2 };
int wb_rt_close(lua_State *L);
int wb_rt_budget_hit(lua_State *L);           /* 1 once a budget error was raised: exit code 3 */
int wb_rt_msgh(lua_State *L);                 /* lua_pcall message handler: message (any value) + traceback */
void wb_rt_add_frame_hook(lua_State *L, int index); /* wb_rt_after_frame calls the function at index(w) */
/* --time-limit's watchdog: a thread that, a grace period past the limit (5 s or 10% of
 * the limit, the longer), ends a script that never came back to a budget check (a __gc
 * finalizer, one long C call): children killed, the last words on stdout, a message
 * naming cfg->script on stderr, exit code 3. A spent memory budget starts it too (with
 * no time limit), with a grace of 3 s: a finalizer that goes on after its allocations
 * were refused is ended the same way. At the limit itself it signals the opening
 * thread (SIGURG, handled while the state is open) to check every instruction. Paused,
 * it waits (the caller's own cleanup, bounded by its own timeouts, such as finishing a
 * recording); the grace counts again from the end of the pause. */
void wb_rt_pause_watchdog(lua_State *L, int paused);
void wb_rt_set_last_words(lua_State *L, const char *text);  /* stdout text for that end (TAP); NULL: none */
const char *wb_rt_lib_dir(void);              /* the folder holding wobble/test.lua, or NULL */
const char *wb_rt_project_root(void);         /* the source tree (tests/bench, assets), or NULL */

/* ---- progress (progress.c): a bar on a terminal, silent otherwise or with --quiet ---- */
void wb_progress_begin(lua_State *L, const char *what, int64_t total, int quiet);  /* quiet: --quiet */
void wb_progress_update(lua_State *L, int64_t done);
void wb_progress_end(lua_State *L);
void wb_progress_note(lua_State *L, const char *note);   /* shown after every bar's label; NULL clears */
void wb_progress_wrap_print(lua_State *L);  /* the global print takes the bar off its line first */

/* ---- result.json of a run (result.c), what `wobble collect` reads ----------------------- */
typedef struct wbl_run_info {
    const char *out_dir;             /* the run's --out folder (exists) */
    const char *scene;
    const char *const *sets;         /* the --set key=value strings */
    int nsets;
    int exit_code;                   /* -1: the run has started and not ended ("running") */
    double wall_time;                /* seconds */
    const char *error;               /* the message of a failed run, or NULL */
} wbl_run_info;
/* the run's figures from L (frames, the last world's hash and warnings, the values of
 * wobble.result): taken before wb_rt_close, even past a spent budget; L may be NULL */
void *wbl_result_take(lua_State *L);
/* out_dir/result.json from a taken snapshot (consumed; NULL: none) and info; 0 and err */
int wbl_result_write(void *taken, const wbl_run_info *info, char *err, size_t n);

#endif
