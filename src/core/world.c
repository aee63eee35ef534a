/* world.c: world lifetime, settings, particles and surfaces; the helpers every owner calls
 * (errors, warnings, growth, the memory budget). */
#include <assert.h>
#include <float.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>

#include "core.h"

static _Thread_local char wb_err[256];

void wb__set_error(const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(wb_err, sizeof wb_err, fmt, ap);
    va_end(ap);
}

const char *wb_last_error(void) { return wb_err; }

void wb__warn(wb_world *w, const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(w->s.last_warning, sizeof w->s.last_warning, fmt, ap);
    va_end(ap);
    w->s.warnings++;
}

int64_t wb_world_warnings(const wb_world *w) { return w->s.warnings; }
const char *wb_world_last_warning(const wb_world *w) { return w->s.last_warning; }

/* grow *ptr to hold need elements (doubling); NULL on failure, *ptr untouched */
void *wb__grow(void *ptr, int32_t *cap, int32_t need, size_t elem)
{
    if (need <= *cap) return ptr;
    int64_t c = *cap ? *cap : 16;
    while (c < need) c *= 2;
    void *q = realloc(ptr, (size_t)c * elem);
    if (!q) return NULL;
    *cap = (int32_t)c;
    return q;
}

wb_status wb__soa_resize(const wb_soa *arr, size_t n, int64_t cap)
{
    for (size_t i = 0; i < n; i++) {
        void *q = realloc(*arr[i].p, (size_t)cap * arr[i].elem);
        if (!q) return WB_ERR_NOMEM;
        *arr[i].p = q;
    }
    return WB_OK;
}

int32_t wb__grown_cap(int32_t cap, int64_t need, int32_t first)
{
    assert(first > 0);
    int64_t c = cap ? cap : first;
    while (c < need) c *= 2;
    return (int32_t)(c < WB_MAX_CONSTRAINTS ? c : WB_MAX_CONSTRAINTS);
}

static int finite3(const wb_real *v) { return isfinite(v[0]) && isfinite(v[1]) && isfinite(v[2]); }

/* ---- world ---------------------------------------------------------------------- */
wb_world_def wb_world_default_def(void)
{
    wb_world_def d;
    memset(&d, 0, sizeof d);
    v3_set(d.gravity, 0, -9.81, 0);
    d.dt = 1.0 / 60.0;
    d.substeps = 10;
    d.iterations = 1;
    d.damping = 0;
    d.solver = WB_SOLVER_GAUSS_SEIDEL;
    d.relaxation = 1;
    d.threads = 1;
    d.contacts = true;
    d.max_depenetration = 0.25;
    return d;
}

const char *wb_world_def_check(const wb_world_def *d)
{
    if (!finite3(d->gravity)) return "gravity must be finite";
    if (!(d->dt > 0) || !isfinite(d->dt) || d->dt > 10) return "dt must be in (0, 10] seconds";
    if (d->substeps < 1 || d->substeps > WB_MAX_SUBSTEPS) return "substeps must be in 1..10000";
    if (d->iterations < 1 || d->iterations > WB_MAX_ITERATIONS) return "iterations must be in 1..10000";
    /* the step divides by h^2 (compliance/h^2, force = lambda/h^2) with h = dt/substeps:
     * h^2 must be a normal double (h >= 1.5e-154 s), else 1/h^2 overflows, 0 * inf turns
     * every position NaN and every frame is undone */
#ifdef WB_FLOAT
    const wb_real h2_min = FLT_MIN;
#else
    const wb_real h2_min = DBL_MIN;
#endif
    const wb_real h = d->dt / d->substeps;
    if (!(h * h >= h2_min)) return "dt/substeps is too short: h = dt/substeps must be >= 1.5e-154 s (h*h underflows)";
    if (!(d->damping >= 0) || !isfinite(d->damping)) return "damping must be >= 0";
    if (d->solver != WB_SOLVER_GAUSS_SEIDEL && d->solver != WB_SOLVER_JACOBI && d->solver != WB_SOLVER_VBD) return "unknown solver";
    if (!(d->relaxation > 0 && d->relaxation < 2)) return "relaxation must be in (0, 2)";
    if (d->threads < 1 || d->threads > WB_MAX_THREADS) return "threads must be in 1..256";
    if (!(d->max_depenetration >= 0) || !isfinite(d->max_depenetration)) return "max_depenetration must be finite and >= 0 (m/s)";
    if (!(d->tolerance >= 0) || !isfinite(d->tolerance)) return "tolerance must be finite and >= 0 (m)";
    return NULL;
}

