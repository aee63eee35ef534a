/* tribroad.c: the broad phase of particle-triangle contacts, once per frame, so that
 * each substep tests only pairs that can meet; tricontact.c projects the candidates it
 * finds every substep.
 *
 * A candidate is a point p and a triangle t such that
 *  - p may collide (reach_p >= 0: radius + a quarter of it + how far velocity and gravity
 *    carry it in a frame) and some corner of t may (mv_t: the most any corner may move,
 *    the same way, without the radius);
 *  - p comes within reach_p of t's box grown by mv_t, within reach_p + mv_t of its plane
 *    and of the triangle itself;
 *  - contact.c's rules let p touch each corner (rules_allow), and, for a point of the
 *    triangle's own body, it did not lie within its radius of the triangle at rest.
 * That set is all that counts: the passes below only decide which pairs are tested.
 *
 *  1. Body culling. A triangle whose corners are of one body that does not collide with
 *     itself has that body as its key; no point of the body may touch it. Points are
 *     keyed by their body. Runs of consecutive points (triangles) of one key, keyless ones
 *     in one catch-all run, get a swept box; a point is kept only if its box (x +- reach)
 *     meets the overlap of its run's box with the box of a triangle run it may touch, and
 *     a triangle likewise (boxes padded by a few ulps: culling never drops a candidate).
 *     Bodies apart, or a body's inside, cost nothing after this pass.
 *  2. Sorted grids of the points kept, as broadphase.c's (row-major counting sort, x
 *     fastest, so a row's cells are one range; wrapping coordinates for a sparse, huge
 *     volume). A few levels by reach: the points up to twice the median reach, then the
 *     same of the rest, ..., the last level takes all that is left; so a few fast points
 *     do not widen every query. Cell: twice the level's median reach.
 *  3. Each kept triangle scans, in each level, the rows its box grown by mv_t and the
 *     level's largest reach covers (a triangle that would scan more rows than the level
 *     has points scans its points instead); a point of its own key is skipped first,
 *     then the exact test. Threads take contiguous ranges of the kept triangles, each
 *     with its own buffer; the pairs are then counting-sorted (stable) by point, and put
 *     in the projection's order (order_as_grid), a function of the positions: the list
 *     is the same for any thread count. */
#include <time.h>
#include <stdio.h>
#include <stdlib.h>

#include "core.h"
#include "broadphase.h"
#include "tricontact.h"

static double now_ms(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return ts.tv_sec * 1e3 + ts.tv_nsec * 1e-6;
}

#define TB 14          /* per triangle: box lo, hi; how far its corners may move; unit normal;
                          its first cell in the projection's order, whether it is big there */
#define RUNS_MAX 256   /* body culling only with at most this many runs of either kind */
#define BOXES_MAX 16   /* a run's overlaps tested one by one up to this many */
#define PAR_MIN 256    /* below this many kept triangles the scan stays on one thread */

typedef struct wb_tribroad_run {
    int32_t key;           /* body; 0 = the catch-all run */
    wb_real lo[3], hi[3];  /* swept box */
    int32_t box0, nbox;    /* its overlaps: boxes[box0 ..], -1: one covers it (keep all) */
} run;

typedef wb_trilevel level;

static int grow(void **p, int32_t *cap, int64_t need, size_t elem)
{
    if (need > INT32_MAX / 2) return 0;
    void *q = wb__grow(*p, cap, (int32_t)(need > 0 ? need : 1), elem);
    if (!q) return 0;
    *p = q;
    return 1;
}

/* ---- who may touch ------------------------------------------------------------------------------ */
/* broadphase.c's pair rule (may_touch) without its rest-neighbour part (applied per
 * triangle below); *same: one body or loose graph */
static int pair_allowed(const wb_model *m, const wb_contacts *c, int32_t p, int32_t v, int *same)
{
    if (wb__graph_of(c, m, p) != wb__graph_of(c, m, v)) return (m->cflags[p] & m->cflags[v] & WB_CF_COLLIDE) != 0;
    *same = 1;
    return m->group[p] == 0 || (m->cflags[p] & m->cflags[v] & WB_CF_SELF) != 0;
}

/* the body no point of which may touch triangle t: its corners' body when that does not
 * collide with itself, or when its spheres cover the triangle (broadphase.c's tcov); else
 * 0 (the search, tri_scan and the quick answer's runs all cull by it: one rule) */
static inline int32_t tri_key(const wb_model *m, const wb_contacts *c, int32_t t)
{
    const int32_t *tv = &m->tri[3 * t], g0 = m->group[tv[0]];
    return g0 > 0 && m->group[tv[1]] == g0 && m->group[tv[2]] == g0 &&
                   (c->tcov[t] || !(m->cflags[tv[0]] & m->cflags[tv[1]] & m->cflags[tv[2]] & WB_CF_SELF))
               ? g0
               : 0;
}

/* the rules without geometry: not its own corner, and each corner allowed; *same: some
 * corner is of the point's own body or graph (the rest rule then applies) */
static int rules_allow(const wb_model *m, const wb_contacts *c, int32_t p, const int32_t *v, int *same)
{
    if (p == v[0] || p == v[1] || p == v[2]) return 0;
    *same = 0;
    for (int k = 0; k < 3; k++)
        if (!pair_allowed(m, c, p, v[k], same)) return 0;
    const wb_real *wv = m->w;
    return wv[p] != 0 || wv[v[0]] != 0 || wv[v[1]] != 0 || wv[v[2]] != 0;
}

/* a constraint joins p to a corner: rest neighbours never touch (asked only where the
 * rules say one may: in one body or graph, or with cross-body links) */
static int joined_corner(const wb_contacts *c, int same, int32_t p, const int32_t *v)
{
    if (!same && !c->cross) return 0;
    return wb__joined(c, p, v[0]) || wb__joined(c, p, v[1]) || wb__joined(c, p, v[2]);
}

/* one body: not a point that lay within its radius of the triangle at rest */
static int rest_apart(const wb_model *m, int32_t p, const int32_t *v)
{
    wb_real bary[3], q[3];
    const wb_real d2 = wb__tri_closest(&m->x0[3 * p], &m->x0[3 * v[0]], &m->x0[3 * v[1]], &m->x0[3 * v[2]], bary, q);
    const wb_real r = m->radius[p] * WB_REST_TOUCH;
    return !(d2 < r * r);
}

static wb_real box_dist2(const wb_real p[3], const wb_real lo[3], const wb_real hi[3])
{
    wb_real s = 0;
    for (int k = 0; k < 3; k++) {
        const wb_real d = p[k] < lo[k] ? lo[k] - p[k] : p[k] > hi[k] ? p[k] - hi[k] : 0;
        s += d * d;
    }
    return s;
}

