//! Jacobi-preconditioned conjugate gradients on the free rows of `A = L M⁻¹ L`, all
//! columns at once (each with its own step lengths), for the two-level least-squares mesh.
//!
//! The iteration is memory-bound (a few multiply-adds per byte read), so each pass over
//! the vertices does as much as it can: the mass scaling goes into the first product with
//! `L`, the fixed rows' zeroing and the `p·Ap` dot products into the second, the update of
//! the iterate and residual, the preconditioning and both residual dot products into one
//! pass, and the preconditioned residual is never stored. The vectors hold only as many
//! columns as are solved for (4 for up to 4, else 8), so the thin-part check's 3-column
//! solve reads half the bytes. Dot products are summed per fixed-size chunk and the chunks
//! in order, so the result does not depend on the thread schedule.

use rayon::prelude::*;

use super::stiffness::Stiffness;

use super::two_level::CgOptions;
use crate::error::{EmbedError, Progress, Stage, check_cancel};
use crate::file::MAX_DIM;

type Row = [f64; MAX_DIM];

/// Vertices per chunk of a dot product (the unit of parallel work and of summation order).
const CHUNK: usize = 4096;

/// The operator of the full system: `A = L M⁻¹ L` restricted to the free rows, and its
/// Jacobi preconditioner.
pub(super) struct FreeOperator<'a> {
    /// Cotangent stiffness `L` (symmetric, both triangles stored).
    pub stiffness: &'a Stiffness,
    /// `1 / m_i`, the lumped mass inverted.
    pub inv_mass: &'a [f64],
    /// Inverse diagonal of `A`; 0 at fixed vertices.
    pub inv_diag: &'a [f64],
    /// Whether each vertex is a landmark (fixed row).
    pub fixed: &'a [bool],
}

/// Sums per-chunk column sums in chunk order.
fn sum_chunks<const C: usize>(parts: Vec<[f64; C]>) -> [f64; C] {
    parts.into_iter().fold([0.0; C], |mut s, t| {
        for c in 0..C {
            s[c] += t[c];
        }
        s
    })
}

