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
 * Free bodies touching each other (vbd.c's touching(): their movable particles, or a
 * point and a triangle whose corners all move) are moved together after the sweeps
 * (wb__vbdc_couple): the Newton steps of the substep's energy along their translations,
 * each pair and point-triangle contact between them a penalty (VBDC_K times its ends'
 * inertia, its multiplier 0: they are not in the sweeps) with Coulomb friction as a
 * tangential spring of the same stiffness capped at mu f_n, one linear system over the
 * bodies solved by conjugate gradients. Each contact's forces on its two bodies are equal
 * and opposite, so the step keeps their momentum whatever the order (Gauss-Seidel over
 * the bodies would not, as over the vertices). Moved alone, each by its own momentum step,
 * two stacked lattices crept 3 cm off centre; not moved at all, a block sliding on a free
 * slab lost a fifth of the momentum and a rope draped on another rested 2.2 mm low.
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
#include "tricontact.h"
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
    uint8_t *bo;             /* (npair) 1: two movable ends of two bodies, at least one of them
                                moved with its partners (wb__vbdc_couple): in that step only */
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
    double *cs;              /* wb__vbdc_couple's scratch: 24 a body, 7 a pair */
    size_t cap_cs, charged_cs;
};

void wb__vbdc_destroy(wb_world *w, wb_vbdc *c)
{
    if (!c) return;
    wb__charge(w, &c->charged, 0);
    wb__charge(w, &c->charged_cs, 0);
    free(c->cs), free(c->bo);
    free(c->start), free(c->ent), free(c->pij), free(c->tgt), free(c->kk), free(c->lam), free(c->mu);
    free(c->ov), free(c->ove), free(c->prev), free(c->fend), free(c->prevf), free(c->fl), free(c->lamp), free(c->sf), free(c->ks), free(c->xc), free(c->cv), free(c->cvs);
    free(c);
}

/* what c holds at these capacities: the struct, the per-vertex arrays (start, cv, xc), the
 * per-pair ones (ent 2, pij 2, prev 2 ints; tgt, kk, lam, mu, ov, ove, fend, prevf, fl,
 * lamp reals; sf, bo 1 byte), the keys and the colour ranges */
static size_t bytes_at(int64_t np, int64_t npair, int64_t ncol1, int64_t nks)
{
    return sizeof(wb_vbdc) + (size_t)np * (2 * sizeof(int32_t) + 3 * sizeof(wb_real)) + sizeof(int32_t) +
           (size_t)npair * (6 * sizeof(int32_t) + 10 * sizeof(wb_real) + 2) + (size_t)nks * sizeof(vbdc_key) +
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
        uint8_t *sf = realloc(c->sf, n), *bo = realloc(c->bo, n);
        if (sf) c->sf = sf;
        if (bo) c->bo = bo;
        if (!e || !p || !r[0] || !r[1] || !r[2] || !r[3] || !ov || !ove || !pv || !q[0] || !q[1] || !q[2] || !lp || !sf || !bo)
            return 0;
        c->cap_pair = npair;
    }
    if (ncol + 1 > c->cap_col) {
        int32_t *s = realloc(c->cvs, sizeof *s * ((size_t)ncol + 1));
        if (!s) return 0;
        c->cvs = s, c->cap_col = ncol + 1;
    }
    return 1;
}

/* groups g1 and g2 were moved apart whole by contact.c in the last substep for an overlap
 * they were made with: their contacts are its to take out (pushed pair by pair, blocks
 * made interleaved flew apart at metres per second) */
int wb__vbdc_made(const wb_world *w, int32_t p, int32_t q)
{
    const wb_contacts *pc = w->k.pc;
    const int32_t g1 = w->m.group[p], g2 = w->m.group[q];
    if (pc->nmade == 0 || g1 <= 0 || g2 <= 0 || g1 == g2) return 0;
    const int32_t a = g1 < g2 ? g1 : g2, b = g1 < g2 ? g2 : g1;
    for (int32_t e = 0; e < pc->nmade; e++)
        if (pc->made_ab[2 * e] == a && pc->made_ab[2 * e + 1] == b) return 1;
    return 0;
}

