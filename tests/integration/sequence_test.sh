#!/usr/bin/env bash
# sequence_test.sh — sy render --frames A:B[:STEP] (image sequences, issue 35):
#   - a 6-frame EXR and PNG sequence of BoxAnimated at 24 fps: every frame written, frame k equal
#     pixel for pixel (exr_equal) to `sy render --at k/24` of a fresh load (the same loaded scene
#     moved frame by frame gives what a single render at that time gives); frames differ over time
#   - --frames 0:8:4: frames 0, 4, 8 only; --fps 12 changes the time of a frame
#   - --resume: an existing frame is left alone (its file is not rewritten), the missing ones written
#   - the path tracer: every frame has its --spp from sample 0 and equals a fresh --at render, also a
#     frame where nothing moved (sy_context_restart)
#   - usage errors (status 2, nothing written): -o without '#', --frames N (names --repeat), a bad
#     range (5:2, 1:, a:b, 0:4:0), --fps without --frames, --frames with --at, --frame (names --frames
#     and --at)
#   - video (where sy was built with SY_WITH_VIDEO and tests/support/video_probe is given): 48 frames
#     at 24 fps to .mp4 (H.264) and .webm (VP9) read back through libavformat as 48 frames at 24 fps,
#     decoded frame 24's mean colour within 3 (of 255) of `sy render --at 1 -o .png`'s; a video
#     without --frames or with --resume is a usage error
# Usage: sequence_test.sh SY TESTDATA_DIR TMP EXR_EQUAL [VIDEO_PROBE]
SY=$1
DATA=$2
TMP=$3
EXR_EQUAL=$4
VIDEO_PROBE=${5:-}
# fail, run NAME CMD..., run_ok LABEL NAME CMD... (and $fails, $rc)
. "$(dirname "${BASH_SOURCE[0]}")/../support/check.sh"
rm -rf "$TMP"
mkdir -p "$TMP"

# usage errors need no test data (the built-in demo scene)
mkdir -p "$TMP/u"
usage() { usage_error "$1" "$2" "$SY" render demo -b whitted -w 16 -h 16 "${@:3}"; } # usage LABEL EXPECTED-TEXT ARGS...
usage "no #" "--frames needs -o with a run of '#'" --frames 0:2 -o "$TMP/u/x.png"
usage "--frames N" "the cluster's repeat count is --repeat N" --frames 3 -o "$TMP/u/x_##.png"
for bad in 5:2 1: a:b 0:4:0 -1:2 0:2:; do
    usage "--frames $bad" "--frames: '$bad'" --frames "$bad" -o "$TMP/u/x_##.png"
done
usage "--fps alone" "--fps and --resume belong to --frames" --fps 30 -o "$TMP/u/x.png"
usage "--resume alone" "--fps and --resume belong to --frames" --resume -o "$TMP/u/x.png"
usage "--fps 0" "--fps: '0'" --frames 0:1 --fps 0 -o "$TMP/u/x_##.png"
usage "--frames and --at" "--at is one time" --frames 0:1 --at 1 -o "$TMP/u/x_##.png"
usage "--frame" "the option that begins so is: --frames; one time on the scene clock: --at SECONDS" --frame 3 -o "$TMP/u/x.png"
usage "video without --frames" "a video (-o .mp4, .webm) needs --frames A:B" -o "$TMP/u/x.mp4"
usage "video --resume" "a video is written whole" --frames 0:1 --resume -o "$TMP/u/x.webm"
[ -z "$(ls -A "$TMP/u")" ] || fail "a refused sequence left files: $(ls "$TMP/u")"

BOXANIM="$DATA/gltf/BoxAnimated/glTF-Binary/BoxAnimated.glb"
if [ ! -f "$BOXANIM" ]; then
    echo "skip: the BoxAnimated sequence checks ($BOXANIM absent)"
    [ "$fails" -eq 0 ] || exit 1
    exit 77
fi
run_ok "exr sequence" seq_exr "$SY" render "$BOXANIM" -b whitted -w 48 -h 36 --frames 0:5 -o "$TMP/f_####.exr"
grep -qF "frames 0..5 step 1 at 24 fps: 6 written, 0 skipped" "$TMP/seq_exr.out" || fail "exr sequence: $(cat "$TMP/seq_exr.out")"
[ ! -s "$TMP/seq_exr.err" ] || fail "exr sequence: not quiet off a terminal: $(cat "$TMP/seq_exr.err")"
for k in 0 1 2 3 4 5; do
    f=$TMP/f_000$k.exr
    [ -f "$f" ] || { fail "frame $k: $f not written"; continue; }
    run_ok "--at $k/24" at_$k "$SY" render "$BOXANIM" -b whitted -w 48 -h 36 --at "$(awk "BEGIN{printf \"%.17g\", $k/24}")" \
        -o "$TMP/at_$k.exr"
    "$EXR_EQUAL" "$f" "$TMP/at_$k.exr" >/dev/null 2>&1 || fail "frame $k differs from sy render --at $k/24"
