/* shape_match.c: meshless shape matching (Müller, Heidelberger, Teschner, Gross 2005) of
 * particle clusters, as an XPBD constraint type, with plastic flow of the rest shape.
 *
 * A cluster keeps its particles' rest positions r_i about the rest mass centre
 * (sum m_i r_i = 0). Each projection finds the current mass centre c and the rotation R
 * that best maps the rest shape onto the current one: the rotational part of
 * A_pq = sum m_i (x_i - c) r_i^T, extracted with Müller et al. 2016 (skin.c's
 * wb_extract_rotation, warm-started from the last projection's). Goals are g_i = c + R r_i.
 * Since sum m_i (g_i - x_i) = R sum m_i r_i = 0, moving every particle by the same
 * fraction of its distance to its goal keeps the momentum (and, R being the polar
 * rotation, the angular momentum).
 *
 * Stiffness. Müller et al. move particles by a fraction `s` of (g - x) once per time step,
 * which makes the material depend on the step: more substeps would make it stiffer. Here
 * each particle is tied to its goal by an XPBD zero-length spring, C_i = x_i - g_i with
 * compliance alpha_i = 1 / (m_i kappa) (so kappa = stiffness / mass, 1/s^2, the same
 * for every particle: a uniform natural frequency sqrt(kappa)), and kappa is chosen so
 * that one projection of a 1/60 s step removes exactly the fraction s:
 *     kappa h^2 / (1 + kappa h^2) = s at h = 1/60 s   <=>   kappa = s / ((1 - s) (1/60 s)^2)
 * At any substep h the projection then removes kappa h^2 / (1 + kappa h^2) (one iteration;
 * the multiplier carries the rest over iterations), which is the same spring, so the
 * material does not change with substeps, iterations or dt (to the XPBD discretisation
 * error, O(h)). stiffness 1 is rigid (the goals exactly), 0 no pull at all.
 *
 * Plasticity (the reference thesis's plastic deformation on impact, for whole bodies):
 * once per frame, the strain e = sqrt(sum m |x - g|^2 / sum m |r|^2) (the RMS distance
 * to the goals over the RMS rest radius, a dimensionless measure of how far the cluster
 * is from a rigid motion of its rest shape) is compared with `yield`; past it, the rest
 * shape flows towards the deformed one seen in the rest frame, R^T (x_i - c), by the
 * part of the strain past yield at min(1, creep dt) per frame (as distance links do,
 * solver.c), and is re-centred.
 *
 * Clusters are projected one after another, serially, in creation order: deterministic for
 * any thread count. Why not in parallel, as the batched types are (their batches are free
 * of write conflicts): a projection is two reductions over the cluster (mass centre, A_pq)
 * and one per-particle update, ~75 ns a particle; measured on a 20^3 lattice (8000
 * particles, 10 substeps, -O3), one cluster over all of it costs 6 ms of a 42 ms frame
 * whose links (already parallel) take the rest, and eight 1000-particle clusters the same.
 * Two threads would save at most ~3 ms there (7%), less in the usual scenes (a few
 * clusters of tens to hundreds of particles: well under 1%), and a parallel version must
 * make its reductions thread-count independent (fixed chunks summed in a fixed order) and
 * colour the clusters by shared particles; not worth its code today. Revisit if a scene is
 * dominated by shape matching (many large clusters). */
#include <assert.h>
#include <stdlib.h>

#include "core.h"
#include "ctype.h"
#include "shape_match.h"
#include "snapshot.h"

#define H_REF ((wb_real)1 / 60)  /* the step at which `stiffness` is the fraction removed */
#define ROT_ITER 20              /* rotation-extraction steps per fit (warm: one or two) */
#define BYTES_CLUSTER (4 + 11 * sizeof(wb_real))
#define BYTES_ID (4 + 6 * sizeof(wb_real))

/* w->sm for reading: an empty one while there is none */
static const wb_smatch no_clusters;
#define SM(w) ((w)->sm ? (w)->sm : &no_clusters)

/* room for n_extra more clusters of ids_extra particles in all; after it, adding them
 * cannot fail */
