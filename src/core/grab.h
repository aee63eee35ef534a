/* grab.h: grabs (grab.c): a particle, or a point fixed in a rigid body, pulled to a point
 * the script moves (the mouse drag of a live viewer). Slots live while gen is odd. */
#ifndef WB_GRAB_H
#define WB_GRAB_H

#include <stdlib.h>

#include "core.h"
#include "rigid.h"

enum { WB_GRAB_PARTICLE = 0, WB_GRAB_RIGID = 1 };

/* a snapshot image's grabs (snapshot.h): the live ones, in slot order */
typedef struct wb_image_grab {
    int32_t n;
    int32_t *p;            /* (n) particle, or the rigid slot (kind 1) */
    int32_t *kind;         /* (n) 0 = particle, 1 = rigid body */
    wb_real *local;        /* (n x 3) a body's grabbed point in its frame (kind 1) */
    wb_real *target, *from; /* (n x 3) target now, and where the next step's sweep starts */
    wb_real *alpha;        /* (n) compliance, m/N */
} wb_image_grab;
struct wb_image;
/* the image's grab arrays for n of them (zeroed), after wb_image_alloc; WB_ERR_NOMEM */
wb_status wb_image_alloc_grab(struct wb_image *g, int32_t n);

/* w->grab: NULL until the first grab */
typedef struct wb_grabs {
    int32_t n, cap, nlive;  /* slots, capacity, live ones */
    int32_t *p;             /* (n) model: particle, or the body's slot (kind WB_GRAB_RIGID) */
    uint8_t *kind;          /* (n) model: WB_GRAB_* */
    uint32_t *tgen;         /* (n) model: the body's generation when grabbed */
    wb_real *local;         /* (n x 3) model: the grabbed point in the body's frame */
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

/* slot s is live and, for a rigid body's grab, the body still is (a removed body leaves
 * its grabs inert until the next step's prepare retires them; the hash and images skip them) */
/* the fastest a grab's target moves over a frame of dt (from where it was to where the
 * script put it), m/s; 0 with none (solver.c's bound on the frame's speeds) */
wb_real wb__grab_speed(const wb_world *w, wb_real dt);

static inline int wb__grab_active(const wb_world *w, const wb_grabs *g, int32_t s)
{
    if (!(g->gen[s] & 1u)) return 0;
    if (g->kind[s] != WB_GRAB_RIGID) return 1;
    const int32_t r = g->p[s];
    return w->rb && r >= 0 && r < w->rb->n && w->rb->gen[r] == g->tgen[s];
}

wb_status wb__grab_reserve(wb_world *w, int64_t extra);
/* kind WB_GRAB_RIGID: p is the body's slot, local the point in its frame (else NULL) */
void wb__grab_put(wb_world *w, int32_t p, int kind, const wb_real local[3], const wb_real target[3],
                  const wb_real from[3], wb_real alpha);
#endif
