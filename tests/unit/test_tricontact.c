/* test_tricontact.c: particle-triangle contacts (src/core/tricontact.c; white-box: core.h).
 *
 * The closest point as barycentrics against hand-computed cases in every Voronoi region
 * (face, three corners, three edges, a degenerate triangle) and against bvh.c's closest
 * point on random input; one step of a point driven into a triangle of unequal masses:
 * left at its radius, on the side it came from, with the momentum of the four particles
 * unchanged to round-off (with friction too); and the rules of who may touch. */
#include <stdlib.h>

#include "core/core.h"
#include "core/broadphase.h"
#include "core/tricontact.h"
#include "core/bvh.h"
#include "test.h"

static void check_closest(const wb_real p[3], const wb_real a[3], const wb_real b[3], const wb_real c[3],
                          wb_real u, wb_real v, wb_real t, wb_real d2_want)
{
    wb_real bary[3], out[3];
    const wb_real d2 = wb__tri_closest(p, a, b, c, bary, out);
    CHECK_NEAR(d2, d2_want, 1e-14);
    CHECK_NEAR(bary[0], u, 1e-14);
    CHECK_NEAR(bary[1], v, 1e-14);
    CHECK_NEAR(bary[2], t, 1e-14);
    CHECK_NEAR(bary[0] + bary[1] + bary[2], 1, 1e-15);
    for (int k = 0; k < 3; k++) CHECK_NEAR(out[k], u * a[k] + v * b[k] + t * c[k], 1e-14);
}

TEST(tricontact_closest_point_regions)
{
    const wb_real a[3] = { 0, 0, 0 }, b[3] = { 1, 0, 0 }, c[3] = { 0, 1, 0 };
    /* face: straight above (0.2, 0.3), 0.5 off the plane */
    check_closest((wb_real[3]){ 0.2, 0.3, 0.5 }, a, b, c, 0.5, 0.2, 0.3, 0.25);
    /* the corners */
    check_closest((wb_real[3]){ -1, -1, 0.5 }, a, b, c, 1, 0, 0, 2.25);
    check_closest((wb_real[3]){ 2, -0.5, 0 }, a, b, c, 0, 1, 0, 1.25);
    check_closest((wb_real[3]){ -0.5, 2, 1 }, a, b, c, 0, 0, 1, 2.25);
    /* the edges: ab at x = 0.25, bc at its middle, ca at y = 0.4 */
    check_closest((wb_real[3]){ 0.25, -1, 0 }, a, b, c, 0.75, 0.25, 0, 1);
    check_closest((wb_real[3]){ 1, 1, 0 }, a, b, c, 0, 0.5, 0.5, 0.5);
    check_closest((wb_real[3]){ -2, 0.4, 0 }, a, b, c, 0.6, 0, 0.4, 4);
    /* collinear corners (0, 0, 0), (1, 0, 0), (2, 0, 0): the nearest point (1.5, 0, 0) on
     * them, weights that give it (not unique: a degenerate triangle) */
    const wb_real p[3] = { 1.5, 1, 0 }, e[3] = { 2, 0, 0 };
    wb_real bary[3], out[3];
    CHECK_NEAR(wb__tri_closest(p, a, b, e, bary, out), 1, 1e-14);
    CHECK_NEAR(out[0], 1.5, 1e-14);
    CHECK_NEAR(out[1], 0, 1e-14);
    CHECK_NEAR(bary[0] + bary[1] + bary[2], 1, 1e-15);
    CHECK_NEAR(bary[1] * b[0] + bary[2] * e[0], 1.5, 1e-14);
    CHECK(bary[0] >= 0 && bary[1] >= 0 && bary[2] >= 0);
}

/* the same distance and point as bvh.c's region method, anywhere around a skewed triangle */
TEST(tricontact_closest_matches_bvh)
{
    uint64_t s = 12345;
    int bad = 0;
    for (int i = 0; i < 2000; i++) {
        wb_real q[12];
        for (int k = 0; k < 12; k++) {
            s = s * 6364136223846793005ull + 1442695040888963407ull;
            q[k] = (wb_real)(s >> 11) / 9007199254740992.0 * 4 - 2;
        }
        wb_real bary[3], o1[3], o2[3];
        int region;
        const wb_real d1 = wb__tri_closest(q, q + 3, q + 6, q + 9, bary, o1);
        const wb_real d2 = wb__closest_on_triangle(q, q + 3, q + 6, q + 9, o2, &region);
        wb_real e[3];
        v3_sub(e, o1, o2);
        if (fabs(d1 - d2) > 1e-12 || v3_len(e) > 1e-12 || fabs(bary[0] + bary[1] + bary[2] - 1) > 1e-14 ||
            bary[0] < 0 || bary[1] < 0 || bary[2] < 0)
            bad++;
    }
    CHECK_EQ(bad, 0);
}

/* a triangle of three unequal masses in z = 0 and a point 0.01 above it moving down at
 * 3 m/s, radius 0.05, no gravity: one step of one substep. The point is made inside its
 * contact distance, overlap that would go out at max_depenetration (0.25 m/s, 4 mm in
 * this substep); lifted here, so that the whole overlap is one projection's */
