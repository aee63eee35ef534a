/* test_distance_simd.c: the AVX2 path of the distance projection (distance.c) gives
 * the same bits as the scalar loop: the same cloths stepped once with the vector
 * path and once with the scalar loop forced, every position and multiplier compared
 * bit for bit.
 * The scenes reach every branch the vector path masks or blends: pinned ends
 * (w = 0), an immovable pair (wsum = 0), coincident particles (len2 tiny), compliance
 * that overflows over h^2 (isinf(at)), damping and infinitely damped links
 * (isinf(gamma)), links made compressed (a lengthening bent past STRETCH_FREE), the
 * undamped and the damped loops, Jacobi with over-relaxation,
 * and 2 threads (batches split between them); with 3 iterations per substep (lambda
 * accumulating from a non-zero start), and with the inverse masses and the substep
 * changed between frames (pin, unpin, dt: the vector path's per-constraint copies of
 * w and alpha/h^2 must follow, the scalar loop reads them fresh). */
#include <float.h>
#include <stdint.h>
#include <stdlib.h>

#include "core/core.h"
#include "core/distance.h"
#include "test.h"

int wb__distance_simd(int on); /* distance.c's internal switch */

static wb_world *scene(int solver, int threads, int damped, int iterations)
{
    wb_world_def d = wb_world_default_def();
    d.threads = threads;
    d.substeps = 4;
    d.iterations = iterations;
    d.solver = solver;
    if (solver == WB_SOLVER_JACOBI) d.relaxation = 1.5;
    wb_world *w = wb_world_create(&d);
    if (!w) return NULL;
    /* coincident particles (len2 < 1e-24), first in their batch (a vector lane): two
     * loose particles at one place, linked */
    const wb_real at[3] = { 3, 3, 3 }, v0[3] = { 0, 0, 0 };
    const int32_t q = wb_particle_add(w, at, v0, 1, 0.01), r = wb_particle_add(w, at, v0, 1, 0.01);
    wb_distance_def l = wb_distance_default_def();
    l.rest = 0.1;
    wb_status st;
    wb_distance_add(w, q, r, &l, &st);
    int bad = st != WB_OK;
    wb_cloth_def c = wb_cloth_default_def();
    c.origin[0] = -1; c.origin[1] = 1; c.origin[2] = -1;
    c.size[0] = c.size[1] = 2;
    c.res[0] = c.res[1] = 40;
    c.shear = true;
    if (damped) { c.link.compliance = 1e-5; c.link.damping = 0.3; }
    wb_body b;
    if (wb_cloth(w, &c, &b) != WB_OK) { wb_world_destroy(w); return NULL; }
    const int32_t p0 = b.first, p1 = b.first + c.res[0] - 1, n = b.count;
    wb_particle_pin(w, p0, NULL);
    wb_particle_pin(w, p1, NULL);
    /* the rare lanes: an immovable pair, an overflowing compliance, an overflowing damping */
    l = wb_distance_default_def();
    { wb_distance_add(w, p0, p1, &l, &st); bad |= st != WB_OK; }
#ifdef WB_FLOAT
    l.compliance = 1e37f; /* / h^2 = inf */
#else
    l.compliance = 1e307; /* / h^2 = inf */
#endif
    for (int32_t i = 0; i + 50 < n; i += 97) {
        wb_distance_add(w, b.first + i, b.first + i + 50, &l, &st);
        bad |= st != WB_OK;
    }
    l.compliance = 1e-3;
#ifdef WB_FLOAT
    l.damping = FLT_MAX;
#else
    l.damping = DBL_MAX;
#endif
    /* gamma = inf (only in damped scenes: any damping takes the damped loop) */
    for (int32_t i = 7; damped && i + 45 < n; i += 89) {
        wb_distance_add(w, b.first + i, b.first + i + 45, &l, &st);
        bad |= st != WB_OK;
    }
    /* links made compressed, so a projection's lengthening is bent (STRETCH_FREE): rest
     * 1.6 x the current length across two cloth cells (bent), 1.05 x (not); only links
     * whose ends are on volume constraints are bent: a volume (compliance 1e-4, rest 1e-5 m^3) joins
     * the first third of the cloth's rows to the row above (the rest stay unbent) */
    const wb_volume_def vd = { 1e-4, true, 1e-5, 0, 0 };
    for (int32_t i = 0; i + 41 < n / 3; i += 3) {
        const int32_t t[4] = { b.first + i, b.first + i + 1, b.first + i + 40, b.first + i + 41 };
        bad |= wb_volume_add(w, t, &vd) < 0;
    }
    l = wb_distance_default_def();
    for (int32_t i = 3; i + 2 < n; i += 13) {
        const wb_real *x = wb_particle_positions(w);
        const wb_real *a = &x[3 * (b.first + i)], *e = &x[3 * (b.first + i + 2)];
        const wb_real len = sqrt((e[0] - a[0]) * (e[0] - a[0]) + (e[1] - a[1]) * (e[1] - a[1]) + (e[2] - a[2]) * (e[2] - a[2]));
        l.rest = len * (i % 2 ? 1.6 : 1.05);
        wb_distance_add(w, b.first + i, b.first + i + 2, &l, &st);
        bad |= st != WB_OK;
    }
    if (bad) { wb_world_destroy(w); return NULL; }
    return w;
}

