// section.js — section planes (docs/WEB.md, "The page"): up to 6 axis-aligned cuts, each an axis
// (X, Y or Z), a slider across the scene's bounds (the tree message's min / max) and a flip of the
// kept side; sent as one "clip" message (the server sets them on its viewports: every back-end
// with SY_CAP_CLIP cuts, picks and shadows alike). "Cap" fills the cut faces of closed meshes in
// the chosen colour (sent as the message's "cap": linear RGB, or false). A read-only server hides them.
"use strict";
(function () {
  const sy = window.sy, ui = sy.ui, el = ui.el;
  const sec = ui.section("Section planes", "sy-section");
  ui.writer(sec);
  const rows = el("div", {}, sec);
  const add = ui.button("+ plane", "add a section plane (at most 6)", function () { addPlane("x", 0.5, false); }, sec);
  add.id = "sy-plane-add";
  const planes = ui.planes = []; // {axis, t (0..1 across the bounds), flip, on}
  let timer = 0;
  // the caps: a switch and a colour (sRGB in the picker, linear on the wire)
  const capRow = el("label", { title: "fill the cut faces of closed meshes" }, sec, "Cap ");
  const capOn = el("input", { type: "checkbox", id: "sy-cap" }, capRow);
  const capColor = el("input", { type: "color", id: "sy-cap-color", value: "#d04020" }, capRow);
  capOn.addEventListener("change", function () { send(); });
  capColor.addEventListener("input", function () { if (capOn.checked) send(); });
  function linear(c) { c /= 255; return c <= 0.04045 ? c / 12.92 : Math.pow((c + 0.055) / 1.055, 2.4); }
  function cap() {
    if (!capOn.checked) return false;
    const h = capColor.value, v = [1, 3, 5].map((i) => linear(parseInt(h.substr(i, 2), 16)));
    return v.every(isFinite) ? v.map((x) => Math.round(x * 1e4) / 1e4) : false;
  }
  // tests and scripts: capping on in colour hex ("#rrggbb"), or off (null)
  ui.setCap = function (hex) { capOn.checked = !!hex; if (hex) capColor.value = hex; send(); };
  function bounds(i) {
    const t = ui.tree || {};
    const lo = t.min && isFinite(t.min[i]) ? t.min[i] : -1, hi = t.max && isFinite(t.max[i]) ? t.max[i] : 1;
    return hi >= lo ? [lo, hi] : [-1, 1];
  }
  // the plane {a, b, c, d}: keeps axis >= s (flipped: <= s)
  function plane(p) {
    const i = "xyz".indexOf(p.axis), [lo, hi] = bounds(i), pad = (hi - lo) * 0.01 + 1e-6;
    const s = lo - pad + (hi - lo + 2 * pad) * p.t, n = [0, 0, 0];
    n[i] = p.flip ? -1 : 1;
    return [n[0], n[1], n[2], p.flip ? s : -s];
  }
  function send() {
    clearTimeout(timer);
    timer = setTimeout(function () { sy.send({ t: "clip", planes: planes.filter((p) => p.on).map(plane), cap: cap() }); }, 50);
    if (ui.measure && ui.measure.refresh) ui.measure.refresh(); // its point-to-plane distances
  }
  ui.sendPlanes = send;
  ui.activePlanes = function () { return planes.filter((p) => p.on).map(plane); }; // measure.js: point-to-plane
  function addPlane(axis, t, flip) {
    if (planes.length >= 6) return null;
    const p = { axis: axis, t: t, flip: flip, on: true };
    planes.push(p);
    const row = el("label", {}, rows);
    const on = el("input", { type: "checkbox", title: "on" }, row);
    on.checked = true;
    const ax = el("select", { title: "axis" }, row);
    for (const a of "xyz") el("option", { value: a }, ax, a.toUpperCase());
    ax.value = axis;
    const r = el("input", { type: "range", min: "0", max: "1", step: "0.001", value: String(t), title: "position across the scene" }, row);
    const flipB = ui.button("⇆", "flip the kept side", function () { p.flip = !p.flip; flipB.classList.toggle("on", p.flip); send(); }, row);
    const del = ui.button("✕", "remove", function () { planes.splice(planes.indexOf(p), 1); row.remove(); add.disabled = false; send(); }, row);
    del.style.padding = flipB.style.padding = "1px 5px";
    on.addEventListener("change", function () { p.on = on.checked; send(); });
    ax.addEventListener("change", function () { p.axis = ax.value; ax.blur(); send(); });
    r.addEventListener("input", function () { p.t = Number(r.value); send(); });
    p.row = row; p.range = r;
    add.disabled = planes.length >= 6;
    send();
    return p;
  }
  ui.addPlane = addPlane;
})();