static wb_world *scene(wb_real mu, int32_t *pt)
{
    wb_world_def d = wb_world_default_def();
    d.gravity[1] = 0;
    d.substeps = 1;
    d.max_depenetration = 1e3;
    wb_world *w = wb_world_create(&d);
    const wb_real x[4][3] = { { 0, 0, 0 }, { 1, 0, 0 }, { 0, 1, 0 }, { 0.2, 0.3, 0.01 } };
    const wb_real v[4][3] = { { 0, 0, 0.5 }, { 0.1, 0, 0 }, { 0, 0, 0 }, { 0.4, -0.2, -3 } };
    const wb_real mass[4] = { 1, 2.5, 0.7, 1.3 };
    for (int i = 0; i < 4; i++) {
        wb_particle_add(w, x[i], v[i], mass[i], i == 3 ? 0.05 : 0);
        wb_particle_set_friction(w, i, mu);
    }
    const int32_t tri[3] = { 0, 1, 2 };
    wb_surface_add(w, tri, 1);
    *pt = 3;
    return w;
}

static void momentum(const wb_world *w, wb_real p[3])
{
    v3_set(p, 0, 0, 0);
    for (int32_t i = 0; i < wb_particle_count(w); i++) {
        wb_real v[3];
        wb_particle_velocity(w, i, v);
        v3_madd(p, v, wb_particle_mass(w, i));
    }
}

TEST(tricontact_projection_conserves_momentum)
{
    for (int f = 0; f < 2; f++) {
        int32_t p;
        wb_world *w = scene(f ? 0.6 : 0, &p);
        wb_real p0[3], p1[3];
        momentum(w, p0);
        REQUIRE(wb_world_step(w) == WB_OK);
        momentum(w, p1);
        /* v = (x - x_prev) / h: an ulp of x (2.2e-16) over h = 1/60 is 1.3e-14 per
         * particle, so 1e-13 is round-off; a correction off by a weight is ~1e-2 */
        for (int k = 0; k < 3; k++) CHECK_NEAR(p1[k], p0[k], 1e-13);
        /* it touched: one contact, the point left at its radius from the triangle's
         * point q = sum b_i x_i along the contact normal (the linearised constraint is
         * met exactly; the triangle's own tilt is the next substep's) */
        CHECK_EQ(wb_world_tri_contact_count(w), 1);
        const wb_tri_contact c = wb_world_tri_contact_at(w, 0);
        CHECK_EQ(c.p, 3);
        CHECK(c.normal[2] < -0.99);
        CHECK(c.depth > 0.04 && c.force > 0);
        const wb_real *x = wb_particle_positions(w);
        wb_real d[3];
        v3_copy(d, &x[9]);
        for (int i = 0; i < 3; i++) v3_madd(d, &x[3 * i], -c.bary[i]);
        CHECK_NEAR(-v3_dot(d, c.normal), 0.05, 1e-12);
        /* the velocity pass: no approach speed left along the normal */
        wb_real u[3], v[3];
        wb_particle_velocity(w, p, u);
        for (int i = 0; i < 3; i++) {
            wb_particle_velocity(w, i, v);
            v3_madd(u, v, -c.bary[i]);
        }
        CHECK(v3_dot(u, c.normal) <= 1e-12);
        wb_world_destroy(w);
    }
}

/* a point of the triangle's own body: only with self-collision, never its own corner,
 * never one within its radius of the triangle where created; an immovable triangle still
 * stops a movable point; contacts = false: nothing */
TEST(tricontact_who_may_touch)
{
    int32_t p;
    wb_world *w = scene(0, &p);
    REQUIRE(wb_world_step(w) == WB_OK);
    CHECK_EQ(w->k.tc->n, 1); /* loose particles: the point and the triangle */
    wb_world_destroy(w);

    /* one body, no self-collision: nothing; with it: the point (0.01 from the triangle
     * where created, radius 0.05) is a rest neighbour: still nothing */
    w = scene(0, &p);
    wb_body b = { 0, 4, 1 };
    wb_body_set_contacts(w, b, true, false, 0);
    REQUIRE(wb_world_step(w) == WB_OK);
    CHECK_EQ(w->k.tc->n, 0);
    wb_group_set_self_collide(w, 1, true);
    REQUIRE(wb_world_step(w) == WB_OK);
    CHECK_EQ(w->k.tc->n, 0);
    wb_world_destroy(w);
    /* ... created 0.2 away it may touch */
    w = scene(0, &p);
    w->m.x0[3 * p + 2] = 0.2;
    wb_body_set_contacts(w, b, true, true, 0);
    REQUIRE(wb_world_step(w) == WB_OK);
    CHECK_EQ(w->k.tc->n, 1);
    wb_world_destroy(w);

    /* an immovable triangle stops the point */
    w = scene(0, &p);
    for (int32_t i = 0; i < 3; i++) wb_particle_pin(w, i, NULL);
    REQUIRE(wb_world_step(w) == WB_OK);
    CHECK_EQ(w->k.tc->n, 1);
    CHECK_NEAR(wb_particle_positions(w)[3 * p + 2], 0.05, 1e-12);
    wb_world_destroy(w);

    wb_world_def d = wb_world_default_def();
    d.contacts = false;
    w = scene(0, &p);
    wb_world_set_def(w, &d);
    wb_world_def d2 = wb_world_get_def(w);
    CHECK(!d2.contacts);
    REQUIRE(wb_world_step(w) == WB_OK);
    CHECK_EQ(w->k.tc->n, 0);
    wb_world_destroy(w);
}
