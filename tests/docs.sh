#!/bin/sh
# tests/docs.sh [BUILD_DIR]: the manual (README.md and docs/) holds together.
#   1. README.md stays an entrance: at most 320 lines (the rest belongs in docs/)
#   2. docs/architecture.md names every file under src/: a row "| `name.c` |" in the
#      table under that folder's line ("`src/core/` ..."), or `src/wobble.h` itself
#   3. every relative link of README.md and docs/*.md leads to a file that exists, and
#      a link to a heading (#anchor) of a page leads to a heading of that page
# Needs only sh, awk and git (or find); the build folder is not used.
cd "$(dirname "$0")/.." || exit 2
pass=0 fail=0
ok() { pass=$((pass + 1)); echo "ok $((pass + fail)) - $1"; }
bad() { fail=$((fail + 1)); echo "not ok $((pass + fail)) - $1"; [ -z "$2" ] || printf '%s\n' "$2" | sed 's/^/  # /'; }
TMP=$(mktemp -d "${TMPDIR:-/tmp}/wobble-docs.XXXXXX") || exit 2
trap 'rm -rf "$TMP"' EXIT

# ---- 1. the README's length
lines=$(wc -l <README.md)
if [ "$lines" -le 320 ]; then ok "README.md has $lines lines (at most 320)"
else bad "README.md has $lines lines, more than 320: move the detail to a page of docs/"; fi

# ---- 2. every source file named in docs/architecture.md
if git ls-files src >/dev/null 2>&1 && [ -n "$(git ls-files src)" ]; then
    git ls-files src | sort >"$TMP/src"
else
    find src -type f | sort >"$TMP/src"
fi
# the names the page gives, as src/FOLDER/NAME: a line starting "`src/FOLDER/`" opens a
# folder's table, and each row's first cell "`NAME`" is a file of it
LC_ALL=C awk '
    /^`src\/wobble\.h`/ { print "src/wobble.h" }
    /^`src\/[a-z_]+\/`/ { d = $0; sub(/^`/, "", d); sub(/`.*/, "", d); next }
    /^## / { d = "" }
    d != "" && /^\| `[^`]+` \|/ { n = $0; sub(/^\| `/, "", n); sub(/`.*/, "", n); print d n }
' docs/architecture.md | sort -u >"$TMP/named"
missing=$(comm -23 "$TMP/src" "$TMP/named")
if [ -z "$missing" ]; then ok "docs/architecture.md names all $(wc -l <"$TMP/src") files under src/"
else bad "docs/architecture.md does not name these files under src/ (a row in their folder's table):" "$missing"; fi
gone=$(comm -13 "$TMP/src" "$TMP/named")
if [ -z "$gone" ]; then ok "every file docs/architecture.md names exists"
else bad "docs/architecture.md names files that do not exist:" "$gone"; fi

# ---- 3. relative links
# the anchors of a page: its headings, as GitHub makes them (lower case; spaces to '-';
# anything but letters, digits, '-' and '_' dropped)
anchors() {
    LC_ALL=C awk '/^```/ { code = !code } !code && /^#+ / {
        h = $0; sub(/^#+ /, "", h); h = tolower(h); gsub(/[^a-z0-9 _-]/, "", h); gsub(/ /, "-", h); print h }' "$1"
}
: >"$TMP/broken"
nlinks=0
for page in README.md docs/*.md; do
    dir=$(dirname "$page")
    # every ](target) outside code blocks and code spans, one per line
    LC_ALL=C awk '/^```/ { code = !code; next } !code {
        line = $0; gsub(/`[^`]*`/, "", line)
        while (match(line, /\]\([^)]*\)/)) { print substr(line, RSTART + 2, RLENGTH - 3); line = substr(line, RSTART + RLENGTH) } }' \
        "$page" >"$TMP/links"
    while IFS= read -r target; do
        case $target in http://* | https://* | mailto:*) continue ;; esac
        nlinks=$((nlinks + 1))
        file=${target%%#*}
        anchor=
        case $target in *'#'*) anchor=${target#*#} ;; esac
        if [ -z "$file" ]; then path=$page; else path=$dir/$file; fi
        if [ ! -e "$path" ]; then
            echo "$page: ($target): no file $path" >>"$TMP/broken"
        elif [ -n "$anchor" ]; then
            case $path in
            *.md) anchors "$path" | grep -qxF "$anchor" ||
                echo "$page: ($target): no heading #$anchor in $path" >>"$TMP/broken" ;;
            esac
        fi
    done <"$TMP/links"
done
if [ ! -s "$TMP/broken" ]; then ok "the $nlinks relative links of README.md and docs/ lead to files and headings that exist"
else bad "relative links of README.md and docs/ that lead nowhere:" "$(cat "$TMP/broken")"; fi

echo "$pass passed, $fail failed"
[ "$fail" -eq 0 ]
