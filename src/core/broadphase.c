/* broadphase.c: the candidate pairs of particle-particle contacts, once per frame
 * (Macklin et al. 2019 "Small steps" §4: swept bounds plus a
 * margin, then every substep projects the same list).
 *
 * wb__contacts_begin works out each particle's reach (its radius with a margin, plus how
 * far its velocity and gravity carry it in a frame) and asks wb__broadphase for every
 * pair closer than reach_i + reach_j that may touch (contact.c's group rules).
 *
 * wb__broadphase, in three passes, each linear in the particles:
 *  1. Body culling. Particles of one body that does not collide with itself share a
 *     nonzero skip key. A body's swept box is the union of its particles' boxes
 *     (x +- reach); a particle can only touch another body if its own box overlaps that
 *     body's box, so it is kept only if its box meets one of its body's overlaps with
 *     the other bodies' boxes. The others (deep inside a body, or every particle of a
 *     body that touches nothing) never enter the grid.
 *  2. A sorted grid: the rest are counting-sorted by cell, row-major (x fastest), and
 *     each cell's by x, so an x-row is one contiguous range of the sorted array, in x
 *     order (a cloth lying across a row: a stretch of it, not whole cells). The cell is the
 *     typical reach (a median of sampled reaches), grown until the grid has at most ~2
 *     cells per particle; one fast particle does not enlarge the cells of all the
 *     others. Past that (particles spread over an enormous volume) the cell coordinates
 *     wrap around the grid, which only costs extra distance tests.
 *  3. The search. A particle whose reach is at most twice the typical one (ordinary)
 *     finds its pairs with the ordinary particles after it in the sorted array, within
 *     its reach + the largest ordinary reach (rows wholly before it are skipped: half
 *     the neighbourhood; of each row only the x-window where that sphere crosses the
 *     row's nearest edge in y and z, so grid cells much larger than the reach, as in a
 *     sheet spread over a large box, cost no more tests). A big (fast) one finds its
 *     pairs with every particle of a smaller reach (ties: the higher index) within twice
 *     its reach, since reach_i + reach_j <= 2 reach_i. Each pair is found once. Pairs of
 *     one skip key are dropped after the distance test, before the group rules (keep).
 *
 * Determinism: threads take contiguous ranges of the sorted array, each with its own
 * pair buffer; the pairs are then counting-sorted into (i, j) order, so the list is the
 * set of pairs alone, the same for any thread count, cell size or search order. */
#include <stdlib.h>
#include <time.h>

#include "core.h"
#include "ctype.h"
#include "broadphase.h"
#include "tricontact.h"
#include "simd.h"

static double now_ms(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return ts.tv_sec * 1e3 + ts.tv_nsec * 1e-6;
}

#ifdef WB_SIMD_H_AVX2
/* lanes 0-2 summed in the scalar order, (q0 + q1) + q2 */
static inline __attribute__((always_inline, target("avx2"))) double hsum3(__m256d q)
{
    const __m128d lo = _mm256_castpd256_pd128(q), hi = _mm256_extractf128_pd(q, 1);
    return _mm_cvtsd_f64(_mm_add_sd(_mm_add_sd(lo, _mm_unpackhi_pd(lo, lo)), hi));
}
#endif

/* below this many particles in the grid the scan stays on one thread (a parallel
 * region costs more than it saves) */
#define PAR_MIN 1024
/* body culling only with at most this many runs (its cost is quadratic in them) */
#define RUNS_MAX 256
/* a run's overlaps tested one by one up to this many */
#define BOXES_MAX 16

typedef struct wb_broad_run {
    int32_t first, last;   /* candidate list range [first, last) */
    int32_t key;           /* skip key; 0 = the catch-all run of keyless particles */
    wb_real lo[3], hi[3];  /* swept box */
    int32_t box0, nbox;    /* its overlaps with other runs: boxes[box0..], -1: covers it */
} run;

typedef wb_pairbuf pairbuf;

typedef struct grid {
    wb_grid g;                         /* origin, cell, shape (grid.c) */
    wb_real big;                       /* reach past which a particle is big */
    wb_real rn;                        /* the largest reach up to big */
} grid;

static int grow(void **p, int32_t *cap, int64_t need, size_t elem)
{
    if (need > INT32_MAX / 2) return 0;
    void *q = wb__grow(*p, cap, (int32_t)(need > 0 ? need : 1), elem);
    if (!q) return 0;
    *p = q;
    return 1;
}

static int cmp_pair(const void *pa, const void *pb);

static inline int64_t cell_of(wb_real v, wb_real o, wb_real inv) { return wb__cell_of(v, o, inv); }

static inline int64_t wrap_to(int64_t c, int64_t n) { return c % n; }

static inline int box_overlap(const wb_real *alo, const wb_real *ahi, const wb_real *blo, const wb_real *bhi)
{
    return alo[0] <= bhi[0] && blo[0] <= ahi[0] && alo[1] <= bhi[1] && blo[1] <= ahi[1] &&
           alo[2] <= bhi[2] && blo[2] <= ahi[2];
}

/* pass 1: runs of consecutive candidates with one nonzero key, every keyless candidate
 * in one catch-all run; keeps in b->cand the candidates whose box overlaps one of their
 * run's overlaps with the runs of other keys (a pair closer than reach_i + reach_j has
 * overlapping boxes, both inside their runs' boxes, so inside the runs' overlap).
 * Returns the survivors, or -1 when out of memory */
static int32_t cull(wb_broad *b, const wb_real *x, const wb_real *reach, const int32_t *skip, int32_t na)
{
    if (!skip) return na;
    int32_t nr = 0, keyless = -1, last = -1;
    for (int32_t k = 0; k < na; k++) {
        const int32_t i = b->cand[k], key = skip[i];
        int32_t cur;
        if (key == 0 && keyless >= 0) cur = keyless;
        else if (key != 0 && last >= 0 && b->runs[last].key == key && b->runs[last].last == k) cur = last;
        else {
            if (nr == RUNS_MAX) return na; /* too fragmented to pay off: no culling */
            if (!grow((void **)&b->runs, &b->cap_runs, nr + 1, sizeof *b->runs)) return -1;
            cur = nr++;
            run *R = &b->runs[cur];
            R->first = k;
            R->key = key;
            for (int a = 0; a < 3; a++) { R->lo[a] = INFINITY; R->hi[a] = -INFINITY; }
            if (key == 0) keyless = cur;
        }
        run *R = &b->runs[cur];
        if (key != 0) { last = cur; R->last = k + 1; }
        const wb_real e = reach[i], *p = &x[3 * i];
        for (int a = 0; a < 3; a++) {
            if (p[a] - e < R->lo[a]) R->lo[a] = p[a] - e;
            if (p[a] + e > R->hi[a]) R->hi[a] = p[a] + e;
        }
    }
    /* each keyed run: its overlaps with the runs of other keys, as boxes (past BOXES_MAX
     * of them the last box grows to the hull of the rest) */
    int32_t nb = 0, culls = 0;
    for (int32_t s = 0; s < nr; s++) {
        run *A = &b->runs[s];
        A->box0 = nb;
        A->nbox = 0;
        if (A->key == 0) continue;
        for (int32_t t = 0; t < nr; t++) {
            const run *B = &b->runs[t];
            if (B->key == A->key || !box_overlap(A->lo, A->hi, B->lo, B->hi)) continue;
            if (A->nbox == BOXES_MAX) nb--, A->nbox--; /* reopen the last box */
            else {
                if (!grow((void **)&b->boxes, &b->cap_boxes, 6 * ((int64_t)nb + 1), sizeof *b->boxes)) return -1;
                for (int a = 0; a < 3; a++) { b->boxes[6 * nb + a] = INFINITY; b->boxes[6 * nb + 3 + a] = -INFINITY; }
            }
            wb_real *bx = &b->boxes[6 * nb];
            for (int a = 0; a < 3; a++) {
                const wb_real lo = A->lo[a] > B->lo[a] ? A->lo[a] : B->lo[a];
                const wb_real hi = A->hi[a] < B->hi[a] ? A->hi[a] : B->hi[a];
                if (lo < bx[a]) bx[a] = lo;
                if (hi > bx[3 + a]) bx[3 + a] = hi;
            }
            nb++;
            A->nbox++;
        }
        /* a box that covers the whole run culls nothing: test none */
        for (int32_t q = A->box0; q < A->box0 + A->nbox; q++) {
            const wb_real *bx = &b->boxes[6 * q];
            if (bx[0] <= A->lo[0] && bx[1] <= A->lo[1] && bx[2] <= A->lo[2] &&
                bx[3] >= A->hi[0] && bx[4] >= A->hi[1] && bx[5] >= A->hi[2]) { A->nbox = -1; break; }
        }
        if (A->nbox >= 0) culls = 1;
    }
    if (!culls) return na;
    /* survivors, in candidate order (the list's order stays the input's) */
    int32_t m = 0, s = 0;
    for (int32_t k = 0; k < na; k++) {
        const int32_t i = b->cand[k];
        if (skip[i] == 0) { b->cand[m++] = i; continue; }
        while (!(b->runs[s].key != 0 && k >= b->runs[s].first && k < b->runs[s].last)) s++;
        const run *A = &b->runs[s];
        if (A->nbox < 0) { b->cand[m++] = i; continue; }
        const wb_real e = reach[i], *p = &x[3 * i];
        for (int32_t q = A->box0; q < A->box0 + A->nbox; q++) {
            const wb_real *bx = &b->boxes[6 * q];
            if ((p[0] + e >= bx[0]) & (p[0] - e <= bx[3]) & (p[1] + e >= bx[1]) & (p[1] - e <= bx[4]) &
                (p[2] + e >= bx[2]) & (p[2] - e <= bx[5])) {
                b->cand[m++] = i;
                break;
            }
        }
    }
    return m;
}

static void push(pairbuf *o, int32_t i, int32_t j)
{
    if (2 * (o->n + 1) > o->cap && !grow((void **)&o->ij, &o->cap, 2 * ((int64_t)o->n + 1), sizeof *o->ij)) {
        o->fail = 1;
        return;
    }
    o->ij[2 * o->n] = i < j ? i : j;
    o->ij[2 * o->n + 1] = i < j ? j : i;
    o->n++;
}

/* Pairs into (i, j) order by two counting sorts, by j and then stably by i: linear in the
 * pairs and particles (a heap's particle can have a hundred pairs: sorting each one's
 * handful by insertion took an eighth of a 128 x 128 heap's frame). The pairs of the nb
 * buffers src (a thread's each), all of particles below np, written to dst (2 n ints);
 * by_j (2 n) and cnt, first (np + 1) are scratch */
static void order_pairs(const pairbuf *src, int nb, int32_t np, int32_t *by_j, int32_t *cnt, int32_t *first,
                        int32_t *dst)
{
    memset(cnt, 0, sizeof *cnt * ((size_t)np + 1));
    memset(first, 0, sizeof *first * ((size_t)np + 1));
    for (int t = 0; t < nb; t++)
        for (int32_t k = 0; k < src[t].n; k++) {
            cnt[src[t].ij[2 * k + 1] + 1]++;
            first[src[t].ij[2 * k] + 1]++;
        }
    for (int32_t i = 0; i < np; i++) cnt[i + 1] += cnt[i], first[i + 1] += first[i];
    for (int t = 0; t < nb; t++)
        for (int32_t k = 0; k < src[t].n; k++) {
            const int32_t *e = &src[t].ij[2 * k], at = cnt[e[1]]++;
            by_j[2 * at] = e[0];
            by_j[2 * at + 1] = e[1];
        }
    const int32_t n = cnt[np];
    for (int32_t k = 0; k < n; k++) {
        const int32_t at = first[by_j[2 * k]]++;
        dst[2 * at] = by_j[2 * k];
        dst[2 * at + 1] = by_j[2 * k + 1];
    }
}

/* an axis's search range [v - e, v + e] as at most two runs of grid cells */
static inline int axis_ranges(const wb_grid *g, int a, wb_real v, wb_real e, int64_t r[4])
{
    int64_t lo = cell_of(v - e, g->o[a], g->inv), hi = cell_of(v + e, g->o[a], g->inv);
    const int64_t n = g->nc[a];
    if (!g->wrap) {
        r[0] = lo; r[1] = hi < n - 1 ? hi : n - 1;
        return 1;
    }
    if (hi - lo + 1 >= n) { r[0] = 0; r[1] = n - 1; return 1; }
    lo = wrap_to(lo, n);
    hi = wrap_to(hi, n);
    if (lo <= hi) { r[0] = lo; r[1] = hi; return 1; }
    r[0] = lo; r[1] = n - 1; r[2] = 0; r[3] = hi;
    return 2;
}

/* the sorted positions [q0, q1) up to x = xmax (exclusive) closer to p (x, y, z, reach)
 * than the two reaches and not of its skip key ks (kz: it has none), appended to hit from
 * nh. Branch-free but for the row's end (taken once): most fail, and a branch per test
 * mispredicts */
static inline int32_t gather(const wb_real *restrict P, const int32_t *restrict key, const wb_real *restrict p,
                             int32_t ks, int kz, int32_t q0, int32_t q1, wb_real xmax, int32_t *restrict hit, int32_t nh)
{
    const wb_real px = p[0], py = p[1], pz = p[2], rs = p[3];
    for (int32_t t = q0; t < q1; t++) {
        const wb_real *q = &P[4 * t];
        if (q[0] >= xmax) break; /* the row is sorted by x (sort_cells) */
        const wb_real d0 = q[0] - px, d1 = q[1] - py, d2 = q[2] - pz, r = rs + q[3];
        hit[nh] = t;
        nh += (d0 * d0 + d1 * d1 + d2 * d2 < r * r) & ((key[t] != ks) | kz);
    }
    return nh;
}

/* s's hits into pairs, kept. big: s is big, partners of a smaller reach (ties: a higher
 * index); else partners that are not big */
static void emit(const wb_broad *b, const grid *g, int32_t s, int big, const int32_t *hit, int32_t nh, pairbuf *o,
                 int (*keep)(void *ud, int32_t i, int32_t j), void *ud)
{
    const wb_real *P = b->p, rs = P[4 * s + 3], T = g->big;
    const int32_t *id = b->id, i = id[s];
    for (int32_t h = 0; h < nh; h++) {
        const int32_t t = hit[h], j = id[t];
        const wb_real rt = P[4 * t + 3];
        if (big ? rt > rs || (rt == rs && j <= i) : rt > T) continue;
        if (keep && !keep(ud, i < j ? i : j, i < j ? j : i)) continue;
        push(o, i, j);
    }
}

/* each cell's slots [start[c], start[c + 1]) sorted by x, stably (an insertion sort: a
 * cell holds a handful) */
static void sort_cells(wb_broad *b, const int32_t *start, int64_t ncell)
{
    wb_real *P = b->p;
    int32_t *id = b->id, *key = b->key;
    for (int64_t c = 0; c < ncell; c++) {
        const int32_t lo = start[c], hi = start[c + 1];
        for (int32_t k = lo + 1; k < hi; k++) {
            if (!(P[4 * k] < P[4 * (k - 1)])) continue;
            wb_real t[4];
            memcpy(t, &P[4 * k], sizeof t);
            const int32_t ti = id[k], tk = key[k];
            int32_t q = k;
            for (; q > lo && t[0] < P[4 * (q - 1)]; q--) {
                memcpy(&P[4 * q], &P[4 * (q - 1)], sizeof t);
                id[q] = id[q - 1], key[q] = key[q - 1];
            }
            memcpy(&P[4 * q], t, sizeof t);
            id[q] = ti, key[q] = tk;
        }
    }
}

/* the first of the sorted slots [lo, hi) of one x-row whose x is not below v (a cell or
 * so of them: a linear skip costs less than a bisection) */
static inline int32_t x_from(const wb_real *P, int32_t lo, int32_t hi, wb_real v)
{
    while (lo < hi && P[4 * lo] < v) lo++;
    return lo;
}

/* pass 3 over the sorted positions [lo, hi) (hit: scratch for hi - lo ... at most every
 * position). A pair of two ordinary particles (reach up to g->big) is found from the one
 * earlier in the sorted array, which searches reach + g->rn (rows wholly before it are
 * skipped); a pair with a big particle from the one with the larger reach (ties: the
 * lower index), which searches twice its reach over the whole neighbourhood */
