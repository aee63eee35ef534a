#!/bin/sh
# tests/render/run.sh BUILD_DIR: `wobble run --record OUT` from outside, one process
# per check: the video's frame count and format (ffprobe), numbered PNG folders, and
# encoders that fail (missing, exiting at once, never reading) giving a clear error
# and exit code 2 instead of a hang. WOBBLE_FFMPEG names the encoder program.
# Last line: "N passed, N failed"; exit status 1 when a check failed.
BUILD=${1:-build}
cd "$(dirname "$0")/../.." || exit 2
W="$BUILD/wobble"
F=tests/render/fixtures
TMP=$(mktemp -d "${TMPDIR:-/tmp}/wobble-render.XXXXXX") || exit 2
trap 'rm -rf "$TMP"' EXIT INT TERM
n=0 passed=0 failed=0

# COND; ok NAME $?: one check, passed when the condition before it held
ok() {
    name=$1
    n=$((n + 1))
    if [ "$2" = 0 ]; then
        passed=$((passed + 1))
        echo "ok $n - $name"
    else
        failed=$((failed + 1))
        echo "not ok $n - $name"
        sed 's/^/  # stderr: /' "$TMP/err" | head -n 10
    fi
}

run() {
    "$@" >"$TMP/out" 2>"$TMP/err"
    code=$?
}

frames() {  # frames of a video, through ffprobe
    ffprobe -v error -count_frames -select_streams v:0 -show_entries stream=nb_read_frames -of csv=p=0 "$1"
}
duration() {   # seconds a player takes for it
    ffprobe -v error -show_entries format=duration -of csv=p=0 "$1"
}
near() {   # near VALUE EXPECTED TOLERANCE
    awk -v v="$1" -v e="$2" -v t="$3" 'BEGIN { d = v - e; exit !(v != "" && d <= t && -d <= t) }'
}
field() {   # one stream field of a video
    ffprobe -v error -select_streams v:0 -show_entries stream="$2" -of csv=p=0 "$1"
}

run "$W" run $F/swing.lua --quiet --record "$TMP/swing.mp4"
[ "$code" = 0 ]; ok "--record .mp4: exit 0" $?
[ "$(frames "$TMP/swing.mp4")" = 15 ]; ok "--record .mp4: 15 frames (w:run and w:step)" $?
[ "$(field "$TMP/swing.mp4" codec_name)" = h264 ] && [ "$(field "$TMP/swing.mp4" pix_fmt)" = yuv420p ] && [ "$(field "$TMP/swing.mp4" width)" = 1280 ] && [ "$(field "$TMP/swing.mp4" height)" = 720 ]; ok "--record .mp4: H.264, yuv420p, 1280x720" $?
[ ! -s "$TMP/err" ]; ok "--record --quiet prints nothing" $?

run "$W" run $F/swing.lua --frames 5 --record "$TMP/swing.gif"
# 8 frames at 60 fps last 0.133 s; a GIF shows them at 50 fps (2 cs a frame): 7 frames, 0.14 s
[ "$code" = 0 ] && [ "$(frames "$TMP/swing.gif")" = 7 ] && near "$(duration "$TMP/swing.gif")" 0.14 0.015; ok "--record .gif with --frames 5: 5 + 3 frames, as long as they last" $?
grep -q "recorded 8 frames to $TMP/swing.gif" "$TMP/err"; ok "--record says where the frames went" $?
[ "$(field "$TMP/swing.gif" width)" = 640 ] && [ "$(field "$TMP/swing.gif" height)" = 360 ]; ok "--record .gif: 640x360 by default (for the web)" $?
run "$W" run $F/swing.lua --quiet --frames 2 --size 480x270 --record "$TMP/sized.gif"
[ "$code" = 0 ] && [ "$(field "$TMP/sized.gif" width)" = 480 ] && [ "$(field "$TMP/sized.gif" height)" = 270 ]; ok "--record .gif --size 480x270: the size asked" $?

run "$W" run $F/swing.lua --quiet --frames 2 --record "$TMP/pngs/"
[ "$code" = 0 ] && [ -s "$TMP/pngs/frame_000000.png" ] && [ -s "$TMP/pngs/frame_000004.png" ] && [ ! -e "$TMP/pngs/frame_000005.png" ]; ok "--record folder/: numbered PNGs" $?

run "$W" run $F/swing.lua --record "$TMP/swing.avi"
[ "$code" = 2 ] && grep -q "unknown extension '.avi'" "$TMP/err"; ok "--record .avi: exit 2, the extension named" $?

