/* io.h: file formats, linked into the command and kept out of the core (libwobble.a):
 * JSON particle configs and snapshots (json.c, cJSON), meshes (mesh.c, assimp),
 * exports for other tools (export.c: PC2, VTK).
 *
 * Callers resolve paths first (the Lua binding through the sandbox, wb_sandbox_path); `shown`
 * is the name error messages print, as the script wrote it. Functions that can fail
 * return 0 or -1 with a one-line message in err[errn], never crash on bad input and
 * change nothing they were given. */
#ifndef WB_IO_H
#define WB_IO_H

#include <limits.h>
#include <stdio.h>

#include "core/snapshot.h"
#include "wobble.h"

/* may the file at path be opened (write = 0 read, 1 write)? 1 yes; 0 no, with a reason
 * in err. Files a format pulls in by itself (an OBJ's .mtl, a glTF's .bin) ask too. */
typedef int (*wbio_allow_fn)(void *ud, const char *path, int write, char *err, size_t errn);

/* ---- files written whole (file.c) ------------------------------------------------------ */
/* A file is written into a temporary beside its name and renamed over it once complete:
 * whatever stops the writer, the name holds the old file or the new one. A symbolic link
 * at the name is never followed (it is replaced); a FIFO or a device there is written in
 * place. The temporaries in progress are removed by wbio_remove_temporaries, on SIGINT,
 * SIGTERM and SIGHUP once wbio_clean_on_signals ran, and at exit(). */
typedef struct wbio_out {
    FILE *f;               /* the temporary, open for writing (NULL once closed) */
    int dir;               /* the folder name and tmp are relative to (AT_FDCWD: paths) */
    int slot;              /* in the table the signal handler reads, or -1 */
    int direct;            /* a FIFO or a device written in place: no temporary */
    int failed;            /* an errno once a write failed: commit refuses */
    char name[PATH_MAX], tmp[PATH_MAX];
} wbio_out;
/* the temporary for name (in dir); -1 with "shown: reason" in err */
int wbio_out_open(wbio_out *o, int dir, const char *name, const char *shown, char *err, size_t errn);
/* close the temporary's stream (its errors kept for commit); the errno of a failure or 0 */
int wbio_out_close_file(wbio_out *o);
/* close and rename into place; on any failure the temporary is removed and the old file stays */
int wbio_out_commit(wbio_out *o, const char *shown, char *err, size_t errn);
void wbio_out_abort(wbio_out *o);      /* remove the temporary: the old file stays */
/* n bytes as the whole file name (in dir) */
int wbio_write_bytes(int dir, const char *name, const char *shown, const void *data, size_t n, char *err, size_t errn);
/* a path named by the user (the command line), whose link is theirs to follow: where it
 * leads when it is a link to something that exists, else the path itself */
int wbio_follow_link(const char *path, char *out, size_t n);
void wbio_remove_temporaries(void);   /* async-signal-safe */
void wbio_clean_on_signals(void);     /* once, for the process: SIGINT, SIGTERM, SIGHUP and exit() */

/* ---- JSON particle configs and snapshots (json.c) ------------------------------------- */
#define WBIO_FORMAT "wobble-particles"
#define WBIO_VERSION 1

typedef struct wbio_part { char *name; int32_t first, count; } wbio_part;

typedef struct wbio_skin_spec {
    char *mesh;            /* path as written, relative to the config's folder */
    wb_real scale;
    wb_skin_def def;
    int32_t *ids;          /* (nids) particles of the config, 0-based; NULL = all */
    int32_t nids;
    char where[160];       /* "file:line:col: skins[i].mesh" for messages about the mesh */
} wbio_skin_spec;

typedef struct wbio_config {
    wb_image img;          /* particles, constraints, colliders, surfaces (+ snapshot state) */
    int snapshot;          /* the file had a "snapshot" section: img.def, slots, clock are its */
    int32_t nparts;
    wbio_part *parts;
    int32_t nskins;
    wbio_skin_spec *skins;
    wb_memory *mem;        /* the budget charged for the arrays read (wbio_read_config_within) */
    size_t charged;
} wbio_config;

