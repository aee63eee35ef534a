/* batch.h: colour batches over a permutation (colour.c), for the constraint types that
 * keep their arrays in creation order and project through an order array (volume.c,
 * tet.c). Those types only grow, so a count that differs from the coloured one means the
 * batches are stale. */
#ifndef WB_BATCH_H
#define WB_BATCH_H

#include "wobble.h"
#include "bend.h" /* WB_MAX_COLOURS */

/* no more of the core than names (core.h): volume.h and tet.h, which snapshot.h includes
 * for their image sections, stay plain data for the file formats */
typedef struct wb_model wb_model;

typedef struct wb_batches {
    int32_t n;                                 /* constraints when coloured (-1: never) */
    int32_t ncolours, serial_start;            /* batches from serial_start on: serial */
    int32_t colour_start[WB_MAX_COLOURS + 2];  /* batch ranges into order */
} wb_batches;

/* colour n constraints of k particles (idx, k per constraint) into order (n slots, by
 * colour then creation); 0 when out of memory (nothing changed) */
int wb__batches_build(wb_batches *b, const wb_model *m, const int32_t *idx, int k, int32_t n, int32_t *order);

/* project order[lo, hi) of one batch (or of the serial tail) */
typedef void (*wb_range_fn)(wb_world *w, const int32_t *order, int32_t lo, int32_t hi, wb_real h);

/* every batch in colour order; a batch of at least min_par constraints is split into
 * contiguous chunks run by the world's pool (conflict-free: the same bits as serially) */
void wb__batches_run(const wb_batches *b, wb_world *w, int32_t min_par, wb_range_fn f,
                     const int32_t *order, wb_real h);

#endif
