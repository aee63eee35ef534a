/* collect.c: `wobble collect DIR [--csv | --json] [--plot X,Y[,COLOUR] OUT.png]`
 * (docs/cli.md, "Sweeps"): one row per run of a sweep (DIR/sweep.json), read from its
 * runs/NNNN/result.json: its --set values, status, exit code, wall time, frames,
 * warnings, final hash and wobble.result values. A run whose folder is not there never
 * started ("missing"); one that started and left no finished result.json was ended from
 * outside ("crashed": a signal, the watchdog, the OOM killer, Slurm's limits). --plot
 * draws a column against another with the renderer's chart code (plot.c): a heat map
 * when both are grid keys, else a line per COLOUR value; failed and non-finite runs
 * are crossed out, so the picture is a stability map. */
#include "sweep.h"
#include "lua/util.h"
#include "render/render.h"

#include <cjson/cJSON.h>
#include <errno.h>
#include <float.h>
#include <limits.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

enum { EXIT_PASS = 0, EXIT_SCRIPT = 2 };

static const char collect_usage[] =
    "usage: wobble collect DIR [--csv | --json] [--plot X,Y[,COLOUR] OUT.png]\n"
    "\n"
    "  one row per run of the sweep in DIR (wobble sweep): run, status (ok, failed, error,\n"
    "  budget, crashed, missing), exit, the grid keys, wall_time, frames, warnings, hash,\n"
    "  the wobble.result values, non_finite (results that were NaN or infinite), error\n"
    "  --csv                 the table as CSV on stdout (the default)\n"
    "  --json                the table as JSON on stdout\n"
    "  --plot X,Y[,COLOUR] OUT.png   X and Y both grid keys: a heat map of COLOUR (default:\n"
    "                        the share of runs that ended ok); else Y over X, one line per\n"
    "                        value of COLOUR. Failed and non-finite runs are crossed out.\n"
    "                        Without --csv or --json nothing else is printed.\n";

static int collect_error(const char *fmt, const char *a, const char *b) {
    fprintf(stderr, "wobble collect: ");
    fprintf(stderr, fmt, a, b);
    fputc('\n', stderr);
    return EXIT_SCRIPT;
}

typedef struct row {
    char run[32];
    const char *status;   /* ok, failed, error, budget, crashed, missing */
    cJSON *res;           /* its result.json, or NULL */
    cJSON *set;           /* sweep.json's grid values of the run (strings) */
    int repeat;
} row;

typedef struct table {
    cJSON *sweep;
    row *rows;
    int n, ng, nr, repeat;
    const char **gkeys;   /* grid keys, in order */
    const char **rkeys;   /* result keys, sorted */
} table;

static const char *const builtin[] = { "run", "status", "exit", "repeat", "wall_time", "frames", "warnings",
                                       "hash", "non_finite", "error", NULL };

static char *read_all(const char *path) {
    FILE *f = fopen(path, "rb");
    if (!f) return NULL;
    char *buf = NULL;
    size_t len = 0, cap = 0;
    for (;;) {
        if (len + 4096 + 1 > cap) {
            cap = cap ? 2 * cap : 16384;
            char *b = realloc(buf, cap);
            if (!b) break;
            buf = b;
        }
        size_t k = fread(buf + len, 1, cap - len - 1, f);
        len += k;
        if (k == 0) break;
    }
    fclose(f);
    if (buf) buf[len] = 0;
    return buf;
}

static int cmp_str(const void *a, const void *b) {
    return strcmp(*(const char *const *)a, *(const char *const *)b);
}

/* sweep.json as wobble sweep writes it; a hand-edited or damaged one is named, not
 * followed (a NULL key or a run named ../.. must not reach strcmp or a path) */
static int bad_sweep(const cJSON *sw, char *why, size_t n) {
    const cJSON *grid = cJSON_GetObjectItem(sw, "grid"), *runs = cJSON_GetObjectItem(sw, "runs"), *e, *v;
    const cJSON *rep = cJSON_GetObjectItem(sw, "repeat");
    int i = 0;
    if (!cJSON_IsArray(grid) || !cJSON_IsArray(runs)) return snprintf(why, n, "no grid and runs arrays"), 1;
    if (rep && (!cJSON_IsNumber(rep) || !(rep->valuedouble >= 1 && rep->valuedouble <= 1e6)))
        return snprintf(why, n, "repeat: expected a number from 1 to 1000000"), 1;
    cJSON_ArrayForEach(e, grid) {
        const char *k = cJSON_GetStringValue(cJSON_GetObjectItem(e, "key"));
        if (!k || !*k) return snprintf(why, n, "grid[%d].key: expected a string", i + 1), 1;
        for (const cJSON *g = grid->child; g != e; g = g->next)  /* unique: a key is a column */
            if (!strcmp(cJSON_GetStringValue(cJSON_GetObjectItem(g, "key")), k))
                return snprintf(why, n, "grid[%d].key: '%s' twice", i + 1, k), 1;
        i++;
    }
    i = 0;
    cJSON_ArrayForEach(e, runs) {
        const char *r = cJSON_GetStringValue(cJSON_GetObjectItem(e, "run"));
        const cJSON *set = cJSON_GetObjectItem(e, "set"), *rp = cJSON_GetObjectItem(e, "repeat");
        i++;
        if (!r || !*r || strlen(r) > 20 || strspn(r, "0123456789") != strlen(r))
            return snprintf(why, n, "runs[%d].run: expected the run's number (digits)", i), 1;
        if (set && !cJSON_IsObject(set)) return snprintf(why, n, "runs[%d].set: expected an object", i), 1;
        cJSON_ArrayForEach(v, set) if (!cJSON_IsString(v))
            return snprintf(why, n, "runs[%d].set.%s: expected a string", i, v->string), 1;
        if (rp && (!cJSON_IsNumber(rp) || !(rp->valuedouble >= 1 && rp->valuedouble <= 1e6)))
            return snprintf(why, n, "runs[%d].repeat: expected a number from 1 to 1000000", i), 1;
    }
    return 0;
}