/* the candidate test itself: point p (reach rp > 0) against triangle t (its record tb) */
static int candidate(const wb_world *w, const wb_real *tb, int32_t t, int32_t p, wb_real rp)
{
    const wb_model *m = &w->m;
    const wb_real *x = w->s.x, reach = rp + tb[6];
    wb_real lo[3], hi[3];
    for (int k = 0; k < 3; k++) lo[k] = tb[k] - tb[6], hi[k] = tb[3 + k] + tb[6];
    if (!(box_dist2(&x[3 * p], lo, hi) < rp * rp)) return 0;
    const int32_t *v = &m->tri[3 * t];
    const wb_contacts *pc = w->k.pc;
    int same;
    if (!rules_allow(m, pc, p, v, &same) || (pc->tcov[t] && m->group[p] == m->group[v[0]])) return 0;
    wb_real d[3];
    v3_sub(d, &x[3 * p], &x[3 * v[0]]);
    if (!(fabs(v3_dot(d, tb + 7)) < reach)) return 0;
    wb_real bary[3], q[3];
    if (!(wb__tri_closest(&x[3 * p], &x[3 * v[0]], &x[3 * v[1]], &x[3 * v[2]], bary, q) < reach * reach)) return 0;
    return !(same && !rest_apart(m, p, v)) && !joined_corner(pc, same, p, v);
}

/* fmax and fmin (a NaN argument gives the other), without the call into libm */
static inline wb_real max_(wb_real a, wb_real b) { return b != b ? a : a > b ? a : b; }
static inline wb_real min_(wb_real a, wb_real b) { return b != b ? a : a < b ? a : b; }

/* ---- pass 1: body culling -------------------------------------------------------------------------- */
static inline int box_overlap(const wb_real *alo, const wb_real *ahi, const wb_real *blo, const wb_real *bhi)
{
    return alo[0] <= bhi[0] && blo[0] <= ahi[0] && alo[1] <= bhi[1] && blo[1] <= ahi[1] &&
           alo[2] <= bhi[2] && blo[2] <= ahi[2];
}

/* an item's box: a point's x +- reach, a triangle's grown box (as the exact test's) */
static inline void item_box(const struct wb_tribroad *b, const wb_real *x, int32_t i, int tris, wb_real lo[3],
                            wb_real hi[3])
{
    if (tris) {
        const wb_real *tb = &b->tbox[TB * i];
        for (int a = 0; a < 3; a++) lo[a] = tb[a] - tb[6], hi[a] = tb[3 + a] + tb[6];
    } else {
        const wb_real r = b->sr[i];
        for (int a = 0; a < 3; a++) lo[a] = x[3 * i + a] - r, hi[a] = x[3 * i + a] + r;
    }
}

/* The runs: consecutive items of one body key share a run, and every keyless item (key
 * 0) shares one wherever it stands. One rule for the points' runs, the triangles' and
 * the quick answer's (pick_run; a picker starts as {0, -1, -1, 0}) */
typedef struct { int32_t n, keyless, last, last_key; } run_picker;

/* the run of the next item (key); *fresh when it is a new one (the last, n - 1); -1 when
 * there would be more than RUNS_MAX */
static inline int32_t pick_run(run_picker *q, int32_t key, int *fresh)
{
    int32_t r;
    *fresh = 0;
    if (key == 0 && q->keyless >= 0) r = q->keyless;
    else if (key > 0 && q->last >= 0 && q->last_key == key) r = q->last;
    else {
        if (q->n == RUNS_MAX) return -1;
        r = q->n++;
        *fresh = 1;
        if (key == 0) q->keyless = r;
    }
    if (key != 0) q->last = r, q->last_key = key;
    return r;
}

/* run boxes grown by a few ulps of their coordinates and of the largest reach (eps): the
 * exact test passes only for boxes that overlap but for round-off, and a pair's boxes
 * then meet inside both runs' grown boxes */
static void pad_runs(run *R, int32_t n, wb_real eps)
{
    for (int32_t r = 0; r < n; r++)
        for (int a = 0; a < 3; a++) {
            const wb_real e = 1e-14 * max_(fabs(R[r].lo[a]), fabs(R[r].hi[a])) + eps;
            R[r].lo[a] -= e;
            R[r].hi[a] += e;
        }
}

/* lo, hi grown to item i's box */
static inline void add_item(const struct wb_tribroad *b, const wb_real *x, int32_t i, int tris, wb_real lo[3],
                            wb_real hi[3])
{
    wb_real l[3], h[3];
    item_box(b, x, i, tris, l, h);
    for (int a = 0; a < 3; a++) {
        lo[a] = l[a] < lo[a] ? l[a] : lo[a];
        hi[a] = h[a] > hi[a] ? h[a] : hi[a];
    }
}

/* the runs of list (n items; tris: triangles keyed by tkey, else points keyed by group)
 * into b->runs from r0, padded (pad_runs); each stretch of consecutive items of one key
 * gathered in one tight loop, the stretches (first, end, run) into seg (*nseg; at most
 * n). Returns the runs, -1 when too many, -2 when out of memory */
static int32_t make_runs(struct wb_tribroad *b, int32_t r0, const int32_t *list, int32_t n, const wb_world *w,
                         int tris, int32_t *seg, int32_t *nseg, wb_real eps)
{
    const int32_t *keys = tris ? b->tkey : w->m.group;
    const wb_real *x = w->s.x;
    run_picker q = { 0, -1, -1, 0 };
    int32_t ns = 0;
    for (int32_t k = 0; k < n;) {
        const int32_t key = keys[list[k]];
        int fresh;
        const int32_t r = pick_run(&q, key, &fresh);
        if (r < 0) return -1;
        if (fresh) {
            if (!grow((void **)&b->runs, &b->cap_runs, r0 + r + 1, sizeof *b->runs)) return -2;
            run *R = &b->runs[r0 + r];
            R->key = key;
            for (int a = 0; a < 3; a++) { R->lo[a] = INFINITY; R->hi[a] = -INFINITY; }
        }
        wb_real lo[3] = { INFINITY, INFINITY, INFINITY }, hi[3] = { -INFINITY, -INFINITY, -INFINITY };
        int32_t k1 = k;
        /* two loops, so that each inlines item_box for its kind (the points' is the quick
         * answer's every frame) */
        if (tris) for (; k1 < n && keys[list[k1]] == key; k1++) add_item(b, x, list[k1], 1, lo, hi);
        else for (; k1 < n && keys[list[k1]] == key; k1++) add_item(b, x, list[k1], 0, lo, hi);
        run *R = &b->runs[r0 + r];
        for (int a = 0; a < 3; a++) R->lo[a] = min_(R->lo[a], lo[a]), R->hi[a] = max_(R->hi[a], hi[a]);
        seg[3 * ns] = k, seg[3 * ns + 1] = k1, seg[3 * ns + 2] = r0 + r;
        ns++;
        k = k1;
    }
    pad_runs(b->runs + r0, q.n, eps);
    *nseg = ns;
    return q.n;
}

