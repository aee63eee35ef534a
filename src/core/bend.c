/* bend.c: dihedral bending constraints (Müller et al. 2007, "Position based dynamics",
 * appendix A, in XPBD form with compliance).
 *
 * A bend joins two triangles (p1, p2, p3) and (p2, p1, p4) hinged on the edge p1-p2 and
 * keeps the angle between their normals at its rest value (the angle at creation). The
 * angle is signed, atan2(sin, cos) of the two normals, so it is smooth through flat (0)
 * and through folded over (+-pi, where C wraps): the acos of the paper has an infinite
 * gradient at both. The gradients are Bridson et al. 2003's bending modes, finite for any
 * non-degenerate pair of triangles; a degenerate one (a wing on the hinge line, or a
 * zero-length hinge) has no angle and is skipped for that projection.
 *
 * Colour batches (colour.c, four particles per constraint) are projected batch after
 * batch, a batch in parallel chunks: the same result for any thread count. Under the
 * Jacobi solver bends are still projected Gauss-Seidel (their batches are conflict-free,
 * so this needs no accumulator and stays deterministic). */
#include <assert.h>
#include <stdlib.h>

#include "ctype.h"

#define PI_R ((wb_real)3.14159265358979323846)

/* bytes per constraint over the model and cache arrays, for the memory budget */
#define BEND_BYTES (8 * sizeof(int32_t) + 5 * sizeof(wb_real) + 2 * sizeof(int32_t) + 1)

/* ---- geometry ---------------------------------------------------------------------------- */
/* the dihedral angle across x1-x2 (0 flat, sign: the wings folding towards n1 x n2 . e)
 * and, when g is not NULL, its gradient for the four particles. 0 when degenerate. */
static int dihedral(const wb_real *x1, const wb_real *x2, const wb_real *x3, const wb_real *x4, wb_real *theta,
                    wb_real g[4][3])
{
    wb_real e[3], a3[3], a4[3], n1[3], n2[3], c[3];
    v3_sub(e, x2, x1);
    v3_sub(a3, x3, x1);
    v3_sub(a4, x4, x1);
    v3_cross(n1, e, a3); /* both normals point the same way when the pair lies flat */
    v3_cross(n2, a4, e);
    const wb_real ee = v3_dot(e, e), q1 = v3_dot(n1, n1), q2 = v3_dot(n2, n2);
    /* a triangle whose height is below 1e-12 of its hinge has no reliable normal */
    if (!(ee > (wb_real)1e-24) || !(q1 > (wb_real)1e-24 * ee * ee) || !(q2 > (wb_real)1e-24 * ee * ee)) return 0;
    const wb_real le = sqrt(ee);
    v3_cross(c, n1, n2);
    *theta = atan2(v3_dot(c, e) / le, v3_dot(n1, n2));
    if (!g) return 1;
    /* the wings move along their normals; the hinge ends share the rest so that the
     * gradients sum to zero (momentum) and are orthogonal to rotations */
    wb_real b3[3], b4[3], s;
    v3_scale(b3, n1, 1 / q1);
    v3_scale(b4, n2, 1 / q2);
    v3_scale(g[2], b3, -le);
    v3_scale(g[3], b4, -le);
    wb_real t[3];
    v3_sub(t, x3, x2);
    s = v3_dot(t, e) / le;
    v3_scale(g[0], b3, -s);
    v3_sub(t, x4, x2);
    s = v3_dot(t, e) / le;
    v3_madd(g[0], b4, -s);
    s = v3_dot(a3, e) / le;
    v3_scale(g[1], b3, s);
    s = v3_dot(a4, e) / le;
    v3_madd(g[1], b4, s);
    return 1;
}

/* theta - rest in (-pi, pi]: the short way round, so a fold past pi is not undone the long way */
static wb_real wrap(wb_real d)
{
    if (d > PI_R) d -= 2 * PI_R;
    else if (d <= -PI_R) d += 2 * PI_R;
    return d;
}

