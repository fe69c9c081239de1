//! Metric multidimensional scaling of the landmark distance matrix (paper Section 3.5).
//!
//! Two steps, as the authors do with MATLAB's `mdscale(Q, 8, 'criterion', 'metricstress')`:
//!
//! 1. **Classical MDS** start: the top `dim` eigenpairs `(λ, u)` of the double-centred
//!    matrix `B = -J Q∘Q J / 2` (`J = I - 11ᵀ/n`) give the points `u sqrt(max(λ, 0))`.
//!    They come from faer's restarted Lanczos (certified by residuals, else the full dense
//!    eigendecomposition): 0.2 s less than the dense solver at 1000 landmarks.
//! 2. **SMACOF** (majorisation) on the weighted raw stress
//!    `σ(X) = Σ_{i<j} w_ij (d_ij(X) - Q_ij)²` with `w_ij = 1/Q_ij²`, i.e. on the *relative*
//!    stress `Σ (d_ij / Q_ij - 1)²`. Each Guttman transform `X ← V⁺ B(X) X` (V the weighted
//!    Laplacian, `B(X)_ij = -w_ij Q_ij / d_ij`) never increases σ. `V⁺` is applied through a
//!    dense Cholesky factor of `V + c 11ᵀ` (exact because the columns of `B(X) X` sum to 0).
//!
//! **Reported stress** (mdscale's `metricstress` with these weights):
//! `stress = sqrt(Σ_{i<j} w_ij (d_ij - Q_ij)² / Σ_{i<j} w_ij Q_ij²)
//!         = sqrt(mean over pairs of (d_ij/Q_ij - 1)²)`,
//! the root-mean-square relative distance error. 0 means exact.
//!
//! **Convergence**: stop when the stress decreases by less than `tolerance` relative to its
//! value (`(σ_prev - σ) <= tolerance · σ_prev`), when it is below `1e-14` (exact), or after
//! `max_iterations` Guttman transforms.

use faer::dyn_stack::{MemBuffer, MemStack};
use faer::linalg::cholesky::llt;
use faer::linalg::matmul::matmul;
use faer::{Accum, Conj, Mat, MatMut, MatRef, Par};
use rayon::prelude::*;

use crate::error::{EmbedError, Progress, Stage, check_cancel};
use crate::file::MAX_DIM;

/// SMACOF settings.
#[derive(Clone, Debug, PartialEq)]
pub struct MdsOptions {
    /// Embedding dimension, `1..=8` (wavg uses 8).
    pub dim: usize,
    /// Maximum number of Guttman transforms.
    pub max_iterations: usize,
    /// Relative stress decrease below which iteration stops.
    pub tolerance: f64,
}

impl Default for MdsOptions {
    fn default() -> Self {
        Self {
            dim: MAX_DIM,
            max_iterations: 300,
            tolerance: 1e-4,
        }
    }
}

/// Result of [`metric_mds`] / [`smacof`].
#[derive(Clone, Debug)]
pub struct MdsResult {
    /// One point per input row; entries `dim..8` are zero.
    pub points: Vec<[f64; MAX_DIM]>,
    /// Final stress (see the module documentation), of `points`.
    pub stress: f64,
    /// Stress of the starting configuration (classical MDS for [`metric_mds`]).
    pub initial_stress: f64,
    /// Guttman transforms performed.
    pub iterations: usize,
    /// True if the tolerance (not the iteration limit) stopped the iteration.
    pub converged: bool,
    /// Stress after each iteration, starting with the initial configuration.
    pub history: Vec<f64>,
}

/// Checks a row-major `n x n` distance matrix and returns its symmetrised, scale-normalised
/// reciprocal `1/Q_ij` (diagonal 0) and the scale (mean off-diagonal distance).
fn inverse_distances(q: &[f64], n: usize) -> Result<(Vec<f64>, f64), EmbedError> {
    if n < 2 {
        return Err(EmbedError::InvalidArgument(format!(
            "MDS needs at least 2 points, got {n}"
        )));
    }
    if q.len() != n * n {
        return Err(EmbedError::InvalidArgument(format!(
            "distance matrix has {} entries, expected {n}x{n}",
            q.len()
        )));
    }
    let mut sum = 0.0;
    for i in 0..n {
        for j in 0..n {
            let v = q[i * n + j];
            if i != j && !(v.is_finite() && v > 0.0) {
                return Err(EmbedError::InvalidArgument(format!(
                    "distance between points {i} and {j} is {v}; MDS needs finite positive \
                     distances (is the mesh connected?)"
                )));
            }
            if i != j {
                sum += v;
            }
        }
    }
    let scale = sum / (n * (n - 1)) as f64;
    let mut inv = vec![0.0; n * n];
    for i in 0..n {
        for j in 0..n {
            if i != j {
                inv[i * n + j] = 2.0 * scale / (q[i * n + j] + q[j * n + i]);
            }
        }
    }
    Ok((inv, scale))
}

