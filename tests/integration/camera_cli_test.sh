#!/usr/bin/env bash
# camera_cli_test.sh SY TESTDATA TMPDIR EXR_EQUAL EXR_ERROR — the camera placement options of sy
# render / pick (--look-at EYE:TARGET[:UP], --orbit AZ,EL[,DIST], --fov DEG) and the cameras of
# sy info (integration_camera_cli, issue 37 item 5):
#   - usage errors (status 2, naming the option and the reason): a missing part, NaN, eye == target,
#     up parallel to the view, --fov 0 / 180, EL beyond 90, DIST <= 0, --look-at with --orbit
#   - Cameras.gltf: --look-at from its perspective camera's eye (0.5,0.5,3 towards -z) renders the
#     same pixels as --camera 0 (exr_equal), and the EXR's sy:camera_to_world is that camera's
#   - Box.gltf: --orbit 0,0,3 equals --look-at 0,0,3:0,0,0 (exr_equal); --orbit 0,0 stands at the
#     default framing distance r / sin(fov/2) * 1.05 (r = the bounds' radius, fov the default 45
#     degrees) on +z, as sy:camera_to_world says, and renders as --look-at from that eye (exr_error)
#   - --orbit 0,20 renders as the default camera (exr_error relmse < 1e-6); --fov on Cameras.gltf's
#     orthographic camera fails (status 1) naming --fov
#   - --fov: the front face of the Box (half width 0.5 at distance 2.5) covers W * 0.2 / tan(fov/2)
#     pixels of the middle row (counted with sy pick), for 40 and 60 degrees, within 2 pixels
#   - sy info Cameras.gltf lists 2 cameras: 0 perspective yfov 0.7, 1 orthographic xmag 1 ymag 1,
#     both at (0.5, 0.5, 3)
# Needs ../shared/testdata (Box, Cameras): exits 77 (skipped) naming what is missing.
set -u
SY=$1
DATA=$2
EXR_EQUAL=$4
EXR_ERROR=$5
. "$(dirname "${BASH_SOURCE[0]}")/../support/check.sh" # fail (and $fails)
fresh_tmp "$3"

# usage errors: status 2 and the option and reason on stderr
usage() { usage_error "$1" "$2" "$SY" render demo -w 16 -h 16 -o "$TMP/u.png" "${@:3}"; } # WHAT EXPECT ARGS...
usage "look-at without target" "--look-at 0,1,5: expected EYE:TARGET" --look-at 0,1,5
usage "look-at two parts" "TARGET is not x,y,z" --look-at 0,1,5:0,0
usage "look-at NaN" "EYE is not x,y,z" --look-at nan,1,5:0,0,0
usage "look-at eye == target" "EYE and TARGET are the same point" --look-at 1,2,3:1,2,3
usage "look-at up parallel" "UP is zero or parallel" --look-at 0,5,0:0,0,0
usage "look-at zero up" "UP is zero or parallel" --look-at 0,1,5:0,0,0:0,0,0
usage "look-at four parts" "expected EYE:TARGET" --look-at 0,1,5:0,0,0:0,1,0:1,1,1
usage "fov 0" "--fov 0: expected the vertical field of view" --fov 0
usage "fov 180" "--fov 180:" --fov 180
usage "fov NaN" "--fov nan:" --fov nan
usage "orbit one number" "--orbit 10: expected AZ,EL" --orbit 10
usage "orbit EL 91" "EL must be from -90 to 90" --orbit 0,91
usage "orbit DIST 0" "DIST must be above 0" --orbit 0,0,0
usage "orbit trailing comma" "expected AZ,EL" --orbit 0,0,
usage "look-at with orbit" "--look-at and --orbit both place the camera" --orbit 0,0 --look-at 0,1,5:0,0,0
usage "orbit with look-at" "--look-at and --orbit both place the camera" --look-at 0,1,5:0,0,0 --orbit 0,0
"$SY" render demo -w 16 -h 16 -o "$TMP/demo.png" --look-at 0,1,5:0,0,0:0,1,0 --fov 50 2>"$TMP/demo.err" ||
    fail "render demo --look-at --fov: $(cat "$TMP/demo.err")"
"$SY" render demo -w 16 -h 16 -o "$TMP/demo.png" --orbit 30,-90 2>"$TMP/demo.err" ||
    fail "render demo --orbit 30,-90 (straight up): $(cat "$TMP/demo.err")"

