/* renderer.c: wobble.renderer{...} and its methods (camera, draw, save_png,
 * record, pixels for tests), wobble.probe and wobble.read_png, and the recording
 * behind `wobble run --record OUT`. Every path a script names goes through the
 * sandbox (wb_sandbox_path); --record's path is the user's own. */
#include <errno.h>
#include <fcntl.h>
#include <limits.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>
#include <sys/stat.h>
#include <time.h>
#include <unistd.h>

#include "io/io.h"
#include "mesh.h"
#include "util.h"
#include "render/render.h"
#include "sandbox.h"

#define WBL_RENDERER "wobble.renderer"

/* where a recording goes, each file whole (io's files): a video grows in a temporary
 * beside its name and takes the name when the recording finishes well, so an old video
 * of that name stays until then; frames land one by one in the folder held open (a
 * link in it is replaced, never followed) */
typedef struct rec_files {
    wbio_out video;
    int dir;              /* the folder of PNG frames, or -1 */
    char path[PATH_MAX];  /* the file or folder, for messages */
} rec_files;

typedef struct wbl_renderer {
    wb_renderer *r;       /* NULL once closed: __gc and __close may run twice */
    wb_recorder *rec;     /* the recording, or NULL */
    rec_files *files;     /* its files */
    bool fps_set;         /* r:record{fps = ...}: the world's dt does not decide */
    int64_t draws;
    bool scene_cam;       /* --record's renderer: drawn last with the scene's camera */
    /* the buffers live outside the Lua heap: charged to the runtime's memory budget */
    wb_memory *mem;
    size_t charged, rec_charged;
    size_t draw_charged;  /* what drawing takes: the layers and GL's buffers, kept between frames */
} wbl_renderer;

static bool over_budget(const wb_memory *m, size_t bytes)
{
    return m->limit && (bytes > m->limit || m->used > m->limit - bytes);
}

/* charge `bytes` more to the budget (*slot keeps what this use holds); raises a budget
 * error naming `what` when the budget would be passed, even after a collection */
static void charge(lua_State *L, size_t *slot, size_t bytes, const char *what)
{
    wbl_charge(L, bytes, what);
    *slot += bytes;
}

static void release(wbl_renderer *u, size_t *slot)
{
    u->mem->used -= *slot < u->mem->used ? *slot : u->mem->used;
    *slot = 0;
}

static bool write_frame(void *ud, const char *name, const void *data, size_t n, char *err, size_t en)
{
    const rec_files *f = ud;
    char shown[PATH_MAX + 80], e[PATH_MAX + 160];
    snprintf(shown, sizeof shown, "%s%s%s", f->path, f->path[strlen(f->path) - 1] == '/' ? "" : "/", name);
    if (wbio_write_bytes(f->dir, name, shown, data, n, e, sizeof e) == 0) return true;
    snprintf(err, en, "cannot write %s", e);
    return false;
}

static void close_files(rec_files *f, bool keep, char *err, size_t n, bool *ok)
{
    if (!f) return;
    if (f->dir >= 0) close(f->dir);
    else if (!keep) wbio_out_abort(&f->video);
    else if (wbio_out_commit(&f->video, f->path, err, n)) *ok = false;
    free(f);
}

/* the destination of a recording of `kind` to path (resolved: the file or folder itself),
 * made and checked now rather than at the first frame; the recorder on it */
static wb_recorder *begin_recording(wbl_renderer *u, const char *path, wb_media kind, int w, int h, char *err, size_t n)
{
    rec_files *f = calloc(1, sizeof *f);
    if (!f) {
        snprintf(err, n, "out of memory");
        return NULL;
    }
    f->dir = -1;
    snprintf(f->path, sizeof f->path, "%s", path);
    wb_media_out out = { f, write_frame, "" };
    char e[PATH_MAX + 160];
    if (kind == WB_MEDIA_FOLDER) {
        if (mkdir(path, 0777) != 0 && errno != EEXIST) {
            snprintf(err, n, "cannot create the folder %s: %s", path, strerror(errno));
            free(f);
            return NULL;
        }
        f->dir = open(path, O_RDONLY | O_DIRECTORY | O_CLOEXEC);
        if (f->dir < 0 || faccessat(f->dir, ".", W_OK, AT_EACCESS) != 0) {
            snprintf(err, n, "cannot write into %s: %s", path, strerror(errno));
            close_files(f, false, NULL, 0, NULL);
            return NULL;
        }
    } else {
        /* the encoder's file, made now (proving the folder writable), empty until it starts */
        if (wbio_out_open(&f->video, AT_FDCWD, path, path, e, sizeof e)) {
            snprintf(err, n, "cannot write %s", e);
            free(f);
            return NULL;
        }
        wbio_out_close_file(&f->video);
        out.encode_to = f->video.tmp;
    }
    wb_recorder *rec = wb_recorder_open(path, kind, w, h, &out, err, n);
    if (!rec) close_files(f, false, NULL, 0, NULL);
    else u->files = f;
    return rec;
}

/* finish the recording (the frames' and the encoder's memory is given back); false with the message. The
 * file takes its name only when every frame went into it */
