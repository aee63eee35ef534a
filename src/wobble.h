/* wobble.h: the public C API of the wobble core (libwobble.a).
 *
 * One line per function, grouped as the Lua API is (docs/lua-api.md): the Lua name
 * w:foo(...) maps to wb_world_foo(w, ...), c:foo() to wb_distance_foo(w, c, ...).
 * The core has no Lua, no GL and no I/O side effects.
 *
 * Conventions
 *   - particle ids are 0-based here (Lua adds 1);
 *   - vectors are wb_real[3], quaternions wb_real[4] as (w, x, y, z);
 *   - constraint and collider handles carry a generation: a stale one is detected
 *     by wb_*_valid() and asserted on elsewhere (contract bug);
 *   - functions that can fail on external input return WB_OK or a negative
 *     wb_status and change nothing when they fail.
 */
#ifndef WOBBLE_H
#define WOBBLE_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#define WB_VERSION "0.1.0"

#ifdef WB_FLOAT
typedef float wb_real;
#else
typedef double wb_real; /* the reference thesis names 32-bit floats as its weakness */
#endif

/* hard limits: a request past them is an error, never an attempt to allocate */
#define WB_MAX_PARTICLES (1 << 24)
#define WB_MAX_CONSTRAINTS (1 << 26)
#define WB_MAX_COLLIDERS (1 << 16)
#define WB_MAX_SUBSTEPS 10000
#define WB_MAX_ITERATIONS 10000
#define WB_MAX_THREADS 256
#define WB_MAX_GROUP (1 << 30)  /* contact groups are 0..WB_MAX_GROUP */

typedef enum wb_status {
    WB_OK = 0,
    WB_ERR_NOMEM = -1,     /* allocation failed */
    WB_ERR_LIMIT = -2,     /* a WB_MAX_* limit would be exceeded */
    WB_ERR_ARG = -3,       /* an argument is out of its range (see wb_last_error) */
    WB_ERR_INTERRUPTED = -4, /* the interrupt callback stopped a step: the frame was undone */
} wb_status;

/* what is wrong with a constraint's arguments, as its type's check (wb_distance_check,
 * wb_bend_check, ...) finds it: the type's file is the one place that decides, and a
 * binding or a file reader says it in its own terms (the option's key, the particle's
 * argument or the file's line). msg NULL: nothing is wrong */
typedef struct wb_fault {
    const char *msg;    /* the whole sentence ("compliance must be >= 0") */
    const char *key;    /* the option at fault, as scripts and files name it; NULL: the particles */
    const char *why;    /* msg without its subject ("must be >= 0") */
    int corner;         /* key NULL: the particle at fault (0-based); -1: the particles together */
} wb_fault;

typedef enum wb_solver { WB_SOLVER_GAUSS_SEIDEL = 0, WB_SOLVER_JACOBI = 1, WB_SOLVER_VBD = 2 } wb_solver;

typedef enum wb_shape {
    WB_SHAPE_PLANE = 0, WB_SHAPE_SPHERE, WB_SHAPE_BOX, WB_SHAPE_CAPSULE, WB_SHAPE_MESH, WB_SHAPE_COUNT
} wb_shape;
/* what scripts and files call a shape, and the fields it takes as words separated by
 * spaces (its file, src/core/shape_NAME.c, gives them): of wb_collider_def (`mesh`: the
 * wb_mesh), of a collider in its own frame as w:save writes it (in that order), of
 * wb_rigid_def (in w:save's order; NULL: no rigid body has the shape) */
typedef struct wb_shape_info { const char *name, *fields, *own_fields, *rigid_fields; } wb_shape_info;
const wb_shape_info *wb_shape_info_of(wb_shape s); /* NULL when s is not a shape */
bool wb_shape_takes(const char *fields, const char *key); /* fields (a list above) has the word key */

typedef struct wb_world wb_world;

/* A memory budget several worlds share (and, in the command line, the Lua heap): each
 * world charges its particle and constraint arrays to it and gives them back when
 * destroyed; growth past `limit` (0 = none) fails with WB_ERR_NOMEM. */
typedef struct wb_memory { size_t limit, used; } wb_memory;

/* handles: index into the world's slot array + generation (0 never valid) */
typedef struct wb_distance_id { uint32_t index; uint32_t gen; } wb_distance_id;
typedef struct wb_collider_id { uint32_t index; uint32_t gen; } wb_collider_id;

/* ---- world ---------------------------------------------------------------- */
typedef struct wb_world_def {
    wb_real gravity[3];   /* m/s^2, default (0,-9.81,0) */
    wb_real dt;           /* frame length in seconds, default 1/60 */
    int substeps;         /* default 10 */
    int iterations;       /* constraint passes per substep, default 1 */
    wb_real damping;      /* linear velocity drag, 1/s: v *= max(0, 1 - damping*h) per substep */
    wb_solver solver;     /* default Gauss-Seidel */
    wb_real relaxation;   /* Jacobi over-relaxation factor omega, default 1 */
    int threads;          /* default 1; results are bit-identical for any value */
    bool contacts;        /* particle-particle contacts, default true */
    wb_real max_depenetration; /* m/s: how fast contacts push out an overlap a pair already had
                                  (bodies made inside each other), default 0.25; >= 0 */
    wb_real tolerance;    /* m: iterations stop once the constraints' residual is at most this
                             (wb_world_residual); 0 (default): always `iterations` */
    wb_memory *memory;    /* budget the world, its worker threads and its arrays are charged to; NULL =
                             none (not copied by set_def) */
} wb_world_def;

wb_world_def wb_world_default_def(void);                      /* the defaults above */
const char *wb_world_def_check(const wb_world_def *def);      /* NULL, or what is wrong ("dt must be > 0") */
wb_world *wb_world_create(const wb_world_def *def);           /* NULL when out of memory (or over def->memory,
                                                                 which is charged the world and its threads);
                                                                 def must pass check */
void wb_world_destroy(wb_world *w);                           /* NULL is fine */
wb_world_def wb_world_get_def(const wb_world *w);             /* current settings */
wb_status wb_world_set_def(wb_world *w, const wb_world_def *def); /* change settings between steps;
                                                                    WB_ERR_NOMEM: the threads do not fit the budget */

wb_status wb_world_step(wb_world *w);                         /* one frame of dt, all substeps */
/* polled once per substep; a nonzero answer abandons the step (WB_ERR_INTERRUPTED),
 * leaving the world as it was before it: a time budget can stop a long frame */
void wb_world_set_interrupt(wb_world *w, int (*fn)(void *ud), void *ud);
double wb_world_time(const wb_world *w);                      /* seconds simulated */
int64_t wb_world_frame(const wb_world *w);                    /* frames stepped */

/* ---- particles ------------------------------------------------------------- */
/* add a particle; mass 0 makes it immovable. Returns its id, or a negative wb_status
 * (WB_ERR_ARG for a mass so small that 1/mass overflows) */
