/* collide.c: kinematic colliders (plane, sphere, oriented box, capsule, triangle mesh)
 * and their projection, friction and restitution.
 *
 * A collider sweeps from its pose at the end of the last step to the pose the script
 * set, substep by substep, so a fast collider pushes particles instead of passing
 * through them. Friction follows Müller et al. 2020 ("Detailed rigid body simulation
 * with extended position based dynamics"): static at position level, dynamic at
 * velocity level, with the normal impulse taken from the penetration depth. */
#include <assert.h>
#include <stdatomic.h>
#include <stdint.h>
#include <stdlib.h>

#include "core.h"
#include "bvh.h"
#include "attach.h"
#include "contact.h"

/* ---- collider API -------------------------------------------------------------------- */
wb_collider_def wb_collider_default_def(wb_shape shape)
{
    wb_collider_def d;
    memset(&d, 0, sizeof d);
    d.shape = shape;
    v3_set(d.normal, 0, 1, 0);
    d.radius = 0.5;
    v3_set(d.half, 0.5, 0.5, 0.5);
    d.rotation[0] = 1;
    v3_set(d.a, 0, -0.5, 0);
    v3_set(d.b, 0, 0.5, 0);
    d.scale = 1;
    return d;
}

const char *wb_collider_def_check(const wb_collider_def *d)
{
    const wb_shape_class *k = wb__shape(d->shape);
    if (!k) return "unknown shape";
    if (!(d->friction >= 0) || !isfinite(d->friction)) return "friction must be >= 0";
    if (!(d->restitution >= 0 && d->restitution <= 1)) return "restitution must be in [0, 1]";
    return k->check(d);
}

/* a mesh collider's copy against the world's memory budget: 0 when it would pass the limit */
int wb__mesh_charge(wb_world *w, const wb_colmesh *cm)
{
    wb_memory *mem = w->m.def.memory;
    if (!mem) return 1;
    if (mem->limit > 0 && (double)mem->used + (double)cm->bytes > (double)mem->limit) return 0;
    mem->used += cm->bytes;
    w->m.charged_mesh += cm->bytes;
    return 1;
}

void wb__mesh_release(wb_world *w, wb_cshape *s)
{
    if (!s->mesh) return;
    wb_memory *mem = w->m.def.memory;
    if (mem) mem->used -= s->mesh->bytes;
    w->m.charged_mesh -= s->mesh->bytes;
    wb__colmesh_free(s->mesh);
    s->mesh = NULL;
}

wb_collider_id wb_collider_add(wb_world *w, const wb_collider_def *def, wb_status *status)
{
    wb_collider_id none = { 0, 0 };
    wb_status dummy;
    if (!status) status = &dummy;
    const char *err = wb_collider_def_check(def);
    if (err) { wb__set_error("%s", err); *status = WB_ERR_ARG; return none; }
    wb_model *m = &w->m;
    /* the mesh's copy first: when it fails nothing has changed */
    wb_colmesh *cm = NULL;
    if (wb__shape(def->shape)->has_mesh) {
        cm = wb__colmesh_build(def->mesh->v, def->mesh->nv, def->mesh->tri, def->mesh->nt, def->scale);
        if (!cm) { *status = WB_ERR_NOMEM; return none; }
        if (!wb__mesh_charge(w, cm)) { wb__colmesh_free(cm); *status = WB_ERR_NOMEM; return none; }
    }
    int32_t slot = -1;
    for (int32_t i = 0; i < m->nc; i++)
        if (!(m->c_gen[i] & 1u)) { slot = i; break; }
    if (slot < 0) {
        wb_cshape tmp = { .mesh = cm };
        if (m->nc >= WB_MAX_COLLIDERS) { wb__mesh_release(w, &tmp); *status = WB_ERR_LIMIT; return none; }
        int32_t cap = m->cap_c, cap2 = m->cap_c, cap3 = m->cap_c;
        wb_cshape *sh = wb__grow(m->c_shape, &cap, m->nc + 1, sizeof *sh);
        if (!sh) { wb__mesh_release(w, &tmp); *status = WB_ERR_NOMEM; return none; }
        m->c_shape = sh;
        uint32_t *gen = wb__grow(m->c_gen, &cap2, m->nc + 1, sizeof *gen);
        if (!gen) { wb__mesh_release(w, &tmp); *status = WB_ERR_NOMEM; return none; }
        m->c_gen = gen;
        wb_collider_pose *po = wb__grow(w->s.c_pose, &cap3, m->nc + 1, sizeof *po);
        if (!po) { wb__mesh_release(w, &tmp); *status = WB_ERR_NOMEM; return none; }
        w->s.c_pose = po;
        m->cap_c = cap;
        slot = m->nc++;
        m->c_gen[slot] = 0;
    }
    wb_cshape *s = &m->c_shape[slot];
    wb_collider_pose *p = &w->s.c_pose[slot];
    memset(s, 0, sizeof *s);
    memset(p, 0, sizeof *p);
    s->shape = def->shape;
    s->friction = def->friction;
    s->restitution = def->restitution;
    p->q[0] = 1;
    wb__shape(def->shape)->make(def, s, p->p, p->q);
    s->mesh = cm;
    v3_copy(p->p0, p->p);
    memcpy(p->q0, p->q, sizeof p->q);
    m->c_gen[slot]++;
    *status = WB_OK;
    wb_collider_id id = { (uint32_t)slot + 1, m->c_gen[slot] };
    return id;
}

bool wb_collider_valid(const wb_world *w, wb_collider_id c)
{
    if (c.index == 0 || c.index > (uint32_t)w->m.nc) return false;
    uint32_t g = w->m.c_gen[c.index - 1];
    return (g & 1u) && g == c.gen;
}

#define CSLOT(w, c) (assert(wb_collider_valid((w), (c))), (int32_t)(c).index - 1)

void wb_collider_remove(wb_world *w, wb_collider_id c)
{
    const int32_t i = CSLOT(w, c);
    wb__mesh_release(w, &w->m.c_shape[i]);
    w->m.c_gen[i]++;
}

int32_t wb_collider_mesh(const wb_world *w, wb_collider_id c, const wb_real **v, const int32_t **tri, int32_t *nt)
{
    const wb_colmesh *cm = w->m.c_shape[CSLOT(w, c)].mesh;
    if (!cm) { *v = NULL; *tri = NULL; *nt = 0; return 0; }
    *v = cm->v;
    *tri = cm->tri;
    *nt = cm->nt;
    return cm->nv;
}

