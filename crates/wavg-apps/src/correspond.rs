//! Correspondence between two surfaces with paired anchors (paper Section 4.4): a point of
//! the source has weights with respect to the source's anchors (inverse problem); the same
//! weights averaged over the target's anchors give its image (forward problem).
//!
//! Which images to trust. The paper keeps a point when its weights are meaningful: the
//! forward problem on the source brings them back to the point (the round trip) and no
//! weight is strongly negative ([`ValidityTest::Paper`]). That test judges the *weights*,
//! not the *image*: on two poses of one shape most rejected points still land within a
//! fraction of a percent of the truth, while a wrong image (one that lands on another
//! part of the target) can have harmless-looking weights. [`ValidityTest::Local`] judges
//! the image by its neighbourhood instead: a continuous map sends the segments from a
//! vertex to the edge of its neighbourhood to short segments, so a vertex is rejected when
//! most of them are stretched beyond `max_stretch` times the map's median edge stretch, or
//! when its image is not answered or does not round trip. A vertex's neighbourhood is a
//! disc of half a percent of the source's diagonal (its one-ring on coarse meshes; at most
//! 256 vertices): judged edge by edge, an image a fraction of an edge off stretches and
//! flips the edges of a fine mesh although it lands well within 1% of the truth (on the
//! procedural body pair a one-ring test kept 0.956 of the vertices, 0.888 after two Loop
//! subdivisions; the disc 0.987 and 0.969). A wrongly mapped vertex, or a wrong patch
//! smaller than the disc, spoils all its segments but few of each correct neighbour's, so
//! the rejection does not spread far. A vertex is also rejected when two thirds of the
//! triangles around its neighbourhood land flipped (their normal disagrees with the
//! target's) where the target is smooth at the scale of its edges; on thin parts
//! (fingers) images a fraction of an edge off flip triangles while landing well within 1%
//! of the diagonal, so flips there are no reason (on the procedural figure pair,
//! rejecting vertices amid any flipped triangles kept 0.884 of the vertices, this test
//! 0.999). The test itself is in `local_test.rs`.

use std::time::Instant;

use nalgebra::Vector3;
use rayon::prelude::*;
use wavg_mesh::{SurfacePoint, ValidMesh};
use wavg_solve::{BatchWeights, ForwardOptions, ForwardResult, Par, RoundTrip, SolveError, Solver};

use crate::decal::check_max_negative;
use crate::local_test::inconsistent_vertices;
use crate::metrics::{Distortion, distortion};

/// Round-trip tolerance of the paper's weights, in mean edge lengths of the source.
pub const ROUND_TRIP_TOLERANCE: f64 = 1e-3;

/// Which points of a map are kept (see the module docs).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ValidityTest {
    /// The paper's: the weights round-trip on the source and none is below
    /// `max_negative`.
    Paper,
    /// The image is consistent with its neighbourhood's (no majority of over-stretched
    /// segments to the neighbourhood's edge, no two thirds of its triangles flipped) and
    /// the weights round-trip.
    Local,
}

/// Options of a correspondence.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CorrespondOptions {
    /// Verified inverse weights (the paper's where they round-trip, else the smallest
    /// offset penalty that does) instead of the paper's weights alone.
    pub verified: bool,
    /// The most negative weight the paper's test accepts.
    pub max_negative: f64,
    /// How points are judged.
    pub test: ValidityTest,
    /// Local test: a segment from a vertex to the edge of its neighbourhood is
    /// over-stretched above this many times the map's median edge stretch (image length
    /// over source length).
    pub max_stretch: f64,
}

impl CorrespondOptions {
    /// Checks the options' ranges: `max_negative` as [`check_max_negative`] does,
    /// `max_stretch` finite and above 1.
    pub fn check(&self) -> Result<(), SolveError> {
        check_max_negative(self.max_negative)?;
        if !(self.max_stretch.is_finite() && self.max_stretch > 1.0) {
            return Err(SolveError::InvalidParameter(format!(
                "max_stretch must be a finite number above 1 (times the median edge \
                 stretch), got {}",
                self.max_stretch
            )));
        }
        Ok(())
    }
}

