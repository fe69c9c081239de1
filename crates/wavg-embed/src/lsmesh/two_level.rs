//! Least-squares mesh of large meshes in two levels.
//!
//! A direct Cholesky factorisation of the bi-Laplacian system grows faster than the mesh
//! (time and memory), so above a size threshold the system is solved on a coarser mesh
//! whose vertices are a subset of the original ones (a state of the landmark decimation,
//! so it contains every landmark), and the coarse solution, prolongated to every vertex,
//! starts a Jacobi-preconditioned conjugate-gradient solve of the full system
//! `A_FF v_F = -A_FS v_S` (the same system as [`crate::lsmesh`]). The coarse solve carries
//! the low frequencies, which conjugate gradients would need very many iterations for; a
//! few iterations remove the high-frequency error of the prolongation. What remains is the
//! coarse mesh's discretisation error at low frequencies, small against the embedding's own
//! error (the landmark distances' MDS fit), so by default the iterations stop early
//! ([`CgOptions::default`]) rather than converge.
//!
//! `A = L M⁻¹ L` is applied as two products with the cotangent stiffness `L` and never
//! assembled, so the memory is a few vectors per vertex on top of the coarse factor. The
//! full system's unknowns are laid out in a vertex order with memory locality
//! ([`VertexOrder::morton`]): its products gather neighbours' values, and in the file's
//! order most of those gathers miss the caches.

use rayon::prelude::*;
use wavg_mesh::ValidMesh;

use super::LsMeshSolver;
use super::cg::FreeOperator;
use super::locality::VertexOrder;
use super::prolong::{FullLevel, prolongate};
use super::stiffness::Stiffness;
use crate::decimate::Decimated;
use crate::error::{EmbedError, Progress, check_cancel};
use crate::file::MAX_DIM;

type Row = [f64; MAX_DIM];

/// Settings of the conjugate-gradient refinement. The default (20 iterations at most) smooths
/// the prolongated coarse solution; a tight tolerance with many iterations converges to the
/// direct solution, slowly. 20 iterations instead of 40 left `geodesic_rel_err` within 0.1%
/// at 2.6M vertices (BENCHMARKS.md) and halve the solve, which is memory-bound.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct CgOptions {
    /// Stop when every column's residual norm is at most this times its right-hand side's.
    pub tolerance: f64,
    /// Stop after this many iterations in any case (the iterate is returned).
    pub max_iterations: usize,
}

impl Default for CgOptions {
    fn default() -> Self {
        Self {
            tolerance: 1e-6,
            max_iterations: 20,
        }
    }
}

/// A least-squares-mesh system ready for landmark values: factored directly, or in two
/// levels for large meshes.
pub(crate) enum LsMeshExtension {
    /// One sparse Cholesky factorisation of the full system.
    Direct(Box<LsMeshSolver>),
    /// Coarse factorisation plus conjugate gradients on the full system.
    TwoLevel(Box<TwoLevelLsMesh>),
}

impl LsMeshExtension {
    /// The extension of `values` (one per landmark) to every vertex; see
    /// [`LsMeshSolver::solve`].
    pub(crate) fn solve(
        &self,
        mesh: &ValidMesh,
        values: &[Row],
        dim: usize,
        progress: &dyn Progress,
    ) -> Result<Vec<Row>, EmbedError> {
        match self {
            Self::Direct(s) => s.solve(values, dim),
            Self::TwoLevel(s) => s.solve(mesh, values, dim, progress),
        }
    }
}

/// The least-squares mesh of a large mesh: a factored coarse system plus the operator of
/// the full one.
pub(crate) struct TwoLevelLsMesh {
    /// The landmarks' positions in `order`.
    landmarks_ordered: Vec<u32>,
    /// Whether each vertex, in `order`, is a landmark.
    fixed: Vec<bool>,
    /// Original ids of the coarse vertices, in coarse order.
    coarse_ids: Vec<u32>,
    coarse: LsMeshSolver,
    /// The coarse mesh (vertex `i` is original vertex `coarse_ids[i]`).
    coarse_mesh: ValidMesh,
    /// The order of the full system's unknowns (and of `fixed`, `stiffness`, `inv_mass`
    /// and `inv_diag`).
    order: VertexOrder,
    /// Cotangent stiffness of the full mesh (symmetric, both triangles stored).
    stiffness: Stiffness,
    inv_mass: Vec<f64>,
    /// Inverse diagonal of `A` (Jacobi preconditioner); 0 at fixed vertices.
    inv_diag: Vec<f64>,
    cg: CgOptions,
}