int32_t wb_particle_add(wb_world *w, const wb_real pos[3], const wb_real vel[3], wb_real mass, wb_real radius);
int32_t wb_particle_count(const wb_world *w);
void wb_particle_position(const wb_world *w, int32_t p, wb_real out[3]);
void wb_particle_set_position(wb_world *w, int32_t p, const wb_real pos[3]); /* teleport: velocity unchanged */
void wb_particle_velocity(const wb_world *w, int32_t p, wb_real out[3]);
void wb_particle_set_velocity(wb_world *w, int32_t p, const wb_real vel[3]);
wb_real wb_particle_mass(const wb_world *w, int32_t p);       /* as created; 0 = immovable */
wb_real wb_particle_radius(const wb_world *w, int32_t p);
void wb_particle_pin(wb_world *w, int32_t p, const wb_real *pos); /* fix in place (at pos when not NULL) */
void wb_particle_unpin(wb_world *w, int32_t p);               /* free again (its own mass back) */
bool wb_particle_pinned(const wb_world *w, int32_t p);
const wb_real *wb_particle_positions(const wb_world *w);      /* (n x 3), valid until the next add */

/* ---- distance constraints (XPBD) -------------------------------------------------- */
typedef struct wb_distance_def {
    wb_real compliance;   /* alpha, m/N (inverse stiffness); 0 = rigid */
    wb_real damping;      /* beta, Macklin et al. 2016 eq. 26; acts when compliance > 0 */
    wb_real rest;         /* rest length; < 0 means the current distance */
    wb_real yield;        /* plastic yield strain; 0 = elastic */
    wb_real creep;        /* plastic flow rate, 1/s, when past yield */
    wb_real break_strain; /* tensile strain that breaks it; 0 = unbreakable */
    wb_real break_force;  /* N: breaks when the force of a frame's last substep passes it; 0 = never */
} wb_distance_def;

wb_distance_def wb_distance_default_def(void);                /* rigid, rest = current, elastic, unbreakable */
const char *wb_distance_def_check(const wb_distance_def *def); /* NULL or what is wrong */
/* what wb_distance_add would refuse of these arguments (np particles; x: their positions,
 * or NULL to leave out the check of their distance) */
wb_fault wb_distance_check(int32_t np, const wb_real *x, int32_t a, int32_t b, const wb_distance_def *def);
/* connect two distinct particles; returns the handle, or index 0 / gen 0 with *status set */
wb_distance_id wb_distance_add(wb_world *w, int32_t a, int32_t b, const wb_distance_def *def, wb_status *status);
bool wb_distance_valid(const wb_world *w, wb_distance_id c);  /* false for stale or removed handles */
void wb_distance_remove(wb_world *w, wb_distance_id c);
wb_real wb_distance_force(const wb_world *w, wb_distance_id c); /* N, |lambda|/h^2 of the last substep */
wb_real wb_distance_rest(const wb_world *w, wb_distance_id c);  /* current (plastic) rest length */
wb_real wb_distance_length(const wb_world *w, wb_distance_id c);
bool wb_distance_broken(const wb_world *w, wb_distance_id c);
void wb_distance_particles(const wb_world *w, wb_distance_id c, int32_t *a, int32_t *b);
int32_t wb_distance_count(const wb_world *w);                 /* live constraints, broken included */
/* iterate: the i-th live constraint for i in [0, count) (order stable between edits) */
wb_distance_id wb_distance_at(const wb_world *w, int32_t i);
/* every live constraint's handle in slot order, at once (out holds wb_distance_count):
 * wb_distance_at is a scan, so a loop over it is quadratic */
int32_t wb_distance_ids(const wb_world *w, wb_distance_id *out);

/* ---- bending constraints (XPBD, bend.c) ------------------------------------------------- */
/* the dihedral angle between triangles (p1, p2, p3) and (p2, p1, p4) across the hinge
 * p1-p2, 0 when they lie flat, +-pi folded over (Müller et al. 2007, appendix A) */
typedef struct wb_bend_id { uint32_t index; uint32_t gen; } wb_bend_id;
typedef struct wb_bend_def {
    wb_real compliance;   /* alpha, rad/(N m) (inverse angular stiffness); 0 = rigid */
    wb_real damping;      /* beta, as a distance's; acts when compliance > 0 */
    wb_real rest;         /* rest angle, rad in [-pi, pi]; NAN = the angle at creation */
    wb_real break_torque; /* N m: breaks when the torque of a frame's last substep passes it; 0 = never */
} wb_bend_def;

wb_bend_def wb_bend_default_def(void);                        /* rigid, undamped, rest = current */
const char *wb_bend_def_check(const wb_bend_def *def);        /* NULL or what is wrong */
/* what wb_bend_add would refuse of these arguments (np particles; x: their positions, or
 * NULL to leave out the check that the triangles have an angle) */
wb_fault wb_bend_check(int32_t np, const wb_real *x, const int32_t p[4], const wb_bend_def *def);
/* four distinct particles whose triangles are not degenerate; index 0 / gen 0 and
 * *status set on failure. Bends are never removed */
wb_bend_id wb_bend_add(wb_world *w, const int32_t p[4], const wb_bend_def *def, wb_status *status);
bool wb_bend_valid(const wb_world *w, wb_bend_id b);
wb_real wb_bend_angle(const wb_world *w, wb_bend_id b);       /* rad now (NAN while degenerate) */
wb_real wb_bend_rest(const wb_world *w, wb_bend_id b);        /* rad */
wb_real wb_bend_force(const wb_world *w, wb_bend_id b);       /* N m, |lambda|/h^2 of the last substep */
void wb_bend_particles(const wb_world *w, wb_bend_id b, int32_t p[4]);
int32_t wb_bend_count(const wb_world *w);
wb_bend_id wb_bend_at(const wb_world *w, int32_t i);          /* 0 <= i < count, creation order */
bool wb_bend_broken(const wb_world *w, wb_bend_id b);         /* broken by its break_torque (no longer projected) */
int32_t wb_world_bend_break_count(const wb_world *w);         /* bends broken in the last step */
wb_bend_id wb_world_bend_break_at(const wb_world *w, int32_t i);
/* the dihedral angle a bend over these positions has (rad); false when degenerate */
bool wb_dihedral_angle(const wb_real x1[3], const wb_real x2[3], const wb_real x3[3], const wb_real x4[3], wb_real *theta);

