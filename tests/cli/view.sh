#!/bin/sh
# tests/cli/view.sh BUILD_DIR: `wobble view` in a real window: each check
# starts its own X server (Xvfb, no screen needed) and drives the mouse and keys with
# xdotool. Proves: no display is a clear error (exit 2); the window opens and shows the
# scene with its overlay (--screenshot); a drag grabs a particle (the input log has
# grab, move and release, and the block is lifted); --record-input then `run --replay`
# ends on the same w:hash(); Space pauses and the right arrow steps one frame; --watch
# and R restart the scene, a script error waits for the next save; Esc ends with exit 0.
# Fixtures: tests/cli/fixtures/view.
# Last line: "N passed, N failed"; exit status 1 when a check failed.
BUILD=${1:-build}
cd "$(dirname "$0")/../.." || exit 2
W="$BUILD/wobble"
F=tests/cli/fixtures/view
TMP=$(mktemp -d "${TMPDIR:-/tmp}/wobble-view.XXXXXX") || exit 2
XPID="" VPID=""
cleanup() {
    [ -n "$VPID" ] && kill "$VPID" 2>/dev/null
    [ -n "$XPID" ] && kill "$XPID" 2>/dev/null
    rm -rf "$TMP"
}
trap cleanup EXIT
trap 'exit 130' INT TERM
. tests/cli/lib.sh

for tool in Xvfb xdotool; do
    if ! command -v $tool >/dev/null 2>&1; then
        echo "not ok 1 - $tool is installed (make deps installs it)"
        echo "0 passed, 1 failed"
        exit 1
    fi
done

# start_x: an X server of our own; Xvfb itself picks a free display number and writes it
# to fd 3 (-displayfd), so two runs in parallel never share one (choosing the number
# here raced: the loser's test then ran on the winner's server, gone when it ended);
# sets DISPLAY and XPID
start_x() {
    Xvfb -displayfd 3 -screen 0 640x480x24 -nolisten tcp 3>"$TMP/xdisplay" >/dev/null 2>&1 &
    XPID=$!
    i=0
    while [ $i -lt 100 ]; do
        d=$(cat "$TMP/xdisplay" 2>/dev/null)
        if [ -n "$d" ] && DISPLAY=":$d" xdotool getdisplaygeometry >/dev/null 2>&1; then
            export DISPLAY=":$d"
            return 0
        fi
        kill -0 "$XPID" 2>/dev/null || break
        sleep 0.1
        i=$((i + 1))
    done
    kill "$XPID" 2>/dev/null
    wait "$XPID" 2>/dev/null
    XPID=""
    return 1
}

stop_x() {
    [ -n "$XPID" ] && kill "$XPID" 2>/dev/null && wait "$XPID" 2>/dev/null
    XPID=""
}

# view ARGS...: the viewer in the background (stdout, stderr in $TMP/out, $TMP/err)
# An X server resets when its last client leaves, and a viewer connecting in that moment
# is refused ("Failed to open display": one case in a few full runs): such a start is
# made again, once. (Xvfb -noreset, the other cure, failed the --watch cases after the
# pause case in every run under load: one full CI run and two of view.sh alone; the same
# file without it passed. Not understood, not taken.)
view() {
    kill -0 "$XPID" 2>/dev/null || { echo "# the X server ended; starting another"; start_x; }
    "$W" view "$@" >"$TMP/out" 2>"$TMP/err" &
    VPID=$!
    i=0
    while kill -0 "$VPID" 2>/dev/null && [ $i -lt 100 ] &&
          [ -z "$(xdotool search --name "wobble view" 2>/dev/null | head -n 1)" ]; do
        sleep 0.1
        i=$((i + 1))
    done
    if ! kill -0 "$VPID" 2>/dev/null && grep -q "cannot open a window on display" "$TMP/err"; then
        wait "$VPID" 2>/dev/null
        echo "# the viewer could not open its window: started again"
        sleep 0.5
        "$W" view "$@" >"$TMP/out" 2>"$TMP/err" &
        VPID=$!
    fi
}