impl TwoLevelLsMesh {
    /// Factors the system on `coarse` (a decimation state of `mesh` containing every
    /// landmark) and sets up the full-mesh operator.
    pub(crate) fn new(
        mesh: &ValidMesh,
        coarse: &Decimated,
        landmarks: &[u32],
        cg: CgOptions,
        progress: &dyn Progress,
    ) -> Result<Self, EmbedError> {
        let n = mesh.n_vertices();
        let fixed = super::fixed_mask(n, landmarks)?;
        let (coarse_mesh, coarse_solver) = coarse_system(n, coarse, landmarks, progress)?;
        check_cancel(progress)?;

        let order = VertexOrder::morton(mesh);
        let (stiffness, mass) = Stiffness::cotan(mesh, Some(&order), progress)?;
        if let Some(j) = mass.iter().position(|&m| !(m > 0.0 && m.is_finite())) {
            return Err(EmbedError::InvalidArgument(format!(
                "vertex {} has zero or invalid area; the least-squares mesh needs a mesh \
                 without isolated vertices or degenerate faces",
                order.old_of_new[j]
            )));
        }
        let inv_mass: Vec<f64> = mass.par_iter().map(|m| 1.0 / m).collect();
        let full = FullOperator {
            order,
            stiffness,
            inv_mass,
        };
        Ok(Self::assemble(
            landmarks,
            fixed,
            coarse,
            (coarse_mesh, coarse_solver),
            full,
            cg,
        ))
    }

    /// The same system with other landmarks, each a vertex of `coarse` (a decimation state
    /// of the same mesh): the full mesh's stiffness and masses, which do not depend on the
    /// landmarks, are kept; the coarse level is factored again.
    pub(crate) fn with_landmarks(
        self,
        coarse: &Decimated,
        landmarks: &[u32],
        progress: &dyn Progress,
    ) -> Result<Self, EmbedError> {
        let n = self.fixed.len();
        let fixed = super::fixed_mask(n, landmarks)?;
        let (cg, full) = (
            self.cg,
            FullOperator {
                order: self.order,
                stiffness: self.stiffness,
                inv_mass: self.inv_mass,
            },
        );
        let level = coarse_system(n, coarse, landmarks, progress)?;
        Ok(Self::assemble(landmarks, fixed, coarse, level, full, cg))
    }

    /// The system from its parts: the Jacobi preconditioner of the free vertices added.
    fn assemble(
        landmarks: &[u32],
        fixed: Vec<bool>,
        coarse: &Decimated,
        (coarse_mesh, coarse_solver): (ValidMesh, LsMeshSolver),
        FullOperator {
            order,
            stiffness,
            inv_mass,
        }: FullOperator,
        cg: CgOptions,
    ) -> Self {
        let fixed = order.to_new(&fixed);
        let landmarks_ordered = (landmarks.iter())
            .map(|&s| order.new_of_old[s as usize])
            .collect();
        // diag(L M⁻¹ L)_j = sum_k L_kj² / m_k.
        let inv_diag: Vec<f64> = (0..fixed.len())
            .into_par_iter()
            .map(|j| {
                if fixed[j] {
                    return 0.0;
                }
                let d: f64 = (stiffness.col_range(j))
                    .map(|k| stiffness.val(k) * stiffness.val(k) * inv_mass[stiffness.row(k)])
                    .sum();
                if d > 0.0 { 1.0 / d } else { 0.0 }
            })
            .collect();
        Self {
            landmarks_ordered,
            fixed,
            coarse_ids: coarse.landmarks.clone(),
            coarse: coarse_solver,
            coarse_mesh,
            order,
            stiffness,
            inv_mass,
            inv_diag,
            cg,
        }
    }

    /// The coarse level: its mesh, the original ids of its vertices (ascending) and its
    /// factored system, whose landmarks are the full system's in the same order. Its
    /// solution is exact on the coarse mesh, where the full one stops early.
    pub(crate) fn coarse_level(&self) -> (&ValidMesh, &[u32], &LsMeshSolver) {
        (&self.coarse_mesh, &self.coarse_ids, &self.coarse)
    }