int wb_collider_solids(const wb_world *w, wb_collider_id c, wb_solid out[WB_MAX_SOLIDS])
{
    const int32_t i = CSLOT(w, c);
    return wb__shape_solids(&w->m.c_shape[i], w->s.c_pose[i].p, w->s.c_pose[i].q, out);
}

bool wb_collider_mesh_closed(const wb_world *w, wb_collider_id c)
{
    const wb_colmesh *cm = w->m.c_shape[CSLOT(w, c)].mesh;
    return cm && cm->closed;
}
wb_shape wb_collider_shape(const wb_world *w, wb_collider_id c) { return w->m.c_shape[CSLOT(w, c)].shape; }

void wb_collider_set_position(wb_world *w, wb_collider_id c, const wb_real p[3]) { v3_copy(w->s.c_pose[CSLOT(w, c)].p, p); }
void wb_collider_set_velocity(wb_world *w, wb_collider_id c, const wb_real v[3]) { v3_copy(w->s.c_pose[CSLOT(w, c)].v, v); }
void wb_collider_set_angular_velocity(wb_world *w, wb_collider_id c, const wb_real om[3]) { v3_copy(w->s.c_pose[CSLOT(w, c)].om, om); }
void wb_collider_position(const wb_world *w, wb_collider_id c, wb_real out[3]) { v3_copy(out, w->s.c_pose[CSLOT(w, c)].p); }
void wb_collider_rotation(const wb_world *w, wb_collider_id c, wb_real out[4]) { memcpy(out, w->s.c_pose[CSLOT(w, c)].q, 4 * sizeof(wb_real)); }
void wb_collider_velocity(const wb_world *w, wb_collider_id c, wb_real out[3]) { v3_copy(out, w->s.c_pose[CSLOT(w, c)].v); }

void wb_collider_set_rotation(wb_world *w, wb_collider_id c, const wb_real q[4])
{
    wb_real *t = w->s.c_pose[CSLOT(w, c)].q;
    memcpy(t, q, 4 * sizeof(wb_real));
    q_normalize(t);
}

void wb_collider_get_def(const wb_world *w, wb_collider_id c, wb_collider_def *out)
{
    int32_t i = CSLOT(w, c);
    const wb_cshape *s = &w->m.c_shape[i];
    const wb_collider_pose *p = &w->s.c_pose[i];
    *out = wb_collider_default_def(s->shape);
    out->friction = s->friction;
    out->restitution = s->restitution;
    out->radius = s->radius;
    v3_copy(out->half, s->half);
    v3_copy(out->center, p->p);
    memcpy(out->rotation, p->q, sizeof out->rotation);
    q_rotate(p->q, s->n, out->normal);
    out->offset = v3_dot(out->normal, p->p);
    q_rotate(p->q, s->a, out->a);
    v3_add(out->a, out->a, p->p);
    q_rotate(p->q, s->b, out->b);
    v3_add(out->b, out->b, p->p);
}

int32_t wb_collider_count(const wb_world *w)
{
    int32_t n = 0;
    for (int32_t i = 0; i < w->m.nc; i++) n += (int32_t)(w->m.c_gen[i] & 1u);
    return n;
}

wb_collider_id wb_collider_at(const wb_world *w, int32_t i)
{
    for (int32_t s = 0; s < w->m.nc; s++) {
        if (!(w->m.c_gen[s] & 1u)) continue;
        if (i-- == 0) { wb_collider_id id = { (uint32_t)s + 1, w->m.c_gen[s] }; return id; }
    }
    wb_collider_id none = { 0, 0 };
    return none;
}

void wb__collider_pose_at(const wb_collider_pose *cp, wb_real t, wb_real p[3], wb_real q[4])
{
    if (t >= 1) { /* exactly the pose the script set, not p0 + (p - p0) rounded */
        v3_copy(p, cp->p);
        memcpy(q, cp->q, 4 * sizeof(wb_real));
        return;
    }
    for (int i = 0; i < 3; i++) p[i] = cp->p0[i] + (cp->p[i] - cp->p0[i]) * t;
    q_slerp(cp->q0, cp->q, t, q);
}

wb_real wb_collider_distance(const wb_world *w, wb_collider_id c, const wb_real x[3])
{
    int32_t i = CSLOT(w, c);
    wb_real n[3];
    return wb__shape_distance(&w->m.c_shape[i], w->s.c_pose[i].p, w->s.c_pose[i].q, x, n);
}

/* ---- projection and velocities ---------------------------------------------------------- */
#if defined(__GNUC__)
#define WB_INLINE static inline __attribute__((always_inline))
#else
#define WB_INLINE static inline
#endif

/* a collider's poses over one substep, worked out once for all particles */
typedef struct sub_pose {
    const wb_cshape *s;
    int32_t slot;
    int moving;
    wb_real p0[3], q0[4], p1[3], q1[4];
    wb_real n[3], off;     /* plane: world normal and offset at the substep's end */
    wb_real n0[3], off0;   /* and at its start (the same bits when it does not move) */
} sub_pose;

typedef struct contact {
    const sub_pose *c;
    wb_real n[3];          /* unit normal, out of the collider */
    wb_real depth;         /* correction along n for dynamic friction (0: static friction spent it) */
    wb_real vc[3];         /* collider surface velocity at the contact */
    wb_real vn_pre;        /* normal velocity relative to the surface before the solve */
} contact;

/* A mesh's contact: depth and the world normal out of it. A closed mesh pushes out of
 * its nearest surface (a particle inside goes out, not deeper). An open mesh has two
 * sides: the particle stays on the side it was on at the substep's start (x_prev in the
 * collider's start pose), so one that crossed the sheet within the substep goes back
 * rather than out the far side. */
