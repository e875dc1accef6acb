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
#   browser_test.sh client SY PNG_IOU MODULES_DIR SCENE MIN_IOU LUM
#     a textured model: the coverage IoU at least MIN_IOU and the canvas' mean luminance within
#     LUM (relative) of sy render -b raster's (LUM "print": printed, not checked), the objects
#     fetched as above (no budget run).
#   browser_test.sh client_timeline SY PNG_IOU MODULES_DIR SCENE
#     an animated scene's client-render page at two times of the server's clock (the page's
#     timeline: WebSocket "time", then GET /api/pose): each canvas covers what `sy render -b raster
#     --at T` covers (IoU >= 0.95), and the two differ (IoU < 0.98).
#   browser_test.sh tree SY PNG_IOU MODULES_DIR generated
#     a generated glTF (a triangle and a group "flat" of 12,000 empty nodes), a 960 x 600 page: the
#     tree lists "flat" closed with its 12,000 children; its ▸ lists the first 512 and a "… 11488
#     more" row, which lists the next 512; asking the tree again keeps "flat" expanded (its first
#     page); ▾ closes it (browser.mjs tree checks each step).
#   browser_test.sh tools SY PNG_IOU MODULES_DIR SCENE
#     sy web SCENE -b raster, a 960 x 600 page: a click on a covered pixel picks its node (the
#     properties name it) and selects it; unticking it in the tree changes the streamed canvas
#     there (mean abs diff > 30 in a 9 x 9 box) and a pick there (one that does not select) no
#     longer names it; ticking it brings the picture back as it was while selected (< 4; 0.0
#     measured); a section plane changes > 0.5% of the canvas; its caps on in
#     magenta make > 0.2% of the canvas magenta (and 10 x what was before); two clicks
#     while measuring give the distance of the two picked points (and, with a plane added, the
#     second point's signed distance to it); the help opens; the environment menu offers scene,
#     studio and none, none and studio each change > 5% of the canvas and the scene's world again
#     brings it back (< 1% changed); the screenshot
#     button downloads a JPEG; synthetic touch pinch and drag send inputs. Then sy web
#     --read-only: the page hides the planes, disables the check boxes, shows its badge; a click
#     selects nothing; a visibility change sent anyway is refused (logged) and changes nothing.
#   browser_test.sh warp SY PNG_IOU MODULES_DIR SCENE
#     sy web SCENE -b raster --delay-ms 100 (100 ms added each way): a scripted drag on the
#     warping page answers at least 75% of its inputs by the estimate, before any server frame
#     answers them (without the warp none is: the check can fail; an order of events, not a
#     time), and the page without the warp (?warp=0) needs at least the added round trip, 200 ms
#     (the delay is there: a lower bound, which load cannot break). The distributions of both
#     are printed, never compared (two runs on a shared machine; the brief keeps speed out of
#     tests); no absolute bound is checked either: on two cores shared with the server and other
#     work (load average 20-30), SwiftShader's display frames and Chromium's input queue stall
#     for hundreds of ms now and then (medians with the warp of 108 to 295 ms were measured,
#     without it 383 to 564 ms). The warped estimate of a 12-pixel drag differs from the
#     server's frame of the same view by a mean absolute difference below 6 (0..255); made-up
#     bad frames sent to the page are each counted for their reason and leave the canvas as it was.
#   browser_test.sh orbit SY PNG_SSIM MODULES_DIR SCENE
#     sy web SCENE -b raster: the page's estimate while its references are held (sy.hold) and the
#     page orbits 10 degrees in a second (browser.mjs orbit, SY_ORBIT_HOLD=1; the warp's level held
#     at 1, ?level=1: what is drawn does not depend on the machine's speed; then again at level 3,
#     stride 8 at half the canvas' resolution, the hole fill at that resolution and then scaled),
#     captured every 100 ms:
#     each capture is an estimate, the hole fill leaves no pixel of it empty (before the fill's
#     rings reached 1024 pixels, up to 1.9 % of the canvas was left black at 7-10 degrees), and its
#     SSIM against the server's exact frame of the same view (png_ssim) is at least 0.88 in every
#     capture and 0.92 at the median (0.910-0.958 and 0.940 measured; the issue's 0.9 is asked of
#     the median of a live orbit: tests/browser/warp_orbit.sh, docs/WEB.md). Level 3 measured 0.914
#     min, 0.939 median; with the fill at the canvas' resolution (until it was filled at the warp's
#     own), 0.871 and 0.899: bilinear taps of the half-size warp took its empty texels' black into
#     the edges of what it covered.
#   browser_test.sh video SY PNG_IOU MODULES_DIR SCENE
#     sy web SCENE -b raster: for each codec this chromium's WebCodecs decodes (none: skipped with
#     that reason), the video page's canvas matches the JPEG page's at the same view within a mean
#     absolute difference of 6 (0..255; the bound of the warp's check: both are lossy codings of
#     the same frame, JPEG at quality 80 and the codec at quantizer 36); its stream is of that
#     codec, decoded without errors or refused frames, and a drag and back are answered by more
#     frames, most of them delta frames.
#   browser_test.sh timeline SY PNG_IOU MODULES_DIR SCENE
#     sy web SCENE (an animated one) -b raster: the page shows the timeline; scrubbing from the
#     clips' start to 16% of their range changes the streamed canvas (mean abs diff > 2), scrubbing
#     back brings it back (< 1.5: the same JPEG of the same pose); space plays (the server's clock
#     advances) and pauses; times out of range and not numbers are refused with a log line each.
#   browser_test.sh converge SY PNG_IOU MODULES_DIR SCENE
#     sy web SCENE -b pathtracer --quality 95, a 320 x 240 page left still: the page shows the
#     server's accumulated frames (docs/WEB.md, "Warping"), so the canvas converges: its noise (mean
#     absolute difference to the mean of the four neighbours) once the frames have 16 times the
#     first full-size frame's samples (at least 64) is below 0.7 of that first frame's; no frame
#     is refused, and the refinements came without their depth channel (SAME_DEPTH) and were
#     warpable with the one before. Quality 95: at the default 80 JPEG smooths most of the early
#     frames' noise away and the measure is mostly the picture's own detail (ratios 0.6-0.73 at 80,
#     one CI run failed at 0.73; 0.16-0.35 at 95, 0.31-0.32 under two busy loops).
#   The warp test runs with ?video=0: its made-up bad frames are JPEG frames; the tools test too: it
#   compares canvases before and after, and a video frame's pixels depend on the frames before it.
#
# MODULES_DIR holds browser.mjs and node_modules/playwright-core. Skipped (77, with the reason)
# without chromium, node, playwright-core (npm ci failed: no network at build time) or the scene;
# with SY_REQUIRE_BROWSER=1 in the environment (CI: .ci/run sets it) each of those is a failure
# instead, so that the browser coverage is never lost silently. SY_KEEP_OUT=DIR keeps a copy of the
# run's folder (screenshots, canvases, logs) in DIR for a look at a failure.
set -u
mode=$1 SY=$2 PNG_IOU=$3 MODULES=$4 SCENE=$5
MIN_IOU=${6:-0.95} LUM=${7:-} # client: the coverage IoU asked for; the mean luminance's relative tolerance (none: not checked)
W=480 H=360
[ "$mode" = tools ] || [ "$mode" = timeline ] || [ "$mode" = tree ] && W=960 H=600 # the panel shows beside the canvas from 600 pixels on
[ "$mode" = converge ] && W=320 H=240 # the path tracer on two shared cores
skip() {
    if [ "${SY_REQUIRE_BROWSER:-0}" = 1 ]; then echo "FAIL: SY_REQUIRE_BROWSER=1 but the test cannot run: $*"; exit 1; fi
    echo "SKIP: $*"
    exit 77
}
[ "$SCENE" = demo ] || [ "$mode" = tree ] || [ -f "$SCENE" ] || skip "$SCENE is absent (the test data in ../shared/testdata)"
CHROMIUM=${SY_CHROMIUM:-/usr/bin/chromium}
[ -x "$CHROMIUM" ] || skip "chromium is not installed ($CHROMIUM; apt-get install chromium)"
command -v node >/dev/null || skip "node is not installed (apt-get install nodejs)"
[ -d "$MODULES/node_modules/playwright-core" ] ||
    skip "playwright-core is not in $MODULES/node_modules (npm ci failed at build time: no network?)"