    /// One point per vertex, equal to `values[k]` at vertex `landmarks[k]` and (to the
    /// conjugate-gradient tolerance) minimising the bi-Laplacian energy elsewhere. Only the
    /// first `dim` entries of each value are used; the rest of the output is zero.
    pub(crate) fn solve(
        &self,
        mesh: &ValidMesh,
        values: &[Row],
        dim: usize,
        progress: &dyn Progress,
    ) -> Result<Vec<Row>, EmbedError> {
        if mesh.n_vertices() != self.fixed.len() {
            return Err(EmbedError::InvalidArgument(format!(
                "the least-squares system is for {} vertices, the mesh has {}",
                self.fixed.len(),
                mesh.n_vertices()
            )));
        }
        let coarse = self.coarse.solve(values, dim)?;
        check_cancel(progress)?;
        let full = FullLevel {
            positions: &mesh.positions,
            order: &self.order,
            stiffness: &self.stiffness,
        };
        let mut x = prolongate(
            &full,
            &self.coarse_mesh,
            &self.coarse_ids,
            &coarse,
            progress,
        )?;
        for (&s, v) in self.landmarks_ordered.iter().zip(values) {
            x[s as usize] = *v;
            x[s as usize][dim..].fill(0.0);
        }
        let op = FreeOperator {
            stiffness: &self.stiffness,
            inv_mass: &self.inv_mass,
            inv_diag: &self.inv_diag,
            fixed: &self.fixed,
        };
        op.solve(&self.landmarks_ordered, &mut x, dim, self.cg, progress)?;
        if x.par_iter().any(|p| p.iter().any(|c| !c.is_finite())) {
            return Err(EmbedError::Numerical(
                "least-squares mesh produced non-finite coordinates".into(),
            ));
        }
        Ok(self.order.to_old(&x))
    }
}

/// The full mesh's part of the system that does not depend on the landmarks.
struct FullOperator {
    order: VertexOrder,
    stiffness: Stiffness,
    inv_mass: Vec<f64>,
}

