/* volume.c: volume constraints (a type of the table in ctype.c, so all of it is here).
 *
 * C = V - V0 with V the signed volume of the tetrahedron (p0 p1 p2 p3),
 * V = (p1-p0) . ((p2-p0) x (p3-p0)) / 6, projected with XPBD (Macklin et al. 2016):
 * dlambda = (-C - alpha~ lambda) / (sum_k w_k |grad_k V|^2 + alpha~), dx_k = w_k grad_k V dlambda.
 * The gradients are those of the signed volume, so a tet pushed inside out is driven
 * back through zero to the sign it was made with, and a flat tet still has gradients
 * (its faces' area normals) to be pushed apart along. The corrections are mass-weighted:
 * sum_k m_k dx_k = dlambda sum_k grad_k V = 0, momentum is conserved.
 *
 * Model: the corners, compliance, yield and creep. State: the signed rest volume, which
 * only plastic flow changes (once per frame, vol_frame_end).
 * Cache: the multipliers of the current substep (force readback) and the colour batches
 * (batch.h, four particles a constraint): Gauss-Seidel batch after batch, each batch in
 * parallel chunks, so the result is the same for any thread count. */
#include <assert.h>
#include <stdlib.h>

#include "core.h"
#include "ctype.h"
#include "volume.h"
#include "snapshot.h"


#define VOLUME_BYTES (10 * sizeof(int32_t) + 7 * sizeof(wb_real))

wb_real wb_tet_signed_volume(const wb_real *a, const wb_real *b, const wb_real *c, const wb_real *d)
{
    wb_real e1[3], e2[3], e3[3], n[3];
    v3_sub(e1, b, a);
    v3_sub(e2, c, a);
    v3_sub(e3, d, a);
    v3_cross(n, e2, e3);
    return v3_dot(e1, n) / 6;
}

wb_volume_def wb_volume_default_def(void)
{
    wb_volume_def d = { 0, false, 0, 0, 0 };
    return d;
}

/* the options' rules: the one place they are decided (the binding and the JSON reader
 * print what this finds) */
static wb_fault def_fault(const wb_volume_def *d)
{
    if (!(d->compliance >= 0) || !isfinite(d->compliance)) return WB_FAULT_KEY("compliance", "must be >= 0");
    if (d->has_rest && !isfinite(d->rest)) return WB_FAULT_KEY("rest", "must be finite");
    if (!(d->yield >= 0) || !isfinite(d->yield)) return WB_FAULT_KEY("yield", "must be >= 0");
    if (!(d->creep >= 0) || !isfinite(d->creep)) return WB_FAULT_KEY("creep", "must be >= 0");
    return WB_NO_FAULT;
}

const char *wb_volume_def_check(const wb_volume_def *d)
{
    return def_fault(d).msg;
}

/* the particles first, then the options, then (without a rest) whether their volume is
 * finite */
wb_fault wb_volume_check(int32_t np, const wb_real *x, const int32_t p[4], const wb_volume_def *d)
{
    wb_fault f = wb__quad_fault(p, np, "volume constraint particle out of range",
                                "a volume constraint needs four distinct particles");
    if (!f.msg) f = def_fault(d);
    if (!f.msg && x && !d->has_rest &&
        !isfinite(wb_tet_signed_volume(&x[3 * p[0]], &x[3 * p[1]], &x[3 * p[2]], &x[3 * p[3]])))
        f = WB_FAULT_AT(-1, "the particles are too far apart (their volume overflows)",
                        "the particles are too far apart (their volume overflows)");
    return f;
}

/* room for `extra` more constraints, charged to the memory budget: refused, nothing made,
 * when it would pass the budget (a failed allocation leaves the larger charge until the
 * next reserve, as wb__charge's other users do) */
