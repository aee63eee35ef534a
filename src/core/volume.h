/* volume.h: the volume constraints' arrays (volume.c), for the core files that copy them
 * (snapshot.c) and the builders that make them (builders.c, tets.c). */
#ifndef WB_VOLUME_H
#define WB_VOLUME_H

#include <stdlib.h>

#include "batch.h"

/* w->vol: NULL until the first one is made */
typedef struct wb_volumes {
    int32_t n, cap;
    int32_t *ijkl;         /* (n x 4) model: corners */
    wb_real *alpha;        /* (n) model: compliance, m^3/Pa */
    wb_real *rest;         /* (n) state: signed rest volume, m^3 (plastic flow moves it) */
    wb_real *yield, *creep; /* (n) model: plastic flow past |V - V0| / |V0| = yield, 1/s */
    int plastic;           /* some constraint has yield and creep > 0 */
    wb_real *lambda;       /* (n) cache: multipliers of the current substep, by batch position */
    int32_t *order;        /* (n) cache: slots by colour batch (batch.h) */
    int32_t *pos;          /* (n) cache: the batch position of each slot (order's inverse) */
    int32_t *pk;           /* (n x 4) cache: corners in batch order */
    wb_real *pa;           /* (n x 2) cache: compliance, rest in batch order */
    wb_batches bt;         /* cache: the batches, rebuilt when n changes */
    size_t charged;        /* bytes charged to def.memory */
} wb_volumes;

/* a snapshot image's volume constraints (snapshot.h), in creation order */
typedef struct wb_image_volume {
    int32_t n;
    int32_t *ijkl;         /* (n x 4) */
    wb_real *alpha, *rest; /* (n) compliance, signed rest volume */
    wb_real *plastic;      /* (n x 2) yield, creep (0: none) */
} wb_image_volume;

/* room for `extra` more, charged to the memory budget; after it wb__volume_put cannot fail */
wb_status wb__volume_reserve(wb_world *w, int64_t extra);
void wb__volume_put(wb_world *w, const int32_t p[4], wb_real alpha, wb_real rest);
/* plastic flow (yield, creep as a distance's) for the constraints from `first` on: a body's
 * builder gives them its links' */
void wb__volume_plastic(wb_world *w, int32_t first, wb_real yield, wb_real creep);
/* tets.c: a lattice cell's 6 tets (Kuhn), corner c at base + (c&1) sx + (c&2) sy + (c&4) sz:
 * volume constraints of compliance alpha, or Neo-Hookean tets (tet.h) when young > 0 */
void wb__kuhn_tets(wb_world *w, int32_t base, int32_t sx, int32_t sy, int32_t sz, wb_real alpha,
                   wb_real young, wb_real poisson);

/* the volumes' corners, wb_volume_count x 4 (NULL: none; distance.c's links backed by them) */
const int32_t *wb__volume_corners(const wb_world *w);

#endif