/* result.json as wobble run writes it: else the run's end is unknown (crashed) */
static int good_result(const cJSON *res) {
    const cJSON *r = cJSON_GetObjectItem(res, "result"), *nf = cJSON_GetObjectItem(res, "non_finite"), *e;
    if (!cJSON_IsObject(res) || !cJSON_IsString(cJSON_GetObjectItem(res, "status"))) return 0;
    if (r && !cJSON_IsNull(r) && !cJSON_IsObject(r)) return 0;
    if (nf && !cJSON_IsNull(nf) && !cJSON_IsArray(nf)) return 0;
    const cJSON *values = cJSON_IsObject(r) ? r : NULL;
    cJSON_ArrayForEach(e, values) if (!e->string || cJSON_IsObject(e) || cJSON_IsArray(e)) return 0;
    return 1;
}

static int load(const char *dir, table *t) {
    char p[PATH_MAX + 64];
    memset(t, 0, sizeof *t);
    snprintf(p, sizeof p, "%s/sweep.json", dir);
    char *text = read_all(p);
    if (!text) {
        struct stat st;
        if (stat(dir, &st) != 0) return collect_error("cannot open %s: %s", dir, strerror(errno));
        return collect_error("%s is not a sweep folder (no sweep.json; make one with wobble sweep)%s", dir, "");
    }
    t->sweep = cJSON_Parse(text);
    free(text);
    cJSON *grid = cJSON_GetObjectItem(t->sweep, "grid"), *runs = cJSON_GetObjectItem(t->sweep, "runs");
    char why[256];
    if (!t->sweep) return collect_error("%s is not a sweep description (wobble sweep writes it): %s", p,
                                        "not JSON, or cut short");
    if (bad_sweep(t->sweep, why, sizeof why))
        return collect_error("%s is not a sweep description (wobble sweep writes it): %s", p, why);
    t->repeat = cJSON_GetObjectItem(t->sweep, "repeat") ? (int)cJSON_GetObjectItem(t->sweep, "repeat")->valuedouble : 1;
    t->ng = cJSON_GetArraySize(grid);
    t->gkeys = calloc((size_t)t->ng + 1, sizeof *t->gkeys);
    for (int j = 0; j < t->ng; j++) t->gkeys[j] = cJSON_GetStringValue(cJSON_GetObjectItem(cJSON_GetArrayItem(grid, j), "key"));
    t->n = cJSON_GetArraySize(runs);
    t->rows = calloc((size_t)t->n + 1, sizeof *t->rows);
    int cap = 16;
    t->rkeys = malloc((size_t)cap * sizeof *t->rkeys);
    for (int i = 0; i < t->n; i++) {
        cJSON *r = cJSON_GetArrayItem(runs, i);
        row *w = &t->rows[i];
        snprintf(w->run, sizeof w->run, "%s", cJSON_GetStringValue(cJSON_GetObjectItem(r, "run")) ?: "?");
        w->set = cJSON_GetObjectItem(r, "set");
        w->repeat = cJSON_GetObjectItem(r, "repeat") ? (int)cJSON_GetObjectItem(r, "repeat")->valuedouble : 1;
        struct stat st;
        snprintf(p, sizeof p, "%s/runs/%s", dir, w->run);
        if (stat(p, &st) != 0) {
            w->status = "missing";
            continue;
        }
        snprintf(p, sizeof p, "%s/runs/%s/result.json", dir, w->run);
        text = read_all(p);
        w->res = text ? cJSON_Parse(text) : NULL;
        free(text);
        const char *s = cJSON_GetStringValue(cJSON_GetObjectItem(w->res, "status"));
        /* "running": written when the run began, never replaced by its end */
        w->status = !s || !strcmp(s, "running") || !good_result(w->res) ? "crashed" : s;
        if (!strcmp(w->status, "crashed")) cJSON_Delete(w->res), w->res = NULL;  /* its figures are not an end */
        cJSON *res = cJSON_GetObjectItem(w->res, "result"), *e;
        cJSON_ArrayForEach(e, res) {
            int k = 0;
            while (k < t->nr && strcmp(t->rkeys[k], e->string)) k++;
            if (k < t->nr) continue;
            if (t->nr == cap) t->rkeys = realloc(t->rkeys, (size_t)(cap *= 2) * sizeof *t->rkeys);
            t->rkeys[t->nr++] = e->string;
        }
    }
    if (t->nr > 1) qsort(t->rkeys, (size_t)t->nr, sizeof *t->rkeys, cmp_str);
    return EXIT_PASS;
}

