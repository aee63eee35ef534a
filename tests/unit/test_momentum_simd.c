/* test_momentum_simd.c: the AVX2 path of the angular-momentum restore (momentum.c) gives
 * the same bits as its scalar runs, and the restore does its job on free spinning bodies.
 * Two free bodies in zero gravity, set spinning and shaken (every particle a different
 * velocity): a 5^3 lattice of soft links (125 particles: 31 groups of 4 and a tail of 1)
 * and a 6-particle rope (a group and a tail of 2). (That the restore keeps what it should
 * is tests/validation/squeeze.lua's and test_squeeze.c's.) */
#include <math.h>
#include <string.h>

#include "core/core.h"
#include "test.h"

int wb__momentum_simd(int on); /* momentum.c's internal switch */

static wb_world *spinning(void)
{
    wb_world_def d = wb_world_default_def();
    d.gravity[0] = d.gravity[1] = d.gravity[2] = 0;
    wb_world *w = wb_world_create(&d);
    if (!w) return NULL;
    wb_lattice_def ld = wb_lattice_default_def();
    for (int a = 0; a < 3; a++) ld.min[a] = -0.5, ld.max[a] = 0.5, ld.res[a] = 5;
    ld.mass = 2;
    ld.link.compliance = 1e-3;
    wb_rope_def rd = wb_rope_default_def();
    const wb_real from[3] = { 3, 0, 0 }, to[3] = { 4, 0.3, 0.2 };
    memcpy(rd.from, from, sizeof from);
    memcpy(rd.to, to, sizeof to);
    rd.segments = 5;
    rd.mass = 1;
    wb_body lb, rb;
    if (wb_lattice(w, &ld, &lb) != WB_OK || wb_rope(w, &rd, &rb) != WB_OK) {
        wb_world_destroy(w);
        return NULL;
    }
    /* spin about an oblique axis through each body's middle, plus a shake */
    const wb_real om[3] = { 1.0, 2.0, -0.5 };
    for (int32_t p = 0; p < wb_particle_count(w); p++) {
        const wb_real *x = &wb_particle_positions(w)[3 * p];
        const wb_real c[3] = { p < lb.count ? 0 : 3.5, p < lb.count ? 0 : 0.15, p < lb.count ? 0 : 0.1 };
        const wb_real r[3] = { x[0] - c[0], x[1] - c[1], x[2] - c[2] };
        wb_real v[3] = { om[1] * r[2] - om[2] * r[1], om[2] * r[0] - om[0] * r[2], om[0] * r[1] - om[1] * r[0] };
        for (int a = 0; a < 3; a++) v[a] += 0.3 * sin(1.7 * p + 2.1 * a);
        wb_particle_set_velocity(w, p, v);
    }
    return w;
}

TEST(momentum_simd_bit_identical_to_scalar)
{
    CHECK_SIMD_RUNS(wb__momentum_simd(1));
    wb_world *v = spinning(), *s = spinning();
    REQUIRE(v && s);
    int diff = 0;
    for (int f = 0; f < 40 && !diff; f++) {
        wb__momentum_simd(1);
        CHECK_EQ(wb_world_step(v), WB_OK);
        wb__momentum_simd(0);
        CHECK_EQ(wb_world_step(s), WB_OK);
        diff = memcmp(wb_particle_positions(v), wb_particle_positions(s),
                      sizeof(wb_real) * 3 * (size_t)wb_particle_count(v)) != 0;
        if (diff) test_fail(__FILE__, __LINE__, "positions differ after frame %d", f + 1);
    }
    /* both bodies were free: the restore turned them every substep (whole groups and the
     * tails) */
    CHECK_EQ(v->k.mc_free, 2);
    wb_world_destroy(v);
    wb_world_destroy(s);
    wb__momentum_simd(1);
}