static wb_real mesh_depth(const sub_pose *sp, const wb_real x[3], const wb_real xprev[3], wb_real r, wb_real n[3],
                          int32_t *tri)
{
    const wb_colmesh *cm = sp->s->mesh;
    wb_real u[3], l[3], nl[3], pn[3], c[3];
    v3_sub(u, x, sp->p1);
    q_rotate_inv(sp->q1, u, l);
    /* far from the tree's box: no contact, and no query */
    const wb_bvh_node *root = &cm->nodes[0];
    wb_real lp[3] = { 0, 0, 0 }, mv = 0; /* set and read only for an open mesh (gcc -O3 cannot tell) */
    if (!cm->closed) {
        v3_sub(u, xprev, sp->p0);
        q_rotate_inv(sp->q0, u, lp);
        v3_sub(u, l, lp);
        mv = v3_len(u);
    }
    const wb_real reach = r + mv;
    for (int k = 0; k < 3; k++)
        if (l[k] < root->lo[k] - reach || l[k] > root->hi[k] + reach) return 0;
    wb_real depth;
    if (cm->closed) {
        depth = r - wb__colmesh_distance_tri(cm, l, nl, c, pn, tri);
    } else {
        int32_t t;
        int region;
        const wb_real d2 = wb__colmesh_closest_within(cm, l, reach * reach, c, &t, &region);
        if (t < 0) return 0;
        *tri = t;
        wb__colmesh_pseudo_normal(cm, t, region, pn);
        const wb_real lpn = v3_len(pn), d = sqrt(d2);
        wb_real a[3], b[3];
        v3_sub(a, l, c);
        v3_sub(b, lp, c);
        const wb_real s_now = v3_dot(a, pn), s_prev = v3_dot(b, pn);
        if (lpn > 0 && s_prev != 0 && (s_now * s_prev < 0 || !(d > 1e-12 * (1 + v3_len(c))))) {
            /* crossed (or on the sheet): back to the side it came from */
            v3_scale(nl, pn, (s_prev > 0 ? 1 : -1) / lpn);
            depth = r - v3_dot(a, nl);
        } else if (d > 0) {
            v3_scale(nl, a, 1 / d);
            depth = r - d;
        } else {
            if (lpn > 0) v3_scale(nl, pn, 1 / lpn);
            else v3_set(nl, 0, 1, 0);
            depth = r;
        }
    }
    q_rotate(sp->q1, nl, n);
    return depth;
}

/* The overlap a particle of radius r at x_prev had with the collider at its start pose:
 * what it began the substep with (made_contact). A mesh: against triangle tri, the one
 * closest to x (a second search of the tree cost as much as the first: +20% for a cloth
 * draped on a mesh); the same unless the closest feature changed within the substep,
 * and then a little off, which moves no kept overlap faster than max_depenetration (that
 * bound is `left`'s). Closed: signed; open: the unsigned distance, the side it was on */
static wb_real start_depth(const sub_pose *sp, const wb_real xprev[3], wb_real r, int32_t tri)
{
    if (sp->s->shape == WB_SHAPE_PLANE) return r + sp->off0 - v3_dot(sp->n0, xprev);
    if (sp->s->shape != WB_SHAPE_MESH) {
        wb_real n[3];
        return r - wb__shape_distance(sp->s, sp->p0, sp->q0, xprev, n);
    }
    const wb_colmesh *cm = sp->s->mesh;
    if (tri < 0) return 0;
    wb_real u[3], l[3], q[3], pn[3];
    v3_sub(u, xprev, sp->p0);
    q_rotate_inv(sp->q0, u, l);
    const int32_t *v = &cm->tri[3 * tri];
    int region;
    const wb_real d = sqrt(wb__closest_on_triangle(l, &cm->v[3 * v[0]], &cm->v[3 * v[1]], &cm->v[3 * v[2]], q, &region));
    if (!cm->closed) return r - d;
    wb__colmesh_pseudo_normal(cm, tri, region, pn);
    v3_sub(u, l, q);
    return v3_dot(u, pn) < 0 ? r + d : r - d;
}

/* more simultaneous contacts than this on one particle keep their position
 * correction but lose their velocity pass (friction, restitution) */
#define MAX_CONTACTS 16

/* Static friction (Coulomb, at position level) on a contact of normal n whose normal
 * correction, the substep's normal impulse per unit mass times h, is depth: slip is the
 * particle's tangential motion over the substep relative to the surface. Within the
 * cone (|slip| < mu depth) it is undone. Outside, two regimes, as for particle pairs
 * (contact.c, wb__contacts_friction):
 * - sliding: the tangential speed relative to the surface before the substep, u (the
 *   predicted v without the substep's gravity, v - g h), is more than one substep of
 *   dynamic friction takes away (|u_t| h > mu depth). Its friction is the velocity pass's;
 * - at rest (otherwise): the slip is undone as far as the budget mu depth allows, static
 *   friction at its bound while the particle breaks away, and the velocity pass adds no
 *   dynamic friction (it would count it twice).
 * All or nothing (undo all, or nothing and leave it to the velocity pass) made a block
 * on a slope creep below tan theta = mu: within a substep its bottom particles carry
 * unequal shares of its weight (Gauss-Seidel, one iteration), the ones over the cone
 * slid a whole substep's slip and the links pulled the others along (a 4 x 4 x 4
 * lattice at tan theta = 0.8 mu: 1.6 cm/s). Returns the normal correction left to the
 * velocity pass's dynamic friction: depth, or 0 when the budget was spent here. */
WB_INLINE wb_real static_friction(wb_real *restrict x, const wb_real slip[3], const wb_real v[3], const wb_real grav[3],
                                  const wb_real *vc, const wb_real n[3], wb_real mu, wb_real depth, wb_real h)
{
    const wb_real sl = v3_len(slip), cap = mu * depth;
    if (sl < cap) {
        v3_madd(x, slip, -1);
        return depth;
    }
    if (!(cap > 0)) return depth;
    /* wb_predict's g h taken back out of the predicted v */
    wb_real u[3] = { v[0] - grav[0] * h, v[1] - grav[1] * h, v[2] - grav[2] * h };
    if (vc) v3_sub(u, u, vc);
    v3_madd(u, n, -v3_dot(u, n));
    if (v3_len(u) * h > cap) return depth;
    v3_madd(x, slip, -cap / sl);
    return 0;
}

/* push particle i out along n by depth, of which shift (overlap it began the substep
 * with: made_contact) moves x_prev too, and apply static friction. The contact's normal
 * impulse (friction's bound, here and in the velocity pass) is what the substep drove
 * in, depth - shift: the repair of an overlap it already had is no force */
