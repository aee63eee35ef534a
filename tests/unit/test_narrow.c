/* test_narrow.c: the narrow phase (core/narrow.c), white-box.
 *
 *   - every pair against analytic answers: sphere-sphere exact, capsules crossing (one
 *     point) and parallel (two), a box resting on a box (the four corners of the contact
 *     face, also when the upper face overhangs and is clipped), crossing box edges (one
 *     point where the edges cross), a tilted box on a plane (its lowest corners), a
 *     capsule on a box (two points, clipped where it overhangs), a sphere in a box's face,
 *     edge and corner regions and deep inside it (the nearest face);
 *   - a face clipped to an octagon is reduced to four points, the deepest kept, spread
 *     wide; a box resting nearly flat always gives its face, never a tying edge pair;
 *   - the order of the shapes only flips the normal and swaps the points; beyond the
 *     margin nothing comes back; coincident, flat, NaN and overflowing input gives
 *     finite answers or none;
 *   - a closed icosahedron mesh against a sphere, a box and a capsule resting on one face,
 *     and an open ground sheet;
 *   - random poses of every pair: each point lies on both surfaces (the shapes' signed
 *     distances, collide.c), depth = (pa - pb).n, and a sphere's depth is exactly its
 *     radius minus the distance of its centre. */
#include <stdlib.h>

#include "core/core.h"
#include "core/bvh.h"
#include "core/narrow.h"
#include "test.h"

static const wb_real Q0[4] = { 1, 0, 0, 0 };

static wb_cshape mk_sphere(wb_real r)
{
    wb_cshape s;
    memset(&s, 0, sizeof s);
    s.shape = WB_SHAPE_SPHERE;
    s.radius = r;
    return s;
}
static wb_cshape mk_box(wb_real x, wb_real y, wb_real z)
{
    wb_cshape s;
    memset(&s, 0, sizeof s);
    s.shape = WB_SHAPE_BOX;
    v3_set(s.half, x, y, z);
    return s;
}
static wb_cshape mk_capsule(const wb_real a[3], const wb_real b[3], wb_real r)
{
    wb_cshape s;
    memset(&s, 0, sizeof s);
    s.shape = WB_SHAPE_CAPSULE;
    v3_copy(s.a, a);
    v3_copy(s.b, b);
    s.radius = r;
    return s;
}
static wb_cshape mk_plane(wb_real x, wb_real y, wb_real z)
{
    wb_cshape s;
    memset(&s, 0, sizeof s);
    s.shape = WB_SHAPE_PLANE;
    v3_set(s.n, x, y, z);
    return s;
}
static void q_axis(wb_real q[4], wb_real x, wb_real y, wb_real z, wb_real angle)
{
    const wb_real l = sqrt(x * x + y * y + z * z), s = sin(angle / 2) / l;
    q[0] = cos(angle / 2);
    q[1] = x * s;
    q[2] = y * s;
    q[3] = z * s;
}
static void q_mul(const wb_real a[4], const wb_real b[4], wb_real o[4])
{
    o[0] = a[0] * b[0] - a[1] * b[1] - a[2] * b[2] - a[3] * b[3];
    o[1] = a[0] * b[1] + a[1] * b[0] + a[2] * b[3] - a[3] * b[2];
    o[2] = a[0] * b[2] - a[1] * b[3] + a[2] * b[0] + a[3] * b[1];
    o[3] = a[0] * b[3] + a[1] * b[2] - a[2] * b[1] + a[3] * b[0];
}
static void to_world(const wb_real p[3], const wb_real q[4], const wb_real l[3], wb_real out[3])
{
    q_rotate(q, l, out);
    v3_add(out, out, p);
}
#define CHECK_V3(v, x, y, z, tol)        \
    do {                                 \
        CHECK_NEAR((v)[0], (x), (tol));  \
        CHECK_NEAR((v)[1], (y), (tol));  \
        CHECK_NEAR((v)[2], (z), (tol));  \
    } while (0)
#define CHECK_V3V(v, w, tol) CHECK_V3(v, (w)[0], (w)[1], (w)[2], tol)

/* the returned point whose pb is nearest to x; its squared distance in *d2 */
static int nearest_pb(const wb_manifold *m, const wb_real x[3], wb_real *d2)
{
    int best = -1;
    *d2 = INFINITY;
    for (int i = 0; i < m->n; i++) {
        wb_real d[3];
        v3_sub(d, m->pt[i].pb, x);
        if (v3_dot(d, d) < *d2) { *d2 = v3_dot(d, d); best = i; }
    }
    return best;
}

TEST(narrow_sphere_sphere)
{
    const wb_cshape a = mk_sphere(1), b = mk_sphere(0.5);
    const wb_real pa[3] = { 0.1, 0.2, 0.3 }, pb[3] = { 1.3, 0.5, -0.1 }; /* 1.3 apart */
    wb_manifold m;
    REQUIRE(wb__narrow(&a, pa, Q0, &b, pb, Q0, 0, &m) == 1);
    CHECK_V3(m.normal, 1.2 / 1.3, 0.3 / 1.3, -0.4 / 1.3, 1e-15);
    CHECK_NEAR(m.pt[0].depth, 0.2, 1e-15);
    CHECK_V3(m.pt[0].pa, 0.1 + 1.2 / 1.3, 0.2 + 0.3 / 1.3, 0.3 - 0.4 / 1.3, 1e-15);
    CHECK_V3(m.pt[0].pb, 1.3 - 0.6 / 1.3, 0.5 - 0.15 / 1.3, -0.1 + 0.2 / 1.3, 1e-15);
    /* 0.5 apart: beyond a margin of 0.4, within one of 0.6 (negative depth) */
    const wb_real far[3] = { 2.1, 0.2, 0.3 };
    CHECK_EQ(wb__narrow(&a, pa, Q0, &b, far, Q0, 0.4, &m), 0);
    REQUIRE(wb__narrow(&a, pa, Q0, &b, far, Q0, 0.6, &m) == 1);
    CHECK_NEAR(m.pt[0].depth, -0.5, 1e-15);
    CHECK_V3(m.normal, 1, 0, 0, 0);
}

