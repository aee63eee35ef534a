/* distance.h: the distance constraints' arrays (distance.c), and their section of a
 * snapshot image (snapshot.h). */
#ifndef WB_DISTANCE_H
#define WB_DISTANCE_H

#include "batch.h"

/* w->dist: NULL until the first one is made. Links are removed (their slots reused) and
 * broken, so the model is by slot, and the batches (batch.h) order the live ones, with
 * the links meeting on a mirror plane as compounds (distance.c) */
typedef struct wb_distances {
    /* model, by slot: a slot is live while its generation is odd */
    int32_t n, cap, nlive; /* slots, their room, live ones */
    int32_t *ij;           /* (n x 2) particles */
    wb_real *alpha;        /* (n) compliance */
    wb_real *beta;         /* (n) damping */
    wb_real *yield, *creep, *break_strain; /* (n) plasticity and breaking */
    wb_real *bforce;       /* (n) force that breaks it, N; 0 = none */
    uint32_t *gen;         /* (n) generation: odd = live */
    int32_t *free_slots;   /* free slots (stack) */
    int32_t nfree;
    size_t charged;        /* bytes charged to def.memory */
    /* state */
    wb_real *rest;         /* (n) rest lengths (plastic flow changes them) */
    uint8_t *broken;       /* (n) */
    wb_distance_id *breaks; /* broken in the last step (reported after it) */
    int32_t nbreaks, cap_breaks;
    /* cache: the colour batches (batch.h, with compounds) over s_slot, and what the
     * kernels read packed in that order; rebuilt when the world's topology changed */
    wb_batches bt;         /* batch ranges, then the compounds, into s_slot */
    int32_t ns;            /* packed constraints (live and not broken): bt.norder */
    int32_t *s_nsp;        /* (2 x compound members) members of its compound at each end */
    int32_t *s_a, *s_b;    /* (ns) particles */
    wb_real *s_rest, *s_alpha, *s_beta; /* (ns) */
    wb_real *s_lambda;     /* (ns) multipliers of the current substep */
    wb_real *s_jac;        /* (ns) Jacobi scale 1/max(n_a, n_b), n = constraints at a movable end */
    /* the vector path's per-constraint data, views into the allocations of s_jac (4 ns
     * reals) and s_slot (3 ns int32 + ns bytes), freed with them: */
    wb_real *s_wa, *s_wc;  /* (ns) m.w of each end, refreshed every step (wb__colour) */
    wb_real *s_at;         /* (ns) alpha / h^2 for h = s_at_h */
    uint32_t *s_oa, *s_oc; /* (ns) 3 a, 3 c: the ends' offsets in x */
    uint8_t *s_ok;         /* (ns) 1: wa > 0, wc > 0 and alpha / h^2 finite (no masked case) */
    uint8_t *s_backed;     /* (ns) 1: both ends are corners of volume or tet constraints (a
                              compressed link's lengthening is bounded: distance.c) */
    int32_t s_backed_vt[2]; /* the volume and tet counts s_backed was worked out for */
    wb_real s_at_h;        /* the substep s_at and s_ok are for */
    int32_t *s_slot;       /* (ns) constraint slot of each packed entry: the batches' order */
    int32_t *slot_pack;    /* (n) packed index of each slot, -1 when not packed */
    int any_damping;
    int s_lambda_stale;    /* s_lambda is the last substep's: the next projection reads it as 0
                              and writes every one (distance.c); force() reads 0 */
    int any_frame_end;     /* a packed distance constraint can break or flow (distance_frame_end) */
    uint32_t s_w_gen;      /* the m.w_gen s_wa, s_wc were copied at */
} wb_distances;

/* w->dist for reading, wb__dist(w->dist): a world without any (NULL) reads as an empty
 * set, so a reader loops over nothing with no check of its own. Never written through */
static inline const wb_distances *wb__dist(const wb_distances *d)
{
    static const wb_distances none;
    return d ? d : &none;
}

/* prepare, once per step (the type's hook): empty the list of links broken (it reports
 * the step about to run), pack and colour the live links when the world's topology
 * changed (m.topology_dirty, cleared here even without links), then bring the packed
 * copies of what may change between steps up to date */
wb_status wb__colour(wb_world *w);

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
