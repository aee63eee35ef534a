/* json_distance.c: distance constraints (core/distance.c) in a particle config: their
 * entries of "constraints" (docs/formats.md, "Particle configs"):
 *
 *   {"type": "distance", "particles": [a, b], "rest": r, "compliance": 0, "damping": 0,
 *    "yield": 0, "creep": 0, "break_strain": 0, "break_force": 0, "broken": false}
 *
 * Options not given are the file's "defaults"; rest defaults to the particles' distance.
 * They fill the distance slots in order (the live ones of the snapshot's "distance_slots";
 * every slot in a plain config). */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "json.h"

/* *slot: the last slot filled (-1 before the first). An entry without a string "type"
 * comes here too (json.c), so that its message is a distance's */
static int read_distance(rd *r, const cJSON *c, const kp *p, const jdefaults *d, wb_image *g, int32_t *slot)
{
    static const char *const keys[] = { "type", "particles", "rest", "compliance", "damping", "yield", "creep",
                                        "break_strain", "broken", "break_force", NULL };
    const cJSON *f[11];
    if (jv_get_object(r, c, p, keys, f)) return -1;
    if (!f[0]) return jv_missing(r, c, p, "type");
    if (!f[1]) return jv_missing(r, c, p, "particles");
    kp tp = { p, "type", 0 }, pp = { p, "particles", 0 };
    const char *type = "";
    /* a string names the type it is read as (json.c): here, a type that is not one */
    if (jv_get_string(r, f[0], &tp, &type)) return -1;
    int32_t ab[2];
    if (jv_get_ids(r, f[1], &pp, g->np, 2, "a distance constraint", ab)) return -1;
    do ++*slot; while (!(g->dist.gen[*slot] & 1u));
    wb_distance_def l = d->link;
    bool broken = false;
    /* a rest the file gives is >= 0: a negative one would read as "their distance" */
    if (jv_opt_nonneg(r, f[2], p, "rest", &l.rest) || jv_opt_real(r, f[3], p, "compliance", &l.compliance) ||
        jv_opt_real(r, f[4], p, "damping", &l.damping) || jv_opt_real(r, f[5], p, "yield", &l.yield) ||
        jv_opt_real(r, f[6], p, "creep", &l.creep) || jv_opt_real(r, f[7], p, "break_strain", &l.break_strain) ||
        jv_opt_real(r, f[9], p, "break_force", &l.break_force))
        return -1;
    if (f[8]) {
        kp q = { p, "broken", 0 };
        if (jv_get_bool(r, f[8], &q, &broken)) return -1;
    }
    /* the core decides what a distance constraint may be (wb_distance_check) */
    const wb_fault ft = wb_distance_check(g->np, g->x, ab[0], ab[1], &l);
    if (jv_fault(r, &ft, p, keys, f, 1)) return -1;
    if (l.rest < 0) {
        const wb_real *xa = &g->x[3 * ab[0]], *xb = &g->x[3 * ab[1]];
        wb_real dx[3] = { xb[0] - xa[0], xb[1] - xa[1], xb[2] - xa[2] };
        l.rest = sqrt(dx[0] * dx[0] + dx[1] * dx[1] + dx[2] * dx[2]);
    }
    const int32_t s = *slot;
    g->dist.ij[2 * s] = ab[0];
    g->dist.ij[2 * s + 1] = ab[1];
    g->dist.alpha[s] = l.compliance;
    g->dist.beta[s] = l.damping;
    g->dist.yield[s] = l.yield;
    g->dist.creep[s] = l.creep;
    g->dist.break_strain[s] = l.break_strain;
    g->dist.bforce[s] = l.break_force;
    g->dist.rest[s] = l.rest;
    g->dist.broken[s] = broken;
    return 0;
}

/* ---- writing (w:save) ------------------------------------------------------------------------ */
/* the live slots, in slot order */
static int write_distances(jw_out *o, const wb_image *g, int first)
{
    FILE *f = o->f;
    for (int32_t i = 0; i < g->dist.n; i++) {
        if (!(g->dist.gen[i] & 1u)) continue;
        jw_next(o, &first);
        fprintf(f, "    {\"type\": \"distance\", \"particles\": [%d, %d], \"rest\": ", g->dist.ij[2 * i],
                g->dist.ij[2 * i + 1]);
        jw_num(o, g->dist.rest[i]);
        jw_key(o, "compliance", g->dist.alpha[i]);
        jw_key(o, "damping", g->dist.beta[i]);
        jw_key(o, "yield", g->dist.yield[i]);
        jw_key(o, "creep", g->dist.creep[i]);
        jw_key(o, "break_strain", g->dist.break_strain[i]);
        if (g->dist.bforce[i] > 0) { /* only when set: configs without it read as before */
            jw_key(o, "break_force", g->dist.bforce[i]);
        }
        fprintf(f, ", \"broken\": %s}", g->dist.broken[i] ? "true" : "false");
    }
    return first;
}

