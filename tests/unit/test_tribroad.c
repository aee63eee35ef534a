/* test_tribroad.c: the particle-triangle broad phase (src/core/tribroad.c; white-box: core.h).
 *
 * Its list must be exactly the (point, triangle) pairs the O(P x T) loop below accepts,
 * written here from the rules alone (tricontact.c's reach and motion, the triangle's box
 * grown by its motion, the plane and the closest point within reach_p + motion, the
 * group rules, the rest rule of one body), each once, and the same list, in the same
 * order, for 1, 2 and 3 threads. The scenes: soft blocks jittered into each other
 * (some self-colliding, one not colliding) with loose particles of mixed radii, a few of
 * them fast, among loose triangles; a crumpled self-colliding cloth under another cloth;
 * bodies far apart with a huge triangle (sparse grids that wrap, a triangle wider than
 * the grid). A body culled too eagerly, a search range one cell short, a level of fast
 * points left out, a pair found twice, lists that differ between thread counts: each fails
 * here. */
#include <stdlib.h>

#include "core/core.h"
#include "test.h"

static uint64_t rng = 0x9E3779B97F4A7C15ull;
static double urand(void)
{
    rng = rng * 6364136223846793005ull + 1442695040888963407ull;
    return (double)(rng >> 11) / 9007199254740992.0;
}

/* ---- the rules, brute force --------------------------------------------------------------------- */
static int allowed(const wb_model *m, int32_t p, int32_t v)
{
    const int32_t gp = m->group[p], gv = m->group[v];
    if (gp != gv || gp == 0) return (m->cflags[p] & m->cflags[v] & WB_CF_COLLIDE) != 0;
    return (m->cflags[p] & m->cflags[v] & WB_CF_SELF) != 0;
}

static wb_real motion(const wb_world *w, int32_t i)
{
    const wb_model *m = &w->m;
    const wb_real dt = m->def.dt, g = v3_len(m->def.gravity) * dt * dt;
    return v3_len_safe(&w->s.v[3 * i]) * dt + g + m->radius[i] / 4;
}

/* whether (p, t) is a candidate of this frame */
static int brute_pair(const wb_world *w, int32_t p, int32_t t)
{
    const wb_model *m = &w->m;
    const wb_real *x = w->s.x;
    const int32_t *v = &m->tri[3 * t];
    if (!(m->cflags[p] & (WB_CF_COLLIDE | WB_CF_SELF))) return 0;
    const wb_real rp = m->radius[p] + motion(w, p);
    if (!(rp >= 0) || !isfinite(rp)) return 0;
    if (!((m->cflags[v[0]] | m->cflags[v[1]] | m->cflags[v[2]]) & (WB_CF_COLLIDE | WB_CF_SELF))) return 0;
    wb_real lo[3], hi[3], mv = 0;
    for (int a = 0; a < 3; a++) {
        lo[a] = fmin(fmin(x[3 * v[0] + a], x[3 * v[1] + a]), x[3 * v[2] + a]);
        hi[a] = fmax(fmax(x[3 * v[0] + a], x[3 * v[1] + a]), x[3 * v[2] + a]);
    }
    for (int k = 0; k < 3; k++) mv = fmax(mv, motion(w, v[k]));
    if (!isfinite(fmax(hi[0] - lo[0], fmax(hi[1] - lo[1], hi[2] - lo[2])) + 2 * mv)) return 0;
    /* the box grown by mv, within rp */
    wb_real s = 0;
    for (int a = 0; a < 3; a++) {
        const wb_real l = lo[a] - mv, h = hi[a] + mv, c = x[3 * p + a];
        const wb_real d = c < l ? l - c : c > h ? c - h : 0;
        s += d * d;
    }
    if (!(s < rp * rp)) return 0;
    /* the rules */
    if (p == v[0] || p == v[1] || p == v[2]) return 0;
    int same = 0;
    for (int k = 0; k < 3; k++) {
        if (!allowed(m, p, v[k])) return 0;
        same |= m->group[p] != 0 && m->group[p] == m->group[v[k]];
    }
    if (m->w[p] == 0 && m->w[v[0]] == 0 && m->w[v[1]] == 0 && m->w[v[2]] == 0) return 0;
    /* the plane, then the triangle, within rp + mv */
    const wb_real reach = rp + mv;
    wb_real e1[3], e2[3], n[3], d[3], bary[3], q[3];
    v3_sub(e1, &x[3 * v[1]], &x[3 * v[0]]);
    v3_sub(e2, &x[3 * v[2]], &x[3 * v[0]]);
    v3_cross(n, e1, e2);
    const wb_real ln = v3_len(n);
    if (ln > 0 && isfinite(ln)) v3_scale(n, n, 1 / ln);
    else v3_set(n, 0, 0, 0);
    v3_sub(d, &x[3 * p], &x[3 * v[0]]);
    if (!(fabs(v3_dot(d, n)) < reach)) return 0;
    if (!(wb__tri_closest(&x[3 * p], &x[3 * v[0]], &x[3 * v[1]], &x[3 * v[2]], bary, q) < reach * reach)) return 0;
    /* one body: not within r_p of the triangle at rest */
    if (same && wb__tri_closest(&m->x0[3 * p], &m->x0[3 * v[0]], &m->x0[3 * v[1]], &m->x0[3 * v[2]], bary, q) <
                    m->radius[p] * m->radius[p])
        return 0;
    return 1;
}