impl Default for CorrespondOptions {
    fn default() -> Self {
        Self {
            verified: true,
            max_negative: -0.1,
            test: ValidityTest::Local,
            max_stretch: 4.0,
        }
    }
}

/// The image of one source point.
#[derive(Clone, Debug, PartialEq)]
pub struct Mapped {
    /// The point on the target (or why there is none).
    pub target: Result<ForwardResult, SolveError>,
    /// Whether the weights return to the source point.
    pub round_trip: bool,
    /// The smallest weight (NaN when the inverse failed).
    pub min_weight: f64,
}

/// Why a source vertex is kept or not.
#[derive(Clone, Debug, PartialEq)]
pub enum Validity {
    /// Kept.
    Valid,
    /// No image: the inverse or the forward problem failed.
    Unanswered(SolveError),
    /// The weights do not return to the source point.
    NoRoundTrip,
    /// A weight is below the limit (paper test).
    NegativeWeight(f64),
    /// Most segments to the edge of the vertex's neighbourhood are over-stretched, or two
    /// thirds of the neighbourhood's triangles land flipped on a smooth part of the target
    /// (local test).
    Inconsistent,
}

impl Validity {
    /// A short reason for output files (`valid`, `unanswered`, `no-round-trip`,
    /// `negative-weight`, `inconsistent`).
    pub fn reason(&self) -> &'static str {
        match self {
            Validity::Valid => "valid",
            Validity::Unanswered(_) => "unanswered",
            Validity::NoRoundTrip => "no-round-trip",
            Validity::NegativeWeight(_) => "negative-weight",
            Validity::Inconsistent => "inconsistent",
        }
    }
}

/// Maps source points onto the target: the inverse problem on `source`, the forward
/// problem on `target` with the same weights, in parallel batches (results in input
/// order, independent of the thread count). The two solvers must have the same number of
/// anchors (anchor `i` of one corresponds to anchor `i` of the other).
///
/// ```
/// use std::sync::Arc;
/// use wavg_mesh::{SurfacePoint, ValidMesh, procedural};
/// use wavg_project::{EmbeddedMesh, Projector};
/// use wavg_solve::{Anchor, Solver};
/// use wavg_apps::map_points;
/// let mesh = Arc::new(ValidMesh::new(procedural::icosphere(3)).unwrap());
/// let proj = Arc::new(Projector::new(Arc::new(EmbeddedMesh::from_positions(mesh))).unwrap());
/// let solver = Solver::new(proj, (0..12).map(Anchor::Vertex)).unwrap();
/// let p = SurfacePoint::new(100, [0.2, 0.3, 0.5]);
/// let m = map_points(&solver, &solver, &[p], true).unwrap();
/// let back = m[0].target.as_ref().unwrap().position;
/// assert!((back - p.position(solver.mesh())).norm() < 1e-6); // onto itself: the identity
/// ```
pub fn map_points(
    source: &Solver,
    target: &Solver,
    points: &[SurfacePoint],
    verified: bool,
) -> Result<Vec<Mapped>, SolveError> {
    check_paired(source, target)?;
    let (weights, trips) = source_weights(source, points, verified);
    let rows: Vec<&[f64]> = weights.iter().map(|r| r.unwrap_or(&[])).collect();
    let images = target.forward_batch(&rows, &ForwardOptions::default());
    Ok(mapped(&weights, images, trips))
}

/// The anchors of `source` and `target` are paired one to one.
fn check_paired(source: &Solver, target: &Solver) -> Result<(), SolveError> {
    if source.n_anchors() != target.n_anchors() {
        return Err(SolveError::InvalidParameter(format!(
            "the source has {} anchors and the target {}; they must be paired one to one",
            source.n_anchors(),
            target.n_anchors()
        )));
    }
    Ok(())
}

/// Each point's weights on the source and whether they return to it: the verified
/// inverse's (round trip checked, penalised where needed) or the paper's, with their
/// round trip checked the same way.
fn source_weights(
    source: &Solver,
    points: &[SurfacePoint],
    verified: bool,
) -> (BatchWeights, Vec<bool>) {
    if !verified {
        return paper_round_trip(source, points);
    }
    let (mut weights, mut trips) = (BatchWeights::default(), Vec::new());
    // `Par::Rayon` always starts.
    let _ = source.inverse_verified_batch_into(
        points,
        ROUND_TRIP_TOLERANCE,
        &mut weights,
        &mut trips,
        Par::Rayon,
    );
    let trips = trips
        .iter()
        .map(|t| t.as_ref().is_ok_and(|t| *t != RoundTrip::NotReached))
        .collect();
    (weights, trips)
}

