/* mesh.c: triangle meshes in memory: creation, welding by position, normals, edges and
 * vertex clustering. No file formats here (io/mesh.c reads and writes them). */
#include <float.h>
#include <stdlib.h>

#include "core.h"

static int fin3(const wb_real *v) { return isfinite(v[0]) && isfinite(v[1]) && isfinite(v[2]); }

static wb_mesh *mesh_alloc(int32_t nv, int32_t nt)
{
    wb_mesh *m = calloc(1, sizeof *m);
    if (!m) return NULL;
    m->v = malloc(sizeof *m->v * 3 * (size_t)(nv > 0 ? nv : 1));
    m->n = malloc(sizeof *m->n * 3 * (size_t)(nv > 0 ? nv : 1));
    m->tri = malloc(sizeof *m->tri * 3 * (size_t)(nt > 0 ? nt : 1));
    if (!m->v || !m->n || !m->tri) {
        wb_mesh_destroy(m);
        return NULL;
    }
    return m;
}

void wb_mesh_destroy(wb_mesh *m)
{
    if (!m) return;
    free(m->v);
    free(m->n);
    free(m->tri);
    free(m);
}

wb_mesh *wb_mesh_create(const wb_real *v, int32_t nv, const int32_t *tri, int32_t nt, wb_status *status)
{
    wb_status dummy;
    if (!status) status = &dummy;
    *status = WB_ERR_ARG;
    if (nv < 0 || nt < 0) { wb__set_error("negative vertex or triangle count"); return NULL; }
    if (nv > WB_MAX_PARTICLES || nt > WB_MAX_CONSTRAINTS) { *status = WB_ERR_LIMIT; return NULL; }
    for (int32_t i = 0; i < nv; i++)
        if (!fin3(&v[3 * i])) { wb__set_error("vertex %d is not finite", i + 1); return NULL; }
    for (int32_t i = 0; i < 3 * nt; i++)
        if (tri[i] < 0 || tri[i] >= nv) {
            wb__set_error("triangle %d: corner %d out of range (1..%d)", i / 3 + 1, tri[i] + 1, nv);
            return NULL;
        }
    wb_mesh *m = mesh_alloc(nv, nt);
    if (!m) { *status = WB_ERR_NOMEM; return NULL; }
    m->nv = nv;
    if (nv) memcpy(m->v, v, sizeof *v * 3 * (size_t)nv);
    /* a triangle repeating a corner has no area and no third edge: drop it */
    for (int32_t i = 0; i < nt; i++) {
        const int32_t *t = &tri[3 * i];
        if (t[0] == t[1] || t[1] == t[2] || t[0] == t[2]) continue;
        memcpy(&m->tri[3 * m->nt++], t, 3 * sizeof *t);
    }
    wb_mesh_compute_normals(m);
    *status = WB_OK;
    return m;
}

wb_mesh *wb_mesh_copy(const wb_mesh *src)
{
    wb_mesh *m = mesh_alloc(src->nv, src->nt);
    if (!m) return NULL;
    m->nv = src->nv;
    m->nt = src->nt;
    if (m->nv) {
        memcpy(m->v, src->v, sizeof *m->v * 3 * (size_t)m->nv);
        memcpy(m->n, src->n, sizeof *m->n * 3 * (size_t)m->nv);
    }
    if (m->nt) memcpy(m->tri, src->tri, sizeof *m->tri * 3 * (size_t)m->nt);
    return m;
}

/* a power of two s with (largest extent of the box) * s near 1, within [2^-1000, 2^1000]:
 * edges scaled by it neither overflow nor underflow in a cross product, and the scaling is
 * exact, so ordinary meshes get the same bits as unscaled */
static wb_real extent_scale(const wb_mesh *m)
{
    wb_real mn[3], mx[3], e = 0;
    if (!wb_mesh_bounds(m, mn, mx)) return 1;
    for (int c = 0; c < 3; c++) e = fmax(e, mx[c] / 2 - mn[c] / 2); /* halves: no overflow */
    if (!(e > 0) || !isfinite(e)) return 1;
    int ex;
    frexp(e, &ex);
    ex = ex < -1000 ? -1000 : ex > 1000 ? 1000 : ex;
    return ldexp(1, -ex);
}

