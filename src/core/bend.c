/* bend.c: dihedral bending constraints (Müller et al. 2007, "Position based dynamics",
 * appendix A, in XPBD form with compliance).
 *
 * A bend joins two triangles (p1, p2, p3) and (p2, p1, p4) hinged on the edge p1-p2 and
 * keeps the angle between their normals at its rest value (the angle at creation). The
 * angle is signed, atan2(sin, cos) of the two normals, so it is smooth through flat (0)
 * and through folded over (+-pi, where C wraps): the acos of the paper has an infinite
 * gradient at both. The gradients are Bridson et al. 2003's bending modes, finite for any
 * non-degenerate pair of triangles; a degenerate one (a wing on the hinge line, or a
 * zero-length hinge) has no angle and is skipped for that projection.
 *
 * Colour batches (colour.c, four particles per constraint) are projected batch after
 * batch, a batch in parallel chunks: the same result for any thread count. Under the
 * Jacobi solver bends are still projected Gauss-Seidel (their batches are conflict-free,
 * so this needs no accumulator and stays deterministic). What the projection reads is
 * packed in its order at colour time; on a CPU with AVX2 a conflict-free batch goes 4
 * bends at a time (project_range_avx2), with the scalar loop's bits (about 2x
 * less CPU per bend than the scalar loop: docs/benchmark.md, "Bends"). */
#include <assert.h>
#include <stdlib.h>

#include "bend.h"
#include "ctype.h"
#include "snapshot.h"
#include "vbd.h"

#define PI_R ((wb_real)3.14159265358979323846)

/* bytes per constraint over the model and cache arrays, for the memory budget */
#define BEND_BYTES (4 * sizeof(int32_t) + 5 * sizeof(wb_real) + 2 * sizeof(int32_t) + 1 + PACK_BYTES)
/* the packed block (bend.h): particles, rest, at, gamma, flag */
#define PACK_BYTES (4 * sizeof(int32_t) + 3 * sizeof(wb_real) + 1)
enum { SKIP = 1, DAMPED = 2 };

/* ---- geometry ---------------------------------------------------------------------------- */
/* the dihedral angle across x1-x2 (0 flat, sign: the wings folding towards n1 x n2 . e)
 * and, when g is not NULL, its gradient for the four particles. 0 when degenerate. */
static inline __attribute__((always_inline)) int dihedral(const wb_real *x1, const wb_real *x2, const wb_real *x3, const wb_real *x4, wb_real *theta,
                    wb_real g[4][3])
{
    wb_real e[3], a3[3], a4[3], n1[3], n2[3], c[3];
    v3_sub(e, x2, x1);
    v3_sub(a3, x3, x1);
    v3_sub(a4, x4, x1);
    v3_cross(n1, e, a3); /* both normals point the same way when the pair lies flat */
    v3_cross(n2, a4, e);
    const wb_real ee = v3_dot(e, e), q1 = v3_dot(n1, n1), q2 = v3_dot(n2, n2);
    /* a triangle whose height is below 1e-12 of its hinge has no reliable normal */
    if (!(ee > (wb_real)1e-24) || !(q1 > (wb_real)1e-24 * ee * ee) || !(q2 > (wb_real)1e-24 * ee * ee)) return 0;
    const wb_real le = sqrt(ee);
    v3_cross(c, n1, n2);
    *theta = atan2(v3_dot(c, e) / le, v3_dot(n1, n2));
    if (!g) return 1;
    /* the wings move along their normals; the hinge ends share the rest so that the
     * gradients sum to zero (momentum) and are orthogonal to rotations */
    wb_real b3[3], b4[3], s;
    v3_scale(b3, n1, 1 / q1);
    v3_scale(b4, n2, 1 / q2);
    v3_scale(g[2], b3, -le);
    v3_scale(g[3], b4, -le);
    wb_real t[3];
    v3_sub(t, x3, x2);
    s = v3_dot(t, e) / le;
    v3_scale(g[0], b3, -s);
    v3_sub(t, x4, x2);
    s = v3_dot(t, e) / le;
    v3_madd(g[0], b4, -s);
    s = v3_dot(a3, e) / le;
    v3_scale(g[1], b3, s);
    s = v3_dot(a4, e) / le;
    v3_madd(g[1], b4, s);
    return 1;
}

/* theta - rest in (-pi, pi]: the short way round, so a fold past pi is not undone the long way */
static wb_real wrap(wb_real d)
{
    if (d > PI_R) d -= 2 * PI_R;
    else if (d <= -PI_R) d += 2 * PI_R;
    return d;
}

/* bend b's angle off its rest (the short way round) and its gradient on its four corners,
 * at the positions x (np x 3) (the VBD energies); 0 when degenerate */
static int bend_off_at(const wb_world *w, const wb_real *x, int32_t b, wb_real *off, wb_real g[4][3])
{
    const int32_t *p = &w->bend->ij[4 * b];
    wb_real th;
    if (!dihedral(&x[3 * p[0]], &x[3 * p[1]], &x[3 * p[2]], &x[3 * p[3]], &th, g)) return 0;
    *off = wrap(th - w->bend->rest[b]);
    return 1;
}

static int bend_off(const wb_world *w, int32_t b, wb_real *off, wb_real g[4][3]) { return bend_off_at(w, w->s.x, b, off, g); }

/* ---- memory --------------------------------------------------------------------------------- */
static int charge(wb_world *w, int32_t cap) { return wb__charge(w, &w->bend->charged, (size_t)cap * BEND_BYTES); }

/* room for need bends; the struct is made with the first (w->bend: NULL until then) */
static wb_status grow(wb_world *w, int32_t need)
{
    if (need > WB_MAX_CONSTRAINTS) return WB_ERR_LIMIT;
    if (!w->bend) {
        if (need <= 0) return WB_OK;
        wb_bends *b = calloc(1, sizeof *b);
        if (!b) return WB_ERR_NOMEM;
        b->bt.n = -1; /* never coloured */
        w->bend = b;
    }
    wb_bends *b = w->bend;
    if (need <= b->cap) return WB_OK;
    int32_t cap = b->cap ? b->cap : 64;
    while (cap < need) cap = cap > WB_MAX_CONSTRAINTS / 2 ? WB_MAX_CONSTRAINTS : cap * 2;
    if (!charge(w, cap)) {
        cap = need;
        if (!charge(w, cap)) return WB_ERR_NOMEM;
    }
    const wb_soa arr[] = {
        { (void **)&b->ij, 4 * sizeof(int32_t) }, { (void **)&b->alpha, sizeof(wb_real) },
        { (void **)&b->beta, sizeof(wb_real) }, { (void **)&b->rest, sizeof(wb_real) },
        { (void **)&b->s_slot, sizeof(int32_t) },
        { (void **)&b->pack, sizeof(int32_t) }, { (void **)&b->lambda, sizeof(wb_real) },
        { (void **)&b->btorque, sizeof(wb_real) }, { (void **)&b->broken, 1 },
    };
    if (WB_SOA_RESIZE(arr, cap) != WB_OK) return WB_ERR_NOMEM;
    b->cap = cap;
    return WB_OK;
}

wb_status wb__bend_reserve(wb_world *w, int64_t extra)
{
    const int32_t n = wb_bend_count(w);
    if (n + extra > WB_MAX_CONSTRAINTS) return WB_ERR_LIMIT;
    return grow(w, n + (int32_t)extra);
}

/* ---- the C API -------------------------------------------------------------------------------- */
wb_bend_def wb_bend_default_def(void)
{
    wb_bend_def d = { 0, 0, NAN, 0 };
    return d;
}

/* the options' rules: the one place they are decided (the binding and the JSON reader
 * print what this finds) */
