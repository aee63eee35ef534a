/* tether.h: tethers, long-range attachments (tether.c) */
#ifndef WB_TETHER_H
#define WB_TETHER_H
#include "core.h"

/* w->teth: NULL until the first one is made */
typedef struct wb_tethers {
    int32_t n, cap;
    int32_t *ij;           /* (n x 2) model: the particles */
    wb_real *len, *alpha;  /* (n) model: the longest they may be apart (m), compliance (m/N) */
    wb_real *lambda;       /* (n) cache: multipliers of the current substep */
    size_t charged;        /* bytes charged to def.memory */
} wb_tethers;

/* a snapshot image's tethers (snapshot.h), in creation order */
typedef struct wb_image_tether {
    int32_t n;
    int32_t *ij;           /* (n x 2) */
    wb_real *len, *alpha;  /* (n) */
} wb_image_tether;

struct wb_image;
wb_status wb_image_alloc_tethers(struct wb_image *g, int32_t n);

#endif