/* run A's overlaps with the runs [s0, s1) of keys it may touch; 0 when out of memory */
static int overlaps(struct wb_tribroad *b, int32_t ra, int32_t s0, int32_t s1, int32_t *nb)
{
    run *A = &b->runs[ra];
    A->box0 = *nb;
    A->nbox = 0;
    for (int32_t s = s0; s < s1; s++) {
        const run *B = &b->runs[s];
        if ((A->key != 0 && B->key == A->key) || !box_overlap(A->lo, A->hi, B->lo, B->hi)) continue;
        if (A->nbox == BOXES_MAX) (*nb)--, A->nbox--; /* reopen the last box */
        else {
            if (!grow((void **)&b->boxes, &b->cap_boxes, 6 * ((int64_t)*nb + 1), sizeof *b->boxes)) return 0;
            for (int a = 0; a < 3; a++) { b->boxes[6 * *nb + a] = INFINITY; b->boxes[6 * *nb + 3 + a] = -INFINITY; }
        }
        wb_real *bx = &b->boxes[6 * *nb];
        for (int a = 0; a < 3; a++) {
            const wb_real lo = max_(A->lo[a], B->lo[a]), hi = min_(A->hi[a], B->hi[a]);
            if (lo < bx[a]) bx[a] = lo;
            if (hi > bx[3 + a]) bx[3 + a] = hi;
        }
        (*nb)++;
        A->nbox++;
    }
    /* a box that covers the whole run culls nothing: test none */
    for (int32_t q = A->box0; q < A->box0 + A->nbox; q++) {
        const wb_real *bx = &b->boxes[6 * q];
        if (bx[0] <= A->lo[0] && bx[1] <= A->lo[1] && bx[2] <= A->lo[2] && bx[3] >= A->hi[0] &&
            bx[4] >= A->hi[1] && bx[5] >= A->hi[2]) { A->nbox = -1; break; }
    }
    return 1;
}

/* whether item i (tris: a triangle, else a point) of run A is kept: A covered by one box,
 * or i's box meets one of A's overlaps */
static inline int kept_item(const struct wb_tribroad *b, const run *A, const wb_real *x, int32_t i, int tris)
{
    if (A->nbox < 0) return 1;
    wb_real lo[3], hi[3];
    item_box(b, x, i, tris, lo, hi);
    for (int32_t q = A->box0; q < A->box0 + A->nbox; q++)
        if (box_overlap(lo, hi, &b->boxes[6 * q], &b->boxes[6 * q + 3])) return 1;
    return 0;
}

/* the items of list (make_runs' seg, nseg stretches; tris: triangles, else points) that
 * kept_item keeps, in order; the stretch of a run that meets no run of the other kind is
 * dropped whole */
static int32_t keep(const struct wb_tribroad *b, int32_t *list, const int32_t *seg, int32_t nseg, const wb_real *x,
                    int tris)
{
    int32_t m = 0;
    for (int32_t s = 0; s < nseg; s++) {
        const run *A = &b->runs[seg[3 * s + 2]];
        if (A->nbox == 0) continue;
        for (int32_t k = seg[3 * s]; k < seg[3 * s + 1]; k++)
            if (kept_item(b, A, x, list[k], tris)) list[m++] = list[k];
    }
    return m;
}

/* culls b->pc (np_ items, the largest reach rmax) and b->tc (nt_ items) in place; -1 when
 * out of memory */
static int cull(struct wb_tribroad *b, const wb_world *w, int32_t *np_, int32_t *nt_, wb_real rmax)
{
    if (!grow((void **)&b->prun, &b->cap_prun, 3 * (int64_t)*np_, sizeof *b->prun) ||
        !grow((void **)&b->trun, &b->cap_trun, 3 * (int64_t)*nt_, sizeof *b->trun))
        return -1;
    const wb_real eps = 1e-14 * rmax;
    int32_t nps, nts;
    const int32_t npr = make_runs(b, 0, b->pc, *np_, w, 0, b->prun, &nps, eps);
    if (npr == -2) return -1;
    if (npr < 0) return 0;
    const int32_t ntr = make_runs(b, npr, b->tc, *nt_, w, 1, b->trun, &nts, eps);
    if (ntr == -2) return -1;
    if (ntr < 0) return 0;
    int32_t nb = 0;
    for (int32_t r = 0; r < npr; r++)
        if (!overlaps(b, r, npr, npr + ntr, &nb)) return -1;
    for (int32_t r = npr; r < npr + ntr; r++)
        if (!overlaps(b, r, 0, npr, &nb)) return -1;
    *np_ = keep(b, b->pc, b->prun, nps, w->s.x, 0);
    *nt_ = keep(b, b->tc, b->trun, nts, w->s.x, 1);
    return 0;
}

/* ---- pass 2: the levels' sorted grids ------------------------------------------------------------ */
/* a level's grid over list (n points): cell twice the typical reach (grid.c's rule) */
static void make_grid(level *l, const wb_real *x, const wb_real *reach, const int32_t *list, int32_t n,
                      wb_real typical)
{
    wb_real lo[3], hi[3], rmax, rn;
    wb__grid_bounds(x, reach, list, n, INFINITY, lo, hi, &rmax, &rn);
    l->rn = rmax;
    wb_real cs = 2 * typical;
    if (!(cs > 0)) cs = 2 * rmax;
    wb__grid_shape(&l->g, lo, hi, cs, n);
}

/* the levels over the kept points b->pc (n); -1 when out of memory */
static int make_levels(struct wb_tribroad *b, const wb_world *w, int32_t n)
{
    const wb_real *x = w->s.x, *reach = b->sr;
    if (!grow((void **)&b->sp, &b->cap_sp, 4 * (int64_t)n, sizeof *b->sp) ||
        !grow((void **)&b->sid, &b->cap_sid, n, sizeof *b->sid) ||
        !grow((void **)&b->skey, &b->cap_skey, n, sizeof *b->skey) ||
        !grow((void **)&b->scell, &b->cap_scell, n, sizeof *b->scell) ||
        !grow((void **)&b->tmp, &b->cap_tmp, n, sizeof *b->tmp))
        return -1;
    int32_t *list = b->pc, rest = n, done = 0;
    int64_t cells = 0;
    b->nlv = 0;
    while (rest > 0) {
        level *l = &b->lv[b->nlv];
        const wb_grid *g = &l->g;
        const wb_real typical = wb__grid_typical(reach, list, rest);
        const wb_real limit = b->nlv == WB_TRI_LEVELS - 1 ? INFINITY : 2 * typical;
        /* this level's points to the front of list, the others after them, both in order */
        int32_t nl = 0, nr = 0;
        for (int32_t k = 0; k < rest; k++) {
            const int32_t i = list[k];
            if (reach[i] <= limit) list[nl++] = i;
            else b->tmp[nr++] = i;
        }
        memcpy(list + nl, b->tmp, sizeof *list * (size_t)nr);
        make_grid(l, x, reach, list, nl, typical);
        l->first = done;
        l->count = nl;
        l->start0 = cells;
        const int64_t nc = g->nc[0] * g->nc[1] * g->nc[2];
        cells += nc + 1;
        if (!grow((void **)&b->start, &b->cap_start, cells, sizeof *b->start)) return -1;
        /* counting sort by cell: stable */
        int32_t *start = b->start + l->start0;
        memset(start, 0, sizeof *start * (size_t)(nc + 1));
        for (int32_t k = 0; k < nl; k++) {
            const int32_t cl = wb__grid_cell(g, &x[3 * list[k]]);
            b->scell[k] = cl;
            start[cl + 1]++;
        }
        for (int64_t q = 0; q < nc; q++) start[q + 1] += start[q];
        for (int32_t k = 0; k < nl; k++) {
            const int32_t i = list[k], s = done + start[b->scell[k]]++;
            wb_real *p = &b->sp[4 * s];
            v3_copy(p, &x[3 * i]);
            p[3] = reach[i];
            b->sid[s] = i;
            b->skey[s] = w->m.group[i];
        }
        for (int64_t q = nc; q > 0; q--) start[q] = start[q - 1] + done; /* back to starts, absolute */
        start[0] = done;
        done += nl;
        list += nl;
        rest -= nl;
        b->nlv++;
    }
    return 0;
}

