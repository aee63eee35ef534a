/* test_contact.c: the broad phase of particle-particle contacts (white-box: core.h) and
 * the group rules.
 *
 * The broad phase must report every pair i < j with |x_i - x_j| < reach_i + reach_j
 * exactly once and no other pair (nor two of one body's skip key): checked against the
 * O(n^2) loop on random input (uniform, clustered, huge and sparse, bodies in a heap,
 * mixed radii, a few very fast particles, particles left out by a negative reach), so a
 * search range one cell short, a body culled too eagerly, or a pair found from both
 * ends fails; and the list must be the same, in the same order, for 1, 2 and 3 threads. */
#include <stdlib.h>

#include "core/core.h"
#include "core/broadphase.h"
#include "core/tricontact.h"
#include "test.h"

/* a small LCG: the same input on every machine */
static uint64_t rng = 88172645463325252ull;
static double urand(void)
{
    rng = rng * 6364136223846793005ull + 1442695040888963407ull;
    return (double)(rng >> 11) / 9007199254740992.0;
}

static int keep_all(void *ud, int32_t i, int32_t j) { (void)ud; (void)i; (void)j; return 1; }

/* the broad phase's list for the given thread count (c zeroed; the caller frees) */
static int32_t broad(wb_contacts *c, const wb_real *x, const wb_real *reach, const int32_t *skip, int32_t n,
                     int threads)
{
    memset(c, 0, sizeof *c);
    wb_pool *pool = wb__pool_create(threads);
    const int32_t r = wb__broadphase(c, x, reach, skip, n, pool, keep_all, NULL);
    wb__pool_destroy(pool);
    return r;
}

static void broad_free(wb_contacts *c)
{
    wb__broadphase_free(c);
    free(c->ij);
}

/* check the broad phase's pairs against brute force, and the same list (order too)
 * with 1, 2 and 3 threads; returns the number of pairs */
static int32_t check_against_brute(const wb_real *x, const wb_real *reach, const int32_t *skip, int32_t n)
{
    wb_contacts c;
    int32_t got = broad(&c, x, reach, skip, n, 1);
    CHECK(got >= 0);
    /* a mark per pair: found once, and only pairs within reach */
    uint8_t *seen = calloc((size_t)n * (size_t)n, 1);
    if (got < 0 || !seen) { CHECK(seen); free(seen); broad_free(&c); return -1; }
    int twice = 0, wrong = 0, order = 0;
    for (int32_t k = 0; k < c.n; k++) {
        const int32_t i = c.ij[2 * k], j = c.ij[2 * k + 1];
        if (!(i < j)) { order++; continue; }
        if (seen[(size_t)i * n + j]++) twice++;
        wb_real d[3];
        v3_sub(d, &x[3 * j], &x[3 * i]);
        if (!(reach[i] >= 0 && reach[j] >= 0 && v3_len(d) < reach[i] + reach[j])) wrong++;
        if (skip && skip[i] != 0 && skip[i] == skip[j]) wrong++;
    }
    int missed = 0;
    int32_t want = 0;
    for (int32_t i = 0; i < n; i++)
        for (int32_t j = i + 1; j < n; j++) {
            if (reach[i] < 0 || reach[j] < 0) continue;
            if (skip && skip[i] != 0 && skip[i] == skip[j]) continue;
            wb_real d[3];
            v3_sub(d, &x[3 * j], &x[3 * i]);
            const wb_real r = reach[i] + reach[j];
            if (v3_dot(d, d) >= r * r) continue;
            want++;
            if (!seen[(size_t)i * n + j]) missed++;
        }
    CHECK_EQ(order, 0);
    CHECK_EQ(twice, 0);
    CHECK_EQ(wrong, 0);
    CHECK_EQ(missed, 0);
    CHECK_EQ(c.n, want);
    /* any thread count: the very same list, in the same order */
    for (int threads = 2; threads <= 3; threads++) {
        wb_contacts t;
        CHECK_EQ(broad(&t, x, reach, skip, n, threads), c.n);
        CHECK(t.n == c.n && (c.n == 0 || memcmp(t.ij, c.ij, sizeof *c.ij * 2 * (size_t)c.n) == 0));
        broad_free(&t);
    }
    free(seen);
    broad_free(&c);
    return want;
}

