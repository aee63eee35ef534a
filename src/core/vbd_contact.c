/* vbd_contact.c: the particle-particle and collider contacts as energies in VBD's vertex steps
 * (docs/physics.md, "VBD"), as Augmented Vertex Block Descent has them (Giles, Diaz,
 * Yuksel, SIGGRAPH 2025): each pair an inequality constraint C = |x_i - x_j| - target >= 0
 * with a penalty k and a multiplier lambda >= 0, its force on i along the pair's normal
 * max(0, lambda - k C), Hessian k n n^T while it pushes; lambda grows by -k C after each
 * sweep, clamped at 0 (not carried to the next substep: carried whole, a block on a
 * slab chattered between 0 and 4 times its weight and crept 4.4 mm in 1 s; 0.9 of it,
 * 1.2 mm).
 *
 * Friction: Coulomb's, mu times a lagged normal force (as IPC and Chen et al.'s VBD lag
 * it), the pair's force where the last substep's solve left it (wb__vbdc_end; the force
 * of the same evaluation, from the prediction, was 8 times the weight). Not as their
 * smoothed energy (mu f_n f1(|u|), one Newton step on it): with one step a substep it
 * stopped half of the slip it could (a block at 0.95 of its sticking angle crept 29 mm
 * in 1 s, a particle on a pinned one slid 2.2% too far), but exactly within the cone,
 * after the vertex's Newton step (wb__vbdc_friction): its slip over the substep across
 * its contacts' mean normal undone if the force that takes, its Hessian times the slip,
 * is within sum mu f_n, else cut by that much. A free body's pairs leave theirs to its
 * momentum step (vbd.c's keep_momentum, wb__vbdc_body), which does the same for the
 * body's translation.
 *
 * Served: pairs of one movable and one immovable particle (a body on a pinned slab); a
 * held body's self-contacts (held_self) and its vertices' collider contacts, each a
 * plane for the substep (gather_colliders), their friction with the current force for a
 * self-contact. Other pairs of two movable particles stay with the projection after the
 * sweeps: Gauss-Seidel over vertices gives the two ends unequal impulses, so a pair's
 * momentum is not kept (two particles meeting head-on at substeps = 1 left at 0.447 and
 * 0.143 m/s where perfectly inelastic is 0.143 for both; tests/validation/depenetration.lua);
 * a held body's momentum is not kept anyway.
 *
 * Free bodies touching each other (vbd.c's touching(): their movable particles, or a
 * point and a triangle whose corners all move) are moved together after the sweeps
 * (wb__vbdc_couple), each rigidly: the Newton steps of the substep's energy along their
 * translations and small turns, each pair and point-triangle contact between them a
 * penalty (VBDC_K times its ends' inertia, its multiplier 0: they are not in the sweeps)
 * with Coulomb friction as a tangential spring of the same stiffness capped at mu f_n, one
 * linear system over the bodies solved by conjugate gradients. Each contact's forces on
 * its two bodies are equal and opposite, so the step keeps their momentum whatever the
 * order (Gauss-Seidel over the bodies would not, as over the vertices). Moved each alone,
 * two stacked lattices crept 3 cm off centre; not moved at all, a block sliding on a free
 * slab lost a fifth of the momentum and a rope draped on another rested 2.2 mm low; moved
 * along their translations only, three stacked blocks tipped over.
 *
 * The contacts projected after the sweeps (contact.c) still run and take what the
 * sweeps left (a penalty leaves 1 / (1 + VBDC_K) of a resting overlap); their friction
 * acts on that part, this file's on the solve's. A made overlap parts no
 * faster than max_depenetration because the target keeps what contact.c's rule keeps
 * (wb__contact_depth).
 *
 * Determinism: a vertex reads its partners from a copy of the positions brought up to
 * date after each colour, never from x, so a partner of the same colour (contacts are not
 * in the colouring) is read as it was before the colour, whichever thread steps it. */
#include <stdlib.h>
#include <string.h>

#include "attach.h"
#include "contact.h"
#include "shape.h"
#include "tricontact.h"
#include "vbd_contact.h"

/* the penalty, in units of the inertia of the pair's ends over the substep
 * 1 / (h^2 (w_i + w_j)), as a rigid link's (vbd.c) */
#define VBDC_K ((wb_real)8)

typedef struct vbdc_key {
    uint64_t key; /* i << 32 | j */
    int32_t k;    /* the candidate */
} vbdc_key;

static int by_key(const void *a, const void *b)
{
    const uint64_t p = ((const vbdc_key *)a)->key, q = ((const vbdc_key *)b)->key;
    return (p > q) - (p < q);
}

struct wb_vbdc {
    int32_t *start;          /* (np + 1) each vertex's range of ent */
    int32_t *ent;            /* 2 pair + side (0: the vertex is the pair's i) */
    int32_t *pij;            /* (npair x 2) */
    wb_real *tgt, *kk, *lam, *mu; /* (npair) */
    wb_real *ov, *ove;       /* (npair) its overlap of the target as the sweeps began and as
                                the last left it (the readout: what they corrected) */
    int32_t npair;
    int32_t *prev;           /* (nprev x 2) the last substep's pairs, with fend: prevf */
    wb_real *fend, *prevf;   /* (npair) each pair's normal force as the substep's solve left
                                it (wb__vbdc_end) */
    wb_real *lamp;           /* (npair) the multiplier before the last sweep's update */
    wb_real *ke;             /* (npair x 2) each end's penalty in its vertex step (begin) */
    uint8_t *sf;             /* (npair) 1: its friction acts in the vertex steps (0: in its
                                body's momentum step, vbd.c) */
    uint8_t *bo;             /* (npair) 1: two movable ends of two bodies, at least one of them
                                moved with its partners (wb__vbdc_couple): in that step only */
    wb_real *fl;             /* (npair) the normal force its friction takes: the last
                                substep's (lagged; the projection after the solve has its
                                own friction for its own part) */
    int32_t nprev;
    int sorted;              /* pij in (i, j) order (0: not set up) */
    vbdc_key *ks;            /* (candidates) the near ones' keys, sorted */
    int32_t cap_ks;
    wb_real *xc;             /* (np x 3) the copy partners are read from (contact ends only) */
    int32_t *cv;             /* the vertices with contacts, by colour */
    int32_t *cvs;            /* (ncolours + 1) ranges of cv */
    int32_t cap_np, cap_pair, cap_col;
    size_t charged;          /* its bytes charged to def.memory (given back by wb__vbdc_destroy) */
    double *cs;              /* wb__vbdc_couple's scratch: 108 doubles a body, 20 a pair, 24 a
                                triangle contact */
    size_t cap_cs, charged_cs;
    /* the collider contacts in the vertex steps: vertex i against collider s (not a mesh),
     * the surface as a plane over the substep, C = n . x - off >= 0 */
    int32_t ng, cap_g, ngprev;
    int32_t *gis, *gprev;    /* (ng x 2) vertex, collider slot, in that order; the last
                                substep's, with gprevf */
    wb_real *gd;             /* (ng x VBDC_GD) its record (G_ below) */
    wb_real *gprevf;         /* (ngprev) the last substep's normal forces as it ended */
    uint8_t *gsf;            /* (ng) 1: its friction acts in the vertex steps (0: its body's
                                momentum step) */
    size_t charged_g;
    int32_t *tk;             /* (ntk x 3) wb__vbdc_couple's triangle contacts between its
                                bodies: candidate, the point's body in the step, the
                                triangle's (-1: held where it is) */
    int32_t cap_tk;
    size_t charged_tk;
};

/* a collider contact's record: its normal (3), the plane's offset, penalty, multiplier, the
 * multiplier before the last sweep's update, friction, lagged normal force, force as the
 * solve left it, and the surface's move over the substep at the contact (3) */
enum { G_N = 0, G_OFF = 3, G_K, G_LAM, G_LAMP, G_MU, G_FL, G_FEND, G_MV, VBDC_GD = G_MV + 3 };

