/* shape_match.h: the shape-matching clusters' arrays (shape_match.c), and their section of
 * a snapshot image (snapshot.h). */
#ifndef WB_SHAPE_MATCH_H
#define WB_SHAPE_MATCH_H

#include <stddef.h>

#include "wobble.h"

/* shape-matching clusters (Müller et al. 2005); w->sm: NULL until the first */
typedef struct wb_smatch {
    /* model */
    int32_t n, cap;                 /* clusters */
    int32_t *start;                 /* (n + 1) ranges into ids */
    wb_real *stiff, *yield, *creep; /* (n) */
    int32_t nids, cap_ids;
    int32_t *ids;                   /* (nids) particles */
    /* state */
    wb_real *rest;                  /* (nids x 3) rest shape about its mass centre (plastic flow moves it) */
    wb_real *q;                     /* (n x 4) rotation at the end of the last frame (warm start) */
    /* cache */
    wb_real *qk;                    /* (n x 4) rotation during the step (state q untouched until it ends) */
    wb_real *lambda;                /* (nids x 3) multipliers of the current substep */
    size_t charged;                 /* bytes charged to the memory budget */
} wb_smatch;

/* a snapshot image's shape-matching clusters (snapshot.h): model and state by cluster */
typedef struct wb_image_smatch {
    int32_t n, nids;
    int32_t *start;        /* (n + 1) ranges into ids */
    int32_t *ids;          /* (nids) particles */
    wb_real *stiff, *yield, *creep; /* (n) */
    wb_real *rest;         /* (nids x 3) rest shape about its mass centre */
    wb_real *q;            /* (n x 4) rotation at the end of the last frame */
} wb_image_smatch;

/* the particles of all the clusters together (momentum.c: its bodies change with them) */
int32_t wb__shape_match_members(const wb_world *w);

#endif
