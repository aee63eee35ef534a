/* narrow.c: the contact manifold between two shapes at poses, for rigid bodies. Pure
 * geometry: no world, no allocation.
 *
 * The pair table pairs[][] gives each ordered pair of shapes its routine. Shapes are
 * ranked plane < mesh < box < round (sphere and capsule are one kind: a segment with a
 * radius, shape.h's segment, a sphere's being a point); a pair given the other way round
 * is worked out swapped and flipped (normal negated, pa and pb exchanged).
 *   round-round  closest points of the two segments; parallel capsules give the two ends
 *                of their overlap, so a capsule lies on another without rocking
 *   box-round    the segment's point of least signed distance to the box (the box's
 *                signed distance is convex, so a golden-section search finds it); a
 *                capsule lying along a face gives the two ends of its part over the face
 *   box-box      SAT over the 15 axes, face axes preferred within a tolerance (so the
 *                manifold does not flicker between near-equal axes); face contact: the
 *                incident face clipped to the reference face's sides (Sutherland-
 *                Hodgman), the points below it kept, reduced to 4 (deepest, widest);
 *                edge-edge: the closest points of the two edges
 *   plane-X      the lowest points: sphere, capsule ends, box corners (up to 4)
 *   mesh-X       candidate points of X against the mesh through its tree: the sphere's
 *                centre; the capsule's ends and its points closest to nearby triangles;
 *                the box's corners, its edges' points closest to nearby triangles and the
 *                mesh vertices inside the box. The deepest gives the normal, the others
 *                are measured along it (one normal per manifold: where X straddles a
 *                crease the points whose own normals turn away more than ~37 degrees
 *                are left out; a mesh edge crossing a box face between the box's edges
 *                and vertices is not seen). A closed mesh has an inside (signed distance
 *                from the pseudo-normals, bvh.h); an open one has two sides and pushes X
 *                to the side X's centre is on. At most 4 points, from at most MESH_TRIS
 *                triangles near X.
 * Every point returned lies on A's surface (pa) and on B's (pb), depth = (pa - pb).n: a
 * capsule's point is the one of its cross-section (an end's hemisphere or the rim) farthest
 * along -n, so where the axis runs through a box (its deepest point a kink of the box's
 * distance) the depth is that cross-section's, under the nearest face. Boxes within the
 * margin but not overlapping sideways (edge to edge over a face axis) give none.
 * One file of some 1000 lines: the pairs share the shapes' helpers, and the contract
 * (RIGID.md) keeps the narrow phase to narrow.c. */
#include "core.h"
#include "bvh.h"
#include "narrow.h"

#define GOLDEN_ITERS 80
#define PARALLEL_SIN2 1e-6  /* capsules closer to parallel than 1e-3 rad give two points */
#define LIE_COS2 0.0625     /* a capsule within ~14 degrees of a box face lies on it */
#define MESH_COS 0.8        /* mesh points whose own normal turns away more are left out */
#define MESH_TRIS 512       /* triangles near a capsule or a box considered at most */
#define MESH_CANDS 96

/* ---- small helpers ----------------------------------------------------------------------- */
static void perp(const wb_real u[3], wb_real out[3]) /* a unit vector normal to u (any when u = 0) */
{
    wb_real e[3] = { 0, 0, 0 };
    const int k = fabs(u[0]) <= fabs(u[1]) && fabs(u[0]) <= fabs(u[2]) ? 0 : fabs(u[1]) <= fabs(u[2]) ? 1 : 2;
    e[k] = 1;
    v3_cross(out, u, e);
    const wb_real l = v3_len(out);
    if (l > 0) v3_scale(out, out, 1 / l);
    else v3_set(out, 0, 1, 0);
}

/* closest points of segments p1 + s d1 and p2 + t d2, s, t in [0, 1] (Ericson 5.1.9);
 * parallel segments get s = 0 first */
static void seg_closest(const wb_real p1[3], const wb_real q1[3], const wb_real p2[3], const wb_real q2[3],
                        wb_real *s, wb_real *t)
{
    wb_real d1[3], d2[3], r[3];
    v3_sub(d1, q1, p1);
    v3_sub(d2, q2, p2);
    v3_sub(r, p1, p2);
    const wb_real a = v3_dot(d1, d1), e = v3_dot(d2, d2), f = v3_dot(d2, r);
    if (!(a > 0) && !(e > 0)) { *s = *t = 0; return; }
    if (!(a > 0)) { *s = 0; *t = clampr(f / e, 0, 1); return; }
    const wb_real c = v3_dot(d1, r);
    if (!(e > 0)) { *t = 0; *s = clampr(-c / a, 0, 1); return; }
    const wb_real b = v3_dot(d1, d2), den = a * e - b * b;
    *s = den > 1e-14 * a * e ? clampr((b * f - c * e) / den, 0, 1) : 0;
    *t = (b * *s + f) / e;
    if (*t < 0) { *t = 0; *s = clampr(-c / a, 0, 1); }
    else if (*t > 1) { *t = 1; *s = clampr((b - c) / a, 0, 1); }
}

static void lerp3(wb_real o[3], const wb_real a[3], const wb_real b[3], wb_real t)
{
    for (int i = 0; i < 3; i++) o[i] = a[i] + (b[i] - a[i]) * t;
}

static void add_point(wb_manifold *m, const wb_real pa[3], const wb_real pb[3])
{
    if (m->n >= WB_MANIFOLD_MAX) return;
    wb_manifold_point *p = &m->pt[m->n++];
    v3_copy(p->pa, pa);
    v3_copy(p->pb, pb);
    wb_real d[3];
    v3_sub(d, pa, pb);
    p->depth = v3_dot(d, m->normal);
}

/* which of points p[0..n) to keep, at most 4: the deepest, the farthest from it, the one
 * making the largest triangle with those, the one adding most area to it (all seen
 * along the normal); returns how many, their indices in k */
