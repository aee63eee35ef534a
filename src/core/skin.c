/* skin.c: linear blend skinning of a high-poly mesh over a coarse particle graph (the
 * reference thesis's third iteration).
 *
 * Binding: every vertex takes its K nearest particles (k-d tree) as bones, weighted by
 * w = (1 - (d/R)^2)^2 with R the distance of the (K+1)-th nearest particle, then
 * normalised. The weight of the K-th bone reaches 0 exactly where another particle would
 * replace it, so weights vary continuously over the mesh and the skin shows no seams.
 *
 * Deformation: bone j follows its particle x_j and turns with R_j, the rotation of its
 * neighbourhood (its nearest particles at bind time) from the bind pose, extracted from
 * A_j = sum_k (x_k - c)(x0_k - c0)^T with Müller et al. 2016, warm-started from the last
 * update. A vertex moves to v' = sum_j w_j (x_j + R_j (v - x0_j)): at the bind pose that
 * is v itself, and under a rigid motion of all particles it is the same rigid motion. */
#include <math.h>
#include <stdlib.h>
#include <stdatomic.h>
#include <string.h>

#include "core.h"

#define MAX_BONES 16
#define MAX_NEIGHBOURS 32

struct wb_skin {
    wb_mesh *rest;        /* the bound mesh (a copy) */
    int k;                /* bones per vertex */
    int iterations;
    int32_t *inf;         /* (nv x k) bone of each influence (index into the bones) */
    wb_real *wt;          /* (nv x k) weights; unused slots have weight 0 and bone 0 */
    int32_t nb;           /* bones: every particle given */
    int32_t *particle;    /* (nb) world particle of each bone */
    wb_real *x0;          /* (nb x 3) bind positions */
    int32_t *nbr_start;   /* (nb + 1) neighbourhood ranges */
    int32_t *nbr;         /* neighbour bones */
    uint8_t *used;        /* (nb) some vertex depends on this bone */
    wb_real *q;           /* (nb x 4) rotations (warm start of the next update) */
    wb_real *R;           /* (nb x 9) the same as matrices */
    wb_real *x;           /* (nb x 3) particle positions at the last update */
    wb_real *out;         /* (nv x 3) deformed vertices */
    wb_real *nrm;         /* (nv x 3) their normals */
    uint64_t bones_key;   /* fingerprint of the positions the bones were updated for */
    uint64_t verts_key, normals_key;
};

/* ---- rotations ----------------------------------------------------------------------- */
void wb_quat_to_matrix(const wb_real q[4], wb_real R[9])
{
    const wb_real w = q[0], x = q[1], y = q[2], z = q[3];
    R[0] = 1 - 2 * (y * y + z * z); R[1] = 2 * (x * y - w * z);     R[2] = 2 * (x * z + w * y);
    R[3] = 2 * (x * y + w * z);     R[4] = 1 - 2 * (x * x + z * z); R[5] = 2 * (y * z - w * x);
    R[6] = 2 * (x * z - w * y);     R[7] = 2 * (y * z + w * x);     R[8] = 1 - 2 * (x * x + y * y);
}

/* Müller, Bender, Chentanez, Macklin 2016, "A robust method to extract the rotational part
 * of deformations": turn R towards A by omega = sum_i r_i x a_i / |sum_i r_i . a_i| (r_i,
 * a_i the columns), the exact rotation by |omega| about omega each time. It needs no SVD,
 * never flips to a reflection, and from a close warm start converges in a few steps. */
/* returns 1 when it stopped at a stationary point (the update vanished), 0 out of steps */
static int muller(const wb_real A[9], wb_real q[4], int max_iter)
{
    for (int it = 0; it < max_iter; it++) {
        wb_real R[9], om[3] = { 0, 0, 0 }, dot = 0;
        wb_quat_to_matrix(q, R);
        for (int i = 0; i < 3; i++) {
            const wb_real r[3] = { R[i], R[3 + i], R[6 + i] }, a[3] = { A[i], A[3 + i], A[6 + i] };
            wb_real c[3];
            v3_cross(c, r, a);
            v3_add(om, om, c);
            dot += v3_dot(r, a);
        }
        v3_scale(om, om, 1 / (fabs(dot) + (wb_real)1e-9));
        const wb_real angle = v3_len(om);
        if (angle < (wb_real)1e-12) return 1;
        q_integrate(q, om, 1, q); /* q <- rot(|om|, om/|om|) q */
    }
    return 0;
}

