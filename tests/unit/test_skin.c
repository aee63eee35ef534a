/* test_skin.c: linear blend skinning and the rotation extraction it relies on.
 * Properties from the issue: the bind pose reproduces the mesh to 1e-9; a rigid motion
 * of all particles moves the mesh rigidly (1e-6 of its size); the rotation matches the
 * polar decomposition on random matrices with moderate strain, with det = +1. */
#include <stdint.h>
#include <stdlib.h>

#include "test.h"
#include "wobble.h"

static uint32_t rng = 777;
static double rnd(void) /* uniform in [-1, 1) */
{
    rng = rng * 1664525u + 1013904223u;
    return (rng >> 8) / (double)(1u << 23) - 1;
}

static void matmul(const double *a, const double *b, double *o)
{
    for (int i = 0; i < 3; i++)
        for (int j = 0; j < 3; j++) o[3 * i + j] = a[3 * i] * b[j] + a[3 * i + 1] * b[3 + j] + a[3 * i + 2] * b[6 + j];
}

static double det3(const double *a)
{
    return a[0] * (a[4] * a[8] - a[5] * a[7]) - a[1] * (a[3] * a[8] - a[5] * a[6]) + a[2] * (a[3] * a[7] - a[4] * a[6]);
}

/* the rotation of the polar decomposition A = R S (det A > 0), by Higham's iteration
 * X <- (X + X^-T) / 2: an independent way to the same answer */
static void polar(const double *A, double *R)
{
    double X[9];
    memcpy(X, A, sizeof X);
    for (int it = 0; it < 100; it++) {
        const double d = det3(X);
        double C[9] = { /* cofactor matrix: X^-T = C / det */
            X[4] * X[8] - X[5] * X[7], X[5] * X[6] - X[3] * X[8], X[3] * X[7] - X[4] * X[6],
            X[2] * X[7] - X[1] * X[8], X[0] * X[8] - X[2] * X[6], X[1] * X[6] - X[0] * X[7],
            X[1] * X[5] - X[2] * X[4], X[2] * X[3] - X[0] * X[5], X[0] * X[4] - X[1] * X[3],
        };
        double diff = 0;
        for (int i = 0; i < 9; i++) {
            const double y = (X[i] + C[i] / d) / 2;
            diff = fmax(diff, fabs(y - X[i]));
            X[i] = y;
        }
        if (diff < 1e-15) break;
    }
    memcpy(R, X, sizeof X);
}

static void random_rotation(double *R)
{
    wb_real q[4] = { rnd(), rnd(), rnd(), rnd() };
    double n = sqrt(q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3]);
    for (int i = 0; i < 4; i++) q[i] /= n;
    wb_real r[9];
    wb_quat_to_matrix(q, r);
    for (int i = 0; i < 9; i++) R[i] = r[i];
}

TEST(rotation_extraction_matches_polar)
{
    double worst = 0, worst_det = 0;
    for (int trial = 0; trial < 500; trial++) {
        /* A = R (I + E): a rotation times a moderate general strain (|E_ij| <= 0.3) */
        double R[9], F[9], A[9], P[9];
        random_rotation(R);
        for (int i = 0; i < 9; i++) F[i] = (i % 4 == 0) + 0.3 * rnd();
        matmul(R, F, A);
        if (det3(A) <= 0) continue; /* an inversion has no rotation to find */
        polar(A, P);
        wb_real a[9], q[4] = { 1, 0, 0, 0 }, M[9];
        for (int i = 0; i < 9; i++) a[i] = A[i];
        wb_extract_rotation(a, q, 200);
        wb_quat_to_matrix(q, M);
        double m[9];
        for (int i = 0; i < 9; i++) {
            m[i] = M[i];
            worst = fmax(worst, fabs(M[i] - P[i]));
        }
        worst_det = fmax(worst_det, fabs(det3(m) - 1));
    }
    CHECK_NEAR(worst, 0, 1e-9);
    CHECK_NEAR(worst_det, 0, 1e-12);
}