# finish SECS: wait up to SECS for the viewer to end; its exit code in $code (124: it
# did not end and was killed)
finish() {
    i=0
    while kill -0 "$VPID" 2>/dev/null && [ $i -lt $(($1 * 10)) ]; do
        sleep 0.1
        i=$((i + 1))
    done
    if kill -0 "$VPID" 2>/dev/null; then
        kill "$VPID" 2>/dev/null
        wait "$VPID" 2>/dev/null
        code=124
    else
        wait "$VPID"
        code=$?
    fi
    VPID=""
}

# wait_for FILE TEXT COUNT SECS: until FILE has COUNT lines containing TEXT; the time is
# tripled, as llvmpipe on a loaded machine can be many times slower (it returns as soon
# as the text is there, so a quick machine does not wait longer)
wait_for() {
    i=0
    while [ "$(grep -cF -- "$2" "$1" 2>/dev/null)" -lt "$3" ] && [ $i -lt $(($4 * 30)) ]; do
        sleep 0.1
        i=$((i + 1))
    done
    [ "$(grep -cF -- "$2" "$1" 2>/dev/null)" -ge "$3" ]
}

# the viewer's window id (waits for it to show)
window() {
    i=0
    while [ $i -lt 300 ]; do
        wid=$(xdotool search --onlyvisible --name "wobble view" 2>/dev/null | head -n 1)
        [ -n "$wid" ] && return 0
        sleep 0.1
        i=$((i + 1))
    done
    return 1
}

# ---- without a display: a clear message, exit 2, no window attempted for long
(unset DISPLAY WAYLAND_DISPLAY; "$W" view $F/rope.lua >"$TMP/out" 2>"$TMP/err")
code=$?
check "view without a display: exit 2 with a message" 2 err "no display" err "Xvfb"
"$W" run $F/rope.lua --watch >"$TMP/out" 2>"$TMP/err"
code=$?
check "--watch is an option of view alone" 2 err "--watch is an option of view"

"$W" view >"$TMP/out" 2>"$TMP/err"
code=$?
check "view without a scene: exit 2" 2 err "view needs a scene script"
"$W" view $F/rope.lua --size 10x10 >"$TMP/out" 2>"$TMP/err"
code=$?
check "view --size is checked" 2 err "--size expects WIDTHxHEIGHT"
"$W" view $F/rope.lua --record x.mp4 >"$TMP/out" 2>"$TMP/err"
code=$?
check "--record is not an option of view" 2 err "--record is an option of run"

# ---- an output path that cannot be written is an error before the window opens (no
# display needed: the check comes first), not after minutes of poking
for opt in --record-input --screenshot; do
    (unset DISPLAY WAYLAND_DISPLAY; "$W" view $F/rope.lua $opt "$TMP/no/such/out.x" >"$TMP/out" 2>"$TMP/err")
    code=$?
    check "view $opt to a folder that does not exist: exit 2 before the window" 2 \
        err "$opt: cannot write $TMP/no/such/out.x" !err "no display"
done
(unset DISPLAY WAYLAND_DISPLAY; "$W" view $F/rope.lua --record-input "$TMP/fresh.json" >"$TMP/out" 2>"$TMP/err")
code=$?
check "the check of a writable --record-input leaves no file behind" 2 err "no display" none "$TMP/fresh.json"

if ! start_x; then
    result "an X server (Xvfb) starts" "no display number answered"
    echo "$passed passed, $failed failed"
    exit 1
fi

# ---- the window shows the scene and the overlay; --frames closes it at the scene's end
view $F/rope.lua --size 320x240 --frames 20 --screenshot "$TMP/shot.png"
finish 20
check "view --frames 20 ends by itself with exit 0" 0 out "hash "
"$W" run $F/png_stats.lua --unsafe --set png="$TMP/shot.png" >"$TMP/stats" 2>&1
blue=$(sed -n 's/^blue //p' "$TMP/stats")
white=$(sed -n 's/^white //p' "$TMP/stats")
why=""
grep -q "size 320x240" "$TMP/stats" || why="screenshot not 320x240: $(cat "$TMP/stats")"
[ "${blue:-0}" -ge 100 ] || why="${why:+$why; }only ${blue:-0} blue (particle) pixels"
[ "${white:-0}" -ge 100 ] || why="${why:+$why; }only ${white:-0} white (overlay text) pixels"
result "the screenshot shows the rope's particles and the overlay" "$why"
"$W" run $F/rope.lua --frames 20 >"$TMP/out.run" 2>&1
if [ "$(grep '^hash' "$TMP/out")" = "$(grep '^hash' "$TMP/out.run")" ]; then why=""
else why="view: $(grep '^hash' "$TMP/out"), run: $(grep '^hash' "$TMP/out.run")"; fi
result "untouched, the viewer's run ends on the same hash as wobble run" "$why"

