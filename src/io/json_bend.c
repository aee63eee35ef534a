/* json_bend.c: bends (core/bend.c) in a particle config: their entries of "constraints"
 * (docs/formats.md, "Particle configs"):
 *
 *   {"type": "bend", "particles": [p1, p2, p3, p4], "rest": angle, "compliance": 0,
 *    "damping": 0, "break_torque": 0, "broken": false}
 *
 * (hinge p1 p2, wings p3 p4); rest defaults to the angle the particles make. */
#include <math.h>

#include "json.h"

/* *at: the last bend read (-1 before the first) */
static int read_bend(rd *r, const cJSON *c, const kp *p, const jdefaults *dflt, wb_image *g, int32_t *at)
{
    static const char *const keys[] = { "type", "particles", "rest", "compliance", "damping", "break_torque", "broken", NULL };
    const cJSON *f[8];
    const int32_t i = ++*at;
    (void)dflt; /* the file's defaults are a link's */
    if (jv_get_object(r, c, p, keys, f)) return -1;
    if (!f[1]) return jv_missing(r, c, p, "particles");
    kp pp = { p, "particles", 0 };
    int32_t n;
    if (jv_get_array(r, f[1], &pp, 16, &n)) return -1;
    if (n != 4) return jv_fail(r, f[1], 0, &pp, "a bend joins 4 particles (hinge p1 p2, wings p3 p4), got %d", n);
    int32_t *q = &g->bend.ij[4 * i];
    if (jv_get_ids(r, f[1], &pp, g->np, 4, "a bend", q)) return -1;
    wb_bend_def d = wb_bend_default_def();
    if (jv_opt_real(r, f[2], p, "rest", &d.rest) || jv_opt_real(r, f[3], p, "compliance", &d.compliance) ||
        jv_opt_real(r, f[4], p, "damping", &d.damping) || jv_opt_real(r, f[5], p, "break_torque", &d.break_torque))
        return -1;
    bool broken = false;
    if (f[6]) {
        kp bp = { p, "broken", 0 };
        if (jv_get_bool(r, f[6], &bp, &broken)) return -1;
    }
    /* the core decides what a bend may be (bend.c) */
    const wb_fault ft = wb_bend_check(g->np, g->x, q, &d);
    if (jv_fault(r, &ft, p, keys, f, 1)) return -1;
    if (isnan(d.rest)) wb_dihedral_angle(&g->x[3 * q[0]], &g->x[3 * q[1]], &g->x[3 * q[2]], &g->x[3 * q[3]], &d.rest);
    g->bend.alpha[i] = d.compliance;
    g->bend.beta[i] = d.damping;
    g->bend.rest[i] = d.rest;
    g->bend.btorque[i] = d.break_torque;
    g->bend.broken[i] = broken;
    return 0;
}

/* ---- writing (w:save) ------------------------------------------------------------------------ */
static int write_bends(jw_out *o, const wb_image *g, int first)
{
    FILE *f = o->f;
    for (int32_t i = 0; i < g->bend.n; i++) {
        const int32_t *p = &g->bend.ij[4 * i];
        jw_next(o, &first);
        fprintf(f, "    {\"type\": \"bend\", \"particles\": [%d, %d, %d, %d], \"rest\": ", p[0], p[1], p[2], p[3]);
        jw_num(o, g->bend.rest[i]);
        jw_key(o, "compliance", g->bend.alpha[i]);
        jw_key(o, "damping", g->bend.beta[i]);
        if (g->bend.btorque[i] > 0) { /* only when set: configs without it read as before */
            jw_key(o, "break_torque", g->bend.btorque[i]);
        }
        if (g->bend.broken[i]) fputs(", \"broken\": true", f);
        fputc('}', f);
    }
    return first;
}

const jtype jt_bend = {
    .entry = "bend", .alloc = wb_image_alloc_bends, .read_item = read_bend, .write = write_bends,
};
