/* rigid_particle.c: two-way contacts between particles and rigid bodies.
 *
 * A particle (its sphere of contact radius) against a body's shape: C = dist - radius >= 0,
 * dist and the outward normal n from wb__shape_distance at the body's current pose. Each
 * substep a violated contact is projected as an XPBD inequality with compliance 0 and the
 * body's generalized inverse mass at the point (Müller et al. 2020, eq. 2-3): lambda =
 * depth / (w_p + w_body), the particle moves by w_p lambda n and the body takes the
 * positional impulse -lambda n (wb__rigid_apply). A light particle barely moves a heavy
 * body; a heavy body pushes the particles until their constraints hold it.
 *
 * Every impulse (normal, static friction at position level, dynamic friction and
 * restitution at velocity level, §3.5-3.6 as rigid.c does for its own contacts) acts on
 * the body at the particle's centre with the opposite sign of the particle's: linear
 * momentum is exchanged exactly, and since both act at one point, so is angular
 * momentum about any origin (a particle has no spin to take up the torque a surface
 * point would leave). For the normal the centre is on the contact's line of action
 * anyway (the surface point is x - dist n).
 *
 * Candidates once per frame: every particle that collides (WB_CF_COLLIDE) whose swept
 * sphere (radius x 1.25 + |v| dt + |g| dt^2, as broadphase.c's reach) meets a body's
 * swept bounding sphere (its bound + |v| dt + |om| bound dt + |g| dt^2). A particle
 * outside the box around all those spheres is dropped with six comparisons; for the
 * others the bodies whose sphere spans the particle's coordinate along one axis (the one
 * the bodies spread most along; the spheres sorted by their low end, two binary searches)
 * take the sphere test: O(np log nb + candidates), not np x nb. Nothing at all without
 * rigid bodies. The list is in particle order, then body slot order, and projected
 * serially: the same for any thread count. */
#include "attach.h"
#include "contact.h"
#include "rigid.h"

static int live(const wb_rigids *rb, int32_t r) { return rb->gen[r] & 1u; }

/* the first of the n sorted keys at or above v */
static int32_t lower_bound(const wb_real *key, int32_t n, wb_real v)
{
    int32_t lo = 0, hi = n;
    while (lo < hi) {
        const int32_t mid = lo + (hi - lo) / 2;
        if (key[mid] < v) lo = mid + 1;
        else hi = mid;
    }
    return lo;
}

static int cmp_key(const void *pa, const void *pb)
{
    /* (low end, packed index) pairs of reals: by the low end, ties by index */
    const wb_real *a = pa, *b = pb;
    return a[0] < b[0] ? -1 : a[0] > b[0] ? 1 : (a[1] > b[1]) - (a[1] < b[1]);
}

static int cmp_i32(const void *pa, const void *pb)
{
    const int32_t a = *(const int32_t *)pa, b = *(const int32_t *)pb;
    return (a > b) - (a < b);
}

