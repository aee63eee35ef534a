/* contact.c: particle-particle contacts (docs/physics.md, "Contacts").
 *
 * Once per frame a broad phase (broadphase.c: a sorted grid over the frame's swept bounds
 * plus a margin, Macklin et al. 2019 "Small steps" §4) lists the candidate pairs; every
 * substep they are projected as inequality constraints |x_i - x_j| >= r_i + r_j (XPBD
 * with compliance 0, mass-weighted so momentum is conserved). Coulomb friction as the
 * collider contacts have it (collide.c): static at position level, checked per particle
 * over all its pair and triangle contacts of the substep (wb__contacts_friction), and
 * dynamic at velocity level for pairs that slide, mass-weighted. After the velocity
 * update a velocity pass removes the approach speed (no restitution), any speed the
 * repair of an old overlap made (bodies made inside each other push apart at
 * max_depenetration, never fly apart), and a sliding pair's tangential speed up to
 * mu x its normal impulse. Inside one
 * body, pairs never collide unless it self-collides, and then not when joined by a
 * constraint or closer than r_i + r_j where they were created (Müller's Ten Minute
 * Physics rule).
 *
 * Determinism: the candidate list depends on the positions alone (broadphase.c, for
 * any thread count), and the pairs are projected in a
 * serial pass in that order, so the result is the same for any thread count. */
#include <stdlib.h>

#include "core.h"
#include "ctype.h"
#include "broadphase.h"
#include "tricontact.h"

/* a contact's record for the velocity pass and the readout (act_nd): normal (i -> j),
 * depth, normal force, old overlap pushed back in full (err), mu when sliding (else 0) */
#define ND 7

/* ---- the scratch (k.pc) -------------------------------------------------------------------- */
int wb__contacts_make(wb_world *w)
{
    if (!w->k.pc) w->k.pc = calloc(1, sizeof *w->k.pc);
    return w->k.pc != NULL;
}

void wb__contacts_destroy(wb_world *w)
{
    wb_contacts *c = w->k.pc;
    if (!c) return;
    wb__broadphase_free(c);
    void *p[] = { c->ij, c->act, c->act_nd, c->left, c->reach, c->keys, c->graph, c->tcov, c->near, c->load,
                  c->made_ab, c->bm };
    for (size_t i = 0; i < sizeof p / sizeof p[0]; i++) free(p[i]);
    free(c);
    w->k.pc = NULL;
}

/* ---- groups and settings ---------------------------------------------------------------- */
int32_t wb_group_new(const wb_world *w)
{
    int32_t g = 0;
    for (int32_t i = 0; i < w->m.np; i++)
        if (w->m.group[i] > g) g = w->m.group[i];
    return g + 1;
}

int32_t wb_particle_group(const wb_world *w, int32_t p) { return w->m.group[p]; }
wb_real wb_particle_friction(const wb_world *w, int32_t p) { return w->m.cfric[p]; }
bool wb_particle_collides(const wb_world *w, int32_t p) { return (w->m.cflags[p] & WB_CF_COLLIDE) != 0; }

void wb_particle_set_group(wb_world *w, int32_t p, int32_t group)
{
    w->m.group[p] = group > 0 ? group : 0;
    if (w->k.pc) w->k.pc->scan_dirty = 1;
}

void wb_particle_set_friction(wb_world *w, int32_t p, wb_real mu) { w->m.cfric[p] = mu; }

void wb_body_set_contacts(wb_world *w, wb_body b, bool collide, bool self_collide, wb_real friction)
{
    const uint8_t f = (uint8_t)((collide ? WB_CF_COLLIDE : 0) | (self_collide ? WB_CF_SELF : 0));
    for (int32_t i = b.first; i < b.first + b.count; i++) {
        w->m.group[i] = b.group;
        w->m.cflags[i] = f;
        w->m.cfric[i] = friction;
    }
    if (w->k.pc) w->k.pc->scan_dirty = 1;
}

wb_status wb__body_finish(wb_world *w, int32_t first, int32_t count, wb_body *out)
{
    out->group = wb_group_new(w); /* before the new particles join it */
    out->first = first;
    out->count = count;
    wb_body_set_contacts(w, *out, true, false, 0);
    return WB_OK;
}

int32_t wb_group_set_self_collide(wb_world *w, int32_t group, bool on)
{
    int32_t n = 0;
    for (int32_t i = 0; i < w->m.np; i++) {
        if (w->m.group[i] != group) continue;
        if (on) w->m.cflags[i] |= WB_CF_SELF;
        else w->m.cflags[i] &= (uint8_t)~WB_CF_SELF;
        n++;
    }
    if (n > 0 && w->k.pc) w->k.pc->scan_dirty = 1;
    return n;
}

bool wb_group_self_collide(const wb_world *w, int32_t group)
{
    for (int32_t i = 0; i < w->m.np; i++)
        if (w->m.group[i] == group && (w->m.cflags[i] & WB_CF_SELF)) return true;
    return false;
}

void wb_particle_set_radius(wb_world *w, int32_t p, wb_real r)
{
    w->m.radius[p] = r;
    if (w->k.pc) w->k.pc->scan_dirty = 1; /* the triangles a body's spheres cover (wb__contact_rules) */
}

/* the body's links (any constraint type's: a Neo-Hookean lattice has tets and no
 * distances) shortening each end's shortest */
typedef struct spacing_ud { const wb_world *w; wb_body b; wb_real *shortest; } spacing_ud;

static void shorten(void *ud, int32_t a, int32_t b, int joined)
{
    const spacing_ud *u = ud;
    if (!joined) return;
    wb_real d[3];
    v3_sub(d, &u->w->s.x[3 * b], &u->w->s.x[3 * a]);
    const wb_real len = v3_len(d);
    const int32_t e[2] = { a - u->b.first, b - u->b.first };
    for (int k = 0; k < 2; k++)
        if (e[k] >= 0 && e[k] < u->b.count && len > 0 && len < u->shortest[e[k]]) u->shortest[e[k]] = len;
}

