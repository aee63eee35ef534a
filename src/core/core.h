/* core.h: the world's internals, shared by the core files only.
 *
 * Model / state split (MuJoCo's mjModel / mjData): the model holds what a step does
 * not change (masses, topology, compliances, collider shapes, colour batches); the
 * state holds what it does (positions, velocities, plastic rest lengths, broken flags,
 * collider poses, time). The step reads the model and writes the state; the solver
 * cache (packed batches, multipliers) is scratch rebuilt from both. */
#ifndef WB_CORE_H
#define WB_CORE_H

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "wobble.h"
#include "vec.h"
#include "shape.h"
#include "bend.h"
#include "shape_match.h"
#include "pool.h"

/* a substep's prediction, per particle: damping, gravity, x += h v (x_prev = x first; a
 * particle with w = 0 stays). solver.c's pass and collide.c's fused one share it, so
 * that fused or not the operations and the bits are the same */
typedef struct wb_predict {
    wb_real keep, g[3], h; /* velocity kept against damping; gravity x h; the substep */
} wb_predict;
static inline void wb__predict_one(const wb_predict *p, wb_real w, wb_real *restrict x, wb_real *restrict xp,
                                   wb_real *restrict v)
{
    v3_copy(xp, x);
    if (w == 0) return;
    /* drag on the velocity only: a body at rest still weighs m g */
    v[0] = v[0] * p->keep + p->g[0]; v[1] = v[1] * p->keep + p->g[1]; v[2] = v[2] * p->keep + p->g[2];
    x[0] += p->h * v[0]; x[1] += p->h * v[1]; x[2] += p->h * v[2];
}

/* ---- model ----------------------------------------------------------------------- */
typedef struct wb_model {
    wb_world_def def;

    int32_t np, cap_p;
    wb_real *inv_mass;     /* (np) as created; 0 = immovable */
    wb_real *w;            /* (np) what the solver uses: 0 while pinned */
    wb_real *radius;       /* (np) */
    uint8_t *pinned;       /* (np) */
    /* contacts (contact.c) */
    int32_t *group;        /* (np) body: 0 = loose (collides with every particle) */
    uint8_t *cflags;       /* (np) WB_CF_* */
    wb_real *cfric;        /* (np) contact friction (Coulomb, static = dynamic) */
    wb_real *x0;           /* (np x 3) where it was created: rest neighbours never collide */

    /* distance constraints by slot; a slot is live while d_gen is odd */
    int32_t nd, cap_d, nd_live;
    int32_t *d_ij;         /* (nd x 2) particles */
    wb_real *d_alpha;      /* (nd) compliance */
    wb_real *d_beta;       /* (nd) damping */
    wb_real *d_yield, *d_creep, *d_break; /* (nd) plasticity and breaking */
    wb_real *d_bforce;     /* (nd) force that breaks it, N; 0 = none */
    uint32_t *d_gen;       /* (nd) generation: odd = live */
    int32_t *d_free;       /* free slots (stack) */
    int32_t nfree;

    /* colliders by slot */
    int32_t nc, cap_c;
    wb_cshape *c_shape; /* (nc) */
    uint32_t *c_gen;       /* (nc) odd = live */

    int topology_dirty;    /* colour batches must be rebuilt */
    uint32_t w_gen;        /* bumped when w changes without a topology change (pin, unpin) */
    size_t charged;        /* bytes charged to def.memory */
    size_t charged_mesh;   /* bytes of mesh colliders' copies, charged to def.memory too */

    /* surfaces: triangles over particles, concatenated */
    int32_t nsurf, cap_surf;
    int32_t *surf_start;   /* (nsurf + 1) triangle ranges */
    int32_t ntri, cap_tri; /* cap_tri counts ints */
    int32_t *tri;          /* (ntri x 3) particle ids */
} wb_model;

/* ---- state ----------------------------------------------------------------------- */
typedef struct wb_collider_pose {
    wb_real p[3], q[4];    /* pose now (set by the script, reached at the end of the next step) */
    wb_real p0[3], q0[4];  /* pose at the end of the last step: start of the next sweep */
    wb_real v[3], om[3];   /* velocities the script set */
} wb_collider_pose;

typedef struct wb_state {
    wb_real *x, *x_prev, *v; /* (np x 3) */
    wb_real *d_rest;       /* (nd) rest lengths (plastic flow changes them) */
    uint8_t *d_broken;     /* (nd) */
    wb_collider_pose *c_pose; /* (nc) */
    double time;
    int64_t frame;
    int64_t warnings;
    char last_warning[160];
} wb_state;

#define WB_CF_COLLIDE 1u     /* collides with other bodies and loose particles */
#define WB_CF_SELF 2u        /* collides with its own body (group > 0) */

