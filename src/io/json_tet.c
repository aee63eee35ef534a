/* json_tet.c: Neo-Hookean tets (core/tet.c) in a particle config: their "tets" section
 * (docs/formats.md, "Particle configs") */
#include <math.h>

#include "json.h"

/* "tets": [ {"particles": [a, b, c, d], "young": E, "poisson": nu, "rest_inverse": [9],
 * "rest_volume": V0, "yield": y, "creep": c}, ... ]: Neo-Hookean tets (core/tet.c). young is
 * required, poisson 0.3 by default; the rest state (Dm^-1 row-major and V0 > 0, both or
 * neither; w:save writes them so a reload has the same future) is the particles' shape by
 * default; yield and creep (plastic flow of the rest shape) 0. */
static int read_tets(rd *r, const cJSON *c, const kp *p, const jdefaults *dflt, wb_image *g, int32_t *at)
{
    static const char *const keys[] = { "particles", "young", "poisson", "rest_inverse", "rest_volume", "yield", "creep", NULL };
    const cJSON *f[8];
    const int32_t i = ++*at;
    (void)dflt;
    kp pp = { p, "particles", 0 };
    if (jv_get_object(r, c, p, keys, f)) return -1;
    if (!f[0]) return jv_missing(r, c, p, "particles");
    if (!f[1]) return jv_missing(r, c, p, "young");
    int32_t *q4 = &g->tet.ijkl[4 * i];
    if (jv_get_ids(r, f[0], &pp, g->np, 4, "a tet", q4)) return -1;
    wb_tet_def d = wb_tet_default_def();
    if (jv_opt_real(r, f[1], p, "young", &d.young) || jv_opt_real(r, f[2], p, "poisson", &d.poisson) ||
        jv_opt_real(r, f[5], p, "yield", &d.yield) || jv_opt_real(r, f[6], p, "creep", &d.creep))
        return -1;
    /* the core decides what a tet may be (tet.c); its rest shape from the positions
     * only when the file does not give it */
    const wb_fault ft = wb_tet_check(g->np, f[3] ? NULL : g->x, q4, &d);
    if (jv_fault(r, &ft, p, keys, f, 0)) return -1;
    g->tet.young[i] = d.young;
    g->tet.poisson[i] = d.poisson;
    g->tet.plastic[2 * i] = d.yield;
    g->tet.plastic[2 * i + 1] = d.creep;
    if (!f[3] != !f[4]) return jv_fail(r, c, 0, p, "rest_inverse and rest_volume go together");
    if (f[3]) {
        kp vq = { p, "rest_volume", 0 };
        if (jv_opt_vec(r, f[3], p, "rest_inverse", 9, &g->tet.dminv[9 * i]) ||
            jv_opt_real(r, f[4], p, "rest_volume", &g->tet.v0[i]))
            return -1;
        if (!(g->tet.v0[i] > 0) || !isfinite(g->tet.v0[i])) return jv_fail(r, f[4], 0, &vq, "must be > 0");
    } else {
        const wb_real *x = g->x;
        wb_tet_rest_shape(&x[3 * q4[0]], &x[3 * q4[1]], &x[3 * q4[2]], &x[3 * q4[3]], &g->tet.dminv[9 * i],
                          &g->tet.v0[i]); /* checked above: not flat */
    }
    return 0;
}

/* ---- writing (w:save) ------------------------------------------------------------------------ */
/* with their rest state (the exact restore) */
static int write_tets(jw_out *o, const wb_image *g, int first)
{
    FILE *f = o->f;
    for (int32_t i = 0; i < g->tet.n; i++) {
        const int32_t *p = &g->tet.ijkl[4 * i];
        jw_next(o, &first);
        fprintf(f, "    {\"particles\": [%d, %d, %d, %d], \"young\": ", p[0], p[1], p[2], p[3]);
        jw_num(o, g->tet.young[i]);
        jw_key(o, "poisson", g->tet.poisson[i]);
        jw_key(o, "rest_volume", g->tet.v0[i]);
        fputs(", \"rest_inverse\": ", f);
        jw_vec(o, &g->tet.dminv[9 * i], 9);
        jw_plastic(o, &g->tet.plastic[2 * i]);
        fputc('}', f);
    }
    return first;
}

const jtype jt_tet = {
    .key = "tets", .alloc = wb_image_alloc_tets, .read_item = read_tets, .write = write_tets,
};
