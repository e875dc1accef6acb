#!/usr/bin/env bash
# motion_blur_test.sh — sy render --shutter / --motion-blur (issue 35 item 7) on a generated X3D
# scene: a 2 m box that a PositionInterpolator moves 2 m along x in 1 s, seen from a fixed Viewpoint.
# The shutter 0,0.5 after --at 0.25 spans box positions x = -0.5 .. 0.5: it moves half its width, so
# the region it sweeps is exactly the union of its two end positions (two overlapping squares).
# For each back-end given (whitted and pathtracer blur in one render with a time per ray,
# SY_CAP_MOTION, and with --sub-frames by the sub-frame mean; raster always by sub-frames; a note says
# which), for both paths:
#   - the blurred image's coverage (alpha > 0.02: some time sample saw the box there) is wider than one
#     time's (the mid time, alpha > 0.5; the move is half the box, so about 1.5 times) and matches the
#     union of the endpoints' coverages (alpha > 0.02 too, so anti-aliased edge pixels count alike) with
#     IoU >= 0.95: the time samples are the strata's midpoints, so the streak's first and last copies
#     sit 0.5 / 16 of the move (0.03 m, about a third of a pixel here) inside the endpoints, which can
#     drop the outermost, partly covered column on each side: 2 x 22 of about 810 pixels, IoU >= 0.946
#     at worst (measured: 0.977 Whitted, 0.998 raster); the path tracer's edges are Monte Carlo: a
#     pixel a few percent covered shows a hit among the union's 2 x 32 samples more often than among
#     the streak's 32, so it gets 0.92 (measured 0.941);
#   - the shutter 0 render equals the render without the option bit for bit, and (ray tracers) so
#     does a shutter over which nothing moves (after the box stopped: one render, nothing moving);
#   - a scene without animations renders bit for bit as without the option (and says why).
# The first back-end ("raster" where built, else the first given, with --sub-frames) also proves the
# accumulation: its blurred mean (R, G, B, A) equals the mean of the sub-frame renders at the four
# time-sample times within 1e-5 (float rounding of the sums; 2e-4 for Whitted, whose pixel points
# follow each sub-frame's seed), and the other back-ends' blurred alpha mean (covered
# area) equals that sub-frame mean within 0.01 (the back-ends' edges differ by anti-aliasing only).
# A blurred sequence frame equals the blurred --at render of its time, bit for bit. A mesh deformed
# over the shutter (morph targets) is interpolated per ray by the ray tracers too (two vertex time
# steps): its streak matches the sub-frames' (IoU >= 0.95, mean alpha within 0.01), and shutter 0 or
# a shutter over which nothing deforms renders bit for bit as without it. A camera moved over the
# shutter is interpolated per camera ray too (in stereo each eye's rays from its own views), and with
# --shutter-steps a spinning bar's streak (9 steps), a square deformed along an arc and a camera
# orbiting the box (5 steps) follow the arc, not the chord; without it the spinning bar gets the 9
# steps by itself (its quarter turn) and a translation 2. An emitter moving over the shutter lights
# the wall from where it is at each ray's time (the lit centroid at its path's middle).
# Usage errors (status 2, naming the option): a negative, NaN, infinite or non-numeric shutter, open
# after close, --shutter with --motion-blur, --shutter-samples alone or 0, --sub-frames alone,
# --shutter-steps alone or outside 2..9.
# Usage: motion_blur_test.sh SY TMP EXR_EQUAL EXR_BLUR BACKEND...
SY=$1
TMP=$2
EXR_EQUAL=$3
EXR_BLUR=$4
shift 4
backends=("$@")
# fail, run NAME CMD..., run_ok LABEL NAME CMD... (and $fails, $rc)
. "$(dirname "${BASH_SOURCE[0]}")/../support/check.sh"
# x3d_shape, x3d_clock, x3d_drive: the scenes' lines
. "$(dirname "${BASH_SOURCE[0]}")/../support/x3d_scene.sh"
rm -rf "$TMP"
mkdir -p "$TMP"
view_scene() { # view_scene FILE LINE...: an X3D scene of the LINEs, seen by the Viewpoint 'V' from 12 m on +z
    {
        echo "<X3D><Scene><Viewpoint DEF='V' position='0 0 12' fieldOfView='0.5'/>"
        printf '%s\n' "${@:2}"
        echo "</Scene></X3D>"
    } >"$1"
}
box=$(x3d_shape "<Box size='2 2 2'/>") # the 2 m box
view_scene "$TMP/moving.x3d" "<Transform DEF='Box'>$box</Transform>" "$(x3d_clock 1)" \
    "<PositionInterpolator DEF='Move' key='0 1' keyValue='-1 0 0 1 0 0'/>" "$(x3d_drive Move Box translation)"
view_scene "$TMP/static.x3d" "<Transform DEF='Box'>$box</Transform>"
size=(-w 96 -h 64)
gt() { awk -v a="$1" -v b="$2" 'BEGIN { exit !(a > b) }'; } # gt A B: A > B
near() { awk -v a="$1" -v b="$2" -v t="$3" 'BEGIN { d = a - b; if (d < 0) d = -d; exit !(d <= t) }'; }

