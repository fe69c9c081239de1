// Drawing frames cheaply in software GL. The mesh is drawn into an off-screen colour +
// depth target only when the view or its colours change, and copied with its depth onto
// the canvas (whose drawing buffer is preserved). Between such changes a frame erases the
// overlay drawn last by drawing its own geometry again with the cached mesh's colour and
// depth, then draws the new overlay: the cost of a frame during a drag follows the pixels
// of the curve and the anchors, not those of the canvas.

import * as THREE from 'three';

// The cached mesh at this pixel (gl_FragCoord: the copy and the erasing read the same
// texel of the same shader, so an erased pixel is exactly the copied one).
const RESTORE = `uniform sampler2D tColor; uniform sampler2D tDepth; uniform vec2 size;
  void main() {
    vec2 uv = gl_FragCoord.xy / size;
    gl_FragColor = texture2D(tColor, uv);
    gl_FragDepth = texture2D(tDepth, uv).r;
    #include <colorspace_fragment>
  }`;

function restoreMaterial(uniforms, vertexShader, side) {
  return new THREE.ShaderMaterial({
    uniforms, vertexShader, fragmentShader: RESTORE, side,
    depthTest: true, depthWrite: true, depthFunc: THREE.AlwaysDepth,
  });
}

/** The colour + depth target of the mesh. */
function makeTarget(w, h) {
  const t = new THREE.WebGLRenderTarget(w, h, { depthTexture: new THREE.DepthTexture(w, h) });
  t.texture.colorSpace = THREE.SRGBColorSpace;
  return t;
}

export class Frames {
  /** Frames of `meshScene` (cached) under `overlay` (drawn each frame), seen by `camera`. */
  constructor(renderer, camera, meshScene, overlay) {
    Object.assign(this, { renderer, camera, meshScene, overlay });
    this.target = makeTarget(1, 1);
    this.uniforms = {
      tColor: { value: this.target.texture },
      tDepth: { value: this.target.depthTexture },
      size: { value: new THREE.Vector2(1, 1) },
    };
    const quad = new THREE.Mesh(new THREE.PlaneGeometry(2, 2), restoreMaterial(
      this.uniforms, 'void main() { gl_Position = vec4(position.xy, 0.0, 1.0); }', THREE.FrontSide,
    ));
    quad.frustumCulled = false;
    this.copyScene = new THREE.Scene().add(quad);
    this.copyCamera = new THREE.OrthographicCamera(-1, 1, 1, -1, 0, 1);
    // The same vertex stage as three's own materials, so the erasing covers every pixel
    // drawn (both sides of triangles: a superset, which only restores mesh pixels).
    this.eraseMaterial = restoreMaterial(this.uniforms,
      '#include <common>\nvoid main() {\n#include <begin_vertex>\n#include <project_vertex>\n}',
      THREE.DoubleSide);
    this.erase = new THREE.Scene(); // proxies of the overlay's objects as last drawn
    this.lines = [];
    this.meshes = [];
    this.retired = [];
    this.meshDirty = true;
    this.canvasDirty = true;
  }

  /** The canvas's new size in pixels. */
  resize(w, h) {
    this.target.dispose();
    this.target.depthTexture.dispose();
    this.target = makeTarget(w, h);
    this.uniforms.tColor.value = this.target.texture;
    this.uniforms.tDepth.value = this.target.depthTexture;
    this.uniforms.size.value.set(w, h);
    this.meshDirty = true;
  }

  /** The mesh (view or colours) changed: redraw it at the next frame. */
  invalidate() { this.meshDirty = true; }

  /** A geometry removed from the overlay, disposed once its pixels are erased. */
  retire(geometry) { this.retired.push(geometry); }

  /** Draws a frame; `full` redraws the canvas from the cached mesh even without a change. */
  render(full = false) {
    const r = this.renderer;
    const autoClear = r.autoClear;
    if (this.meshDirty) {
      r.setRenderTarget(this.target);
      r.autoClear = true;
      r.render(this.meshScene, this.camera);
      r.setRenderTarget(null);
      this.meshDirty = false;
      this.canvasDirty = true;
    }
    if (this.canvasDirty || full) {
      r.autoClear = true;
      r.render(this.copyScene, this.copyCamera);
      this.canvasDirty = false;
    } else {
      r.autoClear = false;
      r.render(this.erase, this.camera);
    }
    r.autoClear = false;
    r.render(this.overlay, this.camera);
    r.autoClear = autoClear;
    this.record();
    for (const g of this.retired) g.dispose();
    this.retired = [];
  }

  /** Keeps proxies of the overlay's visible lines (their vertices copied) and meshes. */
  record() {
    let nl = 0;
    let nm = 0;
    this.overlay.updateMatrixWorld();
    this.overlay.traverseVisible((o) => {
      if (o.isLineSegments) {
        const p = this.proxy(this.lines, nl++, () => new THREE.LineSegments(new THREE.BufferGeometry(), this.eraseMaterial));
        copyPositions(o.geometry, p.geometry);
        p.matrix.copy(o.matrixWorld);
        p.matrixWorldNeedsUpdate = true;
      } else if (o.isMesh) {
        const p = this.proxy(this.meshes, nm++, () => new THREE.Mesh(undefined, this.eraseMaterial));
        p.geometry = o.geometry;
        p.matrix.copy(o.matrixWorld);
        p.matrixWorldNeedsUpdate = true;
      }
    });
    this.lines.forEach((p, i) => { p.visible = i < nl; });
    this.meshes.forEach((p, i) => { p.visible = i < nm; });
  }

  proxy(pool, i, make) {
    if (!pool[i]) {
      const p = make();
      p.matrixAutoUpdate = false;
      p.frustumCulled = false;
      pool.push(p);
      this.erase.add(p);
    }
    pool[i].visible = true;
    return pool[i];
  }
}

/** Copies the drawn vertices of `from` into `to` (its buffer grows when needed). */
function copyPositions(geometry, to) {
  const from = geometry.index ? geometry.toNonIndexed() : geometry;
  const src = from.getAttribute('position');
  const start = Math.max(0, from.drawRange.start);
  const count = Math.max(0, Math.min(src.count, from.drawRange.count) - start);
  let dst = to.getAttribute('position');
  if (!dst || dst.count < count) {
    if (dst) to.dispose();
    dst = new THREE.BufferAttribute(new Float32Array(3 * Math.max(64, 2 * count)), 3);
    dst.setUsage(THREE.DynamicDrawUsage);
    to.setAttribute('position', dst);
  }
  dst.array.set(src.array.subarray(3 * start, 3 * (start + count)));
  dst.needsUpdate = true;
  to.setDrawRange(0, count);
}
