//! Least-squares mesh (paper Section 3.5): extend the landmark embedding to every vertex.
//!
//! The coordinates `v` (one column per embedding dimension) minimise the discrete
//! bi-Laplacian energy `tr(vᵀ A v)` with `A = L M⁻¹ L` (L the positive semidefinite cotangent
//! stiffness, M the lumped mass) subject to `v_s = e(s)` at the landmarks. Splitting the
//! vertices into free (F) and fixed (S) ones, the minimiser solves the SPD system
//! `A_FF v_F = -A_FS v_S`, factored once by a sparse Cholesky (faer; minimum-degree or nested-dissection ordering,
//! sequential) and solved for all columns at once.

use faer::dyn_stack::{MemBuffer, MemStack};
use faer::linalg::cholesky::llt::factor::LltRegularization;
use faer::sparse::linalg::cholesky::{
    LltRef, SymbolicCholesky, SymmetricOrdering, factorize_symbolic_cholesky,
};
use faer::sparse::linalg::matmul::sparse_sparse_matmul;
use faer::sparse::{SparseColMat, SymbolicSparseColMat};
use faer::{Conj, Mat, Par, Side};
use wavg_mesh::{TriMesh, ValidMesh, geometry};

use crate::error::{EmbedError, Progress, Stage, check_cancel};
use crate::file::MAX_DIM;

mod cg;
mod locality;
mod ordering;
mod prolong;
mod stiffness;
pub(crate) mod two_level;

/// The bi-Laplacian `A = L M⁻¹ L` of a mesh (n x n, symmetric positive semidefinite,
/// constants in its kernel).
pub fn bilaplacian(mesh: &TriMesh) -> Result<SparseColMat<usize, f64>, EmbedError> {
    let mesh_err = |e: wavg_mesh::MeshError| EmbedError::InvalidArgument(e.to_string());
    let l = geometry::cotan_stiffness(mesh).map_err(mesh_err)?;
    let mass = geometry::lumped_mass(mesh);
    if let Some(v) = mass.iter().position(|&m| !(m > 0.0 && m.is_finite())) {
        return Err(EmbedError::InvalidArgument(format!(
            "vertex {v} has zero or invalid area; the least-squares mesh needs a mesh \
             without isolated vertices or degenerate faces"
        )));
    }
    // M⁻¹ L: scale row i of L by 1/m_i.
    let (sym, vals) = l.clone().into_parts();
    let mut scaled = vals;
    for j in 0..sym.ncols() {
        for k in sym.col_range(j) {
            scaled[k] /= mass[sym.row_idx()[k]];
        }
    }
    let minv_l = SparseColMat::new(sym, scaled);
    sparse_sparse_matmul(l.as_ref(), minv_l.as_ref(), 1.0, Par::Seq)
        .map_err(|e| EmbedError::Numerical(format!("bi-Laplacian assembly: {e:?}")))
}

/// Checks landmark ids (distinct, in range, at least one) and returns the fixed-vertex mask.
pub(super) fn fixed_mask(n: usize, landmarks: &[u32]) -> Result<Vec<bool>, EmbedError> {
    if landmarks.is_empty() {
        return Err(EmbedError::InvalidArgument(
            "the least-squares mesh needs at least one landmark".into(),
        ));
    }
    let mut fixed = vec![false; n];
    for &s in landmarks {
        let slot = fixed.get_mut(s as usize).ok_or_else(|| {
            EmbedError::InvalidArgument(format!("landmark {s} out of range ({n} vertices)"))
        })?;
        if std::mem::replace(slot, true) {
            return Err(EmbedError::InvalidArgument(format!(
                "landmark {s} appears twice"
            )));
        }
    }
    Ok(fixed)
}

/// Systems with at least this many unknowns also try a nested-dissection ordering.
const NESTED_DISSECTION_MIN: usize = 100_000;