/// Classical (Torgerson) MDS: the top-`dim` eigenvectors of `-J Q∘Q J / 2`, scaled by the
/// square roots of their (clamped non-negative) eigenvalues.
///
/// `q` is a row-major symmetric `n x n` distance matrix.
pub fn classical_mds(q: &[f64], n: usize, dim: usize) -> Result<Vec<[f64; MAX_DIM]>, EmbedError> {
    check_dim(dim)?;
    let (inv, scale) = inverse_distances(q, n)?;
    let x = classical_normalised(&inv, n, dim)?;
    Ok(x.into_iter().map(|p| p.map(|c| c * scale)).collect())
}

fn check_dim(dim: usize) -> Result<(), EmbedError> {
    if dim == 0 || dim > MAX_DIM {
        return Err(EmbedError::InvalidArgument(format!(
            "embedding dimension {dim} not in 1..={MAX_DIM}"
        )));
    }
    Ok(())
}

/// Classical MDS on normalised distances given as reciprocals.
fn classical_normalised(
    inv: &[f64],
    n: usize,
    dim: usize,
) -> Result<Vec<[f64; MAX_DIM]>, EmbedError> {
    classical_normalised_with(inv, n, dim, true)
}

/// `B = -J Q∘Q J / 2` from the reciprocal distances.
fn double_centred(inv: &[f64], n: usize) -> Mat<f64> {
    let sq = |i: usize, j: usize| {
        let r = inv[i * n + j];
        if r == 0.0 { 0.0 } else { 1.0 / (r * r) }
    };
    let row_mean: Vec<f64> = (0..n)
        .map(|i| (0..n).map(|j| sq(i, j)).sum::<f64>() / n as f64)
        .collect();
    let grand = row_mean.iter().sum::<f64>() / n as f64;
    Mat::<f64>::from_fn(n, n, |i, j| {
        -0.5 * (sq(i, j) - row_mean[i] - row_mean[j] + grand)
    })
}

/// [`classical_normalised`], optionally without the partial eigensolver (for tests).
fn classical_normalised_with(
    inv: &[f64],
    n: usize,
    dim: usize,
    allow_partial: bool,
) -> Result<Vec<[f64; MAX_DIM]>, EmbedError> {
    let b = double_centred(inv, n);
    let par = Par::Seq;
    let mut x = vec![[0.0; MAX_DIM]; n];
    let k = dim.min(n);
    // Only the top `dim` eigenpairs are needed: try a restarted Lanczos (faer's partial
    // eigensolver, largest magnitudes) for 2 dim pairs; if at least `dim` of them are
    // positive they are the top ones (a larger positive eigenvalue would have a larger
    // magnitude than some returned one). Otherwise, or if it does not converge, fall back
    // to the full dense eigendecomposition.
    if let Some(pairs) = allow_partial
        .then(|| top_eigenpairs_partial(&b, k, par))
        .flatten()
    {
        for (c, (lambda, u)) in pairs.iter().enumerate() {
            let l = lambda.max(0.0).sqrt();
            for (i, p) in x.iter_mut().enumerate() {
                p[c] = u[i] * l;
            }
        }
        return Ok(x);
    }
    let mut s = faer::diag::Diag::<f64>::zeros(n);
    let mut u = Mat::<f64>::zeros(n, n);
    let scratch = faer::linalg::evd::self_adjoint_evd_scratch::<f64>(
        n,
        faer::linalg::evd::ComputeEigenvectors::Yes,
        par,
        Default::default(),
    );
    faer::linalg::evd::self_adjoint_evd(
        b.as_ref(),
        s.as_mut(),
        Some(u.as_mut()),
        par,
        MemStack::new(&mut MemBuffer::new(scratch)),
        Default::default(),
    )
    .map_err(|e| EmbedError::Numerical(format!("classical MDS eigendecomposition: {e:?}")))?;
    // Eigenvalues are in nondecreasing order: the largest are last.
    for c in 0..k {
        let col = n - 1 - c;
        let lambda = s[col].max(0.0).sqrt();
        for (i, p) in x.iter_mut().enumerate() {
            p[c] = u[(i, col)] * lambda;
        }
    }
    Ok(x)
}