CAMS=$DATA/gltf/Cameras/glTF/Cameras.gltf
BOX=$DATA/gltf/Box/glTF/Box.gltf
missing=""
[ -f "$CAMS" ] || missing="$missing $CAMS"
[ -f "$BOX" ] || missing="$missing $BOX"
if [ -n "$missing" ]; then
    echo "SKIP: test data not found:$missing (the usage checks passed: $fails failures)"
    [ $fails -eq 0 ] && exit 77
    exit 1
fi

# the attribute NAME of an EXR as sy info prints it
attr() { "$SY" info "$1" | sed -n "s/^ *\"$2\": \"\(.*\)\",\{0,1\}$/\1/p"; }

# --look-at from the file camera's eye = --camera 0, pixel for pixel
"$SY" render "$CAMS" -w 64 -h 64 -o "$TMP/cam0.exr" --camera 0 2>/dev/null || fail "render Cameras --camera 0"
"$SY" render "$CAMS" -w 64 -h 64 -o "$TMP/look.exr" --look-at 0.5,0.5,3:0.5,0.5,0 2>/dev/null || fail "render --look-at"
"$SY" render "$CAMS" -w 64 -h 64 -o "$TMP/lookfov.exr" --look-at 0.5,0.5,3:0.5,0.5,-1:0,1,0 --fov 40.107045659157625 \
    2>/dev/null || fail "render --look-at --fov"
"$EXR_EQUAL" "$TMP/look.exr" "$TMP/cam0.exr" || fail "--look-at from camera 0's eye differs from --camera 0"
"$EXR_EQUAL" "$TMP/lookfov.exr" "$TMP/cam0.exr" || fail "--look-at with UP and --fov 0.7 rad differs from --camera 0"
m0=$(attr "$TMP/cam0.exr" sy:camera_to_world)
m1=$(attr "$TMP/look.exr" sy:camera_to_world)
[ "$m0" = "1 0 0 0 0 1 0 0 0 0 1 0 0.5 0.5 3 1" ] && [ "$m1" = "$m0" ] ||
    fail "sy:camera_to_world: --camera 0 '$m0', --look-at '$m1' (want 1 0 0 0 0 1 0 0 0 0 1 0 0.5 0.5 3 1)"
attr "$TMP/look.exr" sy:camera | grep -q -- "--look-at camera at (0.5, 0.5, 3)" ||
    fail "sy:camera of the --look-at render: $(attr "$TMP/look.exr" sy:camera)"

# --orbit: around the bounds' centre (the Box: the origin)
"$SY" render "$BOX" -w 64 -h 64 -o "$TMP/orbit3.exr" --orbit 0,0,3 2>/dev/null || fail "render --orbit 0,0,3"
"$SY" render "$BOX" -w 64 -h 64 -o "$TMP/look3.exr" --look-at 0,0,3:0,0,0 2>/dev/null || fail "render --look-at 0,0,3"
"$EXR_EQUAL" "$TMP/orbit3.exr" "$TMP/look3.exr" || fail "--orbit 0,0,3 differs from --look-at 0,0,3:0,0,0"
# the default distance: r / sin(22.5 deg) * 1.05, r = |(0.5, 0.5, 0.5)|
dist=$(awk 'BEGIN { printf "%.7f", sqrt(0.75) / sin(atan2(1, 1) / 2) * 1.05 }')
"$SY" render "$BOX" -w 64 -h 64 -o "$TMP/orbit.exr" --orbit 0,0 2>/dev/null || fail "render --orbit 0,0"
"$SY" render "$BOX" -w 64 -h 64 -o "$TMP/lookd.exr" --look-at "0,0,$dist:0,0,0" 2>/dev/null || fail "render --look-at 0,0,$dist"
mo=$(attr "$TMP/orbit.exr" sy:camera_to_world)
echo "$mo" | awk -v d="$dist" '{ e = $15 - d; if (e < 0) e = -e; exit !($1 == 1 && $6 == 1 && $11 == 1 && $13 == 0 && $14 == 0 && e < 1e-4) }' ||
    fail "--orbit 0,0 camera_to_world '$mo' (want the identity rotation at (0, 0, $dist))"
