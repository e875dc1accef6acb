#!/bin/bash
# first_picture.sh — time to first picture on the sy web page (issue 37), a measurement, not a test
# (no bound is checked: the brief keeps times out of tests). For each back-end: sy web SCENE -b
# BACKEND, wait for its "ready" line (the back-end translated the scene), open the page in headless
# chromium at W x H (browser.mjs first) and print the page's clock from the navigation's start to
# the first display frame showing a server frame (its size: the governor's coarse first frame) and
# to the first full-size frame. SY_FIRST_WARM=1: a browser in use (browser.mjs first: one page of
# the origin and a WebGL2 context before), else the fresh browser's first page.
#   first_picture.sh SY MODULES_DIR SCENE [W H [BACKEND...]]   (default 1024 768 raster whitted pathtracer)
# MODULES_DIR: the build's tests/browser (browser.mjs and node_modules/playwright-core).
set -u
SY=$1 MODULES=$2 SCENE=$3 W=${4:-1024} H=${5:-768}
shift 5 2>/dev/null || shift $#
backends=("$@")
[ ${#backends[@]} -eq 0 ] && backends=(raster whitted pathtracer)
CHROMIUM=${SY_CHROMIUM:-/usr/bin/chromium}
out=$(mktemp -d)
pid=
cleanup() { [ -n "$pid" ] && kill -TERM "$pid" 2>/dev/null && wait "$pid" 2>/dev/null; rm -rf "$out"; }
trap cleanup EXIT
for be in "${backends[@]}"; do
    "$SY" web "$SCENE" -b "$be" -w "$W" -h "$H" --listen 127.0.0.1:0 >"$out/log" 2>"$out/err" &
    pid=$!
    for _ in $(seq 1 600); do grep -q "ready:\|warming up" "$out/err" && break; kill -0 $pid 2>/dev/null || break; sleep 0.1; done
    url=$(grep -o 'http://[^ ]*' "$out/log" | head -1)
    ready=$(grep -o "ready: .*" "$out/err" | head -1)
    res=$(SY_CHROMIUM=$CHROMIUM SY_FIRST_WARM=${SY_FIRST_WARM:-} node "$MODULES/browser.mjs" first "$url" "$out" "$W" "$H")
    [ -n "${SY_BROWSER_KEEP:-}" ] && cp "$out/first.png" "$SY_BROWSER_KEEP/first_$be.png"
    echo "$be: $res ($ready)"
    kill -TERM $pid 2>/dev/null; wait $pid 2>/dev/null
    pid=
done
