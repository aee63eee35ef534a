/* momentum.c: the constraint solve keeps each free body's angular momentum.
 *
 * Every projection moves its particles mass-weighted along the gradient of a constraint
 * that does not change under rotation, so it conserves linear and angular momentum about
 * the positions it was computed at. Jacobi computes them all at the predicted positions
 * x~ = x_prev + h v and conserves both exactly over the solve. Gauss-Seidel computes each
 * at positions the earlier projections of the sweep have already moved: linear momentum
 * is still exact, angular momentum about x~ is off by the sum over constraints of
 * m (moved - x~) x correction, second order in the corrections. That is nothing while the
 * corrections are small, but a body held strained (a block squeezed by a press, whose
 * links are corrected by centimetres every substep and pushed back by the contacts) gets
 * the same torque every substep. Frictionless contacts cannot take it out: the pressed
 * block spins up (measured: a 5 x 5 x 5 lattice held at 80% of its height, 1 kg, reached
 * an angular momentum of 4.6 N m s and 13 m/s in 5 s; a single cube of 8 particles does
 * it too), its stored elastic energy turns into rotation, and a spinning, strained block
 * is thrown out from under the press.
 *
 * So after the solve, each connected body that nothing outside the solve holds (no
 * immovable or pinned particle, no attachment, no grab) and that touches no particle (in
 * touch after the solve) and no rigid body gets the rigid rotation, about its centre of
 * mass at x~, that takes its angular momentum back to what it was:
 * with r = x~ - c and d = x - x~, L = sum m r x d, I = sum m (|r|^2 E - r r^T),
 * w = I^-1 L and x -= w x r, so that sum m r x (d - w x r) = L - I w = 0, and
 * sum m w x r = 0 keeps the linear momentum. Pinned bodies are left alone: their pins
 * take torques, and the solve's correction of a pinned body is not internal. So are bodies
 * touching particles (below): their contacts' friction holds their parts together and
 * takes such torques as the colliders' friction does, while a rigid turn would slip at each
 * of their contacts (measured: scripts/cloth_heap.lua's self-colliding heap, turned so,
 * never came to rest). Colliders with friction were measured no trouble: a block squeezed
 * between planes of friction 0.5 moves at 0.6 m/s at most with the turn, 0.4 without.
 *
 * Bodies (connected components of the constraints of every type) are found again when the
 * topology changed; which of them something holds is worked out every step (pins,
 * attachments and grabs change between steps). Serial, in particle order: the same bits
 * for any thread count. */
#include <stdlib.h>

#include "ctype.h"
#include "pressure.h"
#include "rigid.h"
#include "shape_match.h"
#include "contact.h"
#include "tricontact.h"

/* per body: 0 mass, 1-3 sum m r, 4-6 sum m r x d, 7-9 sum m d, 10-15 sum m r r^T
 * (xx yy zz xy xz yz), r about the body's first particle (no cancellation far from the
 * origin) */
#define ACC 16

static int grow(void **p, int32_t *cap, int64_t need, size_t elem)
{
    if (need <= *cap) return 1;
    int64_t c = *cap > 0 ? *cap : 16;
    while (c < need) c *= 2;
    if (c > INT32_MAX) return 0;
    void *q = realloc(*p, (size_t)c * elem);
    if (!q) return 0;
    *p = q;
    *cap = (int32_t)c;
    return 1;
}

static int32_t find(int32_t *parent, int32_t i)
{
    while (parent[i] != i) {
        parent[i] = parent[parent[i]];
        i = parent[i];
    }
    return i;
}

static void unite(int32_t *parent, int32_t a, int32_t b)
{
    a = find(parent, a);
    b = find(parent, b);
    /* the smaller index is the root: a body's root is its first particle */
    if (a < b) parent[b] = a;
    else if (b < a) parent[a] = b;
}

static void unite_pair(void *parent, int32_t a, int32_t b, int joined)
{
    (void)joined;
    unite(parent, a, b);
}