/// The symbolic Cholesky factor of `a` (lower triangle) under the fill-reducing ordering
/// with the fewest factor entries: approximate minimum degree, and for large systems also
/// nested dissection by the unknowns' `positions`. Minimum degree does best on small and
/// medium meshes, nested dissection on large ones, where it needs less time and memory; which
/// one wins depends on the mesh, and a symbolic factorisation costs little against the
/// numeric one.
fn fill_reducing_symbolic(
    a: &SparseColMat<usize, f64>,
    positions: &[[f64; 3]],
    nested_dissection_min: usize,
) -> Result<SymbolicCholesky<usize>, EmbedError> {
    let symbolic = |ordering| {
        factorize_symbolic_cholesky(a.symbolic(), Side::Lower, ordering, Default::default())
            .map_err(|e| {
                EmbedError::Numerical(format!("least-squares mesh symbolic Cholesky: {e:?}"))
            })
    };
    let amd = symbolic(SymmetricOrdering::Amd)?;
    if a.ncols() < nested_dissection_min {
        return Ok(amd);
    }
    let (forward, inverse) =
        ordering::nested_dissection(a.symbolic().col_ptr(), a.symbolic().row_idx(), positions);
    let perm = faer::perm::PermRef::new_checked(&forward, &inverse, a.ncols());
    let nd = symbolic(SymmetricOrdering::Custom(perm))?;
    Ok(if nd.len_val() < amd.len_val() {
        nd
    } else {
        amd
    })
}

/// The factored least-squares-mesh system of a mesh and a landmark set; [`Self::solve`]
/// then extends any landmark values. The factorisation depends only on the mesh and the
/// landmarks, so it can run before (or while) the landmark values are computed.
pub(crate) struct LsMeshSolver {
    n: usize,
    landmarks: Vec<u32>,
    /// Free vertex ids, in system order.
    free: Vec<u32>,
    /// Coupling `A_FS`: `(free row, landmark index, value)`.
    coupling: Vec<(u32, u32, f64)>,
    symbolic: SymbolicCholesky<usize>,
    l_values: Vec<f64>,
}

impl LsMeshSolver {
    /// Assembles and factors `A_FF` for `landmarks` (distinct vertex ids, at least one).
    ///
    /// The mesh should be connected (otherwise a component without landmarks makes the
    /// system singular, reported as [`EmbedError::Numerical`]). Progress is reported as
    /// [`Stage::LsMesh`] up to 0.9.
    pub(crate) fn new(
        mesh: &ValidMesh,
        landmarks: &[u32],
        progress: &dyn Progress,
    ) -> Result<Self, EmbedError> {
        Self::with_orderings(mesh, landmarks, progress, NESTED_DISSECTION_MIN)
    }

