/* pressure.c: a closed surface keeps `pressure` x its rest volume (the balloon constraint
 * of Müller et al. 2007, in Macklin et al. 2016's XPBD form).
 *
 * One constraint per closed surface, over all its particles at once:
 *     C = V - p V0,   V = 1/6 sum_triangles (x_a - o) . ((x_b - o) x (x_c - o)),
 *     grad_a V = 1/6 sum_{triangles at a} (x_b - o) x (x_c - o)   (cyclically for b, c)
 * with o a fixed point (the first particle's position at the projection's start: the
 * volume of a closed surface does not depend on o, and products of coordinates near the
 * body keep their precision far from the origin). XPBD: dlambda = (-C - alpha~ lambda) /
 * (sum w_i |grad_i|^2 + alpha~), x_i += w_i grad_i dlambda, alpha~ = compliance / h^2.
 * The gradients of a closed surface sum to zero (translating it leaves V unchanged), so
 * the corrections, weighted by inverse masses, keep the momentum. The energy is
 * C^2 / (2 compliance), J, for a compliant one (compliance in m^6/J).
 *
 * A surface is closed when every edge is shared by exactly two triangles that run it in
 * opposite directions (an oriented 2-manifold without border); it must face outwards
 * (V0 > 0). The constraints are projected one after another, serially: deterministic for
 * any thread count. Why not in parallel, as the batched types are: one projection is a sum
 * over the triangles (V and the gradients, a scatter per triangle) and one update per
 * particle; measured on a 20^3 lattice's hull (4332 triangles, 10 substeps, -O3) it costs
 * 1.5 ms of a 38 ms frame (4%). A parallel version would gather per particle over its
 * triangles and sum V in fixed chunks combined in a fixed order (so that the bits do not
 * depend on the thread count); with two threads it could save about 2% of such a frame:
 * not worth its code. A scene of many pressure bodies is the case to revisit (bodies that
 * share no particle could then run side by side). */
#include <assert.h>
#include <stdio.h>
#include <stdlib.h>

#include "core.h"
#include "ctype.h"
#include "pressure.h"
#include "snapshot.h"

#define BYTES_P (3 * sizeof(int32_t) + 4 * sizeof(wb_real))
#define BYTES_V (sizeof(int32_t))
#define BYTES_T (3 * sizeof(int32_t))

/* w->pr for reading: an empty one while there is none */
static const wb_pressures no_pressures;
#define PR(w) ((w)->pr ? (w)->pr : &no_pressures)

/* room for n_extra constraints over nv_extra particles and nt_extra triangles in all; the
 * struct is made with the first */
static wb_status reserve(wb_world *w, int64_t n_extra, int64_t nv_extra, int64_t nt_extra)
{
    if (!w->pr) {
        if (n_extra <= 0 && nv_extra <= 0 && nt_extra <= 0) return WB_OK;
        if (!(w->pr = calloc(1, sizeof *w->pr))) return WB_ERR_NOMEM;
    }
    wb_pressures *p = w->pr;
    const int64_t n = p->n + n_extra + 1, nv = p->nverts + nv_extra, nt = p->ntri + nt_extra;
    if (n > WB_MAX_CONSTRAINTS || nv > WB_MAX_CONSTRAINTS || nt > WB_MAX_CONSTRAINTS) return WB_ERR_LIMIT;
    if (n <= p->cap && nv <= p->cap_verts && nt <= p->cap_tri) return WB_OK;
    const int32_t cn = n <= p->cap ? p->cap : wb__grown_cap(p->cap, n, 16);
    const int32_t cv = nv <= p->cap_verts ? p->cap_verts : wb__grown_cap(p->cap_verts, nv, 16);
    const int32_t ct = nt <= p->cap_tri ? p->cap_tri : wb__grown_cap(p->cap_tri, nt, 16);
    if (!wb__charge(w, &p->charged, (size_t)cn * BYTES_P + (size_t)cv * BYTES_V + (size_t)ct * BYTES_T))
        return WB_ERR_NOMEM;
    const wb_soa per[] = {
        { (void **)&p->surface, sizeof(int32_t) }, { (void **)&p->pressure, sizeof(wb_real) },
        { (void **)&p->alpha, sizeof(wb_real) }, { (void **)&p->v0, sizeof(wb_real) },
        { (void **)&p->lambda, sizeof(wb_real) }, { (void **)&p->vstart, sizeof(int32_t) },
        { (void **)&p->tstart, sizeof(int32_t) },
    };
    const wb_soa verts[] = { { (void **)&p->verts, sizeof(int32_t) } };
    const wb_soa tris[] = { { (void **)&p->tri, 3 * sizeof(int32_t) } };
    if (WB_SOA_RESIZE(per, cn) != WB_OK || WB_SOA_RESIZE(verts, cv) != WB_OK || WB_SOA_RESIZE(tris, ct) != WB_OK)
        return WB_ERR_NOMEM;
    if (p->cap == 0) p->vstart[0] = p->tstart[0] = 0;
    p->cap = cn;
    p->cap_verts = cv;
    p->cap_tri = ct;
    return WB_OK;
}