static wb_real flat_d(const wb_manifold_point *p, const wb_manifold_point *o, const wb_real n[3], wb_real d[3])
{
    for (int i = 0; i < 3; i++) d[i] = 0.5 * (p->pa[i] + p->pb[i] - o->pa[i] - o->pb[i]);
    v3_madd(d, n, -v3_dot(d, n));
    return v3_dot(d, d);
}
static int pick4(const wb_manifold_point *p, int n, const wb_real nrm[3], int k[4])
{
    if (n <= 0) return 0;
    k[0] = 0;
    for (int i = 1; i < n; i++)
        if (p[i].depth > p[k[0]].depth) k[0] = i;
    wb_real best = -1, d[3], e[3], c[3];
    int m = 1;
    for (int i = 0; i < n; i++) { /* ties (within round-off) to the deeper */
        const wb_real dd = flat_d(&p[i], &p[k[0]], nrm, d);
        if (i != k[0] && (dd > best * (1 + 1e-9) || (dd >= best * (1 - 1e-9) && p[i].depth > p[k[1]].depth))) {
            best = dd;
            k[1] = i;
        }
    }
    if (best < 0) return m;
    const wb_real d01 = best;
    m = 2;
    best = 1e-8 * d01; /* a third point only off the line of the first two */
    wb_real sgn = 1;
    flat_d(&p[k[1]], &p[k[0]], nrm, d);
    for (int i = 0; i < n; i++) {
        if (i == k[0] || i == k[1]) continue;
        flat_d(&p[i], &p[k[0]], nrm, e);
        v3_cross(c, d, e);
        const wb_real ar = v3_dot(c, nrm), a2 = ar * ar / d01;
        if (a2 > best * (1 + 1e-9) || (m == 3 && a2 >= best * (1 - 1e-9) && p[i].depth > p[k[2]].depth)) {
            best = a2;
            k[2] = i;
            m = 3;
            sgn = ar < 0 ? -1 : 1;
        }
    }
    if (m < 3) return m;
    best = 0;
    for (int i = 0; i < n; i++) {
        if (i == k[0] || i == k[1] || i == k[2]) continue;
        wb_real added = 0;
        for (int j = 0; j < 3; j++) { /* the triangle's edges the point lies outside of */
            flat_d(&p[k[(j + 1) % 3]], &p[k[j]], nrm, d);
            flat_d(&p[i], &p[k[j]], nrm, e);
            v3_cross(c, d, e);
            const wb_real ar = sgn * v3_dot(c, nrm);
            if (ar < 0) added -= ar;
        }
        if (added > best * (1 + 1e-9) || (m == 4 && added >= best * (1 - 1e-9) && p[i].depth > p[k[3]].depth)) {
            best = added;
            k[3] = i;
            m = 4;
        }
    }
    return m;
}

static void reduce4(wb_manifold *m)
{
    if (m->n <= 4) return;
    int k[4];
    const int n = pick4(m->pt, m->n, m->normal, k);
    wb_manifold_point keep[4];
    for (int j = 0; j < n; j++) keep[j] = m->pt[k[j]];
    memcpy(m->pt, keep, (size_t)n * sizeof keep[0]);
    m->n = n;
}

/* ---- round shapes (sphere, capsule) -------------------------------------------------------- */
typedef struct round_s { wb_real a[3], b[3], r; } round_s; /* world segment, radius */

static void round_make(const wb_cshape *s, const wb_real p[3], const wb_real q[4], round_s *o)
{
    wb__shape(s->shape)->segment(s, p, q, o->a, o->b);
    o->r = s->radius;
}

/* the surface point farthest along unit m of the cross-section at parameter t: on an
 * end's hemisphere when it faces m, else on the rim (the circle normal to the axis) */
static void round_support(const round_s *s, wb_real t, const wb_real m[3], wb_real out[3])
{
    wb_real u[3], dir[3];
    v3_sub(u, s->b, s->a);
    v3_copy(dir, m);
    const wb_real uu = v3_dot(u, u);
    if (uu > 0) {
        const wb_real mu = v3_dot(m, u);
        if ((t > 0 && t < 1) || (t <= 0 && mu > 0) || (t >= 1 && mu < 0)) {
            v3_madd(dir, u, -mu / uu);
            const wb_real l = v3_len(dir);
            if (l > 1e-12) v3_scale(dir, dir, 1 / l);
            else perp(u, dir);
        }
    }
    lerp3(out, s->a, s->b, t);
    v3_madd(out, dir, s->r);
}

static int round_round(const round_s *A, const round_s *B, wb_real margin, wb_manifold *m)
{
    wb_real s, t, ca[3], cb[3], d[3], ua[3], ub[3];
    seg_closest(A->a, A->b, B->a, B->b, &s, &t);
    lerp3(ca, A->a, A->b, s);
    lerp3(cb, B->a, B->b, t);
    v3_sub(d, cb, ca);
    const wb_real dist = v3_len(d);
    if (dist - A->r - B->r > margin) return 0;
    v3_sub(ua, A->b, A->a);
    v3_sub(ub, B->b, B->a);
    const wb_real la = v3_dot(ua, ua), lb = v3_dot(ub, ub);
    wb_real x[3];
    v3_cross(x, ua, ub);
    const int parallel = la > 0 && lb > 0 && v3_dot(x, x) <= PARALLEL_SIN2 * la * lb;
    const wb_real scale = sqrt(fmax(la, lb)) + A->r + B->r;
    if (dist > 1e-12 * scale) {
        v3_scale(m->normal, d, 1 / dist);
    } else { /* touching axes: normal to both, towards B's centre */
        wb_real cd[3], mida[3], midb[3];
        lerp3(mida, A->a, A->b, 0.5);
        lerp3(midb, B->a, B->b, 0.5);
        v3_sub(cd, midb, mida);
        if (la > 0 && lb > 0 && !parallel) v3_copy(m->normal, x);
        else if (la > 0 || lb > 0) {
            const wb_real *u = la > 0 ? ua : ub;
            v3_copy(m->normal, cd);
            v3_madd(m->normal, u, -v3_dot(cd, u) / v3_dot(u, u));
            if (!(v3_len(m->normal) > 1e-12 * scale)) perp(u, m->normal);
        } else v3_set(m->normal, 0, 1, 0);
        const wb_real l = v3_len(m->normal);
        v3_scale(m->normal, m->normal, (v3_dot(m->normal, cd) < 0 ? -1 : 1) / l);
    }
    wb_real nn[3], pa[3], pb[3];
    v3_scale(nn, m->normal, -1);
    m->n = 0;
    if (parallel) { /* the ends of the overlap of B's projection on A's axis */
        wb_real t0 = v3_dot((wb_real[3]){ B->a[0] - A->a[0], B->a[1] - A->a[1], B->a[2] - A->a[2] }, ua) / la;
        wb_real t1 = v3_dot((wb_real[3]){ B->b[0] - A->a[0], B->b[1] - A->a[1], B->b[2] - A->a[2] }, ua) / la;
        if (t0 > t1) { const wb_real tmp = t0; t0 = t1; t1 = tmp; }
        t0 = fmax(t0, 0);
        t1 = fmin(t1, 1);
        if ((t1 - t0) * sqrt(la) > 1e-9 * scale) {
            for (int e = 0; e < 2; e++) {
                const wb_real ta = e ? t1 : t0;
                wb_real sa[3], u;
                lerp3(sa, A->a, A->b, ta);
                v3_sub(d, sa, B->a);
                u = clampr(v3_dot(d, ub) / lb, 0, 1);
                round_support(A, ta, m->normal, pa);
                round_support(B, u, nn, pb);
                v3_sub(d, pa, pb);
                if (v3_dot(d, m->normal) > -margin) add_point(m, pa, pb);
            }
            if (m->n) return m->n;
        }
    }
    round_support(A, s, m->normal, pa);
    round_support(B, t, nn, pb);
    add_point(m, pa, pb);
    return m->n;
}