/* trace(R^T A): the polar rotation is the one that makes it largest */
static wb_real trace_rta(const wb_real q[4], const wb_real A[9])
{
    wb_real R[9], t = 0;
    wb_quat_to_matrix(q, R);
    for (int i = 0; i < 9; i++) t += R[i] * A[i];
    return t;
}

/* q <- q rot(pi, e_k) for the k that gives the largest trace(R^T A), if that beats q's
 * own; 1 when q changed */
static int best_half_turn(const wb_real A[9], wb_real q[4])
{
    wb_real best[4], bt = trace_rta(q, A) + (wb_real)1e-9;
    int found = 0;
    for (int k = 0; k < 3; k++) {
        const wb_real e[3] = { k == 0, k == 1, k == 2 }, v[3] = { q[1], q[2], q[3] };
        wb_real c[4], x[3];
        v3_cross(x, v, e);
        c[0] = -q[1 + k];
        for (int j = 0; j < 3; j++) c[1 + j] = q[0] * e[j] + x[j];
        const wb_real t = trace_rta(c, A);
        if (t > bt) {
            bt = t;
            memcpy(best, c, sizeof best);
            found = 1;
        }
    }
    if (found) memcpy(q, best, sizeof best);
    return found;
}

void wb_extract_rotation(const wb_real A_in[9], wb_real q[4], int max_iter)
{
    q_normalize(q);
    /* A over its Frobenius norm: the iteration's thresholds are absolute, so without this
     * a 1e-6-sized cage (A ~ 1e-12) would stop at once and a huge one never */
    wb_real A[9], f = 0;
    for (int i = 0; i < 9; i++) f += A_in[i] * A_in[i];
    f = sqrt(f);
    if (!(f > 0) || !isfinite(f) || max_iter <= 0) return;
    for (int i = 0; i < 9; i++) A[i] = A_in[i] / f;
    /* the update vanishes wherever R^T A is symmetric, which includes the saddles half a
     * turn from the answer (a cage turned by exactly pi from the warm start stays put),
     * and near them it crawls. A start that a half turn about a coordinate axis improves
     * is begun from that turn instead (near the answer none does, so a warm start is
     * kept); a stationary end that such a turn beats was a saddle: go on from there */
    best_half_turn(A, q);
    for (int round = 0; round < 4; round++)
        if (!muller(A, q, max_iter) || !best_half_turn(A, q)) break;
}

/* ---- binding ------------------------------------------------------------------------- */
wb_skin_def wb_skin_default_def(void)
{
    wb_skin_def d = { 4, 8, 50 };
    return d;
}

const char *wb_skin_def_check(const wb_skin_def *d)
{
    if (d->bones < 1 || d->bones > MAX_BONES) return "bones must be in 1..16";
    if (d->neighbours < 1 || d->neighbours > MAX_NEIGHBOURS) return "neighbours must be in 1..32";
    if (d->iterations < 1 || d->iterations > 1000) return "iterations must be in 1..1000";
    return NULL;
}

void wb_skin_destroy(wb_skin *s)
{
    if (!s) return;
    wb_mesh_destroy(s->rest);
    void *p[] = { s->inf, s->wt, s->particle, s->x0, s->nbr_start, s->nbr, s->used, s->q, s->R, s->x, s->out, s->nrm };
    for (size_t i = 0; i < sizeof p / sizeof p[0]; i++) free(p[i]);
    free(s);
}

