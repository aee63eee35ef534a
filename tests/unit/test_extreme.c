/* test_extreme.c: extreme but finite input. Every quantity the core derives (positions,
 * rest lengths, masses per particle, weld tolerances, normals, skin weights, 1/h^2) is
 * either representable or refused with an argument error that names the option, and a
 * refusal changes nothing. */
#include <float.h>
#include <stdlib.h>

#include "../../src/wobble.h"
#include "test.h"

static void v3_set_(wb_real *o, wb_real x, wb_real y, wb_real z) { o[0] = x; o[1] = y; o[2] = z; }

static wb_world *new_world(void)
{
    wb_world_def d = wb_world_default_def();
    return wb_world_create(&d);
}

/* counts and hash before == after: nothing changed */
#define CHECK_UNCHANGED(w, np, nd, hash)                  \
    do {                                                  \
        CHECK_EQ(wb_particle_count(w), np);               \
        CHECK_EQ(wb_distance_count(w), nd);               \
        CHECK(wb_world_hash(w) == (hash));                \
    } while (0)

TEST(extreme_builders_refuse_overflowing_extents)
{
    wb_world *w = new_world();
    const wb_real p0[3] = { 0, 0, 0 };
    wb_particle_add(w, p0, NULL, 1, 0.02);
    const uint64_t h0 = wb_world_hash(w);
    wb_body b;

    wb_rope_def r = wb_rope_default_def();
    r.from[0] = -1e308;
    r.to[0] = 1e308; /* to - from overflows */
    CHECK_EQ(wb_rope(w, &r, &b), WB_ERR_ARG);
    CHECK_HAS(wb_last_error(), "from/to");
    CHECK_UNCHANGED(w, 1, 0, h0);
    r.from[0] = -1e200; /* positions finite, but a length squared overflows */
    r.to[0] = 1e200;
    CHECK_EQ(wb_rope(w, &r, &b), WB_ERR_ARG);
    CHECK_HAS(wb_last_error(), "from/to");
    CHECK_UNCHANGED(w, 1, 0, h0);

    wb_cloth_def c = wb_cloth_default_def();
    c.origin[0] = 1e308;
    c.size[0] = 1e308; /* origin + size overflows */
    CHECK_EQ(wb_cloth(w, &c, &b), WB_ERR_ARG);
    CHECK_HAS(wb_last_error(), "origin/size");
    CHECK_UNCHANGED(w, 1, 0, h0);

    wb_lattice_def l = wb_lattice_default_def();
    for (int i = 0; i < 3; i++) { l.min[i] = -1e308; l.max[i] = 1e308; }
    CHECK_EQ(wb_lattice(w, &l, &b), WB_ERR_ARG);
    CHECK_HAS(wb_last_error(), "min/max");
    CHECK_UNCHANGED(w, 1, 0, h0);

    /* the same extents scaled into range build */
    r.from[0] = -1e100;
    r.to[0] = 1e100;
    CHECK_EQ(wb_rope(w, &r, &b), WB_OK);
    CHECK_EQ(b.count, 11);
    wb_world_destroy(w);
}

TEST(extreme_builders_refuse_underflowing_mass_per_particle)
{
    wb_world *w = new_world();
    const uint64_t h0 = wb_world_hash(w);
    wb_body b;
    /* 1e-320 over 11 particles: each mass's inverse overflows; this used to fail half-way,
     * after the first particle was added */
    wb_rope_def r = wb_rope_default_def();
    r.mass = 1e-320;
    CHECK_EQ(wb_rope(w, &r, &b), WB_ERR_ARG);
    CHECK_HAS(wb_last_error(), "mass");
    CHECK_UNCHANGED(w, 0, 0, h0);
    wb_cloth_def c = wb_cloth_default_def();
    c.mass = 1e-310;
    CHECK_EQ(wb_cloth(w, &c, &b), WB_ERR_ARG);
    CHECK_UNCHANGED(w, 0, 0, h0);
    /* a huge mass splits into finite masses */
    r.mass = 1e308;
    REQUIRE(wb_rope(w, &r, &b) == WB_OK);
    CHECK(isfinite(wb_particle_mass(w, 0)) && wb_particle_mass(w, 0) > 0);
    wb_world_destroy(w);
}

