/* vbd.c: Vertex Block Descent (Chen, Liu, Yang, Yuksel, "Vertex Block Descent", SIGGRAPH
 * 2024), the solver = "vbd" (docs/physics.md, "VBD").
 *
 * Each substep minimises the implicit-Euler energy
 *     sum_i m_i / (2 h^2) |x_i - y_i|^2 + sum_c E_c(x)
 * (y: the prediction, x + h v + h^2 g) by Gauss-Seidel over the vertices: each takes one
 * Newton step on its own 3 x 3 block, holding the others. Vertices of one colour share
 * no constraint, so a colour runs in parallel, the same bits on any thread count.
 *
 * A constraint of compliance alpha is the energy C^2 / (2 alpha), as in XPBD, so a material
 * means the same in both solvers. A hard one (alpha = 0) has no finite energy: it goes
 * through the augmented Lagrangian of Giles, Diaz, Yuksel ("Augmented Vertex Block
 * Descent", SIGGRAPH 2025), k C^2 / 2 + lambda C, lambda growing by k C after the sweeps
 * and carried from substep to substep (warm start) so a hanging chain holds its tension
 * instead of finding it again every substep.
 *
 * The energies are the types' (wb_vbd_type, vbd.h: distance links, bends and Neo-Hookean
 * tets, each in its own file, called in the order of wb__vbd_ctypes), and particle pairs
 * with one immovable end (vbd_contact.c). This file is the solver: the vertex colouring,
 * the sweeps, the inertia term and the Newton step. The other types are projected as in
 * XPBD after each sweep, and contacts (all of them, again: what the sweeps left),
 * colliders and rigid bodies follow the sweeps as in the XPBD step (solver.c). */
#include <assert.h>
#include <stdlib.h>
#include <string.h>

#include "pool.h"
#include "rigid.h"
#include "snapshot.h"
#include "vbd.h"
#include "contact.h"
#include "tricontact.h"
#include "vbd_contact.h"

#define VBD_TYPES 4 /* room for wb__vbd_nctypes */

struct wb_vbd {
    int32_t np;            /* the particles it was built for */
    void *part[VBD_TYPES]; /* each served type's part (wb__vbd_ctypes order) */
    int32_t built[VBD_TYPES]; /* the constraints (slots) each part was built for */
    /* the parts with constraints, whose vertex steps the sweep calls */
    int nact;
    const wb_vbd_type *act[VBD_TYPES];
    void *act_part[VBD_TYPES];
    uint8_t *held;         /* (np) 1: a served constraint holds the vertex */
    uint8_t *fold;         /* (np) 1: the vertex starts the substep touching a movable particle
                              of its own body (touching(); the types read it as k.vbd_fold) */
    int nfold;             /* how many do */
    uint8_t *col;          /* (np) each vertex's colour */
    int32_t *order;        /* (np) the vertices by colour */
    int32_t *colour_start; /* (ncolours + 1) ranges of order */
    int32_t ncolours;
    int serial_last;       /* the last colour holds vertices that may share a constraint (more
                              colours than a mask holds): it runs on one thread */
    wb_real *y;            /* (np x 3) the substep's prediction */
    wb_real residual;      /* the last sweep's largest step, m */
    double *tsum;          /* (bodies x 4) each free body's mass and sum m (x - y), then
                              (bodies) 1: it may touch an immovable particle, then (bodies
                              x 3) its momentum step's translation (keep_momentum) */
    int32_t cap_tsum;
    double *csum;          /* (bodies x 17) a free body's contacts in the vertex steps
                              (keep_momentum) */
    uint8_t *bmove;        /* (bodies) 1: its friction goes in its momentum step */
    uint8_t *bclear;       /* (bodies) 1: free and clear of every collider this substep
                              (clear_of_colliders) */
    double *bball;         /* (bodies x 8) its bounds' scratch (clear_of_colliders) */
    int32_t *bvar;         /* (bodies) its index among the free bodies that may touch another
                              free body's movable particle, moved with them
                              (wb__vbdc_couple); -1, or VBD_BY_HELD */
    int32_t nvar;
    double *vsum;          /* (nvar x (WB_VBDC_BS + 14)) their sums, moves, turns and rounding
                              (couple) */
    wb_vbdc *ct;           /* the particle contacts in the vertex steps (vbd_contact.c) */
    int ct_on;             /* ct holds this substep's */
    size_t charged;        /* the struct's and its arrays' bytes charged to def.memory, but for
                              the parts (their own), tsum, csum, bmove, bclear, bball,
                              bvar, vsum (charged_t) and ct (its own) */
    size_t charged_t;
    int nomem;             /* the last solve ran out of memory (the budget refused its
                              scratch): the step undoes the frame (wb__vbd_failed) */
};

#define VBD_COLOURS 64
/* at most this many Newton steps for a free body's translation with its contacts
 * (keep_momentum) */
#define VBD_MOVE_STEPS 8
/* two bodies with a pair closer than this times r_i + r_j where the substep starts (or
 * in contact.c's list of bodies made inside each other) were made inside each other:
 * contact.c parts them, they are not moved together; decided here alone (touching()). A
 * pair of bodies moved together that only starts a substep deeper than depenetration
 * parts in it is left to the projection pair by pair (vbd_contact.c's starts_deep). (Measured,
 * two blocks made with coincident layers: a particle flung at 1.24 m/s with them moved
 * together; 0.5 of the contact distance: 0.88, as before; 0.95: blocks made interleaved
 * gained 49 J where 12 are allowed) */
#define VBD_MADE_DEEP ((wb_real)0.5)
/* bvar of a free body in no coupled step that may touch a held body's movable particle:
 * that pair is the projection's, as a collider's, and the body starts its sweeps as one
 * near a collider (start_guess) */
#define VBD_BY_HELD (-2)

_Static_assert(VBD_COLOURS <= 64, "a vertex's neighbours' colours are one bit each of a uint64_t");

void wb__vbd_destroy(wb_world *w)
{
    struct wb_vbd *v = w->vbd;
    if (!v) return;
    for (int t = 0; t < wb__vbd_nctypes; t++)
        if (v->part[t]) wb__vbd_ctypes[t]->vbd->free(w, v->part[t]);
    free(v->held);
    free(v->fold);
    free(v->col);
    free(v->order);
    free(v->colour_start);
    free(v->y);
    free(v->tsum);
    free(v->csum);
    free(v->bmove);
    free(v->bclear);
    free(v->bball);
    free(v->bvar);
    free(v->vsum);
    wb__vbdc_destroy(w, v->ct);
    wb__charge(w, &v->charged, 0);
    wb__charge(w, &v->charged_t, 0);
    free(v);
    w->vbd = NULL;
}