/* ---- boxes --------------------------------------------------------------------------------- */
typedef struct obox { wb_real c[3], ax[3][3], h[3]; } obox; /* centre, world axes, half sizes */

static void box_make(const wb_cshape *s, const wb_real p[3], const wb_real q[4], obox *o)
{
    v3_copy(o->c, p);
    for (int i = 0; i < 3; i++) {
        wb_real e[3] = { 0, 0, 0 };
        e[i] = 1;
        q_rotate(q, e, o->ax[i]);
        o->h[i] = s->half[i];
    }
}
static void box_local(const obox *o, const wb_real x[3], wb_real l[3])
{
    wb_real d[3];
    v3_sub(d, x, o->c);
    for (int i = 0; i < 3; i++) l[i] = v3_dot(d, o->ax[i]);
}
static void box_world(const obox *o, const wb_real l[3], wb_real x[3])
{
    v3_copy(x, o->c);
    for (int i = 0; i < 3; i++) v3_madd(x, o->ax[i], l[i]);
}
static void box_dir(const obox *o, const wb_real l[3], wb_real x[3])
{
    v3_set(x, 0, 0, 0);
    for (int i = 0; i < 3; i++) v3_madd(x, o->ax[i], l[i]);
}

/* signed distance of local point l to the box; nl: outward unit normal, ql: closest
 * surface point (inside: on the nearest face) */
static wb_real box_sd(const wb_real h[3], const wb_real l[3], wb_real nl[3], wb_real ql[3])
{
    wb_real o[3];
    int out = 0;
    for (int i = 0; i < 3; i++) {
        ql[i] = clampr(l[i], -h[i], h[i]);
        o[i] = l[i] - ql[i];
        out |= o[i] != 0;
    }
    const wb_real d = out ? v3_len(o) : 0;
    if (d > 0) { /* (an outside distance that underflows counts as on the surface) */
        v3_scale(nl, o, 1 / d);
        return d;
    }
    v3_copy(ql, l);
    int k = 0;
    for (int i = 1; i < 3; i++)
        if (fabs(l[i]) - h[i] > fabs(l[k]) - h[k]) k = i;
    v3_set(nl, 0, 0, 0);
    nl[k] = l[k] < 0 ? -1 : 1;
    ql[k] = nl[k] * h[k];
    return fabs(l[k]) - h[k];
}

static wb_real box_sd_at(const obox *o, const wb_real la[3], const wb_real lb[3], wb_real t)
{
    wb_real l[3], nl[3], ql[3];
    lerp3(l, la, lb, t);
    return box_sd(o->h, l, nl, ql);
}

static void box_corner(const obox *o, int k, wb_real x[3])
{
    const wb_real l[3] = { k & 1 ? o->h[0] : -o->h[0], k & 2 ? o->h[1] : -o->h[1], k & 4 ? o->h[2] : -o->h[2] };
    box_world(o, l, x);
}

static int box_round(const obox *A, const round_s *B, wb_real margin, wb_manifold *m)
{
    wb_real la[3], lb[3], u[3];
    box_local(A, B->a, la);
    box_local(A, B->b, lb);
    v3_sub(u, lb, la);
    const wb_real uu = v3_dot(u, u);
    wb_real t = 0;
    if (uu > 0) { /* golden section on the convex signed distance, then the ends */
        const wb_real g = 0.5 * (sqrt(5.0) - 1);
        wb_real lo = 0, hi = 1, x1 = hi - g * (hi - lo), x2 = lo + g * (hi - lo);
        wb_real f1 = box_sd_at(A, la, lb, x1), f2 = box_sd_at(A, la, lb, x2);
        for (int it = 0; it < GOLDEN_ITERS; it++) {
            if (f1 <= f2) { hi = x2; x2 = x1; f2 = f1; x1 = hi - g * (hi - lo); f1 = box_sd_at(A, la, lb, x1); }
            else { lo = x1; x1 = x2; f1 = f2; x2 = lo + g * (hi - lo); f2 = box_sd_at(A, la, lb, x2); }
        }
        t = 0.5 * (lo + hi);
        wb_real ft = box_sd_at(A, la, lb, t);
        const wb_real f0 = box_sd_at(A, la, lb, 0), fe = box_sd_at(A, la, lb, 1);
        /* an end when it ties: its hemisphere then gives the full radius */
        const wb_real tie = 1e-12 * (1 + fabs(ft));
        if (f0 <= ft + tie) { t = 0; ft = f0; }
        if (fe <= ft + tie) t = 1;
    }
    wb_real c[3], nl[3], ql[3], pa[3], pb[3], nn[3];
    lerp3(c, la, lb, t);
    const wb_real sd = box_sd(A->h, c, nl, ql);
    if (sd - B->r > margin) return 0;
    box_dir(A, nl, m->normal);
    v3_scale(nn, m->normal, -1);
    m->n = 0;
    int k = -1, faces = 0;
    for (int i = 0; i < 3; i++)
        if (nl[i] != 0) { k = i; faces++; }
    if (faces == 1 && uu > 0 && u[k] * u[k] < LIE_COS2 * uu) {
        /* lying along face k: the part of the segment over the face, both its ends */
        wb_real t0 = 0, t1 = 1;
        for (int j = 0; j < 3; j++) {
            if (j == k) continue;
            if (u[j] == 0) {
                if (fabs(la[j]) > A->h[j]) t1 = -1;
                continue;
            }
            wb_real s0 = (-A->h[j] - la[j]) / u[j], s1 = (A->h[j] - la[j]) / u[j];
            if (s0 > s1) { const wb_real tmp = s0; s0 = s1; s1 = tmp; }
            t0 = fmax(t0, s0);
            t1 = fmin(t1, s1);
        }
        if (t1 - t0 > 1e-9) {
            for (int e = 0; e < 2; e++) {
                const wb_real te = e ? t1 : t0;
                wb_real el[3], d[3];
                lerp3(el, la, lb, te);
                for (int j = 0; j < 3; j++) if (j != k) el[j] = clampr(el[j], -A->h[j], A->h[j]);
                el[k] = nl[k] * A->h[k];
                box_world(A, el, pa);
                round_support(B, te, nn, pb);
                v3_sub(d, pa, pb);
                if (v3_dot(d, m->normal) > -margin) add_point(m, pa, pb);
            }
            if (m->n) return m->n;
        }
    }
    box_world(A, ql, pa);
    round_support(B, t, nn, pb);
    add_point(m, pa, pb);
    return m->n;
}

