/* test_builders.c: cloth, rope and lattice builders. Counts are worked out by hand
 * in the comments; every constraint is checked to join the expected pair once with
 * its rest length equal to the pair's distance; a failing builder changes nothing. */
#include <stdint.h>
#include <stdlib.h>

#include "test.h"
#include "wobble.h"

static wb_world *new_world(void)
{
    wb_world_def d = wb_world_default_def();
    return wb_world_create(&d);
}

/* every live constraint joins a distinct pair of the body, no pair twice, rest = length
 * (each failure reported through CHECK) */
static void check_links(wb_world *w, wb_body body)
{
    const int32_t n = wb_distance_count(w);
    const int32_t np = body.count;
    unsigned char *seen = calloc((size_t)np * (size_t)np, 1);
    if (!seen) { CHECK(seen != NULL); return; }
    int dup = 0, outside = 0, restbad = 0;
    for (int32_t i = 0; i < n; i++) {
        wb_distance_id c = wb_distance_at(w, i);
        int32_t a, b;
        wb_distance_particles(w, c, &a, &b);
        a -= body.first;
        b -= body.first;
        if (a < 0 || b < 0 || a >= np || b >= np || a == b) { outside++; continue; }
        if (a > b) { int32_t t = a; a = b; b = t; }
        if (seen[(size_t)a * np + b]++) dup++;
        if (fabs(wb_distance_rest(w, c) - wb_distance_length(w, c)) > 1e-14) restbad++;
    }
    CHECK_EQ(outside, 0);
    CHECK_EQ(dup, 0);
    CHECK_EQ(restbad, 0);
    free(seen);
}

TEST(builder_cloth_counts)
{
    /* res {5,4}: 20 particles. Structural links: (5-1)*4 along x + 5*(4-1) along z =
     * 16 + 15 = 31. Shear: one diagonal per cell, (5-1)*(4-1) = 12. Bend (skip one):
     * (5-2)*4 + 5*(4-2) = 12 + 10 = 22. */
    struct { bool shear; wb_real bend; int32_t nd; } cases[] = {
        { false, -1, 31 }, { true, -1, 43 }, { false, 0, 53 }, { true, 1e-3, 65 },
    };
    for (size_t k = 0; k < sizeof cases / sizeof cases[0]; k++) {
        wb_world *w = new_world();
        REQUIRE(w);
        wb_cloth_def d = wb_cloth_default_def();
        d.res[0] = 5; d.res[1] = 4;
        d.size[0] = 2; d.size[1] = 3;
        d.origin[0] = 1; d.origin[1] = 2; d.origin[2] = 3;
        d.mass = 4;
        d.shear = cases[k].shear;
        d.bend_links = cases[k].bend;
        wb_body body = { -1, -1, -1 };
        CHECK_EQ(wb_cloth(w, &d, &body), WB_OK);
        CHECK_EQ(body.first, 0);
        CHECK_EQ(body.count, 20);
        CHECK_EQ(wb_particle_count(w), 20);
        CHECK_EQ(wb_distance_count(w), cases[k].nd);
        check_links(w, body);
        /* grid layout: particle i + j*nx at origin + (size_x i/(nx-1), 0, size_z j/(nz-1)) */
        for (int j = 0; j < 4; j++)
            for (int i = 0; i < 5; i++) {
                wb_real x[3];
                wb_particle_position(w, i + 5 * j, x);
                CHECK_NEAR(x[0], 1 + 2.0 * i / 4, 1e-15);
                CHECK_NEAR(x[1], 2, 0);
                CHECK_NEAR(x[2], 3 + 3.0 * j / 3, 1e-15);
                CHECK_NEAR(wb_particle_mass(w, i + 5 * j), 4.0 / 20, 1e-15);
            }
        /* bend links carry the bend compliance: links of length 2 cells along x are bend */
        if (cases[k].bend >= 0) {
            int nbend = 0;
            for (int32_t i = 0; i < wb_distance_count(w); i++) {
                wb_distance_id c = wb_distance_at(w, i);
                int32_t a, b;
                wb_distance_particles(w, c, &a, &b);
                if (abs(a - b) == 2 && a / 5 == b / 5) nbend++;
                if (abs(a - b) == 10) nbend++;
            }
            CHECK_EQ(nbend, 22);
        }
        wb_world_destroy(w);
    }

    /* the smallest cloth, {2,2}: 4 structural, 1 shear, no bend possible */
    wb_world *w = new_world();
    REQUIRE(w);
    wb_cloth_def d = wb_cloth_default_def();
    d.res[0] = d.res[1] = 2;
    d.bend_links = 0;
    wb_body body;
    CHECK_EQ(wb_cloth(w, &d, &body), WB_OK);
    CHECK_EQ(wb_particle_count(w), 4);
    CHECK_EQ(wb_distance_count(w), 5);
    /* a second body starts after the first */
    d.res[0] = 3; d.res[1] = 3; d.shear = false; d.bend_links = -1;
    CHECK_EQ(wb_cloth(w, &d, &body), WB_OK);
    CHECK_EQ(body.first, 4);
    CHECK_EQ(body.count, 9);
    CHECK_EQ(wb_distance_count(w), 5 + 12);
    wb_world_destroy(w);
}

