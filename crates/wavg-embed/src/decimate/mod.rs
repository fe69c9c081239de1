//! Landmark selection by incremental decimation (halfedge collapses), after OpenMesh's
//! `DecimaterT` with the modules `ModQuadricT` (priority), `ModNormalFlippingT` and
//! optionally `ModNormalDeviationT` and `ModAspectRatioT` (binary constraints).
//!
//! # What is mirrored from OpenMesh
//!
//! * **Halfedge collapse** `u -> v`: `u` is removed and `v` keeps its position, so every
//!   surviving vertex is an original vertex and the survivors are the landmarks.
//! * **Priority queue of vertices** (`DecimaterT`): each vertex stores its best legal
//!   outgoing collapse (smallest priority) and sits in the heap with it. After a collapse
//!   `u -> v` the vertices of the *former one-ring of `u`* (which includes `v`) are
//!   re-evaluated, as OpenMesh does. A popped collapse is re-checked for topological
//!   legality only and skipped (the vertex leaves the heap) if it became illegal.
//! * **Topological legality** (`TriConnectivity::is_collapse_ok` plus
//!   `BaseDecimaterT::is_collapse_legal`): locked `u` refused; a boundary `u` may only
//!   collapse into a boundary `v`, and an edge between two boundary vertices must be a
//!   boundary edge (so boundary vertices only move along their loop); a triangle with two
//!   boundary edges is never removed; the one-ring intersection of `u` and `v` must be
//!   exactly the opposite vertices `{wl, wr}` (link condition). Together these keep the
//!   genus, the number of boundary loops and manifoldness.
//! * **`ModQuadricT`**: per vertex the sum of the planes of its faces, each weighted by the
//!   face area; priority of `u -> v` = `(Q_u + Q_v)(p_v)`; after the collapse
//!   `Q_v += Q_u`.
//! * **`ModNormalFlippingT`**: a collapse is illegal if some face around `u` (other than
//!   the two removed) would turn by more than `max_normal_deviation_deg` against its
//!   *current* normal (face normals are updated after each collapse, as
//!   `DecimaterT::decimate` does with `update_normals`).
//! * **`ModAspectRatioT`** (optional, `max_aspect_ratio`): a collapse is illegal if the
//!   worst aspect ratio (longest edge squared over twice the area) of the faces that stay
//!   around `u` would exceed the bound and not improve on the worst around `u` before.
//!   Without it, quadric errors let thin parts decimate into long triangles along one
//!   side; the landmark pipeline turns it on ([`crate::LANDMARK_ASPECT_RATIO`]).
//! * **`ModNormalDeviationT`** (optional, `max_normal_cone_deg`): per face a normal cone
//!   (`NormalConeT`, merged by SLERP) accumulates all normals the face region had; a
//!   collapse is illegal if a resulting cone's full aperture would exceed the bound.
//!
//! # Where this differs from OpenMesh
//!
//! * Ties: OpenMesh's heap order for equal priorities is an implementation detail; here
//!   equal priorities (exactly planar regions, where every quadric error is 0) are ordered
//!   by the shorter edge first, then by vertex id (a vertex's best collapse: by target id).
//!   Shorter-first keeps the survivors of a flat region spread out instead of clustered at
//!   one end of the index range. The result is deterministic.
//! * Priorities are `f64` (OpenMesh returns `float`).
//! * A collapse that would create a zero-area face (sine of an angle below `1e-12`) is
//!   illegal (OpenMesh's flipping test lets it through at 90 degrees, since the normal of
//!   a degenerate face is the zero vector).
//! * A closed component that is a tetrahedron is never collapsed further.
//! * **First pass on large meshes** (`first_pass.rs`): above twice
//!   [`DecimateOptions::first_pass_vertices`] vertices, meshoptimizer's simplifier first
//!   reduces the mesh to about that many vertices (its collapses also keep original
//!   vertices), its output is cleaned into a valid mesh of the same topology, and the
//!   collapses above continue from there; the full mesh is decimated when the cleanup fails.
//!   The sequential quadric collapses cost about ten times the simplifier's per vertex.
//! * **Relaxation**: OpenMesh stops when the heap is empty. Here, if the target is not yet
//!   reached, every vertex is first re-evaluated (vertices whose popped collapse had become
//!   illegal left the heap, but may have another legal one); if that finds nothing, the
//!   bounds are relaxed (aspect-ratio bound x2 until it is switched off, cone bound x1.5
//!   until it is switched off, then the flipping bound +15 degrees up to 90) and everything is re-evaluated again. Only when nothing can
//!   be collapsed even with a 90-degree flipping bound (a topological limit, for example
//!   a torus below 7 vertices) is it an error. The relaxations applied are reported in
//!   [`Decimated::relaxations`].
//! * Default bounds: `ModNormalFlippingT`'s default is 90 degrees; here it is 45
//!   ([`DecimateOptions::default`]), which keeps the coarse mesh from folding over while
//!   the target is still reached without relaxation on every test mesh we have.
//! * Quadric areas: OpenMesh leaves the normal unnormalised for faces of area below
//!   `FLT_MIN`; valid meshes have no such faces, so this never matters here.
//!
//! # Consequences worth knowing
//!
//! * Like OpenMesh's `ModQuadricT`, the quadrics have no boundary planes: on a flat open
//!   surface a boundary vertex can slide along its loop at zero cost, so corners of open
//!   boundaries are not protected (the loop count is).
//! * Cost: one heap pop and the re-evaluation of the removed vertex's one-ring per
//!   collapse, sequential (the order of collapses is the result). A vertex of very high
//!   valence `k` (a fan of thousands of triangles) makes each re-evaluation of it `O(k)` to
//!   `O(k^2)`.