"$EXR_ERROR" "$TMP/orbit.exr" "$TMP/lookd.exr" >"$TMP/orbit_err.txt" || fail "exr_error --orbit 0,0"
awk '{ exit !($2 < 1e-4) }' "$TMP/orbit_err.txt" || fail "--orbit 0,0 vs --look-at 0,0,$dist: $(cat "$TMP/orbit_err.txt")"
# --orbit 0,20 is the default camera's view (from the front, 20 degrees up, the same distance)
"$SY" render "$BOX" -w 64 -h 64 -o "$TMP/default.exr" 2>/dev/null || fail "render Box"
"$SY" render "$BOX" -w 64 -h 64 -o "$TMP/orbit20.exr" --orbit 0,20 2>/dev/null || fail "render --orbit 0,20"
"$EXR_ERROR" "$TMP/orbit20.exr" "$TMP/default.exr" >"$TMP/orbit20_err.txt" || fail "exr_error --orbit 0,20"
awk '{ exit !($2 < 1e-6) }' "$TMP/orbit20_err.txt" || fail "--orbit 0,20 vs the default camera: $(cat "$TMP/orbit20_err.txt")"
# an orthographic camera has no field of view: --fov is refused naming it
"$SY" render "$CAMS" -w 16 -h 16 -o "$TMP/ortho.png" --camera 1 --fov 30 2>"$TMP/ortho.err"
rc=$?
[ $rc -eq 1 ] && grep -qF -- "--fov: the camera is orthographic" "$TMP/ortho.err" && [ ! -f "$TMP/ortho.png" ] ||
    fail "--fov on an orthographic camera: status $rc, $(cat "$TMP/ortho.err")"
"$SY" render "$BOX" -w 16 -h 16 -o "$TMP/orbit90.exr" --orbit 90,0,3 2>/dev/null || fail "render --orbit 90,0,3"
attr "$TMP/orbit90.exr" sy:camera_to_world | awk '{ exit !($13 > 2.9999 && $13 < 3.0001 && $14 * $14 < 1e-8 && $15 * $15 < 1e-8) }' ||
    fail "--orbit 90,0,3 stands at (3, 0, 0): $(attr "$TMP/orbit90.exr" sy:camera_to_world)"

# --fov: covered pixels of the middle row of a 128 x 128 image, the Box seen from (0, 0, 3)
W=128
xs=""
for ((x = 0; x < W; x++)); do xs="$xs $x 64"; done
for fov in 40 60; do
    # shellcheck disable=SC2086
    "$SY" pick "$BOX" $xs -w $W -h $W --look-at 0,0,3:0,0,0 --fov $fov >"$TMP/pick$fov.json" 2>"$TMP/pick.err" ||
        fail "sy pick --fov $fov: $(cat "$TMP/pick.err")"
    got=$(grep -c '"hit": true' "$TMP/pick$fov.json")
    want=$(awk -v f=$fov -v w=$W 'BEGIN { printf "%.2f", w * 0.2 / (sin(f * atan2(1, 1) / 90) / cos(f * atan2(1, 1) / 90)) }')
    awk -v g="$got" -v w="$want" 'BEGIN { e = g - w; if (e < 0) e = -e; exit !(e <= 2) }' ||
        fail "--fov $fov: $got pixels covered, tan(fov/2) predicts $want"
    echo "fov $fov: $got pixels covered of $W (predicted $want)"
done

# sy info: the two cameras of Cameras.gltf
"$SY" info "$CAMS" >"$TMP/info.json" 2>/dev/null || fail "sy info Cameras.gltf"
tr -d ' \n' <"$TMP/info.json" >"$TMP/info1.json"
grep -qF '"cameras":[{"index":0,"name":null,"camera_name":null,"type":"perspective","yfov":0.699999988,' "$TMP/info1.json" ||
    fail "sy info: camera 0: $(grep -o '"cameras":.*' "$TMP/info1.json" | head -c 400)"
grep -qF '"position":[0.5,0.5,3],"direction":[0,0,-1]},{"index":1,"name":null,"camera_name":null,"type":"orthographic","xmag":1,"ymag":1,' "$TMP/info1.json" ||
    fail "sy info: camera 1: $(grep -o '"cameras":.*' "$TMP/info1.json" | head -c 400)"
[ "$(grep -o '"index":[01],"name"' "$TMP/info1.json" | wc -l)" -eq 2 ] || fail "sy info: not 2 cameras"
grep -qF '"clips":[]' "$TMP/info1.json" || fail "sy info: clips missing"

if [ $fails -ne 0 ]; then
    echo "$fails failure(s)"
    exit 1
fi
echo "camera options: all checks passed"