TEST(builder_cloth_shear_alternates)
{
    /* the diagonals alternate: in a 3x3 cloth (4 cells) cells (0,0) and (1,1) use the
     * 0-(nx+1) diagonal, cells (1,0) and (0,1) the other one */
    wb_world *w = new_world();
    REQUIRE(w);
    wb_cloth_def d = wb_cloth_default_def();
    d.res[0] = d.res[1] = 3;
    wb_body body;
    CHECK_EQ(wb_cloth(w, &d, &body), WB_OK);
    int has[9][9] = { { 0 } };
    for (int32_t i = 0; i < wb_distance_count(w); i++) {
        int32_t a, b;
        wb_distance_particles(w, wb_distance_at(w, i), &a, &b);
        has[a][b] = has[b][a] = 1;
    }
    CHECK(has[0][4]);  /* cell (0,0): main diagonal */
    CHECK(has[2][4]);  /* cell (1,0): anti diagonal 2-4 */
    CHECK(has[4][6]);  /* cell (0,1): anti diagonal 4-6 */
    CHECK(has[4][8]);  /* cell (1,1): main diagonal */
    CHECK(!has[1][3] && !has[1][5] && !has[3][7] && !has[5][7]);
    wb_world_destroy(w);
}

TEST(builder_rope_counts)
{
    wb_world *w = new_world();
    REQUIRE(w);
    wb_rope_def d = wb_rope_default_def();
    d.from[0] = -1; d.from[1] = 2; d.from[2] = 0;
    d.to[0] = 3; d.to[1] = 2; d.to[2] = 4;
    d.segments = 7;
    d.mass = 2;
    wb_body body;
    CHECK_EQ(wb_rope(w, &d, &body), WB_OK);
    /* segments + 1 particles, one link per segment */
    CHECK_EQ(body.count, 8);
    CHECK_EQ(wb_particle_count(w), 8);
    CHECK_EQ(wb_distance_count(w), 7);
    check_links(w, body);
    for (int i = 0; i < 8; i++) {
        wb_real x[3];
        wb_particle_position(w, i, x);
        CHECK_NEAR(x[0], -1 + 4.0 * i / 7, 1e-15);
        CHECK_NEAR(x[2], 4.0 * i / 7, 1e-15);
        CHECK_NEAR(wb_particle_mass(w, i), 2.0 / 8, 1e-15);
    }
    for (int32_t i = 0; i < 7; i++) {
        int32_t a, b;
        wb_distance_particles(w, wb_distance_at(w, i), &a, &b);
        CHECK_EQ(b - a, 1);
        CHECK_NEAR(wb_distance_rest(w, wb_distance_at(w, i)), sqrt(32.0) / 7, 1e-14);
    }
    /* one segment: 2 particles, 1 link */
    d.segments = 1;
    CHECK_EQ(wb_rope(w, &d, &body), WB_OK);
    CHECK_EQ(body.first, 8);
    CHECK_EQ(wb_particle_count(w), 10);
    CHECK_EQ(wb_distance_count(w), 8);
    wb_world_destroy(w);
}

