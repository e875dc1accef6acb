// ui.js — the page's controls around the canvas (docs/WEB.md, "The page"): the tool bar, the side
// panel and its menu (back-end, display filter, exposure, environment), the help overlay (? key and button), the
// screenshot button (the still route at the canvas' size, downloaded) and the stats panel
// (window.sy.stats()). A read-only server (sy web --read-only) hides what it would refuse.
// views.js, tree.js, measure.js, section.js and touch.js add their parts to the panel through window.sy.ui.
"use strict";
(function () {
  const sy = window.sy, canvas = document.getElementById("sy-canvas");
  const css = `
  #sy-bar { position: fixed; right: 8px; top: 32px; display: flex; gap: 4px; z-index: 3; }
  #sy-bar button, #sy-panel button { background: rgba(30,30,30,.85); color: #ddd; border: 1px solid #555; border-radius: 3px;
    font: 13px sans-serif; padding: 3px 8px; cursor: pointer; }
  #sy-bar button.on, #sy-panel button.on { background: #2a5d8f; border-color: #4a8ad0; color: #fff; }
  #sy-panel { position: fixed; right: 8px; top: 62px; bottom: 8px; width: 290px; overflow-y: auto; z-index: 2;
    background: rgba(18,18,18,.88); border: 1px solid #444; border-radius: 4px; padding: 4px 8px; box-sizing: border-box; }
  #sy-panel.hidden, .sy-hidden { display: none !important; }
  #sy-panel h3 { font-size: 12px; text-transform: uppercase; letter-spacing: .05em; color: #9ab; margin: 10px 0 4px; }
  #sy-panel label { display: flex; align-items: center; gap: 6px; margin: 3px 0; }
  #sy-panel select, #sy-panel input[type=range] { flex: 1; min-width: 0; }
  #sy-panel select { background: #222; color: #ddd; border: 1px solid #555; }
  #sy-panel .kv { display: grid; grid-template-columns: 82px 1fr; gap: 1px 6px; font: 12px monospace; word-break: break-all; }
  #sy-panel .kv span:nth-child(odd) { color: #9ab; }
  #sy-panel .note { color: #999; font-size: 12px; }
  #sy-help { position: fixed; inset: 0; z-index: 5; display: flex; align-items: center; justify-content: center;
    background: rgba(0,0,0,.6); }
  #sy-help > div { background: #1c1c1c; border: 1px solid #555; border-radius: 6px; padding: 12px 20px; max-width: 640px;
    max-height: 90vh; overflow-y: auto; }
  #sy-help table { border-collapse: collapse; font-size: 13px; }
  #sy-help td { padding: 2px 10px 2px 0; vertical-align: top; }
  #sy-help td:first-child { color: #fc6; white-space: nowrap; }
  #sy-help h2 { font-size: 16px; margin: 4px 0 8px; } #sy-help h4 { margin: 10px 0 4px; color: #9ab; }
  #sy-readonly { position: fixed; left: 8px; bottom: 8px; padding: 2px 6px; background: rgba(120,40,40,.85); border-radius: 3px; }
  `;
  const style = document.createElement("style");
  style.textContent = css;
  document.head.appendChild(style);
  function el(tag, attrs, parent, text) {
    const e = document.createElement(tag);
    for (const k in attrs || {}) e.setAttribute(k, attrs[k]);
    if (text !== undefined) e.textContent = text;
    if (parent) parent.appendChild(e);
    return e;
  }

  // ---- the tool bar and the panel ----
  const bar = el("div", { id: "sy-bar" }, document.body);
  const panel = el("div", { id: "sy-panel" }, document.body);
  const params = new URLSearchParams(location.search);
  if (params.get("panel") === "0" || window.innerWidth < 600) panel.classList.add("hidden");
  function button(label, title, onclick, parent) {
    const b = el("button", { title: title, type: "button" }, parent || bar, label);
    b.addEventListener("click", function (e) { e.stopPropagation(); onclick(b); });
    return b;
  }
  const ui = sy.ui = { el: el, button: button, panel: panel, bar: bar, readOnly: false, hello: null,
                       section: function (title, id) { const s = el("div", { id: id }, panel); el("h3", {}, s, title); return s; },
                       writers: [], // elements a read-only server hides: add them with ui.writer
                       writer: function () { // (a script may run after the hello: the state applies at once)
                         for (const w of arguments) { ui.writers.push(w); w.classList.toggle("sy-hidden", ui.readOnly); }
                       } };
  button("☰", "the panel: menu, scene tree, properties, measurement, section planes, stats", function () {
    panel.classList.toggle("hidden");
  }).id = "sy-panel-button";

  // ---- the menu: what the server lets a page choose ----
  const menu = ui.section("View", "sy-menu");
  const bSel = el("select", { id: "sy-backend" }, el("label", {}, menu, "Back-end "));
  const fLab = el("label", {}, menu, "Display filter "), fSel = el("select", { id: "sy-filter" }, fLab);
  const eLab = el("label", {}, menu, "Exposure ");
  const eRange = el("input", { id: "sy-exposure", type: "range", min: "-6", max: "6", step: "0.25", value: "0" }, eLab);
  const eVal = el("span", {}, eLab, "0");
  // the environments the server offers (hello.environments: the scene's world, the studio, none)
  const envLab = el("label", {}, menu, "Environment "), envSel = el("select", { id: "sy-environment" }, envLab);
  ui.writer(bSel.parentNode, fLab, eLab, envLab);
  envSel.addEventListener("change", function () { sy.send({ t: "environment", name: envSel.value }); envSel.blur(); });
  bSel.addEventListener("change", function () { sy.input({ t: "key", k: String(bSel.selectedIndex + 1) }); bSel.blur(); });
  fSel.addEventListener("change", function () { sy.send({ t: "filter", name: fSel.value }); fSel.blur(); });
  let eTimer = 0;
  eRange.addEventListener("input", function () {
    eVal.textContent = eRange.value;
    clearTimeout(eTimer);
    eTimer = setTimeout(function () { sy.send({ t: "exposure", stops: Number(eRange.value) }); }, 60);
  });

  // ---- the screenshot: the still route at the canvas' size (a right token goes along) ----
  function screenshot() {
    const w = Math.min(canvas.width, 3840), h = Math.min(canvas.height, 2400), token = params.get("token");
    const url = "/api/frame.jpg?w=" + w + "&h=" + h + (token ? "&token=" + encodeURIComponent(token) : "");
    ui.shot = { state: "pending", w: w, h: h };
    return fetch(url, { cache: "no-store" }).then(function (r) {
      if (!r.ok) return r.text().then(function (t) { throw new Error(r.status + " " + t.trim()); });
      return r.blob();
    }).then(function (b) {
      const a = el("a", { download: "sy-" + new Date().toISOString().replace(/[:.]/g, "-") + ".jpg" }, document.body);
      a.href = URL.createObjectURL(b);
      a.click();
      setTimeout(function () { URL.revokeObjectURL(a.href); a.remove(); }, 1000);
      ui.shot = { state: "done", w: w, h: h, bytes: b.size, type: b.type };
    }).catch(function (e) { ui.shot = { state: "failed", error: String(e.message || e) }; console.warn("screenshot:", e); });
  }
  ui.screenshot = screenshot;
  button("Screenshot", "the server renders the view at the canvas' size (JPEG, downloaded)", screenshot).id = "sy-shot";

  // ---- help: the keys and gestures ----
  const help = el("div", { id: "sy-help", class: "sy-hidden" }, document.body);
  const hb = el("div", {}, help);
  el("h2", {}, hb, "sy web: keys and gestures");
  const rows = [
    ["Mouse", ""], ["left drag", "orbit around the target"], ["right drag, shift + drag", "pan"],
    ["wheel", "zoom (one notch: distance x 0.9)"], ["click", "pick: what is under the pointer, selected (its row in the tree, its properties)"],
    ["Touch", ""], ["one finger", "orbit"], ["two fingers", "pan (move together) and zoom (pinch)"], ["tap", "pick"],
    ["Keys", ""], ["1 - 9", "the back-end at that position of the menu"], ["F", "next display filter"],
    ["[ and ]", "halve / double the filter's threshold"], ["R", "back to the first view"],
    ["Shift + 1 - 9", "recall saved view N (the panel's Saved views; every page shares them)"],
    ["Ctrl + Shift + 1 - 9", "save the view now as N (the server keeps them in the scene's .bookmarks file, as sy view)"],
    ["M", "measure: click two points, their distance in scene units"], ["Esc", "leave measuring (the points go); close this help"],
    ["?", "this help"], ["space", "play / pause the scene (when it moves: the timeline at the bottom scrubs it)"],
    ["Panel", ""], ["☰", "show / hide the panel"], ["Screenshot", "downloads a JPEG of the view at the canvas' size"],
    ["Measure", "click two points: their distance"], ["Saved views", "a number recalls that view, Save as keeps the view now"], ["tree", "the check box shows / hides a node, a click on its name selects it"],
    ["section planes", "up to 6 cuts along X, Y or Z, each with a slider across the scene and a flip; Cap fills the cut faces in a colour"],
    ["environment", "the menu's light from outside the scene: the scene's own, a studio, none"]];
  const tb = el("table", {}, hb);
  for (const [k, v] of rows) {
    if (!v) { el("h4", {}, el("td", { colspan: "2" }, el("tr", {}, tb)), k); continue; }
    const tr = el("tr", {}, tb);
    el("td", {}, tr, k); el("td", {}, tr, v);
  }
  el("p", { class: "note" }, hb, "A read-only server (sy web --read-only) lets you move the camera and the scene clock, recall saved views, pick and take " +
     "screenshots; the saved views, visibility, selection, section planes, exposure, filter and back-end stay as they are.");
  function toggleHelp(on) { help.classList.toggle("sy-hidden", on === undefined ? undefined : !on); ui.helpOpen = !help.classList.contains("sy-hidden"); }
  ui.toggleHelp = toggleHelp;
  help.addEventListener("click", function () { toggleHelp(false); });
  button("?", "help: keys and gestures (? key)", function () { toggleHelp(); }).id = "sy-help-button";
  window.addEventListener("keydown", function (e) {
    if (e.target && /^(INPUT|SELECT|TEXTAREA)$/.test(e.target.tagName)) return;
    if (e.key === "?") toggleHelp();
    else if (e.key === "Escape") toggleHelp(false);
  });

  // ---- stats (window.sy.stats()): the panel's last section (made once every script added its own) ----
  let kv = null;
  window.addEventListener("load", function () { kv = el("div", { class: "kv" }, ui.section("Stats", "sy-stats")); });
  function pct(a, q) { if (!a.length) return "-"; const s = a.slice().sort((x, y) => x - y); return s[Math.min(s.length - 1, Math.floor(q * s.length))].toFixed(0); }
  function updateStats() {
    if (!kv || panel.classList.contains("hidden")) return;
    const s = sy.stats(), o = window.syStats;
    const lines = [["back-end", o.backend || "-"], ["frame", o.width + " x " + o.height + (o.samples > 1 ? ", " + o.samples + " spp" : "")],
                   ["render", o.renderMs.toFixed(1) + " ms"], ["server fps", s.server_fps.toFixed(1)],
                   ["frame size", (s.bytes_per_frame / 1024).toFixed(0) + " KiB"], ["frames", String(s.frames)],
                   ["input→disp", "p50 " + pct(s.input_to_display_ms, 0.5) + " / p95 " + pct(s.input_to_display_ms, 0.95) + " ms"],
                   ["display", "p50 " + pct(s.frame_ms, 0.5) + " ms"], ["warp", s.warp ? "on, stride " + s.stride + ", scale " + s.warp_scale : "off"],
                   ["estimate", s.estimate_share ? "yes" : "no"],
                   ["bad frames", Object.entries(s.bad).filter((e) => e[1]).map((e) => e[0] + " " + e[1]).join(", ") || "none"]];
    kv.textContent = "";
    for (const [k, v] of lines) { el("span", {}, kv, k); el("span", {}, kv, v); }
  }
  setInterval(updateStats, 500);

  // ---- what the server says ----
  sy.on(function (m) {
    if (m.t === "hello") {
      ui.hello = m;
      ui.readOnly = !!m.read_only;
      bSel.textContent = "";
      (m.backends || []).slice(0, 9).forEach(function (b, i) { el("option", { value: b }, bSel, (i + 1) + "  " + b); });
      fSel.textContent = "";
      (m.filters || []).forEach(function (f) { el("option", { value: f }, fSel, f); });
      eRange.value = String(m.exposure || 0); eVal.textContent = eRange.value;
      envSel.textContent = "";
      const envTitles = { scene: "the scene's", studio: "studio light", none: "none" };
      (m.environments || ["scene"]).forEach(function (e) { el("option", { value: e }, envSel, envTitles[e] || e); });
      envSel.value = m.environment || "scene";
      for (const w of ui.writers) w.classList.toggle("sy-hidden", ui.readOnly);
      document.getElementById("sy-readonly") && document.getElementById("sy-readonly").remove();
      if (ui.readOnly) el("div", { id: "sy-readonly", title: "sy web --read-only" }, document.body, "read-only: look, pick, screenshot");
    } else if (m.t === "tree" && m.environment && document.activeElement !== envSel) { // another page may have switched it
      envSel.value = m.environment;
    } else if (m.t === "status") {
      if (m.filter && fSel.value !== m.filter) fSel.value = m.filter;
    }
  });
  // the back-end shown follows the frames (keys 1-9 from any page)
  setInterval(function () {
    const b = window.syStats.backend;
    if (b && document.activeElement !== bSel && bSel.value !== b) bSel.value = b;
  }, 300);
})();