static int is_builtin(const char *k) {
    for (int i = 0; builtin[i]; i++)
        if (!strcmp(builtin[i], k)) return 1;
    return 0;
}

static int is_grid(const table *t, const char *k) {
    for (int j = 0; j < t->ng; j++)
        if (!strcmp(t->gkeys[j], k)) return 1;
    return 0;
}

/* a result's column name: its key, unless a grid key or a fixed column has that name */
static void result_column(const table *t, const char *k, char *buf, size_t n) {
    snprintf(buf, n, "%s%s", is_builtin(k) || is_grid(t, k) ? "result." : "", k);
}

static int in_non_finite(const row *w, const char *k) {
    cJSON *e;
    cJSON_ArrayForEach(e, cJSON_GetObjectItem(w->res, "non_finite"))
        if (cJSON_IsString(e) && !strcmp(e->valuestring, k)) return 1;
    return 0;
}

/* ---- cells ----------------------------------------------------------------------------- */

static const char *json_text(const cJSON *v, char *buf, size_t n) {
    if (!v || cJSON_IsNull(v)) return "";
    if (cJSON_IsString(v)) return v->valuestring;
    if (cJSON_IsBool(v)) return cJSON_IsTrue(v) ? "true" : "false";
    if (cJSON_IsNumber(v)) {
        snprintf(buf, n, "%.17g", v->valuedouble);
        if (v->valuedouble == floor(v->valuedouble) && fabs(v->valuedouble) < 1e15)
            return snprintf(buf, n, "%.0f", v->valuedouble), buf;  /* frames, exit codes: no exponent */
        /* the shortest text that reads back the same */
        for (int prec = 1; prec <= 17; prec++) {
            char b[64];
            snprintf(b, sizeof b, "%.*g", prec, v->valuedouble);
            if (strtod(b, NULL) == v->valuedouble) {
                snprintf(buf, n, "%s", b);
                break;
            }
        }
        return buf;
    }
    return "";
}

/* the column `key` of a row (a fixed column, a grid key, else a result) as text */
static const char *cell(const table *t, const row *w, const char *key, int result, char *buf, size_t n) {
    if (result) return json_text(cJSON_GetObjectItem(cJSON_GetObjectItem(w->res, "result"), key), buf, n);
    if (!strcmp(key, "run")) return w->run;
    if (!strcmp(key, "status")) return w->status;
    if (!strcmp(key, "repeat")) return snprintf(buf, n, "%d", w->repeat), buf;
    if (is_grid(t, key)) return json_text(cJSON_GetObjectItem(w->set, key), buf, n);
    if (!strcmp(key, "non_finite")) {
        cJSON *e;
        buf[0] = 0;
        cJSON_ArrayForEach(e, cJSON_GetObjectItem(w->res, "non_finite"))
            if (cJSON_IsString(e))
                snprintf(buf + strlen(buf), n - strlen(buf), "%s%s", buf[0] ? " " : "", e->valuestring);
        return buf;
    }
    return json_text(cJSON_GetObjectItem(w->res, key), buf, n);
}

static void csv_field(const char *s) {
    if (!strpbrk(s, ",\"\n\r") && s[0] != ' ') {
        fputs(s, stdout);
        return;
    }
    putchar('"');
    for (; *s; s++) {
        if (*s == '"') putchar('"');
        putchar(*s);
    }
    putchar('"');
}

static void print_csv(const table *t) {
    char buf[4096], name[128];
    /* the header */
    printf("run,status,exit");
    for (int j = 0; j < t->ng; j++) putchar(','), csv_field(t->gkeys[j]);
    if (t->repeat > 1) printf(",repeat");
    printf(",wall_time,frames,warnings,hash");
    for (int k = 0; k < t->nr; k++) result_column(t, t->rkeys[k], name, sizeof name), putchar(','), csv_field(name);
    printf(",non_finite,error\n");
    for (int i = 0; i < t->n; i++) {
        const row *w = &t->rows[i];
        static const char *const head[] = { "run", "status", "exit" }, *const mid[] = { "wall_time", "frames",
                                                                                       "warnings", "hash" };
        for (int c = 0; c < 3; c++) fputs(c ? "," : "", stdout), csv_field(cell(t, w, head[c], 0, buf, sizeof buf));
        for (int j = 0; j < t->ng; j++) putchar(','), csv_field(cell(t, w, t->gkeys[j], 0, buf, sizeof buf));
        if (t->repeat > 1) printf(",%d", w->repeat);
        for (int c = 0; c < 4; c++) putchar(','), csv_field(cell(t, w, mid[c], 0, buf, sizeof buf));
        for (int k = 0; k < t->nr; k++) putchar(','), csv_field(cell(t, w, t->rkeys[k], 1, buf, sizeof buf));
        putchar(',');
        csv_field(cell(t, w, "non_finite", 0, buf, sizeof buf));
        putchar(',');
        csv_field(cell(t, w, "error", 0, buf, sizeof buf));
        putchar('\n');
    }
}

/* a --set value as the run saw it (main.c's prepare): true/false, a number, a string */
static cJSON *typed(const char *v) {
    char *end;
    if (!strcmp(v, "true") || !strcmp(v, "false")) return cJSON_CreateBool(v[0] == 't');
    double d = strtod(v, &end);
    if (end != v && !*end && isfinite(d) && !strpbrk(v, "nNxX")) return cJSON_CreateNumber(d);
    return cJSON_CreateString(v);
}