done
"$EXR_EQUAL" "$TMP/f_0000.exr" "$TMP/f_0005.exr" >/dev/null 2>&1 && fail "frames 0 and 5 are the same image"
ls "$TMP" | grep -q '^\.' && fail "temporary files left: $(ls -a "$TMP")"
run_ok "png sequence" seq_png "$SY" render "$BOXANIM" -b whitted -w 48 -h 36 --frames 0:8:4 --fps 12 -o "$TMP/p_##.png"
[ -f "$TMP/p_00.png" ] && [ -f "$TMP/p_04.png" ] && [ -f "$TMP/p_08.png" ] && [ ! -e "$TMP/p_01.png" ] ||
    fail "png --frames 0:8:4: $(ls "$TMP" | grep '^p_')"
[ "$(head -c 8 "$TMP/p_04.png" | od -An -tx1 | tr -d ' ')" = 89504e470d0a1a0a ] || fail "p_04.png is not a PNG"
# --resume: frame 1 is kept as it was (a marker file), 0 and 2 are written
mkdir -p "$TMP/r"
echo keep >"$TMP/r/r_1.exr"
run_ok "--resume" seq_resume "$SY" render "$BOXANIM" -b whitted -w 48 -h 36 --frames 0:2 --resume -o "$TMP/r/r_#.exr"
[ "$(cat "$TMP/r/r_1.exr")" = keep ] || fail "--resume rewrote an existing frame"
[ -f "$TMP/r/r_0.exr" ] && [ -f "$TMP/r/r_2.exr" ] || fail "--resume: missing frames not written: $(ls "$TMP/r")"
grep -qF "2 written, 1 skipped" "$TMP/seq_resume.out" || fail "--resume: $(cat "$TMP/seq_resume.out")"
"$EXR_EQUAL" "$TMP/r/r_2.exr" "$TMP/at_2.exr" >/dev/null 2>&1 || fail "--resume: frame 2 differs from --at 2/24"
# a progressive back-end renders its --spp per frame from sample 0 (sy_context_restart), moved or
# not: frame k is bit for bit a fresh `sy render --at k/24` (the same samples), also where nothing
# moved since the frame before (past the clip's end at 3.7 s: 199, 200), which before the restart
# went on accumulating (4 samples, other random numbers)
run_ok "pathtracer sequence" seq_pt "$SY" render "$BOXANIM" -b pathtracer --spp 2 -w 24 -h 18 --frames 1:2 -o "$TMP/pt_#.exr"
run_ok "pathtracer sequence, still" seq_pt2 "$SY" render "$BOXANIM" -b pathtracer --spp 2 -w 24 -h 18 --frames 199:200 \
    -o "$TMP/pt_#.exr"
for k in 1 2 199 200; do
    "$SY" info "$TMP/pt_$k.exr" | grep -qF '"sy:samples": "2"' ||
        fail "pathtracer frame $k: not 2 samples: $("$SY" info "$TMP/pt_$k.exr" | grep sy:samples)"
    run_ok "pathtracer --at $k/24" pt_at_$k "$SY" render "$BOXANIM" -b pathtracer --spp 2 -w 24 -h 18 \
        --at "$(awk "BEGIN{printf \"%.17g\", $k/24}")" -o "$TMP/pt_at_$k.exr"
    "$EXR_EQUAL" "$TMP/pt_$k.exr" "$TMP/pt_at_$k.exr" >/dev/null 2>&1 ||
        fail "pathtracer frame $k differs from a fresh sy render --at $k/24"
done
# video: 2 s at 24 fps, read back through libavformat (video_probe)
if [ -n "$VIDEO_PROBE" ]; then
    run_ok "png --at 1" at_png "$SY" render "$BOXANIM" -b whitted -w 64 -h 48 --at 1 -o "$TMP/at1.png"
    for kind in mp4:h264 webm:vp9; do
        ext=${kind%%:*}
        run_ok "video .$ext" vid_$ext "$SY" render "$BOXANIM" -b whitted -w 64 -h 48 --frames 0:47 -o "$TMP/anim.$ext"
        "$VIDEO_PROBE" "$TMP/anim.$ext" 24 "$TMP/at1.png" >"$TMP/probe_$ext.out" 2>&1 ||
            fail "video .$ext: not readable: $(cat "$TMP/probe_$ext.out")"
        grep -qxF "frames 48 fps 24 codec ${kind##*:}" "$TMP/probe_$ext.out" ||
            fail "video .$ext: want 48 frames at 24 fps (${kind##*:}): $(cat "$TMP/probe_$ext.out")"
        awk '/^mean video/ { for (c = 0; c < 3; ++c) { d = $(3 + c) - $(7 + c); if (d < -3 || d > 3) bad = 1 } ok = 1 }
             END { exit !(ok && !bad) }' "$TMP/probe_$ext.out" ||
            fail "video .$ext: frame 24's mean colour is not the PNG's: $(grep mean "$TMP/probe_$ext.out")"
    done
    ls -a "$TMP" | grep -q '\.tmp-' && fail "video: temporary files left: $(ls -a "$TMP" | grep tmp)"
else
    echo "skip: the video checks (sy built without SY_WITH_VIDEO: no video_probe)"
fi

[ "$fails" -eq 0 ] || { echo "$fails failure(s)"; exit 1; }
echo "sequence_test: all checks passed"
