/* plot.c: a chart of a run, sampled once per frame: kinetic, potential and
 * total energy, the maximum strain and the constraint error (RMS |length - rest|)
 * over time, three stacked panels with labelled axes, drawn on the CPU (anti-aliased
 * lines, stb_easy_font text) so a user sees at a glance whether a scene is stable. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "render.h"

#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wunused-function"
#pragma GCC diagnostic ignored "-Wsign-compare"
#pragma GCC diagnostic ignored "-Wconversion"
#include <stb/stb_easy_font.h>
#pragma GCC diagnostic pop

enum { S_KE, S_PE, S_TOTAL, S_STRAIN, S_ERROR, S_COUNT };

/* samples kept at most: a long run keeps every stride-th frame, the stride doubling
 * each time the samples fill up (pairs merged), so a plot's memory is bounded (0.8 MB)
 * however long the run, and still many times the chart's width in points */
#define MAX_SAMPLES 16384

struct wb_plot {
    double *t, *v[S_COUNT];
    size_t n, cap;
    size_t stride;         /* frames per sample kept */
    size_t pending;        /* frames seen since the last sample kept */
    double peak[S_COUNT];  /* strain and error: the largest over those frames */
    int32_t *pairs;
    wb_real *strain;
    size_t pcap;
};

wb_plot *wb_plot_create(void)
{
    wb_plot *p = calloc(1, sizeof(wb_plot));
    if (p) p->stride = 1;
    return p;
}

/* halve the samples: each pair becomes its later sample (time, energies), with the
 * pair's largest strain and error, so a spike between two kept frames still shows */
static void merge_pairs(wb_plot *p)
{
    size_t k = 0;
    for (size_t i = 1; i < p->n; i += 2, k++) {
        p->t[k] = p->t[i];
        for (int s = 0; s < S_COUNT; s++) {
            double a = p->v[s][i - 1], b = p->v[s][i];
            p->v[s][k] = (s == S_STRAIN || s == S_ERROR) && a > b ? a : b;
        }
    }
    p->n = k;
    p->stride *= 2;
}

void wb_plot_destroy(wb_plot *p)
{
    if (!p) return;
    free(p->t);
    for (int s = 0; s < S_COUNT; s++) free(p->v[s]);
    free(p->pairs);
    free(p->strain);
    free(p);
}

int64_t wb_plot_samples(const wb_plot *p) { return (int64_t)p->n; }

static bool grow_to(double **a, size_t cap)
{
    double *q = realloc(*a, cap * sizeof *q);
    if (!q) return false;
    *a = q;
    return true;
}

bool wb_plot_sample(wb_plot *p, const wb_world *w)
{
    if (p->n == MAX_SAMPLES) merge_pairs(p);
    if (p->n == p->cap) {
        size_t cap = p->cap ? 2 * p->cap : 1024;
        if (!grow_to(&p->t, cap)) return false;
        for (int s = 0; s < S_COUNT; s++)
            if (!grow_to(&p->v[s], cap)) return false;
        p->cap = cap;
    }
    /* constraint error from the pairs and their strains: rest = len / (1 + strain) */
    int32_t nd = wb_world_distance_pairs(w, NULL, NULL);
    if ((size_t)nd > p->pcap) {
        int32_t *q = realloc(p->pairs, 2 * (size_t)nd * sizeof *q);
        if (!q) return false;
        p->pairs = q;
        wb_real *r = realloc(p->strain, (size_t)nd * sizeof *r);
        if (!r) return false;
        p->strain = r;
        p->pcap = (size_t)nd;
    }
    nd = wb_world_distance_pairs(w, p->pairs, p->strain);
    const wb_real *x = wb_particle_positions(w);
    double sum = 0;
    for (int32_t i = 0; i < nd; i++) {
        const wb_real *a = x + 3 * p->pairs[2 * i], *b = x + 3 * p->pairs[2 * i + 1];
        double d = sqrt((a[0] - b[0]) * (a[0] - b[0]) + (a[1] - b[1]) * (a[1] - b[1]) + (a[2] - b[2]) * (a[2] - b[2]));
        double s = p->strain[i], e = 1 + s != 0 ? d * s / (1 + s) : 0;
        sum += e * e;
    }
    const double strain = 100 * wb_world_max_strain(w), error = nd ? 1000 * sqrt(sum / nd) : 0;   /* %, mm */
    if (p->pending == 0 || strain > p->peak[S_STRAIN]) p->peak[S_STRAIN] = strain;
    if (p->pending == 0 || error > p->peak[S_ERROR]) p->peak[S_ERROR] = error;
    if (++p->pending < p->stride) return true;
    p->pending = 0;
    wb_real ke, pe;
    wb_world_energy(w, &ke, &pe);
    size_t k = p->n++;
    p->t[k] = wb_world_time(w);
    p->v[S_KE][k] = ke;
    p->v[S_PE][k] = pe;
    p->v[S_TOTAL][k] = ke + pe;
    p->v[S_STRAIN][k] = p->peak[S_STRAIN];
    p->v[S_ERROR][k] = p->peak[S_ERROR];
    return true;
}

