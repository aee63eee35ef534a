/* builders.c: cloth, rope and lattice bodies made of particles and distance links.
 * Each checks its whole definition and reserves all memory first, so a failing
 * builder changes nothing. */
#include <stdlib.h>

#include "core.h"
#include "bend.h"
#include "volume.h"
#include "tet.h"

wb_cloth_def wb_cloth_default_def(void)
{
    wb_cloth_def d;
    memset(&d, 0, sizeof d);
    d.size[0] = d.size[1] = 1;
    d.res[0] = d.res[1] = 10;
    d.mass = 1;
    d.radius = 0.02;
    d.shear = true;
    d.bend = -1;
    d.bend_links = -1;
    d.link = wb_distance_default_def();
    return d;
}

wb_rope_def wb_rope_default_def(void)
{
    wb_rope_def d;
    memset(&d, 0, sizeof d);
    v3_set(d.to, 1, 0, 0);
    d.segments = 10;
    d.mass = 1;
    d.radius = 0.02;
    d.link = wb_distance_default_def();
    return d;
}

wb_lattice_def wb_lattice_default_def(void)
{
    wb_lattice_def d;
    memset(&d, 0, sizeof d);
    v3_set(d.max, 1, 1, 1);
    d.res[0] = d.res[1] = d.res[2] = 4;
    d.mass = 1;
    d.radius = 0.02;
    d.link = wb_distance_default_def();
    d.poisson = 0.3;
    return d;
}

static int fin(wb_real x) { return isfinite(x); }

static wb_status bad(const char *msg)
{
    wb__set_error("%s", msg);
    return WB_ERR_ARG;
}

static wb_status check_common(wb_real mass, wb_real radius, const wb_distance_def *link)
{
    if (!(mass > 0) || !fin(mass)) return bad("mass must be > 0");
    if (!(radius >= 0) || !fin(radius)) return bad("radius must be >= 0");
    const char *e = wb_distance_def_check(link);
    return e ? bad(e) : WB_OK;
}

/* The rules every builder applies to what it derives, before it adds anything (the core
 * asserts finite positions, and the solver works with squared lengths):
 *  - every particle position finite (from + (to - from) t overflows long before the
 *    endpoints do);
 *  - the body's bounding-box diagonal squared finite: no link's length squared, and so
 *    no computed rest length, can overflow;
 *  - the mass per particle > 0 with a finite inverse (a tiny mass split over many
 *    particles underflows to 0, which would make them immovable).
 * `pos` gives particle i's position; `what` names the option at fault. */
static wb_status check_derived(void (*pos)(const void *d, int64_t i, wb_real p[3]), const void *d, int64_t np,
                               const char *what, wb_real mass)
{
    wb_real mn[3] = { INFINITY, INFINITY, INFINITY }, mx[3] = { -INFINITY, -INFINITY, -INFINITY };
    for (int64_t i = 0; i < np; i++) {
        wb_real p[3];
        pos(d, i, p);
        for (int c = 0; c < 3; c++) {
            if (!fin(p[c])) {
                wb__set_error("%s: particle %lld's position is not finite (the extent overflows)", what, (long long)i + 1);
                return WB_ERR_ARG;
            }
            mn[c] = fmin(mn[c], p[c]);
            mx[c] = fmax(mx[c], p[c]);
        }
    }
    wb_real dd = 0;
    for (int c = 0; c < 3; c++) {
        const wb_real e = mx[c] - mn[c];
        dd += e * e;
    }
    if (!fin(dd)) {
        wb__set_error("%s: the body is too large (its extent squared overflows; links need finite squared lengths)", what);
        return WB_ERR_ARG;
    }
    const wb_real m = mass / (wb_real)np;
    if (!(m > 0) || !fin(1 / m)) {
        wb__set_error("mass: %g over %lld particles is %g each, too small (its inverse overflows)", (double)mass,
                      (long long)np, (double)m);
        return WB_ERR_ARG;
    }
    return WB_OK;
}

