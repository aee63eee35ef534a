/* test_contact.c: the broad phase of particle-particle contacts (white-box: core.h) and
 * the group rules.
 *
 * The broad phase must report every pair i < j with |x_i - x_j| < reach_i + reach_j
 * exactly once and no other pair: checked against the O(n^2) loop on random input
 * (uniform, clustered, with a few particles left out by a negative reach), so a cell
 * size or a neighbourhood one cell short, or a hash collision counted twice, fails. */
#include <stdlib.h>

#include "core/core.h"
#include "test.h"

/* a small LCG: the same input on every machine */
static uint64_t rng = 88172645463325252ull;
static double urand(void)
{
    rng = rng * 6364136223846793005ull + 1442695040888963407ull;
    return (double)(rng >> 11) / 9007199254740992.0;
}

static int keep_all(void *ud, int32_t i, int32_t j) { (void)ud; (void)i; (void)j; return 1; }

/* check c's pairs against brute force; returns the number of pairs */
static int32_t check_against_brute(const wb_real *x, const wb_real *reach, int32_t n)
{
    wb_contacts c;
    memset(&c, 0, sizeof c);
    int32_t got = wb__broadphase(&c, x, reach, n, keep_all, NULL);
    CHECK(got >= 0);
    /* a mark per pair: found once, and only pairs within reach */
    uint8_t *seen = calloc((size_t)n * (size_t)n, 1);
    if (got < 0 || !seen) { CHECK(seen); free(seen); return -1; }
    int twice = 0, wrong = 0, order = 0;
    for (int32_t k = 0; k < c.n; k++) {
        const int32_t i = c.ij[2 * k], j = c.ij[2 * k + 1];
        if (!(i < j)) { order++; continue; }
        if (seen[(size_t)i * n + j]++) twice++;
        wb_real d[3];
        v3_sub(d, &x[3 * j], &x[3 * i]);
        if (!(reach[i] >= 0 && reach[j] >= 0 && v3_len(d) < reach[i] + reach[j])) wrong++;
    }
    int missed = 0;
    int32_t want = 0;
    for (int32_t i = 0; i < n; i++)
        for (int32_t j = i + 1; j < n; j++) {
            if (reach[i] < 0 || reach[j] < 0) continue;
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
    free(seen);
    free(c.ij);
    free(c.cell_start);
    free(c.cell_ids);
    free(c.stamp);
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
        int32_t pairs = check_against_brute(x, reach, N);
        CHECK(pairs > 20); /* the input has pairs to find */
    }
    free(x);
    free(reach);
}

TEST(contact_broadphase_huge_and_clustered_input)
{
    /* all particles in one spot (every bucket collision there is), and coordinates far
     * from the origin where cell indices are clamped */
    enum { N = 300 };
    wb_real x[3 * N], reach[N];
    for (int i = 0; i < N; i++) {
        for (int a = 0; a < 3; a++) x[3 * i + a] = (i % 2 ? 1e290 : 0) + urand() * 1e-3;
        reach[i] = 1e-3;
    }
    check_against_brute(x, reach, N);
    for (int i = 0; i < N; i++) reach[i] = 0;
    CHECK_EQ(check_against_brute(x, reach, N), 0);
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
    wb_world_step(w);
    /* the pair 0-10 is a candidate (its stretched link yanks particle 10 away within
     * the step, faster than an old overlap is pushed out, so the contact count of the
     * last substep says nothing); the pairs listed: never two linked neighbours */
    int found = 0;
    for (int32_t k = 0; k < w->k.pc.n; k++) {
        const int32_t i = w->k.pc.ij[2 * k], j = w->k.pc.ij[2 * k + 1];
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
    for (int32_t k = 0; k < w->k.pc.n; k++) {
        const int32_t i = w->k.pc.ij[2 * k], j = w->k.pc.ij[2 * k + 1];
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
