// browser.mjs — drives Debian's chromium, headless, over the DevTools protocol (playwright-core from
// npm, tests/browser/package.json) for the sy web tests (tests/browser/browser_test.sh).
//
//   node browser.mjs stream URL OUTDIR WIDTH HEIGHT
//     The streamed page (sy web): waits for a frame of the canvas' full size, writes the canvas
//     pixels to OUTDIR/canvas.png, drags across the canvas, waits for the full-size frame that
//     answers the drag, writes OUTDIR/dragged.png.
//   node browser.mjs client URL OUTDIR WIDTH HEIGHT
//     The client-render page (sy web --client-render): waits until the client is idle (its last
//     cull answer drawn), writes the canvas to OUTDIR/canvas.png and what the page fetched to
//     OUTDIR/client.json (the ids of the answer, the ids fetched over the network, the ids drawn,
//     triangles drawn and the totals).
//
// Prints one line of JSON with what it saw; exits 1 with the reason on any failure (timeouts
// included), 77 when chromium cannot be started.
import { chromium } from 'playwright-core';
import { writeFileSync } from 'node:fs';
import { join } from 'node:path';

const [mode, url, outDir, wArg, hArg] = process.argv.slice(2);
const width = Number(wArg || 480), height = Number(hArg || 360);
if (!['stream', 'client'].includes(mode) || !url || !outDir) {
  console.error('usage: node browser.mjs stream|client URL OUTDIR [WIDTH HEIGHT]');
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
  await page.goto(url, { timeout: TIMEOUT });

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
