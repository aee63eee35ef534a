/* layers.c: what each layer draws, built on the CPU every frame: instances of
 * the solid meshes (particles, pins, colliders), the surfaces' and skins' vertices
 * (position, smooth normal, colour) and triangles, and the links as coloured
 * segments. Strain colours follow the reference thesis's Figure 12: grey at rest, red
 * stretched (links also blue compressed); with the links drawn, surfaces take the
 * colour of their stretch, so a dense cloth shows it rather than a fence of lines.
 * The other materials tint their particles and surfaces the same way (red expanded,
 * blue compressed): a tet's volumetric strain, a shape-matching cluster's, a pressure
 * body's volume against its target, a bend's angle against its rest. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "render.h"
#include "gl.h"
#include "layers_int.h"

/* colours, sRGB */
static const float col_particle[3] = { 0.22f, 0.47f, 0.80f };
static const float col_pin[3] = { 0.98f, 0.68f, 0.08f };
static const float col_attach[3] = { 0.16f, 0.70f, 0.30f };  /* attached to a collider */
static const float col_grab[3] = { 0.85f, 0.15f, 0.75f };    /* grabbed, its target and line */
static const float col_collider[3] = { 0.55f, 0.58f, 0.64f };
static const float col_rigid[3] = { 0.86f, 0.50f, 0.20f };  /* rigid bodies: a warm orange */
/* a surface coloured by strain: light and neutral at rest, so red and blue stand out */
static const float col_cloth[3] = { 0.68f, 0.68f, 0.67f };
static const float col_surface[][3] = {
    { 0.91f, 0.42f, 0.24f }, { 0.26f, 0.64f, 0.56f }, { 0.56f, 0.44f, 0.80f }, { 0.86f, 0.70f, 0.28f },
};
static const float col_skin[3] = { 0.86f, 0.76f, 0.62f };
static const float surface_shine = 0.12f;

void wb_layers_free(wb_layers *l)
{
    free(l->inst);
    free(l->seg);
    free(l->sv);
    free(l->si);
    free(l->pairs);
    free(l->strain);
    free(l->vstrain);
    free(l->mstrain);
    free(l->flags);
    free(l->scratch);
    memset(l, 0, sizeof *l);
}

/* ---- instances -------------------------------------------------------------------------- */
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
    wb_lin3(rgb, in->c);
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

/* a shape's solid (wobble.h) as an instance when it is of group g's kind, with the
 * colour and shine of its owner (spheres in the fine group, under its cylinders' caps);
 * returns the instances written (0 or 1). One that is not finite is not drawn */
static int inst_solid(wb_inst *in, const wb_solid *s, int g, const float rgb[3], float shine)
{
    const double c[3] = { s->c[0], s->c[1], s->c[2] };
    if (g == WB_G_HI && s->kind == WB_SOLID_SPHERE) {
        if (!isfinite(c[0] + c[1] + c[2])) return 0;
        inst_sphere(in, c, s->radius, rgb, shine);
        return 1;
    }
    if (g == WB_G_CYL && s->kind == WB_SOLID_CYLINDER) {
        const double a[3] = { s->a[0], s->a[1], s->a[2] }, b[3] = { s->b[0], s->b[1], s->b[2] };
        if (!isfinite(a[0] + a[1] + a[2] + b[0] + b[1] + b[2])) return 0;
        inst_cylinder(in, a, b, s->radius, rgb);
        return 1;
    }
    if (g == WB_G_BOX && s->kind == WB_SOLID_BOX) {
        double cols[3][3];
        for (int cc = 0; cc < 3; cc++)
            for (int rr = 0; rr < 3; rr++) cols[cc][rr] = s->axes[cc][rr];
        if (!isfinite(c[0] + c[1] + c[2])) return 0;
        inst_set(in, c, cols, rgb, shine);
        return 1;
    }
    return 0;
}

/* instances grouped by mesh: particle spheres, collider spheres and capsule caps,
 * capsule bodies, boxes. Particles of a drawn surface are shown by the surface (a
 * sphere per cloth vertex hides the cloth), those under a skin by the skin. */
