/* input.c: live input as a test (input.h): a poke replays headless. The recorder does each
 * grab, move and release on the world and logs it with the frame it came after; the replay
 * reads such a log back and applies its events from a frame hook after the same frames, so
 * that a headless run reproduces the live one bit for bit (the same w:hash()). */
#include <errno.h>
#include <fcntl.h>
#include <limits.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#include <cJSON.h>

#include "input.h"
#include "io/io.h"
#include "io/json.h"
#include "util.h"

enum { EV_GRAB, EV_MOVE, EV_RELEASE };
static const char *const type_names[] = { "grab", "move", "release", NULL };

/* one event; `grab` is the 1-based ordinal of its grab event among the log's grabs */
typedef struct ev {
    int64_t frame;
    int world, type;
    int32_t particle;   /* grab: 0-based */
    int64_t grab;       /* move, release; in the replay a grab's own ordinal too */
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
    if (!isfinite(target[0]) || !isfinite(target[1]) || !isfinite(target[2])) {
        snprintf(err, n, "grab: the target must be finite");
        return false;
    }
    const wb_fault f = wb_grab_def_fault(compliance); /* the core's rule (grab.c) */
    if (f.msg) {
        snprintf(err, n, "grab: %s", f.msg);
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
    /* the user's file (--record-input), written whole; a link of theirs is followed */
    char real[PATH_MAX];
    wbio_out f;
    if (n) err[0] = 0;
    if (wbio_follow_link(path, real, sizeof real) || wbio_out_open(&f, AT_FDCWD, real, path, err, n)) {
        if (!*err) snprintf(err, n, "%s: path too long", path);
        free(text);
        return false;
    }
    if (fputs(text, f.f) < 0 || fputc('\n', f.f) == EOF) f.failed = errno ? errno : EIO;
    free(text);
    return wbio_out_commit(&f, path, err, n) == 0;
}

/* ---- world ordinals ------------------------------------------------------------------------ */
static const char ordinals_key = 0; /* registry: {[world userdata] = ordinal (weak keys), n = count} */

int wbl_input_world(lua_State *L, int index)
{
    index = lua_absindex(L, index);
    if (lua_rawgetp(L, LUA_REGISTRYINDEX, &ordinals_key) != LUA_TTABLE) {
        lua_pop(L, 1);
        lua_newtable(L);
        lua_createtable(L, 0, 1); /* weak keys: numbering a world must not keep it alive */
        lua_pushliteral(L, "k");
        lua_setfield(L, -2, "__mode");
        lua_setmetatable(L, -2);
        lua_pushvalue(L, -1);
        lua_rawsetp(L, LUA_REGISTRYINDEX, &ordinals_key);
    }
    lua_pushvalue(L, index);
    lua_Integer ord = lua_rawget(L, -2) == LUA_TNUMBER ? lua_tointeger(L, -1) : 0;
    lua_pop(L, 1);
    if (ord == 0) {
        lua_getfield(L, -1, "n");
        ord = lua_tointeger(L, -1) + 1;
        lua_pop(L, 1);
        lua_pushinteger(L, ord);
        lua_setfield(L, -2, "n");
        lua_pushvalue(L, index);
        lua_pushinteger(L, ord);
        lua_rawset(L, -3);
    }
    lua_pop(L, 1);
    return ord > INT32_MAX ? INT32_MAX : (int)ord;
}

/* ---- replay: reading the file ------------------------------------------------------------------ */

/* a grab event of the file while it is read: its world and the event that released it */
typedef struct fgrab { int world; int64_t released_by; } fgrab;
/* the last frame of each world met while reading (frames of one world never go back) */
typedef struct fworld { int world; int64_t frame, event; } fworld;

typedef struct replay {
    evs e;
    int64_t next;         /* the first event not applied yet */
    wb_grab_id *grab;     /* (ngrabs) the core's id of each grab event once applied */
    const wb_world **grab_w;
    int64_t ngrabs;
    fworld *seen;         /* the last frame each world finished in this run */
    int64_t nseen;
    char *shown;          /* the file's name as given */
} replay;

/* where the last item_pos was: the events come in file order, so each position is
 * counted on from the previous one (from the start each time, 10^5 events took minutes) */
typedef struct lc { int32_t off; int line, col; } lc;

/* line and column of a cJSON item (0, 0 when positions are unknown), as jv_line_col */
static void item_pos(const rd *r, const cJSON *it, lc *cur, int *line, int *col)
{
    *line = *col = 0;
    if (!it || !r->pos || it->valueint < 0 || it->valueint >= r->pos->n) return;
    const int32_t off = r->pos->voff[it->valueint];
    if (off < cur->off) *cur = (lc){ 0, 1, 1 };
    for (int32_t i = cur->off; i < off && r->text[i]; i++) {
        if (r->text[i] == '\n') cur->line++, cur->col = 1;
        else cur->col++;
    }
    cur->off = off;
    *line = cur->line;
    *col = cur->col;
}

static const char *const ev_keys[3][7] = {
    { "frame", "world", "type", "particle", "target", "compliance", NULL },
    { "frame", "world", "type", "grab", "target", NULL },
    { "frame", "world", "type", "grab", NULL },
};

/* events[i] into x; grabs and worlds as read so far */
static int read_event(rd *r, const cJSON *it, const kp *p, int64_t i, fgrab **fg, int64_t *nfg,
                      fworld **fw, int64_t *nfw, lc *cur, ev *x)
{
    if (!cJSON_IsObject(it)) return jv_fail(r, it, 0, p, "object expected, got %s", jv_type_name(it));
    const cJSON *t = cJSON_GetObjectItemCaseSensitive(it, "type");
    kp tp = { p, "type", 0 };
    const char *ts;
    if (!t) return jv_missing(r, it, p, "type");
    if (jv_get_string(r, t, &tp, &ts)) return -1;
    int type = 0;
    while (type_names[type] && strcmp(ts, type_names[type])) type++;
    if (!type_names[type]) return jv_fail(r, t, 0, &tp, "unknown event type '%s' (expected grab, move or release)", ts);
    const cJSON *f[7];
    if (jv_get_object(r, it, p, ev_keys[type], f)) return -1;
    memset(x, 0, sizeof *x);
    x->type = type;
    int64_t v;
    kp fp = { p, "frame", 0 }, wp = { p, "world", 0 };
    if (!f[0]) return jv_missing(r, it, p, "frame");
    if (jv_get_int(r, f[0], &fp, 1, (int64_t)1e15, &x->frame)) return -1;
    if (!f[1]) return jv_missing(r, it, p, "world");
    if (jv_get_int(r, f[1], &wp, 1, INT32_MAX, &v)) return -1;
    x->world = (int)v;
    /* frames of one world never go backwards: the log is in the order things happened */
    int64_t k = 0;
    while (k < *nfw && (*fw)[k].world != x->world) k++;
    if (k < *nfw && x->frame < (*fw)[k].frame)
        return jv_fail(r, f[0], 0, &fp, "frame %lld of world %d comes after frame %lld of events[%lld]: frames go backwards",
                       (long long)x->frame, x->world, (long long)(*fw)[k].frame, (long long)(*fw)[k].event);
    if (k == *nfw) {
        fworld *n = realloc(*fw, (size_t)(k + 1) * sizeof *n);
        if (!n) return jv_fail(r, it, 0, p, "out of memory");
        *fw = n;
        (*nfw)++;
        (*fw)[k].world = x->world;
    }
    (*fw)[k].frame = x->frame;
    (*fw)[k].event = i;
    if (type == EV_GRAB) {
        kp pp = { p, "particle", 0 };
        if (!f[3]) return jv_missing(r, it, p, "particle");
        if (jv_get_int(r, f[3], &pp, 1, WB_MAX_PARTICLES, &v)) return -1;
        x->particle = (int32_t)(v - 1);
        item_pos(r, f[3], cur, &x->line, &x->col);
        if (!f[4]) return jv_missing(r, it, p, "target");
        if (jv_opt_vec(r, f[4], p, "target", 3, x->target) || jv_opt_real(r, f[5], p, "compliance", &x->compliance))
            return -1;
        const wb_fault ft = wb_grab_def_fault(x->compliance); /* the core's rule (grab.c) */
        if (jv_fault(r, &ft, p, ev_keys[type], f, 3)) return -1;
        if ((*nfg & (*nfg - 1)) == 0) {  /* doubled at each power of two: one more each time copies n^2 */
            fgrab *n = realloc(*fg, (size_t)(*nfg ? 2 * *nfg : 1) * sizeof *n);
            if (!n) return jv_fail(r, it, 0, p, "out of memory");
            *fg = n;
        }
        (*fg)[(*nfg)++] = (fgrab){ x->world, -1 };
        x->grab = *nfg; /* a grab event's own ordinal */
    } else {
        kp gp = { p, "grab", 0 };
        if (!f[3]) return jv_missing(r, it, p, "grab");
        if (jv_get_int(r, f[3], &gp, 1, INT64_MAX / 2, &x->grab)) return -1;
        item_pos(r, f[3], cur, &x->line, &x->col);
        if (x->grab > *nfg)
            return jv_fail(r, f[3], 0, &gp, "grab %lld does not exist (%lld grab event%s before this one)",
                           (long long)x->grab, (long long)*nfg, *nfg == 1 ? "" : "s");
        fgrab *g = &(*fg)[x->grab - 1];
        if (g->released_by >= 0)
            return jv_fail(r, f[3], 0, &gp, "grab %lld was released by events[%lld]", (long long)x->grab,
                           (long long)g->released_by);
        if (g->world != x->world)
            return jv_fail(r, f[1], 0, &wp, "grab %lld is in world %d, not %d", (long long)x->grab, g->world, x->world);
        if (type == EV_MOVE) {
            if (!f[4]) return jv_missing(r, it, p, "target");
            if (jv_opt_vec(r, f[4], p, "target", 3, x->target)) return -1;
        } else {
            g->released_by = i;
        }
    }
    return 0;
}

static const char *const root_keys[] = { "format", "version", "scene", "events", NULL };

static int read_root(rd *r, const cJSON *root, replay *rp)
{
    const cJSON *f[4];
    if (jv_get_object(r, root, NULL, root_keys, f)) return -1;
    kp fp = { NULL, "format", 0 }, vp = { NULL, "version", 0 }, sp = { NULL, "scene", 0 }, ep = { NULL, "events", 0 };
    const char *s;
    int64_t version;
    if (!f[0]) return jv_missing(r, root, NULL, "format");
    if (jv_get_string(r, f[0], &fp, &s)) return -1;
    if (strcmp(s, "wobble-input"))
        return jv_fail(r, f[0], 0, &fp, "'%s' is not an input log (\"wobble-input\" expected)", s);
    if (!f[1]) return jv_missing(r, root, NULL, "version");
    if (jv_get_int(r, f[1], &vp, INT32_MIN, INT32_MAX, &version)) return -1;
    if (version != 1)
        return jv_fail(r, f[1], 0, &vp, "version %lld is not supported (this wobble reads version 1)", (long long)version);
    if (f[2] && jv_get_string(r, f[2], &sp, &s)) return -1;
    if (!f[3]) return jv_missing(r, root, NULL, "events");
    int32_t n;
    if (jv_get_array(r, f[3], &ep, INT32_MAX, &n)) return -1;
    fgrab *fg = NULL;
    fworld *fw = NULL;
    int64_t nfg = 0, nfw = 0, i = 0;
    int rc = 0;
    lc cur = { 0, 1, 1 };
    for (const cJSON *c = f[3]->child; c && !rc; c = c->next, i++) {
        kp p = { &ep, NULL, i };
        ev x;
        rc = read_event(r, c, &p, i, &fg, &nfg, &fw, &nfw, &cur, &x);
        if (!rc && !evs_push(&rp->e, &x)) rc = jv_fail(r, c, 0, &p, "out of memory");
    }
    free(fg);
    free(fw);
    if (rc) return rc;
    rp->ngrabs = nfg;
    rp->grab = calloc((size_t)nfg + 1, sizeof *rp->grab);
    rp->grab_w = calloc((size_t)nfg + 1, sizeof *rp->grab_w);
    if (!rp->grab || !rp->grab_w) return jv_fail(r, root, 0, NULL, "out of memory");
    return 0;
}

/* the file's text, NUL-terminated; NULL with a message */
static char *read_text(const char *path, char *err, size_t n)
{
    FILE *f = fopen(path, "rb");
    struct stat st;
    if (!f) {
        snprintf(err, n, "%s: %s", path, strerror(errno));
        return NULL;
    }
    if (fstat(fileno(f), &st) != 0 || !S_ISREG(st.st_mode) || st.st_size > (1 << 30)) {
        const bool dir = fstat(fileno(f), &st) == 0 && S_ISDIR(st.st_mode);
        snprintf(err, n, "%s: %s", path, dir ? "is a folder, not a file" : "not a regular file of 1 GiB at most");
        fclose(f);
        return NULL;
    }
    char *t = malloc((size_t)st.st_size + 1);
    size_t got = t ? fread(t, 1, (size_t)st.st_size, f) : 0;
    if (!t || ferror(f)) {
        snprintf(err, n, "%s: %s", path, t ? strerror(errno) : "out of memory");
        free(t);
        fclose(f);
        return NULL;
    }
    fclose(f);
    t[got] = 0;
    if (strlen(t) != got) {
        int line, col;
        jv_line_col(t, (int32_t)strlen(t), &line, &col);
        snprintf(err, n, "%s:%d:%d: not a text file (a NUL byte)", path, line, col);
        free(t);
        return NULL;
    }
    return t;
}

/* parse the file into rp (errors "file:line:col: key.path: reason") */
static bool load(const char *path, replay *rp, char *err, size_t n)
{
    char *text = read_text(path, err, n);
    if (!text) return false;
    const char *end = NULL, *p = text;
    while (*p && (unsigned char)*p <= 32) p++;
    cJSON *root = *p ? cJSON_ParseWithOpts(text, &end, 1) : NULL;
    scan s = { text, text, 0, 0, NULL, NULL, 0 };
    rd r = { path, text, NULL, err, n };
    int rc = -1, line, col;
    if (!*p) {
        snprintf(err, n, "%s: empty file (an input log is a JSON object)", path);
    } else if (!root) {
        char near[24] = "";
        for (int i = 0; i < 20 && end && end[i] && end[i] != '\n'; i++)
            near[i] = (unsigned char)end[i] >= 32 && (unsigned char)end[i] < 127 ? end[i] : '?';
        jv_line_col(text, end ? (int32_t)(end - text) : 0, &line, &col);
        if (end && *end) snprintf(err, n, "%s:%d:%d: JSON syntax error near '%s'", path, line, col, near);
        else snprintf(err, n, "%s:%d:%d: JSON syntax error: unexpected end of file", path, line, col);
    } else {
        if (!strncmp(s.p, "\xEF\xBB\xBF", 3)) s.p += 3; /* cJSON skips a byte-order mark too */
        jv_sk_value(&s, -1);
        int32_t k = 0;
        jv_number_items(root, &k);
        r.pos = !s.oom && k == s.n ? &s : NULL;
        rc = read_root(&r, root, rp);
    }
    cJSON_Delete(root);
    free(s.voff);
    free(s.koff);
    free(text);
    return rc == 0;
}

/* ---- replay: applying the events ---------------------------------------------------------------- */
static const char replay_key = 0; /* registry: the replay userdata */
#define WBL_REPLAY "wobble.replay"

static int replay_gc(lua_State *L)
{
    replay *rp = luaL_checkudata(L, 1, WBL_REPLAY);
    free(rp->e.v);
    free(rp->grab);
    free(rp->grab_w);
    free(rp->seen);
    free(rp->shown);
    memset(rp, 0, sizeof *rp);
    return 0;
}

/* "file:line:col: events[i].key" of event i's particle or grab */
static void ev_where(const replay *rp, int64_t i, char *buf, size_t n)
{
    const ev *x = &rp->e.v[i];
    const char *key = x->type == EV_GRAB ? "particle" : "grab";
    if (x->line) snprintf(buf, n, "%s:%d:%d: events[%lld].%s", rp->shown, x->line, x->col, (long long)i, key);
    else snprintf(buf, n, "%s: events[%lld].%s", rp->shown, (long long)i, key);
}

/* event i on w; raises (a Lua error, exit 2) when the world refuses it */
static void apply(lua_State *L, replay *rp, int64_t i, wb_world *w)
{
    const ev *x = &rp->e.v[i];
    char where[PATH_MAX + 96], msg[PATH_MAX + 512];
    ev_where(rp, i, where, sizeof where);
    msg[0] = 0;
    if (x->type == EV_GRAB) {
        const int32_t np = wb_particle_count(w);
        wb_status st = WB_OK;
        if (x->particle >= np) {
            snprintf(msg, sizeof msg, "%s: particle %d out of range (world %d has %d at frame %lld)", where,
                     (int)x->particle + 1, x->world, (int)np, (long long)x->frame);
        } else {
            wb_grab_id g = wb_grab_add(w, x->particle, x->target, x->compliance, &st);
            if (st == WB_ERR_NOMEM) wb_rt_budget_error(L, "%s: out of memory grabbing the particle", where);
            if (st != WB_OK) snprintf(msg, sizeof msg, "%s: the world refuses the grab: %s", where, wb_last_error());
            rp->grab[x->grab - 1] = g;
            rp->grab_w[x->grab - 1] = w;
        }
    } else {
        const wb_grab_id g = rp->grab[x->grab - 1];
        if (rp->grab_w[x->grab - 1] != w || !wb_grab_valid(w, g))
            snprintf(msg, sizeof msg, "%s: grab %lld is no longer in world %d (the scene released it or closed its world)",
                     where, (long long)x->grab, x->world);
        else if (x->type == EV_MOVE) wb_grab_move(w, g, x->target);
        else wb_grab_release(w, g);
    }
    if (msg[0]) luaL_error(L, "%s", msg); /* (lua_pushfstring knows no %lld) */
}

/* the frame hook: the events due after this frame of this world, in file order */
static int replay_hook(lua_State *L)
{
    replay *rp = luaL_checkudata(L, lua_upvalueindex(1), WBL_REPLAY);
    wbl_world *ud = wbl_checkworld_ud(L, 1);
    if (!ud->w) return 0;
    const int world = wbl_input_world(L, 1);
    const int64_t frame = wb_world_frame(ud->w);
    int64_t k = 0;
    while (k < rp->nseen && rp->seen[k].world != world) k++;
    if (k == rp->nseen) {
        fworld *n = realloc(rp->seen, (size_t)(k + 1) * sizeof *n);
        if (!n) return wb_rt_budget_error(L, "--replay: out of memory");
        rp->seen = n;
        rp->nseen++;
        rp->seen[k] = (fworld){ world, 0, 0 };
    }
    rp->seen[k].frame = frame;
    while (rp->next < rp->e.n && rp->e.v[rp->next].world == world && rp->e.v[rp->next].frame == frame) {
        apply(L, rp, rp->next, ud->w);
        rp->next++;
    }
    return 0;
}

bool wbl_replay_begin(lua_State *L, const char *path, char *err, size_t n)
{
    int top = lua_gettop(L);
    replay *rp = lua_newuserdatauv(L, sizeof *rp, 0);
    memset(rp, 0, sizeof *rp);
    if (luaL_newmetatable(L, WBL_REPLAY)) {
        lua_pushcfunction(L, replay_gc);
        lua_setfield(L, -2, "__gc");
    }
    lua_setmetatable(L, -2);
    if (!(rp->shown = strdup(path)) || !load(path, rp, err, n)) {
        if (!rp->shown) snprintf(err, n, "%s: out of memory", path);
        lua_settop(L, top); /* the collector frees what was read */
        return false;
    }
    lua_pushvalue(L, -1);
    lua_rawsetp(L, LUA_REGISTRYINDEX, &replay_key);
    lua_pushcclosure(L, replay_hook, 1);
    wb_rt_add_frame_hook(L, -1);
    lua_settop(L, top);
    return true;
}

bool wbl_replay_end(lua_State *L, char *err, size_t n)
{
    int top = lua_gettop(L);
    replay *rp = lua_rawgetp(L, LUA_REGISTRYINDEX, &replay_key) == LUA_TUSERDATA ? luaL_testudata(L, -1, WBL_REPLAY) : NULL;
    bool ok = !rp || rp->next >= rp->e.n;
    if (!ok) {
        const ev *x = &rp->e.v[rp->next];
        int64_t k = 0, left = rp->e.n - rp->next;
        while (k < rp->nseen && rp->seen[k].world != x->world) k++;
        char why[128];
        if (k == rp->nseen) snprintf(why, sizeof why, "world %d never finished a frame", x->world);
        else if (rp->seen[k].frame < x->frame)
            snprintf(why, sizeof why, "the scene ended before it: world %d finished frame %lld last", x->world,
                     (long long)rp->seen[k].frame);
        else if (rp->seen[k].frame == x->frame)
            snprintf(why, sizeof why, "it failed (the error above)");
        else
            snprintf(why, sizeof why, "world %d went past that frame (it is at frame %lld): the scene differs from the "
                     "one recorded, or an event before it failed", x->world, (long long)rp->seen[k].frame);
        snprintf(err, n, "%s: %lld event%s not applied, the first events[%lld] (%s after frame %lld of world %d): %s",
                 rp->shown, (long long)left, left == 1 ? " was" : "s were", (long long)rp->next, type_names[x->type],
                 (long long)x->frame, x->world, why);
    }
    lua_settop(L, top);
    return ok;
}