static void resolve(wb_real *restrict xi, wb_real *restrict pi, const wb_real *restrict vi, const sub_pose *c,
                    const wb_real n[3], wb_real depth, wb_real shift, wb_real h, const wb_real grav[3], contact *ct)
{
    v3_madd(xi, n, depth);
    if (shift > 0) v3_madd(pi, n, shift);
    depth -= shift;
    /* the surface point's motion over the substep, carried rigidly by the collider */
    wb_real vc[3] = { 0, 0, 0 };
    if (c->moving) {
        wb_real r[3], l[3], x0[3];
        v3_sub(r, xi, c->p1);
        q_rotate_inv(c->q1, r, l);
        q_rotate(c->q0, l, x0);
        v3_add(x0, x0, c->p0);
        v3_sub(vc, xi, x0);
        v3_scale(vc, vc, 1 / h);
    }
    wb_real fdepth = depth;
    if (c->s->friction > 0) {
        wb_real slip[3];
        v3_sub(slip, xi, pi);
        v3_madd(slip, vc, -h);
        v3_madd(slip, n, -v3_dot(slip, n));
        fdepth = static_friction(xi, slip, vi, grav, vc, n, c->s->friction, depth, h);
    }
    if (!ct) return;
    ct->c = c;
    v3_copy(ct->n, n);
    ct->depth = fdepth;
    v3_copy(ct->vc, vc);
    wb_real rel[3];
    v3_sub(rel, vi, vc);
    ct->vn_pre = v3_dot(rel, n);
}

/* dynamic friction and restitution on the velocity v the positions imply, for a contact
 * of normal n and depth whose normal velocity was vn_pre before, against a surface moving
 * at vc (NULL: a static one, the same bits as a zero vc); one copy for every path */
static inline __attribute__((always_inline)) void
velocity_response(wb_real v[3], const wb_real n[3], const wb_real *vc, wb_real depth, wb_real vn_pre,
                  wb_real friction, wb_real restitution, wb_real h, wb_real g)
{
    wb_real rel[3], vt[3];
    if (vc) v3_sub(rel, v, vc);
    else v3_copy(rel, v);
    const wb_real vn = v3_dot(rel, n);
    v3_copy(vt, rel);
    v3_madd(vt, n, -vn);
    const wb_real vt_len = v3_len(vt);
    if (friction > 0 && vt_len > 0) {
        /* the normal impulse per unit mass is depth / h: |dv_t| <= mu |dv_n| */
        const wb_real dv = friction * depth / h;
        v3_madd(v, vt, -(dv < vt_len ? dv : vt_len) / vt_len);
    }
    if (vn_pre < 0) {
        /* no bounce below 2|g|h: resting contact must not jitter */
        const wb_real e = -vn_pre > 2 * g * h ? restitution : 0;
        v3_madd(v, n, -e * vn_pre - vn);
    }
}

static void contact_velocity(wb_real v[3], const contact *ct, wb_real h, wb_real g)
{
    const wb_cshape *s = ct->c->s;
    velocity_response(v, ct->n, ct->vc, ct->depth, ct->vn_pre, s->friction, s->restitution, h, g);
}

/* a static plane of the fast path: world normal, offset, its material */
typedef struct static_plane {
    wb_real n[3], off, friction, restitution;
} static_plane;

typedef struct collide_job {
    wb_world *w;
    const sub_pose *cs;
    int32_t nlive;
    wb_real h;
    wb_real *left;              /* (np) the overlap each particle kept (made_contact) */
    int fresh;                  /* the frame's first substep: `left` from the state */
    const static_plane *planes; /* nlive of them when every collider is a static plane
                                   and no particle skips one (attachments), else NULL */
    const wb_predict *next;     /* the next substep's prediction, fused; NULL: none */
    _Atomic int64_t ncontacts;
    _Atomic int32_t bad;        /* scan: the first non-finite particle, INT32_MAX none */
} collide_job;

/* Made overlap (a position error, not a collision). A contact's overlap ov is corrected
 * as contact.c corrects a pair's (wb__contact_depth): what of d0, the overlap the
 * particle began the substep with (at x_prev, against the collider's start pose), it kept
 * from substep to substep (`left`: bodies made resting on the ground, half inside it)
 * goes at no more than max_depenetration x h per substep; what the substep drove in goes
 * in full, and so does the rest of d0 (what other contacts' repairs carried into the
 * collider by moving x_prev: a heap's upper layers pressing a made overlap down, which
 * must not sink). All of d0 that goes moves x_prev with x (*shift, Macklin et al. 2014
 * §4.2): a position change, no speed. This pass is the substep's last to move particles,
 * so where it left a particle is where the next substep starts: one `left` per particle,
 * the most any of its contacts kept (a particle in a corner keeps each overlap below it).
 * At a frame's first substep `left` comes from the state alone, contact.c's rule: an
 * overlap one substep would not take counts as kept; a resting contact (pushed out in
 * full) starts each substep at none. *lmax: the particle's new `left` so far; returns the
 * correction */
static inline wb_real made_contact(wb_real ov, wb_real d0, wb_real left, int fresh, wb_real step, wb_real *lmax,
                                   wb_real *shift)
{
    wb_real lk = fresh ? (d0 > step ? d0 : 0) : left, slow, fast;
    const wb_real c = wb__contact_depth(ov, d0, &lk, step, &slow, &fast);
    *lmax = lk > *lmax ? lk : *lmax;
    *shift = slow + fast;
    return c;
}

/* x - x is 0 for a finite x and NaN for inf and NaN: one test for six values */
static inline int finite6(const wb_real x[3], const wb_real v[3])
{
    const wb_real z = (x[0] - x[0]) + (x[1] - x[1]) + (x[2] - x[2]) + (v[0] - v[0]) + (v[1] - v[1]) + (v[2] - v[2]);
    return z == z;
}

/* The pass over particles [lo, hi), instantiated for constant flags (the branches go at
 * compile time): planes, the fast path for static planes (2: exactly one) (resolve and contact_velocity
 * with the collider velocity vc = 0 written out: v - 0 is v and x + -0 is x, so the bits
 * are those of the general path); fuse, the next substep's prediction (wb__predict_one)
 * once the particle's velocity is final; scan, whether x and v ended finite. */
