/* pool.c: the persistent thread pool (pool.h).
 *
 * Posting a job: the claim word `ticket` (generation << 32 | next part) is first closed
 * to the new generation, then the job is written, then the ticket opens at part 0 and
 * `gen` (the word sleeping workers wait on) moves on. A worker reads gen, the job, then
 * claims a part by a compare-and-swap on the ticket that only succeeds while the ticket
 * still carries the generation it read: a worker that wakes after its job is over (or
 * reads a job being rewritten) claims nothing. The caller claims parts the same way and
 * returns when `done` counts them all, so it never waits for a worker that has not
 * started (a busy core), only for parts already running.
 *
 * A worker the OS preempts in the middle of a part (its core shared with another
 * process) holds the caller until it runs again, often milliseconds. The caller keeps
 * the account: each job's time against what the caller alone would have taken at its
 * own pace (`credit`, capped; a worker on the caller's own CPU counts as a loss). When
 * it falls below zero, the pool has lost time overall, and the caller runs the jobs
 * alone for a while ("solo": the same parts inline, so the same results), twice as long
 * each time it happens again, halved after as long a time without. A stall the gains have paid for (an oversubscribed machine,
 * where two threads also get two shares of the CPU) does not make it go solo. */
#include "pool.h"

#include <errno.h>
#include <limits.h>
#include <pthread.h>
#include <sched.h>
#include <signal.h>
#include <stdatomic.h>
#include <stdlib.h>
#include <time.h>
#include <unistd.h>
#include <linux/futex.h>
#include <sys/syscall.h>

#if defined(__x86_64__) || defined(__i386__)
#include <immintrin.h>
#define cpu_relax() _mm_pause()
#else
#define cpu_relax() ((void)0)
#endif

/* how long an idle thread spins before it sleeps: jobs of one substep follow each
 * other within microseconds; a futex wake-up costs 5-50 us */
#define SPIN_NS 5000
#define MAX_PARTS_PER_THREAD 4
/* a job is late when it took this much longer than the caller alone would have (a
 * preempted worker costs milliseconds; a futex wake-up or an uneven split, microseconds);
 * the credit going below minus this much makes the caller go solo */
#define LATE_NS 50000
/* the most the gains of good jobs can pay for a late one */
#define CREDIT_MAX_NS 2000000
/* how long the caller then runs alone: from 2 ms, doubled each time up to 256 ms (then a
 * preempted worker costs at most about 1% of the time), halved again after as long
 * without going solo */
#define SOLO_MIN_NS 2000000
#define SOLO_MAX_NS 256000000
/* after no worker could be started: the next attempt at most this much later */
#define RETRY_NS ((int64_t)10000000000)

struct wb_pool {
    _Alignas(64) _Atomic uint32_t gen;    /* futex word of the workers */
    _Atomic int sleepers;                 /* workers in (or entering) futex_wait on gen */
    _Atomic int stop;
    _Alignas(64) _Atomic uint64_t ticket; /* gen << 32 | next unclaimed part */
    _Alignas(64) _Atomic uint32_t done;   /* parts finished; futex word of the caller */
    _Atomic int caller_sleeps;
    _Atomic int caller_cpu, same_cpu;     /* a worker ran a part on the caller's CPU */
    /* the job, written before gen moves (atomics: a late worker may read while it changes) */
    _Alignas(64) _Atomic(wb_pool_run_fn) run;
    _Atomic(wb_pool_for_fn) rfor;
    void *_Atomic ctx;
    _Atomic int32_t n, nparts;
    int threads, in_job;
    int64_t jobs, solo_jobs, late_jobs;
    int64_t solo_until, solo_ns, calm_since, credit; /* ns (now_ns); see judge */
    int fixed;                            /* wb__pool_adapt(p, 0): never solo */
    pthread_t *th;
    int nth;                              /* workers started */
    int64_t retry_at;                     /* nth == 0: when to try starting them again */
    int failure_told;
};