/* ---- memory --------------------------------------------------------------------------------- */
static int charge(wb_world *w, int32_t cap)
{
    wb_memory *mem = w->m.def.memory;
    wb_bends *b = &w->bend;
    if (!mem) return 1;
    const double want = (double)cap * BEND_BYTES;
    const double used = (double)mem->used - (double)b->charged + want;
    if (mem->limit > 0 && used > (double)mem->limit) return 0;
    mem->used = (size_t)used;
    b->charged = (size_t)want;
    return 1;
}

static wb_status grow(wb_world *w, int32_t need)
{
    wb_bends *b = &w->bend;
    if (need <= b->cap) return WB_OK;
    if (need > WB_MAX_CONSTRAINTS) return WB_ERR_LIMIT;
    int32_t cap = b->cap ? b->cap : 64;
    while (cap < need) cap = cap > WB_MAX_CONSTRAINTS / 2 ? WB_MAX_CONSTRAINTS : cap * 2;
    if (!charge(w, cap)) {
        cap = need;
        if (!charge(w, cap)) return WB_ERR_NOMEM;
    }
    struct { void **p; size_t elem; } arr[] = {
        { (void **)&b->ij, 4 * sizeof(int32_t) }, { (void **)&b->alpha, sizeof(wb_real) },
        { (void **)&b->beta, sizeof(wb_real) }, { (void **)&b->rest, sizeof(wb_real) },
        { (void **)&b->s_ij, 4 * sizeof(int32_t) }, { (void **)&b->s_slot, sizeof(int32_t) },
        { (void **)&b->pack, sizeof(int32_t) }, { (void **)&b->lambda, sizeof(wb_real) },
        { (void **)&b->btorque, sizeof(wb_real) }, { (void **)&b->broken, 1 },
    };
    for (size_t i = 0; i < sizeof arr / sizeof arr[0]; i++) {
        void *q = realloc(*arr[i].p, (size_t)cap * arr[i].elem);
        if (!q) return WB_ERR_NOMEM; /* arrays already grown are merely larger */
        *arr[i].p = q;
    }
    b->cap = cap;
    return WB_OK;
}

wb_status wb__bend_reserve(wb_world *w, int64_t extra)
{
    if (w->bend.n + extra > WB_MAX_CONSTRAINTS) return WB_ERR_LIMIT;
    return grow(w, w->bend.n + (int32_t)extra);
}

/* ---- the C API -------------------------------------------------------------------------------- */
wb_bend_def wb_bend_default_def(void)
{
    wb_bend_def d = { 0, 0, NAN, 0 };
    return d;
}

const char *wb_bend_def_check(const wb_bend_def *d)
{
    if (!(d->compliance >= 0) || !isfinite(d->compliance)) return "compliance must be >= 0";
    if (!(d->damping >= 0) || !isfinite(d->damping)) return "damping must be >= 0";
    if (!isnan(d->rest) && !(d->rest >= -PI_R && d->rest <= PI_R)) return "rest must be an angle in [-pi, pi] (radians)";
    if (!(d->break_torque >= 0) || !isfinite(d->break_torque)) return "break_torque must be >= 0 (N m)";
    return NULL;
}

bool wb_dihedral_angle(const wb_real x1[3], const wb_real x2[3], const wb_real x3[3], const wb_real x4[3], wb_real *theta)
{
    return dihedral(x1, x2, x3, x4, theta, NULL) != 0;
}

wb_real wb__bend_angle_of(const wb_real *x, const int32_t *p, int *ok)
{
    wb_real th = 0;
    *ok = dihedral(&x[3 * p[0]], &x[3 * p[1]], &x[3 * p[2]], &x[3 * p[3]], &th, NULL);
    return th;
}