/* ---- the file's "defaults": a link's options ------------------------------------------------ */
static const char *const default_keys[] = { "compliance", "damping", "yield", "creep", "break_strain", "break_force",
                                            NULL };

static int read_defaults(rd *r, const cJSON *const f[], const kp *p, jdefaults *d)
{
    wb_distance_def *l = &d->link;
    *l = wb_distance_default_def();
    if (!p) return 0;
    if (jv_opt_real(r, f[0], p, "compliance", &l->compliance) || jv_opt_real(r, f[1], p, "damping", &l->damping) ||
        jv_opt_real(r, f[2], p, "yield", &l->yield) || jv_opt_real(r, f[3], p, "creep", &l->creep) ||
        jv_opt_real(r, f[4], p, "break_strain", &l->break_strain) || jv_opt_real(r, f[5], p, "break_force", &l->break_force))
        return -1;
    /* the options as the core decides them (wb_distance_check, of two particles: the
     * options alone, so the fault is an option's) */
    const wb_fault ft = wb_distance_check(2, NULL, 0, 1, l);
    return jv_fault(r, &ft, p, default_keys, f, 0);
}

/* ---- the snapshot's "distance_slots": generations and free slots ------------------------------ */
static int scan_slots(rd *r, const cJSON *it, const kp *up, int32_t nentries, jslots *s)
{
    static const char *const keys[] = { "generations", "free", NULL };
    const cJSON *g[3];
    s->n = nentries; /* a plain config: a slot per entry, all live */
    if (!it) return 0;
    kp q = { up, "distance_slots", 0 };
    if (jv_get_object(r, it, &q, keys, g)) return -1;
    if (!g[0]) return jv_missing(r, it, &q, "generations");
    if (!g[1]) return jv_missing(r, it, &q, "free");
    kp a = { &q, "generations", 0 }, b = { &q, "free", 0 };
    if (jv_get_array(r, g[0], &a, WB_MAX_CONSTRAINTS, &s->n) || jv_get_array(r, g[1], &b, WB_MAX_CONSTRAINTS, &s->nfree))
        return -1;
    s->gen = g[0];
    s->free = g[1];
    return 0;
}

static int read_slots(rd *r, const jslots *s, const kp *up, int32_t nentries, wb_image *g)
{
    if (!s->gen) return 0;
    kp ds = { up, "distance_slots", 0 }, a = { &ds, "generations", 0 }, b = { &ds, "free", 0 };
    int32_t live;
    if (jv_read_generations(r, s->gen, &a, g->dist.gen, &live)) return -1;
    if (live != nentries)
        return jv_fail(r, s->gen, 0, &a, "%d live slots, but \"constraints\" has %d entries", live, nentries);
    int32_t k = 0;
    /* a mark per slot, so a long free list is checked for repeats in linear time */
    uint8_t *seen = s->nfree > 0 ? calloc((size_t)(s->n > 0 ? s->n : 1), 1) : NULL;
    if (s->nfree > 0 && !seen) return jv_fail(r, s->free, 0, &b, "out of memory");
    int bad = 0;
    for (const cJSON *c = s->free->child; c && !bad; c = c->next, k++) {
        kp e = { &b, NULL, k };
        int64_t slot;
        if (jv_get_int(r, c, &e, 0, s->n > 0 ? s->n - 1 : 0, &slot)) bad = -1;
        else if (s->n == 0 || (g->dist.gen[slot] & 1u)) bad = jv_fail(r, c, 0, &e, "slot %lld is live, not free", (long long)slot);
        else if (seen[slot]++) bad = jv_fail(r, c, 0, &e, "slot %lld is listed twice", (long long)slot);
        else g->dist.free_slots[k] = (int32_t)slot;
    }
    free(seen);
    if (bad) return -1;
    if (s->n - live != s->nfree)
        return jv_fail(r, s->free, 0, &b, "%d free slots listed, but %d slots are dead", s->nfree, s->n - live);
    return 0;
}

static void write_slots(FILE *f, const wb_image *g)
{
    fputs(",\n    \"distance_slots\": {\"generations\": ", f);
    jw_ints(f, "      ", g->dist.gen, NULL, g->dist.n);
    fputs(", \"free\": ", f);
    jw_ints(f, "      ", NULL, g->dist.free_slots, g->dist.nfree);
    fputs("}", f);
}

/* no alloc: its arrays are the image's distance slots (wb_image_alloc), which the
 * snapshot's slot table describes */
const jtype jt_distance = {
    .entry = "distance",
    .read_item = read_distance,
    .write = write_distances,
    .default_keys = default_keys,
    .read_defaults = read_defaults,
    .slots_key = "distance_slots",
    .scan_slots = scan_slots,
    .read_slots = read_slots,
    .write_slots = write_slots,
};
