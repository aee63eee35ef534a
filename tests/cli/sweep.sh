#!/bin/sh
# tests/cli/sweep.sh BUILD_DIR: wobble sweep, result.json and wobble collect from
# outside, with a real engine: a 2 x 3 sweep of a tiny scene (tests/cli/fixtures/
# sweep_scene.lua; one grid value fails on purpose) is run through GNU parallel, one
# run is left half-started (crashed) and one never started (missing), then collect's
# CSV, JSON and --plot are checked; also --run, --force and the errors (exit 2).
# Last line: "N passed, N failed".
BUILD=${1:-build}
cd "$(dirname "$0")/../.." || exit 2
W="$(pwd)/$BUILD/wobble"
F=tests/cli/fixtures
TMP=$(mktemp -d "${TMPDIR:-/tmp}/wobble-sweep.XXXXXX") || exit 2
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

S=$TMP/s
run sweep $F/sweep_scene.lua --grid n=2,3 --grid g=1,2,boom --out "$S" --time-limit 60 --memory-limit 512
check "sweep writes the jobs and says how to run them" 0 out "6 runs in" out "parallel --sshloginfile" \
    out "sbatch $S/sweep.slurm"
lines=$(wc -l <"$S/jobs.txt")
[ "$lines" -eq 6 ] && why="" || why="jobs.txt has $lines lines, expected 6"
result "jobs.txt: a line per combination" "$why"
has "a job line is a complete wobble run: absolute paths, its own --out, its --set values, the limits" \
    "$S/jobs.txt" "'$W' run '$(pwd)/$F/sweep_scene.lua' --out '$S/runs/0003' --set 'n=2' --set 'g=boom' --quiet --time-limit '60' --memory-limit '512'"
has "sweep.slurm: a job array over the lines, limits with a margin, output under runs/NNNN" "$S/sweep.slurm" \
    "#SBATCH --array=1-6" "#SBATCH --time=0:02:06" "#SBATCH --mem=896M" 'sed -n "${SLURM_ARRAY_TASK_ID}p"' \
    '>"$dir/runs/$run/output.txt"'
has "sweep.json: grid, repeat, count and the scene" "$S/sweep.json" '"key":	"g"' '"values":	["1", "2", "boom"]' \
    '"repeat":	1' '"count":	6' "\"scene\":	\"$(pwd)/$F/sweep_scene.lua\""
[ ! -e "$S/runs" ] && why="" || why="runs/ exists"
result "nothing runs without --run" "$why"

# a real engine: GNU parallel runs the first 4 lines; line 5 starts and is killed
# (SIGKILL: it cannot write its end); line 6 never starts
head -n 4 "$S/jobs.txt" | parallel --will-cite >"$TMP/out" 2>"$TMP/err"
code=$?
check "parallel runs the jobs; the failing one fails" 1 err "boom: failing on purpose"
( eval "exec $(sed -n 5p "$S/jobs.txt") --set spin=true" ) >/dev/null 2>&1 &
pid=$!
i=0
while [ ! -e "$S/runs/0005/result.json" ] && [ $i -lt 300 ]; do sleep 0.1; i=$((i + 1)); done
kill -9 $pid 2>/dev/null
wait $pid 2>/dev/null
has "a run writes result.json as it starts: \"running\", until it ends" "$S/runs/0005/result.json" \
    '"status":	"running"' '"exit":	null'

has "result.json of a run: set values, status, exit, frames, the values merged (the later call wins)" \
    "$S/runs/0001/result.json" '"n":	2' '"g":	1' '"status":	"ok"' '"exit":	0' '"frames":	2' '"label":	"g=1"' \
    '"stable":	true' '"odd":	1' '"error":	null' '"wall_time":'
h=$(sed -n 's/.*"h":	"\([0-9a-f]*\)".*/\1/p' "$S/runs/0001/result.json")
[ -n "$h" ] && grep -qF "\"hash\":	\"$h\"" "$S/runs/0001/result.json" && why="" || why="hash is not w:hash() ($h)"
result "result.json's hash is the last world's w:hash(), though the scene closed it" "$why"
has "result.json of a script error: exit 2 and the message (no traceback)" "$S/runs/0003/result.json" \
    '"status":	"error"' '"exit":	2' '"error":	"'"$(pwd)/$F"'/sweep_scene.lua:8: boom: failing on purpose"' '"hash":	null'
