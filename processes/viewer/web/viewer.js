// The operator's page of traverse-viewer: draws what the viewer streams over its WebSocket (the
// frames are described in processes/viewer/frames.hpp) with three.js. Each preview profile arrives
// once, in the base frame, with the pose it is drawn at; a loop closure sends new poses only, and
// the page moves the profile's points. A point's colour is the accuracy level of the key pose
// nearest in time to its profile (as the mapper's exports colour it), recoloured whenever the
// annotator republishes levels. window.viewerState holds what the page shows, for tests and for
// a person at the browser's console.
import * as THREE from 'three';
import { OrbitControls } from 'three/addons/controls/OrbitControls.js';
import { Voxels } from './voxels.js';

// Colours as the legend gives them (sRGB bytes), drawn as they are: no colour-space conversion,
// so a legend colour is the colour on the screen.
THREE.ColorManagement.enabled = false;

const GREY = [0.5, 0.5, 0.5];
const state = {
  connected: false, frames: 0, bytes: 0, resets: 0, points: 0, profiles: 0, moves: 0,
  legend: null, annotations: 0, levelCounts: {}, trajectoryPoses: 0, pose: null, guidance: null,
  processes: [], bottom: null, lastFrameAt: 0, voxels: 0, voxelLevelCounts: {}, draws: 0,
};
window.viewerState = state;

// --- drawing ---------------------------------------------------------------------------------
const canvas = document.getElementById('view');
const renderer = new THREE.WebGLRenderer({ canvas, antialias: false });
renderer.outputColorSpace = THREE.LinearSRGBColorSpace;
renderer.setPixelRatio(window.devicePixelRatio);
const scene = new THREE.Scene();
scene.background = new THREE.Color(0x1b1e23);

const topCamera = new THREE.OrthographicCamera(-10, 10, 10, -10, -1000, 1000);
topCamera.position.set(0, 0, 100);
const perspective = new THREE.PerspectiveCamera(55, 1, 0.05, 5000);
perspective.up.set(0, 0, 1);
perspective.position.set(-12, -12, 14);
let camera = topCamera;
let controls = null;
let topHalfHeight = 12;  // [m] half the height the top view shows

function makeControls() {
  if (controls) controls.dispose();
  controls = new OrbitControls(camera, renderer.domElement);
  controls.screenSpacePanning = true;
  controls.enableRotate = camera !== topCamera;
  // Drawn at once while the operator turns or moves the view; a change the feed makes (following
  // the cart) waits for the feed's next redraw.
  controls.addEventListener('change', () => { if (interacting) viewDirty = true; else dirty = true; });
  controls.addEventListener('start', () => {
    interacting = true;
    document.getElementById('follow').checked = false;
  });
  controls.addEventListener('end', () => { interacting = false; });
}

function resize() {
  const w = canvas.clientWidth, h = canvas.clientHeight;
  renderer.setSize(w, h, false);
  const a = w / Math.max(h, 1);
  topCamera.left = -topHalfHeight * a;
  topCamera.right = topHalfHeight * a;
  topCamera.top = topHalfHeight;
  topCamera.bottom = -topHalfHeight;
  topCamera.updateProjectionMatrix();
  perspective.aspect = a;
  perspective.updateProjectionMatrix();
  viewDirty = true;
}

