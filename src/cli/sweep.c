/* sweep.c: `wobble sweep SCENE.lua --grid key=a,b,c ... --out DIR`. The cartesian product
 * of the grids, each combination `--repeat` times, becomes one `wobble run` command line
 * per run in DIR/jobs.txt (for GNU parallel, locally or over ssh), a Slurm job array over
 * the same lines (DIR/sweep.slurm) and DIR/sweep.json, which `wobble collect` reads. wobble
 * schedules nothing itself: those engines do; only `--run` starts GNU parallel on this
 * machine. */
#include "sweep.h"
#include "io/io.h"

#include <cjson/cJSON.h>
#include <dirent.h>
#include <errno.h>
#include <fcntl.h>
#include <ftw.h>
#include <limits.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#define MAX_RUNS 1000000   /* lines of one sweep: more is a typo, not a study */

enum { EXIT_PASS = 0, EXIT_FAILED = 1, EXIT_SCRIPT = 2 };

static const char sweep_usage[] =
    "usage: wobble sweep SCENE.lua --grid key=a,b,c [--grid ...] --out DIR [options]\n"
    "\n"
    "  writes DIR/jobs.txt (one `wobble run` per combination of the grids, for GNU\n"
    "  parallel), DIR/sweep.slurm (a Slurm job array over those lines) and DIR/sweep.json;\n"
    "  every run writes DIR/runs/NNNN/result.json, read by `wobble collect DIR`\n"
    "\n"
    "  --grid key=a,b,c    values of wobble.args.key, as --set takes them; repeatable\n"
    "  --repeat N          every combination N times (each run also gets --set repeat=K)\n"
    "  --out DIR           the sweep's folder (refused when not empty, unless --force)\n"
    "  --force             reuse a non-empty DIR: its jobs are rewritten, runs/ and the\n"
    "                      logs of an earlier sweep removed\n"
    "  --run               start the runs now with GNU parallel (a progress bar on a\n"
    "                      terminal, DIR/joblog.txt); --jobs N of them at a time\n"
    "  --time-limit S, --memory-limit MB, --frames N, --threads N, --set key=value, --unsafe\n"
    "                      passed to every run; the limits also size the Slurm tasks\n";

static int sweep_error(const char *fmt, const char *a, const char *b) {
    fprintf(stderr, "wobble sweep: ");
    fprintf(stderr, fmt, a, b);
    fprintf(stderr, "\n\n%s", sweep_usage);
    return EXIT_SCRIPT;
}

typedef struct grid { const char *key; char **vals; int n; } grid;

typedef struct sweep {
    const char *scene, *out, *time_limit, *memory_limit, *frames, *threads, *jobs;
    const char **sets;
    int nsets, unsafe, run, force, repeat;
    grid *g;
    int ng;
} sweep;

/* a key as wobble.args and a CSV column take it: letters, digits, '_' and '.' */
static int good_key(const char *k, size_t n) {
    if (n == 0 || n > 63 || (k[0] >= '0' && k[0] <= '9')) return 0;
    for (size_t i = 0; i < n; i++)
        if (!(k[i] == '_' || k[i] == '.' || (k[i] >= 'a' && k[i] <= 'z') || (k[i] >= 'A' && k[i] <= 'Z') ||
              (k[i] >= '0' && k[i] <= '9')))
            return 0;
    return 1;
}

/* a number Lua would read as infinite: `wobble run --set` refuses it, so every job would fail */
static int overflows(const char *s) {
    char *end;
    if (strpbrk(s, "nN")) return 0;
    double v = strtod(s, &end);
    return end != s && !*end && !isfinite(v);
}

static int parse_number(const char *s, double lo, double hi) {
    char *end;
    errno = 0;
    double v = strtod(s, &end);
    return *s && !*end && !errno && v >= lo && v <= hi;
}