WB_INLINE void collide_range(collide_job *j, int32_t lo, int32_t hi, const int planes, const int fuse,
                             const int scan)
{
    wb_world *w = j->w;
    const wb_model *m = &w->m;
    const sub_pose *cs = j->cs;
    const static_plane *pl = j->planes;
    /* planes == 2: exactly one plane (a ground), held in locals */
    const int32_t nlive = planes == 2 ? 1 : j->nlive;
    const static_plane one = planes == 2 ? pl[0] : (static_plane){ { 0, 0, 0 }, 0, 0, 0 };
    const wb_real h = j->h, inv_h = 1 / h, g = v3_len(m->def.gravity), step = m->def.max_depenetration * h;
    wb_real *restrict cl = j->left;
    const int fresh = j->fresh;
    /* restrict: the arrays are distinct, so the compiler keeps values in registers
     * across the stores (the same operations, the same bits) */
    const wb_real *restrict wv = m->w, *restrict rad = m->radius;
    wb_real *restrict x = w->s.x, *restrict v = w->s.v;
    wb_real *restrict xp = w->s.x_prev;
    const wb_attaches *att = wb__attach_skips(w); /* attached: no contact */
    const wb_predict pr = fuse ? *j->next : (wb_predict){ 0, { 0, 0, 0 }, 0 };
    int64_t ncontacts = 0;
    int32_t bad = INT32_MAX;
    for (int32_t i = lo; i < hi; i++) {
        wb_real *restrict xi = &x[3 * i], *restrict vi = &v[3 * i], *restrict pi = &xp[3 * i];
        if (wv[i] == 0) { /* pinned and immovable: at rest */
            v3_set(vi, 0, 0, 0);
            if (fresh) cl[i] = 0;
        } else if (planes) {
            /* x, x_prev and v in locals, stored once at the end: a 16-byte load of two
             * values just stored one by one cannot be forwarded from the stores (a stall
             * per particle that cost more than the fused pass saved) */
            wb_real xx[3] = { xi[0], xi[1], xi[2] }, vv[3] = { vi[0], vi[1], vi[2] };
            wb_real pp[3] = { pi[0], pi[1], pi[2] };
            int moved = 0; /* x_prev: an old overlap's repair moved it (resolve) */
            const wb_real left = cl[i];
            wb_real lmax = 0;
            /* contacts: the plane, its depth, the normal velocity before (vc = 0) */
            int32_t cp[MAX_CONTACTS];
            wb_real cd[MAX_CONTACTS], cvn[MAX_CONTACTS];
            int nct = 0;
            for (int32_t c = 0; c < nlive; c++) {
                const static_plane *sp = planes == 2 ? &one : &pl[c];
                wb_real depth = rad[i] + sp->off - v3_dot(sp->n, xx);
                if (!(depth > 0)) continue;
                wb_real shift;
                depth = made_contact(depth, rad[i] + sp->off - v3_dot(sp->n, pp), left, fresh, step, &lmax, &shift);
                v3_madd(xx, sp->n, depth);
                if (shift > 0) v3_madd(pp, sp->n, shift), moved = 1;
                depth -= shift;
                wb_real fdepth = depth;
                if (sp->friction > 0) {
                    wb_real slip[3];
                    v3_sub(slip, xx, pp);
                    v3_madd(slip, sp->n, -v3_dot(slip, sp->n));
                    fdepth = static_friction(xx, slip, vv, m->def.gravity, NULL, sp->n, sp->friction, depth, h);
                }
                if (nct < MAX_CONTACTS) {
                    cp[nct] = c;
                    cd[nct] = fdepth;
                    cvn[nct] = v3_dot(vv, sp->n);
                }
                nct++;
            }
            for (int c = 0; c < 3; c++) vv[c] = (xx[c] - pp[c]) * inv_h;
            for (int c = 0; c < nct && c < MAX_CONTACTS; c++) {
                const static_plane *sp = planes == 2 ? &one : &pl[cp[c]];
                velocity_response(vv, sp->n, NULL, cd[c], cvn[c], sp->friction, sp->restitution, h, g);
            }
            ncontacts += nct;
            if (nct || fresh) cl[i] = lmax;
            if (fuse) wb__predict_one(&pr, wv[i], xx, pi, vv);
            else if (moved) v3_copy(pi, pp);
            v3_copy(xi, xx);
            v3_copy(vi, vv);
            if (scan && bad == INT32_MAX && !finite6(xx, vv)) bad = i;
            continue;
        } else {
            contact ct[MAX_CONTACTS];
            int nct = 0;
            const wb_real left = cl[i];
            wb_real lmax = 0;
            for (int32_t c = 0; c < nlive; c++) {
                const sub_pose *sp = &cs[c];
                if (att && wb__attach_skip(att, i, sp->slot)) continue;
                wb_real n[3], depth;
                int32_t tri = -1;
                if (sp->s->shape == WB_SHAPE_PLANE) {
                    depth = rad[i] + sp->off - v3_dot(sp->n, xi);
                    v3_copy(n, sp->n);
                } else if (sp->s->shape == WB_SHAPE_MESH) {
                    depth = mesh_depth(sp, xi, pi, rad[i], n, &tri);
                } else {
                    depth = rad[i] - wb__shape_distance(sp->s, sp->p1, sp->q1, xi, n);
                }
                if (!(depth > 0)) continue;
                wb_real shift;
                depth = made_contact(depth, start_depth(sp, pi, rad[i], tri), left, fresh, step, &lmax, &shift);
                resolve(xi, pi, vi, sp, n, depth, shift, h, m->def.gravity, nct < MAX_CONTACTS ? &ct[nct] : NULL);
                nct++;
            }
            for (int c = 0; c < 3; c++) vi[c] = (xi[c] - pi[c]) * inv_h;
            for (int c = 0; c < nct && c < MAX_CONTACTS; c++) contact_velocity(vi, &ct[c], h, g);
            ncontacts += nct;
            if (nct || fresh) cl[i] = lmax;
        }
        if (fuse) wb__predict_one(&pr, wv[i], xi, pi, vi);
        if (scan && bad == INT32_MAX && !finite6(xi, vi)) bad = i;
    }
    j->ncontacts += ncontacts; /* a sum of integers: the same in any order */
    if (scan && bad != INT32_MAX) {
        /* the least index over the parts: the same in any order */
        int32_t cur = atomic_load(&j->bad);
        while (bad < cur && !atomic_compare_exchange_weak(&j->bad, &cur, bad)) {}
    }
}

#if defined(__x86_64__) && defined(__GNUC__) && !defined(WB_FLOAT)
#include <immintrin.h>
#define WB_PLANE_AVX2 1
#define AVX2_INLINE static inline __attribute__((always_inline, target("avx2")))

