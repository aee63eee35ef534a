/* rigid.h: XPBD rigid bodies (Müller, Macklin, Chentanez, Jeschke, Kim 2020, "Detailed
 * rigid body simulation with extended position based dynamics").
 *
 * Bodies live in slots with generations (odd = live), as colliders do. Model: shape,
 * inverse mass, body-frame inertia and its inverse. State: pose (centre of mass, unit
 * quaternion) and velocities (linear, angular in the world frame). Cache: the pose at the
 * substep's start, the frame's start (undo) and the substep's contacts. */
#ifndef WB_RIGID_H
#define WB_RIGID_H
#include "core.h"
#include "narrow.h"

typedef struct wb_rcontact {
    int32_t first;         /* the first contact of its manifold (they are contiguous) */
    int32_t a, b;          /* bodies; a < 0: a kinematic collider */
    wb_real ra[3], rb[3];  /* contact points in A's and B's body frame (a collider: world offset) */
    wb_real n[3];          /* unit, A -> B */
    wb_real lambda;        /* normal positional impulse of the substep, N s^2 */
    wb_real vn_pre;        /* normal relative velocity (B - A) before the solve */
    wb_real vc[3];         /* a collider's surface velocity at the point */
    wb_real mu, e;
} wb_rcontact;

/* a body pair's static friction, applied after the substep's normal sweeps (rigid.c) */
typedef struct wb_rfric {
    int32_t a, b;          /* bodies */
    wb_real la[3], lb[3];  /* the manifold's centre of normal impulses in A's and B's frame */
    wb_real n[3];          /* unit, A -> B */
    wb_real lmax;          /* mu x the normal impulse: the friction cone */
} wb_rfric;

typedef struct wb_rigids {
    int32_t n, cap;        /* slots */
    /* model */
    wb_cshape *shape;      /* (n) shape, friction, restitution */
    wb_real *mass;         /* (n) kg, as given */
    wb_real *inv_mass;     /* (n) 1 / mass */
    wb_real *inertia;      /* (n x 9) body-frame inertia tensor (row-major) */
    wb_real *inv_inertia;  /* (n x 9) its inverse */
    wb_real *bound;        /* (n) bounding radius about the centre */
    uint32_t *gen;         /* (n) odd = live */
    /* state */
    wb_real *x, *q, *v, *om; /* (n x 3), (n x 4), (n x 3), (n x 3): om in the world frame */
    /* cache */
    wb_real *x_prev, *q_prev; /* (n x 3), (n x 4) pose at the substep's start */
    wb_real *q_pred;       /* (n x 4) rotation after the substep's prediction */
    wb_real *save;         /* (n x 13) the frame's start: x, q, v, om (undo) */
    uint8_t *moved;        /* (n) a correction moved it this substep: its velocities come from the poses */
    wb_rcontact *ct;       /* contacts of the current substep */
    int32_t nct, cap_ct;
    /* a made overlap each manifold was left with (rigid.c, made_left): an open-addressed
     * table of the frame, (side A, body B) -> overlap, cleared at the frame's start */
    uint64_t *mk; wb_real *ml; int32_t cap_m, nm;
    wb_real step;          /* max_depenetration x h of the current substep */
    wb_rfric *fr;          /* body pairs' static friction of the current substep */
    int32_t nfr, cap_fr;
    int record_fr;         /* the forward sweep records them */
    /* the substep's broad phase (rigid.c), scratch */
    wb_real *cpose; int32_t cap_cpose;   /* (nc x 15) colliders' poses at the substep's start and
                                          * end, and bounding radius (< 0: always tested) */
    wb_real *box; int32_t cap_box;       /* (live bodies x 6) swept boxes: lo, hi */
    struct wb_rkey *ord; int32_t cap_ord; /* live bodies, sorted along the sweep axis */
    int32_t *pair, npair, cap_pair;      /* (npair x 2) candidate body pairs a < b, in (a, b) order */
    size_t charged;        /* bytes charged to def.memory */
    /* particle contacts (rigid_particle.c): the frame's candidates, the substep's active ones */
    int32_t *pc, npc, cap_pc;      /* (npc x 2) particle, body slot */
    wb_real *pc_left; int32_t cap_left; /* (npc) overlap a candidate was left with (wb__contact_depth) */
    wb_real *pc_sph; int32_t cap_sph; /* bodies' swept spheres (scratch) */
    int32_t *pc_slot, cap_slot;    /* their slots (scratch) */
    int32_t *pc_cnt, cap_cnt;      /* (n) contacts per body in the substep */
    wb_real *pc_bd; int32_t cap_bd; /* (n x 6) a body's move (or velocity) and turn of the
                                       pass's joint solve so far (scratch) */
    struct wb_rpcontact *pct;
    int32_t npct, cap_pct;
    int32_t free_hint;     /* no dead slot below it (wb_rigid_add's search starts there) */
} wb_rigids;

