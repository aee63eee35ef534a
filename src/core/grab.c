/* grab.c: grabs (a type of the table in ctype.c, so all of it is here).
 *
 * The scripted form of dragging a particle with the mouse: particle p is pulled to a
 * target point the script moves. A rigid body is grabbed at a point fixed in its frame
 * (`local`): the same constraint with the body's response at that point in place of the
 * particle's 1/m (wb__rigid_point_response, solved in 3D as attachments to bodies are),
 * so a box grabbed off its centre swings about the grab point. XPBD with the vector constraint C = x - t, as
 * attach.c: dlambda = (-C - alpha~ lambda) / (w + alpha~), x += w dlambda. Compliance 0
 * puts the particle exactly on the target at the end of every substep; a compliant grab
 * is a zero-length spring of stiffness 1/alpha (F = -C/alpha, U = |C|^2 / (2 alpha)).
 *
 * A target moved between steps is swept to over the next step (from the last step's
 * target, linearly, substep by substep, as kinematic colliders move), so a jump of the
 * mouse gives the particle the speed of the move over the frame, not over one substep.
 *
 * Model: particle, compliance. State: target and sweep start. Cache: multipliers and the
 * substep counter. Serial pass in slot order: deterministic for any thread count. */
#include <assert.h>

#include "attach.h"
#include "ctype.h"
#include "grab.h"
#include "shape_match.h"
#include "snapshot.h"

#define GRAB_BYTES (sizeof(int32_t) + 1 + 2 * sizeof(uint32_t) + 13 * sizeof(wb_real))

static int live(const wb_grabs *g, int32_t s) { return (g->gen[s] & 1u) != 0; }

wb_status wb__grab_reserve(wb_world *w, int64_t extra)
{
    wb_grabs *g = w->grab;
    if (!g) {
        g = calloc(1, sizeof *g);
        if (!g) return WB_ERR_NOMEM;
        w->grab = g;
    }
    const int64_t need = g->n + extra;
    if (need > WB_MAX_CONSTRAINTS) return WB_ERR_LIMIT;
    if (need <= g->cap) return WB_OK;
    const int32_t cap = wb__grown_cap(g->cap, need, 16);
    if (!wb__charge(w, &g->charged, (size_t)cap * GRAB_BYTES)) return WB_ERR_NOMEM;
    const wb_soa arr[] = {
        { (void **)&g->p, sizeof(int32_t) }, { (void **)&g->alpha, sizeof(wb_real) },
        { (void **)&g->kind, 1 }, { (void **)&g->tgen, sizeof(uint32_t) }, { (void **)&g->local, 3 * sizeof(wb_real) },
        { (void **)&g->gen, sizeof(uint32_t) }, { (void **)&g->target, 3 * sizeof(wb_real) },
        { (void **)&g->from, 3 * sizeof(wb_real) }, { (void **)&g->lambda, 3 * sizeof(wb_real) },
    };
    if (WB_SOA_RESIZE(arr, cap) != WB_OK) return WB_ERR_NOMEM;
    g->cap = cap;
    return WB_OK;
}

static void fill(const wb_world *w, wb_grabs *g, int32_t s, int32_t p, int kind, const wb_real local[3],
                 const wb_real target[3], const wb_real from[3], wb_real alpha)
{
    g->p[s] = p;
    g->kind[s] = (uint8_t)kind;
    g->tgen[s] = kind == WB_GRAB_RIGID ? w->rb->gen[p] : 0;
    if (local) v3_copy(&g->local[3 * s], local);
    else v3_set(&g->local[3 * s], 0, 0, 0);
    g->alpha[s] = alpha;
    v3_copy(&g->target[3 * s], target);
    v3_copy(&g->from[3 * s], from);
    v3_set(&g->lambda[3 * s], 0, 0, 0);
    g->nlive++;
}

/* a new live slot after the last one (snapshots restore the live slots in order) */
void wb__grab_put(wb_world *w, int32_t p, int kind, const wb_real local[3], const wb_real target[3],
                  const wb_real from[3], wb_real alpha)
{
    wb_grabs *g = w->grab;
    assert(g && g->n < g->cap); /* contract: reserved first */
    const int32_t s = g->n++;
    fill(w, g, s, p, kind, local, target, from, alpha);
    g->gen[s] = 1;
}