# usage errors need no rendering
usage() { # usage LABEL EXPECTED-TEXT ARGS...
    usage_error "$1" "$2" "$SY" render "$TMP/moving.x3d" -b whitted -w 8 -h 8 -o "$TMP/usage.exr" "${@:3}"
    [ -e "$TMP/usage.exr" ] && fail "$1: wrote an image"
}
for bad in -0.1 nan inf 0,inf 0.2,0.1 abc 0,1,2 "" 0, -1,0; do
    usage "--shutter '$bad'" "--shutter" --shutter "$bad"
done
usage "open after close" "opens (0.2 s) after it closes (0.1 s)" --shutter 0.2,0.1
usage "--shutter and --motion-blur" "--motion-blur is --shutter 0,0.5/FPS" --shutter 0.1 --motion-blur
usage "--shutter-samples alone" "--shutter-samples belongs to --shutter" --shutter-samples 4
usage "--shutter-samples 0" "--shutter-samples" --shutter 0.1 --shutter-samples 0
usage "--sub-frames alone" "--sub-frames belongs to --shutter" --sub-frames

# rend STEM SCENE NAME ARGS...: renders $TMP/SCENE with back-end $b (and the options in the array
# extra) into $TMP/${b}_STEM_NAME.exr ($TMP/${b}_NAME.exr where STEM is ""), its output beside it
rend() {
    local out=${b}_${1:+$1_}$3 scene=$2
    shift 3
    run_ok "$b ${out#"${b}_"}" "$out" "$SY" render "$TMP/$scene" -b "$b" "${extra[@]}" -o "$TMP/$out.exr" "$@"
}
# for_tracers SPP CHECK: runs the function CHECK for each ray tracer given, the back-end in $b, extra
# --spp SPP for the path tracer
for_tracers() {
    for b in "${backends[@]}"; do
        [ "$b" = raster ] && continue
        extra=()
        [ "$b" = pathtracer ] && extra=(--spp "$1")
        "$2"
    done
}
# pan_widths BLURRED SUB-FRAMES SHARP: the panned box's widths in px (wb blurred, ws as sub-frames, wm
# sharp) and the blurred image's relMSE against the sub-frames (rel)
pan_widths() {
    wb=$("$EXR_BLUR" width 0.02 "$1") ws=$("$EXR_BLUR" width 0.02 "$2") wm=$("$EXR_BLUR" width 0.5 "$3")
    rel=$("$EXR_BLUR" relmse "$1" "$2")
}
mean_alpha() { # mean_alpha FILE: the mean alpha of the EXR render FILE
    local a
    read -r _ _ _ a <<<"$("$EXR_BLUR" mean "$1")"
    echo "$a"
}
r() { rend "" moving.x3d "$1" "${size[@]}" "${@:2}"; } # r NAME ARGS...: the moving box
for b in "$@"; do
    extra=()
    [ "$b" = pathtracer ] && extra=(--spp 32)
    r open --at 0.25
    r close --at 0.75
    r mid --at 0.5
    r blur --at 0.25 --shutter 0,0.5
    r blur_sub --at 0.25 --shutter 0,0.5 --sub-frames
    grep -qF "motion blur: the mean of 16 sub-frames" "$TMP/${b}_blur_sub.err" ||
        fail "$b --sub-frames: no note on the sub-frames: $(cat "$TMP/${b}_blur_sub.err")"
    if [ "$b" = raster ]; then # no SY_CAP_MOTION: sub-frames
        grep -qF "motion blur: the mean of 16 sub-frames" "$TMP/${b}_blur.err" ||
            fail "$b: no note on the sub-frames: $(cat "$TMP/${b}_blur.err")"
    else # the ray tracers: one render, a time per ray (SY_CAP_MOTION)
        grep -qF "motion blur: one render, each" "$TMP/${b}_blur.err" ||
            fail "$b: no note on the one render with per-ray times: $(cat "$TMP/${b}_blur.err")"
    fi
    one=$("$EXR_BLUR" cover 0.5 "$TMP/${b}_mid.exr")
    for kind in blur blur_sub; do
        streak=$("$EXR_BLUR" cover 0.02 "$TMP/${b}_$kind.exr")
        iou=$("$EXR_BLUR" iou 0.02 "$TMP/${b}_$kind.exr" 0.02 "$TMP/${b}_open.exr" "$TMP/${b}_close.exr")
        echo "$b $kind: covered pixels: one time $one, blurred $streak; IoU of the streak against the endpoints' union $iou"
        gt "$streak" "$(awk -v o="$one" 'BEGIN { print o * 1.3 }')" || fail "$b $kind: the streak ($streak px) is not wider than one time ($one px)"
        min_iou=0.95
        [ "$b" = pathtracer ] && min_iou=0.92
        gt "$iou" "$min_iou" || fail "$b $kind: the streak's coverage against the union of the endpoints: IoU $iou < $min_iou"
    done
    if [ "$b" != raster ]; then
        # the box stops at 1 s (the time sensor does not loop): a shutter over which nothing moves takes
        # the one-render path with no moving instance, bit for bit the render without the option (the
        # sub-frame mean is not: N renders of other seeds)
        r still --at 2
        r still_blur --at 2 --shutter 0,0.5
        "$EXR_EQUAL" "$TMP/${b}_still.exr" "$TMP/${b}_still_blur.exr" >/dev/null ||
            fail "$b: a shutter over which nothing moves differs from no shutter"
    fi
    if [ "$b" != raster ]; then # a translation turns nothing: 2 steps, the linear protocol
        r blur_two --at 0.25 --shutter 0,0.5 --shutter-steps 2
        "$EXR_EQUAL" "$TMP/${b}_blur.exr" "$TMP/${b}_blur_two.exr" >/dev/null || fail "$b: a translation's default differs from --shutter-steps 2"
    fi
    r instant --at 0.25 --shutter 0
    "$EXR_EQUAL" "$TMP/${b}_open.exr" "$TMP/${b}_instant.exr" >/dev/null || fail "$b: --shutter 0 differs from no shutter"
    run_ok "$b static" "${b}_static" "$SY" render "$TMP/static.x3d" -b "$b" "${size[@]}" "${extra[@]}" -o "$TMP/${b}_static.exr"
    run_ok "$b static blur" "${b}_static_blur" "$SY" render "$TMP/static.x3d" -b "$b" "${size[@]}" "${extra[@]}" \
        --shutter 0,0.5 -o "$TMP/${b}_static_blur.exr"
    "$EXR_EQUAL" "$TMP/${b}_static.exr" "$TMP/${b}_static_blur.exr" >/dev/null || fail "$b: a static scene with --shutter differs"
    grep -qF "no animations" "$TMP/${b}_static_blur.err" || fail "$b: static scene: no note"
