// The page of `wavg serve`: the shaded mesh with orbit controls, anchors added by clicks
// and dragged along the surface, weight sliders, and the modes of modes.js.

import * as THREE from 'three';
import { OrbitControls } from '/vendor/three/OrbitControls.js';
import { getJson, getMesh } from '/api.js';
import { buildPicker, pick } from '/picking.js';
import { Modes } from '/modes.js';
import { Frames } from '/frame.js';

const $ = (id) => document.getElementById(id);
const view = $('view');
const statusLine = $('status');

/** Shows a message under the mesh counts (`error` colours it). */
export function status(text, error = false) {
  statusLine.textContent = text;
  statusLine.classList.toggle('error', error);
}

const renderer = new THREE.WebGLRenderer({ antialias: false, preserveDrawingBuffer: true });
renderer.setPixelRatio(1);
view.appendChild(renderer.domElement);
// Two scenes: the mesh, drawn only when the view or its colours change, and the overlay
// (anchors, curves, cages), drawn every frame (frame.js).
const camera = new THREE.PerspectiveCamera(40, 1, 0.01, 1000);
const controls = new OrbitControls(camera, renderer.domElement);
function lit(scene) {
  scene.add(new THREE.HemisphereLight(0xffffff, 0x444450, 1.6));
  const sun = new THREE.DirectionalLight(0xffffff, 1.6);
  sun.position.set(0.5, 1, 1).multiplyScalar(1000);
  scene.add(sun);
  return scene;
}
const meshScene = lit(new THREE.Scene());
meshScene.background = new THREE.Color(0xf4f4f2);
const scene = lit(new THREE.Scene());
const frames = new Frames(renderer, camera, meshScene, scene);

// Everything the test suite reads (measurements, state) hangs off window.wavg.
// latencies: mouse move -> frame drawn; requestMs: /api/spline's round trip (JSON parsed
// included); serverMs: its time in the server; drawMs: the frame after the answer.
const stats = { readyMs: null, latencies: [], serverMs: [], requestMs: [], drawMs: [], requests: 0 };
const app = {
  THREE, scene, meshScene, camera, renderer, stats, status, measure: false,
  anchors: [], // {point: [face, b0, b1, b2], pos: THREE.Vector3, weight, sphere}
  mesh: null, info: null, picker: null, radius: 1, ready: false,
  render, invalidate: () => frames.invalidate(), retire: (g) => frames.retire(g), addAnchor, setAnchor, anchorScreen, surfaceScreen, refreshAnchorList,
};
window.wavg = app;

function resize() {
  const w = view.clientWidth;
  const h = view.clientHeight;
  renderer.setSize(w, h);
  frames.resize(w, h);
  camera.aspect = w / Math.max(1, h);
  camera.updateProjectionMatrix();
  render();
}

/** Draws one frame (on demand: after a change, not continuously); `full` redraws the
 * whole canvas from the cached mesh. */
function render(full = false) {
  frames.render(full);
  if (app.measure) {
    // Wait for the frame to be drawn, so measured times include the drawing.
    const gl = renderer.getContext();
    gl.readPixels(0, 0, 1, 1, gl.RGBA, gl.UNSIGNED_BYTE, new Uint8Array(4));
  }
}

controls.addEventListener('change', () => { frames.invalidate(); render(); });
new ResizeObserver(() => { if (app.mesh) resize(); }).observe(view);

/** Screen (page) coordinates of a 3-D point, and whether it faces the camera. */
function screenOf(p) {
  const v = p.clone().project(camera);
  const r = renderer.domElement.getBoundingClientRect();
  return { x: r.left + (v.x + 1) / 2 * r.width, y: r.top + (1 - v.y) / 2 * r.height };
}

function anchorScreen(i) { return screenOf(app.anchors[i].pos); }

/** Screen coordinates of vertex `v` if a ray through them hits the surface there. */
function surfaceScreen(v) {
  const P = app.mesh.positions;
  const p = new THREE.Vector3(P[3 * v], P[3 * v + 1], P[3 * v + 2]);
  const s = screenOf(p);
  const r = renderer.domElement.getBoundingClientRect();
  if (!(s.x > r.left + 4 && s.x < r.right - 4 && s.y > r.top + 4 && s.y < r.bottom - 4)) return null;
  const hit = hitAt(s.x, s.y);
  if (!hit || hit.pos.distanceTo(p) > 0.02 * app.radius) return null;
  return s;
}

/** The surface point under page coordinates (x, y), or null. */
function hitAt(x, y) {
  const r = renderer.domElement.getBoundingClientRect();
  const ndc = new THREE.Vector2((x - r.left) / r.width * 2 - 1, -((y - r.top) / r.height) * 2 + 1);
  const ray = new THREE.Raycaster();
  ray.setFromCamera(ndc, camera);
  const o = ray.ray.origin;
  const d = ray.ray.direction;
  const h = pick(app.picker, [o.x, o.y, o.z], [d.x, d.y, d.z]);
  if (!h) return null;
  return { point: [h.face, ...h.bary], pos: o.clone().addScaledVector(d, h.t) };
}
app.hitAt = hitAt;

const anchorMaterial = new THREE.MeshLambertMaterial({ color: 0xe0602a });
let sphereGeometry = null;

