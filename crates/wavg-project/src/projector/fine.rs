//! Starts on a large mesh: the occupied cells of a grid as fine as the start grid would be
//! without its cap, in a hash table (a dense grid that fine would take gigabytes at 10M
//! vertices; its occupied cells, a surface's worth, take megabytes).
//!
//! The capped grid's walk ends at a vertex about a coarse cell from the query's closest
//! vertex: many edges on a large mesh, each a step of the vertex walk and a round of cache
//! misses. The foot of the query on that vertex's tangent plane lies near the closest
//! vertex (the query's offset from the surface is along the normal there), and the fine
//! cell holding the foot names a vertex a fine cell from it: one lookup for most of the
//! walk.

use rayon::prelude::*;

use super::layout::WalkPoint;
use super::{NONE, VertexId};

/// Bits of a fine cell's index along each axis in its key.
const AXIS_BITS: u32 = 21;
/// The key of a free slot (no cell has it: indices stay below `2^AXIS_BITS`).
const FREE: u64 = u64::MAX;

/// A slot of the table: a fine cell's key and its most central vertex.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[repr(C)]
struct Slot {
    key: u64,
    v: VertexId,
}

/// The occupied cells of a fine grid over three walk axes, hashed with linear probing.
#[derive(Clone, Debug, Default)]
pub(super) struct FineCells {
    axes: [usize; 3],
    origin: [f32; 3],
    /// Fine cells per walk unit.
    inv_cell: f32,
    /// Table size is `2^(64 - shift)`, at least twice the occupied cells.
    shift: u32,
    slots: Vec<Slot>,
}

impl FineCells {
    /// The occupied cells of the grid over walk axes `axes` from `origin`, `inv_cell`
    /// cells per walk unit, each with its most central vertex (ties to the lowest index:
    /// the same table on any number of threads). Empty when `inv_cell` would need more
    /// than `2^21` cells along an axis.
    pub(super) fn new(
        walk: &[WalkPoint],
        axes: [usize; 3],
        origin: [f32; 3],
        inv_cell: f32,
    ) -> Self {
        let mut grid = Self {
            axes,
            origin,
            inv_cell,
            shift: 64,
            slots: Vec::new(),
        };
        if !(inv_cell * 65536.0 < (1u32 << AXIS_BITS) as f32) {
            return grid;
        }
        // (key, squared distance to the cell's centre above the vertex): sorted, the
        // first of each key is its cell's most central, lowest vertex.
        let mut keyed: Vec<(u64, u64)> = walk
            .par_iter()
            .enumerate()
            .with_min_len(4096)
            .filter_map(|(v, w)| {
                let (key, d2) = grid.key_of(&w.unpack())?;
                Some((key, (u64::from(d2.to_bits()) << 32) | v as u64))
            })
            .collect();
        keyed.par_sort_unstable();
        keyed.dedup_by_key(|k| k.0);
        let size = (2 * keyed.len()).next_power_of_two().max(2);
        grid.shift = 64 - size.trailing_zeros();
        grid.slots = vec![Slot { key: FREE, v: NONE }; size];
        for &(key, dv) in &keyed {
            let mut s = grid.home(key);
            while grid.slots[s].key != FREE {
                s = (s + 1) & (size - 1);
            }
            grid.slots[s] = Slot { key, v: dv as u32 };
        }
        grid
    }

    /// The slot a key's probe starts at.
    #[inline(always)]
    fn home(&self, key: u64) -> usize {
        (key.wrapping_mul(0x9E37_79B9_7F4A_7C15) >> self.shift) as usize
    }

    /// The key of the fine cell holding walk point `p` and the squared distance from `p`
    /// to its centre (in cells); `None` outside the grid.
    #[inline(always)]
    fn key_of(&self, p: &[f32; 8]) -> Option<(u64, f32)> {
        let mut key = 0u64;
        let mut d2 = 0.0f32;
        for i in 0..3 {
            let x = (p[self.axes[i]] - self.origin[i]) * self.inv_cell;
            if !(0.0..(1u32 << AXIS_BITS) as f32).contains(&x) {
                return None;
            }
            let c = x.floor();
            let d = x - (c + 0.5);
            d2 += d * d;
            key |= (c as u64) << (AXIS_BITS * i as u32);
        }
        Some((key, d2))
    }