done

# the mean of the sub-frames: 4 time samples over 0.25 + [0, 0.5]: 0.3125 0.4375 0.5625 0.6875
ref=$1
for b in "$@"; do [ "$b" = raster ] && ref=raster; done
subs=()
for t in 0.3125 0.4375 0.5625 0.6875; do
    run_ok "$ref --at $t" "sub_$t" "$SY" render "$TMP/moving.x3d" -b "$ref" "${size[@]}" --at "$t" -o "$TMP/sub_$t.exr"
    subs+=("$TMP/sub_$t.exr")
done
read -r mr mg mb ma <<<"$("$EXR_BLUR" mean "${subs[@]}")"
for b in "$@"; do
    extra=()
    [ "$b" = pathtracer ] && extra=(--spp 32)
    [ "$b" = "$ref" ] && extra+=(--sub-frames) # the sub-frames' mean, exactly
    run_ok "$b 4 samples" "${b}_blur4" "$SY" render "$TMP/moving.x3d" -b "$b" "${size[@]}" "${extra[@]}" --at 0.25 \
        --shutter 0,0.5 --shutter-samples 4 -o "$TMP/${b}_blur4.exr"
    read -r br bg bb ba <<<"$("$EXR_BLUR" mean "$TMP/${b}_blur4.exr")"
    echo "$b: blurred mean RGBA $br $bg $bb $ba; mean of the $ref sub-frames $mr $mg $mb $ma"
    if [ "$b" = "$ref" ]; then
        # the rasterizer's image does not depend on the seed; Whitted's pixel points do (sub-frame i has
        # seed i, the --at renders seed 0): within 2e-4 then (measured 6e-5)
        tol=1e-5
        [ "$ref" = raster ] || tol=2e-4
        for c in "$br $mr" "$bg $mg" "$bb $mb" "$ba $ma"; do
            near $c $tol || fail "$b: blurred mean $c differs from the sub-frames' mean by more than $tol"
        done
    else
        near "$ba" "$ma" 0.01 || fail "$b: blurred covered area $ba differs from the $ref sub-frames' $ma by more than 0.01"
    fi
done

# a mesh deformed over the shutter (a CoordinateInterpolator: morph targets, deformed by the mirror)
# slides a 2 m square 2 m along x in 1 s: the ray tracers interpolate its vertices per ray (two vertex
# time steps) in one render, and the streak matches the sub-frames' (covered pixels IoU >= 0.95;
# measured 0.98 Whitted, 0.99 path tracer) and their mean alpha (within 0.01); shutter 0, and a
# shutter after the morph stopped, render bit for bit as without the option
# morph_square FILE POINTS KEYS VALUES: $TMP/FILE.x3d, a quad of the four POINTS (the Coordinate 'C')
# that the CoordinateInterpolator 'Morph' (KEYS, VALUES) moves over 1 s
morph_square() {
    view_scene "$TMP/$1.x3d" "$(x3d_shape "<IndexedFaceSet coordIndex='0 1 2 3 -1'><Coordinate DEF='C' point='$2'/></IndexedFaceSet>")" \
        "$(x3d_clock 1)" "<CoordinateInterpolator DEF='Morph' key='$3' keyValue='$4'/>" "$(x3d_drive Morph C set_point)"
}
morph_square deform '-1 -1 0 1 -1 0 1 1 0 -1 1 0' '0 1' '-1 -1 0 1 -1 0 1 1 0 -1 1 0 1 -1 0 3 -1 0 3 1 0 1 1 0'
d() { rend deform deform.x3d "$1" "${size[@]}" "${@:2}"; } # d NAME ARGS...: the sliding square
deform_checks() {
    d blur --at 0.25 --shutter 0,0.5
    d sub --at 0.25 --shutter 0,0.5 --sub-frames
    grep -qF "motion blur: one render, each" "$TMP/${b}_deform_blur.err" ||
        fail "$b: a deforming mesh: no note on the one render with per-ray times: $(cat "$TMP/${b}_deform_blur.err")"
    one=$("$EXR_BLUR" cover 0.5 "$TMP/${b}_deform_sub.exr")
    streak=$("$EXR_BLUR" cover 0.02 "$TMP/${b}_deform_blur.exr")
    iou=$("$EXR_BLUR" iou 0.02 "$TMP/${b}_deform_blur.exr" 0.02 "$TMP/${b}_deform_sub.exr" "$TMP/${b}_deform_sub.exr")
    echo "$b deforming: covered pixels: blurred $streak (alpha > 0.5 in the sub-frames' mean: $one); IoU against the sub-frames $iou"
    gt "$streak" "$(awk -v o="$one" 'BEGIN { print o * 1.2 }')" || fail "$b deforming: the streak ($streak px) is not wider than the mean's core ($one px)"
    gt "$iou" 0.95 || fail "$b deforming: the streak against the sub-frames': IoU $iou < 0.95"
    read -r _ _ _ ba <<<"$("$EXR_BLUR" mean "$TMP/${b}_deform_blur.exr")"
    read -r _ _ _ sa <<<"$("$EXR_BLUR" mean "$TMP/${b}_deform_sub.exr")"
    near "$ba" "$sa" 0.01 || fail "$b deforming: blurred covered area $ba differs from the sub-frames' $sa by more than 0.01"
    d sharp --at 0.25
    d instant --at 0.25 --shutter 0
    "$EXR_EQUAL" "$TMP/${b}_deform_sharp.exr" "$TMP/${b}_deform_instant.exr" >/dev/null || fail "$b deforming: --shutter 0 differs from no shutter"
    d still --at 2
    d still_blur --at 2 --shutter 0,0.5
    "$EXR_EQUAL" "$TMP/${b}_deform_still.exr" "$TMP/${b}_deform_still_blur.exr" >/dev/null ||
        fail "$b deforming: a shutter over which nothing deforms differs from no shutter"
}
for_tracers 32 deform_checks