/* ---- raster helpers ----------------------------------------------------------------- */
typedef struct canvas { uint8_t *px; int w, h; } canvas;

static void blend(canvas *c, int x, int y, const uint8_t col[3], double a)
{
    if (x < 0 || y < 0 || x >= c->w || y >= c->h || a <= 0) return;
    if (a > 1) a = 1;
    uint8_t *p = c->px + 3 * ((size_t)y * c->w + x);
    for (int k = 0; k < 3; k++) p[k] = (uint8_t)lrint(p[k] + (col[k] - p[k]) * a);
}

static void rect(canvas *c, int x0, int y0, int x1, int y1, const uint8_t col[3])
{
    for (int y = y0; y < y1; y++)
        for (int x = x0; x < x1; x++) blend(c, x, y, col, 1);
}

/* Xiaolin Wu's anti-aliased line, drawn twice for a 2-pixel stroke */
static void line(canvas *c, double x0, double y0, double x1, double y1, const uint8_t col[3])
{
    bool steep = fabs(y1 - y0) > fabs(x1 - x0);
    if (steep) {
        double t = x0; x0 = y0; y0 = t;
        t = x1; x1 = y1; y1 = t;
    }
    if (x0 > x1) {
        double t = x0; x0 = x1; x1 = t;
        t = y0; y0 = y1; y1 = t;
    }
    double dx = x1 - x0, g = dx > 0 ? (y1 - y0) / dx : 0;
    for (int x = (int)floor(x0); x <= (int)ceil(x1); x++) {
        double y = y0 + g * (x - x0) - 0.5, f = y - floor(y);
        int yi = (int)floor(y);
        for (int k = 0; k < 2; k++) {   /* the stroke covers [y, y + 2) */
            int a = steep ? yi + k : x, b = steep ? x : yi + k;
            blend(c, a, b, col, k == 0 ? 1 - f : 1);
        }
        int a = steep ? yi + 2 : x, b = steep ? x : yi + 2;
        blend(c, a, b, col, f);
    }
}

int wb_text_width(const char *s, int scale)
{
    char buf[256];
    snprintf(buf, sizeof buf, "%s", s);
    return stb_easy_font_width(buf) * scale;
}

void wb_text(uint8_t *rgb, int w, int h, int x, int y, const char *s, const uint8_t colour[3], int scale)
{
    static char vb[256 * 270];   /* the font's vertex buffer: about 270 bytes a character */
    char buf[256];
    snprintf(buf, sizeof buf, "%s", s);
    int nq = stb_easy_font_print(0, 0, buf, NULL, vb, sizeof vb);
    canvas c = { rgb, w, h };
    for (int q = 0; q < nq; q++) {
        const float *v = (const float *)(vb + (size_t)q * 64);   /* 4 vertices of 16 bytes */
        float x0 = v[0], y0 = v[1], x1 = v[0], y1 = v[1];
        for (int k = 1; k < 4; k++) {
            x0 = fminf(x0, v[4 * k]), x1 = fmaxf(x1, v[4 * k]);
            y0 = fminf(y0, v[4 * k + 1]), y1 = fmaxf(y1, v[4 * k + 1]);
        }
        rect(&c, x + (int)lrintf(x0 * scale), y + (int)lrintf(y0 * scale), x + (int)lrintf(x1 * scale),
             y + (int)lrintf(y1 * scale), colour);
    }
}

