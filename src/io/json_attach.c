/* json_attach.c: attachments (core/attach.c) in a particle config: their "attachments"
 * section (docs/formats.md, "Particle configs"):
 *
 *   "attachments": [ {"particle": 3, "collider": 0 | "rigid": 0, "point": [x,y,z], "compliance": 0}, ... ]
 *
 * "collider" counts the file's "colliders" entries from 0, "rigid" its "rigids" entries
 * (removed slots included, as w:save writes them). "point" (in the target's frame)
 * defaults to where the particle is, as w:attach does; w:save writes it. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "json.h"

/* v in the frame of a pose with rotation q (w, x, y, z), unit: q* v q */
static void rotate_inv(const wb_real q[4], const wb_real v[3], wb_real out[3])
{
    const wb_real u[3] = { -q[1], -q[2], -q[3] }, s = q[0];
    /* v + 2 u x (u x v + s v) */
    const wb_real t[3] = { u[1] * v[2] - u[2] * v[1] + s * v[0], u[2] * v[0] - u[0] * v[2] + s * v[1],
                           u[0] * v[1] - u[1] * v[0] + s * v[2] };
    out[0] = v[0] + 2 * (u[1] * t[2] - u[2] * t[1]);
    out[1] = v[1] + 2 * (u[2] * t[0] - u[0] * t[2]);
    out[2] = v[2] + 2 * (u[0] * t[1] - u[1] * t[0]);
}

static int read_attach_items(rd *r, const cJSON *arr, const kp *parent, const char *const *keys, wb_image *g,
                     const int32_t *live, int32_t ncol);

static int read_attachments(rd *r, const cJSON *arr, wb_image *g)
{
    static const char *const keys[] = { "particle", "collider", "point", "compliance", "rigid", NULL };
    kp top = { NULL, "attachments", 0 };
    int32_t n = 0, ncol = 0;
    if (!arr) return 0;
    if (jv_get_array(r, arr, &top, WB_MAX_CONSTRAINTS, &n)) return -1;
    if (wb_image_alloc_attach(g, n) != WB_OK) return jv_fail(r, arr, 0, &top, "out of memory");
    /* the live collider slots in order, once (a scan per attachment is na x nc) */
    int32_t *live = malloc(sizeof *live * (size_t)(g->nc > 0 ? g->nc : 1));
    if (!live) return jv_fail(r, arr, 0, &top, "out of memory");
    for (int32_t c = 0; c < g->nc; c++)
        if (g->c_gen[c] & 1u) live[ncol++] = c;
    const int rc = read_attach_items(r, arr, &top, keys, g, live, ncol);
    free(live);
    return rc;
}

static int read_attach_items(rd *r, const cJSON *arr, const kp *parent, const char *const *keys, wb_image *g,
                     const int32_t *live, int32_t ncol)
{
    int32_t i = 0;
    kp top = *parent;
    for (const cJSON *c = arr->child; c; c = c->next, i++) {
        const cJSON *f[5];
        kp p = { &top, NULL, i };
        int64_t pid, cid;
        if (jv_get_object(r, c, &p, keys, f)) return -1;
        if (!f[0]) return jv_missing(r, c, &p, "particle");
        const int rigid = f[4] != NULL;
        const char *tkey = rigid ? "rigid" : "collider";
        const cJSON *tf = rigid ? f[4] : f[1];
        kp tq = { &p, tkey, 0 };
        if (rigid && f[1]) return jv_fail(r, f[4], 0, &tq, "give collider or rigid, not both");
        if (!tf) return jv_fail(r, c, 0, &p, "missing key 'collider' (or 'rigid')");
        if (g->np == 0) {
            kp q = { &p, "particle", 0 };
            return jv_fail(r, f[0], 0, &q, "there are no particles");
        }
        const int32_t ntarget = rigid ? g->nrb : ncol;
        if (ntarget == 0) return jv_fail(r, tf, 0, &tq, rigid ? "there are no rigid bodies" : "there are no colliders");
        wb_real a = 0;
        if (jv_opt_int(r, f[0], &p, "particle", 0, g->np - 1, &pid) ||
            jv_opt_int(r, tf, &p, tkey, 0, ntarget - 1, &cid) || jv_opt_real(r, f[3], &p, "compliance", &a))
            return -1;
        /* the core decides the compliance (attach.c) */
        const wb_fault ft = wb_attach_def_fault(a);
        if (jv_fault(r, &ft, &p, keys, f, 0)) return -1;
        /* a collider: the cid-th live slot; a rigid body: the cid-th entry of "rigids" */
        const int32_t slot = rigid ? (int32_t)cid : live[cid];
        if (rigid && !(g->rb_gen[slot] & 1u)) return jv_fail(r, tf, 0, &tq, "that rigid body was removed");
        wb_real *local = &g->att.local[3 * i];
        if (f[2]) {
            if (jv_opt_vec(r, f[2], &p, "point", 3, local)) return -1;
        } else {
            const wb_real *tp = rigid ? g->rb[slot].x : g->c[slot].p, *tqr = rigid ? g->rb[slot].q : g->c[slot].q;
            const wb_real *x = &g->x[3 * pid];
            const wb_real d[3] = { x[0] - tp[0], x[1] - tp[1], x[2] - tp[2] };
            wb_real q[4];
            const wb_real qn = sqrt(tqr[0] * tqr[0] + tqr[1] * tqr[1] + tqr[2] * tqr[2] + tqr[3] * tqr[3]);
            for (int k = 0; k < 4; k++) q[k] = tqr[k] / qn;
            rotate_inv(q, d, local);
            if (!isfinite(local[0]) || !isfinite(local[1]) || !isfinite(local[2])) {
                kp q2 = { &p, "particle", 0 };
                return jv_fail(r, f[0], 0, &q2, rigid ? "the particle is too far from the body"
                                                      : "the particle is too far from the collider");
            }
        }
        g->att.p[i] = (int32_t)pid;
        g->att.kind[i] = rigid; /* WB_TARGET_COLLIDER = 0, WB_TARGET_RIGID = 1 (attach.h) */
        g->att.target[i] = slot;
        g->att.alpha[i] = a;
    }
    return 0;
}

/* ---- writing (w:save) ------------------------------------------------------------------------ */
/* An attachment names its collider by its place among the written (live) colliders */
static int write_attachments(jw_out *o, const wb_image *g, int first)
{
    FILE *f = o->f;
    const wb_image_attach *a = &g->att;
    /* slot -> its place among the live ones, once (a count per attachment is na x nc) */
    int32_t *rank = a->n ? malloc(sizeof *rank * (size_t)(g->nc > 0 ? g->nc : 1)) : NULL;
    if (a->n && !rank) {
        o->nomem = 1;
        return first;
    }
    for (int32_t s = 0, r = 0; rank && s < g->nc; s++) {
        rank[s] = r;
        r += (int32_t)(g->c_gen[s] & 1u);
    }
    for (int32_t k = 0; k < a->n; k++) {
        /* a rigid body by its slot: w:save writes every slot of "rigids" */
        const int rigid = a->kind[k] == 1;
        jw_next(o, &first);
        fprintf(f, "    {\"particle\": %d, \"%s\": %d, \"point\": ", a->p[k], rigid ? "rigid" : "collider",
                rigid ? a->target[k] : rank[a->target[k]]);
        jw_vec(o, &a->local[3 * k], 3);
        jw_key(o, "compliance", a->alpha[k]);
        fputc('}', f);
    }
    free(rank);
    return first;
}

const jtype jt_attach = { .key = "attachments", .read = read_attachments, .write = write_attachments };
