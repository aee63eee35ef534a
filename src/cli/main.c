/* main.c: the `wobble` command line (docs/cli.md): run a scene, run scenario tests as
 * TAP 13, run the benchmark scenes. Exit codes: 0 ok, 1 a test or expectation
 * failed, 2 script or input error, 3 a budget was exceeded. */
#include "io/io.h"
#include "lua/input.h"
#include "lua/wobble_lua.h"
#include "render/render.h"
#include "sweep.h"
#include "cli/view.h"

#include <dirent.h>
#include <errno.h>
#include <limits.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <time.h>
#include <unistd.h>

/* the folders above a path named on the command line (`--record out/run1/v.mp4`), made
 * as `--out` would be: the user chose the path */
static int make_parents(const char *path, char *err, size_t n)
{
    char p[PATH_MAX];
    if (snprintf(p, sizeof p, "%s", path) >= (int)sizeof p) {
        snprintf(err, n, "%s: path too long", path);
        return -1;
    }
    for (char *c = p + 1; *c; c++) {
        if (*c != '/') continue;
        *c = 0;
        if (mkdir(p, 0777) != 0 && errno != EEXIST) {
            const int e = errno;
            snprintf(err, n, "cannot make the folder %.900s: %s", p, strerror(e));
            return -1;
        }
        *c = '/';
    }
    return 0;
}

enum { EXIT_PASS = 0, EXIT_FAILED = 1, EXIT_SCRIPT = 2, EXIT_BUDGET = 3 };

static const char usage_text[] =
    "usage: wobble <command> [options]\n"
    "\n"
    "  wobble run SCENE.lua [options]  run a scene script\n"
    "  wobble test [PATH...] [options] run scenario tests (.lua files, folders searched\n"
    "                                  recursively; default tests/); TAP 13 on stdout,\n"
    "                                  last line \"N passed, N failed\"\n"
    "  wobble view SCENE.lua [options] the scene live in a window (docs/cli.md, \"Live viewer\")\n"
    "  wobble bench [--json]           run the benchmark scenes (tests/bench/*.lua, or\n"
    "                                  share/wobble/bench of an installed wobble)\n"
    "  wobble sweep SCENE.lua --grid key=a,b,c ... --out DIR   one run per combination: jobs\n"
    "                                  for GNU parallel and Slurm (wobble sweep --help)\n"
    "  wobble collect DIR [--csv | --json] [--plot X,Y[,COLOUR] OUT.png]   a sweep's results\n"
    "  wobble --version | --help\n"
    "\n"
    "options of run, test and bench:\n"
    "  --frames N          w:run stops after N frames; bench: each scene runs N frames\n"
    "  --record OUT        (run) draw every frame into OUT: .mp4, .gif or a folder of PNGs\n"
    "  --size WxH          (run) --record's frame size (default 1280x720; a .gif 640x360)\n"
    "  --samples N         (run) --record's antialiasing: N samples a pixel (1: none, 4:\n"
    "                      the renderer's default, slower); default one sample and FXAA\n"
    "  --replay INPUT.json (run) apply the grabs of an input log after their frames; exit\n"
    "                      code 1 when some were not applied (the scene ended or differs)\n"
    "  --out DIR           output folder, the only place a script writes (default out);\n"
    "                      run --out DIR writes DIR/result.json (wobble collect)\n"
    "  --set key=value     wobble.args.key = value (numbers, true/false converted); repeatable\n"
    "  --threads N         default thread count of new worlds, 1 to 256 (default 1)\n"
    "                      ($WOBBLE_SOLVER=vbd: the solver of new worlds that name none)\n"
    "  --unsafe            no sandbox: any path, os.execute, io.popen, C modules, debug\n"
    "  --quiet             no progress bar\n"
    "  --time-limit S      stop after S seconds of wall time (exit code 3)\n"
    "  --memory-limit MB   limit of the Lua heap and all worlds together, default 4096\n"
    "                      (exit code 3)\n"
    "\n"
    "options of view (and those of run but --record and --replay):\n"
    "  --watch             restart when the scene or a module it required is saved\n"
    "  --record-input FILE save the grabs (JSON) for `wobble run --replay FILE`\n"
    "  --frames N          also: close the window when the scene ends\n"
    "  --size WxH          the window's size in pixels (default 960x540)\n"
    "  --screenshot FILE   write the window's last picture as PNG when it closes\n"
    "\n"
    "exit codes: 0 ok, 1 a test or expectation failed, 2 script or input error,\n"
    "            3 time or memory budget exceeded\n";

typedef struct opts {
    wb_runtime rt;
    const char **sets, **pos;  /* --set values, positional arguments */
    const char *record;        /* run --record OUT, or NULL */
    const char *replay;        /* run --replay INPUT.json, or NULL */
    int samples;               /* run --samples N (--record's antialiasing), 0: the default */
    int nsets, npos;
    int json;                  /* bench --json */
    int out_given;             /* --out named: run writes result.json there */
    wb_view_opts view;         /* view's own options (view.h) */
} opts;

static int usage_error(const char *fmt, const char *arg) {
    fprintf(stderr, "wobble: ");
    fprintf(stderr, fmt, arg);
    fprintf(stderr, "\n\n%s", usage_text);
    return EXIT_SCRIPT;
}

/* ---- options ------------------------------------------------------------------------- */

static int parse_number(const char *s, double lo, double hi, double *out) {
    char *end;
    errno = 0;
    double v = strtod(s, &end);
    if (!*s || *end || errno || !(v >= lo && v <= hi)) return -1;
    *out = v;
    return 0;
}

/* Would Lua read s as an infinite number (1e999)? Lua converts with strtod, refuses
 * "inf" and "nan" (any n/N) and allows surrounding spaces; a --set value that does
 * not convert stays a string and is fine. */
