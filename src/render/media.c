/* media.c: images and videos. PNG through stb_image_write (fast compression, into
 * memory: the layer above writes the bytes, each file whole); MP4 (H.264, yuv420p) and
 * GIF by piping raw RGB frames to the ffmpeg program, which writes the file the caller
 * names (a temporary it renames when the recording went well); a folder of numbered
 * PNGs, each handed to the caller's write_frame. Frames are encoded on a writer thread so the caller simulates the
 * next frame meanwhile. A failed encoder is an error, never a hang: SIGPIPE is
 * blocked on the writer thread (EPIPE instead), the exit status is checked, and an
 * encoder that stops taking frames is killed after a timeout. */
#include <errno.h>
#include <fcntl.h>
#include <limits.h>
#include <math.h>
#include <pthread.h>
#include <signal.h>
#include <stdatomic.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <time.h>
#include <unistd.h>

#include "render.h"

/* stb's implementation, once in the program, without its warnings */
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wsign-compare"
#pragma GCC diagnostic ignored "-Wunused-parameter"
#pragma GCC diagnostic ignored "-Wunused-function"
#pragma GCC diagnostic ignored "-Wmissing-field-initializers"
#pragma GCC diagnostic ignored "-Wimplicit-fallthrough"
#pragma GCC diagnostic ignored "-Wdouble-promotion"
#pragma GCC diagnostic ignored "-Wcast-qual"
#define STB_IMAGE_WRITE_IMPLEMENTATION
#define STBI_WRITE_NO_STDIO
#include <stb/stb_image_write.h>
#define STB_IMAGE_IMPLEMENTATION
#define STBI_ONLY_PNG
#include <stb/stb_image.h>
#pragma GCC diagnostic pop

#define NSLOT 3   /* frames queued for the writer thread */

/* ---- PNG ------------------------------------------------------------------------------ */
typedef struct membuf { unsigned char *p; size_t n, cap; bool oom; } membuf;

static void mem_write(void *ctx, void *data, int size)
{
    membuf *m = ctx;
    if (m->oom || size <= 0) return;
    if (m->n + (size_t)size > m->cap) {
        size_t cap = m->cap ? m->cap : 65536;
        while (cap < m->n + (size_t)size) cap *= 2;
        unsigned char *q = realloc(m->p, cap);
        if (!q) {
            m->oom = true;
            return;
        }
        m->p = q;
        m->cap = cap;
    }
    memcpy(m->p + m->n, data, (size_t)size);
    m->n += (size_t)size;
}

static bool png_encode(membuf *m, const uint8_t *rgb, int w, int h)
{
    /* level 1: about as small as 8 for rendered frames, several times faster */
    stbi_write_png_compression_level = 1;
    return stbi_write_png_to_func(mem_write, m, w, h, 3, rgb, w * 3) && !m->oom;
}

void *wb_image_encode_png(const uint8_t *rgb, int w, int h, size_t *n)
{
    membuf m = { 0 };
    if (!png_encode(&m, rgb, w, h)) {
        free(m.p);
        return NULL;
    }
    *n = m.n;
    return m.p;
}

size_t wb_image_png_bytes(const char *path, int *w, int *h)
{
    FILE *f = fopen(path, "rb");
    if (!f) return 0;
    int comp = 0;
    const int ok = stbi_info_from_file(f, w, h, &comp), wide = ok && stbi_is_16_bit_from_file(f);
    fclose(f);
    if (!ok || *w < 1 || *h < 1) return 0;
    /* stb holds the inflated rows and the image at the file's depth together, then that
     * image and its RGB8 conversion: at most twice the file's bytes per pixel plus 3 */
    const size_t px = (size_t)*w * (size_t)*h, depth = (size_t)comp * (wide ? 2 : 1);
    return px * (2 * depth + 3) + (size_t)*h;
}

uint8_t *wb_image_read_png(const char *path, int *w, int *h, char *err, size_t n)
{
    FILE *f = fopen(path, "rb");
    if (!f) {
        snprintf(err, n, "cannot open %s: %s", path, strerror(errno));
        return NULL;
    }
    int comp = 0;
    uint8_t *px = stbi_load_from_file(f, w, h, &comp, 3);
    fclose(f);
    if (!px) snprintf(err, n, "%s is not a PNG image we can read (%s)", path, stbi_failure_reason());
    return px;
}

