/* gl.c: the GL objects of the renderer: GLSL 3.30 programs, the meshes every
 * solid is drawn from (unit spheres, cylinder, box), the multisample target and the
 * shadow map. render.c fills buffers and issues draws. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "gl.h"

/* ---- shaders ------------------------------------------------------------------------ */
static const char mesh_vs[] =
    "#version 330 core\n"
    "layout(location = 0) in vec3 a_pos;\n"
    "layout(location = 1) in vec3 a_nrm;\n"
    "layout(location = 2) in vec4 i_m0;\n"
    "layout(location = 3) in vec4 i_m1;\n"
    "layout(location = 4) in vec4 i_m2;\n"
    "layout(location = 5) in vec4 i_m3;\n"
    "layout(location = 6) in vec3 i_n0;\n"
    "layout(location = 7) in vec3 i_n1;\n"
    "layout(location = 8) in vec3 i_n2;\n"
    "layout(location = 9) in vec4 i_col;\n"
    "uniform mat4 u_vp;\n"
    "out vec3 v_pos;\n"
    "out vec3 v_nrm;\n"
    "out vec4 v_col;\n"
    "void main() {\n"
    "  vec4 wp = mat4(i_m0, i_m1, i_m2, i_m3) * vec4(a_pos, 1.0);\n"
    "  v_pos = wp.xyz;\n"
    "  v_nrm = mat3(i_n0, i_n1, i_n2) * a_nrm;\n"
    "  v_col = i_col;\n"
    "  gl_Position = u_vp * wp;\n"
    "}\n";

/* lighting shared by solids and the ground: a warm key light with a filtered shadow
 * map, a sky/ground ambient, a little specular; colours are linear, output sRGB */
static const char light_fs[] =
    "uniform vec3 u_eye;\n"
    "uniform vec3 u_light;\n"
    "uniform mat4 u_lvp;\n"
    "uniform sampler2DShadow u_smap;\n"
    "uniform float u_bias;\n"
    "uniform int u_shadows;\n"
    "uniform vec3 u_amb_down;\n"   /* the ambient light of a surface facing down and up (linear) */
    "uniform vec3 u_amb_up;\n"
    "uniform vec3 u_key;\n"        /* the key light's colour */
    /* the lookup moves off the surface along its normal by u_bias (a few texels), more
     * the more the light grazes (slope-scaled: a texel spans more depth there), up to 8
     * times. The slope is the larger of the smooth normal's and the triangle's own (ng,
     * on the side seen): near a fold of a two-sided cloth the smooth normal faces the
     * light while the triangle turns away, and the map sees the fold's other side just
     * behind it; a fixed offset drew those triangles as stripes of acne */
    "float shadow_at(vec3 p, vec3 n, vec3 ng) {\n"
    "  if (u_shadows == 0) return 1.0;\n"
    "  float c = clamp(min(dot(n, u_light), dot(ng, u_light)), 0.05, 1.0);\n"
    "  float k = min(1.0 + 2.0 * sqrt(1.0 - c * c) / c, 8.0);\n"
    "  vec4 q = u_lvp * vec4(p + n * u_bias * k, 1.0);\n"
    "  vec3 s = q.xyz / q.w * 0.5 + 0.5;\n"
    "  if (any(lessThan(s.xy, vec2(0.0))) || any(greaterThan(s, vec3(1.0)))) return 1.0;\n"
    "  return texture(u_smap, s);\n"  /* one tap: the linear filter is a 2x2 PCF */
    "}\n"
    /* the triangle's own normal on the side of n (derivatives: in uniform control flow) */
    "vec3 face_normal(vec3 p, vec3 n) {\n"
    "  vec3 ng = cross(dFdx(p), dFdy(p));\n"
    "  float l = length(ng);\n"
    "  ng = l > 0.0 ? ng / l : n;\n"
    "  return dot(ng, n) < 0.0 ? -ng : ng;\n"
    "}\n"
    "vec3 lit(vec3 base, vec3 n, vec3 p, float shine) {\n"
    "  vec3 v = normalize(u_eye - p);\n"
    "  vec3 ng = face_normal(p, n);\n"
    "  float ndl = dot(n, u_light);\n"
    "  float sh = ndl > 0.0 ? shadow_at(p, n, ng) : 0.0;\n"
    "  vec3 h = normalize(u_light + v);\n"
    /* the 40th power by squaring: pow is a log and an exp on llvmpipe */
    "  float s2 = max(dot(n, h), 0.0);\n"
    "  s2 *= s2;\n"
    "  float s8 = s2 * s2;\n"
    "  s8 *= s8;\n"
    "  float s32 = s8 * s8;\n"
    "  s32 *= s32;\n"
    "  float spec = shine * s32 * s8;\n"
    "  vec3 amb = mix(u_amb_down, u_amb_up, n.y * 0.5 + 0.5);\n"
    "  float rim = 1.0 - max(dot(n, v), 0.0);\n"
    "  rim = rim * rim * rim * 0.12;\n"
    "  return base * (amb + u_key * max(ndl, 0.0) * sh) + vec3(spec * sh + rim);\n"
    "}\n"
    /* gamma 2 instead of 2.2: a square root is much cheaper than pow on llvmpipe */
    "vec4 to_srgb(vec3 c, float a) { return vec4(sqrt(clamp(c, 0.0, 1.0)), a); }\n";