out=$(mktemp -d)
pid=
cleanup() {
    [ -n "$pid" ] && kill -TERM "$pid" 2>/dev/null && wait "$pid" 2>/dev/null
    [ -n "${SY_KEEP_OUT:-}" ] && { cp -r "$out" "$SY_KEEP_OUT"; } ; rm -rf "$out"
}
trap cleanup EXIT
fail=0
bad() { echo "FAIL: $*"; fail=1; }

if [ "$mode" = tree ]; then # a generated scene: a triangle and a group "flat" of 12,000 empty nodes
    SCENE=$out/bigtree.gltf
    node -e '
      const n = 12000, pos = Buffer.from(new Float32Array([0, 0, 0, 1, 0, 0, 0, 1, 0]).buffer);
      const nodes = [{ name: "root", children: [1, 2] }, { name: "tri", mesh: 0 },
                     { name: "flat", children: Array.from({ length: n }, (_, i) => 3 + i) }];
      for (let i = 0; i < n; i++) nodes.push({ name: "flat " + i, translation: [i * 1e-4, 0, 0] });
      require("fs").writeFileSync(process.argv[1], JSON.stringify({
        asset: { version: "2.0" }, scene: 0, scenes: [{ nodes: [0] }], nodes,
        meshes: [{ primitives: [{ attributes: { POSITION: 0 } }] }],
        accessors: [{ bufferView: 0, componentType: 5126, count: 3, type: "VEC3", min: [0, 0, 0], max: [1, 1, 0] }],
        bufferViews: [{ buffer: 0, byteLength: 36 }],
        buffers: [{ byteLength: 36, uri: "data:application/octet-stream;base64," + pos.toString("base64") }] }));
    ' "$SCENE" || { echo "FAIL: could not write $SCENE"; exit 1; }
