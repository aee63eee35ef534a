/* distance.c: the distance constraint type (the first of ctype.c's table): its slots and
 * the C API (wb_distance_*), packing and colouring of the live links into batches, their
 * XPBD projection (Gauss-Seidel batch by batch or Jacobi), plastic flow and breaking once
 * per frame, and their elastic energy. Its arrays are w->dist (distance.h), made with the
 * first link.
 *
 * The batches are batch.h's, as every coloured type's: over the live, unbroken links only
 * (links are removed and broken), with the links meeting on a mirror plane as compounds
 * projected together from the same positions (a symmetric scene stays symmetric). What
 * the kernels read is packed in the batches' order (s_slot), and the Jacobi solver runs
 * over the same packing. */
#include <assert.h>
#include <stdlib.h>

#include "ctype.h"
#include "distance.h"
#include "snapshot.h"
#include "tet.h"
#include "vbd.h"
#include "volume.h"
#include "contact.h"

static int realloc_n(void **p, int32_t n, size_t elem)
{
    void *q = realloc(*p, (size_t)(n > 0 ? n : 1) * elem);
    if (!q) return 0;
    *p = q;
    return 1;
}

static int packable(const void *ud, int32_t s)
{
    const wb_distances *ds = ud;
    return (ds->gen[s] & 1u) && !ds->broken[s];
}

/* ---- memory: the struct made with the first link ------------------------------------------ */
/* bytes per slot over the arrays that grow with the slots (model, state, slot_pack) and
 * the packed cache, for the memory limit */
#define CONSTRAINT_BYTES (14 * sizeof(wb_real) + 42)

static int slot_live(uint32_t gen) { return gen & 1u; }

/* room for need slots; the struct is made with the first (w->dist: NULL until then) */
static wb_status grow_distances(wb_world *w, int32_t need)
{
    if (need > WB_MAX_CONSTRAINTS) return WB_ERR_LIMIT;
    if (!w->dist) {
        if (need <= 0) return WB_OK;
        wb_distances *ds = calloc(1, sizeof *ds);
        if (!ds) return WB_ERR_NOMEM;
        w->dist = ds;
    }
    wb_distances *ds = w->dist;
    if (need <= ds->cap) return WB_OK;
    const int32_t cap = wb__charge_cap(w, &ds->charged, CONSTRAINT_BYTES, ds->cap, need, WB_MAX_CONSTRAINTS);
    if (cap < 0) return WB_ERR_NOMEM;
    const wb_soa arr[] = {
        { (void **)&ds->ij, 2 * sizeof(int32_t) }, { (void **)&ds->alpha, sizeof(wb_real) },
        { (void **)&ds->beta, sizeof(wb_real) }, { (void **)&ds->yield, sizeof(wb_real) },
        { (void **)&ds->creep, sizeof(wb_real) }, { (void **)&ds->break_strain, sizeof(wb_real) },
        { (void **)&ds->bforce, sizeof(wb_real) },
        { (void **)&ds->gen, sizeof(uint32_t) }, { (void **)&ds->free_slots, sizeof(int32_t) },
        { (void **)&ds->rest, sizeof(wb_real) }, { (void **)&ds->broken, 1 },
        { (void **)&ds->slot_pack, sizeof(int32_t) },
    };
    if (WB_SOA_RESIZE(arr, cap) != WB_OK) return WB_ERR_NOMEM;
    ds->cap = cap;
    return WB_OK;
}

wb_status wb__reserve(wb_world *w, int64_t np_extra, int64_t nd_extra)
{
    const int32_t nd = wb__dist(w->dist)->n;
    if (w->m.np + np_extra > WB_MAX_PARTICLES || nd + nd_extra > WB_MAX_CONSTRAINTS) return WB_ERR_LIMIT;
    wb_status st = wb__particles_reserve(w, np_extra);
    if (st == WB_OK) st = grow_distances(w, nd + (int32_t)nd_extra);
    return st;
}

/* ---- the C API ---------------------------------------------------------------------------- */
wb_distance_def wb_distance_default_def(void)
{
    wb_distance_def d = { 0, 0, -1, 0, 0, 0, 0 };
    return d;
}

/* the options' rules: the one place they are decided (the binding and the JSON reader
 * print what this finds) */
static wb_fault distance_def_fault(const wb_distance_def *d)
{
    if (!(d->compliance >= 0) || !isfinite(d->compliance)) return WB_FAULT_KEY("compliance", "must be >= 0");
    if (!(d->damping >= 0) || !isfinite(d->damping)) return WB_FAULT_KEY("damping", "must be >= 0");
    /* the solver works with squared lengths: a rest whose square overflows can never be met */
    if (!isfinite(d->rest) || !isfinite(d->rest * d->rest))
        return WB_FAULT_KEY("rest", "must be finite and below 1e154 (its square overflows)");
    if (!(d->yield >= 0) || !isfinite(d->yield)) return WB_FAULT_KEY("yield", "must be >= 0");
    if (!(d->creep >= 0) || !isfinite(d->creep)) return WB_FAULT_KEY("creep", "must be >= 0");
    if (!(d->break_strain >= 0) || !isfinite(d->break_strain)) return WB_FAULT_KEY("break_strain", "must be >= 0");
    if (!(d->break_force >= 0) || !isfinite(d->break_force)) return WB_FAULT_KEY("break_force", "must be >= 0");
    return WB_NO_FAULT;
}

const char *wb_distance_def_check(const wb_distance_def *d)
{
    return distance_def_fault(d).msg;
}

/* the particles first (what it joins), then the options, then whether their distance has
 * a finite square (the rest it derives obeys the rule a given one does) */
wb_fault wb_distance_check(int32_t np, const wb_real *x, int32_t a, int32_t b, const wb_distance_def *d)
{
    if (a < 0 || a >= np) return WB_FAULT_AT(0, "particle out of range", "out of range");
    if (b < 0 || b >= np) return WB_FAULT_AT(1, "particle out of range", "out of range");
    if (a == b)
        return WB_FAULT_AT(1, "a constraint needs two distinct particles", "a constraint needs two distinct particles");
    const wb_fault f = distance_def_fault(d);
    if (f.msg || !x) return f;
    wb_real dx[3];
    v3_sub(dx, &x[3 * b], &x[3 * a]);
    if (!isfinite(v3_dot(dx, dx)))
        return WB_FAULT_AT(-1, "the particles are too far apart (their distance squared overflows)",
                           "too far apart (their distance squared overflows)");
    return WB_NO_FAULT;
}

wb_distance_id wb_distance_add(wb_world *w, int32_t a, int32_t b, const wb_distance_def *def, wb_status *status)
{
    wb_distance_id none = { 0, 0 };
    wb_status dummy;
    if (!status) status = &dummy;
    const wb_fault f = wb_distance_check(w->m.np, w->s.x, a, b, def);
    if (f.msg) {
        if (!f.key && f.corner < 0) wb__set_error("particles %d and %d are %s", a + 1, b + 1, f.why);
        else wb__set_error("%s", f.msg);
        *status = WB_ERR_ARG;
        return none;
    }
    wb_real d[3];
    v3_sub(d, &w->s.x[3 * b], &w->s.x[3 * a]);
    const wb_real rest = def->rest >= 0 ? def->rest : v3_len(d);
    int32_t slot;
    if (w->dist && w->dist->nfree > 0) {
        slot = w->dist->free_slots[--w->dist->nfree];
    } else {
        wb_status st = grow_distances(w, wb__dist(w->dist)->n + 1);
        if (st != WB_OK) { *status = st; return none; }
        slot = w->dist->n++;
        w->dist->gen[slot] = 0;
    }
    wb_distances *ds = w->dist;
    ds->ij[2 * slot] = a;
    ds->ij[2 * slot + 1] = b;
    ds->alpha[slot] = def->compliance;
    ds->beta[slot] = def->damping;
    ds->yield[slot] = def->yield;
    ds->creep[slot] = def->creep;
    ds->break_strain[slot] = def->break_strain;
    ds->bforce[slot] = def->break_force;
    ds->gen[slot]++; /* even -> odd: live */
    ds->rest[slot] = rest;
    ds->broken[slot] = 0;
    ds->slot_pack[slot] = -1;
    ds->nlive++;
    w->m.topology_dirty = 1;
    *status = WB_OK;
    wb_distance_id id = { (uint32_t)slot + 1, ds->gen[slot] };
    return id;
}

bool wb_distance_valid(const wb_world *w, wb_distance_id c)
{
    const wb_distances *ds = wb__dist(w->dist);
    if (c.index == 0 || c.index > (uint32_t)ds->n) return false;
    uint32_t g = ds->gen[c.index - 1];
    return slot_live(g) && g == c.gen;
}

/* a valid handle's slot (so w->dist exists) */
#define SLOT(w, c) (assert(wb_distance_valid((w), (c))), (int32_t)(c).index - 1)

void wb_distance_remove(wb_world *w, wb_distance_id c)
{
    int32_t s = SLOT(w, c);
    wb_distances *ds = w->dist;
    ds->gen[s]++; /* odd -> even: dead, old handles stale */
    ds->free_slots[ds->nfree++] = s;
    ds->nlive--;
    w->m.topology_dirty = 1;
}

wb_real wb_distance_force(const wb_world *w, wb_distance_id c)
{
    int32_t s = SLOT(w, c);
    const wb_distances *ds = w->dist;
    int32_t k = ds->slot_pack[s];
    if (k < 0 || k >= ds->ns || ds->s_lambda_stale) return 0; /* not stepped since it was made (or undone) */
    const wb_real h = w->k.h_last; /* of the step that made lambda, whatever dt is now */
    return fabs(ds->s_lambda[k]) / (h * h);
}

wb_real wb_distance_rest(const wb_world *w, wb_distance_id c) { return w->dist->rest[SLOT(w, c)]; }
bool wb_distance_broken(const wb_world *w, wb_distance_id c) { return w->dist->broken[SLOT(w, c)] != 0; }

static wb_real slot_length(const wb_world *w, const wb_distances *ds, int32_t s)
{
    wb_real d[3];
    v3_sub(d, &w->s.x[3 * ds->ij[2 * s + 1]], &w->s.x[3 * ds->ij[2 * s]]);
    return v3_len(d);
}

wb_real wb_distance_length(const wb_world *w, wb_distance_id c) { return slot_length(w, w->dist, SLOT(w, c)); }

void wb_distance_particles(const wb_world *w, wb_distance_id c, int32_t *a, int32_t *b)
{
    int32_t s = SLOT(w, c);
    *a = w->dist->ij[2 * s];
    *b = w->dist->ij[2 * s + 1];
}

int32_t wb_distance_count(const wb_world *w) { return wb__dist(w->dist)->nlive; }

wb_distance_id wb_distance_at(const wb_world *w, int32_t i)
{
    /* live slots in slot order: O(nd) scan, fine for inspection and export */
    const wb_distances *ds = wb__dist(w->dist);
    for (int32_t s = 0; s < ds->n; s++) {
        if (!slot_live(ds->gen[s])) continue;
        if (i-- == 0) { wb_distance_id id = { (uint32_t)s + 1, ds->gen[s] }; return id; }
    }
    wb_distance_id none = { 0, 0 };
    return none;
}

int32_t wb_distance_ids(const wb_world *w, wb_distance_id *out)
{
    const wb_distances *ds = wb__dist(w->dist);
    int32_t n = 0;
    for (int32_t s = 0; s < ds->n; s++)
        if (slot_live(ds->gen[s])) { out[n].index = (uint32_t)s + 1; out[n].gen = ds->gen[s]; n++; }
    return n;
}

/* the live, unbroken links' largest |strain| */
wb_real wb_world_max_strain(const wb_world *w)
{
    const wb_distances *ds = wb__dist(w->dist);
    wb_real best = 0;
    for (int32_t s = 0; s < ds->n; s++) {
        if (!packable(ds, s) || ds->rest[s] <= 0) continue;
        wb_real e = fabs(slot_length(w, ds, s) - ds->rest[s]) / ds->rest[s];
        if (e > best) best = e;
    }
    return best;
}

/* the live, unbroken links' ends and strains, in slot order */
int32_t wb_world_distance_pairs(const wb_world *w, int32_t *ij, wb_real *strain)
{
    const wb_distances *ds = wb__dist(w->dist);
    int32_t n = 0;
    for (int32_t s = 0; s < ds->n; s++) {
        if (!packable(ds, s)) continue;
        if (ij) { ij[2 * n] = ds->ij[2 * s]; ij[2 * n + 1] = ds->ij[2 * s + 1]; }
        if (strain) strain[n] = ds->rest[s] > 0 ? (slot_length(w, ds, s) - ds->rest[s]) / ds->rest[s] : 0;
        n++;
    }
    return n;
}

