/* layers_int.h: what layers.c and strain.c share (the renderer's insides, not an API) */
#ifndef WB_LAYERS_INT_H
#define WB_LAYERS_INT_H
#include <stdbool.h>
#include <stdlib.h>

#include "gl.h"
#include "render.h"

/* a link's or particle's colour at rest (sRGB): grey */
static const float col_rest[3] = { 0.40f, 0.40f, 0.42f };

/* per particle: on a drawn surface; covered by a drawn skin; in a volume, shape-matching
 * or pressure constraint (l->mstrain holds its strain) */
enum { F_SURFACE = 1, F_HIDDEN = 2, F_MATERIAL = 4, F_ON_SURFACE = 8 /* on any surface (wb_strain_auto) */ };

/* grow *p to hold n elements of size sz */
static inline bool wb_grow(void *pp, size_t *cap, size_t n, size_t sz)
{
    void **p = pp;
    if (n <= *cap) return true;
    size_t c = *cap ? *cap : 256;
    while (c < n) c *= 2;
    void *q = realloc(*p, c * sz);
    if (!q) return false;
    *p = q;
    *cap = c;
    return true;
}

/* strain.c: the strain colours (linear rest colour shading to red / blue, fully at
 * +-scale; sRGB for the particles) and each frame's strains */
void wb_strain_colour(double strain, double scale, const float rest[3], float out[3]);
void wb_strain_colour_srgb(double strain, double scale, float out[3]);
bool wb_strain_pairs(wb_layers *l, const wb_world *w);
bool wb_strain_materials(wb_layers *l, const wb_world *w);
bool wb_strain_auto(wb_layers *l, const wb_world *w, const wb_draw_opts *o);
void wb_strain_bends(wb_layers *l, const wb_world *w, double scale);

#endif
