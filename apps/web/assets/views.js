// views.js — saved views (docs/WEB.md, "Saved views"): up to 9 numbered views every page of the
// server shares (bookmarks, as sy view's Ctrl+1..9 / Shift+1..9; the server keeps them in the
// scene's .bookmarks file, so sy view, sy render --bookmark FILE:N and the page use the same).
// The panel's "Saved views": a button per slot recalls it (Shift+1..9), "Save as" puts the view
// now in a slot (Ctrl+Shift+1..9: Ctrl+1..9 is the browser's own tab key). The page sends
// {"t":"view","n":N} (a recall: an input, answered by the frames) and {"t":"view","n":N,"save":true};
// the server answers every page with the list ("views"). A read-only server recalls, never saves.
"use strict";
(function () {
  const sy = window.sy, ui = sy.ui, el = ui.el;
  const sec = ui.section("Saved views", "sy-views");
  const row = el("div", { style: "display: flex; gap: 3px; flex-wrap: wrap;" }, sec);
  const slots = [];
  for (let n = 1; n <= 9; n++) {
    const b = ui.button(String(n), "", function () { recall(n); }, row);
    b.id = "sy-view-" + n;
    b.disabled = true;
    slots[n] = b;
  }
  const saveRow = el("label", { title: "put the view now in a slot (every page sees the list)" }, sec, "Save as ");
  const saveSel = el("select", { id: "sy-view-slot" }, saveRow);
  for (let n = 1; n <= 9; n++) el("option", { value: String(n) }, saveSel, String(n));
  ui.button("Save", "save the view now in the chosen slot (Ctrl+Shift+N)", function () { save(Number(saveSel.value)); }, saveRow).id = "sy-view-save";
  ui.writer(saveRow);
  const note = el("div", { class: "note", id: "sy-views-note" }, sec, "no saved views yet");
  // what the server said last: {views: [{n, eye, target, fov}], kept, note}; for tests and scripts
  ui.views = { list: [], kept: false, note: "", received: 0 };
  function fmt(v) { return "(" + v.map((x) => Number(x.toPrecision(4))).join(", ") + ")"; }
  function recall(n) {
    const v = ui.views.list.find((x) => x.n === n);
    if (!v) { note.textContent = "no view saved in " + n + (ui.readOnly ? "" : " (Save as " + n + " saves one)"); return; }
    sy.input({ t: "view", n: n });
  }
  function save(n) { if (!ui.readOnly) sy.send({ t: "view", n: n, save: true }); }
  ui.recallView = recall;
  ui.saveView = save;
  window.addEventListener("keydown", function (e) {
    if (e.target && /^(INPUT|SELECT|TEXTAREA)$/.test(e.target.tagName)) return;
    const m = /^Digit([1-9])$/.exec(e.code || "");
    if (!m || !e.shiftKey || e.altKey || e.metaKey) return;
    e.preventDefault();
    if (e.ctrlKey) save(Number(m[1])); else recall(Number(m[1]));
  });
  sy.on(function (m) {
    if (m.t !== "views") return;
    ui.views = { list: Array.isArray(m.views) ? m.views : [], kept: !!m.kept, note: m.note || "", received: ui.views.received + 1 };
    for (let n = 1; n <= 9; n++) {
      const v = ui.views.list.find((x) => x.n === n), b = slots[n];
      b.disabled = !v;
      b.classList.toggle("on", !!v);
      b.title = v ? "view " + n + " (Shift+" + n + "): from " + fmt(v.eye) + " at " + fmt(v.target) +
                    (v.fov ? ", " + v.fov.toFixed(1) + "° field of view" : "") : "no view saved in " + n;
    }
    note.textContent = (ui.views.list.length ? ui.views.list.length + " saved" : "no saved views yet") +
                       (ui.views.kept ? ", kept in the server's views file (.bookmarks)" : ", kept by the server while it runs") +
                       (ui.views.note ? " (" + ui.views.note + ")" : "");
  });
})();