static int fin3(const wb_real *v) { return isfinite(v[0]) && isfinite(v[1]) && isfinite(v[2]); }

/* a new grab of particle p, or of body slot p at local point `local` */
static wb_grab_id grab_new(wb_world *w, int32_t p, int kind, const wb_real local[3], const wb_real target[3],
                           wb_real compliance, wb_status *status)
{
    wb_grab_id none = { 0, 0 };
    wb_grabs *g = w->grab;
    int32_t s = -1;
    for (int32_t i = g ? g->free_hint : 0; g && i < g->n && s < 0; i++) /* no dead slot below the hint */
        if (!live(g, i)) s = i;
    if (g) g->free_hint = s < 0 ? g->n : s + 1;
    /* a new grab starts at its target: it pulls from the first substep on */
    if (s < 0) {
        wb_status st = wb__grab_reserve(w, 1);
        if (st != WB_OK) { *status = st; return none; }
        wb__grab_put(w, p, kind, local, target, target, compliance);
        g = w->grab;
        s = g->n - 1;
    } else {
        fill(w, g, s, p, kind, local, target, target, compliance);
        g->gen[s]++; /* even -> odd: live, old handles of the slot stay stale */
    }
    *status = WB_OK;
    wb_grab_id id = { (uint32_t)s + 1, g->gen[s] };
    return id;
}

wb_fault wb_grab_def_fault(wb_real compliance)
{
    return !(compliance >= 0) || !isfinite(compliance) ? WB_FAULT_KEY("compliance", "must be >= 0 (m/N)") : WB_NO_FAULT;
}

wb_grab_id wb_grab_add(wb_world *w, int32_t p, const wb_real target[3], wb_real compliance, wb_status *status)
{
    wb_grab_id none = { 0, 0 };
    wb_status dummy;
    if (!status) status = &dummy;
    const char *err = wb_grab_def_fault(compliance).msg;
    if (!err) err = p < 0 || p >= w->m.np ? "particle out of range"
                    : !fin3(target) ? "target must be finite" : NULL;
    if (err) {
        wb__set_error("%s", err);
        *status = WB_ERR_ARG;
        return none;
    }
    return grab_new(w, p, WB_GRAB_PARTICLE, NULL, target, compliance, status);
}

wb_grab_id wb_grab_rigid(wb_world *w, wb_rigid_id r, const wb_real local[3], const wb_real target[3],
                         wb_real compliance, wb_status *status)
{
    wb_grab_id none = { 0, 0 };
    wb_status dummy;
    if (!status) status = &dummy;
    static const wb_real centre[3] = { 0, 0, 0 };
    if (!local) local = centre;
    const char *err = wb_grab_def_fault(compliance).msg;
    if (!err) err = !wb_rigid_valid(w, r) ? "rigid body removed"
                    : !fin3(local) ? "at must be finite"
                    : !fin3(target) ? "target must be finite" : NULL;
    if (err) {
        wb__set_error("%s", err);
        *status = WB_ERR_ARG;
        return none;
    }
    return grab_new(w, (int32_t)r.index - 1, WB_GRAB_RIGID, local, target, compliance, status);
}

static int32_t slot_of(const wb_world *w, wb_grab_id id)
{
    const wb_grabs *g = w->grab;
    if (!g || id.index == 0 || id.index > (uint32_t)g->n) return -1;
    const int32_t s = (int32_t)id.index - 1;
    return live(g, s) && g->gen[s] == id.gen ? s : -1;
}

/* live, and its body too (a grab of a removed body is over) */
bool wb_grab_valid(const wb_world *w, wb_grab_id id)
{
    const int32_t s = slot_of(w, id);
    return s >= 0 && wb__grab_active(w, w->grab, s);
}

#define SLOT(w, id) (assert(slot_of((w), (id)) >= 0), (int32_t)(id).index - 1)

