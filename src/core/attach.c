/* attach.c: attachments (a type of the table in ctype.c, so all of it is here).
 *
 * A particle is kept at a point fixed in a target's frame: the point `local` is stored
 * in that frame when it is made, and every substep the target is where the target is
 * at that substep (a kinematic collider sweeps from its last pose to the one the script
 * set, wb__collider_pose_at, exactly as the particles' collider contacts see it). So a
 * turning drum carries a rope's end round and winds the rope on.
 *
 * XPBD with a vector constraint C = x - t (zero rest length; the target has no inverse
 * mass): dlambda = (-C - alpha~ lambda) / (w + alpha~), x += w dlambda, alpha~ = alpha/h^2.
 * A vector multiplier has no direction to lose when C = 0. Force on the particle:
 * lambda / h^2. Energy: |C|^2 / (2 alpha) for compliant ones.
 *
 * Model: particle, target {kind, slot, gen}, local point, compliance. Cache: multipliers
 * and the substep counter. The pass is serial in slot order: deterministic for any thread
 * count (attachments are few; colouring them is not worth it). */
#include <assert.h>

#include "attach.h"
#include "ctype.h"
#include "shape_match.h"
#include "snapshot.h"

#define ATTACH_BYTES (2 * sizeof(int32_t) + 1 + 2 * sizeof(uint32_t) + 7 * sizeof(wb_real))

static int live(const wb_attaches *a, int32_t s) { return (a->gen[s] & 1u) != 0; }

/* the target still exists (a removed collider leaves its attachments inert) */
static int target_live(const wb_world *w, const wb_attaches *a, int32_t s) { return wb__attach_active(w, a, s); }

/* the target point: a collider's at fraction f of the current step (f >= 1: the pose
 * now); a rigid body's at its pose now (the solver moves it) */
static void point_at(const wb_world *w, const wb_attaches *a, int32_t s, wb_real f, wb_real out[3])
{
    if (a->kind[s] == WB_TARGET_RIGID) {
        wb__rigid_to_world(w, a->tindex[s], &a->local[3 * s], out);
        return;
    }
    wb_real p[3], q[4];
    wb__collider_pose_at(&w->s.c_pose[a->tindex[s]], f, p, q);
    q_rotate(q, &a->local[3 * s], out);
    v3_add(out, out, p);
}

wb_status wb__attach_reserve(wb_world *w, int64_t extra)
{
    wb_attaches *a = w->att;
    if (!a) {
        a = calloc(1, sizeof *a);
        if (!a) return WB_ERR_NOMEM;
        w->att = a;
    }
    const int64_t need = a->n + extra;
    if (need > WB_MAX_CONSTRAINTS) return WB_ERR_LIMIT;
    if (need <= a->cap) return WB_OK;
    const int32_t cap = wb__grown_cap(a->cap, need, 16);
    if (!wb__charge(w, &a->charged, (size_t)cap * ATTACH_BYTES)) return WB_ERR_NOMEM;
    const wb_soa arr[] = {
        { (void **)&a->p, sizeof(int32_t) }, { (void **)&a->kind, 1 }, { (void **)&a->tindex, sizeof(int32_t) },
        { (void **)&a->tgen, sizeof(uint32_t) }, { (void **)&a->local, 3 * sizeof(wb_real) },
        { (void **)&a->alpha, sizeof(wb_real) }, { (void **)&a->gen, sizeof(uint32_t) },
        { (void **)&a->lambda, 3 * sizeof(wb_real) },
    };
    if (WB_SOA_RESIZE(arr, cap) != WB_OK) return WB_ERR_NOMEM;
    a->cap = cap;
    return WB_OK;
}

static void fill(wb_attaches *a, int32_t s, int32_t p, int kind, int32_t tindex, uint32_t tgen,
                 const wb_real local[3], wb_real alpha)
{
    a->p[s] = p;
    a->kind[s] = (uint8_t)kind;
    a->tindex[s] = tindex;
    a->tgen[s] = tgen;
    v3_copy(&a->local[3 * s], local);
    a->alpha[s] = alpha;
    v3_set(&a->lambda[3 * s], 0, 0, 0);
    a->nlive++;
    a->dirty = 1;
}

