/* test_rigid.c: XPBD rigid bodies (rigid.c): the helpers of RIGID.md against their
 * formulas, inertia tensors, slots and handles, the memory budget, undo of a non-finite
 * frame, exact clones. */
#include <stdlib.h>

#include "test.h"
#include "core/rigid.h"

static wb_world *world(wb_real gy)
{
    wb_world_def d = wb_world_default_def();
    d.gravity[1] = gy;
    return wb_world_create(&d);
}

TEST(rigid_helpers_match_their_formulas)
{
    wb_world *w = world(0);
    REQUIRE(w);
    wb_rigid_def d = wb_rigid_default_def(WB_SHAPE_BOX);
    v3_set(d.half, 0.1, 0.2, 0.3);
    d.mass = 2;
    v3_set(d.pos, 1, 2, 3);
    d.rotation[0] = 0.8; d.rotation[1] = 0.2; d.rotation[2] = -0.4; d.rotation[3] = 0.4;
    wb_rigid_id id = wb_rigid_add(w, &d, NULL);
    REQUIRE(wb_rigid_valid(w, id));
    const int32_t r = (int32_t)id.index - 1;
    /* to_world / to_local are inverses */
    const wb_real l[3] = { 0.1, -0.2, 0.3 };
    wb_real x[3], back[3];
    wb__rigid_to_world(w, r, l, x);
    wb__rigid_to_local(w, r, x, back);
    for (int i = 0; i < 3; i++) CHECK_NEAR(back[i], l[i], 1e-15);
    /* w = 1/m + (r x n) . I^-1 (r x n), I^-1 from the principal moments in the body frame */
    wb_real n[3] = { 0.3, 0.4, 1.2 }, rr[3], rn[3], rb[3];
    v3_scale(n, n, 1 / v3_len(n));
    v3_sub(rr, x, d.pos);
    v3_cross(rn, rr, n);
    q_rotate_inv(w->rb->q, rn, rb);
    const wb_real I[3] = { 2 * (0.04 + 0.09) / 3, 2 * (0.01 + 0.09) / 3, 2 * (0.01 + 0.04) / 3 };
    const wb_real want = 0.5 + rb[0] * rb[0] / I[0] + rb[1] * rb[1] / I[1] + rb[2] * rb[2] / I[2];
    CHECK_NEAR(wb__rigid_w(w, r, x, n), want, 1e-13);
    /* a small positional impulse lambda n at x moves that material point by lambda w
     * along n (to first order: the error is O(lambda^2)) */
    const wb_real lam = 1e-7;
    wb_real dp[3], x1[3], dx[3];
    v3_scale(dp, n, lam);
    wb__rigid_apply(w, r, x, dp);
    wb__rigid_to_world(w, r, l, x1);
    v3_sub(dx, x1, x);
    CHECK_NEAR(v3_dot(dx, n), lam * want, 1e-12 * lam * want + 1e-13);
    /* the centre moved by dp / m exactly */
    wb_real p[3];
    wb_rigid_position(w, id, p);
    CHECK_NEAR(p[0], 1 + dp[0] / 2, 1e-16);
    CHECK_NEAR(p[2], 3 + dp[2] / 2, 1e-16);
    wb_world_destroy(w);
}

