/* contact.c: particle-particle contacts (DESIGN.md §2, issue 8).
 *
 * Once per frame a broad phase (a spatial hash rebuilt from the frame's swept bounds
 * plus a margin, Macklin et al. 2019 "Small steps" §4) lists the candidate pairs; every
 * substep they are projected as inequality constraints |x_i - x_j| >= r_i + r_j (XPBD
 * with compliance 0, mass-weighted so momentum is conserved), with Coulomb friction
 * at position level (static inside the cone, as the collider contacts do in collide.c,
 * and kinetic outside it); after the velocity update a velocity pass removes the
 * approach speed (no restitution) and any speed the repair of an old overlap made (bodies
 * made inside each other push apart at max_depenetration, never fly apart). Inside one
 * body, pairs never collide unless it self-collides, and then not when joined by a
 * constraint or closer than r_i + r_j where they were created (Müller's Ten Minute
 * Physics rule).
 *
 * Determinism: the candidate list depends on the positions alone (its order is the
 * particle order and the hash's bucket order), and the pairs are projected in a
 * serial pass in that order, so the result is the same for any thread count. */
#include <stdlib.h>
#include <time.h>

#include "core.h"

static double now_ms(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return ts.tv_sec * 1e3 + ts.tv_nsec * 1e-6;
}

/* ---- groups and settings ---------------------------------------------------------------- */
int32_t wb_group_new(const wb_world *w)
{
    int32_t g = 0;
    for (int32_t i = 0; i < w->m.np; i++)
        if (w->m.group[i] > g) g = w->m.group[i];
    return g + 1;
}

int32_t wb_particle_group(const wb_world *w, int32_t p) { return w->m.group[p]; }
wb_real wb_particle_friction(const wb_world *w, int32_t p) { return w->m.cfric[p]; }
bool wb_particle_collides(const wb_world *w, int32_t p) { return (w->m.cflags[p] & WB_CF_COLLIDE) != 0; }

void wb_particle_set_group(wb_world *w, int32_t p, int32_t group)
{
    w->m.group[p] = group > 0 ? group : 0;
    w->k.pc.scan_dirty = 1;
}

void wb_particle_set_friction(wb_world *w, int32_t p, wb_real mu) { w->m.cfric[p] = mu; }

void wb_body_set_contacts(wb_world *w, wb_body b, bool collide, bool self_collide, wb_real friction)
{
    const uint8_t f = (uint8_t)((collide ? WB_CF_COLLIDE : 0) | (self_collide ? WB_CF_SELF : 0));
    for (int32_t i = b.first; i < b.first + b.count; i++) {
        w->m.group[i] = b.group;
        w->m.cflags[i] = f;
        w->m.cfric[i] = friction;
    }
    w->k.pc.scan_dirty = 1;
}

wb_status wb__body_finish(wb_world *w, int32_t first, int32_t count, wb_body *out)
{
    out->group = wb_group_new(w); /* before the new particles join it */
    out->first = first;
    out->count = count;
    wb_body_set_contacts(w, *out, true, false, 0);
    return WB_OK;
}

void wb_group_set_self_collide(wb_world *w, int32_t group, bool on)
{
    for (int32_t i = 0; i < w->m.np; i++) {
        if (w->m.group[i] != group) continue;
        if (on) w->m.cflags[i] |= WB_CF_SELF;
        else w->m.cflags[i] &= (uint8_t)~WB_CF_SELF;
    }
    w->k.pc.scan_dirty = 1;
}

bool wb_group_self_collide(const wb_world *w, int32_t group)
{
    for (int32_t i = 0; i < w->m.np; i++)
        if (w->m.group[i] == group && (w->m.cflags[i] & WB_CF_SELF)) return true;
    return false;
}

void wb_particle_set_radius(wb_world *w, int32_t p, wb_real r) { w->m.radius[p] = r; }

