//! Decals (local parametrisation, paper Section 4): anchors carry plane coordinates
//! `(u, v)`; a surface point with weights `w` (inverse problem, the paper's weights, which
//! vary continuously over the surface) gets `uv = sum_i w_i uv_i`. Where the weights are not
//! meaningful (they do not return to the point through the forward problem, or one is
//! strongly negative) the coordinates are still computed but the point is marked; a point
//! whose weighted sum overflows (huge anchor coordinates) is marked with (0, 0). A point
//! its weights already mark skips its forward problem (the marks stay the same).

use nalgebra::Vector3;
use wavg_mesh::SurfacePoint;
use wavg_solve::{ForwardOptions, SolveError, Solver};

use crate::correspond::{ROUND_TRIP_TOLERANCE, vertex_points};
use crate::metrics::{Distortion, distortion};

/// Default most negative weight a decal point's weights may hold before it is marked, in
/// every front end.
pub const DEFAULT_MAX_NEGATIVE: f64 = -0.1;

/// Checks a `max_negative`, the most negative weight a point's weights may hold (decals,
/// the paper's validity test of a correspondence): finite and at most 0. Above 0 it would
/// mark nearly every point (most of a point's weights are small), so such a value is a
/// mistake (a sign left out), refused with the range named.
///
/// ```
/// assert!(wavg_apps::check_max_negative(-0.1).is_ok());
/// assert!(wavg_apps::check_max_negative(-1e9).is_ok());
/// let e = wavg_apps::check_max_negative(5.0).unwrap_err().to_string();
/// assert!(e.contains("at most 0"), "{e}");
/// ```
pub fn check_max_negative(max_negative: f64) -> Result<(), SolveError> {
    if max_negative.is_finite() && max_negative <= 0.0 {
        return Ok(());
    }
    Err(SolveError::InvalidParameter(format!(
        "max_negative must be a finite weight of at most 0 (the most negative weight \
         accepted, {DEFAULT_MAX_NEGATIVE} by default), got {max_negative}"
    )))
}

/// The coordinates of surface points.
#[derive(Clone, Debug, PartialEq)]
pub struct DecalUv {
    /// Per point: `(u, v)` (`[0, 0]` where the inverse problem failed).
    pub uv: Vec<[f64; 2]>,
    /// Per point: the weights are not meaningful (inverse failed, no round trip, or a
    /// weight below the limit).
    pub marked: Vec<bool>,
}

/// `(u, v)` of each point from the anchors' `uv` (one per anchor); points are marked as
/// described in the module docs with `max_negative` the most negative weight accepted.
///
/// ```
/// use std::sync::Arc;
/// use wavg_mesh::{ValidMesh, procedural};
/// use wavg_project::{EmbeddedMesh, Projector};
/// use wavg_solve::{Anchor, Solver};
/// use wavg_apps::decal_uv;
/// let mesh = Arc::new(ValidMesh::new(procedural::icosphere(3)).unwrap());
/// let proj = Arc::new(Projector::new(Arc::new(EmbeddedMesh::from_positions(mesh))).unwrap());
/// let solver = Solver::new(proj, [0u32, 1, 2].map(Anchor::Vertex)).unwrap();
/// let at = solver.anchors().point(1).unwrap();
/// let d = decal_uv(&solver, &[[0.0, 0.0], [1.0, 0.0], [0.0, 1.0]], &[at], -0.1).unwrap();
/// assert!((d.uv[0][0] - 1.0).abs() < 1e-6 && d.uv[0][1].abs() < 1e-6); // an anchor's own uv
/// ```
pub fn decal_uv(
    solver: &Solver,
    uv: &[[f64; 2]],
    points: &[SurfacePoint],
    max_negative: f64,
) -> Result<DecalUv, SolveError> {
    if uv.len() != solver.n_anchors() {
        return Err(SolveError::InvalidParameter(format!(
            "{} (u, v) pairs for {} anchors; give one per anchor",
            uv.len(),
            solver.n_anchors()
        )));
    }
    if let Some(bad) = uv.iter().flatten().find(|x| !x.is_finite()) {
        return Err(SolveError::InvalidParameter(format!(
            "the (u, v) coordinates must be finite, got {bad}"
        )));
    }
    check_max_negative(max_negative)?;
    let batch = solver.inverse_batch(points);
    let (mut out, mut marked) = (Vec::with_capacity(points.len()), Vec::new());
    // Points not marked by their weights alone; only these need their forward problem.
    let mut check = Vec::new();
    for (i, w) in batch.iter().enumerate() {
        match w {
            Ok(w) => {
                let mut p = [0.0; 2];
                for (wi, c) in w.iter().zip(uv) {
                    p[0] += wi * c[0];
                    p[1] += wi * c[1];
                }
                let min = w.iter().copied().fold(f64::INFINITY, f64::min);
                // Huge (u, v) can overflow the weighted sum: such a point is not usable.
                let finite = p.iter().all(|x| x.is_finite());
                out.push(if finite { p } else { [0.0, 0.0] });
                let bad = min < max_negative || !finite;
                marked.push(bad);
                if !bad {
                    check.push(i);
                }
            }
            Err(_) => {
                out.push([0.0, 0.0]);
                marked.push(true);
            }
        }
    }
    let rows: Vec<&[f64]> = check.iter().map(|&i| batch.get(i).unwrap_or(&[])).collect();
    let back = solver.forward_batch(&rows, &ForwardOptions::default());
    let mesh = solver.mesh();
    let tol = ROUND_TRIP_TOLERANCE * solver.mean_edge_length();
    for (&i, b) in check.iter().zip(&back) {
        let p = points[i].position(mesh);
        if !b.as_ref().is_ok_and(|b| (b.position - p).norm() <= tol) {
            marked[i] = true;
        }
    }
    Ok(DecalUv { uv: out, marked })
}