static bool end_recording(wbl_renderer *u, char *err, size_t n)
{
    wb_recorder *rec = u->rec;
    rec_files *f = u->files;
    u->rec = NULL;
    u->files = NULL;
    const bool started = wb_recorder_started(rec);
    bool ok = wb_recorder_close(rec, err, n);   /* the encoder lives until it finishes the file */
    release(u, &u->rec_charged);
    close_files(f, ok && started, err, n, &ok);
    return ok;
}

static wbl_renderer *checkud(lua_State *L, int arg)
{
    return (wbl_renderer *)luaL_checkudata(L, arg, WBL_RENDERER);
}

static wbl_renderer *checkrenderer(lua_State *L, int arg)
{
    wbl_renderer *u = checkud(L, arg);
    if (!u->r) luaL_error(L, "attempt to use a closed renderer");
    return u;
}

/* a script's path, resolved for writing or reading; raises the sandbox's message */
static const char *script_path(lua_State *L, int arg, int write, char *buf, size_t n)
{
    const char *err, *p = wb_sandbox_path(L, wbl_checkfilename(L, arg), write, buf, n, &err);
    if (!p) luaL_error(L, "%s", err);
    return p;
}

/* ---- creation ------------------------------------------------------------------------ */
static const char *const renderer_keys[] = { "width", "height", "samples", "fxaa", "backend", NULL };
static const char *const backend_names[] = { "osmesa", "null", NULL };

static int l_renderer(lua_State *L)
{
    int w = 1280, h = 720, samples = 4;
    bool fxaa = false;
    wbl_checkopts(L, 1, renderer_keys, true);
    const wb_backend *be = &wb_backend_osmesa;
    if (!lua_isnoneornil(L, 1)) {
        wbl_optint(L, 1, "width", 1, WB_RENDER_MAX_SIZE, &w);
        wbl_optint(L, 1, "height", 1, WB_RENDER_MAX_SIZE, &h);
        wbl_optint(L, 1, "samples", 1, 16, &samples);
        wbl_optbool(L, 1, "fxaa", &fxaa);
        if (wbl_optenum(L, 1, "backend", "backend", backend_names) == 1) be = &wb_backend_null;
    }
    wbl_renderer *u = (wbl_renderer *)lua_newuserdatauv(L, sizeof *u, 0);
    memset(u, 0, sizeof *u);
    u->mem = &wb_rt_get(L)->memory;
    luaL_setmetatable(L, WBL_RENDERER);
    char err[512], what[64];
    snprintf(what, sizeof what, "a %dx%d renderer", w, h);
    charge(L, &u->charged, wb_renderer_bytes(be, w, h, samples), what);
    u->r = wb_renderer_create(be, w, h, samples, err, sizeof err);
    if (!u->r) {
        release(u, &u->charged);
        return luaL_error(L, "wobble.renderer: %s", err);
    }
    wb_renderer_set_fxaa(u->r, fxaa);
    /* the context may grant fewer samples than asked (llvmpipe: 4 at most) */
    const size_t real = wb_renderer_bytes(be, w, h, wb_renderer_samples(u->r));
    if (real < u->charged) {
        u->mem->used -= u->charged - real;
        u->charged = real;
    }
    return 1;
}

/* ---- camera --------------------------------------------------------------------------- */
static const char *const camera_keys[] = { "eye", "target", "up", "fov", NULL };

/* the camera table at idx checked: eye, target, up = {0,1,0}, fov = 40 (vertical degrees) */
static void check_camera(lua_State *L, int idx, double e[3], double t[3], double v[3], double *fov_out)
{
    wbl_checkopts(L, idx, camera_keys, false);
    wb_real eye[3], target[3], up[3] = { 0, 1, 0 }, fov = 40;
    if (!wbl_optvec(L, idx, "eye", 3, eye)) wbl_fielderror(L, idx, "eye", "missing ({x,y,z} expected)");
    if (!wbl_optvec(L, idx, "target", 3, target)) wbl_fielderror(L, idx, "target", "missing ({x,y,z} expected)");
    wbl_optvec(L, idx, "up", 3, up);
    if (wbl_optreal(L, idx, "fov", &fov) && !(fov > 0 && fov < 180))
        wbl_fielderror(L, idx, "fov", "must be between 0 and 180 degrees");
    double d[3], c[3];
    for (int k = 0; k < 3; k++) e[k] = eye[k], t[k] = target[k], v[k] = up[k], d[k] = t[k] - e[k];
    double dl = sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]), vl = sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
    if (!(dl > 0)) luaL_argerror(L, idx, "eye and target must differ");
    c[0] = d[1] * v[2] - d[2] * v[1], c[1] = d[2] * v[0] - d[0] * v[2], c[2] = d[0] * v[1] - d[1] * v[0];
    if (!(vl > 0) || sqrt(c[0] * c[0] + c[1] * c[1] + c[2] * c[2]) < 1e-9 * dl * vl)
        wbl_fielderror(L, idx, "up", "must not be zero or along the line of sight");
    *fov_out = fov;
}

/* r:camera{eye, target, up = {0,1,0}, fov = 40}; r:camera() frames the world again */
static int r_camera(lua_State *L)
{
    wbl_renderer *u = checkrenderer(L, 1);
    if (lua_isnoneornil(L, 2)) {
        wb_renderer_auto_camera(u->r);
        return 0;
    }
    double e[3], t[3], v[3], fov;
    check_camera(L, 2, e, t, v, &fov);
    wb_renderer_camera(u->r, e, t, v, fov);
    return 0;
}

