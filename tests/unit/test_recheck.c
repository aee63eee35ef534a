/* test_recheck.c: the contact list is complete at every substep (broadphase.c,
 * wb__contacts_recheck). A stiff cloth hung over the floor and let fall into a heap on
 * itself: its links yank particles farther within a frame than their velocity and
 * gravity carry them, past the reach the frame's list was made with; each substep then
 * finds the particle moved too far and makes the list again. Checked by brute force:
 * every touching pair that may touch is in the list, at every substep. */
#include <math.h>

#include "test.h"
#include "core/core.h"
#include "core/broadphase.h"
#include "core/tricontact.h"

static wb_world *heap(int n)
{
    wb_world_def d = wb_world_default_def();
    d.damping = 0.5;
    wb_world *w = wb_world_create(&d);
    if (!w) return NULL;
    wb_collider_def floor = wb_collider_default_def(WB_SHAPE_PLANE);
    v3_set(floor.normal, 0, 1, 0);
    floor.offset = 0;
    floor.friction = 0.8;
    wb_status st;
    wb_collider_add(w, &floor, &st);
    wb_cloth_def c = wb_cloth_default_def();
    v3_set(c.origin, -0.25, 0, 0);
    c.size[0] = c.size[1] = 0.5;
    c.res[0] = c.res[1] = n;
    c.link.compliance = 1e-6;
    wb_body b;
    if (wb_cloth(w, &c, &b) != WB_OK) { wb_world_destroy(w); return NULL; }
    wb_body_set_contacts(w, b, true, true, 0.8);
    const wb_real r = w->m.radius[b.first];
    /* stood up in x-y, its lower edge two radii above the floor, rippled */
    for (int32_t i = b.first; i < b.first + b.count; i++) {
        wb_real p[3], v[3];
        wb_particle_position(w, i, p);
        const wb_real x = p[0], z = p[2];
        v3_set(p, x, z + 2 * r, 0.02 * sin(60 * z + 6 * x));
        v3_set(v, -1.2 * x * z, 0, 0.2 * sin(27 * z + 4.5 * x));
        wb_particle_set_position(w, i, p);
        wb_particle_set_velocity(w, i, v);
    }
    return w;
}

TEST(contact_list_complete_every_substep)
{
    int64_t missed[2], remakes[2];
    int split = 0;
    for (int on = 0; on < 2; on++) {
        wb_world *w = heap(32);
        REQUIRE(w);
        REQUIRE(wb__contacts_make(w)); /* (the first step's: the switches go in before it) */
        w->k.pc->brute = 1;
        w->k.pc->no_recheck = !on;
        for (int f = 0; f < 90; f++) {
            wb_world_step(w);
            split += on && w->k.pc->span < w->m.def.substeps; /* two lists that frame */
        }
        missed[on] = w->k.pc->missed;
        remakes[on] = w->k.pc->remakes;
        wb_world_destroy(w);
    }
    printf("# missed pairs without the check %lld, with it %lld (lists made again: %lld)\n",
           (long long)missed[0], (long long)missed[1], (long long)remakes[1]);
    CHECK(missed[0] > 0);  /* the scene does outrun the frame's reach */
    CHECK_EQ(missed[1], 0);
    CHECK(remakes[1] > 0);
    CHECK(split > 0);      /* and some frames' lists were made for half of them each */
}

/* The reaches are measured against a reference motion fitted to the particles (a
 * velocity and a turn, broadphase.c), so they stay about a radius while a cloth swings
 * or spins. Still complete at every substep: a self-colliding cloth swinging from two
 * pinned corners (immovable particles, which the reference leaves behind) into a ball
 * in its way, and one thrown tumbling onto the floor (the floor stops its leading edge
 * while the rest still turns over it). */
/* a world of the defaults with a floor at y = 0 */
static wb_world *floor_world(void)
{
    wb_world_def d = wb_world_default_def();
    wb_world *w = wb_world_create(&d);
    if (!w) return NULL;
    wb_collider_def floor = wb_collider_default_def(WB_SHAPE_PLANE);
    v3_set(floor.normal, 0, 1, 0);
    floor.offset = 0;
    wb_status st;
    wb_collider_add(w, &floor, &st);
    return w;
}