/* the cache with an empty part of each served type, not built (np -1) */
static struct wb_vbd *make(wb_world *w)
{
    /* every type with hooks is in the list (a type left out would be neither minimised nor
     * projected) */
    int n = 0;
    for (int t = 0; t < wb__nctypes; t++) n += wb__ctypes[t]->vbd != NULL;
    assert(n == wb__vbd_nctypes && wb__vbd_nctypes <= VBD_TYPES);
    (void)n;
    struct wb_vbd *v = calloc(1, sizeof *v);
    if (!v) return NULL;
    w->vbd = v;
    v->np = -1;
    for (int t = 0; t < wb__vbd_nctypes; t++)
        if (!(v->part[t] = wb__vbd_ctypes[t]->vbd->make())) {
            wb__vbd_destroy(w);
            return NULL;
        }
    return v;
}

/* ---- the model: the types' parts and the colouring ------------------------------------------- */
/* greedy colouring in index order (deterministic): each vertex the least colour none of
 * its coloured neighbours has */
static int build_colours(wb_world *w, struct wb_vbd *v)
{
    const wb_model *m = &w->m;
    const int32_t np = m->np;
    uint8_t *col = malloc((size_t)(np > 0 ? np : 1));
    int32_t *order = malloc(sizeof *order * (size_t)(np > 0 ? np : 1));
    int32_t *cs = calloc(VBD_COLOURS + 1, sizeof *cs);
    uint8_t *held = malloc((size_t)(np > 0 ? np : 1)), *fold = calloc((size_t)(np > 0 ? np : 1), 1);
    if (!col || !order || !cs || !held || !fold) {
        free(col), free(order), free(cs), free(held), free(fold);
        return 0;
    }
    int overflow = 0, ncol = 0;
    for (int32_t i = 0; i < np; i++) {
        uint64_t used = 0;
        held[i] = 0;
        for (int t = 0; t < wb__vbd_nctypes; t++) {
            const wb_vbd_type *vt = wb__vbd_ctypes[t]->vbd;
            used |= vt->neighbours(w, v->part[t], i, col);
            held[i] |= (uint8_t)vt->holds(v->part[t], i);
        }
        int c = 0;
        while (c < VBD_COLOURS - 1 && (used >> c & 1u)) c++;
        overflow |= c == VBD_COLOURS - 1 && (used >> c & 1u);
        col[i] = (uint8_t)c;
        cs[c + 1]++;
        if (c + 1 > ncol) ncol = c + 1;
    }
    for (int c = 0; c < VBD_COLOURS; c++) cs[c + 1] += cs[c];
    int32_t fill[VBD_COLOURS];
    memcpy(fill, cs, sizeof fill);
    for (int32_t i = 0; i < np; i++) order[fill[col[i]]++] = i;
    free(v->col);
    free(v->order);
    free(v->colour_start);
    free(v->held);
    free(v->fold);
    v->fold = fold;
    v->nfold = 0;
    v->col = col;
    v->order = order;
    v->colour_start = cs;
    v->held = held;
    v->ncolours = ncol;
    v->serial_last = overflow;
    return 1;
}

/* the next prepare rebuilds the parts and the colouring (and forgets the links' errors) */
static int rebuild_due(const wb_world *w, const struct wb_vbd *v)
{
    if (w->m.topology_dirty || v->np != w->m.np) return 1;
    for (int t = 0; t < wb__vbd_nctypes; t++)
        if (v->built[t] != wb__vbd_ctypes[t]->vbd->slots(w)) return 1;
    return 0;
}

int wb__vbd_prepare(wb_world *w)
{
    if (w->m.def.solver != WB_SOLVER_VBD) return 1;
    struct wb_vbd *v = w->vbd ? w->vbd : make(w);
    if (!v) return 0;
    v->nomem = 0;
    const wb_model *m = &w->m;
    if (rebuild_due(w, v)) {
        for (int t = 0; t < wb__vbd_nctypes; t++)
            if (!wb__vbd_ctypes[t]->vbd->build(w, v->part[t])) return 0;
        /* the solver's own: the struct, held, fold, col, order, y and colour_start */
        const size_t n1 = (size_t)(m->np > 0 ? m->np : 1);
        if (!wb__charge(w, &v->charged, sizeof *v + n1 * (3 + sizeof(int32_t) + 3 * sizeof(wb_real)) +
                                            (VBD_COLOURS + 1) * sizeof(int32_t)) ||
            !build_colours(w, v))
            return 0;
        wb_real *y = realloc(v->y, sizeof *y * 3 * n1);
        if (!y) return 0;
        v->y = y;
        v->np = m->np;
        v->nact = 0;
        for (int t = 0; t < wb__vbd_nctypes; t++) {
            const wb_vbd_type *vt = wb__vbd_ctypes[t]->vbd;
            v->built[t] = vt->slots(w);
            /* (a part without constraints adds nothing to a vertex step) */
            if (v->built[t] > 0) v->act[v->nact] = vt, v->act_part[v->nact++] = v->part[t];
        }
    }
    for (int t = 0; t < wb__vbd_nctypes; t++)
        if (wb__vbd_ctypes[t]->vbd->save) wb__vbd_ctypes[t]->vbd->save(v->part[t]);
    return 1;
}

void wb__vbd_undo(wb_world *w)
{
    struct wb_vbd *v = w->vbd;
    if (!v || v->np != w->m.np) return;
    for (int t = 0; t < wb__vbd_nctypes; t++)
        if (wb__vbd_ctypes[t]->vbd->undo) wb__vbd_ctypes[t]->vbd->undo(v->part[t]);
}

/* ---- the vertex step ------------------------------------------------------------------------ */
/* solve the symmetric 3 x 3 system H d = f (H: xx, yy, zz, xy, xz, yz); 0 when singular */
static inline __attribute__((always_inline)) int solve3(const wb_real H[6], const wb_real f[3], wb_real d[3])
{
    const wb_real a = H[0], b = H[1], c = H[2], xy = H[3], xz = H[4], yz = H[5];
    const wb_real c00 = b * c - yz * yz, c01 = xz * yz - xy * c, c02 = xy * yz - b * xz;
    const wb_real det = a * c00 + xy * c01 + xz * c02;
    if (!(fabs(det) > 1e-300)) return 0;
    const wb_real c11 = a * c - xz * xz, c12 = xy * xz - a * yz, c22 = a * b - xy * xy, inv = 1 / det;
    d[0] = (c00 * f[0] + c01 * f[1] + c02 * f[2]) * inv;
    d[1] = (c01 * f[0] + c11 * f[1] + c12 * f[2]) * inv;
    d[2] = (c02 * f[0] + c12 * f[1] + c22 * f[2]) * inv;
    return 1;
}