TEST(extreme_distance_refuses_overflowing_rest)
{
    wb_world *w = new_world();
    const wb_real a[3] = { -1e200, 0, 0 }, b[3] = { 1e200, 0, 0 }, c[3] = { 1, 0, 0 };
    wb_particle_add(w, a, NULL, 1, 0);
    wb_particle_add(w, b, NULL, 1, 0);
    wb_particle_add(w, c, NULL, 1, 0);
    const uint64_t h0 = wb_world_hash(w);
    wb_distance_def d = wb_distance_default_def();
    wb_status st = WB_OK;
    /* computed: |b - a|^2 overflows, the rest would be inf */
    wb_distance_id id = wb_distance_add(w, 0, 1, &d, &st);
    CHECK_EQ(st, WB_ERR_ARG);
    CHECK(id.gen == 0);
    CHECK_HAS(wb_last_error(), "too far apart");
    CHECK_UNCHANGED(w, 3, 0, h0);
    /* given: the same rule (the solver squares lengths) */
    d.rest = 1e200;
    CHECK_HAS(wb_distance_def_check(&d), "rest");
    wb_distance_add(w, 1, 2, &d, &st);
    CHECK_EQ(st, WB_ERR_ARG);
    CHECK_UNCHANGED(w, 3, 0, h0);
    d.rest = 1e150;
    CHECK(wb_distance_def_check(&d) == NULL);
    wb_world_destroy(w);
}

TEST(extreme_dt_that_cannot_step_refused)
{
    wb_world_def d = wb_world_default_def();
    d.dt = 1e-300;
    CHECK_HAS(wb_world_def_check(&d), "dt/substeps");
    d.dt = 1e-150; /* h = 1e-151, h^2 = 1e-302: normal */
    CHECK(wb_world_def_check(&d) == NULL);
    d.substeps = 10000; /* h = 1e-154: h^2 underflows */
    CHECK_HAS(wb_world_def_check(&d), "dt/substeps");
    /* the setter refuses it and keeps the old settings */
    wb_world_def ok = wb_world_default_def();
    wb_world *w = wb_world_create(&ok);
    CHECK_EQ(wb_world_set_def(w, &d), WB_ERR_ARG);
    CHECK(wb_world_get_def(w).dt == ok.dt && wb_world_get_def(w).substeps == ok.substeps);
    /* the shortest accepted h steps without undoing a frame */
    d.dt = 1e-150;
    d.substeps = 10;
    REQUIRE(wb_world_set_def(w, &d) == WB_OK);
    const wb_real p[3] = { 0, 1, 0 }, q[3] = { 0, 2, 0 };
    wb_particle_add(w, p, NULL, 1, 0);
    wb_particle_add(w, q, NULL, 1, 0);
    wb_distance_add(w, 0, 1, &(wb_distance_def){ 0, 0, -1, 0, 0, 0, 0 }, NULL);
    for (int i = 0; i < 3; i++) wb_world_step(w);
    CHECK_EQ(wb_world_warnings(w), 0);
    wb_world_destroy(w);
}

TEST(extreme_compliance_over_h2_overflow_is_no_stiffness)
{
    /* compliance 1e308 / h^2 overflows: the constraint is infinitely soft, not NaN */
    wb_world *w = new_world();
    const wb_real p[3] = { 0, 1, 0 }, q[3] = { 0, 2, 0 };
    wb_particle_add(w, p, NULL, 1, 0);
    wb_particle_add(w, q, NULL, 1, 0);
    wb_distance_def d = wb_distance_default_def();
    d.compliance = 1e308;
    wb_distance_id c = wb_distance_add(w, 0, 1, &d, NULL);
    for (int i = 0; i < 10; i++) wb_world_step(w);
    CHECK_EQ(wb_world_warnings(w), 0);
    wb_real x[3];
    wb_particle_position(w, 0, x);
    CHECK(x[1] < 0.9); /* fell freely: 1 - g t^2 / 2 = 0.86 after 1/6 s */
    CHECK(wb_distance_force(w, c) == 0);
    wb_world_destroy(w);
}

