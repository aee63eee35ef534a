/* shape.h: collider shapes, a file each (shape_plane.c, shape_sphere.c, shape_box.c,
 * shape_capsule.c, shape_mesh.c), and the table of them (shape.c).
 *
 * A kinematic collider can have any shape, a rigid body one with an inertia (sphere, box,
 * capsule). What a shape does alone is in its file: the checks of its definition, the
 * part of a definition it keeps and about which point, its signed distance, its bound,
 * its inertia. What two shapes do together (contact manifolds) is narrow.c's pair table;
 * how the renderer draws them, render/layers.c. A new shape: its file, its row in
 * wb__shapes[] (shape.c), its row and column in narrow.c's pairs[][], wobble.h's wb_shape. */
#ifndef WB_SHAPE_H
#define WB_SHAPE_H

#include <string.h>

#include "vec.h"

/* a shape in its own frame (a collider's or a rigid body's pose places it) */
typedef struct wb_cshape {
    wb_shape shape;
    wb_real n[3];          /* plane: unit normal in the collider frame */
    wb_real radius;        /* sphere, capsule */
    wb_real half[3];       /* box */
    wb_real a[3], b[3];    /* capsule segment in the collider frame */
    wb_real friction, restitution;
    struct wb_colmesh *mesh; /* mesh: owned triangles and tree (bvh.h); NULL otherwise */
} wb_cshape;

typedef struct wb_shape_class {
    wb_shape_info info;    /* its names and fields (wobble.h) */
    int has_mesh;          /* keeps a copy of a def's mesh (bvh.h's wb_colmesh) */
    /* a collider def's shape fields: NULL when valid, else what is wrong */
    const char *(*check)(const wb_collider_def *d);
    /* the shape in its frame from a valid collider def, and the frame's pose (p, q): p
     * zero and q the identity on entry; the mesh, when it has one, the caller's */
    void (*make)(const wb_collider_def *d, wb_cshape *s, wb_real p[3], wb_real q[4]);
    /* a restored shape's fields (an image's): NULL when valid; the mesh the caller's */
    const char *(*check_shape)(const wb_cshape *s);
    /* signed distance from l (in the shape's frame) to the surface, nl the outward unit
     * normal there (in that frame) */
    wb_real (*distance)(const wb_cshape *s, const wb_real l[3], wb_real nl[3]);
    /* the same from x in the world at pose (p, q), for a shape with a quicker way than
     * into its frame and back; NULL: through distance */
    wb_real (*distance_world)(const wb_cshape *s, const wb_real p[3], const wb_real q[4], const wb_real x[3],
                              wb_real n[3]);
    /* the radius of a ball about the frame's origin that holds the shape; -1 none (a plane
     * is unbounded, a mesh is tested through its tree) */
    wb_real (*bound)(const wb_cshape *s);
    /* a round shape (a segment swept by a ball of s->radius): the segment's ends in the
     * world at pose (p, q); NULL for the others */
    void (*segment)(const wb_cshape *s, const wb_real p[3], const wb_real q[4], wb_real a[3], wb_real b[3]);
    /* what a renderer draws of it at pose (p, q) (wobble.h's wb_solid); NULL: nothing */
    int (*solids)(const wb_cshape *s, const wb_real p[3], const wb_real q[4], wb_solid out[WB_MAX_SOLIDS]);
    /* rigid bodies: NULL for a shape that cannot be one. A rigid def's shape fields:
     * NULL when valid (its mass given: the inertia must stay finite) */
    const char *(*rigid_check)(const wb_rigid_def *d);
    /* the shape from a valid rigid def, about its centre of mass; 1 when that centre is
     * c in the def's frame (not its origin) */
    int (*rigid_make)(const wb_rigid_def *d, wb_cshape *s, wb_real c[3]);
    /* the inertia tensor of mass m about the centre of mass, in the body frame, into I
     * (row-major, zero on entry) */
    void (*inertia)(const wb_cshape *s, wb_real m, wb_real I[9]);
    /* a restored rigid shape (an image's) about its centre of mass: NULL when it is, else
     * what is wrong; NULL: always */
    const char *(*rigid_check_shape)(const wb_cshape *s);
} wb_shape_class;

extern const wb_shape_class wb__shape_plane, wb__shape_sphere, wb__shape_box, wb__shape_capsule, wb__shape_mesh;

/* shape.c: the class of shape s; NULL when s is not a shape */
const wb_shape_class *wb__shape(wb_shape s);
/* distance from x (world) to the surface of shape s at pose (p, q); n: outward unit normal */
wb_real wb__shape_distance(const wb_cshape *s, const wb_real p[3], const wb_real q[4], const wb_real x[3],
                           wb_real n[3]);
/* the class's bound (-1: none) */
wb_real wb__shape_bound(const wb_cshape *s);
/* the class's solids at pose (p, q) (0 when it has none) */
int wb__shape_solids(const wb_cshape *s, const wb_real p[3], const wb_real q[4], wb_solid out[WB_MAX_SOLIDS]);

/* what the shapes' checks share */
static inline int wb__fin3(const wb_real *v) { return isfinite(v[0]) && isfinite(v[1]) && isfinite(v[2]); }
/* a rotation a def gives: finite and not zero (it is normalised) */
static inline const char *wb__rotation_check(const wb_real r[4])
{
    if (!wb__fin3(&r[1]) || !isfinite(r[0])) return "rotation must be finite";
    if (!(fmax(fabs(r[0]), v3_len_safe(&r[1])) > 1e-12)) return "rotation must not be zero";
    return NULL;
}
/* the midpoint of a and b, halved first: a + b overflows for a = b = 1e308 */
static inline void wb__midpoint(const wb_real a[3], const wb_real b[3], wb_real c[3])
{
    c[0] = a[0] / 2 + b[0] / 2; c[1] = a[1] / 2 + b[1] / 2; c[2] = a[2] / 2 + b[2] / 2;
}

#endif
