/* glfw.c: the window backend (GLFW 3) of `wobble view`. Like osmesa.c it only makes
 * the context: render.c draws and resolves into the window's back buffer, which
 * wb_window_swap presents. One window per process (the viewer's), so the window is
 * also reachable outside the renderer, for events and the overlay.
 *
 * GL calls here and in render.c go through the gl* symbols libOSMesa exports; both it
 * and GLX's Mesa driver dispatch through the shared libglapi, so they reach whichever
 * context is current (the window's, here). */
#define GL_GLEXT_PROTOTYPES
#include <GL/glcorearb.h>
#define GLFW_INCLUDE_NONE
#include <GLFW/glfw3.h>

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "render.h"

typedef struct win {
    GLFWwindow *win;
    int w, h;
    uint8_t *buf, *row;   /* the back buffer read back (RGBA, top row first), a row of scratch */
    GLuint tex, fbo;      /* wb_window_blit's image and the framebuffer reading it */
    int tex_w, tex_h;
} win;

static win *the_window;
static char glfw_error[512];
static const char *window_title = "wobble";

static void on_error(int code, const char *msg)
{
    (void)code;
    snprintf(glfw_error, sizeof glfw_error, "%s", msg);
}

void wb_window_set_title(const char *title)
{
    window_title = title;
    if (the_window) glfwSetWindowTitle(the_window->win, title);
}

bool wb_window_available(char *err, size_t n)
{
    glfwSetErrorCallback(on_error);
    if (glfwInit()) return true;
    const char *d = getenv("DISPLAY"), *wl = getenv("WAYLAND_DISPLAY");
    if ((!d || !*d) && (!wl || !*wl))
        snprintf(err, n, "no display: the viewer needs a window (DISPLAY is not set; on a machine without a "
                         "screen, run it under Xvfb: xvfb-run wobble view ...)");
    else snprintf(err, n, "cannot open a window on display %s: %s", d && *d ? d : wl,
                  glfw_error[0] ? glfw_error : "GLFW failed to start");
    return false;
}

static void bind(win *o);

static void win_destroy(void *p)
{
    win *o = p;
    if (!o) return;
    if (o->win) {
        bind(o);
        if (o->fbo) glDeleteFramebuffers(1, &o->fbo);
        if (o->tex) glDeleteTextures(1, &o->tex);
        glfwMakeContextCurrent(NULL);
        glfwDestroyWindow(o->win);
    }
    if (the_window == o) the_window = NULL;
    free(o->buf);
    free(o->row);
    free(o);
}

/* GLX skips a make-current of the context it thinks is current, but a scene's own
 * OSMesa renderer (wobble.renderer) may have taken the shared dispatch since: release
 * and bind again, so GL calls reach the window's context for sure */
static void bind(win *o)
{
    glfwMakeContextCurrent(NULL);
    glfwMakeContextCurrent(o->win);
}

static bool win_current(void *p)
{
    bind(p);
    return glfwGetCurrentContext() == ((win *)p)->win;
}

static void *win_create(int w, int h, char *err, size_t n)
{
    if (the_window) {
        snprintf(err, n, "the viewer has one window, and it is open");
        return NULL;
    }
    if (!wb_window_available(err, n)) return NULL;
    win *o = calloc(1, sizeof *o);
    if (o) o->buf = malloc((size_t)w * (size_t)h * 4), o->row = malloc((size_t)w * 4);
    if (!o || !o->buf || !o->row) {
        snprintf(err, n, "out of memory for a %dx%d window", w, h);
        win_destroy(o);
        return NULL;
    }
    o->w = w, o->h = h;
    glfwDefaultWindowHints();
    glfwWindowHint(GLFW_CONTEXT_VERSION_MAJOR, 3);
    glfwWindowHint(GLFW_CONTEXT_VERSION_MINOR, 3);
    glfwWindowHint(GLFW_OPENGL_PROFILE, GLFW_OPENGL_CORE_PROFILE);
    glfwWindowHint(GLFW_OPENGL_FORWARD_COMPAT, GLFW_TRUE);
    /* the renderer's frame has a fixed size: a resized window would stretch it */
    glfwWindowHint(GLFW_RESIZABLE, GLFW_FALSE);
    glfwWindowHint(GLFW_DEPTH_BITS, 0);   /* render.c draws into its own framebuffers */
    glfwWindowHint(GLFW_SAMPLES, 0);
    glfw_error[0] = 0;
    o->win = glfwCreateWindow(w, h, window_title, NULL, NULL);
    if (!o->win) {
        snprintf(err, n, "cannot open a %dx%d window with OpenGL 3.3 core: %s", w, h,
                 glfw_error[0] ? glfw_error : "unknown GLFW error");
        win_destroy(o);
        return NULL;
    }
    glfwMakeContextCurrent(o->win);
    glfwSwapInterval(0);   /* the viewer paces itself to the world's dt */
    the_window = o;
    return o;
}

