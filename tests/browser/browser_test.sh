#!/bin/bash
# browser_test.sh — sy web in a real browser: Debian's chromium, headless, driven over the DevTools
# protocol by browser.mjs (playwright-core, installed from npm into the build tree at build time).
#
#   browser_test.sh stream SY PNG_IOU MODULES_DIR SCENE
#     sy web SCENE -b raster: the canvas shows the same coverage as `sy render -b raster` at the
#     canvas size (IoU >= 0.95), and a drag across the canvas changes the view.
#   browser_test.sh client SY PNG_IOU MODULES_DIR SCENE
#     sy web SCENE --client-render: the three.js page fetches exactly the objects the culling
#     service answered (each once, no other), and what it draws covers what `sy render -b raster`
#     covers for the same (initial) view (IoU >= 0.95); then with a budget of a quarter of the
#     scene's triangles: again exactly the answer's objects, fewer than all, drawn within it.
#
# MODULES_DIR holds browser.mjs and node_modules/playwright-core. Skipped (77, with the reason)
# without chromium, node, playwright-core (npm ci failed: no network at build time) or the scene;
# with SY_REQUIRE_BROWSER=1 in the environment (CI: .ci/run sets it) each of those is a failure
# instead, so that the browser coverage is never lost silently.
set -u
mode=$1 SY=$2 PNG_IOU=$3 MODULES=$4 SCENE=$5
W=480 H=360
skip() {
    if [ "${SY_REQUIRE_BROWSER:-0}" = 1 ]; then echo "FAIL: SY_REQUIRE_BROWSER=1 but the test cannot run: $*"; exit 1; fi
    echo "SKIP: $*"
    exit 77
}
[ -f "$SCENE" ] || skip "$SCENE is absent (the test data in ../shared/testdata)"
CHROMIUM=${SY_CHROMIUM:-/usr/bin/chromium}
[ -x "$CHROMIUM" ] || skip "chromium is not installed ($CHROMIUM; apt-get install chromium)"
command -v node >/dev/null || skip "node is not installed (apt-get install nodejs)"
[ -d "$MODULES/node_modules/playwright-core" ] ||
    skip "playwright-core is not in $MODULES/node_modules (npm ci failed at build time: no network?)"
out=$(mktemp -d)
pid=
cleanup() {
    [ -n "$pid" ] && kill -TERM "$pid" 2>/dev/null && wait "$pid" 2>/dev/null
    rm -rf "$out"
}
trap cleanup EXIT
fail=0
bad() { echo "FAIL: $*"; fail=1; }

args=(web "$SCENE" -b raster --listen 127.0.0.1:0)
[ "$mode" = client ] && args+=(--client-render)
"$SY" "${args[@]}" >"$out/log" 2>"$out/err" &
pid=$!
. "$(dirname "$0")/../support/wait.sh" # wait_until: states, never sleeps (hang guard only)
wait_until $pid grep -q 'http://' "$out/log"
url=$(grep -o 'http://[^ ]*' "$out/log" 2>/dev/null | head -1)
[ -n "$url" ] || { echo "FAIL: sy web printed no URL: $(cat "$out/log" "$out/err")"; exit 1; }
echo "sy web: $url"

