// browser.mjs — drives Debian's chromium, headless, over the DevTools protocol (playwright-core from
// npm, tests/browser/package.json) for the sy web tests (tests/browser/browser_test.sh).
//
//   node browser.mjs stream URL OUTDIR WIDTH HEIGHT
//     The streamed page (sy web): waits for a frame of the canvas' full size, writes the canvas
//     pixels to OUTDIR/canvas.png, drags across the canvas, waits for the full-size frame that
//     answers the drag, writes OUTDIR/dragged.png.
//   node browser.mjs warp URL OUTDIR WIDTH HEIGHT
//     The warping page (sy web --delay-ms N): a scripted drag of 40 moves 16 ms apart (SY_DRAG_MS=N:
//     moves for N ms; SY_WARP_DRAG_ONLY=1: print the drag's numbers and stop there),
//     window.sy.stats() after it (input_to_display_ms, frame_ms, ...); a second drag with a
//     screenshot in its middle (OUTDIR/middrag.png, the page with its badge); then the references held (window.sy.hold) while a 12-pixel drag is warped
//     (OUTDIR/warped.png), released, and the server's frame of the same view (OUTDIR/true.png);
//     their mean absolute difference (0..255, RGB) computed in the browser; then a second page
//     whose WebSocket goes through playwright (routeWebSocket) is sent made-up bad frames after
//     the server's (duplicate, sizes that do not add up, depth that does not inflate, cameras
//     not finite or not a rotation, format 4, no JPEG, two that say they have the last depth
//     channel wrongly, one four times the size asked for): their counts in sy.stats().bad and
//     whether the canvas stayed the same. URL?warp=0 gives the same drag without the warp and
//     without the rest (the comparison).
//   node browser.mjs orbit URL OUTDIR WIDTH HEIGHT
//     The estimate during an orbit (a measurement; docs/WEB.md, "The estimate during an orbit"):
//     once a full-size frame answers every input, the page itself drags the orbit at
//     SY_ORBIT_DEG_S degrees a second (default 10) for SY_ORBIT_S seconds (default 6), one input
//     per display frame (sy.input, its dx from the time since the last), and captures the display
//     frame every SY_ORBIT_EVERY_MS (default 250; sy.capture: the pixels before the browser shows
//     them, whether they are an estimate, the view, the share the hole fill left empty).
//     SY_ORBIT_HOLD=1: the references held from the start (sy.hold), so that every capture is
//     the first frame warped by the angle turned since, whatever the server and the load do; the
//     orbit's clock then moves at most 50 ms a display frame (a stalled display takes the same
//     captures at the same angles, later; `ms` is that clock).
//     Then, for each capture that was an estimate, the server's exact frame of the same view (a
//     drag back to it, waited for until a full-size frame answers it, captured): OUTDIR/est_K.png
//     and OUTDIR/true_K.png, K from 0, compared by SY_PNG_SSIM (tests/support/png_ssim.c: SSIM of
//     luma). Prints {captures: [{k, ms, estimate, unfilled, yaw, yaw_true, refs, turned_deg, ssim}],
//     ssim_median, ssim_p10, ssim_min over the estimates, unfilled_max over all captures,
//     yaw_diff_max (estimate's view against its true frame's), frame_ms_p50 (the last 60 display
//     frames), ahead (sy.stats().ahead: frames rendered ahead, the last lead), ...}. URL?ahead=0:
//     the page sends no lead (docs/WEB.md, "Frames rendered ahead"), the comparison.
//   node browser.mjs tools URL OUTDIR WIDTH HEIGHT
//     The page's tools (sy web, a canvas wide enough for the panel): finds a covered pixel near
//     the centre (the server's still of the view), clicks it (pick + select; the properties show
//     the node), hides that node from the tree (the streamed canvas changes there; a pick there no
//     longer names it), shows it again (back as it was while selected), adds a section plane (the canvas
//     changes; with caps on in magenta, the cut faces show magenta), measures two covered points (Esc takes them away), opens the help, takes a screenshot (the download),
//     pinches and drags with synthetic touch pointers, saves the view as 3 (the panel), drags away
//     and recalls it with Shift+3 (the canvas as saved); screenshots OUTDIR/page.png, tree.png,
//     hidden.png, section.png, cap.png, measure.png, help.png, views.png. URL with readonly=1 (sy web --read-only):
//     the controls that change the scene (and Save) are hidden or disabled and a change sent anyway leaves
//     the tree as it was.
//   node browser.mjs video URL OUTDIR WIDTH HEIGHT
//     The video stream: which codecs this chromium's WebCodecs decodes (none: exit 77 with that
//     reason); for each, a page with URL?video=0 (JPEG) and one with URL?codec=C at the same view,
//     each waited for until its full-size frame answers every input, their canvases
//     (OUTDIR/jpeg_C.png, OUTDIR/C.png) and their mean absolute difference (0..255, RGB, computed
//     in the browser); then a drag of 20 moves on the video page (frames keep coming as delta
//     frames) and back; sy.stats().video before and after.
//   node browser.mjs timeline URL OUTDIR WIDTH HEIGHT
//     The timeline of an animated scene: waits for it, scrubs to the clips' start, to 16% of
//     their range and back (BoxAnimated: its inner box half risen; the canvas once steady after each: OUTDIR/t_start.png, t_mid.png,
//     t_start_again.png, and the mean absolute differences start-mid and start-start again),
//     presses space (the server's "clock" messages advance), screenshots the page while playing
//     (OUTDIR/timeline.png), presses space again (paused), then sends bad times (out of range,
//     not a number) that the server refuses.
//   node browser.mjs first URL OUTDIR WIDTH HEIGHT
//     Time to first picture (a measurement, not a check): from the navigation's start to the first
//     display frame showing a server frame (its size: the governor's coarse first frame), as
//     index.html's image (image_ms) or on view.js's canvas (canvas_ms), picture_ms the earlier;
//     then to the first full-size frame; OUTDIR/first.png (what showed first). Prints {picture_ms,
//     image_ms, canvas_ms, width, height, backend, render_ms, dom_ms, response_ms, marks (the
//     performance marks sy-connect, -open, -size, -frame-received, -first-image, -frame-adopted), full_ms}.
//     SY_FIRST_WARM=1: the browser loads a page of the origin (a 404) and makes a WebGL2 context
//     first (a browser in use), else the page is the fresh browser's first.
//   node browser.mjs converge URL OUTDIR WIDTH HEIGHT
//     A still view of the path tracer (sy web -b pathtracer): the canvas of the first full-size
//     frame (OUTDIR/early.png) and once the server's frames have 16 times its samples, at least 64
//     (OUTDIR/late.png), each with its noise (mean absolute difference to the mean of the four
//     neighbours, 0..255, RGB) and the samples the page had before and after the screenshot;
//     sy.stats() after (bad frames, the depth channel's reuse).
//   node browser.mjs client URL OUTDIR WIDTH HEIGHT
//     The client-render page (sy web --client-render): waits until the client is idle (its last
//     cull answer drawn), writes the canvas to OUTDIR/canvas.png and what the page fetched to
//     OUTDIR/client.json (the ids of the answer, the ids fetched over the network, the ids drawn,
//     triangles drawn and the totals).
//   node browser.mjs client_timeline URL OUTDIR WIDTH HEIGHT
//     The client-render page of an animated scene: once settled with its timeline shown, sets the
//     scene clock (syClient.setTime) to the clip's start and to 16 % of it, waits each time for the
//     pose asked after the server's clock message and the page idle again, and writes the canvas
//     to OUTDIR/client_t0.png and client_t1.png and the times to OUTDIR/client_timeline.json.
//
// Prints one line of JSON with what it saw; exits 1 with the reason on any failure (timeouts
// included), 77 when chromium cannot be started.
import { chromium } from 'playwright-core';
import { readFileSync, writeFileSync } from 'node:fs';
import { execFileSync } from 'node:child_process';
import { join } from 'node:path';

const [mode, url, outDir, wArg, hArg] = process.argv.slice(2);
const width = Number(wArg || 480), height = Number(hArg || 360);
if (!['stream', 'client', 'client_timeline', 'warp', 'orbit', 'tools', 'video', 'timeline', 'first', 'converge', 'tree'].includes(mode) || !url || !outDir) {
  console.error('usage: node browser.mjs stream|client|client_timeline|warp|orbit|tools|video|timeline|first|converge|tree URL OUTDIR [WIDTH HEIGHT]');
  process.exit(2);
}
const executablePath = process.env.SY_CHROMIUM || '/usr/bin/chromium';
// Every wait is for a state of the page; the bound is only a hang guard (60 s was too short for
// SwiftShader on two loaded cores: 'the client did not settle' with the page still loading).
const TIMEOUT = Number(process.env.SY_BROWSER_TIMEOUT_MS || 300000);

