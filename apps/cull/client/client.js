// client.js — the culled WebGL client (docs/CULLING.md). It asks POST /api/cull which objects
// cover the most pixels of its current view within a triangle budget, draws only those, fetches
// each object once (GET /api/object/ID, GLB) and keeps it cached, and re-asks (debounced) whenever
// the view changes. The page URL's ?token= is passed on to every request; ?budget=T sets the
// budget (default 2000000 triangles).
//
// An animated scene has a timeline (play / pause, a slider, space): the page joins the server's
// WebSocket (/ws, without a size: it is sent the hello and the "clock" messages, no frames) and
// steers the one scene clock every page shares with "time" and "play" (docs/WEB.md, "The
// timeline"); after each clock message, and every display frame while the clock plays, it asks
// GET /api/pose for the world matrices of the objects that moved and sets them on the loaded
// objects' nodes (rigid motion: skins and morph weights are not carried).
//
// For tests (a browser driven over the DevTools protocol) the state is window.syClient:
//   requested: ids of the last answer (what should be drawn), loaded: ids fetched so far,
//   visible: ids drawn now, triangles: triangles drawn now, fetched_triangles, bytes (GLB bytes),
//   total_objects, total_triangles, queries (answers received), fetches, errors (messages),
//   idle (true when no query or fetch is outstanding and the drawing matches the last answer),
//   lastAnswer (the parsed JSON), cameraJSON() (the view as sent), setView(position, target)
//   (moves the camera and re-asks), cull() (re-asks now), timeline() (shown, time, start, end,
//   playing, poses applied, poseTime: the paused clock's time the last pose was asked at),
//   setTime(seconds), play(on), look (/api/view's "look": the server's environment, intensity and
//   exposure), environment (the one lighting the page: studio, texture, none).
import * as THREE from 'three';
import { GLTFLoader } from 'three/addons/loaders/GLTFLoader.js';
import { OrbitControls } from 'three/addons/controls/OrbitControls.js';
import { MeshoptDecoder } from 'three/addons/libs/meshopt_decoder.module.js';

const params = new URLSearchParams(window.location.search);
const token = params.get('token');
const budgetParam = Number(params.get('budget') ?? 2000000);
const budget = Number.isFinite(budgetParam) && budgetParam >= 0 ? Math.min(Math.floor(budgetParam), 2 ** 40) : 2000000;
const DEBOUNCE_MS = 250;
const MAX_PARALLEL_FETCHES = 6;

function withToken(url) {
  return token ? `${url}${url.includes('?') ? '&' : '?'}token=${encodeURIComponent(token)}` : url;
}

const canvas = document.getElementById('view');
const overlay = document.getElementById('overlay');
const renderer = new THREE.WebGLRenderer({ canvas, antialias: true });
renderer.setPixelRatio(window.devicePixelRatio || 1);
// The look of every back-end (docs/BACKENDS.md, one scene, one look): the objects come without
// lights, so they are lit as the server's view is, by the environment GET /api/view's "look" names
// (the library's studio, sy_look_studio_pixels, or the world's float texture: GET /api/environment,
// prefiltered by three's PMREM) at its intensity, over the default black background; the display
// chain is the library's (sy_post.c): exposure, its ACES curve (not three's ACESFilmic, a
// different fit), sRGB.
THREE.ShaderChunk.tonemapping_pars_fragment = THREE.ShaderChunk.tonemapping_pars_fragment.replace(
  'vec3 CustomToneMapping( vec3 color ) { return color; }',
  'vec3 CustomToneMapping( vec3 color ) {\n\tcolor *= toneMappingExposure;\n' +
  '\treturn saturate( ( color * ( 2.51 * color + 0.03 ) ) / ( color * ( 2.43 * color + 0.59 ) + 0.14 ) );\n}');
renderer.toneMapping = THREE.CustomToneMapping;
const scene = new THREE.Scene();
scene.background = new THREE.Color(0x000000);

// The look's environment image (float32 RGB, row 0 up, sy_look.h's lat-long: u = 0.5 + atan2(x, -z)
// / 2 pi) as three's equirect texture (row 0 down, u = 0.5 + atan2(z, x) / 2 pi: a quarter turn).
function equirect(rgb, w, h) {
  const data = new Float32Array(w * h * 4), shift = Math.round(w / 4);
  for (let j = 0; j < h; j++) {
    for (let i = 0; i < w; i++) {
      const s = 3 * ((h - 1 - j) * w + (i + shift) % w), d = 4 * (j * w + i);
      data[d] = rgb[s]; data[d + 1] = rgb[s + 1]; data[d + 2] = rgb[s + 2]; data[d + 3] = 1;
    }
  }
  const t = new THREE.DataTexture(data, w, h, THREE.RGBAFormat, THREE.FloatType);
  t.mapping = THREE.EquirectangularReflectionMapping;
  t.magFilter = t.minFilter = THREE.LinearFilter;
  t.needsUpdate = true;
  return t;
}

