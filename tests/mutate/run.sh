#!/bin/sh
# tests/mutate/run.sh [ID...]: mutation testing, behind `make mutate`.
#
# Each mutation of tests/mutate/mutations.txt is a small change that looks like a real
# bug (a sed expression over one .c file). One at a time, in a scratch copy of the tree
# (never the user's), the mutation is applied, only its object is rebuilt, and the part
# of the suite that should notice it runs. A mutant whose tests fail is killed; one
# whose tests pass survived: the suite is weaker than it looks there.
#
# Prints a line per mutation, then the kill rate and the survivors. Exit status: 0 when
# at least MUTATE_THRESHOLD percent (default 90) were killed, 1 below it, 2 when the
# harness could not do its job (a mutation that no longer applies because the code
# changed, one that does not compile, or a test subset failing without any mutation).
# With IDs, only those mutations run. MUTATE_JOBS (default 2): make's -j;
# MUTATE_LIST: another list (to check which tests kill what).
set -u
cd "$(dirname "$0")/../.." || exit 2
ROOT=$PWD
LIST=${MUTATE_LIST:-tests/mutate/mutations.txt}
THRESHOLD=${MUTATE_THRESHOLD:-90}
JOBS=${MUTATE_JOBS:-2}
TIMEOUT=${MUTATE_TIMEOUT:-300}
# our makes are not recursive makes of an outer one (see tests/cli/run.sh)
unset MAKEFLAGS MFLAGS MAKELEVEL
TMP=$(mktemp -d "${TMPDIR:-/tmp}/wobble-mutate.XXXXXX") || exit 2
trap 'rm -rf "$TMP"' EXIT
trap 'exit 130' INT TERM
T=$TMP/tree
started=$(date +%s)

# ---- the list: blocks of "mutation ID", "file F", "sed EXPR", "tests T...", "why TEXT"
n=0
while IFS= read -r line || [ -n "$line" ]; do
    line=$(printf '%s' "$line" | sed 's/^[[:space:]]*//')
    key=${line%%[[:space:]]*}
    val=$(printf '%s' "${line#"$key"}" | sed 's/^[[:space:]]*//')
    case $key in
    mutation) n=$((n + 1)); printf '%s\n' "$val" >"$TMP/m$n.id" ;;
    file | sed | tests | why) [ $n -gt 0 ] && printf '%s\n' "$val" >"$TMP/m$n.$key" ;;
    '' | '#'*) ;;
    *) echo "$LIST: unknown line '$line'"; exit 2 ;;
    esac
