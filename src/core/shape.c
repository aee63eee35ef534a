/* shape.c: the table of collider shapes (shape.h), in wb_shape's order, and what goes
 * through it for every shape: the signed distance at a pose, the bound. */
#include "shape.h"

static const wb_shape_class *const shapes[WB_SHAPE_COUNT] = {
    [WB_SHAPE_PLANE] = &wb__shape_plane,
    [WB_SHAPE_SPHERE] = &wb__shape_sphere,
    [WB_SHAPE_BOX] = &wb__shape_box,
    [WB_SHAPE_CAPSULE] = &wb__shape_capsule,
    [WB_SHAPE_MESH] = &wb__shape_mesh,
};

const wb_shape_class *wb__shape(wb_shape s)
{
    return (unsigned)s < WB_SHAPE_COUNT ? shapes[s] : NULL;
}

const wb_shape_info *wb_shape_info_of(wb_shape s)
{
    const wb_shape_class *k = wb__shape(s);
    return k ? &k->info : NULL;
}

bool wb_shape_takes(const char *fields, const char *key)
{
    const size_t n = strlen(key);
    for (const char *p = fields; p && *p;) {
        while (*p == ' ') p++;
        const char *e = p;
        while (*e && *e != ' ') e++;
        if ((size_t)(e - p) == n && n > 0 && !strncmp(p, key, n)) return true;
        p = e;
    }
    return false;
}

wb_real wb__shape_distance(const wb_cshape *s, const wb_real p[3], const wb_real q[4], const wb_real x[3],
                           wb_real n[3])
{
    const wb_shape_class *k = wb__shape(s->shape);
    if (k && k->distance_world) return k->distance_world(s, p, q, x, n);
    wb_real r[3], l[3], nl[3];
    v3_sub(r, x, p);
    q_rotate_inv(q, r, l);
    wb_real dist;
    if (k) dist = k->distance(s, l, nl);
    else {
        v3_set(nl, 0, 1, 0);
        dist = INFINITY;
    }
    q_rotate(q, nl, n);
    return dist;
}

int wb__shape_solids(const wb_cshape *s, const wb_real p[3], const wb_real q[4], wb_solid out[WB_MAX_SOLIDS])
{
    const wb_shape_class *k = wb__shape(s->shape);
    return k && k->solids ? k->solids(s, p, q, out) : 0;
}

wb_real wb__shape_bound(const wb_cshape *s)
{
    const wb_shape_class *k = wb__shape(s->shape);
    return k ? k->bound(s) : -1;
}
