/* test_tet_strain.c: wb_tet_strain (what the materials layer draws a Neo-Hookean tet by):
 * det F - 1 for a change of volume, the von Mises equivalent strain for one of shape. */
#include <math.h>

#include "wobble.h"
#include "test.h"

/* a unit right-angled tet deformed by the row-major F (corner 0 at the origin) */
static wb_real strain_of(const double F[9])
{
    wb_world_def d = wb_world_default_def();
    wb_world *w = wb_world_create(&d);
    if (!w) return NAN;
    const wb_real rest[4][3] = { { 0, 0, 0 }, { 1, 0, 0 }, { 0, 1, 0 }, { 0, 0, 1 } };
    int32_t p[4];
    for (int k = 0; k < 4; k++) p[k] = wb_particle_add(w, rest[k], NULL, 1, 0.1);
    wb_tet_def td = wb_tet_default_def();
    wb_real e = NAN;
    if (wb_tet_add(w, p, &td) == 0) {
        for (int k = 1; k < 4; k++) {
            wb_real x[3];
            for (int r = 0; r < 3; r++) x[r] = (wb_real)F[3 * r + (k - 1)];
            wb_particle_set_position(w, p[k], x);
        }
        e = wb_tet_strain(w, 0);
    }
    wb_world_destroy(w);
    return e;
}

TEST(tet_strain_volume_shape_and_shear)
{
    const double I[9] = { 1, 0, 0, 0, 1, 0, 0, 0, 1 };
    CHECK_NEAR(strain_of(I), 0, 1e-12);
    const double grow[9] = { 1.1, 0, 0, 0, 1.1, 0, 0, 0, 1.1 };   /* volume only: det F - 1 */
    CHECK_NEAR(strain_of(grow), 1.331 - 1, 1e-9);
    const double squash[9] = { 1, 0, 0, 0, 1, 0, 0, 0, 0.9 };    /* volume dominates: negative */
    CHECK_NEAR(strain_of(squash), -0.1, 1e-9);
    /* a volume-keeping uniaxial stretch of e: about e (exactly its isochoric Green strain) */
    const double s = 1.05, q = 1 / sqrt(1.05);
    const double uni[9] = { s, 0, 0, 0, q, 0, 0, 0, q };
    CHECK_NEAR(strain_of(uni), 0.05, 0.01);
    /* a shear of k keeps det F = 1 but is seen: about k / sqrt(3), positive */
    const double k = 0.1, shear[9] = { 1, k, 0, 0, 1, 0, 0, 0, 1 };
    CHECK_NEAR(strain_of(shear), k / sqrt(3), 0.005);
}
