/* fuzz_mesh.c: our side of a mesh import on any input: what wbio_load_mesh does with the
 * importer's arrays (wbio_mesh_from_arrays: scale, checks, weld), then what scripts do
 * with a mesh: edges, clustering, transforms, OBJ/PLY export, w:from_mesh, w:skin and
 * stepping. Fuzzing assimp itself is not ours to do.
 *
 * Built two ways: plain, the input is a small header and raw vertex/triangle arrays (the
 * layout below); with -DFUZZ_FORMAT='"obj"' the input after the header is a file of that
 * format read by assimp in this process (wbio_mesh_from_memory), so what assimp really
 * returns reaches the same code. libFuzzer calls LLVMFuzzerTestOneInput (`make fuzz`);
 * replay.c calls it once per file under gcc (`make test`).
 *
 * Input: 8 header bytes, then the body (missing bytes read as 0):
 *   [0] flags: 1 weld, 2 raw float32 coordinates (else int8 / 4: many coincident and
 *       collinear vertices), 4 cluster to a target, 8 k-nearest links, 16 skin,
 *       32 scale 2.5 on import and a mirrored copy; coordinates times 1e300 (64),
 *       1e-300 (128) or 5e306 (both: extents past the largest double), which no file
 *       format gives but wobble.mesh{} takes
 *   [1] vertices (mod 65)  [2] triangles (mod 129)  [3] weld tolerance (0: the default)
 *   [4] target  [5] neighbours  [6] bones  [7] skin neighbours
 *   body: coordinates (3 per vertex), then 3 corner bytes per triangle (255 is -1;
 *   else byte mod (vertices + 1), so vertices itself is out of range) */
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "io/io.h"

#define CHECK(c) do { if (!(c)) { fprintf(stderr, "fuzz_mesh: invariant failed: %s (line %d)\n", #c, __LINE__); abort(); } } while (0)

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

typedef struct input { const uint8_t *p; size_t n, at; } input;

static uint8_t byte(input *in) { return in->at < in->n ? in->p[in->at++] : 0; }

#ifndef FUZZ_FORMAT
static float f32(input *in)
{
    uint8_t b[4];
    for (int i = 0; i < 4; i++) b[i] = byte(in);
    float f;
    memcpy(&f, b, sizeof f);
    return f;
}
#endif

/* a mesh as the core promises it: corners in range and distinct, finite values, unit
 * (or zero, for a vertex no triangle touches) normals */
static void check_mesh(const wb_mesh *m)
{
    CHECK(m->nv >= 0 && m->nt >= 0);
    for (int32_t i = 0; i < m->nt; i++) {
        const int32_t *t = &m->tri[3 * i];
        for (int c = 0; c < 3; c++) CHECK(t[c] >= 0 && t[c] < m->nv);
        CHECK(t[0] != t[1] && t[1] != t[2] && t[0] != t[2]);
    }
    for (int32_t i = 0; i < m->nv; i++) {
        const wb_real *v = &m->v[3 * i], *n = &m->n[3 * i];
        CHECK(isfinite(v[0]) && isfinite(v[1]) && isfinite(v[2]));
        CHECK(isfinite(n[0]) && isfinite(n[1]) && isfinite(n[2]));
        const wb_real l = sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
        CHECK(l == 0 || fabs(l - 1) < 1e-6);
    }
}

/* particles [first, first+n) pairwise apart (squared distance > 0)? The k-d tree's callers
 * have a known problem with ties at distance 0 (another engineer's fix), coincident or
 * so close that the square underflows: the harness steers clear */
static int distinct(const wb_world *w, int32_t first, int32_t n)
{
    const wb_real *x = wb_particle_positions(w) + 3 * (size_t)first;
    for (int32_t i = 0; i < n; i++)
        for (int32_t j = i + 1; j < n; j++) {
            const wb_real d[3] = { x[3 * i] - x[3 * j], x[3 * i + 1] - x[3 * j + 1], x[3 * i + 2] - x[3 * j + 2] };
            if (!(d[0] * d[0] + d[1] * d[1] + d[2] * d[2] > 0)) return 0;
        }
    return 1;
}

static void check_world(const wb_world *w)
{
    const wb_real *x = wb_particle_positions(w);
    for (int64_t i = 0; i < 3 * (int64_t)wb_particle_count(w); i++) CHECK(isfinite(x[i]));
}

