/* runtime.c: what runs around a scene script. The sandbox of DESIGN §4 (no
 * process control, no bytecode, no debug library, file access through path rules),
 * the budgets (memory through the allocator, wall time through a count hook and
 * after every frame) and the discovery of the Lua library folder. */
#include "wobble_lua.h"
#include "sandbox.h"

#include <lualib.h>

#include <errno.h>
#include <limits.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <time.h>
#include <unistd.h>

#define HOOK_COUNT (1 << 20)          /* instructions between two budget checks */
#define MEM_SLACK ((size_t)64 << 20)  /* granted past the memory limit so the error can be reported */

typedef struct rt_state {
    wb_runtime pub;                   /* first: what wb_rt_get hands out */
    wb_sandbox sb;                    /* the file rules and the folders */
    int mem_refused;                  /* the last growing allocation was refused */
    int mem_over;                     /* refused twice in a row: the budget is exhausted */
    int budget_hit;                   /* a budget error was raised; it is raised again at every step */
    double t0;                        /* wall clock at wb_rt_open */
    char budget_msg[256];
} rt_state;

static const char frame_hooks_key = 0;  /* registry: array of frame hooks */

/* ---- state ------------------------------------------------------------------------- */

static void *rt_alloc(void *ud, void *ptr, size_t osize, size_t nsize);

/* the runtime is the allocator's userdata: found without touching the stack (hooks) */
static rt_state *rt_from(lua_State *L) {
    void *ud = NULL;
    return lua_getallocf(L, &ud) == rt_alloc ? ud : NULL;
}

wb_runtime *wb_rt_get(lua_State *L) {
    /* a state opened without the runtime (embedding, `require "wobble"` from lua) gets
     * permissive defaults so the binding never has to test for NULL */
    static wb_runtime plain = { ".", "out", NULL, 1, 0, 0, -1, 0, 0, { 0, 0 }, NULL };
    rt_state *rt = rt_from(L);
    return rt ? &rt->pub : &plain;
}

static double now(void) {
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + ts.tv_nsec * 1e-9;
}

/* ---- budgets ------------------------------------------------------------------------- */

static void *rt_alloc(void *ud, void *ptr, size_t osize, size_t nsize) {
    rt_state *rt = ud;
    size_t old = ptr ? osize : 0;  /* for a new block osize is a type tag */
    if (nsize == 0) {
        free(ptr);
        rt->pub.memory.used -= old;
        return NULL;
    }
    size_t limit = rt->pub.memory_budget;
    if (limit && nsize > old) {
        if (rt->mem_over) limit = limit > SIZE_MAX - MEM_SLACK ? SIZE_MAX : limit + MEM_SLACK;
        size_t grow = nsize - old;
        /* one account for the Lua heap and every world's arrays */
        if (grow > limit || rt->pub.memory.used > limit - grow) {
            /* Lua collects garbage and asks again once: only the second refusal is final */
            if (rt->mem_refused) rt->mem_over = 1;
            rt->mem_refused = 1;
            return NULL;
        }
    }
    void *p = realloc(ptr, nsize);
    if (!p) return NULL;
    rt->pub.memory.used = rt->pub.memory.used - old + nsize;
    if (nsize > old) rt->mem_refused = 0;
    return p;
}

static void rt_hook(lua_State *L, lua_Debug *ar);

int wb_rt_budget_error(lua_State *L, const char *fmt, ...) {
    rt_state *rt = rt_from(L);
    char msg[sizeof rt->budget_msg];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(msg, sizeof msg, fmt, ap);
    va_end(ap);
    if (rt) {
        if (!rt->budget_hit) memcpy(rt->budget_msg, msg, sizeof msg);
        rt->budget_hit = 1;
        /* from now on every instruction fails, so a script cannot pcall its way past */
        lua_sethook(L, rt_hook, LUA_MASKCOUNT, 1);
    }
    luaL_where(L, 1);
    if (!*lua_tostring(L, -1)) { lua_pop(L, 1); luaL_where(L, 0); }
    lua_pushstring(L, msg);
    lua_concat(L, 2);
    return lua_error(L);
}

static void check_budgets(lua_State *L, rt_state *rt) {
    if (rt->budget_hit) wb_rt_budget_error(L, "%s", rt->budget_msg);
    if (rt->mem_over)
        wb_rt_budget_error(L, "memory limit of %.0f MB exceeded (--memory-limit MB)",
                           rt->pub.memory_budget / 1048576.0);
    if (rt->pub.time_budget > 0 && now() - rt->t0 > rt->pub.time_budget)
        wb_rt_budget_error(L, "time limit of %g s exceeded (--time-limit SECONDS)", rt->pub.time_budget);
}

void wb_rt_check_budgets(lua_State *L) {
    rt_state *rt = rt_from(L);
    if (rt) check_budgets(L, rt);
}

/* called from inside a step, outside Lua: reads the clock and flags only */
static int rt_interrupt(void *ud) {
    const rt_state *rt = ud;
    return rt->budget_hit || rt->mem_over || (rt->pub.time_budget > 0 && now() - rt->t0 > rt->pub.time_budget);
}

