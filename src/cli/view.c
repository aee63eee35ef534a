/* view.c: `wobble view SCENE.lua`: the scene live in a window. Like `run --record`, the
 * script needs no change: a frame hook draws every frame of w:run / w:step through the same
 * renderer (glfw.c's window backend), paces it to the world's dt and polls the window's
 * events. Esc, closing the window, R and a saved file (--watch) cut the script short with
 * an error whose value is a marker (stop_key) that the viewer treats as a normal end; a
 * restart is a new Lua state with the camera kept. Grabs go through lua/input.h so
 * --record-input can save them for `run --replay`. */
#define GLFW_INCLUDE_NONE
#include <GLFW/glfw3.h>

#include <errno.h>
#include <lauxlib.h>
#include <limits.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <time.h>
#include <unistd.h>

#include "cli/view.h"
#include "lua/input.h"
#include "lua/mesh.h"
#include "lua/util.h"
#include "lua/wobble_lua.h"
#include "render/render.h"

#define MAX_WATCH 64

typedef struct watched {
    char path[PATH_MAX];
    struct timespec mtime;
    off_t size;
    bool exists;
} watched;

typedef struct viewer {
    const wb_view_opts *o;
    wb_renderer *r;
    GLFWwindow *win;
    int W, H, text_scale;
    uint8_t *frame;            /* the picture shown: the renderer's frame and the overlay */
    bool drawn;                /* the renderer drew a frame (else the picture is the background) */
    wbl_input_log *log;
    /* this run of the scene */
    lua_State *L;
    wbl_world *world;          /* the world shown (its userdata, anchored in the registry so
                                * a w:close() leaves w NULL, not dangling): the first that
                                * finished a frame, the next to step once the script closes it */
    int world_ord;
    bool running;              /* inside the script (grabs possible), not after its end */
    int64_t frames_shown;
    bool paused, step_once, quit, restart, reload, dirty;
    int exit_code;             /* os.exit's code (--unsafe), else 0 */
    char error[2048];          /* the script's error (--watch), shown until the next run */
    char note[256];            /* a one-line message (a grab refused, a screenshot written) */
    double last_present, fps;
    /* the camera: the renderer's default (following the scene) until the mouse moves it */
    bool cam_fixed;
    bool scene_cam;            /* the last frame drawn with the scene's camera (wobble.camera) */
    double eye[3], target[3], up[3], fov;
    /* the mouse: 0 none, 1 orbit, 2 pan, 3 grab */
    int drag;
    double mx, my;
    wb_grab_id grab;
    int32_t grabbed;           /* the particle held, -1 none */
    double plane_p[3], plane_n[3];
    /* --watch */
    watched files[MAX_WATCH];
    int nfiles;
    double last_check;
} viewer;

static viewer V;
static const char stop_key = 0;     /* the error value that ends a run on purpose */
static const char world_key = 0;    /* registry: the world shown, kept alive for the end */

static double now(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + ts.tv_nsec * 1e-9;
}

static bool stopping(void)
{
    return V.quit || V.restart || V.reload;
}

/* the world shown, NULL when none or the script closed it */
static wb_world *shown(void)
{
    return V.world ? V.world->w : NULL;
}

/* ---- vectors -------------------------------------------------------------------------- */
static double dot3(const double a[3], const double b[3]) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }
static void cross3(const double a[3], const double b[3], double o[3])
{
    o[0] = a[1] * b[2] - a[2] * b[1], o[1] = a[2] * b[0] - a[0] * b[2], o[2] = a[0] * b[1] - a[1] * b[0];
}
static double norm3(double a[3])
{
    double l = sqrt(dot3(a, a));
    if (l > 0) a[0] /= l, a[1] /= l, a[2] /= l;
    return l;
}

/* the camera's frame: forward, right, up (unit) and tan(fov/2) */
static void cam_frame(const double eye[3], const double target[3], const double up[3], double fov, double f[3],
                      double r[3], double u[3], double *th)
{
    for (int k = 0; k < 3; k++) f[k] = target[k] - eye[k];
    norm3(f);
    cross3(f, up, r);
    if (norm3(r) < 1e-12) r[0] = 1, r[1] = r[2] = 0;
    cross3(r, f, u);
    *th = tan(fov * M_PI / 360);
}