/* ---- the chart ------------------------------------------------------------------------- */
double wb_nice_step(double x)
{
    double p = pow(10, floor(log10(x))), m = x / p;
    return (m < 1.5 ? 1 : m < 3.5 ? 2 : m < 7.5 ? 5 : 10) * p;
}

static const uint8_t ink[3] = { 40, 40, 40 }, faint[3] = { 222, 224, 228 }, frame_col[3] = { 120, 120, 120 };
static const uint8_t series_col[S_COUNT][3] = {
    { 214, 39, 40 }, { 31, 119, 180 }, { 40, 40, 40 }, { 230, 120, 10 }, { 44, 150, 44 },
};
static const char *const series_name[S_COUNT] = { "kinetic", "potential", "total", "max strain", "RMS error" };

typedef struct panel { int x0, y0, x1, y1; double lo, hi; } panel;

static void ticks(double lo, double hi, int want, double *first, double *step)
{
    *step = wb_nice_step((hi - lo) / want);
    *first = ceil(lo / *step - 1e-9) * *step;
}

static void fmt_num(char *b, size_t n, double v, double step)
{
    if (fabs(v) < step * 1e-6) v = 0;
    snprintf(b, n, "%.*f", step >= 1 ? 0 : (int)ceil(-log10(step) - 1e-9), v);
    if (fabs(v) >= 1e5 || (v != 0 && fabs(v) < 1e-4)) snprintf(b, n, "%.2g", v);
}

static void draw_panel(canvas *c, panel *p, const wb_plot *pl, const int *series, int ns, const char *title,
                       double t0, double t1, bool x_labels)
{
    /* the y range of the panel's series, padded */
    double lo = INFINITY, hi = -INFINITY;
    for (int s = 0; s < ns; s++)
        for (size_t i = 0; i < pl->n; i++) {
            double v = pl->v[series[s]][i];
            if (isfinite(v)) lo = fmin(lo, v), hi = fmax(hi, v);
        }
    if (!(lo <= hi)) lo = 0, hi = 1;
    if (hi - lo < 1e-12 * fmax(1, fabs(hi))) lo -= fmax(1e-3, fabs(lo) * 0.1), hi += fmax(1e-3, fabs(hi) * 0.1);
    double pad = 0.06 * (hi - lo);
    p->lo = lo - pad, p->hi = hi + pad;
    int W = p->x1 - p->x0, H = p->y1 - p->y0;
    double first, step;
    char b[64];
    /* horizontal grid and y labels */
    ticks(p->lo, p->hi, 5, &first, &step);
    for (double v = first; v <= p->hi + 1e-9 * step; v += step) {
        int y = p->y1 - (int)lrint((v - p->lo) / (p->hi - p->lo) * H);
        rect(c, p->x0, y, p->x1, y + 1, faint);
        fmt_num(b, sizeof b, v, step);
        wb_text(c->px, c->w, c->h, p->x0 - 8 - wb_text_width(b, 1), y - 4, b, ink, 1);
    }
    /* vertical grid and time labels */
    ticks(t0, t1, 8, &first, &step);
    for (double v = first; v <= t1 + 1e-9 * step; v += step) {
        int x = p->x0 + (int)lrint((v - t0) / (t1 - t0) * W);
        rect(c, x, p->y0, x + 1, p->y1, faint);
        if (x_labels) {
            fmt_num(b, sizeof b, v, step);
            wb_text(c->px, c->w, c->h, x - wb_text_width(b, 1) / 2, p->y1 + 6, b, ink, 1);
        }
    }
    /* the series */
    for (int s = 0; s < ns; s++) {
        const double *v = pl->v[series[s]];
        for (size_t i = 0; i + 1 < pl->n || (pl->n == 1 && i == 0); i++) {
            size_t j = pl->n == 1 ? 0 : i + 1;
            if (!isfinite(v[i]) || !isfinite(v[j])) continue;
            double xa = p->x0 + (pl->t[i] - t0) / (t1 - t0) * W, xb = p->x0 + (pl->t[j] - t0) / (t1 - t0) * W;
            double ya = p->y1 - (v[i] - p->lo) / (p->hi - p->lo) * H, yb = p->y1 - (v[j] - p->lo) / (p->hi - p->lo) * H;
            line(c, xa, ya, xb, yb, series_col[series[s]]);
        }
    }
    /* frame, title, legend */
    rect(c, p->x0, p->y0, p->x1, p->y0 + 1, frame_col);
    rect(c, p->x0, p->y1, p->x1, p->y1 + 1, frame_col);
    rect(c, p->x0, p->y0, p->x0 + 1, p->y1, frame_col);
    rect(c, p->x1, p->y0, p->x1 + 1, p->y1 + 1, frame_col);
    wb_text(c->px, c->w, c->h, p->x0, p->y0 - 22, title, ink, 2);
    int x = p->x1;
    for (int s = ns - 1; s >= 0; s--) {
        const char *name = series_name[series[s]];
        x -= wb_text_width(name, 1) + 8;
        wb_text(c->px, c->w, c->h, x, p->y0 - 15, name, ink, 1);
        x -= 22;
        rect(c, x, p->y0 - 12, x + 16, p->y0 - 9, series_col[series[s]]);
        x -= 10;
    }
}

