/* bvh.h: a mesh collider's triangles in its own frame, an AABB tree over them and the
 * closest-point query with the angle-weighted pseudo-normals that sign it (Bærentzen &
 * Aanæs 2005). Core-internal; the unit tests include it (white-box). */
#ifndef WB_BVH_H
#define WB_BVH_H

#include "wobble.h"

/* a node: its box, and either two children (count 0: left and left + 1) or a leaf of
 * `count` triangles order[left .. left + count) */
typedef struct wb_bvh_node {
    wb_real lo[3], hi[3];
    int32_t left, count;
} wb_bvh_node;

typedef struct wb_colmesh {
    int32_t nv, nt;
    wb_real *v;            /* (nv x 3) vertices, own frame, scale applied */
    int32_t *tri;          /* (nt x 3) corners */
    wb_real *fn;           /* (nt x 3) unit face normals (0 for a degenerate triangle) */
    wb_real *en;           /* (nt x 9) edge pseudo-normals: edge k joins corners k, k+1 */
    wb_real *vn;           /* (nv x 3) vertex pseudo-normals: angle-weighted face normals */
    int closed;            /* every edge has exactly two triangles: inside is inside */
    int32_t nnodes;
    wb_bvh_node *nodes;    /* (nnodes) root first */
    int32_t *order;        /* (nt) triangles in leaf order */
    size_t bytes;          /* what it holds, charged to the world's memory budget */
} wb_colmesh;

/* where on a triangle the closest point lies (Ericson's Voronoi regions) */
enum { WB_REGION_FACE = 0, WB_REGION_V0, WB_REGION_V1, WB_REGION_V2, WB_REGION_E01, WB_REGION_E12, WB_REGION_E20 };

/* copy vertices * scale and triangles, compute the normals and the tree; NULL when out of
 * memory (the input is checked by the caller: finite, corners in range, nt > 0) */
wb_colmesh *wb__colmesh_build(const wb_real *v, int32_t nv, const int32_t *tri, int32_t nt, wb_real scale);
void wb__colmesh_free(wb_colmesh *cm);                 /* NULL is fine */
/* the closest point of triangle (a, b, c) to p (Ericson, Real-Time Collision Detection
 * 5.1.5), its region; returns the squared distance */
wb_real wb__closest_on_triangle(const wb_real p[3], const wb_real a[3], const wb_real b[3], const wb_real c[3],
                                wb_real out[3], int *region);
/* the closest point of the mesh to p: squared distance, point, triangle and region;
 * the tree prunes boxes farther than the best so far. *_brute tries every triangle */
wb_real wb__colmesh_closest(const wb_colmesh *cm, const wb_real p[3], wb_real c[3], int32_t *t, int *region);
wb_real wb__colmesh_closest_brute(const wb_colmesh *cm, const wb_real p[3], wb_real c[3], int32_t *t, int *region);
/* the same within sqrt(max_d2) only (*t = -1 when no triangle is): what contacts need */
wb_real wb__colmesh_closest_within(const wb_colmesh *cm, const wb_real p[3], wb_real max_d2, wb_real c[3], int32_t *t,
                                   int *region);
/* the pseudo-normal of triangle t's feature `region` (not unit) */
void wb__colmesh_pseudo_normal(const wb_colmesh *cm, int32_t t, int region, wb_real n[3]);
/* signed distance of p (own frame): negative inside a closed mesh; an open one gives
 * |p - c|. n (may be NULL): the unit direction out of the surface at p; c, pn: the
 * closest point and its pseudo-normal (either may be NULL) */
wb_real wb__colmesh_distance(const wb_colmesh *cm, const wb_real p[3], wb_real n[3], wb_real c[3], wb_real pn[3]);
/* the same, and the triangle of the closest point (*tri, -1 for none) */
wb_real wb__colmesh_distance_tri(const wb_colmesh *cm, const wb_real p[3], wb_real n[3], wb_real c[3], wb_real pn[3],
                                 int32_t *tri);

#endif