fi
args=(web "$SCENE" -b raster --listen 127.0.0.1:0)
[ "$mode" = converge ] && args=(web "$SCENE" -b pathtracer --quality 95 --listen 127.0.0.1:0)
[ "$mode" = client ] || [ "$mode" = client_timeline ] && args+=(--client-render)
[ "$mode" = warp ] && args+=(--delay-ms 100)
[ "$mode" = tools ] && args+=(--bookmarks "$out/views.bookmarks") # the saved views' file (the page saves view 3)
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
# finish [LOG...]: the end of a run: the server still running, no sanitizer's report in its stderr
# (nor in the LOGs given), the summary line and the exit status
finish() {
    kill -0 $pid 2>/dev/null || bad "sy web is no longer running: $(server_said)"
    grep -q -E 'ERROR: (Address|Leak)Sanitizer|runtime error:' "$out/err" "$@" && bad "sy web: $(server_said)"
    [ $fail = 0 ] && echo "ok: sy web $mode in chromium"
    exit $fail
}
# keep: the run's PNG and JSON files into $SY_BROWSER_KEEP when it is set
keep() {
    if [ -n "${SY_BROWSER_KEEP:-}" ]; then cp "$out"/*.png "$out"/*.json "$SY_BROWSER_KEEP"/ 2>/dev/null; fi
    return 0
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

if [ "$mode" = tools ]; then
    # JPEG frames (?video=0): the checks compare the canvas before and after (a node shown again, a
    # view recalled), and a video frame's decoded pixels depend on the frames before it (VP9 delta
    # frames drifted a mean of 5 of 255 at the mirror sphere once moving frames kept their size)
    case $url in *\?*) url="$url&video=0" ;; *) url="$url?video=0" ;; esac
    browse "$url"
    cp "$out/browser.json" "$out/tools.json"
    grep -q '^3 ' "$out/views.bookmarks" 2>/dev/null || bad "the view the page saved as 3 is not in the views' file: $(cat "$out/views.bookmarks" 2>&1)"
    # the same page from a read-only server
    "$SY" web "$SCENE" -b raster --listen 127.0.0.1:0 --read-only >"$out/log2" 2>"$out/err2" &
    pid2=$!
    wait_until $pid2 grep -q 'http://' "$out/log2"
    url2=$(grep -o 'http://[^ ]*' "$out/log2" 2>/dev/null | head -1)
    grep -q "(read-only)" "$out/log2" || bad "sy web --read-only does not say so: $(cat "$out/log2")"
    mkdir -p "$out/ro"
    SY_CHROMIUM=$CHROMIUM node "$MODULES/browser.mjs" tools "${url2}?readonly=1&video=0" "$out/ro" $W $H >"$out/ro.json" || bad "the read-only run failed"
    cat "$out/ro.json"
    kill -TERM $pid2 2>/dev/null; wait $pid2 2>/dev/null
    grep -q "read-only server: refused" "$out/err2" || bad "the read-only server logged no refusal: $(tail -3 "$out/err2")"
    if [ -n "${SY_BROWSER_KEEP:-}" ]; then
        cp "$out"/*.png "$out"/*.json "$SY_BROWSER_KEEP"/ 2>/dev/null
        for f in "$out"/ro/*.png; do cp "$f" "$SY_BROWSER_KEEP/ro_$(basename "$f")"; done 2>/dev/null
    fi
    node -e '
      const fs = require("fs"), t = JSON.parse(fs.readFileSync(process.argv[1])), r = JSON.parse(fs.readFileSync(process.argv[2]));
      const errs = [];
      console.log(`picked node ${t.pick.node} "${t.pick.name}" at ${t.pick.at}; hidden: mean abs diff ${t.hide.box.toFixed(1)} in the 9x9 box, ` +
                  `${(100 * t.hide.changed).toFixed(1)}% of the canvas changed; shown again: ${t.show.box.toFixed(1)}, ${(100 * t.show.changed).toFixed(2)}%; ` +
                  `section plane: ${(100 * t.section.changed).toFixed(1)}% changed; caps: ${(100 * t.cap.before).toFixed(2)}% -> ${(100 * t.cap.after).toFixed(2)}% magenta; measured ${t.measure.distance}, to the plane ${t.to_plane && t.to_plane.shown}; screenshot ${JSON.stringify(t.shot)}; ` +
                  `touch inputs ${t.touch_inputs}`);
      if (!(t.hide.box > 30)) errs.push(`hiding the picked node left the canvas where it was (mean abs diff ${t.hide.box})`);
      if (t.pick_hidden.hit && t.pick_hidden.node === t.pick.node) errs.push("a pick still names the hidden node");
      if (!(t.show.box < 4)) errs.push(`showing it again did not bring the picture back (mean abs diff ${t.show.box})`);
      if (!(t.section.changed > 0.005)) errs.push(`the section plane changed ${t.section.changed} of the canvas`);
      if (!(t.cap && t.cap.after > 0.002 && t.cap.after > 10 * t.cap.before)) errs.push(`caps on in magenta: ${JSON.stringify(t.cap)} of the canvas magenta`);
      const m = t.measure, d = m.points.length === 2 ? Math.hypot(...[0, 1, 2].map((i) => m.points[1][i] - m.points[0][i])) : NaN;
      if (!(m.distance > 0 && Math.abs(m.distance - d) <= 1e-9 * (1 + d) && m.text.includes("distance"))) errs.push(`measurement ${JSON.stringify(m)}`);
      if (!(t.measure_cleared && t.measure_cleared.points === 0 && t.measure_cleared.drawn === 0))
        errs.push(`after Esc the measurement stays: ${JSON.stringify(t.measure_cleared)}`);
      if (!(t.to_plane && t.to_plane.text && t.to_plane.shown.length === 1 && Math.abs(t.to_plane.shown[0] - t.to_plane.want) <= 1e-9 * (1 + Math.abs(t.to_plane.want))))
        errs.push(`point to plane ${JSON.stringify(t.to_plane)}`);
      if (!(t.help > 200)) errs.push("no help text");
      const env = t.environment;
      console.log(`environment: none changes ${(100 * env.none.changed).toFixed(1)}% of the canvas, studio ${(100 * env.studio.changed).toFixed(1)}%, back to the scene world ${(100 * env.scene.changed).toFixed(2)}%`);
      if (JSON.stringify(env.options) !== JSON.stringify(["scene", "studio", "none"])) errs.push(`environment menu ${JSON.stringify(env.options)}`);
      if (!(env.scene.changed < 0.01)) errs.push(`the scene world again did not bring the picture back (${env.scene.changed} changed)`);
      if (!(env.none.changed > 0.05 && env.studio.changed > 0.05)) errs.push(`an environment changed nothing: ${JSON.stringify(env)}`);
      if (!r.environment_hidden) errs.push("a read-only page shows the environment menu");
      if (t.shot.state !== "done" || t.shot.type !== "image/jpeg" || !(t.shot.bytes > 1000) || !/\.jpg$/.test(t.shot.file)) errs.push(`screenshot ${JSON.stringify(t.shot)}`);
      if (!(t.touch_inputs >= 6)) errs.push(`touch sent ${t.touch_inputs} inputs`);
      if (!r.readOnly || !r.hidden_controls.sections || !r.hidden_controls.checkbox_disabled || !r.hidden_controls.badge) errs.push(`read-only page controls ${JSON.stringify(r.hidden_controls)}`);
      if (r.hidden_controls && r.hidden_controls.selected) errs.push("a read-only click selected a node");
      if (!r.still_visible) errs.push("a read-only server applied a visibility change");
      const v = t.views, vs = t.views_saved;
      console.log(`saved views: ${vs && vs.list.length} listed; a drag away changed ${(100 * v.moved.changed).toFixed(1)}% of the canvas, ` +
                  `Shift+3 back: ${(100 * v.recalled.changed).toFixed(2)}% differs (mean abs diff ${v.recalled.box.toFixed(2)} at the pick)`);
      if (!(vs && vs.kept && vs.on3 && vs.off4 && vs.list.length === 1 && vs.list[0].n === 3 && vs.list[0].fov > 0))
        errs.push(`saving view 3: ${JSON.stringify(vs)}`);
      if (!(v.moved.changed > 0.05)) errs.push(`the drag after saving changed ${v.moved.changed} of the canvas`);
      if (!(v.recalled.changed < 0.005 && v.recalled.box < 4)) errs.push(`Shift+3 did not bring the saved view back: ${JSON.stringify(v.recalled)}`);
      if (!(r.views_ro && r.views_ro.section && r.views_ro.save_hidden)) errs.push(`read-only saved views ${JSON.stringify(r.views_ro)}`);
      for (const s of [t, r]) if (s.consoleErrors.length) errs.push(`page errors: ${s.consoleErrors}`);
      if (errs.length) { console.log("FAIL: " + errs.join("; ")); process.exit(1); }
    ' "$out/tools.json" "$out/ro.json" || fail=1
    finish "$out/err2"
fi

if [ "$mode" = client_timeline ]; then
    browse "$url"
    # each time against sy render -b raster --at that time (the view sy web starts with), and the
    # two times against each other (the animated object moved)
    times=$(node -e 'console.log(JSON.parse(require("fs").readFileSync(process.argv[1], "utf8")).times.join(" "))' "$out/client_timeline.json")
    node -e 'const s = JSON.parse(require("fs").readFileSync(process.argv[1], "utf8")); if (s.errors.length || s.consoleErrors.length) { console.log("page errors: " + s.errors + " " + s.consoleErrors); process.exit(1); }' \
        "$out/client_timeline.json" || bad "the client page reported errors"
    k=0
    for t in $times; do
        "$SY" render "$SCENE" -b raster -w $W -h $H --at "$t" -o "$out/ref_t$k.png" >/dev/null 2>"$out/render.err" ||
            { echo "FAIL: sy render --at $t: $(cat "$out/render.err")"; exit 1; }
        res=$("$PNG_IOU" "$out/ref_t$k.png" "$out/client_t$k.png" --min "$MIN_IOU" --tol 8) || bad "at $t s the client canvas differs from sy render -b raster --at $t (coverage IoU below $MIN_IOU)"
        echo "at $t s, the client canvas against sy render -b raster --at $t: $res"
        [ -n "${SY_BROWSER_KEEP:-}" ] && cp "$out/client_t$k.png" "$out/ref_t$k.png" "$SY_BROWSER_KEEP"/
        k=$((k + 1))
    done
    res=$("$PNG_IOU" "$out/client_t0.png" "$out/client_t1.png" --tol 8)
    echo "the client canvas at the two times: $res"
    iou=$(echo "$res" | awk '{print $2}')
    awk -v v="$iou" 'BEGIN { exit !(v < 0.98) }' || bad "the client canvas did not change between the two times (IoU $iou)"
    kill -0 $pid 2>/dev/null || bad "sy web is no longer running: $(server_said)"
    grep -q -E 'ERROR: (Address|Leak)Sanitizer|runtime error:' "$out/err" && bad "sy web: $(server_said)"
    [ $fail = 0 ] && echo "ok: sy web $mode in chromium"
    exit $fail
fi

if [ "$mode" = tree ]; then # browser.mjs checks the page's tree itself
    browse "$url"
    [ -n "${SY_BROWSER_KEEP:-}" ] && cp "$out"/*.png "$out"/*.json "$SY_BROWSER_KEEP"/ 2>/dev/null
    kill -0 $pid 2>/dev/null || bad "sy web is no longer running: $(server_said)"
    grep -q -E 'ERROR: (Address|Leak)Sanitizer|runtime error:' "$out/err" && bad "sy web: $(server_said)"
    [ $fail = 0 ] && echo "ok: sy web $mode in chromium"
    exit $fail
fi

if [ "$mode" = timeline ]; then
    case $url in *\?*) url="$url&video=0" ;; *) url="$url?video=0" ;; esac # JPEG: equal poses give equal frames
    browse "$url"
    keep
    node -e '
      const s = JSON.parse(require("fs").readFileSync(process.argv[1])), errs = [];
      console.log(`timeline ${s.first.start}..${s.first.end} s; start vs 16%: mean abs diff ${s.moved.toFixed(2)}, start vs start again ` +
                  `${s.back.toFixed(2)}; playing: server time ${s.playing.server_time}, paused at ${s.paused.time.toFixed(3)}`);
      if (!(s.first.shown && s.first.end > s.first.start)) errs.push(`timeline ${JSON.stringify(s.first)}`);
      if (!(s.moved > 2)) errs.push(`scrubbing did not change the canvas (mean abs diff ${s.moved})`);
      if (!(s.back >= 0 && s.back < 1.5)) errs.push(`scrubbing back did not bring the picture back (mean abs diff ${s.back})`);
      if (s.paused.playing) errs.push("space did not pause");
      if (!(s.after.time >= s.first.start && s.after.time <= s.first.end)) errs.push(`a bad time moved the clock to ${s.after.time}`);
      if (s.consoleErrors.length) errs.push(`page errors: ${s.consoleErrors}`);
      if (errs.length) { console.log("FAIL: " + errs.join("; ")); process.exit(1); }
    ' "$out/browser.json" || fail=1
    wait_until $pid grep -q "outside the scene's clips" "$out/err" || bad "an out-of-range time was not refused: $(tail -3 "$out/err")"
    wait_until $pid grep -q "time: s must be a finite number" "$out/err" || bad "a time that is no number was not refused: $(tail -3 "$out/err")"
    finish
fi

if [ "$mode" = video ]; then
    browse "$url"
    keep
    node -e '
      const s = JSON.parse(require("fs").readFileSync(process.argv[1])), errs = [], MAD = 6;
      for (const r of s.runs) {
        const b = r.before.video, a = r.after.video;
        console.log(`${r.codec}: canvas vs JPEG mean abs diff ${r.mad.toFixed(2)}; ${a.frames} video frames (${a.keyframes} keyframes, ` +
                    `${a.frames - b.frames} during the drags), ${Math.round(a.bytes_per_frame)} bytes per video frame (PSNR ${a.psnr_db.toFixed(1)} dB) ` +
                    `against ${r.jpeg_bytes_per_frame} per JPEG frame; decode p50 ${[...a.decode_ms].sort((x, y) => x - y)[a.decode_ms.length >> 1]} ms`);
        if (!(r.mad >= 0 && r.mad < MAD)) errs.push(`${r.codec}: the picture differs from the JPEG one by ${r.mad}`);
        if (r.jpeg_video.codec !== "jpeg" || r.jpeg_video.frames !== 0) errs.push(`?video=0 was sent video: ${JSON.stringify(r.jpeg_video)}`);
        if (b.codec !== r.codec || a.codec !== r.codec) errs.push(`${r.codec}: the stream was ${a.codec}`);
        if (a.errors || a.dropped) errs.push(`${r.codec}: ${a.errors} decoder errors, ${a.dropped} frames dropped`);
        if (!(a.frames - b.frames >= 2)) errs.push(`${r.codec}: ${a.frames - b.frames} frames during the drags`);
        if (!(a.keyframes >= 1 && a.keyframes < a.frames)) errs.push(`${r.codec}: ${a.keyframes} keyframes of ${a.frames}`);
        for (const st of [r.before, r.after]) for (const k in st.bad) if (st.bad[k]) errs.push(`${r.codec}: frames refused: ${JSON.stringify(st.bad)}`);
      }
      if (s.consoleErrors.length) errs.push(`page errors: ${s.consoleErrors}`);
      if (errs.length) { console.log("FAIL: " + errs.join("; ")); process.exit(1); }
    ' "$out/browser.json" || fail=1
    grep -E 'video|sent (vp8|vp9|jpeg)' "$out/err" | head -8
    finish
fi

if [ "$mode" = converge ]; then
    browse "$url"
    keep
    node -e '
      const s = JSON.parse(require("fs").readFileSync(process.argv[1])), errs = [];
      console.log(`still path tracer: noise ${s.early.noise.toFixed(2)} at ${s.early.samples.join("-")} spp, ` +
                  `${s.late.noise.toFixed(2)} at ${s.late.samples.join("-")} spp (ratio ${(s.late.noise / s.early.noise).toFixed(2)}); ` +
                  `${s.frames} frames, ${s.bytes_per_frame} bytes per frame; depth ${JSON.stringify(s.depth)}`);
      if (!(s.late.noise < 0.7 * s.early.noise)) errs.push(`the canvas did not converge: noise ${s.early.noise} then ${s.late.noise}`);
      for (const k in s.bad) if (s.bad[k]) errs.push(`frames refused: ${JSON.stringify(s.bad)}`);
      if (!(s.depth && s.depth.same > 0)) errs.push(`no refinement came without its depth channel: ${JSON.stringify(s.depth)}`);
      if (s.consoleErrors.length) errs.push(`page errors: ${s.consoleErrors}`);
      if (errs.length) { console.log("FAIL: " + errs.join("; ")); process.exit(1); }
    ' "$out/browser.json" || fail=1
    finish
fi

if [ "$mode" = orbit ]; then
    export SY_PNG_SSIM=$PNG_IOU SY_ORBIT_HOLD=1 SY_ORBIT_S=1 SY_ORBIT_EVERY_MS=100 # (the third argument is png_ssim here)
    for level in 1 3; do
    case $url in *\?*) lurl="$url&level=$level" ;; *) lurl="$url?level=$level" ;; esac
    browse "$lurl"
    keep
    node -e '
      const r = JSON.parse(require("fs").readFileSync(process.argv[1])), errs = [];
      const n = r.captures.length, est = r.captures.filter((c) => c.estimate);
      console.log(`level ${process.argv[2]}: held orbit of ${Math.max(...r.captures.map((c) => c.turned_deg)).toFixed(1)} degrees: ${est.length} of ${n} captures ` +
                  `estimates; SSIM against the true frames median ${r.ssim_median} min ${r.ssim_min}; largest share left unfilled ${r.unfilled_max}`);
      if (!(n >= 3)) errs.push(`only ${n} captures`);
      if (est.length !== n) errs.push(`${n - est.length} captures were no estimate though the references were held`);
      if (!(r.unfilled_max === 0)) errs.push(`the hole fill left ${(100 * r.unfilled_max).toFixed(2)}% of a canvas empty`);
      if (!(r.ssim_min >= 0.88)) errs.push(`an estimate has SSIM ${r.ssim_min} < 0.88 against its true frame`);
      if (!(r.ssim_median >= 0.92)) errs.push(`median SSIM ${r.ssim_median} < 0.92`);
      if (!(r.yaw_diff_max < 1e-4)) errs.push(`a true frame is ${r.yaw_diff_max} rad off the view of its estimate`);
      for (const k in r.bad) if (r.bad[k]) errs.push(`frames of the server refused: ${JSON.stringify(r.bad)}`);
      if (r.consoleErrors.length) errs.push(`page errors: ${r.consoleErrors}`);
      if (errs.length) { console.log(`FAIL (level ${process.argv[2]}): ` + errs.join("; ")); process.exit(1); }
    ' "$out/browser.json" $level || fail=1
    done
    finish
fi

if [ "$mode" = warp ]; then
    case $url in *\?*) url="$url&video=0" ;; *) url="$url?video=0" ;; esac # the made-up bad frames below are JPEG frames
    browse "$url"
    cp "$out/browser.json" "$out/warp.json"
    case $url in *\?*) nurl="$url&warp=0" ;; *) nurl="$url?warp=0" ;; esac
    browse "$nurl"
    cp "$out/browser.json" "$out/nowarp.json"
    keep
    node -e '
      const fs = require("fs"), w = JSON.parse(fs.readFileSync(process.argv[1])), n = JSON.parse(fs.readFileSync(process.argv[2]));
      const errs = [], BOUND = 200, MAD = 6;
      console.log(`input to display, 100 ms each way: warp p50 ${w.input_to_display_ms.p50.toFixed(1)} p95 ${w.input_to_display_ms.p95.toFixed(1)} ` +
                  `max ${w.input_to_display_ms.max.toFixed(1)} ms (${w.input_to_display_ms.n} inputs, ${(100 * w.by_estimate).toFixed(0)}% by the estimate); without warp p50 ` +
                  `${n.input_to_display_ms.p50.toFixed(1)} p95 ${n.input_to_display_ms.p95.toFixed(1)} ms; display frames p95 ` +
                  `${w.frame_ms.p95.toFixed(1)} ms; estimate vs the server frame: mean abs diff ${w.quality && w.quality.mad.toFixed(2)} ` +
                  `(holes filled: ${w.quality && (100 * w.quality.held.hole_share).toFixed(2)}% of the canvas)`);
      if (!w.warp) errs.push("the page did not warp (no WebGL2?)");
      if (!(w.input_to_display_ms.n >= 30)) errs.push(`only ${w.input_to_display_ms.n} inputs measured`);
      if (!(w.by_estimate >= 0.75)) errs.push(`only ${(100 * w.by_estimate).toFixed(0)}% of the inputs answered by the estimate`);
      if (!(n.input_to_display_ms.p50 >= BOUND)) errs.push(`without warp median ${n.input_to_display_ms.p50} ms < ${BOUND}: the delay is not there`);
      const want = { order: 1, size: 1, large: 1, depth: 3, camera: 2, version: 1, jpeg: 1, magic: 0 };
      if (!w.badFrames || JSON.stringify(Object.keys(want).map((k) => w.badFrames.counts[k])) !== JSON.stringify(Object.values(want)))
        errs.push(`bad frames counted ${JSON.stringify(w.badFrames && w.badFrames.counts)}, not ${JSON.stringify(want)}`);
      if (!w.badFrames || !w.badFrames.unchanged) errs.push("the bad frames changed the picture");
      for (const s of [w, n]) for (const k in s.bad) if (s.bad[k]) errs.push(`frames of the server refused: ${JSON.stringify(s.bad)}`);
      if (!w.quality || !(w.quality.held.estimate_share === 1)) errs.push("the held drag was not shown as an estimate");
      if (!w.quality || !(w.quality.mad >= 0 && w.quality.mad < MAD)) errs.push(`the estimate differs from the true frame: mean abs diff ${w.quality && w.quality.mad}`);
      for (const s of [w, n]) if (s.consoleErrors.length) errs.push(`page errors: ${s.consoleErrors}`);
      if (errs.length) { console.log("FAIL: " + errs.join("; ")); process.exit(1); }
    ' "$out/warp.json" "$out/nowarp.json" || fail=1
    finish
fi

browse "$url"
# The reference: sy render with the rasterizer at the canvas size, the scene's default view (the
# view sy web starts with, and the client page asks the server for).
"$SY" render "$SCENE" -b raster -w $W -h $H -o "$out/ref.png" >/dev/null 2>"$out/render.err" ||
    { echo "FAIL: sy render: $(cat "$out/render.err")"; exit 1; }
# a streamed canvas is JPEG (noise around the background): a wider tolerance than WebGL's
tol=8
[ "$mode" = stream ] && tol=24
lum_args=()
[ -n "$LUM" ] && lum_args=(--lum "$LUM")
[ "$LUM" = print ] && lum_args=(--lum 1e30) # printed, not checked (yet: see docs/WEB.md)
res=$("$PNG_IOU" "$out/ref.png" "$out/canvas.png" --min "$MIN_IOU" --tol $tol "${lum_args[@]}")
rc=$?
echo "canvas against sy render -b raster: $res"
[ $rc = 0 ] || bad "the canvas differs from sy render -b raster (coverage IoU below $MIN_IOU${LUM:+, or mean luminance more than $LUM apart})"
[ -n "${SY_BROWSER_KEEP:-}" ] && cp "$out/canvas.png" "$SY_BROWSER_KEEP/${mode}_canvas.png" && cp "$out/ref.png" "$SY_BROWSER_KEEP/${mode}_ref.png"

if [ "$mode" = stream ]; then
    res=$("$PNG_IOU" "$out/canvas.png" "$out/dragged.png" --tol $tol)
    echo "before against after the drag: $res"
    iou=$(echo "$res" | awk '{print $2}')
    awk -v v="$iou" 'BEGIN { exit !(v < 0.98) }' || bad "a drag did not change the view (IoU $iou against before)"
else
    fetched_check
    # (a textured model's run checks the look only)
    [ -n "$LUM" ] && { kill -0 $pid 2>/dev/null || bad "sy web is no longer running: $(server_said)"; [ $fail = 0 ] && echo "ok: sy web $mode in chromium"; exit $fail; }
    # a budget of a quarter of the scene's triangles: the page fetches just what the cut answer lists
    total=$(node -e 'console.log(JSON.parse(require("fs").readFileSync(process.argv[1], "utf8")).total_triangles)' "$out/client.json")
    budget=$((total / 4))
    case $url in *\?*) burl="$url&budget=$budget" ;; *) burl="$url?budget=$budget" ;; esac
    browse "$burl"
    fetched_check $budget
fi
# the server must have lived through it all, without a sanitizer's report
finish