static void print_json(const table *t) {
    cJSON *o = cJSON_CreateObject(), *runs;
    cJSON_AddStringToObject(o, "format", "wobble-collect");
    cJSON_AddNumberToObject(o, "version", 1);
    cJSON_AddItemToObject(o, "scene", cJSON_Duplicate(cJSON_GetObjectItem(t->sweep, "scene"), 1));
    cJSON_AddItemToObject(o, "grid", cJSON_Duplicate(cJSON_GetObjectItem(t->sweep, "grid"), 1));
    runs = cJSON_AddArrayToObject(o, "runs");
    static const char *const copied[] = { "exit", "wall_time", "frames", "warnings", "hash", "result", "non_finite",
                                          "error", NULL };
    for (int i = 0; i < t->n; i++) {
        const row *w = &t->rows[i];
        cJSON *r = cJSON_CreateObject(), *set = cJSON_CreateObject(), *e;
        cJSON_AddStringToObject(r, "run", w->run);
        cJSON_AddStringToObject(r, "status", w->status);
        cJSON_ArrayForEach(e, w->set) if (cJSON_IsString(e)) cJSON_AddItemToObject(set, e->string, typed(e->valuestring));
        cJSON_AddItemToObject(r, "set", set);
        if (t->repeat > 1) cJSON_AddNumberToObject(r, "repeat", w->repeat);
        for (int c = 0; copied[c]; c++) {
            cJSON *v = w->res && strcmp(w->status, "crashed") ? cJSON_GetObjectItem(w->res, copied[c]) : NULL;
            cJSON_AddItemToObject(r, copied[c], v ? cJSON_Duplicate(v, 1) : cJSON_CreateNull());
        }
        cJSON_AddItemToArray(runs, r);
    }
    char *s = cJSON_Print(o);
    if (s) puts(s);
    free(s);
    cJSON_Delete(o);
}

/* ---- numbers for the plot ------------------------------------------------------------------- */

/* the column as a number: 1 when finite, 0 when absent or not a number, -1 when non-finite */
static int number(const table *t, const row *w, const char *key, double *out) {
    char buf[256];
    int result = !is_grid(t, key) && !is_builtin(key);
    if (result && in_non_finite(w, key)) return *out = NAN, -1;
    if (!result && !strcmp(key, "repeat")) return *out = w->repeat, 1;
    const char *s = cell(t, w, key, result, buf, sizeof buf);
    if (!strcmp(s, "true") || !strcmp(s, "false")) return *out = s[0] == 't', 1;
    char *end;
    double v = strtod(s, &end);
    if (!*s || *end) return 0;
    *out = v;
    return isfinite(v) ? 1 : -1;
}

/* the run went wrong: it did not end ok, or the value shown is not finite */
static int bad_run(const table *t, const row *w, const char *key) {
    double v;
    return strcmp(w->status, "ok") || (key && number(t, w, key, &v) < 0);
}

/* ---- --plot ------------------------------------------------------------------------------ */

static const uint8_t ink[3] = { 40, 40, 40 }, faint[3] = { 222, 224, 228 }, frame_col[3] = { 120, 120, 120 },
                     empty_col[3] = { 215, 215, 215 }, white[3] = { 255, 255, 255 }, bad_col[3] = { 200, 20, 20 };
static const uint8_t palette[10][3] = {
    { 31, 119, 180 }, { 255, 127, 14 }, { 44, 160, 44 }, { 214, 39, 40 }, { 148, 103, 189 },
    { 140, 86, 75 }, { 227, 119, 194 }, { 127, 127, 127 }, { 188, 189, 34 }, { 23, 190, 207 },
};

typedef struct image { uint8_t *px; int w, h; } image;

static void text(const image *im, int x, int y, const char *s, const uint8_t col[3], int scale) {
    wb_text(im->px, im->w, im->h, x, y, s, col, scale);
}

/* a perceptual ramp (viridis' five stops): f in [0, 1] */
static void ramp(double f, uint8_t out[3]) {
    static const double stop[5][3] = {
        { 68, 1, 84 }, { 59, 82, 139 }, { 33, 145, 140 }, { 94, 201, 98 }, { 253, 231, 37 } };
    f = f < 0 ? 0 : f > 1 ? 1 : f;
    int i = f >= 1 ? 3 : (int)(f * 4);
    double u = f * 4 - i;
    for (int k = 0; k < 3; k++) out[k] = (uint8_t)lrint(stop[i][k] + (stop[i + 1][k] - stop[i][k]) * u);
}

static void cross(const image *im, double x, double y, double r, const uint8_t col[3]) {
    wb_chart_line(im->px, im->w, im->h, x - r, y - r, x + r, y + r, col);
    wb_chart_line(im->px, im->w, im->h, x - r, y + r, x + r, y - r, col);
}

static void frame(const image *im, int x0, int y0, int x1, int y1) {
    wb_chart_rect(im->px, im->w, im->h, x0, y0, x1, y0 + 1, frame_col);
    wb_chart_rect(im->px, im->w, im->h, x0, y1, x1 + 1, y1 + 1, frame_col);
    wb_chart_rect(im->px, im->w, im->h, x0, y0, x0 + 1, y1, frame_col);
    wb_chart_rect(im->px, im->w, im->h, x1, y0, x1 + 1, y1 + 1, frame_col);
}