static int overflows(const char *s) {
    char *end;
    if (strpbrk(s, "nN")) return 0;
    double v = strtod(s, &end);
    if (end == s) return 0;
    while (*end == ' ' || (*end >= '\t' && *end <= '\r')) end++;
    return !*end && !isfinite(v);
}

static int parse_opts(int argc, char **argv, const char *cmd, opts *o) {
    memset(o, 0, sizeof *o);
    o->rt.out_dir = "out";
    o->rt.frame_cap = -1;
    o->rt.open_module = luaopen_wobble;
    o->rt.memory_budget = (size_t)4096 << 20;
    o->sets = calloc((size_t)argc + 2, sizeof *o->sets);  /* + bench's json and frames */
    o->pos = calloc((size_t)argc, sizeof *o->pos);
    if (!o->sets || !o->pos) return usage_error("%s", "out of memory");
    /* the solver of worlds that name none: the suite runs the validation tests under VBD */
    const char *solver = getenv("WOBBLE_SOLVER");
    if (solver && *solver) {
        static const char *const names[] = { "gauss-seidel", "jacobi", "vbd" };
        for (int k = 0; k < 3 && !o->rt.solver; k++)
            if (!strcmp(solver, names[k])) o->rt.solver = k + 1;
        if (!o->rt.solver) return usage_error("WOBBLE_SOLVER must be gauss-seidel, jacobi or vbd, got '%s'", solver);
    }
    int only_pos = 0;
    for (int i = 2; i < argc; i++) {
        char *a = argv[i], name[64];
        const char *val = NULL;
        if (only_pos || a[0] != '-' || !a[1]) {
            o->pos[o->npos++] = a;
            continue;
        }
        if (strcmp(a, "--") == 0) {
            only_pos = 1;
            continue;
        }
        /* --name value or --name=value */
        const char *eq = strchr(a, '=');
        size_t nl = eq ? (size_t)(eq - a) : strlen(a);
        if (nl >= sizeof name) return usage_error("unknown option %s", a);
        memcpy(name, a, nl);
        name[nl] = 0;
        int flag = !strcmp(name, "--unsafe") || !strcmp(name, "--quiet") || !strcmp(name, "--json");
        if (!strcmp(name, "--watch")) {
            if (strcmp(cmd, "view")) return usage_error("%s is an option of view", name);
            if (eq) return usage_error("%s takes no value", name);
            o->view.watch = true;
            continue;
        }
        if (!strcmp(name, "--record-input") || !strcmp(name, "--screenshot") || !strcmp(name, "--size")) {
            if (!strcmp(name, "--size") && !strcmp(cmd, "run")) {
            } else if (strcmp(cmd, "view")) {
                return usage_error(!strcmp(name, "--size") ? "%s is an option of run and view" : "%s is an option of view", name);
            }
            if (eq) val = eq + 1;
            else if (i + 1 < argc) val = argv[++i];
            else return usage_error("%s needs a value", name);
            if (!*val) return usage_error("%s needs a value", name);
            int vw = 0, vh = 0, k = 0;
            if (!strcmp(name, "--record-input")) o->view.record_input = val;
            else if (!strcmp(name, "--screenshot")) o->view.screenshot = val;
            else if (sscanf(val, "%dx%d%n", &vw, &vh, &k) != 2 || val[k] || vw < 16 || vh < 16 || vw > 4096 || vh > 4096)
                return usage_error("--size expects WIDTHxHEIGHT, each from 16 to 4096 (as 1280x720), got '%s'", val);
            else o->view.width = vw, o->view.height = vh;
            continue;
        }
        if (flag) {
            if (eq) return usage_error("%s takes no value", name);
            if (!strcmp(name, "--json") && strcmp(cmd, "bench")) return usage_error("unknown option %s", a);
            if (!strcmp(name, "--unsafe")) o->rt.unsafe = 1;
            else if (!strcmp(name, "--quiet")) o->rt.quiet = 1;
            else o->json = 1;
            continue;
        }
        if (strcmp(name, "--frames") && strcmp(name, "--out") && strcmp(name, "--set") && strcmp(name, "--threads") &&
            strcmp(name, "--time-limit") && strcmp(name, "--memory-limit") && strcmp(name, "--record") &&
            strcmp(name, "--replay") && strcmp(name, "--samples"))
            return usage_error("unknown option %s", a);
        if (!strcmp(name, "--samples") && strcmp(cmd, "run")) return usage_error("%s is an option of run", name);
        if (!strcmp(name, "--record") && strcmp(cmd, "run")) return usage_error("%s is an option of run", name);
        if (!strcmp(name, "--replay") && strcmp(cmd, "run")) return usage_error("%s is an option of run", name);
        if (eq) val = eq + 1;
        else if (i + 1 < argc) val = argv[++i];
        else return usage_error("%s needs a value", name);
        double v;
        if (!strcmp(name, "--frames")) {
            if (parse_number(val, 0, 1e15, &v) || v != (int64_t)v)
                return usage_error("--frames expects a whole number of frames, got '%s'", val);
            o->rt.frame_cap = (int64_t)v;
        } else if (!strcmp(name, "--threads")) {
            if (parse_number(val, 1, WB_MAX_THREADS, &v) || v != (int)v)
                return usage_error("--threads expects a whole number from 1 to 256, got '%s'", val);
            o->rt.threads = (int)v;
        } else if (!strcmp(name, "--time-limit")) {
            if (parse_number(val, 0, 1e9, &v)) return usage_error("--time-limit expects seconds, got '%s'", val);
            o->rt.time_budget = v;
        } else if (!strcmp(name, "--memory-limit")) {
            if (parse_number(val, 0, 1e9, &v)) return usage_error("--memory-limit expects megabytes, got '%s'", val);
            o->rt.memory_budget = (size_t)(v * 1048576.0);  /* 0: none */
        } else if (!strcmp(name, "--record")) {
            if (!*val) return usage_error("%s", "--record expects a file (.mp4, .gif) or a folder");
            o->record = val;
        } else if (!strcmp(name, "--samples")) {
            if (parse_number(val, 1, 16, &v) || v != (int)v)
                return usage_error("--samples expects a whole number from 1 to 16, got '%s'", val);
            o->samples = (int)v;
        } else if (!strcmp(name, "--replay")) {
            if (!*val) return usage_error("%s", "--replay expects an input log (.json)");
            o->replay = val;
        } else if (!strcmp(name, "--out")) {
            if (!*val) return usage_error("%s", "--out expects a folder");
            o->rt.out_dir = val;
            o->out_given = 1;
        } else {
            const char *e = strchr(val, '=');
            if (!e || e == val) return usage_error("--set expects key=value, got '%s'", val);
            if (overflows(e + 1)) return usage_error("--set %s: the number is out of range (not finite)", val);
            o->sets[o->nsets++] = val;
        }
    }
    return EXIT_PASS;
}