int32_t wb_world_break_count(const wb_world *w) { return wb__dist(w->dist)->nbreaks; }
wb_distance_id wb_world_break_at(const wb_world *w, int32_t i) { assert(i >= 0 && i < wb_world_break_count(w)); return w->dist->breaks[i]; }

/* ---- packing: rebuild the colour batches when the topology changed --------------------- */
static wb_status colour(wb_world *w);

/* alpha / h^2 per constraint for the substep h, and which constraints need none of the
 * vector path's masks (after s_wa, s_wc) */
static void refresh_at(wb_distances *ds, wb_real h)
{
    const wb_real inv_h2 = 1 / (h * h);
    for (int32_t i = 0; i < ds->ns; i++) {
        const wb_real at = ds->s_alpha[i] * inv_h2;
        ds->s_at[i] = at;
        ds->s_ok[i] = ds->s_wa[i] > 0 && ds->s_wc[i] > 0 && !isinf(at);
    }
    ds->s_at_h = h;
}

/* which packed links have both ends on volume or tet constraints (s_backed): worked out
 * when the links were packed or volumes or tets were made. 0 when out of memory (then no
 * link is marked: they keep their full correction) */
static int mark_backed(wb_world *w)
{
    wb_distances *ds = w->dist;
    const int32_t nv = wb_volume_count(w), nt = wb_tet_count(w), np = w->m.np;
    ds->s_backed_vt[0] = nv;
    ds->s_backed_vt[1] = nt;
    if (ds->ns > 0) memset(ds->s_backed, 0, (size_t)ds->ns);
    if (nv + nt == 0 || ds->ns == 0) return 1;
    uint8_t *on = calloc((size_t)(np > 0 ? np : 1), 1);
    if (!on) return 0;
    const int32_t *vq = wb__volume_corners(w), *tq = wb__tet_corners(w);
    for (int64_t i = 0; i < 4 * (int64_t)nv; i++) on[vq[i]] = 1;
    for (int64_t i = 0; i < 4 * (int64_t)nt; i++) on[tq[i]] = 1;
    for (int32_t i = 0; i < ds->ns; i++) ds->s_backed[i] = on[ds->s_a[i]] & on[ds->s_b[i]];
    free(on);
    return 1;
}

/* prepare, once per step: recolour when the topology changed; then the ends' inverse
 * masses in packed order (the vector path loads them instead of gathering from m.w;
 * pin, unpin, set mass and snapshot loads change m.w between steps only) */
wb_status wb__colour(wb_world *w)
{
    wb_distances *ds = w->dist;
    if (ds) ds->nbreaks = 0; /* the list reports the step about to run */
    const int recoloured = w->m.topology_dirty;
    if (!ds) { /* no links: nothing to pack, the new topology taken as one would */
        if (recoloured && w->k.pc) w->k.pc->keys_dirty = 1;
        w->m.topology_dirty = 0;
        return WB_OK;
    }
    if (recoloured) {
        const wb_status st = colour(w);
        if (st != WB_OK) return st;
    }
    if ((recoloured || ds->s_backed_vt[0] != wb_volume_count(w) || ds->s_backed_vt[1] != wb_tet_count(w)) &&
        !mark_backed(w))
        return WB_ERR_NOMEM;
    /* (only when they changed: the copy cost 3.5% of the 32x32 cloth's frame) */
    if (recoloured || ds->s_w_gen != w->m.w_gen) {
        const wb_real *wv = w->m.w;
        const int32_t *restrict sa = ds->s_a, *restrict sb = ds->s_b;
        wb_real *restrict wa = ds->s_wa, *restrict wc = ds->s_wc;
        for (int32_t i = 0, n = ds->ns; i < n; i++) {
            wa[i] = wv[sa[i]];
            wc[i] = wv[sb[i]];
        }
        ds->s_w_gen = w->m.w_gen;
        ds->s_at_h = NAN; /* s_ok reads s_wa, s_wc */
    }
    /* the solver's substep as it computes it; distance_project checks it too */
    const wb_real h = w->m.def.dt / w->m.def.substeps;
    if (h != ds->s_at_h) refresh_at(ds, h);
    return WB_OK;
}

/* the batches (batch.h) over the live, unbroken links, the links meeting on a mirror plane
 * as compounds; then what the kernels read, packed in the batches' order (s_slot) */
static wb_status colour(wb_world *w)
{
    wb_model *m = &w->m;
    wb_cache *k = &w->k;
    wb_distances *ds = w->dist;
    if (k->pc) k->pc->keys_dirty = 1; /* the constraint pairs that self-collision skips */

    int32_t ns = 0;
    for (int32_t s = 0; s < ds->n; s++) ns += packable(ds, s);

    const wb_batch_def def = { ds->ij, 2, ds->n, packable, ds, 1 };
    if (!realloc_n((void **)&ds->s_a, ns, sizeof(int32_t)) || !realloc_n((void **)&ds->s_b, ns, sizeof(int32_t)) ||
        !realloc_n((void **)&ds->s_rest, ns, sizeof(wb_real)) || !realloc_n((void **)&ds->s_alpha, ns, sizeof(wb_real)) ||
        !realloc_n((void **)&ds->s_beta, ns, sizeof(wb_real)) || !realloc_n((void **)&ds->s_lambda, ns, sizeof(wb_real)) ||
        !realloc_n((void **)&ds->s_jac, ns, 4 * sizeof(wb_real)) ||
        !realloc_n((void **)&ds->s_slot, ns, 3 * sizeof(int32_t) + 2) ||
        !wb__batches_make(&ds->bt, m, &def, ds->s_slot) ||
        !realloc_n((void **)&ds->s_nsp, 2 * (ns - ds->bt.colour_start[ds->bt.ncolours]), sizeof(int32_t)))
        return WB_ERR_NOMEM;
    assert(ds->bt.norder == ns);
    ds->s_wa = ds->s_jac + ns;
    ds->s_wc = ds->s_jac + 2 * ns;
    ds->s_at = ds->s_jac + 3 * ns;
    ds->s_oa = (uint32_t *)(ds->s_slot + ns);
    ds->s_oc = (uint32_t *)(ds->s_slot + 2 * ns);
    ds->s_ok = (uint8_t *)(ds->s_slot + 3 * ns);
    ds->s_backed = ds->s_ok + ns;
    ds->s_at_h = NAN; /* none yet: h != NaN */
    ds->ns = ns;
    ds->any_damping = 0;
    ds->any_frame_end = 0;
    for (int32_t i = 0; i < m->np; i++) k->ncount[i] = 0;
    for (int32_t s = 0; s < ds->n; s++) ds->slot_pack[s] = -1;
    for (int32_t i = 0; i < ns; i++) {
        const int32_t s = ds->s_slot[i], a = ds->ij[2 * s], b = ds->ij[2 * s + 1];
        ds->s_a[i] = a;
        ds->s_b[i] = b;
        ds->s_rest[i] = ds->rest[s];
        ds->s_alpha[i] = ds->alpha[s];
        ds->s_beta[i] = ds->beta[s];
        ds->s_lambda[i] = 0;
        ds->s_oa[i] = 3 * (uint32_t)a;
        ds->s_oc[i] = 3 * (uint32_t)b;
        ds->slot_pack[s] = i;
        k->ncount[a]++;
        k->ncount[b]++;
        if (ds->beta[s] > 0 && ds->alpha[s] > 0) ds->any_damping = 1;
        if (ds->break_strain[s] > 0 || ds->yield[s] > 0 || ds->bforce[s] > 0) ds->any_frame_end = 1;
    }
    /* Jacobi: a constraint's share is set by its busier movable end (an immovable
     * hub must not shrink its spokes' corrections) */
    for (int32_t i = 0; i < ns; i++) {
        const int32_t a = ds->s_a[i], b = ds->s_b[i];
        const int32_t na = m->inv_mass[a] > 0 ? k->ncount[a] : 1, nb = m->inv_mass[b] > 0 ? k->ncount[b] : 1;
        ds->s_jac[i] = (wb_real)1 / (na > nb ? na : nb);
    }
    /* a compound member's ends: how many of its compound's members meet there */
    const int32_t *cs = ds->bt.comp_start, split_start = ds->bt.colour_start[ds->bt.ncolours];
    for (int32_t c = 0; c < ds->bt.ncomp; c++)
        for (int32_t i = cs[c]; i < cs[c + 1]; i++) {
            int32_t *n = &ds->s_nsp[2 * (i - split_start)];
            n[0] = n[1] = 0;
            for (int32_t j = cs[c]; j < cs[c + 1]; j++) {
                n[0] += ds->s_a[j] == ds->s_a[i] || ds->s_b[j] == ds->s_a[i];
                n[1] += ds->s_a[j] == ds->s_b[i] || ds->s_b[j] == ds->s_b[i];
            }
        }
    m->topology_dirty = 0;
    return WB_OK;
}

/* ---- projection ----------------------------------------------------------------------------- */
/* How far one projection may lengthen a compressed link of a solid (both ends corners of
 * volume or tet constraints: s_backed). Its full correction scales the vector between its
 * ends by L / l (rest over current length), and with it how far the ends sit across each
 * other's line: a perturbation across the link grows by L / l. A Gauss-Seidel sweep
 * composes these factors. Links crushed to half their length (a stiff block squeezed by a
 * kinematic press: the contacts, projected after the sweep, crush the layers next to them
 * again every substep) double them at every projection: the layers buckle and particles
 * fly off at tens of m/s, some through the press (measured on 5^3-8^3 lattices of links
 * of 1e-4 and 1e-6 m/N and incompressible tets pressed to 60% at 0.2 m/s: 3-70 m/s; 23-585
 * m/s between pinned plates; Jacobi, which averages, stays calm). So the lengthening
 * e = wsum s of one projection (relative to the current length) is kept up to
 * STRETCH_FREE and bent smoothly (the same value and slope there) towards
 * 2 x STRETCH_FREE: e' = K (2 - K / e), K = STRETCH_FREE. A link shortened by less than
 * 1 - 1 / (1 + K) (11%) within a substep is corrected in full as before; one crushed
 * further regains at most a quarter of its length per projection (its multiplier is what
 * was applied: its force reads less while it recovers); those squeezes then move no
 * faster than the press. The volumes carry the solid's resistance to being crushed and
 * turned inside out. A truss of links alone has nothing else: bent so, its links let a
 * press fold it flat into its mirror image, where every link is at rest (measured:
 * scripts/block_crush.lua's block), so its links keep their full correction. */
#define STRETCH_FREE ((wb_real)0.125)

/* Project the distance constraints [b, e) of the packed arrays (XPBD, Macklin et al.
 * 2016 eq. 18 with the damping of eq. 26). Gauss-Seidel updates positions in place;
 * Jacobi (out = dx) accumulates corrections computed from the same positions, each
 * scaled by omega / max(n_a, n_b) (ds->s_jac) for both its ends, so that a pair's
 * corrections stay equal and opposite (momentum) and lambda is the multiplier
 * actually applied (force readback). Particles with w = 0 are never written, not
 * even with 0: -0.0 would turn +0.0, and immovable particles may be shared inside
 * a batch. The caller guarantees that no two constraints in [b, e) write the same
 * movable particle when it runs the range in parallel. `damped` and `jacobi` are
 * compile-time constants at each call. (A branch-free `omp simd` version with
 * AVX-512 gathers and scatters measured slower than this scalar loop; the AVX2 path
 * below, with transposes, is faster: see project_range4.) */
