#!/bin/sh
# tests/cli/bench.sh BUILD_DIR: `wobble bench` on a tiny configuration: --json
# prints one strict JSON object per scene with the figures of the benchmark
# (tests/cli/fixtures/bench_json_check.lua validates them), --set scenes picks scenes,
# --frames N runs N frames; memory per particle is measured where /proc can be read; the
# Bullet peer's figures become the ratio, and a peer that fails or builds another scene
# stops the benchmark. The peers here are stand-in scripts: no Bullet is needed, and
# no timing is checked. Last line "N passed, N failed".
BUILD=${1:-build}
cd "$(dirname "$0")/../.." || exit 2
W="$BUILD/wobble"
CHECK=tests/cli/fixtures/bench_json_check.lua
TMP=$(mktemp -d "${TMPDIR:-/tmp}/wobble-bench.XXXXXX") || exit 2
trap 'rm -rf "$TMP"' EXIT INT TERM
. tests/cli/lib.sh

# validate FILE SCENES FRAMES [more --set]: the checker's verdict on FILE into $TMP/out
validate() {
    f=$1 s=$2 fr=$3
    shift 3
    mkdir -p "$TMP/chk" && cp "$f" "$TMP/chk/rows.json"   # the sandbox reads under --out
    "$W" run "$CHECK" --quiet --out "$TMP/chk" --set file="$TMP/chk/rows.json" --set scenes="$s" --set frames="$fr" "$@" \
        >"$TMP/out" 2>"$TMP/err"
    code=$?
}

# ---- --json, two scenes of two files, 3 frames
"$W" bench --json --set scenes=cloth32,tets --frames 3 --quiet --time-limit 300 --out "$TMP/b" \
    >"$TMP/bench.out" 2>"$TMP/bench.err"
rc=$?
validate "$TMP/bench.out" cloth32,tets 3
[ $rc -eq 0 ] || code="bench exit code $rc"
check "bench --json --set scenes=cloth32,tets --frames 3: two strict JSON rows with the benchmark's keys" 0 \
    out "scene cloth32" out "scene tets" out "rows 2"
[ -s "$TMP/bench.err" ] && code="stderr: $(head -c 300 "$TMP/bench.err")"
check "bench --json writes nothing on stderr" 0

# the checker itself refuses what is not JSON, a missing key and a wrong frame count
printf '{"scene": "cloth32", "particles": 1024,}\n' >"$TMP/bad.json"
validate "$TMP/bad.json" cloth32 3
check "the checker refuses a trailing comma" 2 err "is not JSON"
sed 's/"ns_per_projection": [^,]*, //' "$TMP/bench.out" >"$TMP/bad.json"
validate "$TMP/bad.json" cloth32,tets 3
check "the checker refuses a row without ns_per_projection" 2 err "has no key ns_per_projection"
validate "$TMP/bench.out" cloth32,tets 4
check "the checker sees the frame count" 2 err "frames = 3"

# ---- memory per particle: measured with --unsafe (/proc/self/status), null without
"$W" bench --json --unsafe --set scenes=scale64 --frames 2 --quiet --time-limit 300 --out "$TMP/b" \
    >"$TMP/mem.out" 2>"$TMP/err"
rc=$?
validate "$TMP/mem.out" scale64 2 --set memory=1
[ $rc -eq 0 ] || code="bench exit code $rc"
check "bench --unsafe measures bytes per particle" 0 out "rows 1"
grep -q '"bytes_per_particle": null' "$TMP/bench.out"
code=$?
check "without --unsafe bytes per particle is null, not a made-up figure" 0