async function applyLook(look) {
  state.look = look;
  renderer.toneMappingExposure = Math.pow(2, look.exposure || 0);
  scene.environment = null;
  if (look.environment === 'none' || !(look.width > 0 && look.height > 0)) return;
  const response = await fetch(withToken('/api/environment'));
  if (!response.ok) throw new Error(`environment: ${response.status} ${await response.text()}`);
  const rgb = new Float32Array(await response.arrayBuffer());
  if (rgb.length !== look.width * look.height * 3) throw new Error(`environment: ${rgb.length} floats, not ${look.width} x ${look.height} x 3`);
  const tex = equirect(rgb, look.width, look.height);
  scene.environment = new THREE.PMREMGenerator(renderer).fromEquirectangular(tex).texture;
  tex.dispose();
  scene.environmentIntensity = look.intensity;
  state.environment = look.environment;
}
const camera = new THREE.PerspectiveCamera(60, 1, 0.05, 1e6);
camera.position.set(0, 0, 10);
const controls = new OrbitControls(camera, canvas);
const loader = new GLTFLoader();
loader.setMeshoptDecoder(MeshoptDecoder);

const objects = new Map(); // id -> THREE.Object3D (loaded)
const pending = new Map(); // id -> Promise (being fetched)
const state = {
  requested: [], loaded: [], visible: [], triangles: 0, fetched_triangles: 0, bytes: 0,
  total_objects: 0, total_triangles: 0, queries: 0, fetches: 0, errors: [], idle: false, lastAnswer: null,
  frames: 0, renderPending: false, look: null, environment: 'none',
};
const triangleCount = new Map(); // id -> triangles (from the answers)
let framed = false;
let inFlight = false;
let again = false;
let timer = null;

// Rendering on demand (three.js's own advice for static scenes): one frame after anything drawn
// changed (the camera, objects loaded or shown, the canvas size) and none while the view rests, so
// a resting page costs no CPU or GPU. syClient.renderPending: a frame is queued, not drawn yet.
function requestRender() {
  if (state.renderPending) return;
  state.renderPending = true;
  requestAnimationFrame(() => {
    renderer.render(scene, camera);
    state.frames++;
    state.renderPending = false;
  });
}

function cameraJSON() {
  const size = renderer.getSize(new THREE.Vector2());
  camera.updateMatrixWorld();
  const p = camera.position, q = camera.quaternion;
  return {
    position: [p.x, p.y, p.z], orientation: [q.x, q.y, q.z, q.w], fov: camera.fov,
    width: Math.max(1, Math.min(16384, Math.round(size.x))), height: Math.max(1, Math.min(16384, Math.round(size.y))),
    budget,
  };
}

function showError(message) {
  state.errors.push(message);
  if (state.errors.length > 20) state.errors.shift();
  updateOverlay();
}

function updateOverlay() {
  const lines = [
    `objects  ${state.visible.length} drawn, ${state.loaded.length} loaded of ${state.total_objects}`,
    `triangles ${state.triangles.toLocaleString()} drawn of ${state.total_triangles.toLocaleString()}` +
      ` (budget ${budget.toLocaleString()})`,
    `fetched  ${state.fetched_triangles.toLocaleString()} triangles, ${(state.bytes / 1e6).toFixed(2)} MB`,
  ];
  overlay.textContent = lines.join('\n');
  if (state.errors.length) {
    const e = document.createElement('div');
    e.className = 'error';
    e.textContent = state.errors[state.errors.length - 1];
    overlay.appendChild(e);
  }
}

// Shows exactly the requested objects that are loaded.
function applyVisibility() {
  const want = new Set(state.requested);
  let tris = 0;
  const vis = [];
  for (const [id, obj] of objects) {
    obj.visible = want.has(id);
    if (obj.visible) {
      vis.push(id);
      tris += triangleCount.get(id) || 0;
    }
  }
  state.visible = vis;
  state.triangles = tris;
  state.idle = !inFlight && !again && timer === null && pending.size === 0 && vis.length === want.size;
  updateOverlay();
  requestRender();
}

async function fetchObject(id) {
  const response = await fetch(withToken(`/api/object/${id}`));
  if (!response.ok) throw new Error(`object ${id}: ${response.status} ${await response.text()}`);
  const data = await response.arrayBuffer();
  state.bytes += data.byteLength;
  state.fetches++;
  const gltf = await loader.parseAsync(data, '');
  gltf.scene.traverse((o) => { o.matrixAutoUpdate = false; o.updateMatrix(); });
  gltf.scene.updateMatrixWorld(true);
  return gltf.scene;
}

