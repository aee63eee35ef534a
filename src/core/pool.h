/* pool.h: a persistent thread pool for the core's parallel loops (replaces OpenMP).
 *
 * A job is cut into a fixed number of parts decided by the sizes alone (never by timing),
 * and the parts are claimed by whichever thread gets to them first: the caller takes
 * part after part itself, so a worker that is slow to wake (the other core busy) costs
 * nothing but the part it has already claimed. Workers spin a few microseconds after a
 * job, then sleep on a futex: an idle pool costs no CPU, a busy core is not robbed.
 * A job that a preempted worker held up (it took longer than the caller alone would
 * have) makes the caller run the next jobs alone for a while (2 ms, doubling up to 256 ms
 * while it happens again): when the other core is busy, 2 threads cost about what one does.
 *
 * Results are bit-identical for any thread count as long as a part's work does not
 * depend on which thread runs it nor on the other parts (callers: a colour batch shares
 * no movable particle; per-part buffers merged in part order afterwards).
 *
 * A NULL pool is a valid one-thread pool everywhere. Not for use from several threads at
 * once (one world, one caller); a job that calls the pool again runs inline. */
#ifndef WB_POOL_H
#define WB_POOL_H
#include <pthread.h>
#include <stdint.h>

typedef struct wb_pool wb_pool;

/* threads in total, the caller included (workers: threads - 1); NULL when threads <= 1
 * (or no memory). When no worker thread can be started the pool still counts `threads`
 * but runs everything on the caller (wb__pool_get tries again at most every 10 s) */
wb_pool *wb__pool_create(int threads);
void wb__pool_destroy(wb_pool *p);
int wb__pool_threads(const wb_pool *p); /* 1 for NULL */

/* *slot as a pool of `threads` threads: kept when it has that many, else replaced
 * (created lazily, the first time a world runs with threads > 1) */
wb_pool *wb__pool_get(wb_pool **slot, int threads);

/* fn(ctx, part, nparts) for part = 0 .. nparts - 1, nparts = wb__pool_threads(p) (per-part
 * buffers: part is not the identity of a thread; two parts may run on one thread) */
typedef void (*wb_pool_run_fn)(void *ctx, int part, int nparts);
void wb__pool_run(wb_pool *p, wb_pool_run_fn fn, void *ctx);

/* fn(ctx, lo, hi) over contiguous ranges covering [0, n) once each. Runs inline on the
 * caller as one range [0, n) when n < 2 grain (waking threads for a tiny loop costs more
 * than the loop); else cut into at most 4 ranges per thread of >= grain indices each */
typedef void (*wb_pool_for_fn)(void *ctx, int32_t lo, int32_t hi);
void wb__pool_for(wb_pool *p, int32_t n, int32_t grain, wb_pool_for_fn fn, void *ctx);

/* jobs handed to the threads so far; jobs big enough for them that the caller ran alone
 * (no worker, or after a late job); late jobs (a worker held the caller up); workers
 * running (tests, stats) */
int64_t wb__pool_jobs(const wb_pool *p);
int64_t wb__pool_solo_jobs(const wb_pool *p);
int64_t wb__pool_late_jobs(const wb_pool *p);
int wb__pool_workers(const wb_pool *p);

/* on = 0: every job big enough goes to the workers, never solo (tests that must
 * exercise the threads on a busy machine); 1, the default: solo after late jobs */
void wb__pool_adapt(wb_pool *p, int on);

/* 1 once per pool when no worker thread could be started (to report it once), else 0 */
int wb__pool_failure_news(wb_pool *p);

/* how workers are started: pthread_create (a test replaces it to make it fail) */
extern int (*wb__pool_thread_create)(pthread_t *, const pthread_attr_t *, void *(*)(void *), void *);

#endif