use nalgebra::Vector3;
use wavg_mesh::{TriMesh, ValidMesh};

use crate::error::{EmbedError, Progress, Stage, check_cancel};

mod aspect;
mod collapse;
mod first_pass;
mod heap;
mod quadric;

pub(crate) use aspect::aspect_ratio;
use collapse::*;
use heap::*;
use quadric::*;

const NONE: u32 = u32::MAX;

/// Vertices evaluated between two looks at the cancellation while the heap is filled.
const CANCEL_EVERY: usize = 1 << 16;

/// Parameters of the landmark decimation.
#[derive(Clone, Debug, PartialEq)]
pub struct DecimateOptions {
    /// Number of vertices to keep (the landmark count).
    pub target: usize,
    /// `ModNormalFlippingT` bound: the largest angle (degrees, `0 < x <= 90`) by which one
    /// collapse may turn any remaining face's normal. 90 means "only forbid flips".
    pub max_normal_deviation_deg: f64,
    /// `ModNormalDeviationT` bound (degrees): the largest full aperture of the normal cone
    /// a face may accumulate over the whole decimation; `None` disables the module.
    pub max_normal_cone_deg: Option<f64>,
    /// `ModAspectRatioT` bound: a collapse may not leave a triangle around the kept vertex
    /// with an aspect ratio (longest edge squared over twice the area; 1.15 for an
    /// equilateral triangle) above this, unless it improves the worst ratio around the
    /// removed vertex; `None` disables the module.
    pub max_aspect_ratio: Option<f64>,
    /// Vertices that must survive (OpenMesh's locked status): never removed, though others
    /// may collapse into them.
    pub locked: Vec<u32>,
    /// Relax the normal bounds when they block the target (see the module docs); without
    /// it, an unreachable target is an error.
    pub relax: bool,
    /// Meshes with more than twice this many vertices (and more than twice the target
    /// and every snapshot) first go through meshoptimizer's simplifier down to about this
    /// many, cleaned up into a valid mesh of the same topology on original vertices; the
    /// quadric decimation continues from there (falling back to the full mesh when the
    /// cleanup fails). 0 turns the first pass off. Default [`FIRST_PASS_VERTICES`].
    pub first_pass_vertices: usize,
}

/// Vertices left by the first pass of large decimations by default: meshes up to twice
/// this size are decimated exactly as without a first pass.
pub const FIRST_PASS_VERTICES: usize = 500_000;

impl Default for DecimateOptions {
    fn default() -> Self {
        Self {
            target: 1000,
            max_normal_deviation_deg: 45.0,
            max_normal_cone_deg: None,
            max_aspect_ratio: None,
            locked: Vec::new(),
            relax: true,
            first_pass_vertices: FIRST_PASS_VERTICES,
        }
    }
}

/// The legality bounds of a decimation, as [`DecimateOptions`] names them.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Bounds {
    /// The normal-flipping bound, degrees.
    pub max_normal_deviation_deg: f64,
    /// The normal-cone bound, degrees, if any.
    pub max_normal_cone_deg: Option<f64>,
    /// The aspect-ratio bound, if any.
    pub max_aspect_ratio: Option<f64>,
}

