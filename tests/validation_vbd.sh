#!/bin/sh
# tests/validation_vbd.sh BUILD_DIR: the validation tests again under the second solver
# (WOBBLE_SOLVER=vbd: every world that names no solver is a VBD world; docs/testing.md).
# Every file of tests/validation runs but those listed below, each with its reason; a new
# validation test runs here too unless it is added to a list. Last line "N passed, N failed".
BUILD=${1:-build}
cd "$(dirname "$0")/.." || exit 2

# They do not apply to VBD:
#   neo_stiff.lua      the warning that a tet is too stiff for its substep is XPBD's (a wave
#                      faster than one substep); VBD is stable there and warns nothing
#   residual.lua       XPBD's residual, |C + alpha~ lambda| by type, and its projection count;
#                      VBD's residual is its last sweep's largest step (vbd.lua checks it)
#   materials.lua      its foam's ringing (zeta 0.8 of Kelvin-Voigt's) is XPBD's one-iteration
#                      figure: XPBD at 20 iterations rings down in fewer than 3 peaks too
#                      (VBD 0.54, 3x Kelvin-Voigt); the rest of the file holds under VBD
not_vbd="neo_stiff.lua residual.lua materials.lua"

# They apply but fail under VBD today (docs/physics.md, "VBD": what it does not serve yet);
# each is a bug of the solver, not of the test:
#   free bodies touching each other's movable particles or hull triangles are moved
#   together, each rigidly (a translation and a turn), with their contacts and friction
#   (vbd_contact.c, wb__vbdc_couple), but a body touching a rigid body (w:rigid) or made
#   deep inside another is not moved: its translation is its sweeps' start's (a rigid box
#   dropped on a soft block spins: symmetric_drop 0.33 and 4.1 rad/s, user/10 2.4 rad/s;
#   a box falling on a cloth trampoline leaves it, rigid_particle); a lone block under a
#   kinematic press (a free body's collider contacts are projected after the sweeps)
#   drifts sideways once released (user/14: 0.28 m), a stiff one runs at 8 m/s (squeeze;
#   in the vertex steps, user/14 passed but a hand-built cloth dropped on a sphere slid
#   off it or blew up: vbd_contact.c's gather_colliders); blocks made stacked
#   1 contact distance
#   deep part too fast (made_stack: 1.7 m/s with friction, 8.1 without) and two made at
#   ground level, the upper 5 cm into the lower, do not come to rest (made_overlapping:
#   0.85 J after 4 s); shape matching is projected after each sweep, so at 4 iterations
#   it sags 11.65 where the test allows 0.049 (its spring of 2 g / kappa at 1 iteration,
#   shape_match):
#     made_overlapping.lua made_stack.lua
#     symmetric_drop.lua user/10_rigid_on_soft.lua
#     user/14_elastic_release_symmetry.lua rigid_particle.lua squeeze.lua shape_match.lua
#   penetration.lua: its rotated box's "something rests on it" (the contacts of the last
#     step) is chance: its lattice slides off as under XPBD, and of the rain 0 particles
#     stay at the defaults, 1-4 at 8 or 12 substeps or 2 iterations (XPBD 2-7); its other
#     tests pass
#   cloth falling on itself: a held body's self-contacts and collider contacts are in the
#   vertex steps, a free body's are still projected after the sweeps, which fight them.
#   A link touching a fold no longer gains energy (its multiplier halved each substep
#   there: heap_energy.lua), so the scripted fold lies in two layers and the drop on a
#   sphere keeps its pairs past 0.9 of their contact distance, but a free cloth dropped
#   in folds heaps without coming to rest (rms 0.37 m/s over its last 2 s against 0.057;
#   the 64 x 64 one stays 0.80 m high); on the sphere 211 particles reach the floor
#   where 230 should, the finer cloth's pairs come to 0.78 of their contact distance;
#   contact_triangles.lua: point-triangle contacts are projected after the sweeps, and
#   a coarse cloth folded onto itself passes through its sheet with 4 particles; its 5
#   other tests pass):
#     cloth_sphere_drop.lua self_collision.lua contact_triangles.lua
#   a cloth folded onto itself by grabs (fold_grabbed): it no longer blows up as its flap
#   comes down (3.55 J gained while the hand held still; kinetic energy 0.016 J to 3.45 J
#   in 3 frames), but its last columns, laid by the hand at the lower layer's very edge,
#   are caught under the held edge where the projection after the sweeps holds them
#   against the links' multipliers, which grow: links 77% long, a pair at 0.835 of its
#   contact distance, 0.09 J gained while the hand holds still, 1.35 J after the release:
#     fold_grabbed.lua
not_yet="made_overlapping.lua made_stack.lua symmetric_drop.lua user/10_rigid_on_soft.lua
user/14_elastic_release_symmetry.lua rigid_particle.lua squeeze.lua shape_match.lua penetration.lua cloth_sphere_drop.lua self_collision.lua contact_triangles.lua
fold_grabbed.lua"

set --
for f in $(find tests/validation -name '*.lua' | sort); do
    rel=${f#tests/validation/}
    skip=0
    for x in $not_vbd $not_yet; do [ "$rel" = "$x" ] && skip=1; done
    [ $skip -eq 0 ] && set -- "$@" "$f"
done
for x in $not_vbd $not_yet; do
    [ -f "tests/validation/$x" ] || { echo "not ok 1 - tests/validation_vbd.sh lists $x, which is gone"; echo "0 passed, 1 failed"; exit 1; }
done
TMP=$(mktemp -d "${TMPDIR:-/tmp}/wobble-vbd.XXXXXX") || exit 2
trap 'rm -rf "$TMP"' EXIT INT TERM
# the switch itself: a world that names no solver is a VBD world, one that names one keeps it
printf 'print(wobble.world{}:solver(), wobble.world{solver = "jacobi"}:solver())\n' >"$TMP/switch.lua"
got=$(WOBBLE_SOLVER=vbd "$BUILD/wobble" run "$TMP/switch.lua" --quiet --out "$TMP/out" 2>&1)
if [ "$got" != "$(printf 'vbd\tjacobi')" ]; then
    echo "not ok 1 - WOBBLE_SOLVER=vbd makes worlds that name no solver VBD worlds (got: $got)"
    echo "0 passed, 1 failed"
    exit 1
fi
WOBBLE_SOLVER=vbd "$BUILD/wobble" test --out "$TMP/out" "$@"
