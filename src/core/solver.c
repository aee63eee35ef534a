/* solver.c: the step (Macklin et al. 2019, "Small steps in physics simulation").
 *
 * Per frame, `substeps` times: predict, project the constraints `iterations` times
 * (XPBD, Gauss-Seidel over colour batches or Jacobi), project collisions (the particle
 * pairs in touch swept a few times, static friction at position level, the pairs swept
 * again: contact.c), update velocities, then dynamic friction and restitution
 * at velocity level (each substep's prediction but the first runs inside the previous
 * substep's collision pass when nothing between them moves particles: fusable()).
 * Plastic flow, breaking and the finiteness check run once per frame. The constraints
 * are projected type by type from the table wb__ctypes (ctype.c): each type is a file of
 * its own. */
#include <stdio.h>
#include <time.h>

#include "ctype.h"
#include "grab.h"
#include "rigid.h"
#include "vbd.h"
#include "contact.h"
#include "tricontact.h"

static double now_ms(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return ts.tv_sec * 1e3 + ts.tv_nsec * 1e-6;
}

/* one pass of every type, `iterations` times: the types run one after the other (Gauss-
 * Seidel between types; inside one, as the type projects: batches or Jacobi) */
/* the residual after the iterations when it is measured (tolerance, or asked for in
 * the last substep: measure), else -1 */
static wb_real solve_constraints(wb_world *w, wb_real h, int measure)
{
    const int iterations = w->m.def.iterations;
    const wb_real tol = w->m.def.tolerance;
    wb_real r = -1;
    for (int it = 0; it < iterations; it++) {
        for (int t = 0; t < wb__nctypes; t++) wb__ctypes[t]->project(w, h);
        w->k.iters_run++;
        /* the residual is a pass over every constraint, about an iteration's cost: measured
         * when asked for, and for the tolerance after each of the first 4 iterations, then
         * every 4th and the last (a tolerance seldom reached cost twice the iterations when
         * every one was checked; now at most 3 iterations run past the one that reached it) */
        const int last = it + 1 == iterations;
        if ((tol > 0 && (it < 4 || (it + 1) % 4 == 0 || last)) || (measure && last)) {
            r = wb__residual_all(w, h);
            if (tol > 0 && r <= tol) break;
        }
    }
    return r;
}

static wb_predict predict_of(const wb_world *w, wb_real h)
{
    const wb_world_def *d = &w->m.def;
    const wb_predict p = { d->damping > 0 ? (d->damping * h < 1 ? 1 - d->damping * h : 0) : 1,
                           { d->gravity[0] * h, d->gravity[1] * h, d->gravity[2] * h }, h };
    return p;
}

/* *dst = max(*dst, v), or min, from any thread: the parts of a parallel pass merge their
 * extremes, which are the same bits in any order (zeros of either sign aside, which
 * nothing below can tell apart) */
static void max_into(wb_real *dst, wb_real v)
{
    wb_real cur;
    __atomic_load(dst, &cur, __ATOMIC_RELAXED);
    while (v > cur && !__atomic_compare_exchange(dst, &cur, &v, 1, __ATOMIC_RELAXED, __ATOMIC_RELAXED)) {}
}

static void min_into(wb_real *dst, wb_real v)
{
    wb_real cur;
    __atomic_load(dst, &cur, __ATOMIC_RELAXED);
    while (v < cur && !__atomic_compare_exchange(dst, &cur, &v, 1, __ATOMIC_RELAXED, __ATOMIC_RELAXED)) {}
}

typedef struct predict_job {
    wb_world *w;
    wb_predict p;
    int save;      /* the frame's first: x and v into x_save, v_save first (undo) */
    int same;      /* (save) x_save holds the last frame's end (k.bl_np): compared first */
    wb_real v0;    /* (save) the fastest particle's squared speed */
    wb_real pin;   /* (save, same) the farthest a pinned particle was moved, squared */
    int moved;     /* (save, same) a movable particle was */
} predict_job;

