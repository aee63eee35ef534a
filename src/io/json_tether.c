/* json_tether.c: tethers (core/tether.c) in a particle config: their "tethers" section
 * (docs/formats.md, "Particle configs") */
#include "json.h"

/* "tethers": [ {"particles": [p, q], "length": l, "compliance": alpha}, ... ]: long-range
 * attachments (length: the particles' distance by default; compliance 0 by default) */
static int read_tethers(rd *r, const cJSON *c, const kp *p, const jdefaults *dflt, wb_image *g, int32_t *at)
{
    static const char *const keys[] = { "particles", "length", "compliance", NULL };
    const cJSON *f[3];
    const int32_t i = ++*at;
    (void)dflt;
    kp pp = { p, "particles", 0 };
    if (jv_get_object(r, c, p, keys, f)) return -1;
    if (!f[0]) return jv_missing(r, c, p, "particles");
    int32_t *ij = &g->teth.ij[2 * i];
    if (jv_get_ids(r, f[0], &pp, g->np, 2, "a tether", ij)) return -1;
    wb_tether_def td = wb_tether_default_def();
    td.has_length = f[1] != NULL;
    if (jv_opt_real(r, f[1], p, "length", &td.length) || jv_opt_real(r, f[2], p, "compliance", &td.compliance))
        return -1;
    /* the core decides what a tether may be (tether.c) */
    const wb_fault ft = wb_tether_check(g->np, g->x, ij[0], ij[1], &td);
    if (jv_fault(r, &ft, p, keys, f, 0)) return -1;
    const wb_real *x = g->x;
    wb_real d[3];
    v3_sub(d, &x[3 * ij[0]], &x[3 * ij[1]]);
    g->teth.len[i] = td.has_length ? td.length : v3_len(d);
    g->teth.alpha[i] = td.compliance;
    return 0;
}

static int write_tethers(jw_out *o, const wb_image *g, int first)
{
    FILE *f = o->f;
    for (int32_t i = 0; i < g->teth.n; i++) {
        jw_next(o, &first);
        fprintf(f, "    {\"particles\": [%d, %d], \"length\": ", g->teth.ij[2 * i], g->teth.ij[2 * i + 1]);
        jw_num(o, g->teth.len[i]);
        jw_key(o, "compliance", g->teth.alpha[i]);
        fputc('}', f);
    }
    return first;
}

const jtype jt_tether = {
    .key = "tethers", .alloc = wb_image_alloc_tethers, .read_item = read_tethers, .write = write_tethers,
};