/* constraints of a lattice: every pair of grid neighbours in the 26-neighbourhood,
 * i.e. over the 13 offsets (dx,dy,dz) != 0 up to sign, prod(n_i - |d_i|) pairs each */
static int64_t lattice_pairs(int nx, int ny, int nz)
{
    int64_t total = 0;
    for (int dx = -1; dx <= 1; dx++)
        for (int dy = -1; dy <= 1; dy++)
            for (int dz = -1; dz <= 1; dz++) {
                if (dx == 0 && dy == 0 && dz == 0) continue;
                total += (int64_t)(nx - abs(dx)) * (ny - abs(dy)) * (nz - abs(dz));
            }
    return total / 2; /* each offset counted with both signs */
}

TEST(builder_lattice_counts)
{
    /* {2,2,2}: one cell, every pair of its 8 corners: C(8,2) = 28.
     * {3,2,2}: two cells sharing a face: 28 + 28 - 6 (the shared face's 4 corners,
     * C(4,2) = 6 pairs) = 50.
     * {3,3,3}: 3 axis offsets x 2*3*3 = 54, 6 face-diagonal offsets x 2*2*3 = 72,
     * 4 body-diagonal offsets x 2*2*2 = 32: 158. */
    struct { int r[3]; int32_t np, nd; } cases[] = {
        { { 2, 2, 2 }, 8, 28 }, { { 3, 2, 2 }, 12, 50 }, { { 3, 3, 3 }, 27, 158 }, { { 4, 3, 5 }, 60, 0 },
    };
    cases[3].nd = (int32_t)lattice_pairs(4, 3, 5);
    CHECK_EQ(lattice_pairs(2, 2, 2), 28);
    CHECK_EQ(lattice_pairs(3, 2, 2), 50);
    CHECK_EQ(lattice_pairs(3, 3, 3), 158);
    for (size_t k = 0; k < sizeof cases / sizeof cases[0]; k++) {
        wb_world *w = new_world();
        REQUIRE(w);
        wb_lattice_def d = wb_lattice_default_def();
        for (int i = 0; i < 3; i++) d.res[i] = cases[k].r[i];
        d.min[0] = -1; d.max[0] = 1; d.max[2] = 0.5;
        wb_body body;
        CHECK_EQ(wb_lattice(w, &d, &body), WB_OK);
        CHECK_EQ(body.count, cases[k].np);
        CHECK_EQ(wb_particle_count(w), cases[k].np);
        CHECK_EQ(wb_distance_count(w), cases[k].nd);
        check_links(w, body);
        /* and only neighbour pairs: every link is at most a cell's body diagonal long */
        const wb_real cx = 2.0 / (d.res[0] - 1), cy = 1.0 / (d.res[1] - 1), cz = 0.5 / (d.res[2] - 1);
        const wb_real diag = sqrt(cx * cx + cy * cy + cz * cz);
        int toolong = 0;
        for (int32_t i = 0; i < wb_distance_count(w); i++)
            if (wb_distance_rest(w, wb_distance_at(w, i)) > diag * (1 + 1e-12)) toolong++;
        CHECK_EQ(toolong, 0);
        wb_world_destroy(w);
    }
}

/* a failing builder leaves counts and hash as they were */
#define CHECK_UNCHANGED(w, np, nd, h)                  \
    do {                                               \
        CHECK_EQ(wb_particle_count(w), np);            \
        CHECK_EQ(wb_distance_count(w), nd);            \
        CHECK(wb_world_hash(w) == (h));                \
    } while (0)