/* ---- running chunks ------------------------------------------------------------------- */

static int assertion_failed;  /* the last error was an expectation of wobble.test */

/* is the value at idx the message of the harness's last failed expectation? */
static int is_expectation(lua_State *L, int idx) {
    idx = lua_absindex(L, idx);
    lua_getfield(L, LUA_REGISTRYINDEX, LUA_LOADED_TABLE);
    int r = 0;
    if (lua_getfield(L, -1, "wobble.test") == LUA_TTABLE) {
        lua_getfield(L, -1, "_last_failure");
        r = lua_rawequal(L, -1, idx);
        lua_pop(L, 1);
    }
    lua_pop(L, 2);
    return r;
}

/* The first expectation that failed although the script caught its error (pcall, a
 * coroutine), as a message pushed on the stack; NULL (nothing pushed) when none. A
 * caught failure still fails: otherwise pcall(expect.eq, 1, 2) would pass a test. */
static const char *caught_failure(lua_State *L) {
    const char *msg = NULL;
    int top = lua_gettop(L);
    lua_getfield(L, LUA_REGISTRYINDEX, LUA_LOADED_TABLE);
    if (lua_getfield(L, -1, "wobble.test") == LUA_TTABLE && lua_getfield(L, -1, "_first_failure") == LUA_TSTRING)
        msg = lua_pushfstring(L, "%s (an expectation failed and the script caught its error; a failed "
                                 "expectation fails the test all the same)", lua_tostring(L, -1));
    if (msg) {
        lua_replace(L, top + 1);
        lua_settop(L, top + 1);
    } else {
        lua_settop(L, top);
    }
    return msg;
}

/* forget caught failures before the next case */
static void clear_caught(lua_State *L) {
    lua_getfield(L, LUA_REGISTRYINDEX, LUA_LOADED_TABLE);
    if (lua_getfield(L, -1, "wobble.test") == LUA_TTABLE) {
        lua_pushnil(L);
        lua_setfield(L, -2, "_first_failure");
    }
    lua_pop(L, 2);
}

static int msgh(lua_State *L) {
    if (lua_type(L, 1) == LUA_TSTRING && is_expectation(L, 1)) assertion_failed = 1;
    return wb_rt_msgh(L);
}

/* call the function on top (no arguments, no results); on error leaves the message and
 * traceback on the stack */
static int pcall_top(lua_State *L) {
    int base = lua_gettop(L);
    lua_pushcfunction(L, msgh);
    lua_insert(L, base);
    assertion_failed = 0;
    int status = lua_pcall(L, 0, 0, base);
    lua_remove(L, base);
    return status;
}

static int run_file(lua_State *L, const char *path) {
    /* the chunk name is the path as given, so messages read "scripts/x.lua:12: ..." */
    int status = luaL_loadfilex(L, path, wb_rt_get(L)->unsafe ? NULL : "t");
    if (status == LUA_OK) status = pcall_top(L);
    return status;
}

/* message of a failed call (on top) and the exit code it stands for */
static int failure(lua_State *L, int status, const char *path, const char **msg) {
    int budget = wb_rt_budget_hit(L);
    *msg = lua_tostring(L, -1);
    if (status == LUA_ERRMEM || !*msg) {
        const wb_runtime *rt = wb_rt_get(L);
        /* memory errors skip the message handler: no line, but the file */
        if (budget) *msg = lua_pushfstring(L, "%s: memory limit of %d MB exceeded (--memory-limit MB)", path,
                                           (int)(rt->memory_budget >> 20));
        else *msg = lua_pushfstring(L, "%s: not enough memory", path);
    }
    return budget ? EXIT_BUDGET : assertion_failed ? EXIT_FAILED : EXIT_SCRIPT;
}

/* print inside a TAP stream (wobble test, and a scene's cases): every line a TAP comment
 * "# ...", so that a consumer never reads a script's output as a test line ("ok 1") */
static int tap_print(lua_State *L) {
    int n = lua_gettop(L);
    luaL_Buffer b;
    luaL_buffinit(L, &b);
    for (int i = 1; i <= n; i++) {
        if (i > 1) luaL_addchar(&b, '\t');
        luaL_tolstring(L, i, NULL);
        luaL_addvalue(&b);
    }
    luaL_pushresult(&b);
    size_t len, at = 0;
    const char *s = lua_tolstring(L, -1, &len);
    do {  /* each line, the empty one after a trailing newline too, as print shows it */
        const char *e = memchr(s + at, '\n', len - at);
        size_t k = e ? (size_t)(e - (s + at)) : len - at;
        fputs(k ? "# " : "#", stdout);
        fwrite(s + at, 1, k, stdout);
        fputc('\n', stdout);
        at += k + 1;
    } while (at <= len);
    fflush(stdout);
    return 0;
}