    /// [`Self::new`], trying nested dissection from `nested_dissection_min` unknowns on
    /// (0 forces it).
    fn with_orderings(
        mesh: &ValidMesh,
        landmarks: &[u32],
        progress: &dyn Progress,
        nested_dissection_min: usize,
    ) -> Result<Self, EmbedError> {
        let n = mesh.n_vertices();
        let fixed = fixed_mask(n, landmarks)?;
        progress.report(Stage::LsMesh, 0.0);
        check_cancel(progress)?;
        let mut landmark_index = vec![u32::MAX; n];
        for (k, &s) in landmarks.iter().enumerate() {
            landmark_index[s as usize] = k as u32;
        }
        let mut free_id = vec![usize::MAX; n];
        let mut free = Vec::with_capacity(n - landmarks.len());
        for v in 0..n {
            if !fixed[v] {
                free_id[v] = free.len();
                free.push(v as u32);
            }
        }
        let nf = free.len();

        let a = bilaplacian(mesh)?;
        progress.report(Stage::LsMesh, 0.15);
        check_cancel(progress)?;

        // A_FF (lower triangle only, which is all the factorisation reads) and the coupling
        // A_FS, in one sweep over the columns of the symmetric A.
        let (sym, vals) = a.parts();
        let mut col_ptr = Vec::with_capacity(nf + 1);
        let mut row_idx = Vec::new();
        let mut ff_vals = Vec::new();
        let mut coupling = Vec::new();
        let mut entries: Vec<(usize, f64)> = Vec::new();
        col_ptr.push(0usize);
        for &j in &free {
            let j = j as usize;
            let jf = free_id[j];
            entries.clear();
            for k in sym.col_range(j) {
                let i = sym.row_idx()[k];
                if fixed[i] {
                    // A symmetric: A_FS[jf, i] = A[i, j].
                    coupling.push((jf as u32, landmark_index[i], vals[k]));
                } else if free_id[i] >= jf {
                    entries.push((free_id[i], vals[k]));
                }
            }
            entries.sort_unstable_by_key(|e| e.0);
            for &(i, x) in &entries {
                row_idx.push(i);
                ff_vals.push(x);
            }
            col_ptr.push(row_idx.len());
        }
        drop(a);
        let a_ff = SparseColMat::new(
            SymbolicSparseColMat::new_checked(nf, nf, col_ptr, None, row_idx),
            ff_vals,
        );
        check_cancel(progress)?;

        let par = Par::Seq;
        let positions: Vec<[f64; 3]> = free
            .iter()
            .map(|&v| {
                let p = mesh.positions[v as usize];
                [p.x, p.y, p.z]
            })
            .collect();
        let symbolic = fill_reducing_symbolic(&a_ff, &positions, nested_dissection_min)?;
        progress.report(Stage::LsMesh, 0.3);
        check_cancel(progress)?;
        let mut l_values = vec![0.0; symbolic.len_val()];
        let scratch = symbolic.factorize_numeric_llt_scratch::<f64>(par, Default::default());
        symbolic
            .factorize_numeric_llt(
                &mut l_values,
                a_ff.as_ref(),
                Side::Lower,
                LltRegularization::default(),
                par,
                MemStack::new(&mut MemBuffer::new(scratch)),
                Default::default(),
            )
            .map_err(|e| {
                EmbedError::Numerical(format!(
                    "least-squares mesh system is not positive definite ({e:?}); \
                     is every connected component given a landmark?"
                ))
            })?;
        progress.report(Stage::LsMesh, 0.9);
        Ok(Self {
            n,
            landmarks: landmarks.to_vec(),
            free,
            coupling,
            symbolic,
            l_values,
        })
    }

    /// One point per vertex, equal to `values[k]` at vertex `landmarks[k]` and minimising the
    /// bi-Laplacian energy elsewhere. Only the first `dim` entries of each value are used;
    /// the rest of the output is zero.
    pub(crate) fn solve(
        &self,
        values: &[[f64; MAX_DIM]],
        dim: usize,
    ) -> Result<Vec<[f64; MAX_DIM]>, EmbedError> {
        if dim == 0 || dim > MAX_DIM {
            return Err(EmbedError::InvalidArgument(format!(
                "embedding dimension {dim} not in 1..={MAX_DIM}"
            )));
        }
        if values.len() != self.landmarks.len() {
            return Err(EmbedError::InvalidArgument(format!(
                "{} values for {} landmarks",
                values.len(),
                self.landmarks.len()
            )));
        }
        if values
            .iter()
            .any(|v| v[..dim].iter().any(|c| !c.is_finite()))
        {
            return Err(EmbedError::InvalidArgument(
                "landmark values must be finite".into(),
            ));
        }
        let mut out = vec![[0.0; MAX_DIM]; self.n];
        for (&s, v) in self.landmarks.iter().zip(values) {
            out[s as usize][..dim].copy_from_slice(&v[..dim]);
        }
        let nf = self.free.len();
        if nf == 0 {
            return Ok(out);
        }
        let mut rhs = Mat::<f64>::zeros(nf, dim);
        for &(jf, k, a) in &self.coupling {
            for c in 0..dim {
                rhs[(jf as usize, c)] -= a * values[k as usize][c];
            }
        }
        let par = Par::Seq;
        let scratch = self.symbolic.solve_in_place_scratch::<f64>(dim, par);
        LltRef::new(&self.symbolic, &self.l_values).solve_in_place_with_conj(
            Conj::No,
            rhs.as_mut(),
            par,
            MemStack::new(&mut MemBuffer::new(scratch)),
        );
        for (jf, &v) in self.free.iter().enumerate() {
            for c in 0..dim {
                out[v as usize][c] = rhs[(jf, c)];
            }
        }
        if out.iter().any(|p| p.iter().any(|c| !c.is_finite())) {
            return Err(EmbedError::Numerical(
                "least-squares mesh produced non-finite coordinates".into(),
            ));
        }
        Ok(out)
    }
}