/* read and check the whole file; on error nothing is allocated (cfg zeroed) */
int wbio_read_config(const char *path, const char *shown, wbio_config *cfg, char *err, size_t errn);
/* the same under a memory budget (NULL: none): the file's text, cJSON's tree (about 40
 * times the text for a file of small numbers) and the positions of its values are
 * charged to mem while the read runs, and the arrays read (a third of that at most) until
 * wbio_config_free. A read that would pass mem->limit fails with *over set and a message
 * saying so; nothing stays charged then */
int wbio_read_config_within(const char *path, const char *shown, wbio_config *cfg, wb_memory *mem, bool *over,
                            char *err, size_t errn);
/* the same from a text in memory (len bytes, no NUL needed): what a file would give */
int wbio_parse_config(const char *data, size_t len, const char *shown, wbio_config *cfg, char *err, size_t errn);
void wbio_config_free(wbio_config *cfg);
/* the full state (a superset of the config format) so that wobble.load restores it exactly;
 * written to a temporary file and renamed, so a failure leaves no half file */
int wbio_write_snapshot(const wb_world *w, const char *path, const char *shown, char *err, size_t errn);

/* ---- meshes (mesh.c) --------------------------------------------------------------------- */
typedef struct wbio_mesh_opts {
    wb_real scale;         /* multiplies every coordinate */
    bool weld;             /* merge vertices by position */
    wb_real tol;           /* their distance; < 0: 1e-6 of the bounds' diagonal */
    double timeout;        /* seconds for the import (a child process); 0: $WOBBLE_IMPORT_TIMEOUT or 60 */
} wbio_mesh_opts;

/* the budgets an import runs under (wbio_load_mesh_within) */
typedef struct wbio_budget {
    /* memory the import may take: the child's address space past what it starts with
     * (RLIMIT_AS) and the arrays it sends back; 0: no budget, half the machine's memory */
    size_t max_bytes;
    int (*interrupt)(void *ud); /* polled while the child works; true stops it (a spent budget) */
    void *interrupt_ud;
    bool stopped;          /* out: max_bytes or interrupt is what stopped the import */
} wbio_budget;

/* any format assimp reads, triangulated, node transforms applied, all meshes of the file
 * merged, welded, normals recomputed. NULL with a message on a missing, empty or corrupt file.
 * assimp runs in a forked child: a file that crashes or hangs it is "the importer failed
 * (crashed|timed out ...)", never the caller's crash; one that needs more memory than
 * the budget is "the importer ran out of memory (...)" with b->stopped set (without a
 * budget, half of the machine's memory is the child's limit). The child dies with the
 * caller (PR_SET_PDEATHSIG) */
wb_mesh *wbio_load_mesh_within(const char *path, const char *shown, const wbio_mesh_opts *o, wbio_budget *b,
                               wbio_allow_fn allow, void *ud, char *err, size_t errn);
wb_mesh *wbio_load_mesh(const char *path, const char *shown, const wbio_mesh_opts *o,
                        wbio_allow_fn allow, void *ud, char *err, size_t errn);   /* no budget */
/* what wbio_load_mesh does with the importer's arrays, whatever their values: v (nv x 3,
 * scaled in place) and tri (nt x 3) checked, made a mesh, welded; NULL with a message */
wb_mesh *wbio_mesh_from_arrays(wb_real *v, int64_t nv, const int32_t *tri, int64_t nt, const wbio_mesh_opts *o,
                               const char *shown, char *err, size_t errn);
/* a file's bytes through assimp in this process, no child and no timeout (assimp may crash
 * or hang on damaged input): for trusted data and for fuzzing our side of the import.
 * hint: the format's extension ("obj", "ply", ...) */
wb_mesh *wbio_mesh_from_memory(const void *data, size_t n, const char *hint, const wbio_mesh_opts *o,
                               const char *shown, char *err, size_t errn);
/* by extension: .obj and .ply written here (vertex order kept, as Blender's Mesh Cache
 * needs), .stl .gltf .glb .fbx .dae through assimp's exporter. v overrides m->v when given
 * (a deformed pose of the same mesh) */
int wbio_save_mesh(const wb_mesh *m, const wb_real *v, const char *path, const char *shown,
                   wbio_allow_fn allow, void *ud, char *err, size_t errn);
