/* render.c: draws a world: the camera and the scene's bounds, the layers' data (built
 * by layers.c) uploaded, and the passes (shadow map, ground, solids, surfaces,
 * links, sky), then resolves the multisample target into the backend's buffer and
 * keeps the frame as RGB, top row first. */
#include <malloc.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "render.h"
#include "fxaa.h"
#include "gl.h"

/* the passes a draw is timed by (pass_mark) */
enum { PASS_LAYERS, PASS_UPLOAD, PASS_SHADOW, PASS_GROUND, PASS_SOLIDS, PASS_LINES, PASS_SKY, PASS_RESOLVE,
       PASS_COPY, PASS_COUNT };

struct wb_renderer {
    const wb_backend *be;
    void *ctx;
    int w, h, samples;
    bool gl_ready;
    wb_gl gl;
    char info[192];
    uint8_t *rgb;                 /* the last frame */
    bool drawn;
    bool fxaa;                    /* antialiased after drawing (fxaa.c) */
    uint8_t *luma;                /* its scratch */
    size_t luma_cap;
    uint8_t *sky;                 /* with one sample: the sky's colour of each row (sky_rows) */
    /* camera: fixed by the script, or framing everything shown since the reset */
    bool fixed;
    double eye[3], target[3], up[3], fov;
    bool have_box;
    double view_lo[3], view_hi[3];/* what the default camera frames (follow_box) */
    const wb_world *box_world;    /* the world it was taken from, at frame box_frame */
    int64_t box_frame;
    /* the last frame's camera and view-projection (row-major 4x4, doubles) */
    double cam_eye[3], cam_target[3], cam_up[3], cam_fov, vp[16];
    wb_layers layers;             /* what the layers draw, rebuilt every frame */
    size_t hi_small;              /* its fine spheres drawn coarse (small_spheres_first) */
    bool timed;                   /* WOBBLE_PASS_TIMES (pass_mark) */
    double pass_s[PASS_COUNT], pass_t;
    int64_t pass_frames;
};

/* WOBBLE_PASS_TIMES=1 in the environment: each pass of a draw is finished (glFinish) and
 * timed in the process's CPU time (llvmpipe's threads included, the encoder's not), and
 * the means a frame are printed when the renderer is closed: what README's Recording
 * figures are. Without it nothing is finished early or timed */
static const char *const pass_names[PASS_COUNT] = { "layers", "upload", "shadow", "ground", "solids", "links",
                                                    "sky", "resolve", "copy" };

static double cpu_seconds(void)
{
    struct timespec t;
    clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &t);
    return (double)t.tv_sec + 1e-9 * (double)t.tv_nsec;
}

/* pass done (-1: a frame begins; the first, which compiles llvmpipe's shaders, is not
 * counted) */
static void pass_mark(wb_renderer *r, int pass)
{
    if (!r->timed) return;
    if (pass >= 0) glFinish();
    const double t = cpu_seconds();
    if (pass >= 0) r->pass_s[pass] += t - r->pass_t;
    else if (r->pass_frames++ == 1) memset(r->pass_s, 0, sizeof r->pass_s);
    r->pass_t = t;
}

static void pass_report(const wb_renderer *r)
{
    if (!r->timed || r->pass_frames < 2) return;
    const double frames = (double)(r->pass_frames - 1);
    double sum = 0;
    fprintf(stderr, "wobble: renderer %dx%d, %d sample%s%s, %lld frames, CPU ms a frame:", r->w, r->h, r->samples,
            r->samples > 1 ? "s" : "", r->fxaa ? " and FXAA" : "", (long long)r->pass_frames - 1);
    for (int k = 0; k < PASS_COUNT; k++) {
        fprintf(stderr, " %s %.2f", pass_names[k], 1000 * r->pass_s[k] / frames);
        sum += r->pass_s[k];
    }
    fprintf(stderr, "; total %.2f\n", 1000 * sum / frames);
}

/* colours, sRGB (the layers' own are in layers.c) */
static const float col_ground[3] = { 0.80f, 0.80f, 0.78f };
static const float col_sky_top[3] = { 0.50f, 0.61f, 0.75f };
static const float col_sky_bottom[3] = { 0.89f, 0.90f, 0.92f };
static const double light_dir[3] = { -0.40, 0.80, 0.45 };   /* towards the light: upper left, in front */
/* the light (linear): ambient on a surface facing down and up (mixed by the normal's y),
 * the key light's colour */
static const float amb_down[3] = { 0.16f, 0.14f, 0.13f }, amb_up[3] = { 0.30f, 0.34f, 0.42f };
static const float key_col[3] = { 1.0f, 0.96f, 0.9f };
/* the default camera's box shrinks by this part of the way per draw: about half a
 * second to settle at 60 draws a second */
static const double box_shrink = 0.03;

wb_draw_opts wb_draw_default_opts(void)
{
    wb_draw_opts o = { true, true, true, true, true, true, true, false, 0.02, 1.5, true, true, true, true };
    return o;
}

/* ---- life cycle -------------------------------------------------------------------------- */
wb_renderer *wb_renderer_create(const wb_backend *be, int width, int height, int samples, char *err, size_t n)
{
    if (width < 1 || height < 1 || width > WB_RENDER_MAX_SIZE || height > WB_RENDER_MAX_SIZE) {
        snprintf(err, n, "size %dx%d out of range (1..%d)", width, height, WB_RENDER_MAX_SIZE);
        return NULL;
    }
    wb_renderer *r = calloc(1, sizeof *r);
    if (r) r->rgb = calloc((size_t)width * (size_t)height, 3);
    if (!r || !r->rgb) {
        if (r) free(r);
        snprintf(err, n, "out of memory for a %dx%d renderer", width, height);
        return NULL;
    }
    r->be = be;
    r->w = width, r->h = height;
    r->samples = samples;
    r->up[1] = 1;
    r->fov = 40;
    const char *timed = getenv("WOBBLE_PASS_TIMES");
    r->timed = be->gl && timed && *timed && strcmp(timed, "0") != 0;
    r->ctx = be->create(width, height, err, n);
    if (!r->ctx) {
        wb_renderer_destroy(r);
        return NULL;
    }
    if (be->gl) {
        if (!wb_gl_init(&r->gl, width, height, &r->samples, be->depth, err, n)) {
            wb_renderer_destroy(r);
            return NULL;
        }
        r->gl_ready = true;
        snprintf(r->info, sizeof r->info, "OpenGL %s, %s", (const char *)glGetString(GL_VERSION),
                 (const char *)glGetString(GL_RENDERER));
    } else {
        r->samples = 1;
        snprintf(r->info, sizeof r->info, "null backend (no pixels)");
    }
    return r;
}

/* a GL context's own cost besides its buffers: llvmpipe's compiled shaders, scene bins
 * and state, measured as the growth of RSS per OSMesa renderer once drawn (6.5 MB on
 * Mesa 22.3, 8x8 to 4096x4096, 1 to 16 llvmpipe threads), rounded up */
#define GL_CONTEXT_BYTES ((size_t)7 << 20)

size_t wb_renderer_bytes(const wb_backend *be, int width, int height, int samples)
{
    size_t px = (size_t)width * (size_t)height, shadow = px > 1920 * 1080 ? 2048 : 1024;
    if (!be->gl) return 3 * px;
    /* per pixel: the RGB frame, the backend's RGBA, the context's own default framebuffer
     * (RGBA and 24-bit depth, which OSMesa allocates at the first draw), colour and depth
     * per sample; then the depth shadow map and the context. Within 5% of the RSS growth
     * measured per renderer (the old sum without the default framebuffer and the context
     * was 40% of it for small frames). One sample is drawn into the default framebuffer
     * when it has depth (no target of its own), with FXAA's two bytes a pixel */
    const size_t target = samples > 1 ? 8 * (size_t)samples : be->depth ? 2 : 8 + 2;
    return px * (3 + 4 + 8 + target) + 4 * shadow * shadow + GL_CONTEXT_BYTES;
}

