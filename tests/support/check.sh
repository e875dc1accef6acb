# check.sh — the check kit of the shell tests (sourced; bash): failures counted, commands run with
# their output captured. The sourcing script sets TMP (a scratch folder; fresh_tmp sets and empties
# it) before it calls run, and ends with its own summary on $fails (a non-zero exit when fails > 0;
# 77 when it skipped parts that need ../shared/testdata).
#   fail MESSAGE...          prints "FAIL: MESSAGE" on stderr and counts it in $fails
#   run NAME CMD...          runs CMD, stdout and stderr to $TMP/NAME.out and $TMP/NAME.err; sets $rc
#   run_ok LABEL NAME CMD... run, then a failure naming LABEL, the status and stderr unless CMD succeeded
#   usage_error LABEL EXPECT CMD...  run (as $TMP/usage.*), then a failure naming LABEL unless CMD
#                            refused its usage: status 2 and EXPECT (a fixed string) on stderr
#   fresh_tmp DIR            TMP=DIR, the scratch folder, removed and made again empty: a test's start
#   exr_same MESSAGE A B     a failure with MESSAGE unless $EXR_EQUAL (tests/support/exr_equal) finds
#                            the EXR files A and B equal; exr_differ MESSAGE A B: unless it finds them
#                            different
fails=0

fail() {
    echo "FAIL: $*" >&2
    fails=$((fails + 1))
}

run() {
    local name=$1
    shift
    "$@" >"$TMP/$name.out" 2>"$TMP/$name.err"
    rc=$?
}

run_ok() {
    local label=$1
    shift
    run "$@"
    if [ "$rc" -ne 0 ]; then fail "$label: status $rc: $(cat "$TMP/$1.err")"; fi
}

usage_error() {
    local label=$1 expect=$2
    shift 2
    run usage "$@"
    if [ "$rc" -ne 2 ] || ! grep -qF -- "$expect" "$TMP/usage.err"; then
        fail "$label: status $rc (want 2), stderr: $(cat "$TMP/usage.err")"
    fi
}

fresh_tmp() {
    TMP=$1
    rm -rf "$TMP"
    mkdir -p "$TMP"
}

exr_same() {
    if ! "$EXR_EQUAL" "$2" "$3" >/dev/null 2>&1; then fail "$1"; fi
}

exr_differ() {
    if "$EXR_EQUAL" "$2" "$3" >/dev/null 2>&1; then fail "$1"; fi
}
