/* simd.h: the AVX2 loads the vector paths share (distance.c's, XPBD's and VBD's): the x, y,
 * z of 4 particles as 3 vectors of lanes. Each row is loaded without its 4th double (maskload
 * does not touch it: the last particle ends the array), then the 4 rows transposed */
#ifndef WB_SIMD_H
#define WB_SIMD_H

#if defined(__x86_64__) && defined(__GNUC__) && !defined(WB_FLOAT)
#define WB_SIMD_H_AVX2 1 /* the functions below exist */
#include <stddef.h>
#include <immintrin.h>

#include "wobble.h"

static inline __attribute__((always_inline, target("avx2"))) __m256d wb__load3(const wb_real *row)
{
    return _mm256_maskload_pd(row, _mm256_set_epi64x(0, -1, -1, -1));
}

/* rows (x, y, z, .) to lanes */
static inline __attribute__((always_inline, target("avx2"))) void
wb__transpose4(__m256d r0, __m256d r1, __m256d r2, __m256d r3, __m256d *X, __m256d *Y, __m256d *Z)
{
    const __m256d t0 = _mm256_unpacklo_pd(r0, r1), t1 = _mm256_unpackhi_pd(r0, r1); /* x0 x1 z0 z1, y0 y1 . . */
    const __m256d t2 = _mm256_unpacklo_pd(r2, r3), t3 = _mm256_unpackhi_pd(r2, r3);
    *X = _mm256_permute2f128_pd(t0, t2, 0x20);
    *Y = _mm256_permute2f128_pd(t1, t3, 0x20);
    *Z = _mm256_permute2f128_pd(t0, t2, 0x31);
}

/* the particles at offsets o of p */
static inline __attribute__((always_inline, target("avx2"))) void
wb__load4(const wb_real *p, const size_t o[4], __m256d *X, __m256d *Y, __m256d *Z)
{
    wb__transpose4(wb__load3(&p[o[0]]), wb__load3(&p[o[1]]), wb__load3(&p[o[2]]), wb__load3(&p[o[3]]), X, Y, Z);
}

#endif
#endif
