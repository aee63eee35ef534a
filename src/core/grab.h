/* grab.h: grabs (grab.c): a particle pulled to a point the script moves (the mouse drag
 * of a live viewer). Slots live while gen is odd. */
#ifndef WB_GRAB_H
#define WB_GRAB_H

#include <stdlib.h>

#include "core.h"

/* w->grab: NULL until the first grab */
typedef struct wb_grabs {
    int32_t n, cap, nlive;  /* slots, capacity, live ones */
    int32_t *p;             /* (n) model: particle */
    wb_real *alpha;         /* (n) model: compliance, m/N */
    uint32_t *gen;          /* (n) odd = live */
    wb_real *target;        /* (n x 3) state: where the script put it */
    wb_real *from;          /* (n x 3) state: the target at the end of the last step; a
                               step sweeps from it to `target` substep by substep, as a
                               collider moves (a far move is no velocity spike) */
    wb_real *lambda;        /* (n x 3) cache: multipliers of the current substep */
    int32_t sub;            /* substeps begun in this step */
    size_t charged;
    int32_t free_hint;      /* no dead slot below it: a new grab's search starts there */
} wb_grabs;

static inline void wb__grab_free(wb_world *w)
{
    wb_grabs *g = w->grab;
    if (!g) return;
    if (w->m.def.memory) w->m.def.memory->used -= g->charged;
    void *p[] = { g->p, g->alpha, g->gen, g->target, g->from, g->lambda };
    for (size_t i = 0; i < sizeof p / sizeof p[0]; i++) free(p[i]);
    free(g);
    w->grab = NULL;
}

wb_status wb__grab_reserve(wb_world *w, int64_t extra);
void wb__grab_put(wb_world *w, int32_t p, const wb_real target[3], const wb_real from[3], wb_real alpha);
#endif
