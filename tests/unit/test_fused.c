/* test_fused.c: the collision pass that also predicts the next substep (solver.c,
 * collide.c) gives the bits of the unfused order: every scene runs twice, fused and with
 * the tests' switch wb_cache.no_fuse, and the hashes must agree; so must the folded
 * finiteness check's warning and undo. The one-plane pass's AVX2 groups against its
 * scalar code (wb_cache.no_simd) at the end. Scenes also run made half inside their
 * plane (sunk): the overlap goes out at max_depenetration over many frames, through the
 * particles' kept overlap (wb_cache.c_left) and x_prev's shift, in every path. */
#include <stdlib.h>

#include "core/core.h"
#include "core/broadphase.h"
#include "core/tricontact.h"
#include "test.h"

enum { SCENE_PLANE, SCENE_PLANES, SCENE_MIXED, SCENE_BODIES };

/* a cloth over colliders, with damping and a slanted gravity: SCENE_PLANE one static
 * ground (the one-plane path), SCENE_PLANES two static planes (the planes path),
 * SCENE_MIXED a plane and a moving sphere (the general path), SCENE_BODIES two cloths
 * that touch (particle contacts: some substeps cannot fuse). res 64: 4096 particles,
 * the pool's threshold */
/* the particles still inside the first collider by more than one substep's
 * max_depenetration x h: kept overlap (the made path at work) */
static int32_t kept_inside(const wb_world *w)
{
    const wb_real step = w->m.def.max_depenetration * w->m.def.dt / w->m.def.substeps;
    wb_collider_id c = wb_collider_at(w, 0);
    int32_t n = 0;
    for (int32_t i = 0; i < w->m.np; i++)
        n += wb_collider_distance(w, c, &w->s.x[3 * i]) < w->m.radius[i] - step;
    return n;
}

static wb_world *scene(int kind, int threads, int no_fuse, int sunk)
{
    wb_world_def d = wb_world_default_def();
    d.threads = threads;
    d.substeps = 6;
    d.damping = 0.7;
    d.gravity[0] = 0.9; d.gravity[1] = -9.81; d.gravity[2] = -0.4;
    wb_world *w = wb_world_create(&d);
    if (!w) return NULL;
    w->k.no_fuse = no_fuse;
    wb_cloth_def c = wb_cloth_default_def();
    c.origin[0] = -1; c.origin[1] = 0.3; c.origin[2] = -1;
    c.size[0] = c.size[1] = 2;
    c.res[0] = c.res[1] = kind == SCENE_BODIES ? 24 : 64;
    c.link.compliance = 1e-7;
    wb_body body;
    if (wb_cloth(w, &c, &body) != WB_OK) { wb_world_destroy(w); return NULL; }
    wb_particle_pin(w, body.first, NULL); /* w = 0: the pass's other branch */
    if (kind == SCENE_BODIES) {
        c.origin[0] = -0.5; c.origin[1] = 0.33; c.origin[2] = -0.5;
        c.size[0] = c.size[1] = 1;
        if (wb_cloth(w, &c, &body) != WB_OK) { wb_world_destroy(w); return NULL; }
    }
    wb_collider_def pl = wb_collider_default_def(WB_SHAPE_PLANE);
    pl.friction = 0.4;
    pl.restitution = 0.6;
    if (sunk) { /* through the cloth: up to 10 cm inside it, by x */
        pl.normal[0] = 0.1;
        pl.offset = 0.3;
    }
    wb_collider_add(w, &pl, NULL);
    if (kind == SCENE_PLANES) {
        wb_collider_def p2 = wb_collider_default_def(WB_SHAPE_PLANE);
        p2.normal[0] = 1; p2.normal[1] = 0.3; p2.normal[2] = 0;
        p2.offset = -0.2;
        p2.friction = 0.8;
        wb_collider_add(w, &p2, NULL);
    }
    if (kind == SCENE_MIXED) {
        wb_collider_def s = wb_collider_default_def(WB_SHAPE_SPHERE);
        s.center[1] = 0.1;
        s.radius = 0.3;
        s.friction = 0.3;
        wb_collider_id id = wb_collider_add(w, &s, NULL);
        const wb_real v[3] = { 0.2, 0.5, 0 };
        wb_collider_set_velocity(w, id, v);
    }
    return w;
}

