/* contact.h: particle-particle contacts' per-frame scratch (contact.c owns it; the broad
 * phase, broadphase.c, fills its candidate list) and the depth rule every contact uses. */
#ifndef WB_CONTACT_H
#define WB_CONTACT_H

#include <stdint.h>

#include "core.h"

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

/* w->k.pc (core.h) */
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
    wb_real *near2, *far2; /* (np) squared made distances: every particle of i's body or
                              graph made closer to it than near2 is a rest neighbour, and no
                              constraint joins it to one made farther than far2 (the rule
                              decided without a search of the keys) */
    int32_t cap_near2, cap_far2;
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
    int32_t span;          /* substeps one list of this frame covers (broadphase.c: list_span) */
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
    uint8_t *grown;        /* (np) 1: the particle left its reach this frame (its margin grows
                              with the frame's remakes; the others' stays) */
    int32_t cap_grown;
    int64_t lanes;         /* particles the substeps' check found on their paths in AVX2 (tests) */
    int32_t remakes_frame; /* ... within this frame */
    int32_t *fix, cap_fix; /* the particles that moved too far */
    int32_t *add, cap_add; /* (2 x) their new pairs */
    int32_t *fixed, cap_fixed, nfixed; /* the particles mended this frame */
    int no_recheck;        /* tests: the list is not checked within the frame */
    wb_real *spd;          /* (np x 2) scratch: speeds from the fitted and the still reference */
    int32_t cap_spd;
    int no_simd;           /* the kept list's motion fitted without AVX2 (the world's no_simd) */
    int along_heap;        /* tests: the rules' searches along the links queue in a heap from
                              the start (broadphase.c, add_along) */
    int64_t along_heaps;   /* tests: those searches that went on as a heap */
    int no_gaps;           /* tests: the kept list's every pair tested every call (broadphase.c) */
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

/* particles p and q are of two groups contact.c moves apart whole for an overlap they were
 * made with (made_ab, as its latest projection found them): their contacts are its to take
 * out (tricontact.c, vbd_contact.c) */
int wb__contacts_made(const wb_world *w, int32_t p, int32_t q);

/* rest neighbours (never a contact pair) include pairs made in touch: created r_i + r_j
 * apart, to round-off (a rope of spacing s and radius 2 s: its particles four apart), they
 * would touch at its slightest bend */
#define WB_REST_TOUCH ((wb_real)(1 + 1e-9))

/* the body a particle is in for the contact rules: its group, or for a loose particle its
 * graph (the loose particles its constraints reach), as -1 - the graph's least particle */
static inline int32_t wb__graph_of(const wb_contacts *c, const wb_model *m, int32_t i)
{
    return m->group[i] > 0 ? m->group[i] : -1 - c->graph[i];
}

#endif