static void check_skin(wb_skin *s, const wb_world *w, int32_t nv, int bones)
{
    const wb_real *v = wb_skin_vertices(s, w), *n = wb_skin_normals(s, w);
    for (int64_t i = 0; i < 3 * (int64_t)nv; i++) CHECK(isfinite(v[i]) && isfinite(n[i]));
    for (int32_t i = 0; i < nv; i++) {
        int32_t p[16];
        wb_real wt[16], sum = 0;
        const int k = wb_skin_influences(s, i, p, wt);
        CHECK(k >= 1 && k <= bones);
        for (int j = 0; j < k; j++) {
            CHECK(p[j] >= 0 && p[j] < wb_particle_count(w));
            CHECK(wt[j] >= 0 && wt[j] <= 1);
            sum += wt[j];
        }
        CHECK(fabs(sum - 1) < 1e-9);
    }
}

/* everything a script can do with a loaded mesh */
static void use_mesh(const wb_mesh *m, uint8_t flags, const uint8_t h[8])
{
    check_mesh(m);
    CHECK(m->nt > 0); /* wbio_mesh_from_arrays refuses a mesh with no triangles left */

    int32_t *ij;
    const int32_t ne = wb_mesh_edges(m, &ij);
    CHECK(ne >= 0 && ne <= 3 * m->nt);
    for (int32_t e = 0; e < ne; e++) {
        CHECK(ij[2 * e] >= 0 && ij[2 * e] < ij[2 * e + 1] && ij[2 * e + 1] < m->nv);
        if (e) CHECK(ij[2 * e - 2] < ij[2 * e] || (ij[2 * e - 2] == ij[2 * e] && ij[2 * e - 1] < ij[2 * e + 1]));
    }
    free(ij);

    wb_real mn[3], mx[3];
    CHECK(wb_mesh_bounds(m, mn, mx));
    const int32_t target = h[4] % 40;
    if (target > 0) {
        int32_t *cl = malloc(sizeof *cl * (size_t)m->nv);
        CHECK(cl);
        const int32_t n = wb_mesh_cluster(m, target, cl);
        CHECK(n >= 1 && n <= m->nv);
        int32_t next = 0; /* numbered by first vertex */
        for (int32_t i = 0; i < m->nv; i++) {
            CHECK(cl[i] >= 0 && cl[i] <= next && cl[i] < n);
            if (cl[i] == next) next++;
        }
        CHECK(next == n);
        free(cl);
    }

    /* export to nowhere: the writers on any mesh */
    FILE *f = fopen("/dev/null", "w");
    if (f) {
        CHECK(wbio_write_obj(f, m, NULL, NULL) == 0);
        CHECK(wbio_write_ply(f, m, NULL, NULL) == 0);
        fclose(f);
    }

    wb_mesh *c = wb_mesh_copy(m);
    CHECK(c);
    const wb_real off[3] = { 1, -2, 3 };
    wb_mesh_transform(c, (flags & 32) ? -1.5 : 0.5, off);
    int fin = 1; /* a huge mesh may overflow when scaled (wb_mesh_transform has no error) */
    for (int32_t i = 0; i < 3 * c->nv; i++) fin &= isfinite(c->v[i]) != 0;
    if (fin) check_mesh(c);
    wb_mesh_destroy(c);

    /* past ~1e150 squared lengths overflow: from_mesh and skin refuse such a mesh with a
     * message (rest lengths must have finite squares); below, they must accept it */
    wb_real big = 0;
    for (int k = 0; k < 3; k++) big = fmax(big, fmax(fabs(mn[k]), fabs(mx[k])));
    const int may_refuse = big > 1e150;

    /* w:from_mesh: first without k-nearest links, to see the particles it makes */
    wb_world_def wd = wb_world_default_def();
    wb_world *w = wb_world_create(&wd);
    CHECK(w);
    wb_from_mesh_def fd = wb_from_mesh_default_def();
    fd.target = (flags & 4) ? target : 0;
    wb_body b;
    wb_status st = wb_from_mesh(w, m, &fd, &b);
    if (st == WB_ERR_ARG && may_refuse) {
        CHECK(wb_particle_count(w) == 0);   /* refused: nothing added */
        wb_world_destroy(w);
        return;
    }
    if (st != WB_OK) fprintf(stderr, "fuzz_mesh: from_mesh refused a loaded mesh: %s\n", wb_last_error());
    CHECK(st == WB_OK);
    CHECK(b.first == 0 && b.count >= 1 && b.count <= m->nv && wb_particle_count(w) == b.count);
    const int apart = distinct(w, b.first, b.count);
    if ((flags & 8) && apart) {
        wb_world_destroy(w);
        w = wb_world_create(&wd);
        CHECK(w);
        fd.neighbours = h[5] % 33;
        st = wb_from_mesh(w, m, &fd, &b);
        CHECK(st == WB_OK || (st == WB_ERR_ARG && may_refuse));
        if (st != WB_OK) {
            wb_world_destroy(w);
            return;
        }
    }
    for (int f = 0; f < 2; f++) CHECK(wb_world_step(w) == WB_OK);
    check_world(w);

    if ((flags & 16) && apart) {
        wb_skin_def sd = wb_skin_default_def();
        sd.bones = 1 + h[6] % 16;
        sd.neighbours = 1 + h[7] % 32;
        int32_t *ids = malloc(sizeof *ids * (size_t)b.count);
        CHECK(ids);
        for (int32_t i = 0; i < b.count; i++) ids[i] = b.first + i;
        wb_skin *s = wb_skin_create(w, m, ids, b.count, &sd, &st);
        free(ids);
        if (!s && st == WB_ERR_ARG && may_refuse) {
            wb_world_destroy(w);
            return;
        }
        if (!s) fprintf(stderr, "fuzz_mesh: skin refused: %s\n", st == WB_ERR_ARG ? wb_last_error() : "no memory");
        CHECK(s);
        check_skin(s, w, m->nv, sd.bones);
        for (int f = 0; f < 2; f++) CHECK(wb_world_step(w) == WB_OK);
        wb_skin_update_bones(s, w);
        check_skin(s, w, m->nv, sd.bones);
        wb_skin_destroy(s);
    }
    wb_world_destroy(w);
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    input in = { data, size, 0 };
    uint8_t h[8];
    for (int i = 0; i < 8; i++) h[i] = byte(&in);
    const uint8_t flags = h[0];
    wbio_mesh_opts o = { (flags & 32) ? 2.5 : 1, (flags & 1) != 0, h[3] ? h[3] / 64.0 : -1, 0 };
    char err[1024] = "";
    wb_mesh *m;
#ifdef FUZZ_FORMAT
    m = wbio_mesh_from_memory(data + in.at, size - in.at, FUZZ_FORMAT, &o, "fuzz." FUZZ_FORMAT, err, sizeof err);
#else
    const int32_t nv = h[1] % 65, nt = h[2] % 129;
    wb_real v[3 * 64 + 1];
    int32_t tri[3 * 128 + 1];
    const wb_real mul = (flags & 192) == 192 ? 5e306 : (flags & 64) ? 1e300 : (flags & 128) ? 1e-300 : 1;
    for (int32_t i = 0; i < 3 * nv; i++) v[i] = mul * ((flags & 2) ? (wb_real)f32(&in) : (wb_real)(int8_t)byte(&in) / 4);
    for (int32_t i = 0; i < 3 * nt; i++) {
        const uint8_t c = byte(&in);
        tri[i] = c == 255 ? -1 : c % (nv + 1);
    }
    /* arrays that are valid (finite once scaled, corners in range) are only refused when
     * no triangle is left: never over a tolerance the caller did not give */
    int valid = 1;
    for (int32_t i = 0; i < 3 * nv; i++) valid &= isfinite(v[i] * o.scale);
    for (int32_t i = 0; i < 3 * nt; i++) valid &= tri[i] >= 0 && tri[i] < nv;
    m = wbio_mesh_from_arrays(v, nv, tri, nt, &o, "fuzz.mesh", err, sizeof err);
    if (!m && valid && nt > 0 && !strstr(err, "no triangles")) {
        fprintf(stderr, "fuzz_mesh: valid arrays refused: %s\n", err);
        abort();
    }
#endif
    if (!m) {
        CHECK(!strncmp(err, "fuzz.", 5) && strlen(err) > 12);
        return 0;
    }
    use_mesh(m, flags, h);
    wb_mesh_destroy(m);
    return 0;
}
