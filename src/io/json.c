/* json.c: JSON particle configs (the reference thesis's second import method) and
 * snapshots, through cJSON. The schema is in docs/formats.md ("Particle configs"); in short:
 *
 *   { "format": "wobble-particles", "version": 1,
 *     "particles": [ {"position": [x,y,z], "mass": 1, "pinned": false}, ... ],
 *     "constraints": [ {"type": "distance", "particles": [0, 1], "compliance": 0}, ... ],
 *     "colliders": [...], "surfaces": [...], "parts": [...], "skins": [...],
 *     "defaults": {...}, "snapshot": {...} }
 *
 * Errors name the file, line and column and the key path ("logo.json:12:7:
 * particles[3].mass: number expected, got string"; how, in json_value.c). The whole
 * file is read and checked into a wb_image before anything is built. Each constraint
 * type's elements ("constraints" entries, "volumes", ...) are read by its own file through
 * the jtypes table (json.h, json_types.c). */
#include <assert.h>
#include <ctype.h>
#include <errno.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>
#include <sys/stat.h>

#include "json.h"

#define MAX_FILE (1ll << 31) /* 2 GiB: a snapshot of WB_MAX_PARTICLES fits; larger is not ours */

/* ---- sections --------------------------------------------------------------------------------- */
#define MAX_DEFAULT_KEYS 32 /* the keys of "defaults": a particle's two and the types' */

/* "defaults": a particle's mass and radius here, each type's options by its reader */
static int read_defaults(rd *r, const cJSON *it, jdefaults *d)
{
    const char *keys[MAX_DEFAULT_KEYS + 1] = { "mass", "radius" };
    const cJSON *f[MAX_DEFAULT_KEYS + 1] = { NULL };
    int nk = 2, at[JT_MAX];
    for (int k = 0; k < njtypes; k++) {
        at[k] = nk;
        for (const char *const *q = jtypes[k]->default_keys; q && *q; q++) {
            assert(nk < MAX_DEFAULT_KEYS);
            keys[nk++] = *q;
        }
    }
    keys[nk] = NULL;
    kp p = { NULL, "defaults", 0 };
    d->mass = 1;
    d->radius = 0.02;
    if (it) {
        if (jv_get_object(r, it, &p, keys, f)) return -1;
        if (jv_opt_nonneg(r, f[0], &p, "mass", &d->mass)) return -1;
        if (d->mass > 0 && !isfinite(1 / d->mass)) {
            kp mp = { &p, "mass", 0 };
            return jv_fail(r, f[0], 0, &mp, "%g is too small (its inverse overflows)", (double)d->mass);
        }
        if (jv_opt_nonneg(r, f[1], &p, "radius", &d->radius)) return -1;
    }
    for (int k = 0; k < njtypes; k++)
        if (jtypes[k]->read_defaults && jtypes[k]->read_defaults(r, &f[at[k]], it ? &p : NULL, d)) return -1;
    return 0;
}

static const char *const solver_names[] = { "gauss-seidel", "jacobi", "vbd" };

/* the "world" settings of a snapshot */
static int read_world(rd *r, const cJSON *it, const kp *up, wb_world_def *d)
{
    static const char *const keys[] = { "gravity", "dt", "substeps", "iterations", "damping", "solver", "relaxation", "threads",
                                        "contacts", "max_depenetration", "tolerance", NULL };
    const cJSON *f[12];
    kp p = { up, "world", 0 };
    int64_t i;
    if (jv_get_object(r, it, &p, keys, f)) return -1;
    if (jv_opt_vec(r, f[0], &p, "gravity", 3, d->gravity) || jv_opt_real(r, f[1], &p, "dt", &d->dt)) return -1;
    if (f[2]) { if (jv_opt_int(r, f[2], &p, "substeps", 1, WB_MAX_SUBSTEPS, &i)) return -1; d->substeps = (int)i; }
    if (f[3]) { if (jv_opt_int(r, f[3], &p, "iterations", 1, WB_MAX_ITERATIONS, &i)) return -1; d->iterations = (int)i; }
    if (jv_opt_real(r, f[4], &p, "damping", &d->damping)) return -1;
    if (f[5]) {
        kp q = { &p, "solver", 0 };
        const char *s = "";
        if (jv_get_string(r, f[5], &q, &s)) return -1;
        int k = 0;
        while (k < 3 && strcmp(s, solver_names[k])) k++;
        if (k == 3) return jv_fail(r, f[5], 0, &q, "unknown solver '%s' (expected gauss-seidel, jacobi or vbd)", s);
        d->solver = (wb_solver)k;
    }
    if (jv_opt_real(r, f[6], &p, "relaxation", &d->relaxation)) return -1;
    if (f[7]) { if (jv_opt_int(r, f[7], &p, "threads", 1, WB_MAX_THREADS, &i)) return -1; d->threads = (int)i; }
    if (f[8]) {
        kp q = { &p, "contacts", 0 };
        if (jv_get_bool(r, f[8], &q, &d->contacts)) return -1;
    }
    if (jv_opt_real(r, f[9], &p, "max_depenetration", &d->max_depenetration)) return -1;
    if (jv_opt_real(r, f[10], &p, "tolerance", &d->tolerance)) return -1;
    const char *e = wb_world_def_check(d);
    return e ? jv_fail(r, it, 0, &p, "%s", e) : 0;
}

typedef struct sections {      /* the top-level values, checked for type */
    const cJSON *particles, *constraints, *colliders, *surfaces, *parts, *skins, *snapshot;
    const cJSON *world, *cgen, *clock[4], *vbd;
    int32_t np, ncons, ncol, nsurf, ntri, nparts, nskins, nc;
    int32_t nentries[JT_MAX];  /* "constraints" entries of each type (ncons: the slotted type's) */
    int slotted;               /* the type stored by slot (jtype.slots_key), -1 none */
    jslots slots;              /* its slot table */
} sections;