static int add_grid(sweep *s, const char *arg) {
    const char *eq = strchr(arg, '=');
    if (!eq || !eq[1]) return sweep_error("--grid expects key=a,b,c, got '%s'%s", arg, "");
    size_t kl = (size_t)(eq - arg);
    if (!good_key(arg, kl))
        return sweep_error("--grid '%s': the key must be letters, digits, '_' or '.'%s", arg, "");
    char *key = strndup(arg, kl);
    for (int i = 0; i < s->ng; i++)
        if (!strcmp(s->g[i].key, key)) {
            sweep_error("--grid %s: the key '%s' is given twice", arg, key);
            free(key);
            return EXIT_SCRIPT;
        }
    grid *g = &s->g[s->ng++];
    g->key = key;
    g->vals = calloc(strlen(eq) + 1, sizeof *g->vals);
    if (!g->vals) return sweep_error("out of memory%s%s", "", "");
    for (const char *v = eq + 1;; ) {
        const char *c = strchr(v, ',');
        size_t n = c ? (size_t)(c - v) : strlen(v);
        if (n == 0) return sweep_error("--grid %s: an empty value (two commas, or one at an end)%s", arg, "");
        char *val = strndup(v, n);
        if (!val) return sweep_error("out of memory%s%s", "", "");
        g->vals[g->n++] = val;  /* freed with the grid, also after an error */
        if (strchr(val, '\n')) return sweep_error("--grid %s: a value holds a line break%s", arg, "");
        if (overflows(val)) return sweep_error("--grid %s: the number %s is out of range (not finite)", arg, val);
        if (!c) break;
        v = c + 1;
    }
    return EXIT_PASS;
}

static int parse(int argc, char **argv, sweep *s) {
    memset(s, 0, sizeof *s);
    s->repeat = 1;
    s->g = calloc((size_t)argc, sizeof *s->g);
    s->sets = calloc((size_t)argc, sizeof *s->sets);
    if (!s->g || !s->sets) return sweep_error("out of memory%s%s", "", "");
    for (int i = 2; i < argc; i++) {
        const char *a = argv[i];
        if (a[0] != '-' || !a[1]) {
            if (s->scene) return sweep_error("sweep takes one scene script, got '%s' and '%s'", s->scene, a);
            s->scene = a;
            continue;
        }
        char name[32];
        const char *eq = strchr(a, '='), *val = NULL;
        size_t nl = eq ? (size_t)(eq - a) : strlen(a);
        snprintf(name, sizeof name, "%.*s", (int)(nl < 31 ? nl : 31), a);
        if (!strcmp(name, "--run") || !strcmp(name, "--force") || !strcmp(name, "--unsafe")) {
            if (eq) return sweep_error("%s takes no value%s", name, "");
            if (name[2] == 'r') s->run = 1;
            else if (name[2] == 'f') s->force = 1;
            else s->unsafe = 1;
            continue;
        }
        static const char *const valued[] = { "--grid", "--repeat", "--out", "--time-limit", "--memory-limit",
                                              "--frames", "--threads", "--set", "--jobs", NULL };
        int k = 0;
        while (valued[k] && strcmp(valued[k], name)) k++;
        if (!valued[k]) return sweep_error("unknown option %s%s", a, "");
        if (eq) val = eq + 1;
        else if (i + 1 < argc) val = argv[++i];
        else return sweep_error("%s needs a value%s", name, "");
        int bad = 0;
        switch (k) {
        case 0: if (add_grid(s, val)) return EXIT_SCRIPT; break;
        case 1:
            bad = !parse_number(val, 1, MAX_RUNS) || strpbrk(val, ".eE");
            s->repeat = bad ? 1 : atoi(val);
            break;
        case 2: bad = !*val; s->out = val; break;
        case 3: bad = !parse_number(val, 0, 1e9); s->time_limit = val; break;
        case 4: bad = !parse_number(val, 0, 1e9); s->memory_limit = val; break;
        case 5: bad = !parse_number(val, 0, 1e15) || strpbrk(val, ".eE"); s->frames = val; break;
        case 6: bad = !parse_number(val, 1, 256) || strpbrk(val, ".eE"); s->threads = val; break;
        case 7: {
            const char *e = strchr(val, '=');
            bad = !e || e == val || overflows(e + 1) || strchr(val, '\n');
            s->sets[s->nsets++] = val;
            break;
        }
        case 8: bad = !parse_number(val, 1, 4096) || strpbrk(val, ".eE"); s->jobs = val; break;
        }
        if (bad) return sweep_error("%s: '%s' is not a valid value", name, val);
    }
    if (!s->scene) return sweep_error("sweep needs a scene script%s%s", "", "");
    if (!s->ng) return sweep_error("sweep needs at least one --grid key=a,b,c%s%s", "", "");
    if (!s->out) return sweep_error("sweep needs --out DIR (the sweep's folder)%s%s", "", "");
    for (int i = 0; i < s->nsets; i++)
        for (int j = 0; j < s->ng; j++) {
            size_t kl = strlen(s->g[j].key);
            if (!strncmp(s->sets[i], s->g[j].key, kl) && s->sets[i][kl] == '=')
                return sweep_error("--set %s: '%s' is a --grid key too", s->sets[i], s->g[j].key);
        }
    if (s->repeat > 1)
        for (int i = 0; i < s->nsets; i++)
            if (!strncmp(s->sets[i], "repeat=", 7))
                return sweep_error("--set %s: with --repeat, 'repeat' is the run's own key%s", s->sets[i], "");
    if (s->repeat > 1)
        for (int j = 0; j < s->ng; j++)
            if (!strcmp(s->g[j].key, "repeat")) return sweep_error("--grid repeat=...: with --repeat, 'repeat' is the "
                                                                   "run's own key%s%s", "", "");
    return EXIT_PASS;
}

