/* rigid.c: XPBD rigid bodies (Müller, Macklin, Chentanez, Jeschke, Kim 2020, "Detailed
 * rigid body simulation with extended position based dynamics").
 *
 * Per substep (the paper's Algorithm 2), beside the particles: predict the pose from the
 * velocities (gravity, the gyroscopic term), correct positions at contacts with the
 * generalized inverse masses (static friction at position level), derive the velocities
 * from the poses, then dynamic friction and restitution at velocity level. */
#include <assert.h>

#include "contact.h"
#include "rigid.h"

/* bytes per slot over the model, state and cache arrays, for the memory budget */
#define SLOT_BYTES (sizeof(wb_cshape) + sizeof(uint32_t) + (2 + 9 + 9 + 1 + 13 + 7 + 13) * sizeof(wb_real) + 1)

static int fin3(const wb_real *v) { return isfinite(v[0]) && isfinite(v[1]) && isfinite(v[2]); }

static wb_rigids *RB(const wb_world *w) { return w->rb; }

/* ---- 3 x 3 helpers (row-major) ----------------------------------------------------------- */
static void m3_mul(const wb_real M[9], const wb_real v[3], wb_real out[3])
{
    wb_real r[3] = { M[0] * v[0] + M[1] * v[1] + M[2] * v[2], M[3] * v[0] + M[4] * v[1] + M[5] * v[2],
                     M[6] * v[0] + M[7] * v[1] + M[8] * v[2] };
    v3_copy(out, r);
}

static int m3_inverse(const wb_real M[9], wb_real out[9])
{
    const wb_real c0 = M[4] * M[8] - M[5] * M[7], c1 = M[5] * M[6] - M[3] * M[8], c2 = M[3] * M[7] - M[4] * M[6];
    const wb_real det = M[0] * c0 + M[1] * c1 + M[2] * c2;
    if (!(fabs(det) > 0) || !isfinite(det)) return 0;
    const wb_real d = 1 / det;
    out[0] = c0 * d; out[1] = (M[2] * M[7] - M[1] * M[8]) * d; out[2] = (M[1] * M[5] - M[2] * M[4]) * d;
    out[3] = c1 * d; out[4] = (M[0] * M[8] - M[2] * M[6]) * d; out[5] = (M[2] * M[3] - M[0] * M[5]) * d;
    out[6] = c2 * d; out[7] = (M[1] * M[6] - M[0] * M[7]) * d; out[8] = (M[0] * M[4] - M[1] * M[3]) * d;
    return 1;
}

void wb__rigid_inertia(const wb_cshape *s, wb_real m, wb_real I[9])
{
    memset(I, 0, 9 * sizeof(wb_real));
    const wb_shape_class *k = wb__shape(s->shape);
    if (k && k->inertia) k->inertia(s, m, I);
}

/* ---- bodies ----------------------------------------------------------------------------- */
wb_rigid_def wb_rigid_default_def(wb_shape shape)
{
    wb_rigid_def d;
    memset(&d, 0, sizeof d);
    d.shape = shape;
    d.radius = 0.5;
    v3_set(d.half, 0.5, 0.5, 0.5);
    v3_set(d.a, 0, -0.5, 0);
    v3_set(d.b, 0, 0.5, 0);
    d.mass = 1;
    d.rotation[0] = 1;
    return d;
}

const char *wb_rigid_def_check(const wb_rigid_def *d)
{
    const wb_shape_class *k = wb__shape(d->shape);
    if (!k || !k->inertia) return "shape must be sphere, box or capsule";
    if (!(d->mass > 0) || !isfinite(d->mass)) return "mass must be > 0";
    if (!(d->friction >= 0) || !isfinite(d->friction)) return "friction must be >= 0";
    if (!(d->restitution >= 0 && d->restitution <= 1)) return "restitution must be in [0, 1]";
    if (!fin3(d->pos)) return "pos must be finite";
    if (!fin3(d->vel)) return "vel must be finite";
    if (!fin3(d->angular_velocity)) return "angular_velocity must be finite";
    const char *e = wb__rotation_check(d->rotation);
    return e ? e : k->rigid_check(d);
}

int wb__rigid_set_slot(wb_world *w, int32_t r, const wb_cshape *s, wb_real mass, const wb_real x[3],
                       const wb_real q[4], const wb_real v[3], const wb_real om[3])
{
    wb_rigids *rb = w->rb;
    wb_real I[9], Ii[9];
    wb__rigid_inertia(s, mass, I);
    if (!m3_inverse(I, Ii)) return 0;
    rb->shape[r] = *s;
    rb->shape[r].mesh = NULL;
    rb->mass[r] = mass;
    rb->inv_mass[r] = 1 / mass;
    memcpy(&rb->inertia[9 * r], I, sizeof I);
    memcpy(&rb->inv_inertia[9 * r], Ii, sizeof Ii);
    rb->bound[r] = wb__shape_bound(s);
    v3_copy(&rb->x[3 * r], x);
    memcpy(&rb->q[4 * r], q, 4 * sizeof(wb_real));
    v3_copy(&rb->v[3 * r], v);
    v3_copy(&rb->om[3 * r], om);
    v3_copy(&rb->x_prev[3 * r], x);
    memcpy(&rb->q_prev[4 * r], q, 4 * sizeof(wb_real));
    rb->moved[r] = 0;
    return 1;
}

/* every per-slot array grows together; 0 on failure, nothing lost */
static int grow(wb_world *w, wb_rigids *rb, int32_t need)
{
    if (need <= rb->cap) return 1;
    int32_t c = rb->cap, cap = rb->cap;
    int64_t want = cap ? cap : 16;
    while (want < need) want *= 2;
    if (!wb__charge(w, &rb->charged, (size_t)want * SLOT_BYTES)) return 0;
#define G(ptr, k)                                                          \
    do {                                                                   \
        c = cap;                                                           \
        void *np_ = wb__grow(rb->ptr, &c, need, (k) * sizeof *rb->ptr);    \
        if (!np_) return 0;                                                \
        rb->ptr = np_;                                                     \
    } while (0)
    G(shape, 1); G(mass, 1); G(inv_mass, 1); G(inertia, 9); G(inv_inertia, 9); G(bound, 1); G(gen, 1);
    G(x, 3); G(q, 4); G(v, 3); G(om, 3); G(x_prev, 3); G(q_prev, 4); G(q_pred, 4); G(save, 13); G(moved, 1);
#undef G
    rb->cap = c;
    return 1;
}

int wb__rigids_reserve(wb_world *w, int32_t need)
{
    if (!w->rb && !(w->rb = calloc(1, sizeof *w->rb))) return 0;
    return grow(w, w->rb, need);
}

void wb__rigid_shape_of(const wb_rigid_def *d, wb_cshape *s, wb_real x[3], wb_real q[4])
{
    memset(s, 0, sizeof *s);
    s->shape = d->shape;
    s->friction = d->friction;
    s->restitution = d->restitution;
    memcpy(q, d->rotation, 4 * sizeof(wb_real));
    q_normalize(q);
    v3_copy(x, d->pos);
    wb_real c[3], cw[3];
    if (wb__shape(d->shape)->rigid_make(d, s, c)) {
        q_rotate(q, c, cw);
        v3_add(x, x, cw);
    }
}