# a blurred sequence of the deforming square: frame 7, after frame 6's motion, equals frame 7 rendered
# alone, bit for bit (the mesh's motion ends with each frame)
# seq_render LABEL NAME SCENE OUT ARGS...: the first back-end's 48 x 32 render of $TMP/SCENE blurred
# by --motion-blur (4 samples; the path tracer at 8 spp) into $TMP/OUT, as run_ok NAME
seq_render() {
    local b=${backends[0]} extra=()
    [ "$b" = pathtracer ] && extra=(--spp 8)
    run_ok "$b $1" "$2" "$SY" render "$TMP/$3" -b "$b" -w 48 -h 32 "${extra[@]}" --motion-blur --shutter-samples 4 \
        -o "$TMP/$4" "${@:5}"
}
b=$1
seq_render "deforming sequence" deform_seq deform.x3d "deform_seq_#.exr" --frames 6:7
seq_render "deforming frame 7" deform_seq7 deform.x3d "deform_one_#.exr" --frames 7:7
"$EXR_EQUAL" "$TMP/deform_seq_7.exr" "$TMP/deform_one_7.exr" >/dev/null ||
    fail "$b: a deforming sequence's frame 7 differs from frame 7 alone"

# a camera that moves over the shutter: the ray tracers build each camera ray at its own time (the
# Viewpoint's position interpolated linearly, its orientation by slerp) in one render. Panning 0.2 rad
# in 1 s, the shutter 0..0.5 turns it 0.1 rad: an edge near the centre sweeps 0.1 x 32 / tan(0.25) =
# 12.53 pixels (64 rows, fieldOfView 0.5), so the blurred box (alpha > 0.02) is that much wider than
# at one time (alpha > 0.5; measured 12.54 Whitted, 12.88 path tracer); the image equals the mean of
# 64 sub-frames within noise (relMSE of RGB 2e-4 Whitted, 2e-3 path tracer at 64 spp). A camera moved
# 1 m sideways over the shutter streaks the box over the union of its two ends' coverages (IoU as the
# moving box's); a camera that stopped renders bit for bit as without the shutter.
view_scene "$TMP/camera.x3d" "$box" "$(x3d_clock 1)" "<PositionInterpolator DEF='Move' key='0 1' keyValue='-1 0 12 1 0 12'/>" \
    "$(x3d_drive Move V position)"
view_scene "$TMP/pan.x3d" "$box" "$(x3d_clock 1)" "<OrientationInterpolator DEF='Pan' key='0 1' keyValue='0 1 0 -0.1 0 1 0 0.1'/>" \
    "$(x3d_drive Pan V orientation)"
