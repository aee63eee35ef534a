/* vbd_contact.c: the particle-particle contacts as energies in VBD's vertex steps
 * (docs/physics.md, "VBD"), as Augmented Vertex Block Descent has them (Giles, Diaz,
 * Yuksel, SIGGRAPH 2025): each pair an inequality constraint C = |x_i - x_j| - target >= 0
 * with a penalty k and a multiplier lambda >= 0, its force on i along the pair's normal
 * max(0, lambda - k C), Hessian k n n^T while it pushes; lambda grows by -k C after each
 * sweep, clamped at 0 (not carried to the next substep: carried whole, a block on a
 * slab chattered between 0 and 4 times its weight and crept 4.4 mm in 1 s; 0.9 of it,
 * 1.2 mm).
 *
 * Friction: Coulomb's, mu times a lagged normal force (as IPC and Chen et al.'s VBD lag
 * it), the pair's force where the last substep's solve left it (wb__vbdc_end; the force
 * of the same evaluation, from the prediction, was 8 times the weight). Not as their
 * smoothed energy (mu f_n f1(|u|), one Newton step on it): with one step a substep it
 * stopped half of the slip it could (a block at 0.95 of its sticking angle crept 29 mm
 * in 1 s, a particle on a pinned one slid 2.2% too far), but exactly within the cone,
 * after the vertex's Newton step (wb__vbdc_friction): its slip over the substep across
 * its contacts' mean normal undone if the force that takes, its Hessian times the slip,
 * is within sum mu f_n, else cut by that much. A free body's pairs leave theirs to its
 * momentum step (vbd.c's keep_momentum, wb__vbdc_body), which does the same for the
 * body's translation.
 *
 * Served: pairs of one movable and one immovable particle (a body on a pinned slab).
 * Pairs of two movable particles stay with the projection after the sweeps: Gauss-Seidel
 * over vertices gives the two ends unequal impulses, so a pair's momentum is not kept
 * (two particles meeting head-on at substeps = 1 left at 0.447 and 0.143 m/s where
 * perfectly inelastic is 0.143 for both; tests/validation/depenetration.lua).
 *
 * The contacts projected after the sweeps (contact.c) still run and take what the
 * sweeps left (a penalty leaves 1 / (1 + VBDC_K) of a resting overlap); their friction
 * acts on that part, this file's on the solve's. A made overlap parts no
 * faster than max_depenetration because the target keeps what contact.c's rule keeps
 * (wb__contact_depth).
 *
 * Determinism: a vertex reads its partners from a copy of the positions brought up to
 * date after each colour, never from x, so a partner of the same colour (contacts are not
 * in the colouring) is read as it was before the colour, whichever thread steps it. */
#include <stdlib.h>
#include <string.h>

#include "contact.h"
#include "vbd_contact.h"

/* the penalty, in units of the inertia of the pair's ends over the substep
 * 1 / (h^2 (w_i + w_j)), as a rigid link's (vbd.c) */
#define VBDC_K ((wb_real)8)
/* a candidate whose ends are closer than this times r_i + r_j at the sweeps' start is in
 * the substep's contacts (the ones farther apart are left to the projection after) */
#define VBDC_NEAR ((wb_real)1.25)

typedef struct vbdc_key {
    uint64_t key; /* i << 32 | j */
    int32_t k;    /* the candidate */
} vbdc_key;

static int by_key(const void *a, const void *b)
{
    const uint64_t p = ((const vbdc_key *)a)->key, q = ((const vbdc_key *)b)->key;
    return (p > q) - (p < q);
}