static wb_fault def_fault(const wb_bend_def *d)
{
    if (!(d->compliance >= 0) || !isfinite(d->compliance)) return WB_FAULT_KEY("compliance", "must be >= 0");
    if (!(d->damping >= 0) || !isfinite(d->damping)) return WB_FAULT_KEY("damping", "must be >= 0");
    if (!isnan(d->rest) && !(d->rest >= -PI_R && d->rest <= PI_R))
        return WB_FAULT_KEY("rest", "must be an angle in [-pi, pi] (radians)");
    if (!(d->break_torque >= 0) || !isfinite(d->break_torque))
        return WB_FAULT_KEY("break_torque", "must be >= 0 (N m; 0: never breaks)");
    return WB_NO_FAULT;
}

const char *wb_bend_def_check(const wb_bend_def *d)
{
    return def_fault(d).msg;
}

/* the particles first (what it joins), then the options, then whether the triangles have
 * an angle to keep when the rest is theirs */
wb_fault wb_bend_check(int32_t np, const wb_real *x, const int32_t p[4], const wb_bend_def *d)
{
    wb_fault f = wb__quad_fault(p, np, "bend particle out of range", "a bend needs four distinct particles");
    if (!f.msg) f = def_fault(d);
    if (!f.msg && x && isnan(d->rest) && !dihedral(&x[3 * p[0]], &x[3 * p[1]], &x[3 * p[2]], &x[3 * p[3]], &(wb_real){ 0 }, NULL))
        f = WB_FAULT_AT(-1, "the two triangles are degenerate (a wing on the hinge line): no angle to keep",
                        "the two triangles are degenerate (a wing on the hinge line): no angle to keep");
    return f;
}

bool wb_dihedral_angle(const wb_real x1[3], const wb_real x2[3], const wb_real x3[3], const wb_real x4[3], wb_real *theta)
{
    return dihedral(x1, x2, x3, x4, theta, NULL) != 0;
}

wb_real wb__bend_angle_of(const wb_real *x, const int32_t *p, int *ok)
{
    wb_real th = 0;
    *ok = dihedral(&x[3 * p[0]], &x[3 * p[1]], &x[3 * p[2]], &x[3 * p[3]], &th, NULL);
    return th;
}

wb_bend_id wb_bend_add(wb_world *w, const int32_t p[4], const wb_bend_def *def, wb_status *status)
{
    wb_bend_id none = { 0, 0 };
    wb_status dummy;
    if (!status) status = &dummy;
    const wb_fault f = wb_bend_check(w->m.np, w->s.x, p, def);
    if (f.msg) {
        wb__set_error("%s", f.msg);
        *status = WB_ERR_ARG;
        return none;
    }
    int ok = 1;
    wb_real rest = def->rest;
    if (isnan(rest)) rest = wb__bend_angle_of(w->s.x, p, &ok);
    wb_status st = grow(w, wb_bend_count(w) + 1);
    if (st != WB_OK) { *status = st; return none; }
    wb_bends *b = w->bend;
    const int32_t s = b->n++;
    memcpy(&b->ij[4 * s], p, 4 * sizeof *p);
    b->alpha[s] = def->compliance;
    b->beta[s] = def->damping;
    b->rest[s] = rest == -PI_R ? PI_R : rest; /* one name for the folded-over angle */
    b->btorque[s] = def->break_torque;
    b->broken[s] = 0;
    b->pack[s] = -1;
    b->dirty = 1;
    *status = WB_OK;
    wb_bend_id id = { (uint32_t)s + 1, 1 };
    return id;
}

bool wb_bend_valid(const wb_world *w, wb_bend_id c) { return c.gen == 1 && c.index >= 1 && c.index <= (uint32_t)wb_bend_count(w); }

#define BSLOT(w, c) (assert(wb_bend_valid((w), (c))), (int32_t)(c).index - 1)

wb_real wb_bend_angle(const wb_world *w, wb_bend_id c)
{
    int ok;
    wb_real th = wb__bend_angle_of(w->s.x, &w->bend->ij[4 * BSLOT(w, c)], &ok);
    return ok ? th : NAN;
}

wb_real wb_bend_rest(const wb_world *w, wb_bend_id c) { return w->bend->rest[BSLOT(w, c)]; }

wb_real wb_bend_force(const wb_world *w, wb_bend_id c)
{
    const int32_t s = BSLOT(w, c), i = w->bend->pack[s];
    if (w->bend->dirty || i < 0 || w->bend->broken[s]) return 0; /* not stepped since it was made, or broken */
    const wb_real h = w->k.h_last;
    return fabs(w->bend->lambda[i]) / (h * h);
}

void wb_bend_particles(const wb_world *w, wb_bend_id c, int32_t p[4]) { memcpy(p, &w->bend->ij[4 * BSLOT(w, c)], 4 * sizeof *p); }
int32_t wb_bend_count(const wb_world *w) { return w->bend ? w->bend->n : 0; }
bool wb_bend_broken(const wb_world *w, wb_bend_id c) { return w->bend->broken[BSLOT(w, c)] != 0; }
int32_t wb_world_bend_break_count(const wb_world *w) { return w->bend ? w->bend->nbreaks : 0; }
wb_bend_id wb_world_bend_break_at(const wb_world *w, int32_t i)
{
    assert(i >= 0 && i < w->bend->nbreaks);
    return w->bend->breaks[i];
}
wb_bend_id wb_bend_at(const wb_world *w, int32_t i)
{
    assert(i >= 0 && i < wb_bend_count(w));
    wb_bend_id id = { (uint32_t)i + 1, 1 };
    return id;
}

/* ---- the type ---------------------------------------------------------------------------- */
static int32_t bend_count(const wb_world *w) { return wb_bend_count(w); }

/* the packed block for n entries: one allocation (bend.h), grown only */
static int pack_alloc(wb_bends *b, int32_t n)
{
    if (n <= b->cap_s && b->s_ij) return 1;
    const size_t cap = (size_t)(n > 0 ? n : 1);
    void *q = malloc(cap * PACK_BYTES);
    if (!q) return 0;
    free(b->s_ij);
    b->s_ij = q;
    b->s_rest = (wb_real *)(b->s_ij + 4 * cap); /* reals after the int32 quadruples: aligned */
    b->s_at = b->s_rest + cap;
    b->s_gamma = b->s_at + cap;
    b->s_flag = (uint8_t *)(b->s_gamma + cap);
    b->cap_s = (int32_t)cap;
    return 1;
}

/* colour batches (batch.h) when bends were made since, and what the projection reads
 * copied in batch order */
static wb_status bend_prepare(wb_world *w)
{
    wb_bends *b = w->bend;
    if (!b) return WB_OK;
    b->nbreaks = 0; /* the list reports the step about to run */
    if (!b->dirty) return WB_OK;
    if (!pack_alloc(b, b->n) || !wb__batches_build(&b->bt, &w->m, b->ij, 4, b->n, b->s_slot))
        return WB_ERR_NOMEM;
    for (int32_t i = 0; i < b->n; i++) {
        const int32_t s = b->s_slot[i];
        memcpy(&b->s_ij[4 * i], &b->ij[4 * s], 4 * sizeof(int32_t));
        b->s_rest[i] = b->rest[s];
        b->pack[s] = i;
        b->lambda[i] = 0;
    }
    b->h_at = NAN; /* s_at, s_gamma, s_flag: at the next projection */
    b->dirty = 0;
    return WB_OK;
}

static void bend_substep_begin(wb_world *w)
{
    if (wb_bend_count(w) > 0) memset(w->bend->lambda, 0, sizeof(wb_real) * (size_t)w->bend->n);
}

/* the per-constraint constants of a substep h, in the packed order: computed as the
 * loop computed them in the loop before (the same bits) */
