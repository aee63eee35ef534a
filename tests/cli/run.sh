#!/bin/sh
# tests/cli/run.sh BUILD_DIR: the command line seen from outside, one process per
# check: exit codes (0 ok, 1 failed expectation, 2 script error, 3 budget), messages
# on stderr, TAP on stdout, the sandbox where it needs a real file system (symlinks).
# Fixture scenes live in tests/cli/fixtures (not searched by `wobble test`).
# Last line: "N passed, N failed"; exit status 1 when a check failed.
BUILD=${1:-build}
cd "$(dirname "$0")/../.." || exit 2
W="$BUILD/wobble"
F=tests/cli/fixtures
TMP=$(mktemp -d "${TMPDIR:-/tmp}/wobble-cli.XXXXXX") || exit 2
trap 'rm -rf "$TMP"' EXIT INT TERM
n=0 passed=0 failed=0

# run ARGS...: run wobble; stdout in $TMP/out, stderr in $TMP/err, exit code in $code
run() {
    "$W" "$@" >"$TMP/out" 2>"$TMP/err"
    code=$?
}

# check NAME CODE [STREAM TEXT]...: the exit code of the last run is CODE and each
# STREAM (out, err) contains TEXT; a STREAM written !out / !err must not contain it
# ("!err ''" : stderr empty)
check() {
    name=$1 want=$2
    shift 2
    why=""
    [ "$code" = "$want" ] || why="exit code $code, expected $want"
    while [ $# -ge 2 ]; do
        case $1 in
        !*) if grep -qF -- "$2" "$TMP/${1#!}"; then why="${why:+$why; }${1#!} has '$2'"; fi ;;
        *) if ! grep -qF -- "$2" "$TMP/$1"; then why="${why:+$why; }$1 lacks '$2'"; fi ;;
        esac
        shift 2
    done
    n=$((n + 1))
    if [ -z "$why" ]; then
        passed=$((passed + 1))
        echo "ok $n - $name"
    else
        failed=$((failed + 1))
        echo "not ok $n - $name"
        echo "  # $why"
        head -n 15 "$TMP/out" | sed 's/^/  # stdout: /'
        head -n 15 "$TMP/err" | sed 's/^/  # stderr: /'
    fi
}

# ---- the command itself
run --version
check "--version" 0 out "wobble "
run --help
check "--help lists the commands" 0 out "wobble run SCENE.lua" out "wobble test" out "wobble bench"
run
check "no command: usage, exit 2" 2 err "usage: wobble"
run frobnicate
check "unknown command" 2 err "unknown command 'frobnicate'" err "usage: wobble"
run run $F/args.lua --no-such-option
check "unknown option" 2 err "unknown option --no-such-option"
run run $F/args.lua --record out.avi
check "--record checks the extension (more in tests/render/run.sh)" 2 err "unknown extension '.avi'"
run sweep x.lua
check "sweep is not there yet" 2 err "not implemented yet"
run run
check "run without a scene" 2 err "run needs a scene script"
run run $F/missing.lua
check "run a missing file" 2 err "cannot open $F/missing.lua"
run run $F/args.lua --frames many
check "--frames wants a number" 2 err "--frames expects a whole number"
run run $F/args.lua --set novalue
check "--set wants key=value" 2 err "--set expects key=value"

# ---- script errors: file:line, traceback, exit 2
run run $F/syntax_error.lua
check "syntax error: file:line, exit 2" 2 err "$F/syntax_error.lua:3:"
run run $F/runtime_error.lua
check "runtime error: file:line and traceback" 2 err "$F/runtime_error.lua:2: attempt to index a nil value" \
    err "stack traceback:" err "$F/runtime_error.lua:4: in main chunk"
run run $F/error_values.lua --set kind=table
check "error({}) says what it got" 2 err "(error object is a table value)"
run run $F/error_values.lua --set kind=nil
check "error() says what it got" 2 err "(error object is a nil value)"
run run $F/error_values.lua --set kind=tostring
check "error(object) uses __tostring" 2 err "custom error text"
run run $F/error_values.lua --set kind=number
check "error(42) prints the number" 2 err "42"
run run $F/stack_overflow.lua
check "deep recursion: stack overflow, exit 2" 2 err "stack overflow"
run run $F/cstack_overflow.lua
check "recursion through C: stack overflow, exit 2" 2 err "stack overflow"
run run $F/assert_fail.lua
check "assert is a script error" 2 err "$F/assert_fail.lua:2: arithmetic is broken"
run run $F/expect_fail.lua
check "failed expectation in a scene: exit 1" 1 err "$F/expect_fail.lua:4: expected 3, got 2" !err "wobble/test.lua"
run run $F/os_exit.lua
check "os.exit is refused" 2 err "os.exit is not available in the sandbox"