wb_rigid_id wb_rigid_add(wb_world *w, const wb_rigid_def *def, wb_status *status)
{
    wb_rigid_id none = { 0, 0 };
    wb_status dummy;
    if (!status) status = &dummy;
    const char *err = wb_rigid_def_check(def);
    if (err) { wb__set_error("%s", err); *status = WB_ERR_ARG; return none; }
    if (!w->rb) {
        w->rb = calloc(1, sizeof *w->rb);
        if (!w->rb) { *status = WB_ERR_NOMEM; return none; }
    }
    wb_rigids *rb = w->rb;
    /* the lowest dead slot, from the hint (no dead slot below it): bodies added in a row
     * cost no quadratic scan */
    int32_t slot = -1;
    for (int32_t i = rb->free_hint; i < rb->n; i++)
        if (!(rb->gen[i] & 1u)) { slot = i; break; }
    rb->free_hint = slot < 0 ? rb->n : slot;
    if (slot < 0) {
        if (rb->n >= WB_MAX_RIGIDS) { *status = WB_ERR_LIMIT; return none; }
        if (!grow(w, rb, rb->n + 1)) { *status = WB_ERR_NOMEM; return none; }
        slot = rb->n++;
        rb->gen[slot] = 0;
    }
    wb_cshape s;
    wb_real x[3], q[4];
    wb__rigid_shape_of(def, &s, x, q);
    if (!wb__rigid_set_slot(w, slot, &s, def->mass, x, q, def->vel, def->angular_velocity)) {
        wb__set_error("the inertia tensor is singular (shape too small for its mass)");
        *status = WB_ERR_ARG;
        if (slot == rb->n - 1 && rb->gen[slot] == 0) rb->n--;
        return none;
    }
    rb->gen[slot]++;
    *status = WB_OK;
    wb_rigid_id id = { (uint32_t)slot + 1, rb->gen[slot] };
    return id;
}

bool wb_rigid_valid(const wb_world *w, wb_rigid_id r)
{
    const wb_rigids *rb = RB(w);
    if (!rb || r.index == 0 || r.index > (uint32_t)rb->n) return false;
    uint32_t g = rb->gen[r.index - 1];
    return (g & 1u) && g == r.gen;
}

#define RSLOT(w, r) (assert(wb_rigid_valid((w), (r))), (int32_t)(r).index - 1)

void wb_rigid_remove(wb_world *w, wb_rigid_id r)
{
    const int32_t i = RSLOT(w, r);
    w->rb->gen[i]++;
    if (i < w->rb->free_hint) w->rb->free_hint = i;
}

int32_t wb_rigid_count(const wb_world *w)
{
    const wb_rigids *rb = RB(w);
    int32_t n = 0;
    for (int32_t i = 0; rb && i < rb->n; i++) n += (int32_t)(rb->gen[i] & 1u);
    return n;
}

wb_rigid_id wb_rigid_at(const wb_world *w, int32_t i)
{
    const wb_rigids *rb = RB(w);
    for (int32_t s = 0; rb && s < rb->n; s++) {
        if (!(rb->gen[s] & 1u)) continue;
        if (i-- == 0) { wb_rigid_id id = { (uint32_t)s + 1, rb->gen[s] }; return id; }
    }
    wb_rigid_id none = { 0, 0 };
    return none;
}

int wb_rigid_solids(const wb_world *w, wb_rigid_id r, wb_solid out[WB_MAX_SOLIDS])
{
    const int32_t i = RSLOT(w, r);
    return wb__shape_solids(&w->rb->shape[i], &w->rb->x[3 * i], &w->rb->q[4 * i], out);
}

wb_real wb_rigid_bound(const wb_world *w, wb_rigid_id r) { return w->rb->bound[RSLOT(w, r)]; }

void wb_rigid_get_def(const wb_world *w, wb_rigid_id r, wb_rigid_def *out)
{
    const int32_t i = RSLOT(w, r);
    const wb_rigids *rb = w->rb;
    const wb_cshape *s = &rb->shape[i];
    *out = wb_rigid_default_def(s->shape);
    out->radius = s->radius;
    v3_copy(out->half, s->half);
    v3_copy(out->a, s->a);
    v3_copy(out->b, s->b);
    out->mass = rb->mass[i];
    out->friction = s->friction;
    out->restitution = s->restitution;
    v3_copy(out->pos, &rb->x[3 * i]);
    memcpy(out->rotation, &rb->q[4 * i], sizeof out->rotation);
    v3_copy(out->vel, &rb->v[3 * i]);
    v3_copy(out->angular_velocity, &rb->om[3 * i]);
}

void wb_rigid_position(const wb_world *w, wb_rigid_id r, wb_real out[3]) { v3_copy(out, &w->rb->x[3 * RSLOT(w, r)]); }
void wb_rigid_rotation(const wb_world *w, wb_rigid_id r, wb_real out[4]) { memcpy(out, &w->rb->q[4 * RSLOT(w, r)], 4 * sizeof(wb_real)); }
void wb_rigid_velocity(const wb_world *w, wb_rigid_id r, wb_real out[3]) { v3_copy(out, &w->rb->v[3 * RSLOT(w, r)]); }
void wb_rigid_angular_velocity(const wb_world *w, wb_rigid_id r, wb_real out[3]) { v3_copy(out, &w->rb->om[3 * RSLOT(w, r)]); }
wb_real wb_rigid_mass(const wb_world *w, wb_rigid_id r) { return w->rb->mass[RSLOT(w, r)]; }
void wb_rigid_set_position(wb_world *w, wb_rigid_id r, const wb_real p[3]) { assert(fin3(p)); v3_copy(&w->rb->x[3 * RSLOT(w, r)], p); }
void wb_rigid_set_velocity(wb_world *w, wb_rigid_id r, const wb_real v[3]) { assert(fin3(v)); v3_copy(&w->rb->v[3 * RSLOT(w, r)], v); }
void wb_rigid_set_angular_velocity(wb_world *w, wb_rigid_id r, const wb_real om[3]) { assert(fin3(om)); v3_copy(&w->rb->om[3 * RSLOT(w, r)], om); }

void wb_rigid_set_rotation(wb_world *w, wb_rigid_id r, const wb_real q[4])
{
    wb_real *t = &w->rb->q[4 * RSLOT(w, r)];
    memcpy(t, q, 4 * sizeof(wb_real));
    q_normalize(t);
}

/* I^-1 v in the world frame: R I_body^-1 R^T v */
static void inv_inertia_world(const wb_rigids *rb, int32_t r, const wb_real v[3], wb_real out[3])
{
    wb_real l[3];
    q_rotate_inv(&rb->q[4 * r], v, l);
    m3_mul(&rb->inv_inertia[9 * r], l, l);
    q_rotate(&rb->q[4 * r], l, out);
}

/* a velocity impulse p at world point x (v += p/m, om += I^-1 (r x p)) */
static void apply_velocity_impulse(wb_rigids *rb, int32_t r, const wb_real x[3], const wb_real p[3])
{
    wb_real d[3], t[3];
    v3_madd(&rb->v[3 * r], p, rb->inv_mass[r]);
    v3_sub(d, x, &rb->x[3 * r]);
    v3_cross(t, d, p);
    inv_inertia_world(rb, r, t, t);
    v3_add(&rb->om[3 * r], &rb->om[3 * r], t);
}

void wb__rigid_impulse(wb_world *w, int32_t r, const wb_real x[3], const wb_real p[3])
{
    apply_velocity_impulse(w->rb, r, x, p);
}

void wb_rigid_apply_impulse(wb_world *w, wb_rigid_id r, const wb_real J[3], const wb_real at[3])
{
    const int32_t i = RSLOT(w, r);
    apply_velocity_impulse(w->rb, i, at ? at : &w->rb->x[3 * i], J);
}