/* ---- the camera ------------------------------------------------------------------------- */
static bool cam_take(void)
{
    if (V.cam_fixed) return true;
    if (!V.drawn) return false;
    wb_renderer_get_camera(V.r, V.eye, V.target, V.up, &V.fov);
    V.up[0] = 0, V.up[1] = 1, V.up[2] = 0;   /* orbiting keeps the world's up */
    V.cam_fixed = true;
    return true;
}

static void cam_set(void)
{
    wb_renderer_camera(V.r, V.eye, V.target, V.up, V.fov);
    V.dirty = true;
}

static void orbit(double dx, double dy)
{
    if (!cam_take()) return;
    double v[3] = { V.eye[0] - V.target[0], V.eye[1] - V.target[1], V.eye[2] - V.target[2] };
    double d = sqrt(dot3(v, v));
    if (!(d > 0)) return;
    double yaw = atan2(v[0], v[2]) - dx * 0.01, pitch = asin(fmax(-1, fmin(1, v[1] / d))) + dy * 0.01;
    pitch = fmax(-1.55, fmin(1.55, pitch));
    V.eye[0] = V.target[0] + d * cos(pitch) * sin(yaw);
    V.eye[1] = V.target[1] + d * sin(pitch);
    V.eye[2] = V.target[2] + d * cos(pitch) * cos(yaw);
    cam_set();
}

static void pan(double dx, double dy)
{
    if (!cam_take()) return;
    double f[3], r[3], u[3], th;
    cam_frame(V.eye, V.target, V.up, V.fov, f, r, u, &th);
    double v[3] = { V.eye[0] - V.target[0], V.eye[1] - V.target[1], V.eye[2] - V.target[2] };
    double s = 2 * sqrt(dot3(v, v)) * th / V.H;   /* world units per pixel at the target */
    for (int k = 0; k < 3; k++) {
        double m = (-dx * r[k] + dy * u[k]) * s;
        V.eye[k] += m, V.target[k] += m;
    }
    cam_set();
}

static void zoom(double steps)
{
    if (!cam_take()) return;
    double s = pow(0.88, steps);
    for (int k = 0; k < 3; k++) V.eye[k] = V.target[k] + (V.eye[k] - V.target[k]) * s;
    cam_set();
}

/* the ray through window pixel (x, y) with the last frame's camera */
static bool pick_ray(double x, double y, double o[3], double d[3], double f[3], double *px_size)
{
    if (!V.drawn) return false;
    double eye[3], target[3], up[3], fov, r[3], u[3], th;
    wb_renderer_get_camera(V.r, eye, target, up, &fov);
    cam_frame(eye, target, up, fov, f, r, u, &th);
    double sx = (2 * x / V.W - 1) * th * V.W / V.H, sy = (1 - 2 * y / V.H) * th;
    for (int k = 0; k < 3; k++) o[k] = eye[k], d[k] = f[k] + sx * r[k] + sy * u[k];
    norm3(d);
    *px_size = 2 * th / V.H;   /* a pixel's size at unit depth */
    return true;
}

/* ---- grabbing ------------------------------------------------------------------------------ */
static double ray_sphere(const double o[3], const double d[3], const double c[3], double rad)
{
    double oc[3] = { o[0] - c[0], o[1] - c[1], o[2] - c[2] };
    double b = dot3(oc, d), q = dot3(oc, oc) - rad * rad, disc = b * b - q;
    if (disc < 0) return INFINITY;
    double s = sqrt(disc), t = -b - s;
    if (t < 0) t = -b + s;
    return t > 0 ? t : INFINITY;
}

static double ray_triangle(const double o[3], const double d[3], const double a[3], const double b[3],
                           const double c[3])
{
    double e1[3], e2[3], p[3], s[3], q[3];
    for (int k = 0; k < 3; k++) e1[k] = b[k] - a[k], e2[k] = c[k] - a[k], s[k] = o[k] - a[k];
    cross3(d, e2, p);
    double det = dot3(e1, p);
    if (fabs(det) < 1e-300) return INFINITY;
    double u = dot3(s, p) / det;
    if (u < 0 || u > 1) return INFINITY;
    cross3(s, e1, q);
    double v = dot3(d, q) / det;
    if (v < 0 || u + v > 1) return INFINITY;
    double t = dot3(e2, q) / det;
    return t > 0 ? t : INFINITY;
}

