/* tricontact.c: particle-triangle contacts (docs/physics.md, "Contacts").
 *
 * The surfaces builders register (a cloth's sheet, a lattice's hull, from_mesh's surface,
 * a JSON config's surfaces) are collision geometry: a particle keeps its radius r_p away
 * from every triangle it may touch, so a small particle cannot slip between the coarse
 * particles of another body. The triangle itself has no thickness: its particles'
 * spheres are already handled by the particle-particle contacts (contact.c), and these
 * contacts close the gaps between them. That keeps a cloth's sheet, which is drawn
 * through its particles' centres, where a particle resting on it is seen to rest, and a
 * self-colliding cloth with the default radius (half its spacing) free of contacts
 * between particles two spacings apart in its own plane, which an interpolated thickness
 * would make touch at rest.
 *
 * Each substep a candidate (point p, triangle abc) with the closest point q = sum b_i x_i
 * is the inequality C = (x_p - q) . n - r_p >= 0, projected with XPBD at compliance 0:
 * gradients n for p and -b_i n for the corners, generalized inverse mass
 * W = w_p + sum b_i^2 w_i, so p moves w_p depth / W and corner i moves -b_i w_i depth / W
 * along n: the corrections' momentum sums to (1 - sum b_i) depth / W = 0. Coulomb
 * friction as contact.c's (mu the mean of p's and the triangle's barycentric friction):
 * the slip of p against q undone at position level within the per-particle cone when at
 * rest, dynamic friction at velocity level when sliding, with the same weights; after the
 * velocity update the approach speed along n is removed the same way. Overlap a point
 * already had goes out as contact.c's does (wb__contact_depth): at max_depenetration
 * and without becoming speed; before, all of it went in one substep, as speed, and
 * bodies made inside each other's hulls flew apart at metres per second.
 *
 * A surface is two-sided: n points to the side the point was on at the substep's start
 * (x_prev), as collide.c does for an open mesh collider, so a point the substep carried
 * through the sheet goes back rather than out the far side.
 *
 * Who may touch: a point and each corner of the triangle must be allowed to touch by
 * contact.c's rules (different groups: both collide; one body: both self-collide), never
 * a triangle's own corner, nor (one body) a point within r_p of the triangle where they
 * were created (wb_model.x0). A triangle whose particles are all immovable still stops
 * others.
 *
 * Broad phase, once per frame, in tribroad.c (which applies these rules): the candidates
 * in an order that depends on the positions alone; they are projected serially in that
 * order, so the step is bit-identical for any thread count. */
#include <stdlib.h>

#include "core.h"
#include "contact.h"
#include "tricontact.h"

/* a contact's record for the velocity pass and the readout (act_d): barycentrics, normal
 * (triangle -> point), depth, force, old overlap pushed back in full, mu when sliding */
#define TD 10

/* ---- closest point, as barycentrics ---------------------------------------------------------- */
/* on segment a + t (b - a): t in [0, 1] */
static wb_real seg_t(const wb_real p[3], const wb_real a[3], const wb_real b[3])
{
    wb_real ab[3], ap[3];
    v3_sub(ab, b, a);
    v3_sub(ap, p, a);
    const wb_real ll = v3_dot(ab, ab);
    return ll > 0 ? clampr(v3_dot(ap, ab) / ll, 0, 1) : 0;
}

static wb_real finish(const wb_real p[3], const wb_real a[3], const wb_real b[3], const wb_real c[3],
                      wb_real u, wb_real v, wb_real t, wb_real bary[3], wb_real out[3])
{
    bary[0] = u; bary[1] = v; bary[2] = t;
    for (int k = 0; k < 3; k++) out[k] = u * a[k] + v * b[k] + t * c[k];
    wb_real d[3];
    v3_sub(d, p, out);
    return v3_dot(d, d);
}

/* Ericson, Real-Time Collision Detection 5.1.5: the Voronoi region of p decides the face,
 * an edge or a corner; the same tests as bvh.c's, keeping the weights */