wb_real wb_rigid_distance(const wb_world *w, wb_rigid_id r, const wb_real p[3])
{
    const int32_t i = RSLOT(w, r);
    wb_real n[3];
    return wb__shape_distance(&w->rb->shape[i], &w->rb->x[3 * i], &w->rb->q[4 * i], p, n);
}

static void turn(wb_real q[4], const wb_real t[3]);

/* ---- the helpers of RIGID.md ---------------------------------------------------------------- */
wb_real wb__rigid_w(const wb_world *w, int32_t r, const wb_real x[3], const wb_real n[3])
{
    const wb_rigids *rb = w->rb;
    wb_real d[3], rn[3], l[3], il[3];
    v3_sub(d, x, &rb->x[3 * r]);
    v3_cross(rn, d, n);
    q_rotate_inv(&rb->q[4 * r], rn, l);
    m3_mul(&rb->inv_inertia[9 * r], l, il);
    return rb->inv_mass[r] + v3_dot(l, il);
}

void wb__rigid_inv_inertia(const wb_world *w, int32_t r, const wb_real v[3], wb_real out[3])
{
    inv_inertia_world(w->rb, r, v, out);
}

void wb__rigid_apply(wb_world *w, int32_t r, const wb_real x[3], const wb_real dp[3])
{
    wb_rigids *rb = w->rb;
    wb_real d[3], t[3];
    wb_real *p = &rb->x[3 * r], *q = &rb->q[4 * r];
    v3_sub(d, x, p);
    v3_cross(t, d, dp);
    inv_inertia_world(rb, r, t, t);
    v3_madd(p, dp, rb->inv_mass[r]);
    turn(q, t);
    rb->moved[r] = 1;
}

void wb__rigid_apply_start(wb_world *w, int32_t r, const wb_real x[3], const wb_real dp[3])
{
    wb_rigids *rb = w->rb;
    wb_real d[3], t[3];
    v3_sub(d, x, &rb->x[3 * r]);
    v3_cross(t, d, dp);
    inv_inertia_world(rb, r, t, t);
    v3_madd(&rb->x_prev[3 * r], dp, rb->inv_mass[r]);
    turn(&rb->q_prev[4 * r], t);
    turn(&rb->q_pred[4 * r], t);
}

void wb__rigid_point_response(const wb_world *w, int32_t r, const wb_real x[3], wb_real K[9])
{
    const wb_rigids *rb = w->rb;
    wb_real d[3];
    v3_sub(d, x, &rb->x[3 * r]);
    for (int k = 0; k < 3; k++) {
        /* column k: how the point moves for a unit impulse along axis k */
        wb_real e[3] = { 0, 0, 0 }, t[3], col[3];
        e[k] = 1;
        v3_cross(t, d, e);
        inv_inertia_world(rb, r, t, t);
        v3_cross(col, t, d);
        for (int i = 0; i < 3; i++) K[3 * i + k] = col[i] + (i == k ? rb->inv_mass[r] : 0);
    }
}

void wb__rigid_to_world(const wb_world *w, int32_t r, const wb_real local[3], wb_real out[3])
{
    wb_real t[3];
    q_rotate(&w->rb->q[4 * r], local, t);
    v3_add(out, t, &w->rb->x[3 * r]);
}

void wb__rigid_to_local(const wb_world *w, int32_t r, const wb_real world[3], wb_real out[3])
{
    wb_real t[3];
    v3_sub(t, world, &w->rb->x[3 * r]);
    q_rotate_inv(&w->rb->q[4 * r], t, out);
}

/* ---- the step --------------------------------------------------------------------------------- */
static int live(const wb_rigids *rb, int32_t r) { return rb->gen[r] & 1u; }

/* The rotation over a substep with the gyroscopic term, in the body frame (Euler's
 * equations: I dom/dt = L x om, i.e. L turns backwards as the body turns): L' = exp(-ob h) L
 * and q' = q exp(ob h) with ob = I^-1 (L + L') / 2, a fixed point. Both turns use the same
 * ob, so L in the world frame, R' L' = R exp(ob h) exp(-ob h) L = R L, is kept exactly (up
 * to the fixed point's tolerance and rounding) and the midpoint keeps the energy to
 * second order. The paper's explicit om += h I^-1 (-om x I om) instead grows |L| by
 * h^2 |om x L|^2 / (2 |L|^2) every substep. om becomes the end's: R' I^-1 L'. */
static void rotate(wb_rigids *rb, int32_t r, wb_real h)
{
    static const wb_real id[4] = { 1, 0, 0, 0 };
    wb_real *q = &rb->q[4 * r], *om = &rb->om[3 * r];
    const wb_real *I = &rb->inertia[9 * r], *Ii = &rb->inv_inertia[9 * r];
    wb_real ob[3], L[3], Ln[3], m[3], dq[4];
    q_rotate_inv(q, om, ob);
    m3_mul(I, ob, L);
    v3_copy(Ln, L);
    for (int it = 0; it < 50; it++) {
        wb_real neg[3], nx[3], d[3];
        v3_add(m, L, Ln);
        v3_scale(m, m, 0.5);
        m3_mul(Ii, m, ob);
        v3_scale(neg, ob, -1);
        q_integrate(id, neg, h, dq);
        q_rotate(dq, L, nx);
        v3_sub(d, nx, Ln);
        v3_copy(Ln, nx);
        if (!(v3_dot(d, d) > 1e-32 * v3_dot(L, L))) break;
    }
    v3_add(m, L, Ln);
    v3_scale(m, m, 0.5);
    m3_mul(Ii, m, ob);
    wb_real ow[3];
    q_rotate(q, ob, ow);
    q_integrate(q, ow, h, q);
    m3_mul(Ii, Ln, ob);
    q_rotate(q, ob, om);
}

void wb__rigids_predict(wb_world *w, wb_real h)
{
    wb_rigids *rb = w->rb;
    if (!rb) return;
    const wb_world_def *d = &w->m.def;
    const wb_real keep = d->damping > 0 ? (d->damping * h < 1 ? 1 - d->damping * h : 0) : 1;
    for (int32_t r = 0; r < rb->n; r++) {
        if (!live(rb, r)) continue;
        wb_real *x = &rb->x[3 * r], *q = &rb->q[4 * r], *v = &rb->v[3 * r], *om = &rb->om[3 * r];
        v3_copy(&rb->x_prev[3 * r], x);
        memcpy(&rb->q_prev[4 * r], q, 4 * sizeof(wb_real));
        rb->moved[r] = 0;
        for (int c = 0; c < 3; c++) v[c] = v[c] * keep + d->gravity[c] * h;
        v3_madd(x, v, h);
        if (keep != 1) v3_scale(om, om, keep);
        if (om[0] != 0 || om[1] != 0 || om[2] != 0) rotate(rb, r, h);
        memcpy(&rb->q_pred[4 * r], q, 4 * sizeof(wb_real));
    }
}

