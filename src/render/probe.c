/* probe.c: reading media back through the helper programs (started by wb_spawn,
 * spawn.c): facts through ffprobe, a decoded
 * frame through ffmpeg, so tests can compare a video's pixels with what was drawn. */
#include <errno.h>
#include <fcntl.h>
#include <limits.h>
#include <poll.h>
#include <signal.h>
#include <spawn.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <time.h>
#include <unistd.h>

#include "render.h"

#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wunused-function"
#include <stb/stb_image.h>   /* declarations only: the implementation is in media.c */
#pragma GCC diagnostic pop

/* run argv[0] and collect its standard output (malloc'd, NUL added, *len bytes; what
 * passes max is read and dropped so the program never blocks); *ok: it exited 0. The
 * helper may wait forever (a FIFO, a live stream): `stop` is asked every 100 ms while
 * it runs, and when it answers true the helper is killed and the call fails. */
static char *capture(const char *const argv[], size_t max, const wb_media_stop *stop, size_t *len, bool *ok,
                     char *err, size_t n)
{
    int pfd[2];
    *ok = false;
    if (pipe2(pfd, O_CLOEXEC) != 0) {
        snprintf(err, n, "cannot run %s: %s", argv[0], strerror(errno));
        return NULL;
    }
    pid_t pid;
    int fds[3] = { -1, pfd[1], -1 }, se = wb_spawn(argv[0], argv, fds, false, &pid);
    close(pfd[1]);
    if (se != 0) {
        close(pfd[0]);
        snprintf(err, n, "cannot run %s: %s", argv[0], strerror(se));
        return NULL;
    }
    size_t got = 0, cap = 4096;
    char *out = malloc(cap + 1), drop[4096];
    bool stopped = false;
    for (;;) {
        if (stop && stop->fn) {
            struct pollfd p = { pfd[0], POLLIN, 0 };
            int r = poll(&p, 1, 100);
            if (r < 0 && errno != EINTR) break;
            if (stop->fn(stop->ud)) {
                stopped = true;
                kill(pid, SIGKILL);
                break;
            }
            if (r <= 0) continue;
        }
        if (out && got == cap && cap < max) {
            size_t c = cap * 2 < max ? cap * 2 : max;
            char *q = realloc(out, c + 1);
            if (!q) free(out);
            out = q, cap = c;
        }
        bool keep = out && got < cap;
        ssize_t k = read(pfd[0], keep ? out + got : drop, keep ? cap - got : sizeof drop);
        if (k < 0 && errno == EINTR) continue;
        if (k <= 0) break;
        if (keep) got += (size_t)k;
    }
    close(pfd[0]);
    /* a helper may close its output and still not end: the same question while it runs */
    int status = 0;
    for (;;) {
        bool ask = stop && stop->fn && !stopped;
        pid_t k = waitpid(pid, &status, ask ? WNOHANG : 0);
        if (k == pid || (k < 0 && errno != EINTR)) break;
        if (k == 0 && stop->fn(stop->ud)) {
            stopped = true;
            kill(pid, SIGKILL);
        } else if (k == 0) {
            struct timespec ts = { 0, 10000000 };
            nanosleep(&ts, NULL);
        }
    }
    if (stopped) {
        free(out);
        snprintf(err, n, "%s was stopped: a budget of the script ran out", argv[0]);
        return NULL;
    }
    if (!out) {
        snprintf(err, n, "out of memory reading what %s wrote", argv[0]);
        return NULL;
    }
    out[got] = 0;
    *len = got;
    *ok = WIFEXITED(status) && WEXITSTATUS(status) == 0;
    return out;
}

static const char *tool(const char *env, const char *dflt)
{
    const char *p = getenv(env);   /* tests point these at failing programs */
    return p && *p ? p : dflt;
}

/* "file:" so neither a leading '-' nor a colon in the name means something else
 * ("concat:", "subfile:", "http:" name a file of that name, nothing more) */