wb_real wb__tri_closest(const wb_real p[3], const wb_real a[3], const wb_real b[3], const wb_real c[3],
                        wb_real bary[3], wb_real out[3])
{
    wb_real ab[3], ac[3], ap[3], bp[3], cp[3];
    v3_sub(ab, b, a);
    v3_sub(ac, c, a);
    v3_sub(ap, p, a);
    const wb_real d1 = v3_dot(ab, ap), d2 = v3_dot(ac, ap);
    if (d1 <= 0 && d2 <= 0) return finish(p, a, b, c, 1, 0, 0, bary, out);
    v3_sub(bp, p, b);
    const wb_real d3 = v3_dot(ab, bp), d4 = v3_dot(ac, bp);
    if (d3 >= 0 && d4 <= d3) return finish(p, a, b, c, 0, 1, 0, bary, out);
    const wb_real vc = d1 * d4 - d3 * d2;
    if (vc <= 0 && d1 >= 0 && d3 <= 0) {
        const wb_real t = d1 / (d1 - d3);
        return finish(p, a, b, c, 1 - t, t, 0, bary, out);
    }
    v3_sub(cp, p, c);
    const wb_real d5 = v3_dot(ab, cp), d6 = v3_dot(ac, cp);
    if (d6 >= 0 && d5 <= d6) return finish(p, a, b, c, 0, 0, 1, bary, out);
    const wb_real vb = d5 * d2 - d1 * d6;
    if (vb <= 0 && d2 >= 0 && d6 <= 0) {
        const wb_real t = d2 / (d2 - d6);
        return finish(p, a, b, c, 1 - t, 0, t, bary, out);
    }
    const wb_real va = d3 * d6 - d5 * d4;
    if (va <= 0 && d4 - d3 >= 0 && d5 - d6 >= 0) {
        const wb_real t = (d4 - d3) / ((d4 - d3) + (d5 - d6));
        return finish(p, a, b, c, 0, 1 - t, t, bary, out);
    }
    const wb_real sum = va + vb + vc;
    if (!(sum > 0)) {
        /* degenerate (collinear corners): the nearest of the three edges */
        wb_real bb[3], o[3], best, e;
        wb_real t = seg_t(p, a, b);
        best = finish(p, a, b, c, 1 - t, t, 0, bary, out);
        t = seg_t(p, b, c);
        if ((e = finish(p, a, b, c, 0, 1 - t, t, bb, o)) < best) { best = e; v3_copy(bary, bb); v3_copy(out, o); }
        t = seg_t(p, c, a);
        if ((e = finish(p, a, b, c, t, 0, 1 - t, bb, o)) < best) { best = e; v3_copy(bary, bb); v3_copy(out, o); }
        return best;
    }
    const wb_real v = vb / sum, t = vc / sum;
    return finish(p, a, b, c, 1 - v - t, v, t, bary, out);
}

/* ---- projection -------------------------------------------------------------------------------------- */
/* p's body and the triangle's are a pair contact.c moves apart (contact.h) */
int wb__contacts_made(const wb_world *w, int32_t p, int32_t corner)
{
    const wb_contacts *pc = w->k.pc;
    const int32_t g1 = w->m.group[p], g2 = w->m.group[corner];
    if (pc->nmade == 0 || g1 <= 0 || g2 <= 0 || g1 == g2) return 0;
    const int32_t a = g1 < g2 ? g1 : g2, b = g1 < g2 ? g2 : g1;
    for (int32_t q = 0; q < pc->nmade; q++)
        if (pc->made_ab[2 * q] == a && pc->made_ab[2 * q + 1] == b) return 1;
    return 0;
}