static bool build_instances(wb_layers *l, const wb_world *w, const wb_draw_opts *o, double unit)
{
    int32_t np = wb_particle_count(w), nc = wb_collider_count(w), nr = o->rigids ? wb_rigid_count(w) : 0;
    const int32_t na = wb_attach_count(w), ng = wb_grab_count(w);
    size_t need = (size_t)np + 3 * (size_t)nc + 3 * (size_t)nr + (size_t)na + 2 * (size_t)ng;
    if (!wb_grow(&l->inst, &l->inst_cap, need + 1, sizeof *l->inst)) return false;
    const wb_real *x = wb_particle_positions(w);
    size_t k = 0;
    l->first[WB_G_LO] = 0;
    for (int32_t i = 0; i < np; i++) {
        bool pin = wb_particle_pinned(w, i);
        double p[3] = { x[3 * i], x[3 * i + 1], x[3 * i + 2] }, rad = wb_particle_radius(w, i);
        if (!isfinite(p[0] + p[1] + p[2])) continue;
        if (rad <= 0) rad = 0.004 * unit;   /* a point still shows */
        if (pin && o->pins) inst_sphere(&l->inst[k++], p, fmax(1.6 * rad, 0.006 * unit), col_pin, 0.5f);
        else if (o->particles && !(l->flags[i] & (F_SURFACE | F_HIDDEN))) {
            float col[3];
            if (o->materials && (l->flags[i] & F_MATERIAL)) wb_strain_colour_srgb(l->mstrain[i], l->scale, col);
            else memcpy(col, col_particle, sizeof col);
            inst_sphere(&l->inst[k++], p, rad, col, 0.5f);
        }
    }
    /* attached particles and grabbed ones are marked as pins are (with the pins), a
     * grab's target as a small sphere of its colour; the ids listed in one pass each
     * (wb_attach_at per one is quadratic) */
    const size_t nid = (size_t)(na > ng ? na : ng);
    void *ids = o->pins && nid > 0 ? malloc(nid * sizeof(wb_attach_id)) : NULL;
    if (o->pins && nid > 0 && !ids) return false;
    if (ids) wb_attach_list(w, ids, na);
    for (int32_t i = 0; o->pins && i < na; i++) {
        const int32_t pi = wb_attach_particle(w, ((const wb_attach_id *)ids)[i]);
        const double p[3] = { x[3 * pi], x[3 * pi + 1], x[3 * pi + 2] };
        if (isfinite(p[0] + p[1] + p[2]))
            inst_sphere(&l->inst[k++], p, fmax(1.6 * wb_particle_radius(w, pi), 0.006 * unit), col_attach, 0.5f);
    }
    if (ids) wb_grab_list(w, ids, ng);
    for (int32_t i = 0; o->pins && i < ng; i++) {
        const wb_grab_id gid = ((const wb_grab_id *)ids)[i];
        const int32_t pi = wb_grab_particle(w, gid); /* -1: a rigid body's point */
        wb_real t[3], gp[3];
        wb_grab_point(w, gid, gp);
        wb_grab_target(w, gid, t);
        const double p[3] = { gp[0], gp[1], gp[2] }, tp[3] = { t[0], t[1], t[2] };
        const double rad = fmax(pi >= 0 ? 1.6 * wb_particle_radius(w, pi) : 0, 0.006 * unit);
        if (isfinite(p[0] + p[1] + p[2])) inst_sphere(&l->inst[k++], p, rad, col_grab, 0.5f);
        inst_sphere(&l->inst[k++], tp, 0.5 * rad, col_grab, 0.5f);
    }
    free(ids);
    l->count[WB_G_LO] = k;
    for (int g = WB_G_HI; g < WB_G_COUNT; g++) {
        l->first[g] = k;
        for (int32_t i = 0; o->colliders && i < nc; i++) {
            wb_solid sol[WB_MAX_SOLIDS];
            const int ns = wb_collider_solids(w, wb_collider_at(w, i), sol);
            for (int j = 0; j < ns; j++) k += inst_solid(&l->inst[k], &sol[j], g, col_collider, 0.35f);
        }
        /* rigid bodies: the same solids at their poses */
        for (int32_t i = 0; i < nr; i++) {
            wb_solid sol[WB_MAX_SOLIDS];
            const int ns = wb_rigid_solids(w, wb_rigid_at(w, i), sol);
            for (int j = 0; j < ns; j++) k += inst_solid(&l->inst[k], &sol[j], g, col_rigid, 0.45f);
        }
        l->count[g] = k - l->first[g];
    }
    return true;
}