static void ff_input(char *in, size_t n, const char *path)
{
    snprintf(in, n, "file:%s%s", path[0] == '/' ? "" : "./", path);
}

/* The demuxer ffmpeg / ffprobe must use for a file, chosen here from its first bytes,
 * never by ffmpeg's own guess and never from its name: ffmpeg would also take formats
 * that open other files (HLS and DASH playlists, ffconcat lists, image2 name patterns,
 * tee, ...), files the sandbox never saw, whatever the name says. Only plain
 * containers that hold their own frames are let through. NULL, and err set: refused. */
static const char *demuxer_of(const char *path, char *err, size_t n)
{
    unsigned char b[16] = { 0 };
    /* O_NONBLOCK: opening a FIFO must not wait for a writer; only a regular file is a
     * media file (a FIFO or a device would keep ffmpeg waiting on a live stream) */
    int fd = open(path, O_RDONLY | O_NONBLOCK | O_CLOEXEC);
    struct stat st;
    if (fd < 0 || fstat(fd, &st) != 0) {
        snprintf(err, n, "cannot read %s: %s", path, strerror(errno));
        if (fd >= 0) close(fd);
        return NULL;
    }
    if (!S_ISREG(st.st_mode)) {
        close(fd);
        snprintf(err, n, "cannot read %s: %s", path, S_ISDIR(st.st_mode) ? strerror(EISDIR) : "not a regular file");
        return NULL;
    }
    ssize_t r = read(fd, b, sizeof b);
    int bad = r < 0 ? errno : 0;
    close(fd);
    if (bad) {
        snprintf(err, n, "cannot read %s: %s", path, strerror(bad));
        return NULL;
    }
    size_t got = (size_t)r;
    static const char *const boxes[] = { "ftyp", "moov", "mdat", "free", "skip", "wide" };  /* ISO BMFF */
    if (got >= 8 && !memcmp(b, "\x89PNG\r\n\x1a\n", 8)) return "png_pipe";   /* one image, no name pattern */
    if (got >= 6 && (!memcmp(b, "GIF87a", 6) || !memcmp(b, "GIF89a", 6))) return "gif";
    if (got >= 4 && !memcmp(b, "\x1a\x45\xdf\xa3", 4)) return "matroska";     /* and webm */
    if (got >= 12 && !memcmp(b, "RIFF", 4) && !memcmp(b + 8, "AVI ", 4)) return "avi";
    for (size_t i = 0; got >= 8 && i < sizeof boxes / sizeof *boxes; i++)
        if (!memcmp(b + 4, boxes[i], 4)) return "mov";                          /* mp4, mov, m4v */
    const char *what = got >= 7 && !memcmp(b, "#EXTM3U", 7) ? " (an HLS playlist)"
                       : got >= 8 && !memcmp(b, "ffconcat", 8) ? " (an ffconcat list)"
                       : got >= 1 && b[0] == '<' ? " (XML: a DASH manifest or the like)" : "";
    snprintf(err, n, "%s is not a media file wobble reads%s: only mp4/mov, gif, png, mkv/webm and avi, known by "
             "their contents; playlists and lists naming other files are refused", path, what);
    return NULL;
}

/* the input's options: the demuxer demuxer_of chose, the file protocol only, and no
 * external tracks ("drefs") in a mov; ffmpeg refuses an option its demuxer lacks, so
 * that one goes to mov alone. Appends at argv[a], returns the new count. */
static int input_args(const char **argv, int a, const char *fmt, const char *in)
{
    const char *head[] = { "-protocol_whitelist", "file", "-f", fmt };
    for (size_t k = 0; k < sizeof head / sizeof *head; k++) argv[a++] = head[k];
    if (!strcmp(fmt, "mov")) {
        argv[a++] = "-enable_drefs";
        argv[a++] = "0";
    }
    argv[a++] = "-i";
    argv[a++] = in;
    return a;
}