/* the layers (CPU) and the GL buffers they are copied to, which llvmpipe keeps in
 * memory of its own: grown by doubling, never shrunk */
size_t wb_renderer_draw_held(const wb_renderer *r)
{
    const wb_layers *l = &r->layers;
    size_t b = l->inst_cap * sizeof *l->inst + l->seg_cap * sizeof *l->seg + l->sv_cap * sizeof *l->sv +
               l->si_cap * sizeof *l->si + l->pair_cap * sizeof *l->pairs + (l->pair_cap / 2 + 1) * sizeof *l->strain +
               l->vstrain_cap * sizeof *l->vstrain + l->flag_cap + l->scratch_cap * sizeof *l->scratch +
               l->mstrain_cap * sizeof *l->mstrain;
    if (r->gl_ready) b += r->gl.inst_cap + r->gl.surf_cap + r->gl.surf_idx_cap + r->gl.seg_cap;
    return b;
}

size_t wb_renderer_draw_bytes(const wb_renderer *r, const wb_world *w, const wb_draw_skin *sk, int nsk)
{
    if (!r->be->gl) return 0;
    size_t np = (size_t)wb_particle_count(w), nc = (size_t)wb_collider_count(w) + (size_t)wb_rigid_count(w);
    size_t nd = (size_t)wb_world_distance_pairs(w, NULL, NULL), nv = np, nt = 0;
    for (int32_t s = 0; s < wb_surface_count(w); s++) {
        int32_t k;
        wb_surface_triangles(w, s, &k);
        nt += (size_t)k;
    }
    const size_t nst = nt;   /* the surfaces' triangles: a vertex per corner at most (creases) */
    nv += 3 * nst;
    for (int i = 0; i < nsk; i++) nv += (size_t)sk[i].nv, nt += (size_t)sk[i].nt;
    /* what wb_layers_build fills (instances, links, surface vertices and indices, each
     * twice: the layers and the GL buffers), its per-pair and per-particle arrays and
     * its scratch (a normal accumulator, an owner per particle, the automatic strain
     * scale's sample; per surface triangle two normals, its corners' incidence, a flag;
     * the broken links) */
    return 2 * ((np + 3 * nc) * sizeof(wb_inst) + nd * sizeof(wb_seg) + nv * WB_SV * sizeof(float) + 3 * nt * sizeof(GLuint)) +
           nd * (2 * sizeof(int32_t) + sizeof(wb_real) + sizeof(float) + sizeof(uint64_t)) +
           np * (7 * sizeof(float) + 1 + 3 * sizeof(double) + 2 + sizeof(int32_t)) +
           nst * (6 * sizeof(double) + 3 * sizeof(int32_t) + 1);
}

void wb_renderer_destroy(wb_renderer *r)
{
    if (!r) return;
    pass_report(r);
    if (r->ctx) {
        if (r->gl_ready && r->be->make_current(r->ctx)) wb_gl_free(&r->gl);
        r->be->destroy(r->ctx);
    }
    free(r->rgb);
    free(r->luma);
    free(r->sky);
    wb_layers_free(&r->layers);
    const bool gl = r->be->gl;
    free(r);
    /* llvmpipe's buffers (the 4 MB shadow map, ...) raise glibc's mmap threshold when
     * freed, so the next renderer's land in the heap, where freeing them does not lower
     * RSS: measured, each renderer made and closed kept 4 MB. Give the free pages back */
    if (gl) malloc_trim(0);
}

void wb_renderer_size(const wb_renderer *r, int *width, int *height)
{
    *width = r->w;
    *height = r->h;
}

int wb_renderer_samples(const wb_renderer *r) { return r->samples; }
void wb_renderer_set_fxaa(wb_renderer *r, bool on) { r->fxaa = on; }
bool wb_renderer_fxaa(const wb_renderer *r) { return r->fxaa; }
const char *wb_renderer_info(const wb_renderer *r) { return r->info; }
const uint8_t *wb_renderer_pixels(const wb_renderer *r) { return r->rgb; }

void wb_renderer_camera(wb_renderer *r, const double eye[3], const double target[3], const double up[3], double fov)
{
    r->fixed = true;
    memcpy(r->eye, eye, sizeof r->eye);
    memcpy(r->target, target, sizeof r->target);
    memcpy(r->up, up, sizeof r->up);
    r->fov = fov;
    r->have_box = false;   /* a new shot: the extent starts again */
}

void wb_renderer_auto_camera(wb_renderer *r)
{
    r->fixed = false;
    r->have_box = false;
}

void wb_renderer_get_camera(const wb_renderer *r, double eye[3], double target[3], double up[3], double *fov)
{
    memcpy(eye, r->cam_eye, sizeof r->cam_eye);
    memcpy(target, r->cam_target, sizeof r->cam_target);
    memcpy(up, r->cam_up, sizeof r->cam_up);
    *fov = r->cam_fov;
}

bool wb_renderer_project(const wb_renderer *r, const double p[3], double *x, double *y, double *depth)
{
    if (!r->drawn) return false;
    double c[4];
    for (int i = 0; i < 4; i++) c[i] = r->vp[i * 4] * p[0] + r->vp[i * 4 + 1] * p[1] + r->vp[i * 4 + 2] * p[2] + r->vp[i * 4 + 3];
    if (c[3] <= 1e-12) return false;
    *x = (c[0] / c[3] * 0.5 + 0.5) * r->w;
    *y = (0.5 - c[1] / c[3] * 0.5) * r->h;
    if (depth) *depth = c[3];
    return true;
}

/* ---- the scene's extent ----------------------------------------------------------------- */
typedef struct box { double lo[3], hi[3]; bool any; } box;

static void box_add(box *b, const double p[3], double r)
{
    for (int k = 0; k < 3; k++) {
        if (!b->any || p[k] - r < b->lo[k]) b->lo[k] = p[k] - r;
        if (!b->any || p[k] + r > b->hi[k]) b->hi[k] = p[k] + r;
    }
    b->any = true;
}

/* how much a plane's normal points up (n.y / |n|; 0 when degenerate) */
static double up_part(const wb_real n[3])
{
    double l = sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
    return l > 0 ? n[1] / l : 0;
}

/* a plane collider facing (nearly) straight up: the ground; *height: where it is */
static bool floor_height(const wb_collider_def *d, double *height)
{
    if (d->shape != WB_SHAPE_PLANE || up_part(d->normal) < 0.9) return false;
    *height = d->offset / sqrt(d->normal[0] * d->normal[0] + d->normal[1] * d->normal[1] + d->normal[2] * d->normal[2]);
    return true;
}

/* a shape's solid (wobble.h): a sphere, a cylinder's two ends with its radius, a box's
 * corners */
static void solid_add(box *b, const wb_solid *s)
{
    const double c[3] = { s->c[0], s->c[1], s->c[2] };
    if (s->kind == WB_SOLID_SPHERE) box_add(b, c, s->radius);
    else if (s->kind == WB_SOLID_CYLINDER) {
        const double a[3] = { s->a[0], s->a[1], s->a[2] }, e[3] = { s->b[0], s->b[1], s->b[2] };
        box_add(b, a, s->radius);
        box_add(b, e, s->radius);
    } else {
        for (int k = 0; k < 8; k++) {
            double p[3];
            for (int r = 0; r < 3; r++)
                p[r] = c[r] + (k & 1 ? 1 : -1) * s->axes[0][r] + (k & 2 ? 1 : -1) * s->axes[1][r] +
                       (k & 4 ? 1 : -1) * s->axes[2][r];
            box_add(b, p, 0);
        }
    }
}

/* particles and the finite colliders; an upward plane below is pulled in when it is
 * near, so the ground the scene rests on is in the picture */