void wb__vbdc_destroy(wb_world *w, wb_vbdc *c)
{
    if (!c) return;
    wb__charge(w, &c->charged_g, 0);
    free(c->gis), free(c->gprev), free(c->gd), free(c->gprevf), free(c->gsf);
    wb__charge(w, &c->charged, 0);
    wb__charge(w, &c->charged_cs, 0);
    wb__charge(w, &c->charged_tk, 0);
    free(c->cs), free(c->tk), free(c->bo);
    free(c->start), free(c->ent), free(c->pij), free(c->tgt), free(c->kk), free(c->lam), free(c->mu);
    free(c->ov), free(c->ove), free(c->prev), free(c->fend), free(c->prevf), free(c->fl), free(c->lamp), free(c->sf), free(c->ks), free(c->xc), free(c->cv), free(c->cvs);
    free(c->ke);
    free(c);
}

/* what c holds at these capacities: the struct, the per-vertex arrays (start, cv, xc), the
 * per-pair ones (ent 2, pij 2, prev 2 ints; tgt, kk, lam, mu, ov, ove, fend, prevf, fl,
 * lamp reals; sf, bo 1 byte), the keys and the colour ranges */
static size_t bytes_at(int64_t np, int64_t npair, int64_t ncol1, int64_t nks)
{
    return sizeof(wb_vbdc) + (size_t)np * (2 * sizeof(int32_t) + 3 * sizeof(wb_real)) + sizeof(int32_t) +
           (size_t)npair * (6 * sizeof(int32_t) + 12 * sizeof(wb_real) + 2) + (size_t)nks * sizeof(vbdc_key) +
           (size_t)ncol1 * sizeof(int32_t);
}

/* room for np vertices, npair pairs, ncol colours and nks keys, charged to the memory
 * budget before it is taken; 0 when the budget refuses it or out of memory */
static int grow(wb_world *w, wb_vbdc *c, int32_t np, int32_t npair, int32_t ncol, int32_t nks)
{
    const int32_t cnp = np > c->cap_np ? np : c->cap_np, cpair = npair > c->cap_pair ? npair : c->cap_pair;
    const int32_t ccol = ncol + 1 > c->cap_col ? ncol + 1 : c->cap_col, cks = nks > c->cap_ks ? nks : c->cap_ks;
    if (!wb__charge(w, &c->charged, bytes_at(cnp, cpair, ccol, cks))) return 0;
    if (nks > c->cap_ks) {
        vbdc_key *ks = realloc(c->ks, sizeof *ks * (size_t)nks);
        if (!ks) return 0;
        c->ks = ks, c->cap_ks = nks;
    }
    if (np > c->cap_np) {
        int32_t *s = realloc(c->start, sizeof *s * ((size_t)np + 1)), *v = realloc(c->cv, sizeof *v * (size_t)np);
        if (s) c->start = s;
        if (v) c->cv = v;
        wb_real *x = realloc(c->xc, sizeof *x * 3 * (size_t)np);
        if (x) c->xc = x;
        if (!s || !v || !x) return 0;
        c->cap_np = np;
    }
    if (npair > c->cap_pair) {
        const size_t n = (size_t)npair;
        int32_t *e = realloc(c->ent, sizeof *e * 2 * n), *p = realloc(c->pij, sizeof *p * 2 * n);
        if (e) c->ent = e;
        if (p) c->pij = p;
        wb_real *r[4] = { realloc(c->tgt, sizeof(wb_real) * n), NULL, NULL, NULL };
        if (r[0]) c->tgt = r[0];
        r[1] = realloc(c->kk, sizeof(wb_real) * n);
        if (r[1]) c->kk = r[1];
        r[2] = realloc(c->lam, sizeof(wb_real) * n);
        if (r[2]) c->lam = r[2];
        r[3] = realloc(c->mu, sizeof(wb_real) * n);
        if (r[3]) c->mu = r[3];
        wb_real *ov = realloc(c->ov, sizeof *ov * n), *ove = realloc(c->ove, sizeof *ove * n);
        if (ov) c->ov = ov;
        if (ove) c->ove = ove;
        int32_t *pv = realloc(c->prev, sizeof *pv * 2 * n);
        if (pv) c->prev = pv;
        wb_real *q[3] = { realloc(c->fend, sizeof(wb_real) * n), NULL, NULL };
        if (q[0]) c->fend = q[0];
        q[1] = realloc(c->prevf, sizeof(wb_real) * n);
        if (q[1]) c->prevf = q[1];
        q[2] = realloc(c->fl, sizeof(wb_real) * n);
        if (q[2]) c->fl = q[2];
        wb_real *lp = realloc(c->lamp, sizeof *lp * n), *ke = realloc(c->ke, sizeof *ke * 2 * n);
        if (lp) c->lamp = lp;
        if (ke) c->ke = ke;
        uint8_t *sf = realloc(c->sf, n), *bo = realloc(c->bo, n);
        if (sf) c->sf = sf;
        if (bo) c->bo = bo;
        if (!e || !p || !r[0] || !r[1] || !r[2] || !r[3] || !ov || !ove || !pv || !q[0] || !q[1] || !q[2] || !lp || !ke || !sf || !bo)
            return 0;
        c->cap_pair = npair;
    }
    if (ncol + 1 > c->cap_col) {
        int32_t *s = realloc(c->cvs, sizeof *s * ((size_t)ncol + 1));
        if (!s) return 0;
        c->cvs = s, c->cap_col = ncol + 1;
    }
    return 1;
}

/* A contact that starts the substep overlapping by more than what depenetration parts in
 * it (d0 > max_depenetration h: contact.c's rule, wb__contact_depth) is the projection's to
 * part slowly, pair by pair, not the coupled step's: the one test for particle pairs and
 * point-triangle contacts. (Two bodies made inside each other are another thing, decided
 * once, by vbd.c's touching(): neither is moved with the other.) */
static inline int starts_deep(wb_real d0, wb_real step) { return d0 > step; }

/* i and j are of one body that something outside the solve holds (a pin, an attachment, a
 * grab): a self-contact the vertex steps take (body: NULL when none is known). A free
 * body's stay the projection's: its momentum step (vbd.c's keep_momentum) moves it rigidly
 * after the sweeps, and with them in the sweeps a hand-built cloth dropped on a sphere
 * gained energy (9.8 J to 25 J in 3 s) */
static inline int held_self(const wb_world *w, const int32_t *body, int32_t i, int32_t j)
{
    return body && body[i] >= 0 && body[i] == body[j] && w->k.mc_acc[16 * body[i]] < 0;
}

/* candidate k is a pair it serves, closer than WB_VBDC_NEAR (r_i + r_j): one movable end,
 * two movable ends of one held body (its self-contacts: see the head of the file), or two
 * movable ends of two bodies, neither held, one of them moved with its partners (bvar: its
 * index there, < 0 none; NULL: no such bodies), not starting deep (a pair of bodies made
 * inside each other: touching() left neither in bvar). body: NULL when none is known */
static inline int near_pair(const wb_world *w, const wb_contacts *pc, const wb_real *x, const wb_real *wv, const wb_real *rad,
                            const int32_t *body, const int32_t *bvar, wb_real step, int32_t k)
{
    const int32_t i = pc->ij[2 * k], j = pc->ij[2 * k + 1];
    if (!(wv[i] > 0) == !(wv[j] > 0) && !(wv[i] > 0 && held_self(w, body, i, j))) {
        if (!bvar || !(wv[i] > 0)) return 0;
        const int32_t a = body[i], b = body[j];
        if (a < 0 || b < 0 || a == b || (bvar[a] < 0 && bvar[b] < 0)) return 0;
        /* (a held body's movable particle is no wall of the step: the projection's, vbd.c's
         * touching()) */
        if (w->k.mc_acc[16 * a] < 0 || w->k.mc_acc[16 * b] < 0) return 0;
        const wb_real *xp = w->s.x_prev;
        wb_real e[3];
        v3_sub(e, &xp[3 * i], &xp[3 * j]);
        if (starts_deep(rad[i] + rad[j] - v3_len(e), step)) return 0;
    }
    const wb_real rn = (rad[i] + rad[j]) * WB_VBDC_NEAR;
    wb_real d[3];
    v3_sub(d, &x[3 * i], &x[3 * j]);
    return v3_dot(d, d) < rn * rn;
}

