/* render.c: draws a world: the camera, the scene's bounds, the instance data of every
 * layer (particles, pins, links coloured by strain, colliders, surfaces) and the
 * passes (shadow map, sky, ground, solids, links), then resolves the multisample
 * target into the backend's buffer and keeps the frame as RGB, top row first. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "render.h"
#include "render_gl.h"

struct wb_renderer {
    const wb_backend *be;
    void *ctx;
    int w, h, samples;
    bool gl_ready;
    wb_gl gl;
    char info[192];
    uint8_t *rgb;                 /* the last frame */
    bool drawn;
    /* camera: fixed by the script, or framing everything shown since the reset */
    bool fixed;
    double eye[3], target[3], up[3], fov;
    bool have_box;
    double view_lo[3], view_hi[3];/* what the default camera frames: eases after the scene */
    /* the last frame's camera and view-projection (row-major 4x4, doubles) */
    double cam_eye[3], cam_target[3], cam_up[3], cam_fov, vp[16];
    /* scratch, grown as needed */
    wb_inst *inst;
    size_t inst_cap;
    wb_seg *seg;
    size_t seg_cap;
    float *sv;                    /* surface vertices: position, normal per particle */
    size_t sv_cap;
    GLuint *si;                   /* surface indices */
    size_t si_cap;
    int32_t *pairs;
    wb_real *strain;
    size_t pair_cap;
    uint8_t *on_surface;
    size_t flag_cap;
};

/* colours, sRGB */
static const float col_particle[3] = { 0.22f, 0.47f, 0.80f };
static const float col_pin[3] = { 0.98f, 0.68f, 0.08f };
static const float col_collider[3] = { 0.55f, 0.58f, 0.64f };
static const float col_rest[3] = { 0.40f, 0.40f, 0.42f };
static const float col_tension[3] = { 0.92f, 0.08f, 0.06f };
static const float col_compress[3] = { 0.12f, 0.32f, 0.92f };
static const float col_ground[3] = { 0.80f, 0.80f, 0.78f };
static const float col_sky_top[3] = { 0.50f, 0.61f, 0.75f };
static const float col_sky_bottom[3] = { 0.89f, 0.90f, 0.92f };
static const float col_surface[][3] = {
    { 0.91f, 0.42f, 0.24f }, { 0.26f, 0.64f, 0.56f }, { 0.56f, 0.44f, 0.80f }, { 0.86f, 0.70f, 0.28f },
};
static const float col_skin[3] = { 0.86f, 0.76f, 0.62f };
static const double light_dir[3] = { -0.40, 0.80, 0.45 };   /* towards the light: upper left, in front */

wb_draw_opts wb_draw_default_opts(void)
{
    wb_draw_opts o = { true, true, true, true, true, true, true, 0.05, 1.5 };
    return o;
}

static float lin(float c) { return c * c; }   /* the shaders output with gamma 2 */

static void lin3(const float s[3], float o[3])
{
    for (int k = 0; k < 3; k++) o[k] = lin(s[k]);
}

