/* json_grab.c: grabs (core/grab.c) in a particle config: their "grabs" section
 * (docs/formats.md, "Particle configs"):
 *
 *   "grabs": [ {"particle": 7 | "rigid": 0, "at": [x,y,z], "target": [x,y,z], "from": [x,y,z],
 *                "compliance": 0}, ... ]
 *
 * "rigid" counts the file's "rigids" entries (removed slots included, as w:save writes
 * them). "from" (where the next step's sweep of the target starts) defaults to the target;
 * w:save writes it. A rigid body's grab names its body as attachments do; "at" (its frame)
 * defaults to the centre. */
#include <string.h>

#include "json.h"

static int read_grabs(rd *r, const cJSON *c, const kp *p, const jdefaults *dflt, wb_image *g, int32_t *at)
{
    static const char *const keys[] = { "particle", "target", "from", "compliance", "rigid", "at", NULL };
    const cJSON *f[6];
    const int32_t i = ++*at;
    (void)dflt;
    int64_t pid;
    if (jv_get_object(r, c, p, keys, f)) return -1;
    const int rigid = f[4] != NULL;
    kp rq = { p, "rigid", 0 }, aq = { p, "at", 0 };
    if (rigid && f[0]) return jv_fail(r, f[4], 0, &rq, "give particle or rigid, not both");
    if (!rigid && f[5]) return jv_fail(r, f[5], 0, &aq, "is for a rigid body's grab (with \"rigid\")");
    if (!f[0] && !rigid) return jv_fail(r, c, 0, p, "missing key 'particle' (or 'rigid')");
    if (!f[1]) return jv_missing(r, c, p, "target");
    wb_real *loc = &g->grab.local[3 * i];
    if (rigid) {
        if (g->nrb == 0) return jv_fail(r, f[4], 0, &rq, "there are no rigid bodies");
        if (jv_opt_int(r, f[4], p, "rigid", 0, g->nrb - 1, &pid)) return -1;
        if (!(g->rb_gen[pid] & 1u)) return jv_fail(r, f[4], 0, &rq, "that rigid body was removed");
        if (f[5] && jv_opt_vec(r, f[5], p, "at", 3, loc)) return -1;
    } else if (g->np == 0) {
        kp q = { p, "particle", 0 };
        return jv_fail(r, f[0], 0, &q, "there are no particles");
    }
    wb_real a = 0, *t = &g->grab.target[3 * i], *fr = &g->grab.from[3 * i];
    if ((!rigid && jv_opt_int(r, f[0], p, "particle", 0, g->np - 1, &pid)) || jv_opt_vec(r, f[1], p, "target", 3, t) ||
        jv_opt_real(r, f[3], p, "compliance", &a))
        return -1;
    /* the core decides the compliance (grab.c) */
    const wb_fault ft = wb_grab_def_fault(a);
    if (jv_fault(r, &ft, p, keys, f, 0)) return -1;
    if (f[2]) {
        if (jv_opt_vec(r, f[2], p, "from", 3, fr)) return -1;
    } else {
        memcpy(fr, t, 3 * sizeof *fr);
    }
    g->grab.p[i] = (int32_t)pid;
    g->grab.kind[i] = rigid; /* WB_GRAB_PARTICLE = 0, WB_GRAB_RIGID = 1 (grab.h) */
    g->grab.alpha[i] = a;
    return 0;
}

/* ---- writing (w:save) ------------------------------------------------------------------------ */
static int write_grabs(jw_out *o, const wb_image *g, int first)
{
    FILE *f = o->f;
    const wb_image_grab *gr = &g->grab;
    for (int32_t k = 0; k < gr->n; k++) {
        /* a rigid body by its slot, as attachments name theirs */
        const int rigid = gr->kind[k] == 1;
        jw_next(o, &first);
        fprintf(f, "    {\"%s\": %d, ", rigid ? "rigid" : "particle", gr->p[k]);
        if (rigid) {
            fputs("\"at\": ", f);
            jw_vec(o, &gr->local[3 * k], 3);
            fputs(", ", f);
        }
        fputs("\"target\": ", f);
        jw_vec(o, &gr->target[3 * k], 3);
        fputs(", \"from\": ", f);
        jw_vec(o, &gr->from[3 * k], 3);
        jw_key(o, "compliance", gr->alpha[k]);
        fputc('}', f);
    }
    return first;
}

const jtype jt_grab = {
    .key = "grabs", .alloc = wb_image_alloc_grab, .read_item = read_grabs, .write = write_grabs,
};
