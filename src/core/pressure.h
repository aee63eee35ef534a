/* pressure.h: the pressure constraints' arrays (pressure.c), and their section of a
 * snapshot image (snapshot.h). */
#ifndef WB_PRESSURE_H
#define WB_PRESSURE_H

#include <stddef.h>

#include "wobble.h"

/* balloon constraints over closed surfaces (Müller et al. 2007, Macklin's XPBD form); w->pr:
 * NULL until the first */
typedef struct wb_pressures {
    /* model */
    int32_t n, cap;
    int32_t *surface;               /* (n) the surface it encloses */
    wb_real *pressure, *alpha, *v0; /* (n) target factor, compliance (m^6/J), rest volume */
    int32_t *vstart, *tstart;       /* (n + 1) ranges into verts and tri */
    int32_t nverts, cap_verts;
    int32_t *verts;                 /* (nverts) the surface's particles, ascending */
    int32_t ntri, cap_tri;
    int32_t *tri;                   /* (ntri x 3) corners as indices into its verts range */
    /* cache */
    wb_real *lambda;                /* (n) multipliers of the current substep */
    wb_real *grad;                  /* (largest verts range x 3) scratch */
    int32_t cap_grad;
    size_t charged;
} wb_pressures;

/* a snapshot image's pressure constraints, each over one of the image's surfaces */
typedef struct wb_image_pressure {
    int32_t n;
    int32_t *surface;      /* (n) */
    wb_real *pressure, *alpha, *v0; /* (n) factor, compliance, rest volume */
} wb_image_pressure;

/* the particles of all the surfaces together (momentum.c: its bodies change with them) */
int32_t wb__pressure_vertices(const wb_world *w);

#endif