/* ---- particle contacts: per-frame scratch (contact.c) -------------------------------- */
/* How much of a contact's overlap ov to correct this substep (contact.c explains why).
 * d0: the overlap it started the substep with (at x_prev, which earlier contacts of the
 * pass may have moved); *left: what the pair was left with by the last substep (at a
 * frame's start, its overlap then if deeper than one step, else 0), updated. Overlap the
 * pair keeps from substep to substep goes at no more than `step` (max_depenetration x h)
 * per substep, whatever pushes it out, so a particle with several such contacts is not
 * pushed out by each at full speed; *slow: what of it goes this substep (the caller moves
 * x_prev with x by it). What was added since it was left: at x_prev (other pairs, the
 * colliders after this pair's projection) in full, *fast (the caller takes its speed out
 * in the velocity pass); since x_prev (the prediction, the links) in full, as a collision.
 * Returns the correction. */
static inline wb_real wb__contact_depth(wb_real ov, wb_real d0, wb_real *left, wb_real step, wb_real *slow,
                                       wb_real *fast)
{
    /* only what is still there is old (a pair that moved apart since has less) */
    d0 = !(d0 > 0) ? 0 : d0 < ov ? d0 : ov;
    const wb_real kept = d0 < *left ? d0 : *left;
    wb_real keep = *left - step;
    keep = !(keep > 0) ? 0 : keep < d0 ? keep : d0;
    *left = keep;
    *slow = kept - keep;
    *fast = d0 - kept;
    return ov - keep;
}

typedef struct wb_contacts {
    int32_t n, cap;        /* candidate pairs of this frame */
    int32_t *ij;           /* (n x 2) i < j, in the broad phase's fixed order */
    int32_t nact, cap_act; /* contacts of the current substep */
    int32_t *act;          /* (nact) candidate index */
    wb_real *act_nd;       /* (nact x 7) normal (i -> j), depth, force, err, mu if sliding */
    int32_t cap_nd;
    wb_real *left;         /* (n) overlap a candidate was left with by its last projection;
                              INFINITY when not known (contact.c: old overlap) */
    int32_t cap_left;
    wb_real *reach;        /* (np) broad-phase reach, < 0 = not a candidate */
    int32_t cap_reach;
    int32_t *skip;         /* (np) broad-phase skip key: a body without self-collision, else 0 */
    int32_t cap_skip;
    struct wb_broad *bp;   /* broad-phase scratch (broadphase.c) */
    uint64_t *keys;        /* sorted (a << 32 | b), each once: the pairs constraints join,
                              which never touch (the ctypes' links) */
    int32_t nkeys, cap_keys;
    int32_t *key_row;      /* (np + 1) keys[key_row[a] .. key_row[a + 1]) are a's (a < b) */
    int32_t cap_key_row;
    int32_t *graph;        /* (np) a loose particle's graph (the least particle of its
                              connected component over the links); its own index in a body */
    int32_t cap_graph;
    int cross;             /* some joined pair is not in one body or one graph: the pair
                              rule asks keys for pairs of two bodies too */
    uint8_t *tcov;         /* (ntri) 1: a triangle of one body that its corners' spheres cover
                              (wb__contact_rules): its own body's points leave it to the
                              particle pairs */
    int32_t cap_tcov;
    int keys_dirty;        /* set when the topology changes */
    uint64_t keys_sig;     /* particles and constraints of each type the keys were built for */
    uint64_t rules_gen;    /* counts the rules' rebuilds (the kept list applies them) */
    int32_t scanned_np;    /* particles when `possible` was worked out */
    int scan_dirty;        /* groups or flags changed since */
    int possible;          /* some pair could collide */
    int32_t last;          /* contacts in the last substep */
    int fresh;             /* a new candidate list: `left` not known yet */
    double broad_ms;       /* broad phase of the last step */
    int32_t *near;         /* (n) the substep's pairs in touch, for its later sweeps
                              (contact.c): an act index, or -(2 k + touching) - 1 */
    int32_t cap_near, nnear, touching;
    int fmoved;            /* the substep's static friction moved a pair (contact.c) */
    wb_real *load;         /* (np) static friction budget of the substep, mu x normal impulse
                              (contact.c's friction pass; pairs' and triangles' together) */
    int32_t cap_load;
    /* each substep checks that no particle moved farther than its reach allowed since the
     * list was made (broadphase.c: wb__contacts_recheck), else the list is made again */
    int check;             /* a list was made this frame: check it */
    int32_t sub;           /* substeps of the frame checked so far */
    wb_real *xf;           /* (np x 3) where the list's reaches were measured from (a particle
                              mended within the frame: where the reference motion below takes
                              to where it was then) */
    int32_t cap_xf;
    /* the reference motion the reaches are measured against (broadphase.c): velocity
     * ref_v and turn ref_om about ref_c, with the world's gravity and drag, from the
     * substep ref_k0 on (the substeps predicted when the list was made) */
    wb_real ref_v[3], ref_om[3], ref_c[3];
    int32_t ref_k0;
    /* (np x 8) each particle's straight path from the list's start, which the substeps
     * check it against: start y (3), allowance eps, velocity u (3), unused; a pair is
     * listed only when the two paths come within r_i + r_j + eps_i + eps_j in the next
     * path_t seconds (broadphase.c) */
    wb_real *path;
    int32_t cap_path;
    wb_real path_t;
    /* the pairs the paths left out (dormant, 2 x nd), each particle's of them (dorm_row:
     * np + 1 offsets into dorm_at, pair indices), which are listed again (dorm_on), and
     * the particles that left their path (off_path: checked against the reference alone) */
    int32_t *dorm, nd, cap_dorm;
    int32_t *dorm_row, cap_dorm_row;
    int32_t *dorm_at, cap_dorm_at;
    uint8_t *dorm_on, *off_path;
    int32_t cap_dorm_on, cap_off_path;
    int32_t *soft, cap_soft;
    int32_t *qs, cap_qs;   /* the dormant pairs a substep lists again */
    int32_t n_old, cap_old;
    int32_t *ij_old;       /* the list before a remake, and what each pair was left with */
    wb_real *left_old;
    int32_t cap_left_old;
    int64_t remakes;       /* lists made again within a frame (tests) */
    int32_t remakes_frame; /* ... within this frame */
    int32_t *fix, cap_fix; /* the particles that moved too far */
    int32_t *add, cap_add; /* (2 x) their new pairs */
    int32_t *fixed, cap_fixed, nfixed; /* the particles mended this frame */
    int no_recheck;        /* tests: the list is not checked within the frame */
    int brute;             /* tests: each substep, every touching pair that may touch is looked
                              for in the list; missed counts those it lacks */
    int64_t missed;
    int32_t *made_ab;      /* (nmade x 2) the body pairs (groups a < b) contact.c moved apart this
                              substep for a made overlap: tricontact.c leaves theirs to it */
    int32_t nmade, cap_made;
    /* (nbm x 3) body pairs (groups a < b) asked whether they were made overlapping, and
     * the answer: derived from x0, so kept until the rules are rebuilt (bm_gen) */
    int32_t *bm, nbm, cap_bm;
    uint64_t bm_gen;
} wb_contacts;

