//! Distortion of a piecewise-linear map between surfaces: the symmetrised L2 stretch and
//! flipped faces.
//!
//! A map sends every vertex of a source triangle mesh to a point in R^3 (another surface,
//! or the plane for a parametrisation) and is linear on each triangle. On triangle `T`
//! its Jacobian `J` (3x2, in an orthonormal frame of `T`) has singular values
//! `G >= g`. Sander et al. (2001) define the L2 stretch of `T` as
//! `sqrt((G^2 + g^2) / 2)` and of the whole map as the root of the area-weighted mean of
//! its square. The inverse map has singular values `1/g, 1/G` and weights by the mapped
//! areas `G g A(T)`. Schreiner et al. (2004) symmetrise by averaging the stretch of the
//! map and of its inverse; each is first normalised by the global scale
//! (`sqrt(sum A / sum A')` for the map, its reciprocal for the inverse) so that a map which
//! only scales uniformly measures exactly 1, and any other measures more.
//!
//! A face is *flipped* when its mapped triangle's normal disagrees (non-positive dot
//! product) with the reference normal supplied for it (the target surface's normal where
//! it lands), or when the mapped triangle has no area. Flipped faces are counted and
//! left out of the stretch, which would otherwise be infinite or meaningless there.

use nalgebra::Vector3;
use rayon::prelude::*;

/// Distortion of a map (see the module docs). With the `serde` feature it serialises its
/// totals (not the per-face vectors) to the keys of `wavg correspond --json`, the stretches
/// as `null` when no face was measured unflipped ([`Distortion::has_stretch`]).
#[derive(Clone, Debug, PartialEq)]
pub struct Distortion {
    /// Per source face: the symmetrised stretch of the face (`None` where a corner is not
    /// mapped or the face is flipped).
    pub face_stretch: Vec<Option<f64>>,
    /// Per source face: flipped (mapped orientation disagrees with the reference normal,
    /// or the mapped triangle is degenerate).
    pub flipped: Vec<bool>,
    /// Faces whose three corners are mapped.
    pub measured_faces: usize,
    /// Flipped faces among the measured ones.
    pub flipped_faces: usize,
    /// Source area of the flipped faces over the source area of the measured ones (0 when
    /// nothing is measured).
    pub flipped_area_fraction: f64,
    /// Symmetrised L2 stretch over the measured, unflipped faces (1 for a map that only
    /// scales uniformly; 1 when nothing is measured).
    pub stretch: f64,
    /// The same over the best 95% of those faces by per-face stretch (the worst 5% left
    /// out), so a few bad triangles do not dominate.
    pub stretch_best95: f64,
}

impl Distortion {
    /// Whether any measured face is unflipped, so that [`Distortion::stretch`] and
    /// [`Distortion::stretch_best95`] measure something (they are 1 otherwise).
    pub fn has_stretch(&self) -> bool {
        self.measured_faces > self.flipped_faces
    }
}

#[cfg(feature = "serde")]
impl serde::Serialize for Distortion {
    fn serialize<S: serde::Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        use serde::ser::SerializeStruct;
        let measured = self.has_stretch();
        let mut st = s.serialize_struct("Distortion", 5)?;
        st.serialize_field("measured_faces", &self.measured_faces)?;
        st.serialize_field("flipped_faces", &self.flipped_faces)?;
        st.serialize_field("flipped_area_fraction", &self.flipped_area_fraction)?;
        st.serialize_field("stretch", &measured.then_some(self.stretch))?;
        st.serialize_field("stretch_best95", &measured.then_some(self.stretch_best95))?;
        st.end()
    }
}

/// Per face: source area, stretch squared of the map and of the inverse (both unnormalised).
#[derive(Clone, Copy)]
struct FaceStretch {
    area: f64,
    mapped_area: f64,
    forward_sq: f64,
    inverse_sq: f64,
}

