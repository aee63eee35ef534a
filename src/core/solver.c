/* solver.c: the step (Macklin et al. 2019, "Small steps in physics simulation").
 *
 * Per frame, `substeps` times: predict, project the constraints `iterations` times
 * (XPBD, Gauss-Seidel over colour batches or Jacobi), project collisions, update
 * velocities, then friction and restitution at velocity level. Plastic flow, breaking
 * and the finiteness check run once per frame. */
#include <stdio.h>
#include <time.h>

#include "core.h"

static double now_ms(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return ts.tv_sec * 1e3 + ts.tv_nsec * 1e-6;
}

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
static void project_batches(wb_world *w, wb_real *dx, wb_real h, wb_real inv_h2)
{
    wb_cache *k = &w->k;
    const int threads = w->m.def.threads;
    for (int32_t c = 0; c < k->ncolours; c++) {
        const int32_t b = k->colour_start[c], e = k->colour_start[c + 1];
        if (c >= k->serial_start || threads == 1 || e - b < 512) {
            project_distances(w, dx, b, e, h, inv_h2);
            continue;
        }
        /* split the batch into contiguous chunks, one per thread: disjoint writes */
        #pragma omp parallel for num_threads(threads) schedule(static)
        for (int t = 0; t < threads; t++) {
            const int32_t n = e - b;
            const int32_t lo = b + (int32_t)((int64_t)n * t / threads), hi = b + (int32_t)((int64_t)n * (t + 1) / threads);
            project_distances(w, dx, lo, hi, h, inv_h2);
        }
    }
}

static void solve_constraints(wb_world *w, wb_real h)
{
    wb_cache *k = &w->k;
    const wb_world_def *d = &w->m.def;
    const wb_real inv_h2 = 1 / (h * h);
    const int32_t np = w->m.np;
    for (int it = 0; it < d->iterations; it++) {
        if (d->solver == WB_SOLVER_GAUSS_SEIDEL) {
            project_batches(w, NULL, h, inv_h2);
            continue;
        }
        /* Jacobi: every correction from the same positions, scaled per constraint
         * (see project_range), then applied at once */
        if (np == 0) break;
        memset(k->dx, 0, sizeof(wb_real) * 3 * (size_t)np);
        project_batches(w, k->dx, h, inv_h2);
        const wb_real *wv = w->m.w;
        for (int32_t i = 0; i < np; i++)
            if (wv[i] > 0) v3_add(&w->s.x[3 * i], &w->s.x[3 * i], &k->dx[3 * i]);
    }
    k->projections += (int64_t)k->ns * d->iterations;
}

static void predict(wb_world *w, wb_real h)
{
    const wb_world_def *d = &w->m.def;
    const wb_real keep = d->damping > 0 ? (d->damping * h < 1 ? 1 - d->damping * h : 0) : 1;
    const wb_real g0 = d->gravity[0] * h, g1 = d->gravity[1] * h, g2 = d->gravity[2] * h;
    wb_real *restrict x = w->s.x, *restrict xp = w->s.x_prev, *restrict v = w->s.v;
    const wb_real *restrict wv = w->m.w;
    for (int32_t i = 0; i < w->m.np; i++) {
        wb_real *xi = &x[3 * i], *vi = &v[3 * i];
        v3_copy(&xp[3 * i], xi);
        if (wv[i] == 0) continue;
        /* drag on the velocity only: a body at rest still weighs m g */
        vi[0] = vi[0] * keep + g0; vi[1] = vi[1] * keep + g1; vi[2] = vi[2] * keep + g2;
        xi[0] += h * vi[0]; xi[1] += h * vi[1]; xi[2] += h * vi[2];
    }
}


