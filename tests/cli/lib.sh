# tests/cli/lib.sh: the TAP helpers the command-line test scripts share (sourced).
# The sourcing script sets TMP (a scratch folder; the last run's stdout and stderr in
# $TMP/out and $TMP/err) and counts in n, passed and failed, and ends with
#   echo "$passed passed, $failed failed"
# OUT_FILE / ERR_FILE, when set, are where a failed run's output is shown from instead.
# MAX_SECS, when set, is the longest a run may take ($secs, set by the script's runner).

n=0 passed=0 failed=0

# result NAME WHY: one TAP line; WHY empty means passed, else it and the run's output
# are shown as TAP comments
result() {
    n=$((n + 1))
    if [ -z "$2" ]; then
        passed=$((passed + 1))
        echo "ok $n - $1"
    else
        failed=$((failed + 1))
        echo "not ok $n - $1"
        echo "  # $2"
        head -n 15 "${OUT_FILE:-$TMP/out}" 2>/dev/null | sed 's/^/  # stdout: /'
        head -n 15 "${ERR_FILE:-$TMP/err}" 2>/dev/null | sed 's/^/  # stderr: /'
    fi
}

# check NAME CODE [STREAM TEXT]...: the exit code of the last run is CODE and each
# STREAM (out, err) contains TEXT; a STREAM written !out / !err must not contain it
# ("!err ''": stderr empty); STREAM "none" names a file that must not exist
check() {
    name=$1 want=$2
    shift 2
    why=""
    [ "$code" = "$want" ] || why="exit code $code, expected $want"
    [ -z "${MAX_SECS:-}" ] || [ "$secs" -le "$MAX_SECS" ] || why="${why:+$why; }took $secs s"
    while [ $# -ge 2 ]; do
        case $1 in
        none) if [ -e "$2" ]; then why="${why:+$why; }$2 was created"; fi ;;
        !*) if grep -qF -- "$2" "$TMP/${1#!}"; then why="${why:+$why; }${1#!} has '$2'"; fi ;;
        *) if ! grep -qF -- "$2" "$TMP/$1"; then why="${why:+$why; }$1 lacks '$2'"; fi ;;
        esac
        shift 2
    done
    result "$name" "$why"
}
