//! A vertex order with memory locality for the iterative solve of large meshes.
//!
//! The conjugate gradients are memory-bound: each product with the stiffness gathers the
//! values of every vertex's neighbours. In a file's vertex order neighbours can lie far
//! apart (a Loop subdivision appends each level's new vertices after the old ones, and
//! scanners emit vertices in acquisition order), so most gathers miss the caches. Sorted
//! along a Z-order (Morton) curve through the bounding box, vertices close in space, and
//! so neighbours on the surface, are mostly close in memory.

use rayon::prelude::*;
use wavg_mesh::TriMesh;

/// Bits per axis of the Morton code (3 x 21 = 63 bits).
const BITS: u32 = 21;

/// A permutation of the vertices: `old_of_new[j]` is the vertex at position `j` of the new
/// order, `new_of_old[v]` its inverse.
pub(crate) struct VertexOrder {
    pub old_of_new: Vec<u32>,
    pub new_of_old: Vec<u32>,
}

impl VertexOrder {
    /// The vertices of `mesh` sorted by the Morton code of their position in its bounding
    /// box (ties, and non-finite positions, by vertex id): deterministic, whatever the
    /// thread count.
    pub(crate) fn morton(mesh: &TriMesh) -> Self {
        let n = mesh.n_vertices();
        let (lo, hi) = mesh
            .bounding_box()
            .map_or(([0.0; 3], [1.0; 3]), |(lo, hi)| {
                ([lo.x, lo.y, lo.z], [hi.x, hi.y, hi.z])
            });
        let scale: [f64; 3] = std::array::from_fn(|a| {
            let extent = hi[a] - lo[a];
            if extent > 0.0 && extent.is_finite() {
                f64::from((1u32 << BITS) - 1) / extent
            } else {
                0.0
            }
        });
        let mut keyed: Vec<(u64, u32)> = (mesh.positions.par_iter().enumerate())
            .map(|(v, p)| {
                let q = [p.x, p.y, p.z];
                let cell: [u64; 3] = std::array::from_fn(|a| {
                    // `as` saturates (NaN to 0), so any input gives a cell in range.
                    let c = ((q[a] - lo[a]) * scale[a]) as u64;
                    c.min((1 << BITS) - 1)
                });
                (
                    spread(cell[0]) | (spread(cell[1]) << 1) | (spread(cell[2]) << 2),
                    v as u32,
                )
            })
            .collect();
        keyed.par_sort_unstable();
        let old_of_new: Vec<u32> = keyed.into_par_iter().map(|(_, v)| v).collect();
        let mut new_of_old = vec![0u32; n];
        for (j, &v) in old_of_new.iter().enumerate() {
            new_of_old[v as usize] = j as u32;
        }
        Self {
            old_of_new,
            new_of_old,
        }
    }

    /// `values` (one per vertex, in the old order) in the new order.
    pub(crate) fn to_new<T: Copy + Send + Sync>(&self, values: &[T]) -> Vec<T> {
        (self.old_of_new.par_iter())
            .map(|&v| values[v as usize])
            .collect()
    }

    /// `values` (one per vertex, in the new order) in the old order.
    pub(crate) fn to_old<T: Copy + Send + Sync>(&self, values: &[T]) -> Vec<T> {
        (self.new_of_old.par_iter())
            .map(|&j| values[j as usize])
            .collect()
    }
}

/// The low 21 bits of `x` spread to every third bit.
fn spread(x: u64) -> u64 {
    let mut x = x & 0x1f_ffff;
    x = (x | (x << 32)) & 0x1f_0000_0000_ffff;
    x = (x | (x << 16)) & 0x1f_0000_ff00_00ff;
    x = (x | (x << 8)) & 0x100f_00f0_0f00_f00f;
    x = (x | (x << 4)) & 0x10c3_0c30_c30c_30c3;
    x = (x | (x << 2)) & 0x1249_2492_4924_9249;
    x
}

#[cfg(test)]
mod tests {
    use super::*;
    use wavg_mesh::procedural;

    /// Bit `i` of the input lands on bit `3 i`.
    #[test]
    fn spread_interleaves() {
        for i in 0..BITS {
            assert_eq!(spread(1 << i), 1 << (3 * i), "bit {i}");
        }
        assert_eq!(spread(u64::MAX), 0x1249_2492_4924_9249);
    }

    /// A permutation and its inverse; neighbours end up closer in memory than in a
    /// shuffled order.
    #[test]
    fn a_permutation_that_brings_neighbours_together() {
        let mut mesh = procedural::torus(80, 40, 1.0, 0.4);
        // Shuffle the vertices (a fixed stride coprime with the count).
        let n = mesh.n_vertices();
        let stride = 1_237;
        assert_eq!(num_gcd(stride, n), 1);
        let to: Vec<u32> = (0..n).map(|v| ((v * stride) % n) as u32).collect();
        let mut positions = mesh.positions.clone();
        for (v, &t) in to.iter().enumerate() {
            positions[t as usize] = mesh.positions[v];
        }
        mesh.positions = positions;
        for t in &mut mesh.triangles {
            *t = t.map(|v| to[v as usize]);
        }
        let order = VertexOrder::morton(&mesh);
        let mut seen = vec![false; n];
        for (j, &v) in order.old_of_new.iter().enumerate() {
            assert!(!std::mem::replace(&mut seen[v as usize], true));
            assert_eq!(order.new_of_old[v as usize] as usize, j);
        }
        let gap = |map: &dyn Fn(u32) -> u32| {
            let edges = mesh
                .triangles
                .iter()
                .flat_map(|t| (0..3).map(|i| (t[i], t[(i + 1) % 3])));
            let gaps: Vec<u64> = edges.map(|(a, b)| map(a).abs_diff(map(b)) as u64).collect();
            gaps.iter().sum::<u64>() / gaps.len() as u64
        };
        let before = gap(&|v| v);
        let after = gap(&|v| order.new_of_old[v as usize]);
        assert!(after * 4 < before, "mean index gap {before} -> {after}");
        let values: Vec<u32> = (0..n as u32).collect();
        assert_eq!(order.to_old(&order.to_new(&values)), values);
    }

    fn num_gcd(a: usize, b: usize) -> usize {
        if b == 0 { a } else { num_gcd(b, a % b) }
    }
}
