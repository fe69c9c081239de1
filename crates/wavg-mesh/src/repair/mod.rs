//! Opt-in repairs for scanned and exported meshes.
//!
//! Each repair returns a [`Repaired`]: the new mesh plus the maps between new and original
//! vertex and face indices, so callers can translate their own ids (landmarks, anchors,
//! per-vertex data). Repairs never change positions, never reorder what they keep, and
//! keep per-corner texture coordinates aligned with the faces they keep.
//!
//! ```
//! use wavg_mesh::{RepairOptions, TriMesh, ValidMesh, repair};
//! use nalgebra::Vector3;
//! // Two triangles of a square written as a soup: 6 vertices, 4 distinct positions.
//! let p = |x: f64, y: f64| Vector3::new(x, y, 0.0);
//! let soup = TriMesh::new(
//!     vec![p(0., 0.), p(1., 0.), p(1., 1.), p(0., 0.), p(1., 1.), p(0., 1.)],
//!     vec![[0, 1, 2], [3, 4, 5]],
//! );
//! let r = repair::repair_all(&soup, &RepairOptions::default());
//! assert_eq!(r.mesh.n_vertices(), 4);
//! assert_eq!(r.vertex_map, vec![0, 1, 2, 5]); // new -> original
//! assert_eq!(r.new_vertex(4), Some(2)); // original 4 was welded onto original 2
//! assert!(ValidMesh::new(r.mesh).is_ok());
//! ```

use std::collections::HashMap;

use crate::analyze::is_degenerate;
use crate::mesh::{NONE, TriMesh};
use crate::topology::face_components;

mod manifold;
pub(crate) mod types;

pub use manifold::{make_manifold, orient_faces, split_nonmanifold_vertices};

use types::{RepairOptions, Repaired};

/// Keeps the faces for which `keep` is true (vertices unchanged).
fn filter_faces(mesh: &TriMesh, keep: impl Fn(usize) -> bool) -> Repaired {
    let face_map: Vec<u32> = (0..mesh.n_faces())
        .filter(|&f| keep(f))
        .map(|f| f as u32)
        .collect();
    let triangles = face_map
        .iter()
        .map(|&f| mesh.triangles[f as usize])
        .collect();
    let uv = mesh.uv.as_ref().map(|uv| crate::mesh::TexCoords {
        coords: uv.coords.clone(),
        faces: face_map
            .iter()
            .filter_map(|&f| uv.faces.get(f as usize).copied())
            .collect(),
    });
    let nv = mesh.n_vertices() as u32;
    Repaired {
        mesh: TriMesh {
            positions: mesh.positions.clone(),
            triangles,
            uv,
        },
        vertex_map: (0..nv).collect(),
        original_to_new: (0..nv).collect(),
        face_map,
    }
}

/// Remaps vertices by `original_to_new` (NONE = dropped; every face must only use kept
/// vertices) with `vertex_map` its inverse; faces unchanged in number and order.
fn remap_vertices(mesh: &TriMesh, original_to_new: Vec<u32>, vertex_map: Vec<u32>) -> Repaired {
    let positions = vertex_map
        .iter()
        .map(|&v| mesh.positions[v as usize])
        .collect();
    let map = |i: u32| original_to_new.get(i as usize).copied().unwrap_or(i);
    let triangles = mesh
        .triangles
        .iter()
        .map(|t| [map(t[0]), map(t[1]), map(t[2])])
        .collect();
    let uv = mesh.uv.clone();
    let mesh = TriMesh {
        positions,
        triangles,
        uv,
    };
    Repaired::faces_kept(mesh, vertex_map, original_to_new)
}