static void scan(const wb_broad *b, const grid *g, int32_t lo, int32_t hi, int32_t *restrict hit, pairbuf *o,
                 int (*keep)(void *ud, int32_t i, int32_t j), void *ud)
{
    const int32_t *restrict start = b->start, *restrict key = b->key;
    const wb_real *restrict P = b->p, *restrict rowr = b->rowr, T = g->big;
    const wb_grid *G = &g->g;
    const int64_t nx = G->nc[0], ny = G->nc[1], nz = G->nc[2];
    const wb_real ox = G->o[0], oy = G->o[1], oz = G->o[2], inv = G->inv;
    for (int32_t s = lo; s < hi; s++) {
        const wb_real *p = &P[4 * s], rs = p[3];
        const int32_t ks = key[s];
        const int kz = ks == 0, big = rs > T;
        const wb_real e = big ? 2 * rs : rs + g->rn;
        int32_t nh = 0;
        if (!G->wrap && !big) {
            /* rows wholly before s in the sorted order hold no partner of it: from its
             * own row on (its own from s + 1). Each row is searched to rs + its own
             * largest reach (rowr) and skipped where its cells lie farther than that in y
             * and z (the gap in cells, less a millionth of a cell for round-off) */
            const int64_t x1r = cell_of(p[0] + e, ox, inv), y1r = cell_of(p[1] + e, oy, inv),
                          z1r = cell_of(p[2] + e, oz, inv);
            const int64_t y1 = y1r < ny - 1 ? y1r : ny - 1, z1 = z1r < nz - 1 ? z1r : nz - 1;
            const int64_t y0 = cell_of(p[1], oy, inv), z0 = cell_of(p[2], oz, inv), ylo = cell_of(p[1] - e, oy, inv);
            const wb_real sy = (p[1] - oy) * inv, sz = (p[2] - oz) * inv, cs = 1 / inv;
            /* round-off in the x window: a millionth of a cell, as the gaps */
            const wb_real tol = (wb_real)1e-6 * cs;
            int64_t row = nx * (y0 + ny * z0);
            {
                const wb_real er = rs + rowr[y0 + ny * z0];
                const int64_t xr = cell_of(p[0] + er, ox, inv), x1 = xr < x1r ? xr : x1r;
                const int32_t q1 = start[row + (x1 < nx - 1 ? x1 : nx - 1) + 1];
                nh = gather(P, key, p, ks, kz, s + 1, q1, p[0] + er + tol, hit, nh);
            }
            for (int64_t z = z0; z <= z1; z++) {
                const wb_real gz = z > z0 ? ((wb_real)z - sz - (wb_real)1e-6) * cs : 0, gz2 = gz > 0 ? gz * gz : 0;
                for (int64_t y = z == z0 ? y0 + 1 : ylo; y <= y1; y++) {
                    const wb_real rr = rowr[y + ny * z];
                    if (rr < 0) continue;
                    const wb_real er = rs + rr;
                    const wb_real gy = y > y0 ? ((wb_real)y - sy - (wb_real)1e-6) * cs
                                     : y < y0 ? (sy - (wb_real)(y + 1) - (wb_real)1e-6) * cs : 0;
                    const wb_real gap2 = (gy > 0 ? gy * gy : 0) + gz2;
                    if (gap2 >= er * er) continue;
                    /* a partner lies within the chord of the sphere er across the row's
                     * nearest y and z: no farther in x than sqrt(er^2 - gap^2) */
                    const wb_real cw = sqrt(er * er - gap2) + tol;
                    const int64_t xa = cell_of(p[0] - cw, ox, inv), xb = cell_of(p[0] + cw, ox, inv);
                    row = nx * (y + ny * z);
                    const int32_t q1 = start[row + (xb < nx - 1 ? xb : nx - 1) + 1];
                    nh = gather(P, key, p, ks, kz, x_from(P, start[row + xa], q1, p[0] - cw), q1, p[0] + cw, hit, nh);
                }
            }
            emit(b, g, s, 0, hit, nh, o, keep, ud);
            continue;
        }
        int64_t rx[4], ry[4], rz[4];
        const int kx = axis_ranges(G, 0, p[0], e, rx), ky = axis_ranges(G, 1, p[1], e, ry),
                  kw = axis_ranges(G, 2, p[2], e, rz);
        for (int az = 0; az < kw; az++)
            for (int64_t z = rz[2 * az]; z <= rz[2 * az + 1]; z++)
                for (int ay = 0; ay < ky; ay++)
                    for (int64_t y = ry[2 * ay]; y <= ry[2 * ay + 1]; y++) {
                        const int64_t row = nx * (y + ny * z);
                        for (int ax = 0; ax < kx; ax++) {
                            int32_t q0 = start[row + rx[2 * ax]];
                            const int32_t q1 = start[row + rx[2 * ax + 1] + 1];
                            if (!big) {
                                if (q1 <= s + 1) continue;
                                if (q0 < s + 1) q0 = s + 1;
                            }
                            nh = gather(P, key, p, ks, kz, q0, q1, INFINITY, hit, nh);
                        }
                    }
        emit(b, g, s, big, hit, nh, o, keep, ud);
    }
}

/* one thread's share of pass 3: the t-th of nt contiguous ranges of the sorted array */
typedef struct scan_ctx {
    const wb_broad *b;
    const grid *g;
    int32_t m;
    int (*keep)(void *ud, int32_t i, int32_t j);
    void *ud;
} scan_ctx;

static void scan_part(void *ctx, int t, int nt)
{
    const scan_ctx *c = ctx;
    const int32_t lo = (int32_t)((int64_t)c->m * t / nt), hi = (int32_t)((int64_t)c->m * (t + 1) / nt);
    pairbuf *o = &c->b->out[t];
    scan(c->b, c->g, lo, hi, o->hit, o, c->keep, c->ud);
}

/* pass 2: the grid's origin, cell size and shape; the cell is the typical reach */
static void make_grid(grid *g, const wb_broad *b, const wb_real *x, const wb_real *reach, int32_t m)
{
    const wb_real typical = wb__grid_typical(reach, b->cand, m);
    g->big = 2 * typical;
    wb_real lo[3], hi[3], rmax;
    wb__grid_bounds(x, reach, b->cand, m, g->big, lo, hi, &rmax, &g->rn);
    wb_real cs = typical;
    if (!(cs > 0)) cs = 2 * rmax;
    wb__grid_shape(&g->g, lo, hi, cs, m);
}

/* the pairs appended to o (from o->n on; its ij grown as needed) */
static int32_t broad(wb_broad *b, wb_pairbuf *o, const wb_real *x, const wb_real *reach, const int32_t *skip,
                     int32_t n, wb_pool *pool, int (*keep)(void *ud, int32_t i, int32_t j), void *ud)
{
    if (!grow((void **)&b->cand, &b->cap_cand, n, sizeof *b->cand)) return -1;
    int32_t na = 0;
    for (int32_t i = 0; i < n; i++) {
        const wb_real *p = &x[3 * i];
        if (reach[i] >= 0 && isfinite(reach[i]) && isfinite(p[0]) && isfinite(p[1]) && isfinite(p[2])) b->cand[na++] = i;
    }
    if (na < 2) return o->n;
    const int32_t m = cull(b, x, reach, skip, na);
    if (m < 0) return -1;
    if (m < 2) return o->n;

    grid g;
    make_grid(&g, b, x, reach, m);
    const int64_t ncell = g.g.nc[0] * g.g.nc[1] * g.g.nc[2];
    if (!grow((void **)&b->start, &b->cap_start, ncell + 1, sizeof *b->start) ||
        !grow((void **)&b->cell, &b->cap_cell, m, sizeof *b->cell) ||
        !grow((void **)&b->p, &b->cap_p, 4 * (int64_t)m, sizeof *b->p) ||
        !grow((void **)&b->id, &b->cap_id, m, sizeof *b->id) ||
        !grow((void **)&b->key, &b->cap_key, m, sizeof *b->key))
        return -1;
    /* counting sort by cell: stable, so a cell's particles stay in index order */
    int32_t *start = b->start;
    memset(start, 0, sizeof *start * (size_t)(ncell + 1));
    for (int32_t k = 0; k < m; k++) {
        const int32_t cl = wb__grid_cell(&g.g, &x[3 * b->cand[k]]);
        b->cell[k] = cl;
        start[cl + 1]++;
    }
    for (int64_t q = 0; q < ncell; q++) start[q + 1] += start[q];
    for (int32_t k = 0; k < m; k++) {
        const int32_t i = b->cand[k], s = start[b->cell[k]]++;
        wb_real *p = &b->p[4 * s];
        v3_copy(p, &x[3 * i]);
        p[3] = reach[i];
        b->id[s] = i;
        b->key[s] = skip ? skip[i] : 0;
    }
    for (int64_t q = ncell; q > 0; q--) start[q] = start[q - 1]; /* back to starts */
    start[0] = 0;
    /* each cell's particles by x (ties: index order), so that an x-row is sorted by x and
     * the search takes from a row only the stretch within reach in x (scan) */
    sort_cells(b, start, ncell);
    /* each x-row's largest ordinary reach (the search of an ordinary particle, scan) */
    const int64_t nrow = g.g.nc[1] * g.g.nc[2];
    if (!grow((void **)&b->rowr, &b->cap_rowr, nrow, sizeof *b->rowr)) return -1;
    for (int64_t q = 0; q < nrow; q++) b->rowr[q] = -1;
    for (int32_t k = 0; k < m; k++) {
        const wb_real r = reach[b->cand[k]];
        wb_real *rr = &b->rowr[b->cell[k] / g.g.nc[0]];
        if (r <= g.big && r > *rr) *rr = r;
    }
    /* the grid stays for the kept list's mends (wb__contacts_recheck): whether it holds
     * every candidate, its shape and its largest reach */
    b->lg = g.g;
    b->lm = m;
    b->lfull = m == na;
    b->lrmax = 0;
    for (int32_t k = 0; k < m; k++) b->lrmax = b->p[4 * k + 3] > b->lrmax ? b->p[4 * k + 3] : b->lrmax;

    /* pass 3: contiguous ranges of the sorted array, one pair buffer each */
    const int threads = wb__pool_threads(pool);
    int nt = threads > 1 && m >= PAR_MIN ? threads : 1;
    if (!wb__pairbufs(&b->out, &b->nout, nt)) return -1;
    for (int t = 0; t < nt; t++) {
        if (!grow((void **)&b->out[t].hit, &b->out[t].cap_hit, m, sizeof *b->out[t].hit)) return -1;
    }
    scan_ctx ctx = { b, &g, m, keep, ud };
    if (nt == 1) scan_part(&ctx, 0, 1);
    else wb__pool_run(pool, scan_part, &ctx); /* nt parts: nt == the pool's threads */
    int64_t total = o->n;
    for (int t = 0; t < nt; t++) {
        if (b->out[t].fail) return -1;
        total += b->out[t].n;
    }
    if (!grow((void **)&o->ij, &o->cap, 2 * total, sizeof *o->ij) ||
        !grow((void **)&b->first, &b->cap_first, (int64_t)n + 1, sizeof *b->first) ||
        !grow((void **)&b->by_j, &b->cap_by_j, 2 * total, sizeof *b->by_j) ||
        !grow((void **)&b->cnt, &b->cap_cnt, (int64_t)n + 1, sizeof *b->cnt))
        return -1;
    /* in (i, j) order, so that the list is the set of pairs alone, whatever the grid, the
     * ranges or the threads */
    order_pairs(b->out, nt, n, b->by_j, b->cnt, b->first, &o->ij[2 * o->n]);
    o->n = (int32_t)total;
    return o->n;
}

int32_t wb__broadphase(wb_contacts *c, const wb_real *x, const wb_real *reach, const int32_t *skip,
                       int32_t n, wb_pool *pool, int (*keep)(void *ud, int32_t i, int32_t j), void *ud)
{
    if (!c->bp && !(c->bp = calloc(1, sizeof *c->bp))) return -1;
    wb_pairbuf o = { c->ij, c->n, c->cap, 0, NULL, 0 };
    const int32_t r = broad(c->bp, &o, x, reach, skip, n, pool, keep, ud);
    c->bp->vn = 0; /* its grid is no longer the kept list's */
    c->bp->lgrid = 0;
    c->ij = o.ij;
    c->cap = o.cap;
    if (r >= 0) c->n = r;
    return r;
}

/* ---- the list kept from frame to frame --------------------------------------------------------- */
/* A neighbour list with a skin (the Verlet lists of molecular dynamics): the pairs within
 * R_i + R_j, R_i = reach_i + skin_i, found at positions X_i, hold every pair within
 * reach_i + reach_j now while each particle has |x_i - X_i| + reach_i <= R_i, since then
 * |X_i - X_j| <= |x_i - x_j| + |x_i - X_i| + |x_j - X_j| < R_i + R_j. Each call checks
 * that (a thousandth of the slack spared for round-off), and that the same particles
 * take part with the same skip keys; the list is rebuilt when any fails, else only
 * filtered with the search's own test (the same bits) in its (i, j) order: the same
 * pairs in the same order as wb__broadphase's. */
#ifndef SKIN
#define SKIN 0.25
#endif
/* skin_i = SKIN x reach_i */

static inline int takes_part(const wb_real *x, const wb_real *reach, int32_t i)
{
    const wb_real *p = &x[3 * i];
    return reach[i] >= 0 && isfinite(reach[i]) && isfinite(p[0]) && isfinite(p[1]) && isfinite(p[2]);
}

/* The list's particles moved as one since it was made: the rigid motion M(X) = c + Q (X - C)
 * that best maps where they were onto where they are (the centres and the rotation of
 * their cross-covariance). M keeps distances, so a pair now within reach_i + reach_j was
 * within reach_i + reach_j + |e_i| + |e_j| at X, e = x - M(X): the list holds while each
 * particle's deviation from M, not its whole displacement, is within its skin. A cloth
 * falling or swinging as a whole keeps its list. */
static void motion_identity(wb_motion *mo)
{
    for (int a = 0; a < 9; a++) mo->Q[a] = a % 4 == 0;
    for (int a = 0; a < 3; a++) mo->C[a] = mo->c[a] = 0;
}

static inline void motion_apply(const wb_motion *mo, const wb_real *X, wb_real out[3])
{
    const wb_real r0 = X[0] - mo->C[0], r1 = X[1] - mo->C[1], r2 = X[2] - mo->C[2];
    for (int a = 0; a < 3; a++) out[a] = mo->c[a] + mo->Q[3 * a] * r0 + mo->Q[3 * a + 1] * r1 + mo->Q[3 * a + 2] * r2;
}

#ifdef WB_SIMD_H_AVX2
/* motion_fit's two sums in AVX2, a particle's x, y, z as the lanes of one vector: each lane
 * the scalar sum's operations in its order (no fused multiply-adds), so the same bits */
static __attribute__((target("avx2"))) int32_t fit_sums_avx2(const wb_broad *b, const wb_real *x, int32_t n,
                                                             double C[3], double c[3], wb_real A[9])
{
    const wb_real *vr = b->vr, *vx = b->vx;
    __m256d sC = _mm256_setzero_pd(), sc = sC;
    int32_t k = 0;
    for (int32_t i = 0; i < n; i++) {
        const wb_real *p = &x[3 * i];
        if (!(vr[i] >= 0) || !isfinite(p[0] + p[1] + p[2])) continue;
        sC = _mm256_add_pd(sC, wb__load3(&vx[3 * i]));
        sc = _mm256_add_pd(sc, wb__load3(p));
        k++;
    }
    if (k == 0) return 0;
    double t[4];
    _mm256_storeu_pd(t, sC);
    for (int a = 0; a < 3; a++) C[a] = t[a] / k;
    _mm256_storeu_pd(t, sc);
    for (int a = 0; a < 3; a++) c[a] = t[a] / k;
    const __m256d vC = _mm256_set_pd(0, C[2], C[1], C[0]), vc = _mm256_set_pd(0, c[2], c[1], c[0]);
    __m256d A0 = _mm256_setzero_pd(), A1 = A0, A2 = A0; /* rows of A */
    for (int32_t i = 0; i < n; i++) {
        const wb_real *p = &x[3 * i];
        if (!(vr[i] >= 0) || !isfinite(p[0] + p[1] + p[2])) continue;
        const __m256d dX = _mm256_sub_pd(wb__load3(&vx[3 * i]), vC), dp = _mm256_sub_pd(wb__load3(p), vc);
        A0 = _mm256_add_pd(A0, _mm256_mul_pd(_mm256_permute4x64_pd(dp, 0x00), dX));
        A1 = _mm256_add_pd(A1, _mm256_mul_pd(_mm256_permute4x64_pd(dp, 0x55), dX));
        A2 = _mm256_add_pd(A2, _mm256_mul_pd(_mm256_permute4x64_pd(dp, 0xaa), dX));
    }
    _mm256_storeu_pd(t, A0);
    memcpy(&A[0], t, 3 * sizeof *A);
    _mm256_storeu_pd(t, A1);
    memcpy(&A[3], t, 3 * sizeof *A);
    _mm256_storeu_pd(t, A2);
    memcpy(&A[6], t, 3 * sizeof *A);
    return k;
}
#endif

