/* test_pool.c: the thread pool (src/core/pool.c, white-box).
 *
 * What a caller relies on: every index of a wb__pool_for runs exactly once, in ranges
 * that tile [0, n); every part of a wb__pool_run runs once with nparts = the threads;
 * tiny loops run inline on the caller; thousands of jobs in a row (workers spinning,
 * sleeping, waking late) lose nothing; a pool can be destroyed at once or while idle;
 * a worker held up in a part (as if preempted) delays nothing but that job, after which
 * the caller runs the jobs alone for a while, then uses the workers again; a pool whose
 * threads cannot be started runs everything on the caller, tries again not at every call
 * and is reported once; and a world gives the same bits with 1, 2 and 3 threads. */
#include <errno.h>
#include <pthread.h>
#include <stdatomic.h>
#include <stdlib.h>
#include <time.h>

#include "core/core.h"
#include "core/broadphase.h"
#include "core/tricontact.h"
#include "test.h"

typedef struct cover {
    _Atomic int32_t *hits;   /* per index */
    _Atomic int32_t calls;   /* ranges handed out */
    _Atomic int32_t bad;     /* empty or out-of-range ranges */
    int32_t n;
} cover;

static void cover_range(void *ctx, int32_t lo, int32_t hi)
{
    cover *c = ctx;
    c->calls++;
    if (!(0 <= lo && lo < hi && hi <= c->n)) { c->bad++; return; }
    for (int32_t i = lo; i < hi; i++) c->hits[i]++;
}

TEST(pool_for_runs_every_index_once)
{
    static const int32_t sizes[] = { 0, 1, 2, 3, 7, 63, 64, 65, 100, 1000, 4097, 100003 };
    static const int32_t grains[] = { 1, 2, 7, 64, 1000, 1 << 20 };
    _Atomic int32_t *hits = calloc(100003, sizeof *hits);
    REQUIRE(hits);
    for (int threads = 1; threads <= 4; threads++) {
        wb_pool *p = wb__pool_create(threads);
        CHECK(threads == 1 ? p == NULL : p != NULL);
        CHECK_EQ(wb__pool_threads(p), threads);
        for (size_t s = 0; s < sizeof sizes / sizeof sizes[0]; s++)
            for (size_t g = 0; g < sizeof grains / sizeof grains[0]; g++) {
                const int32_t n = sizes[s];
                for (int32_t i = 0; i < n; i++) hits[i] = 0;
                cover c = { hits, 0, 0, n };
                wb__pool_for(p, n, grains[g], cover_range, &c);
                int32_t wrong = 0;
                for (int32_t i = 0; i < n; i++) wrong += hits[i] != 1;
                CHECK_EQ(wrong, 0);
                CHECK_EQ(c.bad, 0);
                /* an empty range calls nothing; at most 4 ranges per thread, each >= grain */
                CHECK(n == 0 ? c.calls == 0 : c.calls >= 1 && c.calls <= 4 * threads);
                CHECK(c.calls <= 1 || n / c.calls >= grains[g]);
            }
        wb__pool_destroy(p);
    }
    free(hits);
}

typedef struct parts {
    _Atomic int32_t hit[8];
    _Atomic int32_t wrong_n;
    int expect_n;
} parts;

static void part_fn(void *ctx, int part, int nparts)
{
    parts *q = ctx;
    if (nparts != q->expect_n || part < 0 || part >= 8) { q->wrong_n++; return; }
    q->hit[part]++;
}

TEST(pool_run_every_part_once)
{
    for (int threads = 1; threads <= 5; threads++) {
        wb_pool *p = wb__pool_create(threads);
        for (int rep = 0; rep < 200; rep++) {
            parts q = { .expect_n = threads };
            wb__pool_run(p, part_fn, &q);
            CHECK_EQ(q.wrong_n, 0);
            for (int k = 0; k < 8; k++) CHECK_EQ(q.hit[k], k < threads);
        }
        wb__pool_destroy(p);
    }
}

/* a tiny loop runs on the caller's thread, without a job */
typedef struct who { pthread_t caller; _Atomic int32_t other; } who;
static void who_range(void *ctx, int32_t lo, int32_t hi)
{
    (void)lo; (void)hi;
    who *o = ctx;
    if (!pthread_equal(o->caller, pthread_self())) o->other++;
}

TEST(pool_tiny_loops_stay_on_the_caller)
{
    wb_pool *p = wb__pool_create(2);
    REQUIRE(p);
    who o = { pthread_self(), 0 };
    const int64_t j0 = wb__pool_jobs(p);
    wb__pool_for(p, 100, 64, who_range, &o); /* < 2 grains */
    wb__pool_for(p, 1, 1, who_range, &o);
    CHECK_EQ(wb__pool_jobs(p), j0);
    CHECK_EQ(o.other, 0);
    wb__pool_for(p, 128, 64, who_range, &o); /* 2 grains: a job */
    CHECK_EQ(wb__pool_jobs(p), j0 + 1);
    wb__pool_destroy(p);
}