static const char mesh_fs[] =
    "in vec3 v_pos;\n"
    "in vec3 v_nrm;\n"
    "in vec4 v_col;\n"
    "uniform int u_two_sided;\n"
    "out vec4 o_col;\n"
    "void main() {\n"
    "  vec3 n = normalize(v_nrm);\n"
    "  vec3 base = v_col.rgb;\n"
    "  if (u_two_sided != 0 && !gl_FrontFacing) { n = -n; base *= 0.75; }\n"
    "  o_col = to_srgb(lit(base, n, v_pos, v_col.a), 1.0);\n"
    "}\n";

static const char depth_fs[] =
    "#version 330 core\n"
    "void main() {}\n";

/* a segment as a quad of constant pixel width, expanded in screen space */
static const char line_vs[] =
    "#version 330 core\n"
    "layout(location = 0) in vec3 i_a;\n"
    "layout(location = 1) in vec3 i_b;\n"
    "layout(location = 2) in vec4 i_col;\n"
    "uniform mat4 u_vp;\n"
    "uniform vec2 u_half;\n"
    "uniform float u_width;\n"
    "out vec4 v_col;\n"
    "const vec2 corner[6] = vec2[6](vec2(0, -1), vec2(1, -1), vec2(1, 1), vec2(0, -1), vec2(1, 1), vec2(0, 1));\n"
    "void main() {\n"
    "  vec4 pa = u_vp * vec4(i_a, 1.0), pb = u_vp * vec4(i_b, 1.0);\n"
    "  vec2 c = corner[gl_VertexID];\n"
    "  vec4 p = c.x < 0.5 ? pa : pb;\n"
    "  vec2 d = pb.xy / max(pb.w, 1e-6) * u_half - pa.xy / max(pa.w, 1e-6) * u_half;\n"
    "  float len = length(d);\n"
    "  vec2 side = len > 1e-6 ? vec2(-d.y, d.x) / len : vec2(0.0, 1.0);\n"
    "  p.xy += side * c.y * 0.5 * u_width / u_half * p.w;\n"
    "  p.z -= 2e-4 * p.w;\n"  /* over the surface the links lie on */
    "  gl_Position = p;\n"
    "  v_col = i_col;\n"
    "}\n";

static const char line_fs[] =
    "#version 330 core\n"
    "in vec4 v_col;\n"
    "out vec4 o_col;\n"
    "void main() { o_col = vec4(sqrt(v_col.rgb), 1.0); }\n";

/* the ground: the part of the screen below the plane's horizon and nearer than where
 * it has faded out (render.c clips the frame's square to that, fans of up to 7 corners,
 * the second from u_poly[8]); a corner's NDC x, y and depth and its clip w, and the
 * plane's point there, interpolated in perspective to each pixel */
