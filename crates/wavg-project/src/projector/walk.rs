//! The greedy walk over the vertex graph in compact 16-bit coordinates, one query at a
//! time or several interleaved (so their memory accesses overlap).

use super::*;

/// Queries whose walks [`Projector::project_batch`] interleaves.
pub const WALK_GROUP: usize = 8;

impl Projector {
    /// Interleaved greedy walks (up to [`WALK_GROUP`]); `starts` must be in range.
    pub(super) fn walk_group(&self, ys: &[Vec8], starts: &[VertexId], ends: &mut [VertexId]) {
        let topo = self.emb.mesh().topology();
        let w = &self.walk_coords;
        let m = ends.len();
        let mut yw = [[0.0f32; 8]; WALK_GROUP];
        let mut dv = [0.0f32; WALK_GROUP];
        let mut active = [false; WALK_GROUP];
        for q in 0..m {
            yw[q] = self.walk_point(&ys[q]);
            ends[q] = starts[q];
            dv[q] = w[starts[q] as usize].dist2(&yw[q]);
            active[q] = true;
            for &u in w[starts[q] as usize].ring(topo, starts[q]) {
                prefetch_line(&w[u as usize]);
            }
        }
        let mut left = m;
        while left > 0 {
            for q in 0..m {
                if !active[q] {
                    continue;
                }
                // One step of `walk_inner`, in the same order (so the same path).
                let v = ends[q];
                let mut next = v;
                for &u in w[v as usize].ring(topo, v) {
                    let d = w[u as usize].dist2(&yw[q]);
                    if d < dv[q] {
                        dv[q] = d;
                        next = u;
                    }
                }
                if next == v {
                    active[q] = false;
                    left -= 1;
                    continue;
                }
                ends[q] = next;
                // The next step reads these; the other walks' steps hide the wait.
                for &u in w[next as usize].ring(topo, next) {
                    prefetch_line(&w[u as usize]);
                }
            }
        }
    }

    /// Greedy walk over the vertex graph from `start`: moves to the neighbour closest to
    /// `y` until no neighbour is closer; returns that vertex (a local minimum of the
    /// distance to `y`, a good start for the next query near `y`).
    pub fn walk(&self, y: &Vec8, start: VertexId) -> VertexId {
        let mut ring_d = [0.0f32; 64];
        self.walk_inner(y, start.min(self.verts.len() as u32 - 1), &mut ring_d)
    }

    /// The query in the walk's compact coordinates.
    #[inline]
    pub(super) fn walk_point(&self, y: &Vec8) -> [f32; 8] {
        std::array::from_fn(|k| ((y[k] - self.walk_origin[k]) * self.walk_inv_step) as f32)
    }

    /// The walk; leaves the squared distances of the final vertex's ring in `ring_d`.
    #[inline]
    pub(super) fn walk_inner(&self, y: &Vec8, start: VertexId, ring_d: &mut [f32; 64]) -> VertexId {
        let topo = self.emb.mesh().topology();
        let w = &self.walk_coords;
        let yw = self.walk_point(y);
        let mut v = start;
        let mut dv = w[v as usize].dist2(&yw);
        loop {
            let mut next = v;
            for (j, &u) in w[v as usize].ring(topo, v).iter().enumerate() {
                let d = w[u as usize].dist2(&yw);
                if j < 64 {
                    ring_d[j] = d;
                }
                if d < dv {
                    dv = d;
                    next = u;
                }
            }
            if next == v {
                return v;
            }
            v = next;
            // If `v` ends the walk, its faces and their corners come next: start loading
            // them while its neighbours are checked (measured 2-4% per query).
            let r = &w[v as usize];
            for &f in r.faces(topo, v) {
                prefetch(&self.faces[f as usize]);
            }
            prefetch(&self.verts[v as usize]);
            for &u in r.ring(topo, v) {
                prefetch(&self.verts[u as usize]);
            }
        }
    }
}