static int cmp_u64(const void *a, const void *b)
{
    const uint64_t x = *(const uint64_t *)a, y = *(const uint64_t *)b;
    return x < y ? -1 : x > y;
}

/* the broad phase's list for this thread count (a copy, 2 x *n ints) */
static int32_t *broad_list(wb_world *w, int threads, int32_t *n)
{
    wb_world_def d = wb_world_get_def(w);
    d.threads = threads;
    CHECK(wb_world_set_def(w, &d) == WB_OK);
    wb__contacts_begin(w);
    wb__tricontacts_begin(w);
    *n = w->k.tc.n;
    int32_t *l = malloc(sizeof *l * (size_t)(2 * *n + 1));
    if (!l) abort();
    memcpy(l, w->k.tc.pt, sizeof *l * (size_t)(2 * *n));
    return l;
}

/* the list against brute force and across threads; returns the candidates */
static int32_t check_world(wb_world *w)
{
    const wb_model *m = &w->m;
    int32_t n1, n2, n3;
    int32_t *l1 = broad_list(w, 1, &n1), *l2 = broad_list(w, 2, &n2), *l3 = broad_list(w, 3, &n3);
    CHECK_EQ(n1, n2);
    CHECK_EQ(n1, n3);
    CHECK(n1 == n2 && !memcmp(l1, l2, sizeof *l1 * (size_t)(2 * n1)));
    CHECK(n1 == n3 && !memcmp(l1, l3, sizeof *l1 * (size_t)(2 * n1)));
    /* the list sorted by (p, t) against the brute list in that order, element by element */
    uint64_t *sorted = malloc(sizeof *sorted * (size_t)(n1 + 1));
    if (!sorted) abort();
    for (int32_t q = 0; q < n1; q++) sorted[q] = (uint64_t)(uint32_t)l1[2 * q] << 32 | (uint32_t)l1[2 * q + 1];
    qsort(sorted, (size_t)n1, sizeof *sorted, cmp_u64);
    int32_t k = 0, missed = 0, extra = 0;
    for (int32_t p = 0; p < m->np; p++)
        for (int32_t t = 0; t < m->ntri; t++) {
            if (!brute_pair(w, p, t)) continue;
            const uint64_t want = (uint64_t)(uint32_t)p << 32 | (uint32_t)t;
            /* extra pairs of the broad phase before this one (twice: the second is extra) */
            while (k < n1 && sorted[k] < want) extra++, k++;
            if (k < n1 && sorted[k] == want) k++;
            else missed++;
        }
    extra += n1 - k;
    free(sorted);
    CHECK_EQ(missed, 0);
    CHECK_EQ(extra, 0); /* a pair twice, out of order or not a candidate */
    free(l1);
    free(l2);
    free(l3);
    return n1;
}

static wb_world *world_new(void)
{
    wb_world_def d = wb_world_default_def();
    wb_world *w = wb_world_create(&d);
    if (!w) abort();
    return w;
}

static void random_velocity(wb_world *w, int32_t i, wb_real speed)
{
    wb_real v[3] = { speed * (2 * urand() - 1), speed * (2 * urand() - 1), speed * (2 * urand() - 1) };
    wb_particle_set_velocity(w, i, v);
}

