/* gl.h: what render.c and gl.c share: the GL objects of a renderer,
 * the shaders and the meshes. Private to the renderer. */
#ifndef WB_RENDER_GL_H
#define WB_RENDER_GL_H

#define GL_GLEXT_PROTOTYPES
#include <GL/glcorearb.h>

#include <math.h>
#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>
#include <string.h>

#include "wobble.h"

/* meshes in one vertex buffer (position, normal) and one index buffer */
enum { MESH_SPHERE_LO, MESH_SPHERE_HI, MESH_CYLINDER, MESH_BOX, MESH_COUNT };

/* per-instance data of the mesh shader (attributes 2..9) */
typedef struct wb_inst {
    float m[16];   /* model matrix, column-major */
    float n[9];    /* normal matrix, column-major */
    float c[4];    /* linear RGB + unused */
} wb_inst;

/* per-instance data of the line shader: a segment and its colour */
typedef struct wb_seg {
    float a[3], b[3], c[4];
} wb_seg;

/* surface vertices: position, normal, colour (linear RGB) and shine: WB_SV floats */
#define WB_SV 10

/* instance groups, by mesh: particle spheres, collider spheres and capsule caps,
 * capsule bodies, boxes */
enum { WB_G_LO, WB_G_HI, WB_G_CYL, WB_G_BOX, WB_G_COUNT };

/* what the layers draw this frame (layers.c), and its scratch */
typedef struct wb_layers {
    wb_inst *inst;                                  /* first[g], count[g] of each group */
    size_t first[WB_G_COUNT], count[WB_G_COUNT], inst_cap;
    wb_seg *seg;                                    /* the links */
    size_t nseg, seg_cap;
    bool surfaces;                                  /* anything in sv / si */
    float *sv;                                      /* nv vertices of WB_SV floats */
    size_t nv, sv_cap;
    GLuint *si;                                     /* nidx indices, triangles */
    size_t nidx, si_cap;
    int32_t *pairs, npairs;                         /* distance constraints, their strains */
    wb_real *strain;
    size_t pair_cap;
    float *vstrain;                                 /* per particle: the strain its surface shows */
    size_t vstrain_cap;
    float *mstrain;                                 /* per particle: its materials' strain (F_MATERIAL) */
    size_t mstrain_cap;
    uint8_t *flags;                                 /* per particle: on a surface, under a skin */
    size_t flag_cap;
    float *scratch;                                 /* the automatic strain scale's sample */
    size_t scratch_cap;
    double scale;                                   /* the strain drawn fully red this frame */
    bool strain_shown;                              /* any strain colour drawn (the legend) */
    const wb_world *auto_world;                     /* the automatic scale's easing: the world */
    int64_t auto_frame;                             /* and frame it was last taken at */
    double auto_scale;                              /* and the scale it had */
} wb_layers;

struct wb_draw_opts;
struct wb_draw_skin;
/* fill l for world w (unit: the scene's size, for points without a radius); false:
 * out of memory */
bool wb_layers_build(wb_layers *l, const wb_world *w, const struct wb_draw_opts *o, const struct wb_draw_skin *sk,
                     int nsk, double unit);
void wb_layers_free(wb_layers *l);
void wb_lin3(const float srgb[3], float lin[3]);   /* the shaders' gamma 2 */
/* a link's strain colour at t = strain / scale (-1 blue, 0 grey, +1 red), sRGB */
void wb_strain_srgb(double t, float out[3]);

typedef struct wb_gl {
    GLuint prog_mesh, prog_depth, prog_line, prog_grid, prog_bg;
    GLuint prog_grid_plain;   /* the ground without the shadow map's lookup */
    GLuint vao_mesh, vao_surf, vao_line, vao_empty;
    GLuint vbo_mesh, ebo_mesh, vbo_inst, vbo_surf, ebo_surf, vbo_seg;
    GLint mesh_first[MESH_COUNT], mesh_count[MESH_COUNT];   /* index ranges */
    GLuint fbo_ms, rb_color, rb_depth;                        /* the (multisample) target; 0: the default */
    GLuint fbo_shadow, tex_shadow;
    int shadow_size;
    size_t inst_cap, surf_cap, surf_idx_cap, seg_cap;         /* buffer sizes in bytes */
} wb_gl;