static void cloth_pos(const void *dv, int64_t k, wb_real p[3])
{
    const wb_cloth_def *d = dv;
    const int nx = d->res[0], nz = d->res[1], i = (int)(k % nx), j = (int)(k / nx);
    p[0] = d->origin[0] + d->size[0] * i / (nx - 1);
    p[1] = d->origin[1];
    p[2] = d->origin[2] + d->size[1] * j / (nz - 1);
}

static void rope_pos(const void *dv, int64_t i, wb_real p[3])
{
    const wb_rope_def *d = dv;
    const wb_real t = (wb_real)i / d->segments;
    for (int c = 0; c < 3; c++) p[c] = d->from[c] + (d->to[c] - d->from[c]) * t;
}

static void lattice_pos(const void *dv, int64_t n, wb_real p[3])
{
    const wb_lattice_def *d = dv;
    const int nx = d->res[0], ny = d->res[1], nz = d->res[2];
    const int ix[3] = { (int)(n % nx), (int)(n / nx % ny), (int)(n / nx / ny) }, res[3] = { nx, ny, nz };
    for (int c = 0; c < 3; c++) p[c] = d->min[c] + (d->max[c] - d->min[c]) * ix[c] / (res[c] - 1);
}

/* link a-b with the builder's options; cannot fail after wb__reserve */
static void link(wb_world *w, int32_t a, int32_t b, const wb_distance_def *def)
{
    wb_distance_add(w, a, b, def, NULL);
}

static void dashpot(wb_world *w, int32_t a, int32_t b, const wb_distance_def *def, wb_real young)
{
    wb_real xa[3], xb[3];
    wb_particle_position(w, a, xa);
    wb_particle_position(w, b, xb);
    const wb_real len = sqrt((xb[0] - xa[0]) * (xb[0] - xa[0]) + (xb[1] - xa[1]) * (xb[1] - xa[1]) +
                             (xb[2] - xa[2]) * (xb[2] - xa[2]));
    const wb_distance_def d = wb__dashpot_def(def, young, len);
    wb_distance_add(w, a, b, &d, NULL);
}