static inline __attribute__((always_inline)) void
project_range(const wb_distances *ds, const wb_real *restrict wv, wb_real *x, const wb_real *restrict xp,
              wb_real *out, int32_t b, int32_t e, wb_real h, wb_real inv_h2, wb_real omega,
              const int damped, const int jacobi, const int fresh, const int split)
{
    const int32_t *restrict sa = ds->s_a, *restrict sb = ds->s_b;
    const wb_real *restrict rest = ds->s_rest, *restrict alpha = ds->s_alpha, *restrict beta = ds->s_beta;
    const wb_real *restrict jac = ds->s_jac;
    const uint8_t *restrict backed = ds->s_backed;
    wb_real *restrict lambda = ds->s_lambda;
    for (int32_t i = b; i < e; i++) {
        const int32_t ia = sa[i], ic = sb[i];
        const wb_real wa = wv[ia], wc = wv[ic], wsum = wa + wc;
        /* a compound member sees each shared end's mass split among the members there
         * (their corrections add up) */
        const int32_t *nsp = split ? &ds->s_nsp[2 * (i - ds->bt.colour_start[ds->bt.ncolours])] : NULL;
        const wb_real wden = split ? wa * (wb_real)nsp[0] + wc * (wb_real)nsp[1] : wsum;
        const wb_real *xa = &x[3 * ia], *xc = &x[3 * ic];
        const wb_real d0 = xc[0] - xa[0], d1 = xc[1] - xa[1], d2 = xc[2] - xa[2];
        const wb_real len2 = d0 * d0 + d1 * d1 + d2 * d2;
        /* immovable pair, or coincident particles: nothing to push along */
        if (wsum == 0 || len2 < (wb_real)1e-24) { if (fresh) lambda[i] = 0; continue; }
        const wb_real at = alpha[i] * inv_h2;
        /* compliance/h^2 overflowed: the limit is a constraint with no stiffness (it would
         * otherwise give inf * 0 = NaN below and undo the frame) */
        if (isinf(at)) { if (fresh) lambda[i] = 0; continue; }
        const wb_real len = sqrt(len2);
        const wb_real lam = fresh ? 0 : lambda[i];
        wb_real num = rest[i] - len - at * lam;
        wb_real den = wden + at;
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
                den = wden;
            } else {
                num -= gamma * rel / len;
                den += gamma * wden;
            }
        }
        /* s = dlambda / len, so the correction is s * d without normalising d */
        wb_real s = num / (den * len);
        if (jacobi) s *= omega * jac[i];
        if (backed[i] && s * wsum > STRETCH_FREE) {
            const wb_real e = s * wsum;
            s = STRETCH_FREE * (2 - STRETCH_FREE / e) / wsum;
        }
        lambda[i] = lam + s * len;
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

#if defined(__x86_64__) && defined(__GNUC__) && !defined(WB_FLOAT)
#define WB_DISTANCE_AVX2 1
#include <immintrin.h>

#include "simd.h"

/* load4 on 4 row pointers, and its inverse (the corrections' pass: each row's address
 * made once for its load and its two stores) */
static inline __attribute__((always_inline, target("avx2"))) void
load4p(wb_real *const r[4], __m256d *X, __m256d *Y, __m256d *Z)
{
    wb__transpose4(wb__load3(r[0]), wb__load3(r[1]), wb__load3(r[2]), wb__load3(r[3]), X, Y, Z);
}

static inline __attribute__((always_inline, target("avx2"))) void
store4p(wb_real *const r[4], __m256d X, __m256d Y, __m256d Z)
{
    const __m256d t0 = _mm256_unpacklo_pd(X, Y), t1 = _mm256_unpackhi_pd(X, Y);
    const __m128d zl = _mm256_castpd256_pd128(Z), zh = _mm256_extractf128_pd(Z, 1);
    _mm_storeu_pd(r[0], _mm256_castpd256_pd128(t0));
    _mm_storel_pd(r[0] + 2, zl);
    _mm_storeu_pd(r[1], _mm256_castpd256_pd128(t1));
    _mm_storeh_pd(r[1] + 2, zl);
    _mm_storeu_pd(r[2], _mm256_extractf128_pd(t0, 1));
    _mm_storel_pd(r[2] + 2, zh);
    _mm_storeu_pd(r[3], _mm256_extractf128_pd(t1, 1));
    _mm_storeh_pd(r[3] + 2, zh);
}

/* the rows' offsets of a group's 4 a and 4 c ends (s_oa, s_oc: 3 i precomputed, unsigned:
 * a load and no arithmetic per particle) */
static inline __attribute__((always_inline)) void
offsets(const uint32_t *a, const uint32_t *c, size_t oa[4], size_t oc[4])
{
    for (int l = 0; l < 4; l++) {
        oa[l] = a[l];
        oc[l] = c[l];
    }
}

/* project_range for 4 constraints of a conflict-free batch at a time, in double, with
 * every lane doing exactly the scalar operations in the scalar order (no FMA:
 * -ffp-contract=off), so the bits are the scalar loop's. The skipped lanes (the
 * `continue`s) are masked; the isinf(gamma) limit is blended; a group whose 4
 * constraints all have s_ok (movable ends, finite alpha/h^2) and a length skips the
 * mask arithmetic. A chunk of CH constraints in three passes: 1, the lengths (one
 * square root per group) and masks; 2, s and lambda (one division); 3, the ends
 * reloaded and x - wa s d, x + wc s d (dx -/+ for Jacobi) stored from the vectors when
 * all 4 lanes write both ends (nearly every group of a cloth), else lane by lane. Each
 * pass's groups are independent, so their square roots and divisions overlap. No lane
 * reads a particle another lane of the batch writes (conflict-free for movable
 * particles; immovable ones are never written), so pass 3 recomputes d's bits and the
 * result is the scalar order's.
 * Measured (AMD EPYC (Zen 3) VM, loaded: CPU time from perf samples, medians of 5-6
 * interleaved runs; instructions from callgrind): cloth32 9.7 -> 7.3 ns per projection
 * (70 -> 56 instructions), cloth128 11.1 -> 8.5. The steps: wa, wc packed per
 * constraint instead of 8 scalar gathers per group, and the corrections stored from
 * the vectors instead of a scalar loop re-reading x: 70 -> 48 instructions but one
 * pass, each group's sqrt -> div chain waiting on the last (the reorder window held
 * about one group): no faster; cumulative from there: two passes (s, then
 * corrections): -6%; alpha/h^2, s_ok and 3i offsets precomputed: -17%; the lengths in a
 * pass of their own: -18%; the corrections addressed through row pointers made once
 * (fewer spills): -25%.
 * Tried and dropped: d stored by pass 1 and the corrections made end by end (+10%);
 * pass 1's transposed rows kept for pass 3 instead of reloading (-1% cloth32, +2%
 * cloth128: noise); CH 32 or 128 (no difference). Earlier: prefetching 16 or 64
 * constraints ahead cost 0.3-0.5 ns. */
static inline __attribute__((always_inline, target("avx2"))) void
project_range4(const wb_distances *ds, const wb_real *restrict wv, wb_real *x, const wb_real *restrict xp,
               wb_real *out, int32_t b, int32_t e, wb_real h, wb_real inv_h2, wb_real omega,
               const int damped, const int jacobi, const int fresh)
{
    const uint32_t *restrict soa = ds->s_oa, *restrict soc = ds->s_oc;
    const wb_real *restrict swa = ds->s_wa, *restrict swc = ds->s_wc;
    wb_real *restrict lambda = ds->s_lambda;
    const __m256d zero = _mm256_setzero_pd(), tiny = _mm256_set1_pd(1e-24), inf = _mm256_set1_pd(INFINITY);
    const __m256d absmask = _mm256_castsi256_pd(_mm256_set1_epi64x(INT64_MAX));
    const __m256d vh = _mm256_set1_pd(h), vomega = _mm256_set1_pd(omega);
    const __m256d kfree = _mm256_set1_pd(STRETCH_FREE), two = _mm256_set1_pd(2);
    enum { CH = 64 };
    /* per constraint of the chunk: s; |d|; rel (damped); the lane going on (all bits) */
    double sv[CH] __attribute__((aligned(32))), lv[CH] __attribute__((aligned(32)));
    double rv[CH] __attribute__((aligned(32))), gv[CH] __attribute__((aligned(32)));
    uint8_t wr[CH / 4]; /* per group: bit j, lane j writes its a end; bit 4 + j, its c end */
    uint8_t go[CH / 4]; /* per group: some lane goes on */
    int32_t i = b;
    while (i + 4 <= e) {
        const int32_t c0 = i, cn = (e - i) / 4 * 4 < CH ? (e - i) / 4 * 4 : CH;
        /* 1: the lengths (and the relative velocities), the masks */
        for (int g = 0; g < cn; g += 4) {
            const int32_t j = c0 + g;
            size_t ia[4], ic[4];
            offsets(&soa[j], &soc[j], ia, ic);
            __m256d xa0, xa1, xa2, xc0, xc1, xc2;
            wb__load4(x, ia, &xa0, &xa1, &xa2);
            wb__load4(x, ic, &xc0, &xc1, &xc2);
            const __m256d d0 = _mm256_sub_pd(xc0, xa0), d1 = _mm256_sub_pd(xc1, xa1), d2 = _mm256_sub_pd(xc2, xa2);
            const __m256d len2 = _mm256_add_pd(_mm256_add_pd(_mm256_mul_pd(d0, d0), _mm256_mul_pd(d1, d1)),
                                               _mm256_mul_pd(d2, d2));
            __m256d live = _mm256_cmp_pd(len2, tiny, _CMP_NLT_UQ);
            uint32_t ok;
            memcpy(&ok, &ds->s_ok[j], sizeof ok);
            if (ok == 0x01010101u && _mm256_movemask_pd(live) == 15) {
                wr[g / 4] = 0xff; /* every lane goes on and writes both ends */
            } else {
                /* the lanes that go on: !(wsum == 0 || len2 < 1e-24) && !isinf(at), NaN going on */
                const __m256d wa = _mm256_loadu_pd(&swa[j]), wc = _mm256_loadu_pd(&swc[j]);
                const __m256d at = _mm256_loadu_pd(&ds->s_at[j]);
                live = _mm256_and_pd(_mm256_and_pd(_mm256_cmp_pd(_mm256_add_pd(wa, wc), zero, _CMP_NEQ_UQ), live),
                                     _mm256_cmp_pd(_mm256_and_pd(at, absmask), inf, _CMP_NEQ_UQ));
                const int wra = _mm256_movemask_pd(_mm256_and_pd(live, _mm256_cmp_pd(wa, zero, _CMP_GT_OQ)));
                const int wrc = _mm256_movemask_pd(_mm256_and_pd(live, _mm256_cmp_pd(wc, zero, _CMP_GT_OQ)));
                wr[g / 4] = (uint8_t)(wra | wrc << 4);
            }
            go[g / 4] = _mm256_movemask_pd(live) != 0;
            _mm256_store_pd(&gv[g], live);
            _mm256_store_pd(&lv[g], _mm256_sqrt_pd(len2));
            if (damped) {
                __m256d pa0, pa1, pa2, pc0, pc1, pc2;
                wb__load4(xp, ia, &pa0, &pa1, &pa2);
                wb__load4(xp, ic, &pc0, &pc1, &pc2);
                const __m256d r0 = _mm256_mul_pd(_mm256_sub_pd(_mm256_sub_pd(xc0, pc0), _mm256_sub_pd(xa0, pa0)), d0);
                const __m256d r1 = _mm256_mul_pd(_mm256_sub_pd(_mm256_sub_pd(xc1, pc1), _mm256_sub_pd(xa1, pa1)), d1);
                const __m256d r2 = _mm256_mul_pd(_mm256_sub_pd(_mm256_sub_pd(xc2, pc2), _mm256_sub_pd(xa2, pa2)), d2);
                _mm256_store_pd(&rv[g], _mm256_add_pd(_mm256_add_pd(r0, r1), r2));
            }
        }
        /* 2: s and lambda */
        for (int g = 0; g < cn; g += 4) {
            if (!go[g / 4]) {
                if (fresh) _mm256_storeu_pd(&lambda[c0 + g], zero);
                continue;
            }
            const int32_t j = c0 + g;
            const __m256d wsum = _mm256_add_pd(_mm256_loadu_pd(&swa[j]), _mm256_loadu_pd(&swc[j]));
            const __m256d at = _mm256_loadu_pd(&ds->s_at[j]), len = _mm256_load_pd(&lv[g]);
            const __m256d lam = fresh ? zero : _mm256_loadu_pd(&lambda[j]);
            __m256d num = _mm256_sub_pd(_mm256_sub_pd(_mm256_loadu_pd(&ds->s_rest[j]), len), _mm256_mul_pd(at, lam));
            __m256d den = _mm256_add_pd(wsum, at);
            if (damped) {
                const __m256d gamma = _mm256_mul_pd(_mm256_mul_pd(at, _mm256_loadu_pd(&ds->s_beta[j])), vh);
                const __m256d rel = _mm256_load_pd(&rv[g]);
                const __m256d ginf = _mm256_cmp_pd(_mm256_and_pd(gamma, absmask), inf, _CMP_EQ_OQ);
                const __m256d nfin = _mm256_sub_pd(num, _mm256_div_pd(_mm256_mul_pd(gamma, rel), len));
                const __m256d dfin = _mm256_add_pd(den, _mm256_mul_pd(gamma, wsum));
                const __m256d ninf = _mm256_div_pd(_mm256_xor_pd(rel, _mm256_set1_pd(-0.0)), len);
                num = _mm256_blendv_pd(nfin, ninf, ginf);
                den = _mm256_blendv_pd(dfin, wsum, ginf);
            }
            __m256d s = _mm256_div_pd(num, _mm256_mul_pd(den, len));
            if (jacobi) s = _mm256_mul_pd(s, _mm256_mul_pd(vomega, _mm256_loadu_pd(&ds->s_jac[j])));
            /* a compressed link's lengthening bent past STRETCH_FREE (project_range), the
             * same operations; the divisions only when a live lane needs them */
            uint32_t bk;
            memcpy(&bk, &ds->s_backed[j], sizeof bk);
            if (bk) {
                const __m256i lanes = _mm256_cvtepu8_epi64(_mm_cvtsi32_si128((int)bk));
                const __m256d e = _mm256_mul_pd(s, wsum);
                const __m256d over = _mm256_and_pd(_mm256_cmp_pd(e, kfree, _CMP_GT_OQ),
                                                   _mm256_castsi256_pd(_mm256_cmpgt_epi64(lanes, _mm256_setzero_si256())));
                if (_mm256_movemask_pd(_mm256_and_pd(over, _mm256_load_pd(&gv[g]))))
                    s = _mm256_blendv_pd(
                        s, _mm256_div_pd(_mm256_mul_pd(kfree, _mm256_sub_pd(two, _mm256_div_pd(kfree, e))), wsum), over);
            }
            /* a blend and a plain store: a masked store is slow on AMD */
            _mm256_storeu_pd(&lambda[j], _mm256_blendv_pd(lam, _mm256_add_pd(lam, _mm256_mul_pd(s, len)),
                                                          _mm256_load_pd(&gv[g])));
            _mm256_store_pd(&sv[g], s);
        }
        /* 3: the corrections */
        for (int g = 0; g < cn; g += 4) {
            const int m = wr[g / 4];
            if (!m) continue;
            const int32_t j = c0 + g;
            wb_real *const ra[4] = { out + soa[j], out + soa[j + 1], out + soa[j + 2], out + soa[j + 3] };
            wb_real *const rc[4] = { out + soc[j], out + soc[j + 1], out + soc[j + 2], out + soc[j + 3] };
            __m256d xa0, xa1, xa2, xc0, xc1, xc2;
            if (jacobi) {
                size_t ia[4], ic[4];
                offsets(&soa[j], &soc[j], ia, ic);
                wb__load4(x, ia, &xa0, &xa1, &xa2);
                wb__load4(x, ic, &xc0, &xc1, &xc2);
            } else { /* out is x */
                load4p(ra, &xa0, &xa1, &xa2);
                load4p(rc, &xc0, &xc1, &xc2);
            }
            const __m256d d0 = _mm256_sub_pd(xc0, xa0), d1 = _mm256_sub_pd(xc1, xa1), d2 = _mm256_sub_pd(xc2, xa2);
            const __m256d s = _mm256_load_pd(&sv[g]);
            const __m256d fa = _mm256_mul_pd(_mm256_loadu_pd(&swa[j]), s), fc = _mm256_mul_pd(_mm256_loadu_pd(&swc[j]), s);
            __m256d oa0 = xa0, oa1 = xa1, oa2 = xa2, oc0 = xc0, oc1 = xc1, oc2 = xc2;
            if (jacobi) {
                load4p(ra, &oa0, &oa1, &oa2);
                load4p(rc, &oc0, &oc1, &oc2);
            }
            oa0 = _mm256_sub_pd(oa0, _mm256_mul_pd(fa, d0));
            oa1 = _mm256_sub_pd(oa1, _mm256_mul_pd(fa, d1));
            oa2 = _mm256_sub_pd(oa2, _mm256_mul_pd(fa, d2));
            oc0 = _mm256_add_pd(oc0, _mm256_mul_pd(fc, d0));
            oc1 = _mm256_add_pd(oc1, _mm256_mul_pd(fc, d1));
            oc2 = _mm256_add_pd(oc2, _mm256_mul_pd(fc, d2));
            if (m == 0xff) {
                store4p(ra, oa0, oa1, oa2);
                store4p(rc, oc0, oc1, oc2);
                continue;
            }
            /* a pinned end or a skipped lane in the group: lane by lane */
            double na[3][4] __attribute__((aligned(32))), nc[3][4] __attribute__((aligned(32)));
            _mm256_store_pd(na[0], oa0); _mm256_store_pd(na[1], oa1); _mm256_store_pd(na[2], oa2);
            _mm256_store_pd(nc[0], oc0); _mm256_store_pd(nc[1], oc1); _mm256_store_pd(nc[2], oc2);
            for (int l = 0; l < 4; l++) {
                if (m >> l & 1) {
                    wb_real *o = ra[l];
                    o[0] = na[0][l]; o[1] = na[1][l]; o[2] = na[2][l];
                }
                if (m >> (4 + l) & 1) {
                    wb_real *o = rc[l];
                    o[0] = nc[0][l]; o[1] = nc[1][l]; o[2] = nc[2][l];
                }
            }
        }
        i += cn;
    }
    if (i < e) project_range(ds, wv, x, xp, out, i, e, h, inv_h2, omega, damped, jacobi, fresh, 0);
}