/* links as segments; those touching a drawn surface are shown by its colour (a dense
 * cloth's links would cover it like a fence; a block's inner links would poke through
 * its hull as dots), those under a skin not at all */
static bool build_segments(wb_layers *l, const wb_world *w)
{
    if (!wb_grow(&l->seg, &l->seg_cap, (size_t)l->npairs + 1, sizeof *l->seg)) return false;
    const wb_real *x = wb_particle_positions(w);
    float rest[3];
    wb_lin3(col_rest, rest);
    size_t k = 0;
    for (int32_t i = 0; i < l->npairs; i++) {
        int32_t a = l->pairs[2 * i], b = l->pairs[2 * i + 1];
        if (((l->flags[a] | l->flags[b]) & F_SURFACE) || (l->flags[a] & l->flags[b] & F_HIDDEN)) continue;
        wb_seg *s = &l->seg[k++];
        for (int c = 0; c < 3; c++) s->a[c] = (float)x[3 * a + c], s->b[c] = (float)x[3 * b + c];
        wb_strain_colour(l->strain[i], l->scale, rest, s->c);
        s->c[3] = 1;
    }
    l->nseg = k;
    return true;
}

/* a line from each grabbed particle to its target (after the links) */
static bool build_grab_lines(wb_layers *l, const wb_world *w)
{
    const int32_t ng = wb_grab_count(w);
    if (ng == 0) return true;
    if (!wb_grow(&l->seg, &l->seg_cap, l->nseg + (size_t)ng, sizeof *l->seg)) return false;
    wb_grab_id *ids = malloc((size_t)ng * sizeof *ids);
    if (!ids) return false;
    wb_grab_list(w, ids, ng);
    float col[3];
    wb_lin3(col_grab, col);
    for (int32_t i = 0; i < ng; i++) {
        const wb_grab_id gid = ids[i];
        wb_real t[3], p[3]; /* from the grabbed particle or body point */
        wb_grab_point(w, gid, p);
        wb_grab_target(w, gid, t);
        wb_seg *s = &l->seg[l->nseg++];
        for (int c = 0; c < 3; c++) s->a[c] = (float)p[c], s->b[c] = (float)t[c], s->c[c] = col[c];
        s->c[3] = 1;
    }
    free(ids);
    return true;
}

/* ---- surfaces ------------------------------------------------------------------------------ */
static int cmp_u64(const void *a, const void *b)
{
    uint64_t x = *(const uint64_t *)a, y = *(const uint64_t *)b;
    return (x > y) - (x < y);
}

/* +1 or -1 when a surface is closed (every edge on exactly two triangles), the sign of
 * its enclosed volume: its triangles wind outward or inward; 0 when it is open (a
 * sheet has no outside) or memory runs short */
static int closed_sign(const wb_real *x, const int32_t *t, int32_t nt)
{
    if (nt < 4) return 0;
    uint64_t *e = malloc(3 * (size_t)nt * sizeof *e);
    if (!e) return 0;
    for (int32_t i = 0; i < nt; i++)
        for (int j = 0; j < 3; j++) {
            uint32_t a = (uint32_t)t[3 * i + j], b = (uint32_t)t[3 * i + (j + 1) % 3];
            e[3 * i + j] = a < b ? (uint64_t)a << 32 | b : (uint64_t)b << 32 | a;
        }
    qsort(e, 3 * (size_t)nt, sizeof *e, cmp_u64);
    bool closed = true;
    for (size_t i = 0; closed && i < 3 * (size_t)nt; i += 2)
        closed = i + 1 < 3 * (size_t)nt && e[i + 1] == e[i] && (i + 2 >= 3 * (size_t)nt || e[i + 2] != e[i]);
    free(e);
    if (!closed) return 0;
    double vol = 0;   /* six times the signed volume: the triple products about the origin */
    for (int32_t i = 0; i < nt; i++) {
        const wb_real *a = x + 3 * t[3 * i], *b = x + 3 * t[3 * i + 1], *c = x + 3 * t[3 * i + 2];
        vol += a[0] * (b[1] * c[2] - b[2] * c[1]) + a[1] * (b[2] * c[0] - b[0] * c[2]) + a[2] * (b[0] * c[1] - b[1] * c[0]);
    }
    return vol > 0 ? 1 : vol < 0 ? -1 : 0;
}