TEST(contact_broadphase_matches_brute_force)
{
    enum { N = 1500 };
    wb_real *x = malloc(sizeof(wb_real) * 3 * N), *reach = malloc(sizeof(wb_real) * N);
    REQUIRE(x && reach);
    for (int round = 0; round < 6; round++) {
        for (int i = 0; i < N; i++) {
            for (int a = 0; a < 3; a++) x[3 * i + a] = (urand() - 0.5) * (round < 3 ? 4 : 1);
            /* radii from tiny to large, a few left out */
            reach[i] = round % 3 == 0 ? 0.05 : round % 3 == 1 ? 0.2 * urand() * urand() : 0.01 + 0.3 * urand();
            if (urand() < 0.05) reach[i] = -1;
        }
        int32_t pairs = check_against_brute(x, reach, NULL, N);
        CHECK(pairs > 20); /* the input has pairs to find */
    }
    free(x);
    free(reach);
}

/* bodies as the world makes them: runs of particles with one skip key (a body without
 * self-collision), self-colliding bodies and loose particles (key 0), lattice-like blocks
 * in a heap so that bodies touch, mixed radii, and a few very fast particles whose reach
 * is many times everyone else's */
static void heap(wb_real *x, wb_real *reach, int32_t *skip, int32_t n, int bodies, int fast, double spread)
{
    const int32_t per = n / bodies;
    for (int32_t i = 0; i < n; i++) {
        const int32_t b = i / per < bodies ? i / per : bodies - 1, k = i - b * per;
        /* a body: a jittered 4 x 4 x 4 block (spacing 0.1) somewhere in the heap */
        const double cx = (b % 5) * 0.35 * spread, cy = ((b / 5) % 5) * 0.35 * spread, cz = (b / 25) * 0.35 * spread;
        x[3 * i] = cx + (k % 4) * 0.1 + 0.02 * urand();
        x[3 * i + 1] = cy + ((k / 4) % 4) * 0.1 + 0.02 * urand();
        x[3 * i + 2] = cz + ((k / 16) % 4) * 0.1 + 0.02 * urand() + (k / 64) * 0.01;
        reach[i] = (b % 3 == 0 ? 0.02 : 0.035) * (1 + 0.3 * urand());
        skip[i] = b % 4 == 3 ? 0 : b + 1; /* every fourth body self-collides */
    }
    for (int32_t i = n - 10; i < n; i++) skip[i] = 0; /* loose particles */
    for (int f = 0; f < fast; f++) {
        const int32_t i = (int32_t)(urand() * n);
        reach[i] = 0.3 + urand(); /* very fast: reach over several bodies */
    }
}

TEST(contact_broadphase_bodies_fast_particles_and_threads)
{
    enum { N = 2000 };
    wb_real *x = malloc(sizeof(wb_real) * 3 * N), *reach = malloc(sizeof(wb_real) * N);
    int32_t *skip = malloc(sizeof(int32_t) * N);
    REQUIRE(x && reach && skip);
    const struct { int bodies, fast; double spread; } cases[] = {
        { 31, 0, 1.0 },   /* touching bodies */
        { 31, 4, 1.0 },   /* and a few very fast particles */
        { 31, 3, 1.6 },   /* bodies apart: most are culled whole */
        { 400, 2, 0.5 },  /* many small bodies (more runs than the culling takes) */
        { 100, 1, 0.3 },  /* 100 bodies of 20 in a dense heap: each overlaps many */
        { 1, 0, 1.0 },    /* one body and a few loose particles */
    };
    for (size_t k = 0; k < sizeof cases / sizeof cases[0]; k++) {
        heap(x, reach, skip, N, cases[k].bodies, cases[k].fast, cases[k].spread);
        const int32_t pairs = check_against_brute(x, reach, skip, N);
        CHECK(pairs > 10);
        /* without the keys: the same input, every pair */
        CHECK(check_against_brute(x, reach, NULL, N) > pairs);
    }
    /* a long body (a row of 400 along x) touched by 60 small bodies of 2 along it: its
     * overlaps with them are 60 boxes apart from each other */
    for (int32_t i = 0; i < 400; i++) {
        v3_set(&x[3 * i], 0.01 * i, 0, 0);
        reach[i] = 0.004;
        skip[i] = 1;
    }
    for (int32_t k = 0; k < 60; k++)
        for (int32_t h = 0; h < 2; h++) {
            const int32_t i = 400 + 2 * k + h;
            v3_set(&x[3 * i], 0.065 * k + 0.003 * h, 0.006, 0.002 * urand());
            reach[i] = 0.004;
            skip[i] = 2 + k;
        }
    CHECK(check_against_brute(x, reach, skip, 520) >= 60);
    free(x);
    free(reach);
    free(skip);
}