/* the back buffer, which render.c just resolved into, top row first */
static const uint8_t *win_pixels(void *p)
{
    win *o = p;
    glBindFramebuffer(GL_READ_FRAMEBUFFER, 0);
    glReadBuffer(GL_BACK);
    glPixelStorei(GL_PACK_ALIGNMENT, 1);
    glReadPixels(0, 0, o->w, o->h, GL_RGBA, GL_UNSIGNED_BYTE, o->buf);
    const size_t stride = (size_t)o->w * 4;
    for (int y = 0; y < o->h / 2; y++) {
        uint8_t *a = o->buf + (size_t)y * stride, *b = o->buf + (size_t)(o->h - 1 - y) * stride;
        memcpy(o->row, a, stride);
        memcpy(a, b, stride);
        memcpy(b, o->row, stride);
    }
    return o->buf;
}

const wb_backend wb_backend_glfw = {
    "glfw", true, win_create, win_current, win_pixels, win_destroy, false,
};

void *wb_window_handle(void)
{
    return the_window ? the_window->win : NULL;
}

/* an RGB image (top row first) over the back buffer at pixel (x, y) from the top left:
 * a texture read through a framebuffer and blitted, flipped, so no shader is needed */
bool wb_window_blit(const uint8_t *rgb, int x, int y, int w, int h)
{
    win *o = the_window;
    if (!o || w < 1 || h < 1) return false;
    bind(o);
    if (!o->tex || w > o->tex_w || h > o->tex_h) {
        if (!o->tex) glGenTextures(1, &o->tex), glGenFramebuffers(1, &o->fbo);
        glBindTexture(GL_TEXTURE_2D, o->tex);
        glTexImage2D(GL_TEXTURE_2D, 0, GL_RGB8, w, h, 0, GL_RGB, GL_UNSIGNED_BYTE, NULL);
        glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_NEAREST);
        glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_NEAREST);
        o->tex_w = w, o->tex_h = h;
        glBindFramebuffer(GL_READ_FRAMEBUFFER, o->fbo);
        glFramebufferTexture2D(GL_READ_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_TEXTURE_2D, o->tex, 0);
    }
    glBindTexture(GL_TEXTURE_2D, o->tex);
    glPixelStorei(GL_UNPACK_ALIGNMENT, 1);
    glTexSubImage2D(GL_TEXTURE_2D, 0, 0, 0, w, h, GL_RGB, GL_UNSIGNED_BYTE, rgb);
    glBindFramebuffer(GL_READ_FRAMEBUFFER, o->fbo);
    glBindFramebuffer(GL_DRAW_FRAMEBUFFER, 0);
    glDrawBuffer(GL_BACK);
    /* texture row 0 is the image's top: drawn at the window's top (GL's y runs up) */
    glBlitFramebuffer(0, 0, w, h, x, o->h - y, x + w, o->h - y - h, GL_COLOR_BUFFER_BIT, GL_NEAREST);
    glBindFramebuffer(GL_FRAMEBUFFER, 0);
    glBindTexture(GL_TEXTURE_2D, 0);
    return glGetError() == GL_NO_ERROR;
}

void wb_window_swap(void)
{
    if (!the_window) return;
    bind(the_window);
    glfwSwapBuffers(the_window->win);
}

/* GLFW is left running (the process ends right after): glfwTerminate unloads the GL
 * driver (dlclose), and what the driver keeps until exit then shows up as leaks under
 * LeakSanitizer with no module left to name in a suppression */
void wb_window_terminate(void)
{
}