/* The frame's first prediction also saves x and v (undo) and finds what the blow-up check
 * (below) reads of the frame's start: its fastest particle, and what the script moved
 * since the last frame's end, which x_save holds (a frame's end leaves its positions
 * there: a copy of its own cost the check 2% of the 128 x 128 cloth's frame) */
static void predict_part(void *ctx, int32_t lo, int32_t hi)
{
    predict_job *j = ctx;
    wb_world *w = j->w;
    const wb_predict p = j->p;
    wb_real *restrict x = w->s.x, *restrict xp = w->s.x_prev, *restrict v = w->s.v;
    const wb_real *restrict wv = w->m.w;
    if (lo >= hi) return; /* an empty world: no arrays at all (memcpy from NULL is undefined) */
    if (!j->save) {
        for (int32_t i = lo; i < hi; i++) wb__predict_one(&p, wv[i], &x[3 * i], &xp[3 * i], &v[3 * i]);
        return;
    }
    wb_real *restrict xs = w->k.x_save, *restrict vs = w->k.v_save;
    const int same = j->same;
    if (!same) memcpy(xs + 3 * (size_t)lo, x + 3 * (size_t)lo, sizeof(wb_real) * 3 * (size_t)(hi - lo));
    wb_real v0 = 0, pin = 0;
    int moved = 0;
    for (int32_t i = lo; i < hi; i++) {
        wb_real *xi = &x[3 * i], *vi = &v[3 * i], *si = &xs[3 * i];
        const wb_real q = v3_dot(vi, vi);
        v0 = q > v0 ? q : v0;
        v3_copy(&vs[3 * i], vi);
        if (same && memcmp(si, xi, sizeof(wb_real) * 3)) {
            /* moved by hand since the last frame's end (the bits: a zero's sign is kept) */
            if (wv[i] > 0) {
                moved |= xi[0] != si[0] || xi[1] != si[1] || xi[2] != si[2];
            } else {
                wb_real d[3];
                v3_sub(d, xi, si);
                const wb_real dd = v3_dot(d, d);
                pin = dd > pin ? dd : pin;
            }
            v3_copy(si, xi);
        }
        wb__predict_one(&p, wv[i], xi, &xp[3 * i], vi);
    }
    max_into(&j->v0, v0);
    max_into(&j->pin, pin);
    if (moved) __atomic_store_n(&j->moved, 1, __ATOMIC_RELAXED);
}

/* a substep's prediction on its own (the first substep's, or when the collision pass
 * could not take it), in parallel as the collision pass */
static void predict(wb_world *w, wb_real h, int save)
{
    wb_cache *k = &w->k;
    predict_job j = { w, predict_of(w, h), save, k->bl_np == w->m.np, 0, 0, 0 };
    wb__pool_for(w->m.np >= 4096 ? wb__world_pool(w) : NULL, w->m.np, 2048, predict_part, &j);
    if (!save) return;
    /* (kept until a frame's check reads them: an undone frame's start counts too) */
    k->bl_v0 = j.v0;
    k->bl_pin = j.pin > k->bl_pin ? j.pin : k->bl_pin;
    k->bl_moved |= j.moved || !j.same;
    k->bl_np = w->m.np; /* x_save: the frame's start, and its end once the check has run */
}

/* Between the collision pass of one substep and the prediction of the next run the
 * velocity passes of the particle contacts, the triangle contacts and the particle-rigid
 * contacts (the rigid bodies' own passes touch no particle). When none of them has a
 * contact this substep they change nothing, and the next prediction can run in the
 * collision pass, particle by particle; so can the frame's finiteness check after the
 * last substep. (wb_cache.no_fuse: the tests' switch to the unfused order.) */
static int fusable(const wb_world *w)
{
    return !w->k.no_fuse && w->k.pc->nact == 0 && w->k.tc->nact == 0 && !(w->rb && w->rb->npct > 0);
}

