/* render_gl.h: what render.c and render_gl.c share: the GL objects of a renderer,
 * the shaders and the meshes. Private to the renderer. */
#ifndef WB_RENDER_GL_H
#define WB_RENDER_GL_H

#define GL_GLEXT_PROTOTYPES
#include <GL/glcorearb.h>

#include <stdbool.h>
#include <stddef.h>

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

typedef struct wb_gl {
    GLuint prog_mesh, prog_depth, prog_line, prog_grid, prog_bg;
    GLuint vao_mesh, vao_surf, vao_line, vao_grid, vao_empty;
    GLuint vbo_mesh, ebo_mesh, vbo_inst, vbo_surf, ebo_surf, vbo_seg, vbo_grid;
    GLint mesh_first[MESH_COUNT], mesh_count[MESH_COUNT];   /* index ranges */
    GLuint fbo_ms, rb_color, rb_depth;                        /* the (multisample) target */
    GLuint fbo_shadow, tex_shadow;
    int shadow_size;
    size_t inst_cap, surf_cap, surf_idx_cap, seg_cap;         /* buffer sizes in bytes */
} wb_gl;

/* build programs, meshes and framebuffers for a w x h target with `samples` (clamped
 * to what GL offers, written back); false with a message */
bool wb_gl_init(wb_gl *g, int w, int h, int *samples, char *err, size_t n);
void wb_gl_free(wb_gl *g);
/* make buffer `buf` (of `target`) hold `bytes` from data, growing it when needed */
void wb_gl_upload(GLenum target, GLuint buf, size_t *cap, const void *data, size_t bytes);
/* point the instance attributes of vao_mesh at instance `first` of vbo_inst */
void wb_gl_inst_attribs(const wb_gl *g, size_t first);

#endif