/* 1: a collider the vertex steps take (not a mesh) is in the world */
static int any_collider(const wb_world *w)
{
    for (int32_t s = 0; s < w->m.nc; s++)
        if ((w->m.c_gen[s] & 1u) && w->m.c_shape[s].shape != WB_SHAPE_MESH) return 1;
    return 0;
}

/* room for ng collider contacts (and as many lagged ones), charged first; 0 when refused */
static int grow_g(wb_world *w, wb_vbdc *c, int32_t ng)
{
    if (ng <= c->cap_g) return 1;
    const int32_t cap = ng > 2 * c->cap_g ? ng : 2 * c->cap_g;
    const size_t n = (size_t)cap;
    if (!wb__charge(w, &c->charged_g, n * (4 * sizeof(int32_t) + (VBDC_GD + 1) * sizeof(wb_real) + 1))) return 0;
    int32_t *a = realloc(c->gis, sizeof *a * 2 * n), *b = realloc(c->gprev, sizeof *b * 2 * n);
    if (a) c->gis = a;
    if (b) c->gprev = b;
    wb_real *d = realloc(c->gd, sizeof *d * VBDC_GD * n), *f = realloc(c->gprevf, sizeof *f * n);
    if (d) c->gd = d;
    if (f) c->gprevf = f;
    uint8_t *sf = realloc(c->gsf, n);
    if (sf) c->gsf = sf;
    if (!a || !b || !d || !f || !sf) return 0;
    c->cap_g = cap;
    return 1;
}

/* The collider contacts of the substep (t0, t1: its start and end in the frame): each
 * movable vertex of a held body that a served constraint holds (held), within
 * WB_VBDC_NEAR r_i of a collider's surface at the substep's end pose (meshes, and
 * colliders past the first 64, are left to the projection; so are a free body's, which
 * its momentum step would move back: a hand-built cloth dropped on a sphere slid off it,
 * gaining 2.5 J, or with their friction in the vertex steps blew up, 141 J, as a free body
 * near an immovable particle takes its friction in that step alone, or drifted 0.18 m off
 * the sphere's axis), the surface linearised there as a plane through
 * its closest point, the target r_i less the overlap it keeps (a made overlap parts at
 * max_depenetration, as collide.c's rule), its penalty VBDC_K times the vertex's inertia
 * over the substep (an immovable partner's), its friction lagged as the pairs'. In
 * (vertex, collider) order: the lag's merge. Returns their count, -1 out of memory */
static int32_t gather_colliders(wb_world *w, wb_vbdc *c, wb_real h, wb_real t0, wb_real t1, const uint8_t *held)
{
    /* the last substep's, for the lag */
    int32_t *t = c->gprev;
    c->gprev = c->gis, c->gis = t;
    c->ngprev = c->ng;
    for (int32_t g = 0; g < c->ng; g++) c->gprevf[g] = c->gd[VBDC_GD * g + G_FEND];
    c->ng = 0;
    const wb_model *m = &w->m;
    /* (no held body: none of its vertices to look at) */
    if (!w->k.mc_built || w->k.mc_free == w->k.mc_nbody) return 0;
    int32_t live[64], nl = 0;
    for (int32_t s = 0; s < m->nc && nl < 64; s++)
        if ((m->c_gen[s] & 1u) && m->c_shape[s].shape != WB_SHAPE_MESH) live[nl++] = s;
    if (nl == 0) return 0;
    wb_real p0[64][3], q0[64][4], p1[64][3], q1[64][4];
    for (int32_t k = 0; k < nl; k++) {
        wb__collider_pose_at(&w->s.c_pose[live[k]], t0, p0[k], q0[k]);
        wb__collider_pose_at(&w->s.c_pose[live[k]], t1, p1[k], q1[k]);
    }
    const wb_real *x = w->s.x, *xp = w->s.x_prev, *wv = m->w, *rad = m->radius, inv_h2 = 1 / (h * h);
    const wb_real step = m->def.max_depenetration * h;
    const int32_t *body = w->k.mc_built ? w->k.mc_body : NULL;
    const wb_attaches *att = wb__attach_skips(w); /* attached: no contact */
    int32_t ng = 0;
    for (int32_t i = 0; i < m->np; i++) {
        if (!(wv[i] > 0) || !held[i] || !(body && body[i] >= 0 && w->k.mc_acc[16 * body[i]] < 0)) continue;
        for (int32_t k = 0; k < nl; k++) {
            const int32_t s = live[k];
            if (att && wb__attach_skip(att, i, s)) continue;
            const wb_cshape *sh = &m->c_shape[s];
            wb_real n[3];
            const wb_real d = wb__shape_distance(sh, p1[k], q1[k], &x[3 * i], n);
            if (!(d < WB_VBDC_NEAR * rad[i])) continue;
            if (ng == c->cap_g && !grow_g(w, c, ng + 1)) return -1;
            wb_real *o = &c->gd[VBDC_GD * ng], n0[3], ps[3];
            /* the overlap it began the substep with, of which it keeps all but a step */
            wb_real d0 = rad[i] - wb__shape_distance(sh, p0[k], q0[k], &xp[3 * i], n0), keep = d0 - step;
            keep = !(keep > 0) ? 0 : keep;
            /* the surface point, and where the collider's move took it from */
            v3_copy(ps, &x[3 * i]);
            v3_madd(ps, n, -d);
            wb_real l[3], r0[3];
            v3_sub(l, ps, p1[k]);
            q_rotate_inv(q1[k], l, r0);
            q_rotate(q0[k], r0, l);
            v3_add(l, l, p0[k]);
            v3_copy(&o[G_N], n);
            o[G_OFF] = v3_dot(n, ps) + rad[i] - keep;
            o[G_K] = VBDC_K * inv_h2 / wv[i];
            o[G_LAM] = o[G_LAMP] = o[G_FEND] = 0;
            o[G_MU] = sh->friction;
            v3_sub(&o[G_MV], ps, l);
            c->gis[2 * ng] = i, c->gis[2 * ng + 1] = s;
            c->gsf[ng] = 1;
            ng++;
        }
    }
    /* each one's lagged normal force: the last substep's, where it had it; in a frame's
     * first substep none (-1: the force where the Newton step puts it), so that a frame
     * depends on nothing but the state a snapshot holds (a world loaded from w:save steps
     * on bit for bit) */
    for (int32_t g = 0, o = 0; g < ng; g++) {
        const int32_t i = c->gis[2 * g], s = c->gis[2 * g + 1];
        while (o < c->ngprev && (c->gprev[2 * o] < i || (c->gprev[2 * o] == i && c->gprev[2 * o + 1] < s))) o++;
        c->gd[VBDC_GD * g + G_FL] = !(t0 > 0)                                                              ? -1
                                    : o < c->ngprev && c->gprev[2 * o] == i && c->gprev[2 * o + 1] == s ? c->gprevf[o]
                                                                                                        : 0;
    }
    c->ng = ng;
    return ng;
}