/* what the bodies depend on, besides the distance topology (m.topology_dirty) */
static void signature(const wb_world *w, int64_t sig[8])
{
    sig[0] = w->m.np;
    sig[1] = wb_bend_count(w);
    sig[2] = wb_volume_count(w);
    sig[3] = wb_tet_count(w);
    sig[4] = wb_shape_match_count(w);
    sig[5] = wb__shape_match_members(w);
    sig[6] = wb_pressure_count(w);
    sig[7] = wb__pressure_vertices(w);
}

static int build(wb_world *w)
{
    wb_cache *k = &w->k;
    const wb_model *m = &w->m;
    const int32_t np = m->np;
    if (!grow((void **)&k->mc_body, &k->cap_mc_body, np, sizeof(int32_t))) return 0;
    int32_t *parent = k->mc_body;
    for (int32_t i = 0; i < np; i++) parent[i] = i;
    /* each type's pairs that make one body (its joins hook) */
    for (int t = 0; t < wb__nctypes; t++)
        if (wb__ctypes[t]->joins) wb__ctypes[t]->joins(w, unite_pair, parent);
    /* number the bodies of two or more particles in order of their first particle; a
     * particle alone (no constraint) is nobody's: -1 */
    int32_t nb = 0;
    for (int32_t i = 0; i < np; i++) parent[i] = find(parent, i);
    /* members counted at their root */
    if (!grow((void **)&k->mc_root, &k->cap_mc_root, np, sizeof(int32_t))) return 0;
    int32_t *cnt = k->mc_root;
    for (int32_t i = 0; i < np; i++) cnt[i] = 0;
    for (int32_t i = 0; i < np; i++) cnt[parent[i]]++;
    for (int32_t i = 0; i < np; i++) {
        const int32_t r = parent[i];
        /* the root comes first (it is the least index): its count becomes the body's
         * number, coded below 0, which its later members read */
        if (r == i) cnt[i] = cnt[i] >= 2 ? -1 - nb++ : 0;
        parent[i] = cnt[r] < 0 ? -1 - cnt[r] : -1;
    }
    /* each body's first particle, the reference of its sums, and one past its last when
     * they are consecutive (sizes counted in end first, then checked) */
    for (int32_t i = np - 1; i >= 0; i--)
        if (parent[i] >= 0) cnt[parent[i]] = i;
    if (!grow((void **)&k->mc_end, &k->cap_mc_end, nb > 0 ? nb : 1, sizeof(int32_t))) return 0;
    int32_t *end = k->mc_end;
    for (int32_t b = 0; b < nb; b++) end[b] = 0;
    for (int32_t i = 0; i < np; i++)
        if (parent[i] >= 0) end[parent[i]]++;
    /* consecutive: no particle past first + size (a body's first is its least) */
    for (int32_t i = 0; i < np; i++) {
        const int32_t b = parent[i];
        if (b >= 0 && end[b] > 0 && i >= cnt[b] + end[b]) end[b] = -end[b];
    }
    k->mc_scattered = 0;
    for (int32_t b = 0; b < nb; b++) {
        end[b] = end[b] > 0 ? cnt[b] + end[b] : -1;
        k->mc_scattered += end[b] < 0;
    }
    k->mc_nbody = nb;
    if (!grow((void **)&k->mc_acc, &k->cap_mc_acc, (int64_t)ACC * (nb > 0 ? nb : 1), sizeof(double))) return 0;
    if (!grow((void **)&k->mc_pinned, &k->cap_mc_pinned, nb > 0 ? nb : 1, 1)) return 0;
    k->mc_wgen = w->m.w_gen - 1; /* the pins: found in prepare */
    signature(w, k->mc_sig);
    k->mc_built = 1;
    return 1;
}

