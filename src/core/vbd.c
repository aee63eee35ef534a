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
 * Descent", SIGGRAPH 2025), k C^2 / 2 + lambda C, lambda growing by k C after each sweep
 * and carried from substep to substep (warm start) so a hanging chain holds its tension
 * instead of finding it again every substep.
 *
 * Served: distance links, bends, Neo-Hookean tets, and particle pairs with one immovable
 * end (vbd_contact.c). The other types are projected as in XPBD after each sweep, and
 * contacts (all of them, again: what the sweeps left), colliders and rigid bodies follow
 * the sweeps as in the XPBD step (solver.c). */
#include <stdlib.h>
#include <string.h>

#include "bend.h"
#include "pool.h"
#include "rigid.h"
#include "snapshot.h"
#include "tet.h"
#include "volume.h"
#include "vbd.h"
#include "contact.h"
#include "tricontact.h"
#include "vbd_contact.h"

/* a link as the sweep reads it: its force along it is kk (l - tgt) + lm and its stiffness
 * kk; dmp: a soft link's damping beta / h */
typedef struct vbd_link {
    wb_real tgt, kk, lm, dmp;
} vbd_link;

struct wb_vbd {
    int32_t np, nd, nt, nb; /* the model it was built for */
    int32_t *adj_start;    /* (np + 1) each vertex's range of adj, padded to a multiple of 4 */
    int32_t *adj;          /* link slots touching each vertex (-1: padding) */
    int32_t *adjo;         /* the other end of each of them (padding: the vertex itself) */
    wb_real *ekk, *etg, *elm, *edm; /* each entry's link as the sweep reads it (vbd_link's kk,
                              tgt, lm, dmp; padding 0): 4 entries in one load each */
    int32_t *epos;         /* (2 nd) the two entries of each link */
    int32_t *tadj_start;   /* (np + 1) each vertex's range of tadj */
    int32_t *tadj;         /* 4 tet + corner of the Neo-Hookean tets touching each vertex */
    int32_t *badj_start;   /* (np + 1) each vertex's range of badj */
    int32_t *badj;         /* 4 bend + corner of the bends touching each vertex */
    int32_t *order;        /* (np) the vertices by colour */
    int32_t *colour_start; /* (ncolours + 1) ranges of order */
    int32_t ncolours;
    int serial_last;       /* the last colour holds vertices that may share a link (more
                              colours than a mask holds): it runs on one thread */
    wb_real *y;            /* (np x 3) the substep's prediction */
    wb_real *lam;          /* (nd) a hard link's multiplier (a stiff one's: its tension) */
    wb_real *c0;           /* (nd) a hard link's error (a stiff one's: C - alpha lam) as the
                              last sweep left it, before the types projected after it (NaN:
                              not known), of which it keeps VBD_STAB (AVBD's stabilisation) */
    vbd_link *lk;          /* (nd) what the sweep reads of each link, set each substep */
    int32_t *hard;         /* (nd) the live hard links' slots, this substep, from the front
                              (nhard), and the stiff ones' from the back (nstiff) */
    int32_t nhard, nstiff;
    int32_t cap_lam;
    wb_real *blam, *bkpen; /* (nb, by slot) a hard bend's multiplier and penalty */
    wb_real *btg, *bc0;    /* (nb) a hard bend's target (the error it keeps this substep) and
                              its error as the last sweep left it (NaN: not known) */
    int32_t cap_blam;
    wb_real *save;         /* (2 cap_lam + 2 cap_blam) lam, c0, blam, bc0 at the step's start:
                              an undone frame puts them back (wb__vbd_undo) */
    int restored;          /* made from a snapshot image: the next rebuild keeps c0 (the
                              image holds what the saved world's next step starts from) */
    wb_real residual;      /* the last sweep's largest step, m */
    double *tsum;          /* (bodies x 4) each free body's mass and sum m (x - y), then
                              (bodies) 1: it may touch an immovable particle, then (bodies
                              x 3) its momentum step's translation (keep_momentum) */
    int32_t cap_tsum;
    double *csum;          /* (bodies x 17) a free body's contacts in the vertex steps
                              (keep_momentum) */
    uint8_t *bmove;        /* (bodies) 1: its friction goes in its momentum step */
    int32_t *bvar;         /* (bodies) its index among the free bodies that may touch another
                              body's movable particle, moved with them (wb__vbdc_couple); -1 */
    int32_t nvar;
    double *vsum;          /* (nvar x (WB_VBDC_BS + 14)) their sums, moves, turns and rounding
                              (couple) */
    wb_vbdc *ct;           /* the particle contacts in the vertex steps (vbd_contact.c) */
    int ct_on;             /* ct holds this substep's */
    size_t charged;        /* the struct's and its arrays' bytes charged to def.memory, but for
                              tsum, csum, bmove (charged_t) and ct (its own) */
    size_t charged_t;
    int nomem;             /* the last solve ran out of memory (the budget refused its
                              scratch): the step undoes the frame (wb__vbd_failed) */
};

#define VBD_COLOURS 64
/* A hard link's multiplier lambda is kept whole from substep to substep (decayed, a chain
 * at rest kept a stretch of its decay over its penalty) and grows by k C after each sweep
 * (the augmented Lagrangian's own update). Its penalty k is fixed, VBD_LINK_K times the
 * inertia of its ends over the substep (start_penalty): a penalty that grew while a link
 * was stretched and decayed while it was not pumped energy into swinging chains (a rope
 * swinging at 40 x 4 gained twice its energy); measured: 4 k0 let a 100-link chain hang 6%
 * long, 16 k0 threw a lattice stacked on another, 64 k0 let a two-pin cloth gain 3x its
 * energy. Of the error a link begins the substep with it keeps VBD_STAB (AVBD's
 * stabilisation): carried over, a multiplier that also took in the error it had already
 * corrected fed it back as speed (0.995: the clamped strip at 40 x 1 swung 0.15 m off its
 * droop; all of it corrected, a 1-D chain's modes grew 15% a substep).
 * A hard bend is held the same way (multiplier carried whole, VBD_STAB of its error kept)
 * with its penalty VBD_BEND_K times the inertia of its angle (bend_start_penalty; rad,
 * not m: the gradient of a 5 cm wing is 20 /m). That is the stiffness the bend has until its
 * multiplier catches up: a clamped strip with rigid bends droops 0.55 m at 8, 12 mm at
 * 512 and 1.4 mm at 4096 (10 x 1) before it straightens (512: what the suite ran with) */
#define VBD_LINK_K ((wb_real)8)
#define VBD_STAB ((wb_real)0.999)
/* in a world with volume constraints (projected after the sweeps) a body of rigid links
 * and incompressible tets is over-constrained under a press: a link that takes its error
 * back faster fights the tets (0.99: a block squeezed to 60% blew up 3 s on at 10 m/s), a
 * slower one holds the squeeze after the press lets go (0.999: back to 0.87 of its height) */
#define VBD_STAB_VOL ((wb_real)0.995)
#define VBD_BEND_K ((wb_real)512)
/* a bend keeps VBD_STAB of its error per this much time (the default substep), a link per
 * substep: per time, a rope of rigid links at 40 x 4 stretched 3.7% (3% allowed), the
 * catenary at 40 x 1 read its tension 3.4% off and a hand-built cloth fell through its
 * sphere (user/01-03); the clamped strip at 40 x 1 held its droop better (0.2873 m at
 * frame 2400 against 0.2825, converged 0.2881) */
#define VBD_STAB_T ((wb_real)1 / 600)
/* at most this many Newton steps for a free body's translation with its contacts
 * (keep_momentum) */
#define VBD_MOVE_STEPS 8
/* two bodies with a pair closer than this times r_i + r_j where the substep starts were
 * made inside each other: contact.c parts them, they are not moved together (measured,
 * two blocks made with coincident layers: a particle flung at 1.24 m/s with them moved
 * together; 0.5 of the contact distance: 0.88, as before; 0.95: blocks made interleaved
 * gained 49 J where 12 are allowed) */
#define VBD_MADE_DEEP ((wb_real)0.5)