static __attribute__((target("avx2"))) void
project_distances_avx2(const wb_world *w, wb_real *dx, int32_t b, int32_t e, wb_real h, wb_real inv_h2)
{
    const wb_distances *ds = w->dist;
    const wb_real *wv = w->m.w, *xp = w->s.x_prev, omega = w->m.def.relaxation;
    const int fresh = ds->s_lambda_stale;
    wb_real *x = w->s.x;
    if (dx) {
        if (ds->any_damping) project_range4(ds, wv, x, xp, dx, b, e, h, inv_h2, omega, 1, 1, fresh);
        else project_range4(ds, wv, x, xp, dx, b, e, h, inv_h2, omega, 0, 1, fresh);
    } else {
        if (ds->any_damping) project_range4(ds, wv, x, xp, x, b, e, h, inv_h2, omega, 1, 0, fresh);
        else project_range4(ds, wv, x, xp, x, b, e, h, inv_h2, omega, 0, 0, fresh);
    }
}
#endif

/* the vector path: -1 not yet decided, 0 off (no AVX2, or turned off), 1 on */
static int simd_state = -1;

/* Internal switch for tests: on = 0 forces the scalar loop, on = 1 uses the vector
 * path where the CPU has it; returns whether the vector path is on. Not thread-safe:
 * call it between steps. */
int wb__distance_simd(int on);
int wb__distance_simd(int on) { return wb__simd_set(&simd_state, on); }

static void project_distances(const wb_world *w, wb_real *dx, int32_t b, int32_t e, wb_real h, wb_real inv_h2)
{
    const wb_distances *ds = w->dist;
#ifdef WB_DISTANCE_AVX2
    /* the vector lanes need a conflict-free batch: never the serial tail */
    if (e - b >= 4 && e <= ds->bt.colour_start[ds->bt.serial_start]) {
        /* decided once, possibly by several threads at once (the same answer) */
        int v = __atomic_load_n(&simd_state, __ATOMIC_RELAXED);
        if (v < 0) v = wb__distance_simd(1);
        if (v) {
            project_distances_avx2(w, dx, b, e, h, inv_h2);
            return;
        }
    }
#endif
    const wb_real *wv = w->m.w, *xp = w->s.x_prev, omega = w->m.def.relaxation;
    const int fresh = ds->s_lambda_stale;
    wb_real *x = w->s.x;
    if (dx) {
        if (ds->any_damping) project_range(ds, wv, x, xp, dx, b, e, h, inv_h2, omega, 1, 1, fresh, 0);
        else project_range(ds, wv, x, xp, dx, b, e, h, inv_h2, omega, 0, 1, fresh, 0);
    } else {
        if (ds->any_damping) project_range(ds, wv, x, xp, x, b, e, h, inv_h2, omega, 1, 0, fresh, 0);
        else project_range(ds, wv, x, xp, x, b, e, h, inv_h2, omega, 0, 0, fresh, 0);
    }
}

/* Jacobi's corrections go to dx, Gauss-Seidel's straight to x */
static wb_real *jacobi_dx(const wb_world *w) { return w->m.def.solver == WB_SOLVER_GAUSS_SEIDEL ? NULL : w->k.dx; }

/* packed [lo, hi) of one batch, or of a chunk of one (batch.h) */
static void project_batch(wb_world *w, const int32_t *order, int32_t lo, int32_t hi, wb_real h)
{
    (void)order; /* the packed copies are in batch order already */
    project_distances(w, jacobi_dx(w), lo, hi, h, 1 / (h * h));
}

/* The compounds, one after another, after the batches (batch.h gives them in one call,
 * order[lo, hi) their whole range: a compound is a few links, and a call each cost 13%
 * more instructions). Gauss-Seidel: a compound's members are worked out from the same
 * positions (into dx, zeroed at their ends before and after) and applied together. A
 * compound is its own mirror image, so is its update; projected one by one, as a
 * colouring would, the images would lean the way they follow each other (a box dropped on
 * a 7 x 4 x 7 block turned at 0.69 rad/s). Each shared end's mass is split among the
 * members there (mass splitting: their corrections add up to about one link's, not
 * overshoot). Jacobi: as any other range */
static void project_compounds(wb_world *w, const int32_t *order, int32_t lo, int32_t hi, wb_real h)
{
    if (jacobi_dx(w)) {
        project_batch(w, order, lo, hi, h);
        return;
    }
    const wb_distances *ds = w->dist;
    const wb_real *wv = w->m.w, *xp = w->s.x_prev, inv_h2 = 1 / (h * h);
    const int fresh = ds->s_lambda_stale;
    wb_real *x = w->s.x, *dx = w->k.dx;
    for (int32_t c = 0; c < ds->bt.ncomp; c++) {
        const int32_t b = ds->bt.comp_start[c], e = ds->bt.comp_start[c + 1];
        for (int32_t i = b; i < e; i++) {
            v3_set(&dx[3 * ds->s_a[i]], 0, 0, 0);
            v3_set(&dx[3 * ds->s_b[i]], 0, 0, 0);
        }
        if (ds->any_damping) project_range(ds, wv, x, xp, dx, b, e, h, inv_h2, 1, 1, 0, fresh, 1);
        else project_range(ds, wv, x, xp, dx, b, e, h, inv_h2, 1, 0, 0, fresh, 1);
        for (int32_t i = b; i < e; i++)
            for (int end = 0; end < 2; end++) {
                const int32_t p = end ? ds->s_b[i] : ds->s_a[i];
                if (!(wv[p] > 0)) continue;
                v3_add(&x[3 * p], &x[3 * p], &dx[3 * p]);
                v3_set(&dx[3 * p], 0, 0, 0);
            }
    }
}

/* one iteration over every distance constraint: batch after batch in colour order, a
 * batch of 512 or more in parallel chunks, then the compounds (batch.h) */
static void distance_project(wb_world *w, wb_real h)
{
    wb_distances *ds = w->dist;
    if (!ds) return;
    wb_cache *k = &w->k;
    const int32_t np = w->m.np;
    k->projections += ds->ns;
    if (h != ds->s_at_h) refresh_at(ds, h);
    /* Jacobi: every correction from the same positions, scaled per constraint
     * (see project_range), then applied at once */
    const int jacobi = jacobi_dx(w) != NULL;
    if (jacobi) {
        if (np == 0) return;
        memset(k->dx, 0, sizeof(wb_real) * 3 * (size_t)np);
    }
    wb__batches_run(&ds->bt, w, 512, project_batch, project_compounds, ds->s_slot, h);
    ds->s_lambda_stale = 0;
    if (!jacobi) return;
    const wb_real *wv = w->m.w;
    for (int32_t i = 0; i < np; i++)
        if (wv[i] > 0) v3_add(&w->s.x[3 * i], &w->s.x[3 * i], &k->dx[3 * i]);
}

/* The multipliers start each substep at 0: the first projection reads them as 0 and
 * writes every one, skipped constraints included (a memset of them all cost 2% of the
 * 128 x 128 cloth's frame); until it has, force() reads 0 (an undone frame, no
 * iterations) and distance_frame_end clears them. */
static void distance_substep_begin(wb_world *w)
{
    if (w->dist) w->dist->s_lambda_stale = 1;
}

static void report_break(wb_world *w, int32_t s)
{
    wb_distances *ds = w->dist;
    ds->broken[s] = 1;
    w->m.topology_dirty = 1;
    wb_distance_id id = { (uint32_t)s + 1, ds->gen[s] };
    wb_distance_id *q = wb__grow(ds->breaks, &ds->cap_breaks, ds->nbreaks + 1, sizeof *q);
    if (q) { ds->breaks = q; ds->breaks[ds->nbreaks++] = id; }
}

/* plastic flow and breaking, once per frame on the frame's final lengths; break_force
 * on the multiplier of the frame's last substep (the force wb_distance_force reads) */
