/* core.h: the world's internals, shared by the core files only.
 *
 * Model / state split (MuJoCo's mjModel / mjData): the model holds what a step does
 * not change (masses, topology, collider shapes); the state holds what it does
 * (positions, velocities, collider poses, time); the solver cache is scratch rebuilt
 * from both. These are the particles', colliders' and step's; each constraint type keeps
 * its own model, state and cache (rest lengths, broken flags, colour batches,
 * multipliers) in a struct of its own header, which the world points to. */
#ifndef WB_CORE_H
#define WB_CORE_H

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "wobble.h"
#include "vec.h"
#include "shape.h"
#include "pool.h"

/* a substep's prediction, per particle: damping, gravity, x += h v (x_prev = x first; a
 * particle with w = 0 stays). solver.c's pass and collide.c's fused one share it, so
 * that fused or not the operations and the bits are the same */
typedef struct wb_predict {
    wb_real keep, g[3], h; /* velocity kept against damping; gravity x h; the substep */
} wb_predict;
static inline void wb__predict_one(const wb_predict *p, wb_real w, wb_real *restrict x, wb_real *restrict xp,
                                   wb_real *restrict v)
{
    v3_copy(xp, x);
    if (w == 0) return;
    /* drag on the velocity only: a body at rest still weighs m g */
    v[0] = v[0] * p->keep + p->g[0]; v[1] = v[1] * p->keep + p->g[1]; v[2] = v[2] * p->keep + p->g[2];
    x[0] += p->h * v[0]; x[1] += p->h * v[1]; x[2] += p->h * v[2];
}

/* ---- model ----------------------------------------------------------------------- */
typedef struct wb_model {
    wb_world_def def;

    int32_t np, cap_p;
    wb_real *inv_mass;     /* (np) as created; 0 = immovable */
    wb_real *w;            /* (np) what the solver uses: 0 while pinned */
    wb_real *radius;       /* (np) */
    uint8_t *pinned;       /* (np) */
    /* contacts (contact.c) */
    int32_t *group;        /* (np) body: 0 = loose (collides with every particle) */
    uint8_t *cflags;       /* (np) WB_CF_* */
    wb_real *cfric;        /* (np) contact friction (Coulomb, static = dynamic) */
    wb_real *x0;           /* (np x 3) where it was created: rest neighbours never collide */

    /* colliders by slot */
    int32_t nc, cap_c;
    wb_cshape *c_shape; /* (nc) */
    uint32_t *c_gen;       /* (nc) odd = live */

    int topology_dirty;    /* particles or links added, removed or broken: the links' batches
                              and what is built over the links must be rebuilt */
    uint32_t w_gen;        /* bumped when w changes without a topology change (pin, unpin) */
    size_t charged;        /* bytes of the per-particle arrays charged to def.memory */
    size_t charged_mesh;   /* bytes of mesh colliders' copies, charged to def.memory too */

    /* surfaces: triangles over particles, concatenated */
    int32_t nsurf, cap_surf;
    int32_t *surf_start;   /* (nsurf + 1) triangle ranges */
    int32_t ntri, cap_tri; /* cap_tri counts ints */
    int32_t *tri;          /* (ntri x 3) particle ids */
} wb_model;

/* ---- state ----------------------------------------------------------------------- */
typedef struct wb_collider_pose {
    wb_real p[3], q[4];    /* pose now (set by the script, reached at the end of the next step) */
    wb_real p0[3], q0[4];  /* pose at the end of the last step: start of the next sweep */
    wb_real v[3], om[3];   /* velocities the script set */
} wb_collider_pose;

typedef struct wb_state {
    wb_real *x, *x_prev, *v; /* (np x 3) */
    wb_collider_pose *c_pose; /* (nc) */
    double time;
    int64_t frame;
    int64_t warnings;
    char last_warning[160];
} wb_state;

#define WB_CF_COLLIDE 1u     /* collides with other bodies and loose particles */
#define WB_CF_SELF 2u        /* collides with its own body (group > 0) */


