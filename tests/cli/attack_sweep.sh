#!/bin/sh
# tests/cli/attack_sweep.sh BUILD_DIR: hostile input to wobble sweep, wobble collect and
# wobble run --replay: paths that would break a job line open, --force over a folder
# that is not a sweep, garbage sweep.json / result.json, odd replay files. Each must be
# refused with exit 2 and a message naming the culprit (or read safely), and must change
# nothing. Last line: "N passed, N failed".
BUILD=${1:-build}
cd "$(dirname "$0")/../.." || exit 2
W="$(pwd)/$BUILD/wobble"
F=tests/cli/fixtures
TMP=$(mktemp -d "${TMPDIR:-/tmp}/wobble-attack.XXXXXX") || exit 2
trap 'rm -rf "$TMP"' EXIT INT TERM
. tests/cli/lib.sh

run() {
    "$W" "$@" >"$TMP/out" 2>"$TMP/err"
    code=$?
}

# has NAME FILE TEXT...: FILE contains every TEXT (fixed strings)
has() {
    name=$1 file=$2
    shift 2
    why=""
    for t in "$@"; do grep -qF -- "$t" "$file" 2>/dev/null || why="${why:+$why; }$file lacks '$t'"; done
    result "$name" "$why"
}

# a scene whose path holds a line break: jobs.txt and sweep.slurm would run its second
# line as a command of its own
NL='
'
D="$TMP/d${NL}touch PWNED${NL}"
mkdir -p "$D" && cp $F/sweep_scene.lua "$D/s.lua"
run sweep "$D/s.lua" --grid g=1 --out "$TMP/o1"
check "a scene path with a line break is refused" 2 err "holds a line break" none "$TMP/o1"
run sweep $F/sweep_scene.lua --grid g=1 --out "$TMP/o2${NL}x"
check "an --out with a line break is refused" 2 err "holds a line break" none "$TMP/o2${NL}x"
( cd "$D" && "$W" sweep s.lua --grid g=1 --out o3 >"$TMP/out" 2>"$TMP/err" ); code=$?
check "a relative --out under a folder with a line break is refused" 2 err "holds a line break" none "$D/o3"

# --force removes runs/: never in a folder that is not an earlier sweep's
mkdir -p "$TMP/proj/runs" && echo precious >"$TMP/proj/runs/data.txt" && cp $F/sweep_scene.lua "$TMP/proj/s.lua"
run sweep "$TMP/proj/s.lua" --grid g=1 --out "$TMP/proj" --force
check "--force on a folder without sweep.json is refused, its runs/ kept" 2 err "not an earlier sweep's folder" \
    none "$TMP/proj/jobs.txt"
[ -f "$TMP/proj/runs/data.txt" ] && why="" || why="runs/data.txt was removed"
result "--force on the scene's own folder removes nothing" "$why"

# collect on damaged files: a garbage sweep.json is named (exit 2), never followed into
# a crash; a result.json of the wrong shape is a run whose end is unknown (crashed)
C=$TMP/c
mkdir -p "$C/runs/0001" "$C/runs/0002" "$C/runs/0003"
printf '{"status":"ok","result":[1,2]}' >"$C/runs/0001/result.json"
printf '{"status":"ok","result":{"a":{"x":1}}}' >"$C/runs/0002/result.json"
printf '{"status":"ok","resu' >"$C/runs/0003/result.json"
printf '%s' '{"grid":[{"key":"g","values":["1"]}],"runs":[{"run":"0001","set":{"g":"1"}},{"run":"0002","set":{"g":"1"}},{"run":"0003","set":{"g":"1"}}]}' >"$C/sweep.json"
run collect "$C"
check "collect: result.json of the wrong shape or cut short is crashed" 0 out "0001,crashed,,1" out "0002,crashed,,1" \
    out "0003,crashed,,1"
bad_sweep() {  # NAME REASON JSON
    printf '%s' "$3" >"$C/sweep.json"
    run collect "$C"
    check "collect: $1" 2 err "sweep.json is not a sweep description" err "$2" !out "run,"
}
bad_sweep "a grid entry without a key" "grid[1].key: expected a string" '{"grid":[{}],"runs":[{"run":"0001"}]}'
bad_sweep "a grid key twice" "grid[2].key: 'g' twice" '{"grid":[{"key":"g"},{"key":"g"}],"runs":[]}'
bad_sweep "a run that is not an object" "runs[1].run" '{"grid":[],"runs":[1]}'
bad_sweep "a run named as a path" "runs[1].run: expected the run's number" '{"grid":[],"runs":[{"run":"../../x"}]}'
bad_sweep "a set value that is not a string" "runs[1].set.g: expected a string" \
    '{"grid":[{"key":"g"}],"runs":[{"run":"0001","set":{"g":1}}]}'
bad_sweep "repeat out of range" "repeat: expected a number from 1" '{"grid":[],"runs":[],"repeat":1e300}'
bad_sweep "cut short" "not JSON, or cut short" '{"grid":'

