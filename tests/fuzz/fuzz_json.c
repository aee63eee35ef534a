/* fuzz_json.c: the particle-config and snapshot reader (src/io/json.c, json_value.c) on
 * any bytes, through its memory entry wbio_parse_config. libFuzzer calls
 * LLVMFuzzerTestOneInput (`make fuzz`); replay.c calls it once per file under gcc
 * (`make test`), so every crash found once stays fixed.
 *
 * A rejected input must leave a message and nothing allocated. An accepted one must make
 * a world (wobble.load's path) and add to a world (w:load_particles's path), step
 * without trouble, and save + load back to the same hash, before and after stepping. A
 * broken invariant aborts, which the fuzzer reports as a crash. */
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "io/io.h"

#define CHECK(c) do { if (!(c)) { fprintf(stderr, "fuzz_json: invariant failed: %s (line %d)\n", #c, __LINE__); abort(); } } while (0)

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

/* w:save then wobble.load: the same state, hash for hash */
static void round_trip(const wb_world *w)
{
    static char path[64];
    if (!path[0]) snprintf(path, sizeof path, "%s/wobble-fuzz-%ld.json", getenv("TMPDIR") ? getenv("TMPDIR") : "/tmp", (long)getpid());
    char err[1024];
    /* a long path from TMPDIR: just skip the round trip */
    if (strlen(path) >= sizeof path - 1) return;
    CHECK(wbio_write_snapshot(w, path, "snap.json", err, sizeof err) == 0);
    wbio_config c;
    int rc = wbio_read_config(path, "snap.json", &c, err, sizeof err);
    if (rc) fprintf(stderr, "fuzz_json: a saved snapshot does not load: %s\n", err);
    CHECK(rc == 0);
    CHECK(c.snapshot);
    remove(path);
    wb_status st;
    wb_world *back = wb_world_from_image(&c.img, &st);
    CHECK(back);
    CHECK(wb_world_hash(back) == wb_world_hash(w));
    wb_world_destroy(back);
    wbio_config_free(&c);
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    char err[1024] = "";
    wbio_config cfg;
    if (wbio_parse_config((const char *)data, size, "fuzz.json", &cfg, err, sizeof err)) {
        /* a message that names the file, nothing left allocated */
        CHECK(!strncmp(err, "fuzz.json", 9));
        CHECK(cfg.img.np == 0 && cfg.img.x == NULL && cfg.parts == NULL && cfg.skins == NULL);
        return 0;
    }
    wb_image *g = &cfg.img;
    if (!cfg.snapshot) g->def = wb_world_default_def();
    g->def.threads = 1; /* results are the same for any count; one keeps the fuzzer fast */
    for (int32_t i = 0; i < cfg.nparts; i++)
        CHECK(cfg.parts[i].first >= 0 && cfg.parts[i].count >= 0 && cfg.parts[i].first + cfg.parts[i].count <= g->np);
    for (int32_t i = 0; i < cfg.nskins; i++)
        for (int32_t j = 0; j < cfg.skins[i].nids; j++) CHECK(cfg.skins[i].ids[j] >= 0 && cfg.skins[i].ids[j] < g->np);

    /* wobble.load: whatever the reader accepted, the core takes */
    wb_status st;
    wb_world *w = wb_world_from_image(g, &st);
    if (!w) fprintf(stderr, "fuzz_json: the reader accepted what the core refuses: %s\n", st == WB_ERR_ARG ? wb_last_error() : "no memory");
    CHECK(w);
    CHECK(wb_particle_count(w) == g->np);

    /* w:load_particles into a world that has a particle, a link and a collider already */
    wb_world_def d = wb_world_default_def();
    wb_world *u = wb_world_create(&d);
    CHECK(u);
    const wb_real o[3] = { 0, 0, 0 }, x[3] = { 1, 0, 0 };
    wb_particle_add(u, o, NULL, 1, 0.02);
    wb_particle_add(u, x, NULL, 1, 0.02);
    wb_distance_def dd = wb_distance_default_def();
    wb_distance_add(u, 0, 1, &dd, NULL);
    wb_collider_def cd = wb_collider_default_def(WB_SHAPE_PLANE);
    wb_collider_add(u, &cd, NULL);
    wb_body b;
    st = wb_world_append_image(u, g, &b);
    if (st != WB_OK) fprintf(stderr, "fuzz_json: append refused: %s\n", st == WB_ERR_ARG ? wb_last_error() : "status");
    CHECK(st == WB_OK);
    CHECK(b.first == 2 && b.count == g->np);

    round_trip(w);
    /* step only what is cheap: a fuzzer wants thousands of runs a second */
    const wb_world_def wd = wb_world_get_def(w);
    const int64_t cost = (int64_t)wd.substeps * wd.iterations * (g->np + g->dist.n + 1);
    if (cost <= 200000) {
        for (int f = 0; f < 3; f++) {
            CHECK(wb_world_step(w) == WB_OK);
            CHECK(wb_world_step(u) == WB_OK);
        }
        const wb_real *xs = wb_particle_positions(w);
        for (int64_t i = 0; i < 3 * (int64_t)g->np; i++) CHECK(isfinite(xs[i])); /* the step keeps NaN and infinity out */
        round_trip(w);
    }
    wb_world_destroy(u);
    wb_world_destroy(w);
    wbio_config_free(&cfg);
    return 0;
}