void wb__tricontacts_project(wb_world *w, wb_real h)
{
    wb_tricontacts *c = w->k.tc;
    c->nact = 0;
    if (c->n == 0) { c->last = 0; return; }
    const wb_model *m = &w->m;
    wb_real *x = w->s.x, *xp = w->s.x_prev;
    const wb_real *wv = m->w, *rad = m->radius;
    int32_t *act = wb__grow(c->act, &c->cap_act, c->n, sizeof *act);
    if (!act) goto nomem;
    c->act = act;
    wb_real *ad = wb__grow(c->act_d, &c->cap_d, TD * c->n, sizeof *ad);
    if (!ad) goto nomem;
    c->act_d = ad;
    wb_real *left = wb__grow(c->left, &c->cap_left, c->n, sizeof *left);
    if (!left) goto nomem;
    c->left = left;
    /* a new candidate list: the overlap it has now counts as kept, as in contact.c */
    const wb_real step = m->def.max_depenetration * h;
    if (c->fresh) {
        for (int32_t k = 0; k < c->n; k++) {
            const int32_t p = c->pt[2 * k], *v = &m->tri[3 * c->pt[2 * k + 1]];
            wb_real b[3], q[3];
            const wb_real d0 = rad[p] - sqrt(wb__tri_closest(&xp[3 * p], &xp[3 * v[0]], &xp[3 * v[1]], &xp[3 * v[2]], b, q));
            left[k] = d0 > step ? d0 : 0;
        }
        c->fresh = 0;
    }
    int32_t touching = 0;
    for (int32_t k = 0; k < c->n; k++) {
        const int32_t p = c->pt[2 * k], *v = &m->tri[3 * c->pt[2 * k + 1]];
        wb_real *xs = &x[3 * p];
        const wb_real *xa = &x[3 * v[0]], *xb = &x[3 * v[1]], *xc = &x[3 * v[2]];
        wb_real b[3], q[3], d[3];
        const wb_real r = rad[p];
        /* what it was left with, until it is found overlapping again */
        wb_real lk = left[k];
        /* two bodies made inside each other, which contact.c moves apart whole: theirs
         * to take out (a triangle's normal is no way out of a body made inside another:
         * it pushes the point deeper in as often as out); kept as it is until they stop */
        if (wb__contacts_made(w, p, v[0])) continue;
        left[k] = 0;
        /* the side now and at the substep's start (the plane of the triangle then) */
        wb_real n[3], ln, s_prev, s_now;
        wb__tri_side(x, xp, p, v, n, &ln, &s_prev, &s_now);
        /* on its side and farther than r from the plane: from the triangle too */
        if (ln > 0 && s_now * s_prev >= 0 && fabs(s_now) > r * (1 + (wb_real)1e-9)) continue;
        const wb_real d2 = wb__tri_closest(xs, xa, xb, xc, b, q);
        const wb_real wp = wv[p], W = wp + b[0] * b[0] * wv[v[0]] + b[1] * b[1] * wv[v[1]] + b[2] * b[2] * wv[v[2]];
        if (W == 0) continue;
        v3_sub(d, xs, q);
        const wb_real dist = sqrt(d2);
        /* its normal and depth (through the plane over the face only: beside an edge or a
         * corner the plane's extension means nothing, a point in a valley between two
         * triangles is below each one's extension and still outside) */
        wb_real nn[3], depth;
        const int kind = wb__tri_normal(x, xp, p, v, n, ln, s_prev, s_now, b, d, d2, dist, r, r, nn, &depth);
        if (kind == 0) {
            /* in touch (left at r by the last substep, to round-off): counted, nothing to do */
            const wb_real rt = r * (1 + (wb_real)1e-9);
            if (d2 <= rt * rt) touching++;
            continue;
        }
        if (kind < 0) continue; /* on a degenerate triangle: no direction */
        if (!(depth > 0)) continue;
        /* the overlap it started the substep with: the same distance at x_prev (on the
         * side it was on then). Kept overlap goes out slowly, its push moving x_prev too;
         * the rest in full, its speed taken out in the velocity pass (contact.c) */
        wb_real bp[3], qp[3], slow, err;
        const wb_real dp2 = wb__tri_closest(&xp[3 * p], &xp[3 * v[0]], &xp[3 * v[1]], &xp[3 * v[2]], bp, qp);
        depth = wb__contact_depth(depth, r - sqrt(dp2), &lk, step, &slow, &err);
        left[k] = lk;
        if (!(depth > 0)) { touching++; continue; }
        const wb_real s = depth / W, se = slow / W;
        if (wp > 0) v3_madd(xs, nn, wp * s), v3_madd(&xp[3 * p], nn, wp * se);
        for (int i = 0; i < 3; i++)
            if (wv[v[i]] > 0 && b[i] != 0)
                v3_madd(&x[3 * v[i]], nn, -b[i] * wv[v[i]] * s), v3_madd(&xp[3 * v[i]], nn, -b[i] * wv[v[i]] * se);
        wb_real *o = &ad[TD * c->nact];
        v3_copy(o, b);
        v3_copy(o + 3, nn);
        o[6] = depth;
        o[7] = s / (h * h); /* the multiplier over h^2: newtons */
        o[8] = err;
        o[9] = 0; /* contact.c's friction pass sets it */
        act[c->nact++] = k;
    }
    c->last = c->nact + touching;
    return;
nomem:
    c->last = 0;
    wb__warn(w, "out of memory in triangle contacts; skipped this substep");
}

/* a contact's friction coefficient: the mean of the point's and the triangle's, the
 * triangle's weighted by b */