static void pack_constants(wb_bends *b, wb_real h, wb_real inv_h2)
{
    for (int32_t i = 0; i < b->n; i++) {
        const int32_t s = b->s_slot[i];
        const wb_real at = b->alpha[s] * inv_h2;
        b->s_at[i] = at;
        b->s_gamma[i] = at * b->beta[s] * h;
        b->s_flag[i] = (uint8_t)(b->broken[s] || isinf(at) ? SKIP : b->beta[s] > 0 && at > 0 ? DAMPED : 0);
    }
    b->h_at = h;
}

/* XPBD on packed [lo, hi): dlambda = (-C - at lambda - gamma grad C . (x - x_prev)) /
 * ((1 + gamma) sum w |grad|^2 + at), each movable particle moved by w grad dlambda;
 * particles with w = 0 are never written. The reference for the AVX2 path below: any
 * change here must be made there too, operation for operation. */
static void project_range(wb_bends *b, const wb_real *restrict wv, wb_real *x, const wb_real *restrict xp,
                          int32_t lo, int32_t hi)
{
    const uint8_t *restrict flag = b->s_flag;
    wb_real *restrict lambda = b->lambda;
    for (int32_t i = lo; i < hi; i++) {
        if (flag[i] & SKIP) continue;
        const int32_t *p = &b->s_ij[4 * i];
        wb_real g[4][3], th;
        if (!dihedral(&x[3 * p[0]], &x[3 * p[1]], &x[3 * p[2]], &x[3 * p[3]], &th, g)) continue;
        wb_real den = 0;
        for (int k = 0; k < 4; k++) den += wv[p[k]] * v3_dot(g[k], g[k]);
        if (!(den > 0) || !isfinite(den)) continue;
        const wb_real at = b->s_at[i];
        wb_real num = -wrap(th - b->s_rest[i]) - at * lambda[i], d = den + at;
        if (flag[i] & DAMPED) {
            /* gamma = alpha~ beta~ / h with beta~ = h^2 beta, as a distance's damping */
            const wb_real gamma = b->s_gamma[i];
            wb_real rel = 0;
            for (int k = 0; k < 4; k++) {
                wb_real v[3];
                v3_sub(v, &x[3 * p[k]], &xp[3 * p[k]]);
                rel += v3_dot(g[k], v);
            }
            /* gamma overflowed: its limit, a correction removing the angular velocity */
            if (isinf(gamma)) { num = -rel; d = den; }
            else { num -= gamma * rel; d += gamma * den; }
        }
        const wb_real dl = num / d;
        if (!isfinite(dl)) continue;
        lambda[i] += dl;
        for (int k = 0; k < 4; k++)
            if (wv[p[k]] > 0) v3_madd(&x[3 * p[k]], g[k], wv[p[k]] * dl);
    }
}

#if defined(__x86_64__) && defined(__GNUC__) && !defined(WB_FLOAT)
#define WB_BEND_AVX2 1
#include <immintrin.h>

/* the x, y, z of 4 particles as 3 vectors of lanes: x y pairs and z apart, plain loads
 * (none past a particle: the last one ends the array), put together by lane pairs */
static inline __attribute__((always_inline, target("avx2"))) void
load4(const wb_real *p, const int32_t i[4], __m256d v[3])
{
    const wb_real *p0 = &p[3 * i[0]], *p1 = &p[3 * i[1]], *p2 = &p[3 * i[2]], *p3 = &p[3 * i[3]];
    const __m256d a02 = _mm256_insertf128_pd(_mm256_castpd128_pd256(_mm_loadu_pd(p0)), _mm_loadu_pd(p2), 1);
    const __m256d a13 = _mm256_insertf128_pd(_mm256_castpd128_pd256(_mm_loadu_pd(p1)), _mm_loadu_pd(p3), 1);
    const __m256d z02 = _mm256_insertf128_pd(_mm256_castpd128_pd256(_mm_load_sd(p0 + 2)), _mm_load_sd(p2 + 2), 1);
    const __m256d z13 = _mm256_insertf128_pd(_mm256_castpd128_pd256(_mm_load_sd(p1 + 2)), _mm_load_sd(p3 + 2), 1);
    v[0] = _mm256_unpacklo_pd(a02, a13); /* x0 x1 x2 x3 */
    v[1] = _mm256_unpackhi_pd(a02, a13);
    v[2] = _mm256_unpacklo_pd(z02, z13);
}

#define VADD _mm256_add_pd
#define VSUB _mm256_sub_pd
#define VMUL _mm256_mul_pd
#define VDIV _mm256_div_pd
/* v3_sub, v3_dot, v3_cross of core.h on vectors of lanes, the same operations in order */
#define VSUB3(o, a, b) ((o)[0] = VSUB((a)[0], (b)[0]), (o)[1] = VSUB((a)[1], (b)[1]), (o)[2] = VSUB((a)[2], (b)[2]))
#define VDOT3(a, b) VADD(VADD(VMUL((a)[0], (b)[0]), VMUL((a)[1], (b)[1])), VMUL((a)[2], (b)[2]))
#define VCROSS3(o, a, b)                                                                                             \
    ((o)[0] = VSUB(VMUL((a)[1], (b)[2]), VMUL((a)[2], (b)[1])),                                                     \
     (o)[1] = VSUB(VMUL((a)[2], (b)[0]), VMUL((a)[0], (b)[2])),                                                     \
     (o)[2] = VSUB(VMUL((a)[0], (b)[1]), VMUL((a)[1], (b)[0])))
#define VSCALE3(o, a, s) ((o)[0] = VMUL((a)[0], (s)), (o)[1] = VMUL((a)[1], (s)), (o)[2] = VMUL((a)[2], (s)))
#define VMADD3(o, a, s) ((o)[0] = VADD((o)[0], VMUL((a)[0], (s))), (o)[1] = VADD((o)[1], VMUL((a)[1], (s))), \
                         (o)[2] = VADD((o)[2], VMUL((a)[2], (s))))

/* the 4 x 4 particles of bends i .. i + 3, transposed: ix[k] = the k-th particle of each */
static inline __attribute__((always_inline, target("avx2"))) void
indices4(const int32_t *s_ij, int32_t i, int32_t *ix0, int32_t *ix1, int32_t *ix2, int32_t *ix3)
{
    const __m128i r0 = _mm_loadu_si128((const __m128i *)&s_ij[4 * i]);
    const __m128i r1 = _mm_loadu_si128((const __m128i *)&s_ij[4 * i + 4]);
    const __m128i r2 = _mm_loadu_si128((const __m128i *)&s_ij[4 * i + 8]);
    const __m128i r3 = _mm_loadu_si128((const __m128i *)&s_ij[4 * i + 12]);
    const __m128i t0 = _mm_unpacklo_epi32(r0, r1), t1 = _mm_unpackhi_epi32(r0, r1);
    const __m128i t2 = _mm_unpacklo_epi32(r2, r3), t3 = _mm_unpackhi_epi32(r2, r3);
    _mm_store_si128((__m128i *)ix0, _mm_unpacklo_epi64(t0, t2));
    _mm_store_si128((__m128i *)ix1, _mm_unpackhi_epi64(t0, t2));
    _mm_store_si128((__m128i *)ix2, _mm_unpacklo_epi64(t1, t3));
    _mm_store_si128((__m128i *)ix3, _mm_unpackhi_epi64(t1, t3));
}

/* x, y, z of 4 lanes back into the rows of their particles (load4 undone), only the
 * lanes of mask: 3 doubles each, the next particle's untouched */