/* a new live slot after the last one (snapshots restore the live slots in order) */
void wb__attach_put(wb_world *w, int32_t p, int kind, int32_t tindex, uint32_t tgen, const wb_real local[3],
                    wb_real alpha)
{
    wb_attaches *a = w->att;
    assert(a && a->n < a->cap); /* contract: reserved first */
    const int32_t s = a->n++;
    fill(a, s, p, kind, tindex, tgen, local, alpha);
    a->gen[s] = 1;
}

/* a new attachment of p to target {kind, slot, gen} at local point `local` */
static wb_attach_id attach_new(wb_world *w, int32_t p, int kind, int32_t slot, uint32_t gen, const wb_real local[3],
                               wb_real compliance, wb_status *status)
{
    wb_attach_id none = { 0, 0 };
    if (!isfinite(local[0]) || !isfinite(local[1]) || !isfinite(local[2])) {
        wb__set_error("the particle is too far from the %s (its offset overflows)",
                      kind == WB_TARGET_RIGID ? "body" : "collider");
        *status = WB_ERR_ARG;
        return none;
    }
    /* the lowest dead slot, else a new one (the search starts at the hint: thousands of
     * attachments made in a row cost no quadratic scan) */
    wb_attaches *a = w->att;
    int32_t s = -1;
    for (int32_t i = a ? a->free_hint : 0; a && i < a->n && s < 0; i++)
        if (!live(a, i)) s = i;
    if (a) a->free_hint = s < 0 ? a->n : s + 1;
    if (s < 0) {
        wb_status st = wb__attach_reserve(w, 1);
        if (st != WB_OK) { *status = st; return none; }
        wb__attach_put(w, p, kind, slot, gen, local, compliance);
        a = w->att;
        s = a->n - 1;
    } else {
        fill(a, s, p, kind, slot, gen, local, compliance);
        a->gen[s]++; /* even -> odd: live, old handles of the slot stay stale */
    }
    *status = WB_OK;
    wb_attach_id id = { (uint32_t)s + 1, a->gen[s] };
    return id;
}

wb_fault wb_attach_def_fault(wb_real compliance)
{
    return !(compliance >= 0) || !isfinite(compliance) ? WB_FAULT_KEY("compliance", "must be >= 0 (m/N)") : WB_NO_FAULT;
}

static const char *check_new(const wb_world *w, int32_t p, wb_real compliance)
{
    const char *e = wb_attach_def_fault(compliance).msg;
    return e ? e : p < 0 || p >= w->m.np ? "particle out of range" : NULL;
}

wb_attach_id wb_attach_collider(wb_world *w, int32_t p, wb_collider_id c, wb_real compliance, wb_status *status)
{
    wb_attach_id none = { 0, 0 };
    wb_status dummy;
    if (!status) status = &dummy;
    const char *err = check_new(w, p, compliance);
    if (!err && !wb_collider_valid(w, c)) err = "collider removed";
    if (err) {
        wb__set_error("%s", err);
        *status = WB_ERR_ARG;
        return none;
    }
    /* the point where the particle is now, in the collider's frame at its pose now */
    const int32_t slot_c = (int32_t)c.index - 1;
    const wb_collider_pose *cp = &w->s.c_pose[slot_c];
    wb_real r[3], local[3];
    v3_sub(r, &w->s.x[3 * p], cp->p);
    q_rotate_inv(cp->q, r, local);
    return attach_new(w, p, WB_TARGET_COLLIDER, slot_c, c.gen, local, compliance, status);
}

wb_attach_id wb_attach_rigid(wb_world *w, int32_t p, wb_rigid_id r, wb_real compliance, wb_status *status)
{
    wb_attach_id none = { 0, 0 };
    wb_status dummy;
    if (!status) status = &dummy;
    const char *err = check_new(w, p, compliance);
    if (!err && !wb_rigid_valid(w, r)) err = "rigid body removed";
    if (err) {
        wb__set_error("%s", err);
        *status = WB_ERR_ARG;
        return none;
    }
    const int32_t slot_r = (int32_t)r.index - 1;
    wb_real local[3];
    wb__rigid_to_local(w, slot_r, &w->s.x[3 * p], local);
    return attach_new(w, p, WB_TARGET_RIGID, slot_r, r.gen, local, compliance, status);
}