/* a few ulps of v and a billionth of e beyond e: a query range computed in floating
 * point that surely holds what the exact test accepts */
static inline wb_real pad(wb_real v, wb_real e) { return e * (1 + 1e-9) + 1e-15 * fabs(v); }

/* ---- pass 3: the triangles' scans ---------------------------------------------------------------- */
static void push(wb_pairbuf *o, int32_t p, int32_t t)
{
    if (2 * (o->n + 1) > o->cap && !grow((void **)&o->ij, &o->cap, 2 * ((int64_t)o->n + 1), sizeof *o->ij)) {
        o->fail = 1;
        return;
    }
    o->ij[2 * o->n] = p;
    o->ij[2 * o->n + 1] = t;
    o->n++;
}

/* the sorted points [s0, s1) against triangle t: its own body's skipped, then the slabs of
 * its grown box (as box_dist2 computes them: implied by the exact test), then that */
static void tri_try(const struct wb_tribroad *b, const wb_world *w, const wb_real *tb, const wb_real *lo,
                      const wb_real *hi, int32_t skipkey, int32_t t, int32_t s0, int32_t s1, wb_pairbuf *o)
{
    const wb_real *P = b->sp;
    const int32_t *key = b->skey;
    for (int32_t s = s0; s < s1; s++) {
        if (key[s] == skipkey) continue;
        const wb_real *p = &P[4 * s], rp = p[3];
        if ((p[0] < lo[0] && lo[0] - p[0] >= rp) || (p[0] > hi[0] && p[0] - hi[0] >= rp) ||
            (p[1] < lo[1] && lo[1] - p[1] >= rp) || (p[1] > hi[1] && p[1] - hi[1] >= rp) ||
            (p[2] < lo[2] && lo[2] - p[2] >= rp) || (p[2] > hi[2] && p[2] - hi[2] >= rp))
            continue;
        if (candidate(w, tb, t, b->sid[s], rp)) push(o, b->sid[s], t);
    }
}

/* an axis's search range [lo, hi] as at most two runs of grid cells */
static inline int axis_ranges(const wb_grid *g, int a, wb_real lo, wb_real hi, int64_t r[4])
{
    int64_t c0 = wb__cell_of(lo, g->o[a], g->inv), c1 = wb__cell_of(hi, g->o[a], g->inv);
    const int64_t n = g->nc[a];
    if (!g->wrap) {
        r[0] = c0; r[1] = c1 < n - 1 ? c1 : n - 1;
        return r[0] <= r[1];
    }
    if (c1 - c0 + 1 >= n) { r[0] = 0; r[1] = n - 1; return 1; }
    c0 %= n;
    c1 %= n;
    if (c0 <= c1) { r[0] = c0; r[1] = c1; return 1; }
    r[0] = c0; r[1] = n - 1; r[2] = 0; r[3] = c1;
    return 2;
}

/* the kept triangles [k0, k1) of b->tc */
static void tri_scan(const struct wb_tribroad *b, const wb_world *w, int32_t k0, int32_t k1, wb_pairbuf *o)
{
    for (int32_t k = k0; k < k1; k++) {
        const int32_t t = b->tc[k];
        const wb_real *tb = &b->tbox[TB * t];
        /* a point of its key never touches it; keys are >= 0 */
        const int32_t skipkey = b->tkey[t] != 0 ? b->tkey[t] : -1;
        wb_real lo[3], hi[3];
        for (int a = 0; a < 3; a++) lo[a] = tb[a] - tb[6], hi[a] = tb[3 + a] + tb[6];
        for (int l = 0; l < b->nlv; l++) {
            const level *lv = &b->lv[l];
            const wb_grid *g = &lv->g;
            int64_t r[3][4];
            int kr[3];
            for (int a = 0; a < 3; a++) {
                const wb_real e0 = pad(lo[a], lv->rn), e1 = pad(hi[a], lv->rn);
                kr[a] = axis_ranges(g, a, lo[a] - e0, hi[a] + e1, r[a]);
            }
            if (!kr[0] || !kr[1] || !kr[2]) continue;
            int64_t rows = 0;
            for (int a = 1; a < 3; a++) {
                int64_t c = 0;
                for (int q = 0; q < kr[a]; q++) c += r[a][2 * q + 1] - r[a][2 * q] + 1;
                rows = a == 1 ? c : rows * c;
            }
            if (rows > lv->count) { /* cheaper to look at every point of the level */
                tri_try(b, w, tb, lo, hi, skipkey, t, lv->first, lv->first + lv->count, o);
                continue;
            }
            const int32_t *start = b->start + lv->start0;
            for (int az = 0; az < kr[2]; az++)
                for (int64_t z = r[2][2 * az]; z <= r[2][2 * az + 1]; z++)
                    for (int ay = 0; ay < kr[1]; ay++)
                        for (int64_t y = r[1][2 * ay]; y <= r[1][2 * ay + 1]; y++) {
                            const int64_t row = g->nc[0] * (y + g->nc[1] * z);
                            for (int ax = 0; ax < kr[0]; ax++) {
                                const int32_t q0 = start[row + r[0][2 * ax]], q1 = start[row + r[0][2 * ax + 1] + 1];
                                if (q0 < q1) tri_try(b, w, tb, lo, hi, skipkey, t, q0, q1, o);
                            }
                        }
        }
    }
}

/* ---- the projection's order ------------------------------------------------------------------- */
/* The projection is Gauss-Seidel: the order of the list is part of the result, and scenes
 * tuned with the hashed grid this file replaced are sensitive to it (contact_energy.lua's
 * interleaved tower toppled past its bound with each point's triangles in index order,
 * logo_spring.lua's L stayed flattened with the list in triangle order; reversed, the
 * tower flew apart). So the list keeps that grid's order, which is a function of the
 * positions: cubic cells of size `cell` from the origin; each point (ascending) met the
 * triangles of the cells its box covered in (z, y, x) order, a triangle first in the first
 * cell of its own grown box's cells that the point's cells hold, ties by index; a point
 * whose box covered more than 64 cells met every triangle in index order; triangles whose
 * grown box covered more than 64 cells came last, each (ascending) with every other point
 * in index order. (Two cells that hashed to one bucket could reorder a few; not kept.) */
static int64_t ocell_of(wb_real x, wb_real inv)
{
    const wb_real c = floor(x * inv);
    return c > 1e15 ? (int64_t)1e15 : c < -1e15 ? -(int64_t)1e15 : (int64_t)c;
}