void wb__rigid_particles_begin(wb_world *w)
{
    wb_rigids *rb = w->rb;
    if (!rb) return;
    rb->npc = 0;
    rb->npct = 0;
    const wb_model *m = &w->m;
    int32_t nb = 0;
    for (int32_t r = 0; r < rb->n; r++) nb += live(rb, r);
    if (nb == 0 || m->np == 0) return;
    const wb_real dt = m->def.dt, g = v3_len(m->def.gravity) * dt * dt;
    /* the bodies' swept spheres, packed: centre, radius; then the sort keys (low end,
     * packed index) and the sorted low ends */
    wb_real *sph = wb__grow(rb->pc_sph, &rb->cap_sph, 8 * nb, sizeof *sph);
    if (!sph) goto nomem;
    rb->pc_sph = sph;
    int32_t *slot = wb__grow(rb->pc_slot, &rb->cap_slot, 2 * nb, sizeof *slot); /* slots, then a particle's hits */
    if (!slot) goto nomem;
    rb->pc_slot = slot;
    nb = 0;
    wb_real lo[3] = { INFINITY, INFINITY, INFINITY }, hi[3] = { -INFINITY, -INFINITY, -INFINITY };
    for (int32_t r = 0; r < rb->n; r++) {
        if (!live(rb, r)) continue;
        v3_copy(&sph[4 * nb], &rb->x[3 * r]);
        sph[4 * nb + 3] = rb->bound[r] + dt * (v3_len(&rb->v[3 * r]) + v3_len(&rb->om[3 * r]) * rb->bound[r]) + g;
        for (int c = 0; c < 3; c++) {
            lo[c] = fmin(lo[c], sph[4 * nb + c] - sph[4 * nb + 3]);
            hi[c] = fmax(hi[c], sph[4 * nb + c] + sph[4 * nb + 3]);
        }
        slot[nb++] = r;
    }
    /* the sweep axis: where the bodies' box is longest; keys sorted by the low end */
    const int ax = hi[0] - lo[0] >= hi[1] - lo[1] && hi[0] - lo[0] >= hi[2] - lo[2] ? 0 : hi[1] - lo[1] >= hi[2] - lo[2] ? 1 : 2;
    wb_real *key = sph + 4 * nb, *low = sph + 6 * nb, wmax = 0;
    for (int32_t b = 0; b < nb; b++) {
        key[2 * b] = sph[4 * b + ax] - sph[4 * b + 3];
        key[2 * b + 1] = b;
        wmax = fmax(wmax, 2 * sph[4 * b + 3]);
    }
    qsort(key, (size_t)nb, 2 * sizeof *key, cmp_key);
    for (int32_t b = 0; b < nb; b++) low[b] = key[2 * b];
    int32_t *hits = slot + nb;
    const wb_real *x = w->s.x, *v = w->s.v;
    const wb_attaches *att = wb__attach_skips(w);
    for (int32_t i = 0; i < m->np; i++) {
        if (!(m->cflags[i] & WB_CF_COLLIDE)) continue;
        const wb_real reach = m->radius[i] * (wb_real)1.25 + v3_len(&v[3 * i]) * dt + g;
        if (!isfinite(reach)) continue;
        /* outside the box around all the bodies' spheres: none of them */
        const wb_real *xi = &x[3 * i];
        if (xi[0] < lo[0] - reach || xi[0] > hi[0] + reach || xi[1] < lo[1] - reach || xi[1] > hi[1] + reach ||
            xi[2] < lo[2] - reach || xi[2] > hi[2] + reach)
            continue;
        /* a sphere meeting the particle's has its low end within [x - reach - wmax, x + reach] */
        int32_t nh = 0;
        for (int32_t k = lower_bound(low, nb, xi[ax] - reach - wmax); k < nb && low[k] <= xi[ax] + reach; k++) {
            const int32_t b = (int32_t)key[2 * k + 1];
            wb_real d[3];
            v3_sub(d, &x[3 * i], &sph[4 * b]);
            const wb_real s = reach + sph[4 * b + 3];
            if (v3_dot(d, d) < s * s) hits[nh++] = b;
        }
        if (nh > 1) qsort(hits, (size_t)nh, sizeof *hits, cmp_i32); /* body order (packed = slot order) */
        for (int32_t k = 0; k < nh; k++) {
            const int32_t b = hits[k];
            if (att && wb__attach_skip(att, i, -1 - slot[b])) continue; /* tied to it: no contact */
            int32_t *pc = wb__grow(rb->pc, &rb->cap_pc, 2 * (rb->npc + 1), sizeof *pc);
            if (!pc) goto nomem;
            rb->pc = pc;
            pc[2 * rb->npc] = i;
            pc[2 * rb->npc + 1] = slot[b];
            rb->npc++;
        }
    }
    /* the overlap each candidate has now counts as made (kept) unless one substep would
     * take it all anyway, as contact.c does at a frame's start: from the state alone */
    wb_real *left = wb__grow(rb->pc_left, &rb->cap_left, rb->npc > 0 ? rb->npc : 1, sizeof *left);
    if (!left) goto nomem;
    rb->pc_left = left;
    const wb_real step = m->def.max_depenetration * dt / m->def.substeps;
    for (int32_t k = 0; k < rb->npc; k++) {
        const int32_t i = rb->pc[2 * k], r = rb->pc[2 * k + 1];
        wb_real n[3];
        const wb_real d0 = m->radius[i] - wb__shape_distance(&rb->shape[r], &rb->x[3 * r], &rb->q[4 * r], &x[3 * i], n);
        left[k] = d0 > step ? d0 : 0;
    }
    return;
nomem:
    rb->npc = 0;
    wb__warn(w, "out of memory in particle-rigid contacts; they are skipped this frame");
}

