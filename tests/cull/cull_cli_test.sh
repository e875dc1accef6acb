#!/usr/bin/env bash
# cull_cli_test.sh SY TMPDIR — `sy bench cull` (ctest cull_cli):
#   - --write: a 100-object plant written as GLB reads back with `sy info` (100 nodes, each shared
#     mesh once: the count the generator printed)
#   - a small run (raster built): exit 0, the plant measured through a .glb (the user's path), one
#     row per view, an IoU line whose median lies in 0..1, drawn triangles within the budget (the
#     budget cut is checked by test_cull; no timing checks)
#   - bad values name their option and exit 2
# SY_TEST_PARTS names the parts this build has; without raster the run is skipped, saying so.
set -u
SY=$1
TMP=$2
fails=0
rm -rf "$TMP" && mkdir -p "$TMP"
fail() { echo "FAIL: $*" >&2; fails=$((fails + 1)); }

out=$("$SY" bench cull --tris 20000 --objects 100 --write "$TMP/plant.glb" 2>"$TMP/write.err")
[ $? -eq 0 ] || fail "--write: status $?: $(cat "$TMP/write.err")"
meshes=$(printf '%s\n' "$out" | sed -n 's/.*plant of 100 objects, [0-9]* triangles (\([0-9]*\) shared meshes.*/\1/p')
info=$("$SY" info "$TMP/plant.glb" 2>&1)
printf '%s\n' "$info" | grep -q '"nodes": 100,' || fail "sy info: not 100 nodes: $info"
[ -n "$meshes" ] && printf '%s\n' "$info" | grep -q "\"meshes\": $meshes," || fail "sy info: not $meshes meshes (shared in the file too): $info"

if [[ " ${SY_TEST_PARTS:-} " == *" raster "* ]]; then
    out=$("$SY" bench cull --tris 20000 --objects 100 --budget 3000 --frames 3 -w 64 -h 36 2>"$TMP/run.err")
    rc=$?
    [ $rc -eq 0 ] || fail "bench cull: status $rc: $(cat "$TMP/run.err")"
    rows=$(printf '%s\n' "$out" | grep -cE '^ +[0-9]+ +[0-9]+ +[0-9]+ +[0-9]+ +[0-9]+ +[01]\.[0-9]{4} ')
    [ "$rows" -eq 3 ] || fail "bench cull: $rows view rows, expected 3: $out"
    printf '%s\n' "$out" | grep -q '^written to a .glb and loaded by sy_cli_load in [0-9.]* s' ||
        fail "bench cull: the plant did not go through a .glb: $out"
    med=$(printf '%s\n' "$out" | sed -n 's/^coverage IoU.*median \([0-9.]*\).*/\1/p')
    awk -v m="${med:-x}" 'BEGIN { exit !(m ~ /^[0-9.]+$/ && m >= 0 && m <= 1) }' || fail "bench cull: IoU median '$med'"
    drawn=$(printf '%s\n' "$out" | sed -n 's/^triangles drawn by the client: max \([0-9]*\),.*/\1/p')
    [ -n "$drawn" ] && [ "$drawn" -le 3000 ] || fail "bench cull: drawn '$drawn' over the budget 3000"
else
    echo "skipped the bench run: this build has no raster back-end (SY_TEST_PARTS='${SY_TEST_PARTS:-}')"
fi

for bad in "--tris 0" "--frames x" "-w 0" "--budget -1"; do
    # shellcheck disable=SC2086
    "$SY" bench cull $bad >/dev/null 2>"$TMP/bad.err"
    rc=$?
    opt=${bad%% *}
    [ $rc -eq 2 ] && grep -q -- "$opt" "$TMP/bad.err" || fail "bench cull $bad: status $rc, $(cat "$TMP/bad.err")"
done
[ $fails -eq 0 ] && echo "cull cli: all checks passed"
exit $((fails > 0))