/* the scene's camera (wobble.camera): registry[&scene_cam_key] = 10 doubles (eye,
 * target, up, fov) as a full userdata, absent when the scene leaves the framing automatic */
static const char scene_cam_key = 0;

bool wbl_scene_camera(lua_State *L, double eye[3], double target[3], double up[3], double *fov)
{
    bool set = false;
    if (lua_rawgetp(L, LUA_REGISTRYINDEX, &scene_cam_key) == LUA_TUSERDATA) {
        const double *c = (const double *)lua_touserdata(L, -1);
        for (int k = 0; k < 3; k++) eye[k] = c[k], target[k] = c[3 + k], up[k] = c[6 + k];
        *fov = c[9];
        set = true;
    }
    lua_pop(L, 1);
    return set;
}

static void push_camera(lua_State *L, const double e[3], const double t[3], const double v[3], double fov)
{
    lua_createtable(L, 0, 4);
    const double *vs[3] = { e, t, v };
    const char *names[3] = { "eye", "target", "up" };
    for (int i = 0; i < 3; i++) {
        lua_createtable(L, 3, 0);
        for (int k = 0; k < 3; k++) {
            lua_pushnumber(L, vs[i][k]);
            lua_rawseti(L, -2, k + 1);
        }
        lua_setfield(L, -2, names[i]);
    }
    lua_pushnumber(L, fov);
    lua_setfield(L, -2, "fov");
}

/* wobble.camera{eye, target, up, fov}: the scene's camera, the one `wobble run --record`
 * draws with and `wobble view` starts with; wobble.camera(false) gives the framing back
 * to the automatic camera; wobble.camera() -> the table set, or nil (so that a script's
 * own renderer can take it: r:camera(wobble.camera())) */
static int l_camera(lua_State *L)
{
    if (lua_isnone(L, 1)) {
        double e[3], t[3], v[3], fov;
        if (!wbl_scene_camera(L, e, t, v, &fov)) return 0;
        push_camera(L, e, t, v, fov);
        return 1;
    }
    if (lua_isboolean(L, 1) && !lua_toboolean(L, 1)) {
        lua_pushnil(L);
        lua_rawsetp(L, LUA_REGISTRYINDEX, &scene_cam_key);
        return 0;
    }
    luaL_checktype(L, 1, LUA_TTABLE);
    double e[3], t[3], v[3], fov;
    check_camera(L, 1, e, t, v, &fov);
    double *c = (double *)lua_newuserdatauv(L, 10 * sizeof(double), 0);
    for (int k = 0; k < 3; k++) c[k] = e[k], c[3 + k] = t[k], c[6 + k] = v[k];
    c[9] = fov;
    lua_rawsetp(L, LUA_REGISTRYINDEX, &scene_cam_key);
    return 0;
}

/* the camera of the last frame: {eye = {..}, target = {..}, up = {..}, fov = n} */
static int r_get_camera(lua_State *L)
{
    wbl_renderer *u = checkrenderer(L, 1);
    double e[3], t[3], v[3], fov;
    wb_renderer_get_camera(u->r, e, t, v, &fov);
    push_camera(L, e, t, v, fov);
    return 1;
}

/* ---- drawing and recording ---------------------------------------------------------------- */
static const char *const draw_keys[] = { "particles", "constraints", "colliders", "surfaces", "skins", "pins",
                                         "grid", "cage", "strain_scale", "line_width", "materials", "rigids", "legend",
                                         NULL };

/* finish the recording; raises with the encoder's message when it failed */
static void stop_recording(lua_State *L, wbl_renderer *u)
{
    char err[1024];
    if (!end_recording(u, err, sizeof err)) luaL_error(L, "%s", err);
}

/* the skins made on the world at world_index, for drawing (an array in a userdata left
 * on the stack, collected with it); *n their count */
wb_draw_skin *wbl_world_skins(lua_State *L, int world_index, int *n)
{
    wbl_push_world_skins(L, world_index);
    int len = (int)lua_rawlen(L, -1), k = 0;
    wb_draw_skin *sk = (wb_draw_skin *)lua_newuserdatauv(L, sizeof *sk * (size_t)(len ? len : 1), 0);
    for (int i = 1; i <= len; i++) {
        lua_rawgeti(L, -2, i);
        wb_world *w = NULL;
        wb_skin *s = wbl_toskin(L, -1, &w);
        lua_pop(L, 1);
        if (!s) continue;   /* closed */
        const wb_mesh *m = wb_skin_rest(s);
        sk[k].v = wb_skin_vertices(s, w);
        sk[k].n = wb_skin_normals(s, w);
        sk[k].tri = m->tri;
        sk[k].nv = m->nv;
        sk[k].nt = m->nt;
        sk[k].skin = s;
        k++;
    }
    *n = k;
    return sk;
}

