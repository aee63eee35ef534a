/* vbd_part.c: the tools the types' VBD parts share (vbd.h: wb_vbd_quads, wb__vbd_keep,
 * wb__vbd_half_check). A leaf below the types' files, which the solver (vbd.c) calls
 * through the type table. */
#include <stdlib.h>
#include <string.h>

#include "vbd.h"

size_t wb__vbd_quads_bytes(int32_t np, int32_t n)
{
    return (size_t)((int64_t)np + 1) * sizeof(int32_t) + (size_t)(4 * (int64_t)n > 0 ? 4 * (int64_t)n : 1) * sizeof(int32_t);
}

int wb__vbd_quads_build(wb_vbd_quads *a, int32_t np, const int32_t *q, int32_t n)
{
    int32_t *ts = calloc((size_t)np + 1, sizeof *ts);
    if (!ts) return 0;
    for (int64_t k = 0; k < 4 * (int64_t)n; k++) ts[q[k] + 1]++;
    for (int32_t i = 0; i < np; i++) ts[i + 1] += ts[i];
    int32_t *ta = malloc(sizeof *ta * (size_t)(ts[np] > 0 ? ts[np] : 1)), *tf = malloc(sizeof *tf * (size_t)(np > 0 ? np : 1));
    if (!ta || !tf) {
        free(ts), free(ta), free(tf);
        return 0;
    }
    memcpy(tf, ts, sizeof *tf * (size_t)np);
    for (int32_t k = 0; k < 4 * n; k++) ta[tf[q[k]]++] = k;
    free(tf);
    wb__vbd_quads_free(a);
    a->start = ts;
    a->adj = ta;
    return 1;
}

void wb__vbd_quads_free(wb_vbd_quads *a)
{
    free(a->start), free(a->adj);
    a->start = a->adj = NULL;
}

uint64_t wb__vbd_quads_colours(const wb_vbd_quads *a, const int32_t *q, int32_t i, const uint8_t *col)
{
    uint64_t used = 0;
    for (int32_t e = a->start[i]; e < a->start[i + 1]; e++) {
        const int32_t *c = &q[4 * (a->adj[e] / 4)];
        for (int k = 0; k < 4; k++)
            if (c[k] < i) used |= (uint64_t)1 << col[c[k]];
    }
    return used;
}

void wb__vbd_keep(wb_real *keep, wb_real *a, wb_real *b, int32_t n, int back)
{
    if (n <= 0 || !keep) return;
    const size_t sz = sizeof *keep * (size_t)n;
    if (back) memcpy(a, keep, sz), memcpy(b, keep + n, sz);
    else memcpy(keep, a, sz), memcpy(keep + n, b, sz);
}

const char *wb__vbd_half_check(int32_t n, int32_t want, const wb_real *lam, const wb_real *c0, const char *count)
{
    if (n != want) return count;
    for (int32_t s = 0; s < n; s++)
        if (!isfinite(lam[s]) || isinf(c0[s])) return "VBD multipliers must be finite";
    return NULL;
}
