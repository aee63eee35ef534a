/* fxaa.h: the renderer's antialiasing on the CPU (fxaa.c). Private to the renderer. */
#ifndef WB_RENDER_FXAA_H
#define WB_RENDER_FXAA_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

/* rgba (w x h, stride w*4) antialiased into rgb (stride w*3) where alpha is not 0 or
 * next to it (geometry; the ground and the sky are drawn with alpha 0); *scratch (2 w h
 * bytes, grown with realloc, *scratch_cap its size) holds the luma and the alpha.
 * false: out of memory */
bool wb_fxaa(const uint8_t *rgba, int w, int h, uint8_t *rgb, uint8_t **scratch, size_t *scratch_cap);

#endif
