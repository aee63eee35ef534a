/* tether.c: tethers, the long-range attachments of Kim, Chentanez and Müller 2012 ("Long
 * range attachments: a method to simulate inextensible clothing in computer games").
 *
 * A tether keeps two particles at most `length` apart and never pushes them together:
 * C = |x_p - x_q| - length <= 0, an XPBD inequality (the multiplier only pulls, lambda <= 0).
 * Tied from each particle of a hanging cloth to its pin at their rest distance, it bounds
 * the stretch that one Gauss-Seidel pass a substep leaves in a long chain of links: the
 * links spread a pin's pull one link per pass, the tether reaches the far end at once.
 *
 * Model: the pairs, lengths and compliances. Cache: the multipliers of the substep. They
 * are projected one after the other in the order made (a particle has a tether or a few,
 * and most end at an immovable pin): the same bits on any thread count. */
#include <stdlib.h>
#include <string.h>

#include "ctype.h"
#include "snapshot.h"
#include "tether.h"

#define TETHER_BYTES (2 * sizeof(int32_t) + 3 * sizeof(wb_real))

wb_tether_def wb_tether_default_def(void)
{
    wb_tether_def d = { false, 0, 0 };
    return d;
}

/* the options' rules: the one place they are decided (the binding and the JSON reader
 * print what this finds) */
static wb_fault def_fault(const wb_tether_def *d)
{
    if (d->has_length && !(d->length >= 0 && isfinite(d->length))) return WB_FAULT_KEY("length", "must be finite and >= 0");
    if (!(d->compliance >= 0) || !isfinite(d->compliance)) return WB_FAULT_KEY("compliance", "must be >= 0");
    return WB_NO_FAULT;
}

const char *wb_tether_def_check(const wb_tether_def *d)
{
    return def_fault(d).msg;
}

/* room for `extra` more, charged to the memory budget */
static wb_status reserve(wb_world *w, int64_t extra)
{
    wb_tethers *t = w->teth;
    if (!t) {
        t = calloc(1, sizeof *t);
        if (!t) return WB_ERR_NOMEM;
        w->teth = t;
    }
    const int64_t need = t->n + extra;
    if (need > WB_MAX_CONSTRAINTS) return WB_ERR_LIMIT;
    if (need <= t->cap) return WB_OK;
    const int32_t cap = wb__grown_cap(t->cap, need, 64);
    if (!wb__charge(w, &t->charged, (size_t)cap * TETHER_BYTES)) return WB_ERR_NOMEM;
    const wb_soa arr[] = {
        { (void **)&t->ij, 2 * sizeof(int32_t) }, { (void **)&t->len, sizeof(wb_real) },
        { (void **)&t->alpha, sizeof(wb_real) }, { (void **)&t->lambda, sizeof(wb_real) },
    };
    if (WB_SOA_RESIZE(arr, cap) != WB_OK) return WB_ERR_NOMEM;
    t->cap = cap;
    return WB_OK;
}

/* after reserve: cannot fail */
static void put(wb_world *w, int32_t p, int32_t q, wb_real len, wb_real alpha)
{
    wb_tethers *t = w->teth;
    const int32_t i = t->n++;
    t->ij[2 * i] = p;
    t->ij[2 * i + 1] = q;
    t->len[i] = len;
    t->alpha[i] = alpha;
    t->lambda[i] = 0;
}

static wb_real dist(const wb_real *x, int32_t p, int32_t q)
{
    wb_real d[3];
    v3_sub(d, &x[3 * p], &x[3 * q]);
    return v3_len(d);
}

/* the particles first, then the options, then (without a length) whether their
 * distance is finite */
wb_fault wb_tether_check(int32_t np, const wb_real *x, int32_t p, int32_t q, const wb_tether_def *d)
{
    if (p < 0 || p >= np) return WB_FAULT_AT(0, "tether particle out of range", "out of range");
    if (q < 0 || q >= np) return WB_FAULT_AT(1, "tether particle out of range", "out of range");
    if (p == q) return WB_FAULT_AT(1, "a tether needs two distinct particles", "a tether needs two distinct particles");
    const wb_fault f = def_fault(d);
    if (f.msg || !x || d->has_length || isfinite(dist(x, p, q))) return f;
    return WB_FAULT_AT(-1, "the particles are too far apart (their distance overflows)",
                       "the particles are too far apart (their distance overflows)");
}

int32_t wb_tether_add(wb_world *w, int32_t p, int32_t q, const wb_tether_def *def)
{
    const wb_fault f = wb_tether_check(w->m.np, w->s.x, p, q, def);
    if (f.msg) {
        wb__set_error("%s", f.msg);
        return WB_ERR_ARG;
    }
    const wb_real len = def->has_length ? def->length : dist(w->s.x, p, q);
    const wb_status st = reserve(w, 1);
    if (st != WB_OK) return st;
    put(w, p, q, len, def->compliance);
    return w->teth->n - 1;
}

