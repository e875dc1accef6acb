#!/bin/bash
# assimp_anim_cli: Assimp's own animated samples (Debian assimp-testmodels, read in place) through the
# CLI (issue 35): `sy info` lists each file's clips with a positive duration and reports its skins
# (skins_and_morphs; no not_loaded); `sy render --at` at two times gives different images (EXR,
# exr_equal) for the skinned COLLADA box and FBX tentacle. DirectX's anim_test.x names bones its
# frames lack: the skin is dropped with a warning naming the bone and its two images are the same.
# A .x file the test writes with two clips on one node plays its first (as a glTF file's alternatives).
# Usage: anim_cli_test.sh SY EXR_EQUAL MODELS_DIR TMP. Skipped (77) when the models are absent.
set -u
SY=$1 EXR_EQUAL=$2 MODELS=$3 TMP=$4
[ -f "$MODELS/Collada/box_nested_animation.dae" ] || { echo "SKIP: $MODELS/Collada/box_nested_animation.dae not found (assimp-testmodels)"; exit 77; }
rm -rf "$TMP" && mkdir -p "$TMP"
fail=0
for f in Collada/box_nested_animation.dae FBX/animation_with_skeleton.fbx X/anim_test.x; do
    [ -f "$MODELS/$f" ] || { echo "skip: $f not found"; continue; }
    "$SY" -q info "$MODELS/$f" >"$TMP/info.json" 2>"$TMP/info.err" || { cat "$TMP/info.err"; echo "FAIL: sy info $f"; fail=1; continue; }
    summary=$(python3 - "$TMP/info.json" <<'PY'
import json, sys
d = json.load(open(sys.argv[1]))
clips = d.get("clips", [])
ok = len(clips) >= 1 and all(c["duration"] > 0 and c["channels"] > 0 for c in clips) and "not_loaded" not in d \
    and d.get("skins_and_morphs", {}).get("skinned_meshes", 0) >= 1 and d["loaded"]["animations"] == len(clips)
print("ok" if ok else "bad", json.dumps(clips), json.dumps(d.get("skins_and_morphs")), json.dumps(d.get("warnings")))
PY
)
    echo "$f: $summary"
    [ "${summary%% *}" = ok ] || { echo "FAIL: sy info $f: clips, durations or skins"; fail=1; }
    for t in 0.2 0.7; do
        "$SY" -q render "$MODELS/$f" -w 96 -h 96 --at $t -o "$TMP/t$t.exr" || { echo "FAIL: sy render $f --at $t"; fail=1; }
    done
    "$EXR_EQUAL" "$TMP/t0.2.exr" "$TMP/t0.7.exr" >/dev/null 2>&1
    same=$?
    case $f in
    *.x)
        grep -q "bones\[2\] 'joint3' names no node; skin dropped" "$TMP/info.json" || { echo "FAIL: $f: no warning for the missing bone"; fail=1; }
        [ $same = 0 ] || { echo "FAIL: $f: images differ although the skin was dropped"; fail=1; } ;;
    *)
        [ $same = 1 ] || { echo "FAIL: $f: --at 0.2 and --at 0.7 give the same image (exr_equal $same)"; fail=1; } ;;
    esac
done
# a file whose clips drive the same node holds alternatives (an FBX file's takes): the first plays
cat >"$TMP/two.x" <<'X'
xof 0302txt 0064
Frame Root {
 FrameTransformMatrix { 1.0,0.0,0.0,0.0, 0.0,1.0,0.0,0.0, 0.0,0.0,1.0,0.0, 0.0,0.0,0.0,1.0;; }
 Mesh { 3; 0.0;0.0;0.0;, 1.0;0.0;0.0;, 0.0;1.0;0.0;; 1; 3;0,1,2;; }
}
AnimationSet Up { Animation { {Root} AnimationKey { 2; 2; 0;3;0.0,0.0,0.0;;, 10;3;0.0,1.0,0.0;;; } } }
AnimationSet Side { Animation { {Root} AnimationKey { 2; 2; 0;3;0.0,0.0,0.0;;, 10;3;1.0,0.0,0.0;;; } } }
X
"$SY" render "$TMP/two.x" -w 32 -h 32 --at 0.2 -o "$TMP/two.exr" >"$TMP/two.log" 2>&1 || { cat "$TMP/two.log"; echo "FAIL: sy render two.x"; fail=1; }
grep -q "playing clip 0 (Up) of 2" "$TMP/two.log" || { cat "$TMP/two.log"; echo "FAIL: two.x: the first clip does not play alone"; fail=1; }
rm -rf "$TMP"
[ $fail = 0 ] && echo "ok: Assimp's animated samples list their clips and move under sy render --at"
exit $fail