c() { rend cam "$1.x3d" "$2" "${size[@]}" "${@:3}"; } # c SCENE NAME ARGS...: $TMP/SCENE.x3d into ${b}_cam_NAME
camera_checks() {
    c pan blur --at 0.25 --shutter 0,0.5
    grep -qF "motion blur: one render, each" "$TMP/${b}_cam_blur.err" && grep -qF "the moving camera" "$TMP/${b}_cam_blur.err" ||
        fail "$b: a moving camera: no note on the one render with per-ray times: $(cat "$TMP/${b}_cam_blur.err")"
    c pan sub --at 0.25 --shutter 0,0.5 --sub-frames --shutter-samples 64
    c pan mid --at 0.5
    c pan two --at 0.25 --shutter 0,0.5 --shutter-steps 2
    "$EXR_EQUAL" "$TMP/${b}_cam_blur.exr" "$TMP/${b}_cam_two.exr" >/dev/null || fail "$b: a 5.7-degree pan's default differs from --shutter-steps 2"
    pan_widths "$TMP/${b}_cam_blur.exr" "$TMP/${b}_cam_sub.exr" "$TMP/${b}_cam_mid.exr"
    echo "$b panning camera: box width $wm px sharp, $wb px blurred in one render, $ws px as 64 sub-frames (blur 12.53 px);" \
        "relMSE against the sub-frames $rel"
    near "$(awk -v a="$wb" -v b="$wm" 'BEGIN { print a - b }')" 12.53 1.0 ||
        fail "$b panning camera: the blur ($wb - $wm px) is not 12.53 px within 1"
    near "$(awk -v a="$ws" -v b="$wm" 'BEGIN { print a - b }')" 12.53 1.0 ||
        fail "$b panning camera: the sub-frames' blur ($ws - $wm px) is not 12.53 px within 1"
    max_rel=0.002
    [ "$b" = pathtracer ] && max_rel=0.01
    gt "$max_rel" "$rel" || fail "$b panning camera: relMSE $rel against the sub-frames' mean >= $max_rel"
    c camera move --at 0.25 --shutter 0,0.5
    c camera open --at 0.25
    c camera close --at 0.75
    iou=$("$EXR_BLUR" iou 0.02 "$TMP/${b}_cam_move.exr" 0.02 "$TMP/${b}_cam_open.exr" "$TMP/${b}_cam_close.exr")
    echo "$b moving camera: IoU of the streak against the ends' union $iou"
    min_iou=0.95
    [ "$b" = pathtracer ] && min_iou=0.92
    gt "$iou" "$min_iou" || fail "$b moving camera: the streak against the union of the ends: IoU $iou < $min_iou"
    c pan still --at 2
    c pan still_blur --at 2 --shutter 0,0.5
    "$EXR_EQUAL" "$TMP/${b}_cam_still.exr" "$TMP/${b}_cam_still_blur.exr" >/dev/null ||
        fail "$b: a camera that stopped: the shutter changed the image"
}
for_tracers 64 camera_checks
# the same pan as a glTF camera node's rotation channel (LINEAR, quaternions about +Y from -0.1 to
# 0.1 rad in 1 s) over a 2 m quad 12 m away: the quad's edges blur by 12.6 pixels (12.53 at the centre;
# measured 12.73 Whitted, 13.0 path tracer), the image the mean of 64 sub-frames within noise
# (measured relMSE 1.6e-4 Whitted, 1.9e-3 path tracer)
cat >"$TMP/pan.gltf" <<'EOF'
{"asset":{"version":"2.0"},"scene":0,"scenes":[{"nodes":[0,1]}],"nodes":[{"mesh":0},{"camera":0,"translation":[0,0,12]}],"cameras":[{"type":"perspective","perspective":{"yfov":0.5,"znear":0.1}}],"meshes":[{"primitives":[{"attributes":{"POSITION":0},"indices":1,"material":0}]}],"materials":[{"pbrMetallicRoughness":{"baseColorFactor":[0.8,0.4,0.2,1],"metallicFactor":0}}],"buffers":[{"byteLength":104,"uri":"data:application/octet-stream;base64,AACAvwAAgL8AAAAAAACAPwAAgL8AAAAAAACAPwAAgD8AAAAAAACAvwAAgD8AAAAAAAABAAIAAAACAAMAAAAAAAAAAAAAAIA/AAAAAPW2TL0AAAAAGa5/PwAAAAD1tkw9AAAAABmufz8="}],"bufferViews":[{"buffer":0,"byteOffset":0,"byteLength":48},{"buffer":0,"byteOffset":48,"byteLength":12},{"buffer":0,"byteOffset":64,"byteLength":8},{"buffer":0,"byteOffset":72,"byteLength":32}],"accessors":[{"bufferView":0,"componentType":5126,"count":4,"type":"VEC3","min":[-1,-1,0],"max":[1,1,0]},{"bufferView":1,"componentType":5123,"count":6,"type":"SCALAR"},{"bufferView":2,"componentType":5126,"count":2,"type":"SCALAR","min":[0],"max":[1]},{"bufferView":3,"componentType":5126,"count":2,"type":"VEC4"}],"animations":[{"channels":[{"sampler":0,"target":{"node":1,"path":"rotation"}}],"samplers":[{"input":2,"output":3,"interpolation":"LINEAR"}]}]}
EOF
g() { rend gltf pan.gltf "$1" "${size[@]}" "${@:2}"; } # g NAME ARGS...: the glTF camera's pan
gltf_checks() {
    g blur --at 0.25 --shutter 0,0.5
    grep -qF "the moving camera" "$TMP/${b}_gltf_blur.err" || fail "$b: a glTF camera's pan: no one render: $(cat "$TMP/${b}_gltf_blur.err")"
    g sub --at 0.25 --shutter 0,0.5 --sub-frames --shutter-samples 64
    g mid --at 0.5
    wb=$("$EXR_BLUR" width 0.02 "$TMP/${b}_gltf_blur.exr")
    wm=$("$EXR_BLUR" width 0.5 "$TMP/${b}_gltf_mid.exr")
    rel=$("$EXR_BLUR" relmse "$TMP/${b}_gltf_blur.exr" "$TMP/${b}_gltf_sub.exr")
    echo "$b glTF camera pan: quad width $wm px sharp, $wb px blurred (blur 12.6 px); relMSE against 64 sub-frames $rel"
    near "$(awk -v a="$wb" -v b="$wm" 'BEGIN { print a - b }')" 12.6 1.0 || fail "$b glTF camera pan: the blur ($wb - $wm px) is not 12.6 px within 1"
    max_rel=0.002
    [ "$b" = pathtracer ] && max_rel=0.01
    gt "$max_rel" "$rel" || fail "$b glTF camera pan: relMSE $rel against the sub-frames' mean >= $max_rel"
}
for_tracers 64 gltf_checks
# the pan in stereo (--stereo separate): each eye's camera rays at their own time, its own views, in
# one render per eye; each eye's image is the mean of 64 sub-frames of that eye within noise (relMSE
# of RGB 2e-3 Whitted, 1e-2 path tracer; measured 2.0e-4 and 2.2e-3) and its blur (alpha > 0.02
# against the sharp eye's alpha > 0.5) the sub-frames' within 1 pixel (measured 11.67 against 11.92
# px Whitted: the eyes' off-axis windows make it a little less than the mono 12.53)
stereo_checks() {
    c pan st_blur --at 0.25 --shutter 0,0.5 --stereo separate
    grep -qF "motion blur: one render, each" "$TMP/${b}_cam_st_blur.err" && grep -qF "the moving camera" "$TMP/${b}_cam_st_blur.err" ||
        fail "$b: a moving camera in stereo: no note on the one render: $(cat "$TMP/${b}_cam_st_blur.err")"
    c pan st_sub --at 0.25 --shutter 0,0.5 --sub-frames --shutter-samples 64 --stereo separate
    c pan st_mid --at 0.5 --stereo separate
    max_rel=0.002
    [ "$b" = pathtracer ] && max_rel=0.01
    for eye in left right; do
        pan_widths "$TMP/${b}_cam_st_blur_$eye.exr" "$TMP/${b}_cam_st_sub_$eye.exr" "$TMP/${b}_cam_st_mid_$eye.exr"
        echo "$b panning camera, $eye eye: box width $wm px sharp, $wb px blurred in one render, $ws px as 64 sub-frames;" \
            "relMSE against the sub-frames $rel"
        gt "$(awk -v a="$wb" -v b="$wm" 'BEGIN { print a - b }')" 8 || fail "$b stereo $eye eye: no blur ($wb px, sharp $wm px)"
        near "$wb" "$ws" 1.0 || fail "$b stereo $eye eye: blurred width $wb px is not the sub-frames' $ws px within 1"
        gt "$max_rel" "$rel" || fail "$b stereo $eye eye: relMSE $rel against the sub-frames' mean >= $max_rel"
    done
}
for_tracers 64 stereo_checks

