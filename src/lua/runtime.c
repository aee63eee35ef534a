/* runtime.c: what runs around a scene script. The sandbox, so that a scene from anywhere is
 * safe to run (no process control, no bytecode, no debug library, file access through path
 * rules), the budgets (memory through the allocator, wall time through a count hook, after
 * every frame and a watchdog thread for what hooks never see) and the discovery of the Lua
 * library folder. */
#include "wobble_lua.h"
#include "sandbox.h"
#include "io/io.h"

#include <lualib.h>

#include <dirent.h>
#include <errno.h>
#include <fcntl.h>
#include <limits.h>
#include <malloc.h>
#include <poll.h>
#include <pthread.h>
#include <signal.h>
#include <stdatomic.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <time.h>
#include <unistd.h>

#define HOOK_COUNT (1 << 20)          /* instructions between two budget checks */
#define MEM_SLACK ((size_t)64 << 20)  /* at most granted past the memory limit so the error can be reported */
#define GRACE_MIN 5.0                 /* the watchdog's grace: 5 s or 10% of the limit, the longer */
#define GRACE_PART 0.1
#define MEM_GRACE 3.0                 /* after a spent memory budget: seconds to come back to a check */
#define REARM_SIGNAL SIGURG           /* ignored by default: one arriving after close does nothing */

/* The watchdog: a thread that sleeps until the deadline of --time-limit, raises
 * `expired` (the budget checks read it) and, when the script has not come back to a
 * budget check a grace period later (a __gc finalizer, which Lua runs without hooks;
 * one long C call such as a backtracking string.find; a blocking read), ends the
 * process itself: children killed, `words` on stdout, `msg` on stderr, exit code 3.
 * The grace leaves room for checks that do come, only late: a step polls once per
 * substep, and one substep of a heavy scene under sanitizers takes seconds. */
typedef struct watchdog {
    pthread_t th;
    int on;                           /* the thread runs */
    int sync;                         /* mu and cv are made */
    pthread_mutex_t mu;               /* guards what follows but `expired` */
    pthread_cond_t cv;                /* CLOCK_MONOTONIC; wakes the thread for stop and pause */
    int stop;                         /* wb_rt_close: the thread ends */
    int started;                      /* the thread is in its loop (watchdog_start waits for it) */
    int paused;                       /* the command line's own cleanup runs (wb_rt_pause_watchdog) */
    double resumed;                   /* the last end of a pause: the grace counts from it */
    double deadline, grace;           /* deadline < 0: no time budget */
    double spent_at;                  /* when the memory budget was spent (< 0: it is not) */
    atomic_int expired;               /* the deadline passed */
    pthread_t main;                   /* the thread running the script: REARM_SIGNAL goes to it */
    int rearm;                        /* this runtime owns REARM_SIGNAL's handler (one runtime at a time) */
    struct sigaction old_sa;          /* the handler before ours */
    char msg[PATH_MAX + 512];         /* made in advance: the thread only writes it */
    char mem_msg[PATH_MAX + 512];     /* the same for a spent memory budget */
    char words[2048];                 /* wb_rt_set_last_words */
} watchdog;

typedef struct rt_state {
    wb_runtime pub;                   /* first: what wb_rt_get hands out */
    wb_sandbox sb;                    /* the file rules and the folders */
    lua_State *L;                     /* the main thread: its hook is armed when the budget is spent */
    int mem_refused;                  /* the last growing allocation was refused: ref_* was the request */
    void *ref_ptr;
    size_t ref_old, ref_new;
    int mem_over;                     /* a refusal was final: the budget is spent, for good */
    int budget_hit;                   /* a budget error was raised; it is raised again at every step */
    double t0;                        /* wall clock at wb_rt_open */
    char budget_msg[256];
    watchdog wd;
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
    static wb_runtime plain = { ".", "out", NULL, 1, 0, 0, 0, -1, 0, 0, { 0, 0 }, NULL, NULL, NULL, NULL };
    rt_state *rt = rt_from(L);
    return rt ? &rt->pub : &plain;
}

static double now(void) {
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + ts.tv_nsec * 1e-9;
}

/* ---- budgets ------------------------------------------------------------------------- */

static void rt_hook(lua_State *L, lua_Debug *ar);
static void mem_alarm(rt_state *rt);

/* the memory budget is spent: for good, whatever the script catches. The main thread
 * checks at its next instruction (a loop of big allocations would otherwise reach the
 * count hook only after minutes); code that runs without hooks (a __gc finalizer) has
 * the watchdog's grace to come back */