wb_bend_id wb_bend_add(wb_world *w, const int32_t p[4], const wb_bend_def *def, wb_status *status)
{
    wb_bend_id none = { 0, 0 };
    wb_status dummy;
    if (!status) status = &dummy;
    const char *err = wb_bend_def_check(def);
    for (int i = 0; i < 4 && !err; i++) {
        if (p[i] < 0 || p[i] >= w->m.np) err = "particle out of range";
        for (int j = 0; j < i && !err; j++)
            if (p[i] == p[j]) err = "a bend needs four distinct particles";
    }
    int ok = 1;
    wb_real rest = def->rest;
    if (!err && isnan(rest)) {
        rest = wb__bend_angle_of(w->s.x, p, &ok);
        if (!ok) err = "the two triangles are degenerate (a wing on the hinge line): no angle to keep";
    }
    if (err) {
        wb__set_error("%s", err);
        *status = WB_ERR_ARG;
        return none;
    }
    wb_status st = grow(w, w->bend.n + 1);
    if (st != WB_OK) { *status = st; return none; }
    wb_bends *b = &w->bend;
    const int32_t s = b->n++;
    memcpy(&b->ij[4 * s], p, 4 * sizeof *p);
    b->alpha[s] = def->compliance;
    b->beta[s] = def->damping;
    b->rest[s] = rest == -PI_R ? PI_R : rest; /* one name for the folded-over angle */
    b->btorque[s] = def->break_torque;
    b->broken[s] = 0;
    b->pack[s] = -1;
    b->dirty = 1;
    *status = WB_OK;
    wb_bend_id id = { (uint32_t)s + 1, 1 };
    return id;
}

bool wb_bend_valid(const wb_world *w, wb_bend_id c) { return c.gen == 1 && c.index >= 1 && c.index <= (uint32_t)w->bend.n; }

#define BSLOT(w, c) (assert(wb_bend_valid((w), (c))), (int32_t)(c).index - 1)

wb_real wb_bend_angle(const wb_world *w, wb_bend_id c)
{
    int ok;
    wb_real th = wb__bend_angle_of(w->s.x, &w->bend.ij[4 * BSLOT(w, c)], &ok);
    return ok ? th : NAN;
}

wb_real wb_bend_rest(const wb_world *w, wb_bend_id c) { return w->bend.rest[BSLOT(w, c)]; }

wb_real wb_bend_force(const wb_world *w, wb_bend_id c)
{
    const int32_t s = BSLOT(w, c), i = w->bend.pack[s];
    if (w->bend.dirty || i < 0 || w->bend.broken[s]) return 0; /* not stepped since it was made, or broken */
    const wb_real h = w->k.h_last;
    return fabs(w->bend.lambda[i]) / (h * h);
}

void wb_bend_particles(const wb_world *w, wb_bend_id c, int32_t p[4]) { memcpy(p, &w->bend.ij[4 * BSLOT(w, c)], 4 * sizeof *p); }
int32_t wb_bend_count(const wb_world *w) { return w->bend.n; }
bool wb_bend_broken(const wb_world *w, wb_bend_id c) { return w->bend.broken[BSLOT(w, c)] != 0; }
int32_t wb_world_bend_break_count(const wb_world *w) { return w->bend.nbreaks; }
wb_bend_id wb_world_bend_break_at(const wb_world *w, int32_t i)
{
    assert(i >= 0 && i < w->bend.nbreaks);
    return w->bend.breaks[i];
}
wb_bend_id wb_bend_at(const wb_world *w, int32_t i)
{
    assert(i >= 0 && i < w->bend.n);
    wb_bend_id id = { (uint32_t)i + 1, 1 };
    return id;
}

/* ---- the type ---------------------------------------------------------------------------- */
static int32_t bend_count(const wb_world *w) { return w->bend.n; }

static int always(const void *ud, int32_t i) { (void)ud; (void)i; return 1; }

static wb_status bend_prepare(wb_world *w)
{
    wb_bends *b = &w->bend;
    b->nbreaks = 0; /* the list reports the step about to run */
    if (!b->dirty) return WB_OK;
    uint8_t *colour = malloc((size_t)(b->n > 0 ? b->n : 1));
    int32_t count[WB_MAX_COLOURS + 1], start[WB_MAX_COLOURS + 1];
    if (!colour || !wb__colour_greedy(w->m.inv_mass, w->m.np, b->ij, 4, b->n, always, NULL, colour, count)) {
        free(colour);
        return WB_ERR_NOMEM;
    }
    wb__colour_ranges(count, b->colour_start, &b->ncolours, &b->serial_start, start);
    for (int32_t s = 0; s < b->n; s++) {
        const int32_t i = start[colour[s]]++;
        memcpy(&b->s_ij[4 * i], &b->ij[4 * s], 4 * sizeof(int32_t));
        b->s_slot[i] = s;
        b->pack[s] = i;
        b->lambda[i] = 0;
    }
    free(colour);
    b->dirty = 0;
    return WB_OK;
}