static wb_status reserve(wb_world *w, int64_t n_extra, int64_t ids_extra)
{
    if (!w->sm) {
        if (n_extra <= 0 && ids_extra <= 0) return WB_OK;
        if (!(w->sm = calloc(1, sizeof *w->sm))) return WB_ERR_NOMEM;
    }
    wb_smatch *sm = w->sm;
    const int64_t nc = sm->n + n_extra, ni = sm->nids + ids_extra;
    if (nc + 1 > WB_MAX_CONSTRAINTS || ni > WB_MAX_CONSTRAINTS) return WB_ERR_LIMIT;
    if (nc + 1 <= sm->cap && ni <= sm->cap_ids) return WB_OK;
    const int32_t cc = nc + 1 <= sm->cap ? sm->cap : wb__grown_cap(sm->cap, nc + 1, 16);
    const int32_t ci = ni <= sm->cap_ids ? sm->cap_ids : wb__grown_cap(sm->cap_ids, ni, 16);
    if (!wb__charge(w, &sm->charged, (size_t)cc * BYTES_CLUSTER + (size_t)ci * BYTES_ID)) return WB_ERR_NOMEM;
    const wb_soa clusters[] = {
        { (void **)&sm->start, sizeof(int32_t) }, { (void **)&sm->stiff, sizeof(wb_real) },
        { (void **)&sm->yield, sizeof(wb_real) }, { (void **)&sm->creep, sizeof(wb_real) },
        { (void **)&sm->q, 4 * sizeof(wb_real) }, { (void **)&sm->qk, 4 * sizeof(wb_real) },
    };
    const wb_soa ids[] = {
        { (void **)&sm->ids, sizeof(int32_t) }, { (void **)&sm->rest, 3 * sizeof(wb_real) },
        { (void **)&sm->lambda, 3 * sizeof(wb_real) },
    };
    if (WB_SOA_RESIZE(clusters, cc) != WB_OK || WB_SOA_RESIZE(ids, ci) != WB_OK) return WB_ERR_NOMEM;
    if (sm->cap == 0) sm->start[0] = 0;
    sm->cap = cc;
    sm->cap_ids = ci;
    return WB_OK;
}

/* ---- the fit ------------------------------------------------------------------------------ */
/* mass centre c of cluster k's particles at x and the rotation q (warm start in, fit out)
 * of its rest shape onto them; particles without mass (inv_mass 0) take no part */
static void fit_at(const wb_world *w, int32_t k, const wb_real *x, wb_real q[4], wb_real c[3])
{
    const wb_smatch *sm = SM(w);
    const wb_real *im = w->m.inv_mass;
    wb_real M = 0, A[9] = { 0 };
    v3_set(c, 0, 0, 0);
    for (int32_t j = sm->start[k]; j < sm->start[k + 1]; j++) {
        const int32_t i = sm->ids[j];
        if (im[i] <= 0) continue;
        const wb_real m = 1 / im[i];
        M += m;
        v3_madd(c, &x[3 * i], m);
    }
    v3_scale(c, c, 1 / M);
    for (int32_t j = sm->start[k]; j < sm->start[k + 1]; j++) {
        const int32_t i = sm->ids[j];
        if (im[i] <= 0) continue;
        const wb_real m = 1 / im[i], *r = &sm->rest[3 * j];
        wb_real p[3];
        v3_sub(p, &x[3 * i], c);
        for (int a = 0; a < 3; a++)
            for (int b = 0; b < 3; b++) A[3 * a + b] += m * p[a] * r[b];
    }
    wb_extract_rotation(A, q, ROT_ITER);
}

static void fit(const wb_world *w, int32_t k, wb_real q[4], wb_real c[3]) { fit_at(w, k, w->s.x, q, c); }

static void goal(const wb_real R[9], const wb_real c[3], const wb_real r[3], wb_real g[3])
{
    for (int a = 0; a < 3; a++) g[a] = c[a] + R[3 * a] * r[0] + R[3 * a + 1] * r[1] + R[3 * a + 2] * r[2];
}