/* pthread_create, or a test's stand-in */
int (*wb__pool_thread_create)(pthread_t *, const pthread_attr_t *, void *(*)(void *), void *) = pthread_create;

static void futex_wait(_Atomic uint32_t *addr, uint32_t val)
{
    syscall(SYS_futex, (uint32_t *)addr, FUTEX_WAIT_PRIVATE, val, NULL, NULL, 0);
}

static void futex_wake(_Atomic uint32_t *addr, int n)
{
    syscall(SYS_futex, (uint32_t *)addr, FUTEX_WAKE_PRIVATE, n, NULL, NULL, 0);
}

static int64_t now_ns(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (int64_t)ts.tv_sec * 1000000000 + ts.tv_nsec;
}

/* one part of the job posted as generation g */
static void run_part(wb_pool *p, wb_pool_run_fn run, wb_pool_for_fn rfor, void *ctx, int32_t n, int32_t np, int32_t k)
{
    if (run) run(ctx, k, np);
    else rfor(ctx, (int32_t)((int64_t)n * k / np), (int32_t)((int64_t)n * (k + 1) / np));
    if (atomic_fetch_add(&p->done, 1) + 1 == (uint32_t)np && atomic_load(&p->caller_sleeps))
        futex_wake(&p->done, 1);
}

/* claim and run parts of generation g until none is left; the number run */
static int work(wb_pool *p, uint32_t g, int is_worker)
{
    wb_pool_run_fn run = atomic_load_explicit(&p->run, memory_order_relaxed);
    wb_pool_for_fn rfor = atomic_load_explicit(&p->rfor, memory_order_relaxed);
    void *ctx = atomic_load_explicit(&p->ctx, memory_order_relaxed);
    const int32_t n = atomic_load_explicit(&p->n, memory_order_relaxed);
    const int32_t np = atomic_load_explicit(&p->nparts, memory_order_relaxed);
    /* any value read above from a newer job implies the ticket closed to it (seqlock) */
    atomic_thread_fence(memory_order_acquire);
    uint64_t t = atomic_load(&p->ticket);
    for (int ran = 0;; ran++) {
        for (;;) {
            if ((uint32_t)(t >> 32) != g || (int64_t)(uint32_t)t >= np) return ran;
            if (atomic_compare_exchange_weak(&p->ticket, &t, t + 1)) break;
        }
        /* (sched_getcpu reads the kernel's rseq area: a few ns) */
        if (is_worker && ran == 0) {
            const int cpu = sched_getcpu(); /* -1: unknown, not the same */
            if (cpu >= 0 && cpu == atomic_load_explicit(&p->caller_cpu, memory_order_relaxed))
                atomic_store_explicit(&p->same_cpu, 1, memory_order_relaxed);
        }
        run_part(p, run, rfor, ctx, n, np, (int32_t)(uint32_t)t);
        t = atomic_load(&p->ticket);
    }
}

static void *worker(void *arg)
{
    wb_pool *p = arg;
    uint32_t seen = 0; /* gen at creation: a thread that starts late still sees every change */
    for (;;) {
        uint32_t g = atomic_load(&p->gen);
        if (g == seen) {
            const int64_t t0 = now_ns();
            for (int i = 1; (g = atomic_load(&p->gen)) == seen; i++) {
                cpu_relax();
                if ((i & 63) == 0 && now_ns() - t0 > SPIN_NS) {
                    atomic_fetch_add(&p->sleepers, 1);
                    while ((g = atomic_load(&p->gen)) == seen) futex_wait(&p->gen, seen);
                    atomic_fetch_sub(&p->sleepers, 1);
                    break;
                }
            }
        }
        seen = g;
        if (atomic_load(&p->stop)) return NULL;
        work(p, g, 1);
    }
}

/* p->nth == 0, no job running: start the workers (some may fail: the others share the
 * parts); none at all: the jobs run inline until retry_at */
