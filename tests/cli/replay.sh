#!/bin/sh
# tests/cli/replay.sh BUILD_DIR: input as a test (docs/cli.md, "Replaying input").
#   (a) `wobble run SCENE --replay LOG` = the same grabs done by the script at the same
#       frames: the same w:hash(); a log one frame off gives another hash; worlds are
#       named by the order in which they first finish a frame;
#   (b) the recorder (BUILD_DIR/input_driver, the C API the viewer uses): its saved log
#       replays to the hash of the recorded run (targets that round-trip only with all
#       their digits);
#   (c) errors: bad JSON (file:line:col), unknown keys and types, a bad particle, a
#       released or unknown grab, frames going backwards, a wrong format or version:
#       exit 2 naming the key path; events left unapplied: exit 1; --replay on `test`.
# Fixtures: tests/cli/fixtures/replay_*.lua and tests/cli/fixtures/replay/*.json.
# Last line: "N passed, N failed"; exit status 1 when a check failed.
BUILD=${1:-build}
cd "$(dirname "$0")/../.." || exit 2
W="$BUILD/wobble"
F=tests/cli/fixtures/replay_rope.lua
D=tests/cli/fixtures/replay
TMP=$(mktemp -d "${TMPDIR:-/tmp}/wobble-replay.XXXXXX") || exit 2
trap 'rm -rf "$TMP"' EXIT INT TERM
. tests/cli/lib.sh

run() {
    "$@" >"$TMP/out" 2>"$TMP/err"
    code=$?
}
hash_of() { sed -n 's/^hash \([0-9a-f]*\) .*/\1/p' "$TMP/out"; }
same() { # NAME A B: A and B are equal non-empty hashes
    if [ -n "$2" ] && [ "$2" = "$3" ]; then result "$1" ""; else result "$1" "'$2' against '$3'"; fi
}
differ() {
    if [ -n "$2" ] && [ -n "$3" ] && [ "$2" != "$3" ]; then result "$1" ""; else result "$1" "'$2' against '$3'"; fi
}

# ---- (a) replay = scripted grabs ----
run "$W" run "$F" --quiet --set scripted=true
check "the scene with its own grabs runs" 0
scripted=$(hash_of)
run "$W" run "$F" --quiet
untouched=$(hash_of)
run "$W" run "$F" --quiet --replay "$D/same.json"
check "--replay of the same grabs: exit 0, stderr quiet" 0 !err "wobble"
replayed=$(hash_of)
same "--replay gives the hash of the same grabs done by the script at the same frames" "$scripted" "$replayed"
differ "the grabs change the hash (the scene without them differs)" "$untouched" "$replayed"
run "$W" run "$F" --quiet --replay "$D/off_by_one.json"
check "a log one frame off runs" 0
differ "a move one frame later gives another hash" "$scripted" "$(hash_of)"

run "$W" run tests/cli/fixtures/replay_two.lua --quiet --set scripted=true
two_scripted=$(cat "$TMP/out")
run "$W" run tests/cli/fixtures/replay_two.lua --quiet --replay "$D/two.json"
check "two worlds: the log's world 2 is the second to finish a frame" 0
same "two worlds: both hashes as with the script's grabs" "$two_scripted" "$(cat "$TMP/out")"

# ---- (b) the recorder ----
if [ -x "$BUILD/input_driver" ]; then
    run "$BUILD/input_driver" "$F" "$TMP/log.json"
    check "the recorder logs grab, move, move, release and refuses a bad particle" 0 out "events 4" \
        out "refused: grab: particle 22 out of range (the world has 21)"
    recorded=$(hash_of)
    grep -q '"format":[[:space:]]*"wobble-input"' "$TMP/log.json" && grep -q '1.3333333333333333, 0.30571428571428572' "$TMP/log.json"
    if [ $? -eq 0 ]; then result "the log is a wobble-input file with numbers of 17 digits" ""
    else result "the log is a wobble-input file with numbers of 17 digits" "$(head -c 300 "$TMP/log.json")"; fi
    run "$W" run "$F" --quiet --replay "$TMP/log.json"
    check "the recorded log replays" 0
    same "the replay of a recorded log ends with the recorded run's hash" "$recorded" "$(hash_of)"
    differ "the recorded grabs changed the scene" "$untouched" "$recorded"
else
    result "$BUILD/input_driver is built (make build)" "missing"
fi

# ---- (c) errors ----
run "$W" run "$F" --replay "$D/syntax.json"
check "bad JSON: exit 2 at file:line:col, the scene not run" 2 err "$D/syntax.json:3:63: JSON syntax error" !out "hash"
run "$W" run "$F" --replay "$D/unknown_key.json"
check "an unknown key: exit 2 naming its path" 2 \
    err "$D/unknown_key.json:4:84: events[1].particle: unknown key 'particle' (expected one of: frame, world, type, grab, target)"
run "$W" run "$F" --replay "$D/unknown_type.json"
check "an unknown type: exit 2" 2 err "unknown_type.json:2:50: events[0].type: unknown event type 'poke'"
run "$W" run "$F" --replay "$D/released.json"
check "a move of a released grab: exit 2" 2 err "released.json:5:56: events[2].grab: grab 1 was released by events[1]"
run "$W" run "$F" --replay "$D/unknown_grab.json"
check "a move of an unknown grab: exit 2" 2 err "unknown_grab.json:2:66: events[0].grab: grab 2 does not exist"
run "$W" run "$F" --replay "$D/backwards.json"
check "frames going backwards: exit 2" 2 err "backwards.json:4:16: events[1].frame: frame 9 of world 1 comes after frame 10"
run "$W" run "$F" --replay "$D/version.json"
check "another version: exit 2" 2 err "version.json:1:40: version: version 2 is not supported"
run "$W" run "$F" --replay "$D/format.json"
check "another format: exit 2" 2 err "format.json:1:13: format: 'wobble-particles' is not an input log"
run "$W" run "$F" --replay "$TMP/none.json"
check "a missing file: exit 2" 2 err "none.json: No such file or directory"
run "$W" run "$F" --replay "$D/bad_particle.json"
check "a grab of a particle the world lacks: exit 2 naming the event" 2 \
    err "bad_particle.json:4:60: events[1].particle: particle 22 out of range (world 1 has 21 at frame 12)" \
    err "1 event was not applied, the first events[1] (grab after frame 12 of world 1): it failed"
run "$W" run "$F" --replay "$D/same.json" --frames 40
check "the scene ends before the last event: exit 1, how many and the first one's frame" 1 \
    err "1 event was not applied, the first events[3] (release after frame 45 of world 1): the scene ended before it"
run "$W" run "$F" --replay "$D/world2.json"
check "a world the scene never has: exit 1" 1 \
    err "1 event was not applied, the first events[0] (grab after frame 10 of world 2): world 2 never finished a frame"
run "$W" test tests/cli/fixtures/frames.lua --replay "$D/same.json"
check "--replay is an option of run: a usage error elsewhere" 2 err "--replay is an option of run"
run "$W" run "$F" --replay
check "--replay without a file: a usage error" 2 err "--replay needs a value"

echo "$passed passed, $failed failed"
[ "$failed" -eq 0 ]