void wb__rigids_update(wb_world *w, wb_real h)
{
    wb_rigids *rb = w->rb;
    if (!rb) return;
    for (int32_t r = 0; r < rb->n; r++) {
        /* unmoved: (x - x_prev) / h would only give back the predicted v with the rounding
         * of a difference of positions (ulp(x) / h: 1e-11 m/s at 100 m) */
        if (!live(rb, r) || !rb->moved[r]) continue;
        const wb_real *x = &rb->x[3 * r], *xp = &rb->x_prev[3 * r], *q = &rb->q[4 * r], *p = &rb->q_pred[4 * r];
        wb_real *v = &rb->v[3 * r], *om = &rb->om[3 * r];
        for (int c = 0; c < 3; c++) v[c] = (x[c] - xp[c]) / h;
        /* om: the predicted one (the free rotation's end value, gyroscopic term included)
         * plus the turn the corrections made, dq = q q_pred^-1 as axis x angle / h (the exact
         * inverse of q_integrate). Taking all of om from q q_prev^-1 gives the turn's mean
         * rate instead of its end value: a tumbling box tied to a particle gained 15 % of
         * angular momentum in 2 s */
        wb_real dq[4] = {
            q[0] * p[0] + q[1] * p[1] + q[2] * p[2] + q[3] * p[3],
            -q[0] * p[1] + q[1] * p[0] - q[2] * p[3] + q[3] * p[2],
            -q[0] * p[2] + q[1] * p[3] + q[2] * p[0] - q[3] * p[1],
            -q[0] * p[3] - q[1] * p[2] + q[2] * p[1] + q[3] * p[0],
        };
        if (dq[0] < 0) for (int c = 0; c < 4; c++) dq[c] = -dq[c];
        const wb_real s = v3_len(&dq[1]);
        if (s > 0) v3_madd(om, &dq[1], 2 * atan2(s, dq[0]) / (s * h));
    }
}

/* one side of a contact: a body, or a kinematic collider moving over the substep */
typedef struct side {
    int32_t r;                       /* body, or -1 */
    const wb_real *p0, *q0, *p1, *q1; /* the collider's poses at the substep's start and end */
} side;

/* where a side's local point is now and was at the substep's start */
static void side_points(const wb_rigids *rb, const side *s, const wb_real l[3], wb_real now[3], wb_real prev[3])
{
    const wb_real *p1 = s->r >= 0 ? &rb->x[3 * s->r] : s->p1, *q1 = s->r >= 0 ? &rb->q[4 * s->r] : s->q1;
    const wb_real *p0 = s->r >= 0 ? &rb->x_prev[3 * s->r] : s->p0, *q0 = s->r >= 0 ? &rb->q_prev[4 * s->r] : s->q0;
    q_rotate(q1, l, now);
    v3_add(now, now, p1);
    q_rotate(q0, l, prev);
    v3_add(prev, prev, p0);
}

static void side_local(const wb_rigids *rb, const side *s, const wb_real x[3], wb_real out[3])
{
    const wb_real *p = s->r >= 0 ? &rb->x[3 * s->r] : s->p1, *q = s->r >= 0 ? &rb->q[4 * s->r] : s->q1;
    wb_real t[3];
    v3_sub(t, x, p);
    q_rotate_inv(q, t, out);
}

static wb_real side_w(const wb_world *w, const side *s, const wb_real x[3], const wb_real n[3])
{
    return s->r >= 0 ? wb__rigid_w(w, s->r, x, n) : 0;
}

/* a side's velocity at world point x */
static void side_velocity(const wb_rigids *rb, const side *s, const wb_real x[3], const wb_real vc[3], wb_real out[3])
{
    if (s->r < 0) { v3_copy(out, vc); return; }
    wb_real d[3];
    v3_sub(d, x, &rb->x[3 * s->r]);
    v3_cross(out, &rb->om[3 * s->r], d);
    v3_add(out, out, &rb->v[3 * s->r]);
}

/* positional impulse dp on B at xb and -dp on A at xa */
static void push(wb_world *w, const side *A, const side *B, const wb_real xa[3], const wb_real xb[3], const wb_real dp[3])
{
    if (B->r >= 0) wb__rigid_apply(w, B->r, xb, dp);
    if (A->r >= 0) {
        wb_real m[3] = { -dp[0], -dp[1], -dp[2] };
        wb__rigid_apply(w, A->r, xa, m);
    }
}

/* a side's offset of world point x from its centre (a collider: none needed) */
static void side_arm(const wb_rigids *rb, const side *s, const wb_real x[3], wb_real out[3])
{
    if (s->r >= 0) v3_sub(out, x, &rb->x[3 * s->r]);
    else v3_set(out, 0, 0, 0);
}

/* rotate a body by the small angle vector th: q += 0.5 [th, 0] q (the paper's eq. 8) */
static void turn(wb_real q[4], const wb_real t[3])
{
    const wb_real dq[4] = {
        (-t[0] * q[1] - t[1] * q[2] - t[2] * q[3]) / 2,
        (t[0] * q[0] + t[1] * q[3] - t[2] * q[2]) / 2,
        (-t[0] * q[3] + t[1] * q[0] + t[2] * q[1]) / 2,
        (t[0] * q[2] - t[1] * q[1] + t[2] * q[0]) / 2,
    };
    for (int i = 0; i < 4; i++) q[i] += dq[i];
    q_normalize(q);
}

/* Static friction at one point (A's local la, B's local lb): the two points' relative
 * tangential motion over the substep is undone when the impulse needed, |slip| / (w_A +
 * w_B) along it, is inside the cone lmax (Müller et al. 2020, eq. 9 and §3.5) */
static void slip_correct(wb_world *w, const side *A, const side *B, const wb_real la[3], const wb_real lb[3],
                         const wb_real n[3], wb_real lmax)
{
    const wb_rigids *rb = w->rb;
    wb_real pa[3], pa0[3], pb[3], pb0[3], slip[3];
    side_points(rb, A, la, pa, pa0);
    side_points(rb, B, lb, pb, pb0);
    for (int i = 0; i < 3; i++) slip[i] = (pb[i] - pb0[i]) - (pa[i] - pa0[i]);
    v3_madd(slip, n, -v3_dot(slip, n));
    const wb_real len = v3_len(slip);
    if (!(len > 0)) return;
    wb_real t[3], dp[3];
    v3_scale(t, slip, 1 / len);
    const wb_real wt = side_w(w, A, pa, t) + side_w(w, B, pb, t);
    const wb_real lt = wt > 0 ? len / wt : INFINITY;
    if (!(lt < lmax)) return;
    v3_scale(dp, t, -lt);
    push(w, A, B, pa, pb, dp);
}

/* body pairs' static friction, after both normal sweeps of the substep: the lower bodies
 * are back where the contacts below them put them */
static void static_friction_pairs(wb_world *w)
{
    wb_rigids *rb = w->rb;
    for (int32_t k = 0; k < rb->nfr; k++) {
        const wb_rfric *f = &rb->fr[k];
        if (!live(rb, f->a) || !live(rb, f->b)) continue;
        const side A = { f->a, NULL, NULL, NULL, NULL }, B = { f->b, NULL, NULL, NULL, NULL };
        slip_correct(w, &A, &B, f->la, f->lb, f->n, f->lmax);
    }
}

/* ---- made overlap ---------------------------------------------------------------------------- */
/* A manifold's made overlap (bodies made inside each other or a collider: a position error,
 * not a collision) is kept as contact.c keeps a pair's: `left`, what of the overlap it
 * started with its own last solve left, goes at no more than max_depenetration; what the
 * substep drove in since goes in full, and so does what the other manifolds pushed back
 * after its solve (the bodies of a stack sink into each other by a little every sweep,
 * which the next substep finds at its start: counted as made, that repair, capped, let a
 * stack of 10 boxes sink into itself at 1 cm/s). A manifold is known by its two sides, one
 * table per frame; at its first solve of a frame its overlap at the substep's start counts
 * as made when one substep would not take it (contact.c's rule), so a world loaded from a
 * snapshot goes on as the one saved. The speed the capped repair makes needs nothing more:
 * the velocity pass sets the points' normal speed (wb__rigids_velocity). */
