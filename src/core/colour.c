/* colour.c: greedy graph colouring of constraints into batches, for every type.
 *
 * No two constraints of a batch share a movable particle, so a batch can be projected
 * in parallel (and vectorised) with results identical to a serial sweep: Gauss-Seidel
 * runs batch after batch, always in the same order, whatever the thread count. A
 * constraint joins k particles (2 for a distance, 4 for a bend); the ones that find no
 * free colour among WB_MAX_COLOURS go to one last batch projected serially.
 *
 * The order the greedy colouring visits the constraints decides the batches, and a sweep
 * of one iteration, far from converged, leans the way its batches follow each other. In
 * creation order a lattice's colours drifted across it and a mirror-symmetric scene did
 * not stay symmetric (a box dropped flat and centred on a soft block turned and toppled).
 * So mirror images are coloured alike. Each constraint is keyed by where its particles
 * were created (m->x0: a snapshot colours the same) relative to the middle of its body's
 * bounds (body: what this type's constraints join): the height of its centre, the
 * distances of its centre from the vertical planes through the middle square to x and to
 * z, its extent along x, y and z, quantised (2^-30 of the scene's extent) so that mirror
 * images, equal to rounding, match. Groups of equal keys are visited one after another:
 * members that share no movable particle see mirrored colours at their ends and take the
 * same colour, so every sweep of a symmetric body is symmetric. Members that do (links
 * meeting at a particle on a mirror plane) cannot be alike; such groups are visited last,
 * so that the rest still are. y is up (not gravity's axis, which may change after the
 * colouring: a snapshot must colour as its world did). Alternating the sweep's direction
 * instead measured no better, and alternated every substep it is unstable with one
 * iteration (a rope of rigid links blew up). */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "core.h"
#include "batch.h"

/* a constraint's colour: [0, WB_MAX_COLOURS] (WB_MAX_COLOURS: the serial overflow batch),
 * or none (not live), or a compound's member */
#define NO_COLOUR 255
#define SPLIT_COLOUR 254

/* the compounds of a colouring (wb_batch_def.compounds): member (n slots) gets their
 * members compound by compound in visiting order, comp_start (n + 1 slots) the ncomp + 1
 * compound bounds into member */
typedef struct wb_split {
    int32_t n, first, ncomp; /* members, coloured constraints (visit_order's), compounds */
    int32_t *member, *comp_start;
} wb_split;

/* the visiting order: 0 creation order (tests: the colouring before mirror keys), 1 keys */
static int symmetric = 1;

int wb__colour_symmetric(int on)
{
    const int was = __atomic_load_n(&symmetric, __ATOMIC_RELAXED);
    __atomic_store_n(&symmetric, on != 0, __ATOMIC_RELAXED);
    return was;
}

enum { NKEY = 6 };
typedef struct gkey { int64_t key[NKEY]; int32_t g; } gkey;

static int gkey_cmp(const void *pa, const void *pb)
{
    const gkey *a = pa, *b = pb;
    for (int c = 0; c < NKEY; c++)
        if (a->key[c] != b->key[c]) return a->key[c] < b->key[c] ? -1 : 1;
    return (a->g > b->g) - (a->g < b->g);
}

static int32_t root(int32_t *parent, int32_t p)
{
    while (parent[p] != p) p = parent[p] = parent[parent[p]];
    return p;
}

/* v in steps of 1 / inv_q, to the nearest (v is finite: halves and differences of finite
 * positions; the clamp keeps the conversion defined) */
static int64_t quant(wb_real v, wb_real inv_q)
{
    wb_real s = v * inv_q;
    /* (NaN: 0 x an infinite scale, a scene 5e-324 across: any key will do) */
    s = s > 0x1p62 ? 0x1p62 : s < -0x1p62 ? -0x1p62 : s == s ? s : 0;
    return s >= 0 ? (int64_t)(s + (wb_real)0.5) : -(int64_t)((wb_real)0.5 - s);
}

static uint64_t key_hash(const int64_t *key)
{
    uint64_t h = 0x9e3779b97f4a7c15ull;
    for (int c = 0; c < NKEY; c++) {
        h = (h ^ (uint64_t)key[c]) * 0xbf58476d1ce4e5b9ull;
        h ^= h >> 31;
    }
    return h;
}