/* the snapshot section's shape (its values are read once the image exists) */
static int scan_snapshot(rd *r, sections *s)
{
    /* the clock, the slotted type's table, the colliders', the VBD solver's multipliers */
    const char *keys[] = { "world", "time", "frame", "warnings", "last_warning", NULL, "collider_slots", "vbd", NULL };
    static const char *const ckeys[] = { "generations", NULL };
    const cJSON *f[9] = { NULL }, *g[3];
    kp p = { NULL, "snapshot", 0 };
    const jtype *st = s->slotted >= 0 ? jtypes[s->slotted] : NULL;
    s->slots = (jslots){ NULL, NULL, 0, 0 };
    if (st) keys[5] = st->slots_key;
    else keys[5] = keys[6], keys[6] = keys[7], keys[7] = NULL;
    const int cf = st ? 6 : 5; /* the colliders' table */
    s->nc = s->ncol;
    if (s->snapshot) {
        if (jv_get_object(r, s->snapshot, &p, keys, f)) return -1;
        if (!f[0]) return jv_missing(r, s->snapshot, &p, "world");
        s->world = f[0];
        for (int i = 0; i < 4; i++) s->clock[i] = f[1 + i];
    }
    if (st && st->scan_slots(r, f[5], &p, s->ncons, &s->slots)) return -1;
    if (!s->snapshot) return 0;
    if (f[cf]) {
        kp q = { &p, "collider_slots", 0 };
        if (jv_get_object(r, f[cf], &q, ckeys, g)) return -1;
        if (!g[0]) return jv_missing(r, f[cf], &q, "generations");
        kp a = { &q, "generations", 0 };
        if (jv_get_array(r, g[0], &a, WB_MAX_COLLIDERS, &s->nc)) return -1;
        s->cgen = g[0];
    }
    s->vbd = f[cf + 1];
    return 0;
}

/* the VBD solver's multipliers (json_write.c): one a distance slot, one a bend; an error
 * not known is null */
static int read_vbd(rd *r, const sections *s, const kp *up, wb_image *g)
{
    static const char *const keys[] = { "multipliers", "errors", "bend_multipliers", "bend_errors", NULL };
    const cJSON *f[5];
    kp p = { up, "vbd", 0 };
    if (jv_get_object(r, s->vbd, &p, keys, f)) return -1;
    for (int k = 0; k < 4; k++)
        if (!f[k]) return jv_missing(r, s->vbd, &p, keys[k]);
    const int32_t nd = g->dist.n, want[4] = { nd, nd, g->bend.n, g->bend.n };
    if (wb_image_alloc_vbd(g, nd, g->bend.n) != WB_OK) return jv_fail(r, NULL, 0, NULL, "out of memory");
    wb_real *dst[4] = { g->vbd_lam, g->vbd_c0, g->vbd_blam, g->vbd_bc0 };
    for (int k = 0; k < 4; k++) {
        kp a = { &p, keys[k], 0 };
        int32_t n;
        if (jv_get_array(r, f[k], &a, WB_MAX_CONSTRAINTS, &n)) return -1;
        if (n != want[k]) return jv_fail(r, f[k], 0, &a, "%d numbers, but the world has %d %s", n, want[k], k < 2 ? "distance slots" : "bends");
        int32_t i = 0;
        for (const cJSON *c = f[k]->child; c; c = c->next, i++) {
            kp e = { &a, NULL, i };
            if (k % 2 && cJSON_IsNull(c)) dst[k][i] = (wb_real)NAN;
            else if (jv_get_real(r, c, &e, &dst[k][i])) return -1;
        }
    }
    return 0;
}

static int read_snapshot(rd *r, const sections *s, wb_image *g)
{
    kp p = { NULL, "snapshot", 0 };
    if (read_world(r, s->world, &p, &g->def)) return -1;
    int64_t i;
    if (jv_opt_nonneg(r, s->clock[0], &p, "time", &(wb_real){ 0 })) return -1;
    if (s->clock[0]) g->time = s->clock[0]->valuedouble; /* a double, whatever wb_real is */
    if (jv_opt_int(r, s->clock[1], &p, "frame", 0, (int64_t)1 << 53, &i)) return -1;
    if (s->clock[1]) g->frame = i;
    if (jv_opt_int(r, s->clock[2], &p, "warnings", 0, (int64_t)1 << 53, &i)) return -1;
    if (s->clock[2]) g->warnings = i;
    if (s->clock[3]) {
        kp q = { &p, "last_warning", 0 };
        const char *msg = "";
        if (jv_get_string(r, s->clock[3], &q, &msg)) return -1;
        snprintf(g->last_warning, sizeof g->last_warning, "%s", msg);
    }
    kp cs = { &p, "collider_slots", 0 };
    if (s->slotted >= 0 && jtypes[s->slotted]->read_slots(r, &s->slots, &p, s->ncons, g)) return -1;
    if (s->cgen) {
        kp a = { &cs, "generations", 0 };
        int32_t live;
        if (jv_read_generations(r, s->cgen, &a, g->c_gen, &live)) return -1;
        if (live != s->ncol) return jv_fail(r, s->cgen, 0, &a, "%d live slots, but \"colliders\" has %d entries", live, s->ncol);
    }
    return s->vbd ? read_vbd(r, s, &p, g) : 0;
}

