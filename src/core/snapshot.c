/* snapshot.c: a world to and from flat arrays (wb_image, snapshot.h): exact copies,
 * the JSON snapshot's restore, and appending a particle config to a world.
 *
 * Exact means bit for bit: the restored world has every model and state array of the
 * original, constraint and collider slots in the same order with the same generations
 * and free lists, so it colours its constraints into the same batches and steps the
 * same. The solver cache is not copied; it is rebuilt from the model before the next
 * step, as after any topology edit. */
#include <stdlib.h>

#include "ctype.h"
#include "bvh.h"
#include "snapshot.h"
#include "contact.h"

static int fin3(const wb_real *v) { return isfinite(v[0]) && isfinite(v[1]) && isfinite(v[2]); }

/* calloc of n elements, never of 0 bytes (so NULL always means out of memory) */
static void *zalloc(int64_t n, size_t elem) { return calloc((size_t)(n > 0 ? n : 1), elem); }

wb_status wb_image_alloc(wb_image *g, int32_t np, int32_t nd, int32_t nfree, int32_t nc, int32_t nsurf, int32_t ntri)
{
    memset(g, 0, sizeof *g);
    g->def = wb_world_default_def();
    g->np = np;
    g->nc = nc;
    g->nsurf = nsurf;
    g->ntri = ntri;
    g->x = zalloc(3 * (int64_t)np, sizeof *g->x);
    g->v = zalloc(3 * (int64_t)np, sizeof *g->v);
    g->inv_mass = zalloc(np, sizeof *g->inv_mass);
    g->radius = zalloc(np, sizeof *g->radius);
    g->pinned = zalloc(np, 1);
    g->group = zalloc(np, sizeof *g->group);
    g->cflags = zalloc(np, 1);
    g->cfric = zalloc(np, sizeof *g->cfric);
    g->x0 = zalloc(3 * (int64_t)np, sizeof *g->x0);
    g->c = zalloc(nc, sizeof *g->c);
    g->c_gen = zalloc(nc, sizeof *g->c_gen);
    g->surf_start = zalloc((int64_t)nsurf + 1, sizeof *g->surf_start);
    g->tri = zalloc(3 * (int64_t)ntri, sizeof *g->tri);
    if (!g->x || !g->v || !g->inv_mass || !g->radius || !g->pinned || !g->c || !g->c_gen || !g->surf_start ||
        !g->tri || !g->group || !g->cflags || !g->cfric || !g->x0 || wb_image_alloc_distances(g, nd, nfree) != WB_OK) {
        wb_image_free(g);
        return WB_ERR_NOMEM;
    }
    memset(g->cflags, WB_CF_COLLIDE, (size_t)np);
    for (int32_t i = 0; i < nc; i++) {
        g->c_gen[i] = 1;
        g->c[i].q[0] = g->c[i].q0[0] = 1;
    }
    return WB_OK;
}

void wb_image_free(wb_image *g)
{
    for (int32_t i = 0; g->c && i < g->nc; i++) {
        free(g->c[i].mv);
        free(g->c[i].mt);
    }
    void *p[] = { g->x, g->v, g->inv_mass, g->radius, g->pinned, g->c, g->c_gen, g->surf_start, g->tri, g->group,
                  g->cflags, g->cfric, g->x0 };
    for (size_t i = 0; i < sizeof p / sizeof p[0]; i++) free(p[i]);
    for (int i = 0; i < wb__nctypes; i++)
        if (wb__ctypes[i]->image_free) wb__ctypes[i]->image_free(g);
    wb__rigid_image_free(g);
    wb__vbd_image_free(g);
    memset(g, 0, sizeof *g);
}