/* the live constraints in visiting order into order: groups of equal keys in key order
 * (from the body's bottom up, outwards from its middle: this colours the benchmark's
 * cloth in as few colours as creation order did), a group's members in creation order,
 * the groups whose members share a movable particle last. Returns how many (-1: out of
 * memory). A hash table finds the groups; only the groups are sorted. */
static int32_t visit_order(const wb_model *m, const int32_t *idx, int k, int32_t n,
                           int (*live)(const void *ud, int32_t i), const void *ud, int32_t *order,
                           wb_split *split)
{
    const int32_t np = m->np;
    const size_t npa = (size_t)(np > 0 ? np : 1), na = (size_t)(n > 0 ? n : 1);
    size_t tsize = 1;
    while (tsize < 2 * na) tsize *= 2;
    int32_t *parent = malloc(sizeof *parent * npa), *con = malloc(sizeof *con * na);
    int32_t *group = malloc(sizeof *group * na), *first = malloc(sizeof *first * (na + 1));
    int32_t *table = malloc(sizeof *table * tsize);
    int64_t *key = malloc(sizeof *key * NKEY * na);
    wb_real *box = malloc(sizeof *box * 6 * npa);
    /* (split: each particle's member in the group being split, and a union-find over them) */
    int32_t *owner = split ? malloc(sizeof *owner * npa) : NULL, *uf = split ? malloc(sizeof *uf * 3 * (na + 1)) : NULL;
    gkey *gk = NULL;
    int32_t nl = -1;
    if (!parent || !con || !group || !first || !table || !key || !box || (split && (!owner || !uf))) goto out;
    /* the bodies (union-find over the live constraints) and their bounds */
    for (int32_t p = 0; p < np; p++) parent[p] = p;
    int32_t nlive = 0;
    for (int32_t i = 0; i < n; i++) {
        if (!live(ud, i)) continue;
        con[nlive++] = i;
        const int32_t *c = &idx[(size_t)k * (size_t)i];
        for (int e = 1; e < k; e++) {
            const int32_t r0 = root(parent, c[0]), r = root(parent, c[e]);
            if (r != r0) parent[r] = r0;
        }
    }
    for (int32_t p = 0; p < np; p++)
        for (int a = 0; a < 3; a++) box[6 * p + a] = INFINITY, box[6 * p + 3 + a] = -INFINITY;
    wb_real ext = 0;
    for (int32_t p = 0; p < np; p++) {
        wb_real *b = &box[6 * root(parent, p)];
        for (int a = 0; a < 3; a++) {
            const wb_real x = m->x0[3 * p + a];
            b[a] = x < b[a] ? x : b[a];
            b[3 + a] = x > b[3 + a] ? x : b[3 + a];
            ext = fabs(x) > ext ? fabs(x) : ext;
        }
    }
    const int up = 1, ha = 2, hb = 0; /* y is up */
    int ex;
    frexp(ext > 0 ? ext : 1, &ex);
    /* steps of 2^-30 of the extent (2^-14 in float): far above rounding, far below a spacing */
    const int bits = sizeof(wb_real) == sizeof(float) ? 14 : 30;
    const wb_real inv_q = ldexp(1, bits - ex), inv_k = (wb_real)1 / k; /* powers of two for k = 2, 4 */
    /* the keys, grouped (table: each group's first member) */
    for (size_t t = 0; t < tsize; t++) table[t] = -1;
    int32_t ng = 0;
    for (int32_t j = 0; j < nlive; j++) {
        const int32_t *c = &idx[(size_t)k * (size_t)con[j]];
        const wb_real *b = &box[6 * root(parent, c[0])];
        wb_real mid[3] = { 0, 0, 0 }, spread[3] = { 0, 0, 0 }, off[3];
        for (int e = 0; e < k; e++)
            for (int a = 0; a < 3; a++) mid[a] += m->x0[3 * c[e] + a] * inv_k;
        for (int e = 0; e < k; e++)
            for (int a = 0; a < 3; a++) spread[a] += fabs(m->x0[3 * c[e] + a] - mid[a]);
        for (int a = 0; a < 3; a++) off[a] = mid[a] - (b[a] / 2 + b[3 + a] / 2);
        int64_t *kj = &key[NKEY * (size_t)j];
        kj[0] = quant(off[up], inv_q);
        kj[1] = quant(fabs(off[ha]), inv_q);
        kj[2] = quant(fabs(off[hb]), inv_q);
        kj[3] = quant(spread[up], inv_q);
        kj[4] = quant(spread[ha], inv_q);
        kj[5] = quant(spread[hb], inv_q);
        size_t t = key_hash(kj) & (tsize - 1);
        while (table[t] >= 0 && memcmp(&key[NKEY * (size_t)table[t]], kj, NKEY * sizeof *kj))
            t = (t + 1) & (tsize - 1);
        if (table[t] < 0) {
            table[t] = j;
            first[ng] = j; /* for now: the group's first member */
            group[j] = ng++;
        } else {
            group[j] = group[table[t]];
        }
    }
    /* the groups in key order: group[] becomes the group's rank */
    gk = malloc(sizeof *gk * (size_t)(ng > 0 ? ng : 1));
    if (!gk) goto out;
    for (int32_t g = 0; g < ng; g++) {
        memcpy(gk[g].key, &key[NKEY * (size_t)first[g]], sizeof gk[g].key);
        gk[g].g = g;
    }
    qsort(gk, (size_t)ng, sizeof *gk, gkey_cmp);
    int32_t *rank = table; /* reused: tsize > ng */
    for (int32_t r = 0; r < ng; r++) rank[gk[r].g] = r;
    for (int32_t j = 0; j < nlive; j++) group[j] = rank[group[j]];
    /* members by rank (a stable counting sort); first[g]: where group g starts */
    for (int32_t g = 0; g <= ng; g++) first[g] = 0;
    for (int32_t j = 0; j < nlive; j++) first[group[j] + 1]++;
    for (int32_t g = 0; g < ng; g++) first[g + 1] += first[g];
    int32_t *sorted = table; /* reused: tsize >= nlive, rank no longer needed */
    for (int32_t j = 0; j < nlive; j++) sorted[first[group[j]]++] = con[j];
    for (int32_t g = ng; g > 0; g--) first[g] = first[g - 1];
    first[0] = 0;
    /* the groups whose members share a movable particle after the others (parent now
     * marks the group that last touched a particle) */
    for (int32_t p = 0; p < np; p++) parent[p] = -1;
    int32_t nfirst = 0, nlast = 0;
    for (int32_t g = 0; g < ng; g++) {
        int shared = 0;
        for (int32_t j = first[g]; j < first[g + 1]; j++) {
            const int32_t *c = &idx[(size_t)k * (size_t)sorted[j]];
            for (int x = 0; x < k; x++) {
                if (!(m->inv_mass[c[x]] > 0)) continue;
                shared |= parent[c[x]] == g;
                parent[c[x]] = g;
            }
        }
        if (!shared) {
            for (int32_t j = first[g]; j < first[g + 1]; j++) order[nfirst++] = sorted[j];
        } else if (!split) {
            for (int32_t j = first[g]; j < first[g + 1]; j++) con[nlast++] = sorted[j];
        } else {
            /* the group's compounds: its members joined through shared movable particles,
             * each in the order of its first member, members in group order */
            const int32_t *mem = &sorted[first[g]], gn = first[g + 1] - first[g];
            for (int32_t t = 0; t < gn; t++)
                for (int x = 0; x < k; x++) owner[idx[(size_t)k * (size_t)mem[t] + (size_t)x]] = -1;
            for (int32_t t = 0; t < gn; t++) {
                uf[t] = t;
                for (int x = 0; x < k; x++) {
                    const int32_t p = idx[(size_t)k * (size_t)mem[t] + (size_t)x];
                    if (!(m->inv_mass[p] > 0)) continue;
                    if (owner[p] < 0) owner[p] = t;
                    else uf[root(uf, t)] = root(uf, owner[p]);
                }
            }
            /* compound ids in the order of first members (cid: by root, then by member),
             * then a counting sort of the members by compound */
            int32_t *cid = uf + (na + 1), *comp_of = uf + 2 * (na + 1), nc = 0;
            for (int32_t t = 0; t < gn; t++) cid[t] = -1;
            for (int32_t t = 0; t < gn; t++) {
                const int32_t r = root(uf, t);
                if (cid[r] < 0) cid[r] = nc++;
                comp_of[t] = cid[r];
            }
            int32_t *cnt = cid; /* reused: nc <= gn counters */
            for (int32_t c = 0; c <= nc; c++) cnt[c] = 0;
            for (int32_t t = 0; t < gn; t++) cnt[comp_of[t] + 1]++;
            for (int32_t c = 0; c < nc; c++) {
                cnt[c + 1] += cnt[c];
                split->comp_start[split->ncomp++] = nlast + cnt[c];
            }
            for (int32_t t = 0; t < gn; t++) con[nlast + cnt[comp_of[t]]++] = mem[t];
            nlast += gn;
        }
    }
    if (nlast > 0) memcpy(order + nfirst, con, sizeof *con * (size_t)nlast);
    if (split) {
        split->comp_start[split->ncomp] = nlast;
        split->n = nlast;
        split->first = nfirst;
    }
    nl = nlive;
out:
    free(parent);
    free(con);
    free(group);
    free(first);
    free(table);
    free(key);
    free(box);
    free(gk);
    free(owner);
    free(uf);
    return nl;
}

