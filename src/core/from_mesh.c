/* from_mesh.c: a particle graph from a mesh (the reference thesis's first import method):
 * a particle per welded vertex and a distance constraint per edge, or, with a target
 * count, a coarser graph by vertex clustering for use as a skinning cage. Like the other
 * builders it checks everything and reserves all memory first, so a failure changes
 * nothing. */
#include <stdlib.h>

#include "core.h"

wb_from_mesh_def wb_from_mesh_default_def(void)
{
    wb_from_mesh_def d;
    memset(&d, 0, sizeof d);
    d.mass = 1;
    d.radius = 0.02;
    d.surface = true;
    d.link = wb_distance_default_def();
    return d;
}

static wb_status bad(const char *msg)
{
    wb__set_error("%s", msg);
    return WB_ERR_ARG;
}

static int cmp_u64(const void *a, const void *b)
{
    uint64_t x = *(const uint64_t *)a, y = *(const uint64_t *)b;
    return x < y ? -1 : x > y;
}

static uint64_t pair_key(int32_t a, int32_t b)
{
    return a < b ? (uint64_t)(uint32_t)a << 32 | (uint32_t)b : (uint64_t)(uint32_t)b << 32 | (uint32_t)a;
}

/* sort and drop repeats; returns the new length */
static size_t unique_u64(uint64_t *k, size_t n)
{
    qsort(k, n, sizeof *k, cmp_u64);
    size_t u = 0;
    for (size_t i = 0; i < n; i++)
        if (u == 0 || k[i] != k[u - 1]) k[u++] = k[i];
    return u;
}

/* the graph to build, before anything touches the world */
typedef struct plan {
    int32_t np;
    wb_real *pos;     /* (np x 3) */
    int32_t ntri;
    int32_t *tri;     /* (ntri x 3) over the new particles */
    size_t nd;
    uint64_t *pairs;  /* (nd) sorted a<<32|b */
} plan;

static void plan_free(plan *p)
{
    free(p->pos);
    free(p->tri);
    free(p->pairs);
}

typedef struct tri_key { int32_t c[3], index; } tri_key;

static int cmp_tri(const void *a, const void *b)
{
    const tri_key *x = a, *y = b;
    for (int k = 0; k < 3; k++)
        if (x->c[k] != y->c[k]) return x->c[k] < y->c[k] ? -1 : 1;
    return (x->index > y->index) - (x->index < y->index);
}

static void sort3(int32_t *c)
{
    int32_t t;
    if (c[0] > c[1]) { t = c[0]; c[0] = c[1]; c[1] = t; }
    if (c[1] > c[2]) { t = c[1]; c[1] = c[2]; c[2] = t; }
    if (c[0] > c[1]) { t = c[0]; c[0] = c[1]; c[1] = t; }
}

/* with clustering several fine triangles map to one coarse triangle: keep the first of
 * each set of corners (in mesh order, so the winding is the first one's) */
static wb_status drop_repeated_triangles(plan *p)
{
    tri_key *k = malloc(sizeof *k * (size_t)(p->ntri > 0 ? p->ntri : 1));
    uint8_t *drop = calloc((size_t)(p->ntri > 0 ? p->ntri : 1), 1);
    if (!k || !drop) { free(k); free(drop); return WB_ERR_NOMEM; }
    for (int32_t i = 0; i < p->ntri; i++) {
        memcpy(k[i].c, &p->tri[3 * i], sizeof k[i].c);
        sort3(k[i].c);
        k[i].index = i;
    }
    qsort(k, (size_t)p->ntri, sizeof *k, cmp_tri);
    for (int32_t i = 1; i < p->ntri; i++)
        if (!memcmp(k[i].c, k[i - 1].c, sizeof k[i].c)) drop[k[i].index] = 1;
    int32_t n = 0;
    for (int32_t i = 0; i < p->ntri; i++)
        if (!drop[i]) memmove(&p->tri[3 * n++], &p->tri[3 * i], 3 * sizeof *p->tri);
    p->ntri = n;
    free(k);
    free(drop);
    return WB_OK;
}

