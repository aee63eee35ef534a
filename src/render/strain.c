/* strain.c: the strain colours of layers.c (grey at rest, red stretched, blue
 * compressed) and the strains they show each frame: the distance constraints' (per
 * link, and per particle for surfaces), the materials' (tets, shape matching, pressure,
 * bends) and the automatic scale (strain_scale = "auto") */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "render.h"
#include "gl.h"
#include "layers_int.h"

/* colours, sRGB */
static const float col_tension[3] = { 0.92f, 0.08f, 0.06f };
static const float col_compress[3] = { 0.12f, 0.32f, 0.92f };

void wb_lin3(const float s[3], float o[3])
{
    for (int k = 0; k < 3; k++) o[k] = s[k] * s[k];   /* the shaders output with gamma 2 */
}

/* a particle sphere's colour (sRGB: inst_set linearises): grey at rest, red expanded,
 * blue compressed, fully at +-scale */
void wb_strain_colour_srgb(double strain, double scale, float out[3])
{
    double t = strain / scale;
    t = t > 1 ? 1 : t < -1 ? -1 : t;
    const float *to = t >= 0 ? col_tension : col_compress;
    for (int c = 0; c < 3; c++) out[c] = (float)(col_rest[c] + (to[c] - col_rest[c]) * fabs(t));
}

void wb_strain_srgb(double t, float out[3])
{
    wb_strain_colour_srgb(t, 1, out);
}

/* grey at rest, shading to red stretched and blue compressed, fully at +-strain_scale */
void wb_strain_colour(double strain, double scale, const float rest[3], float out[3])
{
    float ten[3], com[3];
    wb_lin3(col_tension, ten), wb_lin3(col_compress, com);
    double t = strain / scale;
    t = t > 1 ? 1 : t < -1 ? -1 : t;
    const float *to = t >= 0 ? ten : com;
    for (int c = 0; c < 3; c++) out[c] = (float)(rest[c] + (to[c] - rest[c]) * fabs(t));
}

/* the distance constraints and their strains, and per particle the strain its
 * surface shows (l->vstrain[0..np); the rest is scratch) */
bool wb_strain_pairs(wb_layers *l, const wb_world *w)
{
    int32_t n = wb_world_distance_pairs(w, NULL, NULL), np = wb_particle_count(w);
    size_t had = l->pair_cap;
    if (!wb_grow(&l->pairs, &l->pair_cap, 2 * (size_t)n + 2, sizeof *l->pairs)) return false;
    if (l->pair_cap != had || !l->strain) {   /* the strains share the capacity count */
        void *q = realloc(l->strain, (l->pair_cap / 2 + 1) * sizeof *l->strain);
        if (!q) return false;
        l->strain = q;
    }
    if (!wb_grow(&l->vstrain, &l->vstrain_cap, 3 * (size_t)np + 1, sizeof *l->vstrain)) return false;
    l->npairs = wb_world_distance_pairs(w, l->pairs, l->strain);
    /* the largest stretch at each particle (compression in a sheet is its folds, which
     * the shading shows: in colour it would be noise), then averaged over its links'
     * other ends: peaks stay, the checkerboard of stretched and sheared links goes */
    float *peak = l->vstrain + np, *count = l->vstrain + 2 * (size_t)np, *v = l->vstrain;
    memset(peak, 0, 2 * (size_t)np * sizeof *peak);
    for (int32_t i = 0; i < l->npairs; i++)
        for (int e = 0; e < 2; e++) {
            float *pk = &peak[l->pairs[2 * i + e]];
            if (l->strain[i] > *pk) *pk = (float)l->strain[i];
        }
    memcpy(v, peak, (size_t)np * sizeof *v);
    for (int32_t i = 0; i < np; i++) count[i] = 1;
    for (int32_t i = 0; i < l->npairs; i++) {
        int32_t a = l->pairs[2 * i], b = l->pairs[2 * i + 1];
        v[a] += peak[b], count[a]++;
        v[b] += peak[a], count[b]++;
    }
    for (int32_t i = 0; i < np; i++) v[i] /= count[i];
    return true;
}

/* a material's strain e at particle i: where several apply, the largest in magnitude */
static void put_material(wb_layers *l, int32_t i, double e)
{
    if (!isfinite(e)) return;
    if (!(l->flags[i] & F_MATERIAL) || fabs(e) > fabs(l->mstrain[i])) l->mstrain[i] = (float)e;
    l->flags[i] |= F_MATERIAL;
}