/* Sutherland-Hodgman: keep the part of polygon (x, n) with (p - o).d <= h */
static int clip(wb_real (*x)[3], int n, const wb_real o[3], const wb_real d[3], wb_real h, wb_real (*out)[3])
{
    int k = 0;
    for (int i = 0; i < n; i++) {
        const wb_real *p = x[i], *q = x[(i + 1) % n];
        wb_real dp[3], dq[3];
        v3_sub(dp, p, o);
        v3_sub(dq, q, o);
        const wb_real sp = v3_dot(dp, d) - h, sq = v3_dot(dq, d) - h;
        if (sp <= 0) v3_copy(out[k++], p);
        if ((sp < 0 && sq > 0) || (sp > 0 && sq < 0)) lerp3(out[k++], p, q, sp / (sp - sq));
    }
    return k;
}

/* face contact: reference face i of R (outward normal m->normal, set), incident box I;
 * points: pa on R's face, pb on I's incident face */
static void box_face(const obox *R, int i, const obox *I, wb_real margin, wb_manifold *m)
{
    const wb_real *n = m->normal;
    int j = 0;
    for (int k = 1; k < 3; k++)
        if (fabs(v3_dot(I->ax[k], n)) > fabs(v3_dot(I->ax[j], n))) j = k;
    const wb_real sj = v3_dot(I->ax[j], n) > 0 ? -1 : 1; /* incident face faces R */
    const int j1 = (j + 1) % 3, j2 = (j + 2) % 3;
    wb_real poly[2][8][3];
    static const int sg[4][2] = { { 1, 1 }, { -1, 1 }, { -1, -1 }, { 1, -1 } };
    for (int v = 0; v < 4; v++) {
        v3_copy(poly[0][v], I->c);
        v3_madd(poly[0][v], I->ax[j], sj * I->h[j]);
        v3_madd(poly[0][v], I->ax[j1], sg[v][0] * I->h[j1]);
        v3_madd(poly[0][v], I->ax[j2], sg[v][1] * I->h[j2]);
    }
    int np = 4, cur = 0;
    for (int k = 1; k < 3 && np > 0; k++) {
        const int a = (i + k) % 3;
        wb_real neg[3];
        v3_scale(neg, R->ax[a], -1);
        np = clip(poly[cur], np, R->c, R->ax[a], R->h[a], poly[1 - cur]);
        cur = 1 - cur;
        np = clip(poly[cur], np, R->c, neg, R->h[a], poly[1 - cur]);
        cur = 1 - cur;
    }
    m->n = 0;
    for (int v = 0; v < np; v++) {
        wb_real d[3], pa[3];
        v3_sub(d, poly[cur][v], R->c);
        const wb_real sep = v3_dot(d, n) - R->h[i];
        if (!(sep < margin)) continue;
        v3_copy(pa, poly[cur][v]);
        v3_madd(pa, n, -sep);
        add_point(m, pa, poly[cur][v]);
    }
    reduce4(m);
}

static void flip(wb_manifold *m)
{
    v3_scale(m->normal, m->normal, -1);
    for (int i = 0; i < m->n; i++) {
        wb_real t[3];
        v3_copy(t, m->pt[i].pa);
        v3_copy(m->pt[i].pa, m->pt[i].pb);
        v3_copy(m->pt[i].pb, t);
    }
}