static box scene_box(const wb_world *w)
{
    box b = { { 0 }, { 0 }, false };
    int32_t np = wb_particle_count(w);
    const wb_real *x = wb_particle_positions(w);
    for (int32_t i = 0; i < np; i++) {
        double p[3] = { x[3 * i], x[3 * i + 1], x[3 * i + 2] };
        if (isfinite(p[0]) && isfinite(p[1]) && isfinite(p[2])) box_add(&b, p, wb_particle_radius(w, i));
    }
    int32_t nc = wb_collider_count(w);
    for (int32_t i = 0; i < nc; i++) {
        wb_collider_def d;
        wb_collider_get_def(w, wb_collider_at(w, i), &d);
        double c[3] = { d.center[0], d.center[1], d.center[2] };
        wb_solid sol[WB_MAX_SOLIDS];
        const int ns = wb_collider_solids(w, wb_collider_at(w, i), sol);
        for (int j = 0; j < ns; j++) solid_add(&b, &sol[j]);
        const wb_real *v;
        const int32_t *t;
        int32_t nt = 0, nv = wb_collider_mesh(w, wb_collider_at(w, i), &v, &t, &nt); /* 0: not a mesh */
        if (nv > 0) {
            double m[9];
            quat_mat(d.rotation, m);
            for (int32_t k = 0; k < nv; k++) {
                const wb_real *q = &v[3 * k];
                double p[3];
                for (int r = 0; r < 3; r++) p[r] = c[r] + m[r * 3] * q[0] + m[r * 3 + 1] * q[1] + m[r * 3 + 2] * q[2];
                box_add(&b, p, 0);
            }
        }
    }
    for (int32_t i = 0; i < wb_rigid_count(w); i++) {
        wb_rigid_def d;
        wb_rigid_get_def(w, wb_rigid_at(w, i), &d);
        double c[3] = { d.pos[0], d.pos[1], d.pos[2] };
        const double r = wb_rigid_bound(w, wb_rigid_at(w, i));
        if (isfinite(c[0] + c[1] + c[2] + r)) box_add(&b, c, r);
    }
    if (!b.any) {
        double o[3] = { 0, 0, 0 };
        box_add(&b, o, 1);
    }
    double ext = 0;
    for (int k = 0; k < 3; k++) ext = fmax(ext, b.hi[k] - b.lo[k]);
    ext = fmax(ext, 1e-3);
    double lo_ground = b.lo[1];
    for (int32_t i = 0; i < nc; i++) {
        wb_collider_def d;
        wb_collider_get_def(w, wb_collider_at(w, i), &d);
        double h;
        if (!floor_height(&d, &h)) continue;
        /* the gap down to the floor: closed when under ext, then less and less of it up
         * to 2 ext, so a body nearing the ground zooms out smoothly instead of in one jump */
        double g = b.lo[1] - h, pull = g <= ext ? g : g < 2 * ext ? 2 * ext - g : 0;
        if (g > 0) lo_ground = fmin(lo_ground, b.lo[1] - pull);
    }
    b.lo[1] = lo_ground;
    return b;
}

/* the default camera: a three-quarter view from the front right, as close as the
 * box allows with a margin */
static void frame_box(wb_renderer *r, const double lo[3], const double hi[3])
{
    double dir[3] = { 0.35, 0.3, 1.0 }, up[3] = { 0, 1, 0 }, c[3], s[3], u[3], f[3];
    norm3(dir);
    for (int k = 0; k < 3; k++) c[k] = 0.5 * (lo[k] + hi[k]), f[k] = -dir[k];
    cross3(f, up, s);
    norm3(s);
    cross3(s, f, u);
    double ty = tan(r->fov * M_PI / 360) * 0.9, tx = ty * r->w / r->h, dist = 1e-3;
    for (int k = 0; k < 8; k++) {
        double p[3] = { (k & 1 ? hi[0] : lo[0]) - c[0], (k & 2 ? hi[1] : lo[1]) - c[1], (k & 4 ? hi[2] : lo[2]) - c[2] };
        double z = dot3(p, dir);
        dist = fmax(dist, fmax(z + fabs(dot3(p, s)) / tx, z + fabs(dot3(p, u)) / ty));
    }
    for (int k = 0; k < 3; k++) r->cam_eye[k] = c[k] + dir[k] * dist, r->cam_target[k] = c[k], r->cam_up[k] = up[k];
    r->cam_fov = r->fov;
}

/* ---- passes ------------------------------------------------------------------------------ */
static void set_mat(GLuint prog, const char *name, const double m[16])
{
    float f[16];
    to_gl(m, f);
    glUniformMatrix4fv(glGetUniformLocation(prog, name), 1, GL_FALSE, f);
}

static void set_vec(GLuint prog, const char *name, double x, double y, double z)
{
    glUniform3f(glGetUniformLocation(prog, name), (float)x, (float)y, (float)z);
}

/* the fine spheres (colliders, capsule caps) seen under this many pixels of radius are
 * drawn with the coarse mesh: 16 slices are then within a fifth of a pixel of round, and a
 * capsule's thin caps took 3,000 triangles each, rasterised per sample */
#define SPHERE_LO_PIXELS 10.0

/* the fine spheres seen small first in their group (order does not matter: opaque,
 * depth-tested); returns how many */
static size_t small_spheres_first(wb_layers *l, const double vp[16], double fov, int h)
{
    const double f = 0.5 * h / tan(fov * M_PI / 360);
    size_t k = l->first[WB_G_HI];
    const size_t end = k + l->count[WB_G_HI];
    for (size_t i = k; i < end; i++) {
        const float *m = l->inst[i].m;
        const double rad = sqrt((double)m[0] * m[0] + (double)m[1] * m[1] + (double)m[2] * m[2]);
        const double wc = vp[12] * m[12] + vp[13] * m[13] + vp[14] * m[14] + vp[15];
        if (!(wc > rad && rad * f / wc < SPHERE_LO_PIXELS)) continue;
        if (i != k) {
            wb_inst t = l->inst[k];
            l->inst[k] = l->inst[i], l->inst[i] = t;
        }
        k++;
    }
    return k - l->first[WB_G_HI];
}

static void draw_meshes(wb_renderer *r)
{
    static const int mesh_of[WB_G_COUNT] = { MESH_SPHERE_LO, MESH_SPHERE_HI, MESH_CYLINDER, MESH_BOX };
    const wb_layers *l = &r->layers;
    for (int g = 0; g < WB_G_COUNT; g++) {
        /* the fine spheres' group in two draws: those seen small with the coarse mesh */
        for (int part = 0; part < (g == WB_G_HI ? 2 : 1); part++) {
            const size_t small = g == WB_G_HI ? r->hi_small : 0;
            const size_t first = l->first[g] + (part ? small : 0), count = g != WB_G_HI ? l->count[g] : part ? l->count[g] - small : small;
            const int mesh = g == WB_G_HI && part == 0 ? MESH_SPHERE_LO : mesh_of[g];
            if (!count) continue;
            wb_gl_inst_attribs(&r->gl, first);
            glDrawElementsInstanced(GL_TRIANGLES, r->gl.mesh_count[mesh], GL_UNSIGNED_INT,
                                    (const void *)((size_t)r->gl.mesh_first[mesh] * sizeof(GLuint)), (GLsizei)count);
        }
    }
}

static void draw_surfaces(wb_renderer *r)
{
    glBindVertexArray(r->gl.vao_surf);
    /* constant instance attributes: identity model and normal matrices */
    glVertexAttrib4f(2, 1, 0, 0, 0), glVertexAttrib4f(3, 0, 1, 0, 0);
    glVertexAttrib4f(4, 0, 0, 1, 0), glVertexAttrib4f(5, 0, 0, 0, 1);
    glVertexAttrib3f(6, 1, 0, 0), glVertexAttrib3f(7, 0, 1, 0), glVertexAttrib3f(8, 0, 0, 1);
    glDrawElements(GL_TRIANGLES, (GLsizei)r->layers.nidx, GL_UNSIGNED_INT, (const void *)0);
}

/* a plane's frame: the point nearest c, the grid's axes gu and gv and the unit normal gn;
 * returns false when the normal is degenerate */