/* rest neighbours (never a contact pair) include pairs made in touch: created r_i + r_j
 * apart, to round-off (a rope of spacing s and radius 2 s: its particles four apart), they
 * would touch at its slightest bend */
#define WB_REST_TOUCH ((wb_real)(1 + 1e-9))
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
/* the body a particle is in for the contact rules: its group, or for a loose particle its
 * graph (the loose particles its constraints reach), as -1 - the graph's least particle */
static inline int32_t wb__graph_of(const wb_contacts *c, const wb_model *m, int32_t i)
{
    return m->group[i] > 0 ? m->group[i] : -1 - c->graph[i];
}

/* grid.c: the sorted grids of the broad phases (broadphase.c, tribroad.c). Cell (i, j, k)
 * of a point is floor((x - o) * inv) per axis, clamped to [0, 1e15] (wb__cell_of), taken
 * modulo nc when wrap is set (points spread over a volume too big for the budget) */
typedef struct wb_grid {
    wb_real o[3], inv;     /* origin, 1 / cell */
    int64_t nc[3];         /* cells per axis */
    int wrap;              /* coordinates wrap around */
} wb_grid;
/* the box of the points of list (n) and their largest reach, and the largest up to big */
void wb__grid_bounds(const wb_real *x, const wb_real *reach, const int32_t *list, int32_t n, wb_real big,
                     wb_real lo[3], wb_real hi[3], wb_real *rmax, wb_real *rn);
/* the median of up to 31 reaches sampled evenly over list (n > 0) */
wb_real wb__grid_typical(const wb_real *reach, const int32_t *list, int32_t n);
/* the grid over the points inside [lo, hi]: cell cs or larger, at most ~2 cells per
 * point (n), wrapping past that */
void wb__grid_shape(wb_grid *g, const wb_real lo[3], const wb_real hi[3], wb_real cs, int32_t n);
/* a coordinate's cell, monotone in v (a search range never misses a cell); clamped so
 * that the cast stays defined for huge or infinite offsets; truncation is floor for
 * c > 0 (and no libm call without SSE4.1) */
static inline int64_t wb__cell_of(wb_real v, wb_real o, wb_real inv)
{
    const wb_real c = (v - o) * inv;
    return c > 0 ? (c < 1e15 ? (int64_t)c : (int64_t)1e15) : 0;
}
/* a point's cell in g, row-major (x fastest) */
static inline int32_t wb__grid_cell(const wb_grid *g, const wb_real *p)
{
    int64_t c[3];
    for (int a = 0; a < 3; a++) {
        c[a] = wb__cell_of(p[a], g->o[a], g->inv);
        if (g->wrap) c[a] %= g->nc[a];
    }
    return (int32_t)(c[0] + g->nc[0] * (c[1] + g->nc[1] * c[2]));
}

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
/* its scratch, kept from frame to frame (defined here so that the world frees it
 * without calling back into broadphase.c) */