wb_status wb_cloth(wb_world *w, const wb_cloth_def *d, wb_body *out)
{
    wb_status st = check_common(d->mass, d->radius, &d->link);
    if (st) return st;
    const int nx = d->res[0], nz = d->res[1];
    if (nx < 2 || nz < 2) return bad("res must be at least {2,2}");
    if ((int64_t)nx * nz > WB_MAX_PARTICLES) return bad("res is too large (more than 16777216 particles)");
    if (!fin(d->origin[0]) || !fin(d->origin[1]) || !fin(d->origin[2])) return bad("origin must be finite");
    if (!(d->size[0] > 0 && d->size[1] > 0) || !fin(d->size[0]) || !fin(d->size[1])) return bad("size must be > 0");
    if (!(d->bend < 0 || fin(d->bend))) return bad("bend must be a finite compliance >= 0");
    if (!(d->bend_links < 0 || fin(d->bend_links))) return bad("bend_links must be a finite compliance >= 0");
    const int64_t np = (int64_t)nx * nz;
    int64_t nd = (int64_t)(nx - 1) * nz + (int64_t)nx * (nz - 1);
    if (d->shear) nd += (int64_t)(nx - 1) * (nz - 1);
    if (d->bend_links >= 0) nd += (int64_t)(nx - 2 > 0 ? nx - 2 : 0) * nz + (int64_t)nx * (nz - 2 > 0 ? nz - 2 : 0);
    const int64_t ntri = 2 * (int64_t)(nx - 1) * (nz - 1);
    if ((st = check_derived(cloth_pos, d, np, "origin/size", d->mass)) != WB_OK) return st;
    const int32_t first = w->m.np;
    /* the sheet, split along the shear diagonals so shading follows the links; its
     * interior edges are the hinges of the dihedral bends */
    int32_t *tri = malloc(sizeof *tri * 3 * (size_t)ntri), *hinge = NULL, nb = 0;
#define ID(i, j) (first + (i) + (j) * nx)
    if (tri) {
        int32_t *t = tri;
        for (int j = 0; j + 1 < nz; j++)
            for (int i = 0; i + 1 < nx; i++) {
                const int32_t a = ID(i, j), b = ID(i + 1, j), c = ID(i + 1, j + 1), e = ID(i, j + 1);
                if ((i + j) % 2 == 0) { t[0] = a; t[1] = e; t[2] = c; t[3] = a; t[4] = c; t[5] = b; }
                else { t[0] = a; t[1] = e; t[2] = b; t[3] = b; t[4] = e; t[5] = c; }
                t += 6;
            }
    }
    if (d->bend >= 0) {
        hinge = tri ? malloc(sizeof *hinge * 4 * (size_t)(3 * ntri / 2 + 1)) : NULL;
        nb = hinge ? wb__bend_hinges(tri, (int32_t)ntri, hinge) : -1;
        if (nb < 0) st = WB_ERR_NOMEM;
    }
    if (st == WB_OK) st = wb__reserve(w, np, nd);
    if (st == WB_OK) st = wb__surface_reserve(w, (int32_t)ntri);
    if (st == WB_OK) st = wb__bend_reserve(w, nb);
    if (st != WB_OK) {
        free(tri);
        free(hinge);
        return st;
    }

    const wb_real m = d->mass / (wb_real)np;
    for (int64_t i = 0; i < np; i++) {
        wb_real p[3];
        cloth_pos(d, i, p);
        wb_particle_add(w, p, NULL, m, d->radius);
    }
    for (int j = 0; j < nz; j++)
        for (int i = 0; i < nx; i++) {
            if (i + 1 < nx) link(w, ID(i, j), ID(i + 1, j), &d->link);
            if (j + 1 < nz) link(w, ID(i, j), ID(i, j + 1), &d->link);
            if (d->shear && i + 1 < nx && j + 1 < nz) {
                /* alternate the diagonal so the cloth has no preferred shear direction */
                if ((i + j) % 2 == 0) link(w, ID(i, j), ID(i + 1, j + 1), &d->link);
                else link(w, ID(i + 1, j), ID(i, j + 1), &d->link);
            }
        }
    if (d->bend_links >= 0) {
        wb_distance_def bl = d->link;
        bl.compliance = d->bend_links;
        for (int j = 0; j < nz; j++)
            for (int i = 0; i < nx; i++) {
                if (i + 2 < nx) link(w, ID(i, j), ID(i + 2, j), &bl);
                if (j + 2 < nz) link(w, ID(i, j), ID(i, j + 2), &bl);
            }
    }
    /* one bend per interior edge, rest = flat as built */
    wb_bend_def bd = wb_bend_default_def();
    bd.compliance = d->bend;
    for (int32_t i = 0; i < nb; i++) wb_bend_add(w, &hinge[4 * i], &bd, NULL);
    if (tri) wb_surface_add(w, tri, (int32_t)ntri);
    free(tri);
    free(hinge);
#undef ID
    return wb__body_finish(w, first, (int32_t)np, out);
}

wb_status wb_rope(wb_world *w, const wb_rope_def *d, wb_body *out)
{
    wb_status st = check_common(d->mass, d->radius, &d->link);
    if (st) return st;
    if (d->segments < 1) return bad("segments must be >= 1");
    if (d->segments >= WB_MAX_PARTICLES) return bad("segments is too large");
    for (int i = 0; i < 3; i++)
        if (!fin(d->from[i]) || !fin(d->to[i])) return bad("from and to must be finite");
    const int n = d->segments + 1;
    if ((st = check_derived(rope_pos, d, n, "from/to", d->mass)) != WB_OK) return st;
    if ((st = wb__reserve(w, n, d->segments)) != WB_OK) return st;
    const int32_t first = w->m.np;
    for (int i = 0; i < n; i++) {
        wb_real p[3];
        rope_pos(d, i, p);
        wb_particle_add(w, p, NULL, d->mass / n, d->radius);
    }
    for (int i = 0; i + 1 < n; i++) link(w, first + i, first + i + 1, &d->link);
    return wb__body_finish(w, first, n, out);
}

