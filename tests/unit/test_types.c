/* test_types.c: what the step does for every constraint type alike (the table in
 * ctype.h): an abandoned frame (interrupt, or gone non-finite) leaves no multiplier of
 * any type behind, and stats count every type. */
#include <math.h>
#include <string.h>

#include "test.h"
#include "wobble.h"

static int polls;
static int stop_after_2(void *ud)
{
    (void)ud;
    return ++polls > 2;
}

/* a tet and a hinge, each with one free particle hanging on pinned ones: both carry a
 * multiplier after any step */
static wb_world *loaded_world(int32_t *free_tet, wb_bend_id *bend)
{
    wb_world_def d = wb_world_default_def();
    d.substeps = 8;
    wb_world *w = wb_world_create(&d);
    if (!w) return NULL;
    const wb_real t[4][3] = { { 0, 0, 0 }, { 1, 0, 0 }, { 0, 0, 1 }, { 0, 1, 0 } };
    int32_t p[4];
    for (int i = 0; i < 4; i++) p[i] = wb_particle_add(w, t[i], NULL, i == 3 ? 1 : 0, 0);
    wb_volume_def vd = wb_volume_default_def();
    if (wb_volume_add(w, p, &vd) != 0) return NULL;
    *free_tet = p[3];
    /* hinge along z at x = 5; one wing pinned, the other sticking out sideways */
    const wb_real b[4][3] = { { 5, 0, 0 }, { 5, 0, 1 }, { 4, 1, 0.5 }, { 6, 0, 0.5 } };
    int32_t q[4];
    for (int i = 0; i < 4; i++) q[i] = wb_particle_add(w, b[i], NULL, i == 3 ? 1 : 0, 0);
    wb_bend_def bd = wb_bend_default_def();
    wb_status st = WB_OK;
    *bend = wb_bend_add(w, q, &bd, &st);
    return st == WB_OK ? w : NULL;
}

TEST(types_multipliers_cleared_by_an_undone_frame)
{
    int32_t tip = 0;
    wb_bend_id bend;
    wb_world *w = loaded_world(&tip, &bend);
    REQUIRE(w);
    REQUIRE(wb_world_step(w) == WB_OK);
    CHECK(wb_volume_pressure(w, 0) != 0);
    CHECK(wb_bend_force(w, bend) > 0);
    /* interrupted after two substeps: the frame is abandoned, its multipliers with it */
    polls = 0;
    wb_world_set_interrupt(w, stop_after_2, NULL);
    CHECK_EQ(wb_world_step(w), WB_ERR_INTERRUPTED);
    CHECK(wb_volume_pressure(w, 0) == 0);
    CHECK(wb_bend_force(w, bend) == 0);
    wb_world_set_interrupt(w, NULL, NULL);
    REQUIRE(wb_world_step(w) == WB_OK);
    CHECK(wb_volume_pressure(w, 0) != 0);
    /* a frame gone non-finite (a link flung at 1e300 m/s) is undone: no NaN multiplier
     * reads through */
    const wb_real a[3] = { 9, 2, 0 }, b[3] = { 9, 1, 0 }, huge[3] = { 1e300, -1e300, 0 };
    const int32_t pa = wb_particle_add(w, a, NULL, 0, 0), pb = wb_particle_add(w, b, NULL, 1, 0);
    wb_distance_def dd = wb_distance_default_def();
    wb_distance_add(w, pa, pb, &dd, NULL);
    REQUIRE(wb_world_step(w) == WB_OK);
    CHECK(wb_bend_force(w, bend) > 0);
    wb_particle_set_velocity(w, pb, huge);
    wb_world_step(w);
    CHECK_EQ(wb_world_warnings(w), 1);
    CHECK(wb_volume_pressure(w, 0) == 0);
    CHECK(wb_bend_force(w, bend) == 0);
    wb_world_destroy(w);
}

TEST(types_counted_in_stats)
{
    int32_t tip = 0;
    wb_bend_id bend;
    wb_world *w = loaded_world(&tip, &bend);
    REQUIRE(w);
    wb_stats s = wb_world_stats(w);
    CHECK_EQ(s.bends, 1);
    CHECK_EQ(s.volumes, 1);
    CHECK_EQ(s.shape_matches, 0);
    CHECK_EQ(s.pressures, 0);
    REQUIRE(wb_world_step(w) == WB_OK);
    /* one bend and one volume, once per substep (8), one iteration, no distances */
    CHECK_EQ(wb_world_stats(w).projections, 16);
    wb_world_destroy(w);
}
