// touch.js — touch gestures on the canvas (docs/WEB.md, "The page"): one finger orbits, two
// fingers pan (their midpoint moves) and zoom (pinch: the distance between them), sent as the
// same drag and wheel inputs as the mouse's (window.sy.input: the warp answers them at once).
// view.js leaves touch pointers to this script; a tap picks (tree.js).
"use strict";
(function () {
  const sy = window.sy, canvas = document.getElementById("sy-canvas");
  const touches = new Map(); // pointerId -> {x, y}
  let last = null; // two fingers: {mx, my, dist}
  function pair() {
    const [a, b] = [...touches.values()];
    return { mx: (a.x + b.x) / 2, my: (a.y + b.y) / 2, dist: Math.hypot(a.x - b.x, a.y - b.y) };
  }
  canvas.addEventListener("pointerdown", function (e) {
    if (e.pointerType !== "touch") return;
    try { canvas.setPointerCapture(e.pointerId); } catch (err) {} // (a synthetic pointer has nothing to capture)
    touches.set(e.pointerId, { x: e.clientX, y: e.clientY });
    last = touches.size === 2 ? pair() : null;
  });
  canvas.addEventListener("pointermove", function (e) {
    const t = touches.get(e.pointerId);
    if (e.pointerType !== "touch" || !t) return;
    const dx = e.clientX - t.x, dy = e.clientY - t.y;
    t.x = e.clientX; t.y = e.clientY;
    if (touches.size === 1) {
      if (dx || dy) sy.input({ t: "drag", dx: dx, dy: dy, b: 0 });
    } else if (touches.size === 2 && last) {
      const p = pair();
      const mx = p.mx - last.mx, my = p.my - last.my;
      if (mx || my) sy.input({ t: "drag", dx: mx, dy: my, b: 1 });
      if (p.dist > 0 && last.dist > 0 && p.dist !== last.dist) { // pinch out: closer (distance x 0.9 per notch)
        const steps = Math.max(-50, Math.min(50, Math.log(p.dist / last.dist) / -Math.log(0.9)));
        if (Math.abs(steps) > 1e-3) sy.input({ t: "wheel", steps: steps });
      }
      last = p;
    }
  });
  function up(e) {
    if (e.pointerType !== "touch") return;
    touches.delete(e.pointerId);
    last = touches.size === 2 ? pair() : null;
  }
  canvas.addEventListener("pointerup", up);
  canvas.addEventListener("pointercancel", up);
})();
