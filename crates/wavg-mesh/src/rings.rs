//! Rings around a vertex: the vertices a given number of edges away, found breadth first.

use std::collections::VecDeque;

use crate::{Topology, VertexId};

/// Breadth-first search for the vertices `k` edges away from a vertex (its `k`-th ring),
/// with buffers reused from one search to the next (marks are stamped per search, never
/// cleared), so many searches on a large mesh cost only the vertices they visit.
///
/// ```
/// use wavg_mesh::{RingSearch, ValidMesh, procedural};
/// let m = ValidMesh::new(procedural::icosphere(2)).unwrap();
/// let mut rings = RingSearch::new(m.n_vertices());
/// assert_eq!(rings.ring_or_farthest(m.topology(), 0, 1).len(), m.topology().ring(0).len());
/// assert!(!rings.ring_or_farthest(m.topology(), 0, 3).contains(&0));
/// ```
#[derive(Clone, Debug, Default)]
pub struct RingSearch {
    stamp: Vec<u32>,
    depth: Vec<u32>,
    round: u32,
    queue: VecDeque<VertexId>,
    found: Vec<VertexId>,
}

impl RingSearch {
    /// Buffers for a mesh of `n_vertices` vertices.
    pub fn new(n_vertices: usize) -> Self {
        Self {
            stamp: vec![0; n_vertices],
            depth: vec![0; n_vertices],
            ..Self::default()
        }
    }

    /// The vertices exactly `k` edges from `from`, in breadth-first order; when its
    /// connected component has none that far, the one vertex first reached at the greatest
    /// distance (`from` itself for an isolated vertex or `k == 0`).
    pub fn ring_or_farthest(&mut self, topo: &Topology, from: VertexId, k: usize) -> &[VertexId] {
        let k = u32::try_from(k).unwrap_or(u32::MAX);
        if self.stamp.len() < topo.n_vertices() {
            self.stamp.resize(topo.n_vertices(), 0);
            self.depth.resize(topo.n_vertices(), 0);
        }
        self.round = self.round.wrapping_add(1);
        if self.round == 0 {
            self.stamp.fill(0);
            self.round = 1;
        }
        self.queue.clear();
        self.found.clear();
        let mut farthest = (0u32, from);
        self.stamp[from as usize] = self.round;
        self.depth[from as usize] = 0;
        self.queue.push_back(from);
        while let Some(v) = self.queue.pop_front() {
            let d = self.depth[v as usize];
            if d == k {
                self.found.push(v);
                continue;
            }
            if d > farthest.0 {
                farthest = (d, v);
            }
            for &u in topo.ring(v) {
                if self.stamp[u as usize] != self.round {
                    self.stamp[u as usize] = self.round;
                    self.depth[u as usize] = d + 1;
                    self.queue.push_back(u);
                }
            }
        }
        if self.found.is_empty() {
            self.found.push(farthest.1);
        }
        &self.found
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::{ValidMesh, procedural};

    #[test]
    fn rings_are_at_their_distance_and_small_components_give_the_farthest_vertex() {
        let m = ValidMesh::new(procedural::icosphere(2)).unwrap();
        let topo = m.topology();
        let mut rings = RingSearch::new(m.n_vertices());
        let one: Vec<_> = rings.ring_or_farthest(topo, 5, 1).to_vec();
        let mut expected = topo.ring(5).to_vec();
        let mut got = one.clone();
        expected.sort_unstable();
        got.sort_unstable();
        assert_eq!(got, expected);
        let two = rings.ring_or_farthest(topo, 5, 2).to_vec();
        assert!(two.iter().all(|v| *v != 5 && !one.contains(v)));
        assert!(
            two.iter()
                .all(|v| topo.ring(*v).iter().any(|u| one.contains(u)))
        );
        // Farther than the mesh reaches: one farthest vertex.
        let far = rings.ring_or_farthest(topo, 5, 1000);
        assert_eq!(far.len(), 1);
        assert_eq!(rings.ring_or_farthest(topo, 5, 0), &[5]);
    }
}