static int read_particles(rd *r, const sections *s, const jdefaults *d, wb_image *g)
{
    static const char *const keys[] = { "position", "velocity", "mass", "inv_mass", "radius", "pinned",
                                        "group", "friction", "collide", "self_collide", "created_at", NULL };
    kp top = { NULL, "particles", 0 };
    int32_t i = 0;
    for (const cJSON *c = s->particles->child; c; c = c->next, i++) {
        const cJSON *f[12];
        kp p = { &top, NULL, i };
        wb_real mass = d->mass, radius = d->radius;
        bool pinned = false;
        if (jv_get_object(r, c, &p, keys, f)) return -1;
        if (!f[0]) return jv_missing(r, c, &p, "position");
        if (jv_opt_vec(r, f[0], &p, "position", 3, &g->x[3 * i]) || jv_opt_vec(r, f[1], &p, "velocity", 3, &g->v[3 * i]) ||
            jv_opt_nonneg(r, f[2], &p, "mass", &mass) || jv_opt_nonneg(r, f[4], &p, "radius", &radius))
            return -1;
        g->inv_mass[i] = mass > 0 ? 1 / mass : 0;
        /* as wb_particle_add: a mass whose inverse overflows is refused, and so is an
         * inverse whose mass overflows (w:mass, the energy and w:save would meet infinity) */
        kp mp = { &p, "mass", 0 }, ip = { &p, "inv_mass", 0 };
        if (!isfinite(g->inv_mass[i])) return jv_fail(r, f[2] ? f[2] : c, 0, &mp, "%g is too small (its inverse overflows)", (double)mass);
        /* inv_mass (w:save writes it) is exact where 1/mass might not round-trip */
        if (jv_opt_nonneg(r, f[3], &p, "inv_mass", &g->inv_mass[i])) return -1;
        if (g->inv_mass[i] > 0 && !isfinite(1 / g->inv_mass[i]))
            return jv_fail(r, f[3], 0, &ip, "%g is too small (its inverse, the mass, overflows)", (double)g->inv_mass[i]);
        if (f[5]) {
            kp q = { &p, "pinned", 0 };
            if (jv_get_bool(r, f[5], &q, &pinned)) return -1;
        }
        /* contacts: group 0 (the body's own when loaded into a world), collide, no friction,
         * created where it is (w:save writes all of them for the exact restore) */
        int64_t group = 0;
        bool collide = true, self = false;
        memcpy(&g->x0[3 * i], &g->x[3 * i], 3 * sizeof(wb_real));
        if (jv_opt_int(r, f[6], &p, "group", 0, WB_MAX_GROUP, &group) || jv_opt_nonneg(r, f[7], &p, "friction", &g->cfric[i]) ||
            jv_opt_vec(r, f[10], &p, "created_at", 3, &g->x0[3 * i]))
            return -1;
        if (f[8]) {
            kp q = { &p, "collide", 0 };
            if (jv_get_bool(r, f[8], &q, &collide)) return -1;
        }
        if (f[9]) {
            kp q = { &p, "self_collide", 0 };
            if (jv_get_bool(r, f[9], &q, &self)) return -1;
        }
        g->group[i] = (int32_t)group;
        g->cflags[i] = (uint8_t)((collide ? 1 : 0) | (self ? 2 : 0));
        g->radius[i] = radius;
        g->pinned[i] = pinned;
        if (g->inv_mass[i] == 0 || pinned) g->v[3 * i] = g->v[3 * i + 1] = g->v[3 * i + 2] = 0;
    }
    return 0;
}

/* the type a "constraints" entry is read as (jtypes): the one its "type" names; without a
 * string there, the first, whose reader says what is wrong. -1: a type none reads */
static int entry_type(const cJSON *c)
{
    const cJSON *t = cJSON_IsObject(c) ? cJSON_GetObjectItemCaseSensitive(c, "type") : NULL;
    int first = -1;
    for (int k = 0; k < njtypes; k++) {
        if (!jtypes[k]->entry) continue;
        if (cJSON_IsString(t) && !strcmp(t->valuestring, jtypes[k]->entry)) return k;
        if (first < 0) first = k;
    }
    return cJSON_IsString(t) ? -1 : first;
}

/* count the entries of each type (before the image is made), or name the one no type reads */
static int count_entries(rd *r, sections *s)
{
    int64_t i = 0;
    for (const cJSON *c = s->constraints ? s->constraints->child : NULL; c; c = c->next, i++) {
        const int k = entry_type(c);
        if (k >= 0) { s->nentries[k]++; continue; }
        char list[200] = "";
        size_t len = 0;
        int n = 0, m = 0;
        for (int j = 0; j < njtypes; j++) n += jtypes[j]->entry != NULL;
        for (int j = 0; j < njtypes && len < sizeof list; j++)
            if (jtypes[j]->entry)
                len += (size_t)snprintf(list + len, sizeof list - len, "%s%s", m++ == 0 ? "" : m == n ? " or " : ", ",
                                        jtypes[j]->entry);
        kp top = { NULL, "constraints", 0 }, p = { &top, NULL, i }, tp = { &p, "type", 0 };
        const cJSON *t = cJSON_GetObjectItemCaseSensitive(c, "type");
        return jv_fail(r, t, 0, &tp, "unknown constraint type '%s' (expected %s)", t->valuestring, list);
    }
    /* the entries without arrays of their own fill the slots of the type stored by slot */
    s->ncons = 0;
    s->slotted = -1;
    for (int k = 0; k < njtypes; k++) {
        if (jtypes[k]->entry && !jtypes[k]->alloc) s->ncons += s->nentries[k];
        if (jtypes[k]->slots_key) s->slotted = k;
    }
    return 0;
}

/* room in the image for the entries of the types with arrays of their own */
static wb_status alloc_entries(const sections *s, wb_image *g)
{
    for (int k = 0; k < njtypes; k++)
        if (jtypes[k]->alloc && s->nentries[k] > 0 && jtypes[k]->alloc(g, s->nentries[k]) != WB_OK) return WB_ERR_NOMEM;
    return WB_OK;
}

/* every entry of "constraints" by its type's reader */
static int read_constraints(rd *r, const sections *s, const jdefaults *d, wb_image *g)
{
    kp top = { NULL, "constraints", 0 };
    int32_t i = 0, at[JT_MAX];
    for (int k = 0; k < njtypes; k++) at[k] = -1;
    for (const cJSON *c = s->constraints ? s->constraints->child : NULL; c; c = c->next, i++) {
        kp p = { &top, NULL, i };
        const int k = entry_type(c); /* counted before: one of them */
        if (jtypes[k]->read_item(r, c, &p, d, g, &at[k])) return -1;
    }
    return 0;
}

