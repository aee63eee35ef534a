#!/bin/sh
# tests/layers.sh BUILD_DIR: the layers of DESIGN §1 hold in the built objects.
#   1. arrows point down: cli -> lua -> {render, io} -> core (no file calls a layer
#      above its own, render and io do not call each other)
#   2. no circles between files: the "calls a function of" graph has no loop (tsort)
#   3. the core's headers include nothing from the layers above
# The graph comes from the objects' symbols (nm), so it sees calls, not just includes.
BUILD=${1:-build}
cd "$(dirname "$0")/.." || exit 2
OBJ=$BUILD/obj
pass=0 fail=0
ok() { pass=$((pass + 1)); echo "ok $((pass + fail)) - $1"; }
bad() { fail=$((fail + 1)); echo "not ok $((pass + fail)) - $1"; }
EDGES=$(mktemp "${TMPDIR:-/tmp}/wobble-layers.XXXXXX") || exit 2
trap 'rm -f "$EDGES" "$EDGES.def"' EXIT

# "file symbol" for every global definition, then "user definer" for every use
for o in "$OBJ"/*/*.o; do
    nm --defined-only "$o" | awk -v f="${o#$OBJ/}" '$2 ~ /^[TDBRCV]$/ { print f, $3 }'
done >"$EDGES.def"
if [ ! -s "$EDGES.def" ]; then
    bad "objects found under $OBJ/<layer>/"
    echo "$pass passed, $fail failed"
    exit 1
fi
for o in "$OBJ"/*/*.o; do
    nm -u "$o" | awk -v f="${o#$OBJ/}" '{ print f, $NF }'
done | awk 'NR == FNR { def[$2] = $1; next } ($2 in def) && def[$2] != $1 { print $1, def[$2] }' \
    "$EDGES.def" - | sort -u >"$EDGES"

up=$(awk '
    function rank(f) { sub(/\/.*/, "", f); return f == "core" ? 0 : f == "io" || f == "render" ? 1 : f == "lua" ? 2 : 3 }
    { a = $1; b = $2; la = a; lb = b; sub(/\/.*/, "", la); sub(/\/.*/, "", lb)
      if (rank(a) < rank(b) || (la != lb && rank(a) == rank(b))) print "  # " a " -> " b }' "$EDGES")
if [ -z "$up" ]; then ok "arrows point down ($(wc -l <"$EDGES") calls between files)"
else bad "arrows point down: these call a layer above or beside their own"; echo "$up"; fi

if loops=$(tsort "$EDGES" 2>&1 >/dev/null) && [ -z "$loops" ]; then ok "no circle between files"
else bad "no circle between files"; echo "$loops" | sed 's/^/  # /'; fi

# a header of the core's own folder (core.h, snapshot.h, bvh.h, ...) or wobble.h
inc=$(grep -n '#include "' src/core/*.c src/core/*.h | while IFS= read -r line; do
        h=$(echo "$line" | sed 's/.*#include "\([^"]*\)".*/\1/')
        [ "$h" = wobble.h ] || { [ "${h#*/}" = "$h" ] && [ -e "src/core/$h" ]; } || echo "$line"
      done)
if [ -z "$inc" ]; then ok "the core includes only the core and wobble.h"
else bad "the core includes only the core and wobble.h"; echo "$inc" | sed 's/^/  # /'; fi

echo "$pass passed, $fail failed"
[ "$fail" -eq 0 ]