TEST(contact_broadphase_huge_and_clustered_input)
{
    /* all particles in one spot (every particle in one cell), and coordinates far from
     * the origin where cell indices are clamped and the grid wraps around */
    enum { N = 300 };
    wb_real x[3 * N], reach[N];
    for (int i = 0; i < N; i++) {
        for (int a = 0; a < 3; a++) x[3 * i + a] = (i % 2 ? 1e290 : 0) + urand() * 1e-3;
        reach[i] = 1e-3;
    }
    check_against_brute(x, reach, NULL, N);
    for (int i = 0; i < N; i++) reach[i] = 0;
    CHECK_EQ(check_against_brute(x, reach, NULL, N), 0);
    /* sparse: a few clusters far apart along one axis and scattered over 1e6 m (a grid
     * of the natural size would have 1e21 cells), and an infinite position left out */
    for (int i = 0; i < N; i++) {
        const double base = i % 3 == 0 ? 0 : i % 3 == 1 ? 1e6 : -3e5 * urand();
        for (int a = 0; a < 3; a++) x[3 * i + a] = (a == 0 ? base : 0) + urand() * 0.05;
        reach[i] = 0.01 + 0.01 * urand();
    }
    x[3 * 7 + 1] = INFINITY;
    CHECK(check_against_brute(x, reach, NULL, N) > 10);
    /* pairs scattered over a 1e5 m cube (the grid wraps around: its cells hold far
     * particles alike), with a few particles whose search crosses the wrap (reach of
     * a few cells) or spans every cell of an axis */
    for (int i = 0; i < N; i += 2) {
        for (int a = 0; a < 3; a++) {
            x[3 * i + a] = 1e5 * urand();
            x[3 * (i + 1) + a] = x[3 * i + a] + 1e-3 * urand();
        }
        reach[i] = reach[i + 1] = 1e-3;
    }
    for (int i = 0; i < 40; i++) reach[i] = i < 30 ? 300 + 1500 * urand() : 1e5;
    CHECK(check_against_brute(x, reach, NULL, N) > 150);
}

TEST(contact_builders_get_own_groups)
{
    wb_world_def d = wb_world_default_def();
    wb_world *w = wb_world_create(&d);
    REQUIRE(w);
    wb_real p[3] = { 0, 0, 0 };
    int32_t loose = wb_particle_add(w, p, NULL, 1, 0.1);
    CHECK_EQ(wb_particle_group(w, loose), 0);
    wb_cloth_def c = wb_cloth_default_def();
    wb_lattice_def l = wb_lattice_default_def();
    wb_body a, b;
    REQUIRE(wb_cloth(w, &c, &a) == WB_OK);
    REQUIRE(wb_lattice(w, &l, &b) == WB_OK);
    CHECK(a.group > 0 && b.group > 0 && a.group != b.group);
    CHECK_EQ(wb_particle_group(w, a.first), a.group);
    CHECK_EQ(wb_particle_group(w, b.first + b.count - 1), b.group);
    CHECK(wb_particle_collides(w, a.first));
    CHECK(!wb_group_self_collide(w, a.group));
    wb_group_set_self_collide(w, a.group, true);
    CHECK(wb_group_self_collide(w, a.group));
    CHECK(!wb_group_self_collide(w, b.group));
    CHECK_EQ(wb_group_new(w), b.group + 1);
    wb_world_destroy(w);
}