/* a mesh collider's "vertices" (flat x,y,z, ...) and "triangles" (flat, 0-based corners) */
static int read_mesh_arrays(rd *r, const cJSON *it, const kp *p, const cJSON *fv, const cJSON *ft, wb_image_collider *c)
{
    if (!fv) return jv_missing(r, it, p, "vertices");
    if (!ft) return jv_missing(r, it, p, "triangles");
    kp vp = { p, "vertices", 0 }, tp = { p, "triangles", 0 };
    int32_t nv3, nt3;
    if (jv_get_array(r, fv, &vp, 3ll * WB_MAX_PARTICLES, &nv3) || jv_get_array(r, ft, &tp, 3ll * WB_MAX_CONSTRAINTS, &nt3))
        return -1;
    if (nv3 % 3) return jv_fail(r, fv, 0, &vp, "%d numbers is not a whole number of vertices", nv3);
    if (nt3 % 3) return jv_fail(r, ft, 0, &tp, "%d corners is not a whole number of triangles", nt3);
    if (nt3 == 0) return jv_fail(r, ft, 0, &tp, "a mesh collider needs at least one triangle");
    c->mv = malloc((size_t)(nv3 > 0 ? nv3 : 1) * sizeof *c->mv);
    c->mt = malloc((size_t)nt3 * sizeof *c->mt);
    if (!c->mv || !c->mt) return jv_fail(r, it, 0, p, "out of memory");
    c->mnv = nv3 / 3;
    c->mnt = nt3 / 3;
    int32_t k = 0;
    for (const cJSON *e = fv->child; e; e = e->next, k++) {
        kp q = { &vp, NULL, k };
        if (jv_get_real(r, e, &q, &c->mv[k])) return -1;
    }
    k = 0;
    for (const cJSON *e = ft->child; e; e = e->next, k++) {
        kp q = { &tp, NULL, k };
        int64_t v;
        if (c->mnv == 0) return jv_fail(r, e, 0, &q, "there are no vertices");
        if (jv_get_int(r, e, &q, 0, c->mnv - 1, &v)) return -1;
        c->mt[k] = (int32_t)v;
    }
    return 0;
}

/* a rotation as given, normalised only when it is not already unit (a snapshot's rotations
 * are, and must come back bit for bit) */
static int get_quat(rd *r, const cJSON *it, const kp *p, wb_real q[4])
{
    if (jv_get_vec(r, it, p, 4, q)) return -1;
    const wb_real n2 = q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3];
    if (!(n2 > 1e-24)) return jv_fail(r, it, 0, p, "rotation must not be zero");
    if (fabs(n2 - 1) > 1e-12)
        for (int i = 0; i < 4; i++) q[i] /= sqrt(n2);
    return 0;
}

static int read_pose(rd *r, const cJSON *it, const kp *up, wb_image_collider *c)
{
    static const char *const keys[] = { "position", "rotation", "start_position", "start_rotation", "velocity",
                                        "angular_velocity", NULL };
    const cJSON *f[7];
    kp p = { up, "pose", 0 };
    if (jv_get_object(r, it, &p, keys, f)) return -1;
    if (!f[0]) return jv_missing(r, it, &p, "position");
    if (!f[1]) return jv_missing(r, it, &p, "rotation");
    kp q1 = { &p, "rotation", 0 }, q2 = { &p, "start_rotation", 0 };
    if (jv_opt_vec(r, f[0], &p, "position", 3, c->p) || get_quat(r, f[1], &q1, c->q)) return -1;
    memcpy(c->p0, c->p, sizeof c->p0);
    memcpy(c->q0, c->q, sizeof c->q0);
    if (jv_opt_vec(r, f[2], &p, "start_position", 3, c->p0) || (f[3] && get_quat(r, f[3], &q2, c->q0)) ||
        jv_opt_vec(r, f[4], &p, "velocity", 3, c->v) || jv_opt_vec(r, f[5], &p, "angular_velocity", 3, c->om))
        return -1;
    return 0;
}

/* the shape "name" names (wobble.h's wb_shape_info), or -1 after failing with the names */
static int find_shape(rd *r, const cJSON *it, const kp *p, const char *name)
{
    int n = 0;
    while (wb_shape_info_of((wb_shape)n)) n++;
    for (int k = 0; k < n; k++)
        if (!strcmp(name, wb_shape_info_of((wb_shape)k)->name)) return k;
    char list[200] = "";
    size_t len = 0;
    for (int k = 0; k < n && len < sizeof list; k++)
        len += (size_t)snprintf(list + len, sizeof list - len, "%s%s", k == 0 ? "" : k == n - 1 ? " or " : ", ",
                                wb_shape_info_of((wb_shape)k)->name);
    jv_fail(r, it, 0, p, "unknown shape '%s' (expected %s)", name, list);
    return -1;
}

/* the keys of a shape's def in the world form: its fields (wb_shape_info), a mesh given by
 * its arrays ("vertices triangles") where a script gives a mesh object */
static const char *world_keys(const wb_shape_info *in, char buf[160])
{
    size_t n = 0;
    buf[0] = '\0';
    for (const char *q = in->fields; *q && n < 150;) {
        while (*q == ' ') q++;
        const char *e = q;
        while (*e && *e != ' ') e++;
        if (e == q) break;
        const int mesh = e - q == 4 && !strncmp(q, "mesh", 4);
        n += (size_t)snprintf(buf + n, 160 - n, "%s%.*s", n ? " " : "", mesh ? 18 : (int)(e - q),
                              mesh ? "vertices triangles" : q);
        q = e;
    }
    return buf;
}

/* Two forms: as w:collider{...} takes it (world frame), or, with "pose", the shape in the
 * collider's own frame plus its full pose (what w:save writes, exact). Which keys a shape
 * takes, what it keeps in its own frame and what must hold there are its file's
 * (core/shape_NAME.c, through wb_shape_info and wb_image_collider_shape_check) */
