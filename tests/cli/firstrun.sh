#!/bin/sh
# tests/cli/firstrun.sh BUILD_DIR: what a new user meets first. `make deps` without root
# and without sudo says what to run; apt's output goes to a log, not the terminal; the
# README's set-up starts with the command that gets make; `wobble bench --frames N`;
# `print` in a test file is a TAP comment. apt-get, dpkg-query, id and sudo are
# stand-ins written here: nothing is installed. Last line "N passed, N failed".
BUILD=${1:-build}
cd "$(dirname "$0")/../.." || exit 2
W="$BUILD/wobble"
F=tests/cli/fixtures
TMP=$(mktemp -d "${TMPDIR:-/tmp}/wobble-firstrun.XXXXXX") || exit 2
trap 'rm -rf "$TMP"' EXIT INT TERM
. tests/cli/lib.sh


# ---- make deps with stand-ins: a PATH holding only the tools the rule needs, so no real
# sudo or apt-get can be reached
MAKE_BIN=$(command -v make)
if [ -n "$MAKE_BIN" ]; then
    B="$TMP/bin"
    mkdir -p "$B"
    for tool in grep mkdir tail env cat tee awk rm; do ln -s "$(command -v $tool)" "$B/$tool"; done
    # dpkg-query: installed unless named in $FAKE_MISSING
    cat >"$B/dpkg-query" <<'SH'
#!/bin/sh
for pkg; do :; done
case " $FAKE_MISSING " in *" $pkg "*) exit 1 ;; esac
printf "ii "
SH
    # id -u: $FAKE_UID
    printf '#!/bin/sh\necho "$FAKE_UID"\n' >"$B/id"
    # apt-get: logs its arguments and DEBIAN_FRONTEND, talks like dpkg ($FAKE_APT=noisy)
    # or fails like apt on a package it does not know ($FAKE_APT=fail)
    cat >"$B/apt-get" <<'SH'
#!/bin/sh
echo "apt-get $* DEBIAN_FRONTEND=$DEBIAN_FRONTEND" >>"$FAKE_LOG"
case $FAKE_APT in
noisy) [ "$3" = install ] || exit 0; i=0; while [ $i -lt 1500 ]; do echo "Unpacking libfoo$i (1.0-1) ..."
       echo "pmstatus:libfoo$i:$((i / 15)).0000:Unpacking libfoo$i (amd64)"; i=$((i + 1)); done
       echo "debconf: unable to initialize frontend: Dialog" >&2 ;;
fail) [ "$3" = install ] && { echo "E: Unable to locate package ffmpeg" >&2; exit 100; } ;;
esac
exit 0
SH
    chmod +x "$B/dpkg-query" "$B/id" "$B/apt-get"
    # deps RUN...: make deps with the stand-ins, gcc and ffmpeg missing; output in out/err
    deps() {
        rm -f "$TMP/apt.log"
        env -i PATH="$B" FAKE_MISSING="gcc ffmpeg" FAKE_LOG="$TMP/apt.log" "$@" \
            "$MAKE_BIN" -s --no-print-directory deps BUILD="$TMP/b" >"$TMP/out" 2>"$TMP/err"
        code=$?
    }

    deps FAKE_UID=1000
    [ ! -e "$TMP/apt.log" ] || { echo "apt-get was run" >>"$TMP/err"; code=99; }
    check "make deps, not root and no sudo: says what to run as root, exit 2" 2 \
        err "wobble needs these Debian packages: gcc ffmpeg" \
        err "run as root (su -), then make again: apt-get update && apt-get install -y gcc ffmpeg" \
        !err "not found"

    # sudo resets the environment, as the real one does
    printf '#!/bin/sh\necho "sudo $*" >>"$FAKE_LOG"\nexec env -i PATH="$PATH" FAKE_LOG="$FAKE_LOG" "$@"\n' >"$B/sudo"
    chmod +x "$B/sudo"
    deps FAKE_UID=1000
    cat "$TMP/apt.log" >>"$TMP/out" 2>/dev/null
    check "make deps, not root: through sudo, noninteractive apt-get" 0 \
        out "sudo env DEBIAN_FRONTEND=noninteractive apt-get -o APT::Status-Fd=1 install -y -q gcc ffmpeg" \
        out "apt-get -o APT::Status-Fd=1 install -y -q gcc ffmpeg DEBIAN_FRONTEND=noninteractive"
    rm -f "$B/sudo"

    deps FAKE_UID=0 FAKE_APT=noisy
    lines=$(cat "$TMP/out" "$TMP/err" | wc -l)
    logged=$(grep -c "^Unpacking" "$TMP/b/deps.log" 2>/dev/null)
    progress=$(grep -c "^  installing \[" "$TMP/out")
    [ "$lines" -le 20 ] && [ "$progress" -ge 10 ] && [ "${logged:-0}" -eq 1500 ] ||
        code="$code ($lines lines shown, $progress of progress, ${logged:-0} logged)"
    check "make deps as root: what it installs, apt's progress a line each 10% (not a terminal), apt's 1,500 lines in the log" 0 \
        out "installing Debian packages: gcc ffmpeg" out "apt-get's whole output: $TMP/b/deps.log" \
        out "  installing [  0%] Unpacking libfoo0 (amd64)" out "  installing [ 90%] Unpacking libfoo1350 (amd64)" \
        out "installed: gcc ffmpeg" !out "Unpacking libfoo0 (1.0-1)" !err "debconf"

    deps FAKE_UID=0 FAKE_APT=fail
    check "make deps: apt fails: exit 2, the end of its log and where the log is" 2 \
        err "apt-get failed; the end of its output ($TMP/b/deps.log):" \
        err "E: Unable to locate package ffmpeg"