/* M fitted to the particles that took part (vr >= 0) and are finite now; 0 when none */
static int motion_fit(wb_broad *b, const wb_real *x, int32_t n, wb_motion *mo, int simd)
{
    double C[3] = { 0, 0, 0 }, c[3] = { 0, 0, 0 };
    wb_real A[9] = { 0 };
#ifdef WB_SIMD_H_AVX2
    if (simd && __builtin_cpu_supports("avx2")) {
        if (!fit_sums_avx2(b, x, n, C, c, A)) return 0;
        b->fits_simd++;
    } else
#endif
    {
        (void)simd;
        int32_t k = 0;
        for (int32_t i = 0; i < n; i++) {
            const wb_real *p = &x[3 * i], *X = &b->vx[3 * i];
            if (!(b->vr[i] >= 0) || !isfinite(p[0] + p[1] + p[2])) continue;
            for (int a = 0; a < 3; a++) C[a] += X[a], c[a] += p[a];
            k++;
        }
        if (k == 0) return 0;
        for (int a = 0; a < 3; a++) C[a] /= k, c[a] /= k;
        for (int32_t i = 0; i < n; i++) {
            const wb_real *p = &x[3 * i], *X = &b->vx[3 * i];
            if (!(b->vr[i] >= 0) || !isfinite(p[0] + p[1] + p[2])) continue;
            for (int a = 0; a < 3; a++)
                for (int e = 0; e < 3; e++) A[3 * a + e] += (wb_real)((p[a] - c[a]) * (X[e] - C[e]));
        }
    }
    wb_extract_rotation(A, b->mq, 20);
    wb_quat_to_matrix(b->mq, mo->Q);
    for (int a = 0; a < 3; a++) mo->C[a] = (wb_real)C[a], mo->c[a] = (wb_real)c[a];
    return isfinite(mo->Q[0] + mo->Q[4] + mo->Q[8] + mo->c[0] + mo->c[1] + mo->c[2]);
}

/* fn(ctx, j) for every particle the kept list's grid has in the cells within e of p (where
 * the list was built); stops at the first fn that returns 0, and returns 0 then */
static int grid_each(const wb_broad *b, const wb_real *p, wb_real e, int (*fn)(void *ctx, int32_t j), void *ctx)
{
    const wb_grid *G = &b->lg;
    int64_t rx[4], ry[4], rz[4];
    const int kx = axis_ranges(G, 0, p[0], e, rx), ky = axis_ranges(G, 1, p[1], e, ry), kz = axis_ranges(G, 2, p[2], e, rz);
    /* a point past the grid's far side: an axis's range is empty there, and no grid
     * particle is near it that way */
    if (rx[0] > rx[1] || ry[0] > ry[1] || rz[0] > rz[1]) return 1;
    for (int az = 0; az < kz; az++)
        for (int64_t z = rz[2 * az]; z <= rz[2 * az + 1]; z++)
            for (int ay = 0; ay < ky; ay++)
                for (int64_t y = ry[2 * ay]; y <= ry[2 * ay + 1]; y++) {
                    const int64_t row = G->nc[0] * (y + G->nc[1] * z);
                    for (int ax = 0; ax < kx; ax++)
                        for (int32_t t = b->start[row + rx[2 * ax]]; t < b->start[row + rx[2 * ax + 1] + 1]; t++)
                            if (!fn(ctx, b->id[t])) return 0;
                }
    return 1;
}

/* the pairs of add (n, in any order, of particles below np) in (i, j) order, each once,
 * less those of the sorted list (nl) already; returns how many. Many pairs are put in
 * order by counting (b's scratch; a comparison sort where that is out of memory), a few
 * by comparison (the counts cost np) */
static int32_t new_pairs(wb_broad *b, int32_t np, int32_t *add, int32_t n, const int32_t *list, int32_t nl)
{
    if (n > 1) {
        if (b && n >= 64 && 16 * (int64_t)n >= np &&
            grow((void **)&b->by_j, &b->cap_by_j, 2 * (int64_t)n, sizeof *b->by_j) &&
            grow((void **)&b->cnt, &b->cap_cnt, (int64_t)np + 1, sizeof *b->cnt) &&
            grow((void **)&b->first, &b->cap_first, (int64_t)np + 1, sizeof *b->first)) {
            const pairbuf one = { add, n, n, 0, NULL, 0 };
            order_pairs(&one, 1, np, b->by_j, b->cnt, b->first, add);
        } else qsort(add, (size_t)n, 2 * sizeof *add, cmp_pair);
    }
    /* each looked for in the list from where the one before it was (both in order):
     * galloping, then a bisection, so many pairs cost a merge and a few a search */
    int32_t nb = 0, from = 0;
    for (int32_t q = 0; q < n; q++) {
        const int32_t *e = &add[2 * q];
        if (nb > 0 && cmp_pair(&add[2 * nb - 2], e) == 0) continue;
        int32_t lo = from, hi = from;
        for (int32_t step = 1; hi < nl && cmp_pair(&list[2 * hi], e) < 0; step *= 2) {
            lo = hi + 1;
            hi = nl - hi > step ? hi + step : nl;
        }
        while (lo < hi) {
            const int32_t mid = lo + (hi - lo) / 2;
            if (cmp_pair(&list[2 * mid], e) < 0) lo = mid + 1;
            else hi = mid;
        }
        from = lo;
        if (lo < nl && cmp_pair(&list[2 * lo], e) == 0) continue;
        add[2 * nb] = e[0];
        add[2 * nb + 1] = e[1];
        nb++;
    }
    return nb;
}

/* i and j into o when within their list reaches (list positions), not of one skip key, and
 * kept */
typedef struct mend_ctx {
    const wb_broad *b;
    const int32_t *skip;
    int32_t i;
    int (*keep)(void *ud, int32_t i, int32_t j);
    void *ud;
    pairbuf *o;
} mend_ctx;

static void mend_try(const wb_broad *b, const int32_t *skip, int32_t i, int32_t j,
                     int (*keep)(void *ud, int32_t i, int32_t j), void *ud, pairbuf *o)
{
    if (i == j || !(b->vr[j] >= 0)) return;
    const wb_real *P = &b->vx[3 * i], *Q = &b->vx[3 * j];
    const wb_real d0 = Q[0] - P[0], d1 = Q[1] - P[1], d2 = Q[2] - P[2], R = b->vr[i] + b->vr[j];
    if (!(d0 * d0 + d1 * d1 + d2 * d2 < R * R)) return;
    if (skip && skip[i] != 0 && skip[i] == skip[j]) return;
    const int32_t a = i < j ? i : j, c = i < j ? j : i;
    if (keep && !keep(ud, a, c)) return;
    push(o, a, c);
}

/* the grid's particles not mended since it was built (those are tried one by one) */
static int mend_grid(void *ctx, int32_t j)
{
    const mend_ctx *m = ctx;
    if (!m->b->is_moved[j]) mend_try(m->b, m->skip, m->i, j, m->keep, m->ud, m->o);
    return 1;
}

/* list_strays' verdict on particle i from its deviation from M (dd: its square, ds: the
 * sum of its coordinates) and mag (its size, |p|_1 + R_i): 1 out of its skin, 0 within,
 * -1 the list cannot serve; hot[i] as above (hot: NULL, not worked out) */
static inline __attribute__((always_inline)) int stray_verdict(const wb_broad *b, const wb_real *x,
                                                               const wb_real *reach, int32_t i, wb_real dd, wb_real ds,
                                                               wb_real mag, wb_real size, uint8_t *hot, int32_t *nh)
{
    /* takes_part(i) == (R[i] >= 0), its cheap half first: one that was left out (R < 0)
     * must still be; one that took part must have a reach >= 0 and finite, and a position
     * within its slack (a position not finite fails one of the two tests) */
    const wb_real Ri = b->vr[i], ri = reach[i];
    if (Ri < 0) {
        if (takes_part(x, reach, i)) return -1;
        if (hot) hot[i] = 0; /* in no pair */
        return 0;
    }
    if (!(ri >= 0) || !(ri < INFINITY)) return -1;
    const wb_real slack = (Ri - ri) * (wb_real)0.999;
    /* round-off in the pair distances: a slack far above the coordinates' ulps */
    const int out = !(dd <= slack * slack) || !(slack > (wb_real)1e-9 * mag);
    if (out && !isfinite(ds)) return -1;
    if (hot) {
        const wb_real g = b->half[i] * (1 - (wb_real)1e-6) - ri - (wb_real)1e-9 * (mag + size);
        const int h = !(g > 0 && dd < g * g);
        hot[i] = (uint8_t)h;
        *nh += h;
    }
    return out;
}

#ifdef WB_SIMD_H_AVX2
/* list_strays' pass with each deviation in AVX2 (x, y, z as lanes; M's rows as
 * ((c + Q0 r0) + Q1 r1) + Q2 r2, motion_apply's order; no fused multiply-adds): the
 * same bits */
static __attribute__((target("avx2"))) int32_t strays_pass_avx2(const wb_broad *b, const wb_real *x,
                                                                const wb_real *reach, int32_t n, const wb_motion *mo,
                                                                wb_real size, int32_t *bad, int32_t nbad, uint8_t *hot,
                                                                int32_t *nh)
{
    const wb_real *Q = mo->Q, *X = b->vx, *R = b->vr;
    const __m256d C = _mm256_set_pd(0, mo->C[2], mo->C[1], mo->C[0]), c = _mm256_set_pd(0, mo->c[2], mo->c[1], mo->c[0]);
    const __m256d Q0 = _mm256_set_pd(0, Q[6], Q[3], Q[0]), Q1 = _mm256_set_pd(0, Q[7], Q[4], Q[1]),
                  Q2 = _mm256_set_pd(0, Q[8], Q[5], Q[2]), sign = _mm256_set1_pd(-0.0);
    int32_t nb = 0;
    for (int32_t i = 0; i < n; i++) {
        const __m256d r = _mm256_sub_pd(wb__load3(&X[3 * i]), C), p = wb__load3(&x[3 * i]);
        const __m256d y = _mm256_add_pd(_mm256_add_pd(_mm256_add_pd(c, _mm256_mul_pd(Q0, _mm256_permute4x64_pd(r, 0x00))),
                                                      _mm256_mul_pd(Q1, _mm256_permute4x64_pd(r, 0x55))),
                                        _mm256_mul_pd(Q2, _mm256_permute4x64_pd(r, 0xaa)));
        const __m256d d = _mm256_sub_pd(p, y);
        const int k = stray_verdict(b, x, reach, i, hsum3(_mm256_mul_pd(d, d)), hsum3(d),
                                    hsum3(_mm256_andnot_pd(sign, p)) + R[i], size, hot, nh);
        if (k < 0) return -1;
        if (k) {
            if (nb == nbad) return nbad + 1;
            bad[nb++] = i;
        }
    }
    return nb;
}
#endif

/* the particles that left their skin (up to nbad of them in bad; past that nbad + 1), or
 * -1 when the list cannot serve at all (other particles, skip keys or rules, or a particle
 * that joined or left). With hot (the list's gaps known: gap_ok), in the same pass: which
 * particles may be in a pair that passes the distance test now, how many in *nhot. Pair
 * (i, j) passes only if |x_i - x_j| < reach_i + reach_j; M keeps distances, so
 * |x_i - x_j| >= L_ij - |e_i| - |e_j| (L_ij: their list distance, e = x - M(X)), and one
 * of the two has |e| + reach > L_ij / 2 >= its half. A particle is cold when
 * |e| + reach < half less a millionth, and less 1e-9 of the coordinates' size (M's
 * round-off and the pair test's are far below both): a pair of two cold ones fails the
 * test to the bit. simd: the pass in AVX2 where the machine has it */
static int32_t list_strays(const wb_broad *b, const wb_real *x, const wb_real *reach, const int32_t *skip, int32_t n,
                           uint64_t gen, const wb_motion *mo, int32_t *bad, int32_t nbad, uint8_t *hot, int32_t *nhot,
                           int simd)
{
    if (b->vn != n || n == 0 || b->bare || b->vgen != gen) return -1;
    const wb_real *X = b->vx, *R = b->vr;
    const int32_t *K = b->vskip;
    if (skip && memcmp(skip, K, sizeof *K * (size_t)n)) return -1;
    for (int32_t i = 0; !skip && i < n; i++)
        if (K[i] != 0) return -1;
    int32_t nb = 0, nh = 0;
    const wb_real size = fabs(mo->c[0]) + fabs(mo->c[1]) + fabs(mo->c[2]) + fabs(mo->C[0]) + fabs(mo->C[1]) +
                         fabs(mo->C[2]);
#ifdef WB_SIMD_H_AVX2
    if (simd && __builtin_cpu_supports("avx2")) nb = strays_pass_avx2(b, x, reach, n, mo, size, bad, nbad, hot, &nh);
    else
#endif
    {
        (void)simd;
        for (int32_t i = 0; i < n; i++) {
            const wb_real *p = &x[3 * i];
            wb_real y[3];
            motion_apply(mo, &X[3 * i], y);
            const wb_real d0 = p[0] - y[0], d1 = p[1] - y[1], d2 = p[2] - y[2];
            const int k = stray_verdict(b, x, reach, i, d0 * d0 + d1 * d1 + d2 * d2, d0 + d1 + d2,
                                        fabs(p[0]) + fabs(p[1]) + fabs(p[2]) + R[i], size, hot, &nh);
            if (k < 0) return -1;
            if (k) {
                if (nb == nbad) return nbad + 1;
                bad[nb++] = i;
            }
        }
    }
    if (nb >= 0 && nb <= nbad && nhot) *nhot = nh;
    return nb;
}

/* each particle's half (above) for the list as it is; 0 when out of memory */
static int list_gaps(wb_broad *b, int32_t n)
{
    if (!grow((void **)&b->half, &b->cap_half, n, sizeof *b->half) ||
        !grow((void **)&b->hot, &b->cap_hot, n, sizeof *b->hot))
        return 0;
    wb_real *half = b->half;
    const wb_real *X = b->vx;
    for (int32_t i = 0; i < n; i++) half[i] = INFINITY; /* the least squared distance first */
    const int32_t *ij = b->list.ij;
    for (int32_t k = 0; k < b->list.n; k++) {
        const int32_t i = ij[2 * k], j = ij[2 * k + 1];
        const wb_real d0 = X[3 * j] - X[3 * i], d1 = X[3 * j + 1] - X[3 * i + 1], d2 = X[3 * j + 2] - X[3 * i + 2];
        const wb_real dd = d0 * d0 + d1 * d1 + d2 * d2;
        if (dd < half[i]) half[i] = dd;
        if (dd < half[j]) half[j] = dd;
    }
    for (int32_t i = 0; i < n; i++) half[i] = (wb_real)0.5 * sqrt(half[i]);
    b->gap_ok = 1;
    return 1;
}


/* The kept list mended where few particles left their skin (a cloth sliding slowly over a
 * sphere): each one's list position and reach made again from where it is (M^-1 x, in the
 * list's frame), and its pairs looked for among the grid's particles (where the list was
 * built; reach + the grid's largest) and the ones mended before it one by one. Its old
 * pairs stay (each call filters by distance). Every pair the skin argument needs is then
 * listed: two unmended particles' as before, a mended one's by its own search or the
 * later one's. The grid stays the list's, with the mended ones (moved) to try one by one.
 * 0 when out of memory */