# ---- budgets: exit 3, even when the script swallows errors
run run $F/busy_loop.lua --time-limit 0.3
check "time limit" 3 err "time limit of 0.3 s exceeded"
run run $F/busy_pcall.lua --time-limit=0.3
check "time limit through pcall" 3 err "time limit of 0.3 s exceeded"
run run $F/memory_bomb.lua --memory-limit 32
check "memory limit" 3 err "memory limit of 32 MB exceeded"
run run $F/memory_pcall.lua --memory-limit 32
check "memory limit through pcall" 3 err "memory limit of 32 MB exceeded"
run run $F/huge_cloth.lua --memory-limit 256
check "a world past the memory budget" 3 err "huge_cloth.lua:3: out of memory: cloth (the memory budget is 256 MB" !out "should not get here"

# ---- options and the runtime
run run $F/args.lua --set n=3 --set x=0.5 --set hex=0x10 --set name=cloth --set on=true --set off=false \
    --set "text=a=b c" --set empty=
check "--set values are typed" 0 out "args ok"
run run $F/unsafe.lua --unsafe
check "--unsafe gives the full library" 0 out "unsafe ok"
run run $F/unsafe.lua
check "without --unsafe the library is trimmed" 2 err "os.execute"
run run $F/write_out.lua --out "$TMP/o1"
[ "$code" = 0 ] && [ -f "$TMP/o1/nested/dir/result.txt" ]
code=$?
check "relative writes land in --out, folders created" 0
run run $F/require_sibling.lua
check "require finds modules beside the scene" 0 out "sibling ok"
run run $F/frames.lua --frames 7 --quiet
check "--frames caps w:run" 0 out "ran 7 frames"
run run $F/slow_run.lua
check "no progress bar when stderr is not a terminal" 0 out "slow done" !err ""
if command -v script >/dev/null 2>&1; then
    script -qec "$W run $F/slow_run.lua" /dev/null >"$TMP/out" 2>&1
    code=$?
    check "progress bar on a terminal" 0 out "60/60" out "fps"
    script -qec "$W run $F/slow_run.lua --quiet" /dev/null >"$TMP/out" 2>&1
    code=$?
    check "--quiet: no progress bar on a terminal" 0 !out "60/60"
fi

# symlinks cannot lead out of an allowed folder
mkdir -p "$TMP/scene"
ln -s /etc "$TMP/scene/etc_link"
cat >"$TMP/scene/link.lua" <<'EOF'
local f = io.open("etc_link/passwd")
EOF
run run "$TMP/scene/link.lua"
check "a symlink out of the scene folder is refused" 2 err "(/etc/passwd) is outside the allowed folders"
cat >"$TMP/scene/inside.lua" <<'EOF'
local f = assert(io.open("inside.lua"))
print((f:read("l")))
EOF
run run "$TMP/scene/inside.lua" --out "$TMP/o2"
check "the scene folder is readable from anywhere" 0 out "local f = assert"

# ---- wobble test: TAP 13
run test $F/tap_mixed.lua
check "test: TAP with a failure" 1 out "TAP version 13" out "ok 1 - $F/tap_mixed.lua: passes" \
    out "not ok 2 - $F/tap_mixed.lua: fails" out "  message: \"$F/tap_mixed.lua:4: expected 2 +- 0.10000000000000001, got 2.5" \
    out "not ok 3 - $F/tap_mixed.lua: checks nothing" out "no expectations" out "1..3"
[ "$(tail -n 1 "$TMP/out")" = "1 passed, 2 failed" ]
code=$?
check "test: the last line is the summary" 0
[ "$(head -n 1 "$TMP/out")" = "TAP version 13" ]
code=$?
check "test: the first line is the TAP version" 0
run test $F/tap_top_error.lua
check "test: an error at the top of a file is a script error" 2 \
    out "not ok 1 - $F/tap_top_error.lua: loading the file" out "tap_top_error.lua:4: attempt to index" out "0 passed, 1 failed"
run test $F/tap_no_cases.lua
check "test: a file without cases fails" 1 out "no test cases" out "0 passed, 1 failed"
run test $F/tap_budget.lua --time-limit 0.3
check "test: a budget ends the file, exit 3" 3 out "not ok 1 - $F/tap_budget.lua: spins" out "time limit" \
    !out "after the budget" out "0 passed, 1 failed"
run test $F/tapdir
check "test: folders are searched, sorted, fixtures and _files skipped" 0 \
    out "ok 1 - $F/tapdir/a.lua: a" out "ok 2 - $F/tapdir/sub/b.lua: b" out "2 passed, 0 failed" !out "_helper" !out "skip.lua"
run test $F/tapdir/a.lua $F/missing_dir
check "test: a missing path fails" 2 out "cannot open $F/missing_dir" out "1 passed, 1 failed"

echo "$passed passed, $failed failed"
[ "$failed" -eq 0 ]