/// The coarse mesh of a two-level system on a mesh of `n` vertices and its factored
/// system, with `landmarks` (original ids) as its fixed vertices.
fn coarse_system(
    n: usize,
    coarse: &Decimated,
    landmarks: &[u32],
    progress: &dyn Progress,
) -> Result<(ValidMesh, LsMeshSolver), EmbedError> {
    let coarse_landmarks = landmarks
        .iter()
        .map(|&s| {
            coarse.coarse_index(s).ok_or_else(|| {
                EmbedError::InvalidArgument(format!("landmark {s} is not a coarse vertex"))
            })
        })
        .collect::<Result<Vec<_>, _>>()?;
    if coarse.landmarks.iter().any(|&v| v as usize >= n) {
        return Err(EmbedError::InvalidArgument(
            "the coarse mesh is not a decimation of this mesh".into(),
        ));
    }
    let coarse_mesh = ValidMesh::new(coarse.mesh.clone())
        .map_err(|e| EmbedError::InvalidArgument(format!("coarse mesh: {e}")))?;
    let solver = LsMeshSolver::new(&coarse_mesh, &coarse_landmarks, progress)?;
    Ok((coarse_mesh, solver))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::NoProgress;
    use crate::decimate::{DecimateOptions, decimate_with_snapshots};
    use rand::{Rng, SeedableRng};
    use wavg_mesh::procedural;

    /// Direct and two-level solutions of the same problem, and the scale of the values.
    fn both(mesh: &ValidMesh, landmarks: usize, coarse: usize, cg: CgOptions) -> f64 {
        let opts = DecimateOptions {
            target: landmarks,
            ..Default::default()
        };
        let (fin, mut snaps) =
            decimate_with_snapshots(mesh, &opts, &[coarse], &NoProgress).unwrap();
        let snap = snaps.pop().unwrap();
        let lm = fin.landmarks;
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(7);
        let values: Vec<Row> = lm
            .iter()
            .map(|_| std::array::from_fn(|_| rng.random_range(-1.0..1.0)))
            .collect();
        let direct = LsMeshSolver::new(mesh, &lm, &NoProgress)
            .unwrap()
            .solve(&values, MAX_DIM)
            .unwrap();
        let two = TwoLevelLsMesh::new(mesh, &snap, &lm, cg, &NoProgress)
            .unwrap()
            .solve(mesh, &values, MAX_DIM, &NoProgress)
            .unwrap();
        for (&s, v) in lm.iter().zip(&values) {
            assert_eq!(two[s as usize], *v, "landmark {s} moved");
        }
        let scale = direct
            .iter()
            .flat_map(|p| p.iter())
            .fold(0.0f64, |m, c| m.max(c.abs()));
        direct
            .iter()
            .zip(&two)
            .flat_map(|(a, b)| a.iter().zip(b).map(|(a, b)| (a - b).abs()))
            .fold(0.0f64, f64::max)
            / scale
    }

    /// Enough iterations to converge on the small test meshes.
    const CONVERGE: CgOptions = CgOptions {
        tolerance: 1e-11,
        max_iterations: 20_000,
    };

    /// A torus of `n` x `m` quads with 0.2% noise (seeded), so that it is not symmetric.
    fn noisy_torus(n: u32, m: u32, seed: u64) -> ValidMesh {
        let torus = procedural::torus(n, m, 1.0, 0.35);
        ValidMesh::new(procedural::with_noise(torus, 0.002, seed)).unwrap()
    }

    /// A system moved to other landmarks keeps only what does not depend on them: it
    /// solves exactly as one built for those landmarks.
    #[test]
    fn other_landmarks_solve_as_a_new_system() {
        let mesh = noisy_torus(60, 30, 5);
        let opts = |target| DecimateOptions {
            target,
            ..Default::default()
        };
        let (fin, mut snaps) =
            decimate_with_snapshots(&mesh, &opts(80), &[600], &NoProgress).unwrap();
        let snap = snaps.pop().unwrap();
        let first: Vec<u32> = fin.landmarks[..60].to_vec();
        let cg = CgOptions::default();
        let moved = TwoLevelLsMesh::new(&mesh, &snap, &first, cg, &NoProgress)
            .unwrap()
            .with_landmarks(&snap, &fin.landmarks, &NoProgress)
            .unwrap();
        let fresh = TwoLevelLsMesh::new(&mesh, &snap, &fin.landmarks, cg, &NoProgress).unwrap();
        let values: Vec<Row> = (fin.landmarks.iter())
            .map(|&l| std::array::from_fn(|k| ((l as usize * 7 + k) % 13) as f64))
            .collect();
        let a = moved.solve(&mesh, &values, MAX_DIM, &NoProgress).unwrap();
        let b = fresh.solve(&mesh, &values, MAX_DIM, &NoProgress).unwrap();
        assert_eq!(a, b);
        // A landmark off the coarse mesh is refused, as by `new`.
        let off = (0..mesh.n_vertices() as u32)
            .find(|&v| snap.coarse_index(v).is_none())
            .unwrap();
        assert!(fresh.with_landmarks(&snap, &[off], &NoProgress).is_err());
    }

    /// The same bits with 1, 2 and 3 threads: the vertex order, the stiffness's parallel
    /// assembly, the prolongation's layers and the chunked dot products do not depend on
    /// the schedule (the mesh spans several assembly blocks).
    #[test]
    fn the_same_bits_whatever_the_thread_count() {
        let mesh = noisy_torus(200, 100, 9);
        assert!(mesh.n_vertices() > 16_384);
        let opts = DecimateOptions {
            target: 100,
            ..Default::default()
        };
        let (fin, mut snaps) = decimate_with_snapshots(&mesh, &opts, &[2000], &NoProgress).unwrap();
        let snap = snaps.pop().unwrap();
        let values: Vec<Row> = (fin.landmarks.iter())
            .map(|&l| std::array::from_fn(|k| ((l as usize * 5 + k) % 11) as f64))
            .collect();
        let run = |threads| {
            let pool = rayon::ThreadPoolBuilder::new()
                .num_threads(threads)
                .build()
                .unwrap();
            pool.install(|| {
                TwoLevelLsMesh::new(
                    &mesh,
                    &snap,
                    &fin.landmarks,
                    CgOptions::default(),
                    &NoProgress,
                )
                .unwrap()
                .solve(&mesh, &values, MAX_DIM, &NoProgress)
                .unwrap()
            })
        };
        let one = run(1);
        for threads in [2, 3] {
            assert!(run(threads) == one, "{threads} threads");
        }
        for (&s, v) in fin.landmarks.iter().zip(&values) {
            assert_eq!(one[s as usize], *v);
        }
    }

    #[test]
    fn converges_to_the_direct_solve() {
        let mesh = noisy_torus(160, 80, 3);
        let err = both(&mesh, 100, 2000, CONVERGE);
        let default = both(&mesh, 100, 2000, CgOptions::default());
        eprintln!(
            "two-level vs direct, max difference / max value: converged {err:.2e}, \
             default {default:.2e}"
        );
        assert!(err < 1e-7, "{err}");
    }

    #[test]
    fn the_iterations_do_the_work() {
        // Without iterations the prolongated coarse solution is only an approximation; the
        // conjugate gradients must close the gap (so the comparison above can fail).
        let mesh = ValidMesh::new(procedural::grid(90, 60, 3.0, 2.0)).unwrap();
        let none = CgOptions {
            max_iterations: 0,
            ..Default::default()
        };
        // Twice the default: on this small grid with its 800-vertex coarse level the default
        // 20 close less than half of the gap, 40 more than half (at 2.6M and 10.3M vertices
        // both give the same `geodesic_rel_err` to 0.1%).
        let forty = CgOptions {
            max_iterations: 40,
            ..Default::default()
        };
        let coarse_only = both(&mesh, 60, 800, none);
        let default = both(&mesh, 60, 800, CgOptions::default());
        let at_forty = both(&mesh, 60, 800, forty);
        let refined = both(&mesh, 60, 800, CONVERGE);
        eprintln!(
            "coarse only {coarse_only:.2e}, default {default:.2e}, 40 iterations \
             {at_forty:.2e}, converged {refined:.2e}"
        );
        assert!(coarse_only > 1e-3, "{coarse_only}");
        assert!(default < 0.6 * coarse_only, "{default}");
        assert!(
            at_forty < 0.5 * coarse_only && refined < 1e-7,
            "{at_forty} {refined}"
        );
    }

    #[test]
    fn precompute_through_two_levels_keeps_quality() {
        // The pipeline forced onto the two-level path against its direct solve.
        let mesh = noisy_torus(200, 100, 5);
        let direct = crate::PrecomputeOptions {
            landmarks: 200,
            ..Default::default()
        };
        let two = crate::PrecomputeOptions {
            lsmesh_direct_max: 0,
            lsmesh_coarse_vertices: 4000,
            ..direct.clone()
        };
        let (a, ra) = crate::precompute(&mesh, &direct, &NoProgress).unwrap();
        let (b, rb) = crate::precompute(&mesh, &two, &NoProgress).unwrap();
        assert_eq!(a.landmarks, b.landmarks);
        let scale = a
            .coords
            .iter()
            .flat_map(|p| p.iter())
            .fold(0.0f64, |m, c| m.max(c.abs()));
        let diff = a
            .coords
            .iter()
            .zip(&b.coords)
            .flat_map(|(p, q)| p.iter().zip(q).map(|(x, y)| (x - y).abs()))
            .fold(0.0f64, f64::max)
            / scale;
        eprintln!(
            "direct vs two-level: max coordinate difference / scale {diff:.2e}; p50 {:.4} / \
             {:.4}, p90 {:.4} / {:.4}",
            ra.geodesic_rel_err_p50,
            rb.geodesic_rel_err_p50,
            ra.geodesic_rel_err_p90,
            rb.geodesic_rel_err_p90
        );
        assert!(diff > 0.0 && diff < 1e-2, "{diff}");
        assert!((ra.geodesic_rel_err_p50 - rb.geodesic_rel_err_p50).abs() < 0.002);
        assert!((ra.geodesic_rel_err_p90 - rb.geodesic_rel_err_p90).abs() < 0.004);
    }

    #[test]
    fn landmarks_outside_the_coarse_mesh_are_errors() {
        let mesh = ValidMesh::new(procedural::torus(30, 15, 1.0, 0.4)).unwrap();
        let opts = DecimateOptions {
            target: 40,
            ..Default::default()
        };
        let (_, mut snaps) = decimate_with_snapshots(&mesh, &opts, &[200], &NoProgress).unwrap();
        let snap = snaps.pop().unwrap();
        let outside = (0..mesh.n_vertices() as u32)
            .find(|&v| snap.coarse_index(v).is_none())
            .unwrap();
        let run = |lm: &[u32]| {
            TwoLevelLsMesh::new(&mesh, &snap, lm, CgOptions::default(), &NoProgress).is_err()
        };
        assert!(run(&[snap.landmarks[0], outside]));
        assert!(run(&[snap.landmarks[0], snap.landmarks[0]]));
        assert!(run(&[snap.landmarks[0], u32::MAX]));
    }
}
