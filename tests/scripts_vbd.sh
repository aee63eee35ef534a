#!/bin/sh
# tests/scripts_vbd.sh BUILD_DIR: the example scenes that check their claim (scripts/*.lua
# with `if test then`) again under the second solver (WOBBLE_SOLVER=vbd: every world that
# names no solver is a VBD world; docs/testing.md). Every such scene runs but those listed
# below, each with its reason; a new scene that checks its claim runs here too unless it
# is added to a list. Last line "N passed, N failed".
BUILD=${1:-build}
cd "$(dirname "$0")/.." || exit 2

# Their claim is about XPBD, not the scene:
#   cloth_clothesline.lua  "the links at the pegs stretch over 1%": XPBD's stretch at one
#                          iteration (its links of compliance 2e-6 stretch 1e-5 under the
#                          cloth's weight); VBD hangs it at 0.2%, so 1.43 m down, not 1.5
#   cloth_tethers.lua      "the other one stretched" (more than 5%): the untethered cloth's
#                          hard links at one pass a substep, XPBD's; VBD holds them, the
#                          cloth hangs its own length (0.45% short, its free edge sagging)
not_vbd="cloth_clothesline.lua cloth_tethers.lua"

# They apply but fail under VBD today (docs/physics.md, "VBD": what it does not serve yet);
# each is a bug of the solver, not of the scene:
#   pairs of two movable particles of one body and its own particle-triangle contacts are
#   projected after the sweeps: a cloth heaped on itself passes through its folds
#   (cloth_heap: 0 pairs of folds in touch); letters pressed flat spring back to 0.32 of
#   their height, not 0.8 (logo_spring; 0.43 before the letters touching each other were
#   moved together):
#     cloth_heap.lua logo_spring.lua
#   a rope wound on a kinematic drum (colliders after the sweeps): a winch loses 15% of
#   its angular momentum (rope_winch):
#     rope_winch.lua
#   a soft block dropped on the ground settles more slowly than under XPBD (whose one
#   iteration damps its wobble too): its height still changes by 0.106% a frame in the
#   last half second of 4 s (block_drop: 0.1% allowed; 0.003% at 5.5 s):
#     block_drop.lua
not_yet="cloth_heap.lua logo_spring.lua rope_winch.lua block_drop.lua"

set --
for f in $(grep -l '^if test then' scripts/*.lua | sort); do
    rel=${f#scripts/}
    skip=0
    for x in $not_vbd $not_yet; do [ "$rel" = "$x" ] && skip=1; done
    [ $skip -eq 0 ] && set -- "$@" "$f"
done
for x in $not_vbd $not_yet; do
    grep -q '^if test then' "scripts/$x" 2>/dev/null ||
        { echo "not ok 1 - tests/scripts_vbd.sh lists $x, which is gone or checks no claim"; echo "0 passed, 1 failed"; exit 1; }
done
TMP=$(mktemp -d "${TMPDIR:-/tmp}/wobble-scripts-vbd.XXXXXX") || exit 2
trap 'rm -rf "$TMP"' EXIT INT TERM
WOBBLE_SOLVER=vbd "$BUILD/wobble" test --quiet --time-limit 600 --out "$TMP/out" "$@"