/// The result of a decimation: the coarse mesh on the surviving original vertices.
#[derive(Clone, Debug)]
pub struct Decimated {
    /// The coarse mesh; its vertex `i` is original vertex `landmarks[i]` (same position).
    pub mesh: TriMesh,
    /// The surviving original vertex ids, ascending.
    pub landmarks: Vec<u32>,
    /// The bounds after each relaxation that was needed to reach the target (empty if
    /// none was).
    pub relaxations: Vec<Bounds>,
}

impl Decimated {
    /// Index in [`Self::mesh`] of original vertex `v`, if it survived.
    pub fn coarse_index(&self, v: u32) -> Option<u32> {
        self.landmarks.binary_search(&v).ok().map(|i| i as u32)
    }
}

/// Chooses `opts.target` landmark vertices of `mesh` by decimation; returns their original
/// ids, ascending. See the module documentation for the rules.
///
/// ```
/// use wavg_embed::{DecimateOptions, NoProgress, select_landmarks};
/// use wavg_mesh::{ValidMesh, procedural};
/// let mesh = ValidMesh::new(procedural::torus(40, 20, 1.0, 0.3)).unwrap();
/// let opts = DecimateOptions { target: 100, ..Default::default() };
/// let lm = select_landmarks(&mesh, &opts, &NoProgress).unwrap();
/// assert_eq!(lm.len(), 100);
/// assert!(lm.windows(2).all(|w| w[0] < w[1]));
/// ```
pub fn select_landmarks(
    mesh: &ValidMesh,
    opts: &DecimateOptions,
    progress: &dyn Progress,
) -> Result<Vec<u32>, EmbedError> {
    Ok(decimate(mesh, opts, progress)?.landmarks)
}

/// Decimates `mesh` to `opts.target` vertices; returns the coarse mesh and the landmarks.
///
/// ```
/// use wavg_embed::{DecimateOptions, NoProgress, decimate};
/// use wavg_mesh::{ValidMesh, procedural};
/// let mesh = ValidMesh::new(procedural::grid(30, 30, 1.0, 1.0)).unwrap();
/// let d = decimate(&mesh, &DecimateOptions { target: 50, ..Default::default() }, &NoProgress).unwrap();
/// let coarse = ValidMesh::new(d.mesh).unwrap();
/// assert_eq!(coarse.n_vertices(), 50);
/// assert_eq!(coarse.topology().boundary_loops().len(), 1);
/// ```
pub fn decimate(
    mesh: &ValidMesh,
    opts: &DecimateOptions,
    progress: &dyn Progress,
) -> Result<Decimated, EmbedError> {
    Ok(decimate_with_snapshots(mesh, opts, &[], progress)?.0)
}

/// Like [`decimate`], and also returns the state of the same collapse sequence when it had
/// `snapshots[i]` vertices (each in `opts.target..=n_vertices`), in the given order. The
/// vertices of a coarser result are a subset of those of every finer one.
pub fn decimate_with_snapshots(
    mesh: &ValidMesh,
    opts: &DecimateOptions,
    snapshots: &[usize],
    progress: &dyn Progress,
) -> Result<(Decimated, Vec<Decimated>), EmbedError> {
    decimate_beside(mesh, opts, snapshots, progress, || ()).0
}

/// What [`decimate_beside`] returns: the decimation's result, `alongside`'s (when it ran)
/// and the moment the decimation ended.
pub(crate) type Beside<R> = (
    Result<(Decimated, Vec<Decimated>), EmbedError>,
    Option<R>,
    std::time::Instant,
);

