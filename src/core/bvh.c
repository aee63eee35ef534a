/* bvh.c: a mesh collider's triangles: an AABB tree built once in the collider's own
 * frame, the closest point on it (Ericson's region method per triangle, boxes farther
 * than the best so far pruned), and the sign of the distance from angle-weighted
 * pseudo-normals (Bærentzen & Aanæs 2005: the pseudo-normal of the feature the closest
 * point lies on - face, edge or vertex - gives the right sign for a closed mesh, where a
 * face normal alone fails near edges and vertices). */
#include <stdlib.h>

#include "core.h"
#include "bvh.h"

#define LEAF_SIZE 4
#define STACK_MAX 128 /* median splits: depth about log2(nt / LEAF_SIZE) */

static wb_real sqr(wb_real x) { return x * x; }

/* ---- closest point on a triangle -------------------------------------------------------- */
static wb_real closest_on_segment(const wb_real p[3], const wb_real a[3], const wb_real b[3], wb_real out[3])
{
    wb_real ab[3], ap[3], d[3];
    v3_sub(ab, b, a);
    v3_sub(ap, p, a);
    const wb_real ll = v3_dot(ab, ab);
    const wb_real t = ll > 0 ? clampr(v3_dot(ap, ab) / ll, 0, 1) : 0;
    v3_copy(out, a);
    v3_madd(out, ab, t);
    v3_sub(d, p, out);
    return v3_dot(d, d);
}

wb_real wb__closest_on_triangle(const wb_real p[3], const wb_real a[3], const wb_real b[3], const wb_real c[3],
                                wb_real out[3], int *region)
{
    wb_real ab[3], ac[3], ap[3], bp[3], cp[3], d[3];
    v3_sub(ab, b, a);
    v3_sub(ac, c, a);
    v3_sub(ap, p, a);
    const wb_real d1 = v3_dot(ab, ap), d2 = v3_dot(ac, ap);
    if (d1 <= 0 && d2 <= 0) { v3_copy(out, a); *region = WB_REGION_V0; goto done; }
    v3_sub(bp, p, b);
    const wb_real d3 = v3_dot(ab, bp), d4 = v3_dot(ac, bp);
    if (d3 >= 0 && d4 <= d3) { v3_copy(out, b); *region = WB_REGION_V1; goto done; }
    const wb_real vc = d1 * d4 - d3 * d2;
    if (vc <= 0 && d1 >= 0 && d3 <= 0) {
        v3_copy(out, a);
        v3_madd(out, ab, d1 / (d1 - d3));
        *region = WB_REGION_E01;
        goto done;
    }
    v3_sub(cp, p, c);
    const wb_real d5 = v3_dot(ab, cp), d6 = v3_dot(ac, cp);
    if (d6 >= 0 && d5 <= d6) { v3_copy(out, c); *region = WB_REGION_V2; goto done; }
    const wb_real vb = d5 * d2 - d1 * d6;
    if (vb <= 0 && d2 >= 0 && d6 <= 0) {
        v3_copy(out, a);
        v3_madd(out, ac, d2 / (d2 - d6));
        *region = WB_REGION_E20;
        goto done;
    }
    const wb_real va = d3 * d6 - d5 * d4;
    if (va <= 0 && d4 - d3 >= 0 && d5 - d6 >= 0) {
        wb_real bc[3];
        v3_sub(bc, c, b);
        v3_copy(out, b);
        v3_madd(out, bc, (d4 - d3) / ((d4 - d3) + (d5 - d6)));
        *region = WB_REGION_E12;
        goto done;
    }
    const wb_real sum = va + vb + vc;
    if (!(sum > 0)) {
        /* a degenerate (collinear) triangle: its nearest edge */
        wb_real q[3];
        wb_real best = closest_on_segment(p, a, b, out), e;
        *region = WB_REGION_E01;
        if ((e = closest_on_segment(p, b, c, q)) < best) { best = e; v3_copy(out, q); *region = WB_REGION_E12; }
        if ((e = closest_on_segment(p, c, a, q)) < best) { best = e; v3_copy(out, q); *region = WB_REGION_E20; }
        return best;
    }
    {
        const wb_real v = vb / sum, w = vc / sum;
        v3_copy(out, a);
        v3_madd(out, ab, v);
        v3_madd(out, ac, w);
        *region = WB_REGION_FACE;
    }
done:
    v3_sub(d, p, out);
    return v3_dot(d, d);
}

/* ---- build ------------------------------------------------------------------------------- */
typedef struct edge_rec { int32_t lo, hi, t, k; } edge_rec;