static bool plane_frame(const wb_real nrm[3], double offset, const double c[3],
                        double center[3], double gu[3], double gv[3], double gn[3])
{
    double n[3] = { nrm[0], nrm[1], nrm[2] };
    double l = norm3(n);
    if (l <= 0) return false;
    double d = offset / l, h = dot3(n, c) - d;
    for (int k = 0; k < 3; k++) center[k] = c[k] - h * n[k], gn[k] = n[k];
    if (fabs(up_part(nrm)) >= 0.9) {   /* level (a floor or a ceiling): lines along x and z */
        double x[3] = { 1, 0, 0 };
        cross3(x, n, gv);
        norm3(gv);
        cross3(n, gv, gu);
    } else {
        double y[3] = { 0, 1, 0 };
        cross3(n, y, gu);
        norm3(gu);
        cross3(gu, n, gv);
    }
    return true;
}

/* where view rays meet the plane gn.x = gn.eye + s (t > 0): the ray's denominator
 * gn.(cf + x cr + y cu) is linear in the pixel's NDC (x, y), so that is a half-plane of
 * the screen; the screen's square clipped to it (at most 5 corners, 0 when the plane is
 * not seen). Its edge is the horizon, where the ground has fogged out or ended anyway */
static int below_horizon(const double gn[3], double s, const double cam[3][3], float poly[10])
{
    static const double sq[4][2] = { { -1, -1 }, { 1, -1 }, { 1, 1 }, { -1, 1 } };
    if (!(s != 0)) return 0;
    const double sg = s > 0 ? 1 : -1, a = sg * dot3(gn, cam[0]), b = sg * dot3(gn, cam[1]), c = sg * dot3(gn, cam[2]);
    int n = 0;
    for (int i = 0; i < 4; i++) {
        const double *p = sq[i], *q = sq[(i + 1) % 4];
        const double vp = a + b * p[0] + c * p[1], vq = a + b * q[0] + c * q[1];
        if (vp > 0) poly[2 * n] = (float)p[0], poly[2 * n + 1] = (float)p[1], n++;
        if ((vp > 0) != (vq > 0)) {
            const double t = vp / (vp - vq);
            poly[2 * n] = (float)(p[0] + t * (q[0] - p[0])), poly[2 * n + 1] = (float)(p[1] + t * (q[1] - p[1])), n++;
        }
    }
    return n >= 3 ? n : 0;
}

/* where a shadow can fall, for the ground's two programs: the light's view (row-major,
 * its x and y rows are light-space x and y), what the shadow pass drew and how far past
 * a caster's light-space bounds a lookup reaches */
typedef struct shadow_reach {
    double lview[16], margin;
    const wb_layers *l;
    bool surfaces;
} shadow_reach;

#define SHADOW_TILE 32   /* pixels: the ground's programs are chosen per tile */

/* a plane's light-space (x, y) -> clip space map: the plane's point with those light-space
 * coordinates is P0 + x A + y B, so its clip position is q0 + x qa + y qb */
typedef struct plane_map { double q0[4], qa[4], qb[4]; } plane_map;

static bool plane_map_of(const wb_renderer *r, const shadow_reach *s, const double gn[3], double off, plane_map *m)
{
    const double *ex = s->lview, *ey = s->lview + 4;
    /* the rows ex, ey, gn of a 3x3 system: its inverse's columns by cross products */
    double c0[3], c1[3], c2[3];
    cross3(ey, gn, c0);
    cross3(gn, ex, c1);
    cross3(ex, ey, c2);
    const double det = dot3(ex, c0);
    if (!(fabs(det) > 1e-6)) return false;   /* the light along the plane */
    double p0[3], a[3], b[3];
    for (int k = 0; k < 3; k++)
        p0[k] = (-ex[3] * c0[k] - ey[3] * c1[k] + off * c2[k]) / det, a[k] = c0[k] / det, b[k] = c1[k] / det;
    for (int i = 0; i < 4; i++) {
        const double *v = r->vp + 4 * i;
        m->q0[i] = v[0] * p0[0] + v[1] * p0[1] + v[2] * p0[2] + v[3];
        m->qa[i] = v[0] * a[0] + v[1] * a[1] + v[2] * a[2];
        m->qb[i] = v[0] * b[0] + v[1] * b[1] + v[2] * b[2];
    }
    return true;
}

/* mark the tiles where the plane's points of light-space bounds lo..hi (a parallelogram)
 * are seen; false when a corner is behind the camera (then anything may be) */
static bool mark_footprint(const wb_renderer *r, const plane_map *m, const double lo[2], const double hi[2],
                           uint8_t *tiles, int tw, int th)
{
    double x0 = 0, x1 = 0, y0 = 0, y1 = 0;
    for (int k = 0; k < 4; k++) {
        const double X = k & 1 ? hi[0] : lo[0], Y = k & 2 ? hi[1] : lo[1];
        double q[4];
        for (int i = 0; i < 4; i++) q[i] = m->q0[i] + X * m->qa[i] + Y * m->qb[i];
        if (!(q[3] > 1e-9)) return false;
        /* window pixels, rows from the bottom (GL's) */
        const double x = (q[0] / q[3] * 0.5 + 0.5) * r->w, y = (q[1] / q[3] * 0.5 + 0.5) * r->h;
        if (k == 0 || x < x0) x0 = x;
        if (k == 0 || x > x1) x1 = x;
        if (k == 0 || y < y0) y0 = y;
        if (k == 0 || y > y1) y1 = y;
    }
    /* a pixel more each side: every pixel centre inside is in a marked tile */
    const int tx0 = (int)fmax(0, floor((x0 - 1) / SHADOW_TILE)), tx1 = (int)fmin(tw - 1, floor((x1 + 1) / SHADOW_TILE));
    const int ty0 = (int)fmax(0, floor((y0 - 1) / SHADOW_TILE)), ty1 = (int)fmin(th - 1, floor((y1 + 1) / SHADOW_TILE));
    for (int ty = ty0; ty <= ty1; ty++)
        for (int tx = tx0; tx <= tx1; tx++) tiles[ty * tw + tx] = 1;
    return true;
}

/* the tiles of the frame where the plane gn.x = off may have a shadow: under each
 * instance (its unit cube holds the sphere, cylinder and box meshes) and each surface
 * triangle along the light; false: all of them (it cannot be told) */
static bool shadow_tiles(const wb_renderer *r, const shadow_reach *s, const double gn[3], double off, uint8_t *tiles,
                         int tw, int th)
{
    plane_map m;
    if (!plane_map_of(r, s, gn, off, &m)) return false;
    const double *V = s->lview, e = s->margin;
    const wb_layers *l = s->l;
    const size_t ninst = l->first[WB_G_COUNT - 1] + l->count[WB_G_COUNT - 1];
    for (size_t i = 0; i < ninst; i++) {
        const float *t = l->inst[i].m;
        /* the mesh's box: y in 0..1 for a cylinder, -1..1 otherwise; cut along its
         * longest axis into near-cubes (a long thin capsule's bounds across the light
         * would cover much of the ground) */
        const bool cyl = i >= l->first[WB_G_CYL] && i < l->first[WB_G_CYL] + l->count[WB_G_CYL];
        double len[3];
        int j = 0;
        for (int col = 0; col < 3; col++) {
            len[col] = sqrt((double)t[4 * col] * t[4 * col] + (double)t[4 * col + 1] * t[4 * col + 1] +
                            (double)t[4 * col + 2] * t[4 * col + 2]) * (cyl && col == 1 ? 0.5 : 1);
            if (len[col] > len[j]) j = col;
        }
        const double thin = fmax(fmin(len[(j + 1) % 3], len[(j + 2) % 3]), 1e-9 * len[j]);
        const int pieces = (int)fmin(64, fmax(1, ceil(len[j] / thin)));
        const double y0 = cyl ? 0 : -1, span = cyl ? 1 : 2;
        for (int piece = 0; piece < pieces; piece++) {
            double lo[2], hi[2];
            const double mid = y0 + span * (piece + 0.5) / pieces, half = 0.5 * span / pieces;
            for (int a = 0; a < 2; a++) {
                const double *row = V + 4 * a;
                double c = row[3], h = e;
                for (int k = 0; k < 3; k++) c += row[k] * t[12 + k];
                for (int col = 0; col < 3; col++) {
                    const double d = row[0] * t[4 * col] + row[1] * t[4 * col + 1] + row[2] * t[4 * col + 2];
                    const double cm = cyl && col == 1 ? 0.5 : 0, hm = cyl && col == 1 ? 0.5 : 1;
                    if (col == j) c += d * mid, h += fabs(d) * half;
                    else c += d * cm, h += fabs(d) * hm;
                }
                lo[a] = c - h, hi[a] = c + h;
            }
            if (!mark_footprint(r, &m, lo, hi, tiles, tw, th)) return false;
        }
    }
    for (size_t i = 0; s->surfaces && i + 2 < l->nidx; i += 3) {
        double lo[2], hi[2];
        for (int k = 0; k < 3; k++) {
            const float *q = l->sv + WB_SV * (size_t)l->si[i + k];
            for (int a = 0; a < 2; a++) {
                const double *row = V + 4 * a, c = row[0] * q[0] + row[1] * q[1] + row[2] * q[2] + row[3];
                if (k == 0 || c - e < lo[a]) lo[a] = c - e;
                if (k == 0 || c + e > hi[a]) hi[a] = c + e;
            }
        }
        if (!mark_footprint(r, &m, lo, hi, tiles, tw, th)) return false;
    }
    return true;
}