/// The `k` largest (positive) eigenpairs of the symmetric `b` by a partial eigensolver, in
/// decreasing order, or `None` when that cannot be certified (see the caller).
fn top_eigenpairs_partial(b: &Mat<f64>, k: usize, par: Par) -> Option<Vec<(f64, Vec<f64>)>> {
    use faer::matrix_free::eigen::{
        PartialEigenParams, partial_self_adjoint_eigen, partial_self_adjoint_eigen_scratch,
    };
    let n = b.nrows();
    let want = 2 * k;
    // faer's Lanczos needs its subspace (at least 64 vectors) smaller than n.
    if n <= 64.max(4 * want) {
        return None;
    }
    let run = || {
        let mut vecs = Mat::<f64>::zeros(n, want);
        let mut vals = vec![0.0; want];
        // A deterministic start vector that is not orthogonal to anything in particular.
        let v0 = faer::Col::<f64>::from_fn(n, |i| 1.0 + ((i * 7919) % 1009) as f64 / 1009.0);
        let v0 = &v0 * (1.0 / v0.norm_l2());
        let params = PartialEigenParams::default();
        let scratch = partial_self_adjoint_eigen_scratch::<f64>(b, want, par, params);
        let info = partial_self_adjoint_eigen(
            vecs.as_mut(),
            &mut vals,
            b,
            v0.as_ref(),
            1e-10,
            par,
            MemStack::new(&mut MemBuffer::new(scratch)),
            params,
        );
        (info.n_converged_eigen, vals, vecs)
    };
    // A failure of the partial solver only costs the fallback.
    let (converged, vals, vecs) =
        std::panic::catch_unwind(std::panic::AssertUnwindSafe(run)).ok()?;
    if converged < want || vals.iter().any(|v| !v.is_finite()) {
        return None;
    }
    let mut order: Vec<usize> = (0..want).filter(|&i| vals[i] > 0.0).collect();
    if order.len() < k {
        return None;
    }
    order.sort_by(|&i, &j| vals[j].total_cmp(&vals[i]));
    order.truncate(k);
    // Certify: small residuals and orthonormal vectors, else fall back.
    let top = vals[order[0]];
    let u = Mat::<f64>::from_fn(n, k, |r, c| vecs[(r, order[c])]);
    let bu = b * &u;
    for (c, &i) in order.iter().enumerate() {
        let res = (0..n)
            .map(|r| (bu[(r, c)] - vals[i] * u[(r, c)]).powi(2))
            .sum::<f64>()
            .sqrt();
        if res.is_nan() || res > 1e-6 * top {
            return None;
        }
    }
    let gram = u.transpose() * &u;
    for a in 0..k {
        for c in 0..k {
            let expect = if a == c { 1.0 } else { 0.0 };
            let e = (gram[(a, c)] - expect).abs();
            if e.is_nan() || e > 1e-6 {
                return None;
            }
        }
    }
    Some(
        order
            .iter()
            .enumerate()
            .map(|(c, &i)| (vals[i], u.col(c).iter().copied().collect()))
            .collect(),
    )
}

/// Relative stress of `points` against the distances `q` (see the module documentation).
pub fn relative_stress(q: &[f64], n: usize, points: &[[f64; MAX_DIM]]) -> Result<f64, EmbedError> {
    let (inv, scale) = inverse_distances(q, n)?;
    if points.len() != n {
        return Err(EmbedError::InvalidArgument(format!(
            "{} points for a {n}x{n} distance matrix",
            points.len()
        )));
    }
    // Direct pairwise evaluation (independent of the Gram-matrix path SMACOF uses).
    let mut raw = 0.0;
    for i in 0..n {
        for j in 0..i {
            let d = points[i]
                .iter()
                .zip(&points[j])
                .map(|(a, b)| (a - b) * (a - b))
                .sum::<f64>()
                .sqrt();
            raw += (d / scale * inv[i * n + j] - 1.0).powi(2);
        }
    }
    Ok(normalise_stress(raw, n))
}

fn normalise_stress(raw: f64, n: usize) -> f64 {
    (raw / (n * (n - 1) / 2) as f64).sqrt()
}

