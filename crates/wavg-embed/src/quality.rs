//! Embedding quality: how well Euclidean distances in the embedding reproduce geodesic
//! distances on the surface.
//!
//! Seeded random vertex pairs `(a, b)`, `a != b`: `sources` distinct source vertices, each
//! paired with `pairs / sources` random targets (so one fast-marching run serves many pairs;
//! runs go in parallel). The relative error of a pair is
//! `| |e(a) - e(b)| - g(a, b) | / g(a, b)` with `g` the fast-marching distance on the mesh.
//! Percentiles interpolate linearly between order statistics (`p = q (m - 1)`-th value of
//! the `m` sorted errors, as NumPy's default).

use rand::SeedableRng;
use rand::seq::index::sample;
use rayon::prelude::*;
use wavg_mesh::ValidMesh;

use crate::error::{EmbedError, Progress, Stage, check_cancel};
use crate::file::MAX_DIM;
use crate::geodesic::FastMarching;

/// How many pairs to test.
#[derive(Clone, Debug, PartialEq)]
pub struct QualityOptions {
    /// Total number of vertex pairs (rounded down to a multiple of `sources`).
    pub pairs: usize,
    /// Number of distinct source vertices (fast-marching runs).
    pub sources: usize,
    /// Seed of the pair choice.
    pub seed: u64,
}

impl Default for QualityOptions {
    fn default() -> Self {
        Self {
            pairs: 1024,
            sources: 16,
            seed: 0,
        }
    }
}

/// Statistics of the relative distance error.
#[derive(Clone, Debug, PartialEq)]
pub struct Quality {
    /// Pairs evaluated.
    pub pairs: usize,
    /// Median relative error.
    pub rel_err_p50: f64,
    /// 90th percentile.
    pub rel_err_p90: f64,
    /// Mean.
    pub rel_err_mean: f64,
    /// Maximum.
    pub rel_err_max: f64,
}

/// Percentile `q` in `[0, 1]` of sorted values, linear interpolation (NumPy's default).
pub fn percentile(sorted: &[f64], q: f64) -> f64 {
    if sorted.is_empty() {
        return f64::NAN;
    }
    let pos = q.clamp(0.0, 1.0) * (sorted.len() - 1) as f64;
    let lo = pos.floor() as usize;
    let hi = (lo + 1).min(sorted.len() - 1);
    sorted[lo] + (pos - lo as f64) * (sorted[hi] - sorted[lo])
}

/// Seeded random vertex pairs with their fast-marching distances: computed once (they do
/// not depend on the embedding), then [`Self::evaluate`] scores any embedding.
#[derive(Clone, Debug)]
pub struct QualityPairs {
    n: usize,
    /// `(a, b, geodesic distance)`.
    pairs: Vec<(u32, u32, f64)>,
}

impl QualityPairs {
    /// Draws the pairs and runs fast marching (`fm` must be built from `mesh`).
    pub fn compute(
        mesh: &ValidMesh,
        fm: &FastMarching,
        opts: &QualityOptions,
        progress: &dyn Progress,
    ) -> Result<Self, EmbedError> {
        let n = mesh.n_vertices();
        if fm.n_vertices() != n {
            return Err(EmbedError::InvalidArgument(format!(
                "quality check: a {}-vertex fast-marching structure for a {n}-vertex mesh",
                fm.n_vertices()
            )));
        }
        if n < 2 || opts.sources == 0 || opts.pairs < opts.sources {
            return Err(EmbedError::InvalidArgument(format!(
                "quality check needs >= 2 vertices and pairs >= sources >= 1 (got {n} \
                 vertices, {} pairs, {} sources)",
                opts.pairs, opts.sources
            )));
        }
        let n_sources = opts.sources.min(n);
        let per_source = (opts.pairs / opts.sources).min(n - 1);
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(opts.seed);
        let sources: Vec<u32> = sample(&mut rng, n, n_sources)
            .into_iter()
            .map(|v| v as u32)
            .collect();
        // Targets per source: distinct, never the source itself.
        let targets: Vec<Vec<u32>> = sources
            .iter()
            .map(|&s| {
                let mut t: Vec<u32> = sample(&mut rng, n - 1, per_source)
                    .into_iter()
                    .map(|v| {
                        if v as u32 >= s {
                            v as u32 + 1
                        } else {
                            v as u32
                        }
                    })
                    .collect();
                t.sort_unstable();
                t
            })
            .collect();
        progress.report(Stage::Quality, 0.0);
        let done = std::sync::atomic::AtomicUsize::new(0);
        let runs: Vec<Vec<(u32, u32, f64)>> = sources
            .par_iter()
            .zip(&targets)
            .map_init(
                || (fm.workspace(), vec![false; n]),
                |(ws, is_target), (&s, ts)| {
                    check_cancel(progress)?;
                    for &t in ts {
                        is_target[t as usize] = true;
                    }
                    let d =
                        fm.run_until_targets_cancellable(ws, &[s], is_target, ts.len(), progress);
                    // (A cancelled run leaves `is_target` set: the whole check fails.)
                    let d = d?;
                    let mut out = Vec::with_capacity(ts.len());
                    for &t in ts {
                        is_target[t as usize] = false;
                        let g = d[t as usize];
                        if !(g.is_finite() && g > 0.0) {
                            return Err(EmbedError::InvalidArgument(format!(
                                "quality check: vertices {s} and {t} have geodesic distance \
                                 {g} (is the mesh connected?)"
                            )));
                        }
                        out.push((s, t, g));
                    }
                    let k = done.fetch_add(1, std::sync::atomic::Ordering::Relaxed) + 1;
                    progress.report(Stage::Quality, 0.99 * k as f64 / n_sources as f64);
                    Ok(out)
                },
            )
            .collect::<Result<_, EmbedError>>()?;
        Ok(Self {
            n,
            pairs: runs.into_iter().flatten().collect(),
        })
    }

