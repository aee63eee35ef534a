/* test_tet_simd.c: the AVX2 path of the Neo-Hookean projection (tet.c, four tets at a
 * time) gives the scalar loop's bits, and so does a batch cut into chunks by 2 threads.
 * The scene: a lattice block (shared corners, many batches, pinned corners) and 480 loose
 * tets of random rest shape (slivers among them) deformed every few frames the same way
 * in every world: stretched and sheared, inverted (a corner mirrored through the opposite
 * face), flat (a corner on that face), crushed to a point (no deviatoric direction: the
 * hydrostatic solve alone), with 1 to 4 corners pinned (all four: an immovable tet), with
 * young 1e-300 (compliance / h^2 overflows to inf) and 1e14; and packed compliances set
 * to 0 and inf by hand. Every position and multiplier is compared bit for bit after each
 * frame. The tets of a hub that need a serial batch are there too. */
#include <math.h>
#include <stdint.h>
#include <string.h>

#include "core/core.h"
#include "core/tet.h"
#include "test.h"

int wb__tet_simd(int on); /* tet.c's internal switch */

static uint64_t rng_state;
static double rnd(void) /* [0, 1) */
{
    rng_state = rng_state * 6364136223846793005ull + 1442695040888963407ull;
    return (double)(rng_state >> 11) * (1.0 / 9007199254740992.0);
}

enum { LOOSE = 480 };

static wb_world *scene(int threads)
{
    wb_world_def d = wb_world_default_def();
    d.threads = threads;
    d.substeps = 3;
    d.contacts = false;
    wb_world *w = wb_world_create(&d);
    if (!w) return NULL;
    wb_lattice_def l = wb_lattice_default_def();
    l.min[0] = -0.5; l.min[1] = 0.5; l.min[2] = -0.5;
    l.max[0] = 0.5; l.max[1] = 1.5; l.max[2] = 0.5;
    l.res[0] = l.res[1] = l.res[2] = 7;
    l.mass = 10;
    l.tets = true;
    l.young = 2e4;
    l.poisson = 0.3;
    wb_body b;
    if (wb_lattice(w, &l, &b) != WB_OK) { wb_world_destroy(w); return NULL; }
    for (int32_t i = 0; i < 7; i++) wb_particle_pin(w, b.first + i, NULL); /* an edge of the top */
    /* a hub in 80 tets: 64 colours take 64 of them, the rest share it in the serial batch
     * (which the vector lanes must leave alone: they would all read the hub before any
     * wrote it) */
    const wb_real at[3] = { -3, 1, 0 };
    const int32_t hub = wb_particle_add(w, at, NULL, 1, 0.01);
    for (int t = 0; t < 80; t++) {
        const double phi = t * 2.399963229728653, y = 1 - 2 * (t + 0.5) / 80, r = sqrt(1 - y * y);
        int32_t p[4] = { hub };
        for (int k = 1; k < 4; k++) {
            const wb_real x[3] = { at[0] + r * cos(phi) + 0.05 * (k == 2), at[1] + y + 0.05 * (k == 3),
                                   at[2] + r * sin(phi) + 0.03 * (k == 3) };
            p[k] = wb_particle_add(w, x, NULL, 0.01, 0.01);
        }
        const wb_tet_def td = { 10, 0.3, 0, 0 };
        if (wb_tet_add(w, p, &td) < 0) { wb_world_destroy(w); return NULL; }
        const wb_real *q = &wb_particle_positions(w)[3 * p[1]], s = 1 + 0.2 * sin(7 * t);
        const wb_real x[3] = { at[0] + (q[0] - at[0]) * s, at[1] + (q[1] - at[1]) * s, at[2] + (q[2] - at[2]) * s };
        wb_particle_set_position(w, p[1], x); /* out of shape: every tet pulls or pushes the hub */
    }
    rng_state = 12345;
    for (int t = 0; t < LOOSE; t++) {
        const wb_real cx = 3 + 2 * (t % 20), cy = 2 * (t / 20), s = 0.05 + 0.3 * rnd();
        int32_t p[4];
        for (int k = 0; k < 4; k++) {
            wb_real x[3] = { cx + s * rnd(), cy + s * rnd(), s * rnd() };
            if (k == 3 && t % 5 == 0) { /* a sliver: the 4th corner near the face of the others */
                const wb_real *a = wb_particle_positions(w);
                for (int r = 0; r < 3; r++)
                    x[r] = (a[3 * p[0] + r] + a[3 * p[1] + r] + a[3 * p[2] + r]) / 3 + 1e-4 * s * rnd();
            }
            p[k] = wb_particle_add(w, x, NULL, 0.01 + rnd(), 0.01);
        }
        wb_tet_def td = { 1e3 * pow(10, 5 * rnd()), 0.49 * rnd(), 0, 0 };
        if (t % 37 == 3) td.young = 1e-300; /* compliance / h^2 = inf */
        if (t % 41 == 5) td.young = 1e14;
        if (wb_tet_add(w, p, &td) < 0) { wb_world_destroy(w); return NULL; }
        const int pins = t % 9 == 1 ? 1 + t % 4 : 0; /* 1..4 corners */
        for (int k = 0; k < pins; k++) wb_particle_pin(w, p[k], NULL);
    }
    return w;
}