/* put the particles back as they were at the frame's start; the multipliers of the
 * abandoned frame mean nothing (and may be NaN): force() reads 0 until the next step */
static void undo_particles(wb_world *w)
{
    const size_t n = 3 * (size_t)w->m.np;
    if (n > 0) {
        memcpy(w->s.x, w->k.x_save, sizeof(wb_real) * n);
        memcpy(w->s.x_prev, w->k.x_save, sizeof(wb_real) * n);
        memcpy(w->s.v, w->k.v_save, sizeof(wb_real) * n);
    }
    for (int t = 0; t < wb__nctypes; t++) wb__ctypes[t]->substep_begin(w);
    wb__rigids_undo(w);
    wb__vbd_undo(w);
}

/* the colliders' poses at the frame's start, before their velocities move them */
static int save_colliders(wb_world *w)
{
    wb_cache *k = &w->k;
    wb_real *c = wb__grow(k->c_save, &k->cap_c_save, 7 * (w->m.nc > 0 ? w->m.nc : 1), sizeof *c);
    if (!c) return 0;
    k->c_save = c;
    for (int32_t i = 0; i < w->m.nc; i++) {
        v3_copy(&c[7 * i], w->s.c_pose[i].p);
        memcpy(&c[7 * i + 3], w->s.c_pose[i].q, 4 * sizeof(wb_real));
    }
    return 1;
}

static void restore_collider(wb_world *w, int32_t i)
{
    wb_collider_pose *cp = &w->s.c_pose[i];
    v3_copy(cp->p, &w->k.c_save[7 * i]);
    memcpy(cp->q, &w->k.c_save[7 * i + 3], 4 * sizeof(wb_real));
}

/* non-finite values never propagate: a particle gone non-finite undoes the frame's
 * particles; a collider driven to a non-finite pose (absurd velocities) goes back and
 * stops. Returns 1 when the particles were finite. Time still advances: kinematic
 * colliders keep their script's schedule. */
static int check_finite(wb_world *w)
{
    for (int32_t c = 0; c < w->m.nc; c++) {
        wb_collider_pose *cp = &w->s.c_pose[c];
        if (!(w->m.c_gen[c] & 1u)) continue;
        if (isfinite(cp->p[0]) && isfinite(cp->p[1]) && isfinite(cp->p[2]) && isfinite(cp->q[0]) &&
            isfinite(cp->q[1]) && isfinite(cp->q[2]) && isfinite(cp->q[3]))
            continue;
        wb__warn(w, "frame %lld: collider %d moved to a non-finite pose; it was put back and its "
                    "velocities set to zero", (long long)w->s.frame + 1, c + 1);
        restore_collider(w, c);
        v3_set(cp->v, 0, 0, 0);
        v3_set(cp->om, 0, 0, 0);
    }
    const int32_t bad = wb__rigids_finite(w);
    if (bad >= 0) {
        wb__warn(w, "frame %lld: rigid body %d became non-finite; its frame was undone (reduce dt, "
                    "raise substeps)", (long long)w->s.frame + 1, bad + 1);
        undo_particles(w);
        return 0;
    }
    /* the first non-finite particle: found by the last substep's pass, or looked for */
    int32_t badp = w->k.nonfinite;
    if (badp == -2) {
        const int32_t n = 3 * w->m.np;
        const wb_real *x = w->s.x, *v = w->s.v;
        badp = -1;
        for (int32_t i = 0; i < n && badp < 0; i++)
            if (!(isfinite(x[i]) && isfinite(v[i]))) badp = i / 3;
    }
    if (badp >= 0) {
        wb__warn(w, "frame %lld: particle %d became non-finite; its frame was undone (reduce dt, "
                    "raise substeps or compliance)", (long long)w->s.frame + 1, badp + 1);
        undo_particles(w);
        return 0;
    }
    return 1;
}