/* ---- files ----------------------------------------------------------------------------- */

/* text for sh inside '...' (quote): ' written '\'' */
static void escaped(FILE *f, const char *s) {
    for (; *s; s++) {
        if (*s == '\'') fputs("'\\''", f);
        else fputc(*s, f);
    }
}

static void quote(FILE *f, const char *s) {
    fputc('\'', f);
    escaped(f, s);
    fputc('\'', f);
}

/* 'key=value', of any length (a fixed buffer cut long values short, unlike sweep.json's) */
static void quote_kv(FILE *f, const char *k, const char *v) {
    fputc('\'', f);
    escaped(f, k);
    fputc('=', f);
    escaped(f, v);
    fputc('\'', f);
}

static int remove_entry(const char *p, const struct stat *st, int flag, struct FTW *ftw) {
    (void)st, (void)flag, (void)ftw;
    return remove(p);
}

/* mkdir -p */
static int make_dirs(const char *dir) {
    char p[PATH_MAX];
    if (snprintf(p, sizeof p, "%s/", dir) >= (int)sizeof p) return errno = ENAMETOOLONG, -1;
    for (char *c = p + 1; *c; c++) {
        if (*c != '/') continue;
        *c = 0;
        if (mkdir(p, 0777) != 0 && errno != EEXIST) return -1;
        *c = '/';
    }
    return 0;
}

/* a missing folder is empty; a file is not */
static int dir_empty(const char *dir) {
    struct stat st;
    if (stat(dir, &st) != 0) return 1;
    if (!S_ISDIR(st.st_mode)) return 0;
    int n = 0;
    DIR *d = opendir(dir);
    struct dirent *e;
    while (d && (e = readdir(d)))
        if (strcmp(e->d_name, ".") && strcmp(e->d_name, "..")) n++;
    if (d) closedir(d);
    return n == 0;
}

static int width_of(long n) {
    int w = 1;
    while (n >= 10) n /= 10, w++;
    return w < 4 ? 4 : w;
}