function addAnchor(point, pos, weight = 1) {
  const sphere = new THREE.Mesh(sphereGeometry, anchorMaterial);
  sphere.position.copy(pos);
  scene.add(sphere);
  app.anchors.push({ point, pos: pos.clone(), weight, sphere });
  refreshAnchorList();
  modes.changed();
}

function setAnchor(i, point, pos) {
  const a = app.anchors[i];
  a.point = point;
  a.pos.copy(pos);
  a.sphere.position.copy(pos);
  modes.changed();
}

function removeAnchor(i) {
  scene.remove(app.anchors[i].sphere);
  app.anchors.splice(i, 1);
  refreshAnchorList();
  modes.changed();
}

function refreshAnchorList() {
  const list = $('anchors');
  list.replaceChildren();
  app.anchors.forEach((a, i) => {
    const li = document.createElement('li');
    const slider = document.createElement('input');
    Object.assign(slider, { type: 'range', min: 0, max: 1, step: 0.01, value: a.weight });
    slider.setAttribute('aria-label', `weight of anchor ${i + 1}`);
    slider.addEventListener('input', () => { a.weight = Number(slider.value); modes.changed(); });
    const del = document.createElement('button');
    del.textContent = '×';
    del.title = 'remove';
    del.addEventListener('click', () => removeAnchor(i));
    li.append(`face ${a.point[0]} `, slider, del);
    list.appendChild(li);
  });
}

// Pointer handling: press near an anchor (or cage vertex) drags it; a click without
// movement elsewhere adds an anchor; any other drag orbits.
let dragging = null;
let down = null;
const el = renderer.domElement;
el.addEventListener('pointerdown', (e) => {
  down = { x: e.clientX, y: e.clientY };
  const handle = modes.handleAt(e.clientX, e.clientY);
  if (handle) {
    dragging = handle;
    controls.enabled = false;
    el.setPointerCapture(e.pointerId);
  }
});
el.addEventListener('pointermove', (e) => {
  if (!dragging) return;
  const hit = hitAt(e.clientX, e.clientY);
  if (!hit) return;
  // The latency measured runs from the event (before the ray cast) to the frame drawn.
  modes.moveStamp = e.timeStamp;
  dragging.move(hit);
});
el.addEventListener('pointerup', (e) => {
  const moved = down && Math.hypot(e.clientX - down.x, e.clientY - down.y) > 4;
  if (dragging) {
    dragging = null;
    controls.enabled = true;
  } else if (!moved && app.ready && modes.mode !== 'remesh') {
    const hit = hitAt(e.clientX, e.clientY);
    if (hit) addAnchor(hit.point, hit.pos);
  }
  down = null;
});
$('clear').addEventListener('click', () => {
  while (app.anchors.length) removeAnchor(app.anchors.length - 1);
});

const modes = new Modes(app);
app.modes = modes;

async function waitReady() {
  for (;;) {
    const s = await getJson('/api/status');
    if (s.state === 'ready') return;
    if (s.state === 'failed') throw new Error(`the embedding could not be computed: ${s.message}`);
    status(`precomputing the embedding: ${s.stage} ${Math.round(100 * s.fraction)}%`);
    await new Promise((r) => setTimeout(r, 300));
  }
}

async function main() {
  const [info, mesh] = await Promise.all([getJson('/api/info'), getMesh()]);
  app.info = info;
  app.mesh = mesh;
  $('meshinfo').textContent = `${info.vertices} vertices, ${info.faces} faces`;
  const geometry = new THREE.BufferGeometry();
  geometry.setAttribute('position', new THREE.BufferAttribute(mesh.positions, 3));
  geometry.setAttribute('normal', new THREE.BufferAttribute(mesh.normals, 3));
  const colors = new Float32Array(3 * mesh.n).fill(0.78);
  geometry.setAttribute('color', new THREE.BufferAttribute(colors, 3));
  geometry.setIndex(new THREE.BufferAttribute(mesh.triangles, 1));
  const surface = new THREE.Mesh(geometry, new THREE.MeshLambertMaterial({
    vertexColors: true, side: THREE.DoubleSide,
    polygonOffset: true, polygonOffsetFactor: 1, polygonOffsetUnits: 1,
  }));
  meshScene.add(surface);
  app.surface = surface;
  const [lo, hi] = info.bounding_box;
  const center = new THREE.Vector3((lo[0] + hi[0]) / 2, (lo[1] + hi[1]) / 2, (lo[2] + hi[2]) / 2);
  app.radius = Math.max(1e-9, Math.hypot(hi[0] - lo[0], hi[1] - lo[1], hi[2] - lo[2]) / 2);
  sphereGeometry = new THREE.SphereGeometry(0.025 * app.radius, 16, 12);
  controls.target.copy(center);
  camera.position.copy(center).add(new THREE.Vector3(0.3, 0.4, 1).normalize().multiplyScalar(3.4 * app.radius));
  camera.near = app.radius / 100;
  camera.far = app.radius * 100;
  controls.update();
  app.picker = buildPicker(mesh.positions, mesh.triangles);
  resize();
  stats.readyMs = performance.now();
  await waitReady();
  app.ready = true;
  status('ready: click the surface to add anchors');
  modes.changed();
}

main().catch((e) => status(e.message, true));