static void pos(const wb_world *w, int32_t p, double out[3])
{
    wb_real x[3];
    wb_particle_position(w, p, x);
    out[0] = x[0], out[1] = x[1], out[2] = x[2];
}

/* the particle under window pixel (x, y): the nearest hit of a ray against the particles'
 * spheres (at least a few pixels wide) and the surfaces' triangles (the triangle's
 * particle nearest the hit); -1 for none. *hit_t: the distance along the ray */
static int32_t pick(double x, double y, double *hit_t)
{
    double o[3], d[3], f[3], px;
    const wb_world *w = shown();
    if (!w || !pick_ray(x, y, o, d, f, &px)) return -1;
    int32_t best = -1, n = wb_particle_count(w);
    double bt = INFINITY;
    for (int32_t i = 0; i < n; i++) {
        double c[3];
        pos(w, i, c);
        double depth = (c[0] - o[0]) * f[0] + (c[1] - o[1]) * f[1] + (c[2] - o[2]) * f[2];
        if (!(depth > 0)) continue;
        double t = ray_sphere(o, d, c, fmax(wb_particle_radius(w, i), 5 * px * depth));
        if (t < bt) bt = t, best = i;
    }
    for (int32_t s = 0; s < wb_surface_count(w); s++) {
        int32_t nt;
        const int32_t *tri = wb_surface_triangles(w, s, &nt);
        for (int32_t k = 0; tri && k < nt; k++) {
            double a[3], b[3], c[3];
            pos(w, tri[3 * k], a), pos(w, tri[3 * k + 1], b), pos(w, tri[3 * k + 2], c);
            double t = ray_triangle(o, d, a, b, c);
            if (!(t < bt)) continue;
            double h[3] = { o[0] + t * d[0], o[1] + t * d[1], o[2] + t * d[2] }, dm = INFINITY;
            for (int j = 0; j < 3; j++) {
                double q[3];
                pos(w, tri[3 * k + j], q);
                double e[3] = { q[0] - h[0], q[1] - h[1], q[2] - h[2] };
                if (dot3(e, e) < dm) dm = dot3(e, e), best = tri[3 * k + j];
            }
            bt = t;
        }
    }
    *hit_t = bt;
    return best;
}

static void grab_start(double x, double y)
{
    double t;
    int32_t p = pick(x, y, &t);
    if (p < 0) {
        V.drag = 1;   /* empty space: orbit */
        return;
    }
    double o[3], d[3], f[3], px;
    pick_ray(x, y, o, d, f, &px);
    pos(shown(), p, V.plane_p);   /* the plane facing the camera through the particle */
    for (int k = 0; k < 3; k++) V.plane_n[k] = f[k];
    wb_real target[3] = { V.plane_p[0], V.plane_p[1], V.plane_p[2] };
    char err[256];
    if (!wbl_input_grab(V.log, shown(), V.world_ord, p, target, 0, &V.grab, err, sizeof err)) {
        snprintf(V.note, sizeof V.note, "%s", err);
        V.drag = 0;
        V.dirty = true;
        return;
    }
    V.grabbed = p;
    V.drag = 3;
    V.note[0] = 0;
    V.dirty = true;
}

static void grab_move(double x, double y)
{
    double o[3], d[3], f[3], px;
    if (!pick_ray(x, y, o, d, f, &px)) return;
    double den = dot3(d, V.plane_n);
    if (fabs(den) < 1e-9) return;
    double q[3] = { V.plane_p[0] - o[0], V.plane_p[1] - o[1], V.plane_p[2] - o[2] };
    double t = dot3(q, V.plane_n) / den;
    if (!(t > 0)) return;
    wb_real target[3] = { o[0] + t * d[0], o[1] + t * d[1], o[2] + t * d[2] };
    if (!shown()) return;   /* the script closed the world */
    wbl_input_move(V.log, shown(), V.world_ord, V.grab, target);
    V.dirty = true;
}

