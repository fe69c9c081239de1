//! Per-vertex tangent frames in R^8: two orthonormal rows spanning the tangent plane.
//!
//! * Interior vertex: Loop's limit tangent stencil over the cyclic one-ring.
//! * Boundary vertex: Loop's boundary rules. The ring is a fan `u_0 .. u_k` from one
//!   boundary neighbour to the other: the tangent along the boundary is `u_0 - u_k`, the
//!   one across it weights the interior neighbours by `sin(pi j / k)` (into the surface);
//!   for a single face, the direction to the midpoint of the opposite edge. Being
//!   one-sided, it converges linearly under refinement (interior: quadratically).
//! * Degenerate stencils (a vanishing or collinear pair): the best-fit plane of the
//!   one-ring edge vectors (principal components); if even that is degenerate (edges
//!   collapsed by the embedding), any orthonormal completion. Never NaN.

use wavg_mesh::ValidMesh;

use crate::{Mat2x8, Vec8};

/// Relative size below which a stencil vector counts as vanishing (or two as collinear).
const DEGENERATE: f64 = 1e-6;

/// How a vertex's frame was obtained.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum FrameKind {
    /// Loop's interior limit stencil.
    Interior,
    /// Loop's boundary rules.
    Boundary,
    /// Principal plane of the one-ring edges (degenerate stencil).
    Fitted,
    /// Arbitrary orthonormal completion (the one-ring spans less than a plane).
    Arbitrary,
}

/// Frames of every vertex, with how each was obtained.
pub fn vertex_frames(mesh: &ValidMesh, coords: &[Vec8]) -> Vec<(Mat2x8, FrameKind)> {
    (0..mesh.n_vertices())
        .map(|v| vertex_frame(mesh, coords, v as u32))
        .collect()
}

/// The frame of vertex `v`.
pub fn vertex_frame(mesh: &ValidMesh, coords: &[Vec8], v: u32) -> (Mat2x8, FrameKind) {
    let topo = mesh.topology();
    let ring = topo.ring(v);
    let c = coords[v as usize];
    let scale = ring
        .iter()
        .map(|&u| (coords[u as usize] - c).norm())
        .fold(0.0, f64::max);
    let (t1, t2, kind) = if topo.is_boundary_vertex(v) {
        let k = ring.len() - 1;
        // u_0 follows v on the boundary loop: (along, across) then has the orientation of
        // the interior stencil's (t1, t2).
        let along = coords[ring[0] as usize] - coords[ring[k] as usize];
        let across = if k == 1 {
            (coords[ring[0] as usize] + coords[ring[1] as usize]) * 0.5 - c
        } else {
            // Interior neighbours weighted by sin(pi j / k): into the surface. (Loop's
            // boundary stencil, Hoppe et al. 1994, measured slightly worse on smooth
            // open surfaces; both converge linearly, the one-ring being one-sided.)
            let th = std::f64::consts::PI / k as f64;
            let mut s = Vec8::zeros();
            for (j, &u) in ring.iter().enumerate().take(k).skip(1) {
                s += (coords[u as usize] - c) * (th * j as f64).sin();
            }
            s
        };
        (along, across, FrameKind::Boundary)
    } else {
        let k = ring.len();
        let mut t1 = Vec8::zeros();
        let mut t2 = Vec8::zeros();
        for (j, &u) in ring.iter().enumerate() {
            let a = 2.0 * std::f64::consts::PI * j as f64 / k as f64;
            let d = coords[u as usize] - c;
            t1 += d * a.cos();
            t2 += d * a.sin();
        }
        (t1, t2, FrameKind::Interior)
    };
    if let Some(f) = orthonormalize(&t1, &t2, scale) {
        return (f, kind);
    }
    let edges: Vec<Vec8> = ring.iter().map(|&u| coords[u as usize] - c).collect();
    let (mut f, kind) = fitted_frame(&edges, scale);
    orient_like_ring(&mut f, &edges, !topo.is_boundary_vertex(v));
    (f, kind)
}