static void put_vertex(float *v, const double p[3], const double n[3], const float col[3])
{
    for (int c = 0; c < 3; c++) v[c] = (float)p[c], v[3 + c] = (float)n[c], v[6 + c] = col[c];
    v[9] = surface_shine;
}

/* the mesh colliders' triangles (when colliders are drawn) */
static size_t mesh_collider_triangles(const wb_world *w, const wb_draw_opts *o)
{
    size_t n = 0;
    for (int32_t i = 0; o->colliders && i < wb_collider_count(w); i++) {
        const wb_real *v;
        const int32_t *t;
        int32_t nt = 0;
        wb_collider_mesh(w, wb_collider_at(w, i), &v, &t, &nt);
        n += (size_t)nt;
    }
    return n;
}

/* a mesh collider's triangles at its pose, three vertices each with the face's normal:
 * flat shading shows the facets the particles actually collide with */
static size_t put_mesh_colliders(wb_layers *l, const wb_world *w, const wb_draw_opts *o, size_t base, size_t *k)
{
    float col[3];
    wb_lin3(col_collider, col);
    for (int32_t i = 0; o->colliders && i < wb_collider_count(w); i++) {
        const wb_collider_id id = wb_collider_at(w, i);
        const wb_real *v;
        const int32_t *t;
        int32_t nt = 0;
        wb_collider_mesh(w, id, &v, &t, &nt);
        if (nt == 0) continue;
        wb_collider_def d;
        wb_collider_get_def(w, id, &d);
        double m[9];
        quat_mat(d.rotation, m);
        for (int32_t j = 0; j < nt; j++) {
            double p[3][3], e1[3], e2[3], fn[3];
            for (int c = 0; c < 3; c++) {
                const wb_real *q = &v[3 * t[3 * j + c]];
                for (int r = 0; r < 3; r++) p[c][r] = d.center[r] + m[r * 3] * q[0] + m[r * 3 + 1] * q[1] + m[r * 3 + 2] * q[2];
            }
            for (int r = 0; r < 3; r++) e1[r] = p[1][r] - p[0][r], e2[r] = p[2][r] - p[0][r];
            cross3(e1, e2, fn);
            norm3(fn);
            for (int c = 0; c < 3; c++) {
                put_vertex(l->sv + WB_SV * base, p[c], fn, col);
                l->si[(*k)++] = (GLuint)base++;
            }
        }
    }
    return base;
}

/* the particle pairs of the broken links, each as a < b in one uint64, sorted; *n = 0
 * when none is broken. NULL: out of memory */
static uint64_t *broken_pairs(const wb_world *w, size_t *n)
{
    *n = 0;
    const int32_t nd = wb_distance_count(w);
    uint64_t *out = malloc(((size_t)(nd - wb_world_distance_pairs(w, NULL, NULL)) + 1) * sizeof *out);
    if (!out) return NULL;
    if (nd == wb_world_distance_pairs(w, NULL, NULL)) return out;
    wb_distance_id *ids = malloc((size_t)nd * sizeof *ids);
    if (!ids) {
        free(out);
        return NULL;
    }
    const int32_t m = wb_distance_ids(w, ids);
    for (int32_t i = 0; i < m; i++) {
        if (!wb_distance_broken(w, ids[i])) continue;
        int32_t a, b;
        wb_distance_particles(w, ids[i], &a, &b);
        out[(*n)++] = a < b ? (uint64_t)(uint32_t)a << 32 | (uint32_t)b : (uint64_t)(uint32_t)b << 32 | (uint32_t)a;
    }
    free(ids);
    qsort(out, *n, sizeof *out, cmp_u64);
    return out;
}