/// A decal over every vertex of the solver's mesh, with the distortion of the map from
/// the surface to the plane over the unmarked vertices (flips judged against the
/// orientation of most of the decal's area).
#[derive(Clone, Debug)]
pub struct Decal {
    /// Per vertex coordinates and marks.
    pub uv: DecalUv,
    /// Distortion of the surface-to-plane map on faces with three unmarked corners.
    pub distortion: Distortion,
}

/// What a decal over every vertex came to; with the `serde` feature, the `wavg decal
/// --json` keys (the [`Distortion`] totals without `measured_faces`).
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
pub struct DecalReport {
    /// Vertices.
    pub vertices: usize,
    /// Unmarked vertices over all vertices (0 for an empty mesh).
    pub valid_fraction: f64,
    /// [`Distortion::stretch`]; `None` when no face was measured unflipped.
    pub stretch: Option<f64>,
    /// [`Distortion::stretch_best95`]; `None` when no face was measured unflipped.
    pub stretch_best95: Option<f64>,
    /// [`Distortion::flipped_faces`].
    pub flipped_faces: usize,
    /// [`Distortion::flipped_area_fraction`].
    pub flipped_area_fraction: f64,
}

impl Decal {
    /// The decal's [`DecalReport`].
    pub fn report(&self) -> DecalReport {
        let n = self.uv.marked.len();
        let unmarked = self.uv.marked.iter().filter(|m| !**m).count();
        let d = &self.distortion;
        DecalReport {
            vertices: n,
            valid_fraction: unmarked as f64 / n.max(1) as f64,
            stretch: d.has_stretch().then_some(d.stretch),
            stretch_best95: d.has_stretch().then_some(d.stretch_best95),
            flipped_faces: d.flipped_faces,
            flipped_area_fraction: d.flipped_area_fraction,
        }
    }
}

/// [`decal_uv`] at every vertex of the solver's mesh (without the distortion
/// [`decal_vertices`] adds).
pub fn decal_vertex_uv(
    solver: &Solver,
    uv: &[[f64; 2]],
    max_negative: f64,
) -> Result<DecalUv, SolveError> {
    decal_uv(solver, uv, &vertex_points(solver.mesh()), max_negative)
}

/// [`decal_uv`] at every vertex of the solver's mesh, with the map's [`Distortion`].
pub fn decal_vertices(
    solver: &Solver,
    uv: &[[f64; 2]],
    max_negative: f64,
) -> Result<Decal, SolveError> {
    let mesh = solver.mesh();
    let d = decal_vertex_uv(solver, uv, max_negative)?;
    let plane: Vec<Option<Vector3<f64>>> =
        d.uv.iter()
            .zip(&d.marked)
            .map(|(p, &m)| (!m).then_some(Vector3::new(p[0], p[1], 0.0)))
            .collect();
    // The decal's orientation: the sign of its total signed area.
    let signed: f64 = mesh
        .triangles
        .iter()
        .filter_map(|t| {
            let [a, b, c] = t.map(|v| plane[v as usize]);
            Some((b? - a?).cross(&(c? - a?)).z)
        })
        .sum();
    let up = Vector3::z() * if signed < 0.0 { -1.0 } else { 1.0 };
    let normals = vec![Some(up); mesh.n_faces()];
    let distortion = distortion(&mesh.positions, &mesh.triangles, &plane, &normals);
    Ok(Decal { uv: d, distortion })
}

#[cfg(test)]
mod tests {
    use std::sync::Arc;

    use wavg_mesh::{TriMesh, ValidMesh};
    use wavg_project::{EmbeddedMesh, Projector};
    use wavg_solve::Anchor;

    use super::*;

    /// A flat grid in the z = 0 plane, `n` by `n` squares of side 1/n.
    fn grid(n: u32) -> TriMesh {
        let mut pts = Vec::new();
        let mut tris = Vec::new();
        for j in 0..=n {
            for i in 0..=n {
                pts.push(Vector3::new(f64::from(i), f64::from(j), 0.0) / f64::from(n));
            }
        }
        for j in 0..n {
            for i in 0..n {
                let a = j * (n + 1) + i;
                tris.push([a, a + 1, a + n + 2]);
                tris.push([a, a + n + 2, a + n + 1]);
            }
        }
        TriMesh::new(pts, tris)
    }