typedef struct wb_pairbuf {
    int32_t *ij; int32_t n, cap; int fail;
    int32_t *hit; int32_t cap_hit;     /* broadphase.c: one particle's hits */
} wb_pairbuf;
/* grid.c: n pair buffers (one per thread) in *out, grown as needed, emptied; 0 when out of memory */
int wb__pairbufs(wb_pairbuf **out, int *nout, int n);
/* a rigid motion X -> c + Q (X - C) (Q row-major) */
typedef struct wb_motion { wb_real Q[9], C[3], c[3]; } wb_motion;
struct wb_broad {
    int32_t *cand; int32_t cap_cand;   /* candidates in index order, then the survivors */
    int32_t *cell; int32_t cap_cell;   /* cell of each survivor */
    int32_t *start; int32_t cap_start; /* (cells + 1) counting-sort offsets */
    wb_real *p; int32_t cap_p;         /* sorted: x, y, z, reach */
    int32_t *id; int32_t cap_id;       /* sorted: particle */
    int32_t *key; int32_t cap_key;     /* sorted: skip key */
    struct wb_broad_run *runs; int32_t cap_runs;
    wb_real *boxes; int32_t cap_boxes; /* (lo, hi) of runs' overlaps */
    wb_pairbuf *out; int nout;         /* one per thread */
    int32_t *first; int32_t cap_first; /* (n + 1) sorting the pairs by i */
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
};
static inline void wb__broadphase_free(wb_contacts *c)
{
    wb_broad *b = c->bp;
    free(c->skip);
    c->skip = NULL;
    c->cap_skip = 0;
    free(c->key_row); free(c->path); free(c->dorm); free(c->dorm_row); free(c->dorm_at); free(c->dorm_on);
    free(c->off_path); free(c->soft); free(c->qs);
    c->key_row = c->dorm = c->dorm_row = c->dorm_at = c->soft = c->qs = NULL;
    c->cap_qs = 0;
    c->path = NULL;
    c->dorm_on = c->off_path = NULL;
    c->cap_key_row = c->cap_path = c->cap_dorm = c->cap_dorm_row = c->cap_dorm_at = c->cap_dorm_on = 0;
    c->cap_off_path = c->cap_soft = 0;
    c->nd = 0;
    free(c->xf); free(c->ij_old); free(c->left_old); free(c->fix); free(c->add); free(c->fixed);
    c->xf = c->left_old = NULL;
    c->ij_old = c->fix = c->add = c->fixed = NULL;
    c->cap_xf = c->cap_old = c->cap_left_old = c->cap_fix = c->cap_add = c->cap_fixed = 0;
    if (!b) return;
    free(b->cand); free(b->cell); free(b->start); free(b->p); free(b->id); free(b->key);
    free(b->runs); free(b->boxes); free(b->first);
    free(b->vx); free(b->vr); free(b->vskip); free(b->list.ij); free(b->list.hit);
    free(b->moved); free(b->is_moved); free(b->bad); free(b->mend.ij); free(b->mend.hit);
    for (int t = 0; t < b->nout; t++) free(b->out[t].ij), free(b->out[t].hit);
    free(b->out);
    free(b);
    c->bp = NULL;
}

/* ---- particle-triangle contacts: per-frame scratch (tricontact.c) ------------------- */
typedef struct wb_tricontacts {
    int32_t n, cap;        /* candidates of this frame */
    int32_t *pt;           /* (n x 2) point, triangle; in the order tribroad.c explains */
    int32_t nact, cap_act; /* contacts that corrected positions in the current substep */
    int32_t *act;          /* (nact) candidate index */
    wb_real *act_d;        /* (nact x 10) barycentrics, normal (triangle -> point), depth, force, old
                              overlap, mu if sliding */
    int32_t cap_d;
    wb_real *left;         /* (n) overlap a candidate was left with (wb__contact_depth) */
    int32_t cap_left;
    struct wb_tribroad *bp; /* broad-phase scratch (tribroad.c) */
    int32_t last;          /* contacts in the last substep (corrected or in touch) */
    int fresh;             /* a new candidate list: `left` not known yet */
    double broad_ms;       /* its broad phase in the last step */
} wb_tricontacts;

/* tribroad.c's scratch, kept from frame to frame (defined here so that the world frees it
 * without calling into tribroad.c) */