/// Workspace for [`PairPass::run`]: the `n x n` Gram / coefficient matrix.
struct PairPass {
    n: usize,
    work: Vec<f64>,
    sq: Vec<f64>,
}

impl PairPass {
    fn new(n: usize) -> Self {
        Self {
            n,
            work: vec![0.0; n * n],
            sq: vec![0.0; n],
        }
    }

    /// One pass over all pairs: returns the raw relative stress `Σ_{i<j} (d_ij/Q_ij - 1)²`
    /// of `x` (`n x dim`) and writes `B(x) x` into `bx`, where
    /// `(B x)_i = Σ_j (x_i - x_j) / (Q_ij d_ij)`.
    ///
    /// Distances come from the Gram matrix `x xᵀ` (one matrix product, then an elementwise
    /// pass and a second product `C x`), which uses matrix products instead of a pairwise loop;
    /// `x` is kept centred, so the cancellation in `|x_i|² + |x_j|² - 2 x_i·x_j` is harmless
    /// at landmark spacings.
    fn run(&mut self, inv: &[f64], x: MatRef<'_, f64>, bx: MatMut<'_, f64>) -> f64 {
        let n = self.n;
        let par = Par::Seq;
        let mut g = MatMut::from_column_major_slice_mut(&mut self.work, n, n);
        matmul(g.as_mut(), Accum::Replace, x, x.transpose(), 1.0, par);
        for i in 0..n {
            self.sq[i] = g[(i, i)];
        }
        let sq = &self.sq;
        // Column j of the symmetric Gram matrix is row j; overwrite it by c_ij = 1/(Q_ij d_ij).
        let (stress, rowsum): (Vec<f64>, Vec<f64>) = self
            .work
            .par_chunks_mut(n)
            .enumerate()
            .map(|(j, col)| crate::simd::coefficient_column(col, sq, j, &inv[j * n..(j + 1) * n]))
            .unzip();
        let c = MatRef::from_column_major_slice(&self.work, n, n);
        let mut bx = bx;
        matmul(bx.as_mut(), Accum::Replace, c, x, -1.0, par);
        for k in 0..x.ncols() {
            for i in 0..n {
                bx[(i, k)] += rowsum[i] * x[(i, k)];
            }
        }
        0.5 * stress.iter().sum::<f64>()
    }
}

/// The SMACOF solver: a dense Cholesky factor of `V + c 11ᵀ` for the weights `1/Q_ij²`.
struct GuttmanSolver {
    factor: Mat<f64>,
}

impl GuttmanSolver {
    fn new(inv: &[f64], n: usize) -> Result<Self, EmbedError> {
        let mut v = Mat::<f64>::zeros(n, n);
        let mut trace = 0.0;
        for i in 0..n {
            let mut diag = 0.0;
            for j in 0..n {
                if i != j {
                    let w = inv[i * n + j] * inv[i * n + j];
                    v[(i, j)] = -w;
                    diag += w;
                }
            }
            v[(i, i)] = diag;
            trace += diag;
        }
        // (V + c 11ᵀ)⁻¹ b = V⁺ b whenever 1ᵀ b = 0; c makes the added eigenvalue c n equal
        // the mean diagonal, keeping the factorisation well conditioned.
        let c = trace / (n * n) as f64;
        for j in 0..n {
            for i in 0..n {
                v[(i, j)] += c;
            }
        }
        let par = Par::Seq;
        let scratch = llt::factor::cholesky_in_place_scratch::<f64>(n, par, Default::default());
        llt::factor::cholesky_in_place(
            v.as_mut(),
            Default::default(),
            par,
            MemStack::new(&mut MemBuffer::new(scratch)),
            Default::default(),
        )
        .map_err(|e| EmbedError::Numerical(format!("SMACOF weight matrix factorisation: {e:?}")))?;
        Ok(Self { factor: v })
    }

    /// Overwrites `bx` (which holds `B(X) X`) by `V⁺ B(X) X`, the Guttman transform.
    fn apply(&self, bx: MatMut<'_, f64>) {
        let par = Par::Seq;
        let scratch = llt::solve::solve_in_place_scratch::<f64>(bx.nrows(), bx.ncols(), par);
        llt::solve::solve_in_place_with_conj(
            self.factor.as_ref(),
            Conj::No,
            bx,
            par,
            MemStack::new(&mut MemBuffer::new(scratch)),
        );
    }
}