/* Each of ids' particles that is not pinned, to the nearest pinned one among ids where they
 * were made (x0), at that distance: where a cloth was made flat, the distance its links
 * allow. A brute search over the pins (a cloth has a few). */
int32_t wb_tether_to_pins(wb_world *w, const int32_t *ids, int32_t n, wb_real compliance)
{
    const wb_model *m = &w->m;
    if (!(compliance >= 0) || !isfinite(compliance)) {
        wb__set_error("compliance must be >= 0");
        return WB_ERR_ARG;
    }
    int32_t npin = 0, nfree = 0;
    for (int32_t k = 0; k < n; k++) {
        if (ids[k] < 0 || ids[k] >= m->np) {
            wb__set_error("particle out of range");
            return WB_ERR_ARG;
        }
        if (m->pinned[ids[k]]) npin++;
        else nfree++;
    }
    if (npin == 0 || nfree == 0) return 0;
    const wb_status st = reserve(w, nfree);
    if (st != WB_OK) return st;
    for (int32_t k = 0; k < n; k++) {
        const int32_t i = ids[k];
        if (m->pinned[i]) continue;
        int32_t best = -1;
        wb_real bd = INFINITY;
        for (int32_t j = 0; j < n; j++) {
            if (!m->pinned[ids[j]]) continue;
            const wb_real d = dist(m->x0, i, ids[j]);
            if (d < bd) bd = d, best = ids[j];
        }
        put(w, i, best, bd, compliance);
    }
    return nfree;
}

int32_t wb_tether_count(const wb_world *w) { return w->teth ? w->teth->n : 0; }

#define CHECK_T(w, i) ((w)->teth && (i) >= 0 && (i) < (w)->teth->n)

void wb_tether_particles(const wb_world *w, int32_t i, int32_t pq[2])
{
    if (CHECK_T(w, i)) memcpy(pq, &w->teth->ij[2 * i], 2 * sizeof *pq);
}

wb_real wb_tether_length(const wb_world *w, int32_t i) { return CHECK_T(w, i) ? w->teth->len[i] : 0; }

wb_real wb_tether_force(const wb_world *w, int32_t i)
{
    const wb_real h = w->k.h_last;
    return CHECK_T(w, i) && h > 0 ? fabs(w->teth->lambda[i]) / (h * h) : 0;
}

/* ---- the step --------------------------------------------------------------------------------- */
static int32_t teth_count(const wb_world *w) { return wb_tether_count(w); }

static wb_status teth_prepare(wb_world *w)
{
    (void)w;
    return WB_OK;
}

static void teth_substep_begin(wb_world *w)
{
    if (w->teth && w->teth->n > 0) memset(w->teth->lambda, 0, sizeof(wb_real) * (size_t)w->teth->n);
}

/* XPBD as a distance's, the multiplier kept <= 0 (only a pull): a tether slack by more
 * than its multiplier's pull has nothing to do */
static void teth_project(wb_world *w, wb_real h)
{
    wb_tethers *t = w->teth;
    if (!t || t->n == 0) return;
    const wb_real *wv = w->m.w, inv_h2 = 1 / (h * h);
    wb_real *x = w->s.x;
    w->k.projections += t->n;
    for (int32_t i = 0; i < t->n; i++) {
        const int32_t a = t->ij[2 * i], b = t->ij[2 * i + 1];
        const wb_real wa = wv[a], wb = wv[b], at = t->alpha[i] * inv_h2;
        if (wa + wb == 0 || isinf(at)) continue;
        wb_real d[3];
        v3_sub(d, &x[3 * a], &x[3 * b]);
        const wb_real l = v3_len(d);
        if (!(l > 1e-12)) continue;
        const wb_real C = l - t->len[i];
        wb_real dl = (-C - at * t->lambda[i]) / (wa + wb + at);
        if (t->lambda[i] + dl > 0) dl = -t->lambda[i]; /* would push: let go */
        if (dl == 0) continue;
        t->lambda[i] += dl;
        v3_scale(d, d, dl / l);
        v3_madd(&x[3 * a], d, wa);
        v3_madd(&x[3 * b], d, -wb);
    }
}

/* a taut one's |C + alpha~ lambda|; a slack one (C <= 0, lambda = 0) has none */
static wb_real teth_residual(const wb_world *w, wb_real h)
{
    const wb_tethers *t = w->teth;
    if (!t) return 0;
    const wb_real *wv = w->m.w, inv_h2 = 1 / (h * h);
    wb_real r = 0;
    for (int32_t i = 0; i < t->n; i++) {
        const int32_t a = t->ij[2 * i], b = t->ij[2 * i + 1];
        const wb_real at = t->alpha[i] * inv_h2;
        if (wv[a] + wv[b] == 0 || isinf(at)) continue;
        const wb_real c = dist(w->s.x, a, b) - t->len[i] + at * t->lambda[i];
        const wb_real ri = c > 0 || t->lambda[i] < 0 ? fabs(c) : 0;
        r = ri > r ? ri : r;
    }
    return r;
}