/* soft blocks jittered into each other, loose particles and loose triangles */
TEST(tribroad_matches_brute_force_heap)
{
    for (int rep = 0; rep < 3; rep++) {
        wb_world *w = world_new();
        for (int b = 0; b < 10; b++) {
            wb_lattice_def l = wb_lattice_default_def();
            const wb_real s = 0.3 + 0.2 * urand();
            for (int a = 0; a < 3; a++) {
                l.min[a] = 1.2 * urand();
                l.max[a] = l.min[a] + s;
                l.res[a] = 4;
            }
            l.radius = s / 6 * (0.5 + urand());
            wb_body body;
            REQUIRE(wb_lattice(w, &l, &body) == WB_OK);
            /* self-colliding, not colliding at all, or the default */
            if (b % 4 == 1) wb_group_set_self_collide(w, body.group, true);
            if (b == 6) wb_body_set_contacts(w, body, false, false, 0);
            for (int32_t i = body.first; i < body.first + body.count; i++) {
                for (int a = 0; a < 3; a++) w->s.x[3 * i + a] += 0.05 * (2 * urand() - 1);
                random_velocity(w, i, urand() < 0.05 ? 20 : 1);
            }
        }
        /* loose particles, mixed radii, a few fast; loose triangles over some of them */
        const int32_t first = wb_particle_count(w);
        for (int i = 0; i < 300; i++) {
            const wb_real p[3] = { 1.6 * urand() - 0.2, 1.6 * urand() - 0.2, 1.6 * urand() - 0.2 };
            const int32_t id = wb_particle_add(w, p, NULL, 0.01, urand() < 0.5 ? 0.01 : 0.06 * urand());
            random_velocity(w, id, urand() < 0.1 ? 30 : 0.5);
        }
        int32_t tri[3 * 60];
        for (int k = 0; k < 60; k++) {
            const int32_t b = first + (int32_t)(urand() * 297);
            tri[3 * k] = b, tri[3 * k + 1] = b + 1, tri[3 * k + 2] = b + 2;
        }
        REQUIRE(wb_surface_add(w, tri, 60) >= 0);
        CHECK(w->m.ntri >= 1000);
        CHECK(check_world(w) > 200);
        wb_world_destroy(w);
    }
}

/* a crumpled self-colliding cloth (the rest rule) under another cloth that does not */
TEST(tribroad_matches_brute_force_cloth)
{
    wb_world *w = world_new();
    wb_cloth_def c = wb_cloth_default_def();
    c.res[0] = c.res[1] = 24;
    c.size[0] = c.size[1] = 1;
    c.radius = 0.02;
    wb_body a, b;
    REQUIRE(wb_cloth(w, &c, &a) == WB_OK);
    wb_group_set_self_collide(w, a.group, true);
    c.origin[1] = 0.05;
    c.res[0] = c.res[1] = 12;
    REQUIRE(wb_cloth(w, &c, &b) == WB_OK);
    /* folded: x -> a zigzag, so that far parts of the sheet lie close */
    for (int32_t i = a.first; i < a.first + a.count; i++) {
        wb_real *p = &w->s.x[3 * i];
        const wb_real u = p[0];
        p[0] = 0.25 * fabs(fmod(4 * u, 2) - 1);
        p[1] = 0.03 * u + 0.01 * urand();
        random_velocity(w, i, 0.5);
    }
    CHECK(check_world(w) > 100);
    wb_world_destroy(w);
}

/* bodies 1e7 m apart (sparse grids that wrap) and a huge triangle over loose particles */
TEST(tribroad_matches_brute_force_sparse)
{
    wb_world *w = world_new();
    for (int b = 0; b < 6; b++) {
        wb_lattice_def l = wb_lattice_default_def();
        for (int a = 0; a < 3; a++) {
            l.min[a] = (b % 2 ? 1e7 : -3e6) * (a == b % 3) + 0.1 * urand();
            l.max[a] = l.min[a] + 0.3;
            l.res[a] = 3;
        }
        l.radius = 0.05;
        wb_body body;
        REQUIRE(wb_lattice(w, &l, &body) == WB_OK);
        for (int32_t i = body.first; i < body.first + body.count; i++) random_velocity(w, i, 2);
    }
    const int32_t first = wb_particle_count(w);
    for (int i = 0; i < 200; i++) {
        const int far = i % 3 == 0;
        const wb_real p[3] = { far ? 1e7 + urand() : urand(), urand() * 0.6, far ? urand() : 1e7 * urand() };
        wb_particle_add(w, p, NULL, 0.01, 0.03 + 0.1 * urand());
    }
    /* a triangle across the whole volume, and small ones among the loose particles */
    const wb_real big[3][3] = { { -3e6, 0.3, -3e6 }, { 1e7, 0.3, 0 }, { 0, 0.3, 1e7 } };
    int32_t tri[3 * 40];
    for (int k = 0; k < 3; k++) tri[k] = wb_particle_add(w, big[k], NULL, 1, 0);
    for (int k = 1; k < 40; k++) {
        const int32_t b = first + (int32_t)(urand() * 197);
        tri[3 * k] = b, tri[3 * k + 1] = b + 1, tri[3 * k + 2] = b + 2;
    }
    REQUIRE(wb_surface_add(w, tri, 40) >= 0);
    CHECK(check_world(w) > 20);
    wb_world_destroy(w);
}

