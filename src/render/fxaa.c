/* fxaa.c: antialiasing after the fact, on the CPU: FXAA 3.11's "quality" algorithm
 * (Lottes 2011, NVIDIA) on a frame drawn with one sample. A pixel whose luma differs
 * enough from its four neighbours' is on an edge: the edge's direction from the 3x3
 * neighbourhood, its ends searched along it (where the mean luma of the two rows, or
 * columns, it separates leaves the edge's middle value), and the pixel blended with its
 * neighbour across the edge by how far it is from the nearer end (a staircase's step
 * becomes a ramp), or by how much it stands out alone (a pixel-wide feature is softened).
 *
 * Only pixels next to something drawn as geometry (alpha 255) are looked at: the ground
 * writes alpha 128 (its grid lines are anti-aliased by its shader already, and long
 * straight lines are FXAA's most expensive edges) and the sky is where nothing was drawn
 * (alpha 0, filled in here), so a pixel is skipped unless it or one of its four
 * neighbours is geometry. On llvmpipe a fragment pass costs several ms a 720p frame of
 * fixed work per pixel; here a pixel away from edges costs a few comparisons. */
#include <stdlib.h>
#include <string.h>

#include "fxaa.h"

/* FXAA's "high quality" thresholds (luma 0..255): an edge needs a contrast of 1/8 of
 * the brightest neighbour's luma and at least 8 (1/32, "the visible limit"); SUBPIX:
 * how much a lone pixel is softened (FXAA's default) */
#define EDGE_REL 8
#define EDGE_MIN 8
#define SUBPIX 0.75f

/* the search's steps along the edge, in pixels (FXAA's preset 29 in whole pixels: a
 * lookup between two pixels along the edge would cost a second blend); 24 each way */
static const int steps[] = { 1, 1, 1, 1, 2, 2, 2, 2, 4, 8 };
#define NSTEPS ((int)(sizeof steps / sizeof *steps))
#define REACH 24

static inline int imin(int a, int b) { return a < b ? a : b; }
static inline int imax(int a, int b) { return a > b ? a : b; }
static inline float absf(float x) { return x < 0 ? -x : x; }

/* the luma of the pixel d along the edge from pixel i plus that of its neighbour across */
static inline float end_luma(const uint8_t *lu, size_t i, long along, long across, int d)
{
    const long k = (long)i + d * along;
    return (float)(lu[k] + lu[k + across]);
}

/* one pixel on an edge: the index of the neighbour to blend with and how much */
static float edge_blend(const uint8_t *lu, int w, int h, int x, int y, int range, size_t *nb)
{
    const size_t i = (size_t)y * w + x;
    const long up = y > 0 ? -w : 0, down = y < h - 1 ? w : 0, left = x > 0 ? -1 : 0, right = x < w - 1 ? 1 : 0;
    const float M = lu[i], N = lu[i + up], S = lu[i + down], W = lu[i + left], E = lu[i + right];
    const float NW = lu[i + up + left], NE = lu[i + up + right], SW = lu[i + down + left], SE = lu[i + down + right];
    /* an edge along x (the rows above and below differ) or along y */
    const float edge_h = absf(N + S - 2 * M) * 2 + absf(NE + SE - 2 * E) + absf(NW + SW - 2 * W);
    const float edge_v = absf(W + E - 2 * M) * 2 + absf(NW + NE - 2 * N) + absf(SW + SE - 2 * S);
    const bool horz = edge_h >= edge_v;
    /* a lone pixel: how far it stands from the mean of its eight neighbours */
    float sub = absf(((N + S + W + E) * 2 + NW + NE + SW + SE) / 12 - M) / (float)range;
    sub = sub > 1 ? 1 : sub;
    sub = (-2 * sub + 3) * sub * sub;
    sub = sub * sub * SUBPIX;
    /* the side of the edge: the neighbour across it that differs more */
    const float n1 = horz ? N : W, n2 = horz ? S : E, g1 = absf(n1 - M), g2 = absf(n2 - M);
    const bool to_neg = g1 >= g2;
    const long across = horz ? (to_neg ? up : down) : (to_neg ? left : right);
    *nb = (size_t)((long)i + across);
    if (!across) return 0;   /* the frame's border: nothing across */
    const float grad = (g1 > g2 ? g1 : g2) * 0.5f;   /* a quarter of it, in sums of two */
    const float mid2 = M + (to_neg ? n1 : n2);        /* twice the luma halfway across */
    /* walk along the edge both ways, to the frame's border at most */
    const long along = horz ? 1 : w;
    const int at = horz ? x : y, last = (horz ? w : h) - 1;
    const int reach_n = imin(at, REACH), reach_p = imin(last - at, REACH);
    int dn = 0, dp = 0;
    bool done_n = reach_n == 0, done_p = reach_p == 0;
    float end_n = 0, end_p = 0;
    for (int s = 0; s < NSTEPS && !(done_n && done_p); s++) {
        if (!done_n) {
            dn = imin(dn + steps[s], reach_n);
            end_n = end_luma(lu, i, along, across, -dn) - mid2;
            done_n = absf(end_n) >= grad || dn == reach_n;
        }
        if (!done_p) {
            dp = imin(dp + steps[s], reach_p);
            end_p = end_luma(lu, i, along, across, dp) - mid2;
            done_p = absf(end_p) >= grad || dp == reach_p;
        }
    }
    /* the nearer end: a step's ramp only when that end turns the right way (the pixel is
     * on the side of the edge that ends there) */
    const bool m_below = 2 * M < mid2, nearer_n = dn < dp;
    const bool good = nearer_n ? ((end_n < 0) != m_below) : ((end_p < 0) != m_below);
    const float off = good && dn + dp > 0 ? 0.5f - (float)(nearer_n ? dn : dp) / (float)(dn + dp) : 0;
    return off > sub ? off : sub;
}