/* particles: the vertices, or the centroids of their clusters; triangles mapped over them */
static wb_status plan_particles(const wb_mesh *m, int32_t target, plan *p)
{
    int32_t *cl = malloc(sizeof *cl * (size_t)m->nv);
    int32_t *cnt = NULL;
    wb_status st = WB_ERR_NOMEM;
    p->tri = malloc(sizeof *p->tri * 3 * (size_t)(m->nt > 0 ? m->nt : 1));
    if (!cl || !p->tri) goto out;
    int32_t n = m->nv;
    if (target > 0) {
        n = wb_mesh_cluster(m, target, cl);
        if (n < 0) { st = (wb_status)n; goto out; }
    } else {
        for (int32_t i = 0; i < m->nv; i++) cl[i] = i;
    }
    p->np = n;
    p->pos = calloc((size_t)n * 3, sizeof *p->pos);
    cnt = calloc((size_t)n, sizeof *cnt);
    int32_t *lead = malloc(sizeof *lead * (size_t)n);
    if (!p->pos || !cnt || !lead) { free(lead); goto out; }
    /* the centroid as the cluster's first vertex plus the mean offset from it: a plain sum
     * of vertices near 1e308 overflows although the cluster is small */
    for (int32_t c = 0; c < n; c++) lead[c] = -1;
    for (int32_t i = 0; i < m->nv; i++) {
        const int32_t c = cl[i];
        if (lead[c] < 0) lead[c] = i;
        wb_real r[3];
        v3_sub(r, &m->v[3 * i], &m->v[3 * lead[c]]);
        v3_add(&p->pos[3 * c], &p->pos[3 * c], r);
        cnt[c]++;
    }
    for (int32_t c = 0; c < n; c++) {
        wb_real *x = &p->pos[3 * c];
        v3_scale(x, x, 1 / (wb_real)cnt[c]);
        v3_add(x, x, &m->v[3 * lead[c]]);
    }
    free(lead);
    int32_t nt = 0;
    for (int32_t i = 0; i < m->nt; i++) {
        int32_t a = cl[m->tri[3 * i]], b = cl[m->tri[3 * i + 1]], c = cl[m->tri[3 * i + 2]];
        if (a == b || b == c || a == c) continue; /* collapsed inside a cluster */
        p->tri[3 * nt] = a;
        p->tri[3 * nt + 1] = b;
        p->tri[3 * nt + 2] = c;
        nt++;
    }
    p->ntri = nt;
    st = target > 0 ? drop_repeated_triangles(p) : WB_OK;
out:
    free(cl);
    free(cnt);
    return st;
}

/* links: the triangles' edges, plus each particle's k nearest when asked */
static wb_status plan_links(plan *p, int k)
{
    const size_t ne = 3 * (size_t)p->ntri, nk = (size_t)p->np * (size_t)k;
    p->pairs = malloc(sizeof *p->pairs * (ne + nk > 0 ? ne + nk : 1));
    if (!p->pairs) return WB_ERR_NOMEM;
    size_t n = 0;
    for (int32_t i = 0; i < p->ntri; i++)
        for (int c = 0; c < 3; c++) p->pairs[n++] = pair_key(p->tri[3 * i + c], p->tri[3 * i + (c + 1) % 3]);
    if (k > 0 && p->np > 1) {
        wb_kdtree *t = wb_kdtree_build(p->pos, p->np);
        if (!t) return WB_ERR_NOMEM;
        int32_t ids[32]; /* k <= 32, checked by the caller; at most k per particle fit pairs */
        for (int32_t i = 0; i < p->np; i++) {
            int got = wb_kdtree_knn_except(t, &p->pos[3 * i], k, i, ids, NULL);
            for (int j = 0; j < got; j++) p->pairs[n++] = pair_key(i, ids[j]);
        }
        wb_kdtree_destroy(t);
    }
    p->nd = unique_u64(p->pairs, n);
    return WB_OK;
}

/* what the plan derives obeys the builders' rules (builders.c): finite positions, a
 * bounding box whose diagonal squared is finite (so no link's length squared, and no
 * rest length, overflows), a mass per particle with a finite inverse */
