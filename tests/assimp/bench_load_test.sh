#!/bin/bash
# assimp_bench_load: the Assimp part of `sy bench load` runs on a small generated grid (no timing
# is checked): an OBJ row and an FBX row, each with Assimp's and sy's triangle counts equal to the
# grid's and a positive peak per scene byte (the scene is made). Usage: bench_load_test.sh SY
set -u
SY=$1
out=$("$SY" bench load /nonexistent --tris 200 --repeats 1 2>&1) || { echo "$out"; echo "FAIL: sy bench load failed"; exit 1; }
echo "$out"
fail=0
for kind in "grid OBJ" "FBX"; do
    row=$(grep -F "$kind (" <<<"$out" | grep -v '^(' | head -1)
    [ -n "$row" ] || { echo "FAIL: no '$kind' row"; fail=1; continue; }
    # model label, then: file MB, tris, sy tris, assimp ms, sy ms, ratio, assimp peak, sy peak, scene MB, pk/scene
    read -r tris sytris scene <<<"$(sed 's/.*tris) *//' <<<"$row" | awk '{print $2, $3, $10}')"
    [ "$tris" = 200 ] && [ "$sytris" = 200 ] || { echo "FAIL: $kind: triangles $tris (Assimp) and $sytris (sy), expected 200"; fail=1; }
    awk -v s="$scene" 'BEGIN { sub(/x$/, "", s); exit !(s + 0 > 0) }' || { echo "FAIL: $kind: peak per scene byte '$scene'"; fail=1; }
done
[ $fail = 0 ] && echo "ok: the Assimp part of sy bench load ran on a 200-triangle grid"
exit $fail
