/* test_colour.c: validity of the colour batches (white-box: includes core.h).
 *
 * After a step, the packed constraints must satisfy:
 *   - batches before serial_start share no particle with inv_mass > 0 (they run in
 *     parallel and in any order, so two writers of one particle would race);
 *   - every live, unbroken constraint is packed exactly once, with its own particles
 *     and parameters, and slot_pack / s_slot are inverse maps;
 *   - batch ranges are contiguous, increasing and cover [0, ns). */
#include <stdlib.h>

#include "core/core.h"
#include "core/batch.h"
#include "core/distance.h"
#include "test.h"

static void check_colouring(wb_world *w)
{
    const wb_model *m = &w->m;
    /* a break at the end of the last step marks the batches dirty: rebuild as a step would */
    REQUIRE(wb__colour(w) == WB_OK);
    REQUIRE(!m->topology_dirty);
    const wb_distances *ds = wb__dist(w->dist);
    /* ranges */
    REQUIRE(ds->bt.ncolours >= 0 && ds->bt.serial_start >= 0 && ds->bt.serial_start <= ds->bt.ncolours);
    CHECK_EQ(ds->bt.colour_start[0], 0);
    const int32_t split_start = ds->bt.colour_start[ds->bt.ncolours];
    CHECK_EQ(ds->bt.norder, ds->ns);
    for (int32_t c = 0; c < ds->bt.ncolours; c++) CHECK(ds->bt.colour_start[c] < ds->bt.colour_start[c + 1]);
    /* the compounds fill [split_start, ns), each a non-empty run of links joined through
     * shared movable particles, whose ends count the members meeting there */
    REQUIRE(ds->bt.ncomp >= 0);
    CHECK_EQ(ds->bt.comp_start[0], split_start);
    CHECK_EQ(ds->bt.comp_start[ds->bt.ncomp], ds->ns);
    int bad_comp = 0;
    for (int32_t c = 0; c < ds->bt.ncomp; c++) {
        const int32_t b = ds->bt.comp_start[c], e = ds->bt.comp_start[c + 1];
        if (e <= b) { bad_comp++; continue; }
        for (int32_t i = b; i < e; i++) {
            int n[2] = { 0, 0 }, joined = e - b == 1;
            for (int32_t j = b; j < e; j++) {
                n[0] += ds->s_a[j] == ds->s_a[i] || ds->s_b[j] == ds->s_a[i];
                n[1] += ds->s_a[j] == ds->s_b[i] || ds->s_b[j] == ds->s_b[i];
            }
            joined |= n[0] > 1 || n[1] > 1;
            const int32_t *nsp = &ds->s_nsp[2 * (i - split_start)];
            bad_comp += !joined || nsp[0] != n[0] || nsp[1] != n[1];
        }
    }
    CHECK_EQ(bad_comp, 0);
    /* conflict-free batches */
    int32_t *owner = malloc(sizeof(int32_t) * (size_t)(m->np > 0 ? m->np : 1));
    REQUIRE(owner);
    for (int32_t i = 0; i < m->np; i++) owner[i] = -1;
    int conflicts = 0;
    for (int32_t c = 0; c < ds->bt.serial_start; c++)
        for (int32_t i = ds->bt.colour_start[c]; i < ds->bt.colour_start[c + 1]; i++) {
            const int32_t ends[2] = { ds->s_a[i], ds->s_b[i] };
            for (int e = 0; e < 2; e++) {
                const int32_t p = ends[e];
                if (m->inv_mass[p] == 0) continue;
                if (owner[p] == c) conflicts++;
                owner[p] = c;
            }
        }
    CHECK_EQ(conflicts, 0);
    free(owner);
    /* packed exactly once */
    int32_t live = 0;
    int bad_map = 0, bad_data = 0;
    for (int32_t s = 0; s < ds->n; s++) {
        const int is_live = (ds->gen[s] & 1u) && !ds->broken[s];
        const int32_t i = ds->slot_pack[s];
        if (!is_live) { if (i != -1) bad_map++; continue; }
        live++;
        if (i < 0 || i >= ds->ns || ds->s_slot[i] != s) { bad_map++; continue; }
        if (ds->s_a[i] != ds->ij[2 * s] || ds->s_b[i] != ds->ij[2 * s + 1] || ds->s_rest[i] != ds->rest[s] ||
            ds->s_alpha[i] != ds->alpha[s] || ds->s_beta[i] != ds->beta[s])
            bad_data++;
    }
    CHECK_EQ(live, ds->ns);
    for (int32_t i = 0; i < ds->ns; i++) {
        const int32_t s = ds->s_slot[i];
        if (s < 0 || s >= ds->n || ds->slot_pack[s] != i) bad_map++;
    }
    CHECK_EQ(bad_map, 0);
    CHECK_EQ(bad_data, 0);
}

