/* tricontact.h: particle-triangle contacts (tricontact.c) and their broad phase
 * (tribroad.c): the per-frame scratch (w->k.tc, made and freed by tribroad.c) and the
 * step's passes. */
#ifndef WB_TRICONTACT_H
#define WB_TRICONTACT_H

#include <stdlib.h>

#include "grid.h"
#include "vec.h"

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
/* Point p against triangle v (corners' ids), the rule the projection (tricontact.c) and
 * VBD's coupled step (vbd_contact.c) share. wb__tri_side: the triangle's unit normal n now
 * (the zero cross product when it is degenerate: *ln 0), p's signed distance from its plane
 * now *s_now, and the side p was on at the substep's start (x_prev's plane; a signed
 * volume, not a distance) *s_prev; both 0 on a degenerate triangle. */
static inline __attribute__((always_inline)) void
wb__tri_side(const wb_real *x, const wb_real *xp, int32_t p, const int32_t *v, wb_real n[3], wb_real *ln, wb_real *s_prev,
             wb_real *s_now)
{
    wb_real e1[3], e2[3];
    v3_sub(e1, &x[3 * v[1]], &x[3 * v[0]]);
    v3_sub(e2, &x[3 * v[2]], &x[3 * v[0]]);
    v3_cross(n, e1, e2);
    *ln = v3_len(n);
    *s_prev = *s_now = 0;
    if (!(*ln > 0)) return;
    wb_real f1[3], f2[3], np[3], dp[3], d[3];
    v3_scale(n, n, 1 / *ln);
    v3_sub(f1, &xp[3 * v[1]], &xp[3 * v[0]]);
    v3_sub(f2, &xp[3 * v[2]], &xp[3 * v[0]]);
    v3_cross(np, f1, f2);
    v3_sub(dp, &xp[3 * p], &xp[3 * v[0]]);
    *s_prev = v3_dot(dp, np);
    v3_sub(d, &x[3 * p], &x[3 * v[0]]);
    *s_now = v3_dot(d, n);
}

/* wb__tri_normal: the contact's normal nn (unit, out of the triangle to p's side) and its
 * depth r - the gap along nn, from wb__tri_side's answers and p's closest point on the
 * triangle (barycentrics b, d = x_p - q, d2 = |d|^2, dist = |d|). Crossed the plane over
 * the face within reach of it since the substep began (the relative move over the substep
 * bounds how far off it could have crossed): back to the side it was on (1). Else within
 * reach of q: away from q (2), or, on the sheet itself, back to its side (3). 0: farther
 * than reach (a touch is the caller's to count); -1: on a degenerate triangle, no
 * direction. */
static inline __attribute__((always_inline)) int
wb__tri_normal(const wb_real *x, const wb_real *xp, int32_t p, const int32_t *v, const wb_real n[3], wb_real ln,
               wb_real s_prev, wb_real s_now, const wb_real b[3], const wb_real d[3], wb_real d2, wb_real dist, wb_real r,
               wb_real reach, wb_real nn[3], wb_real *depth)
{
    if (s_prev != 0 && s_now * s_prev < 0 && b[0] > 0 && b[1] > 0 && b[2] > 0) {
        wb_real rel[3];
        v3_sub(rel, &x[3 * p], &xp[3 * p]);
        for (int i = 0; i < 3; i++) v3_madd(rel, &x[3 * v[i]], -b[i]), v3_madd(rel, &xp[3 * v[i]], b[i]);
        if (dist < r + v3_len(rel)) {
            v3_scale(nn, n, s_prev > 0 ? 1 : -1);
            *depth = r - v3_dot(d, nn);
            return 1;
        }
    }
    if (!(d2 < reach * reach)) return 0;
    if (dist > r * (wb_real)1e-9 || ln == 0) {
        if (!(dist > 0)) return -1;
        v3_scale(nn, d, 1 / dist);
        *depth = r - dist;
        return 2;
    }
    const wb_real side = s_prev < 0 || (s_prev == 0 && s_now < 0) ? -1 : 1;
    v3_scale(nn, n, side);
    *depth = r - side * s_now;
    return 3;
}

/* the step's three passes, as contact.c's: the broad phase
 * in tribroad.c, the projection and velocity pass in tricontact.c */
void wb__tricontacts_begin(wb_world *w);
void wb__tricontacts_project(wb_world *w, wb_real h);
void wb__tricontacts_velocity(wb_world *w, wb_real h);

#endif