typedef struct prep { const opts *o; int harness_globals; } prep;

/* runs protected: wobble.args from --set; `test` and `expect` globals for wobble test */
static int prepare(lua_State *L) {
    const prep *p = lua_touserdata(L, 1);
    if (lua_getglobal(L, "wobble") == LUA_TTABLE) {
        lua_newtable(L);
        for (int i = 0; i < p->o->nsets; i++) {
            const char *kv = p->o->sets[i], *e = strchr(kv, '=');
            lua_pushlstring(L, kv, (size_t)(e - kv));
            const char *v = e + 1;
            if (!strcmp(v, "true") || !strcmp(v, "false")) lua_pushboolean(L, v[0] == 't');
            else if (!lua_stringtonumber(L, v)) lua_pushstring(L, v);
            lua_rawset(L, -3);
        }
        lua_setfield(L, -2, "args");
    }
    if (p->harness_globals) {
        lua_getglobal(L, "require");
        lua_pushliteral(L, "wobble.test");
        lua_call(L, 1, 1);
        lua_getfield(L, -1, "test");
        lua_setglobal(L, "test");
        lua_getfield(L, -1, "expect");
        lua_setglobal(L, "expect");
        lua_pushcfunction(L, tap_print);  /* the whole file is in the TAP stream */
        lua_setglobal(L, "print");
    }
    return 0;
}

static lua_State *open_state(const opts *o, const char *script, int harness, const char **err) {
    static char dir[PATH_MAX];
    wb_runtime cfg = o->rt;
    snprintf(dir, sizeof dir, "%s", script);
    char *slash = strrchr(dir, '/');
    if (!slash) strcpy(dir, ".");
    else if (slash == dir) dir[1] = 0;
    else *slash = 0;
    cfg.scene_dir = dir;
    cfg.script = script;  /* named by the watchdog when it ends the run */
    lua_State *L = wb_rt_open(&cfg);
    *err = NULL;
    if (!L) return *err = "cannot start the Lua runtime", NULL;
    prep p = { o, harness };
    lua_pushcfunction(L, prepare);
    lua_pushlightuserdata(L, &p);
    if (lua_pcall(L, 1, 0, 0) != LUA_OK) {
        static char buf[1024];
        snprintf(buf, sizeof buf, "%s", lua_tostring(L, -1) ? lua_tostring(L, -1) : "error while starting");
        wb_rt_close(L);
        return *err = buf, NULL;
    }
    return L;
}

/* ---- TAP -------------------------------------------------------------------------------- */

typedef struct tap { int n, passed, failed, code; } tap;

static void yaml_string(FILE *f, const char *s, size_t n) {
    fputc('"', f);
    for (size_t i = 0; i < n; i++) {
        unsigned char c = (unsigned char)s[i];
        if (c == '"' || c == '\\') fprintf(f, "\\%c", c);
        else if (c == '\n') fprintf(f, "\\n");
        else if (c == '\t') fprintf(f, "\\t");
        else if (c < 0x20) fprintf(f, "\\x%02x", c);
        else fputc(c, f);
    }
    fputc('"', f);
}

/* frames of the harness itself and of the C error function tell the reader nothing */
static int noise(const char *line, size_t n) {
    static const char *const pats[] = { "[C]: in function 'error'", "wobble/test.lua:", "[C]: in ?" };
    for (size_t i = 0; i < sizeof pats / sizeof *pats; i++) {
        size_t pl = strlen(pats[i]);
        for (size_t k = 0; k + pl <= n; k++)
            if (!memcmp(line + k, pats[i], pl)) return 1;
    }
    return 0;
}

/* a script error on stderr: the message, then the traceback without the noise */
static void print_error(const char *msg) {
    const char *tb = strstr(msg, "\nstack traceback:\n");
    if (!tb) {
        fprintf(stderr, "%s\n", msg);
        return;
    }
    fprintf(stderr, "%.*s\nstack traceback:\n", (int)(tb - msg), msg);
    for (const char *s = tb + 18; *s;) {
        const char *e = strchr(s, '\n');
        size_t n = e ? (size_t)(e - s) : strlen(s);
        if (!noise(s, n)) fprintf(stderr, "%.*s\n", (int)n, s);
        if (!e) break;
        s = e + 1;
    }
}

/* the TAP line of test n and, for a failure, its YAML block */
static void tap_line(FILE *f, int n, int code, const char *file, const char *name, const char *err) {
    fprintf(f, "%sok %d - %s: ", code == EXIT_PASS ? "" : "not ", n, file);
    for (const char *s = name; *s; s++) {  /* '#' starts a TAP directive */
        if (*s == '#') fputc('\\', f);
        fputc(*s == '\n' ? ' ' : *s, f);
    }
    fputc('\n', f);
    if (err) {
        const char *tb = strstr(err, "\nstack traceback:\n");
        fprintf(f, "  ---\n  message: ");
        yaml_string(f, err, tb ? (size_t)(tb - err) : strlen(err));
        fputc('\n', f);
        if (tb) {
            int header = 0;
            for (const char *s = tb + 18; *s;) {
                const char *e = strchr(s, '\n');
                size_t n = e ? (size_t)(e - s) : strlen(s);
                if (!noise(s, n)) {
                    if (!header) fprintf(f, "  traceback: |-\n");
                    header = 1;
                    while (n && *s == '\t') s++, n--;
                    fprintf(f, "    %.*s\n", (int)n, s);
                }
                s += n + (e != NULL);
                if (!e) break;
            }
        }
        fprintf(f, "  ...\n");
    }
}

