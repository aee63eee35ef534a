/* test_bend_simd.c: the AVX2 path of the bend projection (bend.c) gives the same bits
 * as the scalar loop: the same scenes stepped once with the vector path and once with
 * the scalar loop forced, every position, multiplier and broken flag compared bit for
 * bit after every frame; and 1 vs 2 threads (batches split between them) give the same
 * hash with the vector path on.
 * The scenes reach every lane the vector path masks or blends: a cloth with bends
 * (flat at rest, pinned corners: w = 0 particles shared inside a batch), random bends
 * between loose particles (random rests, near +-pi too, where the angle wraps), bends
 * whose four particles are all pinned (den = 0), degenerate ones (a wing on the hinge
 * line, a zero-length hinge), zero compliance, compliance that overflows over h^2
 * (isinf(at)), damping and infinite damping (isinf(gamma)), and bends that break by
 * torque during the run (skipped from then on). */
#include <float.h>
#include <stdint.h>
#include <stdlib.h>

#include "core/core.h"
#include "core/bend.h"
#include "test.h"

int wb__bend_simd(int on); /* bend.c's internal switch */

/* a reproducible pseudo-random number in [0, 1) */
static double rnd(uint64_t *s)
{
    *s = *s * 6364136223846793005ull + 1442695040888963407ull;
    return (double)(*s >> 11) / 9007199254740992.0;
}

static wb_world *scene(int threads, int damped)
{
    wb_world_def d = wb_world_default_def();
    d.threads = threads;
    d.substeps = 4;
    wb_world *w = wb_world_create(&d);
    if (!w) return NULL;
    wb_cloth_def c = wb_cloth_default_def();
    c.origin[0] = -1; c.origin[1] = 1; c.origin[2] = -1;
    c.size[0] = c.size[1] = 2;
    c.res[0] = c.res[1] = 40;
    c.shear = true;
    c.bend = 1e-2;
    wb_body b;
    if (wb_cloth(w, &c, &b) != WB_OK) { wb_world_destroy(w); return NULL; }
    wb_particle_pin(w, b.first, NULL);
    wb_particle_pin(w, b.first + c.res[0] - 1, NULL);
    /* loose particles in a cube, the last four pinned */
    uint64_t seed = 12345;
    enum { NL = 300 };
    int32_t q[NL];
    for (int i = 0; i < NL; i++) {
        const wb_real x[3] = { 3 + rnd(&seed), rnd(&seed), rnd(&seed) }, v0[3] = { 0, 0, 0 };
        q[i] = wb_particle_add(w, x, v0, 0.5 + rnd(&seed), 0.01);
    }
    for (int i = NL - 4; i < NL; i++) wb_particle_pin(w, q[i], NULL);
    int bad = 0;
    wb_status st;
    const wb_real comp[] = {
        0, 1e-3, 1, 100,
#ifdef WB_FLOAT
        1e37f, /* / h^2 = inf */
#else
        1e307, /* / h^2 = inf */
#endif
    };
#ifdef WB_FLOAT
    const wb_real huge = FLT_MAX;
#else
    const wb_real huge = DBL_MAX;
#endif
    const wb_real damp[] = { 0.5, 0.02, huge }; /* huge: gamma = inf */
    for (int k = 0; k < 900; k++) {
        int32_t p[4];
        for (int i = 0; i < 4; i++) {
            int again;
            do {
                p[i] = q[(int)(rnd(&seed) * (NL - 4))];
                again = 0;
                for (int j = 0; j < i; j++) again |= p[j] == p[i];
            } while (again);
        }
        wb_bend_def bd = wb_bend_default_def();
        bd.compliance = comp[k % 5];
        if (damped && k % 3 == 0) bd.damping = damp[(k / 3) % 3];
        if (k % 4 == 1) bd.rest = (wb_real)(3.14159265358979323846 * (2 * rnd(&seed) - 1));
        if (k % 17 == 0) bd.rest = (wb_real)3.14159265358979323846; /* folded: C wraps */
        if (k % 29 == 0) bd.break_torque = 1e-3;
        wb_bend_add(w, p, &bd, &st);
        bad |= st != WB_OK;
    }
    /* all four pinned: den = 0 */
    wb_bend_def bd = wb_bend_default_def();
    wb_bend_add(w, &q[NL - 4], &bd, &st);
    bad |= st != WB_OK;
    /* degenerate: a wing on the hinge line, and a zero-length hinge (rest given: no
     * angle to take); their own loose particles, which fall together and stay so */
    const wb_real line[4][3] = { { 6, 1, 0 }, { 7, 1, 0 }, { 6.5, 1, 0 }, { 6.5, 1.5, 0.5 } };
    const wb_real dot[4][3] = { { 8, 1, 0 }, { 8, 1, 0 }, { 8.5, 1, 0 }, { 8.5, 1.5, 0.5 } };
    for (int r = 0; r < 2; r++) {
        int32_t p[4];
        for (int i = 0; i < 4; i++) {
            const wb_real v0[3] = { 0, 0, 0 };
            p[i] = wb_particle_add(w, r ? dot[i] : line[i], v0, 1, 0.01);
        }
        bd.rest = 0.3;
        wb_bend_add(w, p, &bd, &st);
        bad |= st != WB_OK;
    }
    if (bad) { wb_world_destroy(w); return NULL; }
    return w;
}