# --plot of values near DBL_MAX: the log axis's end rounded to 10^309 = inf and its grid
# loop never ended; a linear span of -1.7e308..1.7e308 and a mean of repeats overflowed.
# Each plot must end (a time limit: the old code looped forever) with a finite picture
H=$TMP/huge
mkdir -p "$H/runs/0001" "$H/runs/0002" "$H/runs/0003" "$H/runs/0004"
printf '%s' '{"grid":[{"key":"a","values":["1","2"]},{"key":"b","values":["1","2"]}],"repeat":1,"runs":[{"run":"0001","set":{"a":"1","b":"1"}},{"run":"0002","set":{"a":"2","b":"1"}},{"run":"0003","set":{"a":"1","b":"2"}},{"run":"0004","set":{"a":"2","b":"2"}}]}' >"$H/sweep.json"
k=0
for v in "1e300 1.7e308 -1.7e308" "1e-300 9.9e307 1.7976931348623157e308" "1 1.79e308 1.79e308" "1e308 1.7e308 -1e308"; do
    k=$((k + 1))
    set -- $v
    printf '{"status":"ok","result":{"x":%s,"y":%s,"z":%s}}' "$1" "$2" "$3" >"$H/runs/000$k/result.json"
done
for p in x,y x,z y,z a,b,y a,b,z; do
    rm -f "$TMP/huge.png"
    "$W" collect "$H" --plot $p "$TMP/huge.png" >"$TMP/out" 2>"$TMP/err" &
    cpid=$!
    # its output away from the suite's pipe: killing the subshell leaves its sleep, which
    # held the pipe open (make test's last line came 20 s after the rest)
    ( sleep 20; kill -9 $cpid 2>/dev/null ) >/dev/null 2>&1 &
    wpid=$!
    wait $cpid
    code=$?
    kill $wpid 2>/dev/null
    wait $wpid 2>/dev/null
    why=""
    [ "$code" = 0 ] || why="exit $code (137: still drawing after 20 s)"
    [ -s "$TMP/huge.png" ] || why="${why:+$why; }no picture"
    result "collect --plot $p of values near 1.8e308 ends with a picture" "$why"
done

# a grid value longer than a job line's old 4 KiB buffer reaches the run whole
long=$(awk 'BEGIN { for (i = 0; i < 5000; i++) printf "x"; printf "'"'"'end" }')
cat >"$TMP/echo.lua" <<'LUA'
wobble.result{ len = #wobble.args.v, tail = wobble.args.v:sub(-4) }
LUA
run sweep "$TMP/echo.lua" --grid "v=$long" --out "$TMP/lv"
sh -c "$(sed -n 1p "$TMP/lv/jobs.txt")" >/dev/null 2>&1
has "a 5004-byte grid value is passed whole" "$TMP/lv/runs/0001/result.json" '"len":	5004' "\"tail\":	\"'end\""

# wobble.result: a NUL byte would cut a value short in result.json; a key's __tostring
# is never called for the message (it may fail and hide the real error)
cat >"$TMP/res.lua" <<'LUA'
if wobble.args.mode == "nul" then wobble.result{ s = "a\0b" } end
if wobble.args.mode == "key" then wobble.result{ [setmetatable({}, { __tostring = function() return {} end })] = 1 } end
LUA
run run "$TMP/res.lua" --set mode=nul --out "$TMP/rn"
check "wobble.result: a string with a NUL byte is refused, naming the field" 2 err "res.lua:1:" \
    err "field 's': a string holds a NUL byte"
run run "$TMP/res.lua" --set mode=key --out "$TMP/rk"
check "wobble.result: a table key is named without its __tostring" 2 err "res.lua:2:" \
    err "keys must be strings (names of results), got table key"

# result.json: a --set key of any length is kept whole (a 256-byte buffer cut it)
k=$(awk 'BEGIN { for (i = 0; i < 300; i++) printf "k" }')
run run "$TMP/echo.lua" --set v=1 --set "$k=1" --out "$TMP/lk"
has "result.json keeps a 300-byte --set key whole" "$TMP/lk/result.json" "\"$k\":	1"
run sweep "$TMP/echo.lua" --grid v=1 --repeat 2 --set repeat=5 --out "$TMP/rr"
check "sweep: --set repeat=... with --repeat is refused" 2 err "--set repeat=5: with --repeat" none "$TMP/rr"

# --replay of a long log: each event's line:col was counted from the file's start
# (quadratic: 10^5 events took about 20 minutes); now about a second of CPU (the limit is
# generous for ASan on a busy machine). The frames are past the scene's end, so the run
# reports the events it did not apply (exit 1).
awk 'BEGIN { printf "{\"format\":\"wobble-input\",\"version\":1,\"events\":[\n";
             for (i = 1; i <= 100000; i++) printf "%s{\"frame\":%d,\"world\":1,\"type\":\"grab\",\"particle\":1,\"target\":[0,0,0]}\n", (i > 1 ? "," : ""), 1000000 + i;
             print "]}" }' >"$TMP/long.json"
MAX_SECS=300
start=$(date +%s)
timeout 300 "$W" run tests/cli/fixtures/replay_rope.lua --quiet --replay "$TMP/long.json" >"$TMP/out" 2>"$TMP/err"
code=$?
secs=$(($(date +%s) - start))
check "--replay reads 10^5 events within 300 s (minutes of CPU before)" 1 err "100000 events were not applied"
MAX_SECS=

echo "$passed passed, $failed failed"
[ "$failed" -eq 0 ]