static inline __attribute__((always_inline, target("avx2"))) void
store4(wb_real *p, const int32_t i[4], const __m256d v[3], int mask)
{
    const __m256d t0 = _mm256_unpacklo_pd(v[0], v[1]), t1 = _mm256_unpackhi_pd(v[0], v[1]); /* x0 y0 x2 y2, x1 y1 x3 y3 */
    const __m256d u0 = _mm256_unpacklo_pd(v[2], v[2]), u1 = _mm256_unpackhi_pd(v[2], v[2]); /* z0 . z2 ., z1 . z3 . */
    __m256d r[4];
    r[0] = _mm256_permute2f128_pd(t0, u0, 0x20);
    r[1] = _mm256_permute2f128_pd(t1, u1, 0x20);
    r[2] = _mm256_permute2f128_pd(t0, u0, 0x31);
    r[3] = _mm256_permute2f128_pd(t1, u1, 0x31);
    for (int l = 0; l < 4; l++)
        if (mask >> l & 1) {
            _mm_storeu_pd(&p[3 * i[l]], _mm256_castpd256_pd128(r[l]));
            _mm_store_sd(&p[3 * i[l] + 2], _mm256_extractf128_pd(r[l], 1));
        }
}

/* lanes whose flag (4 bytes of s_flag) has any bit of f */
static inline __attribute__((always_inline, target("avx2"))) __m256d flag4(uint32_t fl, int f)
{
    const __m256i v = _mm256_and_si256(_mm256_cvtepu8_epi64(_mm_cvtsi32_si128((int)fl)), _mm256_set1_epi64x(f));
    return _mm256_castsi256_pd(_mm256_xor_si256(_mm256_cmpeq_epi64(v, _mm256_setzero_si256()), _mm256_set1_epi64x(-1)));
}

/* project_range for 4 bends of a conflict-free batch at a time, in double, every lane
 * doing exactly the scalar loop's operations in its order (dihedral() inlined; no FMA:
 * the Makefile's -ffp-contract=off), so the bits are the scalar loop's for any split of
 * the batch. A chunk of CH bends in three passes: the geometry (gradients, den, the
 * skip tests: none of it needs the angle), the angles (the library's atan2 per lane, in
 * a loop of their own: a call inside the vector code spills every ymm register), then
 * the multipliers and corrections, written after the chunk (no lane reads a movable
 * particle another lane of the batch writes), only where the lane goes on and w > 0.
 * The skipped lanes (the `continue`s) are masked, the damping's isinf(gamma) limit
 * blended. */
static __attribute__((target("avx2"))) void
project_range_avx2(wb_bends *b, const wb_real *restrict wv, wb_real *x, const wb_real *restrict xp, int32_t lo,
                   int32_t hi)
{
    enum { CH = 32 };
    /* per bend of the chunk: its particles and their positions, the gradients, w, den,
     * the lanes going on (a mask per lane), atan2's arguments and result */
    int32_t ib[4][CH] __attribute__((aligned(16)));
    double pb[4][3][CH] __attribute__((aligned(32)));
    double gb[4][3][CH] __attribute__((aligned(32))), wb[4][CH] __attribute__((aligned(32)));
    double den_b[CH] __attribute__((aligned(32))), live_b[CH] __attribute__((aligned(32)));
    double ya[CH] __attribute__((aligned(32))), xa[CH] __attribute__((aligned(32))), tha[CH] __attribute__((aligned(32)));
    const __m256d zero = _mm256_setzero_pd(), one = _mm256_set1_pd(1), tiny = _mm256_set1_pd(1e-24);
    const __m256d inf = _mm256_set1_pd(INFINITY), negz = _mm256_set1_pd(-0.0);
    const __m256d absmask = _mm256_castsi256_pd(_mm256_set1_epi64x(INT64_MAX));
    const __m256d pi = _mm256_set1_pd(PI_R), mpi = _mm256_set1_pd(-PI_R), twopi = _mm256_set1_pd(2 * PI_R);
    wb_real *restrict lambda = b->lambda;
    memset(tha, 0, sizeof tha); /* the angle of a lane that has none: read, masked */
    int32_t i = lo;
    while (i + 4 <= hi) {
        const int32_t c0 = i, cn = (hi - i) / 4 * 4 < CH ? (hi - i) / 4 * 4 : CH;
        uint64_t lanes = 0; /* bit g: bend c0 + g goes on to its angle */
        /* pass 1: dihedral() but the angle, the gradients and den */
        for (int g = 0; g < cn; g += 4) {
            uint32_t fl;
            memcpy(&fl, &b->s_flag[c0 + g], 4);
            if ((fl & 0x01010101u) == 0x01010101u) continue; /* all four skipped */
            indices4(b->s_ij, c0 + g, &ib[0][g], &ib[1][g], &ib[2][g], &ib[3][g]);
            __m256d p[4][3];
            for (int k = 0; k < 4; k++) {
                load4(x, &ib[k][g], p[k]);
                for (int j = 0; j < 3; j++) _mm256_store_pd(&pb[k][j][g], p[k][j]);
            }
            __m256d e[3], a3[3], a4[3], n1[3], n2[3], c[3], t[3];
            VSUB3(e, p[1], p[0]);
            VSUB3(a3, p[2], p[0]);
            VSUB3(a4, p[3], p[0]);
            VCROSS3(n1, e, a3);
            VCROSS3(n2, a4, e);
            const __m256d ee = VDOT3(e, e), q1 = VDOT3(n1, n1), q2 = VDOT3(n2, n2);
            const __m256d lim = VMUL(VMUL(tiny, ee), ee);
            __m256d live = _mm256_andnot_pd(flag4(fl, SKIP), _mm256_cmp_pd(ee, tiny, _CMP_GT_OQ));
            live = _mm256_and_pd(live, _mm256_and_pd(_mm256_cmp_pd(q1, lim, _CMP_GT_OQ), _mm256_cmp_pd(q2, lim, _CMP_GT_OQ)));
            if (!_mm256_movemask_pd(live)) continue;
            const __m256d le = _mm256_sqrt_pd(ee);
            VCROSS3(c, n1, n2);
            _mm256_store_pd(&ya[g], VDIV(VDOT3(c, e), le));
            _mm256_store_pd(&xa[g], VDOT3(n1, n2));
            __m256d b3[3], b4[3], gr[4][3], s;
            VSCALE3(b3, n1, VDIV(one, q1));
            VSCALE3(b4, n2, VDIV(one, q2));
            const __m256d mle = _mm256_xor_pd(le, negz);
            VSCALE3(gr[2], b3, mle);
            VSCALE3(gr[3], b4, mle);
            VSUB3(t, p[2], p[1]);
            s = VDIV(VDOT3(t, e), le);
            VSCALE3(gr[0], b3, _mm256_xor_pd(s, negz));
            VSUB3(t, p[3], p[1]);
            s = VDIV(VDOT3(t, e), le);
            VMADD3(gr[0], b4, _mm256_xor_pd(s, negz));
            s = VDIV(VDOT3(a3, e), le);
            VSCALE3(gr[1], b3, s);
            s = VDIV(VDOT3(a4, e), le);
            VMADD3(gr[1], b4, s);
            __m256d den = zero;
            for (int k = 0; k < 4; k++) {
                const int32_t *ik = &ib[k][g];
                const __m256d wk = _mm256_set_pd(wv[ik[3]], wv[ik[2]], wv[ik[1]], wv[ik[0]]);
                den = VADD(den, VMUL(wk, VDOT3(gr[k], gr[k])));
                _mm256_store_pd(&wb[k][g], wk);
                for (int j = 0; j < 3; j++) _mm256_store_pd(&gb[k][j][g], gr[k][j]);
            }
            live = _mm256_and_pd(live, _mm256_and_pd(_mm256_cmp_pd(den, zero, _CMP_GT_OQ),
                                                     _mm256_cmp_pd(_mm256_and_pd(den, absmask), inf, _CMP_LT_OQ)));
            _mm256_store_pd(&den_b[g], den);
            _mm256_store_pd(&live_b[g], live);
            lanes |= (uint64_t)_mm256_movemask_pd(live) << g;
        }
        /* pass 2: the angles */
        for (uint64_t m = lanes; m; m &= m - 1) {
            const int j = __builtin_ctzll(m);
            tha[j] = atan2(ya[j], xa[j]);
        }
        /* pass 3: the multipliers and the corrections, written at once: the chunk's
         * reads are done and the batch writes no particle twice */
        for (int g = 0; g < cn; g += 4) {
            if (!(lanes >> g & 15)) continue;
            const int32_t i4 = c0 + g;
            __m256d live = _mm256_load_pd(&live_b[g]);
            const __m256d den = _mm256_load_pd(&den_b[g]);
            const __m256d at = _mm256_loadu_pd(&b->s_at[i4]), lam = _mm256_loadu_pd(&lambda[i4]);
            const __m256d dd = VSUB(_mm256_load_pd(&tha[g]), _mm256_loadu_pd(&b->s_rest[i4]));
            const __m256d wrapped = _mm256_blendv_pd(_mm256_blendv_pd(dd, VADD(dd, twopi), _mm256_cmp_pd(dd, mpi, _CMP_LE_OQ)),
                                                     VSUB(dd, twopi), _mm256_cmp_pd(dd, pi, _CMP_GT_OQ));
            __m256d num = VSUB(_mm256_xor_pd(wrapped, negz), VMUL(at, lam)), d = VADD(den, at);
            uint32_t fl;
            memcpy(&fl, &b->s_flag[i4], 4);
            const __m256d damped = _mm256_and_pd(flag4(fl, DAMPED), live);
            if (_mm256_movemask_pd(damped)) {
                const __m256d gamma = _mm256_loadu_pd(&b->s_gamma[i4]);
                __m256d rel = zero, q[3], v[3], pk[3], gk[3];
                for (int k = 0; k < 4; k++) {
                    load4(xp, &ib[k][g], q);
                    for (int j = 0; j < 3; j++) {
                        pk[j] = _mm256_load_pd(&pb[k][j][g]);
                        gk[j] = _mm256_load_pd(&gb[k][j][g]);
                    }
                    VSUB3(v, pk, q);
                    rel = VADD(rel, VDOT3(gk, v));
                }
                const __m256d ginf = _mm256_cmp_pd(_mm256_and_pd(gamma, absmask), inf, _CMP_EQ_OQ);
                const __m256d nd = _mm256_blendv_pd(VSUB(num, VMUL(gamma, rel)), _mm256_xor_pd(rel, negz), ginf);
                const __m256d dn = _mm256_blendv_pd(VADD(d, VMUL(gamma, den)), den, ginf);
                num = _mm256_blendv_pd(num, nd, damped);
                d = _mm256_blendv_pd(d, dn, damped);
            }
            const __m256d dl = VDIV(num, d);
            live = _mm256_and_pd(live, _mm256_cmp_pd(_mm256_and_pd(dl, absmask), inf, _CMP_LT_OQ));
            /* a blend and a plain store: a masked store is slow on AMD */
            _mm256_storeu_pd(&lambda[i4], _mm256_blendv_pd(lam, VADD(lam, dl), live));
            for (int k = 0; k < 4; k++) {
                const __m256d wk = _mm256_load_pd(&wb[k][g]), f = VMUL(wk, dl);
                const int wr = _mm256_movemask_pd(_mm256_and_pd(live, _mm256_cmp_pd(wk, zero, _CMP_GT_OQ)));
                if (!wr) continue;
                __m256d nx[3]; /* x += g w dl, as v3_madd */
                for (int j = 0; j < 3; j++)
                    nx[j] = VADD(_mm256_load_pd(&pb[k][j][g]), VMUL(_mm256_load_pd(&gb[k][j][g]), f));
                store4(x, &ib[k][g], nx, wr);
            }
        }
        i += cn;
    }
    if (i < hi) project_range(b, wv, x, xp, i, hi);
}
#undef VADD
#undef VSUB
#undef VMUL
#undef VDIV
#undef VSUB3
#undef VDOT3
#undef VCROSS3
#undef VSCALE3
#undef VMADD3
#endif