int wb__vbdc_begin(wb_world *w, wb_vbdc **cp, wb_real h, wb_real t0, wb_real t1, const int32_t *order,
                   const int32_t *colour_start, int32_t ncolours, const uint8_t *vcol, const uint8_t *held,
                   const uint8_t *bmoved,
                   const int32_t *bvar)
{
    const wb_contacts *pc = w->k.pc;
    wb_vbdc *c = *cp;
    if (c) {
        /* the last substep's pairs and forces kept for the friction's lag (swapped) */
        int32_t *t = c->prev;
        c->prev = c->pij, c->pij = t;
        wb_real *f = c->prevf;
        c->prevf = c->fend, c->fend = f;
        c->nprev = c->sorted ? c->npair : 0;
        c->npair = 0;
        c->sorted = 0;
    }
    if (pc->n == 0 && !any_collider(w)) {
        if (c) c->ng = 0;
        return 0;
    }
    const wb_model *m = &w->m;
    const int32_t np = m->np;
    const wb_real *x = w->s.x, *xp = w->s.x_prev, *wv = m->w, *rad = m->radius, *cf = m->cfric;
    if (!c) {
        c = calloc(1, sizeof *c);
        if (!c) return -1;
        *cp = c;
    }
    /* the pairs it serves, in one pass: a handful of the frame's candidates (a
     * self-colliding cloth has hundreds of thousands and none of them), their keys
     * gathered in (i, j) order (the lag's and the readout's merge; the broad phase's order
     * is its own) */
    const wb_real step = m->def.max_depenetration * h;
    const int32_t *body = w->k.mc_built ? w->k.mc_body : NULL;
    int sorted = 1;
    int32_t n = 0;
    for (int32_t k = 0; k < pc->n; k++) {
        if (!near_pair(w, pc, x, wv, rad, body, bvar, step, k)) continue;
        if (n == c->cap_ks && !grow(w, c, 0, 0, 0, n > 0 ? 2 * n : 64)) {
            c->nprev = 0;
            return -1;
        }
        const int32_t i = pc->ij[2 * k], j = pc->ij[2 * k + 1];
        c->ks[n].key = (uint64_t)i << 32 | (uint32_t)j, c->ks[n].k = k;
        if (n > 0 && c->ks[n - 1].key > c->ks[n].key) sorted = 0;
        n++;
    }
    const int32_t ng = gather_colliders(w, c, h, t0, t1, held);
    if (ng < 0) {
        c->nprev = 0;
        return -1;
    }
    if (n == 0 && ng == 0) {
        c->sorted = 1; /* (no pairs: none lagged into the next substep) */
        return 0;
    }
    /* (the entries, 2 a pair and 1 a collider contact, live in the pairs' room) */
    int32_t want = n + (ng + 1) / 2;
    want = want > c->nprev ? want : c->nprev;
    if (!grow(w, c, np, want, ncolours, n)) {
        c->nprev = 0;
        return -1;
    }
    vbdc_key *ks = c->ks;
    const wb_real inv_h2 = 1 / (h * h);
    /* what each pair was left with by the last projection (contact.c), known within a
     * frame's list; a new list's rule otherwise */
    const wb_real *left = !pc->fresh && pc->left && pc->cap_left >= pc->n ? pc->left : NULL;
    int32_t *start = c->start;
    memset(start, 0, sizeof *start * ((size_t)np + 1));
    if (!sorted) qsort(ks, (size_t)n, sizeof *ks, by_key);
    for (int32_t q = 0; q < n; q++) {
        const int32_t k = ks[q].k, i = pc->ij[2 * k], j = pc->ij[2 * k + 1];
        const wb_real wsum = wv[i] + wv[j], r = rad[i] + rad[j];
        wb_real d[3];
        v3_sub(d, &x[3 * i], &x[3 * j]);
        const wb_real l1 = v3_len(d);
        /* the overlap it keeps this substep, as wb__contact_depth works it out */
        v3_sub(d, &xp[3 * i], &xp[3 * j]);
        wb_real d0 = r - v3_len(d);
        d0 = d0 > 0 ? d0 : 0;
        wb_real l = left && left[k] == left[k] ? left[k] : d0 > step ? d0 : 0;
        l = l < d0 ? l : d0;
        wb_real keep = l - step;
        keep = !(keep > 0) ? 0 : keep;
        c->pij[2 * q] = i, c->pij[2 * q + 1] = j;
        c->tgt[q] = r - keep;
        c->ov[q] = c->ove[q] = r - keep - l1;
        const int self = wv[i] > 0 && wv[j] > 0 && held_self(w, body, i, j);
        c->kk[q] = VBDC_K * inv_h2 / wsum;
        /* each end's penalty in its vertex step: the pair's, but for two movable ends of one
         * colour (contacts are not in the colouring), which step at once from where the
         * other was: each as if the other held, equal masses moved 0.8 of the overlap each
         * (1.6 in all; deferring one end to a Gauss-Seidel step after the colours pushed the
         * two unequally, and a rope dropped across another slid 15 mm along itself). Each
         * sees the pair's penalty in series with the other's inertia, K / (h^2 (w_i + (1 +
         * K) w_j)), so the two steps together are the pair's own implicit step, K / (1 + K)
         * of the overlap shared by inverse mass (the ends' other constraints make it less) */
        const int jac = self && vcol[i] == vcol[j];
        c->ke[2 * q] = jac ? VBDC_K * inv_h2 / (wv[i] + (1 + VBDC_K) * wv[j]) : c->kk[q];
        c->ke[2 * q + 1] = jac ? VBDC_K * inv_h2 / (wv[j] + (1 + VBDC_K) * wv[i]) : c->kk[q];
        c->lam[q] = c->lamp[q] = 0;
        c->mu[q] = (cf[i] + cf[j]) / 2;
        const int32_t mv = wv[i] > 0 ? i : j, b = bmoved && w->k.mc_body ? w->k.mc_body[mv] : -1;
        /* (a self-contact's friction is the body's own: in the vertex steps) */
        c->sf[q] = self || !(b >= 0 && bmoved[b]);
        c->bo[q] = wv[i] > 0 && wv[j] > 0 && !self;
        if (c->bo[q]) continue;
        if (wv[i] > 0) start[i + 1]++;
        if (wv[j] > 0) start[j + 1]++;
    }
    c->npair = n;
    c->sorted = 1;
    /* each pair's lagged normal force: the last substep's, where it had the pair (both
     * lists in (i, j) order) */
    for (int32_t q = 0, o = 0; q < n; q++) {
        const int32_t i = c->pij[2 * q], j = c->pij[2 * q + 1];
        while (o < c->nprev && (c->prev[2 * o] < i || (c->prev[2 * o] == i && c->prev[2 * o + 1] < j))) o++;
        c->fl[q] = o < c->nprev && c->prev[2 * o] == i && c->prev[2 * o + 1] == j ? c->prevf[o] : 0;
    }
    for (int32_t g = 0; g < ng; g++) start[c->gis[2 * g] + 1]++;
    for (int32_t i = 0; i < np; i++) start[i + 1] += start[i];
    const int32_t nent = start[np];
    /* fill from the end of each range backwards, colliders then pairs in reverse: each range
     * its pairs in order, then its colliders (entry -1 - g) */
    for (int32_t g = ng - 1; g >= 0; g--) c->ent[--start[c->gis[2 * g] + 1]] = -1 - g;
    for (int32_t q = n - 1; q >= 0; q--)
        for (int s = 1; s >= 0 && !c->bo[q]; s--) {
            const int32_t i = c->pij[2 * q + s];
            if (wv[i] > 0) c->ent[--start[i + 1]] = 2 * q + s;
        }
    /* (start[i + 1] now holds i's first entry) */
    memmove(start, start + 1, sizeof *start * (size_t)np);
    start[np] = nent;
    int32_t nv = 0;
    for (int32_t col = 0; col < ncolours; col++) {
        c->cvs[col] = nv;
        for (int32_t q = colour_start[col]; q < colour_start[col + 1]; q++) {
            const int32_t i = order[q];
            if (start[i + 1] > start[i]) c->cv[nv++] = i;
        }
    }
    c->cvs[ncolours] = nv;
    /* every end's copy (the immovable ones are not refreshed: they do not move in the solve) */
    for (int32_t q = 0; q < 2 * n; q++) v3_copy(&c->xc[3 * c->pij[q]], &x[3 * c->pij[q]]);
    return 1;
}

/* (sh: i moved by it, its body's move, NULL: where it is; then its self-contacts, which
 * the body's move does not change, are left out; returns the pairs taken) */
