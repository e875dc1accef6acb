#!/usr/bin/env bash
# view_test.sh SY PNG_COMPARE TMPDIR — the interactive viewer in a real window under Xvfb: `sy view
# demo` shows frames and its screenshot (read back from the window's framebuffer) matches `sy
# render` of the same view with the same tone mapping, within 2 of 255 per channel (the screenshot
# goes through an sRGB decode / encode round trip). Skipped (77) when xvfb-run is not installed or
# the viewer was built without GLFW.
set -u
SY=$1
CMP=$2
TMP=$3
rm -rf "$TMP"
mkdir -p "$TMP"
if ! command -v xvfb-run >/dev/null 2>&1; then
    echo "skipped: xvfb-run is not installed (Debian package xvfb)"
    exit 77
fi
if ! "$SY" 2>&1 | grep -q "sy view"; then
    echo "skipped: sy was built without GLFW/OpenGL (no 'sy view')"
    exit 77
fi
timeout 120 xvfb-run -a -s "-screen 0 1024x768x24" "$SY" view demo -w 320 -h 180 --frames 5 \
    --screenshot "$TMP/view.png" >"$TMP/view.out" 2>"$TMP/view.err"
rc=$?
if [ $rc -ne 0 ]; then
    echo "FAIL: sy view exited with status $rc: $(cat "$TMP/view.err")"
    exit 1
fi
"$SY" render demo -b whitted -w 320 -h 180 --tonemap aces -o "$TMP/render.png" >/dev/null || exit 1
"$CMP" "$TMP/view.png" "$TMP/render.png" 2 50 || {
    echo "FAIL: the viewer's window does not show the rendered image"
    exit 1
}
# the path tracer with its pixel display filter (issue 7): applied on the render thread's context
timeout 120 xvfb-run -a -s "-screen 0 1024x768x24" "$SY" view demo -b pathtracer --filter pixel --threshold 0.02 \
    -w 64 -h 48 --frames 6 --screenshot "$TMP/view_filter.png" >"$TMP/view_filter.out" 2>"$TMP/view_filter.err"
rc=$?
if [ $rc -ne 0 ] || [ ! -s "$TMP/view_filter.png" ] || ! grep -q "filter pixel t=0.02" "$TMP/view_filter.out"; then
    echo "FAIL: sy view -b pathtracer --filter pixel: status $rc: $(cat "$TMP/view_filter.out" "$TMP/view_filter.err")"
    exit 1
fi
# an unknown filter is refused before any window opens, naming it
if "$SY" view demo -b pathtracer --filter bogus --frames 1 2>"$TMP/badf.err"; then
    echo "FAIL: sy view accepted an unknown filter"
    exit 1
fi
grep -q bogus "$TMP/badf.err" || { echo "FAIL: the error does not name the filter"; exit 1; }
# a back-end that does not exist is refused before any window opens
if "$SY" view demo -b nosuchbackend --frames 1 2>"$TMP/bad.err"; then
    echo "FAIL: sy view accepted an unknown back-end"
    exit 1
fi
grep -q nosuchbackend "$TMP/bad.err" || { echo "FAIL: the error does not name the back-end"; exit 1; }
echo "integration_view: ok"
