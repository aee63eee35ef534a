/* treepeak: run a command and measure the peak resident memory of its whole process
 * tree (the command and every process it starts, together), for tests/cli/budget.sh.
 *
 *   treepeak [-c CAP_MB] [-t SECONDS] -o FILE -- COMMAND [ARGS...]
 *
 * The tree's RSS is summed every 5 ms from /proc (descendants found by their parent
 * pid; this process is their subreaper, so a child whose parent died stays in the
 * tree). The peak is the larger of that sum and the largest single peak the kernel saw
 * (getrusage of the reaped children). A tree past CAP_MB, or still running after
 * SECONDS, is killed, so a test of a broken budget cannot stress the machine. When the
 * command ends, what it left running is counted and killed.
 *
 * FILE gets one line: "peak_kb N left N capped 0|1 timeout 0|1". The exit status is
 * the command's (128 + signal when it was killed). */
#include <dirent.h>
#include <errno.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/prctl.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <time.h>
#include <unistd.h>

#define MAXP 4096

static double now(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + ts.tv_nsec * 1e-9;
}

/* the live (not zombie) descendants of this process into out; their count */
static int descendants(pid_t *out, int max)
{
    static pid_t pid[MAXP], ppid[MAXP];
    int n = 0;
    DIR *d = opendir("/proc");
    if (!d) return 0;
    struct dirent *e;
    while ((e = readdir(d)) && n < MAXP) {
        char *end, p[64], buf[512];
        long v = strtol(e->d_name, &end, 10);
        if (*end || v <= 0) continue;
        snprintf(p, sizeof p, "/proc/%ld/stat", v);
        FILE *f = fopen(p, "r");
        if (!f) continue;
        size_t k = fread(buf, 1, sizeof buf - 1, f);
        fclose(f);
        buf[k] = 0;
        char *rp = strrchr(buf, ')'), state;
        long pp;
        if (!rp || sscanf(rp + 1, " %c %ld", &state, &pp) != 2 || state == 'Z') continue;
        pid[n] = (pid_t)v;
        ppid[n++] = (pid_t)pp;
    }
    closedir(d);
    /* breadth first from this process */
    int m = 0;
    pid_t me = getpid();
    for (int i = 0; i < n; i++)
        if (ppid[i] == me && m < max) out[m++] = pid[i];
    for (int h = 0; h < m; h++)
        for (int i = 0; i < n; i++)
            if (ppid[i] == out[h] && m < max) out[m++] = pid[i];
    return m;
}

static long rss_kb(pid_t p)
{
    char path[64];
    long size, res;
    snprintf(path, sizeof path, "/proc/%d/statm", (int)p);
    FILE *f = fopen(path, "r");
    if (!f) return 0;
    int ok = fscanf(f, "%ld %ld", &size, &res) == 2;
    fclose(f);
    return ok ? res * (sysconf(_SC_PAGESIZE) / 1024) : 0;
}

static void kill_tree(void)
{
    pid_t t[MAXP];
    for (int round = 0; round < 3; round++) {
        int n = descendants(t, MAXP);
        if (!n) return;
        for (int i = 0; i < n; i++) kill(t[i], SIGKILL);
        while (waitpid(-1, NULL, WNOHANG) > 0) {}
        usleep(20000);
    }
}

int main(int argc, char **argv)
{
    long cap_mb = 0;
    double limit = 0;
    const char *out = NULL;
    int a = 1;
    for (; a < argc && strcmp(argv[a], "--"); a++) {
        if (!strcmp(argv[a], "-c") && a + 1 < argc) cap_mb = atol(argv[++a]);
        else if (!strcmp(argv[a], "-t") && a + 1 < argc) limit = atof(argv[++a]);
        else if (!strcmp(argv[a], "-o") && a + 1 < argc) out = argv[++a];
        else break;
    }
    if (a >= argc || strcmp(argv[a], "--") || a + 1 >= argc || !out) {
        fprintf(stderr, "usage: treepeak [-c CAP_MB] [-t SECONDS] -o FILE -- COMMAND [ARGS...]\n");
        return 125;
    }
    prctl(PR_SET_CHILD_SUBREAPER, 1);
    pid_t child = fork();
    if (child < 0) return perror("fork"), 125;
    if (child == 0) {
        execvp(argv[a + 1], argv + a + 1);
        perror(argv[a + 1]);
        _exit(127);
    }
    long peak = 0;
    int status = 0, capped = 0, timed = 0, done = 0;
    double t0 = now();
    pid_t t[MAXP];
    while (!done) {
        long sum = 0;
        int n = descendants(t, MAXP);
        for (int i = 0; i < n; i++) sum += rss_kb(t[i]);
        if (sum > peak) peak = sum;
        if (!capped && cap_mb > 0 && sum > cap_mb * 1024) capped = 1, kill_tree();
        if (!timed && limit > 0 && now() - t0 > limit) timed = 1, kill_tree();
        /* reap: the command, and orphans of the tree (this process is their subreaper) */
        pid_t k;
        while ((k = waitpid(-1, &status, WNOHANG)) > 0)
            if (k == child) done = 1;
        if (!done) usleep(5000);
    }
    int code = WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
    /* what the command left behind: given a moment to end by itself (a helper that
     * sees its parent die), then counted and killed */
    int left = 0;
    for (int i = 0; i < 40 && (left = descendants(t, MAXP)) > 0; i++) {
        usleep(25000);
        while (waitpid(-1, NULL, WNOHANG) > 0) {}
    }
    if (left) kill_tree();
    while (waitpid(-1, NULL, WNOHANG) > 0) {}
    struct rusage ru;
    if (getrusage(RUSAGE_CHILDREN, &ru) == 0 && ru.ru_maxrss > peak) peak = ru.ru_maxrss;
    FILE *f = fopen(out, "w");
    if (!f) return perror(out), 125;
    fprintf(f, "peak_kb %ld left %d capped %d timeout %d\n", peak, left, capped, timed);
    fclose(f);
    return code;
}