/* four particles' triples (x0 y0 z0 x1 | y1 z1 x2 y2 | z2 x3 y3 z3) to x, y, z and back */
AVX2_INLINE void soa4(const wb_real *p, __m256d *x, __m256d *y, __m256d *z)
{
    const __m256d a = _mm256_loadu_pd(p), b = _mm256_loadu_pd(p + 4), c = _mm256_loadu_pd(p + 8);
    const __m256d m = _mm256_permute2f128_pd(a, c, 0x21); /* a2 a3 c0 c1 */
    const __m256d u = _mm256_blend_pd(a, b, 0xC);        /* a0 a1 b2 b3 */
    const __m256d v = _mm256_blend_pd(b, c, 0xC);        /* b0 b1 c2 c3 */
    *x = _mm256_blend_pd(_mm256_blend_pd(a, m, 0xA), b, 0x4);
    *y = _mm256_shuffle_pd(u, v, 0x5);
    *z = _mm256_shuffle_pd(m, v, 0xA);
}

AVX2_INLINE void aos4(wb_real *p, __m256d x, __m256d y, __m256d z)
{
    const __m256d u = _mm256_unpacklo_pd(x, y);   /* x0 y0 x2 y2 */
    const __m256d v = _mm256_unpackhi_pd(y, z);   /* y1 z1 y3 z3 */
    const __m256d m = _mm256_shuffle_pd(z, x, 0xA); /* z0 x1 z2 x3 */
    _mm256_storeu_pd(p, _mm256_permute2f128_pd(u, m, 0x20));
    _mm256_storeu_pd(p + 4, _mm256_blend_pd(v, u, 0xC));
    _mm256_storeu_pd(p + 8, _mm256_permute2f128_pd(m, v, 0x31));
}

/* the made-overlap correction of a group some of whose contacts began inside or keep an
 * overlap (out of line: the common loop keeps its registers) */
static __attribute__((noinline, target("avx2"))) void
made_group(__m256d *pX, __m256d *pY, __m256d *pZ, __m256d *pPX, __m256d *pPY, __m256d *pPZ, __m256d *plnew,
           int *pmoved, __m256d depth, __m256d d0, __m256d lk, __m256d pos, __m256d in, __m256d n0, __m256d n1,
           __m256d n2, __m256d stepv)
{
    const __m256d zero = _mm256_setzero_pd();
    __m256d X = *pX, Y = *pY, Z = *pZ, PX = *pPX, PY = *pPY, PZ = *pPZ, lnew;
    int moved = 0;
    const __m256d d0c = _mm256_and_pd(pos, _mm256_min_pd(d0, depth));
    const __m256d kept = _mm256_min_pd(d0c, lk), t = _mm256_sub_pd(lk, stepv);
    const __m256d kp = _mm256_and_pd(_mm256_cmp_pd(t, zero, _CMP_GT_OQ), _mm256_min_pd(t, d0c));
    const __m256d shift = _mm256_add_pd(_mm256_sub_pd(kept, kp), _mm256_sub_pd(d0c, kept));
    const __m256d corr = _mm256_sub_pd(depth, kp);
    lnew = kp;
    X = _mm256_blendv_pd(X, _mm256_add_pd(X, _mm256_mul_pd(n0, corr)), in);
    Y = _mm256_blendv_pd(Y, _mm256_add_pd(Y, _mm256_mul_pd(n1, corr)), in);
    Z = _mm256_blendv_pd(Z, _mm256_add_pd(Z, _mm256_mul_pd(n2, corr)), in);
    const __m256d mv = _mm256_and_pd(in, _mm256_cmp_pd(shift, zero, _CMP_GT_OQ));
    if (_mm256_movemask_pd(mv)) {
        PX = _mm256_blendv_pd(PX, _mm256_add_pd(PX, _mm256_mul_pd(n0, shift)), mv);
        PY = _mm256_blendv_pd(PY, _mm256_add_pd(PY, _mm256_mul_pd(n1, shift)), mv);
        PZ = _mm256_blendv_pd(PZ, _mm256_add_pd(PZ, _mm256_mul_pd(n2, shift)), mv);
        moved = 1;
    }
    *pX = X; *pY = Y; *pZ = Z; *pPX = PX; *pPY = PY; *pPZ = PZ; *plnew = lnew; *pmoved = moved;
}

/* The one-plane pass (collide_range, planes == 2) four particles at a time: the same
 * operations in the same order per value (lanes out of contact blended back, not
 * computed differently), so the same bits. Groups with a pinned particle, or in contact
 * with a plane that has friction (the slip's length per particle), run the scalar code. */