static const char grid_vs[] =
    "#version 330 core\n"
    "uniform vec4 u_poly[16];\n"
    "uniform vec3 u_wpos[16];\n"
    "out vec3 v_p;\n"
    "void main() {\n"
    "  vec4 c = u_poly[gl_VertexID];\n"
    "  gl_Position = vec4(c.xyz * c.w, c.w);\n"
    "  v_p = u_wpos[gl_VertexID];\n"
    "}\n";

/* the ground at the plane's point each pixel sees: a floor reaches the
 * horizon, fogged with distance into the sky's colour at that row (the sky is a screen
 * gradient: the far ground meets it without a seam); any other plane is a disc of
 * radius u_extent fading out, as before. Anti-aliased minor and major lines (fwidth)
 * that fade where a cell shrinks to a few pixels (they would only shimmer). The depth is
 * the point's (render.c gives the corners theirs: a plane's is affine on the screen),
 * so bodies stand on the ground; beyond the far plane it is kept just in front of the
 * sky. */
static const char grid_fs[] =
    "in vec3 v_p;\n"
    "uniform vec3 u_center;\n"
    "uniform vec3 u_gu;\n"
    "uniform vec3 u_gv;\n"
    "uniform float u_spacing;\n"
    "uniform float u_extent;\n"
    "uniform float u_fog2;\n"    /* 1 / the fog length squared */
    "uniform int u_floor;\n"
    "out vec4 o_col;\n"
    "uniform vec3 u_top;\n"
    "uniform vec3 u_bottom;\n"
    "uniform float u_height;\n"
    /* the plane's colour in sRGB, unshadowed (render.c: the ground's colour lit from the
     * side seen, whose normal is u_nrm) and, for the shadow, its linear parts */
    "uniform vec3 u_lit;\n"
    "uniform vec3 u_base_amb;\n"
    "uniform vec3 u_base_key;\n"
    "uniform vec3 u_nrm;\n"
    "uniform vec3 u_sc;\n"    /* beyond sqrt(u_sr2) of u_sc, outside the shadow map's box: no shadow */
    "uniform float u_sr2;\n"
    "float grid(vec2 uv, vec2 fw) {\n"
    "  vec2 g = abs(fract(uv - 0.5) - 0.5) / max(fw, vec2(1e-6));\n"
    "  float fade = 1.0 - smoothstep(0.12, 0.4, max(fw.x, fw.y));\n"
    "  return (1.0 - min(min(g.x, g.y), 1.0)) * fade;\n"
    "}\n"
    "void main() {\n"
    "  vec3 p = v_p, d = p - u_center, e = p - u_eye;\n"
    "  float a = u_floor != 0 ? exp(-dot(e, e) * u_fog2)\n"   /* the distance in fog lengths, squared */
    "                         : 1.0 - smoothstep(0.45, 1.0, length(d) / u_extent);\n"
    "  if (a <= 0.002) discard;\n"
    "  vec2 uv = vec2(dot(d, u_gu), dot(d, u_gv)) / u_spacing;\n"
    "  vec2 fw = fwidth(uv);\n"
    /* the lines darken the colour (linear) by m; they have faded out where a major cell
     * is under 2.5 pixels (grid's fade) */
    "  float m = 1.0;\n"
    "  if (max(fw.x, fw.y) < 2.0) m = (1.0 - 0.266 * grid(uv, fw)) * (1.0 - 0.55 * grid(uv / 5.0, fw / 5.0));\n"
    /* diffuse only, its cost is most of the frame's. llvmpipe runs both sides of a branch
     * (masked), so a lookup skipped at run time costs as much as one made: the ground has
     * two programs, with the shadow map (SHADOWED, drawn where a shadow can fall; inside
     * the map's box) and without (everywhere else). sqrt(c m) = sqrt(c) sqrt(m): gamma 2,
     * as to_srgb */
    "#ifdef SHADOWED\n"
    "  float sh = dot(p - u_sc, p - u_sc) < u_sr2 ? shadow_at(p, u_nrm, u_nrm) : 1.0;\n"
    "  vec3 c = sqrt(u_base_amb + u_base_key * sh);\n"
    "#else\n"
    "  vec3 c = u_lit;\n"
    "#endif\n"
    /* opaque: faded into the sky's colour here, so the sky is drawn last and only
     * where nothing else is (the cheapest pixels are those never shaded). Alpha 1/2: not
     * geometry (alpha 1), which FXAA looks at alone, nor the sky (fxaa.c) */
    "  vec3 sky = mix(u_bottom, u_top, clamp(gl_FragCoord.y / u_height, 0.0, 1.0));\n"
    "  o_col = vec4(mix(sky, min(c * sqrt(m), 1.0), a), 0.5);\n"
    "}\n";

