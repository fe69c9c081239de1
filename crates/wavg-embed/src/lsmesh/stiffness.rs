//! The cotangent stiffness of a large mesh in compressed columns with 32-bit indices,
//! assembled in place from the mesh's one-rings: the pattern first (each column is its
//! vertex and its ring, sorted), then the faces' contributions added into their slots.
//! [`wavg_mesh::geometry::cotan_stiffness`] builds the same matrix from a list of
//! triplets, which at its peak holds about 770 bytes a vertex beside the result; this
//! holds the result alone (about 90 bytes a vertex).
//!
//! Each entry sums its contributions in face order, starting from `-0.0` (the identity of
//! floating-point addition). The triplet assembly sums a diagonal entry's contributions
//! in the order of its unstable sort, so diagonals can differ from it in the last bits.

use wavg_mesh::{ValidMesh, geometry};

use crate::error::{EmbedError, Progress, check_cancel};

/// Faces (or vertices) assembled between two looks at `progress`'s cancellation (a few
/// milliseconds of work).
const CANCEL_EVERY: usize = 1 << 16;

/// A symmetric sparse matrix in compressed columns (column `j`'s rows, ascending, and
/// values lie at `col_ptr[j]..col_ptr[j + 1]`).
pub(crate) struct Stiffness {
    col_ptr: Vec<u32>,
    rows: Vec<u32>,
    vals: Vec<f64>,
}

impl Stiffness {
    /// The cotangent stiffness `L` of `mesh` (the sign convention of
    /// [`geometry::cotan_stiffness`]); stops with [`EmbedError::Cancelled`] when
    /// `progress` asks (looked at every [`CANCEL_EVERY`] vertices and faces).
    pub(crate) fn cotan(mesh: &ValidMesh, progress: &dyn Progress) -> Result<Self, EmbedError> {
        let n = mesh.n_vertices();
        let topo = mesh.topology();
        let too_large =
            || EmbedError::InvalidArgument("the mesh is too large for 32-bit indices".into());
        let nnz: usize = n + (0..n as u32).map(|v| topo.ring(v).len()).sum::<usize>();
        u32::try_from(nnz).map_err(|_| too_large())?;
        let mut col_ptr = Vec::with_capacity(n + 1);
        let mut rows = Vec::with_capacity(nnz);
        col_ptr.push(0u32);
        for v in 0..n as u32 {
            if v as usize % CANCEL_EVERY == 0 {
                check_cancel(progress)?;
            }
            let start = rows.len();
            rows.push(v);
            rows.extend_from_slice(topo.ring(v));
            rows[start..].sort_unstable();
            col_ptr.push(rows.len() as u32);
        }
        let mut s = Self {
            col_ptr,
            rows,
            vals: vec![-0.0; nnz],
        };
        for (f, t) in mesh.triangles.iter().enumerate() {
            if f % CANCEL_EVERY == 0 {
                check_cancel(progress)?;
            }
            let cot = geometry::cotangents(mesh, f);
            for i in 0..3 {
                let (a, b) = (t[(i + 1) % 3], t[(i + 2) % 3]);
                let w = 0.5 * cot[i];
                s.add(a, b, -w)?;
                s.add(b, a, -w)?;
                s.add(a, a, w)?;
                s.add(b, b, w)?;
            }
        }
        Ok(s)
    }

    /// Adds `w` to entry `(row, col)` of the pattern.
    fn add(&mut self, row: u32, col: u32, w: f64) -> Result<(), EmbedError> {
        let range = self.col_range(col as usize);
        let k = self.rows[range.clone()]
            .iter()
            .position(|&r| r == row)
            .ok_or_else(|| {
                EmbedError::InvalidArgument(format!(
                    "stiffness: vertices {row} and {col} share a face but not a ring"
                ))
            })?;
        self.vals[range.start + k] += w;
        Ok(())
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
            Stiffness::cotan(&mesh, &Cancelled),
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
            let s = Stiffness::cotan(&mesh, &crate::NoProgress).unwrap();
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
}
