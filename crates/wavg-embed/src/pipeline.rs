//! The whole precomputation: landmarks, geodesics, MDS, least-squares mesh, quality check.

use std::time::Instant;

use wavg_mesh::ValidMesh;

use crate::decimate::{DecimateOptions, Decimated, decimate_beside, decimate_with_snapshots};
use crate::error::{EmbedError, Progress, Stage, check_cancel};
use crate::file::MAX_DIM;
use crate::geodesic::{FastMarching, GeodesicOptions, KeptRows, landmark_distances_kept};
use crate::lsmesh::LsMeshSolver;
use crate::lsmesh::two_level::{CgOptions, LsMeshExtension, TwoLevelLsMesh};
use crate::mds::{MdsOptions, metric_mds};
use crate::memtrace::mark;
use crate::quality::{QualityOptions, QualityPairs, quality_sources};
use crate::report::{Report, StageSeconds};
use crate::thin::{self, landmark_aspect_bound};
use crate::{Embedding, EmbeddingParams};

/// Settings of [`precompute`](crate::precompute).
#[derive(Clone, Debug, PartialEq)]
pub struct PrecomputeOptions {
    /// Number of landmarks (paper: 1000). If the mesh has no more vertices than this, every
    /// vertex is a landmark and no decimation happens.
    pub landmarks: usize,
    /// Seed of the random choices (the quality-check pairs; every other stage is
    /// deterministic).
    pub seed: u64,
    /// Decimation settings; `decimate.target` is ignored (set from `landmarks`). The
    /// default adds an aspect-ratio bound ([`LANDMARK_ASPECT_RATIO`]) to
    /// [`DecimateOptions::default`].
    pub decimate: DecimateOptions,
    /// When the mesh has more vertices than this, the landmark-to-landmark geodesics run on
    /// the landmark decimation's intermediate state with this many vertices (its vertices
    /// are original vertices and include every landmark) instead of the full mesh; 0 means
    /// always the full mesh (the paper's choice). Fast-marching time is proportional to the
    /// vertex count; the quality check always uses the full mesh. Default 10 000, where the
    /// geodesic errors stay close to full resolution's (figures in `BENCHMARKS.md`).
    pub geodesic_vertices: usize,
    /// With an intermediate mesh, replace the distances of close landmark pairs by
    /// full-mesh values from short radius-limited runs
    /// ([`GeodesicOptions::refine_near_pairs`]): close pairs are where the
    /// intermediate mesh is least accurate; distant pairs are unchanged. When the
    /// least-squares mesh is solved in two levels, these runs go on its coarse level's mesh
    /// (`lsmesh_coarse_vertices` vertices, [`GeodesicOptions::refine_on`]) instead, so
    /// that their cost stops growing with the mesh.
    pub refine_near_pairs: bool,
    /// MDS settings (`mds.dim` is the embedding dimension, 8 in wavg).
    pub mds: MdsOptions,
    /// Vertex pairs for the quality check; 0 skips it (errors are then NaN).
    pub quality_pairs: usize,
    /// Fast-marching runs the quality pairs are spread over, at most
    /// `max(2, 16 000 000 / vertices)`: on large meshes fewer runs carry the same number of
    /// pairs, so the check visits about 16M vertices whatever the mesh's size (it is a
    /// check, not an output) while the pairs' distances stay exact full-mesh geodesics.
    /// The default 16 is used in full up to 1M vertices; 8 at 2M, 5 at 3M, 2 from 8M on.
    pub quality_sources: usize,
    /// Meshes with more vertices than this solve the least-squares mesh in two levels
    /// (a direct solve on the landmark decimation's state with
    /// `lsmesh_coarse_vertices` vertices, then conjugate gradients on the full system
    /// started from it) instead of one sparse Cholesky factorisation, whose time and
    /// memory grow faster than the mesh. Default 300 000.
    pub lsmesh_direct_max: usize,
    /// Vertices of the coarse level of the two-level least-squares mesh (default 150 000).
    pub lsmesh_coarse_vertices: usize,
    /// Add landmarks where parts thinner than the landmark spacing (fingers, toes, ears)
    /// would collapse in the embedding (default on): the least-squares extension of the
    /// landmarks' own positions shows where, and up to [`THIN_PART_ROUNDS`] rounds add at
    /// most `landmarks` more in all. On meshes that got some, the solved embedding is
    /// checked too: where it squashes vertices toward a landmark, up to two more rounds
    /// add landmarks there and solve again. Meshes without such parts are unchanged.
    pub cover_thin_parts: bool,
}

/// Rounds of landmark additions around thin parts at most
/// ([`PrecomputeOptions::cover_thin_parts`]): each halves the distance from the collapsed
/// region to its landmarks.
pub const THIN_PART_ROUNDS: usize = 8;