struct wb_vbdc {
    int32_t *start;          /* (np + 1) each vertex's range of ent */
    int32_t *ent;            /* 2 pair + side (0: the vertex is the pair's i) */
    int32_t *pij;            /* (npair x 2) */
    wb_real *tgt, *kk, *lam, *mu; /* (npair) */
    wb_real *ov, *ove;       /* (npair) its overlap of the target as the sweeps began and as
                                the last left it (the readout: what they corrected) */
    int32_t npair;
    int32_t *prev;           /* (nprev x 2) the last substep's pairs, with fend: prevf */
    wb_real *fend, *prevf;   /* (npair) each pair's normal force as the substep's solve left
                                it (wb__vbdc_end) */
    wb_real *lamp;           /* (npair) the multiplier before the last sweep's update */
    uint8_t *sf;             /* (npair) 1: its friction acts in the vertex steps (0: in its
                                body's momentum step, vbd.c) */
    wb_real *fl;             /* (npair) the normal force its friction takes: the last
                                substep's (lagged; the projection after the solve has its
                                own friction for its own part) */
    int32_t nprev;
    int sorted;              /* pij in (i, j) order (0: not set up) */
    vbdc_key *ks;            /* (candidates) the near ones' keys, sorted */
    int32_t cap_ks;
    wb_real *xc;             /* (np x 3) the copy partners are read from (contact ends only) */
    int32_t *cv;             /* the vertices with contacts, by colour */
    int32_t *cvs;            /* (ncolours + 1) ranges of cv */
    int32_t cap_np, cap_pair, cap_col;
    size_t charged;          /* its bytes charged to def.memory (given back by wb__vbdc_destroy) */
};

void wb__vbdc_destroy(wb_world *w, wb_vbdc *c)
{
    if (!c) return;
    wb__charge(w, &c->charged, 0);
    free(c->start), free(c->ent), free(c->pij), free(c->tgt), free(c->kk), free(c->lam), free(c->mu);
    free(c->ov), free(c->ove), free(c->prev), free(c->fend), free(c->prevf), free(c->fl), free(c->lamp), free(c->sf), free(c->ks), free(c->xc), free(c->cv), free(c->cvs);
    free(c);
}

/* what c holds at these capacities: the struct, the per-vertex arrays (start, cv, xc), the
 * per-pair ones (ent 2, pij 2, prev 2 ints; tgt, kk, lam, mu, ov, ove, fend, prevf, fl,
 * lamp reals; sf 1 byte), the keys and the colour ranges */
static size_t bytes_at(int64_t np, int64_t npair, int64_t ncol1, int64_t nks)
{
    return sizeof(wb_vbdc) + (size_t)np * (2 * sizeof(int32_t) + 3 * sizeof(wb_real)) + sizeof(int32_t) +
           (size_t)npair * (6 * sizeof(int32_t) + 10 * sizeof(wb_real) + 1) + (size_t)nks * sizeof(vbdc_key) +
           (size_t)ncol1 * sizeof(int32_t);
}

/* room for np vertices, npair pairs, ncol colours and nks keys, charged to the memory
 * budget before it is taken; 0 when the budget refuses it or out of memory */