TEST(narrow_capsules)
{
    const wb_real xa[3] = { -1, 0, 0 }, xb[3] = { 1, 0, 0 }, za[3] = { 0, 0, -1 }, zb[3] = { 0, 0, 1 };
    const wb_real o[3] = { 0, 0, 0 };
    const wb_cshape cx = mk_capsule(xa, xb, 0.2), cz = mk_capsule(za, zb, 0.2), s = mk_sphere(0.3);
    wb_manifold m;
    /* sphere over the middle of a capsule */
    const wb_real ps[3] = { 0.5, 0.4, 0 };
    REQUIRE(wb__narrow(&cx, o, Q0, &s, ps, Q0, 0, &m) == 1);
    CHECK_V3(m.normal, 0, 1, 0, 1e-15);
    CHECK_NEAR(m.pt[0].depth, 0.1, 1e-15);
    CHECK_V3(m.pt[0].pa, 0.5, 0.2, 0, 1e-15);
    CHECK_V3(m.pt[0].pb, 0.5, 0.1, 0, 1e-15);
    /* crossing capsules: one point where the axes pass closest */
    const wb_real pz[3] = { 0.3, 0.35, 0 };
    REQUIRE(wb__narrow(&cx, o, Q0, &cz, pz, Q0, 0, &m) == 1);
    CHECK_V3(m.normal, 0, 1, 0, 1e-15);
    CHECK_NEAR(m.pt[0].depth, 0.05, 1e-15);
    CHECK_V3(m.pt[0].pa, 0.3, 0.2, 0, 1e-15);
    CHECK_V3(m.pt[0].pb, 0.3, 0.15, 0, 1e-15);
    /* parallel: the two ends of the overlap, x = 0.5 and x = 1 */
    const wb_real px[3] = { 1.5, 0.35, 0 };
    REQUIRE(wb__narrow(&cx, o, Q0, &cx, px, Q0, 0, &m) == 2);
    CHECK_V3(m.normal, 0, 1, 0, 1e-15);
    for (int i = 0; i < 2; i++) {
        const wb_real x = m.pt[i].pa[0];
        CHECK(fabs(x - 0.5) < 1e-12 || fabs(x - 1) < 1e-12);
        CHECK_V3(m.pt[i].pa, x, 0.2, 0, 1e-12);
        CHECK_V3(m.pt[i].pb, x, 0.15, 0, 1e-12);
        CHECK_NEAR(m.pt[i].depth, 0.05, 1e-12);
    }
    CHECK(fabs(m.pt[0].pa[0] - m.pt[1].pa[0]) > 0.4);
}

/* box B (half hb, rotated qb about its centre pb) resting face down on box A: its four
 * bottom corners, each expected at depth d */
static void check_resting(const wb_manifold *m, const wb_real pb[3], const wb_real qb[4], const wb_real hb[3],
                          wb_real top, wb_real d, int n)
{
    CHECK_EQ(m->n, n);
    CHECK_V3(m->normal, 0, 1, 0, 1e-12);
    for (int i = 0; i < m->n; i++) {
        CHECK_NEAR(m->pt[i].depth, d, 1e-12);
        CHECK_NEAR(m->pt[i].pa[1], top, 1e-12);
        CHECK_NEAR(m->pt[i].pb[1], top - d, 1e-12);
    }
    if (!hb) return;
    for (int k = 0; k < 4; k++) {
        const wb_real l[3] = { k & 1 ? hb[0] : -hb[0], -hb[1], k & 2 ? hb[2] : -hb[2] };
        wb_real x[3], d2;
        to_world(pb, qb, l, x);
        const int j = nearest_pb(m, x, &d2);
        CHECK(d2 < 1e-24);
        if (j >= 0) CHECK_V3(m->pt[j].pa, x[0], top, x[2], 1e-12);
    }
}

TEST(narrow_box_box_face)
{
    const wb_cshape a = mk_box(1, 1, 1), b = mk_box(0.5, 0.5, 0.5);
    const wb_real o[3] = { 0, 0, 0 }, pb[3] = { 0.2, 1.49, -0.1 };
    wb_real qb[4];
    q_axis(qb, 0, 1, 0, 0.5);
    wb_manifold m;
    wb__narrow(&a, o, Q0, &b, pb, qb, 0, &m);
    check_resting(&m, pb, qb, b.half, 1, 0.01, 4);
    /* the same from above (B the reference face) */
    wb__narrow(&b, pb, qb, &a, o, Q0, 0, &m);
    CHECK_EQ(m.n, 4);
    CHECK_V3(m.normal, 0, -1, 0, 1e-12);
    for (int i = 0; i < m.n; i++) CHECK_NEAR(m.pt[i].depth, 0.01, 1e-12);
    /* equal boxes, the upper one shifted: its face clipped at x = 1 */
    const wb_real p2[3] = { 0.5, 1.98, 0 };
    wb__narrow(&a, o, Q0, &a, p2, Q0, 0, &m);
    check_resting(&m, p2, Q0, NULL, 1, 0.02, 4);
    const wb_real want[4][2] = { { -0.5, -1 }, { -0.5, 1 }, { 1, -1 }, { 1, 1 } };
    for (int k = 0; k < 4; k++) {
        const wb_real x[3] = { want[k][0], 0.98, want[k][1] };
        wb_real d2;
        nearest_pb(&m, x, &d2);
        CHECK(d2 < 1e-24);
    }
    /* lifted 0.02 above: nothing without a margin, the same four with one */
    const wb_real p3[3] = { 0.2, 1.52, -0.1 };
    CHECK_EQ(wb__narrow(&a, o, Q0, &b, p3, qb, 0.01, &m), 0);
    wb__narrow(&a, o, Q0, &b, p3, qb, 0.03, &m);
    check_resting(&m, p3, qb, b.half, 1, -0.02, 4);
}