// Fetches the requested objects not loaded yet, a few at a time.
async function fetchMissing() {
  const queue = state.requested.filter((id) => !objects.has(id) && !pending.has(id));
  const worker = async () => {
    while (queue.length) {
      const id = queue.shift();
      if (objects.has(id) || pending.has(id)) continue; // another fetchMissing took it meanwhile
      const p = fetchObject(id);
      pending.set(id, p);
      try {
        const obj = await p;
        obj.name = `object ${id}`;
        objects.set(id, obj);
        scene.add(obj);
        state.loaded.push(id);
        state.fetched_triangles += triangleCount.get(id) || 0;
      } catch (e) {
        showError(String(e.message || e));
      } finally {
        pending.delete(id);
        applyVisibility();
      }
    }
  };
  await Promise.all(Array.from({ length: MAX_PARALLEL_FETCHES }, worker));
}

// The server's view (GET /api/view): the page starts where every other back-end starts (the scene's
// camera, or the same framing of its bounds), so the first picture matches `sy render`. Without it
// (an older server) the page frames the bounds of the first answer itself.
let serverView = null;

function applyView(v, b) {
  camera.position.set(...v.position);
  camera.quaternion.set(...v.orientation);
  camera.fov = v.fov;
  const min = new THREE.Vector3(...b.min), max = new THREE.Vector3(...b.max);
  const radius = Math.max(1e-3, max.clone().sub(min).length() * 0.5);
  const dist = camera.position.distanceTo(min.clone().add(max).multiplyScalar(0.5)) + radius;
  camera.near = Math.max(1e-3, Math.min(0.05, dist * 1e-4));
  camera.far = dist * 10;
  camera.updateProjectionMatrix();
  controls.target.set(...v.target);
  controls.update();
  requestRender();
}

function frameBounds(b) {
  if (serverView) {
    applyView(serverView, b);
    return;
  }
  const min = new THREE.Vector3(...b.min), max = new THREE.Vector3(...b.max);
  const centre = min.clone().add(max).multiplyScalar(0.5);
  const radius = Math.max(1e-3, max.clone().sub(min).length() * 0.5);
  const dist = radius / Math.tan(THREE.MathUtils.degToRad(camera.fov * 0.5));
  camera.position.copy(centre).add(new THREE.Vector3(0, 0.5, 1).normalize().multiplyScalar(dist));
  camera.near = Math.max(0.01, dist * 1e-4);
  camera.far = dist * 10 + radius * 10;
  camera.updateProjectionMatrix();
  controls.target.copy(centre);
  controls.update();
  requestRender();
}

async function cull() {
  if (inFlight) {
    again = true;
    return;
  }
  inFlight = true;
  state.idle = false;
  try {
    const response = await fetch(withToken('/api/cull'), {
      method: 'POST', headers: { 'Content-Type': 'application/json' }, body: JSON.stringify(cameraJSON()),
    });
    const text = await response.text();
    if (!response.ok) throw new Error(`cull: ${response.status} ${text}`);
    const answer = JSON.parse(text);
    state.lastAnswer = answer;
    state.queries++;
    state.total_objects = answer.total_objects;
    state.total_triangles = answer.total_triangles;
    if (!framed && answer.bounds) { // the first answer tells where the scene is: frame it, ask again
      framed = true;
      frameBounds(answer.bounds);
      again = true;
    } else {
      for (const o of answer.objects) triangleCount.set(o.id, o.triangles);
      state.requested = answer.objects.map((o) => o.id);
    }
  } catch (e) {
    showError(String(e.message || e));
  } finally {
    inFlight = false;
  }
  if (again) {
    again = false;
    cull();
    return;
  }
  applyVisibility();
  await fetchMissing();
  applyVisibility();
}

function scheduleCull() {
  state.idle = false;
  if (timer !== null) clearTimeout(timer);
  timer = setTimeout(() => { timer = null; cull(); }, DEBOUNCE_MS);
}

function resize() {
  const w = canvas.clientWidth, h = canvas.clientHeight;
  renderer.setSize(w, h, false);
  camera.aspect = w / Math.max(1, h);
  camera.updateProjectionMatrix();
  requestRender();
  scheduleCull();
}

controls.addEventListener('change', () => {
  requestRender();
  scheduleCull();
});
window.addEventListener('resize', resize);

// ---- the timeline: the server's scene clock, the moved objects' poses ----
const bar = document.getElementById('timeline');
const playButton = document.getElementById('play');
const scrub = document.getElementById('scrub');
const timeLabel = document.getElementById('time');
const clock = { known: false, time: 0, start: 0, end: 0, playing: false, loop: true, speed: 1, at: 0 };
const poses = { applied: 0, poseTime: null, inFlight: false, again: false, frame: -1 };
let ws = null;