/* ---- colliders (kinematic: the script moves them) -------------------------------- */
typedef struct wb_collider_def {
    wb_shape shape;
    wb_real normal[3], offset;    /* plane: points x with n.x = offset, normal need not be unit */
    wb_real center[3];            /* sphere, box, mesh */
    wb_real radius;               /* sphere, capsule */
    wb_real half[3];              /* box half extents */
    wb_real rotation[4];          /* box, mesh: (w,x,y,z), normalised on add */
    wb_real a[3], b[3];           /* capsule segment */
    wb_real friction;             /* Coulomb coefficient (static = dynamic) */
    wb_real restitution;          /* 0..1 */
    const struct wb_mesh *mesh;   /* mesh: its triangles, copied (x scale) into the collider's own
                                   * frame; closed (every edge shared by two triangles): inside
                                   * is inside, else two-sided. get_def gives NULL: see wb_collider_mesh */
    wb_real scale;                /* mesh: > 0, default 1 */
} wb_collider_def;

wb_collider_def wb_collider_default_def(wb_shape shape);      /* a unit-ish shape at the origin */
const char *wb_collider_def_check(const wb_collider_def *def); /* NULL or what is wrong ("radius must be > 0") */
wb_collider_id wb_collider_add(wb_world *w, const wb_collider_def *def, wb_status *status);
bool wb_collider_valid(const wb_world *w, wb_collider_id c);
void wb_collider_remove(wb_world *w, wb_collider_id c);
wb_shape wb_collider_shape(const wb_world *w, wb_collider_id c);
/* The pose set between steps is reached at the end of the next step: the collider
 * sweeps there substep by substep, pushing particles (no tunnelling). */
void wb_collider_set_position(wb_world *w, wb_collider_id c, const wb_real p[3]);
void wb_collider_set_rotation(wb_world *w, wb_collider_id c, const wb_real q[4]);
void wb_collider_set_velocity(wb_world *w, wb_collider_id c, const wb_real v[3]);   /* moves it by v*dt per frame */
void wb_collider_set_angular_velocity(wb_world *w, wb_collider_id c, const wb_real om[3]);
void wb_collider_position(const wb_world *w, wb_collider_id c, wb_real out[3]);
void wb_collider_rotation(const wb_world *w, wb_collider_id c, wb_real out[4]);
void wb_collider_velocity(const wb_world *w, wb_collider_id c, wb_real out[3]);
void wb_collider_get_def(const wb_world *w, wb_collider_id c, wb_collider_def *out); /* shape + current pose */
int32_t wb_collider_count(const wb_world *w);
wb_collider_id wb_collider_at(const wb_world *w, int32_t i);
/* signed distance from p to the collider surface at its current pose (negative inside;
 * an open mesh is two-sided: >= 0) */
wb_real wb_collider_distance(const wb_world *w, wb_collider_id c, const wb_real p[3]);
/* a mesh collider's triangles in its own frame (scale applied; world = pose applied):
 * returns the vertex count, 0 for other shapes; pointers valid until it is removed */
int32_t wb_collider_mesh(const wb_world *w, wb_collider_id c, const wb_real **v, const int32_t **tri, int32_t *nt);
bool wb_collider_mesh_closed(const wb_world *w, wb_collider_id c);
/* what a renderer draws of a shape: spheres, cylinders (capped by spheres) and boxes in the
 * world at the current pose; a plane and a mesh have none (the ground; wb_collider_mesh) */
typedef enum wb_solid_kind { WB_SOLID_SPHERE, WB_SOLID_CYLINDER, WB_SOLID_BOX } wb_solid_kind;
typedef struct wb_solid {
    wb_solid_kind kind;
    wb_real c[3];                 /* sphere, box: centre */
    wb_real a[3], b[3];           /* cylinder: its axis' ends */
    wb_real radius;               /* sphere, cylinder */
    wb_real axes[3][3];           /* box: axes[k] is its k-th half axis in the world */
} wb_solid;
#define WB_MAX_SOLIDS 3
/* the collider's solids into out (room for WB_MAX_SOLIDS); returns how many */
int wb_collider_solids(const wb_world *w, wb_collider_id c, wb_solid out[WB_MAX_SOLIDS]);

/* ---- builders: particles are contiguous [first, first+count) --------------------------- */
typedef struct wb_body { int32_t first, count, group; } wb_body; /* group: its contact group */

typedef struct wb_cloth_def {
    wb_real origin[3];    /* corner; the cloth spans +x by size[0] and +z by size[1] */
    wb_real size[2];
    int res[2];           /* particles along x and z (>= 2) */
    wb_real mass;         /* total, spread evenly */
    wb_real radius;
    bool shear;           /* one diagonal per cell, alternating */
    wb_real bend;         /* < 0: none; else compliance (rad/(N m)) of a dihedral bend per interior edge */
    wb_real bend_links;   /* < 0: none; else compliance of skip-one bending links (distance) */
    wb_distance_def link; /* options of every constraint made */
} wb_cloth_def;

typedef struct wb_rope_def {
    wb_real from[3], to[3];
    int segments;         /* >= 1; segments + 1 particles */
    wb_real mass, radius;
    wb_distance_def link;
} wb_rope_def;

typedef struct wb_lattice_def {
    wb_real min[3], max[3];
    int res[3];           /* particles per axis (>= 2) */
    wb_real mass, radius;
    wb_distance_def link; /* edges, face and body diagonals of every cell */
    bool tets;            /* also 6 tetrahedra per cell, each with a volume constraint */
    wb_real volume_compliance; /* theirs (m^3/Pa), default 0: incompressible */
    wb_real young, poisson; /* young > 0 (Pa, needs tets): Neo-Hookean tets (tet.c) instead of
                             * volume constraints and no links; default 0 (off), 0.3 */
} wb_lattice_def;

wb_cloth_def wb_cloth_default_def(void);
wb_rope_def wb_rope_default_def(void);
wb_lattice_def wb_lattice_default_def(void);
wb_status wb_cloth(wb_world *w, const wb_cloth_def *def, wb_body *out);     /* WB_ERR_ARG: see wb_last_error */
wb_status wb_rope(wb_world *w, const wb_rope_def *def, wb_body *out);
wb_status wb_lattice(wb_world *w, const wb_lattice_def *def, wb_body *out);

/* ---- contacts between particles (contact.c) ------------------------------------------- */
/* Every particle has a group: 0 = loose (collides with every particle), > 0 = a body.
 * Pairs of different groups collide when both have `collide`; pairs inside one body only
 * when it self-collides, and then never when joined by a constraint or closer than
 * r_i + r_j where they were created. Contact distance r_i + r_j, friction the mean of
 * the two particles'. wb_world_def.contacts = false turns them all off. Builders give
 * each body a new group (collide on, self-collision off, friction 0). */