wb_real wb_body_spacing(const wb_world *w, wb_body b)
{
    if (b.count <= 0) return 0;
    wb_real *shortest = malloc(sizeof *shortest * (size_t)b.count);
    if (!shortest) return 0;
    for (int32_t i = 0; i < b.count; i++) shortest[i] = INFINITY;
    spacing_ud u = { w, b, shortest };
    for (int t = 0; t < wb__nctypes; t++)
        if (wb__ctypes[t]->links) wb__ctypes[t]->links(w, shorten, &u);
    wb_real sum = 0;
    int32_t n = 0;
    for (int32_t i = 0; i < b.count; i++)
        if (isfinite(shortest[i])) { sum += shortest[i]; n++; }
    free(shortest);
    return n > 0 ? sum / n : 0;
}

/* ---- the step ---------------------------------------------------------------------------------- */
/* Project every candidate once, in list order (Gauss-Seidel): push the pair apart along
 * their line by the overlap, split by inverse mass (friction comes after every pair's and
 * triangle's normal correction: wb__contacts_friction).
 *
 * Old overlap. A correction of depth adds depth / h to the pair's separating speed
 * (v = (x - x_prev) / h). The part that takes back this substep's approach (what the
 * prediction and the links did since x_prev, including the links pulling a pushed
 * particle back) is the collision and stays speed. The part that removes overlap the
 * pair already had at x_prev (d0) is the repair of a position error: kept as speed it
 * would fling them apart at up to depth / h (2 cm at h = 1/600 s: 12 m/s). Of d0:
 *  - what the pair keeps from substep to substep (bodies made inside each other, a deep
 *    squeeze) goes at no more than max_depenetration x h per substep, counting what
 *    other contacts pushed out of it (a particle inside another body touches several of
 *    its particles and triangles: each pushing at full rate sent interleaved blocks off
 *    at metres per second). Its push moves x_prev with x (Macklin et al. 2014, "Unified
 *    particle physics", §4.2, pre-stabilization): a position change, not a speed, which
 *    a pair later in the pass that it pushes into overlap also sees as old;
 *  - the rest (what later pairs or the colliders pushed back after this pair's last
 *    projection: a heap's layers) goes in full, or the heap sinks, and its speed is taken
 *    out in the velocity pass (err). Not through x_prev: a settled stack would then rest
 *    on position corrections alone and keep a velocity (-g h / 3 in a stack of three).
 * wb__contact_depth (core.h) works the parts out; tricontact.c uses it too. */
/* Made overlap between two bodies. Pushed out pair by pair along the pairs' own lines, a
 * body made into another as deep as a contact distance does not come out: a particle
 * level with or past the other's first layer is pushed sideways or back into it, the
 * pushes (no speed: x_prev moves with x) stretch the links, and the links give it back
 * as speed (two lattices made stacked, the upper one's bottom layer level with the
 * lower one's top layer half a spacing aside, flew apart at 86 m/s). So when a made pair
 * of two bodies is deep (below), what the
 * two keep is taken out by moving the bodies whole, a translation of x and x_prev alike
 * (no strain, no speed), apart along u, the shortest way out of the overlap of their
 * bounding boxes at the frame's start (the line between their centres slanted for
 * blocks stacked a little aside and slid the upper one off), by at most
 * max_depenetration x h per substep, until no made pair of theirs overlaps. One over the
 * other (u within 60 degrees of gravity): the upper one is lifted, and takes all of the
 * substep's contact corrections between them, the lower most likely resting on
 * something (moved down into the ground, it was pushed back into the upper one); else
 * they share by their masses; a body with a pinned particle stays. What they keep is the
 * most that a made pair of theirs must move apart along u to touch (sep_along). While
 * they move, their pairs leave the overlap they began the substep with to the shift and
 * take back only the substep's approach along u (along a pair's own line, a particle
 * past the first layer is seen parting as it sinks deeper), and their particle-triangle
 * contacts wait (tricontact.c). tests/validation/made_stack.lua: stacks made up to 1.5
 * contact distances in part below 0.1 m/s and rest stacked. */
typedef struct made {
    int32_t ng;            /* groups 0..ng-1 */
    wb_real *box;          /* (ng x 7) each body's bounds at the frame's start (its particles'
                              spheres), lo then hi, then its mass (INFINITY: a pinned particle) */
    wb_real *shift;        /* (ng x 3) each body's translation this substep */
    int32_t np, cap;       /* body pairs with a made overlap this substep */
    struct made_pair { int32_t a, b; wb_real u[3], keep, s, fa; int deep, met; } *p;
    int tried;
} made;

static void made_free(made *mb)
{
    free(mb->box);
    free(mb->shift);
    free(mb->p);
}

static int body_boxes(const wb_world *w, made *mb)
{
    if (mb->tried) return mb->box != NULL;
    mb->tried = 1;
    const int32_t np = w->m.np, *g = w->m.group;
    int32_t ng = 0;
    for (int32_t i = 0; i < np; i++)
        if (g[i] >= ng) ng = g[i] + 1;
    wb_real *box = malloc(sizeof *box * 7 * (size_t)ng);
    mb->shift = calloc((size_t)ng * 3, sizeof *mb->shift);
    if (!box || !mb->shift) {
        free(box);
        free(mb->shift);
        mb->shift = NULL;
        return 0;
    }
    for (int32_t k = 0; k < ng; k++)
        for (int c = 0; c < 3; c++) box[7 * k + c] = INFINITY, box[7 * k + 3 + c] = -INFINITY, box[7 * k + 6] = 0;
    /* at the frame's start (the undo copy): one way out for the whole frame */
    const wb_real *xs = w->k.x_save ? w->k.x_save : w->s.x_prev, *wv = w->m.w, *rad = w->m.radius;
    for (int32_t i = 0; i < np; i++) {
        wb_real *q = &box[7 * g[i]];
        for (int c = 0; c < 3; c++) {
            const wb_real lo = xs[3 * i + c] - rad[i], hi = xs[3 * i + c] + rad[i];
            if (lo < q[c]) q[c] = lo;
            if (hi > q[3 + c]) q[3 + c] = hi;
        }
        q[6] += wv[i] > 0 ? 1 / wv[i] : INFINITY;
    }
    mb->ng = ng;
    mb->box = box;
    return 1;
}