static int box_box(const obox *A, const obox *B, wb_real margin, wb_manifold *m)
{
    wb_real d[3];
    v3_sub(d, B->c, A->c);
    wb_real s_face[2] = { -INFINITY, -INFINITY }, s_edge = -INFINITY, edge_n[3] = { 0, 1, 0 };
    int face[2] = { 0, 0 }, ei = -1, ej = -1;
    wb_real hmin = INFINITY;
    for (int i = 0; i < 3; i++) hmin = fmin(hmin, fmin(A->h[i], B->h[i]));
    for (int b = 0; b < 2; b++) { /* face axes of A, then of B */
        const obox *P = b ? B : A, *Q = b ? A : B;
        for (int i = 0; i < 3; i++) {
            const wb_real *L = P->ax[i];
            wb_real rq = 0;
            for (int k = 0; k < 3; k++) rq += Q->h[k] * fabs(v3_dot(Q->ax[k], L));
            const wb_real s = fabs(v3_dot(d, L)) - P->h[i] - rq;
            if (s > margin) return 0;
            if (s > s_face[b]) { s_face[b] = s; face[b] = i; }
        }
    }
    for (int i = 0; i < 3; i++)
        for (int j = 0; j < 3; j++) {
            wb_real L[3];
            v3_cross(L, A->ax[i], B->ax[j]);
            const wb_real l = v3_len(L);
            if (l < 1e-6) continue; /* parallel edges: the face axes cover them */
            v3_scale(L, L, 1 / l);
            wb_real ra = 0, rb = 0;
            for (int k = 0; k < 3; k++) {
                ra += A->h[k] * fabs(v3_dot(A->ax[k], L));
                rb += B->h[k] * fabs(v3_dot(B->ax[k], L));
            }
            const wb_real s = fabs(v3_dot(d, L)) - ra - rb;
            if (s > margin) return 0;
            if (s > s_edge) { s_edge = s; ei = i; ej = j; v3_copy(edge_n, L); }
        }
    /* prefer A's face, then B's, then an edge pair: each must beat the last by a margin */
    const wb_real tolr = 0.05, tola = 1e-3 * hmin;
    const int useb = s_face[1] > s_face[0] + tolr * fabs(s_face[0]) + tola;
    const wb_real sf = useb ? s_face[1] : s_face[0];
    if (ei >= 0 && s_edge > sf + tolr * fabs(sf) + tola) {
        if (v3_dot(edge_n, d) < 0) v3_scale(edge_n, edge_n, -1);
        v3_copy(m->normal, edge_n);
        wb_real ea[3], eb[3], a0[3], a1[3], b0[3], b1[3], s, t, pa[3], pb[3];
        v3_copy(ea, A->c);
        v3_copy(eb, B->c);
        for (int k = 0; k < 3; k++) {
            if (k != ei) v3_madd(ea, A->ax[k], (v3_dot(A->ax[k], edge_n) < 0 ? -1 : 1) * A->h[k]);
            if (k != ej) v3_madd(eb, B->ax[k], (v3_dot(B->ax[k], edge_n) > 0 ? -1 : 1) * B->h[k]);
        }
        v3_copy(a0, ea); v3_madd(a0, A->ax[ei], -A->h[ei]);
        v3_copy(a1, ea); v3_madd(a1, A->ax[ei], A->h[ei]);
        v3_copy(b0, eb); v3_madd(b0, B->ax[ej], -B->h[ej]);
        v3_copy(b1, eb); v3_madd(b1, B->ax[ej], B->h[ej]);
        seg_closest(a0, a1, b0, b1, &s, &t);
        lerp3(pa, a0, a1, s);
        lerp3(pb, b0, b1, t);
        m->n = 0;
        v3_sub(d, pa, pb);
        if (v3_dot(d, m->normal) > -margin) add_point(m, pa, pb);
        return m->n;
    }
    const obox *R = useb ? B : A, *I = useb ? A : B;
    const int i = face[useb];
    v3_copy(m->normal, R->ax[i]);
    if (v3_dot(R->ax[i], d) * (useb ? -1 : 1) < 0) v3_scale(m->normal, m->normal, -1);
    box_face(R, i, I, margin, m);
    if (useb) flip(m);
    return m->n;
}

/* ---- planes ---------------------------------------------------------------------------------- */
static void plane_normal(const wb_cshape *s, const wb_real q[4], wb_real n[3])
{
    q_rotate(q, s->n, n);
    const wb_real l = v3_len(n);
    if (l > 0) v3_scale(n, n, 1 / l);
    else v3_set(n, 0, 1, 0);
}

/* B's point x (on its surface) against the plane (o, m->normal) */
static void plane_point(const wb_real o[3], const wb_real x[3], wb_real margin, wb_manifold *m)
{
    wb_real d[3], pa[3];
    v3_sub(d, x, o);
    const wb_real h = v3_dot(d, m->normal);
    if (!(h < margin)) return;
    v3_copy(pa, x);
    v3_madd(pa, m->normal, -h);
    add_point(m, pa, x);
}

static int plane_round(const wb_real o[3], const round_s *B, wb_real margin, wb_manifold *m)
{
    wb_real nn[3], x[3];
    v3_scale(nn, m->normal, -1);
    const int ends = memcmp(B->a, B->b, sizeof B->a) ? 2 : 1;
    for (int e = 0; e < ends; e++) {
        round_support(B, e, nn, x);
        plane_point(o, x, margin, m);
    }
    return m->n;
}

static int plane_box(const wb_real o[3], const obox *B, wb_real margin, wb_manifold *m)
{
    wb_real h[8];
    int idx[8];
    for (int k = 0; k < 8; k++) {
        wb_real x[3], d[3];
        box_corner(B, k, x);
        v3_sub(d, x, o);
        h[k] = v3_dot(d, m->normal);
        idx[k] = k;
    }
    for (int a = 1; a < 8; a++) /* lowest first */
        for (int b = a; b > 0 && h[idx[b]] < h[idx[b - 1]]; b--) { const int t = idx[b]; idx[b] = idx[b - 1]; idx[b - 1] = t; }
    for (int k = 0; k < 4; k++) {
        wb_real x[3];
        box_corner(B, idx[k], x);
        plane_point(o, x, margin, m);
    }
    return m->n;
}

/* ---- meshes ---------------------------------------------------------------------------------- */
typedef struct meshq {
    const wb_colmesh *cm;
    const wb_real *p, *q;  /* pose */
    wb_real side;          /* +1, or for an open mesh -1 when B is behind its pseudo-normals */
    wb_real behind;        /* open mesh: how far B's points may be past the sheet (B's size) */
} meshq;

/* signed distance of world point x to the mesh: INFINITY when farther than reach from
 * the tree's box; n: world unit normal out of the mesh (towards B), c: closest point */
static wb_real mesh_sd(const meshq *M, const wb_real x[3], wb_real reach, wb_real n[3], wb_real c[3])
{
    wb_real u[3], l[3], cl[3], pn[3], nl[3];
    v3_sub(u, x, M->p);
    q_rotate_inv(M->q, u, l);
    const wb_bvh_node *root = &M->cm->nodes[0];
    reach += M->behind;
    for (int k = 0; k < 3; k++)
        if (!(l[k] >= root->lo[k] - reach && l[k] <= root->hi[k] + reach)) return INFINITY;
    int32_t t;
    int region;
    const wb_real d = sqrt(wb__colmesh_closest(M->cm, l, cl, &t, &region));
    if (t < 0) return INFINITY;
    wb__colmesh_pseudo_normal(M->cm, t, region, pn);
    v3_sub(u, l, cl);
    const wb_real sg = (v3_dot(u, pn) < 0 ? -1 : 1) * M->side, lp = v3_len(pn);
    if (d > 1e-12 * (1 + v3_len(cl))) v3_scale(nl, u, sg / d);
    else if (lp > 0) v3_scale(nl, pn, M->side / lp); /* on the surface: its outward side */
    else v3_set(nl, 0, 1, 0);
    q_rotate(M->q, nl, n);
    q_rotate(M->q, cl, c);
    v3_add(c, c, M->p);
    return sg * d;
}