wb_real wb_body_spacing(const wb_world *w, wb_body b)
{
    const wb_model *m = &w->m;
    if (b.count <= 0) return 0;
    wb_real *shortest = malloc(sizeof *shortest * (size_t)b.count);
    if (!shortest) return 0;
    for (int32_t i = 0; i < b.count; i++) shortest[i] = INFINITY;
    for (int32_t s = 0; s < m->nd; s++) {
        if (!(m->d_gen[s] & 1u)) continue;
        const int32_t e[2] = { m->d_ij[2 * s] - b.first, m->d_ij[2 * s + 1] - b.first };
        wb_real d[3];
        v3_sub(d, &w->s.x[3 * m->d_ij[2 * s + 1]], &w->s.x[3 * m->d_ij[2 * s]]);
        const wb_real len = v3_len(d);
        for (int k = 0; k < 2; k++)
            if (e[k] >= 0 && e[k] < b.count && len > 0 && len < shortest[e[k]]) shortest[e[k]] = len;
    }
    wb_real sum = 0;
    int32_t n = 0;
    for (int32_t i = 0; i < b.count; i++)
        if (isfinite(shortest[i])) { sum += shortest[i]; n++; }
    free(shortest);
    return n > 0 ? sum / n : 0;
}

/* ---- broad phase ---------------------------------------------------------------------------- */
static uint32_t cell_hash(int64_t x, int64_t y, int64_t z, uint32_t mask)
{
    /* Teschner et al. 2003's primes; unsigned arithmetic wraps without undefined behaviour */
    return (uint32_t)(((uint64_t)x * 73856093u) ^ ((uint64_t)y * 19349663u) ^ ((uint64_t)z * 83492791u)) & mask;
}

/* cell coordinate, clamped so that the cast stays defined for huge or tiny positions
 * (particles past 1e15 cells from the origin share the last cell: still found, merely
 * tested against more neighbours) */
static int64_t cell_of(wb_real x, wb_real inv)
{
    const wb_real c = floor(x * inv);
    return c > 1e15 ? (int64_t)1e15 : c < -1e15 ? -(int64_t)1e15 : (int64_t)c;
}