/* prog (ffprobe) on path read as fmt with the arguments tail (NULL-ended): its output, at
 * most cap bytes (NULL with the message); *ok: it ended with 0 */
static char *ffprobe(const char *prog, const char *path, const char *fmt, const char *const *tail, size_t cap,
                     const wb_media_stop *stop, bool *ok, char *err, size_t n)
{
    char in[PATH_MAX + 16];
    ff_input(in, sizeof in, path);
    const char *argv[32] = { prog, "-v", "error" };
    int a = input_args(argv, 3, fmt, in);
    for (size_t k = 0; tail[k]; k++) argv[a++] = tail[k];
    argv[a] = NULL;
    size_t len;
    return capture(argv, cap, stop, &len, ok, err, n);
}
bool wb_media_probe(const char *path, wb_media_info *info, const wb_media_stop *stop, char *err, size_t n)
{
    memset(info, 0, sizeof *info);
    const char *e = strrchr(path, '.');
    if (e && !strchr(e, '/') && !strcasecmp(e, ".png")) {
        int comp;
        if (!stbi_info(path, &info->width, &info->height, &comp)) {
            snprintf(err, n, "%s is not a readable PNG (%s)", path, stbi_failure_reason());
            return false;
        }
        info->frames = 1;
        snprintf(info->codec, sizeof info->codec, "png");
        snprintf(info->pix_fmt, sizeof info->pix_fmt, comp == 4 ? "rgba" : comp == 3 ? "rgb24" : "gray");
        return true;
    }
    const char *fmt = demuxer_of(path, err, n);
    if (!fmt) return false;
    const char *prog = tool("WOBBLE_FFPROBE", "ffprobe");
    const char *tail[] = { "-count_frames", "-select_streams", "v:0", "-show_entries",
                           "stream=width,height,codec_name,pix_fmt,nb_read_frames:format=duration", "-of",
                           "default=noprint_wrappers=1", NULL };
    bool ok;
    char *out = ffprobe(prog, path, fmt, tail, 65536, stop, &ok, err, n);
    if (!out) return false;
    char *save = NULL;
    for (char *line = strtok_r(out, "\n", &save); line; line = strtok_r(NULL, "\n", &save)) {
        char *eq = strchr(line, '=');
        if (!eq) continue;
        *eq = 0;
        const char *v = eq + 1;
        if (!strcmp(line, "width")) info->width = atoi(v);
        else if (!strcmp(line, "height")) info->height = atoi(v);
        else if (!strcmp(line, "nb_read_frames")) info->frames = atoll(v);
        else if (!strcmp(line, "duration")) info->duration = atof(v);
        else if (!strcmp(line, "codec_name")) snprintf(info->codec, sizeof info->codec, "%s", v);
        else if (!strcmp(line, "pix_fmt")) snprintf(info->pix_fmt, sizeof info->pix_fmt, "%s", v);
    }
    free(out);
    if (!ok || !info->codec[0]) {
        snprintf(err, n, "%s: not a video %s can read", path, prog);
        return false;
    }
    return true;
}

/* ffmpeg decoding one frame and writing it as a PNG (the decoder's frames, the RGB
 * conversion, the encoder; measured 9 to 17 bytes a pixel over its 55 MB of libraries,
 * PNG and H.264), then here the PNG it wrote (3 bytes a pixel at most) and stb's decode
 * of it (png_bytes: 9 for RGB8) */
#define HELPER_BYTES ((size_t)64 << 20)
#define FRAME_HELPER_PX 24
#define FRAME_HERE_PX 12