wb_status wb_lattice(wb_world *w, const wb_lattice_def *d, wb_body *out)
{
    wb_status st = check_common(d->mass, d->radius, &d->link);
    if (st) return st;
    const int nx = d->res[0], ny = d->res[1], nz = d->res[2];
    if (nx < 2 || ny < 2 || nz < 2) return bad("res must be at least {2,2,2}");
    if ((int64_t)nx * ny * nz > WB_MAX_PARTICLES / 8) return bad("res is too large");
    for (int i = 0; i < 3; i++) {
        if (!fin(d->min[i]) || !fin(d->max[i])) return bad("min and max must be finite");
        if (!(d->max[i] > d->min[i])) return bad("max must be greater than min on every axis");
    }
    const int64_t np = (int64_t)nx * ny * nz;
    /* per cell: 12 edges shared, 6 face diagonals (2 per face) shared, 4 body diagonals */
    const int64_t cells = (int64_t)(nx - 1) * (ny - 1) * (nz - 1);
    const int64_t nd = (int64_t)(nx - 1) * ny * nz + (int64_t)nx * (ny - 1) * nz + (int64_t)nx * ny * (nz - 1) +
                       2 * ((int64_t)(nx - 1) * (ny - 1) * nz + (int64_t)(nx - 1) * ny * (nz - 1) + (int64_t)nx * (ny - 1) * (nz - 1)) +
                       4 * cells;
    const int64_t ntri = 4 * ((int64_t)(nx - 1) * (ny - 1) + (int64_t)(ny - 1) * (nz - 1) + (int64_t)(nz - 1) * (nx - 1));
    if ((st = check_derived(lattice_pos, d, np, "min/max", d->mass)) != WB_OK) return st;
    if (d->tets && !(d->volume_compliance >= 0 && isfinite(d->volume_compliance)))
        return bad("volume_compliance must be >= 0");
    if (d->tets && 6 * cells > WB_MAX_CONSTRAINTS) return bad("res is too large for tets");
    /* young: Neo-Hookean tets and no links (E means E: links would add their stiffness);
     * with damping, dashpot links (nearly no spring) on the same pairs */
    const bool neo = d->young != 0, dash = neo && d->link.damping > 0;
    if (neo && !d->tets) return bad("young needs tets = true");
    if (neo) {
        const wb_tet_def td = { d->young, d->poisson, 0, 0 };
        const char *e = wb_tet_def_check(&td);
        if (e) return bad(e);
    }
    if ((st = wb__reserve(w, np, neo && !dash ? 0 : nd)) != WB_OK || (st = wb__surface_reserve(w, (int32_t)ntri)) != WB_OK ||
        (d->tets && (st = neo ? wb__tet_reserve(w, 6 * cells) : wb__volume_reserve(w, 6 * cells)) != WB_OK))
        return st;
    const int32_t first = w->m.np, first_vol = wb_volume_count(w), first_tet = wb_tet_count(w);
    const wb_real m = d->mass / (wb_real)np;
    for (int64_t i = 0; i < np; i++) {
        wb_real p[3];
        lattice_pos(d, i, p);
        wb_particle_add(w, p, NULL, m, d->radius);
    }
#define ID(i, j, k) (first + (i) + ((j) + (k) * ny) * nx)
    /* every pair of corners of a cell, each pair made once: offsets (di,dj,dk) in {0,1}^3
     * between corner c and c+offset, plus the crossing diagonals of faces and body */
    for (int k = 0; k < nz; k++)
        for (int j = 0; j < ny; j++)
            for (int i = 0; i < nx; i++) {
                const int a = ID(i, j, k);
                const int ex = i + 1 < nx, ey = j + 1 < ny, ez = k + 1 < nz;
                if (neo) {
                    if (ex && ey && ez)
                        wb__kuhn_tets(w, a, ID(i + 1, j, k) - a, ID(i, j + 1, k) - a, ID(i, j, k + 1) - a, 0, d->young, d->poisson);
                    if (!dash) continue;
                }
#define link(w, a, b, def) (dash ? dashpot(w, a, b, def, d->young) : link(w, a, b, def))
                if (ex) link(w, a, ID(i + 1, j, k), &d->link);
                if (ey) link(w, a, ID(i, j + 1, k), &d->link);
                if (ez) link(w, a, ID(i, j, k + 1), &d->link);
                if (ex && ey) { link(w, a, ID(i + 1, j + 1, k), &d->link); link(w, ID(i + 1, j, k), ID(i, j + 1, k), &d->link); }
                if (ex && ez) { link(w, a, ID(i + 1, j, k + 1), &d->link); link(w, ID(i + 1, j, k), ID(i, j, k + 1), &d->link); }
                if (ey && ez) { link(w, a, ID(i, j + 1, k + 1), &d->link); link(w, ID(i, j + 1, k), ID(i, j, k + 1), &d->link); }
                if (ex && ey && ez) {
                    link(w, a, ID(i + 1, j + 1, k + 1), &d->link);
                    link(w, ID(i + 1, j, k), ID(i, j + 1, k + 1), &d->link);
                    link(w, ID(i, j + 1, k), ID(i + 1, j, k + 1), &d->link);
                    link(w, ID(i, j, k + 1), ID(i + 1, j + 1, k), &d->link);
                    if (d->tets && !neo) wb__kuhn_tets(w, ID(i, j, k), ID(i + 1, j, k) - ID(i, j, k), ID(i, j + 1, k) - ID(i, j, k),
                                               ID(i, j, k + 1) - ID(i, j, k), d->volume_compliance, 0, 0);
                }
            }
#undef link
    /* the hull: each of the six faces as a grid of quads, wound outwards */
    int32_t *tri = malloc(sizeof *tri * 3 * (size_t)ntri);
    if (tri) {
        int32_t *t = tri;
        const int n[3] = { nx, ny, nz };
        for (int a = 0; a < 3; a++) {
            const int u = (a + 1) % 3, v = (a + 2) % 3; /* u x v points along +a */
            for (int side = 0; side < 2; side++)
                for (int iv = 0; iv + 1 < n[v]; iv++)
                    for (int iu = 0; iu + 1 < n[u]; iu++) {
                        int32_t q[4];
                        for (int c = 0; c < 4; c++) {
                            int ix[3];
                            ix[a] = side ? n[a] - 1 : 0;
                            ix[u] = iu + (c == 1 || c == 2);
                            ix[v] = iv + (c >= 2);
                            q[c] = ID(ix[0], ix[1], ix[2]);
                        }
                        if (side) { t[0] = q[0]; t[1] = q[1]; t[2] = q[2]; t[3] = q[0]; t[4] = q[2]; t[5] = q[3]; }
                        else { t[0] = q[0]; t[1] = q[2]; t[2] = q[1]; t[3] = q[0]; t[4] = q[3]; t[5] = q[2]; }
                        t += 6;
                    }
        }
        wb_surface_add(w, tri, (int32_t)ntri);
        free(tri);
    }
#undef ID
    /* the links' plastic flow for the tets too: one rest shape for the whole body */
    wb__volume_plastic(w, first_vol, d->link.yield, d->link.creep);
    wb__tet_plastic(w, first_tet, d->link.yield, d->link.creep);
    return wb__body_finish(w, first, (int32_t)np, out);
}
