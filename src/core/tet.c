/* tet.c: Neo-Hookean tetrahedra (a type of the table in ctype.c, so all of it is here).
 *
 * Macklin & Müller 2021, "A constraint-based formulation of stable Neo-Hookean materials":
 * with F = Ds Dm^-1 (Ds = [x1-x0, x2-x0, x3-x0], Dm the same at rest) the energy
 *   Psi = mu/2 (tr(F^T F) - 3) + lam/2 (det F - a)^2,   a = 1 + mu/lam,
 * is split into two XPBD constraints per tet, solved together (a 2x2 system, below):
 *   deviatoric  C_D = sqrt(tr(F^T F)),   compliance 1/(mu V0),
 *   hydrostatic C_H = det F - a,         compliance 1/(lam V0).
 * At F = I their forces cancel (mu F against lam (1 - a) cof F = -mu I), so the rest shape
 * is stress free. det F is signed: an inverted tet has C_H < -a and its gradient (the
 * cofactor) pushes it back through flat to the positive side; a flat one still has one.
 *
 * E means E: linearised about F = I this energy is mu |eps|^2 + (lam - mu)/2 tr(eps)^2, so
 * lam is the Lamé lambda of (E, nu) plus mu (the paper's remapping for the form without its
 * log term); small strains then follow Hooke's law with the given Young's modulus and
 * Poisson's ratio (tests/validation/neo_hookean.lua measures both).
 *
 * Limit: the substep must stay below about the time a wave (sqrt(E / density)) takes to
 * cross the smallest tet: past it the linearised 2x2 step overshoots (a tet stiff against
 * its corners' masses is asked for C_D -> 0, a collapse, that only the compliance stops).
 * A light body of sliver tets explodes; more substeps, not iterations, is the cure. It is
 * not silent: prepare warns once when h exceeds WAVE_LIMIT crossing times (with the substeps
 * that would do), and a frame ending with over 1% of the tets inverted warns once. (A clamp
 * on each projection's correction was tried: it slows the collapse, does not stop it at
 * E = 1e9, and would cap how fast a squashed solid may spring back; so none.)
 *
 * Model: corners, Dm^-1, V0, E, nu (mu and lam derived). Cache: the multipliers of the
 * substep and the colour batches (batch.h, four particles a tet): Gauss-Seidel batch after
 * batch, each batch in parallel chunks, so the result is the same for any thread count. */
#include <assert.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>

#include "core.h"
#include "ctype.h"
#include "snapshot.h"
#include "tet.h"
#include "vbd.h"

/* a packed tet (tet.h pd): Dm^-1, 1/(mu V0 h^2), 1/(lam V0 h^2), 1 + mu/lam */
#define PD 12
enum { PD_AD = 9, PD_AH = 10, PD_A = 11 };

#define TET_BYTES (9 * sizeof(int32_t) + 30 * sizeof(wb_real))

wb_tet_def wb_tet_default_def(void)
{
    wb_tet_def d = { 1e5, 0.3, 0, 0 };
    return d;
}

/* the options' rules: the one place they are decided (the binding and the JSON reader
 * print what this finds) */
static wb_fault def_fault(const wb_tet_def *d)
{
    /* the bound: 100x diamond's modulus; far past it mu V0 and the energy overflow */
    if (!(d->young > 0) || !(d->young <= 1e14)) return WB_FAULT_KEY("young", "must be in (0, 1e14] (Pa)");
    if (!(d->poisson >= 0 && d->poisson < 0.5)) return WB_FAULT_KEY("poisson", "must be in [0, 0.5)");
    if (!(d->yield >= 0) || !isfinite(d->yield)) return WB_FAULT_KEY("yield", "must be >= 0");
    if (!(d->creep >= 0) || !isfinite(d->creep)) return WB_FAULT_KEY("creep", "must be >= 0");
    return WB_NO_FAULT;
}

const char *wb_tet_def_check(const wb_tet_def *d)
{
    return def_fault(d).msg;
}

static void lame(wb_real young, wb_real poisson, wb_real *mu, wb_real *lam)
{
    *mu = young / (2 * (1 + poisson));
    *lam = young * poisson / ((1 + poisson) * (1 - 2 * poisson)) + *mu;
}

wb_status wb__tet_reserve(wb_world *w, int64_t extra)
{
    wb_neos *v = w->neo;
    if (!v) {
        v = calloc(1, sizeof *v);
        if (!v) return WB_ERR_NOMEM;
        w->neo = v;
    }
    const int64_t need = v->n + extra;
    if (need > WB_MAX_CONSTRAINTS) return WB_ERR_LIMIT;
    if (need <= v->cap) return WB_OK;
    const int32_t cap = wb__grown_cap(v->cap, need, 64);
    if (!wb__charge(w, &v->charged, (size_t)cap * TET_BYTES)) return WB_ERR_NOMEM;
    const wb_soa arr[] = {
        { (void **)&v->ijkl, 4 * sizeof(int32_t) }, { (void **)&v->dminv, 9 * sizeof(wb_real) },
        { (void **)&v->v0, sizeof(wb_real) }, { (void **)&v->young, sizeof(wb_real) },
        { (void **)&v->poisson, sizeof(wb_real) }, { (void **)&v->mu, sizeof(wb_real) },
        { (void **)&v->lam, sizeof(wb_real) }, { (void **)&v->ld, sizeof(wb_real) }, { (void **)&v->lh, sizeof(wb_real) },
        { (void **)&v->order, sizeof(int32_t) }, { (void **)&v->pk, 4 * sizeof(int32_t) },
        { (void **)&v->pd, PD * sizeof(wb_real) }, { (void **)&v->yield, sizeof(wb_real) },
        { (void **)&v->creep, sizeof(wb_real) },
    };
    if (WB_SOA_RESIZE(arr, cap) != WB_OK) return WB_ERR_NOMEM;
    v->cap = cap;
    return WB_OK;
}

void wb__tet_put(wb_world *w, const int32_t p[4], const wb_real dminv[9], wb_real v0, wb_real young, wb_real poisson)
{
    wb_neos *v = w->neo;
    assert(v && v->n < v->cap); /* contract: reserved first */
    const int32_t i = v->n++;
    memcpy(&v->ijkl[4 * i], p, 4 * sizeof *p);
    memcpy(&v->dminv[9 * i], dminv, 9 * sizeof *dminv);
    v->v0[i] = v0;
    v->young[i] = young;
    v->poisson[i] = poisson;
    lame(young, poisson, &v->mu[i], &v->lam[i]);
    v->ld[i] = v->lh[i] = 0;
    v->yield[i] = v->creep[i] = 0;
}

void wb__tet_plastic(wb_world *w, int32_t first, wb_real yield, wb_real creep)
{
    wb_neos *v = w->neo;
    if (!v || !(yield > 0) || !(creep > 0)) return;
    for (int32_t i = first < 0 ? 0 : first; i < v->n; i++) {
        v->yield[i] = yield;
        v->creep[i] = creep;
    }
    if (v->n > first) v->plastic = 1;
}