static int cmp_edge(const void *pa, const void *pb)
{
    const edge_rec *a = pa, *b = pb;
    if (a->lo != b->lo) return a->lo < b->lo ? -1 : 1;
    if (a->hi != b->hi) return a->hi < b->hi ? -1 : 1;
    if (a->t != b->t) return a->t < b->t ? -1 : 1;
    return (a->k > b->k) - (a->k < b->k);
}

typedef struct sort_ctx { const wb_real *cen; int axis; } sort_ctx;

static int cmp_centroid(const void *pa, const void *pb, void *ud)
{
    const sort_ctx *s = ud;
    const int32_t a = *(const int32_t *)pa, b = *(const int32_t *)pb;
    const wb_real ca = s->cen[3 * a + s->axis], cb = s->cen[3 * b + s->axis];
    if (ca != cb) return ca < cb ? -1 : 1;
    return (a > b) - (a < b); /* ties by index: the tree never depends on qsort's order */
}

static void tri_box(const wb_colmesh *cm, int32_t t, wb_real lo[3], wb_real hi[3])
{
    for (int k = 0; k < 3; k++) {
        const wb_real *v = &cm->v[3 * cm->tri[3 * t + k]];
        for (int i = 0; i < 3; i++) {
            if (k == 0 || v[i] < lo[i]) lo[i] = v[i];
            if (k == 0 || v[i] > hi[i]) hi[i] = v[i];
        }
    }
}

/* node `ni` over order[first, first + n): a leaf, or two children made next to each other */
static void build_node(wb_colmesh *cm, const wb_real *cen, int32_t ni, int32_t first, int32_t n, int depth)
{
    wb_bvh_node *nd = &cm->nodes[ni];
    wb_real clo[3], chi[3];
    for (int32_t j = 0; j < n; j++) {
        wb_real lo[3], hi[3];
        const int32_t t = cm->order[first + j];
        tri_box(cm, t, lo, hi);
        for (int i = 0; i < 3; i++) {
            if (j == 0 || lo[i] < nd->lo[i]) nd->lo[i] = lo[i];
            if (j == 0 || hi[i] > nd->hi[i]) nd->hi[i] = hi[i];
            if (j == 0 || cen[3 * t + i] < clo[i]) clo[i] = cen[3 * t + i];
            if (j == 0 || cen[3 * t + i] > chi[i]) chi[i] = cen[3 * t + i];
        }
    }
    if (n <= LEAF_SIZE || depth >= STACK_MAX / 2 - 2) {
        nd->left = first;
        nd->count = n;
        return;
    }
    /* median split along the longest extent of the centroids */
    sort_ctx s = { cen, 0 };
    for (int i = 1; i < 3; i++)
        if (chi[i] - clo[i] > chi[s.axis] - clo[s.axis]) s.axis = i;
    qsort_r(&cm->order[first], (size_t)n, sizeof(int32_t), cmp_centroid, &s);
    const int32_t left = cm->nnodes;
    cm->nnodes += 2;
    nd->left = left;
    nd->count = 0;
    build_node(cm, cen, left, first, n / 2, depth + 1);
    build_node(cm, cen, left + 1, first + n / 2, n - n / 2, depth + 1);
}

void wb__colmesh_free(wb_colmesh *cm)
{
    if (!cm) return;
    free(cm->v);
    free(cm->tri);
    free(cm->fn);
    free(cm->en);
    free(cm->vn);
    free(cm->nodes);
    free(cm->order);
    free(cm);
}