static void bend_substep_begin(wb_world *w)
{
    if (w->bend.n > 0) memset(w->bend.lambda, 0, sizeof(wb_real) * (size_t)w->bend.n);
}

/* XPBD on packed [lo, hi): dlambda = (-C - at lambda - gamma grad C . (x - x_prev)) /
 * ((1 + gamma) sum w |grad|^2 + at), each movable particle moved by w grad dlambda;
 * particles with w = 0 are never written */
static void project_range(wb_world *w, int32_t lo, int32_t hi, wb_real h, wb_real inv_h2)
{
    wb_bends *b = &w->bend;
    const wb_real *wv = w->m.w, *xp = w->s.x_prev;
    wb_real *x = w->s.x;
    for (int32_t i = lo; i < hi; i++) {
        const int32_t *p = &b->s_ij[4 * i], s = b->s_slot[i];
        if (b->broken[s]) continue;
        wb_real g[4][3], th;
        if (!dihedral(&x[3 * p[0]], &x[3 * p[1]], &x[3 * p[2]], &x[3 * p[3]], &th, g)) continue;
        wb_real den = 0;
        for (int k = 0; k < 4; k++) den += wv[p[k]] * v3_dot(g[k], g[k]);
        const wb_real at = b->alpha[s] * inv_h2;
        if (!(den > 0) || isinf(at) || !isfinite(den)) continue;
        wb_real num = -wrap(th - b->rest[s]) - at * b->lambda[i], d = den + at;
        if (b->beta[s] > 0 && at > 0) {
            /* gamma = alpha~ beta~ / h with beta~ = h^2 beta, as a distance's damping */
            const wb_real gamma = at * b->beta[s] * h;
            wb_real rel = 0;
            for (int k = 0; k < 4; k++) {
                wb_real v[3];
                v3_sub(v, &x[3 * p[k]], &xp[3 * p[k]]);
                rel += v3_dot(g[k], v);
            }
            /* gamma overflowed: its limit, a correction removing the angular velocity */
            if (isinf(gamma)) { num = -rel; d = den; }
            else { num -= gamma * rel; d += gamma * den; }
        }
        const wb_real dl = num / d;
        if (!isfinite(dl)) continue;
        b->lambda[i] += dl;
        for (int k = 0; k < 4; k++)
            if (wv[p[k]] > 0) v3_madd(&x[3 * p[k]], g[k], wv[p[k]] * dl);
    }
}

typedef struct bend_job { wb_world *w; int32_t lo; wb_real h, inv_h2; } bend_job;

static void bend_part(void *ctx, int32_t lo, int32_t hi)
{
    const bend_job *j = ctx;
    project_range(j->w, j->lo + lo, j->lo + hi, j->h, j->inv_h2);
}

static void bend_project(wb_world *w, wb_real h)
{
    wb_bends *b = &w->bend;
    const wb_real inv_h2 = 1 / (h * h);
    w->k.projections += b->n;
    for (int32_t c = 0; c < b->ncolours; c++) {
        const int32_t lo = b->colour_start[c], hi = b->colour_start[c + 1];
        wb_pool *pool = c < b->serial_start && hi - lo >= 256 ? wb__world_pool(w) : NULL;
        if (!pool) {
            project_range(w, lo, hi, h, inv_h2);
            continue;
        }
        /* contiguous chunks on the pool: a batch shares no movable particle */
        bend_job j = { w, lo, h, inv_h2 };
        wb__pool_for(pool, hi - lo, 128, bend_part, &j);
    }
}