/* ---- surfaces ------------------------------------------------------------------------------ */
static int cmp_u64(const void *a, const void *b)
{
    const uint64_t x = *(const uint64_t *)a, y = *(const uint64_t *)b;
    return (x > y) - (x < y);
}

static int cmp_i32(const void *a, const void *b)
{
    const int32_t x = *(const int32_t *)a, y = *(const int32_t *)b;
    return (x > y) - (x < y);
}

/* NULL when tri[0..nt) is closed and consistently oriented, else what is wrong (msg
 * holds the particle ids of an edge at fault, 1-based as scripts see them) */
static const char *check_closed(const int32_t *tri, int32_t nt, char *msg, size_t n)
{
    if (nt < 4) return "the surface is not closed (a closed surface has at least 4 triangles)";
    uint64_t *e = malloc(sizeof *e * 3 * (size_t)nt);
    if (!e) return "out of memory checking the surface";
    const char *err = NULL;
    for (int32_t t = 0; t < nt && !err; t++)
        for (int c = 0; c < 3; c++) {
            const uint32_t a = (uint32_t)tri[3 * t + c], b = (uint32_t)tri[3 * t + (c + 1) % 3];
            if (a == b) err = "the surface has a degenerate triangle (a corner twice)";
            e[3 * t + c] = (uint64_t)a << 32 | b;
        }
    if (!err) qsort(e, 3 * (size_t)nt, sizeof *e, cmp_u64);
    for (size_t i = 0; !err && i < 3 * (size_t)nt; i++) {
        const uint32_t a = (uint32_t)(e[i] >> 32), b = (uint32_t)e[i];
        const uint64_t rev = (uint64_t)b << 32 | a;
        if (i > 0 && e[i] == e[i - 1]) {
            snprintf(msg, n, "the surface is not closed and consistently oriented: the edge %u-%u is run the same way "
                             "by two triangles", a + 1, b + 1);
            err = msg;
        } else if (!bsearch(&rev, e, 3 * (size_t)nt, sizeof *e, cmp_u64)) {
            snprintf(msg, n, "the surface is not closed: the edge %u-%u has a triangle on one side only", a + 1, b + 1);
            err = msg;
        }
    }
    free(e);
    return err;
}

int32_t wb_body_surface(const wb_world *w, wb_body b)
{
    const wb_model *m = &w->m;
    for (int32_t s = 0; s < m->nsurf; s++) {
        const int32_t t0 = m->surf_start[s], t1 = m->surf_start[s + 1];
        int inside = t1 > t0;
        for (int64_t i = 3 * (int64_t)t0; i < 3 * (int64_t)t1 && inside; i++)
            inside = m->tri[i] >= b.first && m->tri[i] < b.first + b.count;
        if (inside) return s;
    }
    return -1;
}

