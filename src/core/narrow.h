/* narrow.h: contact manifolds between two shapes at poses for rigid bodies. Pure geometry. */
#ifndef WB_NARROW_H
#define WB_NARROW_H
#include "core.h"

#define WB_MANIFOLD_MAX 8
typedef struct wb_manifold_point {
    wb_real pa[3], pb[3];   /* world points on A's and on B's surface */
    wb_real depth;          /* penetration along normal: (pa - pb).normal; > 0 overlapping */
} wb_manifold_point;
typedef struct wb_manifold {
    int n;                  /* 0..WB_MANIFOLD_MAX points */
    wb_real normal[3];      /* unit, pointing from A towards B (push B along +normal) */
    wb_manifold_point pt[WB_MANIFOLD_MAX];
} wb_manifold;

/* The points where A and B are closer than `margin` (depth > -margin), with one normal.
 * A and B: sphere, box, capsule, plane (a plane is a half-space: n in its frame, through
 * its origin) in either order; mesh colliders against sphere, box, capsule (A or B).
 * Returns out->n. Box-box gives a proper manifold (face clipping, up to 8 points; edge-
 * edge 1 point) so boxes stack. */
int wb__narrow(const wb_cshape *a, const wb_real pa[3], const wb_real qa[4],
               const wb_cshape *b, const wb_real pb[3], const wb_real qb[4],
               wb_real margin, wb_manifold *out);
#endif