wb_status wb__volume_reserve(wb_world *w, int64_t extra)
{
    wb_volumes *v = w->vol;
    if (!v) {
        v = calloc(1, sizeof *v);
        if (!v) return WB_ERR_NOMEM;
        w->vol = v;
    }
    const int64_t need = v->n + extra;
    if (need > WB_MAX_CONSTRAINTS) return WB_ERR_LIMIT;
    if (need <= v->cap) return WB_OK;
    const int32_t cap = wb__grown_cap(v->cap, need, 64);
    if (!wb__charge(w, &v->charged, (size_t)cap * VOLUME_BYTES)) return WB_ERR_NOMEM;
    const wb_soa arr[] = {
        { (void **)&v->ijkl, 4 * sizeof(int32_t) }, { (void **)&v->alpha, sizeof(wb_real) },
        { (void **)&v->rest, sizeof(wb_real) }, { (void **)&v->lambda, sizeof(wb_real) },
        { (void **)&v->yield, sizeof(wb_real) }, { (void **)&v->creep, sizeof(wb_real) },
        { (void **)&v->order, sizeof(int32_t) }, { (void **)&v->pos, sizeof(int32_t) },
        { (void **)&v->pk, 4 * sizeof(int32_t) }, { (void **)&v->pa, 2 * sizeof(wb_real) },
    };
    if (WB_SOA_RESIZE(arr, cap) != WB_OK) return WB_ERR_NOMEM;
    v->cap = cap;
    return WB_OK;
}

/* append one constraint after wb__volume_reserve (cannot fail) */
void wb__volume_put(wb_world *w, const int32_t p[4], wb_real alpha, wb_real rest)
{
    wb_volumes *v = w->vol;
    assert(v && v->n < v->cap); /* contract: reserved first */
    const int32_t i = v->n++;
    memcpy(&v->ijkl[4 * i], p, 4 * sizeof *p);
    v->alpha[i] = alpha;
    v->rest[i] = rest;
    v->yield[i] = v->creep[i] = 0;
    v->lambda[i] = 0;
}

void wb__volume_plastic(wb_world *w, int32_t first, wb_real yield, wb_real creep)
{
    wb_volumes *v = w->vol;
    if (!v || !(yield > 0) || !(creep > 0)) return;
    for (int32_t i = first < 0 ? 0 : first; i < v->n; i++) {
        v->yield[i] = yield;
        v->creep[i] = creep;
    }
    if (v->n > first) v->plastic = 1;
}

int32_t wb_volume_add(wb_world *w, const int32_t p[4], const wb_volume_def *def)
{
    const wb_fault f = wb_volume_check(w->m.np, w->s.x, p, def);
    if (f.msg) {
        wb__set_error("%s", f.msg);
        return WB_ERR_ARG;
    }
    const wb_real *x = w->s.x;
    const wb_real rest = def->has_rest ? def->rest
                       : wb_tet_signed_volume(&x[3 * p[0]], &x[3 * p[1]], &x[3 * p[2]], &x[3 * p[3]]);
    wb_status st = wb__volume_reserve(w, 1);
    if (st != WB_OK) return st;
    wb__volume_put(w, p, def->compliance, rest);
    wb__volume_plastic(w, w->vol->n - 1, def->yield, def->creep);
    return w->vol->n - 1;
}

int32_t wb_volume_count(const wb_world *w) { return w->vol ? w->vol->n : 0; }

#define CHECK_V(w, i) ((w)->vol && (i) >= 0 && (i) < (w)->vol->n)

void wb_volume_particles(const wb_world *w, int32_t i, int32_t p[4])
{
    if (!CHECK_V(w, i)) return;
    memcpy(p, &w->vol->ijkl[4 * i], 4 * sizeof *p);
}

wb_real wb_volume_rest(const wb_world *w, int32_t i) { return CHECK_V(w, i) ? w->vol->rest[i] : 0; }
wb_real wb_volume_compliance(const wb_world *w, int32_t i) { return CHECK_V(w, i) ? w->vol->alpha[i] : 0; }

static wb_real current(const wb_world *w, int32_t i)
{
    const int32_t *p = &w->vol->ijkl[4 * i];
    const wb_real *x = w->s.x;
    return wb_tet_signed_volume(&x[3 * p[0]], &x[3 * p[1]], &x[3 * p[2]], &x[3 * p[3]]);
}

wb_real wb_volume_current(const wb_world *w, int32_t i) { return CHECK_V(w, i) ? current(w, i) : 0; }

wb_real wb_volume_pressure(const wb_world *w, int32_t i)
{
    if (!CHECK_V(w, i)) return 0;
    const wb_real h = w->k.h_last;
    /* not stepped since it was made: no multiplier yet */
    if (!(h > 0) || i >= w->vol->bt.n) return 0;
    return w->vol->lambda[w->vol->pos[i]] / (h * h);
}

void wb_world_volume_total(const wb_world *w, wb_real *cur, wb_real *rest)
{
    wb_real c = 0, r = 0;
    for (int32_t i = 0; i < wb_volume_count(w); i++) {
        c += current(w, i);
        r += w->vol->rest[i];
    }
    if (cur) *cur = c;
    if (rest) *rest = r;
}

