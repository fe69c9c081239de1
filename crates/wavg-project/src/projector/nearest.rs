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
        self.nearest_vertex_over(y, within2, usize::MAX).0
    }

    /// [`Projector::nearest_vertex_within`] over at most `leaves` leaves of the
    /// hierarchy: the closest vertex met strictly within `sqrt(within2)` (ties to the
    /// lowest index) and whether the search was complete (then it is the nearest).
    pub(super) fn nearest_vertex_over(
        &self,
        y: &Vec8,
        within2: f64,
        leaves: usize,
    ) -> (Option<VertexId>, bool) {
        let mut best = (within2, NONE);
        let mut bound = within2;
        let mut opened = 0;
        let mut complete = true;
        // A leaf's faces are requested, then all their corners, before any is read: the
        // search is a chain of cold reads otherwise (a query 70 mean edges off a 10.3M
        // vertex mesh opens about 3,400 faces).
        self.bvh.search_leaves(
            y,
            &mut bound,
            |_, _, _| true,
            |leaf, bound| {
                if opened == leaves {
                    // No box lies below a negative bound: the search ends.
                    complete = false;
                    *bound = -1.0;
                    return;
                }
                opened += 1;
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
        ((best.1 != NONE).then_some(best.1), complete)
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

    /// A first-hit search that stops looking for the nearest vertex after a few leaves
    /// answers from the closest vertex met, with a projection (solving on its face again
    /// gives it); unlimited, from the nearest vertex.
    #[test]
    fn first_hits_from_a_vertex_met_early_are_projections() {
        let mut mesh = procedural::icosphere(4);
        for (i, x) in mesh.positions.iter_mut().enumerate() {
            *x *= 1.0 + 0.05 * ((i * 7919 % 13) as f64 / 13.0);
        }
        let m = Arc::new(ValidMesh::new(mesh).unwrap());
        let emb = Arc::new(EmbeddedMesh::from_positions(m.clone()));
        let p = Projector::new(emb.clone()).unwrap();
        let n = m.n_vertices() as u32;
        let (mut early, mut nearest) = (0, 0);
        for q in (0..n).step_by(29) {
            let y = emb.coords()[q as usize] * 1.1;
            // A far vertex as the walk's end: a loose bound, so many leaves to open.
            let far = (q * 7919 + n / 2) % n;
            let full = p.search_from_nearest_over(&y, far, SearchGoal::FirstHit, usize::MAX);
            assert_eq!(full.as_ref().map(|f| f.1), Some(p.nearest_vertex(&y)));
            for leaves in [1, 3, 10] {
                let (b, u, _) = p
                    .search_from_nearest_over(&y, far, SearchGoal::FirstHit, leaves)
                    .expect("a projection");
                let again = p.try_face(b.face, &y).expect("a projection on its face");
                let gap = (0..3)
                    .map(|k| (again.xi[k] - b.xi[k]).abs())
                    .fold(0.0, f64::max);
                assert!(gap < 1e-9, "query {q}, {leaves} leaves: {gap}");
                assert!((again.d2 - b.d2).abs() <= 1e-12 * b.d2.max(1.0));
                match u == full.as_ref().unwrap().1 {
                    true => nearest += 1,
                    false => early += 1,
                }
            }
        }
        assert!(
            early > 10 && nearest > 10,
            "{early} early, {nearest} nearest"
        );
    }
}
