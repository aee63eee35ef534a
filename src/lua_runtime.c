/* lua_runtime.c: what runs around a scene script. The sandbox of DESIGN §4 (no
 * process control, no bytecode, no debug library, file access through path rules),
 * the budgets (memory through the allocator, wall time through a count hook and
 * after every frame) and the discovery of the Lua library folder. */
#include "wobble_lua.h"

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

#define MAX_ROOTS 8
#define HOOK_COUNT (1 << 20)          /* instructions between two budget checks */
#define MEM_SLACK ((size_t)64 << 20)  /* granted past the memory limit so the error can be reported */

typedef struct rt_state {
    wb_runtime pub;                   /* first: what wb_rt_get hands out */
    char cwd[PATH_MAX], scene[PATH_MAX], out[PATH_MAX], lib[PATH_MAX];
    char roots[MAX_ROOTS][PATH_MAX];  /* canonical folders a script may read */
    int nroots;
    int mem_refused;                  /* the last growing allocation was refused */
    int mem_over;                     /* refused twice in a row: the budget is exhausted */
    int budget_hit;                   /* a budget error was raised; it is raised again at every step */
    double t0;                        /* wall clock at wb_rt_open */
    char budget_msg[256];
    char err[2 * PATH_MAX + 128];     /* wb_rt_path messages */
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
    static wb_runtime plain = { ".", "out", NULL, 1, 0, 0, -1, 0, 0, { 0, 0 } };
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
    return rt && (rt->budget_hit || rt->mem_over);
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

/* ---- paths ----------------------------------------------------------------------------- */

static int join(char *out, size_t n, const char *dir, const char *path) {
    int k = path[0] == '/' ? snprintf(out, n, "%s", path)
                           : snprintf(out, n, "%s%s%s", dir, dir[strlen(dir) - 1] == '/' ? "" : "/", path);
    return k >= 0 && (size_t)k < n ? 0 : -1;
}

/* Canonical form of an absolute path: realpath of its longest existing prefix, then the
 * rest with "." and ".." applied by hand (a folder that does not exist yet cannot be a
 * symlink), so neither ".." nor a symlink can leave a folder unnoticed. */
static int canon(const char *abs, char *out) {
    char tmp[PATH_MAX];
    if (snprintf(tmp, sizeof tmp, "%s", abs) >= (int)sizeof tmp) return -1;
    size_t len = strlen(tmp), cut = len;
    for (;;) {
        char save = tmp[cut];
        tmp[cut] = 0;
        int ok = cut > 0 && realpath(tmp, out) != NULL;
        tmp[cut] = save;
        if (ok) break;
        while (cut > 0 && tmp[--cut] != '/') {}
        if (cut == 0) { strcpy(out, "/"); break; }
    }
    size_t olen = strlen(out);
    for (char *s = tmp + cut; *s;) {
        while (*s == '/') s++;
        char *e = s;
        while (*e && *e != '/') e++;
        size_t cl = (size_t)(e - s);
        if (cl == 0 || (cl == 1 && s[0] == '.')) {
        } else if (cl == 2 && s[0] == '.' && s[1] == '.') {
            while (olen > 1 && out[olen - 1] != '/') olen--;
            if (olen > 1) olen--;
            out[olen] = 0;
        } else {
            if (olen + cl + 2 > PATH_MAX) return -1;
            if (olen > 1) out[olen++] = '/';
            memcpy(out + olen, s, cl);
            olen += cl;
            out[olen] = 0;
        }
        s = e;
    }
    if (len > 1 && abs[len - 1] == '/' && olen > 1 && olen + 2 <= PATH_MAX) strcpy(out + olen, "/");
    return 0;
}

static int under(const char *path, const char *root) {
    size_t rl = strlen(root);
    if (rl == 1 && root[0] == '/') return 1;
    return strncmp(path, root, rl) == 0 && (path[rl] == 0 || path[rl] == '/');
}

static int may_read(const rt_state *rt, const char *path) {
    for (int i = 0; i < rt->nroots; i++)
        if (under(path, rt->roots[i])) return 1;
    return 0;
}

static int exists(const char *path) {
    struct stat st;
    return stat(path, &st) == 0;
}

/* mkdir -p of the folders above the last component (and of a path ending in '/') */
static int make_parents(char *path) {
    for (char *s = path + 1; *s; s++) {
        if (*s != '/') continue;
        *s = 0;
        int bad = mkdir(path, 0777) != 0 && errno != EEXIST;
        *s = '/';
        if (bad) return -1;
    }
    return 0;
}

/* "path" or, when the script wrote something else, "given (path)" */
static const char *show(char *buf, size_t n, const char *given, const char *path) {
    if (strcmp(given, path) == 0) snprintf(buf, n, "%s", path);
    else snprintf(buf, n, "%s (%s)", given, path);
    return buf;
}

const char *wb_rt_path(lua_State *L, const char *path, int write, char *buf, size_t n, const char **err) {
    rt_state *rt = rt_from(L);
    char full[PATH_MAX], c[PATH_MAX], named[2 * PATH_MAX + 8];
    *err = NULL;
    if (!rt) {  /* no runtime: no rules */
        if (snprintf(buf, n, "%s", path) >= (int)n) return *err = "path too long", NULL;
        return buf;
    }
    if (!*path) return *err = "empty path", NULL;
    if (write) {
        /* a relative path is taken inside the output folder */
        if (join(full, sizeof full, rt->out, path) || canon(full, c)) return *err = "path too long", NULL;
        if (!rt->pub.unsafe && !under(c, rt->out)) {
            if (snprintf(rt->err, sizeof rt->err, "writing %s is outside the output folder %s; use --out DIR or --unsafe",
                         show(named, sizeof named, path, c), rt->out) >= (int)sizeof rt->err)
                return *err = "writing outside the output folder; use --out DIR or --unsafe", NULL;
            return *err = rt->err, NULL;
        }
        /* never outside the output folder, not even with --unsafe: no surprise folders */
        if (under(c, rt->out) && make_parents(c)) {
            snprintf(rt->err, sizeof rt->err, "cannot create the folders of %s: %s", c, strerror(errno));
            return *err = rt->err, NULL;
        }
    } else {
        /* relative: the current folder, then the scene's folder, then the output folder */
        const char *bases[3] = { rt->cwd, rt->scene, rt->out };
        int nb = path[0] == '/' ? 1 : 3, found = 0;
        char refused[PATH_MAX] = "";
        for (int i = 0; i < nb && !found; i++) {
            if (join(full, sizeof full, bases[i], path) || canon(full, c)) return *err = "path too long", NULL;
            if (!exists(c)) continue;
            if (rt->pub.unsafe || may_read(rt, c)) found = 1;
            else if (!refused[0]) strcpy(refused, c);
        }
        if (!found && refused[0]) strcpy(c, refused);
        /* nothing there: name the scene's folder, where the file was most likely meant to be */
        if (!found && !refused[0] && (join(full, sizeof full, nb == 1 ? "/" : rt->scene, path) || canon(full, c)))
            return *err = "path too long", NULL;
        if (!rt->pub.unsafe && !may_read(rt, c)) {
            snprintf(rt->err, sizeof rt->err,
                     "reading %s is outside the allowed folders (scene, assets, out); use --unsafe",
                     show(named, sizeof named, path, c));
            return *err = rt->err, NULL;
        }
    }
    if (snprintf(buf, n, "%s", c) >= (int)n) return *err = "path too long", NULL;
    return buf;
}

/* ---- the sandbox ------------------------------------------------------------------------- */

/* a path as error messages show it: relative to the current folder when inside it */
static const char *display(const rt_state *rt, const char *path) {
    size_t cl = strlen(rt->cwd);
    if (under(path, rt->cwd) && path[cl] == '/' && cl > 1) return path + cl + 1;
    return path;
}

/* replace the path argument at arg by its resolved form, or raise the rule's message */
static void check_arg(lua_State *L, int arg, int write) {
    char buf[PATH_MAX];
    const char *err, *p = wb_rt_path(L, luaL_checkstring(L, arg), write, buf, sizeof buf, &err);
    if (!p) luaL_error(L, "%s", err);
    lua_pushstring(L, p);
    lua_replace(L, arg);
}

/* call the original function (upvalue 1) with the (checked) arguments */
static int call_original(lua_State *L) {
    int n = lua_gettop(L);
    lua_pushvalue(L, lua_upvalueindex(1));
    lua_insert(L, 1);
    lua_call(L, n, LUA_MULTRET);
    return lua_gettop(L);
}

static int sb_io_open(lua_State *L) {
    const char *mode = luaL_optstring(L, 2, "r");
    check_arg(L, 1, strpbrk(mode, "wa+") != NULL);
    return call_original(L);
}

static int sb_read_arg1(lua_State *L) {  /* io.lines, io.input: a file name is read */
    if (lua_type(L, 1) == LUA_TSTRING) check_arg(L, 1, 0);
    return call_original(L);
}

static int sb_os_remove(lua_State *L) {
    check_arg(L, 1, 1);
    return call_original(L);
}

static int sb_io_output(lua_State *L) {
    if (lua_type(L, 1) == LUA_TSTRING) check_arg(L, 1, 1);
    return call_original(L);
}

static int sb_os_rename(lua_State *L) {
    check_arg(L, 1, 1);
    check_arg(L, 2, 1);
    return call_original(L);
}

static int sb_os_exit(lua_State *L) {
    return luaL_error(L, "os.exit is not available in the sandbox (return from the script or raise an error; "
                         "--unsafe allows it)");
}

/* load: text chunks only, whatever mode the script asks for */
static int sb_load(lua_State *L) {
    lua_settop(L, lua_gettop(L) < 4 ? 3 : 4);  /* keep "env given as nil" apart from "no env" */
    lua_pushliteral(L, "t");
    lua_replace(L, 3);
    return call_original(L);
}

/* load a text chunk from a file already checked; chunk name relative to the cwd */
typedef struct { FILE *f; int pending; char c; char buf[4096]; } file_reader;

static const char *read_file(lua_State *L, void *ud, size_t *size) {
    file_reader *r = ud;
    (void)L;
    if (r->pending) {  /* the newline that ended a skipped "#!" line keeps line numbers right */
        r->pending = 0;
        *size = 1;
        return &r->c;
    }
    *size = fread(r->buf, 1, sizeof r->buf, r->f);
    return *size ? r->buf : NULL;
}

static int load_text(lua_State *L, const char *path) {
    rt_state *rt = rt_from(L);
    file_reader r = { fopen(path, "r"), 0, '\n', "" };
    if (!r.f) {
        lua_pushfstring(L, "cannot open %s: %s", display(rt, path), strerror(errno));
        return LUA_ERRFILE;
    }
    int ch = getc(r.f);
    if (ch == '#') {
        while ((ch = getc(r.f)) != EOF && ch != '\n') {}
        r.pending = ch == '\n';
    } else if (ch != EOF) {
        ungetc(ch, r.f);
    }
    lua_pushfstring(L, "@%s", display(rt, path));
    int status = lua_load(L, read_file, &r, lua_tostring(L, -1), rt->pub.unsafe ? NULL : "t");
    lua_remove(L, -2);
    fclose(r.f);
    return status;
}

static int sb_loadfile(lua_State *L) {
    int env = !lua_isnone(L, 3);
    int status;
    if (lua_isnoneornil(L, 1)) {
        status = luaL_loadfilex(L, NULL, rt_from(L)->pub.unsafe ? NULL : "t");  /* stdin */
    } else {
        check_arg(L, 1, 0);
        status = load_text(L, lua_tostring(L, 1));
    }
    if (status != LUA_OK) {  /* nil, message */
        luaL_pushfail(L);
        lua_insert(L, -2);
        return 2;
    }
    if (env) {
        lua_pushvalue(L, 3);
        if (!lua_setupvalue(L, -2, 1)) lua_pop(L, 1);
    }
    return 1;
}

static int sb_dofile(lua_State *L) {
    lua_settop(L, 1);
    int status;
    if (lua_isnil(L, 1)) {
        status = luaL_loadfilex(L, NULL, rt_from(L)->pub.unsafe ? NULL : "t");
    } else {
        check_arg(L, 1, 0);
        status = load_text(L, lua_tostring(L, 1));
    }
    if (status != LUA_OK) return lua_error(L);
    lua_call(L, 0, LUA_MULTRET);
    return lua_gettop(L) - 1;
}

/* require's Lua searcher: package.path, but every candidate must lie in the library
 * folder or a readable folder, and only text is loaded */
static int sb_searcher(lua_State *L) {
    rt_state *rt = rt_from(L);
    const char *name = luaL_checkstring(L, 1);
    lua_settop(L, 1);
    lua_getfield(L, lua_upvalueindex(1), "path");           /* 2 */
    const char *tpl = lua_tostring(L, 2);
    if (!tpl) return luaL_error(L, "'package.path' must be a string");
    const char *mod = luaL_gsub(L, name, ".", "/");        /* 3 */
    lua_pushliteral(L, "");                                 /* 4: files tried */
    char t[PATH_MAX], full[PATH_MAX], c[PATH_MAX];
    for (const char *s = tpl; *s;) {
        const char *start = s, *e = strchr(s, ';');
        size_t len = e ? (size_t)(e - s) : strlen(s);
        s += len + (e != NULL);
        if (len == 0 || len >= PATH_MAX) continue;
        memcpy(t, start, len);
        t[len] = 0;
        const char *cand = luaL_gsub(L, t, "?", mod);     /* 5 */
        int ok = join(full, sizeof full, rt->cwd, cand) == 0 && canon(full, c) == 0 && exists(c) &&
                 (rt->pub.unsafe || may_read(rt, c) || (rt->lib[0] && under(c, rt->lib)));
        if (ok) {
            if (load_text(L, c) != LUA_OK)
                return luaL_error(L, "error loading module '%s' from file '%s':\n\t%s", name, display(rt, c),
                                  lua_tostring(L, -1));
            lua_pushstring(L, display(rt, c));
            return 2;
        }
        lua_pushfstring(L, "%s%sno file '%s'", lua_tostring(L, 4), *lua_tostring(L, 4) ? "\n\t" : "", cand);
        lua_replace(L, 4);
        lua_pop(L, 1);
    }
    return 1;
}

/* replace t[name] by a C closure over the original function */
static void wrap(lua_State *L, int t, const char *name, lua_CFunction f) {
    t = lua_absindex(L, t);
    lua_getfield(L, t, name);
    lua_pushcclosure(L, f, 1);
    lua_setfield(L, t, name);
}

/* a refused function raises a message naming it, rather than "attempt to call a nil
 * value", so the script's author learns why and what to do */
static int sb_refused(lua_State *L) {
    return luaL_error(L, "%s is not available in the sandbox (--unsafe allows it)",
                      lua_tostring(L, lua_upvalueindex(1)));
}

static void drop(lua_State *L, int t, const char *lib, const char *name) {
    t = lua_absindex(L, t);
    lua_pushfstring(L, "%s.%s", lib, name);
    lua_pushcclosure(L, sb_refused, 1);
    lua_setfield(L, t, name);
}

/* files named by a script go through wb_rt_path in both modes, so a scene writes to
 * the same place with and without --unsafe; only the refusals depend on the mode */
static void open_paths(lua_State *L) {
    lua_pushglobaltable(L);
    lua_pushcfunction(L, sb_loadfile);
    lua_setfield(L, -2, "loadfile");
    lua_pushcfunction(L, sb_dofile);
    lua_setfield(L, -2, "dofile");
    lua_getfield(L, -1, "io");
    wrap(L, -1, "open", sb_io_open);
    wrap(L, -1, "lines", sb_read_arg1);
    wrap(L, -1, "input", sb_read_arg1);
    wrap(L, -1, "output", sb_io_output);
    lua_pop(L, 1);
    lua_getfield(L, -1, "os");
    wrap(L, -1, "remove", sb_os_remove);
    wrap(L, -1, "rename", sb_os_rename);
    lua_pop(L, 2);
}

static void open_sandbox(lua_State *L) {
    static const luaL_Reg libs[] = {
        { LUA_GNAME, luaopen_base },       { LUA_LOADLIBNAME, luaopen_package },
        { LUA_COLIBNAME, luaopen_coroutine }, { LUA_TABLIBNAME, luaopen_table },
        { LUA_IOLIBNAME, luaopen_io },     { LUA_OSLIBNAME, luaopen_os },
        { LUA_STRLIBNAME, luaopen_string }, { LUA_MATHLIBNAME, luaopen_math },
        { LUA_UTF8LIBNAME, luaopen_utf8 }, { NULL, NULL } };  /* no debug */
    for (const luaL_Reg *l = libs; l->name; l++) {
        luaL_requiref(L, l->name, l->func, 1);
        lua_pop(L, 1);
    }
    lua_pushglobaltable(L);
    wrap(L, -1, "load", sb_load);
    lua_getfield(L, -1, "io");
    drop(L, -1, "io", "popen");
    drop(L, -1, "io", "tmpfile");  /* a file outside the output folder */
    lua_pop(L, 1);
    lua_getfield(L, -1, "os");
    drop(L, -1, "os", "execute");
    drop(L, -1, "os", "tmpname");
    drop(L, -1, "os", "setlocale");  /* process-wide: would change how every number is printed and parsed */
    lua_pushcfunction(L, sb_os_exit);
    lua_setfield(L, -2, "exit");
    lua_pop(L, 1);
    lua_getfield(L, -1, "string");
    drop(L, -1, "string", "dump");
    lua_pop(L, 1);
    lua_getfield(L, -1, "package");
    drop(L, -1, "package", "loadlib");
    lua_pushliteral(L, "");
    lua_setfield(L, -2, "cpath");
    lua_createtable(L, 2, 0);  /* searchers: preload, then Lua files through the rules */
    lua_getfield(L, -2, "searchers");
    lua_rawgeti(L, -1, 1);
    lua_rawseti(L, -3, 1);
    lua_pop(L, 1);
    lua_pushvalue(L, -2);
    lua_pushcclosure(L, sb_searcher, 1);
    lua_rawseti(L, -2, 2);
    lua_setfield(L, -2, "searchers");
    lua_pop(L, 2);
}

/* runs protected: everything that can raise while a state is set up */
static int rt_init(lua_State *L) {
    rt_state *rt = lua_touserdata(L, 1);
    lua_pushlightuserdata(L, rt);  /* for code that looks for it by name */
    lua_setfield(L, LUA_REGISTRYINDEX, "wobble.runtime");
    if (rt->pub.unsafe) luaL_openlibs(L);
    else open_sandbox(L);
    open_paths(L);
    /* require: the library folder, then the scene's folder */
    lua_getglobal(L, LUA_LOADLIBNAME);
    luaL_Buffer b;
    luaL_buffinit(L, &b);
    if (rt->lib[0]) {
        luaL_addstring(&b, rt->lib);
        luaL_addstring(&b, "/?.lua;");
        luaL_addstring(&b, rt->lib);
        luaL_addstring(&b, "/?/init.lua;");
    }
    luaL_addstring(&b, rt->scene);
    luaL_addstring(&b, "/?.lua;");
    luaL_addstring(&b, rt->scene);
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
    luaL_requiref(L, "wobble", luaopen_wobble, 1);
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
    char full[PATH_MAX];
    if (!rt) return NULL;
    rt->pub = *cfg;
    rt->pub.memory.limit = cfg->memory_budget;
    rt->pub.memory.used = 0;
    const char *lib = cfg->lib_dir ? cfg->lib_dir : wb_rt_lib_dir();
    const char *root = wb_rt_project_root();
    if (!getcwd(rt->cwd, sizeof rt->cwd) ||
        join(full, sizeof full, rt->cwd, cfg->scene_dir ? cfg->scene_dir : ".") || canon(full, rt->scene) ||
        join(full, sizeof full, rt->cwd, cfg->out_dir ? cfg->out_dir : "out") || canon(full, rt->out) ||
        (lib && (join(full, sizeof full, rt->cwd, lib) || canon(full, rt->lib)))) {
        fprintf(stderr, "wobble: a folder path is too long or the current folder is gone\n");
        free(rt);
        return NULL;
    }
    rt->pub.scene_dir = rt->scene;
    rt->pub.out_dir = rt->out;
    rt->pub.lib_dir = rt->lib[0] ? rt->lib : NULL;
    /* readable: the scene's folder, the assets folders next to it, here and in the
     * project, the output folder */
    const char *rel[][2] = { { rt->scene, "." },     { rt->scene, "../assets" }, { rt->cwd, "assets" },
                             { root, "assets" },     { rt->lib[0] ? rt->lib : NULL, "../assets" },
                             { rt->out, "." } };
    for (size_t i = 0; i < sizeof rel / sizeof rel[0]; i++)
        if (rel[i][0] && join(full, sizeof full, rel[i][0], rel[i][1]) == 0 && canon(full, rt->roots[rt->nroots]) == 0)
            rt->nroots++;
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
    return snprintf(p, sizeof p, "%s/wobble/test.lua", dir) < (int)sizeof p && exists(p);
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