TEST(builder_failure_changes_nothing)
{
    wb_world *w = new_world();
    REQUIRE(w);
    /* some content first, stepped so the state is not trivial */
    wb_rope_def r = wb_rope_default_def();
    wb_body body;
    REQUIRE(wb_rope(w, &r, &body) == WB_OK);
    wb_world_step(w);
    const int32_t np = wb_particle_count(w), nd = wb_distance_count(w);
    const uint64_t h = wb_world_hash(w);
    wb_body untouched = { 12345, 678, 9 };

    wb_cloth_def c = wb_cloth_default_def();
    c.res[0] = 1;
    CHECK_EQ(wb_cloth(w, &c, &untouched), WB_ERR_ARG);
    CHECK_HAS(wb_last_error(), "res");
    CHECK_UNCHANGED(w, np, nd, h);
    c = wb_cloth_default_def();
    c.res[0] = c.res[1] = 5000; /* 25e6 particles > WB_MAX_PARTICLES */
    CHECK_EQ(wb_cloth(w, &c, &untouched), WB_ERR_ARG);
    CHECK_HAS(wb_last_error(), "large");
    CHECK_UNCHANGED(w, np, nd, h);
    c = wb_cloth_default_def();
    c.res[0] = c.res[1] = 4096; /* exactly WB_MAX_PARTICLES: too many with the rope already there */
    CHECK(wb_cloth(w, &c, &untouched) < 0);
    CHECK_UNCHANGED(w, np, nd, h);
    c = wb_cloth_default_def();
    c.mass = 0;
    CHECK_EQ(wb_cloth(w, &c, &untouched), WB_ERR_ARG);
    CHECK_HAS(wb_last_error(), "mass");
    c = wb_cloth_default_def();
    c.size[1] = -1;
    CHECK_EQ(wb_cloth(w, &c, &untouched), WB_ERR_ARG);
    CHECK_HAS(wb_last_error(), "size");
    c = wb_cloth_default_def();
    c.bend = INFINITY;
    CHECK_EQ(wb_cloth(w, &c, &untouched), WB_ERR_ARG);
    CHECK_HAS(wb_last_error(), "bend");
    c = wb_cloth_default_def();
    c.origin[1] = NAN;
    CHECK_EQ(wb_cloth(w, &c, &untouched), WB_ERR_ARG);
    c = wb_cloth_default_def();
    c.link.compliance = -1;
    CHECK_EQ(wb_cloth(w, &c, &untouched), WB_ERR_ARG);
    CHECK_HAS(wb_last_error(), "compliance");
    c = wb_cloth_default_def();
    c.radius = -1;
    CHECK_EQ(wb_cloth(w, &c, &untouched), WB_ERR_ARG);
    CHECK_HAS(wb_last_error(), "radius");
    CHECK_UNCHANGED(w, np, nd, h);

    r = wb_rope_default_def();
    r.segments = 0;
    CHECK_EQ(wb_rope(w, &r, &untouched), WB_ERR_ARG);
    CHECK_HAS(wb_last_error(), "segments");
    r.segments = WB_MAX_PARTICLES;
    CHECK_EQ(wb_rope(w, &r, &untouched), WB_ERR_ARG);
    r = wb_rope_default_def();
    r.segments = WB_MAX_PARTICLES - 1; /* passes the check, over the limit with what exists */
    CHECK(wb_rope(w, &r, &untouched) < 0);
    r = wb_rope_default_def();
    r.to[2] = INFINITY;
    CHECK_EQ(wb_rope(w, &r, &untouched), WB_ERR_ARG);
    r = wb_rope_default_def();
    r.mass = -1;
    CHECK_EQ(wb_rope(w, &r, &untouched), WB_ERR_ARG);
    CHECK_UNCHANGED(w, np, nd, h);

    wb_lattice_def l = wb_lattice_default_def();
    l.res[2] = 1;
    CHECK_EQ(wb_lattice(w, &l, &untouched), WB_ERR_ARG);
    CHECK_HAS(wb_last_error(), "res");
    l = wb_lattice_default_def();
    l.res[0] = l.res[1] = l.res[2] = 1000;
    CHECK_EQ(wb_lattice(w, &l, &untouched), WB_ERR_ARG);
    CHECK_HAS(wb_last_error(), "large");
    l = wb_lattice_default_def();
    l.max[1] = l.min[1];
    CHECK_EQ(wb_lattice(w, &l, &untouched), WB_ERR_ARG);
    CHECK_HAS(wb_last_error(), "max");
    l = wb_lattice_default_def();
    l.link.break_strain = -1;
    CHECK_EQ(wb_lattice(w, &l, &untouched), WB_ERR_ARG);
    CHECK_UNCHANGED(w, np, nd, h);

    CHECK_EQ(untouched.first, 12345);
    CHECK_EQ(untouched.count, 678);
    /* the world still works after all that */
    wb_world_step(w);
    CHECK_EQ(wb_world_warnings(w), 0);
    wb_world_destroy(w);
}