static int read_collider(rd *r, const cJSON *it, const kp *p, wb_image_collider *c)
{
    static const char *const keys[] = { "shape", "normal", "offset", "center", "radius", "half", "rotation", "a", "b",
                                        "friction", "restitution", "pose", "vertices", "triangles", "scale", NULL };
    const cJSON *f[16];
    if (jv_get_object(r, it, p, keys, f)) return -1;
    if (!f[0]) return jv_missing(r, it, p, "shape");
    kp sp = { p, "shape", 0 };
    const char *name = "";
    if (jv_get_string(r, f[0], &sp, &name)) return -1;
    const int shape = find_shape(r, f[0], &sp, name);
    if (shape < 0) return -1;
    const wb_shape_info *in = wb_shape_info_of((wb_shape)shape);
    const int local = f[11] != NULL, has_mesh = wb_shape_takes(in->fields, "mesh");
    char wbuf[160];
    const char *allowed = local ? in->own_fields : world_keys(in, wbuf);
    for (int i = 1; i <= 14; i++) {
        if (!f[i] || (i >= 9 && i <= 11) || wb_shape_takes(allowed, keys[i])) continue;
        kp kk = { p, keys[i], 0 };
        if (local) return jv_fail(r, f[i], 1, &kk, "a %s with a pose takes %s in its own frame, not '%s'", name, allowed, keys[i]);
        return jv_fail(r, f[i], 1, &kk, "a %s takes %s (and friction, restitution, pose), not '%s'", name, allowed, keys[i]);
    }
    wb_collider_def d = wb_collider_default_def((wb_shape)shape);
    if (jv_opt_vec(r, f[1], p, "normal", 3, d.normal) || jv_opt_real(r, f[2], p, "offset", &d.offset) ||
        jv_opt_vec(r, f[3], p, "center", 3, d.center) || jv_opt_real(r, f[4], p, "radius", &d.radius) ||
        jv_opt_vec(r, f[5], p, "half", 3, d.half) || jv_opt_vec(r, f[7], p, "a", 3, d.a) || jv_opt_vec(r, f[8], p, "b", 3, d.b) ||
        jv_opt_nonneg(r, f[9], p, "friction", &d.friction) || jv_opt_nonneg(r, f[10], p, "restitution", &d.restitution))
        return -1;
    if (f[6]) {
        kp q = { p, "rotation", 0 };
        if (get_quat(r, f[6], &q, d.rotation)) return -1;
    }
    if (has_mesh) {
        kp sc = { p, "scale", 0 };
        if (f[14] && jv_get_real(r, f[14], &sc, &d.scale)) return -1;
        if (read_mesh_arrays(r, it, p, f[12], f[13], c)) return -1;
    }
    if (!local && has_mesh) {
        /* the arrays just read are the mesh the def copies (scaled) into the collider */
        wb_mesh mesh = { c->mnv, c->mnt, c->mv, NULL, c->mt };
        d.mesh = &mesh;
        wb_image_collider tmp;
        wb_status st = wb_image_collider_from_def(&d, &tmp);
        if (st == WB_ERR_NOMEM) return jv_fail(r, it, 0, p, "out of memory");
        if (st != WB_OK) return jv_fail(r, it, 0, p, "%s", wb_last_error());
        free(c->mv);
        free(c->mt);
        *c = tmp;
        return 0;
    }
    if (!local) {
        wb_status st = wb_image_collider_from_def(&d, c);
        if (st == WB_ERR_NOMEM) return jv_fail(r, it, 0, p, "out of memory");
        return st != WB_OK ? jv_fail(r, it, 0, p, "%s", wb_last_error()) : 0;
    }
    /* own frame: the values are the collider's internals, as w:save wrote them: the
     * shape's own fields, the others zero */
    wb_real *mv = c->mv;
    int32_t *mt = c->mt, mnv = c->mnv, mnt = c->mnt;
    memset(c, 0, sizeof *c);
    c->mv = mv; /* a mesh's arrays, read above */
    c->mt = mt;
    c->mnv = mnv;
    c->mnt = mnt;
    c->shape = (wb_shape)shape;
    c->friction = d.friction;
    c->restitution = d.restitution;
    if (wb_shape_takes(in->own_fields, "normal")) {
        wb_real n2 = d.normal[0] * d.normal[0] + d.normal[1] * d.normal[1] + d.normal[2] * d.normal[2];
        if (!(n2 > 1e-24)) return jv_fail(r, f[1] ? f[1] : it, 0, p, "normal must not be zero");
        for (int i = 0; i < 3; i++) c->n[i] = fabs(n2 - 1) > 1e-12 ? d.normal[i] / sqrt(n2) : d.normal[i];
    }
    if (wb_shape_takes(in->own_fields, "half")) memcpy(c->half, d.half, sizeof c->half);
    if (wb_shape_takes(in->own_fields, "a")) memcpy(c->a, d.a, sizeof c->a);
    if (wb_shape_takes(in->own_fields, "b")) memcpy(c->b, d.b, sizeof c->b);
    if (wb_shape_takes(in->own_fields, "radius")) c->radius = d.radius;
    if (read_pose(r, f[11], p, c)) return -1;
    const char *e = wb_image_collider_shape_check(c);
    if (e) return jv_fail(r, it, 0, p, "%s", e);
    if (c->restitution > 1) return jv_fail(r, f[10], 0, p, "restitution must be in [0, 1]");
    return 0;
}

static int read_colliders(rd *r, const sections *s, wb_image *g)
{
    kp top = { NULL, "colliders", 0 };
    int32_t i = 0, slot = -1;
    if (!s->colliders) return 0;
    for (const cJSON *c = s->colliders->child; c; c = c->next, i++) {
        kp p = { &top, NULL, i };
        do slot++; while (!(g->c_gen[slot] & 1u));
        if (read_collider(r, c, &p, &g->c[slot])) return -1;
    }
    return 0;
}

/* "surfaces": [ {"triangles": [a,b,c, ...]}, ... ]: first pass counts, second fills */
static int read_surfaces(rd *r, const sections *s, wb_image *g, int32_t *ntri)
{
    static const char *const keys[] = { "triangles", NULL };
    kp top = { NULL, "surfaces", 0 };
    int32_t i = 0, t = 0;
    if (!s->surfaces) { *ntri = 0; return 0; }
    for (const cJSON *c = s->surfaces->child; c; c = c->next, i++) {
        const cJSON *f[2];
        kp p = { &top, NULL, i }, tp = { &p, "triangles", 0 };
        int32_t n;
        if (jv_get_object(r, c, &p, keys, f)) return -1;
        if (!f[0]) return jv_missing(r, c, &p, "triangles");
        if (jv_get_array(r, f[0], &tp, 3ll * WB_MAX_CONSTRAINTS, &n)) return -1;
        if (n % 3) return jv_fail(r, f[0], 0, &tp, "%d corners is not a whole number of triangles", n);
        if (g) {
            g->surf_start[i] = t;
            int32_t k = 0;
            for (const cJSON *e = f[0]->child; e; e = e->next, k++) {
                kp q = { &tp, NULL, k };
                int64_t v;
                if (g->np == 0) return jv_fail(r, e, 0, &q, "there are no particles");
                if (jv_get_int(r, e, &q, 0, g->np - 1, &v)) return -1;
                g->tri[3 * (int64_t)t + k] = (int32_t)v;
            }
        }
        if ((int64_t)t + n / 3 > WB_MAX_CONSTRAINTS) return jv_fail(r, f[0], 0, &tp, "too many triangles");
        t += n / 3;
    }
    if (g) g->surf_start[i] = t;
    *ntri = t;
    return 0;
}