/// Aspect-ratio bound of the landmark decimation by default (raised to twice the input's
/// 90th-percentile ratio where that is larger). Quadric errors alone let thin parts
/// (fingers, tails, tubes) decimate into long triangles that keep landmarks along one
/// side only; the least-squares mesh then folds the other side onto it. With round
/// triangles every cross-section keeps landmarks all around.
pub const LANDMARK_ASPECT_RATIO: f64 = 10.0;

/// The most memory the geodesic runs kept between the rounds of step 4b may take
/// (8 bytes a vertex of the geodesic mesh a landmark): beyond it they run again.
const KEPT_ROWS_BYTES: usize = 256 << 20;

/// What the quality check's first part yields: the full mesh's fast marching, the pairs
/// with their geodesic distances, and its seconds.
type QualityOut = Result<(Option<FastMarching>, Option<QualityPairs>, f64), EmbedError>;

impl Default for PrecomputeOptions {
    fn default() -> Self {
        Self {
            landmarks: 1000,
            seed: 0,
            decimate: DecimateOptions {
                max_aspect_ratio: Some(LANDMARK_ASPECT_RATIO),
                ..DecimateOptions::default()
            },
            geodesic_vertices: crate::geodesic::DEFAULT_GEODESIC_VERTICES,
            refine_near_pairs: true,
            mds: MdsOptions::default(),
            quality_pairs: 1024,
            quality_sources: 16,
            lsmesh_direct_max: 300_000,
            lsmesh_coarse_vertices: 150_000,
            cover_thin_parts: true,
        }
    }
}