// The cloud: one buffer of positions and colours, each profile a run in it.
class Cloud {
  constructor() {
    this.capacity = 0;
    this.count = 0;
    this.geometry = new THREE.BufferGeometry();
    this.material = new THREE.PointsMaterial({ size: 2, sizeAttenuation: false, vertexColors: true });
    this.object = new THREE.Points(this.geometry, this.material);
    this.object.frustumCulled = false;
    this.profiles = new Map();  // index -> {utime, offset, n, base, x, y, theta, level}
    this.version = 0;  // +1 whenever a point moves or changes colour (the voxels follow)
    this.grow(1 << 16);
  }
  grow(capacity) {
    const positions = new Float32Array(capacity * 3), colours = new Float32Array(capacity * 3);
    if (this.positions) {
      positions.set(this.positions.subarray(0, this.count * 3));
      colours.set(this.colours.subarray(0, this.count * 3));
    }
    this.positions = positions;
    this.colours = colours;
    this.capacity = capacity;
    this.geometry.dispose();
    this.geometry.setAttribute('position', new THREE.BufferAttribute(positions, 3));
    this.geometry.setAttribute('color', new THREE.BufferAttribute(colours, 3));
    this.geometry.setDrawRange(0, this.count);
  }
  clear() {
    ++this.version;
    state.levelCounts = {};
    this.profiles.clear();
    this.count = 0;
    this.geometry.setDrawRange(0, 0);
  }
  add(index, utime, x, y, theta, base) {
    const n = base.length / 3;
    if (this.profiles.has(index)) return;  // sent again whole after a reset only
    if (this.count + n > this.capacity) this.grow(Math.max(this.capacity * 2, this.count + n));
    const p = { utime, offset: this.count, n, base, x, y, theta, level: -2 };
    this.profiles.set(index, p);
    this.count += n;
    this.place(p);
    this.paint(p, levelAt(utime));
    state.levelCounts[levelName(p.level)] = (state.levelCounts[levelName(p.level)] || 0) + n;
    this.geometry.setDrawRange(0, this.count);
  }
  move(index, x, y, theta) {
    const p = this.profiles.get(index);
    if (!p) return;
    p.x = x; p.y = y; p.theta = theta;
    this.place(p);
  }
  // p_map = R(theta) p_base + (x, y); the base points are in millimetres.
  place(p) {
    const c = Math.cos(p.theta), s = Math.sin(p.theta), out = this.positions, b = p.base;
    for (let i = 0, o = p.offset * 3; i < b.length; i += 3, o += 3) {
      const bx = b[i] / 1000, by = b[i + 1] / 1000;
      out[o] = p.x + c * bx - s * by;
      out[o + 1] = p.y + s * bx + c * by;
      out[o + 2] = b[i + 2] / 1000;
    }
    const attribute = this.geometry.attributes.position;
    attribute.addUpdateRange(p.offset * 3, p.n * 3);
    attribute.needsUpdate = true;
    ++this.version;
    dirty = true;
  }
  paint(p, level) {
    if (p.level === level) return;
    p.level = level;
    const rgb = colourOf(level), out = this.colours;
    for (let i = 0, o = p.offset * 3; i < p.n; ++i, o += 3) {
      out[o] = rgb[0]; out[o + 1] = rgb[1]; out[o + 2] = rgb[2];
    }
    const attribute = this.geometry.attributes.color;
    attribute.addUpdateRange(p.offset * 3, p.n * 3);
    attribute.needsUpdate = true;
    ++this.version;
    dirty = true;
  }
  recolour() {
    const counts = {};
    for (const p of this.profiles.values()) {
      this.paint(p, levelAt(p.utime));
      counts[levelName(p.level)] = (counts[levelName(p.level)] || 0) + p.n;
    }
    state.levelCounts = counts;
  }
}
const cloud = new Cloud();
scene.add(cloud.object);

// Annotations: by id, and sorted by time for the colour of a profile.
const annotations = new Map();
let keyUtimes = new Float64Array(0), keyLevels = new Int16Array(0);
let annotationsChanged = false;

function rebuildKeyIndex() {
  const keys = [...annotations.values()].sort((a, b) => a.utime - b.utime);
  keyUtimes = Float64Array.from(keys, (k) => k.utime);
  keyLevels = Int16Array.from(keys, (k) => k.level);
}

// Level of the key pose nearest in time; -1 before any annotation.
function levelAt(utime) {
  const n = keyUtimes.length;
  if (n === 0) return -1;
  let lo = 0, hi = n;
  while (lo < hi) {
    const mid = (lo + hi) >> 1;
    if (keyUtimes[mid] < utime) lo = mid + 1; else hi = mid;
  }
  if (lo === n) return keyLevels[n - 1];
  if (lo > 0 && utime - keyUtimes[lo - 1] <= keyUtimes[lo] - utime) return keyLevels[lo - 1];
  return keyLevels[lo];
}

function levelName(level) {
  return level >= 0 && state.legend ? state.legend.levels[level].name : 'none';
}

function colourOf(level) {
  if (level < 0 || !state.legend) return GREY;
  const rgb = state.legend.levels[level].rgb;
  return [rgb[0] / 255, rgb[1] / 255, rgb[2] / 255];
}