/* i and j are in two bodies (whose boxes are known) */
static int two_bodies(const wb_world *w, made *mb, int32_t i, int32_t j)
{
    const int32_t gi = w->m.group[i], gj = w->m.group[j];
    return gi > 0 && gj > 0 && gi != gj && body_boxes(w, mb);
}

/* Only bodies made overlapping keep a made overlap: a body that fell into a soft one
 * overlaps it as deep, but moved apart whole at its deepest (lifted, the soft one's
 * squeeze left to spring back) it rebounded faster than it struck (a 20 kg block on a
 * soft one, at 118% of its impact speed). Made overlapping: two of their particles made
 * (x0) closer than r_i + r_j, beyond the round-off of bodies made in touch. Asked only of
 * bodies deep in each other, and kept until the rules are rebuilt (bm). */
typedef struct { wb_real x; int32_t i; } x_at;

static int by_x(const void *p, const void *q)
{
    const wb_real a = ((const x_at *)p)->x, b = ((const x_at *)q)->x;
    return (a > b) - (a < b);
}

/* the particles of group g whose spheres at x0 meet the box lo..hi, in at[]; their count */
static int32_t group_in_box(const wb_model *m, int32_t g, const wb_real lo[3], const wb_real hi[3], x_at *at)
{
    int32_t n = 0;
    for (int32_t i = 0; i < m->np; i++) {
        if (m->group[i] != g) continue;
        const wb_real *p = &m->x0[3 * i], r = m->radius[i];
        int in = 1;
        for (int c = 0; c < 3; c++) in &= p[c] + r >= lo[c] && p[c] - r <= hi[c];
        if (in) at[n].x = p[0], at[n++].i = i;
    }
    return n;
}

static int made_overlapping(const wb_model *m, int32_t a, int32_t b)
{
    wb_real box[2][6], rmax = 0;
    for (int k = 0; k < 2; k++)
        for (int c = 0; c < 3; c++) box[k][c] = INFINITY, box[k][3 + c] = -INFINITY;
    for (int32_t i = 0; i < m->np; i++) {
        const int k = m->group[i] == a ? 0 : m->group[i] == b ? 1 : -1;
        if (k < 0) continue;
        for (int c = 0; c < 3; c++) {
            const wb_real lo = m->x0[3 * i + c] - m->radius[i], hi = m->x0[3 * i + c] + m->radius[i];
            if (lo < box[k][c]) box[k][c] = lo;
            if (hi > box[k][3 + c]) box[k][3 + c] = hi;
        }
        if (m->radius[i] > rmax) rmax = m->radius[i];
    }
    x_at *at = malloc(sizeof *at * (size_t)m->np * 2);
    if (!at) return 1; /* out of memory: as before bodies were told apart */
    x_at *A = at, *B = at + m->np;
    const int32_t na = group_in_box(m, a, box[1], box[1] + 3, A), nb = group_in_box(m, b, box[0], box[0] + 3, B);
    qsort(B, (size_t)nb, sizeof *B, by_x);
    int made = 0;
    for (int32_t p = 0; p < na && !made; p++) {
        const int32_t i = A[p].i;
        int32_t lo = 0, hi = nb; /* the first of B at or past x_i - r_i - rmax */
        while (lo < hi) {
            const int32_t mid = lo + (hi - lo) / 2;
            if (B[mid].x < A[p].x - m->radius[i] - rmax) lo = mid + 1;
            else hi = mid;
        }
        for (int32_t q = lo; q < nb && B[q].x <= A[p].x + m->radius[i] + rmax && !made; q++) {
            const int32_t j = B[q].i;
            wb_real d[3];
            v3_sub(d, &m->x0[3 * j], &m->x0[3 * i]);
            const wb_real r = (m->radius[i] + m->radius[j]) / WB_REST_TOUCH;
            made = v3_dot(d, d) < r * r;
        }
    }
    free(at);
    return made;
}

/* groups a < b were made overlapping (above), from the cache when asked before */
static int bodies_made(wb_world *w, int32_t a, int32_t b)
{
    wb_contacts *c = w->k.pc;
    if (c->bm_gen != c->rules_gen) c->nbm = 0, c->bm_gen = c->rules_gen;
    for (int32_t q = 0; q < c->nbm; q++)
        if (c->bm[3 * q] == a && c->bm[3 * q + 1] == b) return c->bm[3 * q + 2];
    const int made = made_overlapping(&w->m, a, b);
    int32_t *bm = wb__grow(c->bm, &c->cap_bm, 3 * (c->nbm + 1), sizeof *bm);
    if (bm) {
        c->bm = bm;
        bm[3 * c->nbm] = a, bm[3 * c->nbm + 1] = b, bm[3 * c->nbm++ + 2] = made;
    }
    return made;
}

/* how far j must move from i along u for the two to touch (d = x_j - x_i; 0 when apart) */
static wb_real sep_along(const wb_real d[3], const wb_real u[3], wb_real r)
{
    const wb_real d2 = v3_dot(d, d);
    if (!(d2 < r * r)) return 0;
    const wb_real s = v3_dot(d, u);
    return -s + sqrt(r * r - d2 + s * s);
}

/* what a pair of a new list counts as already overlapping (see below) */
static wb_real fresh_left(const wb_contacts *c, const wb_real *xp, const wb_real *rad, wb_real step, int32_t k)
{
    const int32_t i = c->ij[2 * k], j = c->ij[2 * k + 1];
    wb_real d[3];
    v3_sub(d, &xp[3 * j], &xp[3 * i]);
    const wb_real d0 = rad[i] + rad[j] - v3_len(d);
    return d0 > step ? d0 : 0;
}

/* the body pair of groups (a, b), a < b, added when new with u from a's box to b's, the
 * shortest way out of their overlap (the first of the shortest, in axis order); NULL when
 * out of memory */