void wb_mesh_compute_normals(wb_mesh *m)
{
    if (m->nv) memset(m->n, 0, sizeof *m->n * 3 * (size_t)m->nv);
    /* edges in units of the mesh's extent: a mesh of 1e-200 m (cross product underflows
     * to 0) or 1e200 m (overflows to inf, then inf/inf = NaN) gets the same unit normals
     * as one of 1 m */
    const wb_real s = extent_scale(m);
    /* the unnormalised face normal is twice the area times the unit normal: summing it
     * weights each face by its area, so many thin slivers do not outvote one big face */
    for (int32_t i = 0; i < m->nt; i++) {
        const int32_t *t = &m->tri[3 * i];
        const wb_real *a = &m->v[3 * t[0]], *b = &m->v[3 * t[1]], *c2 = &m->v[3 * t[2]];
        wb_real e1[3], e2[3], c[3];
        for (int k = 0; k < 3; k++) {
            /* scale before subtracting when shrinking (1e308 - -1e308 overflows), after when
             * growing (tiny coordinates far from the origin keep their difference) */
            e1[k] = s <= 1 ? b[k] * s - a[k] * s : (b[k] - a[k]) * s;
            e2[k] = s <= 1 ? c2[k] * s - a[k] * s : (c2[k] - a[k]) * s;
        }
        v3_cross(c, e1, e2);
        for (int k = 0; k < 3; k++) v3_add(&m->n[3 * t[k]], &m->n[3 * t[k]], c);
    }
    for (int32_t i = 0; i < m->nv; i++) {
        wb_real *n = &m->n[3 * i], l = v3_len(n);
        if (l > 0) v3_scale(n, n, 1 / l);
    }
}

bool wb_mesh_bounds(const wb_mesh *m, wb_real mn[3], wb_real mx[3])
{
    if (m->nv == 0) return false;
    v3_copy(mn, m->v);
    v3_copy(mx, m->v);
    for (int32_t i = 1; i < m->nv; i++)
        for (int c = 0; c < 3; c++) {
            wb_real x = m->v[3 * i + c];
            if (x < mn[c]) mn[c] = x;
            if (x > mx[c]) mx[c] = x;
        }
    return true;
}

wb_real wb_mesh_weld_tolerance(const wb_mesh *m)
{
    wb_real mn[3], mx[3];
    if (!wb_mesh_bounds(m, mn, mx)) return 0;
    const wb_real d[3] = { mx[0] - mn[0], mx[1] - mn[1], mx[2] - mn[2] };
    const wb_real dd = d[0] * d[0] + d[1] * d[1] + d[2] * d[2];
    if ((dd >= DBL_MIN && isfinite(dd)) || (d[0] == 0 && d[1] == 0 && d[2] == 0)) return 1e-6 * sqrt(dd);
    /* the diagonal squared underflows (a 1e-200 m mesh) or overflows (1e200 m): its length
     * without squaring, taking 1e-6 of it after when small (1e-6 first would lose a tiny
     * one's digits), first when large (a diagonal near the largest double overflows), and
     * of each corner first when the box itself overflows (1e308 - -1e308) */
    if (isfinite(d[0]) && isfinite(d[1]) && isfinite(d[2])) {
        if (dd < 1) return 1e-6 * v3_len_safe(d);
        const wb_real e[3] = { 1e-6 * d[0], 1e-6 * d[1], 1e-6 * d[2] };
        return v3_len_safe(e);
    }
    const wb_real e[3] = { 1e-6 * mx[0] - 1e-6 * mn[0], 1e-6 * mx[1] - 1e-6 * mn[1], 1e-6 * mx[2] - 1e-6 * mn[2] };
    return v3_len_safe(e);
}

