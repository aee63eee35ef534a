/* attach.h: attachments (attach.c): a particle kept at a point fixed in a target's frame.
 *
 * The target is a tagged union {kind, index, gen}: a kinematic collider (it carries the
 * particle) or a rigid body (rigid.h: the correction moves the body too, so the particle
 * pulls it back). Slots live while gen is odd, like colliders'. */
#ifndef WB_ATTACH_H
#define WB_ATTACH_H

#include <stdlib.h>

#include "core.h"
#include "rigid.h"

enum { WB_TARGET_COLLIDER = 0, WB_TARGET_RIGID = 1 };

/* a snapshot image's attachments (snapshot.h): the live ones, in slot order */
typedef struct wb_image_attach {
    int32_t n;
    int32_t *p;            /* (n) particle */
    int32_t *kind;         /* (n) target kind: 0 = collider */
    int32_t *target;       /* (n) the target's slot (a live collider slot of the image) */
    wb_real *local;        /* (n x 3) the point in the target's frame */
    wb_real *alpha;        /* (n) compliance, m/N */
} wb_image_attach;
struct wb_image;
/* the image's attachment arrays for n of them (zeroed), after wb_image_alloc; WB_ERR_NOMEM */
wb_status wb_image_alloc_attach(struct wb_image *g, int32_t n);

/* w->att: NULL until the first attachment */
typedef struct wb_attaches {
    int32_t n, cap, nlive;  /* slots, capacity, live ones */
    /* model */
    int32_t *p;             /* (n) particle */
    uint8_t *kind;          /* (n) WB_TARGET_* */
    int32_t *tindex;        /* (n) target slot (0-based) */
    uint32_t *tgen;         /* (n) target generation when attached */
    wb_real *local;         /* (n x 3) the point in the target's frame */
    wb_real *alpha;         /* (n) compliance, m/N */
    uint32_t *gen;          /* (n) odd = live */
    /* cache */
    wb_real *lambda;        /* (n x 3) multipliers of the current substep (vector: C = x - target) */
    int32_t sub;            /* substeps begun in this step: the target's pose is the one at sub/substeps */
    size_t charged;         /* bytes charged to def.memory */
    /* particle -> colliders it is attached to (CSR, rebuilt by prepare when dirty): the
     * particle-collider contact of such a pair is skipped (collide.c) */
    int dirty;
    int32_t skip_np;        /* particles when it was built; 0 = no skips */
    int32_t *skip_start;    /* (skip_np + 1) */
    int32_t *skip_col;      /* collider slots */
    int32_t cap_start, cap_col;
    size_t skip_charged;    /* the skip table's bytes charged to def.memory (4 a particle) */
    int32_t free_hint;      /* no dead slot below it: a new attachment's search starts there */
} wb_attaches;

/* slot s is live and its target still exists (a removed collider leaves its attachments
 * inert until the next step's prepare retires them; the hash and images skip them) */
static inline int wb__attach_active(const wb_world *w, const wb_attaches *a, int32_t s)
{
    if (!(a->gen[s] & 1u)) return 0;
    const int32_t t = a->tindex[s];
    if (a->kind[s] == WB_TARGET_RIGID) return w->rb && t >= 0 && t < w->rb->n && w->rb->gen[t] == a->tgen[s];
    return t >= 0 && t < w->m.nc && w->m.c_gen[t] == a->tgen[s];
}

/* the skip table below when a particle is attached (NULL: none; collide.c and
 * rigid_particle.c, whose contacts with what a particle is attached to are skipped) */
static inline const wb_attaches *wb__attach_skips(const wb_world *w) { return w->att && w->att->skip_np > 0 ? w->att : NULL; }

/* collide.c: is particle i attached to collider slot c (no contact between them)? The
 * table holds collider slots c >= 0 and rigid bodies r as -1 - r */
static inline int wb__attach_skip(const wb_attaches *a, int32_t i, int32_t c)
{
    if (i >= a->skip_np) return 0;
    for (int32_t k = a->skip_start[i]; k < a->skip_start[i + 1]; k++)
        if (a->skip_col[k] == c) return 1;
    return 0;
}

/* snapshot.c: room for `extra` more (charged), then put one (cannot fail after reserving) */
wb_status wb__attach_reserve(wb_world *w, int64_t extra);
void wb__attach_put(wb_world *w, int32_t p, int kind, int32_t tindex, uint32_t tgen, const wb_real local[3],
                    wb_real alpha);
#endif
