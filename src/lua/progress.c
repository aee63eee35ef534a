/* progress.c: a one-line progress bar on stderr for long runs. Only on a terminal and
 * without --quiet, so logs and pipes stay clean; redrawn at most ten times a second.
 * One bar per process: a run nested in another's callback keeps the outer bar. */
#include "wobble_lua.h"

#include <stdio.h>
#include <time.h>
#include <unistd.h>

#define BAR_WIDTH 20
#define REDRAW_S 0.1    /* at most ten redraws a second */
#define FIRST_S 0.5     /* short runs never show a bar */

static struct {
    int depth;          /* begin/end nesting; only the outermost draws */
    int on;             /* drawing at all (terminal, not quiet) */
    int drawn;          /* the bar is on the line now */
    int shown;          /* drawn at least once: the end draws it once more, then a newline */
    char what[32];
    int64_t total, done;
    double t0, last;
    char note[96];      /* shown after the label of every bar ("recording out.mp4") */
} bar;

static double now(void) {
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + ts.tv_nsec * 1e-9;
}

static void draw(double t) {
    double el = t - bar.t0, fps = el > 0 ? (double)bar.done / el : 0;
    fprintf(stderr, "\r%s%s%s ", bar.what, bar.note[0] ? ", " : "", bar.note);
    if (bar.total > 0) {
        int64_t fill = bar.done >= bar.total ? BAR_WIDTH : bar.done * BAR_WIDTH / bar.total;
        fputc('[', stderr);
        for (int i = 0; i < BAR_WIDTH; i++) fputc(i < fill ? '#' : ' ', stderr);
        fprintf(stderr, "] %lld/%lld frames  %.0f fps", (long long)bar.done, (long long)bar.total, fps);
        if (fps > 0 && bar.done < bar.total) {
            double eta = (double)(bar.total - bar.done) / fps;
            if (eta < 120) fprintf(stderr, "  ETA %.0fs", eta);
            else fprintf(stderr, "  ETA %.0fm%02.0fs", eta / 60 - 0.5, eta - 60 * (int)(eta / 60));
        }
    } else {  /* open-ended: no bar, no ETA */
        fprintf(stderr, "%lld frames  %.0f fps", (long long)bar.done, fps);
    }
    fputs("\033[K", stderr);  /* clear what a longer line left behind */
    fflush(stderr);
    bar.drawn = bar.shown = 1;
    bar.last = t;
}

void wb_progress_begin(lua_State *L, const char *what, int64_t total, int quiet) {
    (void)L;
    if (bar.depth++ > 0) return;
    bar.on = !quiet && isatty(STDERR_FILENO);
    bar.drawn = bar.shown = 0;
    snprintf(bar.what, sizeof bar.what, "%s", what ? what : "frames");
    bar.total = total;
    bar.done = 0;
    bar.t0 = bar.last = now();
}

void wb_progress_update(lua_State *L, int64_t done) {
    (void)L;
    if (bar.depth != 1 || !bar.on) return;
    bar.done = done;
    double t = now();
    if (t - bar.t0 >= FIRST_S && t - bar.last >= REDRAW_S) draw(t);
}

void wb_progress_end(lua_State *L) {
    (void)L;
    if (bar.depth == 0 || --bar.depth > 0) return;
    if (bar.on && bar.shown) {
        draw(now());
        fputc('\n', stderr);
    }
    bar.on = bar.drawn = bar.shown = 0;
}

/* the scene's print: the bar leaves its line first (else a printed line starts at the
 * bar's end, on the same terminal line) and is drawn again by the next update */
static int progress_print(lua_State *L) {
    if (bar.on && bar.drawn) {
        fputs("\r\033[K", stderr);
        fflush(stderr);
        bar.drawn = 0;
    }
    lua_pushvalue(L, lua_upvalueindex(1));
    lua_insert(L, 1);
    lua_call(L, lua_gettop(L) - 1, LUA_MULTRET);
    return lua_gettop(L);
}

void wb_progress_wrap_print(lua_State *L) {
    lua_getglobal(L, "print");
    if (!lua_isfunction(L, -1)) {
        lua_pop(L, 1);
        return;
    }
    lua_pushcclosure(L, progress_print, 1);
    lua_setglobal(L, "print");
}

void wb_progress_note(lua_State *L, const char *note) {
    (void)L;
    snprintf(bar.note, sizeof bar.note, "%s", note ? note : "");
}