/* plastic flow and breaking, once per frame on the frame's final lengths */
static void plasticity_and_breaking(wb_world *w)
{
    wb_model *m = &w->m;
    wb_cache *k = &w->k;
    const wb_real dt = m->def.dt;
    for (int32_t i = 0; i < k->ns; i++) {
        const int32_t s = k->s_slot[i];
        if (m->d_break[s] <= 0 && m->d_yield[s] <= 0) continue;
        wb_real d[3];
        v3_sub(d, &w->s.x[3 * k->s_b[i]], &w->s.x[3 * k->s_a[i]]);
        const wb_real len = v3_len(d), rest = k->s_rest[i];
        if (rest <= 0) continue;
        const wb_real strain = (len - rest) / rest;
        if (m->d_break[s] > 0 && strain > m->d_break[s]) {
            w->s.d_broken[s] = 1;
            m->topology_dirty = 1;
            wb_distance_id id = { (uint32_t)s + 1, m->d_gen[s] };
            wb_distance_id *q = wb__grow(k->breaks, &k->cap_breaks, k->nbreaks + 1, sizeof *q);
            if (q) { k->breaks = q; k->breaks[k->nbreaks++] = id; }
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

/* put the particles back as they were at the frame's start; the multipliers of the
 * abandoned frame mean nothing (and may be NaN): force() reads 0 until the next step */
static void undo_particles(wb_world *w)
{
    const size_t n = 3 * (size_t)w->m.np;
    if (n > 0) {
        memcpy(w->s.x, w->k.x_save, sizeof(wb_real) * n);
        memcpy(w->s.x_prev, w->k.x_save, sizeof(wb_real) * n);
        memcpy(w->s.v, w->k.v_save, sizeof(wb_real) * n);
    }
    if (w->k.ns > 0) memset(w->k.s_lambda, 0, sizeof(wb_real) * (size_t)w->k.ns);
}

/* the colliders' poses at the frame's start, before their velocities move them */
static int save_colliders(wb_world *w)
{
    wb_cache *k = &w->k;
    wb_real *c = wb__grow(k->c_save, &k->cap_c_save, 7 * (w->m.nc > 0 ? w->m.nc : 1), sizeof *c);
    if (!c) return 0;
    k->c_save = c;
    for (int32_t i = 0; i < w->m.nc; i++) {
        v3_copy(&c[7 * i], w->s.c_pose[i].p);
        memcpy(&c[7 * i + 3], w->s.c_pose[i].q, 4 * sizeof(wb_real));
    }
    return 1;
}

static void restore_collider(wb_world *w, int32_t i)
{
    wb_collider_pose *cp = &w->s.c_pose[i];
    v3_copy(cp->p, &w->k.c_save[7 * i]);
    memcpy(cp->q, &w->k.c_save[7 * i + 3], 4 * sizeof(wb_real));
}

/* non-finite values never propagate: a particle gone non-finite undoes the frame's
 * particles; a collider driven to a non-finite pose (absurd velocities) goes back and
 * stops. Returns 1 when the particles were finite. Time still advances: kinematic
 * colliders keep their script's schedule. */
static int check_finite(wb_world *w)
{
    for (int32_t c = 0; c < w->m.nc; c++) {
        wb_collider_pose *cp = &w->s.c_pose[c];
        if (!(w->m.c_gen[c] & 1u)) continue;
        if (isfinite(cp->p[0]) && isfinite(cp->p[1]) && isfinite(cp->p[2]) && isfinite(cp->q[0]) &&
            isfinite(cp->q[1]) && isfinite(cp->q[2]) && isfinite(cp->q[3]))
            continue;
        wb__warn(w, "frame %lld: collider %d moved to a non-finite pose; it was put back and its "
                    "velocities set to zero", (long long)w->s.frame + 1, c + 1);
        restore_collider(w, c);
        v3_set(cp->v, 0, 0, 0);
        v3_set(cp->om, 0, 0, 0);
    }
    const int32_t n = 3 * w->m.np;
    const wb_real *x = w->s.x, *v = w->s.v;
    for (int32_t i = 0; i < n; i++) {
        if (isfinite(x[i]) && isfinite(v[i])) continue;
        wb__warn(w, "frame %lld: particle %d became non-finite; its frame was undone (reduce dt, "
                    "raise substeps or compliance)", (long long)w->s.frame + 1, i / 3 + 1);
        undo_particles(w);
        return 0;
    }
    return 1;
}

wb_status wb_world_step(wb_world *w)
{
    const double t_begin = now_ms();
    wb_cache *k = &w->k;
    if (wb__colour(w) != WB_OK || !save_colliders(w)) {
        wb__warn(w, "frame %lld: out of memory preparing the step; frame skipped", (long long)w->s.frame + 1);
        return WB_ERR_NOMEM;
    }
    const wb_world_def *d = &w->m.def;
    const wb_real dt = d->dt, h = dt / d->substeps;
    const int32_t np = w->m.np;
    if (np > 0) { /* (memcpy from a NULL array of an empty world is undefined) */
        memcpy(k->x_save, w->s.x, sizeof(wb_real) * 3 * (size_t)np);
        memcpy(k->v_save, w->s.v, sizeof(wb_real) * 3 * (size_t)np);
    }
    k->nbreaks = 0;
    k->projections = 0;
    k->h_last = h;

    /* kinematic colliders: where the script's velocities take them by the frame's end */
    for (int32_t c = 0; c < w->m.nc; c++) {
        if (!(w->m.c_gen[c] & 1u)) continue;
        wb_collider_pose *cp = &w->s.c_pose[c];
        v3_madd(cp->p, cp->v, dt);
        q_integrate(cp->q, cp->om, dt, cp->q);
    }

    wb__contacts_begin(w);
    wb__tricontacts_begin(w);
    double solve = 0;
    for (int sub = 0; sub < d->substeps; sub++) {
        if (k->interrupt && k->interrupt(k->interrupt_ud)) {
            /* abandoned: the world is left as the frame found it */
            undo_particles(w);
            for (int32_t c = 0; c < w->m.nc; c++) restore_collider(w, c);
            k->step_ms = now_ms() - t_begin;
            return WB_ERR_INTERRUPTED;
        }
        predict(w, h);
        double t0 = now_ms();
        if (k->ns > 0) memset(k->s_lambda, 0, sizeof(wb_real) * (size_t)k->ns);
        solve_constraints(w, h);
        solve += now_ms() - t0;
        wb__contacts_project(w, h);
        wb__tricontacts_project(w, h);
        wb__collide_and_update(w, h, (wb_real)sub / d->substeps, (wb_real)(sub + 1) / d->substeps);
        wb__contacts_velocity(w, h);
        wb__tricontacts_velocity(w, h);
    }

    /* a frame gone non-finite is undone before it can bend or break anything */
    if (check_finite(w)) plasticity_and_breaking(w);
    for (int32_t c = 0; c < w->m.nc; c++) {
        wb_collider_pose *cp = &w->s.c_pose[c];
        v3_copy(cp->p0, cp->p);
        memcpy(cp->q0, cp->q, sizeof cp->q);
    }
    w->s.frame++;
    w->s.time += dt;
    k->solve_ms = solve;
    k->step_ms = now_ms() - t_begin;
    return WB_OK;
}
