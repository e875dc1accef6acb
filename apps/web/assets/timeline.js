// timeline.js — the scene clock's timeline (docs/WEB.md, "The timeline"): shown when the server's
// scene has animations (it sends "clock" messages: time, range, playing), a play / pause button, a
// scrub slider over the clip's range, the time and duration, and (a scene with several clips: the
// hello's "clips") a menu of the clips; space plays and pauses. The page sends
// {"t":"time","s":SECONDS}, {"t":"play","on":BOOL} and {"t":"anim","clip":N} (-1: every clip
// together; the server starts on its default clip, e.g. the Fox's first); the server advances the clock, sets
// the scene's time and streams the frames, so every page shows the same moment. Between the
// server's messages (one a second while playing) the shown time runs on locally. A read-only page
// may move the clock too: it is a view change, like the camera's.
"use strict";
(function () {
  const sy = window.sy, ui = sy.ui, el = ui.el;
  const css = `
  #sy-timeline { position: fixed; left: 8px; right: 306px; bottom: 8px; z-index: 2; display: none; align-items: center; gap: 8px;
    background: rgba(18,18,18,.88); border: 1px solid #444; border-radius: 4px; padding: 4px 8px; box-sizing: border-box; }
  #sy-timeline.shown { display: flex; }
  #sy-timeline.wide { right: 8px; }
  #sy-timeline.ro { bottom: 34px; }
  #sy-timeline button { background: rgba(30,30,30,.85); color: #ddd; border: 1px solid #555; border-radius: 3px;
    font: 13px sans-serif; padding: 2px 8px; cursor: pointer; min-width: 34px; }
  #sy-timeline input[type=range] { flex: 1; min-width: 60px; }
  #sy-timeline span { font: 12px monospace; white-space: nowrap; color: #ccc; }
  #sy-timeline select { background: rgba(30,30,30,.85); color: #ddd; border: 1px solid #555; border-radius: 3px; font: 12px sans-serif; max-width: 160px; }
  #sy-timeline select.hidden { display: none; }
  `;
  el("style", {}, document.head, css);
  const bar = el("div", { id: "sy-timeline" }, document.body);
  const play = el("button", { id: "sy-play", type: "button", title: "play / pause the scene (space)" }, bar, "▶");
  const range = el("input", { id: "sy-scrub", type: "range", min: "0", max: "1", step: "0.001", value: "0", title: "scene time" }, bar);
  const label = el("span", { id: "sy-time" }, bar, "");
  const menu = el("select", { id: "sy-clip", class: "hidden", title: "the clip the scene plays" }, bar);
  // the clock as the server last said, and when (performance.now) the page heard it
  const clock = { time: 0, start: 0, end: 0, playing: false, loop: true, speed: 1, at: 0, known: false };
  let scrubbing = false, sendTimer = 0, pendingTime = null;
  function now() { // the clock's time now: the server's, run on locally while it plays
    if (!clock.playing) return clock.time;
    let t = clock.time + (performance.now() - clock.at) / 1000 * clock.speed;
    const len = clock.end - clock.start;
    if (t > clock.end || t < clock.start) t = clock.loop && len > 0 ? clock.start + ((((t - clock.start) % len) + len) % len) : Math.min(Math.max(t, clock.start), clock.end);
    return t;
  }
  function fmt(t) { return t.toFixed(2) + " s"; }
  function show() {
    const t = now();
    if (!scrubbing) range.value = String(t);
    label.textContent = fmt(t) + " / " + fmt(clock.end - clock.start);
    play.textContent = clock.playing ? "❚❚" : "▶";
    play.classList.toggle("on", clock.playing);
    bar.classList.toggle("wide", ui.panel.classList.contains("hidden"));
  }
  function loop() { show(); if (clock.playing) requestAnimationFrame(loop); }
  function setPlaying(on) {
    clock.time = now(); clock.at = performance.now(); clock.playing = on;
    sy.send({ t: "play", on: on });
    show();
    if (on) requestAnimationFrame(loop);
  }
  function sendTime(t) { // coalesced: at most one message per animation frame while scrubbing
    pendingTime = t;
    if (sendTimer) return;
    sendTimer = requestAnimationFrame(function () {
      sendTimer = 0;
      if (pendingTime === null) return;
      sy.send({ t: "time", s: pendingTime });
      clock.time = pendingTime; clock.at = performance.now(); pendingTime = null;
      show();
    });
  }
  menu.addEventListener("change", function () { sy.send({ t: "anim", clip: Number(menu.value) }); menu.blur(); });
  play.addEventListener("click", function (e) { e.stopPropagation(); setPlaying(!clock.playing); play.blur(); });
  range.addEventListener("input", function () { scrubbing = true; sendTime(Number(range.value)); label.textContent = fmt(Number(range.value)) + " / " + fmt(clock.end - clock.start); });
  range.addEventListener("change", function () { scrubbing = false; sendTime(Number(range.value)); range.blur(); });
  window.addEventListener("keydown", function (e) {
    if (!clock.known || e.key !== " " || e.repeat) return;
    if (e.target && /^(INPUT|SELECT|TEXTAREA|BUTTON)$/.test(e.target.tagName) && e.target !== range) return; // typing in the panel
    e.preventDefault();
    setPlaying(!clock.playing);
  });
  sy.on(function (m) {
    if (m.t === "hello") {
      bar.classList.toggle("ro", !!m.read_only);
      const clips = Array.isArray(m.clips) ? m.clips : [];
      menu.textContent = "";
      if (clips.length > 1) el("option", { value: "-1" }, menu, "every clip");
      clips.forEach(function (n, i) { el("option", { value: String(i) }, menu, String(n)); });
      menu.classList.toggle("hidden", clips.length < 2);
    }
    if (m.t !== "clock") return;
    const was = clock.playing;
    Object.assign(clock, { time: m.time, start: m.start, end: m.end, playing: !!m.playing, loop: !!m.loop, speed: m.speed, at: performance.now(), known: true });
    range.min = String(m.start); range.max = String(m.end);
    if (typeof m.clip === "number") menu.value = String(m.clip);
    range.step = String(Math.max((m.end - m.start) / 1000, 1e-4));
    bar.classList.add("shown");
    show();
    if (clock.playing && !was) requestAnimationFrame(loop);
  });
  // tests and other scripts: the timeline's state
  sy.timeline = function () { return { shown: bar.classList.contains("shown"), time: now(), start: clock.start, end: clock.end, playing: clock.playing, server_time: clock.time, clip: Number(menu.value || -1) }; };
})();
