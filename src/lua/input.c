/* input.c: live input as a test (input.h, issue 11). The recorder does each grab, move and
 * release on the world and logs it with the frame it came after; the replay reads such a
 * log back and applies its events from a frame hook after the same frames, so that a
 * headless run reproduces the live one bit for bit (the same w:hash()). */
#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#include <cJSON.h>

#include "input.h"
#include "io/json.h"
#include "util.h"

enum { EV_GRAB, EV_MOVE, EV_RELEASE };
static const char *const type_names[] = { "grab", "move", "release", NULL };

/* one event; `grab` is the 1-based ordinal of its grab event among the log's grabs */
typedef struct ev {
    int64_t frame;
    int world, type;
    int32_t particle;   /* grab: 0-based */
    int64_t grab;       /* move, release */
    wb_real target[3];  /* grab, move */
    wb_real compliance; /* grab */
    int line, col;      /* replay: where the event is in the file (0: unknown) */
} ev;

/* a growing array of events */
typedef struct evs { ev *v; int64_t n, cap; } evs;

static bool evs_push(evs *e, const ev *x)
{
    if (e->n == e->cap) {
        int64_t cap = e->cap ? 2 * e->cap : 64;
        ev *v = (size_t)cap < SIZE_MAX / sizeof *v ? realloc(e->v, (size_t)cap * sizeof *v) : NULL;
        if (!v) return false;
        e->v = v;
        e->cap = cap;
    }
    e->v[e->n++] = *x;
    return true;
}

/* ---- recording -------------------------------------------------------------------------- */

/* a grab the log knows: which world, which core id, its ordinal; released ones stay,
 * dead, so that a reused slot (same index, newer generation) is never confused */
typedef struct lgrab { const wb_world *w; wb_grab_id id; int64_t ord; bool live; } lgrab;

struct wbl_input_log {
    evs e;
    lgrab *g;
    int64_t ng, gcap;
    bool lost;          /* an event could not be logged (out of memory): saving fails */
};

wbl_input_log *wbl_input_log_create(void)
{
    return calloc(1, sizeof(wbl_input_log));
}

void wbl_input_log_clear(wbl_input_log *log)
{
    if (!log) return;
    free(log->e.v);
    free(log->g);
    memset(log, 0, sizeof *log);
}

void wbl_input_log_destroy(wbl_input_log *log)
{
    wbl_input_log_clear(log);
    free(log);
}

int64_t wbl_input_log_events(const wbl_input_log *log)
{
    return log ? log->e.n : 0;
}

/* the live logged grab of w with id g, or NULL (a grab the log never saw) */
static lgrab *find_grab(wbl_input_log *log, const wb_world *w, wb_grab_id g)
{
    for (int64_t i = log->ng - 1; i >= 0; i--)
        if (log->g[i].live && log->g[i].w == w && log->g[i].id.index == g.index && log->g[i].id.gen == g.gen)
            return &log->g[i];
    return NULL;
}

bool wbl_input_grab(wbl_input_log *log, wb_world *w, int world, int32_t particle, const wb_real target[3],
                    wb_real compliance, wb_grab_id *out, char *err, size_t n)
{
    const int64_t frame = wb_world_frame(w);
    if (frame < 1) {
        /* the replay applies events after a frame: one before the first has no frame */
        snprintf(err, n, "grab: the world has not stepped a frame yet");
        return false;
    }
    if (world < 1) {
        snprintf(err, n, "grab: world ordinal %d (1-based) expected", world);
        return false;
    }
    const int32_t np = wb_particle_count(w);
    if (particle < 0 || particle >= np) {
        snprintf(err, n, "grab: particle %lld out of range (the world has %d)", (long long)particle + 1, (int)np);
        return false;
    }
    if (!isfinite(target[0]) || !isfinite(target[1]) || !isfinite(target[2]) || !(compliance >= 0) ||
        !isfinite(compliance)) {
        snprintf(err, n, "grab: the target must be finite and the compliance finite and >= 0");
        return false;
    }
    /* room first, so that a grab done is a grab logged */
    if (log && log->ng == log->gcap) {
        int64_t cap = log->gcap ? 2 * log->gcap : 16;
        lgrab *g = realloc(log->g, (size_t)cap * sizeof *g);
        if (!g) {
            snprintf(err, n, "grab: out of memory");
            return false;
        }
        log->g = g;
        log->gcap = cap;
    }
    ev x = { .frame = frame, .world = world, .type = EV_GRAB, .particle = particle, .compliance = compliance };
    memcpy(x.target, target, sizeof x.target);
    if (log && !evs_push(&log->e, &x)) {
        snprintf(err, n, "grab: out of memory");
        return false;
    }
    wb_status st = WB_OK;
    wb_grab_id id = wb_grab_add(w, particle, target, compliance, &st);
    if (st != WB_OK) {
        if (log) log->e.n--;
        snprintf(err, n, "grab: %s", st == WB_ERR_NOMEM ? "out of memory" : wb_last_error());
        return false;
    }
    if (log) {
        log->g[log->ng] = (lgrab){ w, id, log->ng + 1, true };  /* every grab logged is in g */
        log->ng++;
    }
    if (out) *out = id;
    return true;
}