static void distance_frame_end(wb_world *w)
{
    wb_distances *ds = w->dist;
    /* nothing can break or flow: no walk over them all */
    if (!ds || !ds->any_frame_end) return;
    const wb_real dt = w->m.def.dt, inv_h2 = 1 / (w->k.h_last * w->k.h_last);
    if (ds->s_lambda_stale && ds->ns > 0) { /* (no iterations: nothing projected) */
        memset(ds->s_lambda, 0, sizeof(wb_real) * (size_t)ds->ns);
        ds->s_lambda_stale = 0;
    }
    for (int32_t i = 0; i < ds->ns; i++) {
        const int32_t s = ds->s_slot[i];
        if (ds->break_strain[s] <= 0 && ds->yield[s] <= 0 && ds->bforce[s] <= 0) continue;
        if (ds->bforce[s] > 0 && fabs(ds->s_lambda[i]) * inv_h2 > ds->bforce[s]) {
            report_break(w, s);
            continue;
        }
        if (ds->break_strain[s] <= 0 && ds->yield[s] <= 0) continue;
        wb_real d[3];
        v3_sub(d, &w->s.x[3 * ds->s_b[i]], &w->s.x[3 * ds->s_a[i]]);
        const wb_real len = v3_len(d), rest = ds->s_rest[i];
        if (rest <= 0) continue;
        const wb_real strain = (len - rest) / rest;
        if (ds->break_strain[s] > 0 && strain > ds->break_strain[s]) {
            report_break(w, s);
            continue;
        }
        const wb_real a = fabs(strain), y = ds->yield[s];
        if (y > 0 && a > y) {
            /* flow towards the current length by the part of the strain past yield */
            const wb_real rate = ds->creep[s] * dt < 1 ? ds->creep[s] * dt : 1;
            /* the part past yield, (a - y)/a; a rest so small that the strain overflows
             * (inf/inf = NaN would poison the rest for good) flows as if a were huge: 1 */
            const wb_real past = isinf(a) ? 1 : (a - y) / a;
            const wb_real r = rest + rate * (len - rest) * past;
            ds->s_rest[i] = r;
            ds->rest[s] = r;
        }
    }
}

/* elastic: U = C^2 / (2 alpha) for compliant constraints (alpha = 1/k) */
static wb_real distance_energy(const wb_world *w)
{
    const wb_distances *ds = wb__dist(w->dist);
    wb_real pe = 0;
    for (int32_t s = 0; s < ds->n; s++) {
        if (!packable(ds, s) || ds->alpha[s] <= 0) continue;
        wb_real d[3];
        v3_sub(d, &w->s.x[3 * ds->ij[2 * s + 1]], &w->s.x[3 * ds->ij[2 * s]]);
        wb_real c = v3_len(d) - ds->rest[s];
        pe += c * c / (2 * ds->alpha[s]);
    }
    return pe;
}

static int32_t distance_count(const wb_world *w) { return wb__dist(w->dist)->nlive; }

/* every live link joins its two ends (a torn one too: they were neighbours) */
static void distance_links(const wb_world *w, wb_link_fn fn, void *ud)
{
    const wb_distances *ds = wb__dist(w->dist);
    for (int32_t s = 0; s < ds->n; s++)
        if (ds->gen[s] & 1u) fn(ud, ds->ij[2 * s], ds->ij[2 * s + 1], 1);
}

/* a body is held together by its live, unbroken links (in slot order) */
static void distance_joins(const wb_world *w, wb_link_fn fn, void *ud)
{
    const wb_distances *ds = wb__dist(w->dist);
    for (int32_t s = 0; s < ds->n; s++)
        if (packable(ds, s)) fn(ud, ds->ij[2 * s], ds->ij[2 * s + 1], 1);
}

/* ---- teardown and hash (ctype.h) ----------------------------------------------------------- */
static void distance_destroy(wb_world *w)
{
    wb_distances *ds = w->dist;
    if (!ds) return;
    void *p[] = { ds->ij, ds->alpha, ds->beta, ds->yield, ds->creep, ds->break_strain, ds->bforce, ds->gen,
                  ds->free_slots, ds->rest, ds->broken, ds->s_nsp, ds->s_a, ds->s_b, ds->s_rest,
                  ds->s_alpha, ds->s_beta, ds->s_lambda, ds->s_jac, ds->s_slot, ds->slot_pack, ds->breaks };
    for (size_t i = 0; i < sizeof p / sizeof p[0]; i++) free(p[i]);
    wb__batches_free(&ds->bt);
    free(ds);
    w->dist = NULL;
}

static size_t distance_charged(const wb_world *w) { return w->dist ? w->dist->charged : 0; }

/* the packed links' largest |len - rest + alpha~ lambda| (a link's two gradients are unit) */
static wb_real distance_residual(const wb_world *w, wb_real h)
{
    const wb_distances *ds = wb__dist(w->dist);
    const wb_real *x = w->s.x, *wv = w->m.w, inv_h2 = 1 / (h * h);
    wb_real r = 0;
    for (int32_t i = 0; i < ds->ns; i++) {
        const int32_t a = ds->s_a[i], b = ds->s_b[i];
        if (wv[a] + wv[b] == 0) continue;
        wb_real d[3];
        v3_sub(d, &x[3 * b], &x[3 * a]);
        const wb_real at = ds->s_alpha[i] * inv_h2, lam = ds->s_lambda_stale ? 0 : ds->s_lambda[i];
        const wb_real ri = isinf(at) ? 0 : fabs(v3_len(d) - ds->s_rest[i] + at * lam);
        r = ri > r ? ri : r;
    }
    return r;
}

/* the live ones' state (rest lengths, broken flags) in slot order */
static uint64_t distance_hash(const wb_world *w, uint64_t h)
{
    const wb_distances *ds = wb__dist(w->dist);
    for (int32_t i = 0; i < ds->n; i++) {
        if (!(ds->gen[i] & 1u)) continue;
        h = wb__fnv(h, &ds->rest[i], sizeof ds->rest[i]);
        h = wb__fnv(h, &ds->broken[i], 1);
    }
    return h;
}

static void distance_image_free(wb_image *g)
{
    wb_image_distance *d = &g->dist;
    void *p[] = { d->ij, d->alpha, d->beta, d->yield, d->creep, d->break_strain, d->rest, d->bforce, d->broken,
                  d->gen, d->free_slots };
    for (size_t i = 0; i < sizeof p / sizeof p[0]; i++) free(p[i]);
    memset(d, 0, sizeof *d);
}

/* calloc of n elements, never of 0 bytes (so NULL always means out of memory) */
static void *zalloc(int64_t n, size_t elem) { return calloc((size_t)(n > 0 ? n : 1), elem); }

wb_status wb_image_alloc_distances(wb_image *g, int32_t nd, int32_t nfree)
{
    distance_image_free(g);
    wb_image_distance *d = &g->dist;
    d->n = nd;
    d->nfree = nfree;
    d->ij = zalloc(2 * (int64_t)nd, sizeof *d->ij);
    wb_real **r[] = { &d->alpha, &d->beta, &d->yield, &d->creep, &d->break_strain, &d->rest, &d->bforce };
    int ok = d->ij != NULL;
    for (size_t k = 0; k < sizeof r / sizeof r[0]; k++) ok &= (*r[k] = zalloc(nd, sizeof(wb_real))) != NULL;
    d->broken = zalloc(nd, 1);
    d->gen = zalloc(nd, sizeof *d->gen);
    d->free_slots = zalloc(nfree, sizeof *d->free_slots);
    if (!ok || !d->broken || !d->gen || !d->free_slots) {
        distance_image_free(g);
        return WB_ERR_NOMEM;
    }
    for (int32_t i = 0; i < nd; i++) d->gen[i] = 1;
    return WB_OK;
}

static wb_status distance_image_save(const wb_world *w, wb_image *g)
{
    const wb_distances *ds = wb__dist(w->dist);
    wb_status st = wb_image_alloc_distances(g, ds->n, ds->nfree);
    if (st != WB_OK || ds->n == 0) return st;
    wb_image_distance *d = &g->dist;
    const size_t n = (size_t)ds->n;
    memcpy(d->ij, ds->ij, 2 * n * sizeof *d->ij);
    memcpy(d->alpha, ds->alpha, n * sizeof(wb_real));
    memcpy(d->beta, ds->beta, n * sizeof(wb_real));
    memcpy(d->yield, ds->yield, n * sizeof(wb_real));
    memcpy(d->creep, ds->creep, n * sizeof(wb_real));
    memcpy(d->break_strain, ds->break_strain, n * sizeof(wb_real));
    memcpy(d->bforce, ds->bforce, n * sizeof(wb_real));
    memcpy(d->rest, ds->rest, n * sizeof(wb_real));
    memcpy(d->broken, ds->broken, n);
    memcpy(d->gen, ds->gen, n * sizeof *d->gen);
    if (ds->nfree) memcpy(d->free_slots, ds->free_slots, (size_t)ds->nfree * sizeof *d->free_slots);
    return WB_OK;
}

static wb_distance_def image_def(const wb_image_distance *d, int32_t i)
{
    const wb_distance_def def = { d->alpha[i], d->beta[i], d->rest[i], d->yield[i], d->creep[i], d->break_strain[i],
                                  d->bforce[i] };
    return def;
}

/* the live slots' constraints; *dead counts the others */
static const char *check_live(const wb_image *g, int32_t *dead)
{
    const wb_image_distance *d = &g->dist;
    for (int32_t i = 0; i < d->n; i++) {
        if (!(d->gen[i] & 1u)) { ++*dead; continue; }
        const int32_t a = d->ij[2 * i], b = d->ij[2 * i + 1];
        if (a < 0 || b < 0 || a >= g->np || b >= g->np) return "constraint particle out of range";
        if (a == b) return "a constraint needs two distinct particles";
        const wb_distance_def def = image_def(d, i);
        const char *e = wb_distance_def_check(&def);
        if (e) return e;
        if (!(d->rest[i] >= 0)) return "rest length must be >= 0";
        wb_real dx[3];
        v3_sub(dx, &g->x[3 * b], &g->x[3 * a]);
        if (!isfinite(v3_dot(dx, dx))) return "constraint particles are too far apart (their distance squared overflows)";
    }
    return NULL;
}

static const char *distance_image_check(const wb_image *g)
{
    const wb_image_distance *d = &g->dist;
    if (d->n < 0 || d->n > WB_MAX_CONSTRAINTS) return "too many constraints";
    int32_t dead = 0;
    const char *e = check_live(g, &dead);
    if (e) return e;
    /* the free list is exactly the dead slots, each once (a mark per slot: linear) */
    if (d->nfree != dead) return "the free constraint slots do not match the dead ones";
    if (d->nfree == 0) return NULL;
    uint8_t *seen = calloc((size_t)d->n, 1);
    if (!seen) return "out of memory checking the free constraint slots";
    for (int32_t i = 0; i < d->nfree && !e; i++) {
        const int32_t s = d->free_slots[i];
        if (s < 0 || s >= d->n || (d->gen[s] & 1u)) e = "a free constraint slot is not a dead one";
        else if (seen[s]++) e = "a free constraint slot is listed twice";
    }
    free(seen);
    return e;
}

/* a new world: every slot; appended: the live ones */
static wb_status distance_image_reserve(wb_world *w, const wb_image *g, const wb_image_at *at)
{
    const wb_image_distance *d = &g->dist;
    int32_t n = d->n;
    if (!at->exact) {
        n = 0;
        for (int32_t i = 0; i < d->n; i++) n += (int32_t)(d->gen[i] & 1u);
    }
    return wb__reserve(w, 0, n);
}

/* a new world takes the slots as they are (generations, free list: the same future) */
static void put_exact(wb_world *w, const wb_image_distance *d)
{
    wb_distances *ds = w->dist; /* made by the reserve when there are slots */
    if (!ds) return;
    const size_t n = (size_t)d->n;
    ds->n = d->n;
    ds->nlive = 0;
    if (n) {
        memcpy(ds->ij, d->ij, 2 * n * sizeof *ds->ij);
        memcpy(ds->alpha, d->alpha, n * sizeof(wb_real));
        memcpy(ds->beta, d->beta, n * sizeof(wb_real));
        memcpy(ds->yield, d->yield, n * sizeof(wb_real));
        memcpy(ds->creep, d->creep, n * sizeof(wb_real));
        memcpy(ds->break_strain, d->break_strain, n * sizeof(wb_real));
        memcpy(ds->bforce, d->bforce, n * sizeof(wb_real));
        memcpy(ds->rest, d->rest, n * sizeof(wb_real));
        memcpy(ds->broken, d->broken, n);
        memcpy(ds->gen, d->gen, n * sizeof *ds->gen);
    }
    for (size_t i = 0; i < n; i++) {
        ds->slot_pack[i] = -1;
        ds->nlive += (int32_t)(d->gen[i] & 1u);
    }
    ds->nfree = d->nfree;
    if (d->nfree) memcpy(ds->free_slots, d->free_slots, (size_t)d->nfree * sizeof *ds->free_slots);
}