static int grow(wb_world *w, wb_vbdc *c, int32_t np, int32_t npair, int32_t ncol, int32_t nks)
{
    const int32_t cnp = np > c->cap_np ? np : c->cap_np, cpair = npair > c->cap_pair ? npair : c->cap_pair;
    const int32_t ccol = ncol + 1 > c->cap_col ? ncol + 1 : c->cap_col, cks = nks > c->cap_ks ? nks : c->cap_ks;
    if (!wb__charge(w, &c->charged, bytes_at(cnp, cpair, ccol, cks))) return 0;
    if (nks > c->cap_ks) {
        vbdc_key *ks = realloc(c->ks, sizeof *ks * (size_t)nks);
        if (!ks) return 0;
        c->ks = ks, c->cap_ks = nks;
    }
    if (np > c->cap_np) {
        int32_t *s = realloc(c->start, sizeof *s * ((size_t)np + 1)), *v = realloc(c->cv, sizeof *v * (size_t)np);
        if (s) c->start = s;
        if (v) c->cv = v;
        wb_real *x = realloc(c->xc, sizeof *x * 3 * (size_t)np);
        if (x) c->xc = x;
        if (!s || !v || !x) return 0;
        c->cap_np = np;
    }
    if (npair > c->cap_pair) {
        const size_t n = (size_t)npair;
        int32_t *e = realloc(c->ent, sizeof *e * 2 * n), *p = realloc(c->pij, sizeof *p * 2 * n);
        if (e) c->ent = e;
        if (p) c->pij = p;
        wb_real *r[4] = { realloc(c->tgt, sizeof(wb_real) * n), NULL, NULL, NULL };
        if (r[0]) c->tgt = r[0];
        r[1] = realloc(c->kk, sizeof(wb_real) * n);
        if (r[1]) c->kk = r[1];
        r[2] = realloc(c->lam, sizeof(wb_real) * n);
        if (r[2]) c->lam = r[2];
        r[3] = realloc(c->mu, sizeof(wb_real) * n);
        if (r[3]) c->mu = r[3];
        wb_real *ov = realloc(c->ov, sizeof *ov * n), *ove = realloc(c->ove, sizeof *ove * n);
        if (ov) c->ov = ov;
        if (ove) c->ove = ove;
        int32_t *pv = realloc(c->prev, sizeof *pv * 2 * n);
        if (pv) c->prev = pv;
        wb_real *q[3] = { realloc(c->fend, sizeof(wb_real) * n), NULL, NULL };
        if (q[0]) c->fend = q[0];
        q[1] = realloc(c->prevf, sizeof(wb_real) * n);
        if (q[1]) c->prevf = q[1];
        q[2] = realloc(c->fl, sizeof(wb_real) * n);
        if (q[2]) c->fl = q[2];
        wb_real *lp = realloc(c->lamp, sizeof *lp * n);
        if (lp) c->lamp = lp;
        uint8_t *sf = realloc(c->sf, n);
        if (sf) c->sf = sf;
        if (!e || !p || !r[0] || !r[1] || !r[2] || !r[3] || !ov || !ove || !pv || !q[0] || !q[1] || !q[2] || !lp || !sf) return 0;
        c->cap_pair = npair;
    }
    if (ncol + 1 > c->cap_col) {
        int32_t *s = realloc(c->cvs, sizeof *s * ((size_t)ncol + 1));
        if (!s) return 0;
        c->cvs = s, c->cap_col = ncol + 1;
    }
    return 1;
}

/* candidate k is a pair it serves: one movable end (see the head of the file for why not
 * two), closer than VBDC_NEAR (r_i + r_j) */
static inline int near_pair(const wb_contacts *pc, const wb_real *x, const wb_real *wv, const wb_real *rad, int32_t k)
{
    const int32_t i = pc->ij[2 * k], j = pc->ij[2 * k + 1];
    if (!(wv[i] > 0) == !(wv[j] > 0)) return 0;
    const wb_real rn = (rad[i] + rad[j]) * VBDC_NEAR;
    wb_real d[3];
    v3_sub(d, &x[3 * i], &x[3 * j]);
    return v3_dot(d, d) < rn * rn;
}