static inline __attribute__((always_inline)) int block(const wb_world *w, const wb_vbdc *c, const wb_real *lam, int32_t i,
                                                       const wb_real *sh, wb_real f[3], wb_real H[6], wb_real *fr)
{
    const wb_real *x = w->s.x, *xc = c->xc, *wv = w->m.w;
    wb_real xi[3];
    int got = 0;
    v3_copy(xi, &x[3 * i]);
    if (sh) v3_add(xi, xi, sh);
    for (int32_t e = c->start[i]; e < c->start[i + 1]; e++) {
        if (c->ent[e] < 0) {
            /* a collider: the plane n . x = off */
            const wb_real *o = &c->gd[VBDC_GD * (-1 - c->ent[e])], *n = &o[G_N], kk = o[G_K], fl = o[G_FL];
            const wb_real fn = o[sh ? G_LAMP : G_LAM] - kk * (v3_dot(n, xi) - o[G_OFF]);
            got = 1;
            if (fr && fl > 0) {
                fr[0] += o[G_MU] * fl;
                v3_madd(&fr[1], n, fl);
            }
            if (!(fn > 0)) continue;
            v3_madd(f, n, fn);
            H[0] += kk * n[0] * n[0], H[1] += kk * n[1] * n[1], H[2] += kk * n[2] * n[2];
            H[3] += kk * n[0] * n[1], H[4] += kk * n[0] * n[2], H[5] += kk * n[1] * n[2];
            continue;
        }
        const int32_t q = c->ent[e] >> 1, o = c->pij[2 * q + 1 - (c->ent[e] & 1)];
        if (sh && wv[o] > 0) continue;
        got = 1;
        wb_real d[3];
        v3_sub(d, xi, &xc[3 * o]);
        const wb_real l2 = v3_dot(d, d);
        if (!(l2 > 1e-24)) continue;
        const wb_real l = sqrt(l2), kk = c->ke[c->ent[e]], fn = lam[q] - kk * (l - c->tgt[q]), fl = c->fl[q];
        if (!(fn > 0) && !(fr && fl > 0)) continue;
        wb_real n[3];
        v3_scale(n, d, 1 / l);
        if (fr && fl > 0) {
            /* (the body's friction: its capacity and the direction it pushes along) */
            fr[0] += c->mu[q] * fl;
            v3_madd(&fr[1], n, fl);
        }
        if (!(fn > 0)) continue;
        v3_madd(f, n, fn);
        H[0] += kk * n[0] * n[0], H[1] += kk * n[1] * n[1], H[2] += kk * n[2] * n[2];
        H[3] += kk * n[0] * n[1], H[4] += kk * n[0] * n[2], H[5] += kk * n[1] * n[2];
    }
    return got;
}

void wb__vbdc_block(const wb_world *w, const wb_vbdc *c, int32_t i, wb_real f[3], wb_real H[6])
{
    block(w, c, c->lam, i, NULL, f, H, NULL);
}

void wb__vbdc_friction(const wb_world *w, const wb_vbdc *c, int32_t i, const wb_real H[6], wb_real xi[3])
{
    const wb_real *xc = c->xc, *xp = w->s.x_prev, *wv = w->m.w;
    wb_real cap = 0, N[3] = { 0, 0, 0 }, mv[3] = { 0, 0, 0 }, fm = 0;
    int moving = 0;
    for (int32_t e = c->start[i]; e < c->start[i + 1]; e++) {
        if (c->ent[e] < 0) {
            /* a collider: its surface's move over the substep is the partner's */
            const int32_t g = -1 - c->ent[e];
            const wb_real *o = &c->gd[VBDC_GD * g];
            wb_real fl = o[G_FL];
            if (fl < 0) {
                const wb_real fnow = o[G_LAM] - o[G_K] * (v3_dot(&o[G_N], xi) - o[G_OFF]);
                fl = fnow > 0 ? fnow : 0;
            }
            if (!c->gsf[g] || !(o[G_MU] * fl > 0)) continue;
            cap += o[G_MU] * fl;
            v3_madd(N, &o[G_N], fl);
            fm += fl;
            if (o[G_MV] != 0 || o[G_MV + 1] != 0 || o[G_MV + 2] != 0) v3_madd(mv, &o[G_MV], fl), moving = 1;
            continue;
        }
        const int32_t q = c->ent[e] >> 1, o = c->pij[2 * q + 1 - (c->ent[e] & 1)];
        wb_real fl = c->fl[q], d[3];
        v3_sub(d, xi, &xc[3 * o]);
        const wb_real l = v3_len(d);
        if (wv[o] > 0) {
            /* a movable partner: the force where the Newton step put it (implicit Euler's),
             * not the last substep's, which for two movable ends carries a landing's
             * penalty force (a fold landing on its cloth: 150 times the weight, its flap
             * held where it landed, links stretched 49%) */
            const wb_real fnow = c->lam[q] - c->ke[c->ent[e]] * (l - c->tgt[q]);
            fl = fnow > 0 ? fnow : 0;
        }
        if (!c->sf[q] || !(c->mu[q] * fl > 0)) continue;
        if (!(l > 0)) continue;
        cap += c->mu[q] * fl;
        v3_madd(N, d, fl / l);
        fm += fl;
        if (wv[o] > 0) {
            /* (a movable partner: its move over the substep, weighted by the force; an
             * immovable one's is none) */
            wb_real m[3];
            v3_sub(m, &xc[3 * o], &xp[3 * o]);
            v3_madd(mv, m, fl);
            moving = 1;
        }
    }
    const wb_real nl = v3_len(N);
    if (!(cap > 0) || !(nl > 0)) return;
    v3_scale(N, N, 1 / nl);
    /* the slip over the substep across N (against the movable partners' mean move, the
     * others are immovable) and the force that stops it, the vertex's Hessian times it */
    wb_real u[3], Hu[3];
    v3_sub(u, xi, &xp[3 * i]);
    if (moving) v3_madd(u, mv, -1 / fm);
    v3_madd(u, N, -v3_dot(u, N));
    Hu[0] = H[0] * u[0] + H[3] * u[1] + H[4] * u[2];
    Hu[1] = H[3] * u[0] + H[1] * u[1] + H[5] * u[2];
    Hu[2] = H[4] * u[0] + H[5] * u[1] + H[2] * u[2];
    v3_madd(Hu, N, -v3_dot(Hu, N));
    const wb_real need = v3_len(Hu);
    v3_madd(xi, u, -(need <= cap ? 1 : cap / need));
}

int wb__vbdc_body(const wb_world *w, const wb_vbdc *c, int32_t i, const wb_real sh[3], wb_real f[3], wb_real H[6],
                  wb_real *fr)
{
    return block(w, c, c->lamp, i, sh, f, H, fr);
}

/* pair q's gap C from its target where the particles are, and the force a multiplier
 * base gives it there, clamped at 0 (the dual update of wb__vbdc_dual and _end) */
static inline wb_real pair_force(const wb_real *x, const wb_vbdc *c, int32_t q, wb_real base, wb_real *C)
{
    wb_real d[3];
    v3_sub(d, &x[3 * c->pij[2 * q]], &x[3 * c->pij[2 * q + 1]]);
    *C = v3_len(d) - c->tgt[q];
    const wb_real lm = base - c->kk[q] * *C;
    return lm > 0 ? lm : 0;
}

/* collider contact g's force where the vertex is, from the multiplier base (at 0 or more) */
static inline wb_real g_force(const wb_real *x, const wb_vbdc *c, int32_t g, wb_real base)
{
    const wb_real *o = &c->gd[VBDC_GD * g];
    const wb_real lm = base - o[G_K] * (v3_dot(&o[G_N], &x[3 * c->gis[2 * g]]) - o[G_OFF]);
    return lm > 0 ? lm : 0;
}

void wb__vbdc_end(const wb_world *w, wb_vbdc *c)
{
    for (int32_t g = 0; g < c->ng; g++) {
        wb_real *o = &c->gd[VBDC_GD * g];
        o[G_LAM] = o[G_FEND] = g_force(w->s.x, c, g, o[G_LAMP]);
    }
    for (int32_t q = 0; q < c->npair; q++) {
        wb_real C;
        c->lam[q] = c->fend[q] = pair_force(w->s.x, c, q, c->lamp[q], &C);
        c->ove[q] = -C;
    }
}

const int32_t *wb__vbdc_vertices(const wb_vbdc *c, int32_t ncolours, int32_t *n)
{
    *n = c->cvs[ncolours];
    return c->cv;
}

void wb__vbdc_colour_done(const wb_world *w, wb_vbdc *c, int32_t col)
{
    const wb_real *x = w->s.x;
    for (int32_t q = c->cvs[col]; q < c->cvs[col + 1]; q++) v3_copy(&c->xc[3 * c->cv[q]], &x[3 * c->cv[q]]);
}