/* sum m |x - g|^2 and sum m |r|^2 over cluster k for the fit (q, c) */
static void deviation(const wb_world *w, int32_t k, const wb_real q[4], const wb_real c[3], wb_real *dev, wb_real *size)
{
    const wb_smatch *sm = SM(w);
    const wb_real *im = w->m.inv_mass;
    wb_real R[9];
    wb_quat_to_matrix(q, R);
    *dev = *size = 0;
    for (int32_t j = sm->start[k]; j < sm->start[k + 1]; j++) {
        const int32_t i = sm->ids[j];
        if (im[i] <= 0) continue;
        const wb_real m = 1 / im[i], *r = &sm->rest[3 * j];
        wb_real g[3], d[3];
        goal(R, c, r, g);
        v3_sub(d, &w->s.x[3 * i], g);
        *dev += m * v3_dot(d, d);
        *size += m * v3_dot(r, r);
    }
}

/* ---- the type ------------------------------------------------------------------------------- */
static int32_t sm_count(const wb_world *w) { return SM(w)->n; }

static wb_status sm_prepare(wb_world *w)
{
    wb_smatch *sm = w->sm;
    if (!sm) return WB_OK;
    if (sm->n > 0) memcpy(sm->qk, sm->q, 4 * sizeof(wb_real) * (size_t)sm->n);
    return WB_OK;
}

/* A rigid cluster (stiffness 1) leaves each substep rigid but for what the contacts after
 * it moved (the collisions are the substep's last pass): the ground pushes the particles
 * it meets, and only those. Fitted again from there, the cluster would spread that push
 * over itself as speed while moving those particles back into the ground by the rest,
 * which the ground then pushes out again as a new collision: every push counted twice. A
 * cube of 5^3 particles dropped flat at 4.3 m/s on a floor of restitution 0 rebounded at
 * 1.7 m/s, and landing on an edge it sprang off it spinning and was thrown 0.6 m (a rigid
 * body of its shape: 0.07 m). So at the substep's start a rigid cluster is fitted to where
 * the last one left it and put there, x and x_prev moved alike: the contacts' pushes
 * become the whole cluster's move, with no speed; what that puts back into the ground is
 * an overlap the substep begins with, which the collisions take out with x_prev too.
 * Velocities (x - x_prev) do not change, so neither do momentum and angular momentum.
 * A compliant cluster's deformation is its elastic state: it keeps it. */
static void sm_substep_begin(wb_world *w)
{
    wb_smatch *sm = w->sm;
    if (!sm) return;
    if (sm->nids > 0) memset(sm->lambda, 0, 3 * sizeof(wb_real) * (size_t)sm->nids);
    const wb_real *wv = w->m.w;
    wb_real *x = w->s.x, *xp = w->s.x_prev;
    for (int32_t k = 0; k < sm->n; k++) {
        if (!(sm->stiff[k] >= 1)) continue;
        wb_real c[3], R[9], *q = &sm->qk[4 * k];
        fit_at(w, k, xp, q, c);
        wb_quat_to_matrix(q, R);
        for (int32_t j = sm->start[k]; j < sm->start[k + 1]; j++) {
            const int32_t i = sm->ids[j];
            if (wv[i] == 0) continue;
            wb_real g[3], d[3];
            goal(R, c, &sm->rest[3 * j], g);
            v3_sub(d, g, &xp[3 * i]);
            v3_add(&xp[3 * i], &xp[3 * i], d);
            v3_add(&x[3 * i], &x[3 * i], d);
        }
    }
}

/* kappa h^2 of a cluster of stiffness s (0 for a rigid one, s >= 1): the XPBD spring per
 * particle that removes the fraction s of the distance to the goal per H_REF */
static wb_real kappa_h2(wb_real s, wb_real h) { return s >= 1 ? 0 : s / (1 - s) * (h * h) / (H_REF * H_REF); }