/* an anchors hook's particle (ud: the world's cache): its body is held */
static void held(void *ud, int32_t p, int32_t q, int joined)
{
    (void)q, (void)joined;
    wb_cache *k = ud;
    if (k->mc_body[p] >= 0) k->mc_acc[ACC * k->mc_body[p]] = -1;
}

/* once per step, before the types' prepare (which clears m.topology_dirty): the bodies
 * when the topology changed, then which of them something outside the solve holds
 * (their acc[0] set to -1). 0 when out of memory (then nothing is restored this step) */
int wb__momentum_prepare(wb_world *w)
{
    wb_cache *k = &w->k;
    int64_t sig[8];
    signature(w, sig);
    if (!k->mc_built || w->m.topology_dirty || memcmp(sig, k->mc_sig, sizeof sig)) {
        k->mc_built = 0;
        k->mc_changed = 1; /* (solver.c's blow-up check: constraints were made) */
        if (!build(w)) return 0;
    }
    double *acc = k->mc_acc;
    const int32_t *body = k->mc_body;
    /* the bodies with a pin, again only when m.w changed (pin, unpin, a snapshot: m.w_gen;
     * a new particle: the bodies above; a walk over every particle cost 0.5% of the
     * 128 x 128 cloth's frame) */
    if (k->mc_wgen != w->m.w_gen) {
        for (int32_t b = 0; b < k->mc_nbody; b++) k->mc_pinned[b] = 0;
        for (int32_t i = 0; i < w->m.np; i++)
            if (body[i] >= 0 && !(w->m.w[i] > 0)) k->mc_pinned[body[i]] = 1;
        k->mc_wgen = w->m.w_gen;
    }
    for (int32_t b = 0; b < k->mc_nbody; b++) acc[ACC * b] = k->mc_pinned[b] ? -1 : 0;
    for (int t = 0; t < wb__nctypes; t++)
        if (wb__ctypes[t]->anchors) wb__ctypes[t]->anchors(w, held, k);
    k->mc_free = 0;
    for (int32_t b = 0; b < k->mc_nbody; b++) k->mc_free += acc[ACC * b] == 0;
    return 1;
}

/* the sums of particles [i0, i1) of a body whose first particle is o into A (see ACC) */
static inline void accumulate(double *restrict A, const wb_real *restrict x, const wb_real *restrict xp,
                              const wb_real *restrict v, const wb_real *restrict wv, wb_real h, int32_t o,
                              int32_t i0, int32_t i1)
{
    double s[ACC];
    for (int c = 0; c < ACC; c++) s[c] = A[c];
    const wb_real o0 = xp[3 * o] + h * v[3 * o], o1 = xp[3 * o + 1] + h * v[3 * o + 1],
                  o2 = xp[3 * o + 2] + h * v[3 * o + 2];
    const wb_real oc[3] = { o0, o1, o2 };
    for (int32_t i = i0; i < i1; i++) {
        const double m = 1 / wv[i];
        double r[3], d[3];
        for (int c = 0; c < 3; c++) {
            /* x~ as the prediction made it (x_prev + h v, the same operations) */
            const wb_real xt = xp[3 * i + c] + h * v[3 * i + c];
            r[c] = (double)xt - (double)oc[c];
            d[c] = (double)x[3 * i + c] - (double)xt;
        }
        s[0] += m;
        for (int c = 0; c < 3; c++) s[1 + c] += m * r[c];
        s[4] += m * (r[1] * d[2] - r[2] * d[1]);
        s[5] += m * (r[2] * d[0] - r[0] * d[2]);
        s[6] += m * (r[0] * d[1] - r[1] * d[0]);
        for (int c = 0; c < 3; c++) s[7 + c] += m * d[c];
        s[10] += m * r[0] * r[0];
        s[11] += m * r[1] * r[1];
        s[12] += m * r[2] * r[2];
        s[13] += m * r[0] * r[1];
        s[14] += m * r[0] * r[2];
        s[15] += m * r[1] * r[2];
    }
    for (int c = 0; c < ACC; c++) A[c] = s[c];
}

