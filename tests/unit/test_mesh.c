/* test_mesh.c: meshes (creation, welding, normals, edges, clustering), the k-d tree
 * against a brute-force scan, the particle graph of a mesh, and exact world copies. */
#include <stdint.h>
#include <stdlib.h>

#include "test.h"
#include "wobble.h"

/* a unit cube as an STL file gives it: 12 triangles, 36 corners, each its own vertex */
static wb_mesh *stl_cube(void)
{
    static const wb_real c[8][3] = { { 0, 0, 0 }, { 1, 0, 0 }, { 1, 1, 0 }, { 0, 1, 0 },
                                     { 0, 0, 1 }, { 1, 0, 1 }, { 1, 1, 1 }, { 0, 1, 1 } };
    static const int f[12][3] = { { 0, 2, 1 }, { 0, 3, 2 }, { 4, 5, 6 }, { 4, 6, 7 }, { 0, 1, 5 }, { 0, 5, 4 },
                                  { 1, 2, 6 }, { 1, 6, 5 }, { 2, 3, 7 }, { 2, 7, 6 }, { 3, 0, 4 }, { 3, 4, 7 } };
    wb_real v[36 * 3];
    int32_t t[36];
    for (int i = 0; i < 36; i++) {
        for (int k = 0; k < 3; k++) v[3 * i + k] = c[f[i / 3][i % 3]][k];
        t[i] = i;
    }
    return wb_mesh_create(v, 36, t, 12, NULL);
}

TEST(mesh_weld_stl_cube)
{
    wb_mesh *m = stl_cube();
    REQUIRE(m);
    CHECK_EQ(m->nv, 36);
    int32_t remap[36];
    CHECK_EQ(wb_mesh_weld(m, 0, remap), WB_OK);
    CHECK_EQ(m->nv, 8);
    CHECK_EQ(m->nt, 12);
    /* order of first occurrence kept: corners 0, 2, 1 of the first triangle come first */
    CHECK_EQ(remap[0], 0);
    CHECK_EQ(remap[1], 1);
    CHECK_EQ(remap[2], 2);
    CHECK_NEAR(m->v[3 * 1 + 0], 1, 0);
    CHECK_NEAR(m->v[3 * 1 + 1], 1, 0);
    /* normals point out of the cube: a corner's normal is along (corner - centre) */
    for (int32_t i = 0; i < m->nv; i++) {
        const wb_real *n = &m->n[3 * i], *p = &m->v[3 * i];
        CHECK_NEAR(n[0] * n[0] + n[1] * n[1] + n[2] * n[2], 1, 1e-12);
        CHECK(n[0] * (p[0] - 0.5) + n[1] * (p[1] - 0.5) + n[2] * (p[2] - 0.5) > 0.5);
    }
    int32_t *ij;
    const int32_t ne = wb_mesh_edges(m, &ij);
    CHECK_EQ(ne, 18); /* 12 cube edges + one diagonal per face */
    for (int32_t i = 0; i < ne; i++) CHECK(ij[2 * i] < ij[2 * i + 1]);
    free(ij);
    wb_mesh_destroy(m);
}

TEST(mesh_weld_tolerance_and_degenerates)
{
    /* two triangles sharing an edge whose copies differ by 1e-9: merged at 1e-6, not at 0 */
    const wb_real v[] = { 0, 0, 0, 1, 0, 0, 0, 1, 0, 1e-9, 1, 0, 1, 1e-9, 0, 1, 1, 0 };
    const int32_t t[] = { 0, 1, 2, 4, 5, 3 };
    wb_mesh *m = wb_mesh_create(v, 6, t, 2, NULL);
    REQUIRE(m);
    CHECK_EQ(wb_mesh_weld(m, 0, NULL), WB_OK);
    CHECK_EQ(m->nv, 6);
    CHECK_EQ(wb_mesh_weld(m, 1e-6, NULL), WB_OK);
    CHECK_EQ(m->nv, 4);
    CHECK_EQ(m->nt, 2);
    /* a tolerance that swallows a whole triangle drops it */
    CHECK_EQ(wb_mesh_weld(m, 2, NULL), WB_OK);
    CHECK_EQ(m->nv, 1);
    CHECK_EQ(m->nt, 0);
    CHECK_EQ(wb_mesh_weld(m, -1, NULL), WB_ERR_ARG);
    wb_mesh_destroy(m);
}

