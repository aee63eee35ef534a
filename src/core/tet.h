/* tet.h: the Neo-Hookean tetrahedra's arrays (tet.c), for the core files that copy them
 * (snapshot.c, query.c) and the builders that make them (builders.c, tets.c). */
#ifndef WB_TET_H
#define WB_TET_H

#include <stdlib.h>

#include "batch.h"

/* w->neo: NULL until the first one is made */
typedef struct wb_neos {
    int32_t n, cap;
    int32_t *ijkl;         /* (n x 4) model: corners */
    wb_real *dminv;        /* (n x 9) state: rest edge matrix inverse, row-major (plastic flow
                              changes it) */
    wb_real *v0;           /* (n) state: rest volume, m^3 (> 0), with Dm^-1 */
    wb_real *yield, *creep; /* (n) model: plastic flow of the rest shape (tet.c); 0 none */
    int plastic;           /* some tet has yield and creep > 0 */
    wb_real *young, *poisson; /* (n) model: as given */
    wb_real *mu, *lam;     /* (n) derived: Lamé parameters of the constraint form */
    wb_real *ld, *lh;      /* (n) cache: deviatoric, hydrostatic multipliers of the substep,
                              by batch position */
    int32_t *order;        /* (n) cache: slots by colour batch (batch.h) */
    int32_t *pk;           /* (n x 4) cache: corners in batch order */
    wb_real *pd;           /* (n x 12) cache in batch order: Dm^-1 (9), the compliances over h^2
                              1/(mu V0 h^2), 1/(lam V0 h^2), and 1 + mu/lam (tet.c) */
    wb_real pd_h;          /* the substep those compliances are for (0: none yet) */
    wb_batches bt;         /* cache: the batches, rebuilt when n changes */
    size_t charged;        /* bytes charged to def.memory */
    wb_real warned_h;      /* the substep last warned about as too long (0: none), tet.c */
    int32_t warned_n;      /* ... and the tet count then */
    int32_t advised;       /* the substeps then advised (0: none) */
    int inverted_warned;   /* the inverted-tets warning was given */
} wb_neos;

/* a snapshot image's Neo-Hookean tets (snapshot.h), in creation order */
typedef struct wb_image_tet {
    int32_t n;
    int32_t *ijkl;         /* (n x 4) */
    wb_real *dminv;        /* (n x 9) rest edge matrix inverse, row-major */
    wb_real *v0, *young, *poisson; /* (n) rest volume (> 0), E, nu */
    wb_real *plastic;      /* (n x 2) yield, creep (0: none) */
} wb_image_tet;

/* room for `extra` more, charged to the memory budget; after it wb__tet_put cannot fail */
wb_status wb__tet_reserve(wb_world *w, int64_t extra);
/* append one with its rest state (dminv row-major, v0 > 0) */
void wb__tet_put(wb_world *w, const int32_t p[4], const wb_real dminv[9], wb_real v0, wb_real young, wb_real poisson);
/* append one at rest in its current shape; false (nothing added) when it is flat */
bool wb__tet_put_current(wb_world *w, const int32_t p[4], wb_real young, wb_real poisson);
/* plastic flow (yield, creep) for the tets from `first` on: a body's builder gives them
 * its links' options */
void wb__tet_plastic(wb_world *w, int32_t first, wb_real yield, wb_real creep);

/* the tets' corners, wb_tet_count x 4 (NULL: none; distance.c's links backed by them) */
const int32_t *wb__tet_corners(const wb_world *w);

#endif