# ---- the Bullet peer: its ms per frame over wobble's is the ratio, in JSON and in the table
cat >"$TMP/peer" <<'SH'
#!/bin/sh
# a stand-in Bullet peer: 1000 ms per frame, the sheet asked for (n=N among the arguments)
n=0
for a; do case $a in n=*) n=${a#n=} ;; esac; done
echo "{\"engine\": \"bullet\", \"particles\": $((n * n)), \"links\": 7, \"ms_per_frame\": 1000, \"ns_per_projection\": 5, \"bytes_per_particle\": 64}"
echo "$*" >>"$(dirname "$0")/peer.log"
SH
chmod +x "$TMP/peer"
"$W" bench --json --unsafe --set scenes=cloth32 --frames 2 --set bullet="$TMP/peer" --quiet --out "$TMP/b" \
    >"$TMP/peer.out" 2>"$TMP/err"
rc=$?
validate "$TMP/peer.out" cloth32 2
[ $rc -eq 0 ] || code="bench exit code $rc"
grep -q '"bullet_ms_per_frame": 1000,' "$TMP/peer.out" || code="$code (no bullet_ms_per_frame 1000)"
ratio=$(sed -n 's/.*"bullet_ratio": \([^,}]*\).*/\1/p' "$TMP/peer.out")
ms=$(sed -n 's/.*"ms_per_frame": \([^,}]*\).*/\1/p' "$TMP/peer.out")
awk -v r="$ratio" -v m="$ms" 'BEGIN { exit !(r > 0 && (r * m - 1000) ^ 2 < 1e-3 * 1000 ^ 2) }' ||
    code="$code (ratio $ratio is not 1000 ms / $ms ms)"
check "bench --set bullet=PEER: the ratio is the peer's ms per frame over wobble's" 0 out "rows 1"
grep -q "n=32 frames=2 substeps=10 iterations=1 " "$TMP/peer.log"
code=$?
check "the peer is asked for the same scene: n, frames, substeps, iterations" 0
"$W" bench --unsafe --set scenes=cloth32 --frames 2 --set bullet="$TMP/peer" --quiet --out "$TMP/b" \
    >"$TMP/out" 2>"$TMP/err"
code=$?
check "the table shows Bullet's ms per frame" 0 out "1000.000" out "bullet ms" out "ratio"

# a peer that fails, one that builds another sheet, and a peer without --unsafe: errors
printf '#!/bin/sh\necho "the sheet blew up" >&2\nexit 3\n' >"$TMP/fail"
chmod +x "$TMP/fail"
"$W" bench --unsafe --set scenes=cloth32 --frames 2 --set bullet="$TMP/fail" --quiet --out "$TMP/b" \
    >"$TMP/out" 2>"$TMP/err"
code=$?
check "a Bullet peer that fails stops the benchmark" 2 err "the Bullet peer failed"
printf '#!/bin/sh\necho "{\\"particles\\": 5, \\"ms_per_frame\\": 1}"\n' >"$TMP/other"
chmod +x "$TMP/other"
"$W" bench --unsafe --set scenes=cloth32 --frames 2 --set bullet="$TMP/other" --quiet --out "$TMP/b" \
    >"$TMP/out" 2>"$TMP/err"
code=$?
check "a Bullet peer that made another sheet stops the benchmark" 2 err "the Bullet peer made 5 particles, not 1024"
"$W" bench --set scenes=cloth32 --frames 2 --set bullet="$TMP/peer" --quiet --out "$TMP/b" >"$TMP/out" 2>"$TMP/err"
code=$?
check "the Bullet peer without --unsafe is refused, not skipped" 2 err "needs --unsafe"

# ---- the bending scene: the 128x128 cloth with its 48,133 bends, ns per bend projection
# measured (the solver with the bends less without them); --set bends=0: none, null
"$W" bench --json --set scenes=bend --frames 2 --quiet --time-limit 300 --out "$TMP/b" >"$TMP/bend.out" 2>"$TMP/err"
rc=$?
validate "$TMP/bend.out" bend 2
[ $rc -eq 0 ] || code="bench exit code $rc"
grep -q '"bends": 48133,' "$TMP/bend.out" || code="$code (no \"bends\": 48133)"
grep -q '"constraints": 96774,' "$TMP/bend.out" || code="$code (constraints are not links + bends)"
grep -q '"ns_per_bend": -*[0-9]' "$TMP/bend.out" || code="$code (ns_per_bend not measured)"
check "bench --set scenes=bend: one row, 48,133 bends, ns per bend projection measured" 0 out "scene bend" out "rows 1"
"$W" bench --json --set scenes=bend --set bends=0 --frames 2 --quiet --time-limit 300 --out "$TMP/b" \
    >"$TMP/bend0.out" 2>"$TMP/err"
rc=$?
validate "$TMP/bend0.out" bend 2
[ $rc -eq 0 ] || code="bench exit code $rc"
grep -q '"bends": 0,.*"ns_per_bend": null' "$TMP/bend0.out" || code="$code (bends=0: ns_per_bend is not null)"
check "bench --set scenes=bend --set bends=0: no bends, ns per bend null" 0 out "rows 1"

echo "$passed passed, $failed failed"