static void short_num(char *b, size_t n, double v) {
    snprintf(b, n, "%.3g", v);
}

static int grid_index(const table *t, const char *key) {
    for (int j = 0; j < t->ng; j++)
        if (!strcmp(t->gkeys[j], key)) return j;
    return -1;
}

static cJSON *grid_values(const table *t, const char *key) {
    cJSON *g = cJSON_GetArrayItem(cJSON_GetObjectItem(t->sweep, "grid"), grid_index(t, key));
    return cJSON_GetObjectItem(g, "values");
}

static int value_index(cJSON *vals, const char *v) {
    int i = 0;
    cJSON *e;
    cJSON_ArrayForEach(e, vals) {
        if (cJSON_IsString(e) && !strcmp(e->valuestring, v)) return i;
        i++;
    }
    return -1;
}

/* a colour bar at x, from y0 (hi) to y1 (lo), with its ends labelled */
static void colour_bar(const image *im, int x, int y0, int y1, double lo, double hi) {
    for (int y = y0; y < y1; y++) {
        uint8_t c[3];
        ramp(1 - (double)(y - y0) / (y1 - y0), c);
        wb_chart_rect(im->px, im->w, im->h, x, y, x + 18, y + 1, c);
    }
    frame(im, x, y0, x + 18, y1);
    char b[64];
    for (int k = 0; k <= 4; k++) {
        double v = hi * (1 - k / 4.0) + lo * (k / 4.0);   /* finite for ends near DBL_MAX */
        int y = y0 + (y1 - y0) * k / 4;
        short_num(b, sizeof b, v);
        wb_chart_rect(im->px, im->w, im->h, x + 18, y, x + 23, y + 1, frame_col);
        text(im, x + 27, y - 4, b, ink, 1);
    }
}

/* X and Y both grid keys: a cell per pair of values, its colour COLOUR's mean over the
 * cell's runs that ended ok (or, without COLOUR, the share of runs that ended ok) */
static void heat_map(const table *t, const char *X, const char *Y, const char *C, const image *im) {
    cJSON *gx = grid_values(t, X), *gy = grid_values(t, Y);
    int nx = cJSON_GetArraySize(gx), ny = cJSON_GetArraySize(gy);
    int left = 120, right = im->w - 170, top = 70, bottom = im->h - 80;
    double *sum = calloc((size_t)(nx * ny), sizeof *sum);
    int *cnt = calloc((size_t)(nx * ny), sizeof *cnt), *bad = calloc((size_t)(nx * ny), sizeof *bad),
        *miss = calloc((size_t)(nx * ny), sizeof *miss), *all = calloc((size_t)(nx * ny), sizeof *all);
    char b1[256], b2[256];
    for (int i = 0; i < t->n; i++) {
        const row *w = &t->rows[i];
        int xi = value_index(gx, cell(t, w, X, 0, b1, sizeof b1)), yi = value_index(gy, cell(t, w, Y, 0, b2, sizeof b2));
        if (xi < 0 || yi < 0) continue;
        int c = yi * nx + xi;
        double v;
        all[c]++;
        if (!strcmp(w->status, "missing")) miss[c]++;
        else if (bad_run(t, w, C)) bad[c]++;
        if (!C) sum[c] += !strcmp(w->status, "ok"), cnt[c] += strcmp(w->status, "missing") != 0;
        else if (!bad_run(t, w, C) && number(t, w, C, &v) == 1) {
            /* a running mean: a sum of values near DBL_MAX would overflow */
            cnt[c]++;
            sum[c] += (v / 2 - sum[c] / 2) * (2.0 / cnt[c]);
        }
    }
    double lo = INFINITY, hi = -INFINITY;
    for (int c = 0; c < nx * ny; c++)
        if (cnt[c]) lo = fmin(lo, C ? sum[c] : sum[c] / cnt[c]), hi = fmax(hi, C ? sum[c] : sum[c] / cnt[c]);
    if (!C) lo = 0, hi = 1;
    if (!(lo <= hi)) lo = 0, hi = 1;
    /* halves: the span of values near DBL_MAX overflows */
    if (hi / 2 - lo / 2 < 0.5e-12 * fmax(1, fabs(hi))) lo = fmax(lo - 0.5, -DBL_MAX), hi = fmin(hi + 0.5, DBL_MAX);
    double cw = (double)(right - left) / nx, ch = (double)(bottom - top) / ny;
    for (int yi = 0; yi < ny; yi++)
        for (int xi = 0; xi < nx; xi++) {
            int c = yi * nx + xi;
            int x0 = left + (int)lrint(xi * cw), x1 = left + (int)lrint((xi + 1) * cw);
            int y1 = bottom - (int)lrint(yi * ch), y0 = bottom - (int)lrint((yi + 1) * ch);  /* first value at the bottom */
            uint8_t col[3] = { empty_col[0], empty_col[1], empty_col[2] };
            double v = !cnt[c] ? NAN : C ? sum[c] : sum[c] / cnt[c];
            if (cnt[c]) ramp((v / 2 - lo / 2) / (hi / 2 - lo / 2), col);
            wb_chart_rect(im->px, im->w, im->h, x0 + 1, y0 + 1, x1 - 1, y1 - 1, col);
            double mx = (x0 + x1) / 2.0, my = (y0 + y1) / 2.0;
            if (bad[c]) cross(im, mx, my, fmin(cw, ch) * 0.32, bad_col);
            if (cnt[c] && !bad[c]) {
                short_num(b1, sizeof b1, v);
                int lum = 299 * col[0] + 587 * col[1] + 114 * col[2];
                text(im, (int)mx - wb_text_width(b1, 1) / 2, (int)my - 4, b1, lum > 128000 ? ink : white, 1);
            } else if (miss[c] == all[c]) {
                text(im, (int)mx - wb_text_width("missing", 1) / 2, (int)my - 4, "missing", ink, 1);
            }
        }
    for (int xi = 0; xi < nx; xi++) {
        const char *s = cJSON_GetStringValue(cJSON_GetArrayItem(gx, xi));
        int x = left + (int)lrint((xi + 0.5) * cw);
        text(im, x - wb_text_width(s, 1) / 2, bottom + 8, s, ink, 1);
    }
    for (int yi = 0; yi < ny; yi++) {
        const char *s = cJSON_GetStringValue(cJSON_GetArrayItem(gy, yi));
        int y = bottom - (int)lrint((yi + 0.5) * ch);
        text(im, left - 8 - wb_text_width(s, 1), y - 4, s, ink, 1);
    }
    text(im, (left + right) / 2 - wb_text_width(X, 2) / 2, im->h - 48, X, ink, 2);
    text(im, 12, top - 26, Y, ink, 2);
    colour_bar(im, right + 30, top, bottom - 60, lo, hi);
    text(im, right + 30, top - 18, C ? C : "share ok", ink, 1);
    cross(im, right + 39, bottom - 30, 7, bad_col);
    text(im, right + 54, bottom - 40, "failed or", ink, 1);
    text(im, right + 54, bottom - 28, "non-finite", ink, 1);
    free(sum), free(cnt), free(bad), free(miss), free(all);
}