/* the sky: a vertical gradient over a full-screen triangle (alpha 0, as the ground) */
static const char bg_vs[] =
    "#version 330 core\n"
    "out float v_t;\n"
    "void main() {\n"
    "  vec2 p = vec2(gl_VertexID == 1 ? 3.0 : -1.0, gl_VertexID == 2 ? 3.0 : -1.0);\n"
    "  v_t = p.y * 0.5 + 0.5;\n"
    "  gl_Position = vec4(p, 1.0, 1.0);\n"  /* at the far plane: drawn where the depth is still clear */
    "}\n";

static const char bg_fs[] =
    "#version 330 core\n"
    "in float v_t;\n"
    "uniform vec3 u_top;\n"
    "uniform vec3 u_bottom;\n"
    "out vec4 o_col;\n"
    "void main() { o_col = vec4(mix(u_bottom, u_top, clamp(v_t, 0.0, 1.0)), 0.0); }\n";

static GLuint compile(GLenum type, const char *const *src, int nsrc, char *err, size_t n)
{
    GLuint s = glCreateShader(type);
    glShaderSource(s, nsrc, src, NULL);
    glCompileShader(s);
    GLint ok = 0;
    glGetShaderiv(s, GL_COMPILE_STATUS, &ok);
    if (!ok) {
        char log[1024] = "";
        glGetShaderInfoLog(s, sizeof log, NULL, log);
        snprintf(err, n, "shader does not compile: %s", log);
        glDeleteShader(s);
        return 0;
    }
    return s;
}

/* defs: lines of #define after the light's #version (NULL: none) */
static GLuint program(const char *vs, const char *fs, bool with_light, const char *defs, char *err, size_t n)
{
    const char *fsrc[4] = { "#version 330 core\n", defs ? defs : "", light_fs, fs };
    GLuint v = compile(GL_VERTEX_SHADER, &vs, 1, err, n);
    GLuint f = v ? compile(GL_FRAGMENT_SHADER, with_light ? fsrc : fsrc + 3, with_light ? 4 : 1, err, n) : 0;
    if (!f) {
        if (v) glDeleteShader(v);
        return 0;
    }
    GLuint p = glCreateProgram();
    glAttachShader(p, v);
    glAttachShader(p, f);
    glLinkProgram(p);
    glDeleteShader(v);
    glDeleteShader(f);
    GLint ok = 0;
    glGetProgramiv(p, GL_LINK_STATUS, &ok);
    if (!ok) {
        char log[1024] = "";
        glGetProgramInfoLog(p, sizeof log, NULL, log);
        snprintf(err, n, "shaders do not link: %s", log);
        glDeleteProgram(p);
        return 0;
    }
    return p;
}

/* ---- meshes ---------------------------------------------------------------------------- */
typedef struct mesh_build {
    float *v;       /* position, normal */
    GLuint *i;
    size_t nv, ni, cap_v, cap_i;
    bool oom;
} mesh_build;

