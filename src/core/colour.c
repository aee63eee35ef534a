/* colour.c: greedy graph colouring of constraints into batches, for every type.
 *
 * No two constraints of a batch share a movable particle, so a batch can be projected
 * in parallel (and vectorised) with results identical to a serial sweep: Gauss-Seidel
 * runs batch after batch, always in the same order, whatever the thread count. A
 * constraint joins k particles (2 for a distance, 4 for a bend); the ones that find no
 * free colour among WB_MAX_COLOURS go to one last batch projected serially. */
#include <stdlib.h>

#include "batch.h"

int wb__colour_greedy(const wb_real *inv_mass, int32_t np, const int32_t *idx, int k, int32_t n,
                      int (*live)(const void *ud, int32_t i), const void *ud, uint8_t *colour,
                      int32_t count[WB_MAX_COLOURS + 1])
{
    /* a bit per colour and particle: the colours its constraints already took */
    uint64_t *used = calloc((size_t)(np > 0 ? np : 1), sizeof *used);
    if (!used) return 0;
    for (int c = 0; c <= WB_MAX_COLOURS; c++) count[c] = 0;
    /* the lowest colour free at every end; immovable particles never conflict */
    for (int32_t i = 0; i < n; i++) {
        if (!live(ud, i)) { colour[i] = WB_NO_COLOUR; continue; }
        const int32_t *p = &idx[(size_t)k * (size_t)i];
        uint64_t mask = 0;
        for (int e = 0; e < k; e++)
            if (inv_mass[p[e]] > 0) mask |= used[p[e]];
        int c = ~mask ? __builtin_ctzll(~mask) : WB_MAX_COLOURS;
        if (c < WB_MAX_COLOURS)
            for (int e = 0; e < k; e++) used[p[e]] |= 1ull << c;
        colour[i] = (uint8_t)c;
        count[c]++;
    }
    free(used);
    return 1;
}

int32_t wb__colour_ranges(const int32_t count[WB_MAX_COLOURS + 1], int32_t *colour_start, int32_t *ncolours,
                          int32_t *serial_start, int32_t start[WB_MAX_COLOURS + 1])
{
    /* batches in colour order, constraints in slot order inside each */
    int32_t nc = 0, pos = 0;
    for (int c = 0; c <= WB_MAX_COLOURS; c++) {
        start[c] = pos;
        if (count[c] > 0) {
            colour_start[nc++] = pos;
            if (c == WB_MAX_COLOURS) *serial_start = nc - 1;
        }
        pos += count[c];
    }
    if (count[WB_MAX_COLOURS] == 0) *serial_start = nc;
    colour_start[nc] = pos;
    *ncolours = nc;
    return pos;
}

/* ---- batches over a permutation (batch.h) ----------------------------------------------- */
static int all_live(const void *ud, int32_t i) { (void)ud; (void)i; return 1; }

int wb__batches_build(wb_batches *b, const wb_real *inv_mass, int32_t np, const int32_t *idx, int k, int32_t n,
                      int32_t *order)
{
    uint8_t *colour = malloc((size_t)(n > 0 ? n : 1));
    int32_t count[WB_MAX_COLOURS + 1], start[WB_MAX_COLOURS + 1];
    if (!colour || !wb__colour_greedy(inv_mass, np, idx, k, n, all_live, NULL, colour, count)) {
        free(colour);
        return 0;
    }
    wb__colour_ranges(count, b->colour_start, &b->ncolours, &b->serial_start, start);
    for (int32_t s = 0; s < n; s++) order[start[colour[s]]++] = s;
    free(colour);
    b->n = n;
    return 1;
}

typedef struct batch_job {
    wb_world *w;
    wb_range_fn f;
    const int32_t *order;
    int32_t lo;
    wb_real h;
} batch_job;

static void batch_part(void *ctx, int32_t lo, int32_t hi)
{
    const batch_job *j = ctx;
    j->f(j->w, j->order, j->lo + lo, j->lo + hi, j->h);
}

void wb__batches_run(const wb_batches *b, wb_world *w, int32_t min_par, wb_range_fn f, const int32_t *order,
                     wb_real h)
{
    for (int32_t c = 0; c < b->ncolours; c++) {
        const int32_t lo = b->colour_start[c], hi = b->colour_start[c + 1];
        /* (the pool is asked for only here: a small scene never starts a thread) */
        wb_pool *pool = c < b->serial_start && hi - lo >= min_par ? wb__world_pool(w) : NULL;
        if (!pool) {
            f(w, order, lo, hi, h);
            continue;
        }
        batch_job j = { w, f, order, lo, h };
        wb__pool_for(pool, hi - lo, min_par / 2, batch_part, &j);
    }
}
