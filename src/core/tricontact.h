/* tricontact.h: particle-triangle contacts (tricontact.c) and their broad phase
 * (tribroad.c): the per-frame scratch (w->k.tc, made and freed by tribroad.c) and the
 * step's passes. */
#ifndef WB_TRICONTACT_H
#define WB_TRICONTACT_H

#include <stdlib.h>

#include "grid.h"

typedef struct wb_tricontacts {
    int32_t n, cap;        /* candidates of this frame */
    int32_t *pt;           /* (n x 2) point, triangle; in the order tribroad.c explains */
    int32_t nact, cap_act; /* contacts that corrected positions in the current substep */
    int32_t *act;          /* (nact) candidate index */
    wb_real *act_d;        /* (nact x 10) barycentrics, normal (triangle -> point), depth, force, old
                              overlap, mu if sliding */
    int32_t cap_d;
    wb_real *left;         /* (n) overlap a candidate was left with (wb__contact_depth) */
    int32_t cap_left;
    struct wb_tribroad *bp; /* broad-phase scratch (tribroad.c) */
    int32_t last;          /* contacts in the last substep (corrected or in touch) */
    int fresh;             /* a new candidate list: `left` not known yet */
    double broad_ms;       /* its broad phase in the last step */
} wb_tricontacts;

/* tribroad.c's scratch, kept from frame to frame */
typedef struct wb_trilevel {
    wb_grid g;             /* its grid */
    wb_real rn;            /* the largest reach of its points */
    int32_t first, count;  /* its points' sorted positions [first, first + count) */
    int64_t start0;        /* its cells' offsets: start[start0 .. start0 + cells] */
} wb_trilevel;
#define WB_TRI_LEVELS 4
struct wb_tribroad {
    wb_real *reach; int32_t cap_reach;   /* (np) a point's reach, < 0 = not a point */
    wb_real *mv; int32_t cap_mv;         /* (np) how far it may move this frame (reach without radius) */
    wb_real *tbox; int32_t cap_tbox;     /* (ntri x 14) box, motion, normal, order cell (tribroad.c) */
    int32_t *tkey; int32_t cap_tkey;     /* (ntri) the body none of whose points may touch it, or 0 */
    int32_t *pc, *tc, *prun, *trun, *tmp; /* points, triangles kept; their stretches (first, end,
                                             run: tribroad.c's make_runs); scratch */
    int32_t cap_pc, cap_tc, cap_prun, cap_trun, cap_tmp;
    struct wb_tribroad_run *runs; int32_t cap_runs;
    wb_real *boxes; int32_t cap_boxes;   /* (lo, hi) of runs' overlaps */
    wb_real *sp; int32_t cap_sp;         /* sorted points: x, y, z, reach */
    int32_t *sid, *skey, *scell; int32_t cap_sid, cap_skey, cap_scell; /* their particle, key, cell */
    int32_t *start; int32_t cap_start;   /* the levels' counting-sort offsets */
    wb_trilevel lv[WB_TRI_LEVELS];
    int nlv;
    wb_pairbuf *out; int nout;           /* (point, triangle) per thread */
    int32_t *first; int32_t cap_first;   /* (np + 1) sorting them by point */
    int32_t *pt2; int32_t cap_pt2;       /* (2 x candidates) the list sorted by point */
    uint64_t *okey; int32_t cap_okey;    /* (candidates) sort keys of the projection's order */
    const wb_real *sr;                   /* the reaches the search runs with */
    /* the quick answer's triangle runs (key, first, end corner), their corners, how many
     * (-1: too many); a copy of what they depend on (triangles, flags, groups) */
    int32_t *qrun, *qcorner, *qtrun; int32_t cap_qrun, cap_qcorner, cap_qtrun, nq; /* qtrun: a triangle's run, -1 */
    uint8_t *kmodel; int32_t cap_kmodel; int64_t kbytes;
    int32_t knp, knt;
    int qvalid, fresh_only;              /* fresh_only: the search every frame (the tests' reference) */
    int qback, qwait;                    /* frames the quick answer waits after it left many points */
    int64_t rebuilds;                    /* for the tests */
};

/* the closest point of triangle (a, b, c) to p as barycentrics bary (summing to 1) and the
 * point out; returns the squared distance (a degenerate triangle: its nearest edge) */
wb_real wb__tri_closest(const wb_real p[3], const wb_real a[3], const wb_real b[3], const wb_real c[3],
                        wb_real bary[3], wb_real out[3]);
/* the step's three passes, as contact.c's: the broad phase
 * in tribroad.c, the projection and velocity pass in tricontact.c */
void wb__tricontacts_begin(wb_world *w);
void wb__tricontacts_project(wb_world *w, wb_real h);
void wb__tricontacts_velocity(wb_world *w, wb_real h);

#endif