int32_t wb_group_new(const wb_world *w);                      /* 1 + the largest group in use */
int32_t wb_particle_group(const wb_world *w, int32_t p);
void wb_particle_set_group(wb_world *w, int32_t p, int32_t group); /* group >= 0 */
wb_real wb_particle_friction(const wb_world *w, int32_t p);
void wb_particle_set_friction(wb_world *w, int32_t p, wb_real mu); /* mu >= 0, finite */
bool wb_particle_collides(const wb_world *w, int32_t p);
/* the particles [b.first, b.first + b.count) into group b.group with these settings */
void wb_body_set_contacts(wb_world *w, wb_body b, bool collide, bool self_collide, wb_real friction);
int32_t wb_group_set_self_collide(wb_world *w, int32_t group, bool on); /* every particle of the group; how many */
bool wb_group_self_collide(const wb_world *w, int32_t group);  /* some particle of it self-collides */
void wb_particle_set_radius(wb_world *w, int32_t p, wb_real r); /* r >= 0, finite */
/* the mean over the body's particles of their shortest link, any constraint's (0 when none): the
 * spacing a default contact radius is taken from */
wb_real wb_body_spacing(const wb_world *w, wb_body b);
/* the particle-particle contacts that corrected positions in the last substep of the last
 * step, in projection order (pairs merely in touch, with nothing to correct, are in
 * stats.particle_contacts but not here). force = the normal correction's multiplier over
 * h^2: lambda = depth / (w_a + w_b), force = lambda / h^2 in newtons, h the substep, as
 * wb_distance_force (friction not included); normal: unit, from a towards b; depth: the
 * overlap the substep corrected (m). Valid until the world changes */
typedef struct wb_contact { int32_t a, b; wb_real force, normal[3], depth; } wb_contact;
int32_t wb_world_contact_count(const wb_world *w);
wb_contact wb_world_contact_at(const wb_world *w, int32_t i);     /* 0 <= i < count */
/* particle-triangle contacts (tricontact.c): a particle keeps its radius from the
 * triangles of the registered surfaces it may touch (the pair rules above between it and
 * each corner; never its own triangles, nor, in one body, a triangle it lay within its
 * radius of where created). Those that corrected positions in the last substep, in
 * projection order: p the particle, tri the corners, bary the barycentrics of the
 * closest point; normal unit from p towards the triangle (the triangle is pushed along
 * it, p against it, as wb_contact's a -> b); depth and force as wb_contact's, with
 * lambda = depth / (w_p + sum bary_i^2 w_i). Counted in stats.particle_contacts */
typedef struct wb_tri_contact { int32_t p, tri[3]; wb_real bary[3], force, normal[3], depth; } wb_tri_contact;
int32_t wb_world_tri_contact_count(const wb_world *w);
wb_tri_contact wb_world_tri_contact_at(const wb_world *w, int32_t i); /* 0 <= i < count */

/* ---- surfaces: triangles over particles, for drawing and export ------------------------ */
/* builders register theirs (the cloth's sheet, the lattice's hull); returns the surface
 * index or a negative wb_status; tri is (ntri x 3) particle ids */
int32_t wb_surface_add(wb_world *w, const int32_t *tri, int32_t ntri);
int32_t wb_surface_count(const wb_world *w);
const int32_t *wb_surface_triangles(const wb_world *w, int32_t s, int32_t *ntri); /* valid until the next add */

/* ---- tethers (long-range attachments, tether.c) ------------------------------------------- */
/* Kim, Chentanez, Müller 2012: |x_p - x_q| <= length, a one-sided constraint that pulls and
 * never pushes, so a particle far down a chain of links from its pin stays within its rest
 * distance of it at any iteration count. Numbered 0.. in the order made; never removed. */
typedef struct wb_tether_def {
    bool has_length;      /* false: their distance now */
    wb_real length;       /* m, >= 0 */
    wb_real compliance;   /* m/N; 0 = inextensible past length */
} wb_tether_def;
wb_tether_def wb_tether_default_def(void);
const char *wb_tether_def_check(const wb_tether_def *def);   /* NULL or what is wrong */
/* what wb_tether_add would refuse (x: the positions, or NULL to leave out their distance) */
wb_fault wb_tether_check(int32_t np, const wb_real *x, int32_t p, int32_t q, const wb_tether_def *def);
/* returns the tether's index, or a negative wb_status (WB_ERR_ARG: see wb_last_error) */
int32_t wb_tether_add(wb_world *w, int32_t p, int32_t q, const wb_tether_def *def);
/* a tether from each of ids' particles that is not pinned to the nearest pinned one among
 * them where they were made, that far: how many were made (0 without a pin), or a status */
int32_t wb_tether_to_pins(wb_world *w, const int32_t *ids, int32_t n, wb_real compliance);
int32_t wb_tether_count(const wb_world *w);
void wb_tether_particles(const wb_world *w, int32_t i, int32_t pq[2]);
wb_real wb_tether_length(const wb_world *w, int32_t i);        /* m */
wb_real wb_tether_force(const wb_world *w, int32_t i);         /* N, |lambda|/h^2 of the last substep */

/* ---- queries ---------------------------------------------------------------------- */
void wb_world_energy(const wb_world *w, wb_real *kinetic, wb_real *potential); /* J; potential = gravity + elastic */
void wb_world_momentum(const wb_world *w, wb_real out[3]);          /* movable particles */
void wb_world_angular_momentum(const wb_world *w, wb_real out[3]);  /* about the origin */
bool wb_world_bounds(const wb_world *w, wb_real min[3], wb_real max[3]); /* false when no particles */
wb_real wb_world_max_strain(const wb_world *w);                     /* max |len-rest|/rest over live constraints */
/* every live, unbroken constraint at once (for drawing): particle pairs (n x 2) and
 * signed strains (len-rest)/rest (n), either may be NULL; returns n */
int32_t wb_world_distance_pairs(const wb_world *w, int32_t *ij, wb_real *strain);
uint64_t wb_world_hash(const wb_world *w);                          /* FNV-1a of the whole state */

typedef struct wb_stats {
    int32_t particles, distances, broken, colliders;
    int32_t bends, volumes, tets, shape_matches, pressures;   /* constraints of the other types */
    int32_t colours;          /* batches of the last colouring */
    int32_t contacts;         /* collider contacts in the last substep */
    int32_t particle_contacts; /* particle pairs and particle-triangle pairs overlapping or in touch
                                  in the last substep */
    double broad_ms;          /* broad phase of the last step */
    int32_t broad_remakes;    /* particle contact lists made again within the last step (a
                                 particle moved farther than the list's reach allowed) */
    int64_t projections;      /* constraint projections in the last step, every type's (a
                                 shape-matching cluster or a pressure body counts one) */
    double step_ms;           /* wall time of the last step */
    double solve_ms;          /* of which constraint projection */
    double iterations_run;    /* iterations a substep of the last step ran, on average: the
                                 world's iterations, or fewer where tolerance stopped them */
    int64_t warnings;         /* numerical trouble detected so far */
    int32_t attachments, grabs; /* live ones (attach.c, grab.c) */
    int32_t rigids;           /* live rigid bodies */
    int32_t rigid_contacts;   /* particle-rigid contacts that corrected positions in the last substep */
    int32_t tethers;          /* tethers (wb_tether_add) */
} wb_stats;
wb_stats wb_world_stats(const wb_world *w);
/* the constraints' residual, m: the largest of every constraint's |C + alpha~ lambda| over
 * the RMS of its corners' gradients (how far they are from meeting it), after the last
 * substep's iterations. Measured by each step from the first call on (a pass over every
 * constraint); that first call measures the positions as they are; 0 before any step */