typedef struct wb_trilevel {
    wb_grid g;             /* its grid */
    wb_real rn;            /* the largest reach of its points */
    int32_t first, count;  /* its points' sorted positions [first, first + count) */
    int64_t start0;        /* its cells' offsets: start[start0 .. start0 + cells] */
} wb_trilevel;
#define WB_TRI_LEVELS 4
struct wb_tribroad {
    wb_real *reach; int32_t cap_reach;   /* (np) a point's reach, < 0 = not a point */
    wb_real *mv; int32_t cap_mv;         /* (np) how far it may move this frame (reach without radius) */
    wb_real *tbox; int32_t cap_tbox;     /* (ntri x 14) box, motion, normal, order cell (tribroad.c) */
    int32_t *tkey; int32_t cap_tkey;     /* (ntri) the body none of whose points may touch it, or 0 */
    int32_t *pc, *tc, *prun, *trun, *tmp; /* points, triangles kept; their stretches (first, end,
                                             run: tribroad.c's make_runs); scratch */
    int32_t cap_pc, cap_tc, cap_prun, cap_trun, cap_tmp;
    struct wb_tribroad_run *runs; int32_t cap_runs;
    wb_real *boxes; int32_t cap_boxes;   /* (lo, hi) of runs' overlaps */
    wb_real *sp; int32_t cap_sp;         /* sorted points: x, y, z, reach */
    int32_t *sid, *skey, *scell; int32_t cap_sid, cap_skey, cap_scell; /* their particle, key, cell */
    int32_t *start; int32_t cap_start;   /* the levels' counting-sort offsets */
    wb_trilevel lv[WB_TRI_LEVELS];
    int nlv;
    wb_pairbuf *out; int nout;           /* (point, triangle) per thread */
    int32_t *first; int32_t cap_first;   /* (np + 1) sorting them by point */
    int32_t *pt2; int32_t cap_pt2;       /* (2 x candidates) the list sorted by point */
    uint64_t *okey; int32_t cap_okey;    /* (candidates) sort keys of the projection's order */
    const wb_real *sr;                   /* the reaches the search runs with */
    /* the quick answer's triangle runs (key, first, end corner), their corners, how many
     * (-1: too many); a copy of what they depend on (triangles, flags, groups) */
    int32_t *qrun, *qcorner, *qtrun; int32_t cap_qrun, cap_qcorner, cap_qtrun, nq; /* qtrun: a triangle's run, -1 */
    uint8_t *kmodel; int32_t cap_kmodel; int64_t kbytes;
    int32_t knp, knt;
    int qvalid, fresh_only;              /* fresh_only: the search every frame (the tests' reference) */
    int qback, qwait;                    /* frames the quick answer waits after it left many points */
    int64_t rebuilds;                    /* for the tests */
};
static inline void wb__tribroad_free(wb_tricontacts *c)
{
    struct wb_tribroad *b = c->bp;
    if (!b) return;
    void *p[] = { b->reach, b->mv, b->tbox, b->tkey, b->pc, b->tc, b->prun, b->trun, b->tmp, b->runs, b->boxes,
                  b->sp, b->sid, b->skey, b->scell, b->start, b->first, b->pt2, b->okey,
                  b->qrun, b->qcorner, b->qtrun, b->kmodel };
    for (size_t i = 0; i < sizeof p / sizeof p[0]; i++) free(p[i]);
    for (int t = 0; t < b->nout; t++) free(b->out[t].ij), free(b->out[t].hit);
    free(b->out);
    free(b);
    c->bp = NULL;
}

/* the closest point of triangle (a, b, c) to p as barycentrics bary (summing to 1) and the
 * point out; returns the squared distance (a degenerate triangle: its nearest edge) */
wb_real wb__tri_closest(const wb_real p[3], const wb_real a[3], const wb_real b[3], const wb_real c[3],
                        wb_real bary[3], wb_real out[3]);
/* the step's three passes, as contact.c's (world.c frees the scratch): the broad phase
 * in tribroad.c, the projection and velocity pass in tricontact.c */
void wb__tricontacts_begin(wb_world *w);
void wb__tricontacts_project(wb_world *w, wb_real h);
void wb__tricontacts_velocity(wb_world *w, wb_real h);