/* triangle t's box misses [lo, hi] (mesh frame) */
static int tri_apart(const wb_colmesh *cm, int32_t t, const wb_real lo[3], const wb_real hi[3])
{
    for (int k = 0; k < 3; k++) {
        wb_real a = INFINITY, b = -INFINITY;
        for (int v = 0; v < 3; v++) {
            const wb_real x = cm->v[3 * cm->tri[3 * t + v] + k];
            a = fmin(a, x);
            b = fmax(b, x);
        }
        if (a > hi[k] || b < lo[k]) return 1;
    }
    return 0;
}

/* triangles whose boxes overlap [lo, hi] (mesh frame), at most cap */
static int mesh_tris(const wb_colmesh *cm, const wb_real lo[3], const wb_real hi[3], int32_t *out, int cap)
{
    int32_t stack[128];
    int sp = 0, n = 0;
    stack[sp++] = 0;
    while (sp > 0 && n < cap) {
        const wb_bvh_node *nd = &cm->nodes[stack[--sp]];
        int apart = 0;
        for (int k = 0; k < 3; k++) apart |= nd->lo[k] > hi[k] || nd->hi[k] < lo[k];
        if (apart) continue;
        if (nd->count == 0) {
            if (sp + 2 <= 128) { stack[sp++] = nd->left + 1; stack[sp++] = nd->left; }
            continue;
        }
        for (int32_t j = 0; j < nd->count && n < cap; j++) {
            const int32_t t = cm->order[nd->left + j];
            if (!tri_apart(cm, t, lo, hi)) out[n++] = t;
        }
    }
    return n;
}

/* the parameter of segment s0 s1's point closest to triangle v (mesh frame) */
static wb_real seg_tri(const wb_real s0[3], const wb_real s1[3], const wb_colmesh *cm, int32_t t)
{
    const wb_real *v[3] = { &cm->v[3 * cm->tri[3 * t]], &cm->v[3 * cm->tri[3 * t + 1]], &cm->v[3 * cm->tri[3 * t + 2]] };
    wb_real c[3], x[3], y[3], d[3], n[3], e1[3], e2[3], best, tb = 0, s, u;
    int region;
    best = wb__closest_on_triangle(s0, v[0], v[1], v[2], c, &region);
    const wb_real d1 = wb__closest_on_triangle(s1, v[0], v[1], v[2], c, &region);
    if (d1 < best) { best = d1; tb = 1; }
    for (int k = 0; k < 3; k++) {
        seg_closest(s0, s1, v[k], v[(k + 1) % 3], &s, &u);
        lerp3(x, s0, s1, s);
        lerp3(y, v[k], v[(k + 1) % 3], u);
        v3_sub(d, x, y);
        if (v3_dot(d, d) < best) { best = v3_dot(d, d); tb = s; }
    }
    /* the segment through the triangle */
    v3_sub(e1, v[1], v[0]);
    v3_sub(e2, v[2], v[0]);
    v3_cross(n, e1, e2);
    v3_sub(d, s0, v[0]);
    const wb_real h0 = v3_dot(d, n);
    v3_sub(d, s1, v[0]);
    const wb_real h1 = v3_dot(d, n);
    if (h0 != h1 && ((h0 <= 0 && h1 >= 0) || (h0 >= 0 && h1 <= 0))) {
        const wb_real tt = h0 / (h0 - h1);
        lerp3(x, s0, s1, tt);
        int in = 1;
        for (int k = 0; k < 3; k++) {
            v3_sub(e1, v[(k + 1) % 3], v[k]);
            v3_sub(e2, x, v[k]);
            v3_cross(d, e1, e2);
            in &= v3_dot(d, n) >= 0;
        }
        if (in) tb = tt;
    }
    return tb;
}

typedef struct mcand { wb_manifold_point p; wb_real n[3]; } mcand;
typedef struct mcands { int n; wb_real eps2; mcand c[MESH_CANDS]; } mcands;

/* a candidate point pair with its own normal; the same pair twice is kept once, and when
 * full the shallowest goes */
static void cand_add(mcands *cs, const wb_real pa[3], const wb_real pb[3], const wb_real n[3])
{
    wb_real d[3], e[3];
    v3_sub(d, pa, pb);
    const wb_real depth = v3_dot(d, n);
    int slot = cs->n, low = 0;
    for (int i = 0; i < cs->n; i++) {
        v3_sub(d, cs->c[i].p.pa, pa);
        v3_sub(e, cs->c[i].p.pb, pb);
        if (v3_dot(d, d) <= cs->eps2 && v3_dot(e, e) <= cs->eps2) return;
        if (cs->c[i].p.depth < cs->c[low].p.depth) low = i;
    }
    if (slot == MESH_CANDS) {
        if (!(depth > cs->c[low].p.depth)) return;
        slot = low;
    } else cs->n++;
    v3_copy(cs->c[slot].p.pa, pa);
    v3_copy(cs->c[slot].p.pb, pb);
    v3_copy(cs->c[slot].n, n);
    cs->c[slot].p.depth = depth;
}

/* the axis point at t of round B against the mesh */
static void cand_round(const meshq *M, const round_s *B, wb_real t, wb_real margin, mcands *cs)
{
    wb_real x[3], n[3], c[3], nn[3], pb[3];
    lerp3(x, B->a, B->b, t);
    const wb_real sd = mesh_sd(M, x, B->r + margin, n, c);
    if (!(sd - B->r < margin)) return;
    v3_scale(nn, n, -1);
    round_support(B, t, nn, pb);
    cand_add(cs, c, pb, n);
}

/* a point x of the box's surface against the mesh */
static void cand_box(const meshq *M, const wb_real x[3], wb_real margin, mcands *cs)
{
    wb_real n[3], c[3];
    const wb_real sd = mesh_sd(M, x, margin, n, c);
    if (sd < margin) cand_add(cs, c, x, n);
}

/* local box [lo, hi] of world points x[0..n) in the mesh frame, grown by g */
static void local_bounds(const meshq *M, const wb_real (*x)[3], int n, wb_real g, wb_real lo[3], wb_real hi[3])
{
    for (int i = 0; i < n; i++) {
        wb_real u[3], l[3];
        v3_sub(u, x[i], M->p);
        q_rotate_inv(M->q, u, l);
        for (int k = 0; k < 3; k++) {
            if (i == 0 || l[k] < lo[k]) lo[k] = l[k];
            if (i == 0 || l[k] > hi[k]) hi[k] = l[k];
        }
    }
    for (int k = 0; k < 3; k++) { lo[k] -= g; hi[k] += g; }
}

