/* json_volume.c: volume constraints (core/volume.c) in a particle config: their
 * "volumes" section (docs/formats.md, "Particle configs") */
#include "json.h"

/* "volumes": [ {"particles": [a, b, c, d], "rest": V, "compliance": alpha, "yield": y,
 * "creep": c}, ... ]: volume constraints (the tet's signed volume kept at rest, default the
 * particles' current one; yield and creep: plastic flow of the rest volume, 0 by default) */
static int read_volumes(rd *r, const cJSON *c, const kp *p, const jdefaults *dflt, wb_image *g, int32_t *at)
{
    static const char *const keys[] = { "particles", "rest", "compliance", "yield", "creep", NULL };
    const cJSON *f[6];
    const int32_t i = ++*at;
    (void)dflt;
    kp pp = { p, "particles", 0 };
    if (jv_get_object(r, c, p, keys, f)) return -1;
    if (!f[0]) return jv_missing(r, c, p, "particles");
    int32_t *ijkl = &g->vol.ijkl[4 * i];
    if (jv_get_ids(r, f[0], &pp, g->np, 4, "a volume constraint", ijkl)) return -1;
    wb_volume_def d = wb_volume_default_def();
    d.has_rest = f[1] != NULL;
    if (jv_opt_real(r, f[1], p, "rest", &d.rest) || jv_opt_real(r, f[2], p, "compliance", &d.compliance) ||
        jv_opt_real(r, f[3], p, "yield", &d.yield) || jv_opt_real(r, f[4], p, "creep", &d.creep))
        return -1;
    /* the core decides what a volume constraint may be (volume.c) */
    const wb_fault ft = wb_volume_check(g->np, g->x, ijkl, &d);
    if (jv_fault(r, &ft, p, keys, f, 0)) return -1;
    const wb_real *x = g->x;
    g->vol.rest[i] = d.has_rest ? d.rest
                   : wb_tet_signed_volume(&x[3 * ijkl[0]], &x[3 * ijkl[1]], &x[3 * ijkl[2]], &x[3 * ijkl[3]]);
    g->vol.alpha[i] = d.compliance;
    g->vol.plastic[2 * i] = d.yield;
    g->vol.plastic[2 * i + 1] = d.creep;
    return 0;
}

static int write_volumes(jw_out *o, const wb_image *g, int first)
{
    FILE *f = o->f;
    for (int32_t i = 0; i < g->vol.n; i++) {
        const int32_t *p = &g->vol.ijkl[4 * i];
        jw_next(o, &first);
        fprintf(f, "    {\"particles\": [%d, %d, %d, %d], \"rest\": ", p[0], p[1], p[2], p[3]);
        jw_num(o, g->vol.rest[i]);
        jw_key(o, "compliance", g->vol.alpha[i]);
        jw_plastic(o, &g->vol.plastic[2 * i]);
        fputc('}', f);
    }
    return first;
}

const jtype jt_volume = {
    .key = "volumes", .alloc = wb_image_alloc_volumes, .read_item = read_volumes, .write = write_volumes,
};