typedef struct sweep_job {
    wb_world *w;
    struct wb_vbd *v;
    wb_real inv_h2, inv_h;
    const int32_t *vert;   /* the colour's vertices */
    wb_real step;          /* the largest step taken (max_into) */
    const wb_vbdc *ct;     /* the substep's contacts, NULL: none */
    int32_t run;           /* vertices whose forces are found before any of them moves: VBD_RUN,
                              1 in the last colour when it may hold neighbours (serial_last) */
} sweep_job;

/* A colour's vertices share no constraint, so the forces on a run of them can all be found
 * before any moves (the same bits as one after another): each type's hook is called once a
 * run, not once a vertex */
#define VBD_RUN 64

/* con: the substep has contacts in the vertex steps (two copies: the loop without them
 * stays as it was) */
static inline __attribute__((always_inline)) void sweep_body(void *ctx, int32_t lo, int32_t hi, int con)
{
    sweep_job *j = ctx;
    wb_world *w = j->w;
    const struct wb_vbd *v = j->v;
    wb_real *x = w->s.x;
    const wb_real *wv = w->m.w, *y = v->y, inv_h2 = j->inv_h2, inv_h = j->inv_h;
    const int32_t *vert = j->vert, run = j->run;
    const int nact = v->nact;
    const wb_vbd_type *const *act = v->act;
    void *const *part = v->act_part;
    wb_real big = 0;
    for (int32_t q0 = lo; q0 < hi; q0 += run) {
        const int32_t q1 = hi - q0 > run ? q0 + run : hi;
        int32_t idx[VBD_RUN], n = 0;
        wb_real f[3 * VBD_RUN], H[6 * VBD_RUN];
        /* the inertia term of each movable vertex, then each type's constraints at them (0 +
         * first: a sum starting at +0, as each type's own sums do, so the order of the terms
         * is all that decides) */
        for (int32_t q = q0; q < q1; q++) {
            const int32_t i = vert[q];
            if (!(wv[i] > 0)) continue;
            const wb_real mh = inv_h2 / wv[i], *xi = &x[3 * i], *yi = &y[3 * i];
            wb_real *fk = &f[3 * n], *Hk = &H[6 * n];
            fk[0] = (wb_real)0 + mh * (yi[0] - xi[0]), fk[1] = (wb_real)0 + mh * (yi[1] - xi[1]);
            fk[2] = (wb_real)0 + mh * (yi[2] - xi[2]);
            Hk[0] = Hk[1] = Hk[2] = mh, Hk[3] = Hk[4] = Hk[5] = 0;
            idx[n++] = i;
        }
        for (int t = 0; t < nact; t++) act[t]->vertex(w, part[t], idx, n, inv_h, f, H);
        for (int32_t k = 0; k < n; k++) {
            const int32_t i = idx[k];
            wb_real *fk = &f[3 * k], *Hk = &H[6 * k], d[3];
            if (con) wb__vbdc_block(w, j->ct, i, fk, Hk);
            if (!solve3(Hk, fk, d)) continue;
            if (con) {
                wb_real xn[3];
                v3_add(xn, &x[3 * i], d);
                wb__vbdc_friction(w, j->ct, i, Hk, xn);
                v3_sub(d, xn, &x[3 * i]);
            }
            v3_add(&x[3 * i], &x[3 * i], d);
            const wb_real dd = v3_dot(d, d);
            big = dd > big ? dd : big;
        }
    }
    wb_real cur;
    __atomic_load(&j->step, &cur, __ATOMIC_RELAXED);
    while (big > cur && !__atomic_compare_exchange(&j->step, &cur, &big, 1, __ATOMIC_RELAXED, __ATOMIC_RELAXED)) {}
}

static void sweep_part(void *ctx, int32_t lo, int32_t hi) { sweep_body(ctx, lo, hi, 0); }
static void sweep_part_ct(void *ctx, int32_t lo, int32_t hi) { sweep_body(ctx, lo, hi, 1); }

/* body a may touch a movable particle (or a triangle whose corners all move) of body b:
 * marked for the coupled step when b is free; when b is held, VBD_BY_HELD unless a is
 * marked already (touching()) */
static inline void by_partner(struct wb_vbd *v, const wb_cache *k, int32_t a, int32_t b)
{
    if (!(k->mc_acc[16 * b] < 0)) {
        if (v->bvar[a] < 0) v->bvar[a] = 0;
    } else if (v->bvar[a] == -1) {
        v->bvar[a] = VBD_BY_HELD;
    }
}

/* v->tsum (bodies x 4) zeroed, with [4 b] = -1 for each body b that may touch a rigid body,
 * a movable particle of a body made deep inside it or a triangle held in part this frame
 * (the contacts found for the frame), v->bvar numbering the free bodies that may touch
 * another free body's movable particles otherwise (moved together: couple), VBD_BY_HELD
 * for one that may touch only a held body's; 0 when there are no bodies (or no memory) */