void wb_rt_interrupt(lua_State *L, int (**fn)(void *), void **ud) {
    rt_state *rt = rt_from(L);
    *fn = rt ? rt_interrupt : NULL;
    *ud = rt;
}

static void rt_hook(lua_State *L, lua_Debug *ar) {
    (void)ar;
    rt_state *rt = rt_from(L);
    if (rt) check_budgets(L, rt);
}

int wb_rt_budget_hit(lua_State *L) {
    rt_state *rt = rt_from(L);
    /* mem_refused too: lauxlib's buffers (string.rep, table.concat) ask the allocator
     * once, without the collection and second try, so one refusal is the budget's no */
    return rt && (rt->budget_hit || rt->mem_over || rt->mem_refused);
}

void wb_rt_add_frame_hook(lua_State *L, int index) {
    index = lua_absindex(L, index);
    if (lua_rawgetp(L, LUA_REGISTRYINDEX, &frame_hooks_key) != LUA_TTABLE) {
        lua_pop(L, 1);
        lua_newtable(L);
        lua_pushvalue(L, -1);
        lua_rawsetp(L, LUA_REGISTRYINDEX, &frame_hooks_key);
    }
    lua_pushvalue(L, index);
    lua_rawseti(L, -2, (lua_Integer)lua_rawlen(L, -2) + 1);
    lua_pop(L, 1);
}

void wb_rt_after_frame(lua_State *L, int world_index) {
    rt_state *rt = rt_from(L);
    if (rt) check_budgets(L, rt);
    /* frame hooks (recording, --watch) run after the budget check, in order */
    world_index = lua_absindex(L, world_index);
    if (lua_rawgetp(L, LUA_REGISTRYINDEX, &frame_hooks_key) == LUA_TTABLE) {
        lua_Integer n = (lua_Integer)lua_rawlen(L, -1);
        for (lua_Integer i = 1; i <= n; i++) {
            lua_rawgeti(L, -1, i);
            lua_pushvalue(L, world_index);
            lua_call(L, 1, 0);
        }
    }
    lua_pop(L, 1);
}

/* does the message's first line carry a position, "chunk:line:"? */
static int has_position(const char *msg) {
    for (const char *s = msg; *s && *s != '\n'; s++) {
        if (*s != ':' || s[1] < '0' || s[1] > '9') continue;
        const char *d = s + 1;
        while (*d >= '0' && *d <= '9') d++;
        if (*d == ':') return 1;
    }
    return 0;
}

int wb_rt_msgh(lua_State *L) {
    const char *msg = lua_tostring(L, 1);
    if (!msg) {  /* error(table), error(nil), ...: still say something */
        if (luaL_callmeta(L, 1, "__tostring") && lua_type(L, -1) == LUA_TSTRING)
            msg = lua_tostring(L, -1);
        else
            msg = lua_pushfstring(L, "(error object is a %s value)", luaL_typename(L, 1));
    }
    /* errors Lua raises inside C functions ("C stack overflow", "attempt to yield from
     * outside a coroutine") have no position: name the innermost Lua line */
    lua_Debug ar;
    if (!has_position(msg))
        for (int level = 1; lua_getstack(L, level, &ar); level++)
            if (lua_getinfo(L, "Sl", &ar) && ar.currentline > 0) {
                msg = lua_pushfstring(L, "%s:%d: %s", ar.short_src, ar.currentline, msg);
                break;
            }
    luaL_traceback(L, L, msg, 1);
    return 1;
}

/* runs protected: everything that can raise while a state is set up */
static int rt_init(lua_State *L) {
    rt_state *rt = lua_touserdata(L, 1);
    lua_pushlightuserdata(L, rt);  /* for code that looks for it by name */
    lua_setfield(L, LUA_REGISTRYINDEX, "wobble.runtime");
    wb_sandbox_open(L, &rt->sb);
    /* require: the library folder, then the scene's folder */
    lua_getglobal(L, LUA_LOADLIBNAME);
    luaL_Buffer b;
    luaL_buffinit(L, &b);
    if (rt->sb.lib[0]) {
        luaL_addstring(&b, rt->sb.lib);
        luaL_addstring(&b, "/?.lua;");
        luaL_addstring(&b, rt->sb.lib);
        luaL_addstring(&b, "/?/init.lua;");
    }
    luaL_addstring(&b, rt->sb.scene);
    luaL_addstring(&b, "/?.lua;");
    luaL_addstring(&b, rt->sb.scene);
    luaL_addstring(&b, "/?/init.lua");
    if (rt->pub.unsafe) {  /* trusted: the usual places too */
        lua_getfield(L, -2, "path");
        luaL_addchar(&b, ';');
        luaL_addvalue(&b);
    }
    luaL_pushresult(&b);
    lua_setfield(L, -2, "path");
    lua_pop(L, 1);
    /* `wobble` as a global and as package.loaded.wobble: one table */
    if (!rt->pub.open_module) return 0;
    luaL_requiref(L, "wobble", rt->pub.open_module, 1);
    if (lua_istable(L, -1)) {
        lua_newtable(L);
        lua_setfield(L, -2, "args");
    }
    lua_pop(L, 1);
    return 0;
}

