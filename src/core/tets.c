/* tets.c: tetrahedral solids: the lattice's cells split into tets (Kuhn), a body built
 * from a tet mesh (tetgen's output or a .node/.ele pair), and the closedness check a
 * mesh must pass before it is filled. The volume constraints themselves: volume.c. */
#include <stdlib.h>

#include "core.h"
#include "volume.h"
#include "tet.h"

/* ---- the lattice's cells --------------------------------------------------------------- */
/* Kuhn's split of a cell into the 6 tets around its main diagonal 0 -> 7 (corner c at
 * base + (c&1) sx + (c&2) sy + (c&4) sz): one per order of the axes, corners 0, a, a|b, 7.
 * Every cell is split alike, so a face shared by two cells is cut along the same diagonal
 * (from its lowest to its highest corner) on both sides: the tets of neighbouring cells
 * meet face to face. Each is turned positive (two corners swapped) whatever the axes'
 * handedness, so all of them keep the same sign. Space reserved by the caller. */
void wb__kuhn_tets(wb_world *w, int32_t base, int32_t sx, int32_t sy, int32_t sz, wb_real alpha,
                   wb_real young, wb_real poisson)
{
    static const int perm[6][3] = { { 1, 2, 4 }, { 1, 4, 2 }, { 2, 1, 4 }, { 2, 4, 1 }, { 4, 1, 2 }, { 4, 2, 1 } };
    const wb_real *x = w->s.x;
    for (int t = 0; t < 6; t++) {
        const int c[4] = { 0, perm[t][0], perm[t][0] | perm[t][1], 7 };
        int32_t p[4];
        for (int k = 0; k < 4; k++) p[k] = base + (c[k] & 1 ? sx : 0) + (c[k] & 2 ? sy : 0) + (c[k] & 4 ? sz : 0);
        wb_real v = wb_tet_signed_volume(&x[3 * p[0]], &x[3 * p[1]], &x[3 * p[2]], &x[3 * p[3]]);
        if (v < 0) {
            int32_t s = p[2]; p[2] = p[3]; p[3] = s;
            v = -v;
        }
        if (young > 0) wb__tet_put_current(w, p, young, poisson); /* a lattice cell is never flat */
        else wb__volume_put(w, p, alpha, v);
    }
}

/* ---- closed meshes -------------------------------------------------------------------------- */
static int cmp_u64(const void *a, const void *b)
{
    const uint64_t x = *(const uint64_t *)a, y = *(const uint64_t *)b;
    return x < y ? -1 : x > y;
}

static uint64_t edge_key(int32_t a, int32_t b)
{
    return a < b ? (uint64_t)a << 32 | (uint32_t)b : (uint64_t)b << 32 | (uint32_t)a;
}

int32_t wb_mesh_open_edges(const wb_mesh *m, int32_t *a, int32_t *b)
{
    if (m->nt == 0) return 0;
    uint64_t *k = malloc(sizeof *k * 3 * (size_t)m->nt);
    if (!k) return WB_ERR_NOMEM;
    for (int32_t t = 0; t < m->nt; t++)
        for (int e = 0; e < 3; e++) k[3 * t + e] = edge_key(m->tri[3 * t + e], m->tri[3 * t + (e + 1) % 3]);
    const int64_t n = 3 * (int64_t)m->nt;
    qsort(k, (size_t)n, sizeof *k, cmp_u64);
    int32_t open = 0;
    for (int64_t i = 0; i < n;) {
        int64_t j = i;
        while (j < n && k[j] == k[i]) j++;
        if (j - i != 2) {
            if (open++ == 0) {
                *a = (int32_t)(k[i] >> 32);
                *b = (int32_t)(k[i] & 0xffffffffu);
            }
        }
        i = j;
    }
    free(k);
    return open;
}

/* ---- a body from a tet mesh ---------------------------------------------------------------- */
wb_tet_body_def wb_tet_body_default_def(void)
{
    wb_tet_body_def d;
    memset(&d, 0, sizeof d);
    d.mass = 1;
    d.radius = 0.02;
    d.link = wb_distance_default_def();
    d.volume_compliance = 0;
    d.poisson = 0.3;
    return d;
}

static wb_status bad(const char *fmt, int64_t a, int64_t b)
{
    wb__set_error(fmt, (long long)a, (long long)b);
    return WB_ERR_ARG;
}

/* a tet's face: its corners sorted (the key) and as wound outwards */
typedef struct face { int32_t s[3], f[3]; } face;

static int cmp_face(const void *pa, const void *pb)
{
    const face *a = pa, *b = pb;
    for (int i = 0; i < 3; i++)
        if (a->s[i] != b->s[i]) return a->s[i] < b->s[i] ? -1 : 1;
    return 0;
}

