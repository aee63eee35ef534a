/* query.c: read-only measures of a world: energy, momenta, bounds, strain, hash, stats. */
#include "ctype.h"
#include "rigid.h"
#include "vbd.h"

static wb_real mass_of(const wb_world *w, int32_t i) { return w->m.w[i] > 0 ? 1 / w->m.w[i] : 0; }

void wb_world_energy(const wb_world *w, wb_real *kinetic, wb_real *potential)
{
    /* pinned and immovable particles do not move: they carry no energy that changes */
    wb_real ke = 0, pe = 0;
    const wb_real *g = w->m.def.gravity;
    for (int32_t i = 0; i < w->m.np; i++) {
        wb_real m = mass_of(w, i);
        if (m == 0) continue;
        ke += (wb_real)0.5 * m * v3_dot(&w->s.v[3 * i], &w->s.v[3 * i]);
        pe -= m * v3_dot(g, &w->s.x[3 * i]);
    }
    /* elastic: each constraint type's, U = C^2 / (2 alpha) for compliant ones */
    for (int t = 0; t < wb__nctypes; t++)
        if (wb__ctypes[t]->energy) pe += wb__ctypes[t]->energy(w);
    /* rigid bodies: translation and rotation (om . I om / 2 in the body frame), weight */
    const wb_rigids *rb = w->rb;
    for (int32_t r = 0; rb && r < rb->n; r++) {
        if (!(rb->gen[r] & 1u)) continue;
        const wb_real m = rb->mass[r], *v = &rb->v[3 * r];
        wb_real ob[3], L[3];
        q_rotate_inv(&rb->q[4 * r], &rb->om[3 * r], ob);
        const wb_real *I = &rb->inertia[9 * r];
        for (int c = 0; c < 3; c++) L[c] = I[3 * c] * ob[0] + I[3 * c + 1] * ob[1] + I[3 * c + 2] * ob[2];
        ke += (wb_real)0.5 * (m * v3_dot(v, v) + v3_dot(ob, L));
        pe -= m * v3_dot(g, &rb->x[3 * r]);
    }
    *kinetic = ke;
    *potential = pe;
}

void wb_world_momentum(const wb_world *w, wb_real out[3])
{
    v3_set(out, 0, 0, 0);
    for (int32_t i = 0; i < w->m.np; i++) v3_madd(out, &w->s.v[3 * i], mass_of(w, i));
    const wb_rigids *rb = w->rb;
    for (int32_t r = 0; rb && r < rb->n; r++)
        if (rb->gen[r] & 1u) v3_madd(out, &rb->v[3 * r], rb->mass[r]);
}

void wb_world_angular_momentum(const wb_world *w, wb_real out[3])
{
    v3_set(out, 0, 0, 0);
    for (int32_t i = 0; i < w->m.np; i++) {
        wb_real l[3];
        v3_cross(l, &w->s.x[3 * i], &w->s.v[3 * i]);
        v3_madd(out, l, mass_of(w, i));
    }
    /* rigid bodies: x x m v + R I R^T om */
    const wb_rigids *rb = w->rb;
    for (int32_t r = 0; rb && r < rb->n; r++) {
        if (!(rb->gen[r] & 1u)) continue;
        wb_real l[3], ob[3], L[3];
        const wb_real *I = &rb->inertia[9 * r];
        v3_cross(l, &rb->x[3 * r], &rb->v[3 * r]);
        v3_madd(out, l, rb->mass[r]);
        q_rotate_inv(&rb->q[4 * r], &rb->om[3 * r], ob);
        for (int c = 0; c < 3; c++) L[c] = I[3 * c] * ob[0] + I[3 * c + 1] * ob[1] + I[3 * c + 2] * ob[2];
        q_rotate(&rb->q[4 * r], L, l);
        v3_add(out, out, l);
    }
}

bool wb_world_bounds(const wb_world *w, wb_real mn[3], wb_real mx[3])
{
    if (w->m.np == 0) return false;
    v3_copy(mn, w->s.x);
    v3_copy(mx, w->s.x);
    for (int32_t i = 1; i < w->m.np; i++)
        for (int c = 0; c < 3; c++) {
            wb_real x = w->s.x[3 * i + c];
            if (x < mn[c]) mn[c] = x;
            if (x > mx[c]) mx[c] = x;
        }
    return true;
}