/// [`decimate_with_snapshots`], running `alongside` beside its quadric collapses, after
/// the first pass (if any): the first pass's working memory is freed before `alongside`
/// allocates its own, and the collapses, which take longer, still overlap it. `alongside`
/// does not run when the decimation fails before its collapses (cancelled, bad options).
pub(crate) fn decimate_beside<R: Send>(
    mesh: &ValidMesh,
    opts: &DecimateOptions,
    snapshots: &[usize],
    progress: &dyn Progress,
    alongside: impl FnOnce() -> R + Send,
) -> Beside<R> {
    let now = std::time::Instant::now;
    let n = mesh.n_vertices();
    if let Err(e) = check_options(n, opts) {
        return (Err(e), None, now());
    }
    if let Some(&s) = snapshots.iter().find(|&&s| s < opts.target || s > n) {
        return (
            Err(EmbedError::InvalidArgument(format!(
                "snapshot at {s} vertices is outside {}..={n}",
                opts.target
            ))),
            None,
            now(),
        );
    }
    let keep =
        (snapshots.iter().copied()).fold(opts.first_pass_vertices.max(opts.target), usize::max);
    if opts.first_pass_vertices > 0 && n > 2 * keep {
        let first = check_cancel(progress).and_then(|()| {
            progress.report(Stage::Decimate, 0.0);
            first_pass::first_pass(mesh, keep, &opts.locked, progress)
        });
        let reduced = match first {
            Ok(r) => r,
            Err(e) => return (Err(e), None, now()),
        };
        if let Some(r) = reduced.filter(|r| snapshots.iter().all(|&s| s <= r.mesh.n_vertices())) {
            let lift = |d: Decimated| Decimated {
                landmarks: d
                    .landmarks
                    .iter()
                    .map(|&v| r.original[v as usize])
                    .collect(),
                ..d
            };
            let inner = DecimateOptions {
                locked: (opts.locked.iter())
                    .filter_map(|l| r.original.binary_search(l).ok().map(|i| i as u32))
                    .collect(),
                first_pass_vertices: 0,
                ..opts.clone()
            };
            let ((res, end), other) = rayon::join(
                || (decimate_exact(&r.mesh, &inner, snapshots, progress), now()),
                alongside,
            );
            let res = res.map(|(fin, snaps)| (lift(fin), snaps.into_iter().map(lift).collect()));
            return (res, Some(other), end);
        }
    }
    let ((res, end), other) = rayon::join(
        || (decimate_exact(mesh, opts, snapshots, progress), now()),
        alongside,
    );
    (res, Some(other), end)
}

/// [`decimate_with_snapshots`] by quadric collapses alone, its arguments checked.
fn decimate_exact(
    mesh: &ValidMesh,
    opts: &DecimateOptions,
    snapshots: &[usize],
    progress: &dyn Progress,
) -> Result<(Decimated, Vec<Decimated>), EmbedError> {
    let n = mesh.n_vertices();
    let mut d = Decimator::new(mesh, opts);
    let mut snaps: Vec<Option<Decimated>> = vec![None; snapshots.len()];
    let take = |d: &Decimator, snaps: &mut Vec<Option<Decimated>>| {
        for (i, &s) in snapshots.iter().enumerate() {
            if s == d.n_alive && snaps[i].is_none() {
                snaps[i] = Some(d.result());
            }
        }
    };
    take(&d, &mut snaps);
    d.init_heap(progress)?;
    let total = (n - opts.target).max(1) as f64;
    let mut since_report = 0usize;
    // Whether a collapse happened since the heap was last filled from scratch. Vertices
    // whose popped collapse turned out illegal leave the heap (as in OpenMesh), so an empty
    // heap first triggers a full re-evaluation; only if that finds nothing are the bounds
    // relaxed.
    let mut collapsed_since_fill = false;
    while d.n_alive > opts.target {
        if d.step() {
            collapsed_since_fill = true;
            take(&d, &mut snaps);
            since_report += 1;
            if since_report == 2048 {
                since_report = 0;
                check_cancel(progress)?;
                progress.report(Stage::Decimate, (n - d.n_alive) as f64 / total);
            }
        } else if d.heap.is_empty() {
            if collapsed_since_fill {
                collapsed_since_fill = false;
                d.init_heap(progress)?;
                continue;
            }
            if !opts.relax || !d.relax() {
                return Err(EmbedError::InvalidArgument(format!(
                    "cannot decimate to {} vertices: no legal collapse left at {} vertices \
                     (normal bounds {:.0} deg / {:?}, aspect ratio {:?}); ask for more \
                     landmarks",
                    opts.target, d.n_alive, d.flip_deg, d.cone_deg, d.aspect
                )));
            }
            d.init_heap(progress)?;
        }
    }
    progress.report(Stage::Decimate, 1.0);
    let fin = d.result();
    Ok((
        fin,
        snaps
            .into_iter()
            .map(|s| s.expect("every snapshot level is passed"))
            .collect(),
    ))
}