/// Singular values (larger first) of the linear map sending triangle `p` onto `q`, or
/// `None` when the source triangle is degenerate.
fn singular_values(p: [Vector3<f64>; 3], q: [Vector3<f64>; 3]) -> Option<(f64, f64)> {
    let (e1, e2) = (p[1] - p[0], p[2] - p[0]);
    let l1 = e1.norm();
    let n = e1.cross(&e2);
    let two_area = n.norm();
    if !(l1 > 0.0 && two_area > 0.0 && two_area.is_finite()) {
        return None;
    }
    // Source frame: x along e1, y in the plane. p1 = (l1, 0), p2 = (a, b).
    let a = e1.dot(&e2) / l1;
    let b = two_area / l1;
    let (f1, f2) = (q[1] - q[0], q[2] - q[0]);
    // J (3x2) with J (l1,0) = f1 and J (a,b) = f2.
    let js = f1 / l1;
    let jt = (f2 - js * a) / b;
    let (ee, ff, gg) = (js.dot(&js), js.dot(&jt), jt.dot(&jt));
    let disc = ((ee - gg).powi(2) + 4.0 * ff * ff).sqrt();
    let big = ((ee + gg + disc) / 2.0).max(0.0).sqrt();
    let small = ((ee + gg - disc) / 2.0).max(0.0).sqrt();
    Some((big, small))
}

/// Distortion of the map sending vertex `i` of the source mesh (`positions`,
/// `triangles`) to `mapped[i]` (`None`: not mapped), with `reference_normal[f]` the
/// normal the mapped face `f` should agree with (`None`: do not test for flips).
///
/// ```
/// use nalgebra::Vector3;
/// use wavg_apps::distortion;
/// let p = vec![Vector3::zeros(), Vector3::x(), Vector3::y()];
/// let t = [[0u32, 1, 2]];
/// // Stretch by 2 along x: sqrt((1 + 4) / (2 * 2)) in both directions.
/// let q: Vec<_> = p.iter().map(|v| Some(Vector3::new(2.0 * v.x, v.y, 0.0))).collect();
/// let d = distortion(&p, &t, &q, &[Some(Vector3::z())]);
/// assert!((d.stretch - 1.25f64.sqrt()).abs() < 1e-12);
/// assert_eq!(d.flipped_faces, 0);
/// ```
pub fn distortion(
    positions: &[Vector3<f64>],
    triangles: &[[u32; 3]],
    mapped: &[Option<Vector3<f64>>],
    reference_normal: &[Option<Vector3<f64>>],
) -> Distortion {
    let judged: Vec<Face> = (0..triangles.len())
        .into_par_iter()
        .with_min_len(FACE_CHUNK)
        .map(|f| judge_face(positions, triangles, mapped, reference_normal, f))
        .collect();
    let nf = triangles.len();
    let mut flipped = vec![false; nf];
    let mut per: Vec<Option<FaceStretch>> = vec![None; nf];
    let (mut measured, mut area_measured, mut area_flipped) = (0usize, 0.0f64, 0.0f64);
    // Sums in face order, as one loop would: the totals do not depend on the threads.
    for (f, j) in judged.into_iter().enumerate() {
        match j {
            Face::Unmeasured => continue,
            Face::Flipped(area) => {
                flipped[f] = true;
                area_flipped += area;
                area_measured += area;
            }
            Face::Stretch(s) => {
                per[f] = Some(s);
                area_measured += s.area;
            }
        }
        measured += 1;
    }
    let ok: Vec<FaceStretch> = per.iter().flatten().copied().collect();
    let (stretch, scale) = symmetric(&ok);
    let face_value =
        |s: &FaceStretch| (s.forward_sq.sqrt() / scale + s.inverse_sq.sqrt() * scale) / 2.0;
    let face_stretch: Vec<Option<f64>> = per.iter().map(|s| s.as_ref().map(face_value)).collect();
    // By value, ties in face order (a stable sort's order, so the sums below are too).
    let mut ranked: Vec<(f64, u32)> = ok
        .iter()
        .enumerate()
        .map(|(i, s)| (face_value(s), i as u32))
        .collect();
    ranked.par_sort_unstable_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)));
    let keep = ((ranked.len() as f64) * 0.95).ceil() as usize;
    let best: Vec<FaceStretch> = ranked.iter().take(keep).map(|r| ok[r.1 as usize]).collect();
    Distortion {
        face_stretch,
        flipped,
        measured_faces: measured,
        flipped_faces: measured - ok.len(),
        flipped_area_fraction: if area_measured > 0.0 {
            area_flipped / area_measured
        } else {
            0.0
        },
        stretch,
        stretch_best95: symmetric(&best).0,
    }
}