TEST(extreme_weld_tolerance_of_huge_and_tiny_boxes)
{
    const wb_real v[9] = { -1e308, 0, 0, 1e308, 0, 0, 1e308, 1e308, 0 };
    const int32_t tri[3] = { 0, 1, 2 };
    wb_mesh *m = wb_mesh_create(v, 3, tri, 1, NULL);
    REQUIRE(m != NULL);
    const wb_real tol = wb_mesh_weld_tolerance(m);
    CHECK(isfinite(tol) && tol > 1e302 && tol < 1e303);
    CHECK_EQ(wb_mesh_weld(m, tol, NULL), WB_OK);
    CHECK_EQ(m->nv, 3); /* 2e308 apart is not within 3e302 */
    /* the weld compares lengths in units of tol: 5e302 apart (squared: inf) is not within */
    const wb_real v2[6] = { 0, 0, 0, 5e302, 0, 0 };
    wb_mesh *m2 = wb_mesh_create(v2, 2, NULL, 0, NULL);
    REQUIRE(m2 != NULL);
    CHECK_EQ(wb_mesh_weld(m2, 3e302, NULL), WB_OK);
    CHECK_EQ(m2->nv, 2);
    CHECK_EQ(wb_mesh_weld(m2, 6e302, NULL), WB_OK);
    CHECK_EQ(m2->nv, 1);
    /* a 1e-200 m box: its diagonal squared underflows, the tolerance does not */
    const wb_real v4[6] = { 0, 0, 0, 3e-200, 4e-200, 0 };
    wb_mesh *m4 = wb_mesh_create(v4, 2, NULL, 0, NULL);
    REQUIRE(m4 != NULL);
    CHECK_NEAR(wb_mesh_weld_tolerance(m4) / 5e-206, 1, 1e-12);
    wb_mesh_destroy(m4);
    /* and tiny: 5e-200 apart (squared: 0) is not within 1e-200 */
    const wb_real v3[6] = { 0, 0, 0, 5e-200, 0, 0 };
    wb_mesh *m3 = wb_mesh_create(v3, 2, NULL, 0, NULL);
    REQUIRE(m3 != NULL);
    CHECK_EQ(wb_mesh_weld(m3, 1e-200, NULL), WB_OK);
    CHECK_EQ(m3->nv, 2);
    wb_mesh_destroy(m);
    wb_mesh_destroy(m2);
    wb_mesh_destroy(m3);
}

/* a right triangle in the xy plane scaled by s: its normals are +z at every size */
static void check_normals_at_scale(wb_real s)
{
    const wb_real v[9] = { 0, 0, 0, s, 0, 0, 0, s, 0 };
    const int32_t tri[3] = { 0, 1, 2 };
    wb_mesh *m = wb_mesh_create(v, 3, tri, 1, NULL);
    REQUIRE(m != NULL);
    for (int i = 0; i < 3; i++) {
        CHECK_NEAR(m->n[3 * i], 0, 0);
        CHECK_NEAR(m->n[3 * i + 1], 0, 0);
        CHECK_NEAR(m->n[3 * i + 2], 1, 1e-15);
    }
    wb_mesh_destroy(m);
}

TEST(extreme_normals_of_tiny_and_huge_triangles)
{
    check_normals_at_scale(1);
    check_normals_at_scale(1e-200); /* cross product underflows to 0 unscaled */
    check_normals_at_scale(1e-320); /* subnormal coordinates */
    check_normals_at_scale(1e200);  /* cross product overflows: inf / inf = NaN unscaled */
    check_normals_at_scale(1.5e308);
}

TEST(extreme_from_mesh_refuses_overflowing_extent)
{
    wb_world *w = new_world();
    const wb_real v[9] = { -1e200, 0, 0, 1e200, 0, 0, 0, 1e200, 0 };
    const int32_t tri[3] = { 0, 1, 2 };
    wb_mesh *m = wb_mesh_create(v, 3, tri, 1, NULL);
    REQUIRE(m != NULL);
    wb_from_mesh_def d = wb_from_mesh_default_def();
    wb_body b;
    const uint64_t h0 = wb_world_hash(w);
    CHECK_EQ(wb_from_mesh(w, m, &d, &b), WB_ERR_ARG);
    CHECK_HAS(wb_last_error(), "too large");
    CHECK_UNCHANGED(w, 0, 0, h0);
    /* vertices near 1e308 but close together: their centroid must not overflow */
    const wb_real v2[9] = { 1.7e308, 0, 0, 1.7e308, 1, 0, 1.7e308, 0, 1 };
    wb_mesh *m2 = wb_mesh_create(v2, 3, tri, 1, NULL);
    d.target = 1;
    CHECK_EQ(wb_from_mesh(w, m2, &d, &b), WB_OK);
    CHECK_EQ(b.count, 1);
    wb_real x[3];
    wb_particle_position(w, 0, x);
    CHECK(isfinite(x[0]) && x[0] == 1.7e308);
    /* a mass too small to split */
    d.target = 0;
    d.mass = 1e-322;
    CHECK_EQ(wb_from_mesh(w, m2, &d, &b), WB_ERR_ARG);
    CHECK_HAS(wb_last_error(), "mass");
    CHECK_EQ(wb_particle_count(w), 1);
    wb_mesh_destroy(m);
    wb_mesh_destroy(m2);
    wb_world_destroy(w);
}

