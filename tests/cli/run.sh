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
. tests/cli/lib.sh

# run ARGS...: run wobble; stdout in $TMP/out, stderr in $TMP/err, exit code in $code
run() {
    "$W" "$@" >"$TMP/out" 2>"$TMP/err"
    code=$?
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
# result.json: written when --out names the folder (a sweep's runs do), not by a run
# typed without it (it left out/result.json in whatever folder the user was in)
mkdir -p "$TMP/cwd"
(cd "$TMP/cwd" && "$OLDPWD/$W" run "$OLDPWD/$F/frames.lua" --frames 2 >"$TMP/out" 2>"$TMP/err"); code=$?
check "run without --out writes no out/result.json (nor out/)" 0 out "ran 2 frames" none "$TMP/cwd/out"
run run $F/frames.lua --frames 2 --out "$TMP/named"
cat "$TMP/named/result.json" >"$TMP/out" 2>/dev/null
check "run --out DIR writes DIR/result.json, how the run ended" 0 out '"status":	"ok"' out '"frames":	2'
# --size WxH of run: the recorded frames' size (a PNG's width and height, bytes 16-23)
png_size() { od -An -tu1 -j16 -N8 "$1" | awk '{ printf "%dx%d", $3 * 256 + $4, $7 * 256 + $8 }'; }
run run $F/frames.lua --frames 2 --quiet --size 320x200 --record "$TMP/sized/"
why=""
[ "$code" = 0 ] || why="exit code $code: $(cat "$TMP/err")"
for p in "$TMP"/sized/frame_00000[0-4].png; do
    [ "$(png_size "$p")" = 320x200 ] || why="${why:+$why; }$p is $(png_size "$p")"
done
[ -e "$TMP/sized/frame_000000.png" ] || why="${why:+$why; }no frames"
result "run --size 320x200 --record DIR/: every frame is 320x200" "$why"
run run $F/frames.lua --frames 1 --quiet --size=97x61 --record "$TMP/sized2/"
[ "$code" = 0 ] && [ "$(png_size "$TMP/sized2/frame_000000.png")" = 97x61 ] && why="" || why="exit code $code, $(png_size "$TMP/sized2/frame_000000.png")"
result "run --size=97x61: odd sizes as asked" "$why"
run run $F/frames.lua --size 320 --record "$TMP/bad/"
check "run --size 320: the argument at fault" 2 err "--size expects WIDTHxHEIGHT" err "got '320'" none "$TMP/bad"
run run $F/frames.lua --size 8x8 --record "$TMP/bad/"
check "run --size 8x8: too small" 2 err "each from 16 to 4096" err "got '8x8'"
run run $F/frames.lua --size 5000x100 --record "$TMP/bad/"
check "run --size 5000x100: too large" 2 err "got '5000x100'"
run run $F/frames.lua --size 320x200
check "run --size without --record says it would do nothing" 2 err "give --record OUT too"
run test $F/frames.lua --size 320x200
check "test --size is refused" 2 err "--size is an option of run and view"
run sweep x.lua
check "sweep without --grid (more in tests/cli/sweep.sh)" 2 err "sweep needs at least one --grid"
run run
check "run without a scene" 2 err "run needs a scene script"
run run $F/missing.lua
check "run a missing file" 2 err "cannot open $F/missing.lua"
run run $F/args.lua --frames many
check "--frames wants a number" 2 err "--frames expects a whole number"
run run $F/args.lua --set novalue
check "--set wants key=value" 2 err "--set expects key=value"
run run $F/args.lua --set a=1e999
check "--set refuses a number that is not finite" 2 err "--set a=1e999: the number is out of range"
run run $F/args.lua --set a=-1e400
check "--set refuses -inf too" 2 err "--set a=-1e400: the number is out of range"
run run $F/args.lua --threads 0
check "--threads 0 is refused" 2 err "--threads expects a whole number from 1 to 256, got '0'"

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
# errors Lua raises inside C functions carry no position of their own
run run $F/run_recursion.lua
check "recursion through w:run: file:line of the stack overflow" 2 \
    err "$F/run_recursion.lua:4: C stack overflow" err "stack traceback:"
run run $F/yield_on_frame.lua
check "yield in on_frame outside a coroutine: file:line" 2 \
    err "$F/yield_on_frame.lua:4: attempt to yield from outside a coroutine"
run run $F/expect_caught.lua
check "a failed expectation caught by pcall still fails the scene: exit 1" 1 \
    out "caught: true" err "$F/expect_caught.lua:3: expected 3 < 2" err "the script caught its error"

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
# one world fits in the budget, eight do not: the budget is shared, not per world
run run $F/many_worlds.lua --memory-limit 256
check "eight big worlds share one memory budget" 3 out "world 1" err "many_worlds.lua:6: out of memory" \
    !out "world 8" !out "should not get here"
# the interrupt is polled inside the step: a step of minutes ends within seconds
t0=$(date +%s)
run run $F/slow_step.lua --time-limit 1
t1=$(date +%s)
check "--time-limit stops a single long w:step" 3 err "slow_step.lua:5: time limit of 1 s exceeded" \
    !out "should not get here"
[ $((t1 - t0)) -le 20 ]
code=$?
check "--time-limit 1 ends a step of minutes within seconds ($((t1 - t0)) s)" 0

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
    # a line the scene prints starts a line of its own: the bar leaves its line first
    script -qec "$W run $F/slow_print.lua" /dev/null >"$TMP/out" 2>&1
    code=$?
    check "print during a progress bar: on its own line" 0 out "tick 45" out "60/60"
    tr '\r' '\n' <"$TMP/out" | grep -q "fps.*tick 45" &&
        result "print during a progress bar: not after the bar's text" "a printed line begins at the bar's end" ||
        result "print during a progress bar: not after the bar's text" ""
fi

# symlinks cannot lead out of an allowed folder
mkdir -p "$TMP/scene"
ln -s /etc "$TMP/scene/etc_link"
cat >"$TMP/scene/link.lua" <<'EOF'
local f = io.open("etc_link/passwd")
EOF
run run "$TMP/scene/link.lua"
check "a symlink out of the scene folder is refused, named as the script wrote it" 2 \
    err "reading etc_link/passwd is outside the allowed folders" !err "/etc/passwd"
cat >"$TMP/scene/inside.lua" <<'EOF'
local f = assert(io.open("inside.lua"))
print((f:read("l")))
EOF
run run "$TMP/scene/inside.lua" --out "$TMP/o2"
check "the scene folder is readable from anywhere" 0 out "local f = assert"

# ---- wobble test: TAP 13
run test $F/tap_mixed.lua
check "test: TAP with a failure" 1 out "TAP version 13" out "ok 1 - $F/tap_mixed.lua: passes" \
    out "not ok 2 - $F/tap_mixed.lua: fails" out "  message: \"$F/tap_mixed.lua:4: expected 2 +- 0.1, got 2.5" \
    out "not ok 3 - $F/tap_mixed.lua: checks nothing" out "no expectations" out "1..3"
[ "$(tail -n 1 "$TMP/out")" = "1 passed, 2 failed" ]
code=$?
check "test: the last line is the summary" 0
[ "$(head -n 1 "$TMP/out")" = "TAP version 13" ]
code=$?
check "test: the first line is the TAP version" 0
run test $F/tap_caught.lua
check "test: a failed expectation fails its case even when pcall catches it" 1 \
    out "not ok 1 - $F/tap_caught.lua: pcall around a failing expectation" \
    out "  message: \"$F/tap_caught.lua:4: expected 2, got 1 (an expectation failed and the script caught its error" \
    out "not ok 2 - $F/tap_caught.lua: a failing expectation in a coroutine" \
    out "ok 3 - $F/tap_caught.lua: expect.error of a failing expectation passes" \
    out "ok 4 - $F/tap_caught.lua: the next case starts clean" out "2 passed, 2 failed"
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

# ---- the manual's examples, taken from README.md and docs/ as they are printed there
# readme_block MARKER [FILE]: the ```lua block of FILE (README.md) whose first line is MARKER
readme_block() {
    awk -v m="$1" 'on && /^```/ {exit} on {print} prev == "```lua" && $0 == m {on = 1; print} {prev = $0}' "${2:-README.md}"
}
mkdir -p "$TMP/readme"
readme_block "-- tests/scenarios/rope_hangs.lua" docs/testing.md >"$TMP/readme/rope_hangs.lua"
run test "$TMP/readme/rope_hangs.lua" --out "$TMP/readme/out"
check "docs/testing.md: the scene test example runs as printed" 0 out "ok 1 - " out "1 passed, 0 failed"
[ "$(grep -c . "$TMP/readme/rope_hangs.lua")" -ge 5 ]
code=$?
check "docs/testing.md: the scene test example was found" 0
readme_block "-- drape.lua" >"$TMP/readme/drape.lua"
run run "$TMP/readme/drape.lua" --frames 5 --out "$TMP/readme/out"
check "README: the first scene runs as printed" 0 !err ""
[ "$(grep -c . "$TMP/readme/drape.lua")" -ge 5 ]
code=$?
check "README: the first scene was found" 0

# ---- make: deps, clean, install (the Makefile's own rules, with stand-ins for apt)
# ---- scripts/logo_spring.lua's other claims (make test checks the elastic one): plastic
# letters keep a dent; without shape matching the letters stay flat, so its check fails
run test scripts/logo_spring.lua --set plastic=1 --quiet
check "logo_spring --set plastic=1: the letters keep a dent" 0 out "plastic letters keep a dent"
run test scripts/logo_spring.lua --set shape=0 --quiet
check "logo_spring --set shape=0: links alone do not spring back" 1 out "not ok 2"

if command -v make >/dev/null 2>&1; then
    # these makes are a user's, typed in a shell: under `make -jN test` the outer make's
    # MAKEFLAGS name a jobserver whose pipes it does not hand to this script, and the
    # inner make would warn "jobserver unavailable" (it is not a recursive make of ours)
    unset MAKEFLAGS MFLAGS MAKELEVEL
    mkdir -p "$TMP/fakebin"
    # every package installed but $FAKE_MISSING; apt-get only logs what it was asked
    printf '#!/bin/sh\nfor pkg; do :; done\n[ "$pkg" = "$FAKE_MISSING" ] && exit 1\nprintf "ii "\n' \
        >"$TMP/fakebin/dpkg-query"
    printf '#!/bin/sh\necho "apt-get $*" >>"$FAKE_LOG"\n' >"$TMP/fakebin/apt-get"
    printf '#!/bin/sh\nexec "$@"\n' >"$TMP/fakebin/sudo"
    chmod +x "$TMP/fakebin/dpkg-query" "$TMP/fakebin/apt-get" "$TMP/fakebin/sudo"
    for pkg in none libstb-dev ffmpeg gcc; do
        rm -f "$TMP/apt.log"
        PATH="$TMP/fakebin:$PATH" FAKE_MISSING=$pkg FAKE_LOG="$TMP/apt.log" \
            make -s --no-print-directory check-deps >"$TMP/out" 2>"$TMP/err"
        code=$?
        cat "$TMP/apt.log" >>"$TMP/err" 2>/dev/null
        if [ "$pkg" = none ]; then
            check "make check-deps: quiet when every package is there" 0 !out "" !err ""
        else
            check "make check-deps: a missing $pkg is installed" 0 out "installing Debian packages: $pkg" \
                err "install -y -q $pkg"
        fi
    done
    # the build lines (a dry run of one object: -n prints even the silent recipe lines)
    obj="$BUILD/obj/core/bend.o"
    make -n -B --no-print-directory BUILD="$BUILD" "$obj" >"$TMP/out" 2>"$TMP/err"
    code=$?
    check "make: a short build line per file" 0 out "printf '  %-4s %s" out "src/core/bend.c"
    make -s -n -B --no-print-directory BUILD="$BUILD" "$obj" >"$TMP/out" 2>"$TMP/err"
    code=$?
    check "make -s: no build lines" 0 !out "printf" out "src/core/bend.c"
    make -n -B --no-print-directory BUILD="$BUILD" V=1 "$obj" >"$TMP/out" 2>"$TMP/err"
    code=$?
    check "make V=1: the whole commands" 0 !out "printf" out "-Werror"
    # make clean: the build folders go, the user's out/ stays
    mkdir -p "$TMP/proj/out" "$TMP/proj/build/obj" "$TMP/proj/build-asan" "$TMP/proj/build-bench" "$TMP/proj/build-x"
    echo video >"$TMP/proj/out/demo.mp4"
    make -s --no-print-directory -C "$TMP/proj" -f "$PWD/Makefile" clean BUILD=build-x >"$TMP/out" 2>"$TMP/err" &&
        [ -f "$TMP/proj/out/demo.mp4" ] && ! [ -e "$TMP/proj/build" ] && ! [ -e "$TMP/proj/build-asan" ] &&
        ! [ -e "$TMP/proj/build-bench" ] && ! [ -e "$TMP/proj/build-x" ]
    code=$?
    check "make clean removes the build folders and keeps out/" 0
    # an installed wobble runs its benchmark without the source tree's tests/bench
    # (-o all: install what $BUILD holds, build nothing)
    make -s --no-print-directory -o all install PREFIX="$TMP/inst" BUILD="$BUILD" >"$TMP/out" 2>"$TMP/err"
    code=$?
    check "make install" 0
    [ -f "$TMP/inst/share/wobble/bench/cloth128.lua" ]
    code=$?
    check "make install installs the benchmark scenes" 0
    "$TMP/inst/bin/wobble" bench --frames 1 --set frames=1 --out "$TMP/bench-out" --quiet >"$TMP/out" 2>"$TMP/err"
    code=$?
    check "an installed wobble bench runs the installed scenes" 0 out "share/wobble/bench/cloth128.lua" \
        out "cloth128" !out "tests/bench"
fi

echo "$passed passed, $failed failed"
[ "$failed" -eq 0 ]