/* build programs, meshes and framebuffers for a w x h target with `samples` (clamped
 * to what GL offers, written back); `direct`: with one sample, draw into the default
 * framebuffer (it has a depth buffer), fbo_ms 0. false with a message */
bool wb_gl_init(wb_gl *g, int w, int h, int *samples, bool direct, char *err, size_t n);
void wb_gl_free(wb_gl *g);
/* make buffer `buf` (of `target`) hold `bytes` from data, growing it when needed */
void wb_gl_upload(GLenum target, GLuint buf, size_t *cap, const void *data, size_t bytes);
/* point vao_surf's attributes at vbo_surf (after it was re-specified by growing) */
void wb_gl_surf_attribs(const wb_gl *g);
/* point the instance attributes of vao_mesh at instance `first` of vbo_inst */
void wb_gl_inst_attribs(const wb_gl *g, size_t first);

/* ---- small vector and matrix helpers (doubles; matrices row-major m[r*4+c]) ---- */
static inline double dot3(const double a[3], const double b[3]) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }

static inline void cross3(const double a[3], const double b[3], double o[3])
{
    double t[3] = { a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0] };
    memcpy(o, t, sizeof t);
}

static inline double norm3(double a[3])
{
    double l = sqrt(dot3(a, a));
    if (l > 0) a[0] /= l, a[1] /= l, a[2] /= l;
    return l;
}

static inline void mat_mul(const double a[16], const double b[16], double o[16])
{
    double t[16];
    for (int i = 0; i < 4; i++)
        for (int j = 0; j < 4; j++) {
            double s = 0;
            for (int k = 0; k < 4; k++) s += a[i * 4 + k] * b[k * 4 + j];
            t[i * 4 + j] = s;
        }
    memcpy(o, t, sizeof t);
}

static inline void look_at(const double eye[3], const double target[3], const double up[3], double m[16])
{
    double f[3] = { target[0] - eye[0], target[1] - eye[1], target[2] - eye[2] }, s[3], u[3];
    norm3(f);
    cross3(f, up, s);
    norm3(s);
    cross3(s, f, u);
    double t[16] = { s[0], s[1], s[2], -dot3(s, eye), u[0], u[1], u[2], -dot3(u, eye),
                     -f[0], -f[1], -f[2], dot3(f, eye), 0, 0, 0, 1 };
    memcpy(m, t, sizeof t);
}

static inline void perspective(double fovy_deg, double aspect, double zn, double zf, double m[16])
{
    double f = 1 / tan(fovy_deg * M_PI / 360);
    double t[16] = { f / aspect, 0, 0, 0, 0, f, 0, 0, 0, 0, (zf + zn) / (zn - zf), 2 * zf * zn / (zn - zf), 0, 0, -1, 0 };
    memcpy(m, t, sizeof t);
}

static inline void ortho(double r, double zn, double zf, double m[16])
{
    double t[16] = { 1 / r, 0, 0, 0, 0, 1 / r, 0, 0, 0, 0, -2 / (zf - zn), -(zf + zn) / (zf - zn), 0, 0, 0, 1 };
    memcpy(m, t, sizeof t);
}

static inline void to_gl(const double m[16], float o[16])   /* row-major doubles -> column-major floats */
{
    for (int r = 0; r < 4; r++)
        for (int c = 0; c < 4; c++) o[c * 4 + r] = (float)m[r * 4 + c];
}

/* a quaternion (w,x,y,z) as a rotation matrix (row-major 3x3) */
static inline void quat_mat(const wb_real q[4], double m[9])
{
    double w = q[0], x = q[1], y = q[2], z = q[3], l = sqrt(w * w + x * x + y * y + z * z);
    if (l > 0) w /= l, x /= l, y /= l, z /= l;
    double t[9] = { 1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y),
                    2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x),
                    2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y) };
    memcpy(m, t, sizeof t);
}

#endif
