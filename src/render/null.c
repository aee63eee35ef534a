/* null.c: the null backend: no context and no pixels, so tests of options,
 * recording and errors run without GL (frames come out as the background colour). */
#include <string.h>

#include "render.h"

static void *null_create(int w, int h, char *err, size_t n)
{
    (void)w, (void)h, (void)err, (void)n;
    static int token;
    return &token;
}

static bool null_current(void *ctx)
{
    (void)ctx;
    return true;
}

static const uint8_t *null_pixels(void *ctx)
{
    (void)ctx;
    return NULL;
}

static void null_destroy(void *ctx)
{
    (void)ctx;
}

const wb_backend wb_backend_null = { "null", false, null_create, null_current, null_pixels, null_destroy, false };

const wb_backend *wb_backend_find(const char *name)
{
    static const wb_backend *const all[] = { &wb_backend_osmesa, &wb_backend_null };
    for (size_t i = 0; i < sizeof all / sizeof *all; i++)
        if (!name || strcmp(all[i]->name, name) == 0) return all[i];   /* NULL: the default */
    return NULL;
}