/* Dm^-1 (row-major) and the signed volume of the tet at x; false when flat */
static bool rest_of(const wb_real *x, const int32_t p[4], wb_real inv[9], wb_real *vol)
{
    const wb_real *x0 = &x[3 * p[0]];
    wb_real m[9]; /* columns: the edges from corner 0 */
    for (int k = 0; k < 3; k++)
        for (int r = 0; r < 3; r++) m[3 * r + k] = x[3 * p[k + 1] + r] - x0[r];
    const wb_real det = m[0] * (m[4] * m[8] - m[5] * m[7]) - m[1] * (m[3] * m[8] - m[5] * m[6]) +
                        m[2] * (m[3] * m[7] - m[4] * m[6]);
    *vol = det / 6;
    if (!(fabs(det) > 0) || !isfinite(det)) return false;
    const wb_real id = 1 / det;
    inv[0] = (m[4] * m[8] - m[5] * m[7]) * id;
    inv[1] = (m[2] * m[7] - m[1] * m[8]) * id;
    inv[2] = (m[1] * m[5] - m[2] * m[4]) * id;
    inv[3] = (m[5] * m[6] - m[3] * m[8]) * id;
    inv[4] = (m[0] * m[8] - m[2] * m[6]) * id;
    inv[5] = (m[2] * m[3] - m[0] * m[5]) * id;
    inv[6] = (m[3] * m[7] - m[4] * m[6]) * id;
    inv[7] = (m[1] * m[6] - m[0] * m[7]) * id;
    inv[8] = (m[0] * m[4] - m[1] * m[3]) * id;
    for (int k = 0; k < 9; k++)
        if (!isfinite(inv[k])) return false;
    return true;
}

bool wb_tet_rest_shape(const wb_real *a, const wb_real *b, const wb_real *c, const wb_real *d, wb_real dminv[9],
                       wb_real *volume)
{
    const wb_real x[12] = { a[0], a[1], a[2], b[0], b[1], b[2], c[0], c[1], c[2], d[0], d[1], d[2] };
    const int32_t p[4] = { 0, 1, 2, 3 };
    const bool ok = rest_of(x, p, dminv, volume);
    *volume = fabs(*volume);
    return ok;
}

bool wb__tet_put_current(wb_world *w, const int32_t p[4], wb_real young, wb_real poisson)
{
    wb_real inv[9], vol;
    if (!rest_of(w->s.x, p, inv, &vol)) return false;
    /* a negative rest volume is its own rest: Dm^-1 carries the sign, F = I at rest */
    wb__tet_put(w, p, inv, fabs(vol), young, poisson);
    return true;
}

/* the particles first, then the options, then whether they make a rest shape */
wb_fault wb_tet_check(int32_t np, const wb_real *x, const int32_t p[4], const wb_tet_def *d)
{
    wb_fault f = wb__quad_fault(p, np, "tet particle out of range", "a tet needs four distinct particles");
    if (!f.msg) f = def_fault(d);
    wb_real inv[9], vol;
    if (!f.msg && x && !rest_of(x, p, inv, &vol))
        f = WB_FAULT_AT(-1, "the four particles lie in a plane (a flat tet has no rest shape)",
                        "the four particles lie in a plane (a flat tet has no rest shape)");
    return f;
}

int32_t wb_tet_add(wb_world *w, const int32_t p[4], const wb_tet_def *def)
{
    const wb_fault f = wb_tet_check(w->m.np, w->s.x, p, def);
    if (f.msg) {
        wb__set_error("%s", f.msg);
        return WB_ERR_ARG;
    }
    wb_real inv[9], vol;
    rest_of(w->s.x, p, inv, &vol);
    wb_status st = wb__tet_reserve(w, 1);
    if (st != WB_OK) return st;
    wb__tet_put(w, p, inv, fabs(vol), def->young, def->poisson);
    wb__tet_plastic(w, w->neo->n - 1, def->yield, def->creep);
    return w->neo->n - 1;
}

int32_t wb_tet_count(const wb_world *w) { return w->neo ? w->neo->n : 0; }

#define CHECK_T(w, i) ((w)->neo && (i) >= 0 && (i) < (w)->neo->n)

void wb_tet_particles(const wb_world *w, int32_t i, int32_t p[4])
{
    if (CHECK_T(w, i)) memcpy(p, &w->neo->ijkl[4 * i], 4 * sizeof *p);
}

/* F = Ds Dm^-1 of the tet of corners p and Dm^-1 d (row-major) */
static void deformation_of(const int32_t *p, const wb_real *d, const wb_real *x, wb_real F[9])
{
    const wb_real *x0 = &x[3 * p[0]];
    wb_real e[3][3];
    for (int k = 0; k < 3; k++) v3_sub(e[k], &x[3 * p[k + 1]], x0);
    for (int r = 0; r < 3; r++)
        for (int c = 0; c < 3; c++) F[3 * r + c] = e[0][r] * d[c] + e[1][r] * d[3 + c] + e[2][r] * d[6 + c];
}

/* F of tet i */
static void deformation(const wb_neos *v, const wb_real *x, int32_t i, wb_real F[9])
{
    deformation_of(&v->ijkl[4 * i], &v->dminv[9 * i], x, F);
}

static wb_real det3(const wb_real F[9])
{
    return F[0] * (F[4] * F[8] - F[5] * F[7]) - F[1] * (F[3] * F[8] - F[5] * F[6]) + F[2] * (F[3] * F[7] - F[4] * F[6]);
}

/* the energy of tet i less its rest value (so a body at rest stores none), J */
static wb_real energy_of(const wb_neos *v, const wb_real *x, int32_t i)
{
    wb_real F[9];
    deformation(v, x, i, F);
    wb_real ic = 0;
    for (int k = 0; k < 9; k++) ic += F[k] * F[k];
    const wb_real mu = v->mu[i], lam = v->lam[i], a = 1 + mu / lam, c = det3(F) - a;
    return v->v0[i] * (mu / 2 * (ic - 3) + lam / 2 * c * c - mu * mu / (2 * lam));
}

wb_real wb_tet_energy(const wb_world *w, int32_t i) { return CHECK_T(w, i) ? energy_of(w->neo, w->s.x, i) : 0; }
wb_real wb_tet_rest_volume(const wb_world *w, int32_t i) { return CHECK_T(w, i) ? w->neo->v0[i] : 0; }

/* signed current volume over the signed rest one, det F */
wb_real wb_tet_volume_ratio(const wb_world *w, int32_t i)
{
    if (!CHECK_T(w, i)) return 0;
    wb_real F[9];
    deformation(w->neo, w->s.x, i, F);
    return det3(F);
}

/* the volume change det F - 1, or the shape change where that is larger: the von Mises
 * equivalent of the isochoric Green strain (C' = C / J^(2/3), E = (C' - I)/2,
 * sqrt(2/3 dev E : dev E)), which equals the strain of a volume-keeping uniaxial stretch
 * and is about k/sqrt(3) in a shear of k: pure shear leaves det F at 1 and the volume
 * measure alone blind to it. The shape change has no sign (> 0). */
wb_real wb_tet_strain(const wb_world *w, int32_t i)
{
    if (!CHECK_T(w, i)) return 0;
    wb_real F[9];
    deformation(w->neo, w->s.x, i, F);
    const double J = det3(F), vol = J - 1;
    if (!(fabs(J) > 1e-9)) return (wb_real)vol;   /* flat: no isochoric part */
    const double iso = 1 / cbrt(J * J);
    double E[9], tr = 0, dd = 0;
    for (int r = 0; r < 3; r++)
        for (int c = 0; c < 3; c++) {
            double cc = 0;   /* (F^T F)_rc */
            for (int k = 0; k < 3; k++) cc += (double)F[3 * k + r] * F[3 * k + c];
            E[3 * r + c] = 0.5 * (iso * cc - (r == c));
        }
    for (int k = 0; k < 3; k++) tr += E[4 * k];
    for (int k = 0; k < 9; k++) {
        const double d = E[k] - (k % 4 == 0 ? tr / 3 : 0);
        dd += d * d;
    }
    const double eq = sqrt(2.0 / 3.0 * dd);
    return (wb_real)(fabs(vol) >= eq ? vol : eq);
}