/* the grabbed point now: the particle, or the body's point */
static void grabbed_point(const wb_world *w, const wb_grabs *g, int32_t s, wb_real out[3])
{
    if (g->kind[s] == WB_GRAB_RIGID) wb__rigid_to_world(w, g->p[s], &g->local[3 * s], out);
    else v3_copy(out, &w->s.x[3 * g->p[s]]);
}

void wb_grab_release(wb_world *w, wb_grab_id id)
{
    const int32_t s = SLOT(w, id);
    w->grab->gen[s]++;
    w->grab->nlive--;
    if (s < w->grab->free_hint) w->grab->free_hint = s;
}

void wb_grab_move(wb_world *w, wb_grab_id id, const wb_real target[3])
{
    assert(fin3(target));
    v3_copy(&w->grab->target[3 * SLOT(w, id)], target);
}

void wb_grab_target(const wb_world *w, wb_grab_id id, wb_real out[3]) { v3_copy(out, &w->grab->target[3 * SLOT(w, id)]); }
int32_t wb_grab_particle(const wb_world *w, wb_grab_id id)
{
    const int32_t s = SLOT(w, id);
    return w->grab->kind[s] == WB_GRAB_RIGID ? -1 : w->grab->p[s];
}

wb_rigid_id wb_grab_body(const wb_world *w, wb_grab_id id)
{
    const int32_t s = SLOT(w, id);
    const wb_grabs *g = w->grab;
    wb_rigid_id r = { 0, 0 };
    if (g->kind[s] == WB_GRAB_RIGID) { r.index = (uint32_t)g->p[s] + 1; r.gen = g->tgen[s]; }
    return r;
}

void wb_grab_local(const wb_world *w, wb_grab_id id, wb_real out[3]) { v3_copy(out, &w->grab->local[3 * SLOT(w, id)]); }

void wb_grab_point(const wb_world *w, wb_grab_id id, wb_real out[3])
{
    const int32_t s = SLOT(w, id);
    if (wb__grab_active(w, w->grab, s)) grabbed_point(w, w->grab, s, out);
    else v3_copy(out, &w->grab->target[3 * s]);
}
wb_real wb_grab_compliance(const wb_world *w, wb_grab_id id) { return w->grab->alpha[SLOT(w, id)]; }

wb_real wb_grab_force(const wb_world *w, wb_grab_id id, wb_real f[3])
{
    const int32_t s = SLOT(w, id);
    const wb_real h = w->k.h_last;
    wb_real out[3] = { 0, 0, 0 };
    if (h > 0) v3_scale(out, &w->grab->lambda[3 * s], 1 / (h * h));
    if (f) v3_copy(f, out);
    return v3_len(out);
}

int32_t wb_grab_count(const wb_world *w)
{
    const wb_grabs *g = w->grab;
    int32_t n = 0;
    for (int32_t s = 0; g && s < g->n; s++) n += wb__grab_active(w, g, s);
    return n;
}

wb_grab_id wb_grab_at(const wb_world *w, int32_t i)
{
    const wb_grabs *g = w->grab;
    for (int32_t s = 0; g && s < g->n; s++) {
        if (!wb__grab_active(w, g, s)) continue;
        if (i-- == 0) { wb_grab_id id = { (uint32_t)s + 1, g->gen[s] }; return id; }
    }
    wb_grab_id none = { 0, 0 };
    return none;
}

int32_t wb_grab_list(const wb_world *w, wb_grab_id *out, int32_t cap)
{
    const wb_grabs *g = w->grab;
    int32_t k = 0;
    for (int32_t s = 0; g && s < g->n; s++) {
        if (!wb__grab_active(w, g, s)) continue;
        if (k < cap) { out[k].index = (uint32_t)s + 1; out[k].gen = g->gen[s]; }
        k++;
    }
    return k;
}

/* ---- images (snapshot.h) ------------------------------------------------------------- */
static void *zalloc(int64_t n, size_t elem) { return calloc((size_t)(n > 0 ? n : 1), elem); }

static void grab_image_free(wb_image *g)
{
    wb_image_grab *a = &g->grab;
    free(a->p); free(a->kind); free(a->local); free(a->target); free(a->from); free(a->alpha);
    memset(a, 0, sizeof *a);
}