/// Solves the least-squares mesh: returns one point per vertex, equal to `values[k]` at
/// vertex `landmarks[k]` and minimising the bi-Laplacian energy elsewhere. Only the first
/// `dim` entries of each value are used; the rest of the output is zero.
///
/// The mesh should be connected (otherwise a component without landmarks makes the system
/// singular, reported as [`EmbedError::Numerical`]). The crate-internal `LsMeshSolver` factors once
/// and solves several times.
///
/// ```
/// use wavg_embed::internal::least_squares_mesh;
/// use wavg_embed::NoProgress;
/// use wavg_mesh::{ValidMesh, procedural};
/// let mesh = ValidMesh::new(procedural::icosphere(2)).unwrap();
/// // Constant landmark values extend to the constant.
/// let landmarks = vec![0, 10, 20];
/// let values = vec![[1.0; 8]; 3];
/// let x = least_squares_mesh(&mesh, &landmarks, &values, 8, &NoProgress).unwrap();
/// assert!(x.iter().all(|p| p.iter().all(|&c| (c - 1.0).abs() < 1e-9)));
/// ```
pub fn least_squares_mesh(
    mesh: &ValidMesh,
    landmarks: &[u32],
    values: &[[f64; MAX_DIM]],
    dim: usize,
    progress: &dyn Progress,
) -> Result<Vec<[f64; MAX_DIM]>, EmbedError> {
    if dim == 0 || dim > MAX_DIM {
        return Err(EmbedError::InvalidArgument(format!(
            "embedding dimension {dim} not in 1..={MAX_DIM}"
        )));
    }
    if values.len() != landmarks.len() {
        return Err(EmbedError::InvalidArgument(format!(
            "{} values for {} landmarks",
            values.len(),
            landmarks.len()
        )));
    }
    let solver = LsMeshSolver::new(mesh, landmarks, progress)?;
    check_cancel(progress)?;
    let out = solver.solve(values, dim)?;
    progress.report(Stage::LsMesh, 1.0);
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::NoProgress;
    use rand::seq::index::sample;
    use rand::{Rng, SeedableRng};
    use wavg_mesh::procedural;

    #[test]
    fn nested_dissection_solves_the_same_system() {
        let mesh = ValidMesh::new(procedural::torus(120, 60, 1.0, 0.3)).unwrap();
        let landmarks = random_landmarks(mesh.n_vertices(), 80, 3);
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(4);
        let values: Vec<[f64; MAX_DIM]> = landmarks
            .iter()
            .map(|_| std::array::from_fn(|_| rng.random_range(-1.0..1.0)))
            .collect();
        let solve = |min| {
            LsMeshSolver::with_orderings(&mesh, &landmarks, &NoProgress, min)
                .unwrap()
                .solve(&values, MAX_DIM)
                .unwrap()
        };
        let (amd, nd) = (solve(usize::MAX), solve(0));
        for (a, b) in amd.iter().zip(&nd) {
            for k in 0..MAX_DIM {
                assert!((a[k] - b[k]).abs() < 1e-9, "{a:?} vs {b:?}");
            }
        }
    }

    fn random_landmarks(n: usize, k: usize, seed: u64) -> Vec<u32> {
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(seed);
        sample(&mut rng, n, k)
            .into_iter()
            .map(|i| i as u32)
            .collect()
    }

    /// `A x` for the full bi-Laplacian, column `c` of the points.
    fn apply(a: &SparseColMat<usize, f64>, x: &[[f64; MAX_DIM]], c: usize) -> Vec<f64> {
        let (sym, vals) = a.parts();
        let mut y = vec![0.0; x.len()];
        for (j, xj) in x.iter().enumerate() {
            for k in sym.col_range(j) {
                y[sym.row_idx()[k]] += vals[k] * xj[c];
            }
        }
        y
    }

    #[test]
    fn landmarks_kept_exactly_and_gradient_vanishes_at_free_vertices() {
        for (mesh, k) in [
            (procedural::torus(40, 20, 1.0, 0.35), 60),
            (procedural::grid(30, 20, 3.0, 2.0), 25), // open mesh
            (
                procedural::with_noise(procedural::icosphere(3), 0.01, 4),
                40,
            ),
        ] {
            let mesh = ValidMesh::new(mesh).unwrap();
            let n = mesh.n_vertices();
            let lm = random_landmarks(n, k, 5);
            let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(6);
            let values: Vec<[f64; MAX_DIM]> = lm
                .iter()
                .map(|_| std::array::from_fn(|_| rng.random_range(-1.0..1.0)))
                .collect();
            let x = least_squares_mesh(&mesh, &lm, &values, 8, &NoProgress).unwrap();
            for (&s, v) in lm.iter().zip(&values) {
                assert_eq!(x[s as usize], *v, "landmark {s} moved");
            }
            let a = bilaplacian(&mesh).unwrap();
            let mut fixed = vec![false; n];
            for &s in &lm {
                fixed[s as usize] = true;
            }
            for c in 0..8 {
                let ax = apply(&a, &x, c);
                // Residual at free vertices relative to the right-hand side -A_FS v_S.
                let mut only_fixed = vec![[0.0; MAX_DIM]; n];
                for &s in &lm {
                    only_fixed[s as usize] = x[s as usize];
                }
                let b = apply(&a, &only_fixed, c);
                let (mut r2, mut b2) = (0.0, 0.0);
                for v in (0..n).filter(|&v| !fixed[v]) {
                    r2 += ax[v] * ax[v];
                    b2 += b[v] * b[v];
                }
                let rel = (r2 / b2).sqrt();
                assert!(rel < 1e-8, "relative residual {rel}");
            }
        }
    }

    #[test]
    fn one_factorisation_serves_several_value_sets_linearly() {
        let mesh = ValidMesh::new(procedural::torus(30, 15, 1.0, 0.4)).unwrap();
        let lm = random_landmarks(mesh.n_vertices(), 30, 2);
        let solver = LsMeshSolver::new(&mesh, &lm, &NoProgress).unwrap();
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(3);
        let mut draw = || -> Vec<[f64; MAX_DIM]> {
            lm.iter()
                .map(|_| std::array::from_fn(|_| rng.random_range(-1.0..1.0)))
                .collect()
        };
        let (u, v) = (draw(), draw());
        let w: Vec<[f64; MAX_DIM]> = u
            .iter()
            .zip(&v)
            .map(|(a, b)| std::array::from_fn(|k| 2.0 * a[k] - 3.0 * b[k]))
            .collect();
        let (xu, xv, xw) = (
            solver.solve(&u, 8).unwrap(),
            solver.solve(&v, 8).unwrap(),
            solver.solve(&w, 8).unwrap(),
        );
        assert_eq!(
            xu,
            least_squares_mesh(&mesh, &lm, &u, 8, &NoProgress).unwrap()
        );
        for i in 0..mesh.n_vertices() {
            for k in 0..MAX_DIM {
                let lin = 2.0 * xu[i][k] - 3.0 * xv[i][k];
                assert!((xw[i][k] - lin).abs() < 1e-9, "{} vs {lin}", xw[i][k]);
            }
        }
    }

    #[test]
    fn bilaplacian_is_symmetric_with_constant_kernel() {
        let mesh = procedural::with_noise(procedural::torus(20, 10, 1.0, 0.4), 0.02, 1);
        let a = bilaplacian(&mesh).unwrap();
        let ones = vec![[1.0; MAX_DIM]; mesh.n_vertices()];
        let y = apply(&a, &ones, 0);
        let scale = a.val().iter().fold(0.0f64, |m, v| m.max(v.abs()));
        assert!(y.iter().all(|v| v.abs() < 1e-10 * scale));
        let dense = a.to_dense();
        for i in 0..dense.nrows() {
            for j in 0..i {
                assert!((dense[(i, j)] - dense[(j, i)]).abs() <= 1e-12 * scale);
            }
        }
    }

    #[test]
    fn own_positions_reproduce_the_surface() {
        // Landmarks given their own 3-D positions: the LS mesh is a smooth approximation of
        // the original surface.
        let mesh = ValidMesh::new(procedural::bump_sphere(4, 0.1)).unwrap();
        let n = mesh.n_vertices();
        let diag = mesh.bounding_box_diagonal();
        for k in [100, 400] {
            let lm = random_landmarks(n, k, 9);
            let values: Vec<[f64; MAX_DIM]> = lm
                .iter()
                .map(|&s| {
                    let p = mesh.positions[s as usize];
                    [p.x, p.y, p.z, 0.0, 0.0, 0.0, 0.0, 0.0]
                })
                .collect();
            let x = least_squares_mesh(&mesh, &lm, &values, 3, &NoProgress).unwrap();
            let dev: Vec<f64> = (0..n)
                .map(|v| {
                    let p = mesh.positions[v];
                    let q = x[v];
                    ((p.x - q[0]).powi(2) + (p.y - q[1]).powi(2) + (p.z - q[2]).powi(2)).sqrt()
                        / diag
                })
                .collect();
            let mean = dev.iter().sum::<f64>() / n as f64;
            let max = dev.iter().fold(0.0f64, |m, &d| m.max(d));
            eprintln!(
                "LS mesh of own positions, {n} vertices, {k} landmarks: deviation / bbox \
                 diagonal mean {mean:.2e}, max {max:.2e}"
            );
            assert!(mean < 0.01 && max < 0.05, "mean {mean}, max {max}");
            assert!(x.iter().all(|p| p[3..].iter().all(|&c| c == 0.0)));
        }
    }

    #[test]
    fn bad_inputs_are_errors() {
        let mesh = ValidMesh::new(procedural::icosphere(1)).unwrap();
        let v = [[0.0; MAX_DIM]; 2];
        let run = |lm: &[u32], vals: &[[f64; MAX_DIM]], dim| {
            least_squares_mesh(&mesh, lm, vals, dim, &NoProgress)
        };
        assert!(run(&[], &[], 8).is_err());
        assert!(run(&[0, 0], &v, 8).is_err());
        assert!(run(&[0, 1000], &v, 8).is_err());
        assert!(run(&[0, 1], &v[..1], 8).is_err());
        assert!(run(&[0, 1], &v, 0).is_err());
        assert!(run(&[0, 1], &v, 9).is_err());
        let mut nan = v;
        nan[1][2] = f64::NAN;
        assert!(run(&[0, 1], &nan, 8).is_err());
        assert!(run(&[0, 1], &v, 8).is_ok());
    }

    #[test]
    fn every_vertex_a_landmark_is_the_identity() {
        let mesh = ValidMesh::new(procedural::icosphere(0)).unwrap();
        let lm: Vec<u32> = (0..12).collect();
        let vals: Vec<[f64; MAX_DIM]> = (0..12).map(|i| [i as f64; MAX_DIM]).collect();
        let x = least_squares_mesh(&mesh, &lm, &vals, 8, &NoProgress).unwrap();
        assert_eq!(x, vals);
    }
}
