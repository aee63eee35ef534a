/* test_robust.c: the step under abuse: interrupted frames, absurd collider inputs,
 * force readback across setting changes, and what the hash covers. */
#include <math.h>
#include <string.h>

#include "test.h"
#include "wobble.h"

static int calls;
static int stop_after_3(void *ud)
{
    (void)ud;
    return ++calls > 3;
}

TEST(step_interrupt_leaves_world_unchanged)
{
    /* an interrupt polled once per substep abandons the frame: positions, velocities,
     * collider poses, time and frame are those from before the step */
    wb_world_def d = wb_world_default_def();
    d.substeps = 10;
    wb_world *w = wb_world_create(&d);
    REQUIRE(w);
    wb_rope_def r = wb_rope_default_def();
    wb_body b;
    REQUIRE(wb_rope(w, &r, &b) == WB_OK);
    wb_collider_def cd = wb_collider_default_def(WB_SHAPE_BOX);
    wb_collider_id c = wb_collider_add(w, &cd, NULL);
    const wb_real v[3] = { 0, 0, 3 };
    wb_collider_set_velocity(w, c, v);
    CHECK_EQ(wb_world_step(w), WB_OK);
    const uint64_t h = wb_world_hash(w);
    calls = 0;
    wb_world_set_interrupt(w, stop_after_3, NULL);
    CHECK_EQ(wb_world_step(w), WB_ERR_INTERRUPTED);
    CHECK_EQ(calls, 4); /* three substeps ran, the fourth poll stopped it */
    CHECK(wb_world_hash(w) == h);
    CHECK_EQ(wb_world_frame(w), 1);
    /* without the interrupt the same frame runs as if nothing had happened */
    wb_world_set_interrupt(w, NULL, NULL);
    CHECK_EQ(wb_world_step(w), WB_OK);
    CHECK_EQ(wb_world_frame(w), 2);
    wb_world_destroy(w);
}

TEST(force_reads_the_step_that_made_it)
{
    /* force() = |lambda| / h^2 with the h of the step that produced lambda: changing
     * dt or substeps afterwards must not rescale it */
    wb_world_def d = wb_world_default_def();
    wb_world *w = wb_world_create(&d);
    REQUIRE(w);
    const wb_real top[3] = { 0, 2, 0 }, bot[3] = { 0, 1, 0 };
    const int32_t a = wb_particle_add(w, top, NULL, 0, 0), b = wb_particle_add(w, bot, NULL, 1, 0);
    wb_distance_def dd = wb_distance_default_def();
    wb_distance_id c = wb_distance_add(w, a, b, &dd, NULL);
    wb_world_step(w);
    const wb_real f = wb_distance_force(w, c);
    CHECK_NEAR(f, 9.81, 1e-9); /* rigid link, at rest: each substep's lambda is m g h^2 */
    wb_world_def d2 = d;
    d2.substeps = 100;
    d2.dt = 1.0 / 30;
    REQUIRE(wb_world_set_def(w, &d2) == WB_OK);
    CHECK(wb_distance_force(w, c) == f);
    wb_world_destroy(w);
}

TEST(force_zero_after_an_undone_frame)
{
    /* a frame that went non-finite is undone; its multipliers (NaN) must not leak */
    wb_world_def d = wb_world_default_def();
    wb_world *w = wb_world_create(&d);
    REQUIRE(w);
    const wb_real top[3] = { 0, 2, 0 }, bot[3] = { 0, 1, 0 };
    const int32_t a = wb_particle_add(w, top, NULL, 0, 0), b = wb_particle_add(w, bot, NULL, 1, 0);
    wb_distance_def dd = wb_distance_default_def();
    wb_distance_id c = wb_distance_add(w, a, b, &dd, NULL);
    const wb_real huge[3] = { 1e300, -1e300, 0 };
    wb_particle_set_velocity(w, b, huge);
    wb_world_step(w);
    CHECK_EQ(wb_world_warnings(w), 1);
    CHECK(wb_distance_force(w, c) == 0);
    wb_world_destroy(w);
}

TEST(collider_huge_inputs_normalised)
{
    /* normals and rotations of 1e300 would overflow to inf when squared; they must be
     * normalised as their direction says */
    wb_world_def d = wb_world_default_def();
    wb_world *w = wb_world_create(&d);
    REQUIRE(w);
    wb_collider_def pd = wb_collider_default_def(WB_SHAPE_PLANE);
    pd.normal[0] = 0; pd.normal[1] = 1e300; pd.normal[2] = 0;
    wb_collider_id plane = wb_collider_add(w, &pd, NULL);
    REQUIRE(wb_collider_valid(w, plane));
    const wb_real above[3] = { 0, 5, 0 };
    CHECK_NEAR(wb_collider_distance(w, plane, above), 5, 1e-12);
    wb_collider_def bd = wb_collider_default_def(WB_SHAPE_BOX);
    bd.rotation[0] = 1e200; bd.rotation[1] = 0; bd.rotation[2] = 1e200; bd.rotation[3] = 0; /* 90 deg about y */
    bd.half[0] = 1; bd.half[1] = 0.5; bd.half[2] = 0.25;
    wb_collider_id box = wb_collider_add(w, &bd, NULL);
    wb_real q[4];
    wb_collider_rotation(w, box, q);
    CHECK_NEAR(q[0], sqrt(0.5), 1e-15);
    CHECK_NEAR(q[2], sqrt(0.5), 1e-15);
    /* rotated: the long half-axis (x) now lies along z */
    const wb_real on_z[3] = { 0, 0, 2 };
    CHECK_NEAR(wb_collider_distance(w, box, on_z), 1, 1e-12);
    wb_world_destroy(w);
}

