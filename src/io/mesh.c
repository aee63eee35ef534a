/* mesh.c: meshes from and to files. Reading is assimp's (OBJ, glTF 2, PLY, STL, FBX,
 * Collada, ...): triangulated, node transforms applied, every mesh of the file merged,
 * then welded by position and given fresh normals by the core (mesh.c). OBJ and PLY are
 * written here, vertex order kept (Blender's Mesh Cache matches points by index); other
 * formats go through assimp's exporter.
 *
 * Every file assimp opens, the one named and any it pulls in (an OBJ's .mtl, a glTF's
 * .bin), goes through a wrapper that asks the caller's `allow` first: a model file cannot
 * read past the sandbox by naming "../../etc/passwd" as a buffer. */
#include <assimp/cexport.h>
#include <assimp/cfileio.h>
#include <assimp/cimport.h>
#include <assimp/postprocess.h>
#include <assimp/scene.h>
#include <errno.h>
#include <fcntl.h>
#include <limits.h>
#include <malloc.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>
#include <poll.h>
#include <signal.h>
#include <sys/prctl.h>
#include <sys/resource.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <time.h>
#include <unistd.h>

#include "io.h"

/* ---- assimp's file access through the sandbox ---------------------------------------------- */
typedef struct guard {
    wbio_allow_fn allow;
    void *ud;
    char refused[512];     /* the first refusal, reported if the import then fails */
    wbio_out outs[8];      /* an export's files, kept aside until the whole export worked */
    int nouts;
} guard;

static size_t f_read(struct aiFile *f, char *buf, size_t size, size_t n) { return fread(buf, size, n, (FILE *)f->UserData); }
static size_t f_write(struct aiFile *f, const char *buf, size_t size, size_t n) { return fwrite(buf, size, n, (FILE *)f->UserData); }
static size_t f_tell(struct aiFile *f) { long p = ftell((FILE *)f->UserData); return p < 0 ? 0 : (size_t)p; }
static void f_flush(struct aiFile *f) { fflush((FILE *)f->UserData); }

static size_t f_size(struct aiFile *f)
{
    struct stat st;
    return fstat(fileno((FILE *)f->UserData), &st) == 0 ? (size_t)st.st_size : 0;
}

static enum aiReturn f_seek(struct aiFile *f, size_t off, enum aiOrigin o)
{
    int whence = o == aiOrigin_SET ? SEEK_SET : o == aiOrigin_CUR ? SEEK_CUR : SEEK_END;
    return fseek((FILE *)f->UserData, (long)off, whence) == 0 ? aiReturn_SUCCESS : aiReturn_FAILURE;
}

static struct aiFile *f_open(struct aiFileIO *io, const char *path, const char *mode)
{
    guard *g = (guard *)io->UserData;
    const int write = strpbrk(mode, "wa+") != NULL;
    char why[512] = "too many files in one export";
    if (g->allow && !g->allow(g->ud, path, write, why, sizeof why)) {
        if (!g->refused[0]) snprintf(g->refused, sizeof g->refused, "%s", why);
        return NULL;
    }
    struct stat st;
    if (!write && (stat(path, &st) != 0 || S_ISDIR(st.st_mode))) return NULL;
    FILE *fp = NULL;
    if (!write) fp = fopen(path, mode);
    else if (g->nouts < (int)(sizeof g->outs / sizeof *g->outs) &&
             wbio_out_open(&g->outs[g->nouts], AT_FDCWD, path, path, why, sizeof why) == 0)
        fp = g->outs[g->nouts++].f;
    else if (!g->refused[0]) snprintf(g->refused, sizeof g->refused, "%s", why);
    struct aiFile *f = fp ? calloc(1, sizeof *f) : NULL;
    if (!f) {
        if (fp && !write) fclose(fp);
        return NULL;
    }
    f->ReadProc = f_read;
    f->WriteProc = f_write;
    f->TellProc = f_tell;
    f->FileSizeProc = f_size;
    f->SeekProc = f_seek;
    f->FlushProc = f_flush;
    f->UserData = (aiUserData)fp;
    return f;
}

static void f_close(struct aiFileIO *io, struct aiFile *f)
{
    guard *g = (guard *)io->UserData;
    if (!f) return;
    int k = 0;
    while (k < g->nouts && g->outs[k].f != (FILE *)f->UserData) k++;
    if (k < g->nouts) wbio_out_close_file(&g->outs[k]);   /* renamed once the export is whole */
    else fclose((FILE *)f->UserData);
    free(f);
}

