// Colour maps: viridis for scalars, a checkerboard for decal coordinates.

// Viridis sampled at 9 evenly spaced points (matplotlib's table), interpolated linearly.
const VIRIDIS = [
  [0.267, 0.005, 0.329], [0.283, 0.141, 0.458], [0.254, 0.265, 0.530],
  [0.207, 0.372, 0.553], [0.164, 0.471, 0.558], [0.128, 0.567, 0.551],
  [0.135, 0.659, 0.518], [0.267, 0.749, 0.441], [0.478, 0.821, 0.318],
  [0.741, 0.873, 0.150], [0.993, 0.906, 0.144],
];

/** The viridis colour of `t` in [0, 1], written to `out` at `o`. */
export function viridis(t, out, o) {
  const x = Math.min(1, Math.max(0, t)) * (VIRIDIS.length - 1);
  const i = Math.min(VIRIDIS.length - 2, Math.floor(x));
  const f = x - i;
  for (let k = 0; k < 3; k++) out[o + k] = VIRIDIS[i][k] * (1 - f) + VIRIDIS[i + 1][k] * f;
}

/** Per-vertex colours of a checkerboard of `checks` squares per unit of (u, v). */
export function checkerboard(uv, marked, checks, n) {
  const out = new Float32Array(3 * n);
  const bad = new Uint8Array(n);
  for (const v of marked) bad[v] = 1;
  for (let v = 0; v < n; v++) {
    const [u, w] = uv[v];
    let c;
    if (bad[v]) c = [0.85, 0.15, 0.15];
    else {
      const odd = (Math.floor(u * checks) + Math.floor(w * checks)) & 1;
      c = odd ? [0.15, 0.15, 0.2] : [0.95, 0.93, 0.85];
    }
    out.set(c, 3 * v);
  }
  return out;
}