static wb_world *swinging(int spin)
{
    wb_world *w = floor_world();
    if (!w) return NULL;
    wb_status st;
    wb_cloth_def c = wb_cloth_default_def();
    v3_set(c.origin, -0.5, spin ? 0.6 : 1.2, -0.5);
    c.size[0] = c.size[1] = 1;
    c.res[0] = c.res[1] = 24;
    wb_body b;
    if (wb_cloth(w, &c, &b) != WB_OK) { wb_world_destroy(w); return NULL; }
    wb_body_set_contacts(w, b, true, true, 0.3);
    if (!spin) {
        wb_particle_pin(w, b.first, NULL);
        wb_particle_pin(w, b.first + 23, NULL);
        /* a ball in the way of the swing: the cloth wraps round it, stopped far from
         * where the swing's turn would take it */
        wb_collider_def ball = wb_collider_default_def(WB_SHAPE_SPHERE);
        v3_set(ball.center, 0, 0.55, 0.15);
        ball.radius = 0.25;
        wb_collider_add(w, &ball, &st);
        return w;
    }
    for (int32_t i = b.first; i < b.first + b.count; i++) {
        wb_real p[3], v[3];
        wb_particle_position(w, i, p);
        v3_set(v, 0.5, -1 - 8 * p[2], 0);
        wb_particle_set_velocity(w, i, v);
    }
    return w;
}

TEST(contact_list_complete_with_reference_motion)
{
    for (int spin = 0; spin < 2; spin++) {
        wb_world *w = swinging(spin);
        REQUIRE(w);
        REQUIRE(wb__contacts_make(w));
        w->k.pc->brute = 1;
        wb_real turned = 0;
        int split = 0;
        for (int f = 0; f < 60; f++) {
            wb_world_step(w);
            split += w->k.pc->span < w->m.def.substeps;
            const wb_real *om = w->k.pc->ref_om;
            turned = fmax(turned, sqrt(om[0] * om[0] + om[1] * om[1] + om[2] * om[2]));
        }
        printf("# %s: missed %lld, lists made again %lld, reference turn up to %.3g rad/s\n",
               spin ? "tumbling cloth" : "swinging cloth", (long long)w->k.pc->missed,
               (long long)w->k.pc->remakes, turned);
        CHECK(turned > 0.5); /* the reference did turn with the cloth */
        CHECK(split > 0);    /* frames of two lists, each for half the substeps */
        CHECK_EQ(w->k.pc->missed, 0);
        wb_world_destroy(w);
    }
}

/* The check itself, against a list made with a turning reference: a self-colliding cloth
 * spinning about the vertical, its list made, then one substep later every particle where
 * the reference takes it but a corner folded onto the cloth's far side (a deviation far
 * past its reach). The check must find it and mend the list: the corner's new neighbours
 * are in it. Skipping the check for a moving reference (the control) misses them. */
static int64_t folded_corner_missed(int check)
{
    wb_world_def d = wb_world_default_def();
    v3_set(d.gravity, 0, 0, 0);
    wb_world *w = wb_world_create(&d);
    if (!w) return -1;
    wb_cloth_def cd = wb_cloth_default_def();
    v3_set(cd.origin, -0.5, 1, -0.5);
    cd.size[0] = cd.size[1] = 1;
    cd.res[0] = cd.res[1] = 16;
    wb_body b;
    if (wb_cloth(w, &cd, &b) != WB_OK) { wb_world_destroy(w); return -1; }
    wb_body_set_contacts(w, b, true, true, 0);
    const wb_real om = 6;
    for (int32_t i = b.first; i < b.first + b.count; i++) {
        wb_real p[3], v[3];
        wb_particle_position(w, i, p);
        v3_set(v, om * p[2], 0, -om * p[0]);
        wb_particle_set_velocity(w, i, v);
    }
    if (!wb__contacts_make(w)) abort(); /* (a step's first act) */
    wb__contacts_begin(w);
    wb_contacts *c = w->k.pc;
    CHECK(c->check);
    CHECK(fabs(c->ref_om[1]) > 1); /* the list was made with the turning reference */
    /* one substep on: each particle turned with the reference (S = h, no drag), the first
     * row's first 3 particles laid 1 cm above the far corner's particles */
    const wb_real h = d.dt / d.substeps;
    for (int32_t i = b.first; i < b.first + b.count; i++) {
        wb_real *x = &w->s.x[3 * i];
        const wb_real *cc = c->ref_c, *V = c->ref_v, *o = c->ref_om;
        const wb_real r[3] = { x[0] - cc[0], x[1] - cc[1], x[2] - cc[2] };
        const wb_real mv[3] = { V[0] + o[1] * r[2] - o[2] * r[1], V[1] + o[2] * r[0] - o[0] * r[2],
                                V[2] + o[0] * r[1] - o[1] * r[0] };
        for (int a = 0; a < 3; a++) x[a] += h * mv[a];
    }
    for (int k = 0; k < 3; k++) {
        wb_real *x = &w->s.x[3 * (b.first + k)];
        const wb_real *far = &w->s.x[3 * (b.first + b.count - 1 - k)];
        v3_set(x, far[0], far[1] + 0.01, far[2]);
    }
    if (check) wb__contacts_recheck(w, h);
    c->missed = 0;
    wb__contacts_brute(w);
    const int64_t missed = c->missed;
    wb_world_destroy(w);
    return missed;
}