    /// Number of pairs.
    pub fn len(&self) -> usize {
        self.pairs.len()
    }

    /// True if there are no pairs.
    pub fn is_empty(&self) -> bool {
        self.pairs.is_empty()
    }

    /// Relative distance errors of `coords` (one point per vertex, all 8 entries used).
    pub fn evaluate(&self, coords: &[[f64; MAX_DIM]]) -> Result<Quality, EmbedError> {
        if coords.len() != self.n {
            return Err(EmbedError::InvalidArgument(format!(
                "quality check: {} coordinates for a {}-vertex mesh",
                coords.len(),
                self.n
            )));
        }
        let mut all: Vec<f64> = self
            .pairs
            .iter()
            .map(|&(s, t, g)| {
                let (a, b) = (&coords[s as usize], &coords[t as usize]);
                let e = a
                    .iter()
                    .zip(b)
                    .map(|(x, y)| (x - y) * (x - y))
                    .sum::<f64>()
                    .sqrt();
                (e - g).abs() / g
            })
            .collect();
        if all.iter().any(|e| !e.is_finite()) {
            return Err(EmbedError::InvalidArgument(
                "quality check: non-finite embedding coordinates".into(),
            ));
        }
        all.sort_unstable_by(f64::total_cmp);
        Ok(Quality {
            pairs: all.len(),
            rel_err_p50: percentile(&all, 0.5),
            rel_err_p90: percentile(&all, 0.9),
            rel_err_mean: all.iter().sum::<f64>() / all.len().max(1) as f64,
            rel_err_max: *all.last().unwrap_or(&f64::NAN),
        })
    }
}

/// Relative error of embedding distance vs fast-marching geodesic distance on random pairs
/// ([`QualityPairs::compute`] then [`QualityPairs::evaluate`]).
///
/// `fm` must be built from `mesh`; `coords` holds one embedded point per vertex (all 8
/// entries are used; unused dimensions must be zero).
///
/// ```
/// use wavg_embed::FastMarching;
/// use wavg_embed::internal::{QualityOptions, geodesic_quality};
/// use wavg_embed::NoProgress;
/// use wavg_mesh::{ValidMesh, procedural};
/// // A flat grid embedded as itself: geodesic = Euclidean, small error.
/// let mesh = ValidMesh::new(procedural::grid(40, 40, 1.0, 1.0)).unwrap();
/// let coords: Vec<[f64; 8]> =
///     mesh.positions.iter().map(|p| [p.x, p.y, p.z, 0.0, 0.0, 0.0, 0.0, 0.0]).collect();
/// let fm = FastMarching::new(&mesh);
/// let q = geodesic_quality(&mesh, &fm, &coords, &QualityOptions::default(), &NoProgress).unwrap();
/// assert!(q.rel_err_p90 < 0.05);
/// ```
pub fn geodesic_quality(
    mesh: &ValidMesh,
    fm: &FastMarching,
    coords: &[[f64; MAX_DIM]],
    opts: &QualityOptions,
    progress: &dyn Progress,
) -> Result<Quality, EmbedError> {
    if coords.len() != mesh.n_vertices() {
        return Err(EmbedError::InvalidArgument(format!(
            "quality check: {} coordinates for a {}-vertex mesh",
            coords.len(),
            mesh.n_vertices()
        )));
    }
    let q = QualityPairs::compute(mesh, fm, opts, progress)?.evaluate(coords)?;
    progress.report(Stage::Quality, 1.0);
    Ok(q)
}

/// Vertex visits (sources x vertices) above which the quality check uses fewer sources.
pub(crate) const QUALITY_SOURCE_VERTICES: usize = 16_000_000;

/// Fewest quality-check sources on large meshes: two regions of the surface rather than one.
const QUALITY_MIN_SOURCES: usize = 2;

