/* fxaa.h: the renderer's antialiasing on the CPU (fxaa.c). Private to the renderer. */
#ifndef WB_RENDER_FXAA_H
#define WB_RENDER_FXAA_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

/* rgba (w x h, stride w*4) antialiased into rgb (stride w*3) at and next to geometry
 * (alpha 255; the ground is drawn with alpha 128); where nothing was drawn (alpha 0) the
 * sky's colour of the row, sky[3 * row] (top first), when sky is not NULL. *scratch
 * (2 w h bytes, grown with realloc, *scratch_cap its size) holds the luma and the
 * geometry's mask. false: out of memory */
bool wb_fxaa(const uint8_t *rgba, int w, int h, const uint8_t *sky, uint8_t *rgb, uint8_t **scratch,
             size_t *scratch_cap);

#endif