wb_status wb_image_of(const wb_world *w, wb_image *g)
{
    const wb_model *m = &w->m;
    const wb_state *s = &w->s;
    wb_status st = wb_image_alloc(g, m->np, 0, 0, m->nc, m->nsurf, m->ntri); /* the types' sections: below */
    if (st != WB_OK) return st;
    g->def = m->def;
    const size_t np = (size_t)m->np;
    if (np) {
        memcpy(g->x, s->x, 3 * np * sizeof *g->x);
        memcpy(g->v, s->v, 3 * np * sizeof *g->v);
        memcpy(g->inv_mass, m->inv_mass, np * sizeof *g->inv_mass);
        memcpy(g->radius, m->radius, np * sizeof *g->radius);
        memcpy(g->pinned, m->pinned, np);
        memcpy(g->group, m->group, np * sizeof *g->group);
        memcpy(g->cflags, m->cflags, np);
        memcpy(g->cfric, m->cfric, np * sizeof *g->cfric);
        memcpy(g->x0, m->x0, 3 * np * sizeof *g->x0);
    }
    for (int32_t i = 0; i < m->nc; i++) {
        const wb_cshape *cs = &m->c_shape[i];
        const wb_collider_pose *cp = &s->c_pose[i];
        wb_image_collider *c = &g->c[i];
        c->shape = cs->shape;
        v3_copy(c->n, cs->n);
        c->radius = cs->radius;
        v3_copy(c->half, cs->half);
        v3_copy(c->a, cs->a);
        v3_copy(c->b, cs->b);
        c->friction = cs->friction;
        c->restitution = cs->restitution;
        v3_copy(c->p, cp->p);
        memcpy(c->q, cp->q, sizeof c->q);
        v3_copy(c->p0, cp->p0);
        memcpy(c->q0, cp->q0, sizeof c->q0);
        v3_copy(c->v, cp->v);
        v3_copy(c->om, cp->om);
        g->c_gen[i] = m->c_gen[i];
        if (cs->mesh && (m->c_gen[i] & 1u)) {
            const wb_colmesh *cm = cs->mesh;
            c->mv = malloc(3 * (size_t)(cm->nv > 0 ? cm->nv : 1) * sizeof *c->mv);
            c->mt = malloc(3 * (size_t)cm->nt * sizeof *c->mt);
            if (!c->mv || !c->mt) {
                wb_image_free(g);
                return WB_ERR_NOMEM;
            }
            c->mnv = cm->nv;
            c->mnt = cm->nt;
            memcpy(c->mv, cm->v, 3 * (size_t)cm->nv * sizeof *c->mv);
            memcpy(c->mt, cm->tri, 3 * (size_t)cm->nt * sizeof *c->mt);
        }
    }
    if (m->nsurf) memcpy(g->surf_start, m->surf_start, ((size_t)m->nsurf + 1) * sizeof *g->surf_start);
    if (m->ntri) memcpy(g->tri, m->tri, 3 * (size_t)m->ntri * sizeof *g->tri);
    g->time = s->time;
    g->frame = s->frame;
    g->warnings = s->warnings;
    memcpy(g->last_warning, s->last_warning, sizeof g->last_warning);
    if ((st = wb__rigid_image_of(w, g)) != WB_OK) {
        wb_image_free(g);
        return st;
    }
    for (int i = 0; i < wb__nctypes && st == WB_OK; i++)
        if (wb__ctypes[i]->image_save) st = wb__ctypes[i]->image_save(w, g);
    if (st == WB_OK) st = wb__vbd_image_of(w, g);
    if (st != WB_OK) wb_image_free(g);
    return st;
}

/* ---- checks ---------------------------------------------------------------------------- */
const char *wb_image_collider_shape_check(const wb_image_collider *c)
{
    const wb_shape_class *k = wb__shape(c->shape);
    if (!k) return "unknown collider shape";
    if (!k->check_shape) return NULL;
    wb_cshape t = { .shape = c->shape, .radius = c->radius };
    v3_copy(t.n, c->n);
    v3_copy(t.half, c->half);
    v3_copy(t.a, c->a);
    v3_copy(t.b, c->b);
    return k->check_shape(&t);
}