static void sm_project(wb_world *w, wb_real h)
{
    wb_smatch *sm = w->sm;
    if (!sm) return;
    const wb_real *wv = w->m.w, *im = w->m.inv_mass;
    wb_real *x = w->s.x;
    w->k.projections += sm->n;   /* a cluster is one projection */
    for (int32_t k = 0; k < sm->n; k++) {
        const wb_real s = sm->stiff[k];
        if (s <= 0) continue;
        const int hard = s >= 1;
        const wb_real kh2 = kappa_h2(s, h);
        wb_real c[3], R[9], *q = &sm->qk[4 * k];
        fit(w, k, q, c);
        wb_quat_to_matrix(q, R);
        /* every goal from the same fit, then the moves */
        for (int32_t j = sm->start[k]; j < sm->start[k + 1]; j++) {
            const int32_t i = sm->ids[j];
            const wb_real wi = wv[i];
            if (wi == 0) continue; /* immovable or pinned: never written */
            wb_real g[3], *xi = &x[3 * i];
            goal(R, c, &sm->rest[3 * j], g);
            if (hard) {
                v3_copy(xi, g);
                continue;
            }
            /* XPBD per coordinate (the gradient of x - g is the identity), alpha~ =
             * inv_mass / (kappa h^2) */
            const wb_real at = im[i] / kh2;
            wb_real *lam = &sm->lambda[3 * j];
            for (int a = 0; a < 3; a++) {
                const wb_real dl = (g[a] - xi[a] - at * lam[a]) / (wi + at);
                lam[a] += dl;
                xi[a] += wi * dl;
            }
        }
    }
}

static void sm_frame_end(wb_world *w)
{
    wb_smatch *sm = w->sm;
    if (!sm) return;
    const wb_real dt = w->m.def.dt, *im = w->m.inv_mass;
    for (int32_t k = 0; k < sm->n; k++) {
        wb_real *q = &sm->q[4 * k];
        memcpy(q, &sm->qk[4 * k], 4 * sizeof(wb_real));
        const wb_real y = sm->yield[k];
        if (y <= 0 || sm->creep[k] <= 0) continue;
        wb_real c[3], dev, size;
        fit(w, k, q, c);
        deviation(w, k, q, c, &dev, &size);
        if (!(size > 0)) continue;
        const wb_real e = sqrt(dev / size);
        if (!(e > y) || !isfinite(e)) continue;
        const wb_real rate = sm->creep[k] * dt < 1 ? sm->creep[k] * dt : 1, f = rate * (e - y) / e;
        wb_real R[9], mean[3] = { 0, 0, 0 }, M = 0;
        wb_quat_to_matrix(q, R);
        for (int32_t j = sm->start[k]; j < sm->start[k + 1]; j++) {
            const int32_t i = sm->ids[j];
            wb_real p[3], d[3], *r = &sm->rest[3 * j];
            v3_sub(p, &w->s.x[3 * i], c);
            /* the deformed shape in the rest frame: R^T (x - c) */
            for (int a = 0; a < 3; a++) d[a] = R[a] * p[0] + R[3 + a] * p[1] + R[6 + a] * p[2] - r[a];
            v3_madd(r, d, f);
            if (im[i] > 0) {
                v3_madd(mean, r, 1 / im[i]);
                M += 1 / im[i];
            }
        }
        /* about the mass centre again (it is already, up to rounding): momentum */
        v3_scale(mean, mean, 1 / M);
        for (int32_t j = sm->start[k]; j < sm->start[k + 1]; j++) v3_sub(&sm->rest[3 * j], &sm->rest[3 * j], mean);
    }
}

/* U = sum 1/2 m kappa |x - g|^2 over the compliant clusters (rigid ones store none) */
/* each member's distance from its goal (less what its compliance allows), the goals from
 * a fit of the positions as they are (from a copy of the cluster's rotation) */
