#!/bin/sh
# tests/fuzz/replay.sh BUILD_DIR: every input of the fuzz corpus (tests/fuzz/corpus/T) and
# every input that once crashed a fuzz target (tests/fuzz/regress/T) run once through the
# same target built with gcc (BUILD_DIR/fuzz_T_replay, from tests/fuzz/replay.c): a crash,
# a sanitizer report or a broken invariant fails that file. No clang needed.
BUILD=${1:-build}
cd "$(dirname "$0")/../.." || exit 2
pass=0 fail=0
# under `make asan`: assimp's own leaks are not ours (the targets use no renderer, so its
# suppressions are not needed here)
LSAN_OPTIONS="${LSAN_OPTIONS:+$LSAN_OPTIONS:}suppressions=$PWD/tests/fuzz/lsan.supp"
export LSAN_OPTIONS
LOG=$(mktemp "${TMPDIR:-/tmp}/wobble-replay.XXXXXX") || exit 2
trap 'rm -f "$LOG"' EXIT
for t in json mesh mesh_obj; do
    bin=$BUILD/fuzz_${t}_replay
    for f in tests/fuzz/corpus/$t/* tests/fuzz/regress/$t/*; do
        [ -f "$f" ] || continue
        if [ ! -x "$bin" ]; then
            fail=$((fail + 1)); echo "not ok $((pass + fail)) - $f ($bin not built)"; continue
        fi
        # full malloc stacks, so that the suppression sees assimp's frames
        asan=$ASAN_OPTIONS
        [ "$t" = mesh_obj ] && asan="${ASAN_OPTIONS:+$ASAN_OPTIONS:}fast_unwind_on_malloc=0"
        if ASAN_OPTIONS=$asan "$bin" "$f" >"$LOG" 2>&1; then
            pass=$((pass + 1)); echo "ok $((pass + fail)) - $f"
        else
            rc=$?
            fail=$((fail + 1)); echo "not ok $((pass + fail)) - $f (exit code $rc)"
            sed 's/^/  # /' "$LOG" | head -n 40
        fi
    done
done
echo "$pass passed, $fail failed"
[ "$fail" -eq 0 ]