static int32_t slot_of(const wb_world *w, wb_attach_id id)
{
    const wb_attaches *a = w->att;
    if (!a || id.index == 0 || id.index > (uint32_t)a->n) return -1;
    const int32_t s = (int32_t)id.index - 1;
    return live(a, s) && a->gen[s] == id.gen ? s : -1;
}

bool wb_attach_valid(const wb_world *w, wb_attach_id id)
{
    const int32_t s = slot_of(w, id);
    return s >= 0 && target_live(w, w->att, s);
}

#define SLOT(w, id) (assert(slot_of((w), (id)) >= 0), (int32_t)(id).index - 1)

void wb_attach_remove(wb_world *w, wb_attach_id id)
{
    const int32_t s = SLOT(w, id);
    w->att->gen[s]++;
    w->att->nlive--;
    w->att->dirty = 1;
    if (s < w->att->free_hint) w->att->free_hint = s;
}

wb_real wb_attach_force(const wb_world *w, wb_attach_id id, wb_real f[3])
{
    const int32_t s = SLOT(w, id);
    const wb_real h = w->k.h_last;
    wb_real out[3] = { 0, 0, 0 };
    if (h > 0) v3_scale(out, &w->att->lambda[3 * s], 1 / (h * h));
    if (f) v3_copy(f, out);
    return v3_len(out);
}

int32_t wb_attach_particle(const wb_world *w, wb_attach_id id) { return w->att->p[SLOT(w, id)]; }
wb_real wb_attach_compliance(const wb_world *w, wb_attach_id id) { return w->att->alpha[SLOT(w, id)]; }

void wb_attach_point(const wb_world *w, wb_attach_id id, wb_real out[3])
{
    const int32_t s = SLOT(w, id);
    if (target_live(w, w->att, s)) point_at(w, w->att, s, 1, out);
    else v3_copy(out, &w->s.x[3 * w->att->p[s]]);
}

int32_t wb_attach_count(const wb_world *w)
{
    const wb_attaches *a = w->att;
    int32_t n = 0;
    for (int32_t s = 0; a && s < a->n; s++) n += target_live(w, a, s);
    return n;
}

wb_attach_id wb_attach_at(const wb_world *w, int32_t i)
{
    const wb_attaches *a = w->att;
    for (int32_t s = 0; a && s < a->n; s++) {
        if (!target_live(w, a, s)) continue;
        if (i-- == 0) { wb_attach_id id = { (uint32_t)s + 1, a->gen[s] }; return id; }
    }
    wb_attach_id none = { 0, 0 };
    return none;
}

int32_t wb_attach_list(const wb_world *w, wb_attach_id *out, int32_t cap)
{
    const wb_attaches *a = w->att;
    int32_t k = 0;
    for (int32_t s = 0; a && s < a->n; s++) {
        if (!target_live(w, a, s)) continue;
        if (k < cap) { out[k].index = (uint32_t)s + 1; out[k].gen = a->gen[s]; }
        k++;
    }
    return k;
}

/* ---- images (snapshot.h) ------------------------------------------------------------- */
static void *zalloc(int64_t n, size_t elem) { return calloc((size_t)(n > 0 ? n : 1), elem); }

static void att_image_free(wb_image *g)
{
    wb_image_attach *a = &g->att;
    free(a->p); free(a->kind); free(a->target); free(a->local); free(a->alpha);
    memset(a, 0, sizeof *a);
}

wb_status wb_image_alloc_attach(wb_image *g, int32_t n)
{
    att_image_free(g);
    wb_image_attach *a = &g->att;
    a->n = n;
    a->p = zalloc(n, sizeof *a->p);
    a->kind = zalloc(n, sizeof *a->kind);
    a->target = zalloc(n, sizeof *a->target);
    a->local = zalloc(3 * (int64_t)n, sizeof *a->local);
    a->alpha = zalloc(n, sizeof *a->alpha);
    if (a->p && a->kind && a->target && a->local && a->alpha) return WB_OK;
    att_image_free(g);
    return WB_ERR_NOMEM;
}

