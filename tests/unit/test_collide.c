/* test_collide.c: collider signed distances at hand-computed points, kinematic
 * sweeps that push instead of tunnelling, resting contact. */
#include "test.h"
#include "wobble.h"

static wb_world *new_world(wb_real gy)
{
    wb_world_def d = wb_world_default_def();
    d.gravity[1] = gy;
    return wb_world_create(&d);
}

static wb_real dist_at(wb_world *w, wb_collider_id c, wb_real x, wb_real y, wb_real z)
{
    const wb_real p[3] = { x, y, z };
    return wb_collider_distance(w, c, p);
}

TEST(collider_distance_plane)
{
    wb_world *w = new_world(-9.81);
    REQUIRE(w);
    /* n.x = offset with a non-unit normal: 2y = 2 is the plane y = 1 */
    wb_collider_def d = wb_collider_default_def(WB_SHAPE_PLANE);
    d.normal[0] = 0; d.normal[1] = 2; d.normal[2] = 0;
    d.offset = 2;
    wb_status st;
    wb_collider_id c = wb_collider_add(w, &d, &st);
    REQUIRE(st == WB_OK);
    CHECK_NEAR(dist_at(w, c, 3, 4, -1), 3, 1e-15);
    CHECK_NEAR(dist_at(w, c, 0, 0, 0), -1, 1e-15);
    CHECK_NEAR(dist_at(w, c, 7, 1, 9), 0, 1e-15);
    /* a tilted plane through the origin: normal (1,1,0)/sqrt2 */
    d.normal[0] = 1; d.normal[1] = 1; d.offset = 0;
    wb_collider_id t = wb_collider_add(w, &d, &st);
    CHECK_NEAR(dist_at(w, t, 1, 1, 5), sqrt(2.0), 1e-15);
    CHECK_NEAR(dist_at(w, t, 1, -1, 0), 0, 1e-15);
    CHECK_NEAR(dist_at(w, t, -2, 0, 0), -sqrt(2.0), 1e-15);
    /* offset with a tilted normal: n.x = 2 with n = (3,4,0): distance (3x+4y-2)/5 */
    d.normal[0] = 3; d.normal[1] = 4; d.offset = 2;
    wb_collider_id u = wb_collider_add(w, &d, &st);
    CHECK_NEAR(dist_at(w, u, 1, 1, 0), (3 + 4 - 2) / 5.0, 1e-15);
    /* the def read back describes the same plane */
    wb_collider_def g;
    wb_collider_get_def(w, u, &g);
    CHECK_NEAR(g.normal[0], 0.6, 1e-15);
    CHECK_NEAR(g.normal[1], 0.8, 1e-15);
    CHECK_NEAR(g.offset, 0.4, 1e-15);
    wb_world_destroy(w);
}

TEST(collider_distance_sphere)
{
    wb_world *w = new_world(-9.81);
    REQUIRE(w);
    wb_collider_def d = wb_collider_default_def(WB_SHAPE_SPHERE);
    d.center[0] = 1; d.center[1] = 2; d.center[2] = 3;
    d.radius = 0.5;
    wb_status st;
    wb_collider_id c = wb_collider_add(w, &d, &st);
    REQUIRE(st == WB_OK);
    CHECK_NEAR(dist_at(w, c, 1, 2, 5), 1.5, 1e-15);
    CHECK_NEAR(dist_at(w, c, 1, 2, 3), -0.5, 1e-15);
    CHECK_NEAR(dist_at(w, c, 1 + 3, 2 + 4, 3), 4.5, 1e-15); /* |(3,4,0)| = 5 */
    CHECK_NEAR(dist_at(w, c, 1.25, 2, 3), -0.25, 1e-15);
    /* moved: the distance follows the position set */
    const wb_real np[3] = { 0, 0, 0 };
    wb_collider_set_position(w, c, np);
    CHECK_NEAR(dist_at(w, c, 0, 0, 2), 1.5, 1e-15);
    wb_real pos[3];
    wb_collider_position(w, c, pos);
    CHECK_NEAR(pos[0], 0, 0);
    wb_world_destroy(w);
}