/// Flips the second row if the frame's orientation disagrees with the (counter-clockwise)
/// ring's, so that neighbouring frames can be aligned by rotations.
fn orient_like_ring(f: &mut Mat2x8, edges: &[Vec8], cyclic: bool) {
    let n = edges.len();
    let pairs = if cyclic { n } else { n.saturating_sub(1) };
    let mut s = 0.0;
    for j in 0..pairs {
        let a = *f * edges[j];
        let b = *f * edges[(j + 1) % n];
        s += a[0] * b[1] - a[1] * b[0];
    }
    if s < 0.0 {
        let r = -f.row(1);
        f.row_mut(1).copy_from(&r);
    }
}

/// Gram-Schmidt of two stencil vectors, or `None` when they are (nearly) degenerate
/// relative to the ring size `scale`.
fn orthonormalize(t1: &Vec8, t2: &Vec8, scale: f64) -> Option<Mat2x8> {
    let n1 = t1.norm();
    if !(n1 > DEGENERATE * scale) || !n1.is_finite() {
        return None;
    }
    let e1 = t1 / n1;
    let r = t2 - e1 * e1.dot(t2);
    let n2 = r.norm();
    if !(n2 > DEGENERATE * t2.norm().max(DEGENERATE * scale)) || !(n2 > 1e-300) {
        return None;
    }
    let e2 = r / n2;
    Some(rows(&e1, &e2))
}

fn rows(e1: &Vec8, e2: &Vec8) -> Mat2x8 {
    let mut m = Mat2x8::zeros();
    m.row_mut(0).copy_from(&e1.transpose());
    m.row_mut(1).copy_from(&e2.transpose());
    m
}

/// Principal plane of the edge vectors; orthonormal completion if they span < 2 dims.
fn fitted_frame(edges: &[Vec8], scale: f64) -> (Mat2x8, FrameKind) {
    let mut cov = nalgebra::SMatrix::<f64, 8, 8>::zeros();
    for e in edges {
        cov += e * e.transpose();
    }
    let eig = nalgebra::SymmetricEigen::new(cov);
    let mut idx: Vec<usize> = (0..8).collect();
    idx.sort_by(|&a, &b| eig.eigenvalues[b].total_cmp(&eig.eigenvalues[a]));
    let l0 = eig.eigenvalues[idx[0]];
    let l1 = eig.eigenvalues[idx[1]];
    let tiny = (DEGENERATE * scale).powi(2);
    if l0.is_finite() && l1 > tiny && l1 > 1e-12 * l0 {
        let e1: Vec8 = eig.eigenvectors.column(idx[0]).into();
        let e2: Vec8 = eig.eigenvectors.column(idx[1]).into();
        if let Some(f) = orthonormalize(&e1, &e2, 1.0) {
            return (f, FrameKind::Fitted);
        }
    }
    // Complete whatever direction there is with coordinate axes.
    let first = if l0.is_finite() && l0 > 0.0 {
        let v: Vec8 = eig.eigenvectors.column(idx[0]).into();
        v
    } else {
        Vec8::x()
    };
    let n = first.norm();
    let e1 = if n.is_finite() && n > 0.0 {
        first / n
    } else {
        Vec8::x()
    };
    for axis in 0..8 {
        let mut a = Vec8::zeros();
        a[axis] = 1.0;
        if let Some(f) = orthonormalize(&e1, &a, 1.0) {
            return (f, FrameKind::Arbitrary);
        }
    }
    (rows(&Vec8::x(), &Vec8::y()), FrameKind::Arbitrary)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn fitted_frame_of_planar_edges_spans_them() {
        let mut e = vec![Vec8::zeros(); 3];
        e[0][0] = 1.0;
        e[1][1] = 2.0;
        e[2][0] = -1.0;
        e[2][1] = -1.0;
        let (f, k) = fitted_frame(&e, 2.0);
        assert_eq!(k, FrameKind::Fitted);
        for v in &e {
            let inplane = f.transpose() * (f * v);
            assert!((inplane - v).norm() < 1e-12);
        }
    }

    #[test]
    fn collapsed_ring_gives_an_orthonormal_frame() {
        let e = vec![Vec8::zeros(); 4];
        let (f, k) = fitted_frame(&e, 0.0);
        assert_eq!(k, FrameKind::Arbitrary);
        let g = f * f.transpose();
        assert!((g - nalgebra::Matrix2::identity()).norm() < 1e-12);
    }
}
