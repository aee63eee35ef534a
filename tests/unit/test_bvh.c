/* test_bvh.c: the mesh collider's tree and point-triangle projection (white-box:
 * includes core/bvh.h).
 *
 *   - the closest point on a triangle lies on it and no point of a fine grid over the
 *     triangle is closer (the grid's spacing bounds how much closer one could be);
 *   - the tree's closest point equals brute force over every triangle, bit for bit
 *     (the tree prunes only boxes strictly farther than the best, and ties go to the
 *     lower triangle in both), on random triangle soups and random points near and far;
 *   - a closed mesh is recognised as closed, an open one as open, and a mesh collider's
 *     copy is charged to the world's memory budget and given back when removed. */
#include <stdlib.h>

#include "core/core.h"
#include "core/bvh.h"
#include "test.h"

static double rnd(unsigned *s)
{
    *s = *s * 1664525u + 1013904223u;
    return (double)(*s >> 8) / (double)(1u << 24);
}

TEST(bvh_point_triangle_projection)
{
    unsigned seed = 7;
    for (int it = 0; it < 300; it++) {
        wb_real a[3], b[3], c[3], p[3], q[3];
        for (int k = 0; k < 3; k++) {
            a[k] = rnd(&seed) * 2 - 1;
            b[k] = rnd(&seed) * 2 - 1;
            c[k] = rnd(&seed) * 2 - 1;
            p[k] = rnd(&seed) * 4 - 2;
        }
        int region = -1;
        const wb_real d2 = wb__closest_on_triangle(p, a, b, c, q, &region);
        CHECK(region >= WB_REGION_FACE && region <= WB_REGION_E20);
        /* on the triangle: q = a + v (b - a) + w (c - a) with v, w >= 0, v + w <= 1 */
        wb_real e1[3], e2[3], r[3], n[3];
        v3_sub(e1, b, a);
        v3_sub(e2, c, a);
        v3_sub(r, q, a);
        v3_cross(n, e1, e2);
        const wb_real d11 = v3_dot(e1, e1), d12 = v3_dot(e1, e2), d22 = v3_dot(e2, e2);
        const wb_real r1 = v3_dot(r, e1), r2 = v3_dot(r, e2), den = d11 * d22 - d12 * d12;
        const wb_real v = (d22 * r1 - d12 * r2) / den, w = (d11 * r2 - d12 * r1) / den;
        CHECK(v >= -1e-9 && w >= -1e-9 && v + w <= 1 + 1e-9);
        CHECK_NEAR(v3_dot(r, n) / v3_len(n), 0, 1e-12);
        /* no grid point closer: a grid of step 1/N is within h = (|e1| + |e2|) / N of any point */
        const int N = 60;
        wb_real best = INFINITY;
        for (int i = 0; i <= N; i++)
            for (int j = 0; i + j <= N; j++) {
                wb_real g[3], dd[3];
                for (int k = 0; k < 3; k++) g[k] = a[k] + e1[k] * i / N + e2[k] * j / N;
                v3_sub(dd, p, g);
                if (v3_dot(dd, dd) < best) best = v3_dot(dd, dd);
            }
        CHECK(sqrt(d2) <= sqrt(best) + 1e-12);
        CHECK(sqrt(best) - sqrt(d2) <= (v3_len(e1) + v3_len(e2)) / N);
    }
}

TEST(bvh_closest_matches_brute_force)
{
    unsigned seed = 11;
    for (int mesh = 0; mesh < 6; mesh++) {
        const int32_t nv = 30 + 150 * mesh, nt = 20 + 200 * mesh;
        wb_real *v = malloc(sizeof(wb_real) * 3 * (size_t)nv);
        int32_t *t = malloc(sizeof(int32_t) * 3 * (size_t)nt);
        REQUIRE(v && t);
        for (int32_t i = 0; i < 3 * nv; i++) v[i] = rnd(&seed) * 2 - 1;
        for (int32_t i = 0; i < 3 * nt; i++) t[i] = (int32_t)(rnd(&seed) * nv) % nv;
        wb_colmesh *cm = wb__colmesh_build(v, nv, t, nt, mesh % 2 ? 2.5 : 1);
        REQUIRE(cm);
        CHECK(!cm->closed);
        int agree = 0;
        for (int q = 0; q < 400; q++) {
            wb_real p[3], c1[3], c2[3];
            const double spread = q % 4 == 0 ? 20 : 3;
            for (int k = 0; k < 3; k++) p[k] = (rnd(&seed) * 2 - 1) * spread;
            int32_t t1, t2;
            int r1, r2;
            const wb_real d1 = wb__colmesh_closest(cm, p, c1, &t1, &r1);
            const wb_real d2 = wb__colmesh_closest_brute(cm, p, c2, &t2, &r2);
            agree += d1 == d2 && t1 == t2 && r1 == r2 && !memcmp(c1, c2, sizeof c1);
            /* within a bound: the same answer when the bound holds it, none past it */
            int32_t t3;
            int r3;
            wb_real c3[3];
            wb__colmesh_closest_within(cm, p, d2 * 1.0001 + 1e-300, c3, &t3, &r3);
            CHECK_EQ(t3, t2);
            wb__colmesh_closest_within(cm, p, d2 * 0.999, c3, &t3, &r3);
            CHECK_EQ(t3, -1);
        }
        CHECK_EQ(agree, 400);
        wb__colmesh_free(cm);
        free(v);
        free(t);
    }
}