    #[test]
    fn anchors_with_their_own_xy_reproduce_a_flat_grid() {
        let n = 20;
        let mesh = Arc::new(ValidMesh::new(grid(n)).unwrap());
        let proj = Projector::new(Arc::new(EmbeddedMesh::from_positions(mesh.clone()))).unwrap();
        let ids: Vec<u32> = (0..(n + 1) * (n + 1)).step_by(37).collect();
        let solver = Solver::new(Arc::new(proj), ids.iter().map(|&v| Anchor::Vertex(v))).unwrap();
        let uv: Vec<[f64; 2]> = ids
            .iter()
            .map(|&v| [mesh.positions[v as usize].x, mesh.positions[v as usize].y])
            .collect();
        let d = decal_vertices(&solver, &uv, -0.1).unwrap();
        // Weights reproduce affine functions on a plane: uv = xy wherever they return.
        for (v, (p, &m)) in d.uv.uv.iter().zip(&d.uv.marked).enumerate() {
            if !m {
                let q = mesh.positions[v];
                assert!(
                    (p[0] - q.x).abs() < 1e-6 && (p[1] - q.y).abs() < 1e-6,
                    "{v}"
                );
            }
        }
        let valid = d.uv.marked.iter().filter(|m| !**m).count();
        assert!(valid as f64 > 0.5 * mesh.n_vertices() as f64, "{valid}");
        assert!((d.distortion.stretch - 1.0).abs() < 1e-6);
        assert_eq!(d.distortion.flipped_faces, 0);
        // Mirrored uv: the same, all orientation-consistent (the decal's own orientation).
        let mirrored: Vec<[f64; 2]> = uv.iter().map(|p| [-p[0], p[1]]).collect();
        let m = decal_vertices(&solver, &mirrored, -0.1).unwrap();
        assert_eq!(m.distortion.flipped_faces, 0);
    }

    /// The marks as they were before points marked by their weights skipped their forward
    /// problem: every point's round trip checked.
    fn marks_checking_every_point(
        solver: &Solver,
        uv: &[[f64; 2]],
        points: &[SurfacePoint],
        max_negative: f64,
    ) -> Vec<bool> {
        let (batch, trips) = crate::correspond::paper_round_trip(solver, points);
        batch
            .iter()
            .zip(trips)
            .map(|(w, trip)| match w {
                Ok(w) => {
                    let min = w.iter().copied().fold(f64::INFINITY, f64::min);
                    let p = w
                        .iter()
                        .zip(uv)
                        .fold([0.0; 2], |p, (wi, c)| [p[0] + wi * c[0], p[1] + wi * c[1]]);
                    !trip || min < max_negative || !p.iter().all(|x| x.is_finite())
                }
                Err(_) => true,
            })
            .collect()
    }

    #[test]
    fn skipping_the_forward_problem_of_marked_points_keeps_every_mark() {
        // A small generator (splitmix64) for the anchors and their coordinates.
        let mut state = 3u64;
        let mut next = move || {
            state = state.wrapping_add(0x9e37_79b9_7f4a_7c15);
            let mut z = state;
            z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
            z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
            z ^ (z >> 31)
        };
        let mesh = Arc::new(ValidMesh::new(wavg_mesh::procedural::icosphere(4)).unwrap());
        let proj =
            Arc::new(Projector::new(Arc::new(EmbeddedMesh::from_positions(mesh.clone()))).unwrap());
        let mut checked = 0;
        for case in 0..6 {
            let k = 4 + 3 * case;
            let ids: Vec<u32> = (0..k)
                .map(|_| (next() % mesh.n_vertices() as u64) as u32)
                .collect();
            let Ok(solver) = Solver::new(proj.clone(), ids.iter().map(|&v| Anchor::Vertex(v)))
            else {
                continue;
            };
            let mut unit = || (next() >> 11) as f64 / (1u64 << 53) as f64 * 2.0 - 1.0;
            let uv: Vec<[f64; 2]> = (0..k).map(|_| [unit(), unit()]).collect();
            let points = vertex_points(&mesh);
            for max_negative in [-0.1, -0.5, -1e9] {
                let d = decal_uv(&solver, &uv, &points, max_negative).unwrap();
                let want = marks_checking_every_point(&solver, &uv, &points, max_negative);
                assert_eq!(d.marked, want, "case {case}, max_negative {max_negative}");
                checked += 1;
                // Some points are marked by their weights and some by their round trip.
                if max_negative == -0.1 {
                    assert!(d.marked.iter().any(|m| *m) && d.marked.iter().any(|m| !*m));
                }
            }
        }
        assert!(checked >= 12, "{checked}");
    }

    #[test]
    fn uv_count_must_match() {
        let mesh = Arc::new(ValidMesh::new(grid(4)).unwrap());
        let proj = Projector::new(Arc::new(EmbeddedMesh::from_positions(mesh))).unwrap();
        let solver = Solver::new(Arc::new(proj), [0u32, 4, 24].map(Anchor::Vertex)).unwrap();
        assert!(decal_vertices(&solver, &[[0.0, 0.0]], -0.1).is_err());
        let nan = [[f64::NAN, 0.0], [0.0, 0.0], [1.0, 1.0]];
        assert!(decal_vertices(&solver, &nan, -0.1).is_err());
    }
}