/* what a world takes before it holds anything: the struct (malloc's header too) and, for
 * threads > 1, its worker threads (the stack pages a step touches, thread-local storage:
 * about 18 kB each measured; 256 threads = 255 workers) */
#define THREAD_BYTES ((size_t)32 << 10)
static size_t self_bytes(int threads)
{
    return sizeof(wb_world) + 16 + (threads > 1 ? (size_t)(threads - 1) * THREAD_BYTES : 0);
}

/* charge the world's own bytes for `threads` to its budget; 0 when that would pass
 * the limit (nothing changed then) */
static int charge_self(wb_world *w, wb_memory *mem, int threads)
{
    const size_t want = self_bytes(threads);
    if (!mem) return 1;
    if (want > w->charged_self) {
        const size_t more = want - w->charged_self;
        if (mem->limit > 0 && (more > mem->limit || mem->used > mem->limit - more)) return 0;
        mem->used += more;
    } else {
        mem->used -= w->charged_self - want;
    }
    w->charged_self = want;
    return 1;
}

wb_world *wb_world_create(const wb_world_def *def)
{
    assert(wb_world_def_check(def) == NULL);
    wb_world *w = calloc(1, sizeof *w);
    if (!w) return NULL;
    if (!charge_self(w, def->memory, def->threads)) {
        free(w);
        return NULL;
    }
    w->m.def = *def;
    return w;
}

wb_pool *wb__world_pool(const wb_world *w)
{
    wb_world *mw = (wb_world *)w; /* worlds are heap objects: the pool is a mutable cache */
    wb_pool *p = wb__pool_get(&mw->pool, w->m.def.threads);
    if (wb__pool_failure_news(p))
        wb__warn(mw, "threads = %d: no worker thread could be started; the steps run on one thread "
                 "(the same results)", w->m.def.threads);
    return p;
}

wb_world_def wb_world_get_def(const wb_world *w) { return w->m.def; }

wb_status wb_world_set_def(wb_world *w, const wb_world_def *def)
{
    const char *err = wb_world_def_check(def);
    if (err) { wb__set_error("%s", err); return WB_ERR_ARG; }
    wb_memory *mem = w->m.def.memory; /* charged to it: a world keeps its budget */
    if (!charge_self(w, mem, def->threads)) return WB_ERR_NOMEM; /* more threads than the budget has room for */
    w->m.def = *def;
    w->m.def.memory = mem;
    return WB_OK;
}

double wb_world_time(const wb_world *w) { return w->s.time; }

void wb_world_set_interrupt(wb_world *w, int (*fn)(void *ud), void *ud)
{
    w->k.interrupt = fn;
    w->k.interrupt_ud = ud;
}
int64_t wb_world_frame(const wb_world *w) { return w->s.frame; }

/* ---- particles ------------------------------------------------------------------- */
/* bytes per particle over all the arrays that grow with them (model, state and solver
 * cache), for the memory limit */
#define PARTICLE_BYTES (25 * sizeof(wb_real) + 5 + 8 + 5)

int wb__charge(wb_world *w, size_t *charged, size_t want)
{
    wb_memory *mem = w->m.def.memory;
    if (mem) {
        const double used = (double)mem->used - (double)*charged + (double)want;
        if (mem->limit > 0 && used > (double)mem->limit) return 0;
        mem->used = (size_t)used;
    }
    *charged = want;
    return 1;
}

