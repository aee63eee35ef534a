#!/bin/sh
# tests/fuzz/replay.sh BUILD_DIR: every input of the fuzz corpus (tests/fuzz/corpus/T) and
# every input that once crashed a fuzz target (tests/fuzz/regress/T) run once through the
# same target built with gcc (BUILD_DIR/fuzz_T_replay, from tests/fuzz/replay.c): a crash,
# a sanitizer report or a broken invariant fails that file. No clang needed.
BUILD=${1:-build}
cd "$(dirname "$0")/../.." || exit 2
pass=0 fail=0
LOG=$(mktemp "${TMPDIR:-/tmp}/wobble-replay.XXXXXX") || exit 2
trap 'rm -f "$LOG"' EXIT
for t in json mesh mesh_obj; do
    bin=$BUILD/fuzz_${t}_replay
    for f in tests/fuzz/corpus/$t/* tests/fuzz/regress/$t/*; do
        [ -f "$f" ] || continue
        if [ ! -x "$bin" ]; then
            fail=$((fail + 1)); echo "not ok $((pass + fail)) - $f ($bin not built)"; continue
        fi
        if "$bin" "$f" >"$LOG" 2>&1; then
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