static int mend_list(wb_broad *b, const wb_real *x, const wb_real *reach, const int32_t *skip, int32_t n,
                     const wb_motion *mo, const int32_t *bad, int32_t nb,
                     int (*keep)(void *ud, int32_t i, int32_t j), void *ud)
{
    if (!grow((void **)&b->moved, &b->cap_moved, (int64_t)b->nmoved + nb, sizeof *b->moved) ||
        !grow((void **)&b->is_moved, &b->cap_is_moved, n, sizeof *b->is_moved))
        return 0;
    if (b->nmoved == 0) memset(b->is_moved, 0, (size_t)n);
    const wb_real *Q = mo->Q;
    for (int32_t k = 0; k < nb; k++) {
        const int32_t i = bad[k];
        const wb_real *p = &x[3 * i], r0 = p[0] - mo->c[0], r1 = p[1] - mo->c[1], r2 = p[2] - mo->c[2];
        wb_real *X = &b->vx[3 * i];
        for (int a = 0; a < 3; a++) X[a] = mo->C[a] + Q[a] * r0 + Q[3 + a] * r1 + Q[6 + a] * r2;
        const wb_real R = reach[i] * (1 + (wb_real)SKIN);
        b->vr[i] = isfinite(R) ? R : reach[i];
        if (!b->is_moved[i]) {
            b->is_moved[i] = 1;
            b->moved[b->nmoved++] = i;
        }
    }
    pairbuf *o = &b->mend;
    o->n = 0;
    o->fail = 0;
    for (int32_t k = 0; k < nb; k++) {
        const int32_t i = bad[k];
        /* the grid's, then the mended ones' (a pair of two mended ones: found from both) */
        mend_ctx mc = { b, skip, i, keep, ud, o };
        grid_each(b, &b->vx[3 * i], b->vr[i] + b->lrmax, mend_grid, &mc);
        for (int32_t q = 0; q < b->nmoved; q++) mend_try(b, skip, i, b->moved[q], keep, ud, o);
    }
    if (o->fail) return 0;
    if (o->n == 0) return 1;
    /* in order, each once, those the list lacks, merged in */
    const int32_t na = new_pairs(b, n, o->ij, o->n, b->list.ij, b->list.n);
    if (!grow((void **)&b->list.ij, &b->list.cap, 2 * ((int64_t)b->list.n + na), sizeof *b->list.ij)) return 0;
    int32_t *ij = b->list.ij;
    for (int32_t p = b->list.n - 1, q = na - 1, w = b->list.n + na - 1; q >= 0; w--) {
        if (p >= 0 && cmp_pair(&ij[2 * p], &o->ij[2 * q]) > 0) {
            ij[2 * w] = ij[2 * p];
            ij[2 * w + 1] = ij[2 * p + 1];
            p--;
        } else {
            ij[2 * w] = o->ij[2 * q];
            ij[2 * w + 1] = o->ij[2 * q + 1];
            q--;
        }
    }
    b->list.n += na;
    return 1;
}

static int skin_pays(wb_broad *b, const wb_real *x, const wb_real *reach, int32_t n, const wb_motion *mo)
{
    if (b->vn != n) return 1;
    int32_t out = 0, in = 0;
    for (int32_t i = 0; i < n; i++) {
        if (!(b->vr[i] >= 0) || !(reach[i] >= 0)) continue;
        const wb_real *p = &x[3 * i], e = (wb_real)SKIN * reach[i];
        wb_real y[3];
        motion_apply(mo, &b->vx[3 * i], y);
        const wb_real d0 = p[0] - y[0], d1 = p[1] - y[1], d2 = p[2] - y[2];
        if (d0 * d0 + d1 * d1 + d2 * d2 > e * e) out++;
        else in++;
    }
    return out <= in;
}

int32_t wb__broadphase_kept(wb_contacts *c, const wb_real *x, const wb_real *reach, const int32_t *skip,
                            int32_t n, wb_pool *pool, int (*keep)(void *ud, int32_t i, int32_t j), uint64_t gen,
                            int (*keep_now)(void *ud, int32_t i, int32_t j), void *ud)
{
    if (!c->bp && !(c->bp = calloc(1, sizeof *c->bp))) return -1;
    wb_broad *b = c->bp;
    /* tried first under the motion it last served with (identity for a new list): a
     * cloth come to rest keeps it, and needs no fit */
    wb_motion mo = b->mo;
    if (b->vn == 0) motion_identity(&mo);
    /* particles that may be in a passing pair, known when the list serves unmended: -1
     * (every pair tested) otherwise */
    int32_t nhot = -1;
    uint8_t *hot = b->gap_ok && !c->no_gaps ? b->hot : NULL;
    int valid = list_strays(b, x, reach, skip, n, gen, &mo, NULL, 0, hot, &nhot, !c->no_simd) == 0;
    if (!valid && b->vn == n && !b->bare && b->vgen == gen && motion_fit(b, x, n, &mo, !c->no_simd)) {
        /* a few particles out of their skin: the list mended for them (up to 1 in 32, and
         * 1 in 8 mended since it was built) */
        const int32_t most = n / 32 > 16 ? n / 32 : 16;
        int32_t *bad = wb__grow(b->bad, &b->cap_bad, most, sizeof *bad);
        if (bad) b->bad = bad;
        const int32_t nb = bad ? list_strays(b, x, reach, skip, n, gen, &mo, bad, most, hot, &nhot, !c->no_simd) : -1;
        valid = nb == 0;
        if (nb > 0 && nb <= most && b->lgrid && b->lfull && b->nmoved + nb <= n / 8 + 16) {
            if (!mend_list(b, x, reach, skip, n, &mo, bad, nb, keep, ud)) return -1;
            b->mends++;
            b->gap_ok = 0;
            valid = 1;
        }
    }
    if (!valid || !hot || b->gap_ok == 0) nhot = -1;
    if (valid) {
        b->mo = mo;
        b->used = 1;
    } else {
        /* a skin pays only where a list lasts: where most particles moved farther than a
         * skin (from the motion they share) since the last list, the next one is built
         * without (a cloth on the move every which way: the skin only doubled the pairs
         * searched), and after a list with a skin that was never used again, the next
         * 1, 2, 4 or 8 in a row as that goes on (a cloth sliding slowly over a sphere: a
         * few particles leave their skin every frame) */
        if (!b->bare) {
            b->bare_run = b->used || b->vn != n ? 0 : b->bare_run ? (b->bare_run < 8 ? 2 * b->bare_run : 8) : 1;
            b->bare_left = b->bare_run;
        }
        const int skin = b->bare_left == 0 && skin_pays(b, x, reach, n, &mo);
        if (b->bare_left > 0) b->bare_left--;
        b->used = 0;
        motion_identity(&b->mo);
        b->mq[0] = 1, b->mq[1] = b->mq[2] = b->mq[3] = 0;
        b->nmoved = 0;
        const wb_real grow_by = skin ? 1 + (wb_real)SKIN : 1;
        b->vn = 0;
        if (!grow((void **)&b->vx, &b->cap_vx, 3 * (int64_t)n, sizeof *b->vx) ||
            !grow((void **)&b->vr, &b->cap_vr, n, sizeof *b->vr) ||
            !grow((void **)&b->vskip, &b->cap_vskip, n, sizeof *b->vskip))
            return -1;
        for (int32_t i = 0; i < n; i++) {
            wb_real r = takes_part(x, reach, i) ? reach[i] * grow_by : -1;
            /* a reach that overflows with the skin: none (the check then rebuilds) */
            b->vr[i] = isfinite(r) ? r : reach[i];
            b->vskip[i] = skip ? skip[i] : 0;
        }
        if (n > 0) memcpy(b->vx, x, sizeof *x * 3 * (size_t)n);
        b->list.n = 0;
        b->lgrid = 0;
        b->gap_ok = 0;
        /* keep's rules applied in the search (the list is rebuilt when they change); a list
         * without a skin serves this call alone (its distance test below passes every pair) */
        b->bare = !skin;
        if (broad(b, &b->list, x, b->vr, skip, n, pool, keep, ud) < 0) return -1;
        b->lgrid = 1;
        b->vn = n;
        b->vgen = gen;
        b->rebuilds++;
    }
    if (!grow((void **)&c->ij, &c->cap, 2 * ((int64_t)c->n + b->list.n), sizeof *c->ij)) return -1;
    int32_t *out = c->ij, at = c->n;
    const int32_t *ij = b->list.ij;
    if (nhot >= 0) b->gap_calls++, b->gap_quiet += nhot == 0;
    /* a pair of two cold particles fails below: none tested when every particle is cold */
    const int32_t npair = nhot == 0 ? 0 : b->list.n;
    for (int32_t k = 0; k < npair; k++) {
        const int32_t i = ij[2 * k], j = ij[2 * k + 1];
        if (nhot > 0 && !(hot[i] | hot[j])) continue;
        const wb_real *p = &x[3 * i], *q = &x[3 * j];
        const wb_real d0 = q[0] - p[0], d1 = q[1] - p[1], d2 = q[2] - p[2], r = reach[i] + reach[j];
        if (d0 * d0 + d1 * d1 + d2 * d2 >= r * r) continue;
        if (keep_now && !keep_now(ud, i, j)) continue;
        out[2 * at] = i;
        out[2 * at + 1] = j;
        at++;
    }
    c->n = at;
    /* the gaps of a list just built or mended, for the next calls (a list without a skin
     * serves this call alone) */
    if (!b->gap_ok && !b->bare && !c->no_gaps && !list_gaps(b, n)) return -1;
    return c->n;
}

/* ---- which pairs may touch -------------------------------------------------------------------- */
static int cmp_i32(const void *a, const void *b)
{
    const int32_t x = *(const int32_t *)a, y = *(const int32_t *)b;
    return (x > y) - (x < y);
}

static int cmp_u64(const void *a, const void *b)
{
    uint64_t x = *(const uint64_t *)a, y = *(const uint64_t *)b;
    return x < y ? -1 : x > y;
}

/* pairs (i, j) in (i, j) order */
static int cmp_pair(const void *pa, const void *pb)
{
    const int32_t *a = pa, *b = pb;
    return a[0] != b[0] ? (a[0] < b[0] ? -1 : 1) : (a[1] > b[1]) - (a[1] < b[1]);
}

static uint64_t pair_key(int32_t a, int32_t b)
{
    return a < b ? (uint64_t)(uint32_t)a << 32 | (uint32_t)b : (uint64_t)(uint32_t)b << 32 | (uint32_t)a;
}

/* ---- the rest-neighbour rule's data: joined pairs and loose graphs ----------------------------- */
typedef struct links_ud {
    wb_contacts *c;
    const wb_model *m;
    int32_t n, cap;        /* keys so far */
    int fail;
} links_ud;

/* the root of a graph, halving the path on the way (union-find) */
static int32_t graph_root(int32_t *g, int32_t i)
{
    while (g[i] != i) {
        g[i] = g[g[i]];
        i = g[i];
    }
    return i;
}

static void add_link(void *ud, int32_t a, int32_t b, int joined)
{
    links_ud *u = ud;
    wb_contacts *c = u->c;
    if (a == b) return;
    if (joined) {
        if (u->n == u->cap) {
            uint64_t *k = wb__grow(c->keys, &c->cap_keys, u->n + 1, sizeof *k);
            if (!k) { u->fail = 1; return; }
            c->keys = k;
            u->cap = c->cap_keys;
        }
        c->keys[u->n++] = pair_key(a, b);
    }
    /* a loose particle's graph: the loose particles its links reach (a body's particles
     * are their body's already) */
    if (u->m->group[a] == 0 && u->m->group[b] == 0) {
        const int32_t ra = graph_root(c->graph, a), rb = graph_root(c->graph, b);
        if (ra < rb) c->graph[rb] = ra;
        else c->graph[ra] = rb;
    }
}

/* Rest neighbours along a hand-built graph or a self-colliding body. Two particles of one
 * graph (or body) that were
 * made less than ALONG (r_i + r_j) apart, and are joined by a path along its constraints
 * (the sum of its links' lengths where they were made) shorter than sqrt 2 ALONG
 * (r_i + r_j), never touch either: a fold takes about pi r of the body to bring two layers
 * 2r apart (ALONG = pi / 2), so such a pair only meets by the graph shearing or bunching,
 * not by folding onto itself. The path bounds how far along the body they are: up to
 * sqrt 2 longer than the straight line over a square net, while a pair made close across
 * a fold (a coiled rope) has a far longer one. Without it a net 1.57 cm apart with the
 * default radius 0.02 m touched its neighbours two cells off the diagonal (made 4.45 cm
 * apart) where it sheared near a pin, 6 frames after it was let go. Each search stops
 * after ALONG_MOST particles (a radius many times the spacing): past that only the
 * created-closer rule holds. Keys of the pairs, added to u's; 0 when out of memory */
#define ALONG 1.5707963267948966 /* pi / 2 */
#define ALONG_PATH 1.4142135623730951 /* sqrt 2 */
#define ALONG_MOST 256

typedef struct along_item { wb_real d; int32_t j; } along_item;

static void along_push(along_item *h, int32_t *n, along_item e)
{
    int32_t k = (*n)++;
    while (k > 0) {
        const int32_t up = (k - 1) / 2;
        if (h[up].d < e.d || (h[up].d == e.d && h[up].j <= e.j)) break;
        h[k] = h[up];
        k = up;
    }
    h[k] = e;
}

static along_item along_pop(along_item *h, int32_t *n)
{
    const along_item top = h[0], e = h[--*n];
    int32_t k = 0;
    for (;;) {
        int32_t c = 2 * k + 1;
        if (c >= *n) break;
        if (c + 1 < *n && (h[c + 1].d < h[c].d || (h[c + 1].d == h[c].d && h[c + 1].j < h[c].j))) c++;
        if (e.d < h[c].d || (e.d == h[c].d && e.j <= h[c].j)) break;
        h[k] = h[c];
        k = c;
    }
    if (*n > 0) h[k] = e;
    return top;
}

/* add_along's queue of (d, j), the least first (ties: the lesser j, a strict order: one
 * particle is queued again only nearer). While short, a sorted run [head, n): a new item
 * is mostly among the farthest, a few moves from the end, where a heap's pop costs a
 * sift through its levels; past ALONG_RUN items the run (sorted, so a heap already) goes
 * on as a binary heap. Either pops the items in the same order */
#define ALONG_RUN 32
typedef struct along_queue { along_item *a; int32_t head, n, heap; } along_queue;

static inline int32_t along_size(const along_queue *q) { return q->n - q->head; }

static inline void along_add(along_queue *q, along_item e)
{
    if (!q->heap && q->n - q->head >= ALONG_RUN) {
        memmove(q->a, q->a + q->head, sizeof *q->a * (size_t)(q->n - q->head));
        q->n -= q->head;
        q->head = 0;
        q->heap = 1;
    }
    if (q->heap) {
        along_push(q->a, &q->n, e);
        return;
    }
    int32_t k = q->n++;
    for (; k > q->head && (e.d < q->a[k - 1].d || (e.d == q->a[k - 1].d && e.j < q->a[k - 1].j)); k--)
        q->a[k] = q->a[k - 1];
    q->a[k] = e;
}

static inline along_item along_next(along_queue *q)
{
    return q->heap ? along_pop(q->a, &q->n) : q->a[q->head++];
}

/* a link add_along walks: both ends loose, or both of one body that collides with
 * itself (no other body pairs within itself) */
static inline int along_link(const wb_model *m, int32_t a, int32_t b)
{
    return m->group[a] == m->group[b] && (m->group[a] == 0 || (m->cflags[a] & m->cflags[b] & WB_CF_SELF));
}

