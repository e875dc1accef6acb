// video.js — the page's video stream (docs/WEB.md, "The video stream"): which codecs this browser
// decodes (WebCodecs' VideoDecoder.isConfigSupported), and one decoder fed every video frame that
// arrives, in order (each predicts from the one before), whether or not the page shows it.
// view.js lists syVideo.codecs in its size message, passes every binary message to feed() and
// asks frame(seq) for the picture of a frame it shows. ?video=0: JPEG only; ?codec=vp8 (or vp9):
// offer only that one.
"use strict";
(function () {
  const HEADER = 192, MAGIC = 0x33465953, KEYFRAME = 2; // frame format 3 (docs/WEB.md)
  const NAMES = { 1: "vp8", 2: "vp9" };
  // best first: the server takes the first it encodes. vp9: about half vp8's bytes at the same
  // SSIM, and the governor's smaller moving frames go on in its stream (scaled references) where
  // vp8 needs a keyframe for each new size (docs/WEB.md, "The video stream")
  const CANDIDATES = [["vp9", "vp09.00.10.08"], ["vp8", "vp8"]];
  const params = new URLSearchParams(location.search);
  const only = params.get("codec");
  const hist = { bytes: [], psnr: [], decode: [] };
  function keep(a, v, n) { a.push(v); if (a.length > n) a.shift(); }
  const st = { codec: "jpeg", frames: 0, keyframes: 0, errors: 0, keyframe_requests: 0, dropped: 0 };
  let decoder = null, decoderCodec = 0, needKey = true, lastAsk = -1e9;
  const entries = new Map(); // seq -> {frame, claimed, resolve, reject, t}

  const api = window.syVideo = {
    codecs: [],        // what this page decodes, filled by ready
    ready: null,       // a promise: the codecs are known
    askKeyframe: null, // set by view.js: sends {"t":"keyframe"}
    feed: feed, frame: frame, reset: reset,
    stats: function () {
      const mean = (a) => a.length ? a.reduce((x, y) => x + y, 0) / a.length : 0;
      return Object.assign({}, st, { offered: api.codecs.slice(), bytes_per_frame: mean(hist.bytes),
                                     psnr_db: mean(hist.psnr), decode_ms: hist.decode.slice() });
    },
  };
  api.ready = (async function () {
    if (params.get("video") === "0" || typeof VideoDecoder === "undefined") return api.codecs;
    for (const [name, codec] of CANDIDATES) {
      if (only && only !== name) continue;
      try {
        const s = await VideoDecoder.isConfigSupported({ codec: codec, optimizeForLatency: true });
        if (s.supported) api.codecs.push(name);
      } catch (e) { /* not this one */ }
    }
    return api.codecs;
  })();

  function fail(why) { // the decoder lost its place: what waits is refused, a keyframe is asked
    st.errors++;
    for (const e of entries.values()) { if (e.frame) e.frame.close(); if (e.claimed) e.reject(new Error("video")); }
    entries.clear();
    needKey = true;
    if (decoder && decoder.state !== "closed") try { decoder.close(); } catch (e) {}
    decoder = null;
    ask();
  }
  function ask() { // {"t":"keyframe"}, at most twice a second
    const now = performance.now();
    if (now - lastAsk < 500 || !api.askKeyframe) return;
    lastAsk = now; st.keyframe_requests++;
    api.askKeyframe();
  }
  function output(vf) {
    const seq = vf.timestamp, e = entries.get(seq);
    for (const [s, o] of entries) // older frames nobody asked for: never shown
      if (s < seq && !o.claimed) { if (o.frame) o.frame.close(); entries.delete(s); }
    if (!e) { vf.close(); return; }
    keep(hist.decode, performance.now() - e.t, 60);
    if (e.claimed) { entries.delete(seq); e.resolve(vf); } else e.frame = vf;
  }
  function reset() { fail("reset"); st.errors--; }
  // every binary message: a video frame goes to the decoder now (returns true), JPEG is left to view.js
  function feed(buf) {
    if (buf.byteLength < HEADER) return false;
    const dv = new DataView(buf);
    if (dv.getUint32(0, true) !== MAGIC || dv.getUint32(40, true) !== HEADER) return false;
    const codec = dv.getUint32(184, true), len = dv.getUint32(44, true);
    if (!NAMES[codec] || HEADER + len > buf.byteLength) return false;
    const key = (dv.getUint32(180, true) & KEYFRAME) !== 0, seq = Number(dv.getBigUint64(24, true));
    st.codec = NAMES[codec];
    if (needKey && !key) { st.dropped++; ask(); return true; } // undecodable until a keyframe
    if (!decoder || decoderCodec !== codec) {
      if (decoder && decoder.state !== "closed") try { decoder.close(); } catch (e) {}
      decoder = new VideoDecoder({ output: output, error: function () { fail("decode"); } });
      decoder.configure({ codec: CANDIDATES.find((c) => c[0] === NAMES[codec])[1], optimizeForLatency: true });
      decoderCodec = codec;
    }
    needKey = false;
    st.frames++; if (key) st.keyframes++;
    keep(hist.bytes, len, 60); keep(hist.psnr, dv.getFloat32(188, true), 60);
    let resolve, reject;
    const p = new Promise(function (a, b) { resolve = a; reject = b; });
    p.catch(function () {});
    entries.set(seq, { frame: null, claimed: false, resolve: resolve, reject: reject, t: performance.now(), p: p });
    try {
      decoder.decode(new EncodedVideoChunk({ type: key ? "key" : "delta", timestamp: seq,
                                             data: new Uint8Array(buf, HEADER, len) }));
    } catch (e) { fail("decode"); }
    return true;
  }
  // the picture of video frame seq (a VideoFrame: the caller closes it), or a refusal
  function frame(seq) {
    const e = entries.get(seq);
    if (!e) return Promise.reject(new Error("video"));
    if (e.frame) { entries.delete(seq); return Promise.resolve(e.frame); }
    e.claimed = true;
    return e.p;
  }
})();