#define MADE_NONE UINT64_MAX

static uint64_t made_key(int32_t a, int32_t b) { return (uint64_t)(uint32_t)a << 32 | (uint32_t)b; }

static int32_t made_slot(const uint64_t *mk, int32_t cap, uint64_t key)
{
    int32_t i = (int32_t)((key * 0x9E3779B97F4A7C15u) >> 40) & (cap - 1);
    while (mk[i] != MADE_NONE && mk[i] != key) i = (i + 1) & (cap - 1);
    return i;
}

/* the manifold's entry (added, *fresh, at its first solve of the frame); NULL when out
 * of memory */
static wb_real *made_left(wb_rigids *rb, uint64_t key, int *fresh)
{
    if (2 * (rb->nm + 1) > rb->cap_m) {
        const int32_t cap = rb->cap_m > 0 ? 2 * rb->cap_m : 64;
        uint64_t *mk = malloc(sizeof *mk * (size_t)cap);
        wb_real *ml = malloc(sizeof *ml * (size_t)cap);
        if (!mk || !ml) { free(mk); free(ml); return NULL; }
        for (int32_t i = 0; i < cap; i++) mk[i] = MADE_NONE;
        for (int32_t i = 0; i < rb->cap_m; i++) {
            if (rb->mk[i] == MADE_NONE) continue;
            const int32_t j = made_slot(mk, cap, rb->mk[i]);
            mk[j] = rb->mk[i];
            ml[j] = rb->ml[i];
        }
        free(rb->mk);
        free(rb->ml);
        rb->mk = mk;
        rb->ml = ml;
        rb->cap_m = cap;
    }
    const int32_t i = made_slot(rb->mk, rb->cap_m, key);
    *fresh = rb->mk[i] == MADE_NONE;
    if (*fresh) {
        rb->mk[i] = key;
        rb->ml[i] = 0;
        rb->nm++;
    }
    return &rb->ml[i];
}

/* The manifold's normal corrections are solved together: point after point (Gauss-Seidel
 * over the points, each moving the body before the next) tilts a box resting on four
 * corners a little differently every substep, and the tilts, not commuting, pump a spin
 * about the normal that nothing frictionless takes out again. Instead the multipliers
 * solve K lambda = depth, lambda >= 0 (K: the points' coupling through the two bodies'
 * generalized inverse masses at this pose) by projected Gauss-Seidel on the small system,
 * and the bodies move once: a symmetric contact gives a symmetric push. */
static void solve_manifold(wb_world *w, const side *A, const side *B, const wb_cshape *sa, const wb_cshape *sb,
                           const wb_manifold *m, uint64_t key, wb_real h)
{
    wb_rigids *rb = w->rb;
    const wb_real mu = fmax(sa->friction, sb->friction), e = fmax(sa->restitution, sb->restitution);
    const wb_real *n = m->normal;
    const int np = m->n < WB_MANIFOLD_MAX ? m->n : WB_MANIFOLD_MAX;
    wb_real la[WB_MANIFOLD_MAX][3], lb[WB_MANIFOLD_MAX][3], d[WB_MANIFOLD_MAX], vn_pre[WB_MANIFOLD_MAX];
    wb_real vcs[WB_MANIFOLD_MAX][3], ja[WB_MANIFOLD_MAX][3], jb[WB_MANIFOLD_MAX][3], lam[WB_MANIFOLD_MAX];
    wb_real d0[WB_MANIFOLD_MAX];
    int any = 0;
    for (int k = 0; k < np; k++) {
        wb_real pa[3], pa0[3], pb[3], pb0[3], d3[3], va[3], vb[3], rel[3], ra[3], rr[3];
        side_local(rb, A, m->pt[k].pa, la[k]);
        side_local(rb, B, m->pt[k].pb, lb[k]);
        side_points(rb, A, la[k], pa, pa0);
        side_points(rb, B, lb[k], pb, pb0);
        v3_sub(d3, pa, pb);
        d[k] = v3_dot(d3, n);
        v3_sub(d3, pa0, pb0);
        d0[k] = v3_dot(d3, n); /* at the substep's start */
        /* the velocities the bodies came in with */
        v3_sub(vcs[k], pa, pa0);
        v3_scale(vcs[k], vcs[k], 1 / h);
        side_velocity(rb, A, pa, vcs[k], va);
        side_velocity(rb, B, pb, vcs[k], vb);
        v3_sub(rel, vb, va);
        vn_pre[k] = v3_dot(rel, n);
        /* I^-1 (r x n) of each side, body frame rotated to the world */
        side_arm(rb, A, pa, ra);
        side_arm(rb, B, pb, rr);
        v3_cross(ja[k], ra, n);
        v3_cross(jb[k], rr, n);
        lam[k] = 0;
    }
    /* a made overlap: what of it the manifold kept goes at no more than half a substep's
     * max_depenetration x h per solve (it is solved twice per substep, the sweeps forward
     * and back); the rest in full (see made_left) */
    int fresh;
    wb_real *left = made_left(rb, key, &fresh);
    if (!left) wb__warn(w, "out of memory in rigid contacts; a made overlap is pushed out at once");
    if (left && fresh) {
        wb_real most = 0;
        for (int k = 0; k < np; k++)
            if (d[k] > 0 && d0[k] > most) most = d0[k];
        *left = most > rb->step ? most : 0;
    }
    wb_real kept = 0;
    for (int k = 0; k < np; k++) {
        if (left && d[k] > 0) {
            wb_real lk = *left, slow, err;
            d[k] = wb__contact_depth(d[k], d0[k], &lk, rb->step / 2, &slow, &err);
            if (lk > kept) kept = lk;
        }
        any |= d[k] > 0;
    }
    if (left) *left = kept;
    if (!any) return;
    wb_real ia[WB_MANIFOLD_MAX][3], ib[WB_MANIFOLD_MAX][3], K[WB_MANIFOLD_MAX][WB_MANIFOLD_MAX];
    const wb_real wa = A->r >= 0 ? rb->inv_mass[A->r] : 0, wbm = B->r >= 0 ? rb->inv_mass[B->r] : 0;
    for (int k = 0; k < np; k++) {
        if (A->r >= 0) inv_inertia_world(rb, A->r, ja[k], ia[k]); else v3_set(ia[k], 0, 0, 0);
        if (B->r >= 0) inv_inertia_world(rb, B->r, jb[k], ib[k]); else v3_set(ib[k], 0, 0, 0);
    }
    for (int i = 0; i < np; i++)
        for (int j = 0; j < np; j++) K[i][j] = wa + wbm + v3_dot(ja[i], ia[j]) + v3_dot(jb[i], ib[j]);
    for (int it = 0; it < 8 * np; it++) {
        wb_real change = 0;
        for (int i = 0; i < np; i++) {
            if (!(K[i][i] > 0)) continue;
            wb_real r = d[i];
            for (int j = 0; j < np; j++) r -= K[i][j] * lam[j];
            wb_real nl = lam[i] + r / K[i][i];
            if (!(nl > 0)) nl = 0;
            change = fmax(change, fabs(nl - lam[i]) * K[i][i]);
            lam[i] = nl;
        }
        if (!(change > 1e-15 * fabs(d[0]) + 1e-300)) break;
    }
    /* move each body once by the sum of its points' impulses */
    wb_real lsum = 0, ta[3] = { 0, 0, 0 }, tb[3] = { 0, 0, 0 };
    for (int k = 0; k < np; k++) {
        lsum += lam[k];
        v3_madd(ta, ia[k], -lam[k]);
        v3_madd(tb, ib[k], lam[k]);
    }
    if (B->r >= 0) { v3_madd(&rb->x[3 * B->r], n, lsum * wbm); turn(&rb->q[4 * B->r], tb); rb->moved[B->r] = 1; }
    if (A->r >= 0) { v3_madd(&rb->x[3 * A->r], n, -lsum * wa); turn(&rb->q[4 * A->r], ta); rb->moved[A->r] = 1; }
    /* static friction (§3.5): undo the tangential slip of the two bodies over the substep
     * when the impulse needed stays inside the friction cone, mu x the normal impulse. One
     * correction for the manifold, at the centre of its normal impulses: corner by corner
     * each correction turned the box about the normal and left the next corner slipping,
     * and a box on a slope crept down at 1 mm/s. Against a collider at once; between two
     * bodies after the substep's normal sweeps (static_friction_pairs): here the sweep has
     * just turned the lower body about its centre under the upper one's off-centre load
     * (the contact below turns it back later in the sweep), a correction now would drag the
     * upper body along with that passing turn, and, substep after substep, a box set 0.1 m
     * off the centre of the box below walked off it at 1 cm/s. */
    if (mu > 0 && lsum > 0 && (A->r < 0 || rb->record_fr)) {
        wb_real c[3] = { 0, 0, 0 }, lca[3], lcb[3];
        for (int k = 0; k < np; k++) {
            v3_madd(c, m->pt[k].pa, lam[k] / (2 * lsum));
            v3_madd(c, m->pt[k].pb, lam[k] / (2 * lsum));
        }
        /* c's local points in each body (after this solve: the slip is measured from the
         * substep's start poses to the poses when the correction is made) */
        side_local(rb, A, c, lca);
        side_local(rb, B, c, lcb);
        if (A->r < 0) {
            slip_correct(w, A, B, lca, lcb, n, mu * lsum);
        } else {
            wb_rfric *fr = wb__grow(rb->fr, &rb->cap_fr, rb->nfr + 1, sizeof *fr);
            if (fr) {
                rb->fr = fr;
                fr = &fr[rb->nfr++];
                fr->a = A->r;
                fr->b = B->r;
                v3_copy(fr->la, lca);
                v3_copy(fr->lb, lcb);
                v3_copy(fr->n, n);
                fr->lmax = mu * lsum;
            } else {
                wb__warn(w, "out of memory in rigid contacts; static friction skipped");
            }
        }
    }
    const int32_t first = rb->nct;
    for (int k = 0; k < np; k++) {
        if (!(lam[k] > 0) && !(d[k] > 0)) continue;
        /* kept for the velocity pass */
        wb_rcontact *ct = wb__grow(rb->ct, &rb->cap_ct, rb->nct + 1, sizeof *ct);
        if (!ct) { wb__warn(w, "out of memory in rigid contacts; friction and restitution skipped"); continue; }
        rb->ct = ct;
        ct = &ct[rb->nct++];
        ct->first = first;
        ct->a = A->r;
        ct->b = B->r;
        v3_copy(ct->ra, la[k]);
        v3_copy(ct->rb, lb[k]);
        if (A->r < 0) { wb_real pa0[3]; side_points(rb, A, la[k], ct->ra, pa0); } /* a collider: the world point */
        v3_copy(ct->n, n);
        ct->lambda = lam[k];
        ct->vn_pre = vn_pre[k];
        v3_copy(ct->vc, vcs[k]);
        ct->mu = mu;
        ct->e = e;
    }
}