wb_status wb_image_alloc_grab(wb_image *g, int32_t n)
{
    grab_image_free(g);
    wb_image_grab *a = &g->grab;
    a->n = n;
    a->p = zalloc(n, sizeof *a->p);
    a->kind = zalloc(n, sizeof *a->kind);
    a->local = zalloc(3 * (int64_t)n, sizeof *a->local);
    a->target = zalloc(3 * (int64_t)n, sizeof *a->target);
    a->from = zalloc(3 * (int64_t)n, sizeof *a->from);
    a->alpha = zalloc(n, sizeof *a->alpha);
    if (a->p && a->kind && a->local && a->target && a->from && a->alpha) return WB_OK;
    grab_image_free(g);
    return WB_ERR_NOMEM;
}

static wb_status grab_image_save(const wb_world *w, wb_image *img)
{
    wb_status st = wb_image_alloc_grab(img, wb_grab_count(w));
    if (st != WB_OK) return st;
    const wb_grabs *g = w->grab;
    int32_t k = 0;
    for (int32_t s = 0; g && s < g->n; s++) {
        if (!wb__grab_active(w, g, s)) continue;
        img->grab.p[k] = g->p[s];
        img->grab.kind[k] = g->kind[s];
        v3_copy(&img->grab.local[3 * k], &g->local[3 * s]);
        v3_copy(&img->grab.target[3 * k], &g->target[3 * s]);
        v3_copy(&img->grab.from[3 * k], &g->from[3 * s]);
        img->grab.alpha[k] = g->alpha[s];
        k++;
    }
    return WB_OK;
}

static const char *grab_image_check(const wb_image *img)
{
    const wb_image_grab *g = &img->grab;
    if (g->n < 0 || g->n > WB_MAX_CONSTRAINTS) return "too many grabs";
    for (int32_t k = 0; k < g->n; k++) {
        if (g->kind[k] == WB_GRAB_RIGID) {
            const int32_t r = g->p[k];
            if (r < 0 || r >= img->nrb || !(img->rb_gen[r] & 1u)) return "grab rigid body out of range";
            if (!fin3(&g->local[3 * k])) return "grab point (at) must be finite";
        } else if (g->kind[k] != WB_GRAB_PARTICLE) {
            return "grab kind unknown (0 = particle, 1 = rigid body)";
        } else if (g->p[k] < 0 || g->p[k] >= img->np) {
            return "grab particle out of range";
        }
        if (!fin3(&g->target[3 * k]) || !fin3(&g->from[3 * k])) return "grab target must be finite";
        if (wb_grab_def_fault(g->alpha[k]).msg) return "grab compliance must be >= 0 (m/N)";
    }
    return NULL;
}

static wb_status grab_image_reserve(wb_world *w, const wb_image *img, const wb_image_at *at)
{
    (void)at;
    return img->grab.n > 0 ? wb__grab_reserve(w, img->grab.n) : WB_OK;
}

static void grab_image_put(wb_world *w, const wb_image *img, const wb_image_at *at)
{
    const int32_t pshift = at->pshift, *rmap = at->rmap;
    const wb_image_grab *g = &img->grab;
    for (int32_t k = 0; k < g->n; k++) {
        const int rigid = g->kind[k] == WB_GRAB_RIGID;
        const int32_t p = rigid ? (rmap ? rmap[g->p[k]] : g->p[k]) : g->p[k] + pshift;
        wb__grab_put(w, p, rigid ? WB_GRAB_RIGID : WB_GRAB_PARTICLE, rigid ? &g->local[3 * k] : NULL,
                     &g->target[3 * k], &g->from[3 * k], g->alpha[k]);
    }
}

/* ---- the type ---------------------------------------------------------------------- */
static int32_t grab_count(const wb_world *w) { return wb_grab_count(w); }

/* once per step: grabs of removed bodies end */
static wb_status grab_prepare(wb_world *w)
{
    wb_grabs *g = w->grab;
    if (!g) return WB_OK;
    g->sub = 0;
    for (int32_t s = 0; s < g->n; s++)
        if (live(g, s) && !wb__grab_active(w, g, s)) {
            g->gen[s]++;
            g->nlive--;
            if (s < g->free_hint) g->free_hint = s;
        }
    return WB_OK;
}