# curved motion (--shutter-steps N): a 4 m bar spinning a quarter turn over the shutter sweeps two
# quarter discs; with the two ends alone (the default) the ray tracers move its ends along chords and
# it shrinks to 0.71 of its length half way, so it misses the discs' rims (covered area, mean alpha,
# about two thirds of the 64 sub-frames': measured 0.0215 Whitted, 0.0218 path tracer against 0.0327);
# with 9 steps (8 chords of the arc) the streak matches the sub-frames' (IoU of alpha > 0.02 >= 0.93,
# measured 0.943 Whitted, 0.969 path tracer; mean alpha within 0.002, measured 0.0006 and 0.0001).
# Without --shutter-steps the steps are chosen from the largest turn over the shutter (a step per 12
# degrees): the quarter turn gets 9, bit for bit the --shutter-steps 9 image (and not the 2 steps'),
# and a translation (the moving box, the camera's 5.7-degree pan) gets 2, bit for bit --shutter-steps 2
view_scene "$TMP/spin.x3d" "<Transform DEF='Bar'>$(x3d_shape "<Box size='4 0.3 0.3'/>")</Transform>" "$(x3d_clock 1)" \
    "<OrientationInterpolator DEF='Spin' key='0 0.25 0.5 0.75 1' keyValue='0 0 1 0 0 0 1 1.5707963 0 0 1 3.1415926 0 0 1 4.712389 0 0 1 6.2831853'/>" \
    "$(x3d_drive Spin Bar rotation)"