TEST(collider_distance_box_rotated)
{
    wb_world *w = new_world(-9.81);
    REQUIRE(w);
    /* half extents (1, 0.5, 0.25) at (1,0,0), rotated 90 degrees about z (given
     * unnormalised, twice the unit quaternion): local x maps to world y, local y to
     * world -x. World extent: x in [0.5, 1.5], y in [-1, 1], z in [-0.25, 0.25]. */
    wb_collider_def d = wb_collider_default_def(WB_SHAPE_BOX);
    d.center[0] = 1; d.center[1] = 0; d.center[2] = 0;
    d.half[0] = 1; d.half[1] = 0.5; d.half[2] = 0.25;
    d.rotation[0] = 2 * cos(M_PI / 4); d.rotation[1] = 0; d.rotation[2] = 0; d.rotation[3] = 2 * sin(M_PI / 4);
    wb_status st;
    wb_collider_id c = wb_collider_add(w, &d, &st);
    REQUIRE(st == WB_OK);
    wb_real q[4];
    wb_collider_rotation(w, c, q);
    CHECK_NEAR(q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3], 1, 1e-15);
    const double e = 1e-14;
    CHECK_NEAR(dist_at(w, c, 1, 3, 0), 2, e);          /* above the top face (local +x) */
    CHECK_NEAR(dist_at(w, c, 3, 0, 0), 1.5, e);        /* right of the face at x = 1.5 */
    CHECK_NEAR(dist_at(w, c, 1, 0, -1), 0.75, e);      /* below the z = -0.25 face */
    CHECK_NEAR(dist_at(w, c, 2.5, 2, 1.25), sqrt(3.0), e); /* off the corner (1.5,1,0.25) by (1,1,1) */
    CHECK_NEAR(dist_at(w, c, 2.5, 1, 0), 1, e);        /* off the edge x = 1.5, y = 1: (1,0,0) */
    CHECK_NEAR(dist_at(w, c, 1, 0, 0), -0.25, e);      /* centre: nearest face is z = +-0.25 */
    CHECK_NEAR(dist_at(w, c, 1, 0.9, 0), -0.1, e);     /* inside, 0.1 below the top face */
    CHECK_NEAR(dist_at(w, c, 0.6, 0, 0.1), -0.1, e);   /* inside, 0.1 from x = 0.5 */
    /* read back: center and rotation as given (normalised) */
    wb_collider_def g;
    wb_collider_get_def(w, c, &g);
    CHECK_NEAR(g.center[0], 1, 0);
    CHECK_NEAR(g.half[0], 1, 0);
    CHECK_NEAR(g.rotation[3], sin(M_PI / 4), 1e-15);
    /* set_rotation: back to identity, extents along the world axes again */
    const wb_real id[4] = { 3, 0, 0, 0 };
    wb_collider_set_rotation(w, c, id);
    CHECK_NEAR(dist_at(w, c, 3, 0, 0), 1, e);
    CHECK_NEAR(dist_at(w, c, 1, 3, 0), 2.5, e);
    wb_world_destroy(w);
}

TEST(collider_distance_capsule)
{
    wb_world *w = new_world(-9.81);
    REQUIRE(w);
    wb_collider_def d = wb_collider_default_def(WB_SHAPE_CAPSULE);
    d.a[0] = 0; d.a[1] = 0; d.a[2] = 0;
    d.b[0] = 0; d.b[1] = 2; d.b[2] = 0;
    d.radius = 0.5;
    wb_status st;
    wb_collider_id c = wb_collider_add(w, &d, &st);
    REQUIRE(st == WB_OK);
    const double e = 1e-15;
    CHECK_NEAR(dist_at(w, c, 1, 1, 0), 0.5, e);          /* beside the segment */
    CHECK_NEAR(dist_at(w, c, 0, 3, 0), 0.5, e);          /* above the cap at b */
    CHECK_NEAR(dist_at(w, c, 0, -1, 0), 0.5, e);         /* below the cap at a */
    CHECK_NEAR(dist_at(w, c, 0, 1, 0), -0.5, e);         /* on the axis */
    CHECK_NEAR(dist_at(w, c, 0.3, 1.7, -0.4), 0.0, e);   /* |(0.3, 0, -0.4)| = 0.5 */
    CHECK_NEAR(dist_at(w, c, 3, 5, 4), sqrt(34.0) - 0.5, 1e-14); /* nearest end b */
    wb_collider_def g;
    wb_collider_get_def(w, c, &g);
    CHECK_NEAR(g.a[1], 0, 1e-15);
    CHECK_NEAR(g.b[1], 2, 1e-15);
    wb_world_destroy(w);
}