/* body r's velocity at world point x */
static void body_velocity(const wb_rigids *rb, int32_t r, const wb_real x[3], wb_real out[3])
{
    wb_real d[3];
    v3_sub(d, x, &rb->x[3 * r]);
    v3_cross(out, &rb->om[3 * r], d);
    v3_add(out, out, &rb->v[3 * r]);
}

/* The contacts' normal corrections are solved together (projected Gauss-Seidel, sweeps
 * alternately forward and backward, against the bodies' poses at the pass's start, each
 * body's move and turn so far kept aside and applied once at the end): a body resting on
 * several particles comes out of all of them at once, and heavy particles (or immovable
 * ones) under a body are not pushed out one by one as if each held it alone. With one
 * Jacobi pass that saw the body N times heavier for N contacts (mass splitting), a box
 * landing flat on immovable particles came out by less than its overlap (an edge
 * particle's share also turned it), kept the rest to the next substep, and was pushed out
 * of it there in full: it rebounded at 12% of its impact speed with restitution 0. The
 * symmetric sweeps leave no corner first (one forward Gauss-Seidel pass tilted a box
 * landing flat: it drifted off a block). Friction stays per contact, split among a
 * body's contacts. Particles move at once. */
#define JOINT_SWEEPS 64
#define JOINT_TOL_X ((wb_real)1e-9)  /* m: a sweep that moves nothing more ends the solve */
#define JOINT_TOL_V ((wb_real)1e-7)  /* m/s */

/* body r's move so far at arm a (bd: move, turn) */
static void joint_point(const wb_real *bd, const wb_real a[3], wb_real out[3])
{
    v3_cross(out, &bd[3], a);
    v3_add(out, out, bd);
}

/* body r takes -dl n at arm a into bd */
static void joint_take(const wb_world *w, int32_t r, wb_real *bd, const wb_real a[3], const wb_real n[3], wb_real dl)
{
    wb_real t[3];
    v3_madd(bd, n, -dl * w->rb->inv_mass[r]);
    v3_cross(t, a, n);
    wb__rigid_inv_inertia(w, r, t, t);
    v3_madd(&bd[3], t, -dl);
}

static wb_real *joint_scratch(wb_rigids *rb)
{
    wb_real *bd = wb__grow(rb->pc_bd, &rb->cap_bd, 6 * rb->n, sizeof *bd);
    if (!bd) return NULL;
    rb->pc_bd = bd;
    memset(bd, 0, sizeof *bd * 6 * (size_t)rb->n);
    return bd;
}