/* ---- solver cache: packed colour batches and per-step scratch ------------------------ */
typedef struct wb_cache {
    int32_t ns;            /* packed constraints (live and not broken) */
    int32_t ncolours;
    int32_t *colour_start; /* (ncolours + 1) batch ranges */
    int32_t serial_start;  /* batches from here on are projected serially (overflow colours) */
    int32_t split_start;   /* the compounds (colour.c's split) fill [split_start, ns) */
    int32_t ncomp;
    int32_t *comp_start;   /* (ncomp + 1) compound bounds in packed order, then s_nsp */
    int32_t *s_nsp;        /* (2 (ns - split_start)) members of its compound at each end */
    int32_t *s_a, *s_b;    /* (ns) particles */
    wb_real *s_rest, *s_alpha, *s_beta; /* (ns) */
    wb_real *s_lambda;     /* (ns) multipliers of the current substep */
    wb_real *s_jac;        /* (ns) Jacobi scale 1/max(n_a, n_b), n = constraints at a movable end */
    /* the vector path's per-constraint data (distance.c), views into the allocations of
     * s_jac (4 ns reals) and s_slot (3 ns int32 + ns bytes), freed with them: */
    wb_real *s_wa, *s_wc;  /* (ns) m.w of each end, refreshed every step (wb__colour) */
    wb_real *s_at;         /* (ns) alpha / h^2 for h = s_at_h */
    uint32_t *s_oa, *s_oc; /* (ns) 3 a, 3 c: the ends' offsets in x */
    uint8_t *s_ok;         /* (ns) 1: wa > 0, wc > 0 and alpha / h^2 finite (no masked case) */
    uint8_t *s_backed;     /* (ns) 1: both ends are corners of volume or tet constraints (a
                              compressed link's lengthening is bounded: distance.c) */
    int32_t s_backed_vt[2]; /* the volume and tet counts s_backed was worked out for */
    wb_real s_at_h;        /* the substep s_at and s_ok are for */
    int32_t *s_slot;       /* (ns) constraint slot of each packed entry */
    int32_t *slot_pack;    /* (nd) packed index of each slot, -1 when not packed */
    int any_damping;
    int s_lambda_stale;    /* s_lambda is the last substep's: the next projection reads it as 0
                              and writes every one (distance.c); force() reads 0 */
    int any_frame_end;     /* a packed distance constraint can break or flow (distance_frame_end) */
    uint32_t s_w_gen;      /* the m.w_gen s_wa, s_wc were copied at */
    wb_real *dx;           /* (np x 3) Jacobi accumulators */
    int32_t *ncount;       /* (np) constraints per particle (for s_jac) */
    wb_real *x_save, *v_save; /* (np x 3) last finite frame, for recovery */
    void *c_sub;           /* (nc) collider poses at the substep's start and end, then (nc)
                              static planes (collide.c); cap_c_sub in bytes */
    int32_t cap_c_sub;
    wb_real *c_left;       /* (np) overlap with the colliders each particle kept (collide.c) */
    int32_t cap_c_left;
    wb_distance_id *breaks;
    int32_t nbreaks, cap_breaks;
    wb_real *c_save;       /* (nc x 7) collider poses at the frame's start, for undo */
    int32_t cap_c_save;
    wb_real h_last;        /* substep length of the last step (force readback) */
    int residual_on;       /* the residual was asked for: each step measures it (query.c) */
    wb_real residual;      /* ... after the last substep's iterations (-1: not yet) */
    int (*interrupt)(void *);
    void *interrupt_ud;
    int32_t last_contacts;
    wb_contacts pc;        /* particle-particle contacts (contact.c) */
    wb_tricontacts tc;     /* particle-triangle contacts (tricontact.c) */
    int64_t projections;
    double step_ms, solve_ms;
    int no_fuse;           /* tests: the plain order, the next substep's prediction never
                              fused into the collision pass (solver.c), nor the static-plane
                              fast path taken (collide.c); the results must not change */
    int no_simd;           /* tests: the one-plane pass (collide.c) without its AVX2 groups
                              of four; the results must not change */
    int64_t fused;         /* substeps predicted in the collision pass so far (tests) */
    int32_t nonfinite;     /* the last substep's pass scanned x and v (solver.c): the first
                              non-finite particle, -1 none; -2 when it did not scan */
    /* the bodies whose angular momentum the solve keeps (momentum.c) */
    int32_t *mc_body;      /* (np) body of each particle, -1 none */
    int32_t *mc_root;      /* (bodies) first particle of each */
    double *mc_acc;        /* (bodies x 16) sums; [0] < 0: held from outside the solve */
    uint8_t *mc_pinned;    /* (bodies) has an immovable particle, as of m.w_gen mc_wgen */
    int32_t *mc_end;       /* (bodies) one past its last particle when its particles are
                              consecutive (a builder's body), else -1 */
    int32_t cap_mc_body, cap_mc_root, cap_mc_acc, cap_mc_pinned, cap_mc_end, mc_nbody, mc_free;
    int32_t mc_scattered;  /* bodies whose particles are not consecutive (end -1) */
    int mc_built, mc_changed;
    uint32_t mc_wgen;
    int64_t mc_sig[8];     /* what the bodies were found for (besides m.topology_dirty) */
    /* the blow-up check at a frame's end (solver.c) */
    int32_t bl_np;         /* x_save holds the last frame's end (or its start: an undone frame)
                              for this many particles */
    wb_real bl_v0;         /* the fastest particle's squared speed at the frame's start */
    wb_real bl_pin;        /* the farthest the script moved a pinned particle, squared, and */
    int bl_moved;          /* whether it moved a movable one, since the last frame's check */
    wb_real bl_user;       /* the fastest speed given from outside (scripts, new particles) */
    wb_real bl_vend;       /* the fastest particle at the last frame's end */
    int bl_have;           /* bl_vend is known (a step ended since the world was made or loaded) */
    int bl_warned;         /* the blow-up was reported (once per world) */
    int32_t bl_hot;        /* consecutive frames with a particle past the lower limit */
    int bl_armed;          /* a blow-up was found: the lower limit holds from then on */
    double bl_given;       /* time the script last gave the world energy (made constraints,
                              moved particles, changed settings) */
    uint32_t bl_wgen;      /* m.w_gen then */
    wb_world_def bl_def;   /* the settings then */
} wb_cache;