void wb__vbd_destroy(wb_world *w)
{
    struct wb_vbd *v = w->vbd;
    if (!v) return;
    free(v->adj_start);
    free(v->adj);
    free(v->adjo);
    free(v->ekk);
    free(v->etg);
    free(v->elm);
    free(v->edm);
    free(v->epos);
    free(v->lk);
    free(v->hard);
    free(v->tadj_start);
    free(v->tadj);
    free(v->badj_start);
    free(v->badj);
    free(v->order);
    free(v->colour_start);
    free(v->y);
    free(v->lam);
    free(v->c0);
    free(v->blam);
    free(v->bkpen);
    free(v->btg);
    free(v->bc0);
    free(v->save);
    free(v->tsum);
    free(v->csum);
    free(v->bmove);
    free(v->bvar);
    free(v->vsum);
    wb__vbdc_destroy(w, v->ct);
    wb__charge(w, &v->charged, 0);
    wb__charge(w, &v->charged_t, 0);
    free(v);
    w->vbd = NULL;
}

int wb__vbd_serves(const wb_ctype *t) { return t == &wb__distance_type || t == &wb__tet_type || t == &wb__bend_type; }

static int link_live(const wb_world *w, int32_t s)
{
    const wb_distances *ds = wb__dist(w->dist);
    return (ds->gen[s] & 1u) && !ds->broken[s];
}

/* each vertex's elements of four corners q (n x 4), as 4 element + corner (CSR) */
static int quads(int32_t np, const int32_t *q, int32_t n, int32_t **start_out, int32_t **adj_out)
{
    int32_t *ts = calloc((size_t)np + 1, sizeof *ts);
    if (!ts) return 0;
    for (int64_t k = 0; k < 4 * (int64_t)n; k++) ts[q[k] + 1]++;
    for (int32_t i = 0; i < np; i++) ts[i + 1] += ts[i];
    int32_t *ta = malloc(sizeof *ta * (size_t)(ts[np] > 0 ? ts[np] : 1)), *tf = malloc(sizeof *tf * (size_t)(np > 0 ? np : 1));
    if (!ta || !tf) {
        free(ts), free(ta), free(tf);
        return 0;
    }
    memcpy(tf, ts, sizeof *tf * (size_t)np);
    for (int32_t k = 0; k < 4 * n; k++) ta[tf[q[k]]++] = k;
    free(tf);
    free(*start_out);
    free(*adj_out);
    *start_out = ts;
    *adj_out = ta;
    return 1;
}

/* what prepare holds for np vertices, ne adjacency entries, nd link slots, nt tets, nb
 * bends and the multipliers' capacities: the struct, the adjacency (adj_start, adj, adjo,
 * the 4 entry arrays, epos, tadj, badj and their starts), the colouring (order,
 * colour_start), y, the links' lam, c0, lk, hard, the bends' blam, bkpen, btg, bc0, save */
static size_t model_bytes(int64_t np, int64_t ne, int64_t nd, int64_t nt, int64_t nb, int64_t cap_lam, int64_t cap_blam)
{
    const int64_t n1 = np > 0 ? np : 1;
    const size_t r = sizeof(wb_real), i4 = sizeof(int32_t);
    return sizeof(struct wb_vbd) + 3 * (size_t)(np + 1) * i4 + (size_t)ne * (2 * i4 + 4 * r) +
           2 * (size_t)(nd > 0 ? nd : 1) * i4 + (size_t)(4 * nt > 0 ? 4 * nt : 1) * i4 +
           (size_t)(4 * nb > 0 ? 4 * nb : 1) * i4 + (size_t)n1 * (i4 + 3 * r) + (VBD_COLOURS + 1) * i4 +
           (size_t)cap_lam * (2 * r + sizeof(vbd_link) + i4) + (size_t)cap_blam * 4 * r +
           (2 * (size_t)cap_lam + 2 * (size_t)cap_blam + 1) * r;
}

/* each vertex's links (CSR, each range padded to a multiple of 4 for the vector lanes) */
static int build_adjacency(wb_world *w, struct wb_vbd *v)
{
    const wb_model *m = &w->m;
    const wb_distances *ds = wb__dist(w->dist);
    const int32_t np = m->np, nd = ds->n;
    int32_t *start = calloc((size_t)np + 1, sizeof *start);
    if (!start) return 0;
    for (int32_t s = 0; s < nd; s++)
        if (link_live(w, s)) start[ds->ij[2 * s] + 1]++, start[ds->ij[2 * s + 1] + 1]++;
    for (int32_t i = 0; i < np; i++) start[i + 1] = start[i] + ((start[i + 1] + 3) & ~3);
    const size_t ne = (size_t)(start[np] > 0 ? start[np] : 1);
    /* everything prepare holds for this model, charged before it is taken */
    const int32_t nb = wb_bend_count(w);
    if (!wb__charge(w, &v->charged, model_bytes(np, (int64_t)ne, nd, w->neo ? w->neo->n : 0, nb,
                                                nd > v->cap_lam ? nd : v->cap_lam, nb > v->cap_blam ? nb : v->cap_blam))) {
        free(start);
        return 0;
    }
    int32_t *adj = malloc(sizeof *adj * ne), *adjo = malloc(sizeof *adjo * ne);
    int32_t *epos = malloc(sizeof *epos * 2 * (size_t)(nd > 0 ? nd : 1));
    int32_t *fill = malloc(sizeof *fill * (size_t)(np > 0 ? np : 1));
    wb_real *ek[4];
    for (int c = 0; c < 4; c++) ek[c] = calloc(ne, sizeof(wb_real));
    if (!adj || !adjo || !epos || !fill || !ek[0] || !ek[1] || !ek[2] || !ek[3]) {
        free(start), free(adj), free(adjo), free(epos), free(fill);
        for (int c = 0; c < 4; c++) free(ek[c]);
        return 0;
    }
    memcpy(fill, start, sizeof *fill * (size_t)np);
    for (int32_t s = 0; s < nd; s++) {
        if (!link_live(w, s)) continue;
        const int32_t a = ds->ij[2 * s], b = ds->ij[2 * s + 1];
        epos[2 * s] = fill[a], adjo[fill[a]] = b, adj[fill[a]++] = s;
        epos[2 * s + 1] = fill[b], adjo[fill[b]] = a, adj[fill[b]++] = s;
    }
    for (int32_t i = 0; i < np; i++)
        for (int32_t e = fill[i]; e < start[i + 1]; e++) adj[e] = -1, adjo[e] = i;
    free(fill);
    free(v->adj_start), free(v->adj), free(v->adjo), free(v->epos);
    free(v->ekk), free(v->etg), free(v->elm), free(v->edm);
    v->adj_start = start, v->adj = adj, v->adjo = adjo, v->epos = epos;
    v->ekk = ek[0], v->etg = ek[1], v->elm = ek[2], v->edm = ek[3];
    return quads(np, w->neo ? w->neo->ijkl : NULL, w->neo ? w->neo->n : 0, &v->tadj_start, &v->tadj) &&
           quads(np, w->bend ? w->bend->ij : NULL, wb_bend_count(w), &v->badj_start, &v->badj);
}

/* greedy colouring in index order (deterministic): each vertex the least colour none of
 * its coloured neighbours has */
