/* ctype.h: the constraint-type table (docs/architecture.md). One file per type in src/core/;
 * the step walks wb__ctypes[] in order, and so do the world's teardown (destroy.c), its
 * hash (query.c), its snapshots (snapshot.c) and the VBD solver (vbd.c, through wb_ctype.vbd):
 * a type's file is the one place that names its arrays. */
#ifndef WB_CTYPE_H
#define WB_CTYPE_H
#include "core.h"

typedef void (*wb_link_fn)(void *ud, int32_t a, int32_t b, int joined);
typedef struct wb_image wb_image; /* snapshot.h */
typedef struct wb_vbd_type wb_vbd_type; /* vbd.h */

/* where an image's items go in the world they are put into (snapshot.c) */
typedef struct wb_image_at {
    int exact;                  /* 1: a new world, the image's slots as they are; 0: appended */
    int32_t pshift, sshift;     /* added to the image's particle and surface indices */
    const int32_t *cmap, *rmap; /* the image's collider and rigid slots -> the world's (NULL:
                                   the same slots) */
} wb_image_at;

/* FNV-1a over n bytes: w:hash() and each type's part of it */
static inline uint64_t wb__fnv(uint64_t h, const void *p, size_t n)
{
    const unsigned char *b = p;
    for (size_t i = 0; i < n; i++) { h ^= b[i]; h *= 1099511628211ull; }
    return h;
}

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
    /* the particle pairs that make its particles one body (momentum.c: a free body keeps
     * its angular momentum), each through fn(ud, a, b, 1): not always its links (a broken
     * link joins no body but its ends stay rest neighbours; a tether joins none). May be
     * NULL: none */
    void (*joins)(const wb_world *w, wb_link_fn fn, void *ud);
    /* the particles its constraints hold to something outside the particles (a collider, a
     * rigid body, a grab's target), each through fn(ud, p, p): momentum.c's body with one is
     * not free. May be NULL: none */
    void (*anchors)(const wb_world *w, wb_link_fn fn, void *ud);

    /* the world's teardown: free the type's arrays (the world is freed after) */
    void (*destroy)(wb_world *w);
    /* bytes it has charged to def.memory (given back at teardown); may be NULL: its bytes
     * are charged with the particles' */
    size_t (*charged)(const wb_world *w);
    /* its counts in w:stats() (its fields of wb_stats) */
    void (*stats)(const wb_world *w, wb_stats *st);
    /* its part of w:hash(), fed into h: the bytes and order the hash has always had, so
     * that saved hashes still compare (a world without any of the type adds nothing) */
    uint64_t (*hash)(const wb_world *w, uint64_t h);
    /* its section of a snapshot image (snapshot.h): free it (fine when empty), copy the
     * world's into it, check it (the image's particles, colliders, surfaces and rigid
     * bodies already checked: NULL or what is wrong), make room in w for it (adding
     * nothing), then put it (after reserving: cannot fail) */
    void (*image_free)(wb_image *g);
    wb_status (*image_save)(const wb_world *w, wb_image *g);
    const char *(*image_check)(const wb_image *g);
    wb_status (*image_reserve)(wb_world *w, const wb_image *g, const wb_image_at *at);
    void (*image_put)(wb_world *w, const wb_image *g, const wb_image_at *at);
    /* its largest residual at the positions as they are, with the multipliers of the last
     * projection (h: its substep), in metres (wb__residual); may be NULL: none */
    wb_real (*residual)(const wb_world *w, wb_real h);
    /* what the VBD solver minimises of it in its vertex steps (vbd.h); NULL: it is
     * projected as in XPBD after each sweep. A type with it is listed in wb__vbd_ctypes */
    const wb_vbd_type *vbd;
} wb_ctype;

/* every type's largest residual (query.c), for the iterations' early stop (solver.c) */
wb_real wb__residual_all(const wb_world *w, wb_real h);
/* A constraint's residual in metres: what XPBD drives to zero, |C + alpha~ lambda| (C
 * alone for a hard one), over the root mean square of its corners' gradients (g2: the sum
 * of their squares over n corners), so an angle or a volume reads as how far its corners
 * are from meeting it. 0 where it has no direction (a flat tet's volume, coincident ends) */
static inline wb_real wb__residual(wb_real c, wb_real g2, int n)
{
    return g2 > 0 && isfinite(g2) ? fabs(c) / sqrt(g2 / n) : 0;
}

/* the links of n elements of four particles each (q: n x 4): every pair of an element's
 * corners is joined (a bend's hinge and wings, a tet's or volume's edges) */
static inline void wb__link_quads(const int32_t *q, int32_t n, wb_link_fn fn, void *ud)
{
    for (int32_t e = 0; e < n; e++)
        for (int a = 0; a < 3; a++)
            for (int b = a + 1; b < 4; b++) fn(ud, q[4 * e + a], q[4 * e + b], 1);
}

/* a joins hook's pairs for n elements of k particles each (q: n x k): the first with
 * each of the others, enough to make them one body */
static inline void wb__join_elements(const int32_t *q, int32_t n, int k, wb_link_fn fn, void *ud)
{
    for (int32_t e = 0; e < n; e++)
        for (int j = 1; j < k; j++) fn(ud, q[(size_t)k * (size_t)e], q[(size_t)k * (size_t)e + (size_t)j], 1);
}

/* a type's check's faults (wb_fault): an option's, with its key (a string literal), and
 * the particles' (corner: the one at fault, -1: together) */
#define WB_FAULT_KEY(k, why_) ((wb_fault){ k " " why_, k, why_, -1 })
#define WB_FAULT_AT(c, msg_, why_) ((wb_fault){ msg_, NULL, why_, c })
#define WB_NO_FAULT ((wb_fault){ NULL, NULL, NULL, -1 })

/* the four corners of an element (a bend, a volume, a tet): no fault when each is a
 * particle of [0, np) and no two are one; else the first corner that is not, in the
 * type's words: range ("bend particle out of range"), distinct ("a bend needs four
 * distinct particles"). The API and the snapshot checks share it */
static inline wb_fault wb__quad_fault(const int32_t p[4], int32_t np, const char *range, const char *distinct)
{
    for (int k = 0; k < 4; k++) {
        if (p[k] < 0 || p[k] >= np) return WB_FAULT_AT(k, range, "out of range");
        for (int j = 0; j < k; j++)
            if (p[j] == p[k]) return WB_FAULT_AT(k, distinct, distinct);
    }
    return WB_NO_FAULT;
}

extern const wb_ctype wb__distance_type, wb__bend_type, wb__volume_type,
                      wb__shape_type, wb__pressure_type, wb__tet_type;
extern const wb_ctype wb__attach_type, wb__grab_type, wb__tether_type; /* attach.c, grab.c, tether.c */

/* the table the step walks (solver.c), in projection order, and its length */
extern const wb_ctype *const wb__ctypes[];
extern const int wb__nctypes;
/* the same types in the order w:hash() feeds them in (query.c), wb__nctypes + 1 entries:
 * NULL stands for the colliders' poses */
extern const wb_ctype *const wb__ctypes_hashed[];
/* the types with VBD hooks, in the order the vertex step adds their forces (vbd.c), and
 * their count */
extern const wb_ctype *const wb__vbd_ctypes[];
extern const int wb__vbd_nctypes;
#endif