/// SMACOF from the starting configuration `init` (entries beyond `opts.dim` are ignored).
pub fn smacof(
    q: &[f64],
    n: usize,
    init: &[[f64; MAX_DIM]],
    opts: &MdsOptions,
    progress: &dyn Progress,
) -> Result<MdsResult, EmbedError> {
    check_dim(opts.dim)?;
    if !(opts.tolerance.is_finite() && opts.tolerance >= 0.0) {
        return Err(EmbedError::InvalidArgument(format!(
            "MDS tolerance {} must be finite and non-negative",
            opts.tolerance
        )));
    }
    let (inv, scale) = inverse_distances(q, n)?;
    if init.len() != n {
        return Err(EmbedError::InvalidArgument(format!(
            "{} starting points for a {n}x{n} distance matrix",
            init.len()
        )));
    }
    let x = Mat::<f64>::from_fn(n, opts.dim, |i, k| init[i][k] / scale);
    if x.col_iter().flat_map(|c| c.iter()).any(|c| !c.is_finite()) {
        return Err(EmbedError::InvalidArgument(
            "non-finite starting configuration".into(),
        ));
    }
    smacof_normalised(&inv, x, opts, progress).map(|mut r| {
        for p in &mut r.points {
            *p = p.map(|c| c * scale);
        }
        r
    })
}

/// SMACOF on normalised distances (given as reciprocals) from `x` (`n x dim`).
fn smacof_normalised(
    inv: &[f64],
    mut x: Mat<f64>,
    opts: &MdsOptions,
    progress: &dyn Progress,
) -> Result<MdsResult, EmbedError> {
    let (n, dim) = (x.nrows(), x.ncols());
    // Centre: the Guttman transform keeps the centroid at 0 and the Gram path wants it there.
    for k in 0..dim {
        let mean = x.col(k).iter().sum::<f64>() / n as f64;
        for i in 0..n {
            x[(i, k)] -= mean;
        }
    }
    let solver = GuttmanSolver::new(inv, n)?;
    let mut pass = PairPass::new(n);
    let mut bx = Mat::<f64>::zeros(n, dim);
    let mut history = Vec::new();
    let mut converged = false;
    let mut iterations = 0;
    loop {
        check_cancel(progress)?;
        let stress = normalise_stress(pass.run(inv, x.as_ref(), bx.as_mut()), n);
        if !stress.is_finite() {
            return Err(EmbedError::Numerical("SMACOF stress is not finite".into()));
        }
        if let Some(&prev) = history.last() {
            if prev - stress <= opts.tolerance * prev {
                history.push(stress);
                converged = true;
                break;
            }
        }
        history.push(stress);
        if stress < 1e-14 {
            converged = true;
            break;
        }
        if iterations == opts.max_iterations {
            break;
        }
        solver.apply(bx.as_mut());
        std::mem::swap(&mut x, &mut bx);
        iterations += 1;
        progress.report(Stage::Mds, iterations as f64 / opts.max_iterations as f64);
    }
    progress.report(Stage::Mds, 1.0);
    let mut points = vec![[0.0; MAX_DIM]; n];
    for (i, p) in points.iter_mut().enumerate() {
        for k in 0..dim {
            p[k] = x[(i, k)];
        }
    }
    Ok(MdsResult {
        points,
        stress: *history.last().expect("at least one stress"),
        initial_stress: history[0],
        iterations,
        converged,
        history,
    })
}