void wb_tet_material(const wb_world *w, int32_t i, wb_real *young, wb_real *poisson)
{
    if (!CHECK_T(w, i)) return;
    if (young) *young = w->neo->young[i];
    if (poisson) *poisson = w->neo->poisson[i];
}

/* ---- snapshots (snapshot.h): the model as it is, so a restored world has the same future */
static void tet_image_free(wb_image *g)
{
    wb_image_tet *t = &g->tet;
    free(t->ijkl); free(t->dminv); free(t->v0); free(t->young); free(t->poisson); free(t->plastic);
    memset(t, 0, sizeof *t);
}

/* calloc of n elements, never of 0 bytes (so NULL always means out of memory) */
static void *zalloc(int64_t n, size_t elem) { return calloc((size_t)(n > 0 ? n : 1), elem); }

wb_status wb_image_alloc_tets(wb_image *g, int32_t n)
{
    tet_image_free(g);
    wb_image_tet *t = &g->tet;
    t->n = n;
    t->ijkl = zalloc(4 * (int64_t)n, sizeof *t->ijkl);
    t->dminv = zalloc(9 * (int64_t)n, sizeof *t->dminv);
    t->v0 = zalloc(n, sizeof *t->v0);
    t->young = zalloc(n, sizeof *t->young);
    t->poisson = zalloc(n, sizeof *t->poisson);
    t->plastic = zalloc(2 * (int64_t)n, sizeof *t->plastic);
    if (t->ijkl && t->dminv && t->v0 && t->young && t->poisson && t->plastic) return WB_OK;
    tet_image_free(g);
    return WB_ERR_NOMEM;
}

static wb_status tet_image_save(const wb_world *w, wb_image *g)
{
    const int32_t n = wb_tet_count(w);
    if (wb_image_alloc_tets(g, n) != WB_OK) return WB_ERR_NOMEM;
    if (n == 0) return WB_OK;
    const wb_neos *v = w->neo;
    memcpy(g->tet.ijkl, v->ijkl, 4 * sizeof(int32_t) * (size_t)n);
    memcpy(g->tet.dminv, v->dminv, 9 * sizeof(wb_real) * (size_t)n);
    memcpy(g->tet.v0, v->v0, sizeof(wb_real) * (size_t)n);
    memcpy(g->tet.young, v->young, sizeof(wb_real) * (size_t)n);
    memcpy(g->tet.poisson, v->poisson, sizeof(wb_real) * (size_t)n);
    for (int32_t i = 0; i < n; i++) {
        g->tet.plastic[2 * i] = v->yield[i];
        g->tet.plastic[2 * i + 1] = v->creep[i];
    }
    return WB_OK;
}

static const char *tet_image_check(const wb_image *g)
{
    if (g->tet.n < 0 || g->tet.n > WB_MAX_CONSTRAINTS) return "too many tets";
    for (int32_t i = 0; i < g->tet.n; i++) {
        const wb_tet_def d = { g->tet.young[i], g->tet.poisson[i], g->tet.plastic[2 * i], g->tet.plastic[2 * i + 1] };
        const wb_fault f = wb_tet_check(g->np, NULL, &g->tet.ijkl[4 * i], &d);
        if (f.msg) return f.msg;
        if (!(g->tet.v0[i] > 0) || !isfinite(g->tet.v0[i])) return "a tet's rest volume must be > 0";
        const wb_real *dm = &g->tet.dminv[9 * i];
        for (int k = 0; k < 9; k++)
            if (!isfinite(dm[k]) || fabs(dm[k]) > 1e150) return "a tet's rest shape must be finite";
        /* Dm^-1 and V0 describe one rest tet (V0 = 1 / (6 |det Dm^-1|)); a singular or
         * mismatched pair from a hand-edited file would make F and the energy NaN */
        const wb_real det = det3(dm);
        if (!(fabs(6 * g->tet.v0[i] * det - 1) <= 1e-6) && !(fabs(6 * g->tet.v0[i] * det + 1) <= 1e-6))
            return "a tet's rest_inverse and rest_volume disagree (V0 = 1 / (6 |det|))";
    }
    return NULL;
}

static wb_status tet_image_reserve(wb_world *w, const wb_image *g, const wb_image_at *at)
{
    (void)at;
    return g->tet.n > 0 ? wb__tet_reserve(w, g->tet.n) : WB_OK;
}

static void tet_image_put(wb_world *w, const wb_image *g, const wb_image_at *at)
{
    const int32_t shift = at->pshift;
    for (int32_t i = 0; i < g->tet.n; i++) {
        int32_t p[4];
        for (int k = 0; k < 4; k++) p[k] = g->tet.ijkl[4 * i + k] + shift;
        wb__tet_put(w, p, &g->tet.dminv[9 * i], g->tet.v0[i], g->tet.young[i], g->tet.poisson[i]);
        wb__tet_plastic(w, w->neo->n - 1, g->tet.plastic[2 * i], g->tet.plastic[2 * i + 1]);
    }
}

/* ---- the type ---------------------------------------------------------------------- */
static int32_t tet_count(const wb_world *w) { return wb_tet_count(w); }

#define WAVE_LIMIT ((wb_real)2)

/* the corners' mass of tet i (0 for a pinned corner) */
static wb_real corner_mass(const wb_world *w, int32_t i)
{
    wb_real m = 0;
    for (int k = 0; k < 4; k++) {
        const wb_real wk = w->m.w[w->neo->ijkl[4 * i + k]];
        if (wk > 0) m += 1 / wk;
    }
    return m;
}

/* the longest h/t over the tets, t the time a wave sqrt(E/density) takes to cross the tet:
 * t^-2 = E V0 sum_k w_k |dx_k at rest|^2 (E V0 / (m L^2) = (E/density) / L^2), the ratio of
 * the deviatoric stiffness to the corners' mass over h^2 (k11 / ad of tet_project at rest);
 * *at is the tet (-1 when none moves) */
static wb_real wave_ratio(const wb_world *w, wb_real h, int32_t *at)
{
    const wb_neos *v = w->neo;
    const wb_real *wv = w->m.w;
    wb_real worst = 0;
    *at = -1;
    for (int32_t i = 0; v && i < v->n; i++) {
        const int32_t *p = &v->ijkl[4 * i];
        const wb_real *d = &v->dminv[9 * i];
        wb_real s = 0;
        for (int r = 0; r < 3; r++) { /* corner 0's gradient is minus the sum of the rows */
            const wb_real g0 = d[r] + d[3 + r] + d[6 + r];
            s += wv[p[0]] * g0 * g0 + wv[p[1]] * d[r] * d[r] + wv[p[2]] * d[3 + r] * d[3 + r] +
                 wv[p[3]] * d[6 + r] * d[6 + r];
        }
        const wb_real q = h * h * v->young[i] * v->v0[i] * s;
        if (q > worst) { worst = q; *at = i; }
    }
    return sqrt(worst);
}