/* ---- reading --------------------------------------------------------------------------------- */
/* assimp 5.2 is not safe on damaged input: a PLY cut in its header loops forever, one cut in
 * its body trips an ai_assert (abort), fuzzed binary PLY and Collada files segfault. So the
 * import runs in a child process that sends the bare arrays back over a pipe; the parent
 * waits with a wall-clock limit and turns a crash, an abort or a hang into an error. */
typedef struct import_head {
    int32_t ok;            /* 1: nv, nt and the arrays follow; 0: a message of len bytes; 2: the
                              same, the child ran out of the memory it was given */
    int32_t len;
    int64_t nv, nt;
} import_head;

static void count_scene(const struct aiScene *sc, int64_t *nv, int64_t *nt)
{
    *nv = *nt = 0;
    for (unsigned i = 0; i < sc->mNumMeshes; i++) {
        const struct aiMesh *m = sc->mMeshes[i];
        if (!(m->mPrimitiveTypes & aiPrimitiveType_TRIANGLE)) continue;
        *nv += m->mNumVertices;
        for (unsigned f = 0; f < m->mNumFaces; f++) *nt += m->mFaces[f].mNumIndices == 3;
    }
}

static int write_all(int fd, const void *buf, size_t n)
{
    const char *p = buf;
    while (n > 0) {
        ssize_t k = write(fd, p, n);
        if (k < 0 && errno == EINTR) continue;
        if (k <= 0) return -1;
        p += k;
        n -= (size_t)k;
    }
    return 0;
}

static void child_fail(int fd, const char *why)
{
    /* assimp turns a refused allocation into the message of std::bad_alloc */
    const int oom = strstr(why, "bad_alloc") || strstr(why, "out of memory");
    import_head h = { oom ? 2 : 0, (int32_t)strlen(why), 0, 0 };
    if (write_all(fd, &h, sizeof h) == 0) write_all(fd, why, (size_t)h.len);
}

/* every triangle mesh of the scene flattened into one pair of arrays (malloc'd), or a
 * message in why */
static int flatten_scene(const struct aiScene *sc, wb_real **v_out, int64_t *nv_out, int32_t **tri_out,
                         int64_t *nt_out, char *why, size_t whyn)
{
    int64_t nv, nt;
    count_scene(sc, &nv, &nt);
    if ((sc->mFlags & AI_SCENE_FLAGS_INCOMPLETE) || nt == 0) {
        snprintf(why, whyn, "no triangles in this file");
        return -1;
    }
    if (nv > WB_MAX_PARTICLES || nt > WB_MAX_CONSTRAINTS) {
        snprintf(why, whyn, "too large (%lld vertices, %lld triangles)", (long long)nv, (long long)nt);
        return -1;
    }
    wb_real *v = malloc(sizeof *v * 3 * (size_t)(nv > 0 ? nv : 1));
    int32_t *tri = malloc(sizeof *tri * 3 * (size_t)nt);
    if (!v || !tri) {
        free(v);
        free(tri);
        snprintf(why, whyn, "out of memory");
        return -1;
    }
    int32_t base = 0, t = 0;
    for (unsigned i = 0; i < sc->mNumMeshes; i++) {
        const struct aiMesh *m = sc->mMeshes[i];
        if (!(m->mPrimitiveTypes & aiPrimitiveType_TRIANGLE)) continue;
        for (unsigned k = 0; k < m->mNumVertices; k++) {
            v[3 * (base + k)] = (wb_real)m->mVertices[k].x;
            v[3 * (base + k) + 1] = (wb_real)m->mVertices[k].y;
            v[3 * (base + k) + 2] = (wb_real)m->mVertices[k].z;
        }
        for (unsigned f = 0; f < m->mNumFaces; f++) {
            const struct aiFace *fc = &m->mFaces[f];
            if (fc->mNumIndices != 3) continue;
            for (int c = 0; c < 3; c++) tri[3 * t + c] = base + (int32_t)fc->mIndices[c];
            t++;
        }
        base += (int32_t)m->mNumVertices;
    }
    *v_out = v;
    *tri_out = tri;
    *nv_out = nv;
    *nt_out = t;
    return 0;
}