/* greedy colouring of the constraints live() accepts, in visiting order: the lowest colour
 * free at every movable end; colour[i] gets NO_COLOUR, SPLIT_COLOUR or the colour, counted
 * in count. 0 when out of memory */
static int colour_greedy(const wb_model *m, const int32_t *idx, int k, int32_t n,
                         int (*live)(const void *ud, int32_t i), const void *ud, uint8_t *colour,
                         int32_t count[WB_MAX_COLOURS + 1], wb_split *split)
{
    /* a bit per colour and particle: the colours its constraints already took */
    uint64_t *used = calloc((size_t)(m->np > 0 ? m->np : 1), sizeof *used);
    int32_t *order = malloc(sizeof *order * (size_t)(n > 0 ? n : 1));
    int32_t nl = 0;
    if (!used || !order) goto fail;
    if (__atomic_load_n(&symmetric, __ATOMIC_RELAXED)) {
        if (split) split->n = split->first = split->ncomp = 0;
        if ((nl = visit_order(m, idx, k, n, live, ud, order, split)) < 0) goto fail;
        if (split) {
            /* the compounds' members are not coloured */
            memcpy(split->member, order + split->first, sizeof *order * (size_t)split->n);
            nl = split->first;
        }
    } else {
        if (split) split->n = split->first = split->ncomp = 0, split->comp_start[0] = 0;
        for (int32_t i = 0; i < n; i++)
            if (live(ud, i)) order[nl++] = i;
    }
    for (int c = 0; c <= WB_MAX_COLOURS; c++) count[c] = 0;
    for (int32_t i = 0; i < n; i++) colour[i] = NO_COLOUR;
    for (int32_t j = 0; split && j < split->n; j++) colour[split->member[j]] = SPLIT_COLOUR;
    /* the lowest colour free at every end; immovable particles never conflict */
    for (int32_t j = 0; j < nl; j++) {
        const int32_t i = order[j];
        const int32_t *p = &idx[(size_t)k * (size_t)i];
        uint64_t mask = 0;
        for (int e = 0; e < k; e++)
            if (m->inv_mass[p[e]] > 0) mask |= used[p[e]];
        int c = ~mask ? __builtin_ctzll(~mask) : WB_MAX_COLOURS;
        if (c < WB_MAX_COLOURS)
            for (int e = 0; e < k; e++) used[p[e]] |= 1ull << c;
        colour[i] = (uint8_t)c;
        count[c]++;
    }
    free(used);
    free(order);
    return 1;
fail:
    free(used);
    free(order);
    return 0;
}