void wb__rigid_particles_solve(wb_world *w)
{
    wb_rigids *rb = w->rb;
    if (!rb) return;
    rb->npct = 0;
    if (rb->npc == 0) return;
    const wb_model *m = &w->m;
    wb_real *x = w->s.x, *xp = w->s.x_prev, *left = rb->pc_left;
    const wb_real step = m->def.max_depenetration * w->k.h_last;
    int32_t *cnt = wb__grow(rb->pc_cnt, &rb->cap_cnt, rb->n, sizeof *cnt);
    if (!cnt) goto nomem;
    rb->pc_cnt = cnt;
    memset(cnt, 0, sizeof *cnt * (size_t)rb->n);
    /* the overlaps at the pass's start */
    for (int32_t k = 0; k < rb->npc; k++) {
        const int32_t i = rb->pc[2 * k], r = rb->pc[2 * k + 1];
        if (!live(rb, r)) continue;
        wb_real n[3], n0[3];
        wb_real depth = m->radius[i] - wb__shape_distance(&rb->shape[r], &rb->x[3 * r], &rb->q[4 * r], &x[3 * i], n);
        if (!(depth > 0)) { left[k] = 0; continue; }
        /* the overlap at the substep's start (the particle's x_prev, the body's start
         * pose): what of it the candidate kept goes at no more than max_depenetration, its
         * push moving the start poses too (slow), the rest in full with its speed taken
         * out in the velocity pass (err); what the substep drove in, in full (contact.c) */
        const wb_real d0 = m->radius[i] - wb__shape_distance(&rb->shape[r], &rb->x_prev[3 * r], &rb->q_prev[4 * r], &xp[3 * i], n0);
        wb_real slow, err;
        depth = wb__contact_depth(depth, d0, &left[k], step, &slow, &err);
        if (!(depth > 0)) continue;
        wb_rpcontact *ct = wb__grow(rb->pct, &rb->cap_pct, rb->npct + 1, sizeof *ct);
        if (!ct) goto nomem;
        rb->pct = ct;
        ct = &ct[rb->npct++];
        ct->i = i;
        ct->r = r;
        v3_copy(ct->n, n);
        ct->depth = depth;
        ct->slow = slow;
        ct->err = err;
        ct->lambda = 0;
        v3_copy(ct->x0, &x[3 * i]);
        /* where the positional impulses act on the body: the particle's offset from the
         * centre at the substep's start (see the file's head) */
        v3_sub(ct->arm, &xp[3 * i], &rb->x_prev[3 * r]);
        wb_real at[3];
        v3_add(at, ct->arm, &rb->x[3 * r]);
        ct->wb = wb__rigid_w(w, r, at, n);
        /* the normal velocity they came in with, for restitution */
        wb_real vb[3], rel[3];
        body_velocity(rb, r, &x[3 * i], vb);
        v3_sub(rel, &w->s.v[3 * i], vb);
        ct->vn_pre = v3_dot(rel, n);
        cnt[r]++;
    }
    if (rb->npct == 0) return;
    wb_real *bd = joint_scratch(rb);
    if (!bd) goto nomem;
    for (int sweep = 0, more = 1; sweep < JOINT_SWEEPS && more; sweep++) {
        more = 0;
        for (int32_t j = 0; j < rb->npct; j++) {
            wb_rpcontact *ct = &rb->pct[sweep & 1 ? rb->npct - 1 - j : j];
            const int32_t i = ct->i, r = ct->r;
            const wb_real *n = ct->n, wp = m->w[i], den = wp + ct->wb;
            if (!(den > 0)) continue;
            wb_real d[3], mv[3];
            joint_point(&bd[6 * r], ct->arm, d);
            v3_sub(mv, &x[3 * i], ct->x0);
            const wb_real res = ct->depth - v3_dot(n, mv) + v3_dot(n, d);
            const wb_real lam = fmax(ct->lambda + res / den, 0), dl = lam - ct->lambda;
            if (dl == 0) continue;
            more |= fabs(dl) * den > JOINT_TOL_X;
            ct->lambda = lam;
            v3_madd(&x[3 * i], n, wp * dl);
            joint_take(w, r, &bd[6 * r], ct->arm, n, dl);
        }
    }
    for (int32_t k = 0; k < rb->npct; k++) {
        wb_rpcontact *ct = &rb->pct[k];
        const int32_t i = ct->i, r = ct->r;
        const wb_real *n = ct->n, mu = rb->shape[r].friction, wp = m->w[i], split = cnt[r], lam = ct->lambda;
        wb_real *xi = &x[3 * i], at[3];
        v3_add(at, ct->arm, &rb->x[3 * r]);
        /* of the correction, the made overlap's slow part moves the start poses too */
        ct->lslow = ct->slow > 0 ? lam * ct->slow / ct->depth : 0;
        v3_scale(ct->dp, n, -lam);
        if (ct->lslow > 0) v3_madd(&xp[3 * i], n, wp * ct->lslow);
        /* static friction (§3.5): undo the relative tangential slip of the substep when the
         * impulse it takes stays inside the cone, mu x lambda */
        if (!(mu > 0) || !(lam > 0)) continue;
        wb_real l[3], prev[3], slip[3];
        wb__rigid_to_local(w, r, xi, l);
        q_rotate(&rb->q_prev[4 * r], l, prev);
        v3_add(prev, prev, &rb->x_prev[3 * r]);
        /* (the body's point now is xi itself) */
        for (int c = 0; c < 3; c++) slip[c] = prev[c] - xp[3 * i + c];
        v3_madd(slip, n, -v3_dot(slip, n));
        const wb_real len = v3_len(slip);
        if (!(len > 0)) continue;
        wb_real t[3];
        v3_scale(t, slip, 1 / len);
        const wb_real lt = len / (wp + split * wb__rigid_w(w, r, at, t));
        if (lt < mu * lam) {
            v3_madd(ct->dp, t, lt);
            v3_madd(xi, t, -wp * lt);
        }
    }
    for (int32_t k = 0; k < rb->npct; k++) {
        const wb_rpcontact *ct = &rb->pct[k];
        wb_real at[3];
        v3_add(at, ct->arm, &rb->x[3 * ct->r]);
        wb__rigid_apply(w, ct->r, at, ct->dp);
        if (ct->lslow > 0) {
            wb_real ds[3];
            v3_scale(ds, ct->n, -ct->lslow);
            wb__rigid_apply_start(w, ct->r, at, ds);
        }
    }
    return;
nomem:
    rb->npct = 0;
    wb__warn(w, "out of memory in particle-rigid contacts; they are skipped this substep");
}