// The same points as coloured voxels, drawn instead of the points when "voxels" is ticked.
const voxels = new Voxels(scene, cloud, colourOf);
let voxelsBuiltFor = -1;  // cloud.version they show

// Key poses, drawn larger than the cloud's points in their level's colour.
const keyPoints = new THREE.Points(new THREE.BufferGeometry(),
  new THREE.PointsMaterial({ size: 6, sizeAttenuation: false, vertexColors: true }));
keyPoints.frustumCulled = false;
scene.add(keyPoints);

function redrawKeys() {
  const keys = [...annotations.values()];
  const pos = new Float32Array(keys.length * 3), col = new Float32Array(keys.length * 3);
  keys.forEach((k, i) => {
    pos.set([k.x, k.y, 0.02], i * 3);
    col.set(colourOf(k.level), i * 3);
  });
  keyPoints.geometry.dispose();
  keyPoints.geometry = new THREE.BufferGeometry();
  keyPoints.geometry.setAttribute('position', new THREE.BufferAttribute(pos, 3));
  keyPoints.geometry.setAttribute('color', new THREE.BufferAttribute(col, 3));
}

// The corrected trajectory: one polyline per densifier segment.
const segments = new Map();
let trajectoryChanged = false;
const trajectory = new THREE.LineSegments(new THREE.BufferGeometry(),
  new THREE.LineBasicMaterial({ color: 0x5fb4ff }));
trajectory.frustumCulled = false;
scene.add(trajectory);

function redrawTrajectory() {
  const v = [];
  let poses = 0;
  for (const s of segments.values()) {
    poses += s.xy.length / 2;
    for (let i = 2; i < s.xy.length; i += 2) v.push(s.xy[i - 2], s.xy[i - 1], 0.01, s.xy[i], s.xy[i + 1], 0.01);
  }
  state.trajectoryPoses = poses;
  trajectory.geometry.dispose();
  trajectory.geometry = new THREE.BufferGeometry();
  trajectory.geometry.setAttribute('position', new THREE.Float32BufferAttribute(v, 3));
}

// The cart: an arrow at the current pose.
const cart = new THREE.Mesh(new THREE.ConeGeometry(0.25, 0.8, 16),
  new THREE.MeshBasicMaterial({ color: 0xffffff }));
cart.geometry.rotateZ(-Math.PI / 2);  // along +x
cart.visible = false;
scene.add(cart);

// Guidance: rings at the nearest poor region and at the loop-closure target, lines to them.
function ring(colour) {
  const m = new THREE.Mesh(new THREE.RingGeometry(0.7, 0.95, 40),
    new THREE.MeshBasicMaterial({ color: colour, side: THREE.DoubleSide }));
  m.visible = false;
  scene.add(m);
  return m;
}
const poorRing = ring(0xff4040), loopRing = ring(0x40ff70);
const guideLines = new THREE.LineSegments(new THREE.BufferGeometry(),
  new THREE.LineDashedMaterial({ color: 0xffffff, dashSize: 0.4, gapSize: 0.3 }));
scene.add(guideLines);

// --- the feed ----------------------------------------------------------------------------------
// Two kinds of redraw. What the operator does (turning the view, a toggle, a resize) is drawn at
// the next animation frame. What the feed changes (new points, colours, the cart, the trajectory)
// is drawn at most once per redraw period (the viewer's redraw_period_s, sent in its "view"
// frame): without a graphics processor the browser draws in software, and drawing every update
// (five a second) took half a core of the graph's own 2-core machine (viewer_config.hpp).
let dirty = true;      // the feed changed something
let viewDirty = true;  // the operator changed the view
let interacting = false;
let redrawPeriodMs = 500;
let lastFeedDraw = -Infinity;

