//! Morphing: the source's connectivity with its vertices moved onto the target. Vertices
//! without a trusted image are filled harmonically (each becomes the average of its
//! neighbours, the trusted ones held fixed: the discrete Laplace equation with the
//! uniform Laplacian, solved by Gauss-Seidel), then frames blend linearly between the
//! source positions and the mapped ones.

use nalgebra::Vector3;
use wavg_mesh::ValidMesh;
use wavg_solve::SolveError;

/// Gauss-Seidel sweeps at most.
const MAX_SWEEPS: usize = 20_000;

/// Every vertex's position: `known[v]` where given, elsewhere the harmonic fill from the
/// known ones (see the module docs). An error when a connected component has no known
/// vertex (nothing to fill from).
///
/// ```
/// use nalgebra::Vector3;
/// use wavg_mesh::{ValidMesh, procedural};
/// use wavg_apps::harmonic_fill;
/// let mesh = ValidMesh::new(procedural::icosphere(2)).unwrap();
/// let mut known: Vec<_> = mesh.positions.iter().map(|&p| Some(p * 2.0)).collect();
/// known[7] = None;
/// let filled = harmonic_fill(&mesh, &known).unwrap();
/// let ring = mesh.topology().ring(7);
/// let mean = ring.iter().map(|&u| filled[u as usize]).sum::<Vector3<f64>>() / ring.len() as f64;
/// assert!((filled[7] - mean).norm() < 1e-9);
/// ```
pub fn harmonic_fill(
    mesh: &ValidMesh,
    known: &[Option<Vector3<f64>>],
) -> Result<Vec<Vector3<f64>>, SolveError> {
    let n = mesh.n_vertices();
    if known.len() != n {
        return Err(SolveError::InvalidParameter(format!(
            "{} positions for {n} vertices",
            known.len()
        )));
    }
    let topo = mesh.topology();
    // Start: breadth-first from the known vertices, each new vertex the mean of its
    // already reached neighbours (a good first guess, so few sweeps are needed).
    let mut pos: Vec<Option<Vector3<f64>>> = known.to_vec();
    let mut frontier: Vec<u32> = (0..n as u32)
        .filter(|&v| pos[v as usize].is_some())
        .collect();
    while !frontier.is_empty() {
        let mut next = Vec::new();
        for &v in &frontier {
            for &u in topo.ring(v) {
                if pos[u as usize].is_none() {
                    next.push(u);
                }
            }
        }
        next.sort_unstable();
        next.dedup();
        let vals: Vec<Option<Vector3<f64>>> = next
            .iter()
            .map(|&u| {
                let reached: Vec<Vector3<f64>> = topo
                    .ring(u)
                    .iter()
                    .filter_map(|&w| pos[w as usize])
                    .collect();
                (!reached.is_empty())
                    .then(|| reached.iter().sum::<Vector3<f64>>() / reached.len() as f64)
            })
            .collect();
        for (&u, p) in next.iter().zip(vals) {
            pos[u as usize] = p;
        }
        frontier = next;
    }
    let mut out = Vec::with_capacity(n);
    for (v, p) in pos.iter().enumerate() {
        match p {
            Some(p) => out.push(*p),
            None => {
                return Err(SolveError::InvalidParameter(format!(
                    "vertex {v} lies in a part of the mesh without any mapped vertex"
                )));
            }
        }
    }
    let free: Vec<usize> = (0..n).filter(|&v| known[v].is_none()).collect();
    let scale = mesh.bounding_box_diagonal().max(f64::MIN_POSITIVE);
    for _ in 0..MAX_SWEEPS {
        let mut change = 0.0f64;
        for &v in &free {
            let ring = topo.ring(v as u32);
            let mean = ring.iter().map(|&u| out[u as usize]).sum::<Vector3<f64>>()
                / ring.len().max(1) as f64;
            change = change.max((mean - out[v]).norm());
            out[v] = mean;
        }
        if change <= 1e-12 * scale {
            break;
        }
    }
    Ok(out)
}

/// What a morph came to; with the `serde` feature, the `wavg morph --json` keys.
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
pub struct MorphReport {
    /// Frames written.
    pub frames: usize,
    /// Vertices mapped directly (the rest filled by [`harmonic_fill`]) over all vertices.
    pub valid_fraction: f64,
}

/// `frames` positions blending linearly from `from` (frame 0) to `to` (the last frame);
/// a single frame is `to`, the morph's result.
pub fn morph_frames(
    from: &[Vector3<f64>],
    to: &[Vector3<f64>],
    frames: usize,
) -> Vec<Vec<Vector3<f64>>> {
    (0..frames)
        .map(|k| {
            let t = if frames > 1 {
                k as f64 / (frames - 1) as f64
            } else {
                1.0
            };
            from.iter().zip(to).map(|(a, b)| a + (b - a) * t).collect()
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use wavg_mesh::procedural;

    use super::*;

    #[test]
    fn fill_is_harmonic_and_keeps_known_values() {
        let mesh = ValidMesh::new(procedural::icosphere(3)).unwrap();
        // Known: a linear function of position on half the vertices.
        let f = |p: Vector3<f64>| Vector3::new(p.x + 2.0 * p.y, p.z, 1.0);
        let known: Vec<_> = mesh
            .positions
            .iter()
            .map(|&p| (p.z > 0.2 || p.z < -0.5).then(|| f(p)))
            .collect();
        let filled = harmonic_fill(&mesh, &known).unwrap();
        let topo = mesh.topology();
        for v in 0..mesh.n_vertices() {
            if let Some(k) = known[v] {
                assert_eq!(filled[v], k);
            } else {
                let ring = topo.ring(v as u32);
                let mean = ring
                    .iter()
                    .map(|&u| filled[u as usize])
                    .sum::<Vector3<f64>>()
                    / ring.len() as f64;
                assert!((filled[v] - mean).norm() < 1e-8, "{v}");
                // Constant third coordinate stays constant (maximum principle).
                assert!((filled[v].z - 1.0).abs() < 1e-9);
            }
        }
    }

    #[test]
    fn nothing_known_is_an_error() {
        let mesh = ValidMesh::new(procedural::icosphere(1)).unwrap();
        assert!(harmonic_fill(&mesh, &vec![None; mesh.n_vertices()]).is_err());
        assert!(harmonic_fill(&mesh, &[]).is_err());
    }

    #[test]
    fn frames_run_from_source_to_target() {
        let a = vec![Vector3::zeros(), Vector3::x()];
        let b = vec![Vector3::y(), Vector3::new(3.0, 0.0, 0.0)];
        let f = morph_frames(&a, &b, 3);
        assert_eq!(f.len(), 3);
        assert_eq!(f[0], a);
        assert_eq!(f[2], b);
        assert_eq!(f[1][1], Vector3::new(2.0, 0.0, 0.0));
        assert_eq!(morph_frames(&a, &b, 1), vec![b]);
    }
}