/* appended: the live ones added after w's (checked and reserved: cannot fail) */
static void distance_image_put(wb_world *w, const wb_image *g, const wb_image_at *at)
{
    const wb_image_distance *d = &g->dist;
    if (at->exact) {
        put_exact(w, d);
        return;
    }
    for (int32_t i = 0; i < d->n; i++) {
        if (!(d->gen[i] & 1u)) continue;
        const wb_distance_def def = image_def(d, i);
        const wb_distance_id id = wb_distance_add(w, at->pshift + d->ij[2 * i], at->pshift + d->ij[2 * i + 1], &def, NULL);
        w->dist->broken[id.index - 1] = d->broken[i];
    }
}

static void distance_stats(const wb_world *w, wb_stats *st)
{
    const wb_distances *ds = wb__dist(w->dist);
    st->distances = ds->nlive;
    st->colours = ds->bt.ncolours;
    for (int32_t s = 0; s < ds->n; s++)
        if ((ds->gen[s] & 1u) && ds->broken[s]) st->broken++;
}

/* ---- the VBD solver's part (vbd.h) --------------------------------------------------------- */
/* A hard link's multiplier lambda is kept whole from substep to substep (decayed, a chain
 * at rest kept a stretch of its decay over its penalty) and grows by k C after each
 * substep's sweeps (the augmented Lagrangian's own update). Its penalty k is fixed,
 * VBD_LINK_K times the inertia of its ends over the substep (start_penalty): a penalty that
 * grew while a link was stretched and decayed while it was not pumped energy into swinging
 * chains (a rope swinging at 40 x 4 gained twice its energy); measured: 4 k0 let a 100-link
 * chain hang 6% long, 16 k0 threw a lattice stacked on another, 64 k0 let a two-pin cloth
 * gain 3x its energy. Of the error it begins the substep with it keeps WB_VBD_STAB */
#define VBD_LINK_K ((wb_real)8)
/* in a world with volume constraints (projected after the sweeps) a body of rigid links
 * and incompressible tets is over-constrained under a press: a link that takes its error
 * back faster fights the tets (0.99: a block squeezed to 60% blew up 3 s on at 10 m/s), a
 * slower one holds the squeeze after the press lets go (0.999: back to 0.87 of its height) */
#define VBD_STAB_VOL ((wb_real)0.995)

/* a link as the vertex step reads it: its force along it is kk (l - tgt) + lm and its
 * stiffness kk; dmp: a soft link's damping beta / h */
typedef struct vbd_link {
    wb_real tgt, kk, lm, dmp;
} vbd_link;

/* the links' part of the VBD solver's cache */
typedef struct dist_vbd {
    int32_t nd;            /* the slots it was built for */
    int32_t *adj_start;    /* (np + 1) each vertex's range of adj, padded to a multiple of 4 */
    int32_t *adj;          /* link slots touching each vertex (-1: padding) */
    int32_t *adjo;         /* the other end j of each of them as its offset in x, 3 j (padding:
                              the vertex itself) */
    wb_real *ekk, *etg, *elm, *edm; /* each entry's link as the sweep reads it (vbd_link's kk,
                              tgt, lm, dmp; padding 0): 4 entries in one load each */
    int32_t *epos;         /* (2 nd) the two entries of each link */
    wb_real *lam;          /* (cap) a hard link's multiplier (a stiff one's: its tension) */
    wb_real *c0;           /* (cap) a hard link's error (a stiff one's: C - alpha lam) as the
                              last sweep left it, before the types projected after it (NaN:
                              not known), of which it keeps WB_VBD_STAB */
    vbd_link *lk;          /* (cap) what the sweep reads of each link, set each substep */
    int32_t *hard;         /* (cap) the live hard links' slots, this substep, from the front
                              (nhard), and the stiff ones' from the back (nstiff) */
    int32_t nhard, nstiff, cap;
    int damped;            /* some link has a damping in the vertex steps this substep */
    wb_real *save;         /* (2 cap + 1) lam and c0 at the step's start (an undone frame) */
    int restored;          /* made from a snapshot image: the next build keeps c0 (the image
                              holds what the saved world's next step starts from) */
    size_t charged;        /* its bytes charged to def.memory */
} dist_vbd;

static void *dvbd_make(void) { return calloc(1, sizeof(dist_vbd)); }

static void dvbd_free(wb_world *w, void *part)
{
    dist_vbd *p = part;
    void *a[] = { p->adj_start, p->adj, p->adjo, p->ekk, p->etg, p->elm, p->edm, p->epos,
                  p->lam, p->c0, p->lk, p->hard, p->save };
    for (size_t i = 0; i < sizeof a / sizeof a[0]; i++) free(a[i]);
    wb__charge(w, &p->charged, 0);
    free(p);
}

static int32_t dvbd_slots(const wb_world *w) { return wb__dist(w->dist)->n; }

/* what a part holds for np vertices, ne adjacency entries, nd slots and multipliers for
 * cap: the struct, adj_start, adj, adjo, the 4 entry arrays, epos, lam, c0, lk, hard, save */
static size_t dvbd_bytes(int64_t np, int64_t ne, int64_t nd, int64_t cap)
{
    const size_t r = sizeof(wb_real), i4 = sizeof(int32_t);
    return sizeof(dist_vbd) + (size_t)(np + 1) * i4 + (size_t)ne * (2 * i4 + 4 * r) + 2 * (size_t)(nd > 0 ? nd : 1) * i4 +
           (size_t)cap * (2 * r + sizeof(vbd_link) + i4) + (2 * (size_t)cap + 1) * r;
}

/* each vertex's links (CSR, each range padded to a multiple of 4 for the vector lanes),
 * and multipliers for every slot */
static int dvbd_build(wb_world *w, void *part)
{
    dist_vbd *v = part;
    const wb_distances *ds = wb__dist(w->dist);
    const int32_t np = w->m.np, nd = ds->n;
    int32_t *start = calloc((size_t)np + 1, sizeof *start);
    if (!start) return 0;
    for (int32_t s = 0; s < nd; s++)
        if (packable(ds, s)) start[ds->ij[2 * s] + 1]++, start[ds->ij[2 * s + 1] + 1]++;
    for (int32_t i = 0; i < np; i++) start[i + 1] = start[i] + ((start[i + 1] + 3) & ~3);
    const size_t ne = (size_t)(start[np] > 0 ? start[np] : 1);
    const int32_t cap = nd > v->cap ? nd : v->cap;
    /* everything it holds for this model, charged before it is taken */
    if (!wb__charge(w, &v->charged, dvbd_bytes(np, (int64_t)ne, nd, cap))) {
        free(start);
        return 0;
    }
    int32_t *adj = malloc(sizeof *adj * ne), *adjo = malloc(sizeof *adjo * ne);
    int32_t *epos = malloc(sizeof *epos * 2 * (size_t)(nd > 0 ? nd : 1));
    int32_t *fill = malloc(sizeof *fill * (size_t)(np > 0 ? np : 1));
    wb_real *ek[4];
    for (int c = 0; c < 4; c++) ek[c] = calloc(ne, sizeof(wb_real));
    if (!adj || !adjo || !epos || !fill || !ek[0] || !ek[1] || !ek[2] || !ek[3]) {
        free(start), free(adj), free(adjo), free(epos), free(fill);
        for (int c = 0; c < 4; c++) free(ek[c]);
        return 0;
    }
    memcpy(fill, start, sizeof *fill * (size_t)np);
    for (int32_t s = 0; s < nd; s++) {
        if (!packable(ds, s)) continue;
        const int32_t a = ds->ij[2 * s], b = ds->ij[2 * s + 1];
        epos[2 * s] = fill[a], adjo[fill[a]] = 3 * b, adj[fill[a]++] = s;
        epos[2 * s + 1] = fill[b], adjo[fill[b]] = 3 * a, adj[fill[b]++] = s;
    }
    for (int32_t i = 0; i < np; i++)
        for (int32_t e = fill[i]; e < start[i + 1]; e++) adj[e] = -1, adjo[e] = 3 * i;
    free(fill);
    free(v->adj_start), free(v->adj), free(v->adjo), free(v->epos);
    free(v->ekk), free(v->etg), free(v->elm), free(v->edm);
    v->adj_start = start, v->adj = adj, v->adjo = adjo, v->epos = epos;
    v->ekk = ek[0], v->etg = ek[1], v->elm = ek[2], v->edm = ek[3];
    if (cap > v->cap) {
        if (!realloc_n((void **)&v->lam, cap, sizeof *v->lam) || !realloc_n((void **)&v->c0, cap, sizeof *v->c0) ||
            !realloc_n((void **)&v->lk, cap, sizeof *v->lk) || !realloc_n((void **)&v->hard, cap, sizeof *v->hard))
            return 0;
        /* new slots start with no multiplier and no error known (also in a part just
         * restored, whose image holds the errors of its own slots only) */
        memset(v->lam + v->cap, 0, sizeof *v->lam * (size_t)(cap - v->cap));
        for (int32_t q = v->cap; q < cap; q++) v->c0[q] = (wb_real)NAN;
    }
    if (!realloc_n((void **)&v->save, 2 * cap + 1, sizeof *v->save)) return 0;
    v->cap = cap;
    /* (a slot may hold another link now: its error is the one it starts with) */
    if (!v->restored)
        for (int32_t q = 0; q < nd; q++) v->c0[q] = (wb_real)NAN;
    v->restored = 0;
    v->nd = nd;
    return 1;
}

static uint64_t dvbd_neighbours(const wb_world *w, const void *part, int32_t i, const uint8_t *col)
{
    (void)w;
    const dist_vbd *v = part;
    uint64_t used = 0;
    for (int32_t e = v->adj_start[i]; e < v->adj_start[i + 1]; e++) {
        if (v->adj[e] < 0) continue;
        const int32_t j = v->adjo[e] / 3;
        if (j < i) used |= (uint64_t)1 << col[j];
    }
    return used;
}

static int dvbd_holds(const void *part, int32_t i)
{
    const dist_vbd *v = part;
    return v->adj_start[i + 1] > v->adj_start[i];
}

/* A link's force on i along n = (x_i - x_j) / l and its stiffness: a soft one's energy
 * C^2 / (2 alpha); a hard one's k C^2 / 2 + lambda C (vbd_link: C = l - tgt). The
 * Hessian's part across n, the force over l, is kept only while it pulls (a pushed link's
 * is indefinite: left out, as VBD does). A soft link's damping beta (N s/m) acts on the
 * speed it stretches at over the substep, as XPBD's (a hard link has none there either);
 * its block is beta / h n n^T.
 * A vertex's links are summed in 4 lanes (link q into lane q % 4, the lanes added as
 * (0 + 1) + (2 + 3)), and that sum added into the vertex step's fs and hs: the AVX2 path
 * below takes 4 links at once and gives these bits. */
static inline void links_scalar(const wb_world *w, const dist_vbd *v, int32_t i, wb_real fs[3], wb_real hs[6])
{
    wb_real F[3][4] = { { 0 } }, Hl[6][4] = { { 0 } };
    const wb_real *x = w->s.x, *xp = w->s.x_prev;
    const int32_t e0 = v->adj_start[i], n = v->adj_start[i + 1] - e0;
    for (int32_t q = 0; q < n; q++) {
        if (v->adj[e0 + q] < 0) continue;
        const int32_t j = v->adjo[e0 + q], c = q & 3; /* (3 j) */
        const vbd_link *L = &v->lk[v->adj[e0 + q]];
        const wb_real d0 = x[3 * i] - x[j], d1 = x[3 * i + 1] - x[j + 1], d2 = x[3 * i + 2] - x[j + 2];
        const wb_real l2 = d0 * d0 + d1 * d1 + d2 * d2;
        if (!(l2 > 1e-24)) continue;
        const wb_real l = sqrt(l2), il = 1 / l;
        wb_real fm = L->kk * (l - L->tgt) + L->lm, kn = L->kk;
        if (L->dmp > 0) {
            const wb_real u = d0 * (xp[j] - xp[3 * i]) + d1 * (xp[j + 1] - xp[3 * i + 1]) + d2 * (xp[j + 2] - xp[3 * i + 2]);
            fm = fm + L->dmp * (l + u * il);
            kn = kn + L->dmp;
        }
        const wb_real g = fm > 0 ? fm * il : 0, a = (kn - g) * il * il, fl = fm * il;
        F[0][c] -= fl * d0, F[1][c] -= fl * d1, F[2][c] -= fl * d2;
        Hl[0][c] += a * d0 * d0 + g, Hl[1][c] += a * d1 * d1 + g, Hl[2][c] += a * d2 * d2 + g;
        Hl[3][c] += a * d0 * d1, Hl[4][c] += a * d0 * d2, Hl[5][c] += a * d1 * d2;
    }
    for (int c = 0; c < 3; c++) fs[c] += (F[c][0] + F[c][1]) + (F[c][2] + F[c][3]);
    for (int c = 0; c < 6; c++) hs[c] += (Hl[c][0] + Hl[c][1]) + (Hl[c][2] + Hl[c][3]);
}