static const char *check_collider(const wb_image_collider *c)
{
    if (!wb__shape(c->shape)) return "unknown collider shape";
    if (!(c->friction >= 0) || !isfinite(c->friction)) return "collider friction must be >= 0";
    if (!(c->restitution >= 0 && c->restitution <= 1)) return "collider restitution must be in [0, 1]";
    if (!fin3(c->n) || !fin3(c->half) || !fin3(c->a) || !fin3(c->b) || !isfinite(c->radius)) return "collider shape must be finite";
    if (!fin3(c->p) || !fin3(c->p0) || !fin3(c->v) || !fin3(c->om)) return "collider pose must be finite";
    for (int i = 0; i < 4; i++)
        if (!isfinite(c->q[i]) || !isfinite(c->q0[i])) return "collider rotation must be finite";
    if (c->q[0] * c->q[0] + v3_dot(&c->q[1], &c->q[1]) < 1e-24) return "collider rotation must not be zero";
    if (c->q0[0] * c->q0[0] + v3_dot(&c->q0[1], &c->q0[1]) < 1e-24) return "collider rotation must not be zero";
    const char *e = wb_image_collider_shape_check(c);
    if (e) return e;
    if (wb__shape(c->shape)->has_mesh) {
        if (!c->mv || !c->mt || c->mnt <= 0 || c->mnv <= 0) return "mesh collider has no triangles";
        for (int64_t i = 0; i < 3 * (int64_t)c->mnv; i++)
            if (!isfinite(c->mv[i])) return "mesh collider vertices must be finite";
        for (int64_t i = 0; i < 3 * (int64_t)c->mnt; i++)
            if (c->mt[i] < 0 || c->mt[i] >= c->mnv) return "mesh collider corner out of range";
    }
    return NULL;
}

const char *wb_image_check(const wb_image *g)
{
    const char *e = wb_world_def_check(&g->def);
    if (e) return e;
    if (g->np < 0 || g->np > WB_MAX_PARTICLES) return "too many particles";
    if (g->nc < 0 || g->nc > WB_MAX_COLLIDERS) return "too many colliders";
    if (g->nsurf < 0 || g->ntri < 0 || g->ntri > WB_MAX_CONSTRAINTS) return "too many triangles";
    for (int32_t i = 0; i < g->np; i++) {
        if (!fin3(&g->x[3 * i]) || !fin3(&g->v[3 * i])) return "particle position and velocity must be finite";
        if (!(g->inv_mass[i] >= 0) || !isfinite(g->inv_mass[i])) return "particle mass must be >= 0";
        if (!(g->radius[i] >= 0) || !isfinite(g->radius[i])) return "particle radius must be >= 0";
        if (g->group[i] < 0 || g->group[i] > WB_MAX_GROUP) return "particle group must be in 0..2^30";
        if (g->cflags[i] > (WB_CF_COLLIDE | WB_CF_SELF)) return "particle contact flags out of range";
        if (!(g->cfric[i] >= 0) || !isfinite(g->cfric[i])) return "particle friction must be >= 0";
        if (!fin3(&g->x0[3 * i])) return "particle rest position must be finite";
    }
    for (int32_t i = 0; i < g->nc; i++)
        if ((g->c_gen[i] & 1u) && (e = check_collider(&g->c[i]))) return e;
    if (g->nsurf > 0 && (g->surf_start[0] != 0 || g->surf_start[g->nsurf] != g->ntri)) return "surface ranges do not cover the triangles";
    for (int32_t i = 0; i < g->nsurf; i++)
        if (g->surf_start[i + 1] < g->surf_start[i]) return "surface ranges are not in order";
    if (g->nsurf == 0 && g->ntri != 0) return "triangles without a surface";
    for (int64_t i = 0; i < 3 * (int64_t)g->ntri; i++)
        if (g->tri[i] < 0 || g->tri[i] >= g->np) return "surface corner out of range";
    if (!(g->time >= 0) || !isfinite(g->time) || g->frame < 0 || g->warnings < 0) return "time, frame and warnings must be finite and >= 0";
    for (int i = 0; i < wb__nctypes; i++)
        if (wb__ctypes[i]->image_check && (e = wb__ctypes[i]->image_check(g))) return e;
    if ((e = wb__vbd_image_check(g))) return e;
    return wb__rigid_image_check(g);
}

/* every type's section of the image: room for it in w, then (nothing can fail) put */
static wb_status reserve_types(wb_world *w, const wb_image *g, const wb_image_at *at)
{
    wb_status st = WB_OK;
    for (int i = 0; i < wb__nctypes && st == WB_OK; i++)
        if (wb__ctypes[i]->image_reserve) st = wb__ctypes[i]->image_reserve(w, g, at);
    return st;
}

static void put_types(wb_world *w, const wb_image *g, const wb_image_at *at)
{
    for (int i = 0; i < wb__nctypes; i++)
        if (wb__ctypes[i]->image_put) wb__ctypes[i]->image_put(w, g, at);
}