static void start_workers(wb_pool *p)
{
    /* the workers block every signal: the process's handlers run on the caller's thread */
    sigset_t all, old;
    sigfillset(&all);
    pthread_sigmask(SIG_SETMASK, &all, &old);
    for (int i = 0; i < p->threads - 1; i++) {
        if (wb__pool_thread_create(&p->th[i], NULL, worker, p) != 0) break;
        p->nth++;
    }
    pthread_sigmask(SIG_SETMASK, &old, NULL);
    if (p->nth == 0) p->retry_at = now_ns() + RETRY_NS;
}

wb_pool *wb__pool_create(int threads)
{
    if (threads <= 1) return NULL;
    wb_pool *p = calloc(1, sizeof *p);
    if (!p) return NULL;
    p->threads = threads;
    p->solo_ns = SOLO_MIN_NS;
    /* trusted at first: a slow first job (threads starting, pages touched) is no reason
     * to run alone; a worker held up again and again still uses this up within a job */
    p->credit = CREDIT_MAX_NS;
    p->th = calloc((size_t)threads, sizeof *p->th);
    if (!p->th) { free(p); return NULL; }
    start_workers(p);
    return p;
}

void wb__pool_destroy(wb_pool *p)
{
    if (!p) return;
    atomic_store(&p->stop, 1);
    atomic_fetch_add(&p->gen, 1);
    futex_wake(&p->gen, INT_MAX);
    for (int i = 0; i < p->nth; i++) pthread_join(p->th[i], NULL);
    free(p->th);
    free(p);
}

int wb__pool_threads(const wb_pool *p) { return p ? p->threads : 1; }

int64_t wb__pool_jobs(const wb_pool *p) { return p ? p->jobs : 0; }
int64_t wb__pool_solo_jobs(const wb_pool *p) { return p ? p->solo_jobs : 0; }
int64_t wb__pool_late_jobs(const wb_pool *p) { return p ? p->late_jobs : 0; }
int wb__pool_workers(const wb_pool *p) { return p ? p->nth : 0; }
void wb__pool_adapt(wb_pool *p, int on) { if (p) p->fixed = !on; }

int wb__pool_failure_news(wb_pool *p)
{
    if (!p || p->nth > 0 || p->failure_told) return 0;
    p->failure_told = 1;
    return 1;
}

wb_pool *wb__pool_get(wb_pool **slot, int threads)
{
    if (threads <= 1) return NULL; /* kept for when the count goes up again */
    wb_pool *p = *slot;
    if (p && p->threads == threads) {
        /* no worker started: once in a while (not at every loop) try again */
        if (p->nth == 0 && !p->in_job && now_ns() >= p->retry_at) start_workers(p);
        return p;
    }
    wb__pool_destroy(p);
    *slot = wb__pool_create(threads);
    return *slot;
}

/* after a job handed to the threads (t0 posted, t1 the caller out of parts after running
 * kc of them, t2 all done, `same`: a worker ran on the caller's CPU): the gain against
 * the caller alone at its pace goes to the credit; below -LATE_NS: solo for solo_ns, and
 * the next time twice that */
static void judge(wb_pool *p, int64_t t0, int64_t t1, int64_t t2, int kc, int np, int same)
{
    const int64_t alone = kc > 0 ? (t1 - t0) * np / kc : t1 - t0;
    int64_t gain = alone - (t2 - t0);
    /* two threads taking turns on one core (the caller's parts then include the worker's
     * turns, so `alone` says nothing): measured 10-13% slower than one thread */
    if (same && gain > -(t2 - t0) / 8) gain = -(t2 - t0) / 8;
    p->credit += gain;
    if (p->credit > CREDIT_MAX_NS) p->credit = CREDIT_MAX_NS;
    if (gain < -LATE_NS) p->late_jobs++;
    if (p->credit < -LATE_NS && !p->fixed) {
        p->credit = 0;
        p->solo_until = t2 + p->solo_ns;
        p->calm_since = p->solo_until;
        if (p->solo_ns < SOLO_MAX_NS) p->solo_ns *= 2;
    } else if (t2 - p->calm_since > p->solo_ns && p->solo_ns > SOLO_MIN_NS) {
        p->solo_ns /= 2;
        p->calm_since = t2;
    }
}