/* the particles' arrays at capacity cap_p */
int32_t wb__charge_cap(wb_world *w, size_t *charged, size_t per, int32_t cap, int32_t need, int32_t max)
{
    if (cap <= 0) cap = 64;
    while (cap < need) cap = cap > max / 2 ? max : cap * 2;
    if (wb__charge(w, charged, (size_t)cap * per)) return cap;
    return wb__charge(w, charged, (size_t)need * per) ? need : -1;
}

/* every per-particle array grows together; on failure nothing is lost */
static wb_status grow_particles(wb_world *w, int32_t need)
{
    wb_model *m = &w->m;
    if (need <= m->cap_p) return WB_OK;
    if (need > WB_MAX_PARTICLES) return WB_ERR_LIMIT;
    const int32_t cap = wb__charge_cap(w, &m->charged, PARTICLE_BYTES, m->cap_p, need, WB_MAX_PARTICLES);
    if (cap < 0) return WB_ERR_NOMEM;
    const wb_soa arr[] = {
        { (void **)&m->inv_mass, sizeof(wb_real) }, { (void **)&m->w, sizeof(wb_real) },
        { (void **)&m->radius, sizeof(wb_real) }, { (void **)&m->pinned, 1 },
        { (void **)&w->s.x, 3 * sizeof(wb_real) }, { (void **)&w->s.x_prev, 3 * sizeof(wb_real) },
        { (void **)&w->s.v, 3 * sizeof(wb_real) }, { (void **)&w->k.dx, 3 * sizeof(wb_real) },
        { (void **)&w->k.x_save, 3 * sizeof(wb_real) }, { (void **)&w->k.v_save, 3 * sizeof(wb_real) },
        { (void **)&w->k.ncount, sizeof(int32_t) },
        { (void **)&m->group, sizeof(int32_t) }, { (void **)&m->cflags, 1 },
        { (void **)&m->cfric, sizeof(wb_real) }, { (void **)&m->x0, 3 * sizeof(wb_real) },
    };
    if (WB_SOA_RESIZE(arr, cap) != WB_OK) return WB_ERR_NOMEM;
    m->cap_p = cap;
    return WB_OK;
}

wb_status wb__particles_reserve(wb_world *w, int64_t extra)
{
    if (w->m.np + extra > WB_MAX_PARTICLES) return WB_ERR_LIMIT;
    return grow_particles(w, w->m.np + (int32_t)extra);
}

int32_t wb_particle_add(wb_world *w, const wb_real pos[3], const wb_real vel[3], wb_real mass, wb_real radius)
{
    assert(finite3(pos) && (!vel || finite3(vel)) && mass >= 0 && radius >= 0);
    if (mass > 0 && !isfinite(1 / mass)) {
        wb__set_error("mass %g is too small (its inverse overflows)", (double)mass);
        return WB_ERR_ARG;
    }
    wb_model *m = &w->m;
    wb_status st = grow_particles(w, m->np + 1);
    if (st != WB_OK) return st;
    int32_t i = m->np++;
    m->inv_mass[i] = mass > 0 ? 1 / mass : 0;
    m->w[i] = m->inv_mass[i];
    m->radius[i] = radius;
    m->pinned[i] = 0;
    m->group[i] = 0;
    m->cflags[i] = WB_CF_COLLIDE;
    m->cfric[i] = 0;
    v3_copy(&m->x0[3 * i], pos);
    v3_copy(&w->s.x[3 * i], pos);
    v3_copy(&w->s.x_prev[3 * i], pos);
    if (vel && mass > 0) v3_copy(&w->s.v[3 * i], vel);
    else v3_set(&w->s.v[3 * i], 0, 0, 0);
    m->topology_dirty = 1; /* Jacobi counts and scratch sizes */
    return i;
}

int32_t wb_particle_count(const wb_world *w) { return w->m.np; }
const wb_real *wb_particle_positions(const wb_world *w) { return w->s.x; }

#define CHECK_P(w, p) assert((p) >= 0 && (p) < (w)->m.np)