wb_real wb_world_residual(wb_world *w);

/* numerical trouble: counted, the last message kept; the step restores the previous
 * frame's particles when a position or velocity turns non-finite */
int64_t wb_world_warnings(const wb_world *w);
const char *wb_world_last_warning(const wb_world *w);  /* "" when none */

/* events buffered during the last step (never a callback inside the solver) */
int32_t wb_world_break_count(const wb_world *w);                   /* constraints broken in the last step */
wb_distance_id wb_world_break_at(const wb_world *w, int32_t i);

const char *wb_last_error(void);   /* message of the last WB_ERR_ARG in this thread */

/* ==== meshes, particle graphs from meshes, skinning, snapshots ============================ */

/* ---- meshes (mesh.c): triangle meshes in memory; file formats live outside the core ---- */
typedef struct wb_mesh {
    int32_t nv, nt;
    wb_real *v;           /* (nv x 3) positions */
    wb_real *n;           /* (nv x 3) unit normals: area-weighted mean of the faces around */
    int32_t *tri;         /* (nt x 3) vertex ids, counter-clockwise seen from outside */
} wb_mesh;

/* copy vertices and triangles (triangles repeating a corner are dropped), compute normals;
 * NULL with *status set (WB_ERR_ARG: non-finite vertex, corner out of range; see wb_last_error) */
wb_mesh *wb_mesh_create(const wb_real *v, int32_t nv, const int32_t *tri, int32_t nt, wb_status *status);
wb_mesh *wb_mesh_copy(const wb_mesh *m);                      /* NULL when out of memory */
void wb_mesh_destroy(wb_mesh *m);                             /* NULL is fine */
/* merge vertices closer than tol (0: identical positions only), first occurrence kept, order
 * kept; triangles that collapse are dropped, normals recomputed. remap (old nv) may be NULL */
wb_status wb_mesh_weld(wb_mesh *m, wb_real tol, int32_t *remap);
void wb_mesh_compute_normals(wb_mesh *m);
bool wb_mesh_bounds(const wb_mesh *m, wb_real min[3], wb_real max[3]); /* false when empty */
void wb_mesh_transform(wb_mesh *m, wb_real scale, const wb_real offset[3]); /* v = v * scale + offset */
/* the unique undirected edges (a < b, sorted); *ij (n x 2) is malloc'd, the caller frees it;
 * returns n or a negative wb_status */
int32_t wb_mesh_edges(const wb_mesh *m, int32_t **ij);
/* vertex clustering on a uniform grid whose cell size is searched so that about `target`
 * cells are occupied: cluster[v] in [0, n), numbered by first vertex; returns n or < 0 */
int32_t wb_mesh_cluster(const wb_mesh *m, int32_t target, int32_t *cluster);

/* ---- k-d tree (kdtree.c): K nearest neighbours over a fixed point set -------------------- */
typedef struct wb_kdtree wb_kdtree;
wb_kdtree *wb_kdtree_build(const wb_real *pts, int32_t n);    /* copies (n x 3) points; NULL on no memory */
void wb_kdtree_destroy(wb_kdtree *t);
#define WB_KDTREE_MAXK 64 /* a larger k is served as this many */
/* the k nearest points to q, nearest first, ties by lower index: ids and squared distances
 * (either may be NULL, else sized by the caller for k entries: never more are written);
 * returns min(k, WB_KDTREE_MAXK, n) */
int wb_kdtree_knn(const wb_kdtree *t, const wb_real q[3], int k, int32_t *ids, wb_real *dist2);
/* the same over every point but `skip` (a point's own neighbours: asking for k + 1 and
 * dropping the point itself overflows a k-sized buffer when ties at distance 0 rank a
 * lower index before it); returns min(k, WB_KDTREE_MAXK, n - 1) for a valid skip */
int wb_kdtree_knn_except(const wb_kdtree *t, const wb_real q[3], int k, int32_t skip, int32_t *ids, wb_real *dist2);

/* ---- particle graph from a mesh (from_mesh.c) ------------------------------------------- */
typedef struct wb_from_mesh_def {
    wb_real mass, radius; /* total mass spread evenly; particle radius */
    int32_t target;       /* 0: a particle per vertex; else about this many, by vertex clustering */
    int neighbours;       /* also link each particle to its k nearest (volume for hollow shells) */
    bool surface;         /* register the (clustered) triangles as a surface */
    wb_distance_def link; /* options of every constraint made (rest = current length) */
} wb_from_mesh_def;

wb_from_mesh_def wb_from_mesh_default_def(void);              /* mass 1, radius 0.02, every vertex, surface */
/* a particle per (clustered) vertex, a distance constraint per edge; out->count particles */
wb_status wb_from_mesh(wb_world *w, const wb_mesh *m, const wb_from_mesh_def *def, wb_body *out);

/* ---- skinning (skin.c): linear blend skinning of a mesh over particles ------------------- */
/* Each vertex binds to its `bones` nearest particles (k-d tree) with weights that sum to 1
 * and fall off with distance. A bone's frame follows its particle and the rotation of its
 * neighbourhood (its `neighbours` nearest particles at bind time), extracted with Müller
 * et al. 2016 warm-started from the last update. */
typedef struct wb_skin wb_skin;
typedef struct wb_skin_def {
    int bones;            /* particles per vertex, 1..16, default 4 */
    int neighbours;       /* particles whose motion gives a bone's rotation, 1..32, default 8 */
    int iterations;       /* max rotation-extraction iterations per update, default 50 (a warm start
                           * converges in one or two; a sudden large turn needs tens) */
} wb_skin_def;

wb_skin_def wb_skin_default_def(void);
const char *wb_skin_def_check(const wb_skin_def *def);        /* NULL or what is wrong */
/* bind m (copied) to the particles ids[0..n) at their current positions; NULL with *status */
wb_skin *wb_skin_create(const wb_world *w, const wb_mesh *m, const int32_t *ids, int32_t n,
                        const wb_skin_def *def, wb_status *status);
void wb_skin_destroy(wb_skin *s);                             /* NULL is fine */
/* Bring the bones up to the particles' positions (a no-op when they have not moved since
 * the last update); the binding calls it after every frame so the warm start stays close */