# ---- the scene's camera (wobble.camera) is the one the window starts with: looking away
# from the rope, the same window shows none of its particles
view $F/rope_away.lua --size 320x240 --frames 20 --screenshot "$TMP/away.png"
finish 20
"$W" run $F/png_stats.lua --unsafe --set png="$TMP/away.png" >"$TMP/stats" 2>&1
blue=$(sed -n 's/^blue_above //p' "$TMP/stats")
if [ -n "$blue" ] && [ "$blue" -lt 5 ]; then why=""; else why="${blue:-no} blue (particle) pixels above the legend: $(cat "$TMP/stats")"; fi
result "the viewer starts with the scene's camera (wobble.camera)" "$why"

# ---- a scene with its own (OSMesa) renderer: both pictures are drawn (GLX skipped
# binding the window's context again once OSMesa had taken the dispatch: a crash)
view $F/own_renderer.lua --size 320x240 --frames 20 --screenshot "$TMP/shot2.png" --out "$TMP/o"
finish 20
check "a scene drawing with wobble.renderer in the viewer ends with exit 0" 0 out "hash "
why=""
for png in "$TMP/shot2.png" "$TMP/o/own.png"; do
    "$W" run $F/png_stats.lua --unsafe --set png="$png" >"$TMP/stats" 2>&1
    blue=$(sed -n 's/^blue //p' "$TMP/stats")
    [ "${blue:-0}" -ge 20 ] || why="${why:+$why; }$png: only ${blue:-0} blue pixels"
done
result "the window and the scene's own renderer both show the rope" "$why"

# ---- a drag lifts the block: grab, moves, release in the log; --replay repeats it
view $F/grab.lua --size 320x240 --frames 240 --record-input "$TMP/input.json"
why=""
if window && wait_for "$TMP/out" "frame 30" 1 20; then
    xdotool mousemove --window "$wid" 160 120 mousedown 1
    for dy in 10 20 30 40 50 60 70 80; do
        xdotool mousemove --window "$wid" 160 $((120 - dy))
        sleep 0.05
    done
    sleep 0.5
    xdotool mouseup 1
else
    why="no window"
fi
finish 30
cp "$TMP/out" "$TMP/out.view"
check "the drag's run ends with exit 0 and saves the input" 0 out "hash " err "input events to"
for ev in '"type":	"grab"' '"type":	"move"' '"type":	"release"'; do
    grep -qF "$ev" "$TMP/input.json" 2>/dev/null || why="${why:+$why; }no $ev event in the log"
done
top=$(sed -n 's/^highest //p' "$TMP/out.view")
# the block rests with its top at 0.75 (`run` without input: highest 0.750); the drag
# lifts it far higher
awk -v t="${top:-0}" 'BEGIN { exit !(t > 1.0) }' || why="${why:+$why; }the block's top came to ${top:-?} at most, not lifted"
result "a left-drag on the block grabs a particle and lifts it" "$why"
"$W" run $F/grab.lua --frames 240 >"$TMP/out.plain" 2>&1
"$W" run $F/grab.lua --frames 240 --replay "$TMP/input.json" >"$TMP/out" 2>"$TMP/err"
code=$?
why=""
[ "$code" = 0 ] || why="--replay: exit code $code"
vh=$(grep '^hash' "$TMP/out.view") rh=$(grep '^hash' "$TMP/out") ph=$(grep '^hash' "$TMP/out.plain")
[ -n "$vh" ] && [ "$vh" = "$rh" ] || why="${why:+$why; }view '$vh', replay '$rh'"
[ "$vh" != "$ph" ] || why="${why:+$why; }the drag changed nothing: $ph without input too"
plain=$(sed -n 's/^highest //p' "$TMP/out.plain")
awk -v t="${plain:-9}" 'BEGIN { exit !(t < 0.8) }' || why="${why:+$why; }without input the block came to ${plain:-?}"
result "--record-input, then run --replay: the same w:hash() as the live run" "$why"

