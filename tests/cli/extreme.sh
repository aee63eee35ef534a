#!/bin/sh
# tests/cli/extreme.sh BUILD_DIR: extreme but finite input from the command line ends
# with exit 2 and a `bad argument` naming the option at the script's line, never an
# assertion (exit 134), a heap overflow or a frozen world.
# Last line: "N passed, N failed"; exit status 1 when a check failed.
BUILD=${1:-build}
cd "$(dirname "$0")/../.." || exit 2
W="$BUILD/wobble"
TMP=$(mktemp -d "${TMPDIR:-/tmp}/wobble-extreme.XXXXXX") || exit 2
trap 'rm -rf "$TMP"' EXIT INT TERM
n=0 passed=0 failed=0

# case NAME WANT_CODE WANT_ERR SCRIPT: run SCRIPT (a scene), check its exit code and stderr
case_() {
    n=$((n + 1))
    printf '%s\n' "$4" >"$TMP/scene.lua"
    "$W" run "$TMP/scene.lua" --frames 1 --quiet >"$TMP/out" 2>"$TMP/err"
    code=$?
    why=""
    [ "$code" = "$2" ] || why="exit code $code, expected $2"
    [ -z "$3" ] || grep -qF -- "$3" "$TMP/err" || why="$why; stderr lacks: $3"
    if [ -z "$why" ]; then
        passed=$((passed + 1))
        echo "ok $n - $1"
    else
        failed=$((failed + 1))
        echo "not ok $n - $1 ($why)"
        sed 's/^/  # /' "$TMP/err" | head -5
    fi
}

case_ "rope whose extent overflows" 2 "scene.lua:2: bad argument #1 to 'rope' (from/to: " \
'local w = wobble.world{}
w:rope{ from = {-1e308, 0, 0}, to = {1e308, 0, 0} }'
case_ "cloth whose extent overflows" 2 "bad argument #1 to 'cloth' (origin/size: " \
'local w = wobble.world{}
w:cloth{ origin = {1e308, 0, 0}, size = {1e308, 1} }'
case_ "lattice whose extent overflows" 2 "bad argument #1 to 'lattice' (min/max: " \
'local w = wobble.world{}
w:lattice{ min = {-1e308, 0, 0}, max = {1e308, 1, 1} }'
case_ "distance between particles 2e200 apart" 2 "scene.lua:4: bad argument #2 to 'distance' (particles 1 and 2 are too far apart" \
'local w = wobble.world{}
local a = w:particle{ pos = {-1e200, 0, 0} }
local b = w:particle{ pos = {1e200, 0, 0} }
w:distance(a, b)'
case_ "from_mesh whose extent overflows" 2 "bad argument #1 to 'from_mesh' (the mesh is too large" \
'local m = wobble.mesh{ vertices = {{-1e200, 0, 0}, {1e200, 0, 0}, {0, 1e200, 0}}, triangles = {{1, 2, 3}} }
wobble.world{}:from_mesh(m)'
case_ "from_mesh neighbours on vertices 5e-324 apart builds" 0 "" \
'local v = {}
for i = 0, 39 do v[#v + 1] = {i * 4.9406564584124654e-324, 0, 0} end
local w = wobble.world{}
w:from_mesh(wobble.mesh{ vertices = v, triangles = {} }, { neighbours = 8 })
w:step()'
case_ "dt = 1e-300" 2 "bad argument #1 to 'world' (dt/substeps is too short" \
'wobble.world{ dt = 1e-300 }'

echo "$passed passed, $failed failed"
[ "$failed" -eq 0 ]