static wb_real tri_mu(const wb_real *cf, int32_t p, const int32_t *v, const wb_real *b)
{
    return (cf[p] + b[0] * cf[v[0]] + b[1] * cf[v[1]] + b[2] * cf[v[2]]) / 2;
}

/* ---- friction (contact.c's pass: the regimes and the budget per particle explained there) -- */
/* a contact sliding (p's speed relative to the triangle's point q = sum b_i x_i, along it,
 * more than one substep of dynamic friction takes away) gets mu in its record for the
 * velocity pass; the others add their normal impulse lambda = (depth - err) / W to the particles'
 * budgets: mu lambda for the point, b_i mu lambda for corner i, the normal correction's
 * weights */
void wb__tricontacts_load(wb_world *w, wb_real h, wb_real *load)
{
    wb_tricontacts *c = w->k.tc;
    const wb_model *m = &w->m;
    const wb_real *wv = m->w, *vel = w->s.v;
    for (int32_t a = 0; a < c->nact; a++) {
        const int32_t k = c->act[a], p = c->pt[2 * k], *v = &m->tri[3 * c->pt[2 * k + 1]];
        wb_real *b = &c->act_d[TD * a], *nn = b + 3;
        const wb_real mu = tri_mu(m->cfric, p, v, b);
        if (!(mu > 0)) continue;
        wb_real u[3];
        v3_copy(u, &vel[3 * p]);
        for (int i = 0; i < 3; i++) v3_madd(u, &vel[3 * v[i]], -b[i]);
        v3_madd(u, nn, -v3_dot(u, nn));
        if (v3_len(u) * h > mu * b[6]) {
            b[9] = mu;
            continue;
        }
        const wb_real W = wv[p] + b[0] * b[0] * wv[v[0]] + b[1] * b[1] * wv[v[1]] + b[2] * b[2] * wv[v[2]];
        const wb_real l = mu * (b[6] - b[8]) / W; /* the part that holds them apart (contact.c) */
        load[p] += l;
        for (int i = 0; i < 3; i++) load[v[i]] += b[i] * l;
    }
}

/* an at-rest contact: the slip of p against q this substep, tangential to n, undone with
 * the impulse |slip| / W (b_i of it for corner i), or the part of it that what is left of
 * every movable particle's budget allows */
void wb__tricontacts_static(wb_world *w, wb_real *load)
{
    const wb_tricontacts *c = w->k.tc;
    const wb_model *m = &w->m;
    wb_real *x = w->s.x;
    const wb_real *xp = w->s.x_prev, *wv = m->w;
    for (int32_t a = 0; a < c->nact; a++) {
        const int32_t k = c->act[a], p = c->pt[2 * k], *v = &m->tri[3 * c->pt[2 * k + 1]];
        const wb_real *b = &c->act_d[TD * a], *nn = b + 3;
        if (!(tri_mu(m->cfric, p, v, b) > 0) || b[9] > 0) continue;
        const wb_real W = wv[p] + b[0] * b[0] * wv[v[0]] + b[1] * b[1] * wv[v[1]] + b[2] * b[2] * wv[v[2]];
        wb_real slip[3];
        v3_sub(slip, &x[3 * p], &xp[3 * p]);
        for (int i = 0; i < 3; i++) v3_madd(slip, &x[3 * v[i]], -b[i]), v3_madd(slip, &xp[3 * v[i]], b[i]);
        v3_madd(slip, nn, -v3_dot(slip, nn));
        const wb_real need = v3_len(slip) / W;
        wb_real tau = need;
        if (wv[p] > 0 && load[p] < tau) tau = load[p];
        for (int i = 0; i < 3; i++)
            if (wv[v[i]] > 0 && b[i] > 0 && load[v[i]] < b[i] * tau) tau = load[v[i]] / b[i];
        if (!(tau > 0)) continue;
        const wb_real f = tau / need / W;
        load[p] -= tau;
        if (wv[p] > 0) v3_madd(&x[3 * p], slip, -f * wv[p]);
        for (int i = 0; i < 3; i++) {
            load[v[i]] -= b[i] * tau;
            if (wv[v[i]] > 0 && b[i] != 0) v3_madd(&x[3 * v[i]], slip, f * b[i] * wv[v[i]]);
        }
    }
}

/* after v = (x - x_prev)/h, as contact.c's pass: no speed made out of old overlap (at most
 * the separating speed there is), then no approach speed of p towards the triangle's
 * point left, then a sliding contact's dynamic friction on their relative tangential
 * speed, mu (depth - err) / h at most; each change split with the weights of the normal
 * correction */