/* per particle, the strain of the materials it belongs to (l->mstrain[0..np), flag
 * F_MATERIAL; the rest is scratch): the volumetric strain (V - V0) / V0 averaged over
 * its tets (volume constraints and Neo-Hookean tets); a shape-matching cluster's strain (wb_shape_match_strain), negative when the
 * cluster drew in (its spread about the centre of mass below the rest shape's); a
 * pressure body's V / (pressure V0) - 1 on its surface; a bend's angle off its rest
 * (load_bends) */
bool wb_strain_materials(wb_layers *l, const wb_world *w)
{
    const int32_t np = wb_particle_count(w), nv = wb_volume_count(w);
    if (!wb_grow(&l->mstrain, &l->mstrain_cap, 3 * (size_t)np + 1, sizeof *l->mstrain)) return false;
    float *sum = l->mstrain + np, *count = l->mstrain + 2 * (size_t)np;
    memset(l->mstrain, 0, 3 * (size_t)np * sizeof *l->mstrain);
    for (int32_t i = 0; i < nv; i++) {
        const double v0 = wb_volume_rest(w, i);
        if (v0 == 0) continue;
        const double e = (wb_volume_current(w, i) - v0) / v0;
        if (!isfinite(e)) continue;
        int32_t p[4];
        wb_volume_particles(w, i, p);
        for (int k = 0; k < 4; k++) sum[p[k]] += (float)e, count[p[k]]++;
    }
    /* Neo-Hookean tets the same way, by det F - 1 (their (V - V0) / V0) or, where larger,
     * their shape change (wb_tet_strain: a shear keeps the volume) */
    const int32_t nt = wb_tet_count(w);
    for (int32_t i = 0; i < nt; i++) {
        const double e = wb_tet_strain(w, i);
        if (!isfinite(e)) continue;
        int32_t p[4];
        wb_tet_particles(w, i, p);
        for (int k = 0; k < 4; k++) sum[p[k]] += (float)e, count[p[k]]++;
    }
    for (int32_t i = 0; nv + nt > 0 && i < np; i++)
        if (count[i] > 0) put_material(l, i, sum[i] / count[i]);
    const wb_real *x = wb_particle_positions(w);
    for (int32_t s = 0; s < wb_shape_match_count(w); s++) {
        const int32_t n = wb_shape_match_size(w, s);
        double c[3] = { 0, 0, 0 }, m = 0, now = 0, rest = 0;
        for (int32_t i = 0; i < n; i++) {
            const int32_t p = wb_shape_match_particle(w, s, i);
            const double mi = wb_particle_mass(w, p);
            for (int k = 0; k < 3; k++) c[k] += mi * x[3 * p + k];
            m += mi;
        }
        if (!(m > 0)) continue;
        for (int i = 0; i < n; i++) {
            const int32_t p = wb_shape_match_particle(w, s, i);
            const double mi = wb_particle_mass(w, p);
            wb_real r[3];
            wb_shape_match_rest(w, s, i, r);
            for (int k = 0; k < 3; k++) {
                const double d = x[3 * p + k] - c[k] / m;
                now += mi * d * d, rest += mi * (double)r[k] * r[k];
            }
        }
        const double e = (now < rest ? -1 : 1) * (double)wb_shape_match_strain(w, s);
        for (int32_t i = 0; i < n; i++) put_material(l, wb_shape_match_particle(w, s, i), e);
    }
    for (int32_t i = 0; i < wb_pressure_count(w); i++) {
        const double target = wb_pressure_get_def(w, i).pressure * wb_pressure_rest_volume(w, i);
        if (!(target > 0)) continue;
        const double e = wb_pressure_volume(w, i) / target - 1;
        int32_t nt = 0;
        const int32_t *t = wb_surface_triangles(w, wb_pressure_surface(w, i), &nt);
        for (int32_t k = 0; k < 3 * nt; k++) put_material(l, t[k], e);
    }
    return true;
}

/* the k-th smallest of v[0..n) in place (quickselect) */
static float select_k(float *v, size_t n, size_t k)
{
    size_t lo = 0, hi = n - 1;
    while (lo < hi) {
        const float pivot = v[lo + (hi - lo) / 2];
        size_t i = lo, j = hi;
        while (i <= j) {
            while (v[i] < pivot) i++;
            while (v[j] > pivot) j--;
            if (i <= j) {
                const float t = v[i];
                v[i] = v[j], v[j] = t;
                i++;
                if (j == 0) break;
                j--;
            }
        }
        if (k <= j) hi = j;
        else if (k >= i) lo = i;
        else break;
    }
    return v[k];
}

