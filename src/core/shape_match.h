/* shape_match.h: the data of shape-matching clusters (shape_match.c) and of pressure
 * constraints (pressure.c), one member each of struct wb_world, and their sections of a
 * snapshot image (snapshot.h). */
#ifndef WB_SHAPE_MATCH_H
#define WB_SHAPE_MATCH_H

#include <stddef.h>

#include "wobble.h"

/* shape-matching clusters (Müller et al. 2005) */
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

/* balloon constraints over closed surfaces (Müller et al. 2007, Macklin's XPBD form) */
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

/* (world.c's wb_world_destroy frees both structs' arrays and gives their charge back) */
struct wb_world;
/* a snapshot image's shape-matching clusters (snapshot.h): model and state by cluster */
typedef struct wb_image_smatch {
    int32_t n, nids;
    int32_t *start;        /* (n + 1) ranges into ids */
    int32_t *ids;          /* (nids) particles */
    wb_real *stiff, *yield, *creep; /* (n) */
    wb_real *rest;         /* (nids x 3) rest shape about its mass centre */
    wb_real *q;            /* (n x 4) rotation at the end of the last frame */
} wb_image_smatch;

/* a snapshot image's pressure constraints, each over one of the image's surfaces */
typedef struct wb_image_pressure {
    int32_t n;
    int32_t *surface;      /* (n) */
    wb_real *pressure, *alpha, *v0; /* (n) factor, compliance, rest volume */
} wb_image_pressure;


#endif