/* ---- exact restore ----------------------------------------------------------------------- */
static wb_status grow_colliders(wb_world *w, int32_t need)
{
    wb_model *m = &w->m;
    if (need <= m->cap_c) return WB_OK;
    /* the three arrays share cap_c (as collide.c grows them): grow them alike */
    int32_t c1 = m->cap_c, c2 = m->cap_c, c3 = m->cap_c;
    wb_cshape *sh = wb__grow(m->c_shape, &c1, need, sizeof *sh);
    if (!sh) return WB_ERR_NOMEM;
    m->c_shape = sh;
    uint32_t *gen = wb__grow(m->c_gen, &c2, need, sizeof *gen);
    if (!gen) return WB_ERR_NOMEM;
    m->c_gen = gen;
    wb_collider_pose *po = wb__grow(w->s.c_pose, &c3, need, sizeof *po);
    if (!po) return WB_ERR_NOMEM;
    w->s.c_pose = po;
    m->cap_c = c1;
    return WB_OK;
}

/* the mesh colliders' copies of the image's live colliders, built and charged before
 * anything changes (all or nothing); cms[i] is NULL for other shapes */
static wb_status build_meshes(wb_world *w, const wb_image *g, wb_colmesh **cms)
{
    for (int32_t i = 0; i < g->nc; i++) {
        const wb_image_collider *c = &g->c[i];
        cms[i] = NULL;
        if (!(g->c_gen[i] & 1u) || !wb__shape(c->shape) || !wb__shape(c->shape)->has_mesh) continue;
        cms[i] = wb__colmesh_build(c->mv, c->mnv, c->mt, c->mnt, 1);
        if (!cms[i] || !wb__mesh_charge(w, cms[i])) {
            wb__colmesh_free(cms[i]);
            for (int32_t j = 0; j < i; j++) {
                wb_cshape tmp = { .mesh = cms[j] };
                wb__mesh_release(w, &tmp);
            }
            return WB_ERR_NOMEM;
        }
    }
    return WB_OK;
}

static void put_collider(wb_world *w, int32_t slot, const wb_image_collider *c, wb_colmesh *cm)
{
    wb_cshape *cs = &w->m.c_shape[slot];
    wb_collider_pose *cp = &w->s.c_pose[slot];
    memset(cs, 0, sizeof *cs);
    cs->mesh = cm;
    cs->shape = c->shape;
    v3_copy(cs->n, c->n);
    cs->radius = c->radius;
    v3_copy(cs->half, c->half);
    v3_copy(cs->a, c->a);
    v3_copy(cs->b, c->b);
    cs->friction = c->friction;
    cs->restitution = c->restitution;
    v3_copy(cp->p, c->p);
    memcpy(cp->q, c->q, sizeof cp->q);
    v3_copy(cp->p0, c->p0);
    memcpy(cp->q0, c->q0, sizeof cp->q0);
    v3_copy(cp->v, c->v);
    v3_copy(cp->om, c->om);
}

static wb_status reserve_surfaces(wb_world *w, int32_t nsurf, int32_t ntri)
{
    wb_model *m = &w->m;
    if (nsurf == 0) return WB_OK;
    wb_status st = wb__surface_reserve(w, ntri);
    if (st != WB_OK) return st;
    int32_t *ss = wb__grow(m->surf_start, &m->cap_surf, m->nsurf + nsurf + 1, sizeof *ss);
    if (!ss) return WB_ERR_NOMEM;
    m->surf_start = ss;
    return WB_OK;
}

/* copy the image's surfaces after w's, corners shifted by `shift` (space reserved) */
static void put_surfaces(wb_world *w, const wb_image *g, int32_t shift)
{
    wb_model *m = &w->m;
    if (g->nsurf == 0) return;
    if (m->nsurf == 0) m->surf_start[0] = 0;
    for (int64_t i = 0; i < 3 * (int64_t)g->ntri; i++) m->tri[3 * (int64_t)m->ntri + i] = g->tri[i] + shift;
    for (int32_t s = 1; s <= g->nsurf; s++) m->surf_start[m->nsurf + s] = m->ntri + g->surf_start[s];
    m->nsurf += g->nsurf;
    m->ntri += g->ntri;
}

