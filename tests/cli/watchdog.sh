#!/bin/sh
# tests/cli/watchdog.sh BUILD_DIR: --time-limit where the count hook never runs. Lua
# runs __gc finalizers without hooks, one C call (a backtracking string.find) never
# returns to Lua, ffprobe / ffmpeg never answer: each run must still end
# with exit 3 within 15 s (limit 2 s, grace 5 s), name the script, and leave no helper
# process behind. `timeout 60` makes a regression fail instead of hanging the suite.
# Last line: "N passed, N failed"; exit status 1 when a check failed.
BUILD=${1:-build}
cd "$(dirname "$0")/../.." || exit 2
W="$BUILD/wobble"
F=tests/cli/fixtures
TMP=$(mktemp -d "${TMPDIR:-/tmp}/wobble-watchdog.XXXXXX") || exit 2
trap 'rm -rf "$TMP"' EXIT INT TERM
. tests/cli/lib.sh
MAX_SECS=15   # the limit (2 s), the grace (5 s) and room to start

# run ARGS...: wobble under timeout; stdout in $TMP/out, stderr in $TMP/err, exit
# code in $code (124: timeout killed it), seconds taken in $secs
run() {
    t0=$(date +%s)
    timeout 60 "$W" "$@" >"$TMP/out" 2>"$TMP/err"
    code=$?
    secs=$(($(date +%s) - t0))
}

# left PATTERN: the live (not zombie) processes whose command line holds PATTERN,
# after giving a SIGKILL a few seconds to land
left() {
    for _ in 1 2 3 4 5 6 7 8 9 10; do
        live=""
        for pid in $(pgrep -f -- "$1"); do
            state=$(sed 's/.*) \(.\).*/\1/' "/proc/$pid/stat" 2>/dev/null)
            [ -n "$state" ] && [ "$state" != Z ] && live="$live $pid"
        done
        [ -z "$live" ] && return 0
        sleep 0.5
    done
    echo "$live"
    for pid in $live; do kill -9 "-$pid" 2>/dev/null; kill -9 "$pid" 2>/dev/null; done  # leave nothing behind
    return 1
}


LIMIT="time limit of 2 s exceeded"

# ---- finalizers: Lua runs them without hooks
run run $F/gc_loop_exit.lua --time-limit 2
check "a finalizer that never returns at exit: exit 3 (${secs} s)" 3 out "script done" \
    err "$F/gc_loop_exit.lua: $LIMIT" err "grace period of 5 s"
run run $F/gc_loop_collect.lua --time-limit 2
check "a finalizer that never returns in collectgarbage(): exit 3 (${secs} s)" 3 \
    err "$F/gc_loop_collect.lua: $LIMIT" !out "should not get here"
run run $F/gc_slow_exit.lua --time-limit 2
check "a finalizer at exit that ends past the limit: exit 3 (${secs} s)" 3 out "finalizer done" \
    err "$F/gc_slow_exit.lua: $LIMIT (--time-limit SECONDS) while the finalizers (__gc) ran at the end"
run run $F/gc_quick.lua --time-limit 600
check "a quick finalizer runs at exit and the run ends at once under a long limit (${secs} s)" 0 \
    out "script done" out "finalized" !err ""

# ---- one long C call: string patterns never return to Lua
run run $F/pattern_find.lua --time-limit 2
check "a backtracking string.find: exit 3 (${secs} s)" 3 err "$F/pattern_find.lua: $LIMIT" !out "should not get here"
run run $F/pattern_gsub.lua --time-limit 2
check "a backtracking string.gsub: exit 3 (${secs} s)" 3 err "$F/pattern_gsub.lua: $LIMIT" !out "should not get here"

# many slow C calls: at the deadline the hook is re-armed to check every instruction,
# so the script stops at its own line (not through the watchdog's end of the process)
run run $F/slow_calls.lua --time-limit 2
check "slow C calls between hook checks stop at the script's line (${secs} s)" 3 \
    err "$F/slow_calls.lua:5: $LIMIT" !err "grace period"

# a read of standard input that never ends: a FIFO held open (fd 3) and never written
mkfifo "$TMP/stdin.fifo"
exec 3<>"$TMP/stdin.fifo"
run run $F/stdin_read.lua --time-limit 2 <"$TMP/stdin.fifo"
exec 3>&-
check "io.read of a pipe that never ends: exit 3 (${secs} s)" 3 err "$F/stdin_read.lua: $LIMIT" \
    !out "should not get here"