TEST(contact_check_follows_reference_motion)
{
    const int64_t with = folded_corner_missed(1), without = folded_corner_missed(0);
    printf("# a corner folded past its reach: missed %lld with the check, %lld without\n", (long long)with,
           (long long)without);
    CHECK(without > 0);
    CHECK_EQ(with, 0);
}

/* The substeps' check in AVX2 (broadphase.c, check_avx2) decides as the scalar one, to the
 * bit: the stiff heap above (particles off their paths and past their reaches every few
 * substeps) stepped both ways, the same state, lists and remakes every frame */
/* the two worlds' particles at the same positions and velocities, to the bit */
static int same_bits(const wb_world *a, const wb_world *b)
{
    const size_t bytes = sizeof(wb_real) * 3 * (size_t)a->m.np;
    return a->m.np == b->m.np && memcmp(a->s.x, b->s.x, bytes) == 0 && memcmp(a->s.v, b->s.v, bytes) == 0;
}

/* n x n: 32 (the vector check's groups of four alone) and 31 (one particle left for the
 * one-at-a-time tail) */
static void simd_bits(int n)
{
    wb_world *a = heap(n), *b = heap(n);
    REQUIRE(a && b);
    b->k.no_simd = 1;
    int same = 1;
    for (int f = 0; f < 60 && same; f++) {
        wb_world_step(a);
        wb_world_step(b);
        same = same_bits(a, b) &&
               a->k.pc->remakes == b->k.pc->remakes && a->k.pc->n == b->k.pc->n;
        /* the kept list's motion fit (it decides only whether the list serves, which the
         * positions would not show): the same rotation and motion to the bit */
        const wb_broad *ba = a->k.pc->bp, *bb = b->k.pc->bp;
        /* and the reference motion with the reaches measured from it (fit_reference) */
        const wb_contacts *ca = a->k.pc, *cb = b->k.pc;
        same = same && memcmp(ca->ref_v, cb->ref_v, sizeof ca->ref_v) == 0 &&
               memcmp(ca->ref_om, cb->ref_om, sizeof ca->ref_om) == 0 &&
               memcmp(ca->ref_c, cb->ref_c, sizeof ca->ref_c) == 0 &&
               memcmp(ca->reach, cb->reach, sizeof(wb_real) * (size_t)a->m.np) == 0;
        same = same && ba && bb && memcmp(ba->mq, bb->mq, sizeof ba->mq) == 0 &&
               memcmp(&ba->mo, &bb->mo, sizeof ba->mo) == 0 && ba->rebuilds == bb->rebuilds && ba->mends == bb->mends;
        if (!same) printf("    frame %d differs\n", f);
    }
    CHECK(same);
    CHECK(a->k.pc->remakes > 0); /* the scene does leave the paths */
    CHECK_EQ(b->k.pc->lanes, 0);
    CHECK_EQ(b->k.pc->bp->fits_simd, 0);
#if defined(__x86_64__) && defined(__GNUC__) && !defined(WB_FLOAT)
    if (__builtin_cpu_supports("avx2")) CHECK(a->k.pc->lanes > 0 && a->k.pc->bp->fits_simd > 0);
    else printf("# no AVX2 here: both ran the scalar check\n");
#endif
    wb_world_destroy(a);
    wb_world_destroy(b);
}

TEST(recheck_simd_bits)
{
    simd_bits(32);
    simd_bits(31);
}

/* A hand-built sheet of loose particles (the default radius over a spacing of 1.57 cm)
 * dropped onto the floor, where it lies: its kept list holds pairs that never come within
 * reach. The list's gaps (broadphase.c, list_gaps) skip testing them; the same world
 * with every pair tested each frame must stay the same to the bit, and the skip must
 * have run (the gaps kill it otherwise) */
static wb_world *loose_sheet(int n, wb_real y, wb_real r)
{
    wb_world *w = floor_world();
    if (!w) return NULL;
    wb_status st;
    const wb_real s = 2.0 / 127;
    for (int j = 0; j < n; j++)
        for (int i = 0; i < n; i++) {
            const wb_real p[3] = { i * s, y, j * s };
            wb_particle_add(w, p, NULL, 1.0 / (n * n), r);
        }
    const wb_distance_def d = wb_distance_default_def();
    for (int j = 0; j < n; j++)
        for (int i = 0; i < n; i++) {
            if (i < n - 1) wb_distance_add(w, j * n + i, j * n + i + 1, &d, &st);
            if (j < n - 1) wb_distance_add(w, j * n + i, (j + 1) * n + i, &d, &st);
        }
    return w;
}

