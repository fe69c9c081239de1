//! The vertex nearest to a point of R^8 (branch and bound over the hierarchy).

use super::*;

impl Projector {
    /// Vertex closest to `y` in R^8 (ties to the lowest index), by branch and bound over
    /// the faces' bounding boxes: every vertex is a corner of some face, and a box's
    /// distance bounds its corners'. 0 for a query that is not finite.
    ///
    /// ```
    /// use std::sync::Arc;
    /// use wavg_mesh::{ValidMesh, procedural};
    /// use wavg_project::{EmbeddedMesh, Projector};
    /// let m = Arc::new(ValidMesh::new(procedural::icosphere(3)).unwrap());
    /// let emb = Arc::new(EmbeddedMesh::from_positions(m));
    /// let p = Projector::new(emb.clone()).unwrap();
    /// let y = emb.coords()[17] * 1.5;
    /// assert_eq!(p.nearest_vertex(&y), 17);
    /// ```
    pub fn nearest_vertex(&self, y: &Vec8) -> VertexId {
        if !y.iter().all(|v| v.is_finite()) {
            return 0;
        }
        self.nearest_vertex_within(y, f64::INFINITY).unwrap_or(0)
    }

    /// [`Projector::nearest_vertex`] (the same vertex, ties to the lowest index) for a
    /// finite `y`, found by a greedy descent in f64 from vertex `v` first and a branch and
    /// bound within the distance it reached. Unbounded, the search opens thousands of boxes
    /// around a query far off a large mesh (70 mean edges off rocker-arm level 5, 10.3M
    /// vertices: 447 us on average); the walk's 16-bit coordinates stop it a few edges
    /// short of the minimum there, which the descent covers.
    pub(super) fn nearest_vertex_from(&self, y: &Vec8, v: VertexId) -> VertexId {
        let d2v = (self.verts[v as usize].x - y).norm_squared();
        let (u, d2u) = self.descend(y, v, d2v);
        // The next float up keeps every vertex at exactly `u`'s distance.
        self.nearest_vertex_within(y, f64::from_bits(d2u.to_bits() + 1))
            .unwrap_or(u)
    }

    /// Greedy descent in f64 over the vertex graph from `v` (squared distance `d2v` to
    /// `y`): moves to the neighbour closest to `y` while one is strictly closer; the last
    /// vertex and its squared distance.
    pub(super) fn descend(&self, y: &Vec8, mut v: VertexId, mut d2v: f64) -> (VertexId, f64) {
        let topo = self.emb.mesh().topology();
        loop {
            let mut next = v;
            for &u in self.walk_coords[v as usize].ring(topo, v) {
                let d = (self.verts[u as usize].x - y).norm_squared();
                if d < d2v {
                    (next, d2v) = (u, d);
                }
            }
            if next == v {
                return (v, d2v);
            }
            v = next;
        }
    }

    /// The vertex closest to `y` (ties to the lowest index) if one is strictly closer
    /// than `sqrt(within2)`: a small radius keeps the branch and bound to a few boxes.
    pub(super) fn nearest_vertex_within(&self, y: &Vec8, within2: f64) -> Option<VertexId> {
        let mut best = (within2, NONE);
        let mut bound = within2;
        // A leaf's faces are requested, then all their corners, before any is read: the
        // search is a chain of cold reads otherwise (a query 70 mean edges off a 10.3M
        // vertex mesh opens about 3,400 faces).
        self.bvh.search_leaves(
            y,
            &mut bound,
            |_, _, _| true,
            |leaf, bound| {
                for &f in leaf {
                    prefetch_line(&self.faces[f as usize].v);
                }
                for &f in leaf {
                    for v in self.faces[f as usize].v {
                        prefetch_line(&self.verts[v as usize].x);
                    }
                }
                for &f in leaf {
                    for v in self.faces[f as usize].v {
                        let d = (self.verts[v as usize].x - y).norm_squared();
                        if d < best.0 || (d == best.0 && best.1 != NONE && v < best.1) {
                            best = (d, v);
                            // Keep boxes at exactly this distance: they may hold a lower index.
                            *bound = f64::from_bits(d.to_bits() + 1); // the next float up (d >= 0)
                        }
                    }
                }
            },
        );
        (best.1 != NONE).then_some(best.1)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use wavg_mesh::{ValidMesh, procedural};

    /// The unbounded search finds the nearest vertex (brute force), and from any start the
    /// descent and the bounded search find it too; queries on, near and far off a mesh
    /// (scale 0: the centre, about equally far from every vertex).
    #[test]
    fn the_nearest_vertex_from_any_start_is_the_nearest_vertex() {
        let m = Arc::new(ValidMesh::new(procedural::icosphere(4)).unwrap());
        let emb = Arc::new(EmbeddedMesh::from_positions(m.clone()));
        let p = Projector::new(emb.clone()).unwrap();
        let n = m.n_vertices() as u32;
        let mut moved = 0;
        for (k, scale) in [0.0, 0.3, 0.9, 1.0, 1.02, 3.0].into_iter().enumerate() {
            for q in (0..n).step_by(37) {
                let y = emb.coords()[q as usize] * scale;
                let best = p.nearest_vertex(&y);
                // Brute force over every vertex (ties to the lowest index).
                let d2 = |v: usize| (emb.coords()[v] - y).norm_squared();
                let brute = (0..n as usize)
                    .min_by(|&a, &b| d2(a).total_cmp(&d2(b)))
                    .unwrap();
                assert_eq!(best as usize, brute, "scale {scale} query {q}");
                for v in [0, q, (q * 7 + k as u32 * 13) % n, best] {
                    assert_eq!(
                        p.nearest_vertex_from(&y, v),
                        best,
                        "scale {scale} query {q} start {v}"
                    );
                    moved += usize::from(v != best);
                }
            }
        }
        assert!(moved > 300, "{moved}");
    }
}