# a scene in a deep folder (a long checkout path): Lua shortens a long file name in a
# position to "...its end"; the error names the scene by its whole path
L=$TMP/a-folder-deep-enough-that-lua-would-shorten-the-name-of-its-scene/and-deeper
mkdir -p "$L" && cp $F/sweep_scene.lua "$L/"
run sweep "$L/sweep_scene.lua" --grid g=boom --out "$TMP/deep"
sh -c "$(sed -n 1p "$TMP/deep/jobs.txt")" >/dev/null 2>&1
has "a scene in a deep folder: result.json's error names it by its whole path" "$TMP/deep/runs/0001/result.json" \
    '"error":	"'"$L"'/sweep_scene.lua:8: boom: failing on purpose"'
grep -q "stack traceback" "$S/runs/0003/result.json" && why="the traceback is in it" || why=""
result "result.json's error is the message alone" "$why"
has "result.json: a NaN result is text, and listed in non_finite" "$S/runs/0004/result.json" '"odd":	"nan"' \
    '"non_finite":	["odd"]'

run collect "$S" --csv
check "collect --csv" 0 out "run,status,exit,n,g,wall_time,frames,warnings,hash,h,label,odd,stable,y,non_finite,error"
has "CSV: an ok run with its values" "$TMP/out" "0001,ok,0,2,1," ",g=1,1,true,-0.00058333333333333"
has "CSV: the failed run, with its message" "$TMP/out" "0003,error,2,2,boom," "sweep_scene.lua:8: boom: failing on purpose"
has "CSV: a non-finite result is flagged" "$TMP/out" ",g=1,nan,false,-0.0012916666666666" ",odd,"
has "CSV: a run that started and left no result is crashed, one that never started missing" "$TMP/out" \
    "0005,crashed,,3,2,,,,,," "0006,missing,,3,boom,"
rows=$(grep -c '^000[1-6],' "$TMP/out")
[ "$rows" -eq 6 ] && why="" || why="$rows rows"
result "CSV: one row per job line" "$why"

run collect "$S" --json
check "collect --json" 0 out '"format":	"wobble-collect"'
for st in ok:3 error:1 crashed:1 missing:1; do
    c=$(grep -c "\"status\":	\"${st%:*}\"" "$TMP/out")
    [ "$c" -eq "${st#*:}" ] && why="" || why="$c runs with status ${st%:*}, expected ${st#*:}"
    result "JSON: ${st#*:} run(s) ${st%:*}" "$why"
done
has "JSON: typed set values, results, non_finite" "$TMP/out" '"g":	"boom"' '"n":	3' '"odd":	"nan"' '"non_finite":	["odd"]'

# --plot: a heat map (two grid keys); the failed cell (n=2, g=boom: top left) and the
# crashed one (n=3, g=2: middle right) crossed out in red, an ok cell (n=2, g=1) not
run collect "$S" --plot n,g,y "$TMP/heat.png"
check "collect --plot: a heat map, nothing on stdout" 0 !out "run,"
cat >"$TMP/pixels.lua" <<'LUA'
local w, h, px = wobble.read_png(wobble.args.png)
local function red(x, y)
  local i = (y * w + x) * 3 + 1
  local r, g, b = px:byte(i, i + 2)
  return r > 150 and g < 90 and b < 90
end
print(("size %dx%d"):format(w, h))
print("failed cell crossed: " .. tostring(red(287, 151)))
print("crashed cell crossed: " .. tostring(red(622, 315)))
print("ok cell crossed: " .. tostring(red(200, 450) or red(287, 478)))
LUA
"$W" run "$TMP/pixels.lua" --unsafe --quiet --out "$TMP/px" --set png="$TMP/heat.png" >"$TMP/out" 2>"$TMP/err"
code=$?
check "the heat map marks failed and crashed runs, not ok ones" 0 out "size 960x640" out "failed cell crossed: true" \
    out "crashed cell crossed: true" out "ok cell crossed: false"
run collect "$S" --plot n,y,g "$TMP/line.png" --csv
check "collect --plot: a line per colour value, and the table with --csv" 0 out "0006,missing"
"$W" run "$TMP/pixels.lua" --unsafe --quiet --out "$TMP/px" --set png="$TMP/line.png" >"$TMP/out" 2>"$TMP/err"
code=$?
check "the line chart is a PNG" 0 out "size 960x640"

