// The page's modes: each asks the server for what the anchors (or the cage) define and
// draws it. Requests are coalesced: while one is in flight, changes only mark the state
// dirty, and the latest state is sent when it returns.

import * as THREE from 'three';
import { post } from '/api.js';
import { checkerboard, viridis } from '/colors.js';

const $ = (id) => document.getElementById(id);
const PICK_PIXELS = 12;

export class Modes {
  constructor(app) {
    this.app = app;
    this.mode = 'spline';
    this.busy = false;
    this.dirty = false;
    this.moveStamp = null;
    this.cage = null;
    this.overlay = new THREE.Group();
    app.scene.add(this.overlay);
    this.lineMaterial = new THREE.LineBasicMaterial({ color: 0x1f4fd0 });
    // The spline's line segments, rewritten in place for each answer.
    this.curve = new THREE.LineSegments(new THREE.BufferGeometry(), this.lineMaterial);
    this.curve.frustumCulled = false;
    this.cageMaterial = new THREE.LineBasicMaterial({ color: 0xe0602a });
    this.pointMaterial = new THREE.MeshLambertMaterial({ color: 0x1aa34a });
    this.last = {}; // the latest answer of each mode (read by the tests)
    $('mode').addEventListener('change', () => this.setMode($('mode').value));
    for (const id of ['closed', 'bezier', 'degree', 'samples', 'checks', 'levels', 'smooth']) {
      $(id).addEventListener('change', () => this.changed());
    }
    $('cagesize').addEventListener('change', () => { this.cage = null; this.changed(); });
    $('dl-curve').addEventListener('click', () => this.download('spline'));
    $('dl-decal').addEventListener('click', () => this.download('decal'));
    $('dl-remesh').addEventListener('click', () => this.download('remesh'));
    this.showOptions();
  }

  setMode(mode) {
    this.mode = mode;
    $('mode').value = mode;
    this.showOptions();
    this.changed();
  }

  showOptions() {
    for (const m of ['spline', 'decal', 'remesh']) $(`opts-${m}`).hidden = m !== this.mode;
  }

  /** Something changed: recompute (now, or when the request in flight returns). */
  changed() {
    if (!this.app.ready) return;
    if (this.busy) { this.dirty = true; return; }
    this.busy = true;
    const stamp = this.moveStamp;
    this.moveStamp = null;
    this.update()
      .then(() => {
        const t = performance.now();
        this.app.render();
        const done = performance.now();
        if (stamp !== null) {
          this.app.stats.latencies.push(done - stamp);
          this.app.stats.drawMs.push(done - t);
        }
      })
      .catch((e) => this.app.status(e.message, true))
      .finally(() => {
        this.busy = false;
        this.app.stats.requests += 1;
        if (this.dirty) { this.dirty = false; this.changed(); }
      });
  }

  /** A handle under page coordinates (x, y): an anchor, or a cage vertex in remesh mode. */
  handleAt(x, y) {
    const app = this.app;
    const near = (points) => {
      let best = -1;
      let bestD = PICK_PIXELS;
      points.forEach((p, i) => {
        const v = p.clone().project(app.camera);
        const r = app.renderer.domElement.getBoundingClientRect();
        const d = Math.hypot(r.left + (v.x + 1) / 2 * r.width - x, r.top + (1 - v.y) / 2 * r.height - y);
        if (d < bestD && v.z < 1) { bestD = d; best = i; }
      });
      return best;
    };
    if (this.mode === 'remesh' && this.cage) {
      const i = near(this.cage.vertices.map((p) => new THREE.Vector3(...p)));
      if (i < 0) return null;
      return { move: (hit) => { this.cage.vertices[i] = hit.pos.toArray(); this.changed(); } };
    }
    const i = near(app.anchors.map((a) => a.pos));
    if (i < 0) return null;
    return { move: (hit) => app.setAnchor(i, hit.point, hit.pos) };
  }

  /** Removes what the overlay shows (geometries are disposed once erased from the canvas). */
  clearOverlay() {
    for (const c of [...this.overlay.children]) {
      this.overlay.remove(c);
      if (c.geometry && c !== this.curve) this.app.retire(c.geometry);
    }
  }

  setColors(colors) {
    if (!colors && !this.colored) return;
    this.colored = Boolean(colors);
    const attr = this.app.surface.geometry.getAttribute('color');
    if (colors) attr.array.set(colors);
    else attr.array.fill(0.78);
    attr.needsUpdate = true;
    this.app.invalidate();
  }