/* U = C^2 / (2 alpha) for compliant bends (alpha = 1/k, k in N m / rad) */
static wb_real bend_energy(const wb_world *w)
{
    const wb_bends *b = &w->bend;
    wb_real e = 0;
    for (int32_t s = 0; s < b->n; s++) {
        int ok;
        if (b->alpha[s] <= 0 || b->broken[s]) continue;
        const wb_real th = wb__bend_angle_of(w->s.x, &b->ij[4 * s], &ok);
        if (!ok) continue;
        const wb_real c = wrap(th - b->rest[s]);
        e += c * c / (2 * b->alpha[s]);
    }
    return e;
}

/* breaking by torque, once per frame on the multiplier of the frame's last substep (the
 * torque wb_bend_force reads: lambda / h^2 of an angle is N m), as distances break by
 * force; a broken bend stays (its slot is its handle) and is skipped from then on */
static void bend_frame_end(wb_world *w)
{
    wb_bends *b = &w->bend;
    if (b->dirty || !(w->k.h_last > 0)) return;
    const wb_real inv_h2 = 1 / (w->k.h_last * w->k.h_last);
    for (int32_t i = 0; i < b->n; i++) {
        const int32_t s = b->s_slot[i];
        if (!(b->btorque[s] > 0) || b->broken[s] || !(fabs(b->lambda[i]) * inv_h2 > b->btorque[s])) continue;
        b->broken[s] = 1;
        wb_bend_id id = { (uint32_t)s + 1, 1 };
        wb_bend_id *q = wb__grow(b->breaks, &b->cap_breaks, b->nbreaks + 1, sizeof *q);
        if (q) { b->breaks = q; b->breaks[b->nbreaks++] = id; }
    }
}

const wb_ctype wb__bend_type = {
    .name = "bend",
    .count = bend_count,
    .prepare = bend_prepare,
    .substep_begin = bend_substep_begin,
    .project = bend_project,
    .frame_end = bend_frame_end,
    .energy = bend_energy,
};

/* ---- hinges of a triangle list ----------------------------------------------------------------- */
typedef struct hedge { int32_t lo, hi, u, v, opp, t; } hedge;

static int cmp_hedge(const void *pa, const void *pb)
{
    const hedge *a = pa, *b = pb;
    if (a->lo != b->lo) return a->lo < b->lo ? -1 : 1;
    if (a->hi != b->hi) return a->hi < b->hi ? -1 : 1;
    return a->t < b->t ? -1 : a->t > b->t; /* (lo, hi, t) is unique: a total order, so any qsort agrees */
}

int32_t wb__bend_hinges(const int32_t *tri, int32_t ntri, int32_t *out)
{
    hedge *e = malloc(sizeof *e * 3 * (size_t)(ntri > 0 ? ntri : 1));
    if (!e) return -1;
    for (int32_t t = 0; t < ntri; t++)
        for (int k = 0; k < 3; k++) {
            const int32_t u = tri[3 * t + k], v = tri[3 * t + (k + 1) % 3], o = tri[3 * t + (k + 2) % 3];
            hedge h = { u < v ? u : v, u < v ? v : u, u, v, o, t };
            e[3 * t + k] = h;
        }
    qsort(e, 3 * (size_t)ntri, sizeof *e, cmp_hedge);
    int32_t n = 0;
    for (int32_t i = 0; i < 3 * ntri;) {
        int32_t j = i + 1;
        while (j < 3 * ntri && e[j].lo == e[i].lo && e[j].hi == e[i].hi) j++;
        /* exactly two triangles: an interior edge (a border has one, a non-manifold edge more) */
        if (j - i == 2 && e[i].opp != e[i + 1].opp) {
            /* hinge in the first triangle's winding: (p1, p2, p3) and (p2, p1, p4) */
            out[4 * n] = e[i].u;
            out[4 * n + 1] = e[i].v;
            out[4 * n + 2] = e[i].opp;
            out[4 * n + 3] = e[i + 1].opp;
            n++;
        }
        i = j;
    }
    free(e);
    return n;
}