static void grab_end(void)
{
    if (V.grabbed >= 0 && shown()) wbl_input_release(V.log, shown(), V.world_ord, V.grab);
    V.grabbed = -1;
    V.dirty = true;
}

/* ---- window events (called inside glfwPollEvents / glfwWaitEvents*) ------------------------- */
static void on_button(GLFWwindow *win, int button, int action, int mods)
{
    (void)mods;
    double x, y;
    glfwGetCursorPos(win, &x, &y);
    V.mx = x, V.my = y;
    if (action == GLFW_PRESS && V.drag == 0) {
        if (button == GLFW_MOUSE_BUTTON_LEFT) {
            /* a grab needs a running world: after the script's end nothing would step */
            if (V.running && shown()) grab_start(x, y);
            else V.drag = 1;
        } else if (button == GLFW_MOUSE_BUTTON_RIGHT || button == GLFW_MOUSE_BUTTON_MIDDLE) {
            V.drag = 2;
        }
    } else if (action == GLFW_RELEASE) {
        if (V.drag == 3 && button == GLFW_MOUSE_BUTTON_LEFT) grab_end();
        if ((V.drag == 1 || V.drag == 3) && button == GLFW_MOUSE_BUTTON_LEFT) V.drag = 0;
        if (V.drag == 2 && button != GLFW_MOUSE_BUTTON_LEFT) V.drag = 0;
    }
}

static void on_cursor(GLFWwindow *win, double x, double y)
{
    (void)win;
    double dx = x - V.mx, dy = y - V.my;
    V.mx = x, V.my = y;
    if (V.drag == 1) orbit(dx, dy);
    else if (V.drag == 2) pan(dx, dy);
    else if (V.drag == 3) grab_move(x, y);
}

static void on_scroll(GLFWwindow *win, double dx, double dy)
{
    (void)win, (void)dx;
    zoom(dy);
}

static void on_key(GLFWwindow *win, int key, int scancode, int action, int mods)
{
    (void)win, (void)scancode, (void)mods;
    if (action == GLFW_RELEASE) return;
    if (key == GLFW_KEY_RIGHT) {
        if (V.paused) V.step_once = true;
        return;
    }
    if (action != GLFW_PRESS) return;
    if (key == GLFW_KEY_ESCAPE) V.quit = true;
    else if (key == GLFW_KEY_SPACE) V.paused = !V.paused, V.dirty = true;
    else if (key == GLFW_KEY_R) V.restart = true;
    else if (key == GLFW_KEY_A) {   /* back to the scene's camera, or the one that follows the scene */
        V.cam_fixed = false;
        V.scene_cam = false;
        wb_renderer_auto_camera(V.r);
        V.dirty = true;
    }
}

static void on_close(GLFWwindow *win)
{
    (void)win;
    V.quit = true;
}

/* ---- --watch ------------------------------------------------------------------------------------- */
static void stamp(watched *f)
{
    struct stat st;
    f->exists = stat(f->path, &st) == 0;
    f->mtime = f->exists ? st.st_mtim : (struct timespec){ 0, 0 };
    f->size = f->exists ? st.st_size : 0;
}

static void watch_add(const char *path)
{
    char abs[PATH_MAX];
    if (!realpath(path, abs)) snprintf(abs, sizeof abs, "%s", path);
    for (int i = 0; i < V.nfiles; i++)
        if (!strcmp(V.files[i].path, abs)) return;
    if (V.nfiles == MAX_WATCH) {
        static bool told;
        if (!told) fprintf(stderr, "wobble: --watch follows the first %d files the scene read; %s and later ones are not watched\n",
                           MAX_WATCH, abs);
        told = true;
        return;
    }
    watched *f = &V.files[V.nfiles++];
    snprintf(f->path, sizeof f->path, "%s", abs);
    stamp(f);
}

/* every file the scene reads (meshes, configs, dofile, io.open), through the sandbox */
void wb_view_file_read(void *ud, const char *path)
{
    (void)ud;
    if (V.o && V.o->watch) watch_add(path);
}

/* the Lua modules the scene required: each name of package.loaded that
 * package.searchpath finds on package.path (the sandbox's rules) */
