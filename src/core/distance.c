/* distance.c: the distance constraint type (DESIGN.md §2): packing and colouring of
 * the live links into batches, their XPBD projection (Gauss-Seidel batch by batch or
 * Jacobi), plastic flow and breaking once per frame, and their elastic energy. The
 * slot arrays and the C API (wb_distance_*) live in world.c with the other model
 * arrays; this file owns the solver cache built from them (wb_cache's s_* arrays). */
#include <stdlib.h>

#include "ctype.h"

static int realloc_n(void **p, int32_t n, size_t elem)
{
    void *q = realloc(*p, (size_t)(n > 0 ? n : 1) * elem);
    if (!q) return 0;
    *p = q;
    return 1;
}

static int packable(const void *ud, int32_t s)
{
    const wb_world *w = ud;
    return (w->m.d_gen[s] & 1u) && !w->s.d_broken[s];
}

/* ---- packing: rebuild the colour batches when the topology changed --------------------- */
wb_status wb__colour(wb_world *w)
{
    wb_model *m = &w->m;
    wb_cache *k = &w->k;
    if (!m->topology_dirty) return WB_OK;
    k->pc.keys_dirty = 1; /* the constraint pairs that self-collision skips */

    int32_t ns = 0;
    for (int32_t s = 0; s < m->nd; s++) ns += packable(w, s);

    uint8_t *colour = malloc((size_t)(m->nd > 0 ? m->nd : 1));
    int32_t count[WB_MAX_COLOURS + 1];
    if (!colour ||
        !realloc_n((void **)&k->s_a, ns, sizeof(int32_t)) || !realloc_n((void **)&k->s_b, ns, sizeof(int32_t)) ||
        !realloc_n((void **)&k->s_rest, ns, sizeof(wb_real)) || !realloc_n((void **)&k->s_alpha, ns, sizeof(wb_real)) ||
        !realloc_n((void **)&k->s_beta, ns, sizeof(wb_real)) || !realloc_n((void **)&k->s_lambda, ns, sizeof(wb_real)) ||
        !realloc_n((void **)&k->s_jac, ns, sizeof(wb_real)) ||
        !realloc_n((void **)&k->s_slot, ns, sizeof(int32_t)) ||
        !realloc_n((void **)&k->colour_start, WB_MAX_COLOURS + 2, sizeof(int32_t)) ||
        !wb__colour_greedy(m->inv_mass, m->np, m->d_ij, 2, m->nd, packable, w, colour, count)) {
        free(colour);
        return WB_ERR_NOMEM;
    }
    int32_t start[WB_MAX_COLOURS + 1];
    k->ns = wb__colour_ranges(count, k->colour_start, &k->ncolours, &k->serial_start, start);
    k->any_damping = 0;
    for (int32_t i = 0; i < m->np; i++) k->ncount[i] = 0;
    for (int32_t s = 0; s < m->nd; s++) {
        if (colour[s] == WB_NO_COLOUR) { k->slot_pack[s] = -1; continue; }
        int32_t i = start[colour[s]]++;
        int32_t a = m->d_ij[2 * s], b = m->d_ij[2 * s + 1];
        k->s_a[i] = a;
        k->s_b[i] = b;
        k->s_rest[i] = w->s.d_rest[s];
        k->s_alpha[i] = m->d_alpha[s];
        k->s_beta[i] = m->d_beta[s];
        k->s_lambda[i] = 0;
        k->s_slot[i] = s;
        k->slot_pack[s] = i;
        k->ncount[a]++;
        k->ncount[b]++;
        if (m->d_beta[s] > 0 && m->d_alpha[s] > 0) k->any_damping = 1;
    }
    /* Jacobi: a constraint's share is set by its busier movable end (an immovable
     * hub must not shrink its spokes' corrections) */
    for (int32_t i = 0; i < ns; i++) {
        const int32_t a = k->s_a[i], b = k->s_b[i];
        const int32_t na = m->inv_mass[a] > 0 ? k->ncount[a] : 1, nb = m->inv_mass[b] > 0 ? k->ncount[b] : 1;
        k->s_jac[i] = (wb_real)1 / (na > nb ? na : nb);
    }
    free(colour);
    m->topology_dirty = 0;
    return WB_OK;
}

/* ---- projection ----------------------------------------------------------------------------- */
/* Project the distance constraints [b, e) of the packed arrays (XPBD, Macklin et al.
 * 2016 eq. 18 with the damping of eq. 26). Gauss-Seidel updates positions in place;
 * Jacobi (out = dx) accumulates corrections computed from the same positions, each
 * scaled by omega / max(n_a, n_b) (k->s_jac) for both its ends, so that a pair's
 * corrections stay equal and opposite (momentum) and lambda is the multiplier
 * actually applied (force readback). Particles with w = 0 are never written, not
 * even with 0: -0.0 would turn +0.0, and immovable particles may be shared inside
 * a batch. The caller guarantees that no two constraints in [b, e) write the same
 * movable particle when it runs the range in parallel. `damped` and `jacobi` are
 * compile-time constants at each call. (A branch-free `omp simd` version with
 * AVX-512 gathers and scatters measured slower than this scalar loop.) */