void wb_mesh_transform(wb_mesh *m, wb_real scale, const wb_real offset[3])
{
    for (int32_t i = 0; i < m->nv; i++)
        for (int c = 0; c < 3; c++) m->v[3 * i + c] = m->v[3 * i + c] * scale + (offset ? offset[c] : 0);
    if (scale < 0) {
        /* a mirror turns the winding inside out: swap two corners to keep it outward */
        for (int32_t i = 0; i < m->nt; i++) {
            int32_t t = m->tri[3 * i + 1];
            m->tri[3 * i + 1] = m->tri[3 * i + 2];
            m->tri[3 * i + 2] = t;
        }
    }
    wb_mesh_compute_normals(m);
}

/* ---- a hash grid over vertices: welding and clustering -------------------------------- */
typedef struct grid {
    int32_t nb;       /* buckets, a power of two */
    int32_t *head;    /* (nb) first entry of each bucket, -1 = empty */
    int32_t *next;    /* (cap) chain */
    int64_t *cell;    /* (cap x 3) cell of each entry */
    int32_t *val;     /* (cap) payload */
    int32_t n;
} grid;

static int grid_init(grid *g, int32_t cap)
{
    memset(g, 0, sizeof *g);
    g->nb = 16;
    while (g->nb < 2 * cap && g->nb < (1 << 30)) g->nb *= 2;
    g->head = malloc(sizeof *g->head * (size_t)g->nb);
    g->next = malloc(sizeof *g->next * (size_t)(cap > 0 ? cap : 1));
    g->cell = malloc(sizeof *g->cell * 3 * (size_t)(cap > 0 ? cap : 1));
    g->val = malloc(sizeof *g->val * (size_t)(cap > 0 ? cap : 1));
    if (!g->head || !g->next || !g->cell || !g->val) return 0;
    for (int32_t i = 0; i < g->nb; i++) g->head[i] = -1;
    return 1;
}

static void grid_free(grid *g)
{
    free(g->head);
    free(g->next);
    free(g->cell);
    free(g->val);
}

static uint32_t grid_hash(const int64_t c[3], int32_t nb)
{
    uint64_t h = (uint64_t)c[0] * 73856093ull ^ (uint64_t)c[1] * 19349663ull ^ (uint64_t)c[2] * 83492791ull;
    h ^= h >> 29;
    h *= 0xbf58476d1ce4e5b9ull;
    h ^= h >> 32;
    return (uint32_t)(h & (uint64_t)(nb - 1));
}

static void grid_add(grid *g, const int64_t c[3], int32_t val)
{
    int32_t e = g->n++;
    uint32_t b = grid_hash(c, g->nb);
    memcpy(&g->cell[3 * e], c, 3 * sizeof *c);
    g->val[e] = val;
    g->next[e] = g->head[b];
    g->head[b] = e;
}

/* the cell of x for cell size h; h == 0 means "the exact position" (the bits themselves) */
static void cell_of(const wb_real *x, wb_real h, int64_t c[3])
{
    for (int k = 0; k < 3; k++) {
        if (h > 0) {
            c[k] = (int64_t)floor(x[k] / h);
        } else {
            double d = x[k] == 0 ? 0.0 : (double)x[k]; /* -0 and +0 are the same position */
            memcpy(&c[k], &d, sizeof d);
        }
    }
}

/* cell indices must fit an int64 for this h: else the caller falls back to exact */
static int cells_fit(const wb_mesh *m, wb_real h)
{
    wb_real mn[3], mx[3];
    if (!wb_mesh_bounds(m, mn, mx)) return 1;
    for (int c = 0; c < 3; c++)
        if (!(fabs(mn[c] / h) < 1e15 && fabs(mx[c] / h) < 1e15)) return 0;
    return 1;
}