/* the tiles of value v as rectangles of window pixels (x, y, width, height): each row's
 * runs, a run the same as the one below it merged into that rectangle; returns how many */
static int tile_rects(const uint8_t *tiles, int tw, int th, uint8_t v, int w, int h, int (*out)[4], int *open)
{
    int n = 0;
    for (int x = 0; x < tw; x++) open[x] = -1;
    for (int ty = 0; ty < th; ty++) {
        const int y0 = ty * SHADOW_TILE, y1 = y0 + SHADOW_TILE < h ? y0 + SHADOW_TILE : h;
        for (int tx = 0; tx < tw;) {
            if (tiles[ty * tw + tx] != v) {
                open[tx++] = -1;
                continue;
            }
            int end = tx;
            while (end < tw && tiles[ty * tw + end] == v) end++;
            const int x0 = tx * SHADOW_TILE, x1 = end * SHADOW_TILE < w ? end * SHADOW_TILE : w, o = open[tx];
            if (o >= 0 && out[o][0] == x0 && out[o][2] == x1 - x0 && out[o][1] + out[o][3] == y0) {
                out[o][3] = y1 - out[o][1];
            } else {
                out[n][0] = x0, out[n][1] = y0, out[n][2] = x1 - x0, out[n][3] = y1 - y0;
                open[tx] = n++;
            }
            for (int k = tx + 1; k < end; k++) open[k] = -1;
            tx = end;
        }
    }
    return n;
}

/* the plane's depth (NDC z) at NDC (x, y) is a + b x + c y: a point's NDC z is affine
 * in 1 / t along its view ray (the eye has clip w 0, and a ray's clip z and w do not
 * depend on x and y: r and u are square to the view axis), and 1 / t = gn.dir / s is
 * affine in x and y. Exact up to rounding, at the horizon too (its limit) */
static void plane_depth(const wb_renderer *r, const double gn[3], double s, const double cam[3][3], double abc[3])
{
    const double *vp = r->vp, *e = r->cam_eye;
    const double ez = vp[8] * e[0] + vp[9] * e[1] + vp[10] * e[2] + vp[11];
    const double ew = vp[12] * e[0] + vp[13] * e[1] + vp[14] * e[2] + vp[15];
    double z[3];
    for (int k = 0; k < 3; k++) {
        const double x = k == 1, y = k == 2;
        double d[3];
        for (int i = 0; i < 3; i++) d[i] = cam[0][i] + x * cam[1][i] + y * cam[2][i];
        const double it = dot3(gn, d) / s, dz = vp[8] * d[0] + vp[9] * d[1] + vp[10] * d[2];
        const double dw = vp[12] * d[0] + vp[13] * d[1] + vp[14] * d[2];
        z[k] = (ez * it + dz) / (ew * it + dw);
    }
    abc[0] = z[0], abc[1] = z[1] - z[0], abc[2] = z[2] - z[0];
}

/* the part of a convex polygon (n corners x, y) where f = a + b x + c y <= 0 (sign 1) or
 * >= 0 (sign -1), into out (n + 1 corners at most); its corner count, 0 when nothing */
static int clip_poly(const double *poly, int n, const double abc[3], double sign, double *out)
{
    int k = 0;
    for (int i = 0; i < n; i++) {
        const double *p = poly + 2 * i, *q = poly + 2 * ((i + 1) % n);
        const double fp = sign * (abc[0] + abc[1] * p[0] + abc[2] * p[1]), fq = sign * (abc[0] + abc[1] * q[0] + abc[2] * q[1]);
        if (fp <= 0) out[2 * k] = p[0], out[2 * k + 1] = p[1], k++;
        if ((fp <= 0) != (fq <= 0)) {
            const double t = fp / (fp - fq);
            out[2 * k] = p[0] + t * (q[0] - p[0]), out[2 * k + 1] = p[1] + t * (q[1] - p[1]), k++;
        }
    }
    return k >= 3 ? k : 0;
}

/* a plane (n.x = offset) over the part of the screen below its horizon; a floor reaches
 * the horizon, fogged over `fog`; any other plane is a disc of radius ext around center.
 * cam: the view rays' axes (camera_rays). Two programs draw it: the one that looks up
 * the shadow map on the tiles where a shadow can fall (shadow_tiles), the one that does
 * not on the others; outside a shadow both give the same colour, so no seam */