TEST(rotation_extraction_warm_start)
{
    /* started at the answer it stays there; started near it, it needs few steps */
    double R[9], F[9], A[9];
    random_rotation(R);
    for (int i = 0; i < 9; i++) F[i] = (i % 4 == 0) + 0.2 * rnd();
    matmul(R, F, A);
    wb_real a[9], q[4] = { 1, 0, 0, 0 };
    for (int i = 0; i < 9; i++) a[i] = A[i];
    wb_extract_rotation(a, q, 500);
    wb_real q2[4];
    memcpy(q2, q, sizeof q);
    wb_extract_rotation(a, q2, 1);
    for (int i = 0; i < 4; i++) CHECK_NEAR(q2[i], q[i], 1e-12);
    /* a small turn of A (what a frame does): from the last answer it takes fewer
     * iterations to converge than from identity, and converges within the default 50 */
    const double t = 0.02;
    double S[9] = { cos(t), -sin(t), 0, sin(t), cos(t), 0, 0, 0, 1 }, B[9];
    matmul(S, A, B);
    wb_real b[9], exact[4] = { 1, 0, 0, 0 };
    for (int i = 0; i < 9; i++) b[i] = B[i];
    wb_extract_rotation(b, exact, 1000);
    int warm = 0, cold = 0;
    for (int start = 0; start < 2; start++) {
        int k = 1;
        for (; k <= 1000; k++) {
            wb_real qk[4] = { 1, 0, 0, 0 };
            if (start == 0) memcpy(qk, q, sizeof q);
            wb_extract_rotation(b, qk, k);
            const double dot = fabs(qk[0] * exact[0] + qk[1] * exact[1] + qk[2] * exact[2] + qk[3] * exact[3]);
            if (1 - dot < 1e-14) break;
        }
        if (start == 0) warm = k;
        else cold = k;
    }
    CHECK(warm < cold);
    CHECK(warm <= wb_skin_default_def().iterations);
}

/* a dense mesh (a bumpy sphere, radius about 0.45) inside a 5x5x5 lattice on [0,1]^3 */
static wb_mesh *bumpy_sphere(int nu, int nv)
{
    const int32_t n = nu * nv;
    wb_real *v = malloc(sizeof *v * 3 * (size_t)n);
    int32_t *t = malloc(sizeof *t * 6 * (size_t)n);
    int32_t nt = 0;
    for (int j = 0; j < nv; j++)
        for (int i = 0; i < nu; i++) {
            const double th = 3.14159265358979 * (j + 0.5) / nv, ph = 2 * 3.14159265358979 * i / nu;
            const double r = 0.42 + 0.03 * sin(5 * ph) * sin(3 * th);
            wb_real *p = &v[3 * (j * nu + i)];
            p[0] = 0.5 + r * sin(th) * cos(ph);
            p[1] = 0.5 + r * cos(th);
            p[2] = 0.5 + r * sin(th) * sin(ph);
            if (j + 1 < nv) {
                const int32_t a = j * nu + i, b = j * nu + (i + 1) % nu, c = a + nu, d = b + nu;
                t[3 * nt] = a; t[3 * nt + 1] = b; t[3 * nt + 2] = c; nt++;
                t[3 * nt] = c; t[3 * nt + 1] = b; t[3 * nt + 2] = d; nt++;
            }
        }
    wb_mesh *m = wb_mesh_create(v, n, t, nt, NULL);
    free(v);
    free(t);
    return m;
}

typedef struct rig { wb_world *w; wb_mesh *m; wb_skin *s; int32_t *ids; int32_t n; } rig;

static int rig_make(rig *r, int bones)
{
    wb_world_def wd = wb_world_default_def();
    r->w = wb_world_create(&wd);
    r->m = bumpy_sphere(120, 60);
    wb_lattice_def ld = wb_lattice_default_def();
    ld.res[0] = ld.res[1] = ld.res[2] = 5;
    wb_body b;
    if (!r->w || !r->m || wb_lattice(r->w, &ld, &b) != WB_OK) return 0;
    r->n = b.count;
    r->ids = malloc(sizeof *r->ids * (size_t)b.count);
    for (int32_t i = 0; i < b.count; i++) r->ids[i] = b.first + i;
    wb_skin_def sd = wb_skin_default_def();
    sd.bones = bones;
    r->s = wb_skin_create(r->w, r->m, r->ids, r->n, &sd, NULL);
    return r->s != NULL;
}

