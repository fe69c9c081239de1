//! The whole precomputation: landmarks, geodesics, MDS, least-squares mesh, quality check.

use std::time::Instant;

use wavg_mesh::ValidMesh;

use crate::decimate::{DecimateOptions, select_landmarks};
use crate::error::{EmbedError, Progress, check_cancel};
use crate::file::{Embedding, EmbeddingParams, MAX_DIM};
use crate::geodesic::{FastMarching, landmark_distances_with};
use crate::lsmesh::least_squares_mesh;
use crate::mds::{MdsOptions, metric_mds};
use crate::quality::{QualityOptions, geodesic_quality};

/// Settings of [`precompute`].
#[derive(Clone, Debug, PartialEq)]
pub struct PrecomputeOptions {
    /// Number of landmarks (paper: 1000). If the mesh has no more vertices than this, every
    /// vertex is a landmark and no decimation happens.
    pub landmarks: usize,
    /// Seed of the random choices (the quality-check pairs; every other stage is
    /// deterministic).
    pub seed: u64,
    /// Decimation settings; `decimate.target` is ignored (set from `landmarks`).
    pub decimate: DecimateOptions,
    /// MDS settings (`mds.dim` is the embedding dimension, 8 in wavg).
    pub mds: MdsOptions,
    /// Vertex pairs for the quality check; 0 skips it (errors are then NaN).
    pub quality_pairs: usize,
    /// Fast-marching runs the quality pairs are spread over.
    pub quality_sources: usize,
}

impl Default for PrecomputeOptions {
    fn default() -> Self {
        Self {
            landmarks: 1000,
            seed: 0,
            decimate: DecimateOptions::default(),
            mds: MdsOptions::default(),
            quality_pairs: 1024,
            quality_sources: 16,
        }
    }
}

/// Wall-clock seconds per stage.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct StageSeconds {
    /// Landmark selection.
    pub decimate: f64,
    /// Fast-marching setup and landmark-to-landmark distances.
    pub geodesics: f64,
    /// Classical MDS and SMACOF.
    pub mds: f64,
    /// Least-squares mesh.
    pub lsmesh: f64,
    /// Quality check (0 if skipped).
    pub quality: f64,
}

/// What [`precompute`] measured.
#[derive(Clone, Debug, PartialEq)]
pub struct Report {
    /// Total wall-clock seconds.
    pub seconds: f64,
    /// Per stage.
    pub stages: StageSeconds,
    /// Landmarks used.
    pub landmarks: usize,
    /// Embedding dimension.
    pub dim: usize,
    /// Final MDS stress (RMS relative landmark distance error, see [`crate::mds`]).
    pub stress: f64,
    /// Stress of the classical-MDS start.
    pub initial_stress: f64,
    /// SMACOF iterations.
    pub mds_iterations: usize,
    /// Whether SMACOF met its tolerance.
    pub mds_converged: bool,
    /// Median relative error of embedding vs geodesic distance (NaN if not measured).
    pub geodesic_rel_err_p50: f64,
    /// 90th percentile of the same.
    pub geodesic_rel_err_p90: f64,
    /// Pairs in the quality check.
    pub quality_pairs: usize,
    /// Mesh vertices.
    pub vertices: usize,
    /// Mesh faces.
    pub faces: usize,
}

