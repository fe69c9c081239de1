// Ray casting against the mesh on its typed arrays (Möller–Trumbore over every triangle,
// skipped quickly by a per-cell bounding test of a coarse grid of triangle clusters).

const CLUSTER = 64;

/** Precomputes triangle clusters (consecutive triangles) with their bounding boxes. */
export function buildPicker(positions, triangles) {
  const m = triangles.length / 3;
  const k = Math.ceil(m / CLUSTER);
  const boxes = new Float32Array(6 * k);
  for (let c = 0; c < k; c++) {
    let lo = [Infinity, Infinity, Infinity];
    let hi = [-Infinity, -Infinity, -Infinity];
    for (let f = c * CLUSTER; f < Math.min(m, (c + 1) * CLUSTER); f++) {
      for (let j = 0; j < 3; j++) {
        const v = triangles[3 * f + j];
        for (let a = 0; a < 3; a++) {
          const x = positions[3 * v + a];
          if (x < lo[a]) lo[a] = x;
          if (x > hi[a]) hi[a] = x;
        }
      }
    }
    boxes.set([...lo, ...hi], 6 * c);
  }
  return { positions, triangles, boxes, m, k };
}

function hitsBox(b, o, ox, oy, oz, ix, iy, iz, best) {
  let t0 = 0;
  let t1 = best;
  const lo = [b[o], b[o + 1], b[o + 2]];
  const hi = [b[o + 3], b[o + 4], b[o + 5]];
  const org = [ox, oy, oz];
  const inv = [ix, iy, iz];
  for (let a = 0; a < 3; a++) {
    let ta = (lo[a] - org[a]) * inv[a];
    let tb = (hi[a] - org[a]) * inv[a];
    if (ta > tb) { const s = ta; ta = tb; tb = s; }
    if (ta > t0) t0 = ta;
    if (tb < t1) t1 = tb;
    if (t0 > t1) return false;
  }
  return true;
}

/**
 * The first triangle hit by the ray `origin + t dir`: `{face, bary: [b0, b1, b2], t}` or
 * null (barycentric coordinates of the triangle's corners, summing to 1).
 */
export function pick(picker, origin, dir) {
  const { positions: P, triangles: T, boxes, m, k } = picker;
  const [ox, oy, oz] = origin;
  const [dx, dy, dz] = dir;
  const ix = 1 / dx;
  const iy = 1 / dy;
  const iz = 1 / dz;
  let best = Infinity;
  let hit = null;
  for (let c = 0; c < k; c++) {
    if (!hitsBox(boxes, 6 * c, ox, oy, oz, ix, iy, iz, best)) continue;
    for (let f = c * CLUSTER; f < Math.min(m, (c + 1) * CLUSTER); f++) {
      const a = 3 * T[3 * f];
      const b = 3 * T[3 * f + 1];
      const cc = 3 * T[3 * f + 2];
      const e1x = P[b] - P[a]; const e1y = P[b + 1] - P[a + 1]; const e1z = P[b + 2] - P[a + 2];
      const e2x = P[cc] - P[a]; const e2y = P[cc + 1] - P[a + 1]; const e2z = P[cc + 2] - P[a + 2];
      const px = dy * e2z - dz * e2y; const py = dz * e2x - dx * e2z; const pz = dx * e2y - dy * e2x;
      const det = e1x * px + e1y * py + e1z * pz;
      if (Math.abs(det) < 1e-20) continue;
      const inv = 1 / det;
      const sx = ox - P[a]; const sy = oy - P[a + 1]; const sz = oz - P[a + 2];
      const u = (sx * px + sy * py + sz * pz) * inv;
      if (u < 0 || u > 1) continue;
      const qx = sy * e1z - sz * e1y; const qy = sz * e1x - sx * e1z; const qz = sx * e1y - sy * e1x;
      const v = (dx * qx + dy * qy + dz * qz) * inv;
      if (v < 0 || u + v > 1) continue;
      const t = (e2x * qx + e2y * qy + e2z * qz) * inv;
      if (t > 0 && t < best) {
        best = t;
        hit = { face: f, bary: [1 - u - v, u, v], t };
      }
    }
  }
  return hit;
}