/* ---- what a path records to --------------------------------------------------------- */
static const char *ext_of(const char *path)
{
    const char *slash = strrchr(path, '/'), *base = slash ? slash + 1 : path, *dot = strrchr(base, '.');
    return dot && dot != base ? dot : NULL;
}

wb_media wb_media_of(const char *given, const char *path, char *err, size_t n)
{
    size_t len = strlen(given);
    struct stat st;
    if (len == 0) {
        snprintf(err, n, "empty path");
        return WB_MEDIA_NONE;
    }
    if (given[len - 1] == '/' || (stat(path ? path : given, &st) == 0 && S_ISDIR(st.st_mode))) return WB_MEDIA_FOLDER;
    const char *e = ext_of(given);
    if (!e) return WB_MEDIA_FOLDER;
    if (!strcasecmp(e, ".mp4")) return WB_MEDIA_MP4;
    if (!strcasecmp(e, ".gif")) return WB_MEDIA_GIF;
    snprintf(err, n, "cannot record to '%s': unknown extension '%s' (expected .mp4, .gif, or a folder for PNG frames)",
             given, e);
    return WB_MEDIA_NONE;
}

/* ---- the recorder ---------------------------------------------------------------------- */
struct wb_recorder {
    wb_media kind;
    char path[PATH_MAX];
    wb_media_out out;             /* where the frames or the encoder's file go */
    char encode_to[PATH_MAX];
    int w, h;
    double fps, timeout;
    size_t bytes;                 /* of one frame */
    bool started;
    pid_t pid;                    /* ffmpeg, or 0 */
    int fd, errfd;                /* its stdin (our end) and its stderr (a temporary file) */
    pthread_t th;
    bool thread_on;
    pthread_mutex_t mu;
    pthread_cond_t cv;
    uint8_t *slot[NSLOT];
    uint8_t *yuv;                 /* an MP4 of even size: the frame as the encoder takes it */
    int head, queued;
    bool stop, failed;
    char msg[768];
    int64_t frames, written;
};

static const char *ffmpeg_prog(void)
{
    const char *p = getenv("WOBBLE_FFMPEG");   /* tests point it at a failing program */
    return p && *p ? p : "ffmpeg";
}

wb_recorder *wb_recorder_open(const char *path, wb_media kind, int w, int h, const wb_media_out *out, char *err,
                              size_t n)
{
    if (kind == WB_MEDIA_NONE) {
        snprintf(err, n, "cannot record to '%s': no media kind", path);
        return NULL;
    }
    if (strlen(path) >= PATH_MAX - 32 || (kind != WB_MEDIA_FOLDER && strlen(out->encode_to) >= PATH_MAX)) {
        snprintf(err, n, "path too long");
        return NULL;
    }
    wb_recorder *rec = calloc(1, sizeof *rec);
    if (!rec) {
        snprintf(err, n, "out of memory");
        return NULL;
    }
    rec->kind = kind;
    rec->out = *out;
    if (kind != WB_MEDIA_FOLDER) snprintf(rec->encode_to, sizeof rec->encode_to, "%s", out->encode_to);
    rec->out.encode_to = NULL;   /* the caller's string need not outlive this call */
    snprintf(rec->path, sizeof rec->path, "%s", path);
    rec->w = w, rec->h = h;
    rec->fps = 60;
    rec->bytes = (size_t)w * (size_t)h * 3;
    rec->fd = rec->errfd = -1;
    const char *t = getenv("WOBBLE_ENCODER_TIMEOUT");
    rec->timeout = t && atof(t) > 0 ? atof(t) : 60;
    pthread_mutex_init(&rec->mu, NULL);
    pthread_cond_init(&rec->cv, NULL);
    return rec;
}

/* The encoder's threads, fixed so that what it takes is known: x264 alone would take 1.5
 * per core, and each holds frames of its own */
#define ENC_THREADS_MAX 4
static int encoder_threads(void)
{
    long n = sysconf(_SC_NPROCESSORS_ONLN);
    return n < 1 ? 1 : n > ENC_THREADS_MAX ? ENC_THREADS_MAX : (int)n;
}

/* ffmpeg encoding w x h frames: its libraries, then per pixel the raw frames it queues,
 * the yuv420p conversion, x264's lookahead and reference frames and one frame more per
 * thread. Measured peaks (veryfast, which holds more than superfast, 1 / 4 threads): 512^2 80 / 93 MB, 1024^2 149 / 198 MB,
 * 2048^2 392 / 556 MB; the GIF's palette filters take less (132 MB at 1024^2) */