usage "--shutter-steps alone" "--shutter-steps belongs to --shutter" --shutter-steps 4
usage "--shutter-steps 1" "--shutter-steps" --shutter 0.1 --shutter-steps 1
usage "--shutter-steps 10" "--shutter-steps" --shutter 0.1 --shutter-steps 10
# curve STEM SCENE SIZE SHUTTER STEPS SUB-ARGS...: renders $TMP/SCENE (SIZE x SIZE pixels, --at 0 over
# SHUTTER) into ${b}_STEM_sub (sub-frames, and SUB-ARGS), _chord (two steps) and _arc
# (STEPS steps), and sets sa, ca and aa (their mean alpha) and iou (arc against sub, alpha > 0.02)
curve() {
    local stem=$1 scene=$2 px=$3 shutter=$4 steps=$5
    shift 5
    rend "$stem" "$scene" sub -w "$px" -h "$px" --at 0 --shutter "$shutter" --sub-frames "$@"
    rend "$stem" "$scene" chord -w "$px" -h "$px" --at 0 --shutter "$shutter" --shutter-steps 2
    rend "$stem" "$scene" arc -w "$px" -h "$px" --at 0 --shutter "$shutter" --shutter-steps "$steps"
    sa=$(mean_alpha "$TMP/${b}_${stem}_sub.exr")
    ca=$(mean_alpha "$TMP/${b}_${stem}_chord.exr")
    aa=$(mean_alpha "$TMP/${b}_${stem}_arc.exr")
    iou=$("$EXR_BLUR" iou 0.02 "$TMP/${b}_${stem}_arc.exr" 0.02 "$TMP/${b}_${stem}_sub.exr" "$TMP/${b}_${stem}_sub.exr")
}
# curve_checks WHAT STEPS SUBS TOL MIN_IOU: after curve, the STEPS steps' mean alpha is the SUBS
# sub-frames' within TOL and their IoU at least MIN_IOU
curve_checks() {
    echo "$b $1: mean alpha 2 steps $ca, $2 steps $aa, $3 sub-frames $sa; IoU of $2 steps against the sub-frames $iou"
    near "$aa" "$sa" "$4" || fail "$b $1: $2 steps cover $aa, not the sub-frames' $sa within $4"
    gt "$iou" "$5" || fail "$b $1: $2 steps against the sub-frames: IoU $iou < $5"
}
spin_checks() {
    curve spin spin.x3d 96 0,0.25 9 --shutter-samples 64
    rend spin spin.x3d auto -w 96 -h 96 --at 0 --shutter 0,0.25
    grep -qF "motion blur: 9 time steps (the largest turn over the shutter is 90 degrees" "$TMP/${b}_spin_auto.err" ||
        fail "$b spinning bar: no note on the 9 steps chosen: $(cat "$TMP/${b}_spin_auto.err")"
    "$EXR_EQUAL" "$TMP/${b}_spin_arc.exr" "$TMP/${b}_spin_auto.exr" >/dev/null || fail "$b spinning bar: the default differs from 9 steps"
    "$EXR_EQUAL" "$TMP/${b}_spin_chord.exr" "$TMP/${b}_spin_auto.exr" >/dev/null && fail "$b spinning bar: the default is the 2 steps' image"
    gt "$(awk -v s="$sa" 'BEGIN { print s * 0.8 }')" "$ca" || fail "$b spinning bar: 2 steps cover $ca, not a chord's less than the arc's $sa"
    curve_checks "spinning bar" 9 64 0.002 0.93
}
for_tracers 64 spin_checks

# curved deformation: a 0.6 m square whose vertices a CoordinateInterpolator carries a quarter turn
# round the origin at radius 2 (5 keys: a polyline of 4 chords of the arc) over the shutter 0..1. With
# the two ends alone the ray tracers slide it along the one chord (covered area, mean alpha, two thirds
# of the 64 sub-frames': measured 0.0062 Whitted against 0.0093, IoU 0.30); with 5 steps (the keys'
# times) it follows the polyline the sub-frames sample (mean alpha within 0.0005, measured 0.000005
# Whitted; IoU of alpha > 0.02 >= 0.9, measured 0.93 Whitted, 0.97 path tracer)
morph_square arc '1.70000 -0.30000 0.00000 2.30000 -0.30000 0.00000 2.30000 0.30000 0.00000 1.70000 0.30000 0.00000' \
    '0 0.25 0.5 0.75 1' '1.70000 -0.30000 0.00000 2.30000 -0.30000 0.00000 2.30000 0.30000 0.00000 1.70000 0.30000 0.00000 1.68540 0.37340 0.00000 2.23973 0.60301 0.00000 2.01012 1.15734 0.00000 1.45579 0.92773 0.00000 1.41421 0.98995 0.00000 1.83848 1.41421 0.00000 1.41421 1.83848 0.00000 0.98995 1.41421 0.00000 0.92773 1.45579 0.00000 1.15734 2.01012 0.00000 0.60301 2.23973 0.00000 0.37340 1.68540 0.00000 0.30000 1.70000 0.00000 0.30000 2.30000 0.00000 -0.30000 2.30000 0.00000 -0.30000 1.70000 0.00000'
arc_checks() {
    curve arc arc.x3d 96 0,1 5 --shutter-samples 64
    gt "$(awk -v s="$sa" 'BEGIN { print s * 0.8 }')" "$ca" || fail "$b deforming arc: 2 steps cover $ca, not a chord's less than $sa"
    curve_checks "deforming along an arc" 5 64 0.0005 0.9
}
for_tracers 64 arc_checks

# a curved camera path: the Viewpoint orbits a quarter turn round the box at 12 m (5 keys of position
# and orientation) over the shutter 0..1. With its two ends alone the camera cuts the chord (8.5 m
# from the box half way: the box drawn larger, mean alpha 0.250 against the 16 sub-frames' 0.168);
# with 5 steps it follows the keys' path (mean alpha within 0.005, IoU of alpha > 0.02 >= 0.95;
# measured 0.1678 against 0.1679 and 0.974 Whitted, 0.1679 against 0.1680 and 0.976 path tracer)
view_scene "$TMP/orbit.x3d" "$box" "<Transform translation='3 0 0'>$(x3d_shape "<Sphere radius='0.5'/>" "0.2 0.4 0.8")</Transform>" \
    "$(x3d_clock 1)" \
    "<PositionInterpolator DEF='P' key='0 0.25 0.5 0.75 1' keyValue='0.000000 0.000000 12.000000 4.592201 0.000000 11.086554 8.485281 0.000000 8.485281 11.086554 0.000000 4.592201 12.000000 0.000000 0.000000'/>" \
    "<OrientationInterpolator DEF='O' key='0 0.25 0.5 0.75 1' keyValue='0.000000 1.000000 0.000000 0.000000 0.000000 1.000000 0.000000 0.392699 0.000000 1.000000 0.000000 0.785398 0.000000 1.000000 0.000000 1.178097 0.000000 1.000000 0.000000 1.570796'/>" \
    "$(x3d_drive P V position)" "$(x3d_drive O V orientation)"