wb_world *wb_world_from_image(const wb_image *g, wb_status *status)
{
    wb_status dummy;
    if (!status) status = &dummy;
    const char *e = wb_image_check(g);
    if (e) {
        wb__set_error("%s", e);
        *status = WB_ERR_ARG;
        return NULL;
    }
    wb_world *w = wb_world_create(&g->def);
    wb_colmesh **cms = calloc((size_t)(g->nc > 0 ? g->nc : 1), sizeof *cms);
    const wb_image_at at = { 1, 0, 0, NULL, NULL };
    wb_status st = w && cms ? wb__particles_reserve(w, g->np) : WB_ERR_NOMEM;
    if (st == WB_OK) st = grow_colliders(w, g->nc);
    if (st == WB_OK) st = reserve_surfaces(w, g->nsurf, g->ntri);
    if (st == WB_OK) st = wb__rigid_reserve(w, g, 1);
    if (st == WB_OK) st = reserve_types(w, g, &at);
    if (st == WB_OK) st = wb__vbd_image_put(w, g);
    if (st == WB_OK) st = build_meshes(w, g, cms);
    if (st != WB_OK) {
        free(cms);
        wb_world_destroy(w);
        *status = st;
        return NULL;
    }
    wb_model *m = &w->m;
    wb_state *s = &w->s;
    const size_t np = (size_t)g->np;
    m->np = g->np;
    if (np) {
        memcpy(s->x, g->x, 3 * np * sizeof *s->x);
        memcpy(s->x_prev, g->x, 3 * np * sizeof *s->x);
        memcpy(s->v, g->v, 3 * np * sizeof *s->v);
        memcpy(m->inv_mass, g->inv_mass, np * sizeof *m->inv_mass);
        memcpy(m->radius, g->radius, np * sizeof *m->radius);
        memcpy(m->pinned, g->pinned, np);
        memcpy(m->group, g->group, np * sizeof *m->group);
        memcpy(m->cflags, g->cflags, np);
        memcpy(m->cfric, g->cfric, np * sizeof *m->cfric);
        memcpy(m->x0, g->x0, 3 * np * sizeof *m->x0);
    }
    for (size_t i = 0; i < np; i++) m->w[i] = g->pinned[i] ? 0 : g->inv_mass[i];
    m->w_gen++;
    m->nc = g->nc;
    for (int32_t i = 0; i < g->nc; i++) {
        put_collider(w, i, &g->c[i], cms[i]);
        m->c_gen[i] = g->c_gen[i];
    }
    free(cms);
    put_surfaces(w, g, 0);
    wb__rigid_put(w, g, 1, NULL); /* before the types: attachments and grabs name bodies */
    put_types(w, g, &at);
    s->time = g->time;
    s->frame = g->frame;
    s->warnings = g->warnings;
    memcpy(s->last_warning, g->last_warning, sizeof s->last_warning);
    s->last_warning[sizeof s->last_warning - 1] = '\0';
    m->topology_dirty = 1;
    *status = WB_OK;
    return w;
}

wb_world *wb_world_clone(const wb_world *w)
{
    wb_image g;
    if (wb_image_of(w, &g) != WB_OK) return NULL;
    wb_world *c = wb_world_from_image(&g, NULL);
    wb_image_free(&g);
    return c;
}

