#!/bin/sh
# tests/cli/kill.sh BUILD_DIR: a run stopped while it writes never destroys a good file.
# Each writer (fixtures/kill_writer.lua) writes its file over and over, or records, and
# is killed (SIGKILL, SIGTERM) at several moments: the file's name then holds the old
# file, byte for byte, or a complete new one (the same bytes as an uninterrupted write);
# a recording's .pvd names only complete frames; after SIGTERM, a time limit or the
# watchdog's end, no temporary file is left beside it.
# Last line: "N passed, N failed"; exit status 1 when a check failed.
BUILD=${1:-build}
cd "$(dirname "$0")/../.." || exit 2
case $BUILD in /*) W=$BUILD/wobble ;; *) W=$PWD/$BUILD/wobble ;; esac
F=$PWD/tests/cli/fixtures
TMP=$(mktemp -d "${TMPDIR:-/tmp}/wobble-kill.XXXXXX") || exit 2
pid=""
trap '[ -n "$pid" ] && kill -9 "$pid" 2>/dev/null; rm -rf "$TMP"' EXIT
trap 'exit 130' INT TERM
. tests/cli/lib.sh

# start OUT ARGS...: kill_writer.lua in the background (its pid in $pid), output folder
# OUT; returns once it says "writing" (the world is built, the writes begin)
start() {
    out=$1
    shift
    # a background job of a script starts with SIGINT ignored (and wobble leaves an
    # ignored signal alone, as under nohup): give it back its default for the INT case
    env --default-signal=INT "$W" run "$F/kill_writer.lua" --quiet --out "$out" "$@" >"$TMP/out" 2>"$TMP/err" &
    pid=$!
    for _ in $(seq 600); do
        grep -q writing "$TMP/out" 2>/dev/null && return 0
        kill -0 "$pid" 2>/dev/null || return 1
        sleep 0.1
    done
    return 1
}

# stop SIG SECONDS: signal the writer that many seconds after it began, and reap it
stop() {
    sleep "$2"
    kill -s "$1" "$pid" 2>/dev/null
    wait "$pid" 2>/dev/null
    code=$?
    pid=""
}

# temps DIR: the temporaries left in DIR (.NAME.PID-N.tmp; main's w:save used NAME.tmpPID), one line each
temps() { find "$1" -name '*.tmp*' 2>/dev/null; }
# no_temps DIR MUST: the temporaries left in DIR are removed; with MUST = 1 (a stop that
# can clean up: SIGTERM, SIGINT, a limit) any counts against the case (in why)
no_temps() {
    left=$(temps "$1")
    [ "$2" = 1 ] && [ -n "$left" ] && why="${why:+$why; }left behind: $left"
    [ -n "$left" ] && rm -f $left
    return 0
}

# one_shot HOW N NAME FILE...: FILE(s) in the output folder, written by HOW; N the size
one_shot() {
    how=$1 size=$2 name=$3
    shift 3
    D=$TMP/$how
    rm -rf "$D" "$TMP/ref" "$TMP/old"
    mkdir -p "$TMP/old" "$TMP/ref"
    # the old file (small) and the new one as an uninterrupted write makes it
    "$W" run "$F/kill_writer.lua" --quiet --out "$D" --set how=$how --set name=$name --set n=4 >/dev/null 2>&1
    "$W" run "$F/kill_writer.lua" --quiet --out "$TMP/ref" --set how=$how --set name=$name --set n=$size \
        >/dev/null 2>&1
    for f in "$@"; do cp "$D/$f" "$TMP/old/$f" 2>/dev/null; done
    for sig in KILL TERM; do
        for t in 0.05 0.3 0.7; do
            for f in "$@"; do cp "$TMP/old/$f" "$D/$f" 2>/dev/null; done
            why=""
            if start "$D" --set how=$how --set name=$name --set n=$size --set loops=100000; then
                stop $sig $t
            else
                why="the writer did not start: $(head -c 300 "$TMP/err")"
            fi
            for f in "$@"; do
                [ -s "$TMP/old/$f" ] && [ -s "$TMP/ref/$f" ] || why="${why:+$why; }no old or reference $f"
                cmp -s "$D/$f" "$TMP/old/$f" || cmp -s "$D/$f" "$TMP/ref/$f" ||
                    why="${why:+$why; }$f is neither the old file nor a complete new one ($(wc -c <"$D/$f" 2>/dev/null) bytes)"
            done
            no_temps "$D" $([ $sig = TERM ] && echo 1)
            result "$how ($*) killed by SIG$sig ${t} s into its writes: old or complete" "$why"
        done
    done
}

one_shot save 250 f.json f.json
one_shot save_vtp 300 f.vtp f.vtp
one_shot save_obj 300 m.obj m.obj
one_shot save_tets 24 t t.node t.ele

# ---- PC2: the cache takes its name when the recorder closes; killed before, the old one
D=$TMP/pc2
"$W" run "$F/kill_writer.lua" --quiet --out "$D" --set how=pc2 --set name=c.pc2 --set n=8 --set loops=3 >/dev/null 2>&1
cp "$D/c.pc2" "$TMP/old.pc2"
for sig in KILL TERM; do
    for t in 0.1 0.5; do
        why=""
        start "$D" --set how=pc2 --set name=c.pc2 --set n=100 --set loops=1000000 || why="did not start"
        stop $sig $t
        cmp -s "$D/c.pc2" "$TMP/old.pc2" || why="${why:+$why; }c.pc2 is not the old cache ($(wc -c <"$D/c.pc2") bytes)"
        no_temps "$D" $([ $sig = TERM ] && echo 1)
        result "record_pc2 killed by SIG$sig ${t} s into the recording: the old cache intact" "$why"
    done
done
# pc2_ok FILE: the header's point and sample counts match the file's size
pc2_ok() {
    pts=$(od -An -t u4 -j 16 -N 4 "$1" | tr -d ' ')
    smp=$(od -An -t u4 -j 28 -N 4 "$1" | tr -d ' ')
    [ -n "$smp" ] && [ "$smp" -gt 3 ] && [ "$(wc -c <"$1")" -eq $((32 + smp * pts * 12)) ]
}
"$W" run "$F/kill_writer.lua" --quiet --out "$D" --set how=pc2 --set name=c.pc2 --set n=100 --set loops=100000000 \
    --time-limit 1 >"$TMP/out" 2>"$TMP/err"
code=$?
why=""
[ $code = 3 ] || why="exit $code, expected 3"
pc2_ok "$D/c.pc2" || why="${why:+$why; }c.pc2 is not a complete cache of more than 3 samples"
no_temps "$D" 1
result "record_pc2 stopped by --time-limit: the cache of the frames so far, whole, and no temporary" "$why"
cp "$TMP/old.pc2" "$D/c.pc2"
t0=$(date +%s)
timeout 60 "$W" run "$F/kill_writer.lua" --quiet --out "$D" --set how=stuck --set name=c.pc2 --set n=8 \
    --time-limit 1 >"$TMP/out" 2>"$TMP/err"
code=$?
why=""
[ $code = 3 ] && grep -q "grace period" "$TMP/err" || why="exit $code, expected 3 from the watchdog"
cmp -s "$D/c.pc2" "$TMP/old.pc2" || why="${why:+$why; }c.pc2 is not the old cache"
no_temps "$D" 1
result "a run the watchdog ends while it records ($(($(date +%s) - t0)) s): the old cache, no temporary" "$why"

# ---- VTK: after every frame the .pvd is whole and names complete frames only
D=$TMP/vtk
for sig in KILL TERM; do
    for t in 0.2 0.6 1.2; do
        rm -rf "$D"
        why=""
        start "$D" --set how=vtk --set name=v --set n=120 --set loops=1000000 || why="did not start"
        stop $sig $t
        tail -n 1 "$D/v.pvd" 2>/dev/null | grep -qx '</VTKFile>' || why="${why:+$why; }v.pvd does not end with </VTKFile>"
        k=0
        for f in $(sed -n 's/.*file="\([^"]*\)".*/\1/p' "$D/v.pvd" 2>/dev/null); do
            k=$((k + 1))
            tail -n 1 "$D/$f" 2>/dev/null | grep -qx '</VTKFile>' || why="${why:+$why; }$f is not complete"
        done
        [ $k -ge 1 ] || why="${why:+$why; }v.pvd names no frame"
        no_temps "$D" $([ $sig = TERM ] && echo 1)
        result "record_vtk killed by SIG$sig ${t} s in: v.pvd whole, its $k frames complete" "$why"
    done
