// measure.js — the measuring tool (docs/WEB.md, "The page"): while it is on (the Measure button or the M key),
// clicks pick without selecting and the first two picked points give their distance in scene
// units (glTF: metres) and its X, Y, Z parts, and the last point's distance to each section plane
// in use; a third click starts again, Esc takes them away. The points and the line
// between them are drawn over the canvas where window.sy.project puts them, every display frame.
"use strict";
(function () {
  const sy = window.sy, ui = sy.ui, el = ui.el;
  const sec = ui.section("Measure", "sy-measure");
  const out = el("div", { class: "kv", id: "sy-measure-out" }, sec);
  const note = el("div", { class: "note" }, sec, "Measure (or M), then click two points");
  const NS = "http://www.w3.org/2000/svg";
  const svg = document.createElementNS(NS, "svg");
  svg.setAttribute("style", "position: fixed; left: 0; top: 0; width: 100vw; height: 100vh; pointer-events: none; z-index: 1;");
  document.body.appendChild(svg);
  const line = document.createElementNS(NS, "line");
  line.setAttribute("stroke", "#ffd54a"); line.setAttribute("stroke-width", "2"); line.setAttribute("stroke-dasharray", "6 3");
  svg.appendChild(line);
  const dots = [0, 1].map(function () {
    const c = document.createElementNS(NS, "circle");
    c.setAttribute("r", "5"); c.setAttribute("fill", "#ffd54a"); c.setAttribute("stroke", "#000");
    svg.appendChild(c);
    return c;
  });
  const label = document.createElementNS(NS, "text");
  label.setAttribute("fill", "#ffd54a"); label.setAttribute("stroke", "#000"); label.setAttribute("stroke-width", "3");
  label.setAttribute("paint-order", "stroke"); label.setAttribute("font", "bold 14px sans-serif"); label.setAttribute("font-size", "14");
  svg.appendChild(label);
  const m = ui.measure = { active: false, points: [], distance: null };
  const btn = ui.button("Measure", "click two points: their distance in scene units (M)", function () { setActive(!m.active); });
  btn.id = "sy-measure-button";
  function setActive(on) {
    m.active = on;
    btn.classList.toggle("on", on);
    document.getElementById("sy-canvas").style.cursor = on ? "crosshair" : "";
    note.textContent = on ? "click two points on the model" : "Measure (or M), then click two points";
  }
  m.setActive = setActive;
  // Esc: leaves measuring and takes the points and the line away (the button alone keeps them)
  function clear() {
    setActive(false);
    m.points = []; m.distance = null;
    show();
  }
  const fmt = (x) => Math.abs(x) >= 1e4 || (Math.abs(x) < 1e-3 && x) ? x.toExponential(4) : x.toFixed(4);
  function show() {
    out.textContent = "";
    const rows = [];
    m.points.forEach(function (p, i) { rows.push(["point " + (i + 1), p.map(fmt).join(", ")]); });
    if (m.distance !== null) {
      const d = [0, 1, 2].map((i) => m.points[1][i] - m.points[0][i]);
      rows.push(["distance", fmt(m.distance) + " (scene units)"], ["dx, dy, dz", d.map(fmt).join(", ")]);
    }
    // the last point's distance to each section plane in use (signed: positive on the kept side)
    const last = m.points[m.points.length - 1], planes = ui.activePlanes ? ui.activePlanes() : [];
    m.toPlanes = last ? planes.map((q) => (q[0] * last[0] + q[1] * last[1] + q[2] * last[2] + q[3]) / Math.hypot(q[0], q[1], q[2])) : [];
    m.toPlanes.forEach(function (d, i) { rows.push(["to plane " + (i + 1), fmt(d)]); });
    for (const [k, v] of rows) { el("span", {}, out, k); el("span", {}, out, v); }
  }
  m.refresh = show;
  ui.onPick = function (p) {
    if (!m.active) return false;
    if (!p.hit) { note.textContent = "nothing there: click on the model"; return true; }
    if (m.points.length >= 2) m.points = [];
    m.points.push(p.position.slice());
    m.distance = m.points.length === 2 ? Math.hypot(...[0, 1, 2].map((i) => m.points[1][i] - m.points[0][i])) : null;
    note.textContent = m.points.length === 2 ? "a third click starts again" : "and the second point";
    show();
    return true;
  };
  window.addEventListener("keydown", function (e) {
    if (e.target && /^(INPUT|SELECT|TEXTAREA)$/.test(e.target.tagName)) return;
    if (e.key === "m" || e.key === "M") setActive(!m.active);
    else if (e.key === "Escape") clear();
  });
  // the overlay follows the view every display frame
  function place(node, q, show) { node.style.display = show && q ? "" : "none"; return q; }
  function frame() {
    const q = m.points.map((p) => sy.project(p));
    q.forEach(function (s, i) { if (place(dots[i], s, true)) { dots[i].setAttribute("cx", s[0]); dots[i].setAttribute("cy", s[1]); } });
    for (let i = q.length; i < 2; i++) dots[i].style.display = "none";
    const both = q.length === 2 && q[0] && q[1];
    line.style.display = label.style.display = both ? "" : "none";
    if (both) {
      line.setAttribute("x1", q[0][0]); line.setAttribute("y1", q[0][1]); line.setAttribute("x2", q[1][0]); line.setAttribute("y2", q[1][1]);
      label.setAttribute("x", (q[0][0] + q[1][0]) / 2 + 8); label.setAttribute("y", (q[0][1] + q[1][1]) / 2 - 8);
      label.textContent = fmt(m.distance);
    }
    requestAnimationFrame(frame);
  }
  requestAnimationFrame(frame);
})();
