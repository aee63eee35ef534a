/* tets.c: tetrahedral meshes: tetgen's .node/.ele files read and written, and a closed
 * triangle mesh filled with tets by the `tetgen` program (Debian package tetgen), run
 * as a separate process in a private temporary folder: its input (.poly) is written
 * there, it runs there under a timeout and a memory limit, its .node/.ele are read back
 * from there, and the folder is removed. Paths come only from that folder. */
#include <dirent.h>
#include <errno.h>
#include <limits.h>
#include <math.h>
#include <signal.h>
#include <stdlib.h>
#include <string.h>
#include <sys/prctl.h>
#include <sys/resource.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <fcntl.h>
#include <time.h>
#include <unistd.h>

#include "io.h"

void wbio_tets_free(wbio_tets *t)
{
    free(t->v);
    free(t->tet);
    memset(t, 0, sizeof *t);
}

/* ---- reading .node / .ele --------------------------------------------------------------- */
typedef struct reader {
    char *buf, *p;         /* the whole file, NUL-terminated; p: next line */
    int line;              /* of the last line returned */
    const char *shown;
} reader;

static int slurp(const char *path, const char *shown, reader *r, char *err, size_t errn)
{
    memset(r, 0, sizeof *r);
    r->shown = shown;
    FILE *f = fopen(path, "rb");
    if (!f) { snprintf(err, errn, "%s: %s", shown, strerror(errno)); return -1; }
    size_t cap = 1 << 16, n = 0;
    char *b = malloc(cap);
    while (b) {
        n += fread(b + n, 1, cap - n - 1, f);
        if (n < cap - 1) break;
        char *q = cap < ((size_t)1 << 34) ? realloc(b, cap * 2) : NULL;
        if (!q) { free(b); b = NULL; break; }
        b = q;
        cap *= 2;
    }
    const int bad = ferror(f);
    fclose(f);
    if (!b || bad) {
        free(b);
        snprintf(err, errn, "%s: %s", shown, b ? "read error" : "out of memory (file too large)");
        return -1;
    }
    b[n] = 0;
    if (memchr(b, 0, n)) { free(b); snprintf(err, errn, "%s: not a text file", shown); return -1; }
    r->buf = r->p = b;
    return 0;
}

/* the next line with something on it (comments, from '#', dropped); NULL at the end */
static char *next_line(reader *r)
{
    while (*r->p) {
        char *s = r->p, *e = strchr(s, '\n');
        r->p = e ? e + 1 : s + strlen(s);
        if (e) *e = 0;
        r->line++;
        char *h = strchr(s, '#');
        if (h) *h = 0;
        while (*s == ' ' || *s == '\t' || *s == '\r') s++;
        if (*s) return s;
    }
    return NULL;
}

/* up to n numbers of the line; returns how many were read, -1 on a word that is not one */
static int numbers(char *s, double *out, int n)
{
    int k = 0;
    while (k < n) {
        while (*s == ' ' || *s == '\t' || *s == '\r' || *s == ',') s++;
        if (!*s) break;
        char *e;
        out[k] = strtod(s, &e);
        if (e == s) return -1;
        k++;
        s = e;
    }
    return k;
}

#define FAIL(...) do { snprintf(err, errn, __VA_ARGS__); goto fail; } while (0)

static int integral(double x, double lo, double hi) { return x == floor(x) && x >= lo && x <= hi; }