static void tap_result(tap *t, int code, const char *file, const char *name, const char *err) {
    t->n++;
    if (code == EXIT_PASS) t->passed++;
    else t->failed++;
    if (code > t->code) t->code = code;
    tap_line(stdout, t->n, code, file, name, err);
    fflush(stdout);
}

/* What the watchdog prints on stdout should it end the process while `what` runs (a
 * finalizer or a C call that never returns past --time-limit): that test failed and
 * the summary, so the TAP stream ends as it does for any other budget. */
static void tap_last_words(lua_State *L, const tap *t, const char *file, const char *what) {
    double limit = wb_rt_get(L)->time_budget;
    size_t mem = wb_rt_get(L)->memory_budget;
    char *buf = NULL, msg[PATH_MAX + 256];
    size_t len = 0;
    FILE *f;
    if ((limit <= 0 && !mem) || !(f = open_memstream(&buf, &len))) return;
    if (limit > 0)
        snprintf(msg, sizeof msg, "%s: time limit of %g s exceeded (--time-limit SECONDS); ended by the watchdog", file,
                 limit);
    else
        snprintf(msg, sizeof msg, "%s: memory limit of %d MB exceeded (--memory-limit MB); ended by the watchdog", file,
                 (int)(mem >> 20));
    tap_line(f, t->n + 1, EXIT_BUDGET, file, what, msg);
    fprintf(f, "1..%d\n%d passed, %d failed\n", t->n + 1, t->passed, t->failed + 1);
    if (fclose(f) == 0) wb_rt_set_last_words(L, buf);
    free(buf);
}

/* how many cases the chunk registered with wobble.test */
static int case_count(lua_State *L) {
    int top = lua_gettop(L), n = 0;
    lua_getfield(L, LUA_REGISTRYINDEX, LUA_LOADED_TABLE);
    if (lua_getfield(L, -1, "wobble.test") == LUA_TTABLE && lua_getfield(L, -1, "cases") == LUA_TTABLE)
        n = (int)lua_rawlen(L, -1);
    lua_settop(L, top);
    return n;
}

/* run the cases a chunk registered with wobble.test; returns how many there were */
static int run_cases(lua_State *L, const char *file, tap *t) {
    int top = lua_gettop(L);
    lua_getfield(L, LUA_REGISTRYINDEX, LUA_LOADED_TABLE);
    if (lua_getfield(L, -1, "wobble.test") != LUA_TTABLE || lua_getfield(L, -1, "cases") != LUA_TTABLE) {
        lua_settop(L, top);
        return 0;
    }
    int m = top + 2, cases = top + 3;
    int n = (int)lua_rawlen(L, cases);
    for (int i = 1; i <= n; i++) {
        lua_rawgeti(L, cases, i);
        lua_getfield(L, -1, "name");
        const char *name = lua_tostring(L, -1) ? lua_tostring(L, -1) : "?";
        lua_pushinteger(L, 0);
        lua_setfield(L, m, "_count");
        lua_pushnil(L);
        lua_setfield(L, m, "_last_failure");
        lua_pushnil(L);
        lua_setfield(L, m, "_first_failure");
        lua_pushboolean(L, 1);
        lua_setfield(L, m, "_running");
        tap_last_words(L, t, file, name);
        lua_getfield(L, -2, "fn");
        int status = pcall_top(L);
        lua_pushboolean(L, 0);
        lua_setfield(L, m, "_running");
        const char *caught;
        if (status == LUA_OK && (caught = caught_failure(L))) {
            tap_result(t, EXIT_FAILED, file, name, caught);
        } else if (status == LUA_OK) {
            lua_getfield(L, m, "_count");
            int count = (int)lua_tointeger(L, -1);
            lua_pop(L, 1);
            if (count == 0)
                tap_result(t, EXIT_FAILED, file, name,
                           "no expectations: a test case must call expect.* at least once");
            else tap_result(t, wb_rt_budget_hit(L) ? EXIT_BUDGET : EXIT_PASS, file, name, NULL);
        } else {
            const char *msg;
            int code = failure(L, status, file, &msg);
            /* an error inside a case is a failed test; only file-level trouble is a script error */
            tap_result(t, code == EXIT_SCRIPT ? EXIT_FAILED : code, file, name, msg);
        }
        lua_settop(L, cases);
        if (wb_rt_budget_hit(L)) break;  /* every further instruction would fail too */
    }
    wb_rt_set_last_words(L, NULL);
    lua_settop(L, top);
    return n;
}

/* ---- test files -------------------------------------------------------------------------- */

typedef struct list { char **v; int n, cap; } list;

static int list_add(list *l, const char *s) {
    if (l->n == l->cap) {
        int cap = l->cap ? 2 * l->cap : 16;
        char **v = realloc(l->v, (size_t)cap * sizeof *v);
        if (!v) return -1;
        l->v = v;
        l->cap = cap;
    }
    return (l->v[l->n] = strdup(s)) ? (l->n++, 0) : -1;
}

static int cmp_str(const void *a, const void *b) {
    return strcmp(*(char *const *)a, *(char *const *)b);
}

static int ends_with(const char *s, const char *suffix) {
    size_t n = strlen(s), k = strlen(suffix);
    return n >= k && !strcmp(s + n - k, suffix);
}

/* *.lua below dir, skipping hidden and _private entries, benchmarks and fixtures (scenes
 * that tests run in a separate process, some of them failing on purpose) */
