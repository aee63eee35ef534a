/* grid.h: the sorted grids and pair buffers the two broad phases (broadphase.c,
 * tribroad.c) share (grid.c). */
#ifndef WB_GRID_H
#define WB_GRID_H

#include <stdint.h>

#include "wobble.h"

/* grid.c: the sorted grids of the broad phases (broadphase.c, tribroad.c). Cell (i, j, k)
 * of a point is floor((x - o) * inv) per axis, clamped to [0, 1e15] (wb__cell_of), taken
 * modulo nc when wrap is set (points spread over a volume too big for the budget) */
typedef struct wb_grid {
    wb_real o[3], inv;     /* origin, 1 / cell */
    int64_t nc[3];         /* cells per axis */
    int wrap;              /* coordinates wrap around */
} wb_grid;
/* the box of the points of list (n) and their largest reach, and the largest up to big */
void wb__grid_bounds(const wb_real *x, const wb_real *reach, const int32_t *list, int32_t n, wb_real big,
                     wb_real lo[3], wb_real hi[3], wb_real *rmax, wb_real *rn);
/* the median of up to 31 reaches sampled evenly over list (n > 0) */
wb_real wb__grid_typical(const wb_real *reach, const int32_t *list, int32_t n);
/* the grid over the points inside [lo, hi]: cell cs or larger, at most ~2 cells per
 * point (n), wrapping past that */
void wb__grid_shape(wb_grid *g, const wb_real lo[3], const wb_real hi[3], wb_real cs, int32_t n);
/* a coordinate's cell, monotone in v (a search range never misses a cell); clamped so
 * that the cast stays defined for huge or infinite offsets; truncation is floor for
 * c > 0 (and no libm call without SSE4.1) */
static inline int64_t wb__cell_of(wb_real v, wb_real o, wb_real inv)
{
    const wb_real c = (v - o) * inv;
    return c > 0 ? (c < 1e15 ? (int64_t)c : (int64_t)1e15) : 0;
}
/* a point's cell in g, row-major (x fastest) */
static inline int32_t wb__grid_cell(const wb_grid *g, const wb_real *p)
{
    int64_t c[3];
    for (int a = 0; a < 3; a++) {
        c[a] = wb__cell_of(p[a], g->o[a], g->inv);
        if (g->wrap) c[a] %= g->nc[a];
    }
    return (int32_t)(c[0] + g->nc[0] * (c[1] + g->nc[1] * c[2]));
}

/* a broad phase's pairs, one buffer per thread, kept from frame to frame */
typedef struct wb_pairbuf {
    int32_t *ij; int32_t n, cap; int fail;
    int32_t *hit; int32_t cap_hit;     /* broadphase.c: one particle's hits */
} wb_pairbuf;
/* grid.c: n pair buffers (one per thread) in *out, grown as needed, emptied; 0 when out of memory */
int wb__pairbufs(wb_pairbuf **out, int *nout, int n);

#endif