/* A run of a body's consecutive particles [i0, i1) is summed in 4 interleaved partial
 * sums (particle i0 + 4 q + l into lane l), added to A lane after lane: 4 particles at a
 * time with AVX2, each lane doing the scalar operations in the scalar order (no FMA:
 * -ffp-contract=off), so either path gives the same bits. (The restore was 5% of a 21^3
 * tet block's frame, summed one particle after another.) */
#if defined(__x86_64__) && defined(__GNUC__) && !defined(WB_FLOAT)
#define WB_MOMENTUM_AVX2 1
#include <immintrin.h>

/* 4 consecutive particles' rows (12 doubles from p) as x, y, z lanes, and back */
static inline __attribute__((always_inline, target("avx2"))) void
load_rows4(const double *p, __m256d *X, __m256d *Y, __m256d *Z)
{
    const __m256d a = _mm256_loadu_pd(p), b = _mm256_loadu_pd(p + 4), c = _mm256_loadu_pd(p + 8);
    const __m256d P = _mm256_permute2f128_pd(a, b, 0x30), Q = _mm256_permute2f128_pd(a, c, 0x21),
                  R = _mm256_permute2f128_pd(b, c, 0x30);
    *X = _mm256_shuffle_pd(P, Q, 0xA);
    *Y = _mm256_shuffle_pd(P, R, 0x5);
    *Z = _mm256_shuffle_pd(Q, R, 0xA);
}

static inline __attribute__((always_inline, target("avx2"))) void
store_rows4(double *p, __m256d X, __m256d Y, __m256d Z)
{
    const __m256d P = _mm256_unpacklo_pd(X, Y), Q = _mm256_shuffle_pd(Z, X, 0xA), R = _mm256_unpackhi_pd(Y, Z);
    _mm256_storeu_pd(p, _mm256_permute2f128_pd(P, Q, 0x20));
    _mm256_storeu_pd(p + 4, _mm256_permute2f128_pd(R, P, 0x30));
    _mm256_storeu_pd(p + 8, _mm256_permute2f128_pd(Q, R, 0x31));
}

/* particles i .. i + 3: their x rows as lanes, and x~ as the prediction made it */
static inline __attribute__((always_inline, target("avx2"))) void
load_group(const double *x, const double *xp, const double *v, __m256d H, int32_t i, __m256d X[3], __m256d T[3])
{
    __m256d P[3], V[3];
    load_rows4(&x[3 * i], &X[0], &X[1], &X[2]);
    load_rows4(&xp[3 * i], &P[0], &P[1], &P[2]);
    load_rows4(&v[3 * i], &V[0], &V[1], &V[2]);
    for (int c = 0; c < 3; c++) T[c] = _mm256_add_pd(P[c], _mm256_mul_pd(H, V[c]));
}

/* lanes[l][c] += the sums of particles i0 + 4 q + l for the whole groups of 4 in [i0, i1);
 * returns where the groups end */
