/* ctype.h: the constraint-type table (DESIGN.md §2). One file per type in src/core/;
 * the step walks wb__ctypes[] in order. */
#ifndef WB_CTYPE_H
#define WB_CTYPE_H
#include "core.h"

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
} wb_ctype;

extern const wb_ctype wb__distance_type, wb__bend_type, wb__volume_type,
                      wb__shape_type, wb__pressure_type, wb__tet_type;
extern const wb_ctype wb__attach_type, wb__grab_type; /* attach.c, grab.c (issue 10) */

/* the table the step walks (solver.c), in projection order, and its length */
extern const wb_ctype *const wb__ctypes[];
extern const int wb__nctypes;
#endif