function onText(msg) {
  switch (msg.type) {
    case 'reset':
      ++state.resets;
      cloud.clear();
      annotations.clear();
      segments.clear();
      annotationsChanged = trajectoryChanged = true;
      state.points = state.profiles = 0;
      break;
    case 'legend':
      state.legend = msg;
      showLegend();
      annotationsChanged = true;
      break;
    case 'annotations':
      for (const [id, utime, x, y, level, bound, local] of msg.keys) {
        annotations.set(id, { id, utime, x, y, level, bound, local });
      }
      annotationsChanged = true;
      break;
    case 'trajectory':
      for (const s of msg.segments) segments.set(s.id, s);
      trajectoryChanged = true;
      break;
    case 'pose':
      state.pose = msg;
      cart.position.set(msg.x, msg.y, 0.3);
      cart.rotation.z = msg.theta;
      cart.visible = true;
      follow();
      break;
    case 'status':
      state.processes = msg.processes;
      showStatus();
      break;
    case 'guidance':
      state.guidance = msg;
      showGuidance();
      break;
    case 'view':
      voxels.setSize(msg.voxel_m);
      if (msg.redraw_period_s !== undefined) redrawPeriodMs = 1000 * msg.redraw_period_s;
      break;
  }
  dirty = true;
}

function onBinary(buffer) {
  const d = new DataView(buffer);
  const kind = d.getUint8(0), count = d.getUint32(1, true);
  let o = 5;
  for (let c = 0; c < count; ++c) {
    if (kind === 1) {
      const utime = d.getFloat64(o, true), index = d.getUint32(o + 8, true);
      const x = d.getFloat32(o + 12, true), y = d.getFloat32(o + 16, true);
      const theta = d.getFloat32(o + 20, true), n = d.getUint32(o + 24, true);
      o += 28;
      const base = new Int16Array(buffer.slice(o, o + n * 6));
      o += n * 6;
      cloud.add(index, utime, x, y, theta, base);
      state.points += n;
      ++state.profiles;
    } else if (kind === 2) {
      cloud.move(d.getUint32(o, true), d.getFloat32(o + 4, true), d.getFloat32(o + 8, true),
        d.getFloat32(o + 12, true));
      o += 16;
      ++state.moves;
    }
  }
}

function connect() {
  const ws = new WebSocket(`${location.protocol === 'https:' ? 'wss' : 'ws'}://${location.host}/ws`);
  ws.binaryType = 'arraybuffer';
  ws.onopen = () => { state.connected = true; showConnection(); };
  ws.onclose = () => {
    state.connected = false;
    showConnection();
    setTimeout(connect, 2000);
  };
  ws.onmessage = (e) => {
    ++state.frames;
    state.lastFrameAt = Date.now();
    if (typeof e.data === 'string') {
      state.bytes += e.data.length;
      onText(JSON.parse(e.data));
    } else {
      state.bytes += e.data.byteLength;
      onBinary(e.data);
    }
  };
}

// --- the panel ---------------------------------------------------------------------------------
const $ = (id) => document.getElementById(id);

function showConnection() {
  $('connection').textContent = state.connected ? 'live' : 'disconnected';
  $('connection').className = state.connected ? 'good' : 'bad';
}

function range(l) {
  const mm = (m) => `${+(m * 1000).toFixed(1)} mm`;
  return l.max_m === null ? `over ${mm(l.min_m)}` : `${mm(l.min_m)} to ${mm(l.max_m)}`;
}

function showLegend() {
  const l = state.legend;
  $('standard').textContent = `(${l.standard})`;
  $('legend').innerHTML = l.levels.map((v, i) =>
    `<li><span class="swatch" style="background: rgb(${v.rgb.join(',')})"></span>` +
    `<b>${v.name}</b> ${range(v)}${v.accepted ? '' : ' (not accepted)'}` +
    `<span class="count" id="level-${i}"></span></li>`).join('');
  $('legend-note').textContent = `95 % bound (${l.bound_method}), ${l.coloured_by}: ` +
    `green at ${l.levels[l.best_level].name} or better, red at ${l.levels[l.worst_level].name} or worse`;
  const select = $('bottom');
  const keep = state.bottom ?? l.worst_level;
  select.innerHTML = l.levels.map((v, i) => `<option value="${i}">${v.name}</option>`).join('');
  select.value = String(Math.min(keep, l.levels.length - 1));
  state.bottom = +select.value;
}

function showCounts() {
  $('counts').textContent = `${state.points.toLocaleString()} points of ${state.profiles.toLocaleString()} profiles (decimated for the screen), ` +
    `${annotations.size} key poses, ${state.trajectoryPoses} trajectory poses`;
  if (!state.legend) return;
  state.legend.levels.forEach((v, i) => {
    const e = $(`level-${i}`);
    if (e) e.textContent = state.levelCounts[v.name] ? `${state.levelCounts[v.name].toLocaleString()} pts` : '';
  });
}

