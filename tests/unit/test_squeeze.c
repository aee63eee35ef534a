/* test_squeeze.c: the end-of-frame blow-up check (solver.c) and the solve's angular
 * momentum (momentum.c). */
#include <stdlib.h>

#include "core/core.h"
#include "test.h"

/* the interrupt hook runs before every substep: from frame 90 on (past the grace after the
 * world was made) it gives particle 0 a speed the scene has nowhere to take from, as a
 * solve gone wrong would (a push of speed x h along x each substep); 0: the step goes on */
typedef struct kick {
    wb_world *w;
    wb_real speed;
} kick;

static int kick_substep(void *ud)
{
    const kick *k = ud;
    /* a displacement after the substep's prediction (which may already have run, fused
     * into the last collision pass): the velocity update turns it into the speed */
    const wb_world_def *d = &k->w->m.def;
    if (wb_world_frame(k->w) >= 90) k->w->s.x[0] += k->speed * d->dt / d->substeps;
    return 0;
}

TEST(blowup_slowed_and_reported_once)
{
    /* two particles on a link resting on the ground: the scene's speed scale is the fall
     * across it, sqrt(2 g 0.1) = 1.4 m/s; a particle at 1000 m/s is a blow-up at once
     * (past 16 x 1.4 + 20 m/s), slowed to the lower limit 8 x scale + 5 m/s, every frame it
     * happens, and reported once */
    wb_world_def d = wb_world_default_def();
    wb_world *w = wb_world_create(&d);
    REQUIRE(w);
    wb_collider_def cd = wb_collider_default_def(WB_SHAPE_PLANE);
    wb_status st;
    wb_collider_add(w, &cd, &st);
    const wb_real a[3] = { 0, 0.1, 0 }, b[3] = { 0, 0.2, 0 };
    const int32_t p = wb_particle_add(w, a, NULL, 1, 0.1), q = wb_particle_add(w, b, NULL, 1, 0.1);
    wb_distance_def dd = wb_distance_default_def();
    wb_distance_add(w, p, q, &dd, &st);
    kick k = { w, 1000 };
    wb_world_set_interrupt(w, kick_substep, &k);
    for (int f = 0; f < 90; f++) wb_world_step(w);
    CHECK_EQ(wb_world_warnings(w), 0);
    for (int f = 0; f < 30; f++) {
        wb_world_step(w);
        wb_real v[3];
        wb_particle_velocity(w, p, v);
        const double s = sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
        /* 8 x the scale (at most the fall across a scene of a few m: ~10 m/s) + 5 m/s */
        CHECK(s < 100);
        CHECK(isfinite(s));
    }
    CHECK_EQ(wb_world_warnings(w), 1);
    CHECK(strstr(wb_world_last_warning(w), "m/s") != NULL);
    wb_world_destroy(w);
}

TEST(blowup_not_a_long_fall_nor_a_thrown_particle)
{
    /* a lone particle falls for 10 s (98 m/s, nothing in the scene but gravity) and another
     * is thrown at 300 m/s by hand: neither is a blow-up */
    wb_world_def d = wb_world_default_def();
    wb_world *w = wb_world_create(&d);
    REQUIRE(w);
    const wb_real x[3] = { 0, 0, 0 }, y[3] = { 5, 0, 0 }, v[3] = { 300, 0, 0 };
    wb_particle_add(w, x, NULL, 1, 0.1);
    for (int f = 0; f < 300; f++) wb_world_step(w);
    wb_particle_add(w, y, v, 1, 0.1);
    for (int f = 0; f < 300; f++) wb_world_step(w);
    wb_real u[3];
    wb_particle_velocity(w, 0, u);
    CHECK_NEAR(u[1], -9.81 * 10, 1e-6);
    wb_particle_velocity(w, 1, u);
    CHECK_NEAR(u[0], 300, 1e-9);
    CHECK_EQ(wb_world_warnings(w), 0);
    wb_world_destroy(w);
}

/* one projection of a link made at twice its length (rest 2 m, 1 m apart, equal masses,
 * no gravity, one substep) whose ends are corners of volume constraints: its full
 * correction would double it; the lengthening is bent (distance.c, STRETCH_FREE = 1/8) to
 * 1/8 (2 - 1/8) = 15/64 of its length: 1.234375 m, exactly in binary. Each end's volume
 * has its other three corners in the plane y = 1, so moving the end along x keeps it (no
 * volume correction). A link shortened by 1/11 of its rest (a lengthening of 0.1 < 1/8)
 * is corrected in full, as before; so is the link of 2 m between ends on no volume (a
 * truss's links keep their full push: nothing else stops it folding). (One link runs the
 * scalar loop; test_distance_simd.c holds the vector path to its bits.) */
TEST(distance_compressed_link_regains_a_bounded_share)
{
    const wb_real rests[3] = { 2, 1.1, 2 }, want[3] = { 1.234375, 1.1, 2 };
    for (int c = 0; c < 3; c++) {
        wb_world_def d = wb_world_default_def();
        d.gravity[1] = 0;
        d.substeps = 1;
        wb_world *w = wb_world_create(&d);
        REQUIRE(w);
        const wb_real a[3] = { 0, 0, 0 }, b[3] = { 1, 0, 0 };
        const int32_t p = wb_particle_add(w, a, NULL, 1, 0.01), q = wb_particle_add(w, b, NULL, 1, 0.01);
        if (c < 2)
            for (int e = 0; e < 2; e++) {
                /* three corners far from each other and from the link (no contact) */
                const wb_real o = 10 * e - 5;
                const wb_real c1[3] = { o, 1, -3 }, c2[3] = { o, 1, 3 }, c3[3] = { o + 3, 1, 0 };
                const int32_t t[4] = { e ? q : p, wb_particle_add(w, c1, NULL, 1, 0.01), wb_particle_add(w, c2, NULL, 1, 0.01),
                                       wb_particle_add(w, c3, NULL, 1, 0.01) };
                const wb_volume_def vd = wb_volume_default_def();
                REQUIRE(wb_volume_add(w, t, &vd) >= 0);
            }
        wb_distance_def dd = wb_distance_default_def();
        dd.rest = rests[c];
        wb_status st;
        wb_distance_add(w, p, q, &dd, &st);
        REQUIRE(st == WB_OK);
        CHECK_EQ(wb_world_step(w), WB_OK);
        wb_real xp[3], xq[3];
        wb_particle_position(w, p, xp);
        wb_particle_position(w, q, xq);
        CHECK_NEAR(xq[0] - xp[0], want[c], 1e-12);
        CHECK_NEAR(xp[0] + xq[0], 1, 1e-12); /* equal and opposite */
        CHECK_NEAR(xp[1], 0, 1e-12);
        wb_world_destroy(w);
    }
}