static void spend(rt_state *rt) {
    if (rt->mem_over) return;
    rt->mem_over = 1;
    /* lua_sethook only sets fields: safe here, as in a signal handler */
    if (rt->L) lua_sethook(rt->L, rt_hook, LUA_MASKCOUNT, 1);
    mem_alarm(rt);
}

/* what a block really takes of the heap: its usable size and malloc's header (small
 * blocks: a 33-byte string is a 48-byte chunk; the requested sizes alone let the
 * process grow half as much again as the budget) */
#define CHUNK_HEADER sizeof(size_t)
static size_t chunk_bytes(void *p) { return p ? malloc_usable_size(p) + CHUNK_HEADER : 0; }

/* past the limit, what reporting the error may take: a sixteenth of the limit, 4 to 64 MB */
static size_t mem_slack(size_t limit) {
    size_t s = limit / 16;
    return s < ((size_t)4 << 20) ? (size_t)4 << 20 : s > MEM_SLACK ? MEM_SLACK : s;
}

static void *rt_alloc(void *ud, void *ptr, size_t osize, size_t nsize) {
    rt_state *rt = ud;
    size_t old = ptr ? osize : 0;  /* for a new block osize is a type tag */
    size_t held = chunk_bytes(ptr);
    if (nsize == 0) {
        free(ptr);
        rt->pub.memory.used -= held;
        return NULL;
    }
    size_t limit = rt->pub.memory_budget;
    if (limit && nsize > old) {
        /* Lua answers a refusal by collecting garbage and asking again at once, the
         * same request; any other request next means that the refusal stood (lauxlib's
         * buffers ask once: string.rep, table.concat) and a memory error was raised,
         * which pcall may have caught. The budget is spent then. */
        if (rt->mem_refused && (ptr != rt->ref_ptr || old != rt->ref_old || nsize != rt->ref_new)) spend(rt);
        if (rt->mem_over) limit = limit > SIZE_MAX - MEM_SLACK ? SIZE_MAX : limit + mem_slack(limit);
        /* one account for the Lua heap and every world's arrays */
        size_t need = nsize > SIZE_MAX - 2 * CHUNK_HEADER ? SIZE_MAX : nsize + 2 * CHUNK_HEADER;
        size_t others = rt->pub.memory.used - held;
        if (need > limit || others > limit - need) {
            if (rt->mem_refused) spend(rt);  /* the second try refused too */
            rt->mem_refused = 1;
            rt->ref_ptr = ptr, rt->ref_old = old, rt->ref_new = nsize;
            return NULL;
        }
    }
    void *p = realloc(ptr, nsize);
    if (!p) return NULL;
    rt->pub.memory.used = rt->pub.memory.used - held + chunk_bytes(p);
    if (nsize > old) rt->mem_refused = 0;
    return p;
}

/* the watchdog's flag, or the clock when no watchdog runs (it could not start) */
static int time_over(const rt_state *rt) {
    if (rt->pub.time_budget <= 0) return 0;
    return atomic_load_explicit(&rt->wd.expired, memory_order_relaxed) || now() - rt->t0 > rt->pub.time_budget;
}

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
        /* and what runs without hooks has a grace to end (the time limit's watchdog has
         * its own) */
        if (!time_over(rt)) mem_alarm(rt);
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
    if (time_over(rt))
        wb_rt_budget_error(L, "time limit of %g s exceeded (--time-limit SECONDS)", rt->pub.time_budget);
}

void wb_rt_check_budgets(lua_State *L) {
    rt_state *rt = rt_from(L);
    if (rt) check_budgets(L, rt);
}