/* ---- the list kept from frame to frame -------------------------------------------------------- */
/* this frame's list through the kept list (threads as given), and a fresh search's */
static int32_t *kept_and_fresh(wb_world *w, int threads, int32_t *n, int32_t **fresh, int32_t *nf)
{
    int32_t *l = broad_list(w, threads, n);
    if (w->k.tc.bp) w->k.tc.bp->fresh_only = 1;
    *fresh = broad_list(w, 1, nf);
    if (w->k.tc.bp) w->k.tc.bp->fresh_only = 0;
    return l;
}

static int64_t rebuilds(const wb_world *w) { return w->k.tc.bp ? w->k.tc.bp->rebuilds : 0; }

/* Every frame the kept list must give the fresh search's list, pair for pair in order
 * (and, now and then, the brute force's set on 1-3 threads), while the particles drift,
 * now and then one jumps past its skin or speeds up, and between frames triangles and a
 * body are added, a particle is pinned and freed, a body's self-collision, a group and a
 * radius change, a position goes NaN and back, and the last particle is removed: each
 * of those frames must rebuild the list (a list kept one frame too long misses a pair or
 * keeps one). And the list must be kept most frames (it is used). */
TEST(tribroad_kept_list_matches_fresh_search_over_frames)
{
    wb_world *w = world_new();
    wb_body bodies[6];
    for (int b = 0; b < 6; b++) {
        wb_lattice_def l = wb_lattice_default_def();
        for (int a = 0; a < 3; a++) {
            l.min[a] = 0.8 * urand();
            l.max[a] = l.min[a] + 0.35;
            l.res[a] = 4;
        }
        l.radius = 0.04;
        REQUIRE(wb_lattice(w, &l, &bodies[b]) == WB_OK);
        if (b % 3 == 1) wb_group_set_self_collide(w, bodies[b].group, true);
    }
    const int32_t first = wb_particle_count(w);
    for (int i = 0; i < 150; i++) {
        const wb_real p[3] = { 1.2 * urand(), 1.2 * urand(), 1.2 * urand() };
        wb_particle_add(w, p, NULL, 0.01, 0.02 + 0.03 * urand());
    }
    int32_t tri[3 * 30];
    for (int k = 0; k < 30; k++) {
        const int32_t b = first + (int32_t)(urand() * 140);
        tri[3 * k] = b, tri[3 * k + 1] = b + 3, tri[3 * k + 2] = b + 7;
    }
    REQUIRE(wb_surface_add(w, tri, 30) >= 0);
    for (int32_t i = 0; i < wb_particle_count(w); i++) random_velocity(w, i, 0.2);
    enum { FRAMES = 90 };
    int bad = 0, missed_rebuild = 0, events = 0;
    int64_t pairs = 0;
    for (int f = 0; f < FRAMES; f++) {
        wb_model *m = &w->m;
        int event = 1;
        /* a drift of up to ~1.5 mm a frame, all one way for the blocks (they close in) */
        for (int32_t i = 0; i < 3 * m->np; i++) w->s.x[i] += 0.003 * (urand() - 0.5) + (i % 3 == 1 ? 0.0005 : 0);
        if (f % 9 == 4) v3_set(&w->s.x[3 * (f * 37 % m->np)], 1.2 * urand(), 1.2 * urand(), 1.2 * urand()); /* a jump */
        else if (f % 11 == 6) random_velocity(w, f * 53 % m->np, 3);                                        /* faster */
        else if (f == 20) { /* triangles added */
            const int32_t t2[6] = { first + 1, first + 2, first + 5, bodies[0].first, first + 9, bodies[2].first + 5 };
            REQUIRE(wb_surface_add(w, t2, 2) >= 0);
        } else if (f == 25) { /* a body added among the others */
            wb_lattice_def l = wb_lattice_default_def();
            for (int a = 0; a < 3; a++) l.min[a] = 0.4, l.max[a] = 0.7, l.res[a] = 3;
            l.radius = 0.04;
            wb_body b;
            REQUIRE(wb_lattice(w, &l, &b) == WB_OK);
        } else if (f == 30) wb_particle_pin(w, bodies[1].first + 21, NULL);
        else if (f == 33) wb_particle_unpin(w, bodies[1].first + 21);
        else if (f == 37) wb_group_set_self_collide(w, bodies[0].group, true);
        else if (f == 41) wb_particle_set_group(w, first + 3, bodies[3].group);
        else if (f == 46) wb_particle_set_radius(w, first + 7, 0.09);
        else if (f == 50) w->s.x[3 * (bodies[4].first + 10) + 1] = NAN;
        else if (f == 52) w->s.x[3 * (bodies[4].first + 10) + 1] = 0.5;
        else if (f == 57) m->np--; /* the last particle removed (the new body's corner: no triangle of it) */
        else event = 0;
        if (f == 57) { /* its triangles go with it */
            int32_t nt = 0;
            for (int32_t t = 0; t < m->ntri; t++)
                if (m->tri[3 * t] < m->np && m->tri[3 * t + 1] < m->np && m->tri[3 * t + 2] < m->np) {
                    memmove(&m->tri[3 * nt], &m->tri[3 * t], sizeof *m->tri * 3);
                    nt++;
                }
            m->ntri = nt;
        }
        const int64_t r0 = rebuilds(w);
        int32_t n, nf, *fresh;
        int32_t *l = kept_and_fresh(w, 1 + f % 3, &n, &fresh, &nf);
        /* f == 52: the NaN's frame before it used the fresh search; the list may still hold */
        if (event && f != 52 && f > 0) {
            events++;
            if (rebuilds(w) == r0) missed_rebuild++;
        }
        if (n != nf || memcmp(l, fresh, sizeof *l * (size_t)(2 * n))) bad++;
        pairs += n;
        free(l);
        free(fresh);
        if (f % 15 == 14) CHECK(check_world(w) >= 0);
    }
    CHECK_EQ(bad, 0);
    CHECK_EQ(missed_rebuild, 0);
    CHECK(events >= 15);
    CHECK(pairs > 50 * FRAMES);
    CHECK(rebuilds(w) < FRAMES * 3 / 4); /* kept most frames */
    wb_world_destroy(w);
}

