/* json_material.c: the "shape_matches" and "pressures" sections of a particle config
 * (docs/formats.md, "Particle configs"):
 *
 *   "shape_matches": [ {"particles": [0, 1, 2, ...], "stiffness": 1, "yield": 0, "creep": 1,
 *                       "rest": [x,y,z, ...], "rotation": [w,x,y,z]}, ... ]
 *   "pressures": [ {"surface": 0, "pressure": 1, "compliance": 0, "rest_volume": 0.5}, ... ]
 *
 * "rest" (the rest shape about its mass centre) defaults to the particles' positions
 * about their mass centre, "rest_volume" to the surface's volume at load; w:save writes
 * both and the rotation (the fit's warm start) for the exact restore. As w:shape_match,
 * a cluster given a yield but no creep flows at 1/s. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "json.h"

int jm_read_shape_matches(rd *r, const cJSON *arr, wb_image *g)
{
    static const char *const keys[] = { "particles", "stiffness", "yield", "creep", "rest", "rotation", NULL };
    kp top = { NULL, "shape_matches", 0 };
    int32_t n = 0, i = 0;
    int64_t nids = 0;
    if (!arr) return 0;
    if (jv_get_array(r, arr, &top, WB_MAX_CONSTRAINTS, &n)) return -1;
    /* first pass: the shape of every entry and the total of particles */
    for (const cJSON *c = arr->child; c; c = c->next, i++) {
        const cJSON *f[7];
        kp p = { &top, NULL, i }, pp = { &p, "particles", 0 };
        int32_t k;
        if (jv_get_object(r, c, &p, keys, f)) return -1;
        if (!f[0]) return jv_missing(r, c, &p, "particles");
        if (jv_get_array(r, f[0], &pp, WB_MAX_PARTICLES, &k)) return -1;
        if (k < 2) return jv_fail(r, f[0], 0, &pp, "a cluster needs at least 2 particles, got %d", k);
        nids += k;
        if (nids > WB_MAX_CONSTRAINTS) return jv_fail(r, f[0], 0, &pp, "too many particles in clusters");
    }
    if (wb_image_alloc_smatch(g, n, (int32_t)nids) != WB_OK) return jv_fail(r, arr, 0, &top, "out of memory");
    wb_image_smatch *s = &g->sm;
    int32_t at = 0;
    i = 0;
    for (const cJSON *c = arr->child; c; c = c->next, i++) {
        const cJSON *f[7];
        kp p = { &top, NULL, i }, pp = { &p, "particles", 0 };
        jv_get_object(r, c, &p, keys, f); /* checked above */
        const int32_t first = at;
        int32_t k = 0;
        for (const cJSON *e = f[0]->child; e; e = e->next, k++) {
            kp q = { &pp, NULL, k };
            int64_t v;
            if (g->np == 0) return jv_fail(r, e, 0, &q, "there are no particles");
            if (jv_get_int(r, e, &q, 0, g->np - 1, &v)) return -1;
            s->ids[at++] = (int32_t)v;
        }
        s->start[i + 1] = at;
        wb_shape_match_def d = { 1, 0, 0 };
        if (jv_opt_real(r, f[1], &p, "stiffness", &d.stiffness) || jv_opt_real(r, f[2], &p, "yield", &d.yield) ||
            jv_opt_real(r, f[3], &p, "creep", &d.creep) || jv_opt_vec(r, f[5], &p, "rotation", 4, &s->q[4 * i]))
            return -1;
        /* the core decides the options (shape_match.c) */
        const wb_fault ft = wb_shape_match_def_fault(&d);
        if (jv_fault(r, &ft, &p, keys, f, 0)) return -1;
        if (!f[3] && d.yield > 0) d.creep = 1;
        s->stiff[i] = d.stiffness;
        s->yield[i] = d.yield;
        s->creep[i] = d.creep;
        if (f[4]) {
            kp q = { &p, "rest", 0 };
            int32_t m;
            if (jv_get_array(r, f[4], &q, 3ll * WB_MAX_PARTICLES, &m)) return -1;
            if (m != 3 * k) return jv_fail(r, f[4], 0, &q, "%d numbers expected (x, y, z of each particle), got %d", 3 * k, m);
            int32_t j = 0;
            for (const cJSON *e = f[4]->child; e; e = e->next, j++) {
                kp ej = { &q, NULL, j };
                if (jv_get_real(r, e, &ej, &s->rest[3 * (int64_t)first + j])) return -1;
            }
        } else {
            /* the positions about their mass centre, as w:shape_match takes them */
            wb_real cm[3] = { 0, 0, 0 }, M = 0;
            for (int32_t j = first; j < at; j++) {
                const wb_real im = g->inv_mass[s->ids[j]];
                if (im <= 0) continue;
                for (int a = 0; a < 3; a++) cm[a] += g->x[3 * s->ids[j] + a] * (1 / im);
                M += 1 / im;
            }
            if (!(M > 0)) return jv_fail(r, f[0], 0, &pp, "a cluster needs a particle with mass (all are immovable)");
            for (int a = 0; a < 3; a++) cm[a] *= 1 / M;
            for (int32_t j = first; j < at; j++)
                for (int a = 0; a < 3; a++) s->rest[3 * j + a] = g->x[3 * s->ids[j] + a] - cm[a];
        }
    }
    return 0;
}

