/* file.c: files written whole. Every file wobble writes for a script or a user goes
 * into a temporary beside its name (same folder: the rename is atomic) and is renamed
 * over the name once complete, so a reader, an error, a budget stop or a kill -9 finds
 * the old file or the new one, never part of one.
 *
 * The name is never followed when it is a symbolic link: the temporary is made with
 * O_CREAT | O_EXCL | O_NOFOLLOW and the rename replaces the link itself, so a link left
 * in an output folder cannot lead a write elsewhere. (The sandbox decides beforehand
 * whether a script may write a name; this file makes sure the write lands there.)
 *
 * The temporaries in progress are listed in a table the signal handler can read
 * without locks: SIGINT, SIGTERM and SIGHUP remove them before the process dies of the
 * signal, as does an exit() and the watchdog's end of a run past its time limit. */
#include <errno.h>
#include <fcntl.h>
#include <limits.h>
#include <pthread.h>
#include <signal.h>
#include <stdatomic.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "io.h"

/* ---- the table of temporaries ------------------------------------------------------------- */
/* state: 0 free, 1 taken (being filled or emptied), 2 a temporary that exists. A fork
 * without exec (the importer's child) inherits the table: pid keeps it from removing
 * its parent's files. Past NTEMP temporaries at once, the others are not listed (they are
 * still removed by their writers, just not by a signal). */
#define NTEMP 256
static struct temp_slot {
    atomic_int state;
    pid_t pid;
    int dir;
    char name[PATH_MAX];
} temps[NTEMP];

static int list_temp(int dir, const char *name)
{
    if (strlen(name) >= PATH_MAX) return -1;
    for (int i = 0; i < NTEMP; i++) {
        int free_state = 0;
        if (!atomic_compare_exchange_strong(&temps[i].state, &free_state, 1)) continue;
        temps[i].pid = getpid();
        temps[i].dir = dir;
        strcpy(temps[i].name, name);
        atomic_store(&temps[i].state, 2);
        return i;
    }
    return -1;
}

static void unlist_temp(int slot)
{
    if (slot < 0) return;
    atomic_store(&temps[slot].state, 1);
    atomic_store(&temps[slot].state, 0);
}

/* A temporary is made and listed between a rise and a fall of `opening`, with the
 * caller's signals blocked; the removal first sets `dying`, then waits (bounded) for the
 * makings under way, so another thread cannot make a temporary after the removal ran
 * over the list and before the process is gone: a making that starts after it sees
 * `dying` and makes nothing */
static atomic_int opening, dying;

/* async-signal-safe: unlinkat and getpid only */
void wbio_remove_temporaries(void)
{
    const pid_t me = getpid();
    atomic_store(&dying, 1);
    for (long spin = 0; atomic_load(&opening) > 0 && spin < 100000000L; spin++) {}
    for (int i = 0; i < NTEMP; i++)
        if (atomic_load(&temps[i].state) == 2 && temps[i].pid == me) unlinkat(temps[i].dir, temps[i].name, 0);
}

static void on_signal(int sig)
{
    wbio_remove_temporaries();
    /* then die of the signal, as without the handler (it is blocked until we return) */
    struct sigaction dfl;
    memset(&dfl, 0, sizeof dfl);
    dfl.sa_handler = SIG_DFL;
    sigemptyset(&dfl.sa_mask);
    sigaction(sig, &dfl, NULL);
    raise(sig);
}

static void at_exit(void) { wbio_remove_temporaries(); }

void wbio_clean_on_signals(void)
{
    static atomic_int done;
    if (atomic_exchange(&done, 1)) return;
    static const int sigs[] = { SIGINT, SIGTERM, SIGHUP };
    for (size_t i = 0; i < sizeof sigs / sizeof *sigs; i++) {
        struct sigaction old, sa;
        /* a signal the caller ignores (nohup, a background job's SIGINT) stays ignored */
        if (sigaction(sigs[i], NULL, &old) != 0 || old.sa_handler != SIG_DFL) continue;
        memset(&sa, 0, sizeof sa);
        sa.sa_handler = on_signal;
        sigfillset(&sa.sa_mask);
        sigaction(sigs[i], &sa, NULL);
    }
    atexit(at_exit);
}

/* ---- one file -------------------------------------------------------------------------------- */
static void set_err(char *err, size_t errn, const char *shown, int e)
{
    if (err && errn) snprintf(err, errn, "%s%s%s", shown, *shown ? ": " : "", strerror(e ? e : EIO));
}