/* convex hull area of the points' pb seen from above (y), at most 8 points, by gift wrapping */
static wb_real hull_area_y(const wb_manifold *m)
{
    int start = 0, cur, h[WB_MANIFOLD_MAX + 1], nh = 0;
    for (int i = 1; i < m->n; i++)
        if (m->pt[i].pb[0] < m->pt[start].pb[0]) start = i;
    cur = start;
    do {
        h[nh++] = cur;
        int nx = (cur + 1) % m->n;
        for (int i = 0; i < m->n; i++) {
            const wb_real *a = m->pt[cur].pb, *b = m->pt[nx].pb, *c = m->pt[i].pb;
            const wb_real cr = (b[0] - a[0]) * (c[2] - a[2]) - (b[2] - a[2]) * (c[0] - a[0]);
            if (cr < 0) nx = i;
        }
        cur = nx;
    } while (cur != start && nh <= WB_MANIFOLD_MAX);
    wb_real ar = 0;
    for (int i = 0; i < nh; i++) {
        const wb_real *a = m->pt[h[i]].pb, *b = m->pt[h[(i + 1) % nh]].pb;
        ar += a[0] * b[2] - a[2] * b[0];
    }
    return fabs(ar) / 2;
}

TEST(narrow_box_box_reduced_and_face_preferred)
{
    /* a square on a square turned 45 degrees: the clipped face is an octagon (area 3.31);
     * four points are kept, the deepest (B tilted a little) among them, spread wide */
    const wb_cshape a = mk_box(1, 1, 1);
    const wb_real o[3] = { 0, 0, 0 }, pb[3] = { 0, 1.98, 0 };
    wb_real qt[4], qy[4], qb[4];
    q_axis(qy, 0, 1, 0, M_PI / 4);
    q_axis(qt, 1, 0, 0.3, 0.002);
    q_mul(qt, qy, qb);
    wb_manifold m;
    wb__narrow(&a, o, Q0, &a, pb, qb, 0.05, &m);
    CHECK_EQ(m.n, 4);
    CHECK(hull_area_y(&m) > 0.6 * 3.31);
    wb_real deepest = -INFINITY, kept = -INFINITY;
    for (int i = 0; i < m.n; i++) kept = fmax(kept, m.pt[i].depth);
    for (int i = 0; i <= 400; i++) /* B's bottom face over A's top face, finely sampled */
        for (int j = 0; j <= 400; j++) {
            const wb_real l[3] = { -1 + i / 200.0, -1, -1 + j / 200.0 };
            wb_real x[3];
            to_world(pb, qb, l, x);
            if (fabs(x[0]) <= 1 && fabs(x[2]) <= 1) deepest = fmax(deepest, 1 - x[1]);
        }
    CHECK_NEAR(kept, deepest, 1e-4); /* the grid misses the octagon's corners by < 0.005 x 0.002 */
    /* a box resting nearly flat on another (tilts up to 0.005 rad, corners 0.01 deep):
     * always the face manifold of four points, never an edge pair that ties with it */
    const wb_cshape b = mk_box(0.5, 0.3, 0.4);
    int faces = 0;
    for (int it = 0; it < 400; it++) {
        wb_real q[4], p[3];
        q_axis(q, sin(it * 1.3), cos(it * 0.7), sin(it * 2.1 + 1), 0.005 * (it % 7) / 6);
        q_axis(qy, 0, 1, 0, 0.01 * it);
        q_mul(q, qy, qb);
        v3_set(p, 0.3 * sin(it * 0.37), 1 + 0.3 - 0.01, 0.3 * cos(it * 0.53));
        wb__narrow(&a, o, Q0, &b, p, qb, 0.05, &m);
        faces += m.n == 4;
    }
    CHECK_EQ(faces, 400);
}

TEST(narrow_box_box_edge)
{
    /* A's top edge along z at y = sqrt 2, B's bottom edge along x at y = sqrt 2 - 0.1 */
    const wb_cshape a = mk_box(1, 1, 1);
    const wb_real r2 = sqrt(2.0), o[3] = { 0.3, 0, 0.2 }, pb[3] = { 0.3, 2 * r2 - 0.1, 0.2 };
    wb_real qa[4], qb[4];
    q_axis(qa, 0, 0, 1, M_PI / 4);
    q_axis(qb, 1, 0, 0, M_PI / 4);
    wb_manifold m;
    REQUIRE(wb__narrow(&a, o, qa, &a, pb, qb, 0, &m) == 1);
    CHECK_V3(m.normal, 0, 1, 0, 1e-12);
    CHECK_NEAR(m.pt[0].depth, 0.1, 1e-12);
    CHECK_V3(m.pt[0].pa, 0.3, r2, 0.2, 1e-12);
    CHECK_V3(m.pt[0].pb, 0.3, r2 - 0.1, 0.2, 1e-12);
}