/* the event of a move or release of a logged grab (an unlogged grab is done, not logged:
 * the replay could not name it) */
static void log_event(wbl_input_log *log, wb_world *w, int world, int type, wb_grab_id g, const wb_real *target)
{
    if (!log) return;
    lgrab *lg = find_grab(log, w, g);
    if (!lg) return;
    ev x = { .frame = wb_world_frame(w), .world = world, .type = type, .grab = lg->ord };
    if (target) memcpy(x.target, target, sizeof x.target);
    if (!evs_push(&log->e, &x)) log->lost = true;
    if (type == EV_RELEASE) lg->live = false;
}

void wbl_input_move(wbl_input_log *log, wb_world *w, int world, wb_grab_id g, const wb_real target[3])
{
    if (!wb_grab_valid(w, g) || !isfinite(target[0]) || !isfinite(target[1]) || !isfinite(target[2])) return;
    wb_grab_move(w, g, target);
    log_event(log, w, world, EV_MOVE, g, target);
}

void wbl_input_release(wbl_input_log *log, wb_world *w, int world, wb_grab_id g)
{
    if (!wb_grab_valid(w, g)) return;
    wb_grab_release(w, g);
    log_event(log, w, world, EV_RELEASE, g, NULL);
}

/* a number as "%.17g", which strtod (cJSON's reader) turns back into the same double */
static cJSON *num(double x)
{
    char b[40];
    snprintf(b, sizeof b, "%.17g", x);
    return cJSON_CreateRaw(b);
}

static bool add_num(cJSON *o, const char *key, double x)
{
    cJSON *v = num(x);
    return v && cJSON_AddItemToObject(o, key, v);
}

static bool add_vec(cJSON *o, const char *key, const wb_real v[3])
{
    cJSON *a = cJSON_AddArrayToObject(o, key);
    for (int i = 0; a && i < 3; i++) {
        cJSON *x = num((double)v[i]);
        if (!x || !cJSON_AddItemToArray(a, x)) return false;
    }
    return a != NULL;
}

static cJSON *log_json(const wbl_input_log *log, const char *scene)
{
    cJSON *root = cJSON_CreateObject(), *arr;
    if (!root || !cJSON_AddStringToObject(root, "format", "wobble-input") || !add_num(root, "version", 1) ||
        !cJSON_AddStringToObject(root, "scene", scene ? scene : "") || !(arr = cJSON_AddArrayToObject(root, "events")))
        goto fail;
    for (int64_t i = 0; log && i < log->e.n; i++) {
        const ev *x = &log->e.v[i];
        cJSON *o = cJSON_CreateObject();
        if (!o || !cJSON_AddItemToArray(arr, o)) {
            cJSON_Delete(o);
            goto fail;
        }
        if (!add_num(o, "frame", (double)x->frame) || !add_num(o, "world", x->world) ||
            !cJSON_AddStringToObject(o, "type", type_names[x->type]))
            goto fail;
        bool ok = x->type == EV_GRAB ? add_num(o, "particle", (double)x->particle + 1) && add_vec(o, "target", x->target) &&
                                           add_num(o, "compliance", (double)x->compliance)
                                     : add_num(o, "grab", (double)x->grab) &&
                                           (x->type == EV_RELEASE || add_vec(o, "target", x->target));
        if (!ok) goto fail;
    }
    return root;
fail:
    cJSON_Delete(root);
    return NULL;
}

bool wbl_input_log_save(const wbl_input_log *log, const char *path, const char *scene, char *err, size_t n)
{
    if (log && log->lost) {
        snprintf(err, n, "%s: some input could not be logged (out of memory); nothing written", path);
        return false;
    }
    cJSON *root = log_json(log, scene);
    char *text = root ? cJSON_Print(root) : NULL;
    cJSON_Delete(root);
    if (!text) {
        snprintf(err, n, "%s: out of memory", path);
        return false;
    }
    FILE *f = fopen(path, "w");
    if (!f) {
        snprintf(err, n, "%s: %s", path, strerror(errno));
        free(text);
        return false;
    }
    bool ok = fputs(text, f) >= 0 && fputc('\n', f) != EOF;
    int e = errno;
    if (fclose(f) != 0 && ok) ok = false, e = errno;
    free(text);
    if (!ok) snprintf(err, n, "%s: %s", path, strerror(e));
    return ok;
}

/* ---- replay ------------------------------------------------------------------------------- */

bool wbl_replay_begin(lua_State *L, const char *path, char *err, size_t n)
{
    (void)L;
    snprintf(err, n, "%s: --replay is not implemented yet", path);
    return false;
}

bool wbl_replay_end(lua_State *L, char *err, size_t n)
{
    (void)L;
    (void)err;
    (void)n;
    return true;
}
