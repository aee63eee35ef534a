/* snapshot.h: a world as flat arrays (an "image"), for the JSON reader and writer and for
 * exact copies. Internal: it shows the slot layout (generations, free lists), which the
 * public API hides behind handles. Everything here is plain data over public types, so
 * io/json.c needs no core internals. */
#ifndef WB_SNAPSHOT_H
#define WB_SNAPSHOT_H

#include "wobble.h"
/* the constraint types' own sections of an image, declared by their owners */
#include "attach.h"
#include "bend.h"
#include "distance.h"
#include "grab.h"
#include "pressure.h"
#include "shape_match.h"
#include "tet.h"
#include "tether.h"
#include "volume.h"

/* a collider: its shape in its own frame and its full pose */
typedef struct wb_image_collider {
    wb_shape shape;
    wb_real n[3];          /* plane: unit normal in the collider frame */
    wb_real radius;        /* sphere, capsule */
    wb_real half[3];       /* box */
    wb_real a[3], b[3];    /* capsule segment in the collider frame */
    wb_real friction, restitution;
    wb_real p[3], q[4];    /* pose now */
    wb_real p0[3], q0[4];  /* pose at the end of the last step: start of the next sweep */
    wb_real v[3], om[3];   /* velocities the script set */
    int32_t mnv, mnt;      /* mesh: vertex and triangle counts */
    wb_real *mv;           /* mesh: (mnv x 3) vertices in the collider frame (malloc'd, the image owns it) */
    int32_t *mt;           /* mesh: (mnt x 3) corners (malloc'd, the image owns it) */
} wb_image_collider;

/* a rigid body (rigid.c): its shape in its own frame, mass, pose and velocities, raw (a
 * capsule's a and b about its centre of mass, the rotation unit) */
typedef struct wb_image_rigid {
    wb_shape shape;
    wb_real radius, half[3], a[3], b[3];
    wb_real friction, restitution, mass;
    wb_real x[3], q[4], v[3], om[3];
} wb_image_rigid;

typedef struct wb_image {
    wb_world_def def;

    int32_t np;
    wb_real *x, *v;        /* (np x 3) */
    wb_real *inv_mass;     /* (np) as created; 0 = immovable */
    wb_real *radius;       /* (np) */
    uint8_t *pinned;       /* (np) */
    int32_t *group;        /* (np) contact group, 0 = loose */
    uint8_t *cflags;       /* (np) bit 0: collide, bit 1: self-collide */
    wb_real *cfric;        /* (np) contact friction */
    wb_real *x0;           /* (np x 3) where created (the self-collision rest rule) */

    wb_image_distance dist; /* distance.h */

    wb_image_bend bend;    /* bend.h: empty unless wb_image_alloc_bends */

    int32_t nc;
    wb_image_collider *c;  /* (nc) by slot */
    uint32_t *c_gen;       /* (nc) odd = live */

    int32_t nsurf;
    int32_t *surf_start;   /* (nsurf + 1) */
    int32_t ntri;
    int32_t *tri;          /* (ntri x 3) */

    double time;
    int64_t frame, warnings;
    char last_warning[160];

    wb_image_volume vol;   /* volume.h: empty unless wb_image_alloc_volumes */
    wb_image_tet tet;      /* tet.h: empty unless wb_image_alloc_tets */
    wb_image_smatch sm;    /* shape_match.h: empty unless wb_image_alloc_smatch */
    wb_image_pressure pr;  /* pressure.h: empty unless wb_image_alloc_pressure */
    wb_image_attach att;   /* attach.h: empty unless wb_image_alloc_attach */
    wb_image_grab grab;    /* grab.h: empty unless wb_image_alloc_grab */
    wb_image_tether teth;  /* tether.h: empty unless wb_image_alloc_tethers */
    int32_t nrb;           /* rigid bodies by slot: empty unless wb_image_alloc_rigids */
    wb_image_rigid *rb;    /* (nrb) */
    uint32_t *rb_gen;      /* (nrb) odd = live */
    /* the VBD solver's multipliers (vbd.c; each half saved and put by its type's VBD hooks,
     * distance.c and bend.c), what its next substep starts from: empty (0, 0) in an XPBD
     * world or a VBD world that has not stepped */
    int32_t vbd_nd, vbd_nb;
    wb_real *vbd_lam, *vbd_c0;   /* (vbd_nd) by distance slot: a rigid link's multiplier and its
                                    error as the last sweep left it (NaN: not known) */
    wb_real *vbd_blam, *vbd_bc0; /* (vbd_nb) the same of each rigid bend */
} wb_image;
/* the image has a VBD section (either half) */
static inline int wb__image_has_vbd(const wb_image *g) { return g->vbd_nd || g->vbd_nb; }
/* vbd.c: the VBD section for nd distance slots and nb bends (uninitialised); WB_ERR_NOMEM
 * (the section left empty) */