TEST(narrow_plane)
{
    /* a plane through (0, 1, 0) tilted 0.3 rad about x: its normal in its frame is y */
    const wb_cshape pl = mk_plane(0, 1, 0);
    wb_real qp[4], n[3];
    const wb_real pp[3] = { 0, 1, 0 }, y[3] = { 0, 1, 0 };
    q_axis(qp, 1, 0, 0, 0.3);
    q_rotate(qp, y, n);
    const wb_cshape b = mk_box(0.5, 0.3, 0.2);
    wb_manifold m;
    for (int rot = 0; rot < 2; rot++) { /* about z only: an edge lowest; then a corner */
        wb_real qb[4], qr[4], pb[3] = { 0.4, 0, 0 };
        if (rot == 0) q_axis(qr, 0, 0, 1, 0.5); /* about the plane's z: an edge along it lowest */
        else q_axis(qr, 1, 0.3, 0.6, 0.5);
        q_mul(qp, qr, qb);
        /* the lowest corner 0.05 below the plane */
        wb_real low = INFINITY, h[8], x[8][3];
        for (int k = 0; k < 8; k++) {
            const wb_real l[3] = { k & 1 ? 0.5 : -0.5, k & 2 ? 0.3 : -0.3, k & 4 ? 0.2 : -0.2 };
            wb_real d[3];
            to_world(pb, qb, l, x[k]);
            v3_sub(d, x[k], pp);
            h[k] = v3_dot(d, n);
            low = fmin(low, h[k]);
        }
        for (int k = 0; k < 8; k++) {
            v3_madd(x[k], n, -0.05 - low);
            h[k] -= 0.05 + low;
        }
        v3_madd(pb, n, -0.05 - low);
        wb__narrow(&pl, pp, qp, &b, pb, qb, 0.001, &m);
        int want = 0;
        for (int k = 0; k < 8; k++) want += h[k] < 0.001;
        CHECK_EQ(want, rot == 0 ? 2 : 1);
        CHECK_EQ(m.n, want);
        CHECK_V3V(m.normal, n, 1e-15);
        for (int k = 0; k < 8; k++) {
            if (!(h[k] < 0.001)) continue;
            wb_real d2;
            const int j = nearest_pb(&m, x[k], &d2);
            CHECK(d2 < 1e-24);
            if (j < 0) continue;
            CHECK_NEAR(m.pt[j].depth, -h[k], 1e-12);
            wb_real d[3];
            v3_sub(d, m.pt[j].pa, pp);
            CHECK_NEAR(v3_dot(d, n), 0, 1e-12);
        }
    }
    /* a sphere and a lying capsule (both ends) on a level plane */
    const wb_real o[3] = { 0, 0, 0 }, ps[3] = { 1, 0.4, 2 }, ca[3] = { -1, 0, 0 }, cb[3] = { 1, 0, 0 };
    const wb_cshape s = mk_sphere(0.5), c = mk_capsule(ca, cb, 0.5);
    REQUIRE(wb__narrow(&pl, o, Q0, &s, ps, Q0, 0, &m) == 1);
    CHECK_NEAR(m.pt[0].depth, 0.1, 1e-15);
    CHECK_V3(m.pt[0].pa, 1, 0, 2, 1e-15);
    CHECK_V3(m.pt[0].pb, 1, -0.1, 2, 1e-15);
    REQUIRE(wb__narrow(&pl, o, Q0, &c, ps, Q0, 0, &m) == 2);
    CHECK_NEAR(m.pt[0].depth, 0.1, 1e-15);
    CHECK_NEAR(m.pt[1].depth, 0.1, 1e-15);
    CHECK_NEAR(fabs(m.pt[0].pb[0] - m.pt[1].pb[0]), 2, 1e-15);
}

TEST(narrow_capsule_box)
{
    const wb_cshape a = mk_box(1, 0.5, 1);
    const wb_real o[3] = { 0, 0, 0 }, ca[3] = { -0.6, 0, 0 }, cb[3] = { 0.6, 0, 0 };
    const wb_cshape c = mk_capsule(ca, cb, 0.2);
    wb_manifold m;
    /* lying on the top face: both ends */
    const wb_real p1[3] = { 0.1, 0.68, 0.3 };
    REQUIRE(wb__narrow(&a, o, Q0, &c, p1, Q0, 0, &m) == 2);
    CHECK_V3(m.normal, 0, 1, 0, 1e-12);
    for (int i = 0; i < 2; i++) {
        const wb_real x = m.pt[i].pa[0];
        CHECK(fabs(x + 0.5) < 1e-9 || fabs(x - 0.7) < 1e-9);
        CHECK_V3(m.pt[i].pa, x, 0.5, 0.3, 1e-9);
        CHECK_V3(m.pt[i].pb, x, 0.48, 0.3, 1e-9);
        CHECK_NEAR(m.pt[i].depth, 0.02, 1e-12);
    }
    CHECK(fabs(m.pt[0].pa[0] - m.pt[1].pa[0]) > 1);
    /* overhanging the edge x = 1: the part over the face, x = 0.2 .. 1 */
    const wb_real p2[3] = { 0.8, 0.68, 0 };
    REQUIRE(wb__narrow(&a, o, Q0, &c, p2, Q0, 0, &m) == 2);
    for (int i = 0; i < 2; i++) {
        const wb_real x = m.pt[i].pa[0];
        CHECK(fabs(x - 0.2) < 1e-9 || fabs(x - 1) < 1e-9);
        CHECK_NEAR(m.pt[i].depth, 0.02, 1e-12);
    }
    CHECK(fabs(m.pt[0].pa[0] - m.pt[1].pa[0]) > 0.7);
    /* tilted 45 degrees, the lower end down: one point below that end */
    wb_real q[4], end[3];
    q_axis(q, 0, 0, 1, M_PI / 4);
    const wb_real p3[3] = { 0, 0.5 + 0.6 * sqrt(0.5) + 0.2 - 0.03, 0 };
    to_world(p3, q, ca, end);
    REQUIRE(wb__narrow(&a, o, Q0, &c, p3, q, 0, &m) == 1);
    CHECK_V3(m.normal, 0, 1, 0, 1e-9);
    CHECK_NEAR(m.pt[0].depth, 0.03, 1e-9);
    CHECK_V3(m.pt[0].pb, end[0], end[1] - 0.2, end[2], 1e-9);
}