/* batch ranges from the counts: colour_start (ncolours + 1), the first serial batch, and
 * start[c] the first packed index of colour c; returns the packed total. Batches in colour
 * order, constraints in slot order inside each */
static int32_t colour_ranges(const int32_t count[WB_MAX_COLOURS + 1], wb_batches *b, int32_t start[WB_MAX_COLOURS + 1])
{
    int32_t nc = 0, pos = 0;
    for (int c = 0; c <= WB_MAX_COLOURS; c++) {
        start[c] = pos;
        if (count[c] > 0) {
            b->colour_start[nc++] = pos;
            if (c == WB_MAX_COLOURS) b->serial_start = nc - 1;
        }
        pos += count[c];
    }
    if (count[WB_MAX_COLOURS] == 0) b->serial_start = nc;
    b->colour_start[nc] = pos;
    b->ncolours = nc;
    return pos;
}

/* ---- batches over a permutation (batch.h) ----------------------------------------------- */
static int all_live(const void *ud, int32_t i) { (void)ud; (void)i; return 1; }

int wb__batches_make(wb_batches *b, const wb_model *m, const wb_batch_def *d, int32_t *order)
{
    const int32_t n = d->n;
    const size_t na = (size_t)(n > 0 ? n : 1);
    uint8_t *colour = malloc(na);
    int32_t count[WB_MAX_COLOURS + 1], start[WB_MAX_COLOURS + 1];
    wb_split split = { 0, 0, 0, NULL, NULL }, *sp = NULL;
    int ok = colour != NULL;
    if (ok && d->compounds) {
        /* (ncomp <= n: room for every bound up front) */
        int32_t *cs = realloc(b->comp_start, sizeof *cs * (na + 1));
        if (cs) b->comp_start = cs;
        split.member = malloc(sizeof *split.member * na);
        split.comp_start = malloc(sizeof *split.comp_start * (na + 1));
        ok = cs && split.member && split.comp_start;
        sp = &split;
    }
    ok = ok && colour_greedy(m, d->idx, d->k, n, d->live ? d->live : all_live, d->ud, colour, count, sp);
    if (ok) {
        const int32_t first = colour_ranges(count, b, start);
        for (int32_t s = 0; s < n; s++)
            if (colour[s] < SPLIT_COLOUR) order[start[colour[s]]++] = s;
        /* then the compounds, in visit_order's order */
        b->ncomp = split.ncomp;
        if (split.n > 0) memcpy(order + first, split.member, sizeof *order * (size_t)split.n);
        for (int32_t c = 0; sp && c <= split.ncomp; c++) b->comp_start[c] = first + split.comp_start[c];
        b->norder = first + split.n;
        b->n = n;
    }
    free(colour);
    free(split.member);
    free(split.comp_start);
    return ok;
}