static int build_colours(wb_world *w, struct wb_vbd *v)
{
    const wb_model *m = &w->m;
    const int32_t np = m->np;
    uint8_t *col = malloc((size_t)(np > 0 ? np : 1));
    int32_t *order = malloc(sizeof *order * (size_t)(np > 0 ? np : 1));
    int32_t *cs = calloc(VBD_COLOURS + 1, sizeof *cs);
    if (!col || !order || !cs) {
        free(col), free(order), free(cs);
        return 0;
    }
    int overflow = 0, ncol = 0;
    for (int32_t i = 0; i < np; i++) {
        uint64_t used = 0;
        for (int32_t e = v->adj_start[i]; e < v->adj_start[i + 1]; e++) {
            if (v->adj[e] < 0) continue;
            const int32_t j = v->adjo[e];
            if (j < i) used |= (uint64_t)1 << col[j];
        }
        for (int32_t e = v->tadj_start[i]; e < v->tadj_start[i + 1]; e++) {
            const int32_t *c = &w->neo->ijkl[4 * (v->tadj[e] / 4)];
            for (int k = 0; k < 4; k++)
                if (c[k] < i) used |= (uint64_t)1 << col[c[k]];
        }
        for (int32_t e = v->badj_start[i]; e < v->badj_start[i + 1]; e++) {
            const int32_t *c = &w->bend->ij[4 * (v->badj[e] / 4)];
            for (int k = 0; k < 4; k++)
                if (c[k] < i) used |= (uint64_t)1 << col[c[k]];
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
    free(col);
    free(v->order);
    free(v->colour_start);
    v->order = order;
    v->colour_start = cs;
    v->ncolours = ncol;
    v->serial_last = overflow;
    return 1;
}

/* the next prepare rebuilds the adjacency (and forgets the links' errors) */
static int rebuild_due(const wb_world *w, const struct wb_vbd *v)
{
    const wb_model *m = &w->m;
    const wb_distances *ds = wb__dist(w->dist);
    const int32_t nt = w->neo ? w->neo->n : 0;
    return m->topology_dirty || v->np != m->np || v->nd != ds->n || v->nt != nt || v->nb != wb_bend_count(w);
}

int wb__vbd_prepare(wb_world *w)
{
    if (w->m.def.solver != WB_SOLVER_VBD) return 1;
    struct wb_vbd *v = w->vbd;
    if (!v) {
        v = calloc(1, sizeof *v);
        if (!v) return 0;
        w->vbd = v;
        v->np = -1;
    }
    v->nomem = 0;
    const wb_model *m = &w->m;
    const wb_distances *ds = wb__dist(w->dist);
    const int32_t nt = w->neo ? w->neo->n : 0;
    if (rebuild_due(w, v)) {
        if (!build_adjacency(w, v) || !build_colours(w, v)) return 0;
        wb_real *y = realloc(v->y, sizeof *y * 3 * (size_t)(m->np > 0 ? m->np : 1));
        if (!y) return 0;
        v->y = y;
        if (ds->n > v->cap_lam) {
            wb_real *lam = realloc(v->lam, sizeof *lam * (size_t)ds->n);
            if (lam) v->lam = lam;
            wb_real *c0 = realloc(v->c0, sizeof *c0 * (size_t)ds->n);
            if (c0) v->c0 = c0;
            vbd_link *lk = realloc(v->lk, sizeof *lk * (size_t)ds->n);
            if (lk) v->lk = lk;
            int32_t *hd = realloc(v->hard, sizeof *hd * (size_t)ds->n);
            if (hd) v->hard = hd;
            if (!lam || !c0 || !lk || !hd) return 0;
            /* new slots start with no multiplier and no error known (also in a world just
             * restored, whose image holds the errors of its own slots only) */
            memset(v->lam + v->cap_lam, 0, sizeof *lam * (size_t)(ds->n - v->cap_lam));
            for (int32_t q = v->cap_lam; q < ds->n; q++) v->c0[q] = (wb_real)NAN;
            v->cap_lam = ds->n;
        }
        if (wb_bend_count(w) > v->cap_blam) {
            const size_t n = (size_t)wb_bend_count(w);
            wb_real *bl = realloc(v->blam, sizeof *bl * n), *bk = realloc(v->bkpen, sizeof *bk * n);
            if (bl) v->blam = bl;
            if (bk) v->bkpen = bk;
            wb_real *bt = realloc(v->btg, sizeof *bt * n), *bc = realloc(v->bc0, sizeof *bc * n);
            if (bt) v->btg = bt;
            if (bc) v->bc0 = bc;
            if (!bl || !bk || !bt || !bc) return 0;
            memset(v->blam + v->cap_blam, 0, sizeof *bl * (n - (size_t)v->cap_blam));
            memset(v->bkpen + v->cap_blam, 0, sizeof *bk * (n - (size_t)v->cap_blam));
            for (int32_t b = v->cap_blam; b < wb_bend_count(w); b++) v->btg[b] = 0, v->bc0[b] = (wb_real)NAN;
            v->cap_blam = wb_bend_count(w);
        }
        /* (a slot may hold another link now: its error is the one it starts with) */
        if (!v->restored)
            for (int32_t q = 0; q < ds->n; q++) v->c0[q] = (wb_real)NAN;
        v->restored = 0;
        v->np = m->np;
        v->nd = ds->n;
        v->nt = nt;
        v->nb = wb_bend_count(w);
        wb_real *sv = realloc(v->save, sizeof *sv * (2 * (size_t)v->cap_lam + 2 * (size_t)v->cap_blam + 1));
        if (!sv) return 0;
        v->save = sv;
    }
    const size_t nl = (size_t)v->cap_lam, nb = (size_t)v->cap_blam;
    if (nl) {
        memcpy(v->save, v->lam, sizeof *v->save * nl);
        memcpy(v->save + nl, v->c0, sizeof *v->save * nl);
    }
    if (nb) {
        memcpy(v->save + 2 * nl, v->blam, sizeof *v->save * nb);
        memcpy(v->save + 2 * nl + nb, v->bc0, sizeof *v->save * nb);
    }
    return 1;
}

void wb__vbd_undo(wb_world *w)
{
    struct wb_vbd *v = w->vbd;
    if (!v || !v->save || v->np != w->m.np) return;
    const size_t nl = (size_t)v->cap_lam, nb = (size_t)v->cap_blam;
    if (nl) {
        memcpy(v->lam, v->save, sizeof *v->save * nl);
        memcpy(v->c0, v->save + nl, sizeof *v->save * nl);
    }
    if (nb) {
        memcpy(v->blam, v->save + 2 * nl, sizeof *v->save * nb);
        memcpy(v->bc0, v->save + 2 * nl + nb, sizeof *v->save * nb);
    }
}

/* ---- the vertex step ------------------------------------------------------------------------ */
/* solve the symmetric 3 x 3 system H d = f (H: xx, yy, zz, xy, xz, yz); 0 when singular */
static int solve3(const wb_real H[6], const wb_real f[3], wb_real d[3])
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
} sweep_job;

/* A link's force on i along n = (x_i - x_j) / l and its stiffness: a soft one's energy
 * C^2 / (2 alpha); a hard one's k C^2 / 2 + lambda C (vbd_link: C = l - tgt). The
 * Hessian's part across n, the force over l, is kept only while it pulls (a pushed link's
 * is indefinite: left out, as VBD does). A soft link's damping beta (N s/m) acts on the
 * speed it stretches at over the substep, as XPBD's (a hard link has none there either);
 * its block is beta / h n n^T.
 * A vertex's links are summed in 4 lanes (link q into lane q % 4, the lanes added as
 * (0 + 1) + (2 + 3)): the AVX2 path below takes 4 links at once and gives these bits. */
static void links_scalar(const wb_world *w, const struct wb_vbd *v, int32_t i, wb_real fs[3], wb_real hs[6])
{
    wb_real F[3][4] = { { 0 } }, Hl[6][4] = { { 0 } };
    const wb_real *x = w->s.x, *xp = w->s.x_prev;
    const int32_t e0 = v->adj_start[i], n = v->adj_start[i + 1] - e0;
    for (int32_t q = 0; q < n; q++) {
        if (v->adj[e0 + q] < 0) continue;
        const int32_t j = v->adjo[e0 + q], c = q & 3;
        const vbd_link *L = &v->lk[v->adj[e0 + q]];
        const wb_real d0 = x[3 * i] - x[3 * j], d1 = x[3 * i + 1] - x[3 * j + 1], d2 = x[3 * i + 2] - x[3 * j + 2];
        const wb_real l2 = d0 * d0 + d1 * d1 + d2 * d2;
        if (!(l2 > 1e-24)) continue;
        const wb_real l = sqrt(l2), il = 1 / l;
        wb_real fm = L->kk * (l - L->tgt) + L->lm, kn = L->kk;
        if (L->dmp > 0) {
            const wb_real u = d0 * (xp[3 * j] - xp[3 * i]) + d1 * (xp[3 * j + 1] - xp[3 * i + 1]) + d2 * (xp[3 * j + 2] - xp[3 * i + 2]);
            fm = fm + L->dmp * (l + u * il);
            kn = kn + L->dmp;
        }
        const wb_real g = fm > 0 ? fm * il : 0, a = (kn - g) * il * il, fl = fm * il;
        F[0][c] -= fl * d0, F[1][c] -= fl * d1, F[2][c] -= fl * d2;
        Hl[0][c] += a * d0 * d0 + g, Hl[1][c] += a * d1 * d1 + g, Hl[2][c] += a * d2 * d2 + g;
        Hl[3][c] += a * d0 * d1, Hl[4][c] += a * d0 * d2, Hl[5][c] += a * d1 * d2;
    }
    for (int c = 0; c < 3; c++) fs[c] = (F[c][0] + F[c][1]) + (F[c][2] + F[c][3]);
    for (int c = 0; c < 6; c++) hs[c] = (Hl[c][0] + Hl[c][1]) + (Hl[c][2] + Hl[c][3]);
}

#if defined(__x86_64__) && defined(__GNUC__) && !defined(WB_FLOAT)
#define WB_VBD_AVX2 1
#include <immintrin.h>

#include "simd.h"

/* the lanes of a and b added as (0 + 1) + (2 + 3): out[0] a's, out[1] b's */
static inline __attribute__((always_inline, target("avx2"))) void sum2(__m256d a, __m256d b, wb_real out[2])
{
    const __m256d t = _mm256_hadd_pd(a, b); /* a0+a1, b0+b1, a2+a3, b2+b3 */
    _mm_storeu_pd(out, _mm_add_pd(_mm256_castpd256_pd128(t), _mm256_extractf128_pd(t, 1)));
}

static __attribute__((target("avx2"))) void links_avx2(const wb_world *w, const struct wb_vbd *v, int32_t i, wb_real fs[3],
                                                       wb_real hs[6])
{
    const wb_real *x = w->s.x, *xp = w->s.x_prev;
    const int32_t e0 = v->adj_start[i], n = v->adj_start[i + 1] - e0;
    __m256d f0 = _mm256_setzero_pd(), f1 = f0, f2 = f0, h0 = f0, h1 = f0, h2 = f0, h3 = f0, h4 = f0, h5 = f0;
    const __m256d xi = _mm256_set1_pd(x[3 * i]), yi = _mm256_set1_pd(x[3 * i + 1]), zi = _mm256_set1_pd(x[3 * i + 2]);
    const __m256d zero = _mm256_setzero_pd(), one = _mm256_set1_pd(1), tiny = _mm256_set1_pd(1e-24);
    for (int32_t q = 0; q < n; q += 4) {
        const int32_t e = e0 + q, *j = &v->adjo[e];
        const size_t o[4] = { 3 * (size_t)j[0], 3 * (size_t)j[1], 3 * (size_t)j[2], 3 * (size_t)j[3] };
        __m256d d0, d1, d2;
        wb__load4(x, o, &d0, &d1, &d2);
        d0 = _mm256_sub_pd(xi, d0), d1 = _mm256_sub_pd(yi, d1), d2 = _mm256_sub_pd(zi, d2);
        const __m256d l2 = _mm256_add_pd(_mm256_add_pd(_mm256_mul_pd(d0, d0), _mm256_mul_pd(d1, d1)), _mm256_mul_pd(d2, d2));
        const __m256d live = _mm256_cmp_pd(l2, tiny, _CMP_GT_OQ);
        const __m256d l = _mm256_sqrt_pd(l2), il = _mm256_div_pd(one, l);
        const __m256d K = _mm256_loadu_pd(&v->ekk[e]), D = _mm256_loadu_pd(&v->edm[e]);
        __m256d fm = _mm256_add_pd(_mm256_mul_pd(K, _mm256_sub_pd(l, _mm256_loadu_pd(&v->etg[e]))), _mm256_loadu_pd(&v->elm[e]));
        __m256d kn = K;
        if (_mm256_movemask_pd(_mm256_cmp_pd(D, zero, _CMP_GT_OQ))) {
            /* the damped lanes only (a lane of dmp 0 would add 0 times a finite number: the
             * same fm, never -0, but the scalar loop does not add it) */
            __m256d u0, u1, u2;
            wb__load4(xp, o, &u0, &u1, &u2);
            u0 = _mm256_sub_pd(u0, _mm256_set1_pd(xp[3 * i]));
            u1 = _mm256_sub_pd(u1, _mm256_set1_pd(xp[3 * i + 1]));
            u2 = _mm256_sub_pd(u2, _mm256_set1_pd(xp[3 * i + 2]));
            const __m256d u = _mm256_add_pd(_mm256_add_pd(_mm256_mul_pd(d0, u0), _mm256_mul_pd(d1, u1)), _mm256_mul_pd(d2, u2));
            const __m256d dfm = _mm256_mul_pd(D, _mm256_add_pd(l, _mm256_mul_pd(u, il)));
            fm = _mm256_blendv_pd(fm, _mm256_add_pd(fm, dfm), _mm256_cmp_pd(D, zero, _CMP_GT_OQ));
            kn = _mm256_blendv_pd(kn, _mm256_add_pd(kn, D), _mm256_cmp_pd(D, zero, _CMP_GT_OQ));
        }
        const __m256d g = _mm256_and_pd(_mm256_mul_pd(fm, il), _mm256_cmp_pd(fm, zero, _CMP_GT_OQ));
        const __m256d a = _mm256_mul_pd(_mm256_mul_pd(_mm256_sub_pd(kn, g), il), il), fl = _mm256_mul_pd(fm, il);
        const __m256d ad0 = _mm256_mul_pd(a, d0), ad1 = _mm256_mul_pd(a, d1);
        f0 = _mm256_sub_pd(f0, _mm256_and_pd(_mm256_mul_pd(fl, d0), live));
        f1 = _mm256_sub_pd(f1, _mm256_and_pd(_mm256_mul_pd(fl, d1), live));
        f2 = _mm256_sub_pd(f2, _mm256_and_pd(_mm256_mul_pd(fl, d2), live));
        h0 = _mm256_add_pd(h0, _mm256_and_pd(_mm256_add_pd(_mm256_mul_pd(ad0, d0), g), live));
        h1 = _mm256_add_pd(h1, _mm256_and_pd(_mm256_add_pd(_mm256_mul_pd(ad1, d1), g), live));
        h2 = _mm256_add_pd(h2, _mm256_and_pd(_mm256_add_pd(_mm256_mul_pd(_mm256_mul_pd(a, d2), d2), g), live));
        h3 = _mm256_add_pd(h3, _mm256_and_pd(_mm256_mul_pd(ad0, d1), live));
        h4 = _mm256_add_pd(h4, _mm256_and_pd(_mm256_mul_pd(ad0, d2), live));
        h5 = _mm256_add_pd(h5, _mm256_and_pd(_mm256_mul_pd(ad1, d2), live));
    }
    wb_real t[2];
    sum2(f0, f1, fs);
    sum2(f2, h0, t);
    fs[2] = t[0], hs[0] = t[1];
    sum2(h1, h2, hs + 1);
    sum2(h3, h4, hs + 3);
    sum2(h5, h5, t);
    hs[5] = t[0];
}
#endif

/* the vector path: -1 not yet decided, 0 off (no AVX2, or turned off), 1 on */
static int simd_state = -1;

/* Internal switch for tests, as wb__distance_simd: on = 0 forces the scalar loop */
int wb__vbd_simd(int on);
int wb__vbd_simd(int on) { return wb__simd_set(&simd_state, on); }

static inline void link_lanes(const wb_world *w, const struct wb_vbd *v, int32_t i, wb_real F[3], wb_real Hl[6])
{
#ifdef WB_VBD_AVX2
    int s = __atomic_load_n(&simd_state, __ATOMIC_RELAXED);
    if (s < 0) s = wb__vbd_simd(1);
    if (s) {
        links_avx2(w, v, i, F, Hl);
        return;
    }
#endif
    links_scalar(w, v, i, F, Hl);
}

/* A Neo-Hookean tet's energy on corner k, in its constraint form (tet.c): V0 (mu/2 |F|^2 +
 * lam/2 (det F - a)^2), a = 1 + mu/lam, F = sum_k x_k b_k^T (b_k: row k-1 of Dm^-1, b_0
 * minus their sum). The first term is quadratic in x: its block is exact, mu V0 |b_k|^2 I;
 * the second's is Gauss-Newton, lam V0 g g^T with g = cof(F) b_k (what is left, (det F -
 * a) times J's second derivative, is indefinite: left out, as VBD does) */
static void tet_block(const wb_world *w, int32_t q, wb_real f[3], wb_real H[6])
{
    const wb_neos *nv = w->neo;
    const int32_t t = q / 4, k = q % 4, *p = &nv->ijkl[4 * t];
    const wb_real *d = &nv->dminv[9 * t], *x = w->s.x, V = nv->v0[t], mu = nv->mu[t], lam = nv->lam[t];
    wb_real F[9], e[3][3], b[3];
    for (int c = 0; c < 3; c++) v3_sub(e[c], &x[3 * p[c + 1]], &x[3 * p[0]]);
    for (int r = 0; r < 3; r++)
        for (int c = 0; c < 3; c++) F[3 * r + c] = e[0][r] * d[c] + e[1][r] * d[3 + c] + e[2][r] * d[6 + c];
    if (k > 0) v3_copy(b, &d[3 * (k - 1)]);
    else for (int c = 0; c < 3; c++) b[c] = -(d[c] + d[3 + c] + d[6 + c]);
    /* the columns of F and of its cofactor */
    const wb_real f0[3] = { F[0], F[3], F[6] }, f1[3] = { F[1], F[4], F[7] }, f2[3] = { F[2], F[5], F[8] };
    wb_real c0[3], c1[3], c2[3], Fb[3], g[3];
    v3_cross(c0, f1, f2);
    v3_cross(c1, f2, f0);
    v3_cross(c2, f0, f1);
    for (int r = 0; r < 3; r++) {
        Fb[r] = F[3 * r] * b[0] + F[3 * r + 1] * b[1] + F[3 * r + 2] * b[2];
        g[r] = c0[r] * b[0] + c1[r] * b[1] + c2[r] * b[2];
    }
    const wb_real J = v3_dot(f0, c0), s = lam * V * (J - (1 + mu / lam)), kd = mu * V * v3_dot(b, b), kh = lam * V;
    for (int r = 0; r < 3; r++) f[r] -= mu * V * Fb[r] + s * g[r];
    H[0] += kd + kh * g[0] * g[0], H[1] += kd + kh * g[1] * g[1], H[2] += kd + kh * g[2] * g[2];
    H[3] += kh * g[0] * g[1], H[4] += kh * g[0] * g[2], H[5] += kh * g[1] * g[2];
}

/* a bend's energy off^2 / (2 alpha) on corner k: Gauss-Newton, k g g^T; a rigid one (alpha
 * 0) through the augmented Lagrangian, k (off - t)^2 / 2 + lambda (off - t), as a hard link
 * (t: the error it keeps this substep).
 * Its damping beta (N m s) on the angle's speed over the substep, as XPBD's */
static void bend_block(const wb_world *w, const struct wb_vbd *v, int32_t q, wb_real inv_h, wb_real f[3], wb_real H[6])
{
    const int32_t b = q / 4, k = q % 4;
    if (w->bend->broken[b]) return;
    wb_real off, g[4][3];
    if (!wb__bend_off(w, b, &off, g)) return;
    const wb_real a = w->bend->alpha[b], *gk = g[k];
    wb_real kb = a > 0 ? 1 / a : v->bkpen[b], fm = a > 0 ? kb * off : kb * (off - v->btg[b]) + v->blam[b];
    const wb_real beta = w->bend->beta[b];
    if (a > 0 && beta > 0) {
        const int32_t *p = &w->bend->ij[4 * b];
        wb_real rel = 0;
        for (int c = 0; c < 4; c++) {
            wb_real u[3];
            v3_sub(u, &w->s.x[3 * p[c]], &w->s.x_prev[3 * p[c]]);
            rel += v3_dot(g[c], u);
        }
        fm += beta * rel * inv_h;
        kb += beta * inv_h;
    }
    v3_madd(f, gk, -fm);
    H[0] += kb * gk[0] * gk[0], H[1] += kb * gk[1] * gk[1], H[2] += kb * gk[2] * gk[2];
    H[3] += kb * gk[0] * gk[1], H[4] += kb * gk[0] * gk[2], H[5] += kb * gk[1] * gk[2];
}

/* con: the substep has contacts in the vertex steps (two copies: the loop without them
 * stays as it was) */
static inline __attribute__((always_inline)) void sweep_body(void *ctx, int32_t lo, int32_t hi, int con)
{
    sweep_job *j = ctx;
    wb_world *w = j->w;
    const struct wb_vbd *v = j->v;
    wb_real *x = w->s.x;
    const wb_real *wv = w->m.w;
    wb_real big = 0;
    for (int32_t q = lo; q < hi; q++) {
        const int32_t i = j->vert[q];
        if (!(wv[i] > 0)) continue;
        const wb_real mh = j->inv_h2 / wv[i];
        wb_real f[3], H[6], d[3];
        link_lanes(w, v, i, f, H);
        for (int c = 0; c < 3; c++) f[c] += mh * (v->y[3 * i + c] - x[3 * i + c]), H[c] += mh;
        for (int32_t e = v->tadj_start[i]; e < v->tadj_start[i + 1]; e++) tet_block(w, v->tadj[e], f, H);
        for (int32_t e = v->badj_start[i]; e < v->badj_start[i + 1]; e++) bend_block(w, v, v->badj[e], j->inv_h, f, H);
        if (con) wb__vbdc_block(w, j->ct, i, f, H);
        if (!solve3(H, f, d)) continue;
        if (con) {
            wb_real xn[3];
            v3_add(xn, &x[3 * i], d);
            wb__vbdc_friction(w, j->ct, i, H, xn);
            v3_sub(d, xn, &x[3 * i]);
        }
        v3_add(&x[3 * i], &x[3 * i], d);
        const wb_real dd = v3_dot(d, d);
        big = dd > big ? dd : big;
    }
    wb_real cur;
    __atomic_load(&j->step, &cur, __ATOMIC_RELAXED);
    while (big > cur && !__atomic_compare_exchange(&j->step, &cur, &big, 1, __ATOMIC_RELAXED, __ATOMIC_RELAXED)) {}
}

static void sweep_part(void *ctx, int32_t lo, int32_t hi) { sweep_body(ctx, lo, hi, 0); }
static void sweep_part_ct(void *ctx, int32_t lo, int32_t hi) { sweep_body(ctx, lo, hi, 1); }

/* ---- the hard links' multipliers ------------------------------------------------------------ */
/* the inertia of a hard link's ends over the substep, 1 / (h^2 (w_i + w_j)) */
static wb_real start_penalty(const wb_world *w, int32_t s, wb_real inv_h2)
{
    const int32_t *ij = wb__dist(w->dist)->ij;
    const wb_real wsum = w->m.w[ij[2 * s]] + w->m.w[ij[2 * s + 1]];
    return wsum > 0 ? inv_h2 / wsum : 0;
}

/* link s's two entries of the vertex lists, as the vector lanes read them */
static void put_entries(struct wb_vbd *v, int32_t s, const vbd_link *L)
{
    for (int c = 0; c < 2; c++) {
        const int32_t e = v->epos[2 * s + c];
        v->ekk[e] = L->kk, v->etg[e] = L->tgt, v->elm[e] = L->lm, v->edm[e] = L->dmp;
    }
}

/* each link as the sweeps read it this substep (vbd_link), and the hard links' list */
static void warm_start(wb_world *w, struct wb_vbd *v, wb_real inv_h2, wb_real inv_h)
{
    const wb_distances *ds = wb__dist(w->dist);
    const wb_real *xp = w->s.x_prev;
    v->nhard = v->nstiff = 0;
    /* volume constraints are projected after the sweeps: with rigid links they may hold
     * a body over-constrained (rigid links and incompressible tets under a press), and a
     * link that took back what the press pushed into it each substep fought them (a
     * lattice with tets squeezed to 60% blew up at 55 m/s): there every error is kept */
    const int keep_all = wb_volume_count(w) > 0;
    for (int32_t s = 0; s < ds->n; s++) {
        if (!link_live(w, s)) continue;
        vbd_link *L = &v->lk[s];
        const wb_real alpha = ds->alpha[s], rest = ds->rest[s], kap = VBD_LINK_K * start_penalty(w, s, inv_h2);
        wb_real d[3];
        if (alpha > 0) {
            L->dmp = ds->beta[s] > 0 ? ds->beta[s] * inv_h : 0;
            if (!(1 / alpha > kap)) { /* its own energy */
                L->tgt = rest, L->kk = 1 / alpha, L->lm = 0;
                v->lam[s] = 0, v->c0[s] = (wb_real)NAN;
                put_entries(v, s, L);
                continue;
            }
            /* stiffer than a rigid link's penalty: as one (dual_update), its error C - alpha
             * lambda */
            const wb_real r = 1 / (1 + alpha * kap);
            v3_sub(d, &xp[3 * ds->ij[2 * s]], &xp[3 * ds->ij[2 * s + 1]]);
            const wb_real c = v3_len(d) - rest - alpha * v->lam[s], ce = v->c0[s];
            const wb_real c0 = keep_all || !isfinite(ce) ? c : c * ce <= 0 ? 0 : fabs(c) < fabs(ce) ? c : ce;
            L->tgt = rest + (keep_all ? VBD_STAB_VOL : VBD_STAB) * c0;
            L->kk = kap * r, L->lm = r * v->lam[s];
            put_entries(v, s, L);
            v->hard[ds->n - 1 - v->nstiff++] = s;
            continue;
        }
        v3_sub(d, &xp[3 * ds->ij[2 * s]], &xp[3 * ds->ij[2 * s + 1]]);
        /* the error kept is no more than the solve itself left: what the contacts and
         * colliders did to the link since (pushing a body's bottom up into it) is a load
         * it takes, not a drift to stabilise, or a block on the ground sags by 100 g h^2
         * a link (a 4 x 4 x 4 lattice's lowest links 17% short on a slope) */
        const wb_real c = v3_len(d) - rest, ce = v->c0[s];
        const wb_real c0 = keep_all || !isfinite(ce) ? c : c * ce <= 0 ? 0 : fabs(c) < fabs(ce) ? c : ce;
        L->tgt = rest + (keep_all ? VBD_STAB_VOL : VBD_STAB) * c0;
        L->kk = kap, L->lm = v->lam[s], L->dmp = 0;
        put_entries(v, s, L);
        v->hard[v->nhard++] = s;
    }
}

/* After the substep's last sweep: a hard link's multiplier grows by k C. A stiff link
 * (compliance alpha with 1 / alpha above the rigid links' penalty k) goes through the
 * augmented Lagrangian of its energy written as z^2 / 2 alpha under the constraint z = C:
 * with z eliminated the sweep sees the force r (lambda + k C) and the stiffness r k,
 * r = 1 / (1 + alpha k), lambda its tension after the last update (C / alpha at rest);
 * its error, C - alpha lambda, is kept as a hard link's. With its whole stiffness in the
 * vertex step (1e6 N/m for a w:cloth's links of compliance 1e-6 at 20 substeps, 160 times
 * that penalty) one sweep left a vertex's neighbours far from where it assumed them: a
 * cloth hung by a row of pins gained energy until it blew up (max strain 0.1% after
 * 0.3 s, 11% after 1 s, particles at 20 m/s; stable at 10 iterations). At alpha = 0 it is
 * the hard link's update */
static void dual_update(wb_world *w, struct wb_vbd *v)
{
    const wb_distances *ds = wb__dist(w->dist);
    const wb_real *x = w->s.x;
    for (int32_t q = 0; q < v->nhard; q++) {
        const int32_t s = v->hard[q], a = ds->ij[2 * s], b = ds->ij[2 * s + 1];
        vbd_link *L = &v->lk[s];
        wb_real d[3];
        v3_sub(d, &x[3 * a], &x[3 * b]);
        const wb_real l = v3_len(d);
        L->lm += L->kk * (l - L->tgt);
        v->c0[s] = l - ds->rest[s]; /* (before the types projected after the sweep) */
        const int32_t e = v->epos[2 * s], f = v->epos[2 * s + 1];
        v->elm[e] = v->elm[f] = L->lm;
    }
    for (int32_t q = ds->n - v->nstiff; q < ds->n; q++) {
        const int32_t s = v->hard[q], a = ds->ij[2 * s], b = ds->ij[2 * s + 1];
        vbd_link *L = &v->lk[s];
        wb_real d[3];
        v3_sub(d, &x[3 * a], &x[3 * b]);
        const wb_real l = v3_len(d), f = L->kk * (l - L->tgt) + L->lm, alpha = ds->alpha[s];
        v->lam[s] = f;
        L->lm = (1 - alpha * L->kk) * f;
        v->c0[s] = l - ds->rest[s] - alpha * f;
        const int32_t e = v->epos[2 * s], g = v->epos[2 * s + 1];
        v->elm[e] = v->elm[g] = L->lm;
    }
}

/* the hard links' multipliers carried to the next substep (a stiff one's: dual_update) */
static void keep_multipliers(struct wb_vbd *v)
{
    for (int32_t q = 0; q < v->nhard; q++) v->lam[v->hard[q]] = v->lk[v->hard[q]].lm;
}

/* a hard bend's penalty: the inertia of its angle, 1 / (h^2 w sum |g|^2), with w its
 * lightest movable corner's inverse mass over all four corners. Over the movable corners
 * alone (sum w |g|^2) it grew without bound where they barely turn the angle (a row of
 * pins along a cloth's edge: a hinge corner's gradient near 0), and the multiplier with it:
 * a 9 x 9 cloth hung by an edge blew up in 5 frames */
static wb_real bend_start_penalty(const wb_world *w, int32_t b, const wb_real g[4][3], wb_real inv_h2)
{
    const int32_t *p = &w->bend->ij[4 * b];
    wb_real wm = 0, gg = 0;
    for (int c = 0; c < 4; c++) {
        wm = w->m.w[p[c]] > wm ? w->m.w[p[c]] : wm;
        gg += v3_dot(g[c], g[c]);
    }
    return wm * gg > 0 ? inv_h2 / (wm * gg) : 0;
}

static int hard_bend(const wb_world *w, int32_t b) { return !w->bend->broken[b] && !(w->bend->alpha[b] > 0); }

/* each hard bend's penalty and the error it keeps this substep, as warm_start's links:
 * measured where the substep starts (x_prev), not at the sweeps' start: kept from the
 * prediction, a bend took its swing in as error and the multiplier fed it back (the strip
 * with rigid bends blew up within 5 s at any penalty). It keeps VBD_STAB of it per
 * VBD_STAB_T of time, not per substep: the multiplier integrates what is not kept, and at
 * 0.999 a substep the strip at 40 x 1 (the rate 4 times the default's, 2.4 /s against
 * its drag of 2 /s) swung up to 0.6 m in 50 s; so it held within 1.3 mm */
static void bend_warm_start(wb_world *w, struct wb_vbd *v, wb_real h)
{
    const wb_real inv_h2 = 1 / (h * h), keep = pow(VBD_STAB, h / VBD_STAB_T);
    for (int32_t b = 0; b < wb_bend_count(w); b++) {
        wb_real off, g[4][3];
        if (!hard_bend(w, b)) continue;
        if (!wb__bend_off_at(w, w->s.x_prev, b, &off, g)) { /* degenerate: no penalty this substep */
            v->bkpen[b] = v->btg[b] = 0;
            continue;
        }
        v->bkpen[b] = VBD_BEND_K * bend_start_penalty(w, b, g, inv_h2);
        const wb_real ce = v->bc0[b];
        const wb_real c0 = !isfinite(ce) ? 0 : off * ce <= 0 ? 0 : fabs(off) < fabs(ce) ? off : ce;
        v->btg[b] = keep * c0;
    }
}

/* a hard bend's multiplier after a sweep, as a hard link's; its torque (what force() and
 * break_torque read, XPBD's multiplier lambda = -torque h^2) is the multiplier */
static void bend_dual_update(wb_world *w, struct wb_vbd *v, wb_real h)
{
    wb_bends *bs = w->bend;
    for (int32_t b = 0; b < wb_bend_count(w); b++) {
        wb_real off, g[4][3];
        if (!hard_bend(w, b) || !wb__bend_off(w, b, &off, g)) continue;
        v->blam[b] += v->bkpen[b] * (off - v->btg[b]);
        v->bc0[b] = off;
        if (!bs->dirty) bs->lambda[bs->pack[b]] = -v->blam[b] * h * h;
    }
}

/* What force() and break_force read, in XPBD's multipliers (lambda = -force h^2, a
 * stretched link's negative): a soft link's C / alpha, a hard one's lambda + k C of the
 * last sweep; a soft bend's off / alpha (a hard one's: bend_dual_update) */
static void write_forces(wb_world *w, const struct wb_vbd *v, wb_real h)
{
    wb_distances *ds = w->dist;
    const wb_real h2 = h * h;
    for (int32_t i = 0; ds && i < ds->ns; i++) {
        const int32_t s = ds->s_slot[i];
        if (!link_live(w, s)) { ds->s_lambda[i] = 0; continue; }
        const wb_real alpha = ds->alpha[s];
        if (alpha > 0) {
            wb_real d[3];
            v3_sub(d, &w->s.x[3 * ds->ij[2 * s]], &w->s.x[3 * ds->ij[2 * s + 1]]);
            ds->s_lambda[i] = -(v3_len(d) - ds->rest[s]) / alpha * h2;
        } else {
            ds->s_lambda[i] = -v->lam[s] * h2;
        }
    }
    if (ds) ds->s_lambda_stale = 0;
    wb_bends *bs = w->bend;
    if (!bs || bs->dirty) return;
    for (int32_t b = 0; b < bs->n; b++) {
        wb_real off, g[4][3];
        if (bs->broken[b] || !(bs->alpha[b] > 0)) continue;
        bs->lambda[bs->pack[b]] = wb__bend_off(w, b, &off, g) ? -off / bs->alpha[b] * h2 : 0;
    }
}

/* v->tsum (bodies x 4) zeroed, with [4 b] = -1 for each body b that may touch a rigid body,
 * a movable particle of a body made deep inside it or a triangle held in part this frame
 * (the contacts found for the frame), v->bvar numbering the free bodies that may touch
 * another body's movable particles otherwise (moved together: couple); 0 when there are
 * no bodies (or no memory) */
static int touching(wb_world *w, struct wb_vbd *v)
{
    const wb_cache *k = &w->k;
    if (!k->mc_built || k->mc_nbody == 0) return 0;
    const int32_t nb = k->mc_nbody, *body = k->mc_body;
    if (nb > v->cap_tsum) {
        if (!wb__charge(w, &v->charged_t, (sizeof(double) * (25 + WB_VBDC_BS + 14) + sizeof(int32_t) + 1) * (size_t)nb)) {
            v->nomem = 1;
            return 0;
        }
        double *t = realloc(v->tsum, sizeof *t * 8 * (size_t)nb), *e = realloc(v->csum, sizeof *e * 17 * (size_t)nb);
        double *vs = realloc(v->vsum, sizeof *vs * (WB_VBDC_BS + 14) * (size_t)nb);
        uint8_t *bm = realloc(v->bmove, (size_t)nb);
        int32_t *bv = realloc(v->bvar, sizeof *bv * (size_t)nb);
        if (t) v->tsum = t;
        if (e) v->csum = e;
        if (vs) v->vsum = vs;
        if (bm) v->bmove = bm;
        if (bv) v->bvar = bv;
        if (!t || !e || !vs || !bm || !bv) {
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
            const wb_real rn = (rad[i] + rad[j]) * (wb_real)1.25;
            if (v3_dot(d, d) < rn * rn) T[4 * nb + body[wv[i] > 0 ? i : j]] = 1;
        }
        if (a < 0 || b < 0 || a == b) continue;
        /* (marked here, numbered below; bodies made deep inside each other are contact.c's
         * to part) */
        wb_real e[3];
        v3_sub(e, &xp[3 * i], &xp[3 * j]);
        const wb_real rs = (rad[i] + rad[j]) * VBD_MADE_DEEP;
        const int made = wb__contacts_made(w, i, j) || v3_dot(e, e) < rs * rs;
        if (wv[j] > 0) {
            if (made) T[4 * a] = -1;
            else if (v->bvar[a] < 0) v->bvar[a] = 0;
        }
        if (wv[i] > 0) {
            if (made) T[4 * b] = -1;
            else if (v->bvar[b] < 0) v->bvar[b] = 0;
        }
    }
    const wb_tricontacts *tc = k->tc;
    for (int32_t c = 0; c < tc->n; c++) {
        const int32_t t = tc->pt[2 * c + 1], p[4] = { tc->pt[2 * c], w->m.tri[3 * t], w->m.tri[3 * t + 1], w->m.tri[3 * t + 2] };
        const int32_t a = body[p[0]], b = body[p[1]];
        if (a < 0 || b < 0 || a == b) continue;
        /* (a triangle of one body, all its corners movable: in the coupled step) */
        const int made = wb__contacts_made(w, p[0], p[1]);
        const int whole = !made && body[p[2]] == b && body[p[3]] == b && wv[p[1]] > 0 && wv[p[2]] > 0 && wv[p[3]] > 0;
        if (whole) v->bvar[a] = v->bvar[a] < 0 ? 0 : v->bvar[a];
        else if (wv[p[1]] > 0 || wv[p[2]] > 0 || wv[p[3]] > 0) T[4 * a] = -1;
        if (wv[p[0]] > 0) {
            if (made) T[4 * b] = -1;
            else if (v->bvar[b] < 0) v->bvar[b] = 0;
        }
    }
    if (w->rb)
        for (int32_t c = 0; c < w->rb->npct; c++)
            if (body[w->rb->pc[2 * c]] >= 0) T[4 * body[w->rb->pc[2 * c]]] = -1;
    /* a free body that may touch another body's movable particle is moved with the bodies
     * it may touch (keep_momentum), unless it is held or touches what that step does not
     * take in (a rigid body, a triangle of another body) */
    v->nvar = 0;
    for (int32_t b = 0; b < nb; b++)
        v->bvar[b] = v->bvar[b] == 0 && !(T[4 * b] < 0) && !(k->mc_acc[16 * b] < 0) ? v->nvar++ : -1;
    return 1;
}

/* The sweeps start from where its speed alone takes a vertex held by a constraint, the
 * prediction less this substep's gravity (x + h v; Chen et al. 2024 list it among their
 * starts), and a free vertex from the prediction, its minimum. A body held by pins or
 * its own links is then at rest a fixed point of a single sweep (from y itself, one sweep
 * a substep never reaches it: a bar of E = 1e7 hung at 18.6 mm where it stretches 0.049
 * mm). Chen et al.'s adaptive start, the prediction less the part of gravity a vertex did
 * not follow last substep, fed the swing of such a body back into its next start (the
 * clamped strip swung on at 10 x 1, 0.63 m against 0.29; the bar crept to 0.8 mm at
 * 10 x 1). A body that nothing holds (no pin, attachment or grab) but that may touch
 * another body's movable particle or a rigid body (touching()) starts from the
 * prediction: the contacts carry it (after the sweeps, or in its momentum step with the
 * bodies it touches) and where keep_momentum leaves it alone the gravity it follows is the
 * one its start has (from x + h v, a lattice made overlapping another was lifted 0.25 m
 * instead of 0.15; from the adaptive start, a stack still moved after 4 s). So does a
 * free body near an immovable particle: its contacts in the vertex steps then push from
 * the start (from x + h v a Newton step did not see them, and their multipliers took 8
 * times the weight after it). A held one touching itself keeps x + h v (from y, a pinned
 * rope folding onto itself as it swung gained energy) */
static void start_guess(wb_world *w, struct wb_vbd *v, wb_real h, int touch)
{
    const wb_real *g = w->m.def.gravity, *wv = w->m.w;
    wb_real *x = w->s.x;
    const int32_t *body = w->k.mc_body;
    for (int32_t i = 0; i < w->m.np; i++) {
        const int held = v->adj_start[i + 1] > v->adj_start[i] || v->tadj_start[i + 1] > v->tadj_start[i] ||
                         v->badj_start[i + 1] > v->badj_start[i];
        const int32_t b = body ? body[i] : -1;
        const int from_y = touch && b >= 0 && !(w->k.mc_acc[16 * b] < 0) &&
                           (v->tsum[4 * b] < 0 || v->tsum[4 * w->k.mc_nbody + b] > 0 || v->bvar[b] >= 0);
        if (!(wv[i] > 0) || !held || from_y) continue;
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
     * particles is moved with it (couple) */
    if (!touch) return;
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
                wb__vbdc_body(w, v->ct, cv[q], sh, f, H, pass == 0 ? fr : NULL);
                E[17 * b] = 1;
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

wb_real wb__vbd_solve(wb_world *w, wb_real h)
{
    struct wb_vbd *v = w->vbd;
    if (!v || v->np != w->m.np) return -1; /* (prepare failed: out of memory, warned there) */
    const wb_real inv_h2 = 1 / (h * h);
    if (w->m.np > 0) memcpy(v->y, w->s.x, sizeof *v->y * 3 * (size_t)w->m.np); /* none: rigid bodies alone */
    /* which bodies touch another's movable particle or a rigid body: the contacts are the
     * frame's list, the same for the start and the momentum step (one pass, not two) */
    const int touch = touching(w, v);
    start_guess(w, v, h, touch);
    warm_start(w, v, inv_h2, 1 / h);
    bend_warm_start(w, v, h);
    /* the contacts in the vertex steps */
    if (touch)
        for (int32_t b = 0; b < w->k.mc_nbody; b++)
            v->bmove[b] = v->tsum[4 * w->k.mc_nbody + b] > 0 && v->tsum[4 * b] >= 0 && !(w->k.mc_acc[16 * b] < 0) &&
                          v->bvar[b] < 0;
    const int got = wb__vbdc_begin(w, &v->ct, h, v->order, v->colour_start, v->ncolours, touch ? v->bmove : NULL,
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
        sweep_job j = { w, v, inv_h2, 1 / h, NULL, 0, cs };
        if (cs && it > 0) wb__vbdc_refresh(w, cs, v->ncolours);
        for (int32_t c = 0; c < v->ncolours; c++) {
            const int32_t lo = v->colour_start[c], n = v->colour_start[c + 1] - lo;
            j.vert = v->order + lo;
            const int serial = v->serial_last && c == v->ncolours - 1;
            wb__pool_for(serial ? NULL : pool, n, 1024, cs ? sweep_part_ct : sweep_part, &j);
            if (cs) wb__vbdc_colour_done(w, cs, c);
        }
        v->residual = sqrt(j.step);
        const int last = it + 1 == w->m.def.iterations || (w->m.def.tolerance > 0 && v->residual <= w->m.def.tolerance);
        if (ct) wb__vbdc_dual(w, ct);
        /* the links' multipliers grow once a substep, after its last sweep: grown after
         * every sweep, they took in what the contacts and colliders projected after the
         * solve would push back anyway, as often as there were sweeps (two stacked blocks
         * of rigid links at 2 iterations: links 45% long within 2.5 s; a cloth of them
         * draped on a sphere: 72%) */
        if (last) dual_update(w, v);
        bend_dual_update(w, v, h);
        for (int t = 0; t < wb__nctypes; t++)
            if (!wb__vbd_serves(wb__ctypes[t])) wb__ctypes[t]->project(w, h);
        if (last) break;
    }
    keep_momentum(w, v, touch, h);
    if (v->ct_on) wb__vbdc_end(w, v->ct);
    keep_multipliers(v);
    write_forces(w, v, h);
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

/* what the world's next substep starts from: a slot the cache has not met yet starts
 * with no multiplier, and the errors of a cache about to be rebuilt are forgotten */
wb_status wb__vbd_image_of(const wb_world *w, wb_image *g)
{
    const struct wb_vbd *v = w->vbd;
    if (!v || w->m.def.solver != WB_SOLVER_VBD || (wb__dist(w->dist)->n == 0 && wb_bend_count(w) == 0)) return WB_OK;
    const int32_t nd = wb__dist(w->dist)->n, nb = wb_bend_count(w);
    if (wb_image_alloc_vbd(g, nd, nb) != WB_OK) return WB_ERR_NOMEM;
    /* (a world just restored has its image's errors for every slot it held) */
    const int32_t known = v->restored ? v->cap_lam : rebuild_due(w, v) ? 0 : v->nd;
    for (int32_t s = 0; s < nd; s++) {
        g->vbd_lam[s] = s < v->cap_lam ? v->lam[s] : 0;
        g->vbd_c0[s] = s < known ? v->c0[s] : (wb_real)NAN;
    }
    for (int32_t b = 0; b < nb; b++) {
        g->vbd_blam[b] = b < v->cap_blam ? v->blam[b] : 0;
        g->vbd_bc0[b] = b < v->cap_blam ? v->bc0[b] : (wb_real)NAN;
    }
    return WB_OK;
}

const char *wb__vbd_image_check(const wb_image *g)
{
    if (g->vbd_nd == 0 && g->vbd_nb == 0) return NULL;
    if (g->def.solver != WB_SOLVER_VBD) return "VBD multipliers in a world of another solver";
    if (g->vbd_nd != g->dist.n) return "VBD multipliers: one per distance slot";
    if (g->vbd_nb != g->bend.n) return "VBD bend multipliers: one per bend";
    for (int32_t s = 0; s < g->vbd_nd; s++)
        if (!isfinite(g->vbd_lam[s]) || isinf(g->vbd_c0[s])) return "VBD multipliers must be finite";
    for (int32_t b = 0; b < g->vbd_nb; b++)
        if (!isfinite(g->vbd_blam[b]) || isinf(g->vbd_bc0[b])) return "VBD multipliers must be finite";
    return NULL;
}

wb_status wb__vbd_image_put(wb_world *w, const wb_image *g)
{
    if (g->vbd_nd == 0 && g->vbd_nb == 0) return WB_OK;
    struct wb_vbd *v = calloc(1, sizeof *v);
    if (!v) return WB_ERR_NOMEM;
    w->vbd = v;
    v->np = -1;
    const size_t nd = (size_t)(g->vbd_nd > 0 ? g->vbd_nd : 1), nb = (size_t)(g->vbd_nb > 0 ? g->vbd_nb : 1);
    v->lam = malloc(sizeof *v->lam * nd), v->c0 = malloc(sizeof *v->c0 * nd);
    v->lk = malloc(sizeof *v->lk * nd), v->hard = malloc(sizeof *v->hard * nd);
    v->blam = malloc(sizeof *v->blam * nb), v->bkpen = calloc(nb, sizeof *v->bkpen);
    v->btg = calloc(nb, sizeof *v->btg), v->bc0 = malloc(sizeof *v->bc0 * nb);
    if (!v->lam || !v->c0 || !v->lk || !v->hard || !v->blam || !v->bkpen || !v->btg || !v->bc0) return WB_ERR_NOMEM;
    if (g->vbd_nd) {
        memcpy(v->lam, g->vbd_lam, sizeof *v->lam * (size_t)g->vbd_nd);
        memcpy(v->c0, g->vbd_c0, sizeof *v->c0 * (size_t)g->vbd_nd);
    }
    if (g->vbd_nb) {
        memcpy(v->blam, g->vbd_blam, sizeof *v->blam * (size_t)g->vbd_nb);
        memcpy(v->bc0, g->vbd_bc0, sizeof *v->bc0 * (size_t)g->vbd_nb);
    }
    v->cap_lam = g->vbd_nd, v->cap_blam = g->vbd_nb;
    v->restored = 1;
    return WB_OK;
}