int wb__vbdc_begin(wb_world *w, wb_vbdc **cp, wb_real h, const int32_t *order, const int32_t *colour_start,
                   int32_t ncolours, const uint8_t *bmoved)
{
    const wb_contacts *pc = w->k.pc;
    wb_vbdc *c = *cp;
    if (c) {
        /* the last substep's pairs and forces kept for the friction's lag (swapped) */
        int32_t *t = c->prev;
        c->prev = c->pij, c->pij = t;
        wb_real *f = c->prevf;
        c->prevf = c->fend, c->fend = f;
        c->nprev = c->sorted ? c->npair : 0;
        c->npair = 0;
        c->sorted = 0;
    }
    if (pc->n == 0) return 0;
    const wb_model *m = &w->m;
    const int32_t np = m->np;
    const wb_real *x = w->s.x, *xp = w->s.x_prev, *wv = m->w, *rad = m->radius, *cf = m->cfric;
    /* the pairs it serves, counted before anything is sized: a handful of the frame's
     * candidates (a self-colliding cloth has hundreds of thousands and none of them) */
    int32_t n = 0;
    for (int32_t k = 0; k < pc->n; k++)
        n += near_pair(pc, x, wv, rad, k);
    if (n == 0) {
        if (c) c->sorted = 1; /* (no pairs: none lagged into the next substep) */
        return 0;
    }
    if (!c) {
        c = calloc(1, sizeof *c);
        if (!c) return -1;
        *cp = c;
    }
    if (!grow(w, c, np, n > c->nprev ? n : c->nprev, ncolours, n)) {
        c->nprev = 0;
        return -1;
    }
    vbdc_key *ks = c->ks;
    const wb_real step = m->def.max_depenetration * h, inv_h2 = 1 / (h * h);
    /* what each pair was left with by the last projection (contact.c), known within a
     * frame's list; a new list's rule otherwise */
    const wb_real *left = !pc->fresh && pc->left && pc->cap_left >= pc->n ? pc->left : NULL;
    int32_t *start = c->start;
    memset(start, 0, sizeof *start * ((size_t)np + 1));
    /* the candidates near enough, in (i, j) order (the lag's and the readout's merge;
     * the broad phase's order is its own) */
    int sorted = 1;
    n = 0;
    for (int32_t k = 0; k < pc->n; k++) {
        if (!near_pair(pc, x, wv, rad, k)) continue;
        const int32_t i = pc->ij[2 * k], j = pc->ij[2 * k + 1];
        ks[n].key = (uint64_t)i << 32 | (uint32_t)j, ks[n].k = k;
        if (n > 0 && ks[n - 1].key > ks[n].key) sorted = 0;
        n++;
    }
    if (!sorted) qsort(ks, (size_t)n, sizeof *ks, by_key);
    for (int32_t q = 0; q < n; q++) {
        const int32_t k = ks[q].k, i = pc->ij[2 * k], j = pc->ij[2 * k + 1];
        const wb_real wsum = wv[i] + wv[j], r = rad[i] + rad[j];
        wb_real d[3];
        v3_sub(d, &x[3 * i], &x[3 * j]);
        const wb_real l1 = v3_len(d);
        /* the overlap it keeps this substep, as wb__contact_depth works it out */
        v3_sub(d, &xp[3 * i], &xp[3 * j]);
        wb_real d0 = r - v3_len(d);
        d0 = d0 > 0 ? d0 : 0;
        wb_real l = left && left[k] == left[k] ? left[k] : d0 > step ? d0 : 0;
        l = l < d0 ? l : d0;
        wb_real keep = l - step;
        keep = !(keep > 0) ? 0 : keep;
        c->pij[2 * q] = i, c->pij[2 * q + 1] = j;
        c->tgt[q] = r - keep;
        c->ov[q] = c->ove[q] = r - keep - l1;
        c->kk[q] = VBDC_K * inv_h2 / wsum;
        c->lam[q] = 0;
        c->mu[q] = (cf[i] + cf[j]) / 2;
        const int32_t mv = wv[i] > 0 ? i : j, b = bmoved && w->k.mc_body ? w->k.mc_body[mv] : -1;
        c->sf[q] = !(b >= 0 && bmoved[b]);
        if (wv[i] > 0) start[i + 1]++;
        if (wv[j] > 0) start[j + 1]++;
    }
    c->npair = n;
    c->sorted = 1;
    /* each pair's lagged normal force: the last substep's, where it had the pair (both
     * lists in (i, j) order) */
    for (int32_t q = 0, o = 0; q < n; q++) {
        const int32_t i = c->pij[2 * q], j = c->pij[2 * q + 1];
        while (o < c->nprev && (c->prev[2 * o] < i || (c->prev[2 * o] == i && c->prev[2 * o + 1] < j))) o++;
        c->fl[q] = o < c->nprev && c->prev[2 * o] == i && c->prev[2 * o + 1] == j ? c->prevf[o] : 0;
    }
    for (int32_t i = 0; i < np; i++) start[i + 1] += start[i];
    const int32_t nent = start[np];
    /* fill from the end of each range backwards, pairs in reverse: each range in pair order */
    for (int32_t q = n - 1; q >= 0; q--)
        for (int s = 1; s >= 0; s--) {
            const int32_t i = c->pij[2 * q + s];
            if (wv[i] > 0) c->ent[--start[i + 1]] = 2 * q + s;
        }
    /* (start[i + 1] now holds i's first entry) */
    memmove(start, start + 1, sizeof *start * (size_t)np);
    start[np] = nent;
    int32_t nv = 0;
    for (int32_t col = 0; col < ncolours; col++) {
        c->cvs[col] = nv;
        for (int32_t q = colour_start[col]; q < colour_start[col + 1]; q++) {
            const int32_t i = order[q];
            if (start[i + 1] > start[i]) c->cv[nv++] = i;
        }
    }
    c->cvs[ncolours] = nv;
    /* every end's copy (the immovable ones are not refreshed: they do not move in the solve) */
    for (int32_t q = 0; q < 2 * n; q++) v3_copy(&c->xc[3 * c->pij[q]], &x[3 * c->pij[q]]);
    return 1;
}

