/* test_batches.c: the colour batches of volume constraints and Neo-Hookean tets
 * (white-box: batch.h over a permutation): every constraint once, no batch before the
 * serial tail sharing a movable particle, batches large enough to run in parallel. */
#include <stdlib.h>

#include "core/core.h"
#include "core/tet.h"
#include "core/volume.h"
#include "test.h"

static wb_world *block(int threads, bool neo)
{
    wb_world_def d = wb_world_default_def();
    d.threads = threads;
    wb_world *w = wb_world_create(&d);
    if (!w) return NULL;
    wb_lattice_def l = wb_lattice_default_def();
    l.max[0] = l.max[1] = l.max[2] = 1;
    l.res[0] = l.res[1] = l.res[2] = 12;
    l.tets = true;
    l.volume_compliance = 1e-6;
    if (neo) l.young = 1e4;
    wb_body b;
    if (wb_lattice(w, &l, &b) != WB_OK) { wb_world_destroy(w); return NULL; }
    wb_particle_pin(w, b.first, NULL); /* a pinned corner: still a conflict (only mass 0 is not) */
    return w;
}

static void check_batches(const wb_world *w, const wb_batches *bt, const int32_t *order, const int32_t *ijkl, int32_t n)
{
    CHECK_EQ(bt->n, n);
    CHECK_EQ(bt->colour_start[0], 0);
    CHECK_EQ(bt->colour_start[bt->ncolours], n);
    CHECK(bt->serial_start == bt->ncolours); /* a lattice needs far fewer than 64 colours */
    int32_t *seen = calloc((size_t)n, sizeof *seen), *owner = malloc(sizeof(int32_t) * (size_t)w->m.np);
    REQUIRE(seen && owner);
    for (int32_t i = 0; i < w->m.np; i++) owner[i] = -1;
    int conflicts = 0, big = 0;
    for (int32_t c = 0; c < bt->serial_start; c++) {
        if (bt->colour_start[c + 1] - bt->colour_start[c] >= 256) big++;
        for (int32_t j = bt->colour_start[c]; j < bt->colour_start[c + 1]; j++) {
            const int32_t s = order[j];
            REQUIRE(s >= 0 && s < n);
            seen[s]++;
            for (int e = 0; e < 4; e++) {
                const int32_t p = ijkl[4 * s + e];
                if (w->m.inv_mass[p] == 0) continue;
                if (owner[p] == c) conflicts++;
                owner[p] = c;
            }
        }
    }
    int once = 1;
    for (int32_t s = 0; s < n; s++) once &= seen[s] == 1;
    CHECK(once);
    CHECK_EQ(conflicts, 0);
    CHECK(big > 0);
    free(seen);
    free(owner);
}

TEST(volume_tet_batches_valid)
{
    wb_world *v = block(1, false), *t = block(1, true);
    REQUIRE(v && t);
    wb_world_step(v);
    wb_world_step(t);
    REQUIRE(v->vol && t->neo);
    check_batches(v, &v->vol->bt, v->vol->order, v->vol->ijkl, v->vol->n);
    check_batches(t, &t->neo->bt, t->neo->order, t->neo->ijkl, t->neo->n);
    wb_world_destroy(v);
    wb_world_destroy(t);
}

/* the same bits for 1 and 3 threads (batches of >= 256 volumes / 64 tets are split) */
TEST(volume_tet_threads_identical)
{
    for (int neo = 0; neo < 2; neo++) {
        wb_world *a = block(1, neo), *b = block(3, neo);
        REQUIRE(a && b);
        for (int f = 0; f < 15; f++) { wb_world_step(a); wb_world_step(b); }
        CHECK_EQ(wb_world_hash(a), wb_world_hash(b));
        wb_world_destroy(a);
        wb_world_destroy(b);
    }
}