static void warn_off(void *ud, const char *msg, int tocont);

/* warn(): off until a script says "@on", as in the lua command */
static void warn_print(void *ud, const char *msg, int tocont) {
    static int cont = 0;
    lua_State *L = ud;
    if (!cont && msg[0] == '@') {
        if (strcmp(msg, "@off") == 0) lua_setwarnf(L, warn_off, L);
        return;
    }
    fprintf(stderr, "%s%s%s", cont ? "" : "Lua warning: ", msg, tocont ? "" : "\n");
    cont = tocont;
}

static void warn_off(void *ud, const char *msg, int tocont) {
    lua_State *L = ud;
    if (!tocont && strcmp(msg, "@on") == 0) lua_setwarnf(L, warn_print, L);
}

static int panic(lua_State *L) {
    const char *msg = lua_tostring(L, -1);
    fprintf(stderr, "wobble: unprotected Lua error: %s\n", msg ? msg : "(not a string)");
    return 0;  /* Lua aborts */
}

lua_State *wb_rt_open(const wb_runtime *cfg) {
    rt_state *rt = calloc(1, sizeof *rt);
    if (!rt) return NULL;
    rt->pub = *cfg;
    rt->pub.memory.limit = cfg->memory_budget;
    rt->pub.memory.used = 0;
    if (wb_sandbox_init(&rt->sb, cfg->scene_dir, cfg->out_dir, cfg->lib_dir ? cfg->lib_dir : wb_rt_lib_dir(),
                        wb_rt_project_root(), cfg->unsafe)) {
        fprintf(stderr, "wobble: a folder path is too long or the current folder is gone\n");
        free(rt);
        return NULL;
    }
    rt->pub.scene_dir = rt->sb.scene;
    rt->pub.out_dir = rt->sb.out;
    rt->pub.lib_dir = rt->sb.lib[0] ? rt->sb.lib : NULL;
    rt->t0 = now();
    lua_State *L = lua_newstate(rt_alloc, rt);
    if (!L) {
        free(rt);
        return NULL;
    }
    lua_atpanic(L, panic);
    lua_setwarnf(L, warn_off, L);
    lua_pushcfunction(L, rt_init);
    lua_pushlightuserdata(L, rt);
    if (lua_pcall(L, 1, 0, 0) != LUA_OK) {
        const char *msg = lua_tostring(L, -1);
        fprintf(stderr, "wobble: cannot start the Lua runtime: %s\n", msg ? msg : "(error object is not a string)");
        wb_rt_close(L);
        return NULL;
    }
    lua_sethook(L, rt_hook, LUA_MASKCOUNT, HOOK_COUNT);
    return L;
}

void wb_rt_close(lua_State *L) {
    if (!L) return;
    rt_state *rt = rt_from(L);
    lua_sethook(L, NULL, 0, 0);          /* finalizers must run, budget or not */
    if (rt) rt->pub.memory_budget = rt->pub.memory.limit = 0;
    lua_close(L);
    free(rt);
}

/* ---- where the library and the project are ---------------------------------------------- */

static int has_harness(const char *dir) {
    char p[PATH_MAX];
    return snprintf(p, sizeof p, "%s/wobble/test.lua", dir) < (int)sizeof p && access(p, F_OK) == 0;
}

static char found_lib[PATH_MAX], found_root[PATH_MAX];

/* next to the executable first (build/wobble in the tree, bin/wobble installed), then
 * the places the Makefile compiled in */
static void discover(void) {
    static int done = 0;
    char exe[PATH_MAX], p[PATH_MAX];
    if (done) return;
    done = 1;
    ssize_t k = readlink("/proc/self/exe", exe, sizeof exe - 1);
    if (k > 0) {
        exe[k] = 0;
        char *slash = strrchr(exe, '/');
        if (slash) *slash = 0;
        if (snprintf(p, sizeof p, "%s/../lua", exe) < (int)sizeof p && has_harness(p) && realpath(p, found_lib)) {
            if (snprintf(p, sizeof p, "%s/..", exe) >= (int)sizeof p || !realpath(p, found_root)) found_root[0] = 0;
            return;
        }
        if (snprintf(p, sizeof p, "%s/../share/wobble/lua", exe) < (int)sizeof p && has_harness(p) &&
            realpath(p, found_lib)) {
            if (has_harness(WB_ROOT "/lua")) snprintf(found_root, sizeof found_root, "%s", WB_ROOT);
            return;
        }
    }
    if (has_harness(WB_ROOT "/lua")) {
        snprintf(found_lib, sizeof found_lib, "%s", WB_ROOT "/lua");
        snprintf(found_root, sizeof found_root, "%s", WB_ROOT);
    } else if (has_harness(WB_PREFIX "/share/wobble/lua")) {
        snprintf(found_lib, sizeof found_lib, "%s", WB_PREFIX "/share/wobble/lua");
    }
}

const char *wb_rt_lib_dir(void) {
    discover();
    return found_lib[0] ? found_lib : NULL;
}

const char *wb_rt_project_root(void) {
    discover();
    return found_root[0] ? found_root : NULL;
}