/* FNV-1a over the bytes of the state: bit-identical states, identical hashes */
uint64_t wb_world_hash(const wb_world *w)
{
    const wb_model *m = &w->m;
    const wb_state *s = &w->s;
    uint64_t h = 14695981039346656037ull;
    h = wb__fnv(h, &m->np, sizeof m->np);
    h = wb__fnv(h, s->x, sizeof(wb_real) * 3 * (size_t)m->np);
    h = wb__fnv(h, s->v, sizeof(wb_real) * 3 * (size_t)m->np);
    h = wb__fnv(h, m->pinned, (size_t)m->np);
    h = wb__fnv(h, m->inv_mass, sizeof(wb_real) * (size_t)m->np);
    h = wb__fnv(h, m->radius, sizeof(wb_real) * (size_t)m->np);
    h = wb__fnv(h, m->group, sizeof(int32_t) * (size_t)m->np);
    h = wb__fnv(h, m->cflags, (size_t)m->np);
    h = wb__fnv(h, m->cfric, sizeof(wb_real) * (size_t)m->np);
    h = wb__fnv(h, m->x0, sizeof(wb_real) * 3 * (size_t)m->np);
    /* the types' state in the hash's own order, the colliders' poses at their place (NULL) */
    for (int t = 0; t <= wb__nctypes; t++) {
        const wb_ctype *ct = wb__ctypes_hashed[t];
        if (ct) { h = ct->hash(w, h); continue; }
        for (int32_t c = 0; c < m->nc; c++) {
            if (!(m->c_gen[c] & 1u)) continue;
            h = wb__fnv(h, &s->c_pose[c], sizeof s->c_pose[c]); /* pose, sweep start, velocities */
        }
    }
    const wb_rigids *rb = w->rb;
    for (int32_t r = 0; rb && r < rb->n; r++) { /* (worlds without any hash as they always did) */
        if (!(rb->gen[r] & 1u)) continue;
        const wb_cshape *sh = &rb->shape[r];
        const int32_t shape = (int32_t)sh->shape;
        h = wb__fnv(h, &r, sizeof r);
        h = wb__fnv(h, &rb->gen[r], sizeof rb->gen[r]);
        h = wb__fnv(h, &shape, sizeof shape);
        h = wb__fnv(h, &sh->radius, sizeof sh->radius);
        h = wb__fnv(h, sh->half, sizeof sh->half);
        h = wb__fnv(h, sh->a, sizeof sh->a);
        h = wb__fnv(h, sh->b, sizeof sh->b);
        h = wb__fnv(h, &sh->friction, sizeof sh->friction);
        h = wb__fnv(h, &sh->restitution, sizeof sh->restitution);
        h = wb__fnv(h, &rb->mass[r], sizeof(wb_real));
        h = wb__fnv(h, &rb->x[3 * r], 3 * sizeof(wb_real));
        h = wb__fnv(h, &rb->q[4 * r], 4 * sizeof(wb_real));
        h = wb__fnv(h, &rb->v[3 * r], 3 * sizeof(wb_real));
        h = wb__fnv(h, &rb->om[3 * r], 3 * sizeof(wb_real));
    }
    h = wb__fnv(h, &s->time, sizeof s->time);
    h = wb__fnv(h, &s->frame, sizeof s->frame);
    return h;
}

wb_real wb__residual_all(const wb_world *w, wb_real h)
{
    wb_real r = 0;
    for (int i = 0; i < wb__nctypes; i++) {
        const wb_real ri = wb__ctypes[i]->residual ? wb__ctypes[i]->residual(w, h) : 0;
        r = ri > r ? ri : r;
    }
    return r;
}

/* measured in the step from the first time it is asked for (solver.c); until a step has,
 * at the positions as they are */
wb_real wb_world_residual(wb_world *w)
{
    wb_cache *k = &w->k;
    const int was = k->residual_on;
    k->residual_on = 1;
    if (was && k->residual >= 0) return k->residual;
    if (w->m.def.solver == WB_SOLVER_VBD) return wb__vbd_residual(w); /* (its last sweep's) */
    return k->h_last > 0 ? wb__residual_all(w, k->h_last) : 0;
}

wb_stats wb_world_stats(const wb_world *w)
{
    wb_stats st;
    memset(&st, 0, sizeof st);
    st.particles = w->m.np;
    for (int i = 0; i < wb__nctypes; i++) wb__ctypes[i]->stats(w, &st);
    st.colliders = wb_collider_count(w);
    st.contacts = w->k.last_contacts;
    wb__contacts_stats(w, &st);
    st.projections = w->k.projections;
    st.step_ms = w->k.step_ms;
    st.solve_ms = w->k.solve_ms;
    st.iterations_run = w->m.def.substeps > 0 ? (double)w->k.iters_run / w->m.def.substeps : 0;
    st.warnings = w->s.warnings;
    st.rigids = wb_rigid_count(w);
    st.rigid_contacts = wb_world_rigid_contact_count(w);
    return st;
}