/* A real pile: soft blocks dropped on a pinned cloth and on each other, stepped 120
 * frames with the kept list and again with a fresh search every frame, on 1 and 3
 * threads: the same hash (the projection sees the same list in the same order). */
TEST(tribroad_kept_list_same_steps_as_fresh_search)
{
    uint64_t h[4];
    for (int run = 0; run < 4; run++) {
        wb_world_def d = wb_world_default_def();
        d.threads = run / 2 ? 3 : 1;
        wb_world *w = wb_world_create(&d);
        REQUIRE(w);
        wb_cloth_def c = wb_cloth_default_def();
        c.res[0] = c.res[1] = 10;
        c.size[0] = c.size[1] = 1;
        c.radius = 0.03;
        wb_body cloth;
        REQUIRE(wb_cloth(w, &c, &cloth) == WB_OK);
        for (int32_t i = cloth.first; i < cloth.first + cloth.count; i++) wb_particle_pin(w, i, NULL);
        for (int b = 0; b < 4; b++) {
            wb_lattice_def l = wb_lattice_default_def();
            for (int a = 0; a < 3; a++) {
                l.min[a] = (a == 1 ? 0.1 + 0.25 * b : 0.2 + 0.1 * b);
                l.max[a] = l.min[a] + 0.2;
                l.res[a] = 3;
            }
            l.radius = 0.03;
            wb_body body;
            REQUIRE(wb_lattice(w, &l, &body) == WB_OK);
        }
        int64_t touching = 0;
        for (int f = 0; f < 120; f++) {
            if (f == 1 && run % 2) w->k.tc.bp->fresh_only = 1;
            REQUIRE(wb_world_step(w) == WB_OK);
            touching += w->k.tc.n;
        }
        CHECK(touching > 1000);
        h[run] = wb_world_hash(w);
        wb_world_destroy(w);
    }
    CHECK(h[0] == h[1]);
    CHECK(h[2] == h[3]);
    CHECK(h[0] == h[2]);
}