done <"$LIST"
sel=""
i=1
while [ $i -le $n ]; do
    for f in id file sed tests; do
        [ -s "$TMP/m$i.$f" ] || { echo "$LIST: mutation $i ($(cat "$TMP/m$i.id" 2>/dev/null)) has no '$f'"; exit 2; }
    done
    id=$(cat "$TMP/m$i.id")
    if [ $# -eq 0 ]; then sel="$sel $i"; else
        for want; do [ "$want" = "$id" ] && sel="$sel $i"; done
    fi
    i=$((i + 1))
done
[ -n "$sel" ] || { echo "no mutation selected (ids: see $LIST)"; exit 2; }

# ---- the scratch tree, built once (build folders, out/ and .git are not copied)
mkdir -p "$T"
tar -C "$ROOT" --exclude=./.git --exclude='./build*' --exclude=./out -cf - . | tar -C "$T" -xf - || exit 2
echo "== building a scratch copy of the tree in $T"
if ! make -s -C "$T" -j"$JOBS" build >"$TMP/build.log" 2>&1; then
    cat "$TMP/build.log"
    echo "the unmutated tree does not build"
    exit 2
fi

# run_tests TOKENS...: unit[:NAME,NAME] (the C unit tests, or those named), cli, render,
# a tests/.../NAME.sh script (run as `sh NAME.sh build`), and .lua files or folders for
# `wobble test`. Prints the first token that failed.
run_tests() {
    lua=""
    for tok; do
        case $tok in
        *.sh) ;;
        *.lua | tests/*) lua="$lua $tok" ;;
        esac
    done
    for tok; do
        case $tok in
        unit) cmd="build/unit_tests" ;;
        unit:*) cmd="build/unit_tests $(echo "${tok#unit:}" | tr ',' ' ')" ;;
        cli) cmd="sh tests/cli/run.sh build" ;;
        render) cmd="sh tests/render/run.sh build" ;;
        *.sh) cmd="sh $tok build" ;;
        *.lua | tests/*) continue ;;
        *) echo "unknown test '$tok'"; return 0 ;;
        esac
        # shellcheck disable=SC2086
        (cd "$T" && timeout "$TIMEOUT" $cmd) >"$TMP/test.log" 2>&1 || { echo "$tok"; return 0; }
    done
    if [ -n "$lua" ]; then
        # shellcheck disable=SC2086
        rm -rf "$TMP/out"   # what one mutant wrote must not fail the next one's tests
        (cd "$T" && timeout "$TIMEOUT" build/wobble test --out "$TMP/out" $lua) >"$TMP/test.log" 2>&1 ||
            { first=$(grep -m1 '^not ok' "$TMP/test.log" | sed 's/^not ok [0-9]* - //' | cut -c1-70)
              echo "${first:-wobble test (no 'not ok' line: a crash or a hang)}"; return 0; }
    fi
    return 0
}

# ---- the subsets pass without any mutation (else a "kill" would mean nothing)
all_tests=$(for i in $sel; do tr ' ' '\n' <"$TMP/m$i.tests"; done | grep . | sort -u | tr '\n' ' ')
echo "== the tests the mutations use, unmutated: $all_tests"
# shellcheck disable=SC2086
bad=$(run_tests $all_tests)
if [ -n "$bad" ]; then
    cat "$TMP/test.log"
    echo "the suite fails without any mutation ($bad): fix that first"
    exit 2
fi

# ---- the mutations
killed=0 survived=0 broken=0 survivors=""
printf '== %-28s %-26s %s\n' "mutation" "file" "result"
for i in $sel; do
    id=$(cat "$TMP/m$i.id") file=$(cat "$TMP/m$i.file") tests=$(cat "$TMP/m$i.tests")
    src=$T/$file
    obj=$T/build/obj/${file#src/}
    obj=${obj%.c}.o
    t0=$(date +%s)
    # the command always; the unit tests (all recompiled when libwobble.a changes) when used
    targets=build/wobble
    case " $tests" in *" unit"*) targets="$targets build/unit_tests" ;; esac
    case $file in src/*.c) ;; *) printf '   %-28s %-26s %s\n' "$id" "$file" "BROKEN: not a .c file under src/"; broken=$((broken + 1)); continue ;; esac
    cp -p "$src" "$TMP/orig.c" && cp -p "$obj" "$TMP/orig.o" || exit 2
    sed -e "$(cat "$TMP/m$i.sed")" "$TMP/orig.c" >"$src"
    if cmp -s "$src" "$TMP/orig.c"; then
        result="BROKEN: the sed rule no longer applies (the code changed; update $LIST)"
        broken=$((broken + 1))
    elif ! make -s -C "$T" -j"$JOBS" $targets >"$TMP/build.log" 2>&1; then
        result="BROKEN: the mutant does not compile ($(grep -m1 'error' "$TMP/build.log" | cut -c1-80))"
        broken=$((broken + 1))
    else
        # shellcheck disable=SC2086
        # (stderr: the shell's "Aborted" when a mutant crashes; the logs are in test.log)
        by=$(run_tests $tests 2>/dev/null)
        if [ -n "$by" ]; then
            result="killed by $by"
            killed=$((killed + 1))
        else
            result="SURVIVED ($tests)"
            survived=$((survived + 1))
            survivors="$survivors $i"
        fi
    fi
    # back to the original: its source with its old time, its object as new (so what
    # was linked with the mutant is linked again, and nothing else recompiles)
    cp -p "$TMP/orig.c" "$src"
    cp "$TMP/orig.o" "$obj"
    printf '   %-28s %-26s %s (%ds)\n' "$id" "$file" "$result" $(($(date +%s) - t0))
done

total=$((killed + survived))
rate=0
[ $total -gt 0 ] && rate=$((100 * killed / total))
echo "== $killed of $total mutants killed ($rate%), $survived survived, $broken broken; $(($(date +%s) - started)) s"
for i in $survivors; do
    echo "survivor: $(cat "$TMP/m$i.id") ($(cat "$TMP/m$i.file")): $(cat "$TMP/m$i.why" 2>/dev/null)"
done
[ $broken -eq 0 ] || exit 2
[ $rate -ge "$THRESHOLD" ] || { echo "kill rate $rate% is below $THRESHOLD%"; exit 1; }
exit 0