    /// The most central vertex of the fine cell holding walk point `p`, if that cell holds
    /// a vertex.
    #[inline]
    pub(super) fn vertex_at(&self, p: &[f32; 8]) -> Option<VertexId> {
        if self.slots.is_empty() {
            return None;
        }
        let (key, _) = self.key_of(p)?;
        let mask = self.slots.len() - 1;
        let mut s = self.home(key);
        loop {
            let slot = &self.slots[s];
            if slot.key == key {
                return Some(slot.v);
            }
            if slot.key == FREE {
                return None;
            }
            s = (s + 1) & mask;
        }
    }

    /// Starts loading the slot where [`FineCells::vertex_at`]'s probe for `p` begins (for
    /// interleaved lookups); no effect on results.
    #[inline]
    pub(super) fn prefetch(&self, p: &[f32; 8]) {
        if let Some((key, _)) = self.key_of(p) {
            if let Some(slot) = self.slots.get(self.home(key)) {
                super::prefetch_line(slot);
            }
        }
    }

    /// Whether the table holds any cell.
    #[inline]
    pub(super) fn is_empty(&self) -> bool {
        self.slots.is_empty()
    }

    /// Heap bytes used.
    pub(super) fn bytes(&self) -> usize {
        std::mem::size_of_val(&self.slots[..])
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::{EmbeddedMesh, Projector};
    use std::sync::Arc;
    use wavg_mesh::{ValidMesh, procedural};

    /// Each occupied cell names its most central vertex (lowest index on ties), found by
    /// brute force; empty cells and points off the grid name none; the table is the
    /// same on any number of threads.
    #[test]
    fn each_cell_names_its_most_central_vertex_whatever_the_threads() {
        let m = ValidMesh::new(procedural::with_noise(procedural::icosphere(4), 0.01, 5)).unwrap();
        let emb = Arc::new(EmbeddedMesh::from_positions(Arc::new(m)));
        let p = Projector::new(emb).unwrap();
        let w = &p.walk_coords;
        let fine = FineCells::new(w, [0, 1, 2], [0.0; 3], 24.0 / 65536.0);
        let mut best = std::collections::HashMap::new();
        for (v, r) in w.iter().enumerate() {
            let (key, d2) = fine.key_of(&r.unpack()).unwrap();
            let e = best.entry(key).or_insert((d2, v as u32));
            if (d2, v as u32) < *e {
                *e = (d2, v as u32);
            }
        }
        assert!(best.len() > 500, "{} cells", best.len());
        assert!(fine.slots.len() >= 2 * best.len());
        for r in w {
            let (key, _) = fine.key_of(&r.unpack()).unwrap();
            assert_eq!(fine.vertex_at(&r.unpack()), Some(best[&key].1));
        }
        // The sphere's centre cell and points past the grid's sides hold no vertex.
        let mut centre = w[0].unpack();
        for a in 0..3 {
            let (lo, hi) = w.iter().fold((f32::MAX, f32::MIN), |(l, h), r| {
                (l.min(r.c[a] as f32), h.max(r.c[a] as f32))
            });
            centre[a] = 0.5 * (lo + hi);
        }
        assert_eq!(fine.vertex_at(&centre), None);
        let mut off = w[0].unpack();
        off[1] = -10.0;
        assert_eq!(fine.vertex_at(&off), None);
        off[1] = f32::NAN;
        assert_eq!(fine.vertex_at(&off), None);
        for threads in [1, 3] {
            let pool = rayon::ThreadPoolBuilder::new()
                .num_threads(threads)
                .build()
                .unwrap();
            let q = pool.install(|| FineCells::new(w, [0, 1, 2], [0.0; 3], 24.0 / 65536.0));
            assert_eq!(q.slots, fine.slots);
        }
        // Cells so fine that their indices would not fit make no table.
        assert!(FineCells::new(w, [0, 1, 2], [0.0; 3], 64.0).is_empty());
    }
}