static const unsigned import_flags = aiProcess_Triangulate | aiProcess_PreTransformVertices | aiProcess_SortByPType |
                                     aiProcess_ValidateDataStructure;

/* assimp's message for a failed import */
static const char *import_error(const guard *g)
{
    const char *why = g->refused[0] ? g->refused : aiGetErrorString();
    /* assimp's validator words a file without meshes as a broken scene */
    if (!g->refused[0] && why && strstr(why, "mNumMeshes is 0")) why = "no triangles in this file";
    return why && *why ? why : "cannot read this file";
}

/* the child's whole work: import, flatten every triangle mesh into one pair of arrays */
static void child_import(int fd, const char *path, wbio_allow_fn allow, void *ud)
{
    guard g = { allow, ud, "", { { 0 } }, 0 };
    struct aiFileIO io = { f_open, f_close, (aiUserData)&g };
    const struct aiScene *sc = aiImportFileEx(path, import_flags, &io);
    if (!sc) {
        child_fail(fd, import_error(&g));
        return;
    }
    wb_real *v;
    int32_t *tri;
    int64_t nv, nt;
    char why[128];
    if (flatten_scene(sc, &v, &nv, &tri, &nt, why, sizeof why)) {
        child_fail(fd, why);
        return;
    }
    /* the scene goes before the arrays are sent: the caller makes its copy of them while
     * this process still holds its own, and both count against one budget */
    aiReleaseImport(sc);
    malloc_trim(0);
    import_head h = { 1, 0, nv, nt };
    if (write_all(fd, &h, sizeof h) == 0 && write_all(fd, v, sizeof *v * 3 * (size_t)nv) == 0)
        write_all(fd, tri, sizeof *tri * 3 * (size_t)nt);
    /* no free: the process ends now */
}