static struct made_pair *made_pair_of(made *mb, int32_t a, int32_t b)
{
    for (int32_t q = 0; q < mb->np; q++)
        if (mb->p[q].a == a && mb->p[q].b == b) return &mb->p[q];
    if (mb->np == mb->cap) {
        const int32_t cap = mb->cap ? 2 * mb->cap : 8;
        struct made_pair *p = realloc(mb->p, sizeof *p * (size_t)cap);
        if (!p) return NULL;
        mb->p = p;
        mb->cap = cap;
    }
    struct made_pair *p = &mb->p[mb->np++];
    p->a = a;
    p->b = b;
    const wb_real *A = &mb->box[7 * a], *B = &mb->box[7 * b];
    wb_real best = INFINITY;
    v3_set(p->u, 0, 1, 0);
    for (int c = 0; c < 3; c++) {
        const wb_real up = A[3 + c] - B[c], down = B[3 + c] - A[c]; /* b moved +c, -c */
        if (up < best) best = up, v3_set(p->u, 0, 0, 0), p->u[c] = 1;
        if (down < best) best = down, v3_set(p->u, 0, 0, 0), p->u[c] = -1;
    }
    p->keep = 0;
    p->s = 0;
    p->fa = 0.5;
    p->deep = 0;
    p->met = -1;
    return p;
}

/* the body pair of groups a and b when it is moved apart this substep, else NULL */
static const struct made_pair *moving(const made *mb, int32_t a, int32_t b)
{
    if (a <= 0 || b <= 0 || a == b) return NULL;
    if (a > b) { const int32_t t = a; a = b; b = t; }
    for (int32_t q = 0; q < mb->np; q++)
        if (mb->p[q].a == a && mb->p[q].b == b) return mb->p[q].s > 0 ? &mb->p[q] : NULL;
    return NULL;
}

/* the bodies that keep a made overlap moved apart (above); 0 when none is */
static int made_shift(wb_world *w, made *mb, const wb_real *left, wb_real step, int32_t nprev)
{
    wb_contacts *c = w->k.pc;
    const int32_t *g = w->m.group;
    const wb_real *xp = w->s.x_prev, *rad = w->m.radius;
    for (int32_t k = 0; k < c->n; k++) {
        if (!(left[k] > step)) continue; /* a resting contact's g h^2 is no made overlap */
        const int32_t i = c->ij[2 * k], j = c->ij[2 * k + 1];
        if (!two_bodies(w, mb, i, j)) continue;
        const int i_first = g[i] < g[j];
        const int32_t a = i_first ? g[i] : g[j], b = i_first ? g[j] : g[i];
        struct made_pair *p = made_pair_of(mb, a, b);
        if (!p) return 0;
        if (p->met < 0) p->met = !bodies_made(w, a, b); /* met by moving: each pair parts as any */
        if (p->met) continue;
        wb_real d[3], u[3];
        v3_sub(d, &xp[3 * j], &xp[3 * i]);
        v3_scale(u, p->u, i_first ? 1 : -1);
        const wb_real rs = rad[i] + rad[j], sep = sep_along(d, u, rs);
        if (sep > p->keep) p->keep = sep;
        /* deep: b's particle past a's on the way out, or on it, or, moved along u to
         * touch, ending more than 44 degrees off u (in a hollow: 45). Pushed along its
         * own line such a pair sends the bodies into each other or sideways (blocks made
         * offset half a spacing and half a contact distance into the hollows part at 8.7
         * m/s). Pairs that part (nearly) along u, or beside each other (a tower made
         * interleaved, moved sideways), part pair by pair as before */
        const wb_real du = v3_dot(d, u);
        if (du < (wb_real)-0.01 * rs || v3_len(d) < (wb_real)0.01 * rs || du + sep < (wb_real)0.72 * rs)
            p->deep = 1;
    }
    /* a pair moved in the last substep goes on until it is out */
    for (int32_t q = 0; q < mb->np; q++)
        for (int32_t e = 0; e < nprev && !mb->p[q].deep && !mb->p[q].met; e++)
            if (c->made_ab[2 * e] == mb->p[q].a && c->made_ab[2 * e + 1] == mb->p[q].b) mb->p[q].deep = 1;
    int any = 0;
    for (int32_t q = 0; q < mb->np; q++) {
        struct made_pair *p = &mb->p[q];
        const wb_real ma = mb->box[7 * p->a + 6], mbb = mb->box[7 * p->b + 6];
        if (isinf(ma) && isinf(mbb)) continue; /* both held: their pairs push as any contact */
        if (!p->deep) continue; /* shallower: the pairs part it (as any contact's made overlap) */
        p->s = p->keep < step ? p->keep : step;
        wb_real fa = isinf(ma) ? 0 : isinf(mbb) ? 1 : mbb / (ma + mbb);
        const wb_real *gv = w->m.def.gravity, gl = v3_len(gv), ug = gl > 0 ? v3_dot(p->u, gv) / gl : 0;
        if (!isinf(ma) && !isinf(mbb) && fabs(ug) > (wb_real)0.5) fa = ug > 0 ? 1 : 0;
        p->fa = fa;
        v3_madd(&mb->shift[3 * p->a], p->u, -p->s * fa);
        v3_madd(&mb->shift[3 * p->b], p->u, p->s * (1 - fa));
        any |= p->s > 0;
    }
    if (!any) return 0;
    /* the pairs moved, for tricontact.c and the next substep */
    int32_t *ab = wb__grow(c->made_ab, &c->cap_made, 2 * mb->np, sizeof *ab);
    if (ab) {
        c->made_ab = ab;
        c->nmade = 0;
        for (int32_t q = 0; q < mb->np; q++)
            if (mb->p[q].s > 0) ab[2 * c->nmade] = mb->p[q].a, ab[2 * c->nmade++ + 1] = mb->p[q].b;
    }
    wb_real *x = w->s.x, *xo = w->s.x_prev;
    for (int32_t i = 0; i < w->m.np; i++) {
        const wb_real *s = &mb->shift[3 * g[i]];
        if (g[i] <= 0 || w->m.w[i] == 0 || (s[0] == 0 && s[1] == 0 && s[2] == 0)) continue;
        v3_add(&x[3 * i], &x[3 * i], s);
        v3_add(&xo[3 * i], &xo[3 * i], s);
    }
    return 1;
}