TEST(rigid_inertia_of_the_shapes)
{
    wb_cshape s;
    wb_real I[9];
    memset(&s, 0, sizeof s);
    s.shape = WB_SHAPE_SPHERE;
    s.radius = 0.5;
    wb__rigid_inertia(&s, 3, I);
    CHECK_NEAR(I[0], 0.4 * 3 * 0.25, 1e-15);
    CHECK_NEAR(I[4], I[0], 0);
    CHECK_NEAR(I[1], 0, 0);
    s.shape = WB_SHAPE_BOX;
    v3_set(s.half, 0.5, 1, 1.5); /* a 1 x 2 x 3 box: m (b^2 + c^2) / 12 with full sides */
    wb__rigid_inertia(&s, 12, I);
    CHECK_NEAR(I[0], 4 + 9, 1e-13);
    CHECK_NEAR(I[4], 1 + 9, 1e-13);
    CHECK_NEAR(I[8], 1 + 4, 1e-13);
    /* a capsule along (1, 1, 0) / sqrt 2: its tensor is the axial and transverse moments
     * in that frame; a zero-length capsule is a ball */
    s.shape = WB_SHAPE_CAPSULE;
    s.radius = 0.2;
    v3_set(s.a, 0, 0, 0);
    v3_set(s.b, 0, 0, 0);
    wb__rigid_inertia(&s, 2, I);
    CHECK_NEAR(I[0], 0.4 * 2 * 0.04, 1e-15);
    CHECK_NEAR(I[8], I[0], 1e-15);
    const wb_real h = 0.5 / sqrt(2.0);
    v3_set(s.a, -h, -h, 0);
    v3_set(s.b, h, h, 0);
    wb__rigid_inertia(&s, 2, I);
    wb_real Ix[9];
    v3_set(s.a, -0.5, 0, 0);
    v3_set(s.b, 0.5, 0, 0);
    wb__rigid_inertia(&s, 2, Ix);
    const wb_real ia = Ix[0], it = Ix[4];
    CHECK(ia < it);
    CHECK_NEAR(Ix[8], it, 1e-15);
    /* u u^T ia + (1 - u u^T) it, u = (1, 1, 0)/sqrt 2 */
    CHECK_NEAR(I[0], (ia + it) / 2, 1e-15);
    CHECK_NEAR(I[1], (ia - it) / 2, 1e-15);
    CHECK_NEAR(I[8], it, 1e-15);
}

TEST(rigid_slots_handles_and_budget)
{
    wb_memory mem = { 1u << 20, 0 };
    wb_world_def d = wb_world_default_def();
    d.memory = &mem;
    wb_world *w = wb_world_create(&d);
    REQUIRE(w);
    wb_rigid_def rd = wb_rigid_default_def(WB_SHAPE_SPHERE);
    wb_rigid_id a = wb_rigid_add(w, &rd, NULL), b = wb_rigid_add(w, &rd, NULL);
    CHECK(mem.used > 0);
    CHECK_EQ(wb_rigid_count(w), 2);
    wb_rigid_remove(w, a);
    CHECK(!wb_rigid_valid(w, a));
    wb_rigid_id c = wb_rigid_add(w, &rd, NULL);
    CHECK_EQ(c.index, a.index);          /* the free slot, a new generation */
    CHECK(c.gen != a.gen && (c.gen & 1u));
    CHECK(wb_rigid_valid(w, b));
    CHECK_EQ(wb_rigid_at(w, 1).index, b.index);
    /* a bad def changes nothing and says why */
    rd.mass = -1;
    wb_status st;
    wb_rigid_id bad = wb_rigid_add(w, &rd, &st);
    CHECK_EQ(st, WB_ERR_ARG);
    CHECK_EQ(bad.index, 0);
    CHECK_HAS(wb_last_error(), "mass");
    CHECK_EQ(wb_rigid_count(w), 2);
    /* bodies until the budget refuses: then NOMEM, and nothing half made */
    rd.mass = 1;
    int32_t n = 2;
    for (; n < 200000; n++) {
        wb_rigid_add(w, &rd, &st);
        if (st != WB_OK) break;
    }
    CHECK_EQ(st, WB_ERR_NOMEM);
    CHECK_EQ(wb_rigid_count(w), n);
    CHECK(mem.used <= mem.limit);
    wb_world_destroy(w);
    CHECK_EQ(mem.used, 0);
}

TEST(rigid_nonfinite_frame_undone)
{
    wb_world *w = world(-9.81);
    REQUIRE(w);
    wb_rigid_def d = wb_rigid_default_def(WB_SHAPE_BOX);
    v3_set(d.pos, 1.797e308, 0, 0);
    v3_set(d.vel, 1e308, 0, 0); /* x + v dt overflows */
    wb_rigid_id id = wb_rigid_add(w, &d, NULL);
    const int32_t p = wb_particle_add(w, (const wb_real[3]){ 0, 1, 0 }, (const wb_real[3]){ 0, 0, 0 }, 1, 0.01);
    CHECK_EQ(wb_world_step(w), WB_OK);
    CHECK(wb_world_warnings(w) > 0);
    CHECK_HAS(wb_world_last_warning(w), "rigid body 1");
    wb_real x[3], v[3];
    wb_rigid_position(w, id, x);
    wb_rigid_velocity(w, id, v);
    CHECK_NEAR(x[0], 1.797e308, 0);
    CHECK_NEAR(v[0], 1e308, 0);
    CHECK_NEAR(v[1], 0, 0);
    /* the particles' frame went with it */
    CHECK_NEAR(wb_particle_positions(w)[3 * p + 1], 1, 0);
    wb_world_destroy(w);
}

