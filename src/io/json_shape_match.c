/* json_shape_match.c: shape-matching clusters (core/shape_match.c) in a particle config:
 * their "shape_matches" section (docs/formats.md, "Particle configs"):
 *
 *   "shape_matches": [ {"particles": [0, 1, 2, ...], "stiffness": 1, "yield": 0, "creep": 1,
 *                       "rest": [x,y,z, ...], "rotation": [w,x,y,z]}, ... ]
 *
 * "rest" (the rest shape about its mass centre) defaults to the particles' positions about
 * their mass centre; w:save writes it and the rotation (the fit's warm start) for the exact
 * restore. As w:shape_match, a cluster given a yield but no creep flows at 1/s. */
#include "json.h"

static int read_shape_matches(rd *r, const cJSON *arr, wb_image *g)
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

/* ---- writing (w:save) ------------------------------------------------------------------------ */
/* with the rest shapes and rotations (the exact restore) */
static int write_shape_matches(jw_out *o, const wb_image *g, int first)
{
    FILE *f = o->f;
    const wb_image_smatch *s = &g->sm;
    for (int32_t k = 0; k < s->n; k++) {
        const int32_t a = s->start[k], b = s->start[k + 1];
        jw_next(o, &first);
        fputs("    {\"particles\": ", f);
        jw_ints(f, "      ", NULL, &s->ids[a], b - a);
        jw_key(o, "stiffness", s->stiff[k]);
        jw_key(o, "yield", s->yield[k]);
        jw_key(o, "creep", s->creep[k]);
        fputs(",\n     \"rest\": ", f);
        jw_vec(o, &s->rest[3 * (int64_t)a], 3 * (b - a));
        fputs(", \"rotation\": ", f);
        jw_vec(o, &s->q[4 * k], 4);
        fputc('}', f);
    }
    return first;
}

const jtype jt_shape_match = {
    .key = "shape_matches", .read = read_shape_matches, .write = write_shape_matches,
};
