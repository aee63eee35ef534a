/* shape_plane.c: a plane collider, the half-space behind a unit normal through the
 * collider's position (kinematic only: no rigid body is a plane). */
#include "shape.h"

static const char *check(const wb_collider_def *d)
{
    if (!wb__fin3(d->normal) || !isfinite(d->offset)) return "normal and offset must be finite";
    if (!(v3_len_safe(d->normal) > 1e-12)) return "normal must not be zero";
    /* the plane's point is offset/|normal| along it */
    if (!isfinite(d->offset / v3_len_safe(d->normal))) return "offset / |normal| overflows: offset must be finite over a unit normal";
    return NULL;
}

static void make(const wb_collider_def *d, wb_cshape *s, wb_real p[3], wb_real q[4])
{
    (void)q;
    wb_real n = v3_len_safe(d->normal);
    v3_scale(s->n, d->normal, 1 / n);
    v3_scale(p, s->n, d->offset / n); /* the plane passes through its position */
}

static const char *check_shape(const wb_cshape *s)
{
    return v3_len(s->n) > 1e-12 ? NULL : "plane normal must not be zero";
}

static wb_real distance(const wb_cshape *s, const wb_real l[3], wb_real nl[3])
{
    v3_copy(nl, s->n);
    return v3_dot(l, s->n);
}

static wb_real bound(const wb_cshape *s) { (void)s; return -1; }

const wb_shape_class wb__shape_plane = {
    .info = { "plane", "normal offset", "normal", NULL }, .check = check, .make = make, .check_shape = check_shape, .distance = distance, .bound = bound,
};