int32_t wb__broadphase(wb_contacts *c, const wb_real *x, const wb_real *reach, int32_t n,
                       int (*keep)(void *ud, int32_t i, int32_t j), void *ud)
{
    /* the cell is the largest reach diameter: a pair within reach_i + reach_j lies in
     * neighbouring cells (at most one apart on every axis) */
    wb_real rmax = 0;
    int32_t na = 0;
    for (int32_t i = 0; i < n; i++)
        if (reach[i] >= 0) { na++; if (reach[i] > rmax) rmax = reach[i]; }
    if (na < 2 || !(rmax > 0) || !isfinite(rmax)) return c->n;
    const wb_real inv = 1 / (2 * rmax);
    uint32_t size = 16;
    while (size < 2 * (uint32_t)na && size < (1u << 30)) size *= 2;
    const uint32_t mask = size - 1;
    int32_t *cs = wb__grow(c->cell_start, &c->cap_cells, (int32_t)size + 1, sizeof *cs);
    if (!cs) return -1;
    c->cell_start = cs;
    int32_t *ids = wb__grow(c->cell_ids, &c->cap_ids, na, sizeof *ids);
    if (!ids) return -1;
    c->cell_ids = ids;
    int32_t *stamp = wb__grow(c->stamp, &c->cap_stamp, (int32_t)size, sizeof *stamp);
    if (!stamp) return -1;
    c->stamp = stamp;
    for (uint32_t b = 0; b < size; b++) stamp[b] = -1;
    /* counting sort by bucket; particles stay in index order inside a bucket */
    memset(cs, 0, sizeof *cs * (size + 1));
    for (int32_t i = 0; i < n; i++) {
        if (reach[i] < 0) continue;
        const wb_real *p = &x[3 * i];
        cs[cell_hash(cell_of(p[0], inv), cell_of(p[1], inv), cell_of(p[2], inv), mask) + 1]++;
    }
    for (uint32_t b = 0; b < size; b++) cs[b + 1] += cs[b];
    for (int32_t i = 0; i < n; i++) {
        if (reach[i] < 0) continue;
        const wb_real *p = &x[3 * i];
        ids[cs[cell_hash(cell_of(p[0], inv), cell_of(p[1], inv), cell_of(p[2], inv), mask)]++] = i;
    }
    for (uint32_t b = size; b > 0; b--) cs[b] = cs[b - 1]; /* back to starts */
    cs[0] = 0;
    for (int32_t i = 0; i < n; i++) {
        if (reach[i] < 0) continue;
        const wb_real *p = &x[3 * i];
        const int64_t cx = cell_of(p[0], inv), cy = cell_of(p[1], inv), cz = cell_of(p[2], inv);
        /* the 27 neighbour cells' buckets, each once: two cells hashing to one bucket
         * must not report its particles twice (a stamp per bucket: the last particle
         * that visited it) */
        for (int dz = -1; dz <= 1; dz++)
            for (int dy = -1; dy <= 1; dy++)
                for (int dx = -1; dx <= 1; dx++) {
                    const uint32_t bk = cell_hash(cx + dx, cy + dy, cz + dz, mask);
                    if (stamp[bk] == i) continue;
                    stamp[bk] = i;
                    for (int32_t s = cs[bk]; s < cs[bk + 1]; s++) {
                        const int32_t j = ids[s];
                        if (j <= i) continue;
                        const wb_real *q = &x[3 * j];
                        const wb_real d0 = q[0] - p[0], d1 = q[1] - p[1], d2 = q[2] - p[2], r = reach[i] + reach[j];
                        if (d0 * d0 + d1 * d1 + d2 * d2 >= r * r) continue;
                        if (keep && !keep(ud, i, j)) continue;
                        int32_t *ij = wb__grow(c->ij, &c->cap, 2 * (c->n + 1), sizeof *ij);
                        if (!ij) return -1;
                        c->ij = ij;
                        ij[2 * c->n] = i;
                        ij[2 * c->n + 1] = j;
                        c->n++;
                    }
                }
    }
    return c->n;
}

/* ---- which pairs may touch -------------------------------------------------------------------- */
static int cmp_u64(const void *a, const void *b)
{
    uint64_t x = *(const uint64_t *)a, y = *(const uint64_t *)b;
    return x < y ? -1 : x > y;
}

static uint64_t pair_key(int32_t a, int32_t b)
{
    return a < b ? (uint64_t)(uint32_t)a << 32 | (uint32_t)b : (uint64_t)(uint32_t)b << 32 | (uint32_t)a;
}

/* the live constraints' pairs, sorted, for the self-collision rule */
static int build_keys(wb_world *w)
{
    wb_contacts *c = &w->k.pc;
    const wb_model *m = &w->m;
    uint64_t *k = wb__grow(c->keys, &c->cap_keys, m->nd_live > 0 ? m->nd_live : 1, sizeof *k);
    if (!k) return 0;
    c->keys = k;
    c->nkeys = 0;
    for (int32_t s = 0; s < m->nd; s++)
        if (m->d_gen[s] & 1u) k[c->nkeys++] = pair_key(m->d_ij[2 * s], m->d_ij[2 * s + 1]);
    qsort(k, (size_t)c->nkeys, sizeof *k, cmp_u64);
    c->keys_dirty = 0;
    return 1;
}

static int joined(const wb_contacts *c, int32_t i, int32_t j)
{
    const uint64_t key = pair_key(i, j);
    int32_t lo = 0, hi = c->nkeys;
    while (lo < hi) {
        const int32_t mid = lo + (hi - lo) / 2;
        if (c->keys[mid] < key) lo = mid + 1;
        else hi = mid;
    }
    return lo < c->nkeys && c->keys[lo] == key;
}