static int ocells(const wb_real *lo, const wb_real *hi, wb_real g, wb_real inv, int64_t c0[3])
{
    double n = 1;
    for (int k = 0; k < 3; k++) {
        c0[k] = ocell_of(lo[k] - g, inv);
        n *= (double)(ocell_of(hi[k] + g, inv) - c0[k] + 1);
    }
    return n > 64;
}

static int cmp_u64(const void *a, const void *b)
{
    const uint64_t x = *(const uint64_t *)a, y = *(const uint64_t *)b;
    return x < y ? -1 : x > y;
}

/* by_p (b->pt2: total pairs by point, each point's in triangle order) into out in that
 * order; 0 when out of memory */
static int order_as_grid(struct wb_tribroad *b, const wb_world *w, wb_real cell, int64_t total, int32_t *out)
{
    const int32_t *by_p = b->pt2;
    if (!(cell > 0) || !isfinite(cell)) {
        memcpy(out, by_p, sizeof *out * (size_t)(2 * total));
        return 1;
    }
    if (!grow((void **)&b->okey, &b->cap_okey, total, sizeof *b->okey)) return 0;
    const wb_real inv = 1 / cell;
    int64_t at = 0, nbig = 0;
    for (int64_t q0 = 0; q0 < total;) {
        const int32_t p = by_p[2 * q0];
        int64_t q1 = q0;
        while (q1 < total && by_p[2 * q1] == p) q1++;
        int64_t pc[3];
        const wb_real *xp = &w->s.x[3 * p];
        if (ocells(xp, xp, b->reach[p], inv, pc)) { /* a big point: index order */
            memcpy(out + 2 * at, by_p + 2 * q0, sizeof *out * (size_t)(2 * (q1 - q0)));
            at += q1 - q0;
            q0 = q1;
            continue;
        }
        int64_t n = 0;
        for (int64_t q = q0; q < q1; q++) {
            const int32_t t = by_p[2 * q + 1];
            const wb_real *tb = &b->tbox[TB * t];
            if (tb[13] != 0) { nbig++; continue; } /* after every point */
            /* the first cell both cover, relative to the point's first (each < 64) */
            uint64_t key = 0;
            for (int k = 2; k >= 0; k--) {
                const int64_t tc = (int64_t)tb[10 + k];
                key = key * 64 + (uint64_t)((tc > pc[k] ? tc : pc[k]) - pc[k]);
            }
            b->okey[n++] = key << 32 | (uint32_t)t;
        }
        if (n > 16) qsort(b->okey, (size_t)n, sizeof *b->okey, cmp_u64);
        else
            for (int64_t k = 1; k < n; k++) { /* a point's handful */
                const uint64_t v = b->okey[k];
                int64_t j = k;
                for (; j > 0 && b->okey[j - 1] > v; j--) b->okey[j] = b->okey[j - 1];
                b->okey[j] = v;
            }
        for (int64_t k = 0; k < n; k++, at++) out[2 * at] = p, out[2 * at + 1] = (int32_t)(b->okey[k] & 0xffffffffu);
        q0 = q1;
    }
    if (nbig == 0) return 1;
    /* the big triangles' pairs with the other points, by triangle then point */
    int64_t n = 0;
    for (int64_t q = 0; q < total; q++) {
        const int32_t p = by_p[2 * q], t = by_p[2 * q + 1];
        int64_t c0[3];
        if (b->tbox[TB * t + 13] == 0 || ocells(&w->s.x[3 * p], &w->s.x[3 * p], b->reach[p], inv, c0)) continue;
        b->okey[n++] = (uint64_t)(uint32_t)t << 32 | (uint32_t)p;
    }
    qsort(b->okey, (size_t)n, sizeof *b->okey, cmp_u64);
    for (int64_t k = 0; k < n; k++, at++)
        out[2 * at] = (int32_t)(b->okey[k] & 0xffffffffu), out[2 * at + 1] = (int32_t)(b->okey[k] >> 32);
    return 1;
}

/* ---- the frame's list ----------------------------------------------------------------------------- */
/* the scan on the pool: part k takes its contiguous range of the kept triangles into
 * its own buffer */
typedef struct tri_job { const struct wb_tribroad *b; const wb_world *w; int32_t nt; } tri_job;

static void tri_part(void *ctx, int k, int nth)
{
    const tri_job *j = ctx;
    tri_scan(j->b, j->w, (int32_t)((int64_t)j->nt * k / nth), (int32_t)((int64_t)j->nt * (k + 1) / nth),
             &j->b->out[k]);
}

/* triangle t's record from the motions mvp: box, motion; -1 in tb[6] when left out (no
 * corner may collide, or not finite). Returns the extent that sizes the order's cell
 * (NAN when left out) */
static wb_real tri_box(const wb_model *m, const wb_real *x, const wb_real *mvp, int32_t t, wb_real *tb)
{
    const int32_t *tv = &m->tri[3 * t];
    tb[6] = -1;
    if (!((m->cflags[tv[0]] | m->cflags[tv[1]] | m->cflags[tv[2]]) & (WB_CF_COLLIDE | WB_CF_SELF))) return NAN;
    /* the corners' box in locals (tb may alias nothing, the compiler cannot know) */
    const wb_real *p0 = &x[3 * tv[0]], *p1 = &x[3 * tv[1]], *p2 = &x[3 * tv[2]];
    wb_real lo[3], hi[3];
    for (int a = 0; a < 3; a++) {
        lo[a] = p0[a], hi[a] = p0[a];
        lo[a] = p1[a] < lo[a] ? p1[a] : lo[a];
        hi[a] = p1[a] > hi[a] ? p1[a] : hi[a];
        lo[a] = p2[a] < lo[a] ? p2[a] : lo[a];
        hi[a] = p2[a] > hi[a] ? p2[a] : hi[a];
    }
    wb_real mv = mvp[tv[0]] > 0 ? mvp[tv[0]] : 0;
    mv = mvp[tv[1]] > mv ? mvp[tv[1]] : mv;
    mv = mvp[tv[2]] > mv ? mvp[tv[2]] : mv;
    const wb_real e = max_(hi[0] - lo[0], max_(hi[1] - lo[1], hi[2] - lo[2])) + 2 * mv;
    if (!isfinite(e)) return NAN;
    for (int a = 0; a < 3; a++) tb[a] = lo[a], tb[3 + a] = hi[a];
    tb[6] = mv;
    return e;
}

/* the unit normal (0 when degenerate): a point farther than its reach from the plane is
 * farther from the triangle */
static void tri_normal(const wb_model *m, const wb_real *x, int32_t t, wb_real *n)
{
    const int32_t *tv = &m->tri[3 * t];
    wb_real e1[3], e2[3];
    v3_sub(e1, &x[3 * tv[1]], &x[3 * tv[0]]);
    v3_sub(e2, &x[3 * tv[2]], &x[3 * tv[0]]);
    v3_cross(n, e1, e2);
    const wb_real ln = v3_len(n);
    if (ln > 0 && isfinite(ln)) v3_scale(n, n, 1 / ln);
    else v3_set(n, 0, 0, 0);
}