static void grab_substep_begin(wb_world *w)
{
    wb_grabs *g = w->grab;
    if (!g) return;
    g->sub++;
    if (g->n > 0) memset(g->lambda, 0, sizeof(wb_real) * 3 * (size_t)g->n);
}

/* a body's point pulled to the target: (K + alpha~ E) dlambda = t - x - alpha~ lambda with
 * K the body's response at the point (as attach.c's rigid case, the target immovable) */
static void project_rigid(wb_world *w, wb_grabs *g, int32_t s, wb_real h, wb_real f)
{
    const int32_t r = g->p[s];
    const wb_real at = g->alpha[s] / (h * h);
    if (isinf(at)) return;
    const wb_real *t1 = &g->target[3 * s], *t0 = &g->from[3 * s];
    wb_real x[3], K[9], rhs[3], dl[3], *l = &g->lambda[3 * s];
    wb__rigid_to_world(w, r, &g->local[3 * s], x);
    wb__rigid_point_response(w, r, x, K);
    for (int k = 0; k < 3; k++) {
        const wb_real t = g->sub >= w->m.def.substeps ? t1[k] : t0[k] + (t1[k] - t0[k]) * f;
        K[4 * k] += at;
        rhs[k] = t - x[k] - at * l[k];
    }
    if (!wb__solve3(K, rhs, dl)) return;
    v3_add(l, l, dl);
    wb__rigid_apply(w, r, x, dl);
}

static void grab_project(wb_world *w, wb_real h)
{
    wb_grabs *g = w->grab;
    if (!g || g->nlive == 0) return;
    const int32_t n_sub = w->m.def.substeps;
    const wb_real f = (wb_real)g->sub / n_sub;
    const wb_real inv_h2 = 1 / (h * h);
    const wb_real *wv = w->m.w;
    wb_real *x = w->s.x;
    w->k.projections += g->nlive;
    for (int32_t s = 0; s < g->n; s++) {
        if (!wb__grab_active(w, g, s)) continue;
        if (g->kind[s] == WB_GRAB_RIGID) {
            project_rigid(w, g, s, h, f);
            continue;
        }
        const int32_t p = g->p[s];
        const wb_real wp = wv[p];
        if (wp == 0) continue; /* pinned or immovable: never written */
        const wb_real at = g->alpha[s] * inv_h2;
        if (isinf(at)) continue;
        const wb_real *t1 = &g->target[3 * s], *t0 = &g->from[3 * s];
        wb_real *xp = &x[3 * p], *l = &g->lambda[3 * s];
        const wb_real inv = 1 / (wp + at);
        for (int k = 0; k < 3; k++) {
            /* the last substep reaches the target exactly, not t0 + (t1 - t0) rounded */
            const wb_real t = g->sub >= n_sub ? t1[k] : t0[k] + (t1[k] - t0[k]) * f;
            const wb_real dl = (t - xp[k] - at * l[k]) * inv;
            l[k] += dl;
            xp[k] += wp * dl;
        }
    }
}

/* the sweep of the next step starts where this one ended */
static void grab_frame_end(wb_world *w)
{
    wb_grabs *g = w->grab;
    if (g && g->n > 0) memcpy(g->from, g->target, sizeof(wb_real) * 3 * (size_t)g->n);
}

/* |x - t + alpha~ lambda| (C = x - t), the target where this substep's projection put it */
static wb_real grab_residual(const wb_world *w, wb_real h)
{
    const wb_grabs *g = w->grab;
    if (!g) return 0;
    const int32_t n_sub = w->m.def.substeps;
    const wb_real f = (wb_real)g->sub / n_sub, inv_h2 = 1 / (h * h);
    wb_real r = 0;
    for (int32_t s = 0; s < g->n; s++) {
        if (!wb__grab_active(w, g, s)) continue;
        const wb_real at = g->alpha[s] * inv_h2;
        if (isinf(at)) continue;
        wb_real x[3], c[3];
        if (g->kind[s] == WB_GRAB_RIGID) wb__rigid_to_world(w, g->p[s], &g->local[3 * s], x);
        else if (w->m.w[g->p[s]] == 0) continue;
        else v3_copy(x, &w->s.x[3 * g->p[s]]);
        const wb_real *t1 = &g->target[3 * s], *t0 = &g->from[3 * s];
        for (int k = 0; k < 3; k++) c[k] = x[k] - (g->sub >= n_sub ? t1[k] : t0[k] + (t1[k] - t0[k]) * f) + at * g->lambda[3 * s + k];
        const wb_real ri = v3_len(c);
        r = ri > r ? ri : r;
    }
    return r;
}