/* a triangle across a tear: one of its edges is a broken link. Its particles fly apart
 * with nothing holding them, so it would be drawn as a stretched sliver over the gap. */
static bool torn(const uint64_t *broken, size_t nb, const int32_t *v)
{
    for (int j = 0; nb && j < 3; j++) {
        uint32_t a = (uint32_t)v[j], b = (uint32_t)v[(j + 1) % 3];
        uint64_t key = a < b ? (uint64_t)a << 32 | b : (uint64_t)b << 32 | a;
        if (bsearch(&key, broken, nb, sizeof key, cmp_u64)) return true;
    }
    return false;
}

/* Smooth normals stop at a crease of a closed surface (a hull): where two triangles at a
 * particle meet at more than CREASE_DEG, each keeps the normal of its own side (an own
 * vertex per corner there). Not on open sheets: a coarse cloth's sharp folds would show
 * as facets, and a cloth has no edges by design.
 * 55 degrees: above the 45 of a round body cut in eight (a coarse ball or capsule stays
 * smooth), well under the 90 of a voxel body's edges (a
 * lattice's hull, the logo's letters), which stay sharp while squashed by a third. */
#define CREASE_DEG 55.0

/* vertices: the particles, then the corners at creases, then every skin's, then the
 * mesh colliders'; indices: the surfaces' triangles (those not wholly under a drawn
 * skin nor across a tear), then the skins', then the mesh colliders'. Smooth normals:
 * area-weighted, split at creases. A closed surface's vertices sit out along their
 * smooth normals (never the split ones: the hull stays closed) by their particle's
 * contact radius, where its sphere ends: bodies that touch (or rest on a collider,
 * also at the radius) look touching, not a spacing apart; an open one (a cloth) stays
 * through the centres. */