/* ---- solver cache: per-step scratch ------------------------------------------------ */
typedef struct wb_cache {
    /* per particle, grown with the particles: the distances' scratch (distance.c) */
    wb_real *dx;           /* (np x 3) Jacobi and compound accumulators */
    int32_t *ncount;       /* (np) links at each particle (for the Jacobi scale) */
    wb_real *x_save, *v_save; /* (np x 3) last finite frame, for recovery */
    void *c_sub;           /* (nc) collider poses at the substep's start and end, then (nc)
                              static planes (collide.c); cap_c_sub in bytes */
    int32_t cap_c_sub;
    wb_real *c_left;       /* (np) overlap with the colliders each particle kept (collide.c) */
    int32_t cap_c_left;
    wb_real *c_save;       /* (nc x 7) collider poses at the frame's start, for undo */
    int32_t cap_c_save;
    wb_real h_last;        /* substep length of the last step (force readback) */
    const uint8_t *vbd_fold; /* (np) during a VBD solve, for the types' begin: 1 for a movable
                                particle in touch with a movable particle of its own body (not
                                a rest neighbour) where the substep starts; NULL when none is
                                (vbd.c's touching()) */
    int residual_on;       /* the residual was asked for: each step measures it (query.c) */
    wb_real residual;      /* ... after the last substep's iterations (-1: not yet) */
    int (*interrupt)(void *);
    void *interrupt_ud;
    int32_t last_contacts;
    /* the contacts' scratch, made by their files at the first step (NULL before it; a file
     * that reads them outside a step checks): particle pairs (contact.h, contact.c) and
     * particle-triangle pairs (tricontact.h, tribroad.c and tricontact.c) */
    struct wb_contacts *pc;
    struct wb_tricontacts *tc;
    int64_t projections;
    int64_t iters_run;     /* iterations the last step's substeps ran, summed (tolerance stops some) */
    double step_ms, solve_ms;
    int no_fuse;           /* tests: the plain order, the next substep's prediction never
                              fused into the collision pass (solver.c), nor the static-plane
                              fast path taken (collide.c); the results must not change */
    int no_simd;           /* tests: the one-plane pass (collide.c) without its AVX2 groups
                              of four; the results must not change */
    int64_t fused;         /* substeps predicted in the collision pass so far (tests) */
    int32_t nonfinite;     /* the last substep's pass scanned x and v (solver.c): the first
                              non-finite particle, -1 none; -2 when it did not scan */
    /* the bodies whose angular momentum the solve keeps (momentum.c) */
    int32_t *mc_body;      /* (np) body of each particle, -1 none */
    int32_t *mc_root;      /* (bodies) first particle of each */
    double *mc_acc;        /* (bodies x 16) sums; [0] < 0: held from outside the solve */
    uint8_t *mc_pinned;    /* (bodies) has an immovable particle, as of m.w_gen mc_wgen */
    int32_t *mc_end;       /* (bodies) one past its last particle when its particles are
                              consecutive (a builder's body), else -1 */
    int32_t cap_mc_body, cap_mc_root, cap_mc_acc, cap_mc_pinned, cap_mc_end, mc_nbody, mc_free;
    int32_t mc_scattered;  /* bodies whose particles are not consecutive (end -1) */
    int mc_built, mc_changed;
    uint32_t mc_wgen;
    int64_t mc_sig[8];     /* what the bodies were found for (besides m.topology_dirty) */
    /* the blow-up check at a frame's end (solver.c) */
    int32_t bl_np;         /* x_save holds the last frame's end (or its start: an undone frame)
                              for this many particles */
    wb_real bl_v0;         /* the fastest particle's squared speed at the frame's start */
    wb_real bl_pin;        /* the farthest the script moved a pinned particle, squared, and */
    int bl_moved;          /* whether it moved a movable one, since the last frame's check */
    wb_real bl_user;       /* the fastest speed given from outside (scripts, new particles) */
    wb_real bl_vend;       /* the fastest particle at the last frame's end */
    int bl_have;           /* bl_vend is known (a step ended since the world was made or loaded) */
    int bl_warned;         /* the blow-up was reported (once per world) */
    int32_t bl_hot;        /* consecutive frames with a particle past the lower limit */
    int bl_armed;          /* a blow-up was found: the lower limit holds from then on */
    double bl_given;       /* time the script last gave the world energy (made constraints,
                              moved particles, changed settings) */
    uint32_t bl_wgen;      /* m.w_gen then */
    wb_world_def bl_def;   /* the settings then */
} wb_cache;