static wb_status att_image_save(const wb_world *w, wb_image *g)
{
    wb_status st = wb_image_alloc_attach(g, wb_attach_count(w));
    if (st != WB_OK) return st;
    const wb_attaches *a = w->att;
    int32_t k = 0;
    for (int32_t s = 0; a && s < a->n; s++) {
        if (!target_live(w, a, s)) continue;
        g->att.p[k] = a->p[s];
        g->att.kind[k] = a->kind[s];
        g->att.target[k] = a->tindex[s];
        v3_copy(&g->att.local[3 * k], &a->local[3 * s]);
        g->att.alpha[k] = a->alpha[s];
        k++;
    }
    return WB_OK;
}

static const char *att_image_check(const wb_image *g)
{
    const wb_image_attach *a = &g->att;
    if (a->n < 0 || a->n > WB_MAX_CONSTRAINTS) return "too many attachments";
    for (int32_t k = 0; k < a->n; k++) {
        if (a->p[k] < 0 || a->p[k] >= g->np) return "attachment particle out of range";
        const int32_t c = a->target[k];
        if (a->kind[k] == WB_TARGET_RIGID) {
            if (c < 0 || c >= g->nrb || !(g->rb_gen[c] & 1u)) return "attachment rigid body out of range";
        } else if (a->kind[k] != WB_TARGET_COLLIDER) {
            return "attachment target kind unknown (0 = collider, 1 = rigid body)";
        } else if (c < 0 || c >= g->nc || !(g->c_gen[c] & 1u)) {
            return "attachment collider out of range";
        }
        if (!isfinite(a->local[3 * k]) || !isfinite(a->local[3 * k + 1]) || !isfinite(a->local[3 * k + 2]))
            return "attachment point must be finite";
        if (wb_attach_def_fault(a->alpha[k]).msg) return "attachment compliance must be >= 0 (m/N)";
    }
    return NULL;
}

static wb_status att_image_reserve(wb_world *w, const wb_image *g, const wb_image_at *at)
{
    (void)at;
    return g->att.n > 0 ? wb__attach_reserve(w, g->att.n) : WB_OK;
}

static void att_image_put(wb_world *w, const wb_image *g, const wb_image_at *at)
{
    const int32_t pshift = at->pshift, *cmap = at->cmap, *rmap = at->rmap;
    const wb_image_attach *a = &g->att;
    for (int32_t k = 0; k < a->n; k++) {
        const int rigid = a->kind[k] == WB_TARGET_RIGID;
        const int32_t *map = rigid ? rmap : cmap;
        const int32_t t = map ? map[a->target[k]] : a->target[k];
        wb__attach_put(w, a->p[k] + pshift, a->kind[k], t, rigid ? w->rb->gen[t] : w->m.c_gen[t], &a->local[3 * k],
                       a->alpha[k]);
    }
}

/* ---- the type ---------------------------------------------------------------------- */
static int32_t att_count(const wb_world *w) { return wb_attach_count(w); }

/* once per step: attachments whose collider was removed die; the particle -> collider
 * skip table is rebuilt when anything changed */