static size_t encoder_bytes(int w, int h)
{
    const size_t px = (size_t)(w + (w & 1)) * (size_t)(h + (h & 1));
    return ((size_t)64 << 20) + px * (size_t)(88 + 12 * encoder_threads());
}

size_t wb_recorder_bytes(wb_media kind, int w, int h)
{
    const size_t frames = NSLOT * (size_t)w * (size_t)h * 3 + (kind == WB_MEDIA_MP4 ? (size_t)w * (size_t)h * 3 / 2 : 0);
    return kind == WB_MEDIA_MP4 || kind == WB_MEDIA_GIF ? frames + encoder_bytes(w, h) : frames;
}

void wb_recorder_set_fps(wb_recorder *rec, double fps)
{
    if (!rec->started && fps > 0) rec->fps = fps;
}

bool wb_recorder_started(const wb_recorder *rec) { return rec->started; }
int64_t wb_recorder_frames(const wb_recorder *rec) { return rec->frames; }
const char *wb_recorder_path(const wb_recorder *rec) { return rec->path; }

static void fail(wb_recorder *rec, const char *fmt, const char *a, const char *b)
{
    if (rec->failed) return;
    rec->failed = true;
    snprintf(rec->msg, sizeof rec->msg, fmt, a, b);
}

static bool write_all(int fd, const uint8_t *p, size_t n, int *e)
{
    while (n) {
        ssize_t k = write(fd, p, n);
        if (k < 0 && errno == EINTR) continue;
        if (k <= 0) {
            *e = k < 0 ? errno : EIO;
            return false;
        }
        p += k;
        n -= (size_t)k;
    }
    return true;
}

/* RGB (top row first) as planar yuv420p, BT.709 in limited range: what ffmpeg's scale
 * filter made of it (out_color_matrix=bt709:out_range=tv), at a third of its CPU time and
 * half the bytes through the pipe. Chroma from each 2x2 block's mean. Fixed point: the
 * matrix's rows times 2^16 / 255 */
static void rgb_to_yuv420(const uint8_t *rgb, int w, int h, uint8_t *yuv)
{
    uint8_t *Y = yuv, *U = yuv + (size_t)w * h, *V = U + (size_t)(w / 2) * (h / 2);
    enum { YR = 11966, YG = 40254, YB = 4064,          /* 219 x (0.2126, 0.7152, 0.0722) */
           UR = -6596, UG = -22189, UB = 28785,        /* 224 x (-0.2126, -0.7152, 0.9278) / 1.8556 */
           VR = 28785, VG = -26145, VB = -2640 };      /* 224 x (0.7874, -0.7152, -0.0722) / 1.5748 */
    for (int y = 0; y < h; y++) {
        const uint8_t *p = rgb + (size_t)y * w * 3;
        uint8_t *o = Y + (size_t)y * w;
        for (int x = 0; x < w; x++, p += 3) o[x] = (uint8_t)((YR * p[0] + YG * p[1] + YB * p[2] + (16 << 16) + 32768) >> 16);
    }
    for (int y = 0; y < h / 2; y++) {
        const uint8_t *a = rgb + (size_t)(2 * y) * w * 3, *b = a + (size_t)w * 3;
        uint8_t *u = U + (size_t)y * (w / 2), *v = V + (size_t)y * (w / 2);
        for (int x = 0; x < w / 2; x++, a += 6, b += 6) {
            const int r = a[0] + a[3] + b[0] + b[3], g = a[1] + a[4] + b[1] + b[4], bl = a[2] + a[5] + b[2] + b[5];
            /* the sums are of four pixels: a quarter, with the offset and the rounding */
            u[x] = (uint8_t)((UR * r + UG * g + UB * bl + (128 << 18) + (1 << 17)) >> 18);
            v[x] = (uint8_t)((VR * r + VG * g + VB * bl + (128 << 18) + (1 << 17)) >> 18);
        }
    }
}

/* one frame out (writer thread, no lock held); false with rec->msg-worthy text in m */
static bool emit(wb_recorder *rec, const uint8_t *rgb, int64_t index, char *m, size_t mn)
{
    if (rec->kind == WB_MEDIA_FOLDER) {
        char name[64];
        snprintf(name, sizeof name, "frame_%06lld.png", (long long)index);
        size_t bytes;
        void *png = wb_image_encode_png(rgb, rec->w, rec->h, &bytes);
        if (!png) {
            snprintf(m, mn, "out of memory encoding %s", name);
            return false;
        }
        bool ok = rec->out.write_frame(rec->out.ud, name, png, bytes, m, mn);
        free(png);
        return ok;
    }
    int e = 0;
    if (rec->yuv) rgb_to_yuv420(rgb, rec->w, rec->h, rec->yuv);
    if (rec->yuv ? write_all(rec->fd, rec->yuv, (size_t)rec->w * rec->h * 3 / 2, &e) : write_all(rec->fd, rgb, rec->bytes, &e))
        return true;
    snprintf(m, mn, "%s", strerror(e));
    return false;
}