/* an axis: linear, or logarithmic when the values span three decades or more. Values
 * near DBL_MAX stay finite on either: a log axis keeps its ends as powers of ten (10^309
 * would be infinite), a linear one is measured in halves (hi - lo can overflow) */
typedef struct axis { double lo, hi; int log, elo, ehi; } axis;

static double ax_pos(const axis *a, double v) {
    return a->log ? (log10(v) - a->elo) / (a->ehi - a->elo) : (v / 2 - a->lo / 2) / (a->hi / 2 - a->lo / 2);
}

static void ax_fit(axis *a, double lo, double hi, int allow_log) {
    if (!(lo <= hi) || !isfinite(lo) || !isfinite(hi)) lo = 0, hi = 1;
    a->log = allow_log && lo > 0 && hi / lo >= 1000;
    if (a->log) {
        a->elo = (int)floor(log10(lo) - 0.05), a->ehi = (int)ceil(log10(hi) + 0.05);
        a->lo = lo, a->hi = hi;
        return;
    }
    if (hi / 2 - lo / 2 < 0.5e-12 * fmax(1, fabs(hi))) {
        lo -= fmax(1e-3, fabs(lo) * 0.1), hi += fmax(1e-3, fabs(hi) * 0.1);
        lo = fmax(lo, -DBL_MAX), hi = fmin(hi, DBL_MAX);
    }
    double pad = 0.06 * (hi / 2 - lo / 2) * 2;
    a->lo = fmax(lo - pad, -DBL_MAX), a->hi = fmin(hi + pad, DBL_MAX);
}

/* grid lines and labels of an axis; vertical: the y axis */
static void ax_draw(const image *im, const axis *a, int vertical, int x0, int y0, int x1, int y1) {
    char b[64];
    double first, step, end;
    if (a->log) {  /* whole decades, a few labels even over 600 of them */
        step = fmax(1, ceil(wb_nice_step((double)(a->ehi - a->elo) / (vertical ? 5 : 8))));
        first = ceil(a->elo / step) * step, end = a->ehi;
    }
    else {
        step = wb_nice_step((a->hi / 2 - a->lo / 2) / (vertical ? 2.5 : 4));
        first = ceil(a->lo / step - 1e-9) * step, end = a->hi;
    }
    /* a step that rounding makes vanish (or an overflow) must not loop forever */
    for (int k = 0; k < 64; k++) {
        const double v = first + k * step;
        if (!isfinite(v) || v > end + 1e-9 * step) break;
        double f = a->log ? (v - a->elo) / (a->ehi - a->elo) : ax_pos(a, v);
        if (a->log) snprintf(b, sizeof b, "1e%d", (int)lrint(v));
        else wb_chart_label(b, sizeof b, v, step);
        if (vertical) {
            int y = y1 - (int)lrint(f * (y1 - y0));
            wb_chart_rect(im->px, im->w, im->h, x0, y, x1, y + 1, faint);
            text(im, x0 - 8 - wb_text_width(b, 1), y - 4, b, ink, 1);
        } else {
            int x = x0 + (int)lrint(f * (x1 - x0));
            wb_chart_rect(im->px, im->w, im->h, x, y0, x + 1, y1, faint);
            text(im, x - wb_text_width(b, 1) / 2, y1 + 6, b, ink, 1);
        }
    }
}

