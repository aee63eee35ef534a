#!/bin/sh
# tests/run_all.sh BUILD_DIR: the whole suite behind `make test` and `make asan`.
#   (a) BUILD_DIR/unit_tests                    C unit tests of the core
#   (b) wobble test tests/scenarios tests/validation   Lua scenario and validation tests
#       tests/validation_vbd.sh                 the validation tests again under solver = "vbd"
#   (c) every scripts/*.lua for 5 frames        one test per example scene (pass = exit 0)
#       the scenes that check their claim       run in full under wobble test
#       the output of (b) and of those scenes   no warning/assert/error line that no test announced
#       tests/scripts_vbd.sh                    those scenes again under solver = "vbd"
#   (d) tests/cli/run.sh                        the command line in separate processes
#       tests/cli/sandbox.sh                    escapes from the file rules, in separate processes
#       tests/cli/extreme.sh                    extreme input (overflowing builders, rest lengths, KNN ties)
#       tests/cli/memory.sh                     --memory-limit outside the Lua heap: meshes, renderers, PNGs, assimp
#       tests/cli/budget.sh                     --memory-limit with no time limit: the process tree's peak RSS
#       tests/cli/kill.sh                       writers killed mid-write: the old file or a complete new one
#   (e) tests/render/run.sh                     wobble run --record, encoders that fail
#   (f) tests/layers.sh                         the layers (docs/architecture.md): no upward call, no circle
#   (g) tests/cli/firstrun.sh                   what a new user meets: make deps, bench --frames, print
#   (h) tests/cli/watchdog.sh                   --time-limit in finalizers, C calls, helper programs
#   (i) tests/fuzz/replay.sh                    the fuzz corpus and past crashes, once each
#   (j) tests/cli/sweep.sh                      wobble sweep run by GNU parallel, result.json, collect
#   (k) tests/cli/bench.sh                      wobble bench --json on a tiny configuration
#   (l) tests/docs.sh                           the manual: README length, every src/ file in
#                                               docs/architecture.md, relative links lead somewhere
# Each part prints its output and ends with "N passed, N failed"; a part that crashes
# or prints no such line counts as a failure, never as zero tests. The last line is
# the sum, "N passed, N failed"; the exit status is 1 when anything failed.
BUILD=${1:-build}
cd "$(dirname "$0")/.." || exit 2
TMP=$(mktemp -d "${TMPDIR:-/tmp}/wobble-tests.XXXXXX") || exit 2
trap 'rm -rf "$TMP"' EXIT
trap 'exit 130' INT TERM
total_pass=0 total_fail=0

# part NAME COMMAND...: run COMMAND (output shown as it comes), add its summary line
part() {
    part_name=$1
    shift
    echo "== $part_name"
    { "$@"; echo $? >"$TMP/rc"; } 2>&1 | tee "$TMP/log"
    part_rc=$(cat "$TMP/rc" 2>/dev/null || echo 127)
    part_last=$(tail -n 1 "$TMP/log")
    part_p=$(echo "$part_last" | sed -n 's/^\([0-9][0-9]*\) passed, \([0-9][0-9]*\) failed$/\1/p')
    part_f=$(echo "$part_last" | sed -n 's/^\([0-9][0-9]*\) passed, \([0-9][0-9]*\) failed$/\2/p')
    if [ -z "$part_p" ]; then
        echo "!! $part_name: no \"N passed, N failed\" line at the end (exit code $part_rc): one failure"
        total_fail=$((total_fail + 1))
        return
    fi
    total_pass=$((total_pass + part_p))
    total_fail=$((total_fail + part_f))
    if [ "$part_rc" -ne 0 ] && [ "$part_f" -eq 0 ]; then
        echo "!! $part_name: exit code $part_rc although no test failed: one failure"
        total_fail=$((total_fail + 1))
    fi
}