int jm_read_pressures(rd *r, const cJSON *arr, wb_image *g)
{
    static const char *const keys[] = { "surface", "pressure", "compliance", "rest_volume", NULL };
    kp top = { NULL, "pressures", 0 };
    int32_t n = 0, i = 0;
    if (!arr) return 0;
    if (jv_get_array(r, arr, &top, WB_MAX_CONSTRAINTS, &n)) return -1;
    if (wb_image_alloc_pressure(g, n) != WB_OK) return jv_fail(r, arr, 0, &top, "out of memory");
    for (const cJSON *c = arr->child; c; c = c->next, i++) {
        const cJSON *f[5];
        kp p = { &top, NULL, i };
        int64_t s;
        if (jv_get_object(r, c, &p, keys, f)) return -1;
        if (!f[0]) return jv_missing(r, c, &p, "surface");
        if (g->nsurf == 0) {
            kp q = { &p, "surface", 0 };
            return jv_fail(r, f[0], 0, &q, "there are no surfaces");
        }
        wb_pressure_def d = { 1, 0 };
        wb_real v0 = -1;
        if (jv_opt_int(r, f[0], &p, "surface", 0, g->nsurf - 1, &s) || jv_opt_real(r, f[1], &p, "pressure", &d.pressure) ||
            jv_opt_real(r, f[2], &p, "compliance", &d.compliance) || jv_opt_real(r, f[3], &p, "rest_volume", &v0))
            return -1;
        /* the core decides the options (pressure.c); the rest volume is the file's state */
        const wb_fault ft = wb_pressure_def_fault(&d);
        if (jv_fault(r, &ft, &p, keys, f, 0)) return -1;
        kp vq = { &p, "rest_volume", 0 };
        if (f[3] && !(v0 > 0)) return jv_fail(r, f[3], 0, &vq, "must be > 0");
        g->pr.surface[i] = (int32_t)s;
        g->pr.pressure[i] = d.pressure;
        g->pr.alpha[i] = d.compliance;
        g->pr.v0[i] = v0; /* < 0: the volume at load */
    }
    return 0;
}

/* "tets": [ {"particles": [a, b, c, d], "young": E, "poisson": nu, "rest_inverse": [9],
 * "rest_volume": V0, "yield": y, "creep": c}, ... ]: Neo-Hookean tets (core/tet.c). young is
 * required, poisson 0.3 by default; the rest state (Dm^-1 row-major and V0 > 0, both or
 * neither; w:save writes them so a reload has the same future) is the particles' shape by
 * default; yield and creep (plastic flow of the rest shape) 0. */