/* Later sweeps over the pairs in touch. One Gauss-Seidel pass leaves a dense contact set
 * overlapping: where a fold's crease jams, a particle pushed out of one pair is pushed back
 * into another by the pairs after it, and the links squeeze the crease again each substep
 * (a 56 x 56 cloth dropped onto a sphere at 10 substeps: pairs at 0.86 of r_i + r_j after
 * the pass, 0.88 at the frame's end; tests/validation/cloth_sphere_drop.lua). The pairs in
 * touch after the pass (in overlap, in touch, or within NEAR x r_i + r_j) are swept again
 * in list order, each pushed back to the overlap its pass left it with (left: a made
 * overlap going out at max_depenetration keeps its part), up to SWEEPS passes in all, fewer
 * once a sweep's largest correction is below SWEEP_TOL x r_i + r_j; and again after the
 * static friction (wb__contacts_settle), whose slips undone push the neighbouring pairs
 * back into overlap (0.97 after the sweeps, 0.92 after the friction). A sweep's push is
 * speed, as the pass's depth beyond the old overlap, and adds to the pair's depth and
 * force as an XPBD iteration adds to its multiplier: so the friction's bound is the load
 * the pair carries, some of which reaches a stack's lower layers in the sweeps only (left
 * out of the bound, the folds of scripts/cloth_heap.lua crept 3.9 cm in its 4th second,
 * against 0.7 cm with one pass). Of it, what the pair overlapped by at x_prev beyond its
 * kept part is old overlap (err: its speed is taken out after the velocity update). A
 * 64 x 64 heap at rest, rms over its last 2 s, eight variants of its start: 0.005-0.020
 * m/s, against 0.009-0.12 with one pass (tests/validation/self_collision.lua). Bodies
 * being moved apart whole (made_shift) are not swept. Returns how many pairs the pass
 * counted in touch the sweeps made contacts. */
#define SWEEPS 4
#define NEAR ((wb_real)1.1)
#define SWEEP_TOL ((wb_real)1e-3)
#define SWEEP_G ((wb_real)1e-3)
static int32_t sweep(wb_world *w, wb_real h, int32_t *near, int32_t nn)
{
    wb_contacts *c = w->k.pc;
    const wb_model *m = &w->m;
    wb_real *x = w->s.x, *nds = c->act_nd;
    const wb_real *xp = w->s.x_prev, *wv = m->w, *rad = m->radius, *left = c->left;
    int32_t was_touching = 0;
    /* the sweeps stop early only once their corrections are small against what gravity
     * moves a particle in a substep too: stopped at SWEEP_TOL x (r_i + r_j) alone (4e-5 m
     * for particles of radius 2 cm, more than g h^2 = 2.7e-5 m at 10 substeps) a stack of
     * three particles on an immovable one never came to rest (1 mm/s) and read 2.44,
     * 1.58, 0.76 m g for 3, 2, 1. Not under VBD, whose contacts after its sweeps fight
     * them (docs/physics.md, "VBD"): passes until then blew a hand-built cloth landing on
     * a sphere up (tests/validation/user/03_cloth_hand_built_sphere.lua: 134 J from 9.8) */
    const wb_real gh2 = m->def.solver == WB_SOLVER_VBD ? INFINITY : v3_len(m->def.gravity) * h * h * SWEEP_G;
    for (int s = 1; s < SWEEPS; s++) {
        wb_real worst = 0, worst_abs = 0;
        for (int32_t q = 0; q < nn; q++) {
            const int32_t e = near[q], k = e >= 0 ? c->act[e] : (-e - 1) >> 1;
            const int32_t i = c->ij[2 * k], j = c->ij[2 * k + 1];
            const wb_real wi = wv[i], wj = wv[j], wsum = wi + wj;
            if (wsum == 0) continue;
            wb_real *xi = &x[3 * i], *xj = &x[3 * j], d[3];
            v3_sub(d, xj, xi);
            const wb_real r = rad[i] + rad[j], to = r - left[k], d2 = v3_dot(d, d);
            if (!(d2 < to * to)) continue;
            const wb_real len = sqrt(d2), depth = to - len;
            wb_real n[3];
            if (len > r * (wb_real)1e-9) v3_scale(n, d, 1 / len);
            else v3_set(n, 0, 1, 0);
            if (wi > 0) v3_madd(xi, n, -depth * wi / wsum);
            if (wj > 0) v3_madd(xj, n, depth * wj / wsum);
            if (depth > worst * r) worst = depth / r;
            if (depth > worst_abs) worst_abs = depth;
            /* old overlap: what the pair overlaps by at x_prev beyond its kept part, which
             * the made overlap of others, pushed out with x_prev since the pass, adds to */
            wb_real dp[3];
            v3_sub(dp, &xp[3 * j], &xp[3 * i]);
            wb_real old = to - v3_len(dp);
            if (e >= 0) {
                old -= nds[ND * e + 5];
                old = !(old > 0) ? 0 : old < depth ? old : depth;
                nds[ND * e + 3] += depth;
                nds[ND * e + 4] += depth / wsum / (h * h);
                nds[ND * e + 5] += old;
                continue;
            }
            old = !(old > 0) ? 0 : old < depth ? old : depth;
            /* a pair in touch after the pass made a contact */
            const int32_t a = c->nact++;
            was_touching += (-e - 1) & 1;
            near[q] = a;
            c->act[a] = k;
            v3_copy(&nds[ND * a], n);
            nds[ND * a + 3] = depth;
            nds[ND * a + 4] = depth / wsum / (h * h);
            nds[ND * a + 5] = old;
            nds[ND * a + 6] = 0;
        }
        if (worst < SWEEP_TOL && worst_abs < gh2) break;
    }
    return was_touching;
}