TEST(colour_batches_valid)
{
    wb_world_def wd = wb_world_default_def();
    wb_world *w = wb_world_create(&wd);
    REQUIRE(w);
    /* a cloth with shear and bend, a lattice, and a rope with a pinned end */
    wb_cloth_def cd = wb_cloth_default_def();
    cd.res[0] = 17; cd.res[1] = 13;
    cd.bend_links = 1e-4;
    wb_body cloth, lat, rope;
    REQUIRE(wb_cloth(w, &cd, &cloth) == WB_OK);
    wb_lattice_def ld = wb_lattice_default_def();
    ld.min[1] = 2; ld.max[1] = 3;
    REQUIRE(wb_lattice(w, &ld, &lat) == WB_OK);
    wb_rope_def rd = wb_rope_default_def();
    rd.from[1] = rd.to[1] = 5;
    REQUIRE(wb_rope(w, &rd, &rope) == WB_OK);
    wb_particle_pin(w, rope.first, NULL);
    /* a star around an immovable hub: the hub never conflicts, so 80 spokes fit one batch */
    wb_real hub_p[3] = { 0, 8, 0 };
    const int32_t hub = wb_particle_add(w, hub_p, NULL, 0, 0);
    wb_distance_def dd = wb_distance_default_def();
    for (int i = 0; i < 80; i++) {
        wb_real p[3] = { cos(i * 0.1), 9, sin(i * 0.1) };
        const int32_t q = wb_particle_add(w, p, NULL, 1, 0);
        REQUIRE(wb_distance_add(w, hub, q, &dd, NULL).index != 0);
    }
    wb_world_step(w);
    check_colouring(w);
    CHECK(wb__dist(w->dist)->bt.ncolours >= 4);

    /* a star around a movable hub with 100 spokes needs 100 colours: past the 64 of
     * the bit mask the rest go to the serial batch */
    hub_p[1] = 12;
    const int32_t hub2 = wb_particle_add(w, hub_p, NULL, 1, 0);
    for (int i = 0; i < 100; i++) {
        wb_real p[3] = { 2 + cos(i * 0.1), 13, sin(i * 0.1) };
        const int32_t q = wb_particle_add(w, p, NULL, 1, 0);
        REQUIRE(wb_distance_add(w, hub2, q, &dd, NULL).index != 0);
    }
    wb_world_step(w);
    check_colouring(w);
    CHECK(wb__dist(w->dist)->bt.serial_start < wb__dist(w->dist)->bt.ncolours);

    /* edits: remove every third constraint, add a few, break none: rebuilt and valid */
    int32_t n = wb_distance_count(w);
    wb_distance_id *ids = malloc(sizeof *ids * (size_t)n);
    REQUIRE(ids);
    for (int32_t i = 0; i < n; i++) ids[i] = wb_distance_at(w, i);
    for (int32_t i = 0; i < n; i += 3) wb_distance_remove(w, ids[i]);
    free(ids);
    for (int i = 0; i < 10; i++) wb_distance_add(w, cloth.first + i, cloth.first + 40 + i, &dd, NULL);
    wb_world_step(w);
    check_colouring(w);
    CHECK_EQ(wb_world_warnings(w), 0);
    wb_world_destroy(w);
}