/* the value of the grid at run index r (0-based; the first grid varies slowest) */
static const char *value_at(const sweep *s, long r, int gi) {
    long idx = r / s->repeat;
    for (int j = s->ng - 1; j > gi; j--) idx /= s->g[j].n;
    return s->g[gi].vals[idx % s->g[gi].n];
}

static void job_line(FILE *f, const sweep *s, const char *exe, const char *scene, const char *dir, long r, int w) {
    char run[PATH_MAX + 32];
    quote(f, exe);
    fputs(" run ", f);
    quote(f, scene);
    if (snprintf(run, sizeof run, "%s/runs/%0*ld", dir, w, r + 1) >= (int)sizeof run) run[0] = 0;
    fputs(" --out ", f);
    quote(f, run);
    for (int i = 0; i < s->nsets; i++) fputs(" --set ", f), quote(f, s->sets[i]);
    for (int j = 0; j < s->ng; j++) fputs(" --set ", f), quote_kv(f, s->g[j].key, value_at(s, r, j));
    if (s->repeat > 1) fprintf(f, " --set repeat=%ld", r % s->repeat + 1);
    fputs(" --quiet", f);
    if (s->time_limit) fputs(" --time-limit ", f), quote(f, s->time_limit);
    if (s->memory_limit) fputs(" --memory-limit ", f), quote(f, s->memory_limit);
    if (s->frames) fputs(" --frames ", f), quote(f, s->frames);
    if (s->threads) fputs(" --threads ", f), quote(f, s->threads);
    if (s->unsafe) fputs(" --unsafe", f);
    fputc('\n', f);
}

/* The array: task i runs line i of jobs.txt, its output in runs/NNNN/output.txt
 * (Slurm's own messages, such as a time limit, in DIR/slurm/). The limits get a
 * margin: wobble's watchdog allows 5 s or 10 % past --time-limit, and the process
 * needs memory besides its budget (the program, the renderer's buffers). */
static void slurm_script(FILE *f, const sweep *s, const char *dir, long count, int w) {
    fprintf(f, "#!/bin/sh\n# wobble sweep of %s: %ld runs, one array task each (task i runs line i of jobs.txt).\n",
            s->scene, count);
    fprintf(f, "# Submit from anywhere: sbatch ");
    quote(f, dir);
    fprintf(f, "/sweep.slurm   (add --wait to block until all are done)\n");
    fprintf(f, "#SBATCH --job-name=wobble-sweep\n#SBATCH --array=1-%ld\n#SBATCH --ntasks=1\n", count);
    fprintf(f, "#SBATCH --cpus-per-task=%s\n", s->threads ? s->threads : "1");
    if (s->time_limit) {
        long t = (long)ceil(atof(s->time_limit) * 1.1 + 60);
        fprintf(f, "#SBATCH --time=%ld:%02ld:%02ld\n", t / 3600, t / 60 % 60, t % 60);
    }
    if (s->memory_limit) fprintf(f, "#SBATCH --mem=%ldM\n", (long)ceil(atof(s->memory_limit) * 1.25 + 256));
    /* #SBATCH lines take no quotes: a folder with spaces would break this one */
    fprintf(f, "#SBATCH --output=%s/slurm/%%A_%%a.out\n", dir);
    fputs("dir=", f);
    quote(f, dir);
    fprintf(f, "\nline=$(sed -n \"${SLURM_ARRAY_TASK_ID}p\" \"$dir/jobs.txt\")\n");
    fprintf(f, "run=$(printf %%0%dd \"$SLURM_ARRAY_TASK_ID\")\n", w);
    fprintf(f, "mkdir -p \"$dir/runs/$run\" || exit 1\n");
    fprintf(f, "exec sh -c \"$line\" >\"$dir/runs/$run/output.txt\" 2>&1\n");
}