TEST(contact_self_collision_skips_rest_neighbours)
{
    /* a rope folded back onto itself: its linked neighbours and the pairs closer than
     * 2 r as built never collide; the far ones do when it self-collides */
    wb_world_def d = wb_world_default_def();
    v3_set(d.gravity, 0, 0, 0);
    wb_world *w = wb_world_create(&d);
    REQUIRE(w);
    wb_rope_def r = wb_rope_default_def();
    r.segments = 10;
    r.radius = 0.06; /* spacing 0.1: next-but-one (0.2 apart) is >= 2 r, next is linked */
    wb_body b;
    REQUIRE(wb_rope(w, &r, &b) == WB_OK);
    /* bring particle 10 onto particle 0 */
    wb_real p0[3];
    wb_particle_position(w, b.first, p0);
    p0[1] += 0.05;
    wb_particle_set_position(w, b.first + 10, p0);
    wb_world_step(w);
    CHECK_EQ(wb_world_stats(w).particle_contacts, 0); /* one body, no self-collision */
    wb_group_set_self_collide(w, b.group, true);
    wb_particle_set_position(w, b.first + 10, p0);
    /* the frame's list as the step makes it: the pair 0-10 is a candidate (within the
     * step its stretched link yanks particle 10 away, faster than an old overlap is
     * pushed out, and farther than its reach: the list is made again, so neither the
     * last substep's contacts nor the list after the step say anything); the pairs
     * listed: never two linked neighbours */
    wb__contacts_begin(w);
    int found = 0;
    for (int32_t k = 0; k < w->k.pc->n; k++) {
        const int32_t i = w->k.pc->ij[2 * k], j = w->k.pc->ij[2 * k + 1];
        CHECK(j - i >= 2);
        if (i == b.first && j == b.first + 10) found = 1;
    }
    CHECK(found);
    wb_world_destroy(w);

    /* a thinner rope (r = 0.04: as built, neighbours 0.1 apart are outside 2 r) with a
     * link squeezed to 0.05: still never a candidate, being linked */
    w = wb_world_create(&d);
    REQUIRE(w);
    r.radius = 0.04;
    REQUIRE(wb_rope(w, &r, &b) == WB_OK);
    wb_group_set_self_collide(w, b.group, true);
    wb_real p1[3];
    wb_particle_position(w, b.first, p1);
    p1[0] += 0.05;
    wb_particle_set_position(w, b.first + 1, p1);
    wb_world_step(w);
    for (int32_t k = 0; k < w->k.pc->n; k++) {
        const int32_t i = w->k.pc->ij[2 * k], j = w->k.pc->ij[2 * k + 1];
        CHECK(j - i >= 2);
    }
    wb_world_destroy(w);

    /* a fat rope (r = 0.12, next-but-one 0.2 apart, not linked, inside 2 r as built):
     * self-colliding and straight, it has no contact and does not move */
    w = wb_world_create(&d);
    REQUIRE(w);
    r.radius = 0.12;
    REQUIRE(wb_rope(w, &r, &b) == WB_OK);
    wb_group_set_self_collide(w, b.group, true);
    const uint64_t h0 = wb_world_hash(w);
    wb_world_step(w);
    CHECK_EQ(wb_world_stats(w).particle_contacts, 0);
    wb_real q[3];
    wb_particle_position(w, b.first + 2, q);
    CHECK_NEAR(q[0], 0.2, 1e-12);
    CHECK(wb_world_hash(w) != h0); /* (time moved on) */
    wb_world_destroy(w);
}

TEST(contact_clone_keeps_groups)
{
    wb_world_def d = wb_world_default_def();
    d.contacts = false;
    wb_world *w = wb_world_create(&d);
    REQUIRE(w);
    wb_lattice_def l = wb_lattice_default_def();
    wb_body b;
    REQUIRE(wb_lattice(w, &l, &b) == WB_OK);
    wb_group_set_self_collide(w, b.group, true);
    wb_particle_set_friction(w, b.first, 0.7);
    wb_world *c = wb_world_clone(w);
    REQUIRE(c);
    CHECK_EQ(wb_world_hash(c), wb_world_hash(w));
    CHECK_EQ(wb_particle_group(c, b.first), b.group);
    CHECK(wb_group_self_collide(c, b.group));
    CHECK_EQ(wb_particle_friction(c, b.first), 0.7);
    CHECK(!wb_world_get_def(c).contacts);
    /* the hash sees the contact settings */
    wb_particle_set_friction(c, b.first, 0.5);
    CHECK(wb_world_hash(c) != wb_world_hash(w));
    wb_world_destroy(c);
    wb_world_destroy(w);
}
