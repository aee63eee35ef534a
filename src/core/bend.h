/* bend.h: the bending constraints' arrays (bend.c), and their section of a snapshot image
 * (snapshot.h). */
#ifndef WB_BEND_H
#define WB_BEND_H

#include "batch.h"

/* w->bend: NULL until the first one is made */
typedef struct wb_bends {
    /* model: what a step does not change */
    int32_t n, cap;        /* constraints (never removed: the slot is the handle) */
    int32_t *ij;           /* (n x 4) p1 p2 = the hinge edge, p3 p4 = the wings */
    wb_real *alpha;        /* (n) compliance, rad/(N m) */
    wb_real *beta;         /* (n) damping (as a distance's, Macklin et al. 2016 eq. 26) */
    wb_real *rest;         /* (n) rest dihedral angle, rad in (-pi, pi] */
    wb_real *btorque;      /* (n) torque that breaks it, N m; 0 = never */
    /* state: what a step changes */
    uint8_t *broken;       /* (n) broken by its torque: no longer projected */
    wb_bend_id *breaks;    /* broken in the last step (reported after it) */
    int32_t nbreaks, cap_breaks;
    size_t charged;        /* bytes charged to def.memory */
    /* cache: packed by colour (batch.h), rebuilt when dirty */
    int dirty;
    wb_batches bt;         /* the batches, ranges into the packed order */
    /* what the projection reads, packed in its order at colour time: one allocation
     * starting at s_ij (bend_destroy frees it), cap_s entries; s_at, s_gamma and the skip
     * flag hold for the substep h_at (recomputed when h changes: NaN = not yet) */
    int32_t *s_ij;         /* (n x 4) packed particles */
    wb_real *s_rest;       /* (n) rest angle */
    wb_real *s_at;         /* (n) alpha / h^2 */
    wb_real *s_gamma;      /* (n) alpha / h^2 * beta * h, the damping's gamma */
    uint8_t *s_flag;       /* (n) 1: skipped (broken, or alpha / h^2 = inf); 2: damped */
    wb_real h_at;
    int32_t cap_s;
    int32_t *s_slot;       /* (n) slot of each packed entry (the batches' order) */
    int32_t *pack;         /* (n) packed index of each slot */
    wb_real *lambda;       /* (n) multipliers of the current substep, by packed index */
} wb_bends;

/* a snapshot image's bends, in creation order: plain data (the JSON files read and write
 * it); allocated by wb_image_alloc_bends */
typedef struct wb_image_bend {
    int32_t n;
    int32_t *ij;           /* (n x 4) hinge p1 p2, wings p3 p4 */
    wb_real *alpha, *beta, *rest; /* (n) compliance, damping, rest angle */
    wb_real *btorque;      /* (n) break_torque, N m (0: never) */
    uint8_t *broken;       /* (n) broken by it */
} wb_image_bend;

/* after it, extra bends add without failing (charged to the memory budget) */
wb_status wb__bend_reserve(wb_world *w, int64_t extra);
/* the dihedral angle of the bend over particles p[0..3] at positions x; *ok = 0
 * when a triangle is degenerate */
wb_real wb__bend_angle_of(const wb_real *x, const int32_t *p, int *ok);
/* the interior edges of a triangle list (each shared by exactly two triangles), as
 * hinges p1 p2 p3 p4 into out (room for 3 ntri / 2 x 4), in edge order; -1 when out of memory */
int32_t wb__bend_hinges(const int32_t *tri, int32_t ntri, int32_t *out);

#endif