static int read_node(const char *path, const char *shown, wbio_tets *t, int *base, char *err, size_t errn)
{
    reader r;
    if (slurp(path, shown, &r, err, errn)) return -1;
    double h[4];
    char *s = next_line(&r);
    if (!s) FAIL("%s: empty file (a .node file starts with: points dimension attributes markers)", shown);
    int k = numbers(s, h, 4);
    if (k < 1 || !integral(h[0], 4, WB_MAX_PARTICLES))
        FAIL("%s:%d: the point count must be an integer in 4..%d", shown, r.line, WB_MAX_PARTICLES);
    if (k >= 2 && h[1] != 3) FAIL("%s:%d: dimension must be 3", shown, r.line);
    const int nattr = k >= 3 && integral(h[2], 0, 1000) ? (int)h[2] : 0;
    const int marker = k >= 4 && h[3] != 0;
    /* a point takes a line of at least 8 bytes: a count the file cannot hold is refused
     * before anything is allocated for it */
    if (h[0] > (double)strlen(r.p) / 8 + 1) FAIL("%s: %.0f points announced, the file is too short for them", shown, h[0]);
    t->nv = (int32_t)h[0];
    t->v = malloc(sizeof *t->v * 3 * (size_t)t->nv);
    if (!t->v) FAIL("%s: out of memory", shown);
    for (int32_t i = 0; i < t->nv; i++) {
        double q[5];
        if (!(s = next_line(&r))) FAIL("%s: %d points announced, %d found", shown, (int)t->nv, (int)i);
        k = numbers(s, q, 4);
        if (k < 4) FAIL("%s:%d: a point is: index x y z%s%s", shown, r.line, nattr ? " attributes" : "", marker ? " marker" : "");
        if (i == 0) {
            if (q[0] != 0 && q[0] != 1) FAIL("%s:%d: the first point's index must be 0 or 1", shown, r.line);
            *base = (int)q[0];
        }
        if (q[0] != i + *base) FAIL("%s:%d: point index %.0f out of order (expected %d)", shown, r.line, q[0], (int)i + *base);
        for (int c = 0; c < 3; c++) {
            if (!isfinite(q[1 + c])) FAIL("%s:%d: coordinates must be finite", shown, r.line);
            t->v[3 * i + c] = (wb_real)q[1 + c];
        }
    }
    free(r.buf);
    return 0;
fail:
    free(r.buf);
    wbio_tets_free(t);
    return -1;
}

static int read_ele(const char *path, const char *shown, wbio_tets *t, int base, char *err, size_t errn)
{
    reader r;
    if (slurp(path, shown, &r, err, errn)) return -1;
    double h[3];
    char *s = next_line(&r);
    if (!s) FAIL("%s: empty file (an .ele file starts with: tets nodes_per_tet attributes)", shown);
    int k = numbers(s, h, 3);
    if (k < 1 || !integral(h[0], 1, WB_MAX_CONSTRAINTS / 6))
        FAIL("%s:%d: the tet count must be an integer in 1..%d", shown, r.line, WB_MAX_CONSTRAINTS / 6);
    if (k >= 2 && h[1] != 4 && h[1] != 10) FAIL("%s:%d: nodes per tet must be 4 (or 10: the first 4 are used)", shown, r.line);
    if (h[0] > (double)strlen(r.p) / 10 + 1) FAIL("%s: %.0f tets announced, the file is too short for them", shown, h[0]);
    t->nt = (int32_t)h[0];
    t->tet = malloc(sizeof *t->tet * 4 * (size_t)t->nt);
    if (!t->tet) FAIL("%s: out of memory", shown);
    for (int32_t i = 0; i < t->nt; i++) {
        double q[5];
        if (!(s = next_line(&r))) FAIL("%s: %d tets announced, %d found", shown, (int)t->nt, (int)i);
        k = numbers(s, q, 5);
        if (k < 5) FAIL("%s:%d: a tet is: index n1 n2 n3 n4", shown, r.line);
        if (q[0] != i + base) FAIL("%s:%d: tet index %.0f out of order (expected %d)", shown, r.line, q[0], (int)i + base);
        for (int c = 0; c < 4; c++) {
            if (!integral(q[1 + c], base, (double)t->nv - 1 + base))
                FAIL("%s:%d: node %.17g out of range (%d..%d)", shown, r.line, q[1 + c], base, (int)t->nv - 1 + base);
            t->tet[4 * i + c] = (int32_t)q[1 + c] - base;
        }
    }
    free(r.buf);
    return 0;
fail:
    free(r.buf);
    wbio_tets_free(t);
    return -1;
}

int wbio_read_tets(const char *node_path, const char *node_shown, const char *ele_path, const char *ele_shown,
                   wbio_tets *out, char *err, size_t errn)
{
    memset(out, 0, sizeof *out);
    int base = 1;
    if (read_node(node_path, node_shown, out, &base, err, errn)) return -1;
    if (read_ele(ele_path, ele_shown, out, base, err, errn)) return -1;
    return 0;
}