# the example scenes, a few frames each; the time limit keeps a hung scene from
# hanging the suite
examples() {
    ex_n=0 ex_p=0 ex_f=0
    for ex in scripts/*.lua; do
        [ -e "$ex" ] || continue
        ex_n=$((ex_n + 1))
        if "$BUILD/wobble" run "$ex" --frames 5 --quiet --time-limit 600 --out "$TMP/out-examples" \
            >"$TMP/example.log" 2>&1; then
            ex_p=$((ex_p + 1))
            echo "ok $ex_n - $ex"
        else
            ex_rc=$?
            ex_f=$((ex_f + 1))
            echo "not ok $ex_n - $ex (exit code $ex_rc)"
            sed 's/^/  # /' "$TMP/example.log"
        fi
    done
    echo "$ex_p passed, $ex_f failed"
}

# the example scenes that check what their header says (`if test then ... end` at their
# end: the cloth rests on the sphere, the rope winds round its post, ...), in full
checked_examples() {
    # shellcheck disable=SC2046  # one file name per line, none with spaces
    set -- $(grep -l '^if test then' scripts/*.lua 2>/dev/null)
    if [ $# -eq 0 ]; then
        echo "not ok 1 - no example scene checks its claim (if test then ... end)"
        echo "0 passed, 1 failed"
        return 1
    fi
    "$BUILD/wobble" test --quiet --time-limit 600 --out "$TMP/out-checked" "$@"
}

# expected_noise LOG: a line of LOG that looks like trouble (a warning, an assertion, an
# error, an abort) must come from a test that announced it ("# expected on stderr: ..."
# before its ok line); anything else alarming in a passing run is a finding
expected_noise() {
    awk '
      /^# expected on stderr/ { allowed = 1; next }
      /^(not )?ok [0-9]/ { allowed = 0; next }
      /^#/ || /^  / { next }
      !allowed && tolower($0) ~ /warning|assert|abort|error|fatal|core dumped|segmentation fault|sanitizer/ { print }
    ' "$1" >"$TMP/noise"
    if [ -s "$TMP/noise" ]; then
        echo "not ok 1 - alarming lines no test announced as expected (print(\"expected on stderr: ...\") first):"
        sed 's/^/  # /' "$TMP/noise"
        echo "0 passed, 1 failed"
        return 1
    fi
    echo "ok 1 - every warning, assertion or error line was announced as expected"
    echo "1 passed, 0 failed"
}

if [ -e "$BUILD/unit_tests" ]; then
    part "C unit tests ($BUILD/unit_tests)" "$BUILD/unit_tests"
else
    echo "== C unit tests: $BUILD/unit_tests not built, skipped"
fi

lua_dirs=""
for d in tests/scenarios tests/validation; do
    [ -d "$d" ] && lua_dirs="$lua_dirs $d"
done
# shellcheck disable=SC2086  # the folder list is meant to split
part "scenario and validation tests" "$BUILD/wobble" test --out "$TMP/out-tests" $lua_dirs
cp "$TMP/log" "$TMP/scenarios.log"
part "expected stderr of the scenario tests is labelled" expected_noise "$TMP/scenarios.log"
part "validation tests under VBD (tests/validation_vbd.sh)" sh tests/validation_vbd.sh "$BUILD"
part "example scenes (scripts/*.lua, 5 frames)" examples
part "example scenes that check their claim, in full" checked_examples
cp "$TMP/log" "$TMP/checked.log"
part "expected stderr of the checked example scenes is labelled" expected_noise "$TMP/checked.log"
part "example scenes that check their claim, under VBD (tests/scripts_vbd.sh)" sh tests/scripts_vbd.sh "$BUILD"
part "command line (tests/cli/run.sh)" sh tests/cli/run.sh "$BUILD"
part "sandbox escapes (tests/cli/sandbox.sh)" sh tests/cli/sandbox.sh "$BUILD"
part "extreme input from the command line (tests/cli/extreme.sh)" sh tests/cli/extreme.sh "$BUILD"
part "memory budgets (tests/cli/memory.sh)" sh tests/cli/memory.sh "$BUILD"
part "memory budgets without a time limit (tests/cli/budget.sh)" sh tests/cli/budget.sh "$BUILD"
part "writers killed mid-write (tests/cli/kill.sh)" sh tests/cli/kill.sh "$BUILD"
part "recording from the command line (tests/render/run.sh)" sh tests/render/run.sh "$BUILD"
part "layers (tests/layers.sh)" sh tests/layers.sh "$BUILD"
part "the manual (tests/docs.sh)" sh tests/docs.sh "$BUILD"
part "first run (tests/cli/firstrun.sh)" sh tests/cli/firstrun.sh "$BUILD"
part "--time-limit watchdog (tests/cli/watchdog.sh)" sh tests/cli/watchdog.sh "$BUILD"
part "fuzz corpus replay (tests/fuzz/replay.sh)" sh tests/fuzz/replay.sh "$BUILD"
part "tetgen under the budgets (tests/cli/tets.sh)" sh tests/cli/tets.sh "$BUILD"
part "--replay of input logs (tests/cli/replay.sh)" sh tests/cli/replay.sh "$BUILD"
part "sweeps through GNU parallel, result.json, collect (tests/cli/sweep.sh)" sh tests/cli/sweep.sh "$BUILD"
part "wobble bench --json and the Bullet peer's plumbing (tests/cli/bench.sh)" sh tests/cli/bench.sh "$BUILD"
part "the live viewer under Xvfb (tests/cli/view.sh)" sh tests/cli/view.sh "$BUILD"
part "hostile input to sweep, collect, --replay (tests/cli/attack_sweep.sh)" sh tests/cli/attack_sweep.sh "$BUILD"

echo "$total_pass passed, $total_fail failed"
[ "$total_fail" -eq 0 ]