/* the vector path: -1 not yet decided, 0 off (no AVX2, or turned off), 1 on */
static int simd_state = -1;

/* Internal switch for tests: on = 0 forces the scalar loop, on = 1 uses the vector
 * path where the CPU has it; returns whether the vector path is on. Not thread-safe:
 * call it between steps. */
int wb__bend_simd(int on);
int wb__bend_simd(int on) { return wb__simd_set(&simd_state, on); }

/* packed [lo, hi) of one batch, or of a chunk of one (batch.h); the serial tail's
 * bends may share a movable particle, so only the others take the vector path */
static void project_batch(wb_world *w, const int32_t *order, int32_t lo, int32_t hi, wb_real h)
{
    (void)order; /* the packed copies are in batch order already */
    (void)h;     /* ... and hold the substep's constants (pack_constants) */
    wb_bends *b = w->bend;
#ifdef WB_BEND_AVX2
    const int apart = hi <= b->bt.colour_start[b->bt.serial_start];
    if (apart && hi - lo >= 4) {
        /* decided once, possibly by several threads at once (the same answer) */
        int v = __atomic_load_n(&simd_state, __ATOMIC_RELAXED);
        if (v < 0) v = wb__bend_simd(1);
        if (v) {
            project_range_avx2(b, w->m.w, w->s.x, w->s.x_prev, lo, hi);
            return;
        }
    }
#endif
    project_range(b, w->m.w, w->s.x, w->s.x_prev, lo, hi);
}

/* batch after batch in colour order, a batch of 256 or more in parallel chunks (batch.h):
 * the same bits for any thread count */
static void bend_project(wb_world *w, wb_real h)
{
    wb_bends *b = w->bend;
    if (!b) return;
    w->k.projections += b->n;
    if (!(h == b->h_at)) pack_constants(b, h, 1 / (h * h));
    wb__batches_run(&b->bt, w, 256, project_batch, NULL, b->s_slot, h);
}

/* U = C^2 / (2 alpha) for compliant bends (alpha = 1/k, k in N m / rad) */
static wb_real bend_energy(const wb_world *w)
{
    const wb_bends *b = w->bend;
    wb_real e = 0;
    for (int32_t s = 0; s < wb_bend_count(w); s++) {
        int ok;
        if (b->alpha[s] <= 0 || b->broken[s]) continue;
        const wb_real th = wb__bend_angle_of(w->s.x, &b->ij[4 * s], &ok);
        if (!ok) continue;
        const wb_real c = wrap(th - b->rest[s]);
        e += c * c / (2 * b->alpha[s]);
    }
    return e;
}

/* breaking by torque, once per frame on the multiplier of the frame's last substep (the
 * torque wb_bend_force reads: lambda / h^2 of an angle is N m), as distances break by
 * force; a broken bend stays (its slot is its handle) and is skipped from then on */
static void bend_frame_end(wb_world *w)
{
    wb_bends *b = w->bend;
    if (!b || b->dirty || !(w->k.h_last > 0)) return;
    const wb_real inv_h2 = 1 / (w->k.h_last * w->k.h_last);
    for (int32_t i = 0; i < b->n; i++) {
        const int32_t s = b->s_slot[i];
        if (!(b->btorque[s] > 0) || b->broken[s] || !(fabs(b->lambda[i]) * inv_h2 > b->btorque[s])) continue;
        b->broken[s] = 1;
        b->s_flag[i] |= SKIP;
        wb_bend_id id = { (uint32_t)s + 1, 1 };
        wb_bend_id *q = wb__grow(b->breaks, &b->cap_breaks, b->nbreaks + 1, sizeof *q);
        if (q) { b->breaks = q; b->breaks[b->nbreaks++] = id; }
    }
}

