/* material.c: named material presets (wb_material_preset): measured figures a builder
 * turns into its constraints' parameters (the conversions are the binding's and the
 * builders', docs/physics.md "Material presets"). Sources per row; `damping` is a Kelvin-Voigt viscosity
 * eta = tan(delta) E / omega at omega = 2 pi 10 Hz (the wobble of a scene-sized body),
 * tan(delta) the loss factor quoted in the row's comment. */
#include <string.h>

#include "wobble.h"

static const wb_material presets[] = {
    /* soft vulcanised natural rubber (Shore A ~40): E 1.5-5 MPa, nu 0.49-0.5 (Gent,
     * "Engineering with Rubber", 3rd ed. 2012, ch. 1-2), density 1100-1200 (ibid.),
     * loss factor 0.1-0.3 (filled compounds; ibid. ch. 3), friction on dry surfaces 0.6-1
     * (Persson, "Sliding Friction", 2000) */
    { "rubber", 2e6, 0.49, 1100, 0.2 * 2e6 / 62.83, 0.8, 0.01 },
    /* gelatin-like gel (a few % gelatin, a dessert jelly): E 1-30 kPa (Czerner et al. 2015,
     * J. Food Eng. 149; Markidou et al. 2005), nearly incompressible (nu 0.45-0.5),
     * density of water, loss factor ~0.2 taken at the top of the quoted G''/G' 0.05-0.2,
     * friction of a wet gel 0.1-0.5 (Gong 2006, Soft Matter 2) */
    { "jelly", 1e4, 0.45, 1030, 0.2 * 1e4 / 62.83, 0.3, 0.01 },
    /* flexible open-cell polyurethane foam (cushions): E 10 kPa-1 MPa at 20-60 kg/m^3,
     * nu ~0.3 (Gibson & Ashby, "Cellular Solids", 2nd ed. 1997, ch. 5 and table 5.1),
     * loss factor 0.2-0.5 (viscoelastic foams up to 1), friction ~0.6 */
    { "foam", 5e4, 0.3, 40, 0.4 * 5e4 / 62.83, 0.6, 0.01 },
    /* woven cotton shirting: areal density 100-200 g/m^2 at ~0.5 mm (density 300 kg/m^3),
     * tensile stiffness per width E t of a few kN/m (Kawabata KES-F data, Kawabata 1980,
     * "The standardization and analysis of hand evaluation"), loss factor ~0.1, friction
     * cotton on cotton 0.3-0.6 */
    { "cloth", 1e7, 0.3, 300, 0.1 * 1e7 / 62.83, 0.5, 0.0005 },
    /* vegetable-tanned cattle leather ~1.5 mm: E 20-100 MPa in tension, density 800-1000
     * kg/m^3 (Covington, "Tanning Chemistry", 2009, ch. 1; Ashby, "Materials Selection
     * in Mechanical Design", 4th ed., leather bubble: E 0.1-0.5 GPa, rho 810-1050),
     * loss factor ~0.15, friction leather on wood or metal 0.3-0.6 */
    { "leather", 5e7, 0.4, 860, 0.15 * 5e7 / 62.83, 0.5, 0.0015 },
    /* stranded steel wire rope, 10 mm: E of the rope 90-110 GPa (steel 200 GPa; the strands'
     * helix halves it), mass 0.0036 d^2 kg/m for d in mm (Feyrer, "Wire Ropes", 2nd ed.
     * 2015, ch. 1-3): 0.36 kg/m, density 4600 over the nominal circle; loss factor ~0.02;
     * friction greased rope on a steel sheave 0.1-0.2 */
    { "steel_cable", 1e11, 0.3, 4600, 0.02 * 1e11 / 62.83, 0.15, 0.01 },
};

int32_t wb_material_count(void) { return (int32_t)(sizeof presets / sizeof presets[0]); }

const wb_material *wb_material_at(int32_t i) { return i >= 0 && i < wb_material_count() ? &presets[i] : NULL; }

const wb_material *wb_material_preset(const char *name)
{
    for (int32_t i = 0; name && i < wb_material_count(); i++)
        if (strcmp(presets[i].name, name) == 0) return &presets[i];
    return NULL;
}
