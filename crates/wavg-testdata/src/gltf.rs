//! glTF files built in code for the tests of every crate that reads them: a GLB (or
//! `.gltf` + `.bin`) from accessors, meshes and nodes written as JSON text, so a test can
//! also break any part of it.

/// The pieces of a glTF file; `json()` and `glb()` assemble them.
#[derive(Default, Clone)]
pub struct Gltf {
    /// The one buffer's bytes.
    pub bin: Vec<u8>,
    /// Buffer views (JSON objects).
    pub views: Vec<String>,
    /// Accessors (JSON objects).
    pub accessors: Vec<String>,
    /// Meshes (JSON objects).
    pub meshes: Vec<String>,
    /// Nodes (JSON objects).
    pub nodes: Vec<String>,
    /// The scene's root nodes; `None`: every node is a root.
    pub roots: Option<Vec<usize>>,
    /// Materials (JSON objects).
    pub materials: Vec<String>,
    /// Textures (JSON objects).
    pub textures: Vec<String>,
    /// Images (JSON objects).
    pub images: Vec<String>,
    /// More top-level members, e.g. `"extensionsRequired": [...]`.
    pub extra: Vec<String>,
}

impl Gltf {
    /// A buffer view over `bytes` (appended to the binary buffer, 4-byte aligned).
    pub fn view(&mut self, bytes: &[u8]) -> usize {
        while self.bin.len() % 4 != 0 {
            self.bin.push(0);
        }
        let at = self.bin.len();
        self.bin.extend_from_slice(bytes);
        self.views.push(format!(
            r#"{{"buffer":0,"byteOffset":{at},"byteLength":{}}}"#,
            bytes.len()
        ));
        self.views.len() - 1
    }