/* whether any position, multiplier or broken flag differs in its bits */
static int differing(const wb_world *a, const wb_world *b)
{
    const int32_t n = wb_particle_count(a), nb = a->bend->n;
    if (n != wb_particle_count(b) || nb != b->bend->n) return 1;
    return memcmp(wb_particle_positions(a), wb_particle_positions(b), sizeof(wb_real) * 3 * (size_t)n) != 0 ||
           memcmp(a->bend->lambda, b->bend->lambda, sizeof(wb_real) * (size_t)nb) != 0 ||
           memcmp(a->bend->broken, b->bend->broken, (size_t)nb) != 0;
}

TEST(bend_simd_bit_identical_to_scalar)
{
    CHECK_SIMD_RUNS(wb__bend_simd(1));
    const int cases[][2] = { { 1, 0 }, { 1, 1 }, { 2, 1 } };
    for (size_t c = 0; c < sizeof cases / sizeof cases[0]; c++) {
        wb_world *v = scene(cases[c][0], cases[c][1]), *s = scene(cases[c][0], cases[c][1]);
        REQUIRE(v && s);
        int diff = 0;
        for (int f = 0; f < 30 && !diff; f++) {
            wb__bend_simd(1);
            CHECK_EQ(wb_world_step(v), WB_OK);
            wb__bend_simd(0);
            CHECK_EQ(wb_world_step(s), WB_OK);
            diff = differing(v, s);
            if (diff)
                test_fail(__FILE__, __LINE__, "case %zu: positions, multipliers or breaks differ after frame %d", c,
                          f + 1);
        }
        /* the scene reached what it is for: some bends broke, none of the loose ones blew up */
        int broken = 0;
        for (int32_t i = 0; i < v->bend->n; i++) broken += v->bend->broken[i];
        CHECK(broken > 0 && broken < v->bend->n / 10);
        CHECK_EQ(wb_world_warnings(v), 0);
        wb_world_destroy(v);
        wb_world_destroy(s);
    }
    wb__bend_simd(1);
}

/* the vector path on, 1 and 2 threads: the same hash every frame */
TEST(bend_simd_threads_identical)
{
    wb__bend_simd(1);
    wb_world *a = scene(1, 1), *b = scene(2, 1);
    REQUIRE(a && b);
    int32_t big = 0;
    for (int f = 0; f < 20; f++) {
        CHECK_EQ(wb_world_step(a), WB_OK);
        CHECK_EQ(wb_world_step(b), WB_OK);
        CHECK_EQ(wb_world_hash(a), wb_world_hash(b));
    }
    for (int32_t c = 0; c < b->bend->bt.serial_start; c++)
        if (b->bend->bt.colour_start[c + 1] - b->bend->bt.colour_start[c] >= 256) big++;
    CHECK(big > 0); /* batches that the pool splits */
    wb_world_destroy(a);
    wb_world_destroy(b);
}