uint8_t *wb_plot_render(const wb_plot *pl, int w, int h, const char *title)
{
    uint8_t *px = malloc((size_t)w * h * 3);
    if (!px) return NULL;
    memset(px, 255, (size_t)w * h * 3);
    canvas c = { px, w, h };
    wb_text(px, w, h, 20, 12, title ? title : "wobble run", ink, 2);
    double t0 = pl->n ? pl->t[0] : 0, t1 = pl->n ? pl->t[pl->n - 1] : 1;
    if (!(t1 > t0)) t1 = t0 + 1;
    int left = 90, right = w - 24, top = 70, bottom = h - 56, gap = 46;
    int ph = (bottom - top - 2 * gap) / 3;
    static const int energy[] = { S_KE, S_PE, S_TOTAL }, strain[] = { S_STRAIN }, error[] = { S_ERROR };
    panel p[3];
    for (int k = 0; k < 3; k++) {
        p[k].x0 = left, p[k].x1 = right;
        p[k].y0 = top + k * (ph + gap), p[k].y1 = p[k].y0 + ph;
    }
    draw_panel(&c, &p[0], pl, energy, 3, "energy [J]", t0, t1, false);
    draw_panel(&c, &p[1], pl, strain, 1, "maximum strain [%]", t0, t1, false);
    draw_panel(&c, &p[2], pl, error, 1, "constraint error [mm]", t0, t1, true);
    const char *xl = "time [s]";
    wb_text(px, w, h, (left + right) / 2 - wb_text_width(xl, 2) / 2, h - 30, xl, ink, 2);
    if (!pl->n) wb_text(px, w, h, left + 20, top + 20, "no frames were run", ink, 2);
    return px;
}

/* ---- the helpers for other charts (render.h) ---------------------------------------------- */
void wb_chart_rect(uint8_t *rgb, int w, int h, int x0, int y0, int x1, int y1, const uint8_t colour[3])
{
    canvas c = { rgb, w, h };
    rect(&c, x0 < 0 ? 0 : x0, y0 < 0 ? 0 : y0, x1 > w ? w : x1, y1 > h ? h : y1, colour);
}

void wb_chart_line(uint8_t *rgb, int w, int h, double x0, double y0, double x1, double y1, const uint8_t colour[3])
{
    canvas c = { rgb, w, h };
    line(&c, x0, y0, x1, y1, colour);
}

void wb_chart_label(char *buf, size_t n, double v, double step)
{
    fmt_num(buf, n, v, step);
}
