/* shape_box.c: an oriented box about the frame's origin (half extents along its axes),
 * collider or rigid body. */
#include "shape.h"

static const char *check(const wb_collider_def *d)
{
    if (!wb__fin3(d->center)) return "center must be finite";
    if (!(d->half[0] > 0 && d->half[1] > 0 && d->half[2] > 0) || !wb__fin3(d->half)) return "half extents must be > 0";
    return wb__rotation_check(d->rotation);
}

static void make(const wb_collider_def *d, wb_cshape *s, wb_real p[3], wb_real q[4])
{
    v3_copy(s->half, d->half);
    v3_copy(p, d->center);
    memcpy(q, d->rotation, 4 * sizeof(wb_real));
    q_normalize(q);
}

static const char *check_shape(const wb_cshape *s)
{
    return s->half[0] > 0 && s->half[1] > 0 && s->half[2] > 0 ? NULL : "box half extents must be > 0";
}

static wb_real distance(const wb_cshape *s, const wb_real l[3], wb_real nl[3])
{
    wb_real d[3], o[3] = { 0, 0, 0 }, dist;
    int inside = 1;
    for (int i = 0; i < 3; i++) {
        d[i] = fabs(l[i]) - s->half[i];
        if (d[i] > 0) { o[i] = l[i] > 0 ? d[i] : -d[i]; inside = 0; }
    }
    if (!inside) {
        dist = v3_len(o);
        v3_scale(nl, o, 1 / dist);
    } else {
        /* nearest face */
        int k = d[0] > d[1] ? (d[0] > d[2] ? 0 : 2) : (d[1] > d[2] ? 1 : 2);
        v3_set(nl, 0, 0, 0);
        nl[k] = l[k] >= 0 ? 1 : -1;
        dist = d[k];
    }
    return dist;
}

static wb_real bound(const wb_cshape *s) { return v3_len(s->half); }

static int solids(const wb_cshape *s, const wb_real p[3], const wb_real q[4], wb_solid out[WB_MAX_SOLIDS])
{
    memset(out, 0, sizeof *out);
    out->kind = WB_SOLID_BOX;
    v3_copy(out->c, p);
    for (int k = 0; k < 3; k++) {
        wb_real e[3] = { 0, 0, 0 };
        e[k] = s->half[k];
        q_rotate(q, e, out->axes[k]);
    }
    return 1;
}

static const char *rigid_check(const wb_rigid_def *d)
{
    if (!(d->half[0] > 0 && d->half[1] > 0 && d->half[2] > 0) || !wb__fin3(d->half)) return "half extents must be > 0";
    if (!isfinite(v3_dot(d->half, d->half) * d->mass)) return "half extents are too large";
    return NULL;
}

static int rigid_make(const wb_rigid_def *d, wb_cshape *s, wb_real c[3])
{
    (void)c;
    v3_copy(s->half, d->half);
    return 0;
}

static void inertia(const wb_cshape *s, wb_real m, wb_real I[9])
{
    const wb_real x = s->half[0] * s->half[0], y = s->half[1] * s->half[1], z = s->half[2] * s->half[2];
    I[0] = m * (y + z) / 3;
    I[4] = m * (x + z) / 3;
    I[8] = m * (x + y) / 3;
}

const wb_shape_class wb__shape_box = {
    .info = { "box", "center half rotation", "half", "half" }, .check = check, .make = make, .check_shape = check_shape, .distance = distance, .bound = bound, .solids = solids,
    .rigid_check = rigid_check, .rigid_make = rigid_make, .inertia = inertia,
};