run "$W" run $F/swing.lua --quiet --frames 2 --record "$TMP/no/such/dir/x.gif"
[ "$code" = 0 ] && [ "$(frames "$TMP/no/such/dir/x.gif")" -ge 2 ]; ok "--record into a missing folder: the folders are made (as --out does)" $?
: > "$TMP/afile"
run "$W" run $F/swing.lua --record "$TMP/afile/x.mp4"
[ "$code" = 2 ] && grep -q "cannot write $TMP/afile/x.mp4: Not a directory" "$TMP/err" && [ ! -s "$TMP/out" ]; ok "--record under a file: exit 2 before running" $?

run "$W" test tests/scenarios/api_run.lua --record "$TMP/x.mp4"
[ "$code" = 2 ] && grep -q "option of run" "$TMP/err"; ok "--record is an option of run only" $?

run env WOBBLE_FFMPEG=/nonexistent/ffmpeg "$W" run $F/swing.lua --record "$TMP/missing.mp4"
[ "$code" = 2 ] && grep -q "is not installed" "$TMP/err"; ok "missing ffmpeg: exit 2, says so" $?
[ ! -e "$TMP/missing.mp4" ]; ok "missing ffmpeg: no empty file left" $?

run env WOBBLE_FFMPEG=false "$W" run $F/swing.lua --record "$TMP/false.mp4"
[ "$code" = 2 ] && grep -q "exited with status 1" "$TMP/err"; ok "an encoder that exits at once: exit 2, its status named" $?

start=$(date +%s)
run env WOBBLE_FFMPEG="$PWD/$F/stall.sh" WOBBLE_ENCODER_TIMEOUT=1 timeout 60 "$W" run $F/swing.lua --record "$TMP/stall.mp4"
took=$(( $(date +%s) - start ))
[ "$code" = 2 ] && grep -q "took no frame" "$TMP/err" && [ "$took" -lt 30 ]; ok "an encoder that never reads: stopped after the timeout, exit 2 (took ${took}s)" $?

# files that were there before are never deleted by a failed write or recording
mkdir -p "$TMP/keep"
echo precious >"$TMP/keep/old.png"
# a file size limit of 2 KB: the PNG write fails part way (SIGXFSZ ignored: EFBIG)
run sh -c 'trap "" XFSZ; ulimit -f 4; exec "$@"' sh "$W" run $F/save_png.lua --quiet --out "$TMP/keep"
[ "$code" = 2 ] && grep -q "cannot write .*old.png" "$TMP/err"; ok "a PNG write that fails part way: exit 2, the file named" $?
[ "$(cat "$TMP/keep/old.png")" = precious ] && [ "$(ls -A "$TMP/keep" | grep -vx result.json)" = old.png ]; ok "... the old file is intact and nothing else is left" $?
run "$W" run $F/save_png.lua --quiet --out "$TMP/keep"
[ "$code" = 0 ] && [ "$(head -c 4 "$TMP/keep/old.png" | tail -c 3)" = PNG ] && [ "$(ls -A "$TMP/keep" | grep -vx result.json)" = old.png ]; ok "the same write without the limit replaces it" $?

echo precious >"$TMP/keep/old.mp4"
run env WOBBLE_FFMPEG=/nonexistent/ffmpeg "$W" run $F/swing.lua --record "$TMP/keep/old.mp4"
[ "$code" = 2 ] && [ "$(cat "$TMP/keep/old.mp4")" = precious ]; ok "a recording that fails before its first frame leaves an existing file alone" $?
printf 'local w = wobble.world{}\n' >"$TMP/nostep.lua"
run "$W" run "$TMP/nostep.lua" --record "$TMP/keep/old.mp4"
[ "$code" = 0 ] && [ "$(cat "$TMP/keep/old.mp4")" = precious ] && grep -q "nothing written" "$TMP/err"; ok "a scene that steps no frame leaves an existing file alone" $?
run "$W" run "$TMP/nostep.lua" --record "$TMP/keep/new.mp4"
[ "$code" = 0 ] && [ ! -e "$TMP/keep/new.mp4" ]; ok "... and removes the empty file it made" $?

# the encoder gets no descriptor of the script's (fds.sh fails when it sees held.txt)
run env WOBBLE_FFMPEG="$PWD/$F/fds.sh" "$W" run $F/record.lua --quiet --out "$TMP/fds"
[ "$code" = 0 ]; ok "the encoder does not inherit the script's open files" $?