static void collect(const char *dir, list *out, int depth) {
    DIR *d = opendir(dir);
    struct dirent *e;
    if (!d || depth > 32) {
        if (d) closedir(d);
        return;
    }
    while ((e = readdir(d))) {
        char p[PATH_MAX];
        struct stat st;
        if (e->d_name[0] == '.' || e->d_name[0] == '_') continue;
        if (snprintf(p, sizeof p, "%s%s%s", dir, ends_with(dir, "/") ? "" : "/", e->d_name) >= (int)sizeof p ||
            stat(p, &st) != 0)
            continue;
        if (S_ISDIR(st.st_mode)) {
            if (strcmp(e->d_name, "bench") && strcmp(e->d_name, "fixtures")) collect(p, out, depth + 1);
        } else if (S_ISREG(st.st_mode) && ends_with(e->d_name, ".lua")) {
            list_add(out, p);
        }
    }
    closedir(d);
}

static void list_free(list *l) {
    for (int i = 0; i < l->n; i++) free(l->v[i]);
    free(l->v);
}

/* the finalizers run under the time budget: past it, they fail the file */
static void close_test_state(lua_State *L, tap *t, const char *path) {
    double limit = wb_rt_get(L)->time_budget;
    size_t mem = wb_rt_get(L)->memory_budget;
    tap_last_words(L, t, path, "closing the file (finalizers)");
    int late = wb_rt_close(L);
    if (late) {
        char msg[PATH_MAX + 128];
        if (late == WB_RT_LATE_TIME)
            snprintf(msg, sizeof msg, "%s: time limit of %g s exceeded (--time-limit SECONDS) while the finalizers (__gc) ran",
                     path, limit);
        else
            snprintf(msg, sizeof msg, "%s: memory limit of %d MB exceeded (--memory-limit MB) while the finalizers (__gc) ran",
                     path, (int)(mem >> 20));
        tap_result(t, EXIT_BUDGET, path, "closing the file (finalizers)", msg);
    }
}

static void test_file(const char *path, const opts *o, tap *t) {
    const char *err;
    lua_State *L = open_state(o, path, 1, &err);
    if (!L) {
        tap_result(t, EXIT_SCRIPT, path, "loading the file", err);
        return;
    }
    tap_last_words(L, t, path, "loading the file");
    int status = run_file(L, path);
    const char *caught;
    if (status != LUA_OK) {
        const char *msg;
        int code = failure(L, status, path, &msg);
        tap_result(t, code, path, "loading the file", msg);
        close_test_state(L, t, path);
        return;
    }
    if ((caught = caught_failure(L))) {  /* an expectation at the top of the file */
        tap_result(t, EXIT_FAILED, path, "loading the file", caught);
        clear_caught(L);
    }
    if (run_cases(L, path, t) == 0) {
        tap_result(t, EXIT_FAILED, path, "no test cases",
                   "the file defines no test cases: call test(name, function() ... end) "
                   "(a scene without them runs with `wobble run FILE`)");
    }
    close_test_state(L, t, path);
}

static int cmd_test(const opts *o) {
    static const char *const deflt[] = { "tests/" };
    const char *const *paths = o->npos ? o->pos : deflt;
    int np = o->npos ? o->npos : 1, nfiles = 0;
    tap t = { 0, 0, 0, 0 };
    printf("TAP version 13\n");
    fflush(stdout);
    for (int i = 0; i < np; i++) {
        struct stat st;
        list files = { 0 };
        if (stat(paths[i], &st) != 0) {
            char msg[PATH_MAX + 64];
            snprintf(msg, sizeof msg, "cannot open %s: %s", paths[i], strerror(errno));
            tap_result(&t, EXIT_SCRIPT, paths[i], "loading the file", msg);
            continue;
        }
        if (S_ISDIR(st.st_mode)) collect(paths[i], &files, 0);
        else list_add(&files, paths[i]);
        if (files.n > 1) qsort(files.v, (size_t)files.n, sizeof *files.v, cmp_str);
        if (files.n == 0) printf("# no *.lua files under %s\n", paths[i]);
        for (int k = 0; k < files.n; k++) test_file(files.v[k], o, &t);
        nfiles += files.n;
        list_free(&files);
    }
    if (nfiles == 0 && t.failed == 0) {
        fprintf(stderr, "wobble: no test files found\n");
        t.code = EXIT_SCRIPT;
    }
    printf("1..%d\n%d passed, %d failed\n", t.n, t.passed, t.failed);
    return t.code;
}

/* ---- run and bench ----------------------------------------------------------------------- */

/* what `wobble run` keeps for OUTDIR/result.json: the figures of the state before it
 * closes and the first error, without its traceback */
typedef struct run_report { void *taken; char error[2048]; } run_report;

static void report_error(run_report *rep, const char *msg) {
    if (!rep || rep->error[0] || !msg) return;
    const char *tb = strstr(msg, "\nstack traceback:");
    snprintf(rep->error, sizeof rep->error, "%.*s", (int)(tb ? (size_t)(tb - msg) : strlen(msg)), msg);
}

static void report_take(run_report *rep, lua_State *L) {
    if (rep && !rep->taken) rep->taken = wbl_result_take(L);
}

/* run one scene; test cases it registered run afterwards as TAP; rep (run, not bench)
 * collects what result.json says */