AVX2_INLINE void plane_range_avx2(collide_job *j, int32_t lo, int32_t hi, const int fuse, const int scan)
{
    wb_world *w = j->w;
    const wb_model *m = &w->m;
    const static_plane one = j->planes[0];
    const wb_real h = j->h, inv_h = 1 / h, g = v3_len(m->def.gravity);
    const wb_real *restrict wv = m->w, *restrict rad = m->radius;
    wb_real *restrict x = w->s.x, *restrict v = w->s.v;
    wb_real *restrict xp = w->s.x_prev;
    const wb_predict pr = fuse ? *j->next : (wb_predict){ 0, { 0, 0, 0 }, 0 };
    const __m256d n0 = _mm256_set1_pd(one.n[0]), n1 = _mm256_set1_pd(one.n[1]), n2 = _mm256_set1_pd(one.n[2]);
    const __m256d off = _mm256_set1_pd(one.off), rest = _mm256_set1_pd(one.restitution);
    const __m256d vih = _mm256_set1_pd(inv_h), g2h = _mm256_set1_pd(2 * g * h);
    const __m256d stepv = _mm256_set1_pd(m->def.max_depenetration * h);
    wb_real *restrict cl = j->left;
    const int fresh = j->fresh;
    const __m256d zero = _mm256_setzero_pd(), sign = _mm256_set1_pd(-0.0);
    const __m256d keep = _mm256_set1_pd(pr.keep), ph = _mm256_set1_pd(pr.h);
    const __m256d gx = _mm256_set1_pd(pr.g[0]), gy = _mm256_set1_pd(pr.g[1]), gz = _mm256_set1_pd(pr.g[2]);
    const int fric = one.friction > 0;
    int64_t ncontacts = 0;
    int32_t bad = INT32_MAX;
    int32_t run = lo; /* [run, i): groups left to the scalar code, run at the next vector group */
    int32_t i = lo;
    for (; i + 4 <= hi; i += 4) {
        if (_mm256_movemask_pd(_mm256_cmp_pd(_mm256_loadu_pd(&wv[i]), zero, _CMP_EQ_OQ))) continue;
        __m256d X, Y, Z;
        soa4(&x[3 * i], &X, &Y, &Z);
        const __m256d ro = _mm256_add_pd(_mm256_loadu_pd(&rad[i]), off);
        const __m256d depth = _mm256_sub_pd(ro, _mm256_add_pd(_mm256_add_pd(_mm256_mul_pd(n0, X), _mm256_mul_pd(n1, Y)),
                                                              _mm256_mul_pd(n2, Z)));
        const __m256d in = _mm256_cmp_pd(depth, zero, _CMP_GT_OQ);
        const int inm = _mm256_movemask_pd(in);
        if (inm && fric) continue;
        if (run < i) collide_range(j, run, i, 2, fuse, scan);
        run = i + 4;
        __m256d PX, PY, PZ, VX, VY, VZ;
        soa4(&xp[3 * i], &PX, &PY, &PZ);
        soa4(&v[3 * i], &VX, &VY, &VZ);
        __m256d cvn = zero, lnew = zero;
        int moved = 0; /* some lane's x_prev moved (an old overlap's repair) */
        int nokeep = 0;
        if (inm) {
            /* made_contact: the overlap at x_prev, what of it was kept, what stays, the
             * correction; the new left and x_prev's shift */
            const __m256d d0 =
                _mm256_sub_pd(ro, _mm256_add_pd(_mm256_add_pd(_mm256_mul_pd(n0, PX), _mm256_mul_pd(n1, PY)),
                                                _mm256_mul_pd(n2, PZ)));
            const __m256d lk = fresh ? _mm256_and_pd(_mm256_cmp_pd(d0, stepv, _CMP_GT_OQ), d0) : _mm256_loadu_pd(&cl[i]);
            const __m256d pos = _mm256_cmp_pd(d0, zero, _CMP_GT_OQ);
            if (!_mm256_movemask_pd(_mm256_and_pd(in, _mm256_or_pd(pos, _mm256_cmp_pd(lk, zero, _CMP_NEQ_UQ))))) {
                /* no contact began the substep inside nor keeps an overlap: all of it is
                 * new, pushed out in full (shift 0, left 0) */
                X = _mm256_blendv_pd(X, _mm256_add_pd(X, _mm256_mul_pd(n0, depth)), in);
                Y = _mm256_blendv_pd(Y, _mm256_add_pd(Y, _mm256_mul_pd(n1, depth)), in);
                Z = _mm256_blendv_pd(Z, _mm256_add_pd(Z, _mm256_mul_pd(n2, depth)), in);
                nokeep = 1;
            } else {
                made_group(&X, &Y, &Z, &PX, &PY, &PZ, &lnew, &moved, depth, d0, lk, pos, in, n0, n1, n2, stepv);
            }
            cvn = _mm256_add_pd(_mm256_add_pd(_mm256_mul_pd(VX, n0), _mm256_mul_pd(VY, n1)), _mm256_mul_pd(VZ, n2));
        }
        VX = _mm256_mul_pd(_mm256_sub_pd(X, PX), vih);
        VY = _mm256_mul_pd(_mm256_sub_pd(Y, PY), vih);
        VZ = _mm256_mul_pd(_mm256_sub_pd(Z, PZ), vih);
        if (inm) {
            const __m256d upd = _mm256_and_pd(in, _mm256_cmp_pd(cvn, zero, _CMP_LT_OQ));
            if (_mm256_movemask_pd(upd)) {
                const __m256d vn =
                    _mm256_add_pd(_mm256_add_pd(_mm256_mul_pd(VX, n0), _mm256_mul_pd(VY, n1)), _mm256_mul_pd(VZ, n2));
                /* e = -cvn > 2 g h ? restitution : 0; vv += n (-e cvn - vn) */
                const __m256d e =
                    _mm256_and_pd(rest, _mm256_cmp_pd(_mm256_xor_pd(cvn, sign), g2h, _CMP_GT_OQ));
                const __m256d k = _mm256_sub_pd(_mm256_mul_pd(_mm256_xor_pd(e, sign), cvn), vn);
                VX = _mm256_blendv_pd(VX, _mm256_add_pd(VX, _mm256_mul_pd(n0, k)), upd);
                VY = _mm256_blendv_pd(VY, _mm256_add_pd(VY, _mm256_mul_pd(n1, k)), upd);
                VZ = _mm256_blendv_pd(VZ, _mm256_add_pd(VZ, _mm256_mul_pd(n2, k)), upd);
            }
            ncontacts += __builtin_popcount((unsigned)inm);
        }
        /* left: the contacts' new one, the others' as it was (at a frame's start, none) */
        if ((inm && !nokeep) || fresh)
            _mm256_storeu_pd(&cl[i], _mm256_blendv_pd(fresh ? zero : _mm256_loadu_pd(&cl[i]), lnew, in));
        if (!fuse && moved) aos4(&xp[3 * i], PX, PY, PZ);
        if (fuse) {
            aos4(&xp[3 * i], X, Y, Z);
            VX = _mm256_add_pd(_mm256_mul_pd(VX, keep), gx);
            VY = _mm256_add_pd(_mm256_mul_pd(VY, keep), gy);
            VZ = _mm256_add_pd(_mm256_mul_pd(VZ, keep), gz);
            X = _mm256_add_pd(X, _mm256_mul_pd(ph, VX));
            Y = _mm256_add_pd(Y, _mm256_mul_pd(ph, VY));
            Z = _mm256_add_pd(Z, _mm256_mul_pd(ph, VZ));
        }
        aos4(&x[3 * i], X, Y, Z);
        aos4(&v[3 * i], VX, VY, VZ);
        if (scan && bad == INT32_MAX) {
            /* x - x: 0 when finite, NaN otherwise (finite6) */
            const __m256d s = _mm256_add_pd(
                _mm256_add_pd(_mm256_add_pd(_mm256_sub_pd(X, X), _mm256_sub_pd(Y, Y)), _mm256_sub_pd(Z, Z)),
                _mm256_add_pd(_mm256_add_pd(_mm256_sub_pd(VX, VX), _mm256_sub_pd(VY, VY)), _mm256_sub_pd(VZ, VZ)));
            const int nf = _mm256_movemask_pd(_mm256_cmp_pd(s, s, _CMP_UNORD_Q));
            if (nf) bad = i + __builtin_ctz((unsigned)nf);
        }
    }
    if (run < hi) collide_range(j, run, hi, 2, fuse, scan);
    j->ncontacts += ncontacts;
    if (scan && bad != INT32_MAX) {
        int32_t cur = atomic_load(&j->bad);
        while (bad < cur && !atomic_compare_exchange_weak(&j->bad, &cur, bad)) {}
    }
}