orbit_checks() {
    curve orbit orbit.x3d 64 0,1 5
    grep -qF "the moving camera" "$TMP/${b}_orbit_arc.err" || fail "$b orbit: no one render: $(cat "$TMP/${b}_orbit_arc.err")"
    gt "$ca" "$(awk -v s="$sa" 'BEGIN { print s * 1.2 }')" || fail "$b orbit: 2 steps cover $ca, not a chord's more than $sa"
    curve_checks "orbiting camera" 5 16 0.005 0.95
}
for_tracers 32 orbit_checks

# moving emitters light the scene from where they are at each ray's time: a 1 m emissive square 3.4 m
# up (out of view, facing down) slides from x = -1 to 1 over the shutter 0..1, 1 m in front of a 8 m
# wall that the camera faces (no other light: --no-default-light); the lit wall's luminance centroid
# is at the path's middle, the image's centre column 48 (the scene is symmetric about x = 0), within
# 1 px (measured 48.00 Whitted, 47.98 path tracer at 64 spp), not at the open's 39.1 (what the
# emitter's open triangles gave: 39.14); once as a moved Transform (a moving instance) and once as a
# CoordinateInterpolator (a deforming mesh)
emitter_scene() { # emitter_scene FILE SHAPE-COORDINATE LINES...
    {
        echo "<X3D><Scene><Viewpoint DEF='V' position='0 0 12' fieldOfView='0.5'/>"
        x3d_shape "<IndexedFaceSet coordIndex='0 1 2 3 -1'><Coordinate point='-4 -4 0 4 -4 0 4 4 0 -4 4 0'/></IndexedFaceSet>" "0.8 0.8 0.8"
        printf '%s\n' "${@:2}" "$(x3d_clock 1)"
        echo "</Scene></X3D>"
    } >"$TMP/$1.x3d"
}
emitter() { # emitter COORDINATE-ATTRS: the emissive square's Shape
    echo "<Shape><Appearance><Material diffuseColor='0 0 0' emissiveColor='1 1 1'/></Appearance><IndexedFaceSet coordIndex='0 1 2 3 -1'><Coordinate $1/></IndexedFaceSet></Shape>"
}
emitter_scene emit_move "<Transform DEF='L' translation='-1 3.4 1'>$(emitter "point='-0.5 0 -0.5 0.5 0 -0.5 0.5 0 0.5 -0.5 0 0.5'")</Transform>" \
    "<PositionInterpolator DEF='Move' key='0 1' keyValue='-1 3.4 1 1 3.4 1'/>" "$(x3d_drive Move L translation)"
emitter_scene emit_deform "$(emitter "DEF='C' point='-1.5 3.4 0.5 -0.5 3.4 0.5 -0.5 3.4 1.5 -1.5 3.4 1.5'")" \
    "<CoordinateInterpolator DEF='Morph' key='0 1' keyValue='-1.5 3.4 0.5 -0.5 3.4 0.5 -0.5 3.4 1.5 -1.5 3.4 1.5 0.5 3.4 0.5 1.5 3.4 0.5 1.5 3.4 1.5 0.5 3.4 1.5'/>" \
    "$(x3d_drive Morph C set_point)"
emitter_checks() {
    local kind cx co
    for kind in move deform; do
        rend "emit_$kind" "emit_$kind.x3d" open "${size[@]}" --no-default-light --at 0
        rend "emit_$kind" "emit_$kind.x3d" blur "${size[@]}" --no-default-light --at 0 --shutter 0,1
        grep -qF "motion blur: one render, each" "$TMP/${b}_emit_${kind}_blur.err" ||
            fail "$b moving emitter ($kind): no one render: $(cat "$TMP/${b}_emit_${kind}_blur.err")"
        read -r co _ <<<"$("$EXR_BLUR" centroid "$TMP/${b}_emit_${kind}_open.exr")"
        read -r cx _ <<<"$("$EXR_BLUR" centroid "$TMP/${b}_emit_${kind}_blur.exr")"
        echo "$b moving emitter ($kind): lit centroid column $cx blurred, $co at the open (the path's middle: 48)"
        gt 42 "$co" || fail "$b moving emitter ($kind): the open's light is not left of the middle ($co)"
        near "$cx" 48 1.0 || fail "$b moving emitter ($kind): the blurred light's centroid $cx is not the path's middle 48 within 1"
    done
}
for_tracers 64 emitter_checks

# a sequence: frame 6 at 24 fps with --motion-blur (0,1/48) equals --at 0.25 with the same shutter, bit
# for bit (the frame's time opens the shutter; every time sample restarts the accumulation)
b=$1
seq_render "sequence blur" seq moving.x3d "seq_#.exr" --frames 6:7
seq_render "--at blur" seq_at moving.x3d seq_at.exr --at 0.25
"$EXR_EQUAL" "$TMP/seq_6.exr" "$TMP/seq_at.exr" >/dev/null || fail "$b: a blurred sequence frame differs from --at with the same shutter"
"$EXR_EQUAL" "$TMP/seq_6.exr" "$TMP/seq_7.exr" >/dev/null && fail "$b: blurred frames 6 and 7 are the same image"

[ "$fails" -eq 0 ] || exit 1
rm -rf "$TMP"
echo "ok: $*"