static double now_s(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

/* read n bytes before the deadline: 0, -1 end of file or error, -2 time is up, -6 the
 * caller's interrupt said stop (polled ten times a second) */
static int read_all(int fd, void *buf, size_t n, double deadline, const wbio_budget *o)
{
    char *p = buf;
    while (n > 0) {
        double left = deadline - now_s();
        if (left <= 0) return -2;
        if (o->interrupt && o->interrupt(o->interrupt_ud)) return -6;
        if (o->interrupt && left > 0.1) left = 0.1;
        struct pollfd pf = { fd, POLLIN, 0 };
        int r = poll(&pf, 1, left > 1e6 ? 1000000000 : (int)(left * 1000) + 1);
        if (r < 0 && errno == EINTR) continue;
        if (r < 0) return -1;
        if (r == 0) continue;
        ssize_t k = read(fd, p, n);
        if (k < 0 && errno == EINTR) continue;
        if (k <= 0) return -1;
        p += k;
        n -= (size_t)k;
    }
    return 0;
}

static double import_timeout(const wbio_mesh_opts *o)
{
    if (o->timeout > 0) return o->timeout;
    const char *t = getenv("WOBBLE_IMPORT_TIMEOUT");
    return t && atof(t) > 0 ? atof(t) : 60;
}

/* the memory an import may take: the caller's budget, else half of this machine's */
static size_t import_bytes(const wbio_budget *o)
{
    if (o->max_bytes) return o->max_bytes;
    long pages = sysconf(_SC_PHYS_PAGES), page = sysconf(_SC_PAGESIZE);
    return pages > 0 && page > 0 ? (size_t)pages / 2 * (size_t)page : (size_t)1 << 32;
}

/* in the child, before assimp runs: a header that promises a billion vertices must meet
 * a refused allocation (std::bad_alloc, reported) rather than grow the machine into its
 * OOM killer. The address space it starts with is the parent's (libraries, heaps, the
 * renderers' threads), so the limit is that plus what it may take; CPU time is capped as
 * well, in case the parent's clock is not watching any more */
static void limit_child(size_t bytes, double timeout)
{
    unsigned long size = 0;
    FILE *f = fopen("/proc/self/statm", "r");
    if (f) {
        if (fscanf(f, "%lu", &size) != 1) size = 0;
        fclose(f);
    }
    const long page = sysconf(_SC_PAGESIZE);
    const double as = (double)size * (double)(page > 0 ? page : 4096) + (double)bytes;
    if (size && as < (double)RLIM_INFINITY) {
        struct rlimit rl = { (rlim_t)as, (rlim_t)as };
        setrlimit(RLIMIT_AS, &rl);
    }
    struct rlimit cpu = { (rlim_t)timeout + 2, (rlim_t)timeout + 3 };
    setrlimit(RLIMIT_CPU, &cpu);
}

/* run the import in a child; arrays (malloc'd) or a message in why */
static int import_isolated(const char *path, const wbio_mesh_opts *mo, wbio_budget *o, wbio_allow_fn allow,
                           void *ud, wb_real **v, int64_t *nv, int32_t **tri, int64_t *nt, char *why, size_t whyn)
{
    *v = NULL;
    *tri = NULL;
    const size_t budget = import_bytes(o);
    int fds[2];
    if (pipe(fds) != 0) { snprintf(why, whyn, "cannot start the importer: %s", strerror(errno)); return -1; }
    fflush(NULL);   /* the child must not write the parent's buffered output a second time */
    const pid_t parent = getpid();
    pid_t pid = fork();
    if (pid < 0) {
        snprintf(why, whyn, "cannot start the importer: %s", strerror(errno));
        close(fds[0]);
        close(fds[1]);
        return -1;
    }
    if (pid == 0) {
        /* killed with the parent: an import never outlives the run that asked for it
         * (checked again after, in case the parent died before the request) */
        prctl(PR_SET_PDEATHSIG, SIGKILL);
        if (getppid() != parent) _exit(1);
        close(fds[0]);
        signal(SIGPIPE, SIG_DFL);
        limit_child(budget, import_timeout(mo));
        child_import(fds[1], path, allow, ud);
        _exit(0);   /* no atexit handlers: they belong to the parent (Lua, the renderer) */
    }
    close(fds[1]);
    const double deadline = now_s() + import_timeout(mo);
    import_head h;
    int r = read_all(fds[0], &h, sizeof h, deadline, o);
    if (r == 0 && h.ok == 1) {
        /* the arrays on their way, then the mesh made of them (wbio_load_mesh) while they
         * are still held, and the weld's grid over its vertices (map, buckets, chain,
         * cells: 52 bytes a vertex) */
        const double weld = mo->weld ? 52 : 0;
        const double need = (double)h.nv * (3 * sizeof **v + 6 * sizeof(wb_real) + weld) + (double)h.nt * 6 * sizeof **tri;
        if (h.nv < 1 || h.nt < 1 || h.nv > WB_MAX_PARTICLES || h.nt > WB_MAX_CONSTRAINTS) r = -1;
        else if (need > (double)budget) r = -5;
        else {
            *v = malloc(sizeof **v * 3 * (size_t)h.nv);
            *tri = malloc(sizeof **tri * 3 * (size_t)h.nt);
            if (!*v || !*tri) r = -3;
            else if ((r = read_all(fds[0], *v, sizeof **v * 3 * (size_t)h.nv, deadline, o)) == 0)
                r = read_all(fds[0], *tri, sizeof **tri * 3 * (size_t)h.nt, deadline, o);
        }
        *nv = h.nv;
        *nt = h.nt;
    } else if (r == 0) {
        char msg[512];
        size_t len = h.len < 0 ? 0 : (size_t)h.len < sizeof msg - 1 ? (size_t)h.len : sizeof msg - 1;
        if ((r = read_all(fds[0], msg, len, deadline, o)) == 0) {
            msg[len] = 0;
            snprintf(why, whyn, "%s", msg);
            r = h.ok == 2 ? -5 : -4;
        }
    }
    if (r != 0 && r != -4) kill(pid, SIGKILL);   /* still running, or on its way out */
    close(fds[0]);
    int status = 0;
    while (waitpid(pid, &status, 0) < 0 && errno == EINTR) {}
    if (r == 0) return 0;
    free(*v);
    free(*tri);
    *v = NULL;
    *tri = NULL;
    if (r == -6 || (r == -5 && o->max_bytes)) o->stopped = true;
    if (r == -1 && WIFSIGNALED(status) && WTERMSIG(status) == SIGXCPU) r = -2;
    if (r == -2) snprintf(why, whyn, "the importer failed (timed out after %g s)", import_timeout(mo));
    else if (r == -3) snprintf(why, whyn, "out of memory");
    else if (r == -5) snprintf(why, whyn, "the importer ran out of memory (%.0f MB allowed%s)", budget / 1048576.0,
                               o->max_bytes ? "" : ", half of this machine's");
    else if (r == -6) snprintf(why, whyn, "the import was stopped (a budget is spent)");
    else if (r == -1) snprintf(why, whyn, "the importer failed (crashed%s%s)",
                               WIFSIGNALED(status) ? ": " : "", WIFSIGNALED(status) ? strsignal(WTERMSIG(status)) : "");
    return -1;
}

/* a PLY cut inside its header sends assimp into an endless loop: caught here at once
 * rather than after the importer's timeout. 1 when the file is a PLY without end_header */
static int ply_header_cut(const char *path)
{
    enum { HEAD = 65536 };   /* far more than any real header */
    FILE *f = fopen(path, "rb");
    char *buf = f ? malloc(HEAD) : NULL;
    if (!buf) {
        if (f) fclose(f);
        return 0;
    }
    size_t n = fread(buf, 1, HEAD, f);
    fclose(f);
    int cut = n >= 4 && memcmp(buf, "ply", 3) == 0 && (buf[3] == '\n' || buf[3] == '\r') &&
              memmem(buf, n, "end_header", 10) == NULL;
    free(buf);
    return cut;
}

wb_mesh *wbio_load_mesh(const char *path, const char *shown, const wbio_mesh_opts *o,
                        wbio_allow_fn allow, void *ud, char *err, size_t errn)
{
    wbio_budget none = { 0, NULL, NULL, false };
    return wbio_load_mesh_within(path, shown, o, &none, allow, ud, err, errn);
}

wb_mesh *wbio_load_mesh_within(const char *path, const char *shown, const wbio_mesh_opts *o, wbio_budget *b,
                               wbio_allow_fn allow, void *ud, char *err, size_t errn)
{
    struct stat st;
    if (stat(path, &st) != 0) { snprintf(err, errn, "%s: %s", shown, strerror(errno)); return NULL; }
    if (S_ISDIR(st.st_mode)) { snprintf(err, errn, "%s: is a folder, not a file", shown); return NULL; }
    if (st.st_size == 0) { snprintf(err, errn, "%s: empty file", shown); return NULL; }
    if (allow) {
        char why[512];
        if (!allow(ud, path, 0, why, sizeof why)) { snprintf(err, errn, "%s: %s", shown, why); return NULL; }
    }
    if (ply_header_cut(path)) { snprintf(err, errn, "%s: PLY header without end_header (a cut file?)", shown); return NULL; }
    wb_real *v;
    int32_t *tri;
    int64_t nv, nt;
    char why[512];
    if (import_isolated(path, o, b, allow, ud, &v, &nv, &tri, &nt, why, sizeof why) != 0) {
        snprintf(err, errn, "%s: %s", shown, why);
        return NULL;
    }
    wb_mesh *mesh = wbio_mesh_from_arrays(v, nv, tri, nt, o, shown, err, errn);
    free(v);
    free(tri);
    return mesh;
}

wb_mesh *wbio_mesh_from_arrays(wb_real *v, int64_t nv, const int32_t *tri, int64_t nt, const wbio_mesh_opts *o,
                               const char *shown, char *err, size_t errn)
{
    if (nv < 0 || nt < 0 || nv > WB_MAX_PARTICLES || nt > WB_MAX_CONSTRAINTS) {
        snprintf(err, errn, "%s: too large (%lld vertices, %lld triangles)", shown, (long long)nv, (long long)nt);
        return NULL;
    }
    for (int64_t i = 0; i < 3 * nv; i++) v[i] *= o->scale;
    wb_status status = WB_ERR_NOMEM;
    wb_mesh *mesh = wb_mesh_create(v, (int32_t)nv, tri, (int32_t)nt, &status);
    if (mesh && o->weld) {
        /* files repeat a vertex per face it touches (an STL cube has 36): merge by position */
        status = wb_mesh_weld(mesh, o->tol < 0 ? wb_mesh_weld_tolerance(mesh) : o->tol, NULL);
        if (status != WB_OK) {
            wb_mesh_destroy(mesh);
            mesh = NULL;
        }
    }
    if (!mesh) {
        snprintf(err, errn, "%s: %s", shown, status == WB_ERR_NOMEM ? "out of memory" : wb_last_error());
        return NULL;
    }
    if (mesh->nt == 0) {
        snprintf(err, errn, "%s: no triangles in this file (all degenerate)", shown);
        wb_mesh_destroy(mesh);
        return NULL;
    }
    return mesh;
}

wb_mesh *wbio_mesh_from_memory(const void *data, size_t n, const char *hint, const wbio_mesh_opts *o,
                               const char *shown, char *err, size_t errn)
{
    guard g = { NULL, NULL, "", { { 0 } }, 0 };
    /* assimp asserts (aborts) on an empty buffer; its length is an unsigned int */
    if (n == 0 || n > UINT_MAX) {
        snprintf(err, errn, "%s: %s", shown, n ? "too large" : "empty file");
        return NULL;
    }
    const struct aiScene *sc = aiImportFileFromMemory(data, (unsigned)n, import_flags, hint);
    if (!sc) {
        snprintf(err, errn, "%s: %s", shown, import_error(&g));
        return NULL;
    }
    wb_real *v;
    int32_t *tri;
    int64_t nv, nt;
    char why[128];
    wb_mesh *mesh = NULL;
    if (flatten_scene(sc, &v, &nv, &tri, &nt, why, sizeof why)) snprintf(err, errn, "%s: %s", shown, why);
    else {
        mesh = wbio_mesh_from_arrays(v, nv, tri, nt, o, shown, err, errn);
        free(v);
        free(tri);
    }
    aiReleaseImport(sc);
    return mesh;
}

/* ---- writing ---------------------------------------------------------------------------------- */
int wbio_write_obj(FILE *f, const wb_mesh *m, const wb_real *v, const wb_real *n)
{
    if (!v) v = m->v;
    if (!n) n = m->n;
    fprintf(f, "# wobble %s: %d vertices, %d triangles\n", WB_VERSION, m->nv, m->nt);
    for (int32_t i = 0; i < m->nv; i++) fprintf(f, "v %.9g %.9g %.9g\n", v[3 * i], v[3 * i + 1], v[3 * i + 2]);
    for (int32_t i = 0; i < m->nv; i++) fprintf(f, "vn %.6g %.6g %.6g\n", n[3 * i], n[3 * i + 1], n[3 * i + 2]);
    for (int32_t i = 0; i < m->nt; i++) {
        const int32_t *t = &m->tri[3 * i];
        fprintf(f, "f %d//%d %d//%d %d//%d\n", t[0] + 1, t[0] + 1, t[1] + 1, t[1] + 1, t[2] + 1, t[2] + 1);
    }
    return ferror(f) ? -1 : 0;
}

int wbio_write_ply(FILE *f, const wb_mesh *m, const wb_real *v, const wb_real *n)
{
    if (!v) v = m->v;
    if (!n) n = m->n;
    fprintf(f, "ply\nformat ascii 1.0\ncomment wobble %s\nelement vertex %d\n"
               "property float x\nproperty float y\nproperty float z\n"
               "property float nx\nproperty float ny\nproperty float nz\n"
               "element face %d\nproperty list uchar int vertex_indices\nend_header\n",
            WB_VERSION, m->nv, m->nt);
    for (int32_t i = 0; i < m->nv; i++)
        fprintf(f, "%.9g %.9g %.9g %.6g %.6g %.6g\n", v[3 * i], v[3 * i + 1], v[3 * i + 2], n[3 * i], n[3 * i + 1], n[3 * i + 2]);
    for (int32_t i = 0; i < m->nt; i++) fprintf(f, "3 %d %d %d\n", m->tri[3 * i], m->tri[3 * i + 1], m->tri[3 * i + 2]);
    return ferror(f) ? -1 : 0;
}

static const char *extension(const char *path)
{
    const char *dot = strrchr(path, '.'), *slash = strrchr(path, '/');
    return dot && (!slash || dot > slash) ? dot + 1 : "";
}

/* a one-mesh scene built by hand for assimp's exporter (which copies what it is given) */
static int export_assimp(const wb_mesh *m, const wb_real *v, const char *path, const char *format,
                         guard *g, char *msg, size_t n)
{
    struct aiScene sc;
    struct aiNode root;
    struct aiMesh mesh;
    struct aiMaterial mat;
    struct aiMesh *meshes[1] = { &mesh };
    struct aiMaterial *mats[1] = { &mat };
    unsigned mesh_index = 0;
    memset(&sc, 0, sizeof sc);
    memset(&root, 0, sizeof root);
    memset(&mesh, 0, sizeof mesh);
    memset(&mat, 0, sizeof mat);
    for (int i = 0; i < 4; i++) (&root.mTransformation.a1)[5 * i] = 1; /* identity */
    strcpy(root.mName.data, "wobble");
    root.mName.length = 6;
    root.mNumMeshes = 1;
    root.mMeshes = &mesh_index;
    mesh.mPrimitiveTypes = aiPrimitiveType_TRIANGLE;
    mesh.mNumVertices = (unsigned)m->nv;
    mesh.mNumFaces = (unsigned)m->nt;
    mesh.mVertices = malloc(sizeof *mesh.mVertices * (size_t)(m->nv ? m->nv : 1));
    mesh.mNormals = malloc(sizeof *mesh.mNormals * (size_t)(m->nv ? m->nv : 1));
    mesh.mFaces = malloc(sizeof *mesh.mFaces * (size_t)(m->nt ? m->nt : 1));
    unsigned *idx = malloc(sizeof *idx * 3 * (size_t)(m->nt ? m->nt : 1));
    int rc = -1;
    if (mesh.mVertices && mesh.mNormals && mesh.mFaces && idx) {
        for (int32_t i = 0; i < m->nv; i++) {
            mesh.mVertices[i].x = (ai_real)v[3 * i];
            mesh.mVertices[i].y = (ai_real)v[3 * i + 1];
            mesh.mVertices[i].z = (ai_real)v[3 * i + 2];
            mesh.mNormals[i].x = (ai_real)m->n[3 * i];
            mesh.mNormals[i].y = (ai_real)m->n[3 * i + 1];
            mesh.mNormals[i].z = (ai_real)m->n[3 * i + 2];
        }
        for (int32_t i = 0; i < m->nt; i++) {
            for (int c = 0; c < 3; c++) idx[3 * i + c] = (unsigned)m->tri[3 * i + c];
            mesh.mFaces[i].mNumIndices = 3;
            mesh.mFaces[i].mIndices = &idx[3 * i];
        }
        sc.mRootNode = &root;
        sc.mNumMeshes = 1;
        sc.mMeshes = meshes;
        sc.mNumMaterials = 1;
        sc.mMaterials = mats;
        struct aiFileIO io = { f_open, f_close, (aiUserData)g };
        if (aiExportSceneEx(&sc, format, path, &io, 0) == aiReturn_SUCCESS) rc = 0;
        else snprintf(msg, n, "%s", g->refused[0] ? g->refused : aiGetErrorString());
        for (int k = 0; k < g->nouts; k++) {
            if (rc == 0 && wbio_out_commit(&g->outs[k], g->outs[k].name, msg, n)) rc = -1;
            else wbio_out_abort(&g->outs[k]);   /* nothing left behind, nothing half replaced */
        }
    } else {
        snprintf(msg, n, "out of memory");
    }
    free(mesh.mVertices);
    free(mesh.mNormals);
    free(mesh.mFaces);
    free(idx);
    return rc;
}

int wbio_save_mesh(const wb_mesh *m, const wb_real *v, const char *path, const char *shown,
                   wbio_allow_fn allow, void *ud, char *err, size_t errn)
{
    static const char *const formats[][2] = { { "stl", "stlb" }, { "gltf", "gltf2" }, { "glb", "glb2" },
                                              { "fbx", "fbxa" }, { "dae", "collada" }, { NULL, NULL } };
    const char *ext = extension(path);
    if (!v) v = m->v;
    if (!strcasecmp(ext, "obj") || !strcasecmp(ext, "ply")) {
        wbio_out o;
        if (wbio_out_open(&o, AT_FDCWD, path, shown, err, errn)) return -1;
        if (strcasecmp(ext, "obj") ? wbio_write_ply(o.f, m, v, NULL) : wbio_write_obj(o.f, m, v, NULL))
            o.failed = errno ? errno : EIO;
        return wbio_out_commit(&o, shown, err, errn);
    }
    for (int i = 0; formats[i][0]; i++) {
        if (strcasecmp(ext, formats[i][0])) continue;
        guard g = { allow, ud, "", { { 0 } }, 0 };
        char msg[512] = "";
        if (export_assimp(m, v, path, formats[i][1], &g, msg, sizeof msg) == 0) return 0;
        snprintf(err, errn, "%s: %s", shown, msg[0] ? msg : "assimp could not write it");
        return -1;
    }
    snprintf(err, errn, "%s: unknown mesh format '.%s' (expected .obj, .ply, .stl, .gltf, .glb, .fbx or .dae)", shown, ext);
    return -1;
}