static void rig_free(rig *r)
{
    wb_skin_destroy(r->s);
    wb_mesh_destroy(r->m);
    wb_world_destroy(r->w);
    free(r->ids);
}

TEST(skin_rest_pose_reproduces_mesh)
{
    rig r;
    REQUIRE(rig_make(&r, 4));
    /* move a particle and back: the vertices are blended again, not returned from the bind */
    wb_real x[3], moved[3];
    wb_particle_position(r.w, 7, x);
    memcpy(moved, x, sizeof x);
    moved[1] += 0.1;
    wb_particle_set_position(r.w, 7, moved);
    const wb_real *v = wb_skin_vertices(r.s, r.w);
    wb_particle_set_position(r.w, 7, x);
    v = wb_skin_vertices(r.s, r.w);
    double err = 0;
    for (int32_t i = 0; i < 3 * r.m->nv; i++) err = fmax(err, fabs(v[i] - r.m->v[i]));
    CHECK_NEAR(err, 0, 1e-9);
    rig_free(&r);
}

TEST(skin_weights_sum_to_one_and_fall_off)
{
    rig r;
    REQUIRE(rig_make(&r, 4));
    for (int32_t v = 0; v < r.m->nv; v += 7) {
        int32_t ids[16];
        wb_real wt[16], sum = 0, last = 2, last_d = -1;
        const int n = wb_skin_influences(r.s, v, ids, wt);
        CHECK(n >= 1 && n <= 4);
        for (int k = 0; k < n; k++) {
            wb_real p[3];
            wb_particle_position(r.w, ids[k], p);
            const wb_real *q = &r.m->v[3 * v];
            const wb_real d = sqrt((p[0] - q[0]) * (p[0] - q[0]) + (p[1] - q[1]) * (p[1] - q[1]) + (p[2] - q[2]) * (p[2] - q[2]));
            CHECK(wt[k] > 0);
            CHECK(d >= last_d);        /* nearest first ... */
            CHECK(wt[k] <= last);      /* ... and weights fall off with distance */
            last = wt[k];
            last_d = d;
            sum += wt[k];
        }
        CHECK_NEAR(sum, 1, 1e-12);
    }
    rig_free(&r);
}

TEST(skin_rigid_motion_is_rigid)
{
    rig r;
    REQUIRE(rig_make(&r, 4));
    double R[9];
    random_rotation(R);
    const double t[3] = { 1.5, -0.7, 2.25 };
    for (int32_t i = 0; i < r.n; i++) {
        wb_real x[3], y[3];
        wb_particle_position(r.w, r.ids[i], x);
        for (int k = 0; k < 3; k++) y[k] = R[3 * k] * x[0] + R[3 * k + 1] * x[1] + R[3 * k + 2] * x[2] + t[k];
        wb_particle_set_position(r.w, r.ids[i], y);
    }
    const wb_real *v = wb_skin_vertices(r.s, r.w);
    double err = 0;
    for (int32_t i = 0; i < r.m->nv; i++) {
        const wb_real *x = &r.m->v[3 * i];
        for (int k = 0; k < 3; k++)
            err = fmax(err, fabs(v[3 * i + k] - (R[3 * k] * x[0] + R[3 * k + 1] * x[1] + R[3 * k + 2] * x[2] + t[k])));
    }
    CHECK_NEAR(err, 0, 1e-6 * 0.9); /* the mesh is about 0.9 across */
    /* every bone turned by R */
    for (int32_t b = 0; b < wb_skin_bone_count(r.s); b++) {
        wb_real q[4], M[9];
        wb_skin_bone_rotation(r.s, b, q);
        if (q[0] == 1 && q[1] == 0) continue; /* a bone no vertex uses is not updated */
        wb_quat_to_matrix(q, M);
        double e = 0;
        for (int i = 0; i < 9; i++) e = fmax(e, fabs(M[i] - R[i]));
        CHECK_NEAR(e, 0, 1e-9);
    }
    rig_free(&r);
}