/* the volume of constraint k and (when grad) its gradients, unscaled: 6 V and 6 grad V */
static wb_real volume6(const wb_world *w, int32_t k, wb_real *grad)
{
    const wb_pressures *p = PR(w);
    const int32_t *v = &p->verts[p->vstart[k]], nv = p->vstart[k + 1] - p->vstart[k];
    const wb_real *x = w->s.x;
    wb_real o[3], V = 0;
    v3_copy(o, &x[3 * v[0]]);
    if (grad) memset(grad, 0, 3 * sizeof(wb_real) * (size_t)nv);
    for (int32_t t = p->tstart[k]; t < p->tstart[k + 1]; t++) {
        const int32_t *c = &p->tri[3 * t];
        wb_real a[3], b[3], d[3], bc[3];
        v3_sub(a, &x[3 * v[c[0]]], o);
        v3_sub(b, &x[3 * v[c[1]]], o);
        v3_sub(d, &x[3 * v[c[2]]], o);
        v3_cross(bc, b, d);
        V += v3_dot(a, bc);
        if (!grad) continue;
        wb_real ca[3], ab[3];
        v3_cross(ca, d, a);
        v3_cross(ab, a, b);
        v3_add(&grad[3 * c[0]], &grad[3 * c[0]], bc);
        v3_add(&grad[3 * c[1]], &grad[3 * c[1]], ca);
        v3_add(&grad[3 * c[2]], &grad[3 * c[2]], ab);
    }
    return V;
}

/* a new constraint over world surface s (reserved room for 3 nt particles and nt
 * triangles, surface checked); v0 < 0: the volume now */
static int32_t build(wb_world *w, int32_t s, wb_real pressure, wb_real alpha, wb_real v0)
{
    wb_pressures *p = w->pr;
    const wb_model *m = &w->m;
    const int32_t t0 = m->surf_start[s], nt = m->surf_start[s + 1] - t0, k = p->n;
    /* the surface's particles, ascending, made in place in the reserved room */
    int32_t *v = &p->verts[p->nverts], nv = 0;
    memcpy(v, &m->tri[3 * (int64_t)t0], 3 * sizeof(int32_t) * (size_t)nt);
    qsort(v, 3 * (size_t)nt, sizeof *v, cmp_i32);
    for (int32_t i = 0; i < 3 * nt; i++)
        if (nv == 0 || v[i] != v[nv - 1]) v[nv++] = v[i];
    for (int64_t i = 0; i < 3 * (int64_t)nt; i++) {
        const int32_t *f = bsearch(&m->tri[3 * (int64_t)t0 + i], v, (size_t)nv, sizeof *v, cmp_i32);
        p->tri[3 * (int64_t)p->ntri + i] = (int32_t)(f - v);
    }
    p->nverts += nv;
    p->ntri += nt;
    p->vstart[k + 1] = p->nverts;
    p->tstart[k + 1] = p->ntri;
    p->surface[k] = s;
    p->pressure[k] = pressure;
    p->alpha[k] = alpha;
    p->lambda[k] = 0;
    p->n++;
    p->v0[k] = v0 >= 0 ? v0 : volume6(w, k, NULL) / 6;
    return k;
}

/* ---- the type ------------------------------------------------------------------------------- */
static int32_t pr_count(const wb_world *w) { return PR(w)->n; }

/* a closed surface is one body (no links: its particles are not rest neighbours for it) */
static void pr_joins(const wb_world *w, wb_link_fn fn, void *ud)
{
    const wb_pressures *pr = PR(w);
    for (int32_t c = 0; c < pr->n; c++) wb__join_elements(&pr->verts[pr->vstart[c]], 1, pr->vstart[c + 1] - pr->vstart[c], fn, ud);
}

static wb_status pr_prepare(wb_world *w)
{
    wb_pressures *p = w->pr;
    if (!p) return WB_OK;
    int32_t most = 0;
    for (int32_t k = 0; k < p->n; k++)
        if (p->vstart[k + 1] - p->vstart[k] > most) most = p->vstart[k + 1] - p->vstart[k];
    /* at least one: a NULL array would read as no memory */
    wb_real *g = wb__grow(p->grad, &p->cap_grad, 3 * most + 1, sizeof *g);
    if (!g) return WB_ERR_NOMEM;
    p->grad = g;
    return WB_OK;
}

static void pr_substep_begin(wb_world *w)
{
    if (pr_count(w) > 0) memset(w->pr->lambda, 0, sizeof(wb_real) * (size_t)w->pr->n);
}

