/* shape_capsule.c: a capsule, the points within radius of a segment whose midpoint is
 * the frame's origin, collider or rigid body. */
#include "shape.h"

static const char *check(const wb_collider_def *d)
{
    if (!wb__fin3(d->a) || !wb__fin3(d->b)) return "a and b must be finite";
    /* distances to the segment square b - a */
    const wb_real ab[3] = { d->b[0] - d->a[0], d->b[1] - d->a[1], d->b[2] - d->a[2] };
    if (!isfinite(v3_dot(ab, ab))) return "a and b are too far apart (|b - a| squared overflows)";
    if (!(d->radius > 0) || !isfinite(d->radius)) return "radius must be > 0";
    return NULL;
}

static void make(const wb_collider_def *d, wb_cshape *s, wb_real p[3], wb_real q[4])
{
    (void)q;
    s->radius = d->radius;
    wb__midpoint(d->a, d->b, p);
    v3_sub(s->a, d->a, p);
    v3_sub(s->b, d->b, p);
}

static const char *check_shape(const wb_cshape *s)
{
    if (!(s->radius > 0)) return "collider radius must be > 0";
    wb_real ab[3];
    v3_sub(ab, s->b, s->a);
    if (!isfinite(v3_dot(ab, ab))) return "capsule ends are too far apart (|b - a| squared overflows)";
    return NULL;
}

static wb_real distance(const wb_cshape *s, const wb_real l[3], wb_real nl[3])
{
    wb_real ab[3], al[3], c[3];
    v3_sub(ab, s->b, s->a);
    v3_sub(al, l, s->a);
    wb_real ll = v3_dot(ab, ab), t = ll > 0 ? clampr(v3_dot(al, ab) / ll, 0, 1) : 0;
    v3_copy(c, s->a);
    v3_madd(c, ab, t);
    v3_sub(c, l, c);
    wb_real len = v3_len(c);
    if (len > 0) v3_scale(nl, c, 1 / len);
    else v3_set(nl, 0, 1, 0);
    return len - s->radius;
}

static wb_real bound(const wb_cshape *s) { return fmax(v3_len(s->a), v3_len(s->b)) + s->radius; }

static void segment(const wb_cshape *s, const wb_real p[3], const wb_real q[4], wb_real a[3], wb_real b[3])
{
    q_rotate(q, s->a, a);
    v3_add(a, a, p);
    q_rotate(q, s->b, b);
    v3_add(b, b, p);
}

/* a ball at each end and the cylinder between */
static int solids(const wb_cshape *s, const wb_real p[3], const wb_real q[4], wb_solid out[WB_MAX_SOLIDS])
{
    wb_real a[3], b[3];
    segment(s, p, q, a, b);
    memset(out, 0, 3 * sizeof *out);
    out[0].kind = out[1].kind = WB_SOLID_SPHERE;
    out[2].kind = WB_SOLID_CYLINDER;
    v3_copy(out[0].c, a);
    v3_copy(out[1].c, b);
    v3_copy(out[2].a, a);
    v3_copy(out[2].b, b);
    out[0].radius = out[1].radius = out[2].radius = s->radius;
    return 3;
}

static const char *rigid_check(const wb_rigid_def *d)
{
    if (!(d->radius > 0) || !isfinite(d->radius * d->radius * d->mass)) return "radius must be > 0 (and not huge)";
    if (!wb__fin3(d->a) || !wb__fin3(d->b)) return "a and b must be finite";
    const wb_real ab[3] = { d->b[0] - d->a[0], d->b[1] - d->a[1], d->b[2] - d->a[2] };
    if (!isfinite(v3_dot(ab, ab) * d->mass)) return "a and b are too far apart";
    return NULL;
}

/* the segment about its midpoint, the centre of mass */
static int rigid_make(const wb_rigid_def *d, wb_cshape *s, wb_real c[3])
{
    s->radius = d->radius;
    wb__midpoint(d->a, d->b, c);
    v3_sub(s->a, d->a, c);
    v3_sub(s->b, d->b, c);
    return 1;
}

static const char *rigid_check_shape(const wb_cshape *s)
{
    for (int i = 0; i < 3; i++)
        if (fabs(s->a[i] + s->b[i]) > 1e-9 * (1 + fabs(s->a[i]) + fabs(s->b[i])))
            return "rigid capsule a and b must be about its centre (a = -b)";
    return NULL;
}

static void inertia(const wb_cshape *s, wb_real m, wb_real I[9])
{
    /* a cylinder of length L and two hemispheres (together a ball), mass by volume */
    wb_real u[3];
    v3_sub(u, s->b, s->a);
    const wb_real L = v3_len(u), r = s->radius, r2 = r * r;
    const wb_real vc = M_PI * r2 * L, vs = (wb_real)4 / 3 * M_PI * r2 * r;
    const wb_real mc = m * vc / (vc + vs), ms = m * vs / (vc + vs);
    /* axial: the cylinder's m r^2/2, the ball's 2/5 m r^2 */
    const wb_real ia = mc * r2 / 2 + ms * r2 * (wb_real)0.4;
    /* transverse: the cylinder's m (L^2/12 + r^2/4); each hemisphere about its own centroid
     * (83/320 m r^2) shifted by the parallel-axis term to L/2 + 3r/8 from the centre:
     * together ms (2/5 r^2 + L^2/4 + 3 L r/8) */
    const wb_real it = mc * (L * L / 12 + r2 / 4) + ms * ((wb_real)0.4 * r2 + L * L / 4 + 3 * L * r / 8);
    if (L > 0) v3_scale(u, u, 1 / L);
    else v3_set(u, 0, 1, 0);
    for (int i = 0; i < 3; i++)
        for (int j = 0; j < 3; j++) I[3 * i + j] = (i == j ? it : 0) + (ia - it) * u[i] * u[j];
}

const wb_shape_class wb__shape_capsule = {
    .info = { "capsule", "a b radius", "a b radius", "radius a b" }, .check = check, .make = make, .check_shape = check_shape, .distance = distance,
    .bound = bound, .segment = segment, .solids = solids, .rigid_check = rigid_check, .rigid_make = rigid_make, .inertia = inertia,
    .rigid_check_shape = rigid_check_shape,
};