static void fused_case(int kind, int threads, int sunk)
{
    wb_world *a = scene(kind, threads, 0, sunk), *b = scene(kind, threads, 1, sunk);
    REQUIRE(a && b);
    for (int f = 0; f < 30; f++) {
        wb_world_step(a);
        wb_world_step(b);
        if (sunk && f == 2) CHECK(kept_inside(a) > 100);
    }
    CHECK(wb_world_hash(a) == wb_world_hash(b));
    CHECK(memcmp(a->s.x_prev, b->s.x_prev, sizeof(wb_real) * 3 * (size_t)a->m.np) == 0);
    /* the fused path was taken (not every substep with particle contacts), the other never */
    CHECK(a->k.fused > 0);
    CHECK(kind == SCENE_BODIES ? a->k.fused < 30 * 5 : a->k.fused == 30 * 5);
    CHECK_EQ(b->k.fused, 0);
    CHECK(wb_world_stats(a).contacts > 0); /* the cloth reached a collider */
    if (kind == SCENE_BODIES) CHECK(a->k.pc->n > 0);
    CHECK_EQ(wb_world_warnings(a), 0);
    wb_world_destroy(a);
    wb_world_destroy(b);
}

TEST(fused_predict_bits_one_plane) { fused_case(SCENE_PLANE, 1, 0); fused_case(SCENE_PLANE, 2, 0); }
TEST(fused_predict_bits_planes) { fused_case(SCENE_PLANES, 1, 0); fused_case(SCENE_PLANES, 2, 0); }
TEST(fused_predict_bits_mixed_colliders) { fused_case(SCENE_MIXED, 1, 0); fused_case(SCENE_MIXED, 3, 0); }
TEST(fused_predict_bits_with_particle_contacts) { fused_case(SCENE_BODIES, 1, 0); }
TEST(fused_predict_bits_made_overlapping)
{
    fused_case(SCENE_PLANE, 1, 1);
    fused_case(SCENE_PLANE, 2, 1);
    fused_case(SCENE_PLANES, 2, 1);
    fused_case(SCENE_MIXED, 3, 1);
    fused_case(SCENE_BODIES, 1, 1);
}

/* the last substep's pass checks x and v: a particle gone non-finite undoes the frame
 * with the warning (and particle) of the unfused check */
TEST(fused_scan_finds_the_first_nonfinite_particle)
{
    for (int threads = 1; threads <= 2; threads++) {
        wb_world *a = scene(SCENE_PLANE, threads, 0, 0), *b = scene(SCENE_PLANE, threads, 1, 0);
        REQUIRE(a && b);
        wb_world_step(a);
        wb_world_step(b);
        const int32_t np = a->m.np;
        wb_real *x = malloc(sizeof(wb_real) * 3 * (size_t)np);
        REQUIRE(x);
        memcpy(x, a->s.x, sizeof(wb_real) * 3 * (size_t)np);
        /* two particles far apart (in different parts with 2 threads); the first named */
        const wb_real huge[3] = { 1e300, -1e300, 0 };
        wb_particle_set_velocity(a, 3900, huge);
        wb_particle_set_velocity(b, 3900, huge);
        wb_particle_set_velocity(a, 1000, huge);
        wb_particle_set_velocity(b, 1000, huge);
        wb_world_step(a);
        wb_world_step(b);
        CHECK_EQ(wb_world_warnings(a), 1);
        CHECK_HAS(wb_world_last_warning(a), "non-finite");
        CHECK(strcmp(wb_world_last_warning(a), wb_world_last_warning(b)) == 0);
        CHECK(a->k.nonfinite >= 0);   /* found by the pass */
        CHECK_EQ(b->k.nonfinite, -2); /* b looked for it afterwards */
        CHECK(memcmp(x, a->s.x, sizeof(wb_real) * 3 * (size_t)np) == 0); /* undone */
        CHECK(wb_world_hash(a) == wb_world_hash(b));
        free(x);
        wb_world_destroy(a);
        wb_world_destroy(b);
    }
}

/* The one-plane pass's AVX2 groups of four (collide.c) give the bits of its scalar code:
 * a cloth falls onto the ground and lies there, run with and without the switch
 * wb_cache.no_simd; x, x_prev, v and the hash must agree after every frame. res 31: a
 * count of particles not a multiple of four (the scalar tail); pins: groups with w = 0;
 * friction: groups in contact take the scalar code; restitution: the bounce's lanes. */