/* after the static friction: the pairs in touch swept again (above) */
void wb__contacts_settle(wb_world *w, wb_real h)
{
    wb_contacts *c = w->k.pc;
    if (c->nnear == 0 || (!c->fmoved && w->k.tc->nact == 0)) return; /* (the friction moved nothing) */
    c->touching -= sweep(w, h, c->near, c->nnear);
    c->last = c->nact + c->touching;
}

void wb__contacts_project(wb_world *w, wb_real h)
{
    wb_contacts *c = w->k.pc;
    c->nact = 0;
    c->nnear = 0;
    /* the body pairs moved in the last substep, within the frame only: a frame's start
     * works them out from the state alone (a snapshot's future is the same) */
    const int32_t nprev = c->fresh ? 0 : c->nmade;
    c->nmade = 0;
    /* the list still holds (else it is made again, and each old pair's left is kept) */
    const int32_t n_before = c->n;
    const int remade = wb__contacts_recheck(w, h);
    if (remade < 0) wb__warn(w, "out of memory in the contact broad phase; contacts skipped");
    if (remade == 1 && !c->fresh && n_before > 0) {
        wb_real *lo = wb__grow(c->left_old, &c->cap_left_old, n_before, sizeof *lo);
        if (!lo) { c->fresh = 1; goto nomem; }
        c->left_old = lo;
        memcpy(lo, c->left, sizeof *lo * (size_t)n_before);
    }
    if (c->brute) wb__contacts_brute(w);
    if (c->n == 0) { c->last = 0; return; }
    int32_t touching = 0;
    const wb_model *m = &w->m;
    wb_real *x = w->s.x, *xp = w->s.x_prev;
    const wb_real *wv = m->w, *rad = m->radius, vmax = m->def.max_depenetration;
    int32_t *act = wb__grow(c->act, &c->cap_act, c->n, sizeof *act);
    if (!act) goto nomem;
    c->act = act;
    wb_real *nds = wb__grow(c->act_nd, &c->cap_nd, ND * c->n, sizeof *nds);
    if (!nds) goto nomem;
    c->act_nd = nds;
    wb_real *left = wb__grow(c->left, &c->cap_left, c->n, sizeof *left);
    if (!left) goto nomem;
    c->left = left;
    int32_t *near = wb__grow(c->near, &c->cap_near, c->n, sizeof *near), nn = 0;
    if (!near) goto nomem;
    c->near = near;
    /* a new candidate list (each frame): what each pair was left with is not known; the
     * overlap it has now counts as kept, unless one step would take it all anyway (a
     * resting contact's g h^2: then its repair is taken out of the speed as within a
     * frame, and a settled stack stays exactly at rest). Worked out from the state
     * alone, so a step interrupted and run again gives the same result */
    made mb;
    memset(&mb, 0, sizeof mb);
    if (c->fresh) {
        for (int32_t k = 0; k < c->n; k++) left[k] = fresh_left(c, xp, rad, vmax * h, k);
        c->fresh = 0;
    } else if (remade == 2) {
        /* pairs added to the list in place: theirs is NaN */
        for (int32_t k = 0; k < c->n; k++)
            if (left[k] != left[k]) left[k] = fresh_left(c, xp, rad, vmax * h, k);
    } else if (remade == 1) {
        /* a list made again within the frame: a pair it had keeps what it was left with
         * (both lists are in (i, j) order), a new one starts as a new list's */
        const int32_t *io = c->ij_old, no = c->n_old;
        for (int32_t k = 0, q = 0; k < c->n; k++) {
            const int32_t i = c->ij[2 * k], j = c->ij[2 * k + 1];
            while (q < no && (io[2 * q] < i || (io[2 * q] == i && io[2 * q + 1] < j))) q++;
            left[k] = q < no && io[2 * q] == i && io[2 * q + 1] == j ? c->left_old[q] : fresh_left(c, xp, rad, vmax * h, k);
        }
    }
    const int shifted = made_shift(w, &mb, left, vmax * h, nprev);
    /* the list and the count in locals: the stores below (int32 act and near) could alias
     * the scratch's fields for the compiler, which would then load them every pair */
    const int32_t npairs = c->n, *ij = c->ij;
    int32_t nact = 0;
    for (int32_t k = 0; k < npairs; k++) {
        const int32_t i = ij[2 * k], j = ij[2 * k + 1];
        const wb_real wi = wv[i], wj = wv[j], wsum = wi + wj;
        if (wsum == 0) continue;
        wb_real *xi = &x[3 * i], *xj = &x[3 * j], *pi = &xp[3 * i], *pj = &xp[3 * j];
        wb_real d[3];
        v3_sub(d, xj, xi);
        const wb_real r = rad[i] + rad[j], d2 = v3_dot(d, d);
        if (!(d2 < r * r)) {
            /* in touch (left at r_i + r_j by the last substep, to round-off): a contact
             * for the count, with nothing to correct */
            const wb_real rt = r * (1 + (wb_real)1e-9), rn = r * NEAR;
            const int t = d2 <= rt * rt;
            touching += t;
            left[k] = 0;
            if (d2 < rn * rn && !(shifted && moving(&mb, m->group[i], m->group[j]))) near[nn++] = -(2 * k + t) - 1;
            continue;
        }
        wb_real n[3], dp[3], slow, err, depth;
        v3_sub(dp, pj, pi);
        const wb_real len = sqrt(d2);
        if (len > r * (wb_real)1e-9) v3_scale(n, d, 1 / len);
        else v3_set(n, 0, 1, 0); /* coincident: any direction separates them */
        const struct made_pair *mp = shifted ? moving(&mb, m->group[i], m->group[j]) : NULL;
        if (mp) {
            /* two bodies being moved apart: the overlap the pair began the substep with
             * is theirs to take out. Along the pair's line a particle past the other
             * body's first layer is seen parting as it sinks deeper into it: what the
             * substep drove in is the pair's approach along the bodies' line, undone */
            const wb_real d0 = r - v3_len(dp);
            left[k] = d0 > 0 ? d0 : 0;
            if (mp->a == m->group[i]) v3_copy(n, mp->u);
            else v3_scale(n, mp->u, -1);
            wb_real dd[3];
            v3_sub(dd, d, dp);
            depth = -v3_dot(dd, n);
            slow = err = 0;
        } else {
            depth = wb__contact_depth(r - len, r - v3_len(dp), &left[k], vmax * h, &slow, &err);
        }
        if (!(depth > 0)) {
            touching++;
            if (!mp) near[nn++] = -(2 * k + 1) - 1;
            continue;
        }
        if (mp && (mp->fa == 0 || mp->fa == 1)) {
            /* one of the two stays (above): the other takes all of it */
            const int i_stays = (mp->fa == 0) == (mp->a == m->group[i]);
            if (i_stays && wj > 0) v3_madd(xj, n, depth);
            else if (!i_stays && wi > 0) v3_madd(xi, n, -depth);
            else {
                if (wi > 0) v3_madd(xi, n, -depth * wi / wsum);
                if (wj > 0) v3_madd(xj, n, depth * wj / wsum);
            }
        } else {
            if (wi > 0) v3_madd(xi, n, -depth * wi / wsum), v3_madd(pi, n, -slow * wi / wsum);
            if (wj > 0) v3_madd(xj, n, depth * wj / wsum), v3_madd(pj, n, slow * wj / wsum);
        }
        /* normal and depth, kept for the velocity pass; the normal force for the readout
         * (XPBD multiplier of a zero-compliance contact, depth / (w_i + w_j), over h^2) */
        act[nact] = k;
        v3_copy(&nds[ND * nact], n);
        nds[ND * nact + 3] = depth;
        nds[ND * nact + 4] = depth / wsum / (h * h);
        nds[ND * nact + 5] = err;
        nds[ND * nact + 6] = 0; /* the friction pass sets it */
        if (!mp) near[nn++] = nact;
        nact++;
    }
    c->nact = nact;
    made_free(&mb);
    /* (no correction: nothing moved since any pair's projection) */
    if (c->nact == 0) nn = 0;
    touching -= sweep(w, h, near, nn);
    c->nnear = nn;
    c->touching = touching;
    c->last = c->nact + touching;
    return;
nomem:
    c->last = 0;
    wb__warn(w, "out of memory in contacts; contacts skipped this substep");
}