void wb__rigid_contact_rigid(wb_world *w, int32_t a, int32_t b, const wb_manifold *m, wb_real h)
{
    const side A = { a, NULL, NULL, NULL, NULL }, B = { b, NULL, NULL, NULL, NULL };
    solve_manifold(w, &A, &B, &w->rb->shape[a], &w->rb->shape[b], m, made_key(a, b), h);
}

void wb__rigid_contact_collider(wb_world *w, int32_t c, const wb_real p0[3], const wb_real q0[4],
                                const wb_real p1[3], const wb_real q1[4], int32_t r,
                                const wb_manifold *m, wb_real h)
{
    const side A = { -1, p0, q0, p1, q1 }, B = { r, NULL, NULL, NULL, NULL };
    solve_manifold(w, &A, &B, &w->m.c_shape[c], &w->rb->shape[r], m, made_key(-1 - c, r), h);
}

/* the colliders' poses at the substep's start and end, and a bounding radius about the
 * pose (planes and meshes: -1, always tested), once per substep for all bodies */
static int collider_poses(wb_world *w, wb_real f0, wb_real f1)
{
    wb_rigids *rb = w->rb;
    const wb_model *m = &w->m;
    wb_real *cp = wb__grow(rb->cpose, &rb->cap_cpose, 15 * (m->nc > 0 ? m->nc : 1), sizeof *cp);
    if (!cp) return 0;
    rb->cpose = cp;
    for (int32_t c = 0; c < m->nc; c++) {
        if (!(m->c_gen[c] & 1u)) continue;
        wb_real *e = &cp[15 * c];
        wb__collider_pose_at(&w->s.c_pose[c], f0, e, e + 3);
        wb__collider_pose_at(&w->s.c_pose[c], f1, e + 7, e + 10);
        e[14] = wb__shape_bound(&m->c_shape[c]);
    }
    return 1;
}

/* body r against the live colliders. A collider whose bounding sphere is farther from the
 * body's than the margin has no point within it: skipped without the narrow phase */
static void touch_colliders(wb_world *w, int32_t r, wb_real h)
{
    wb_rigids *rb = w->rb;
    const wb_model *m = &w->m;
    /* points that may touch by the substep's end */
    const wb_real margin = h * (v3_len(&rb->v[3 * r]) + v3_len(&rb->om[3 * r]) * rb->bound[r]);
    const wb_real *xr = &rb->x[3 * r];
    for (int32_t c = 0; c < m->nc; c++) {
        if (!(m->c_gen[c] & 1u)) continue;
        const wb_real *e = &rb->cpose[15 * c];
        if (e[14] >= 0) {
            const wb_real reach = e[14] + rb->bound[r] + margin, d[3] = { xr[0] - e[7], xr[1] - e[8], xr[2] - e[9] };
            if (v3_dot(d, d) > reach * reach) continue;
        }
        wb_manifold mf;
        if (wb__narrow(&m->c_shape[c], e + 7, e + 10, &rb->shape[r], xr, &rb->q[4 * r], margin, &mf) > 0)
            wb__rigid_contact_collider(w, c, e, e + 3, e + 7, e + 10, r, &mf, h);
    }
}

/* bodies a < b if their bounding spheres meet */
static void touch_pair(wb_world *w, int32_t a, int32_t b, wb_real h)
{
    wb_rigids *rb = w->rb;
    wb_real d[3];
    v3_sub(d, &rb->x[3 * b], &rb->x[3 * a]);
    const wb_real margin = h * (v3_len(&rb->v[3 * a]) + v3_len(&rb->v[3 * b]) +
                                v3_len(&rb->om[3 * a]) * rb->bound[a] + v3_len(&rb->om[3 * b]) * rb->bound[b]);
    const wb_real reach = rb->bound[a] + rb->bound[b] + margin;
    if (v3_dot(d, d) > reach * reach) return;
    wb_manifold mf;
    if (wb__narrow(&rb->shape[a], &rb->x[3 * a], &rb->q[4 * a], &rb->shape[b], &rb->x[3 * b], &rb->q[4 * b],
                   margin, &mf) > 0)
        wb__rigid_contact_rigid(w, a, b, &mf, h);
}