int jm_read_tets(rd *r, const cJSON *arr, wb_image *g)
{
    static const char *const keys[] = { "particles", "young", "poisson", "rest_inverse", "rest_volume", "yield", "creep", NULL };
    kp top = { NULL, "tets", 0 };
    int32_t n = 0, i = 0;
    if (!arr) return 0;
    if (jv_get_array(r, arr, &top, WB_MAX_CONSTRAINTS, &n)) return -1;
    if (wb_image_alloc_tets(g, n) != WB_OK) return jv_fail(r, arr, 0, &top, "out of memory");
    for (const cJSON *c = arr->child; c; c = c->next, i++) {
        const cJSON *f[8];
        kp p = { &top, NULL, i }, pp = { &p, "particles", 0 };
        if (jv_get_object(r, c, &p, keys, f)) return -1;
        if (!f[0]) return jv_missing(r, c, &p, "particles");
        if (!f[1]) return jv_missing(r, c, &p, "young");
        int32_t *q4 = &g->tet.ijkl[4 * i];
        if (jv_get_ids(r, f[0], &pp, g->np, 4, "a tet", q4)) return -1;
        wb_tet_def d = wb_tet_default_def();
        if (jv_opt_real(r, f[1], &p, "young", &d.young) || jv_opt_real(r, f[2], &p, "poisson", &d.poisson) ||
            jv_opt_real(r, f[5], &p, "yield", &d.yield) || jv_opt_real(r, f[6], &p, "creep", &d.creep))
            return -1;
        /* the core decides what a tet may be (tet.c); its rest shape from the positions
         * only when the file does not give it */
        const wb_fault ft = wb_tet_check(g->np, f[3] ? NULL : g->x, q4, &d);
        if (jv_fault(r, &ft, &p, keys, f, 0)) return -1;
        g->tet.young[i] = d.young;
        g->tet.poisson[i] = d.poisson;
        g->tet.plastic[2 * i] = d.yield;
        g->tet.plastic[2 * i + 1] = d.creep;
        if (!f[3] != !f[4]) return jv_fail(r, c, 0, &p, "rest_inverse and rest_volume go together");
        if (f[3]) {
            kp vq = { &p, "rest_volume", 0 };
            if (jv_opt_vec(r, f[3], &p, "rest_inverse", 9, &g->tet.dminv[9 * i]) ||
                jv_opt_real(r, f[4], &p, "rest_volume", &g->tet.v0[i]))
                return -1;
            if (!(g->tet.v0[i] > 0) || !isfinite(g->tet.v0[i])) return jv_fail(r, f[4], 0, &vq, "must be > 0");
        } else {
            const wb_real *x = g->x;
            wb_tet_rest_shape(&x[3 * q4[0]], &x[3 * q4[1]], &x[3 * q4[2]], &x[3 * q4[3]], &g->tet.dminv[9 * i],
                              &g->tet.v0[i]); /* checked above: not flat */
        }
    }
    return 0;
}

/* ---- writing (w:save) ------------------------------------------------------------------------ */
/* "tets": Neo-Hookean tets with their rest state (only when present) */
void jm_write_tets(jw_out *o, const wb_image *g)
{
    FILE *f = o->f;
    if (g->tet.n == 0) return;
    fputs("  \"tets\": [", f);
    for (int32_t i = 0; i < g->tet.n; i++) {
        const int32_t *p = &g->tet.ijkl[4 * i];
        fprintf(f, "%s    {\"particles\": [%d, %d, %d, %d], \"young\": ", i ? ",\n" : "\n", p[0], p[1], p[2], p[3]);
        jw_num(o, g->tet.young[i]);
        fputs(", \"poisson\": ", f);
        jw_num(o, g->tet.poisson[i]);
        fputs(", \"rest_volume\": ", f);
        jw_num(o, g->tet.v0[i]);
        fputs(", \"rest_inverse\": ", f);
        jw_vec(o, &g->tet.dminv[9 * i], 9);
        jw_plastic(o, &g->tet.plastic[2 * i]);
        fputc('}', f);
    }
    fputs("\n  ],\n", f);
}

/* "shape_matches": only when present, with the rest shapes and rotations (the exact restore) */
void jm_write_shape_matches(jw_out *o, const wb_image *g)
{
    FILE *f = o->f;
    const wb_image_smatch *s = &g->sm;
    for (int32_t k = 0; k < s->n; k++) {
        const int32_t a = s->start[k], b = s->start[k + 1];
        fputs(k ? ",\n    {\"particles\": " : "  \"shape_matches\": [\n    {\"particles\": ", f);
        jw_ints(f, "      ", NULL, &s->ids[a], b - a);
        fputs(", \"stiffness\": ", f);
        jw_num(o, s->stiff[k]);
        fputs(", \"yield\": ", f);
        jw_num(o, s->yield[k]);
        fputs(", \"creep\": ", f);
        jw_num(o, s->creep[k]);
        fputs(",\n     \"rest\": ", f);
        jw_vec(o, &s->rest[3 * (int64_t)a], 3 * (b - a));
        fputs(", \"rotation\": ", f);
        jw_vec(o, &s->q[4 * k], 4);
        fputc('}', f);
    }
    if (s->n) fputs("\n  ],\n", f);
}

/* "pressures": only when present, with the rest volumes */
void jm_write_pressures(jw_out *o, const wb_image *g)
{
    FILE *f = o->f;
    for (int32_t k = 0; k < g->pr.n; k++) {
        fprintf(f, "%s    {\"surface\": %d, \"pressure\": ", k ? ",\n" : "  \"pressures\": [\n", g->pr.surface[k]);
        jw_num(o, g->pr.pressure[k]);
        fputs(", \"compliance\": ", f);
        jw_num(o, g->pr.alpha[k]);
        fputs(", \"rest_volume\": ", f);
        jw_num(o, g->pr.v0[k]);
        fputc('}', f);
    }
    if (g->pr.n) fputs("\n  ],\n", f);
}