impl FreeOperator<'_> {
    /// `t = M⁻¹ L x`.
    fn scaled_stiffness<const C: usize>(&self, x: &[[f64; C]], t: &mut [[f64; C]]) {
        let sym = self.stiffness;
        t.par_iter_mut()
            .with_min_len(1024)
            .enumerate()
            .for_each(|(j, tj)| {
                let mut acc = [0.0; C];
                for k in sym.col_range(j) {
                    let (a, xi) = (sym.val(k), &x[sym.row(k)]);
                    for c in 0..C {
                        acc[c] += a * xi[c];
                    }
                }
                let w = self.inv_mass[j];
                *tj = acc.map(|v| v * w);
            });
    }

    /// `y = L t` on the free rows, 0 on the fixed ones (so `y = A x` for `t = M⁻¹ L x`),
    /// and the per-column dot products `p·y`.
    fn free_stiffness_dot<const C: usize>(
        &self,
        t: &[[f64; C]],
        y: &mut [[f64; C]],
        p: &[[f64; C]],
    ) -> [f64; C] {
        let sym = self.stiffness;
        let parts = y
            .par_chunks_mut(CHUNK)
            .enumerate()
            .map(|(ci, ys)| {
                let mut s = [0.0; C];
                for (i, yj) in ys.iter_mut().enumerate() {
                    let j = ci * CHUNK + i;
                    if self.fixed[j] {
                        *yj = [0.0; C];
                        continue;
                    }
                    let mut acc = [0.0; C];
                    for k in sym.col_range(j) {
                        let (a, ti) = (sym.val(k), &t[sym.row(k)]);
                        for c in 0..C {
                            acc[c] += a * ti[c];
                        }
                    }
                    *yj = acc;
                    for c in 0..C {
                        s[c] += p[j][c] * acc[c];
                    }
                }
                s
            })
            .collect();
        sum_chunks(parts)
    }

    /// `y = A x` on the free rows (0 on the fixed ones) and `x·y`, with `t` as scratch.
    fn apply<const C: usize>(
        &self,
        x: &[[f64; C]],
        t: &mut [[f64; C]],
        y: &mut [[f64; C]],
    ) -> [f64; C] {
        self.scaled_stiffness(x, t);
        self.free_stiffness_dot(t, y, x)
    }

    /// Per-column squared norms of `A x_S` on the free rows, where `x_S` is `x` at the
    /// landmarks and 0 elsewhere: the right-hand side's norms, which the stopping test
    /// compares against. `x_S` reaches only the landmarks' two-rings, so only those rows
    /// are computed, each as [`Self::apply`] computes it (the same terms in the same
    /// order, 0 for the vertices left out), and summed per chunk in the same order: the
    /// same bits as the full product, without its pass over every vertex.
    fn rhs_norms<const C: usize>(&self, landmarks: &[u32], x: &[[f64; C]]) -> [f64; C] {
        use std::collections::HashMap;
        let sym = self.stiffness;
        let ring_of = |vs: &mut dyn Iterator<Item = usize>| -> Vec<usize> {
            let mut ring: Vec<usize> = vs
                .flat_map(|v| sym.col_rows(v).iter().map(|&u| u as usize))
                .collect();
            ring.sort_unstable();
            ring.dedup();
            ring
        };
        // One pass of `M⁻¹ L` or `L` over the rows `at`, reading `v` (0 where absent).
        let product = |at: &[usize], v: &HashMap<usize, [f64; C]>| -> Vec<[f64; C]> {
            at.iter()
                .map(|&j| {
                    let mut acc = [0.0; C];
                    for k in sym.col_range(j) {
                        let (a, vi) = (sym.val(k), v.get(&sym.row(k)).unwrap_or(&[0.0; C]));
                        for c in 0..C {
                            acc[c] += a * vi[c];
                        }
                    }
                    acc
                })
                .collect()
        };
        let xs: HashMap<usize, [f64; C]> = (landmarks.iter())
            .map(|&s| (s as usize, x[s as usize]))
            .collect();
        let ring1 = ring_of(&mut landmarks.iter().map(|&s| s as usize));
        let t: HashMap<usize, [f64; C]> = (ring1.iter().zip(product(&ring1, &xs)))
            .map(|(&j, acc)| (j, acc.map(|v| v * self.inv_mass[j])))
            .collect();
        let ring2: Vec<usize> = ring_of(&mut ring1.iter().copied())
            .into_iter()
            .filter(|&j| !self.fixed[j])
            .collect();
        let y = product(&ring2, &t);
        // Chunks in order, rows in order within each: the full sum's order (its other
        // rows add +0).
        let mut parts: Vec<[f64; C]> = Vec::new();
        let mut chunk = usize::MAX;
        for (&j, yj) in ring2.iter().zip(&y) {
            if j / CHUNK != chunk {
                chunk = j / CHUNK;
                parts.push([0.0; C]);
            }
            let s = parts.last_mut().expect("a chunk was pushed");
            for c in 0..C {
                s[c] += yj[c] * yj[c];
            }
        }
        sum_chunks(parts)
    }

    /// Conjugate gradients from the iterate `x` (whose fixed rows hold the landmark values
    /// and stay unchanged) on the first `dim` columns, until every column's residual norm
    /// is at most `cg.tolerance` times its right-hand side's or `cg.max_iterations` pass.
    pub(super) fn solve(
        &self,
        landmarks: &[u32],
        x: &mut [Row],
        dim: usize,
        cg: CgOptions,
        progress: &dyn Progress,
    ) -> Result<(), EmbedError> {
        if dim <= 4 {
            self.solve_width::<4>(landmarks, x, dim, cg, progress)
        } else {
            self.solve_width::<MAX_DIM>(landmarks, x, dim, cg, progress)
        }
    }

    /// [`Self::solve`] with vectors of `C >= dim` columns.
    fn solve_width<const C: usize>(
        &self,
        landmarks: &[u32],
        x_out: &mut [Row],
        dim: usize,
        cg: CgOptions,
        progress: &dyn Progress,
    ) -> Result<(), EmbedError> {
        let n = x_out.len();
        let mut x: Vec<[f64; C]> = x_out
            .par_iter()
            .map(|v| std::array::from_fn(|c| v[c]))
            .collect();
        let mut t = vec![[0.0; C]; n];
        let mut r = vec![[0.0; C]; n];
        // Right-hand side norms: b = -(A x_S) on the free rows.
        let b2 = self.rhs_norms(landmarks, &x);
        // r = b - A_FF x_F = -(A x) on the free rows; p = z = D r.
        self.apply(&x, &mut t, &mut r);
        let mut p = vec![[0.0; C]; n];
        let parts: Vec<([f64; C], [f64; C])> = r
            .par_chunks_mut(CHUNK)
            .zip(p.par_chunks_mut(CHUNK))
            .enumerate()
            .map(|(ci, (rs, ps))| {
                let (mut rz, mut rr) = ([0.0; C], [0.0; C]);
                for (i, (ri, pi)) in rs.iter_mut().zip(ps).enumerate() {
                    let d = self.inv_diag[ci * CHUNK + i];
                    for c in 0..C {
                        ri[c] = -ri[c];
                        pi[c] = ri[c] * d;
                        rz[c] += ri[c] * pi[c];
                        rr[c] += ri[c] * ri[c];
                    }
                }
                (rz, rr)
            })
            .collect();
        let (rz_parts, rr_parts): (Vec<_>, Vec<_>) = parts.into_iter().unzip();
        let (mut rz, mut r2) = (sum_chunks(rz_parts), sum_chunks(rr_parts));
        let mut q = vec![[0.0; C]; n];
        let tol2 = cg.tolerance * cg.tolerance;
        let mut active: [bool; C] = std::array::from_fn(|c| c < dim && b2[c] > 0.0);
        for it in 0..cg.max_iterations {
            for c in 0..C {
                active[c] &= r2[c] > tol2 * b2[c];
            }
            if !active.iter().any(|&a| a) {
                break;
            }
            // Every iteration: one is about a second at 10M vertices under load.
            check_cancel(progress)?;
            if it % 16 == 0 {
                progress.report(
                    Stage::LsMesh,
                    0.9 + 0.1 * it as f64 / cg.max_iterations as f64,
                );
            }
            let pq = self.apply(&p, &mut t, &mut q);
            let alpha: [f64; C] = std::array::from_fn(|c| {
                if active[c] && pq[c] > 0.0 {
                    rz[c] / pq[c]
                } else {
                    0.0
                }
            });
            // x += alpha p, r -= alpha q, and the dot products of the new r with D r and r.
            let parts: Vec<([f64; C], [f64; C])> = x
                .par_chunks_mut(CHUNK)
                .zip(r.par_chunks_mut(CHUNK))
                .zip(p.par_chunks(CHUNK).zip(q.par_chunks(CHUNK)))
                .enumerate()
                .map(|(ci, ((xs, rs), (ps, qs)))| {
                    let (mut rz, mut rr) = ([0.0; C], [0.0; C]);
                    for (i, ((xi, ri), (pi, qi))) in
                        xs.iter_mut().zip(rs).zip(ps.iter().zip(qs)).enumerate()
                    {
                        let d = self.inv_diag[ci * CHUNK + i];
                        for c in 0..C {
                            xi[c] += alpha[c] * pi[c];
                            ri[c] -= alpha[c] * qi[c];
                            rz[c] += ri[c] * ri[c] * d;
                            rr[c] += ri[c] * ri[c];
                        }
                    }
                    (rz, rr)
                })
                .collect();
            let (rz_parts, rr_parts): (Vec<_>, Vec<_>) = parts.into_iter().unzip();
            let rz_new = sum_chunks(rz_parts);
            r2 = sum_chunks(rr_parts);
            let beta: [f64; C] = std::array::from_fn(|c| {
                if active[c] && rz[c] > 0.0 {
                    rz_new[c] / rz[c]
                } else {
                    0.0
                }
            });
            rz = rz_new;
            // p = D r + beta p.
            p.par_iter_mut()
                .with_min_len(1024)
                .zip(&r)
                .zip(self.inv_diag)
                .for_each(|((pi, ri), &d)| {
                    for c in 0..C {
                        pi[c] = ri[c] * d + beta[c] * pi[c];
                    }
                });
        }
        x_out
            .par_iter_mut()
            .zip(&x)
            .for_each(|(o, v)| o[..C].copy_from_slice(v));
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::NoProgress;
    use rand::{Rng, SeedableRng};
    use wavg_mesh::{ValidMesh, procedural};

    /// The right-hand side's norms from the landmarks' two-rings have the bits of the full
    /// product's, on a mesh of several chunks with landmarks spread over them.
    #[test]
    fn right_hand_side_norms_from_the_two_rings_equal_the_full_product_bitwise() {
        let torus = procedural::torus(160, 80, 1.0, 0.35);
        let mesh = ValidMesh::new(procedural::with_noise(torus, 0.002, 3)).unwrap();
        let n = mesh.n_vertices();
        assert!(n > 3 * CHUNK);
        let (stiffness, mass) = Stiffness::cotan(&mesh, None, &NoProgress).unwrap();
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(11);
        let mut landmarks: Vec<u32> = (0..40).map(|_| rng.random_range(0..n as u32)).collect();
        landmarks.push(0);
        landmarks.push(n as u32 - 1);
        landmarks.sort_unstable();
        landmarks.dedup();
        let mut fixed = vec![false; n];
        for &s in &landmarks {
            fixed[s as usize] = true;
        }
        let inv_mass: Vec<f64> = mass.iter().map(|m| 1.0 / m).collect();
        let inv_diag = vec![1.0; n];
        let op = FreeOperator {
            stiffness: &stiffness,
            inv_mass: &inv_mass,
            inv_diag: &inv_diag,
            fixed: &fixed,
        };
        let x: Vec<[f64; 4]> = (0..n)
            .map(|_| std::array::from_fn(|_| rng.random_range(-1.0..1.0)))
            .collect();
        let mut xs = vec![[0.0; 4]; n];
        for &s in &landmarks {
            xs[s as usize] = x[s as usize];
        }
        let (mut t, mut r) = (vec![[0.0; 4]; n], vec![[0.0; 4]; n]);
        op.apply(&xs, &mut t, &mut r);
        let full = sum_chunks(
            r.chunks(CHUNK)
                .map(|rs| {
                    let mut s = [0.0; 4];
                    for ri in rs {
                        for c in 0..4 {
                            s[c] += ri[c] * ri[c];
                        }
                    }
                    s
                })
                .collect(),
        );
        let sparse = op.rhs_norms(&landmarks, &x);
        assert!(full.iter().all(|&v| v > 0.0));
        assert_eq!(full.map(f64::to_bits), sparse.map(f64::to_bits));
    }
}