/* the pairs of points of reach `reach` (rsum summed over nr) and triangles of motions mvp
 * into b->pt2 by point, each point's by triangle (*total); *ocell: the cell of the
 * projection's order (set when *total > 0). The points: b->pc[0 .. npts) when npts >= 0
 * (what the quick answer left), else all; the triangles: those of the quick answer's runs
 * marked in need, else all. -1 when out of memory */
static int search(struct wb_tribroad *b, wb_world *w, const wb_real *reach, const wb_real *mvp, wb_real rsum,
                  int32_t nr, int32_t npts, const uint8_t *need, int64_t *total, wb_real *ocell)
{
    wb_model *m = &w->m;
    const wb_real *x = w->s.x;
    *total = 0;
    if (!grow((void **)&b->tbox, &b->cap_tbox, TB * (int64_t)m->ntri, sizeof *b->tbox) ||
        !grow((void **)&b->tkey, &b->cap_tkey, m->ntri, sizeof *b->tkey) ||
        !grow((void **)&b->pc, &b->cap_pc, m->np, sizeof *b->pc) ||
        !grow((void **)&b->tc, &b->cap_tc, m->ntri, sizeof *b->tc))
        return -1;
    /* a zero reach or a position not finite meets no triangle (the exact test fails); the
     * quick answer's points when it gave them (npts >= 0, in b->pc: such points, in order) */
    int32_t na = 0;
    wb_real rmax = 0;
    if (npts >= 0) {
        na = npts;
        for (int32_t k = 0; k < na; k++) rmax = reach[b->pc[k]] > rmax ? reach[b->pc[k]] : rmax;
    } else
        for (int32_t i = 0; i < m->np; i++) {
            const wb_real *p = &x[3 * i];
            if (reach[i] > 0 && isfinite(p[0]) && isfinite(p[1]) && isfinite(p[2])) {
                b->pc[na++] = i;
                if (reach[i] > rmax) rmax = reach[i];
            }
        }
    /* triangles: box, motion; and the body no point of which may touch it (its corners'
     * body when it does not self-collide; else 0); only the quick answer's runs a point
     * may meet when it gave them (need) */
    int32_t nt = 0;
    wb_real sum = 0;
    for (int32_t t = 0; t < m->ntri; t++) {
        if (need && (b->qtrun[t] < 0 || !need[b->qtrun[t]])) continue;
        const wb_real e = tri_box(m, x, mvp, t, &b->tbox[TB * t]);
        if (e != e) continue;
        b->tkey[t] = tri_key(m, w->k.pc, t);
        b->tc[nt++] = t;
        sum += e;
    }
    if (na == 0 || nt == 0) return 0;
    const int32_t nt_all = nt;
    b->sr = reach;
    if (cull(b, w, &na, &nt, rmax) < 0) return -1;
    if (na == 0 || nt == 0) return 0;
    for (int32_t k = 0; k < nt; k++) tri_normal(m, x, b->tc[k], &b->tbox[TB * b->tc[k]] + 7);
    if (make_levels(b, w, na) < 0) return -1;

    /* contiguous ranges of the kept triangles, one pair buffer each */
    const int nth = m->def.threads > 1 && nt >= PAR_MIN ? m->def.threads : 1;
    if (!wb__pairbufs(&b->out, &b->nout, nth)) return -1;
    if (nth == 1) tri_scan(b, w, 0, nt, &b->out[0]);
    else {
        tri_job j = { b, w, nt };
        wb__pool_run(wb__world_pool(w), tri_part, &j); /* nth parts: nth == the pool's threads */
    }
    int64_t n = 0;
    for (int k = 0; k < nth; k++) {
        if (b->out[k].fail) return -1;
        n += b->out[k].n;
    }
    if (!grow((void **)&b->pt2, &b->cap_pt2, 2 * n, sizeof *b->pt2) ||
        !grow((void **)&b->first, &b->cap_first, (int64_t)m->np + 1, sizeof *b->first))
        return -1;
    /* by point (stable: a thread's pairs of one point come in ascending triangle order,
     * the threads' ranges ascend) */
    int32_t *first = b->first, *by_p = b->pt2;
    memset(first, 0, sizeof *first * ((size_t)m->np + 1));
    for (int k = 0; k < nth; k++)
        for (int32_t q = 0; q < b->out[k].n; q++) first[b->out[k].ij[2 * q] + 1]++;
    for (int32_t i = 0; i < m->np; i++) first[i + 1] += first[i];
    for (int k = 0; k < nth; k++)
        for (int32_t q = 0; q < b->out[k].n; q++) {
            const int32_t at = first[b->out[k].ij[2 * q]]++;
            by_p[2 * at] = b->out[k].ij[2 * q];
            by_p[2 * at + 1] = b->out[k].ij[2 * q + 1];
        }
    *total = n;
    if (n == 0) return 0;
    /* the cell of the order (see order_as_grid): the larger of every triangle's mean extent
     * (the boxes of the runs left out worked out now: only lists that are not empty need
     * it) and twice the points' mean reach; each listed triangle's first cell in it */
    int32_t nsum = nt_all;
    if (need) {
        sum = 0;
        nsum = 0;
        for (int32_t t = 0; t < m->ntri; t++) {
            const wb_real e = tri_box(m, x, mvp, t, &b->tbox[TB * t]); /* (the same bits again) */
            if (e == e) sum += e, nsum++;
        }
    }
    const wb_real oc = *ocell = max_(sum / nsum, 2 * rsum / nr);
    if (oc > 0 && isfinite(oc))
        for (int32_t k = 0; k < nt; k++) { /* its first cell in the order, whether it is big there */
            wb_real *tb = &b->tbox[TB * b->tc[k]];
            int64_t c0[3];
            tb[13] = ocells(tb, tb + 3, tb[6], 1 / oc, c0);
            for (int a = 0; a < 3; a++) tb[10 + a] = (wb_real)c0[a]; /* |c| <= 1e15: exact */
        }
    return 0;
}

/* b->pt2 (total pairs by point) into c->pt in the projection's order (cell ocell) */
static int finish(struct wb_tribroad *b, wb_world *w, int64_t total, wb_real ocell)
{
    wb_tricontacts *c = w->k.tc;
    if (!grow((void **)&c->pt, &c->cap, 2 * total, sizeof *c->pt)) return -1;
    if (!order_as_grid(b, w, ocell, total, c->pt)) return -1;
    c->n = (int32_t)total;
    return 0;
}

/* ---- the quick answer: no candidate this frame ------------------------------------------------- */
/* In a resting heap every frame's list is empty, yet the search computes the box of every
 * triangle to find that out. The body culling's runs of triangles are fixed by the
 * topology, flags and groups alone; each run's box (the union of its triangles' boxes
 * grown by their motions) lies inside the box of its corners grown by their largest
 * motion. So the runs are kept between frames with their corners (rebuilt when anything
 * they depend on changes), their boxes come from the corners (about half the particles,
 * once each, instead of 9 coordinates per triangle), and the points are culled against
 * them as in pass 1: when no point is left, no pair can pass the exact test and the
 * list is empty, as the search would find (the larger boxes only keep more). Else the
 * search takes the points left and the triangles of the runs their boxes meet (what
 * is left out meets nothing, by the same boxes): the list is the search's either way. */