function showGuidance() {
  const g = state.guidance, l = state.legend;
  if (!g || !l || !state.pose) return;
  const b = state.bottom ?? l.worst_level;
  const poor = g.below[b];
  const lines = [];
  const from = [state.pose.x, state.pose.y, 0.05];
  if (poor) {
    $('guide-poor').innerHTML = `<span class="bad">Nearest region worse than ${l.levels[b].name}:</span> ` +
      `${poor.distance_m.toFixed(1)} m (key poses ${poor.first_id} to ${poor.last_id}, ${poor.keys} of them)`;
    poorRing.position.set(poor.x, poor.y, 0.04);
    lines.push(...from, poor.x, poor.y, 0.05);
  } else {
    $('guide-poor').textContent = `No key pose worse than ${l.levels[b].name}.`;
  }
  poorRing.visible = !!poor;
  const t = g.loop_target;
  if (t) {
    $('guide-loop').innerHTML = `<span class="good">Nearest well-localised area to close a loop with:</span> ` +
      `${t.distance_m.toFixed(1)} m (key pose ${t.id})`;
    loopRing.position.set(t.x, t.y, 0.04);
    lines.push(...from, t.x, t.y, 0.05);
  } else {
    $('guide-loop').textContent = 'No well-localised area old enough to close a loop with yet.';
  }
  loopRing.visible = !!t;
  guideLines.geometry.dispose();
  guideLines.geometry = new THREE.BufferGeometry();
  guideLines.geometry.setAttribute('position', new THREE.Float32BufferAttribute(lines, 3));
  guideLines.computeLineDistances();
}

function showStatus() {
  const n = (v) => (v ? `${v}` : '0');
  $('status').querySelector('tbody').innerHTML = state.processes.map((p) => {
    const bad = p.stale || p.missed || p.dropped || p.rejected || p.errors;
    const st = p.stale ? `no status for ${p.age_s} s` : p.state;
    return `<tr class="${bad ? 'bad' : ''}"><td>${p.process}</td><td>${st}</td><td>${p.in_hz}</td>` +
      `<td>${p.out_hz}</td><td>${p.cpu_percent}</td><td>${n(p.missed)}</td><td>${n(p.dropped)}</td>` +
      `<td>${n(p.rejected)}</td><td>${n(p.errors)}</td></tr>`;
  }).join('');
}

// Follow the cart: the view keeps its offset to the cart as the cart moves.
function follow() {
  if (!$('follow').checked || !state.pose) return;
  const target = new THREE.Vector3(state.pose.x, state.pose.y, camera === topCamera ? 0 : 0.5);
  const offset = camera.position.clone().sub(controls.target);
  controls.target.copy(target);
  camera.position.copy(target).add(offset);
  controls.update();
}

function setView(mode) {
  const target = controls ? controls.target.clone() : new THREE.Vector3();
  camera = mode === 'top' ? topCamera : perspective;
  if (mode === 'top') {
    topCamera.position.set(target.x, target.y, 100);
    topCamera.up.set(0, 1, 0);
  } else {
    perspective.position.set(target.x - 10, target.y - 10, target.z + 12);
  }
  makeControls();
  controls.target.copy(target);
  controls.update();
  $('view-top').className = mode === 'top' ? 'on' : '';
  $('view-3d').className = mode === 'top' ? '' : 'on';
  resize();
}

// Shows the whole cloud and trajectory from above (and stops following the cart).
function fit() {
  const box = new THREE.Box3(), v = new THREE.Vector3();
  for (let i = 0; i < cloud.count * 3; i += 3) {
    box.expandByPoint(v.set(cloud.positions[i], cloud.positions[i + 1], 0));
  }
  for (const s of segments.values()) {
    for (let i = 0; i < s.xy.length; i += 2) box.expandByPoint(v.set(s.xy[i], s.xy[i + 1], 0));
  }
  // Key poses too: a viewer fed the pose graph alone (a replayed graph log) has nothing else.
  for (const k of annotations.values()) box.expandByPoint(v.set(k.x, k.y, 0));
  if (box.isEmpty()) return;
  $('follow').checked = false;
  setView('top');
  const centre = box.getCenter(new THREE.Vector3()), size = box.getSize(new THREE.Vector3());
  const a = canvas.clientWidth / Math.max(canvas.clientHeight, 1);
  topHalfHeight = Math.max(size.y / 2, size.x / 2 / a) * 1.05 + 0.5;
  controls.target.set(centre.x, centre.y, 0);
  topCamera.position.set(centre.x, centre.y, 100);
  topCamera.zoom = 1;
  controls.update();
  resize();
}