/// Computes the 8-D embedding of `mesh` (paper Section 3.5).
///
/// The mesh must be connected (one component; any genus, boundaries allowed). Progress is
/// reported per [`crate::Stage`]; when `progress.cancelled()` turns true the computation
/// stops at the next check and returns [`EmbedError::Cancelled`].
///
/// ```
/// use wavg_embed::pipeline::{PrecomputeOptions, precompute};
/// use wavg_embed::NoProgress;
/// use wavg_mesh::{ValidMesh, procedural};
/// let mesh = ValidMesh::new(procedural::torus(48, 24, 1.0, 0.4)).unwrap();
/// let opts = PrecomputeOptions { landmarks: 100, ..Default::default() };
/// let (emb, report) = precompute(&mesh, &opts, &NoProgress).unwrap();
/// assert_eq!(emb.coords.len(), mesh.n_vertices());
/// assert_eq!(report.landmarks, 100);
/// assert!(report.geodesic_rel_err_p50 < 0.1);
/// ```
pub fn precompute(
    mesh: &ValidMesh,
    opts: &PrecomputeOptions,
    progress: &dyn Progress,
) -> Result<(Embedding, Report), EmbedError> {
    let start = Instant::now();
    let n = mesh.n_vertices();
    let components = mesh.topology().n_components();
    if components != 1 {
        return Err(EmbedError::InvalidArgument(format!(
            "the mesh has {components} connected components; the embedding needs exactly one \
             (repair with `--largest-component`)"
        )));
    }
    if opts.landmarks < 4 {
        return Err(EmbedError::InvalidArgument(format!(
            "{} landmarks requested; at least 4 are needed",
            opts.landmarks
        )));
    }
    if n < 4 {
        return Err(EmbedError::InvalidArgument(format!(
            "the mesh has {n} vertices; at least 4 are needed"
        )));
    }
    let dim = opts.mds.dim;
    if dim == 0 || dim > MAX_DIM {
        return Err(EmbedError::InvalidArgument(format!(
            "embedding dimension {dim} not in 1..={MAX_DIM}"
        )));
    }
    let mut stages = StageSeconds::default();

    // 1. Landmarks.
    let t = Instant::now();
    let landmarks: Vec<u32> = if opts.landmarks >= n {
        (0..n as u32).collect()
    } else {
        let d = DecimateOptions {
            target: opts.landmarks,
            ..opts.decimate.clone()
        };
        select_landmarks(mesh, &d, progress)?
    };
    stages.decimate = t.elapsed().as_secs_f64();
    check_cancel(progress)?;

    // 2. Geodesic distances between landmarks.
    let t = Instant::now();
    let fm = FastMarching::new(mesh);
    let q = landmark_distances_with(&fm, &landmarks, progress)?;
    stages.geodesics = t.elapsed().as_secs_f64();
    check_cancel(progress)?;

    // 3. MDS of the landmarks.
    let t = Instant::now();
    let mds = metric_mds(&q, landmarks.len(), &opts.mds, progress)?;
    drop(q);
    stages.mds = t.elapsed().as_secs_f64();
    check_cancel(progress)?;

    // 4. Least-squares mesh.
    let t = Instant::now();
    let coords = least_squares_mesh(mesh, &landmarks, &mds.points, dim, progress)?;
    stages.lsmesh = t.elapsed().as_secs_f64();
    check_cancel(progress)?;

    // 5. Quality.
    let t = Instant::now();
    let quality = if opts.quality_pairs > 0 {
        let qo = QualityOptions {
            pairs: opts.quality_pairs,
            sources: opts.quality_sources.clamp(1, opts.quality_pairs),
            seed: opts.seed,
        };
        Some(geodesic_quality(mesh, &fm, &coords, &qo, progress)?)
    } else {
        None
    };
    stages.quality = t.elapsed().as_secs_f64();

    let (p50, p90) = quality
        .as_ref()
        .map_or((f64::NAN, f64::NAN), |q| (q.rel_err_p50, q.rel_err_p90));
    let embedding = Embedding {
        dim,
        coords,
        landmarks: landmarks.clone(),
        params: EmbeddingParams {
            landmarks_requested: opts.landmarks as u64,
            seed: opts.seed,
            mds_max_iterations: opts.mds.max_iterations as u64,
            mds_tolerance: opts.mds.tolerance,
            geodesic_mesh_vertices: 0,
        },
        stress: mds.stress,
        geodesic_rel_err_p50: p50,
        geodesic_rel_err_p90: p90,
    };
    let report = Report {
        seconds: start.elapsed().as_secs_f64(),
        stages,
        landmarks: landmarks.len(),
        dim,
        stress: mds.stress,
        initial_stress: mds.initial_stress,
        mds_iterations: mds.iterations,
        mds_converged: mds.converged,
        geodesic_rel_err_p50: p50,
        geodesic_rel_err_p90: p90,
        quality_pairs: quality.map_or(0, |q| q.pairs),
        vertices: n,
        faces: mesh.n_faces(),
    };
    Ok((embedding, report))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::{NoProgress, Stage};
    use std::sync::Mutex;
    use std::sync::atomic::{AtomicBool, Ordering};
    use wavg_mesh::{TriMesh, procedural};

    fn opts(landmarks: usize) -> PrecomputeOptions {
        PrecomputeOptions {
            landmarks,
            quality_pairs: 512,
            ..Default::default()
        }
    }

    fn check(mesh: TriMesh, landmarks: usize, p50: f64, p90: f64) -> (Embedding, Report) {
        let mesh = ValidMesh::new(mesh).unwrap();
        let (emb, r) = precompute(&mesh, &opts(landmarks), &NoProgress).unwrap();
        emb.validate(mesh.n_vertices()).unwrap();
        assert_eq!(emb.landmarks.len(), landmarks);
        assert_eq!(r.landmarks, landmarks);
        assert_eq!((r.vertices, r.faces), (mesh.n_vertices(), mesh.n_faces()));
        assert!(r.stress < r.initial_stress + 1e-12);
        eprintln!(
            "{} vertices, {landmarks} landmarks: stress {:.4}, rel err p50 {:.4} p90 {:.4}",
            r.vertices, r.stress, r.geodesic_rel_err_p50, r.geodesic_rel_err_p90
        );
        assert!(
            r.geodesic_rel_err_p50 < p50 && r.geodesic_rel_err_p90 < p90,
            "{r:?}"
        );
        // The file round trip works on the result.
        let bytes = crate::file::encode(&emb, &mesh).unwrap();
        let back = crate::file::decode(&bytes, &mesh, std::path::Path::new("x")).unwrap();
        assert_eq!(back.coords, emb.coords);
        (emb, r)
    }

    #[test]
    fn genus_zero_genus_one_and_open_meshes_embed() {
        // A sphere has no isometric embedding in any R^d: larger errors than real shapes.
        check(procedural::bump_sphere(4, 0.15), 150, 0.1, 0.2);
        check(procedural::torus(60, 30, 1.0, 0.4), 150, 0.1, 0.2);
        check(procedural::grid(40, 40, 1.0, 1.0), 100, 0.05, 0.15);
    }

    #[test]
    fn landmarks_take_their_mds_positions() {
        let mesh = ValidMesh::new(procedural::torus(40, 20, 1.0, 0.4)).unwrap();
        let o = opts(60);
        let (emb, r) = precompute(&mesh, &o, &NoProgress).unwrap();
        // Recompute the landmark MDS independently and compare distances at landmarks.
        let fm = FastMarching::new(&mesh);
        let q = landmark_distances_with(&fm, &emb.landmarks, &NoProgress).unwrap();
        let stress = crate::mds::relative_stress(
            &q,
            60,
            &emb.landmarks
                .iter()
                .map(|&s| emb.coords[s as usize])
                .collect::<Vec<_>>(),
        )
        .unwrap();
        assert!((stress - r.stress).abs() < 1e-9, "{stress} vs {}", r.stress);
    }

    #[test]
    fn more_landmarks_than_vertices_uses_every_vertex() {
        let mesh = ValidMesh::new(procedural::icosphere(1)).unwrap();
        let (emb, r) = precompute(&mesh, &opts(1000), &NoProgress).unwrap();
        assert_eq!(r.landmarks, 42);
        assert_eq!(emb.landmarks, (0..42).collect::<Vec<u32>>());
    }

    #[test]
    fn several_components_are_refused_with_the_repair_hint() {
        let a = procedural::icosphere(2);
        let b = a.clone().map_positions(|p| p.add_scalar(5.0));
        let na = a.n_vertices() as u32;
        let mut m = a.clone();
        m.positions.extend(&b.positions);
        m.triangles
            .extend(b.triangles.iter().map(|t| t.map(|v| v + na)));
        let mesh = ValidMesh::new(m).unwrap();
        let e = precompute(&mesh, &opts(50), &NoProgress).unwrap_err();
        assert!(e.to_string().contains("--largest-component"), "{e}");
    }

    #[test]
    fn bad_options_are_refused() {
        let mesh = ValidMesh::new(procedural::icosphere(2)).unwrap();
        assert!(precompute(&mesh, &opts(3), &NoProgress).is_err());
        let mut o = opts(50);
        o.mds.dim = 9;
        assert!(precompute(&mesh, &o, &NoProgress).is_err());
    }

    /// Cancels once a report for `stage` arrives; records the stages seen.
    struct CancelAt {
        stage: Stage,
        flag: AtomicBool,
        seen: Mutex<Vec<Stage>>,
    }

    impl Progress for CancelAt {
        fn report(&self, stage: Stage, fraction: f64) {
            assert!((0.0..=1.0).contains(&fraction), "{fraction}");
            let mut seen = self.seen.lock().unwrap();
            if seen.last() != Some(&stage) {
                seen.push(stage);
            }
            if stage == self.stage {
                self.flag.store(true, Ordering::SeqCst);
            }
        }
        fn cancelled(&self) -> bool {
            self.flag.load(Ordering::SeqCst)
        }
    }

    #[test]
    fn cancellation_stops_in_every_stage_and_stages_come_in_order() {
        let mesh = ValidMesh::new(procedural::torus(40, 20, 1.0, 0.4)).unwrap();
        for stage in [
            Stage::Decimate,
            Stage::Geodesics,
            Stage::Mds,
            Stage::LsMesh,
            Stage::Quality,
        ] {
            let p = CancelAt {
                stage,
                flag: AtomicBool::new(false),
                seen: Mutex::new(Vec::new()),
            };
            let r = precompute(&mesh, &opts(60), &p);
            assert!(matches!(r, Err(EmbedError::Cancelled)), "{stage:?}: {r:?}");
            let seen = p.seen.lock().unwrap().clone();
            assert_eq!(seen.last(), Some(&stage));
        }
        // Uncancelled: all five stages, in order.
        let p = CancelAt {
            stage: Stage::Quality,
            flag: AtomicBool::new(false),
            seen: Mutex::new(Vec::new()),
        };
        struct Never<'a>(&'a CancelAt);
        impl Progress for Never<'_> {
            fn report(&self, s: Stage, f: f64) {
                let mut seen = self.0.seen.lock().unwrap();
                assert!((0.0..=1.0).contains(&f));
                if seen.last() != Some(&s) {
                    seen.push(s);
                }
            }
        }
        precompute(&mesh, &opts(60), &Never(&p)).unwrap();
        assert_eq!(
            *p.seen.lock().unwrap(),
            vec![
                Stage::Decimate,
                Stage::Geodesics,
                Stage::Mds,
                Stage::LsMesh,
                Stage::Quality
            ]
        );
    }
}