/// Merges vertices whose positions are within `tolerance` (Euclidean; `0.0` merges only
/// bit-identical positions). Each vertex is merged onto the first earlier vertex (in index
/// order) that is within `tolerance`, so groups never chain further than `tolerance` from
/// their representative. Non-finite positions are never merged. Faces are kept (a face
/// whose corners were merged together becomes degenerate: follow with
/// [`drop_degenerate_faces`]). Unreferenced vertices are welded too.
pub fn weld_vertices(mesh: &TriMesh, tolerance: f64) -> Repaired {
    let nv = mesh.n_vertices();
    let tol = if tolerance.is_finite() && tolerance > 0.0 {
        tolerance
    } else {
        0.0
    };
    let mut original_to_new = vec![NONE; nv];
    let mut vertex_map: Vec<u32> = Vec::new();
    if tol == 0.0 {
        let mut seen: HashMap<[u64; 3], u32> = HashMap::with_capacity(nv);
        for (v, p) in mesh.positions.iter().enumerate() {
            let new = vertex_map.len() as u32;
            let target = if p.iter().all(|c| c.is_finite()) {
                // -0.0 and 0.0 are the same position.
                let key = [p.x + 0.0, p.y + 0.0, p.z + 0.0].map(f64::to_bits);
                *seen.entry(key).or_insert(new)
            } else {
                new
            };
            if target == new {
                vertex_map.push(v as u32);
            }
            original_to_new[v] = target;
        }
    } else {
        // Hash grid with cell size = tolerance: candidates are in the 27 neighbouring cells.
        let mut grid: HashMap<[i64; 3], Vec<u32>> = HashMap::new();
        let cell = |x: f64| (x / tol).floor().clamp(-9.0e15, 9.0e15) as i64;
        for (v, p) in mesh.positions.iter().enumerate() {
            let new = vertex_map.len() as u32;
            let mut target = new;
            if p.iter().all(|c| c.is_finite()) {
                let c = [cell(p.x), cell(p.y), cell(p.z)];
                let mut best: Option<u32> = None;
                for dx in -1..=1 {
                    for dy in -1..=1 {
                        for dz in -1..=1 {
                            let key = [c[0] + dx, c[1] + dy, c[2] + dz];
                            for &rep in grid.get(&key).into_iter().flatten() {
                                let q = mesh.positions[vertex_map[rep as usize] as usize];
                                if (q - p).norm() <= tol && best.is_none_or(|b| rep < b) {
                                    best = Some(rep);
                                }
                            }
                        }
                    }
                }
                match best {
                    Some(b) => target = b,
                    None => grid.entry(c).or_default().push(new),
                }
            }
            if target == new {
                vertex_map.push(v as u32);
            }
            original_to_new[v] = target;
        }
    }
    remap_vertices(mesh, original_to_new, vertex_map)
}

/// Whether a face is unusable: an index out of range, a repeated index, a non-finite
/// corner, or (numerically) zero area by the same scale-relative test as validation.
fn is_bad_face(mesh: &TriMesh, f: usize) -> bool {
    let t = mesh.triangles[f];
    let nv = mesh.n_vertices();
    if t.iter().any(|&i| i as usize >= nv) || t[0] == t[1] || t[1] == t[2] || t[2] == t[0] {
        return true;
    }
    let [a, b, c] = mesh.corners(f);
    if ![a, b, c].iter().all(|p| p.iter().all(|x| x.is_finite())) {
        return true;
    }
    is_degenerate(a, b, c)
}

/// Drops faces with an out-of-range or repeated index, a non-finite corner, or zero area
/// (see [`crate::analyze::ZERO_AREA_RELATIVE_TOLERANCE`]). Vertices are unchanged.
pub fn drop_degenerate_faces(mesh: &TriMesh) -> Repaired {
    filter_faces(mesh, |f| !is_bad_face(mesh, f))
}