static int touching(wb_world *w, struct wb_vbd *v)
{
    const wb_cache *k = &w->k;
    if (v->nfold > 0) memset(v->fold, 0, (size_t)w->m.np);
    v->nfold = 0;
    w->k.vbd_fold = NULL;
    if (!k->mc_built || k->mc_nbody == 0) return 0;
    const int32_t nb = k->mc_nbody, *body = k->mc_body;
    if (nb > v->cap_tsum) {
        if (!wb__charge(w, &v->charged_t, (sizeof(double) * (33 + WB_VBDC_BS + 14) + sizeof(int32_t) + 2) * (size_t)nb)) {
            v->nomem = 1;
            return 0;
        }
        double *t = realloc(v->tsum, sizeof *t * 8 * (size_t)nb), *e = realloc(v->csum, sizeof *e * 17 * (size_t)nb);
        double *vs = realloc(v->vsum, sizeof *vs * (WB_VBDC_BS + 14) * (size_t)nb);
        double *bb = realloc(v->bball, sizeof *bb * 8 * (size_t)nb);
        uint8_t *bm = realloc(v->bmove, (size_t)nb), *bc = realloc(v->bclear, (size_t)nb);
        int32_t *bv = realloc(v->bvar, sizeof *bv * (size_t)nb);
        if (t) v->tsum = t;
        if (e) v->csum = e;
        if (vs) v->vsum = vs;
        if (bb) v->bball = bb;
        if (bm) v->bmove = bm;
        if (bc) v->bclear = bc;
        if (bv) v->bvar = bv;
        if (!t || !e || !vs || !bb || !bm || !bc || !bv) {
            v->nomem = 1;
            return 0;
        }
        v->cap_tsum = nb;
    }
    double *T = v->tsum;
    memset(T, 0, sizeof *T * 5 * (size_t)nb);
    for (int32_t b = 0; b < nb; b++) v->bvar[b] = -1;
    /* only what moves outside the body counts: its own folds, loose particles and
     * immovable particles (a pinned slab, as a collider) keep the momentum the move keeps
     * (a block on a pinned slab at 0.95 of its sticking angle crept 26 mm in 1 s, then
     * 1.03). Immovable particles near it are flagged: they are contacts in the vertex
     * steps (vbd_contact.c), the body starts from the prediction and its move takes them
     * in (keep_momentum) */
    const wb_real *wv = w->m.w;
    const wb_contacts *pc = k->pc;
    const wb_real *xp = w->s.x_prev, *rad = w->m.radius;
    for (int32_t c = 0; c < pc->n; c++) {
        const int32_t i = pc->ij[2 * c], j = pc->ij[2 * c + 1], a = body[i], b = body[j];
        /* [4 nb + b] = 1: b may touch an immovable particle (a contact in the vertex steps) */
        if (!(wv[i] > 0) != !(wv[j] > 0) && body[wv[i] > 0 ? i : j] >= 0) {
            wb_real d[3];
            v3_sub(d, &xp[3 * i], &xp[3 * j]);
            const wb_real rn = (rad[i] + rad[j]) * WB_VBDC_NEAR;
            if (v3_dot(d, d) < rn * rn) T[4 * nb + body[wv[i] > 0 ? i : j]] = 1;
        }
        if (a >= 0 && a == b && wv[i] > 0 && wv[j] > 0) {
            /* a fold: two movable particles of one body in touch where the substep starts
             * (k.vbd_fold) */
            wb_real d[3];
            v3_sub(d, &xp[3 * i], &xp[3 * j]);
            const wb_real r = rad[i] + rad[j];
            if (v3_dot(d, d) < r * r) {
                v->nfold += !v->fold[i] + !v->fold[j];
                v->fold[i] = v->fold[j] = 1;
            }
            continue;
        }
        if (a < 0 || b < 0 || a == b) continue;
        /* (marked here, numbered below; bodies made deep inside each other are contact.c's
         * to part). A held body's movable particle puts no one in the coupled step: the
         * step cannot move a held body, and as a wall there its particle gave the free
         * body the pair's whole push, which the projection after the sweeps gives again
         * and shares with the held end: a chain of rigid links dropped upright on a net
         * pinned at its rim was stopped whole by its lowest contact and stood as a rod
         * (chain_pile.lua: its top 0.78 m above free fall). The body keeps its momentum
         * through the sweeps and the projection takes the pair, as on a collider; it starts
         * as near one (VBD_BY_HELD) */
        wb_real e[3];
        v3_sub(e, &xp[3 * i], &xp[3 * j]);
        const wb_real rs = (rad[i] + rad[j]) * VBD_MADE_DEEP;
        const int made = wb__contacts_made(w, i, j) || v3_dot(e, e) < rs * rs;
        if (wv[j] > 0) {
            if (made) T[4 * a] = -1;
            else by_partner(v, k, a, b);
        }
        if (wv[i] > 0) {
            if (made) T[4 * b] = -1;
            else by_partner(v, k, b, a);
        }
    }
    const wb_tricontacts *tc = k->tc;
    for (int32_t c = 0; c < tc->n; c++) {
        const int32_t t = tc->pt[2 * c + 1], p[4] = { tc->pt[2 * c], w->m.tri[3 * t], w->m.tri[3 * t + 1], w->m.tri[3 * t + 2] };
        int32_t a, b;
        const int kind = wb__vbdc_tri_kind(w, c, &a, &b);
        if (!kind) continue;
        /* (a triangle of one body, all its corners movable: in the coupled step unless that
         * body is held, then the projection's as a held particle's) */
        const int made = kind & WB_VBDC_MADE;
        const int whole = !made && (kind & WB_VBDC_WHOLE);
        if (whole) by_partner(v, k, a, b);
        else if (wv[p[1]] > 0 || wv[p[2]] > 0 || wv[p[3]] > 0) T[4 * a] = -1;
        if (wv[p[0]] > 0) {
            if (made) T[4 * b] = -1;
            else by_partner(v, k, b, a);
        }
    }
    if (w->rb)
        for (int32_t c = 0; c < w->rb->npct; c++)
            if (body[w->rb->pc[2 * c]] >= 0) T[4 * body[w->rb->pc[2 * c]]] = -1;
    w->k.vbd_fold = v->nfold > 0 ? v->fold : NULL;
    /* a free body that may touch another free body's movable particle is moved with the
     * bodies it may touch (keep_momentum), unless it is held or touches what that step does
     * not take in (a rigid body, a triangle of another body held in part) */
    v->nvar = 0;
    for (int32_t b = 0; b < nb; b++)
        v->bvar[b] = v->bvar[b] == 0 && !(T[4 * b] < 0) && !(k->mc_acc[16 * b] < 0) ? v->nvar++
                     : v->bvar[b] == VBD_BY_HELD                                    ? VBD_BY_HELD
                                                                                    : -1;
    return 1;
}

/* v->bclear: 1 for each free body (nothing outside the solve holds it) that no collider
 * can reach this substep. Its ball, the box of its particles at the substep's start and
 * at the prediction (centre c, half diagonal) grown by its largest radius and by its
 * largest predicted move again (the solve moves a vertex off the prediction by about as
 * much as the prediction moves it), is clear of a collider whose signed distance at c,
 * at the frame's end pose, is past the ball's radius R by the collider's reach over the
 * frame D = |p - p0| + a (R + |c - p| + |p - p0|), a its turn (a point of the surface
 * within R of c at any time of the frame is at most a (its distance from the turn's
 * centre) plus the shift from where it ends). Serial, in particle order. */