static __attribute__((target("avx2"))) void plane_avx2(void *ctx, int32_t lo, int32_t hi)
{
    plane_range_avx2(ctx, lo, hi, 0, 0);
}
static __attribute__((target("avx2"))) void plane_fuse_avx2(void *ctx, int32_t lo, int32_t hi)
{
    plane_range_avx2(ctx, lo, hi, 1, 0);
}
static __attribute__((target("avx2"))) void plane_scan_avx2(void *ctx, int32_t lo, int32_t hi)
{
    plane_range_avx2(ctx, lo, hi, 0, 1);
}
#endif

static void part_any(void *ctx, int32_t lo, int32_t hi) { collide_range(ctx, lo, hi, 0, 0, 0); }
static void part_any_fuse(void *ctx, int32_t lo, int32_t hi) { collide_range(ctx, lo, hi, 0, 1, 0); }
static void part_any_scan(void *ctx, int32_t lo, int32_t hi) { collide_range(ctx, lo, hi, 0, 0, 1); }
static void part_planes(void *ctx, int32_t lo, int32_t hi) { collide_range(ctx, lo, hi, 1, 0, 0); }
static void part_planes_fuse(void *ctx, int32_t lo, int32_t hi) { collide_range(ctx, lo, hi, 1, 1, 0); }
static void part_planes_scan(void *ctx, int32_t lo, int32_t hi) { collide_range(ctx, lo, hi, 1, 0, 1); }
static void part_plane(void *ctx, int32_t lo, int32_t hi) { collide_range(ctx, lo, hi, 2, 0, 0); }
static void part_plane_fuse(void *ctx, int32_t lo, int32_t hi) { collide_range(ctx, lo, hi, 2, 1, 0); }
static void part_plane_scan(void *ctx, int32_t lo, int32_t hi) { collide_range(ctx, lo, hi, 2, 0, 1); }

/* One pass per particle after the constraints: push it out of every collider at the
 * collider's substep-end pose, set v = (x - x_prev) / h, then friction and
 * restitution for the contacts it has. Particles are independent here, so the pass
 * runs in parallel with results identical for any thread count. The caller may fold
 * the next substep's prediction into it (next), or the frame's finiteness check (scan):
 * both per particle too. */
int wb__collide_and_update(wb_world *w, wb_real h, wb_real f0, wb_real f1, const wb_predict *next, int scan)
{
    wb_model *m = &w->m;
    wb_cache *k = &w->k;
    int32_t nlive = 0;
    /* the sub_poses, then as many static_planes (the fast path) */
    const size_t need = (size_t)(m->nc > 0 ? m->nc : 1) * (sizeof(sub_pose) + sizeof(static_plane));
    sub_pose *cs = wb__grow(k->c_sub, &k->cap_c_sub, (int32_t)need, 1);
    if (!cs) { wb__warn(w, "out of memory in collision"); return 0; }
    k->c_sub = cs;
    static_plane *pl = (static_plane *)(void *)&cs[m->nc > 0 ? m->nc : 1];
    int planes = !k->no_fuse && !wb__attach_skips(w); /* (no_fuse: the tests' plain path) */
    for (int32_t c = 0; c < m->nc; c++) {
        if (!(m->c_gen[c] & 1u)) continue;
        sub_pose *sp = &cs[nlive++];
        sp->s = &m->c_shape[c];
        sp->slot = c;
        wb__collider_pose_at(&w->s.c_pose[c], f0, sp->p0, sp->q0);
        wb__collider_pose_at(&w->s.c_pose[c], f1, sp->p1, sp->q1);
        sp->moving = memcmp(sp->p0, sp->p1, sizeof sp->p0) || memcmp(sp->q0, sp->q1, sizeof sp->q0);
        q_rotate(sp->q1, sp->s->n, sp->n);
        sp->off = v3_dot(sp->n, sp->p1);
        q_rotate(sp->q0, sp->s->n, sp->n0);
        sp->off0 = v3_dot(sp->n0, sp->p0);
        if (sp->s->shape != WB_SHAPE_PLANE || sp->moving) planes = 0;
        static_plane *p = &pl[nlive - 1];
        v3_copy(p->n, sp->n);
        p->off = sp->off;
        p->friction = sp->s->friction;
        p->restitution = sp->s->restitution;
    }
    /* the overlap each particle kept (made_contact), zeroed where new (read, not used, at
     * a frame's first substep, which writes every particle's) */
    const int32_t cap0 = k->cap_c_left;
    wb_real *left = wb__grow(k->c_left, &k->cap_c_left, m->np > 0 ? m->np : 1, sizeof *left);
    if (!left) { wb__warn(w, "out of memory in collision"); return 0; }
    k->c_left = left;
    if (k->cap_c_left > cap0) memset(left + cap0, 0, sizeof *left * (size_t)(k->cap_c_left - cap0));
    collide_job j = { w, cs, nlive, h, left, !(f0 > 0), planes ? pl : NULL, next, 0, INT32_MAX };
    static const wb_pool_for_fn fns[3][3] = { { part_any, part_any_fuse, part_any_scan },
                                              { part_planes, part_planes_fuse, part_planes_scan },
                                              { part_plane, part_plane_fuse, part_plane_scan } };
    if (planes && nlive == 1) planes = 2;
    wb_pool_for_fn fn = fns[planes][next ? 1 : scan ? 2 : 0];
#ifdef WB_PLANE_AVX2
    /* (no_simd: the tests' scalar one-plane pass) */
    if (planes == 2 && !k->no_simd && __builtin_cpu_supports("avx2"))
        fn = next ? plane_fuse_avx2 : scan ? plane_scan_avx2 : plane_avx2;
#endif
    wb__pool_for(m->np >= 4096 ? wb__world_pool(w) : NULL, m->np, 2048, fn, &j);
    k->last_contacts = (int32_t)j.ncontacts;
    if (next) k->fused++;
    if (scan && !next) k->nonfinite = j.bad == INT32_MAX ? -1 : j.bad;
    return 1;
}
