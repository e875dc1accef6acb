#!/bin/bash
# warp_orbit.sh — the page's estimate during an orbit, measured (issue 36's "quality of the
# estimate"; docs/WEB.md, "The estimate during an orbit"). A measurement, not a test: ctest's
# browser_orbit (browser_test.sh orbit) checks the held, timing-free variant.
#   tests/browser/warp_orbit.sh BUILD SCENE OUTDIR [W H] [-- sy web options...]
# sy web SCENE --listen 127.0.0.1:0 with the options (default: -b raster --delay-ms 50, a 100 ms
# round trip), then headless chromium at W x H (default 480 x 360) orbiting at SY_ORBIT_DEG_S (10)
# degrees a second for SY_ORBIT_S (6) seconds (browser.mjs orbit; its other SY_ORBIT_* apply, and
# SY_ORBIT_QUERY is added to the page's URL, e.g. '?level=1'): each captured estimate against the
# server's exact frame of its view. Prints browser.mjs's JSON (SSIM median, 10th percentile and
# minimum over the estimates, the largest share of a canvas the hole fill left empty, per capture
# its time, views and SSIM). OUTDIR keeps the pairs (est_K.png, true_K.png) and the server's log.
set -u
BUILD=$1 SCENE=$2 OUT=$3
shift 3
W=480 H=360
if [ $# -ge 2 ] && [ "$1" != -- ]; then W=$1 H=$2; shift 2; fi
[ "${1:-}" = -- ] && shift
opts=("$@")
[ ${#opts[@]} = 0 ] && opts=(-b raster --delay-ms 50)
mkdir -p "$OUT"
"$BUILD/apps/sy/sy" web "$SCENE" --listen 127.0.0.1:0 "${opts[@]}" >"$OUT/log" 2>"$OUT/err" &
pid=$!
trap 'kill -TERM $pid 2>/dev/null; wait $pid 2>/dev/null' EXIT
. "$(dirname "$0")/../support/wait.sh"
wait_until $pid grep -q 'http://' "$OUT/log"
url=$(grep -o 'http://[^ ]*' "$OUT/log" | head -1)
[ -n "$url" ] || { echo "sy web printed no URL: $(cat "$OUT/err")"; exit 1; }
SY_PNG_SSIM="$BUILD/tests/png_ssim" node "$BUILD/tests/browser/browser.mjs" orbit "$url${SY_ORBIT_QUERY:-}" "$OUT" $W $H