# budgets and wobble.result's checks, in a run of their own
run run $F/sweep_scene.lua --out "$TMP/mem" --memory-limit 16 --set mem=true
check "a budget exit" 3 err "memory limit"
has "result.json of a budget exit (3)" "$TMP/mem/result.json" '"status":	"budget"' '"exit":	3' '"error":	' \
    'memory limit of 16 MB exceeded' '"frames":	2' '"y":	'
run run $F/sweep_scene.lua --out "$TMP/bad" --set bad=true
check "wobble.result refuses a table, naming the key" 2 err "field 'nested': expected a number, string or boolean, got table"
has "result.json of that error" "$TMP/bad/result.json" '"exit":	2' "field 'nested'"
grep -q '"fine"' "$TMP/bad/result.json" && why="a refused call kept 'fine'" || why=""
result "a refused wobble.result call keeps nothing" "$why"

# --run: GNU parallel on this machine, a joblog; --force over an earlier sweep
run sweep $F/sweep_scene.lua --grid g=1,2 --grid n=1 --repeat 2 --out "$TMP/r" --run
check "sweep --run starts GNU parallel" 0 err "4 runs done"
has "--run keeps parallel's joblog" "$TMP/r/joblog.txt" "Exitval"
run collect "$TMP/r"
check "--repeat: a row per repeat" 0 out ",repeat," out "0004,ok,0,2,1,2,"
run sweep $F/sweep_scene.lua --grid g=1 --out "$TMP/r"
check "a non-empty --out is refused" 2 err "--out $TMP/r is not empty" none "$TMP/r/runs/0005"
run sweep $F/sweep_scene.lua --grid g=1 --out "$TMP/r" --force
check "--force rewrites the sweep" 0 out "1 runs in"
[ ! -e "$TMP/r/runs" ] && [ "$(wc -l <"$TMP/r/jobs.txt")" -eq 1 ] && why="" || why="the old runs/ or jobs remain"
result "--force removes the earlier runs" "$why"

# input errors: exit 2, naming the argument
run sweep $F/sweep_scene.lua --grid n --out "$TMP/e1"
check "--grid without values" 2 err "--grid expects key=a,b,c, got 'n'" none "$TMP/e1"
run sweep $F/sweep_scene.lua --grid n=1,,2 --out "$TMP/e2"
check "--grid with an empty value" 2 err "--grid n=1,,2: an empty value" none "$TMP/e2"
run sweep $F/sweep_scene.lua --grid n=1 --grid n=2 --out "$TMP/e3"
check "--grid key twice" 2 err "the key 'n' is given twice"
run sweep $F/no_such_scene.lua --grid n=1 --out "$TMP/e4"
check "an unknown scene" 2 err "cannot open the scene $F/no_such_scene.lua" none "$TMP/e4"
: >"$TMP/afile"
run sweep $F/sweep_scene.lua --grid n=1 --out "$TMP/afile/sub"
check "an --out that cannot be made" 2 err "--out $TMP/afile/sub: cannot make the folder"
run sweep $F/sweep_scene.lua --grid n=1
check "sweep without --out" 2 err "sweep needs --out DIR"
run sweep $F/sweep_scene.lua --grid n=1 --out "$TMP/afile"
check "an --out that is a file" 2 err "--out $TMP/afile is a file, not a folder"
run sweep $F/sweep_scene.lua --grid n=1 --repeat 1e3 --out "$TMP/e5"
check "--repeat wants a whole number" 2 err "--repeat: '1e3' is not a valid value" none "$TMP/e5"
run collect "$S" --plot n,zzz "$TMP/z.png"
check "--plot on an unknown key names it and lists the keys" 2 err "--plot n,zzz: unknown key 'zzz'" \
    err "grid keys: n g; results: h label odd stable y" none "$TMP/z.png"
run collect "$S" --plot n "$TMP/z.png"
check "--plot with one key" 2 err "--plot expects X,Y or X,Y,COLOUR"
run collect "$TMP/afile"
check "collect of a folder that is no sweep" 2 err "is not a sweep folder"
run collect "$S" --plot n,g,y /proc/nope/x.png
check "--plot to a path that cannot be written" 2 err "--plot /proc/nope/x.png"

echo "$passed passed, $failed failed"
[ "$failed" -eq 0 ]
