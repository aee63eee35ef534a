/* test_broadphase_kept.c: the neighbour list broadphase.c keeps from frame to frame
 * (wb__broadphase_kept, white-box: core.h) must give, every frame, the very list of a fresh
 * search (wb__broadphase): the same pairs in the same order, the keep filter applied.
 * Particles of bodies in a heap drift a little each frame (so that the list stays valid
 * for a while and then the drift adds up past the skin), and now and then one jumps, a
 * reach grows, a particle drops out (negative reach, then a non-finite position) and comes
 * back, or a body's skip key changes: a list kept one frame too long misses or keeps a
 * pair. The list must also be rebuilt far less often than every frame (it is used). */
#include <stdlib.h>

#include "core/core.h"
#include "core/broadphase.h"
#include "core/tricontact.h"
#include "test.h"

static uint64_t rng = 0x2545F4914F6CDD1Dull;
static double urand(void)
{
    rng = rng * 6364136223846793005ull + 1442695040888963407ull;
    return (double)(rng >> 11) / 9007199254740992.0;
}

/* drops a fixed, scattered tenth of the pairs (the filter runs on the kept list too) */
static int keep_some(void *ud, int32_t i, int32_t j)
{
    (void)ud;
    return (i * 31 + j * 17) % 10 != 3;
}

/* keys: bodies with skip keys (culled: the list's grid lacks some, so no mends), else every
 * particle keyless (one grid of all: few strays are mended in the list, not rebuilt) */
static void kept_matches_fresh(int keys)
{
    enum { N = 1200, FRAMES = 60 };
    wb_real *x = malloc(sizeof(wb_real) * 3 * N), *reach = malloc(sizeof(wb_real) * N);
    int32_t *skip = malloc(sizeof(int32_t) * N);
    REQUIRE(x && reach && skip);
    /* 30 bodies of 40 (4 x 5 x 2, spacing 0.1) in a heap, touching; every fifth without a key */
    for (int32_t i = 0; i < N; i++) {
        const int32_t b = i / 40, k = i % 40;
        x[3 * i] = (b % 5) * 0.35 + (k % 4) * 0.1;
        x[3 * i + 1] = ((b / 5) % 3) * 0.45 + ((k / 4) % 5) * 0.1;
        x[3 * i + 2] = (b / 15) * 0.15 + (k / 20) * 0.1;
        reach[i] = 0.03 + 0.01 * urand();
        skip[i] = !keys || b % 5 == 4 ? 0 : b + 1;
    }
    wb_contacts kept;
    memset(&kept, 0, sizeof kept);
    wb_pool *pool = wb__pool_create(2); /* odd frames on 2 threads */
    int bad = 0, checked = 0;
    for (int f = 0; f < FRAMES; f++) {
        /* a drift of up to ~2 mm a frame: the skin (a quarter of a reach, ~8 mm) lasts a few frames */
        for (int32_t i = 0; i < 3 * N; i++) x[i] += 0.002 * (urand() - 0.5) + (i % 3 == 1 ? -0.0008 : 0);
        if (f % 9 == 4) v3_set(&x[3 * (f * 37 % N)], 0.5 * urand(), 0.5 * urand(), 0.2 * urand()); /* a jump */
        if (f % 11 == 6) reach[f * 53 % N] *= 1.4;                                             /* faster */
        /* two neighbours made faster a frame apart: the second's mend must find the first's
         * pair among the ones mended before it (the grid has the first where it was) */
        if (f % 13 == 7 && !keys) reach[f * 29 % (N - 1)] *= 2;
        if (f % 13 == 8 && !keys) reach[(f - 1) * 29 % (N - 1) + 1] *= 2;
        /* a jump, and a frame later another particle jumps beside it: the second's mend must
         * find the first among the ones mended before it (the grid has it where it was) */
        if (f % 10 == 2 && !keys) v3_set(&x[3 * (f * 41 % N)], 0.9, 0.5 + 0.01 * f, 0.4);
        if (f % 10 == 3 && !keys) v3_set(&x[3 * ((f * 43 + 7) % N)], 0.95, 0.5 + 0.01 * (f - 1), 0.4);
        if (f == 20) reach[77] = -1;                                                        /* out */
        if (f == 24) reach[77] = 0.035;                                                     /* back */
        if (f == 30) x[3 * 500 + 2] = NAN;
        if (f == 33) x[3 * 500 + 2] = 0.1;
        if (f == 41 && keys)
            for (int32_t i = 400; i < 440; i++) skip[i] = skip[440]; /* two touching bodies made one */
        kept.n = 0;
        const int32_t got = wb__broadphase_kept(&kept, x, reach, skip, N, f % 2 ? pool : NULL, keep_some, 0, NULL, NULL);
        wb_contacts fresh;
        memset(&fresh, 0, sizeof fresh);
        const int32_t want = wb__broadphase(&fresh, x, reach, skip, N, NULL, keep_some, NULL);
        CHECK(want > 100); /* the heap touches */
        if (got != want || memcmp(kept.ij, fresh.ij, sizeof *kept.ij * 2 * (size_t)(want > 0 ? want : 0)) != 0) bad++;
        checked++;
        wb__broadphase_free(&fresh);
        free(fresh.ij);
    }
    CHECK_EQ(bad, 0);
    CHECK_EQ(checked, FRAMES);
    /* used: rebuilt now and then (the drift, the jumps, the changes), not every frame */
    const int64_t rebuilds = kept.bp ? kept.bp->rebuilds : -1;
    const int64_t mends = kept.bp ? kept.bp->mends : -1;
    printf("# %s: rebuilt %lld times, mended %lld times in %d frames\n", keys ? "bodies" : "keyless",
           (long long)rebuilds, (long long)mends, FRAMES);
    CHECK(rebuilds > (keys ? 5 : 1));
    CHECK(rebuilds < FRAMES / 2);
    if (!keys) CHECK(mends > 5); /* the jumps and faster particles are mended in place */
    /* the calls that served the list unmended tested only the pairs of particles that came
     * near enough (the heap touches: some always do) */
    CHECK(kept.bp && kept.bp->gap_calls > 10);
    wb__broadphase_free(&kept);
    wb__pool_destroy(pool);
    free(kept.ij);
    free(x);
    free(reach);
    free(skip);
}

TEST(contact_broadphase_kept_list_matches_fresh_search) { kept_matches_fresh(1); }
TEST(contact_broadphase_kept_list_mended_matches_fresh_search) { kept_matches_fresh(0); }