/* ---- writing ------------------------------------------------------------------------------ */
int wbio_write_tets(const char *node_path, const char *node_shown, const char *ele_path, const char *ele_shown,
                    const wb_real *v, int32_t nv, const int32_t *tet, int32_t nt, char *err, size_t errn)
{
    /* both written aside first, then renamed one after the other: a stop while they are
     * written leaves the old pair */
    wbio_out node, ele;
    if (wbio_out_open(&node, AT_FDCWD, node_path, node_shown, err, errn)) return -1;
    if (wbio_out_open(&ele, AT_FDCWD, ele_path, ele_shown, err, errn)) {
        wbio_out_abort(&node);
        return -1;
    }
    /* %.17g: every double read back as itself */
    fprintf(node.f, "# wobble %s: %d points\n%d 3 0 0\n", WB_VERSION, (int)nv, (int)nv);
    for (int32_t i = 0; i < nv; i++)
        fprintf(node.f, "%d %.17g %.17g %.17g\n", (int)i + 1, (double)v[3 * i], (double)v[3 * i + 1], (double)v[3 * i + 2]);
    fprintf(ele.f, "# wobble %s: %d tets\n%d 4 0\n", WB_VERSION, (int)nt, (int)nt);
    for (int32_t i = 0; i < nt; i++)
        fprintf(ele.f, "%d %d %d %d %d\n", (int)i + 1, tet[4 * i] + 1, tet[4 * i + 1] + 1, tet[4 * i + 2] + 1,
                tet[4 * i + 3] + 1);
    const int enode = wbio_out_close_file(&node), eele = wbio_out_close_file(&ele);
    if (enode || eele) {
        snprintf(err, errn, "%s: %s", enode ? node_shown : ele_shown, strerror(enode ? enode : eele));
        wbio_out_abort(&node);
        wbio_out_abort(&ele);
        return -1;
    }
    if (wbio_out_commit(&node, node_shown, err, errn)) {
        wbio_out_abort(&ele);
        return -1;
    }
    return wbio_out_commit(&ele, ele_shown, err, errn);
}

