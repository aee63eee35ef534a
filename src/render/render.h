/* render.h: rendering and media. Not part of the core, so the core stays free of GL: the
 * renderer reads a world through the public API of wobble.h only.
 *
 *   wb_renderer   an OpenGL 3.3 core pipeline (render.c, gl.c) behind a
 *                 backend that only makes a context (osmesa.c; null.c
 *                 for tests that need no pixels)
 *   wb_image_*    PNG files (media.c, stb_image_write)
 *   wb_recorder   MP4 / GIF through the ffmpeg program, or a folder of PNGs
 *   wb_media_*    facts and frames of a video through ffprobe / ffmpeg (probe.c)
 *   wb_plot       energy / strain charts as PNG (plot.c)
 *
 * Images are RGB8, top row first, stride width*3. Errors: functions that can fail
 * return false (or NULL) and write a message into err[n]. */
#ifndef WB_RENDER_H
#define WB_RENDER_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>
#include <sys/types.h>

#include "wobble.h"

#define WB_RENDER_MAX_SIZE 8192   /* width and height */

/* ---- backends: context creation only ------------------------------------------- */
typedef struct wb_backend {
    const char *name;
    bool gl;   /* false: no GL at all (the null backend): frames are the background */
    /* a current GL 3.3 core context with a w x h RGBA8 default framebuffer */
    void *(*create)(int w, int h, char *err, size_t n);
    bool (*make_current)(void *ctx);
    /* after glFinish: the default framebuffer, RGBA8, top row first (stride w*4) */
    const uint8_t *(*pixels)(void *ctx);
    void (*destroy)(void *ctx);
    /* the default framebuffer has a depth buffer: with one sample the renderer draws
     * into it (no framebuffer of its own to copy from) */
    bool depth;
} wb_backend;

extern const wb_backend wb_backend_osmesa;
extern const wb_backend wb_backend_null;
const wb_backend *wb_backend_find(const char *name);   /* "osmesa", "null"; NULL when unknown */

/* the window of `wobble view` (glfw.c): one per process, made by the backend's create.
 * wb_window_available starts GLFW: false with a message (no display, ...) */
extern const wb_backend wb_backend_glfw;
bool wb_window_available(char *err, size_t n);
void wb_window_set_title(const char *title);
void *wb_window_handle(void);   /* the GLFWwindow, NULL when none is open */
/* an RGB image (top row first) over the back buffer with its top left at pixel (x, y) */
bool wb_window_blit(const uint8_t *rgb, int x, int y, int w, int h);
void wb_window_swap(void);      /* present the back buffer */
void wb_window_terminate(void); /* end GLFW once the window is closed */

/* ---- the renderer ----------------------------------------------------------------- */
typedef struct wb_renderer wb_renderer;

typedef struct wb_draw_opts {
    bool particles, constraints, colliders, surfaces, skins, pins, grid;
    bool cage;             /* also the particles, links and surfaces a drawn skin covers */
    double strain_scale;   /* |strain| drawn fully red (tension) / blue (compression) */
    double line_width;     /* pixels at 720 rows; scaled with the height */
    bool materials;        /* tint the particles and surfaces of volume, shape-matching and
                              pressure bodies by their strain (layers.c) */
    bool rigids;           /* rigid bodies, as shaded solids in their own colour */
    bool strain_auto;      /* strain_scale chosen per frame (layers.c, wb_strain_auto): the 95th
                              percentile of |strain|, at least 0.5 %, eased over frames */
    bool legend;           /* a colour bar with its numbers when strain colours are shown */
} wb_draw_opts;

/* every layer on but the cage, the automatic strain scale (strain_scale 0.02 when it
 * is switched off), line_width 1.5, the legend */
wb_draw_opts wb_draw_default_opts(void);

wb_renderer *wb_renderer_create(const wb_backend *be, int width, int height, int samples, char *err, size_t n);
void wb_renderer_destroy(wb_renderer *r);
/* about how many bytes such a renderer's buffers take (its frame, the backend's, the
 * multisample target, the shadow map), for a memory budget */