TEST(contact_list_gaps_same_bits)
{
    wb_world *a = loose_sheet(40, 0.05, 0.02), *b = loose_sheet(40, 0.05, 0.02);
    REQUIRE(a && b);
    REQUIRE(wb__contacts_make(a) && wb__contacts_make(b));
    b->k.pc->no_gaps = 1;
    int same = 1;
    for (int f = 0; f < 40 && same; f++) {
        wb_world_step(a);
        wb_world_step(b);
        same = same_bits(a, b) &&
               a->k.pc->n == b->k.pc->n && a->k.pc->nd == b->k.pc->nd &&
               memcmp(a->k.pc->ij, b->k.pc->ij, sizeof(int32_t) * 2 * (size_t)a->k.pc->n) == 0;
        if (!same) printf("    frame %d differs\n", f);
    }
    CHECK(same);
    REQUIRE(a->k.pc->bp && b->k.pc->bp);
    printf("# listed pairs %d; calls through the gaps %lld, with no pair tested %lld\n", a->k.pc->bp->list.n,
           (long long)a->k.pc->bp->gap_calls, (long long)a->k.pc->bp->gap_quiet);
    CHECK(a->k.pc->bp->list.n > 1000); /* pairs listed that no call tested */
    CHECK(a->k.pc->bp->gap_quiet > 20);
    CHECK_EQ(b->k.pc->bp->gap_calls, 0);
    wb_world_destroy(a);
    wb_world_destroy(b);
}

/* the reference motion fitted in AVX2 (fit_reference) and the speeds it leaves: the loose
 * sheet falls 60 cm as one, so the fit is kept while it falls and dropped once it lies
 * still; the same reference and reaches to the bit as the scalar fit's, either way */
TEST(contact_reference_simd_bits)
{
    wb_world *a = loose_sheet(24, 0.6, 0.02), *b = loose_sheet(24, 0.6, 0.02);
    REQUIRE(a && b);
    b->k.no_simd = 1;
    REQUIRE(wb__contacts_make(a) && wb__contacts_make(b));
    int same = 1, kept = 0, still = 0;
    for (int f = 0; f < 40 && same; f++) {
        wb_world_step(a);
        wb_world_step(b);
        const wb_contacts *ca = a->k.pc, *cb = b->k.pc;
        same = same_bits(a, b) &&
               memcmp(ca->ref_v, cb->ref_v, sizeof ca->ref_v) == 0 &&
               memcmp(ca->ref_om, cb->ref_om, sizeof ca->ref_om) == 0 &&
               memcmp(ca->ref_c, cb->ref_c, sizeof ca->ref_c) == 0 &&
               memcmp(ca->reach, cb->reach, sizeof(wb_real) * (size_t)a->m.np) == 0;
        if (!same) printf("    frame %d differs\n", f);
        kept += ca->ref_v[1] != 0;
        still += ca->ref_v[1] == 0;
    }
    CHECK(same);
    printf("# frames with the reference kept %d, without %d\n", kept, still);
    CHECK(kept > 0 && still > 0);
    wb_world_destroy(a);
    wb_world_destroy(b);
}

/* The rules' search along the links from every particle (add_along) queues in a short
 * sorted run, and goes on as a heap past a few dozen items: the same keys and made-distance
 * bounds as with a heap throughout, for the default radius (every search a run) and a
 * radius of 3 spacings (long queues: some go on as a heap) */
TEST(contact_rules_queue_same_keys)
{
    const wb_real radius[2] = { 0.02, 0.05 };
    for (int k = 0; k < 2; k++) {
        wb_world *a = loose_sheet(30, 0.05, radius[k]), *b = loose_sheet(30, 0.05, radius[k]);
        REQUIRE(a && b);
        REQUIRE(wb__contacts_make(a) && wb__contacts_make(b));
        b->k.pc->along_heap = 1;
        REQUIRE(wb__contact_rules(a) && wb__contact_rules(b));
        const wb_contacts *ca = a->k.pc, *cb = b->k.pc;
        const size_t np = (size_t)a->m.np;
        CHECK(ca->nkeys > 0 && ca->nkeys == cb->nkeys);
        CHECK(memcmp(ca->keys, cb->keys, sizeof *ca->keys * (size_t)ca->nkeys) == 0);
        CHECK(memcmp(ca->near2, cb->near2, sizeof *ca->near2 * np) == 0);
        CHECK(memcmp(ca->far2, cb->far2, sizeof *ca->far2 * np) == 0);
        printf("# radius %g: %d keys, searches gone on as a heap %lld of %zu\n", radius[k], ca->nkeys,
               (long long)ca->along_heaps, np);
        if (k == 0) CHECK_EQ(ca->along_heaps, 0);
        else CHECK(ca->along_heaps > 0);
        CHECK_EQ(cb->along_heaps, (int64_t)np);
        wb_world_destroy(a);
        wb_world_destroy(b);
    }
}