TEST(extreme_kdtree_knn_except_bounded_under_ties)
{
    /* 40 points 5e-324 apart: every squared distance underflows to 0, all tie */
    enum { N = 40 };
    wb_real p[3 * N];
    for (int i = 0; i < N; i++) { p[3 * i] = i * 4.9406564584124654e-324; p[3 * i + 1] = p[3 * i + 2] = 0; }
    wb_kdtree *t = wb_kdtree_build(p, N);
    REQUIRE(t != NULL);
    for (int i = 0; i < N; i++) {
        int32_t ids[9];
        ids[8] = -7; /* a canary past the k = 8 asked for */
        const int got = wb_kdtree_knn_except(t, &p[3 * i], 8, i, ids, NULL);
        CHECK_EQ(got, 8);
        CHECK_EQ(ids[8], -7);
        for (int j = 0; j < got; j++) CHECK(ids[j] != i);
    }
    wb_kdtree_destroy(t);
}

TEST(extreme_from_mesh_neighbours_with_ties)
{
    /* each particle's k nearest tie at 0 with lower ids: asking k + 1 and dropping itself
     * wrote k + 1 links for most particles into room for k (heap overflow under ASan) */
    enum { N = 40, K = 8 };
    wb_real v[3 * N];
    for (int i = 0; i < N; i++) { v[3 * i] = i * 4.9406564584124654e-324; v[3 * i + 1] = v[3 * i + 2] = 0; }
    wb_mesh *m = wb_mesh_create(v, N, NULL, 0, NULL);
    REQUIRE(m != NULL);
    wb_world *w = new_world();
    wb_from_mesh_def d = wb_from_mesh_default_def();
    d.neighbours = K;
    wb_body b;
    REQUIRE(wb_from_mesh(w, m, &d, &b) == WB_OK);
    CHECK_EQ(b.count, N);
    CHECK(wb_distance_count(w) <= N * K);
    wb_mesh_destroy(m);
    wb_world_destroy(w);
}

TEST(extreme_skin_neighbours_with_ties)
{
    /* 40 particles on a circle of radius 5e-163 (every particle-particle distance squared
     * underflows to 0) and a vertex far out beside each, so that every particle is some
     * vertex's bone: each bone's 33 nearest tie at 0, and with the 32 neighbours asked
     * as 33-and-drop-itself the neighbour table overflowed */
    enum { N = 40 };
    wb_world *w = new_world();
    wb_real v[3 * N];
    for (int i = 0; i < N; i++) {
        const double a = 2 * 3.14159265358979 * i / N;
        const wb_real x[3] = { 5e-163 * cos(a), 5e-163 * sin(a), 0 };
        wb_particle_add(w, x, NULL, 1, 0);
        v[3 * i] = 1e-152 * cos(a);
        v[3 * i + 1] = 1e-152 * sin(a);
        v[3 * i + 2] = 0;
    }
    wb_mesh *m = wb_mesh_create(v, N, NULL, 0, NULL);
    REQUIRE(m != NULL);
    int32_t ids[N];
    for (int i = 0; i < N; i++) ids[i] = i;
    wb_skin_def sd = wb_skin_default_def();
    sd.bones = 1;
    sd.neighbours = 32;
    wb_status st;
    wb_skin *s = wb_skin_create(w, m, ids, N, &sd, &st);
    REQUIRE(s != NULL);
    /* every particle is a bone of its own vertex */
    for (int i = 0; i < N; i++) {
        int32_t pp[1];
        CHECK_EQ(wb_skin_influences(s, i, pp, NULL), 1);
        CHECK_EQ(pp[0], i);
    }
    wb_skin_destroy(s);
    wb_mesh_destroy(m);
    wb_world_destroy(w);
}

TEST(extreme_skin_refuses_vertices_out_of_range)
{
    wb_world *w = new_world();
    const wb_real x[3] = { -1e200, 0, 0 };
    wb_particle_add(w, x, NULL, 1, 0);
    const wb_real v[3] = { 1e200, 0, 0 };
    wb_mesh *m = wb_mesh_create(v, 1, NULL, 0, NULL);
    int32_t id = 0;
    wb_skin_def sd = wb_skin_default_def();
    wb_status st;
    CHECK(wb_skin_create(w, m, &id, 1, &sd, &st) == NULL);
    CHECK_EQ(st, WB_ERR_ARG);
    CHECK_HAS(wb_last_error(), "too far");
    wb_mesh_destroy(m);
    wb_world_destroy(w);
}