static void bend_links(const wb_world *w, wb_link_fn fn, void *ud)
{
    if (w->bend) wb__link_quads(w->bend->ij, w->bend->n, fn, ud);
}

/* broken or not: a body joined once too often is only kept a little less well */
static void bend_joins(const wb_world *w, wb_link_fn fn, void *ud)
{
    if (w->bend) wb__join_elements(w->bend->ij, w->bend->n, 4, fn, ud);
}

/* ---- teardown, hash, snapshots (ctype.h) ------------------------------------------------ */
static void bend_destroy(wb_world *w)
{
    wb_bends *b = w->bend;
    if (!b) return;
    void *p[] = { b->ij, b->alpha, b->beta, b->rest, b->s_ij, b->s_slot, b->pack, b->lambda, b->btorque,
                  b->broken, b->breaks };
    for (size_t i = 0; i < sizeof p / sizeof p[0]; i++) free(p[i]);
    free(b);
    w->bend = NULL;
}

static size_t bend_charged(const wb_world *w) { return w->bend ? w->bend->charged : 0; }

static wb_real bend_residual(const wb_world *w, wb_real h)
{
    const wb_bends *b = w->bend;
    const wb_real *x = w->s.x, *wv = w->m.w, inv_h2 = 1 / (h * h);
    wb_real r = 0;
    if (!b || b->dirty) return 0; /* made since the last step: not packed, never projected */
    for (int32_t i = 0; i < b->n; i++) {
        const int32_t s = b->s_slot[i], *p = &b->s_ij[4 * i];
        const wb_real at = b->alpha[s] * inv_h2;
        if (b->broken[s] || isinf(at) || wv[p[0]] + wv[p[1]] + wv[p[2]] + wv[p[3]] == 0) continue;
        wb_real g[4][3], th;
        if (!dihedral(&x[3 * p[0]], &x[3 * p[1]], &x[3 * p[2]], &x[3 * p[3]], &th, g)) continue;
        wb_real g2 = 0;
        for (int k = 0; k < 4; k++) g2 += v3_dot(g[k], g[k]);
        const wb_real ri = wb__residual(wrap(th - b->s_rest[i]) + at * b->lambda[i], g2, 4);
        r = ri > r ? ri : r;
    }
    return r;
}

/* the broken ones' slots (state): a world without one adds nothing */
static uint64_t bend_hash(const wb_world *w, uint64_t h)
{
    for (int32_t i = 0; i < wb_bend_count(w); i++)
        if (w->bend->broken[i]) h = wb__fnv(h, &i, sizeof i);
    return h;
}

static void bend_image_free(wb_image *g)
{
    wb_image_bend *b = &g->bend;
    free(b->ij); free(b->alpha); free(b->beta); free(b->rest); free(b->btorque); free(b->broken);
    memset(b, 0, sizeof *b);
}

/* calloc of n elements, never of 0 bytes (so NULL always means out of memory) */
static void *zalloc(int64_t n, size_t elem) { return calloc((size_t)(n > 0 ? n : 1), elem); }

wb_status wb_image_alloc_bends(wb_image *g, int32_t n)
{
    bend_image_free(g);
    wb_image_bend *b = &g->bend;
    b->n = n;
    b->ij = zalloc(4 * (int64_t)n, sizeof *b->ij);
    b->alpha = zalloc(n, sizeof(wb_real));
    b->beta = zalloc(n, sizeof(wb_real));
    b->rest = zalloc(n, sizeof(wb_real));
    b->btorque = zalloc(n, sizeof(wb_real));
    b->broken = zalloc(n, 1);
    if (b->ij && b->alpha && b->beta && b->rest && b->btorque && b->broken) return WB_OK;
    bend_image_free(g);
    return WB_ERR_NOMEM;
}

static wb_status bend_image_save(const wb_world *w, wb_image *g)
{
    const wb_bends *bd = w->bend;
    const size_t n = (size_t)wb_bend_count(w);
    if (n == 0) return WB_OK;
    wb_status st = wb_image_alloc_bends(g, bd->n);
    if (st != WB_OK) return st;
    wb_image_bend *b = &g->bend;
    memcpy(b->ij, bd->ij, 4 * n * sizeof *b->ij);
    memcpy(b->alpha, bd->alpha, n * sizeof(wb_real));
    memcpy(b->beta, bd->beta, n * sizeof(wb_real));
    memcpy(b->rest, bd->rest, n * sizeof(wb_real));
    memcpy(b->btorque, bd->btorque, n * sizeof(wb_real));
    memcpy(b->broken, bd->broken, n);
    return WB_OK;
}

static const char *bend_image_check(const wb_image *g)
{
    const wb_image_bend *b = &g->bend;
    if (b->n < 0 || b->n > WB_MAX_CONSTRAINTS) return "too many bends";
    for (int32_t i = 0; i < b->n; i++) {
        /* an image keeps the angle (never NaN, the API's "current"), and a broken bend's
         * triangles may have none: no positions */
        const wb_bend_def d = { b->alpha[i], b->beta[i], b->rest[i], b->btorque[i] };
        if (isnan(b->rest[i])) return "bend rest must be an angle in [-pi, pi] (radians)";
        const wb_fault f = wb_bend_check(g->np, NULL, &b->ij[4 * i], &d);
        if (f.msg) return f.msg;
    }
    return NULL;
}

static wb_status bend_image_reserve(wb_world *w, const wb_image *g, const wb_image_at *at)
{
    (void)at;
    return wb__bend_reserve(w, g->bend.n);
}

/* a new world takes the arrays as they are; an appended image's bends are added one by
 * one after w's (checked and reserved: that cannot fail) */
static void bend_image_put(wb_world *w, const wb_image *g, const wb_image_at *at)
{
    const wb_image_bend *b = &g->bend;
    wb_bends *bd = w->bend;
    const size_t n = (size_t)b->n;
    if (n == 0) return;
    if (at->exact) {
        bd->n = b->n;
        memcpy(bd->ij, b->ij, 4 * n * sizeof *bd->ij);
        memcpy(bd->alpha, b->alpha, n * sizeof(wb_real));
        memcpy(bd->beta, b->beta, n * sizeof(wb_real));
        memcpy(bd->rest, b->rest, n * sizeof(wb_real));
        memcpy(bd->btorque, b->btorque, n * sizeof(wb_real));
        memcpy(bd->broken, b->broken, n);
        bd->dirty = 1;
        return;
    }
    for (int32_t i = 0; i < b->n; i++) {
        int32_t p[4];
        for (int k = 0; k < 4; k++) p[k] = b->ij[4 * i + k] + at->pshift;
        const wb_bend_def d = { b->alpha[i], b->beta[i], b->rest[i], b->btorque[i] };
        const wb_bend_id id = wb_bend_add(w, p, &d, NULL);
        bd->broken[id.index - 1] = b->broken[i];
    }
}

static void bend_stats(const wb_world *w, wb_stats *st)
{
    st->bends = wb_bend_count(w);
}

/* ---- the VBD solver's part (vbd.h) --------------------------------------------------------- */
/* A hard bend is held as a hard link (distance.c): its multiplier carried whole from
 * substep to substep, WB_VBD_STAB of its error kept, with its penalty VBD_BEND_K times the
 * inertia of its angle (bend_start_penalty; rad, not m: the gradient of a 5 cm wing is
 * 20 /m). That is the stiffness the bend has until its multiplier catches up: a clamped
 * strip with rigid bends droops 0.55 m at 8, 12 mm at 512 and 1.4 mm at 4096 (10 x 1)
 * before it straightens (512: what the suite ran with) */