fn check_options(n: usize, opts: &DecimateOptions) -> Result<(), EmbedError> {
    if opts.target == 0 {
        return Err(EmbedError::InvalidArgument(
            "the landmark count must be at least 1".into(),
        ));
    }
    if opts.target > n {
        return Err(EmbedError::InvalidArgument(format!(
            "the mesh has {n} vertices, fewer than the {} landmarks asked for; ask for at most {n}",
            opts.target
        )));
    }
    let f = opts.max_normal_deviation_deg;
    if !(f > 0.0 && f <= 90.0) {
        return Err(EmbedError::InvalidArgument(format!(
            "max_normal_deviation_deg = {f} is not in (0, 90]"
        )));
    }
    if let Some(c) = opts.max_normal_cone_deg {
        if !(c > 0.0 && c <= 360.0) {
            return Err(EmbedError::InvalidArgument(format!(
                "max_normal_cone_deg = {c} is not in (0, 360]"
            )));
        }
    }
    if let Some(a) = opts.max_aspect_ratio {
        // An equilateral triangle's ratio, 2 / sqrt(3), is the smallest there is.
        if !(a.is_finite() && a >= 2.0 / 3f64.sqrt()) {
            return Err(EmbedError::InvalidArgument(format!(
                "max_aspect_ratio = {a} is not finite and at least 2/sqrt(3) (equilateral)"
            )));
        }
    }
    let mut seen = vec![false; n];
    for &l in &opts.locked {
        match seen.get_mut(l as usize) {
            None => {
                return Err(EmbedError::InvalidArgument(format!(
                    "locked vertex {l} out of range (mesh has {n} vertices)"
                )));
            }
            Some(s) => *s = true,
        }
    }
    let k = seen.iter().filter(|&&s| s).count();
    if k > opts.target {
        return Err(EmbedError::InvalidArgument(format!(
            "{k} locked vertices cannot fit in a target of {}",
            opts.target
        )));
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::error::NoProgress;
    use proptest::prelude::*;
    use wavg_mesh::procedural;

    fn valid(m: TriMesh) -> ValidMesh {
        ValidMesh::new(m).unwrap()
    }

    fn opts(target: usize) -> DecimateOptions {
        DecimateOptions {
            target,
            ..Default::default()
        }
    }

    /// Checks the invariants of a decimation result against its input and returns the
    /// validated coarse mesh.
    fn check(mesh: &ValidMesh, d: &Decimated, target: usize) -> ValidMesh {
        assert_eq!(d.landmarks.len(), target);
        assert!(
            d.landmarks.windows(2).all(|w| w[0] < w[1]),
            "sorted and distinct"
        );
        assert!(
            d.landmarks
                .iter()
                .all(|&l| (l as usize) < mesh.n_vertices())
        );
        for (i, &l) in d.landmarks.iter().enumerate() {
            assert_eq!(d.mesh.positions[i], mesh.positions[l as usize]);
        }
        let coarse = ValidMesh::new(d.mesh.clone()).expect("decimated mesh is a valid manifold");
        let (a, b) = (mesh.topology(), coarse.topology());
        assert_eq!(b.genus(), a.genus(), "genus");
        assert_eq!(
            b.boundary_loops().len(),
            a.boundary_loops().len(),
            "boundary loops"
        );
        assert_eq!(b.n_components(), a.n_components(), "components");
        // Orientation is kept: every coarse face normal agrees with the normals of the
        // original faces around its corners at least loosely (no flipped face).
        coarse
    }

    /// A disk: one centre vertex of valence `k` and a boundary ring of `k` vertices,
    /// slightly domed so that the quadrics are not all zero.
    fn fan(k: u32) -> TriMesh {
        let mut pos = vec![Vector3::new(0.0, 0.0, 0.3)];
        for i in 0..k {
            let a = std::f64::consts::TAU * i as f64 / k as f64;
            pos.push(Vector3::new(a.cos(), a.sin(), 0.0));
        }
        let tris = (0..k).map(|i| [0, 1 + i, 1 + (i + 1) % k]).collect();
        TriMesh::new(pos, tris)
    }

    fn grid_with_hole() -> TriMesh {
        let g = procedural::grid(30, 30, 1.0, 1.0);
        let tris = g
            .triangles
            .iter()
            .filter(|t| {
                let c = t
                    .iter()
                    .map(|&v| g.positions[v as usize])
                    .sum::<Vector3<f64>>()
                    / 3.0;
                (c - Vector3::new(0.5, 0.5, 0.0)).norm() > 0.2
            })
            .copied()
            .collect();
        let m = TriMesh::new(g.positions.clone(), tris);
        // Drop vertices that lost all faces.
        let mut used = vec![false; m.n_vertices()];
        for t in &m.triangles {
            for &v in t {
                used[v as usize] = true;
            }
        }
        let mut id = vec![u32::MAX; m.n_vertices()];
        let mut pos = Vec::new();
        for v in 0..m.n_vertices() {
            if used[v] {
                id[v] = pos.len() as u32;
                pos.push(m.positions[v]);
            }
        }
        TriMesh::new(
            pos,
            m.triangles
                .iter()
                .map(|t| t.map(|v| id[v as usize]))
                .collect(),
        )
    }

    #[test]
    fn keeps_topology_on_procedural_meshes() {
        let cases: Vec<(&str, TriMesh, usize)> = vec![
            ("icosphere", procedural::icosphere(4), 100),
            (
                "noisy sphere",
                procedural::with_noise(procedural::icosphere(4), 0.3, 2),
                60,
            ),
            ("torus", procedural::torus(60, 24, 1.0, 0.3), 80),
            ("grid", procedural::grid(40, 30, 2.0, 1.0), 50),
            ("grid with hole", grid_with_hole(), 60),
            ("bump", procedural::bump_sphere(4, 0.5), 30),
            ("fan of 4500 triangles", fan(4500), 4200),
        ];
        for (name, m, target) in cases {
            let mesh = valid(m);
            let d = decimate(&mesh, &opts(target), &NoProgress).unwrap();
            check(&mesh, &d, target);
            eprintln!(
                "{name}: {} -> {target} vertices, genus {}, {} boundary loops, relaxations {:?}",
                mesh.n_vertices(),
                mesh.topology().genus(),
                mesh.topology().boundary_loops().len(),
                d.relaxations
            );
        }
    }

    /// Below twice `first_pass_vertices` the decimation is the exact one; above, the
    /// first pass runs and the result keeps every invariant (target, topology, locked
    /// vertices, nested snapshots on original vertices).
    #[test]
    fn first_pass_threshold() {
        let mesh = valid(procedural::with_noise(
            procedural::torus(120, 50, 1.0, 0.3),
            0.2,
            4,
        ));
        let n = mesh.n_vertices();
        let exact = DecimateOptions {
            first_pass_vertices: 0,
            ..opts(80)
        };
        let below = DecimateOptions {
            first_pass_vertices: n / 2,
            ..opts(80)
        };
        let a = decimate(&mesh, &exact, &NoProgress).unwrap();
        let b = decimate(&mesh, &below, &NoProgress).unwrap();
        assert_eq!(a.landmarks, b.landmarks);
        assert_eq!(a.mesh.triangles, b.mesh.triangles);
        assert_eq!(
            decimate(&mesh, &opts(80), &NoProgress).unwrap().landmarks,
            a.landmarks,
            "the default first pass leaves small meshes alone"
        );
        let locked = vec![5, 999, 4000];
        let above = DecimateOptions {
            first_pass_vertices: n / 2 - 1,
            locked: locked.clone(),
            ..opts(80)
        };
        let (fin, snaps) =
            decimate_with_snapshots(&mesh, &above, &[1000, 300], &NoProgress).unwrap();
        check(&mesh, &fin, 80);
        assert_ne!(fin.landmarks, a.landmarks, "the first pass ran");
        for l in locked {
            assert!(fin.coarse_index(l).is_some(), "{l}");
        }
        for (s, want) in snaps.iter().zip([1000, 300]) {
            check(&mesh, s, want);
            assert!(fin.landmarks.iter().all(|l| s.coarse_index(*l).is_some()));
        }
    }

    #[test]
    fn deterministic() {
        let mesh = valid(procedural::with_noise(
            procedural::torus(50, 20, 1.0, 0.3),
            0.2,
            5,
        ));
        let a = select_landmarks(&mesh, &opts(77), &NoProgress).unwrap();
        let b = select_landmarks(&mesh, &opts(77), &NoProgress).unwrap();
        assert_eq!(a, b);
    }

    #[test]
    fn quadric_keeps_the_sharp_feature() {
        // A flat grid with one spike: the spike's collapse costs a lot, so it survives.
        let mut g = procedural::grid(20, 20, 1.0, 1.0);
        let spike = 10 * 21 + 10;
        g.positions[spike].z = 0.5;
        let mesh = valid(g);
        let lm = select_landmarks(&mesh, &opts(12), &NoProgress).unwrap();
        assert!(lm.contains(&(spike as u32)), "{lm:?}");
        eprintln!("grid with spike -> {lm:?}");
    }

    #[test]
    fn bad_requests_are_refused() {
        let mesh = valid(procedural::icosphere(1));
        let n = mesh.n_vertices();
        for o in [
            opts(0),
            opts(n + 1),
            DecimateOptions {
                max_normal_deviation_deg: 0.0,
                ..opts(10)
            },
            DecimateOptions {
                max_normal_deviation_deg: f64::NAN,
                ..opts(10)
            },
            DecimateOptions {
                max_normal_cone_deg: Some(-1.0),
                ..opts(10)
            },
            DecimateOptions {
                locked: vec![n as u32],
                ..opts(10)
            },
            DecimateOptions {
                locked: (0..11).collect(),
                ..opts(10)
            },
        ] {
            assert!(
                matches!(
                    decimate(&mesh, &o, &NoProgress),
                    Err(EmbedError::InvalidArgument(_))
                ),
                "{o:?}"
            );
        }
        // Target = all vertices: nothing to do.
        let d = decimate(&mesh, &opts(n), &NoProgress).unwrap();
        assert_eq!(d.landmarks, (0..n as u32).collect::<Vec<_>>());
        assert_eq!(d.mesh.triangles, mesh.triangles);
    }

    #[test]
    fn topological_limits_are_errors_not_hangs() {
        // An icosahedron decimates to a tetrahedron, not further.
        let mesh = valid(procedural::icosphere(0));
        let d = decimate(&mesh, &opts(4), &NoProgress).unwrap();
        check(&mesh, &d, 4);
        assert!(matches!(
            decimate(&mesh, &opts(3), &NoProgress),
            Err(EmbedError::InvalidArgument(_))
        ));
        // A torus needs at least 7 vertices.
        let mesh = valid(procedural::torus(12, 6, 1.0, 0.3));
        let e = decimate(&mesh, &opts(5), &NoProgress).unwrap_err();
        eprintln!("torus to 5 vertices: {e}");
        // A single triangle cannot lose a vertex.
        let tri = valid(TriMesh::new(
            vec![Vector3::zeros(), Vector3::x(), Vector3::y()],
            vec![[0, 1, 2]],
        ));
        assert!(decimate(&tri, &opts(2), &NoProgress).is_err());
    }

    #[test]
    fn locked_vertices_survive() {
        let mesh = valid(procedural::icosphere(3));
        let locked: Vec<u32> = (0..40).map(|i| i * 13 + 1).collect();
        let d = decimate(
            &mesh,
            &DecimateOptions {
                locked: locked.clone(),
                ..opts(50)
            },
            &NoProgress,
        )
        .unwrap();
        check(&mesh, &d, 50);
        for l in locked {
            assert!(d.coarse_index(l).is_some(), "{l}");
        }
    }

    #[test]
    fn tight_bounds_are_relaxed_to_reach_the_target() {
        let mesh = valid(procedural::with_noise(procedural::icosphere(4), 0.3, 8));
        let o = DecimateOptions {
            max_normal_deviation_deg: 2.0,
            max_normal_cone_deg: Some(10.0),
            ..opts(40)
        };
        let d = decimate(&mesh, &o, &NoProgress).unwrap();
        check(&mesh, &d, 40);
        assert!(!d.relaxations.is_empty());
        eprintln!("relaxations {:?}", d.relaxations);
        let strict = DecimateOptions { relax: false, ..o };
        assert!(decimate(&mesh, &strict, &NoProgress).is_err());
    }

    #[test]
    fn aspect_bounds_are_checked_and_relaxed() {
        let mesh = valid(procedural::with_noise(procedural::icosphere(4), 0.3, 8));
        for bad in [f64::NAN, f64::INFINITY, 1.0] {
            let o = DecimateOptions {
                max_aspect_ratio: Some(bad),
                ..opts(40)
            };
            assert!(decimate(&mesh, &o, &NoProgress).is_err(), "{bad}");
        }
        // Near-equilateral only: blocked long before the target, relaxed until reached.
        let o = DecimateOptions {
            max_aspect_ratio: Some(1.2),
            ..opts(40)
        };
        let d = decimate(&mesh, &o, &NoProgress).unwrap();
        check(&mesh, &d, 40);
        assert!(
            d.relaxations[0].max_aspect_ratio > Some(1.2),
            "{:?}",
            d.relaxations
        );
    }

    #[test]
    fn normal_cone_module() {
        let mesh = valid(procedural::bump_sphere(4, 0.5));
        let o = DecimateOptions {
            max_normal_cone_deg: Some(60.0),
            ..opts(200)
        };
        let d = decimate(&mesh, &o, &NoProgress).unwrap();
        check(&mesh, &d, 200);
    }

    #[test]
    fn snapshots_are_nested() {
        let mesh = valid(procedural::with_noise(
            procedural::torus(60, 24, 1.0, 0.3),
            0.2,
            1,
        ));
        let n = mesh.n_vertices();
        let (fin, snaps) =
            decimate_with_snapshots(&mesh, &opts(70), &[500, n, 70, 200], &NoProgress).unwrap();
        let direct = decimate(&mesh, &opts(70), &NoProgress).unwrap();
        assert_eq!(fin.landmarks, direct.landmarks);
        for (s, want) in snaps.iter().zip([500, n, 70, 200]) {
            check(&mesh, s, want);
            assert!(fin.landmarks.iter().all(|l| s.coarse_index(*l).is_some()));
        }
        assert_eq!(snaps[2].landmarks, fin.landmarks);
        assert!(
            snaps[0]
                .landmarks
                .iter()
                .all(|l| snaps[1].coarse_index(*l).is_some())
        );
        assert!(decimate_with_snapshots(&mesh, &opts(70), &[60], &NoProgress).is_err());
    }

    #[test]
    fn cancellation() {
        struct Stop;
        impl Progress for Stop {
            fn report(&self, _: Stage, _: f64) {}
            fn cancelled(&self) -> bool {
                true
            }
        }
        let mesh = valid(procedural::icosphere(5));
        assert!(matches!(
            decimate(&mesh, &opts(100), &Stop),
            Err(EmbedError::Cancelled)
        ));
    }

    #[test]
    fn real_meshes_keep_topology() {
        for (file, target) in [
            ("meshes/pig.off", 1000),
            ("meshes/fertility.off", 1000),
            ("meshes/camelhead.off", 1000),
            ("meshes/3holes.off", 300),
            ("meshes/torus.obj", 50),
        ] {
            let Some(path) = wavg_testdata::require_data_file("decimate::real_meshes", file) else {
                return;
            };
            let mesh = valid(wavg_mesh::io::load(&path).unwrap());
            let t = std::time::Instant::now();
            let d = decimate(&mesh, &opts(target), &NoProgress).unwrap();
            let secs = t.elapsed().as_secs_f64();
            check(&mesh, &d, target);
            eprintln!(
                "{file}: {} -> {target} vertices in {secs:.3} s (test build), genus {}, {} loops, relaxations {:?}",
                mesh.n_vertices(),
                mesh.topology().genus(),
                mesh.topology().boundary_loops().len(),
                d.relaxations
            );
        }
    }

    proptest! {
        #[test]
        fn indexed_heap_pops_in_key_order(ops in proptest::collection::vec((0u32..50, 0u64..20, any::<bool>()), 0..300)) {
            let mut h = IndexedHeap::new(50);
            let mut model = std::collections::BTreeMap::new();
            for (v, k, set) in ops {
                if set {
                    h.set(v, (k, 0, v));
                    model.insert(v, (k, 0, v));
                } else {
                    h.remove(v);
                    model.remove(&v);
                }
            }
            let mut want: Vec<_> = model.into_values().collect();
            want.sort();
            let mut got = Vec::new();
            while let Some(&(k, v)) = h.items.first() {
                prop_assert_eq!(h.pop(), Some(v));
                got.push(k);
            }
            prop_assert_eq!(got, want);
        }
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(24))]
        #[test]
        fn random_meshes_and_targets(seed in 0u64..10_000, kind in 0usize..3, frac in 0.02f64..0.9) {
            let m = match kind {
                0 => procedural::with_noise(procedural::icosphere(3), 0.4, seed),
                1 => procedural::with_noise(procedural::torus(24, 12, 1.0, 0.35), 0.4, seed),
                _ => procedural::with_noise(procedural::grid(16, 12, 1.0, 1.0), 0.4, seed),
            };
            let mesh = valid(m);
            let target = ((mesh.n_vertices() as f64 * frac) as usize).max(12);
            let d = decimate(&mesh, &opts(target), &NoProgress).unwrap();
            check(&mesh, &d, target);
        }
    }
}