/* ---- the type ---------------------------------------------------------------------- */
static int32_t vol_count(const wb_world *w) { return wb_volume_count(w); }

/* colour batches when constraints were added since (they are never removed) */
static wb_status vol_prepare(wb_world *w)
{
    wb_volumes *v = w->vol;
    if (!v || v->n == v->bt.n) return WB_OK;
    if (!wb__batches_build(&v->bt, &w->m, v->ijkl, 4, v->n, v->order)) return WB_ERR_NOMEM;
    /* what a projection reads, copied in batch order: a batch streams through memory */
    for (int32_t j = 0; j < v->n; j++) {
        const int32_t i = v->order[j];
        memcpy(&v->pk[4 * j], &v->ijkl[4 * i], 4 * sizeof(int32_t));
        v->pa[2 * j] = v->alpha[i];
        v->pa[2 * j + 1] = v->rest[i];
        v->pos[i] = j;
    }
    return WB_OK;
}

static void vol_substep_begin(wb_world *w)
{
    if (w->vol && w->vol->n > 0) memset(w->vol->lambda, 0, sizeof(wb_real) * (size_t)w->vol->n);
}

/* the constraints order[lo, hi): one batch's chunk, or the serial tail */
static void project_range(wb_world *w, const int32_t *order, int32_t lo, int32_t hi, wb_real h)
{
    (void)order; /* the packed copies are in batch order already */
    wb_volumes *v = w->vol;
    const wb_real inv_h2 = 1 / (h * h);
    const wb_real *wv = w->m.w;
    wb_real *x = w->s.x;
    for (int32_t j = lo; j < hi; j++) {
        const int32_t *p = &v->pk[4 * j];
        const wb_real wk[4] = { wv[p[0]], wv[p[1]], wv[p[2]], wv[p[3]] };
        if (wk[0] + wk[1] + wk[2] + wk[3] == 0) continue;
        const wb_real *x0 = &x[3 * p[0]], *x1 = &x[3 * p[1]], *x2 = &x[3 * p[2]], *x3 = &x[3 * p[3]];
        wb_real e1[3], e2[3], e3[3], g[4][3];
        v3_sub(e1, x1, x0);
        v3_sub(e2, x2, x0);
        v3_sub(e3, x3, x0);
        /* grad_1 V = e2 x e3 / 6, grad_2 = e3 x e1 / 6, grad_3 = e1 x e2 / 6, grad_0 = -sum */
        v3_cross(g[1], e2, e3);
        v3_cross(g[2], e3, e1);
        v3_cross(g[3], e1, e2);
        for (int k = 1; k < 4; k++) v3_scale(g[k], g[k], (wb_real)1 / 6);
        for (int c = 0; c < 3; c++) g[0][c] = -(g[1][c] + g[2][c] + g[3][c]);
        const wb_real vol = v3_dot(e1, g[1]);
        const wb_real at = v->pa[2 * j] * inv_h2;
        if (isinf(at)) continue; /* compliance/h^2 overflowed: no stiffness */
        wb_real den = at;
        for (int k = 0; k < 4; k++) den += wk[k] * v3_dot(g[k], g[k]);
        /* all four on a line (or on a point): no direction changes the volume */
        if (!(den > (wb_real)1e-300) || !isfinite(den)) continue;
        const wb_real dl = (v->pa[2 * j + 1] - vol - at * v->lambda[j]) / den;
        v->lambda[j] += dl;
        for (int k = 0; k < 4; k++)
            if (wk[k] > 0) v3_madd(&x[3 * p[k]], g[k], wk[k] * dl);
    }
}

/* batch after batch in colour order, a batch in parallel chunks (a batch shares no
 * movable particle): the same bits for any thread count */
static void vol_project(wb_world *w, wb_real h)
{
    wb_volumes *v = w->vol;
    if (!v) return;
    w->k.projections += v->n;
    wb__batches_run(&v->bt, w, 256, project_range, NULL, v->order, h);
}