/* a compliant one stretched past its length */
static wb_real teth_energy(const wb_world *w)
{
    const wb_tethers *t = w->teth;
    wb_real e = 0;
    for (int32_t i = 0; t && i < t->n; i++) {
        const wb_real c = dist(w->s.x, t->ij[2 * i], t->ij[2 * i + 1]) - t->len[i];
        if (t->alpha[i] > 0 && c > 0) e += c * c / (2 * t->alpha[i]);
    }
    return e;
}

/* its two particles never touch (joined by a constraint: docs/physics.md, "Contacts") */
static void teth_links(const wb_world *w, wb_link_fn fn, void *ud)
{
    for (int32_t i = 0; w->teth && i < w->teth->n; i++) fn(ud, w->teth->ij[2 * i], w->teth->ij[2 * i + 1], 1);
}

/* ---- teardown, hash, snapshots (ctype.h) ---------------------------------------------------- */
static void teth_destroy(wb_world *w)
{
    wb_tethers *t = w->teth;
    if (!t) return;
    free(t->ij);
    free(t->len);
    free(t->alpha);
    free(t->lambda);
    free(t);
    w->teth = NULL;
}

static size_t teth_charged(const wb_world *w) { return w->teth ? w->teth->charged : 0; }

static void teth_stats(const wb_world *w, wb_stats *st) { st->tethers = wb_tether_count(w); }

/* no state: what a step changes of them is only the multipliers, a cache */
static uint64_t teth_hash(const wb_world *w, uint64_t h)
{
    (void)w;
    return h;
}

static void teth_image_free(wb_image *g)
{
    wb_image_tether *t = &g->teth;
    free(t->ij);
    free(t->len);
    free(t->alpha);
    memset(t, 0, sizeof *t);
}

wb_status wb_image_alloc_tethers(wb_image *g, int32_t n)
{
    teth_image_free(g);
    wb_image_tether *t = &g->teth;
    t->n = n;
    t->ij = calloc((size_t)(n > 0 ? 2 * n : 1), sizeof *t->ij);
    t->len = calloc((size_t)(n > 0 ? n : 1), sizeof *t->len);
    t->alpha = calloc((size_t)(n > 0 ? n : 1), sizeof *t->alpha);
    if (t->ij && t->len && t->alpha) return WB_OK;
    teth_image_free(g);
    return WB_ERR_NOMEM;
}

static wb_status teth_image_save(const wb_world *w, wb_image *g)
{
    const int32_t n = wb_tether_count(w);
    if (wb_image_alloc_tethers(g, n) != WB_OK) return WB_ERR_NOMEM;
    if (n == 0) return WB_OK;
    memcpy(g->teth.ij, w->teth->ij, 2 * sizeof *g->teth.ij * (size_t)n);
    memcpy(g->teth.len, w->teth->len, sizeof *g->teth.len * (size_t)n);
    memcpy(g->teth.alpha, w->teth->alpha, sizeof *g->teth.alpha * (size_t)n);
    return WB_OK;
}

static const char *teth_image_check(const wb_image *g)
{
    const wb_image_tether *t = &g->teth;
    if (t->n < 0 || t->n > WB_MAX_CONSTRAINTS) return "too many tethers";
    for (int32_t i = 0; i < t->n; i++) {
        const wb_tether_def d = { true, t->len[i], t->alpha[i] };
        const wb_fault f = wb_tether_check(g->np, NULL, t->ij[2 * i], t->ij[2 * i + 1], &d);
        if (f.msg) return f.msg;
    }
    return NULL;
}

static wb_status teth_image_reserve(wb_world *w, const wb_image *g, const wb_image_at *at)
{
    (void)at;
    return g->teth.n > 0 ? reserve(w, g->teth.n) : WB_OK;
}

static void teth_image_put(wb_world *w, const wb_image *g, const wb_image_at *at)
{
    for (int32_t i = 0; i < g->teth.n; i++)
        put(w, g->teth.ij[2 * i] + at->pshift, g->teth.ij[2 * i + 1] + at->pshift, g->teth.len[i], g->teth.alpha[i]);
}

const wb_ctype wb__tether_type = {
    .name = "tether",
    .count = teth_count,
    .prepare = teth_prepare,
    .substep_begin = teth_substep_begin,
    .project = teth_project,
    .energy = teth_energy,
    .links = teth_links,
    .destroy = teth_destroy,
    .charged = teth_charged,
    .stats = teth_stats,
    .hash = teth_hash,
    .image_free = teth_image_free,
    .image_save = teth_image_save,
    .image_check = teth_image_check,
    .image_reserve = teth_image_reserve,
    .image_put = teth_image_put,
    .residual = teth_residual,
};
