/* test_attach.c: the C API of attachments and grabs (attach.c, grab.c): an undone frame
 * leaves no multiplier behind, a clone keeps them (same hash, same future), the memory
 * budget is charged and given back, ids go stale on removal, release and reuse. */
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

TEST(attach_grab_forces_cleared_by_an_undone_frame)
{
    wb_world_def d = wb_world_default_def();
    wb_world *w = wb_world_create(&d);
    REQUIRE(w);
    wb_collider_def cd = wb_collider_default_def(WB_SHAPE_SPHERE);
    wb_status st;
    wb_collider_id c = wb_collider_add(w, &cd, &st);
    const wb_real x0[3] = { 0, 2, 0 }, x1[3] = { 1, 2, 0 };
    const int32_t p = wb_particle_add(w, x0, NULL, 1, 0), q = wb_particle_add(w, x1, NULL, 1, 0);
    wb_attach_id a = wb_attach_collider(w, p, c, 0, &st);
    REQUIRE(st == WB_OK);
    wb_grab_id g = wb_grab_add(w, q, x1, 0, &st);
    REQUIRE(st == WB_OK);
    REQUIRE(wb_world_step(w) == WB_OK);
    wb_real f[3];
    CHECK_NEAR(wb_attach_force(w, a, f), 9.81, 1e-9);
    CHECK_NEAR(f[1], 9.81, 1e-9); /* up: towards the point the particle is pulled to */
    CHECK_NEAR(wb_grab_force(w, g, NULL), 9.81, 1e-9);
    polls = 0;
    wb_world_set_interrupt(w, stop_after_2, NULL);
    CHECK_EQ(wb_world_step(w), WB_ERR_INTERRUPTED);
    CHECK(wb_attach_force(w, a, NULL) == 0);
    CHECK(wb_grab_force(w, g, NULL) == 0);
    wb_world_destroy(w);
}

TEST(attach_grab_clone_same_future)
{
    wb_world_def d = wb_world_default_def();
    wb_world *w = wb_world_create(&d);
    REQUIRE(w);
    wb_collider_def cd = wb_collider_default_def(WB_SHAPE_BOX);
    wb_status st;
    wb_collider_id c = wb_collider_add(w, &cd, &st);
    const wb_real om[3] = { 0, 0, 3 }, x0[3] = { 0.6, 0, 0 }, x1[3] = { 2, 0, 0 }, t[3] = { 2, 1, 0 };
    wb_collider_set_angular_velocity(w, c, om);
    const int32_t p = wb_particle_add(w, x0, NULL, 1, 0.05), q = wb_particle_add(w, x1, NULL, 1, 0);
    wb_attach_collider(w, p, c, 1e-4, &st);
    wb_grab_id g = wb_grab_add(w, q, x1, 1e-3, &st);
    for (int i = 0; i < 5; i++) wb_world_step(w);
    wb_grab_move(w, g, t);
    wb_world *v = wb_world_clone(w);
    REQUIRE(v);
    CHECK(wb_world_hash(v) == wb_world_hash(w));
    CHECK_EQ(wb_attach_count(v), 1);
    CHECK_EQ(wb_grab_count(v), 1);
    for (int i = 0; i < 10; i++) {
        wb_world_step(w);
        wb_world_step(v);
    }
    CHECK(wb_world_hash(v) == wb_world_hash(w));
    wb_world_destroy(v);
    wb_world_destroy(w);
}

TEST(attach_grab_ids_and_memory)
{
    wb_memory mem = { 0, 0 };
    wb_world_def d = wb_world_default_def();
    d.memory = &mem;
    wb_world *w = wb_world_create(&d);
    REQUIRE(w);
    wb_collider_def cd = wb_collider_default_def(WB_SHAPE_SPHERE);
    wb_status st;
    wb_collider_id c = wb_collider_add(w, &cd, &st);
    const wb_real x0[3] = { 0, 2, 0 }, bad[3] = { 0, NAN, 0 };
    const int32_t p = wb_particle_add(w, x0, NULL, 1, 0);
    const size_t before = mem.used;
    wb_attach_id a = wb_attach_collider(w, p, c, 0, &st);
    CHECK(mem.used > before); /* charged */
    /* refused: nothing changes */
    wb_attach_collider(w, p, c, -1, &st);
    CHECK_EQ(st, WB_ERR_ARG);
    wb_attach_collider(w, 7, c, 0, &st);
    CHECK_EQ(st, WB_ERR_ARG);
    wb_grab_add(w, p, bad, 0, &st);
    CHECK_EQ(st, WB_ERR_ARG);
    CHECK_EQ(wb_attach_count(w), 1);
    CHECK_EQ(wb_grab_count(w), 0);
    /* removal and slot reuse: the old id stays stale */
    wb_attach_remove(w, a);
    CHECK(!wb_attach_valid(w, a));
    wb_attach_id b = wb_attach_collider(w, p, c, 0, &st);
    CHECK(b.index == a.index && b.gen != a.gen);
    CHECK(!wb_attach_valid(w, a));
    CHECK(wb_attach_valid(w, b));
    /* the collider removed: its attachment is no longer valid, nor counted */
    wb_collider_remove(w, c);
    CHECK(!wb_attach_valid(w, b));
    CHECK_EQ(wb_attach_count(w), 0);
    CHECK(wb_world_step(w) == WB_OK);
    wb_grab_id g = wb_grab_add(w, p, x0, 0, &st);
    wb_grab_release(w, g);
    CHECK(!wb_grab_valid(w, g));
    wb_world_destroy(w);
    CHECK_EQ(mem.used, (size_t)0); /* given back */
}