static wb_real sm_residual(const wb_world *w, wb_real h)
{
    const wb_smatch *sm = SM(w);
    const wb_real *x = w->s.x, *wv = w->m.w, *im = w->m.inv_mass;
    wb_real r = 0;
    for (int32_t k = 0; k < sm->n; k++) {
        const wb_real s = sm->stiff[k];
        if (s <= 0) continue;
        const wb_real kh2 = kappa_h2(s, h);
        wb_real q[4], c[3], R[9];
        memcpy(q, &sm->qk[4 * k], sizeof q);
        fit(w, k, q, c);
        wb_quat_to_matrix(q, R);
        for (int32_t j = sm->start[k]; j < sm->start[k + 1]; j++) {
            const int32_t i = sm->ids[j];
            if (wv[i] == 0) continue;
            wb_real g[3], d[3];
            goal(R, c, &sm->rest[3 * j], g);
            v3_sub(d, &x[3 * i], g);
            if (kh2 > 0) v3_madd(d, &sm->lambda[3 * j], im[i] / kh2); /* C = x - g */
            const wb_real ri = v3_len(d);
            r = ri > r ? ri : r;
        }
    }
    return r;
}

static wb_real sm_energy(const wb_world *w)
{
    const wb_smatch *sm = SM(w);
    wb_real u = 0;
    for (int32_t k = 0; k < sm->n; k++) {
        const wb_real s = sm->stiff[k];
        if (s <= 0 || s >= 1) continue;
        wb_real q[4], c[3], dev, size;
        memcpy(q, &sm->q[4 * k], sizeof q);
        fit(w, k, q, c);
        deviation(w, k, q, c, &dev, &size);
        u += (wb_real)0.5 * s / ((1 - s) * H_REF * H_REF) * dev;
    }
    return u;
}

/* a cluster is one graph (its particles keep their rest shape, so only pairs made
 * overlapping could touch, and the rest rule takes those): a chain through it */
static void sm_links(const wb_world *w, wb_link_fn fn, void *ud)
{
    const wb_smatch *sm = SM(w);
    for (int32_t c = 0; c < sm->n; c++)
        for (int32_t i = sm->start[c] + 1; i < sm->start[c + 1]; i++) fn(ud, sm->ids[i - 1], sm->ids[i], 0);
}

/* a cluster is one body */
static void sm_joins(const wb_world *w, wb_link_fn fn, void *ud)
{
    const wb_smatch *sm = SM(w);
    for (int32_t c = 0; c < sm->n; c++) wb__join_elements(&sm->ids[sm->start[c]], 1, sm->start[c + 1] - sm->start[c], fn, ud);
}


/* ---- API ------------------------------------------------------------------------------------ */
wb_shape_match_def wb_shape_match_default_def(void)
{
    wb_shape_match_def d = { 1, 0, 0 };
    return d;
}

/* the options' rules: the one place they are decided (the binding and the JSON reader
 * print what this finds; the cluster's particles are wb_shape_match_add's to judge) */
wb_fault wb_shape_match_def_fault(const wb_shape_match_def *d)
{
    if (!(d->stiffness >= 0 && d->stiffness <= 1)) return WB_FAULT_KEY("stiffness", "must be in [0, 1]");
    if (!(d->yield >= 0) || !isfinite(d->yield)) return WB_FAULT_KEY("yield", "must be >= 0");
    if (!(d->creep >= 0) || !isfinite(d->creep)) return WB_FAULT_KEY("creep", "must be >= 0");
    return WB_NO_FAULT;
}

const char *wb_shape_match_def_check(const wb_shape_match_def *d)
{
    return wb_shape_match_def_fault(d).msg;
}

static int cmp_i32(const void *a, const void *b)
{
    const int32_t x = *(const int32_t *)a, y = *(const int32_t *)b;
    return (x > y) - (x < y);
}

/* what is wrong with ids[0..n) as a cluster of a world of np particles with inverse
 * masses im, or NULL; scratch holds n ints */
static const char *check_ids(const int32_t *ids, int32_t n, int32_t np, const wb_real *im, int32_t *scratch)
{
    if (n < 2) return "a cluster needs at least 2 particles";
    int some_mass = 0;
    for (int32_t j = 0; j < n; j++) {
        if (ids[j] < 0 || ids[j] >= np) return "particle out of range";
        some_mass |= im[ids[j]] > 0;
    }
    if (!some_mass) return "a cluster needs a particle with mass (all are immovable)";
    memcpy(scratch, ids, sizeof *ids * (size_t)n);
    qsort(scratch, (size_t)n, sizeof *scratch, cmp_i32);
    for (int32_t j = 1; j < n; j++)
        if (scratch[j] == scratch[j - 1]) return "a cluster lists a particle twice";
    return NULL;
}