# ---- helpers that wait forever. A FIFO is refused before any helper starts (only a
# regular file is media; opening it must not wait for a writer) ...
mkdir -p "$TMP/out-fifo" "$TMP/fakebin"
mkfifo "$TMP/out-fifo/live.fifo"
run run $F/probe_fifo.lua --out "$TMP/out-fifo" --set path=live.fifo --time-limit 2
check "wobble.probe of a FIFO: refused at once, not waited on (${secs} s)" 0 out "not a regular file"
run run $F/probe_fifo.lua --out "$TMP/out-fifo" --set path=live.fifo --set frame=true --time-limit 2
check "wobble.read_frame of a FIFO: refused at once, not waited on (${secs} s)" 0 out "not a regular file"
# ... and a helper that never answers (a stand-in for ffprobe / ffmpeg stuck on a
# stream) is waited on only until the budget: exit 3 at the script's line, helper killed
printf '\000\000\000\030ftypisom0000' >"$TMP/out-fifo/still.mp4"
printf '#!/bin/sh\nwhile :; do sleep 1; done\n' >"$TMP/fakebin/stuck-helper"
chmod +x "$TMP/fakebin/stuck-helper"
WOBBLE_FFPROBE="$TMP/fakebin/stuck-helper" run run $F/probe_fifo.lua --out "$TMP/out-fifo" --set path=still.mp4 \
    --time-limit 2
check "wobble.probe with a helper that never answers: exit 3 at the script's line (${secs} s)" 3 \
    err "$F/probe_fifo.lua:6: $LIMIT" !out "should not get here"
stray=$(left "$TMP/fakebin/stuck-helper")
code=$?
check "no ffprobe left behind${stray:+ (pids$stray)}" 0
# (read_frame asks ffprobe for the frame's size before ffmpeg decodes it: both stuck)
WOBBLE_FFPROBE="$TMP/fakebin/stuck-helper" WOBBLE_FFMPEG="$TMP/fakebin/stuck-helper" run run $F/probe_fifo.lua \
    --out "$TMP/out-fifo" --set path=still.mp4 --set frame=true --time-limit 2
check "wobble.read_frame with a helper that never answers: exit 3 at the script's line (${secs} s)" 3 \
    err "$F/probe_fifo.lua:6: $LIMIT" !out "should not get here"
stray=$(left "$TMP/fakebin/stuck-helper")
code=$?
check "no ffmpeg left behind${stray:+ (pids$stray)}" 0

# ---- the encoder of --record (a process group of its own) dies with the run
run run $F/record_hang.lua --record "$TMP/rec/v.mp4" --out "$TMP/out" --time-limit 3
check "stuck while recording: exit 3 (${secs} s)" 3 err "$F/record_hang.lua: time limit of 3 s exceeded" !out "should not get here"

# an encoder that takes no frame and never ends, even at the end of its input: only
# the kill of its process group ends it
printf '#!/bin/sh\nwhile :; do sleep 1; done\n' >"$TMP/fakebin/stuck-encoder"
chmod +x "$TMP/fakebin/stuck-encoder"
export WOBBLE_FFMPEG="$TMP/fakebin/stuck-encoder"
run run $F/record_hang.lua --record "$TMP/rec2/v.mp4" --out "$TMP/out" --time-limit 3
unset WOBBLE_FFMPEG
check "stuck while a stuck encoder records: exit 3 (${secs} s)" 3 err "$F/record_hang.lua: time limit of 3 s exceeded"
stray=$(left "$TMP/fakebin/stuck-encoder")
code=$?
check "the stuck encoder is killed with its process group${stray:+ (pids$stray)}" 0

# ---- wobble test: the TAP stream still ends with the plan and the summary
run test $F/tap_watchdog.lua --time-limit 2
last=$(tail -n 1 "$TMP/out")
check "test: a case stuck in a C call: exit 3, TAP complete (${secs} s)" 3 \
    out "ok 1 - $F/tap_watchdog.lua: passes" out "not ok 2 - $F/tap_watchdog.lua: a pattern that never ends" \
    out "1..2" !out "after the budget" err "$F/tap_watchdog.lua: $LIMIT"
[ "$last" = "1 passed, 1 failed" ]
code=$?
check "test: the last line is the summary ('$last')" 0
run test $F/tap_gc_close.lua --time-limit 2
last=$(tail -n 1 "$TMP/out")
check "test: a finalizer that never returns at the file's end: exit 3 (${secs} s)" 3 \
    out "ok 1 - $F/tap_gc_close.lua: passes" out "not ok 2 - $F/tap_gc_close.lua: closing the file (finalizers)" \
    out "1..2" err "$F/tap_gc_close.lua: $LIMIT"
[ "$last" = "1 passed, 1 failed" ]
code=$?
check "test: the last line is the summary ('$last')" 0

echo "$passed passed, $failed failed"
[ "$failed" -eq 0 ]