static __attribute__((target("avx2"))) int32_t
accumulate_avx2(double lanes[4][ACC], const double *restrict x, const double *restrict xp,
                const double *restrict v, const double *restrict wv, double h, const double oc[3],
                int32_t i0, int32_t i1)
{
    __m256d s[ACC];
    for (int c = 0; c < ACC; c++) s[c] = _mm256_setzero_pd();
    const __m256d H = _mm256_set1_pd(h), one = _mm256_set1_pd(1);
    const __m256d O0 = _mm256_set1_pd(oc[0]), O1 = _mm256_set1_pd(oc[1]), O2 = _mm256_set1_pd(oc[2]);
    int32_t i = i0;
    for (; i + 4 <= i1; i += 4) {
        __m256d X[3], T[3];
        load_group(x, xp, v, H, i, X, T);
        const __m256d m = _mm256_div_pd(one, _mm256_loadu_pd(&wv[i]));
        const __m256d r0 = _mm256_sub_pd(T[0], O0), r1 = _mm256_sub_pd(T[1], O1), r2 = _mm256_sub_pd(T[2], O2);
        const __m256d d0 = _mm256_sub_pd(X[0], T[0]), d1 = _mm256_sub_pd(X[1], T[1]), d2 = _mm256_sub_pd(X[2], T[2]);
        s[0] = _mm256_add_pd(s[0], m);
        s[1] = _mm256_add_pd(s[1], _mm256_mul_pd(m, r0));
        s[2] = _mm256_add_pd(s[2], _mm256_mul_pd(m, r1));
        s[3] = _mm256_add_pd(s[3], _mm256_mul_pd(m, r2));
        s[4] = _mm256_add_pd(s[4], _mm256_mul_pd(m, _mm256_sub_pd(_mm256_mul_pd(r1, d2), _mm256_mul_pd(r2, d1))));
        s[5] = _mm256_add_pd(s[5], _mm256_mul_pd(m, _mm256_sub_pd(_mm256_mul_pd(r2, d0), _mm256_mul_pd(r0, d2))));
        s[6] = _mm256_add_pd(s[6], _mm256_mul_pd(m, _mm256_sub_pd(_mm256_mul_pd(r0, d1), _mm256_mul_pd(r1, d0))));
        s[7] = _mm256_add_pd(s[7], _mm256_mul_pd(m, d0));
        s[8] = _mm256_add_pd(s[8], _mm256_mul_pd(m, d1));
        s[9] = _mm256_add_pd(s[9], _mm256_mul_pd(m, d2));
        const __m256d m0 = _mm256_mul_pd(m, r0), m1 = _mm256_mul_pd(m, r1);
        s[10] = _mm256_add_pd(s[10], _mm256_mul_pd(m0, r0));
        s[11] = _mm256_add_pd(s[11], _mm256_mul_pd(m1, r1));
        s[12] = _mm256_add_pd(s[12], _mm256_mul_pd(_mm256_mul_pd(m, r2), r2));
        s[13] = _mm256_add_pd(s[13], _mm256_mul_pd(m0, r1));
        s[14] = _mm256_add_pd(s[14], _mm256_mul_pd(m0, r2));
        s[15] = _mm256_add_pd(s[15], _mm256_mul_pd(m1, r2));
    }
    for (int c = 0; c < ACC; c++) {
        double t[4];
        _mm256_storeu_pd(t, s[c]);
        for (int l = 0; l < 4; l++) lanes[l][c] += t[l];
    }
    return i;
}

/* turn on whole groups of 4 in [i0, i1); returns where they end */
static __attribute__((target("avx2"))) int32_t
turn_avx2(const double *restrict A, double *restrict x, const double *restrict xp, const double *restrict v,
          double h, const double oc[3], int32_t i0, int32_t i1)
{
    const __m256d H = _mm256_set1_pd(h);
    const __m256d O0 = _mm256_set1_pd(oc[0]), O1 = _mm256_set1_pd(oc[1]), O2 = _mm256_set1_pd(oc[2]);
    const __m256d C0 = _mm256_set1_pd(A[1]), C1 = _mm256_set1_pd(A[2]), C2 = _mm256_set1_pd(A[3]);
    const __m256d W0 = _mm256_set1_pd(A[4]), W1 = _mm256_set1_pd(A[5]), W2 = _mm256_set1_pd(A[6]);
    int32_t i = i0;
    for (; i + 4 <= i1; i += 4) {
        __m256d X[3], T[3];
        load_group(x, xp, v, H, i, X, T);
        const __m256d r0 = _mm256_sub_pd(_mm256_sub_pd(T[0], O0), C0), r1 = _mm256_sub_pd(_mm256_sub_pd(T[1], O1), C1),
                      r2 = _mm256_sub_pd(_mm256_sub_pd(T[2], O2), C2);
        X[0] = _mm256_sub_pd(X[0], _mm256_sub_pd(_mm256_mul_pd(W1, r2), _mm256_mul_pd(W2, r1)));
        X[1] = _mm256_sub_pd(X[1], _mm256_sub_pd(_mm256_mul_pd(W2, r0), _mm256_mul_pd(W0, r2)));
        X[2] = _mm256_sub_pd(X[2], _mm256_sub_pd(_mm256_mul_pd(W0, r1), _mm256_mul_pd(W1, r0)));
        store_rows4(&x[3 * i], X[0], X[1], X[2]);
    }
    return i;
}
#endif