/* ---- tetgen -------------------------------------------------------------------------------- */
static double now_s(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

/* the program's full path on $PATH, or 0 */
static int find_program(const char *name, char *out, size_t n)
{
    const char *path = getenv("PATH");
    if (!path || !*path) path = "/usr/local/bin:/usr/bin:/bin";
    while (*path) {
        const char *e = strchr(path, ':');
        const size_t len = e ? (size_t)(e - path) : strlen(path);
        if (len > 0 && (size_t)snprintf(out, n, "%.*s/%s", (int)len, path, name) < n && access(out, X_OK) == 0) return 1;
        path += len + (e != NULL);
    }
    return 0;
}

static void remove_dir(const char *dir)
{
    DIR *d = opendir(dir);
    if (d) {
        struct dirent *e;
        char p[PATH_MAX];
        while ((e = readdir(d)))
            if (strcmp(e->d_name, ".") && strcmp(e->d_name, "..") &&
                (size_t)snprintf(p, sizeof p, "%s/%s", dir, e->d_name) < sizeof p)
                unlink(p);
        closedir(d);
    }
    rmdir(dir);
}

/* the closed mesh as a piecewise linear complex: its vertices, one facet per triangle */
static int write_poly(const char *path, const wb_mesh *m)
{
    FILE *f = fopen(path, "w");
    if (!f) return -1;
    fprintf(f, "%d 3 0 0\n", (int)m->nv);
    for (int32_t i = 0; i < m->nv; i++)
        fprintf(f, "%d %.17g %.17g %.17g\n", (int)i + 1, (double)m->v[3 * i], (double)m->v[3 * i + 1], (double)m->v[3 * i + 2]);
    fprintf(f, "%d 0\n", (int)m->nt);
    for (int32_t t = 0; t < m->nt; t++)
        fprintf(f, "1\n3 %d %d %d\n", m->tri[3 * t] + 1, m->tri[3 * t + 1] + 1, m->tri[3 * t + 2] + 1);
    fprintf(f, "0\n0\n");
    return fclose(f) == 0 ? 0 : -1;
}

/* run argv in dir with stdout and stderr to dir/log; 0 exited 0, else what happened:
 * 1 failed (exit status or signal in *status), -2 timed out, -6 interrupted, -1 not started */
static int run_child(const char *dir, const char *const argv[], size_t bytes, double timeout, wbio_budget *b, int *status,
                     double *peak)
{
    char log[PATH_MAX];
    snprintf(log, sizeof log, "%s/log", dir);
    fflush(NULL);
    const pid_t parent = getpid();
    pid_t pid = fork();
    if (pid < 0) return -1;
    if (pid == 0) {
        prctl(PR_SET_PDEATHSIG, SIGKILL);   /* never outlives the run that asked for it */
        if (getppid() != parent || chdir(dir) != 0) _exit(126);
        int fd = open("log", O_WRONLY | O_CREAT | O_TRUNC, 0600);
        int nul = open("/dev/null", O_RDONLY);
        if (fd < 0 || nul < 0 || dup2(nul, 0) < 0 || dup2(fd, 1) < 0 || dup2(fd, 2) < 0) _exit(126);
        for (int i = 3; i < 1024; i++) close(i);   /* the script's files are none of its business */
        signal(SIGPIPE, SIG_DFL);
        /* a fresh program: its address space is what it takes, so the budget is the limit */
        struct rlimit as = { (rlim_t)bytes, (rlim_t)bytes };
        setrlimit(RLIMIT_AS, &as);
        struct rlimit cpu = { (rlim_t)timeout + 2, (rlim_t)timeout + 3 };
        setrlimit(RLIMIT_CPU, &cpu);
        execv(argv[0], (char *const *)argv);
        _exit(127);
    }
    const double deadline = now_s() + timeout;
    int r = 1;
    struct rusage ru;
    memset(&ru, 0, sizeof ru);
    for (;;) {
        pid_t k = wait4(pid, status, WNOHANG, &ru);
        if (k == pid) break;
        if (k < 0 && errno != EINTR) { r = -1; break; }
        if (now_s() > deadline) { r = -2; break; }
        if (b->interrupt && b->interrupt(b->interrupt_ud)) { r = -6; break; }
        struct timespec ts = { 0, 5000000 };
        nanosleep(&ts, NULL);
    }
    if (r != 1) {
        kill(pid, SIGKILL);
        while (waitpid(pid, status, 0) < 0 && errno == EINTR) {}
        return r;
    }
    *peak = (double)ru.ru_maxrss * 1024; /* bytes it touched at most */
    if (WIFEXITED(*status) && WEXITSTATUS(*status) == 0) return 0;
    if (WIFSIGNALED(*status) && WTERMSIG(*status) == SIGXCPU) return -2;
    return 1;
}

/* the most telling line of tetgen's log: one it marks "!!" (a finding), else one that
 * names the trouble, else the last */
static void log_reason(const char *dir, char *out, size_t n)
{
    char p[PATH_MAX];
    snprintf(p, sizeof p, "%s/log", dir);
    out[0] = 0;
    FILE *f = fopen(p, "r");
    if (!f) return;
    char line[512], last[512] = "";
    int found = 0; /* 2: a "!!" line, 1: a line with a telling word */
    while (fgets(line, sizeof line, f)) {
        line[strcspn(line, "\r\n")] = 0;
        const int marked = line[0] == '!';
        char *s = line;
        while (*s == ' ' || *s == '!') s++;
        if (!*s) continue;
        const int telling = strstr(s, "rror") || strstr(s, "nvalid") || strstr(s, "memory") || strstr(s, "bad_alloc") ||
                            (strstr(s, "ntersect") && !strstr(s, "Detecting"));
        if ((marked && found < 2) || (telling && found < 1)) {
            snprintf(out, n, "%s", s);
            found = marked ? 2 : 1;
        }
        snprintf(last, sizeof last, "%s", s);
    }
    fclose(f);
    if (!found) snprintf(out, n, "%s", last);
}

/* the largest tet's volume, m^3 */
static double largest_tet(const wbio_tets *t)
{
    double big = 0;
    for (int32_t i = 0; i < t->nt; i++) {
        const int32_t *q = &t->tet[4 * i];
        double d[3][3];
        for (int r = 0; r < 3; r++)
            for (int c = 0; c < 3; c++) d[r][c] = (double)t->v[3 * q[r + 1] + c] - (double)t->v[3 * q[0] + c];
        const double v = fabs(d[0][0] * (d[1][1] * d[2][2] - d[1][2] * d[2][1]) -
                              d[0][1] * (d[1][0] * d[2][2] - d[1][2] * d[2][0]) +
                              d[0][2] * (d[1][0] * d[2][1] - d[1][1] * d[2][0])) / 6;
        if (v > big) big = v;
    }
    return big;
}

static size_t tetgen_bytes(const wbio_budget *b)
{
    if (b->max_bytes) return b->max_bytes;
    long pages = sysconf(_SC_PHYS_PAGES), page = sysconf(_SC_PAGESIZE);
    return pages > 0 && page > 0 ? (size_t)pages / 2 * (size_t)page : (size_t)1 << 32;
}

/* tetgen's switches: a PLC (p), the surface kept (Y), quality (q ratio), volume bound (a,
 * fixed point: tetgen does not read exponents), no .face/.edge (F) */
static void switches(char *sw, size_t n, const wbio_tetgen_opts *o, int keep)
{
    int len = snprintf(sw, n, "-p%sF", keep ? "Y" : "");
    if (o->quality > 0) len += snprintf(sw + len, n - (size_t)len, "q%.6f", o->quality);
    if (o->max_volume > 0) {
        int dec = 6 - (int)floor(log10(o->max_volume));
        dec = dec < 6 ? 6 : dec > 40 ? 40 : dec;
        snprintf(sw + len, n - (size_t)len, "a%.*f", dec, o->max_volume);
    }
}

int wbio_tetgen(const wb_mesh *m, wbio_tetgen_opts *o, wbio_budget *b, wbio_tets *out, char *err, size_t errn)
{
    memset(out, 0, sizeof *out);
    o->kept = false;
    int32_t ea = 0, eb = 0;
    const int32_t open_edges = wb_mesh_open_edges(m, &ea, &eb);
    if (open_edges < 0) { snprintf(err, errn, "out of memory"); return -1; }
    if (m->nt < 4 || open_edges > 0) {
        snprintf(err, errn, "the mesh is not closed: %d edge(s) not shared by exactly two triangles (the first between "
                 "vertices %d and %d); tets fill a closed surface only", (int)open_edges, (int)ea + 1, (int)eb + 1);
        return -1;
    }
    char tetgen[PATH_MAX], stdbuf[PATH_MAX];
    if (!find_program("tetgen", tetgen, sizeof tetgen)) {
        snprintf(err, errn, "the tetgen program is not installed (Debian package tetgen: apt-get install tetgen, or make deps)");
        return -1;
    }
    const char *tmp = getenv("TMPDIR");
    char dir[PATH_MAX];
    snprintf(dir, sizeof dir, "%s/wobble-tetgen.XXXXXX", tmp && *tmp ? tmp : "/tmp");
    if (!mkdtemp(dir)) { snprintf(err, errn, "cannot make a temporary folder for tetgen: %s", strerror(errno)); return -1; }
    char poly[PATH_MAX + 16];
    snprintf(poly, sizeof poly, "%s/in.poly", dir);
    if (write_poly(poly, m)) {
        snprintf(err, errn, "cannot write tetgen's input: %s", strerror(errno));
        remove_dir(dir);
        return -1;
    }
    /* line-buffered through stdbuf where there is one: tetgen aborts on some inputs, and a
     * full buffer would lose the line that says why */
    const int have_stdbuf = find_program("stdbuf", stdbuf, sizeof stdbuf);
    char sw[128];
    const char *argv_sb[] = { stdbuf, "-oL", tetgen, sw, "in.poly", NULL };
    const char *argv_pl[] = { tetgen, sw, "in.poly", NULL };
    const size_t bytes = tetgen_bytes(b);
    const double timeout = o->timeout > 0 ? o->timeout : 60;
    int status = 0;
    double peak = 0;
    int keep = o->keep_surface != 0;
    int r;
    char why[512];
again:
    switches(sw, sizeof sw, o, keep);
    r = run_child(dir, have_stdbuf ? argv_sb : argv_pl, bytes, timeout, b, &status, &peak);
    if (r == 0) {
        char node[PATH_MAX + 16], ele[PATH_MAX + 16];
        snprintf(node, sizeof node, "%s/in.1.node", dir);
        snprintf(ele, sizeof ele, "%s/in.1.ele", dir);
        char e2[512];
        /* 0.1 %: tetgen rounds its points' coordinates */
        if (wbio_read_tets(node, "in.1.node", ele, "in.1.ele", out, e2, sizeof e2))
            snprintf(err, errn, "tetgen's output could not be read: %s", e2);
        else if (out->nv < m->nv)
            snprintf(err, errn, "tetgen's output has fewer points (%d) than the mesh (%d)", (int)out->nv, (int)m->nv);
        else if (!(o->max_volume > 0 && largest_tet(out) > o->max_volume * (1 + 1e-3)) ||
                 (!o->bound_given && !(keep && o->keep_surface < 0))) {
            /* met, or missed where the bound was only a target and the surface stays as
             * asked */
            o->kept = keep;
            remove_dir(dir);
            return 0;
        } else if (keep && o->keep_surface < 0) {
            /* tetgen -Y splits no boundary triangle, so a tet on a large one stays large (a
             * cube of 8 corners gets no interior point at all): let it split them */
            wbio_tets_free(out);
            keep = 0;
            goto again;
        } else if (keep) {
            snprintf(err, errn, "max_volume = %g cannot be met with keep_surface = true: tetgen keeps the mesh's "
                     "triangles, and its largest tet is %g m^3 (keep_surface = false, or left out, lets tetgen "
                     "split the surface; or give a finer mesh, or a larger max_volume)", o->max_volume, largest_tet(out));
        } else {
            snprintf(err, errn, "tetgen did not meet max_volume = %g: its largest tet is %g m^3", o->max_volume,
                     largest_tet(out));
        }
        wbio_tets_free(out);
        remove_dir(dir);
        return -1;
    }
    log_reason(dir, why, sizeof why);
    if (r == -2) snprintf(err, errn, "tetgen timed out after %g s (raise timeout, or max_volume)", timeout);
    else if (r == -6) { snprintf(err, errn, "tetgen was stopped (a budget is spent)"); b->stopped = true; }
    else if (r == -1) snprintf(err, errn, "cannot start tetgen: %s", strerror(errno));
    else if (strstr(why, "memory") || strstr(why, "bad_alloc") ||
             (WIFSIGNALED(status) && WTERMSIG(status) == SIGABRT && peak > 0.5 * (double)bytes)) {
        /* this tetgen aborts without a word when an allocation fails: a failure after it
         * touched half of what it may take is taken for that */
        snprintf(err, errn, "tetgen ran out of memory (%.0f MB allowed%s)", bytes / 1048576.0,
                 b->max_bytes ? "" : ", half of this machine's");
        if (b->max_bytes) b->stopped = true;
    } else {
        /* a failure without a word is most often an input that intersects itself (this
         * tetgen aborts then): ask its detector, which says so */
        const char *argv_d[] = { have_stdbuf ? stdbuf : tetgen, "-oL", tetgen, "-dNEF", "in.poly", NULL };
        const char *const *ad = have_stdbuf ? argv_d : (const char *const[]){ tetgen, "-dNEF", "in.poly", NULL };
        char why_d[512] = "";
        int st2 = 0;
        double peak2 = 0;
        if (run_child(dir, ad, bytes, timeout, b, &st2, &peak2) >= 0) log_reason(dir, why_d, sizeof why_d);
        if (strstr(why_d, "ntersect") && !strstr(why_d, "No faces"))
            snprintf(err, errn, "the mesh intersects itself (tetgen: %s); tets need a closed surface that does not "
                     "cross itself", why_d);
        else {
            char how[64];
            if (WIFSIGNALED(status)) snprintf(how, sizeof how, "killed by %s", strsignal(WTERMSIG(status)));
            else snprintf(how, sizeof how, "exit status %d", WEXITSTATUS(status));
            snprintf(err, errn, "tetgen failed (%s)%s%s", how, why[0] ? ": " : "", why);
        }
    }
    remove_dir(dir);
    return -1;
}