static void clear_of_colliders(wb_world *w, struct wb_vbd *v)
{
    const wb_cache *k = &w->k;
    const int32_t nb = k->mc_nbody, *body = k->mc_body;
    const wb_real *x = w->s.x, *xp = w->s.x_prev, *rad = w->m.radius;
    double *B = v->bball; /* (bodies x 8) lo, hi, largest radius, largest squared move */
    int any = 0;
    for (int32_t b = 0; b < nb; b++) {
        v->bclear[b] = !(k->mc_acc[16 * b] < 0);
        any |= v->bclear[b];
        for (int c = 0; c < 3; c++) B[8 * b + c] = INFINITY, B[8 * b + 3 + c] = -INFINITY;
        B[8 * b + 6] = B[8 * b + 7] = 0;
    }
    int live = 0;
    for (int32_t s = 0; s < w->m.nc; s++) live |= (int)(w->m.c_gen[s] & 1u);
    if (!any || !live) return;
    for (int32_t i = 0; i < w->m.np; i++) {
        const int32_t b = body[i];
        if (b < 0 || !v->bclear[b]) continue;
        double *o = &B[8 * b], m2 = 0;
        for (int c = 0; c < 3; c++) {
            const double a = x[3 * i + c], p = xp[3 * i + c];
            o[c] = a < o[c] ? a : o[c], o[c] = p < o[c] ? p : o[c];
            o[3 + c] = a > o[3 + c] ? a : o[3 + c], o[3 + c] = p > o[3 + c] ? p : o[3 + c];
            m2 += (a - p) * (a - p);
        }
        o[6] = rad[i] > o[6] ? rad[i] : o[6];
        o[7] = m2 > o[7] ? m2 : o[7];
    }
    for (int32_t b = 0; b < nb; b++) {
        if (!v->bclear[b]) continue;
        const double *o = &B[8 * b];
        wb_real c[3], n[3];
        double half = 0;
        for (int q = 0; q < 3; q++) c[q] = (wb_real)(o[q] / 2 + o[3 + q] / 2), half += (o[3 + q] - o[q]) * (o[3 + q] - o[q]);
        const double R = sqrt(half) / 2 + o[6] + sqrt(o[7]);
        for (int32_t s = 0; s < w->m.nc && v->bclear[b]; s++) {
            if (!(w->m.c_gen[s] & 1u)) continue;
            const wb_collider_pose *cp = &w->s.c_pose[s];
            wb_real e[3], f[3];
            v3_sub(e, cp->p, cp->p0);
            v3_sub(f, c, cp->p);
            const double dot = fabs(cp->q0[0] * cp->q[0] + cp->q0[1] * cp->q[1] + cp->q0[2] * cp->q[2] + cp->q0[3] * cp->q[3]);
            const double turn = 2 * acos(dot < 1 ? dot : 1), shift = v3_len(e);
            const double D = shift + turn * (R + v3_len(f) + shift);
            v->bclear[b] = wb__shape_distance(&w->m.c_shape[s], cp->p, cp->q, c, n) > R + D;
        }
    }
}

/* The sweeps start from the prediction y where nothing immovable can touch the body: a
 * free body clear of every collider (clear_of_colliders) falls as it was made, y being
 * its rigid move under gravity, where each vertex's energy is at its minimum. From the
 * prediction less this substep's gravity (x + h v) one sweep of Gauss-Seidel moved each
 * vertex only part of the way, the multipliers took the rest as tension, and a wavy
 * chain of 80 rigid links fell bent (0.74 m off its shape after 1 s at 20 substeps).
 * A vertex held by a constraint of a body that something holds (pins, attachments,
 * grabs) or that may touch a collider (or a held body's movable particle: VBD_BY_HELD)
 * starts from x + h v, where its speed alone takes it (Chen et al. 2024 list it among
 * their starts): a body held at rest is then a fixed point of a single sweep (from y
 * itself, one sweep a substep never reaches it: a bar
 * of E = 1e7 hung at 18.6 mm where it stretches 0.049 mm), and one resting on a
 * collider, which is projected after the sweeps, stays at rest (from y a hand-built
 * cloth on a sphere blew up, a draped one did not settle). Chen et al.'s adaptive start,
 * the prediction less the part of gravity a vertex did not follow last substep, fed the
 * swing of such a body back into its next start (the clamped strip swung on at 10 x 1,
 * 0.63 m against 0.29; the bar crept to 0.8 mm at 10 x 1). A free body that may touch
 * another free body's movable particle or a rigid body (touching()) starts from the
 * prediction too, near a collider or not: the contacts carry it (after the sweeps, or
 * in its momentum step with the bodies it touches) and where keep_momentum leaves it
 * alone the gravity it follows is the one its start has (from x + h v, a lattice made
 * overlapping another was lifted 0.25 m instead of 0.15; from the adaptive start, a
 * stack still moved after 4 s). So does a free body near an immovable particle: its
 * contacts in the vertex steps then push from the start (from x + h v a Newton step did
 * not see them, and their multipliers took 8 times the weight after it). A held one
 * touching itself keeps x + h v (from y, a pinned rope folding onto itself as it swung
 * gained energy) */
static void start_guess(wb_world *w, struct wb_vbd *v, wb_real h, int touch)
{
    const wb_real *g = w->m.def.gravity, *wv = w->m.w;
    wb_real *x = w->s.x;
    const int32_t *body = w->k.mc_body;
    if (touch) clear_of_colliders(w, v);
    for (int32_t i = 0; i < w->m.np; i++) {
        const int32_t b = body ? body[i] : -1;
        const int from_y = touch && b >= 0 && !(w->k.mc_acc[16 * b] < 0) &&
                           ((v->bclear[b] && v->bvar[b] != VBD_BY_HELD) || v->tsum[4 * b] < 0 ||
                            v->tsum[4 * w->k.mc_nbody + b] > 0 || v->bvar[b] >= 0);
        if (!(wv[i] > 0) || !v->held[i] || from_y) continue;
        v3_madd(&x[3 * i], g, -h * h);
    }
}

/* The free bodies that may touch each other's movable particles (touching(): bvar) take
 * together the Newton steps of the substep's energy along their rigid moves, a translation
 * and a small turn each, with their contacts (wb__vbdc_couple): each contact's forces on
 * its two bodies are equal and opposite, so the step keeps their momentum, and its
 * inertia term their angular momentum but for the contacts' torques (the turns the sweeps'
 * Gauss-Seidel gives a loaded body go: momentum.c leaves bodies that touch particles
 * alone). Moved along their translations only, three blocks stacked tipped over: the
 * contacts pushed their centres, not where they touch. Singular (non-finite input), they
 * keep the plain move (T) */
