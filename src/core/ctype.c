/* ctype.c: the table of constraint types (ctype.h). It is a file of its own because the
 * step (solver.c) and the contact rules (broadphase.c) both walk it. */
#include "ctype.h"

/* the constraint types the step walks, in projection order (ctype.h; docs/architecture.md,
 * "The constraint-type table"): adding a type adds its line here. */
const wb_ctype *const wb__ctypes[] = {
    &wb__distance_type,
    &wb__bend_type,
    &wb__volume_type,
    &wb__tet_type,
    &wb__shape_type,
    &wb__pressure_type,
    &wb__attach_type,
    &wb__grab_type,
};
const int wb__nctypes = (int)(sizeof wb__ctypes / sizeof wb__ctypes[0]);