typedef struct pt { double x, y; } pt;

static int cmp_pt(const void *a, const void *b) {
    double d = ((const pt *)a)->x - ((const pt *)b)->x;
    return d < 0 ? -1 : d > 0;
}

/* Y over X, a line per COLOUR value (the mean of the runs that ended ok at each X);
 * runs that failed or whose Y is not finite: a cross at X (at the top without a Y) */
static void line_chart(const table *t, const char *X, const char *Y, const char *C, const image *im) {
    int left = 100, right = im->w - 30, top = 80, bottom = im->h - 70;
    char b[256];
    /* the groups: COLOUR's values, in grid order for a grid key */
    int ng = 0;
    const char **groups = calloc((size_t)t->n + 1, sizeof *groups);
    char **owned = calloc((size_t)t->n + 1, sizeof *owned);
    for (int i = 0; i < t->n; i++) {
        const char *g = C ? cell(t, &t->rows[i], C, !is_grid(t, C) && !is_builtin(C), b, sizeof b) : "";
        int k = 0;
        while (k < ng && strcmp(groups[k], g)) k++;
        if (k == ng) groups[ng] = owned[ng] = strdup(g), ng++;
    }
    if (C && is_grid(t, C)) {  /* the grid's order, not the runs' */
        cJSON *vals = grid_values(t, C), *e;
        int k = 0;
        cJSON_ArrayForEach(e, vals) if (cJSON_IsString(e) && k < ng) groups[k++] = e->valuestring;
    }
    double xlo = INFINITY, xhi = -INFINITY, ylo = INFINITY, yhi = -INFINITY, x, y;
    for (int i = 0; i < t->n; i++) {
        const row *w = &t->rows[i];
        if (number(t, w, X, &x) != 1) continue;
        xlo = fmin(xlo, x), xhi = fmax(xhi, x);
        if (number(t, w, Y, &y) == 1) ylo = fmin(ylo, y), yhi = fmax(yhi, y);
    }
    axis ax, ay;
    ax_fit(&ax, xlo, xhi, 1);
    ax_fit(&ay, ylo, yhi, 1);
    ax_draw(im, &ay, 1, left, top, right, bottom);
    ax_draw(im, &ax, 0, left, top, right, bottom);
    pt *pts = malloc(((size_t)t->n + 1) * sizeof *pts);
    for (int g = 0; g < ng; g++) {
        const uint8_t *col = palette[g % 10];
        int np = 0;
        for (int i = 0; i < t->n; i++) {
            const row *w = &t->rows[i];
            const char *gv = C ? cell(t, w, C, !is_grid(t, C) && !is_builtin(C), b, sizeof b) : "";
            if (strcmp(gv, groups[g]) || number(t, w, X, &x) != 1 || (ax.log && x <= 0)) continue;
            double px = left + ax_pos(&ax, x) * (right - left);
            int has_y = number(t, w, Y, &y) == 1 && !(ay.log && y <= 0);
            double py = has_y ? bottom - ax_pos(&ay, y) * (bottom - top) : top + 8;
            if (!strcmp(w->status, "missing")) continue;
            if (bad_run(t, w, Y) || !has_y) cross(im, px, py, 6, col);
            else pts[np++] = (pt){ px, py };
        }
        qsort(pts, (size_t)np, sizeof *pts, cmp_pt);
        /* repeats: the mean at each X */
        int m = 0;
        for (int i = 0; i < np;) {
            int j = i;
            double s = 0;
            while (j < np && pts[j].x == pts[i].x) s += pts[j++].y;
            pts[m++] = (pt){ pts[i].x, s / (j - i) };
            i = j;
        }
        for (int i = 0; i < m; i++) {
            if (i) wb_chart_line(im->px, im->w, im->h, pts[i - 1].x, pts[i - 1].y, pts[i].x, pts[i].y, col);
            wb_chart_rect(im->px, im->w, im->h, (int)pts[i].x - 3, (int)pts[i].y - 3, (int)pts[i].x + 3,
                          (int)pts[i].y + 3, col);
        }
    }
    frame(im, left, top, right, bottom);
    /* the legend, right to left above the chart */
    int lx = right;
    cross(im, lx - 8, top - 14, 5, ink);
    lx -= 18;
    snprintf(b, sizeof b, "failed or non-finite");
    lx -= wb_text_width(b, 1);
    text(im, lx, top - 18, b, ink, 1);
    lx -= 24;
    for (int g = ng - 1; g >= 0 && C; g--) {
        char name[300];
        snprintf(name, sizeof name, "%s = %s", C, groups[g]);
        lx -= wb_text_width(name, 1);
        text(im, lx, top - 18, name, ink, 1);
        lx -= 22;
        wb_chart_rect(im->px, im->w, im->h, lx, top - 15, lx + 16, top - 12, palette[g % 10]);
        lx -= 14;
    }
    text(im, (left + right) / 2 - wb_text_width(X, 2) / 2, im->h - 34, X, ink, 2);
    text(im, 12, top - 36, Y, ink, 2);
    free(pts);
    for (int g = 0; g < t->n; g++) free(owned[g]);
    free(owned);
    free(groups);
}