static GLuint vert(mesh_build *m, float x, float y, float z, float nx, float ny, float nz)
{
    if (m->nv == m->cap_v) {
        size_t cap = m->cap_v ? 2 * m->cap_v : 1024;
        float *v = realloc(m->v, cap * 6 * sizeof *v);
        if (!v) return m->oom = true, 0;
        m->v = v;
        m->cap_v = cap;
    }
    float *p = m->v + 6 * m->nv;
    p[0] = x, p[1] = y, p[2] = z, p[3] = nx, p[4] = ny, p[5] = nz;
    return (GLuint)m->nv++;
}

static void tri(mesh_build *m, GLuint a, GLuint b, GLuint c)
{
    if (m->ni + 3 > m->cap_i) {
        size_t cap = m->cap_i ? 2 * m->cap_i : 4096;
        GLuint *i = realloc(m->i, cap * sizeof *i);
        if (!i) {
            m->oom = true;
            return;
        }
        m->i = i;
        m->cap_i = cap;
    }
    m->i[m->ni++] = a, m->i[m->ni++] = b, m->i[m->ni++] = c;
}

/* unit sphere, counter-clockwise seen from outside */
static void sphere(mesh_build *m, int stacks, int slices)
{
    GLuint base = (GLuint)m->nv;
    for (int s = 0; s <= stacks; s++) {
        double th = M_PI * s / stacks;
        for (int k = 0; k <= slices; k++) {
            double ph = 2 * M_PI * k / slices;
            float x = (float)(sin(th) * cos(ph)), y = (float)cos(th), z = (float)(-sin(th) * sin(ph));
            vert(m, x, y, z, x, y, z);
        }
    }
    for (int s = 0; s < stacks; s++)
        for (int k = 0; k < slices; k++) {
            GLuint a = base + (GLuint)(s * (slices + 1) + k), b = a + (GLuint)(slices + 1);
            if (s > 0) tri(m, a, b, a + 1);
            if (s < stacks - 1) tri(m, a + 1, b, b + 1);
        }
}

/* radius 1, y from 0 to 1, side only: the caps of a capsule are spheres */
static void cylinder(mesh_build *m, int slices)
{
    GLuint base = (GLuint)m->nv;
    for (int k = 0; k <= slices; k++) {
        double ph = 2 * M_PI * k / slices;
        float x = (float)cos(ph), z = (float)-sin(ph);
        vert(m, x, 0, z, x, 0, z);
        vert(m, x, 1, z, x, 0, z);
    }
    for (int k = 0; k < slices; k++) {
        GLuint a = base + (GLuint)(2 * k);
        tri(m, a, a + 2, a + 1);
        tri(m, a + 1, a + 2, a + 3);
    }
}

/* the cube [-1,1]^3 with a normal per face */
static void box(mesh_build *m)
{
    for (int axis = 0; axis < 3; axis++)
        for (int sgn = -1; sgn <= 1; sgn += 2) {
            float n[3] = { 0, 0, 0 }, u[3] = { 0, 0, 0 }, v[3] = { 0, 0, 0 };
            n[axis] = (float)sgn;
            u[(axis + 1) % 3] = 1;
            v[(axis + 2) % 3] = 1;
            /* u x v = +axis: flip u on the negative face to keep counter-clockwise */
            if (sgn < 0) u[(axis + 1) % 3] = -1;
            GLuint c[4];
            for (int q = 0; q < 4; q++) {
                float a = (q == 1 || q == 2) ? 1.f : -1.f, b = q >= 2 ? 1.f : -1.f;
                c[q] = vert(m, n[0] + a * u[0] + b * v[0], n[1] + a * u[1] + b * v[1], n[2] + a * u[2] + b * v[2],
                            n[0], n[1], n[2]);
            }
            tri(m, c[0], c[1], c[2]);
            tri(m, c[0], c[2], c[3]);
        }
}

/* ---- set-up ----------------------------------------------------------------------------- */
void wb_gl_upload(GLenum target, GLuint buf, size_t *cap, const void *data, size_t bytes)
{
    glBindBuffer(target, buf);
    if (bytes > *cap) {
        size_t c = *cap ? *cap : 4096;
        while (c < bytes) c *= 2;
        glBufferData(target, (GLsizeiptr)c, NULL, GL_STREAM_DRAW);
        *cap = c;
    }
    if (bytes) glBufferSubData(target, 0, (GLsizeiptr)bytes, data);
}