static inline __attribute__((always_inline)) void
project_range(const wb_cache *k, const wb_real *restrict wv, wb_real *x, const wb_real *restrict xp,
              wb_real *out, int32_t b, int32_t e, wb_real h, wb_real inv_h2, wb_real omega,
              const int damped, const int jacobi)
{
    const int32_t *restrict sa = k->s_a, *restrict sb = k->s_b;
    const wb_real *restrict rest = k->s_rest, *restrict alpha = k->s_alpha, *restrict beta = k->s_beta;
    const wb_real *restrict jac = k->s_jac;
    wb_real *restrict lambda = k->s_lambda;
    for (int32_t i = b; i < e; i++) {
        const int32_t ia = sa[i], ic = sb[i];
        const wb_real wa = wv[ia], wc = wv[ic], wsum = wa + wc;
        const wb_real *xa = &x[3 * ia], *xc = &x[3 * ic];
        const wb_real d0 = xc[0] - xa[0], d1 = xc[1] - xa[1], d2 = xc[2] - xa[2];
        const wb_real len2 = d0 * d0 + d1 * d1 + d2 * d2;
        /* immovable pair, or coincident particles: nothing to push along */
        if (wsum == 0 || len2 < (wb_real)1e-24) continue;
        const wb_real at = alpha[i] * inv_h2;
        /* compliance/h^2 overflowed: the limit is a constraint with no stiffness (it would
         * otherwise give inf * 0 = NaN below and undo the frame) */
        if (isinf(at)) continue;
        const wb_real len = sqrt(len2);
        wb_real num = rest[i] - len - at * lambda[i];
        wb_real den = wsum + at;
        if (damped) {
            /* gamma = alpha~ beta~ / h with beta~ = h^2 beta */
            const wb_real gamma = at * beta[i] * h;
            const wb_real *pa = &xp[3 * ia], *pc = &xp[3 * ic];
            const wb_real rel = ((xc[0] - pc[0]) - (xa[0] - pa[0])) * d0 + ((xc[1] - pc[1]) - (xa[1] - pa[1])) * d1 +
                                ((xc[2] - pc[2]) - (xa[2] - pa[2])) * d2;
            if (isinf(gamma)) {
                /* alpha~ beta h overflowed: the limit gamma -> inf of num/den, a correction
                 * that removes the relative velocity along d (inf * 0 would be NaN) */
                num = -rel / len;
                den = wsum;
            } else {
                num -= gamma * rel / len;
                den += gamma * wsum;
            }
        }
        /* s = dlambda / len, so the correction is s * d without normalising d */
        wb_real s = num / (den * len);
        if (jacobi) s *= omega * jac[i];
        lambda[i] += s * len;
        if (wa > 0) {
            wb_real *oa = &out[3 * ia];
            const wb_real f = wa * s;
            oa[0] -= f * d0; oa[1] -= f * d1; oa[2] -= f * d2;
        }
        if (wc > 0) {
            wb_real *oc = &out[3 * ic];
            const wb_real f = wc * s;
            oc[0] += f * d0; oc[1] += f * d1; oc[2] += f * d2;
        }
    }
}

static void project_distances(const wb_world *w, wb_real *dx, int32_t b, int32_t e, wb_real h, wb_real inv_h2)
{
    const wb_cache *k = &w->k;
    const wb_real *wv = w->m.w, *xp = w->s.x_prev, omega = w->m.def.relaxation;
    wb_real *x = w->s.x;
    if (dx) {
        if (k->any_damping) project_range(k, wv, x, xp, dx, b, e, h, inv_h2, omega, 1, 1);
        else project_range(k, wv, x, xp, dx, b, e, h, inv_h2, omega, 0, 1);
    } else {
        if (k->any_damping) project_range(k, wv, x, xp, x, b, e, h, inv_h2, omega, 1, 0);
        else project_range(k, wv, x, xp, x, b, e, h, inv_h2, omega, 0, 0);
    }
}

/* one pass over every batch; batches before serial_start are conflict-free */
typedef struct dist_job { wb_world *w; wb_real *dx; int32_t b; wb_real h, inv_h2; } dist_job;

static void dist_part(void *ctx, int32_t lo, int32_t hi)
{
    const dist_job *j = ctx;
    project_distances(j->w, j->dx, j->b + lo, j->b + hi, j->h, j->inv_h2);
}

static void project_batches(wb_world *w, wb_real *dx, wb_real h, wb_real inv_h2)
{
    wb_cache *k = &w->k;
    for (int32_t c = 0; c < k->ncolours; c++) {
        const int32_t b = k->colour_start[c], e = k->colour_start[c + 1];
        /* (the pool is asked for only here: a small scene never starts a thread) */
        wb_pool *pool = c < k->serial_start && e - b >= 512 ? wb__world_pool(w) : NULL;
        if (!pool) {
            project_distances(w, dx, b, e, h, inv_h2);
            continue;
        }
        /* split the batch into contiguous chunks on the pool: disjoint writes */
        dist_job j = { w, dx, b, h, inv_h2 };
        wb__pool_for(pool, e - b, 256, dist_part, &j);
    }
}