/* whether any position or multiplier (the force readback) differs in its bits */
static int differing(const wb_world *a, const wb_world *b)
{
    const int32_t n = wb_particle_count(a);
    if (n != wb_particle_count(b) || wb__dist(a->dist)->ns != wb__dist(b->dist)->ns) return 1;
    return memcmp(wb_particle_positions(a), wb_particle_positions(b), sizeof(wb_real) * 3 * (size_t)n) != 0 ||
           memcmp(wb__dist(a->dist)->s_lambda, wb__dist(b->dist)->s_lambda, sizeof(wb_real) * (size_t)wb__dist(a->dist)->ns) != 0;
}

TEST(distance_simd_bit_identical_to_scalar)
{
    CHECK_SIMD_RUNS(wb__distance_simd(1));
    /* solver, threads, damped, iterations, changes between frames */
    const int cases[][5] = { { WB_SOLVER_GAUSS_SEIDEL, 1, 0, 1, 0 }, { WB_SOLVER_GAUSS_SEIDEL, 1, 1, 1, 0 },
                             { WB_SOLVER_JACOBI, 1, 1, 1, 0 },       { WB_SOLVER_JACOBI, 1, 0, 1, 0 },
                             { WB_SOLVER_GAUSS_SEIDEL, 2, 1, 1, 0 }, { WB_SOLVER_GAUSS_SEIDEL, 1, 0, 3, 1 },
                             { WB_SOLVER_GAUSS_SEIDEL, 1, 1, 3, 1 }, { WB_SOLVER_JACOBI, 1, 1, 3, 1 },
                             { WB_SOLVER_GAUSS_SEIDEL, 2, 0, 3, 1 } };
    for (size_t c = 0; c < sizeof cases / sizeof cases[0]; c++) {
        const int *cs = cases[c];
        wb_world *v = scene(cs[0], cs[1], cs[2], cs[3]), *s = scene(cs[0], cs[1], cs[2], cs[3]);
        REQUIRE(v && s);
        int diff = 0;
        for (int f = 0; f < 30 && !diff; f++) {
            if (cs[4]) {
                wb_world *ws[2] = { v, s };
                for (int k = 0; k < 2; k++) {
                    /* a cloth end freed, then pinned again (w changes with no new topology);
                     * a particle mid-cloth pinned; the substep shortened */
                    const int32_t p1 = 2 + 39; /* the cloth's second pinned corner */
                    if (f == 8) wb_particle_unpin(ws[k], p1);
                    if (f == 14) wb_particle_pin(ws[k], p1, NULL);
                    if (f == 11) wb_particle_pin(ws[k], 2 + 20 * 40 + 20, NULL);
                    if (f == 17) {
                        wb_world_def d = ws[k]->m.def;
                        d.dt *= 0.5;
                        CHECK_EQ(wb_world_set_def(ws[k], &d), WB_OK);
                    }
                }
            }
            wb__distance_simd(1);
            CHECK_EQ(wb_world_step(v), WB_OK);
            wb__distance_simd(0);
            CHECK_EQ(wb_world_step(s), WB_OK);
            diff = differing(v, s);
            if (diff)
                test_fail(__FILE__, __LINE__, "case %zu: positions or multipliers differ after frame %d", c, f + 1);
        }
        wb_world_destroy(v);
        wb_world_destroy(s);
    }
    wb__distance_simd(1);
}