static cJSON *describe(const sweep *s, const char *exe, const char *scene, const char *dir, long count, int w) {
    cJSON *o = cJSON_CreateObject(), *g = NULL, *runs = NULL, *sets = NULL;
    cJSON_AddStringToObject(o, "format", "wobble-sweep");
    cJSON_AddNumberToObject(o, "version", 1);
    cJSON_AddStringToObject(o, "scene", scene);
    cJSON_AddStringToObject(o, "wobble", exe);
    cJSON_AddStringToObject(o, "dir", dir);
    if ((g = cJSON_AddArrayToObject(o, "grid")))
        for (int j = 0; j < s->ng; j++) {
            cJSON *e = cJSON_CreateObject();
            cJSON_AddStringToObject(e, "key", s->g[j].key);
            cJSON_AddItemToObject(e, "values", cJSON_CreateStringArray((const char *const *)s->g[j].vals, s->g[j].n));
            cJSON_AddItemToArray(g, e);
        }
    cJSON_AddNumberToObject(o, "repeat", s->repeat);
    cJSON_AddNumberToObject(o, "count", (double)count);
    cJSON_AddNumberToObject(o, "width", w);
    if ((sets = cJSON_AddArrayToObject(o, "set")))
        for (int i = 0; i < s->nsets; i++) cJSON_AddItemToArray(sets, cJSON_CreateString(s->sets[i]));
    if (s->time_limit) cJSON_AddNumberToObject(o, "time_limit", atof(s->time_limit));
    else cJSON_AddNullToObject(o, "time_limit");
    if (s->memory_limit) cJSON_AddNumberToObject(o, "memory_limit", atof(s->memory_limit));
    else cJSON_AddNullToObject(o, "memory_limit");
    /* run NNNN's grid values, so collect needs no shell parsing of jobs.txt */
    if ((runs = cJSON_AddArrayToObject(o, "runs")))
        for (long r = 0; r < count; r++) {
            cJSON *e = cJSON_CreateObject(), *v = cJSON_CreateObject();
            char name[32];
            if (snprintf(name, sizeof name, "%0*ld", w, r + 1) >= (int)sizeof name) name[0] = 0;
            cJSON_AddStringToObject(e, "run", name);
            for (int j = 0; j < s->ng; j++) cJSON_AddStringToObject(v, s->g[j].key, value_at(s, r, j));
            cJSON_AddItemToObject(e, "set", v);
            if (s->repeat > 1) cJSON_AddNumberToObject(e, "repeat", (double)(r % s->repeat + 1));
            cJSON_AddItemToArray(runs, e);
        }
    return o;
}

static int write_file(const char *dir, const char *name, const char *text, int mode, char *err, size_t n) {
    char p[PATH_MAX + 64];
    snprintf(p, sizeof p, "%s/%s", dir, name);
    char e[2 * PATH_MAX];
    int ok = wbio_write_bytes(AT_FDCWD, p, p, text, strlen(text), e, sizeof e) == 0;
    if (ok && mode) chmod(p, (mode_t)mode);
    if (!ok) snprintf(err, n, "cannot write %.*s", (int)(n > 16 ? n - 16 : 0), e);
    return ok;
}

/* ---- --run: GNU parallel on this machine -------------------------------------------------- */