/* the arrays the runs depend on (triangles, flags, groups, covers), one after the other: copied
 * into b->kmodel (store), or compared with it */
static int model_same(struct wb_tribroad *b, const wb_model *m, const uint8_t *cov, int store)
{
    const struct { const void *p; size_t n; } a[] = {
        { m->tri, sizeof *m->tri * 3 * (size_t)m->ntri },
        { m->cflags, sizeof *m->cflags * (size_t)m->np },
        { m->group, sizeof *m->group * (size_t)m->np },
        { cov, sizeof *cov * (size_t)m->ntri },
    };
    size_t at = 0;
    for (size_t k = 0; k < sizeof a / sizeof a[0]; k++) at += a[k].n;
    if (store) {
        if (at > INT32_MAX / 2 || !grow((void **)&b->kmodel, &b->cap_kmodel, (int64_t)at, 1)) return 0;
        b->kbytes = (int64_t)at;
        b->knp = m->np;
        b->knt = m->ntri;
    } else if (b->kbytes != (int64_t)at || b->knp != m->np || b->knt != m->ntri)
        return 0;
    at = 0;
    for (size_t k = 0; k < sizeof a / sizeof a[0]; k++) {
        if (a[k].n == 0) continue;
        if (store) memcpy(b->kmodel + at, a[k].p, a[k].n);
        else if (memcmp(b->kmodel + at, a[k].p, a[k].n)) return 0;
        at += a[k].n;
    }
    return 1;
}

static int cmp_i32(const void *a, const void *b)
{
    const int32_t x = *(const int32_t *)a, y = *(const int32_t *)b;
    return x < y ? -1 : x > y;
}

/* the triangle runs (pick_run's rule) and each run's corners, once each: b->qrun
 * (key, first corner, end), b->qcorner; b->nq = -1 when too many runs. 0 when out of memory */
static int quick_runs(struct wb_tribroad *b, const wb_world *w)
{
    const wb_model *m = &w->m;
    b->qvalid = 0;
    if (!model_same(b, m, w->k.pc->tcov, 1) || !grow((void **)&b->qtrun, &b->cap_qtrun, m->ntri, sizeof *b->qtrun)) return 0;
    int32_t *rid = b->qtrun;
    int32_t keys[RUNS_MAX];
    run_picker pick = { 0, -1, -1, 0 };
    for (int32_t t = 0; t < m->ntri; t++) {
        const int32_t *tv = &m->tri[3 * t];
        const uint8_t f0 = m->cflags[tv[0]], f1 = m->cflags[tv[1]], f2 = m->cflags[tv[2]];
        rid[t] = -1;
        if (!((f0 | f1 | f2) & (WB_CF_COLLIDE | WB_CF_SELF))) continue;
        const int32_t key = tri_key(m, w->k.pc, t);
        int fresh;
        rid[t] = pick_run(&pick, key, &fresh);
        if (rid[t] < 0) { b->nq = -1; b->qvalid = 1; return 1; }
        if (fresh) keys[rid[t]] = key;
    }
    const int32_t nq = pick.n;
    /* corners by run (a counting sort), then each run's sorted and made unique */
    if (!grow((void **)&b->qrun, &b->cap_qrun, 3 * (int64_t)nq + 3, sizeof *b->qrun) ||
        !grow((void **)&b->qcorner, &b->cap_qcorner, 3 * (int64_t)m->ntri, sizeof *b->qcorner))
        return 0;
    int32_t *q = b->qrun;
    for (int32_t r = 0; r <= nq; r++) q[3 * r + 1] = 0;
    for (int32_t t = 0; t < m->ntri; t++)
        if (rid[t] >= 0) q[3 * rid[t] + 4] += 3;
    for (int32_t r = 0; r < nq; r++) q[3 * r + 4] += q[3 * r + 1], q[3 * r] = keys[r], q[3 * r + 2] = q[3 * r + 1];
    for (int32_t t = 0; t < m->ntri; t++)
        if (rid[t] >= 0)
            for (int k = 0; k < 3; k++) b->qcorner[q[3 * rid[t] + 2]++] = m->tri[3 * t + k];
    for (int32_t r = 0; r < nq; r++) {
        int32_t *c = b->qcorner + q[3 * r + 1], n = q[3 * r + 2] - q[3 * r + 1], u = 0;
        qsort(c, (size_t)n, sizeof *c, cmp_i32);
        for (int32_t k = 0; k < n; k++)
            if (k == 0 || c[k] != c[u - 1]) c[u++] = c[k];
        q[3 * r + 2] = q[3 * r + 1] + u;
    }
    b->nq = nq;
    b->qvalid = 1;
    b->rebuilds++;
    return 1;
}

/* 1 when no point can meet a triangle this frame (the points b->pc, na, their largest
 * reach rmax; positions and motions finite), 0 when some may, -1 when out of memory.
 * When some may, the points that may are left first in b->pc, *left of them (-1: not
 * worked out), and when *tris need[r] says whether one may meet a triangle of run r */
static int quick_empty(struct wb_tribroad *b, wb_world *w, int32_t na, wb_real rmax, int32_t *left, uint8_t *need,
                       int *tris)
{
    *left = -1;
    *tris = 0;
    const wb_model *m = &w->m;
    const wb_real *x = w->s.x, *mvp = b->mv;
    if (!b->qvalid || !model_same(b, m, w->k.pc->tcov, 0)) {
        if (!quick_runs(b, w)) return -1;
    }
    if (b->nq < 0) return 0;
    if (na == 0 || b->nq == 0) return 1;
    if (!grow((void **)&b->prun, &b->cap_prun, 3 * (int64_t)na, sizeof *b->prun)) return -1;
    const wb_real eps = 1e-14 * rmax;
    int32_t nseg;
    const int32_t npr = make_runs(b, 0, b->pc, na, w, 0, b->prun, &nseg, eps);
    if (npr == -2) return -1;
    if (npr < 0) return 0;
    if (!grow((void **)&b->runs, &b->cap_runs, npr + b->nq, sizeof *b->runs)) return -1;
    for (int32_t r = 0; r < b->nq; r++) { /* the corners' box grown by their largest motion */
        const int32_t *q = &b->qrun[3 * r];
        run *R = &b->runs[npr + r];
        wb_real lo[3] = { INFINITY, INFINITY, INFINITY }, hi[3] = { -INFINITY, -INFINITY, -INFINITY }, mv = 0;
        for (int32_t k = q[1]; k < q[2]; k++) {
            const int32_t i = b->qcorner[k];
            const wb_real *p = &x[3 * i];
            for (int a = 0; a < 3; a++) {
                lo[a] = p[a] < lo[a] ? p[a] : lo[a];
                hi[a] = p[a] > hi[a] ? p[a] : hi[a];
            }
            mv = mvp[i] > mv ? mvp[i] : mv;
        }
        R->key = q[0];
        for (int a = 0; a < 3; a++) R->lo[a] = lo[a] - mv, R->hi[a] = hi[a] + mv;
    }
    pad_runs(b->runs + npr, b->nq, eps);
    int32_t nb = 0;
    for (int32_t r = 0; r < npr; r++)
        if (!overlaps(b, r, npr, npr + b->nq, &nb)) return -1;
    const int32_t n = keep(b, b->pc, b->prun, nseg, x, 0);
    if (n == 0) return 1;
    /* the triangle runs some point left meets (its box against the run's, as overlaps
     * tests runs), when that is cheap next to boxing every triangle */
    *left = n;
    *tris = (int64_t)n * b->nq <= 4 * (int64_t)m->ntri + 1024; /* else every triangle */
    memset(need, 0, (size_t)b->nq);
    for (int32_t k = 0; *tris && k < n; k++) {
        const int32_t p = b->pc[k], key = m->group[p];
        wb_real lo[3], hi[3];
        item_box(b, x, p, 0, lo, hi);
        for (int32_t r = 0; r < b->nq; r++) {
            const run *R = &b->runs[npr + r];
            if (!need[r] && !(key != 0 && R->key == key) && box_overlap(lo, hi, R->lo, R->hi)) need[r] = 1;
        }
    }
    return 0;
}