void wb__vbdc_dual(const wb_world *w, wb_vbdc *c)
{
    for (int32_t g = 0; g < c->ng; g++) {
        wb_real *o = &c->gd[VBDC_GD * g];
        const wb_real f = g_force(w->s.x, c, g, o[G_LAM]);
        o[G_LAMP] = o[G_LAM];
        o[G_LAM] = f;
    }
    for (int32_t q = 0; q < c->npair; q++) {
        if (c->bo[q]) continue; /* (not in the sweeps: its penalty alone in the coupled step, its
                                   multipliers left at begin's 0) */
        wb_real C;
        const wb_real f = pair_force(w->s.x, c, q, c->lam[q], &C);
        c->lamp[q] = c->lam[q];
        c->lam[q] = f;
    }
}

void wb__vbdc_refresh(const wb_world *w, wb_vbdc *c, int32_t ncolours)
{
    const wb_real *x = w->s.x;
    for (int32_t q = 0; q < c->cvs[ncolours]; q++) v3_copy(&c->xc[3 * c->cv[q]], &x[3 * c->cv[q]]);
}

/* the substep's contacts as w:contacts() reads them: to what the projection after the
 * sweeps reports for a pair (its force depth / (w_i + w_j) / h^2 and that depth) the
 * force the sweeps left it pushing with (its multiplier after the last) and the overlap
 * they corrected. A pair the sweeps parted is not in the projection's list: not
 * reported. */
void wb__vbdc_readout(wb_world *w, const wb_vbdc *c)
{
    wb_contacts *pc = w->k.pc;
    if (!c || !c->sorted || c->npair == 0) return;
    for (int32_t a = 0; a < pc->nact; a++) {
        const int32_t k = pc->act[a], i = pc->ij[2 * k], j = pc->ij[2 * k + 1];
        int32_t lo = 0, hi = c->npair;
        while (lo < hi) {
            const int32_t mid = lo + (hi - lo) / 2, pi = c->pij[2 * mid], pj = c->pij[2 * mid + 1];
            if (pi < i || (pi == i && pj < j)) lo = mid + 1;
            else hi = mid;
        }
        if (!(lo < c->npair && c->pij[2 * lo] == i && c->pij[2 * lo + 1] == j)) continue;
        const wb_real done = c->ov[lo] - c->ove[lo];
        pc->act_nd[7 * a + 4] += c->lam[lo];
        if (done > 0) pc->act_nd[7 * a + 3] += done;
    }
}

/* ---- the bodies moved together ------------------------------------------------------------- */
/* A body's move in the coupled step is u = (t, th): its translation and a small turn about
 * its centre c, so a point r = x - c of it moves by A u = t + th x r; a force f there is
 * A^T f = (f, r x f) on it. */
static inline void cross3(const double a[3], const double b[3], double out[3])
{
    out[0] = a[1] * b[2] - a[2] * b[1], out[1] = a[2] * b[0] - a[0] * b[2], out[2] = a[0] * b[1] - a[1] * b[0];
}

static inline void sym3_mul(const double H[6], const double u[3], double out[3])
{
    out[0] = H[0] * u[0] + H[3] * u[1] + H[4] * u[2];
    out[1] = H[3] * u[0] + H[1] * u[1] + H[5] * u[2];
    out[2] = H[4] * u[0] + H[5] * u[1] + H[2] * u[2];
}

/* d = A u at r */
static inline void a_mul(const double r[3], const double u[6], double d[3])
{
    cross3(&u[3], r, d);
    for (int k = 0; k < 3; k++) d[k] += u[k];
}

/* y (6) += s A^T v at r */
static inline void at_add(const double r[3], const double v[3], double s, double y[6])
{
    double m[3];
    cross3(r, v, m);
    for (int k = 0; k < 3; k++) y[k] += s * v[k], y[3 + k] += s * m[k];
}

/* D (6 x 6) += A^T H A at r (H: symmetric 3 x 3, xx, yy, zz, xy, xz, yz) */
static void add_block(double D[36], const double r[3], const double H[6])
{
    double col[6][3], Hc[6][3];
    for (int k = 0; k < 6; k++) {
        double e[3] = { 0, 0, 0 };
        e[k % 3] = 1;
        if (k < 3) col[k][0] = e[0], col[k][1] = e[1], col[k][2] = e[2];
        else cross3(e, r, col[k]);
        sym3_mul(H, col[k], Hc[k]);
    }
    for (int i = 0; i < 6; i++)
        for (int j = 0; j < 6; j++) D[6 * i + j] += col[i][0] * Hc[j][0] + col[i][1] * Hc[j][1] + col[i][2] * Hc[j][2];
}

/* the Cholesky factor L of a symmetric positive definite 6 x 6 D (lower, row-major); 0 when
 * it is not */
static int chol6(const double D[36], double L[36])
{
    for (int i = 0; i < 6; i++)
        for (int j = 0; j <= i; j++) {
            double s = D[6 * i + j];
            for (int k = 0; k < j; k++) s -= L[6 * i + k] * L[6 * j + k];
            if (i == j) {
                if (!(s > 0)) return 0;
                L[6 * i + i] = sqrt(s);
            } else {
                L[6 * i + j] = s / L[6 * j + j];
            }
        }
    return 1;
}

static void chol6_solve(const double L[36], const double b[6], double x[6])
{
    double y[6];
    for (int i = 0; i < 6; i++) {
        double s = b[i];
        for (int k = 0; k < i; k++) s -= L[6 * i + k] * y[k];
        y[i] = s / L[6 * i + i];
    }
    for (int i = 5; i >= 0; i--) {
        double s = y[i];
        for (int k = i + 1; k < 6; k++) s -= L[6 * k + i] * x[k];
        x[i] = s / L[6 * i + i];
    }
}

/* a contact record of the step (CQ doubles): its Hessian across its ends' points (sym. 3 x 3),
 * 1 while it pushes (else -1), the points' offsets from their bodies' centres */
#define CQ 13

/* y = A u for the step's matrix: each body's block D times its u, less, for each contact
 * pushing between two bodies of the step, A_a^T H A_b u_b on a and A_b^T H A_a u_a on b */
static void couple_mul(int32_t ncq, const int32_t *vi, const double *D, const double *cq, int32_t nv, const double *u,
                       double *y)
{
    for (int32_t b = 0; b < nv; b++)
        for (int i = 0; i < 6; i++) {
            double s = 0;
            for (int j = 0; j < 6; j++) s += D[36 * b + 6 * i + j] * u[6 * b + j];
            y[6 * b + i] = s;
        }
    for (int32_t q = 0; q < ncq; q++) {
        const int32_t a = vi[2 * q], b = vi[2 * q + 1];
        const double *o = &cq[CQ * q];
        if (a < 0 || b < 0 || o[6] < 0) continue;
        double da[3], db[3], ha[3], hb[3];
        a_mul(o + 7, &u[6 * a], da);
        a_mul(o + 10, &u[6 * b], db);
        sym3_mul(o, db, hb);
        sym3_mul(o, da, ha);
        at_add(o + 7, hb, -1, &y[6 * a]);
        at_add(o + 10, ha, -1, &y[6 * b]);
    }
}

/* a contact of the step pushing with fn > 0 along n (from b's side to a's), of penalty kk,
 * with its friction: the relative slip us over the substep across n held by a tangential
 * spring of the same stiffness while its force is within mu fn, else pushed back by mu fn
 * (its Hessian then the cone's, fn mu / |u_t| across u_t and n). Its force goes to a (b:
 * the opposite), its Hessian to o (CQ record, whose offsets are set) and both bodies'
 * blocks D: each contact's forces are equal and opposite, the step keeps the momentum */