/* draw and, when recording, add the frame; false + message instead of raising */
static bool draw_frame(lua_State *L, wbl_renderer *u, int world_index, const wb_draw_opts *o, char *err, size_t n)
{
    int top = lua_gettop(L), nsk = 0;
    wb_world *w = wbl_checkworld(L, world_index);
    wb_draw_skin *sk = o->skins ? wbl_world_skins(L, world_index, &nsk) : NULL;
    /* a world of a million links takes hundreds of MB to draw: charged before drawing,
     * then what the renderer holds after (its buffers grow by doubling and stay) */
    size_t want = wb_renderer_draw_bytes(u->r, w, sk, nsk);
    if (want > u->draw_charged) charge(L, &u->draw_charged, want - u->draw_charged, "drawing this world");
    bool ok = wb_renderer_draw(u->r, w, o, sk, nsk, err, n);
    lua_settop(L, top);
    if (!ok) return false;
    size_t held = wb_renderer_draw_held(u->r);
    if (held > u->draw_charged) charge(L, &u->draw_charged, held - u->draw_charged, "drawing this world");
    u->draws++;
    if (u->rec) {
        if (!u->fps_set && !wb_recorder_started(u->rec)) wb_recorder_set_fps(u->rec, 1.0 / wb_world_get_def(w).dt);
        if (!wb_recorder_add(u->rec, wb_renderer_pixels(u->r), err, n)) return false;
    }
    return true;
}

static int r_draw(lua_State *L)
{
    wbl_renderer *u = checkrenderer(L, 1);
    wbl_checkworld(L, 2);
    wbl_checkopts(L, 3, draw_keys, true);
    wb_draw_opts o = wb_draw_default_opts();
    if (!lua_isnoneornil(L, 3)) {
        wbl_optbool(L, 3, "particles", &o.particles);
        wbl_optbool(L, 3, "constraints", &o.constraints);
        wbl_optbool(L, 3, "colliders", &o.colliders);
        wbl_optbool(L, 3, "surfaces", &o.surfaces);
        wbl_optbool(L, 3, "skins", &o.skins);
        wbl_optbool(L, 3, "pins", &o.pins);
        wbl_optbool(L, 3, "grid", &o.grid);
        wbl_optbool(L, 3, "cage", &o.cage);
        wbl_optbool(L, 3, "materials", &o.materials);
        wbl_optbool(L, 3, "rigids", &o.rigids);
        wbl_optbool(L, 3, "legend", &o.legend);
        wb_real v;
        /* a number > 0, or "auto" (the default) */
        lua_getfield(L, 3, "strain_scale");
        const bool is_auto = lua_type(L, -1) == LUA_TSTRING && strcmp(lua_tostring(L, -1), "auto") == 0;
        lua_pop(L, 1);
        if (!is_auto) {
            lua_getfield(L, 3, "strain_scale");
            const int t = lua_type(L, -1);
            lua_pop(L, 1);
            if (t != LUA_TNIL && t != LUA_TNUMBER)
                return wbl_fielderror(L, 3, "strain_scale", "must be a number > 0 or \"auto\"");
            if (wbl_optreal(L, 3, "strain_scale", &v)) {
                if (!(v > 0)) return wbl_fielderror(L, 3, "strain_scale", "must be a number > 0 or \"auto\"");
                o.strain_scale = v;
                o.strain_auto = false;
            }
        }
        if (wbl_optreal(L, 3, "line_width", &v)) {
            if (!(v > 0 && v <= 64)) return wbl_fielderror(L, 3, "line_width", "must be in (0, 64] pixels");
            o.line_width = v;
        }
    }
    char err[1024];
    if (!draw_frame(L, u, 2, &o, err, sizeof err)) {
        /* a failed frame ends the recording: closing it gets the encoder's own words */
        if (u->rec) stop_recording(L, u);
        return luaL_error(L, "%s", err);
    }
    return 0;
}

static int r_save_png(lua_State *L)
{
    wbl_renderer *u = checkrenderer(L, 1);
    char buf[PATH_MAX], err[PATH_MAX + 128];
    const char *given = wbl_checkfilename(L, 2), *e = strrchr(given, '.');
    if (!e || strchr(e, '/') || strcasecmp(e, ".png") != 0)   /* a PNG by any other name surprises */
        return luaL_argerror(L, 2, lua_pushfstring(L, "a .png file name expected, got '%s'", given));
    const char *path = script_path(L, 2, 1, buf, sizeof buf);
    if (!u->draws) return luaL_error(L, "nothing to save: call r:draw(world) first");
    int w, h;
    wb_renderer_size(u->r, &w, &h);
    if (!wbl_write_png(path, wb_renderer_pixels(u->r), w, h, err, sizeof err)) return luaL_error(L, "%s", err);
    return 0;
}

static const char *const record_keys[] = { "fps", NULL };