struct wb_world {
    wb_model m;
    wb_state s;
    wb_cache k;
    wb_bends bend;         /* bending constraints (bend.c): model, state and cache */
    struct wb_volumes *vol; /* volume constraints (volume.h), NULL until the first */
    struct wb_neos *neo;    /* Neo-Hookean tets (tet.h), NULL until the first */
    wb_smatch sm;          /* shape-matching clusters (shape_match.c) */
    wb_pressures pr;       /* pressure constraints (pressure.c) */
    struct wb_attaches *att; /* attachments (attach.h), NULL until the first */
    struct wb_grabs *grab;  /* grabs (grab.h), NULL until the first */
    struct wb_tethers *teth; /* tethers (tether.h), NULL until the first */
    struct wb_rigids *rb;  /* rigid bodies (rigid.h), NULL until the first */
    struct wb_vbd *vbd;    /* the VBD solver's cache (vbd.c), NULL until a step with it */
    wb_pool *pool;         /* the threads (pool.h), NULL until a step runs with threads > 1 */
    size_t charged_self;   /* the struct and its worker threads, charged to def.memory (world.c) */
};

/* The vector paths' switches (distance.c, bend.c, tet.c, momentum.c: wb__*_simd): *state
 * (-1 until decided) set to on where the build and the CPU have AVX2; returns it. The
 * vector paths give the scalar loops' bits, so this only picks the faster. */
#if defined(__x86_64__) && defined(__GNUC__) && !defined(WB_FLOAT)
#define WB_HAVE_AVX2 1
#endif
static inline int wb__simd_set(int *state, int on)
{
#ifdef WB_HAVE_AVX2
    __builtin_cpu_init();
    const int v = on && __builtin_cpu_supports("avx2");
#else
    const int v = 0;
    (void)on;
#endif
    __atomic_store_n(state, v, __ATOMIC_RELAXED);
    return v;
}

/* internal entry points */
wb_status wb__colour(wb_world *w);                 /* distance.c: rebuild the distance batches if dirty */
/* momentum.c: once per step before the types' prepare (0: out of memory, nothing kept this
 * step); after each substep's solve, every free body's angular momentum back as it was */
int wb__momentum_prepare(wb_world *w);
void wb__momentum_restore(wb_world *w, wb_real h);
/* momentum.c: om = I^-1 L, I the inertia tensor of a set of points whose second moments
 * about their mass centre are S (xx yy zz xy xz yz): the turn that carries angular
 * momentum L; 0 when singular or not finite (broadphase.c's reference motion too) */
void wb__turn_rate(const double S[6], const double L[3], double om[3]);
/* colour.c: greedy colouring of n constraints of k particles each (constraint i joins
 * idx[k i .. k i + k - 1]), mirror images alike (colour.c's header); those live() refuses
 * get WB_NO_COLOUR, the others a colour in [0, WB_MAX_COLOURS] (WB_MAX_COLOURS: the serial
 * overflow batch), counted in count. 0 when out of memory */
#define WB_NO_COLOUR 255
/* With split (not NULL, mirror keys on): the groups of mirror images that share a movable
 * particle (links meeting on a mirror plane), which no colouring can keep alike, are not
 * coloured (WB_SPLIT_COLOUR, not counted) but returned as compounds: each a set of images
 * joined through shared particles, to be projected together from the same positions
 * (distance.c). split->member (n slots) gets them compound by compound in visiting order,
 * split->comp_start (n + 1 slots) the ncomp + 1 compound bounds into member. */
#define WB_SPLIT_COLOUR 254
typedef struct wb_split {
    int32_t n, first, ncomp; /* members, coloured constraints (visit_order's), compounds */
    int32_t *member, *comp_start;
} wb_split;
int wb__colour_greedy(const wb_model *m, const int32_t *idx, int k, int32_t n,
                      int (*live)(const void *ud, int32_t i), const void *ud, uint8_t *colour,
                      int32_t count[WB_MAX_COLOURS + 1], wb_split *split);
/* colour.c, tests: on = 0 colours in creation order (as before mirror keys), 1 with mirror
 * keys (the default) from the next colouring on; returns the previous setting. Not
 * thread-safe: call it between steps */
int wb__colour_symmetric(int on);
/* batch ranges from the counts: colour_start (ncolours + 1), the first serial batch, and
 * start[c] the first packed index of colour c; returns the packed total */
int32_t wb__colour_ranges(const int32_t count[WB_MAX_COLOURS + 1], int32_t *colour_start, int32_t *ncolours,
                          int32_t *serial_start, int32_t start[WB_MAX_COLOURS + 1]);