function fail(msg) {
  console.error(`browser.mjs ${mode}: ${msg}`);
  process.exit(1);
}

// The canvas as shown (a screenshot of its element: a WebGL canvas' drawing buffer is gone once
// composited), with every other element of the page hidden (the overlays) meanwhile.
async function canvasPng(page, selector, path) {
  await page.evaluate((sel) => {
    for (const e of document.body.querySelectorAll('*')) if (!e.matches(sel) && !e.contains(document.querySelector(sel))) e.style.visibility = 'hidden';
  }, selector);
  await page.locator(selector).screenshot({ path });
  await page.evaluate(() => { for (const e of document.body.querySelectorAll('*')) e.style.visibility = ''; });
}

// the warping page (warp, orbit) shows a full-size, exact frame answering every input sent so far
function exactFrame(page) {
  return page.waitForFunction(
    ([w, h]) => window.syStats && window.sy && syStats.frames > 0 && syStats.width === w && syStats.height === h &&
                syStats.answeredInput === syStats.lastInput && sy.stats().estimate_share === 0,
    [width, height], { timeout: TIMEOUT });
}

// mean absolute difference (0..255, RGB) of two PNG files of the same size, computed in page p
async function pngMad(p, fa, fb) {
  const a = readFileSync(fa).toString('base64'), b = readFileSync(fb).toString('base64');
  return p.evaluate(async ([a, b]) => {
    const px = async (s) => {
      const bmp = await createImageBitmap(await (await fetch('data:image/png;base64,' + s)).blob());
      const c = new OffscreenCanvas(bmp.width, bmp.height), g = c.getContext('2d');
      g.drawImage(bmp, 0, 0);
      return g.getImageData(0, 0, bmp.width, bmp.height).data;
    };
    const [p, q] = [await px(a), await px(b)];
    if (p.length !== q.length) return -1;
    let s = 0;
    for (let i = 0; i < p.length; i += 4) s += Math.abs(p[i] - q[i]) + Math.abs(p[i + 1] - q[i + 1]) + Math.abs(p[i + 2] - q[i + 2]);
    return s / (p.length / 4 * 3);
  }, [a, b]);
}