#define VBD_BEND_K ((wb_real)512)
/* a bend keeps WB_VBD_STAB of its error per this much time (the default substep), a link
 * per substep: per time, a rope of rigid links at 40 x 4 stretched 3.7% (3% allowed), the
 * catenary at 40 x 1 read its tension 3.4% off and a hand-built cloth fell through its
 * sphere (user/01-03); the clamped strip at 40 x 1 held its droop better (0.2873 m at
 * frame 2400 against 0.2825, converged 0.2881) */
#define VBD_STAB_T ((wb_real)1 / 600)

/* the bends' part of the VBD solver's cache */
typedef struct bend_vbd {
    int32_t nb;            /* the bends it was built for */
    wb_vbd_quads at;       /* the bends at each vertex, as 4 bend + corner */
    wb_real *blam, *bkpen; /* (cap, by slot) a hard bend's multiplier and penalty */
    wb_real *btg, *bc0;    /* (cap) a hard bend's target (the error it keeps this substep) and
                              its error as the last sweep left it (NaN: not known) */
    int32_t cap;
    wb_real *save;         /* (2 cap + 1) blam and bc0 at the step's start (an undone frame) */
    size_t charged;        /* its bytes charged to def.memory */
} bend_vbd;

static void *bvbd_make(void) { return calloc(1, sizeof(bend_vbd)); }

static void bvbd_free(wb_world *w, void *part)
{
    bend_vbd *v = part;
    wb__vbd_quads_free(&v->at);
    free(v->blam), free(v->bkpen), free(v->btg), free(v->bc0), free(v->save);
    wb__charge(w, &v->charged, 0);
    free(v);
}

static int32_t bvbd_slots(const wb_world *w) { return wb_bend_count(w); }

static int bvbd_build(wb_world *w, void *part)
{
    bend_vbd *v = part;
    const int32_t nb = wb_bend_count(w), cap = nb > v->cap ? nb : v->cap;
    const size_t bytes = sizeof *v + wb__vbd_quads_bytes(w->m.np, nb) + (size_t)cap * 4 * sizeof(wb_real) +
                         (2 * (size_t)cap + 1) * sizeof(wb_real);
    if (!wb__charge(w, &v->charged, bytes) || !wb__vbd_quads_build(&v->at, w->m.np, w->bend ? w->bend->ij : NULL, nb))
        return 0;
    if (cap > v->cap) {
        const size_t n = (size_t)cap;
        wb_real *bl = realloc(v->blam, sizeof *bl * n), *bk = realloc(v->bkpen, sizeof *bk * n);
        if (bl) v->blam = bl;
        if (bk) v->bkpen = bk;
        wb_real *bt = realloc(v->btg, sizeof *bt * n), *bc = realloc(v->bc0, sizeof *bc * n);
        if (bt) v->btg = bt;
        if (bc) v->bc0 = bc;
        if (!bl || !bk || !bt || !bc) return 0;
        memset(v->blam + v->cap, 0, sizeof *bl * (n - (size_t)v->cap));
        memset(v->bkpen + v->cap, 0, sizeof *bk * (n - (size_t)v->cap));
        for (int32_t b = v->cap; b < cap; b++) v->btg[b] = 0, v->bc0[b] = (wb_real)NAN;
    }
    wb_real *sv = realloc(v->save, sizeof *sv * (2 * (size_t)cap + 1));
    if (!sv) return 0;
    v->save = sv;
    v->cap = cap;
    v->nb = nb;
    return 1;
}

static uint64_t bvbd_neighbours(const wb_world *w, const void *part, int32_t i, const uint8_t *col)
{
    return wb__vbd_quads_colours(&((const bend_vbd *)part)->at, w->bend ? w->bend->ij : NULL, i, col);
}

static int bvbd_holds(const void *part, int32_t i) { return wb__vbd_quads_hold(&((const bend_vbd *)part)->at, i); }

/* a bend's energy off^2 / (2 alpha) on corner k: Gauss-Newton, k g g^T; a rigid one (alpha
 * 0) through the augmented Lagrangian, k (off - t)^2 / 2 + lambda (off - t), as a hard link
 * (t: the error it keeps this substep).
 * Its damping beta (N m s) on the angle's speed over the substep, as XPBD's */
static void bend_block(const wb_world *w, const bend_vbd *v, int32_t q, wb_real inv_h, wb_real f[3], wb_real H[6])
{
    const int32_t b = q / 4, k = q % 4;
    if (w->bend->broken[b]) return;
    wb_real off, g[4][3];
    if (!bend_off(w, b, &off, g)) return;
    const wb_real a = w->bend->alpha[b], *gk = g[k];
    wb_real kb = a > 0 ? 1 / a : v->bkpen[b], fm = a > 0 ? kb * off : kb * (off - v->btg[b]) + v->blam[b];
    const wb_real beta = w->bend->beta[b];
    if (a > 0 && beta > 0) {
        const int32_t *p = &w->bend->ij[4 * b];
        wb_real rel = 0;
        for (int c = 0; c < 4; c++) {
            wb_real u[3];
            v3_sub(u, &w->s.x[3 * p[c]], &w->s.x_prev[3 * p[c]]);
            rel += v3_dot(g[c], u);
        }
        fm += beta * rel * inv_h;
        kb += beta * inv_h;
    }
    v3_madd(f, gk, -fm);
    H[0] += kb * gk[0] * gk[0], H[1] += kb * gk[1] * gk[1], H[2] += kb * gk[2] * gk[2];
    H[3] += kb * gk[0] * gk[1], H[4] += kb * gk[0] * gk[2], H[5] += kb * gk[1] * gk[2];
}

/* a hard bend's penalty: the inertia of its angle, 1 / (h^2 w sum |g|^2), with w its
 * lightest movable corner's inverse mass over all four corners. Over the movable corners
 * alone (sum w |g|^2) it grew without bound where they barely turn the angle (a row of
 * pins along a cloth's edge: a hinge corner's gradient near 0), and the multiplier with it:
 * a 9 x 9 cloth hung by an edge blew up in 5 frames */
static wb_real bend_start_penalty(const wb_world *w, int32_t b, const wb_real g[4][3], wb_real inv_h2)
{
    const int32_t *p = &w->bend->ij[4 * b];
    wb_real wm = 0, gg = 0;
    for (int c = 0; c < 4; c++) {
        wm = w->m.w[p[c]] > wm ? w->m.w[p[c]] : wm;
        gg += v3_dot(g[c], g[c]);
    }
    return wm * gg > 0 ? inv_h2 / (wm * gg) : 0;
}

static int hard_bend(const wb_world *w, int32_t b) { return !w->bend->broken[b] && !(w->bend->alpha[b] > 0); }

/* each hard bend's penalty and the error it keeps this substep, as the hard links' (distance.c):
 * measured where the substep starts (x_prev), not at the sweeps' start: kept from the
 * prediction, a bend took its swing in as error and the multiplier fed it back (the strip
 * with rigid bends blew up within 5 s at any penalty). It keeps WB_VBD_STAB of it per
 * VBD_STAB_T of time, not per substep: the multiplier integrates what is not kept, and at
 * 0.999 a substep the strip at 40 x 1 (the rate 4 times the default's, 2.4 /s against
 * its drag of 2 /s) swung up to 0.6 m in 50 s; so it held within 1.3 mm */
static void bvbd_begin(wb_world *w, void *part, wb_real h)
{
    bend_vbd *v = part;
    const wb_real inv_h2 = 1 / (h * h), keep = pow(WB_VBD_STAB, h / VBD_STAB_T);
    for (int32_t b = 0; b < wb_bend_count(w); b++) {
        wb_real off, g[4][3];
        if (!hard_bend(w, b)) continue;
        if (!bend_off_at(w, w->s.x_prev, b, &off, g)) { /* degenerate: no penalty this substep */
            v->bkpen[b] = v->btg[b] = 0;
            continue;
        }
        v->bkpen[b] = VBD_BEND_K * bend_start_penalty(w, b, g, inv_h2);
        const wb_real ce = v->bc0[b];
        const wb_real c0 = !isfinite(ce) ? 0 : off * ce <= 0 ? 0 : fabs(off) < fabs(ce) ? off : ce;
        v->btg[b] = keep * c0;
    }
}