static int add_along(links_ud *u, int32_t nlinks)
{
    wb_contacts *c = u->c;
    const wb_model *m = u->m;
    const int32_t np = m->np;
    wb_real rmax = 0;
    for (int32_t i = 0; i < np; i++)
        if ((m->group[i] == 0 || (m->cflags[i] & WB_CF_SELF)) && m->radius[i] > rmax) rmax = m->radius[i];
    if (!(rmax > 0) || nlinks == 0) return 1;
    /* the loose particles' links as rows (each both ways) */
    int32_t *row = calloc((size_t)np + 1, sizeof *row), *to = malloc(sizeof *to * 2 * (size_t)nlinks);
    wb_real *len = malloc(sizeof *len * 2 * (size_t)nlinks), *dist = malloc(sizeof *dist * (size_t)np);
    int32_t *seen = malloc(sizeof *seen * (size_t)np);
    along_item *heap = malloc(sizeof *heap * (4 * (size_t)ALONG_MOST + 2 * (size_t)nlinks));
    int ok = row && to && len && dist && seen && heap;
    if (!ok) goto done;
    for (int32_t k = 0; k < nlinks; k++) {
        const int32_t a = (int32_t)(c->keys[k] >> 32), b = (int32_t)(uint32_t)c->keys[k];
        if (along_link(m, a, b)) row[a + 1]++, row[b + 1]++;
    }
    for (int32_t i = 0; i < np; i++) row[i + 1] += row[i];
    for (int32_t k = 0; k < nlinks; k++) {
        const int32_t a = (int32_t)(c->keys[k] >> 32), b = (int32_t)(uint32_t)c->keys[k];
        if (!along_link(m, a, b)) continue;
        wb_real d[3];
        v3_sub(d, &m->x0[3 * b], &m->x0[3 * a]);
        const wb_real l = v3_len(d);
        to[row[a]] = b, len[row[a]++] = l;
        to[row[b]] = a, len[row[b]++] = l;
    }
    for (int32_t i = np; i > 0; i--) row[i] = row[i - 1];
    row[0] = 0;
    for (int32_t i = 0; i < np; i++) seen[i] = -1;
    for (int32_t i = 0; ok && i < np; i++) {
        if (row[i] == row[i + 1]) continue;
        const wb_real bound = (wb_real)ALONG_PATH * ALONG * (m->radius[i] + rmax);
        /* (a run: at most 1 + 2 nlinks items are ever queued, fewer than heap holds) */
        along_queue qu = { heap, 0, 0, c->along_heap };
        int32_t settled = 0;
        dist[i] = 0;
        seen[i] = i;
        along_add(&qu, (along_item){ 0, i });
        while (along_size(&qu) > 0 && settled < ALONG_MOST) {
            const along_item e = along_next(&qu);
            if (e.d > dist[e.j]) continue; /* a longer way to one settled already */
            settled++;
            const int32_t j = e.j;
            const wb_real rij = m->radius[i] + m->radius[j];
            if (j != i && e.d < (wb_real)ALONG_PATH * ALONG * rij) {
                wb_real d[3];
                v3_sub(d, &m->x0[3 * j], &m->x0[3 * i]);
                const wb_real dd = v3_dot(d, d), r = rij * WB_REST_TOUCH, a = ALONG * rij;
                if (dd >= r * r && dd < a * a) { /* (the created-closer rule has the closer) */
                    if (u->n == u->cap) {
                        uint64_t *kk = wb__grow(c->keys, &c->cap_keys, (int64_t)u->n + 1, sizeof *kk);
                        if (!kk) { ok = 0; break; }
                        c->keys = kk;
                        u->cap = c->cap_keys;
                    }
                    c->keys[u->n++] = pair_key(i, j);
                }
            }
            for (int32_t q = row[j]; q < row[j + 1]; q++) {
                const int32_t o = to[q];
                const wb_real d = e.d + len[q];
                if (!(d < bound) || (seen[o] == i && !(d < dist[o]))) continue;
                seen[o] = i;
                dist[o] = d;
                if (along_size(&qu) < 4 * ALONG_MOST + 2 * nlinks) along_add(&qu, (along_item){ d, o });
            }
        }
        c->along_heaps += qu.heap;
    }
done:
    free(row); free(to); free(len); free(dist); free(seen); free(heap);
    return ok;
}

static inline wb_real made_d2(const wb_model *m, int32_t i, int32_t j)
{
    wb_real d[3];
    v3_sub(d, &m->x0[3 * j], &m->x0[3 * i]);
    return v3_dot(d, d);
}

/* The rule's bounds by made distance (near2, far2), so that most pairs are decided
 * without searching the keys: a hand-built net or a cloth finds its rest neighbours in
 * the search every frame (dozens a particle with the default radius over a fine net) and
 * rejected each by a search of its keys. far2: the farthest a key of the particle was
 * made. near2: the nearest a particle of its body or graph that is no rest neighbour was
 * made, found by one search of the made positions (below: as far as it was searched).
 * Worked out with the rules; 0 when out of memory */
static int one_graph_rule(const wb_world *w, int32_t i, int32_t j, int bounds);

static int made_bounds(wb_world *w)
{
    wb_contacts *c = w->k.pc;
    const wb_model *m = &w->m;
    const int32_t np = m->np;
    wb_real *n2 = wb__grow(c->near2, &c->cap_near2, np > 0 ? np : 1, sizeof *n2);
    if (n2) c->near2 = n2;
    wb_real *f2 = wb__grow(c->far2, &c->cap_far2, np > 0 ? np : 1, sizeof *f2);
    if (f2) c->far2 = f2;
    wb_real *reach = wb__grow(c->reach, &c->cap_reach, np > 0 ? np : 1, sizeof *reach);
    if (reach) c->reach = reach;
    if (!n2 || !f2 || !reach) return 0;
    for (int32_t i = 0; i < np; i++) f2[i] = 0;
    for (int32_t k = 0; k < c->nkeys; k++) {
        const int32_t a = (int32_t)(c->keys[k] >> 32), b = (int32_t)(uint32_t)c->keys[k];
        const wb_real d2 = made_d2(m, a, b);
        f2[a] = d2 > f2[a] ? d2 : f2[a];
        f2[b] = d2 > f2[b] ? d2 : f2[b];
    }
    /* the particles that pair within their body or graph (loose, or self-colliding), each
     * searched to ALONG r_i, or half as far as its farthest key where that is nearer (a
     * radius many times the spacing: the search then finds about as many particles as it
     * has keys) */
    wb_real rmin = INFINITY;
    for (int32_t i = 0; i < np; i++) {
        const int takes = (m->group[i] == 0 || (m->cflags[i] & WB_CF_SELF)) &&
                          isfinite(m->x0[3 * i] + m->x0[3 * i + 1] + m->x0[3 * i + 2]);
        const wb_real a = (wb_real)ALONG * m->radius[i], b = (wb_real)0.5 * sqrt(f2[i]);
        reach[i] = takes ? (a < b ? a : b) : -1;
        if (reach[i] >= 0 && reach[i] < rmin) rmin = reach[i];
    }
    for (int32_t i = 0; i < np; i++) {
        /* every particle made within reach_i + rmin was searched (a millionth less: the
         * search's own test of the distance may round the other way) */
        const wb_real cap = (reach[i] + rmin) * (wb_real)(1 - 1e-6);
        n2[i] = reach[i] >= 0 ? cap * cap : 0;
    }
    c->n = 0; /* (called with no list: wb__contacts_begin) */
    const int32_t r = wb__broadphase(c, m->x0, reach, NULL, np, wb__world_pool(w), NULL, NULL);
    for (int32_t k = 0; k < r; k++) {
        const int32_t i = c->ij[2 * k], j = c->ij[2 * k + 1];
        if (wb__graph_of(c, m, i) != wb__graph_of(c, m, j) || !one_graph_rule(w, i, j, 0)) continue;
        const wb_real d2 = made_d2(m, i, j);
        n2[i] = d2 < n2[i] ? d2 : n2[i];
        n2[j] = d2 < n2[j] ? d2 : n2[j];
    }
    c->n = 0;
    return r >= 0;
}

/* n keys of particles below np sorted, by two counting sorts (by the greater particle,
 * then stably by the less): linear, where a comparison sort of a cloth's ~300k keys took
 * most of the rules' build; 0 when out of memory */
static int sort_keys(uint64_t *keys, int32_t n, int32_t np)
{
    for (int32_t k = 0; k < n; k++)
        if ((uint32_t)(keys[k] >> 32) >= (uint32_t)np || (uint32_t)keys[k] >= (uint32_t)np) {
            qsort(keys, (size_t)n, sizeof *keys, cmp_u64); /* (not a particle's: never so far) */
            return 1;
        }
    uint64_t *tmp = malloc(sizeof *tmp * (size_t)n);
    int32_t *at = malloc(sizeof *at * ((size_t)np + 1));
    const int ok = tmp && at;
    for (int pass = 0; ok && pass < 2; pass++) {
        /* pass 0: keys into tmp by their low half; pass 1: back by their high half */
        const uint64_t *src = pass ? tmp : keys;
        uint64_t *dst = pass ? keys : tmp;
        const int shift = pass ? 32 : 0;
        memset(at, 0, sizeof *at * ((size_t)np + 1));
        for (int32_t k = 0; k < n; k++) at[(uint32_t)(src[k] >> shift) + 1]++;
        for (int32_t i = 0; i < np; i++) at[i + 1] += at[i];
        for (int32_t k = 0; k < n; k++) dst[at[(uint32_t)(src[k] >> shift)]++] = src[k];
    }
    free(tmp);
    free(at);
    return ok;
}

/* what the pair rule asks (may_touch, tribroad.c's): every type's links as sorted keys,
 * each once, and the loose particles' graphs; 0 when out of memory */
static int build_rules(wb_world *w)
{
    wb_contacts *c = w->k.pc;
    const wb_model *m = &w->m;
    int32_t *g = wb__grow(c->graph, &c->cap_graph, m->np > 0 ? m->np : 1, sizeof *g);
    if (!g) return 0;
    c->graph = g;
    for (int32_t i = 0; i < m->np; i++) g[i] = i;
    links_ud u = { c, m, 0, c->cap_keys, 0 };
    for (int t = 0; t < wb__nctypes && !u.fail; t++)
        if (wb__ctypes[t]->links) wb__ctypes[t]->links(w, add_link, &u);
    if (u.fail || !add_along(&u, u.n)) return 0;
    for (int32_t i = 0; i < m->np; i++) g[i] = graph_root(g, i);
    if (u.n > 1 && !sort_keys(c->keys, u.n, m->np)) return 0; /* keys is NULL while none */
    int32_t n = 0;
    c->cross = 0;
    for (int32_t k = 0; k < u.n; k++) {
        if (n > 0 && c->keys[n - 1] == c->keys[k]) continue;
        c->keys[n++] = c->keys[k];
        const int32_t a = (int32_t)(c->keys[k] >> 32), b = (int32_t)(uint32_t)c->keys[k];
        if (wb__graph_of(c, m, a) != wb__graph_of(c, m, b)) c->cross = 1;
    }
    c->nkeys = n;
    c->keys_dirty = 0;
    /* each particle's row of keys (they are sorted by their less particle): wb__joined
     * then searches a handful, not all of them */
    int32_t *row = wb__grow(c->key_row, &c->cap_key_row, m->np + 1, sizeof *row);
    if (!row) return 0;
    c->key_row = row;
    memset(row, 0, sizeof *row * ((size_t)m->np + 1));
    for (int32_t k = 0; k < n; k++) row[(c->keys[k] >> 32) + 1]++;
    for (int32_t i = 0; i < m->np; i++) row[i + 1] += row[i];
    return made_bounds(w);
}

/* Self-collision by particles alone where they cover the surface (Macklin et al. 2014,
 * "Unified particle physics", and Vellum's or Obi's thickness): a triangle whose every
 * point lies within r_min + min(r_corner) of a corner at rest, with COVER_STRETCH to spare,
 * cannot be crossed by a point of its own body (radius >= r_min, the body's least) without
 * that point touching a corner first, up to that much stretch: its own body's points leave
 * it to the particle pairs. The farthest a point of the triangle lies from its nearest
 * corner is at most the circumradius (the circumcentre, or outside an obtuse triangle:
 * then the bound is loose and the triangle is kept). A cloth or lattice of spacing s and
 * radius s / 2: R = 0.71 s, covered up to 41% stretch. */
#define COVER_STRETCH 1.25

typedef struct group_radius { int32_t g; wb_real r; } group_radius;

static int cmp_group_radius(const void *a, const void *b)
{
    const group_radius *x = a, *y = b;
    return x->g < y->g ? -1 : x->g > y->g ? 1 : (x->r < y->r ? -1 : x->r > y->r);
}

static int build_cover(wb_world *w)
{
    wb_contacts *c = w->k.pc;
    const wb_model *m = &w->m;
    uint8_t *cov = wb__grow(c->tcov, &c->cap_tcov, m->ntri > 0 ? m->ntri : 1, sizeof *cov);
    if (!cov) return 0;
    c->tcov = cov;
    if (m->ntri == 0) return 1;
    /* each body's least radius: (group, radius) sorted, the first of each group */
    group_radius *gr = malloc(sizeof *gr * (size_t)(m->np > 0 ? m->np : 1));
    if (!gr) return 0;
    int32_t n = 0, ng = 0;
    for (int32_t i = 0; i < m->np; i++)
        if (m->group[i] > 0) gr[n++] = (group_radius){ m->group[i], m->radius[i] };
    qsort(gr, (size_t)n, sizeof *gr, cmp_group_radius);
    for (int32_t k = 0; k < n; k++)
        if (ng == 0 || gr[ng - 1].g != gr[k].g) gr[ng++] = gr[k];
    const wb_real *x0 = m->x0, *rad = m->radius;
    for (int32_t t = 0; t < m->ntri; t++) {
        const int32_t *v = &m->tri[3 * t], g = m->group[v[0]];
        cov[t] = 0;
        if (g <= 0 || m->group[v[1]] != g || m->group[v[2]] != g) continue;
        int32_t lo = 0, hi = ng;
        while (lo < hi) {
            const int32_t mid = lo + (hi - lo) / 2;
            if (gr[mid].g < g) lo = mid + 1;
            else hi = mid;
        }
        const wb_real rc = fmin(rad[v[0]], fmin(rad[v[1]], rad[v[2]])), reach = gr[lo].r + rc;
        wb_real e0[3], e1[3], e2[3], n3[3];
        v3_sub(e0, &x0[3 * v[1]], &x0[3 * v[0]]);
        v3_sub(e1, &x0[3 * v[2]], &x0[3 * v[1]]);
        v3_sub(e2, &x0[3 * v[0]], &x0[3 * v[2]]);
        v3_cross(n3, e0, e2);
        /* R = abc / (4 area) = abc / (2 |e0 x e2|), compared without dividing */
        const wb_real abc = v3_len(e0) * v3_len(e1) * v3_len(e2), twice_area = v3_len(n3);
        cov[t] = twice_area > 0 && abc * (wb_real)COVER_STRETCH <= 2 * twice_area * reach;
    }
    free(gr);
    return 1;
}

/* the particles, triangles and each type's constraints, so that adding any rebuilds the
 * rules */
static uint64_t rules_sig(const wb_world *w)
{
    uint64_t h = (1469598103934665603ull ^ (uint64_t)(uint32_t)w->m.np) * 1099511628211ull;
    h = (h ^ (uint64_t)(uint32_t)w->m.ntri) * 1099511628211ull;
    for (int t = 0; t < wb__nctypes; t++)
        h = (h ^ (uint64_t)(uint32_t)wb__ctypes[t]->count(w)) * 1099511628211ull;
    return h;
}

int wb__contact_rules(wb_world *w)
{
    wb_contacts *c = w->k.pc;
    const uint64_t sig = rules_sig(w);
    if (!c->keys_dirty && !c->scan_dirty && c->keys_sig == sig && c->graph) return 1;
    if (!build_rules(w) || !build_cover(w)) return 0;
    c->keys_sig = sig;
    c->rules_gen++;
    return 1;
}

int wb__joined(const wb_contacts *c, int32_t i, int32_t j)
{
    if (c->nkeys == 0) return 0;
    const uint64_t key = pair_key(i, j);
    const int32_t a = i < j ? i : j;
    /* a row holds the handful of links, bends, ... from a: a linear scan beats a bisection
     * there; a hub's long row is bisected down to such a stretch first */
    const uint64_t *k = &c->keys[c->key_row[a]], *end = &c->keys[c->key_row[a + 1]];
    for (const uint64_t *hi = end; hi - k > 16;) {
        const uint64_t *mid = k + (hi - k) / 2;
        if (*mid < key) k = mid + 1;
        else hi = mid;
    }
    while (k < end && *k < key) k++;
    return k < end && *k == key;
}

/* two particles of one body or graph; with bounds, most decided by their made distance
 * alone (made_bounds), else by the keys (made_bounds works the bounds out so) */
static int one_graph_rule(const wb_world *w, int32_t i, int32_t j, int bounds)
{
    const wb_model *m = &w->m;
    const wb_contacts *c = w->k.pc;
    if (m->group[i] > 0 && !(m->cflags[i] & m->cflags[j] & WB_CF_SELF)) return 0;
    const wb_real d2 = made_d2(m, i, j);
    if (bounds && (d2 < c->near2[i] || d2 < c->near2[j])) return 0;
    const wb_real r = (m->radius[i] + m->radius[j]) * WB_REST_TOUCH;
    if (d2 < r * r) return 0;
    return (bounds && d2 > c->far2[i]) || !wb__joined(c, i, j);
}

/* The contact rule (docs/physics.md, "Contacts"): particles of two bodies (or graphs)
 * touch when both collide, unless a constraint joins them; of one, only when it collides
 * with itself (a loose graph always does), and never rest neighbours: joined, or made
 * closer than r_i + r_j (or in touch: WB_REST_TOUCH) */
static int rules(const wb_world *w, int32_t i, int32_t j, int bounds)
{
    const wb_model *m = &w->m;
    const wb_contacts *c = w->k.pc;
    if (wb__graph_of(c, m, i) != wb__graph_of(c, m, j))
        return (m->cflags[i] & m->cflags[j] & WB_CF_COLLIDE) && !(c->cross && wb__joined(c, i, j));
    return one_graph_rule(w, i, j, bounds);
}

static int may_touch_rules(void *ud, int32_t i, int32_t j) { return rules(ud, i, j, 1); }