/* Dynamic friction (§3.6) on the velocities the poses gave, split among a body's contacts:
 * the tangential relative velocity loses at most mu lambda / h. Then the normal relative
 * velocity of every contact of the substep is set to -e times the one it came in with (0
 * below 2 |g| h, so that resting contact does not jitter; Müller et al. 2020 eq. 34),
 * solved together as the positions are: an approach left by the pass is stopped, and a
 * separating speed the pass made (pushing out an overlap the substep began with, which
 * is not a bounce) is taken out, by a pull no larger than the push the contact gave this
 * substep (lambda / h). Impulses act at the particle's centre */
void wb__rigid_particles_velocity(wb_world *w, wb_real h)
{
    wb_rigids *rb = w->rb;
    if (!rb || rb->npct == 0) return;
    const wb_model *m = &w->m;
    const wb_real g = v3_len(m->def.gravity);
    for (int32_t k = 0; k < rb->npct; k++) {
        wb_rpcontact *ct = &rb->pct[k];
        const int32_t i = ct->i, r = ct->r;
        const wb_cshape *s = &rb->shape[r];
        const wb_real *xi = &w->s.x[3 * i], *n = ct->n, wp = m->w[i], split = rb->pc_cnt[r];
        wb_real *vi = &w->s.v[3 * i], vb[3], u[3];
        v3_set(ct->dp, 0, 0, 0);
        ct->wb = wb__rigid_w(w, r, xi, n);
        if (!(s->friction > 0)) continue;
        body_velocity(rb, r, xi, vb);
        v3_sub(u, vi, vb);
        const wb_real un = v3_dot(u, n);
        wb_real ut[3];
        v3_copy(ut, u);
        v3_madd(ut, n, -un);
        const wb_real vt = v3_len(ut);
        if (!(vt > 0)) continue;
        wb_real t[3];
        v3_scale(t, ut, 1 / vt);
        /* the normal impulse that stayed speed: without err's, as contact.c */
        const wb_real ln = ct->err > 0 ? ct->lambda * (ct->depth - ct->err) / ct->depth : ct->lambda;
        const wb_real P = fmin(s->friction * ln / h, vt / (wp + split * wb__rigid_w(w, r, xi, t)));
        v3_madd(ct->dp, t, P);
        v3_madd(vi, t, -wp * P);
    }
    wb_real *bd = joint_scratch(rb);
    if (!bd) {
        wb__warn(w, "out of memory in particle-rigid contacts; their velocities are left this substep");
        return;
    }
    /* ct->x0 holds the normal impulse so far (x0[0]), its floor (x0[1]) and target (x0[2]) */
    for (int32_t k = 0; k < rb->npct; k++) {
        wb_rpcontact *ct = &rb->pct[k];
        const wb_real e = fabs(ct->vn_pre) > 2 * g * h ? rb->shape[ct->r].restitution : 0;
        wb_real vb[3], u[3], target = fmax(-e * ct->vn_pre, 0);
        body_velocity(rb, ct->r, &w->s.x[3 * ct->i], vb);
        v3_sub(u, &w->s.v[3 * ct->i], vb);
        const wb_real un = v3_dot(u, ct->n);
        if (un > target) target = fmax(target, un - ct->err / h);
        v3_set(ct->x0, 0, -(ct->lambda - ct->lslow) / h, target);
    }
    for (int sweep = 0, more = 1; sweep < JOINT_SWEEPS && more; sweep++) {
        more = 0;
        for (int32_t j = 0; j < rb->npct; j++) {
            wb_rpcontact *ct = &rb->pct[sweep & 1 ? rb->npct - 1 - j : j];
            const int32_t i = ct->i, r = ct->r;
            const wb_real *n = ct->n, wp = m->w[i], den = wp + ct->wb;
            if (!(den > 0)) continue;
            wb_real *vi = &w->s.v[3 * i], vb[3], a[3], d[3], u[3];
            body_velocity(rb, r, &w->s.x[3 * i], vb);
            v3_sub(a, &w->s.x[3 * i], &rb->x[3 * r]);
            joint_point(&bd[6 * r], a, d);
            v3_add(vb, vb, d);
            v3_sub(u, vi, vb);
            const wb_real p = fmax(ct->x0[0] + (ct->x0[2] - v3_dot(u, n)) / den, ct->x0[1]), dl = p - ct->x0[0];
            if (dl == 0) continue;
            more |= fabs(dl) * den > JOINT_TOL_V;
            ct->x0[0] = p;
            v3_madd(vi, n, wp * dl);
            joint_take(w, r, &bd[6 * r], a, n, dl);
        }
    }
    for (int32_t k = 0; k < rb->npct; k++) {
        wb_rpcontact *ct = &rb->pct[k];
        v3_madd(ct->dp, ct->n, -ct->x0[0]);
        wb__rigid_impulse(w, ct->r, &w->s.x[3 * ct->i], ct->dp);
    }
}

int32_t wb_world_rigid_contact_count(const wb_world *w) { return w->rb ? w->rb->npct : 0; }

wb_rigid_contact wb_world_rigid_contact_at(const wb_world *w, int32_t k)
{
    wb_rigid_contact out = { -1, { 0, 0 }, { 0, 0, 0 }, 0, 0 };
    const wb_rigids *rb = w->rb;
    if (!rb || k < 0 || k >= rb->npct) return out;
    const wb_rpcontact *ct = &rb->pct[k];
    out.particle = ct->i;
    out.body.index = (uint32_t)ct->r + 1;
    out.body.gen = rb->gen[ct->r];
    v3_copy(out.normal, ct->n);
    out.depth = ct->depth;
    out.force = ct->lambda / (w->k.h_last * w->k.h_last);
    return out;
}