static wb_real grab_energy(const wb_world *w)
{
    const wb_grabs *g = w->grab;
    wb_real e = 0;
    for (int32_t s = 0; g && s < g->n; s++) {
        if (!wb__grab_active(w, g, s) || !(g->alpha[s] > 0)) continue;
        wb_real c[3];
        grabbed_point(w, g, s, c);
        v3_sub(c, c, &g->target[3 * s]);
        e += v3_dot(c, c) / (2 * g->alpha[s]);
    }
    return e;
}

/* ---- teardown and hash (ctype.h) --------------------------------------------------------- */
static void grab_destroy(wb_world *w)
{
    wb_grabs *g = w->grab;
    if (!g) return;
    void *p[] = { g->p, g->kind, g->tgen, g->local, g->alpha, g->gen, g->target, g->from, g->lambda };
    for (size_t i = 0; i < sizeof p / sizeof p[0]; i++) free(p[i]);
    free(g);
    w->grab = NULL;
}

static size_t grab_charged(const wb_world *w) { return w->grab ? w->grab->charged : 0; }

/* the live ones in slot order, as a snapshot keeps them */
static uint64_t grab_hash(const wb_world *w, uint64_t h)
{
    const wb_grabs *g = w->grab;
    for (int32_t i = 0; g && i < g->n; i++) {
        if (!wb__grab_active(w, g, i)) continue;
        h = wb__fnv(h, &g->p[i], sizeof g->p[i]);
        if (g->kind[i] == WB_GRAB_RIGID) { /* (particle grabs hash as they always did) */
            h = wb__fnv(h, &g->kind[i], 1);
            h = wb__fnv(h, &g->local[3 * i], 3 * sizeof(wb_real));
        }
        h = wb__fnv(h, &g->target[3 * i], 3 * sizeof(wb_real));
        h = wb__fnv(h, &g->from[3 * i], 3 * sizeof(wb_real));
        h = wb__fnv(h, &g->alpha[i], sizeof(wb_real));
    }
    return h;
}

static void grab_stats(const wb_world *w, wb_stats *st)
{
    st->grabs = wb_grab_count(w);
}

wb_real wb__grab_speed(const wb_world *w, wb_real dt)
{
    const wb_grabs *gr = w->grab;
    wb_real s = 0;
    for (int32_t i = 0; gr && i < gr->n; i++) {
        if (!(gr->gen[i] & 1u)) continue;
        wb_real d[3];
        v3_sub(d, &gr->target[3 * i], &gr->from[3 * i]);
        s = fmax(s, v3_len(d) / dt);
    }
    return s;
}

/* a live grab of a particle holds it (a grab of a rigid body's point holds no particle) */
static void grab_anchors(const wb_world *w, wb_link_fn fn, void *ud)
{
    const wb_grabs *g = w->grab;
    for (int32_t s = 0; g && s < g->n; s++)
        if ((g->gen[s] & 1u) && g->kind[s] == WB_GRAB_PARTICLE) fn(ud, g->p[s], g->p[s], 1);
}

const wb_ctype wb__grab_type = {
    .name = "grab",
    .count = grab_count,
    .prepare = grab_prepare,
    .substep_begin = grab_substep_begin,
    .project = grab_project,
    .frame_end = grab_frame_end,
    .energy = grab_energy,
    .destroy = grab_destroy,
    .charged = grab_charged,
    .stats = grab_stats,
    .hash = grab_hash,
    .image_free = grab_image_free,
    .image_save = grab_image_save,
    .image_check = grab_image_check,
    .image_reserve = grab_image_reserve,
    .image_put = grab_image_put,
    .residual = grab_residual,
    .anchors = grab_anchors,
};
