//! The cotangent stiffness of a large mesh in compressed columns with 32-bit indices,
//! assembled in place from the mesh's one-rings, one column per vertex, in parallel: each
//! column is its vertex and its ring (sorted), and each entry sums the contributions of
//! the vertex's faces in ascending face order. [`wavg_mesh::geometry::cotan_stiffness`]
//! builds the same matrix from a list of triplets, which at its peak holds about 770 bytes
//! a vertex beside the result; this holds the result alone (about 90 bytes a vertex).
//!
//! The columns can be laid out in another vertex order ([`VertexOrder`]): column and row
//! `j` are then vertex `old_of_new[j]`, and every value is bit for bit the one of the
//! file's order. Each entry starts from `-0.0` (the identity of floating-point
//! addition); the triplet assembly sums a diagonal entry's contributions in the order of
//! its unstable sort, so diagonals can differ from it in the last bits.

use rayon::prelude::*;
use wavg_mesh::{ValidMesh, geometry};

use super::locality::VertexOrder;
use crate::error::{EmbedError, Progress, check_cancel};

/// Columns assembled between two looks at `progress`'s cancellation (a few milliseconds
/// of work), and the unit of parallel work.
const CANCEL_EVERY: usize = 1 << 14;

/// A symmetric sparse matrix in compressed columns (column `j`'s rows, ascending, and
/// values lie at `col_ptr[j]..col_ptr[j + 1]`).
pub(crate) struct Stiffness {
    col_ptr: Vec<u32>,
    rows: Vec<u32>,
    vals: Vec<f64>,
}

impl Stiffness {
    /// The cotangent stiffness `L` of `mesh` (the sign convention of
    /// [`geometry::cotan_stiffness`]) with its rows and columns in `order` (the file's
    /// order when `None`), and the lumped masses ([`geometry::lumped_mass`], bit for bit)
    /// in the same order. Stops with [`EmbedError::Cancelled`] when `progress` asks
    /// (looked at every [`CANCEL_EVERY`] columns).
    pub(crate) fn cotan(
        mesh: &ValidMesh,
        order: Option<&VertexOrder>,
        progress: &dyn Progress,
    ) -> Result<(Self, Vec<f64>), EmbedError> {
        let n = mesh.n_vertices();
        let topo = mesh.topology();
        let old = |j: usize| order.map_or(j, |o| o.old_of_new[j] as usize) as u32;
        let new = |v: u32| order.map_or(v, |o| o.new_of_old[v as usize]);
        let lens: Vec<u32> = (0..n)
            .into_par_iter()
            .map(|j| 1 + topo.ring(old(j)).len() as u32)
            .collect();
        let nnz: usize = lens.iter().map(|&l| l as usize).sum();
        u32::try_from(nnz).map_err(|_| {
            EmbedError::InvalidArgument("the mesh is too large for 32-bit indices".into())
        })?;
        let mut col_ptr = Vec::with_capacity(n + 1);
        col_ptr.push(0u32);
        let mut end = 0u32;
        for l in lens {
            end += l;
            col_ptr.push(end);
        }
        let mut rows = vec![0u32; nnz];
        let mut vals = vec![-0.0; nnz];
        let mut mass = vec![0.0; n];
        // Blocks of columns with their slices of the arrays, filled in parallel.
        let mut blocks = Vec::with_capacity(n.div_ceil(CANCEL_EVERY));
        let (mut rest_rows, mut rest_vals) = (&mut rows[..], &mut vals[..]);
        for (b, m) in mass.chunks_mut(CANCEL_EVERY).enumerate() {
            let first = b * CANCEL_EVERY;
            let len = (col_ptr[first + m.len()] - col_ptr[first]) as usize;
            let (r, rr) = std::mem::take(&mut rest_rows).split_at_mut(len);
            let (v, rv) = std::mem::take(&mut rest_vals).split_at_mut(len);
            (rest_rows, rest_vals) = (rr, rv);
            blocks.push((first, m, r, v));
        }
        blocks
            .into_par_iter()
            .try_for_each(|(first, mass, rows, vals)| {
                check_cancel(progress)?;
                let (mut entries, mut faces) = (Vec::new(), Vec::new());
                let mut at = 0;
                for (i, m) in mass.iter_mut().enumerate() {
                    *m = column(mesh, old(first + i), &mut entries, &mut faces)?;
                    entries.iter_mut().for_each(|e| e.0 = new(e.0));
                    entries.sort_unstable_by_key(|e| e.0);
                    for (k, &(r, x)) in entries.iter().enumerate() {
                        rows[at + k] = r;
                        vals[at + k] = x;
                    }
                    at += entries.len();
                }
                Ok::<_, EmbedError>(())
            })?;
        Ok((
            Self {
                col_ptr,
                rows,
                vals,
            },
            mass,
        ))
    }

    /// The slots of column `j`.
    #[inline]
    pub(crate) fn col_range(&self, j: usize) -> std::ops::Range<usize> {
        self.col_ptr[j] as usize..self.col_ptr[j + 1] as usize
    }

    /// Row of slot `k`.
    #[inline]
    pub(crate) fn row(&self, k: usize) -> usize {
        self.rows[k] as usize
    }

    /// Value of slot `k`.
    #[inline]
    pub(crate) fn val(&self, k: usize) -> f64 {
        self.vals[k]
    }