# ---- Space pauses (no frame steps), the right arrow steps one frame, Space runs again
view $F/frames.lua --size 320x240
why=""
wait_for "$TMP/out" "frame 5" 1 15 && window || why="the scene did not start"
xdotool mousemove --window "$wid" 10 10
xdotool key --window "$wid" space
# paused: the count stops (a busy machine may take a while to read the key)
i=0 c1=-1 c2=0
while [ "$c1" != "$c2" ] && [ $i -lt 10 ]; do
    c1=$(grep -c '^frame' "$TMP/out")
    sleep 0.7
    c2=$(grep -c '^frame' "$TMP/out")
    i=$((i + 1))
done
[ "$c1" = "$c2" ] || why="${why:+$why; }paused, yet frames went on ($c1, then $c2)"
xdotool key --window "$wid" Right
wait_for "$TMP/out" "frame $((c2 + 1))" 1 5 || why="${why:+$why; }the right arrow stepped no frame"
sleep 0.5
c3=$(grep -c '^frame' "$TMP/out")
[ "$c3" = $((c2 + 1)) ] || why="${why:+$why; }the right arrow stepped $((c3 - c2)) frames, not 1"
xdotool key --window "$wid" space
wait_for "$TMP/out" "frame $((c3 + 10))" 1 10 || why="${why:+$why; }space did not run it again"
xdotool key --window "$wid" Escape 2>/dev/null   # its release may find the window gone
finish 10
[ "$code" = 0 ] || why="${why:+$why; }Esc: exit code $code"
result "Space pauses, the right arrow steps one frame, Space runs on" "$why"

# ---- --watch: a saved scene or module restarts; an error waits for the next save
mkdir -p "$TMP/w"
cp $F/watch.lua $F/view_mod.lua "$TMP/w/"
printf 'one\n' >"$TMP/w/view_data.txt"
view "$TMP/w/watch.lua" --watch --size 320x240
why=""
wait_for "$TMP/out" "start 1" 1 15 || why="the scene did not start"
sleep 0.3
printf 'return { n = 2 }\n' >"$TMP/w/view_mod.lua"
wait_for "$TMP/out" "start 2" 1 10 || why="${why:+$why; }saving the module did not restart it"
sleep 0.3
touch "$TMP/w/watch.lua"
wait_for "$TMP/out" "start 2" 2 10 || why="${why:+$why; }touching the scene did not restart it"
result "--watch restarts the scene when it or a module it required is saved" "$why"
why=""
sleep 0.3
printf 'two\n' >"$TMP/w/view_data.txt"
wait_for "$TMP/out" "data two" 1 10 || why="saving a data file the scene read did not restart it"
result "--watch restarts the scene when a file it read (io.open) is saved" "$why"
why=""
cp "$TMP/w/watch.lua" "$TMP/watch.good"
printf 'local x = = 1\n' >"$TMP/w/watch.lua"
wait_for "$TMP/err" "watch.lua:1:" 1 10 || why="the syntax error is not on the terminal"
sleep 0.5
kill -0 "$VPID" 2>/dev/null || why="${why:+$why; }the viewer closed on the error"
cp "$TMP/watch.good" "$TMP/w/watch.lua"
wait_for "$TMP/out" "start 2" 4 10 || why="${why:+$why; }fixing the file did not run it again"
result "--watch: a script error is shown and the viewer waits for the next save" "$why"
why=""
window || why="no window"
xdotool mousemove --window "$wid" 10 10
xdotool key --window "$wid" r
wait_for "$TMP/out" "start 2" 5 10 || why="R did not restart the scene"
xdotool key --window "$wid" Escape 2>/dev/null   # its release may find the window gone
finish 10
[ "$code" = 0 ] || why="${why:+$why; }Esc: exit code $code"
result "R restarts the scene; Esc closes the viewer with exit 0" "$why"

# ---- the script closes the world shown and steps another: that one is shown and can be
# grabbed (the viewer kept a pointer to the freed world: a use after free)
view $F/closed_world.lua --size 320x240 --frames 240 --record-input "$TMP/input2.json"
why=""
if window && wait_for "$TMP/out" "frame 30" 1 20; then
    xdotool mousemove --window "$wid" 160 120 mousedown 1
    for dy in 10 20 30 40 50 60; do
        xdotool mousemove --window "$wid" 160 $((120 - dy))
        sleep 0.05
    done
    sleep 0.3
    xdotool mouseup 1