/* ... and not both immovable (pins change from frame to frame; the rules do not) */
static int movable_pair(void *ud, int32_t i, int32_t j)
{
    const wb_model *m = &((const wb_world *)ud)->m;
    return m->w[i] != 0 || m->w[j] != 0;
}

static int may_touch(void *ud, int32_t i, int32_t j) { return movable_pair(ud, i, j) && may_touch_rules(ud, i, j); }

/* whether any pair could collide at all: one body without self-collision costs nothing */
static int any_possible(const wb_model *m)
{
    int32_t loose = 0, g1 = -1;
    int groups = 0;
    for (int32_t i = 0; i < m->np; i++) {
        const uint8_t f = m->cflags[i];
        if (f & WB_CF_SELF) return 1;
        if (!(f & WB_CF_COLLIDE)) continue;
        if (m->group[i] == 0) loose++;
        else if (g1 < 0) { g1 = m->group[i]; groups = 1; }
        else if (m->group[i] != g1) groups = 2;
        if (loose >= 2 || groups >= 2 || (loose >= 1 && groups >= 1)) return 1;
    }
    return 0;
}

/* ---- the step ---------------------------------------------------------------------------------- */
/* The reference motion. A particle's reach is how far it can get from where the motion
 * every particle shares takes it: a velocity V and a turn om about c fitted to the
 * particles (the mass-weighted least squares: momentum and angular momentum about the
 * mass centre), slowed by the world's drag as the prediction slows velocities (v <-
 * lambda v + g h): after j substeps of h the reference takes any point to
 * Phi_j(x) = x + S_j (V + om x (x - c)), S_j = h (lambda + ... + lambda^j). Its linear
 * part I + S_j [om]x never shortens a vector (|u + s om x u|^2 = |u|^2 + s^2 |om x u|^2),
 * so two points farther apart than reach_i + reach_j at the list's start are still so
 * under the reference, and each particle's deviation from it, x_i - Phi_j(xf_i), kept
 * within reach_i - r_i by the substeps' check, keeps them farther than r_i + r_j. One
 * map for every particle: any two bodies, however each moves. A swinging cloth then
 * needs reaches of about its radius, not of how far it travels in a frame (|v| dt).
 * Gravity stays in every reach (|g| dt^2), not in the reference: a particle resting on
 * the floor does not fall with it. When the fit does not cut the volume the reaches search
 * to a quarter (bodies moving every which way, a heap), the reference stands still, as
 * before. */
typedef struct ref_step { wb_real S, vf; } ref_step;

/* after j substeps of h from the list's start: S_j, and the factor vf of the
 * reference's velocity there, vf (V + om x r) */
static ref_step ref_at(const wb_world *w, int32_t j, wb_real h)
{
    const wb_real damping = w->m.def.damping;
    const wb_real keep = damping > 0 ? (damping * h < 1 ? 1 - damping * h : 0) : 1;
    ref_step r = { 0, 1 };
    for (int32_t i = 0; i < j; i++) {
        r.vf *= keep;
        r.S += h * r.vf;
    }
    return r;
}

/* the reference's velocity at y (out) scaled by s */
static inline void ref_vel(const wb_contacts *c, wb_real s, const wb_real *y, wb_real out[3])
{
    const wb_real *V = c->ref_v, *om = c->ref_om, *cc = c->ref_c;
    const wb_real r0 = y[0] - cc[0], r1 = y[1] - cc[1], r2 = y[2] - cc[2];
    out[0] = s * (V[0] + om[1] * r2 - om[2] * r1);
    out[1] = s * (V[1] + om[2] * r0 - om[0] * r2);
    out[2] = s * (V[2] + om[0] * r1 - om[1] * r0);
}

/* u = the particle's velocity less the reference's at y (an immovable particle: 0, it
 * stays) after the substeps of rs */
static inline void ref_rel(const wb_contacts *c, const ref_step *rs, const wb_real *y, const wb_real *v, int movable,
                           wb_real u[3])
{
    wb_real q[3];
    ref_vel(c, rs->vf, y, q);
    for (int a = 0; a < 3; a++) u[a] = (movable ? v[a] : 0) - q[a];
}

static void keep_reference(wb_contacts *c, const double V[3], const double om[3], const double cc[3])
{
    for (int a = 0; a < 3; a++) c->ref_v[a] = (wb_real)V[a], c->ref_om[a] = (wb_real)om[a], c->ref_c[a] = (wb_real)cc[a];
}

#ifdef WB_SIMD_H_AVX2
/* lanes (1, 2, 0) and (2, 0, 1) of a 3-vector: its cross products */
#define YZX(a) _mm256_permute4x64_pd(a, 0xC9)
#define ZXY(a) _mm256_permute4x64_pd(a, 0xD2)

/* fit_reference with a particle's x, y, z as the lanes of one vector, each lane the scalar
 * code's operations in its order (no fused multiply-adds): the same bits. Its last pass
 * works out each candidate's velocity from the reference either way (fitted or standing
 * still) and leaves the one kept in reach, as make_list's ref_rel and v3_len_fast would
 * (1; 0: not done, make_list does it). c->spd: scratch */
static __attribute__((target("avx2"))) int fit_reference_avx2(wb_world *w, wb_real *reach, wb_real t)
{
    wb_contacts *c = w->k.pc;
    const wb_model *m = &w->m;
    const wb_real *x = w->s.x, *v = w->s.v, *wv = m->w;
    const int32_t np = m->np;
    double M = 0;
    __m256d mx = _mm256_setzero_pd(), mv = mx;
    for (int32_t i = 0; i < np; i++) {
        if (reach[i] < 0 || !(wv[i] > 0)) continue;
        const double mi = 1 / (double)wv[i];
        const __m256d vm = _mm256_set1_pd(mi);
        M += mi;
        mx = _mm256_add_pd(mx, _mm256_mul_pd(vm, wb__load3(&x[3 * i])));
        mv = _mm256_add_pd(mv, _mm256_mul_pd(vm, wb__load3(&v[3 * i])));
    }
    if (!(M > 0) || !isfinite(M)) return 0;
    const __m256d vM = _mm256_set1_pd(M), vcc = _mm256_div_pd(mx, vM), vV = _mm256_div_pd(mv, vM);
    double cc[4], V[4];
    _mm256_storeu_pd(cc, vcc);
    _mm256_storeu_pd(V, vV);
    /* L, and sum m r r^T as its diagonal (xx yy zz) and (xy xz yz) */
    __m256d L = _mm256_setzero_pd(), Id = L, Io = L;
    for (int32_t i = 0; i < np; i++) {
        if (reach[i] < 0 || !(wv[i] > 0)) continue;
        const double mi = 1 / (double)wv[i];
        const __m256d vm = _mm256_set1_pd(mi);
        const __m256d r = _mm256_sub_pd(wb__load3(&x[3 * i]), vcc), u = _mm256_sub_pd(wb__load3(&v[3 * i]), vV);
        L = _mm256_add_pd(L, _mm256_mul_pd(vm, _mm256_sub_pd(_mm256_mul_pd(YZX(r), ZXY(u)), _mm256_mul_pd(ZXY(r), YZX(u)))));
        const __m256d mr = _mm256_mul_pd(vm, r);
        Id = _mm256_add_pd(Id, _mm256_mul_pd(mr, r));
        /* (mi r0) r1, (mi r0) r2, (mi r1) r2 */
        Io = _mm256_add_pd(Io, _mm256_mul_pd(_mm256_permute4x64_pd(mr, 0x10), _mm256_permute4x64_pd(r, 0x29)));
    }
    double Lv[4], Ia[4], Ib[4], om[3];
    _mm256_storeu_pd(Lv, L);
    _mm256_storeu_pd(Ia, Id);
    _mm256_storeu_pd(Ib, Io);
    const double I[6] = { Ia[0], Ia[1], Ia[2], Ib[0], Ib[1], Ib[2] };
    wb__turn_rate(I, Lv, om);
    if (!(isfinite(V[0] + V[1] + V[2] + om[0] + om[1] + om[2] + cc[0] + cc[1] + cc[2]))) return 0;
    wb_real *spd = wb__grow(c->spd, &c->cap_spd, 2 * (int64_t)np, sizeof *spd);
    if (spd) c->spd = spd;
    int odd = !spd; /* some speed not worked out here: make_list's pass does them all */
    const __m256d vom = _mm256_set_pd(0, om[2], om[1], om[0]), zero = _mm256_setzero_pd();
    const __m256d omy = YZX(vom), omz = ZXY(vom);
    double with = 0, without = 0;
    for (int32_t i = 0; i < np; i++) {
        if (reach[i] < 0) continue;
        const __m256d xi = wb__load3(&x[3 * i]), r = _mm256_sub_pd(xi, vcc);
        const int mov = wv[i] > 0;
        const __m256d vi = mov ? wb__load3(&v[3 * i]) : zero;
        /* V + om x r as V[0] + om[1] r[2] - om[2] r[1], ... */
        const __m256d u = _mm256_sub_pd(vi, _mm256_sub_pd(_mm256_add_pd(vV, _mm256_mul_pd(omy, ZXY(r))),
                                                          _mm256_mul_pd(omz, YZX(r))));
        const double uu = hsum3(_mm256_mul_pd(u, u)), vv = hsum3(_mm256_mul_pd(vi, vi));
        const double r0 = 1.25 * m->radius[i], a = r0 + sqrt(uu) * t, b = r0 + (mov ? sqrt(vv) : 0) * t;
        with += a * a * a;
        without += b * b * b;
        if (odd) continue;
        /* v3_len_fast of u (fitted), of the velocity (standing still: r = x exactly, so
         * u = v - (0 + 0 r2 - 0 r1) = v while x is finite) */
        if (!(uu < 1e300) || !(vv < 1e300) || !isfinite(x[3 * i] + x[3 * i + 1] + x[3 * i + 2])) {
            odd = 1;
            continue;
        }
        spd[2 * i] = sqrt(uu);
        spd[2 * i + 1] = sqrt(vv);
    }
    const int keep = with < (double)0.25 * without;
    if (keep) keep_reference(c, V, om, cc);
    if (odd) return 0;
    for (int32_t i = 0; i < np; i++)
        if (reach[i] >= 0) reach[i] = spd[2 * i + !keep];
    return 1;
}
#undef YZX
#undef ZXY
#endif

/* the reference fitted to the candidates (reach >= 0) at x with velocities v; kept only
 * where it shrinks the volume their reaches search (below). 1 when it also left each
 * candidate's speed from the reference in reach (its AVX2 form) */
static int fit_reference(wb_world *w, wb_real *reach, wb_real t)
{
    wb_contacts *c = w->k.pc;
    const wb_model *m = &w->m;
    const wb_real *x = w->s.x, *v = w->s.v, *wv = m->w;
    for (int a = 0; a < 3; a++) c->ref_v[a] = c->ref_om[a] = c->ref_c[a] = 0;
#ifdef WB_SIMD_H_AVX2
    if (!w->k.no_simd && __builtin_cpu_supports("avx2")) return fit_reference_avx2(w, reach, t);
#endif
    double M = 0, mx[3] = { 0, 0, 0 }, mv[3] = { 0, 0, 0 };
    for (int32_t i = 0; i < m->np; i++) {
        if (reach[i] < 0 || !(wv[i] > 0)) continue;
        const double mi = 1 / (double)wv[i];
        M += mi;
        for (int a = 0; a < 3; a++) mx[a] += mi * x[3 * i + a], mv[a] += mi * v[3 * i + a];
    }
    if (!(M > 0) || !isfinite(M)) return 0;
    const double cc[3] = { mx[0] / M, mx[1] / M, mx[2] / M }, V[3] = { mv[0] / M, mv[1] / M, mv[2] / M };
    double L[3] = { 0, 0, 0 }, I[6] = { 0, 0, 0, 0, 0, 0 }; /* sum m r r^T: xx yy zz xy xz yz */
    for (int32_t i = 0; i < m->np; i++) {
        if (reach[i] < 0 || !(wv[i] > 0)) continue;
        const double mi = 1 / (double)wv[i];
        const double r[3] = { x[3 * i] - cc[0], x[3 * i + 1] - cc[1], x[3 * i + 2] - cc[2] };
        const double u[3] = { v[3 * i] - V[0], v[3 * i + 1] - V[1], v[3 * i + 2] - V[2] };
        L[0] += mi * (r[1] * u[2] - r[2] * u[1]);
        L[1] += mi * (r[2] * u[0] - r[0] * u[2]);
        L[2] += mi * (r[0] * u[1] - r[1] * u[0]);
        I[0] += mi * r[0] * r[0], I[1] += mi * r[1] * r[1], I[2] += mi * r[2] * r[2];
        I[3] += mi * r[0] * r[1], I[4] += mi * r[0] * r[2], I[5] += mi * r[1] * r[2];
    }
    double om[3];
    wb__turn_rate(I, L, om);
    if (!(isfinite(V[0] + V[1] + V[2] + om[0] + om[1] + om[2] + cc[0] + cc[1] + cc[2]))) return 0;
    /* what the search costs with the fit and without: the sum of the reaches' cubes (the
     * volume each one searches; a few large reaches cost more than their sum says), an
     * immovable particle's counting how far the reference leaves it */
    double with = 0, without = 0;
    for (int32_t i = 0; i < m->np; i++) {
        if (reach[i] < 0) continue;
        const wb_real *xi = &x[3 * i];
        const double r[3] = { xi[0] - cc[0], xi[1] - cc[1], xi[2] - cc[2] };
        const int mov = wv[i] > 0;
        double u[3];
        u[0] = (mov ? v[3 * i] : 0) - (V[0] + om[1] * r[2] - om[2] * r[1]);
        u[1] = (mov ? v[3 * i + 1] : 0) - (V[1] + om[2] * r[0] - om[0] * r[2]);
        u[2] = (mov ? v[3 * i + 2] : 0) - (V[2] + om[0] * r[1] - om[1] * r[0]);
        const double r0 = 1.25 * m->radius[i], a = r0 + sqrt(u[0] * u[0] + u[1] * u[1] + u[2] * u[2]) * t,
                     b = r0 + (mov ? v3_len(&v[3 * i]) : 0) * t;
        with += a * a * a;
        without += b * b * b;
    }
    /* kept where it cuts that to a quarter or less: a marginal fit costs more than it saves
     * (measured: a cloth heap where only part still falls, 124 -> 146 ms a frame with the
     * fit kept whenever it was smaller at all; 0.1 threw away half of a hand-built
     * sheet's gain) */
    if (with < (double)0.25 * without) keep_reference(c, V, om, cc);
    return 0;
}

/* Straight paths. Each particle is also checked against the straight line its velocity
 * takes it on from the list's start, p_i(s) = y_i + S u_i (S as above: what the substeps'
 * drag leaves of the time), within eps_i, the part of its reach that is not velocity (its
 * margin and gravity). That implies the reference check: p_i(s) - Phi_s(y_i) =
 * S (u_i - Psi(y_i)), no longer than |u_i - Psi(y_i)| t, the velocity's part of the
 * reach. And two particles within their paths' allowances are at least
 * min_s |p_i(s) - p_j(s)| - eps_i - eps_j apart: a pair of the search whose paths never
 * come within r_i + r_j + eps_i + eps_j over the list's time cannot touch, and is left out
 * of the list (a swinging or falling cloth: neighbours move alike, so only the pairs
 * that close in on each other are projected). p_i - p_j is linear in S: its least length
 * over S in [0, t] in closed form */
static inline int paths_meet(const wb_contacts *c, const wb_real *rad, int32_t i, int32_t j)
{
    const wb_real *P = &c->path[8 * i], *Q = &c->path[8 * j];
    const wb_real d0 = Q[0] - P[0], d1 = Q[1] - P[1], d2 = Q[2] - P[2];
    const wb_real q0 = Q[4] - P[4], q1 = Q[5] - P[5], q2 = Q[6] - P[6];
    const wb_real qq = q0 * q0 + q1 * q1 + q2 * q2, dq = d0 * q0 + d1 * q1 + d2 * q2;
    wb_real S = 0;
    if (dq < 0 && qq > 0) S = -dq < c->path_t * qq ? -dq / qq : c->path_t;
    const wb_real e0 = d0 + S * q0, e1 = d1 + S * q1, e2 = d2 + S * q2, R = rad[i] + rad[j] + P[3] + Q[3];
    return !(e0 * e0 + e1 * e1 + e2 * e2 >= R * R);
}

/* particle i's straight path from y with velocity u, allowance eps */
static inline void set_path(wb_contacts *c, int32_t i, const wb_real *y, const wb_real *u, wb_real eps)
{
    wb_real *P = &c->path[8 * i];
    v3_copy(P, y);
    P[3] = eps;
    v3_copy(&P[4], u);
    P[7] = 0;
}