TEST(narrow_sphere_box_regions)
{
    const wb_cshape a = mk_box(1, 2, 3);
    const wb_real pa[3] = { 0.5, -1, 2 };
    wb_real qa[4];
    q_axis(qa, 0, 1, 0, 0.7);
    /* sphere centre (box frame), radius, then the expected normal and closest point (box frame) */
    const wb_real cases[4][10] = {
        { 0.3, 2.4, -1, 0.5, 0, 1, 0, 0.3, 2, -1 },             /* face +y */
        { 1.3, 2.4, 0, 0.6, 0.6, 0.8, 0, 1, 2, 0 },             /* edge x, y */
        { 1.2, 2.2, 3.1, 0.4, 2 / 3., 2 / 3., 1 / 3., 1, 2, 3 }, /* corner */
        { 0.1, 1.7, -0.5, 0.3, 0, 1, 0, 0.1, 2, -0.5 },         /* deep inside: nearest face +y */
    };
    const wb_real depth[4] = { 0.1, 0.1, 0.1, 0.6 };
    for (int c = 0; c < 4; c++) {
        const wb_cshape s = mk_sphere(cases[c][3]);
        wb_real ps[3], n[3], q[3], pb[3];
        to_world(pa, qa, cases[c], ps);
        q_rotate(qa, &cases[c][4], n);
        to_world(pa, qa, &cases[c][7], q);
        v3_copy(pb, ps);
        v3_madd(pb, n, -cases[c][3]);
        wb_manifold m;
        REQUIRE(wb__narrow(&a, pa, qa, &s, ps, Q0, 0, &m) == 1);
        CHECK_V3V(m.normal, n, 1e-12);
        CHECK_NEAR(m.pt[0].depth, depth[c], 1e-12);
        CHECK_V3V(m.pt[0].pa, q, 1e-12);
        CHECK_V3V(m.pt[0].pb, pb, 1e-12);
    }
}

/* ---- meshes -------------------------------------------------------------------------------- */
/* a unit icosahedron, faces wound outwards (found as the triples of vertices an edge apart) */
static wb_colmesh *icosahedron(void)
{
    const wb_real g = (1 + sqrt(5.0)) / 2;
    wb_real v[12][3];
    int nv = 0, tri[20][3], nt = 0;
    for (int i = 0; i < 4; i++) {
        const wb_real s1 = i & 1 ? -1 : 1, s2 = i & 2 ? -g : g;
        v3_set(v[nv++], 0, s1, s2);
        v3_set(v[nv++], s1, s2, 0);
        v3_set(v[nv++], s2, 0, s1);
    }
    for (int i = 0; i < 12; i++) v3_scale(v[i], v[i], 1 / sqrt(1 + g * g));
    const wb_real edge = 2 / sqrt(1 + g * g);
    for (int i = 0; i < 12; i++)
        for (int j = i + 1; j < 12; j++)
            for (int k = j + 1; k < 12; k++) {
                wb_real d1[3], d2[3], d3[3], n[3], c[3];
                v3_sub(d1, v[j], v[i]);
                v3_sub(d2, v[k], v[i]);
                v3_sub(d3, v[k], v[j]);
                if (fabs(v3_len(d1) - edge) > 1e-9 || fabs(v3_len(d2) - edge) > 1e-9 || fabs(v3_len(d3) - edge) > 1e-9)
                    continue;
                v3_cross(n, d1, d2);
                v3_add(c, v[i], v[j]);
                v3_add(c, c, v[k]);
                const int out = v3_dot(n, c) > 0;
                tri[nt][0] = i;
                tri[nt][1] = out ? j : k;
                tri[nt][2] = out ? k : j;
                nt++;
            }
    if (nt != 20) return NULL;
    return wb__colmesh_build(&v[0][0], 12, &tri[0][0], 20, 1);
}

/* a rotation taking y to unit n */
static void q_from_y(const wb_real n[3], wb_real q[4])
{
    const wb_real y[3] = { 0, 1, 0 };
    wb_real c[3];
    v3_cross(c, y, n);
    q[0] = 1 + v3_dot(y, n);
    q[1] = c[0];
    q[2] = c[1];
    q[3] = c[2];
    q_normalize(q);
}

