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
    /// How far outside the first face (in barycentric units) the query's orthogonal
    /// projection onto the tangent plane of the vertex falls, the face projected there
    /// too (negative inside; infinite when not computed).
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
    /// `y`: by how far inside each face the orthogonal projection of `y` onto `v`'s
    /// tangent plane falls, the faces projected there too (walk coordinates, in cache
    /// right after a walk ending at `v`). That plane is the one the projection's equations
    /// use at `v`, so far off a fine mesh (where each face's own plane tilts the query's
    /// foot across several faces) the first face still holds the projection: rocker-arm
    /// subdivided five times (10.3M vertices), 89% of first-hit searches against 33% by
    /// the faces' planes. Starts loading the first face's data. The order is a heuristic;
    /// it never changes which answers exist.
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
        let mut out = FaceOrder::EMPTY;
        self.order_faces_into(y, v, ring_d, &mut out);
        out
    }

    /// [`Projector::order_faces`] into `out` (a group's orders stay in place: no copies).
    pub(super) fn order_faces_into(
        &self,
        y: &Vec8,
        v: VertexId,
        ring_d: &[f32; 64],
        out: &mut FaceOrder,
    ) {
        let topo = self.emb.mesh().topology();
        let ring = self.walk_coords[v as usize].ring(topo, v);
        let faces = self.walk_coords[v as usize].faces(topo, v);
        let mut scores = [f32::INFINITY; 64];
        if ring.len() <= 64 {
            // In `v`'s tangent plane (its frame, the one Newton's method interpolates at
            // that corner): `y - v` and the edges `u_j - v`, each as two coordinates.
            let yw = self.walk_point(y);
            let wv = self.walk_coords[v as usize].unpack();
            let (t0, t1) = self.verts[v as usize].tangents();
            let in_plane = |p: &[f32; 8]| {
                let d: [f32; 8] = std::array::from_fn(|k| p[k] - wv[k]);
                [wdot(t0, &d), wdot(t1, &d)]
            };
            let q = in_plane(&yw);
            let mut e = [[0.0f32; 2]; 64];
            for (j, &u) in ring.iter().enumerate() {
                e[j] = in_plane(&self.walk_coords[u as usize].unpack());
            }
            // Face j lies between ring[j] and ring[j + 1] (cyclically when interior): `q`
            // in the coordinates of its two edges from `v` (either orientation).
            for j in 0..ring.len() {
                let l = if j + 1 == ring.len() { 0 } else { j + 1 };
                let (a, b) = (e[j], e[l]);
                let det = a[0] * b[1] - a[1] * b[0];
                if det != 0.0 {
                    let s = (q[0] * b[1] - q[1] * b[0]) / det;
                    let t = (a[0] * q[1] - a[1] * q[0]) / det;
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
        for (f, o) in out.faces.iter_mut().zip(&order[..m]) {
            *f = o.1;
        }
        out.n = m;
        // Scores are outside measures only for rings of up to 64 vertices.
        out.first_outside = if m > 0 && ring.len() <= 64 {
            order[0].0
        } else {
            f32::INFINITY
        };
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
