#!/bin/sh
# tests/cli/memory.sh BUILD_DIR: --memory-limit holds for what lives outside the Lua
# heap: meshes, skins, renderers, a plot's samples, a PNG decoded, the assimp child
# (fixtures in tests/cli/fixtures/memory). Each run must end with exit 3 and a message
# naming the script, with its peak RSS (process and children, GNU time's %M) within 1.5
# times the limit, and leave no process behind. The limit is 200 MB: the command alone
# (Mesa, LLVM, assimp) is ~60 MB of RSS that no budget counts.
# Under a sanitizer build (make asan) the RSS and address-space checks are left out: its
# shadow memory and quarantine are not the program's.
# Last line: "N passed, N failed"; exit status 1 when a check failed.
BUILD=${1:-build}
cd "$(dirname "$0")/../.." || exit 2
W="$BUILD/wobble"
F=tests/cli/fixtures/memory
LIMIT=200
TMP=$(mktemp -d "${TMPDIR:-/tmp}/wobble-memory.XXXXXX") || exit 2
trap 'rm -rf "$TMP"' EXIT INT TERM
mkdir -p "$TMP/out"
. tests/cli/lib.sh
OUT_FILE=$TMP/stdout ERR_FILE=$TMP/stderr   # what result shows of a failed run
SAN=0
if ldd "$W" 2>/dev/null | grep -q 'libasan\|libubsan'; then SAN=1; fi

# peak RSS in kB of a command and all it waits for: GNU time, else Python's rusage
if [ -x /usr/bin/time ]; then
    peak_of() { /usr/bin/time -f %M -o "$TMP/peak" "$@"; }
elif command -v python3 >/dev/null; then
    peak_of() {
        python3 -c 'import resource, subprocess, sys
rc = subprocess.call(sys.argv[2:])
open(sys.argv[1], "w").write("%d\n" % resource.getrusage(resource.RUSAGE_CHILDREN).ru_maxrss)
sys.exit(rc)' "$TMP/peak" "$@"
    }
else
    peak_of() { echo 0 >"$TMP/peak"; "$@"; }
fi

# run FIXTURE ARGS...: wobble run under the limit; $code, $peak (kB), $secs, its output
# in $TMP/stdout and $TMP/stderr
run() {
    fixture=$1
    shift
    t0=$(date +%s)
    peak_of "$W" run "$F/$fixture" --memory-limit $LIMIT --time-limit 60 --quiet --out "$TMP/out" \
        --set dir="$TMP/out" "$@" >"$TMP/stdout" 2>"$TMP/stderr"
    code=$?
    secs=$(($(date +%s) - t0))
    peak=$(tail -n 1 "$TMP/peak" 2>/dev/null)
    case $peak in '' | *[!0-9]*) peak=0 ;; esac
    [ $SAN = 0 ] || peak=0
}

# check NAME [STREAM TEXT]...: as tests/cli/run.sh's, for a budget run: exit code 3 within
# 20 s, peak RSS at most 1.5 x the limit, no wobble process left under $TMP; STREAM is
# out or err, !out / !err must not contain TEXT
check() {
    name=$1
    shift
    why=""
    [ "$code" = 3 ] || why="exit code $code, expected 3"
    [ "$secs" -le 20 ] || why="${why:+$why; }took $secs s"
    [ "$peak" -le $((LIMIT * 1024 * 3 / 2)) ] || why="${why:+$why; }peak RSS $((peak / 1024)) MB, over 1.5 x $LIMIT MB"
    sleep 0.2
    if pgrep -f -- "$TMP" >/dev/null; then why="${why:+$why; }a process left behind: $(pgrep -af -- "$TMP")"; fi
    while [ $# -ge 2 ]; do
        case $1 in
        !out | !err) if grep -qF -- "$2" "$TMP/std${1#!}"; then why="${why:+$why; }${1#!} has '$2'"; fi ;;
        *) if ! grep -qF -- "$2" "$TMP/std$1"; then why="${why:+$why; }$1 lacks '$2'"; fi ;;
        esac
        shift 2
    done
    result "$name ($((peak / 1024)) MB peak, $secs s)" "$why"
}


# ---- the assimp child: a billion vertices promised in 200 bytes. The shell's own limit
# is a safety net for this machine should the child's limit ever be lost (it is far above
# what the child is given)
if [ $SAN = 0 ]; then
    (
        ulimit -v 8388608 2>/dev/null
        run ply_bomb.lua
        echo "$code $peak $secs" >"$TMP/ply"
    )
    read -r code peak secs <"$TMP/ply"
    check "a PLY header claiming a billion vertices: a budget error from the import's child" \
        err "ply_bomb.lua:10: load_mesh:" err "the importer ran out of memory" \
        err "memory limit of $LIMIT MB exceeded" !out "load_mesh returned"
else
    # not run, so not counted: ASan reserves terabytes of address space, so RLIMIT_AS
    # cannot be set in a sanitizer build
    echo "# not run under a sanitizer build (no RLIMIT_AS): a PLY header claiming a billion vertices"
fi

