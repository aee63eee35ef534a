/* query.c: read-only measures of a world: energy, momenta, bounds, strain, hash, stats. */
#include "ctype.h"
#include "attach.h"
#include "grab.h"
#include "rigid.h"
#include "tet.h"
#include "vbd.h"
#include "volume.h"

static wb_real mass_of(const wb_world *w, int32_t i) { return w->m.w[i] > 0 ? 1 / w->m.w[i] : 0; }

static int live(const wb_world *w, int32_t s) { return (w->m.d_gen[s] & 1u) && !w->s.d_broken[s]; }

static wb_real slot_length(const wb_world *w, int32_t s)
{
    wb_real d[3];
    v3_sub(d, &w->s.x[3 * w->m.d_ij[2 * s + 1]], &w->s.x[3 * w->m.d_ij[2 * s]]);
    return v3_len(d);
}

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

wb_real wb_world_max_strain(const wb_world *w)
{
    wb_real best = 0;
    for (int32_t s = 0; s < w->m.nd; s++) {
        if (!live(w, s) || w->s.d_rest[s] <= 0) continue;
        wb_real e = fabs(slot_length(w, s) - w->s.d_rest[s]) / w->s.d_rest[s];
        if (e > best) best = e;
    }
    return best;
}

int32_t wb_world_distance_pairs(const wb_world *w, int32_t *ij, wb_real *strain)
{
    int32_t n = 0;
    for (int32_t s = 0; s < w->m.nd; s++) {
        if (!live(w, s)) continue;
        if (ij) { ij[2 * n] = w->m.d_ij[2 * s]; ij[2 * n + 1] = w->m.d_ij[2 * s + 1]; }
        if (strain) strain[n] = w->s.d_rest[s] > 0 ? (slot_length(w, s) - w->s.d_rest[s]) / w->s.d_rest[s] : 0;
        n++;
    }
    return n;
}

/* FNV-1a over the bytes of the state: bit-identical states, identical hashes */
static uint64_t fnv(uint64_t h, const void *p, size_t n)
{
    const unsigned char *b = p;
    for (size_t i = 0; i < n; i++) { h ^= b[i]; h *= 1099511628211ull; }
    return h;
}