int32_t wb_shape_match_add(wb_world *w, const int32_t *ids, int32_t n, const wb_shape_match_def *def)
{
    const char *err = wb_shape_match_def_check(def);
    if (err) { wb__set_error("%s", err); return WB_ERR_ARG; }
    if (n > WB_MAX_PARTICLES) return WB_ERR_LIMIT;
    int32_t *scratch = malloc(sizeof *scratch * (size_t)(n > 0 ? n : 1));
    if (!scratch) return WB_ERR_NOMEM;
    err = check_ids(ids, n, w->m.np, w->m.inv_mass, scratch);
    free(scratch);
    if (err) { wb__set_error("%s", err); return WB_ERR_ARG; }
    /* the rest shape about the mass centre must be finite (particles 1e300 apart are not) */
    const wb_real *x = w->s.x, *im = w->m.inv_mass;
    wb_real c[3] = { 0, 0, 0 }, M = 0;
    for (int32_t j = 0; j < n; j++)
        if (im[ids[j]] > 0) { v3_madd(c, &x[3 * ids[j]], 1 / im[ids[j]]); M += 1 / im[ids[j]]; }
    v3_scale(c, c, 1 / M);
    for (int32_t j = 0; j < n; j++) {
        wb_real r[3];
        v3_sub(r, &x[3 * ids[j]], c);
        if (!isfinite(v3_dot(r, r)) || !isfinite(M)) { wb__set_error("the particles are too far apart (the rest shape overflows)"); return WB_ERR_ARG; }
    }
    wb_status st = reserve(w, 1, n);
    if (st != WB_OK) return st;
    wb_smatch *sm = w->sm;
    const int32_t k = sm->n++, first = sm->nids;
    sm->nids += n;
    sm->start[k + 1] = sm->nids;
    sm->stiff[k] = def->stiffness;
    sm->yield[k] = def->yield;
    sm->creep[k] = def->creep;
    wb_real *q = &sm->q[4 * k];
    q[0] = 1; q[1] = q[2] = q[3] = 0;
    for (int32_t j = 0; j < n; j++) {
        sm->ids[first + j] = ids[j];
        v3_sub(&sm->rest[3 * (first + j)], &x[3 * ids[j]], c);
    }
    return k;
}

int32_t wb_shape_match_count(const wb_world *w) { return SM(w)->n; }

#define CHECK_S(w, s) assert((s) >= 0 && (s) < wb_shape_match_count(w))

wb_shape_match_def wb_shape_match_get_def(const wb_world *w, int32_t s)
{
    CHECK_S(w, s);
    wb_shape_match_def d = { w->sm->stiff[s], w->sm->yield[s], w->sm->creep[s] };
    return d;
}

int32_t wb_shape_match_size(const wb_world *w, int32_t s) { CHECK_S(w, s); return w->sm->start[s + 1] - w->sm->start[s]; }

int32_t wb_shape_match_particle(const wb_world *w, int32_t s, int32_t i)
{
    assert(i >= 0 && i < wb_shape_match_size(w, s));
    return w->sm->ids[w->sm->start[s] + i];
}

void wb_shape_match_rest(const wb_world *w, int32_t s, int32_t i, wb_real out[3])
{
    assert(i >= 0 && i < wb_shape_match_size(w, s));
    v3_copy(out, &w->sm->rest[3 * (w->sm->start[s] + i)]);
}

wb_real wb_shape_match_strain(const wb_world *w, int32_t s)
{
    CHECK_S(w, s);
    wb_real q[4], c[3], dev, size;
    memcpy(q, &w->sm->q[4 * s], sizeof q);
    fit(w, s, q, c);
    deviation(w, s, q, c, &dev, &size);
    return size > 0 ? sqrt(dev / size) : 0;
}

/* ---- snapshots -------------------------------------------------------------------------------- */
static void sm_image_free(wb_image *g);

