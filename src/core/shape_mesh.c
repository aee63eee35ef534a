/* shape_mesh.c: a triangle-mesh collider (kinematic only): a copy of the def's mesh
 * scaled into the collider's frame, with its tree (bvh.c). Closed, it has an inside;
 * open, two sides (collide.c keeps a particle on the side it came from). */
#include "shape.h"
#include "bvh.h"

static const char *check(const wb_collider_def *d)
{
    if (!d->mesh) return "mesh is missing";
    if (d->mesh->nt <= 0) return "mesh is empty (no triangles)";
    if (!(d->scale > 0) || !isfinite(d->scale)) return "scale must be > 0";
    if (!wb__fin3(d->center)) return "center must be finite";
    const char *e = wb__rotation_check(d->rotation);
    if (e) return e;
    for (int64_t i = 0; i < 3 * (int64_t)d->mesh->nv; i++)
        if (!isfinite(d->mesh->v[i] * d->scale)) return "mesh vertices x scale must be finite";
    for (int64_t i = 0; i < 3 * (int64_t)d->mesh->nt; i++)
        if (d->mesh->tri[i] < 0 || d->mesh->tri[i] >= d->mesh->nv) return "mesh corner out of range";
    return NULL;
}

static void make(const wb_collider_def *d, wb_cshape *s, wb_real p[3], wb_real q[4])
{
    (void)s;
    v3_copy(p, d->center);
    memcpy(q, d->rotation, 4 * sizeof(wb_real));
    q_normalize(q);
}

static wb_real distance(const wb_cshape *s, const wb_real l[3], wb_real nl[3])
{
    return wb__colmesh_distance(s->mesh, l, nl, NULL, NULL);
}

static wb_real bound(const wb_cshape *s) { (void)s; return -1; }

const wb_shape_class wb__shape_mesh = {
    .info = { "mesh", "mesh center rotation scale", "vertices triangles", NULL }, .has_mesh = 1, .check = check, .make = make, .distance = distance, .bound = bound,
};