static void watch_modules(lua_State *L)
{
    int top = lua_gettop(L);
    if (lua_getglobal(L, "package") != LUA_TTABLE || lua_getfield(L, top + 1, "loaded") != LUA_TTABLE ||
        lua_getfield(L, top + 1, "path") != LUA_TSTRING || lua_getfield(L, top + 1, "searchpath") != LUA_TFUNCTION) {
        lua_settop(L, top);
        return;
    }
    lua_pushnil(L);
    while (lua_next(L, top + 2)) {
        lua_pop(L, 1);
        if (lua_type(L, -1) != LUA_TSTRING) continue;
        lua_pushvalue(L, top + 4);
        lua_pushvalue(L, -2);
        lua_pushvalue(L, top + 3);
        if (lua_pcall(L, 2, 1, 0) == LUA_OK && lua_type(L, -1) == LUA_TSTRING) watch_add(lua_tostring(L, -1));
        lua_pop(L, 1);
    }
    lua_settop(L, top);
}

/* has a watched file changed since the last look? (the stamps are then renewed) */
static bool watch_changed(void)
{
    bool changed = false;
    for (int i = 0; i < V.nfiles; i++) {
        watched old = V.files[i];
        stamp(&V.files[i]);
        if (old.exists != V.files[i].exists || old.size != V.files[i].size ||
            old.mtime.tv_sec != V.files[i].mtime.tv_sec || old.mtime.tv_nsec != V.files[i].mtime.tv_nsec)
            changed = true;
    }
    return changed;
}

static void watch_poll(void)
{
    if (!V.o->watch || now() - V.last_check < 0.2) return;
    V.last_check = now();
    if (V.L && V.running) watch_modules(V.L);
    if (watch_changed()) V.reload = true;
}

/* ---- drawing --------------------------------------------------------------------------------------- */
static const uint8_t white[3] = { 255, 255, 255 }, yellow[3] = { 255, 220, 90 }, red[3] = { 255, 110, 100 };

static void text_line(int *y, const char *s, const uint8_t col[3], int *wmax)
{
    int lh = 12 * V.text_scale;
    /* a darker band behind each line keeps it readable over any scene */
    int tw = wb_text_width(s, V.text_scale) + 8;
    if (tw > V.W) tw = V.W;
    for (int yy = *y; yy < *y + lh && yy < V.H; yy++)
        for (int xx = 0; xx < tw; xx++) {
            uint8_t *p = V.frame + 3 * ((size_t)yy * V.W + xx);
            p[0] = (uint8_t)(p[0] * 0.35), p[1] = (uint8_t)(p[1] * 0.35), p[2] = (uint8_t)(p[2] * 0.35);
        }
    wb_text(V.frame, V.W, V.H, 4, *y + V.text_scale, s, col, V.text_scale);
    *y += lh;
    if (tw > *wmax) *wmax = tw;
}

/* the error's lines (without the traceback), cut to the window's width */
static void error_lines(int *y, int *wmax)
{
    const char *s = V.error;
    int chars = (V.W - 8) / (6 * V.text_scale);
    if (chars < 8) chars = 8;
    if (chars > 200) chars = 200;
    while (*s && *y < V.H - 12 * V.text_scale) {
        const char *e = strchr(s, '\n');
        int n = e ? (int)(e - s) : (int)strlen(s);
        if (!strncmp(s, "stack traceback:", 16)) break;
        do {
            char line[256];
            int k = n < chars ? n : chars;
            snprintf(line, sizeof line, "%.*s", k, s);
            for (char *c = line; *c; c++)
                if (*c == '\t') *c = ' ';
            text_line(y, line, red, wmax);
            s += k, n -= k;
        } while (n > 0 && *y < V.H - 12 * V.text_scale);
        s += n;
        if (*s == '\n') s++;
    }
}