static wb_world *ground_cloth(int res, int pins, wb_real friction, wb_real restitution, int sunk, int no_simd)
{
    wb_world_def d = wb_world_default_def();
    d.substeps = 5;
    d.damping = 0.3;
    d.gravity[0] = 0.7; d.gravity[1] = -9.81; d.gravity[2] = -0.3;
    wb_world *w = wb_world_create(&d);
    if (!w) return NULL;
    w->k.no_simd = no_simd;
    wb_cloth_def c = wb_cloth_default_def();
    c.origin[0] = -1; c.origin[1] = 0.2; c.origin[2] = -1;
    c.size[0] = c.size[1] = 2;
    c.res[0] = c.res[1] = res;
    c.link.compliance = 1e-6;
    wb_body body;
    if (wb_cloth(w, &c, &body) != WB_OK) { wb_world_destroy(w); return NULL; }
    for (int p = 0; p < pins; p++) wb_particle_pin(w, body.first + 37 * p, NULL);
    wb_collider_def pl = wb_collider_default_def(WB_SHAPE_PLANE);
    pl.friction = friction;
    pl.restitution = restitution;
    if (sunk) { /* through the cloth, tilted both ways: lanes in and out of it, kept or not */
        pl.normal[0] = 0.1;
        pl.normal[2] = 0.05;
        pl.offset = 0.2;
    }
    wb_collider_add(w, &pl, NULL);
    return w;
}

static void simd_case(int res, int pins, wb_real friction, wb_real restitution, int sunk)
{
    wb_world *a = ground_cloth(res, pins, friction, restitution, sunk, 0);
    wb_world *b = ground_cloth(res, pins, friction, restitution, sunk, 1);
    REQUIRE(a && b);
    const size_t bytes = sizeof(wb_real) * 3 * (size_t)a->m.np;
    int same = 1, touched = 0;
    for (int f = 0; f < 90 && same; f++) {
        /* a push now and then: some particles leave the ground and come back */
        if (f == 50) {
            const wb_real up[3] = { 0.1, 3, 0 };
            wb_particle_set_velocity(a, 5, up);
            wb_particle_set_velocity(b, 5, up);
        }
        wb_world_step(a);
        wb_world_step(b);
        same = wb_world_hash(a) == wb_world_hash(b) && memcmp(a->s.x, b->s.x, bytes) == 0 &&
               memcmp(a->s.x_prev, b->s.x_prev, bytes) == 0 && memcmp(a->s.v, b->s.v, bytes) == 0 &&
               wb_world_stats(a).contacts == wb_world_stats(b).contacts;
        if (!same) printf("    res %d pins %d friction %g restitution %g: frame %d differs\n", res, pins,
                          (double)friction, (double)restitution, f);
        touched += wb_world_stats(a).contacts > a->m.np / 2; /* most of it on the ground */
        if (sunk && f == 2) CHECK(kept_inside(a) > 0);
    }
    CHECK(same);
    CHECK(touched > 5);
    CHECK(a->k.fused > 0);
    CHECK_EQ(wb_world_warnings(a), 0);
    wb_world_destroy(a);
    wb_world_destroy(b);
}

TEST(fused_plane_simd_bits)
{
    simd_case(32, 0, 0, 0, 0);     /* the bench's cloth: every group in vectors */
    simd_case(31, 3, 0, 0, 0);     /* the tail, pinned groups */
    simd_case(32, 2, 0, 0.8, 0);   /* bounces */
    simd_case(31, 0, 0.5, 0.4, 0); /* friction: contact groups scalar */
    simd_case(32, 0, 0, 0, 1);     /* made half inside the ground: kept overlap in lanes */
    simd_case(31, 3, 0, 0.8, 1);
    simd_case(31, 0, 0.5, 0, 1);
}

/* the scan of the last substep in groups of four: the same first non-finite particle */
TEST(fused_plane_simd_scan_nonfinite)
{
    wb_world *a = ground_cloth(32, 0, 0, 0, 0, 0), *b = ground_cloth(32, 0, 0, 0, 0, 1);
    REQUIRE(a && b);
    wb_world_step(a);
    wb_world_step(b);
    const wb_real huge[3] = { 1e300, -1e300, 0 };
    wb_particle_set_velocity(a, 702, huge);
    wb_particle_set_velocity(b, 702, huge);
    wb_particle_set_velocity(a, 901, huge);
    wb_particle_set_velocity(b, 901, huge);
    wb_world_step(a);
    wb_world_step(b);
    CHECK_EQ(wb_world_warnings(a), 1);
    CHECK(a->k.nonfinite >= 0);
    CHECK_EQ(a->k.nonfinite, b->k.nonfinite);
    CHECK(strcmp(wb_world_last_warning(a), wb_world_last_warning(b)) == 0);
    CHECK(wb_world_hash(a) == wb_world_hash(b));
    wb_world_destroy(a);
    wb_world_destroy(b);
}
