/* shape_sphere.c: a sphere about the frame's origin, collider or rigid body. */
#include "shape.h"

static const char *check(const wb_collider_def *d)
{
    if (!wb__fin3(d->center)) return "center must be finite";
    if (!(d->radius > 0) || !isfinite(d->radius)) return "radius must be > 0";
    return NULL;
}

static void make(const wb_collider_def *d, wb_cshape *s, wb_real p[3], wb_real q[4])
{
    (void)q;
    s->radius = d->radius;
    v3_copy(p, d->center);
}

static const char *check_shape(const wb_cshape *s)
{
    return s->radius > 0 ? NULL : "collider radius must be > 0";
}

static wb_real distance(const wb_cshape *s, const wb_real l[3], wb_real nl[3])
{
    wb_real len = v3_len(l);
    if (len > 0) v3_scale(nl, l, 1 / len);
    else v3_set(nl, 0, 1, 0);
    return len - s->radius;
}

/* round: no turn into its frame and back (two quaternion rotations a contact) */
static wb_real distance_world(const wb_cshape *s, const wb_real p[3], const wb_real q[4], const wb_real x[3],
                              wb_real n[3])
{
    wb_real r[3], nl[3];
    v3_sub(r, x, p);
    const wb_real len = v3_len(r);
    if (len > 0) v3_scale(n, r, 1 / len);
    else {
        v3_set(nl, 0, 1, 0);
        q_rotate(q, nl, n);
    }
    return len - s->radius;
}

static wb_real bound(const wb_cshape *s) { return s->radius; }

static void segment(const wb_cshape *s, const wb_real p[3], const wb_real q[4], wb_real a[3], wb_real b[3])
{
    (void)s; (void)q;
    v3_copy(a, p);
    v3_copy(b, p);
}

static int solids(const wb_cshape *s, const wb_real p[3], const wb_real q[4], wb_solid out[WB_MAX_SOLIDS])
{
    (void)q;
    memset(out, 0, sizeof *out);
    out->kind = WB_SOLID_SPHERE;
    v3_copy(out->c, p);
    out->radius = s->radius;
    return 1;
}

static const char *rigid_check(const wb_rigid_def *d)
{
    if (!(d->radius > 0) || !isfinite(d->radius * d->radius * d->mass)) return "radius must be > 0 (and not huge)";
    return NULL;
}

static int rigid_make(const wb_rigid_def *d, wb_cshape *s, wb_real c[3])
{
    (void)c;
    s->radius = d->radius;
    return 0;
}

static void inertia(const wb_cshape *s, wb_real m, wb_real I[9])
{
    I[0] = I[4] = I[8] = (wb_real)0.4 * m * s->radius * s->radius;
}

const wb_shape_class wb__shape_sphere = {
    .info = { "sphere", "center radius", "radius", "radius" }, .check = check, .make = make, .check_shape = check_shape, .distance = distance,
    .distance_world = distance_world, .bound = bound, .segment = segment, .solids = solids,
    .rigid_check = rigid_check, .rigid_make = rigid_make, .inertia = inertia,
};