/* grow *p to hold n elements of size sz */
static bool grow(void *pp, size_t *cap, size_t n, size_t sz)
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
    r->ctx = be->create(width, height, err, n);
    if (!r->ctx) {
        wb_renderer_destroy(r);
        return NULL;
    }
    if (be->gl) {
        if (!wb_gl_init(&r->gl, width, height, &r->samples, err, n)) {
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

void wb_renderer_destroy(wb_renderer *r)
{
    if (!r) return;
    if (r->ctx) {
        if (r->gl_ready && r->be->make_current(r->ctx)) wb_gl_free(&r->gl);
        r->be->destroy(r->ctx);
    }
    free(r->rgb);
    free(r->inst);
    free(r->seg);
    free(r->sv);
    free(r->si);
    free(r->pairs);
    free(r->strain);
    free(r->on_surface);
    free(r);
}

void wb_renderer_size(const wb_renderer *r, int *width, int *height)
{
    *width = r->w;
    *height = r->h;
}

int wb_renderer_samples(const wb_renderer *r) { return r->samples; }
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
        if (d.shape == WB_SHAPE_SPHERE) {
            box_add(&b, c, d.radius);
        } else if (d.shape == WB_SHAPE_BOX) {
            double m[9];
            quat_mat(d.rotation, m);
            for (int k = 0; k < 8; k++) {
                double s[3] = { k & 1 ? d.half[0] : -d.half[0], k & 2 ? d.half[1] : -d.half[1],
                                k & 4 ? d.half[2] : -d.half[2] };
                double p[3];
                for (int r = 0; r < 3; r++) p[r] = c[r] + m[r * 3] * s[0] + m[r * 3 + 1] * s[1] + m[r * 3 + 2] * s[2];
                box_add(&b, p, 0);
            }
        } else if (d.shape == WB_SHAPE_CAPSULE) {
            double a[3] = { d.a[0], d.a[1], d.a[2] }, e[3] = { d.b[0], d.b[1], d.b[2] };
            box_add(&b, a, d.radius);
            box_add(&b, e, d.radius);
        }
    }
    if (!b.any) {
        double o[3] = { 0, 0, 0 };
        box_add(&b, o, 1);
    }
    double ext = 0;
    for (int k = 0; k < 3; k++) ext = fmax(ext, b.hi[k] - b.lo[k]);
    ext = fmax(ext, 1e-3);
    for (int32_t i = 0; i < nc; i++) {
        wb_collider_def d;
        wb_collider_get_def(w, wb_collider_at(w, i), &d);
        double nl = sqrt(d.normal[0] * d.normal[0] + d.normal[1] * d.normal[1] + d.normal[2] * d.normal[2]);
        if (d.shape != WB_SHAPE_PLANE || nl <= 0 || d.normal[1] / nl < 0.9) continue;
        double h = d.offset / nl;   /* height of the (nearly) horizontal plane */
        if (h < b.lo[1] && h > b.lo[1] - ext) b.lo[1] = h;
    }
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

/* ---- instance data ------------------------------------------------------------------------ */
/* model = T(p) * [c0 c1 c2] (columns already scaled), normal matrix = columns / scale^2 */
static void inst_set(wb_inst *in, const double p[3], const double cols[3][3], const float rgb[3], float shine)
{
    memset(in, 0, sizeof *in);
    for (int c = 0; c < 3; c++) {
        double l2 = dot3(cols[c], cols[c]);
        for (int r = 0; r < 3; r++) {
            in->m[c * 4 + r] = (float)cols[c][r];
            in->n[c * 3 + r] = (float)(l2 > 0 ? cols[c][r] / l2 : 0);
        }
    }
    for (int r = 0; r < 3; r++) in->m[12 + r] = (float)p[r];
    in->m[15] = 1;
    lin3(rgb, in->c);
    in->c[3] = shine;
}

static void inst_sphere(wb_inst *in, const double p[3], double rad, const float rgb[3], float shine)
{
    double cols[3][3] = { { rad, 0, 0 }, { 0, rad, 0 }, { 0, 0, rad } };
    inst_set(in, p, cols, rgb, shine);
}

/* a unit cylinder (y in 0..1) from a to b */
static void inst_cylinder(wb_inst *in, const double a[3], const double b[3], double rad, const float rgb[3])
{
    double y[3] = { b[0] - a[0], b[1] - a[1], b[2] - a[2] }, d[3], x[3], z[3];
    memcpy(d, y, sizeof d);
    double len = norm3(d);
    if (len <= 0) d[0] = 0, d[1] = 1, d[2] = 0;
    double pick[3] = { fabs(d[0]) < 0.9 ? 1 : 0, fabs(d[0]) < 0.9 ? 0 : 1, 0 };
    cross3(d, pick, x);
    norm3(x);
    cross3(x, d, z);
    double cols[3][3] = { { x[0] * rad, x[1] * rad, x[2] * rad }, { y[0], y[1], y[2] }, { z[0] * rad, z[1] * rad, z[2] * rad } };
    if (len <= 0) cols[1][1] = 1e-9;
    inst_set(in, a, cols, rgb, 0.35f);
}

enum { G_LO, G_HI, G_CYL, G_BOX, G_COUNT };

/* instances grouped by mesh: particle spheres, collider spheres and capsule caps,
 * capsule bodies, boxes; first[g] and count[g] index r->inst. Particles of a drawn
 * surface are shown by the surface (a sphere per cloth vertex hides the cloth). */
static bool build_instances(wb_renderer *r, const wb_world *w, const wb_draw_opts *o, double unit,
                            bool surfaces, size_t first[G_COUNT], size_t count[G_COUNT])
{
    int32_t np = wb_particle_count(w), nc = wb_collider_count(w);
    size_t need = (size_t)np + 3 * (size_t)nc;
    if (!grow(&r->inst, &r->inst_cap, need + 1, sizeof *r->inst)) return false;
    const wb_real *x = wb_particle_positions(w);
    size_t k = 0;
    first[G_LO] = 0;
    for (int32_t i = 0; i < np; i++) {
        bool pin = wb_particle_pinned(w, i);
        double p[3] = { x[3 * i], x[3 * i + 1], x[3 * i + 2] }, rad = wb_particle_radius(w, i);
        if (!isfinite(p[0] + p[1] + p[2])) continue;
        if (rad <= 0) rad = 0.004 * unit;   /* a point still shows */
        if (pin && o->pins) inst_sphere(&r->inst[k++], p, fmax(1.6 * rad, 0.006 * unit), col_pin, 0.5f);
        else if (o->particles && !(surfaces && r->on_surface[i])) inst_sphere(&r->inst[k++], p, rad, col_particle, 0.5f);
    }
    count[G_LO] = k - first[G_LO];
    wb_collider_def ds[1];
    for (int g = G_HI; g < G_COUNT; g++) {
        first[g] = k;
        for (int32_t i = 0; o->colliders && i < nc; i++) {
            wb_collider_def *d = ds;
            wb_collider_get_def(w, wb_collider_at(w, i), d);
            double c[3] = { d->center[0], d->center[1], d->center[2] };
            double a[3] = { d->a[0], d->a[1], d->a[2] }, b[3] = { d->b[0], d->b[1], d->b[2] };
            if (g == G_HI && d->shape == WB_SHAPE_SPHERE) {
                inst_sphere(&r->inst[k++], c, d->radius, col_collider, 0.35f);
            } else if (g == G_HI && d->shape == WB_SHAPE_CAPSULE) {
                inst_sphere(&r->inst[k++], a, d->radius, col_collider, 0.35f);
                inst_sphere(&r->inst[k++], b, d->radius, col_collider, 0.35f);
            } else if (g == G_CYL && d->shape == WB_SHAPE_CAPSULE) {
                inst_cylinder(&r->inst[k++], a, b, d->radius, col_collider);
            } else if (g == G_BOX && d->shape == WB_SHAPE_BOX) {
                double m[9], cols[3][3];
                quat_mat(d->rotation, m);
                for (int cc = 0; cc < 3; cc++)
                    for (int rr = 0; rr < 3; rr++) cols[cc][rr] = m[rr * 3 + cc] * d->half[cc];
                inst_set(&r->inst[k++], c, cols, col_collider, 0.35f);
            }
        }
        count[g] = k - first[g];
    }
    return true;
}

/* per-particle smooth normals of every surface (area-weighted face normals) */
/* vertices: the particles, then every skin's; indices: the surfaces', then the skins' */
static bool build_surfaces(wb_renderer *r, const wb_world *w, const wb_draw_opts *o, const wb_draw_skin *sk,
                           int nsk, size_t *nidx)
{
    int32_t np = wb_particle_count(w), ns = o->surfaces ? wb_surface_count(w) : 0;
    const wb_real *x = wb_particle_positions(w);
    size_t total = 0, nv = (size_t)np;
    for (int32_t s = 0; s < ns; s++) {
        int32_t nt = 0;
        wb_surface_triangles(w, s, &nt);
        total += 3 * (size_t)nt;
    }
    for (int i = 0; i < nsk; i++) total += 3 * (size_t)sk[i].nt, nv += (size_t)sk[i].nv;
    *nidx = total;
    if (!grow(&r->sv, &r->sv_cap, 6 * nv + 6, sizeof *r->sv) ||
        !grow(&r->si, &r->si_cap, total + 1, sizeof *r->si) ||
        !grow(&r->on_surface, &r->flag_cap, (size_t)np + 1, 1))
        return false;
    memset(r->on_surface, 0, (size_t)np);
    double *acc = calloc((size_t)np * 3 + 3, sizeof *acc);
    if (!acc) return false;
    size_t k = 0;
    for (int32_t s = 0; s < ns; s++) {
        int32_t nt = 0;
        const int32_t *t = wb_surface_triangles(w, s, &nt);
        for (int32_t i = 0; i < nt; i++) {
            const int32_t *v = t + 3 * i;
            double e1[3], e2[3], fn[3];
            for (int c = 0; c < 3; c++) e1[c] = x[3 * v[1] + c] - x[3 * v[0] + c], e2[c] = x[3 * v[2] + c] - x[3 * v[0] + c];
            cross3(e1, e2, fn);
            for (int j = 0; j < 3; j++) {
                for (int c = 0; c < 3; c++) acc[3 * v[j] + c] += fn[c];
                r->si[k++] = (GLuint)v[j];
                r->on_surface[v[j]] = 1;
            }
        }
    }
    for (int32_t i = 0; i < np; i++) {
        double *a = acc + 3 * i;
        norm3(a);
        for (int c = 0; c < 3; c++) r->sv[6 * i + c] = (float)x[3 * i + c], r->sv[6 * i + 3 + c] = (float)a[c];
    }
    free(acc);
    size_t base = (size_t)np;   /* skins: their own (deformed) vertices and normals */
    for (int i = 0; i < nsk; i++) {
        for (int32_t v = 0; v < sk[i].nv; v++)
            for (int c = 0; c < 3; c++)
                r->sv[6 * (base + v) + c] = (float)sk[i].v[3 * v + c], r->sv[6 * (base + v) + 3 + c] = (float)sk[i].n[3 * v + c];
        for (int32_t t = 0; t < 3 * sk[i].nt; t++) r->si[k++] = (GLuint)(base + (size_t)sk[i].tri[t]);
        base += (size_t)sk[i].nv;
    }
    return true;
}

/* links as segments, grey at rest, red stretched, blue compressed */
static bool build_segments(wb_renderer *r, const wb_world *w, const wb_draw_opts *o, size_t *nseg)
{
    int32_t n = wb_world_distance_pairs(w, NULL, NULL);
    if (!grow(&r->pairs, &r->pair_cap, 2 * (size_t)n + 2, sizeof *r->pairs)) return false;
    size_t cap2 = r->pair_cap / 2;   /* strain array shares the capacity count */
    void *q = realloc(r->strain, (cap2 + 1) * sizeof *r->strain);
    if (!q) return false;
    r->strain = q;
    if (!grow(&r->seg, &r->seg_cap, (size_t)n + 1, sizeof *r->seg)) return false;
    n = wb_world_distance_pairs(w, r->pairs, r->strain);
    const wb_real *x = wb_particle_positions(w);
    float rest[3], ten[3], com[3];
    lin3(col_rest, rest), lin3(col_tension, ten), lin3(col_compress, com);
    for (int32_t i = 0; i < n; i++) {
        wb_seg *s = &r->seg[i];
        int32_t a = r->pairs[2 * i], b = r->pairs[2 * i + 1];
        for (int c = 0; c < 3; c++) s->a[c] = (float)x[3 * a + c], s->b[c] = (float)x[3 * b + c];
        double t = r->strain[i] / o->strain_scale;
        t = t > 1 ? 1 : t < -1 ? -1 : t;
        const float *to = t >= 0 ? ten : com;
        double f = fabs(t);
        for (int c = 0; c < 3; c++) s->c[c] = (float)(rest[c] + (to[c] - rest[c]) * f);
        s->c[3] = 1;
    }
    *nseg = (size_t)n;
    return true;
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

static void draw_meshes(wb_renderer *r, const size_t first[G_COUNT], const size_t count[G_COUNT])
{
    static const int mesh_of[G_COUNT] = { MESH_SPHERE_LO, MESH_SPHERE_HI, MESH_CYLINDER, MESH_BOX };
    for (int g = 0; g < G_COUNT; g++) {
        if (!count[g]) continue;
        wb_gl_inst_attribs(&r->gl, first[g]);
        glDrawElementsInstanced(GL_TRIANGLES, r->gl.mesh_count[mesh_of[g]], GL_UNSIGNED_INT,
                                (const void *)((size_t)r->gl.mesh_first[mesh_of[g]] * sizeof(GLuint)),
                                (GLsizei)count[g]);
    }
}

static void draw_surfaces(wb_renderer *r, const wb_world *w, const wb_draw_opts *o, const wb_draw_skin *sk, int nsk)
{
    glBindVertexArray(r->gl.vao_surf);
    /* constant instance attributes: identity model and normal matrices, one colour each */
    glVertexAttrib4f(2, 1, 0, 0, 0), glVertexAttrib4f(3, 0, 1, 0, 0);
    glVertexAttrib4f(4, 0, 0, 1, 0), glVertexAttrib4f(5, 0, 0, 0, 1);
    glVertexAttrib3f(6, 1, 0, 0), glVertexAttrib3f(7, 0, 1, 0), glVertexAttrib3f(8, 0, 0, 1);
    size_t off = 0;
    int32_t ns = o->surfaces ? wb_surface_count(w) : 0;
    for (int32_t s = 0; s < ns + nsk; s++) {
        int32_t nt = 0;
        if (s < ns) wb_surface_triangles(w, s, &nt);
        else nt = sk[s - ns].nt;
        float c[3];
        lin3(s < ns ? col_surface[s % 4] : col_skin, c);
        glVertexAttrib4f(9, c[0], c[1], c[2], 0.12f);
        glDrawElements(GL_TRIANGLES, 3 * nt, GL_UNSIGNED_INT, (const void *)(off * sizeof(GLuint)));
        off += 3 * (size_t)nt;
    }
}

/* a plane as a square of half size ext around the point nearest c; returns false
 * when the normal is degenerate */
static bool plane_quad(const wb_real nrm[3], double offset, const double c[3], double ext, float quad[12],
                       double center[3], double gu[3], double gv[3], double gn[3])
{
    double n[3] = { nrm[0], nrm[1], nrm[2] };
    double l = norm3(n);
    if (l <= 0) return false;
    double d = offset / l, h = dot3(n, c) - d;
    for (int k = 0; k < 3; k++) center[k] = c[k] - h * n[k], gn[k] = n[k];
    if (fabs(n[1]) > 0.9) {   /* a floor: lines along x and z */
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
    static const int sx[4] = { -1, 1, -1, 1 }, sy[4] = { -1, -1, 1, 1 };
    for (int v = 0; v < 4; v++)
        for (int k = 0; k < 3; k++) quad[3 * v + k] = (float)(center[k] + ext * (sx[v] * gu[k] + sy[v] * gv[k]));
    return true;
}

static double nice_step(double x)
{
    double p = pow(10, floor(log10(x))), m = x / p;
    return (m < 1.5 ? 1 : m < 3.5 ? 2 : m < 7.5 ? 5 : 10) * p;
}

static void draw_grid(wb_renderer *r, const float quad[12], const double center[3], const double gu[3],
                      const double gv[3], const double gn[3], double spacing, double ext)
{
    GLuint p = r->gl.prog_grid;
    glBindVertexArray(r->gl.vao_grid);
    glBindBuffer(GL_ARRAY_BUFFER, r->gl.vbo_grid);
    glBufferSubData(GL_ARRAY_BUFFER, 0, 12 * sizeof(float), quad);
    set_vec(p, "u_center", center[0], center[1], center[2]);
    set_vec(p, "u_gu", gu[0], gu[1], gu[2]);
    set_vec(p, "u_gv", gv[0], gv[1], gv[2]);
    set_vec(p, "u_gn", gn[0], gn[1], gn[2]);
    glUniform1f(glGetUniformLocation(p, "u_spacing"), (float)spacing);
    glUniform1f(glGetUniformLocation(p, "u_extent"), (float)ext);
    float g[3];
    lin3(col_ground, g);
    glUniform3f(glGetUniformLocation(p, "u_base"), g[0], g[1], g[2]);
    glDrawArrays(GL_TRIANGLE_STRIP, 0, 4);
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

bool wb_renderer_draw(wb_renderer *r, const wb_world *w, const wb_draw_opts *o, const wb_draw_skin *skins,
                      int nskins, char *err, size_t n)
{
    /* camera and extent */
    box cur = scene_box(w);
    if (!r->have_box) {
        memcpy(r->view_lo, cur.lo, sizeof r->view_lo);
        memcpy(r->view_hi, cur.hi, sizeof r->view_hi);
        r->have_box = true;
    } else {
        /* the camera follows what is there now, eased (a fifth of a second at 60
         * draws a second) so a video neither jumps nor shakes */
        for (int k = 0; k < 3; k++) {
            r->view_lo[k] += 0.08 * (cur.lo[k] - r->view_lo[k]);
            r->view_hi[k] += 0.08 * (cur.hi[k] - r->view_hi[k]);
        }
    }
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
        return true;
    }
    if (!r->be->make_current(r->ctx)) {
        snprintf(err, n, "cannot make the renderer's GL context current");
        return false;
    }

    /* layers */
    size_t first[G_COUNT], count[G_COUNT], nidx = 0, nseg = 0;
    int32_t np = wb_particle_count(w);
    if (!o->skins) nskins = 0;
    bool surfaces = (o->surfaces && wb_surface_count(w) > 0 && np > 0) || nskins > 0;
    if (surfaces && !build_surfaces(r, w, o, skins, nskins, &nidx)) goto oom;
    if (!build_instances(r, w, o, R, surfaces, first, count)) goto oom;
    if (o->constraints && !build_segments(r, w, o, &nseg)) goto oom;
    wb_gl *g = &r->gl;
    size_t ninst = first[G_COUNT - 1] + count[G_COUNT - 1];
    wb_gl_upload(GL_ARRAY_BUFFER, g->vbo_inst, &g->inst_cap, r->inst, ninst * sizeof *r->inst);
    if (surfaces) {
        size_t nv = (size_t)np;
        for (int i = 0; i < nskins; i++) nv += (size_t)skins[i].nv;
        wb_gl_upload(GL_ARRAY_BUFFER, g->vbo_surf, &g->surf_cap, r->sv, 6 * nv * sizeof *r->sv);
        glBindVertexArray(g->vao_surf);
        wb_gl_upload(GL_ELEMENT_ARRAY_BUFFER, g->ebo_surf, &g->surf_idx_cap, r->si, nidx * sizeof *r->si);
        glBindVertexArray(g->vao_surf);   /* growing re-specified the buffer: bind it again */
        glBindBuffer(GL_ELEMENT_ARRAY_BUFFER, g->ebo_surf);
        glBindBuffer(GL_ARRAY_BUFFER, g->vbo_surf);
        glVertexAttribPointer(0, 3, GL_FLOAT, GL_FALSE, 6 * sizeof(float), (const void *)0);
        glVertexAttribPointer(1, 3, GL_FLOAT, GL_FALSE, 6 * sizeof(float), (const void *)(3 * sizeof(float)));
    }
    if (nseg) wb_gl_upload(GL_ARRAY_BUFFER, g->vbo_seg, &g->seg_cap, r->seg, nseg * sizeof *r->seg);

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
    draw_meshes(r, first, count);
    if (surfaces) draw_surfaces(r, w, o, skins, nskins);
    glDisable(GL_POLYGON_OFFSET_FILL);

    /* the picture */
    glBindFramebuffer(GL_FRAMEBUFFER, g->fbo_ms);
    glViewport(0, 0, r->w, r->h);
    glClear(GL_DEPTH_BUFFER_BIT);
    glEnable(GL_DEPTH_TEST);
    glActiveTexture(GL_TEXTURE0);
    glBindTexture(GL_TEXTURE_2D, g->tex_shadow);

    /* the ground: every plane collider, or a floor under the scene */
    light_uniforms(g->prog_grid, r->vp, lvp, r->cam_eye, L, bias, true);
    glUniform3f(glGetUniformLocation(g->prog_grid, "u_top"), col_sky_top[0], col_sky_top[1], col_sky_top[2]);
    glUniform3f(glGetUniformLocation(g->prog_grid, "u_bottom"), col_sky_bottom[0], col_sky_bottom[1], col_sky_bottom[2]);
    glUniform1f(glGetUniformLocation(g->prog_grid, "u_height"), (float)r->h);
    double spacing = nice_step(R / 6), center[3], gu[3], gv[3], gn[3];
    float quad[12];
    int planes = 0;
    int32_t nc = wb_collider_count(w);
    for (int32_t i = 0; i < nc && (o->colliders || o->grid); i++) {
        wb_collider_def d;
        wb_collider_get_def(w, wb_collider_at(w, i), &d);
        if (d.shape != WB_SHAPE_PLANE) continue;
        double nl = sqrt(d.normal[0] * d.normal[0] + d.normal[1] * d.normal[1] + d.normal[2] * d.normal[2]);
        bool floor = nl > 0 && d.normal[1] / nl > 0.9;
        if (!(o->colliders || (o->grid && floor))) continue;
        if (plane_quad(d.normal, d.offset, c, ext, quad, center, gu, gv, gn)) {
            draw_grid(r, quad, center, gu, gv, gn, spacing, ext);
            planes++;
        }
    }
    if (!planes && o->grid) {
        wb_real up[3] = { 0, 1, 0 };
        if (plane_quad(up, fmin(cur.lo[1], r->view_lo[1]), c, ext, quad, center, gu, gv, gn))
            draw_grid(r, quad, center, gu, gv, gn, spacing, ext);
    }

    /* solids, then the surfaces pushed back a little so links on them stay visible */
    light_uniforms(g->prog_mesh, r->vp, lvp, r->cam_eye, L, bias, true);
    glUniform1i(glGetUniformLocation(g->prog_mesh, "u_two_sided"), 0);
    draw_meshes(r, first, count);
    if (surfaces) {
        glUniform1i(glGetUniformLocation(g->prog_mesh, "u_two_sided"), 1);
        glEnable(GL_POLYGON_OFFSET_FILL);
        glPolygonOffset(1, 2);
        draw_surfaces(r, w, o, skins, nskins);
        glDisable(GL_POLYGON_OFFSET_FILL);
    }
    if (nseg) {
        glUseProgram(g->prog_line);
        set_mat(g->prog_line, "u_vp", r->vp);
        glUniform2f(glGetUniformLocation(g->prog_line, "u_half"), 0.5f * r->w, 0.5f * r->h);
        glUniform1f(glGetUniformLocation(g->prog_line, "u_width"), (float)(o->line_width * fmax(r->h / 720.0, 0.5)));
        glBindVertexArray(g->vao_line);
        glDrawArraysInstanced(GL_TRIANGLES, 0, 6, (GLsizei)nseg);
    }
    /* the sky last, behind everything: only uncovered pixels pass the depth test */
    glDepthFunc(GL_LEQUAL);
    glDepthMask(GL_FALSE);
    glUseProgram(g->prog_bg);
    glUniform3f(glGetUniformLocation(g->prog_bg, "u_top"), col_sky_top[0], col_sky_top[1], col_sky_top[2]);
    glUniform3f(glGetUniformLocation(g->prog_bg, "u_bottom"), col_sky_bottom[0], col_sky_bottom[1], col_sky_bottom[2]);
    glBindVertexArray(g->vao_empty);
    glDrawArrays(GL_TRIANGLES, 0, 3);
    glDepthFunc(GL_LESS);
    glDepthMask(GL_TRUE);

    /* resolve into the backend's buffer and keep the frame */
    glBindFramebuffer(GL_READ_FRAMEBUFFER, g->fbo_ms);
    glBindFramebuffer(GL_DRAW_FRAMEBUFFER, 0);
    glBlitFramebuffer(0, 0, r->w, r->h, 0, 0, r->w, r->h, GL_COLOR_BUFFER_BIT, GL_NEAREST);
    glBindFramebuffer(GL_FRAMEBUFFER, 0);
    glBindVertexArray(0);
    glFinish();
    GLenum e = glGetError();
    if (e != GL_NO_ERROR) {
        snprintf(err, n, "OpenGL error 0x%04x while drawing", (unsigned)e);
        return false;
    }
    const uint8_t *px = r->be->pixels(r->ctx);
    size_t npx = (size_t)r->w * r->h;
    for (size_t i = 0; i < npx; i++) memcpy(r->rgb + 3 * i, px + 4 * i, 3);
    return true;
oom:
    snprintf(err, n, "out of memory drawing %d particles", (int)np);
    return false;
}
