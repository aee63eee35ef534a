/* vec.h: the vector and quaternion maths every core file uses (a leaf: it needs only
 * wobble.h's wb_real). Vectors are wb_real[3]; quaternions (w, x, y, z), unit. */
#ifndef WB_VEC_H
#define WB_VEC_H

#include <math.h>

#include "wobble.h"

static inline void v3_set(wb_real *o, wb_real x, wb_real y, wb_real z) { o[0] = x; o[1] = y; o[2] = z; }
static inline void v3_copy(wb_real *o, const wb_real *a) { o[0] = a[0]; o[1] = a[1]; o[2] = a[2]; }
static inline void v3_add(wb_real *o, const wb_real *a, const wb_real *b) { o[0] = a[0] + b[0]; o[1] = a[1] + b[1]; o[2] = a[2] + b[2]; }
static inline void v3_sub(wb_real *o, const wb_real *a, const wb_real *b) { o[0] = a[0] - b[0]; o[1] = a[1] - b[1]; o[2] = a[2] - b[2]; }
static inline void v3_scale(wb_real *o, const wb_real *a, wb_real s) { o[0] = a[0] * s; o[1] = a[1] * s; o[2] = a[2] * s; }
static inline void v3_madd(wb_real *o, const wb_real *a, wb_real s) { o[0] += a[0] * s; o[1] += a[1] * s; o[2] += a[2] * s; }
static inline wb_real v3_dot(const wb_real *a, const wb_real *b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }
static inline wb_real v3_len(const wb_real *a) { return sqrt(v3_dot(a, a)); }
/* |a| without overflow for huge components (1e300 squared is inf) */
static inline wb_real v3_len_safe(const wb_real *a)
{
    wb_real m = fmax(fabs(a[0]), fmax(fabs(a[1]), fabs(a[2])));
    if (m == 0 || !isfinite(m)) return m;
    wb_real b[3] = { a[0] / m, a[1] / m, a[2] / m };
    return m * v3_len(b);
}
/* the same, the quick way while the square cannot overflow (the broad phases' speeds) */
static inline wb_real v3_len_fast(const wb_real *a)
{
    const wb_real s = v3_dot(a, a);
    return s < 1e300 ? sqrt(s) : v3_len_safe(a);
}
static inline void v3_cross(wb_real *o, const wb_real *a, const wb_real *b)
{
    wb_real x = a[1] * b[2] - a[2] * b[1], y = a[2] * b[0] - a[0] * b[2], z = a[0] * b[1] - a[1] * b[0];
    o[0] = x; o[1] = y; o[2] = z;
}
static inline wb_real clampr(wb_real x, wb_real lo, wb_real hi) { return x < lo ? lo : x > hi ? hi : x; }

/* q v q*; inline: the collision passes rotate into each collider's frame per particle */
static inline void q_rotate(const wb_real q[4], const wb_real v[3], wb_real out[3])
{
    /* v + 2 u x (u x v + w v), u = (x, y, z) */
    const wb_real *u = &q[1];
    wb_real t[3], c[3];
    v3_cross(t, u, v);
    v3_madd(t, v, q[0]);
    v3_cross(c, u, t);
    wb_real r[3] = { v[0] + 2 * c[0], v[1] + 2 * c[1], v[2] + 2 * c[2] };
    v3_copy(out, r);
}

/* q* v q */
static inline void q_rotate_inv(const wb_real q[4], const wb_real v[3], wb_real out[3])
{
    wb_real c[4] = { q[0], -q[1], -q[2], -q[3] };
    q_rotate(c, v, out);
}

/* quat.c */
void q_normalize(wb_real q[4]);
void q_slerp(const wb_real a[4], const wb_real b[4], wb_real t, wb_real out[4]);
void q_integrate(const wb_real q[4], const wb_real om[3], wb_real h, wb_real out[4]);

#endif