/* (sh: i moved by it, NULL: where it is) */
static inline __attribute__((always_inline)) void block(const wb_world *w, const wb_vbdc *c, const wb_real *lam, int32_t i,
                                                        const wb_real *sh, wb_real f[3], wb_real H[6], wb_real *fr)
{
    const wb_real *x = w->s.x, *xc = c->xc;
    wb_real xi[3];
    v3_copy(xi, &x[3 * i]);
    if (sh) v3_add(xi, xi, sh);
    for (int32_t e = c->start[i]; e < c->start[i + 1]; e++) {
        const int32_t q = c->ent[e] >> 1, o = c->pij[2 * q + 1 - (c->ent[e] & 1)];
        wb_real d[3];
        v3_sub(d, xi, &xc[3 * o]);
        const wb_real l2 = v3_dot(d, d);
        if (!(l2 > 1e-24)) continue;
        const wb_real l = sqrt(l2), kk = c->kk[q], fn = lam[q] - kk * (l - c->tgt[q]), fl = c->fl[q];
        if (!(fn > 0) && !(fr && fl > 0)) continue;
        wb_real n[3];
        v3_scale(n, d, 1 / l);
        if (fr && fl > 0) {
            /* (the body's friction: its capacity and the direction it pushes along) */
            fr[0] += c->mu[q] * fl;
            v3_madd(&fr[1], n, fl);
        }
        if (!(fn > 0)) continue;
        v3_madd(f, n, fn);
        H[0] += kk * n[0] * n[0], H[1] += kk * n[1] * n[1], H[2] += kk * n[2] * n[2];
        H[3] += kk * n[0] * n[1], H[4] += kk * n[0] * n[2], H[5] += kk * n[1] * n[2];
    }
}

void wb__vbdc_block(const wb_world *w, const wb_vbdc *c, int32_t i, wb_real f[3], wb_real H[6])
{
    block(w, c, c->lam, i, NULL, f, H, NULL);
}

void wb__vbdc_friction(const wb_world *w, const wb_vbdc *c, int32_t i, const wb_real H[6], wb_real xi[3])
{
    const wb_real *xc = c->xc, *xp = w->s.x_prev;
    wb_real cap = 0, N[3] = { 0, 0, 0 };
    for (int32_t e = c->start[i]; e < c->start[i + 1]; e++) {
        const int32_t q = c->ent[e] >> 1, o = c->pij[2 * q + 1 - (c->ent[e] & 1)];
        const wb_real fl = c->fl[q];
        if (!c->sf[q] || !(c->mu[q] * fl > 0)) continue;
        wb_real d[3];
        v3_sub(d, xi, &xc[3 * o]);
        const wb_real l = v3_len(d);
        if (!(l > 0)) continue;
        cap += c->mu[q] * fl;
        v3_madd(N, d, fl / l);
    }
    const wb_real nl = v3_len(N);
    if (!(cap > 0) || !(nl > 0)) return;
    v3_scale(N, N, 1 / nl);
    /* the slip over the substep across N (the partners are immovable) and the force that
     * stops it, the vertex's Hessian times it */
    wb_real u[3], Hu[3];
    v3_sub(u, xi, &xp[3 * i]);
    v3_madd(u, N, -v3_dot(u, N));
    Hu[0] = H[0] * u[0] + H[3] * u[1] + H[4] * u[2];
    Hu[1] = H[3] * u[0] + H[1] * u[1] + H[5] * u[2];
    Hu[2] = H[4] * u[0] + H[5] * u[1] + H[2] * u[2];
    v3_madd(Hu, N, -v3_dot(Hu, N));
    const wb_real need = v3_len(Hu);
    v3_madd(xi, u, -(need <= cap ? 1 : cap / need));
}

