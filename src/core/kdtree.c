/* kdtree.c: a static k-d tree for K-nearest-neighbour queries (skin binding, clustering
 * links). Balanced by median splits on the widest axis of each range; the points are
 * stored in tree order so a query walks contiguous memory. Ties are broken by the
 * original index, so results never depend on the traversal order. */
#include <stdlib.h>

#include "core.h"

#define LEAF 8 /* ranges this small are scanned, not split */

struct wb_kdtree {
    int32_t n;
    wb_real *p;     /* (n x 3) points in tree order */
    int32_t *id;    /* (n) original index of each */
    uint8_t *axis;  /* (n) split axis of the node whose median sits here */
};

/* (coordinate, index) order: a strict total order, so medians are unique */
static int less(const wb_real *pts, int32_t a, int32_t b, int ax)
{
    wb_real x = pts[3 * a + ax], y = pts[3 * b + ax];
    return x < y || (x == y && a < b);
}

/* put the k-th smallest of idx[lo, hi) at idx[k], smaller ones before it (quickselect
 * with a median-of-three pivot) */
static void select_kth(const wb_real *pts, int32_t *idx, int32_t lo, int32_t hi, int32_t k, int ax)
{
    while (hi - lo > 1) {
        int32_t mid = lo + (hi - lo) / 2, a = idx[lo], b = idx[mid], c = idx[hi - 1], pv;
        if (less(pts, a, b, ax)) pv = less(pts, b, c, ax) ? b : (less(pts, a, c, ax) ? c : a);
        else pv = less(pts, a, c, ax) ? a : (less(pts, b, c, ax) ? c : b);
        /* three-way partition around pv: [lo, i) < pv, [i, j) == pv (one element), [j, hi) > pv */
        int32_t i = lo, j = lo, e = hi;
        while (j < e) {
            int32_t t = idx[j];
            if (t == pv) j++;
            else if (less(pts, t, pv, ax)) { idx[j] = idx[i]; idx[i] = t; i++; j++; }
            else { e--; idx[j] = idx[e]; idx[e] = t; }
        }
        if (k < i) hi = i;
        else if (k >= j) lo = j;
        else return;
    }
}

static void build(const wb_real *pts, int32_t *idx, uint8_t *axis, int32_t lo, int32_t hi)
{
    while (hi - lo > LEAF) {
        wb_real mn[3], mx[3];
        v3_copy(mn, &pts[3 * idx[lo]]);
        v3_copy(mx, mn);
        for (int32_t i = lo + 1; i < hi; i++)
            for (int c = 0; c < 3; c++) {
                wb_real x = pts[3 * idx[i] + c];
                if (x < mn[c]) mn[c] = x;
                if (x > mx[c]) mx[c] = x;
            }
        int ax = 0;
        for (int c = 1; c < 3; c++)
            if (mx[c] - mn[c] > mx[ax] - mn[ax]) ax = c;
        int32_t mid = lo + (hi - lo) / 2;
        select_kth(pts, idx, lo, hi, mid, ax);
        axis[mid] = (uint8_t)ax;
        build(pts, idx, axis, lo, mid);
        lo = mid + 1; /* the upper half iteratively: recursion depth stays log2(n) */
    }
}

wb_kdtree *wb_kdtree_build(const wb_real *pts, int32_t n)
{
    wb_kdtree *t = calloc(1, sizeof *t);
    if (!t) return NULL;
    size_t m = (size_t)(n > 0 ? n : 1);
    t->n = n > 0 ? n : 0;
    t->p = malloc(m * 3 * sizeof *t->p);
    t->id = malloc(m * sizeof *t->id);
    t->axis = calloc(m, 1);
    if (!t->p || !t->id || !t->axis) {
        wb_kdtree_destroy(t);
        return NULL;
    }
    for (int32_t i = 0; i < t->n; i++) t->id[i] = i;
    build(pts, t->id, t->axis, 0, t->n);
    for (int32_t i = 0; i < t->n; i++) v3_copy(&t->p[3 * i], &pts[3 * t->id[i]]);
    return t;
}

void wb_kdtree_destroy(wb_kdtree *t)
{
    if (!t) return;
    free(t->p);
    free(t->id);
    free(t->axis);
    free(t);
}

/* the k best so far, sorted by (dist2, id) */
typedef struct knn {
    int k, n;
    int32_t skip;   /* original index never offered (-1: none) */
    int32_t *id;
    wb_real *d2;
} knn;

static int worse(wb_real da, int32_t ia, wb_real db, int32_t ib) { return da > db || (da == db && ia > ib); }

static void offer(knn *r, wb_real d2, int32_t id)
{
    if (id == r->skip) return;
    if (r->n == r->k && !worse(r->d2[r->n - 1], r->id[r->n - 1], d2, id)) return;
    int i = r->n < r->k ? r->n++ : r->n - 1;
    while (i > 0 && worse(r->d2[i - 1], r->id[i - 1], d2, id)) {
        r->d2[i] = r->d2[i - 1];
        r->id[i] = r->id[i - 1];
        i--;
    }
    r->d2[i] = d2;
    r->id[i] = id;
}

static wb_real dist2(const wb_real *a, const wb_real *b)
{
    wb_real d[3];
    v3_sub(d, a, b);
    return v3_dot(d, d);
}

static void search(const wb_kdtree *t, const wb_real *q, int32_t lo, int32_t hi, knn *r)
{
    while (hi - lo > LEAF) {
        int32_t mid = lo + (hi - lo) / 2;
        int ax = t->axis[mid];
        const wb_real diff = q[ax] - t->p[3 * mid + ax];
        offer(r, dist2(q, &t->p[3 * mid]), t->id[mid]);
        /* the near side first, so the far side is usually pruned */
        int32_t nlo = lo, nhi = mid, flo = mid + 1, fhi = hi;
        if (diff >= 0) { nlo = mid + 1; nhi = hi; flo = lo; fhi = mid; }
        search(t, q, nlo, nhi, r);
        /* <=: a point on the splitting plane may tie with the worst kept */
        if (r->n == r->k && diff * diff > r->d2[r->n - 1]) return;
        lo = flo;
        hi = fhi;
    }
    for (int32_t i = lo; i < hi; i++) offer(r, dist2(q, &t->p[3 * i]), t->id[i]);
}

/* k is the capacity of ids and d2: never more than k are written, whatever ties there are */
int wb_kdtree_knn_except(const wb_kdtree *t, const wb_real q[3], int k, int32_t skip, int32_t *ids, wb_real *d2)
{
    int32_t id_buf[WB_KDTREE_MAXK];
    wb_real d_buf[WB_KDTREE_MAXK];
    if (k <= 0 || t->n == 0) return 0;
    if (k > WB_KDTREE_MAXK) k = WB_KDTREE_MAXK;
    knn r = { k, 0, skip, id_buf, d_buf };
    search(t, q, 0, t->n, &r);
    for (int i = 0; i < r.n; i++) {
        if (ids) ids[i] = r.id[i];
        if (d2) d2[i] = r.d2[i];
    }
    return r.n;
}

int wb_kdtree_knn(const wb_kdtree *t, const wb_real q[3], int k, int32_t *ids, wb_real *d2)
{
    return wb_kdtree_knn_except(t, q, k, -1, ids, d2);
}
