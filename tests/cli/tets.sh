#!/bin/sh
# tests/cli/tets.sh BUILD_DIR: w:from_mesh(m, {tets = true}) runs the tetgen program as a
# child under the run's budgets (fixture tests/cli/fixtures/tets_big.lua: the rounded cube
# cut into tets of at most max_volume, 1e-7 m^3 by default, i.e. ~10 million tets: far
# more than the budgets below allow):
#   - without tetgen on $PATH: exit 2 and a message naming the Debian package;
#   - past --memory-limit: exit 3 (a budget), the message naming tetgen and the limit;
#   - past --time-limit: exit 3 (tetgen is stopped when the run's time is up);
#   - past its timeout: exit 2, "tetgen timed out";
#   - each leaves nothing in $TMPDIR (its private folder removed) and no tetgen running.
# Last line: "N passed, N failed"; exit status 1 when a check failed.
BUILD=${1:-build}
cd "$(dirname "$0")/../.." || exit 2
W="$(pwd)/$BUILD/wobble"
F=tests/cli/fixtures/tets_big.lua
TMP=$(mktemp -d "${TMPDIR:-/tmp}/wobble-tets.XXXXXX") || exit 2
trap 'rm -rf "$TMP"' EXIT INT TERM
mkdir -p "$TMP/tmp"
. tests/cli/lib.sh

run() {
    t0=$(date +%s)
    TMPDIR="$TMP/tmp" "$@" >"$TMP/out" 2>"$TMP/err"
    code=$?
    secs=$(($(date +%s) - t0))
}
left() { # what the run left behind: temporary folders, tetgen processes of ours (those
    # working in a folder under our $TMPDIR: other runs on the machine are not ours)
    ls -A "$TMP/tmp"
    for p in $(pgrep -f "tetgen.*in.poly" 2>/dev/null); do
        case "$(readlink "/proc/$p/cwd" 2>/dev/null)" in "$TMP"/tmp/*) echo "a tetgen process"; break ;; esac
    done
}

if ! command -v tetgen >/dev/null 2>&1; then
    echo "# tetgen is not installed (make deps): only the missing-program check runs"
fi

run env PATH=/nonexistent "$W" run "$F" --set maxv=0.01
check "without tetgen: exit 2, the package named" 2 err "the tetgen program is not installed (Debian package tetgen" \
    err "tets_big.lua:6:"
result "without tetgen: nothing left behind" "$(left)"

if command -v tetgen >/dev/null 2>&1; then
    MAX_SECS=60
    run "$W" run "$F" --memory-limit 150
    check "past --memory-limit: exit 3 naming tetgen and the limit" 3 err "tetgen ran out of memory" \
        err "memory limit of 150 MB"
    result "past --memory-limit: nothing left behind" "$(left)"
    run "$W" run "$F" --time-limit 2
    check "past --time-limit: exit 3, the time limit named" 3 err "time limit of 2 s exceeded"
    result "past --time-limit: nothing left behind" "$(left)"
    run "$W" run "$F" --set timeout=0.5
    check "past its timeout: exit 2" 2 err "tetgen timed out after 0.5 s"
    result "past its timeout: nothing left behind" "$(left)"
    run "$W" run "$F" --set maxv=0.01
    check "a feasible job: made" 0 out "made"
    result "a feasible job: nothing left behind" "$(left)"
fi
echo "$passed passed, $failed failed"
[ "$failed" -eq 0 ]