void wb_particle_position(const wb_world *w, int32_t p, wb_real out[3]) { CHECK_P(w, p); v3_copy(out, &w->s.x[3 * p]); }
void wb_particle_velocity(const wb_world *w, int32_t p, wb_real out[3]) { CHECK_P(w, p); v3_copy(out, &w->s.v[3 * p]); }
wb_real wb_particle_mass(const wb_world *w, int32_t p) { CHECK_P(w, p); return w->m.inv_mass[p] > 0 ? 1 / w->m.inv_mass[p] : 0; }
wb_real wb_particle_radius(const wb_world *w, int32_t p) { CHECK_P(w, p); return w->m.radius[p]; }
bool wb_particle_pinned(const wb_world *w, int32_t p) { CHECK_P(w, p); return w->m.pinned[p] != 0; }

void wb_particle_set_position(wb_world *w, int32_t p, const wb_real pos[3])
{
    CHECK_P(w, p);
    assert(finite3(pos));
    v3_copy(&w->s.x[3 * p], pos);
    v3_copy(&w->s.x_prev[3 * p], pos);
}

void wb_particle_set_velocity(wb_world *w, int32_t p, const wb_real vel[3])
{
    CHECK_P(w, p);
    assert(finite3(vel));
    if (w->m.w[p] > 0) v3_copy(&w->s.v[3 * p], vel); /* an immovable particle keeps v = 0 */
}

void wb_particle_pin(wb_world *w, int32_t p, const wb_real *pos)
{
    CHECK_P(w, p);
    if (pos) wb_particle_set_position(w, p, pos);
    w->m.pinned[p] = 1;
    w->m.w[p] = 0;
    w->m.w_gen++;
    v3_set(&w->s.v[3 * p], 0, 0, 0);
}

void wb_particle_unpin(wb_world *w, int32_t p)
{
    CHECK_P(w, p);
    w->m.pinned[p] = 0;
    w->m.w[p] = w->m.inv_mass[p];
    w->m.w_gen++;
}

/* ---- surfaces ------------------------------------------------------------------------ */
/* room for one more surface of ntri triangles: after it, wb_surface_add cannot fail
 * for lack of memory (builders reserve before they add anything) */
wb_status wb__surface_reserve(wb_world *w, int32_t ntri)
{
    wb_model *m = &w->m;
    if (ntri < 0 || (int64_t)m->ntri + ntri > WB_MAX_CONSTRAINTS) return WB_ERR_LIMIT;
    int32_t *st = wb__grow(m->surf_start, &m->cap_surf, m->nsurf + 2, sizeof *st);
    if (!st) return WB_ERR_NOMEM;
    m->surf_start = st;
    /* at least one slot: a surface may be empty, and a NULL array would read as no memory */
    int32_t *t = wb__grow(m->tri, &m->cap_tri, 3 * (m->ntri + ntri) + 1, sizeof *t);
    if (!t) return WB_ERR_NOMEM;
    m->tri = t;
    return WB_OK;
}

int32_t wb_surface_add(wb_world *w, const int32_t *tri, int32_t ntri)
{
    wb_model *m = &w->m;
    if (ntri < 0) { wb__set_error("negative triangle count"); return WB_ERR_ARG; }
    for (int32_t i = 0; i < 3 * ntri; i++)
        if (tri[i] < 0 || tri[i] >= m->np) { wb__set_error("triangle corner out of range"); return WB_ERR_ARG; }
    wb_status st = wb__surface_reserve(w, ntri);
    if (st != WB_OK) return st;
    if (m->nsurf == 0) m->surf_start[0] = 0;
    memcpy(&m->tri[3 * m->ntri], tri, sizeof *tri * 3 * (size_t)ntri);
    m->ntri += ntri;
    m->surf_start[++m->nsurf] = m->ntri;
    return m->nsurf - 1;
}

int32_t wb_surface_count(const wb_world *w) { return w->m.nsurf; }

const int32_t *wb_surface_triangles(const wb_world *w, int32_t s, int32_t *ntri)
{
    assert(s >= 0 && s < w->m.nsurf);
    *ntri = w->m.surf_start[s + 1] - w->m.surf_start[s];
    return &w->m.tri[3 * w->m.surf_start[s]];
}