static int read_parts(rd *r, const sections *s, wbio_config *cfg)
{
    static const char *const keys[] = { "name", "first", "count", NULL };
    kp top = { NULL, "parts", 0 };
    int32_t i = 0;
    for (const cJSON *c = s->parts ? s->parts->child : NULL; c; c = c->next, i++) {
        const cJSON *f[4];
        kp p = { &top, NULL, i }, np = { &p, "name", 0 };
        const char *name = "";
        int64_t first, count;
        if (jv_get_object(r, c, &p, keys, f)) return -1;
        if (!f[0]) return jv_missing(r, c, &p, "name");
        if (!f[1]) return jv_missing(r, c, &p, "first");
        if (!f[2]) return jv_missing(r, c, &p, "count");
        if (jv_get_string(r, f[0], &np, &name) || jv_opt_int(r, f[1], &p, "first", 0, s->np, &first) ||
            jv_opt_int(r, f[2], &p, "count", 0, s->np - first, &count))
            return -1;
        for (int32_t j = 0; j < i; j++)
            if (!strcmp(cfg->parts[j].name, name)) return jv_fail(r, f[0], 0, &np, "a part named '%s' already exists", name);
        cfg->parts[i].name = strdup(name);
        if (!cfg->parts[i].name) return jv_fail(r, c, 0, &p, "out of memory");
        cfg->parts[i].first = (int32_t)first;
        cfg->parts[i].count = (int32_t)count;
        cfg->nparts = i + 1;
    }
    return 0;
}

static int read_skins(rd *r, const sections *s, wbio_config *cfg)
{
    static const char *const keys[] = { "mesh", "scale", "bones", "neighbours", "particles", NULL };
    kp top = { NULL, "skins", 0 };
    int32_t i = 0;
    for (const cJSON *c = s->skins ? s->skins->child : NULL; c; c = c->next, i++) {
        const cJSON *f[6];
        kp p = { &top, NULL, i }, mp = { &p, "mesh", 0 };
        wbio_skin_spec *k = &cfg->skins[i];
        const char *mesh = "";
        int64_t v;
        cfg->nskins = i + 1;
        k->scale = 1;
        k->def = wb_skin_default_def();
        if (jv_get_object(r, c, &p, keys, f)) return -1;
        if (!f[0]) return jv_missing(r, c, &p, "mesh");
        if (jv_get_string(r, f[0], &mp, &mesh) || jv_opt_real(r, f[1], &p, "scale", &k->scale)) return -1;
        if (!(k->scale > 0)) return jv_fail(r, f[1], 0, &p, "scale must be > 0");
        if (f[2]) { if (jv_opt_int(r, f[2], &p, "bones", 1, 16, &v)) return -1; k->def.bones = (int)v; }
        if (f[3]) { if (jv_opt_int(r, f[3], &p, "neighbours", 2, 32, &v)) return -1; k->def.neighbours = (int)v; }
        k->mesh = strdup(mesh);
        if (!k->mesh) return jv_fail(r, c, 0, &p, "out of memory");
        jv_where_of(r, f[0], 0, &mp, k->where, sizeof k->where); /* for messages about loading it */
        if (f[4]) {
            kp pp = { &p, "particles", 0 };
            if (jv_get_array(r, f[4], &pp, s->np, &k->nids)) return -1;
            if (k->nids == 0) return jv_fail(r, f[4], 0, &pp, "a skin needs at least one particle");
            k->ids = malloc(sizeof *k->ids * (size_t)k->nids);
            if (!k->ids) return jv_fail(r, c, 0, &p, "out of memory");
            int32_t j = 0;
            for (const cJSON *e = f[4]->child; e; e = e->next, j++) {
                kp q = { &pp, NULL, j };
                if (jv_get_int(r, e, &q, 0, s->np - 1, &v)) return -1;
                k->ids[j] = (int32_t)v;
            }
        } else if (s->np == 0) {
            return jv_fail(r, c, 0, &p, "a skin needs at least one particle");
        }
    }
    return 0;
}

/* ---- the file ---------------------------------------------------------------------------------- */
/* a type's array of its own (arr may be NULL: none) */
static int read_section(rd *r, const jtype *t, const cJSON *arr, const jdefaults *d, wb_image *g)
{
    if (t->read) return t->read(r, arr, g);
    kp top = { NULL, t->key, 0 };
    int32_t n, i = 0, at = -1;
    if (!arr) return 0;
    if (jv_get_array(r, arr, &top, WB_MAX_CONSTRAINTS, &n)) return -1;
    if (t->alloc(g, n) != WB_OK) return jv_fail(r, arr, 0, &top, "out of memory");
    for (const cJSON *c = arr->child; c; c = c->next, i++) {
        kp p = { &top, NULL, i };
        if (t->read_item(r, c, &p, d, g, &at)) return -1;
    }
    return 0;
}

/* each type's array of its own (jtypes), after the rigid bodies that attachments and grabs name */
static int read_sections(rd *r, const cJSON *root, const jdefaults *d, wb_image *g)
{
    for (int i = 0; i < njtypes; i++)
        if (jtypes[i]->key && read_section(r, jtypes[i], cJSON_GetObjectItemCaseSensitive(root, jtypes[i]->key), d, g))
            return -1;
    return 0;
}

/* the root's keys: the file's own, then the types' sections (jtypes) */
static void root_keys(const char *keys[])
{
    static const char *const own[] = { "format", "version", "description", "defaults", "particles", "constraints",
                                       "colliders", "surfaces", "parts", "skins", "snapshot", "rigids", NULL };
    int n = 0;
    for (; own[n]; n++) keys[n] = own[n];
    for (int k = 0; k < njtypes; k++)
        if (jtypes[k]->key) keys[n++] = jtypes[k]->key;
    keys[n] = NULL;
}