/* the automatic strain scale: the 95th percentile of |strain| over the links and the
 * materials' particles, so the most strained few percent are in full colour and the
 * rest shades (a fixed 2 % turns any loaded body uniformly red); at least 0.5 %, or a
 * body settling would show its noise (0.1 %, the logo's letters at rest) in full colour. Eased over frames in log
 * scale: a fifth of the way up per frame (a blow shows within a few frames), a
 * twentieth down (a settling body fades over about a second at 60 fps); the same frame
 * drawn again, or another world, takes it as it is. Bends are left out: their colour is
 * a part of the scale (load_bends). */
#define AUTO_PERCENTILE 0.95
#define AUTO_MIN 0.005
bool wb_strain_auto(wb_layers *l, const wb_world *w, const wb_draw_opts *o)
{
    const int32_t np = wb_particle_count(w);
    /* a free link's strain each, and at most one per particle (a surface's or a material's) */
    const size_t want = (o->constraints ? (size_t)l->npairs : 0) + (o->constraints || o->materials ? (size_t)np : 0) + 1;
    if (!wb_grow(&l->scratch, &l->scratch_cap, want, sizeof *l->scratch)) return false;
    /* the strains as shown: a free link's, a surface particle's stretch (vstrain), a
     * material's */
    for (int32_t s = 0; o->surfaces && s < wb_surface_count(w); s++) {
        int32_t nt = 0;
        const int32_t *t = wb_surface_triangles(w, s, &nt);
        for (int32_t i = 0; i < 3 * nt; i++) l->flags[t[i]] |= F_ON_SURFACE;
    }
    size_t n = 0;
    for (int32_t i = 0; o->constraints && i < l->npairs; i++)
        if (isfinite(l->strain[i]) && !((l->flags[l->pairs[2 * i]] | l->flags[l->pairs[2 * i + 1]]) & F_ON_SURFACE))
            l->scratch[n++] = (float)fabs(l->strain[i]);
    for (int32_t i = 0; i < np; i++) {
        float e = 0;
        if (o->constraints && (l->flags[i] & F_ON_SURFACE)) e = l->vstrain[i];
        if (o->materials && (l->flags[i] & F_MATERIAL) && fabsf(l->mstrain[i]) > e) e = fabsf(l->mstrain[i]);
        if ((o->constraints && (l->flags[i] & F_ON_SURFACE)) || (o->materials && (l->flags[i] & F_MATERIAL)))
            if (isfinite(e)) l->scratch[n++] = e;
    }
    double target = AUTO_MIN;
    if (n > 0) target = fmax(target, select_k(l->scratch, n, (size_t)(AUTO_PERCENTILE * (double)(n - 1))));
    const int64_t frame = wb_world_frame(w);
    if (l->auto_world == w && frame > l->auto_frame && l->auto_scale > 0) {
        /* per frame stepped since the last draw */
        const double rate = 1 - pow(target > l->auto_scale ? 0.8 : 0.95, (double)(frame - l->auto_frame));
        l->auto_scale = exp(log(l->auto_scale) + rate * (log(target) - log(l->auto_scale)));
    } else {
        l->auto_scale = target;
    }
    l->auto_world = w;
    l->auto_frame = frame;
    l->scale = l->auto_scale;
    return true;
}

/* bends at their hinge's two particles (after the other materials: their colour is a
 * part of the scale) */
void wb_strain_bends(wb_layers *l, const wb_world *w, double scale)
{
    /* |angle - rest| / (pi/4) of strain_scale (a
     * bend pi/4 off its rest is as full a colour as a link strain_scale off its); red
     * when bent further than its rest (further from flat, or through to the other side),
     * blue when opened out flatter. The angle's sign follows the wings' order, so only
     * its size against the rest's says which way */
    for (int32_t i = 0; i < wb_bend_count(w); i++) {
        const wb_bend_id b = wb_bend_at(w, i);
        const double a = wb_bend_angle(w, b), r = wb_bend_rest(w, b);
        double d = a - r;
        if (!isfinite(d)) continue;
        d = fabs(remainder(d, 2 * M_PI));
        const bool flatter = a * r >= 0 && fabs(a) < fabs(r);
        const double e = (flatter ? -1 : 1) * scale * d / (M_PI / 4);
        int32_t p[4];
        wb_bend_particles(w, b, p);
        put_material(l, p[0], e), put_material(l, p[1], e);
    }
}
