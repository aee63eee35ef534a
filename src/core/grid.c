/* grid.c: the shape of the sorted grids of the two broad phases (broadphase.c, tribroad.c):
 * one rule, so that both size their cells alike. */
#include <stdlib.h>
#include <string.h>

#include "core.h"
#include "grid.h"

static int cmp_real(const void *a, const void *b)
{
    const wb_real x = *(const wb_real *)a, y = *(const wb_real *)b;
    return x < y ? -1 : x > y;
}

void wb__grid_bounds(const wb_real *x, const wb_real *reach, const int32_t *list, int32_t n, wb_real big,
                     wb_real lo[3], wb_real hi[3], wb_real *rmax, wb_real *rn)
{
    for (int a = 0; a < 3; a++) lo[a] = INFINITY, hi[a] = -INFINITY;
    wb_real rm = 0, rb = 0;
    for (int32_t k = 0; k < n; k++) {
        const int32_t i = list[k];
        for (int a = 0; a < 3; a++) {
            if (x[3 * i + a] < lo[a]) lo[a] = x[3 * i + a];
            if (x[3 * i + a] > hi[a]) hi[a] = x[3 * i + a];
        }
        if (reach[i] > rm) rm = reach[i];
        if (reach[i] > rb && !(reach[i] > big)) rb = reach[i];
    }
    *rmax = rm;
    *rn = rb;
}

wb_real wb__grid_typical(const wb_real *reach, const int32_t *list, int32_t n)
{
    wb_real sample[31];
    const int ns = n < 31 ? (int)n : 31;
    if (ns < 1) return 0;
    for (int k = 0; k < ns; k++) sample[k] = reach[list[(int64_t)n * k / ns]];
    qsort(sample, (size_t)ns, sizeof *sample, cmp_real);
    return sample[ns / 2];
}

/* at most ~2 cells per point: the cell grown by 2^(1/3) until the box fits, past 2^20
 * times the asked size the coordinates wrap instead, the budget then shared out from
 * the thinnest axis up */
void wb__grid_shape(wb_grid *g, const wb_real lo[3], const wb_real hi[3], wb_real cs, int32_t n)
{
    if (!(cs > 1e-300)) cs = 1e-300;
    const double budget = 2.0 * n + 64;
    double dims[3];
    wb_real inv = 1 / cs;
    for (int step = 0;; step++) {
        double prod = 1;
        inv = 1 / cs;
        for (int a = 0; a < 3; a++) {
            /* as wb__cell_of computes it: the last point's cell is inside */
            dims[a] = floor((hi[a] - lo[a]) * inv) + 1;
            if (!(dims[a] < 1e15)) dims[a] = 1e15;
            prod *= dims[a];
        }
        g->wrap = prod > budget;
        if (!g->wrap || step == 60) break;
        cs *= 1.2599210498948732;
    }
    if (g->wrap) {
        int order[3] = { 0, 1, 2 };
        for (int a = 0; a < 2; a++)
            for (int c = a + 1; c < 3; c++)
                if (dims[order[c]] < dims[order[a]]) { int t = order[a]; order[a] = order[c]; order[c] = t; }
        double left = budget;
        for (int k = 0; k < 3; k++) {
            const int a = order[k];
            double cap = floor(pow(left, 1.0 / (3 - k)) + 1e-9);
            if (cap < 1) cap = 1;
            if (dims[a] > cap) dims[a] = cap;
            left /= dims[a];
        }
    }
    for (int a = 0; a < 3; a++) { g->o[a] = lo[a]; g->nc[a] = (int64_t)dims[a]; }
    g->inv = inv;
}

int wb__pairbufs(wb_pairbuf **out, int *nout, int n)
{
    if (n > *nout) {
        wb_pairbuf *o = realloc(*out, sizeof *o * (size_t)n);
        if (!o) return 0;
        memset(o + *nout, 0, sizeof *o * (size_t)(n - *nout));
        *out = o;
        *nout = n;
    }
    for (int k = 0; k < n; k++) (*out)[k].n = 0, (*out)[k].fail = 0;
    return 1;
}