wb_colmesh *wb__colmesh_build(const wb_real *v, int32_t nv, const int32_t *tri, int32_t nt, wb_real scale)
{
    wb_colmesh *cm = calloc(1, sizeof *cm);
    if (!cm) return NULL;
    cm->nv = nv;
    cm->nt = nt;
    const size_t snv = (size_t)(nv > 0 ? nv : 1), snt = (size_t)(nt > 0 ? nt : 1);
    cm->v = malloc(3 * snv * sizeof(wb_real));
    cm->tri = malloc(3 * snt * sizeof(int32_t));
    cm->fn = calloc(3 * snt, sizeof(wb_real));
    cm->en = calloc(9 * snt, sizeof(wb_real));
    cm->vn = calloc(3 * snv, sizeof(wb_real));
    cm->nodes = calloc(2 * snt, sizeof(wb_bvh_node));
    cm->order = malloc(snt * sizeof(int32_t));
    wb_real *cen = malloc(3 * snt * sizeof(wb_real));
    edge_rec *er = malloc(3 * snt * sizeof(edge_rec));
    if (!cm->v || !cm->tri || !cm->fn || !cm->en || !cm->vn || !cm->nodes || !cm->order || !cen || !er) {
        free(cen);
        free(er);
        wb__colmesh_free(cm);
        return NULL;
    }
    cm->bytes = sizeof *cm + snv * 6 * sizeof(wb_real) + snt * (12 * sizeof(wb_real) + 4 * sizeof(int32_t)) +
                2 * snt * sizeof(wb_bvh_node);
    for (int64_t i = 0; i < 3 * (int64_t)nv; i++) cm->v[i] = scale == 1 ? v[i] : v[i] * scale;
    memcpy(cm->tri, tri, 3 * (size_t)nt * sizeof(int32_t));
    /* face normals, vertex pseudo-normals (angle-weighted), centroids, edges */
    for (int32_t t = 0; t < nt; t++) {
        const int32_t *c = &cm->tri[3 * t];
        const wb_real *p[3] = { &cm->v[3 * c[0]], &cm->v[3 * c[1]], &cm->v[3 * c[2]] };
        wb_real e1[3], e2[3], n[3];
        v3_sub(e1, p[1], p[0]);
        v3_sub(e2, p[2], p[0]);
        v3_cross(n, e1, e2);
        const wb_real len = v3_len_safe(n);
        if (len > 0 && isfinite(len)) v3_scale(&cm->fn[3 * t], n, 1 / len);
        for (int k = 0; k < 3; k++) {
            wb_real u[3], w[3];
            v3_sub(u, p[(k + 1) % 3], p[k]);
            v3_sub(w, p[(k + 2) % 3], p[k]);
            const wb_real lu = v3_len_safe(u), lw = v3_len_safe(w);
            if (lu > 0 && lw > 0) {
                const wb_real ang = acos(clampr(v3_dot(u, w) / lu / lw, -1, 1));
                v3_madd(&cm->vn[3 * c[k]], &cm->fn[3 * t], ang);
            }
            cen[3 * t + k] = (p[0][k] + p[1][k] + p[2][k]) / 3;
            const int32_t a = c[k], b = c[(k + 1) % 3];
            edge_rec r = { a < b ? a : b, a < b ? b : a, t, k };
            er[3 * t + k] = r;
        }
    }
    /* edge pseudo-normals: the sum of the normals of the faces sharing the edge */
    qsort(er, 3 * (size_t)nt, sizeof *er, cmp_edge);
    cm->closed = nt > 0;
    for (int64_t i = 0; i < 3 * (int64_t)nt;) {
        int64_t j = i;
        wb_real s[3] = { 0, 0, 0 };
        while (j < 3 * (int64_t)nt && er[j].lo == er[i].lo && er[j].hi == er[i].hi) {
            v3_add(s, s, &cm->fn[3 * er[j].t]);
            j++;
        }
        if (j - i != 2) cm->closed = 0;
        for (int64_t k = i; k < j; k++) v3_copy(&cm->en[9 * er[k].t + 3 * er[k].k], s);
        i = j;
    }
    free(er);
    for (int32_t t = 0; t < nt; t++) cm->order[t] = t;
    cm->nnodes = 1;
    if (nt > 0) build_node(cm, cen, 0, 0, nt, 0);
    free(cen);
    return cm;
}

/* ---- queries ------------------------------------------------------------------------------ */
static wb_real box_d2(const wb_bvh_node *n, const wb_real p[3])
{
    wb_real d = 0;
    for (int i = 0; i < 3; i++) {
        if (p[i] < n->lo[i]) d += sqr(n->lo[i] - p[i]);
        else if (p[i] > n->hi[i]) d += sqr(p[i] - n->hi[i]);
    }
    return d;
}

static void try_tri(const wb_colmesh *cm, int32_t t, const wb_real p[3], wb_real *best, wb_real c[3], int32_t *bt,
                    int *region)
{
    const int32_t *k = &cm->tri[3 * t];
    wb_real q[3];
    int r;
    const wb_real d2 = wb__closest_on_triangle(p, &cm->v[3 * k[0]], &cm->v[3 * k[1]], &cm->v[3 * k[2]], q, &r);
    /* ties go to the lower triangle: the tree and brute force agree exactly */
    if (d2 < *best || (d2 == *best && *bt >= 0 && t < *bt)) {
        *best = d2;
        *bt = t;
        *region = r;
        v3_copy(c, q);
    }
}