static wb_status tet_prepare(wb_world *w)
{
    if (!w->neo || w->neo->n == 0) return WB_OK;
    /* colour batches when tets were added since (they are never removed) */
    wb_neos *nv = w->neo;
    if (nv->n != nv->bt.n) {
        if (!wb__batches_build(&nv->bt, &w->m, nv->ijkl, 4, nv->n, nv->order)) return WB_ERR_NOMEM;
        /* what a projection reads, copied in batch order: a batch streams through memory
         * (through the order array it jumped across the whole block, 10% slower) */
        for (int32_t j = 0; j < nv->n; j++) {
            const int32_t i = nv->order[j];
            memcpy(&nv->pk[4 * j], &nv->ijkl[4 * i], 4 * sizeof(int32_t));
            wb_real *d = &nv->pd[PD * j];
            memcpy(d, &nv->dminv[9 * i], 9 * sizeof(wb_real));
            d[PD_A] = 1 + nv->mu[i] / nv->lam[i];
        }
        nv->pd_h = 0; /* the compliances: at the next projection */
    }
    int32_t at;
    const wb_real h = w->m.def.dt / w->m.def.substeps, r = wave_ratio(w, h, &at);
    /* stable up to about 2 (a hanging lattice bar: whole at 2.3, collapsed at 3.2); once per
     * substep length and tet count, not per step */
    wb_neos *v = w->neo;
    /* (VBD's Newton steps are stable at any stiffness: the limit is XPBD's) */
    if (r > WAVE_LIMIT && w->m.def.solver != WB_SOLVER_VBD && (h != v->warned_h || v->n != v->warned_n)) {
        const wb_real m = corner_mass(w, at);
        const double need = ceil(w->m.def.substeps * r / WAVE_LIMIT);
        v->advised = need < 1e9 ? (int32_t)need : 1000000000;
        wb__warn(w, "Neo-Hookean tets: substep %.3g s is %.1f times a wave's time across tet %d (E %.3g Pa, "
                    "%.3g kg; ok to 2): raise substeps to about %d or lower young",
                 h, r, at + 1, v->young[at], m, (int)v->advised);
        v->warned_h = h;
        v->warned_n = v->n;
    }
    return WB_OK;
}

/* the eigenvalues d and eigenvectors (the columns of q, row-major) of the symmetric a:
 * cyclic Jacobi rotations, a fixed order (the same bits everywhere) */
static void eigen_sym3(const double a_in[9], double d[3], double q[9])
{
    double a[9];
    memcpy(a, a_in, sizeof a);
    for (int k = 0; k < 9; k++) q[k] = k % 4 == 0;
    for (int sweep = 0; sweep < 32; sweep++) {
        const double off = a[1] * a[1] + a[2] * a[2] + a[5] * a[5];
        const double diag = a[0] * a[0] + a[4] * a[4] + a[8] * a[8];
        if (!(off > 1e-30 * diag)) break;
        static const int pairs[3][2] = { { 0, 1 }, { 0, 2 }, { 1, 2 } };
        for (int t = 0; t < 3; t++) {
            const int p = pairs[t][0], r = pairs[t][1];
            const double apr = a[3 * p + r];
            if (apr == 0) continue;
            const double th = (a[3 * r + r] - a[3 * p + p]) / (2 * apr);
            const double tn = (th >= 0 ? 1 : -1) / (fabs(th) + sqrt(th * th + 1));
            const double c = 1 / sqrt(tn * tn + 1), sn = tn * c;
            /* a <- J^T a J with J the rotation in the (p, r) plane; q <- q J */
            for (int k = 0; k < 3; k++) {
                const double akp = a[3 * k + p], akr = a[3 * k + r];
                a[3 * k + p] = c * akp - sn * akr;
                a[3 * k + r] = sn * akp + c * akr;
            }
            for (int k = 0; k < 3; k++) {
                const double apk = a[3 * p + k], ark = a[3 * r + k];
                a[3 * p + k] = c * apk - sn * ark;
                a[3 * r + k] = sn * apk + c * ark;
            }
            for (int k = 0; k < 3; k++) {
                const double qkp = q[3 * k + p], qkr = q[3 * k + r];
                q[3 * k + p] = c * qkp - sn * qkr;
                q[3 * k + r] = sn * qkp + c * qkr;
            }
        }
    }
    for (int k = 0; k < 3; k++) d[k] = a[4 * k];
}

/* Plastic flow, once per frame on the frame's final shape, the rule of the distance links
 * (distance.c) in the tet's principal directions: with F = R S (S = sqrt(F^T F), principal
 * stretches s_k), the strain is e = max |s_k - 1| (a link along a principal direction
 * would have s_k - 1); past yield the rest shape moves towards the deformed one seen in the
 * rest frame, Dm <- T Dm with T = I + f (S - I), f = min(1, creep dt) (e - yield) / e: so
 * Dm^-1 <- Dm^-1 T^-1 and V0 <- V0 det T, and F becomes R S T^-1 (f = 1: R, at rest).
 * Shape matching and volume constraints flow the same way, so a body whose links yield
 * keeps one rest shape for all its constraints. An inverted tet (det F <= 0) is no shape to
 * flow to and does not. */
static void tet_flow(wb_world *w)
{
    wb_neos *v = w->neo;
    const wb_real dt = w->m.def.dt;
    int changed = 0;
    for (int32_t j = 0; j < v->bt.n; j++) {
        const int32_t i = v->order[j];
        const wb_real y = v->yield[i];
        if (!(y > 0) || !(v->creep[i] > 0)) continue;
        wb_real F[9];
        deformation(v, w->s.x, i, F);
        if (!(det3(F) > 0)) continue;
        double C[9], lam[3], Q[9], s[3], e = 0;
        for (int r = 0; r < 3; r++)
            for (int c = 0; c < 3; c++)
                C[3 * r + c] = (double)F[r] * F[c] + (double)F[3 + r] * F[3 + c] + (double)F[6 + r] * F[6 + c];
        eigen_sym3(C, lam, Q);
        for (int k = 0; k < 3; k++) {
            s[k] = sqrt(lam[k] > 0 ? lam[k] : 0);
            if (fabs(s[k] - 1) > e) e = fabs(s[k] - 1);
        }
        if (!(e > y) || !isfinite(e)) continue;
        const double rate = v->creep[i] * dt < 1 ? v->creep[i] * dt : 1, f = rate * (e - y) / e;
        double t[3], Ti[9], vt = 1;
        for (int k = 0; k < 3; k++) {
            t[k] = 1 + f * (s[k] - 1); /* > 0: s_k >= 0 and f <= 1 */
            vt *= t[k];
        }
        if (!(vt > 0)) continue;
        for (int r = 0; r < 3; r++)
            for (int c = 0; c < 3; c++)
                Ti[3 * r + c] = Q[3 * r] * Q[3 * c] / t[0] + Q[3 * r + 1] * Q[3 * c + 1] / t[1] + Q[3 * r + 2] * Q[3 * c + 2] / t[2];
        wb_real *dm = &v->dminv[9 * i], nd[9];
        for (int r = 0; r < 3; r++)
            for (int c = 0; c < 3; c++)
                nd[3 * r + c] = (wb_real)(dm[3 * r] * Ti[c] + dm[3 * r + 1] * Ti[3 + c] + dm[3 * r + 2] * Ti[6 + c]);
        const wb_real nv0 = (wb_real)(v->v0[i] * vt);
        bool ok = nv0 > 0 && isfinite(nv0);
        for (int k = 0; k < 9 && ok; k++) ok = isfinite(nd[k]);
        if (!ok) continue;
        memcpy(dm, nd, sizeof nd);
        memcpy(&v->pd[PD * j], nd, sizeof nd); /* the packed copy the projection reads */
        v->v0[i] = nv0;
        changed = 1;
    }
    if (changed) v->pd_h = 0; /* the compliances 1/(mu V0 h^2), 1/(lam V0 h^2): anew */
}