void wb_gl_surf_attribs(const wb_gl *g)
{
    glBindVertexArray(g->vao_surf);
    glBindBuffer(GL_ARRAY_BUFFER, g->vbo_surf);
    for (GLuint a = 0; a < 3; a++) glEnableVertexAttribArray(a == 2 ? 9 : a);
    const GLsizei stride = WB_SV * sizeof(float);
    glVertexAttribPointer(0, 3, GL_FLOAT, GL_FALSE, stride, (const void *)0);
    glVertexAttribPointer(1, 3, GL_FLOAT, GL_FALSE, stride, (const void *)(3 * sizeof(float)));
    glVertexAttribPointer(9, 4, GL_FLOAT, GL_FALSE, stride, (const void *)(6 * sizeof(float)));
}

void wb_gl_inst_attribs(const wb_gl *g, size_t first)
{
    glBindVertexArray(g->vao_mesh);
    glBindBuffer(GL_ARRAY_BUFFER, g->vbo_inst);
    size_t base = first * sizeof(wb_inst);
    for (int k = 0; k < 4; k++)
        glVertexAttribPointer((GLuint)(2 + k), 4, GL_FLOAT, GL_FALSE, sizeof(wb_inst),
                              (const void *)(base + offsetof(wb_inst, m) + (size_t)k * 16));
    for (int k = 0; k < 3; k++)
        glVertexAttribPointer((GLuint)(6 + k), 3, GL_FLOAT, GL_FALSE, sizeof(wb_inst),
                              (const void *)(base + offsetof(wb_inst, n) + (size_t)k * 12));
    glVertexAttribPointer(9, 4, GL_FLOAT, GL_FALSE, sizeof(wb_inst), (const void *)(base + offsetof(wb_inst, c)));
}

/* the frame's own colour and depth (multisample when samples > 1) */
static bool frame_target(wb_gl *g, int w, int h, int samples, char *err, size_t n)
{
    glGenFramebuffers(1, &g->fbo_ms);
    glGenRenderbuffers(1, &g->rb_color);
    glGenRenderbuffers(1, &g->rb_depth);
    glBindFramebuffer(GL_FRAMEBUFFER, g->fbo_ms);
    glBindRenderbuffer(GL_RENDERBUFFER, g->rb_color);
    glRenderbufferStorageMultisample(GL_RENDERBUFFER, samples > 1 ? samples : 0, GL_RGBA8, w, h);
    glFramebufferRenderbuffer(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_RENDERBUFFER, g->rb_color);
    glBindRenderbuffer(GL_RENDERBUFFER, g->rb_depth);
    glRenderbufferStorageMultisample(GL_RENDERBUFFER, samples > 1 ? samples : 0, GL_DEPTH_COMPONENT24, w, h);
    glFramebufferRenderbuffer(GL_FRAMEBUFFER, GL_DEPTH_ATTACHMENT, GL_RENDERBUFFER, g->rb_depth);
    if (glCheckFramebufferStatus(GL_FRAMEBUFFER) != GL_FRAMEBUFFER_COMPLETE) {
        snprintf(err, n, "the %dx%d framebuffer with %d samples is not supported", w, h, samples);
        return false;
    }
    return true;
}

