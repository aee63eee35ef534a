/* osmesa.c: the OSMesa backend (Mesa's llvmpipe, no display, no GPU). It only
 * makes the context: everything drawn goes through render.c's framebuffers and is
 * resolved into the buffer this file owns. When Mesa drops OSMesa, an EGL backend
 * (surfaceless + pbuffer) is a file of the same shape. */
#include <GL/osmesa.h>

#include <stdio.h>
#include <stdlib.h>

#include "render.h"

typedef struct osm {
    OSMesaContext ctx;
    int w, h;
    uint8_t *buf;   /* w x h RGBA, the context's default framebuffer */
} osm;

static void osm_destroy(void *p)
{
    osm *o = p;
    if (!o) return;
    if (o->ctx) OSMesaDestroyContext(o->ctx);
    free(o->buf);
    free(o);
}

static bool osm_current(void *p)
{
    osm *o = p;
    return OSMesaMakeCurrent(o->ctx, o->buf, GL_UNSIGNED_BYTE, o->w, o->h) == GL_TRUE;
}

static void *osm_create(int w, int h, char *err, size_t n)
{
    osm *o = calloc(1, sizeof *o);
    if (o) o->buf = malloc((size_t)w * (size_t)h * 4);
    if (!o || !o->buf) {
        snprintf(err, n, "out of memory for a %dx%d frame", w, h);
        osm_destroy(o);
        return NULL;
    }
    o->w = w;
    o->h = h;
    /* a core profile is what the shaders are written for: no compatibility fallback,
     * since Mesa without it would not run them anyway */
    const int attrs[] = { OSMESA_FORMAT, OSMESA_RGBA, OSMESA_DEPTH_BITS, 24, OSMESA_STENCIL_BITS, 0,
                          OSMESA_ACCUM_BITS, 0, OSMESA_PROFILE, OSMESA_CORE_PROFILE,
                          OSMESA_CONTEXT_MAJOR_VERSION, 3, OSMESA_CONTEXT_MINOR_VERSION, 3, 0 };
    o->ctx = OSMesaCreateContextAttribs(attrs, NULL);
    if (!o->ctx) {
        snprintf(err, n, "OSMesa cannot create an OpenGL 3.3 core context (Mesa too old or built "
                         "without llvmpipe?); use backend = \"null\" for no pixels");
        osm_destroy(o);
        return NULL;
    }
    if (!osm_current(o)) {
        snprintf(err, n, "OSMesa cannot make a %dx%d context current", w, h);
        osm_destroy(o);
        return NULL;
    }
    /* row 0 of the buffer is the top of the image: no flip later */
    OSMesaPixelStore(OSMESA_Y_UP, 0);
    return o;
}

static const uint8_t *osm_pixels(void *p)
{
    return ((osm *)p)->buf;
}

const wb_backend wb_backend_osmesa = {
    "osmesa", true, osm_create, osm_current, osm_pixels, osm_destroy, true,
};
