/* distance.h: the distance constraints' section of a snapshot image (snapshot.h). Their
 * arrays live in the world's model and state (core.h), which grow with the particles'. */
#ifndef WB_DISTANCE_H
#define WB_DISTANCE_H

#include "wobble.h"

/* by slot, as the world keeps them: a slot is live while its generation is odd, and the
 * free list is the dead slots in stack order (so a restored world reuses them alike) */
typedef struct wb_image_distance {
    int32_t n;
    int32_t *ij;           /* (n x 2) */
    wb_real *alpha, *beta, *yield, *creep, *break_strain, *rest; /* (n) */
    wb_real *bforce;       /* (n) break_force, N (0 = none) */
    uint8_t *broken;       /* (n) */
    uint32_t *gen;         /* (n) */
    int32_t nfree;
    int32_t *free_slots;   /* (nfree) */
} wb_image_distance;

#endif