/// The images with their weights' round trips and smallest weights.
fn mapped(
    weights: &BatchWeights,
    images: Vec<Result<ForwardResult, SolveError>>,
    trips: Vec<bool>,
) -> Vec<Mapped> {
    weights
        .iter()
        .zip(images)
        .zip(trips)
        .map(|((w, img), round_trip)| match w {
            Ok(w) => Mapped {
                target: img,
                round_trip,
                min_weight: w.iter().copied().fold(f64::INFINITY, f64::min),
            },
            Err(e) => Mapped {
                target: Err(e.clone()),
                round_trip: false,
                min_weight: f64::NAN,
            },
        })
        .collect()
}

/// The paper's inverse weights of `points` and whether each returns to its point
/// (forward problem on the same solver, within [`ROUND_TRIP_TOLERANCE`] mean edge
/// lengths), both in parallel batches.
pub(crate) fn paper_round_trip(
    solver: &Solver,
    points: &[SurfacePoint],
) -> (wavg_solve::BatchWeights, Vec<bool>) {
    let batch = solver.inverse_batch(points);
    let rows: Vec<&[f64]> = batch.iter().map(|r| r.unwrap_or(&[])).collect();
    let back = solver.forward_batch(&rows, &ForwardOptions::default());
    let mesh = solver.mesh();
    let tol = ROUND_TRIP_TOLERANCE * solver.mean_edge_length();
    let trips = back
        .par_iter()
        .zip(points)
        // A point whose inverse failed has no weights, so no forward answer: the point is
        // only read after a successful inverse checked it.
        .map(|(b, p)| {
            b.as_ref()
                .is_ok_and(|b| (b.position - p.position(mesh)).norm() <= tol)
        })
        .collect();
    (batch, trips)
}

/// A map of every source vertex onto the target, with each vertex's validity and the
/// map's distortion.
#[derive(Clone, Debug)]
pub struct Correspondence {
    /// Per source vertex: its image.
    pub mapped: Vec<Mapped>,
    /// Per source vertex: kept or why not.
    pub validity: Vec<Validity>,
    /// Distortion of the map restricted to valid vertices (faces with three valid
    /// corners); flips are judged against the target's normals where the corners land.
    pub distortion: Distortion,
    /// Wall time of each stage of [`correspond_vertices`].
    pub timings: CorrespondTimings,
}

/// Wall time of each stage of a correspondence, in seconds; with the `serde` feature,
/// keyed by the field names.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
pub struct CorrespondTimings {
    /// The weights of every source vertex: the inverse problem on the source with its
    /// round-trip check (forward problems on the source, and the penalty ladder for the
    /// verified inverse).
    pub weights_seconds: f64,
    /// The forward problems on the target.
    pub forward_seconds: f64,
    /// The validity test and the distortion of the map.
    pub validity_seconds: f64,
}

/// Vertices per [`Validity::reason`]; with the `serde` feature, keyed by those reasons.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
#[cfg_attr(feature = "serde", serde(rename_all = "kebab-case"))]
pub struct ReasonCounts {
    /// Kept.
    pub valid: usize,
    /// No image: the inverse or the forward problem failed.
    pub unanswered: usize,
    /// The weights do not return to the source point.
    pub no_round_trip: usize,
    /// A weight is below the limit (paper test).
    pub negative_weight: usize,
    /// Most segments to the edge of the vertex's neighbourhood are over-stretched, or two
    /// thirds of the neighbourhood's triangles land flipped on a smooth part of the target
    /// (local test).
    pub inconsistent: usize,
}

