/* test_bend.c: the bend type (white-box: includes core.h): its colour batches, thread
 * independence, momentum, the hinges of a triangle list and refused definitions. */
#include <stdlib.h>

#include "core/core.h"
#include "core/bend.h"
#include "test.h"

static wb_world *bent_cloth(int threads, wb_solver solver, int res)
{
    wb_world_def d = wb_world_default_def();
    d.threads = threads;
    d.solver = solver;
    wb_world *w = wb_world_create(&d);
    if (!w) return NULL;
    wb_cloth_def c = wb_cloth_default_def();
    c.origin[1] = 1;
    c.res[0] = c.res[1] = res;
    c.bend = 1;
    c.link.compliance = 1e-6;
    wb_body b;
    if (wb_cloth(w, &c, &b) != WB_OK) { wb_world_destroy(w); return NULL; }
    wb_particle_pin(w, b.first, NULL);
    wb_particle_pin(w, b.first + res - 1, NULL);
    return w;
}

/* the batches before serial_start share no movable particle; every bend packed once */
TEST(bend_batches_valid)
{
    wb_world *w = bent_cloth(1, WB_SOLVER_GAUSS_SEIDEL, 33);
    REQUIRE(w);
    wb_world_step(w);
    const wb_bends *b = w->bend;
    REQUIRE(!b->dirty);
    CHECK_EQ(b->n, 2 * 32 * 33 + 32 * 32 - 4 * 32); /* interior edges of a 32 x 32-cell sheet */
    CHECK_EQ(b->bt.colour_start[0], 0);
    CHECK_EQ(b->bt.colour_start[b->bt.ncolours], b->n);
    CHECK(b->bt.ncolours >= 4); /* four particles each: a hinge, its two wings */
    int32_t *owner = malloc(sizeof(int32_t) * (size_t)w->m.np);
    REQUIRE(owner);
    for (int32_t i = 0; i < w->m.np; i++) owner[i] = -1;
    int conflicts = 0, bad = 0;
    for (int32_t c = 0; c < b->bt.serial_start; c++)
        for (int32_t i = b->bt.colour_start[c]; i < b->bt.colour_start[c + 1]; i++)
            for (int e = 0; e < 4; e++) {
                const int32_t p = b->s_ij[4 * i + e];
                if (w->m.inv_mass[p] == 0) continue;
                if (owner[p] == c) conflicts++;
                owner[p] = c;
            }
    for (int32_t s = 0; s < b->n; s++) {
        const int32_t i = b->pack[s];
        if (i < 0 || i >= b->n || b->s_slot[i] != s || memcmp(&b->s_ij[4 * i], &b->ij[4 * s], 4 * sizeof(int32_t))) bad++;
    }
    CHECK_EQ(conflicts, 0);
    CHECK_EQ(bad, 0);
    free(owner);
    wb_world_destroy(w);
}

/* parallel batches (a batch past 256 bends runs in chunks): bit-identical for any thread count */
TEST(bend_threads_identical)
{
    const wb_solver solvers[2] = { WB_SOLVER_GAUSS_SEIDEL, WB_SOLVER_JACOBI };
    for (int s = 0; s < 2; s++) {
        wb_world *a = bent_cloth(1, solvers[s], 48), *b = bent_cloth(4, solvers[s], 48);
        REQUIRE(a && b);
        for (int f = 0; f < 20; f++) { wb_world_step(a); wb_world_step(b); }
        int32_t big = 0;
        for (int32_t c = 0; c < b->bend->bt.serial_start; c++)
            if (b->bend->bt.colour_start[c + 1] - b->bend->bt.colour_start[c] >= 256) big++;
        CHECK(big > 0);
        CHECK_EQ(wb_world_hash(a), wb_world_hash(b));
        CHECK_EQ(wb_world_warnings(b), 0);
        wb_world_destroy(a);
        wb_world_destroy(b);
    }
}

/* free particles, no gravity: a bend's gradients sum to zero, so its corrections
 * (mass-weighted) leave the momentum alone; they are rotation-free too (the angle does not
 * change under a rotation), so a spinning pair keeps its angular momentum up to the
 * velocity update's O(h) splitting */