TEST(collider_absurd_velocity_recovers)
{
    /* a collider driven to a non-finite pose is put back, stopped and reported
     * (1e308 m/s over dt = 10 s is past the largest double) */
    wb_world_def d = wb_world_default_def();
    d.dt = 10;
    wb_world *w = wb_world_create(&d);
    REQUIRE(w);
    wb_collider_def sd = wb_collider_default_def(WB_SHAPE_SPHERE);
    wb_collider_id c = wb_collider_add(w, &sd, NULL);
    const wb_real om[3] = { 1e308, 1e308, 0 }, v[3] = { 1e308, 0, 0 };
    wb_collider_set_angular_velocity(w, c, om);
    wb_collider_set_velocity(w, c, v);
    wb_world_step(w);
    wb_real p[3], q[4];
    wb_collider_position(w, c, p);
    wb_collider_rotation(w, c, q);
    CHECK(isfinite(p[0]) && isfinite(q[0]) && isfinite(q[1]) && isfinite(q[2]) && isfinite(q[3]));
    CHECK_EQ(wb_world_warnings(w), 1);
    CHECK_HAS(wb_world_last_warning(w), "collider 1");
    wb_collider_velocity(w, c, p);
    CHECK(p[0] == 0);
    wb_world_destroy(w);
}

TEST(hash_covers_collider_velocity_mass_radius)
{
    /* worlds that differ only in a collider's velocity, a mass or a radius diverge
     * at the next step: their hashes must differ already */
    wb_world_def d = wb_world_default_def();
    const wb_real x[3] = { 0, 1, 0 }, v[3] = { 1, 0, 0 };
    uint64_t h[4];
    for (int k = 0; k < 4; k++) {
        wb_world *w = wb_world_create(&d);
        REQUIRE(w);
        wb_particle_add(w, x, NULL, k == 2 ? 2 : 1, k == 3 ? 0.5 : 0.02);
        wb_collider_def cd = wb_collider_default_def(WB_SHAPE_SPHERE);
        wb_collider_id c = wb_collider_add(w, &cd, NULL);
        if (k == 1) wb_collider_set_velocity(w, c, v);
        h[k] = wb_world_hash(w);
        wb_world_destroy(w);
    }
    CHECK(h[0] != h[1]);
    CHECK(h[0] != h[2]);
    CHECK(h[0] != h[3]);
}

TEST(memory_budget_shared_by_worlds)
{
    /* two worlds charged to one budget: the second cannot take what the first holds,
     * and destroying the first gives it back */
    wb_memory mem = { 64u << 20, 0 };
    wb_world_def d = wb_world_default_def();
    d.memory = &mem;
    wb_world *a = wb_world_create(&d), *b = wb_world_create(&d);
    REQUIRE(a && b);
    wb_cloth_def c = wb_cloth_default_def();
    c.res[0] = c.res[1] = 250; /* 62.5k particles, 187k links: over half the 64 MB */
    wb_body body;
    CHECK_EQ(wb_cloth(a, &c, &body), WB_OK);
    CHECK(mem.used > (32u << 20) && mem.used <= mem.limit);
    CHECK_EQ(wb_cloth(b, &c, &body), WB_ERR_NOMEM);
    CHECK_EQ(wb_particle_count(b), 0);
    wb_world_destroy(a);
    CHECK_EQ(wb_cloth(b, &c, &body), WB_OK);
    wb_world_destroy(b);
    CHECK_EQ(mem.used, 0);
}