TEST(mesh_create_rejects_bad_input)
{
    const wb_real v[] = { 0, 0, 0, 1, 0, 0, 0, 1, 0 };
    const int32_t bad[] = { 0, 1, 3 };
    wb_status st = WB_OK;
    CHECK(wb_mesh_create(v, 3, bad, 1, &st) == NULL);
    CHECK_EQ(st, WB_ERR_ARG);
    CHECK_HAS(wb_last_error(), "out of range");
    const wb_real nan_v[] = { 0, 0, 0, NAN, 0, 0, 0, 1, 0 };
    const int32_t t[] = { 0, 1, 2 };
    CHECK(wb_mesh_create(nan_v, 3, t, 1, &st) == NULL);
    CHECK_HAS(wb_last_error(), "not finite");
    /* a triangle repeating a corner is dropped, not an error */
    const int32_t degen[] = { 0, 1, 1, 0, 1, 2 };
    wb_mesh *m = wb_mesh_create(v, 3, degen, 2, &st);
    REQUIRE(m);
    CHECK_EQ(m->nt, 1);
    wb_mesh_destroy(m);
}

static uint32_t rng = 12345;
static wb_real rnd(void)
{
    rng = rng * 1664525u + 1013904223u;
    return (rng >> 8) / (wb_real)(1u << 24);
}

TEST(kdtree_matches_brute_force)
{
    enum { N = 3000, Q = 300, K = 7 };
    static wb_real p[N * 3];
    for (int i = 0; i < 3 * N; i++) p[i] = rnd();
    /* some exact duplicates and points on a grid: ties must break by index */
    for (int i = 0; i < 100; i++)
        for (int k = 0; k < 3; k++) p[3 * (N - 1 - i) + k] = p[3 * i + k];
    for (int i = 100; i < 300; i++)
        for (int k = 0; k < 3; k++) p[3 * i + k] = (wb_real)((i + k) % 5) / 4;
    wb_kdtree *t = wb_kdtree_build(p, N);
    REQUIRE(t);
    for (int q = 0; q < Q; q++) {
        wb_real x[3] = { rnd(), rnd(), rnd() };
        if (q % 3 == 0)
            for (int k = 0; k < 3; k++) x[k] = p[3 * (q * 7 % N) + k];
        int32_t ids[K];
        wb_real d2[K];
        REQUIRE(wb_kdtree_knn(t, x, K, ids, d2) == K);
        /* brute force: the K smallest (d2, index) pairs, in order */
        int32_t best[K];
        wb_real bd[K];
        int nb = 0;
        for (int32_t i = 0; i < N; i++) {
            wb_real dx = p[3 * i] - x[0], dy = p[3 * i + 1] - x[1], dz = p[3 * i + 2] - x[2];
            wb_real d = dx * dx + dy * dy + dz * dz;
            int j = nb < K ? nb++ : K;
            while (j > 0 && (bd[j - 1] > d)) {
                if (j < K) { bd[j] = bd[j - 1]; best[j] = best[j - 1]; }
                j--;
            }
            if (j < K) { bd[j] = d; best[j] = i; }
        }
        for (int k = 0; k < K; k++) {
            CHECK_EQ(ids[k], best[k]);
            CHECK_NEAR(d2[k], bd[k], 0);
        }
    }
    wb_real x[3] = { 0, 0, 0 };
    CHECK_EQ(wb_kdtree_knn(t, x, 0, NULL, NULL), 0);
    wb_kdtree_destroy(t);
    wb_kdtree *e = wb_kdtree_build(p, 0);
    REQUIRE(e);
    CHECK_EQ(wb_kdtree_knn(e, x, 3, NULL, NULL), 0);
    wb_kdtree_destroy(e);
}