/// Faces one parallel task judges.
const FACE_CHUNK: usize = 1024;

/// One face of a map.
#[derive(Clone, Copy)]
enum Face {
    /// A corner is missing or not mapped, or the source face has no area.
    Unmeasured,
    /// Flipped (see the module docs), with its source area.
    Flipped(f64),
    /// Measured unflipped.
    Stretch(FaceStretch),
}

/// Judges face `f` of the map (arguments as [`distortion`]'s).
#[inline]
fn judge_face(
    positions: &[Vector3<f64>],
    triangles: &[[u32; 3]],
    mapped: &[Option<Vector3<f64>>],
    reference_normal: &[Option<Vector3<f64>>],
    f: usize,
) -> Face {
    let t = &triangles[f];
    let get = |k: usize| positions.get(t[k] as usize).copied();
    let map = |k: usize| mapped.get(t[k] as usize).copied().flatten();
    let (Some(p0), Some(p1), Some(p2)) = (get(0), get(1), get(2)) else {
        return Face::Unmeasured;
    };
    let (Some(q0), Some(q1), Some(q2)) = (map(0), map(1), map(2)) else {
        return Face::Unmeasured;
    };
    let area = (p1 - p0).cross(&(p2 - p0)).norm() / 2.0;
    if !(area > 0.0 && area.is_finite()) {
        return Face::Unmeasured;
    }
    let n = (q1 - q0).cross(&(q2 - q0));
    let mapped_area = n.norm() / 2.0;
    let reversed = reference_normal
        .get(f)
        .copied()
        .flatten()
        .is_some_and(|r| n.dot(&r) <= 0.0);
    match singular_values([p0, p1, p2], [q0, q1, q2]) {
        Some((big, small)) if !reversed && small > 0.0 && mapped_area > 0.0 => {
            Face::Stretch(FaceStretch {
                area,
                mapped_area,
                forward_sq: (big * big + small * small) / 2.0,
                inverse_sq: (1.0 / (big * big) + 1.0 / (small * small)) / 2.0,
            })
        }
        _ => Face::Flipped(area),
    }
}

/// Per face, whether the map flips it: [`Distortion::flipped`] of [`distortion`] with the
/// same arguments, without the stretch.
pub(crate) fn flipped_faces(
    positions: &[Vector3<f64>],
    triangles: &[[u32; 3]],
    mapped: &[Option<Vector3<f64>>],
    reference_normal: &[Option<Vector3<f64>>],
) -> Vec<bool> {
    (0..triangles.len())
        .into_par_iter()
        .with_min_len(FACE_CHUNK)
        .map(|f| {
            matches!(
                judge_face(positions, triangles, mapped, reference_normal, f),
                Face::Flipped(_)
            )
        })
        .collect()
}

/// The symmetrised stretch of a set of faces and the global scale
/// `sqrt(sum A' / sum A)` (1 and 1 for an empty set).
fn symmetric(faces: &[FaceStretch]) -> (f64, f64) {
    let a: f64 = faces.iter().map(|s| s.area).sum();
    let a2: f64 = faces.iter().map(|s| s.mapped_area).sum();
    if !(a > 0.0 && a2 > 0.0) {
        return (1.0, 1.0);
    }
    let scale = (a2 / a).sqrt();
    let fwd = (faces.iter().map(|s| s.area * s.forward_sq).sum::<f64>() / a).sqrt() / scale;
    let inv = (faces
        .iter()
        .map(|s| s.mapped_area * s.inverse_sq)
        .sum::<f64>()
        / a2)
        .sqrt()
        * scale;
    ((fwd + inv) / 2.0, scale)
}

