/* batch.h: colour batches over a permutation (colour.c), for the constraint types that
 * keep their arrays in creation order and project through an order array (bend.c,
 * volume.c, tet.c). Those types only grow, so a count that differs from the coloured one
 * means the batches are stale. */
#ifndef WB_BATCH_H
#define WB_BATCH_H

#include "wobble.h"

#define WB_MAX_COLOURS 64  /* one bit each in a per-particle mask; the rest go to a serial batch */

/* no more of the core than names (core.h): volume.h and tet.h, which snapshot.h includes
 * for their image sections, stay plain data for the file formats */
typedef struct wb_model wb_model;

/* colour.c: greedy colouring of n constraints of k particles each (constraint i joins
 * idx[k i .. k i + k - 1]), mirror images alike (colour.c's header); those live() refuses
 * get WB_NO_COLOUR, the others a colour in [0, WB_MAX_COLOURS] (WB_MAX_COLOURS: the serial
 * overflow batch), counted in count. 0 when out of memory */
#define WB_NO_COLOUR 255
/* With split (not NULL, mirror keys on): the groups of mirror images that share a movable
 * particle (links meeting on a mirror plane), which no colouring can keep alike, are not
 * coloured (WB_SPLIT_COLOUR, not counted) but returned as compounds: each a set of images
 * joined through shared particles, to be projected together from the same positions
 * (distance.c). split->member (n slots) gets them compound by compound in visiting order,
 * split->comp_start (n + 1 slots) the ncomp + 1 compound bounds into member. */
#define WB_SPLIT_COLOUR 254
typedef struct wb_split {
    int32_t n, first, ncomp; /* members, coloured constraints (visit_order's), compounds */
    int32_t *member, *comp_start;
} wb_split;
int wb__colour_greedy(const wb_model *m, const int32_t *idx, int k, int32_t n,
                      int (*live)(const void *ud, int32_t i), const void *ud, uint8_t *colour,
                      int32_t count[WB_MAX_COLOURS + 1], wb_split *split);
/* colour.c, tests: on = 0 colours in creation order (as before mirror keys), 1 with mirror
 * keys (the default) from the next colouring on; returns the previous setting. Not
 * thread-safe: call it between steps */
int wb__colour_symmetric(int on);
/* batch ranges from the counts: colour_start (ncolours + 1), the first serial batch, and
 * start[c] the first packed index of colour c; returns the packed total */
int32_t wb__colour_ranges(const int32_t count[WB_MAX_COLOURS + 1], int32_t *colour_start, int32_t *ncolours,
                          int32_t *serial_start, int32_t start[WB_MAX_COLOURS + 1]);

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