struct wb_world {
    wb_model m;
    wb_state s;
    wb_cache k;
    /* each constraint type: its struct (model, state and cache) declared in its own
     * header, made by its file with the first constraint, freed by its destroy hook
     * (ctype.h); NULL until the first */
    struct wb_distances *dist; /* distance constraints (distance.h) */
    struct wb_bends *bend;  /* bends (bend.h) */
    struct wb_volumes *vol; /* volume constraints (volume.h) */
    struct wb_neos *neo;    /* Neo-Hookean tets (tet.h) */
    struct wb_smatch *sm;   /* shape-matching clusters (shape_match.h) */
    struct wb_pressures *pr; /* pressure constraints (pressure.h) */
    struct wb_attaches *att; /* attachments (attach.h) */
    struct wb_grabs *grab;  /* grabs (grab.h) */
    struct wb_tethers *teth; /* tethers (tether.h) */
    struct wb_rigids *rb;  /* rigid bodies (rigid.h), NULL until the first */
    struct wb_vbd *vbd;    /* the VBD solver's cache (vbd.c), NULL until a step with it */
    wb_pool *pool;         /* the threads (pool.h), NULL until a step runs with threads > 1 */
    size_t charged_self;   /* the struct and its worker threads, charged to def.memory (world.c) */
};

/* The vector paths' switches (distance.c, bend.c, tet.c, momentum.c: wb__*_simd): *state
 * (-1 until decided) set to on where the build and the CPU have AVX2; returns it. The
 * vector paths give the scalar loops' bits, so this only picks the faster. */
#if defined(__x86_64__) && defined(__GNUC__) && !defined(WB_FLOAT)
#define WB_HAVE_AVX2 1
#endif
static inline int wb__simd_set(int *state, int on)
{
#ifdef WB_HAVE_AVX2
    __builtin_cpu_init();
    const int v = on && __builtin_cpu_supports("avx2");
#else
    const int v = 0;
    (void)on;
#endif
    __atomic_store_n(state, v, __ATOMIC_RELAXED);
    return v;
}

/* internal entry points */
/* momentum.c: once per step before the types' prepare (0: out of memory, nothing kept this
 * step); after each substep's solve, every free body's angular momentum back as it was */
int wb__momentum_prepare(wb_world *w);
void wb__momentum_restore(wb_world *w, wb_real h);
/* momentum.c: om = I^-1 L, I the inertia tensor of a set of points whose second moments
 * about their mass centre are S (xx yy zz xy xz yz): the turn that carries angular
 * momentum L; 0 when singular or not finite (broadphase.c's reference motion too) */
void wb__turn_rate(const double S[6], const double L[3], double om[3]);
/* collide.c: collisions, then v = (x - x_prev)/h, friction and restitution; then, per
 * particle in the same pass, the next substep's prediction when next != NULL, or (scan)
 * the finiteness check of x and v into k.nonfinite. 0 when out of memory (nothing done) */
int wb__collide_and_update(wb_world *w, wb_real h, wb_real f0, wb_real f1, const wb_predict *next, int scan);
void wb__collider_pose_at(const wb_collider_pose *cp, wb_real t, wb_real p[3], wb_real q[4]);
/* collide.c: a mesh collider's copy charged to / given back to the memory budget (and freed) */
int wb__mesh_charge(wb_world *w, const struct wb_colmesh *cm);
void wb__mesh_release(wb_world *w, wb_cshape *s);
/* contact.c, tribroad.c: the contacts' scratch (k.pc, k.tc) made when there is none
 * (each step, first: 0 when out of memory), and freed with the world */
int wb__contacts_make(wb_world *w);
int wb__tricontacts_make(wb_world *w);
void wb__contacts_destroy(wb_world *w);
void wb__tricontacts_destroy(wb_world *w);
/* contact.c: the contacts' counts in w:stats() (nothing before the first step) */
void wb__contacts_stats(const wb_world *w, wb_stats *st);
/* contact.c: broad phase once per frame, projection per substep, velocity pass after
 * the velocities are updated */