static bool build_surfaces(wb_layers *l, const wb_world *w, const wb_draw_opts *o, const wb_draw_skin *sk, int nsk)
{
    int32_t np = wb_particle_count(w), ns = o->surfaces ? wb_surface_count(w) : 0;
    const wb_real *x = wb_particle_positions(w);
    size_t total = 0, nv = (size_t)np;
    for (int32_t s = 0; s < ns; s++) {
        int32_t nt = 0;
        wb_surface_triangles(w, s, &nt);
        total += 3 * (size_t)nt;
    }
    const size_t nsurf = total;   /* surface corners at most */
    for (int i = 0; i < nsk; i++) total += 3 * (size_t)sk[i].nt, nv += (size_t)sk[i].nv;
    const size_t nmesh = mesh_collider_triangles(w, o);
    total += 3 * nmesh;
    nv += 3 * nmesh;
    if (!wb_grow(&l->si, &l->si_cap, total + 1, sizeof *l->si)) return false;
    size_t nb = 0;
    uint64_t *broken = ns ? broken_pairs(w, &nb) : NULL;
    double *acc = calloc((size_t)np * 3 + 3, sizeof *acc);
    /* per drawn triangle: its unit normal, then its area-weighted one */
    double *fn = malloc((nsurf / 3 + 1) * 6 * sizeof *fn);
    int32_t *start = calloc((size_t)np + 2, sizeof *start), *inc = malloc((nsurf + 1) * sizeof *inc);
    bool *hull = malloc(nsurf / 3 + 1);   /* per drawn triangle: on a closed surface */
    int16_t *owner = malloc(((size_t)np + 1) * sizeof *owner);   /* the first surface a particle is on */
    signed char *out = calloc((size_t)np + 1, 1);   /* per particle: +-1 on a closed surface */
    bool ok = (broken || !ns) && acc && fn && start && inc && hull && owner && out;
    if (!ok) goto done;
    memset(owner, 0xff, ((size_t)np + 1) * sizeof *owner);
    size_t k = 0;
    for (int32_t s = 0; s < ns; s++) {
        int32_t nt = 0;
        const int32_t *t = wb_surface_triangles(w, s, &nt);
        const int sign = closed_sign(x, t, nt);
        for (int32_t i = 0; sign && i < 3 * nt; i++) out[t[i]] = (signed char)sign;
        for (int32_t i = 0; i < nt; i++) {
            const int32_t *v = t + 3 * i;
            if (l->flags[v[0]] & l->flags[v[1]] & l->flags[v[2]] & F_HIDDEN) continue;
            if (torn(broken, nb, v)) continue;
            double e1[3], e2[3], *f = fn + 2 * k;
            for (int c = 0; c < 3; c++) e1[c] = x[3 * v[1] + c] - x[3 * v[0] + c], e2[c] = x[3 * v[2] + c] - x[3 * v[0] + c];
            cross3(e1, e2, f);
            memcpy(f + 3, f, 3 * sizeof *f);
            hull[k / 3] = sign != 0;
            norm3(f);
            for (int j = 0; j < 3; j++) {
                /* weighted by the triangle's angle at the particle, not its area: a flat
                 * face then counts alike however it is cut, so the particles along a
                 * cube's edge all sit out along its diagonal (by area each leaned to
                 * whichever side had the larger triangles there, and the edge drawn out
                 * along those normals was a saw-tooth) */
                const wb_real *p0 = &x[3 * v[j]], *p1 = &x[3 * v[(j + 1) % 3]], *p2 = &x[3 * v[(j + 2) % 3]];
                double a[3], b[3];
                for (int c = 0; c < 3; c++) a[c] = p1[c] - p0[c], b[c] = p2[c] - p0[c];
                const double la = norm3(a), lb = norm3(b);
                const double cs = dot3(a, b), ang = la > 0 && lb > 0 ? acos(cs < -1 ? -1 : cs > 1 ? 1 : cs) : 0;
                for (int c = 0; c < 3; c++) acc[3 * v[j] + c] += ang * f[c];
                l->si[k++] = (GLuint)v[j];
                l->flags[v[j]] |= F_SURFACE;
                start[v[j] + 1]++;
                if (owner[v[j]] < 0) owner[v[j]] = (int16_t)(s % 4);
            }
        }
    }
    const size_t ncorner = k;
    /* the triangles at each particle: inc[start[i] .. start[i+1]) */
    for (int32_t i = 0; i < np; i++) start[i + 1] += start[i];
    for (size_t c = 0; c < ncorner; c++) inc[start[l->si[c]]++] = (int32_t)(c / 3);
    for (int32_t i = np; i > 0; i--) start[i] = start[i - 1];
    start[0] = 0;
    /* a particle is creased when two of its triangles are further apart than the crease */
    const double cos_crease = cos(CREASE_DEG * M_PI / 180);
    size_t extra = 0;
    for (size_t c = 0; c < ncorner; c++) {
        const int32_t v = (int32_t)l->si[c];
        const double *f = fn + 6 * (c / 3);
        for (int32_t q = start[v]; hull[c / 3] && q < start[v + 1]; q++)
            if (dot3(f, fn + 6 * inc[q]) < cos_crease) {
                extra++;
                break;
            }
    }
    nv += extra;
    if (!wb_grow(&l->sv, &l->sv_cap, WB_SV * nv + WB_SV, sizeof *l->sv)) {
        ok = false;
        goto done;
    }
    float cloth[3];
    wb_lin3(col_cloth, cloth);
    for (int32_t i = 0; i < np; i++) {
        double p[3] = { x[3 * i], x[3 * i + 1], x[3 * i + 2] };
        float col[3];
        if (o->materials && (l->flags[i] & F_MATERIAL)) {
            /* the material's strain, or its links' stretch where that is larger */
            double e = l->mstrain[i];
            if (o->constraints && fabs(l->vstrain[i]) > fabs(e)) e = l->vstrain[i];
            wb_strain_colour(e, l->scale, cloth, col);
        } else if (o->constraints) wb_strain_colour(l->vstrain[i], l->scale, cloth, col);
        else wb_lin3(col_surface[owner[i] < 0 ? 0 : owner[i]], col);
        norm3(acc + 3 * i);
        const double off = out[i] * (double)wb_particle_radius(w, i);
        for (int c = 0; c < 3; c++) p[c] += off * acc[3 * i + c];
        put_vertex(l->sv + WB_SV * i, p, acc + 3 * i, col);
    }
    /* the corners at creases: the particle's vertex with the normal of the triangles on
     * this corner's side of the crease (area-weighted again) */
    size_t base = (size_t)np;
    for (size_t c = 0; extra && c < ncorner; c++) {
        const int32_t v = (int32_t)l->si[c];
        if (!hull[c / 3]) continue;
        const double *f = fn + 6 * (c / 3);
        double n[3] = { 0, 0, 0 };
        bool creased = false;
        for (int32_t q = start[v]; q < start[v + 1]; q++) {
            const double *g = fn + 6 * inc[q];
            if (dot3(f, g) < cos_crease) {
                creased = true;
                continue;
            }
            for (int d = 0; d < 3; d++) n[d] += g[3 + d];
        }
        if (!creased) continue;
        norm3(n);
        float *dst = l->sv + WB_SV * base;
        memcpy(dst, l->sv + WB_SV * (size_t)v, WB_SV * sizeof *dst);
        for (int d = 0; d < 3; d++) dst[3 + d] = (float)n[d];
        l->si[c] = (GLuint)base++;
    }
    float skin[3];   /* skins: their own (deformed) vertices and normals */
    wb_lin3(col_skin, skin);
    for (int i = 0; i < nsk; i++) {
        for (int32_t v = 0; v < sk[i].nv; v++) {
            double p[3] = { sk[i].v[3 * v], sk[i].v[3 * v + 1], sk[i].v[3 * v + 2] };
            double n[3] = { sk[i].n[3 * v], sk[i].n[3 * v + 1], sk[i].n[3 * v + 2] };
            put_vertex(l->sv + WB_SV * (base + v), p, n, skin);
        }
        for (int32_t t = 0; t < 3 * sk[i].nt; t++) l->si[k++] = (GLuint)(base + (size_t)sk[i].tri[t]);
        base += (size_t)sk[i].nv;
    }
    put_mesh_colliders(l, w, o, base, &k);
    l->nv = nv;
    l->nidx = k;
done:
    free(broken);
    free(acc);
    free(fn);
    free(start);
    free(inc);
    free(hull);
    free(owner);
    free(out);
    return ok;
}