void wb__tricontacts_velocity(wb_world *w, wb_real h)
{
    wb_tricontacts *c = w->k.tc;
    const wb_model *m = &w->m;
    wb_real *vel = w->s.v;
    const wb_real *wv = m->w;
    for (int32_t a = 0; a < c->nact; a++) {
        const int32_t k = c->act[a], p = c->pt[2 * k], *v = &m->tri[3 * c->pt[2 * k + 1]];
        const wb_real *b = &c->act_d[TD * a], *nn = b + 3;
        const wb_real W = wv[p] + b[0] * b[0] * wv[v[0]] + b[1] * b[1] * wv[v[1]] + b[2] * b[2] * wv[v[2]];
        if (!(b[8] > 0) || W == 0) continue;
        wb_real u[3];
        v3_copy(u, &vel[3 * p]);
        for (int i = 0; i < 3; i++) v3_madd(u, &vel[3 * v[i]], -b[i]);
        const wb_real un = v3_dot(u, nn), e = b[8] / h; /* the projection's push of err, as speed */
        const wb_real s = (e < un ? e : un) / W;
        if (!(s > 0)) continue;
        if (wv[p] > 0) v3_madd(&vel[3 * p], nn, -s * wv[p]);
        for (int i = 0; i < 3; i++)
            if (wv[v[i]] > 0 && b[i] != 0) v3_madd(&vel[3 * v[i]], nn, s * b[i] * wv[v[i]]);
    }
    for (int32_t a = 0; a < c->nact; a++) {
        const int32_t k = c->act[a], p = c->pt[2 * k], *v = &m->tri[3 * c->pt[2 * k + 1]];
        const wb_real *b = &c->act_d[TD * a], *nn = b + 3;
        const wb_real W = wv[p] + b[0] * b[0] * wv[v[0]] + b[1] * b[1] * wv[v[1]] + b[2] * b[2] * wv[v[2]];
        if (W == 0) continue;
        wb_real u[3];
        v3_copy(u, &vel[3 * p]);
        for (int i = 0; i < 3; i++) v3_madd(u, &vel[3 * v[i]], -b[i]);
        const wb_real un = v3_dot(u, nn);
        if (un < 0) {
            const wb_real s = un / W;
            if (wv[p] > 0) v3_madd(&vel[3 * p], nn, -s * wv[p]);
            for (int i = 0; i < 3; i++)
                if (wv[v[i]] > 0 && b[i] != 0) v3_madd(&vel[3 * v[i]], nn, s * b[i] * wv[v[i]]);
        }
        const wb_real mu = b[9];
        if (!(mu > 0)) continue;
        v3_madd(u, nn, -un); /* tangential: the normal change left it as it was */
        const wb_real ut = v3_len(u), dv = mu * (b[6] - b[8]) / h;
        if (!(ut > 0)) continue;
        /* change u by -min(dv, ut) u / ut */
        const wb_real f = (dv < ut ? dv : ut) / ut / W;
        if (wv[p] > 0) v3_madd(&vel[3 * p], u, -f * wv[p]);
        for (int i = 0; i < 3; i++)
            if (wv[v[i]] > 0 && b[i] != 0) v3_madd(&vel[3 * v[i]], u, f * b[i] * wv[v[i]]);
    }
}

/* ---- readout -------------------------------------------------------------------------------------------- */
int32_t wb_world_tri_contact_count(const wb_world *w) { return w->k.tc ? w->k.tc->nact : 0; }

wb_tri_contact wb_world_tri_contact_at(const wb_world *w, int32_t i)
{
    const wb_tricontacts *c = w->k.tc;
    wb_tri_contact out;
    memset(&out, 0, sizeof out);
    out.p = out.tri[0] = out.tri[1] = out.tri[2] = -1;
    if (i < 0 || i >= wb_world_tri_contact_count(w)) return out;
    const int32_t k = c->act[i];
    const wb_real *d = &c->act_d[TD * i];
    out.p = c->pt[2 * k];
    memcpy(out.tri, &w->m.tri[3 * c->pt[2 * k + 1]], sizeof out.tri);
    v3_copy(out.bary, d);
    v3_scale(out.normal, d + 3, -1); /* point -> triangle, as wb_contact's a -> b */
    out.depth = d[6];
    out.force = d[7];
    return out;
}