static bool targets(wb_gl *g, int w, int h, int *samples, bool direct, char *err, size_t n)
{
    GLint max = 1;
    glGetIntegerv(GL_MAX_SAMPLES, &max);
    if (*samples > max) *samples = max;
    if (*samples < 1) *samples = 1;
    /* one sample into the default framebuffer: a copy of the frame less (5 ms at 720p) */
    if (!(*samples == 1 && direct) && !frame_target(g, w, h, *samples, err, n)) return false;
    /* the shadow map: 1024 texels over the scene's sphere is a few mm for a room-sized
     * scene; 2048 costs a tenth of a 720p frame */
    g->shadow_size = w * h > 1920 * 1080 ? 2048 : 1024;
    glGenTextures(1, &g->tex_shadow);
    glBindTexture(GL_TEXTURE_2D, g->tex_shadow);
    glTexImage2D(GL_TEXTURE_2D, 0, GL_DEPTH_COMPONENT24, g->shadow_size, g->shadow_size, 0, GL_DEPTH_COMPONENT,
                 GL_UNSIGNED_INT, NULL);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_LINEAR);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_LINEAR);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_S, GL_CLAMP_TO_EDGE);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_T, GL_CLAMP_TO_EDGE);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_COMPARE_MODE, GL_COMPARE_REF_TO_TEXTURE);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_COMPARE_FUNC, GL_LEQUAL);
    glGenFramebuffers(1, &g->fbo_shadow);
    glBindFramebuffer(GL_FRAMEBUFFER, g->fbo_shadow);
    glFramebufferTexture2D(GL_FRAMEBUFFER, GL_DEPTH_ATTACHMENT, GL_TEXTURE_2D, g->tex_shadow, 0);
    glDrawBuffer(GL_NONE);
    glReadBuffer(GL_NONE);
    if (glCheckFramebufferStatus(GL_FRAMEBUFFER) != GL_FRAMEBUFFER_COMPLETE) {
        snprintf(err, n, "the shadow map framebuffer is not supported");
        return false;
    }
    glBindFramebuffer(GL_FRAMEBUFFER, 0);
    return true;
}