TEST(extreme_damping_overflow_is_the_infinitely_damped_limit)
{
    /* compliance/h^2 * damping * h overflows: the limit, not inf * 0 = NaN */
    wb_world *w = new_world();
    const wb_real p[3] = { 0, 1, 0 }, q[3] = { 0, 2, 0 }, v[3] = { 0, 5, 0 };
    wb_particle_add(w, p, NULL, 1, 0);
    wb_particle_add(w, q, v, 1, 0);
    wb_distance_def d = wb_distance_default_def();
    d.compliance = 1;
    d.damping = 1e308;
    wb_distance_add(w, 0, 1, &d, NULL);
    for (int i = 0; i < 10; i++) wb_world_step(w);
    CHECK_EQ(wb_world_warnings(w), 0);
    /* the damping cancels relative velocity along the link: they move together */
    wb_real va[3], vb[3];
    wb_particle_velocity(w, 0, va);
    wb_particle_velocity(w, 1, vb);
    CHECK_NEAR(va[1], vb[1], 1e-9);
    CHECK(va[1] > -2); /* not free fall (-1.6 m/s): the upward push was shared */
    wb_world_destroy(w);
}

TEST(extreme_plastic_flow_of_a_tiny_rest_stays_finite)
{
    /* rest 1e-320 at length 1: the strain (len - rest)/rest overflows to inf, and the
     * flow's (a - y)/a was inf/inf = NaN, a NaN rest that froze the world */
    wb_world *w = new_world();
    const wb_real p[3] = { 0, 0, 0 }, q[3] = { 1, 0, 0 };
    wb_particle_add(w, p, NULL, 0, 0);
    wb_particle_add(w, q, NULL, 0, 0);
    wb_distance_def d = wb_distance_default_def();
    d.rest = 1e-320;
    d.yield = 0.1;
    d.creep = 1;
    wb_distance_id c = wb_distance_add(w, 0, 1, &d, NULL);
    for (int i = 0; i < 3; i++) wb_world_step(w);
    CHECK(isfinite(wb_distance_rest(w, c)));
    CHECK(wb_distance_rest(w, c) > 1e-320);
    CHECK(isfinite(wb_world_max_strain(w)));
    CHECK_EQ(wb_world_warnings(w), 0);
    wb_world_destroy(w);
}

TEST(extreme_collider_derived_poses_finite)
{
    wb_world *w = new_world();
    wb_status st;
    /* a capsule whose ends are both at 1e308: its centre (a + b)/2 overflowed to inf */
    wb_collider_def c = wb_collider_default_def(WB_SHAPE_CAPSULE);
    v3_set_(c.a, 1e308, 0, 0);
    v3_set_(c.b, 1e308, 1, 0);
    wb_collider_id id = wb_collider_add(w, &c, &st);
    REQUIRE(st == WB_OK);
    wb_real p[3];
    wb_collider_position(w, id, p);
    CHECK(isfinite(p[0]) && p[0] == 1e308);
    const wb_real x[3] = { 1e308, 0.5, 0 };
    CHECK_NEAR(wb_collider_distance(w, id, x), -c.radius, 1e-12);
    /* ends so far apart that |b - a|^2 overflows */
    v3_set_(c.a, -1e200, 0, 0);
    v3_set_(c.b, 1e200, 0, 0);
    CHECK_HAS(wb_collider_def_check(&c), "too far apart");
    /* a plane whose point offset/|normal| overflows */
    wb_collider_def pl = wb_collider_default_def(WB_SHAPE_PLANE);
    v3_set_(pl.normal, 0, 1e-10, 0);
    pl.offset = 1e308;
    CHECK_HAS(wb_collider_def_check(&pl), "offset");
    CHECK_EQ(wb_collider_count(w), 1);
    wb_world_destroy(w);
}

TEST(extreme_cluster_of_an_overflowing_box)
{
    /* offsets from the box's minimum overflow (1e308 - -1e308): cell indices were
     * (int64_t)floor(inf / h), undefined behaviour. Clustering is scale-free, so the
     * box is clustered as the same mesh a quarter the size (exact: a power of two) */
    const wb_real v[9] = { -1e308, 0, 0, 1e308, 0, 0, 0, 1, 0 };
    const wb_real q[9] = { -0.25e308, 0, 0, 0.25e308, 0, 0, 0, 0.25, 0 };
    wb_mesh *m = wb_mesh_create(v, 3, NULL, 0, NULL), *mq = wb_mesh_create(q, 3, NULL, 0, NULL);
    REQUIRE(m != NULL && mq != NULL);
    int32_t cl[3], clq[3];
    const int32_t n = wb_mesh_cluster(m, 2, cl);
    CHECK(n >= 1 && n <= 3);
    CHECK_EQ(n, wb_mesh_cluster(mq, 2, clq));
    for (int i = 0; i < 3; i++) CHECK_EQ(cl[i], clq[i]);
    wb_mesh_destroy(m);
    wb_mesh_destroy(mq);
}