#if defined(__x86_64__) && defined(__GNUC__) && !defined(WB_FLOAT)
#define WB_DISTANCE_VBD_AVX2 1

/* the lanes of a and b added as (0 + 1) + (2 + 3): out[0] a's, out[1] b's */
static inline __attribute__((always_inline, target("avx2"))) void sum2(__m256d a, __m256d b, wb_real out[2])
{
    const __m256d t = _mm256_hadd_pd(a, b); /* a0+a1, b0+b1, a2+a3, b2+b3 */
    _mm_storeu_pd(out, _mm_add_pd(_mm256_castpd256_pd128(t), _mm256_extractf128_pd(t, 1)));
}

/* one group of 4 of vertex i's links (entries e .. e + 3; xi: i's position in each lane)
 * added into its lane sums s (f0, f1, f2, h0 .. h5). damped 0: no link of the part has a
 * damping, whose test the loop then leaves out */
static inline __attribute__((always_inline, target("avx2"))) void
link_group(const wb_real *x, const wb_real *xp, const dist_vbd *v, int32_t i, int32_t e, const __m256d xi[3], __m256d s[9],
           int damped)
{
    const __m256d zero = _mm256_setzero_pd(), one = _mm256_set1_pd(1), tiny = _mm256_set1_pd(1e-24);
    const int32_t *j = &v->adjo[e];
    const size_t o[4] = { (size_t)j[0], (size_t)j[1], (size_t)j[2], (size_t)j[3] };
    __m256d d0, d1, d2;
    wb__load4(x, o, &d0, &d1, &d2);
    d0 = _mm256_sub_pd(xi[0], d0), d1 = _mm256_sub_pd(xi[1], d1), d2 = _mm256_sub_pd(xi[2], d2);
    const __m256d l2 = _mm256_add_pd(_mm256_add_pd(_mm256_mul_pd(d0, d0), _mm256_mul_pd(d1, d1)), _mm256_mul_pd(d2, d2));
    /* a lane of no link (padding, or both ends at one point) gets 1 / l = 0: its force and
     * Hessian are then +-0, which leave the sums' bits as they are (a sum from +0 is never
     * -0), as the scalar loop that skips it */
    const __m256d l = _mm256_sqrt_pd(l2), il = _mm256_and_pd(_mm256_div_pd(one, l), _mm256_cmp_pd(l2, tiny, _CMP_GT_OQ));
    const __m256d K = _mm256_loadu_pd(&v->ekk[e]);
    __m256d fm = _mm256_add_pd(_mm256_mul_pd(K, _mm256_sub_pd(l, _mm256_loadu_pd(&v->etg[e]))), _mm256_loadu_pd(&v->elm[e]));
    __m256d kn = K;
    if (damped) {
        const __m256d D = _mm256_loadu_pd(&v->edm[e]), on = _mm256_cmp_pd(D, zero, _CMP_GT_OQ);
        if (_mm256_movemask_pd(on)) {
            /* the damped lanes only (a lane of dmp 0 would add 0 times a finite number: the
             * same fm, never -0, but the scalar loop does not add it) */
            __m256d u0, u1, u2;
            wb__load4(xp, o, &u0, &u1, &u2);
            u0 = _mm256_sub_pd(u0, _mm256_set1_pd(xp[3 * i]));
            u1 = _mm256_sub_pd(u1, _mm256_set1_pd(xp[3 * i + 1]));
            u2 = _mm256_sub_pd(u2, _mm256_set1_pd(xp[3 * i + 2]));
            const __m256d u = _mm256_add_pd(_mm256_add_pd(_mm256_mul_pd(d0, u0), _mm256_mul_pd(d1, u1)), _mm256_mul_pd(d2, u2));
            const __m256d dfm = _mm256_mul_pd(D, _mm256_add_pd(l, _mm256_mul_pd(u, il)));
            fm = _mm256_blendv_pd(fm, _mm256_add_pd(fm, dfm), on);
            kn = _mm256_blendv_pd(kn, _mm256_add_pd(kn, D), on);
        }
    }
    const __m256d g = _mm256_and_pd(_mm256_mul_pd(fm, il), _mm256_cmp_pd(fm, zero, _CMP_GT_OQ));
    const __m256d a = _mm256_mul_pd(_mm256_mul_pd(_mm256_sub_pd(kn, g), il), il), fl = _mm256_mul_pd(fm, il);
    const __m256d ad0 = _mm256_mul_pd(a, d0), ad1 = _mm256_mul_pd(a, d1);
    s[0] = _mm256_sub_pd(s[0], _mm256_mul_pd(fl, d0));
    s[1] = _mm256_sub_pd(s[1], _mm256_mul_pd(fl, d1));
    s[2] = _mm256_sub_pd(s[2], _mm256_mul_pd(fl, d2));
    s[3] = _mm256_add_pd(s[3], _mm256_add_pd(_mm256_mul_pd(ad0, d0), g));
    s[4] = _mm256_add_pd(s[4], _mm256_add_pd(_mm256_mul_pd(ad1, d1), g));
    s[5] = _mm256_add_pd(s[5], _mm256_add_pd(_mm256_mul_pd(_mm256_mul_pd(a, d2), d2), g));
    s[6] = _mm256_add_pd(s[6], _mm256_mul_pd(ad0, d1));
    s[7] = _mm256_add_pd(s[7], _mm256_mul_pd(ad0, d2));
    s[8] = _mm256_add_pd(s[8], _mm256_mul_pd(ad1, d2));
}

/* vertex i's position in each lane, its lane sums zeroed */
static inline __attribute__((always_inline, target("avx2"))) void link_start(const wb_real *x, int32_t i, __m256d xi[3],
                                                                            __m256d s[9])
{
    /* (written out: a loop over them kept the sums in memory at -O2) */
    xi[0] = _mm256_set1_pd(x[3 * i]), xi[1] = _mm256_set1_pd(x[3 * i + 1]), xi[2] = _mm256_set1_pd(x[3 * i + 2]);
    s[0] = s[1] = s[2] = s[3] = s[4] = s[5] = s[6] = s[7] = s[8] = _mm256_setzero_pd();
}

/* the lane sums added into the vertex step's fs and hs */
static inline __attribute__((always_inline, target("avx2"))) void link_sums(const __m256d s[9], wb_real fs[3], wb_real hs[6])
{
    wb_real t[10];
    sum2(s[0], s[1], t);
    sum2(s[2], s[3], t + 2);
    sum2(s[4], s[5], t + 4);
    sum2(s[6], s[7], t + 6);
    sum2(s[8], s[8], t + 8);
    fs[0] += t[0], fs[1] += t[1], fs[2] += t[2];
    hs[0] += t[3], hs[1] += t[4], hs[2] += t[5], hs[3] += t[6], hs[4] += t[7], hs[5] += t[8];
}

/* The vertices of a run two at a time, their groups interleaved, in a build for a core with
 * 32 vector registers (AVX-512's; -march=native on such a machine, as make bench's): one
 * vertex's groups are a chain of latencies (a square root and a division, then its sums)
 * that the core ran mostly one vertex at a time, two independent chains side by side keep
 * it busy (one iteration of the 128 x 128 cloth 11% faster). With 16 registers the two
 * vertices' 18 sums spill, and it was 10% slower: one at a time there. Each vertex's sums
 * are taken in the same order either way: the same bits */
#ifdef __AVX512F__
#define LINK_PAIRS 1
#else
#define LINK_PAIRS 0
#endif
static inline __attribute__((always_inline, target("avx2"))) void
links_avx2(const wb_world *w, const dist_vbd *v, const int32_t *vert, int32_t n, wb_real *f, wb_real *H, int damped)
{
    const wb_real *x = w->s.x, *xp = w->s.x_prev;
    int32_t k = 0;
    for (; LINK_PAIRS && k + 1 < n; k += 2) {
        const int32_t i = vert[k], i1 = vert[k + 1];
        const int32_t e0 = v->adj_start[i], n0 = v->adj_start[i + 1] - e0;
        const int32_t e1 = v->adj_start[i1], n1 = v->adj_start[i1 + 1] - e1;
        __m256d xi[3], s[9], xi1[3], s1[9];
        link_start(x, i, xi, s);
        link_start(x, i1, xi1, s1);
        int32_t q = 0;
        for (; q < n0 && q < n1; q += 4) {
            link_group(x, xp, v, i, e0 + q, xi, s, damped);
            link_group(x, xp, v, i1, e1 + q, xi1, s1, damped);
        }
        for (int32_t r = q; r < n0; r += 4) link_group(x, xp, v, i, e0 + r, xi, s, damped);
        for (int32_t r = q; r < n1; r += 4) link_group(x, xp, v, i1, e1 + r, xi1, s1, damped);
        link_sums(s, &f[3 * k], &H[6 * k]);
        link_sums(s1, &f[3 * (k + 1)], &H[6 * (k + 1)]);
    }
    for (; k < n; k++) {
        const int32_t i = vert[k], e0 = v->adj_start[i], n0 = v->adj_start[i + 1] - e0;
        __m256d xi[3], s[9];
        link_start(x, i, xi, s);
        for (int32_t q = 0; q < n0; q += 4) link_group(x, xp, v, i, e0 + q, xi, s, damped);
        link_sums(s, &f[3 * k], &H[6 * k]);
    }
}

static __attribute__((target("avx2"))) void links_avx2_run(const wb_world *w, const dist_vbd *v, const int32_t *vert,
                                                           int32_t n, wb_real *f, wb_real *H)
{
    if (v->damped) links_avx2(w, v, vert, n, f, H, 1);
    else links_avx2(w, v, vert, n, f, H, 0);
}
#endif

/* the vector path of the vertex step: -1 not yet decided, 0 off (no AVX2, or turned
 * off), 1 on */
static int vbd_simd_state = -1;

/* Internal switch for tests, as wb__distance_simd: on = 0 forces the vertex step's scalar
 * loop */
int wb__distance_vbd_simd(int on);
int wb__distance_vbd_simd(int on) { return wb__simd_set(&vbd_simd_state, on); }

/* the vertex steps at vert[0 .. n): their links' forces and Hessians added into f and H */
static void dvbd_vertex(const wb_world *w, const void *part, const int32_t *vert, int32_t n, wb_real inv_h, wb_real *f,
                        wb_real *H)
{
    (void)inv_h;
    const dist_vbd *v = part;
#ifdef WB_DISTANCE_VBD_AVX2
    int s = __atomic_load_n(&vbd_simd_state, __ATOMIC_RELAXED);
    if (s < 0) s = wb__distance_vbd_simd(1);
    if (s) {
        links_avx2_run(w, v, vert, n, f, H);
        return;
    }
#endif
    for (int32_t k = 0; k < n; k++) links_scalar(w, v, vert[k], &f[3 * k], &H[6 * k]);
}

/* the inertia of a hard link's ends over the substep, 1 / (h^2 (w_i + w_j)) */
static wb_real start_penalty(const wb_world *w, int32_t s, wb_real inv_h2)
{
    const int32_t *ij = wb__dist(w->dist)->ij;
    const wb_real wsum = w->m.w[ij[2 * s]] + w->m.w[ij[2 * s + 1]];
    return wsum > 0 ? inv_h2 / wsum : 0;
}

/* link s's two entries of the vertex lists, as the vector lanes read them */
static void put_entries(dist_vbd *v, int32_t s, const vbd_link *L)
{
    for (int c = 0; c < 2; c++) {
        const int32_t e = v->epos[2 * s + c];
        v->ekk[e] = L->kk, v->etg[e] = L->tgt, v->elm[e] = L->lm, v->edm[e] = L->dmp;
    }
}