static void *writer(void *p)
{
    wb_recorder *rec = p;
    char m[512];
    pthread_mutex_lock(&rec->mu);
    for (;;) {
        while (!rec->queued && !rec->stop) pthread_cond_wait(&rec->cv, &rec->mu);
        if (!rec->queued) break;
        const uint8_t *buf = rec->slot[rec->head];
        int64_t index = rec->written;
        bool skip = rec->failed;   /* after a failure frames are dropped, callers are told */
        pthread_mutex_unlock(&rec->mu);
        bool ok = skip || emit(rec, buf, index, m, sizeof m);
        pthread_mutex_lock(&rec->mu);
        if (!ok) fail(rec, "%s%s", m, "");
        rec->head = (rec->head + 1) % NSLOT;
        rec->queued--;
        rec->written++;
        pthread_cond_broadcast(&rec->cv);
    }
    pthread_mutex_unlock(&rec->mu);
    return NULL;
}

/* ffmpeg reading raw RGB on stdin, its stderr into a temporary file */
static bool spawn_encoder(wb_recorder *rec, char *err, size_t n)
{
    char size[32], rate[32], out[PATH_MAX + 16], tmpl[PATH_MAX], gif_vf[160];
    snprintf(size, sizeof size, "%dx%d", rec->w, rec->h);
    snprintf(rate, sizeof rate, "%.6g", rec->fps);
    /* "file:" so neither a leading '-' nor a colon in the name means something else */
    snprintf(out, sizeof out, "file:%s%s", rec->encode_to[0] == '/' ? "" : "./", rec->encode_to);
    const char *prog = ffmpeg_prog();
    const char *argv[48];
    int a = 0;
    char threads[16];
    snprintf(threads, sizeof threads, "%d", encoder_threads());
    const char *head[] = { prog, "-hide_banner", "-loglevel", "error", "-nostdin", "-y", "-filter_threads", threads,
                           "-f", "rawvideo", "-pixel_format", rec->yuv ? "yuv420p" : "rgb24", "-video_size", size,
                           "-framerate", rate,
                           "-i", "pipe:0", "-an", "-threads", threads };
    for (size_t k = 0; k < sizeof head / sizeof *head; k++) argv[a++] = head[k];
    if (rec->kind == WB_MEDIA_MP4) {
        /* yuv420p plays everywhere but needs even sizes: pad odd ones by a pixel. The
         * conversion uses the BT.709 matrix in limited range and the stream says so:
         * players assume BT.709 for HD, and an untagged BT.601 conversion (ffmpeg's
         * default) shifted saturated colours (the strain's red). Even sizes come
         * converted (rgb_to_yuv420): no filter */
        /* superfast: x264 at about 2/3 of veryfast's CPU time (10 against 16 ms a 720p
         * frame, measured), the file about twice as large at the same crf */
        const char *mp4[] = { "-c:v", "libx264", "-preset", "superfast", "-crf", "18",
                              "-vf", rec->yuv ? "null" : "pad=ceil(iw/2)*2:ceil(ih/2)*2,scale=out_color_matrix=bt709:out_range=tv,format=yuv420p",
                              "-pix_fmt", "yuv420p", "-colorspace", "bt709", "-color_primaries", "bt709",
                              "-color_trc", "bt709", "-color_range", "tv", "-movflags", "+faststart", "-f", "mp4" };
        for (size_t k = 0; k < sizeof mp4 / sizeof *mp4; k++) argv[a++] = mp4[k];
    } else {
        /* a GIF's delays are whole centiseconds and players show one under 2 cs as 10:
         * resample to 100/d frames a second, d >= 2 (60 fps becomes 50), so it plays at
         * the right speed; a palette per frame: nothing buffered for the whole stream */
        double d = fmax(2, ceil(100 / rec->fps - 1e-9));
        snprintf(gif_vf, sizeof gif_vf, "fps=100/%.0f,split[a][b];[a]palettegen=stats_mode=single[p];"
                 "[b][p]paletteuse=new=1", d);
        const char *gif[] = { "-vf", gif_vf, "-loop", "0", "-f", "gif" };
        for (size_t k = 0; k < sizeof gif / sizeof *gif; k++) argv[a++] = gif[k];
    }
    argv[a++] = out;
    argv[a] = NULL;

    const char *tmp = getenv("TMPDIR");
    snprintf(tmpl, sizeof tmpl, "%s/wobble-ffmpeg-XXXXXX", tmp && *tmp ? tmp : "/tmp");
    rec->errfd = mkostemp(tmpl, O_CLOEXEC);
    if (rec->errfd >= 0) unlink(tmpl);
    int pfd[2];
    if (rec->errfd < 0 || pipe2(pfd, O_CLOEXEC) != 0) {
        snprintf(err, n, "cannot start %s: %s", prog, strerror(errno));
        return false;
    }
    /* its own process group: a stalled encoder is killed with whatever it started */
    int fds[3] = { pfd[0], -1, rec->errfd }, e = wb_spawn(prog, argv, fds, true, &rec->pid);
    close(pfd[0]);
    if (e != 0) {
        close(pfd[1]);
        rec->pid = 0;
        if (e == ENOENT)
            snprintf(err, n, "cannot record %s: the program '%s' is not installed (Debian package ffmpeg; "
                             "or record to a folder of PNGs)", rec->path, prog);
        else snprintf(err, n, "cannot start %s: %s", prog, strerror(e));
        return false;
    }
    rec->fd = pfd[1];
    return true;
}