TEST(bend_conserves_momentum)
{
    wb_world_def d = wb_world_default_def();
    d.gravity[1] = 0;
    wb_world *w = wb_world_create(&d);
    REQUIRE(w);
    const wb_real x[4][3] = { { 0, 0, 0 }, { 1, 0.1, 0 }, { 0.4, 0.2, 1 }, { 0.6, 0.7, -0.8 } };
    const wb_real mass[4] = { 1, 2, 0.5, 3 };
    const wb_real om[3] = { 0.3, -1, 0.5 }, drift[3] = { 0.2, 0.1, -0.3 };
    int32_t p[4];
    for (int i = 0; i < 4; i++) {
        /* a rigid spin plus a drift, and a kick on one wing that bends the pair */
        wb_real v[3];
        v3_cross(v, om, x[i]);
        v3_add(v, v, drift);
        if (i == 3) v[1] += 2;
        p[i] = wb_particle_add(w, x[i], v, mass[i], 0);
    }
    wb_bend_def bd = wb_bend_default_def();
    wb_status st;
    wb_bend_id id = wb_bend_add(w, p, &bd, &st);
    REQUIRE(st == WB_OK);
    const wb_real rest = wb_bend_rest(w, id);
    wb_real p0[3], l0[3], p1[3], l1[3];
    wb_world_momentum(w, p0);
    wb_world_angular_momentum(w, l0);
    for (int f = 0; f < 30; f++) wb_world_step(w);
    wb_world_momentum(w, p1);
    wb_world_angular_momentum(w, l1);
    /* 1e-10: 300 substeps of v = dx/h amplify position rounding (1e-16) by 1/h = 600 */
    for (int c = 0; c < 3; c++) CHECK_NEAR(p1[c], p0[c], 1e-10);
    /* angular momentum: the kick's share that the bend turns into spin is kept to 1% */
    const wb_real l = v3_len(l0);
    for (int c = 0; c < 3; c++) CHECK_NEAR(l1[c], l0[c], 0.01 * l);
    CHECK_NEAR(wb_bend_angle(w, id), rest, 1e-6);
    wb_world_destroy(w);
}

TEST(bend_hinges_and_refusals)
{
    /* a closed tetrahedron: every one of its 6 edges is shared by two faces */
    const int32_t tet[12] = { 0, 2, 1, 0, 1, 3, 0, 3, 2, 1, 2, 3 };
    int32_t h[4 * 7];
    CHECK_EQ(wb__bend_hinges(tet, 4, h), 6);
    /* two triangles sharing one edge, wound alike: one hinge in the first's winding */
    const int32_t pair[6] = { 0, 1, 2, 1, 0, 3 };
    REQUIRE(wb__bend_hinges(pair, 2, h) == 1);
    CHECK(h[0] == 0 && h[1] == 1 && h[2] == 2 && h[3] == 3);

    wb_world_def d = wb_world_default_def();
    wb_world *w = wb_world_create(&d);
    REQUIRE(w);
    const wb_real x[5][3] = { { 0, 0, 0 }, { 1, 0, 0 }, { 0.5, 0, 1 }, { 0.5, 0, -1 }, { 2, 0, 0 } };
    for (int i = 0; i < 5; i++) wb_particle_add(w, x[i], NULL, 1, 0);
    wb_bend_def bd = wb_bend_default_def();
    wb_status st;
    const int32_t same[4] = { 0, 1, 2, 2 }, line[4] = { 0, 1, 2, 4 }, out[4] = { 0, 1, 2, 9 }, ok[4] = { 0, 1, 2, 3 };
    wb_bend_add(w, same, &bd, &st);
    CHECK(st == WB_ERR_ARG);
    CHECK_HAS(wb_last_error(), "distinct");
    wb_bend_add(w, line, &bd, &st); /* the wing 4 lies on the hinge's line */
    CHECK(st == WB_ERR_ARG);
    CHECK_HAS(wb_last_error(), "degenerate");
    wb_bend_add(w, out, &bd, &st);
    CHECK(st == WB_ERR_ARG);
    bd.rest = 4;
    wb_bend_add(w, ok, &bd, &st);
    CHECK(st == WB_ERR_ARG);
    CHECK_HAS(wb_last_error(), "rest");
    CHECK_EQ(wb_bend_count(w), 0);
    bd.rest = NAN;
    wb_bend_id id = wb_bend_add(w, ok, &bd, &st);
    CHECK(st == WB_OK);
    CHECK_NEAR(wb_bend_rest(w, id), 0, 1e-15); /* flat as made */
    wb_world_destroy(w);
}