static void to_local(const meshq *M, const wb_real x[3], wb_real l[3])
{
    wb_real u[3];
    v3_sub(u, x, M->p);
    q_rotate_inv(M->q, u, l);
}

/* a new parameter (not within 1e-6 of one in t[0..*n)), remembered while there is room */
static int fresh_t(wb_real *t, int *n, int cap, wb_real x)
{
    for (int i = 0; i < *n; i++)
        if (fabs(t[i] - x) < 1e-6) return 0;
    if (*n < cap) t[(*n)++] = x;
    return 1;
}

static void mesh_round(const meshq *M, const round_s *B, wb_real margin, mcands *cs)
{
    cand_round(M, B, 0, margin, cs);
    if (!memcmp(B->a, B->b, sizeof B->a)) return;
    cand_round(M, B, 1, margin, cs);
    wb_real ends[2][3], la[3], lb[3], lo[3], hi[3], tried[32];
    int32_t tris[MESH_TRIS];
    int nt = 2;
    tried[0] = 0;
    tried[1] = 1;
    v3_copy(ends[0], B->a);
    v3_copy(ends[1], B->b);
    local_bounds(M, (const wb_real (*)[3])ends, 2, B->r + margin, lo, hi);
    to_local(M, B->a, la);
    to_local(M, B->b, lb);
    const int n = mesh_tris(M->cm, lo, hi, tris, MESH_TRIS);
    for (int i = 0; i < n; i++) {
        const wb_real t = seg_tri(la, lb, M->cm, tris[i]);
        if (fresh_t(tried, &nt, 32, t)) cand_round(M, B, t, margin, cs);
    }
}

static void mesh_box(const meshq *M, const obox *B, wb_real margin, mcands *cs)
{
    wb_real x[8][3], lo[3], hi[3], l[8][3];
    int32_t tris[MESH_TRIS];
    for (int k = 0; k < 8; k++) {
        box_corner(B, k, x[k]);
        cand_box(M, x[k], margin, cs);
        to_local(M, x[k], l[k]);
    }
    local_bounds(M, (const wb_real (*)[3])x, 8, margin, lo, hi);
    const int n = mesh_tris(M->cm, lo, hi, tris, MESH_TRIS);
    /* mesh vertices in the box */
    for (int i = 0; i < n; i++)
        for (int v = 0; v < 3; v++) {
            wb_real vw[3], bl[3], nl[3], ql[3], pb[3], nb[3];
            q_rotate(M->q, &M->cm->v[3 * M->cm->tri[3 * tris[i] + v]], vw);
            v3_add(vw, vw, M->p);
            box_local(B, vw, bl);
            if (!(box_sd(B->h, bl, nl, ql) < margin)) continue;
            box_world(B, ql, pb);
            box_dir(B, nl, nb);
            v3_scale(nb, nb, -1);
            cand_add(cs, vw, pb, nb);
        }
    /* the box's edges against the triangles near each */
    for (int ax = 0; ax < 3; ax++)
        for (int k = 0; k < 8; k++) {
            if (k & (1 << ax)) continue;
            const int k2 = k | (1 << ax);
            wb_real elo[3], ehi[3], tried[8];
            int nt = 0;
            for (int j = 0; j < 3; j++) {
                elo[j] = fmin(l[k][j], l[k2][j]) - margin;
                ehi[j] = fmax(l[k][j], l[k2][j]) + margin;
            }
            for (int i = 0; i < n; i++) {
                if (tri_apart(M->cm, tris[i], elo, ehi)) continue;
                const wb_real t = seg_tri(l[k], l[k2], M->cm, tris[i]);
                if (!(t > 0 && t < 1) || !fresh_t(tried, &nt, 8, t)) continue;
                wb_real e[3];
                lerp3(e, x[k], x[k2], t);
                cand_box(M, e, margin, cs);
            }
        }
}

static void mesh_shape(const wb_colmesh *cm, const wb_real p[3], const wb_real q[4], const wb_cshape *b,
                       const wb_real pb[3], const wb_real qb[4], wb_real margin, wb_manifold *m, int box)
{
    if (cm->nt <= 0 || !cm->nodes) return;
    meshq M = { cm, p, q, 1, 0 };
    if (!cm->closed) { /* the side B's centre is on */
        wb_real u[3], l[3], cl[3], pn[3];
        int32_t t;
        int region;
        to_local(&M, pb, l);
        wb__colmesh_closest(cm, l, cl, &t, &region);
        if (t >= 0) {
            wb__colmesh_pseudo_normal(cm, t, region, pn);
            v3_sub(u, l, cl);
            if (v3_dot(u, pn) < 0) M.side = -1;
        }
    }
    mcands cs;
    cs.n = 0;
    round_s rs;
    obox bx;
    wb_real size;
    if (box) {
        box_make(b, pb, qb, &bx);
        size = v3_len(bx.h);
    } else {
        round_make(b, pb, qb, &rs);
        wb_real u[3];
        v3_sub(u, rs.b, rs.a);
        size = v3_len(u) + rs.r;
    }
    cs.eps2 = 1e-18 * size * size;
    if (!cm->closed) M.behind = 2 * size;
    if (box) mesh_box(&M, &bx, margin, &cs);
    else mesh_round(&M, &rs, margin, &cs);
    if (cs.n == 0) return;
    /* the deepest gives the normal; the others are measured along it */
    int best = 0;
    for (int i = 1; i < cs.n; i++)
        if (cs.c[i].p.depth > cs.c[best].p.depth) best = i;
    v3_copy(m->normal, cs.c[best].n);
    wb_manifold_point pts[MESH_CANDS];
    int np = 0;
    for (int i = 0; i < cs.n; i++) {
        if (v3_dot(cs.c[i].n, m->normal) < MESH_COS) continue;
        wb_real d[3];
        pts[np] = cs.c[i].p;
        v3_sub(d, pts[np].pa, pts[np].pb);
        pts[np].depth = v3_dot(d, m->normal);
        if (pts[np].depth > -margin) np++;
    }
    int k[4];
    const int nk = pick4(pts, np, m->normal, k);
    m->n = 0;
    for (int j = 0; j < nk; j++) m->pt[m->n++] = pts[k[j]];
}

/* ---- the pair table ------------------------------------------------------------------------- */
typedef void (*pair_fn)(const wb_cshape *a, const wb_real pa[3], const wb_real qa[4], const wb_cshape *b,
                        const wb_real pb[3], const wb_real qb[4], wb_real margin, wb_manifold *m);