static int read_root(rd *r, const cJSON *root, wbio_config *cfg)
{
    const char *keys[13 + JT_MAX];
    const cJSON *f[13 + JT_MAX];
    sections s;
    jdefaults d;
    memset(&s, 0, sizeof s);
    root_keys(keys);
    if (!cJSON_IsObject(root)) return jv_fail(r, root, 0, NULL, "a particle config is a JSON object, got %s", jv_type_name(root));
    if (jv_get_object(r, root, NULL, keys, f)) return -1;
    kp fp = { NULL, "format", 0 }, vp = { NULL, "version", 0 };
    const char *str = "";
    int64_t version;
    if (!f[0]) return jv_fail(r, root, 0, NULL, "missing key 'format' (a particle config starts with "
                                              "\"format\": \"" WBIO_FORMAT "\", \"version\": 1)");
    if (jv_get_string(r, f[0], &fp, &str)) return -1;
    if (strcmp(str, WBIO_FORMAT)) return jv_fail(r, f[0], 0, &fp, "'%s' is not a particle config (expected '" WBIO_FORMAT "')", str);
    if (!f[1]) return jv_missing(r, root, NULL, "version");
    if (jv_get_int(r, f[1], &vp, INT32_MIN, INT32_MAX, &version)) return -1;
    if (version != WBIO_VERSION)
        return jv_fail(r, f[1], 0, &vp, "version %lld is not supported (this wobble reads version %d)", (long long)version, WBIO_VERSION);
    if (f[2]) {
        kp dp = { NULL, "description", 0 };
        if (jv_get_string(r, f[2], &dp, &str)) return -1;
    }
    if (read_defaults(r, f[3], &d)) return -1;
    if (!f[4]) return jv_missing(r, root, NULL, "particles");
    struct { const cJSON **dst; int32_t *n; int64_t max; int k; } arrays[] = {
        { &s.particles, &s.np, WB_MAX_PARTICLES, 4 }, { &s.constraints, &s.ncons, WB_MAX_CONSTRAINTS, 5 },
        { &s.colliders, &s.ncol, WB_MAX_COLLIDERS, 6 }, { &s.surfaces, &s.nsurf, WB_MAX_CONSTRAINTS, 7 },
        { &s.parts, &s.nparts, 1 << 20, 8 }, { &s.skins, &s.nskins, 1 << 10, 9 },
    };
    for (size_t i = 0; i < sizeof arrays / sizeof arrays[0]; i++) {
        const cJSON *it = f[arrays[i].k];
        kp ap = { NULL, keys[arrays[i].k], 0 };
        *arrays[i].dst = it;
        if (it && jv_get_array(r, it, &ap, arrays[i].max, arrays[i].n)) return -1;
    }
    /* a type none reads is named here, before a slot count that would miss it blames the
     * slot tables instead */
    if (count_entries(r, &s)) return -1;
    s.snapshot = f[10];
    if (scan_snapshot(r, &s) || read_surfaces(r, &s, NULL, &s.ntri)) return -1;
    if (wb_image_alloc(&cfg->img, s.np, s.slots.n, s.slots.nfree, s.nc, s.nsurf, s.ntri) != WB_OK ||
        alloc_entries(&s, &cfg->img) != WB_OK ||
        !(cfg->parts = calloc((size_t)s.nparts + 1, sizeof *cfg->parts)) ||
        !(cfg->skins = calloc((size_t)s.nskins + 1, sizeof *cfg->skins)))
        return jv_fail(r, NULL, 0, NULL, "out of memory");
    cfg->snapshot = s.snapshot != NULL;
    /* the snapshot first: its slot tables say where the constraints and colliders go */
    if ((s.snapshot && read_snapshot(r, &s, &cfg->img)) || read_particles(r, &s, &d, &cfg->img) ||
        read_constraints(r, &s, &d, &cfg->img) || read_colliders(r, &s, &cfg->img) ||
        read_surfaces(r, &s, &cfg->img, &s.ntri) || read_parts(r, &s, cfg) || read_skins(r, &s, cfg) ||
        jr_read_rigids(r, f[11], &cfg->img) || read_sections(r, root, &d, &cfg->img))
        return -1;
    /* every value was checked where it was read: this is the last line of defence */
    const char *e = wb_image_check(&cfg->img);
    return e ? jv_fail(r, root, 0, NULL, "%s", e) : 0;
}

/* the image read from a tree is at most a third of it: a number is an 80-byte node of
 * the tree and at most 8 bytes of an array, an entry (a particle, a link) has a node of
 * its own and adds at most 30 bytes of flags and generations. Charged before the arrays
 * are made, kept with the config; 0 when it does not fit */
static int reserve_image(wbio_config *cfg)
{
    if (!jv_budget || !jv_budget->mem) return 1;
    wb_memory *m = jv_budget->mem;
    const size_t r = jv_budget->held / 3;
    if (m->limit && (r > m->limit || m->used > m->limit - r)) {
        jv_budget->over = true;
        return 0;
    }
    m->used += r;
    cfg->mem = m;
    cfg->charged = r;
    return 1;
}

static char *read_text(const char *path, const char *shown, size_t *len, char *err, size_t errn)
{
    FILE *fp = fopen(path, "rb");
    struct stat st;
    if (!fp) { snprintf(err, errn, "%s: %s", shown, strerror(errno)); return NULL; }
    if (fstat(fileno(fp), &st) == 0 && S_ISDIR(st.st_mode)) {
        snprintf(err, errn, "%s: is a folder, not a file", shown);
        fclose(fp);
        return NULL;
    }
    size_t cap = 1 << 16, n = 0;
    char *t = jb_realloc(NULL, cap);
    while (t) {
        if (n + 1 >= cap) {
            char *u = cap < (size_t)MAX_FILE ? jb_realloc(t, cap * 2) : NULL;
            if (!u) break;
            t = u;
            cap *= 2;
        }
        size_t got = fread(t + n, 1, cap - n - 1, fp);
        n += got;
        if (got == 0) {
            if (ferror(fp)) { snprintf(err, errn, "%s: %s", shown, strerror(errno)); jb_free(t); fclose(fp); return NULL; }
            t[n] = '\0';
            fclose(fp);
            *len = n;
            return t;
        }
    }
    snprintf(err, errn, "%s: %s", shown, t ? "too large (2 GiB at most)" : "out of memory");
    jb_free(t);
    fclose(fp);
    return NULL;
}