done

# ---- PNG frames: each frame whole (a PNG ends with its IEND chunk)
D=$TMP/frames
for sig in KILL TERM; do
    rm -rf "$D"
    why=""
    start "$D" --set how=frames --set name=f/ --set n=40 --set loops=1000000 || why="did not start"
    stop $sig 1
    k=0
    for f in "$D"/f/frame_*.png; do
        [ -e "$f" ] || continue
        k=$((k + 1))
        tail -c 8 "$f" | head -c 4 | grep -q IEND || why="${why:+$why; }$f is not complete"
    done
    [ $k -ge 1 ] || why="${why:+$why; }no frame written"
    no_temps "$D" $([ $sig = TERM ] && echo 1)
    result "r:record(folder) killed by SIG$sig: its $k frames complete" "$why"
done

# ---- --record over an existing video: the old video until the new one is finished
if command -v ffmpeg >/dev/null 2>&1; then
    D=$TMP/video
    mkdir -p "$D"
    "$W" run "$F/kill_writer.lua" --quiet --out "$D" --set how=steps --set n=8 --set loops=3 --record "$D/v.mp4" \
        >/dev/null 2>&1
    cp "$D/v.mp4" "$TMP/old.mp4"
    for sig in KILL TERM INT; do
        why=""
        [ -s "$TMP/old.mp4" ] || why="no old video"
        start "$D" --set how=steps --set n=8 --set loops=1000000 --record "$D/v.mp4" || why="did not start"
        stop $sig 1.5
        cmp -s "$D/v.mp4" "$TMP/old.mp4" || why="${why:+$why; }v.mp4 is not the old video ($(wc -c <"$D/v.mp4") bytes)"
        no_temps "$D" $([ $sig != KILL ] && echo 1)
        result "--record v.mp4 over a video, killed by SIG$sig: the old video intact" "$why"
    done
    "$W" run "$F/kill_writer.lua" --quiet --out "$D" --set how=steps --set n=8 --set loops=10 --record "$D/v.mp4" \
        >/dev/null 2>&1
    code=$?
    why=""
    [ $code = 0 ] || why="exit $code"
    cmp -s "$D/v.mp4" "$TMP/old.mp4" && why="${why:+$why; }still the old video"
    [ -n "$(temps "$D")" ] && why="${why:+$why; }a temporary left"
    result "--record v.mp4 run to its end replaces the old video" "$why"
fi

echo "$passed passed, $failed failed"
[ "$failed" -eq 0 ]