/* candidate k is a pair it serves, closer than VBDC_NEAR (r_i + r_j): one movable end (see
 * the head of the file for why not two), or two movable ends of two bodies, one of them
 * moved with its partners (bvar: its index there, -1 none; NULL: no such bodies) */
static inline int near_pair(const wb_world *w, const wb_contacts *pc, const wb_real *x, const wb_real *wv, const wb_real *rad,
                            const int32_t *body, const int32_t *bvar, wb_real step_h, int32_t k)
{
    const int32_t i = pc->ij[2 * k], j = pc->ij[2 * k + 1];
    if (!(wv[i] > 0) == !(wv[j] > 0)) {
        if (!bvar || !(wv[i] > 0)) return 0;
        const int32_t a = body[i], b = body[j];
        if (a < 0 || b < 0 || a == b || (bvar[a] < 0 && bvar[b] < 0) || wb__vbdc_made(w, i, j)) return 0;
        /* made overlapping (more than a substep's depenetration at its start): the
         * projection's to part slowly, pair by pair */
        const wb_real *xp = w->s.x_prev, rs = rad[i] + rad[j] - w->m.def.max_depenetration * step_h;
        wb_real e[3];
        v3_sub(e, &xp[3 * i], &xp[3 * j]);
        if (v3_dot(e, e) < rs * rs) return 0;
    }
    const wb_real rn = (rad[i] + rad[j]) * VBDC_NEAR;
    wb_real d[3];
    v3_sub(d, &x[3 * i], &x[3 * j]);
    return v3_dot(d, d) < rn * rn;
}