wb_status wb_mesh_weld(wb_mesh *m, wb_real tol, int32_t *remap)
{
    if (!(tol >= 0) || !isfinite(tol)) { wb__set_error("weld tolerance must be >= 0"); return WB_ERR_ARG; }
    if (tol > 0 && !cells_fit(m, tol)) tol = 0;
    grid g;
    int32_t *map = malloc(sizeof *map * (size_t)(m->nv > 0 ? m->nv : 1));
    if (!map || !grid_init(&g, m->nv)) {
        free(map);
        grid_free(&g);
        return WB_ERR_NOMEM;
    }
    /* d.d <= tol^2 squares lengths: for a tolerance whose square leaves the normal range
     * (tol > 1e154 overflows, tol < 1e-154 underflows) compare in units of tol instead */
    const wb_real tol2 = tol * tol;
    const int scaled = tol > 0 && !(tol2 >= DBL_MIN && isfinite(tol2));
    const int32_t nv_old = m->nv;
    int32_t nv = 0;
    for (int32_t i = 0; i < m->nv; i++) {
        const wb_real *x = &m->v[3 * i];
        int64_t c[3];
        cell_of(x, tol, c);
        /* the lowest kept vertex within tol: the 27 cells around (only its own when exact) */
        int32_t best = -1;
        const int r = tol > 0 ? 1 : 0;
        for (int dz = -r; dz <= r; dz++)
            for (int dy = -r; dy <= r; dy++)
                for (int dx = -r; dx <= r; dx++) {
                    int64_t cc[3] = { c[0] + dx, c[1] + dy, c[2] + dz };
                    for (int32_t e = g.head[grid_hash(cc, g.nb)]; e >= 0; e = g.next[e]) {
                        if (memcmp(&g.cell[3 * e], cc, sizeof cc)) continue;
                        const int32_t k = g.val[e];
                        wb_real d[3];
                        const wb_real *y = &m->v[3 * k];
                        if (scaled) for (int q = 0; q < 3; q++) d[q] = y[q] / tol - x[q] / tol;
                        else v3_sub(d, y, x);
                        if ((tol > 0 ? v3_dot(d, d) <= (scaled ? 1 : tol2) : 1) && (best < 0 || k < best)) best = k;
                    }
                }
        if (best >= 0) {
            map[i] = best; /* best is already a kept (new) index */
            continue;
        }
        /* kept: move it down to its new place (nv <= i, so nothing unread is overwritten) */
        map[i] = nv;
        if (nv != i) v3_copy(&m->v[3 * nv], x);
        grid_add(&g, c, nv);
        nv++;
    }
    grid_free(&g);
    m->nv = nv;
    int32_t nt = 0;
    for (int32_t i = 0; i < m->nt; i++) {
        int32_t a = map[m->tri[3 * i]], b = map[m->tri[3 * i + 1]], c = map[m->tri[3 * i + 2]];
        if (a == b || b == c || a == c) continue;
        m->tri[3 * nt] = a;
        m->tri[3 * nt + 1] = b;
        m->tri[3 * nt + 2] = c;
        nt++;
    }
    m->nt = nt;
    if (remap && nv_old) memcpy(remap, map, sizeof *map * (size_t)nv_old);
    wb_mesh_compute_normals(m);
    free(map);
    return WB_OK;
}

/* ---- edges ------------------------------------------------------------------------------- */
static int cmp_u64(const void *a, const void *b)
{
    uint64_t x = *(const uint64_t *)a, y = *(const uint64_t *)b;
    return x < y ? -1 : x > y;
}

int32_t wb_mesh_edges(const wb_mesh *m, int32_t **ij)
{
    *ij = NULL;
    const size_t n = 3 * (size_t)m->nt;
    uint64_t *key = malloc(sizeof *key * (n > 0 ? n : 1));
    if (!key) return WB_ERR_NOMEM;
    for (int32_t i = 0; i < m->nt; i++)
        for (int k = 0; k < 3; k++) {
            uint32_t a = (uint32_t)m->tri[3 * i + k], b = (uint32_t)m->tri[3 * i + (k + 1) % 3];
            key[3 * (size_t)i + k] = a < b ? (uint64_t)a << 32 | b : (uint64_t)b << 32 | a;
        }
    qsort(key, n, sizeof *key, cmp_u64);
    size_t u = 0;
    for (size_t i = 0; i < n; i++)
        if (u == 0 || key[i] != key[u - 1]) key[u++] = key[i];
    int32_t *out = malloc(sizeof *out * 2 * (u > 0 ? u : 1));
    if (!out) { free(key); return WB_ERR_NOMEM; }
    for (size_t i = 0; i < u; i++) {
        out[2 * i] = (int32_t)(key[i] >> 32);
        out[2 * i + 1] = (int32_t)(key[i] & 0xffffffffu);
    }
    free(key);
    *ij = out;
    return (int32_t)u;
}