/* r:record(path [, {fps}]): every later r:draw adds a frame until r:stop() */
static int r_record(lua_State *L)
{
    wbl_renderer *u = checkrenderer(L, 1);
    char buf[PATH_MAX], err[PATH_MAX + 256];
    wbl_checkfilename(L, 2);
    wbl_checkopts(L, 3, record_keys, true);
    wb_real fps = 0;
    bool has_fps = !lua_isnoneornil(L, 3) && wbl_optreal(L, 3, "fps", &fps);
    if (has_fps && !(fps > 0 && fps <= 1000)) return wbl_fielderror(L, 3, "fps", "must be in (0, 1000]");
    if (u->rec) return luaL_error(L, "already recording to %s: call r:stop() first", wb_recorder_path(u->rec));
    const char *given = lua_tostring(L, 2);
    if (wb_media_of(given, NULL, err, sizeof err) == WB_MEDIA_NONE) return luaL_argerror(L, 2, err);
    const char *path = script_path(L, 2, 1, buf, sizeof buf);
    wb_media kind = wb_media_of(given, path, err, sizeof err);   /* the name decides, not where it leads */
    int w, h;
    char what[96];
    wb_renderer_size(u->r, &w, &h);
    /* the frames queued and, for a video, ffmpeg encoding them (hundreds of MB for large
     * frames): a size whose encoder does not fit is refused before anything starts */
    snprintf(what, sizeof what, "recording %dx%d frames%s", w, h, kind == WB_MEDIA_FOLDER ? "" : " (ffmpeg included)");
    charge(L, &u->rec_charged, wb_recorder_bytes(kind, w, h), what);
    u->rec = begin_recording(u, path, kind, w, h, err, sizeof err);
    if (!u->rec) {
        release(u, &u->rec_charged);
        return luaL_error(L, "%s", err);
    }
    u->fps_set = has_fps;
    if (has_fps) wb_recorder_set_fps(u->rec, fps);
    return 0;
}

/* r:stop() -> path, frames: finish the file; raises when the encoder failed */
static int r_stop(lua_State *L)
{
    wbl_renderer *u = checkrenderer(L, 1);
    if (!u->rec) return luaL_error(L, "not recording");
    lua_pushstring(L, wb_recorder_path(u->rec));
    lua_pushinteger(L, (lua_Integer)wb_recorder_frames(u->rec));
    stop_recording(L, u);
    return 2;
}

static int r_recording(lua_State *L)
{
    wbl_renderer *u = checkrenderer(L, 1);
    if (!u->rec) {
        lua_pushnil(L);
        return 1;
    }
    lua_pushstring(L, wb_recorder_path(u->rec));
    lua_pushinteger(L, (lua_Integer)wb_recorder_frames(u->rec));
    return 2;
}

/* ---- reading the frame back -------------------------------------------------------------- */
static int r_size(lua_State *L)
{
    int w, h;
    wb_renderer_size(checkrenderer(L, 1)->r, &w, &h);
    lua_pushinteger(L, w);
    lua_pushinteger(L, h);
    return 2;
}

/* r:pixel(x, y) -> r, g, b (0..255); x, y from the top left, 0-based, as r:project gives */
static int r_pixel(lua_State *L)
{
    wbl_renderer *u = checkrenderer(L, 1);
    int w, h;
    wb_renderer_size(u->r, &w, &h);
    lua_Number fx = luaL_checknumber(L, 2), fy = luaL_checknumber(L, 3);
    if (!(fx >= 0 && fx < w)) return luaL_argerror(L, 2, lua_pushfstring(L, "x out of range [0, %d)", w));
    if (!(fy >= 0 && fy < h)) return luaL_argerror(L, 3, lua_pushfstring(L, "y out of range [0, %d)", h));
    const uint8_t *p = wb_renderer_pixels(u->r) + 3 * ((size_t)floor(fy) * (size_t)w + (size_t)floor(fx));
    for (int k = 0; k < 3; k++) lua_pushinteger(L, p[k]);
    return 3;
}

/* r:image() -> the last frame as a string of RGB bytes, top row first */
static int r_image(lua_State *L)
{
    wbl_renderer *u = checkrenderer(L, 1);
    int w, h;
    wb_renderer_size(u->r, &w, &h);
    lua_pushlstring(L, (const char *)wb_renderer_pixels(u->r), (size_t)w * h * 3);
    return 1;
}

/* r:project(x, y, z) -> px, py, depth (pixel coordinates of the last frame) or nil */
static int r_project(lua_State *L)
{
    wbl_renderer *u = checkrenderer(L, 1);
    wb_real p[3];
    wbl_checkreals(L, 2, 3, p);
    double q[3] = { p[0], p[1], p[2] }, x, y, d;
    if (!wb_renderer_project(u->r, q, &x, &y, &d)) {
        lua_pushnil(L);
        return 1;
    }
    lua_pushnumber(L, x);
    lua_pushnumber(L, y);
    lua_pushnumber(L, d);
    return 3;
}

/* r:strain_scale() -> the strain drawn in full colour in the last frame (the given
 * strain_scale or the automatic one), or nil when it showed no strain colour */
static int r_strain_scale(lua_State *L)
{
    const double s = wb_renderer_strain_scale(checkrenderer(L, 1)->r);
    if (s > 0) lua_pushnumber(L, s);
    else lua_pushnil(L);
    return 1;
}

static int r_info(lua_State *L)
{
    wbl_renderer *u = checkrenderer(L, 1);
    lua_pushstring(L, wb_renderer_info(u->r));
    lua_pushinteger(L, wb_renderer_samples(u->r));
    lua_pushboolean(L, wb_renderer_fxaa(u->r));
    return 3;
}