fi

# ---- the README's set-up starts with the command that gets make on a fresh Debian
awk '/^## Set-up/ {on = 1; next} on && /^## / {exit} on && /^```sh$/ {block = 1; next}
     block && /^```$/ {exit} block {print}' README.md >"$TMP/out"
: >"$TMP/err"
code=0
check "README: the set-up's first command, as root, installs make and git" 0 \
    out "apt-get install -y make git"

# ---- the README's first scene, as printed, does what the README says: the cloth drapes
# over the sphere (some of it rests on the sphere's top), it does not slide off
awk 'on && /^```/ {exit} on {print} prev == "```lua" && $0 == "-- drape.lua" {on = 1; print} {prev = $0}' \
    README.md >"$TMP/drape.lua"
cat >>"$TMP/drape.lua" <<'LUA'
test("the cloth rests on the sphere's top", function()
  local on_top = 0
  for _, p in ipairs(cloth.particles) do
    local x, y, z = w:position(p)
    local above = math.sqrt(x * x + (y - 0.5) ^ 2 + z * z) - 0.4
    if x * x + z * z < 0.2 ^ 2 and y > 0.5 and above < 0.05 then on_top = on_top + 1 end
  end
  -- the cloth still swings at 3 s: 6 to 15 particles there at single frames of the last
  -- second (mean 9.3 to 9.6 with either colouring order); one slid off leaves none
  expect.gt(on_top, 5, "particles of the cloth lying on the sphere's top")
end)
LUA
"$W" test "$TMP/drape.lua" --quiet --out "$TMP/drape-out" >"$TMP/out" 2>"$TMP/err"
code=$?
[ "$(grep -c . "$TMP/drape.lua")" -ge 15 ] || code="$code (the README's drape.lua was not found)"
check "README: the first scene drapes the cloth over the sphere" 0 out "1 passed, 0 failed"

# ---- wobble bench --frames N: every benchmark scene runs N frames
"$W" bench --frames 2 --json --quiet --time-limit 300 --out "$TMP/bench" >"$TMP/out" 2>"$TMP/err"
code=$?
scenes=$(ls tests/bench/*.lua | wc -l)   # a file may hold several scenes (cloth128.lua)
rows=$(grep -c . "$TMP/out")
[ "$(grep -c '"frames": 2[,}]' "$TMP/out")" -eq "$rows" ] && [ "$rows" -ge "$scenes" ] ||
    code="$code (not every scene ran 2 frames)"
check "bench --frames 2: every scene of the $scenes benchmark files runs 2 frames" 0 out '"scene": "cloth128"'
"$W" bench --frames 0 >"$TMP/out" 2>"$TMP/err"
code=$?
check "bench --frames 0 is refused" 2 err "bench --frames expects at least 1 frame"
"$W" --help >"$TMP/out" 2>"$TMP/err"
code=$?
check "--help says what --frames does for bench" 0 out "bench: each scene runs N frames"

# ---- print inside a test: TAP comments
"$W" test $F/tap_print.lua >"$TMP/out" 2>"$TMP/err"
code=$?
[ "$(grep -c '^ok ' "$TMP/out")" -eq 1 ] || code="$code (a print was read as a result)"
check "test: print writes TAP comments, a line each" 0 out "# from the top of the file" \
    out "# ok 99 - a print that looks like a result" out "# two" out "# lines" out "1..1"
"$W" run $F/tap_print_scene.lua >"$TMP/out" 2>"$TMP/err"
code=$?
grep -qx "scene output" "$TMP/out" || code="$code (the scene's own output was changed)"
check "run: a scene's own print stays plain, its cases' prints are TAP comments" 0 \
    out "# ok 98 - printed by a case" out "ok 1 - $F/tap_print_scene.lua: prints"

echo "$passed passed, $failed failed"
[ "$failed" -eq 0 ]
