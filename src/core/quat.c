/* quat.c: quaternion maths (w, x, y, z) beyond rotating a vector (vec.h): normalising, slerp,
 * integration of an angular velocity. Scaled where a square could overflow. */
#include <string.h>

#include "vec.h"

void q_normalize(wb_real q[4])
{
    /* scaled first: components of 1e200 must not overflow to inf when squared */
    wb_real m = fmax(fmax(fabs(q[0]), fabs(q[1])), fmax(fabs(q[2]), fabs(q[3])));
    if (m == 0 || !isfinite(m)) { q[0] = 1; q[1] = q[2] = q[3] = 0; return; }
    for (int i = 0; i < 4; i++) q[i] /= m;
    wb_real n = sqrt(q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3]);
    for (int i = 0; i < 4; i++) q[i] /= n;
}

void q_slerp(const wb_real a[4], const wb_real b[4], wb_real t, wb_real out[4])
{
    wb_real d = a[0] * b[0] + a[1] * b[1] + a[2] * b[2] + a[3] * b[3], s = 1;
    if (d < 0) { d = -d; s = -1; } /* the short way round */
    wb_real wa, wb;
    if (d > (wb_real)0.9995) {
        wa = 1 - t;
        wb = t;
    } else {
        wb_real th = acos(d), sn = sin(th);
        wa = sin((1 - t) * th) / sn;
        wb = sin(t * th) / sn;
    }
    wb_real r[4];
    for (int i = 0; i < 4; i++) r[i] = wa * a[i] + s * wb * b[i];
    q_normalize(r);
    memcpy(out, r, sizeof r);
}

void q_integrate(const wb_real q[4], const wb_real om[3], wb_real h, wb_real out[4])
{
    wb_real n = v3_len_safe(om);
    if (n == 0) { if (out != q) memcpy(out, q, 4 * sizeof(wb_real)); return; }
    /* exact rotation by |om| h about om: dq * q */
    wb_real half = n * h / 2, s = sin(half) / n;
    wb_real dq[4] = { cos(half), om[0] * s, om[1] * s, om[2] * s };
    wb_real r[4] = {
        dq[0] * q[0] - dq[1] * q[1] - dq[2] * q[2] - dq[3] * q[3],
        dq[0] * q[1] + dq[1] * q[0] + dq[2] * q[3] - dq[3] * q[2],
        dq[0] * q[2] - dq[1] * q[3] + dq[2] * q[0] + dq[3] * q[1],
        dq[0] * q[3] + dq[1] * q[2] - dq[2] * q[1] + dq[3] * q[0],
    };
    q_normalize(r);
    memcpy(out, r, sizeof r);
}