    /// The rows of column `j`.
    pub(crate) fn col_rows(&self, j: usize) -> &[u32] {
        &self.rows[self.col_range(j)]
    }
}

/// Column `v` of the stiffness into `entries` (`(row, value)` for `v` and its ring, in
/// ring order), each entry summed over `v`'s faces in ascending face order, as the serial
/// assembly over all faces would; returns `v`'s lumped mass, summed the same way.
/// `faces` is scratch.
fn column(
    mesh: &ValidMesh,
    v: u32,
    entries: &mut Vec<(u32, f64)>,
    faces: &mut Vec<u32>,
) -> Result<f64, EmbedError> {
    let topo = mesh.topology();
    entries.clear();
    entries.push((v, -0.0));
    entries.extend(topo.ring(v).iter().map(|&u| (u, -0.0)));
    faces.clear();
    faces.extend_from_slice(topo.ring_faces(v));
    faces.sort_unstable();
    let mut mass = 0.0;
    for &f in faces.iter() {
        let f = f as usize;
        let t = mesh.triangles[f];
        let cot = geometry::cotangents(mesh, f);
        for i in 0..3 {
            let (a, b) = (t[(i + 1) % 3], t[(i + 2) % 3]);
            let other = match (a == v, b == v) {
                (true, _) => b,
                (_, true) => a,
                _ => continue,
            };
            let w = 0.5 * cot[i];
            let slot = (entries[1..].iter_mut())
                .find(|e| e.0 == other)
                .ok_or_else(|| {
                    EmbedError::InvalidArgument(format!(
                        "stiffness: vertices {other} and {v} share a face but not a ring"
                    ))
                })?;
            slot.1 += -w;
            entries[0].1 += w;
        }
        mass += geometry::face_area(mesh, f) / 3.0;
    }
    Ok(mass)
}

#[cfg(test)]
mod tests {
    use super::*;
    use wavg_mesh::procedural;

    /// A cancelled assembly stops (at its first look) with `Cancelled`.
    #[test]
    fn a_cancelled_assembly_stops() {
        struct Cancelled;
        impl Progress for Cancelled {
            fn report(&self, _: crate::Stage, _: f64) {}
            fn cancelled(&self) -> bool {
                true
            }
        }
        let mesh = ValidMesh::new(procedural::torus(30, 14, 1.0, 0.4)).unwrap();
        assert!(matches!(
            Stiffness::cotan(&mesh, None, &Cancelled),
            Err(EmbedError::Cancelled)
        ));
    }

    /// The same pattern and, up to rounding of the diagonal sums, the same values as the
    /// triplet assembly, on a closed and an open mesh.
    #[test]
    fn the_same_matrix_as_the_triplet_assembly() {
        for m in [
            procedural::with_noise(procedural::torus(30, 14, 1.0, 0.4), 0.3, 2),
            procedural::with_noise(procedural::grid(12, 9, 2.0, 1.0), 0.2, 5),
        ] {
            let mesh = ValidMesh::new(m).unwrap();
            let (s, mass) = Stiffness::cotan(&mesh, None, &crate::NoProgress).unwrap();
            let lumped = geometry::lumped_mass(&mesh);
            assert!(
                mass.iter()
                    .zip(&lumped)
                    .all(|(a, b)| a.to_bits() == b.to_bits())
            );
            let reference = geometry::cotan_stiffness(&mesh).unwrap();
            let (sym, vals) = reference.parts();
            assert_eq!(s.rows.len(), vals.len());
            for j in 0..mesh.n_vertices() {
                let (a, b) = (s.col_range(j), sym.col_range(j));
                assert_eq!(a.len(), b.len());
                for (ka, kb) in a.zip(b) {
                    assert_eq!(s.row(ka), sym.row_idx()[kb]);
                    let (x, y) = (s.val(ka), vals[kb]);
                    assert!((x - y).abs() <= 1e-14 * y.abs().max(1.0), "{x} vs {y}");
                    if s.row(ka) != j {
                        // At most two contributions: addition commutes, the bits agree.
                        assert_eq!(x.to_bits(), y.to_bits());
                    }
                }
            }
        }
    }

    /// In the Morton order, the same matrix and masses bit for bit, permuted.
    #[test]
    fn another_order_permutes_the_same_values() {
        let mesh = ValidMesh::new(procedural::with_noise(
            procedural::torus(40, 18, 1.0, 0.4),
            0.3,
            4,
        ))
        .unwrap();
        let order = VertexOrder::morton(&mesh);
        let (a, ma) = Stiffness::cotan(&mesh, None, &crate::NoProgress).unwrap();
        let (b, mb) = Stiffness::cotan(&mesh, Some(&order), &crate::NoProgress).unwrap();
        assert!(
            order
                .old_of_new
                .iter()
                .enumerate()
                .any(|(j, &v)| j != v as usize)
        );
        for (j, &v) in order.old_of_new.iter().enumerate() {
            let v = v as usize;
            assert_eq!(ma[v].to_bits(), mb[j].to_bits());
            let mut want: Vec<(u32, u64)> = (a.col_range(v))
                .map(|k| (order.new_of_old[a.row(k)], a.val(k).to_bits()))
                .collect();
            want.sort_unstable();
            let got: Vec<(u32, u64)> = (b.col_range(j))
                .map(|k| (b.row(k) as u32, b.val(k).to_bits()))
                .collect();
            assert_eq!(got, want, "column {j}");
        }
    }
}
