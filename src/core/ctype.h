/* ctype.h: the constraint-type table, so the step need not know each type. One file per
 * type in src/core/; the step walks wb__ctypes[] in order. */
#ifndef WB_CTYPE_H
#define WB_CTYPE_H
#include "core.h"

typedef void (*wb_link_fn)(void *ud, int32_t a, int32_t b, int joined);

typedef struct wb_ctype {
    const char *name;                                  /* "distance", "bend", "volume", ... */
    int32_t (*count)(const wb_world *w);               /* live constraints of the type */
    wb_status (*prepare)(wb_world *w);                 /* once per step, before the substeps:
                                                          (re)pack and colour when dirty */
    void (*substep_begin)(wb_world *w);                /* each substep: multipliers to zero */
    void (*project)(wb_world *w, wb_real h);           /* one iteration over all of them */
    void (*frame_end)(wb_world *w);                    /* once per frame after the substeps
                                                          (plastic flow, breaking); may be NULL */
    wb_real (*energy)(const wb_world *w);              /* elastic potential energy, J; may be NULL */
    /* the particle pairs its constraints join, for the contact rules (broadphase.c): each
     * through fn(ud, a, b, joined); joined = 1: a and b never touch (rest neighbours:
     * docs/physics.md, "Contacts"); 0: they are one graph only (a cluster's chain).
     * May be NULL: none */
    void (*links)(const wb_world *w, wb_link_fn fn, void *ud);
} wb_ctype;

/* the links of n elements of four particles each (q: n x 4): every pair of an element's
 * corners is joined (a bend's hinge and wings, a tet's or volume's edges) */
static inline void wb__link_quads(const int32_t *q, int32_t n, wb_link_fn fn, void *ud)
{
    for (int32_t e = 0; e < n; e++)
        for (int a = 0; a < 3; a++)
            for (int b = a + 1; b < 4; b++) fn(ud, q[4 * e + a], q[4 * e + b], 1);
}

extern const wb_ctype wb__distance_type, wb__bend_type, wb__volume_type,
                      wb__shape_type, wb__pressure_type, wb__tet_type;
extern const wb_ctype wb__attach_type, wb__grab_type; /* attach.c, grab.c */

/* the table the step walks (solver.c), in projection order, and its length */
extern const wb_ctype *const wb__ctypes[];
extern const int wb__nctypes;
#endif
