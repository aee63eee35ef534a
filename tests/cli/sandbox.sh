#!/bin/sh
# tests/cli/sandbox.sh BUILD_DIR: escapes from the file rules of DESIGN §4 that need a
# process of their own: files made in the current folder, --unsafe, a real precompiled
# chunk (made by string.dump under --unsafe), media that names a file outside the
# allowed folders. The Lua side is in tests/scenarios/sandbox_escapes.lua.
# Every run happens in a scratch folder, so nothing can land in the checkout.
# Last line: "N passed, N failed"; exit status 1 when a check failed.
BUILD=${1:-build}
cd "$(dirname "$0")/../.." || exit 2
case $BUILD in /*) W=$BUILD/wobble ;; *) W=$PWD/$BUILD/wobble ;; esac
TMP=$(mktemp -d "${TMPDIR:-/tmp}/wobble-sandbox.XXXXXX") || exit 2
trap 'rm -rf "$TMP"' EXIT INT TERM
S=$TMP/scene WD=$TMP/work RD=$TMP/read
mkdir -p "$S" "$WD" "$RD" "$TMP/secret"
. tests/cli/lib.sh

# run DIR ARGS...: wobble in folder DIR; stdout in $TMP/out, stderr in $TMP/err, exit code in $code
run() {
    dir=$1
    shift
    (cd "$dir" && "$W" "$@") >"$TMP/out" 2>"$TMP/err"
    code=$?
}



# ---- a number as a file name: refused in both modes, nothing made in the current folder
cat >"$S/number.lua" <<'EOF'
local calls = {
  output = function() io.output(4242); io.write("escaped\n"); io.close() end,
  input = function() io.input(4242); print(io.read("l")) end,
  lines = function() for l in io.lines(4242) do print(l) end end,
  open = function() assert(io.open(4242, "w")):write("escaped\n") end,
  loadfile = function() print(loadfile(4242)) end,
  dofile = function() dofile(4242) end,
}
calls[wobble.args.call]()
EOF
printf 'secret-4242\nprint("secret-4242")\n' >"$RD/4242"
for mode in "" --unsafe; do
    for call in output open; do
        run "$WD" run "$S/number.lua" --set call=$call $mode
        check "io.$call(4242) ${mode:-sandboxed}: refused, no ./4242" 2 \
            err "bad argument #1 to '$call' (file name" none "$WD/4242" none "$WD/out/4242"
    done
    for call in input lines loadfile dofile; do
        run "$RD" run "$S/number.lua" --set call=$call $mode
        check "$call(4242) ${mode:-sandboxed}: refused, ./4242 not read" 2 \
            err "bad argument #1 to '$call' (file name" !out "secret-4242"
    done
done
run "$WD" run "$S/number.lua" --set call=output
check "the message names the script's line" 2 err "number.lua:2: bad argument #1 to 'output' (file name or file handle expected, got number)"

# ---- precompiled chunks in files: refused in the sandbox, run with --unsafe
cat >"$S/dump.lua" <<'EOF'
local f = assert(io.open("chunk.luac", "wb"))
f:write(string.dump(function() return 6 * 7 end))
f:close()
EOF
cat >"$S/bin.lua" <<'EOF'
local how, name = wobble.args.how, wobble.args.name
local r
if how == "loadfile" then r = assert(loadfile(name))()
elseif how == "loadfile_t" then r = assert(loadfile(name, "t"))()
elseif how == "dofile" then r = dofile(name)
else r = require((name:gsub("%.lua$", ""))) end
print("chunk says " .. tostring(r))
EOF
run "$WD" run "$S/dump.lua" --unsafe --out "$TMP/dump"
check "--unsafe: string.dump writes a binary chunk" 0
head -c 5 "$TMP/dump/chunk.luac" 2>/dev/null | od -An -c | grep -q 'L   u   a'
result "the chunk starts with ESC Lua" "$([ $? = 0 ] || echo "no binary chunk in $TMP/dump/chunk.luac")"
cp "$TMP/dump/chunk.luac" "$S/binmod.lua" 2>/dev/null
{ printf '#!/usr/bin/env wobble\n'; cat "$TMP/dump/chunk.luac"; } >"$S/shebangmod.lua" 2>/dev/null
for file in binmod.lua shebangmod.lua; do
    for how in loadfile dofile require; do
        run "$WD" run "$S/bin.lua" --set how=$how --set name=$file
        check "$how of a binary chunk ($file) is refused in the sandbox" 2 \
            err "it is a precompiled (binary) chunk, not allowed in the sandbox (--unsafe allows it)" \
            err "$file" !out "chunk says"
        run "$WD" run "$S/bin.lua" --set how=$how --set name=$file --unsafe
        check "$how of a binary chunk ($file) runs with --unsafe" 0 out "chunk says 42"
    done
done
run "$WD" run "$S/bin.lua" --set how=loadfile_t --set name=binmod.lua --unsafe
check "--unsafe: loadfile(name, 't') still refuses a binary chunk" 2 err "attempt to load a binary chunk (mode is 't')"

# ---- a symbolic link already in the output folder: every writer refuses a link at its
# name that leads nowhere (its target would be made wherever it points) or out of the
# folder, and a recorder's frames replace a link in their folder instead of writing
# through it. Links to nothing ($SEC/made-*) and to a file outside ($SEC/victim-*).
SEC=$TMP/secret
cat >"$S/writers.lua" <<'EOF'
local how, name = wobble.args.how, wobble.args.name
local w = wobble.world{}
local body = w:lattice{ min = {0, 0, 0}, max = {1, 1, 1}, res = {2, 2, 2}, tets = true }
local m = wobble.mesh{ vertices = { {0, 0, 0}, {1, 0, 0}, {0, 1, 0} }, triangles = { {1, 2, 3} } }
local function r() return wobble.renderer{ width = 16, height = 16, backend = "null" } end
local calls = {
  io_w = function() local f = assert(io.open(name, "w")); f:write("x"); f:close() end,
  io_a = function() local f = assert(io.open(name, "a")); f:write("x"); f:close() end,
  io_rw = function() local f = assert(io.open(name, "r+")); f:write("x"); f:close() end,
  io_output = function() io.output(name); io.write("x"); io.close() end,
  save_obj = function() assert(m:save_obj(name)) end,
  save_ply = function() assert(m:save(name)) end,
  save_stl = function() assert(m:save(name)) end,
  skin_obj = function() assert(w:skin(m, body):save_obj(name)) end,
  save_vtp = function() assert(w:save_vtp(name)) end,
  save = function() assert(w:save(name)) end,
  save_tets = function() assert(w:save_tets(name, body)) end,
  pc2 = function() local rec = assert(w:record_pc2(name, { rest = false })); w:step(); assert(rec:close()) end,
  pc2_rest = function() local rec = assert(w:record_pc2(name)); w:step(); assert(rec:close()) end,
  vtk = function() local rec = assert(w:record_vtk(name)); w:run{ frames = 2 }; assert(rec:close()) end,
  save_png = function() local x = r(); x:draw(w); x:save_png(name) end,
  plot = function() w:run{ frames = 2, plot = name } end,
  record = function() local x = r(); x:record(name); for _ = 1, 3 do w:step(); x:draw(w) end; x:stop() end,
}
calls[how]()
print("wrote " .. name)
EOF
# link_case HOW NAME LINK [MUST_REFUSE]: LINK (a path in the output folder) leads to
# nothing, then to a file outside; neither may be written, nor named in a message
link_case() {
    how=$1 name=$2 link=$3 refuse=${4:-yes}
    for kind in made victim; do
        out=$TMP/lk-$how-$kind
        rm -rf "$out" "$SEC/made-$how" "$SEC/victim-$how"
        mkdir -p "$(dirname "$out/$link")"
        [ $kind = victim ] && echo precious >"$SEC/victim-$how"
        ln -s "$SEC/$kind-$how" "$out/$link"
        run "$WD" run "$S/writers.lua" --out "$out" --set how=$how --set name=$name
        why=""
        [ -e "$SEC/made-$how" ] && why="$SEC/made-$how was created"
        [ $kind = victim ] && [ "$(cat "$SEC/victim-$how")" != precious ] && why="$SEC/victim-$how was overwritten"
        grep -q "$SEC" "$TMP/out" "$TMP/err" && why="${why:+$why; }a message names $SEC"
        if [ $refuse = yes ]; then
            grep -q "wrote $name" "$TMP/out" && why="${why:+$why; }the write went through"
            grep -qE "symbolic link to nothing|outside the output folder" "$TMP/err" ||
                why="${why:+$why; }no refusal on stderr"
        else
            grep -q "wrote $name" "$TMP/out" || why="${why:+$why; }the recording failed (exit $code)"
        fi
        result "$how: a link at $link to $([ $kind = made ] && echo nothing || echo a file outside)" "$why"
    done
}
ctl=""  # without a link in the way every one of them writes (so a refusal below is the link's)
for c in io_w:f.txt io_a:f.txt io_rw:f.txt io_output:g.txt save_vtp:f.vtp save:f.json save_obj:m.obj \
         skin_obj:s.obj save_ply:m.ply save_stl:m.stl save_tets:t pc2:c.pc2 pc2_rest:d.pc2 vtk:v \
         save_png:p.png plot:q.png record:v.mp4 record:frames/; do
    run "$WD" run "$S/writers.lua" --out "$TMP/lk-plain" --set how=${c%%:*} --set name=${c#*:}
    grep -q "wrote ${c#*:}" "$TMP/out" || ctl="$ctl ${c%%:*}"
done
result "every writer writes where no link is in the way" "${ctl:+failed:$ctl}"
for how in io_w io_a io_rw io_output save_vtp save; do link_case $how f.txt f.txt; done
link_case save_obj m.obj m.obj
link_case skin_obj s.obj s.obj
link_case save_ply m.ply m.ply
link_case save_stl m.stl m.stl
link_case save_tets t t.node
link_case pc2 c.pc2 c.pc2
link_case pc2_rest c.pc2 c.obj
link_case vtk v v.pvd
link_case vtk v v/frame_000001.vtp no
link_case save_png p.png p.png
link_case plot p.png p.png
link_case record v.mp4 v.mp4
link_case record frames/ frames/frame_000002.png no
run "$WD" run "$S/writers.lua" --set how=io_w --set name="$SEC/x/../escape.txt"
check "a refusal names the path as the script gave it, not where it resolves" 2 \
    err "writing $SEC/x/../escape.txt is outside the output folder out;" !err "$SEC/escape.txt"
mkdir -p "$WD/out" && ln -s "$SEC/made-dangling" "$WD/out/dl"
run "$WD" run "$S/writers.lua" --set how=io_w --set name=dl
check "... and so does the refusal of a link to nothing" 2 \
    err "writing dl goes through a symbolic link to nothing" !err "made-dangling" none "$SEC/made-dangling"
printf 'assert(os.remove("dl"))\nprint("removed")\n' >"$S/unlink.lua"
run "$WD" run "$S/unlink.lua"
check "os.remove of a link removes the link, not what it names" 0 out removed
result "... the link is gone" "$([ -L "$WD/out/dl" ] && echo "still there")"
rm -rf "$WD/out"

# ---- media naming other files: an HLS playlist (called .mp4) that plays a video kept
# outside the allowed folders; refused in both modes (ffmpeg is not the sandbox's to lift)
if ffmpeg -v error -y -f lavfi -i color=red:s=32x32:d=0.2 -pix_fmt yuv420p "$TMP/secret/s.mp4" </dev/null; then
    cat >"$S/hls.lua" <<'EOF'
local f = assert(io.open("evil.mp4", "w"))
f:write("#EXTM3U\n#EXT-X-TARGETDURATION:1\n#EXTINF:1,\n" .. wobble.args.secret .. "\n#EXT-X-ENDLIST\n")
f:close()
local w, err = wobble.read_frame("evil.mp4")
print(w and "LEAK read_frame " .. w or "refused: " .. err)
local p, perr = wobble.probe("evil.mp4")
print(p and "LEAK probe " .. p.width or "refused: " .. perr)
print(wobble.read_frame(wobble.args.secret))
EOF
    run "$WD" run "$S/hls.lua" --set secret="$TMP/secret/s.mp4"
    check "an HLS playlist naming a video outside is refused (the video itself too)" 2 \
        out "evil.mp4 is not a media file wobble reads (an HLS playlist)" !out "LEAK" \
        err "hls.lua:8: reading $TMP/secret/s.mp4 is outside the allowed folders"
    run "$WD" run "$S/hls.lua" --set secret="$TMP/secret/s.mp4" --unsafe
    check "--unsafe: the playlist is still refused, the video itself reads" 0 \
        out "evil.mp4 is not a media file wobble reads (an HLS playlist)" !out "LEAK" out "32	32	"
else
    result "ffmpeg makes a test video" "ffmpeg failed"
fi

echo "$passed passed, $failed failed"
[ "$failed" -eq 0 ]