static int run_scene(const opts *o, const char *path, run_report *rep) {
    const char *err, *msg;
    lua_State *L = open_state(o, path, 0, &err);
    if (!L) {
        fprintf(stderr, "wobble: %s\n", err);
        report_error(rep, err);
        return EXIT_SCRIPT;
    }
    char rerr[1024];
    /* --replay: the logged grabs applied after their frames (a frame hook); read first,
     * so that a bad file leaves nothing begun */
    if (o->replay && !wbl_replay_begin(L, o->replay, rerr, sizeof rerr)) {
        fprintf(stderr, "wobble: --replay: %s\n", rerr);
        report_error(rep, rerr);
        wb_rt_close(L);
        return EXIT_SCRIPT;
    }
    /* --record: every frame the scene steps is drawn and encoded (the path is the
     * user's choice, not the sandbox's); the file is finished even after an error */
    if (o->record && make_parents(o->record, rerr, sizeof rerr) != 0) {
        fprintf(stderr, "wobble: --record: %s\n", rerr);
        report_error(rep, rerr);
        report_take(rep, L);
        wb_rt_close(L);
        return EXIT_SCRIPT;
    }
    if (o->record && !wbl_record_begin(L, o->record, o->view.width, o->view.height, o->samples, rerr, sizeof rerr)) {
        fprintf(stderr, "wobble: %s\n", rerr);
        report_error(rep, rerr);
        report_take(rep, L);
        wb_rt_close(L);
        return EXIT_SCRIPT;
    }
    int status = run_file(L, path), code = EXIT_PASS;
    if (status != LUA_OK) {
        code = failure(L, status, path, &msg);
        print_error(msg);
        report_error(rep, msg);
    } else {
        tap t = { 0, 0, 0, 0 };
        const char *caught = caught_failure(L);
        if (caught) {  /* an expectation of the scene itself */
            print_error(caught);
            report_error(rep, caught);
            t.code = EXIT_FAILED;
            clear_caught(L);
        }
        if (case_count(L) > 0) {
            printf("TAP version 13\n");
            lua_pushcfunction(L, tap_print);  /* the cases' output is in the TAP stream */
            lua_setglobal(L, "print");
            run_cases(L, path, &t);
            printf("1..%d\n%d passed, %d failed\n", t.n, t.passed, t.failed);
        }
        code = t.code;
        if (wb_rt_budget_hit(L) && code < EXIT_BUDGET) {
            fprintf(stderr, "wobble: %s: a time or memory budget was exceeded\n", path);
            report_error(rep, "a time or memory budget was exceeded (an error the script caught)");
            code = EXIT_BUDGET;
        }
    }
    /* events left over: the run did not reproduce the recorded one, a failed check */
    if (o->replay && !wbl_replay_end(L, rerr, sizeof rerr)) {
        fprintf(stderr, "wobble: --replay: %s\n", rerr);
        report_error(rep, rerr);
        if (code == EXIT_PASS) code = EXIT_FAILED;
    }
    wb_rt_pause_watchdog(L, 1);  /* finishing the file has the encoder's own timeouts */
    if (o->record && !wbl_record_end(L, rerr, sizeof rerr)) {
        fprintf(stderr, "wobble: --record: %s\n", rerr);
        if (code == EXIT_PASS) report_error(rep, rerr), code = EXIT_SCRIPT;
    }
    wb_rt_pause_watchdog(L, 0);
    report_take(rep, L);
    int late = wb_rt_close(L);
    if (late == WB_RT_LATE_TIME && code < EXIT_BUDGET) {  /* finalizers ran past the limit */
        report_error(rep, "time limit exceeded while the finalizers (__gc) ran at the end");
        fprintf(stderr, "%s: time limit of %g s exceeded (--time-limit SECONDS) while the finalizers (__gc) ran at the end\n",
                path, o->rt.time_budget);
        code = EXIT_BUDGET;
    } else if (late == WB_RT_LATE_MEMORY && code < EXIT_BUDGET) {
        report_error(rep, "memory limit exceeded while the finalizers (__gc) ran at the end");
        fprintf(stderr, "%s: memory limit of %d MB exceeded (--memory-limit MB) while the finalizers (__gc) ran at the end\n",
                path, (int)(o->rt.memory_budget >> 20));
        code = EXIT_BUDGET;
    }
    return code;
}

/* wobble run: the scene, then OUTDIR/result.json (for `wobble collect`) when --out names
 * the folder (a sweep's runs always do): a run typed by hand leaves no file it did not
 * ask for. The file is first written saying "running", so a run ended from outside (a
 * signal, the watchdog past --time-limit, the OOM killer, Slurm) leaves a run that
 * started and never finished, which collect shows as crashed. */
static int cmd_run(const opts *o, const char *path) {
    if (!o->out_given) return run_scene(o, path, NULL);
    run_report rep = { 0 };
    char err[PATH_MAX + 128], dir[PATH_MAX];
    struct timespec t0, t1;
    clock_gettime(CLOCK_MONOTONIC, &t0);
    wbl_run_info info = { o->rt.out_dir, path, o->sets, o->nsets, -1, 0, NULL };
    snprintf(dir, sizeof dir, "%s/", o->rt.out_dir);  /* make_parents makes the folder itself */
    if (make_parents(dir, err, sizeof err) == 0) wbl_result_write(NULL, &info, err, sizeof err);
    int code = run_scene(o, path, &rep);
    clock_gettime(CLOCK_MONOTONIC, &t1);
    if (code != EXIT_PASS && !rep.error[0])
        report_error(&rep, code == EXIT_FAILED ? "a test case failed (see the TAP output)"
                           : code == EXIT_BUDGET ? "a time or memory budget was exceeded" : "the run failed");
    info.exit_code = code;
    info.wall_time = (double)(t1.tv_sec - t0.tv_sec) + (t1.tv_nsec - t0.tv_nsec) * 1e-9;
    info.error = rep.error[0] ? rep.error : NULL;
    if (!rep.taken) rep.taken = wbl_result_take(NULL);
    /* the output folder cannot be written: the run cannot report, an input error */
    if (!wbl_result_write(rep.taken, &info, err, sizeof err)) {
        fprintf(stderr, "wobble: --out: %s\n", err);
        if (code == EXIT_PASS) code = EXIT_SCRIPT;
    }
    return code;
}

