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
