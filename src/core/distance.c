/* colour.c: greedy graph colouring of the constraints into batches.
 *
 * No two constraints of a batch share a movable particle, so a batch can be projected
 * in parallel (and vectorised) with results identical to a serial sweep: Gauss-Seidel
 * runs batch after batch, always in the same order, whatever the thread count. */
#include <stdlib.h>

#include "core.h"

#define MAX_COLOURS 64 /* one bit each in a per-particle mask; the rest go to a serial batch */

static int realloc_n(void **p, int32_t n, size_t elem)
{
    void *q = realloc(*p, (size_t)(n > 0 ? n : 1) * elem);
    if (!q) return 0;
    *p = q;
    return 1;
}

wb_status wb__colour(wb_world *w)
{
    wb_model *m = &w->m;
    wb_cache *k = &w->k;
    if (!m->topology_dirty) return WB_OK;
    k->pc.keys_dirty = 1; /* the constraint pairs that self-collision skips */

    int32_t ns = 0;
    for (int32_t s = 0; s < m->nd; s++)
        if ((m->d_gen[s] & 1u) && !w->s.d_broken[s]) ns++;

    uint64_t *used = calloc((size_t)(m->np > 0 ? m->np : 1), sizeof *used);
    uint8_t *colour = malloc((size_t)(m->nd > 0 ? m->nd : 1));
    int32_t count[MAX_COLOURS + 1] = { 0 };
    if (!used || !colour ||
        !realloc_n((void **)&k->s_a, ns, sizeof(int32_t)) || !realloc_n((void **)&k->s_b, ns, sizeof(int32_t)) ||
        !realloc_n((void **)&k->s_rest, ns, sizeof(wb_real)) || !realloc_n((void **)&k->s_alpha, ns, sizeof(wb_real)) ||
        !realloc_n((void **)&k->s_beta, ns, sizeof(wb_real)) || !realloc_n((void **)&k->s_lambda, ns, sizeof(wb_real)) ||
        !realloc_n((void **)&k->s_jac, ns, sizeof(wb_real)) ||
        !realloc_n((void **)&k->s_slot, ns, sizeof(int32_t)) ||
        !realloc_n((void **)&k->colour_start, MAX_COLOURS + 2, sizeof(int32_t))) {
        free(used);
        free(colour);
        return WB_ERR_NOMEM;
    }

    /* greedy: the lowest colour free at both ends; immovable particles never conflict */
    for (int32_t s = 0; s < m->nd; s++) {
        if (!(m->d_gen[s] & 1u) || w->s.d_broken[s]) continue;
        int32_t a = m->d_ij[2 * s], b = m->d_ij[2 * s + 1];
        uint64_t mask = 0;
        if (m->inv_mass[a] > 0) mask |= used[a];
        if (m->inv_mass[b] > 0) mask |= used[b];
        int c = ~mask ? __builtin_ctzll(~mask) : MAX_COLOURS;
        if (c < MAX_COLOURS) {
            used[a] |= 1ull << c;
            used[b] |= 1ull << c;
        }
        colour[s] = (uint8_t)c;
        count[c]++;
    }

    /* batches in colour order, constraints in slot order inside each */
    int32_t nc = 0, start[MAX_COLOURS + 1], pos = 0;
    for (int c = 0; c <= MAX_COLOURS; c++) {
        start[c] = pos;
        if (count[c] > 0) {
            k->colour_start[nc++] = pos;
            if (c == MAX_COLOURS) k->serial_start = nc - 1;
        }
        pos += count[c];
    }
    if (count[MAX_COLOURS] == 0) k->serial_start = nc;
    k->colour_start[nc] = pos;
    k->ncolours = nc;
    k->ns = ns;
    k->any_damping = 0;
    for (int32_t i = 0; i < m->np; i++) k->ncount[i] = 0;
    for (int32_t s = 0; s < m->nd; s++) {
        if (!(m->d_gen[s] & 1u) || w->s.d_broken[s]) { k->slot_pack[s] = -1; continue; }
        int32_t i = start[colour[s]]++;
        int32_t a = m->d_ij[2 * s], b = m->d_ij[2 * s + 1];
        k->s_a[i] = a;
        k->s_b[i] = b;
        k->s_rest[i] = w->s.d_rest[s];
        k->s_alpha[i] = m->d_alpha[s];
        k->s_beta[i] = m->d_beta[s];
        k->s_lambda[i] = 0;
        k->s_slot[i] = s;
        k->slot_pack[s] = i;
        k->ncount[a]++;
        k->ncount[b]++;
        if (m->d_beta[s] > 0 && m->d_alpha[s] > 0) k->any_damping = 1;
    }
    /* Jacobi: a constraint's share is set by its busier movable end (an immovable
     * hub must not shrink its spokes' corrections) */
    for (int32_t i = 0; i < ns; i++) {
        const int32_t a = k->s_a[i], b = k->s_b[i];
        const int32_t na = m->inv_mass[a] > 0 ? k->ncount[a] : 1, nb = m->inv_mass[b] > 0 ? k->ncount[b] : 1;
        k->s_jac[i] = (wb_real)1 / (na > nb ? na : nb);
    }
    free(used);
    free(colour);
    m->topology_dirty = 0;
    return WB_OK;
}