/* the caller alone this time: no worker, or solo after a late job */
static int solo(wb_pool *p)
{
    if (p->nth > 0 && (p->solo_until == 0 || now_ns() >= p->solo_until)) {
        p->solo_until = 0;
        return 0;
    }
    p->solo_jobs++;
    return 1;
}

static void post(wb_pool *p, wb_pool_run_fn run, wb_pool_for_fn rfor, void *ctx, int32_t n, int32_t np)
{
    const uint32_t g = atomic_load_explicit(&p->gen, memory_order_relaxed) + 1;
    const int64_t t0 = now_ns();
    p->in_job = 1;
    p->jobs++;
    /* close the claims to the old job before the job changes (see work) */
    atomic_store(&p->ticket, (uint64_t)g << 32 | 0xffffffffu);
    atomic_thread_fence(memory_order_release);
    atomic_store_explicit(&p->run, run, memory_order_relaxed);
    atomic_store_explicit(&p->rfor, rfor, memory_order_relaxed);
    atomic_store_explicit(&p->ctx, ctx, memory_order_relaxed);
    atomic_store_explicit(&p->n, n, memory_order_relaxed);
    atomic_store_explicit(&p->nparts, np, memory_order_relaxed);
    atomic_store(&p->done, 0);
    atomic_store_explicit(&p->caller_cpu, sched_getcpu(), memory_order_relaxed);
    atomic_store_explicit(&p->same_cpu, 0, memory_order_relaxed);
    atomic_store(&p->ticket, (uint64_t)g << 32);
    atomic_store(&p->gen, g);
    if (atomic_load(&p->sleepers) > 0) futex_wake(&p->gen, INT_MAX);
    const int kc = work(p, g, 0);
    const int64_t t1 = now_ns();
    /* the parts claimed by workers and still running */
    uint32_t d = atomic_load(&p->done);
    if (d != (uint32_t)np) {
        for (int i = 1; (d = atomic_load(&p->done)) != (uint32_t)np; i++) {
            cpu_relax();
            if ((i & 63) == 0 && now_ns() - t1 > SPIN_NS) {
                atomic_store(&p->caller_sleeps, 1);
                while ((d = atomic_load(&p->done)) != (uint32_t)np) futex_wait(&p->done, d);
                atomic_store(&p->caller_sleeps, 0);
                break;
            }
        }
    }
    judge(p, t0, t1, now_ns(), kc, np, atomic_load_explicit(&p->same_cpu, memory_order_relaxed));
    p->in_job = 0;
}

void wb__pool_run(wb_pool *p, wb_pool_run_fn fn, void *ctx)
{
    if (!p || p->in_job || solo(p)) {
        /* inline, the same parts in order: per-part results do not change */
        const int np = wb__pool_threads(p);
        for (int k = 0; k < np; k++) fn(ctx, k, np);
        return;
    }
    post(p, fn, NULL, ctx, 0, p->threads);
}

void wb__pool_for(wb_pool *p, int32_t n, int32_t grain, wb_pool_for_fn fn, void *ctx)
{
    if (n <= 0) return;
    if (grain < 1) grain = 1;
    int64_t np = n / grain;
    if (p && np > (int64_t)p->threads * MAX_PARTS_PER_THREAD) np = (int64_t)p->threads * MAX_PARTS_PER_THREAD;
    if (!p || p->in_job || np < 2 || solo(p)) {
        fn(ctx, 0, n); /* callers' results do not depend on the ranges (pool.h) */
        return;
    }
    post(p, NULL, fn, ctx, n, (int32_t)np);
}