static void couple(wb_world *w, struct wb_vbd *v, wb_real h)
{
    const int32_t nb = w->k.mc_nbody, nv = v->nvar, *body = w->k.mc_body;
    if (nv == 0) return;
    double *T = v->tsum, *bs = v->vsum, *u = bs + WB_VBDC_BS * (size_t)nv;
    const wb_real *x = w->s.x, *y = v->y, *wv = w->m.w;
    memset(bs, 0, sizeof *bs * WB_VBDC_BS * (size_t)nv);
    for (int32_t b = 0; b < nb; b++) {
        const int32_t q = v->bvar[b];
        if (q < 0) continue;
        bs[WB_VBDC_BS * q] = T[4 * b];
        for (int c = 0; c < 3; c++) bs[WB_VBDC_BS * q + 1 + c] = T[4 * b + 1 + c];
    }
    /* centres, then the turn's sums about them */
    for (int32_t i = 0; i < w->m.np; i++) {
        const int32_t q = body[i] >= 0 ? v->bvar[body[i]] : -1;
        if (q < 0 || !(wv[i] > 0)) continue;
        for (int c = 0; c < 3; c++) bs[WB_VBDC_BS * q + 4 + c] += (double)x[3 * i + c] / wv[i];
    }
    for (int32_t q = 0; q < nv; q++)
        for (int c = 0; c < 3; c++) bs[WB_VBDC_BS * q + 4 + c] /= bs[WB_VBDC_BS * q];
    for (int32_t i = 0; i < w->m.np; i++) {
        const int32_t q = body[i] >= 0 ? v->bvar[body[i]] : -1;
        if (q < 0 || !(wv[i] > 0)) continue;
        double *B = &bs[WB_VBDC_BS * q], r[3], d[3];
        const double m = 1 / (double)wv[i];
        for (int c = 0; c < 3; c++) r[c] = (double)x[3 * i + c] - B[4 + c], d[c] = (double)x[3 * i + c] - (double)y[3 * i + c];
        B[7] += m * (r[1] * d[2] - r[2] * d[1]), B[8] += m * (r[2] * d[0] - r[0] * d[2]), B[9] += m * (r[0] * d[1] - r[1] * d[0]);
        B[10] += m * (r[1] * r[1] + r[2] * r[2]), B[11] += m * (r[0] * r[0] + r[2] * r[2]), B[12] += m * (r[0] * r[0] + r[1] * r[1]);
        B[13] -= m * r[0] * r[1], B[14] -= m * r[0] * r[2], B[15] -= m * r[1] * r[2];
    }
    const int done = wb__vbdc_couple(w, &v->ct, v->bvar, nv, bs, u, h, VBD_MOVE_STEPS);
    if (done < 0) v->nomem = 1; /* (the step undoes the frame) */
    if (done <= 0) return;
    /* each moved: x = c + t + R(th) (x - c), the turn exact (Rodrigues, 1 - cos a as 2 sin^2
     * a/2) so it keeps the body's shape; its momentum step done here (T[4 b] = 0:
     * keep_momentum moves it no more) */
    wb_real *xw = w->s.x;
    double *R = u + 6 * (size_t)nv; /* (nv x 5) each turn's axis k, sin a, 1 - cos a */
    double *carry = R + 5 * (size_t)nv; /* (nv x 3) the momentum the moves so far lost to rounding */
    memset(carry, 0, sizeof *carry * 3 * (size_t)nv);
    for (int32_t q = 0; q < nv; q++) {
        const double *th = &u[6 * q + 3], a = sqrt(th[0] * th[0] + th[1] * th[1] + th[2] * th[2]), h2 = sin(a / 2);
        for (int c = 0; c < 3; c++) R[5 * q + c] = a > 0 ? th[c] / a : 0;
        R[5 * q + 3] = sin(a), R[5 * q + 4] = 2 * h2 * h2;
    }
    for (int32_t i = 0; i < w->m.np; i++) {
        const int32_t q = body[i] >= 0 ? v->bvar[body[i]] : -1;
        if (q < 0 || !(wv[i] > 0)) continue;
        const double *B = &bs[WB_VBDC_BS * q], *t = &u[6 * q], *k = &R[5 * q];
        double r[3], kr[3];
        for (int c = 0; c < 3; c++) r[c] = (double)xw[3 * i + c] - B[4 + c];
        kr[0] = k[1] * r[2] - k[2] * r[1], kr[1] = k[2] * r[0] - k[0] * r[2], kr[2] = k[0] * r[1] - k[1] * r[0];
        /* the move, small, added once; what its rounding loses of the body's momentum goes
         * to the next particle's (the new position less the old is exact): the body's
         * momentum kept to a rounding of one particle, not of all (contact_kinetic's
         * slab and block: 1.1e-12 kg m/s off in 1.5 s without) */
        const double kd = k[0] * r[0] + k[1] * r[1] + k[2] * r[2], m = 1 / (double)wv[i];
        for (int c = 0; c < 3; c++) {
            const double want = t[c] + (kr[c] * k[3] + (k[c] * kd - r[c]) * k[4]) + carry[3 * q + c] / m;
            const wb_real old = xw[3 * i + c];
            xw[3 * i + c] = old + (wb_real)want;
            carry[3 * q + c] = (want - ((double)xw[3 * i + c] - (double)old)) * m;
        }
    }
    for (int32_t b = 0; b < nb; b++)
        if (v->bvar[b] >= 0) T[4 * b] = 0;
}

/* Each free body (momentum.c's: nothing outside the solve holds it) moved rigidly so that
 * the solve keeps its momentum, sum m (x - y) = 0. Its energies do not change under a
 * translation, so the move only lowers the inertia term: it is the exact step of the
 * substep's energy along the body's translation, which the vertex steps cannot take for
 * a stiff body (a vertex's own block is its stiffness, which one translating with its
 * neighbours does not feel: each sweep moves the body by m / (h^2 k) of what is left,
 * and the start (start_guess) would carry it). Serial, in particle order: the same bits
 * on any thread count. touch: touching() ran this substep (v->tsum holds its flags) */