/* a column --plot can draw: a grid key, a number of result.json, a wobble.result key */
static int plottable(const table *t, const char *k) {
    static const char *const nums[] = { "exit", "repeat", "wall_time", "frames", "warnings", NULL };
    for (int i = 0; nums[i]; i++)
        if (!strcmp(nums[i], k)) return 1;
    if (is_grid(t, k)) return 1;
    for (int i = 0; i < t->nr; i++)
        if (!strcmp(t->rkeys[i], k)) return 1;
    return 0;
}

static int plot(const table *t, const char *spec, const char *png) {
    char names[3][128], list[2048] = "";
    int nn = 0;
    for (const char *s = spec;; nn++) {
        const char *c = strchr(s, ',');
        size_t n = c ? (size_t)(c - s) : strlen(s);
        if (nn == 3 || n == 0 || n >= sizeof names[0])
            return collect_error("--plot expects X,Y or X,Y,COLOUR (keys of the table), got '%s'%s", spec, "");
        snprintf(names[nn], sizeof names[nn], "%.*s", (int)n, s);
        if (!c) break;
        s = c + 1;
    }
    nn++;
    if (nn < 2) return collect_error("--plot expects X,Y or X,Y,COLOUR (keys of the table), got '%s'%s", spec, "");
    for (int k = 0; k < nn; k++) {
        if (plottable(t, names[k])) continue;
        snprintf(list, sizeof list, "grid keys:");
        for (int j = 0; j < t->ng; j++) snprintf(list + strlen(list), sizeof list - strlen(list), " %s", t->gkeys[j]);
        snprintf(list + strlen(list), sizeof list - strlen(list), "; results:");
        for (int j = 0; j < t->nr; j++) snprintf(list + strlen(list), sizeof list - strlen(list), " %s", t->rkeys[j]);
        if (!t->nr) snprintf(list + strlen(list), sizeof list - strlen(list), " (none yet)");
        snprintf(list + strlen(list), sizeof list - strlen(list), "; also wall_time frames warnings exit");
        fprintf(stderr, "wobble collect: --plot %s: unknown key '%s' (%s)\n", spec, names[k], list);
        return EXIT_SCRIPT;
    }
    image im = { NULL, 960, 640 };
    im.px = malloc((size_t)im.w * im.h * 3);
    if (!im.px) return collect_error("--plot: out of memory%s%s", "", "");
    memset(im.px, 255, (size_t)im.w * im.h * 3);
    const char *X = names[0], *Y = names[1], *C = nn == 3 ? names[2] : NULL;
    const char *scene = cJSON_GetStringValue(cJSON_GetObjectItem(t->sweep, "scene"));
    const char *base = scene && strrchr(scene, '/') ? strrchr(scene, '/') + 1 : scene ? scene : "sweep";
    char title[512];
    int heat = is_grid(t, X) && is_grid(t, Y) && strcmp(X, Y);
    if (heat) {
        snprintf(title, sizeof title, "%s: %s over %s x %s", base, C ? C : "runs that ended ok", X, Y);
        heat_map(t, X, Y, C, &im);
    } else {
        snprintf(title, sizeof title, "%s: %s over %s", base, Y, X);
        line_chart(t, X, Y, C, &im);
    }
    text(&im, 20, 12, title, ink, 2);
    char err[PATH_MAX + 128];
    int ok = wbl_write_png(png, im.px, im.w, im.h, err, sizeof err);
    free(im.px);
    if (!ok) return collect_error("--plot %s: %s", png, err);
    return EXIT_PASS;
}

/* ---- the command ------------------------------------------------------------------------ */

int wb_cmd_collect(int argc, char **argv) {
    const char *dir = NULL, *spec = NULL, *png = NULL;
    int csv = 0, json = 0;
    for (int i = 2; i < argc; i++) {
        const char *a = argv[i];
        if (!strcmp(a, "--help") || !strcmp(a, "-h")) {
            fputs(collect_usage, stdout);
            return EXIT_PASS;
        } else if (!strcmp(a, "--csv")) {
            csv = 1;
        } else if (!strcmp(a, "--json")) {
            json = 1;
        } else if (!strcmp(a, "--plot")) {
            if (i + 2 >= argc) return collect_error("--plot needs X,Y[,COLOUR] and OUT.png%s%s", "", "");
            spec = argv[++i];
            png = argv[++i];
        } else if (a[0] == '-' && a[1]) {
            fprintf(stderr, "wobble collect: unknown option %s\n\n%s", a, collect_usage);
            return EXIT_SCRIPT;
        } else if (dir) {
            return collect_error("collect takes one sweep folder, got '%s' and '%s'", dir, a);
        } else {
            dir = a;
        }
    }
    if (!dir) {
        fprintf(stderr, "wobble collect: which sweep? wobble collect DIR\n\n%s", collect_usage);
        return EXIT_SCRIPT;
    }
    if (csv && json) return collect_error("--csv and --json: choose one%s%s", "", "");
    table t;
    int code = load(dir, &t);
    if (code == EXIT_PASS && spec) code = plot(&t, spec, png);
    if (code == EXIT_PASS) {
        if (json) print_json(&t);
        else if (csv || !spec) print_csv(&t);
    }
    for (int i = 0; i < t.n; i++) cJSON_Delete(t.rows[i].res);
    free(t.rows);
    free(t.gkeys);
    free(t.rkeys);
    cJSON_Delete(t.sweep);
    return code;
}