impl Correspondence {
    /// Vertices per reason.
    pub fn reason_counts(&self) -> ReasonCounts {
        let mut c = ReasonCounts::default();
        for v in &self.validity {
            *match v {
                Validity::Valid => &mut c.valid,
                Validity::Unanswered(_) => &mut c.unanswered,
                Validity::NoRoundTrip => &mut c.no_round_trip,
                Validity::NegativeWeight(_) => &mut c.negative_weight,
                Validity::Inconsistent => &mut c.inconsistent,
            } += 1;
        }
        c
    }

    /// Valid vertices.
    pub fn valid(&self) -> usize {
        self.validity
            .iter()
            .filter(|v| **v == Validity::Valid)
            .count()
    }

    /// Valid vertices over all vertices (0 for an empty mesh).
    pub fn valid_fraction(&self) -> f64 {
        self.valid() as f64 / self.validity.len().max(1) as f64
    }

    /// The target position of every valid vertex (`None` elsewhere).
    pub fn valid_positions(&self) -> Vec<Option<Vector3<f64>>> {
        self.mapped
            .iter()
            .zip(&self.validity)
            .map(|(m, v)| match (v, &m.target) {
                (Validity::Valid, Ok(t)) => Some(t.position),
                _ => None,
            })
            .collect()
    }
}

/// Maps every vertex of the source onto the target ([`map_points`]) and judges each with
/// `opts.test` (see the module docs).
pub fn correspond_vertices(
    source: &Solver,
    target: &Solver,
    opts: &CorrespondOptions,
) -> Result<Correspondence, SolveError> {
    opts.check()?;
    check_paired(source, target)?;
    let t = Instant::now();
    let mesh = source.mesh();
    let points = vertex_points(mesh);
    let (weights, trips) = source_weights(source, &points, opts.verified);
    let weights_seconds = t.elapsed().as_secs_f64();
    let t = Instant::now();
    let rows: Vec<&[f64]> = weights.iter().map(|r| r.unwrap_or(&[])).collect();
    let images = target.forward_batch(&rows, &ForwardOptions::default());
    let forward_seconds = t.elapsed().as_secs_f64();
    let t = Instant::now();
    let mapped = mapped(&weights, images, trips);
    let mut validity: Vec<Validity> = mapped
        .iter()
        .map(|m| match &m.target {
            Err(e) => Validity::Unanswered(e.clone()),
            Ok(_) if !m.round_trip => Validity::NoRoundTrip,
            Ok(_) if opts.test == ValidityTest::Paper && m.min_weight < opts.max_negative => {
                Validity::NegativeWeight(m.min_weight)
            }
            Ok(_) => Validity::Valid,
        })
        .collect();
    let image_normals = image_normals(target.mesh(), &mapped);
    let normals = mapped_normals(mesh, &image_normals);
    if opts.test == ValidityTest::Local {
        let answered: Vec<Option<Vector3<f64>>> = mapped
            .iter()
            .map(|m| m.target.as_ref().ok().map(|t| t.position))
            .collect();
        let smooth = smooth_normals(mesh, &normals, &image_normals);
        let inconsistent = inconsistent_vertices(mesh, &answered, &smooth, opts.max_stretch);
        for (v, bad) in validity.iter_mut().zip(inconsistent) {
            if bad && *v == Validity::Valid {
                *v = Validity::Inconsistent;
            }
        }
    }
    let valid: Vec<Option<Vector3<f64>>> = mapped
        .iter()
        .zip(&validity)
        .map(|(m, v)| match (v, &m.target) {
            (Validity::Valid, Ok(t)) => Some(t.position),
            _ => None,
        })
        .collect();
    let distortion = distortion(&mesh.positions, &mesh.triangles, &valid, &normals);
    Ok(Correspondence {
        mapped,
        validity,
        distortion,
        timings: CorrespondTimings {
            weights_seconds,
            forward_seconds,
            validity_seconds: t.elapsed().as_secs_f64(),
        },
    })
}

/// Every vertex as a surface point (a corner of one of its faces; every vertex of a
/// valid mesh has one).
pub fn vertex_points(mesh: &ValidMesh) -> Vec<SurfacePoint> {
    let topo = mesh.topology();
    (0..mesh.n_vertices() as u32)
        .map(|v| {
            let f = topo.ring_faces(v).first().copied().unwrap_or(0);
            let k = mesh.triangles[f as usize]
                .iter()
                .position(|&c| c == v)
                .unwrap_or(0);
            SurfacePoint::at_corner(f, k)
        })
        .collect()
}