/* weights of one vertex from its K+1 nearest squared distances (got of them) */
static void vertex_weights(const wb_real *d2, int got, int k, wb_real *wt)
{
    const int n = got < k ? got : k;
    /* R: the (K+1)-th distance; with no (K+1)-th particle, past the farthest one */
    wb_real R2 = got > k ? d2[k] : 4 * d2[n - 1];
    wb_real sum = 0;
    for (int j = 0; j < n; j++) {
        wb_real t = R2 > 0 ? 1 - d2[j] / R2 : 0;
        wt[j] = t > 0 ? t * t : 0;
        sum += wt[j];
    }
    /* every one as far as the (K+1)-th (a symmetric spot): share equally */
    for (int j = 0; j < n; j++) wt[j] = sum > 0 ? wt[j] / sum : (wb_real)1 / n;
    for (int j = n; j < k; j++) wt[j] = 0;
}

static uint64_t fingerprint(const wb_skin *s, const wb_world *w)
{
    uint64_t h = 14695981039346656037ull;
    for (int32_t b = 0; b < s->nb; b++) {
        const unsigned char *p = (const unsigned char *)&w->s.x[3 * s->particle[b]];
        for (size_t i = 0; i < 3 * sizeof(wb_real); i++) { h ^= p[i]; h *= 1099511628211ull; }
    }
    return h;
}

/* every vertex of [lo, hi): its K nearest particles, one more for the weights' radius */
typedef struct bind_job {
    wb_skin *s;
    const wb_kdtree *t;
    const wb_mesh *m;
    _Atomic int32_t far; /* the first vertex whose squared distance to a bone overflows */
} bind_job;

static void bind_part(void *ctx, int32_t lo, int32_t hi)
{
    bind_job *bj = ctx;
    wb_skin *s = bj->s;
    const int k = s->k;
    int32_t far = INT32_MAX;
    for (int32_t v = lo; v < hi; v++) {
        int32_t id[MAX_BONES + 1];
        wb_real d2[MAX_BONES + 1];
        int got = wb_kdtree_knn(bj->t, &bj->m->v[3 * v], k + 1, id, d2);
        for (int j = 0; j < got; j++)
            if (!isfinite(d2[j]) && v < far) far = v;
        vertex_weights(d2, got, k, &s->wt[(size_t)v * k]);
        for (int j = 0; j < k; j++) s->inf[(size_t)v * k + j] = j < got ? id[j] : 0;
    }
    /* the minimum over the parts, whatever their order */
    int32_t cur = bj->far;
    while (far < cur && !atomic_compare_exchange_weak(&bj->far, &cur, far)) {}
}