wb_status wb_image_alloc_smatch(wb_image *g, int32_t n, int32_t nids)
{
    wb_image_smatch *s = &g->sm;
    s->n = n;
    s->nids = nids;
    s->start = calloc((size_t)n + 1, sizeof *s->start);
    s->ids = calloc((size_t)(nids > 0 ? nids : 1), sizeof *s->ids);
    s->stiff = calloc((size_t)(n > 0 ? n : 1), sizeof(wb_real));
    s->yield = calloc((size_t)(n > 0 ? n : 1), sizeof(wb_real));
    s->creep = calloc((size_t)(n > 0 ? n : 1), sizeof(wb_real));
    s->rest = calloc(3 * (size_t)(nids > 0 ? nids : 1), sizeof(wb_real));
    s->q = calloc(4 * (size_t)(n > 0 ? n : 1), sizeof(wb_real));
    if (!s->start || !s->ids || !s->stiff || !s->yield || !s->creep || !s->rest || !s->q) {
        sm_image_free(g);
        return WB_ERR_NOMEM;
    }
    for (int32_t k = 0; k < n; k++) s->q[4 * k] = 1;
    return WB_OK;
}

static void sm_image_free(wb_image *g)
{
    wb_image_smatch *s = &g->sm;
    void *p[] = { s->start, s->ids, s->stiff, s->yield, s->creep, s->rest, s->q };
    for (size_t i = 0; i < sizeof p / sizeof p[0]; i++) free(p[i]);
    memset(s, 0, sizeof *s);
}

static wb_status sm_image_save(const wb_world *w, wb_image *g)
{
    const wb_smatch *sm = SM(w);
    if (sm->n == 0) return WB_OK;
    wb_status st = wb_image_alloc_smatch(g, sm->n, sm->nids);
    if (st != WB_OK) return st;
    const size_t n = (size_t)sm->n, ni = (size_t)sm->nids;
    memcpy(g->sm.start, sm->start, (n + 1) * sizeof(int32_t));
    memcpy(g->sm.ids, sm->ids, ni * sizeof(int32_t));
    memcpy(g->sm.stiff, sm->stiff, n * sizeof(wb_real));
    memcpy(g->sm.yield, sm->yield, n * sizeof(wb_real));
    memcpy(g->sm.creep, sm->creep, n * sizeof(wb_real));
    memcpy(g->sm.rest, sm->rest, 3 * ni * sizeof(wb_real));
    memcpy(g->sm.q, sm->q, 4 * n * sizeof(wb_real));
    return WB_OK;
}

static const char *sm_image_check(const wb_image *g)
{
    const wb_image_smatch *s = &g->sm;
    if (s->n < 0 || s->nids < 0 || s->n > WB_MAX_CONSTRAINTS || s->nids > WB_MAX_CONSTRAINTS) return "too many shape-matching clusters";
    if (s->n == 0) return s->nids ? "shape-matching particles without a cluster" : NULL;
    if (s->start[0] != 0 || s->start[s->n] != s->nids) return "shape-matching ranges do not cover the particles";
    int32_t most = 0;
    for (int32_t k = 0; k < s->n; k++) {
        if (s->start[k + 1] < s->start[k]) return "shape-matching ranges are not in order";
        if (s->start[k + 1] - s->start[k] > most) most = s->start[k + 1] - s->start[k];
        wb_shape_match_def d = { s->stiff[k], s->yield[k], s->creep[k] };
        const char *e = wb_shape_match_def_check(&d);
        if (e) return e;
        const wb_real *q = &s->q[4 * k];
        if (!isfinite(q[0]) || !isfinite(q[1]) || !isfinite(q[2]) || !isfinite(q[3]) ||
            !(q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3] > 1e-24))
            return "a shape-matching rotation must be finite and not zero";
    }
    for (int64_t j = 0; j < 3 * (int64_t)s->nids; j++)
        if (!isfinite(s->rest[j]) || !isfinite(s->rest[j] * s->rest[j])) return "a shape-matching rest position must be finite (below 1e154)";
    int32_t *scratch = malloc(sizeof *scratch * (size_t)(most > 0 ? most : 1));
    if (!scratch) return "out of memory checking the shape-matching clusters";
    const char *e = NULL;
    for (int32_t k = 0; k < s->n && !e; k++)
        e = check_ids(&s->ids[s->start[k]], s->start[k + 1] - s->start[k], g->np, g->inv_mass, scratch);
    free(scratch);
    return e;
}