    /// A float accessor of `ty` (`VEC2`, `VEC3`) over `data`.
    pub fn floats(&mut self, data: &[f32], ty: &str) -> usize {
        let bytes: Vec<u8> = data.iter().flat_map(|x| x.to_le_bytes()).collect();
        let n = if ty == "VEC2" { 2 } else { 3 };
        let v = self.view(&bytes);
        let mut minmax = String::new();
        if n == 3 && !data.is_empty() {
            let (mut lo, mut hi) = ([f32::MAX; 3], [f32::MIN; 3]);
            for c in data.chunks(3) {
                for k in 0..3 {
                    lo[k] = lo[k].min(c[k]);
                    hi[k] = hi[k].max(c[k]);
                }
            }
            minmax = format!(r#","min":{lo:?},"max":{hi:?}"#);
        }
        self.accessors.push(format!(
            r#"{{"bufferView":{v},"componentType":5126,"count":{},"type":"{ty}"{minmax}}}"#,
            data.len() / n
        ));
        self.accessors.len() - 1
    }

    /// An unsigned-int index accessor.
    pub fn indices(&mut self, data: &[u32]) -> usize {
        let bytes: Vec<u8> = data.iter().flat_map(|x| x.to_le_bytes()).collect();
        let v = self.view(&bytes);
        self.accessors.push(format!(
            r#"{{"bufferView":{v},"componentType":5125,"count":{},"type":"SCALAR"}}"#,
            data.len()
        ));
        self.accessors.len() - 1
    }

    /// A mesh of the given primitives (JSON objects, see [`prim`]).
    pub fn mesh(&mut self, name: &str, prims: &[String]) -> usize {
        self.meshes.push(format!(
            r#"{{"name":"{name}","primitives":[{}]}}"#,
            prims.join(",")
        ));
        self.meshes.len() - 1
    }

    /// A node (its JSON object).
    pub fn node(&mut self, json: &str) -> usize {
        self.nodes.push(json.to_string());
        self.nodes.len() - 1
    }

    /// The glTF JSON; the buffer is the GLB's binary chunk (`uri` None) or `uri`.
    pub fn json(&self, uri: Option<&str>) -> String {
        let list = |v: &[String]| v.join(",");
        let roots = match &self.roots {
            Some(r) => r.clone(),
            None => (0..self.nodes.len()).collect(),
        };
        let uri = uri.map_or(String::new(), |u| format!(r#","uri":"{u}""#));
        let mut parts = vec![
            r#""asset":{"version":"2.0"}"#.to_string(),
            format!(r#""buffers":[{{"byteLength":{}{uri}}}]"#, self.bin.len()),
            format!(r#""bufferViews":[{}]"#, list(&self.views)),
            format!(r#""accessors":[{}]"#, list(&self.accessors)),
            format!(r#""meshes":[{}]"#, list(&self.meshes)),
        ];
        if !self.nodes.is_empty() {
            parts.push(format!(r#""nodes":[{}]"#, list(&self.nodes)));
            parts.push(format!(r#""scenes":[{{"nodes":{roots:?}}}],"scene":0"#));
        }
        for (key, v) in [
            ("materials", &self.materials),
            ("textures", &self.textures),
            ("images", &self.images),
        ] {
            if !v.is_empty() {
                parts.push(format!(r#""{key}":[{}]"#, list(v)));
            }
        }
        parts.extend(self.extra.iter().cloned());
        format!("{{{}}}", parts.join(","))
    }

    /// The binary glTF file.
    pub fn glb(&self) -> Vec<u8> {
        glb(&self.json(None), &self.bin)
    }
}

/// A GLB container of `json` and `bin`.
pub fn glb(json: &str, bin: &[u8]) -> Vec<u8> {
    let mut j = json.as_bytes().to_vec();
    while j.len() % 4 != 0 {
        j.push(b' ');
    }
    let mut b = bin.to_vec();
    while b.len() % 4 != 0 {
        b.push(0);
    }
    let total = 12 + 8 + j.len() + if b.is_empty() { 0 } else { 8 + b.len() };
    let mut out = b"glTF".to_vec();
    out.extend(2u32.to_le_bytes());
    out.extend((total as u32).to_le_bytes());
    out.extend((j.len() as u32).to_le_bytes());
    out.extend(0x4E4F_534Au32.to_le_bytes());
    out.extend(j);
    if !b.is_empty() {
        out.extend((b.len() as u32).to_le_bytes());
        out.extend(0x004E_4942u32.to_le_bytes());
        out.extend(b);
    }
    out
}

/// A primitive's JSON object.
pub fn prim(pos: usize, indices: Option<usize>, uv: Option<usize>, mode: u32) -> String {
    let uv = uv.map_or(String::new(), |u| format!(r#","TEXCOORD_0":{u}"#));
    let idx = indices.map_or(String::new(), |i| format!(r#","indices":{i}"#));
    format!(r#"{{"attributes":{{"POSITION":{pos}{uv}}}{idx},"mode":{mode}}}"#)
}

/// A mesh with per-corner texture coordinates split as glTF exporters do: one glTF
/// vertex per distinct (position, uv) pair. Returns (positions, uvs, indices).
pub fn split_at_seams(
    positions: &[[f32; 3]],
    triangles: &[[u32; 3]],
    corner_uv: &[CornerUv],
) -> (Vec<f32>, Vec<f32>, Vec<u32>) {
    let mut seen = std::collections::HashMap::new();
    let (mut p, mut t, mut idx) = (Vec::new(), Vec::new(), Vec::new());
    for (tri, uvs) in triangles.iter().zip(corner_uv) {
        for k in 0..3 {
            let key = (tri[k], uvs[k][0].to_bits(), uvs[k][1].to_bits());
            let next = seen.len() as u32;
            let id = *seen.entry(key).or_insert(next);
            if id == next {
                p.extend(positions[tri[k] as usize]);
                t.extend(uvs[k]);
            }
            idx.push(id);
        }
    }
    (p, t, idx)
}

/// The texture coordinates of a triangle's three corners.
pub type CornerUv = [[f32; 2]; 3];

/// A torus (`nu` x `nv` quads, genus 1) whose texture is cut along both seams, as
/// exported: (positions, triangles, per-corner uvs in glTF's convention).
pub fn seamed_torus(nu: u32, nv: u32) -> (Vec<[f32; 3]>, Vec<[u32; 3]>, Vec<CornerUv>) {
    use std::f64::consts::PI;
    let mut pos = Vec::new();
    for i in 0..nu {
        for j in 0..nv {
            let (u, v) = (
                2.0 * PI * i as f64 / nu as f64,
                2.0 * PI * j as f64 / nv as f64,
            );
            let r = 1.0 + 0.3 * v.cos();
            pos.push([
                (r * u.cos()) as f32,
                (r * u.sin()) as f32,
                (0.3 * v.sin()) as f32,
            ]);
        }
    }
    let id = |i: u32, j: u32| (i % nu) * nv + (j % nv);
    let uv = |i: u32, j: u32| [i as f32 / nu as f32, j as f32 / nv as f32];
    let (mut tris, mut uvs) = (Vec::new(), Vec::new());
    for i in 0..nu {
        for j in 0..nv {
            let q = [(i, j), (i + 1, j), (i + 1, j + 1), (i, j + 1)];
            for [a, b, c] in [[0, 1, 2], [0, 2, 3]] {
                tris.push([q[a], q[b], q[c]].map(|(x, y)| id(x, y)));
                uvs.push([q[a], q[b], q[c]].map(|(x, y)| uv(x, y)));
            }
        }
    }
    (pos, tris, uvs)
}

/// A GLB of one seamed torus mesh named `name` on one node: `nu * nv` vertices once
/// welded, `(nu + 1) * (nv + 1)` as written, `2 * nu * nv` triangles, genus 1.
pub fn torus_glb(nu: u32, nv: u32, name: &str) -> (Gltf, Vec<u8>) {
    let (pos, tris, uvs) = seamed_torus(nu, nv);
    let (p, t, idx) = split_at_seams(&pos, &tris, &uvs);
    let mut g = Gltf::default();
    let (a, b, c) = (g.floats(&p, "VEC3"), g.floats(&t, "VEC2"), g.indices(&idx));
    g.mesh(name, &[prim(a, Some(c), Some(b), 4)]);
    g.node(r#"{"mesh":0}"#);
    let bytes = g.glb();
    (g, bytes)
}

/// [`torus_glb`] with `png` embedded as its base colour texture.
pub fn textured_torus_glb(nu: u32, nv: u32, png: &[u8]) -> Vec<u8> {
    let (mut g, _) = torus_glb(nu, nv, "Torus");
    let view = g.view(png);
    g.images
        .push(format!(r#"{{"bufferView":{view},"mimeType":"image/png"}}"#));
    g.textures.push(r#"{"source":0}"#.to_string());
    g.materials
        .push(r#"{"pbrMetallicRoughness":{"baseColorTexture":{"index":0}}}"#.to_string());
    g.meshes[0] = g.meshes[0].replace(r#""mode":4"#, r#""mode":4,"material":0"#);
    g.glb()
}