void wb_skin_update_bones(wb_skin *s, const wb_world *w);
/* the deformed vertices (nv x 3), updated when the particles moved; valid until the next call */
const wb_real *wb_skin_vertices(wb_skin *s, const wb_world *w);
const wb_real *wb_skin_normals(wb_skin *s, const wb_world *w); /* (nv x 3) of the deformed mesh */
const wb_mesh *wb_skin_rest(const wb_skin *s);                /* the bound mesh, rest pose */
int32_t wb_skin_bone_count(const wb_skin *s);                 /* particles bound */
int32_t wb_skin_bone_particle(const wb_skin *s, int32_t b);
void wb_skin_bone_rotation(const wb_skin *s, int32_t b, wb_real q[4]); /* at the last update */
/* vertex v's particles and weights (arrays of wb_skin_def.bones); returns how many */
int wb_skin_influences(const wb_skin *s, int32_t v, int32_t *particles, wb_real *weights);

/* rotational part of A (3 x 3, row-major) after Müller et al. 2016, "A robust method to
 * extract the rotational part of deformations": q (w,x,y,z) is the warm start and the result */
void wb_extract_rotation(const wb_real A[9], wb_real q[4], int max_iter);
void wb_quat_to_matrix(const wb_real q[4], wb_real R[9]);     /* row-major */
/* the weld distance used unless one is given (wobble.load_mesh, wobble.mesh{weld = true},
 * wb_from_mesh): 1e-6 of the bounding box's diagonal, 0 for an empty mesh */
wb_real wb_mesh_weld_tolerance(const wb_mesh *m);

/* ---- snapshots (snapshot.c) --------------------------------------------------------------- */
/* an exact copy: same hash, and the two step bit-identically; NULL when out of memory */
wb_world *wb_world_clone(const wb_world *w);


/* ==== volume constraints and tetrahedral solids (volume.c, tets.c) ========================= */
/* A volume constraint keeps the signed volume of the tetrahedron p0 p1 p2 p3,
 * V = (p1-p0) . ((p2-p0) x (p3-p0)) / 6, at its rest value (XPBD, gradients of V, mass
 * weighted): a tet pushed inside out is pushed back to the sign it was made with.
 * Compliance alpha in m^3/Pa (C = V - V0 = alpha * p, p the pressure); 0 = incompressible.
 * Constraints are numbered 0.. in the order made and are not removed. */
typedef struct wb_volume_def {
    wb_real compliance;   /* m^3/Pa; 0 = incompressible */
    bool has_rest;        /* false: the current signed volume */
    wb_real rest;         /* the signed rest volume, when has_rest */
    wb_real yield, creep; /* plastic flow of the rest volume as a distance's; 0: none */
} wb_volume_def;

wb_volume_def wb_volume_default_def(void);                    /* incompressible, rest = current */
const char *wb_volume_def_check(const wb_volume_def *def);    /* NULL or what is wrong */
/* what wb_volume_add would refuse (x: the positions, or NULL to leave out their volume) */
wb_fault wb_volume_check(int32_t np, const wb_real *x, const int32_t p[4], const wb_volume_def *def);
/* returns the constraint's index, or a negative wb_status (WB_ERR_ARG: see wb_last_error) */
int32_t wb_volume_add(wb_world *w, const int32_t p[4], const wb_volume_def *def);
int32_t wb_volume_count(const wb_world *w);
void wb_volume_particles(const wb_world *w, int32_t i, int32_t p[4]);
wb_real wb_volume_rest(const wb_world *w, int32_t i);          /* signed, m^3 */
wb_real wb_volume_current(const wb_world *w, int32_t i);       /* signed, m^3 */
wb_real wb_volume_compliance(const wb_world *w, int32_t i);
wb_real wb_volume_pressure(const wb_world *w, int32_t i);      /* Pa, lambda/h^2 of the last substep; > 0 compressed */
/* sums over every volume constraint of the current and rest signed volumes */
void wb_world_volume_total(const wb_world *w, wb_real *current, wb_real *rest);
/* ==== Neo-Hookean tetrahedra (tet.c; Macklin & Müller 2021) ===============================
 * Two XPBD constraints per tet (deviatoric, hydrostatic), rest shape = the particles' shape
 * when made; recovers from inversion. */
typedef struct wb_tet_def {
    wb_real young;        /* Young's modulus, Pa (> 0), default 1e5 */
    wb_real poisson;      /* Poisson's ratio in [0, 0.5), default 0.3 */
    wb_real yield, creep; /* plastic flow of the rest shape (tet.c); 0: none */
} wb_tet_def;
wb_tet_def wb_tet_default_def(void);
const char *wb_tet_def_check(const wb_tet_def *def);          /* NULL or what is wrong */
/* what wb_tet_add would refuse (x: the positions, or NULL to leave out their rest shape) */
wb_fault wb_tet_check(int32_t np, const wb_real *x, const int32_t p[4], const wb_tet_def *def);
/* index, or WB_ERR_ARG (see wb_last_error: a particle twice, a flat tet) */
int32_t wb_tet_add(wb_world *w, const int32_t p[4], const wb_tet_def *def);
int32_t wb_tet_count(const wb_world *w);
void wb_tet_particles(const wb_world *w, int32_t i, int32_t p[4]);
wb_real wb_tet_energy(const wb_world *w, int32_t i);           /* J, 0 at rest */
wb_real wb_tet_rest_volume(const wb_world *w, int32_t i);      /* m^3, > 0 */
wb_real wb_tet_volume_ratio(const wb_world *w, int32_t i);     /* det F: < 0 inverted */
/* det F - 1, or where larger the shape change (shear too; > 0, von Mises equivalent strain) */
wb_real wb_tet_strain(const wb_world *w, int32_t i);
void wb_tet_material(const wb_world *w, int32_t i, wb_real *young, wb_real *poisson);
/* the rest state of a tet (a b c d): Dm^-1 (row-major) and |volume|; false when flat */
bool wb_tet_rest_shape(const wb_real *a, const wb_real *b, const wb_real *c, const wb_real *d, wb_real dminv[9],
                       wb_real *volume);
wb_real wb_tet_signed_volume(const wb_real *a, const wb_real *b, const wb_real *c, const wb_real *d);

/* a tetrahedral solid: a particle per node (mass lumped by tet volume), a volume constraint
 * per tet (turned positive: two corners swapped when given inside out), a distance link per
 * tet edge, and a surface: tri when given (ntri > 0), else the tets' boundary faces */
typedef struct wb_tet_body_def {
    wb_real mass, radius; /* total mass, particle radius */
    wb_distance_def link; /* every edge link (rest = current length) */
    wb_real volume_compliance; /* every tet's volume constraint */
    wb_real young, poisson; /* young > 0 (Pa): Neo-Hookean tets instead, no links; default 0, 0.3 */
} wb_tet_body_def;
wb_tet_body_def wb_tet_body_default_def(void);                 /* mass 1, radius 0.02, rigid */
wb_status wb_tet_body(wb_world *w, const wb_real *v, int32_t nv, const int32_t *tet, int32_t nt,
                      const int32_t *tri, int32_t ntri, const wb_tet_body_def *def, wb_body *out);