TEST(narrow_mesh_icosahedron)
{
    wb_colmesh *cm = icosahedron();
    REQUIRE(cm);
    CHECK(cm->closed);
    wb_cshape me;
    memset(&me, 0, sizeof me);
    me.shape = WB_SHAPE_MESH;
    me.mesh = cm;
    const wb_real pm[3] = { 1, -2, 0.5 };
    wb_real qm[4];
    q_axis(qm, 1, 1, 0, 0.4);
    /* face 5: centroid, normal, inradius */
    const int f = 5;
    wb_real cl[3] = { 0, 0, 0 }, nl[3], c[3], n[3];
    for (int k = 0; k < 3; k++) v3_madd(cl, &cm->v[3 * cm->tri[3 * f + k]], 1 / 3.);
    v3_copy(nl, &cm->fn[3 * f]);
    const wb_real rin = v3_dot(cl, nl);
    to_world(pm, qm, cl, c);
    q_rotate(qm, nl, n);
    /* a sphere resting on the face 0.01 deep */
    const wb_cshape s = mk_sphere(0.3);
    wb_real ps[3];
    v3_copy(ps, c);
    v3_madd(ps, n, 0.29);
    wb_manifold m, m2;
    REQUIRE(wb__narrow(&me, pm, qm, &s, ps, Q0, 0, &m) == 1);
    CHECK_V3V(m.normal, n, 1e-12);
    CHECK_NEAR(m.pt[0].depth, 0.01, 1e-12);
    CHECK_V3V(m.pt[0].pa, c, 1e-12);
    /* swapped */
    REQUIRE(wb__narrow(&s, ps, Q0, &me, pm, qm, 0, &m2) == 1);
    CHECK_V3(m2.normal, -n[0], -n[1], -n[2], 1e-12);
    CHECK_V3V(m2.pt[0].pb, c, 1e-12);
    CHECK_NEAR(m2.pt[0].depth, 0.01, 1e-12);
    /* its centre inside, 0.1 under the face: pushed out through it */
    v3_copy(ps, c);
    v3_madd(ps, n, -0.1);
    REQUIRE(wb__narrow(&me, pm, qm, &s, ps, Q0, 0, &m) == 1);
    CHECK_V3V(m.normal, n, 1e-12);
    CHECK_NEAR(m.pt[0].depth, 0.4, 1e-12);
    /* a small box face down on the face, 0.01 deep: its four bottom corners */
    const wb_cshape b = mk_box(0.1, 0.05, 0.1);
    wb_real qb[4], pb[3];
    q_from_y(n, qb);
    v3_copy(pb, c);
    v3_madd(pb, n, 0.04);
    wb__narrow(&me, pm, qm, &b, pb, qb, 0, &m);
    CHECK_EQ(m.n, 4);
    CHECK_V3V(m.normal, n, 1e-12);
    for (int k = 0; k < 4; k++) {
        const wb_real l[3] = { k & 1 ? 0.1 : -0.1, -0.05, k & 2 ? 0.1 : -0.1 };
        wb_real x[3], d2;
        to_world(pb, qb, l, x);
        const int j = nearest_pb(&m, x, &d2);
        CHECK(d2 < 1e-24);
        if (j >= 0) CHECK_NEAR(m.pt[j].depth, 0.01, 1e-12);
    }
    /* a capsule lying on the face: both ends */
    const wb_real ca[3] = { -0.1, 0, 0 }, cb[3] = { 0.1, 0, 0 };
    const wb_cshape cp = mk_capsule(ca, cb, 0.05);
    wb__narrow(&me, pm, qm, &cp, pb, qb, 0, &m);
    CHECK_EQ(m.n, 2);
    CHECK_V3V(m.normal, n, 1e-12);
    for (int i = 0; i < m.n; i++) CHECK_NEAR(m.pt[i].depth, 0.01, 1e-12);
    /* a box straddling a vertex: the vertex poking into its bottom face is a contact */
    wb_real vl[3], vw[3], vn[3];
    v3_copy(vl, &cm->v[0]);
    to_world(pm, qm, vl, vw);
    q_rotate(qm, vl, vn); /* a unit icosahedron's vertex normal is its position */
    q_from_y(vn, qb);
    v3_copy(pb, vw);
    v3_madd(pb, vn, 0.05 - 0.02);
    const wb_cshape big = mk_box(0.3, 0.05, 0.3);
    wb__narrow(&me, pm, qm, &big, pb, qb, 0, &m);
    REQUIRE(m.n >= 1);
    CHECK_V3V(m.normal, vn, 1e-9);
    CHECK_V3V(m.pt[0].pa, vw, 1e-12);
    CHECK_NEAR(m.pt[0].depth, 0.02, 1e-12);
    (void)rin;
    wb__colmesh_free(cm);
}

TEST(narrow_mesh_open_sheet)
{
    /* a ground sheet of two triangles at y = 0, its normals up */
    const wb_real v[4][3] = { { -5, 0, -5 }, { 5, 0, -5 }, { 5, 0, 5 }, { -5, 0, 5 } };
    const int32_t tri[2][3] = { { 0, 2, 1 }, { 0, 3, 2 } };
    wb_colmesh *cm = wb__colmesh_build(&v[0][0], 4, &tri[0][0], 2, 1);
    REQUIRE(cm);
    CHECK(!cm->closed);
    wb_cshape me;
    memset(&me, 0, sizeof me);
    me.shape = WB_SHAPE_MESH;
    me.mesh = cm;
    const wb_real o[3] = { 0, 0, 0 };
    const wb_cshape b = mk_box(0.5, 0.25, 0.5);
    wb_real qb[4];
    q_axis(qb, 0, 1, 0, 0.3);
    wb_manifold m;
    for (int side = 1; side >= -1; side -= 2) { /* above it, and below it (pushed down) */
        const wb_real pb[3] = { 0.5, side * 0.24, 1 };
        wb__narrow(&me, o, Q0, &b, pb, qb, 0, &m);
        CHECK_EQ(m.n, 4);
        CHECK_V3(m.normal, 0, side, 0, 1e-12);
        for (int i = 0; i < m.n; i++) {
            CHECK_NEAR(m.pt[i].depth, 0.01, 1e-12);
            CHECK_NEAR(m.pt[i].pa[1], 0, 1e-12);
        }
    }
    wb__colmesh_free(cm);
}