static void draw_grid(wb_renderer *r, const double cam[3][3], const double center[3], const double gu[3],
                      const double gv[3], const double gn[3], double spacing, double ext, bool floor, double fog,
                      const shadow_reach *sr)
{
    float flat[10];
    const double s = dot3(gn, center) - dot3(gn, r->cam_eye);
    const int nflat = below_horizon(gn, s, cam, flat);
    if (!nflat) return;
    /* the view rays meet the plane at t = s / gn.dir (a view depth: dir's forward part is
     * 1), 1 / t affine on the screen: nearer than where the ground has faded out (a floor:
     * 2.5 fog lengths, its alpha under 0.002, which grid_fs discards; a disc: its edge) */
    double corners[10], poly[12], near[14], far[14], toc[3];
    for (int i = 0; i < 2 * nflat; i++) corners[i] = flat[i];
    for (int k = 0; k < 3; k++) toc[k] = center[k] - r->cam_eye[k];
    const double tmax = floor ? 2.5 * fog : sqrt(dot3(toc, toc)) + ext;
    const double inv_t[3] = { 1 / tmax - dot3(gn, cam[0]) / s, -dot3(gn, cam[1]) / s, -dot3(gn, cam[2]) / s };
    const int np = clip_poly(corners, nflat, inv_t, 1, poly);
    if (!np) return;
    /* the depth from the corners (a fragment shader writing its depth would test it late,
     * at a third of the ground's cost), kept just in front of the sky beyond the far plane:
     * the polygon cut where the plane's depth reaches that, the part beyond at that depth */
    double abc[3];
    const double zmax = 2 * 0.99999 - 1;
    plane_depth(r, gn, s, cam, abc);
    const double cut[3] = { abc[0] - zmax, abc[1], abc[2] };
    const int nnear = clip_poly(poly, np, cut, 1, near), nfar = clip_poly(poly, np, cut, -1, far);
    float corner[64], wpos[48];
    for (int i = 0; i < nnear + nfar; i++) {
        const double *q = i < nnear ? near + 2 * i : far + 2 * (i - nnear);
        double d[3];
        for (int k = 0; k < 3; k++) d[k] = cam[0][k] + q[0] * cam[1][k] + q[1] * cam[2][k];
        const double t = s / dot3(gn, d), z = abc[0] + abc[1] * q[0] + abc[2] * q[1];
        const int slot = i < nnear ? i : 8 + i - nnear;
        corner[4 * slot] = (float)q[0], corner[4 * slot + 1] = (float)q[1];
        corner[4 * slot + 2] = (float)(i < nnear ? fmin(z, zmax) : zmax), corner[4 * slot + 3] = (float)t;
        for (int k = 0; k < 3; k++) wpos[3 * slot + k] = (float)(r->cam_eye[k] + t * d[k]);
    }
    /* its light, the same over the plane: the side seen (normal n) lit by the ambient and
     * the key light (the ground's colour times each, linear), and unshadowed in sRGB */
    double n[3], L[3] = { light_dir[0], light_dir[1], light_dir[2] };
    norm3(L);
    const double side = s <= 0 ? 1 : -1;   /* the eye above the plane (along gn): gn */
    for (int k = 0; k < 3; k++) n[k] = side * gn[k];
    const double ndl = fmax(dot3(n, L), 0), up = n[1] * 0.5 + 0.5;
    float g[3], lit[3], base_amb[3], base_key[3];
    wb_lin3(col_ground, g);
    for (int k = 0; k < 3; k++) {
        base_amb[k] = (float)(g[k] * (amb_down[k] + (amb_up[k] - amb_down[k]) * up));
        base_key[k] = (float)(g[k] * key_col[k] * ndl);
        lit[k] = (float)sqrt(fmin(base_amb[k] + base_key[k], 1));
    }
    const int tw = (r->w + SHADOW_TILE - 1) / SHADOW_TILE, th = (r->h + SHADOW_TILE - 1) / SHADOW_TILE;
    const size_t nt = (size_t)tw * (size_t)th;
    /* the tiles, then the rectangles of each program and a row's open runs */
    uint8_t *tiles = calloc(nt, 1);
    int (*rects)[4] = tiles ? malloc(2 * nt * sizeof *rects) : NULL;
    int *open = rects ? malloc((size_t)tw * sizeof *open) : NULL;
    int nrect[2] = { 1, 0 };
    int whole[4] = { 0, 0, r->w, r->h };
    const bool tiled = open && shadow_tiles(r, sr, gn, dot3(gn, center), tiles, tw, th);
    if (tiled) {
        nrect[0] = tile_rects(tiles, tw, th, 1, r->w, r->h, rects, open);
        nrect[1] = tile_rects(tiles, tw, th, 0, r->w, r->h, rects + nt, open);
    }
    glBindVertexArray(r->gl.vao_empty);
    glEnable(GL_SCISSOR_TEST);
    /* ground nearer than the near plane is drawn at depth 0, as a written depth was */
    glEnable(GL_DEPTH_CLAMP);
    for (int pass = 0; pass < 2; pass++) {
        if (!nrect[pass]) continue;
        GLuint p = pass == 0 ? r->gl.prog_grid : r->gl.prog_grid_plain;
        glUseProgram(p);
        glUniform4fv(glGetUniformLocation(p, "u_poly"), 16, corner);
        glUniform3fv(glGetUniformLocation(p, "u_wpos"), 16, wpos);
        set_vec(p, "u_center", center[0], center[1], center[2]);
        set_vec(p, "u_gu", gu[0], gu[1], gu[2]);
        set_vec(p, "u_gv", gv[0], gv[1], gv[2]);
        set_vec(p, "u_nrm", n[0], n[1], n[2]);
        glUniform1f(glGetUniformLocation(p, "u_spacing"), (float)spacing);
        glUniform1f(glGetUniformLocation(p, "u_extent"), (float)ext);
        glUniform1f(glGetUniformLocation(p, "u_fog2"), (float)(1 / (fog * fog)));
        glUniform1i(glGetUniformLocation(p, "u_floor"), floor);
        glUniform3fv(glGetUniformLocation(p, "u_lit"), 1, lit);
        glUniform3fv(glGetUniformLocation(p, "u_base_amb"), 1, base_amb);
        glUniform3fv(glGetUniformLocation(p, "u_base_key"), 1, base_key);
        for (int k = 0; k < nrect[pass]; k++) {
            /* untold (or out of memory for the tiles): all of it with the shadow map */
            const int *q = tiled ? rects[pass * nt + k] : whole;
            glScissor(q[0], q[1], q[2], q[3]);
            if (nnear) glDrawArrays(GL_TRIANGLE_FAN, 0, nnear);
            if (nfar) glDrawArrays(GL_TRIANGLE_FAN, 8, nfar);
        }
    }
    glDisable(GL_SCISSOR_TEST);
    glDisable(GL_DEPTH_CLAMP);
    free(open);
    free(rects);
    free(tiles);
}

/* the camera's axes for the ground's view rays: forward, and right and up scaled to
 * the frame's edges (a pixel's ray is f + x r + y u, x and y in NDC, -1..1) */
static void camera_rays(const wb_renderer *r, double cam[3][3])
{
    double f[3], s[3], u[3];
    for (int k = 0; k < 3; k++) f[k] = r->cam_target[k] - r->cam_eye[k];
    norm3(f);
    cross3(f, r->cam_up, s);
    norm3(s);
    cross3(s, f, u);
    const double ty = tan(r->cam_fov * M_PI / 360), tx = ty * r->w / r->h;
    for (int k = 0; k < 3; k++) cam[0][k] = f[k], cam[1][k] = tx * s[k], cam[2][k] = ty * u[k];
}

/* uniforms of the lit programs */
static void light_uniforms(GLuint p, const double vp[16], const double lvp[16], const double eye[3],
                           const double L[3], double bias, bool shadows)
{
    glUseProgram(p);
    set_mat(p, "u_vp", vp);
    set_mat(p, "u_lvp", lvp);
    set_vec(p, "u_eye", eye[0], eye[1], eye[2]);
    set_vec(p, "u_light", L[0], L[1], L[2]);
    glUniform1f(glGetUniformLocation(p, "u_bias"), (float)bias);
    glUniform1i(glGetUniformLocation(p, "u_shadows"), shadows);
    glUniform1i(glGetUniformLocation(p, "u_smap"), 0);
    glUniform3fv(glGetUniformLocation(p, "u_amb_down"), 1, amb_down);
    glUniform3fv(glGetUniformLocation(p, "u_amb_up"), 1, amb_up);
    glUniform3fv(glGetUniformLocation(p, "u_key"), 1, key_col);
}

/* the sky's colour of each row, top first, as the sky's shader would draw it (bg_fs:
 * the gradient at the pixel's centre, rounded to 8 bits); NULL: out of memory */
static const uint8_t *sky_rows(wb_renderer *r)
{
    if (r->sky) return r->sky;
    r->sky = malloc(3 * (size_t)r->h);
    for (int y = 0; r->sky && y < r->h; y++) {
        const float t = ((float)(r->h - y) - 0.5f) / (float)r->h;
        for (int k = 0; k < 3; k++) r->sky[3 * y + k] = (uint8_t)lrintf(255 * (col_sky_bottom[k] + (col_sky_top[k] - col_sky_bottom[k]) * t));
    }
    return r->sky;
}

static void background_cpu(wb_renderer *r)
{
    for (int y = 0; y < r->h; y++) {
        double t = r->h > 1 ? 1 - (double)y / (r->h - 1) : 1;
        uint8_t c[3];
        for (int k = 0; k < 3; k++) c[k] = (uint8_t)lrint(255 * (col_sky_bottom[k] + (col_sky_top[k] - col_sky_bottom[k]) * t));
        for (int x = 0; x < r->w; x++) memcpy(r->rgb + 3 * ((size_t)y * r->w + x), c, 3);
    }
}

/* the strain colours' legend, bottom left of the frame: "strain" over a bar from blue
 * (compression) through grey to red (tension) and its numbers, the scale in percent,
 * on a light panel; only on frames of at least 320 x 200 (on a thumbnail it would
 * cover the scene) */