static int simd_state = -1;

/* tests: on = 0 forces the scalar runs (distance.c's wb__distance_simd); returns the state */
int wb__momentum_simd(int on);
int wb__momentum_simd(int on) { return wb__simd_set(&simd_state, on); }

static void accumulate_run(double *restrict A, const wb_real *restrict x, const wb_real *restrict xp,
                           const wb_real *restrict v, const wb_real *restrict wv, wb_real h, int32_t i0, int32_t i1)
{
    double lanes[4][ACC] = { { 0 } };
    int32_t i = i0;
#ifdef WB_MOMENTUM_AVX2
    int on = __atomic_load_n(&simd_state, __ATOMIC_RELAXED);
    if (on < 0) on = wb__momentum_simd(1);
    if (on) {
        const double oc[3] = { xp[3 * i0] + h * v[3 * i0], xp[3 * i0 + 1] + h * v[3 * i0 + 1],
                               xp[3 * i0 + 2] + h * v[3 * i0 + 2] };
        i = accumulate_avx2(lanes, x, xp, v, wv, h, oc, i0, i1);
    }
#endif
    for (; i < i1; i++) accumulate(lanes[(i - i0) & 3], x, xp, v, wv, h, i0, i, i + 1);
    for (int l = 0; l < 4; l++)
        for (int c = 0; c < ACC; c++) A[c] += lanes[l][c];
}

/* particles [i0, i1) of a body whose first particle is o turned by -w about its centre
 * (A: c in 1-3, w in 4-6) */
static inline void turn(const double *restrict A, wb_real *restrict x, const wb_real *restrict xp,
                        const wb_real *restrict v, wb_real h, int32_t o, int32_t i0, int32_t i1)
{
    const wb_real oc[3] = { xp[3 * o] + h * v[3 * o], xp[3 * o + 1] + h * v[3 * o + 1], xp[3 * o + 2] + h * v[3 * o + 2] };
    const double c0 = A[1], c1 = A[2], c2 = A[3], w0 = A[4], w1 = A[5], w2 = A[6];
    for (int32_t i = i0; i < i1; i++) {
        const double r0 = (double)(xp[3 * i] + h * v[3 * i]) - (double)oc[0] - c0;
        const double r1 = (double)(xp[3 * i + 1] + h * v[3 * i + 1]) - (double)oc[1] - c1;
        const double r2 = (double)(xp[3 * i + 2] + h * v[3 * i + 2]) - (double)oc[2] - c2;
        x[3 * i] -= (wb_real)(w1 * r2 - w2 * r1);
        x[3 * i + 1] -= (wb_real)(w2 * r0 - w0 * r2);
        x[3 * i + 2] -= (wb_real)(w0 * r1 - w1 * r0);
    }
}

static void turn_run(const double *restrict A, wb_real *restrict x, const wb_real *restrict xp,
                     const wb_real *restrict v, wb_real h, int32_t i0, int32_t i1)
{
    int32_t i = i0;
#ifdef WB_MOMENTUM_AVX2
    if (__atomic_load_n(&simd_state, __ATOMIC_RELAXED) > 0) {
        const double oc[3] = { xp[3 * i0] + h * v[3 * i0], xp[3 * i0 + 1] + h * v[3 * i0 + 1],
                               xp[3 * i0 + 2] + h * v[3 * i0 + 2] };
        i = turn_avx2(A, x, xp, v, h, oc, i0, i1);
    }
#endif
    turn(A, x, xp, v, h, i0, i, i1);
}

