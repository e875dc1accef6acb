// tree.js — the scene tree and picking (docs/WEB.md, "The page"): the server's hierarchy ("tree"
// messages, a page at a time: {t: "tree", node, offset} answers at most 512 children of node, or of
// the roots, each opened below while the answer stays within 4096 nodes; a closed node is expanded
// by its ▸, which asks for its children, and "more" rows ask for the next page; asked again
// whenever a page changed visibility or selection, the expanded nodes asked for again) with a
// visibility check box per node and a click on a name to select it; a click (or tap) on the
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
                            lastPick: null, seq: 0, picks: 0, pending: 0 }; // pending: node pages asked for, not answered
  // requests: seq -> {base: the base request they belong to, at: the row the answer goes after (a
  // node's row, or a "more" row it replaces)}; the base request (no node, offset 0) lists the tree anew
  let treeSeq = 0, baseSeq = 0, pickSeq = 0;
  const asked = new Map();
  const expanded = new Set(), collapsed = new Set(); // the user's choices, kept across answers
  function askTree() { baseSeq = ++treeSeq; asked.clear(); state.pending = 0; sy.send({ t: "tree", seq: baseSeq }); }
  function askBelow(row, node, offset) {
    const seq = ++treeSeq;
    asked.set(seq, { base: baseSeq, at: row });
    sy.send({ t: "tree", seq: seq, node: node, offset: offset });
    state.pending = asked.size;
  }
  state.refresh = askTree;
  state.expanded = expanded;
  // the rows of an answer: nodes at depth + base, then a "more" row when the level goes on
  function rows(m, base, parent) {
    const out = (m.nodes || []).map((n) => Object.assign({}, n, { depth: base + (n.depth || 0) }));
    const next = (m.offset || 0) + (m.nodes || []).filter((n) => !n.depth).length; // the level's nodes listed
    if (next < m.count) out.push({ more: true, parent: parent, offset: next, left: m.count - next, depth: base });
    return out;
  }
  // the end of row i's subtree (the first row after it that is not deeper)
  function subtreeEnd(i) {
    let j = i + 1;
    while (j < state.nodes.length && state.nodes[j].depth > state.nodes[i].depth) j++;
    return j;
  }
  function toggle(n) {
    const i = state.nodes.indexOf(n);
    if (i < 0) return;
    if (n.open) { // collapse: its rows go
      state.nodes.splice(i + 1, subtreeEnd(i) - i - 1);
      n.open = false; expanded.delete(n.id); collapsed.add(n.id);
      render();
    } else {
      expanded.add(n.id); collapsed.delete(n.id);
      n.open = true; n.loading = true;
      render();
      askBelow(n, n.id, 0);
    }
  }
  // the user's choices on freshly listed rows: collapsed ones closed, expanded closed ones asked for
  function restore(from, to) {
    for (let i = from; i < to && i < state.nodes.length; i++) {
      const n = state.nodes[i];
      if (n.more) continue;
      if (n.open && collapsed.has(n.id)) {
        const e = subtreeEnd(i);
        state.nodes.splice(i + 1, e - i - 1); to -= e - i - 1;
        n.open = false;
      } else if (!n.open && n.children > 0 && expanded.has(n.id)) {
        n.open = true; n.loading = true;
        askBelow(n, n.id, 0);
      }
    }
  }
  const fmt = (v) => v.map((x) => Math.abs(x) >= 1e4 || (Math.abs(x) < 1e-3 && x) ? x.toExponential(3) : x.toFixed(4)).join(", ");
  function render() {
    list.textContent = "";
    const ro = ui.readOnly;
    for (const n of state.nodes) {
      if (n.more) {
        const more = el("div", { class: "sy-tree-more", style: "cursor: pointer; color: #8cf; padding-left: " + (n.depth * 12 + 14) + "px;" }, list,
                        "… " + n.left + " more" + (n.loading ? " (asking)" : ""));
        more.addEventListener("click", function () {
          if (n.loading) return;
          n.loading = true; render();
          askBelow(n, n.parent, n.offset);
        });
        continue;
      }
      const row = el("div", { "data-node": String(n.id), style: "display: flex; align-items: center; gap: 4px; white-space: nowrap; padding-left: " +
                               (n.depth * 12) + "px;" + (n.selected ? " background: #2a5d8f;" : "") }, list);
      const ex = el("span", { class: "sy-tree-expand", style: "width: 10px; cursor: pointer; color: #aaa;" }, row,
                    n.children > 0 ? (n.open ? "▾" : "▸") : "");
      if (n.children > 0) {
        ex.title = n.children + " child" + (n.children === 1 ? "" : "ren");
        ex.addEventListener("click", function () { toggle(n); });
      }
      const cb = el("input", { type: "checkbox", title: "visible" }, row);
      cb.checked = n.visible; cb.disabled = ro;
      cb.addEventListener("change", function () { sy.send({ t: "visible", node: n.id, on: cb.checked }); });
      const icon = { mesh: "▣", light: "☀", camera: "◉", group: "◇" }[n.kind] || "·"; // ▸ / ▾: the expander
      const name = el("span", { style: "cursor: pointer;" + (n.visible ? "" : " color: #777;") }, row,
                      icon + " " + (n.name || "(node " + n.id + ")"));
      name.title = "node " + n.id + " (" + n.kind + ")";
      name.addEventListener("click", function () {
        if (ro) return;
        sy.send({ t: "select", node: 0, on: false });
        sy.send({ t: "select", node: n.id, on: true });
      });
    }
    const shown = state.nodes.filter((n) => !n.more).length;
    const more = state.nodes.some((n) => n.more || (n.children > 0 && !n.open));
    info.textContent = state.total + " node" + (state.total === 1 ? "" : "s") +
                       (shown < state.total ? ", " + shown + " listed" + (more ? " (▸ expands)" : "") : "");
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
      if (m.seq !== baseSeq) { // a node's children or a further page
        const q = asked.get(m.seq);
        asked.delete(m.seq); state.pending = asked.size;
        if (!q || q.base !== baseSeq) return; // asked before the tree was listed anew
        let i = state.nodes.indexOf(q.at);
        if (i < 0) return; // collapsed meanwhile
        let at, base;
        if (q.at.more) { base = q.at.depth; at = i; state.nodes.splice(i, 1); } // the "more" row goes
        else { q.at.loading = false; base = q.at.depth + 1; at = subtreeEnd(i); }
        const add = rows(m, base, q.at.more ? q.at.parent : q.at.id);
        state.nodes.splice(at, 0, ...add);
        state.total = m.total;
        restore(at, at + add.length);
        state.version = (state.version || 0) + 1;
        render();
        return;
      }
      state.nodes = rows(m, 0, 0); state.total = m.total; state.truncated = m.truncated;
      restore(0, state.nodes.length);
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
