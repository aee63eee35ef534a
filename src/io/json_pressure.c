/* json_pressure.c: pressure constraints (core/pressure.c) in a particle config: their
 * "pressures" section (docs/formats.md, "Particle configs"):
 *
 *   "pressures": [ {"surface": 0, "pressure": 1, "compliance": 0, "rest_volume": 0.5}, ... ]
 *
 * "rest_volume" defaults to the surface's volume at load; w:save writes it for the exact
 * restore. */
#include "json.h"

static int read_pressures(rd *r, const cJSON *c, const kp *p, const jdefaults *dflt, wb_image *g, int32_t *at)
{
    static const char *const keys[] = { "surface", "pressure", "compliance", "rest_volume", NULL };
    const cJSON *f[5];
    const int32_t i = ++*at;
    (void)dflt;
    int64_t s;
    if (jv_get_object(r, c, p, keys, f)) return -1;
    if (!f[0]) return jv_missing(r, c, p, "surface");
    if (g->nsurf == 0) {
        kp q = { p, "surface", 0 };
        return jv_fail(r, f[0], 0, &q, "there are no surfaces");
    }
    wb_pressure_def d = { 1, 0 };
    wb_real v0 = -1;
    if (jv_opt_int(r, f[0], p, "surface", 0, g->nsurf - 1, &s) || jv_opt_real(r, f[1], p, "pressure", &d.pressure) ||
        jv_opt_real(r, f[2], p, "compliance", &d.compliance) || jv_opt_real(r, f[3], p, "rest_volume", &v0))
        return -1;
    /* the core decides the options (pressure.c); the rest volume is the file's state */
    const wb_fault ft = wb_pressure_def_fault(&d);
    if (jv_fault(r, &ft, p, keys, f, 0)) return -1;
    kp vq = { p, "rest_volume", 0 };
    if (f[3] && !(v0 > 0)) return jv_fail(r, f[3], 0, &vq, "must be > 0");
    g->pr.surface[i] = (int32_t)s;
    g->pr.pressure[i] = d.pressure;
    g->pr.alpha[i] = d.compliance;
    g->pr.v0[i] = v0; /* < 0: the volume at load */
    return 0;
}

/* ---- writing (w:save) ------------------------------------------------------------------------ */
/* with the rest volumes */
static int write_pressures(jw_out *o, const wb_image *g, int first)
{
    FILE *f = o->f;
    for (int32_t k = 0; k < g->pr.n; k++) {
        jw_next(o, &first);
        fprintf(f, "    {\"surface\": %d, \"pressure\": ", g->pr.surface[k]);
        jw_num(o, g->pr.pressure[k]);
        jw_key(o, "compliance", g->pr.alpha[k]);
        jw_key(o, "rest_volume", g->pr.v0[k]);
        fputc('}', f);
    }
    return first;
}

const jtype jt_pressure = {
    .key = "pressures", .alloc = wb_image_alloc_pressure,
    .read_item = read_pressures, .write = write_pressures,
};