wb_skin *wb_skin_create(const wb_world *w, const wb_mesh *m, const int32_t *ids, int32_t n,
                        const wb_skin_def *def, wb_status *status)
{
    wb_status dummy;
    if (!status) status = &dummy;
    *status = WB_ERR_ARG;
    const char *err = wb_skin_def_check(def);
    if (err) { wb__set_error("%s", err); return NULL; }
    if (n < 1) { wb__set_error("a skin needs at least one particle"); return NULL; }
    for (int32_t i = 0; i < n; i++)
        if (ids[i] < 0 || ids[i] >= w->m.np) { wb__set_error("particle %d out of range", ids[i] + 1); return NULL; }
    /* a non-finite vertex would give every weight and every deformed position NaN */
    for (int32_t i = 0; i < 3 * m->nv; i++)
        if (!isfinite(m->v[i])) { wb__set_error("mesh vertex %d is not finite", i / 3 + 1); return NULL; }
    *status = WB_ERR_NOMEM;
    wb_skin *s = calloc(1, sizeof *s);
    if (!s) return NULL;
    const int32_t nv = m->nv, k = def->bones;
    const size_t nvs = (size_t)(nv > 0 ? nv : 1), nbs = (size_t)n;
    s->k = k;
    s->iterations = def->iterations;
    s->nb = n;
    s->rest = wb_mesh_copy(m);
    s->inf = calloc(nvs * (size_t)k, sizeof *s->inf);
    s->wt = calloc(nvs * (size_t)k, sizeof *s->wt);
    s->particle = malloc(nbs * sizeof *s->particle);
    s->x0 = malloc(nbs * 3 * sizeof *s->x0);
    s->x = malloc(nbs * 3 * sizeof *s->x);
    s->nbr_start = malloc((nbs + 1) * sizeof *s->nbr_start);
    s->nbr = malloc(nbs * MAX_NEIGHBOURS * sizeof *s->nbr);
    s->used = calloc(nbs, 1);
    s->q = malloc(nbs * 4 * sizeof *s->q);
    s->R = malloc(nbs * 9 * sizeof *s->R);
    s->out = malloc(nvs * 3 * sizeof *s->out);
    s->nrm = malloc(nvs * 3 * sizeof *s->nrm);
    if (!s->rest || !s->inf || !s->wt || !s->particle || !s->x0 || !s->x || !s->nbr_start || !s->nbr || !s->used ||
        !s->q || !s->R || !s->out || !s->nrm) {
        wb_skin_destroy(s);
        return NULL;
    }
    for (int32_t b = 0; b < n; b++) {
        s->particle[b] = ids[b];
        v3_copy(&s->x0[3 * b], &w->s.x[3 * ids[b]]);
        v3_copy(&s->x[3 * b], &s->x0[3 * b]);
        s->q[4 * b] = 1;
        s->q[4 * b + 1] = s->q[4 * b + 2] = s->q[4 * b + 3] = 0;
        wb_quat_to_matrix(&s->q[4 * b], &s->R[9 * b]);
    }
    wb_kdtree *t = wb_kdtree_build(s->x0, n);
    if (!t) { wb_skin_destroy(s); return NULL; }
    /* every vertex: its K nearest particles, one more for the weights' radius */
    bind_job bj = { s, t, m, nv };
    wb__pool_for(nv > 20000 ? wb__world_pool(w) : NULL, nv, 5000, bind_part, &bj);
    const int32_t far = bj.far;
    if (far < nv) {
        /* weights are d^2 / R^2 (inf / inf = NaN) and offsets v - x0 overflow: refuse */
        wb_kdtree_destroy(t);
        wb_skin_destroy(s);
        wb__set_error("mesh vertex %d is too far from the particles (its squared distance overflows)", far + 1);
        *status = WB_ERR_ARG;
        return NULL;
    }
    for (size_t i = 0; i < (size_t)nv * k; i++)
        if (s->wt[i] > 0) s->used[s->inf[i]] = 1;
    /* every bone a vertex uses: its neighbourhood at bind time, for its rotation */
    int32_t e = 0;
    for (int32_t b = 0; b < n; b++) {
        s->nbr_start[b] = e;
        if (!s->used[b]) continue;
        /* at most `neighbours` others, what nbr has room for per bone */
        int32_t id[MAX_NEIGHBOURS];
        int got = wb_kdtree_knn_except(t, &s->x0[3 * b], def->neighbours, b, id, NULL);
        for (int j = 0; j < got; j++) s->nbr[e++] = id[j];
    }
    s->nbr_start[n] = e;
    wb_kdtree_destroy(t);
    /* the bind pose: the mesh itself */
    if (nv) {
        memcpy(s->out, m->v, nvs * 3 * sizeof *s->out);
        memcpy(s->nrm, m->n, nvs * 3 * sizeof *s->nrm);
    }
    s->bones_key = s->verts_key = s->normals_key = fingerprint(s, w);
    *status = WB_OK;
    return s;
}

/* ---- updates --------------------------------------------------------------------------- */
/* A = sum_k (x_k - c)(x0_k - c0)^T over the bone and its neighbours */
static void neighbourhood_matrix(const wb_skin *s, int32_t b, wb_real A[9])
{
    const int32_t lo = s->nbr_start[b], hi = s->nbr_start[b + 1];
    wb_real c[3], c0[3];
    v3_copy(c, &s->x[3 * b]);
    v3_copy(c0, &s->x0[3 * b]);
    for (int32_t i = lo; i < hi; i++) {
        v3_add(c, c, &s->x[3 * s->nbr[i]]);
        v3_add(c0, c0, &s->x0[3 * s->nbr[i]]);
    }
    const wb_real inv = 1 / (wb_real)(hi - lo + 1);
    v3_scale(c, c, inv);
    v3_scale(c0, c0, inv);
    memset(A, 0, 9 * sizeof *A);
    for (int32_t i = lo - 1; i < hi; i++) {
        const int32_t k = i < lo ? b : s->nbr[i];
        wb_real p[3], p0[3];
        v3_sub(p, &s->x[3 * k], c);
        v3_sub(p0, &s->x0[3 * k], c0);
        for (int r = 0; r < 3; r++)
            for (int col = 0; col < 3; col++) A[3 * r + col] += p[r] * p0[col];
    }
}