/* U = C^2 / (2 alpha) for compliant constraints; incompressible ones store none */
static wb_real vol_residual(const wb_world *w, wb_real h)
{
    const wb_volumes *v = w->vol;
    if (!v || v->bt.n <= 0) return 0;
    const wb_real *x = w->s.x, *wv = w->m.w, inv_h2 = 1 / (h * h);
    wb_real r = 0;
    for (int32_t j = 0; j < v->bt.n; j++) {
        const int32_t *p = &v->pk[4 * j];
        const wb_real at = v->pa[2 * j] * inv_h2;
        if (isinf(at) || wv[p[0]] + wv[p[1]] + wv[p[2]] + wv[p[3]] == 0) continue;
        wb_real e1[3], e2[3], e3[3], g[4][3];
        v3_sub(e1, &x[3 * p[1]], &x[3 * p[0]]);
        v3_sub(e2, &x[3 * p[2]], &x[3 * p[0]]);
        v3_sub(e3, &x[3 * p[3]], &x[3 * p[0]]);
        v3_cross(g[1], e2, e3);
        v3_cross(g[2], e3, e1);
        v3_cross(g[3], e1, e2);
        for (int c = 0; c < 3; c++) g[0][c] = -(g[1][c] + g[2][c] + g[3][c]);
        wb_real g2 = 0;
        for (int k = 0; k < 4; k++) g2 += v3_dot(g[k], g[k]) / 36;
        const wb_real ri = wb__residual(v3_dot(e1, g[1]) / 6 - v->pa[2 * j + 1] + at * v->lambda[j], g2, 4);
        r = ri > r ? ri : r;
    }
    return r;
}

static wb_real vol_energy(const wb_world *w)
{
    wb_real e = 0;
    for (int32_t i = 0; i < wb_volume_count(w); i++) {
        const wb_real a = w->vol->alpha[i];
        if (a <= 0) continue;
        const wb_real c = current(w, i) - w->vol->rest[i];
        e += c * c / (2 * a);
    }
    return e;
}

/* Plastic flow, once per frame on the frame's final shape, as a distance constraint's
 * (distance.c): past |e| = |V - V0| / |V0| > yield the rest volume moves towards the
 * volume by the part of the strain past yield, at min(1, creep dt) per frame. A body
 * whose links flow but whose volumes kept the volume it was made with would fight its
 * own links for ever once it yielded (its links' rest shape encloses another volume).
 * A tet turned inside out is no shape to flow to: it does not flow. */
static void vol_frame_end(wb_world *w)
{
    wb_volumes *v = w->vol;
    if (!v || !v->plastic) return;
    const wb_real dt = w->m.def.dt;
    for (int32_t i = 0; i < v->n; i++) {
        const wb_real y = v->yield[i], r = v->rest[i];
        if (!(y > 0) || !(v->creep[i] > 0) || r == 0) continue;
        const wb_real c = current(w, i);
        if (!(c * r > 0) || !isfinite(c)) continue;
        const wb_real a = fabs((c - r) / r);
        if (!(a > y)) continue;
        const wb_real rate = v->creep[i] * dt < 1 ? v->creep[i] * dt : 1;
        const wb_real past = isinf(a) ? 1 : (a - y) / a;
        v->rest[i] = r + rate * (c - r) * past;
        /* the packed copy the projection reads (a constraint added since is packed anew) */
        if (i < v->bt.n) v->pa[2 * v->pos[i] + 1] = v->rest[i];
    }
}

static void vol_links(const wb_world *w, wb_link_fn fn, void *ud)
{
    if (w->vol) wb__link_quads(w->vol->ijkl, w->vol->n, fn, ud);
}

static void vol_joins(const wb_world *w, wb_link_fn fn, void *ud)
{
    if (w->vol) wb__join_elements(w->vol->ijkl, w->vol->n, 4, fn, ud);
}

/* ---- teardown, hash, snapshots (ctype.h) -------------------------------------------------- */
static void vol_destroy(wb_world *w)
{
    wb_volumes *v = w->vol;
    if (!v) return;
    void *p[] = { v->ijkl, v->alpha, v->rest, v->yield, v->creep, v->lambda, v->order, v->pos, v->pk, v->pa };
    for (size_t i = 0; i < sizeof p / sizeof p[0]; i++) free(p[i]);
    free(v);
    w->vol = NULL;
}

static size_t vol_charged(const wb_world *w) { return w->vol ? w->vol->charged : 0; }

/* plastic ones' rest volumes flow (state), and how; elastic ones add nothing */
static uint64_t vol_hash(const wb_world *w, uint64_t h)
{
    const wb_volumes *vo = w->vol;
    if (!vo || !vo->plastic) return h;
    h = wb__fnv(h, vo->rest, sizeof(wb_real) * (size_t)vo->n);
    h = wb__fnv(h, vo->yield, sizeof(wb_real) * (size_t)vo->n);
    return wb__fnv(h, vo->creep, sizeof(wb_real) * (size_t)vo->n);
}