static void couple_add(int32_t a, int32_t b, const double n[3], double fn, double kk, double mu, const double us[3],
                       double *o, double *D, double *g)
{
    double f[3], ut[3];
    const double un = us[0] * n[0] + us[1] * n[1] + us[2] * n[2];
    for (int k = 0; k < 3; k++) ut[k] = us[k] - un * n[k], f[k] = fn * n[k];
    const double ul = sqrt(ut[0] * ut[0] + ut[1] * ut[1] + ut[2] * ut[2]), cap = mu * fn;
    double kt = 0, ks = 0, e[3] = { 0, 0, 0 }; /* across n, kt (I - n n^T) - ks e e^T */
    if (cap > 0 && ul > 0) {
        if (kk * ul <= cap) {
            kt = kk;
            for (int k = 0; k < 3; k++) f[k] -= kk * ut[k];
        } else {
            kt = cap / ul, ks = kt;
            for (int k = 0; k < 3; k++) e[k] = ut[k] / ul, f[k] -= cap * e[k];
        }
    }
    const double kn = kk - kt;
    double *H = o;
    H[0] = kn * n[0] * n[0] + kt - ks * e[0] * e[0], H[1] = kn * n[1] * n[1] + kt - ks * e[1] * e[1];
    H[2] = kn * n[2] * n[2] + kt - ks * e[2] * e[2], H[3] = kn * n[0] * n[1] - ks * e[0] * e[1];
    H[4] = kn * n[0] * n[2] - ks * e[0] * e[2], H[5] = kn * n[1] * n[2] - ks * e[1] * e[2], H[6] = 1;
    if (a >= 0) add_block(&D[36 * a], o + 7, H), at_add(o + 7, f, 1, &g[6 * a]);
    if (b >= 0) add_block(&D[36 * b], o + 10, H), at_add(o + 10, f, -1, &g[6 * b]);
}

int wb__vbdc_tri_kind(const wb_world *w, int32_t k, int32_t *bp, int32_t *bt)
{
    const wb_tricontacts *tc = w->k.tc;
    const int32_t *body = w->k.mc_body, p = tc->pt[2 * k], *v = &w->m.tri[3 * tc->pt[2 * k + 1]];
    const wb_real *wv = w->m.w;
    *bp = body[p], *bt = body[v[0]];
    if (*bp < 0 || *bt < 0 || *bp == *bt) return 0;
    int kind = WB_VBDC_TRI | (wb__contacts_made(w, p, v[0]) ? WB_VBDC_MADE : 0);
    if (body[v[1]] == *bt && body[v[2]] == *bt) {
        kind |= WB_VBDC_ONE;
        if (wv[v[0]] > 0 && wv[v[1]] > 0 && wv[v[2]] > 0) kind |= WB_VBDC_WHOLE;
    }
    return kind;
}

/* the triangle contacts between two bodies of the coupled step: a point of one body, a
 * triangle of another (all its corners that body's), not made inside each other; a
 * triangle held anywhere stays where it is in the step (touching() keeps a point's body
 * out of the step when the triangle is held only in part). *a, *b: the point's and the
 * triangle's bodies in the step, -1 held; 1 when one of them is in it */
static int tri_between(const wb_world *w, const int32_t *bvar, int32_t k, int32_t *a, int32_t *b)
{
    int32_t bp, bt;
    const int kind = wb__vbdc_tri_kind(w, k, &bp, &bt);
    if (!(kind & WB_VBDC_ONE) || (kind & WB_VBDC_MADE)) return 0;
    /* (a held body's movable point or triangle is no wall of the step: the projection's) */
    const int pmove = w->m.w[w->k.tc->pt[2 * k]] > 0;
    if ((pmove && w->k.mc_acc[16 * bp] < 0) || ((kind & WB_VBDC_WHOLE) && w->k.mc_acc[16 * bt] < 0)) return 0;
    *a = pmove ? bvar[bp] : -1;
    *b = kind & WB_VBDC_WHOLE ? bvar[bt] : -1;
    return *a >= 0 || *b >= 0;
}

/* (a point's offset from the centre of body a of the step, 0 when it is not one) */
static inline void offset(const double *bs, int32_t a, const wb_real *xq, double r[3])
{
    for (int k = 0; k < 3; k++) r[k] = a >= 0 ? (double)xq[k] - bs[WB_VBDC_BS * a + 4 + k] : 0;
}