static void pr_project(wb_world *w, wb_real h)
{
    wb_pressures *p = w->pr;
    if (!p) return;
    const wb_real *wv = w->m.w;
    wb_real *x = w->s.x, *g = p->grad;
    w->k.projections += p->n;
    for (int32_t k = 0; k < p->n; k++) {
        const int32_t *v = &p->verts[p->vstart[k]], nv = p->vstart[k + 1] - p->vstart[k];
        const wb_real C = volume6(w, k, g) / 6 - p->pressure[k] * p->v0[k];
        const wb_real at = p->alpha[k] / (h * h);
        if (isinf(at)) continue; /* no stiffness left (inf * 0 would be NaN) */
        wb_real den = at;
        for (int32_t i = 0; i < nv; i++) den += wv[v[i]] * v3_dot(&g[3 * i], &g[3 * i]) / 36;
        if (!(den > 0)) continue; /* immovable, or flat: nothing to push along */
        const wb_real dl = (-C - at * p->lambda[k]) / den;
        p->lambda[k] += dl;
        for (int32_t i = 0; i < nv; i++)
            if (wv[v[i]] > 0) v3_madd(&x[3 * v[i]], &g[3 * i], wv[v[i]] * dl / 6);
    }
}

static wb_real pr_residual(const wb_world *w, wb_real h)
{
    const wb_pressures *p = PR(w);
    wb_real r = 0, *g = p->grad; /* (scratch) */
    for (int32_t k = 0; k < p->n; k++) {
        const wb_real at = p->alpha[k] / (h * h);
        if (isinf(at)) continue;
        const int32_t nv = p->vstart[k + 1] - p->vstart[k];
        const wb_real C = volume6(w, k, g) / 6 - p->pressure[k] * p->v0[k];
        wb_real g2 = 0;
        for (int32_t i = 0; i < nv; i++) g2 += v3_dot(&g[3 * i], &g[3 * i]) / 36;
        const wb_real ri = wb__residual(C + at * p->lambda[k], g2, nv);
        r = ri > r ? ri : r;
    }
    return r;
}

static wb_real pr_energy(const wb_world *w)
{
    const wb_pressures *p = PR(w);
    wb_real u = 0;
    for (int32_t k = 0; k < p->n; k++) {
        if (p->alpha[k] <= 0) continue;
        const wb_real C = volume6(w, k, NULL) / 6 - p->pressure[k] * p->v0[k];
        u += C * C / (2 * p->alpha[k]);
    }
    return u;
}


/* ---- API ------------------------------------------------------------------------------------ */
wb_pressure_def wb_pressure_default_def(void)
{
    wb_pressure_def d = { 1, 0 };
    return d;
}

/* the options' rules: the one place they are decided (the binding and the JSON reader
 * print what this finds; the surface is wb_pressure_add's to judge) */
wb_fault wb_pressure_def_fault(const wb_pressure_def *d)
{
    if (!(d->pressure > 0) || !isfinite(d->pressure)) return WB_FAULT_KEY("pressure", "must be > 0");
    if (!(d->compliance >= 0) || !isfinite(d->compliance)) return WB_FAULT_KEY("compliance", "must be >= 0");
    return WB_NO_FAULT;
}

const char *wb_pressure_def_check(const wb_pressure_def *d)
{
    return wb_pressure_def_fault(d).msg;
}

/* what is wrong with surface s (of nsurf, ranges ss, corners tri) for a pressure, or NULL */
static const char *check_surface(int32_t s, int32_t nsurf, const int32_t *ss, const int32_t *tri, char *msg, size_t n)
{
    if (s < 0 || s >= nsurf) return "surface out of range";
    return check_closed(&tri[3 * (int64_t)ss[s]], ss[s + 1] - ss[s], msg, n);
}

