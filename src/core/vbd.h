/* vbd.h: the Vertex Block Descent solver (solver = "vbd"; vbd.c), and what a constraint type
 * gives it to be minimised in its vertex steps (wb_vbd_type, the type's own file) */
#ifndef WB_VBD_H
#define WB_VBD_H
#include "ctype.h"

/* `iterations` sweeps of per-vertex Newton steps over the types it serves (the others
 * are projected as in XPBD after each sweep; fewer once the last sweep's largest step is
 * at most the tolerance); t0, t1: the substep's start and end in the frame (the
 * colliders' poses); returns that step, the residual (m), or -1 */
wb_real wb__vbd_solve(wb_world *w, wb_real h, wb_real t0, wb_real t1);
/* once per step before the types' prepare: the adjacency and colouring when the topology
 * changed; 0 when out of memory */
int wb__vbd_prepare(wb_world *w);
void wb__vbd_destroy(wb_world *w);
/* an undone frame: the multipliers back as the step found them */
void wb__vbd_undo(wb_world *w);
/* at a substep's end: the particle contacts' readout takes in the sweeps' forces */
void wb__vbd_contacts_done(wb_world *w);
/* 1 when the last wb__vbd_solve ran out of memory (the budget refused its scratch): it
 * did nothing, and the step must undo its frame */
int wb__vbd_failed(const wb_world *w);
/* the last substep's residual: the largest Newton step of its last sweep, m */
wb_real wb__vbd_residual(const wb_world *w);

/* A type the solver minimises as an energy in its vertex steps (wb_ctype.vbd; a type
 * without is projected as in XPBD after each sweep). A constraint of compliance alpha is
 * the energy C^2 / (2 alpha), so a material means the same in both solvers; a hard one
 * (alpha = 0) goes through the augmented Lagrangian (AVBD: vbd.c's header), its multiplier
 * carried from substep to substep. The type keeps its part of the solver's cache (part:
 * its own struct, opaque to vbd.c): what the vertex step reads at each vertex, and the
 * multipliers. The solver calls the types in the order of wb__vbd_ctypes (ctype.c). */
typedef struct wb_vbd_type {
    void *(*make)(void);                            /* an empty part; NULL: out of memory */
    void (*free)(wb_world *w, void *part);          /* frees it and gives back its bytes */
    int32_t (*slots)(const wb_world *w);            /* the constraints a part is built for
                                                       (a different count: rebuilt) */
    /* (re)built for the world's topology (m.np particles, slots(w) constraints): what it
     * holds at each vertex, multipliers for new slots (none, no error known), all charged
     * to def.memory before it is taken; 0 when out of memory */
    int (*build)(wb_world *w, void *part);
    /* the colours (col[j], a bit each) of the vertices j < i its constraints join to i */
    uint64_t (*neighbours)(const wb_world *w, const void *part, int32_t i, const uint8_t *col);
    int (*holds)(const void *part, int32_t i);      /* 1: a constraint of it holds vertex i */
    /* the vertex steps at vert[0 .. n), vertices that share no constraint (one colour's):
     * each one's constraints' force on it and their 3 x 3 Hessian (xx, yy, zz, xy, xz, yz)
     * added into f (n x 3) and H (n x 6), at the positions as they are (a call a run of
     * vertices, not one each: the sweep's per-vertex calls were a sixth of its cost) */
    void (*vertex)(const wb_world *w, const void *part, const int32_t *vert, int32_t n, wb_real inv_h, wb_real *f,
                   wb_real *H);
    /* may be NULL (a type with no multipliers): */
    void (*begin)(wb_world *w, void *part, wb_real h);          /* a substep, before its sweeps */
    void (*dual)(wb_world *w, void *part, wb_real h, int last); /* after each sweep (last: the
                                                                   substep's last) */
    void (*end)(wb_world *w, void *part, wb_real h);            /* after the substep's sweeps:
                                                                   the forces force() reads */
    void (*save)(void *part);                      /* the multipliers as the step starts... */
    void (*undo)(void *part);                      /* ...and back there (an undone frame) */
    /* its half of a snapshot's VBD section (snapshot.h): copy out (stale: the next prepare
     * rebuilds the part), check it (the section present), put it into a part just made */
    wb_status (*image_save)(const wb_world *w, const void *part, wb_image *g, int stale);
    const char *(*image_check)(const wb_image *g);
    wb_status (*image_put)(void *part, const wb_image *g);
} wb_vbd_type;

/* the tools the types' parts share (vbd_part.c) */
/* of a hard constraint's error at the substep's start, the part kept (carried over, a
 * multiplier that also took in the error it had already corrected fed it back as speed:
 * the clamped strip at 40 x 1 swung 0.15 m off its droop at 0.995; all of it corrected, a
 * 1-D chain's modes grew 15% a substep); AVBD's stabilisation */
#define WB_VBD_STAB ((wb_real)0.999)
/* each vertex's elements of four corners (q: n x 4, element e's corner k at 4 e + k), as
 * 4 e + k by vertex: adj[start[i], start[i + 1]) */
typedef struct wb_vbd_quads {
    int32_t *start, *adj;
} wb_vbd_quads;
/* the bytes of a wb_vbd_quads of np vertices and n elements */
size_t wb__vbd_quads_bytes(int32_t np, int32_t n);
/* build it (the old arrays freed); 0 when out of memory (unchanged) */
int wb__vbd_quads_build(wb_vbd_quads *a, int32_t np, const int32_t *q, int32_t n);
void wb__vbd_quads_free(wb_vbd_quads *a);
/* the colours of the corners j < i of the elements at vertex i (the neighbours hook) */
uint64_t wb__vbd_quads_colours(const wb_vbd_quads *a, const int32_t *q, int32_t i, const uint8_t *col);
/* a part's save and undo: its two arrays of n multipliers a and b copied into keep (2 n),
 * or back from it (back = 1; keep NULL: nothing kept yet) */
void wb__vbd_keep(wb_real *keep, wb_real *a, wb_real *b, int32_t n, int back);
/* a type's half of a snapshot's VBD section: n multipliers lam and errors c0 (NaN: not
 * known) for the image's want constraints; NULL, count (n is not want) or what is wrong */
const char *wb__vbd_half_check(int32_t n, int32_t want, const wb_real *lam, const wb_real *c0, const char *count);
static inline int wb__vbd_quads_hold(const wb_vbd_quads *a, int32_t i) { return a->start[i + 1] > a->start[i]; }

#endif