function clockNow() { // the server's time, run on locally while it plays (as the streamed page does)
  if (!clock.playing) return clock.time;
  let t = clock.time + (performance.now() - clock.at) / 1000 * clock.speed;
  const len = clock.end - clock.start;
  if (t > clock.end || t < clock.start) {
    t = clock.loop && len > 0 ? clock.start + ((((t - clock.start) % len) + len) % len) : Math.min(Math.max(t, clock.start), clock.end);
  }
  return t;
}

function showClock() {
  const t = clockNow();
  if (document.activeElement !== scrub) scrub.value = String(t);
  timeLabel.textContent = `${t.toFixed(2)} s / ${(clock.end - clock.start).toFixed(2)} s`;
  playButton.textContent = clock.playing ? '❚❚' : '▶';
}

function applyPose(p) {
  for (const o of p.objects || []) {
    const obj = objects.get(o.id);
    if (!obj) continue; // not loaded: its GLB comes in the pose of its time
    o.matrices.forEach((m, k) => {
      const node = obj.children[k]; // one root node per placement, in the answer's order
      if (node && Array.isArray(m) && m.length === 16) node.matrix.fromArray(m);
    });
    obj.updateMatrixWorld(true);
  }
  poses.applied++;
  poses.frame = p.frame;
  requestRender();
}

async function requestPose() {
  if (poses.inFlight) {
    poses.again = true;
    return;
  }
  poses.inFlight = true;
  const asked = clock.playing ? null : clock.time;
  try {
    const response = await fetch(withToken('/api/pose'));
    const text = await response.text();
    if (!response.ok) throw new Error(`pose: ${response.status} ${text}`);
    applyPose(JSON.parse(text));
    poses.poseTime = asked;
  } catch (e) {
    showError(String(e.message || e));
  } finally {
    poses.inFlight = false;
  }
  if (poses.again || clock.playing) { // playing: the next pose on the next display frame
    poses.again = false;
    requestAnimationFrame(() => { showClock(); requestPose(); });
  } else {
    scheduleCull(); // what covers the view may have changed
  }
}

function sendClock(message) {
  if (ws && ws.readyState === WebSocket.OPEN) ws.send(JSON.stringify(message));
}

function connectClock() {
  const url = new URL('/ws', window.location.href);
  url.protocol = url.protocol === 'https:' ? 'wss:' : 'ws:';
  url.search = token ? `?token=${encodeURIComponent(token)}` : '';
  ws = new WebSocket(url, 'sy-view'); // the server's protocol (docs/WEB.md)
  ws.onmessage = (ev) => {
    if (typeof ev.data !== 'string') return;
    let m;
    try { m = JSON.parse(ev.data); } catch (e) { return; }
    if (m.t !== 'clock') return;
    const was = clock.playing;
    Object.assign(clock, { known: true, time: m.time, start: m.start, end: m.end, playing: !!m.playing, loop: !!m.loop,
                           speed: m.speed, at: performance.now() });
    scrub.min = String(m.start);
    scrub.max = String(m.end);
    scrub.step = String(Math.max((m.end - m.start) / 1000, 1e-4));
    bar.classList.add('shown');
    showClock();
    if (!was || !clock.playing) requestPose(); // the server applied the time before it answers
  };
  ws.onclose = () => { ws = null; };
}

function setTime(t) {
  sendClock({ t: 'time', s: t });
}

function play(on) {
  clock.time = clockNow();
  clock.at = performance.now();
  clock.playing = on;
  sendClock({ t: 'play', on });
  showClock();
  if (on) requestPose();
}

playButton.addEventListener('click', (e) => { e.stopPropagation(); play(!clock.playing); playButton.blur(); });
scrub.addEventListener('input', () => setTime(Number(scrub.value)));
window.addEventListener('keydown', (e) => {
  if (!clock.known || e.key !== ' ' || e.repeat) return;
  e.preventDefault();
  play(!clock.playing);
});

window.syClient = Object.assign(state, {
  cameraJSON,
  cull,
  timeline() {
    return { shown: bar.classList.contains('shown'), time: clockNow(), start: clock.start, end: clock.end, playing: clock.playing,
             poses: poses.applied, poseTime: poses.poseTime, frame: poses.frame };
  },
  setTime,
  play,
  setView(position, target) {
    camera.position.set(...position);
    controls.target.set(...target);
    controls.update();
    framed = true;
    requestRender();
    scheduleCull();
  },
});

requestRender();
try {
  const response = await fetch(withToken('/api/view'));
  if (response.ok) serverView = await response.json();
} catch (e) {
  serverView = null;
}
try {
  // an older server says nothing of its look: the studio would be a guess, so no environment
  if (serverView && serverView.look) await applyLook(serverView.look);
} catch (e) {
  showError(String(e.message || e));
}
resize();
connectClock();