/* an octahedron: closed; without one face: open */
static const wb_real octa_v[] = { 1, 0, 0, -1, 0, 0, 0, 1, 0, 0, -1, 0, 0, 0, 1, 0, 0, -1 };
static const int32_t octa_t[] = { 0, 2, 4, 2, 1, 4, 1, 3, 4, 3, 0, 4, 2, 0, 5, 1, 2, 5, 3, 1, 5, 0, 3, 5 };

TEST(bvh_closed_and_open_and_sign)
{
    wb_colmesh *cm = wb__colmesh_build(octa_v, 6, octa_t, 8, 1);
    REQUIRE(cm);
    CHECK(cm->closed);
    /* inside: minus the distance to the nearest face plane, |x|+|y|+|z| = 1 */
    const wb_real in[3] = { 0.1, 0.2, -0.05 }, out[3] = { 0.1, 2, 0.3 }, tip[3] = { 2, 0, 0 };
    CHECK_NEAR(wb__colmesh_distance(cm, in, NULL, NULL, NULL), (0.35 - 1) / sqrt(3), 1e-15);
    CHECK(wb__colmesh_distance(cm, out, NULL, NULL, NULL) > 0);
    /* past a vertex: the vertex's pseudo-normal signs it (a face normal alone can fail) */
    CHECK_NEAR(wb__colmesh_distance(cm, tip, NULL, NULL, NULL), 1, 1e-15);
    const wb_real tip_in[3] = { 0.999, 0, 0 };
    CHECK_NEAR(wb__colmesh_distance(cm, tip_in, NULL, NULL, NULL), -0.001 / sqrt(3), 1e-12);
    wb__colmesh_free(cm);
    /* a sharp pyramid (apex (0,10,0)): past the apex, sideways, the closest point is the
     * apex for all four sides (a tie: the first side, +x, is taken), and the +x face's
     * normal says "inside" for a point on the -x side; the apex's angle-weighted
     * pseudo-normal (about +y) signs it right (Bærentzen & Aanæs's case for them) */
    static const wb_real pyr_v[] = { -1, 0, -1, 1, 0, -1, 1, 0, 1, -1, 0, 1, 0, 10, 0 };
    static const int32_t pyr_t[] = { 1, 4, 2, 0, 3, 4, 2, 4, 3, 0, 4, 1, 0, 1, 2, 0, 2, 3 };
    cm = wb__colmesh_build(pyr_v, 5, pyr_t, 6, 1);
    REQUIRE(cm);
    CHECK(cm->closed);
    const wb_real side[3] = { -0.5, 10.25, 0 };
    CHECK_NEAR(wb__colmesh_distance(cm, side, NULL, NULL, NULL), 0.5 * sqrt(1.25), 1e-14);
    /* and near an edge of the base, outside below it: the edge's pseudo-normal */
    const wb_real below[3] = { 1.2, -0.01, 0 };
    CHECK(wb__colmesh_distance(cm, below, NULL, NULL, NULL) > 0);
    wb__colmesh_free(cm);
    cm = wb__colmesh_build(octa_v, 6, octa_t, 7, 1);
    REQUIRE(cm);
    CHECK(!cm->closed);
    CHECK(wb__colmesh_distance(cm, in, NULL, NULL, NULL) > 0); /* open: two-sided, never negative */
    wb__colmesh_free(cm);
}

TEST(bvh_mesh_collider_memory_charged)
{
    wb_memory mem = { 0, 0 };
    wb_world_def wd = wb_world_default_def();
    wd.memory = &mem;
    wb_world *w = wb_world_create(&wd);
    REQUIRE(w);
    wb_status st;
    wb_mesh *m = wb_mesh_create(octa_v, 6, octa_t, 8, &st);
    REQUIRE(m);
    wb_collider_def d = wb_collider_default_def(WB_SHAPE_MESH);
    d.mesh = m;
    const size_t before = mem.used;
    wb_collider_id c = wb_collider_add(w, &d, &st);
    CHECK_EQ(st, WB_OK);
    CHECK(mem.used > before);
    wb_collider_remove(w, c);
    CHECK_EQ((long long)mem.used, (long long)before);
    /* a budget too small for the copy: refused, nothing added */
    mem.limit = mem.used + 16;
    c = wb_collider_add(w, &d, &st);
    CHECK_EQ(st, WB_ERR_NOMEM);
    CHECK_EQ(wb_collider_count(w), 0);
    mem.limit = 0;
    c = wb_collider_add(w, &d, &st);
    CHECK_EQ(st, WB_OK);
    wb_world_destroy(w); /* gives the copy back */
    CHECK_EQ((long long)mem.used, 0);
    wb_mesh_destroy(m);
}