/* the loose tets pushed out of shape, the same way in every world for one seed */
static void deform(wb_world *w, uint64_t seed)
{
    rng_state = seed;
    const int32_t first = wb_tet_count(w) - LOOSE;
    for (int32_t t = 0; t < LOOSE; t++) {
        int32_t p[4];
        wb_tet_particles(w, first + t, p);
        const wb_real *x = wb_particle_positions(w);
        wb_real c[4][3];
        for (int k = 0; k < 4; k++) memcpy(c[k], &x[3 * p[k]], sizeof c[k]);
        const int kind = (int)(rnd() * 5);
        wb_real e1[3], e2[3], n[3], d[3];
        v3_sub(e1, c[1], c[0]);
        v3_sub(e2, c[2], c[0]);
        v3_cross(n, e1, e2);
        v3_sub(d, c[3], c[0]);
        const wb_real nn = v3_dot(n, n), h = nn > 0 ? v3_dot(d, n) / nn : 0;
        if (kind == 0) /* stretched and sheared */
            for (int k = 0; k < 4; k++)
                for (int r = 0; r < 3; r++) c[k][r] += 0.3 * (rnd() - 0.5) * (1 + c[k][(r + 1) % 3] - c[0][(r + 1) % 3]);
        else if (kind == 1) /* inverted: corner 3 mirrored through the face 0 1 2 */
            v3_madd(c[3], n, -2 * h);
        else if (kind == 2) /* flat */
            v3_madd(c[3], n, -h);
        else if (kind == 3) /* crushed to a point */
            for (int k = 1; k < 4; k++) memcpy(c[k], c[0], sizeof c[k]);
        for (int k = 0; k < 4; k++)
            if (!wb_particle_pinned(w, p[k])) wb_particle_set_position(w, p[k], c[k]);
    }
}

/* packed compliances of 0 and inf (by hand: a stiffness no material reaches), in lanes
 * of the loose tets' batch */
static void poke(wb_world *w)
{
    wb_neos *v = w->neo;
    for (int32_t j = 5; j < v->n; j += 53) {
        wb_real *pd = &v->pd[12 * j];
        const int kind = (int)(j % 4);
        pd[9] = kind == 0 ? 0 : kind == 1 ? INFINITY : pd[9];
        pd[10] = kind == 2 ? 0 : kind == 3 ? INFINITY : kind == 0 ? 0 : pd[10];
    }
}

/* whether any position or multiplier differs in its bits */
static int differing(const wb_world *a, const wb_world *b)
{
    const int32_t n = wb_particle_count(a), nt = a->neo->n;
    if (n != wb_particle_count(b) || nt != b->neo->n) return 1;
    return memcmp(wb_particle_positions(a), wb_particle_positions(b), sizeof(wb_real) * 3 * (size_t)n) != 0 ||
           memcmp(a->neo->ld, b->neo->ld, sizeof(wb_real) * (size_t)nt) != 0 ||
           memcmp(a->neo->lh, b->neo->lh, sizeof(wb_real) * (size_t)nt) != 0;
}

/* run worlds side by side, each with the vector path on or off; 1 when all agree */
static int same_bits(wb_world **w, const int *simd, int nw, int frames)
{
    for (int f = 0; f < frames; f++) {
        for (int i = 0; i < nw; i++) {
            if (f % 6 == 0) deform(w[i], 1000 + (uint64_t)f);
            wb__tet_simd(simd[i]);
            CHECK_EQ(wb_world_step(w[i]), WB_OK);
            if (f == 0) poke(w[i]); /* after the first step packed them (kept: h does not change) */
        }
        for (int i = 1; i < nw; i++)
            if (differing(w[0], w[i])) {
                test_fail(__FILE__, __LINE__, "world %d differs from world 0 after frame %d", i, f + 1);
                return 0;
            }
    }
    return 1;
}

TEST(tet_simd_bit_identical_to_scalar)
{
    CHECK_SIMD_RUNS(wb__tet_simd(1));
    wb_world *w[2] = { scene(1), scene(1) };
    REQUIRE(w[0] && w[1]);
    const int simd[2] = { 1, 0 };
    CHECK(same_bits(w, simd, 2, 24));
    /* the scene reached what it is for: the loose tets still move, nothing went NaN */
    const wb_real *x = wb_particle_positions(w[0]);
    int finite = 1;
    for (int32_t i = 0; i < 3 * wb_particle_count(w[0]); i++) finite &= isfinite(x[i]) != 0;
    CHECK(finite);
    for (int i = 0; i < 2; i++) wb_world_destroy(w[i]);
    wb__tet_simd(1);
}

/* a batch of 480 loose tets cut by 2 threads into chunks that are no multiple of 4:
 * lanes grouped differently, the same bits (and hash) as 1 thread */
TEST(tet_threads_1_and_2_same_bits)
{
    wb_world *w[3] = { scene(1), scene(2), scene(2) };
    REQUIRE(w[0] && w[1] && w[2]);
    const int simd[3] = { 1, 1, 0 };
    CHECK(same_bits(w, simd, 3, 18));
    CHECK(wb_world_hash(w[0]) == wb_world_hash(w[1]));
    CHECK(wb_world_hash(w[0]) == wb_world_hash(w[2]));
    for (int i = 0; i < 3; i++) wb_world_destroy(w[i]);
    wb__tet_simd(1);
}