typedef struct wb_rpcontact {
    int32_t i, r;          /* particle, body slot */
    wb_real n[3];          /* unit, out of the body */
    wb_real depth, lambda; /* overlap corrected, positional impulse (N s^2) */
    wb_real slow, err;     /* of depth: a made overlap's repair, pushed with the start poses
                              (slow) or in full with its speed taken out (err): wb__contact_depth */
    wb_real lslow;         /* the positional impulse of slow (N s^2) */
    wb_real vn_pre;        /* normal relative velocity (particle - body) before the solve */
    wb_real x0[3];         /* the particle at the pass's start (the joint solve's reference) */
    wb_real wb;            /* the body's generalized inverse mass along n at the contact */
    wb_real arm[3];        /* where the body takes the impulses: offset from its centre */
    wb_real dp[3];         /* the body's impulse of the pass (scratch) */
} wb_rpcontact;

/* generalized inverse mass of body r for a positional correction along unit n at world point x
 * (Müller 2020 eq. 2): 1/m + (r x n)^T I^-1 (r x n), r = x - centre */
wb_real wb__rigid_w(const wb_world *w, int32_t r, const wb_real x[3], const wb_real n[3]);
/* I^-1 v in the world frame, at body r's current rotation */
void wb__rigid_inv_inertia(const wb_world *w, int32_t r, const wb_real v[3], wb_real out[3]);
/* apply positional impulse dp (= lambda n, world) at world point x: p += dp/m, q += 0.5 [I^-1 (r x dp), 0] q */
void wb__rigid_apply(wb_world *w, int32_t r, const wb_real x[3], const wb_real dp[3]);
/* K (3 x 3, row-major, symmetric): how world point x of body r moves per unit positional
 * impulse there, 1/m E - [d]x I^-1 [d]x (d = x - centre): a point constraint in 3D (an
 * attachment) solves K dlambda = -C at once instead of along C's direction only */
void wb__rigid_point_response(const wb_world *w, int32_t r, const wb_real x[3], wb_real K[9]);
/* x = A^-1 b for a 3 x 3 A (Cramer's rule; attachments and grabs to a body); 0 when singular */
static inline int wb__solve3(const wb_real A[9], const wb_real b[3], wb_real x[3])
{
    const wb_real c0[3] = { A[0], A[3], A[6] }, c1[3] = { A[1], A[4], A[7] }, c2[3] = { A[2], A[5], A[8] };
    wb_real t[3], u[3];
    v3_cross(t, c1, c2);
    const wb_real det = v3_dot(c0, t);
    if (!(fabs(det) > 0) || !isfinite(det)) return 0;
    x[0] = v3_dot(b, t) / det;
    v3_cross(u, b, c2);
    x[1] = v3_dot(c0, u) / det;
    v3_cross(u, c1, b);
    x[2] = v3_dot(c0, u) / det;
    return 1;
}
/* world point of a body-local point, and body-local of a world point, at the current pose */
void wb__rigid_to_world(const wb_world *w, int32_t r, const wb_real local[3], wb_real out[3]);
void wb__rigid_to_local(const wb_world *w, int32_t r, const wb_real world[3], wb_real out[3]);