TEST(colour_broken_constraints_unpacked)
{
    /* a rope whose links break: broken links are left out of the batches */
    wb_world_def wd = wb_world_default_def();
    wb_world *w = wb_world_create(&wd);
    REQUIRE(w);
    wb_rope_def rd = wb_rope_default_def();
    rd.segments = 6;
    rd.link.compliance = 1e-2; /* soft: the top link holds ~0.84 N, stretching ~0.5 of its length */
    rd.link.break_strain = 0.01;
    wb_body rope;
    REQUIRE(wb_rope(w, &rd, &rope) == WB_OK);
    wb_particle_pin(w, rope.first, NULL);
    int broke = 0;
    for (int f = 0; f < 120; f++) {
        wb_world_step(w);
        broke += wb_world_break_count(w);
        for (int32_t i = 0; i < wb_world_break_count(w); i++) CHECK(wb_distance_broken(w, wb_world_break_at(w, i)));
    }
    CHECK(broke > 0);
    check_colouring(w);
    wb_stats st = wb_world_stats(w);
    CHECK_EQ(st.broken, broke);
    CHECK_EQ(st.distances, 6);
    CHECK_EQ(wb__dist(w->dist)->ns, 6 - broke);
    wb_world_destroy(w);
}

/* the colour of the packed distance constraint joining local particles a and b of a
 * lattice body (first .. first + np - 1), 1000 + its compound's run (below) for a
 * compound's member, -1 when none: a dense np x np table */
static int *lattice_colours(const wb_world *w, int32_t first, int32_t np)
{
    int *col = malloc(sizeof *col * (size_t)np * (size_t)np);
    if (!col) return NULL;
    for (int32_t i = 0; i < np * np; i++) col[i] = -1;
    const wb_distances *ds = wb__dist(w->dist);
    for (int32_t c = 0; c < ds->bt.ncolours; c++)
        for (int32_t i = ds->bt.colour_start[c]; i < ds->bt.colour_start[c + 1]; i++) {
            const int32_t a = ds->s_a[i] - first, b = ds->s_b[i] - first;
            col[a * np + b] = col[b * np + a] = c;
        }
    /* compounds touching none of the run they follow commute with it: a run projects as
     * one, in any order (each compound's images are in its run) */
    int32_t *run = malloc(sizeof *run * (size_t)np);
    if (!run) { free(col); return NULL; }
    for (int32_t p = 0; p < np; p++) run[p] = -1;
    int32_t cur = 0;
    for (int32_t c = 0; c < ds->bt.ncomp; c++) {
        int shares = 0;
        for (int32_t i = ds->bt.comp_start[c]; i < ds->bt.comp_start[c + 1]; i++)
            shares |= run[ds->s_a[i] - first] == cur || run[ds->s_b[i] - first] == cur;
        if (shares) cur++;
        for (int32_t i = ds->bt.comp_start[c]; i < ds->bt.comp_start[c + 1]; i++) {
            const int32_t a = ds->s_a[i] - first, b = ds->s_b[i] - first;
            run[a] = run[b] = cur;
            col[a * np + b] = col[b * np + a] = 1000 + cur;
        }
    }
    free(run);
    return col;
}

/* a lattice n x ny x n centred on x = z = 0, coloured with (on = 1) or without mirror
 * keys; counts the links whose images across x = 0 or z = 0 have another colour:
 * mism[0] of links with no particle on either plane, mism[1] of the others; mism[2]: the
 * compounds */
