//! Ordering: Morton keys that sort a batch so nearby queries run together, and the order
//! in which the faces around the walk's end are tried (most promising first).

use super::layout::wdot;
use super::*;

/// Faces around a vertex, most promising for a query first (from
/// `internal::faces_by_promise`).
#[derive(Clone, Copy, Debug)]
pub struct FaceOrder {
    pub(super) faces: [FaceId; 64],
    pub(super) n: usize,
    /// How far outside the first face the Euclidean projection of the query onto its
    /// plane falls (negative inside; infinite when not computed).
    pub(super) first_outside: f32,
}

impl FaceOrder {
    pub(super) const EMPTY: Self = Self {
        faces: [0; 64],
        n: 0,
        first_outside: f32::INFINITY,
    };

    /// The faces, most promising first.
    pub fn as_slice(&self) -> &[FaceId] {
        &self.faces[..self.n]
    }
}

impl Projector {
    /// A 30-bit Morton code of the first three walk coordinates of `y` (10 bits each;
    /// anything outside the bounding box, or not finite, clamps to its faces): sorting
    /// queries by it puts nearby ones together, so their searches share cached data.
    ///
    /// ```
    /// use std::sync::Arc;
    /// use wavg_mesh::{ValidMesh, procedural};
    /// use wavg_project::{EmbeddedMesh, Projector};
    /// let m = Arc::new(ValidMesh::new(procedural::icosphere(2)).unwrap());
    /// let emb = Arc::new(EmbeddedMesh::from_positions(m));
    /// let p = Projector::new(emb.clone()).unwrap();
    /// let y = emb.coords()[0];
    /// use wavg_project::internal::locality_key;
    /// assert_eq!(locality_key(&p, &y), locality_key(&p, &(y * (1.0 + 1e-12))));
    /// assert!(locality_key(&p, &y) < 1 << 30);
    /// ```
    pub(crate) fn locality_key(&self, y: &Vec8) -> u32 {
        let w = self.walk_point(y);
        let spread = |c: f32| {
            // `as` saturates (NaN to 0): a coordinate in 0..=1023.
            let mut x = ((c as u32).min(65535) >> 6) & 0x3ff;
            x = (x | (x << 16)) & 0x0300_00ff;
            x = (x | (x << 8)) & 0x0300_f00f;
            x = (x | (x << 4)) & 0x030c_30c3;
            (x | (x << 2)) & 0x0924_9249
        };
        spread(w[0]) | (spread(w[1]) << 1) | (spread(w[2]) << 2)
    }

    /// Squared walk distances from `y` to `v`'s neighbours, as `walk_inner` leaves them
    /// (only rings over 64 use them, see [`Projector::order_faces`]).
    pub(super) fn ring_dists(&self, y: &Vec8, v: VertexId) -> [f32; 64] {
        let mut d = [f32::INFINITY; 64];
        let ring = self.walk_coords[v as usize].ring(self.emb.mesh().topology(), v);
        if ring.len() > 64 {
            let yw = self.walk_point(y);
            for (j, &u) in ring.iter().take(64).enumerate() {
                d[j] = self.walk_coords[u as usize].dist2(&yw);
            }
        }
        d
    }

    /// The faces around vertex `v` (at most 64), most promising first for a projection of
    /// `y`: by how far inside each face's plane the orthogonal projection of `y` falls
    /// (walk coordinates, in cache right after a walk ending at `v`). Starts loading the
    /// first face's data. The order is a heuristic; it never changes which answers exist.
    ///
    /// ```
    /// use std::sync::Arc;
    /// use wavg_mesh::{SurfacePoint, ValidMesh, procedural};
    /// use wavg_project::{EmbeddedMesh, Projector};
    /// let m = Arc::new(ValidMesh::new(procedural::icosphere(2)).unwrap());
    /// let emb = Arc::new(EmbeddedMesh::from_positions(m.clone()));
    /// let p = Projector::new(emb.clone()).unwrap();
    /// let f = m.topology().ring_faces(5)[2];
    /// let y = emb.point(&SurfacePoint::new(f, [0.4, 0.3, 0.3]));
    /// let order = wavg_project::internal::faces_by_promise(&p, &y, 5);
    /// assert_eq!(order.as_slice()[0], f);
    /// ```
    pub(crate) fn faces_by_promise(&self, y: &Vec8, v: VertexId) -> FaceOrder {
        self.order_faces(y, v, &[f32::INFINITY; 64])
    }