/* pixel i of row y as drawn: the sky's colour where nothing was */
static inline const uint8_t *drawn(const uint8_t *rgba, const uint8_t *sky, size_t i, size_t y)
{
    return sky && !rgba[4 * i + 3] ? sky + 3 * y : rgba + 4 * i;
}

bool wb_fxaa(const uint8_t *rgba, int w, int h, const uint8_t *sky, uint8_t *rgb, uint8_t **scratch,
             size_t *scratch_cap)
{
    const size_t n = (size_t)w * (size_t)h;
    if (*scratch_cap < 2 * n) {
        uint8_t *p = realloc(*scratch, 2 * n);
        if (!p) return false;
        *scratch = p;
        *scratch_cap = 2 * n;
    }
    uint8_t *lu = *scratch, *geo = *scratch + n;
    /* the frame as RGB, its luma (Rec. 601 weights on the stored, gamma-encoded values, as
     * FXAA takes them) and where geometry was drawn */
    for (size_t y = 0, i = 0; y < (size_t)h; y++)
        for (int x = 0; x < w; x++, i++) {
            const uint8_t *p = drawn(rgba, sky, i, y);
            uint8_t *o = rgb + 3 * i;
            o[0] = p[0], o[1] = p[1], o[2] = p[2];
            lu[i] = (uint8_t)((77 * p[0] + 150 * p[1] + 29 * p[2] + 128) >> 8);
            geo[i] = rgba[4 * i + 3] == 255;
        }
    for (int y = 0; y < h; y++) {
        const size_t r = (size_t)y * w;
        const uint8_t *gm = geo + r, *gu = geo + (y > 0 ? r - w : r), *gd = geo + (y < h - 1 ? r + w : r);
        const uint8_t *row = lu + r, *lup = lu + (y > 0 ? r - w : r), *ldn = lu + (y < h - 1 ? r + w : r);
        for (int x = 0; x < w; x++) {
            /* eight pixels at a time far from geometry (the most of a frame) */
            uint64_t a8, b8, c8;
            if (x + 9 <= w && (memcpy(&a8, gm + x, 8), memcpy(&b8, gu + x, 8), memcpy(&c8, gd + x, 8),
                               !(a8 | b8 | c8 | gm[x + 8] | gm[x > 0 ? x - 1 : 0]))) {
                x += 7;
                continue;
            }
            const int xl = x > 0 ? x - 1 : 0, xr = x < w - 1 ? x + 1 : x;
            if (!(gm[x] | gu[x] | gd[x] | gm[xl] | gm[xr])) continue;
            const int M = row[x], N = lup[x], S = ldn[x], W = row[xl], E = row[xr];
            const int hi = imax(imax(imax(N, S), imax(W, E)), M), lo = imin(imin(imin(N, S), imin(W, E)), M);
            const int range = hi - lo;
            if (range < EDGE_MIN || range * EDGE_REL < hi) continue;
            size_t nb;
            const float a = edge_blend(lu, w, h, x, y, range, &nb);
            if (!(a > 0)) continue;
            const uint8_t *p = drawn(rgba, sky, r + x, (size_t)y), *q = drawn(rgba, sky, nb, nb / (size_t)w);
            uint8_t *o = rgb + 3 * (r + x);
            for (int c = 0; c < 3; c++) o[c] = (uint8_t)(p[c] + (q[c] - p[c]) * a + 0.5f);
        }
    }
    return true;
}
