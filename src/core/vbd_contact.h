/* vbd_contact.h: the particle contacts as energies in VBD's vertex steps (vbd_contact.c) */
#ifndef WB_VBD_CONTACT_H
#define WB_VBD_CONTACT_H
#include "core.h"

typedef struct wb_vbdc wb_vbdc;

/* a candidate whose ends are closer than this times r_i + r_j at the sweeps' start is in
 * the substep's contacts (the ones farther apart are left to the projection after); so is
 * a body near an immovable particle (vbd.c's touching()) */
#define WB_VBDC_NEAR ((wb_real)1.25)

/* Once a substep, after the sweeps' start: the frame's candidate pairs near enough to
 * touch during it and the vertices near a collider (not a mesh; t0, t1: the substep's
 * start and end in the frame, where the colliders are), each vertex's list of them, and
 * the copy its partners are read from.
 * order / colour_start / ncolours: the sweep's vertices by colour, vcol (np) each one's
 * colour (a pair of two movable ends of one colour steps both at once), held (np) 1 for a vertex a served constraint holds (the others
 * have nothing in the sweeps to fight a collider: theirs stay the projection's). Returns 1 when it holds
 * pairs (then call the others; maybe none in the vertex steps, all of them between bodies
 * moved together), 0 when none, -1 when out of memory (the contacts after the sweeps
 * still hold). *c is made on first use. bmoved (bodies, may be NULL): 1 for a body whose
 * friction its momentum step takes (wb__vbdc_body), not the vertex steps; bvar (bodies,
 * may be NULL): a body's index among those moved together (wb__vbdc_couple), -1 none. */
int wb__vbdc_begin(wb_world *w, wb_vbdc **c, wb_real h, wb_real t0, wb_real t1, const int32_t *order,
                   const int32_t *colour_start, int32_t ncolours, const uint8_t *vcol, const uint8_t *held,
                   const uint8_t *bmoved, const int32_t *bvar);
/* vertex i's contact forces and their Hessian added to f and H (H: xx, yy, zz, xy, xz, yz) */
void wb__vbdc_block(const wb_world *w, const wb_vbdc *c, int32_t i, wb_real f[3], wb_real H[6]);
/* after vertex i's Newton step to xi (H: its Hessian): its friction with its partners */
void wb__vbdc_friction(const wb_world *w, const wb_vbdc *c, int32_t i, const wb_real H[6], wb_real xi[3]);
/* vertex i's contact forces after the sweeps (the multipliers before the last update),
 * moved by sh, without friction, added to f and H; unless fr is NULL, fr[0] += its
 * friction's capacity, sum mu f_n (the lagged forces), fr[1..3] += sum f_n n (the
 * direction they push it): a body's momentum step's. Its self-contacts (a movable
 * partner) are left out: the body's move does not change them. 1 when it has others */
int wb__vbdc_body(const wb_world *w, const wb_vbdc *c, int32_t i, const wb_real sh[3], wb_real f[3], wb_real H[6],
                  wb_real *fr);
/* after the sweeps and the momentum step: each pair's force where they left it (the
 * readout's, and the next substep's friction's) */
void wb__vbdc_end(const wb_world *w, wb_vbdc *c);
/* the vertices with contacts this substep (*n of them) */
const int32_t *wb__vbdc_vertices(const wb_vbdc *c, int32_t ncolours, int32_t *n);
/* after colour col's vertices stepped: the copy of their positions brought up to date */
void wb__vbdc_colour_done(const wb_world *w, wb_vbdc *c, int32_t col);
/* after a sweep: each contact's multiplier grown by its penalty times its overlap */
void wb__vbdc_dual(const wb_world *w, wb_vbdc *c);
/* before a sweep after the first: the copy taken again (the types projected after a
 * sweep move vertices) */
void wb__vbdc_refresh(const wb_world *w, wb_vbdc *c, int32_t ncolours);
/* after the contacts' projection (contact.c): their reported forces take in the sweeps' */
void wb__vbdc_readout(wb_world *w, const wb_vbdc *c);
/* The nv bodies moved with their partners (bvar: a body's index among them, -1 none; bs:
 * WB_VBDC_BS doubles each, its mass, mean x - y, centre c, sum m r x (x - y) and
 * inertia sum m (|r|^2 E - r r^T) (xx, yy, zz, xy, xz, yz), r = x - c, after the sweeps)
 * take the Newton steps (at most steps) of the substep's energy along their translations
 * t and small turns th about c with all their pairs and the triangle contacts between them
 * (h: the substep; *c made if need be); u (nv x 6) gets each one's t and th. 1 done, 0
 * singular (u not to be used), -1 out of memory */
#define WB_VBDC_BS 16
int wb__vbdc_couple(wb_world *w, wb_vbdc **c, const int32_t *bvar, int32_t nv, const double *bs, double *u, wb_real h,
                    int32_t steps);
/* A triangle contact candidate k between two bodies: *bp its point's body, *bt its
 * triangle's (its first corner's). 0 when it is not between two bodies (a particle of no
 * body, or one body); else WB_VBDC_TRI | WB_VBDC_MADE when the point and the triangle were
 * made inside each other (contact.c's to part) | WB_VBDC_ONE when the corners are all of
 * bt | WB_VBDC_WHOLE when they are also all movable (the triangle can be moved with bt). */
enum { WB_VBDC_TRI = 1, WB_VBDC_MADE = 2, WB_VBDC_ONE = 4, WB_VBDC_WHOLE = 8 };
int wb__vbdc_tri_kind(const wb_world *w, int32_t k, int32_t *bp, int32_t *bt);
/* (its charge given back) */
void wb__vbdc_destroy(wb_world *w, wb_vbdc *c);

#endif