void wb__vbdc_body(const wb_world *w, const wb_vbdc *c, int32_t i, const wb_real sh[3], wb_real f[3], wb_real H[6],
                   wb_real *fr)
{
    block(w, c, c->lamp, i, sh, f, H, fr);
}

/* pair q's gap C from its target where the particles are, and the force a multiplier
 * base gives it there, clamped at 0 (the dual update of wb__vbdc_dual and _end) */
static inline wb_real pair_force(const wb_real *x, const wb_vbdc *c, int32_t q, wb_real base, wb_real *C)
{
    wb_real d[3];
    v3_sub(d, &x[3 * c->pij[2 * q]], &x[3 * c->pij[2 * q + 1]]);
    *C = v3_len(d) - c->tgt[q];
    const wb_real lm = base - c->kk[q] * *C;
    return lm > 0 ? lm : 0;
}

void wb__vbdc_end(const wb_world *w, wb_vbdc *c)
{
    for (int32_t q = 0; q < c->npair; q++) {
        wb_real C;
        c->lam[q] = c->fend[q] = pair_force(w->s.x, c, q, c->lamp[q], &C);
        c->ove[q] = -C;
    }
}

const int32_t *wb__vbdc_vertices(const wb_vbdc *c, int32_t ncolours, int32_t *n)
{
    *n = c->cvs[ncolours];
    return c->cv;
}

void wb__vbdc_colour_done(const wb_world *w, wb_vbdc *c, int32_t col)
{
    const wb_real *x = w->s.x;
    for (int32_t q = c->cvs[col]; q < c->cvs[col + 1]; q++) v3_copy(&c->xc[3 * c->cv[q]], &x[3 * c->cv[q]]);
}

void wb__vbdc_dual(const wb_world *w, wb_vbdc *c)
{
    for (int32_t q = 0; q < c->npair; q++) {
        wb_real C;
        const wb_real f = pair_force(w->s.x, c, q, c->lam[q], &C);
        c->lamp[q] = c->lam[q];
        c->lam[q] = f;
    }
}

void wb__vbdc_refresh(const wb_world *w, wb_vbdc *c, int32_t ncolours)
{
    const wb_real *x = w->s.x;
    for (int32_t q = 0; q < c->cvs[ncolours]; q++) v3_copy(&c->xc[3 * c->cv[q]], &x[3 * c->cv[q]]);
}

/* the substep's contacts as w:contacts() reads them: to what the projection after the
 * sweeps reports for a pair (its force depth / (w_i + w_j) / h^2 and that depth) the
 * force the sweeps left it pushing with (its multiplier after the last) and the overlap
 * they corrected. A pair the sweeps parted is not in the projection's list: not
 * reported. */
void wb__vbdc_readout(wb_world *w, const wb_vbdc *c)
{
    wb_contacts *pc = w->k.pc;
    if (!c || !c->sorted || c->npair == 0) return;
    for (int32_t a = 0; a < pc->nact; a++) {
        const int32_t k = pc->act[a], i = pc->ij[2 * k], j = pc->ij[2 * k + 1];
        int32_t lo = 0, hi = c->npair;
        while (lo < hi) {
            const int32_t mid = lo + (hi - lo) / 2, pi = c->pij[2 * mid], pj = c->pij[2 * mid + 1];
            if (pi < i || (pi == i && pj < j)) lo = mid + 1;
            else hi = mid;
        }
        if (!(lo < c->npair && c->pij[2 * lo] == i && c->pij[2 * lo + 1] == j)) continue;
        const wb_real done = c->ov[lo] - c->ove[lo];
        pc->act_nd[7 * a + 4] += c->lam[lo];
        if (done > 0) pc->act_nd[7 * a + 3] += done;
    }
}