wb_real wb__colmesh_closest_brute(const wb_colmesh *cm, const wb_real p[3], wb_real c[3], int32_t *t, int *region)
{
    wb_real best = INFINITY;
    *t = -1;
    *region = 0;
    for (int32_t i = 0; i < cm->nt; i++) try_tri(cm, i, p, &best, c, t, region);
    return best;
}

/* bounded: only triangles within sqrt(max_d2) count; *t = -1 when none is */
static wb_real closest_within(const wb_colmesh *cm, const wb_real p[3], wb_real max_d2, wb_real c[3], int32_t *t,
                              int *region)
{
    wb_real best = max_d2;
    *t = -1;
    *region = 0;
    if (cm->nt == 0) return best;
    int32_t stack[STACK_MAX];
    int sp = 0;
    stack[sp++] = 0;
    while (sp > 0) {
        const wb_bvh_node *n = &cm->nodes[stack[--sp]];
        /* boxes strictly farther than the best cannot hold a closer or tying triangle */
        if (box_d2(n, p) > best) continue;
        if (n->count > 0) {
            for (int32_t j = 0; j < n->count; j++) try_tri(cm, cm->order[n->left + j], p, &best, c, t, region);
            continue;
        }
        /* the nearer child on top, so it is searched first and prunes more */
        const wb_real dl = box_d2(&cm->nodes[n->left], p), dr = box_d2(&cm->nodes[n->left + 1], p);
        if (dl <= dr) { stack[sp++] = n->left + 1; stack[sp++] = n->left; }
        else { stack[sp++] = n->left; stack[sp++] = n->left + 1; }
    }
    return best;
}

wb_real wb__colmesh_closest(const wb_colmesh *cm, const wb_real p[3], wb_real c[3], int32_t *t, int *region)
{
    return closest_within(cm, p, INFINITY, c, t, region);
}

void wb__colmesh_pseudo_normal(const wb_colmesh *cm, int32_t t, int region, wb_real n[3])
{
    switch (region) {
    case WB_REGION_V0: case WB_REGION_V1: case WB_REGION_V2:
        v3_copy(n, &cm->vn[3 * cm->tri[3 * t + region - WB_REGION_V0]]);
        break;
    case WB_REGION_E01: case WB_REGION_E12: case WB_REGION_E20:
        v3_copy(n, &cm->en[9 * t + 3 * (region - WB_REGION_E01)]);
        break;
    default:
        v3_copy(n, &cm->fn[3 * t]);
        break;
    }
}

/* the unit direction out of the surface: from the closest point, or the pseudo-normal when
 * p lies on the surface (then p - c says nothing) */
static void out_dir(const wb_real p[3], const wb_real c[3], wb_real d, const wb_real pn[3], wb_real sign, wb_real n[3])
{
    const wb_real lp = v3_len_safe(pn);
    if (d > 1e-12 * (1 + v3_len_safe(c))) {
        wb_real u[3];
        v3_sub(u, p, c);
        v3_scale(n, u, sign / d);
    } else if (lp > 0) {
        v3_scale(n, pn, 1 / lp);
    } else {
        v3_set(n, 0, 1, 0);
    }
}

wb_real wb__colmesh_distance(const wb_colmesh *cm, const wb_real p[3], wb_real n[3], wb_real c[3], wb_real pn[3])
{
    return wb__colmesh_distance_tri(cm, p, n, c, pn, NULL);
}

wb_real wb__colmesh_distance_tri(const wb_colmesh *cm, const wb_real p[3], wb_real n[3], wb_real c[3], wb_real pn[3],
                                 int32_t *tri)
{
    wb_real q[3], nn[3], pnn[3];
    int32_t t;
    int region;
    const wb_real d2 = closest_within(cm, p, INFINITY, q, &t, &region);
    if (tri) *tri = t;
    if (t < 0) {
        if (n) v3_set(n, 0, 1, 0);
        return INFINITY;
    }
    wb__colmesh_pseudo_normal(cm, t, region, pnn);
    const wb_real d = sqrt(d2);
    wb_real u[3];
    v3_sub(u, p, q);
    const wb_real sign = cm->closed && v3_dot(u, pnn) < 0 ? -1 : 1;
    out_dir(p, q, d, pnn, sign, nn);
    if (n) v3_copy(n, nn);
    if (c) v3_copy(c, q);
    if (pn) v3_copy(pn, pnn);
    return sign * d;
}

/* the collision query: closest point within sqrt(max_d2) (contacts need nothing farther) */
wb_real wb__colmesh_closest_within(const wb_colmesh *cm, const wb_real p[3], wb_real max_d2, wb_real c[3], int32_t *t,
                                   int *region)
{
    return closest_within(cm, p, max_d2, c, t, region);
}