/* ---- view ----------------------------------------------------------------------------------- */

static lua_State *view_open(void *host, const char **err)
{
    const opts *o = host;
    return open_state(o, o->pos[0], 0, err);
}

static int cmd_view(opts *o)
{
    if (o->npos != 1) return usage_error("%s", o->npos ? "view takes one scene script" : "view needs a scene script");
    wb_view_opts *v = &o->view;
    v->scene = o->pos[0];
    v->frames = o->rt.frame_cap;   /* w:run stops there too, as with run */
    if (!v->width) v->width = 960, v->height = 540;
    v->open = view_open;
    o->rt.on_read = wb_view_file_read;   /* --watch: meshes and configs the scene reads too */
    v->print_error = print_error;
    v->host = o;
    o->rt.quiet = 1;   /* no progress bar under the window */
    return wb_view_main(v);
}

/* the benchmark scenes: installed beside the Lua library (share/wobble/bench, so an
 * installed command needs no source tree), else tests/bench of the project */
static int bench_dir(char dir[PATH_MAX]) {
    const char *lib = wb_rt_lib_dir(), *root = wb_rt_project_root();
    char p[PATH_MAX];
    struct stat st;
    if (lib && snprintf(p, sizeof p, "%s/../bench", lib) < (int)sizeof p && realpath(p, dir) &&
        stat(dir, &st) == 0 && S_ISDIR(st.st_mode))
        return 0;
    if (root && snprintf(p, sizeof p, "%s/tests/bench", root) < (int)sizeof p && realpath(p, dir) &&
        stat(dir, &st) == 0 && S_ISDIR(st.st_mode))
        return 0;
    return -1;
}

static int cmd_bench(opts *o) {
    char dir[PATH_MAX], cwd[PATH_MAX];
    if (o->rt.frame_cap == 0) return usage_error("%s", "bench --frames expects at least 1 frame");
    if (bench_dir(dir)) {
        fprintf(stderr, "wobble: cannot find the benchmark scenes (share/wobble/bench of an installed wobble, "
                        "or tests/bench of the project)\n");
        return EXIT_SCRIPT;
    }
    list files = { 0 };
    collect(dir, &files, 1);
    if (files.n > 1) qsort(files.v, (size_t)files.n, sizeof *files.v, cmp_str);
    if (files.n == 0) {
        fprintf(stderr, "wobble: no benchmark scenes in %s\n", dir);
        list_free(&files);
        return EXIT_SCRIPT;
    }
    /* a benchmark scene reads wobble.args.json and wobble.args.frames (--frames N wins
     * over --set frames=M: the later value is kept) */
    static char frames[40];
    if (o->json) o->sets[o->nsets++] = "json=true";
    if (o->rt.frame_cap > 0) {
        snprintf(frames, sizeof frames, "frames=%lld", (long long)o->rt.frame_cap);
        o->sets[o->nsets++] = frames;
    }
    size_t cl = getcwd(cwd, sizeof cwd) ? strlen(cwd) : 0;
    int code = EXIT_PASS;
    for (int i = 0; i < files.n; i++) {
        const char *p = files.v[i];
        if (cl > 1 && !strncmp(p, cwd, cl) && p[cl] == '/') p += cl + 1;  /* shorter messages */
        if (!o->json) {
            printf("# %s\n", p);
            fflush(stdout);
        }
        int c = run_scene(o, p, NULL);
        if (c > code) code = c;
    }
    list_free(&files);
    return code;
}

int main(int argc, char **argv) {
    setvbuf(stdout, NULL, _IOLBF, 0);  /* TAP lines and script output in order through a pipe */
    wbio_clean_on_signals();  /* Ctrl-C, kill, a closed terminal: no half-written file left */
    if (argc < 2) {
        fputs(usage_text, stderr);
        return EXIT_SCRIPT;
    }
    const char *cmd = argv[1];
    if (!strcmp(cmd, "--version") || !strcmp(cmd, "-v")) {
        printf("wobble %s\n", WB_VERSION);
        return EXIT_PASS;
    }
    if (!strcmp(cmd, "--help") || !strcmp(cmd, "-h") || !strcmp(cmd, "help")) {
        fputs(usage_text, stdout);
        return EXIT_PASS;
    }
    if (!strcmp(cmd, "sweep")) return wb_cmd_sweep(argc, argv);
    if (!strcmp(cmd, "collect")) return wb_cmd_collect(argc, argv);
    if (strcmp(cmd, "run") && strcmp(cmd, "test") && strcmp(cmd, "bench") && strcmp(cmd, "view"))
        return usage_error(cmd[0] == '-' ? "unknown option %s" : "unknown command '%s'", cmd);
    opts o;
    int code = parse_opts(argc, argv, cmd, &o);
    if (code == EXIT_PASS) {
        if (!strcmp(cmd, "run")) {
            if (o.npos != 1) code = usage_error("%s", o.npos ? "run takes one scene script" : "run needs a scene script");
            /* run draws nothing else: a --size alone would be silently ignored */
            else if (o.view.width && !o.record) code = usage_error("%s", "--size sets --record's frame size: give --record OUT too");
            else if (o.samples && !o.record) code = usage_error("%s", "--samples sets --record's antialiasing: give --record OUT too");
            else code = cmd_run(&o, o.pos[0]);
        } else if (!strcmp(cmd, "view")) {
            code = cmd_view(&o);
        } else if (!strcmp(cmd, "test")) {
            code = cmd_test(&o);
        } else if (o.npos) {
            code = usage_error("bench takes no file names: it runs tests/bench/*.lua, got '%s'", o.pos[0]);
        } else {
            code = cmd_bench(&o);
        }
    }
    free(o.sets);
    free(o.pos);
    return code;
}