TEST(narrow_swapped_order)
{
    const wb_real ca[3] = { -0.5, 0, 0 }, cb[3] = { 0.5, 0.2, 0 };
    const wb_cshape sh[5] = { mk_plane(0, 1, 0), mk_sphere(0.4), mk_box(0.3, 0.4, 0.5), mk_capsule(ca, cb, 0.3),
                              mk_box(0.6, 0.2, 0.3) };
    const wb_real p1[3] = { 0.1, 0.2, 0 }, p2[3] = { 0.3, 0.6, 0.2 };
    wb_real q1[4], q2[4];
    q_axis(q1, 1, 2, 0, 0.3);
    q_axis(q2, 0, 1, 3, 0.6);
    int tried = 0;
    for (int i = 0; i < 5; i++)
        for (int j = 1; j < 5; j++) {
            wb_manifold m, w;
            const int n = wb__narrow(&sh[i], p1, q1, &sh[j], p2, q2, 0.05, &m);
            CHECK_EQ(wb__narrow(&sh[j], p2, q2, &sh[i], p1, q1, 0.05, &w), n);
            tried += n > 0;
            if (n != w.n) continue;
            CHECK_V3(w.normal, -m.normal[0], -m.normal[1], -m.normal[2], 1e-12);
            for (int k = 0; k < n; k++) {
                CHECK_NEAR(w.pt[k].depth, m.pt[k].depth, 1e-12);
                CHECK_V3V(w.pt[k].pa, m.pt[k].pb, 1e-12);
                CHECK_V3V(w.pt[k].pb, m.pt[k].pa, 1e-12);
            }
        }
    CHECK(tried >= 12);
}

/* every value finite, the normal unit, depth consistent */
static int sane(const wb_manifold *m)
{
    int ok = m->n >= 0 && m->n <= WB_MANIFOLD_MAX;
    if (m->n > 0) ok &= fabs(v3_len(m->normal) - 1) < 1e-12;
    for (int i = 0; i < m->n; i++) {
        wb_real d[3];
        v3_sub(d, m->pt[i].pa, m->pt[i].pb);
        ok &= isfinite(m->pt[i].depth) && fabs(m->pt[i].depth - v3_dot(d, m->normal)) < 1e-9;
    }
    return ok;
}

TEST(narrow_degenerate_input)
{
    const wb_real o[3] = { 0.5, 0.5, 0.5 }, ca[3] = { -1, 0, 0 }, cb[3] = { 1, 0, 0 };
    const wb_cshape s1 = mk_sphere(0.3), s2 = mk_sphere(0.2), c = mk_capsule(ca, cb, 0.1), b = mk_box(0.2, 0.3, 0.4),
                    flat = mk_box(0, 0, 0), pl = mk_plane(0, 1, 0);
    wb_manifold m;
    /* concentric spheres, coaxial capsules, a box on itself: some direction, full depth */
    REQUIRE(wb__narrow(&s1, o, Q0, &s2, o, Q0, 0, &m) == 1);
    CHECK(sane(&m));
    CHECK_NEAR(m.pt[0].depth, 0.5, 1e-15);
    const wb_real o2[3] = { 1, 0.5, 0.5 };
    CHECK(wb__narrow(&c, o, Q0, &c, o2, Q0, 0, &m) >= 1);
    CHECK(sane(&m));
    CHECK_NEAR(m.pt[0].depth, 0.2, 1e-15);
    CHECK(wb__narrow(&b, o, Q0, &b, o, Q0, 0, &m) >= 1);
    CHECK(sane(&m));
    /* a box of no size is a point */
    const wb_real low[3] = { 0, -0.1, 0 };
    REQUIRE(wb__narrow(&pl, Q0 + 1, Q0, &flat, low, Q0, 0, &m) >= 1);
    CHECK(sane(&m));
    CHECK_NEAR(m.pt[0].depth, 0.1, 1e-15);
    CHECK(wb__narrow(&flat, low, Q0, &b, o, Q0, 0, &m) >= 0 && sane(&m));
    /* not finite, or too large to square: nothing rather than NaN */
    const wb_real nan3[3] = { NAN, 0, 0 }, huge[3] = { 1e300, 1e300, -1e300 };
    const wb_cshape shapes[4] = { s1, c, b, pl };
    for (int i = 0; i < 4; i++)
        for (int j = 0; j < 3; j++) {
            CHECK_EQ(wb__narrow(&shapes[i], nan3, Q0, &shapes[j], o, Q0, 0.1, &m), 0);
            wb__narrow(&shapes[i], huge, Q0, &shapes[j], huge, Q0, 0.1, &m);
            CHECK(sane(&m));
            CHECK(wb__narrow(&shapes[i], o, Q0, &shapes[j], o, Q0, NAN, &m) > 0); /* NaN margin: 0 */
        }
}

/* ---- random poses ---------------------------------------------------------------------------- */
static uint64_t rng = 0x9e3779b97f4a7c15ull;
static wb_real urand(void)
{
    rng ^= rng << 13;
    rng ^= rng >> 7;
    rng ^= rng << 17;
    return (wb_real)(rng >> 11) / 9007199254740992.0;
}