/* Friction (Coulomb, one coefficient mu: the mean of the two particles' `friction`), after
 * the normal corrections of the substep's pairs and triangle contacts, in two regimes as
 * for the collider contacts (collide.c): static at position level, dynamic at velocity
 * level (Müller et al. 2020, "Detailed rigid body simulation with extended position
 * based dynamics", §3.5-3.6).
 *
 * Sliding: the pair's relative tangential speed as predicted for the substep (before
 * the constraints) is more than one substep of dynamic friction takes away
 * (|u_t| > mu depth / h). Its friction is left to
 * the velocity pass (wb__contacts_velocity): -mu (depth - err) / h of it, at most all
 * of it (err: the old overlap pushed back in full, whose speed that pass takes out).
 *
 * At rest (otherwise): the relative tangential slip of the substep is undone at position
 * level, split by inverse mass, within the friction cone. The cone is checked per
 * particle, not per contact: a particle's normal load is split over all its contacts (a
 * block's particle on a slab of many, in a hollow of four), and a contact alone holds
 * only its share. Each particle has a budget of mu x the sum of its at-rest contacts'
 * normal impulses (lambda = (depth - err) / (w_i + w_j); a triangle's corner b_k of its
 * contact's): the part of the correction that holds the pair apart, as for the dynamic
 * friction below. With all of depth, the repair of overlap the links keep pressing shut
 * lent friction that pushed a settled cloth heap about (0.30 m/s rms, against 0.020 m/s:
 * tests/validation/self_collision.lua). A contact takes the impulse that undoes its slip, |slip| / (w_i + w_j),
 * from what is left of both its particles' budgets. The contacts go in list order, each
 * seeing the slip the ones before it left: the first contact of a particle that sticks
 * takes its slip away and its other contacts need (nearly) nothing, so what a particle
 * sticks with is its slip against its partners, bounded by mu x its contacts' normal
 * corrections (an immovable partner: |slip| <= mu sum(depth), collide.c's test for one
 * contact). Where the budget is short, it undoes what the budget allows: static friction
 * at its bound mu N while the pair breaks away, as large as the dynamic friction it meets
 * once sliding. An all-or-nothing test (undo all or nothing) made a stiff block on a
 * bumpy slab chatter below the critical angle: its particles' shares of the load differ
 * by the slab's bumps (+-10%), the ones over the cone slid a whole substep's slip, their
 * links pulled the others over it, and the block crept down at 0.95 tan^-1 mu.
 * An immovable particle has no budget to keep. */
