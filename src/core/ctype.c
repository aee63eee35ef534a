/* ctype.c: the tables of constraint types (ctype.h). A file of its own because the step
 * (solver.c), the contact rules (broadphase.c), the teardown (destroy.c), the hash
 * (query.c) and the snapshots (snapshot.c) all walk them. */
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
    &wb__tether_type, /* last: the pull the links and the rest left a long chain short of */
};
const int wb__nctypes = (int)(sizeof wb__ctypes / sizeof wb__ctypes[0]);

/* the order w:hash() has always fed the types in (query.c): saved hashes compare only
 * while it stays, so it is not the projection order. NULL: the colliders' poses */
const wb_ctype *const wb__ctypes_hashed[] = {
    &wb__distance_type,
    NULL,
    &wb__bend_type,
    &wb__shape_type,
    &wb__pressure_type,
    &wb__volume_type,
    &wb__tet_type,
    &wb__attach_type,
    &wb__grab_type,
    &wb__tether_type,
};
_Static_assert(sizeof wb__ctypes_hashed / sizeof wb__ctypes_hashed[0] == sizeof wb__ctypes / sizeof wb__ctypes[0] + 1,
               "every type has its place in the hash");

/* the types the VBD solver minimises itself (wb_ctype.vbd), in the order its vertex step
 * adds their forces and Hessians (vbd.c): a VBD world's bits depend on it, so it is not
 * the projection order either */
const wb_ctype *const wb__vbd_ctypes[] = {
    &wb__distance_type,
    &wb__tet_type,
    &wb__bend_type,
};
const int wb__vbd_nctypes = (int)(sizeof wb__vbd_ctypes / sizeof wb__vbd_ctypes[0]);