/* ---- blow-ups ------------------------------------------------------------------------ */
/* Constraints that cannot all hold (a stiff body squeezed flat by a kinematic press) can
 * feed particle speeds the scene has no source for. The scene's speed scale is the fastest
 * of: a kinematic collider's surface (its move over the frame, its turn times the reach to
 * the farthest particle), a rigid body's (|v| + |om| x its bound), a grab's target, a
 * pinned particle the script moves, the fastest speed a script gave (w:set_velocity, a new
 * particle, what a change by hand set free: below), and a fall across the scene,
 * sqrt(2 |g| H) (H: the particles' extent along g), which also covers what one body passes
 * to another. A particle is past a limit L when it is faster than L and faster than it was
 * at the frame's start by more than BLOW_G |g| dt (so that no fall, however long, is).
 * A blow-up is
 *   a particle past BLOW_K2 x scale + BLOW_F2 (no scene of the suite comes near), or
 *   BLOW_RUN frames in a row with a particle past BLOW_K1 x scale + BLOW_F1 (a spring let
 *   go, a whip does it for a frame or two; a body that blows up keeps doing it).
 * From then on, every particle past the lower limit is slowed to it (its direction kept),
 * and the first time the world warns, once. Energy a script gives by hand (a constraint
 * made away from its rest, a particle moved into a strained shape, a setting changed) is let
 * go first: nothing is judged during BLOW_GRACE seconds after such a change, and the speeds
 * it reached count as given. Stored elastic energy is no source: the squeezed body that
 * blows up holds more of it (C^2 / 2 alpha of links its solve cannot satisfy) than would
 * explain any speed. Measured over every test and scripts/ scene run in full: nothing
 * passes the upper limit, the lower one 2 frames in a row at most (logo_spring.lua's
 * letters springing back, momentum.lua's whipping rope, volume.lua's squeezed block). */
#define BLOW_K1 ((wb_real)3)
#define BLOW_F1 ((wb_real)3)      /* m/s */
#define BLOW_RUN 5
#define BLOW_K2 ((wb_real)16)
#define BLOW_F2 ((wb_real)20)     /* m/s */
#define BLOW_G ((wb_real)3)
#define BLOW_GRACE 0.5            /* s */

/* What the check reads of the particles: the frame's start (predict_part: k.bl_v0, bl_pin,
 * bl_moved), then one pass at its end, which also leaves the end's positions in x_save for
 * the next frame's start to compare with (seven passes cost 5% of the 128 x 128 cloth's
 * frame). Maxima of squares: sqrt and / dt are monotonic, so the root of the largest square
 * is the largest root, to the bit. */
typedef struct scan_job {
    wb_world *w;
    wb_real v1;           /* the fastest particle's squared speed */
    wb_real lo[3], hi[3]; /* the particles' bounds */
} scan_job;

static void scan_part(void *ctx, int32_t lo, int32_t hi)
{
    scan_job *j = ctx;
    const wb_real *restrict x = j->w->s.x, *restrict v = j->w->s.v;
    wb_real *restrict xs = j->w->k.x_save;
    wb_real v1 = 0, l[3] = { INFINITY, INFINITY, INFINITY }, u[3] = { -INFINITY, -INFINITY, -INFINITY };
    for (int32_t i = lo; i < hi; i++) {
        const wb_real *xi = &x[3 * i];
        const wb_real q = v3_dot(&v[3 * i], &v[3 * i]);
        v1 = q > v1 ? q : v1;
        for (int c = 0; c < 3; c++) {
            /* comparisons, not fmin / fmax (libm calls; a finite frame has no NaN) */
            l[c] = xi[c] < l[c] ? xi[c] : l[c];
            u[c] = xi[c] > u[c] ? xi[c] : u[c];
        }
        v3_copy(&xs[3 * i], xi);
    }
    max_into(&j->v1, v1);
    for (int c = 0; c < 3; c++) {
        min_into(&j->lo[c], l[c]);
        max_into(&j->hi[c], u[c]);
    }
}

