//! Making a mesh manifold without losing surface: vertices are split into one copy per
//! fan of faces, and consistent orientation is restored by flipping faces.

use crate::mesh::TriMesh;
use crate::topology::UnionFind;

use super::types::Repaired;
use super::{drop_unreferenced_vertices, filter_faces};

/// Rounds of split-then-drop before giving up on an edge with more than two faces.
const MAX_ROUNDS: usize = 4;

/// Every undirected edge as `(lo, hi, face, corner)` sorted by edge: `corner` is the
/// corner of `face` where the edge starts (the edge runs from corner `c` to `c + 1`).
/// Faces with an out-of-range or repeated index are skipped.
fn sorted_edges(mesh: &TriMesh) -> Vec<(u32, u32, u32, u8)> {
    let nv = mesh.n_vertices();
    let mut edges = Vec::with_capacity(3 * mesh.n_faces());
    for (f, t) in mesh.triangles.iter().enumerate() {
        if t.iter().any(|&i| i as usize >= nv) || t[0] == t[1] || t[1] == t[2] || t[2] == t[0] {
            continue;
        }
        for c in 0..3 {
            let (a, b) = (t[c], t[(c + 1) % 3]);
            edges.push((a.min(b), a.max(b), f as u32, c as u8));
        }
    }
    edges.sort_unstable();
    edges
}

/// The runs of `edges` that share one undirected edge.
fn edge_groups(edges: &[(u32, u32, u32, u8)]) -> impl Iterator<Item = &[(u32, u32, u32, u8)]> {
    edges.chunk_by(|x, y| (x.0, x.1) == (y.0, y.1))
}

/// Splits every vertex whose faces form several fans (groups of faces joined through
/// edges that have exactly two faces) into one vertex per fan: the fan holding the
/// vertex's first corner keeps its index, the others get new vertices appended at the
/// end with the same position. An edge with three or more faces joins none of them, so
/// its sheets come apart. Faces, their order and their texture coordinates are unchanged;
/// original vertex indices still name the same vertex (`original_to_new` is the identity).
pub fn split_nonmanifold_vertices(mesh: &TriMesh) -> Repaired {
    let nv = mesh.n_vertices();
    let nf = mesh.n_faces();
    let mut uf = UnionFind::new(3 * nf);
    let edges = sorted_edges(mesh);
    for group in edge_groups(&edges) {
        if let &[(_, _, f, c), (_, _, g, _)] = group {
            let (tf, tg) = (mesh.triangles[f as usize], mesh.triangles[g as usize]);
            // Join the corners of the two faces at each end of the edge.
            for x in [c as usize, (c as usize + 1) % 3] {
                let v = tf[x];
                if let Some(y) = tg.iter().position(|&w| w == v) {
                    uf.union(3 * f as usize + x, 3 * g as usize + y);
                }
            }
        }
    }
    let mut triangles = mesh.triangles.clone();
    let mut positions = mesh.positions.clone();
    let mut vertex_map: Vec<u32> = (0..nv as u32).collect();
    // For each vertex, the fan root that kept the original index.
    let mut owner = vec![usize::MAX; nv];
    // New vertex of each other fan root, found by its root corner.
    let mut copy = std::collections::HashMap::new();
    for (f, t) in mesh.triangles.iter().enumerate() {
        for (c, &v) in t.iter().enumerate() {
            let Some(own) = owner.get_mut(v as usize) else {
                continue;
            };
            let root = uf.find(3 * f + c);
            if *own == usize::MAX {
                *own = root;
            } else if *own != root {
                let new = *copy.entry(root).or_insert_with(|| {
                    positions.push(mesh.positions[v as usize]);
                    vertex_map.push(v);
                    (positions.len() - 1) as u32
                });
                triangles[f][c] = new;
            }
        }
    }
    let uv = mesh.uv.clone();
    let mesh = TriMesh {
        positions,
        triangles,
        uv,
    };
    Repaired::faces_kept(mesh, vertex_map, (0..nv as u32).collect())
}

/// Drops, on every edge with more than two faces, all faces but the first two (in face
/// order). Vertices are unchanged.
fn drop_extra_edge_faces(mesh: &TriMesh) -> Option<Repaired> {
    let mut drop = vec![false; mesh.n_faces()];
    let mut any = false;
    for g in edge_groups(&sorted_edges(mesh)) {
        if g.len() > 2 {
            let mut faces: Vec<u32> = g.iter().map(|e| e.2).collect();
            faces.sort_unstable();
            for &f in &faces[2..] {
                drop[f as usize] = true;
                any = true;
            }
        }
    }
    any.then(|| filter_faces(mesh, |f| !drop[f]))
}

/// Makes the mesh manifold: splits vertices into fans
/// ([`split_nonmanifold_vertices`]); where an edge still has more than two faces (sheets
/// that also share their other corners), drops the extra faces and splits again; then
/// drops vertices left unreferenced.
pub fn make_manifold(mesh: &TriMesh) -> Repaired {
    let mut r = Repaired::identity(mesh);
    for _ in 0..MAX_ROUNDS {
        let split = split_nonmanifold_vertices(&r.mesh);
        r = r.then(split);
        match drop_extra_edge_faces(&r.mesh) {
            Some(next) => r = r.then(next),
            None => break,
        }
    }
    let next = drop_unreferenced_vertices(&r.mesh);
    r.then(next)
}

/// Flips faces so that neighbours across every two-face edge traverse it in opposite
/// directions, component by component (breadth first from each component's first face,
/// which keeps its orientation). Where no consistent orientation exists (a Möbius strip)
/// the faces reached first win and the rest stay inconsistent. A flipped face swaps its
/// last two corners, and its texture coordinates with them; positions, vertex and face
/// order are unchanged.
pub fn orient_faces(mesh: &TriMesh) -> Repaired {
    let nf = mesh.n_faces();
    let edges = sorted_edges(mesh);
    // Neighbour across each corner's edge (two-face edges only), with whether the two
    // faces traverse the edge in the same direction.
    let mut across = vec![(u32::MAX, false); 3 * nf];
    for group in edge_groups(&edges) {
        if let &[(_, _, f, c), (_, _, g, d)] = group {
            let tf = mesh.triangles[f as usize];
            let tg = mesh.triangles[g as usize];
            let same = tf[c as usize] == tg[d as usize];
            across[3 * f as usize + c as usize] = (g, same);
            across[3 * g as usize + d as usize] = (f, same);
        }
    }
    let mut flip = vec![false; nf];
    let mut seen = vec![false; nf];
    let mut queue = std::collections::VecDeque::new();
    for start in 0..nf {
        if seen[start] {
            continue;
        }
        seen[start] = true;
        queue.push_back(start);
        while let Some(f) = queue.pop_front() {
            for c in 0..3 {
                let (g, same) = across[3 * f + c];
                if g == u32::MAX || seen[g as usize] {
                    continue;
                }
                seen[g as usize] = true;
                // Consistent when the directions differ after both faces' flips.
                flip[g as usize] = flip[f] ^ same;
                queue.push_back(g as usize);
            }
        }
    }
    let mut out = mesh.clone();
    for (f, &fl) in flip.iter().enumerate() {
        if fl {
            out.triangles[f].swap(1, 2);
            if let Some(uv) = out.uv.as_mut().and_then(|uv| uv.faces.get_mut(f)) {
                uv.swap(1, 2);
            }
        }
    }
    let nv = mesh.n_vertices() as u32;
    Repaired::faces_kept(out, (0..nv).collect(), (0..nv).collect())
}
