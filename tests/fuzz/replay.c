/* replay.c: a main for the fuzz targets without libFuzzer: runs each file named on the
 * command line once through LLVMFuzzerTestOneInput. Built with gcc by `make build`, so
 * `make test` (and `make asan`) replays the seed corpus and every input that once crashed
 * (tests/fuzz/regress) on machines without clang. Exit 0 when all ran; a broken
 * invariant aborts, a memory error crashes (or ASan reports it). */
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

int main(int argc, char **argv)
{
    for (int i = 1; i < argc; i++) {
        FILE *f = fopen(argv[i], "rb");
        if (!f) { perror(argv[i]); return 2; }
        size_t cap = 4096, n = 0, got;
        uint8_t *buf = malloc(cap);
        while (buf && (got = fread(buf + n, 1, cap - n, f)) > 0) {
            n += got;
            if (n == cap) {
                uint8_t *b = realloc(buf, cap *= 2);
                if (!b) free(buf);
                buf = b;
            }
        }
        fclose(f);
        if (!buf) { fprintf(stderr, "%s: out of memory\n", argv[i]); return 2; }
        LLVMFuzzerTestOneInput(buf, n);
        free(buf);
    }
    return 0;
}