static void sort3(int32_t *s)
{
    int32_t t;
    if (s[0] > s[1]) { t = s[0]; s[0] = s[1]; s[1] = t; }
    if (s[1] > s[2]) { t = s[1]; s[1] = s[2]; s[2] = t; }
    if (s[0] > s[1]) { t = s[0]; s[0] = s[1]; s[1] = t; }
}

/* the faces of the (positive) tets used by one tet only, wound outwards: (ntri x 3)
 * malloc'd in *tri; returns ntri or a negative wb_status */
static int32_t boundary_faces(const int32_t *tet, int32_t nt, int32_t **tri)
{
    /* outward faces of a positive tet (a b c d): (a c b), (a b d), (a d c), (b c d) */
    static const int fc[4][3] = { { 0, 2, 1 }, { 0, 1, 3 }, { 0, 3, 2 }, { 1, 2, 3 } };
    const int64_t n = 4 * (int64_t)nt;
    face *f = malloc(sizeof *f * (size_t)n);
    int32_t *out = malloc(sizeof *out * 3 * (size_t)n);
    if (!f || !out) { free(f); free(out); return WB_ERR_NOMEM; }
    for (int32_t t = 0; t < nt; t++)
        for (int k = 0; k < 4; k++) {
            face *g = &f[4 * t + k];
            for (int c = 0; c < 3; c++) g->s[c] = g->f[c] = tet[4 * t + fc[k][c]];
            sort3(g->s);
        }
    qsort(f, (size_t)n, sizeof *f, cmp_face);
    int32_t m = 0;
    for (int64_t i = 0; i < n;) {
        int64_t j = i;
        while (j < n && cmp_face(&f[j], &f[i]) == 0) j++;
        if (j - i == 1) { memcpy(&out[3 * m], f[i].f, sizeof f[i].f); m++; }
        i = j;
    }
    free(f);
    *tri = out;
    return m;
}