/* a hard bend's multiplier after each sweep, as a hard link's after the last (distance.c); its torque (what force() and
 * break_torque read, XPBD's multiplier lambda = -torque h^2) is the multiplier */
static void bvbd_dual(wb_world *w, void *part, wb_real h, int last)
{
    (void)last;
    bend_vbd *v = part;
    wb_bends *bs = w->bend;
    for (int32_t b = 0; b < wb_bend_count(w); b++) {
        wb_real off, g[4][3];
        if (!hard_bend(w, b) || !bend_off(w, b, &off, g)) continue;
        v->blam[b] += v->bkpen[b] * (off - v->btg[b]);
        v->bc0[b] = off;
        if (!bs->dirty) bs->lambda[bs->pack[b]] = -v->blam[b] * h * h;
    }
}

static void bvbd_vertex(const wb_world *w, const void *part, const int32_t *vert, int32_t n, wb_real inv_h, wb_real *f,
                        wb_real *H)
{
    const bend_vbd *v = part;
    for (int32_t k = 0; k < n; k++)
        for (int32_t e = v->at.start[vert[k]]; e < v->at.start[vert[k] + 1]; e++)
            bend_block(w, v, v->at.adj[e], inv_h, &f[3 * k], &H[6 * k]);
}

/* what force() and break_torque read of a soft bend, off / alpha (a hard one's:
 * bvbd_dual) */
static void bvbd_end(wb_world *w, void *part, wb_real h)
{
    (void)part;
    wb_bends *bs = w->bend;
    if (!bs || bs->dirty) return;
    const wb_real h2 = h * h;
    for (int32_t b = 0; b < bs->n; b++) {
        wb_real off, g[4][3];
        if (bs->broken[b] || !(bs->alpha[b] > 0)) continue;
        bs->lambda[bs->pack[b]] = bend_off(w, b, &off, g) ? -off / bs->alpha[b] * h2 : 0;
    }
}

static void bvbd_save(void *part)
{
    bend_vbd *v = part;
    wb__vbd_keep(v->save, v->blam, v->bc0, v->cap, 0);
}

static void bvbd_undo(void *part)
{
    bend_vbd *v = part;
    wb__vbd_keep(v->save, v->blam, v->bc0, v->cap, 1);
}

static wb_status bvbd_image_save(const wb_world *w, const void *part, wb_image *g, int stale)
{
    (void)stale;
    const bend_vbd *v = part;
    const int32_t nb = wb_bend_count(w);
    if (nb == 0) return WB_OK;
    g->vbd_blam = malloc(sizeof(wb_real) * (size_t)nb), g->vbd_bc0 = malloc(sizeof(wb_real) * (size_t)nb);
    if (!g->vbd_blam || !g->vbd_bc0) return WB_ERR_NOMEM;
    g->vbd_nb = nb;
    for (int32_t b = 0; b < nb; b++) {
        g->vbd_blam[b] = b < v->cap ? v->blam[b] : 0;
        g->vbd_bc0[b] = b < v->cap ? v->bc0[b] : (wb_real)NAN;
    }
    return WB_OK;
}

static const char *bvbd_image_check(const wb_image *g)
{
    return wb__vbd_half_check(g->vbd_nb, g->bend.n, g->vbd_blam, g->vbd_bc0, "VBD bend multipliers: one per bend");
}

static wb_status bvbd_image_put(void *part, const wb_image *g)
{
    bend_vbd *v = part;
    const size_t nb = (size_t)(g->vbd_nb > 0 ? g->vbd_nb : 1);
    v->blam = malloc(sizeof *v->blam * nb), v->bkpen = calloc(nb, sizeof *v->bkpen);
    v->btg = calloc(nb, sizeof *v->btg), v->bc0 = malloc(sizeof *v->bc0 * nb);
    if (!v->blam || !v->bkpen || !v->btg || !v->bc0) return WB_ERR_NOMEM;
    if (g->vbd_nb) {
        memcpy(v->blam, g->vbd_blam, sizeof *v->blam * (size_t)g->vbd_nb);
        memcpy(v->bc0, g->vbd_bc0, sizeof *v->bc0 * (size_t)g->vbd_nb);
    }
    v->cap = g->vbd_nb;
    return WB_OK;
}

static const wb_vbd_type bend_vbd_hooks = {
    .make = bvbd_make,
    .free = bvbd_free,
    .slots = bvbd_slots,
    .build = bvbd_build,
    .neighbours = bvbd_neighbours,
    .holds = bvbd_holds,
    .vertex = bvbd_vertex,
    .begin = bvbd_begin,
    .dual = bvbd_dual,
    .end = bvbd_end,
    .save = bvbd_save,
    .undo = bvbd_undo,
    .image_save = bvbd_image_save,
    .image_check = bvbd_image_check,
    .image_put = bvbd_image_put,
};

const wb_ctype wb__bend_type = {
    .name = "bend",
    .count = bend_count,
    .prepare = bend_prepare,
    .substep_begin = bend_substep_begin,
    .project = bend_project,
    .frame_end = bend_frame_end,
    .energy = bend_energy,
    .links = bend_links,
    .joins = bend_joins,
    .destroy = bend_destroy,
    .charged = bend_charged,
    .stats = bend_stats,
    .hash = bend_hash,
    .image_free = bend_image_free,
    .image_save = bend_image_save,
    .image_check = bend_image_check,
    .image_reserve = bend_image_reserve,
    .image_put = bend_image_put,
    .residual = bend_residual,
    .vbd = &bend_vbd_hooks,
};

/* ---- hinges of a triangle list ----------------------------------------------------------------- */
typedef struct hedge { int32_t lo, hi, u, v, opp, t; } hedge;

static int cmp_hedge(const void *pa, const void *pb)
{
    const hedge *a = pa, *b = pb;
    if (a->lo != b->lo) return a->lo < b->lo ? -1 : 1;
    if (a->hi != b->hi) return a->hi < b->hi ? -1 : 1;
    return a->t < b->t ? -1 : a->t > b->t; /* (lo, hi, t) is unique: a total order, so any qsort agrees */
}

int32_t wb__bend_hinges(const int32_t *tri, int32_t ntri, int32_t *out)
{
    hedge *e = malloc(sizeof *e * 3 * (size_t)(ntri > 0 ? ntri : 1));
    if (!e) return -1;
    for (int32_t t = 0; t < ntri; t++)
        for (int k = 0; k < 3; k++) {
            const int32_t u = tri[3 * t + k], v = tri[3 * t + (k + 1) % 3], o = tri[3 * t + (k + 2) % 3];
            hedge h = { u < v ? u : v, u < v ? v : u, u, v, o, t };
            e[3 * t + k] = h;
        }
    qsort(e, 3 * (size_t)ntri, sizeof *e, cmp_hedge);
    int32_t n = 0;
    for (int32_t i = 0; i < 3 * ntri;) {
        int32_t j = i + 1;
        while (j < 3 * ntri && e[j].lo == e[i].lo && e[j].hi == e[i].hi) j++;
        /* exactly two triangles: an interior edge (a border has one, a non-manifold edge more) */
        if (j - i == 2 && e[i].opp != e[i + 1].opp) {
            /* hinge in the first triangle's winding: (p1, p2, p3) and (p2, p1, p4) */
            out[4 * n] = e[i].u;
            out[4 * n + 1] = e[i].v;
            out[4 * n + 2] = e[i].opp;
            out[4 * n + 3] = e[i + 1].opp;
            n++;
        }
        i = j;
    }
    free(e);
    return n;
}