static void draw_legend(wb_renderer *r, double scale)
{
    if (r->w < 320 || r->h < 200) return;
    const int ts = r->h >= 540 ? 2 : 1, pad = 4 * ts, m = 6 * ts, line = 11 * ts, bh = 8 * ts;
    char lo[32], hi[32];
    snprintf(hi, sizeof hi, "+%.3g%%", 100 * scale);
    snprintf(lo, sizeof lo, "-%.3g%%", 100 * scale);
    const int bw = fmax(80 * ts, wb_text_width(lo, ts) + wb_text_width(hi, ts) + wb_text_width("0", ts) + 12 * ts);
    const int pw = bw + 2 * pad, ph = 2 * pad + 2 * line + bh + 4 * ts;
    if (pw + 2 * m > r->w || ph + 2 * m > r->h) return;
    const int x0 = m, y0 = r->h - m - ph;
    for (int y = y0; y < y0 + ph; y++)
        for (int x = x0; x < x0 + pw; x++) {
            uint8_t *p = r->rgb + 3 * ((size_t)y * r->w + x);
            for (int k = 0; k < 3; k++) p[k] = (uint8_t)((p[k] + 3 * 242) / 4);
        }
    static const uint8_t ink[3] = { 40, 40, 44 };
    wb_text(r->rgb, r->w, r->h, x0 + pad, y0 + pad, "strain", ink, ts);
    const int by = y0 + pad + line + 2 * ts;
    for (int x = 0; x < bw; x++) {
        float c[3];
        wb_strain_srgb(2.0 * x / (bw - 1) - 1, c);
        for (int y = by; y < by + bh; y++) {
            uint8_t *p = r->rgb + 3 * ((size_t)y * r->w + x0 + pad + x);
            for (int k = 0; k < 3; k++) p[k] = (uint8_t)lrint(255 * c[k]);
        }
    }
    const int ty = by + bh + 2 * ts;
    wb_text(r->rgb, r->w, r->h, x0 + pad, ty, lo, ink, ts);
    wb_text(r->rgb, r->w, r->h, x0 + pad + (bw - wb_text_width("0", ts)) / 2, ty, "0", ink, ts);
    wb_text(r->rgb, r->w, r->h, x0 + pad + bw - wb_text_width(hi, ts), ty, hi, ink, ts);
}

double wb_renderer_strain_scale(const wb_renderer *r)
{
    return r->drawn && r->layers.strain_shown ? r->layers.scale : 0;
}

/* what the default camera frames: the union of the current extent and the eased one,
 * so whatever is there now is always in the picture; the box grows at once and only
 * shrinks eased (a video neither shakes nor cuts a falling body off). Another world,
 * or the same one started again, starts afresh. */
static void follow_box(wb_renderer *r, const wb_world *w, const box *cur)
{
    int64_t frame = wb_world_frame(w);
    if (!r->have_box || w != r->box_world || frame < r->box_frame) {
        memcpy(r->view_lo, cur->lo, sizeof r->view_lo);
        memcpy(r->view_hi, cur->hi, sizeof r->view_hi);
        r->have_box = true;
    } else {
        for (int k = 0; k < 3; k++) {
            r->view_lo[k] = fmin(cur->lo[k], r->view_lo[k] + box_shrink * (cur->lo[k] - r->view_lo[k]));
            r->view_hi[k] = fmax(cur->hi[k], r->view_hi[k] + box_shrink * (cur->hi[k] - r->view_hi[k]));
        }
    }
    r->box_world = w;
    r->box_frame = frame;
}