/* plastic flow; then a frame ending with many tets inside out is a solid that collapsed
 * (too long a substep, a crushing contact): said once per world, as it costs only a
 * determinant per tet a frame */
static void tet_frame_end(wb_world *w)
{
    wb_neos *v = w->neo;
    if (v && v->plastic) tet_flow(w);
    if (!v || v->n == 0 || v->inverted_warned) return;
    int32_t bad = 0;
    for (int32_t i = 0; i < v->n; i++) {
        wb_real F[9];
        deformation(v, w->s.x, i, F);
        bad += !(det3(F) > 0);
    }
    if ((int64_t)bad * 100 <= v->n) return; /* a few: a contact may pinch a tet flat */
    v->inverted_warned = 1;
    /* the CLI shows the last warning: repeat the advice of the substep one */
    char advice[64] = "";
    if (v->advised > 0) snprintf(advice, sizeof advice, " to about %d", (int)v->advised);
    wb__warn(w, "frame %lld: %d of %d Neo-Hookean tets are inverted (det F <= 0); the solid has "
                "collapsed: raise substeps%s or lower young", (long long)w->s.frame + 1, bad, v->n, advice);
}

static void tet_substep_begin(wb_world *w)
{
    if (w->neo && w->neo->n > 0) {
        memset(w->neo->ld, 0, sizeof(wb_real) * (size_t)w->neo->n);
        memset(w->neo->lh, 0, sizeof(wb_real) * (size_t)w->neo->n);
    }
}

/* dC/dx_k of a constraint with dC/dF = G (row-major): column k-1 of G Dm^-T for k = 1..3,
 * minus their sum for k = 0 */
static inline void grads(const wb_real *dminv, const wb_real G[9], wb_real g[4][3])
{
    for (int k = 0; k < 3; k++)
        for (int r = 0; r < 3; r++)
            g[k + 1][r] = G[3 * r] * dminv[3 * k] + G[3 * r + 1] * dminv[3 * k + 1] + G[3 * r + 2] * dminv[3 * k + 2];
    for (int r = 0; r < 3; r++) g[0][r] = -(g[1][r] + g[2][r] + g[3][r]);
}

static inline wb_real wdot(const wb_real wk[4], wb_real a[4][3], wb_real b[4][3])
{
    wb_real s = 0;
    for (int k = 0; k < 4; k++) s += wk[k] * v3_dot(a[k], b[k]);
    return s;
}

/* Both constraints of a tet in one 2x2 XPBD solve (the linearised system of the pair), not
 * one after the other: at rest their gradients are parallel and their values large (C_D =
 * sqrt 3, C_H = -mu/lam), balanced only through the compliances; projected in turn, each
 * under-converged pass leaves a bias that squeezes the solid (measured: a hanging bar
 * shortened instead of stretched). Solved together, the rest shape is a fixed point of a
 * single iteration at any stiffness, and the error is that of the linearisation.
 * Packed tets [lo, hi) (batch positions). This loop is the reference: project_range4 does
 * the same operations in the same order, four tets at a time. */
static void project_scalar(wb_world *w, int32_t lo, int32_t hi)
{
    wb_neos *v = w->neo;
    const wb_real *wv = w->m.w;
    wb_real *x = w->s.x;
    for (int32_t j = lo; j < hi; j++) {
        const int32_t *p = &v->pk[4 * j];
        const wb_real wk[4] = { wv[p[0]], wv[p[1]], wv[p[2]], wv[p[3]] };
        if (wk[0] + wk[1] + wk[2] + wk[3] == 0) continue;
        const wb_real *dm = &v->pd[PD * j], ad = dm[PD_AD], ah = dm[PD_AH];
        wb_real F[9], G[9], gd[4][3], gh[4][3];
        deformation_of(p, dm, x, F);
        wb_real ic = 0;
        for (int k = 0; k < 9; k++) ic += F[k] * F[k];
        const wb_real cd = sqrt(ic);
        /* deviatoric: dC_D/dF = F / C_D; a tet crushed to a point has no direction */
        const bool dev = cd > (wb_real)1e-12;
        if (dev) {
            for (int k = 0; k < 9; k++) G[k] = F[k] / cd;
            grads(dm, G, gd);
        }
        /* hydrostatic: dJ/dF = cof F, its columns f1 x f2, f2 x f0, f0 x f1 */
        const wb_real f0[3] = { F[0], F[3], F[6] }, f1[3] = { F[1], F[4], F[7] }, f2[3] = { F[2], F[5], F[8] };
        wb_real c0[3], c1[3], c2[3];
        v3_cross(c0, f1, f2);
        v3_cross(c1, f2, f0);
        v3_cross(c2, f0, f1);
        for (int r = 0; r < 3; r++) { G[3 * r] = c0[r]; G[3 * r + 1] = c1[r]; G[3 * r + 2] = c2[r]; }
        grads(dm, G, gh);
        const wb_real ch = v3_dot(f0, c0) - dm[PD_A];
        const wb_real rh = -ch - ah * v->lh[j];
        const wb_real a22 = wdot(wk, gh, gh) + ah;
        wb_real dd = 0, dh;
        if (dev) {
            const wb_real k22 = a22 - ah, k12 = wdot(wk, gd, gh), k11 = wdot(wk, gd, gd), rd = -cd - ad * v->ld[j];
            /* det = k11 k22 - k12^2 + ad k22 + ah k11 + ad ah; the gradients are nearly
             * parallel near rest, so k11 k22 - k12^2 (>= 0) is not formed by subtraction
             * (it cancels to noise on stiff or sliver tets) but as k22 |gd - (k12/k22) gh|^2 */
            wb_real gram = 0;
            if (k22 > 0) {
                const wb_real c = k12 / k22;
                wb_real o[4][3];
                for (int k = 0; k < 4; k++)
                    for (int r = 0; r < 3; r++) o[k][r] = gd[k][r] - c * gh[k][r];
                gram = k22 * wdot(wk, o, o);
            }
            const wb_real a11 = k11 + ad, a12 = k12;
            const wb_real det = gram + ad * k22 + ah * k11 + ad * ah;
            if (!(det > 0) || !isfinite(det)) continue;
            dd = (rd * a22 - a12 * rh) / det;
            dh = (a11 * rh - a12 * rd) / det;
        } else {
            if (!(a22 > 0) || !isfinite(a22)) continue;
            dh = rh / a22;
        }
        v->ld[j] += dd;
        v->lh[j] += dh;
        for (int k = 0; k < 4; k++)
            if (wk[k] > 0)
                for (int r = 0; r < 3; r++) x[3 * p[k] + r] += wk[k] * ((dev ? gd[k][r] * dd : 0) + gh[k][r] * dh);
    }
}

#if defined(__x86_64__) && defined(__GNUC__) && !defined(WB_FLOAT)
#define WB_TET_AVX2 1
#include <immintrin.h>

