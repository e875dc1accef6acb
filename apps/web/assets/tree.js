// tree.js — the scene tree and picking (docs/WEB.md, "The page"): the server's hierarchy ("tree"
// messages, at most 4096 nodes; asked again whenever a page changed visibility or selection) with
// a visibility check box per node and a click on a name to select it; a click (or tap) on the
// canvas picks what is under it (the server's sy_viewport_pick) and selects it (the server
// highlights the selection); the picked object's properties (node, mesh, material, primitive,
// triangle, world position and normal, distance). measure.js takes the clicks while measuring.
"use strict";
(function () {
  const sy = window.sy, ui = sy.ui, el = ui.el, canvas = document.getElementById("sy-canvas");
  const treeSec = ui.section("Scene", "sy-tree-section");
  const bar = el("div", {}, treeSec);
  const info = el("div", { class: "note" }, treeSec, "asking the server...");
  const list = el("div", { id: "sy-tree", style: "max-height: 34vh; overflow-y: auto; font-size: 12px; margin-top: 3px;" }, treeSec);
  const showAll = ui.button("show all", "show every node", function () { sy.send({ t: "isolate", node: 0 }); }, bar);
  const isolate = ui.button("isolate", "show only the selected node (with its ancestors and children)", function () {
    if (state.selected) sy.send({ t: "isolate", node: state.selected });
  }, bar);
  const clear = ui.button("deselect", "clear the selection", function () { sy.send({ t: "select", node: 0, on: false }); }, bar);
  ui.writer(showAll, isolate, clear);
  const propSec = ui.section("Picked", "sy-props");
  const props = el("div", { class: "kv" }, propSec);
  el("div", { class: "note" }, propSec, "click an object to pick it");
  const state = ui.tree = { nodes: [], total: 0, truncated: false, min: null, max: null, planes: [], selected: 0,
                            lastPick: null, seq: 0, picks: 0 };
  let treeSeq = 0, pickSeq = 0;
  function askTree() { sy.send({ t: "tree", seq: ++treeSeq }); }
  state.refresh = askTree;
  const fmt = (v) => v.map((x) => Math.abs(x) >= 1e4 || (Math.abs(x) < 1e-3 && x) ? x.toExponential(3) : x.toFixed(4)).join(", ");
  function render() {
    list.textContent = "";
    const ro = ui.readOnly;
    for (const n of state.nodes) {
      const row = el("div", { "data-node": String(n.id), style: "display: flex; align-items: center; gap: 4px; white-space: nowrap; padding-left: " +
                               (n.depth * 12) + "px;" + (n.selected ? " background: #2a5d8f;" : "") }, list);
      const cb = el("input", { type: "checkbox", title: "visible" }, row);
      cb.checked = n.visible; cb.disabled = ro;
      cb.addEventListener("change", function () { sy.send({ t: "visible", node: n.id, on: cb.checked }); });
      const icon = { mesh: "▣", light: "☀", camera: "◉", group: "▸" }[n.kind] || "·";
      const name = el("span", { style: "cursor: pointer;" + (n.visible ? "" : " color: #777;") }, row,
                      icon + " " + (n.name || "(node " + n.id + ")"));
      name.title = "node " + n.id + " (" + n.kind + ")";
      name.addEventListener("click", function () {
        if (ro) return;
        sy.send({ t: "select", node: 0, on: false });
        sy.send({ t: "select", node: n.id, on: true });
      });
    }
    info.textContent = state.total + " node" + (state.total === 1 ? "" : "s") +
                       (state.truncated ? ", the first " + state.nodes.length + " listed" : "");
  }
  function showPick(m) {
    props.textContent = "";
    const rows = m.hit ? [["node", (m.name || "(unnamed)") + " #" + m.node], ["mesh", (m.mesh_name || "(unnamed)") + " #" + m.mesh],
                          ["material", (m.material_name || "(unnamed)") + " #" + m.material],
                          ["primitive", m.primitive + ", triangle " + m.triangle], ["position", fmt(m.position)],
                          ["normal", fmt(m.normal)], ["distance", fmt([m.distance])], ["by", m.backend]]
                       : [["nothing", "no surface under the pointer"]];
    for (const [k, v] of rows) { el("span", {}, props, k); el("span", {}, props, v); }
  }
  sy.on(function (m) {
    if (m.t === "hello" || m.t === "scene") askTree();
    else if (m.t === "tree") {
      if (m.seq !== treeSeq) return; // an older answer
      state.nodes = m.nodes || []; state.total = m.total; state.truncated = m.truncated;
      state.min = m.min; state.max = m.max; state.planes = m.planes || [];
      state.cap = m.cap || null; state.environment = m.environment || "scene"; // the server's caps and environment
      const sel = state.nodes.find((n) => n.selected);
      state.selected = sel ? sel.id : 0;
      state.version = (state.version || 0) + 1;
      render();
      if (ui.onTree) ui.onTree(state);
    } else if (m.t === "pick") {
      state.picks++;
      if (ui.onPick && ui.onPick(m)) return; // measure.js took it
      state.lastPick = m;
      showPick(m);
    } else if (m.t === "refused") {
      info.textContent = "refused: " + m.what + ": " + m.reason;
    }
  });
  // a click (or a tap): down and up within 5 pixels and 600 ms, the primary button
  let down = null;
  canvas.addEventListener("pointerdown", function (e) {
    down = e.isPrimary && e.button === 0 && !e.shiftKey ? { x: e.clientX, y: e.clientY, t: e.timeStamp, touches: 1 } : null;
  });
  canvas.addEventListener("pointerup", function (e) {
    if (!down || !e.isPrimary || Math.hypot(e.clientX - down.x, e.clientY - down.y) > 5 || e.timeStamp - down.t > 600) return;
    down = null;
    const r = canvas.getBoundingClientRect();
    const x = (e.clientX - r.left) / r.width, y = (e.clientY - r.top) / r.height;
    if (!(x >= 0 && x < 1 && y >= 0 && y < 1)) return;
    state.pickAt(x, y);
  });
  // x, y: fractions of the canvas; a measuring click does not select
  state.pickAt = function (x, y) {
    const measuring = !!(ui.measure && ui.measure.active);
    sy.send({ t: "pick", x: x, y: y, select: !measuring && !ui.readOnly, seq: ++pickSeq });
  };
})();