int32_t wb_pressure_add(wb_world *w, int32_t s, const wb_pressure_def *def)
{
    char msg[160];
    const char *e = wb_pressure_def_check(def);
    if (!e) e = check_surface(s, w->m.nsurf, w->m.surf_start, w->m.tri, msg, sizeof msg);
    if (e) {
        wb__set_error("%s", e);
        return strncmp(e, "out of memory", 13) ? WB_ERR_ARG : WB_ERR_NOMEM;
    }
    const int32_t nt = w->m.surf_start[s + 1] - w->m.surf_start[s];
    wb_status st = reserve(w, 1, 3 * (int64_t)nt, nt);
    if (st != WB_OK) return st;
    const int32_t k = build(w, s, def->pressure, def->compliance, -1);
    const wb_real v0 = w->pr->v0[k];
    if (!(v0 > 0) || !isfinite(v0)) {
        /* undo: nothing else points at the arrays' tails */
        wb_pressures *p = w->pr;
        p->n--;
        p->nverts = p->vstart[k];
        p->ntri = p->tstart[k];
        wb__set_error(v0 < 0 ? "the surface encloses a negative volume (its triangles face inwards)"
                             : "the surface encloses no volume (flat or degenerate)");
        return WB_ERR_ARG;
    }
    return k;
}

#define CHECK_K(w, k) assert((k) >= 0 && (k) < wb_pressure_count(w))

int32_t wb_pressure_count(const wb_world *w) { return PR(w)->n; }

wb_pressure_def wb_pressure_get_def(const wb_world *w, int32_t k)
{
    CHECK_K(w, k);
    wb_pressure_def d = { w->pr->pressure[k], w->pr->alpha[k] };
    return d;
}

void wb_pressure_set(wb_world *w, int32_t k, wb_real pressure)
{
    CHECK_K(w, k);
    assert(pressure > 0 && isfinite(pressure));
    w->pr->pressure[k] = pressure;
}

wb_real wb_pressure_volume(const wb_world *w, int32_t k) { CHECK_K(w, k); return volume6(w, k, NULL) / 6; }
wb_real wb_pressure_rest_volume(const wb_world *w, int32_t k) { CHECK_K(w, k); return w->pr->v0[k]; }
int32_t wb_pressure_surface(const wb_world *w, int32_t k) { CHECK_K(w, k); return w->pr->surface[k]; }

/* ---- snapshots -------------------------------------------------------------------------------- */
static void pr_image_free(wb_image *g);

wb_status wb_image_alloc_pressure(wb_image *g, int32_t n)
{
    wb_image_pressure *p = &g->pr;
    const size_t c = (size_t)(n > 0 ? n : 1);
    p->n = n;
    p->surface = calloc(c, sizeof *p->surface);
    p->pressure = calloc(c, sizeof(wb_real));
    p->alpha = calloc(c, sizeof(wb_real));
    p->v0 = calloc(c, sizeof(wb_real));
    if (!p->surface || !p->pressure || !p->alpha || !p->v0) {
        pr_image_free(g);
        return WB_ERR_NOMEM;
    }
    return WB_OK;
}

static void pr_image_free(wb_image *g)
{
    wb_image_pressure *p = &g->pr;
    free(p->surface);
    free(p->pressure);
    free(p->alpha);
    free(p->v0);
    memset(p, 0, sizeof *p);
}

static wb_status pr_image_save(const wb_world *w, wb_image *g)
{
    const wb_pressures *p = PR(w);
    if (p->n == 0) return WB_OK;
    wb_status st = wb_image_alloc_pressure(g, p->n);
    if (st != WB_OK) return st;
    const size_t n = (size_t)p->n;
    memcpy(g->pr.surface, p->surface, n * sizeof(int32_t));
    memcpy(g->pr.pressure, p->pressure, n * sizeof(wb_real));
    memcpy(g->pr.alpha, p->alpha, n * sizeof(wb_real));
    memcpy(g->pr.v0, p->v0, n * sizeof(wb_real));
    return WB_OK;
}

/* the volume of the image's surface s, about its first corner */
static wb_real image_volume(const wb_image *g, int32_t s)
{
    const int32_t *t = &g->tri[3 * (int64_t)g->surf_start[s]];
    const wb_real *o = &g->x[3 * t[0]];
    wb_real V = 0;
    for (int32_t i = 0; i < g->surf_start[s + 1] - g->surf_start[s]; i++, t += 3) {
        wb_real a[3], b[3], c[3], bc[3];
        v3_sub(a, &g->x[3 * t[0]], o);
        v3_sub(b, &g->x[3 * t[1]], o);
        v3_sub(c, &g->x[3 * t[2]], o);
        v3_cross(bc, b, c);
        V += v3_dot(a, bc);
    }
    return V / 6;
}