void wb__turn_rate(const double S[6], const double L[3], double om[3])
{
    const double xx = S[0], yy = S[1], zz = S[2], xy = S[3], xz = S[4], yz = S[5], tr = xx + yy + zz;
    /* a set on a line has no inertia about it (and no torque about it either): the tiny
     * regularisation only keeps the solve finite */
    const double reg = 1e-12 * tr;
    const double I[9] = { yy + zz + reg, -xy, -xz, -xy, xx + zz + reg, -yz, -xz, -yz, xx + yy + reg };
    const double det = I[0] * (I[4] * I[8] - I[5] * I[7]) - I[1] * (I[3] * I[8] - I[5] * I[6]) +
                       I[2] * (I[3] * I[7] - I[4] * I[6]);
    om[0] = om[1] = om[2] = 0;
    if (det > 0 && isfinite(det)) {
        const double inv[9] = { I[4] * I[8] - I[5] * I[7], I[2] * I[7] - I[1] * I[8], I[1] * I[5] - I[2] * I[4],
                                I[5] * I[6] - I[3] * I[8], I[0] * I[8] - I[2] * I[6], I[2] * I[3] - I[0] * I[5],
                                I[3] * I[7] - I[4] * I[6], I[1] * I[6] - I[0] * I[7], I[0] * I[4] - I[1] * I[3] };
        for (int r = 0; r < 3; r++) om[r] = (inv[3 * r] * L[0] + inv[3 * r + 1] * L[1] + inv[3 * r + 2] * L[2]) / det;
    }
    if (!(isfinite(om[0]) && isfinite(om[1]) && isfinite(om[2]))) om[0] = om[1] = om[2] = 0;
}

/* in touch, for the turn: within this much of r_i + r_j (the contacts leave a resting pair
 * at r_i + r_j to round-off) */
#define TOUCH ((wb_real)(1 + 1e-6))

/* after the solve of a substep of length h: each free body's angular momentum back to
 * what it was before the solve (see the top of the file) */