/* many small jobs in a row, with pauses now and then so that the workers go to sleep
 * and wake up late: no part lost or run twice, the sums exact */
typedef struct sum { const int32_t *v; _Atomic int64_t total; } sum;
static void sum_range(void *ctx, int32_t lo, int32_t hi)
{
    sum *s = ctx;
    int64_t t = 0;
    for (int32_t i = lo; i < hi; i++) t += s->v[i];
    s->total += t;
}

TEST(pool_many_successive_jobs)
{
    enum { N = 4096 };
    int32_t *v = malloc(N * sizeof *v);
    REQUIRE(v);
    int64_t want = 0;
    for (int32_t i = 0; i < N; i++) { v[i] = (i * 7919) % 1013; want += v[i]; }
    for (int threads = 2; threads <= 3; threads++) {
        wb_pool *p = wb__pool_create(threads);
        REQUIRE(p);
        wb__pool_adapt(p, 0); /* tiny jobs: on a busy machine the pool would go solo */
        int32_t wrong = 0;
        for (int rep = 0; rep < 20000; rep++) {
            sum s = { v, 0 };
            const int32_t n = 1 + rep % N;
            wb__pool_for(p, n, 1 + rep % 17, sum_range, &s);
            int64_t w = 0;
            for (int32_t i = 0; i < n; i++) w += v[i];
            wrong += s.total != w;
            if (rep % 2000 == 0) nanosleep(&(struct timespec){ 0, 200000 }, NULL); /* workers sleep */
        }
        CHECK_EQ(wrong, 0);
        CHECK(wb__pool_jobs(p) > 10000);
        sum s = { v, 0 };
        wb__pool_for(p, N, 1, sum_range, &s);
        CHECK_EQ(s.total, want);
        wb__pool_destroy(p);
    }
    free(v);
}

TEST(pool_destroyed_at_once_or_idle)
{
    /* at once: the workers may not have started yet (they must still see the stop) */
    for (int i = 0; i < 50; i++) wb__pool_destroy(wb__pool_create(2 + i % 3));
    /* idle: after a job, once the workers sleep */
    wb_pool *p = wb__pool_create(3);
    REQUIRE(p);
    parts q = { .expect_n = 3 };
    wb__pool_run(p, part_fn, &q);
    nanosleep(&(struct timespec){ 0, 20000000 }, NULL);
    wb__pool_destroy(p);
    CHECK_EQ(q.hit[0] + q.hit[1] + q.hit[2], 3);
    /* the slot helper: the same pool for the same count, replaced for another, NULL for 1 */
    wb_pool *slot = NULL;
    wb_pool *a = wb__pool_get(&slot, 2);
    CHECK(a != NULL && wb__pool_get(&slot, 2) == a);
    CHECK(wb__pool_get(&slot, 1) == NULL);
    CHECK_EQ(wb__pool_threads(wb__pool_get(&slot, 3)), 3);
    wb__pool_destroy(slot);
    wb__pool_destroy(NULL);
}

/* a job that calls the pool again runs that call inline (no deadlock) */
typedef struct nest { wb_pool *p; _Atomic int32_t *hits; int32_t n; } nest;
static void nest_part(void *ctx, int part, int nparts)
{
    nest *o = ctx;
    cover c = { o->hits + part * o->n, 0, 0, o->n };
    (void)nparts;
    wb__pool_for(o->p, o->n, 1, cover_range, &c);
}

TEST(pool_nested_call_runs_inline)
{
    wb_pool *p = wb__pool_create(2);
    REQUIRE(p);
    _Atomic int32_t hits[2 * 100] = { 0 };
    nest o = { p, hits, 100 };
    wb__pool_run(p, nest_part, &o);
    int32_t wrong = 0;
    for (int i = 0; i < 200; i++) wrong += hits[i] != 1;
    CHECK_EQ(wrong, 0);
    wb__pool_destroy(p);
}

/* a worker held up 200 ms in the first part it claims, as if the OS had preempted it:
 * the job still runs every part once; it counts as late, so the next jobs run on the
 * caller alone (solo), and after the solo time the workers take parts again */
static int64_t mono_ns(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (int64_t)ts.tv_sec * 1000000000 + ts.tv_nsec;
}

typedef struct held {
    pthread_t caller;
    _Atomic int32_t hits[8], on_worker;
    _Atomic int delayed, quick; /* quick: the caller's parts do not wait either */
    _Atomic int64_t woke; /* when the held-up worker went on */
} held;