static wb_real speed_scale(wb_world *w, wb_real dt, const scan_job *f)
{
    const wb_model *m = &w->m;
    wb_cache *k = &w->k;
    const int32_t np = m->np;
    const wb_real *lo = f->lo, *hi = f->hi;
    wb_real s = k->bl_user;
    /* a fall across the scene */
    const wb_real g = v3_len(m->def.gravity);
    if (g > 0 && np > 0) {
        wb_real ext = 0;
        for (int c = 0; c < 3; c++) ext += fabs(m->def.gravity[c]) / g * (hi[c] - lo[c]);
        s = fmax(s, sqrt(2 * g * ext));
    }
    /* kinematic colliders: the move and turn over this frame, from the pose the step saved
     * at its start */
    for (int32_t c = 0; c < m->nc; c++) {
        if (!(m->c_gen[c] & 1u) || np == 0) continue;
        const wb_collider_pose *cp = &w->s.c_pose[c];
        const wb_real *p0 = &k->c_save[7 * c], *q0 = &k->c_save[7 * c + 3];
        wb_real d[3], reach = 0;
        v3_sub(d, cp->p, p0);
        for (int a = 0; a < 3; a++) {
            const wb_real e = fmax(fabs(lo[a] - cp->p[a]), fabs(hi[a] - cp->p[a]));
            reach += e * e;
        }
        const wb_real dot = fabs(q0[0] * cp->q[0] + q0[1] * cp->q[1] + q0[2] * cp->q[2] + q0[3] * cp->q[3]);
        const wb_real turn = 2 * acos(dot < 1 ? dot : 1);
        s = fmax(s, (v3_len(d) + turn * sqrt(reach)) / dt);
    }
    const wb_rigids *rb = w->rb;
    for (int32_t i = 0; rb && i < rb->n; i++)
        if (rb->gen[i] & 1u) s = fmax(s, v3_len(&rb->v[3 * i]) + v3_len(&rb->om[3 * i]) * rb->bound[i]);
    s = fmax(s, wb__grab_speed(w, dt));
    /* pinned particles the script moves (between frames: against the last frame's end; 0
     * when none did, and s >= 0) */
    s = fmax(s, sqrt(k->bl_pin) / dt);
    return s;
}

/* did the script give the world energy by hand since the last frame (see above)? */
static int given(wb_world *w)
{
    const wb_model *m = &w->m;
    wb_cache *k = &w->k;
    const int g = !k->bl_have || k->mc_changed || k->bl_moved || k->bl_wgen != m->w_gen ||
                  memcmp(&k->bl_def, &m->def, sizeof k->bl_def);
    k->mc_changed = 0;
    k->bl_wgen = m->w_gen;
    k->bl_def = m->def;
    return g;
}

/* after a finite frame: the blow-up check (above); the frame's start velocities are in
 * k->v_save */