wb_status wb__bend_reserve(wb_world *w, int64_t extra); /* bend.c: after it, extra bends add without failing */
/* bend.c: the dihedral angle of the bend over particles p[0..3] at positions x; *ok = 0
 * when a triangle is degenerate */
wb_real wb__bend_angle_of(const wb_real *x, const int32_t *p, int *ok);
/* bend.c: the interior edges of a triangle list (each shared by exactly two triangles), as
 * hinges p1 p2 p3 p4 into out (room for 3 ntri / 2 x 4), in edge order; -1 when out of memory */
int32_t wb__bend_hinges(const int32_t *tri, int32_t ntri, int32_t *out);
/* collide.c: collisions, then v = (x - x_prev)/h, friction and restitution; then, per
 * particle in the same pass, the next substep's prediction when next != NULL, or (scan)
 * the finiteness check of x and v into k.nonfinite. 0 when out of memory (nothing done) */
int wb__collide_and_update(wb_world *w, wb_real h, wb_real f0, wb_real f1, const wb_predict *next, int scan);
void wb__collider_pose_at(const wb_collider_pose *cp, wb_real t, wb_real p[3], wb_real q[4]);
/* collide.c: a mesh collider's copy charged to / given back to the memory budget (and freed) */
int wb__mesh_charge(wb_world *w, const struct wb_colmesh *cm);
void wb__mesh_release(wb_world *w, wb_cshape *s);
/* contact.c: broad phase once per frame, projection per substep, velocity pass after
 * the velocities are updated */
void wb__contacts_begin(wb_world *w);
/* a builder's particles first..first+count as a body: a new contact group of its own,
 * colliding with others, not with itself, no contact friction (the binding sets those) */
wb_status wb__body_finish(wb_world *w, int32_t first, int32_t count, wb_body *out);
void wb__contacts_project(wb_world *w, wb_real h);
void wb__contacts_velocity(wb_world *w, wb_real h);
/* contact.c: static friction of the substep's pair and triangle contacts, after both
 * projections (per particle: its contacts' normal corrections bound what it may stick
 * with); tricontact.c: the triangle contacts' part of it */
void wb__contacts_friction(wb_world *w, wb_real h);
/* after it, the pairs in touch swept again (contact.c) */
void wb__contacts_settle(wb_world *w, wb_real h);
void wb__tricontacts_load(wb_world *w, wb_real h, wb_real *load);
void wb__tricontacts_static(wb_world *w, wb_real *load);
wb_status wb__reserve(wb_world *w, int64_t np_extra, int64_t nd_extra); /* world.c */
/* A Neo-Hookean body's damping (builders.c, tets.c): a dashpot along a tet edge of rest
 * length `length`, a link whose spring is 1e-4 of the edge's own stiffness E L (so E stays
 * E to about 1e-4 per link) and whose damping beta acts in full: with alpha~ >> 1/m the
 * XPBD damping of eq. 26 is a dashpot of beta N s/m whatever alpha is (distance.c: gamma /
 * alpha~ = beta h). Inline: both builders use it and neither calls the other's file. */
static inline wb_distance_def wb__dashpot_def(const wb_distance_def *link, wb_real young, wb_real length)
{
    wb_distance_def d = *link;
    d.compliance = 1 / ((wb_real)1e-4 * young * length);
    d.yield = d.creep = d.break_strain = d.break_force = 0;
    return d;
}
wb_status wb__surface_reserve(wb_world *w, int32_t ntri);
/* world.c: the world's pool for its current thread count (NULL: one thread); created
 * lazily, the same pool from call to call. A cache: callable on a const world */
wb_pool *wb__world_pool(const wb_world *w);
void *wb__grow(void *ptr, int32_t *cap, int32_t need, size_t elem); /* world.c: realloc helper */
/* world.c, the one budget routine: charge `want` bytes in place of *charged to the world's
 * memory budget (def.memory); 0 (nothing charged) when it would pass the limit */
int wb__charge(wb_world *w, size_t *charged, size_t want);
/* one array of a structure of arrays: where its pointer is, the bytes of an element */
typedef struct { void **p; size_t elem; } wb_soa;
/* world.c: each of the n arrays reallocated to cap elements; WB_ERR_NOMEM when one fails
 * (the arrays grown before it are merely larger, all still valid) */
wb_status wb__soa_resize(const wb_soa *arr, size_t n, int64_t cap);
/* world.c: a capacity for need (> cap) elements: cap (first when 0) doubled until it
 * holds them, at most WB_MAX_CONSTRAINTS */
int32_t wb__grown_cap(int32_t cap, int64_t need, int32_t first);
#define WB_SOA_RESIZE(arr, cap) wb__soa_resize((arr), sizeof(arr) / sizeof((arr)[0]), (cap))
void wb__set_error(const char *fmt, ...);
void wb__warn(wb_world *w, const char *fmt, ...);

#endif
