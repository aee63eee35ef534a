/* vbd.h: the Vertex Block Descent solver (solver = "vbd"; vbd.c) */
#ifndef WB_VBD_H
#define WB_VBD_H
#include "ctype.h"

/* `iterations` sweeps of per-vertex Newton steps over the types it serves (the others
 * are projected as in XPBD after each sweep; fewer once the last sweep's largest step is
 * at most the tolerance); returns that step, the residual (m), or -1 */
wb_real wb__vbd_solve(wb_world *w, wb_real h);
/* the types the solver minimises as energies itself */
int wb__vbd_serves(const wb_ctype *t);
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

#endif
