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

    /// The vertex closest to `y` (ties to the lowest index) if one is strictly closer
    /// than `sqrt(within2)`: a small radius keeps the branch and bound to a few boxes.
    pub(super) fn nearest_vertex_within(&self, y: &Vec8, within2: f64) -> Option<VertexId> {
        let mut best = (within2, NONE);
        let mut bound = within2;
        self.bvh.search(y, &mut bound, |f, bound| {
            for v in self.faces[f as usize].v {
                let d = (self.verts[v as usize].x - y).norm_squared();
                if d < best.0 || (d == best.0 && best.1 != NONE && v < best.1) {
                    best = (d, v);
                    // Keep boxes at exactly this distance: they may hold a lower index.
                    *bound = f64::from_bits(d.to_bits() + 1); // the next float up (d >= 0)
                }
            }
        });
        (best.1 != NONE).then_some(best.1)
    }
}