static int run_parallel(const sweep *s, const char *dir, long count) {
    char jobs[PATH_MAX + 16], log[PATH_MAX + 16];
    snprintf(jobs, sizeof jobs, "%s/jobs.txt", dir);
    snprintf(log, sizeof log, "%s/joblog.txt", dir);
    const char *argv[16];
    int k = 0;
    argv[k++] = "parallel";
    argv[k++] = "--will-cite";
    argv[k++] = "--joblog";
    argv[k++] = log;
    if (isatty(STDERR_FILENO)) argv[k++] = "--bar";
    if (s->jobs) argv[k++] = "--jobs", argv[k++] = s->jobs;
    argv[k++] = "-a";
    argv[k++] = jobs;
    argv[k] = NULL;
    fflush(NULL);
    pid_t pid = fork();
    if (pid < 0) {
        fprintf(stderr, "wobble sweep: --run: cannot start GNU parallel: %s\n", strerror(errno));
        return EXIT_SCRIPT;
    }
    if (pid == 0) {
        execvp(argv[0], (char *const *)argv);
        fprintf(stderr, "wobble sweep: --run needs GNU parallel (Debian: apt-get install parallel): %s\n",
                strerror(errno));
        _exit(127);
    }
    int st;
    while (waitpid(pid, &st, 0) < 0 && errno == EINTR) {}
    if (!WIFEXITED(st) || WEXITSTATUS(st) == 127 || WEXITSTATUS(st) == 255) return EXIT_SCRIPT;
    int failed = WEXITSTATUS(st);  /* parallel: the number of failed jobs, up to 100 */
    if (failed) fprintf(stderr, "wobble sweep: %s%d of %ld runs failed; see wobble collect %s\n",
                        failed > 100 ? "more than " : "", failed > 100 ? 100 : failed, count, dir);
    else fprintf(stderr, "wobble sweep: %ld runs done; wobble collect %s\n", count, dir);
    return failed ? EXIT_FAILED : EXIT_PASS;
}

static void sweep_free(sweep *s) {
    for (int j = 0; j < s->ng; j++) {
        for (int i = 0; i < s->g[j].n; i++) free(s->g[j].vals[i]);
        free(s->g[j].vals);
        free((char *)s->g[j].key);
    }
    free(s->g);
    free(s->sets);
}

static int make_sweep(sweep *s);

int wb_cmd_sweep(int argc, char **argv) {
    sweep s;
    if (argc >= 3 && (!strcmp(argv[2], "--help") || !strcmp(argv[2], "-h"))) {
        fputs(sweep_usage, stdout);
        return EXIT_PASS;
    }
    int code = parse(argc, argv, &s);
    if (code == EXIT_PASS) code = make_sweep(&s);
    sweep_free(&s);
    return code;
}

