//! Kimmel and Sethian's unfolding: splitting an obtuse corner by a virtual edge to a
//! vertex found across the opposite edge.

use super::*;

/// The vertex `W` found by unfolding, and the 2-D vectors from `x` to `A`, `W`, `B`.
pub(super) type Split = (u32, Vector2<f64>, Vector2<f64>, Vector2<f64>);

/// Splits the obtuse corner `k` of face `f` (Kimmel & Sethian's unfolding). Returns the
/// vertex `W` found and the 2-D vectors from `x` to `A`, `W`, `B` in the unfolded plane.
pub(super) fn unfold(
    mesh: &ValidMesh,
    f: u32,
    k: usize,
    topo: &wavg_mesh::Topology,
) -> Option<Split> {
    let pos = &mesh.positions;
    let t = mesh.triangles[f as usize];
    let x = t[k];
    let (a, b) = (t[(k + 1) % 3], t[(k + 2) % 3]);
    let px = pos[x as usize];
    let va = pos[a as usize] - px;
    let vb = pos[b as usize] - px;
    let la = va.norm();
    let a2 = Vector2::new(la, 0.0);
    let b2 = Vector2::new(va.dot(&vb) / la, va.cross(&vb).norm() / la);
    // Current edge (p, r) with p on A's side and r on B's side, crossed from face `face`.
    let (mut p, mut r) = (a, b);
    let (mut p2, mut r2) = (a2, b2);
    let mut face = f;
    for _ in 0..MAX_UNFOLD_STEPS {
        let next = across(mesh, topo, face, p, r)?;
        let tn = mesh.triangles[next as usize];
        let w = tn.into_iter().find(|&v| v != p && v != r)?;
        if w == x {
            return None;
        }
        let w2 = super::near_field::place(
            &p2,
            &r2,
            (pos[w as usize] - pos[p as usize]).norm(),
            (pos[w as usize] - pos[r as usize]).norm(),
        )?;
        let (da, db) = (w2.dot(&a2), w2.dot(&b2));
        if da > 0.0 && db > 0.0 {
            return Some((w, a2, w2, b2));
        }
        if db <= 0.0 {
            // W is on A's side of the section: continue across (W, r).
            p = w;
            p2 = w2;
        } else {
            r = w;
            r2 = w2;
        }
        face = next;
    }
    None
}

/// The face on the other side of edge `{p, r}` of `face`, if any.
pub(super) fn across(
    mesh: &ValidMesh,
    topo: &wavg_mesh::Topology,
    face: u32,
    p: u32,
    r: u32,
) -> Option<u32> {
    let t = mesh.triangles[face as usize];
    for i in 0..3 {
        let (s, e) = (t[i], t[(i + 1) % 3]);
        if (s == p && e == r) || (s == r && e == p) {
            let g = topo.face_neighbors(face)[i];
            return (g != NONE).then_some(g);
        }
    }
    None
}