  anchorPoints() { return this.app.anchors.map((a) => a.point); }

  async update() {
    const n = this.app.anchors.length;
    const idle = (msg) => { this.clearOverlay(); this.setColors(null); this.app.status(msg); };
    switch (this.mode) {
      case 'spline': {
        const body = this.splineBody();
        if (!body) return idle(`spline: add at least ${this.minControls()} control points`);
        const t = performance.now();
        const { data, serverMs } = await post('/api/spline', body);
        this.app.stats.requestMs.push(performance.now() - t);
        this.app.stats.serverMs.push(serverMs);
        this.last.spline = data.points;
        this.clearOverlay();
        this.setColors(null);
        polyline(this.curve.geometry, data.points, body.closed && !body.bezier);
        this.overlay.add(this.curve);
        const ok = data.points.filter((p) => p).length;
        return this.app.status(`spline: ${ok} of ${data.points.length} samples, length ${data.length.toFixed(4)}`);
      }
      case 'average': {
        const w = this.app.anchors.map((a) => a.weight);
        if (n < 1 || !(w.reduce((s, x) => s + x, 0) > 0)) return idle('average: add anchors with weights');
        const { data } = await post('/api/forward', { anchors: this.anchorPoints(), weights: [w], normalize: true });
        this.last.average = data.points[0];
        this.clearOverlay();
        this.setColors(null);
        const p = data.points[0];
        if (p) {
          const dot = new THREE.Mesh(new THREE.SphereGeometry(0.035 * this.app.radius, 20, 14), this.pointMaterial);
          dot.position.set(p[4], p[5], p[6]);
          this.overlay.add(dot);
        }
        const sum = w.reduce((s, x) => s + x, 0);
        return this.app.status(p ? `average of weights ${w.map((x) => (x / sum).toFixed(2)).join(', ')}`
          : 'average: no weighted average for these weights');
      }
      case 'decal': {
        if (n < 3) return idle('decal: add at least 3 anchors');
        const { data } = await post('/api/decal', this.decalBody());
        this.last.decal = data;
        this.clearOverlay();
        this.setColors(checkerboard(data.uv, data.marked, Number($('checks').value) || 8, this.app.mesh.n));
        return this.app.status(`decal: ${(100 * data.report.valid_fraction).toFixed(1)}% of the vertices valid (${data.marked.length} shown red)`);
      }
      case 'distance': {
        if (n < 1) return idle('distance: add an anchor (the source)');
        const { data } = await post('/api/distance', { source: this.app.anchors[0].point });
        this.last.distance = data.max;
        this.clearOverlay();
        const c = new Float32Array(3 * this.app.mesh.n);
        const max = data.max > 0 ? data.max : 1;
        data.distances.forEach((d, v) => viridis(d / max, c, 3 * v));
        this.setColors(c);
        return this.app.status(`distance from anchor 1 in the embedding: up to ${data.max.toFixed(4)}`);
      }
      case 'remesh': {
        if (!this.cage) {
          const { data } = await post('/api/cage', { vertices: Number($('cagesize').value) || 40 });
          this.cage = data;
        }
        const { data } = await post('/api/remesh', this.remeshBody());
        this.last.remesh = data;
        this.clearOverlay();
        this.setColors(null);
        this.overlay.add(edges(data.vertices, data.faces, this.lineMaterial));
        const cagePts = data.cage.map((p) => [p[4], p[5], p[6]]);
        this.overlay.add(edges(cagePts, this.cage.faces, this.cageMaterial));
        const g = new THREE.SphereGeometry(0.015 * this.app.radius, 10, 8);
        for (const p of cagePts) {
          const s = new THREE.Mesh(g, this.cageMaterial);
          s.position.set(...p);
          this.overlay.add(s);
        }
        return this.app.status(`remesh: ${data.vertices.length} vertices, ${data.faces.length} faces (drag an orange cage vertex)`);
      }
      default:
        return undefined;
    }
  }

  minControls() {
    return $('bezier').checked ? 2 : Math.max(2, Number($('degree').value) + 1);
  }

  splineBody() {
    if (this.app.anchors.length < this.minControls()) return null;
    return {
      control: this.anchorPoints(),
      degree: Number($('degree').value),
      closed: $('closed').checked,
      bezier: $('bezier').checked,
      samples: Math.max(1, Number($('samples').value) || 400),
    };
  }

