// The server's API (docs/serve.md): JSON routes and the binary mesh.

/** The duration `name` of a `Server-Timing` header (NaN when absent). */
function timing(header, name) {
  const m = header && header.match(new RegExp(`${name};dur=([0-9.]+)`));
  return m ? parseFloat(m[1]) : NaN;
}

/**
 * POST `body` as JSON to `route`; resolves to the parsed answer with the server's time
 * (`serverMs`: from taking the request to the answer ready; `computeMs`: the computation),
 * or throws its message.
 */
export async function post(route, body, format) {
  const res = await fetch(route, {
    method: 'POST',
    headers: { 'Content-Type': 'application/json' },
    body: JSON.stringify(format ? { ...body, format } : body),
  });
  const header = res.headers.get('Server-Timing');
  const serverMs = timing(header, 'total');
  const computeMs = timing(header, 'compute');
  if (!res.ok) {
    let message = `${route}: HTTP ${res.status}`;
    try { message = (await res.json()).error || message; } catch (_) { /* not JSON */ }
    throw new Error(message);
  }
  const data = format ? await res.text() : await res.json();
  return { data, serverMs, computeMs };
}

/** GET a JSON route. */
export async function getJson(route) {
  const res = await fetch(route);
  if (!res.ok) throw new Error(`${route}: HTTP ${res.status}`);
  return res.json();
}

/**
 * GET /api/mesh: u32 n, u32 m, f32 positions[3n], u32 triangles[3m], f32 normals[3n]
 * (little-endian; every section 4-byte aligned).
 */
export async function getMesh() {
  const res = await fetch('/api/mesh');
  if (!res.ok) throw new Error(`/api/mesh: HTTP ${res.status}`);
  const buf = await res.arrayBuffer();
  const head = new Uint32Array(buf, 0, 2);
  const n = head[0];
  const m = head[1];
  const positions = new Float32Array(buf, 8, 3 * n);
  const triangles = new Uint32Array(buf, 8 + 12 * n, 3 * m);
  const normals = new Float32Array(buf, 8 + 12 * n + 12 * m, 3 * n);
  return { n, m, positions, triangles, normals };
}
