/* batch.h: colour batches over a permutation (colour.c), the one way every coloured
 * constraint type (distance.c, bend.c, volume.c, tet.c) is batched. A type colours its
 * constraints into an order array and projects order[lo, hi) batch after batch; what it
 * packs for its kernels (copies in batch order) is a cache derived from that order. */
#ifndef WB_BATCH_H
#define WB_BATCH_H

#include "wobble.h"

#define WB_MAX_COLOURS 64  /* one bit each in a per-particle mask; the rest go to a serial batch */

/* no more of the core than names (core.h): the types' headers, which snapshot.h includes
 * for their image sections, stay plain data for the file formats */
typedef struct wb_model wb_model;

typedef struct wb_batches {
    int32_t n;                                 /* constraints when coloured (-1: never) */
    int32_t ncolours, serial_start;            /* batches from serial_start on: serial */
    int32_t colour_start[WB_MAX_COLOURS + 2];  /* batch ranges into order */
    /* the compounds (wb_batch_def.compounds), after the batches: order[comp_start[c],
     * comp_start[c + 1]) for c < ncomp, from colour_start[ncolours] to norder */
    int32_t ncomp;
    int32_t *comp_start;                       /* (ncomp + 1), owned: wb__batches_free */
    int32_t norder;                            /* entries of order: batches, then compounds */
} wb_batches;

/* what a type colours: n constraints of k particles each (constraint i joins idx[k i ..
 * k i + k - 1]) */
typedef struct wb_batch_def {
    const int32_t *idx;
    int k;
    int32_t n;
    /* which of them to colour (NULL: all); the others are left out of order */
    int (*live)(const void *ud, int32_t i);
    const void *ud;
    /* 1: mirror images that share a movable particle (links meeting on a mirror plane),
     * which no colouring keeps alike, are not coloured but returned as compounds: each a
     * set of images joined through shared movable particles, to be projected together from
     * the same positions so that a symmetric scene stays symmetric (colour.c's header) */
    int compounds;
} wb_batch_def;

/* Mirror images are coloured alike (colour.c's header): every constraint's particles as
 * they were created (m->x0) decide the order they are visited in, a type's batches in
 * order of colour, then of creation (slot). order: room for the constraints coloured
 * (the live ones); b->norder says how many it got. 0 when out of memory (order and b
 * unchanged, but for comp_start's room) */
int wb__batches_make(wb_batches *b, const wb_model *m, const wb_batch_def *d, int32_t *order);
/* every constraint, no compounds (the types that only grow: bend, volume, tet) */
int wb__batches_build(wb_batches *b, const wb_model *m, const int32_t *idx, int k, int32_t n, int32_t *order);
void wb__batches_free(wb_batches *b);

/* tests: on = 0 colours in creation order (as before mirror keys), 1 with mirror keys
 * (the default) from the next colouring on; returns the previous setting. Not
 * thread-safe: call it between steps */
int wb__colour_symmetric(int on);

/* project order[lo, hi) of one batch (or of the serial tail, or of the compounds) */
typedef void (*wb_range_fn)(wb_world *w, const int32_t *order, int32_t lo, int32_t hi, wb_real h);

/* every batch in colour order; a batch of at least min_par constraints is split into
 * contiguous chunks run by the world's pool (conflict-free: the same bits as serially).
 * Then the compounds through fc (NULL when the type has none), in one call over their
 * whole range, order[colour_start[ncolours], norder): a compound is a handful of
 * constraints, and fc projects each (comp_start) one after another */
void wb__batches_run(const wb_batches *b, wb_world *w, int32_t min_par, wb_range_fn f, wb_range_fn fc,
                     const int32_t *order, wb_real h);

#endif