/* the list's pairs whose paths meet stay in it, in its order; the others are dormant,
 * found by either particle through dorm_row. Every particle starts on its path. 0 when
 * out of memory */
static int split_dormant(wb_contacts *c, const wb_model *m, int32_t r)
{
    const int32_t np = m->np;
    if (!grow((void **)&c->dorm, &c->cap_dorm, 2 * (int64_t)(r > 0 ? r : 1), sizeof *c->dorm) ||
        !grow((void **)&c->dorm_row, &c->cap_dorm_row, (int64_t)np + 1, sizeof *c->dorm_row) ||
        !grow((void **)&c->off_path, &c->cap_off_path, np, sizeof *c->off_path))
        return 0;
    int32_t *ij = c->ij, *d = c->dorm, n = 0, nd = 0;
    for (int32_t k = 0; k < r; k++) {
        const int32_t i = ij[2 * k], j = ij[2 * k + 1];
        int32_t *o = paths_meet(c, m->radius, i, j) ? &ij[2 * n++] : &d[2 * nd++];
        o[0] = i;
        o[1] = j;
    }
    c->n = n;
    c->nd = nd;
    memset(c->off_path, 0, (size_t)np);
    if (!grow((void **)&c->dorm_at, &c->cap_dorm_at, 2 * (int64_t)(nd > 0 ? nd : 1), sizeof *c->dorm_at) ||
        !grow((void **)&c->dorm_on, &c->cap_dorm_on, nd > 0 ? nd : 1, sizeof *c->dorm_on))
        return 0;
    int32_t *row = c->dorm_row;
    memset(row, 0, sizeof *row * ((size_t)np + 1));
    if (nd == 0) return 1; /* (every row empty) */
    for (int32_t q = 0; q < 2 * nd; q++) row[d[q] + 1]++;
    for (int32_t i = 0; i < np; i++) row[i + 1] += row[i];
    for (int32_t q = 0; q < nd; q++) {
        c->dorm_at[row[d[2 * q]]++] = q;
        c->dorm_at[row[d[2 * q + 1]]++] = q;
    }
    for (int32_t i = np; i > 0; i--) row[i] = row[i - 1];
    row[0] = 0;
    memset(c->dorm_on, 0, (size_t)nd);
    return 1;
}

/* How many substeps one list covers: the frame's, or half of them where the particles get
 * more than SPAN_R radii farther than their radii from the reference motion in a frame
 * (the mean of (|u| dt + |g| dt^2) / r). A list's reaches grow with that and the pairs it
 * holds with their square on a sheet, their cube in a heap, so where it is large two
 * lists of half the span cost less than one; where it is small the second list is the
 * grid, the reference and the paths made again for little. Measured with callgrind
 * (instructions; docs/benchmark.md) with one, two or three lists in every frame: a 128 x
 * 128 cloth swinging from two corners, 60 frames, 15.67 / 11.79 G (and 11.88 G with one
 * list below a radius of motion, two to 2 radii, three above); a 64 x 64 cloth falling
 * into a heap 6.33 / 4.81 / 4.87 G; 27
 * soft blocks falling into a box (the contacts bench, radii of 8 cm) 4.50 / 4.65 G. From
 * the state alone (the velocities and the reference), so a step run again makes the same
 * lists. */
#define SPAN_R 0.5
static int32_t list_span(int32_t substeps, double motion)
{
    return motion > SPAN_R && substeps >= 6 ? (substeps + 1) / 2 : substeps;
}

/* the candidate list for the next substeps of h, at most kmax (k0 substeps into the
 * frame; list_span picks how many) from where the particles are: each one's reach is how
 * far it can get from the reference motion in that time, plus a quarter of its radius for
 * what the constraints move it (margin times its radius for the particles that left their
 * reach earlier in the frame); kept in c->xf for the substeps' checks. Sets
 * c->span at a frame's start. Returns the pairs, or -1 when out of memory */
static int32_t make_list(wb_world *w, wb_real h, int32_t kmax, wb_real margin, int32_t k0)
{
    wb_model *m = &w->m;
    wb_contacts *c = w->k.pc;
    c->check = 0;
    c->nfixed = 0; /* every particle's xf and reach from here */
    wb_real *reach = wb__grow(c->reach, &c->cap_reach, m->np, sizeof *reach);
    if (reach) c->reach = reach;
    int32_t *skip = wb__grow(c->skip, &c->cap_skip, m->np, sizeof *skip);
    if (skip) c->skip = skip;
    wb_real *xf = wb__grow(c->xf, &c->cap_xf, 3 * m->np, sizeof *xf);
    if (xf) c->xf = xf;
    wb_real *path = wb__grow(c->path, &c->cap_path, 8 * m->np, sizeof *path);
    if (path) c->path = path;
    uint8_t *grown = wb__grow(c->grown, &c->cap_grown, m->np, sizeof *grown);
    if (grown) c->grown = grown;
    if (!reach || !skip || !xf || !path || !grown) return -1;
    if (k0 == 0) memset(grown, 0, (size_t)m->np);
    const wb_real *v = w->s.v;
    for (int32_t i = 0; i < m->np; i++) {
        const uint8_t f = m->cflags[i];
        const int32_t gi = m->group[i];
        /* may_touch's rules: other bodies need `collide`, its own body `self_collide` */
        reach[i] = (f & WB_CF_COLLIDE) || (gi > 0 && (f & WB_CF_SELF)) ? 0 : -1;
        skip[i] = gi > 0 && !(f & WB_CF_SELF) ? gi : 0;
    }
    const int have = fit_reference(w, reach, h * kmax);
    c->ref_k0 = k0;
    const ref_step rs0 = { 0, 1 };
    /* each candidate's speed from the reference (in reach for now), and their mean motion
     * over kmax substeps in radii, for the span */
    double motion = 0;
    int32_t nmov = 0; /* (the span is the frame's: worked out at its start) */
    const wb_real g = v3_len(m->def.gravity);
    for (int32_t i = 0; i < m->np; i++) {
        if (reach[i] < 0) continue;
        if (!have) {
            wb_real u[3];
            ref_rel(c, &rs0, &w->s.x[3 * i], &v[3 * i], m->w[i] > 0, u);
            reach[i] = v3_len_fast(u);
        }
        if (k0 == 0 && m->radius[i] > 0) /* (a remake within the frame keeps its span) */
            motion += (reach[i] * h * kmax + g * h * h * kmax * kmax) / m->radius[i], nmov++;
    }
    if (k0 == 0) c->span = list_span(kmax, nmov > 0 ? motion / nmov : 0);
    const int32_t span = k0 == 0 ? c->span : kmax;
    const wb_real t = h * span, gt2 = g * t * t;
    c->path_t = t;
    static const wb_real still[3] = { 0, 0, 0 };
    for (int32_t i = 0; i < m->np; i++) {
        if (reach[i] < 0) continue;
        const wb_real *p = &w->s.x[3 * i], eps = m->radius[i] * (grown[i] ? margin : (wb_real)0.25) + gt2;
        const int movable = m->w[i] > 0;
        reach[i] = m->radius[i] + eps + reach[i] * t;
        if (!isfinite(reach[i] + p[0] + p[1] + p[2])) reach[i] = -1;
        set_path(c, i, p, movable ? &v[3 * i] : still, eps);
    }
    memcpy(xf, w->s.x, sizeof *xf * 3 * (size_t)m->np);
    c->n = 0;
    c->no_simd = w->k.no_simd;
    int32_t r = wb__broadphase_kept(c, w->s.x, reach, skip, m->np, wb__world_pool(w), may_touch_rules, c->rules_gen,
                                    movable_pair, w);
    if (r >= 0 && !split_dormant(c, m, r)) r = -1;
    c->check = r >= 0;
    return r;
}

void wb__broadphase_free(wb_contacts *c)
{
    wb_broad *b = c->bp;
    free(c->skip);
    c->skip = NULL;
    c->cap_skip = 0;
    free(c->key_row); free(c->path); free(c->dorm); free(c->dorm_row); free(c->dorm_at); free(c->dorm_on);
    free(c->off_path); free(c->soft); free(c->qs); free(c->near2); free(c->far2); free(c->grown); free(c->spd);
    c->spd = NULL;
    c->cap_spd = 0;
    c->grown = NULL;
    c->cap_grown = 0;
    c->near2 = c->far2 = NULL;
    c->cap_near2 = c->cap_far2 = 0;
    c->key_row = c->dorm = c->dorm_row = c->dorm_at = c->soft = c->qs = NULL;
    c->cap_qs = 0;
    c->path = NULL;
    c->dorm_on = c->off_path = NULL;
    c->cap_key_row = c->cap_path = c->cap_dorm = c->cap_dorm_row = c->cap_dorm_at = c->cap_dorm_on = 0;
    c->cap_off_path = c->cap_soft = 0;
    c->nd = 0;
    free(c->xf); free(c->ij_old); free(c->left_old); free(c->fix); free(c->add); free(c->fixed);
    c->xf = c->left_old = NULL;
    c->ij_old = c->fix = c->add = c->fixed = NULL;
    c->cap_xf = c->cap_old = c->cap_left_old = c->cap_fix = c->cap_add = c->cap_fixed = 0;
    if (!b) return;
    free(b->cand); free(b->cell); free(b->start); free(b->p); free(b->id); free(b->key);
    free(b->runs); free(b->boxes); free(b->first); free(b->by_j); free(b->cnt); free(b->rowr);
    free(b->vx); free(b->vr); free(b->vskip); free(b->list.ij); free(b->list.hit);
    free(b->moved); free(b->is_moved); free(b->bad); free(b->mend.ij); free(b->mend.hit);
    free(b->half); free(b->hot);
    for (int t = 0; t < b->nout; t++) free(b->out[t].ij), free(b->out[t].hit);
    free(b->out);
    free(b);
    c->bp = NULL;
}

void wb__contacts_begin(wb_world *w)
{
    wb_model *m = &w->m;
    wb_contacts *c = w->k.pc;
    c->n = 0;
    c->nact = 0;
    c->last = 0;
    c->fresh = 1;
    c->broad_ms = 0;
    c->check = 0;
    c->sub = 0;
    c->span = m->def.substeps;
    c->remakes_frame = 0;
    if (!m->def.contacts || m->np < 2) return;
    if (!wb__contact_rules(w)) {
        c->possible = 0; /* the triangles' broad phase asks the same rules */
        wb__warn(w, "out of memory in the contact broad phase; contacts skipped");
        return;
    }
    if (c->scan_dirty || c->scanned_np != m->np) {
        c->possible = any_possible(m);
        c->scanned_np = m->np;
        c->scan_dirty = 0;
    }
    if (!c->possible) return;
    const double t0 = now_ms();
    if (make_list(w, m->def.dt / m->def.substeps, m->def.substeps, (wb_real)0.25, 0) < 0) {
        c->n = 0;
        wb__warn(w, "out of memory in the contact broad phase; contacts skipped");
    }
    c->broad_ms = now_ms() - t0;
}

/* The reach assumes each particle moves at most a quarter of its radius farther than its
 * velocity and gravity carry it; a link yanking a particle (a stiff cloth landing, a
 * whip) can move it farther, and a pair the list lacks could pass through each other.
 * So each substep checks every particle against that, and one that moved farther (the
 * list would then be missing pairs) has the list made again from where the particles
 * are, for the rest of the frame. */
/* A particle that moved too far: its reach made again from where it is, for the rest of
 * the frame t, and its pairs looked for among every particle's frame bounds: one within
 * its reach stays within reach_j - r_j of xf_j, so one it could touch is within
 * reach_i + reach_j of it. The kept list's grid finds them: xf_j is within R_j - reach_j
 * of where the grid has j (the list held, or was made, at xf), so they are within
 * reach_i + R_j of the grid's j. Particles mended earlier in the frame (their xf and
 * reach changed) are tried one by one, and every particle when the grid lacks some (its
 * bodies culled) or would be searched too widely. The new pairs are merged into the
 * list. Returns 0 when out of memory */
#define REPAIR_MAX 1024

static int add_pair(wb_world *w, int32_t i, int32_t j, int32_t *na)
{
    wb_contacts *c = w->k.pc;
    const wb_real *xf = c->xf, *reach = c->reach, *p = &xf[3 * i];
    if (j == i || reach[j] < 0) return 1;
    const wb_real d0 = xf[3 * j] - p[0], d1 = xf[3 * j + 1] - p[1], d2 = xf[3 * j + 2] - p[2];
    const wb_real R = reach[i] + reach[j];
    if (!(d0 * d0 + d1 * d1 + d2 * d2 < R * R)) return 1;
    const int32_t a = i < j ? i : j, b = i < j ? j : i;
    if (c->skip[a] != 0 && c->skip[a] == c->skip[b]) return 1;
    if (!may_touch(w, a, b)) return 1;
    if (!grow((void **)&c->add, &c->cap_add, 2 * ((int64_t)*na + 1), sizeof *c->add)) return 0;
    c->add[2 * *na] = a;
    c->add[2 * *na + 1] = b;
    (*na)++;
    return 1;
}

typedef struct add_ctx { wb_world *w; int32_t i; int32_t *na; } add_ctx;

static int add_grid(void *ctx, int32_t j)
{
    const add_ctx *a = ctx;
    return add_pair(a->w, a->i, j, a->na);
}

/* the grid's particles within e of p, through add_pair; 0: too wide a search (or out of
 * memory: *fail) */
static int grid_pairs(wb_world *w, const wb_broad *b, int32_t i, wb_real e, int32_t *na, int *fail)
{
    const wb_grid *G = &b->lg;
    /* the grid holds the list's positions X: where M^-1 takes xf_i (each xf_j is within
     * its skin of M(X_j)) */
    const wb_real *xi = &w->k.pc->xf[3 * i], *Q = b->mo.Q;
    const wb_real r0 = xi[0] - b->mo.c[0], r1 = xi[1] - b->mo.c[1], r2 = xi[2] - b->mo.c[2];
    wb_real p[3];
    for (int a = 0; a < 3; a++) p[a] = b->mo.C[a] + Q[a] * r0 + Q[3 + a] * r1 + Q[6 + a] * r2;
    if (!(e * G->inv <= 8)) return 0;
    add_ctx ac = { w, i, na };
    if (!grid_each(b, p, e, add_grid, &ac)) *fail = 1;
    return 1;
}