void wb__contacts_begin(wb_world *w);
/* a builder's particles first..first+count as a body: a new contact group of its own,
 * colliding with others, not with itself, no contact friction (the binding sets those) */
wb_status wb__body_finish(wb_world *w, int32_t first, int32_t count, wb_body *out);
void wb__contacts_project(wb_world *w, wb_real h);
void wb__contacts_velocity(wb_world *w, wb_real h);
/* contact.c: static friction of the substep's pair and triangle contacts, after both
 * projections (per particle: its contacts' normal corrections bound what it may stick
 * with); tricontact.c: the triangle contacts' part of it */
void wb__contacts_friction(wb_world *w, wb_real h);
/* after it, the pairs in touch swept again (contact.c) */
void wb__contacts_settle(wb_world *w, wb_real h);
void wb__tricontacts_load(wb_world *w, wb_real h, wb_real *load);
void wb__tricontacts_static(wb_world *w, wb_real *load);
/* world.c: room for extra more particles (after it, adding them cannot fail) */
wb_status wb__particles_reserve(wb_world *w, int64_t extra);
/* distance.c: room for np_extra more particles and nd_extra more links: after it, adding
 * them cannot fail, so a builder never leaves half a body behind */
wb_status wb__reserve(wb_world *w, int64_t np_extra, int64_t nd_extra);
/* A Neo-Hookean body's damping (builders.c, tets.c): a dashpot along a tet edge of rest
 * length `length`, a link whose spring is 1e-4 of the edge's own stiffness E L (so E stays
 * E to about 1e-4 per link) and whose damping beta acts in full: with alpha~ >> 1/m the
 * XPBD damping of eq. 26 is a dashpot of beta N s/m whatever alpha is (distance.c: gamma /
 * alpha~ = beta h). Inline: both builders use it and neither calls the other's file. */
static inline wb_distance_def wb__dashpot_def(const wb_distance_def *link, wb_real young, wb_real length)
{
    wb_distance_def d = *link;
    d.compliance = 1 / ((wb_real)1e-4 * young * length);
    d.yield = d.creep = d.break_strain = d.break_force = 0;
    return d;
}
wb_status wb__surface_reserve(wb_world *w, int32_t ntri);
/* world.c: the world's pool for its current thread count (NULL: one thread); created
 * lazily, the same pool from call to call. A cache: callable on a const world */
wb_pool *wb__world_pool(const wb_world *w);
void *wb__grow(void *ptr, int32_t *cap, int32_t need, size_t elem); /* world.c: realloc helper */
/* world.c, the one budget routine: charge `want` bytes in place of *charged to the world's
 * memory budget (def.memory); 0 (nothing charged) when it would pass the limit */
int wb__charge(wb_world *w, size_t *charged, size_t want);
/* world.c: the capacity for need items of per bytes each, doubled from cap (64 at first)
 * up to max and charged to *charged (as wb__charge); an exact fit when doubling would
 * cross the limit; -1 when even that is refused */
int32_t wb__charge_cap(wb_world *w, size_t *charged, size_t per, int32_t cap, int32_t need, int32_t max);
/* one array of a structure of arrays: where its pointer is, the bytes of an element */
typedef struct { void **p; size_t elem; } wb_soa;
/* world.c: each of the n arrays reallocated to cap elements; WB_ERR_NOMEM when one fails
 * (the arrays grown before it are merely larger, all still valid) */
wb_status wb__soa_resize(const wb_soa *arr, size_t n, int64_t cap);
/* world.c: a capacity for need (> cap) elements: cap (first when 0) doubled until it
 * holds them, at most WB_MAX_CONSTRAINTS */
int32_t wb__grown_cap(int32_t cap, int64_t need, int32_t first);
#define WB_SOA_RESIZE(arr, cap) wb__soa_resize((arr), sizeof(arr) / sizeof((arr)[0]), (cap))
void wb__set_error(const char *fmt, ...);
void wb__warn(wb_world *w, const char *fmt, ...);

#endif