static int may_touch(void *ud, int32_t i, int32_t j)
{
    const wb_world *w = ud;
    const wb_model *m = &w->m;
    if (m->w[i] == 0 && m->w[j] == 0) return 0;
    const int32_t gi = m->group[i], gj = m->group[j];
    if (gi != gj || gi == 0) return (m->cflags[i] & m->cflags[j] & WB_CF_COLLIDE) != 0;
    /* one body: only when it self-collides, and never between rest neighbours */
    if (!(m->cflags[i] & m->cflags[j] & WB_CF_SELF)) return 0;
    wb_real d[3];
    v3_sub(d, &m->x0[3 * j], &m->x0[3 * i]);
    const wb_real r = m->radius[i] + m->radius[j];
    if (v3_dot(d, d) < r * r) return 0;
    return !joined(&w->k.pc, i, j);
}

/* whether any pair could collide at all: one body without self-collision costs nothing */
static int any_possible(const wb_model *m)
{
    int32_t loose = 0, g1 = -1;
    int groups = 0;
    for (int32_t i = 0; i < m->np; i++) {
        const uint8_t f = m->cflags[i];
        if (f & WB_CF_SELF) return 1;
        if (!(f & WB_CF_COLLIDE)) continue;
        if (m->group[i] == 0) loose++;
        else if (g1 < 0) { g1 = m->group[i]; groups = 1; }
        else if (m->group[i] != g1) groups = 2;
        if (loose >= 2 || groups >= 2 || (loose >= 1 && groups >= 1)) return 1;
    }
    return 0;
}

/* ---- the step ---------------------------------------------------------------------------------- */
void wb__contacts_begin(wb_world *w)
{
    wb_model *m = &w->m;
    wb_contacts *c = &w->k.pc;
    c->n = 0;
    c->nact = 0;
    c->last = 0;
    c->broad_ms = 0;
    if (!m->def.contacts || m->np < 2) return;
    if (c->scan_dirty || c->scanned_np != m->np) {
        c->possible = any_possible(m);
        c->scanned_np = m->np;
        c->scan_dirty = 0;
    }
    if (!c->possible) return;
    const double t0 = now_ms();
    if (c->keys_dirty || c->nkeys == 0) {
        if (!build_keys(w)) { wb__warn(w, "out of memory in the contact broad phase; contacts skipped"); return; }
    }
    wb_real *reach = wb__grow(c->reach, &c->cap_reach, m->np, sizeof *reach);
    if (!reach) { wb__warn(w, "out of memory in the contact broad phase; contacts skipped"); return; }
    c->reach = reach;
    /* swept bounds: how far a particle can get this frame (its velocity and gravity over
     * dt), plus a quarter of its radius for what the constraints move it */
    const wb_real dt = m->def.dt, g = v3_len(m->def.gravity) * dt * dt;
    for (int32_t i = 0; i < m->np; i++) {
        const int in = m->group[i] == 0 || (m->cflags[i] & (WB_CF_COLLIDE | WB_CF_SELF));
        reach[i] = in ? m->radius[i] * (wb_real)1.25 + v3_len_safe(&w->s.v[3 * i]) * dt + g : -1;
        if (!isfinite(reach[i])) reach[i] = -1;
    }
    if (wb__broadphase(c, w->s.x, reach, m->np, may_touch, w) < 0) {
        c->n = 0;
        wb__warn(w, "out of memory in the contact broad phase; contacts skipped");
    }
    c->broad_ms = now_ms() - t0;
}

/* Project every candidate once, in list order (Gauss-Seidel): push the pair apart along
 * their line by the overlap, split by inverse mass, then undo their relative tangential
 * slip of this substep when it is within the friction cone (mu x depth). */