static int repair(wb_world *w, const int32_t *moved, int32_t nm, const int32_t *soft, int32_t ns, wb_real t,
                  wb_real margin, const ref_step *rs)
{
    wb_model *m = &w->m;
    wb_contacts *c = w->k.pc;
    const wb_broad *b = c->bp;
    wb_real *xf = c->xf, *reach = c->reach;
    const wb_real *x = w->s.x, *v = w->s.v, gt2 = v3_len(m->def.gravity) * t * t;
    const wb_real *V = c->ref_v, *om = c->ref_om, *cc = c->ref_c;
    /* (I + S [om]x)^-1 b = (b - a x b + (a . b) a) / (1 + |a|^2), a = S om */
    const wb_real a[3] = { rs->S * om[0], rs->S * om[1], rs->S * om[2] }, aa = 1 + v3_dot(a, a);
    /* the particles mended this frame: these and the earlier ones */
    if (!grow((void **)&c->fixed, &c->cap_fixed, (int64_t)c->nfixed + nm, sizeof *c->fixed)) return 0;
    for (int32_t k = 0; k < nm; k++) {
        const int32_t i = moved[k];
        const wb_real *p = &x[3 * i];
        /* where the reference motion takes to where it is now (its deviation restarts at
         * 0), and its reach from there for the rest of the frame */
        wb_real bb[3], axb[3], y[3], u[3];
        for (int e = 0; e < 3; e++) bb[e] = p[e] - cc[e] - rs->S * V[e];
        v3_cross(axb, a, bb);
        const wb_real ab = v3_dot(a, bb);
        for (int e = 0; e < 3; e++) y[e] = cc[e] + (bb[e] - axb[e] + ab * a[e]) / aa;
        v3_copy(&xf[3 * i], y);
        ref_rel(c, rs, y, &v[3 * i], m->w[i] > 0, u);
        const wb_real eps = m->radius[i] * margin + gt2, r = m->radius[i] + eps + v3_len_fast(u) * t;
        reach[i] = isfinite(r + y[0] + y[1] + y[2]) ? r : -1;
        c->fixed[c->nfixed++] = i;
        /* its pairs are all searched for again: its dormant ones are no longer */
        c->off_path[i] = 1;
        for (int32_t q = c->dorm_row[i]; q < c->dorm_row[i + 1]; q++) c->dorm_on[c->dorm_at[q]] = 1;
    }
    const int use_grid = b && b->lgrid && b->lfull && b->vn == m->np;
    int32_t na = 0;
    int fail = 0;
    for (int32_t k = 0; k < nm && !fail; k++) {
        const int32_t i = moved[k];
        if (reach[i] < 0) continue;
        if (use_grid && grid_pairs(w, b, i, reach[i] + b->lrmax, &na, &fail)) {
            for (int32_t q = 0; q < c->nfixed && !fail; q++) fail = !add_pair(w, i, c->fixed[q], &na);
            for (int32_t q = 0; q < b->nmoved && !fail; q++) fail = !add_pair(w, i, b->moved[q], &na);
            continue;
        }
        for (int32_t j = 0; j < m->np && !fail; j++) fail = !add_pair(w, i, j, &na);
    }
    if (fail) return 0;
    /* a particle off its path but within its reach: its dormant pairs listed again (none
     * is listed yet: a mended particle's are no longer dormant), and from here on it is
     * checked against the reference alone */
    int32_t nq = 0;
    for (int32_t k = 0; k < ns; k++) {
        const int32_t i = soft[k];
        c->off_path[i] = 1;
        for (int32_t a = c->dorm_row[i]; a < c->dorm_row[i + 1]; a++) {
            const int32_t q = c->dorm_at[a];
            if (c->dorm_on[q]) continue;
            c->dorm_on[q] = 2; /* new in this call */
            if (!grow((void **)&c->qs, &c->cap_qs, (int64_t)nq + 1, sizeof *c->qs)) return 0;
            c->qs[nq++] = q;
        }
    }
    /* in order: sorted, or when they are many, read off the marks in order */
    if ((int64_t)nq * 16 > c->nd) {
        nq = 0;
        for (int32_t q = 0; q < c->nd; q++)
            if (c->dorm_on[q] == 2) c->qs[nq++] = q;
    } else if (nq > 1) qsort(c->qs, (size_t)nq, sizeof *c->qs, cmp_i32);
    for (int32_t k = 0; k < nq; k++) c->dorm_on[c->qs[k]] = 1;
    if (na == 0 && nq == 0) return 1;
    /* the new pairs in order, each once and not already listed */
    int32_t nb = new_pairs(c->bp, m->np, c->add, na, c->ij, c->n);
    /* with the dormant ones, in order as the dormant list is (merged from the back) */
    if (!grow((void **)&c->add, &c->cap_add, 2 * ((int64_t)nb + nq), sizeof *c->add)) return 0;
    for (int32_t o = nb + nq - 1, p = nb - 1, q = nq - 1; q >= 0; o--) {
        const int32_t *d = &c->dorm[2 * c->qs[q]];
        if (p >= 0 && cmp_pair(&c->add[2 * p], d) > 0) {
            c->add[2 * o] = c->add[2 * p];
            c->add[2 * o + 1] = c->add[2 * p + 1];
            p--;
        } else {
            c->add[2 * o] = d[0];
            c->add[2 * o + 1] = d[1];
            q--;
        }
    }
    nb += nq;
    if (nb == 0) return 1;
    /* merged from the back into the list, and what each pair was left with along with
     * it (a new pair: NaN, worked out by contact.c) */
    const int have_left = !c->fresh && c->left && c->cap_left >= c->n;
    if (!grow((void **)&c->ij, &c->cap, 2 * ((int64_t)c->n + nb), sizeof *c->ij)) return 0;
    if (have_left && !grow((void **)&c->left, &c->cap_left, (int64_t)c->n + nb, sizeof *c->left)) return 0;
    int32_t *ij = c->ij, p = c->n - 1, q = nb - 1, o = c->n + nb - 1;
    for (; q >= 0; o--) {
        if (p >= 0 && cmp_pair(&ij[2 * p], &c->add[2 * q]) > 0) {
            ij[2 * o] = ij[2 * p];
            ij[2 * o + 1] = ij[2 * p + 1];
            if (have_left) c->left[o] = c->left[p];
            p--;
        } else {
            ij[2 * o] = c->add[2 * q];
            ij[2 * o + 1] = c->add[2 * q + 1];
            if (have_left) c->left[o] = NAN;
            q--;
        }
    }
    c->n += nb;
    return 1;
}

/* particle i is farther from where the reference motion takes xf_i than its reach
 * allows (a reach < 0 is no candidate; a position gone non-finite fails and is left out) */
/* 0: particle i is within eps_i of its path (or, off its path, within reach_i - r_i of
 * where the reference motion takes xf_i); 1: off its path but within that; 2: farther
 * (a reach < 0 is no candidate: 0; a position gone non-finite: 2) */
static inline int strays(const wb_contacts *c, const wb_real *x, const wb_real *rad, const ref_step *rs, int32_t i)
{
    if (c->reach[i] < 0) return 0;
    const wb_real *P = &c->path[8 * i], *p = &x[3 * i];
    if (!c->off_path[i]) {
        const wb_real d0 = p[0] - P[0] - rs->S * P[4], d1 = p[1] - P[1] - rs->S * P[5], d2 = p[2] - P[2] - rs->S * P[6];
        if (d0 * d0 + d1 * d1 + d2 * d2 <= P[3] * P[3]) return 0;
    }
    const wb_real e = c->reach[i] - rad[i], *y = &c->xf[3 * i];
    wb_real mv[3];
    ref_vel(c, rs->S, y, mv);
    const wb_real d0 = p[0] - y[0] - mv[0], d1 = p[1] - y[1] - mv[1], d2 = p[2] - y[2] - mv[2];
    if (d0 * d0 + d1 * d1 + d2 * d2 <= e * e) return !c->off_path[i];
    return 2;
}

/* a particle into the substep's lists by what strays says of it: off its path (soft), past
 * its reach (mv: counted past REPAIR_MAX, kept up to it) */
static inline void sort_stray(int k, int32_t i, int32_t *soft, int32_t *ns, int32_t *mv, int32_t *nm, uint8_t *grown)
{
    if (k == 1) soft[(*ns)++] = i;
    else if (k == 2) {
        if (*nm < REPAIR_MAX) mv[*nm] = i;
        (*nm)++;
        grown[i] = 1;
    }
}

#ifdef WB_SIMD_H_AVX2
/* rows r0..r3 of 4 doubles into columns c0..c3 */
static inline __attribute__((always_inline, target("avx2"))) void
wb__transpose4x4(__m256d r0, __m256d r1, __m256d r2, __m256d r3, __m256d *c0, __m256d *c1, __m256d *c2, __m256d *c3)
{
    const __m256d t0 = _mm256_unpacklo_pd(r0, r1), t1 = _mm256_unpackhi_pd(r0, r1);
    const __m256d t2 = _mm256_unpacklo_pd(r2, r3), t3 = _mm256_unpackhi_pd(r2, r3);
    *c0 = _mm256_permute2f128_pd(t0, t2, 0x20);
    *c1 = _mm256_permute2f128_pd(t1, t3, 0x20);
    *c2 = _mm256_permute2f128_pd(t0, t2, 0x31);
    *c3 = _mm256_permute2f128_pd(t1, t3, 0x31);
}

/* The same pass with strays' first test (on its path) in AVX2: each particle's path as two
 * vectors, (y, eps) and (u, 0), and its position as (x, 0), so that lane 3 of the deviation
 * is -eps; the same operations in the same order as the scalar test (no fused
 * multiply-adds), so the same decisions to the bit. The rest (off their paths) as
 * strays. Returns the particles found on their paths */
static __attribute__((target("avx2"))) int32_t check_avx2(wb_contacts *c, const wb_real *x,
                                                          const wb_real *rad, const ref_step *rs, int32_t np,
                                                          int32_t *soft, int32_t *ns, int32_t *mv, int32_t *nm)
{
    const __m256d S = _mm256_set1_pd(rs->S);
    /* (in locals: the byte stores of sort_stray may alias anything, and would have every
     * pointer of c loaded again each particle) */
    const wb_real *reach = c->reach, *path = c->path;
    const uint8_t *off = c->off_path;
    uint8_t *grown = c->grown;
    int32_t on = 0, i = 0;
    /* four particles at a time, their coordinates as lanes (the same operations per lane);
     * the lanes not found on their paths (or no candidates, or off their paths) go to
     * strays one by one, in order */
    const __m256d zero = _mm256_setzero_pd();
    for (; i + 4 <= np; i += 4) {
        uint32_t off4;
        memcpy(&off4, &off[i], sizeof off4);
        int go = _mm256_movemask_pd(_mm256_cmp_pd(_mm256_loadu_pd(&reach[i]), zero, _CMP_GE_OQ));
        for (int l = 0; off4 && l < 4; l++)
            if (off[i + l]) go &= ~(1 << l);
        int in = 0;
        if (go) {
            __m256d X, Y, Z, P0, P1, P2, E, U0, U1, U2, U3;
            const wb_real *xi = &x[3 * (size_t)i];
            wb__transpose4(wb__load3(xi), wb__load3(xi + 3), wb__load3(xi + 6), wb__load3(xi + 9), &X, &Y, &Z);
            const wb_real *P = &path[8 * (size_t)i];
            wb__transpose4x4(_mm256_loadu_pd(P), _mm256_loadu_pd(P + 8), _mm256_loadu_pd(P + 16), _mm256_loadu_pd(P + 24),
                             &P0, &P1, &P2, &E);
            wb__transpose4x4(_mm256_loadu_pd(P + 4), _mm256_loadu_pd(P + 12), _mm256_loadu_pd(P + 20),
                             _mm256_loadu_pd(P + 28), &U0, &U1, &U2, &U3);
            const __m256d d0 = _mm256_sub_pd(_mm256_sub_pd(X, P0), _mm256_mul_pd(S, U0));
            const __m256d d1 = _mm256_sub_pd(_mm256_sub_pd(Y, P1), _mm256_mul_pd(S, U1));
            const __m256d d2 = _mm256_sub_pd(_mm256_sub_pd(Z, P2), _mm256_mul_pd(S, U2));
            const __m256d dd = _mm256_add_pd(_mm256_add_pd(_mm256_mul_pd(d0, d0), _mm256_mul_pd(d1, d1)), _mm256_mul_pd(d2, d2));
            in = go & _mm256_movemask_pd(_mm256_cmp_pd(dd, _mm256_mul_pd(E, E), _CMP_LE_OQ));
        }
        if (in == 15) { on += 4; continue; }
        for (int l = 0; l < 4; l++) {
            if (in >> l & 1) { on++; continue; }
            sort_stray(strays(c, x, rad, rs, i + l), i + l, soft, ns, mv, nm, grown);
        }
    }
    for (; i < np; i++) {
        if (reach[i] >= 0 && !off[i]) {
            const wb_real *P = &path[8 * i];
            const __m256d d = _mm256_sub_pd(_mm256_sub_pd(wb__load3(&x[3 * i]), _mm256_loadu_pd(P)),
                                            _mm256_mul_pd(S, _mm256_loadu_pd(P + 4)));
            const __m256d q = _mm256_mul_pd(d, d);
            const __m128d lo = _mm256_castpd256_pd128(q), hi = _mm256_extractf128_pd(q, 1);
            const __m128d dd = _mm_add_sd(_mm_add_sd(lo, _mm_unpackhi_pd(lo, lo)), hi);
            if (_mm_comile_sd(dd, _mm_unpackhi_pd(hi, hi))) { on++; continue; }
        }
        sort_stray(strays(c, x, rad, rs, i), i, soft, ns, mv, nm, grown);
    }
    return on;
}
#endif

int wb__contacts_recheck(wb_world *w, wb_real h)
{
    wb_model *m = &w->m;
    wb_contacts *c = w->k.pc;
    if (!c->check || c->no_recheck) return 0;
    const int32_t sub = c->sub++;
    const wb_real *x = w->s.x;
    /* the substep's prediction is done: sub + 1 of the frame's, sub + 1 - ref_k0 since the
     * list was made */
    const ref_step rs = ref_at(w, sub + 1 - c->ref_k0, h);
    const wb_real *rad = m->radius;
    /* one pass: those off their paths (soft) and those past their reach (mv; counted past
     * REPAIR_MAX, kept up to it) */
    int32_t *soft = wb__grow(c->soft, &c->cap_soft, m->np, sizeof *soft), ns = 0;
    int32_t *mv = wb__grow(c->fix, &c->cap_fix, REPAIR_MAX, sizeof *mv), nm = 0, r;
    if (soft) c->soft = soft;
    if (mv) c->fix = mv;
    if (!soft || !mv) { c->n = 0; c->check = 0; return -1; }
#ifdef WB_SIMD_H_AVX2
    if (!w->k.no_simd && __builtin_cpu_supports("avx2")) c->lanes += check_avx2(c, x, rad, &rs, m->np, soft, &ns, mv, &nm);
    else
#endif
        for (int32_t i = 0; i < m->np; i++) sort_stray(strays(c, x, rad, &rs, i), i, soft, &ns, mv, &nm, c->grown);
    /* a span ends here (list_span): the list for the next */
    const int due = sub > 0 && sub % c->span == 0;
    if (ns == 0 && nm == 0 && !due) return 0;
    const double t0 = now_ms();
    if (nm == 0 && !due) { /* off their paths alone */
        r = repair(w, NULL, 0, soft, ns, 0, 0, &rs);
        c->broad_ms += now_ms() - t0;
        if (!r) { c->n = 0; c->check = 0; return -1; }
        return 2;
    }
    if (!due) {
        c->remakes++;
        c->remakes_frame++;
    }
    /* due: for the next span; else what is left of the frame, this substep included (the
     * constraints moved some particle farther than its margin allowed: the particles that
     * left their reach this frame get a margin that doubles with the frame's remakes, so
     * that a frame makes the list again a few times at most: up to 4 radii for the few a
     * repair mends, up to one radius when the list is made again; the others keep a
     * quarter radius. Grown for every particle at once, the reaches of a heap landing on
     * the floor searched the whole heap: 1.2-2.1 s for one frame of a 128 x 128 cloth) */
    const int32_t kleft = due ? (c->span < m->def.substeps - sub ? c->span : m->def.substeps - sub)
                              : m->def.substeps - sub;
    const wb_real t = (wb_real)kleft * h;
    const int32_t g = c->remakes_frame;
    const wb_real margin = due ? (wb_real)0.25 : (wb_real)0.25 * (wb_real)(1 << (g < 4 ? g : 4));
    if (!due && nm <= REPAIR_MAX) {
        r = repair(w, mv, nm, soft, ns, t, margin, &rs);
        c->broad_ms += now_ms() - t0;
        if (!r) { c->n = 0; c->check = 0; return -1; }
        return 2;
    }
    /* the old list kept for what its pairs were left with */
    int32_t *io = wb__grow(c->ij_old, &c->cap_old, 2 * (c->n > 0 ? c->n : 1), sizeof *io);
    if (!io) { c->n = 0; c->check = 0; return -1; }
    c->ij_old = io;
    if (c->n > 0) memcpy(io, c->ij, sizeof *io * 2 * (size_t)c->n);
    c->n_old = c->n;
    r = make_list(w, h, kleft, due ? margin : (wb_real)0.25 * (wb_real)(1 << (g < 2 ? g : 2)), sub + 1);
    c->broad_ms += now_ms() - t0;
    if (r < 0) { c->n = 0; c->check = 0; return -1; }
    return 1;
}

void wb__contacts_brute(wb_world *w)
{
    const wb_model *m = &w->m;
    wb_contacts *c = w->k.pc;
    const wb_real *x = w->s.x;
    if (!m->def.contacts) return;
    for (int32_t i = 0; i < m->np; i++)
        for (int32_t j = i + 1; j < m->np; j++) {
            wb_real d[3];
            v3_sub(d, &x[3 * j], &x[3 * i]);
            const wb_real r = m->radius[i] + m->radius[j];
            /* (by the keys alone, not made_bounds: a bound too wide would show as a miss) */
            if (!(v3_dot(d, d) < r * r) || !movable_pair(w, i, j) || !rules(w, i, j, 0)) continue;
            int32_t lo = 0, hi = c->n;
            while (lo < hi) {
                const int32_t mid = lo + (hi - lo) / 2, a = c->ij[2 * mid], b = c->ij[2 * mid + 1];
                if (a < i || (a == i && b < j)) lo = mid + 1;
                else hi = mid;
            }
            c->missed += !(lo < c->n && c->ij[2 * lo] == i && c->ij[2 * lo + 1] == j);
        }
}
