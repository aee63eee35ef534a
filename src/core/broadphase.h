/* broadphase.h: the particle pairs' broad phase (broadphase.c): its entry points, the
 * contact rules, and its scratch kept from frame to frame. */
#ifndef WB_BROADPHASE_H
#define WB_BROADPHASE_H

#include <stdlib.h>

#include "contact.h"
#include "grid.h"
#include "pool.h"

/* broadphase.c: the contact rules' data (keys, graph, cross) brought up to date with the
 * constraints and groups; 0 when out of memory. wb__joined: a constraint joins i and j */
int wb__contact_rules(wb_world *w);
int wb__joined(const wb_contacts *c, int32_t i, int32_t j);
/* at a substep (the frame's sub-th, step h): 0 when the list holds; when some particle
 * moved past what its reach allowed, 2 when its pairs were added to the list in place
 * (with left NaN, and the rest of left moved along when the list had it), 1 when the
 * list was made again for the rest of the frame (the old one in ij_old, n_old); -1 when
 * out of memory (the list is then empty).
 * wb__contacts_brute: the tests' count of touching pairs the list lacks (brute) */
int wb__contacts_recheck(wb_world *w, wb_real h);
void wb__contacts_brute(wb_world *w);
/* broadphase.c: every pair i < j with |x_i - x_j| < reach_i + reach_j (particles with
 * reach < 0 or a non-finite position left out; pairs with one nonzero skip key too,
 * skip may be NULL), each once, in (i, j) order (so the same for any thread count);
 * keep(ud, i, j) filters them (NULL: all; called from several threads
 * at once). A sorted grid, linear in n. Appends to c->ij; -1 when out of memory */
typedef struct wb_broad wb_broad;
int32_t wb__broadphase(wb_contacts *c, const wb_real *x, const wb_real *reach, const int32_t *skip,
                       int32_t n, wb_pool *pool, int (*keep)(void *ud, int32_t i, int32_t j), void *ud);
/* the same pairs from a neighbour list kept from call to call in c->bp and rebuilt (by
 * wb__broadphase) only when some particle moved past its skin (from the motion they
 * share), the particles' reach >= 0 or skip keys changed, or keep's rules did (gen: a
 * number that changes with them; keep is applied when the list is built); keep_now
 * (NULL: none) filters each call's pairs (broadphase.c) */
int32_t wb__broadphase_kept(wb_contacts *c, const wb_real *x, const wb_real *reach, const int32_t *skip,
                            int32_t n, wb_pool *pool, int (*keep)(void *ud, int32_t i, int32_t j), uint64_t gen,
                            int (*keep_now)(void *ud, int32_t i, int32_t j), void *ud);
/* a rigid motion X -> c + Q (X - C) (Q row-major) */
typedef struct wb_motion { wb_real Q[9], C[3], c[3]; } wb_motion;
struct wb_broad {
    int32_t *cand; int32_t cap_cand;   /* candidates in index order, then the survivors */
    int32_t *cell; int32_t cap_cell;   /* cell of each survivor */
    int32_t *start; int32_t cap_start; /* (cells + 1) counting-sort offsets */
    wb_real *p; int32_t cap_p;         /* sorted: x, y, z, reach */
    wb_real *rowr; int32_t cap_rowr;   /* (rows) each x-row's largest ordinary reach, -1: none */
    int32_t *id; int32_t cap_id;       /* sorted: particle */
    int32_t *key; int32_t cap_key;     /* sorted: skip key */
    struct wb_broad_run *runs; int32_t cap_runs;
    wb_real *boxes; int32_t cap_boxes; /* (lo, hi) of runs' overlaps */
    wb_pairbuf *out; int nout;         /* one per thread */
    int32_t *first; int32_t cap_first; /* (n + 1) sorting the pairs by i */
    int32_t *by_j; int32_t cap_by_j;   /* (2 pairs) the pairs sorted by j, then stably by i */
    int32_t *cnt; int32_t cap_cnt;     /* (n + 1) counts for sorting by j */
    /* the kept list (wb__broadphase_kept): positions, reaches with the skin (-1: left
     * out) and skip keys it was built with, its pairs (keep not applied) */
    int32_t vn;                        /* particles it was built for; 0: none */
    wb_real *vx, *vr; int32_t cap_vx, cap_vr;
    int32_t *vskip; int32_t cap_vskip;
    wb_pairbuf list;
    int64_t rebuilds;                  /* for the tests */
    int bare;                          /* the list was built without a skin, keep applied */
    wb_motion mo;                      /* the motion it was last used under (list_valid) */
    uint64_t vgen;                     /* keep's rules it was built with */
    int used;                          /* it was used again since it was built */
    /* particles whose list position and reach were made again since it was built (the
     * grid has them where it was built), a flag each; scratch for the mends */
    int32_t *moved, nmoved, cap_moved;
    uint8_t *is_moved; int32_t cap_is_moved;
    int32_t *bad, cap_bad;
    wb_pairbuf mend;
    int64_t mends;                     /* for the tests */
    int bare_left, bare_run;           /* lists still to build without a skin; how many
                                          the last run had */
    wb_real mq[4];                     /* its rotation, the next fit's start */
    /* the grid of the last search (cand, start, p, id), when it is the kept list's
     * (lgrid): its shape, particles, whether they are all the candidates (none culled),
     * and their largest reach */
    int lgrid, lfull;
    wb_grid lg;
    int32_t lm;
    wb_real lrmax;
    /* half the least list distance of each particle to its partners in the list (list
     * positions; INFINITY: none), for the current list (gap_ok): a pair can only pass the
     * call's distance test where one of its particles moved that far from the list,
     * reach included (hot; list_strays) */
    wb_real *half; int32_t cap_half;
    uint8_t *hot; int32_t cap_hot;
    int gap_ok;
    int64_t fits_simd;                 /* tests: motions fitted in AVX2 */
    int64_t gap_calls, gap_quiet;      /* tests: calls filtered by hot particles; of them,
                                          with none (no pair tested) */
};
/* its scratch freed (contact.c's teardown; the tests' own lists) */
void wb__broadphase_free(wb_contacts *c);

#endif