#[cfg(test)]
mod tests {
    use proptest::prelude::*;
    use wavg_mesh::procedural;

    use super::*;

    fn normals(mesh: &wavg_mesh::TriMesh, flip: f64) -> Vec<Option<Vector3<f64>>> {
        (0..mesh.n_faces())
            .map(|f| {
                let [a, b, c] = mesh.corners(f);
                Some((b - a).cross(&(c - a)) * flip)
            })
            .collect()
    }

    fn run(mesh: &wavg_mesh::TriMesh, f: impl Fn(Vector3<f64>) -> Vector3<f64>) -> Distortion {
        let q: Vec<_> = mesh.positions.iter().map(|&p| Some(f(p))).collect();
        distortion(&mesh.positions, &mesh.triangles, &q, &normals(mesh, 1.0))
    }

    #[test]
    fn identity_and_uniform_scaling_measure_one() {
        let mesh = procedural::icosphere(3);
        for s in [1.0, 0.01, 7.5] {
            let d = run(&mesh, |p| p * s);
            assert!((d.stretch - 1.0).abs() < 1e-12, "{s}: {}", d.stretch);
            assert!((d.stretch_best95 - 1.0).abs() < 1e-12);
            assert_eq!(d.flipped_faces, 0);
            assert_eq!(d.flipped_area_fraction, 0.0);
            assert_eq!(d.measured_faces, mesh.n_faces());
            assert!(
                d.face_stretch
                    .iter()
                    .all(|s| (s.unwrap() - 1.0).abs() < 1e-9)
            );
        }
    }

    #[test]
    fn reflection_flips_every_face() {
        let mesh = procedural::icosphere(2);
        let q: Vec<_> = mesh
            .positions
            .iter()
            .map(|p| Some(Vector3::new(-p.x, p.y, p.z)))
            .collect();
        // The reference normals of the reflected surface (the reflected face normals, which
        // point outwards on the mirrored sphere) disagree with the mapped faces' orientation.
        let reference: Vec<_> = (0..mesh.n_faces())
            .map(|f| {
                let [a, b, c] = mesh.corners(f);
                let n = (b - a).cross(&(c - a));
                Some(Vector3::new(-n.x, n.y, n.z))
            })
            .collect();
        let d = distortion(&mesh.positions, &mesh.triangles, &q, &reference);
        assert_eq!(d.flipped_faces, mesh.n_faces());
        assert!((d.flipped_area_fraction - 1.0).abs() < 1e-12);
        assert!(d.face_stretch.iter().all(Option::is_none));
    }

    #[test]
    fn unmapped_corners_leave_faces_unmeasured() {
        let mesh = procedural::icosphere(2);
        let mut q: Vec<_> = mesh.positions.iter().map(|&p| Some(p)).collect();
        q[0] = None;
        let d = distortion(&mesh.positions, &mesh.triangles, &q, &normals(&mesh, 1.0));
        let touching = mesh.triangles.iter().filter(|t| t.contains(&0)).count();
        assert_eq!(d.measured_faces, mesh.n_faces() - touching);
        assert!((d.stretch - 1.0).abs() < 1e-12);
    }

    #[test]
    fn collapsed_faces_are_flipped_not_infinite() {
        let mesh = procedural::icosphere(1);
        let q = vec![Some(Vector3::zeros()); mesh.n_vertices()];
        let d = distortion(&mesh.positions, &mesh.triangles, &q, &normals(&mesh, 1.0));
        assert_eq!(d.flipped_faces, mesh.n_faces());
        assert_eq!(d.stretch, 1.0);
    }