typedef __m256d V4;
#define TGT __attribute__((always_inline, target("avx2"))) static inline
TGT V4 add(V4 a, V4 b) { return _mm256_add_pd(a, b); }
TGT V4 sub(V4 a, V4 b) { return _mm256_sub_pd(a, b); }
TGT V4 mul(V4 a, V4 b) { return _mm256_mul_pd(a, b); }
TGT V4 dv(V4 a, V4 b) { return _mm256_div_pd(a, b); }
TGT V4 neg(V4 a) { return _mm256_xor_pd(a, _mm256_set1_pd(-0.0)); }
/* b where m, else a */
TGT V4 pick(V4 a, V4 b, V4 m) { return _mm256_blendv_pd(a, b, m); }
TGT V4 dot3(const V4 a[3], const V4 b[3]) { return add(add(mul(a[0], b[0]), mul(a[1], b[1])), mul(a[2], b[2])); }

/* columns of the 4x4 block of rows r0..r3 */
TGT void transpose4(V4 r0, V4 r1, V4 r2, V4 r3, V4 *c)
{
    const V4 t0 = _mm256_unpacklo_pd(r0, r1), t1 = _mm256_unpackhi_pd(r0, r1);
    const V4 t2 = _mm256_unpacklo_pd(r2, r3), t3 = _mm256_unpackhi_pd(r2, r3);
    c[0] = _mm256_permute2f128_pd(t0, t2, 0x20);
    c[1] = _mm256_permute2f128_pd(t1, t3, 0x20);
    c[2] = _mm256_permute2f128_pd(t0, t2, 0x31);
    c[3] = _mm256_permute2f128_pd(t1, t3, 0x31);
}

/* the x, y, z of 4 particles as lanes (distance.c's load4): maskload leaves the 4th double
 * alone (the last particle ends the array) */
TGT void load4(const wb_real *x, int32_t i0, int32_t i1, int32_t i2, int32_t i3, V4 out[3])
{
    const __m256i m = _mm256_set_epi64x(0, -1, -1, -1);
    V4 c[4];
    transpose4(_mm256_maskload_pd(&x[3 * i0], m), _mm256_maskload_pd(&x[3 * i1], m), _mm256_maskload_pd(&x[3 * i2], m),
               _mm256_maskload_pd(&x[3 * i3], m), c);
    out[0] = c[0]; out[1] = c[1]; out[2] = c[2];
}

/* the gradients of a constraint with dC/dF = G (G[3r + c] lanes), grads() lane by lane */
TGT void grads4(const V4 *D, const V4 *G, V4 g[4][3])
{
    for (int k = 0; k < 3; k++)
        for (int r = 0; r < 3; r++)
            g[k + 1][r] = add(add(mul(G[3 * r], D[3 * k]), mul(G[3 * r + 1], D[3 * k + 1])), mul(G[3 * r + 2], D[3 * k + 2]));
    for (int r = 0; r < 3; r++) g[0][r] = neg(add(add(g[1][r], g[2][r]), g[3][r]));
}

TGT V4 wdot4(const V4 wk[4], V4 a[4][3], V4 b[4][3])
{
    V4 s = _mm256_setzero_pd();
    for (int k = 0; k < 4; k++) s = add(s, mul(wk[k], dot3(a[k], b[k])));
    return s;
}

/* project_scalar four tets at a time (a conflict-free batch: no tet reads a particle that
 * another writes), every lane doing the scalar operations in the scalar order without FMA
 * (-ffp-contract=off), so the bits are the scalar loop's whatever the lanes' grouping:
 * the same for any chunking of a batch, so for any thread count. The branches are masks
 * and blends. Measured (tests/bench/tets.lua, AMD EPYC VM, make bench build): 928 -> 269
 * instructions per tet (callgrind), 148 -> 37 ns of CPU per tet (perf samples, load ~10)
 * against the scalar loop with its per-tet divisions for the compliances. */
static __attribute__((target("avx2"))) void project_range4(wb_world *w, int32_t lo, int32_t hi)
{
    wb_neos *v = w->neo;
    const wb_real *wv = w->m.w;
    wb_real *x = w->s.x;
    const V4 zero = _mm256_setzero_pd(), inf = _mm256_set1_pd(INFINITY), tiny = _mm256_set1_pd(1e-12);
    int32_t j = lo;
    for (; j + 4 <= hi; j += 4) {
        const int32_t *p = &v->pk[4 * j]; /* p[4 l + k]: corner k of lane l */
        V4 wk[4];
        for (int k = 0; k < 4; k++) wk[k] = _mm256_set_pd(wv[p[12 + k]], wv[p[8 + k]], wv[p[4 + k]], wv[p[k]]);
        const V4 any = _mm256_cmp_pd(add(add(add(wk[0], wk[1]), wk[2]), wk[3]), zero, _CMP_NEQ_UQ);
        if (!_mm256_movemask_pd(any)) continue;
        V4 D[12];
        const wb_real *pd = &v->pd[PD * j];
        for (int b = 0; b < 3; b++)
            transpose4(_mm256_loadu_pd(&pd[4 * b]), _mm256_loadu_pd(&pd[PD + 4 * b]),
                       _mm256_loadu_pd(&pd[2 * PD + 4 * b]), _mm256_loadu_pd(&pd[3 * PD + 4 * b]), &D[4 * b]);
        const V4 ad = D[PD_AD], ah = D[PD_AH];
        V4 X[4][3], e[3][3], F[9], G[9], gd[4][3], gh[4][3];
        for (int k = 0; k < 4; k++) load4(x, p[k], p[4 + k], p[8 + k], p[12 + k], X[k]);
        for (int k = 0; k < 3; k++)
            for (int r = 0; r < 3; r++) e[k][r] = sub(X[k + 1][r], X[0][r]);
        for (int r = 0; r < 3; r++)
            for (int c = 0; c < 3; c++)
                F[3 * r + c] = add(add(mul(e[0][r], D[c]), mul(e[1][r], D[3 + c])), mul(e[2][r], D[6 + c]));
        V4 ic = zero;
        for (int k = 0; k < 9; k++) ic = add(ic, mul(F[k], F[k]));
        const V4 cd = _mm256_sqrt_pd(ic);
        const V4 dev = _mm256_cmp_pd(cd, tiny, _CMP_GT_OQ);
        for (int k = 0; k < 9; k++) G[k] = dv(F[k], cd);
        grads4(D, G, gd);
        const V4 f0[3] = { F[0], F[3], F[6] }, f1[3] = { F[1], F[4], F[7] }, f2[3] = { F[2], F[5], F[8] };
        for (int r = 0; r < 3; r++) { /* v3_cross, componentwise */
            const int r1 = (r + 1) % 3, r2 = (r + 2) % 3;
            G[3 * r] = sub(mul(f1[r1], f2[r2]), mul(f1[r2], f2[r1]));
            G[3 * r + 1] = sub(mul(f2[r1], f0[r2]), mul(f2[r2], f0[r1]));
            G[3 * r + 2] = sub(mul(f0[r1], f1[r2]), mul(f0[r2], f1[r1]));
        }
        grads4(D, G, gh);
        const V4 c0[3] = { G[0], G[3], G[6] };
        const V4 ch = sub(dot3(f0, c0), D[PD_A]);
        const V4 lh = _mm256_loadu_pd(&v->lh[j]), ld = _mm256_loadu_pd(&v->ld[j]);
        const V4 rh = sub(neg(ch), mul(ah, lh));
        const V4 a22 = add(wdot4(wk, gh, gh), ah);
        /* the deviatoric lanes */
        const V4 k22 = sub(a22, ah), k12 = wdot4(wk, gd, gh), k11 = wdot4(wk, gd, gd);
        const V4 rd = sub(neg(cd), mul(ad, ld));
        const V4 c = dv(k12, k22);
        V4 o[4][3];
        for (int k = 0; k < 4; k++)
            for (int r = 0; r < 3; r++) o[k][r] = sub(gd[k][r], mul(c, gh[k][r]));
        const V4 gram = pick(zero, mul(k22, wdot4(wk, o, o)), _mm256_cmp_pd(k22, zero, _CMP_GT_OQ));
        const V4 a11 = add(k11, ad);
        const V4 det = add(add(add(gram, mul(ad, k22)), mul(ah, k11)), mul(ad, ah));
        const V4 okd = _mm256_and_pd(_mm256_cmp_pd(det, zero, _CMP_GT_OQ), _mm256_cmp_pd(det, inf, _CMP_LT_OQ));
        const V4 dd = pick(zero, dv(sub(mul(rd, a22), mul(k12, rh)), det), dev);
        V4 dh = dv(sub(mul(a11, rh), mul(k12, rd)), det), ok = okd;
        if (_mm256_movemask_pd(dev) != 15) { /* a lane crushed to a point: the hydrostatic one alone */
            const V4 okh = _mm256_and_pd(_mm256_cmp_pd(a22, zero, _CMP_GT_OQ), _mm256_cmp_pd(a22, inf, _CMP_LT_OQ));
            dh = pick(dv(rh, a22), dh, dev);
            ok = pick(okh, okd, dev);
        }
        const V4 live = _mm256_and_pd(any, ok);
        const int lm = _mm256_movemask_pd(live);
        if (!lm) continue;
        _mm256_storeu_pd(&v->ld[j], pick(ld, add(ld, dd), live));
        _mm256_storeu_pd(&v->lh[j], pick(lh, add(lh, dh), live));
        /* the new positions (x + wk ((gd dd) + gh dh), as the scalar +=) back in rows:
         * 3 doubles a particle, stored where the corner moves */
        for (int k = 0; k < 4; k++) {
            V4 q[4];
            for (int r = 0; r < 3; r++)
                q[r] = add(X[k][r], mul(wk[k], add(pick(zero, mul(gd[k][r], dd), dev), mul(gh[k][r], dh))));
            q[3] = zero;
            const int wm = _mm256_movemask_pd(_mm256_cmp_pd(wk[k], zero, _CMP_GT_OQ)) & lm;
            V4 row[4];
            transpose4(q[0], q[1], q[2], q[3], row);
            for (int l = 0; l < 4; l++)
                if (wm >> l & 1) {
                    wb_real *o = &x[3 * p[4 * l + k]];
                    _mm_storeu_pd(o, _mm256_castpd256_pd128(row[l]));
                    _mm_store_sd(o + 2, _mm256_extractf128_pd(row[l], 1));
                }
        }
    }
    if (j < hi) project_scalar(w, j, hi);
}
#endif