static wb_status att_prepare(wb_world *w)
{
    wb_attaches *a = w->att;
    if (!a) return WB_OK;
    a->sub = 0;
    for (int32_t s = 0; s < a->n; s++)
        if (live(a, s) && !target_live(w, a, s)) {
            a->gen[s]++;
            a->nlive--;
            a->dirty = 1;
            if (s < a->free_hint) a->free_hint = s;
        }
    const int32_t np = w->m.np;
    if (a->nlive == 0) a->skip_np = 0; /* nothing to skip: collide.c does not look */
    if (a->nlive == 0 || (!a->dirty && a->skip_np == np)) return WB_OK;
    int32_t *st = wb__grow(a->skip_start, &a->cap_start, np + 1, sizeof *st);
    if (!st) return WB_ERR_NOMEM;
    a->skip_start = st;
    int32_t *col = wb__grow(a->skip_col, &a->cap_col, a->nlive > 0 ? a->nlive : 1, sizeof *col);
    if (!col) return WB_ERR_NOMEM;
    a->skip_col = col;
    /* charged like the attachments (a million particles make it 4 MB); past the budget
     * the step fails and the table stays built-but-unused until the world goes */
    if (!wb__charge(w, &a->skip_charged, sizeof(int32_t) * ((size_t)a->cap_start + (size_t)a->cap_col))) {
        a->skip_np = 0;
        return WB_ERR_NOMEM;
    }
    /* counting sort by particle, slot order inside one */
    memset(st, 0, sizeof *st * ((size_t)np + 1));
    for (int32_t s = 0; s < a->n; s++)
        if (live(a, s) && a->p[s] < np) st[a->p[s] + 1]++;
    for (int32_t i = 0; i < np; i++) st[i + 1] += st[i];
    for (int32_t s = 0; s < a->n; s++)
        if (live(a, s) && a->p[s] < np)
            col[st[a->p[s]]++] = a->kind[s] == WB_TARGET_RIGID ? -1 - a->tindex[s] : a->tindex[s];
    for (int32_t i = np; i > 0; i--) st[i] = st[i - 1];
    st[0] = 0;
    a->skip_np = np;
    a->dirty = 0;
    return WB_OK;
}

static void att_substep_begin(wb_world *w)
{
    wb_attaches *a = w->att;
    if (!a) return;
    a->sub++;
    if (a->n > 0) memset(a->lambda, 0, sizeof(wb_real) * 3 * (size_t)a->n);
}

static void att_project(wb_world *w, wb_real h)
{
    wb_attaches *a = w->att;
    if (!a || a->nlive == 0) return;
    /* the target at this substep's end, as the collider contacts place the collider */
    const wb_real f = (wb_real)a->sub / w->m.def.substeps;
    const wb_real inv_h2 = 1 / (h * h);
    const wb_real *wv = w->m.w;
    wb_real *x = w->s.x;
    w->k.projections += a->nlive;
    for (int32_t s = 0; s < a->n; s++) {
        if (!target_live(w, a, s)) continue;
        const int32_t p = a->p[s];
        const wb_real wp = wv[p];
        /* pinned or immovable: never written (but a body still hangs from it) */
        if (wp == 0 && a->kind[s] != WB_TARGET_RIGID) continue;
        const wb_real at = a->alpha[s] * inv_h2;
        if (isinf(at)) continue;
        wb_real t[3];
        point_at(w, a, s, f, t);
        wb_real *xp = &x[3 * p], *l = &a->lambda[3 * s];
        if (a->kind[s] == WB_TARGET_RIGID) {
            /* the point constraint C = x - t in 3D: (K + alpha~ E) dlambda = -C - alpha~ lambda,
             * K = wp E + the body's response at the point (Müller et al. 2020's generalized
             * inverse mass as a matrix). Along C's direction only (the scalar form), each
             * correction moved the point sideways as well, and a swinging body's attachment
             * rang from substep to substep with a force 1.7 times its weight */
            wb_real K[9], rhs[3], dl[3];
            wb__rigid_point_response(w, a->tindex[s], xp, K);
            for (int k = 0; k < 3; k++) {
                K[4 * k] += wp + at;
                rhs[k] = t[k] - xp[k] - at * l[k];
            }
            if (!wb__solve3(K, rhs, dl)) continue;
            v3_add(l, l, dl);
            wb_real dp[3];
            v3_scale(dp, dl, -1);
            /* applied to the body at the particle's position, so the pair's impulses are
             * equal, opposite and on one line: angular momentum kept to round-off */
            wb__rigid_apply(w, a->tindex[s], xp, dp);
            if (wp > 0) v3_madd(xp, dl, wp);
            continue;
        }
        const wb_real inv = 1 / (wp + at);
        for (int k = 0; k < 3; k++) {
            const wb_real dl = (t[k] - xp[k] - at * l[k]) * inv;
            l[k] += dl;
            xp[k] += wp * dl;
        }
    }
}