let browser;
try {
  // SwiftShader gives WebGL without a GPU (the client page); the stream page needs only a 2D canvas.
  browser = await chromium.launch({ executablePath, args: ['--use-angle=swiftshader', '--enable-unsafe-swiftshader'] });
} catch (e) {
  console.log(`SKIP: chromium (${executablePath}) does not start: ${String(e.message || e).split('\n')[0]}`);
  process.exit(77);
}
try {
  const page = await browser.newPage({ viewport: { width, height }, deviceScaleFactor: 1 });
  const consoleErrors = [];
  page.on('console', (m) => { if (m.type() === 'error') consoleErrors.push(m.text()); });
  page.on('pageerror', (e) => consoleErrors.push(String(e)));
  const fetched = [];
  page.on('request', (r) => {
    const m = /\/api\/object\/(\d+)/.exec(r.url());
    if (m) fetched.push(Number(m[1]));
  });
  if (mode === 'first') { // from the navigation's start: the first display frame after the first server frame was adopted
    await page.addInitScript(() => {
      window.__first = {};
      // the first picture: index.html's image of the first frame (syEarly.picture_ms: the display
      // frame after it loaded) or view.js's first frame on the canvas, whichever came first
      const poll = () => {
        const s = window.syStats, f = window.__first, e = window.syEarly;
        if (e && e.picture_ms && !f.image_ms) f.image_ms = e.picture_ms;
        if (s && s.frames > 0 && !f.canvas_ms) { f.canvas_ms = performance.now(); f.width = s.width; f.height = s.height; f.backend = s.backend; f.render_ms = s.renderMs; }
        if ((f.image_ms || f.canvas_ms) && !f.picture_ms) f.picture_ms = Math.min(f.image_ms || Infinity, f.canvas_ms || Infinity);
        if (!f.canvas_ms) requestAnimationFrame(poll);
      };
      requestAnimationFrame(poll);
    });
  }
  if (mode === 'first' && process.env.SY_FIRST_WARM) {
    // a browser that has been used: one page of the origin (a 404) with a WebGL2 context before, so
    // the renderer and GPU processes (SwiftShader) are up when the page is requested
    await page.goto(new URL('/warm-up', url).href, { timeout: TIMEOUT });
    await page.evaluate(() => !!document.createElement('canvas').getContext('webgl2'));
  }
  await page.goto(url, { timeout: TIMEOUT });

  if (mode === 'first') {
    // time to first picture (not a test: printed for docs/WEB.md): the page's clock from the navigation start
    await page.waitForFunction(() => window.__first && window.__first.picture_ms > 0, null, { timeout: TIMEOUT, polling: 50 });
    await page.screenshot({ path: join(outDir, 'first.png') }); // what shows first
    await page.waitForFunction(() => window.__first && window.__first.canvas_ms > 0, null, { timeout: TIMEOUT, polling: 50 });
    const first = await page.evaluate(() => {
      const nav = performance.getEntriesByType('navigation')[0], marks = {};
      for (const m of performance.getEntriesByType('mark')) if (m.name.startsWith('sy-') && !(m.name.slice(3) in marks)) marks[m.name.slice(3)] = Math.round(m.startTime);
      return Object.assign({}, window.__first, { dom_ms: nav.domContentLoadedEventEnd, response_ms: nav.responseEnd, marks: marks });
    });
    // the refinement follows: a full-size frame
    await page.waitForFunction(([w, h]) => syStats.width === w && syStats.height === h, [width, height], { timeout: TIMEOUT });
    first.full_ms = await page.evaluate(() => performance.now());
    console.log(JSON.stringify(first));
    await browser.close();
    process.exit(0);
  }
  if (mode === 'tree') {
    // the scene tree a page at a time (tree.js): browser_test.sh tree's generated scene
    const rows = () => page.locator('#sy-tree [data-node]').count();
    const settled = (v) => page.waitForFunction((x) => sy.ui.tree.version > x && !sy.ui.tree.pending, v, { timeout: TIMEOUT });
    await page.waitForFunction(() => window.sy && sy.ui && sy.ui.tree && sy.ui.tree.version > 0, null, { timeout: TIMEOUT });
    const res = { total: await page.evaluate(() => sy.ui.tree.total) };
    const flat = await page.evaluate(() => { const n = sy.ui.tree.nodes.find((x) => x.name === 'flat'); return n && { id: n.id, children: n.children, open: n.open }; });
    if (!flat || flat.children !== 12000 || flat.open) fail(`the group "flat" is not listed closed with 12000 children: ${JSON.stringify(flat)}`);
    if (!(res.total > 12000)) fail(`the tree has ${res.total} nodes`);
    res.rows_closed = await rows();
    if (res.rows_closed > 20) fail(`${res.rows_closed} rows before expanding`);
    let v = await page.evaluate(() => sy.ui.tree.version);
    await page.locator(`#sy-tree [data-node="${flat.id}"] .sy-tree-expand`).click();
    await settled(v);
    res.rows_open = await rows();
    res.more = await page.locator('#sy-tree .sy-tree-more').textContent();
    if (res.rows_open !== res.rows_closed + 512 || !/11488 more/.test(res.more)) fail(`expanded: ${JSON.stringify(res)}`);
    await page.screenshot({ path: join(outDir, 'tree_big.png') });
    v = await page.evaluate(() => sy.ui.tree.version);
    await page.locator('#sy-tree .sy-tree-more').click();
    await settled(v);
    res.rows_more = await rows();
    res.more2 = await page.locator('#sy-tree .sy-tree-more').textContent();
    const names = await page.evaluate(() => sy.ui.tree.nodes.filter((n) => /^flat \d+$/.test(n.name || '')).map((n) => n.name));
    res.in_order = names.length === 1024 && names.every((x, i) => x === `flat ${i}`);
    if (res.rows_more !== res.rows_open + 512 || !/10976 more/.test(res.more2) || !res.in_order) fail(`the next page: ${JSON.stringify(res)}`);
    // asked again (as after a visibility change): "flat" stays expanded, its first page listed
    v = await page.evaluate(() => { const x = sy.ui.tree.version; sy.ui.tree.refresh(); return x; });
    await page.waitForFunction((x) => sy.ui.tree.version > x + 1 && !sy.ui.tree.pending, v, { timeout: TIMEOUT });
    res.rows_again = await rows();
    if (res.rows_again !== res.rows_open) fail(`asked again: ${res.rows_again} rows, not ${res.rows_open}`);
    await page.locator(`#sy-tree [data-node="${flat.id}"] .sy-tree-expand`).click();
    res.rows_collapsed = await rows();
    if (res.rows_collapsed !== res.rows_closed) fail(`collapsed: ${res.rows_collapsed} rows, not ${res.rows_closed}`);
    res.consoleErrors = consoleErrors;
    if (consoleErrors.length) fail(`page errors: ${consoleErrors}`);
    console.log(JSON.stringify(res));
    await browser.close();
    process.exit(0);
  }
  if (mode === 'stream') {
    // a full-size frame answering every input sent so far
    const settled = () => page.waitForFunction(
      ([w, h]) => window.syStats && syStats.frames > 0 && syStats.width === w && syStats.height === h &&
                  syStats.answeredInput === syStats.lastInput,
      [width, height], { timeout: TIMEOUT });
    await settled().catch(() => fail('no full-size frame within the timeout'));
    await page.waitForTimeout(300); // a progressive back-end keeps refining; any frame of the still view will do
    await canvasPng(page, '#sy-canvas', join(outDir, 'canvas.png'));
    const before = await page.evaluate(() => ({ ...syStats }));
    await page.mouse.move(width / 2, height / 2);
    await page.mouse.down();
    await page.mouse.move(width / 2 + width / 4, height / 2, { steps: 8 });
    await page.mouse.up();
    await page.waitForFunction((n) => syStats.lastInput > n, before.lastInput, { timeout: TIMEOUT })
      .catch(() => fail('the drag sent no input'));
    await settled().catch(() => fail('no full-size frame answered the drag'));
    await page.waitForTimeout(300);
    await canvasPng(page, '#sy-canvas', join(outDir, 'dragged.png'));
    const after = await page.evaluate(() => ({ ...syStats }));
    console.log(JSON.stringify({ before, after, consoleErrors }));
  } else if (mode === 'warp') {
    const settled = () => exactFrame(page);
    const pct = (a, q) => { const s = [...a].sort((x, y) => x - y); return s.length ? s[Math.min(s.length - 1, Math.floor(q * s.length))] : null; };
    const summary = (a) => ({ n: a.length, p50: pct(a, 0.5), p95: pct(a, 0.95), max: a.length ? Math.max(...a) : null });
    await settled().catch(() => fail('no full-size frame within the timeout'));
    const before = await page.evaluate(() => sy.stats());
    const frames0 = before.frames;
    // the drag: 40 moves of 4 pixels, 16 ms apart (a hand at the display's rate); SY_DRAG_MS=N
    // (measurements): moves for N ms, back and forth over 160 pixels
    const x0 = width / 2 - 80, y0 = height / 2, dragMs = Number(process.env.SY_DRAG_MS || 0);
    await page.mouse.move(x0, y0);
    await page.mouse.down();
    const tDrag = Date.now();
    for (let i = 1; dragMs ? Date.now() - tDrag < dragMs : i <= 40; i++) {
      const k = i % 80;
      await page.mouse.move(x0 + 4 * (k <= 40 ? k : 80 - k), y0 + (i % 2));
      await page.waitForTimeout(16);
    }
    await page.mouse.up();
    await settled().catch(() => fail('no full-size frame answered the drag'));
    const st = await page.evaluate(() => sy.stats());
    if (process.env.SY_WARP_DRAG_ONLY) { // measurements: the drag's numbers alone
      const drag = st.input_to_display_ms.slice(-(st.inputs_displayed - before.inputs_displayed));
      const frameMs = st.frame_ms.slice(-Math.min(st.frame_ms.length, st.display_frames - before.display_frames));
      console.log(JSON.stringify({ warp: st.warp, drag_ms: Date.now() - tDrag, input_to_display_ms: summary(drag), frame_ms: summary(frameMs),
                                   by_estimate: (st.inputs_by_estimate - before.inputs_by_estimate) / Math.max(1, drag.length),
                                   server_fps: st.server_fps, bytes_per_frame: Math.round(st.bytes_per_frame), depth: st.depth,
                                   video: st.video && { codec: st.video.codec, bytes_per_frame: Math.round(st.video.bytes_per_frame) },
                                   frames_during_drag: st.frames - frames0, bad: st.bad, stride: st.stride, warp_scale: st.warp_scale,
                                   adopt_ms: summary(st.adopt_ms.slice(-Math.min(st.adopt_ms.length, st.frames - frames0))) }));
      await browser.close();
      process.exit(0);
    }
    // a look mid-drag (not measured: the screenshot takes a while): the stats, then the page with its badge
    await page.mouse.move(x0, y0);
    await page.mouse.down();
    for (let i = 1; i <= 10; i++) { await page.mouse.move(x0 - 4 * i, y0); await page.waitForTimeout(16); }
    const mid = await page.evaluate(() => { const s = sy.stats({ holes: true }); return { estimate_share: s.estimate_share, hole_share: s.hole_share }; });
    await page.screenshot({ path: join(outDir, 'middrag.png') });
    await page.mouse.up();
    await settled().catch(() => fail('no full-size frame answered the second drag'));
    // input events are counted from the drag on
    const drag = st.input_to_display_ms.slice(-(st.inputs_displayed - before.inputs_displayed));
    const frameMs = st.frame_ms.slice(-Math.min(st.frame_ms.length, st.display_frames - before.display_frames));
    // the estimate against the truth: references held at this view, a 12-pixel drag warped
    let quality = null;
    if (st.warp) {
      await page.evaluate(() => sy.hold(true));
      await page.mouse.move(x0, y0);
      await page.mouse.down();
      for (let i = 1; i <= 6; i++) { await page.mouse.move(x0 + 2 * i, y0); await page.waitForTimeout(16); }
      await page.mouse.up();
      await page.waitForFunction(() => sy.stats().shown_input === sy.stats().last_input, null, { timeout: TIMEOUT });
      await page.evaluate(() => new Promise((r) => requestAnimationFrame(() => requestAnimationFrame(r))));
      const held = await page.evaluate(() => { const s = sy.stats({ holes: true }); return { estimate_share: s.estimate_share, hole_share: s.hole_share }; });
      await canvasPng(page, '#sy-canvas', join(outDir, 'warped.png'));
      await page.evaluate(() => sy.hold(false));
      await settled().catch(() => fail('no full-size frame after the held drag'));
      await page.evaluate(() => new Promise((r) => requestAnimationFrame(() => requestAnimationFrame(r))));
      await canvasPng(page, '#sy-canvas', join(outDir, 'true.png'));
      const mad = await pngMad(page, join(outDir, 'warped.png'), join(outDir, 'true.png'));
      quality = { mad, held };
    }
    // bad frames (a page of its own whose WebSocket goes through the test: the server's messages
    // passed on, then made-up ones): each refused for its reason, the picture unchanged
    let badFrames = null;
    if (st.warp) {
      const p2 = await browser.newPage({ viewport: { width, height }, deviceScaleFactor: 1 });
      p2.on('pageerror', (e) => consoleErrors.push(String(e)));
      let toPage = null, last = null;
      await p2.routeWebSocket(/\/ws/, (ws) => {
        const server = ws.connectToServer();
        toPage = ws;
        ws.onMessage((m) => server.send(m));
        // the newest frame with its own depth channel (a refinement may say it has the last one's)
        server.onMessage((m) => { if (typeof m !== 'string' && Buffer.from(m).readUInt32LE(48)) last = Buffer.from(m); ws.send(m); });
      });
      await p2.goto(url, { timeout: TIMEOUT });
      await p2.waitForFunction(([w, h]) => window.syStats && window.sy && syStats.frames > 0 && syStats.width === w &&
                                           syStats.height === h && sy.stats().estimate_share === 0, [width, height], { timeout: TIMEOUT })
        .catch(() => fail('the routed page got no full-size frame'));
      await p2.waitForTimeout(500);
      await canvasPng(p2, '#sy-canvas', join(outDir, 'before_bad.png'));
      const f = last, seq = f.readBigUInt64LE(24), jl = f.readUInt32LE(44);
      const variant = (k, edit) => { const b = Buffer.from(f); b.writeBigUInt64LE(seq + BigInt(1000 + k), 24); edit(b); return b; };
      const bads = [
        Buffer.from(f),                                                   // the same frame again: order
        variant(1, (b) => b.writeUInt32LE(b.readUInt32LE(4) + 1, 4)).subarray(0, f.length - 7), // sizes that do not add up: size
        variant(2, (b) => b.fill(0, 192 + jl)),                           // depth that does not inflate: depth
        variant(3, (b) => b.writeFloatLE(NaN, 64)),                       // a camera that is not finite: camera
        variant(4, (b) => { b.writeFloatLE(2, 64); }),                    // not a rotation: camera
        variant(5, (b) => b.writeUInt8(0x34, 3)),                         // format 4: version
        variant(6, (b) => b.fill(0, 192, 192 + jl)),                      // no JPEG: jpeg
        variant(7, (b) => b.writeUInt32LE(b.readUInt32LE(180) | 4, 180)), // says it has the last depth, carries one: depth
        variant(8, (b) => { b.writeUInt32LE(b.readUInt32LE(180) | 4, 180); b.writeUInt32LE(0, 48); b.writeUInt32LE(b.readUInt32LE(4) - 4, 4); })
          .subarray(0, 192 + jl),                                         // the last depth, of another size: depth
        variant(9, (b) => { b.writeUInt32LE(4 * b.readUInt32LE(4), 4); b.writeUInt32LE(4 * b.readUInt32LE(8), 8); }), // larger than asked: large
      ];
      // one at a time: the page decodes only the newest of the frames that come while it is busy
      const refused = () => p2.evaluate(() => Object.values(sy.stats().bad).reduce((a, b) => a + b, 0));
      for (const b of bads) {
        const n0 = await refused();
        toPage.send(b);
        await p2.waitForFunction((n) => Object.values(sy.stats().bad).reduce((a, b) => a + b, 0) > n, n0, { timeout: 20000 }).catch(() => {});
      }
      await p2.waitForFunction((n) => Object.values(sy.stats().bad).reduce((a, b) => a + b, 0) >= n, bads.length, { timeout: TIMEOUT })
        .catch(() => {});
      await p2.evaluate(() => new Promise((r) => requestAnimationFrame(() => requestAnimationFrame(r))));
      await canvasPng(p2, '#sy-canvas', join(outDir, 'after_bad.png'));
      const counts = await p2.evaluate(() => sy.stats().bad);
      const a = readFileSync(join(outDir, 'before_bad.png')), b = readFileSync(join(outDir, 'after_bad.png'));
      badFrames = { counts, unchanged: a.equals(b) };
      await p2.close();
    }
    console.log(JSON.stringify({ warp: st.warp, stride: st.stride, warp_scale: st.warp_scale, input_to_display_ms: summary(drag), frame_ms: summary(frameMs), adopt_ms: summary(st.adopt_ms),
                                 by_estimate: (st.inputs_by_estimate - before.inputs_by_estimate) / Math.max(1, drag.length),
                                 server_fps: st.server_fps, bytes_per_frame: Math.round(st.bytes_per_frame),
                                 frames_during_drag: st.frames - frames0, mid, quality, bad: st.bad, badFrames, consoleErrors,
                                 input_to_display_all: drag.map((v) => Math.round(v)) }));
  } else if (mode === 'orbit') {
    const settled = () => exactFrame(page);
    await settled().catch(() => fail('no full-size frame within the timeout'));
    const degS = Number(process.env.SY_ORBIT_DEG_S || 10), secs = Number(process.env.SY_ORBIT_S || 6);
    const everyMs = Number(process.env.SY_ORBIT_EVERY_MS || 250), held = process.env.SY_ORBIT_HOLD === '1';
    // the orbit, driven by the page's own display frames; captures kept in the page (window.__caps)
    const run = await page.evaluate(([degS, secs, everyMs, held]) => new Promise((done) => {
      const DEG_PER_PX = 0.008 * 180 / Math.PI; // view.js applyInput: 0.008 rad of yaw per pixel
      const caps = window.__caps = [], cum = [0], id0 = syStats.lastInput;
      // the orbit's own clock: wall time, but when held at most STEP_MS a display frame, so that
      // a display stalled by load (Chromium on two busy cores: 400 ms between frames seen) takes
      // the same captures at the same angles, only later
      const STEP_MS = held ? 50 : Infinity;
      let last = null, clock = 0, nextCap = everyMs;
      if (held) sy.hold(true);
      function tick(t) {
        if (last === null) { last = t; requestAnimationFrame(tick); return; }
        const dt = Math.min(t - last, STEP_MS), dx = degS * dt / 1000 / DEG_PER_PX;
        last = t;
        clock += dt;
        sy.input({ t: 'drag', dx: dx, dy: 0, b: 0 });
        cum.push(cum[cum.length - 1] + dx);
        if (clock >= nextCap) {
          nextCap += everyMs;
          const ms = clock;
          sy.capture().then((c) => { c.ms = ms; caps.push(c); });
        }
        if (clock < secs * 1000) requestAnimationFrame(tick);
        else sy.capture().then(() => { if (held) sy.hold(false); done({ id0: id0, cum: cum }); });
      }
      requestAnimationFrame(tick);
    }), [degS, secs, everyMs, held]);
    await settled().catch(() => fail('no full-size frame answered the orbit'));
    // each estimate's true frame: a drag back (or on) to its view, then the exact frame of it
    const png = (name, k) => page.evaluate(async ([name, k]) => {
      const c = window.__caps[k], src = name === 'est' ? c : c.truth, w = src.w, h = src.h;
      const img = new ImageData(w, h);
      for (let y = 0; y < h; y++) img.data.set(src.pixels.subarray((h - 1 - y) * w * 4, (h - y) * w * 4), y * w * 4);
      const oc = new OffscreenCanvas(w, h);
      oc.getContext('2d').putImageData(img, 0, 0);
      const b = new Uint8Array(await (await oc.convertToBlob({ type: 'image/png' })).arrayBuffer());
      let s = '';
      for (let i = 0; i < b.length; i += 0x8000) s += String.fromCharCode.apply(null, b.subarray(i, i + 0x8000));
      return btoa(s);
    }, [name, k]);
    const n = await page.evaluate(() => window.__caps.length);
    const out = [];
    let at = run.cum.length - 1; // the inputs of the orbit the server's view includes now
    for (let k = 0; k < n; k++) {
      const c = await page.evaluate((k) => { const c = window.__caps[k]; return { estimate: c.estimate, input: c.input, unfilled: c.unfilled, yaw: c.orbit.yaw, ms: c.ms, refs: c.refs }; }, k);
      const i = Math.max(0, Math.min(run.cum.length - 1, c.input - run.id0));
      const rec = { k, ms: Math.round(c.ms), estimate: c.estimate, unfilled: c.unfilled, yaw: c.yaw, refs: c.refs,
                    turned_deg: run.cum[i] * 0.008 * 180 / Math.PI };
      if (c.estimate) {
        const dx = run.cum[i] - run.cum[at];
        if (dx) await page.evaluate((dx) => sy.input({ t: 'drag', dx: dx, dy: 0, b: 0 }), dx);
        at = i;
        await settled().catch(() => fail(`no full-size frame of capture ${k}'s view`));
        rec.yaw_true = await page.evaluate(async (k) => { const t = await sy.capture(); window.__caps[k].truth = t; return t.orbit.yaw; }, k);
        writeFileSync(join(outDir, `est_${k}.png`), Buffer.from(await png('est', k), 'base64'));
        writeFileSync(join(outDir, `true_${k}.png`), Buffer.from(await png('true', k), 'base64'));
      }
      out.push(rec);
    }
    const est = out.filter((c) => c.estimate);
    if (!est.length) fail('no capture was an estimate');
    if (!process.env.SY_PNG_SSIM) fail('SY_PNG_SSIM (tests/support/png_ssim) is not set');
    let said;
    try {
      said = execFileSync(process.env.SY_PNG_SSIM, est.flatMap((c) => [join(outDir, `est_${c.k}.png`), join(outDir, `true_${c.k}.png`)]),
                          { encoding: 'utf8' }).trim().split('\n');
    } catch (e) { fail(`png_ssim: ${String(e.stderr || e.message).trim()}`); }
    est.forEach((c, i) => { c.ssim = Number(said[i].split(' ')[1]); });
    const s = est.map((c) => c.ssim).sort((a, b) => a - b), q = (p) => s[Math.min(s.length - 1, Math.floor(p * s.length))];
    const angle = (a, b) => { const d = Math.abs(a - b) % (2 * Math.PI); return Math.min(d, 2 * Math.PI - d); };
    const st = await page.evaluate(() => sy.stats());
    const fm = st.frame_ms.slice(-60).sort((a, b) => a - b);
    console.log(JSON.stringify({ held, deg_s: degS, secs, estimates: est.length, frame_ms_p50: fm[fm.length >> 1], ssim_median: q(0.5), ssim_p10: q(0.1), ssim_min: s[0],
                                 unfilled_max: Math.max(...out.map((c) => c.unfilled)), yaw_diff_max: Math.max(...est.map((c) => angle(c.yaw, c.yaw_true))),
                                 bad: st.bad, server_fps: st.server_fps, stride: st.stride, warp_scale: st.warp_scale, ahead: st.ahead, consoleErrors, captures: out }));
  } else if (mode === 'converge') {
    // a still view of a progressive back-end: the canvas early (the first full-size frames) and
    // late (16 times the samples, at least 64): noise, the mean absolute difference of each pixel
    // to the mean of its four neighbours (0..255, RGB), computed in the browser
    const snap = async (name) => {
      const s0 = await page.evaluate(() => syStats.samples);
      await canvasPng(page, '#sy-canvas', join(outDir, name));
      const s1 = await page.evaluate(() => syStats.samples);
      const png = readFileSync(join(outDir, name)).toString('base64');
      const noise = await page.evaluate(async (s) => {
        const bmp = await createImageBitmap(await (await fetch('data:image/png;base64,' + s)).blob());
        const c = new OffscreenCanvas(bmp.width, bmp.height), g = c.getContext('2d');
        g.drawImage(bmp, 0, 0);
        const p = g.getImageData(0, 0, bmp.width, bmp.height).data, w = bmp.width, h = bmp.height;
        let sum = 0, n = 0;
        for (let y = 1; y < h - 1; y++) for (let x = 1; x < w - 1; x++) for (let k = 0; k < 3; k++) {
          const i = 4 * (y * w + x) + k;
          sum += Math.abs(p[i] - (p[i - 4] + p[i + 4] + p[i - 4 * w] + p[i + 4 * w]) / 4); n++;
        }
        return sum / n;
      }, png);
      return { samples: [s0, s1], noise };
    };
    await page.waitForFunction(([w, h]) => window.syStats && syStats.frames > 0 && syStats.width === w && syStats.height === h,
                               [width, height], { timeout: TIMEOUT }).catch(() => fail('no full-size frame within the timeout'));
    const early = await snap('early.png');
    const want = Math.max(64, 16 * early.samples[1]);
    await page.waitForFunction((n) => syStats.samples >= n, want, { timeout: TIMEOUT })
      .catch(() => fail(`the still view did not reach ${want} samples`));
    const late = await snap('late.png');
    const st = await page.evaluate(() => sy.stats());
    console.log(JSON.stringify({ early, late, bad: st.bad, frames: st.frames, bytes_per_frame: Math.round(st.bytes_per_frame),
                                 depth: st.depth, server_fps: st.server_fps, consoleErrors }));
  } else if (mode === 'tools') {
    // the page's tools (ui.js, tree.js, measure.js, section.js): pick by a click, hide from the
    // tree, measure, a section plane, the help, the screenshot; screenshots of each state
    const readOnly = url.includes('readonly=1'); // browser_test.sh's second server: sy web --read-only
    const settled = () => page.waitForFunction(
      ([w, h]) => window.syStats && syStats.frames > 0 && syStats.width === w && syStats.height === h &&
                  syStats.answeredInput === syStats.lastInput && window.sy && sy.ui && sy.ui.tree && sy.ui.tree.version > 0,
      [width, height], { timeout: TIMEOUT });
    await settled();
    const frames = () => page.evaluate(() => syStats.frames);
    // a few display frames after the newest server frame: it is on the canvas
    const shown = async (n) => {
      await page.waitForFunction((k) => syStats.frames > k, n, { timeout: TIMEOUT });
      await page.evaluate(() => new Promise((r) => requestAnimationFrame(() => requestAnimationFrame(r))));
    };
    // a change of the server's view settings (planes, caps, environment) is applied once the answer
    // to a tree request sent after it says so (the render thread takes the requests in order and
    // renders after each batch); one tree request at a time: the page drops an older one's answer
    const applied = async (cond, arg) => {
      for (let k = 0; ; k++) {
        const v = await page.evaluate(() => { sy.ui.tree.refresh(); return sy.ui.tree.version; });
        await page.waitForFunction((x) => sy.ui.tree.version > x, v, { timeout: TIMEOUT });
        if (await page.evaluate(([c, a]) => new Function('a', 'return ' + c)(a), [cond, arg])) break;
        if (k === 50) fail(`the server did not apply ${cond} (${arg})`);
      }
      // then a frame rendered after it: one that answers inputs sent now (a wheel notch in and out:
      // the same view), at full size
      // (each its own frame: in and out in one batch would leave the view as it was, and a view
      // at rest is not rendered again)
      for (const steps of [1, -1]) {
        await page.evaluate((n) => sy.input({ t: 'wheel', steps: n }), steps);
        await settled();
      }
      await page.evaluate(() => new Promise((r) => requestAnimationFrame(() => requestAnimationFrame(r))));
    };
    // the covered pixels of the current view: the server's still at the canvas size (its coverage
    // is the stream's), decoded in the page; the one nearest the centre and one to its right
    const targets = await page.evaluate(async ([w, h]) => {
      const r = await fetch(`/api/frame.jpg?w=${w}&h=${h}`);
      const bmp = await createImageBitmap(await r.blob());
      const c = new OffscreenCanvas(w, h), g = c.getContext('2d');
      g.drawImage(bmp, 0, 0);
      const d = g.getImageData(0, 0, w, h).data, lit = (x, y) => d[4 * (y * w + x)] + d[4 * (y * w + x) + 1] + d[4 * (y * w + x) + 2] > 60;
      let best = null;
      for (let y = 0; y < h; y += 2) for (let x = 0; x < w; x += 2)
        if (lit(x, y) && (!best || Math.hypot(x - w / 2, y - h / 2) < Math.hypot(best[0] - w / 2, best[1] - h / 2))) best = [x, y];
      let second = null;
      for (let x = Math.min(w - 1, best[0] + 120); x > best[0] + 10 && !second; x--) if (lit(x, best[1])) second = [x, best[1]];
      for (let x = Math.max(0, best[0] - 120); x < best[0] - 10 && !second; x++) if (lit(x, best[1])) second = [x, best[1]];
      return { first: best, second };
    }, [width, height]);
    if (!targets.first || !targets.second) fail(`no covered pixels to pick: ${JSON.stringify(targets)}`);
    const [px, py] = targets.first;
    // the streamed canvas (overlays hidden) as PNG, base64
    const canvasB64 = async (name) => { await canvasPng(page, '#sy-canvas', join(outDir, name)); return readFileSync(join(outDir, name)).toString('base64'); };
    // mean absolute RGB difference of two canvas PNGs in the 9 x 9 box at (x, y), and the share of the canvas that differs by > 40
    const diff = (a, b, x, y) => page.evaluate(async ([a, b, x, y]) => {
      const load = async (s) => { const bm = await createImageBitmap(await (await fetch('data:image/png;base64,' + s)).blob());
        const c = new OffscreenCanvas(bm.width, bm.height), g = c.getContext('2d'); g.drawImage(bm, 0, 0); return g.getImageData(0, 0, bm.width, bm.height); };
      const A = await load(a), B = await load(b);
      let box = 0, n = 0, changed = 0;
      for (let i = 0; i < A.data.length; i += 4) {
        const e = Math.abs(A.data[i] - B.data[i]) + Math.abs(A.data[i + 1] - B.data[i + 1]) + Math.abs(A.data[i + 2] - B.data[i + 2]);
        const p = i / 4, u = p % A.width, v = Math.floor(p / A.width);
        if (e > 40 * 3) changed++;
        if (Math.abs(u - x) <= 4 && Math.abs(v - y) <= 4) { box += e / 3; n++; }
      }
      return { box: box / n, changed: changed / (A.width * A.height) };
    }, [a, b, x, y]);
    const before = await canvasB64('before.png');
    await page.screenshot({ path: join(outDir, 'page.png') });
    // 1. a click picks and (unless read-only) selects
    const picks0 = await page.evaluate(() => sy.ui.tree.picks);
    await page.mouse.click(px, py);
    await page.waitForFunction((n) => sy.ui.tree.picks > n && sy.ui.tree.lastPick, picks0, { timeout: TIMEOUT });
    const pick = await page.evaluate(() => sy.ui.tree.lastPick);
    if (!pick.hit || !(pick.node > 0)) fail(`the click at ${px},${py} picked nothing: ${JSON.stringify(pick)}`);
    const props = await page.evaluate(() => document.getElementById('sy-props').innerText);
    if (!props.includes('#' + pick.node) || !props.includes('position')) fail(`the properties do not show the pick: ${props}`);
    if (!readOnly) await page.waitForFunction((n) => sy.ui.tree.selected === n, pick.node, { timeout: TIMEOUT });
    // for the screenshot: the selection's refined frame (a scene change gives a coarse frame first;
    // not a check: the wait ends quietly when that frame came before this)
    const fs0 = await frames();
    await page.waitForFunction(([k, w]) => syStats.frames > k && syStats.width === w, [fs0, width], { timeout: 20000 }).catch(() => {});
    await settled();
    let f0 = await frames();
    await page.screenshot({ path: join(outDir, 'tree.png') });
    // 2. hide the picked node from the tree: the streamed image changes where it was
    const row = page.locator(`#sy-tree [data-node="${pick.node}"] input[type=checkbox]`);
    const result = { pick: { node: pick.node, name: pick.name, position: pick.position, at: [px, py] }, readOnly };
    if (readOnly) {
      result.hidden_controls = await page.evaluate(() => ({ sections: getComputedStyle(document.getElementById('sy-section')).display === 'none',
        checkbox_disabled: [...document.querySelectorAll('#sy-tree input')].every((c) => c.disabled), badge: !!document.getElementById('sy-readonly'),
        selected: sy.ui.tree.selected }));
      // a page that sends a change anyway: refused by the server, the tree unchanged
      const v0 = await page.evaluate(() => sy.ui.tree.version);
      await page.evaluate((n) => { sy.send({ t: 'visible', node: n, on: false }); sy.ui.tree.refresh(); }, pick.node);
      await page.waitForFunction((v) => sy.ui.tree.version > v, v0, { timeout: TIMEOUT });
      result.still_visible = await page.evaluate((n) => sy.ui.tree.nodes.find((x) => x.id === n).visible, pick.node);
    } else {
      // the picture with the picked node selected (its highlight): what showing it again must bring back
      await applied('sy.ui.tree.selected === a', pick.node);
      const selected = await canvasB64('selected_canvas.png');
      await row.click();
      await page.waitForFunction((n) => { const x = sy.ui.tree.nodes.find((k) => k.id === n); return x && !x.visible; }, pick.node, { timeout: TIMEOUT });
      await shown(f0);
      await settled();
      await page.screenshot({ path: join(outDir, 'hidden.png') });
      const hidden = await canvasB64('hidden_canvas.png');
      result.hide = await diff(before, hidden, px, py);
      // a pick there no longer names it (a pick that does not select: a click would select what is
      // behind, the floor, whose tint the mirror sphere reflects when it is shown again)
      const p1 = await page.evaluate(() => sy.ui.tree.picks);
      await page.evaluate(([x, y]) => { const r = document.getElementById('sy-canvas').getBoundingClientRect();
        sy.send({ t: 'pick', x: (x - r.left) / r.width, y: (y - r.top) / r.height, select: false, seq: 76 }); }, [px, py]);
      await page.waitForFunction((n) => sy.ui.tree.picks > n, p1, { timeout: TIMEOUT });
      result.pick_hidden = await page.evaluate(() => ({ hit: sy.ui.tree.lastPick.hit, node: sy.ui.tree.lastPick.node }));
      // show it again: back as it was
      f0 = await frames();
      await row.click();
      await page.waitForFunction((n) => { const x = sy.ui.tree.nodes.find((k) => k.id === n); return x && x.visible; }, pick.node, { timeout: TIMEOUT });
      await shown(f0);
      await settled();
      result.show = await diff(selected, await canvasB64('shown_canvas.png'), px, py);
      // (for 3b: where the demo's gold box is, before any plane cuts it)
      const boxPick = await page.evaluate(async () => {
        const n = sy.ui.tree.picks;
        sy.send({ t: 'pick', x: 0.458, y: 0.70, select: false, seq: 77 });
        for (let k = 0; k < 600 && sy.ui.tree.picks === n; k++) await new Promise((r) => setTimeout(r, 100));
        return sy.ui.tree.lastPick;
      });
      if (!boxPick || !boxPick.hit || !/box/.test(boxPick.name)) fail(`no box at 46 %, 70 % of the canvas: ${JSON.stringify(boxPick)}`);
      // 3. a section plane (X, in the middle of the scene): the image changes; removed: back
      f0 = await frames();
      await page.click('#sy-plane-add');
      await shown(f0);
      await settled();
      await page.screenshot({ path: join(outDir, 'section.png') });
      const sectionB64 = await canvasB64('section_canvas.png');
      result.section = await diff(before, sectionB64, px, py);
      // 3b. caps on in magenta: the cut faces of the closed meshes show that colour (ACES and sRGB
      // keep a magenta's hue: red and blue high, green low), none did before
      // the plane turned to Z through the demo's gold box (a closed mesh; the spheres are not),
      // 0.1 behind its front face (a pick at the box, 46 % across and 70 % down the canvas),
      // keeping the far side: the cut face looks at the camera
      await page.evaluate((z) => {
        const p = sy.ui.planes[0], t = sy.ui.tree, lo = t.min[2], hi = t.max[2], pad = (hi - lo) * 0.01 + 1e-6;
        p.axis = 'z'; p.flip = true; p.row.querySelector('select').value = 'z';
        p.t = (z - 0.1 - (lo - pad)) / (hi - lo + 2 * pad); p.range.value = String(p.t);
        sy.ui.sendPlanes();
      }, boxPick.position[2]);
      await applied('sy.ui.tree.planes.length === 1 && sy.ui.tree.planes[0][2] === -1', null);
      const zcutB64 = await canvasB64('zcut_canvas.png');
      await page.evaluate(() => sy.ui.setCap('#ff00ff'));
      await applied('sy.ui.tree.cap && sy.ui.tree.cap[0] === 1 && sy.ui.tree.cap[1] === 0', null);
      await page.evaluate(() => { document.getElementById('sy-section').scrollIntoView(); });
      await page.screenshot({ path: join(outDir, 'cap.png') });
      const magenta = (b64) => page.evaluate(async (s) => {
        const bm = await createImageBitmap(await (await fetch('data:image/png;base64,' + s)).blob());
        const c = new OffscreenCanvas(bm.width, bm.height), g = c.getContext('2d'); g.drawImage(bm, 0, 0);
        const d = g.getImageData(0, 0, bm.width, bm.height).data;
        let n = 0;
        for (let i = 0; i < d.length; i += 4) if (d[i] > 150 && d[i + 2] > 150 && d[i + 1] < 90) n++;
        return n / (bm.width * bm.height);
      }, b64);
      result.cap = { before: await magenta(zcutB64), after: await magenta(await canvasB64('cap_canvas.png')) };
      await page.evaluate(() => sy.ui.setCap(null));
      await applied('sy.ui.tree.cap === null', null);
      f0 = await frames();
      await page.locator('#sy-section button[title=remove]').click();
      await shown(f0);
      await settled();
    }
    // 4. measure two points
    await page.keyboard.press('m');
    for (const [x, y] of [targets.first, targets.second]) {
      const n = await page.evaluate(() => sy.ui.tree.picks);
      await page.mouse.click(x, y);
      await page.waitForFunction((k) => sy.ui.tree.picks > k, n, { timeout: TIMEOUT });
    }
    await page.waitForFunction(() => sy.ui.measure.points.length === 2 && sy.ui.measure.distance !== null, null, { timeout: TIMEOUT });
    await page.evaluate(() => new Promise((r) => requestAnimationFrame(() => requestAnimationFrame(r))));
    await page.screenshot({ path: join(outDir, 'measure.png') });
    result.measure = await page.evaluate(() => ({ points: sy.ui.measure.points, distance: sy.ui.measure.distance,
                                                   text: document.getElementById('sy-measure-out').innerText }));
    if (!readOnly) { // a section plane (X, mid-scene): the last point's signed distance to it
      await page.click('#sy-plane-add');
      result.to_plane = await page.evaluate(() => {
        const t = sy.ui.tree, p = sy.ui.measure.points[1];
        return { shown: sy.ui.measure.toPlanes, want: p[0] - (t.min[0] + t.max[0]) / 2,
                 text: document.getElementById('sy-measure-out').innerText.includes('to plane 1') };
      });
      await page.locator('#sy-section button[title=remove]').click();
    }
    await page.keyboard.press('Escape'); // leaves measuring: the points and the line go
    await page.evaluate(() => new Promise((r) => requestAnimationFrame(() => requestAnimationFrame(r))));
    result.measure_cleared = await page.evaluate(() => ({ points: sy.ui.measure.points.length,
      drawn: [...document.querySelectorAll('svg line, svg circle')].filter((n) => n.style.display !== 'none').length }));
    // 5. the help overlay
    await page.keyboard.press('?');
    await page.waitForFunction(() => sy.ui.helpOpen, null, { timeout: TIMEOUT });
    await page.screenshot({ path: join(outDir, 'help.png') });
    result.help = await page.evaluate(() => document.getElementById('sy-help').innerText.length);
    await page.keyboard.press('Escape');
    // 5b. the environment menu: "none" then the studio (the tree, every page's menu, names it), back to the scene's
    if (!readOnly) {
      result.environment = {};
      await applied('true', null); // the planes of the measuring step gone, refined
      const envCanvas = {}, envBefore = await canvasB64('env_before_canvas.png');
      for (const env of ['none', 'studio', 'scene']) {
        await page.selectOption('#sy-environment', env);
        await applied('sy.ui.tree.environment === a', env);
        if (env === 'none') {
          await page.evaluate(() => { document.getElementById('sy-panel').scrollTop = 0; });
          await page.screenshot({ path: join(outDir, 'menu.png') });
        }
        envCanvas[env] = await canvasB64(`env_${env}_canvas.png`);
      }
      result.environment.none = await diff(envBefore, envCanvas.none, px, py);
      result.environment.studio = await diff(envBefore, envCanvas.studio, px, py);
      result.environment.scene = await diff(envBefore, envCanvas.scene, px, py);
      result.environment.options = await page.evaluate(() => [...document.querySelectorAll('#sy-environment option')].map((o) => o.value));
    } else {
      result.environment_hidden = await page.evaluate(() => getComputedStyle(document.getElementById('sy-environment').parentNode).display === 'none');
    }
    // 6. the screenshot button: a JPEG of the canvas' size, downloaded
    const download = page.waitForEvent('download', { timeout: TIMEOUT });
    await page.click('#sy-shot');
    const dl = await download;
    await page.waitForFunction(() => sy.ui.shot && sy.ui.shot.state !== 'pending', null, { timeout: TIMEOUT });
    result.shot = Object.assign(await page.evaluate(() => sy.ui.shot), { file: dl.suggestedFilename() });
    // 7. touch: a two-finger pinch (synthetic pointer events) zooms, one finger orbits
    const in0 = await page.evaluate(() => sy.stats().last_input);
    await page.evaluate(([x, y]) => {
      const c = document.getElementById('sy-canvas');
      const ev = (type, id, cx, cy) => c.dispatchEvent(new PointerEvent(type, { pointerId: id, pointerType: 'touch', clientX: cx, clientY: cy,
                                                                             isPrimary: id === 11, bubbles: true }));
      ev('pointerdown', 11, x - 20, y); ev('pointerdown', 12, x + 20, y);
      for (let k = 1; k <= 5; k++) { ev('pointermove', 11, x - 20 - 8 * k, y); ev('pointermove', 12, x + 20 + 8 * k, y); }
      ev('pointerup', 11, x - 60, y); ev('pointerup', 12, x + 60, y);
      ev('pointerdown', 13, x, y);
      for (let k = 1; k <= 5; k++) ev('pointermove', 13, x + 6 * k, y);
      ev('pointerup', 13, x + 30, y);
    }, [px, py]);
    result.touch_inputs = (await page.evaluate(() => sy.stats().last_input)) - in0;
    await settled();
    // 8. saved views (views.js): the view now saved as 3 with the panel's Save as (listed, its
    // button on, 4's off), a drag away (the canvas changes), Shift+3 recalls it (the canvas as it
    // was). A read-only page has no Save (browser_test.sh: the server refuses one sent anyway)
    const atRest = async () => { await settled(); await page.evaluate(() => new Promise((r) => requestAnimationFrame(() => requestAnimationFrame(r)))); };
    if (!readOnly) {
      await atRest();
      const savedB64 = await canvasB64('view_saved_canvas.png');
      const v0 = await page.evaluate(() => sy.ui.views.received);
      await page.selectOption('#sy-view-slot', '3');
      await page.click('#sy-view-save');
      await page.waitForFunction((n) => sy.ui.views.received > n && sy.ui.views.list.some((v) => v.n === 3), v0, { timeout: TIMEOUT });
      result.views_saved = await page.evaluate(() => ({ list: sy.ui.views.list, kept: sy.ui.views.kept,
        on3: !document.getElementById('sy-view-3').disabled, off4: document.getElementById('sy-view-4').disabled }));
      await page.mouse.move(px, py); await page.mouse.down();
      await page.mouse.move(px + 90, py + 30, { steps: 6 }); await page.mouse.up();
      await atRest();
      const movedB64 = await canvasB64('view_moved_canvas.png');
      await page.keyboard.press('Shift+Digit3');
      await page.waitForFunction(() => sy.stats().last_input > 0 && syStats.answeredInput === syStats.lastInput, null, { timeout: TIMEOUT });
      await atRest();
      await page.screenshot({ path: join(outDir, 'views.png') });
      const backB64 = await canvasB64('view_recalled_canvas.png');
      result.views = { moved: await diff(savedB64, movedB64, px, py), recalled: await diff(savedB64, backB64, px, py) };
    } else {
      await page.evaluate(() => sy.send({ t: 'view', n: 1, save: true })); // refused: the server logs it
      result.views_ro = await page.evaluate(() => ({ save_hidden: getComputedStyle(document.getElementById('sy-view-save').parentNode).display === 'none',
                                                    section: !!document.getElementById('sy-views') }));
    }
    result.consoleErrors = consoleErrors;
    console.log(JSON.stringify(result));
  } else if (mode === 'timeline') {
    // the scene clock from the page: scrub to the start, to the middle and back, play, pause
    await page.waitForFunction(() => window.syStats && syStats.frames > 0 && window.sy && sy.timeline && sy.timeline().shown,
      null, { timeout: TIMEOUT }).catch(() => fail('no frame, or no timeline (the scene has no animations?)'));
    const tl = () => page.evaluate(() => sy.timeline());
    const first = await tl();
    // moves the slider as a user does (input, then change) and waits for frames rendered after it
    const scrub = async (t) => {
      const n = await page.evaluate(() => syStats.frames);
      await page.evaluate((v) => {
        const r = document.getElementById('sy-scrub');
        r.value = String(v);
        r.dispatchEvent(new Event('input', { bubbles: true }));
        r.dispatchEvent(new Event('change', { bubbles: true }));
      }, t);
      await page.waitForFunction((n) => syStats.frames >= n + 2, n, { timeout: TIMEOUT }).catch(() => fail(`no frames after scrubbing to ${t}`));
    };
    // the canvas once it stopped changing: frames until two in a row are equal (at most 20)
    const steady = async (name) => {
      const path = join(outDir, name + '.png'), prev = join(outDir, name + '_prev.png');
      await canvasPng(page, '#sy-canvas', prev);
      for (let i = 0; i < 20; i++) {
        const n = await page.evaluate(() => syStats.frames);
        await page.waitForFunction((n) => syStats.frames > n, n, { timeout: 5000 }).catch(() => {}); // a still view sends no more
        await canvasPng(page, '#sy-canvas', path);
        if ((await pngMad(page, prev, path)) < 0.5) return path;
        await canvasPng(page, '#sy-canvas', prev);
      }
      return path;
    };
    const mid = first.start + 0.16 * (first.end - first.start); // BoxAnimated: the inner box half risen (0.59 s)
    await scrub(first.start);
    const a = await steady('t_start');
    await scrub(mid);
    const b = await steady('t_mid');
    await scrub(first.start);
    const c = await steady('t_start_again');
    const moved = await pngMad(page, a, b), back = await pngMad(page, a, c);
    const scrubbed = await tl();
    // play: space on the canvas; the server's clock advances (its "clock" messages say so)
    await page.locator('#sy-canvas').focus();
    await page.keyboard.press('Space');
    const t0 = (await tl()).server_time;
    await page.waitForFunction((t0) => { const s = sy.timeline(); return s.playing && s.server_time !== t0; }, t0, { timeout: TIMEOUT })
      .catch(() => fail('play: the server\'s clock did not advance'));
    const playing = await tl();
    await page.screenshot({ path: join(outDir, 'timeline.png') });
    const playedFrames = await page.evaluate(() => syStats.frames);
    await page.waitForFunction((n) => syStats.frames >= n + 3, playedFrames, { timeout: TIMEOUT })
      .catch(() => fail('play: no frames while playing'));
    await page.keyboard.press('Space');
    await page.waitForFunction(() => !sy.timeline().playing, null, { timeout: TIMEOUT }).catch(() => fail('space did not pause'));
    const paused = await tl();
    // bad times: out of the clips' range and not a number (JSON null): refused by the server (logged)
    await page.evaluate(([lo, hi]) => { sy.send({ t: 'time', s: hi + 100 }); sy.send({ t: 'time', s: NaN }); sy.send({ t: 'time', s: lo - 1 }); },
      [first.start, first.end]);
    await page.waitForTimeout(200); // the refusals are only logged: nothing to wait for on the page
    const after = await tl();
    console.log(JSON.stringify({ first, scrubbed, playing, paused, after, moved, back, consoleErrors }));
  } else if (mode === 'client_timeline') {
    const settled = () => page.waitForFunction(() => window.syClient && syClient.queries > 0 && syClient.idle &&
                                                      syClient.requested.length > 0 && !syClient.renderPending, null,
                                               { timeout: TIMEOUT });
    await settled().catch(() => fail('the client did not settle'));
    await page.waitForFunction(() => syClient.timeline().shown, null, { timeout: TIMEOUT })
      .catch(() => fail('no timeline on the client page (the scene has no animations?)'));
    const first = await page.evaluate(() => syClient.timeline());
    // (milliseconds: the server's clock messages print times with 9 digits)
    const times = [first.start, Math.round((first.start + 0.16 * (first.end - first.start)) * 1000) / 1000];
    const shots = [];
    for (let k = 0; k < times.length; k++) {
      const t = times[k];
      await page.evaluate((t) => syClient.setTime(t), t);
      // the pose asked after the server's clock message of t, then the page idle (a cull after it) and drawn
      await page.waitForFunction((t) => { const s = syClient.timeline(); return s.poseTime !== null && Math.abs(s.poseTime - t) < 1e-6 && !s.playing; }, t, { timeout: TIMEOUT })
        .catch(async () => fail(`no pose at ${t} s: ${JSON.stringify(await page.evaluate(() => syClient.timeline()))}`));
      await page.waitForFunction(() => syClient.idle && !syClient.renderPending && syClient.frames > 0, null, { timeout: TIMEOUT })
        .catch(() => fail(`the client did not settle at ${t} s`));
      await page.evaluate(() => new Promise((r) => requestAnimationFrame(() => requestAnimationFrame(r))));
      await canvasPng(page, 'canvas', join(outDir, `client_t${k}.png`));
      shots.push(await page.evaluate(() => syClient.timeline()));
    }
    const errors = await page.evaluate(() => syClient.errors);
    writeFileSync(join(outDir, 'client_timeline.json'), JSON.stringify({ times, shots, errors, consoleErrors }));
    console.log(JSON.stringify({ first, times, shots, errors, consoleErrors }));
  } else if (mode === 'video') {
    const codecs = await page.evaluate(() => window.syVideo ? syVideo.ready : []);
    await page.goto('about:blank'); // no viewer beside the pages below
    if (!codecs.length) {
      console.log("SKIP: this chromium's WebCodecs decodes neither vp8 nor vp9 (VideoDecoder.isConfigSupported)");
      await browser.close();
      process.exit(77);
    }
    const withQuery = (q) => url + (url.includes('?') ? '&' : '?') + q;
    // a full-size frame answering every input sent so far, shown as it is (of the codec asked)
    const settled = (p, video) => p.waitForFunction(
      ([w, h, video]) => window.syStats && window.sy && syStats.frames > 0 && syStats.width === w && syStats.height === h &&
                         syStats.answeredInput === syStats.lastInput && sy.stats().estimate_share === 0 &&
                         (!video || (sy.stats().video.codec === video && sy.stats().video.frames > 0)),
      [width, height, video], { timeout: TIMEOUT });
    const open = async (q) => {
      const p = await browser.newPage({ viewport: { width, height }, deviceScaleFactor: 1 });
      p.on('console', (m) => { if (m.type() === 'error') consoleErrors.push(m.text()); });
      p.on('pageerror', (e) => consoleErrors.push(String(e)));
      await p.goto(withQuery(q), { timeout: TIMEOUT });
      return p;
    };
    const still = (p) => p.waitForTimeout(300).then(() => p.evaluate(() => new Promise((r) => requestAnimationFrame(() => requestAnimationFrame(r)))));
    const result = { codecs, runs: [] };
    for (const codec of codecs) {
      const pj = await open('video=0');
      await settled(pj, null).catch(() => fail('the JPEG page got no full-size frame'));
      await still(pj);
      await canvasPng(pj, '#sy-canvas', join(outDir, `jpeg_${codec}.png`));
      const jpegStats = await pj.evaluate(() => sy.stats());
      await pj.close();
      const pv = await open('codec=' + codec);
      await settled(pv, codec).catch(() => fail(`the ${codec} page got no full-size ${codec} frame`));
      await still(pv);
      await canvasPng(pv, '#sy-canvas', join(outDir, `${codec}.png`));
      const before = await pv.evaluate(() => sy.stats());
      const mad = await pngMad(pv, join(outDir, `jpeg_${codec}.png`), join(outDir, `${codec}.png`));
      // a drag and back: the stream goes on with delta frames
      const x0 = width / 2 - 60, y0 = height / 2;
      for (const dir of [1, -1]) {
        await pv.mouse.move(x0, y0);
        await pv.mouse.down();
        for (let i = 1; i <= 20; i++) { await pv.mouse.move(x0 + dir * 3 * i, y0); await pv.waitForTimeout(16); }
        await pv.mouse.up();
        await settled(pv, codec).catch(() => fail(`no full-size ${codec} frame answered the drag`));
      }
      const after = await pv.evaluate(() => sy.stats());
      await pv.close();
      result.runs.push({ codec, mad, jpeg_bytes_per_frame: Math.round(jpegStats.bytes_per_frame), jpeg_video: jpegStats.video,
                         before: { video: before.video, bad: before.bad, frames: before.frames },
                         after: { video: after.video, bad: after.bad, frames: after.frames, bytes_per_frame: Math.round(after.bytes_per_frame) } });
    }
    result.consoleErrors = consoleErrors;
    console.log(JSON.stringify(result));
  } else {
    // idle (the last answer's objects all shown) and that state drawn (the page renders on demand)
    await page.waitForFunction(() => window.syClient && syClient.queries > 0 && syClient.idle &&
                                     syClient.requested.length > 0 && !syClient.renderPending, null,
                               { timeout: TIMEOUT })
      .catch(async () => fail(`the client did not settle: ${JSON.stringify(await page.evaluate(() => window.syClient &&
        { queries: syClient.queries, idle: syClient.idle, errors: syClient.errors }))}`));
    await canvasPng(page, 'canvas', join(outDir, 'canvas.png'));
    const s = await page.evaluate(() => ({
      requested: syClient.requested, loaded: syClient.loaded, visible: syClient.visible,
      triangles: syClient.triangles, fetched_triangles: syClient.fetched_triangles, bytes: syClient.bytes,
      total_objects: syClient.total_objects, total_triangles: syClient.total_triangles, errors: syClient.errors,
      camera: syClient.cameraJSON(),
    }));
    s.fetched = fetched;
    s.consoleErrors = consoleErrors;
    writeFileSync(join(outDir, 'client.json'), JSON.stringify(s));
    console.log(JSON.stringify({ requested: s.requested.length, fetched: fetched.length, triangles: s.triangles,
                                 total_objects: s.total_objects, total_triangles: s.total_triangles }));
  }
} catch (e) {
  fail(String(e.stack || e));
} finally {
  await browser.close();
}