static void destroy(wbl_renderer *u)
{
    wb_renderer_destroy(u->r);
    u->r = NULL;
    if (u->mem) {
        release(u, &u->charged);
        release(u, &u->draw_charged);
    }
}

/* __gc, __close and r:close(): a recording is finished; at collection its failure can
 * only be printed */
static int r_close(lua_State *L)
{
    wbl_renderer *u = checkud(L, 1);
    bool gc = lua_toboolean(L, lua_upvalueindex(1));
    char err[1024];
    bool ok = !u->rec || end_recording(u, err, sizeof err);
    destroy(u);
    if (!ok && gc) fprintf(stderr, "wobble: %s\n", err);
    else if (!ok) return luaL_error(L, "%s", err);
    return 0;
}

static int r_tostring(lua_State *L)
{
    wbl_renderer *u = checkud(L, 1);
    if (!u->r) {
        lua_pushfstring(L, "wobble.renderer: %p (closed)", (void *)u);
        return 1;
    }
    int w, h;
    wb_renderer_size(u->r, &w, &h);
    lua_pushfstring(L, "wobble.renderer: %p (%dx%d)", (void *)u, w, h);
    return 1;
}

/* ---- media files ---------------------------------------------------------------------------- */
/* the frame size of the file at path from its header (ffprobe, charged while it runs);
 * false with nil and the message pushed */
static bool frame_size(lua_State *L, const char *path, const wb_media_stop *stop, int *w, int *h)
{
    char err[PATH_MAX + 128];
    const size_t helper = wb_media_helper_bytes(0, 0);
    wbl_charge(L, helper, "starting ffprobe");
    bool ok = wb_media_frame_size(path, stop, w, h, err, sizeof err);
    wbl_release(L, helper);
    if (ok) return true;
    wb_rt_check_budgets(L);
    luaL_pushfail(L);
    lua_pushstring(L, err);
    return false;
}

/* wobble.probe(path) -> {width, height, frames, codec, pix_fmt, duration} or nil, message */
static int l_probe(lua_State *L)
{
    char buf[PATH_MAX], err[PATH_MAX + 128], what[96];
    const char *path = script_path(L, 1, 0, buf, sizeof buf);
    wb_media_info mi;
    wb_media_stop stop;
    wb_rt_interrupt(L, &stop.fn, &stop.ud);   /* ffprobe may wait forever (a FIFO): the budgets end it */
    /* ffprobe decodes every frame to count them: charged for frames of the header's size */
    int w, h;
    if (!frame_size(L, path, &stop, &w, &h)) return 2;
    const size_t helper = wb_media_helper_bytes(w, h);
    snprintf(what, sizeof what, "probe: ffprobe decoding %dx%d frames", w, h);
    wbl_charge(L, helper, what);
    bool ok = wb_media_probe(path, &mi, &stop, err, sizeof err);
    wbl_release(L, helper);
    if (!ok) {
        wb_rt_check_budgets(L);
        luaL_pushfail(L);
        lua_pushstring(L, err);
        return 2;
    }
    lua_createtable(L, 0, 6);
    lua_pushinteger(L, mi.width);
    lua_setfield(L, -2, "width");
    lua_pushinteger(L, mi.height);
    lua_setfield(L, -2, "height");
    lua_pushinteger(L, (lua_Integer)mi.frames);
    lua_setfield(L, -2, "frames");
    lua_pushstring(L, mi.codec);
    lua_setfield(L, -2, "codec");
    lua_pushstring(L, mi.pix_fmt);
    lua_setfield(L, -2, "pix_fmt");
    lua_pushnumber(L, mi.duration);
    lua_setfield(L, -2, "duration");
    return 1;
}

static int push_pixels(lua_State *L)
{
    lua_pushlstring(L, (const char *)lua_touserdata(L, 1), (size_t)lua_tointeger(L, 2));
    return 1;
}

/* wobble.read_png(path) -> width, height, RGB string; or nil, message */
static int l_read_png(lua_State *L)
{
    char buf[PATH_MAX], err[PATH_MAX + 128], what[96];
    const char *path = script_path(L, 1, 0, buf, sizeof buf);
    int w = 0, h = 0;
    /* the header first: a 30 kB file can claim 16000 x 16000 pixels (2 GB decoded).
     * The decoder's peak is charged while it runs, then the pixels while Lua copies
     * them into a string (the string is the Lua heap's own) */
    const size_t dec = wb_image_png_bytes(path, &w, &h), rgb = dec ? (size_t)w * (size_t)h * 3 : 0;
    snprintf(what, sizeof what, "read_png: a %dx%d image", w, h);
    if (dec) wbl_charge(L, dec + rgb, what);
    uint8_t *px = wb_image_read_png(path, &w, &h, err, sizeof err);
    wbl_release(L, dec);
    if (!px) {
        wbl_release(L, rgb);
        luaL_pushfail(L);
        lua_pushstring(L, err);
        return 2;
    }
    lua_pushinteger(L, w);
    lua_pushinteger(L, h);
    /* protected, so that a refused string cannot leak the pixels */
    lua_pushcfunction(L, push_pixels);
    lua_pushlightuserdata(L, px);
    lua_pushinteger(L, (lua_Integer)w * h * 3);
    const int st = lua_pcall(L, 2, 1, 0);
    free(px);
    wbl_release(L, rgb);
    if (st != LUA_OK) return lua_error(L);
    return 3;
}