size_t wb_renderer_bytes(const wb_backend *be, int width, int height, int samples);
void wb_renderer_size(const wb_renderer *r, int *width, int *height);
int wb_renderer_samples(const wb_renderer *r);            /* MSAA samples in use (1 = none) */
/* FXAA on the frame drawn (fxaa.c): the cheap antialiasing of one sample, for recordings
 * (about 2 ms a 720p frame on the CPU against 20 for 4 samples on llvmpipe); off by default */
void wb_renderer_set_fxaa(wb_renderer *r, bool on);
bool wb_renderer_fxaa(const wb_renderer *r);
const char *wb_renderer_info(const wb_renderer *r);       /* "OpenGL 4.5 (Core Profile) Mesa ..., llvmpipe" */
/* a fixed camera (fov: vertical, degrees); wb_renderer_auto_camera goes back to the
 * default, which keeps all of the world drawn in the frame: its box grows with the
 * scene at once and shrinks eased; drawing another world (or the same one restarted,
 * its frame count lower) frames afresh */
void wb_renderer_camera(wb_renderer *r, const double eye[3], const double target[3], const double up[3], double fov);
void wb_renderer_auto_camera(wb_renderer *r);
/* a skinned mesh to draw with the world (the skins belong to the Lua side): deformed
 * vertices and normals (nv x 3), triangles (nt x 3), the skin */
typedef struct wb_draw_skin {
    const wb_real *v, *n;
    const int32_t *tri;
    int32_t nv, nt;
    const wb_skin *skin;   /* the particles it is bound to are hidden unless opts.cage; may be NULL */
} wb_draw_skin;
bool wb_renderer_draw(wb_renderer *r, const wb_world *w, const wb_draw_opts *o, const wb_draw_skin *skins,
                      int nskins, char *err, size_t n);
/* for a memory budget: about how many bytes drawing w takes (what it draws, on the CPU
 * and in GL's buffers), before drawing; and what the renderer holds for that after */
size_t wb_renderer_draw_bytes(const wb_renderer *r, const wb_world *w, const wb_draw_skin *skins, int nskins);
size_t wb_renderer_draw_held(const wb_renderer *r);
/* the strain drawn fully red / blue in the last frame (strain_scale, or the automatic
 * one); 0 when no strain colour was shown */
double wb_renderer_strain_scale(const wb_renderer *r);
const uint8_t *wb_renderer_pixels(const wb_renderer *r);  /* the last frame, RGB */
/* world point -> pixel coordinates of the last frame (x right, y down, pixel (i,j)
 * covers [i,i+1) x [j,j+1)); false when behind the camera or nothing drawn yet */
bool wb_renderer_project(const wb_renderer *r, const double p[3], double *x, double *y, double *depth);
/* the camera of the last frame */
void wb_renderer_get_camera(const wb_renderer *r, double eye[3], double target[3], double up[3], double *fov);

/* ---- images ------------------------------------------------------------------------ */
/* a PNG file's bytes in memory (malloc'd, free()); NULL when out of memory */
void *wb_image_encode_png(const uint8_t *rgb, int w, int h, size_t *n);
/* RGB8 pixels of a PNG (malloc'd, free()), NULL with a message */
uint8_t *wb_image_read_png(const char *path, int *w, int *h, char *err, size_t n);
/* from the PNG's header alone: its size and about how many bytes wb_image_read_png takes
 * at its peak (its result included), so a small file claiming a huge image can be refused
 * before it is decoded; 0 when the header cannot be read */
size_t wb_image_png_bytes(const char *path, int *w, int *h);

/* ---- recording ---------------------------------------------------------------------- */
typedef enum wb_media { WB_MEDIA_NONE = 0, WB_MEDIA_MP4, WB_MEDIA_GIF, WB_MEDIA_FOLDER } wb_media;
typedef struct wb_recorder wb_recorder;