/* A hard (or stiff) link with an end in a fold of its own body (k.vbd_fold: in touch with
 * a movable particle of that body, not a rest neighbour, where the substep starts) carries
 * only VBD_FOLD_CARRY of its multiplier into the substep. The contacts are projected after
 * the sweeps, and a link pulling on a particle caught in a fold (its ends held apart by
 * what lies between them) cannot win: carried whole, its multiplier grew by k C every
 * substep, a force no stretch had stored, which the fold's sliding turned into speed (a
 * hand-built 20 x 20 net heaping on itself went from 1,980 J to 34,000, a 24 x 48 cloth
 * never came to rest). Halved each substep it is bounded by twice what one substep adds
 * (0.8: the net still gained 3,000 J; none carried: a chain of rigid links piling on a
 * net was held up as a rod, its top 6.4 cm above free fall, tests/validation/chain_pile).
 * Of its error such a link keeps at most VBD_FOLD_KEEP of its length: what it keeps is
 * what lets it give way to the fold (keeping no more than it kept the substep before,
 * the net gained 11,000 J; all that its sweep leaves, a cloth draped on a sphere had
 * links 59% long after 3 s; 5%: a hand-built cloth dropped on a sphere slid off it,
 * tests/validation/user/03). A plastic give, for as long as it touches */
#define VBD_FOLD_CARRY ((wb_real)0.5)
#define VBD_FOLD_KEEP ((wb_real)0.08)
static inline wb_real fold_keep(wb_real c0, int folded, wb_real rest)
{
    if (!folded) return c0;
    const wb_real cm = VBD_FOLD_KEEP * rest;
    return c0 > cm ? cm : c0 < -cm ? -cm : c0;
}

/* each link as the sweeps read it this substep (vbd_link), and the hard links' list */
static void warm_start(wb_world *w, dist_vbd *v, wb_real inv_h2, wb_real inv_h)
{
    const wb_distances *ds = wb__dist(w->dist);
    const wb_real *xp = w->s.x_prev;
    v->nhard = v->nstiff = 0;
    v->damped = 0;
    /* volume constraints are projected after the sweeps: with rigid links they may hold
     * a body over-constrained (rigid links and incompressible tets under a press), and a
     * link that took back what the press pushed into it each substep fought them (a
     * lattice with tets squeezed to 60% blew up at 55 m/s): there every error is kept */
    const int keep_all = wb_volume_count(w) > 0;
    const uint8_t *fold = w->k.vbd_fold;
    for (int32_t s = 0; s < ds->n; s++) {
        if (!packable(ds, s)) continue;
        vbd_link *L = &v->lk[s];
        /* a link with an end in a fold starts from no multiplier and keeps at most
         * VBD_FOLD_KEEP of its length as error (fold_keep) */
        const int folded = fold && (fold[ds->ij[2 * s]] || fold[ds->ij[2 * s + 1]]);
        if (folded) v->lam[s] *= VBD_FOLD_CARRY;
        const wb_real alpha = ds->alpha[s], rest = ds->rest[s], kap = VBD_LINK_K * start_penalty(w, s, inv_h2);
        wb_real d[3];
        if (alpha > 0) {
            L->dmp = ds->beta[s] > 0 ? ds->beta[s] * inv_h : 0;
            v->damped |= L->dmp > 0;
            if (!(1 / alpha > kap)) { /* its own energy */
                L->tgt = rest, L->kk = 1 / alpha, L->lm = 0;
                v->lam[s] = 0, v->c0[s] = (wb_real)NAN;
                put_entries(v, s, L);
                continue;
            }
            /* stiffer than a rigid link's penalty: as one (dual_update), its error C - alpha
             * lambda */
            const wb_real r = 1 / (1 + alpha * kap);
            v3_sub(d, &xp[3 * ds->ij[2 * s]], &xp[3 * ds->ij[2 * s + 1]]);
            const wb_real c = v3_len(d) - rest - alpha * v->lam[s], ce = v->c0[s];
            const wb_real c0 = fold_keep(keep_all || !isfinite(ce) ? c : c * ce <= 0 ? 0 : fabs(c) < fabs(ce) ? c : ce,
                                         folded, rest);
            L->tgt = rest + (keep_all ? VBD_STAB_VOL : WB_VBD_STAB) * c0;
            L->kk = kap * r, L->lm = r * v->lam[s];
            put_entries(v, s, L);
            v->hard[ds->n - 1 - v->nstiff++] = s;
            continue;
        }
        v3_sub(d, &xp[3 * ds->ij[2 * s]], &xp[3 * ds->ij[2 * s + 1]]);
        /* the error kept is no more than the solve itself left: what the contacts and
         * colliders did to the link since (pushing a body's bottom up into it) is a load
         * it takes, not a drift to stabilise, or a block on the ground sags by 100 g h^2
         * a link (a 4 x 4 x 4 lattice's lowest links 17% short on a slope) */
        const wb_real c = v3_len(d) - rest, ce = v->c0[s];
        const wb_real c0 = fold_keep(keep_all || !isfinite(ce) ? c : c * ce <= 0 ? 0 : fabs(c) < fabs(ce) ? c : ce,
                                     folded, rest);
        L->tgt = rest + (keep_all ? VBD_STAB_VOL : WB_VBD_STAB) * c0;
        L->kk = kap, L->lm = v->lam[s], L->dmp = 0;
        put_entries(v, s, L);
        v->hard[v->nhard++] = s;
    }
}

/* After the substep's last sweep: a hard link's multiplier grows by k C. A stiff link
 * (compliance alpha with 1 / alpha above the rigid links' penalty k) goes through the
 * augmented Lagrangian of its energy written as z^2 / 2 alpha under the constraint z = C:
 * with z eliminated the sweep sees the force r (lambda + k C) and the stiffness r k,
 * r = 1 / (1 + alpha k), lambda its tension after the last update (C / alpha at rest);
 * its error, C - alpha lambda, is kept as a hard link's. With its whole stiffness in the
 * vertex step (1e6 N/m for a w:cloth's links of compliance 1e-6 at 20 substeps, 160 times
 * that penalty) one sweep left a vertex's neighbours far from where it assumed them: a
 * cloth hung by a row of pins gained energy until it blew up (max strain 0.1% after
 * 0.3 s, 11% after 1 s, particles at 20 m/s; stable at 10 iterations). At alpha = 0 it is
 * the hard link's update */
static void dual_update(wb_world *w, dist_vbd *v)
{
    const wb_distances *ds = wb__dist(w->dist);
    const wb_real *x = w->s.x;
    for (int32_t q = 0; q < v->nhard; q++) {
        const int32_t s = v->hard[q], a = ds->ij[2 * s], b = ds->ij[2 * s + 1];
        vbd_link *L = &v->lk[s];
        wb_real d[3];
        v3_sub(d, &x[3 * a], &x[3 * b]);
        const wb_real l = v3_len(d);
        L->lm += L->kk * (l - L->tgt);
        v->c0[s] = l - ds->rest[s]; /* (before the types projected after the sweep) */
        const int32_t e = v->epos[2 * s], f = v->epos[2 * s + 1];
        v->elm[e] = v->elm[f] = L->lm;
    }
    for (int32_t q = ds->n - v->nstiff; q < ds->n; q++) {
        const int32_t s = v->hard[q], a = ds->ij[2 * s], b = ds->ij[2 * s + 1];
        vbd_link *L = &v->lk[s];
        wb_real d[3];
        v3_sub(d, &x[3 * a], &x[3 * b]);
        const wb_real l = v3_len(d), f = L->kk * (l - L->tgt) + L->lm, alpha = ds->alpha[s];
        v->lam[s] = f;
        L->lm = (1 - alpha * L->kk) * f;
        v->c0[s] = l - ds->rest[s] - alpha * f;
        const int32_t e = v->epos[2 * s], g = v->epos[2 * s + 1];
        v->elm[e] = v->elm[g] = L->lm;
    }
}

static void dvbd_begin(wb_world *w, void *part, wb_real h) { warm_start(w, part, 1 / (h * h), 1 / h); }

static void dvbd_dual(wb_world *w, void *part, wb_real h, int last)
{
    (void)h;
    /* the links' multipliers grow once a substep, after its last sweep: grown after every
     * sweep, they took in what the contacts and colliders projected after the solve would
     * push back anyway, as often as there were sweeps (two stacked blocks of rigid links
     * at 2 iterations: links 45% long within 2.5 s; a cloth of them draped on a sphere: 72%) */
    if (last) dual_update(w, part);
}

/* What force() and break_force read, in XPBD's multipliers (lambda = -force h^2, a
 * stretched link's negative): a soft link's C / alpha, a hard one's lambda + k C of the
 * last sweep, carried to the next substep (a stiff one's: dual_update) */
static void dvbd_end(wb_world *w, void *part, wb_real h)
{
    dist_vbd *v = part;
    for (int32_t q = 0; q < v->nhard; q++) v->lam[v->hard[q]] = v->lk[v->hard[q]].lm;
    wb_distances *ds = w->dist;
    const wb_real h2 = h * h;
    for (int32_t i = 0; ds && i < ds->ns; i++) {
        const int32_t s = ds->s_slot[i];
        if (!packable(ds, s)) { ds->s_lambda[i] = 0; continue; }
        const wb_real alpha = ds->alpha[s];
        if (alpha > 0) {
            wb_real d[3];
            v3_sub(d, &w->s.x[3 * ds->ij[2 * s]], &w->s.x[3 * ds->ij[2 * s + 1]]);
            ds->s_lambda[i] = -(v3_len(d) - ds->rest[s]) / alpha * h2;
        } else {
            ds->s_lambda[i] = -v->lam[s] * h2;
        }
    }
    if (ds) ds->s_lambda_stale = 0;
}

static void dvbd_save(void *part)
{
    dist_vbd *v = part;
    wb__vbd_keep(v->save, v->lam, v->c0, v->cap, 0);
}

static void dvbd_undo(void *part)
{
    dist_vbd *v = part;
    wb__vbd_keep(v->save, v->lam, v->c0, v->cap, 1);
}

static wb_status dvbd_image_save(const wb_world *w, const void *part, wb_image *g, int stale)
{
    const dist_vbd *v = part;
    const int32_t nd = wb__dist(w->dist)->n;
    if (nd == 0) return WB_OK;
    g->vbd_lam = malloc(sizeof(wb_real) * (size_t)nd), g->vbd_c0 = malloc(sizeof(wb_real) * (size_t)nd);
    if (!g->vbd_lam || !g->vbd_c0) return WB_ERR_NOMEM;
    g->vbd_nd = nd;
    /* (a part just restored has its image's errors for every slot it held) */
    const int32_t known = v->restored ? v->cap : stale ? 0 : v->nd;
    for (int32_t s = 0; s < nd; s++) {
        g->vbd_lam[s] = s < v->cap ? v->lam[s] : 0;
        g->vbd_c0[s] = s < known ? v->c0[s] : (wb_real)NAN;
    }
    return WB_OK;
}

static const char *dvbd_image_check(const wb_image *g)
{
    return wb__vbd_half_check(g->vbd_nd, g->dist.n, g->vbd_lam, g->vbd_c0, "VBD multipliers: one per distance slot");
}

static wb_status dvbd_image_put(void *part, const wb_image *g)
{
    dist_vbd *v = part;
    const int32_t nd = g->vbd_nd;
    if (!realloc_n((void **)&v->lam, nd, sizeof *v->lam) || !realloc_n((void **)&v->c0, nd, sizeof *v->c0) ||
        !realloc_n((void **)&v->lk, nd, sizeof *v->lk) || !realloc_n((void **)&v->hard, nd, sizeof *v->hard))
        return WB_ERR_NOMEM;
    if (nd) {
        memcpy(v->lam, g->vbd_lam, sizeof *v->lam * (size_t)nd);
        memcpy(v->c0, g->vbd_c0, sizeof *v->c0 * (size_t)nd);
    }
    v->cap = nd;
    v->restored = 1;
    return WB_OK;
}

static const wb_vbd_type distance_vbd = {
    .make = dvbd_make,
    .free = dvbd_free,
    .slots = dvbd_slots,
    .build = dvbd_build,
    .neighbours = dvbd_neighbours,
    .holds = dvbd_holds,
    .vertex = dvbd_vertex,
    .begin = dvbd_begin,
    .dual = dvbd_dual,
    .end = dvbd_end,
    .save = dvbd_save,
    .undo = dvbd_undo,
    .image_save = dvbd_image_save,
    .image_check = dvbd_image_check,
    .image_put = dvbd_image_put,
};

const wb_ctype wb__distance_type = {
    .name = "distance",
    .count = distance_count,
    .prepare = wb__colour,
    .substep_begin = distance_substep_begin,
    .project = distance_project,
    .frame_end = distance_frame_end,
    .energy = distance_energy,
    .links = distance_links,
    .joins = distance_joins,
    .destroy = distance_destroy,
    .charged = distance_charged,
    .stats = distance_stats,
    .hash = distance_hash,
    .image_free = distance_image_free,
    .image_save = distance_image_save,
    .image_check = distance_image_check,
    .image_reserve = distance_image_reserve,
    .image_put = distance_image_put,
    .residual = distance_residual,
    .vbd = &distance_vbd,
};