int wbio_out_open(wbio_out *o, int dir, const char *name, const char *shown, char *err, size_t errn)
{
    static atomic_uint seq;
    memset(o, 0, sizeof *o);
    o->dir = dir;
    o->slot = -1;
    if (!*name || snprintf(o->name, sizeof o->name, "%s", name) >= (int)sizeof o->name) {
        set_err(err, errn, shown, *name ? ENAMETOOLONG : ENOENT);
        return -1;
    }
    struct stat st;
    const int exists = fstatat(dir, name, &st, AT_SYMLINK_NOFOLLOW) == 0;
    if (exists && S_ISDIR(st.st_mode)) {
        set_err(err, errn, shown, EISDIR);
        return -1;
    }
    /* a FIFO or a device (not a link to one) is written in place: there is nothing to keep */
    if (exists && !S_ISREG(st.st_mode) && !S_ISLNK(st.st_mode)) {
        int fd = openat(dir, name, O_WRONLY | O_NOFOLLOW | O_CLOEXEC);
        if (fd < 0 || !(o->f = fdopen(fd, "wb"))) {
            int e = errno;
            if (fd >= 0) close(fd);
            set_err(err, errn, shown, e);
            return -1;
        }
        o->direct = 1;
        return 0;
    }
    /* a file we could not write in place is not replaced either */
    if (exists && S_ISREG(st.st_mode) && faccessat(dir, name, W_OK, AT_EACCESS) != 0) {
        set_err(err, errn, shown, errno);
        return -1;
    }
    const char *slash = strrchr(name, '/'), *base = slash ? slash + 1 : name;
    const int dl = slash ? (int)(slash - name + 1) : 0;
    int fd = -1;
    sigset_t all, old;
    sigfillset(&all);
    pthread_sigmask(SIG_BLOCK, &all, &old);
    atomic_fetch_add(&opening, 1);
    if (atomic_load(&dying)) errno = EINTR;
    for (int tries = 0; fd < 0 && tries < 100 && !atomic_load(&dying); tries++) {
        /* hidden, and named after its file so a stray one says where it came from */
        if (snprintf(o->tmp, sizeof o->tmp, "%.*s.%.200s.%ld-%u.tmp", dl, name, base, (long)getpid(),
                     atomic_fetch_add(&seq, 1)) >= (int)sizeof o->tmp) {
            set_err(err, errn, shown, ENAMETOOLONG);
            return -1;
        }
        fd = openat(dir, o->tmp, O_WRONLY | O_CREAT | O_EXCL | O_NOFOLLOW | O_CLOEXEC, 0666);
        if (fd < 0 && errno != EEXIST) break;
    }
    if (fd >= 0) o->slot = list_temp(dir, o->tmp);
    const int e = errno;
    atomic_fetch_sub(&opening, 1);
    pthread_sigmask(SIG_SETMASK, &old, NULL);
    if (fd < 0) {
        set_err(err, errn, shown, e);
        return -1;
    }
    /* the new file keeps the old one's permissions */
    if (exists && S_ISREG(st.st_mode)) (void)fchmod(fd, st.st_mode & 07777);
    if (!(o->f = fdopen(fd, "wb"))) {
        int e = errno;
        close(fd);
        wbio_out_abort(o);
        set_err(err, errn, shown, e);
        return -1;
    }
    return 0;
}

int wbio_out_close_file(wbio_out *o)
{
    if (!o->f) return o->failed;
    int bad = ferror(o->f), e = errno;
    if (fclose(o->f) != 0 && !bad) bad = 1, e = errno;
    o->f = NULL;
    if (bad && !o->failed) o->failed = e ? e : EIO;
    return o->failed;
}

int wbio_out_commit(wbio_out *o, const char *shown, char *err, size_t errn)
{
    int e = wbio_out_close_file(o);
    if (!e && !o->direct && renameat(o->dir, o->tmp, o->dir, o->name) != 0) e = errno;
    if (e) {
        wbio_out_abort(o);
        set_err(err, errn, shown, e);
        return -1;
    }
    unlist_temp(o->slot);
    o->slot = -1;
    o->tmp[0] = 0;
    return 0;
}

void wbio_out_abort(wbio_out *o)
{
    if (o->f) fclose(o->f);
    o->f = NULL;
    if (!o->direct && o->tmp[0]) unlinkat(o->dir, o->tmp, 0);
    unlist_temp(o->slot);
    o->slot = -1;
    o->tmp[0] = 0;
}

int wbio_write_bytes(int dir, const char *name, const char *shown, const void *data, size_t n, char *err, size_t errn)
{
    wbio_out o;
    if (wbio_out_open(&o, dir, name, shown, err, errn)) return -1;
    if (fwrite(data, 1, n, o.f) != n) o.failed = errno ? errno : EIO;
    return wbio_out_commit(&o, shown, err, errn);
}

int wbio_follow_link(const char *path, char *out, size_t n)
{
    struct stat st;
    char real[PATH_MAX];
    if (lstat(path, &st) == 0 && S_ISLNK(st.st_mode) && realpath(path, real)) path = real;
    return snprintf(out, n, "%s", path) < (int)n ? 0 : -1;
}