/* the picture: the renderer's last frame (or a dark background) and the overlay */
static void compose(void)
{
    const uint8_t *px = V.drawn ? wb_renderer_pixels(V.r) : NULL;
    if (px) memcpy(V.frame, px, (size_t)V.W * V.H * 3);
    else
        for (size_t i = 0; i < (size_t)V.W * V.H; i++) V.frame[3 * i] = 40, V.frame[3 * i + 1] = 42, V.frame[3 * i + 2] = 48;
    int y = 2, wmax = 0;
    char line[256];
    if (shown()) {
        const wb_world *w = shown();
        wb_stats st = wb_world_stats(w);
        double dt = wb_world_get_def(w).dt;
        snprintf(line, sizeof line, "frame %lld  t %.2f s  %.2f ms/step  %.0f fps (%.2fx)",
                 (long long)wb_world_frame(w), wb_world_time(w), st.step_ms, V.fps, V.fps * dt);
        text_line(&y, line, white, &wmax);
        snprintf(line, sizeof line, "particles %d  contacts %d, particle %d  warnings %lld", (int)st.particles,
                 (int)(st.contacts + st.rigid_contacts), (int)st.particle_contacts, (long long)st.warnings);
        text_line(&y, line, st.warnings ? yellow : white, &wmax);
    }
    if (V.error[0]) {
        text_line(&y, V.o->watch ? "script error (save a file to run again; R: restart, Esc: quit)" : "script error",
                  yellow, &wmax);
        error_lines(&y, &wmax);
    } else if (!V.running) {
        text_line(&y, "the scene ended: R restarts, Esc quits", yellow, &wmax);
    } else if (V.paused) {
        text_line(&y, "PAUSED: space runs, right arrow steps a frame", yellow, &wmax);
    }
    if (V.grabbed >= 0) {
        snprintf(line, sizeof line, "holding particle %d", (int)V.grabbed + 1);
        text_line(&y, line, yellow, &wmax);
    }
    if (V.note[0]) text_line(&y, V.note, yellow, &wmax);
}

static void present(void)
{
    compose();
    wb_window_blit(V.frame, 0, 0, V.W, V.H);
    wb_window_swap();
    V.dirty = false;
}

/* the world at world_index drawn with its skins, every layer on */
static void draw_world(lua_State *L, int world_index)
{
    int top = lua_gettop(L), nsk = 0;
    world_index = lua_absindex(L, world_index);
    wbl_world *ud = wbl_checkworld_ud(L, world_index);
    if (!ud->w) return;   /* closed by the script */
    const wb_draw_skin *sk = wbl_world_skins(L, world_index, &nsk);  /* on the stack until settop */
    wb_draw_opts o = wb_draw_default_opts();
    char err[512];
    /* until the mouse moves it, the scene's camera when it set one (wobble.camera) */
    double e[3], t[3], v[3], fov;
    if (!V.cam_fixed && wbl_scene_camera(L, e, t, v, &fov)) {
        wb_renderer_camera(V.r, e, t, v, fov);
        V.scene_cam = true;
    } else if (!V.cam_fixed && V.scene_cam) {
        wb_renderer_auto_camera(V.r);
        V.scene_cam = false;
    }
    if (wb_renderer_draw(V.r, ud->w, &o, sk, nsk, err, sizeof err)) V.drawn = true;
    else snprintf(V.note, sizeof V.note, "drawing failed: %.200s", err);
    lua_settop(L, top);
}

/* wait for events until `until` (monotonic seconds) or something to do */
static void wait_events(double until)
{
    double left = until - now();
    if (left > 0) glfwWaitEventsTimeout(left);
    else glfwPollEvents();
    watch_poll();
}

/* ---- the frame hook ------------------------------------------------------------------------------ */
static int stop_run(lua_State *L)
{
    lua_pushlightuserdata(L, (void *)&stop_key);
    return lua_error(L);
}