/* the vector path: -1 not yet decided, 0 off (no AVX2, or turned off), 1 on */
static int simd_state = -1;

/* Internal switch for tests (distance.c's wb__distance_simd for the tets): on = 0 forces
 * the scalar loop, on = 1 uses the vector path where the CPU has it; returns whether the
 * vector path is on. Not thread-safe: call it between steps. */
int wb__tet_simd(int on);
int wb__tet_simd(int on) { return wb__simd_set(&simd_state, on); }

/* order[lo, hi) of one batch (batch.h): the packed copies are in that order already */
static void project_range(wb_world *w, const int32_t *order, int32_t lo, int32_t hi, wb_real h)
{
    (void)order;
    (void)h;
#ifdef WB_TET_AVX2
    const wb_batches *bt = &w->neo->bt;
    /* the lanes need a conflict-free batch: never the serial tail */
    if (hi - lo >= 4 && hi <= bt->colour_start[bt->serial_start]) {
        int s = __atomic_load_n(&simd_state, __ATOMIC_RELAXED); /* possibly decided by several threads at once */
        if (s < 0) s = wb__tet_simd(1);
        if (s) {
            project_range4(w, lo, hi);
            return;
        }
    }
#endif
    project_scalar(w, lo, hi);
}

/* batch after batch in colour order, a batch in parallel chunks (a batch shares no
 * movable particle): the same bits for any thread count */
static void tet_project(wb_world *w, wb_real h)
{
    wb_neos *v = w->neo;
    if (!v) return;
    if (v->pd_h != h) {
        /* the compliances over h^2, divided once per substep length instead of per
         * projection (the same divisions: the same bits) */
        const wb_real inv_h2 = 1 / (h * h);
        for (int32_t j = 0; j < v->n; j++) {
            const int32_t i = v->order[j];
            v->pd[PD * j + PD_AD] = inv_h2 / (v->mu[i] * v->v0[i]);
            v->pd[PD * j + PD_AH] = inv_h2 / (v->lam[i] * v->v0[i]);
        }
        v->pd_h = h;
    }
    wb__batches_run(&v->bt, w, 64, project_range, NULL, v->order, h);
    w->k.projections += v->n; /* a tet (both of its constraints) is one projection */
}

/* both constraints of each coloured tet (as project_scalar forms them) */
static wb_real tet_residual(const wb_world *w, wb_real h)
{
    const wb_neos *v = w->neo;
    if (!v || v->bt.n <= 0 || !(v->pd_h > 0)) return 0;
    const wb_real *x = w->s.x, *wv = w->m.w, s2 = (v->pd_h / h) * (v->pd_h / h);
    wb_real r = 0;
    for (int32_t j = 0; j < v->bt.n; j++) {
        const int32_t *p = &v->pk[4 * j];
        if (wv[p[0]] + wv[p[1]] + wv[p[2]] + wv[p[3]] == 0) continue;
        const wb_real *dm = &v->pd[PD * j];
        wb_real F[9], G[9], g[4][3], ic = 0;
        deformation_of(p, dm, x, F);
        for (int k = 0; k < 9; k++) ic += F[k] * F[k];
        const wb_real cd = sqrt(ic);
        if (cd > (wb_real)1e-12) {
            for (int k = 0; k < 9; k++) G[k] = F[k] / cd;
            grads(dm, G, g);
            const wb_real ones[4] = { 1, 1, 1, 1 }, ri = wb__residual(cd + dm[PD_AD] * s2 * v->ld[j], wdot(ones, g, g), 4);
            r = ri > r ? ri : r;
        }
        const wb_real f0[3] = { F[0], F[3], F[6] }, f1[3] = { F[1], F[4], F[7] }, f2[3] = { F[2], F[5], F[8] };
        wb_real c[3][3];
        v3_cross(c[0], f1, f2);
        v3_cross(c[1], f2, f0);
        v3_cross(c[2], f0, f1);
        for (int a = 0; a < 3; a++)
            for (int b = 0; b < 3; b++) G[3 * a + b] = c[b][a];
        grads(dm, G, g);
        const wb_real ones[4] = { 1, 1, 1, 1 };
        const wb_real ri = wb__residual(v3_dot(f0, c[0]) - dm[PD_A] + dm[PD_AH] * s2 * v->lh[j], wdot(ones, g, g), 4);
        r = ri > r ? ri : r;
    }
    return r;
}

static wb_real tet_energy(const wb_world *w)
{
    wb_real e = 0;
    for (int32_t i = 0; i < wb_tet_count(w); i++) e += energy_of(w->neo, w->s.x, i);
    return e;
}

static void tet_links(const wb_world *w, wb_link_fn fn, void *ud)
{
    if (w->neo) wb__link_quads(w->neo->ijkl, w->neo->n, fn, ud);
}