static void check_speeds(wb_world *w)
{
    const wb_model *m = &w->m;
    wb_cache *k = &w->k;
    const int32_t np = m->np;
    const wb_real dt = m->def.dt, g = v3_len(m->def.gravity), fall = BLOW_G * g * dt;
    wb_real *v = w->s.v;
    const wb_real *v0 = k->v_save;
    scan_job f = { w, 0, { INFINITY, INFINITY, INFINITY }, { -INFINITY, -INFINITY, -INFINITY } };
    wb__pool_for(np >= 4096 ? wb__world_pool(w) : NULL, np, 2048, scan_part, &f);
    /* the fastest particle at the frame's start; a speed from outside when faster than any
     * the last frame ended with (a script's w:set_velocity, a new particle) */
    const wb_real s0 = sqrt(k->bl_v0);
    if (!k->bl_have || s0 > k->bl_vend) k->bl_user = fmax(k->bl_user, s0);
    /* (the time is the frame's start's: it advances after this) */
    if (given(w)) k->bl_given = w->s.time;
    wb_real end = sqrt(f.v1);
    if (w->s.time - k->bl_given < BLOW_GRACE - 0.5 * dt) {
        /* what a change by hand sets free counts as given */
        k->bl_user = fmax(k->bl_user, end);
        k->bl_hot = 0;
    } else {
        const wb_real scale = speed_scale(w, dt, &f), lo = BLOW_K1 * scale + BLOW_F1, hi = BLOW_K2 * scale + BLOW_F2;
        int32_t worst = -1;
        wb_real top = 0;
        /* (the common case: no particle is past the lower limit, and there is no walk) */
        for (int32_t i = 0; f.v1 > lo * lo && i < np; i++) {
            if (!(v3_dot(&v[3 * i], &v[3 * i]) > lo * lo)) continue;
            const wb_real s = v3_len(&v[3 * i]);
            if (s > lo && s > v3_len(&v0[3 * i]) + fall && s > top) { top = s; worst = i; }
        }
        k->bl_hot = worst >= 0 ? k->bl_hot + 1 : 0;
        if (worst >= 0 && (top > hi || k->bl_hot >= BLOW_RUN)) k->bl_armed = 1;
        if (worst >= 0 && k->bl_armed) {
            int32_t count = 0;
            wb_real q1 = 0;
            for (int32_t i = 0; i < np; i++) {
                wb_real *vi = &v[3 * i];
                const wb_real s = v3_len(vi);
                if (s > lo && s > v3_len(&v0[3 * i]) + fall) {
                    v3_scale(vi, vi, lo / s);
                    count++;
                }
                const wb_real q = v3_dot(vi, vi);
                q1 = q > q1 ? q : q1;
            }
            end = sqrt(q1); /* the fastest once slowed */
            if (!k->bl_warned) {
                k->bl_warned = 1;
                /* (one line of last_warning: what, where, what was done, what to do) */
                wb__warn(w, "frame %lld: particle %d at %.3g m/s, the scene explains %.3g: a blow-up (constraints "
                            "fighting?); %d past %.3g m/s slowed; raise iterations or compliance",
                         (long long)w->s.frame + 1, worst + 1, top, scale, count, lo);
            }
        }
    }
    k->bl_vend = end;
    k->bl_have = 1;
    k->bl_moved = 0;
    k->bl_pin = 0;
}