/* called from inside a step, outside Lua: reads the clock and flags only */
static int rt_interrupt(void *ud) {
    const rt_state *rt = ud;
    return rt->budget_hit || rt->mem_over || time_over(rt);
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

/* ---- the watchdog -------------------------------------------------------------------- */

/* write everything unless the reader stops taking it: a full pipe must not keep the
 * process alive past its budget */
static void say(int fd, const char *s) {
    size_t n = strlen(s);
    while (n) {
        struct pollfd p = { fd, POLLOUT, 0 };
        if (poll(&p, 1, 1000) <= 0) return;
        ssize_t k = write(fd, s, n);
        if (k < 0 && errno == EINTR) continue;
        if (k <= 0) return;
        s += k;
        n -= (size_t)k;
    }
}

/* SIGKILL every child of this process (the encoder with its process group, ffprobe,
 * what an --unsafe script started), found in /proc: a zombie keeps its pid until we
 * reap it, so no pid read here can belong to a stranger yet */
static void kill_children(void) {
    const long me = (long)getpid();
    DIR *d = opendir("/proc");
    if (!d) return;
    struct dirent *e;
    while ((e = readdir(d))) {
        char *end, p[64], buf[512];
        long pid = strtol(e->d_name, &end, 10);
        if (*end || pid <= 0) continue;
        snprintf(p, sizeof p, "/proc/%ld/stat", pid);
        int fd = open(p, O_RDONLY | O_CLOEXEC);
        if (fd < 0) continue;
        ssize_t k = read(fd, buf, sizeof buf - 1);
        close(fd);
        if (k <= 0) continue;
        buf[k] = 0;
        /* "pid (comm) state ppid pgrp ...": comm may hold anything but the last ')' */
        char *rp = strrchr(buf, ')'), state;
        long ppid, pgrp;
        if (!rp || sscanf(rp + 1, " %c %ld %ld", &state, &ppid, &pgrp) != 3 || ppid != me) continue;
        if (pgrp == pid) kill(-(pid_t)pid, SIGKILL);  /* a group leader: whatever it started too */
        kill((pid_t)pid, SIGKILL);
    }
    closedir(d);
}

/* the grace period is over: the script cannot be stopped from inside, so end it */
static _Noreturn void end_process(watchdog *wd, const char *msg) {
    kill_children();
    wbio_remove_temporaries();  /* a file being written keeps its old version */
    /* what the script printed and stdio still holds, unless the main thread is inside
     * a write (its lock taken) */
    struct pollfd p = { STDOUT_FILENO, POLLOUT, 0 };
    if (poll(&p, 1, 1000) > 0 && ftrylockfile(stdout) == 0) {
        fflush_unlocked(stdout);
        funlockfile(stdout);
    }
    say(STDOUT_FILENO, wd->words);
    say(STDERR_FILENO, msg);
    _exit(3);  /* exit code 3: a budget was exceeded */
}

/* The state whose hook the deadline re-arms. At the deadline the watchdog signals the
 * script's thread, whose handler sets the count hook to 1 instruction: a loop whose
 * every few instructions call a slow C function (string.rep of megabytes) would
 * otherwise reach the next check only after 2^20 of them. Lua allows lua_sethook in a
 * signal handler (ldebug.c) but not from another thread; the handler runs on the
 * script's thread, so wb_rt_close clearing the pointer first is enough. */
static lua_State *_Atomic rearm_state;

static void rearm(int sig) {
    (void)sig;
    int e = errno;
    lua_State *L = atomic_load(&rearm_state);
    if (L) lua_sethook(L, rt_hook, LUA_MASKCOUNT, 1);
    errno = e;
}

static struct timespec monotonic_at(double t) {
    struct timespec ts;
    ts.tv_sec = (time_t)t;
    ts.tv_nsec = (long)((t - (double)ts.tv_sec) * 1e9);
    if (ts.tv_nsec >= 1000000000) ts.tv_sec++, ts.tv_nsec -= 1000000000;
    if (ts.tv_nsec < 0) ts.tv_nsec = 0;
    return ts;
}

static void *watchdog_main(void *arg) {
    watchdog *wd = arg;
    pthread_mutex_lock(&wd->mu);
    wd->started = 1;
    pthread_cond_broadcast(&wd->cv);
    while (!wd->stop) {
        double t = now(), wake = -1;  /* -1: until woken */
        if (wd->deadline < 0) {
            /* no time budget: the thread is here for a spent memory budget */
        } else if (!atomic_load(&wd->expired)) {
            if (t >= wd->deadline) {
                /* the hook, the step's interrupt and the probes read this */
                atomic_store(&wd->expired, 1);
                if (wd->rearm) pthread_kill(wd->main, REARM_SIGNAL);
                continue;
            }
            wake = wd->deadline;
        } else if (!wd->paused) {
            double end = (wd->resumed > wd->deadline ? wd->resumed : wd->deadline) + wd->grace;
            if (t >= end) end_process(wd, wd->msg);
            wake = end;
        }
        if (wd->spent_at >= 0 && !wd->paused) {
            double end = (wd->resumed > wd->spent_at ? wd->resumed : wd->spent_at) + MEM_GRACE;
            if (t >= end) end_process(wd, wd->mem_msg);
            if (wake < 0 || end < wake) wake = end;
        }
        if (wake < 0) {
            pthread_cond_wait(&wd->cv, &wd->mu);
        } else {
            struct timespec ts = monotonic_at(wake);
            pthread_cond_timedwait(&wd->cv, &wd->mu, &ts);
        }
    }
    pthread_mutex_unlock(&wd->mu);
    return NULL;
}

/* the lock and the condition, made with the state: a spent memory budget may start the
 * thread at any time */
static void watchdog_init(rt_state *rt) {
    watchdog *wd = &rt->wd;
    wd->deadline = -1;
    wd->spent_at = -1;
    snprintf(wd->mem_msg, sizeof wd->mem_msg,
             "%s: memory limit of %.0f MB exceeded (--memory-limit MB); the script did not come back to a budget "
             "check within %g s (a __gc finalizer that goes on after its allocations were refused), so wobble "
             "ended it\n",
             rt->pub.script ? rt->pub.script : "wobble", rt->pub.memory_budget / 1048576.0, MEM_GRACE);
    pthread_condattr_t ca;
    if (pthread_condattr_init(&ca) != 0) return;
    int e = pthread_condattr_setclock(&ca, CLOCK_MONOTONIC);
    if (!e) e = pthread_cond_init(&wd->cv, &ca);
    pthread_condattr_destroy(&ca);
    if (e) return;
    if (pthread_mutex_init(&wd->mu, NULL) != 0) {
        pthread_cond_destroy(&wd->cv);
        return;
    }
    wd->sync = 1;
}

/* the thread, once (wd->mu held); 0 when it could not start */
static int watchdog_thread(watchdog *wd) {
    if (wd->on) return 1;
    if (!wd->sync) return 0;
    /* signals (SIGINT, SIGPIPE of the script's writes) stay the main thread's */
    sigset_t all, old;
    sigfillset(&all);
    pthread_sigmask(SIG_SETMASK, &all, &old);
    int e = pthread_create(&wd->th, NULL, watchdog_main, wd);
    pthread_sigmask(SIG_SETMASK, &old, NULL);
    if (e) return 0;
    /* Back only once the thread waits in its loop: a thread still starting (its stack,
     * its TLS, a sanitizer's bookkeeping) may hold an allocator lock, and a process that
     * forks then (the mesh importer and tetgen run in forked children, without exec) gives
     * the child that lock held for ever. Measured under make asan: 5 imports in 150, run
     * at once after the start, hung in the child on ASan's allocator mutex; none since.
     * (The caller holds wd->mu: the wait lets the thread take it.) */
    while (!wd->started) pthread_cond_wait(&wd->cv, &wd->mu);
    wd->on = 1;
    return 1;
}

/* only with a time budget; without a thread (it could not start) the hook and the
 * clock hold the budget wherever they run */
static void watchdog_start(rt_state *rt, lua_State *L) {
    watchdog *wd = &rt->wd;
    double limit = rt->pub.time_budget;
    if (limit <= 0 || !wd->sync) return;
    wd->grace = limit * GRACE_PART > GRACE_MIN ? limit * GRACE_PART : GRACE_MIN;
    snprintf(wd->msg, sizeof wd->msg,
             "%s: time limit of %g s exceeded (--time-limit SECONDS); the script did not come back to a budget "
             "check within the grace period of %g s (a __gc finalizer, one long C call such as a backtracking "
             "string pattern, or a read that never ends), so wobble ended it\n",
             rt->pub.script ? rt->pub.script : "wobble", limit, wd->grace);
    /* the re-arm signal, when no other runtime has it (SA_RESTART: reads go on) */
    lua_State *none = NULL;
    wd->main = pthread_self();
    if (atomic_compare_exchange_strong(&rearm_state, &none, L)) {
        struct sigaction sa;
        memset(&sa, 0, sizeof sa);
        sa.sa_handler = rearm;
        sa.sa_flags = SA_RESTART;
        sigemptyset(&sa.sa_mask);
        if (sigaction(REARM_SIGNAL, &sa, &wd->old_sa) == 0) wd->rearm = 1;
        else atomic_store(&rearm_state, NULL);
    }
    wd->deadline = rt->t0 + limit;
    pthread_mutex_lock(&wd->mu);
    const int started = watchdog_thread(wd);
    pthread_mutex_unlock(&wd->mu);
    if (!started) {
        wd->deadline = -1;
        if (wd->rearm) {
            atomic_store(&rearm_state, NULL);
            sigaction(REARM_SIGNAL, &wd->old_sa, NULL);
            wd->rearm = 0;
        }
    }
}

/* a memory budget was spent: the script has MEM_GRACE seconds (not counting pauses) to
 * come back to a check and end; the thread starts now if no time budget runs it */
static void mem_alarm(rt_state *rt) {
    watchdog *wd = &rt->wd;
    if (!wd->sync || !rt->pub.memory_budget || wd->spent_at >= 0) return;
    pthread_mutex_lock(&wd->mu);
    wd->spent_at = now();
    if (watchdog_thread(wd)) pthread_cond_signal(&wd->cv);
    pthread_mutex_unlock(&wd->mu);
}

static void watchdog_stop(rt_state *rt) {
    watchdog *wd = &rt->wd;
    if (wd->on) {
        pthread_mutex_lock(&wd->mu);
        wd->stop = 1;
        pthread_cond_signal(&wd->cv);
        pthread_mutex_unlock(&wd->mu);
        pthread_join(wd->th, NULL);
        wd->on = 0;
    }
    if (wd->rearm) sigaction(REARM_SIGNAL, &wd->old_sa, NULL);  /* rearm_state is NULL by now */
    wd->rearm = 0;
    if (wd->sync) {
        pthread_mutex_destroy(&wd->mu);
        pthread_cond_destroy(&wd->cv);
        wd->sync = 0;
    }
}

void wb_rt_pause_watchdog(lua_State *L, int paused) {
    rt_state *rt = rt_from(L);
    if (!rt || !rt->wd.sync) return;
    pthread_mutex_lock(&rt->wd.mu);
    rt->wd.paused = paused;
    if (!paused) rt->wd.resumed = now();
    pthread_cond_signal(&rt->wd.cv);
    pthread_mutex_unlock(&rt->wd.mu);
}

void wb_rt_set_last_words(lua_State *L, const char *text) {
    rt_state *rt = rt_from(L);
    if (!rt || !rt->wd.sync) return;
    pthread_mutex_lock(&rt->wd.mu);
    snprintf(rt->wd.words, sizeof rt->wd.words, "%s", text ? text : "");
    pthread_mutex_unlock(&rt->wd.mu);
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
                msg = lua_pushfstring(L, "%s:%d: %s", ar.source[0] == '@' ? ar.source + 1 : ar.short_src,
                                      ar.currentline, msg);
                break;
            }
    /* Lua shortens a long file name in a position to "...its end" (LUA_IDSIZE, 60 bytes):
     * a script in a deep folder (a sweep names its scene by its absolute path) would be
     * named by a fragment. The file of a function on the stack whose name ends so is
     * named whole */
    if (!strncmp(msg, "...", 3)) {
        const char *tail = msg + 3, *colon = strchr(tail, ':');
        while (colon && !(colon[1] >= '0' && colon[1] <= '9')) colon = strchr(colon + 1, ':');
        const size_t tn = colon ? (size_t)(colon - tail) : 0;
        for (int level = 0; tn && lua_getstack(L, level, &ar); level++) {
            if (!lua_getinfo(L, "S", &ar) || ar.source[0] != '@') continue;
            const size_t sn = strlen(ar.source + 1);
            if (sn > tn && !strncmp(ar.source + 1 + sn - tn, tail, tn)) {
                msg = lua_pushfstring(L, "%s%s", ar.source + 1, colon);
                break;
            }
        }
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
    wb_progress_wrap_print(L);
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
    rt->sb.on_read = cfg->on_read;
    rt->sb.on_read_ud = cfg->on_read_ud;
    rt->pub.scene_dir = rt->sb.scene;
    rt->pub.out_dir = rt->sb.out;
    rt->pub.lib_dir = rt->sb.lib[0] ? rt->sb.lib : NULL;
    rt->t0 = now();
    watchdog_init(rt);
    lua_State *L = lua_newstate(rt_alloc, rt);
    if (!L) {
        watchdog_stop(rt);
        free(rt);
        return NULL;
    }
    rt->L = L;
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
    watchdog_start(rt, L);
    return L;
}

int wb_rt_close(lua_State *L) {
    if (!L) return 0;
    rt_state *rt = rt_from(L);
    int before = rt && time_over(rt), spent = rt && (rt->mem_over || rt->mem_refused || rt->budget_hit);
    /* no re-arm from here on: the state goes (finalizers run without hooks anyway) */
    if (rt && rt->wd.rearm) atomic_store(&rearm_state, NULL);
    /* finalizers run under both budgets: an allocation past the memory limit fails
     * (Lua reports it as a warning and goes on with the next finalizer), and the
     * watchdog ends one that never returns */
    lua_close(L);
    int late = 0;
    if (rt && !before && time_over(rt)) late = WB_RT_LATE_TIME;
    else if (rt && !spent && (rt->mem_over || rt->mem_refused)) late = WB_RT_LATE_MEMORY;
    if (rt) watchdog_stop(rt);
    free(rt);
    return late;
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