    proptest! {
        /// The flips alone are the full distortion's, on random maps of a sphere (some
        /// corners unmapped, some reference normals missing or reversed, images scattered
        /// so that faces fold and collapse).
        #[test]
        fn flipped_faces_are_the_distortions(seed in any::<u64>(), spread in 0.0f64..0.3) {
            use rand::{Rng, SeedableRng};
            let mut r = rand_chacha::ChaCha8Rng::seed_from_u64(seed);
            let mesh = procedural::icosphere(2);
            let q: Vec<_> = mesh
                .positions
                .iter()
                .map(|&p| {
                    let jitter = Vector3::new(r.random(), r.random(), r.random()) * spread;
                    // One vertex in 20 unmapped; one in 20 collapsed onto the origin.
                    match r.random_range(0..20) {
                        0 => None,
                        1 => Some(Vector3::zeros()),
                        _ => Some(p + jitter),
                    }
                })
                .collect();
            let reference: Vec<_> = normals(&mesh, 1.0)
                .into_iter()
                .map(|n| match r.random_range(0..10) {
                    0 => None,
                    1 => n.map(|n| -n),
                    _ => n,
                })
                .collect();
            let d = distortion(&mesh.positions, &mesh.triangles, &q, &reference);
            let f = flipped_faces(&mesh.positions, &mesh.triangles, &q, &reference);
            prop_assert_eq!(&f, &d.flipped);
            prop_assert!(f.iter().any(|&x| x));
            // The best 95% by a stable sort of the measured faces, summed in that order.
            let mut ok: Vec<(f64, FaceStretch)> = (0..mesh.n_faces())
                .filter_map(|f| match judge_face(&mesh.positions, &mesh.triangles, &q, &reference, f) {
                    Face::Stretch(s) => d.face_stretch[f].map(|v| (v, s)),
                    _ => None,
                })
                .collect();
            ok.sort_by(|a, b| a.0.total_cmp(&b.0));
            let keep = ((ok.len() as f64) * 0.95).ceil() as usize;
            let best: Vec<FaceStretch> = ok.iter().take(keep).map(|r| r.1).collect();
            prop_assert_eq!(symmetric(&best).0.to_bits(), d.stretch_best95.to_bits());
        }

        /// Scaling by `s` along one axis of a planar grid: both directions measure
        /// `sqrt((1 + s^2) / (2 s))` (singular values `s` and 1 on every face).
        #[test]
        fn one_axis_scaling_has_the_closed_form(s in 0.05f64..20.0, angle in 0.0f64..3.0) {
            let mut pts = Vec::new();
            let mut tris = Vec::new();
            let n = 6u32;
            for j in 0..=n {
                for i in 0..=n {
                    pts.push(Vector3::new(f64::from(i), f64::from(j) * 0.7 + 0.1 * f64::from(i), 0.0));
                }
            }
            for j in 0..n {
                for i in 0..n {
                    let a = j * (n + 1) + i;
                    tris.push([a, a + 1, a + n + 2]);
                    tris.push([a, a + n + 2, a + n + 1]);
                }
            }
            let (c, sn) = (angle.cos(), angle.sin());
            let q: Vec<_> = pts.iter().map(|p| {
                // Scale along the direction (c, sn).
                let along = p.x * c + p.y * sn;
                Some(p + Vector3::new(c, sn, 0.0) * (along * (s - 1.0)))
            }).collect();
            let d = distortion(&pts, &tris, &q, &vec![Some(Vector3::z()); tris.len()]);
            let want = ((1.0 + s * s) / (2.0 * s)).sqrt();
            prop_assert!((d.stretch - want).abs() < 1e-9 * want, "{} vs {want}", d.stretch);
            prop_assert_eq!(d.flipped_faces, 0);
            prop_assert!(d.stretch >= 1.0 - 1e-12);
        }
    }
}