/* ---- append (w:load_particles) ------------------------------------------------------------ */
wb_status wb_world_append_image(wb_world *w, const wb_image *g, wb_body *out)
{
    const char *e = wb_image_check(g);
    if (e) {
        wb__set_error("%s", e);
        return WB_ERR_ARG;
    }
    wb_model *m = &w->m;
    int32_t live_c = 0, dead_c = 0;
    for (int32_t i = 0; i < g->nc; i++) live_c += (int32_t)(g->c_gen[i] & 1u);
    for (int32_t i = 0; i < m->nc; i++) dead_c += !(m->c_gen[i] & 1u);
    const int32_t new_c = live_c > dead_c ? live_c - dead_c : 0;
    if ((int64_t)m->nc + new_c > WB_MAX_COLLIDERS || (int64_t)m->ntri + g->ntri > WB_MAX_CONSTRAINTS) return WB_ERR_LIMIT;
    /* the image's groups become new ones: its loose particles (a plain config has no
     * groups) the body's group, its group k the group body + k */
    const int32_t group = wb_group_new(w);
    int32_t gmax = 0;
    for (int32_t i = 0; i < g->np; i++)
        if (g->group[i] > gmax) gmax = g->group[i];
    if ((int64_t)group + gmax > WB_MAX_GROUP) return WB_ERR_LIMIT;
    /* everything reserved first: after this nothing can fail */
    wb_colmesh **cms = calloc((size_t)(g->nc > 0 ? g->nc : 1), sizeof *cms);
    int32_t *cmap = calloc((size_t)(g->nc > 0 ? g->nc : 1), sizeof *cmap); /* image slot -> w's */
    int32_t *rmap = calloc((size_t)(g->nrb > 0 ? g->nrb : 1), sizeof *rmap); /* the same for rigid bodies */
    if (!cms || !cmap || !rmap) { free(cms); free(cmap); free(rmap); return WB_ERR_NOMEM; }
    const wb_image_at at = { 0, m->np, m->nsurf, cmap, rmap };
    wb_status st = wb__particles_reserve(w, g->np);
    if (st == WB_OK) st = grow_colliders(w, m->nc + new_c);
    if (st == WB_OK) st = reserve_surfaces(w, g->nsurf, g->ntri);
    if (st == WB_OK) st = wb__rigid_reserve(w, g, 0);
    if (st == WB_OK) st = reserve_types(w, g, &at);
    if (st == WB_OK) st = build_meshes(w, g, cms);
    if (st != WB_OK) {
        free(cms);
        free(cmap);
        free(rmap);
        return st;
    }

    const int32_t first = m->np;
    for (int32_t i = 0; i < g->np; i++) {
        wb_particle_add(w, &g->x[3 * i], &g->v[3 * i], g->inv_mass[i] > 0 ? 1 / g->inv_mass[i] : 0, g->radius[i]);
        /* the exact inverse mass (1/(1/m) need not give m back), and the velocity even of a
         * particle added as immovable is 0 as the image says */
        m->inv_mass[first + i] = g->inv_mass[i];
        m->pinned[first + i] = g->pinned[i];
        m->w[first + i] = g->pinned[i] ? 0 : g->inv_mass[i];
        memcpy(&w->s.v[3 * (first + i)], &g->v[3 * i], 3 * sizeof(wb_real));
        m->group[first + i] = group + g->group[i];
        m->cflags[first + i] = g->cflags[i];
        m->cfric[first + i] = g->cfric[i];
        memcpy(&m->x0[3 * (first + i)], &g->x0[3 * i], 3 * sizeof(wb_real));
    }
    if (w->k.pc) w->k.pc->scan_dirty = 1;
    int32_t scan = 0; /* dead slots are taken lowest first: the scan never goes back */
    for (int32_t i = 0; i < g->nc; i++) {
        if (!(g->c_gen[i] & 1u)) continue;
        int32_t slot = -1;
        for (; scan < m->nc && slot < 0; scan++)
            if (!(m->c_gen[scan] & 1u)) slot = scan;
        if (slot < 0) {
            slot = m->nc++;
            m->c_gen[slot] = 0;
        }
        put_collider(w, slot, &g->c[i], cms[i]);
        m->c_gen[slot]++;
        cmap[i] = slot;
    }
    free(cms);
    put_surfaces(w, g, first);
    /* the image's rigid bodies go to free or new slots: the attachments follow them */
    wb__rigid_put(w, g, 0, rmap);
    put_types(w, g, &at);
    free(rmap);
    free(cmap);
    m->topology_dirty = 1;
    out->first = first;
    out->count = g->np;
    out->group = group;
    return WB_OK;
}

/* a collider given as w:collider{...} would make it (world-frame def -> own frame + pose),
 * through the same code path, so the two cannot differ by a rounding */
wb_status wb_image_collider_from_def(const wb_collider_def *d, wb_image_collider *out)
{
    const char *e = wb_collider_def_check(d);
    if (e) {
        wb__set_error("%s", e);
        return WB_ERR_ARG;
    }
    wb_world_def wd = wb_world_default_def();
    wb_world *w = wb_world_create(&wd);
    if (!w) return WB_ERR_NOMEM;
    wb_status st = WB_OK;
    wb_collider_id id = wb_collider_add(w, d, &st);
    if (st == WB_OK) {
        wb_image g;
        st = wb_image_of(w, &g);
        if (st == WB_OK) {
            *out = g.c[id.index - 1];
            g.c[id.index - 1].mv = NULL; /* the mesh's arrays go to out */
            g.c[id.index - 1].mt = NULL;
        }
        wb_image_free(&g);
    }
    wb_world_destroy(w);
    return st;
}