/* ---- vertex clustering (Rossignac and Borrel 1993) ------------------------------------- */
/* label the vertices by occupied cell of size h (anchored at the bounds' minimum);
 * returns the number of cells, or -1 when out of memory */
static int32_t label_cells(const wb_mesh *m, const wb_real mn[3], wb_real h, int32_t *cluster)
{
    grid g;
    if (!grid_init(&g, m->nv)) { grid_free(&g); return -1; }
    int32_t n = 0;
    for (int32_t i = 0; i < m->nv; i++) {
        wb_real r[3];
        int64_t c[3];
        v3_sub(r, &m->v[3 * i], mn);
        cell_of(r, h, c);
        int32_t found = -1;
        for (int32_t e = g.head[grid_hash(c, g.nb)]; e >= 0 && found < 0; e = g.next[e])
            if (!memcmp(&g.cell[3 * e], c, sizeof c)) found = g.val[e];
        if (found < 0) {
            found = n++;
            grid_add(&g, c, found);
        }
        if (cluster) cluster[i] = found;
    }
    grid_free(&g);
    return n;
}

int32_t wb_mesh_cluster(const wb_mesh *m, int32_t target, int32_t *cluster)
{
    if (target < 1) { wb__set_error("target must be >= 1"); return WB_ERR_ARG; }
    wb_real mn[3], mx[3], d[3];
    if (!wb_mesh_bounds(m, mn, mx)) return 0;
    v3_sub(d, mx, mn);
    if (!isfinite(d[0]) || !isfinite(d[1]) || !isfinite(d[2])) {
        /* an extent past the largest double: cluster a copy a quarter the size (a power of
         * two, so the cells come out the same; its extent is finite) rather than divide
         * infinities */
        wb_mesh *q = wb_mesh_copy(m);
        if (!q) return WB_ERR_NOMEM;
        for (int32_t i = 0; i < 3 * q->nv; i++) q->v[i] = ldexp(q->v[i], -2);
        const int32_t n = wb_mesh_cluster(q, target, cluster);
        wb_mesh_destroy(q);
        return n;
    }
    wb_real diag = v3_len(d);
    /* its square overflows or underflows, not it */
    if (!isfinite(diag) || (diag == 0 && (d[0] != 0 || d[1] != 0 || d[2] != 0))) diag = v3_len_safe(d);
    if (diag == 0 || target >= m->nv) {
        /* a single point is one cluster; a target past the vertex count keeps every vertex */
        for (int32_t i = 0; i < m->nv; i++) cluster[i] = diag == 0 ? 0 : i;
        return diag == 0 ? 1 : m->nv;
    }
    /* the occupied-cell count falls (roughly monotonically) as cells grow: bisect on
     * log h and keep the size whose count is closest to the target */
    wb_real lo = log(diag * 1e-7), hi = isfinite(diag * 1.01) ? log(diag * 1.01) : log(diag) + log(1.01), best_h = diag;
    int32_t best = -1;
    for (int it = 0; it < 48; it++) {
        const wb_real mid = (lo + hi) / 2, h = exp(mid);
        const int32_t n = label_cells(m, mn, h, NULL);
        if (n < 0) return WB_ERR_NOMEM;
        if (best < 0 || abs(n - target) < abs(best - target) || (abs(n - target) == abs(best - target) && h > best_h)) {
            best = n;
            best_h = h;
        }
        if (n == target) break;
        if (n > target) lo = mid;
        else hi = mid;
    }
    const int32_t n = label_cells(m, mn, best_h, cluster);
    return n < 0 ? WB_ERR_NOMEM : n;
}