static void tet_joins(const wb_world *w, wb_link_fn fn, void *ud)
{
    if (w->neo) wb__join_elements(w->neo->ijkl, w->neo->n, 4, fn, ud);
}

/* ---- teardown and hash (ctype.h) --------------------------------------------------------- */
static void tet_destroy(wb_world *w)
{
    wb_neos *v = w->neo;
    if (!v) return;
    void *a[] = { v->ijkl, v->dminv, v->v0, v->young, v->poisson, v->mu, v->lam, v->ld, v->lh, v->order, v->pk, v->pd,
                  v->yield, v->creep };
    for (size_t i = 0; i < sizeof a / sizeof a[0]; i++) free(a[i]);
    free(v);
    w->neo = NULL;
}

static size_t tet_charged(const wb_world *w) { return w->neo ? w->neo->charged : 0; }

/* plastic tets' rest state flows (state), and how; elastic ones add nothing */
static uint64_t tet_hash(const wb_world *w, uint64_t h)
{
    const wb_neos *ne = w->neo;
    if (!ne || !ne->plastic) return h;
    h = wb__fnv(h, ne->dminv, sizeof(wb_real) * 9 * (size_t)ne->n);
    h = wb__fnv(h, ne->v0, sizeof(wb_real) * (size_t)ne->n);
    h = wb__fnv(h, ne->yield, sizeof(wb_real) * (size_t)ne->n);
    return wb__fnv(h, ne->creep, sizeof(wb_real) * (size_t)ne->n);
}

static void tet_stats(const wb_world *w, wb_stats *st)
{
    st->tets = wb_tet_count(w);
}

/* ---- the VBD solver's part (vbd.h) --------------------------------------------------------- */
/* the tets at each vertex, as 4 tet + corner */
typedef struct tet_vbd {
    wb_vbd_quads at;
    size_t charged;        /* its bytes charged to def.memory */
} tet_vbd;

static void *tvbd_make(void) { return calloc(1, sizeof(tet_vbd)); }

static void tvbd_free(wb_world *w, void *part)
{
    tet_vbd *p = part;
    wb__vbd_quads_free(&p->at);
    wb__charge(w, &p->charged, 0);
    free(p);
}

static int32_t tvbd_slots(const wb_world *w) { return w->neo ? w->neo->n : 0; }

static int tvbd_build(wb_world *w, void *part)
{
    tet_vbd *p = part;
    const int32_t n = tvbd_slots(w);
    return wb__charge(w, &p->charged, sizeof *p + wb__vbd_quads_bytes(w->m.np, n)) &&
           wb__vbd_quads_build(&p->at, w->m.np, w->neo ? w->neo->ijkl : NULL, n);
}

static uint64_t tvbd_neighbours(const wb_world *w, const void *part, int32_t i, const uint8_t *col)
{
    return wb__vbd_quads_colours(&((const tet_vbd *)part)->at, w->neo ? w->neo->ijkl : NULL, i, col);
}

static int tvbd_holds(const void *part, int32_t i) { return wb__vbd_quads_hold(&((const tet_vbd *)part)->at, i); }

/* A Neo-Hookean tet's energy on corner k, in its constraint form (tet_project): V0 (mu/2 |F|^2 +
 * lam/2 (det F - a)^2), a = 1 + mu/lam, F = sum_k x_k b_k^T (b_k: row k-1 of Dm^-1, b_0
 * minus their sum). The first term is quadratic in x: its block is exact, mu V0 |b_k|^2 I;
 * the second's is Gauss-Newton, lam V0 g g^T with g = cof(F) b_k (what is left, (det F -
 * a) times J's second derivative, is indefinite: left out, as VBD does) */
static void tet_block(const wb_world *w, int32_t q, wb_real f[3], wb_real H[6])
{
    const wb_neos *nv = w->neo;
    const int32_t t = q / 4, k = q % 4, *p = &nv->ijkl[4 * t];
    const wb_real *d = &nv->dminv[9 * t], *x = w->s.x, V = nv->v0[t], mu = nv->mu[t], lam = nv->lam[t];
    wb_real F[9], e[3][3], b[3];
    for (int c = 0; c < 3; c++) v3_sub(e[c], &x[3 * p[c + 1]], &x[3 * p[0]]);
    for (int r = 0; r < 3; r++)
        for (int c = 0; c < 3; c++) F[3 * r + c] = e[0][r] * d[c] + e[1][r] * d[3 + c] + e[2][r] * d[6 + c];
    if (k > 0) v3_copy(b, &d[3 * (k - 1)]);
    else for (int c = 0; c < 3; c++) b[c] = -(d[c] + d[3 + c] + d[6 + c]);
    /* the columns of F and of its cofactor */
    const wb_real f0[3] = { F[0], F[3], F[6] }, f1[3] = { F[1], F[4], F[7] }, f2[3] = { F[2], F[5], F[8] };
    wb_real c0[3], c1[3], c2[3], Fb[3], g[3];
    v3_cross(c0, f1, f2);
    v3_cross(c1, f2, f0);
    v3_cross(c2, f0, f1);
    for (int r = 0; r < 3; r++) {
        Fb[r] = F[3 * r] * b[0] + F[3 * r + 1] * b[1] + F[3 * r + 2] * b[2];
        g[r] = c0[r] * b[0] + c1[r] * b[1] + c2[r] * b[2];
    }
    const wb_real J = v3_dot(f0, c0), s = lam * V * (J - (1 + mu / lam)), kd = mu * V * v3_dot(b, b), kh = lam * V;
    for (int r = 0; r < 3; r++) f[r] -= mu * V * Fb[r] + s * g[r];
    H[0] += kd + kh * g[0] * g[0], H[1] += kd + kh * g[1] * g[1], H[2] += kd + kh * g[2] * g[2];
    H[3] += kh * g[0] * g[1], H[4] += kh * g[0] * g[2], H[5] += kh * g[1] * g[2];
}

static void tvbd_vertex(const wb_world *w, const void *part, const int32_t *vert, int32_t n, wb_real inv_h, wb_real *f,
                        wb_real *H)
{
    (void)inv_h;
    const wb_vbd_quads *a = &((const tet_vbd *)part)->at;
    for (int32_t k = 0; k < n; k++)
        for (int32_t e = a->start[vert[k]]; e < a->start[vert[k] + 1]; e++) tet_block(w, a->adj[e], &f[3 * k], &H[6 * k]);
}

static const wb_vbd_type tet_vbd_hooks = {
    .make = tvbd_make,
    .free = tvbd_free,
    .slots = tvbd_slots,
    .build = tvbd_build,
    .neighbours = tvbd_neighbours,
    .holds = tvbd_holds,
    .vertex = tvbd_vertex,
};

const int32_t *wb__tet_corners(const wb_world *w) { return w->neo ? w->neo->ijkl : NULL; }

const wb_ctype wb__tet_type = {
    .name = "tet",
    .count = tet_count,
    .prepare = tet_prepare,
    .substep_begin = tet_substep_begin,
    .project = tet_project,
    .frame_end = tet_frame_end,
    .energy = tet_energy,
    .links = tet_links,
    .joins = tet_joins,
    .destroy = tet_destroy,
    .charged = tet_charged,
    .stats = tet_stats,
    .hash = tet_hash,
    .image_free = tet_image_free,
    .image_save = tet_image_save,
    .image_check = tet_image_check,
    .image_reserve = tet_image_reserve,
    .image_put = tet_image_put,
    .residual = tet_residual,
    .vbd = &tet_vbd_hooks,
};