bool wb_media_frame_size(const char *path, const wb_media_stop *stop, int *w, int *h, char *err, size_t n)
{
    *w = *h = 0;
    const char *fmt = demuxer_of(path, err, n);
    if (!fmt) return false;
    if (!strcmp(fmt, "png_pipe")) {   /* its header, never ffprobe: that decodes the image */
        int comp;
        if (stbi_info(path, w, h, &comp) && *w > 0 && *h > 0) return true;
        snprintf(err, n, "%s is not a readable PNG (%s)", path, stbi_failure_reason());
        return false;
    }
    const char *prog = tool("WOBBLE_FFPROBE", "ffprobe");
    const char *tail[] = { "-select_streams", "v:0", "-show_entries", "stream=width,height", "-of",
                           "default=noprint_wrappers=1", NULL };
    bool ok;
    char *out = ffprobe(prog, path, fmt, tail, 4096, stop, &ok, err, n);
    if (!out) return false;
    char *save = NULL;
    for (char *line = strtok_r(out, "\n", &save); line; line = strtok_r(NULL, "\n", &save)) {
        if (!strncmp(line, "width=", 6)) *w = atoi(line + 6);
        else if (!strncmp(line, "height=", 7)) *h = atoi(line + 7);
    }
    free(out);
    if (!ok || *w <= 0 || *h <= 0) {
        snprintf(err, n, "%s: not a video %s can read", path, prog);
        return false;
    }
    return true;
}

size_t wb_media_helper_bytes(int w, int h)
{
    const size_t px = (size_t)(w > 0 ? w : 0) * (size_t)(h > 0 ? h : 0);
    return HELPER_BYTES + px * FRAME_HELPER_PX;
}

size_t wb_media_frame_bytes(int w, int h)
{
    const size_t px = (size_t)(w > 0 ? w : 0) * (size_t)(h > 0 ? h : 0);
    return wb_media_helper_bytes(w, h) + px * FRAME_HERE_PX;
}

uint8_t *wb_media_read_frame(const char *path, int64_t index, const wb_media_stop *stop, int *w, int *h, char *err,
                             size_t n)
{
    const int want_w = *w, want_h = *h;
    const char *fmt = demuxer_of(path, err, n);
    if (!fmt) return NULL;
    const char *prog = tool("WOBBLE_FFMPEG", "ffmpeg");
    char in[PATH_MAX + 16], select[64];
    ff_input(in, sizeof in, path);
    snprintf(select, sizeof select, "select=eq(n\\,%lld)", (long long)index);
    /* the frame as a PNG on stdout: it carries its own size; the input as in probe */
    const char *argv[32] = { prog, "-v", "error", "-nostdin" };
    int a = input_args(argv, 4, fmt, in);
    const char *tail[] = { "-vf", select, "-fps_mode", "passthrough", "-frames:v", "1", "-f", "image2pipe",
                           "-c:v", "png", "pipe:1", NULL };
    for (size_t k = 0; k < sizeof tail / sizeof *tail; k++) argv[a++] = tail[k];
    size_t len;
    bool ok;
    /* a frame of the size asked for: what passes its PNG (rows of RGB, a filter byte
     * each, stored uncompressed at worst) is dropped, and a frame of any other size (a
     * stream that changes size on the way) is refused before it is decoded */
    const size_t max = want_w > 0 && want_h > 0 ? ((size_t)want_w * 3 + 1) * (size_t)want_h + ((size_t)1 << 20)
                                                 : (size_t)1 << 30;
    char *out = capture(argv, max, stop, &len, &ok, err, n);
    if (!out) return NULL;
    int comp, fw = 0, fh = 0;
    if (ok && len && want_w > 0 && want_h > 0 &&
        (!stbi_info_from_memory((const unsigned char *)out, (int)len, &fw, &fh, &comp) || fw != want_w || fh != want_h)) {
        free(out);
        snprintf(err, n, "%s: frame %lld is not %dx%d as the file's header says", path, (long long)index, want_w,
                 want_h);
        return NULL;
    }
    uint8_t *px = ok && len ? stbi_load_from_memory((const unsigned char *)out, (int)len, w, h, &comp, 3) : NULL;
    free(out);
    if (!px) snprintf(err, n, "%s: no frame %lld (%s could not decode it)", path, (long long)index, prog);
    return px;
}