$('view-top').onclick = () => setView('top');
$('fit').onclick = fit;
$('view-3d').onclick = () => setView('3d');
$('follow').onchange = () => follow();
$('voxels').onchange = () => {
  const on = $('voxels').checked;
  voxels.show(on);
  cloud.object.visible = !on;
  viewDirty = true;
};
$('bottom').onchange = () => { state.bottom = +$('bottom').value; showGuidance(); };
window.addEventListener('resize', resize);

function frame(now) {
  requestAnimationFrame(frame);
  const feedDue = dirty && now - lastFeedDraw >= redrawPeriodMs;
  if (feedDue) {
    dirty = false;
    lastFeedDraw = now;
    if (annotationsChanged) {
      annotationsChanged = false;
      rebuildKeyIndex();
      cloud.recolour();
      redrawKeys();
      state.annotations = annotations.size;
    }
    if (trajectoryChanged) {
      trajectoryChanged = false;
      redrawTrajectory();
    }
    if (cloud.version !== voxelsBuiltFor) voxels.stale = true;
  }
  const voxelsBuilt = voxels.update(now);
  if (voxelsBuilt) {
    voxelsBuiltFor = cloud.version;
    state.voxels = voxels.count;
    state.voxelLevelCounts = Object.fromEntries(Object.entries(voxels.levelCounts)
      .map(([level, n]) => [levelName(+level), n]));
  }
  if (feedDue || viewDirty || voxelsBuilt) {
    viewDirty = false;
    ++state.draws;
    showCounts();
    renderer.render(scene, camera);
  }
}

// Where each key pose is drawn now: its level and its pixel in the drawing buffer (origin at the
// bottom left, as gl.readPixels reads it).
function keysOnScreen() {
  const w = renderer.getContext().drawingBufferWidth, h = renderer.getContext().drawingBufferHeight;
  const v = new THREE.Vector3();
  return [...annotations.values()].map((k) => {
    v.set(k.x, k.y, 0.02).project(camera);
    return { id: k.id, level: k.level, sx: Math.round((v.x + 1) / 2 * w - 0.5),
      sy: Math.round((v.y + 1) / 2 * h - 0.5) };
  });
}

// The whole view drawn now, as RGBA bytes of the drawing buffer (rows from the bottom).
function pixels() {
  renderer.render(scene, camera);
  const gl = renderer.getContext();
  const w = gl.drawingBufferWidth, h = gl.drawingBufferHeight, px = new Uint8Array(w * h * 4);
  gl.readPixels(0, 0, w, h, gl.RGBA, gl.UNSIGNED_BYTE, px);
  return { w, h, px };
}

// The whole map from above, key poses hidden: pixels per legend colour ("r,g,b" -> count; levels
// may share a colour), for tests and for a person at the console.
function legendPixels() {
  const out = {};
  if (!state.legend) return out;
  fit();
  keyPoints.visible = false;
  const { px } = pixels();
  keyPoints.visible = true;
  renderer.render(scene, camera);
  for (const l of state.legend.levels) {
    const key = l.rgb.join(',');
    if (key in out) continue;
    let n = 0;
    for (let i = 0; i < px.length; i += 4) {
      if (Math.abs(px[i] - l.rgb[0]) <= 2 && Math.abs(px[i + 1] - l.rgb[1]) <= 2 &&
          Math.abs(px[i + 2] - l.rgb[2]) <= 2) ++n;
    }
    out[key] = n;
  }
  return out;
}

// For tests: draw now (the pixels are then read in the same task) and the objects drawn.
window.viewer = { renderer, scene, render: () => renderer.render(scene, camera), cloud, keyPoints, fit,
  keysOnScreen, pixels, legendPixels, voxels };

setView('top');
connect();
requestAnimationFrame(frame);