void wb__contacts_project(wb_world *w, wb_real h)
{
    wb_contacts *c = &w->k.pc;
    c->nact = 0;
    if (c->n == 0) { c->last = 0; return; }
    int32_t touching = 0;
    const wb_model *m = &w->m;
    wb_real *x = w->s.x;
    const wb_real *xp = w->s.x_prev, *wv = m->w, *rad = m->radius, vmax = m->def.max_depenetration;
    int32_t *act = wb__grow(c->act, &c->cap_act, c->n, sizeof *act);
    if (!act) goto nomem;
    c->act = act;
    wb_real *nds = wb__grow(c->act_nd, &c->cap_nd, 6 * c->n, sizeof *nds);
    if (!nds) goto nomem;
    c->act_nd = nds;
    wb_real *left = wb__grow(c->left, &c->cap_left, c->n, sizeof *left);
    if (!left) goto nomem;
    c->left = left;
    /* a new candidate list (wb__contacts_begin clears c->last; so does a substep with no
     * contact, whose pairs were left with nothing): what each pair was left with is not
     * known, and all of its overlap counts as old. Worked out from the state alone, so
     * a step interrupted and run again gives the same result */
    if (c->last == 0)
        for (int32_t k = 0; k < c->n; k++) left[k] = INFINITY;
    for (int32_t k = 0; k < c->n; k++) {
        const int32_t i = c->ij[2 * k], j = c->ij[2 * k + 1];
        const wb_real wi = wv[i], wj = wv[j], wsum = wi + wj;
        if (wsum == 0) continue;
        wb_real *xi = &x[3 * i], *xj = &x[3 * j];
        wb_real d[3];
        v3_sub(d, xj, xi);
        const wb_real r = rad[i] + rad[j], d2 = v3_dot(d, d);
        if (!(d2 < r * r)) {
            /* in touch (left at r_i + r_j by the last substep, to round-off): a contact
             * for the count, with nothing to correct */
            const wb_real rt = r * (1 + (wb_real)1e-9);
            if (d2 <= rt * rt) touching++;
            left[k] = 0;
            continue;
        }
        wb_real n[3];
        const wb_real len = sqrt(d2);
        if (len > r * (wb_real)1e-9) v3_scale(n, d, 1 / len);
        else v3_set(n, 0, 1, 0); /* coincident: any direction separates them */
        /* d0: the overlap the pair started the substep with (at x_prev). Most of it is
         * what the contact pass left to the links and colliders after it, or what later
         * pairs of the pass pushed back (Gauss-Seidel): repaired in full, as every
         * substep must, or a heap's layers sink into each other. What is older, the
         * overlap this pair was itself left with last substep (bodies made inside each
         * other, a deep squeeze; before a frame's first substep all of d0 counts), goes
         * at no more than max_depenetration x h per substep, so that a body is not
         * squashed in one substep. Neither becomes speed (wb__contacts_velocity) */
        wb_real depth = r - len, dp[3];
        v3_sub(dp, &xp[3 * j], &xp[3 * i]);
        const wb_real d0 = r - v3_len(dp), old = d0 < left[k] ? d0 : left[k], keep = old - vmax * h;
        if (keep > 0) depth = depth > keep ? depth - keep : 0;
        left[k] = r - len - depth;
        if (!(depth > 0)) { touching++; continue; }
        const wb_real err = !(d0 > 0) ? 0 : d0 < depth ? d0 : depth; /* of it, old overlap */
        if (wi > 0) v3_madd(xi, n, -depth * wi / wsum);
        if (wj > 0) v3_madd(xj, n, depth * wj / wsum);
        /* friction at position level (Macklin et al. 2014, "Unified particle physics", §6.1):
         * the relative tangential slip of the substep is undone up to mu x depth, all of it
         * inside the cone (static), mu x depth of it outside (kinetic). Bounded per contact
         * by its own depth, so a load split over several contacts gets the same friction
         * as one contact (a plain all-or-nothing test would fail on each half) */
        const wb_real mu = (m->cfric[i] + m->cfric[j]) / 2;
        if (mu > 0) {
            wb_real slip[3];
            for (int a = 0; a < 3; a++) slip[a] = (xi[a] - xp[3 * i + a]) - (xj[a] - xp[3 * j + a]);
            v3_madd(slip, n, -v3_dot(slip, n));
            const wb_real sl = v3_len(slip), cap = mu * depth;
            if (sl > 0) {
                const wb_real f = sl < cap ? 1 : cap / sl;
                if (wi > 0) v3_madd(xi, slip, -f * wi / wsum);
                if (wj > 0) v3_madd(xj, slip, f * wj / wsum);
            }
        }
        /* normal, depth and old overlap, kept for the velocity pass; the normal force for
         * the readout (XPBD multiplier of a zero-compliance contact, depth / (w_i + w_j), over h^2) */
        act[c->nact] = k;
        v3_copy(&nds[6 * c->nact], n);
        nds[6 * c->nact + 3] = depth;
        nds[6 * c->nact + 4] = depth / wsum / (h * h);
        nds[6 * c->nact + 5] = err;
        c->nact++;
    }
    c->last = c->nact + touching;
    return;
nomem:
    c->last = 0;
    wb__warn(w, "out of memory in contacts; contacts skipped this substep");
}