/* a closed grid sphere (UV sphere with shared poles) */
static wb_mesh *uv_sphere(int nu, int nv, wb_real r)
{
    const int32_t n = 2 + nu * (nv - 1);
    wb_real *v = malloc(sizeof *v * 3 * (size_t)n);
    int32_t *t = malloc(sizeof *t * 6 * (size_t)nu * (size_t)nv);
    int32_t k = 0, nt = 0;
    v[k++] = 0; v[k++] = r; v[k++] = 0;
    v[k++] = 0; v[k++] = -r; v[k++] = 0;
    for (int j = 1; j < nv; j++)
        for (int i = 0; i < nu; i++) {
            wb_real th = 3.14159265358979 * j / nv, ph = 2 * 3.14159265358979 * i / nu;
            v[k++] = r * sin(th) * cos(ph);
            v[k++] = r * cos(th);
            v[k++] = r * sin(th) * sin(ph);
        }
#define RING(j, i) (2 + ((j) - 1) * nu + ((i) % nu))
    for (int i = 0; i < nu; i++) {
        t[3 * nt] = 0; t[3 * nt + 1] = RING(1, i + 1); t[3 * nt + 2] = RING(1, i); nt++;
        t[3 * nt] = 1; t[3 * nt + 1] = RING(nv - 1, i); t[3 * nt + 2] = RING(nv - 1, i + 1); nt++;
        for (int j = 1; j + 1 < nv; j++) {
            t[3 * nt] = RING(j, i); t[3 * nt + 1] = RING(j, i + 1); t[3 * nt + 2] = RING(j + 1, i); nt++;
            t[3 * nt] = RING(j + 1, i); t[3 * nt + 1] = RING(j, i + 1); t[3 * nt + 2] = RING(j + 1, i + 1); nt++;
        }
    }
#undef RING
    wb_mesh *m = wb_mesh_create(v, n, t, nt, NULL);
    free(v);
    free(t);
    return m;
}

TEST(mesh_cluster_target)
{
    wb_mesh *m = uv_sphere(64, 32, 1);
    REQUIRE(m);
    int32_t *cl = malloc(sizeof *cl * (size_t)m->nv);
    const int32_t targets[] = { 20, 100, 400 };
    for (int i = 0; i < 3; i++) {
        const int32_t n = wb_mesh_cluster(m, targets[i], cl);
        /* about the target: the occupied-cell count moves in steps */
        CHECK(n > targets[i] * 6 / 10 && n < targets[i] * 14 / 10);
        int ok = 1;
        for (int32_t v = 0; v < m->nv; v++) ok &= cl[v] >= 0 && cl[v] < n;
        CHECK(ok);
    }
    CHECK_EQ(wb_mesh_cluster(m, m->nv + 5, cl), m->nv);
    CHECK_EQ(wb_mesh_cluster(m, 0, cl), WB_ERR_ARG);
    free(cl);
    wb_mesh_destroy(m);
}