/* sort keys: a body's low end along the sweep axis (ties by slot); a pair by (a, b) */
typedef struct wb_rkey { wb_real lo; int32_t r; } wb_rkey;
static int cmp_lo(const void *pa, const void *pb)
{
    const wb_rkey *a = pa, *b = pb;
    return a->lo < b->lo ? -1 : a->lo > b->lo ? 1 : (a->r > b->r) - (a->r < b->r);
}
static int cmp_pair(const void *pa, const void *pb)
{
    const int32_t *a = pa, *b = pb;
    return a[0] != b[0] ? (a[0] > b[0]) - (a[0] < b[0]) : (a[1] > b[1]) - (a[1] < b[1]);
}

/* The candidate body pairs of the substep by sort and sweep (O(n log n + pairs) instead of
 * all n^2 pairs), in the order of the all-pairs loop, (a, b) with a < b: the solve is the
 * same. A body's box: its bounding sphere grown by twice its margin (the pair test's reach
 * is the two spheres plus the two margins) and 5 % of its bound, so that the corrections
 * of the sweep, which move the bodies after the boxes are made, leave no pair out that the
 * exact test (touch_pair) would take. The axis: the one the centres spread most along.
 * 0 when out of memory (the caller tries all pairs). */
static int candidate_pairs(wb_world *w, wb_real h)
{
    wb_rigids *rb = w->rb;
    rb->npair = 0;
    int32_t nb = 0;
    for (int32_t r = 0; r < rb->n; r++) nb += live(rb, r);
    wb_real *box = wb__grow(rb->box, &rb->cap_box, 6 * (rb->n > 0 ? rb->n : 1), sizeof *box);
    if (!box) return 0;
    rb->box = box;
    wb_rkey *ord = wb__grow(rb->ord, &rb->cap_ord, nb > 0 ? nb : 1, sizeof *ord);
    if (!ord) return 0;
    rb->ord = ord;
    wb_real mean[3] = { 0, 0, 0 }, var[3] = { 0, 0, 0 };
    nb = 0;
    for (int32_t r = 0; r < rb->n; r++) {
        if (!live(rb, r)) continue;
        const wb_real *x = &rb->x[3 * r];
        const wb_real e = rb->bound[r] * (wb_real)1.05 + 2 * h * (v3_len(&rb->v[3 * r]) + v3_len(&rb->om[3 * r]) * rb->bound[r]);
        for (int c = 0; c < 3; c++) {
            box[6 * r + c] = x[c] - e;
            box[6 * r + 3 + c] = x[c] + e;
            mean[c] += x[c];
        }
        ord[nb++].r = r;
    }
    if (nb < 2) return 1;
    for (int c = 0; c < 3; c++) mean[c] /= nb;
    for (int32_t k = 0; k < nb; k++)
        for (int c = 0; c < 3; c++) var[c] += (rb->x[3 * ord[k].r + c] - mean[c]) * (rb->x[3 * ord[k].r + c] - mean[c]);
    const int ax = var[0] >= var[1] && var[0] >= var[2] ? 0 : var[1] >= var[2] ? 1 : 2;
    for (int32_t k = 0; k < nb; k++) ord[k].lo = box[6 * ord[k].r + ax];
    qsort(ord, (size_t)nb, sizeof *ord, cmp_lo);
    for (int32_t i = 0; i < nb; i++) {
        const int32_t a = ord[i].r;
        const wb_real *ba = &box[6 * a];
        for (int32_t k = i + 1; k < nb && ord[k].lo <= ba[3 + ax]; k++) {
            const int32_t b = ord[k].r;
            const wb_real *bb = &box[6 * b];
            int apart = 0;
            for (int c = 0; c < 3; c++) apart |= bb[c] > ba[3 + c] || ba[c] > bb[3 + c];
            if (apart) continue;
            int32_t *pr = wb__grow(rb->pair, &rb->cap_pair, 2 * (rb->npair + 1), sizeof *pr);
            if (!pr) return 0;
            rb->pair = pr;
            pr[2 * rb->npair] = a < b ? a : b;
            pr[2 * rb->npair + 1] = a < b ? b : a;
            rb->npair++;
        }
    }
    if (rb->npair > 1) qsort(rb->pair, (size_t)rb->npair, 2 * sizeof *rb->pair, cmp_pair);
    return 1;
}

/* Two Gauss-Seidel sweeps over the manifolds per substep, forward then backward. One
 * forward sweep is a product of projections that do not commute: its eigenvalues are
 * complex, and with the velocities taken from the positions, x' = G (2 x - x_prev), a mode
 * with eigenvalue l grows as |l +- sqrt(l^2 - l)|, above 1 for complex l (0.9 e^0.5i: 1.45
 * per substep). The boxes in the middle of a stack with friction have such modes: stacks
 * of 3 and more boxes jittered at cm/s from round-off and 10 fell. Forward then backward
 * is the symmetric product, with real eigenvalues l in [0, 1] and |mu|^2 = l <= 1.
 * (Alternating the direction from substep to substep left a |g| h bounce.) The velocity
 * pass keeps the forward sweep's contacts: their multipliers carry nearly all of the
 * push, and their incoming velocities are the ones restitution needs. The pairs come from
 * a sort and sweep (candidate_pairs), in the all-pairs order. */
void wb__rigids_solve(wb_world *w, wb_real h, wb_real f0, wb_real f1)
{
    wb_rigids *rb = w->rb;
    if (!rb) return;
    rb->nct = 0;
    rb->nfr = 0;
    if (!collider_poses(w, f0, f1)) {
        wb__warn(w, "out of memory in rigid contacts; the substep's contacts are skipped");
        return;
    }
    rb->step = w->m.def.max_depenetration * h;
    for (int32_t r = 0; r < rb->n; r++)
        if (live(rb, r)) touch_colliders(w, r, h);
    const int sweep = candidate_pairs(w, h);
    rb->record_fr = 1;
    if (sweep) {
        for (int32_t k = 0; k < rb->npair; k++) touch_pair(w, rb->pair[2 * k], rb->pair[2 * k + 1], h);
    } else {
        for (int32_t a = 0; a < rb->n; a++)
            for (int32_t b = a + 1; live(rb, a) && b < rb->n; b++)
                if (live(rb, b)) touch_pair(w, a, b, h);
    }
    rb->record_fr = 0;
    const int32_t kept = rb->nct;
    if (sweep) {
        for (int32_t k = rb->npair - 1; k >= 0; k--) touch_pair(w, rb->pair[2 * k], rb->pair[2 * k + 1], h);
    } else {
        for (int32_t a = rb->n - 1; a >= 0; a--)
            for (int32_t b = rb->n - 1; live(rb, a) && b > a; b--)
                if (live(rb, b)) touch_pair(w, a, b, h);
    }
    for (int32_t r = rb->n - 1; r >= 0; r--)
        if (live(rb, r)) touch_colliders(w, r, h);
    static_friction_pairs(w);
    rb->nct = kept;
}

/* a contact's world points and its sides */
static void contact_points(const wb_world *w, const wb_rcontact *ct, side *A, side *B, wb_real pa[3], wb_real pb[3])
{
    const side a = { ct->a, NULL, NULL, NULL, NULL }, b = { ct->b, NULL, NULL, NULL, NULL };
    *A = a;
    *B = b;
    if (ct->a >= 0) wb__rigid_to_world(w, ct->a, ct->ra, pa);
    else v3_copy(pa, ct->ra);
    wb__rigid_to_world(w, ct->b, ct->rb, pb);
}