static void keep_momentum(wb_world *w, struct wb_vbd *v, int touch, wb_real h)
{
    const wb_cache *k = &w->k;
    /* a body that may touch a rigid body, or a body made deep inside it, this frame is left
     * as the sweeps leave it (touching()): the contacts projected after the solve would take
     * the step back from one side only (measured: two stacked lattices crept 3 cm off
     * centre, when they were moved alone); one that may touch another body's movable
     * particles is moved with it (couple); none free (a pinned cloth), nothing to do */
    if (!touch || k->mc_free == 0) return;
    const wb_real inv_h2 = 1 / (h * h);
    const int32_t nb = k->mc_nbody, *body = k->mc_body;
    double *T = v->tsum;
    const wb_real *wv = w->m.w, *y = v->y;
    wb_real *x = w->s.x;
    for (int32_t i = 0; i < w->m.np; i++) {
        const int32_t b = body[i];
        if (b < 0 || k->mc_acc[16 * b] < 0 || T[4 * b] < 0 || !(wv[i] > 0)) continue;
        const double m = 1 / (double)wv[i];
        T[4 * b] += m;
        for (int c = 0; c < 3; c++) T[4 * b + 1 + c] += m * ((double)x[3 * i + c] - (double)y[3 * i + c]);
    }
    for (int32_t b = 0; b < nb; b++)
        if (T[4 * b] > 0)
            for (int c = 1; c < 4; c++) T[4 * b + c] /= T[4 * b];
    /* A body with contacts in the vertex steps (their partners immovable: forces from
     * outside it) takes the Newton step of the substep's energy along its translation t
     * with their normal forces, (M / h^2 + sum H_c) t = -M / h^2 mean(x - y) + sum f_c,
     * and then its friction exactly: the body's slip over the substep across the contacts'
     * mean normal stopped if M / h^2 |slip| is within sum mu f_n (the lagged forces), else
     * cut by that much. Without the step the move above took the contacts' net force back
     * (a block on a pinned slab at 0.95 of its sticking angle moved 1.007 mm in 1 s); with
     * the vertices' smoothed friction in it (one Newton step on |slip|) it fell short of
     * the stop by half and the block crept 29 mm */
    if (v->ct_on) {
        int32_t nc;
        const int32_t *cv = wb__vbdc_vertices(v->ct, v->ncolours, &nc);
        double *E = v->csum; /* (bodies x 17): 1, sum f_c, sum H_c, friction, sum m (y - x_prev) */
        memset(E, 0, sizeof *E * 17 * (size_t)nb);
        const wb_real *xp = w->s.x_prev;
        for (int32_t i = 0; i < w->m.np; i++) {
            const int32_t b = body[i];
            if (b < 0 || !(T[4 * b] > 0) || !(wv[i] > 0)) continue;
            const double m = 1 / (double)wv[i];
            for (int c = 0; c < 3; c++) E[17 * b + 14 + c] += m * ((double)y[3 * i + c] - (double)xp[3 * i + c]);
        }
        /* the translation t (tb) by Newton steps until the pairs pushing are the same: the
         * contacts are piecewise linear along it, and one step with the Hessian of the pairs
         * pushing at the sweeps' end stopped short where some of them let go (a block on a
         * slab at 1.05 of its sticking angle kept 1.57 times its weight on its last two
         * pairs, and the lagged friction of that held it) */
        double *tb = v->tsum + 5 * (size_t)nb; /* (bodies x 3) */
        memset(tb, 0, sizeof *tb * 3 * (size_t)nb);
        for (int pass = 0; pass < VBD_MOVE_STEPS; pass++) {
            for (int32_t b = 0; b < nb; b++)
                for (int c = 0; c < 10; c++) E[17 * b + c] = 0;
            for (int32_t q = 0; q < nc; q++) {
                const int32_t b = body[cv[q]];
                if (b < 0 || !(T[4 * b] > 0) || isnan(tb[3 * b]) || v->bvar[b] >= 0) continue;
                wb_real f[3] = { 0, 0, 0 }, H[6] = { 0, 0, 0, 0, 0, 0 }, fr[4] = { 0, 0, 0, 0 }, sh[3];
                for (int c = 0; c < 3; c++) sh[c] = (wb_real)tb[3 * b + c];
                if (wb__vbdc_body(w, v->ct, cv[q], sh, f, H, pass == 0 ? fr : NULL)) E[17 * b] = 1;
                for (int c = 0; c < 3; c++) E[17 * b + 1 + c] += f[c];
                for (int c = 0; c < 6; c++) E[17 * b + 4 + c] += H[c];
                if (pass == 0)
                    for (int c = 0; c < 4; c++) E[17 * b + 10 + c] += fr[c];
            }
            int more = 0;
            for (int32_t b = 0; b < nb; b++) {
                const double *e = &E[17 * b];
                if (!(e[0] > 0)) continue;
                const double mh = T[4 * b] * inv_h2;
                wb_real Hb[6], fb[3], dt[3];
                for (int c = 0; c < 6; c++) Hb[c] = (wb_real)(e[4 + c] + (c < 3 ? mh : 0));
                for (int c = 0; c < 3; c++) fb[c] = (wb_real)(e[1 + c] - mh * (T[4 * b + 1 + c] + tb[3 * b + c]));
                if (!solve3(Hb, fb, dt)) {
                    /* singular at the first step (non-finite input): the body keeps the
                     * plain move above, as one without such contacts */
                    if (pass == 0) tb[3 * b] = NAN;
                    continue;
                }
                double d2 = 0, t2 = 0;
                for (int c = 0; c < 3; c++) {
                    tb[3 * b + c] += dt[c];
                    d2 += (double)dt[c] * dt[c], t2 += tb[3 * b + c] * tb[3 * b + c];
                }
                more |= d2 > 1e-12 * t2;
            }
            if (!more) break;
        }
        for (int32_t b = 0; b < nb; b++) {
            const double *e = &E[17 * b];
            if (!(e[0] > 0) || isnan(tb[3 * b])) continue;
            const double mh = T[4 * b] * inv_h2;
            wb_real t[3];
            for (int c = 0; c < 3; c++) t[c] = (wb_real)tb[3 * b + c];
            const double nl = sqrt(e[11] * e[11] + e[12] * e[12] + e[13] * e[13]);
            if (v->bmove[b] && e[10] > 0 && nl > 0) {
                double D[3], dn = 0;
                for (int c = 0; c < 3; c++) D[c] = T[4 * b + 1 + c] + t[c] + e[14 + c] / T[4 * b], dn += D[c] * e[11 + c] / nl;
                for (int c = 0; c < 3; c++) D[c] -= dn * e[11 + c] / nl;
                const double sl = sqrt(D[0] * D[0] + D[1] * D[1] + D[2] * D[2]), need = mh * sl;
                const double cut = need <= e[10] ? 1 : e[10] / need;
                for (int c = 0; c < 3; c++) t[c] -= (wb_real)(D[c] * cut);
            }
            for (int c = 0; c < 3; c++) T[4 * b + 1 + c] = -t[c];
        }
    }
    couple(w, v, h);
    for (int32_t i = 0; i < w->m.np; i++) {
        const int32_t b = body[i];
        if (b < 0 || !(T[4 * b] > 0) || !(wv[i] > 0)) continue;
        for (int c = 0; c < 3; c++) x[3 * i + c] -= (wb_real)T[4 * b + 1 + c];
    }
}