/* what a name records to, decided by the name the user gave (a symlink's target may be
 * called anything): .mp4 (H.264), .gif, a folder (ends in '/', has no extension, or
 * `path`, where the name resolves to (NULL: the name itself), exists as one);
 * WB_MEDIA_NONE with a message for anything else */
wb_media wb_media_of(const char *given, const char *path, char *err, size_t n);
/* Where a recording's bytes go; the caller makes and checks the destination (the
 * renderer writes no file of its own). A folder: write_frame(ud, "frame_NNNNNN.png",
 * bytes) for each frame, called on the writer thread, false with a message. A video:
 * the encoder writes the file encode_to (copied) */
typedef struct wb_media_out {
    void *ud;
    bool (*write_frame)(void *ud, const char *name, const void *data, size_t n, char *err, size_t en);
    const char *encode_to;
} wb_media_out;
/* record `kind` (from wb_media_of) of the file or folder path (the name messages show)
 * into out; the encoder starts with the first frame */
wb_recorder *wb_recorder_open(const char *path, wb_media kind, int w, int h, const wb_media_out *out, char *err,
                              size_t n);
/* about how many bytes a recording of w x h frames holds: the queued frames and, for a
 * video, the ffmpeg encoding it (its peak resident memory, measured; its thread count is
 * fixed, at most 4, so that this holds on any machine) */
size_t wb_recorder_bytes(wb_media kind, int w, int h);
/* frames per second of the file; settable until the first frame (default 60) */
void wb_recorder_set_fps(wb_recorder *rec, double fps);
bool wb_recorder_started(const wb_recorder *rec);
/* queue one frame (copied): encoding runs on a thread while the caller simulates */
bool wb_recorder_add(wb_recorder *rec, const uint8_t *rgb, char *err, size_t n);
int64_t wb_recorder_frames(const wb_recorder *rec);
const char *wb_recorder_path(const wb_recorder *rec);
/* finish the file (waits for the encoder, checks its exit status) and free rec;
 * false with a message when anything failed on the way. NULL is fine. */
bool wb_recorder_close(wb_recorder *rec, char *err, size_t n);

/* media facts through ffprobe (or the PNG header): frames, size, codec, duration in
 * seconds as players will see it (0 for a PNG) */
typedef struct wb_media_info {
    int width, height;
    int64_t frames;
    double duration;
    char codec[32], pix_fmt[32];
} wb_media_info;
/* `stop` (may be NULL) is asked while ffprobe / ffmpeg runs, which can be forever (a
 * FIFO, a live stream): when fn(ud) answers true the helper is killed and the call
 * fails (the Lua side passes the script's budgets, wb_rt_interrupt) */
typedef struct wb_media_stop { int (*fn)(void *ud); void *ud; } wb_media_stop;
bool wb_media_probe(const char *path, wb_media_info *info, const wb_media_stop *stop, char *err, size_t n);
/* frame `index` (0 first) of a video decoded by ffmpeg: RGB8, top row first (malloc'd,
 * free()), NULL with a message. For tests that compare a file with what was drawn.
 * *w x *h (> 0) is the size expected (wb_media_frame_size): a frame of another size is
 * refused; 0 x 0: any size */
uint8_t *wb_media_read_frame(const char *path, int64_t index, const wb_media_stop *stop, int *w, int *h, char *err,
                             size_t n);
/* the frame size of a video (its first video stream) or PNG from its header, nothing
 * decoded (ffprobe for a video); false with a message */
bool wb_media_frame_size(const char *path, const wb_media_stop *stop, int *w, int *h, char *err, size_t n);
/* about what wb_media_read_frame of a w x h frame takes at its peak, ffmpeg included;
 * what ffprobe or ffmpeg alone takes decoding such frames (0 x 0: started, no frame) */
size_t wb_media_frame_bytes(int w, int h);
size_t wb_media_helper_bytes(int w, int h);