static bool start(wb_recorder *rec, char *err, size_t n)
{
    for (int k = 0; k < NSLOT; k++)
        if (!(rec->slot[k] = malloc(rec->bytes))) {
            snprintf(err, n, "out of memory for the frames of %s", rec->path);
            return false;
        }
    if (rec->kind == WB_MEDIA_MP4 && rec->w % 2 == 0 && rec->h % 2 == 0 &&
        !(rec->yuv = malloc((size_t)rec->w * rec->h * 3 / 2))) {
        snprintf(err, n, "out of memory for the frames of %s", rec->path);
        return false;
    }
    if (rec->kind != WB_MEDIA_FOLDER && !spawn_encoder(rec, err, n)) return false;
    /* the writer thread is born with SIGPIPE blocked: a dead encoder gives EPIPE; the
     * signal left pending on that thread goes away with it */
    sigset_t pipe_only, old;
    sigemptyset(&pipe_only);
    sigaddset(&pipe_only, SIGPIPE);
    pthread_sigmask(SIG_BLOCK, &pipe_only, &old);
    int e = pthread_create(&rec->th, NULL, writer, rec);
    pthread_sigmask(SIG_SETMASK, &old, NULL);
    if (e != 0) {
        snprintf(err, n, "cannot start the writer thread: %s", strerror(e));
        return false;
    }
    rec->thread_on = true;
    rec->started = true;
    return true;
}

static double now(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + ts.tv_nsec * 1e-9;
}

/* wait (lock held) until the queue has fewer than `below` frames or a failure; an
 * encoder that takes nothing for the timeout is killed, so the writer sees EPIPE */
static void wait_queue(wb_recorder *rec, int below)
{
    double t0 = now();
    int64_t seen = rec->written;
    while (rec->queued >= below && !(rec->failed && below > 0)) {
        struct timespec ts;
        clock_gettime(CLOCK_REALTIME, &ts);
        ts.tv_nsec += 100000000;
        if (ts.tv_nsec >= 1000000000) ts.tv_sec++, ts.tv_nsec -= 1000000000;
        pthread_cond_timedwait(&rec->cv, &rec->mu, &ts);
        if (rec->written != seen) seen = rec->written, t0 = now();
        else if (rec->pid > 0 && now() - t0 > rec->timeout) {
            char s[32];
            snprintf(s, sizeof s, "%g", rec->timeout);
            fail(rec, "the encoder took no frame for %s s and was stopped%s", s, "");
            kill(-rec->pid, SIGKILL);
            t0 = now();
        }
    }
}