uint64_t wb_world_hash(const wb_world *w)
{
    const wb_model *m = &w->m;
    const wb_state *s = &w->s;
    uint64_t h = 14695981039346656037ull;
    h = fnv(h, &m->np, sizeof m->np);
    h = fnv(h, s->x, sizeof(wb_real) * 3 * (size_t)m->np);
    h = fnv(h, s->v, sizeof(wb_real) * 3 * (size_t)m->np);
    h = fnv(h, m->pinned, (size_t)m->np);
    h = fnv(h, m->inv_mass, sizeof(wb_real) * (size_t)m->np);
    h = fnv(h, m->radius, sizeof(wb_real) * (size_t)m->np);
    h = fnv(h, m->group, sizeof(int32_t) * (size_t)m->np);
    h = fnv(h, m->cflags, (size_t)m->np);
    h = fnv(h, m->cfric, sizeof(wb_real) * (size_t)m->np);
    h = fnv(h, m->x0, sizeof(wb_real) * 3 * (size_t)m->np);
    for (int32_t i = 0; i < m->nd; i++) {
        if (!(m->d_gen[i] & 1u)) continue;
        h = fnv(h, &s->d_rest[i], sizeof s->d_rest[i]);
        h = fnv(h, &s->d_broken[i], 1);
    }
    for (int32_t c = 0; c < m->nc; c++) {
        if (!(m->c_gen[c] & 1u)) continue;
        h = fnv(h, &s->c_pose[c], sizeof s->c_pose[c]); /* pose, sweep start, velocities */
    }
    /* broken bends (state): their slots, so worlds without one hash as they always did */
    for (int32_t i = 0; i < w->bend.n; i++)
        if (w->bend.broken[i]) h = fnv(h, &i, sizeof i);
    /* shape matching and pressure: their parameters and state (rest shapes, rotations) */
    const wb_smatch *sm = &w->sm;
    if (sm->n > 0) { /* (worlds without any hash as they always did) */
        h = fnv(h, &sm->n, sizeof sm->n);
        h = fnv(h, sm->start, sizeof(int32_t) * ((size_t)sm->n + 1));
        h = fnv(h, sm->ids, sizeof(int32_t) * (size_t)sm->nids);
        h = fnv(h, sm->stiff, sizeof(wb_real) * (size_t)sm->n);
        h = fnv(h, sm->yield, sizeof(wb_real) * (size_t)sm->n);
        h = fnv(h, sm->creep, sizeof(wb_real) * (size_t)sm->n);
        h = fnv(h, sm->rest, sizeof(wb_real) * 3 * (size_t)sm->nids);
        h = fnv(h, sm->q, sizeof(wb_real) * 4 * (size_t)sm->n);
    }
    const wb_pressures *pr = &w->pr;
    if (pr->n > 0) {
        h = fnv(h, &pr->n, sizeof pr->n);
        h = fnv(h, pr->surface, sizeof(int32_t) * (size_t)pr->n);
        h = fnv(h, pr->pressure, sizeof(wb_real) * (size_t)pr->n);
        h = fnv(h, pr->alpha, sizeof(wb_real) * (size_t)pr->n);
        h = fnv(h, pr->v0, sizeof(wb_real) * (size_t)pr->n);
    }
    /* plastic volume constraints and tets: their rest state flows (state), and how (worlds
     * without any hash as they always did) */
    const wb_volumes *vo = w->vol;
    if (vo && vo->plastic) {
        h = fnv(h, vo->rest, sizeof(wb_real) * (size_t)vo->n);
        h = fnv(h, vo->yield, sizeof(wb_real) * (size_t)vo->n);
        h = fnv(h, vo->creep, sizeof(wb_real) * (size_t)vo->n);
    }
    const wb_neos *ne = w->neo;
    if (ne && ne->plastic) {
        h = fnv(h, ne->dminv, sizeof(wb_real) * 9 * (size_t)ne->n);
        h = fnv(h, ne->v0, sizeof(wb_real) * (size_t)ne->n);
        h = fnv(h, ne->yield, sizeof(wb_real) * (size_t)ne->n);
        h = fnv(h, ne->creep, sizeof(wb_real) * (size_t)ne->n);
    }
    /* attachments and grabs: the live ones in slot order (a snapshot keeps that order;
     * it drops an attachment whose collider was removed, so the hash does too) */
    const wb_attaches *at = w->att;
    for (int32_t i = 0; at && i < at->n; i++) {
        if (!wb__attach_active(w, at, i)) continue;
        h = fnv(h, &at->p[i], sizeof at->p[i]);
        h = fnv(h, &at->kind[i], 1);
        h = fnv(h, &at->tindex[i], sizeof at->tindex[i]);
        h = fnv(h, &at->local[3 * i], 3 * sizeof(wb_real));
        h = fnv(h, &at->alpha[i], sizeof(wb_real));
    }
    const wb_grabs *gr = w->grab;
    for (int32_t i = 0; gr && i < gr->n; i++) {
        if (!wb__grab_active(w, gr, i)) continue;
        h = fnv(h, &gr->p[i], sizeof gr->p[i]);
        if (gr->kind[i] == WB_GRAB_RIGID) { /* (particle grabs hash as they always did) */
            h = fnv(h, &gr->kind[i], 1);
            h = fnv(h, &gr->local[3 * i], 3 * sizeof(wb_real));
        }
        h = fnv(h, &gr->target[3 * i], 3 * sizeof(wb_real));
        h = fnv(h, &gr->from[3 * i], 3 * sizeof(wb_real));
        h = fnv(h, &gr->alpha[i], sizeof(wb_real));
    }
    const wb_rigids *rb = w->rb;
    for (int32_t r = 0; rb && r < rb->n; r++) { /* (worlds without any hash as they always did) */
        if (!(rb->gen[r] & 1u)) continue;
        const wb_cshape *sh = &rb->shape[r];
        const int32_t shape = (int32_t)sh->shape;
        h = fnv(h, &r, sizeof r);
        h = fnv(h, &rb->gen[r], sizeof rb->gen[r]);
        h = fnv(h, &shape, sizeof shape);
        h = fnv(h, &sh->radius, sizeof sh->radius);
        h = fnv(h, sh->half, sizeof sh->half);
        h = fnv(h, sh->a, sizeof sh->a);
        h = fnv(h, sh->b, sizeof sh->b);
        h = fnv(h, &sh->friction, sizeof sh->friction);
        h = fnv(h, &sh->restitution, sizeof sh->restitution);
        h = fnv(h, &rb->mass[r], sizeof(wb_real));
        h = fnv(h, &rb->x[3 * r], 3 * sizeof(wb_real));
        h = fnv(h, &rb->q[4 * r], 4 * sizeof(wb_real));
        h = fnv(h, &rb->v[3 * r], 3 * sizeof(wb_real));
        h = fnv(h, &rb->om[3 * r], 3 * sizeof(wb_real));
    }
    h = fnv(h, &s->time, sizeof s->time);
    h = fnv(h, &s->frame, sizeof s->frame);
    return h;
}

wb_stats wb_world_stats(const wb_world *w)
{
    wb_stats st;
    memset(&st, 0, sizeof st);
    st.particles = w->m.np;
    st.distances = w->m.nd_live;
    for (int32_t s = 0; s < w->m.nd; s++)
        if ((w->m.d_gen[s] & 1u) && w->s.d_broken[s]) st.broken++;
    st.colliders = wb_collider_count(w);
    st.bends = wb_bend_count(w);
    st.volumes = wb_volume_count(w);
    st.tets = wb_tet_count(w);
    st.shape_matches = wb_shape_match_count(w);
    st.pressures = wb_pressure_count(w);
    st.colours = w->k.ncolours;
    st.contacts = w->k.last_contacts;
    st.particle_contacts = w->k.pc.last + w->k.tc.last;
    st.broad_ms = w->k.pc.broad_ms + w->k.tc.broad_ms;
    st.residual = wb__vbd_residual(w);
    st.broad_remakes = w->k.pc.remakes_frame;
    st.projections = w->k.projections;
    st.step_ms = w->k.step_ms;
    st.solve_ms = w->k.solve_ms;
    st.warnings = w->s.warnings;
    st.attachments = wb_attach_count(w);
    st.grabs = wb_grab_count(w);
    st.rigids = wb_rigid_count(w);
    st.rigid_contacts = wb_world_rigid_contact_count(w);
    return st;
}