TEST(skin_follows_simulation)
{
    /* a soft block falls on the ground: the skin stays finite and inside the
     * particles' bounds grown by the bind distance */
    rig r;
    REQUIRE(rig_make(&r, 4));
    wb_collider_def pd = wb_collider_default_def(WB_SHAPE_PLANE);
    pd.offset = -1;
    wb_collider_add(r.w, &pd, NULL);
    for (int f = 0; f < 90; f++) {
        wb_world_step(r.w);
        wb_skin_update_bones(r.s, r.w);
    }
    const wb_real *v = wb_skin_vertices(r.s, r.w);
    wb_real mn[3], mx[3];
    wb_world_bounds(r.w, mn, mx);
    int ok = 1;
    for (int32_t i = 0; i < r.m->nv; i++)
        for (int k = 0; k < 3; k++) ok &= isfinite(v[3 * i + k]) && v[3 * i + k] > mn[k] - 0.2 && v[3 * i + k] < mx[k] + 0.2;
    CHECK(ok);
    CHECK(mn[1] < -0.9);
    rig_free(&r);
}

TEST(skin_bad_definitions)
{
    wb_world_def wd = wb_world_default_def();
    wb_world *w = wb_world_create(&wd);
    REQUIRE(w);
    const wb_real p[3] = { 0, 0, 0 };
    wb_particle_add(w, p, NULL, 1, 0);
    wb_mesh *m = bumpy_sphere(8, 4);
    REQUIRE(m);
    wb_skin_def d = wb_skin_default_def();
    int32_t id = 0, bad = 5;
    wb_status st = WB_OK;
    d.bones = 0;
    CHECK(wb_skin_create(w, m, &id, 1, &d, &st) == NULL);
    CHECK_HAS(wb_last_error(), "bones");
    d = wb_skin_default_def();
    CHECK(wb_skin_create(w, m, &bad, 1, &d, &st) == NULL);
    CHECK_EQ(st, WB_ERR_ARG);
    CHECK_HAS(wb_last_error(), "out of range");
    /* one particle: every vertex on it with weight 1, a pure translation */
    wb_skin *s = wb_skin_create(w, m, &id, 1, &d, &st);
    REQUIRE(s);
    const wb_real q[3] = { 1, 2, 3 };
    wb_particle_set_position(w, 0, q);
    const wb_real *v = wb_skin_vertices(s, w);
    CHECK_NEAR(v[0], m->v[0] + 1, 1e-12);
    CHECK_NEAR(v[2], m->v[2] + 3, 1e-12);
    wb_skin_destroy(s);
    wb_mesh_destroy(m);
    wb_world_destroy(w);
}

/* the skin of a bumpy sphere on a res^3 lattice over [0, size]^3, the particles turned
 * by R about the cage's centre: the largest vertex error over the mesh's size */
static double turned_cage_error(int res, double size, const double R[9])
{
    wb_world_def wd = wb_world_default_def();
    wb_world *w = wb_world_create(&wd);
    wb_mesh *m = bumpy_sphere(60, 30);
    wb_lattice_def ld = wb_lattice_default_def();
    ld.res[0] = ld.res[1] = ld.res[2] = res;
    for (int k = 0; k < 3; k++) ld.min[k] = 0, ld.max[k] = size;
    wb_body b;
    if (!w || !m || wb_lattice(w, &ld, &b) != WB_OK) return 1e30;
    wb_mesh_transform(m, size, NULL);
    int32_t *ids = malloc(sizeof *ids * (size_t)b.count);
    for (int32_t i = 0; i < b.count; i++) ids[i] = b.first + i;
    wb_skin_def sd = wb_skin_default_def();
    wb_skin *s = wb_skin_create(w, m, ids, b.count, &sd, NULL);
    if (!s) return 1e30;
    const double c = size / 2;
    for (int32_t i = 0; i < b.count; i++) {
        wb_real x[3], y[3];
        wb_particle_position(w, ids[i], x);
        for (int k = 0; k < 3; k++)
            y[k] = c + R[3 * k] * (x[0] - c) + R[3 * k + 1] * (x[1] - c) + R[3 * k + 2] * (x[2] - c);
        wb_particle_set_position(w, ids[i], y);
    }
    const wb_real *v = wb_skin_vertices(s, w);
    double err = 0;
    for (int32_t i = 0; i < m->nv; i++) {
        const wb_real *x = &m->v[3 * i];
        for (int k = 0; k < 3; k++) {
            const double want = c + R[3 * k] * (x[0] - c) + R[3 * k + 1] * (x[1] - c) + R[3 * k + 2] * (x[2] - c);
            err = fmax(err, fabs(v[3 * i + k] - want) / size);
        }
    }
    wb_skin_destroy(s);
    wb_mesh_destroy(m);
    wb_world_destroy(w);
    free(ids);
    return err;
}

