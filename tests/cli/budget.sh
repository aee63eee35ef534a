#!/bin/sh
# tests/cli/budget.sh BUILD_DIR: --memory-limit alone, with no time limit, holds where it
# had holes (fixtures in tests/cli/fixtures/budget): finalizers at the end, worlds and
# their threads, JSON configs, the meshes a config's skins name, read_frame, ffmpeg
# encoding r:record's frames, and refusals that pcall catches. Each run must end with
# exit 3 within 20 s, with the peak resident memory of its whole process tree (wobble
# and its helpers together, build/treepeak) at most 1.5 times the limit, and leave no
# process behind. treepeak kills a tree past 4 times the limit, so a hole costs this
# machine little. The command alone (Mesa, LLVM, assimp) is ~57 MB that no budget counts.
# Under a sanitizer build (make asan) the RSS checks are left out: its shadow memory and
# quarantine are not the program's.
# Last line: "N passed, N failed"; exit status 1 when a check failed.
BUILD=${1:-build}
cd "$(dirname "$0")/../.." || exit 2
W="$BUILD/wobble"
PEAK="$BUILD/treepeak"
F=tests/cli/fixtures/budget
TMP=$(mktemp -d "${TMPDIR:-/tmp}/wobble-budget.XXXXXX") || exit 2
trap 'rm -rf "$TMP"' EXIT INT TERM
mkdir -p "$TMP/out"
. tests/cli/lib.sh
SAN=0
if ldd "$W" 2>/dev/null | grep -q 'libasan\|libubsan'; then SAN=1; fi
LIMIT=200

# run FIXTURE ARGS...: wobble run under --memory-limit $LIMIT and no time limit, in
# treepeak; $code, $peak (kB), $left (processes left behind), $secs; its output in
# $TMP/out and $TMP/err
run() {
    fixture=$1
    shift
    cap=$((LIMIT * 4))
    [ $SAN = 0 ] || cap=0
    t0=$(date +%s)
    "$PEAK" -c $cap -t 60 -o "$TMP/peak" -- "$W" run "$F/$fixture" --memory-limit $LIMIT --quiet \
        --out "$TMP/out" --set dir="$TMP/out" "$@" >"$TMP/out/stdout" 2>"$TMP/out/stderr"
    code=$?
    secs=$(($(date +%s) - t0))
    mv "$TMP/out/stdout" "$TMP/out.txt"
    mv "$TMP/out/stderr" "$TMP/err.txt"
    read -r _ peak _ left _ capped _ timed <"$TMP/peak" || peak=0 left=0 capped=0 timed=0
    [ $SAN = 0 ] || peak=0
}

# bcheck NAME [STREAM TEXT]...: exit code 3 within 20 s, peak RSS of the tree at most
# 1.5 x the limit, nothing left running; STREAM is out or err, !out / !err must not
# contain TEXT
bcheck() {
    name=$1
    shift
    why=""
    [ "$code" = 3 ] || why="exit code $code, expected 3"
    [ "$capped" = 0 ] || why="${why:+$why; }killed at 4 x the limit"
    [ "$timed" = 0 ] || why="${why:+$why; }killed after 60 s"
    [ "$secs" -le 20 ] || why="${why:+$why; }took $secs s"
    [ "$peak" -le $((LIMIT * 1024 * 3 / 2)) ] || why="${why:+$why; }peak RSS $((peak / 1024)) MB, over 1.5 x $LIMIT MB"
    [ "$left" = 0 ] || why="${why:+$why; }$left processes left behind"
    while [ $# -ge 2 ]; do
        case $1 in
        !out | !err) if grep -qF -- "$2" "$TMP/${1#!}.txt"; then why="${why:+$why; }${1#!} has '$2'"; fi ;;
        *) if ! grep -qF -- "$2" "$TMP/$1.txt"; then why="${why:+$why; }$1 lacks '$2'"; fi ;;
        esac
        shift 2
    done
    OUT_FILE=$TMP/out.txt ERR_FILE=$TMP/err.txt result "$name ($((peak / 1024)) MB peak, $secs s)" "$why"
}