wb_status wb_image_alloc_vbd(wb_image *img, int32_t nd, int32_t nb);
/* vbd.c: the section above (free: fine when empty; put: into a world just made from the
 * image, before its first step; check: NULL or what is wrong) */
wb_status wb__vbd_image_of(const wb_world *w, wb_image *g);
void wb__vbd_image_free(wb_image *g);
const char *wb__vbd_image_check(const wb_image *g);
wb_status wb__vbd_image_put(wb_world *w, const wb_image *g);

/* allocate the arrays for these counts (zeroed; generations 1, i.e. live; particles collide);
 * WB_ERR_NOMEM */
wb_status wb_image_alloc(wb_image *img, int32_t np, int32_t nd, int32_t nfree, int32_t nc, int32_t nsurf, int32_t ntri);
/* distance.c: the distance section for nd slots (generations 1) and nfree free ones (zeroed);
 * WB_ERR_NOMEM (the section left empty) */
wb_status wb_image_alloc_distances(wb_image *img, int32_t nd, int32_t nfree);
/* bend.c: the bend arrays for nb bends (zeroed), after wb_image_alloc; WB_ERR_NOMEM (the
 * section left empty) */
wb_status wb_image_alloc_bends(wb_image *img, int32_t nb);
/* the volume constraints' arrays for n of them (zeroed; volume.c); WB_ERR_NOMEM */
wb_status wb_image_alloc_volumes(wb_image *img, int32_t n);
/* the Neo-Hookean tets' arrays for n of them (zeroed; tet.c); WB_ERR_NOMEM */
wb_status wb_image_alloc_tets(wb_image *img, int32_t n);
/* the materials' sections (after wb_image_alloc; zeroed, rotations identity; shape_match.c,
 * pressure.c); WB_ERR_NOMEM */
wb_status wb_image_alloc_smatch(wb_image *img, int32_t n, int32_t nids);
wb_status wb_image_alloc_pressure(wb_image *img, int32_t n);
void wb_image_free(wb_image *img);                     /* and zero it (mesh colliders' arrays too); fine on a zeroed image */
wb_status wb_image_of(const wb_world *w, wb_image *img); /* a full copy of the world */
/* NULL, or what is inconsistent (an index out of range, a free list that does not match
 * the dead slots, a non-finite value, ...): a reader's last line of defence */
const char *wb_image_check(const wb_image *img);
/* the world the image describes, exactly (same hash, same future); NULL with *status */
wb_world *wb_world_from_image(const wb_image *img, wb_status *status);
/* add the image's particles, live constraints, live colliders and surfaces to w, ids
 * shifted after w's particles; all or nothing. out: the new particles' range */
wb_status wb_world_append_image(wb_world *w, const wb_image *img, wb_body *out);
/* the collider w:collider{...} would make from a world-frame def, in its own frame + pose */
wb_status wb_image_collider_from_def(const wb_collider_def *d, wb_image_collider *out);
/* a collider's shape fields in its own frame as its shape's file judges them (wb_image_check
 * asks it too): NULL, or what is wrong */
const char *wb_image_collider_shape_check(const wb_image_collider *c);

/* Each constraint type's part of the functions above (save, check, put) is its own,
 * reached through its hooks (ctype.h) */

/* rigid bodies (rigid_image.c): n slots, zeroed, generations 1 (live); WB_ERR_NOMEM */
wb_status wb_image_alloc_rigids(wb_image *img, int32_t n);
/* the body w:rigid{...} would make from a def (checked by wb_rigid_def_check): WB_ERR_ARG */
wb_status wb_image_rigid_from_def(const wb_rigid_def *d, wb_image_rigid *out);
/* a live body as a snapshot holds it (unit rotation, capsule about its centre): NULL or why not */
const char *wb_image_rigid_check(const wb_image_rigid *o);
void wb__rigid_image_free(wb_image *g);
wb_status wb__rigid_image_of(const wb_world *w, wb_image *g);
const char *wb__rigid_image_check(const wb_image *g);
/* room for the image's bodies in w: exact (a new world: the image's slots as they are)
 * or appended (its live bodies into free or new slots) */
wb_status wb__rigid_reserve(wb_world *w, const wb_image *g, int exact);
/* map (nrb, may be NULL): where each image slot went (-1: a dead one) */
void wb__rigid_put(wb_world *w, const wb_image *g, int exact, int32_t *map);

#endif