static const char *pr_image_check(const wb_image *g)
{
    static _Thread_local char msg[160];
    const wb_image_pressure *p = &g->pr;
    if (p->n < 0 || p->n > WB_MAX_CONSTRAINTS) return "too many pressure constraints";
    for (int32_t k = 0; k < p->n; k++) {
        wb_pressure_def d = { p->pressure[k], p->alpha[k] };
        const char *e = wb_pressure_def_check(&d);
        if (!e) e = check_surface(p->surface[k], g->nsurf, g->surf_start, g->tri, msg, sizeof msg);
        if (e) return e;
        /* v0 < 0 (a config without "rest_volume"): the surface's volume at load, which must
         * then be positive */
        if (p->v0[k] < 0 && !(image_volume(g, p->surface[k]) > 0))
            return "a pressure's surface encloses no volume (or faces inwards)";
        if (!(p->v0[k] > 0 || p->v0[k] < 0) || !isfinite(p->v0[k])) return "a pressure's rest volume must be a finite number > 0";
    }
    return NULL;
}

static wb_status pr_image_reserve(wb_world *w, const wb_image *g, const wb_image_at *at)
{
    (void)at;
    int64_t nt = 0;
    for (int32_t k = 0; k < g->pr.n; k++) nt += g->surf_start[g->pr.surface[k] + 1] - g->surf_start[g->pr.surface[k]];
    return reserve(w, g->pr.n, 3 * nt, nt);
}

static void pr_image_put(wb_world *w, const wb_image *g, const wb_image_at *at)
{
    const int32_t sshift = at->sshift;
    const wb_image_pressure *p = &g->pr;
    for (int32_t k = 0; k < p->n; k++) build(w, p->surface[k] + sshift, p->pressure[k], p->alpha[k], p->v0[k]);
}

/* ---- teardown and hash (ctype.h) --------------------------------------------------------- */
static void pr_destroy(wb_world *w)
{
    wb_pressures *pr = w->pr;
    if (!pr) return;
    void *p[] = { pr->surface, pr->pressure, pr->alpha, pr->v0, pr->vstart, pr->tstart, pr->verts, pr->tri,
                  pr->lambda, pr->grad };
    for (size_t i = 0; i < sizeof p / sizeof p[0]; i++) free(p[i]);
    free(pr);
    w->pr = NULL;
}

static size_t pr_charged(const wb_world *w) { return PR(w)->charged; }

/* parameters and rest volumes; a world without any adds nothing */
static uint64_t pr_hash(const wb_world *w, uint64_t h)
{
    const wb_pressures *pr = PR(w);
    if (pr->n == 0) return h;
    h = wb__fnv(h, &pr->n, sizeof pr->n);
    h = wb__fnv(h, pr->surface, sizeof(int32_t) * (size_t)pr->n);
    h = wb__fnv(h, pr->pressure, sizeof(wb_real) * (size_t)pr->n);
    h = wb__fnv(h, pr->alpha, sizeof(wb_real) * (size_t)pr->n);
    return wb__fnv(h, pr->v0, sizeof(wb_real) * (size_t)pr->n);
}

static void pr_stats(const wb_world *w, wb_stats *st)
{
    st->pressures = wb_pressure_count(w);
}

int32_t wb__pressure_vertices(const wb_world *w) { return w->pr ? w->pr->nverts : 0; }

const wb_ctype wb__pressure_type = {
    .name = "pressure",
    .count = pr_count,
    .prepare = pr_prepare,
    .substep_begin = pr_substep_begin,
    .project = pr_project,
    .energy = pr_energy,
    .joins = pr_joins,
    .destroy = pr_destroy,
    .charged = pr_charged,
    .stats = pr_stats,
    .hash = pr_hash,
    .image_free = pr_image_free,
    .image_save = pr_image_save,
    .image_check = pr_image_check,
    .image_reserve = pr_image_reserve,
    .image_put = pr_image_put,
    .residual = pr_residual,
};