int wb__batches_build(wb_batches *b, const wb_model *m, const int32_t *idx, int k, int32_t n, int32_t *order)
{
    const wb_batch_def d = { idx, k, n, NULL, NULL, 0 };
    return wb__batches_make(b, m, &d, order);
}

void wb__batches_free(wb_batches *b)
{
    free(b->comp_start);
    b->comp_start = NULL;
    b->ncomp = 0;
}

typedef struct batch_job {
    wb_world *w;
    wb_range_fn f;
    const int32_t *order;
    int32_t lo;
    wb_real h;
} batch_job;

static void batch_part(void *ctx, int32_t lo, int32_t hi)
{
    const batch_job *j = ctx;
    j->f(j->w, j->order, j->lo + lo, j->lo + hi, j->h);
}

void wb__batches_run(const wb_batches *b, wb_world *w, int32_t min_par, wb_range_fn f, wb_range_fn fc,
                     const int32_t *order, wb_real h)
{
    for (int32_t c = 0; c < b->ncolours; c++) {
        const int32_t lo = b->colour_start[c], hi = b->colour_start[c + 1];
        /* (the pool is asked for only here: a small scene never starts a thread) */
        wb_pool *pool = c < b->serial_start && hi - lo >= min_par ? wb__world_pool(w) : NULL;
        if (!pool) {
            f(w, order, lo, hi, h);
            continue;
        }
        batch_job j = { w, f, order, lo, h };
        wb__pool_for(pool, hi - lo, min_par / 2, batch_part, &j);
    }
    if (fc && b->ncomp > 0) fc(w, order, b->colour_start[b->ncolours], b->norder, h);
}