static int broadphase(wb_world *w)
{
    wb_model *m = &w->m;
    wb_tricontacts *c = w->k.tc;
    if (!c->bp && !(c->bp = calloc(1, sizeof *c->bp))) return -1;
    struct wb_tribroad *b = c->bp;
    const wb_real *x = w->s.x, *v = w->s.v;
    if (!grow((void **)&b->reach, &b->cap_reach, m->np, sizeof *b->reach) ||
        !grow((void **)&b->mv, &b->cap_mv, m->np, sizeof *b->mv) ||
        !grow((void **)&b->pc, &b->cap_pc, m->np, sizeof *b->pc))
        return -1;
    wb_real *reach = b->reach, *mvp = b->mv;
    /* how far a particle may get this frame (velocity and gravity over dt, and a quarter
     * of its radius for what the constraints move it, as contact.c); a point's reach
     * adds its radius */
    const wb_real dt = m->def.dt, g = v3_len(m->def.gravity) * dt * dt;
    int32_t nr = 0, na = 0;
    wb_real rsum = 0, rmax = 0;
    int finite = 1;
    for (int32_t i = 0; i < m->np; i++) {
        mvp[i] = v3_len_fast(&v[3 * i]) * dt + g + m->radius[i] / 4;
        reach[i] = (m->cflags[i] & (WB_CF_COLLIDE | WB_CF_SELF)) ? m->radius[i] + mvp[i] : -1;
        if (!isfinite(reach[i])) reach[i] = -1;
        if (reach[i] >= 0) nr++, rsum += reach[i];
        const wb_real *p = &x[3 * i];
        finite &= isfinite(p[0] + p[1] + p[2] + mvp[i]);
        if (reach[i] > 0) {
            b->pc[na++] = i;
            if (reach[i] > rmax) rmax = reach[i];
        }
    }
    b->sr = reach;
    /* the quick answer; when it has none, the search takes the points it left and the
     * triangles of the runs they may meet (the list is the same). When it leaves more
     * than half the points (or cannot answer: too many runs), it waits 1, 2, 4 ... 16
     * frames (a scene always in touch pays for it once in a while only) */
    int32_t left = -1;
    uint8_t need[RUNS_MAX];
    int tris = 0;
    if (b->qwait > 0) b->qwait--;
    else if (finite && !b->fresh_only) {
        const int r = quick_empty(b, w, na, rmax, &left, need, &tris);
        if (r < 0) return -1;
        if (r || (left >= 0 && left <= na / 2)) b->qback = 0;
        else {
            b->qback = b->qback ? (b->qback < 16 ? 2 * b->qback : 16) : 1;
            b->qwait = b->qback - 1;
        }
        if (r) return 0;
    }
    int64_t total;
    wb_real ocell;
    if (search(b, w, reach, mvp, rsum, nr, left, tris ? need : NULL, &total, &ocell) < 0) return -1;
    if (total == 0) return 0;
    return finish(b, w, total, ocell);
}

/* its scratch freed (the teardown below) */
static void tribroad_free(wb_tricontacts *c)
{
    struct wb_tribroad *b = c->bp;
    if (!b) return;
    void *p[] = { b->reach, b->mv, b->tbox, b->tkey, b->pc, b->tc, b->prun, b->trun, b->tmp, b->runs, b->boxes,
                  b->sp, b->sid, b->skey, b->scell, b->start, b->first, b->pt2, b->okey,
                  b->qrun, b->qcorner, b->qtrun, b->kmodel };
    for (size_t i = 0; i < sizeof p / sizeof p[0]; i++) free(p[i]);
    for (int t = 0; t < b->nout; t++) free(b->out[t].ij), free(b->out[t].hit);
    free(b->out);
    free(b);
    c->bp = NULL;
}

/* ---- the scratch (k.tc) -------------------------------------------------------------------------- */
int wb__tricontacts_make(wb_world *w)
{
    if (!w->k.tc) w->k.tc = calloc(1, sizeof *w->k.tc);
    return w->k.tc != NULL;
}

void wb__tricontacts_destroy(wb_world *w)
{
    wb_tricontacts *c = w->k.tc;
    if (!c) return;
    tribroad_free(c);
    void *p[] = { c->pt, c->act, c->act_d, c->left };
    for (size_t i = 0; i < sizeof p / sizeof p[0]; i++) free(p[i]);
    free(c);
    w->k.tc = NULL;
}

/* whether no point may touch any triangle by the rules alone: every triangle closed to one
 * body's points (tri_key), and every point of that body (a w:cloth whose spheres cover it,
 * alone in its world but for colliders: no search, no quick answer) */
static int none_possible(const wb_world *w)
{
    const wb_model *m = &w->m;
    const wb_contacts *pc = w->k.pc;
    const int32_t g = m->ntri > 0 ? tri_key(m, pc, 0) : 0;
    if (g == 0) return 0;
    for (int32_t t = 1; t < m->ntri; t++)
        if (tri_key(m, pc, t) != g) return 0;
    for (int32_t i = 0; i < m->np; i++)
        if ((m->cflags[i] & (WB_CF_COLLIDE | WB_CF_SELF)) && m->group[i] != g) return 0;
    return 1;
}

void wb__tricontacts_begin(wb_world *w)
{
    const wb_model *m = &w->m;
    wb_tricontacts *c = w->k.tc;
    c->n = 0;
    c->nact = 0;
    c->last = 0;
    c->fresh = 1;
    c->broad_ms = 0;
    /* contact.c's scan of this frame: no pair of particles may touch, so no point a
     * triangle either (its corners' rules are the pairs'); one body costs nothing */
    if (!m->def.contacts || m->ntri == 0 || m->np < 4 || !w->k.pc->possible || none_possible(w)) return;
    const double t0 = now_ms();
    if (broadphase(w) < 0) {
        c->n = 0;
        if (c->bp) c->bp->qvalid = 0;
        wb__warn(w, "out of memory in the triangle contact broad phase; triangle contacts skipped");
    }
    c->broad_ms = now_ms() - t0;
}
