/* rigid_image.c: rigid bodies in a world's image (snapshot.h): copied out exactly, checked,
 * and put back exactly (same hash, same future) or appended to another world. */
#include "rigid.h"
#include "snapshot.h"

wb_status wb_image_alloc_rigids(wb_image *g, int32_t n)
{
    wb__rigid_image_free(g);
    g->rb = calloc((size_t)(n > 0 ? n : 1), sizeof *g->rb);
    g->rb_gen = calloc((size_t)(n > 0 ? n : 1), sizeof *g->rb_gen);
    if (!g->rb || !g->rb_gen) { wb__rigid_image_free(g); return WB_ERR_NOMEM; }
    for (int32_t i = 0; i < n; i++) {
        g->rb_gen[i] = 1;
        g->rb[i].q[0] = 1;
    }
    g->nrb = n;
    return WB_OK;
}

void wb__rigid_image_free(wb_image *g)
{
    free(g->rb);
    free(g->rb_gen);
    g->rb = NULL;
    g->rb_gen = NULL;
    g->nrb = 0;
}

wb_status wb_image_rigid_from_def(const wb_rigid_def *d, wb_image_rigid *o)
{
    const char *e = wb_rigid_def_check(d);
    if (e) { wb__set_error("%s", e); return WB_ERR_ARG; }
    memset(o, 0, sizeof *o);
    o->shape = d->shape;
    o->friction = d->friction;
    o->restitution = d->restitution;
    o->mass = d->mass;
    v3_copy(o->v, d->vel);
    v3_copy(o->om, d->angular_velocity);
    wb_cshape s;
    wb__rigid_shape_of(d, &s, o->x, o->q); /* as wb_rigid_add */
    o->radius = s.radius;
    v3_copy(o->half, s.half);
    v3_copy(o->a, s.a);
    v3_copy(o->b, s.b);
    return WB_OK;
}

wb_status wb__rigid_image_of(const wb_world *w, wb_image *g)
{
    const wb_rigids *rb = w->rb;
    if (!rb || rb->n == 0) { wb__rigid_image_free(g); return WB_OK; }
    if (wb_image_alloc_rigids(g, rb->n) != WB_OK) return WB_ERR_NOMEM;
    for (int32_t r = 0; r < rb->n; r++) {
        wb_image_rigid *o = &g->rb[r];
        const wb_cshape *s = &rb->shape[r];
        g->rb_gen[r] = rb->gen[r];
        o->shape = s->shape;
        o->radius = s->radius;
        v3_copy(o->half, s->half);
        v3_copy(o->a, s->a);
        v3_copy(o->b, s->b);
        o->friction = s->friction;
        o->restitution = s->restitution;
        o->mass = rb->mass[r];
        v3_copy(o->x, &rb->x[3 * r]);
        memcpy(o->q, &rb->q[4 * r], sizeof o->q);
        v3_copy(o->v, &rb->v[3 * r]);
        v3_copy(o->om, &rb->om[3 * r]);
    }
    return WB_OK;
}

static int fin(const wb_real *v, int n)
{
    for (int i = 0; i < n; i++)
        if (!isfinite(v[i])) return 0;
    return 1;
}

const char *wb_image_rigid_check(const wb_image_rigid *o)
{
    wb_rigid_def d = wb_rigid_default_def(o->shape);
    d.radius = o->radius;
    v3_copy(d.half, o->half);
    v3_copy(d.a, o->a);
    v3_copy(d.b, o->b);
    d.mass = o->mass;
    d.friction = o->friction;
    d.restitution = o->restitution;
    v3_copy(d.pos, o->x);
    memcpy(d.rotation, o->q, sizeof d.rotation);
    v3_copy(d.vel, o->v);
    v3_copy(d.angular_velocity, o->om);
    const char *e = wb_rigid_def_check(&d);
    if (e) return e;
    if (!fin(o->q, 4) || fabs(o->q[0] * o->q[0] + v3_dot(&o->q[1], &o->q[1]) - 1) > 1e-9)
        return "rigid body rotation must be a unit quaternion";
    /* the shape about its centre of mass */
    const wb_shape_class *k = wb__shape(o->shape);
    if (!k->rigid_check_shape) return NULL;
    wb_cshape s = { .shape = o->shape, .radius = o->radius };
    v3_copy(s.half, o->half);
    v3_copy(s.a, o->a);
    v3_copy(s.b, o->b);
    return k->rigid_check_shape(&s);
}