void wb__contacts_friction(wb_world *w, wb_real h)
{
    wb_contacts *c = w->k.pc;
    c->fmoved = 0;
    if (c->nact == 0 && w->k.tc->nact == 0) return;
    const wb_model *m = &w->m;
    wb_real *load = wb__grow(c->load, &c->cap_load, m->np, sizeof *load);
    if (!load) { wb__warn(w, "out of memory in contact friction; friction skipped this substep"); return; }
    c->load = load;
    memset(load, 0, sizeof *load * (size_t)m->np);
    wb_real *x = w->s.x, *nds = c->act_nd;
    const wb_real *xp = w->s.x_prev, *v = w->s.v, *wv = m->w, *cf = m->cfric;
    for (int32_t a = 0; a < c->nact; a++) {
        const int32_t k = c->act[a], i = c->ij[2 * k], j = c->ij[2 * k + 1];
        const wb_real mu = (cf[i] + cf[j]) / 2, *n = &nds[ND * a], depth = nds[ND * a + 3];
        if (!(mu > 0)) continue;
        wb_real u[3];
        v3_sub(u, &v[3 * j], &v[3 * i]);
        v3_madd(u, n, -v3_dot(u, n));
        if (v3_len(u) * h > mu * depth) {
            nds[ND * a + 6] = mu; /* sliding: the velocity pass's */
            continue;
        }
        const wb_real l = mu * (depth - nds[ND * a + 5]) / (wv[i] + wv[j]);
        load[i] += l;
        load[j] += l;
    }
    wb__tricontacts_load(w, h, load);
    for (int32_t a = 0; a < c->nact; a++) {
        const int32_t k = c->act[a], i = c->ij[2 * k], j = c->ij[2 * k + 1];
        if (!(cf[i] + cf[j] > 0) || nds[ND * a + 6] > 0) continue;
        const wb_real wi = wv[i], wj = wv[j], wsum = wi + wj, *n = &nds[ND * a];
        wb_real *xi = &x[3 * i], *xj = &x[3 * j], slip[3];
        for (int d = 0; d < 3; d++) slip[d] = (xi[d] - xp[3 * i + d]) - (xj[d] - xp[3 * j + d]);
        v3_madd(slip, n, -v3_dot(slip, n));
        const wb_real need = v3_len(slip) / wsum;
        wb_real tau = need;
        if (wi > 0 && load[i] < tau) tau = load[i];
        if (wj > 0 && load[j] < tau) tau = load[j];
        if (!(tau > 0)) continue;
        c->fmoved = 1;
        load[i] -= tau;
        load[j] -= tau;
        const wb_real f = tau / need / wsum;
        if (wi > 0) v3_madd(xi, slip, -f * wi);
        if (wj > 0) v3_madd(xj, slip, f * wj);
    }
    wb__tricontacts_static(w, load);
}

/* after v = (x - x_prev)/h, per pair: no speed made out of old overlap pushed back in
 * full (err, above), then no approach speed left (perfectly inelastic), then a sliding
 * pair's dynamic friction: its relative tangential speed reduced by mu x the normal
 * impulse, mu (depth - err) / h (collide.c's rule), at most to zero; each change split by
 * inverse mass, so momentum is kept exactly.
 *
 * The speed of err taken out is at most the pair's separating speed. When the links,
 * the colliders or other contacts pushed the pair back together after its projection (a
 * tight fold, a particle wedged against the floor), that speed is already gone; taking it
 * out anyway made an approach speed that this pair's next pass took back along its normal
 * but the contacts between, along other normals, left partly in place: a particle wedged
 * under two others read 5.3 cm/s without moving, one in a settled cloth heap 3.4 cm/s
 * (tests/validation/contact_kinetic.lua). The dynamic friction's normal impulse is
 * likewise the speed the contact kept, depth - err: with all of depth, the repair of a
 * fold the links keep pressing shut made friction that kept a cloth heap moving. */
void wb__contacts_velocity(wb_world *w, wb_real h)
{
    wb_contacts *c = w->k.pc;
    const wb_model *m = &w->m;
    wb_real *v = w->s.v;
    for (int32_t a = 0; a < c->nact; a++) {
        const int32_t k = c->act[a], i = c->ij[2 * k], j = c->ij[2 * k + 1];
        const wb_real wi = m->w[i], wj = m->w[j], wsum = wi + wj, e = c->act_nd[ND * a + 5] / h;
        if (!(e > 0) || wsum == 0) continue;
        const wb_real *n = &c->act_nd[ND * a];
        wb_real u[3];
        v3_sub(u, &v[3 * j], &v[3 * i]);
        const wb_real un = v3_dot(u, n), s = e < un ? e : un;
        if (!(s > 0)) continue;
        if (wi > 0) v3_madd(&v[3 * i], n, s * wi / wsum);
        if (wj > 0) v3_madd(&v[3 * j], n, -s * wj / wsum);
    }
    for (int32_t a = 0; a < c->nact; a++) {
        const int32_t k = c->act[a], i = c->ij[2 * k], j = c->ij[2 * k + 1];
        const wb_real wi = m->w[i], wj = m->w[j], wsum = wi + wj;
        if (wsum == 0) continue;
        const wb_real *n = &c->act_nd[ND * a], mu = c->act_nd[ND * a + 6];
        wb_real *vi = &v[3 * i], *vj = &v[3 * j], u[3];
        v3_sub(u, vj, vi);
        const wb_real un = v3_dot(u, n);
        /* change u = vj - vi by -un n, split by inverse mass */
        if (un < 0) {
            if (wi > 0) v3_madd(vi, n, un * wi / wsum);
            if (wj > 0) v3_madd(vj, n, -un * wj / wsum);
        }
        if (!(mu > 0)) continue;
        v3_madd(u, n, -un); /* the tangential part, which the normal change left as it was */
        const wb_real ut = v3_len(u), dv = mu * (c->act_nd[ND * a + 3] - c->act_nd[ND * a + 5]) / h;
        if (!(ut > 0)) continue;
        /* change u by -min(dv, ut) u / ut */
        const wb_real f = (dv < ut ? dv : ut) / ut / wsum;
        if (wi > 0) v3_madd(vi, u, f * wi);
        if (wj > 0) v3_madd(vj, u, -f * wj);
    }
}

/* ---- readout of the last substep's contacts ------------------------------------------------ */
void wb__contacts_stats(const wb_world *w, wb_stats *st)
{
    const wb_contacts *pc = w->k.pc;
    const wb_tricontacts *tc = w->k.tc;
    if (!pc || !tc) return; /* never stepped */
    st->particle_contacts = pc->last + tc->last;
    st->broad_ms = pc->broad_ms + tc->broad_ms;
    st->broad_remakes = pc->remakes_frame;
}

int32_t wb_world_contact_count(const wb_world *w) { return w->k.pc ? w->k.pc->nact : 0; }

wb_contact wb_world_contact_at(const wb_world *w, int32_t i)
{
    const wb_contacts *c = w->k.pc;
    wb_contact out = { -1, -1, 0, { 0, 0, 0 }, 0 };
    if (i < 0 || i >= wb_world_contact_count(w)) return out;
    const int32_t k = c->act[i];
    const wb_real *nd = &c->act_nd[ND * i];
    out.a = c->ij[2 * k];
    out.b = c->ij[2 * k + 1];
    v3_copy(out.normal, nd);
    out.depth = nd[3];
    out.force = nd[4];
    return out;
}