/* wobble.read_frame(path [, index = 0]) -> width, height, RGB string of that frame of a
 * video (decoded by ffmpeg); or nil, message */
static int l_read_frame(lua_State *L)
{
    char buf[PATH_MAX], err[PATH_MAX + 128];
    const char *path = script_path(L, 1, 0, buf, sizeof buf);
    lua_Integer index = luaL_optinteger(L, 2, 0);
    luaL_argcheck(L, index >= 0, 2, "frame index must be >= 0");
    int w, h;
    wb_media_stop stop;
    wb_rt_interrupt(L, &stop.fn, &stop.ud);
    /* the size from the header first, as read_png: ffmpeg's decode and ours are charged
     * while they run, then the pixels while Lua copies them */
    if (!frame_size(L, path, &stop, &w, &h)) return 2;
    char what[96];
    const size_t dec = wb_media_frame_bytes(w, h), rgb = (size_t)w * (size_t)h * 3;
    snprintf(what, sizeof what, "read_frame: a %dx%d frame", w, h);
    wbl_charge(L, dec + rgb, what);
    uint8_t *px = wb_media_read_frame(path, (int64_t)index, &stop, &w, &h, err, sizeof err);
    wbl_release(L, dec);
    if (!px) {
        wbl_release(L, rgb);
        wb_rt_check_budgets(L);
        luaL_pushfail(L);
        lua_pushstring(L, err);
        return 2;
    }
    lua_pushinteger(L, w);
    lua_pushinteger(L, h);
    /* protected, so that a refused string cannot leak the pixels */
    lua_pushcfunction(L, push_pixels);
    lua_pushlightuserdata(L, px);
    lua_pushinteger(L, (lua_Integer)w * h * 3);
    const int st = lua_pcall(L, 2, 1, 0);
    free(px);
    wbl_release(L, rgb);
    if (st != LUA_OK) return lua_error(L);
    return 3;
}

/* wobble.clock() -> seconds of wall time (monotonic): for timing frames, where
 * os.clock() would add up the renderer's threads */
static int l_clock(lua_State *L)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    lua_pushnumber(L, (lua_Number)ts.tv_sec + ts.tv_nsec * 1e-9);
    return 1;
}

/* ---- wobble run --record OUT ------------------------------------------------------------------ */
static const char rec_key = 0;   /* registry: {renderer = ud, world = the world recorded} */

static int record_hook(lua_State *L)
{
    if (lua_rawgetp(L, LUA_REGISTRYINDEX, &rec_key) != LUA_TTABLE) return 0;
    lua_getfield(L, -1, "renderer");
    wbl_renderer *u = (wbl_renderer *)luaL_testudata(L, -1, WBL_RENDERER);
    if (!u || !u->r) return 0;
    /* the first world that steps is the one recorded: frames of two worlds would
     * interleave */
    if (lua_getfield(L, -2, "world") == LUA_TNIL) {
        lua_pushvalue(L, 1);
        lua_setfield(L, -4, "world");
    } else if (!lua_rawequal(L, -1, 1)) {
        return 0;
    }
    wbl_checkworld(L, 1);
    /* the scene's camera when it set one (wobble.camera), else the automatic framing */
    double e[3], t[3], v[3], fov;
    if (wbl_scene_camera(L, e, t, v, &fov)) {
        wb_renderer_camera(u->r, e, t, v, fov);
        u->scene_cam = true;
    } else if (u->scene_cam) {   /* given back (wobble.camera(false)): framing starts afresh */
        wb_renderer_auto_camera(u->r);
        u->scene_cam = false;
    }
    wb_draw_opts o = wb_draw_default_opts();
    char err[1024];
    if (!draw_frame(L, u, 1, &o, err, sizeof err)) {
        char more[1024];
        if (!end_recording(u, more, sizeof more)) return luaL_error(L, "--record: %s", more);
        return luaL_error(L, "--record: %s", err);
    }
    return 0;
}