# ---- the child stops with --time-limit (assimp loops on this one) and dies with its parent
WOBBLE_IMPORT_TIMEOUT=15 run import_hang.lua --time-limit 2
check "an import that hangs is stopped by --time-limit" err "import_hang.lua:7: time limit of 2 s exceeded" \
    !out "load_mesh returned"
WOBBLE_IMPORT_TIMEOUT=30 "$W" run "$F/import_hang.lua" --quiet --out "$TMP/out" --set dir="$TMP/out" >/dev/null 2>&1 &
parent=$!
child=""
for i in $(seq 50); do
    child=$(pgrep -P $parent)
    [ -n "$child" ] && break
    sleep 0.1
done
kill -9 $parent 2>/dev/null
wait $parent 2>/dev/null
for i in $(seq 30); do
    [ -n "$child" ] && kill -0 "$child" 2>/dev/null || break
    sleep 0.1
done
why=""
[ -n "$child" ] || why="the import's child never showed"
if [ -n "$child" ] && kill -0 "$child" 2>/dev/null; then
    why="the import's child $child outlived its parent by 3 s"
    kill -9 "$child"
fi
: >"$TMP/stdout"
: >"$TMP/stderr"
result "the import's child dies with its parent (kill -9)" "$why"

# ---- a PNG of 30 kB that decodes to 16000 x 16000
png="$TMP/out/bomb.png"
python3 - "$png" <<'EOF' 2>/dev/null || ffmpeg -v error -f lavfi -i color=black:s=16000x16000 -frames:v 1 -pix_fmt monob -y "$png"
import struct, sys, zlib
w = h = 16000
def chunk(t, d): return struct.pack(">I", len(d)) + t + d + struct.pack(">I", zlib.crc32(t + d) & 0xffffffff)
z = zlib.compressobj(9)
row = b"\0" * (1 + (w + 7) // 8)   # filter 0, a row of 1-bit grey
idat = b"".join(z.compress(row) for _ in range(h)) + z.flush()
ihdr = struct.pack(">IIBBBBB", w, h, 1, 0, 0, 0, 0)
open(sys.argv[1], "wb").write(b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", ihdr) + chunk(b"IDAT", idat) + chunk(b"IEND", b""))
EOF
run png_bomb.lua --set png="$png"
check "read_png of a 16000x16000 PNG: refused from its header" \
    err "png_bomb.lua:3: read_png: a 16000x16000 image needs about" err "over the memory budget of $LIMIT MB" \
    !out "read_png returned"

# ---- meshes, skins and renderers are charged, and given back when collected
run mesh_copies.lua
check "mesh copies are charged; dropped ones are given back" err "mesh_copies.lua:8: m:copy() needs about 7 MB" \
    out "dropped 200 copies" !out "should not get here"
run skins.lua
check "skins are charged; closed ones are given back" err "skins.lua:9: skin needs about" out "closed 10 skins" \
    !out "should not get here"
run renderers.lua
check "renderers are charged what llvmpipe takes; dropped ones are given back" \
    err "renderers.lua:10: a 320x240 renderer needs about 14 MB" out "dropped 5 renderers" !out "should not get here"

run draw_world.lua
check "drawing a world of 0.8 million links is charged before the frame" \
    err "draw_world.lua:6: drawing this world needs about" !out "should not get here"

# ---- renderers made and closed over and over give their memory back (to the system:
# RSS, not only the budget's account)
LIMIT=100
run renderer_churn.lua
LIMIT=200
why=""
[ "$code" = 0 ] || why="exit code $code, expected 0"
[ "$peak" -le $((100 * 1024 * 3 / 2)) ] || why="${why:+$why; }peak RSS $((peak / 1024)) MB, over 1.5 x 100 MB"
grep -q "made and closed 25 renderers" "$TMP/stdout" || why="${why:+$why; }stdout lacks 'made and closed 25 renderers'"
result "25 renderers made and closed under --memory-limit 100 ($((peak / 1024)) MB peak)" "$why"

# ---- one refusal by the budget, not retried by Lua (lauxlib's buffers): still exit 3
run string_rep.lua
check "string.rep of 1 GB: a budget error, not 'not enough memory'" \
    err "string_rep.lua: memory limit of $LIMIT MB exceeded" !err "not enough memory"

# ---- a plot over a million frames keeps a bounded number of samples (it was 48 bytes a
# frame): its peak RSS is that of a thousand frames, give or take 16 MB
run long_plot.lua --set frames=1000
short=$peak
run long_plot.lua --set frames=1000000
why=""
[ "$code" = 0 ] || why="exit code $code, expected 0"
[ -s "$TMP/out/long.png" ] || why="${why:+$why; }no plot written"
[ "$peak" -le $((short + 16384)) ] || why="${why:+$why; }peak RSS $((peak / 1024)) MB, $(((peak - short) / 1024)) MB over 1000 frames'"
result "w:run{plot} over 1,000,000 frames: $(((peak - short) / 1024)) MB more than over 1000" "$why"

echo "$passed passed, $failed failed"
[ "$failed" -eq 0 ]