/// Per source vertex: the target's area-weighted vertex normals (see [`vertex_normals`])
/// interpolated at its image, `None` without an image. Computed once per vertex, it is
/// shared by the faces around the vertex in [`mapped_normals`] and [`smooth_normals`].
fn image_normals(target: &ValidMesh, mapped: &[Mapped]) -> Vec<Option<Vector3<f64>>> {
    let vn = vertex_normals(target);
    mapped
        .par_iter()
        .with_min_len(VERTEX_CHUNK)
        .map(|m| Some(m.target.as_ref().ok()?.point.interpolate(target, &vn)))
        .collect()
}

/// Vertices one parallel task handles in the validity stage's per-vertex passes.
const VERTEX_CHUNK: usize = 1024;

/// Per source face: the target's normal where its corners land (the sum of the target's
/// area-weighted vertex normals interpolated at the three images, `image`, which is
/// smooth across the target's edges, unlike face normals at creases), `None` when a
/// corner has no image.
fn mapped_normals(source: &ValidMesh, image: &[Option<Vector3<f64>>]) -> Vec<Option<Vector3<f64>>> {
    source
        .triangles
        .par_iter()
        .with_min_len(VERTEX_CHUNK)
        .map(|t| {
            let mut n = Vector3::zeros();
            for &v in t {
                n += (*image.get(v as usize)?)?;
            }
            Some(n)
        })
        .collect()
}

/// `normals` where the target is smooth at the scale of its edges around the three images
/// (their interpolated vertex normals `image` within [`SMOOTH_DEGREES`] of their sum),
/// `None` elsewhere: on thin parts (fingers) an image a fraction of an edge off flips
/// triangles while landing close to the truth, so flips there are no evidence of a wrong
/// image.
fn smooth_normals(
    source: &ValidMesh,
    normals: &[Option<Vector3<f64>>],
    image: &[Option<Vector3<f64>>],
) -> Vec<Option<Vector3<f64>>> {
    let min_cos = SMOOTH_DEGREES.to_radians().cos();
    source
        .triangles
        .par_iter()
        .with_min_len(VERTEX_CHUNK)
        .zip(normals)
        .map(|(t, n)| {
            let sum = (*n)?.normalize();
            for &v in t {
                let c = (*image.get(v as usize)?)?.normalize();
                let cos = c.dot(&sum);
                if cos.is_nan() || cos < min_cos {
                    return None;
                }
            }
            Some(sum)
        })
        .collect()
}

/// The largest angle between the target's normal at a corner's image and the face's
/// reference normal for a flip to count in the local test.
const SMOOTH_DEGREES: f64 = 30.0;

/// Area-weighted vertex normals (unnormalised sums of the incident faces' cross products).
pub(crate) fn vertex_normals(mesh: &ValidMesh) -> Vec<Vector3<f64>> {
    let mut n = vec![Vector3::zeros(); mesh.n_vertices()];
    for (f, t) in mesh.triangles.iter().enumerate() {
        let [a, b, c] = mesh.corners(f);
        let fnormal = (b - a).cross(&(c - a));
        for &v in t {
            n[v as usize] += fnormal;
        }
    }
    n
}

#[cfg(test)]
mod tests {
    use std::sync::Arc;

    use wavg_mesh::procedural;
    use wavg_project::{EmbeddedMesh, Projector};
    use wavg_solve::Anchor;

    use super::*;

    fn solver(mesh: wavg_mesh::TriMesh, anchors: &[u32]) -> Solver {
        let mesh = Arc::new(ValidMesh::new(mesh).unwrap());
        let proj = Projector::new(Arc::new(EmbeddedMesh::from_positions(mesh))).unwrap();
        Solver::new(Arc::new(proj), anchors.iter().map(|&v| Anchor::Vertex(v))).unwrap()
    }

    fn anchors() -> Vec<u32> {
        (0..40).map(|i| i * 61).collect()
    }