static wb_real normal_velocity(const wb_rigids *rb, const wb_rcontact *ct, const side *A, const side *B,
                               const wb_real pa[3], const wb_real pb[3], wb_real rel[3])
{
    wb_real va[3], vb[3];
    side_velocity(rb, A, pa, ct->vc, va);
    side_velocity(rb, B, pb, ct->vc, vb);
    v3_sub(rel, vb, va);
    return v3_dot(rel, ct->n);
}

static void impulse(wb_rigids *rb, const wb_rcontact *ct, const wb_real pa[3], const wb_real pb[3], const wb_real p[3])
{
    if (ct->b >= 0) apply_velocity_impulse(rb, ct->b, pb, p);
    if (ct->a >= 0) {
        const wb_real m[3] = { -p[0], -p[1], -p[2] };
        apply_velocity_impulse(rb, ct->a, pa, m);
    }
}

/* Dynamic friction and restitution (§3.6) on the velocities the poses gave, a manifold
 * at a time: friction (|tangential impulse| <= mu x the point's normal impulse
 * lambda / h), then the normal velocities of all its points together (as the
 * positions: point by point, a box sliding with friction, pitched by it, kept an upward
 * velocity every substep and pressed the ground 3% too lightly). The target normal
 * velocity is -e times the one the point came in with, none below 2 |g| h so that
 * resting contact does not jitter. */
void wb__rigids_velocity(wb_world *w, wb_real h)
{
    wb_rigids *rb = w->rb;
    if (!rb) return;
    const wb_real g = v3_len(w->m.def.gravity);
    for (int32_t k0 = 0, k1; k0 < rb->nct; k0 = k1) {
        for (k1 = k0 + 1; k1 < rb->nct && rb->ct[k1].first == k0; k1++) {}
        const int np = k1 - k0;
        side A = { -1, NULL, NULL, NULL, NULL }, B = A;
        wb_real pa[WB_MANIFOLD_MAX][3], pb[WB_MANIFOLD_MAX][3], rel[3], p[3];
        /* friction impulses all from the same velocities, then applied (point by point,
         * the corners of a sliding box each met a slightly different velocity and it
         * veered); each stops no more than its share 1/np of its point's slip */
        wb_real pt[WB_MANIFOLD_MAX][3];
        for (int k = 0; k < np; k++) {
            const wb_rcontact *ct = &rb->ct[k0 + k];
            contact_points(w, ct, &A, &B, pa[k], pb[k]);
            v3_set(pt[k], 0, 0, 0);
            if (!(ct->mu > 0)) continue;
            const wb_real vn = normal_velocity(rb, ct, &A, &B, pa[k], pb[k], rel);
            v3_madd(rel, ct->n, -vn);
            const wb_real vtl = v3_len(rel);
            if (!(vtl > 0)) continue;
            wb_real t[3];
            v3_scale(t, rel, 1 / vtl);
            const wb_real wt = side_w(w, &A, pa[k], t) + side_w(w, &B, pb[k], t);
            if (!(wt > 0)) continue;
            v3_scale(pt[k], t, -fmin(ct->mu * ct->lambda / h, vtl / (wt * np)));
        }
        for (int k = 0; k < np; k++) impulse(rb, &rb->ct[k0 + k], pa[k], pb[k], pt[k]);
        /* K dl = target - vn, by Gauss-Seidel on the small system (K as in solve_manifold) */
        const wb_real *n = rb->ct[k0].n;
        wb_real ja[WB_MANIFOLD_MAX][3], jb[WB_MANIFOLD_MAX][3], ia[WB_MANIFOLD_MAX][3], ib[WB_MANIFOLD_MAX][3];
        wb_real K[WB_MANIFOLD_MAX][WB_MANIFOLD_MAX], b[WB_MANIFOLD_MAX], dl[WB_MANIFOLD_MAX];
        const wb_real wa = A.r >= 0 ? rb->inv_mass[A.r] : 0, wbm = rb->inv_mass[B.r];
        for (int k = 0; k < np; k++) {
            const wb_rcontact *ct = &rb->ct[k0 + k];
            wb_real r[3];
            side_arm(rb, &A, pa[k], r);
            v3_cross(ja[k], r, n);
            side_arm(rb, &B, pb[k], r);
            v3_cross(jb[k], r, n);
            if (A.r >= 0) inv_inertia_world(rb, A.r, ja[k], ia[k]); else v3_set(ia[k], 0, 0, 0);
            inv_inertia_world(rb, B.r, jb[k], ib[k]);
            const wb_real vn = normal_velocity(rb, ct, &A, &B, pa[k], pb[k], rel);
            const wb_real e = fabs(ct->vn_pre) > 2 * g * h ? ct->e : 0;
            b[k] = fmax(-e * ct->vn_pre, 0) - vn;
            dl[k] = 0;
        }
        for (int i = 0; i < np; i++)
            for (int j = 0; j < np; j++) K[i][j] = wa + wbm + v3_dot(ja[i], ia[j]) + v3_dot(jb[i], ib[j]);
        for (int it = 0; it < 8 * np; it++)
            for (int i = 0; i < np; i++) {
                if (!(K[i][i] > 0)) continue;
                wb_real r = b[i];
                for (int j = 0; j < np; j++) r -= K[i][j] * dl[j];
                dl[i] += r / K[i][i];
            }
        for (int k = 0; k < np; k++) {
            v3_scale(p, n, dl[k]);
            impulse(rb, &rb->ct[k0 + k], pa[k], pb[k], p);
        }
    }
}

void wb__rigids_save(wb_world *w)
{
    wb_rigids *rb = w->rb;
    if (!rb) return;
    /* the made overlaps of a new frame, worked out from the state (made_left) */
    for (int32_t i = 0; i < rb->cap_m; i++) rb->mk[i] = MADE_NONE;
    rb->nm = 0;
    for (int32_t r = 0; r < rb->n; r++) {
        wb_real *s = &rb->save[13 * r];
        v3_copy(s, &rb->x[3 * r]);
        memcpy(s + 3, &rb->q[4 * r], 4 * sizeof(wb_real));
        v3_copy(s + 7, &rb->v[3 * r]);
        v3_copy(s + 10, &rb->om[3 * r]);
    }
}

void wb__rigids_undo(wb_world *w)
{
    wb_rigids *rb = w->rb;
    if (!rb) return;
    for (int32_t r = 0; r < rb->n; r++) {
        const wb_real *s = &rb->save[13 * r];
        v3_copy(&rb->x[3 * r], s);
        memcpy(&rb->q[4 * r], s + 3, 4 * sizeof(wb_real));
        v3_copy(&rb->v[3 * r], s + 7);
        v3_copy(&rb->om[3 * r], s + 10);
    }
    rb->nct = 0;
}

int wb__rigids_finite(const wb_world *w)
{
    const wb_rigids *rb = w->rb;
    for (int32_t r = 0; rb && r < rb->n; r++) {
        if (!live(rb, r)) continue;
        const wb_real *x = &rb->x[3 * r], *q = &rb->q[4 * r];
        if (!fin3(x) || !fin3(&q[1]) || !isfinite(q[0]) || !fin3(&rb->v[3 * r]) || !fin3(&rb->om[3 * r])) return r;
    }
    return -1;
}