/* after v = (x - x_prev)/h: no approach speed left (perfectly inelastic; friction was
 * applied at position level, so the tangential velocity is already what it implies),
 * and no speed made out of old overlap.
 *
 * A correction of depth adds depth / h to the pair's separating speed. The part that
 * takes back this substep's approach is the collision; the part that removed overlap
 * the pair already had (err, from the projection) is the repair of a position error
 * (bodies made inside each other, a ball squeezed into a pile): kept as speed it
 * would fling them apart at up to depth / h (2 cm at h = 1/600 s: 12 m/s). So it is
 * taken out of the velocity again, both particles along n split by inverse mass
 * (momentum exact), and the pair leaves with what the rest of the step gave it (what
 * Bullet's split impulse does for rigid bodies). Pushing that overlap out slowly (at
 * most max_depenetration x h per substep, in the projection) keeps a body from being
 * squashed in one substep, which its links would then turn into the same speed. */
void wb__contacts_velocity(wb_world *w, wb_real h)
{
    wb_contacts *c = &w->k.pc;
    const wb_model *m = &w->m;
    wb_real *v = w->s.v;
    for (int32_t a = 0; a < c->nact; a++) {
        const int32_t k = c->act[a], i = c->ij[2 * k], j = c->ij[2 * k + 1];
        const wb_real wi = m->w[i], wj = m->w[j], wsum = wi + wj, e = c->act_nd[6 * a + 5] / h;
        if (!(e > 0) || wsum == 0) continue;
        const wb_real *n = &c->act_nd[6 * a];
        if (wi > 0) v3_madd(&v[3 * i], n, e * wi / wsum);
        if (wj > 0) v3_madd(&v[3 * j], n, -e * wj / wsum);
    }
    for (int32_t a = 0; a < c->nact; a++) {
        const int32_t k = c->act[a], i = c->ij[2 * k], j = c->ij[2 * k + 1];
        const wb_real wi = m->w[i], wj = m->w[j], wsum = wi + wj;
        if (wsum == 0) continue;
        const wb_real *n = &c->act_nd[6 * a];
        wb_real *vi = &v[3 * i], *vj = &v[3 * j], u[3];
        v3_sub(u, vj, vi);
        const wb_real un = v3_dot(u, n);
        if (!(un < 0)) continue;
        /* change u = vj - vi by -un n, split by inverse mass */
        if (wi > 0) v3_madd(vi, n, un * wi / wsum);
        if (wj > 0) v3_madd(vj, n, -un * wj / wsum);
    }
}

/* ---- readout of the last substep's contacts ------------------------------------------------ */
int32_t wb_world_contact_count(const wb_world *w) { return w->k.pc.nact; }

wb_contact wb_world_contact_at(const wb_world *w, int32_t i)
{
    const wb_contacts *c = &w->k.pc;
    wb_contact out = { -1, -1, 0, { 0, 0, 0 }, 0 };
    if (i < 0 || i >= c->nact) return out;
    const int32_t k = c->act[i];
    const wb_real *nd = &c->act_nd[6 * i];
    out.a = c->ij[2 * k];
    out.b = c->ij[2 * k + 1];
    v3_copy(out.normal, nd);
    out.depth = nd[3];
    out.force = nd[4];
    return out;
}