EXCEEDED="memory limit of $LIMIT MB exceeded"

# ---- finalizers run under the budget (Lua runs them without hooks)
run gc_alloc.lua
bcheck "a finalizer that allocates without end at exit" out "script done" \
    err "$F/gc_alloc.lua: $EXCEEDED (--memory-limit MB) while the finalizers (__gc) ran at the end"
run gc_pcall_loop.lua
bcheck "a finalizer at exit that swallows its refused allocations for ever: ended by the watchdog" \
    out "script done" err "$F/gc_pcall_loop.lua: $EXCEEDED" err "did not come back to a budget check"

# ---- a refusal caught by pcall spends the budget for good
run pcall_rep.lua
bcheck "pcall(string.rep, 'y', 3e8) a million times" err "pcall_rep.lua:4: $EXCEEDED" !out "should not get here"

# ---- worlds and their threads live outside the Lua heap
run worlds.lua
bcheck "10^7 empty worlds" err "worlds.lua:4: out of memory: creating a world" !out "should not get here"
LIMIT=100
run threads.lua
bcheck "worlds of 256 threads, stepped (--memory-limit 100)" err "threads.lua:5: out of memory: creating a world" \
    !out "should not get here"
LIMIT=200
run vbd_world.lua
bcheck "a VBD cloth whose solver's arrays do not fit: its step fails" out "built" \
    err "vbd_world.lua:8: out of memory stepping the world" !out "stepped"
run vbd_world.lua --set solver=gauss-seidel
why=""
[ "$code" = 0 ] && grep -qF stepped "$TMP/out.txt" || why="exit code $code, expected 0 and 'stepped'"
OUT_FILE=$TMP/out.txt ERR_FILE=$TMP/err.txt result "the same cloth under XPBD steps within the limit (the check has power)" "$why"

# ---- files read: a JSON config, the meshes its skins name, a video frame
run json_big.lua
bcheck "a particle config of 600,000 particles (14 MB) the script wrote" \
    err "json_big.lua:14: $TMP/out/big.json: reading it needs more than" err "of the memory budget of $LIMIT MB" \
    !out "load_particles returned"
if [ $SAN = 0 ]; then
    # the shell's own limit is a safety net should the child's be lost (memory.sh)
    (
        ulimit -v 8388608 2>/dev/null
        run skin_bomb.lua
        echo "$code $peak $left $capped $timed $secs" >"$TMP/skin"
    )
    read -r code peak left capped timed secs <"$TMP/skin"
    bcheck "a config's skin naming a PLY header of a billion vertices" \
        err "skins[0].mesh: bomb.ply: the importer ran out of memory" err "$EXCEEDED" !out "load_particles returned"
else
    echo "# not run under a sanitizer build (no RLIMIT_AS): a config's skin naming a PLY bomb"
fi
png="$TMP/out/frame.png"
ffmpeg -v error -f lavfi -i color=black:s=8000x8000 -frames:v 1 -pix_fmt monob -y "$png"
run frame_bomb.lua --set png="$png"
bcheck "read_frame of an 8000x8000 PNG of a few kB" \
    err "frame_bomb.lua:3: read_frame: a 8000x8000 frame needs about" err "over the memory budget of $LIMIT MB" \
    !out "read_frame returned"

# ---- the encoder of r:record
run record_big.lua
bcheck "r:record of 1024x1024 frames: ffmpeg counts" \
    err "record_big.lua:6: recording 1024x1024 frames (ffmpeg included) needs about" !out "should not get here"
[ ! -e "$TMP/out/big.mp4" ]
code=$?
result "r:record refused: no file made" "$([ $code = 0 ] || echo "big.mp4 exists")"

echo "$passed passed, $failed failed"
[ "$failed" -eq 0 ]