/* the same positional impulse on body r's pose at the substep's start (x_prev, q_prev) and
 * its predicted rotation (q_pred), turned as its pose now would turn: the pose moves
 * without the move becoming speed (a made overlap's repair) */
void wb__rigid_apply_start(wb_world *w, int32_t r, const wb_real x[3], const wb_real dp[3]);

/* velocity impulse p at world point x on body r (v += p/m, om += I^-1 (r x p)) */
void wb__rigid_impulse(wb_world *w, int32_t r, const wb_real x[3], const wb_real p[3]);

/* particle-rigid contacts (rigid_particle.c): candidates once per frame, then per substep
 * the positional solve (after wb__rigids_solve) and the velocity pass (after wb__rigids_velocity) */
void wb__rigid_particles_begin(wb_world *w);
void wb__rigid_particles_solve(wb_world *w);
void wb__rigid_particles_velocity(wb_world *w, wb_real h);

/* the step's hooks (solver.c), per substep of length h */
void wb__rigids_predict(wb_world *w, wb_real h);   /* gravity, gyroscopic term, pose */
void wb__rigids_solve(wb_world *w, wb_real h, wb_real f0, wb_real f1); /* contacts; colliders at f0 -> f1 */
void wb__rigids_update(wb_world *w, wb_real h);    /* v, om from the poses */
void wb__rigids_velocity(wb_world *w, wb_real h);  /* dynamic friction, restitution */
void wb__rigids_save(wb_world *w);                 /* the frame's start, for undo */
void wb__rigids_undo(wb_world *w);                 /* back to it */
int wb__rigids_finite(const wb_world *w);          /* -1 when all are finite, else a slot */

/* contact solving given a manifold (narrow.h): two bodies, or collider slot c (A) and
 * body r (B); the collider's poses at the substep's start and end */
void wb__rigid_contact_rigid(wb_world *w, int32_t a, int32_t b, const wb_manifold *m, wb_real h);
void wb__rigid_contact_collider(wb_world *w, int32_t c, const wb_real p0[3], const wb_real q0[4],
                                const wb_real p1[3], const wb_real q1[4], int32_t r,
                                const wb_manifold *m, wb_real h);

/* room for `need` slots (charged to the budget); put slot `r` (< need) as given, raw:
 * shape (the capsule about its centre), mass, pose, velocities; 0 when the inertia is
 * singular (nothing changed). The snapshot (rigid_image.c) restores bodies through these */
int wb__rigids_reserve(wb_world *w, int32_t need);
int wb__rigid_set_slot(wb_world *w, int32_t r, const wb_cshape *s, wb_real mass, const wb_real x[3],
                       const wb_real q[4], const wb_real v[3], const wb_real om[3]);

/* body-frame inertia tensor (row-major 3 x 3) of a shape of mass m about its centre */
void wb__rigid_inertia(const wb_cshape *s, wb_real m, wb_real I[9]);
/* a valid def's shape (about its centre of mass), that centre x and the unit rotation q:
 * what wb_rigid_add and a def's image keep */
void wb__rigid_shape_of(const wb_rigid_def *d, wb_cshape *s, wb_real x[3], wb_real q[4]);

/* freed by world.c (an inline: a call into rigid.c would close a circle) */
static inline void wb__rigids_free(wb_world *w, wb_rigids *rb)
{
    if (!rb) return;
    if (w->m.def.memory) w->m.def.memory->used -= rb->charged;
    void *p[] = { rb->shape, rb->mass, rb->inv_mass, rb->inertia, rb->inv_inertia, rb->bound, rb->gen, rb->x, rb->q,
                  rb->v, rb->om, rb->x_prev, rb->q_prev, rb->q_pred, rb->save, rb->mk, rb->ml, rb->ct, rb->fr, rb->moved, rb->cpose, rb->box, rb->ord, rb->pair,
                  rb->pc, rb->pc_left, rb->pc_sph, rb->pc_slot, rb->pc_cnt, rb->pc_bd, rb->pct };
    for (size_t i = 0; i < sizeof p / sizeof p[0]; i++) free(p[i]);
    free(rb);
}
#endif