static int view_hook(lua_State *L)
{
    int ord = wbl_input_world(L, 1);   /* every world numbered, as the replay numbers them */
    if (!V.world_ord || (ord != V.world_ord && !shown())) {
        V.world_ord = ord;
        V.world = wbl_checkworld_ud(L, 1);
        V.frames_shown = 0;   /* --frames N counts the frames of the world shown */
        if (V.drag == 3) V.drag = 0;   /* a grab of a closed world is gone with it */
        V.grabbed = -1;
        lua_pushvalue(L, 1);
        lua_rawsetp(L, LUA_REGISTRYINDEX, &world_key);
    }
    if (ord != V.world_ord) {
        /* one world is shown (two would interleave); the window still answers */
        glfwPollEvents();
        watch_poll();
        return stopping() ? stop_run(L) : 0;
    }
    if (stopping()) return stop_run(L); /* the script caught the marker and stepped on */
    if (V.o->frames >= 0 && ++V.frames_shown > V.o->frames) {
        V.quit = true;   /* --frames N: a w:step loop past N ends here */
        return stop_run(L);
    }
    glfwPollEvents();
    draw_world(L, 1);
    /* real time: each frame shown dt after the last, or as soon as drawn when slower */
    double dt = wb_world_get_def(shown()).dt, due = V.last_present + dt;
    while (!stopping() && now() < due && V.last_present > 0) wait_events(due);
    double t = now();
    if (V.last_present > 0 && t > V.last_present) {
        double fps = 1 / (t - V.last_present);
        V.fps = V.fps > 0 ? 0.9 * V.fps + 0.1 * fps : fps;
    }
    V.last_present = t;
    present();
    watch_poll();
    /* paused: draw when the camera or a grab changes, until space, a step or an end */
    while (V.paused && !V.step_once && !stopping()) {
        if (V.dirty) {
            draw_world(L, 1);
            present();
        }
        wait_events(now() + 0.1);
        V.last_present = 0;   /* no catching up after a pause */
    }
    V.step_once = false;
    if (stopping()) return stop_run(L);
    return 0;
}

/* os.exit (--unsafe): the viewer closes as with Esc, with the code given, so the
 * input log and the screenshot are still written (a process exit would lose them) */
static int view_os_exit(lua_State *L)
{
    int code = 0;
    if (lua_isboolean(L, 1)) code = lua_toboolean(L, 1) ? 0 : 1;
    else if (!lua_isnoneornil(L, 1)) code = (int)(luaL_checkinteger(L, 1) & 0xff);
    V.exit_code = code;
    V.quit = true;
    return stop_run(L);
}

/* the marker passes unchanged; any other error gets its traceback */
static int view_msgh(lua_State *L)
{
    if (lua_touserdata(L, 1) == &stop_key) return 1;
    return wb_rt_msgh(L);
}

/* after the script: the last picture until Esc, R or (--watch) a saved file */
static void wait_end(lua_State *L)
{
    /* the script is over: the time limit bounds it, not the person looking at the end */
    wb_rt_pause_watchdog(L, 1);
    V.dirty = true;
    while (!stopping()) {
        if (V.dirty) {
            if (shown() && lua_rawgetp(L, LUA_REGISTRYINDEX, &world_key) == LUA_TUSERDATA) draw_world(L, -1);
            lua_settop(L, 0);
            present();
        }
        wait_events(now() + 0.1);
    }
    wb_rt_pause_watchdog(L, 0);   /* the finalizers of wb_rt_close are bounded again */
}

/* one run of the scene: 0 to go on (restart), else the exit code + 1 */
static int run_once(void)
{
    const wb_view_opts *o = V.o;
    const char *err;
    V.world = NULL;
    V.world_ord = 0;
    V.frames_shown = 0;
    V.restart = V.reload = false;
    V.grabbed = -1;
    V.drag = V.drag == 3 ? 0 : V.drag;
    V.last_present = 0;
    V.note[0] = 0;
    V.error[0] = 0;   /* the last run's error is shown until this one starts */
    lua_State *L = o->open(o->host, &err);
    if (!L) {
        fprintf(stderr, "wobble: %s\n", err);
        return 1 + 2;
    }
    V.L = L;
    lua_pushcfunction(L, view_hook);
    wb_rt_add_frame_hook(L, -1);
    lua_pop(L, 1);
    if (wb_rt_get(L)->unsafe && lua_getglobal(L, "os") == LUA_TTABLE) {
        lua_pushcfunction(L, view_os_exit);
        lua_setfield(L, -2, "exit");
    }
    lua_settop(L, 0);
    lua_pushcfunction(L, view_msgh);
    V.running = true;
    int status = luaL_loadfilex(L, o->scene, wb_rt_get(L)->unsafe ? NULL : "t");
    if (status == LUA_OK) status = lua_pcall(L, 0, 0, 1);
    V.running = false;
    if (V.grabbed >= 0) V.grabbed = -1;   /* the world steps no more */
    if (V.drag == 3) V.drag = 0;
    int code = 0;
    if (!stopping()) {
        if (status != LUA_OK) {
            const char *msg = lua_tostring(L, -1);
            int budget = wb_rt_budget_hit(L);
            if (!msg) msg = status == LUA_ERRMEM ? "not enough memory" : "error";
            o->print_error(msg);
            if (!o->watch) code = 1 + (budget ? 3 : 2);
            else snprintf(V.error, sizeof V.error, "%s", msg);
        } else {
            V.error[0] = 0;
            if (o->frames >= 0) code = 1 + 0;   /* --frames: the scene's end closes the viewer */
        }
        lua_settop(L, 0);
        if (o->watch) watch_modules(L);
        if (!code) wait_end(L);
    } else {
        V.error[0] = 0;
        if (o->watch) watch_modules(L);
    }
    if (V.quit && !code) code = 1 + V.exit_code;
    /* the window's last picture, before the world it names is gone */
    if (code && o->screenshot) {
        char err[1024];
        if (!wbl_write_png(o->screenshot, V.frame, V.W, V.H, err, sizeof err)) {
            fprintf(stderr, "wobble: --screenshot: %s\n", err);
            if (code == 1) code = 1 + 2;
        }
    }
    V.world = NULL;
    V.L = NULL;
    wb_rt_close(L);
    if (!code && V.log) wbl_input_log_clear(V.log);   /* a restart: the log starts again */
    return code;
}