static void vol_image_free(wb_image *g)
{
    wb_image_volume *v = &g->vol;
    free(v->ijkl); free(v->alpha); free(v->rest); free(v->plastic);
    memset(v, 0, sizeof *v);
}

/* calloc of n elements, never of 0 bytes (so NULL always means out of memory) */
static void *zalloc(int64_t n, size_t elem) { return calloc((size_t)(n > 0 ? n : 1), elem); }

wb_status wb_image_alloc_volumes(wb_image *g, int32_t n)
{
    vol_image_free(g);
    wb_image_volume *v = &g->vol;
    v->n = n;
    v->ijkl = zalloc(4 * (int64_t)n, sizeof *v->ijkl);
    v->alpha = zalloc(n, sizeof *v->alpha);
    v->rest = zalloc(n, sizeof *v->rest);
    v->plastic = zalloc(2 * (int64_t)n, sizeof *v->plastic);
    if (v->ijkl && v->alpha && v->rest && v->plastic) return WB_OK;
    vol_image_free(g);
    return WB_ERR_NOMEM;
}

static wb_status vol_image_save(const wb_world *w, wb_image *g)
{
    const int32_t n = wb_volume_count(w);
    if (wb_image_alloc_volumes(g, n) != WB_OK) return WB_ERR_NOMEM;
    if (n == 0) return WB_OK;
    const wb_volumes *v = w->vol;
    memcpy(g->vol.ijkl, v->ijkl, 4 * (size_t)n * sizeof *g->vol.ijkl);
    memcpy(g->vol.alpha, v->alpha, (size_t)n * sizeof *g->vol.alpha);
    memcpy(g->vol.rest, v->rest, (size_t)n * sizeof *g->vol.rest);
    for (int32_t i = 0; i < n; i++) {
        g->vol.plastic[2 * i] = v->yield[i];
        g->vol.plastic[2 * i + 1] = v->creep[i];
    }
    return WB_OK;
}

static const char *vol_image_check(const wb_image *g)
{
    if (g->vol.n < 0 || g->vol.n > WB_MAX_CONSTRAINTS) return "too many volume constraints";
    for (int32_t i = 0; i < g->vol.n; i++) {
        const wb_volume_def d = { g->vol.alpha[i], true, g->vol.rest[i], g->vol.plastic[2 * i], g->vol.plastic[2 * i + 1] };
        const wb_fault f = wb_volume_check(g->np, NULL, &g->vol.ijkl[4 * i], &d);
        if (f.msg) return f.msg;
    }
    return NULL;
}

static wb_status vol_image_reserve(wb_world *w, const wb_image *g, const wb_image_at *at)
{
    (void)at;
    return g->vol.n > 0 ? wb__volume_reserve(w, g->vol.n) : WB_OK;
}

/* after w's, particles shifted (reserved: cannot fail) */
static void vol_image_put(wb_world *w, const wb_image *g, const wb_image_at *at)
{
    for (int32_t i = 0; i < g->vol.n; i++) {
        int32_t p[4];
        for (int k = 0; k < 4; k++) p[k] = g->vol.ijkl[4 * i + k] + at->pshift;
        wb__volume_put(w, p, g->vol.alpha[i], g->vol.rest[i]);
        wb__volume_plastic(w, w->vol->n - 1, g->vol.plastic[2 * i], g->vol.plastic[2 * i + 1]);
    }
}

static void vol_stats(const wb_world *w, wb_stats *st)
{
    st->volumes = wb_volume_count(w);
}

const int32_t *wb__volume_corners(const wb_world *w) { return w->vol ? w->vol->ijkl : NULL; }

const wb_ctype wb__volume_type = {
    .name = "volume",
    .count = vol_count,
    .prepare = vol_prepare,
    .substep_begin = vol_substep_begin,
    .project = vol_project,
    .frame_end = vol_frame_end,
    .energy = vol_energy,
    .links = vol_links,
    .joins = vol_joins,
    .destroy = vol_destroy,
    .charged = vol_charged,
    .stats = vol_stats,
    .hash = vol_hash,
    .image_free = vol_image_free,
    .image_save = vol_image_save,
    .image_check = vol_image_check,
    .image_reserve = vol_image_reserve,
    .image_put = vol_image_put,
    .residual = vol_residual,
};