bool wbl_record_begin(lua_State *L, const char *path, int w, int h, int samples, char *err, size_t n)
{
    char e[PATH_MAX + 256];
    wb_media kind = wb_media_of(path, NULL, e, sizeof e);
    if (kind == WB_MEDIA_NONE) {
        snprintf(err, n, "--record: %s", e);
        return false;
    }
    /* a GIF at 1280x720 is tens of MB for a few seconds: half that size unless asked */
    if (w <= 0 || h <= 0) {
        w = kind == WB_MEDIA_GIF ? WB_RECORD_GIF_WIDTH : WB_RECORD_WIDTH;
        h = kind == WB_MEDIA_GIF ? WB_RECORD_GIF_HEIGHT : WB_RECORD_HEIGHT;
    }
    int top = lua_gettop(L);
    lua_pushcfunction(L, l_renderer);
    lua_createtable(L, 0, 2);
    lua_pushinteger(L, w);
    lua_setfield(L, -2, "width");
    lua_pushinteger(L, h);
    lua_setfield(L, -2, "height");
    /* by default one sample and FXAA: the drawing at about half the CPU time of 4
     * samples, edges alike (README, Recording) */
    lua_pushinteger(L, samples > 0 ? samples : 1);
    lua_setfield(L, -2, "samples");
    lua_pushboolean(L, samples <= 0);
    lua_setfield(L, -2, "fxaa");
    if (lua_pcall(L, 1, 1, 0) != LUA_OK) {
        snprintf(err, n, "--record: %s", lua_tostring(L, -1) ? lua_tostring(L, -1) : "cannot create the renderer");
        lua_settop(L, top);
        return false;
    }
    wbl_renderer *u = checkud(L, -1);
    wb_renderer_size(u->r, &w, &h);
    size_t bytes = wb_recorder_bytes(kind, w, h);
    if (over_budget(u->mem, bytes)) {
        snprintf(err, n, "--record: the frames%s need about %.0f MB, over the memory budget of %.0f MB (--memory-limit MB)",
                 kind == WB_MEDIA_FOLDER ? "" : " and ffmpeg encoding them", bytes / 1048576.0,
                 u->mem->limit / 1048576.0);
        lua_settop(L, top);
        return false;
    }
    u->mem->used += bytes;
    u->rec_charged = bytes;
    char real[PATH_MAX];   /* the user's path: a link of theirs is followed */
    if (wbio_follow_link(path, real, sizeof real)) snprintf(real, sizeof real, "%s", path);
    u->rec = begin_recording(u, real, kind, w, h, e, sizeof e);
    if (!u->rec) {
        release(u, &u->rec_charged);
        snprintf(err, n, "--record: %s", e);
        lua_settop(L, top);
        return false;
    }
    lua_createtable(L, 0, 2);
    lua_pushvalue(L, -2);
    lua_setfield(L, -2, "renderer");
    lua_rawsetp(L, LUA_REGISTRYINDEX, &rec_key);
    lua_pushcfunction(L, record_hook);
    wb_rt_add_frame_hook(L, -1);
    lua_settop(L, top);
    /* w:run's progress bar says where the frames go */
    const char *slash = strrchr(path, '/');
    char note[96];
    snprintf(note, sizeof note, "recording %s", slash && slash[1] ? slash + 1 : path);
    wb_progress_note(L, note);
    return true;
}

bool wbl_record_end(lua_State *L, char *err, size_t n)
{
    int top = lua_gettop(L);
    bool ok = true;
    if (lua_rawgetp(L, LUA_REGISTRYINDEX, &rec_key) == LUA_TTABLE && lua_getfield(L, -1, "renderer") == LUA_TUSERDATA) {
        wbl_renderer *u = (wbl_renderer *)luaL_testudata(L, -1, WBL_RENDERER);
        if (u && u->rec) {
            char path[PATH_MAX];
            snprintf(path, sizeof path, "%s", wb_recorder_path(u->rec));
            int64_t frames = wb_recorder_frames(u->rec);
            ok = end_recording(u, err, n);
            if (ok && !wb_rt_get(L)->quiet) {
                if (frames) fprintf(stderr, "wobble: recorded %lld frames to %s\n", (long long)frames, path);
                else fprintf(stderr, "wobble: --record: the scene stepped no frame, nothing written to %s\n", path);
            }
        }
        if (u) destroy(u);
    }
    lua_settop(L, top);
    return ok;
}

/* ---- registration ------------------------------------------------------------------------------ */
static const luaL_Reg renderer_methods[] = {
    { "camera", r_camera },
    { "get_camera", r_get_camera },
    { "draw", r_draw },
    { "save_png", r_save_png },
    { "record", r_record },
    { "stop", r_stop },
    { "recording", r_recording },
    { "size", r_size },
    { "pixel", r_pixel },
    { "image", r_image },
    { "project", r_project },
    { "info", r_info },
    { "strain_scale", r_strain_scale },
    { "close", r_close },
    { NULL, NULL }
};

void wbl_open_renderer(lua_State *L)
{
    luaL_newmetatable(L, WBL_RENDERER);
    lua_pushboolean(L, 1);   /* upvalue: called as a finalizer, errors are printed */
    lua_pushcclosure(L, r_close, 1);
    lua_setfield(L, -2, "__gc");
    lua_pushcfunction(L, r_close);
    lua_setfield(L, -2, "__close");
    lua_pushcfunction(L, r_tostring);
    lua_setfield(L, -2, "__tostring");
    luaL_newlibtable(L, renderer_methods);
    luaL_setfuncs(L, renderer_methods, 0);
    lua_setfield(L, -2, "__index");
    lua_pop(L, 1);
    /* the module table is on top when luaopen_wobble calls this */
    lua_pushcfunction(L, l_renderer);
    lua_setfield(L, -2, "renderer");
    lua_pushcfunction(L, l_probe);
    lua_setfield(L, -2, "probe");
    lua_pushcfunction(L, l_read_png);
    lua_setfield(L, -2, "read_png");
    lua_pushcfunction(L, l_read_frame);
    lua_setfield(L, -2, "read_frame");
    lua_pushcfunction(L, l_clock);
    lua_setfield(L, -2, "clock");
    lua_pushcfunction(L, l_camera);
    lua_setfield(L, -2, "camera");
    wbl_open_plot(L);
}