bool wb_renderer_draw(wb_renderer *r, const wb_world *w, const wb_draw_opts *o, const wb_draw_skin *skins,
                      int nskins, char *err, size_t n)
{
    /* camera and extent */
    pass_mark(r, -1);
    box cur = scene_box(w);
    follow_box(r, w, &cur);
    if (r->fixed) {
        memcpy(r->cam_eye, r->eye, sizeof r->eye);
        memcpy(r->cam_target, r->target, sizeof r->target);
        memcpy(r->cam_up, r->up, sizeof r->up);
        r->cam_fov = r->fov;
    } else {
        frame_box(r, r->view_lo, r->view_hi);
    }
    double c[3], R = 0;
    for (int k = 0; k < 3; k++) {
        double lo = fmin(cur.lo[k], r->view_lo[k]), hi = fmax(cur.hi[k], r->view_hi[k]);
        c[k] = 0.5 * (lo + hi);
        R += 0.25 * (hi - lo) * (hi - lo);
    }
    R = fmax(sqrt(R), 1e-3);
    double ext = 4 * R, to_c[3] = { c[0] - r->cam_eye[0], c[1] - r->cam_eye[1], c[2] - r->cam_eye[2] };
    double dc = sqrt(dot3(to_c, to_c)), zf = dc + 2 * ext, zn = fmax(zf * 2e-4, 0.5 * (dc - 1.5 * R));
    double view[16], proj[16];
    look_at(r->cam_eye, r->cam_target, r->cam_up, view);
    perspective(r->cam_fov, (double)r->w / r->h, zn, zf, proj);
    mat_mul(proj, view, r->vp);
    r->drawn = true;
    if (!r->be->gl) {
        background_cpu(r);
        r->layers.strain_shown = false;
        return true;
    }
    if (!r->be->make_current(r->ctx)) {
        snprintf(err, n, "cannot make the renderer's GL context current");
        return false;
    }

    /* layers */
    wb_layers *l = &r->layers;
    if (!o->skins) nskins = 0;
    if (!wb_layers_build(l, w, o, skins, nskins, R)) {
        snprintf(err, n, "out of memory drawing %d particles", (int)wb_particle_count(w));
        return false;
    }
    pass_mark(r, PASS_LAYERS);
    wb_gl *g = &r->gl;
    r->hi_small = small_spheres_first(l, r->vp, r->cam_fov, r->h);
    size_t ninst = l->first[WB_G_COUNT - 1] + l->count[WB_G_COUNT - 1];
    wb_gl_upload(GL_ARRAY_BUFFER, g->vbo_inst, &g->inst_cap, l->inst, ninst * sizeof *l->inst);
    bool surfaces = l->surfaces && l->nidx > 0;
    if (surfaces) {
        wb_gl_upload(GL_ARRAY_BUFFER, g->vbo_surf, &g->surf_cap, l->sv, WB_SV * l->nv * sizeof *l->sv);
        glBindVertexArray(g->vao_surf);
        wb_gl_upload(GL_ELEMENT_ARRAY_BUFFER, g->ebo_surf, &g->surf_idx_cap, l->si, l->nidx * sizeof *l->si);
        glBindVertexArray(g->vao_surf);   /* growing re-specified the buffers: bind them again */
        glBindBuffer(GL_ELEMENT_ARRAY_BUFFER, g->ebo_surf);
        wb_gl_surf_attribs(g);
    }
    size_t nseg = l->nseg;
    if (nseg) wb_gl_upload(GL_ARRAY_BUFFER, g->vbo_seg, &g->seg_cap, l->seg, nseg * sizeof *l->seg);

    pass_mark(r, PASS_UPLOAD);
    /* the shadow map: an orthographic view along the light over the scene's sphere */
    double L[3] = { light_dir[0], light_dir[1], light_dir[2] }, lvp[16], lview[16], lproj[16];
    norm3(L);
    double leye[3] = { c[0] + 2 * R * L[0], c[1] + 2 * R * L[1], c[2] + 2 * R * L[2] }, lup[3] = { 0, 1, 0 };
    if (fabs(L[1]) > 0.99) lup[1] = 0, lup[2] = 1;
    look_at(leye, c, lup, lview);
    ortho(R, 0.01 * R, 4 * R, lproj);
    mat_mul(lproj, lview, lvp);
    double bias = 3 * R / g->shadow_size;   /* normal offset: a few texels against acne */
    glBindFramebuffer(GL_FRAMEBUFFER, g->fbo_shadow);
    glViewport(0, 0, g->shadow_size, g->shadow_size);
    glEnable(GL_DEPTH_TEST);
    glDepthMask(GL_TRUE);
    glClear(GL_DEPTH_BUFFER_BIT);
    glEnable(GL_POLYGON_OFFSET_FILL);
    glPolygonOffset(2, 4);
    glUseProgram(g->prog_depth);
    set_mat(g->prog_depth, "u_vp", lvp);
    draw_meshes(r);
    if (surfaces) draw_surfaces(r);
    glDisable(GL_POLYGON_OFFSET_FILL);
    pass_mark(r, PASS_SHADOW);

    /* the picture. With one sample the sky is the CPU's (wb_fxaa, sky_copy): where nothing
     * was drawn, alpha 0 from the clear (a pass over the uncovered pixels took 2-3 ms at
     * 720p); samples would mix the clear's black into the edges */
    const uint8_t *sky = r->samples == 1 ? sky_rows(r) : NULL;
    glBindFramebuffer(GL_FRAMEBUFFER, g->fbo_ms);
    glViewport(0, 0, r->w, r->h);
    glClearColor(0, 0, 0, 0);
    glClear(sky ? GL_COLOR_BUFFER_BIT | GL_DEPTH_BUFFER_BIT : GL_DEPTH_BUFFER_BIT);
    glEnable(GL_DEPTH_TEST);
    glActiveTexture(GL_TEXTURE0);
    glBindTexture(GL_TEXTURE_2D, g->tex_shadow);

    /* the ground: every plane collider, or a floor under the scene; its two programs
     * (draw_grid) take the same uniforms */
    double cam[3][3];
    camera_rays(r, cam);
    for (int k = 0; k < 2; k++) {
        const GLuint p = k ? g->prog_grid_plain : g->prog_grid;
        light_uniforms(p, r->vp, lvp, r->cam_eye, L, bias, true);
        glUniform3f(glGetUniformLocation(p, "u_top"), col_sky_top[0], col_sky_top[1], col_sky_top[2]);
        glUniform3f(glGetUniformLocation(p, "u_bottom"), col_sky_bottom[0], col_sky_bottom[1], col_sky_bottom[2]);
        glUniform1f(glGetUniformLocation(p, "u_height"), (float)r->h);
        /* the shadow map's box (ortho, below) lies within sqrt(6) R of c: no shadow beyond */
        set_vec(p, "u_sc", c[0], c[1], c[2]);
        glUniform1f(glGetUniformLocation(p, "u_sr2"), (float)(6.05 * R * R));
    }
    /* a lookup reaches past its point by the normal offset (at most 8 biases) and the
     * filter's texel: 16 texels of margin (a texel is 2R / shadow_size) */
    shadow_reach sr = { .margin = 32 * R / g->shadow_size, .l = l, .surfaces = surfaces };
    memcpy(sr.lview, lview, sizeof sr.lview);
    /* the fog: the ground around the scene stays clear however far the camera is */
    const double spacing = wb_nice_step(R / 6), fog = 2 * dc + 3 * ext;
    double center[3], gu[3], gv[3], gn[3];
    int planes = 0;
    int32_t nc = wb_collider_count(w);
    for (int32_t i = 0; i < nc && (o->colliders || o->grid); i++) {
        wb_collider_def d;
        wb_collider_get_def(w, wb_collider_at(w, i), &d);
        double h;
        const bool floor = floor_height(&d, &h);
        if (d.shape != WB_SHAPE_PLANE || !(o->colliders || (o->grid && floor))) continue;
        if (plane_frame(d.normal, d.offset, c, center, gu, gv, gn)) {
            draw_grid(r, cam, center, gu, gv, gn, spacing, ext, floor, fog, &sr);
            planes++;
        }
    }
    /* the floor under the scene, only below the eye: bodies made above it (a cloth hung
     * flat at the start) would put it overhead, a ceiling hiding them */
    const double floor_h = fmin(cur.lo[1], r->view_lo[1]);
    if (!planes && o->grid && floor_h < r->cam_eye[1]) {
        wb_real up[3] = { 0, 1, 0 };
        if (plane_frame(up, floor_h, c, center, gu, gv, gn))
            draw_grid(r, cam, center, gu, gv, gn, spacing, ext, true, fog, &sr);
    }

    pass_mark(r, PASS_GROUND);
    /* solids, then the surfaces pushed back a little so links on them stay visible */
    light_uniforms(g->prog_mesh, r->vp, lvp, r->cam_eye, L, bias, true);
    glUniform1i(glGetUniformLocation(g->prog_mesh, "u_two_sided"), 0);
    draw_meshes(r);
    if (surfaces) {
        glUniform1i(glGetUniformLocation(g->prog_mesh, "u_two_sided"), 1);
        glEnable(GL_POLYGON_OFFSET_FILL);
        glPolygonOffset(1, 2);
        draw_surfaces(r);
        glDisable(GL_POLYGON_OFFSET_FILL);
    }
    pass_mark(r, PASS_SOLIDS);
    if (nseg) {
        glUseProgram(g->prog_line);
        set_mat(g->prog_line, "u_vp", r->vp);
        glUniform2f(glGetUniformLocation(g->prog_line, "u_half"), 0.5f * r->w, 0.5f * r->h);
        glUniform1f(glGetUniformLocation(g->prog_line, "u_width"), (float)(o->line_width * fmax(r->h / 720.0, 0.5)));
        glBindVertexArray(g->vao_line);
        glDrawArraysInstanced(GL_TRIANGLES, 0, 6, (GLsizei)nseg);
    }
    pass_mark(r, PASS_LINES);
    /* the sky last, behind everything: only uncovered pixels pass the depth test */
    if (!sky) {
        glDepthFunc(GL_LEQUAL);
        glDepthMask(GL_FALSE);
        glUseProgram(g->prog_bg);
        glUniform3f(glGetUniformLocation(g->prog_bg, "u_top"), col_sky_top[0], col_sky_top[1], col_sky_top[2]);
        glUniform3f(glGetUniformLocation(g->prog_bg, "u_bottom"), col_sky_bottom[0], col_sky_bottom[1], col_sky_bottom[2]);
        glBindVertexArray(g->vao_empty);
        glDrawArrays(GL_TRIANGLES, 0, 3);
        glDepthFunc(GL_LESS);
        glDepthMask(GL_TRUE);
    }

    pass_mark(r, PASS_SKY);
    /* resolve into the backend's buffer (unless drawn there) and keep the frame */
    if (g->fbo_ms) {
        glBindFramebuffer(GL_READ_FRAMEBUFFER, g->fbo_ms);
        glBindFramebuffer(GL_DRAW_FRAMEBUFFER, 0);
        glBlitFramebuffer(0, 0, r->w, r->h, 0, 0, r->w, r->h, GL_COLOR_BUFFER_BIT, GL_NEAREST);
    }
    glBindFramebuffer(GL_FRAMEBUFFER, 0);
    glBindVertexArray(0);
    glFinish();
    GLenum e = glGetError();
    if (e != GL_NO_ERROR) {
        snprintf(err, n, "OpenGL error 0x%04x while drawing", (unsigned)e);
        return false;
    }
    pass_mark(r, PASS_RESOLVE);
    const uint8_t *px = r->be->pixels(r->ctx);
    size_t npx = (size_t)r->w * r->h;
    if (!r->fxaa || !wb_fxaa(px, r->w, r->h, sky, r->rgb, &r->luma, &r->luma_cap)) {   /* out of memory: as drawn */
        for (size_t i = 0; i < npx; i++) memcpy(r->rgb + 3 * i, px + 4 * i, 3);
        for (int y = 0; sky && y < r->h; y++)
            for (int x = 0; x < r->w; x++)
                if (!px[4 * ((size_t)y * r->w + x) + 3]) memcpy(r->rgb + 3 * ((size_t)y * r->w + x), sky + 3 * y, 3);
    }
    if (o->legend && l->strain_shown) draw_legend(r, l->scale);
    pass_mark(r, PASS_COPY);
    return true;
}