static void axis_rotation(const double u_in[3], double t, double R[9])
{
    const double n = sqrt(u_in[0] * u_in[0] + u_in[1] * u_in[1] + u_in[2] * u_in[2]);
    const double u[3] = { u_in[0] / n, u_in[1] / n, u_in[2] / n }, c = cos(t), s = sin(t);
    for (int i = 0; i < 3; i++)
        for (int j = 0; j < 3; j++) R[3 * i + j] = (i == j) * c + (1 - c) * u[i] * u[j];
    R[1] -= s * u[2]; R[2] += s * u[1];
    R[3] += s * u[2]; R[5] -= s * u[0];
    R[6] -= s * u[1]; R[7] += s * u[0];
}

TEST(skin_follows_half_turns)
{
    /* Müller's update is zero at the saddle half a turn from the warm start: a cage turned
     * by exactly pi must still be followed, about coordinate axes and an oblique one */
    const double axes[4][3] = { { 0, 1, 0 }, { 1, 0, 0 }, { 0, 0, 1 }, { 1, 2, 3 } };
    for (int a = 0; a < 4; a++) {
        double R[9];
        axis_rotation(axes[a], 3.14159265358979323846, R);
        CHECK_NEAR(turned_cage_error(4, 1, R), 0, 1e-6);
        /* and the extraction alone, from identity, on A = R */
        wb_real A[9], q[4] = { 1, 0, 0, 0 }, M[9];
        for (int i = 0; i < 9; i++) A[i] = R[i];
        wb_extract_rotation(A, q, 50);
        wb_quat_to_matrix(q, M);
        double e = 0;
        for (int i = 0; i < 9; i++) e = fmax(e, fabs(M[i] - R[i]));
        CHECK_NEAR(e, 0, 1e-9);
    }
}

TEST(skin_rotation_independent_of_scale)
{
    /* the same rigid turn of a cage 1e-6 across and of one 1e6 across */
    double R[9];
    const double u[3] = { 0.3, -1, 0.5 };
    axis_rotation(u, 0.7, R);
    CHECK_NEAR(turned_cage_error(4, 1e-6, R), 0, 1e-6);
    CHECK_NEAR(turned_cage_error(4, 1e6, R), 0, 1e-6);
}

TEST(skin_and_from_mesh_refuse_nonfinite_vertices)
{
    wb_world_def wd = wb_world_default_def();
    wb_world *w = wb_world_create(&wd);
    REQUIRE(w);
    const wb_real p[3] = { 0, 0, 0 };
    wb_particle_add(w, p, NULL, 1, 0);
    wb_mesh *m = bumpy_sphere(8, 4);
    REQUIRE(m);
    wb_mesh_transform(m, 1e200, NULL);
    wb_mesh_transform(m, 1e200, NULL); /* now inf (and NaN normals) */
    wb_skin_def d = wb_skin_default_def();
    int32_t id = 0;
    wb_status st = WB_OK;
    CHECK(wb_skin_create(w, m, &id, 1, &d, &st) == NULL);
    CHECK_EQ(st, WB_ERR_ARG);
    CHECK_HAS(wb_last_error(), "not finite");
    wb_from_mesh_def fd = wb_from_mesh_default_def();
    wb_body b;
    CHECK_EQ(wb_from_mesh(w, m, &fd, &b), WB_ERR_ARG);
    CHECK_HAS(wb_last_error(), "not finite");
    CHECK_EQ(wb_particle_count(w), 1);
    wb_mesh_destroy(m);
    wb_world_destroy(w);
}