    #[test]
    fn a_surface_onto_itself_is_the_identity_and_all_valid() {
        let s = solver(procedural::icosphere(4), &anchors());
        for test in [ValidityTest::Local, ValidityTest::Paper] {
            let opts = CorrespondOptions {
                test,
                ..Default::default()
            };
            let c = correspond_vertices(&s, &s, &opts).unwrap();
            let r = c.reason_counts();
            let count = |name| c.validity.iter().filter(|v| v.reason() == name).count();
            let reasons = [
                "valid",
                "unanswered",
                "no-round-trip",
                "negative-weight",
                "inconsistent",
            ];
            assert_eq!(
                [
                    r.valid,
                    r.unanswered,
                    r.no_round_trip,
                    r.negative_weight,
                    r.inconsistent
                ],
                reasons.map(count)
            );
            assert_eq!(r.valid, c.valid());
            // The paper's test also rejects correct images with negative weights.
            let want = if test == ValidityTest::Local {
                0.99
            } else {
                0.5
            };
            assert!(
                c.valid_fraction() > want,
                "{test:?}: {}",
                c.valid_fraction()
            );
            for (v, p) in c.valid_positions().iter().enumerate() {
                if let Some(p) = p {
                    assert!((p - s.mesh().positions[v]).norm() < 1e-6);
                }
            }
            assert!((c.distortion.stretch - 1.0).abs() < 1e-6);
            assert_eq!(c.distortion.flipped_faces, 0);
        }
    }

    #[test]
    fn a_scaled_copy_maps_vertex_to_vertex() {
        let a = procedural::icosphere(4);
        let b = a
            .clone()
            .map_positions(|p| Vector3::new(2.0 * p.x, p.y, p.z));
        let (sa, sb) = (solver(a, &anchors()), solver(b, &anchors()));
        let c = correspond_vertices(&sa, &sb, &CorrespondOptions::default()).unwrap();
        assert!(c.valid_fraction() > 0.95, "{}", c.valid_fraction());
        let diag = sb.mesh().bounding_box_diagonal();
        let mut err = 0.0;
        for (v, p) in c.valid_positions().iter().enumerate() {
            if let Some(p) = p {
                err += (p - sb.mesh().positions[v]).norm() / diag;
            }
        }
        assert!(
            err / (c.valid() as f64) < 0.02,
            "mean error {}",
            err / c.valid() as f64
        );
        // Scaling by 2 along x: the stretch is near sqrt(5/4) on the whole sphere's faces
        // whose planes are not perpendicular to x, and 1 on others; between the two.
        assert!(c.distortion.stretch > 1.0 && c.distortion.stretch < 1.2);
    }

    #[test]
    fn anchor_counts_must_agree() {
        let s = solver(procedural::icosphere(3), &[0, 1, 2, 3, 4]);
        let t = solver(procedural::icosphere(3), &[0, 1, 2, 3]);
        assert!(matches!(
            map_points(&s, &t, &[SurfacePoint::new(0, [1.0, 0.0, 0.0])], true),
            Err(SolveError::InvalidParameter(_))
        ));
    }

    #[test]
    fn a_wrong_vertex_is_rejected_by_the_local_test_but_not_its_neighbours() {
        let s = solver(procedural::icosphere(4), &anchors());
        let mesh = s.mesh();
        let c = correspond_vertices(&s, &s, &CorrespondOptions::default()).unwrap();
        let mut answered: Vec<Option<Vector3<f64>>> = c
            .mapped
            .iter()
            .map(|m| m.target.as_ref().ok().map(|t| t.position))
            .collect();
        let normals = mapped_normals(mesh, &image_normals(mesh, &c.mapped));
        let before = inconsistent_vertices(mesh, &answered, &normals, 4.0);
        assert!(before.iter().all(|b| !b));
        // Send vertex 1000's image to the far side of the sphere.
        let v = 1000;
        answered[v] = Some(-mesh.positions[v]);
        let after = inconsistent_vertices(mesh, &answered, &normals, 4.0);
        assert!(after[v]);
        for &u in mesh.topology().ring(v as u32) {
            assert!(!after[u as usize], "neighbour {u} rejected too");
        }
        assert_eq!(after.iter().filter(|b| **b).count(), 1);
    }
}