/// Metric MDS: classical MDS start, then SMACOF on the relative stress.
///
/// `q` is a row-major symmetric `n x n` matrix of positive distances (diagonal ignored;
/// the matrix is symmetrised by averaging).
///
/// ```
/// use wavg_embed::{MdsOptions, internal::metric_mds};
/// use wavg_embed::NoProgress;
/// // Four corners of a unit square.
/// let p: [[f64; 2]; 4] = [[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]];
/// let q: Vec<f64> = (0..16)
///     .map(|k| {
///         let (a, b) = (p[k / 4], p[k % 4]);
///         ((a[0] - b[0]) * (a[0] - b[0]) + (a[1] - b[1]) * (a[1] - b[1])).sqrt()
///     })
///     .collect();
/// let r = metric_mds(&q, 4, &MdsOptions::default(), &NoProgress).unwrap();
/// assert!(r.stress < 1e-9);
/// ```
pub fn metric_mds(
    q: &[f64],
    n: usize,
    opts: &MdsOptions,
    progress: &dyn Progress,
) -> Result<MdsResult, EmbedError> {
    check_dim(opts.dim)?;
    let (inv, scale) = inverse_distances(q, n)?;
    progress.report(Stage::Mds, 0.0);
    check_cancel(progress)?;
    let x = classical_normalised(&inv, n, opts.dim)?;
    let x = Mat::<f64>::from_fn(n, opts.dim, |i, k| x[i][k]);
    let mut r = smacof_normalised(&inv, x, opts, progress)?;
    for p in &mut r.points {
        *p = p.map(|c| c * scale);
    }
    Ok(r)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::NoProgress;
    use rand::{Rng, SeedableRng};

    fn dist(a: &[f64; MAX_DIM], b: &[f64; MAX_DIM]) -> f64 {
        a.iter()
            .zip(b)
            .map(|(x, y)| (x - y) * (x - y))
            .sum::<f64>()
            .sqrt()
    }

    fn random_points(n: usize, dim: usize, seed: u64) -> Vec<[f64; MAX_DIM]> {
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(seed);
        (0..n)
            .map(|_| {
                let mut p = [0.0; MAX_DIM];
                for c in &mut p[..dim] {
                    *c = rng.random_range(-5.0..5.0);
                }
                p
            })
            .collect()
    }

    fn distance_matrix(p: &[[f64; MAX_DIM]]) -> Vec<f64> {
        let n = p.len();
        (0..n * n).map(|k| dist(&p[k / n], &p[k % n])).collect()
    }

    fn max_rel_err(q: &[f64], x: &[[f64; MAX_DIM]]) -> f64 {
        let n = x.len();
        let mut m: f64 = 0.0;
        for i in 0..n {
            for j in 0..i {
                m = m.max((dist(&x[i], &x[j]) / q[i * n + j] - 1.0).abs());
            }
        }
        m
    }

    #[test]
    fn exactly_embeddable_points_in_r8_are_reproduced() {
        let p = random_points(120, 8, 7);
        let q = distance_matrix(&p);
        // Classical MDS alone is exact for Euclidean distances.
        let c = classical_mds(&q, 120, 8).unwrap();
        assert!(
            max_rel_err(&q, &c) < 1e-8,
            "classical {}",
            max_rel_err(&q, &c)
        );
        let r = metric_mds(&q, 120, &MdsOptions::default(), &NoProgress).unwrap();
        assert!(r.stress < 1e-9, "stress {}", r.stress);
        assert!(max_rel_err(&q, &r.points) < 1e-8);
        // And the reported stress agrees with an independent evaluation.
        let s = relative_stress(&q, 120, &r.points).unwrap();
        assert!((s - r.stress).abs() < 1e-9);
    }

    #[test]
    fn smacof_recovers_from_a_perturbed_start_and_stress_decreases_monotonically() {
        let p = random_points(80, 8, 3);
        let q = distance_matrix(&p);
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(9);
        let init: Vec<[f64; MAX_DIM]> = p
            .iter()
            .map(|x| x.map(|c| c + rng.random_range(-1.0..1.0)))
            .collect();
        let opts = MdsOptions {
            max_iterations: 2000,
            tolerance: 1e-12,
            ..MdsOptions::default()
        };
        let r = smacof(&q, 80, &init, &opts, &NoProgress).unwrap();
        assert!(r.initial_stress > 0.05);
        for w in r.history.windows(2) {
            assert!(
                w[1] <= w[0] * (1.0 + 1e-12),
                "stress rose: {} -> {}",
                w[0],
                w[1]
            );
        }
        assert!(r.stress < 1e-6, "stress {}", r.stress);
    }

    #[test]
    fn non_euclidean_distances_lower_the_relative_stress_of_the_classical_start() {
        // Geodesic-like distances: points on a circle, arc-length metric, embedded in 2-D.
        let n = 60;
        let q: Vec<f64> = (0..n * n)
            .map(|k| {
                let (i, j) = ((k / n) as f64, (k % n) as f64);
                let t = (i - j).abs() * std::f64::consts::TAU / n as f64;
                t.min(std::f64::consts::TAU - t)
            })
            .collect();
        let opts = MdsOptions {
            dim: 2,
            ..MdsOptions::default()
        };
        let r = metric_mds(&q, n, &opts, &NoProgress).unwrap();
        assert!(r.stress < r.initial_stress);
        for w in r.history.windows(2) {
            assert!(w[1] <= w[0] * (1.0 + 1e-12));
        }
        assert!(r.points.iter().all(|p| p[2..].iter().all(|&c| c == 0.0)));
        assert!((relative_stress(&q, n, &r.points).unwrap() - r.stress).abs() < 1e-9);
    }

    #[test]
    fn low_rank_distances_are_reproduced() {
        // Points in R^3 embedded in 8-D: only 3 positive eigenvalues.
        let p = random_points(200, 3, 21);
        let q = distance_matrix(&p);
        let c = classical_mds(&q, 200, 8).unwrap();
        assert!(max_rel_err(&q, &c) < 1e-6, "{}", max_rel_err(&q, &c));
    }

    #[test]
    fn partial_and_full_eigensolvers_give_the_same_classical_start() {
        // Non-Euclidean (geodesic-like) distances: arcs on a circle plus a height.
        let n = 150;
        let q: Vec<f64> = (0..n * n)
            .map(|k| {
                let (i, j) = (k / n, k % n);
                let t = (i as f64 - j as f64).abs() * std::f64::consts::TAU / n as f64;
                let arc = t.min(std::f64::consts::TAU - t);
                let h = ((i % 7) as f64 - (j % 7) as f64) * 0.1;
                (arc * arc + h * h).sqrt()
            })
            .collect();
        let (inv, _) = inverse_distances(&q, n).unwrap();
        // The partial solver really succeeds here (no silent fallback).
        assert!(top_eigenpairs_partial(&double_centred(&inv, n), 8, Par::Seq).is_some());
        let a = classical_normalised_with(&inv, n, 8, true).unwrap();
        let b = classical_normalised_with(&inv, n, 8, false).unwrap();
        // Eigenvector signs are arbitrary: compare the Gram matrices.
        let gram = |x: &[[f64; MAX_DIM]], i: usize, j: usize| {
            x[i].iter().zip(&x[j]).map(|(u, v)| u * v).sum::<f64>()
        };
        let scale = (0..n).map(|i| gram(&b, i, i)).fold(0.0f64, f64::max);
        for i in 0..n {
            for j in 0..n {
                let d = (gram(&a, i, j) - gram(&b, i, j)).abs();
                assert!(d < 1e-8 * scale, "({i}, {j}): {d}");
            }
        }
    }

    #[test]
    fn scale_invariance() {
        let p = random_points(40, 5, 11);
        let q = distance_matrix(&p);
        let opts = MdsOptions {
            max_iterations: 5,
            ..MdsOptions::default()
        };
        let init = random_points(40, 8, 12);
        let a = smacof(&q, 40, &init, &opts, &NoProgress).unwrap();
        let q2: Vec<f64> = q.iter().map(|d| d * 1e-6).collect();
        let init2: Vec<_> = init.iter().map(|p| p.map(|c| c * 1e-6)).collect();
        let b = smacof(&q2, 40, &init2, &opts, &NoProgress).unwrap();
        assert!((a.stress - b.stress).abs() < 1e-10 * a.stress.max(1e-300));
    }

    #[test]
    fn bad_inputs_are_errors() {
        let q = vec![0.0, 1.0, 1.0, 0.0];
        assert!(metric_mds(&q, 2, &MdsOptions::default(), &NoProgress).is_ok());
        assert!(metric_mds(&q[..3], 2, &MdsOptions::default(), &NoProgress).is_err());
        assert!(metric_mds(&[0.0], 1, &MdsOptions::default(), &NoProgress).is_err());
        for bad in [0.0, -1.0, f64::NAN, f64::INFINITY] {
            let q = vec![0.0, bad, bad, 0.0];
            assert!(matches!(
                metric_mds(&q, 2, &MdsOptions::default(), &NoProgress),
                Err(EmbedError::InvalidArgument(_))
            ));
        }
        let opts = MdsOptions {
            dim: 9,
            ..MdsOptions::default()
        };
        assert!(metric_mds(&q, 2, &opts, &NoProgress).is_err());
    }

    #[test]
    fn cancellation_stops() {
        struct Stop;
        impl Progress for Stop {
            fn report(&self, _: Stage, _: f64) {}
            fn cancelled(&self) -> bool {
                true
            }
        }
        let q = distance_matrix(&random_points(10, 3, 1));
        assert!(matches!(
            metric_mds(&q, 10, &MdsOptions::default(), &Stop),
            Err(EmbedError::Cancelled)
        ));
    }
}