/* can the file be written? Asked before the window opens, so that a bad path is not
 * found out after minutes of poking; a file made for the test is removed again */
static bool writable(const char *opt, const char *path)
{
    bool existed = access(path, F_OK) == 0;
    FILE *f = fopen(path, "a");
    if (!f) {
        fprintf(stderr, "wobble: %s: cannot write %s: %s\n", opt, path, strerror(errno));
        return false;
    }
    fclose(f);
    if (!existed) remove(path);
    return true;
}

int wb_view_main(const wb_view_opts *o)
{
    char err[1024];
    memset(&V, 0, sizeof V);
    V.o = o;
    V.grabbed = -1;
    V.W = o->width, V.H = o->height;
    V.text_scale = V.H >= 600 ? 2 : 1;
    if ((o->record_input && !writable("--record-input", o->record_input)) ||
        (o->screenshot && !writable("--screenshot", o->screenshot)))
        return 2;
    if (!wb_window_available(err, sizeof err)) {
        fprintf(stderr, "wobble: view: %s\n", err);
        return 2;
    }
    char title[PATH_MAX + 32];
    snprintf(title, sizeof title, "wobble view: %s", o->scene);
    wb_window_set_title(title);
    V.frame = malloc((size_t)V.W * V.H * 3);
    V.log = wbl_input_log_create();
    V.r = V.frame && V.log ? wb_renderer_create(&wb_backend_glfw, V.W, V.H, 4, err, sizeof err) : NULL;
    if (!V.r) {
        fprintf(stderr, "wobble: view: %s\n", V.frame && V.log ? err : "out of memory");
        free(V.frame);
        wbl_input_log_destroy(V.log);
        wb_window_terminate();
        return 2;
    }
    V.win = wb_window_handle();
    glfwSetMouseButtonCallback(V.win, on_button);
    glfwSetCursorPosCallback(V.win, on_cursor);
    glfwSetScrollCallback(V.win, on_scroll);
    glfwSetKeyCallback(V.win, on_key);
    glfwSetWindowCloseCallback(V.win, on_close);
    present();   /* the window shows something while the scene sets up */
    watch_add(o->scene);
    int code;
    while (!(code = run_once())) {
        if (V.reload) fprintf(stderr, "wobble: view: a file changed, %s restarts\n", o->scene);
    }
    code -= 1;
    if (o->record_input) {
        if (!wbl_input_log_save(V.log, o->record_input, o->scene, err, sizeof err)) {
            fprintf(stderr, "wobble: --record-input: %s\n", err);
            if (!code) code = 2;
        } else {
            fprintf(stderr, "wobble: recorded %lld input events to %s\n", (long long)wbl_input_log_events(V.log),
                    o->record_input);
        }
    }
    wb_renderer_destroy(V.r);
    wb_window_terminate();
    wbl_input_log_destroy(V.log);
    free(V.frame);
    return code;
}