bool wb_layers_build(wb_layers *l, const wb_world *w, const wb_draw_opts *o, const wb_draw_skin *sk, int nsk,
                     double unit)
{
    int32_t np = wb_particle_count(w);
    if (!wb_grow(&l->flags, &l->flag_cap, (size_t)np + 1, 1)) return false;
    memset(l->flags, 0, (size_t)np + 1);
    /* the particles a drawn skin is bound to are its cage: the skin shows them */
    for (int i = 0; !o->cage && i < nsk; i++)
        for (int32_t b = 0; sk[i].skin && b < wb_skin_bone_count(sk[i].skin); b++) {
            int32_t p = wb_skin_bone_particle(sk[i].skin, b);
            if (p >= 0 && p < np) l->flags[p] |= F_HIDDEN;
        }
    l->npairs = 0;
    if (o->constraints && !wb_strain_pairs(l, w)) return false;
    if (o->materials && !wb_strain_materials(l, w)) return false;
    l->scale = o->strain_scale;
    if (o->strain_auto && (o->constraints || o->materials) && !wb_strain_auto(l, w, o)) return false;
    if (o->materials) wb_strain_bends(l, w, l->scale);
    l->nv = l->nidx = l->nseg = 0;
    l->surfaces = (o->surfaces && wb_surface_count(w) > 0 && np > 0) || nsk > 0 || mesh_collider_triangles(w, o) > 0;
    if (l->surfaces && !build_surfaces(l, w, o, sk, nsk)) return false;
    if (!build_instances(l, w, o, unit)) return false;
    if (o->constraints && !build_segments(l, w)) return false;
    if (o->pins && !build_grab_lines(l, w)) return false;
    l->strain_shown = o->constraints && l->npairs > 0;
    for (int32_t i = 0; o->materials && !l->strain_shown && i < np; i++) l->strain_shown = l->flags[i] & F_MATERIAL;
    return true;
}