static void held_range(void *ctx, int32_t lo, int32_t hi)
{
    held *h = ctx;
    for (int32_t i = lo; i < hi; i++) h->hits[i]++;
    if (!pthread_equal(h->caller, pthread_self())) {
        h->on_worker++;
        int no = 0;
        if (atomic_compare_exchange_strong(&h->delayed, &no, 1)) {
            nanosleep(&(struct timespec){ 0, 200000000 }, NULL);
            h->woke = mono_ns();
        }
    } else if (!h->quick) {
        /* the caller's parts take a while: time for the worker to wake and claim one */
        const int64_t t = mono_ns();
        while (mono_ns() - t < 300000) {}
    }
}

TEST(pool_held_up_worker_then_solo)
{
    wb_pool *p = wb__pool_create(2);
    REQUIRE(p);
    held h = { .caller = pthread_self() };
    int32_t wrong = 0;
    for (int attempt = 0; attempt < 200 && !h.delayed; attempt++) {
        for (int i = 0; i < 8; i++) h.hits[i] = 0;
        wb__pool_for(p, 8, 1, held_range, &h);
        for (int i = 0; i < 8; i++) wrong += h.hits[i] != 1;
    }
    CHECK_EQ(wrong, 0);
    REQUIRE(h.delayed); /* a worker took a part (and was held up) */
    CHECK_EQ(wb__pool_late_jobs(p), 1);
    /* right after it: the caller alone, the same ranges covered (solo lasts 2 ms; a test
     * thread itself held up longer than that proves nothing either way) */
    const int64_t jobs = wb__pool_jobs(p), solos = wb__pool_solo_jobs(p);
    for (int i = 0; i < 8; i++) h.hits[i] = 0;
    h.on_worker = 0;
    h.quick = 1;
    wb__pool_for(p, 8, 1, held_range, &h);
    if (mono_ns() - h.woke < 1500000) {
        CHECK_EQ(wb__pool_solo_jobs(p), solos + 1);
        CHECK_EQ(wb__pool_jobs(p), jobs);
        CHECK_EQ(h.on_worker, 0);
    }
    for (int i = 0; i < 8; i++) wrong += h.hits[i] != 1;
    CHECK_EQ(wrong, 0);
    /* the per-part form too: the same parts, inline */
    parts q = { .expect_n = 2 };
    wb__pool_run(p, part_fn, &q);
    CHECK_EQ(q.wrong_n, 0);
    CHECK(q.hit[0] == 1 && q.hit[1] == 1);
    /* after the solo time the workers are used again */
    nanosleep(&(struct timespec){ 0, 20000000 }, NULL);
    const int64_t j1 = wb__pool_jobs(p);
    wb__pool_for(p, 8, 1, held_range, &h);
    CHECK_EQ(wb__pool_jobs(p), j1 + 1);
    wb__pool_destroy(p);
}

/* a 64 x 64 cloth with bending links, self-contacts and a sphere, over a plane: every
 * pooled loop of a step (distance batches, collisions of 4096 particles, the contact
 * broad phase of the two cloths) with 1, 2 and 3 threads gives the same bits */
static wb_world *cloth_world(int threads)
{
    wb_world_def d = wb_world_default_def();
    d.threads = threads;
    wb_world *w = wb_world_create(&d);
    if (!w) return NULL;
    wb_cloth_def c = wb_cloth_default_def();
    c.origin[0] = -1; c.origin[1] = 0.3; c.origin[2] = -1;
    c.size[0] = c.size[1] = 2;
    c.res[0] = c.res[1] = 64;
    c.bend_links = 1e-3;
    c.link.compliance = 1e-6;
    wb_body body;
    if (wb_cloth(w, &c, &body) != WB_OK) { wb_world_destroy(w); return NULL; }
    /* a second cloth falling on the first: particle pairs for the broad phase */
    c.origin[1] = 0.4;
    c.res[0] = c.res[1] = 40;
    if (wb_cloth(w, &c, &body) != WB_OK) { wb_world_destroy(w); return NULL; }
    wb_collider_def s = wb_collider_default_def(WB_SHAPE_SPHERE);
    s.radius = 0.4;
    s.friction = 0.3;
    wb_collider_add(w, &s, NULL);
    wb_collider_def pl = wb_collider_default_def(WB_SHAPE_PLANE);
    pl.offset = -0.5;
    wb_collider_add(w, &pl, NULL);
    return w;
}