    /// [`Projector::faces_by_promise`]; `ring_d` (squared walk distances of `v`'s
    /// neighbours) orders the faces of rings too long for the exact score.
    pub(super) fn order_faces(&self, y: &Vec8, v: VertexId, ring_d: &[f32; 64]) -> FaceOrder {
        let topo = self.emb.mesh().topology();
        let ring = self.walk_coords[v as usize].ring(topo, v);
        let faces = self.walk_coords[v as usize].faces(topo, v);
        let mut scores = [f32::INFINITY; 64];
        if ring.len() <= 64 {
            let yw = self.walk_point(y);
            let wv = self.walk_coords[v as usize].unpack();
            let mut dy = [0.0f32; 8];
            for k in 0..8 {
                dy[k] = yw[k] - wv[k];
            }
            // Per neighbour j: |e_j|^2, e_j . (y - v) and e_j . e_{j+1}, e_j = u_j - v.
            let mut ee = [0.0f32; 64];
            let mut de = [0.0f32; 64];
            let mut ee1 = [0.0f32; 64];
            let edge = |u: u32| {
                let wu = self.walk_coords[u as usize].unpack();
                let mut d = [0.0f32; 8];
                for k in 0..8 {
                    d[k] = wu[k] - wv[k];
                }
                d
            };
            let first = edge(ring[0]);
            let mut cur = first;
            for j in 0..ring.len() {
                let next = if j + 1 < ring.len() {
                    edge(ring[j + 1])
                } else {
                    first
                };
                ee[j] = wdot(&cur, &cur);
                de[j] = wdot(&cur, &dy);
                ee1[j] = wdot(&cur, &next);
                cur = next;
            }
            // Face j lies between ring[j] and ring[j + 1] (cyclically when interior).
            for j in 0..ring.len() {
                let l = if j + 1 == ring.len() { 0 } else { j + 1 };
                let ab = ee1[j];
                let det = ee[j] * ee[l] - ab * ab;
                if det > 0.0 {
                    let s = (ee[l] * de[j] - ab * de[l]) / det;
                    let t = (ee[j] * de[l] - ab * de[j]) / det;
                    let score = -(s.min(t).min(1.0 - s - t));
                    if !score.is_nan() {
                        scores[j] = score;
                    }
                }
            }
        } else {
            for j in 0..64 {
                scores[j] = ring_d[j] + ring_d[(j + 1) % 64];
            }
        }
        let m = faces.len().min(64);
        let mut order = [(0.0f32, 0u32); 64];
        for j in 0..m {
            order[j] = (scores[j], faces[j]);
        }
        // Ties (and unscored faces) by id, so the order never depends on the sort.
        order[..m].sort_unstable_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)));
        if m > 0 {
            // The first candidate nearly always holds the answer: request its record and
            // its corners' records together rather than one after the other.
            let f = order[0].1;
            self.prefetch_face(f, v, ring, faces);
        }
        FaceOrder {
            faces: std::array::from_fn(|j| order[j].1),
            n: m,
            // Scores are outside measures only for rings of up to 64 vertices.
            first_outside: if m > 0 && ring.len() <= 64 {
                order[0].0
            } else {
                f32::INFINITY
            },
        }
    }

    /// Starts loading face `f` (around `v`) and its three corners' records. The corners
    /// are `v` and the two ring neighbours beside `f`, known without reading the face.
    #[inline(always)]
    pub(super) fn prefetch_face(&self, f: FaceId, v: VertexId, ring: &[u32], faces: &[u32]) {
        let Some(j) = faces.iter().position(|&g| g == f) else {
            return;
        };
        let next = if j + 1 < ring.len() { j + 1 } else { 0 };
        prefetch(&self.faces[f as usize]);
        for u in [v, ring[j], ring[next]] {
            prefetch(&self.verts[u as usize]);
        }
    }
}