else
    why="no window"
fi
finish 30
cp "$TMP/out" "$TMP/out.view"
check "a scene closing its first world ends with exit 0" 0 out "hash "
grep -qF '"world":	2' "$TMP/input2.json" 2>/dev/null || why="${why:+$why; }no event of world 2 in the log"
grep -qF '"type":	"grab"' "$TMP/input2.json" 2>/dev/null || why="${why:+$why; }no grab in the log"
"$W" run $F/closed_world.lua --frames 240 --replay "$TMP/input2.json" >"$TMP/out" 2>"$TMP/err"
vh=$(grep '^hash' "$TMP/out.view") rh=$(grep '^hash' "$TMP/out")
[ -n "$vh" ] && [ "$vh" = "$rh" ] || why="${why:+$why; }view '$vh', replay '$rh'"
result "after the script closes the world shown, the next world is shown and grabbed" "$why"

# ---- a drag on empty space orbits (nothing logged); a grab made while paused, then R:
# the log starts again, so the file holds no event of the run before
view $F/grab.lua --size 320x240 --set frames=100000 --record-input "$TMP/orbit.json"
why=""
if window && wait_for "$TMP/out" "frame 30" 1 20; then
    xdotool mousemove --window "$wid" 5 230 mousedown 1
    for dx in 20 40 60 80; do
        xdotool mousemove --window "$wid" $((5 + dx)) 230
        sleep 0.05
    done
    xdotool mouseup 1
    sleep 0.3
    xdotool key --window "$wid" Escape 2>/dev/null
else
    why="no window"
fi
finish 20
check "a drag on empty space: exit 0 and the log saved" 0 err "recorded 0 input events"
view $F/grab.lua --size 320x240 --set frames=100000 --record-input "$TMP/restart.json"
why=""
if window && wait_for "$TMP/out" "frame 30" 1 20; then
    xdotool mousemove --window "$wid" 10 10 key --window "$wid" space
    sleep 1
    xdotool mousemove --window "$wid" 160 120 mousedown 1
    for dy in 10 20 30 40; do
        xdotool mousemove --window "$wid" 160 $((120 - dy))
        sleep 0.05
    done
    xdotool mouseup 1
    sleep 0.3
    xdotool key --window "$wid" r
    sleep 0.3
    # R keeps the pause (docs/cli.md): Space runs the new run on to its frame 30
    xdotool key --window "$wid" space
    wait_for "$TMP/out" "frame 30" 2 20 || why="R did not restart the scene"
    xdotool key --window "$wid" Escape 2>/dev/null
else
    why="no window"
fi
finish 20
# (check starts its own why: a reason found above is reported by result instead)
if [ -n "$why" ]; then
    result "a grab while paused, then R: the log holds the new run alone" "$why"
else
    check "a grab while paused, then R: the log holds the new run alone" 0 err "recorded 0 input events"
fi

# ---- os.exit (--unsafe) closes the viewer with its code; the input log and the
# screenshot are still written (the process used to exit on the spot)
view $F/exit.lua --unsafe --size 320x240 --record-input "$TMP/exit.json" --screenshot "$TMP/exit.png"
finish 20
check "os.exit(4) in the viewer: exit code 4, the log is saved" 4 err "input events to"
why=""
[ -s "$TMP/exit.json" ] || why="no input log written"
[ -s "$TMP/exit.png" ] || why="${why:+$why; }no screenshot written"
result "os.exit in the viewer still writes --record-input and --screenshot" "$why"

# ---- --time-limit bounds the script, not the look at its last picture: the viewer
# waiting for Esc past the limit and the watchdog's grace (5 s) is not ended with exit 3
view $F/short.lua --size 320x240 --time-limit 1
why=""
wait_for "$TMP/out" "ended" 1 15 || why="the scene did not end"
sleep 8
kill -0 "$VPID" 2>/dev/null || why="${why:+$why; }the viewer was ended while it waited for Esc"
window && xdotool key --window "$wid" Escape 2>/dev/null
finish 10
[ "$code" = 0 ] || why="${why:+$why; }exit code $code, expected 0"
result "--time-limit: the wait after the scene's end is not under the budget" "$why"

stop_x
echo "$passed passed, $failed failed"
[ "$failed" -eq 0 ]