TEST(rigid_clone_same_hash_and_future)
{
    wb_world *w = world(-9.81);
    REQUIRE(w);
    wb_collider_def g = wb_collider_default_def(WB_SHAPE_PLANE);
    g.friction = 0.5;
    wb_collider_add(w, &g, NULL);
    wb_rigid_def d = wb_rigid_default_def(WB_SHAPE_BOX);
    v3_set(d.pos, 0, 1, 0);
    v3_set(d.angular_velocity, 1, 2, 3);
    wb_rigid_add(w, &d, NULL);
    d = wb_rigid_default_def(WB_SHAPE_CAPSULE);
    v3_set(d.pos, 2, 1, 0);
    v3_set(d.b, 0.5, 0.7, 0.1);
    d.restitution = 0.5;
    wb_rigid_id gone = wb_rigid_add(w, &d, NULL);
    wb_rigid_add(w, &d, NULL);
    for (int i = 0; i < 30; i++) wb_world_step(w);
    wb_rigid_remove(w, gone);
    wb_world *c = wb_world_clone(w);
    REQUIRE(c);
    CHECK(wb_world_hash(c) == wb_world_hash(w));
    for (int i = 0; i < 30; i++) { wb_world_step(w); wb_world_step(c); }
    CHECK(wb_world_hash(c) == wb_world_hash(w));
    CHECK_EQ(wb_rigid_count(c), 2);
    wb_world_destroy(c);
    wb_world_destroy(w);
}

TEST(rigid_pair_manifold_pushes_apart_by_inverse_mass)
{
    /* two spheres overlapping 0.1 along x, masses 1 and 3: the manifold's correction
     * moves them apart by 3/4 and 1/4 of it (no turn: the arms are along the normal),
     * sum m dx = 0 exactly as the impulses are opposite; the contact is kept for the
     * velocity pass */
    wb_world *w = world(0);
    REQUIRE(w);
    wb_rigid_def d = wb_rigid_default_def(WB_SHAPE_SPHERE);
    d.radius = 0.5;
    wb_rigid_id a = wb_rigid_add(w, &d, NULL);
    v3_set(d.pos, 0.9, 0, 0);
    d.mass = 3;
    wb_rigid_id b = wb_rigid_add(w, &d, NULL);
    wb_manifold m;
    memset(&m, 0, sizeof m);
    m.n = 1;
    v3_set(m.normal, 1, 0, 0);
    v3_set(m.pt[0].pa, 0.5, 0, 0);
    v3_set(m.pt[0].pb, 0.4, 0, 0);
    m.pt[0].depth = 0.1;
    w->rb->nct = 0;
    /* driven in by the substep: b was touching a at its start (a made overlap would go
     * out at max_depenetration only) */
    w->rb->x_prev[3 * ((int32_t)b.index - 1)] = 1.0;
    wb__rigid_contact_rigid(w, (int32_t)a.index - 1, (int32_t)b.index - 1, &m, 1.0 / 600);
    wb_real xa[3], xb[3], q[4];
    wb_rigid_position(w, a, xa);
    wb_rigid_position(w, b, xb);
    CHECK_NEAR(xa[0], -0.075, 1e-15);
    CHECK_NEAR(xb[0], 0.925, 1e-15);
    CHECK_NEAR(1 * xa[0] + 3 * (xb[0] - 0.9), 0, 1e-15);
    CHECK_NEAR(xb[0] - xa[0], 1.0, 1e-15);   /* touching */
    wb_rigid_rotation(w, a, q);
    CHECK_NEAR(q[0], 1, 0);
    CHECK_EQ(w->rb->nct, 1);
    CHECK_NEAR(w->rb->ct[0].lambda, 0.1 / (1 + 1.0 / 3), 1e-15);
    wb_world_destroy(w);
}