/* a box swept fast through a layer of particles pushes the whole layer ahead of
 * it: the sweep is split over the substeps, each moving the box by less than its
 * thickness */
static void sweep_case(int by_velocity)
{
    wb_world *w = new_world(0);
    REQUIRE(w);
    const wb_real r = 0.01;
    for (int j = -2; j <= 2; j++)
        for (int k = -2; k <= 2; k++) {
            const wb_real p[3] = { 0, 0.2 * j, 0.2 * k };
            wb_particle_add(w, p, NULL, 1, r);
        }
    /* thickness 1 along x, wide in y and z so the x faces are nearest */
    wb_collider_def d = wb_collider_default_def(WB_SHAPE_BOX);
    d.center[0] = -1;
    d.half[0] = 0.5; d.half[1] = 5; d.half[2] = 5;
    wb_status st;
    wb_collider_id c = wb_collider_add(w, &d, &st);
    REQUIRE(st == WB_OK);
    /* 4 m in one frame (240 m/s): 0.4 m per substep. Starting with the box's front
     * face at -0.5, the layer at x = 0 would be skipped entirely by a collider that
     * only jumped to its end pose (front face at 3.5, back face at 2.5). */
    if (by_velocity) {
        const wb_real v[3] = { 240, 0, 0 };
        wb_collider_set_velocity(w, c, v);
    } else {
        const wb_real to[3] = { 3, 0, 0 };
        wb_collider_set_position(w, c, to);
    }
    wb_world_step(w);
    wb_real cp[3];
    wb_collider_position(w, c, cp);
    CHECK_NEAR(cp[0], 3, 1e-12);
    int behind = 0;
    for (int32_t i = 0; i < wb_particle_count(w); i++) {
        wb_real x[3];
        wb_particle_position(w, i, x);
        /* in front of the face at x = 3.5, at least one radius away (round-off apart) */
        if (!(x[0] >= 3.5 + r - 1e-12)) behind++;
        CHECK(wb_collider_distance(w, c, x) >= r - 1e-12);
        /* pushed straight along x */
        CHECK_NEAR(x[1], 0.2 * ((i / 5) - 2), 1e-12);
        CHECK_NEAR(x[2], 0.2 * ((i % 5) - 2), 1e-12);
    }
    CHECK_EQ(behind, 0);
    wb_world_destroy(w);
}

TEST(collider_sweep_pushes_not_tunnels) { sweep_case(0); }
TEST(collider_sweep_by_velocity_pushes) { sweep_case(1); }

TEST(collider_resting_contact_no_bounce)
{
    /* a particle resting on a plane with restitution 1 stays at rest: approach speeds
     * below 2|g|h (here g h per substep, from gravity alone) do not bounce */
    wb_world *w = new_world(-9.81);
    REQUIRE(w);
    wb_collider_def d = wb_collider_default_def(WB_SHAPE_PLANE);
    d.restitution = 1;
    wb_status st;
    wb_collider_add(w, &d, &st);
    REQUIRE(st == WB_OK);
    const wb_real r = 0.05, p[3] = { 0, r, 0 };
    const int32_t i = wb_particle_add(w, p, NULL, 1, r);
    wb_real ymax = r, ymin = r;
    for (int f = 0; f < 120; f++) {
        wb_world_step(w);
        wb_real x[3];
        wb_particle_position(w, i, x);
        if (x[1] > ymax) ymax = x[1];
        if (x[1] < ymin) ymin = x[1];
    }
    CHECK_NEAR(ymax, r, 1e-12);
    CHECK_NEAR(ymin, r, 1e-12);
    wb_real v[3];
    wb_particle_velocity(w, i, v);
    CHECK_NEAR(v[1], 0, 1e-9);
    CHECK_EQ(wb_world_stats(w).contacts, 1);
    wb_world_destroy(w);
}
