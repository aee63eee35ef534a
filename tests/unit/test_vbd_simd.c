/* test_vbd_simd.c: the AVX2 path of VBD's vertex step (distance.c: a vertex's links 4 at a
 * time) gives the same bits as the scalar loop: the same cloths stepped with the vector
 * path and with the scalar loop forced, every position compared bit for bit after each
 * frame. The scenes reach what the lanes mask or blend: pinned corners, coincident
 * particles (a dead lane), padding lanes (vertices of 1 to 8 links), hard links (the
 * augmented Lagrangian's multipliers, rewritten each iteration), soft damped links (the
 * damped lanes) beside undamped ones in one group, 3 iterations, and 2 threads. */
#include <stdint.h>
#include <string.h>

#include "core/core.h"
#include "test.h"

int wb__distance_vbd_simd(int on); /* distance.c's internal switch for the VBD vertex step */

static wb_world *scene(int threads, int damped, int iterations)
{
    wb_world_def d = wb_world_default_def();
    d.threads = threads;
    d.substeps = 4;
    d.iterations = iterations;
    d.solver = WB_SOLVER_VBD;
    wb_world *w = wb_world_create(&d);
    if (!w) return NULL;
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
    c.res[0] = c.res[1] = 24;
    c.shear = true;
    if (damped) { c.link.compliance = 1e-5; c.link.damping = 0.3; }
    wb_body b;
    if (wb_cloth(w, &c, &b) != WB_OK) { wb_world_destroy(w); return NULL; }
    wb_particle_pin(w, b.first, NULL);
    wb_particle_pin(w, b.first + c.res[0] - 1, NULL);
    /* undamped hard links beside the damped ones: mixed lanes */
    l = wb_distance_default_def();
    for (int k = 0; k < 5; k++) { wb_distance_add(w, b.first + 30 + k, b.first + 80 + 3 * k, &l, &st); bad |= st != WB_OK; }
    if (bad) { wb_world_destroy(w); return NULL; }
    return w;
}

TEST(vbd_simd_bit_identical_to_scalar)
{
    CHECK_SIMD_RUNS(wb__distance_vbd_simd(1));
    const int cases[][3] = { { 1, 0, 1 }, { 1, 1, 1 }, { 1, 1, 3 }, { 2, 0, 3 }, { 2, 1, 1 } };
    for (size_t c = 0; c < sizeof cases / sizeof cases[0]; c++) {
        wb_world *v = scene(cases[c][0], cases[c][1], cases[c][2]), *s = scene(cases[c][0], cases[c][1], cases[c][2]);
        REQUIRE(v && s);
        int diff = 0;
        for (int f = 0; f < 30 && !diff; f++) {
            wb__distance_vbd_simd(1);
            CHECK_EQ(wb_world_step(v), WB_OK);
            wb__distance_vbd_simd(0);
            CHECK_EQ(wb_world_step(s), WB_OK);
            const int32_t n = wb_particle_count(v);
            diff = memcmp(wb_particle_positions(v), wb_particle_positions(s), sizeof(wb_real) * 3 * (size_t)n) != 0;
            if (diff) test_fail(__FILE__, __LINE__, "case %zu: positions differ after frame %d", c, f + 1);
        }
        wb_world_destroy(v);
        wb_world_destroy(s);
    }
    wb__distance_vbd_simd(1);
}