static wb_status sm_image_reserve(wb_world *w, const wb_image *g, const wb_image_at *at)
{
    (void)at;
    return reserve(w, g->sm.n, g->sm.nids);
}

static void sm_image_put(wb_world *w, const wb_image *g, const wb_image_at *at)
{
    const int32_t pshift = at->pshift;
    wb_smatch *sm = w->sm;
    const wb_image_smatch *s = &g->sm;
    if (s->n == 0) return; /* (then it has no particles either: checked) */
    for (int32_t k = 0; k < s->n; k++) {
        const int32_t c = sm->n + k;
        sm->start[c + 1] = sm->nids + s->start[k + 1];
        sm->stiff[c] = s->stiff[k];
        sm->yield[c] = s->yield[k];
        sm->creep[c] = s->creep[k];
        memcpy(&sm->q[4 * c], &s->q[4 * k], 4 * sizeof(wb_real));
    }
    for (int32_t j = 0; j < s->nids; j++) sm->ids[sm->nids + j] = s->ids[j] + pshift;
    if (s->nids) memcpy(&sm->rest[3 * (size_t)sm->nids], s->rest, 3 * (size_t)s->nids * sizeof(wb_real));
    sm->n += s->n;
    sm->nids += s->nids;
}

/* ---- teardown and hash (ctype.h) --------------------------------------------------------- */
static void sm_destroy(wb_world *w)
{
    wb_smatch *sm = w->sm;
    if (!sm) return;
    void *p[] = { sm->start, sm->stiff, sm->yield, sm->creep, sm->ids, sm->rest, sm->q, sm->qk, sm->lambda };
    for (size_t i = 0; i < sizeof p / sizeof p[0]; i++) free(p[i]);
    free(sm);
    w->sm = NULL;
}

static size_t sm_charged(const wb_world *w) { return SM(w)->charged; }

/* parameters and state (rest shapes, rotations); a world without any adds nothing */
static uint64_t sm_hash(const wb_world *w, uint64_t h)
{
    const wb_smatch *sm = SM(w);
    if (sm->n == 0) return h;
    h = wb__fnv(h, &sm->n, sizeof sm->n);
    h = wb__fnv(h, sm->start, sizeof(int32_t) * ((size_t)sm->n + 1));
    h = wb__fnv(h, sm->ids, sizeof(int32_t) * (size_t)sm->nids);
    h = wb__fnv(h, sm->stiff, sizeof(wb_real) * (size_t)sm->n);
    h = wb__fnv(h, sm->yield, sizeof(wb_real) * (size_t)sm->n);
    h = wb__fnv(h, sm->creep, sizeof(wb_real) * (size_t)sm->n);
    h = wb__fnv(h, sm->rest, sizeof(wb_real) * 3 * (size_t)sm->nids);
    return wb__fnv(h, sm->q, sizeof(wb_real) * 4 * (size_t)sm->n);
}

static void sm_stats(const wb_world *w, wb_stats *st)
{
    st->shape_matches = wb_shape_match_count(w);
}

int32_t wb__shape_match_members(const wb_world *w) { return w->sm ? w->sm->nids : 0; }

const wb_ctype wb__shape_type = {
    .name = "shape_match",
    .count = sm_count,
    .prepare = sm_prepare,
    .substep_begin = sm_substep_begin,
    .project = sm_project,
    .frame_end = sm_frame_end,
    .energy = sm_energy,
    .links = sm_links,
    .joins = sm_joins,
    .destroy = sm_destroy,
    .charged = sm_charged,
    .stats = sm_stats,
    .hash = sm_hash,
    .image_free = sm_image_free,
    .image_save = sm_image_save,
    .image_check = sm_image_check,
    .image_reserve = sm_image_reserve,
    .image_put = sm_image_put,
    .residual = sm_residual,
};