TEST(pool_world_identical_for_1_2_3_threads)
{
    wb_world *w[3];
    for (int t = 0; t < 3; t++) REQUIRE((w[t] = cloth_world(t + 1)));
    for (int f = 0; f < 30; f++)
        for (int t = 0; t < 3; t++) {
            wb_world_step(w[t]);
            wb__pool_adapt(w[t]->pool, 0); /* the threads in every job, even on a busy machine */
        }
    CHECK(w[0]->pool == NULL);
    CHECK(w[1]->pool != NULL && w[2]->pool != NULL);
    CHECK(wb__pool_jobs(w[1]->pool) > 0); /* the pool really ran the loops */
    CHECK(wb_world_stats(w[0]).contacts > 0);
    CHECK(w[0]->k.pc->n > 0); /* the cloths met: pairs from the broad phase */
    CHECK(wb_world_hash(w[0]) == wb_world_hash(w[1]));
    CHECK(wb_world_hash(w[0]) == wb_world_hash(w[2]));
    CHECK(memcmp(w[0]->s.x, w[2]->s.x, sizeof(wb_real) * 3 * (size_t)w[0]->m.np) == 0);
    for (int t = 0; t < 3; t++) wb_world_destroy(w[t]);
}

/* no worker thread can be started (pthread_create fails): the pool runs every loop on
 * the caller with the same parts, does not try again at every call (once in 10 s), and a
 * world reports it once (a warning) and gives the bits of one thread */
static _Atomic int create_calls, create_ok;
static int failing_create(pthread_t *t, const pthread_attr_t *a, void *(*f)(void *), void *arg)
{
    if (create_calls++ < create_ok) return pthread_create(t, a, f, arg);
    return EAGAIN;
}

TEST(pool_without_threads_runs_inline)
{
    int (*real)(pthread_t *, const pthread_attr_t *, void *(*)(void *), void *) = wb__pool_thread_create;
    wb__pool_thread_create = failing_create;
    create_calls = 0;
    create_ok = 0;
    wb_pool *p = wb__pool_create(3);
    REQUIRE(p);
    CHECK_EQ(wb__pool_threads(p), 3);
    CHECK_EQ(wb__pool_workers(p), 0);
    CHECK_EQ(create_calls, 1); /* gave up at the first failure */
    _Atomic int32_t hits[1000] = { 0 };
    cover c = { hits, 0, 0, 1000 };
    wb__pool_for(p, 1000, 10, cover_range, &c);
    int32_t wrong = 0;
    for (int i = 0; i < 1000; i++) wrong += hits[i] != 1;
    CHECK_EQ(wrong, 0);
    who o = { pthread_self(), 0 };
    wb__pool_for(p, 1000, 10, who_range, &o);
    CHECK_EQ(o.other, 0);
    parts q = { .expect_n = 3 };
    wb__pool_run(p, part_fn, &q);
    CHECK(q.wrong_n == 0 && q.hit[0] == 1 && q.hit[1] == 1 && q.hit[2] == 1);
    CHECK_EQ(wb__pool_jobs(p), 0);
    CHECK_EQ(wb__pool_solo_jobs(p), 3);
    /* the slot keeps it and does not try again at every call */
    wb_pool *slot = p;
    for (int i = 0; i < 1000; i++) CHECK(wb__pool_get(&slot, 3) == p);
    CHECK_EQ(create_calls, 1);
    CHECK_EQ(wb__pool_failure_news(p), 1);
    CHECK_EQ(wb__pool_failure_news(p), 0);
    wb__pool_destroy(p);
    /* some started, not all: those share the parts, nothing to report */
    create_calls = 0;
    create_ok = 1;
    p = wb__pool_create(3);
    REQUIRE(p);
    CHECK_EQ(wb__pool_workers(p), 1);
    CHECK_EQ(wb__pool_failure_news(p), 0);
    for (int i = 0; i < 1000; i++) hits[i] = 0;
    wb__pool_for(p, 1000, 10, cover_range, &c);
    wrong = 0;
    for (int i = 0; i < 1000; i++) wrong += hits[i] != 1;
    CHECK_EQ(wrong, 0);
    wb__pool_destroy(p);
    /* a world: one warning, the bits of one thread */
    create_calls = 0;
    create_ok = 0;
    wb_world *w1 = cloth_world(1), *w3 = cloth_world(3);
    REQUIRE(w1 && w3);
    for (int f = 0; f < 10; f++) wb_world_step(w1), wb_world_step(w3);
    CHECK(w3->pool != NULL && wb__pool_workers(w3->pool) == 0);
    CHECK_EQ(create_calls, 1);
    CHECK_EQ(wb_world_warnings(w1), 0);
    CHECK_EQ(wb_world_warnings(w3), 1);
    CHECK(strstr(wb_world_last_warning(w3), "no worker thread") != NULL);
    CHECK(wb_world_hash(w1) == wb_world_hash(w3));
    wb_world_destroy(w1);
    wb_world_destroy(w3);
    wb__pool_thread_create = real;
}
