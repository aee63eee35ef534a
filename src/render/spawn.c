/* spawn.c: starting a helper program (ffmpeg, ffprobe) with chosen standard files,
 * none of the script's other files, default signals and, for the recorder's encoder,
 * a process group of its own. */
#include <fcntl.h>
#include <signal.h>
#include <spawn.h>

#include "render.h"

extern char **environ;

/* posix_spawn_file_actions_addclosefrom_np: glibc 2.34 and later */
#if defined(__GLIBC__) && (__GLIBC__ > 2 || (__GLIBC__ == 2 && __GLIBC_MINOR__ >= 34))
#define HAVE_CLOSEFROM 1
#endif

int wb_spawn(const char *prog, const char *const argv[], const int fds[3], bool group, pid_t *pid)
{
    posix_spawn_file_actions_t fa;
    posix_spawnattr_t at;
    posix_spawn_file_actions_init(&fa);
    for (int k = 0; k < 3; k++) {
        if (fds[k] >= 0) posix_spawn_file_actions_adddup2(&fa, fds[k], k);
        else posix_spawn_file_actions_addopen(&fa, k, "/dev/null", k ? O_WRONLY : O_RDONLY, 0);
    }
#ifdef HAVE_CLOSEFROM
    /* the script's open files (io.open keeps no O_CLOEXEC) are none of its business */
    posix_spawn_file_actions_addclosefrom_np(&fa, 3);
#endif
    posix_spawnattr_init(&at);
    sigset_t none, def;
    sigemptyset(&none);
    sigemptyset(&def);
    sigaddset(&def, SIGPIPE);   /* the writer thread blocks it; the child must not inherit that */
    posix_spawnattr_setsigmask(&at, &none);
    posix_spawnattr_setsigdefault(&at, &def);
    short flags = POSIX_SPAWN_SETSIGMASK | POSIX_SPAWN_SETSIGDEF;
    if (group) {
        posix_spawnattr_setpgroup(&at, 0);
        flags |= POSIX_SPAWN_SETPGROUP;
    }
    posix_spawnattr_setflags(&at, flags);
    int e = posix_spawnp(pid, prog, &fa, &at, (char *const *)argv, environ);
    posix_spawn_file_actions_destroy(&fa);
    posix_spawnattr_destroy(&at);
    return e;
}