/* the attack (tests/scenarios/attach_attack.lua): the particle -> collider skip table the
 * first step builds (4 bytes a particle) is charged too, and given back; wb_attach_list
 * and wb_grab_list give the live ids in slot order */
TEST(attach_skip_table_charged_and_lists)
{
    wb_memory mem = { 0, 0 };
    wb_world_def d = wb_world_default_def();
    d.memory = &mem;
    wb_world *w = wb_world_create(&d);
    REQUIRE(w);
    wb_collider_def cd = wb_collider_default_def(WB_SHAPE_SPHERE);
    wb_status st;
    wb_collider_id c = wb_collider_add(w, &cd, &st);
    const int32_t n = 20000;
    for (int32_t i = 0; i < n; i++) {
        const wb_real x[3] = { (wb_real)(i % 100), 2 + (wb_real)(i / 100), 0 };
        wb_particle_add(w, x, NULL, 1, 0);
    }
    wb_attach_id a[3];
    for (int k = 0; k < 3; k++) a[k] = wb_attach_collider(w, k, c, 0, &st);
    const wb_real t[3] = { 0, 0, 0 };
    wb_grab_id g0 = wb_grab_add(w, 5, t, 0, &st), g1 = wb_grab_add(w, 6, t, 0, &st);
    const size_t before = mem.used;
    CHECK(wb_world_step(w) == WB_OK);
    CHECK(mem.used >= before + sizeof(int32_t) * (size_t)n); /* the table is charged */
    wb_attach_remove(w, a[1]);
    wb_grab_release(w, g0);
    wb_attach_id ids[4];
    CHECK_EQ(wb_attach_list(w, ids, 4), 2);
    CHECK(ids[0].index == a[0].index && ids[0].gen == a[0].gen && ids[1].index == a[2].index);
    CHECK_EQ(wb_attach_list(w, ids, 1), 2); /* the count even when cap is smaller */
    wb_grab_id gids[2];
    CHECK_EQ(wb_grab_list(w, gids, 2), 1);
    CHECK(gids[0].index == g1.index && gids[0].gen == g1.gen);
    wb_world_destroy(w);
    CHECK_EQ(mem.used, (size_t)0); /* given back */
}

/* a rigid body's grab: NULL local = its centre; bad arguments refused; the body's removal
 * ends it (count, list, valid), and the next step retires the slot for reuse */
TEST(attach_grab_rigid_ids)
{
    wb_world_def d = wb_world_default_def();
    wb_world *w = wb_world_create(&d);
    REQUIRE(w);
    wb_status st;
    wb_rigid_def rd = wb_rigid_default_def(WB_SHAPE_BOX);
    rd.pos[1] = 1;
    rd.mass = 2;
    wb_rigid_id r = wb_rigid_add(w, &rd, &st);
    REQUIRE(st == WB_OK);
    const wb_real t[3] = { 0, 1, 0 }, bad[3] = { 0, NAN, 0 };
    wb_grab_rigid(w, r, bad, t, 0, &st);
    CHECK_EQ(st, WB_ERR_ARG);
    wb_grab_rigid(w, r, NULL, t, -1, &st);
    CHECK_EQ(st, WB_ERR_ARG);
    CHECK_EQ(wb_grab_count(w), 0);
    wb_grab_id g = wb_grab_rigid(w, r, NULL, t, 0, &st);
    REQUIRE(st == WB_OK);
    CHECK_EQ(wb_grab_particle(w, g), -1);
    wb_rigid_id b = wb_grab_body(w, g);
    CHECK(b.index == r.index && b.gen == r.gen);
    for (int i = 0; i < 10; i++) REQUIRE(wb_world_step(w) == WB_OK);
    CHECK_NEAR(wb_grab_force(w, g, NULL), 2 * 9.81, 1e-9); /* carries the weight */
    wb_real x[3];
    wb_grab_point(w, g, x);
    CHECK_NEAR(x[1], 1, 1e-12);
    wb_rigid_remove(w, r);
    CHECK(!wb_grab_valid(w, g));
    CHECK_EQ(wb_grab_count(w), 0);
    wb_grab_id ids[1];
    CHECK_EQ(wb_grab_list(w, ids, 1), 0);
    wb_grab_rigid(w, r, NULL, t, 0, &st);
    CHECK_EQ(st, WB_ERR_ARG);
    REQUIRE(wb_world_step(w) == WB_OK);
    const wb_real x0[3] = { 0, 0, 0 };
    const int32_t p = wb_particle_add(w, x0, NULL, 1, 0);
    wb_grab_id h = wb_grab_add(w, p, x0, 0, &st);
    CHECK(st == WB_OK && h.index == g.index && h.gen != g.gen); /* the retired slot, reused */
    wb_world_destroy(w);
}
