// view.js — the page of sy web: server frames, the local orbit and the warp (docs/WEB.md, "The page").
"use strict";
(function () {
  // The page of sy web (docs/WEB.md, "The page"): server frames (JPEG or video + depth + camera,
  // frame format 3) kept as the last two references; every input moves the local orbit at once (the
  // maths of core/sy_orbit.c) and each display frame warps the references to it (depth-based 3D
  // warping as point splats, the nearer wins, then a hole fill) until the server's frame for
  // that view arrives. ?warp=0: show server frames only (the comparison).
  const canvas = document.getElementById("sy-canvas"), hud = document.getElementById("sy-hud");
  const badge = document.getElementById("sy-estimate");
  const params = new URLSearchParams(location.search);
  const warpOn = params.get("warp") !== "0", showHoles = params.get("holes") === "1";
  const aheadOn = params.get("ahead") !== "0"; // ?ahead=0: frames of the view the inputs reached (the comparison)
  const FORMAT = 3, HEADER = 192, MAGIC = 0x33465953, SAME_DEPTH = 4;
  // Test hook (browser tests): frames received, the newest input id sent and the one the last
  // frame answers, the frame's size, back-end, samples and render time.
  const stats = window.syStats = { frames: 0, lastInput: 0, answeredInput: 0, width: 0, height: 0,
                                   backend: "", backends: [], samples: 0, renderMs: 0, connected: false };
  const token = params.get("token");
  const wsUrl = (location.protocol === "https:" ? "wss://" : "ws://") + location.host + "/ws" +
                (token ? "?token=" + encodeURIComponent(token) : "");
  let ws = null, inputId = 0, decoding = false, pending = null, lastSeq = -1, hold = false;
  const bad = { magic: 0, version: 0, size: 0, large: 0, order: 0, camera: 0, depth: 0, jpeg: 0, video: 0 };
  const asked = { w: 0, h: 0 }; // the largest frame size asked for on this connection
  const video = window.syVideo || null; // video.js: the video stream's decoder (docs/WEB.md)
  const hist = { input: [], frame: [], bytes: [], arrivals: [], adopt: [], depth: [], latency: [] };
  const depthCount = { own: 0, same: 0, none: 0, mesh_kept: 0 }; // frames shown by where their depth came from
  function keep(a, v, n) { a.push(v); if (a.length > n) a.shift(); }

  // ---- the orbit camera: the same rules as core/sy_orbit.c (sy_orbit_rotate, _pan, _zoom) ----
  const HALF = 0.5e12; // SY_COORD_MAX / 2
  function orbitMatrix(o) { // camera-to-world, column-major (sy_mat4)
    const cp = Math.cos(o.pitch), bk = [cp * Math.sin(o.yaw), Math.sin(o.pitch), cp * Math.cos(o.yaw)];
    const pos = [0, 1, 2].map((i) => o.target[i] + bk[i] * o.dist);
    let x = [bk[2], 0, -bk[0]], xl = Math.hypot(x[0], x[2]);
    if (xl < 1e-6) { x = [1, 0, 0]; xl = 1; }
    x = [x[0] / xl, 0, x[2] / xl];
    const y = [bk[1] * x[2] - bk[2] * x[1], bk[2] * x[0] - bk[0] * x[2], bk[0] * x[1] - bk[1] * x[0]];
    return new Float32Array([x[0], x[1], x[2], 0, y[0], y[1], y[2], 0, bk[0], bk[1], bk[2], 0, pos[0], pos[1], pos[2], 1]);
  }
  function clampOrbit(o) {
    for (let i = 0; i < 3; i++) o.target[i] = isFinite(o.target[i]) ? Math.min(Math.max(o.target[i], -HALF), HALF) : 0;
    o.dist = isFinite(o.dist) ? Math.min(Math.max(o.dist, 1e-3), HALF) : 1;
  }
  function applyInput(o, m) {
    if (m.t === "drag" && !m.b) {
      let yaw = Math.fround(o.yaw - Math.fround(m.dx * 0.008));
      o.yaw = Math.fround(yaw % (2 * 3.14159265));
      o.pitch = Math.min(Math.max(Math.fround(o.pitch + Math.fround(m.dy * 0.008)), -1.55), 1.55);
    } else if (m.t === "drag") {
      const mm = orbitMatrix(o), k = o.dist * 0.0015;
      for (let i = 0; i < 3; i++) o.target[i] += (-m.dx * mm[i] + m.dy * mm[4 + i]) * k;
    } else if (m.t === "wheel") {
      o.dist *= Math.pow(0.9, Math.min(Math.max(m.steps, -50), 50));
    }
    clampOrbit(o);
  }
  const sent = []; // inputs sent and not yet answered by the newest reference: {id, m, t (ms)}
  const waiting = []; // inputs not yet displayed: {id, t}
  let shownInput = 0; // the newest input the picture on screen answers

  // ---- WebGL2: references, the warp, the hole fill ----
  const gl = canvas.getContext("webgl2", { antialias: false, alpha: false, depth: false });
  const g2 = gl ? null : canvas.getContext("2d");
  const refs = []; // newest first, at most 2: {color, depth, w, h, c2w, win, orbit, seq, answered, warpable}
  let vao = null, prog = null, fillProg = null, blitProg = null, fbo = null, fboColor = null, fboDepth = null, fboW = 0, fboH = 0;
  let fillFbo = null, fillTex = null; // the hole fill at the warp's resolution when that is below the canvas'
  function compile(vs, fs) {
    const p = gl.createProgram();
    for (const [type, src] of [[gl.VERTEX_SHADER, vs], [gl.FRAGMENT_SHADER, fs]]) {
      const sh = gl.createShader(type);
      gl.shaderSource(sh, "#version 300 es\nprecision highp float;\nprecision highp int;\n" + src);
      gl.compileShader(sh);
      if (!gl.getShaderParameter(sh, gl.COMPILE_STATUS)) throw new Error(gl.getShaderInfoLog(sh));
      gl.attachShader(p, sh);
    }
    gl.linkProgram(p);
    if (!gl.getProgramParameter(p, gl.LINK_STATUS)) throw new Error(gl.getProgramInfoLog(p));
    const u = {};
    const n = gl.getProgramParameter(p, gl.ACTIVE_UNIFORMS);
    for (let i = 0; i < n; i++) { const name = gl.getActiveUniform(p, i).name; u[name] = gl.getUniformLocation(p, name); }
    return { p, u };
  }
  const FULL = "void main() { vec2 v = vec2(gl_VertexID == 1 ? 3.0 : -1.0, gl_VertexID == 2 ? 3.0 : -1.0);" +
               " gl_Position = vec4(v, 0.0, 1.0); }";
  if (gl) {
    // a grid mesh over the reference (a vertex every `stride` pixels, two triangles per cell, built
    // when the frame arrives: buildMesh), each vertex at its depth along its ray in the reference's
    // camera space (no hit: a direction, at infinity), moved into the current view here; the
    // colour is sampled per fragment at full resolution. Cells across a depth edge are drawn
    // apart (uSheet): behind every surface but in front of the sky (behind it, an object's side
    // seen at a grazing angle vanished), they fill only what neither reference covers. Cells with
    // a hit and a miss are not drawn: stretched to the horizon they smeared an object's edge over
    // what a turn uncovers (DamagedHelmet, docs/WEB.md); the hole fill shows what is behind.
    prog = compile(`
      layout(location = 0) in vec4 aPos; layout(location = 1) in vec2 aUV;
      uniform mat4 uRefToCur; uniform vec4 uCurWin; uniform float uBias; uniform int uSheet;
      out vec2 vUV; out float vFar;
      void main() {
        vec4 q = uRefToCur * aPos;
        float z = -q.z, l = uCurWin.x, r = uCurWin.y, b = uCurWin.z, t = uCurWin.w;
        float dz = uSheet == 1 ? 0.9985 : aPos.w > 0.0 ? clamp(log2(1.0 + max(z, 0.0)) / 48.0 + uBias, 0.0, 0.998) : 0.999;
        // the hole fill's depth in alpha: lower is farther (0 = nothing drawn)
        vFar = uSheet == 1 || aPos.w == 0.0 ? 1.0 / 255.0 : 1.0 - clamp(log2(1.0 + max(z, 0.0)) / 24.0, 0.0, 0.99);
        vUV = aUV;
        // homogeneous (w = the view depth): the clipper cuts what is behind the camera
        gl_Position = vec4(2.0 * q.x / (r - l) - (2.0 * l / (r - l) + 1.0) * z,
                           2.0 * q.y / (t - b) - (2.0 * b / (t - b) + 1.0) * z, (dz * 2.0 - 1.0) * z, z);
      }`, `
      uniform sampler2D uColor; in vec2 vUV; in float vFar; out vec4 o;
      void main() { o = vec4(texture(uColor, vUV).rgb, max(vFar, 1.0 / 255.0)); }`);
    // holes (nothing drawn): on the nearest ring (1, 4, 16, 64, 256, 1024 pixels, 8 directions) that has
    // covered pixels, the mean of the farthest of them (alpha: 0 = hole, else lower = farther): a
    // disocclusion shows what is behind, not the edge of what moved in front
    fillProg = compile(FULL, `
      uniform sampler2D uWarp; uniform int uShowHoles, uMark; uniform float uScale; out vec4 o;
      void main() {
        ivec2 sz = textureSize(uWarp, 0), p = min(ivec2(gl_FragCoord.xy * uScale), sz - 1);
        vec4 c = texelFetch(uWarp, p, 0);
        if (c.a > 0.0) { o = vec4(texture(uWarp, gl_FragCoord.xy * uScale / vec2(sz)).rgb, 1.0); return; }
        vec3 sum = vec3(0.0); float n = 0.0;
        for (int r = 1; r <= 1024 && n == 0.0; r *= 4) {
          vec4 s[8]; float amin = 2.0;
          for (int k = 0; k < 8; k++) {
            ivec2 d = ivec2(k == 0 || k == 1 || k == 7 ? 1 : (k == 3 || k == 4 || k == 5 ? -1 : 0),
                            k == 1 || k == 2 || k == 3 ? 1 : (k == 5 || k == 6 || k == 7 ? -1 : 0)) * r;
            s[k] = texelFetch(uWarp, clamp(p + d, ivec2(0), sz - 1), 0);
            if (s[k].a > 0.0) amin = min(amin, s[k].a);
          }
          for (int k = 0; k < 8; k++)
            if (s[k].a > 0.0 && s[k].a <= amin + 3.0 / 255.0) { sum += s[k].rgb; n += 1.0; }
        }
        vec3 f = n > 0.0 ? sum / n : vec3(0.0);
        // uMark (sy.capture): alpha 0 where no ring found a covered pixel (the fill left a hole)
        o = vec4(uShowHoles == 1 ? mix(f, vec3(1.0, 0.0, 1.0), 0.5) : f, uMark == 1 && n == 0.0 ? 0.0 : 1.0);
      }`);
    // the exact frame (rows top-down): scaled to the canvas; uCopy: a texture of ours (bottom-up,
    // its alpha kept: the hole fill's marks) scaled to the target
    blitProg = compile(FULL, `
      uniform sampler2D uColor; uniform vec2 uCanvas; uniform int uCopy; out vec4 o;
      void main() {
        vec2 uv = gl_FragCoord.xy / uCanvas;
        o = uCopy == 1 ? texture(uColor, uv) : vec4(texture(uColor, vec2(uv.x, 1.0 - uv.y)).rgb, 1.0);
      }`);
    vao = gl.createVertexArray();
    gl.bindVertexArray(vao);
  }
  // the bound TEXTURE_2D's sampling: bilinear, clamped at its edges
  function linearClamp() {
    gl.texParameteri(gl.TEXTURE_2D, gl.TEXTURE_MIN_FILTER, gl.LINEAR);
    gl.texParameteri(gl.TEXTURE_2D, gl.TEXTURE_MAG_FILTER, gl.LINEAR);
    gl.texParameteri(gl.TEXTURE_2D, gl.TEXTURE_WRAP_S, gl.CLAMP_TO_EDGE);
    gl.texParameteri(gl.TEXTURE_2D, gl.TEXTURE_WRAP_T, gl.CLAMP_TO_EDGE);
  }
  // a new framebuffer drawing into a new RGBA8 texture of w x h (linearClamp): {fb, tex}
  function colorTarget(w, h) {
    const fb = gl.createFramebuffer(), tex = gl.createTexture();
    gl.bindTexture(gl.TEXTURE_2D, tex);
    gl.texStorage2D(gl.TEXTURE_2D, 1, gl.RGBA8, w, h);
    linearClamp();
    gl.bindFramebuffer(gl.FRAMEBUFFER, fb);
    gl.framebufferTexture2D(gl.FRAMEBUFFER, gl.COLOR_ATTACHMENT0, gl.TEXTURE_2D, tex, 0);
    gl.bindFramebuffer(gl.FRAMEBUFFER, null);
    return { fb: fb, tex: tex };
  }
  function ensureFbo(w, h) {
    if (fbo && fboW === w && fboH === h) return;
    if (fbo) { gl.deleteFramebuffer(fbo); gl.deleteTexture(fboColor); gl.deleteRenderbuffer(fboDepth); }
    if (fillFbo) { gl.deleteFramebuffer(fillFbo); gl.deleteTexture(fillTex); fillFbo = fillTex = null; }
    const t = colorTarget(w, h);
    fbo = t.fb; fboColor = t.tex; fboDepth = gl.createRenderbuffer();
    gl.bindRenderbuffer(gl.RENDERBUFFER, fboDepth);
    gl.renderbufferStorage(gl.RENDERBUFFER, gl.DEPTH_COMPONENT24, w, h);
    gl.bindFramebuffer(gl.FRAMEBUFFER, fbo);
    gl.framebufferRenderbuffer(gl.FRAMEBUFFER, gl.DEPTH_ATTACHMENT, gl.RENDERBUFFER, fboDepth);
    gl.bindFramebuffer(gl.FRAMEBUFFER, null);
    fboW = w; fboH = h;
    if (w !== canvas.width || h !== canvas.height) { // the fill at this size, then scaled (fill())
      const f = colorTarget(w, h);
      fillFbo = f.fb; fillTex = f.tex;
    }
  }
  function texture(w, h, bmp) {
    const t = gl.createTexture();
    gl.bindTexture(gl.TEXTURE_2D, t);
    linearClamp();
    gl.texImage2D(gl.TEXTURE_2D, 0, gl.RGBA8, gl.RGBA, gl.UNSIGNED_BYTE, bmp);
    return t;
  }
  // 4x4 maths (column-major): the inverse of a rigid camera-to-world, products
  function rigidInverse(m) {
    const r = new Float32Array(16);
    for (let i = 0; i < 3; i++) for (let j = 0; j < 3; j++) r[j * 4 + i] = m[i * 4 + j];
    for (let i = 0; i < 3; i++) r[12 + i] = -(r[i] * m[12] + r[4 + i] * m[13] + r[8 + i] * m[14]);
    r[15] = 1;
    return r;
  }
  function mul(a, b) {
    const r = new Float32Array(16);
    for (let c = 0; c < 4; c++) for (let i = 0; i < 4; i++) {
      let s = 0;
      for (let k = 0; k < 4; k++) s += a[k * 4 + i] * b[c * 4 + k];
      r[c * 4 + i] = s;
    }
    return r;
  }

  // ---- frames in: checked, decoded, kept ----
  function camOk(c2w, win) { // finite, a rotation (orthonormal, det 1), a window with extent
    if (!c2w.every(isFinite) || !win.every(isFinite) || !(win[1] > win[0]) || !(win[3] > win[2])) return false;
    const col = (j) => [c2w[j * 4], c2w[j * 4 + 1], c2w[j * 4 + 2]];
    const x = col(0), y = col(1), z = col(2), dot = (a, b) => a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
    const det = x[0] * (y[1] * z[2] - y[2] * z[1]) - y[0] * (x[1] * z[2] - x[2] * z[1]) + z[0] * (x[1] * y[2] - x[2] * y[1]);
    return Math.abs(det - 1) < 1e-3 && Math.abs(dot(x, y)) < 1e-3 && Math.abs(dot(y, z)) < 1e-3 && Math.abs(dot(x, z)) < 1e-3;
  }
  // inflates at most limit bytes: a stream that would give more is refused as it grows, so a few
  // bytes of deflate never become a large allocation
  async function inflate(bytes, limit) {
    const reader = new Blob([bytes]).stream().pipeThrough(new DecompressionStream("deflate")).getReader();
    const out = new Uint8Array(limit);
    for (let n = 0; ;) {
      const { done, value } = await reader.read();
      if (done) return out.subarray(0, n);
      if (value.length > limit - n) { reader.cancel().catch(() => {}); throw new Error("depth"); }
      out.set(value, n); n += value.length;
    }
  }
  // docs/WEB.md, depth coding 2: the grid of every fourth pixel (and the last column and row),
  // 12-bit log depth, each value minus its MED prediction, byte planes; {d, gw, gh} (0: no hit)
  const STEP = 4, gridN = (n) => Math.ceil((n - 1) / STEP) + 1;
  function decodeDepth(planes, w, h, dmin, dmax) {
    const gw = gridN(w), gh = gridN(h), n = gw * gh, q = new Uint16Array(n), d = new Float32Array(n);
    const span = dmax > dmin ? Math.log(dmax / dmin) / 4094 : 0;
    for (let j = 0, k = 0; j < gh; j++) for (let i = 0; i < gw; i++, k++) {
      let p;
      if (!j) p = i ? q[k - 1] : 0;
      else if (!i) p = q[k - gw];
      else {
        const a = q[k - 1], b = q[k - gw], c = q[k - gw - 1], mx = Math.max(a, b), mn = Math.min(a, b);
        p = c >= mx ? mn : c <= mn ? mx : a + b - c;
      }
      const v = q[k] = (p + (planes[k] | planes[n + k] << 8)) & 0xffff;
      if (v > 4095) throw new Error("depth"); // beyond the 12-bit scale
      d[k] = v ? dmin * Math.exp((v - 1) * span) : 0;
    }
    return { d: d, gw: gw, gh: gh, w: w, h: h };
  }
  // the depth of pixel (x, y) from the grid (sy_web_depth_grid_at in apps/web/sy_web_frame.c): a
  // grid point's own; between, 1 / depth bilinear from the grid points around it, or where one of
  // them has no hit the nearest one's (0: no hit)
  function gridAxis(x, n, gn) {
    const i0 = Math.min(Math.floor(x / STEP), gn - 1), p0 = Math.min(STEP * i0, n - 1);
    if (p0 === x || i0 === gn - 1) return [i0, i0, 0];
    return [i0, i0 + 1, (x - p0) / (Math.min(STEP * (i0 + 1), n - 1) - p0)];
  }
  function depthAt(g, x, y) {
    const [i0, i1, tx] = gridAxis(x, g.w, g.gw), [j0, j1, ty] = gridAxis(y, g.h, g.gh);
    if (!tx && !ty) return g.d[j0 * g.gw + i0];
    const c = [g.d[j0 * g.gw + i0], g.d[j0 * g.gw + i1], g.d[j1 * g.gw + i0], g.d[j1 * g.gw + i1]];
    const wt = [(1 - tx) * (1 - ty), tx * (1 - ty), (1 - tx) * ty, tx * ty];
    let inv = 0, near = 0;
    for (let k = 0; k < 4; k++) {
      if (wt[k] > wt[near]) near = k;
      if (wt[k] > 0 && !(c[k] > 0)) inv = -1;
      else if (inv >= 0 && wt[k] > 0) inv += wt[k] / c[k];
    }
    return inv > 0 ? 1 / inv : c[near];
  }
  // where a frame's depth comes from, decided as it arrives (frames arrive in order; the page may
  // skip some while it is busy): its own channel, or for a frame that says it has the last one
  // (SAME_DEPTH) the last channel that arrived; decoded once for all the frames that share it
  let lastDepth = null;
  function depthSource(buf) {
    if (buf.byteLength < HEADER) return null;
    const dv = new DataView(buf);
    if (dv.getUint32(0, true) !== MAGIC || dv.getUint32(40, true) !== HEADER) return null;
    const jl = dv.getUint32(44, true), dl = dv.getUint32(48, true);
    if (dl && HEADER + jl + dl === buf.byteLength)
      lastDepth = { bytes: new Uint8Array(buf, HEADER + jl, dl), w: dv.getUint32(4, true), h: dv.getUint32(8, true),
                    dmin: dv.getFloat32(56, true), dmax: dv.getFloat32(60, true), grid: null };
    return dl ? lastDepth : (dv.getUint32(180, true) & SAME_DEPTH) ? lastDepth : null;
  }
  function depthGrid(src) { // a promise of the decoded grid
    if (!src.grid) {
      const gn = gridN(src.w) * gridN(src.h);
      src.grid = inflate(src.bytes, 2 * gn).then((p) => {
        if (p.length !== 2 * gn) throw new Error("depth");
        return decodeDepth(p, src.w, src.h, src.dmin, src.dmax);
      });
    }
    return src.grid;
  }
  function parse(buf) { // the header (docs/WEB.md) or the reason it is refused
    const dv = new DataView(buf), len = buf.byteLength;
    if (len < 8 || (dv.getUint32(0, true) & 0xffffff) !== (MAGIC & 0xffffff)) return { bad: "magic" };
    if (dv.getUint32(0, true) !== MAGIC) return { bad: "version", version: String.fromCharCode(dv.getUint8(3)) };
    if (len < HEADER || dv.getUint32(40, true) !== HEADER) return { bad: "size" };
    const f = { w: dv.getUint32(4, true), h: dv.getUint32(8, true), bi: dv.getUint32(12, true), samples: dv.getUint32(16, true),
                renderMs: dv.getFloat32(20, true), seq: Number(dv.getBigUint64(24, true)),
                answered: Number(dv.getBigUint64(32, true)), jpegLen: dv.getUint32(44, true), depthLen: dv.getUint32(48, true),
                coding: dv.getUint32(52, true), dmin: dv.getFloat32(56, true), dmax: dv.getFloat32(60, true),
                c2w: new Float32Array(buf.slice(64, 128)), win: [0, 1, 2, 3].map((i) => dv.getFloat32(128 + 4 * i, true)),
                proj: dv.getUint32(144, true), flags: dv.getUint32(180, true), bytes: len, codec: dv.getUint32(184, true),
                sameDepth: (dv.getUint32(180, true) & SAME_DEPTH) !== 0,
                orbit: { target: [0, 1, 2].map((i) => dv.getFloat32(156 + 4 * i, true)), yaw: dv.getFloat32(168, true),
                         pitch: dv.getFloat32(172, true), dist: dv.getFloat32(176, true) } };
    if (!f.w || !f.h || f.w > 16384 || f.h > 16384 || f.w * f.h > 67108864 || HEADER + f.jpegLen + f.depthLen !== len) return { bad: "size" };
    // never larger than this page asked for (the largest size it asked on this connection: frames
    // of a size asked before a resize may still be on their way): a server cannot make the page
    // decode more than it shows
    if (f.w > asked.w || f.h > asked.h) return { bad: "large" };
    if (f.seq <= lastSeq) return { bad: "order" };
    if (!camOk(f.c2w, f.win) || ![f.orbit.yaw, f.orbit.pitch, f.orbit.dist, ...f.orbit.target].every(isFinite) ||
        !(f.orbit.dist > 0)) return { bad: "camera" };
    f.warpable = f.proj === 0; // an orthographic frame is shown as it is, never warped
    if (f.depthLen && (f.coding !== 2 || f.sameDepth || !(f.dmin > 0) || !(f.dmax >= f.dmin) || !isFinite(f.dmax))) return { bad: "depth" };
    return f;
  }
  // the reference's mesh: grid points every s pixels (camera space: (tx d, ty d, -d, 1), no hit
  // (tx, ty, -1, 0)) and their texture coordinates; the cells' triangles, those across a depth
  // edge (corners more than 5% apart) after the others, none for a cell of hits and misses
  function buildMesh(depth, w, h, win, s) {
    s = Math.max(1, Math.min(s, w - 1, h - 1));
    const cols = Math.max(1, Math.ceil((w - 1) / s)), rows = Math.max(1, Math.ceil((h - 1) / s)), gx = cols + 1, gy = rows + 1;
    const v = new Float32Array(gx * gy * 6), dd = new Float32Array(gx * gy);
    for (let j = 0, n = 0; j < gy; j++) {
      const y = Math.min(j * s, h - 1), ty = win[3] + (win[2] - win[3]) * (y + 0.5) / h;
      for (let i = 0; i < gx; i++, n++) {
        const x = Math.min(i * s, w - 1), tx = win[0] + (win[1] - win[0]) * (x + 0.5) / w;
        const d = depthAt(depth, x, y);
        const o = n * 6;
        if (d > 0) { v[o] = tx * d; v[o + 1] = ty * d; v[o + 2] = -d; v[o + 3] = 1; }
        else { v[o] = tx; v[o + 1] = ty; v[o + 2] = -1; v[o + 3] = 0; }
        v[o + 4] = (x + 0.5) / w; v[o + 5] = (y + 0.5) / h;
        dd[n] = d;
      }
    }
    const idx = new Uint32Array(cols * rows * 6);
    let a = 0, b = idx.length;
    for (let j = 0; j < rows; j++) for (let i = 0; i < cols; i++) {
      const p = j * gx + i, q = [p, p + 1, p + gx, p + 1, p + gx + 1, p + gx];
      const c = [dd[p], dd[p + 1], dd[p + gx], dd[p + gx + 1]], lo = Math.min(...c), hi = Math.max(...c);
      if (hi > 0 && lo <= 0) continue; // a hit beside a miss: a sheet would stretch it to the horizon
      if (hi > lo * 1.05) { b -= 6; idx.set(q, b); } else { idx.set(q, a); a += 6; }
    }
    // the sheet cells were written from the end: solid [0, a), sheet [b, end)
    const m = { vao: gl.createVertexArray(), vbo: gl.createBuffer(), ibo: gl.createBuffer(), solid: a, sheet: idx.length - b, sheetAt: b };
    gl.bindVertexArray(m.vao);
    gl.bindBuffer(gl.ARRAY_BUFFER, m.vbo);
    gl.bufferData(gl.ARRAY_BUFFER, v, gl.STATIC_DRAW);
    gl.enableVertexAttribArray(0); gl.vertexAttribPointer(0, 4, gl.FLOAT, false, 24, 0);
    gl.enableVertexAttribArray(1); gl.vertexAttribPointer(1, 2, gl.FLOAT, false, 24, 16);
    gl.bindBuffer(gl.ELEMENT_ARRAY_BUFFER, m.ibo);
    gl.bufferData(gl.ELEMENT_ARRAY_BUFFER, idx, gl.STATIC_DRAW);
    gl.bindVertexArray(vao);
    return m;
  }
  function freeRef(o) {
    gl.deleteTexture(o.color);
    if (o.mesh && !o.meshKept) { gl.deleteVertexArray(o.mesh.vao); gl.deleteBuffer(o.mesh.vbo); gl.deleteBuffer(o.mesh.ibo); }
  }
  function adopt(f, bmp, depth, src) {
    if (gl) {
      const warpable = f.warpable && !!depth && f.w > 1 && f.h > 1;
      // two views: a frame of the newest one's view (its refinement) replaces it, and keeps its
      // mesh when the depth is the same (a progressive back-end's samples: SAME_DEPTH)
      const same = refs.length && JSON.stringify(refs[0].orbit) === JSON.stringify(f.orbit) &&
                   refs[0].c2w.every((x, i) => x === f.c2w[i]);
      const keepMesh = same && warpable && refs[0].mesh && refs[0].src === src && refs[0].stride === stride;
      if (keepMesh) { refs[0].meshKept = true; depthCount.mesh_kept++; }
      const r = { color: texture(f.w, f.h, bmp),
                  mesh: keepMesh ? refs[0].mesh : warpable ? buildMesh(depth, f.w, f.h, f.win, stride) : null,
                  src: src, stride: stride,
                  w: f.w, h: f.h, c2w: f.c2w, win: f.win, orbit: f.orbit, seq: f.seq, answered: f.answered, warpable: warpable,
                  ahead: renderedAhead(f) };
      if (r.ahead) aheadFrames++;
      if (same) freeRef(refs.shift());
      refs.unshift(r);
      while (refs.length > 2) freeRef(refs.pop());
    } else {
      g2.drawImage(bmp, 0, 0, canvas.width, canvas.height);
    }
    // the inputs this frame includes are no longer predicted on top of it; the newest one's time
    // to this frame is the latency the lead covers
    const now = performance.now();
    for (const s of sent) if (s.id === f.answered) keep(hist.latency, now - s.t, 16);
    while (sent.length && sent[0].id <= f.answered) sent.shift();
    newFrame = true;
  }
  function show(buf, src) {
    const f = parse(buf);
    if (f.bad) {
      bad[f.bad]++;
      if (f.bad === "version") hud.textContent = "the server sends frame format " + f.version + ", this page reads " + FORMAT + ": reload";
      return next();
    }
    keep(hist.bytes, f.bytes, 60); keep(hist.arrivals, performance.now(), 120); keep(hist.depth, f.depthLen, 60);
    decoding = true;
    const jpeg = f.codec ? null : new Blob([new Uint8Array(buf, HEADER, f.jpegLen)], { type: "image/jpeg" });
    const picture = !f.codec ? createImageBitmap(jpeg).catch(() => { throw new Error("jpeg"); })
      : !video ? Promise.reject(new Error("video")) // a video frame: video.js decoded it as it arrived
      : video.frame(f.seq).then((vf) => createImageBitmap(vf).finally(() => vf.close())).catch(() => { throw new Error("video"); });
    // the frame's depth: its own, or the last one for a frame that says it has it (same size)
    const depth = f.sameDepth && !src ? Promise.reject(new Error("depth"))
      : !src || (!f.depthLen && !f.sameDepth) ? Promise.resolve(null)
      : src.w !== f.w || src.h !== f.h ? Promise.reject(new Error("depth")) : depthGrid(src);
    Promise.all([picture, depth.catch(() => { throw new Error("depth"); })])
      .then(function ([bmp, d]) {
        if (bmp.width !== f.w || bmp.height !== f.h) { bmp.close(); throw new Error("size"); }
        if (hold) { bmp.close(); return; } // tests: the references stay as they are
        if (f.seq <= lastSeq) { bmp.close(); throw new Error("order"); }
        lastSeq = f.seq;
        const t0 = performance.now();
        adopt(f, bmp, d, src);
        depthCount[f.depthLen ? "own" : f.sameDepth ? "same" : "none"]++;
        keep(hist.adopt, performance.now() - t0, 60);
        bmp.close();
        stats.frames++; stats.width = f.w; stats.height = f.h; stats.answeredInput = f.answered;
        mark("sy-frame-adopted");
        if (stats.frames === 1 && window.syEarly) { // the first picture's image gives way to the canvas
          window.syEarly.adopted = true;
          const img = document.getElementById("sy-first");
          if (img) { img.style.display = "none"; if (img.src) URL.revokeObjectURL(img.src); }
        }
        stats.samples = f.samples; stats.renderMs = f.renderMs;
        stats.backend = stats.backends[f.bi] || String(f.bi);
        hud.textContent = stats.backend + " | " + f.w + "x" + f.h + " | " + f.renderMs.toFixed(1) + " ms" +
                          (f.samples > 1 ? " | " + f.samples + " spp" : "") + (stats.filter ? " | " + stats.filter : "");
      }).catch(function (e) { bad[e.message in bad ? e.message : "jpeg"]++; }).finally(function () { decoding = false; next(); });
  }
  function next() { if (pending) { const p = pending; pending = null; show(p.buf, p.src); } } // only the newest waiting frame

  // ---- each display frame: the exact frame, or the references warped to the local orbit ----
  let frameCount = 0, inputCount = 0, warpAnswered = 0, newFrame = false, moved = false, lastT = 0;
  let drawnInput = 0, drawnServer = 0, estimate = 0;
  function localOrbit() {
    const o = JSON.parse(JSON.stringify(refs[0].orbit));
    for (const s of sent) applyInput(o, s.m);
    return o;
  }
  function draw() {
    const cw = canvas.width, ch = canvas.height;
    const r0 = refs[0];
    if (!warpOn || (!sent.length && !r0.ahead) || !r0.warpable) { // the newest frame as it is
      gl.bindFramebuffer(gl.FRAMEBUFFER, null);
      gl.viewport(0, 0, cw, ch);
      gl.useProgram(blitProg.p);
      gl.activeTexture(gl.TEXTURE0); gl.bindTexture(gl.TEXTURE_2D, r0.color);
      gl.uniform1i(blitProg.u.uColor, 0); gl.uniform2f(blitProg.u.uCanvas, cw, ch); gl.uniform1i(blitProg.u.uCopy, 0);
      gl.drawArrays(gl.TRIANGLES, 0, 3);
      estimate = 0;
      return r0.answered;
    }
    const o = localOrbit(), cur = orbitMatrix(o), toCur = rigidInverse(cur), win = r0.win;
    const fw = Math.max(1, Math.round(cw * LEVELS[level].scale)), fh = Math.max(1, Math.round(ch * LEVELS[level].scale));
    ensureFbo(fw, fh);
    gl.bindFramebuffer(gl.FRAMEBUFFER, fbo);
    gl.viewport(0, 0, fw, fh);
    gl.clearColor(0, 0, 0, 0); gl.clearDepth(1); gl.clear(gl.COLOR_BUFFER_BIT | gl.DEPTH_BUFFER_BIT);
    gl.enable(gl.DEPTH_TEST); gl.depthFunc(gl.LESS);
    gl.useProgram(prog.p);
    refs.forEach(function (r, k) { // the newest first; the older fills what it does not cover
      if (!r.warpable) return;
      gl.activeTexture(gl.TEXTURE0); gl.bindTexture(gl.TEXTURE_2D, r.color);
      gl.uniform1i(prog.u.uColor, 0);
      gl.uniformMatrix4fv(prog.u.uRefToCur, false, mul(toCur, r.c2w));
      gl.uniform4fv(prog.u.uCurWin, win);
      gl.uniform1f(prog.u.uBias, k ? 0.001 : 0);
      gl.bindVertexArray(r.mesh.vao);
      gl.uniform1i(prog.u.uSheet, 0);
      gl.drawElements(gl.TRIANGLES, r.mesh.solid, gl.UNSIGNED_INT, 0);
      gl.uniform1i(prog.u.uSheet, 1);
      if (r.mesh.sheet) gl.drawElements(gl.TRIANGLES, r.mesh.sheet, gl.UNSIGNED_INT, 4 * r.mesh.sheetAt);
      gl.bindVertexArray(vao);
    });
    gl.disable(gl.DEPTH_TEST);
    fill(null, false);
    estimate = 1;
    return inputId; // every input sent so far is in the local orbit
  }
  // the hole fill: the warp (fboColor) scaled to the canvas into target (null: the canvas); mark:
  // alpha 0 where it found nothing to fill with (sy.capture). A warp below the canvas' resolution
  // is filled at its own (fillFbo) and then scaled, bilinear: the fill's cost follows the level (at
  // the canvas' resolution it was most of a coarse level's display frame in SwiftShader)
  function fill(target, mark) {
    const cw = canvas.width, ch = canvas.height, direct = !fillFbo || (fboW === cw && fboH === ch);
    gl.bindFramebuffer(gl.FRAMEBUFFER, direct ? target : fillFbo);
    gl.viewport(0, 0, direct ? cw : fboW, direct ? ch : fboH);
    gl.useProgram(fillProg.p);
    gl.uniform1f(fillProg.u.uScale, direct ? fboW / cw : 1);
    gl.activeTexture(gl.TEXTURE0); gl.bindTexture(gl.TEXTURE_2D, fboColor);
    gl.uniform1i(fillProg.u.uWarp, 0); gl.uniform1i(fillProg.u.uShowHoles, showHoles ? 1 : 0);
    gl.uniform1i(fillProg.u.uMark, mark ? 1 : 0);
    gl.drawArrays(gl.TRIANGLES, 0, 3);
    if (!direct) {
      gl.bindFramebuffer(gl.FRAMEBUFFER, target);
      gl.viewport(0, 0, cw, ch);
      gl.useProgram(blitProg.p);
      gl.bindTexture(gl.TEXTURE_2D, fillTex);
      gl.uniform1i(blitProg.u.uColor, 0); gl.uniform2f(blitProg.u.uCanvas, cw, ch); gl.uniform1i(blitProg.u.uCopy, 1);
      gl.drawArrays(gl.TRIANGLES, 0, 3);
    }
    gl.bindFramebuffer(gl.FRAMEBUFFER, null);
  }
  // the warp adapts to what the display frames cost: a level is the mesh density (a vertex every
  // stride pixels; meshes built from then on) and the warp's resolution (its share of the canvas,
  // scaled up by the hole-fill pass); a level down while a warped display frame takes two
  // refreshes or more (> 34 ms), up while one refresh (< 20 ms) is enough
  const LEVELS = [{ stride: 2, scale: 1 }, { stride: 4, scale: 1 }, { stride: 4, scale: 0.5 },
                  { stride: 8, scale: 0.5 }, { stride: 8, scale: 0.25 }];
  // ?level=N (measurements): the warp held at level N (0..4), not adapted
  const fixedLevel = /^[0-4]$/.test(params.get("level") || "") ? Number(params.get("level")) : -1;
  let level = fixedLevel >= 0 ? fixedLevel : 1, stride = LEVELS[level].stride, lastWarped = false;
  function frame(t) {
    if (lastT) {
      keep(hist.frame, t - lastT, 240); frameCount++;
      if (fixedLevel >= 0) level = fixedLevel;
      else if (lastWarped && t - lastT > 34 && level < LEVELS.length - 1) level++;
      else if (lastWarped && t - lastT < 20 && level > 0) level--;
      stride = LEVELS[level].stride;
    }
    lastT = t;
    // the picture drawn in the last callback is on screen now: the inputs it answers are displayed
    // (now, not t: t is when the display frame began, which may precede an input handled since)
    const now = performance.now();
    // (camera inputs: by the local camera or a server frame; others, e.g. keys: by a server frame)
    for (let i = 0; i < waiting.length;) {
      const w = waiting[i];
      if (w.id <= drawnServer || (w.cam && w.id <= drawnInput)) {
        keep(hist.input, now - w.t, 240); inputCount++;
        if (w.id > drawnServer) warpAnswered++; // the estimate answered it before the server did
        waiting.splice(i, 1);
      } else i++;
    }
    if ((newFrame || moved || captures.length) && refs.length) {
      drawnInput = Math.max(drawnInput, draw());
      drawnServer = Math.max(drawnServer, refs[0].answered);
      shownInput = drawnInput;
      if (captures.length && gl) capture();
    } else if (!gl && newFrame) {
      drawnServer = drawnInput = stats.answeredInput;
    }
    lastWarped = estimate === 1 && (newFrame || moved);
    if (leadSent && now - lastDrag > LEAD_REST_MS) { // the hand rests: frames of the view it reached
      leadSent = false;
      send({ t: "lead", lead: [0, 0], b: 0 });
    }
    newFrame = moved = false;
    badge.style.display = estimate ? "block" : "none";
    requestAnimationFrame(frame);
  }
  requestAnimationFrame(frame);

  // ---- window.sy: measurable from outside (docs/WEB.md) ----
  // sy.capture (browser.mjs orbit): the display frame just drawn, read back before the browser
  // shows it: RGBA at the canvas' size (rows bottom-up), whether it is an estimate, the view it
  // shows (the local orbit, or the frame's), the newest input it answers and the share of the
  // canvas the hole fill left empty (an estimate's fill drawn again into capFbo, marking them)
  const captures = [];
  let capFbo = null, capTex = null, capW = 0, capH = 0;
  function capture() {
    const cw = canvas.width, ch = canvas.height, px = new Uint8Array(cw * ch * 4);
    let unfilled = 0;
    if (estimate) {
      if (!capFbo || capW !== cw || capH !== ch) {
        if (capFbo) { gl.deleteFramebuffer(capFbo); gl.deleteTexture(capTex); }
        const t = colorTarget(cw, ch);
        capFbo = t.fb; capTex = t.tex; capW = cw; capH = ch;
      }
      fill(capFbo, true);
      gl.bindFramebuffer(gl.FRAMEBUFFER, capFbo);
      gl.readPixels(0, 0, cw, ch, gl.RGBA, gl.UNSIGNED_BYTE, px);
      gl.bindFramebuffer(gl.FRAMEBUFFER, null);
      for (let i = 3; i < px.length; i += 4) if (!px[i]) { unfilled++; px[i] = 255; }
    } else {
      gl.readPixels(0, 0, cw, ch, gl.RGBA, gl.UNSIGNED_BYTE, px);
    }
    const c = { w: cw, h: ch, pixels: px, estimate: estimate, orbit: estimate ? localOrbit() : refs[0].orbit,
                input: drawnInput, unfilled: unfilled / (cw * ch),
                refs: refs.map(function (r) { return { w: r.w, h: r.h, yaw: r.orbit.yaw, pitch: r.orbit.pitch }; }) };
    for (const r of captures.splice(0)) r(c);
  }
  function holeShare() { // read back on demand: the pixels no reference point landed on
    if (!gl || !fbo || !estimate) return 0;
    const px = new Uint8Array(fboW * fboH * 4);
    gl.bindFramebuffer(gl.FRAMEBUFFER, fbo);
    gl.readPixels(0, 0, fboW, fboH, gl.RGBA, gl.UNSIGNED_BYTE, px);
    gl.bindFramebuffer(gl.FRAMEBUFFER, null);
    let n = 0;
    for (let i = 3; i < px.length; i += 4) if (!px[i]) n++;
    return n / (fboW * fboH);
  }
  window.sy = {
    stats: function (opts) { // opts.holes: read the warp back for hole_share (a GPU round trip)
      const now = performance.now(), recent = hist.arrivals.filter((a) => now - a < 2000);
      const mean = (a) => a.length ? a.reduce((x, y) => x + y, 0) / a.length : 0;
      return { input_to_display_ms: hist.input.slice(), frame_ms: hist.frame.slice(), adopt_ms: hist.adopt.slice(),
               server_fps: recent.length / 2, bytes_per_frame: mean(hist.bytes),
               estimate_share: estimate, hole_share: opts && opts.holes ? holeShare() : null, stride: stride, warp_scale: LEVELS[level].scale, warp: warpOn && !!gl,
               bad: Object.assign({}, bad),
               depth: Object.assign({ bytes_per_frame: mean(hist.depth) }, depthCount),
               video: video ? video.stats() : null,
               shown_input: shownInput, last_input: inputId, frames: stats.frames,
               display_frames: frameCount, inputs_displayed: inputCount, inputs_by_estimate: warpAnswered, // counts: slice the arrays' ends
               ahead: { on: aheadOn && warpOn && !!gl, lead_ms: leadMs, latency_ms: hist.latency.slice(), frames: aheadFrames } };
    },
    // tests: keep the references (frames arriving are dropped); released, the page asks for a frame
    hold: function (on) { hold = !!on; if (!hold) sendSize(); },
    // tests: a promise of the next display frame, drawn and read back (capture above)
    capture: function () { return new Promise(function (r) { captures.push(r); }); },
    // for the page's other scripts (ui.js, tree.js, ...): send a message, an input (the camera's
    // are predicted by the warp), listen to the server's text messages, and where a world point
    // is on the canvas now (CSS pixels; null when behind the camera or before the first frame)
    send: function (o) { send(o); },
    input: function (o) { input(o, null); },
    // a script that subscribes after the server's hello (the page's scripts load one by one while
    // the socket is open) is handed that hello at once
    on: function (f) { // a script that loads later gets the messages so far (while the page loads), else the hello
      listeners.push(f);
      for (const m of pageLoading ? early : lastHello ? [lastHello] : []) try { f(m); } catch (err) { console.error(err); }
    },
    project: function (p) {
      if (!refs.length) return null;
      const m = rigidInverse(orbitMatrix(sent.length ? localOrbit() : refs[0].orbit)), win = refs[0].win;
      const q = [0, 1, 2].map((i) => m[i] * p[0] + m[4 + i] * p[1] + m[8 + i] * p[2] + m[12 + i]), z = -q[2];
      if (!(z > 0)) return null;
      return [(q[0] / z - win[0]) / (win[1] - win[0]) * canvas.clientWidth, (win[3] - q[1] / z) / (win[3] - win[2]) * canvas.clientHeight];
    },
  };

  const listeners = []; // window.sy.on: the server's text messages, parsed
  let lastHello = null;
  // the server's text messages while the page loads: until index.html's "sy-scripts-loaded", which
  // comes after every one of the page's scripts ran (or the window's load, should a script fail)
  const early = [];
  let pageLoading = !(window.syEarly && window.syEarly.scriptsLoaded);
  function loaded() { pageLoading = false; early.length = 0; }
  document.addEventListener("sy-scripts-loaded", loaded);
  window.addEventListener("load", loaded); // (after it too: scripts inserted while the page loads hold its load event)
  function send(o) {
    if (ws && ws.readyState === 1) ws.send(JSON.stringify(o));
  }
  // ---- frames rendered ahead (docs/WEB.md, "Frames rendered ahead") ----
  // A warped frame is as good as its reference is near the view: while the hand moves steadily, each
  // drag asks the server to render its frame further along by a lead, the drag the hand adds in the
  // time until that frame shows plus half the time it stays the newest (the page's own measures:
  // the median input-to-frame latency, the median interval between frames). The velocity: drag
  // pixels over the last LEAD_WINDOW_MS (3 inputs at least, all with one button; a jump, such as a
  // view recalled, is no motion). The frame's header keeps the orbit the inputs reached and its camera
  // the one ahead: the page warps it to the local orbit as any reference. The hand rests
  // (LEAD_REST_MS without a drag): lead [0, 0], and the server renders the exact view again.
  const LEAD_WINDOW_MS = 400, LEAD_REST_MS = 250, LEAD_MAX_MS = 800, LEAD_MAX_PX = 64;
  const drags = []; // {t, dx, dy, b}: recent drag inputs
  let leadSent = false, lastDrag = 0, leadMs = 0, aheadFrames = 0;
  function median(a) { const s = a.slice().sort((x, y) => x - y); return s.length ? s[s.length >> 1] : 0; }
  function leadFor(m, t) {
    keep(drags, { t: t, dx: m.dx, dy: m.dy, b: m.b || 0 }, 64);
    lastDrag = t;
    if (!aheadOn || !warpOn || !gl || hist.latency.length < 2) return null;
    const win = drags.filter((d) => t - d.t <= LEAD_WINDOW_MS);
    if (win.length < 3 || win.some((d) => d.b !== (m.b || 0))) return null;
    const span = win[win.length - 1].t - win[0].t;
    if (span < 30) return null;
    let sx = 0, sy = 0;
    for (let i = 1; i < win.length; i++) { sx += win[i].dx; sy += win[i].dy; } // the first's drag came before win[0].t
    const gaps = [];
    for (let i = Math.max(1, hist.arrivals.length - 9); i < hist.arrivals.length; i++) gaps.push(hist.arrivals[i] - hist.arrivals[i - 1]);
    leadMs = Math.min(LEAD_MAX_MS, median(hist.latency) + median(gaps) / 2);
    let lx = sx / span * leadMs, ly = sy / span * leadMs;
    const len = Math.hypot(lx, ly);
    if (len > LEAD_MAX_PX) { lx *= LEAD_MAX_PX / len; ly *= LEAD_MAX_PX / len; }
    return len >= 0.05 ? [Math.round(lx * 100) / 100, Math.round(ly * 100) / 100] : null;
  }
  // a frame rendered ahead: its camera is not its orbit's (orbitMatrix: the server's maths in float)
  function renderedAhead(f) {
    const m = orbitMatrix(f.orbit);
    for (let i = 0; i < 16; i++) if (Math.abs(m[i] - f.c2w[i]) > 1e-4 * (i >= 12 ? Math.max(1, f.orbit.dist) : 1)) return true;
    return false;
  }
  function input(o, e) { // e: the event (its timeStamp: when it happened, before any wait for the page)
    const t = e && e.timeStamp > 0 && e.timeStamp <= performance.now() ? e.timeStamp : performance.now();
    if (o.t === "drag") {
      const lead = leadFor(o, t);
      if (lead) o.lead = lead; // (a drag without one: [0, 0])
      leadSent = !!lead;
    }
    o.id = ++inputId; stats.lastInput = inputId; send(o);
    const cam = o.t === "drag" || o.t === "wheel";
    waiting.push({ id: o.id, t: t, cam: cam });
    if (cam) { sent.push({ id: o.id, m: o, t: t }); moved = true; }
  }
  function sendSize() {
    const dpr = Math.min(window.devicePixelRatio || 1, 2);
    const w = Math.max(1, Math.round(canvas.clientWidth * dpr)), h = Math.max(1, Math.round(canvas.clientHeight * dpr));
    canvas.width = w; canvas.height = h;
    asked.w = Math.max(asked.w, w); asked.h = Math.max(asked.h, h);
    moved = true;
    send({ t: "size", w: w, h: h, v: FORMAT, warp: warpOn && !!gl, codecs: video ? video.codecs : undefined });
    mark("sy-size");
  }
  // the first picture's path, as performance marks (once each; tests/browser/first_picture.sh)
  const marked = {};
  function mark(name) { if (!marked[name]) { marked[name] = true; try { performance.mark(name); } catch (e) {} } }
  // the socket: index.html's (window.syEarly: opened before the scripts loaded, its size sent, its
  // messages so far replayed here), else a new one; the size goes at once (JPEG), again with the
  // video codecs once video.js knows them (a same size: the server renders nothing new for it)
  function connect() {
    const pre = window.syEarly;
    if (pre && !pre.taken && !pre.closed) {
      pre.taken = true;
      ws = pre.ws;
    } else {
      mark("sy-connect");
      ws = new WebSocket(wsUrl, "sy-view");
      ws.binaryType = "arraybuffer";
    }
    ws.onopen = function () {
      mark("sy-open");
      stats.connected = true; lastSeq = -1; // a restarted server counts from 1 again
      asked.w = asked.h = 0;
      hud.textContent = gl ? "connected" : "connected (no WebGL2: server frames only)";
      if (video) { video.reset(); video.askKeyframe = function () { send({ t: "keyframe" }); }; }
      sendSize();
      if (video) video.ready.then(function () { if (video.codecs.length) sendSize(); });
    };
    ws.onclose = function (e) {
      stats.connected = false;
      hud.textContent = "disconnected (" + e.code + (e.reason ? ": " + e.reason : "") + "), retrying...";
      setTimeout(connect, 2000);
    };
    ws.onmessage = onMessage;
    if (ws.readyState === 1) ws.onopen();
    if (ws === (pre && pre.ws)) for (const m of pre.queue.splice(0)) onMessage(m);
  }
  function onMessage(e) {
    if (typeof e.data === "string") {
      try {
        const m = JSON.parse(e.data);
        if (m.t === "hello") stats.backends = m.backends, lastHello = m;
        if (m.t === "status") { stats.filter = m.filter; if (m.error) hud.textContent = m.error; }
        if (pageLoading) early.push(m); // for the scripts still to come
        for (const f of listeners) try { f(m); } catch (err) { console.error(err); }
      } catch (err) {}
      return;
    }
    mark("sy-frame-received");
    if (video) video.feed(e.data); // every video frame is decoded, in order, shown or not
    const src = depthSource(e.data);
    if (decoding) pending = { buf: e.data, src: src }; else show(e.data, src);
  }
  // mouse and touch: one pointer drags (left: orbit, right or shift: pan), the wheel zooms
  let drag = null;
  canvas.addEventListener("pointerdown", function (e) {
    if (e.pointerType === "touch") return; // touch.js: one finger orbits, two pan and pinch
    canvas.setPointerCapture(e.pointerId); canvas.focus();
    drag = { x: e.clientX, y: e.clientY, b: (e.button === 2 || e.shiftKey) ? 2 : 0 };
  });
  canvas.addEventListener("pointermove", function (e) {
    if (!drag) return;
    const dx = e.clientX - drag.x, dy = e.clientY - drag.y;
    drag.x = e.clientX; drag.y = e.clientY;
    if (dx || dy) input({ t: "drag", dx: dx, dy: dy, b: drag.b }, e);
  });
  function end() { drag = null; }
  canvas.addEventListener("pointerup", end);
  canvas.addEventListener("pointercancel", end);
  canvas.addEventListener("contextmenu", function (e) { e.preventDefault(); });
  canvas.addEventListener("wheel", function (e) {
    e.preventDefault();
    input({ t: "wheel", steps: e.deltaY < 0 ? 1 : -1 }, e);
  }, { passive: false });
  window.addEventListener("keydown", function (e) {
    if (e.target && /^(INPUT|SELECT|TEXTAREA)$/.test(e.target.tagName)) return; // typing in the panel
    if (e.ctrlKey || e.altKey || e.metaKey) return; // the browser's keys (Ctrl+R, Ctrl+1..9), views.js's
    const k = e.key.length === 1 ? e.key.toLowerCase() : "";
    if (/^[1-9f\[\]r]$/.test(k)) input({ t: "key", k: k }, e);
  });
  let resizeTimer = 0;
  window.addEventListener("resize", function () { clearTimeout(resizeTimer); resizeTimer = setTimeout(sendSize, 100); });
  connect();
})();