# server_said: what sy web wrote to stderr that explains a failure: a sanitizer's report from its
# first line (the error and the stack), else the last lines
server_said() {
    if grep -q -E 'ERROR: (Address|Leak)Sanitizer|runtime error:' "$out/err"; then
        sed -n -E '/ERROR: (Address|Leak)Sanitizer|runtime error:/,$p' "$out/err" | head -60
    else
        tail -5 "$out/err"
    fi
}
browse() { # browse URL: the browser run into $out; exit on failure
    SY_CHROMIUM=$CHROMIUM node "$MODULES/browser.mjs" "$mode" "$1" "$out" $W $H >"$out/browser.json"
    local rc=$?
    cat "$out/browser.json"
    [ $rc = 77 ] && skip "$(cat "$out/browser.json")"
    [ $rc = 0 ] || { echo "FAIL: the browser run failed (exit $rc); sy web said: $(server_said)"; exit 1; }
}
# fetched_check [BUDGET]: what the page fetched is each object of the answer once, nothing else;
# with BUDGET, the answer is cut at it and leaves objects out
fetched_check() {
    node -e '
      const s = JSON.parse(require("fs").readFileSync(process.argv[1], "utf8")), budget = Number(process.argv[2] || 0);
      const req = [...new Set(s.requested)].sort((a, b) => a - b), got = [...s.fetched].sort((a, b) => a - b);
      const dup = got.filter((v, i) => i > 0 && got[i - 1] === v);
      const extra = got.filter((v) => !req.includes(v)), missing = req.filter((v) => !got.includes(v));
      console.log(`${budget ? "budget " + budget : "default budget"}: answer ${req.length} of ${s.total_objects} objects; ` +
                  `fetched ${got.length}; drawn ${s.visible.length} objects, ${s.triangles} of ${s.total_triangles} ` +
                  `triangles; ${s.bytes} GLB bytes`);
      const errs = [];
      if (dup.length) errs.push(`fetched twice: ${dup.slice(0, 10)}`);
      if (extra.length) errs.push(`fetched but not in the answer: ${extra.slice(0, 10)}`);
      if (missing.length) errs.push(`in the answer but not fetched: ${missing.slice(0, 10)}`);
      if (s.errors && s.errors.length) errs.push(`page errors: ${s.errors}`);
      if (budget && s.triangles > budget) errs.push(`${s.triangles} triangles drawn over the budget ${budget}`);
      if (budget && req.length >= s.total_objects) errs.push("the budget left no object out (the check would prove nothing)");
      if (errs.length) { console.log("FAIL: " + errs.join("; ")); process.exit(1); }
    ' "$out/client.json" "${1:-}" || fail=1
}

browse "$url"
# The reference: sy render with the rasterizer at the canvas size, the scene's default view (the
# view sy web starts with, and the client page asks the server for).
"$SY" render "$SCENE" -b raster -w $W -h $H -o "$out/ref.png" >/dev/null 2>"$out/render.err" ||
    { echo "FAIL: sy render: $(cat "$out/render.err")"; exit 1; }
# a streamed canvas is JPEG (noise around the background): a wider tolerance than WebGL's
tol=8
[ "$mode" = stream ] && tol=24
res=$("$PNG_IOU" "$out/canvas.png" "$out/ref.png" --min 0.95 --tol $tol)
rc=$?
echo "canvas against sy render -b raster: $res"
[ $rc = 0 ] || bad "the canvas' coverage differs from sy render -b raster (IoU below 0.95)"

if [ "$mode" = stream ]; then
    res=$("$PNG_IOU" "$out/canvas.png" "$out/dragged.png" --tol $tol)
    echo "before against after the drag: $res"
    iou=$(echo "$res" | awk '{print $2}')
    awk -v v="$iou" 'BEGIN { exit !(v < 0.98) }' || bad "a drag did not change the view (IoU $iou against before)"
else
    fetched_check
    # a budget of a quarter of the scene's triangles: the page fetches just what the cut answer lists
    total=$(node -e 'console.log(JSON.parse(require("fs").readFileSync(process.argv[1], "utf8")).total_triangles)' "$out/client.json")
    budget=$((total / 4))
    case $url in *\?*) burl="$url&budget=$budget" ;; *) burl="$url?budget=$budget" ;; esac
    browse "$burl"
    fetched_check $budget
fi
# the server must have lived through it all, without a sanitizer's report
kill -0 $pid 2>/dev/null || bad "sy web is no longer running: $(server_said)"
grep -q -E 'ERROR: (Address|Leak)Sanitizer|runtime error:' "$out/err" && bad "sy web: $(server_said)"
[ $fail = 0 ] && echo "ok: sy web $mode in chromium"
exit $fail