int wb__vbdc_begin(wb_world *w, wb_vbdc **cp, wb_real h, const int32_t *order, const int32_t *colour_start,
                   int32_t ncolours, const uint8_t *bmoved, const int32_t *bvar)
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
        n += near_pair(w, pc, x, wv, rad, w->k.mc_body, bvar, h, k);
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
        if (!near_pair(w, pc, x, wv, rad, w->k.mc_body, bvar, h, k)) continue;
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
        c->bo[q] = wv[i] > 0 && wv[j] > 0;
        if (c->bo[q]) continue;
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
        for (int s = 1; s >= 0 && !c->bo[q]; s--) {
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
        if (c->bo[q]) { /* (not in the sweeps: its penalty alone in the momentum step) */
            c->lamp[q] = c->lam[q] = 0;
            continue;
        }
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

/* H d = f for a symmetric 3 x 3 H (xx, yy, zz, xy, xz, yz); 0 when singular */
static int solve_sym3(const double H[6], const double f[3], double d[3])
{
    const double a = H[0], b = H[1], c = H[2], xy = H[3], xz = H[4], yz = H[5];
    const double c00 = b * c - yz * yz, c01 = xz * yz - xy * c, c02 = xy * yz - b * xz;
    const double det = a * c00 + xy * c01 + xz * c02;
    if (!(fabs(det) > 1e-300)) return 0;
    const double c11 = a * c - xz * xz, c12 = xy * xz - a * yz, c22 = a * b - xy * xy, inv = 1 / det;
    d[0] = (c00 * f[0] + c01 * f[1] + c02 * f[2]) * inv;
    d[1] = (c01 * f[0] + c11 * f[1] + c12 * f[2]) * inv;
    d[2] = (c02 * f[0] + c12 * f[1] + c22 * f[2]) * inv;
    return 1;
}

static inline void sym3_mul(const double H[6], const double u[3], double out[3])
{
    out[0] = H[0] * u[0] + H[3] * u[1] + H[4] * u[2];
    out[1] = H[3] * u[0] + H[1] * u[1] + H[5] * u[2];
    out[2] = H[4] * u[0] + H[5] * u[1] + H[2] * u[2];
}

/* y = A u for the coupled step's matrix: each body's D u_b less, for each pair pushing
 * between two bodies of the step, its Hessian times the partner's u (hq: pair q's,
 * hq[6] < 0: not pushing) */
static void couple_mul(int32_t npair, const int32_t *vi, const double *D, const double *hq, int32_t nv, const double *u,
                       double *y)
{
    for (int32_t b = 0; b < nv; b++) sym3_mul(&D[6 * b], &u[3 * b], &y[3 * b]);
    for (int32_t q = 0; q < npair; q++) {
        const int32_t a = vi[2 * q], b = vi[2 * q + 1];
        if (a < 0 || b < 0 || hq[7 * q + 6] < 0) continue;
        double ha[3], hb[3];
        sym3_mul(&hq[7 * q], &u[3 * b], hb);
        sym3_mul(&hq[7 * q], &u[3 * a], ha);
        for (int k = 0; k < 3; k++) y[3 * a + k] -= hb[k], y[3 * b + k] -= ha[k];
    }
}

/* a contact of the coupled step pushing with fn > 0 along n (from b's side to a's), of
 * penalty kk, with its friction: the relative slip u over the substep across n held by a
 * tangential spring of the same stiffness while its force is within mu fn, else pushed
 * back by mu fn (its Hessian then the cone's, fn mu / |u_t| across u_t and n). Its force
 * goes to a (b: the opposite), its Hessian to H (sym. 3 x 3, H[6] = 1) and both bodies'
 * blocks D: each pair's forces equal and opposite, the step keeps the momentum */
static void couple_add(int32_t a, int32_t b, const double n[3], double fn, double kk, double mu, const double u[3],
                       double H[7], double *D, double *g)
{
    double f[3], ut[3];
    const double un = u[0] * n[0] + u[1] * n[1] + u[2] * n[2];
    for (int k = 0; k < 3; k++) ut[k] = u[k] - un * n[k], f[k] = fn * n[k];
    const double ul = sqrt(ut[0] * ut[0] + ut[1] * ut[1] + ut[2] * ut[2]), cap = mu * fn;
    double kt = 0, ks = 0, e[3] = { 0, 0, 0 }; /* across n, kt (I - n n^T) - ks e e^T */
    if (cap > 0 && ul > 0) {
        if (kk * ul <= cap) {
            kt = kk;
            for (int k = 0; k < 3; k++) f[k] -= kk * ut[k];
        } else {
            kt = cap / ul, ks = kt;
            for (int k = 0; k < 3; k++) e[k] = ut[k] / ul, f[k] -= cap * e[k];
        }
    }
    const double kn = kk - kt;
    H[0] = kn * n[0] * n[0] + kt - ks * e[0] * e[0], H[1] = kn * n[1] * n[1] + kt - ks * e[1] * e[1];
    H[2] = kn * n[2] * n[2] + kt - ks * e[2] * e[2], H[3] = kn * n[0] * n[1] - ks * e[0] * e[1];
    H[4] = kn * n[0] * n[2] - ks * e[0] * e[2], H[5] = kn * n[1] * n[2] - ks * e[1] * e[2], H[6] = 1;
    for (int k = 0; k < 6; k++) {
        if (a >= 0) D[6 * a + k] += H[k];
        if (b >= 0) D[6 * b + k] += H[k];
    }
    for (int k = 0; k < 3; k++) {
        if (a >= 0) g[3 * a + k] += f[k];
        if (b >= 0) g[3 * b + k] -= f[k];
    }
}

/* the triangle contacts between two bodies of the coupled step: a point of one body, a
 * triangle of another whose corners are all movable (a triangle held anywhere is left to
 * the projection after the solve, touching() marks its point's body) */
static int tri_between(const wb_world *w, const int32_t *bvar, int32_t k, int32_t *a, int32_t *b)
{
    const wb_tricontacts *tc = w->k.tc;
    const int32_t *body = w->k.mc_body, p = tc->pt[2 * k], *v = &w->m.tri[3 * tc->pt[2 * k + 1]];
    const wb_real *wv = w->m.w;
    const int32_t bp = body[p], bt = body[v[0]];
    if (bp < 0 || bt < 0 || bp == bt || body[v[1]] != bt || body[v[2]] != bt || wb__vbdc_made(w, p, v[0])) return 0;
    *a = wv[p] > 0 ? bvar[bp] : -1;
    *b = wv[v[0]] > 0 && wv[v[1]] > 0 && wv[v[2]] > 0 ? bvar[bt] : -1;
    return *a >= 0 || *b >= 0;
}

int wb__vbdc_couple(wb_world *w, wb_vbdc **cp, const int32_t *bvar, int32_t nv, const double *mass, const double *mean,
                    double *t, wb_real h, int32_t steps)
{
    const int32_t *body = w->k.mc_body;
    const wb_real *x = w->s.x, *xp = w->s.x_prev, *wv = w->m.w, *rad = w->m.radius, *cf = w->m.cfric, inv_h2 = 1 / (h * h);
    const wb_tricontacts *tc = w->k.tc;
    if (!*cp) {
        *cp = calloc(1, sizeof **cp);
        if (!*cp) return -1;
        (*cp)->sorted = 1;
    }
    wb_vbdc *c = *cp;
    int32_t ntc = 0;
    for (int32_t k = 0; k < tc->n; k++) {
        int32_t a, b;
        ntc += tri_between(w, bvar, k, &a, &b);
    }
    const size_t need = 24 * (size_t)nv + 9 * (size_t)c->npair + 18 * (size_t)ntc;
    if (need > c->cap_cs) {
        if (!wb__charge(w, &c->charged_cs, sizeof(double) * need)) return -1;
        double *cs = realloc(c->cs, sizeof *cs * need);
        if (!cs) return -1;
        c->cs = cs, c->cap_cs = need;
    }
    double *D = c->cs, *g = D + 6 * (size_t)nv, *r = g + 3 * (size_t)nv, *z = r + 3 * (size_t)nv;
    double *p = z + 3 * (size_t)nv, *Ap = p + 3 * (size_t)nv, *dt = Ap + 3 * (size_t)nv, *hq = dt + 3 * (size_t)nv;
    /* (each pair's ends' indices in the step, -1: held where they are, as doubles' room) */
    const int32_t np2 = c->npair;
    int32_t *vi = (int32_t *)(hq + 7 * ((size_t)np2 + (size_t)ntc));
    for (int32_t q = 0; q < np2; q++)
        for (int s = 0; s < 2; s++) {
            const int32_t i = c->pij[2 * q + s];
            vi[2 * q + s] = wv[i] > 0 && body[i] >= 0 ? bvar[body[i]] : -1;
        }
    /* each triangle contact near enough as a plane: its normal nn and the gap's base
     * nn . (x_p - q) at t = 0 (the triangle only translates here: its closest point and
     * normal stay), the target r_p less the overlap it keeps (wb__contact_depth's rule),
     * its penalty over W = w_p + sum b_i^2 w_i; td: nn, base, target, k, the slip of
     * p against its closest point over the substep at t = 0, mu (tricontact.c's) */
    double *td = (double *)(vi + 2 * ((size_t)np2 + (size_t)ntc));
    int32_t nt = 0;
    const wb_real step = w->m.def.max_depenetration * h;
    for (int32_t k = 0; k < tc->n; k++) {
        int32_t a, b;
        if (!tri_between(w, bvar, k, &a, &b)) continue;
        const int32_t p = tc->pt[2 * k], *v = &w->m.tri[3 * tc->pt[2 * k + 1]];
        const wb_real r = rad[p];
        wb_real bc[3], q[3], d[3], e1[3], e2[3], n[3];
        const wb_real d2 = wb__tri_closest(&x[3 * p], &x[3 * v[0]], &x[3 * v[1]], &x[3 * v[2]], bc, q);
        v3_sub(d, &x[3 * p], q);
        const wb_real dist = sqrt(d2);
        v3_sub(e1, &xp[3 * v[1]], &xp[3 * v[0]]);
        v3_sub(e2, &xp[3 * v[2]], &xp[3 * v[0]]);
        v3_cross(n, e1, e2);
        wb_real dp[3];
        v3_sub(dp, &xp[3 * p], &xp[3 * v[0]]);
        const wb_real s_prev = v3_dot(dp, n), ln = v3_len(n);
        double nn[3], base;
        v3_sub(dp, &x[3 * p], &x[3 * v[0]]);
        if (ln > 0 && s_prev != 0 && v3_dot(dp, n) * s_prev < 0 && bc[0] > 0 && bc[1] > 0 && bc[2] > 0) {
            /* through the face since the substep began: back to the side it was on */
            for (int c3 = 0; c3 < 3; c3++) nn[c3] = n[c3] / ln * (s_prev > 0 ? 1 : -1);
        } else if (dist > r * (wb_real)1e-9 && dist < r * VBDC_NEAR) {
            for (int c3 = 0; c3 < 3; c3++) nn[c3] = d[c3] / dist;
        } else {
            continue;
        }
        base = nn[0] * d[0] + nn[1] * d[1] + nn[2] * d[2];
        const wb_real W = wv[p] + bc[0] * bc[0] * wv[v[0]] + bc[1] * bc[1] * wv[v[1]] + bc[2] * bc[2] * wv[v[2]];
        if (!(W > 0)) continue;
        wb_real bp[3], qp[3];
        const wb_real d0 = r - sqrt(wb__tri_closest(&xp[3 * p], &xp[3 * v[0]], &xp[3 * v[1]], &xp[3 * v[2]], bp, qp));
        /* a point made inside the other body: a triangle's normal is no way out of it
         * (tricontact.c), its projection's to part slowly */
        if (d0 > step) continue;
        const wb_real keep = 0;
        double *o = &td[10 * (size_t)nt];
        for (int c3 = 0; c3 < 3; c3++) {
            o[c3] = nn[c3];
            o[6 + c3] = (double)x[3 * p + c3] - (double)xp[3 * p + c3];
            for (int e = 0; e < 3; e++) o[6 + c3] -= bc[e] * ((double)x[3 * v[e] + c3] - (double)xp[3 * v[e] + c3]);
        }
        o[3] = base, o[4] = r - keep, o[5] = VBDC_K * inv_h2 / W;
        o[9] = (cf[p] + bc[0] * cf[v[0]] + bc[1] * cf[v[1]] + bc[2] * cf[v[2]]) / 2;
        vi[2 * (np2 + nt)] = a, vi[2 * (np2 + nt) + 1] = b;
        nt++;
    }
    memset(t, 0, sizeof *t * 3 * (size_t)nv);
    for (int32_t pass = 0; pass < steps; pass++) {
        for (int32_t b = 0; b < nv; b++) {
            const double mh = mass[b] * inv_h2;
            D[6 * b] = D[6 * b + 1] = D[6 * b + 2] = mh, D[6 * b + 3] = D[6 * b + 4] = D[6 * b + 5] = 0;
            for (int k = 0; k < 3; k++) g[3 * b + k] = -mh * (mean[3 * b + k] + t[3 * b + k]);
        }
        for (int32_t q = 0; q < np2; q++) {
            const int32_t a = vi[2 * q], b = vi[2 * q + 1], i = c->pij[2 * q], j = c->pij[2 * q + 1];
            hq[7 * q + 6] = -1;
            if (a < 0 && b < 0) continue;
            double d[3];
            for (int k = 0; k < 3; k++)
                d[k] = ((double)x[3 * i + k] + (a >= 0 ? t[3 * a + k] : 0)) - ((double)x[3 * j + k] + (b >= 0 ? t[3 * b + k] : 0));
            const double l = sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]), kk = c->kk[q];
            if (!(l > 1e-12)) continue;
            const double fn = (double)c->lamp[q] - kk * (l - (double)c->tgt[q]);
            if (!(fn > 0)) continue;
            const double n[3] = { d[0] / l, d[1] / l, d[2] / l };
            double u[3];
            for (int k = 0; k < 3; k++)
                u[k] = ((double)x[3 * i + k] - (double)xp[3 * i + k] + (a >= 0 ? t[3 * a + k] : 0)) -
                       ((double)x[3 * j + k] - (double)xp[3 * j + k] + (b >= 0 ? t[3 * b + k] : 0));
            couple_add(a, b, n, fn, kk, c->mu[q], u, &hq[7 * q], D, g);
        }
        for (int32_t q = 0; q < nt; q++) {
            const int32_t a = vi[2 * (np2 + q)], b = vi[2 * (np2 + q) + 1];
            const double *o = &td[10 * (size_t)q];
            double *H = &hq[7 * ((size_t)np2 + (size_t)q)];
            double gap = o[3];
            for (int k = 0; k < 3; k++) gap += o[k] * ((a >= 0 ? t[3 * a + k] : 0) - (b >= 0 ? t[3 * b + k] : 0));
            const double fn = -o[5] * (gap - o[4]);
            H[6] = -1;
            if (!(fn > 0)) continue;
            double u[3];
            for (int k = 0; k < 3; k++) u[k] = o[6 + k] + (a >= 0 ? t[3 * a + k] : 0) - (b >= 0 ? t[3 * b + k] : 0);
            couple_add(a, b, o, fn, o[5], o[9], u, H, D, g);
        }
        /* the Newton step, A dt = g, by conjugate gradients with each body's block as the
         * preconditioner (serial, in body order: the same bits on any thread count) */
        double rz = 0, gg = 0;
        for (int32_t b = 0; b < nv; b++) {
            if (!solve_sym3(&D[6 * b], &g[3 * b], &z[3 * b])) return 0;
            for (int k = 0; k < 3; k++) {
                dt[3 * b + k] = 0, r[3 * b + k] = g[3 * b + k], p[3 * b + k] = z[3 * b + k];
                rz += r[3 * b + k] * z[3 * b + k], gg += g[3 * b + k] * g[3 * b + k];
            }
        }
        for (int32_t it = 0; it < 3 * nv + 20 && rz > 0; it++) {
            couple_mul(np2 + nt, vi, D, hq, nv, p, Ap);
            double pAp = 0;
            for (int32_t k = 0; k < 3 * nv; k++) pAp += p[k] * Ap[k];
            if (!(pAp > 0)) break;
            const double al = rz / pAp;
            double rr = 0;
            for (int32_t k = 0; k < 3 * nv; k++) dt[k] += al * p[k], r[k] -= al * Ap[k], rr += r[k] * r[k];
            if (!(rr > 1e-30 * gg)) break;
            double rz1 = 0;
            for (int32_t b = 0; b < nv; b++) {
                solve_sym3(&D[6 * b], &r[3 * b], &z[3 * b]);
                for (int k = 0; k < 3; k++) rz1 += r[3 * b + k] * z[3 * b + k];
            }
            const double be = rz1 / rz;
            rz = rz1;
            for (int32_t k = 0; k < 3 * nv; k++) p[k] = z[k] + be * p[k];
        }
        double d2 = 0, t2 = 0;
        for (int32_t k = 0; k < 3 * nv; k++) {
            t[k] += dt[k];
            d2 += dt[k] * dt[k], t2 += t[k] * t[k];
        }
        if (!(d2 > 1e-24 * t2)) break;
    }
    return 1;
}