void wb__momentum_restore(wb_world *w, wb_real h)
{
    wb_cache *k = &w->k;
    if (!k->mc_built || k->mc_free == 0) return;
    const int32_t np = w->m.np, *body = k->mc_body, *root = k->mc_root;
    const wb_real *wv = w->m.w, *xp = w->s.x_prev, *v = w->s.v;
    wb_real *x = w->s.x;
    double *acc = k->mc_acc;
    for (int32_t b = 0; b < k->mc_nbody; b++)
        if (acc[ACC * b] >= 0) memset(&acc[ACC * b], 0, ACC * sizeof(double));
    /* a body whose particles touch particles (its own folds, another body: the contact
     * candidates in touch after the solve, to TOUCH) is left as the solve leaves it: the
     * contacts' friction holds its parts against each other, and a rigid turn of the whole
     * would slip at every contact, which friction then takes back as a twist of the body
     * (a self-colliding cloth heap, turned so, never comes to rest). So is one touching a
     * rigid body. A candidate merely near changes nothing: a body moves as it would
     * without contacts, to the bit (a hand-built graph's promise) */
    const wb_contacts *pc = k->pc;
    const wb_real *rad = w->m.radius;
    for (int32_t c = 0; c < pc->n; c++) {
        const int32_t i = pc->ij[2 * c], j = pc->ij[2 * c + 1];
        if ((body[i] < 0 || acc[ACC * body[i]] < 0) && (body[j] < 0 || acc[ACC * body[j]] < 0)) continue;
        const wb_real d0 = x[3 * j] - x[3 * i], d1 = x[3 * j + 1] - x[3 * i + 1], d2 = x[3 * j + 2] - x[3 * i + 2];
        const wb_real r = (rad[i] + rad[j]) * TOUCH;
        if (!(d0 * d0 + d1 * d1 + d2 * d2 < r * r)) continue;
        if (body[i] >= 0 && acc[ACC * body[i]] >= 0) acc[ACC * body[i]] = -2;
        if (body[j] >= 0 && acc[ACC * body[j]] >= 0) acc[ACC * body[j]] = -2;
    }
    const wb_tricontacts *tc = k->tc;
    for (int32_t c = 0; c < tc->n; c++) {
        const int32_t t = tc->pt[2 * c + 1], pts[4] = { tc->pt[2 * c], w->m.tri[3 * t], w->m.tri[3 * t + 1], w->m.tri[3 * t + 2] };
        for (int e = 0; e < 4; e++)
            if (body[pts[e]] >= 0 && acc[ACC * body[pts[e]]] >= 0) acc[ACC * body[pts[e]]] = -2;
    }
    if (w->rb)
        for (int32_t c = 0; c < w->rb->npct; c++)
            if (body[w->rb->pc[2 * c]] >= 0 && acc[ACC * body[w->rb->pc[2 * c]]] >= 0) acc[ACC * body[w->rb->pc[2 * c]]] = -2;
    /* a body of consecutive particles (a builder's) summed in one run, in registers; the
     * others particle by particle; either way in particle order, the same bits */
    const int32_t *end = k->mc_end;
    for (int32_t b = 0; b < k->mc_nbody; b++)
        if (acc[ACC * b] >= 0 && end[b] >= 0) accumulate_run(&acc[ACC * b], x, xp, v, wv, h, root[b], end[b]);
    for (int32_t i = 0; k->mc_scattered > 0 && i < np; i++) {
        const int32_t b = body[i];
        if (b < 0 || acc[ACC * b] < 0 || end[b] >= 0) continue;
        accumulate(&acc[ACC * b], x, xp, v, wv, h, root[b], i, i + 1);
    }
    /* per body: the centre c (relative to its root), w = I^-1 L about c, kept in A[1..6] */
    for (int32_t b = 0; b < k->mc_nbody; b++) {
        double *A = &acc[ACC * b];
        if (!(A[0] > 0)) continue;
        const double M = A[0], c[3] = { A[1] / M, A[2] / M, A[3] / M };
        /* L about c: sum m (r - c) x d = sum m r x d - c x sum m d */
        const double L[3] = { A[4] - (c[1] * A[9] - c[2] * A[8]), A[5] - (c[2] * A[7] - c[0] * A[9]),
                              A[6] - (c[0] * A[8] - c[1] * A[7]) };
        /* second moments about c, then the inertia tensor */
        const double xx = A[10] - M * c[0] * c[0], yy = A[11] - M * c[1] * c[1], zz = A[12] - M * c[2] * c[2];
        const double xy = A[13] - M * c[0] * c[1], xz = A[14] - M * c[0] * c[2], yz = A[15] - M * c[1] * c[2];
        const double S[6] = { xx, yy, zz, xy, xz, yz };
        double om[3];
        wb__turn_rate(S, L, om);
        A[1] = c[0]; A[2] = c[1]; A[3] = c[2];
        A[4] = om[0]; A[5] = om[1]; A[6] = om[2];
    }
    for (int32_t b = 0; b < k->mc_nbody; b++)
        if (acc[ACC * b] > 0 && end[b] >= 0) turn_run(&acc[ACC * b], x, xp, v, h, root[b], end[b]);
    for (int32_t i = 0; k->mc_scattered > 0 && i < np; i++) {
        const int32_t b = body[i];
        if (b < 0 || !(acc[ACC * b] > 0) || end[b] >= 0) continue;
        turn(&acc[ACC * b], x, xp, v, h, root[b], i, i + 1);
    }
    /* the bodies skipped for their contacts are judged again next substep */
    for (int32_t b = 0; b < k->mc_nbody; b++)
        if (acc[ACC * b] == -2) acc[ACC * b] = 0;
}