/* one iteration over every distance constraint */
static void distance_project(wb_world *w, wb_real h)
{
    wb_cache *k = &w->k;
    const wb_real inv_h2 = 1 / (h * h);
    const int32_t np = w->m.np;
    k->projections += k->ns;
    if (w->m.def.solver == WB_SOLVER_GAUSS_SEIDEL) {
        project_batches(w, NULL, h, inv_h2);
        return;
    }
    /* Jacobi: every correction from the same positions, scaled per constraint
     * (see project_range), then applied at once */
    if (np == 0) return;
    memset(k->dx, 0, sizeof(wb_real) * 3 * (size_t)np);
    project_batches(w, k->dx, h, inv_h2);
    const wb_real *wv = w->m.w;
    for (int32_t i = 0; i < np; i++)
        if (wv[i] > 0) v3_add(&w->s.x[3 * i], &w->s.x[3 * i], &k->dx[3 * i]);
}

static void distance_substep_begin(wb_world *w)
{
    if (w->k.ns > 0) memset(w->k.s_lambda, 0, sizeof(wb_real) * (size_t)w->k.ns);
}

static void report_break(wb_world *w, int32_t s)
{
    wb_cache *k = &w->k;
    w->s.d_broken[s] = 1;
    w->m.topology_dirty = 1;
    wb_distance_id id = { (uint32_t)s + 1, w->m.d_gen[s] };
    wb_distance_id *q = wb__grow(k->breaks, &k->cap_breaks, k->nbreaks + 1, sizeof *q);
    if (q) { k->breaks = q; k->breaks[k->nbreaks++] = id; }
}

/* plastic flow and breaking, once per frame on the frame's final lengths; break_force
 * on the multiplier of the frame's last substep (the force wb_distance_force reads) */
static void distance_frame_end(wb_world *w)
{
    wb_model *m = &w->m;
    wb_cache *k = &w->k;
    const wb_real dt = m->def.dt, inv_h2 = 1 / (k->h_last * k->h_last);
    for (int32_t i = 0; i < k->ns; i++) {
        const int32_t s = k->s_slot[i];
        if (m->d_break[s] <= 0 && m->d_yield[s] <= 0 && m->d_bforce[s] <= 0) continue;
        if (m->d_bforce[s] > 0 && fabs(k->s_lambda[i]) * inv_h2 > m->d_bforce[s]) {
            report_break(w, s);
            continue;
        }
        if (m->d_break[s] <= 0 && m->d_yield[s] <= 0) continue;
        wb_real d[3];
        v3_sub(d, &w->s.x[3 * k->s_b[i]], &w->s.x[3 * k->s_a[i]]);
        const wb_real len = v3_len(d), rest = k->s_rest[i];
        if (rest <= 0) continue;
        const wb_real strain = (len - rest) / rest;
        if (m->d_break[s] > 0 && strain > m->d_break[s]) {
            report_break(w, s);
            continue;
        }
        const wb_real a = fabs(strain), y = m->d_yield[s];
        if (y > 0 && a > y) {
            /* flow towards the current length by the part of the strain past yield */
            const wb_real rate = m->d_creep[s] * dt < 1 ? m->d_creep[s] * dt : 1;
            /* the part past yield, (a - y)/a; a rest so small that the strain overflows
             * (inf/inf = NaN would poison the rest for good) flows as if a were huge: 1 */
            const wb_real past = isinf(a) ? 1 : (a - y) / a;
            const wb_real r = rest + rate * (len - rest) * past;
            k->s_rest[i] = r;
            w->s.d_rest[s] = r;
        }
    }
}

/* elastic: U = C^2 / (2 alpha) for compliant constraints (alpha = 1/k) */
static wb_real distance_energy(const wb_world *w)
{
    wb_real pe = 0;
    for (int32_t s = 0; s < w->m.nd; s++) {
        if (!packable(w, s) || w->m.d_alpha[s] <= 0) continue;
        wb_real d[3];
        v3_sub(d, &w->s.x[3 * w->m.d_ij[2 * s + 1]], &w->s.x[3 * w->m.d_ij[2 * s]]);
        wb_real c = v3_len(d) - w->s.d_rest[s];
        pe += c * c / (2 * w->m.d_alpha[s]);
    }
    return pe;
}

static int32_t distance_count(const wb_world *w) { return w->m.nd_live; }

const wb_ctype wb__distance_type = {
    .name = "distance",
    .count = distance_count,
    .prepare = wb__colour,
    .substep_begin = distance_substep_begin,
    .project = distance_project,
    .frame_end = distance_frame_end,
    .energy = distance_energy,
};