bool wb_gl_init(wb_gl *g, int w, int h, int *samples, bool direct, char *err, size_t n)
{
    memset(g, 0, sizeof *g);
    if (!(g->prog_mesh = program(mesh_vs, mesh_fs, true, NULL, err, n)) ||
        !(g->prog_depth = program(mesh_vs, depth_fs, false, NULL, err, n)) ||
        !(g->prog_line = program(line_vs, line_fs, false, NULL, err, n)) ||
        !(g->prog_grid = program(grid_vs, grid_fs, true, "#define SHADOWED\n", err, n)) ||
        !(g->prog_grid_plain = program(grid_vs, grid_fs, true, NULL, err, n)) ||
        !(g->prog_bg = program(bg_vs, bg_fs, false, NULL, err, n)))
        return false;

    mesh_build m = { 0 };
    static const struct { int kind, a, b; } parts[] = {
        { MESH_SPHERE_LO, 10, 16 }, { MESH_SPHERE_HI, 32, 48 }, { MESH_CYLINDER, 48, 0 }, { MESH_BOX, 0, 0 },
    };
    for (size_t k = 0; k < sizeof parts / sizeof *parts; k++) {
        g->mesh_first[parts[k].kind] = (GLint)m.ni;
        if (parts[k].kind == MESH_CYLINDER) cylinder(&m, parts[k].a);
        else if (parts[k].kind == MESH_BOX) box(&m);
        else sphere(&m, parts[k].a, parts[k].b);
        g->mesh_count[parts[k].kind] = (GLint)m.ni - g->mesh_first[parts[k].kind];
    }
    if (m.oom) {
        free(m.v);
        free(m.i);
        snprintf(err, n, "out of memory building meshes");
        return false;
    }
    GLuint bufs[6];
    glGenBuffers(6, bufs);
    g->vbo_mesh = bufs[0], g->ebo_mesh = bufs[1], g->vbo_inst = bufs[2], g->vbo_surf = bufs[3];
    g->ebo_surf = bufs[4], g->vbo_seg = bufs[5];
    GLuint vaos[4];
    glGenVertexArrays(4, vaos);
    g->vao_mesh = vaos[0], g->vao_surf = vaos[1], g->vao_line = vaos[2], g->vao_empty = vaos[3];

    glBindVertexArray(g->vao_mesh);
    glBindBuffer(GL_ARRAY_BUFFER, g->vbo_mesh);
    glBufferData(GL_ARRAY_BUFFER, (GLsizeiptr)(m.nv * 6 * sizeof(float)), m.v, GL_STATIC_DRAW);
    glBindBuffer(GL_ELEMENT_ARRAY_BUFFER, g->ebo_mesh);
    glBufferData(GL_ELEMENT_ARRAY_BUFFER, (GLsizeiptr)(m.ni * sizeof(GLuint)), m.i, GL_STATIC_DRAW);
    free(m.v);
    free(m.i);
    glEnableVertexAttribArray(0);
    glEnableVertexAttribArray(1);
    glVertexAttribPointer(0, 3, GL_FLOAT, GL_FALSE, 6 * sizeof(float), (const void *)0);
    glVertexAttribPointer(1, 3, GL_FLOAT, GL_FALSE, 6 * sizeof(float), (const void *)(3 * sizeof(float)));
    for (GLuint a = 2; a <= 9; a++) {
        glEnableVertexAttribArray(a);
        glVertexAttribDivisor(a, 1);
    }
    g->inst_cap = 0;
    wb_gl_upload(GL_ARRAY_BUFFER, g->vbo_inst, &g->inst_cap, NULL, 64 * sizeof(wb_inst));
    wb_gl_inst_attribs(g, 0);

    /* surfaces: per-vertex position, normal and colour; the other instance
     * attributes stay disabled and take constant values (identity model) */
    glBindVertexArray(g->vao_surf);
    wb_gl_upload(GL_ARRAY_BUFFER, g->vbo_surf, &g->surf_cap, NULL, 4096);
    glBindBuffer(GL_ELEMENT_ARRAY_BUFFER, g->ebo_surf);
    wb_gl_surf_attribs(g);

    glBindVertexArray(g->vao_line);
    wb_gl_upload(GL_ARRAY_BUFFER, g->vbo_seg, &g->seg_cap, NULL, 4096);
    for (GLuint a = 0; a < 3; a++) {
        glEnableVertexAttribArray(a);
        glVertexAttribDivisor(a, 1);
    }
    glVertexAttribPointer(0, 3, GL_FLOAT, GL_FALSE, sizeof(wb_seg), (const void *)offsetof(wb_seg, a));
    glVertexAttribPointer(1, 3, GL_FLOAT, GL_FALSE, sizeof(wb_seg), (const void *)offsetof(wb_seg, b));
    glVertexAttribPointer(2, 4, GL_FLOAT, GL_FALSE, sizeof(wb_seg), (const void *)offsetof(wb_seg, c));
    glBindVertexArray(0);

    if (!targets(g, w, h, samples, direct, err, n)) return false;
    GLenum e = glGetError();
    if (e != GL_NO_ERROR) {
        snprintf(err, n, "OpenGL error 0x%04x while setting up the renderer", (unsigned)e);
        return false;
    }
    return true;
}

void wb_gl_free(wb_gl *g)
{
    GLuint progs[] = { g->prog_mesh, g->prog_depth, g->prog_line, g->prog_grid, g->prog_grid_plain, g->prog_bg };
    for (size_t k = 0; k < sizeof progs / sizeof *progs; k++)
        if (progs[k]) glDeleteProgram(progs[k]);
    GLuint bufs[] = { g->vbo_mesh, g->ebo_mesh, g->vbo_inst, g->vbo_surf, g->ebo_surf, g->vbo_seg };
    glDeleteBuffers(6, bufs);
    GLuint vaos[] = { g->vao_mesh, g->vao_surf, g->vao_line, g->vao_empty };
    glDeleteVertexArrays(4, vaos);
    GLuint fbos[] = { g->fbo_ms, g->fbo_shadow };
    glDeleteFramebuffers(2, fbos);
    GLuint rbs[] = { g->rb_color, g->rb_depth };
    glDeleteRenderbuffers(2, rbs);
    if (g->tex_shadow) glDeleteTextures(1, &g->tex_shadow);
    memset(g, 0, sizeof *g);
}