static void mirror_mismatches(int n, int ny, int on, int mism[3])
{
    const int was = wb__colour_symmetric(on);
    wb_world_def wd = wb_world_default_def();
    wb_world *w = wb_world_create(&wd);
    REQUIRE(w);
    wb_lattice_def ld = wb_lattice_default_def();
    ld.min[0] = ld.min[2] = -0.5;
    ld.max[0] = ld.max[2] = 0.5;
    ld.res[0] = ld.res[2] = n;
    ld.res[1] = ny;
    wb_body b;
    REQUIRE(wb_lattice(w, &ld, &b) == WB_OK);
    wb_world_step(w);
    wb__colour_symmetric(was);
    const int32_t np = b.count;
    int *col = lattice_colours(w, b.first, np);
    REQUIRE(col);
    /* a lattice's compounds are the 2 or 4 images meeting at a particle on a plane */
    const wb_distances *ds = wb__dist(w->dist);
    for (int32_t c = 0; c < ds->bt.ncomp; c++) CHECK(ds->bt.comp_start[c + 1] - ds->bt.comp_start[c] <= 4);
    mism[2] = ds->bt.ncomp;
    mism[0] = mism[1] = 0;
    for (int32_t p = 0; p < np; p++)
        for (int32_t q = p + 1; q < np; q++) {
            if (col[p * np + q] < 0) continue;
            const int ip = p % n, kp = p / n / ny, iq = q % n, kq = q / n / ny;
            const int32_t mxp = p + (n - 1 - 2 * ip), mxq = q + (n - 1 - 2 * iq);        /* i -> n-1-i */
            const int32_t mzp = p + (n - 1 - 2 * kp) * n * ny, mzq = q + (n - 1 - 2 * kq) * n * ny;
            const int on_plane = 2 * ip == n - 1 || 2 * iq == n - 1 || 2 * kp == n - 1 || 2 * kq == n - 1;
            if (col[mxp * np + mxq] != col[p * np + q] || col[mzp * np + mzq] != col[p * np + q]) mism[on_plane]++;
        }
    free(col);
    CHECK_EQ(wb_world_warnings(w), 0);
    wb_world_destroy(w);
}

/* A body symmetric about vertical planes is coloured symmetrically: a link and its
 * mirror images get the same colour, so every Gauss-Seidel sweep is symmetric (a box
 * dropped centred on a soft block stays upright: tests/validation/symmetric_drop.lua).
 * With particles on the planes, the images that meet there cannot share a colour: they
 * form one compound, projected together (its images in the same compound). The
 * creation-order colouring mirrored neither. */
TEST(colour_mirror_images_alike)
{
    int m[3];
    mirror_mismatches(6, 4, 1, m); /* no particle on the planes */
    CHECK_EQ(m[0], 0);
    CHECK_EQ(m[1], 0);
    CHECK_EQ(m[2], 0);
    mirror_mismatches(6, 4, 0, m);
    CHECK(m[0] > 0);
    mirror_mismatches(7, 3, 1, m); /* a column of particles on each plane */
    CHECK_EQ(m[0], 0);
    CHECK_EQ(m[1], 0);
    CHECK(m[2] > 0);
    mirror_mismatches(7, 3, 0, m);
    CHECK(m[0] > 0);
}

/* the distances' struct is made with the first link: a world without any has none
 * (stepped by either solver, cloned), and what the links charged is given back */
TEST(colour_distances_made_with_the_first_link)
{
    wb_memory mem = { 0, 0 };
    wb_world_def wd = wb_world_default_def();
    wd.memory = &mem;
    for (int jacobi = 0; jacobi < 2; jacobi++) {
        wd.solver = jacobi ? WB_SOLVER_JACOBI : WB_SOLVER_GAUSS_SEIDEL;
        wb_world *w = wb_world_create(&wd);
        REQUIRE(w);
        const wb_real pos[4][3] = { { 0, 1, 0 }, { 1, 1, 0 }, { 0, 2, 0 }, { 0, 1, 1 } };
        int32_t p[4];
        for (int i = 0; i < 4; i++) p[i] = wb_particle_add(w, pos[i], NULL, 1, 0.01);
        const wb_tet_def td = wb_tet_default_def();
        REQUIRE(wb_tet_add(w, p, &td) >= 0);
        for (int f = 0; f < 3; f++) REQUIRE(wb_world_step(w) == WB_OK);
        CHECK(w->dist == NULL);
        const wb_stats st = wb_world_stats(w);
        CHECK_EQ(st.distances, 0);
        CHECK_EQ(st.colours, 0);
        wb_world *c = wb_world_clone(w);
        REQUIRE(c);
        CHECK(c->dist == NULL);
        wb_world_destroy(c);
        const wb_distance_def dd = wb_distance_default_def();
        const wb_distance_id id = wb_distance_add(w, p[0], p[1], &dd, NULL);
        REQUIRE(id.index != 0);
        REQUIRE(w->dist != NULL);
        CHECK(w->dist->charged > 0);
        REQUIRE(wb_world_step(w) == WB_OK);
        CHECK_EQ(wb_world_stats(w).distances, 1);
        wb_world_destroy(w);
        CHECK_EQ(mem.used, 0);
    }
}