static int make_sweep(sweep *sp) {
    sweep s = *sp;
    long count = s.repeat;
    for (int j = 0; j < s.ng; j++) {
        if (count * s.g[j].n > MAX_RUNS) return sweep_error("the grids make more than %s runs%s", "1000000", "");
        count *= s.g[j].n;
    }
    char scene[PATH_MAX], exe[PATH_MAX], dir[PATH_MAX], err[PATH_MAX + 128] = "";
    struct stat st = { 0 };
    if (stat(s.scene, &st) != 0 || !S_ISREG(st.st_mode) || !realpath(s.scene, scene)) {
        fprintf(stderr, "wobble sweep: cannot open the scene %s: %s\n", s.scene,
                errno && !S_ISDIR(st.st_mode) ? strerror(errno) : "not a file");
        return EXIT_SCRIPT;
    }
    ssize_t k = readlink("/proc/self/exe", exe, sizeof exe - 1);
    if (k <= 0) {
        fprintf(stderr, "wobble sweep: cannot find the wobble program (/proc/self/exe)\n");
        return EXIT_SCRIPT;
    }
    exe[k] = 0;
    /* every job line is one line of shell (parallel, sed -n Np) and sweep.slurm quotes
     * nothing in its comments: a line break in a path would start a command of its own */
    char cwd[PATH_MAX];
    if (s.out[0] == '/' || !getcwd(cwd, sizeof cwd)) cwd[0] = 0;  /* a relative --out is under it */
    const char *broken = strpbrk(scene, "\n\r") ? scene : strpbrk(exe, "\n\r") ? exe
                       : strpbrk(s.out, "\n\r") ? s.out : strpbrk(cwd, "\n\r") ? cwd : NULL;
    if (broken) {
        fprintf(stderr, "wobble sweep: the path '%s' holds a line break: rename it (job lines are one line of "
                        "shell each)\n", broken);
        return EXIT_SCRIPT;
    }
    /* an earlier sweep's results must not mix with this one's */
    struct stat ost;
    if (stat(s.out, &ost) == 0 && !S_ISDIR(ost.st_mode)) {
        fprintf(stderr, "wobble sweep: --out %s is a file, not a folder\n", s.out);
        return EXIT_SCRIPT;
    }
    if (!dir_empty(s.out) && !s.force) {
        fprintf(stderr, "wobble sweep: --out %s is not empty (an earlier sweep?): choose another folder, or add "
                        "--force to rewrite its jobs and remove its runs/\n", s.out);
        return EXIT_SCRIPT;
    }
    /* --force removes runs/ and slurm/: only an earlier sweep's, never those of a folder
     * of the user's (the scene's own, a home) that happens to have them */
    char mark[PATH_MAX + 16];
    if (!dir_empty(s.out) && s.force &&
        (snprintf(mark, sizeof mark, "%s/sweep.json", s.out) >= (int)sizeof mark || stat(mark, &st) != 0 ||
         !S_ISREG(st.st_mode))) {
        fprintf(stderr, "wobble sweep: --force: --out %s is not an earlier sweep's folder (no sweep.json): its "
                        "runs/ would be removed; choose another folder\n", s.out);
        return EXIT_SCRIPT;
    }
    if (make_dirs(s.out) != 0 || !realpath(s.out, dir)) {
        fprintf(stderr, "wobble sweep: --out %s: cannot make the folder: %s\n", s.out, strerror(errno));
        return EXIT_SCRIPT;
    }
    if (s.force) {
        static const char *const old[] = { "runs", "slurm", "joblog.txt", NULL };
        for (int i = 0; old[i]; i++) {
            char p[PATH_MAX + 32];
            snprintf(p, sizeof p, "%s/%s", dir, old[i]);
            if (lstat(p, &st) == 0 && nftw(p, remove_entry, 16, FTW_DEPTH | FTW_PHYS) != 0) {
                fprintf(stderr, "wobble sweep: --force: cannot remove %s: %s\n", p, strerror(errno));
                return EXIT_SCRIPT;
            }
        }
    }
    int w = width_of(count);
    char *jobs = NULL, *slurm = NULL;
    size_t jl = 0, sl = 0;
    FILE *f = open_memstream(&jobs, &jl);
    for (long r = 0; f && r < count; r++) job_line(f, &s, exe, scene, dir, r, w);
    if (f) fclose(f);
    f = open_memstream(&slurm, &sl);
    if (f) slurm_script(f, &s, dir, count, w), fclose(f);
    cJSON *desc = describe(&s, exe, scene, dir, count, w);
    char *json = desc ? cJSON_Print(desc) : NULL;
    cJSON_Delete(desc);
    char slurm_dir[PATH_MAX + 16];
    snprintf(slurm_dir, sizeof slurm_dir, "%s/slurm", dir);
    int ok = jobs && slurm && json && write_file(dir, "jobs.txt", jobs, 0, err, sizeof err) &&
             write_file(dir, "sweep.slurm", slurm, 0755, err, sizeof err) &&
             write_file(dir, "sweep.json", json, 0, err, sizeof err);
    if (ok && mkdir(slurm_dir, 0777) != 0 && errno != EEXIST) {
        snprintf(err, sizeof err, "cannot make %s: %s", slurm_dir, strerror(errno));
        ok = 0;
    }
    free(jobs);
    free(slurm);
    free(json);
    if (!ok) {
        fprintf(stderr, "wobble sweep: --out %s: %s\n", s.out, jobs && slurm && json ? err : "out of memory");
        return EXIT_SCRIPT;
    }
    if (!s.run) {
        printf("%ld runs in %s/jobs.txt\n"
               "  this machine:  parallel < %s/jobs.txt      (or wobble sweep ... --run)\n"
               "  over ssh:      parallel --sshloginfile HOSTS < %s/jobs.txt\n"
               "  Slurm:         sbatch %s/sweep.slurm\n"
               "  then:          wobble collect %s\n",
               count, dir, dir, dir, dir, dir);
        return EXIT_PASS;
    }
    return run_parallel(&s, dir, count);
}