/* start prog (found through PATH) with argv, its stdin, stdout and stderr the
 * descriptors fds[0..2] (-1: /dev/null) and no other descriptor of ours; SIGPIPE
 * default, no signal blocked; in a process group of its own when `group`. Returns 0
 * or an errno (ENOENT: no such program). probe.c; the recorder uses it too. */
int wb_spawn(const char *prog, const char *const argv[], const int fds[3], bool group, pid_t *pid);

/* ---- plots --------------------------------------------------------------------------- */
typedef struct wb_plot wb_plot;
wb_plot *wb_plot_create(void);
void wb_plot_destroy(wb_plot *p);
bool wb_plot_sample(wb_plot *p, const wb_world *w);   /* false: out of memory */
int64_t wb_plot_samples(const wb_plot *p);
/* chart of kinetic, potential and total energy, maximum strain and constraint
 * error (RMS |length - rest|) over time, as a w x h RGB image (malloc'd) */
uint8_t *wb_plot_render(const wb_plot *p, int w, int h, const char *title);

/* a round step near x > 0: 1, 2 or 5 times a power of ten (axis ticks, grid lines) */
double wb_nice_step(double x);

/* draw text into an RGB image with stb_easy_font (scale 1 = about 6 x 11 pixels) */
void wb_text(uint8_t *rgb, int w, int h, int x, int y, const char *s, const uint8_t colour[3], int scale);
int wb_text_width(const char *s, int scale);
/* the charts' raster helpers, for other charts (wobble collect --plot): a filled
 * rectangle [x0, x1) x [y0, y1), an anti-aliased 2-pixel line, a tick label for a
 * value on an axis whose ticks are `step` apart */
void wb_chart_rect(uint8_t *rgb, int w, int h, int x0, int y0, int x1, int y1, const uint8_t colour[3]);
void wb_chart_line(uint8_t *rgb, int w, int h, double x0, double y0, double x1, double y1, const uint8_t colour[3]);
void wb_chart_label(char *buf, size_t n, double v, double step);

/* ---- the Lua side (lua/renderer.c, lua/plot.c) --------------------------------------- */
typedef struct lua_State lua_State;
void wbl_open_renderer(lua_State *L);   /* wobble.renderer, probe, read_png, read_frame, clock */
/* `wobble run --record OUT`: every frame any w:run / w:step makes is drawn (the scene's
 * camera, every layer) and added to OUT, a path of the user's choice; frames of w x h
 * pixels (--size), or with w = 0 the default: 1280x720, a .gif 640x360 (for the web);
 * drawn with `samples` (--samples; 1: no antialiasing), or with 0 the default: one
 * sample and FXAA */
#define WB_RECORD_WIDTH 1280
#define WB_RECORD_HEIGHT 720
#define WB_RECORD_GIF_WIDTH 640
#define WB_RECORD_GIF_HEIGHT 360
bool wbl_record_begin(lua_State *L, const char *path, int w, int h, int samples, char *err, size_t n);
bool wbl_record_end(lua_State *L, char *err, size_t n);   /* finish the file; prints where it went */
/* the camera the scene set with wobble.camera{...}; false when it left the framing automatic */
bool wbl_scene_camera(lua_State *L, double eye[3], double target[3], double up[3], double *fov);
/* the live skins of the world at world_index, ready to draw (Lua userdata left on the
 * stack, collected with it); *n their count (the viewer draws with it too) */
wb_draw_skin *wbl_world_skins(lua_State *L, int world_index, int *n);
/* w:run{plot = path}: push a plot sampler for the path in field `key` of the options
 * at `opts` (nil when absent; the path is checked through the sandbox now, and the
 * world's state sampled); sample after each frame; write the PNG when the run ends */
void wbl_open_plot(lua_State *L);   /* called by wbl_open_renderer */
void wbl_plot_push(lua_State *L, int opts, const char *key, int world);
void wbl_plot_frame(lua_State *L, int plot, int world);
void wbl_plot_finish(lua_State *L, int plot);

#endif