/* edges of m used by other than two triangles (0 for a closed mesh); the first in *a, *b */
int32_t wb_mesh_open_edges(const wb_mesh *m, int32_t *a, int32_t *b);
/* ---- shape matching (shape_match.c) ---------------------------------------------------------
 * Müller et al. 2005: a cluster's particles are pulled towards goal positions, their rest
 * shape turned by the rotation that best fits the current shape (Müller et al. 2016's
 * extraction) about the current mass centre; mass-weighted, so momentum is kept. */
typedef struct wb_shape_match_def {
    wb_real stiffness;    /* [0, 1], default 1 (rigid): the fraction of a particle's distance
                           * to its goal removed per 1/60 s; a spring of the same strength at
                           * any dt and substeps (see shape_match.c) */
    wb_real yield;        /* shape strain past which the rest shape flows; 0 = elastic */
    wb_real creep;        /* plastic flow rate, 1/s, past yield */
} wb_shape_match_def;

wb_shape_match_def wb_shape_match_default_def(void);          /* rigid, elastic */
const char *wb_shape_match_def_check(const wb_shape_match_def *def); /* NULL or what is wrong */
/* the options' fault as wb_shape_match_def_check finds it, by key (wb_fault) */
wb_fault wb_shape_match_def_fault(const wb_shape_match_def *def);
/* a cluster of n >= 2 distinct particles, some with mass, their rest shape as they are now;
 * returns its index (clusters are never removed) or a negative wb_status */
int32_t wb_shape_match_add(wb_world *w, const int32_t *ids, int32_t n, const wb_shape_match_def *def);
int32_t wb_shape_match_count(const wb_world *w);
wb_shape_match_def wb_shape_match_get_def(const wb_world *w, int32_t s);
int32_t wb_shape_match_size(const wb_world *w, int32_t s);    /* particles in it */
int32_t wb_shape_match_particle(const wb_world *w, int32_t s, int32_t i); /* its i-th particle */
/* sqrt(sum m |x - goal|^2 / sum m |rest|^2) now: the strain that `yield` is compared with */
wb_real wb_shape_match_strain(const wb_world *w, int32_t s);
/* its i-th particle's rest position about the rest mass centre (plastic flow moves it) */
void wb_shape_match_rest(const wb_world *w, int32_t s, int32_t i, wb_real out[3]);

/* ---- pressure (pressure.c): a closed surface keeps pressure x its rest volume ------------- */
typedef struct wb_pressure_def {
    wb_real pressure;     /* target volume / rest volume, > 0, default 1 */
    wb_real compliance;   /* XPBD compliance of C = V - pressure V0, m^6/J (U = C^2 / 2 alpha); 0 = hard */
} wb_pressure_def;

wb_pressure_def wb_pressure_default_def(void);
const char *wb_pressure_def_check(const wb_pressure_def *def);
/* the options' fault as wb_pressure_def_check finds it, by key (wb_fault) */
wb_fault wb_pressure_def_fault(const wb_pressure_def *def);
/* the first surface whose corners all lie in the body's particles; -1 when none */
int32_t wb_body_surface(const wb_world *w, wb_body b);
/* over surface s, which must be closed (every edge shared by exactly two triangles,
 * consistently oriented) and enclose a positive volume (outward facing); its rest
 * volume is the one now. Returns its index or a negative wb_status (WB_ERR_ARG: see
 * wb_last_error) */
int32_t wb_pressure_add(wb_world *w, int32_t surface, const wb_pressure_def *def);
int32_t wb_pressure_count(const wb_world *w);
wb_pressure_def wb_pressure_get_def(const wb_world *w, int32_t i);
void wb_pressure_set(wb_world *w, int32_t i, wb_real pressure); /* pressure > 0, finite */
wb_real wb_pressure_volume(const wb_world *w, int32_t i);      /* enclosed now, m^3 */
wb_real wb_pressure_rest_volume(const wb_world *w, int32_t i); /* V0, m^3 */
int32_t wb_pressure_surface(const wb_world *w, int32_t i);

/* ---- attachments and grabs (attach.c, grab.c) -------------------------------------------- */
/* XPBD constraints C = x_p - target (a vector, zero rest length): compliance alpha in m/N
 * (0 = exactly there at the end of every substep; else a spring of stiffness 1/alpha,
 * F = -C/alpha, U = |C|^2 / (2 alpha)). force() is the force on the particle, lambda/h^2
 * of the last substep, pointing to the target; it returns |F|. */
typedef struct wb_attach_id { uint32_t index; uint32_t gen; } wb_attach_id;
typedef struct wb_grab_id { uint32_t index; uint32_t gen; } wb_grab_id;
/* their option as the core decides it (wb_fault by key): a compliance, finite and >= 0;
 * attach.c and grab.c each say it for their own (the particle, target and pose are the
 * caller's to check, as it numbers them) */
wb_fault wb_attach_def_fault(wb_real compliance);
wb_fault wb_grab_def_fault(wb_real compliance);

/* particle p kept where it is now in collider c's frame: it rides the collider as the
 * collider moves and turns, and no longer collides with it */
wb_attach_id wb_attach_collider(wb_world *w, int32_t p, wb_collider_id c, wb_real compliance, wb_status *status);
bool wb_attach_valid(const wb_world *w, wb_attach_id a);          /* live, its collider too */
void wb_attach_remove(wb_world *w, wb_attach_id a);
wb_real wb_attach_force(const wb_world *w, wb_attach_id a, wb_real f[3]); /* f may be NULL */
int32_t wb_attach_particle(const wb_world *w, wb_attach_id a);
void wb_attach_point(const wb_world *w, wb_attach_id a, wb_real out[3]); /* its target now, world */
wb_real wb_attach_compliance(const wb_world *w, wb_attach_id a);
int32_t wb_attach_count(const wb_world *w);                        /* live ones */
wb_attach_id wb_attach_at(const wb_world *w, int32_t i);           /* i-th live, slot order */
/* the live ones in slot order into out (at most cap of them); returns how many there are
 * (wb_attach_at in a loop is quadratic) */
int32_t wb_attach_list(const wb_world *w, wb_attach_id *out, int32_t cap);

/* particle p pulled to target; the pose moved between steps is swept to over the next step */
wb_grab_id wb_grab_add(wb_world *w, int32_t p, const wb_real target[3], wb_real compliance, wb_status *status);
bool wb_grab_valid(const wb_world *w, wb_grab_id g);
void wb_grab_release(wb_world *w, wb_grab_id g);
void wb_grab_move(wb_world *w, wb_grab_id g, const wb_real target[3]); /* finite */
void wb_grab_target(const wb_world *w, wb_grab_id g, wb_real out[3]);
wb_real wb_grab_force(const wb_world *w, wb_grab_id g, wb_real f[3]);   /* f may be NULL */
int32_t wb_grab_particle(const wb_world *w, wb_grab_id g);
wb_real wb_grab_compliance(const wb_world *w, wb_grab_id g);
int32_t wb_grab_count(const wb_world *w);
wb_grab_id wb_grab_at(const wb_world *w, int32_t i);
int32_t wb_grab_list(const wb_world *w, wb_grab_id *out, int32_t cap); /* as wb_attach_list */