TEST(from_mesh_graph)
{
    wb_mesh *m = stl_cube();
    REQUIRE(m);
    wb_mesh_weld(m, 0, NULL);
    wb_world_def wd = wb_world_default_def();
    wb_world *w = wb_world_create(&wd);
    REQUIRE(w);
    wb_from_mesh_def d = wb_from_mesh_default_def();
    d.mass = 8;
    wb_body b;
    REQUIRE(wb_from_mesh(w, m, &d, &b) == WB_OK);
    CHECK_EQ(b.first, 0);
    CHECK_EQ(b.count, 8);
    CHECK_EQ(wb_distance_count(w), 18);
    CHECK_EQ(wb_surface_count(w), 1);
    CHECK_NEAR(wb_particle_mass(w, 3), 1, 1e-15);
    /* rest lengths are the mesh's: the structure is at rest */
    CHECK_NEAR(wb_world_max_strain(w), 0, 1e-15);
    /* k nearest links brace the hollow shell: the body diagonals of the cube appear */
    d.neighbours = 7;
    REQUIRE(wb_from_mesh(w, m, &d, &b) == WB_OK);
    CHECK_EQ(b.first, 8);
    CHECK_EQ(wb_distance_count(w), 18 + 28); /* every pair of 8 corners */
    /* bad options change nothing */
    const int32_t np = wb_particle_count(w), nd = wb_distance_count(w);
    d.mass = -1;
    CHECK_EQ(wb_from_mesh(w, m, &d, &b), WB_ERR_ARG);
    CHECK_HAS(wb_last_error(), "mass");
    CHECK_EQ(wb_particle_count(w), np);
    CHECK_EQ(wb_distance_count(w), nd);
    wb_mesh_destroy(m);
    /* clustering: a 4000-vertex sphere as a graph of about 60 particles */
    wb_mesh *s = uv_sphere(64, 64, 1);
    REQUIRE(s);
    d = wb_from_mesh_default_def();
    d.target = 60;
    REQUIRE(wb_from_mesh(w, s, &d, &b) == WB_OK);
    CHECK(b.count > 36 && b.count < 84);
    CHECK_EQ(wb_surface_count(w), 3);
    wb_mesh_destroy(s);
    wb_world_destroy(w);
}

TEST(world_clone_exact)
{
    wb_world_def wd = wb_world_default_def();
    wd.substeps = 8;
    wb_world *w = wb_world_create(&wd);
    REQUIRE(w);
    wb_lattice_def ld = wb_lattice_default_def();
    ld.min[1] = 0.3;
    ld.max[1] = 1.3;
    ld.link.compliance = 1e-4;
    ld.link.yield = 0.01;
    ld.link.creep = 5;
    ld.link.break_strain = 0.3;
    wb_body b;
    REQUIRE(wb_lattice(w, &ld, &b) == WB_OK);
    wb_particle_pin(w, 0, NULL);
    wb_collider_def pd = wb_collider_default_def(WB_SHAPE_PLANE);
    pd.friction = 0.5;
    wb_collider_add(w, &pd, NULL);
    wb_collider_def bd = wb_collider_default_def(WB_SHAPE_BOX);
    bd.center[1] = 2;
    bd.friction = 0.3;
    wb_collider_id box = wb_collider_add(w, &bd, NULL);
    wb_collider_def sd = wb_collider_default_def(WB_SHAPE_SPHERE);
    wb_collider_remove(w, wb_collider_add(w, &sd, NULL)); /* a dead slot */
    wb_distance_remove(w, wb_distance_at(w, 5));          /* a free constraint slot */
    for (int f = 0; f < 30; f++) {
        const wb_real p[3] = { 0.1 * f / 30, 2 - 1.2 * f / 30, 0 };
        wb_collider_set_position(w, box, p);
        wb_world_step(w);
    }
    /* mid-sweep: the box has a pose set that the next step will reach */
    const wb_real p[3] = { 0.2, 0.7, 0 };
    wb_collider_set_position(w, box, p);
    wb_world *c = wb_world_clone(w);
    REQUIRE(c);
    CHECK(wb_world_hash(c) == wb_world_hash(w));
    for (int f = 0; f < 40; f++) {
        wb_world_step(w);
        wb_world_step(c);
    }
    CHECK(wb_world_hash(c) == wb_world_hash(w));
    CHECK_EQ(wb_distance_count(c), wb_distance_count(w));
    wb_world_destroy(c);
    wb_world_destroy(w);
}