int wbio_write_obj(FILE *f, const wb_mesh *m, const wb_real *v, const wb_real *n);
int wbio_write_ply(FILE *f, const wb_mesh *m, const wb_real *v, const wb_real *n);

/* ---- exports (export.c) -------------------------------------------------------------------- */
/* PC2 point cache (Blender's Mesh Cache modifier): header, then float32 xyz per point per
 * sample; the header's sample count is kept current after every sample. sample_rate: frames
 * per sample (a sample every `every` frames) */
typedef struct wbio_pc2 wbio_pc2;
wbio_pc2 *wbio_pc2_open(const char *path, const char *shown, int32_t npoints, double start_frame,
                        double sample_rate, char *err, size_t errn);
int wbio_pc2_write(wbio_pc2 *p, const wb_real *pts, char *err, size_t errn); /* (npoints x 3) */
/* keep: the cache takes its name (else it is removed, an old file of the name stays);
 * NULL is fine; frees */
int wbio_pc2_close(wbio_pc2 *p, int keep, char *err, size_t errn);
int32_t wbio_pc2_samples(const wbio_pc2 *p);

/* VTK series for ParaView: a .pvd collection and one .vtp PolyData per frame in a folder
 * beside it (points = particles with velocity, speed, strain, mass, pinned; cells = the
 * particles, the constraints and the surfaces' triangles). Each frame writes its .vtp
 * and then the whole .pvd again, each file whole (file.c): the series on disk is
 * complete after every frame. Times are frame x dt. */
typedef struct wbio_vtk wbio_vtk;
/* pvd_path: the .pvd file; dir: the folder for the .vtp files (exists); rel_dir: that
 * folder as the .pvd names it (relative, so the series can be moved) */
wbio_vtk *wbio_vtk_open(const char *pvd_path, const char *dir, const char *rel_dir, const char *shown,
                        char *err, size_t errn);
int wbio_vtk_write(wbio_vtk *v, const wb_world *w, char *err, size_t errn);
int wbio_vtk_close(wbio_vtk *v, char *err, size_t errn);     /* NULL is fine; frees; nothing left to write */
int32_t wbio_vtk_frames(const wbio_vtk *v);
int wbio_write_vtp(FILE *f, const wb_world *w);               /* one frame */


/* ---- tet meshes (tets.c): tetgen's .node/.ele, and the tetgen program ------------------------ */
typedef struct wbio_tets {
    int32_t nv, nt;
    wb_real *v;            /* (nv x 3) nodes */
    int32_t *tet;          /* (nt x 4) 0-based node ids */
} wbio_tets;
void wbio_tets_free(wbio_tets *t);                    /* and zero it; fine on a zeroed one */
/* a .node and an .ele file (indices from 0 or 1, as the .node's first point says; extra
 * attributes and markers ignored; 10-node tets keep their corners) */
int wbio_read_tets(const char *node_path, const char *node_shown, const char *ele_path, const char *ele_shown,
                   wbio_tets *out, char *err, size_t errn);
int wbio_write_tets(const char *node_path, const char *node_shown, const char *ele_path, const char *ele_shown,
                    const wb_real *v, int32_t nv, const int32_t *tet, int32_t nt, char *err, size_t errn);
typedef struct wbio_tetgen_opts {
    double max_volume;     /* tetgen -a: largest tet volume, m^3; 0 = none */
    double quality;        /* tetgen -q: largest radius-edge ratio; 0 = none */
    int keep_surface;      /* tetgen -Y: the mesh's triangles stay the surface (nodes 0..nv-1 are
                              its vertices): 1 always, 0 never (tetgen may split them), -1 when
                              max_volume can be met so, else split */
    bool bound_given;      /* max_volume is the caller's promise (missed: an error), not a target */
    double timeout;        /* seconds; 0 = 60 */
    bool kept;             /* out: the mesh's triangles were kept (-Y) */
} wbio_tetgen_opts;
/* fill the closed mesh m with tets by running the tetgen program in a private temporary
 * folder (removed after), under b's memory (the child's address space) and interrupt.
 * Refuses an open mesh before running anything; an input that intersects itself is named
 * as such; without tetgen installed, the message names the Debian package */
int wbio_tetgen(const wb_mesh *m, wbio_tetgen_opts *o, wbio_budget *b, wbio_tets *out, char *err, size_t errn);

#endif