/// Drops every face that uses the same three vertices as an earlier face (in either
/// orientation). Vertices are unchanged.
pub fn drop_duplicate_faces(mesh: &TriMesh) -> Repaired {
    let mut keys: Vec<([u32; 3], u32)> = mesh
        .triangles
        .iter()
        .enumerate()
        .map(|(f, t)| {
            let mut k = *t;
            k.sort_unstable();
            (k, f as u32)
        })
        .collect();
    keys.sort_unstable();
    let mut dup = vec![false; mesh.n_faces()];
    for w in keys.windows(2) {
        if w[0].0 == w[1].0 {
            dup[w[1].1 as usize] = true;
        }
    }
    filter_faces(mesh, |f| !dup[f])
}

/// Drops vertices no face refers to, renumbering the rest in their original order.
/// Faces with out-of-range indices keep those indices unchanged (shifted into range they
/// would silently point at the wrong vertex); drop them first with
/// [`drop_degenerate_faces`].
pub fn drop_unreferenced_vertices(mesh: &TriMesh) -> Repaired {
    let nv = mesh.n_vertices();
    let mut used = vec![false; nv];
    for t in &mesh.triangles {
        for &i in t {
            if let Some(u) = used.get_mut(i as usize) {
                *u = true;
            }
        }
    }
    let mut original_to_new = vec![NONE; nv];
    let mut vertex_map = Vec::new();
    for v in 0..nv {
        if used[v] {
            original_to_new[v] = vertex_map.len() as u32;
            vertex_map.push(v as u32);
        }
    }
    let mut r = remap_vertices(mesh, original_to_new, vertex_map);
    // Out-of-range indices must stay out of range after renumbering.
    let new_nv = r.mesh.n_vertices() as u32;
    for (t, orig) in r.mesh.triangles.iter_mut().zip(&mesh.triangles) {
        for c in 0..3 {
            if orig[c] as usize >= nv {
                t[c] = orig[c].max(new_nv);
            }
        }
    }
    r
}

/// Keeps the faces of the connected component (faces sharing a vertex are connected) with
/// the most faces (the earliest such component on ties), then drops the vertices left
/// unreferenced. Unusable faces (out-of-range or repeated indices) are dropped too.
pub fn keep_largest_component(mesh: &TriMesh) -> Repaired {
    let nv = mesh.n_vertices();
    let usable: Vec<bool> = mesh
        .triangles
        .iter()
        .map(|t| {
            t.iter().all(|&i| (i as usize) < nv) && t[0] != t[1] && t[1] != t[2] && t[2] != t[0]
        })
        .collect();
    let comps = face_components(nv, &mesh.triangles, &usable);
    let mut sizes = vec![0usize; comps.count];
    for &c in &comps.of_face {
        if c != NONE {
            sizes[c as usize] += 1;
        }
    }
    // max_by_key returns the last maximum; iterate in reverse to prefer the earliest.
    let best = (0..comps.count).rev().max_by_key(|&c| sizes[c]);
    let faces = filter_faces(mesh, |f| Some(comps.of_face[f] as usize) == best);
    let verts = drop_unreferenced_vertices(&faces.mesh);
    faces.then(verts)
}

/// Applies the selected repairs in order, composing the index maps so that they refer to
/// the input mesh.
pub fn repair_all(mesh: &TriMesh, options: &RepairOptions) -> Repaired {
    let mut r = Repaired::identity(mesh);
    if let Some(tol) = options.weld {
        let next = weld_vertices(&r.mesh, tol);
        r = r.then(next);
    }
    if options.drop_degenerate_faces {
        let next = drop_degenerate_faces(&r.mesh);
        r = r.then(next);
    }
    if options.drop_duplicate_faces {
        let next = drop_duplicate_faces(&r.mesh);
        r = r.then(next);
    }
    if options.make_manifold {
        let next = make_manifold(&r.mesh);
        r = r.then(next);
    }
    if options.orient {
        let next = orient_faces(&r.mesh);
        r = r.then(next);
    }
    if options.keep_largest_component {
        let next = keep_largest_component(&r.mesh);
        r = r.then(next);
    }
    if options.drop_unreferenced_vertices {
        let next = drop_unreferenced_vertices(&r.mesh);
        r = r.then(next);
    }
    r
}