const char *wb__rigid_image_check(const wb_image *g)
{
    if (g->nrb < 0 || g->nrb > WB_MAX_RIGIDS) return "too many rigid bodies";
    for (int32_t r = 0; r < g->nrb; r++) {
        if (!(g->rb_gen[r] & 1u)) continue;
        const char *e = wb_image_rigid_check(&g->rb[r]);
        if (e) return e;
    }
    return NULL;
}

int32_t wb_rigid_list(const wb_world *w, wb_rigid_id *out, int32_t cap)
{
    int32_t k = 0;
    for (int32_t r = 0; w->rb && r < w->rb->n && k < cap; r++)
        if (w->rb->gen[r] & 1u) {
            out[k].index = (uint32_t)r + 1;
            out[k].gen = w->rb->gen[r];
            k++;
        }
    return k;
}

/* the slot an appended body takes: free ones lowest first, then new ones */
static int32_t free_slots(const wb_world *w)
{
    int32_t n = 0;
    for (int32_t r = 0; w->rb && r < w->rb->n; r++) n += !(w->rb->gen[r] & 1u);
    return n;
}

wb_status wb__rigid_reserve(wb_world *w, const wb_image *g, int exact)
{
    int32_t live = 0;
    for (int32_t r = 0; r < g->nrb; r++) live += (int32_t)(g->rb_gen[r] & 1u);
    if (g->nrb == 0 || (!exact && live == 0)) return WB_OK;
    int64_t need = exact ? g->nrb : (int64_t)(w->rb ? w->rb->n : 0) + (live - free_slots(w));
    if (!exact && need <= (w->rb ? w->rb->n : 0)) return WB_OK;
    if (need > WB_MAX_RIGIDS) return WB_ERR_LIMIT;
    return wb__rigids_reserve(w, (int32_t)need) ? WB_OK : WB_ERR_NOMEM;
}

static void put_one(wb_world *w, int32_t slot, const wb_image_rigid *o)
{
    wb_cshape s;
    memset(&s, 0, sizeof s);
    s.shape = o->shape;
    s.radius = o->radius;
    v3_copy(s.half, o->half);
    v3_copy(s.a, o->a);
    v3_copy(s.b, o->b);
    s.friction = o->friction;
    s.restitution = o->restitution;
    wb__rigid_set_slot(w, slot, &s, o->mass, o->x, o->q, o->v, o->om); /* checked: cannot fail */
}

void wb__rigid_put(wb_world *w, const wb_image *g, int exact, int32_t *map)
{
    if (g->nrb == 0) return;
    wb_rigids *rb = w->rb;
    rb->free_hint = 0; /* slots change here: search from the start again */
    if (exact) {
        for (int32_t r = 0; r < g->nrb; r++) {
            if (map) map[r] = r;
            rb->gen[r] = g->rb_gen[r];
            if (g->rb_gen[r] & 1u) put_one(w, r, &g->rb[r]);
            else memset(&rb->shape[r], 0, sizeof rb->shape[r]);
        }
        rb->n = g->nrb;
        return;
    }
    int32_t scan = 0;
    for (int32_t r = 0; r < g->nrb; r++) {
        if (map) map[r] = -1;
        if (!(g->rb_gen[r] & 1u)) continue;
        int32_t slot = -1;
        for (; scan < rb->n && slot < 0; scan++)
            if (!(rb->gen[scan] & 1u)) slot = scan;
        if (slot < 0) {
            slot = rb->n++;
            rb->gen[slot] = 0;
        }
        put_one(w, slot, &g->rb[r]);
        rb->gen[slot]++;
        if (map) map[r] = slot;
    }
}