wb_real wb__vbd_solve(wb_world *w, wb_real h, wb_real t0, wb_real t1)
{
    struct wb_vbd *v = w->vbd;
    if (!v || v->np != w->m.np) return -1; /* (prepare failed: out of memory, warned there) */
    const wb_real inv_h2 = 1 / (h * h);
    if (w->m.np > 0) memcpy(v->y, w->s.x, sizeof *v->y * 3 * (size_t)w->m.np); /* none: rigid bodies alone */
    /* which bodies touch another's movable particle or a rigid body: the contacts are the
     * frame's list, the same for the start and the momentum step (one pass, not two) */
    const int touch = touching(w, v);
    start_guess(w, v, h, touch);
    for (int t = 0; t < v->nact; t++)
        if (v->act[t]->begin) v->act[t]->begin(w, v->act_part[t], h);
    /* the contacts in the vertex steps */
    if (touch)
        for (int32_t b = 0; b < w->k.mc_nbody; b++)
            v->bmove[b] = v->tsum[4 * w->k.mc_nbody + b] > 0 && v->tsum[4 * b] >= 0 && !(w->k.mc_acc[16 * b] < 0) &&
                          v->bvar[b] < 0;
    const int got = wb__vbdc_begin(w, &v->ct, h, t0, t1, v->order, v->colour_start, v->ncolours, v->col, v->held,
                                   touch ? v->bmove : NULL,
                                   touch && v->nvar > 0 ? v->bvar : NULL);
    v->ct_on = got > 0;
    if (got < 0) v->nomem = 1;
    if (v->nomem) return -1; /* (the step undoes the frame) */
    wb_vbdc *ct = v->ct_on ? v->ct : NULL;
    /* (the sweeps' copy with contacts only when some vertex has one: the pairs between
     * bodies moved together are not in them) */
    int32_t nvc = 0;
    if (ct) wb__vbdc_vertices(ct, v->ncolours, &nvc);
    wb_vbdc *cs = nvc > 0 ? ct : NULL;
    wb_pool *pool = wb__world_pool(w);
    for (int it = 0; it < w->m.def.iterations; it++) {
        sweep_job j = { w, v, inv_h2, 1 / h, NULL, 0, cs, VBD_RUN };
        if (cs && it > 0) wb__vbdc_refresh(w, cs, v->ncolours);
        for (int32_t c = 0; c < v->ncolours; c++) {
            const int32_t lo = v->colour_start[c], n = v->colour_start[c + 1] - lo;
            j.vert = v->order + lo;
            const int serial = v->serial_last && c == v->ncolours - 1;
            j.run = serial ? 1 : VBD_RUN;
            wb__pool_for(serial ? NULL : pool, n, 1024, cs ? sweep_part_ct : sweep_part, &j);
            if (cs) wb__vbdc_colour_done(w, cs, c);
        }
        v->residual = sqrt(j.step);
        w->k.iters_run++;
        const int last = it + 1 == w->m.def.iterations || (w->m.def.tolerance > 0 && v->residual <= w->m.def.tolerance);
        if (ct) wb__vbdc_dual(w, ct);
        for (int t = 0; t < v->nact; t++)
            if (v->act[t]->dual) v->act[t]->dual(w, v->act_part[t], h, last);
        for (int t = 0; t < wb__nctypes; t++)
            if (!wb__ctypes[t]->vbd) wb__ctypes[t]->project(w, h);
        if (last) break;
    }
    keep_momentum(w, v, touch, h);
    if (v->ct_on) wb__vbdc_end(w, v->ct);
    for (int t = 0; t < v->nact; t++)
        if (v->act[t]->end) v->act[t]->end(w, v->act_part[t], h);
    return v->residual;
}

void wb__vbd_contacts_done(wb_world *w)
{
    if (w->vbd && w->vbd->ct_on) wb__vbdc_readout(w, w->vbd->ct);
}

wb_real wb__vbd_residual(const wb_world *w) { return w->vbd ? w->vbd->residual : 0; }

int wb__vbd_failed(const wb_world *w) { return w->vbd && w->vbd->nomem; }

/* ---- snapshots ------------------------------------------------------------------------------- */
void wb__vbd_image_free(wb_image *g)
{
    free(g->vbd_lam), free(g->vbd_c0), free(g->vbd_blam), free(g->vbd_bc0);
    g->vbd_lam = g->vbd_c0 = g->vbd_blam = g->vbd_bc0 = NULL;
    g->vbd_nd = g->vbd_nb = 0;
}

wb_status wb_image_alloc_vbd(wb_image *g, int32_t nd, int32_t nb)
{
    wb__vbd_image_free(g);
    g->vbd_lam = malloc(sizeof(wb_real) * (size_t)(nd > 0 ? nd : 1));
    g->vbd_c0 = malloc(sizeof(wb_real) * (size_t)(nd > 0 ? nd : 1));
    g->vbd_blam = malloc(sizeof(wb_real) * (size_t)(nb > 0 ? nb : 1));
    g->vbd_bc0 = malloc(sizeof(wb_real) * (size_t)(nb > 0 ? nb : 1));
    if (!g->vbd_lam || !g->vbd_c0 || !g->vbd_blam || !g->vbd_bc0) {
        wb__vbd_image_free(g);
        return WB_ERR_NOMEM;
    }
    g->vbd_nd = nd, g->vbd_nb = nb;
    return WB_OK;
}

/* what the world's next substep starts from, each type's half (none: the section empty) */
wb_status wb__vbd_image_of(const wb_world *w, wb_image *g)
{
    const struct wb_vbd *v = w->vbd;
    if (!v || w->m.def.solver != WB_SOLVER_VBD) return WB_OK;
    const int stale = rebuild_due(w, v);
    for (int t = 0; t < wb__vbd_nctypes; t++) {
        const wb_vbd_type *vt = wb__vbd_ctypes[t]->vbd;
        if (!vt->image_save) continue;
        const wb_status st = vt->image_save(w, v->part[t], g, stale);
        if (st != WB_OK) return st;
    }
    return WB_OK;
}

const char *wb__vbd_image_check(const wb_image *g)
{
    if (!wb__image_has_vbd(g)) return NULL;
    if (g->def.solver != WB_SOLVER_VBD) return "VBD multipliers in a world of another solver";
    for (int t = 0; t < wb__vbd_nctypes; t++) {
        const wb_vbd_type *vt = wb__vbd_ctypes[t]->vbd;
        const char *e = vt->image_check ? vt->image_check(g) : NULL;
        if (e) return e;
    }
    return NULL;
}

wb_status wb__vbd_image_put(wb_world *w, const wb_image *g)
{
    if (!wb__image_has_vbd(g)) return WB_OK;
    struct wb_vbd *v = make(w);
    if (!v) return WB_ERR_NOMEM;
    for (int t = 0; t < wb__vbd_nctypes; t++) {
        const wb_vbd_type *vt = wb__vbd_ctypes[t]->vbd;
        const wb_status st = vt->image_put ? vt->image_put(v->part[t], g) : WB_OK;
        if (st != WB_OK) return st;
    }
    return WB_OK;
}