# the format comes from the name the script gave, not from where a symlink leads
mkdir -p "$TMP/link/data" && : >"$TMP/link/data/clip" && ln -s data/clip "$TMP/link/v.mp4"
run "$W" run $F/record.lua --quiet --out "$TMP/link" --set name=v.mp4
[ "$code" = 0 ] && [ "$(field "$TMP/link/data/clip" codec_name)" = h264 ] && [ "$(frames "$TMP/link/data/clip")" = 3 ]; ok "r:record(v.mp4), a symlink to a file without extension: an MP4" $?

# --record draws with the scene's camera (wobble.camera): its frame is the one the scene
# draws itself with that camera, byte for byte, and not the automatic framing's
run "$W" run $F/camera.lua --quiet --out "$TMP/cam" --set own=1 --record "$TMP/camrec/"
[ "$code" = 0 ] && cmp -s "$TMP/cam/own.png" "$TMP/camrec/frame_000002.png"; ok "--record uses the scene's camera (wobble.camera)" $?
# ... and its antialiasing: one sample and FXAA unless --samples N asks for N samples
run "$W" run $F/camera.lua --quiet --out "$TMP/cam4" --set own=1 --set samples=4 --samples 4 --record "$TMP/camrec4/"
[ "$code" = 0 ] && cmp -s "$TMP/cam4/own.png" "$TMP/camrec4/frame_000002.png" && ! cmp -s "$TMP/camrec4/frame_000002.png" "$TMP/camrec/frame_000002.png"; ok "--record --samples 4: 4x multisampling, as wobble.renderer{samples = 4}" $?
run "$W" run $F/camera.lua --quiet --out "$TMP/cam1" --samples 1 --record "$TMP/camrec1/"
[ "$code" = 0 ] && ! cmp -s "$TMP/camrec1/frame_000002.png" "$TMP/camrec/frame_000002.png"; ok "--record --samples 1: no FXAA (the default's frame differs)" $?
run "$W" run $F/camera.lua --samples 4
[ "$code" = 2 ] && grep -q "give --record OUT too" "$TMP/err"; ok "--samples without --record: exit 2" $?
run "$W" run $F/camera.lua --samples 0 --record "$TMP/x0/"
[ "$code" = 2 ] && grep -q "from 1 to 16" "$TMP/err"; ok "--samples 0: exit 2, the range said" $?
run "$W" run $F/camera.lua --quiet --out "$TMP/cam2" --set auto=1 --record "$TMP/camauto/"
[ "$code" = 0 ] && [ -s "$TMP/camauto/frame_000002.png" ] && ! cmp -s "$TMP/camauto/frame_000002.png" "$TMP/camrec/frame_000002.png"; ok "... and the automatic framing when the scene sets none" $?
# MP4 colours: converted with the BT.709 matrix in limited range and tagged so. A player
# reads an HD video as BT.709 (untagged too): the frame decoded so matches what was drawn
# (the untagged BT.601 conversion before: 8.1 levels off on the strain's reds; now 2.3)
run "$W" run $F/colour.lua --quiet --out "$TMP/col"
[ "$code" = 0 ] && [ "$(field "$TMP/col/c.mp4" color_space,color_primaries,color_transfer,color_range)" = "tv,bt709,bt709,bt709" ]
ok "--record .mp4: tagged BT.709 (matrix, primaries, transfer), limited range" $?
ffmpeg -v error -nostdin -y -i "$TMP/col/c.mp4" -vf "select=eq(n\\,2),scale=in_color_matrix=bt709:in_range=tv" \
    -frames:v 1 "$TMP/col/as709.png" 2>"$TMP/err"
run "$W" run $F/colour.lua --out "$TMP/col" --set with=as709.png
e=$(sed -n 's/^colour error \([0-9.]*\) over \([0-9]*\) pixels$/\1 \2/p' "$TMP/out")
[ "$code" = 0 ] && [ -n "$e" ] && echo "$e" | awk '{ exit !($1 < 4 && $2 > 1000) }'
ok "--record .mp4 read as BT.709: the strain's reds within 4 levels of the drawn frame ($e)" $?

# the renderer's buffers count against --memory-limit
run "$W" run $F/big.lua --memory-limit 64
[ "$code" = 3 ] && grep -q "4096x4096 renderer needs about .* MB, over the memory budget of 64 MB" "$TMP/err"; ok "a renderer too large for --memory-limit: exit 3, says why" $?
run "$W" run $F/big.lua --memory-limit 64 --set width=320 --set height=240
[ "$code" = 0 ]; ok "a small one fits" $?

echo "$passed passed, $failed failed"
[ "$failed" -eq 0 ]