bool wb_recorder_add(wb_recorder *rec, const uint8_t *rgb, char *err, size_t n)
{
    if (!rec->started && rec->failed) {   /* the encoder never started: say why again */
        snprintf(err, n, "%s", rec->msg);
        return false;
    }
    if (!rec->started && !start(rec, err, n)) {
        rec->failed = true;
        snprintf(rec->msg, sizeof rec->msg, "%s", err);
        return false;
    }
    pthread_mutex_lock(&rec->mu);
    wait_queue(rec, NSLOT);
    bool ok = !rec->failed;
    if (ok) {
        memcpy(rec->slot[(rec->head + rec->queued) % NSLOT], rgb, rec->bytes);
        rec->queued++;
        rec->frames++;
        pthread_cond_broadcast(&rec->cv);
    } else {
        snprintf(err, n, "recording %s failed: %s", rec->path, rec->msg);
    }
    pthread_mutex_unlock(&rec->mu);
    return ok;
}

/* the last lines ffmpeg wrote on stderr, on one line */
static void encoder_says(wb_recorder *rec, char *out, size_t n)
{
    char buf[4096];
    out[0] = 0;
    off_t end = lseek(rec->errfd, 0, SEEK_END);
    if (end <= 0) return;
    off_t from = end > (off_t)sizeof buf - 1 ? end - (off_t)sizeof buf + 1 : 0;
    ssize_t k = pread(rec->errfd, buf, sizeof buf - 1, from);
    if (k <= 0) return;
    buf[k] = 0;
    while (k > 0 && (buf[k - 1] == '\n' || buf[k - 1] == '\r' || buf[k - 1] == ' ')) buf[--k] = 0;
    char *s = buf;
    for (int lines = 0; k > 0 && lines < 3; k--)   /* the last three lines */
        if (buf[k - 1] == '\n' && ++lines == 3) s = buf + k;
    for (char *c = s; *c; c++)
        if (*c == '\n' || *c == '\r') *c = ' ';
    size_t len = strlen(s);
    if (len >= n) s += len - (n - 1);   /* the end says most */
    memcpy(out, s, strlen(s) + 1);
}

bool wb_recorder_close(wb_recorder *rec, char *err, size_t n)
{
    if (!rec) return true;
    bool ok = true;
    if (rec->thread_on) {
        pthread_mutex_lock(&rec->mu);
        wait_queue(rec, 1);   /* drain (with the encoder's timeout) */
        rec->stop = true;
        pthread_cond_broadcast(&rec->cv);
        pthread_mutex_unlock(&rec->mu);
        pthread_join(rec->th, NULL);
    }
    if (rec->fd >= 0) close(rec->fd);   /* end of input: ffmpeg finishes the file */
    if (rec->pid > 0) {
        int status = 0;
        double t0 = now();
        pid_t k;
        while ((k = waitpid(rec->pid, &status, WNOHANG)) == 0) {
            if (now() - t0 > 5 * rec->timeout) {
                kill(-rec->pid, SIGKILL);
                fail(rec, "the encoder did not finish the file and was stopped%s%s", "", "");
            }
            struct timespec ts = { 0, 5000000 };
            nanosleep(&ts, NULL);
        }
        char says[512];
        encoder_says(rec, says, sizeof says);
        bool exited_ok = k == rec->pid && WIFEXITED(status) && WEXITSTATUS(status) == 0;
        if (!exited_ok || rec->failed) {
            char how[64];
            if (k == rec->pid && WIFEXITED(status)) snprintf(how, sizeof how, "exited with status %d", WEXITSTATUS(status));
            else if (k == rec->pid && WIFSIGNALED(status)) snprintf(how, sizeof how, "was killed by signal %d", WTERMSIG(status));
            else snprintf(how, sizeof how, "was lost");
            /* what ffmpeg said explains a broken pipe better than EPIPE does */
            char m[sizeof rec->msg];
            snprintf(m, sizeof m, "%s", rec->msg);
            snprintf(err, n, "recording %s failed: %s %s%s%s%s%s", rec->path, ffmpeg_prog(), exited_ok ? "finished" : how,
                     *says ? ": " : "", says, rec->failed && *m ? "; " : "", rec->failed ? m : "");
            ok = false;
        }
    } else if (rec->failed) {
        if (rec->started) snprintf(err, n, "recording %s failed: %s", rec->path, rec->msg);
        else snprintf(err, n, "%s", rec->msg);   /* the start's message says it all */
        ok = false;
    }
    if (rec->errfd >= 0) close(rec->errfd);
    for (int k = 0; k < NSLOT; k++) free(rec->slot[k]);
    free(rec->yuv);
    pthread_mutex_destroy(&rec->mu);
    pthread_cond_destroy(&rec->cv);
    free(rec);
    return ok;
}