int wb__vbdc_couple(wb_world *w, wb_vbdc **cp, const int32_t *bvar, int32_t nv, const double *bs, double *u, wb_real h,
                    int32_t steps)
{
    const int32_t *body = w->k.mc_body;
    const wb_real *x = w->s.x, *xp = w->s.x_prev, *wv = w->m.w, *rad = w->m.radius, *cf = w->m.cfric, inv_h2 = 1 / (h * h);
    const wb_tricontacts *tc = w->k.tc;
    if (!*cp) {
        *cp = calloc(1, sizeof **cp);
        if (!*cp) return -1;
        (*cp)->sorted = 1;
    }
    wb_vbdc *c = *cp;
    /* the triangle contacts between the bodies, gathered once (candidate, a, b) */
    int32_t ntc = 0;
    for (int32_t k = 0; k < tc->n; k++) {
        int32_t a, b;
        if (!tri_between(w, bvar, k, &a, &b)) continue;
        if (ntc == c->cap_tk) {
            const int32_t cap = ntc > 0 ? 2 * ntc : 64;
            if (!wb__charge(w, &c->charged_tk, sizeof(int32_t) * 3 * (size_t)cap)) return -1;
            int32_t *t = realloc(c->tk, sizeof *t * 3 * (size_t)cap);
            if (!t) return -1;
            c->tk = t, c->cap_tk = cap;
        }
        c->tk[3 * ntc] = k, c->tk[3 * ntc + 1] = a, c->tk[3 * ntc + 2] = b;
        ntc++;
    }
    const int32_t np2 = c->npair;
    const size_t ncq = (size_t)np2 + (size_t)ntc;
    const size_t need = 108 * (size_t)nv + (CQ + 1) * ncq + 10 * (size_t)ntc + 6 * (size_t)np2;
    if (need > c->cap_cs) {
        if (!wb__charge(w, &c->charged_cs, sizeof(double) * need)) return -1;
        double *cs = realloc(c->cs, sizeof *cs * need);
        if (!cs) return -1;
        c->cs = cs, c->cap_cs = need;
    }
    double *D = c->cs, *Lf = D + 36 * (size_t)nv, *g = Lf + 36 * (size_t)nv, *r = g + 6 * (size_t)nv;
    double *z = r + 6 * (size_t)nv, *p = z + 6 * (size_t)nv, *Ap = p + 6 * (size_t)nv, *du = Ap + 6 * (size_t)nv;
    double *cq = du + 6 * (size_t)nv;
    /* (each contact's ends' bodies in the step, -1: held where they are, in doubles' room) */
    int32_t *vi = (int32_t *)(cq + CQ * ncq);
    for (int32_t q = 0; q < np2; q++)
        for (int s = 0; s < 2; s++) {
            const int32_t i = c->pij[2 * q + s];
            vi[2 * q + s] = wv[i] > 0 && body[i] >= 0 ? bvar[body[i]] : -1;
            offset(bs, vi[2 * q + s], &x[3 * i], &cq[CQ * q + 7 + 3 * s]);
        }
    /* each triangle contact near enough as a plane: its normal nn and the gap's base
     * nn . (x_p - q) at u = 0 (the triangle moves rigidly here: its closest point and
     * normal are kept, linearised), the target r_p (a point made inside the other body is
     * the projection's), its penalty over W = w_p + sum b_i^2 w_i; td: nn, base, target,
     * k, the slip of p against its closest point over the substep at u = 0, mu
     * (tricontact.c's) */
    double *td = (double *)(vi + 2 * ncq);
    /* (each pair's ends' moves over the substep so far, x - x_prev: the slip's base, the
     * same at every Newton step) */
    double *ev = td + 10 * (size_t)ntc;
    for (int32_t q = 0; q < np2; q++)
        for (int k = 0; k < 3; k++) {
            const int32_t i = c->pij[2 * q], j = c->pij[2 * q + 1];
            ev[6 * q + k] = (double)x[3 * i + k] - (double)xp[3 * i + k];
            ev[6 * q + 3 + k] = (double)x[3 * j + k] - (double)xp[3 * j + k];
        }
    int32_t nt = 0;
    const wb_real step = w->m.def.max_depenetration * h;
    for (int32_t g = 0; g < ntc; g++) {
        const int32_t k = c->tk[3 * g], a = c->tk[3 * g + 1], b = c->tk[3 * g + 2];
        const int32_t pp = tc->pt[2 * k], *v = &w->m.tri[3 * tc->pt[2 * k + 1]];
        const wb_real rr = rad[pp];
        wb_real bc[3], q[3], d[3], n[3], ln, s_prev, s_now, nw[3], depth;
        const wb_real d2 = wb__tri_closest(&x[3 * pp], &x[3 * v[0]], &x[3 * v[1]], &x[3 * v[2]], bc, q);
        v3_sub(d, &x[3 * pp], q);
        /* the projection's normal (wb__tri_normal), within the pairs' reach */
        wb__tri_side(x, xp, pp, v, n, &ln, &s_prev, &s_now);
        if (wb__tri_normal(x, xp, pp, v, n, ln, s_prev, s_now, bc, d, d2, sqrt(d2), rr, rr * WB_VBDC_NEAR, nw, &depth) <= 0)
            continue;
        const double nn[3] = { nw[0], nw[1], nw[2] };
        const wb_real W = wv[pp] + bc[0] * bc[0] * wv[v[0]] + bc[1] * bc[1] * wv[v[1]] + bc[2] * bc[2] * wv[v[2]];
        if (!(W > 0)) continue;
        wb_real bp[3], qp[3];
        const wb_real d0 = rr - sqrt(wb__tri_closest(&xp[3 * pp], &xp[3 * v[0]], &xp[3 * v[1]], &xp[3 * v[2]], bp, qp));
        if (starts_deep(d0, step)) continue;
        double *o = &td[10 * (size_t)nt];
        for (int k3 = 0; k3 < 3; k3++) {
            o[k3] = nn[k3];
            o[6 + k3] = (double)x[3 * pp + k3] - (double)xp[3 * pp + k3];
            for (int e = 0; e < 3; e++) o[6 + k3] -= bc[e] * ((double)x[3 * v[e] + k3] - (double)xp[3 * v[e] + k3]);
        }
        o[3] = nn[0] * d[0] + nn[1] * d[1] + nn[2] * d[2], o[4] = rr, o[5] = VBDC_K * inv_h2 / W;
        o[9] = (cf[pp] + bc[0] * cf[v[0]] + bc[1] * cf[v[1]] + bc[2] * cf[v[2]]) / 2;
        const size_t e = (size_t)np2 + (size_t)nt;
        vi[2 * e] = a, vi[2 * e + 1] = b;
        offset(bs, a, &x[3 * pp], &cq[CQ * e + 7]);
        offset(bs, b, q, &cq[CQ * e + 10]);
        nt++;
    }
    const int32_t nc = np2 + nt;
    memset(u, 0, sizeof *u * 6 * (size_t)nv);
    for (int32_t pass = 0; pass < steps; pass++) {
        /* each body's inertia: M / h^2 for t, I / h^2 for th (its least axis kept from 0: a
         * rope's own axis), the gradient of sum m |x - y + A u|^2 / 2 h^2 */
        for (int32_t b = 0; b < nv; b++) {
            const double *B = &bs[WB_VBDC_BS * b], mh = B[0] * inv_h2, *I = &B[10];
            const double reg = 1e-6 * (I[0] + I[1] + I[2]) / 3 + 1e-30;
            double *Db = &D[36 * b], Ith[3];
            memset(Db, 0, sizeof *Db * 36);
            Db[0] = Db[7] = Db[14] = mh;
            const double Is[6] = { I[0] + reg, I[1] + reg, I[2] + reg, I[3], I[4], I[5] };
            const int ix[3][3] = { { 0, 3, 4 }, { 3, 1, 5 }, { 4, 5, 2 } };
            for (int i = 0; i < 3; i++)
                for (int j = 0; j < 3; j++) Db[6 * (3 + i) + 3 + j] = Is[ix[i][j]] * inv_h2;
            sym3_mul(Is, &u[6 * b + 3], Ith);
            for (int k = 0; k < 3; k++) {
                g[6 * b + k] = -mh * (B[1 + k] + u[6 * b + k]);
                g[6 * b + 3 + k] = -(B[7 + k] + Ith[k]) * inv_h2;
            }
        }
        for (int32_t q = 0; q < np2; q++) {
            const int32_t a = vi[2 * q], b = vi[2 * q + 1], i = c->pij[2 * q], j = c->pij[2 * q + 1];
            double *o = &cq[CQ * q];
            o[6] = -1;
            if (a < 0 && b < 0) continue;
            double da[3] = { 0, 0, 0 }, db[3] = { 0, 0, 0 }, d[3], us[3];
            if (a >= 0) a_mul(o + 7, &u[6 * a], da);
            if (b >= 0) a_mul(o + 10, &u[6 * b], db);
            for (int k = 0; k < 3; k++) {
                d[k] = ((double)x[3 * i + k] + da[k]) - ((double)x[3 * j + k] + db[k]);
                us[k] = (ev[6 * q + k] + da[k]) - (ev[6 * q + 3 + k] + db[k]);
            }
            const double l = sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]), kk = c->kk[q];
            if (!(l > 1e-12)) continue;
            const double fn = (double)c->lamp[q] - kk * (l - (double)c->tgt[q]);
            if (!(fn > 0)) continue;
            const double n[3] = { d[0] / l, d[1] / l, d[2] / l };
            couple_add(a, b, n, fn, kk, c->mu[q], us, o, D, g);
        }
        for (int32_t q = 0; q < nt; q++) {
            const size_t e = (size_t)np2 + (size_t)q;
            const int32_t a = vi[2 * e], b = vi[2 * e + 1];
            const double *t = &td[10 * (size_t)q];
            double *o = &cq[CQ * e];
            double da[3] = { 0, 0, 0 }, db[3] = { 0, 0, 0 }, us[3];
            if (a >= 0) a_mul(o + 7, &u[6 * a], da);
            if (b >= 0) a_mul(o + 10, &u[6 * b], db);
            double gap = t[3];
            for (int k = 0; k < 3; k++) gap += t[k] * (da[k] - db[k]), us[k] = t[6 + k] + da[k] - db[k];
            const double fn = -t[5] * (gap - t[4]);
            o[6] = -1;
            if (!(fn > 0)) continue;
            couple_add(a, b, t, fn, t[5], t[9], us, o, D, g);
        }
        /* the Newton step, A du = g, by conjugate gradients with each body's block as the
         * preconditioner (serial, in body order: the same bits on any thread count) */
        double rz = 0, gg = 0;
        for (int32_t b = 0; b < nv; b++) {
            if (!chol6(&D[36 * b], &Lf[36 * b])) return 0;
            chol6_solve(&Lf[36 * b], &g[6 * b], &z[6 * b]);
            for (int k = 0; k < 6; k++) {
                du[6 * b + k] = 0, r[6 * b + k] = g[6 * b + k], p[6 * b + k] = z[6 * b + k];
                rz += r[6 * b + k] * z[6 * b + k], gg += g[6 * b + k] * g[6 * b + k];
            }
        }
        for (int32_t it = 0; it < 6 * nv + 20 && rz > 0; it++) {
            couple_mul(nc, vi, D, cq, nv, p, Ap);
            double pAp = 0;
            for (int32_t k = 0; k < 6 * nv; k++) pAp += p[k] * Ap[k];
            if (!(pAp > 0)) break;
            const double al = rz / pAp;
            double rr = 0;
            for (int32_t k = 0; k < 6 * nv; k++) du[k] += al * p[k], r[k] -= al * Ap[k], rr += r[k] * r[k];
            if (!(rr > 1e-30 * gg)) break;
            double rz1 = 0;
            for (int32_t b = 0; b < nv; b++) {
                chol6_solve(&Lf[36 * b], &r[6 * b], &z[6 * b]);
                for (int k = 0; k < 6; k++) rz1 += r[6 * b + k] * z[6 * b + k];
            }
            const double be = rz1 / rz;
            rz = rz1;
            for (int32_t k = 0; k < 6 * nv; k++) p[k] = z[k] + be * p[k];
        }
        double d2 = 0, u2 = 0;
        for (int32_t k = 0; k < 6 * nv; k++) {
            u[k] += du[k];
            d2 += du[k] * du[k], u2 += u[k] * u[k];
        }
        if (!(d2 > 1e-24 * u2)) break;
    }
    return 1;
}