static wb_status check_plan(const plan *p, wb_real mass)
{
    wb_real mn[3] = { INFINITY, INFINITY, INFINITY }, mx[3] = { -INFINITY, -INFINITY, -INFINITY };
    for (int32_t i = 0; i < p->np; i++)
        for (int c = 0; c < 3; c++) {
            const wb_real x = p->pos[3 * i + c];
            if (!isfinite(x)) return bad("a particle position is not finite (the mesh's extent overflows)");
            mn[c] = fmin(mn[c], x);
            mx[c] = fmax(mx[c], x);
        }
    wb_real dd = 0;
    for (int c = 0; c < 3; c++) dd += (mx[c] - mn[c]) * (mx[c] - mn[c]);
    if (!isfinite(dd)) return bad("the mesh is too large (its extent squared overflows; links need finite squared lengths)");
    const wb_real pm = mass / (wb_real)p->np;
    if (!(pm > 0) || !isfinite(1 / pm)) {
        wb__set_error("mass: %g over %d particles is %g each, too small (its inverse overflows)", (double)mass,
                      (int)p->np, (double)pm);
        return WB_ERR_ARG;
    }
    return WB_OK;
}

wb_status wb_from_mesh(wb_world *w, const wb_mesh *m, const wb_from_mesh_def *d, wb_body *out)
{
    if (!(d->mass > 0) || !isfinite(d->mass)) return bad("mass must be > 0");
    if (!(d->radius >= 0) || !isfinite(d->radius)) return bad("radius must be >= 0");
    const char *e = wb_distance_def_check(&d->link);
    if (e) return bad(e);
    if (d->target < 0) return bad("target must be >= 0");
    if (d->neighbours < 0 || d->neighbours > 32) return bad("neighbours must be in 0..32");
    if (m->nv == 0) return bad("the mesh has no vertices");
    if (m->nv > WB_MAX_PARTICLES) return WB_ERR_LIMIT;
    /* the core asserts finite particle positions: refuse here, with the vertex named */
    for (int32_t i = 0; i < 3 * m->nv; i++)
        if (!isfinite(m->v[i])) {
            wb__set_error("mesh vertex %d is not finite", i / 3 + 1);
            return WB_ERR_ARG;
        }

    /* a particle per welded vertex: a flat-shaded mesh repeats a corner per face, and
     * unwelded it would fall apart into loose triangles (a copy, the caller's mesh stays) */
    wb_mesh *wm = wb_mesh_copy(m);
    if (!wm) return WB_ERR_NOMEM;
    wb_status st = wb_mesh_weld(wm, wb_mesh_weld_tolerance(wm), NULL);
    if (st != WB_OK) {
        wb_mesh_destroy(wm);
        return st;
    }
    plan p;
    memset(&p, 0, sizeof p);
    st = plan_particles(wm, d->target, &p);
    wb_mesh_destroy(wm);
    if (st == WB_OK) st = check_plan(&p, d->mass);
    if (st == WB_OK) st = plan_links(&p, d->neighbours);
    if (st == WB_OK && p.nd > (size_t)WB_MAX_CONSTRAINTS) st = WB_ERR_LIMIT;
    if (st == WB_OK) st = wb__reserve(w, p.np, (int64_t)p.nd);
    if (st == WB_OK && d->surface && p.ntri > 0) st = wb__surface_reserve(w, p.ntri);
    if (st != WB_OK) {
        plan_free(&p);
        return st;
    }
    /* from here on nothing can fail */
    const int32_t first = w->m.np;
    const wb_real pm = d->mass / (wb_real)p.np;
    for (int32_t i = 0; i < p.np; i++) wb_particle_add(w, &p.pos[3 * i], NULL, pm, d->radius);
    wb_distance_def link = d->link;
    link.rest = -1; /* the mesh's own lengths */
    for (size_t i = 0; i < p.nd; i++) {
        const int32_t a = (int32_t)(p.pairs[i] >> 32), b = (int32_t)(p.pairs[i] & 0xffffffffu);
        wb_distance_add(w, first + a, first + b, &link, NULL);
    }
    if (d->surface && p.ntri > 0) {
        for (int32_t i = 0; i < 3 * p.ntri; i++) p.tri[i] += first;
        wb_surface_add(w, p.tri, p.ntri);
    }
    plan_free(&p);
    return wb__body_finish(w, first, p.np, out);
}