/* |x - t + alpha~ lambda| (C = x - t, a point: its gradients are the identity), the
 * target where this substep's projection put it */
static wb_real att_residual(const wb_world *w, wb_real h)
{
    const wb_attaches *a = w->att;
    if (!a) return 0;
    const wb_real f = (wb_real)a->sub / w->m.def.substeps, inv_h2 = 1 / (h * h);
    wb_real r = 0;
    for (int32_t s = 0; s < a->n; s++) {
        if (!target_live(w, a, s)) continue;
        const int32_t p = a->p[s];
        const wb_real at = a->alpha[s] * inv_h2;
        if ((w->m.w[p] == 0 && a->kind[s] != WB_TARGET_RIGID) || isinf(at)) continue;
        wb_real t[3], c[3];
        point_at(w, a, s, f, t);
        v3_sub(c, &w->s.x[3 * p], t);
        v3_madd(c, &a->lambda[3 * s], at);
        const wb_real ri = v3_len(c);
        r = ri > r ? ri : r;
    }
    return r;
}

static wb_real att_energy(const wb_world *w)
{
    const wb_attaches *a = w->att;
    wb_real e = 0;
    for (int32_t s = 0; a && s < a->n; s++) {
        if (!target_live(w, a, s) || !(a->alpha[s] > 0)) continue;
        wb_real t[3], c[3];
        point_at(w, a, s, 1, t);
        v3_sub(c, &w->s.x[3 * a->p[s]], t);
        e += v3_dot(c, c) / (2 * a->alpha[s]);
    }
    return e;
}

/* ---- teardown and hash (ctype.h) --------------------------------------------------------- */
static void att_destroy(wb_world *w)
{
    wb_attaches *a = w->att;
    if (!a) return;
    void *p[] = { a->p, a->kind, a->tindex, a->tgen, a->local, a->alpha, a->gen, a->lambda,
                  a->skip_start, a->skip_col };
    for (size_t i = 0; i < sizeof p / sizeof p[0]; i++) free(p[i]);
    free(a);
    w->att = NULL;
}

static size_t att_charged(const wb_world *w) { return w->att ? w->att->charged + w->att->skip_charged : 0; }

/* the live ones in slot order (a snapshot keeps that order; it drops an attachment whose
 * collider was removed, so the hash does too) */
static uint64_t att_hash(const wb_world *w, uint64_t h)
{
    const wb_attaches *a = w->att;
    for (int32_t i = 0; a && i < a->n; i++) {
        if (!wb__attach_active(w, a, i)) continue;
        h = wb__fnv(h, &a->p[i], sizeof a->p[i]);
        h = wb__fnv(h, &a->kind[i], 1);
        h = wb__fnv(h, &a->tindex[i], sizeof a->tindex[i]);
        h = wb__fnv(h, &a->local[3 * i], 3 * sizeof(wb_real));
        h = wb__fnv(h, &a->alpha[i], sizeof(wb_real));
    }
    return h;
}

static void att_stats(const wb_world *w, wb_stats *st)
{
    st->attachments = wb_attach_count(w);
}

/* every live attachment holds its particle (its target gone or not: prepare retires it) */
static void attach_anchors(const wb_world *w, wb_link_fn fn, void *ud)
{
    const wb_attaches *a = w->att;
    for (int32_t s = 0; a && s < a->n; s++)
        if (a->gen[s] & 1u) fn(ud, a->p[s], a->p[s], 1);
}

const wb_ctype wb__attach_type = {
    .name = "attach",
    .count = att_count,
    .prepare = att_prepare,
    .substep_begin = att_substep_begin,
    .project = att_project,
    .energy = att_energy,
    .destroy = att_destroy,
    .charged = att_charged,
    .stats = att_stats,
    .hash = att_hash,
    .image_free = att_image_free,
    .image_save = att_image_save,
    .image_check = att_image_check,
    .image_reserve = att_image_reserve,
    .image_put = att_image_put,
    .residual = att_residual,
    .anchors = attach_anchors,
};