/* how many arrays and objects are open at `end` (strings skipped): cJSON stops at the
 * bracket that goes past CJSON_NESTING_LIMIT, which is no syntax error of the file's */
static int json_depth(const char *text, const char *end)
{
    int depth = 0, in_string = 0;
    for (const char *p = text; p < end; p++) {
        if (in_string) {
            if (*p == '\\' && p + 1 < end) p++;
            else if (*p == '"') in_string = 0;
        } else if (*p == '"') in_string = 1;
        else if (*p == '[' || *p == '{') depth++;
        else if (*p == ']' || *p == '}') depth--;
    }
    return depth;
}

/* cJSON with its nodes charged to the read's budget (its hooks are global: set for the
 * call alone, and the tree is deleted under the same ones) */
static cJSON *parse_tree(const char *text, const char **end)
{
    cJSON_Hooks h = { jb_malloc, jb_free };
    cJSON_InitHooks(&h);
    cJSON *root = cJSON_ParseWithOpts(text, end, 1);
    cJSON_InitHooks(NULL);
    return root;
}

static void delete_tree(cJSON *root)
{
    cJSON_Hooks h = { jb_malloc, jb_free };
    cJSON_InitHooks(&h);
    cJSON_Delete(root);
    cJSON_InitHooks(NULL);
}

/* the parse of a whole text (text[len] is a NUL the reader put there); frees text */
static int parse_text(char *text, size_t len, const char *shown, wbio_config *cfg, char *err, size_t errn)
{
    scan s = { text, text, 0, 0, NULL, NULL, 0 };
    rd r = { shown, text, NULL, err, errn };
    int rc = -1, line, col;
    cJSON *root = NULL;
    const char *nul = memchr(text, '\0', len), *end = NULL, *p = text;
    while (*p && (unsigned char)*p <= 32) p++;
    if (nul) {
        jv_line_col(text, (int32_t)(nul - text), &line, &col);
        snprintf(err, errn, "%s:%d:%d: not a text file (a NUL byte)", shown, line, col);
    } else if (!*p) {
        snprintf(err, errn, "%s: empty file (a particle config is a JSON object)", shown);
    } else if (!(root = parse_tree(text, &end))) {
        /* cJSON's error pointer, turned into a line and column */
        const int32_t off = end ? (int32_t)(end - text) : 0;
        char near[24] = "";
        for (int i = 0; i < 20 && end && end[i] && end[i] != '\n'; i++) near[i] = isprint((unsigned char)end[i]) ? end[i] : '?';
        jv_line_col(text, off, &line, &col);
        if (end && *end && json_depth(text, end) >= CJSON_NESTING_LIMIT)
            snprintf(err, errn, "%s:%d:%d: JSON nested too deeply (more than %d levels of arrays and objects)", shown,
                     line, col, CJSON_NESTING_LIMIT);
        else if (end && *end) snprintf(err, errn, "%s:%d:%d: JSON syntax error near '%s'", shown, line, col, near);
        else snprintf(err, errn, "%s:%d:%d: JSON syntax error: unexpected end of file", shown, line, col);
    } else {
        if (!strncmp(s.p, "\xEF\xBB\xBF", 3)) s.p += 3; /* cJSON skips a UTF-8 byte-order mark too */
        jv_sk_value(&s, -1);
        int32_t k = 0;
        jv_number_items(root, &k);
        r.pos = !s.oom && k == s.n ? &s : NULL; /* without positions, messages still name the key */
        rc = reserve_image(cfg) ? read_root(&r, root, cfg) : -1;
    }
    delete_tree(root);
    jb_free(s.voff);
    jb_free(s.koff);
    jb_free(text);
    if (rc) wbio_config_free(cfg);
    return rc;
}

int wbio_read_config(const char *path, const char *shown, wbio_config *cfg, char *err, size_t errn)
{
    memset(cfg, 0, sizeof *cfg);
    size_t len = 0;
    char *text = read_text(path, shown, &len, err, errn);
    return text ? parse_text(text, len, shown, cfg, err, errn) : -1;
}

int wbio_read_config_within(const char *path, const char *shown, wbio_config *cfg, wb_memory *mem, bool *over,
                            char *err, size_t errn)
{
    jbudget b = { mem, 0, false };
    jbudget *outer = jv_budget;
    const size_t left = mem && mem->used < mem->limit ? mem->limit - mem->used : 0;
    jv_budget = &b;
    int rc = wbio_read_config(path, shown, cfg, err, errn);
    jv_budget = outer;
    *over = b.over;
    if (rc && b.over)   /* cJSON says "syntax error" where its allocation was refused */
        snprintf(err, errn, "%s: reading it needs more than the %.0f MB left of the memory budget of %.0f MB", shown,
                 left / 1048576.0, mem->limit / 1048576.0);
    return rc;
}

int wbio_parse_config(const char *data, size_t len, const char *shown, wbio_config *cfg, char *err, size_t errn)
{
    memset(cfg, 0, sizeof *cfg);
    /* a copy ending in the NUL that cJSON's parser and the position scanner stop at */
    char *text = len < (size_t)MAX_FILE ? malloc(len + 1) : NULL;
    if (!text) {
        snprintf(err, errn, "%s: %s", shown, len < (size_t)MAX_FILE ? "out of memory" : "too large (2 GiB at most)");
        return -1;
    }
    memcpy(text, data, len);
    text[len] = '\0';
    return parse_text(text, len, shown, cfg, err, errn);
}

void wbio_config_free(wbio_config *cfg)
{
    if (cfg->mem) cfg->mem->used -= cfg->charged;
    wb_image_free(&cfg->img);
    for (int32_t i = 0; cfg->parts && i < cfg->nparts; i++) free(cfg->parts[i].name);
    for (int32_t i = 0; cfg->skins && i < cfg->nskins; i++) {
        free(cfg->skins[i].mesh);
        free(cfg->skins[i].ids);
    }
    free(cfg->parts);
    free(cfg->skins);
    memset(cfg, 0, sizeof *cfg);
}