/* ---- rigid bodies (rigid.c): XPBD rigid bodies (Müller et al. 2020) ------------------- */
#define WB_MAX_RIGIDS (1 << 20)
typedef struct wb_rigid_id { uint32_t index; uint32_t gen; } wb_rigid_id; /* odd gen = live */
typedef struct wb_rigid_def {
    wb_shape shape;               /* WB_SHAPE_SPHERE, WB_SHAPE_BOX or WB_SHAPE_CAPSULE */
    wb_real radius;               /* sphere, capsule */
    wb_real half[3];              /* box half extents */
    wb_real a[3], b[3];           /* capsule segment in the body frame (its midpoint is the
                                   * centre of mass: a and b are taken about it) */
    wb_real mass;                 /* kg, > 0 */
    wb_real pos[3];               /* centre of mass */
    wb_real rotation[4];          /* (w,x,y,z), normalised on add */
    wb_real vel[3], angular_velocity[3]; /* m/s, rad/s (world frame) */
    wb_real friction;             /* Coulomb, static = dynamic; a contact takes the larger of two */
    wb_real restitution;          /* 0..1; a contact takes the larger of two */
} wb_rigid_def;

wb_rigid_def wb_rigid_default_def(wb_shape shape);           /* unit-ish, mass 1, at the origin */
const char *wb_rigid_def_check(const wb_rigid_def *def);     /* NULL or what is wrong */
wb_rigid_id wb_rigid_add(wb_world *w, const wb_rigid_def *def, wb_status *status);
bool wb_rigid_valid(const wb_world *w, wb_rigid_id r);
void wb_rigid_remove(wb_world *w, wb_rigid_id r);
int32_t wb_rigid_count(const wb_world *w);                   /* live bodies */
wb_rigid_id wb_rigid_at(const wb_world *w, int32_t i);       /* 0 <= i < count, slot order */
/* the live bodies' ids in slot order, at most cap, in one pass (wb_rigid_at each is n^2);
 * returns how many were written (rigid_image.c) */
int32_t wb_rigid_list(const wb_world *w, wb_rigid_id *out, int32_t cap);
void wb_rigid_get_def(const wb_world *w, wb_rigid_id r, wb_rigid_def *out); /* shape + state now */
/* the body's solids as wb_collider_solids; the radius of a ball about its centre of mass
 * holding it */
int wb_rigid_solids(const wb_world *w, wb_rigid_id r, wb_solid out[WB_MAX_SOLIDS]);
wb_real wb_rigid_bound(const wb_world *w, wb_rigid_id r);
void wb_rigid_position(const wb_world *w, wb_rigid_id r, wb_real out[3]);
void wb_rigid_rotation(const wb_world *w, wb_rigid_id r, wb_real out[4]);
void wb_rigid_velocity(const wb_world *w, wb_rigid_id r, wb_real out[3]);
void wb_rigid_angular_velocity(const wb_world *w, wb_rigid_id r, wb_real out[3]);
wb_real wb_rigid_mass(const wb_world *w, wb_rigid_id r);
/* setters take finite values (asserted; the binding checks) */
void wb_rigid_set_position(wb_world *w, wb_rigid_id r, const wb_real p[3]);
void wb_rigid_set_rotation(wb_world *w, wb_rigid_id r, const wb_real q[4]); /* normalised; not zero */
void wb_rigid_set_velocity(wb_world *w, wb_rigid_id r, const wb_real v[3]);
void wb_rigid_set_angular_velocity(wb_world *w, wb_rigid_id r, const wb_real om[3]);
/* an impulse J (N s) at world point `at` (NULL: the centre): v += J/m, om += I^-1 (r x J) */
void wb_rigid_apply_impulse(wb_world *w, wb_rigid_id r, const wb_real J[3], const wb_real at[3]);

/* grabs of rigid bodies (grab.c): the body's point `local` (its frame; NULL = the centre
 * of mass) pulled to target, two-way through the body's response at the point. The grab's
 * other functions are wb_grab_*'s; wb_grab_particle gives -1 for one. Removing the body
 * ends its grabs. */
wb_grab_id wb_grab_rigid(wb_world *w, wb_rigid_id r, const wb_real local[3], const wb_real target[3],
                         wb_real compliance, wb_status *status);
wb_rigid_id wb_grab_body(const wb_world *w, wb_grab_id g);           /* {0, 0}: a particle's grab */
void wb_grab_local(const wb_world *w, wb_grab_id g, wb_real out[3]);  /* the body point, its frame */
void wb_grab_point(const wb_world *w, wb_grab_id g, wb_real out[3]);  /* the grabbed point now, world */

/* its surface's signed distance from p (negative inside) */
wb_real wb_rigid_distance(const wb_world *w, wb_rigid_id r, const wb_real p[3]);
/* particle p kept where it is now in body r's frame (attach.c; see wb_attach_collider): the
 * correction moves the body too, so the particle pulls it back (a ball on a rope) */
wb_attach_id wb_attach_rigid(wb_world *w, int32_t p, wb_rigid_id r, wb_real compliance, wb_status *status);
/* particle-rigid contacts that corrected positions in the last substep (rigid_particle.c) */
typedef struct wb_rigid_contact {
    int32_t particle;     /* 0-based */
    wb_rigid_id body;
    wb_real normal[3];    /* unit, out of the body */
    wb_real depth;        /* overlap corrected, m */
    wb_real force;        /* normal force, N (the multiplier over h^2) */
} wb_rigid_contact;
int32_t wb_world_rigid_contact_count(const wb_world *w);
wb_rigid_contact wb_world_rigid_contact_at(const wb_world *w, int32_t i);

/* ---- material presets (material.c) -------------------------------------------------------
 * Named measured materials (docs/physics.md, "Material presets", gives the sources):
 * builders take their figures as the defaults of young, poisson, mass (density x volume),
 * damping, friction */
typedef struct wb_material {
    const char *name;     /* lower_snake: "rubber", "jelly", "foam", "cloth", "leather", "steel_cable" */
    wb_real young;        /* Young's modulus, Pa */
    wb_real poisson;      /* Poisson's ratio */
    wb_real density;      /* kg/m^3 */
    wb_real viscosity;    /* Kelvin-Voigt damping, Pa s (stress = E strain + viscosity strain rate) */
    wb_real friction;     /* Coulomb coefficient of its particles' contacts */
    wb_real thickness;    /* m: a sheet's thickness (cloth), a rope's diameter (rope) */
} wb_material;
int32_t wb_material_count(void);
const wb_material *wb_material_at(int32_t i);                 /* NULL out of [0, count) */
const wb_material *wb_material_preset(const char *name);      /* NULL for an unknown name */

#endif