static void plane_box_pair(const wb_cshape *a, const wb_real pa[3], const wb_real qa[4], const wb_cshape *b,
                           const wb_real pb[3], const wb_real qb[4], wb_real margin, wb_manifold *m)
{
    obox bb;
    plane_normal(a, qa, m->normal);
    box_make(b, pb, qb, &bb);
    plane_box(pa, &bb, margin, m);
}

static void plane_round_pair(const wb_cshape *a, const wb_real pa[3], const wb_real qa[4], const wb_cshape *b,
                             const wb_real pb[3], const wb_real qb[4], wb_real margin, wb_manifold *m)
{
    round_s rs;
    plane_normal(a, qa, m->normal);
    round_make(b, pb, qb, &rs);
    plane_round(pa, &rs, margin, m);
}

static void mesh_box_pair(const wb_cshape *a, const wb_real pa[3], const wb_real qa[4], const wb_cshape *b,
                          const wb_real pb[3], const wb_real qb[4], wb_real margin, wb_manifold *m)
{
    if (a->mesh) mesh_shape(a->mesh, pa, qa, b, pb, qb, margin, m, 1);
}

static void mesh_round_pair(const wb_cshape *a, const wb_real pa[3], const wb_real qa[4], const wb_cshape *b,
                            const wb_real pb[3], const wb_real qb[4], wb_real margin, wb_manifold *m)
{
    if (a->mesh) mesh_shape(a->mesh, pa, qa, b, pb, qb, margin, m, 0);
}

static void box_box_pair(const wb_cshape *a, const wb_real pa[3], const wb_real qa[4], const wb_cshape *b,
                         const wb_real pb[3], const wb_real qb[4], wb_real margin, wb_manifold *m)
{
    obox ba, bb;
    box_make(a, pa, qa, &ba);
    box_make(b, pb, qb, &bb);
    box_box(&ba, &bb, margin, m);
}

static void box_round_pair(const wb_cshape *a, const wb_real pa[3], const wb_real qa[4], const wb_cshape *b,
                           const wb_real pb[3], const wb_real qb[4], wb_real margin, wb_manifold *m)
{
    obox ba;
    round_s rs;
    box_make(a, pa, qa, &ba);
    round_make(b, pb, qb, &rs);
    box_round(&ba, &rs, margin, m);
}

static void round_round_pair(const wb_cshape *a, const wb_real pa[3], const wb_real qa[4], const wb_cshape *b,
                             const wb_real pb[3], const wb_real qb[4], wb_real margin, wb_manifold *m)
{
    round_s r1, r2;
    round_make(a, pa, qa, &r1);
    round_make(b, pb, qb, &r2);
    round_round(&r1, &r2, margin, m);
}

/* pairs[A][B]: the routine for A against B, or swap: B against A, flipped. Plane-plane,
 * plane-mesh and mesh-mesh have none (colliders never touch each other) */
typedef struct pair { pair_fn fn; int swap; } pair;
#define SWAP { NULL, 1 }
static const pair pairs[WB_SHAPE_COUNT][WB_SHAPE_COUNT] = {
    [WB_SHAPE_PLANE] = {
        [WB_SHAPE_SPHERE] = { plane_round_pair, 0 }, [WB_SHAPE_BOX] = { plane_box_pair, 0 },
        [WB_SHAPE_CAPSULE] = { plane_round_pair, 0 },
    },
    [WB_SHAPE_SPHERE] = {
        [WB_SHAPE_PLANE] = SWAP, [WB_SHAPE_SPHERE] = { round_round_pair, 0 }, [WB_SHAPE_BOX] = SWAP,
        [WB_SHAPE_CAPSULE] = { round_round_pair, 0 }, [WB_SHAPE_MESH] = SWAP,
    },
    [WB_SHAPE_BOX] = {
        [WB_SHAPE_PLANE] = SWAP, [WB_SHAPE_SPHERE] = { box_round_pair, 0 }, [WB_SHAPE_BOX] = { box_box_pair, 0 },
        [WB_SHAPE_CAPSULE] = { box_round_pair, 0 }, [WB_SHAPE_MESH] = SWAP,
    },
    [WB_SHAPE_CAPSULE] = {
        [WB_SHAPE_PLANE] = SWAP, [WB_SHAPE_SPHERE] = { round_round_pair, 0 }, [WB_SHAPE_BOX] = SWAP,
        [WB_SHAPE_CAPSULE] = { round_round_pair, 0 }, [WB_SHAPE_MESH] = SWAP,
    },
    [WB_SHAPE_MESH] = {
        [WB_SHAPE_PLANE] = SWAP, [WB_SHAPE_SPHERE] = { mesh_round_pair, 0 }, [WB_SHAPE_BOX] = { mesh_box_pair, 0 },
        [WB_SHAPE_CAPSULE] = { mesh_round_pair, 0 },
    },
};
#undef SWAP

static int finite_manifold(const wb_manifold *m)
{
    if (!isfinite(m->normal[0] + m->normal[1] + m->normal[2])) return 0;
    for (int i = 0; i < m->n; i++) {
        const wb_manifold_point *p = &m->pt[i];
        if (!isfinite(p->pa[0] + p->pa[1] + p->pa[2] + p->pb[0] + p->pb[1] + p->pb[2] + p->depth)) return 0;
    }
    return 1;
}

int wb__narrow(const wb_cshape *a, const wb_real pa[3], const wb_real qa[4],
               const wb_cshape *b, const wb_real pb[3], const wb_real qb[4],
               wb_real margin, wb_manifold *out)
{
    out->n = 0;
    v3_set(out->normal, 0, 1, 0);
    if ((unsigned)a->shape >= WB_SHAPE_COUNT || (unsigned)b->shape >= WB_SHAPE_COUNT) return 0;
    const pair *e = &pairs[a->shape][b->shape];
    if (e->swap) {
        wb__narrow(b, pb, qb, a, pa, qa, margin, out);
        flip(out);
        return out->n;
    }
    if (isnan(margin)) margin = 0;
    if (e->fn) e->fn(a, pa, qa, b, pb, qb, margin, out);
    int k = 0; /* support points off the closest pair may fall a little short */
    for (int i = 0; i < out->n; i++)
        if (out->pt[i].depth > -margin) out->pt[k++] = out->pt[i];
    out->n = k;
    if (!finite_manifold(out)) out->n = 0;
    return out->n;
}