  /** The anchors' (u, v): their positions in the plane facing their mean normal. */
  decalBody() {
    const { anchors, mesh } = this.app;
    const c = new THREE.Vector3();
    const nrm = new THREE.Vector3();
    for (const a of anchors) {
      c.add(a.pos);
      const [f] = a.point;
      for (let k = 0; k < 3; k++) {
        const v = mesh.triangles[3 * f + k];
        nrm.add(new THREE.Vector3(mesh.normals[3 * v], mesh.normals[3 * v + 1], mesh.normals[3 * v + 2]));
      }
    }
    c.divideScalar(anchors.length);
    if (nrm.lengthSq() === 0) nrm.set(0, 0, 1);
    nrm.normalize();
    const e1 = new THREE.Vector3(1, 0, 0);
    if (Math.abs(e1.dot(nrm)) > 0.9) e1.set(0, 1, 0);
    e1.addScaledVector(nrm, -e1.dot(nrm)).normalize();
    const e2 = new THREE.Vector3().crossVectors(nrm, e1);
    let uv = anchors.map((a) => { const d = a.pos.clone().sub(c); return [d.dot(e1), d.dot(e2)]; });
    const scale = Math.max(1e-12, ...uv.map(([u, v]) => Math.hypot(u, v)));
    uv = uv.map(([u, v]) => [0.5 + u / (2 * scale), 0.5 + v / (2 * scale)]);
    return { anchors: this.anchorPoints(), uv };
  }

  remeshBody() {
    return {
      cage: this.cage,
      levels: Number($('levels').value),
      smooth: Number($('smooth').value),
    };
  }

  /** Downloads the command line's file for the current curve, decal or remeshing. */
  async download(what) {
    try {
      let route;
      let body;
      let name;
      if (what === 'spline') {
        body = this.splineBody();
        if (!body) throw new Error(`spline: add at least ${this.minControls()} control points`);
        [route, name] = ['/api/spline', 'curve.txt'];
      } else if (what === 'decal') {
        if (this.app.anchors.length < 3) throw new Error('decal: add at least 3 anchors');
        [route, body, name] = ['/api/decal', this.decalBody(), 'decal.obj'];
      } else {
        if (!this.cage) throw new Error('remesh: switch to remesh mode first');
        [route, body, name] = ['/api/remesh', this.remeshBody(), 'remeshed.obj'];
      }
      const { data } = await post(route, body, what === 'spline' ? 'text' : 'obj');
      const a = document.createElement('a');
      a.href = URL.createObjectURL(new Blob([data], { type: 'text/plain' }));
      a.download = name;
      document.body.appendChild(a);
      a.click();
      a.remove();
    } catch (e) {
      this.app.status(e.message, true);
    }
  }
}

/** Writes into `geometry` the line segments through consecutive non-null points (and back
 * to the first if closed), reusing its buffer when it is large enough. */
function polyline(geometry, points, closed) {
  const n = points.length;
  let attr = geometry.getAttribute('position');
  if (!attr || attr.count < 2 * n) {
    if (attr) geometry.dispose();
    attr = new THREE.BufferAttribute(new Float32Array(6 * Math.max(n, 64)), 3);
    attr.setUsage(THREE.DynamicDrawUsage);
    geometry.setAttribute('position', attr);
  }
  const seg = attr.array;
  let k = 0;
  for (let i = 0; i + 1 < n + (closed ? 1 : 0); i++) {
    const a = points[i];
    const b = points[(i + 1) % n];
    if (a && b) {
      seg[k++] = a[4]; seg[k++] = a[5]; seg[k++] = a[6];
      seg[k++] = b[4]; seg[k++] = b[5]; seg[k++] = b[6];
    }
  }
  attr.clearUpdateRanges();
  attr.addUpdateRange(0, k);
  attr.needsUpdate = true;
  geometry.setDrawRange(0, k / 3);
}

/** The edges of polygons over `vertices`. */
function edges(vertices, faces, material) {
  const seg = [];
  for (const f of faces) {
    for (let k = 0; k < f.length; k++) {
      const a = vertices[f[k]];
      const b = vertices[f[(k + 1) % f.length]];
      seg.push(...a, ...b);
    }
  }
  const g = new THREE.BufferGeometry();
  g.setAttribute('position', new THREE.Float32BufferAttribute(seg, 3));
  return new THREE.LineSegments(g, material);
}