static wb_cshape random_shape(int kind, wb_cshape *mesh)
{
    switch (kind) {
    case 0: return mk_plane(urand() - 0.5, 1, urand() - 0.5);
    case 1: return mk_sphere(0.1 + 0.5 * urand());
    case 2: return mk_box(0.1 + 0.5 * urand(), 0.1 + 0.5 * urand(), 0.1 + 0.5 * urand());
    case 3: {
        wb_real a[3], b[3];
        for (int k = 0; k < 3; k++) { a[k] = 0.5 * (urand() - 0.5); b[k] = -a[k]; }
        return mk_capsule(a, b, 0.05 + 0.3 * urand());
    }
    default: return *mesh;
    }
}

TEST(narrow_random_consistency)
{
    wb_colmesh *cm = icosahedron();
    REQUIRE(cm);
    wb_cshape me;
    memset(&me, 0, sizeof me);
    me.shape = WB_SHAPE_MESH;
    me.mesh = cm;
    int contacts = 0, points = 0, bad = 0;
    const wb_real margin = 0.05;
    for (int it = 0; it < 20000 && bad < 20; it++) {
        const int ka = (int)(urand() * 5), kb = (int)(urand() * 5);
        if ((ka == 0 || ka == 4) && (kb == 0 || kb == 4)) continue; /* no pair */
        wb_cshape a = random_shape(ka, &me), b = random_shape(kb, &me);
        if (ka == 0) v3_scale(a.n, a.n, 1 / v3_len(a.n));
        if (kb == 0) v3_scale(b.n, b.n, 1 / v3_len(b.n));
        wb_real pa[3], pb[3], qa[4], qb[4];
        for (int k = 0; k < 3; k++) { pa[k] = urand() - 0.5; pb[k] = urand() - 0.5; }
        for (int k = 0; k < 4; k++) { qa[k] = urand() - 0.5; qb[k] = urand() - 0.5; }
        q_normalize(qa);
        q_normalize(qb);
        wb_manifold m;
        const int n = wb__narrow(&a, pa, qa, &b, pb, qb, margin, &m);
        const int fails = test_failures;
        CHECK(n >= 0 && n <= WB_MANIFOLD_MAX && n == m.n);
        if (n > 0) CHECK_NEAR(v3_len(m.normal), 1, 1e-12);
        contacts += n > 0;
        points += n;
        wb_real deepest = -INFINITY;
        for (int i = 0; i < n; i++) {
            const wb_manifold_point *p = &m.pt[i];
            wb_real d[3], nn[3];
            v3_sub(d, p->pa, p->pb);
            CHECK_NEAR(p->depth, v3_dot(d, m.normal), 1e-12);
            CHECK(p->depth > -margin);
            CHECK_NEAR(wb__shape_distance(&a, pa, qa, p->pa, nn), 0, 1e-9);
            CHECK_NEAR(wb__shape_distance(&b, pb, qb, p->pb, nn), 0, 1e-9);
            deepest = fmax(deepest, p->depth);
        }
        /* a sphere B (or A): depth exactly its radius less its centre's distance */
        for (int side = 0; side < 2; side++) {
            const wb_cshape *s = side ? &a : &b, *o = side ? &b : &a;
            if (s->shape != WB_SHAPE_SPHERE) continue;
            wb_real nn[3];
            const wb_real want = s->radius - wb__shape_distance(o, side ? pb : pa, side ? qb : qa, side ? pa : pb, nn);
            if (want > -margin + 1e-9) {
                CHECK_EQ(n, 1);
                CHECK_NEAR(deepest, want, 1e-9);
            } else if (want < -margin - 1e-9) CHECK_EQ(n, 0);
        }
        /* a capsule B against a convex A: no point of its axis deeper than what came back */
        if (b.shape == WB_SHAPE_CAPSULE) {
            wb_real want = -INFINITY, nn[3];
            for (int k = 0; k <= 200; k++) {
                wb_real l[3], x[3];
                for (int j = 0; j < 3; j++) l[j] = b.a[j] + (b.b[j] - b.a[j]) * k / 200.0;
                to_world(pb, qb, l, x);
                want = fmax(want, b.radius - wb__shape_distance(&a, pa, qa, x, nn));
            }
            if (want > -margin + 1e-6) CHECK(n > 0);
            /* (with its axis inside A the deepest depends on which face is nearest) */
            if (want > -margin + 1e-6 && want < b.radius) CHECK(deepest >= want - 1e-6);
        }
        /* a box B: a corner inside A means contact */
        if (b.shape == WB_SHAPE_BOX) {
            wb_real nn[3], inside = INFINITY;
            for (int k = 0; k < 8; k++) {
                const wb_real l[3] = { k & 1 ? b.half[0] : -b.half[0], k & 2 ? b.half[1] : -b.half[1],
                                       k & 4 ? b.half[2] : -b.half[2] };
                wb_real x[3];
                to_world(pb, qb, l, x);
                inside = fmin(inside, wb__shape_distance(&a, pa, qa, x, nn));
            }
            if (inside < -1e-6) CHECK(n > 0);
            if (a.shape == WB_SHAPE_PLANE && inside < margin - 1e-9) CHECK_NEAR(deepest, -inside, 1e-12);
        }
        if (test_failures > fails) {
            bad++;
            printf("#   it %d: shapes %d %d, %d points\n", it, a.shape, b.shape, n);
        }
    }
    CHECK(contacts > 3000);
    CHECK(points > contacts);
    wb__colmesh_free(cm);
}