void wb_skin_update_bones(wb_skin *s, const wb_world *w)
{
    const uint64_t key = fingerprint(s, w);
    if (key == s->bones_key) return;
    for (int32_t b = 0; b < s->nb; b++) v3_copy(&s->x[3 * b], &w->s.x[3 * s->particle[b]]);
    for (int32_t b = 0; b < s->nb; b++) {
        if (!s->used[b] || s->nbr_start[b + 1] == s->nbr_start[b]) continue;
        wb_real A[9];
        neighbourhood_matrix(s, b, A);
        wb_extract_rotation(A, &s->q[4 * b], s->iterations);
        wb_quat_to_matrix(&s->q[4 * b], &s->R[9 * b]);
    }
    s->bones_key = key;
}

/* the blended positions of vertices [lo, hi) */
static void blend_part(void *ctx, int32_t lo, int32_t hi)
{
    wb_skin *s = ctx;
    const int k = s->k;
    const wb_real *v0 = s->rest->v;
    for (int32_t v = lo; v < hi; v++) {
        wb_real o[3] = { 0, 0, 0 };
        for (int j = 0; j < k; j++) {
            const wb_real wj = s->wt[(size_t)v * k + j];
            if (wj == 0) continue;
            const int32_t b = s->inf[(size_t)v * k + j];
            const wb_real *R = &s->R[9 * b], *xb = &s->x[3 * b];
            wb_real r[3];
            v3_sub(r, &v0[3 * v], &s->x0[3 * b]);
            o[0] += wj * (xb[0] + R[0] * r[0] + R[1] * r[1] + R[2] * r[2]);
            o[1] += wj * (xb[1] + R[3] * r[0] + R[4] * r[1] + R[5] * r[2]);
            o[2] += wj * (xb[2] + R[6] * r[0] + R[7] * r[1] + R[8] * r[2]);
        }
        v3_copy(&s->out[3 * v], o);
    }
}

const wb_real *wb_skin_vertices(wb_skin *s, const wb_world *w)
{
    wb_skin_update_bones(s, w);
    if (s->verts_key == s->bones_key) return s->out;
    wb__pool_for(s->rest->nv > 20000 ? wb__world_pool(w) : NULL, s->rest->nv, 5000, blend_part, s);
    s->verts_key = s->bones_key;
    return s->out;
}

const wb_real *wb_skin_normals(wb_skin *s, const wb_world *w)
{
    const wb_real *v = wb_skin_vertices(s, w);
    if (s->normals_key == s->verts_key) return s->nrm;
    /* the deformed mesh's own normals, as wb_mesh_compute_normals makes them */
    wb_mesh tmp = { s->rest->nv, s->rest->nt, (wb_real *)v, s->nrm, s->rest->tri };
    wb_mesh_compute_normals(&tmp);
    s->normals_key = s->verts_key;
    return s->nrm;
}

const wb_mesh *wb_skin_rest(const wb_skin *s) { return s->rest; }
int32_t wb_skin_bone_count(const wb_skin *s) { return s->nb; }
int32_t wb_skin_bone_particle(const wb_skin *s, int32_t b) { return s->particle[b]; }

void wb_skin_bone_rotation(const wb_skin *s, int32_t b, wb_real q[4])
{
    memcpy(q, &s->q[4 * b], 4 * sizeof *q);
}

int wb_skin_influences(const wb_skin *s, int32_t v, int32_t *particles, wb_real *weights)
{
    int n = 0;
    for (int j = 0; j < s->k; j++) {
        const wb_real wj = s->wt[(size_t)v * s->k + j];
        if (wj == 0) continue;
        if (particles) particles[n] = s->particle[s->inf[(size_t)v * s->k + j]];
        if (weights) weights[n] = wj;
        n++;
    }
    return n;
}