/// Fast-marching runs of the quality check on an `n`-vertex mesh for `asked` sources and
/// `pairs` pairs ([`PrecomputeOptions::quality_sources`](crate::PrecomputeOptions::quality_sources)).
pub(crate) fn quality_sources(asked: usize, n: usize, pairs: usize) -> usize {
    asked
        .min((QUALITY_SOURCE_VERTICES / n.max(1)).max(QUALITY_MIN_SOURCES))
        .clamp(1, pairs.max(1))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::NoProgress;
    use wavg_mesh::procedural;

    fn identity_coords(mesh: &ValidMesh, scale: f64) -> Vec<[f64; MAX_DIM]> {
        mesh.positions
            .iter()
            .map(|p| {
                [
                    p.x * scale,
                    p.y * scale,
                    p.z * scale,
                    0.0,
                    0.0,
                    0.0,
                    0.0,
                    0.0,
                ]
            })
            .collect()
    }

    #[test]
    fn percentile_interpolates() {
        let v = [1.0, 2.0, 3.0, 4.0, 5.0];
        assert_eq!(percentile(&v, 0.5), 3.0);
        assert_eq!(percentile(&v, 0.9), 4.6);
        assert_eq!(percentile(&v, 0.0), 1.0);
        assert_eq!(percentile(&v, 1.0), 5.0);
        assert_eq!(percentile(&[7.0], 0.9), 7.0);
        assert!(percentile(&[], 0.5).is_nan());
    }

    #[test]
    fn flat_grid_is_its_own_isometric_embedding() {
        let mesh = ValidMesh::new(procedural::grid(50, 50, 2.0, 2.0)).unwrap();
        let fm = FastMarching::new(&mesh);
        let q = geodesic_quality(
            &mesh,
            &fm,
            &identity_coords(&mesh, 1.0),
            &QualityOptions::default(),
            &NoProgress,
        )
        .unwrap();
        assert_eq!(q.pairs, 1024);
        assert!(q.rel_err_p50 < 0.02 && q.rel_err_p90 < 0.05, "{q:?}");
        assert!(q.rel_err_p50 <= q.rel_err_p90 && q.rel_err_p90 <= q.rel_err_max);
    }

    #[test]
    fn a_scaled_embedding_has_the_scale_error() {
        // Coordinates scaled by 1.5: every embedding distance is 1.5x the Euclidean one,
        // which on a flat grid is (nearly) the geodesic one: errors near 0.5.
        let mesh = ValidMesh::new(procedural::grid(50, 50, 2.0, 2.0)).unwrap();
        let fm = FastMarching::new(&mesh);
        let q = geodesic_quality(
            &mesh,
            &fm,
            &identity_coords(&mesh, 1.5),
            &QualityOptions::default(),
            &NoProgress,
        )
        .unwrap();
        assert!((q.rel_err_p50 - 0.5).abs() < 0.03, "{q:?}");
    }

    #[test]
    fn sphere_chords_underestimate_arcs() {
        // Unit sphere embedded as itself: chord 2 sin(t/2) vs arc t; the error grows with t
        // and the median over random pairs is substantial (about 0.15 to 0.2).
        let mesh = ValidMesh::new(procedural::icosphere(4)).unwrap();
        let fm = FastMarching::new(&mesh);
        let opts = QualityOptions {
            pairs: 400,
            sources: 8,
            seed: 3,
        };
        let q =
            geodesic_quality(&mesh, &fm, &identity_coords(&mesh, 1.0), &opts, &NoProgress).unwrap();
        assert!(q.rel_err_p50 > 0.08 && q.rel_err_p50 < 0.3, "{q:?}");
        assert!(q.rel_err_max < 1.0 - 2.0 / std::f64::consts::PI + 0.03);
        // Deterministic for a seed.
        let again =
            geodesic_quality(&mesh, &fm, &identity_coords(&mesh, 1.0), &opts, &NoProgress).unwrap();
        assert_eq!(q, again);
    }

    #[test]
    fn bad_inputs_are_errors() {
        let mesh = ValidMesh::new(procedural::icosphere(1)).unwrap();
        let fm = FastMarching::new(&mesh);
        let c = identity_coords(&mesh, 1.0);
        let o = QualityOptions::default();
        assert!(geodesic_quality(&mesh, &fm, &c[1..], &o, &NoProgress).is_err());
        let zero = QualityOptions {
            sources: 0,
            ..o.clone()
        };
        assert!(geodesic_quality(&mesh, &fm, &c, &zero, &NoProgress).is_err());
        let mut nan = c.clone();
        nan.iter_mut().for_each(|p| p[0] = f64::NAN);
        assert!(geodesic_quality(&mesh, &fm, &nan, &o, &NoProgress).is_err());
        // More pairs than vertices: capped, still fine.
        let q = geodesic_quality(&mesh, &fm, &c, &o, &NoProgress).unwrap();
        assert_eq!(q.pairs, 16 * 41);
    }
}