/// [`crate::precompute`] on a mesh of moderate scale (see [`crate::scaled`]), its range
/// already checked; `keep_rows` keeps the geodesic runs for step 4b's rounds (the same
/// numbers either way: off only to test that).
pub(crate) fn precompute_unscaled(
    mesh: &ValidMesh,
    opts: &PrecomputeOptions,
    progress: &dyn Progress,
    keep_rows: bool,
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
    mark("before the precomputation");
    let mut stages = StageSeconds::default();
    let secs = |t: Instant| t.elapsed().as_secs_f64();
    // 1. Landmarks (and, for large meshes, intermediate meshes for the geodesics and the
    //    least-squares mesh): `target` of them, keeping `locked`, with `alongside` run
    //    beside the decimation's collapses (after its first pass).
    type Alongside<'a> = Box<dyn FnOnce() -> QualityOut + Send + 'a>;
    // The intermediate meshes' sizes for `target` landmarks: the geodesics' and the
    // two-level least-squares mesh's, each if used.
    let snapshot_sizes = |target: usize| {
        let use_coarse = opts.geodesic_vertices > target && opts.geodesic_vertices < n;
        let two_level = n > opts.lsmesh_direct_max
            && opts.lsmesh_coarse_vertices > target
            && opts.lsmesh_coarse_vertices < n;
        [
            use_coarse.then_some(opts.geodesic_vertices),
            two_level.then_some(opts.lsmesh_coarse_vertices),
        ]
    };
    // One pass over the faces, whatever the rounds.
    let aspect_bound = landmark_aspect_bound(mesh, opts.decimate.max_aspect_ratio);
    let decimate_options = |target: usize, locked: Vec<u32>| DecimateOptions {
        target,
        max_aspect_ratio: aspect_bound,
        locked,
        ..opts.decimate.clone()
    };
    let select = |target: usize, locked: &[u32], alongside: Option<Alongside<'_>>| {
        let t = Instant::now();
        let run = move || alongside.map(|f| f());
        if target >= n {
            let all = ((0..n as u32).collect::<Vec<u32>>(), None, None, secs(t));
            return (Ok(all), run());
        }
        let [coarse_size, ls_size] = snapshot_sizes(target);
        let d = decimate_options(target, locked.to_vec());
        let sizes: Vec<usize> = [coarse_size, ls_size].into_iter().flatten().collect();
        let (res, other, end) = decimate_beside(mesh, &d, &sizes, progress, run);
        let res = res.map(|(fin, mut snaps)| {
            let ls = if ls_size.is_some() { snaps.pop() } else { None };
            let coarse = if coarse_size.is_some() {
                snaps.pop()
            } else {
                None
            };
            (fin.landmarks, coarse, ls, (end - t).as_secs_f64())
        });
        (res, other.flatten())
    };
    // A later round's selection, restarted from `base`, the finest intermediate mesh of
    // the round before (which holds every locked vertex): the full mesh is not decimated
    // again.
    let reselect = |base: &Decimated, target: usize, locked: &[u32]| {
        let t = Instant::now();
        let sizes = snapshot_sizes(target);
        let nb = base.landmarks.len();
        let local = (locked.iter())
            .map(|&l| base.coarse_index(l))
            .collect::<Option<Vec<u32>>>();
        let (Some(local), true) = (local, sizes.iter().flatten().all(|&s| s <= nb)) else {
            return select(target, locked, None).0;
        };
        let base_mesh = ValidMesh::new(base.mesh.clone())
            .map_err(|e| EmbedError::InvalidArgument(format!("intermediate mesh: {e}")))?;
        let d = DecimateOptions {
            first_pass_vertices: 0,
            ..decimate_options(target, local)
        };
        let smaller: Vec<usize> = sizes
            .iter()
            .flatten()
            .copied()
            .filter(|&s| s < nb)
            .collect();
        let (fin, snaps) = decimate_with_snapshots(&base_mesh, &d, &smaller, progress)?;
        let lift = |d: Decimated| Decimated {
            landmarks: (d.landmarks.iter())
                .map(|&v| base.landmarks[v as usize])
                .collect(),
            ..d
        };
        let mut snaps = snaps.into_iter().map(lift);
        let [coarse, ls] = sizes.map(|s| match s {
            Some(s) if s < nb => snaps.next(),
            Some(_) => Some(base.clone()),
            None => None,
        });
        Ok((lift(fin).landmarks, coarse, ls, secs(t)))
    };
    // The quality check's fast marching on the full mesh (it does not depend on the
    // embedding) runs beside the first selection's collapses, after the decimation's
    // first pass: the two largest transient allocations of the stage do not overlap.
    let quality = || -> QualityOut {
        let t = Instant::now();
        if opts.quality_pairs == 0 {
            return Ok((None, None, 0.0));
        }
        let fm = FastMarching::new_cancellable(mesh, progress)?;
        let sources = quality_sources(opts.quality_sources, n, opts.quality_pairs);
        let qo = QualityOptions {
            pairs: opts.quality_pairs,
            sources,
            seed: opts.seed,
        };
        let pairs = QualityPairs::compute(mesh, &fm, &qo, progress)?;
        Ok((Some(fm), Some(pairs), secs(t)))
    };
    let (landmark_result, quality_result) = select(
        opts.landmarks,
        &opts.decimate.locked,
        Some(Box::new(quality)),
    );
    // The quality check does not run when the decimation failed before its collapses.
    let quality_result = quality_result.unwrap_or(Err(EmbedError::Cancelled));
    let mut selected = landmark_result?;
    let (fm, quality_pairs, t_quality) = quality_result?;
    // The full mesh's fast marching (about 400 bytes a vertex) is kept only where the
    // landmark geodesics use it: with an intermediate mesh whose close pairs are refined on
    // the least-squares mesh's coarse level, they never do (`landmark_distances` builds one
    // itself should a later round need it).
    let needs_fine = selected.1.is_none() || (opts.refine_near_pairs && selected.2.is_none());
    // (Matched as a tuple that owns it, so that the unused one is dropped here.)
    let fm = match (fm, needs_fine) {
        (Some(fm), true) => Some(fm),
        (None, true) => Some(FastMarching::new_cancellable(mesh, progress)?),
        (_, false) => None,
    };
    mark("decimation + quality geodesics");
    stages.quality = t_quality;
    check_cancel(progress)?;

    // 2. Geodesic distances between landmarks (parallel), while the least-squares system,
    //    which depends only on the mesh and the landmarks, is factored alongside
    //    (sequential): this fills the second core during the geodesics' tail. Then, where
    //    the landmarks leave a thin part uncovered (see `thin`), the landmarks so far are
    //    locked, more are added (on the finest intermediate mesh where it has vertices there),
    //    and steps 1 and 2 run again (at most `THIN_PART_ROUNDS` times, adding at most as
    //    many landmarks as asked for in all): the decimation restarts from that
    //    intermediate mesh, not from the full one.
    let geodesics = |fine: Option<&FastMarching>,
                     landmarks: &[u32],
                     coarse: Option<&Decimated>,
                     mid: Option<&Decimated>,
                     kept: Option<&mut KeptRows>| {
        let t = Instant::now();
        let mut geo = GeodesicOptions::new();
        if let Some(fine) = fine {
            geo = geo.fast_marching(fine);
        }
        if let Some(c) = coarse {
            // All pairs on the intermediate mesh, close pairs corrected on the full mesh.
            geo = geo.coarse_mesh(c).refine_near_pairs(opts.refine_near_pairs);
            if let Some(mid) = mid {
                geo = geo.refine_on(mid);
            }
        }
        let q = landmark_distances_kept(mesh, landmarks, &geo, kept, progress)?;
        Ok::<_, EmbedError>((q, secs(t)))
    };
    // The least-squares system; a later round's two-level system keeps the full mesh's
    // operator of the round before (`previous`).
    let factor = |landmarks: &[u32], mid: Option<&Decimated>, previous: Option<LsMeshExtension>| {
        let t = Instant::now();
        let solver = match (mid, previous) {
            (Some(c), Some(LsMeshExtension::TwoLevel(p))) => {
                LsMeshExtension::TwoLevel(Box::new(p.with_landmarks(c, landmarks, progress)?))
            }
            (Some(c), _) => LsMeshExtension::TwoLevel(Box::new(TwoLevelLsMesh::new(
                mesh,
                c,
                landmarks,
                CgOptions::default(),
                progress,
            )?)),
            (None, _) => {
                LsMeshExtension::Direct(Box::new(LsMeshSolver::new(mesh, landmarks, progress)?))
            }
        };
        Ok::<_, EmbedError>((solver, secs(t)))
    };
    // The selection of `locked` landmarks after a round (from `base`, the finest
    // intermediate mesh, if any), with 1 or 8 more should no collapse remove a vertex.
    let relock = |base: Option<&Decimated>, locked: &[u32]| {
        [0, 1, 8]
            .into_iter()
            .filter(|extra| locked.len() + extra <= n)
            .find_map(|extra| {
                let target = locked.len() + extra;
                let next = match base {
                    Some(b) => reselect(b, target, locked),
                    None => select(target, locked, None).0,
                };
                match next {
                    Err(EmbedError::InvalidArgument(_)) => None,
                    other => Some(other),
                }
            })
    };
    let mut added = 0;
    let mut round = 0;
    let mut previous: Option<LsMeshExtension> = None;
    let (landmarks, q, solver, coarse, ls_coarse) = loop {
        let (landmarks, coarse, ls_coarse, t_decimate) = selected;
        stages.decimate += t_decimate;
        // Later rounds only need the factorisation; the geodesics wait for the last.
        let (q, solver) = if round == 0 {
            let (q, solver) = rayon::join(
                || {
                    geodesics(
                        fm.as_ref(),
                        &landmarks,
                        coarse.as_ref(),
                        ls_coarse.as_ref(),
                        None,
                    )
                },
                || factor(&landmarks, ls_coarse.as_ref(), None),
            );
            let (q, t_geodesics) = q?;
            stages.geodesics += t_geodesics;
            (Some(q), solver?)
        } else {
            (
                None,
                factor(&landmarks, ls_coarse.as_ref(), previous.take())?,
            )
        };
        let (solver, t_factor) = solver;
        stages.lsmesh += t_factor;
        mark(if round == 0 {
            "geodesics + lsmesh factorisation"
        } else {
            "thin parts: lsmesh factorisation"
        });
        check_cancel(progress)?;
        // The finest intermediate mesh: later rounds restart from it.
        let base = ls_coarse.as_ref().or(coarse.as_ref());
        let more = if opts.cover_thin_parts && round < THIN_PART_ROUNDS {
            let t = Instant::now();
            let collapsed =
                thin::collapsed_vertices(mesh, &landmarks, &solver, round > 0, progress)?;
            // Samples go on the intermediate mesh a later round restarts from, where
            // it has vertices to offer.
            let on_base = base.map(|b| thin::kept_by(b, n));
            let limit = opts
                .landmarks
                .saturating_sub(added)
                .min(n - landmarks.len());
            let more =
                thin::landmarks_to_add(mesh, &landmarks, &collapsed, on_base.as_deref(), limit);
            stages.decimate += secs(t);
            more
        } else {
            Vec::new()
        };
        if more.is_empty() {
            break (landmarks, q, solver, coarse, ls_coarse);
        }
        let locked = thin::merged(&landmarks, &more);
        // The factorisation and the distances go before the next decimation allocates
        // (should no decimation be possible, they are computed again); a two-level
        // system's full-mesh operator stays for the next round when the decimation
        // restarts from an intermediate mesh (a small one).
        drop(q);
        previous = match solver {
            LsMeshExtension::TwoLevel(t) if base.is_some() => Some(LsMeshExtension::TwoLevel(t)),
            other => {
                drop(other);
                None
            }
        };
        match relock(base, &locked) {
            Some(next) => {
                drop((coarse, ls_coarse));
                selected = next?;
                mark("thin parts: decimation");
            }
            None => {
                let (solver, t_factor) = factor(&landmarks, ls_coarse.as_ref(), previous.take())?;
                stages.lsmesh += t_factor;
                break (landmarks, None, solver, coarse, ls_coarse);
            }
        }
        added += more.len();
        round += 1;
        check_cancel(progress)?;
    };
    // Where the rounds of step 4b may follow, they reuse these runs (`KeptRows`).
    let rounds = usize::from(opts.cover_thin_parts && added > 0) * thin::SQUASHED_ROUNDS;
    let mut kept = (rounds > 0 && keep_rows).then(|| KeptRows::new(KEPT_ROWS_BYTES));
    let q = match q {
        Some(q) => q,
        None => {
            let (c, ls) = (coarse.as_ref(), ls_coarse.as_ref());
            let (q, t_geodesics) = geodesics(fm.as_ref(), &landmarks, c, ls, kept.as_mut())?;
            stages.geodesics += t_geodesics;
            q
        }
    };
    drop(fm);
    mark("landmark geodesics (if redone)");

    // 3. MDS of the landmarks.
    let t = Instant::now();
    let mds = metric_mds(&q, landmarks.len(), &opts.mds, progress)?;
    drop(q);
    stages.mds = secs(t);
    mark("mds");
    check_cancel(progress)?;

    // 4. Least-squares mesh: the landmarks' MDS positions extended to every vertex.
    let t = Instant::now();
    let mut coords = solver.solve(mesh, &mds.points, dim, progress)?;
    drop(solver);
    mark("lsmesh solve");
    progress.report(Stage::LsMesh, 1.0);
    stages.lsmesh += secs(t);
    check_cancel(progress)?;

    // 4b. On meshes with thin parts (landmarks were added), where the solved embedding
    //     still squashes vertices (`thin::squashed_vertices`), landmarks go there and the
    //     selection, geodesics, MDS and solve run again.
    //     The landmarks kept from the round before keep their geodesic runs where the
    //     geodesic mesh is the same (the full mesh, or the restart's intermediate mesh).
    let (mut landmarks, mut mds, mut coarse, mut ls_coarse) = (landmarks, mds, coarse, ls_coarse);
    for r in 0..rounds {
        let t = Instant::now();
        let base = ls_coarse.as_ref().or(coarse.as_ref());
        let limit = opts.landmarks.saturating_sub(added);
        let more = thin::landmarks_where_squashed(mesh, &landmarks, &coords, base, limit);
        stages.decimate += secs(t);
        if more.is_empty() {
            break;
        }
        let Some(next) = relock(base, &thin::merged(&landmarks, &more)) else {
            break;
        };
        let (next, c, ls, t_decimate) = next?;
        stages.decimate += t_decimate;
        if let Some(k) = kept.as_mut() {
            k.keep = r + 1 < rounds;
        }
        let (q, solver) = rayon::join(
            || geodesics(None, &next, c.as_ref(), ls.as_ref(), kept.as_mut()),
            || factor(&next, ls.as_ref(), None),
        );
        let ((q, t_geodesics), (solver, t_factor)) = (q?, solver?);
        (stages.geodesics, stages.lsmesh) =
            (stages.geodesics + t_geodesics, stages.lsmesh + t_factor);
        let t = Instant::now();
        mds = metric_mds(&q, next.len(), &opts.mds, progress)?;
        stages.mds += secs(t);
        let t = Instant::now();
        coords = solver.solve(mesh, &mds.points, dim, progress)?;
        stages.lsmesh += secs(t);
        added += next.len() - landmarks.len();
        (landmarks, coarse, ls_coarse) = (next, c, ls);
        mark("squashed vertices: selection, geodesics, mds, solve");
        check_cancel(progress)?;
    }
    let geodesic_mesh_vertices = coarse.as_ref().map_or(0, |c| c.mesh.n_vertices());
    drop((coarse, ls_coarse, kept));

    // 5. Quality.
    let t = Instant::now();
    let quality = match &quality_pairs {
        Some(p) => Some(p.evaluate(&coords)?),
        None => None,
    };
    if quality.is_some() {
        progress.report(Stage::Quality, 1.0);
    }
    stages.quality += secs(t);
    mark("quality evaluation");

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
            geodesic_mesh_vertices: geodesic_mesh_vertices as u64,
        },
        stress: mds.stress,
        geodesic_rel_err_p50: p50,
        geodesic_rel_err_p90: p90,
    };
    let report = Report {
        seconds: start.elapsed().as_secs_f64(),
        stages,
        landmarks: landmarks.len(),
        geodesic_mesh_vertices: if geodesic_mesh_vertices == 0 {
            n
        } else {
            geodesic_mesh_vertices
        },
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
    use crate::geodesic::landmark_distances;
    use crate::{NoProgress, Stage, precompute};
    use std::sync::Mutex;
    use std::sync::atomic::{AtomicBool, Ordering};
    use wavg_mesh::{TriMesh, procedural};

    /// Coordinates beyond what single-precision lengths hold are refused with the remedy;
    /// just inside the limit the embedding keeps the unit mesh's distances (within 1%).
    #[test]
    fn coordinates_beyond_the_supported_range_are_refused() {
        let scaled = |s: f64| {
            let mut m = procedural::icosphere(2);
            m.positions.iter_mut().for_each(|p| *p *= s);
            ValidMesh::new(m).unwrap()
        };
        let o = PrecomputeOptions {
            landmarks: 40,
            quality_pairs: 0,
            ..Default::default()
        };
        let err = precompute(&scaled(1e40), &o, &NoProgress).unwrap_err();
        assert!(err.to_string().contains("scale the mesh down"), "{err}");
        let (unit, _) = precompute(&scaled(1.0), &o, &NoProgress).unwrap();
        let s = 2f64.powi(120); // about 1.3e36; a power of two scales without rounding
        let (big, _) = precompute(&scaled(s), &o, &NoProgress).unwrap();
        // The same distances (the embedding itself is determined up to a rigid motion).
        let d = |c: &[[f64; 8]], i: usize| {
            (0..8)
                .map(|k| (c[i][k] - c[0][k]).powi(2))
                .sum::<f64>()
                .sqrt()
        };
        for i in 1..unit.coords.len() {
            let (a, b) = (d(&unit.coords, i) * s, d(&big.coords, i));
            assert!((a - b).abs() <= 1e-2 * a, "vertex {i}: {a} vs {b}");
        }
    }

    fn opts(landmarks: usize) -> PrecomputeOptions {
        PrecomputeOptions {
            landmarks,
            quality_pairs: 512,
            ..Default::default()
        }
    }

    /// A mesh whose landmarks cover every part gets none added: the embedding is the one
    /// without the check. A part thinner than the landmark spacing (a thin tube with few
    /// landmarks) gets more, at most as many again as asked for.
    #[test]
    fn landmarks_are_added_only_around_thin_parts() {
        let run = |mesh: &ValidMesh, landmarks: usize, cover_thin_parts: bool| {
            let o = PrecomputeOptions {
                quality_pairs: 0,
                cover_thin_parts,
                ..opts(landmarks)
            };
            precompute(mesh, &o, &NoProgress).unwrap().0
        };
        let round = ValidMesh::new(procedural::with_noise(
            procedural::torus(40, 20, 1.0, 0.4),
            0.2,
            3,
        ))
        .unwrap();
        let (a, b) = (run(&round, 80, true), run(&round, 80, false));
        assert_eq!(a.landmarks, b.landmarks);
        assert_eq!(a.coords, b.coords);
        let thin = ValidMesh::new(procedural::torus(200, 12, 1.0, 0.02)).unwrap();
        let (a, b) = (run(&thin, 60, true), run(&thin, 60, false));
        assert_eq!(b.landmarks.len(), 60);
        assert!(
            a.landmarks.len() > 60 && a.landmarks.len() <= 120,
            "{} landmarks",
            a.landmarks.len()
        );
        assert!(b.landmarks.iter().all(|l| a.landmarks.contains(l)));
    }

    /// Later thin-part rounds restart from the finest intermediate mesh of the first one
    /// (the geodesics' mesh, or the two-level least-squares mesh's coarse level, where the
    /// check also runs): every landmark, added ones included, is a vertex of it.
    #[test]
    fn thin_part_rounds_restart_from_the_intermediate_mesh() {
        let tube = ValidMesh::new(procedural::torus(200, 12, 1.0, 0.02)).unwrap();
        let tube = ValidMesh::new(wavg_mesh::subdivide::loop_subdivide(&tube).unwrap()).unwrap();
        let geodesics_only = PrecomputeOptions {
            quality_pairs: 0,
            geodesic_vertices: 3000,
            ..opts(60)
        };
        let two_level = PrecomputeOptions {
            lsmesh_direct_max: 5000,
            lsmesh_coarse_vertices: 4000,
            ..geodesics_only.clone()
        };
        for (o, finest) in [(geodesics_only, 3000), (two_level, 4000)] {
            let (emb, _) = precompute(&tube, &o, &NoProgress).unwrap();
            assert!(emb.landmarks.len() > 60, "{}", emb.landmarks.len());
            let d = DecimateOptions {
                target: 60,
                max_aspect_ratio: landmark_aspect_bound(&tube, o.decimate.max_aspect_ratio),
                ..o.decimate.clone()
            };
            let (_, snaps) = decimate_with_snapshots(&tube, &d, &[finest], &NoProgress).unwrap();
            let outside = (emb.landmarks.iter())
                .filter(|&&l| snaps[0].coarse_index(l).is_none())
                .count();
            assert_eq!(outside, 0, "landmarks off the {finest}-vertex mesh");
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

    /// The quality check's runs: as asked up to 1M vertices, then about 16M vertex visits
    /// in all, never fewer than two runs.
    #[test]
    fn quality_sources_bound_the_check() {
        assert_eq!(quality_sources(16, 134_345, 1024), 16);
        assert_eq!(quality_sources(16, 1_000_000, 1024), 16);
        assert_eq!(quality_sources(16, 2_149_490, 1024), 7);
        assert_eq!(quality_sources(16, 3_102_914, 1024), 5);
        assert_eq!(quality_sources(16, 8_597_954, 1024), 2);
        assert_eq!(quality_sources(16, 40_000_000, 1024), 2);
        assert_eq!(quality_sources(16, 1000, 4), 4);
        assert_eq!(quality_sources(32, 100, 1024), 32);
    }

    /// The landmark decimation's aspect bound is the one asked for on well-shaped meshes
    /// and rises to twice the 90th percentile on a mesh of slivers.
    #[test]
    fn landmark_aspect_bound_follows_slivers() {
        let round = ValidMesh::new(procedural::icosphere(3)).unwrap();
        assert_eq!(landmark_aspect_bound(&round, Some(10.0)), Some(10.0));
        assert_eq!(landmark_aspect_bound(&round, None), None);
        // Cells 100 times wider than tall: every triangle's ratio is about 100.
        let slivers = ValidMesh::new(procedural::grid(4, 4, 1.0, 0.01)).unwrap();
        let b = landmark_aspect_bound(&slivers, Some(10.0)).unwrap();
        assert!((190.0..=210.0).contains(&b), "{b}");
    }

    #[test]
    fn genus_zero_genus_one_and_open_meshes_embed() {
        // A sphere has no isometric embedding in any R^d: larger errors than real shapes.
        check(procedural::bump_sphere(4, 0.15), 150, 0.1, 0.2);
        check(procedural::torus(60, 30, 1.0, 0.4), 150, 0.1, 0.2);
        check(procedural::grid(40, 40, 1.0, 1.0), 100, 0.05, 0.15);
    }

    #[test]
    fn geodesics_on_an_intermediate_mesh() {
        let mesh = ValidMesh::new(procedural::torus(60, 30, 1.0, 0.4)).unwrap();
        let o = PrecomputeOptions {
            geodesic_vertices: 600,
            ..opts(100)
        };
        let (emb, r) = precompute(&mesh, &o, &NoProgress).unwrap();
        assert_eq!(r.geodesic_mesh_vertices, 600);
        assert_eq!(emb.params.geodesic_mesh_vertices, 600);
        assert_eq!(emb.landmarks.len(), 100);
        let full = precompute(
            &mesh,
            &PrecomputeOptions {
                geodesic_vertices: 0,
                ..opts(100)
            },
            &NoProgress,
        )
        .unwrap()
        .1;
        assert_eq!(full.geodesic_mesh_vertices, mesh.n_vertices());
        eprintln!(
            "torus, 100 landmarks: p50/p90 {:.4}/{:.4} (intermediate 600) vs {:.4}/{:.4} (full)",
            r.geodesic_rel_err_p50,
            r.geodesic_rel_err_p90,
            full.geodesic_rel_err_p50,
            full.geodesic_rel_err_p90
        );
        assert!(r.geodesic_rel_err_p50 < full.geodesic_rel_err_p50 + 0.02);
    }

    #[test]
    fn landmarks_take_their_mds_positions() {
        let mesh = ValidMesh::new(procedural::torus(40, 20, 1.0, 0.4)).unwrap();
        let o = opts(60);
        let (emb, r) = precompute(&mesh, &o, &NoProgress).unwrap();
        // Recompute the landmark MDS independently and compare distances at landmarks.
        let fm = FastMarching::new(&mesh);
        let geo = GeodesicOptions::new().fast_marching(&fm);
        let q = landmark_distances(&mesh, &emb.landmarks, &geo, &NoProgress).unwrap();
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

    /// Every report, in order.
    struct Record(Mutex<Vec<(Stage, f64)>>);

    impl Progress for Record {
        fn report(&self, s: Stage, f: f64) {
            assert!((0.0..=1.0).contains(&f));
            self.0.lock().unwrap().push((s, f));
        }
    }

    /// The landmark matrices computed (each one's geodesics reports end at 1), the
    /// smallest fraction the last one reported, and whether some stage's fraction went
    /// down.
    fn rounds_seen(seen: &[(Stage, f64)]) -> (usize, f64, bool) {
        let g: Vec<f64> = (seen.iter().filter(|x| x.0 == Stage::Geodesics))
            .map(|x| x.1)
            .collect();
        let matrices: Vec<&[f64]> = g.split_inclusive(|&f| f == 1.0).collect();
        let lowest = matrices.last().unwrap().iter().copied().fold(1.0, f64::min);
        let down = Stage::ALL.iter().any(|&st| {
            let f: Vec<f64> = seen.iter().filter(|x| x.0 == st).map(|x| x.1).collect();
            f.windows(2).any(|w| w[1] < w[0])
        });
        (matrices.len(), lowest, down)
    }

    /// A body whose solved embedding squashes its hands (`thin_parts`'s
    /// `no_pair_of_a_body_collapses_between_its_landmarks`), so that the rounds of step
    /// 4b run: keeping the geodesic runs of the landmarks kept from one round to the next
    /// changes no bit of the embedding, and most rows come from them. The progress the
    /// caller sees never goes down within a stage, although the rounds start the
    /// stages again.
    #[test]
    fn rounds_reuse_the_kept_rows_and_progress_never_goes_down() {
        let mesh =
            ValidMesh::new(procedural::body(&procedural::FigureShape::SQUASHED_HANDS)).unwrap();
        let o = PrecomputeOptions {
            quality_pairs: 0,
            ..Default::default()
        };
        let run = |keep_rows: bool| {
            let rec = Record(Mutex::new(Vec::new()));
            let (emb, _) = precompute_unscaled(&mesh, &o, &rec, keep_rows).unwrap();
            (emb, rec.0.into_inner().unwrap())
        };
        let (kept, kept_seen) = run(true);
        let (fresh, fresh_seen) = run(false);
        let bits = |e: &Embedding| -> Vec<u64> {
            e.coords.iter().flatten().map(|x| x.to_bits()).collect()
        };
        assert_eq!(kept.landmarks, fresh.landmarks);
        assert_eq!(bits(&kept), bits(&fresh));
        // The rounds ran (a matrix for the first round, one after the thin-part rounds,
        // then at least one for the squashed vertices), and the last one started far
        // along with the kept rows.
        let (matrices, lowest_kept, down) = rounds_seen(&kept_seen);
        let (_, lowest_fresh, _) = rounds_seen(&fresh_seen);
        assert!(matrices >= 3, "{matrices} landmark matrices");
        assert!(lowest_fresh < 0.01, "{lowest_fresh}");
        assert!(lowest_kept > 0.5, "{lowest_kept}");
        assert!(down, "the pipeline's own reports go down");
        // Through `precompute`, they do not.
        let rec = Record(Mutex::new(Vec::new()));
        let (public, _) = precompute(&mesh, &o, &rec).unwrap();
        assert_eq!(bits(&public), bits(&kept));
        let seen = rec.0.into_inner().unwrap();
        assert!(!rounds_seen(&seen).2, "a fraction went down");
        // (No quality check here.)
        for stage in [Stage::Decimate, Stage::Geodesics, Stage::Mds, Stage::LsMesh] {
            let last = seen.iter().rev().find(|(s, _)| *s == stage).map(|x| x.1);
            assert_eq!(last, Some(1.0), "{stage:?}");
        }
    }

    /// Cancels once a report for `stage` arrives; records every report.
    struct CancelAt {
        stage: Stage,
        flag: AtomicBool,
        seen: Mutex<Vec<(Stage, f64)>>,
    }

    impl Progress for CancelAt {
        fn report(&self, stage: Stage, fraction: f64) {
            assert!((0.0..=1.0).contains(&fraction), "{fraction}");
            self.seen.lock().unwrap().push((stage, fraction));
            if stage == self.stage {
                self.flag.store(true, Ordering::SeqCst);
            }
        }
        fn cancelled(&self) -> bool {
            self.flag.load(Ordering::SeqCst)
        }
    }

    #[test]
    fn cancellation_stops_every_stage_and_stages_keep_their_order() {
        let mesh = ValidMesh::new(procedural::torus(40, 20, 1.0, 0.4)).unwrap();
        for stage in Stage::ALL {
            let p = CancelAt {
                stage,
                flag: AtomicBool::new(false),
                seen: Mutex::new(Vec::new()),
            };
            let r = precompute(&mesh, &opts(60), &p);
            assert!(matches!(r, Err(EmbedError::Cancelled)), "{stage:?}: {r:?}");
            let seen = p.seen.lock().unwrap().clone();
            // Stages that run strictly after the cancelled one never start (the quality
            // check's fast marching runs alongside the decimation, the least-squares
            // factorisation alongside the geodesics), and the final solve never happens.
            let never: &[Stage] = match stage {
                Stage::Decimate | Stage::Quality => &[Stage::Geodesics, Stage::Mds, Stage::LsMesh],
                Stage::Geodesics | Stage::LsMesh => &[Stage::Mds],
                Stage::Mds => &[],
            };
            for (s, f) in &seen {
                assert!(
                    !never.contains(s),
                    "cancelled at {stage:?} but {s:?} reported"
                );
                assert!(
                    !(*s == Stage::LsMesh && *f == 1.0),
                    "solve ran after cancel"
                );
            }
        }
        // Uncancelled: every stage reports, and each one finally reaches 1.
        let rec = Record(Mutex::new(Vec::new()));
        precompute(&mesh, &opts(60), &rec).unwrap();
        let seen = rec.0.into_inner().unwrap();
        for stage in Stage::ALL {
            let last = seen.iter().rev().find(|(s, _)| *s == stage).map(|x| x.1);
            assert_eq!(last, Some(1.0), "{stage:?}");
        }
        // Geodesics start after the decimation ended, the solve after the MDS ended.
        let first = |st: Stage| seen.iter().position(|(s, _)| *s == st).unwrap();
        let last = |st: Stage| seen.iter().rposition(|(s, _)| *s == st).unwrap();
        assert!(last(Stage::Decimate) < first(Stage::Geodesics));
        assert!(last(Stage::Geodesics) < first(Stage::Mds));
        assert!(last(Stage::Mds) < last(Stage::LsMesh));
    }
}