wb_status wb_tet_body(wb_world *w, const wb_real *v, int32_t nv, const int32_t *tet_in, int32_t nt,
                      const int32_t *tri_in, int32_t ntri, const wb_tet_body_def *d, wb_body *out)
{
    const char *e = wb_distance_def_check(&d->link);
    if (e) { wb__set_error("%s", e); return WB_ERR_ARG; }
    if (!(d->mass > 0) || !isfinite(d->mass)) return bad("mass must be > 0", 0, 0);
    if (!(d->radius >= 0) || !isfinite(d->radius)) return bad("radius must be >= 0", 0, 0);
    if (!(d->volume_compliance >= 0) || !isfinite(d->volume_compliance)) return bad("volume_compliance must be >= 0", 0, 0);
    const bool neo = d->young != 0;
    if (neo) {
        const wb_tet_def td = { d->young, d->poisson, 0, 0 };
        if ((e = wb_tet_def_check(&td))) { wb__set_error("%s", e); return WB_ERR_ARG; }
    }
    if (nv < 4 || nt < 1) return bad("a tet mesh needs at least 4 nodes and 1 tet (got %lld nodes, %lld tets)", nv, nt);
    if (nv > WB_MAX_PARTICLES || nt > WB_MAX_CONSTRAINTS / 6 || ntri < 0 || ntri > WB_MAX_CONSTRAINTS) return WB_ERR_LIMIT;
    for (int64_t i = 0; i < 3 * (int64_t)nv; i++)
        if (!isfinite(v[i])) return bad("node %lld is not finite", i / 3 + 1, 0);
    for (int32_t t = 0; t < nt; t++)
        for (int k = 0; k < 4; k++) {
            const int32_t p = tet_in[4 * t + k];
            if (p < 0 || p >= nv) return bad("tet %lld: node out of range (%lld)", t + 1, (int64_t)p + 1);
            for (int j = 0; j < k; j++)
                if (tet_in[4 * t + j] == p) return bad("tet %lld repeats node %lld", t + 1, (int64_t)p + 1);
        }
    for (int64_t i = 0; i < 3 * (int64_t)ntri; i++)
        if (tri_in[i] < 0 || tri_in[i] >= nv) return bad("surface triangle %lld: node out of range", i / 3 + 1, 0);

    /* positive tets, their volumes and the mass lumped to their corners by volume */
    int32_t *tet = malloc(sizeof *tet * 4 * (size_t)nt);
    wb_real *vol = malloc(sizeof *vol * (size_t)nt);
    wb_real *mass = calloc((size_t)nv, sizeof *mass);
    uint64_t *ek = malloc(sizeof *ek * 6 * (size_t)nt);
    int32_t *tri = NULL;
    wb_status st = tet && vol && mass && ek ? WB_OK : WB_ERR_NOMEM;
    wb_real total = 0;
    for (int32_t t = 0; t < nt && st == WB_OK; t++) {
        int32_t *p = &tet[4 * t];
        memcpy(p, &tet_in[4 * t], 4 * sizeof *p);
        wb_real x = wb_tet_signed_volume(&v[3 * p[0]], &v[3 * p[1]], &v[3 * p[2]], &v[3 * p[3]]);
        if (x < 0) {
            int32_t s = p[2]; p[2] = p[3]; p[3] = s;
            x = -x;
        }
        if (!(x > 0) || !isfinite(x)) st = bad("tet %lld is flat: its four nodes lie in a plane", t + 1, 0);
        vol[t] = x;
        total += x;
    }
    int32_t ne = 0;
    if (st == WB_OK) {
        for (int32_t t = 0; t < nt; t++) {
            for (int k = 0; k < 4; k++) mass[tet[4 * t + k]] += d->mass * vol[t] / total / 4;
            const int32_t *p = &tet[4 * t];
            const int pairs[6][2] = { { 0, 1 }, { 0, 2 }, { 0, 3 }, { 1, 2 }, { 1, 3 }, { 2, 3 } };
            for (int k = 0; k < 6; k++) ek[6 * t + k] = edge_key(p[pairs[k][0]], p[pairs[k][1]]);
        }
        qsort(ek, 6 * (size_t)nt, sizeof *ek, cmp_u64);
        for (int64_t i = 0; i < 6 * (int64_t)nt; i++)
            if (i == 0 || ek[i] != ek[i - 1]) ek[ne++] = ek[i];
        if (ntri == 0) {
            int32_t n = boundary_faces(tet, nt, &tri);
            if (n < 0) st = (wb_status)n;
            else ntri = n;
        } else {
            tri = malloc(sizeof *tri * 3 * (size_t)ntri);
            if (!tri) st = WB_ERR_NOMEM;
            else memcpy(tri, tri_in, sizeof *tri * 3 * (size_t)ntri);
        }
    }
    /* everything reserved first: after this nothing can fail */
    /* Neo-Hookean: the tets alone make the solid (links would stiffen it past E) */
    /* ... but with damping, dashpots on the edges (builders.c's wb__dashpot_def) */
    const bool dash = neo && d->link.damping > 0;
    if (neo && !dash) ne = 0;
    if (st == WB_OK) st = wb__reserve(w, nv, ne);
    if (st == WB_OK) st = wb__surface_reserve(w, ntri);
    if (st == WB_OK) st = neo ? wb__tet_reserve(w, nt) : wb__volume_reserve(w, nt);
    if (st == WB_OK) {
        const int32_t first = w->m.np, first_vol = wb_volume_count(w), first_tet = wb_tet_count(w);
        for (int32_t i = 0; i < nv; i++) {
            /* a node no tet uses (a stray one in a file) weighs as much as an average node */
            const wb_real mi = mass[i] > 0 ? mass[i] : d->mass / nv;
            wb_particle_add(w, &v[3 * i], NULL, mi, d->radius);
        }
        for (int32_t i = 0; i < ne; i++) {
            wb_status s2;
            const int32_t a = (int32_t)(ek[i] >> 32), b = (int32_t)(ek[i] & 0xffffffffu);
            wb_distance_def ld = d->link;
            if (dash) {
                const wb_real *va = &v[3 * a], *vb = &v[3 * b];
                ld = wb__dashpot_def(&d->link, d->young, sqrt((va[0] - vb[0]) * (va[0] - vb[0]) +
                                                              (va[1] - vb[1]) * (va[1] - vb[1]) +
                                                              (va[2] - vb[2]) * (va[2] - vb[2])));
            }
            wb_distance_add(w, first + a, first + b, &ld, &s2);
        }
        for (int32_t t = 0; t < nt; t++) {
            int32_t p[4];
            for (int k = 0; k < 4; k++) p[k] = first + tet[4 * t + k];
            if (neo) wb__tet_put_current(w, p, d->young, d->poisson); /* not flat: checked above */
            else wb__volume_put(w, p, d->volume_compliance, vol[t]);
        }
        for (int64_t i = 0; i < 3 * (int64_t)ntri; i++) tri[i] += first;
        wb_surface_add(w, tri, ntri);
        /* the links' plastic flow for the tets too: one rest shape for the whole body */
        wb__volume_plastic(w, first_vol, d->link.yield, d->link.creep);
        wb__tet_plastic(w, first_tet, d->link.yield, d->link.creep);
        st = wb__body_finish(w, first, nv, out);
    }
    free(tet);
    free(vol);
    free(mass);
    free(ek);
    free(tri);
    return st;
}