wb_status wb_world_step(wb_world *w)
{
    const double t_begin = now_ms();
    wb_cache *k = &w->k;
    /* the contacts' scratch, made with the first step (so the step's passes find it) */
    wb_status prep = wb__contacts_make(w) && wb__tricontacts_make(w) ? WB_OK : WB_ERR_NOMEM;
    wb__momentum_prepare(w); /* (first: the types' prepare clears the topology flag it reads) */
    if (!wb__vbd_prepare(w)) prep = WB_ERR_NOMEM; /* (as well) */
    for (int t = 0; t < wb__nctypes && prep == WB_OK; t++) prep = wb__ctypes[t]->prepare(w);
    if (prep != WB_OK || !save_colliders(w)) {
        wb__warn(w, "frame %lld: out of memory preparing the step; frame skipped", (long long)w->s.frame + 1);
        return WB_ERR_NOMEM;
    }
    const wb_world_def *d = &w->m.def;
    const wb_real dt = d->dt, h = dt / d->substeps;
    wb__rigids_save(w);
    k->projections = 0;
    k->iters_run = 0;
    k->h_last = h;

    /* kinematic colliders: where the script's velocities take them by the frame's end */
    for (int32_t c = 0; c < w->m.nc; c++) {
        if (!(w->m.c_gen[c] & 1u)) continue;
        wb_collider_pose *cp = &w->s.c_pose[c];
        v3_madd(cp->p, cp->v, dt);
        q_integrate(cp->q, cp->om, dt, cp->q);
    }

    wb__contacts_begin(w);
    wb__tricontacts_begin(w);
    wb__rigid_particles_begin(w);
    /* the particles saved for undo (none of the above moves them) and the first
     * substep's prediction, in one pass */
    predict(w, h, 1);
    int predicted = 1;  /* the substep's prediction is done */
    k->nonfinite = -2;
    const wb_predict next = predict_of(w, h);
    double solve = 0;
    for (int sub = 0; sub < d->substeps; sub++) {
        if (k->interrupt && k->interrupt(k->interrupt_ud)) {
            /* abandoned: the world is left as the frame found it */
            undo_particles(w);
            for (int32_t c = 0; c < w->m.nc; c++) restore_collider(w, c);
            k->step_ms = now_ms() - t_begin;
            return WB_ERR_INTERRUPTED;
        }
        if (!predicted) predict(w, h, 0);
        wb__rigids_predict(w, h);
        double t0 = now_ms();
        /* TYPE HOOK: the constraint types, walked from the table (wb__ctypes) */
        for (int t = 0; t < wb__nctypes; t++) wb__ctypes[t]->substep_begin(w);
        const int measure = k->residual_on && sub + 1 == d->substeps;
        const wb_real r = d->solver == WB_SOLVER_VBD
                              ? wb__vbd_solve(w, h, (wb_real)sub / d->substeps, (wb_real)(sub + 1) / d->substeps)
                              : solve_constraints(w, h, measure);
        if (d->solver == WB_SOLVER_VBD && wb__vbd_failed(w)) {
            /* its scratch refused by the memory budget: the world is left as the frame found it */
            undo_particles(w);
            for (int32_t c = 0; c < w->m.nc; c++) restore_collider(w, c);
            wb__warn(w, "frame %lld: out of memory in the VBD solve; frame undone", (long long)w->s.frame + 1);
            k->step_ms = now_ms() - t_begin;
            return WB_ERR_NOMEM;
        }
        if (sub + 1 == d->substeps) k->residual = r;
        wb__momentum_restore(w, h);
        solve += now_ms() - t0;
        wb__contacts_project(w, h);
        wb__tricontacts_project(w, h);
        wb__contacts_friction(w, h);
        wb__contacts_settle(w, h);
        wb__rigids_solve(w, h, (wb_real)sub / d->substeps, (wb_real)(sub + 1) / d->substeps);
        wb__rigid_particles_solve(w);
        const int last = sub + 1 == d->substeps, fuse = fusable(w);
        predicted = wb__collide_and_update(w, h, (wb_real)sub / d->substeps, (wb_real)(sub + 1) / d->substeps,
                                           fuse && !last ? &next : NULL, fuse && last) &&
                    fuse && !last;
        wb__rigids_update(w, h);
        wb__contacts_velocity(w, h);
        wb__tricontacts_velocity(w, h);
        wb__rigids_velocity(w, h);
        wb__rigid_particles_velocity(w, h);
        if (d->solver == WB_SOLVER_VBD) wb__vbd_contacts_done(w);
    }

    /* a frame gone non-finite is undone before it can bend or break anything; a blow-up is
     * slowed (velocities only: plastic flow and breaking read positions) */
    if (check_finite(w)) {
        check_speeds(w);
        for (int t = 0; t < wb__nctypes; t++)
            if (wb__ctypes[t]->frame_end) wb__ctypes[t]->frame_end(w);
    }
    for (int32_t c = 0; c < w->m.nc; c++) {
        wb_collider_pose *cp = &w->s.c_pose[c];
        v3_copy(cp->p0, cp->p);
        memcpy(cp->q0, cp->q, sizeof cp->q);
    }
    w->s.frame++;
    w->s.time += dt;
    k->solve_ms = solve;
    k->step_ms = now_ms() - t_begin;
    return WB_OK;
}