TEST(memory_budget_charges_worlds_and_threads)
{
    /* an empty world is charged what it is (the struct, over a kilobyte), and a world
     * of 256 threads its 255 workers too (32 kB each, 8 MB): 10^7 empty worlds or a few
     * dozen of 256 threads must not pass a budget that only saw their Lua handles */
    wb_memory mem = { 4u << 20, 0 };
    wb_world_def d = wb_world_default_def();
    d.memory = &mem;
    wb_world *w = wb_world_create(&d);
    REQUIRE(w);
    const size_t one = mem.used;
    CHECK(one > 1024);
    d.threads = WB_MAX_THREADS;
    CHECK(wb_world_create(&d) == NULL); /* 8 MB of threads in 4 MB */
    CHECK_EQ(mem.used, one);
    CHECK_EQ(wb_world_set_def(w, &d), WB_ERR_NOMEM); /* nor made so afterwards */
    CHECK_EQ(wb_world_get_def(w).threads, 1);
    CHECK_EQ(mem.used, one);
    d.threads = 8;
    CHECK_EQ(wb_world_set_def(w, &d), WB_OK);
    CHECK(mem.used >= one + 7 * (size_t)(32 << 10));
    d.threads = 1;
    CHECK_EQ(wb_world_set_def(w, &d), WB_OK); /* fewer threads give it back */
    CHECK_EQ(mem.used, one);
    /* as many as fit, then a refusal */
    wb_world *many[8192];
    int n = 0;
    while (n < 8192 && (many[n] = wb_world_create(&d))) n++;
    CHECK(n < 8192 && mem.used <= mem.limit && mem.used + one > mem.limit);
    for (int i = 0; i < n; i++) wb_world_destroy(many[i]);
    wb_world_destroy(w);
    CHECK_EQ(mem.used, 0);
}

/* adds tets (kind 0) or volume constraints (kind 1) over the same four particles until one
 * is refused, at most cap of them; returns how many were added */
static int32_t add_until_refused(wb_world *w, const int32_t p[4], int kind, int32_t cap, int32_t *last)
{
    const wb_tet_def td = wb_tet_default_def();
    const wb_volume_def vd = wb_volume_default_def();
    int32_t n = 0;
    *last = 0;
    while (n < cap && (*last = kind ? wb_volume_add(w, p, &vd) : wb_tet_add(w, p, &td)) >= 0) n++;
    return n;
}

TEST(memory_budget_charges_tets_and_volumes)
{
    /* a tet holds 148 to 260 bytes (float or double) and a volume constraint 60 to 80,
     * their arrays doubling from 64: under a budget 1 MiB above what the particles took,
     * adding them is refused (WB_ERR_NOMEM) at a capacity between 2048 (double tets) and
     * 16384 (float volumes), the refused one charging nothing; the budget is never
     * passed, what was added stays, and destroying the world gives it all back */
    static const wb_real x[4][3] = { { 0, 0, 0 }, { 1, 0, 0 }, { 0, 1, 0 }, { 0, 0, 1 } };
    for (int kind = 0; kind < 2; kind++) {
        wb_memory mem = { 0, 0 };
        wb_world_def d = wb_world_default_def();
        d.memory = &mem;
        wb_world *w = wb_world_create(&d);
        REQUIRE(w);
        int32_t p[4];
        for (int k = 0; k < 4; k++) {
            p[k] = wb_particle_add(w, x[k], NULL, 1, 0);
            REQUIRE(p[k] >= 0);
        }
        mem.limit = mem.used + (1u << 20);
        int32_t last;
        const int32_t n = add_until_refused(w, p, kind, 1 << 16, &last);
        REQUIRE(last == WB_ERR_NOMEM); /* a world past the budget is not stepped */
        CHECK(n >= 2048 && n <= 16384 && (n & (n - 1)) == 0);
        CHECK(mem.used <= mem.limit);
        const size_t used = mem.used;
        CHECK_EQ(add_until_refused(w, p, kind, 1, &last), 0);
        CHECK_EQ(last, WB_ERR_NOMEM);
        CHECK_EQ(mem.used, used);
        CHECK_EQ(kind ? wb_volume_count(w) : wb_tet_count(w), n);
        CHECK_EQ(wb_world_step(w), WB_OK);
        wb_world_destroy(w);
        CHECK_EQ(mem.used, 0);
    }
}

TEST(distance_ids_match_distance_at)
{
    /* the bulk listing is the same as the one-at-a-time scan, holes and reused slots
     * included */
    wb_world_def d = wb_world_default_def();
    wb_world *w = wb_world_create(&d);
    REQUIRE(w);
    wb_rope_def r = wb_rope_default_def();
    r.segments = 20;
    wb_body b;
    REQUIRE(wb_rope(w, &r, &b) == WB_OK);
    wb_distance_remove(w, wb_distance_at(w, 3));
    wb_distance_remove(w, wb_distance_at(w, 10));
    wb_distance_def dd = wb_distance_default_def();
    wb_distance_add(w, 0, 5, &dd, NULL); /* reuses a freed slot */
    wb_distance_id ids[32];
    const int32_t n = wb_distance_ids(w, ids);
    CHECK_EQ(n, wb_distance_count(w));
    CHECK_EQ(n, 19);
    for (int32_t i = 0; i < n; i++) {
        const wb_distance_id a = wb_distance_at(w, i);
        CHECK(ids[i].index == a.index && ids[i].gen == a.gen && wb_distance_valid(w, ids[i]));
    }
    wb_world_destroy(w);
}
