//! The greedy walk over the vertex graph in compact 16-bit coordinates, ended by a descent
//! in f64 where their rounding may have stopped it short, one query at a time or several
//! interleaved (so their memory accesses overlap).

use super::*;

/// Queries whose walks [`Projector::project_batch`] and the solver's forward batches
/// interleave (rocker-arm level 5, 10.3M vertices, and igea: 4-5% less time a forward
/// query than 8; 4 and 12 in between).
pub const WALK_GROUP: usize = 16;

impl Projector {
    /// Interleaved greedy walks (up to [`WALK_GROUP`]), each ended by its descent in f64
    /// (see [`Projector::finish_walk`]), interleaved too; `starts` must be in range.
    pub(super) fn walk_group(&self, ys: &[Vec8], starts: &[VertexId], ends: &mut [VertexId]) {
        let topo = self.emb.mesh().topology();
        let w = &self.walk_coords;
        let m = ends.len();
        let mut yw = [[0.0f32; 8]; WALK_GROUP];
        let mut dv = [0.0f32; WALK_GROUP];
        // The squared distance in f64 once a walk descends in f64 (NaN before).
        let mut d64 = [f64::NAN; WALK_GROUP];
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
                let v = ends[q];
                let mut next = v;
                if d64[q].is_nan() {
                    // One step of `walk_inner`, in the same order (so the same path).
                    for &u in w[v as usize].ring(topo, v) {
                        let d = w[u as usize].dist2(&yw[q]);
                        if d < dv[q] {
                            dv[q] = d;
                            next = u;
                        }
                    }
                    if next == v {
                        // The descent's first step reads these (only their points: the
                        // face order requests the frames it needs).
                        d64[q] = (self.verts[v as usize].x - ys[q]).norm_squared();
                        for &u in w[v as usize].ring(topo, v) {
                            prefetch_line(&self.verts[u as usize]);
                        }
                        continue;
                    }
                } else {
                    // One step of `descend`, in the same order.
                    for &u in w[v as usize].ring(topo, v) {
                        let d = (self.verts[u as usize].x - ys[q]).norm_squared();
                        if d < d64[q] {
                            (next, d64[q]) = (u, d);
                        }
                    }
                    if next == v {
                        active[q] = false;
                        left -= 1;
                        continue;
                    }
                    for &u in w[next as usize].ring(topo, next) {
                        prefetch_line(&self.verts[u as usize]);
                    }
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
    /// `y` until no neighbour is closer, in compact coordinates and then in f64 (where
    /// their rounding may have stopped it short); returns that vertex (a local minimum of
    /// the distance to `y`, a good start for the next query near `y`).
    pub fn walk(&self, y: &Vec8, start: VertexId) -> VertexId {
        let mut ring_d = [0.0f32; 64];
        self.walk_inner(y, start.min(self.verts.len() as u32 - 1), &mut ring_d)
    }

    /// The query in the walk's compact coordinates.
    #[inline]
    pub(super) fn walk_point(&self, y: &Vec8) -> [f32; 8] {
        std::array::from_fn(|k| ((y[k] - self.walk_origin[k]) * self.walk_inv_step) as f32)
    }

    /// The end of the walk from `v`, where the compact coordinates see no closer
    /// neighbour: a greedy descent in f64 from there. Far off a large mesh the distance is
    /// nearly flat over many edges and the compact coordinates' rounding stops the walk
    /// short of its minimum, where the local search then finds nothing; at the minimum
    /// (most walks) this checks one ring whose records the last step requested.
    #[inline]
    pub(super) fn finish_walk(&self, y: &Vec8, v: VertexId) -> VertexId {
        let d2v = (self.verts[v as usize].x - y).norm_squared();
        self.descend(y, v, d2v).0
    }

    /// The walk; leaves the squared distances of the final vertex's ring in `ring_d`
    /// (walk units; only those of rings over 64 when the descent in f64 moved it).
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
                let n = w[v as usize].ring(topo, v).len();
                if n <= 64 && clear_of_rounding(&ring_d[..n], dv, &yw) {
                    return v;
                }
                let u = self.finish_walk(y, v);
                if u != v {
                    *ring_d = self.ring_dists(y, u);
                }
                return u;
            }
            v = next;
            let r = &w[v as usize];
            // The next step reads these: requested before the loads below, which would
            // otherwise hold the memory requests' slots ahead of them (on a mesh far
            // larger than the cache, 5% of a projection at 10M vertices).
            for &u in r.ring(topo, v) {
                prefetch_line(&w[u as usize]);
            }
            // If `v` ends the walk, its faces and their corners come next: start loading
            // them while its neighbours are checked (measured 2-4% per query).
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

/// Whether every neighbour (squared walk distances `ring` to the walk point `yw`) lies
/// farther than the walk's end (`dv`) by more than the compact coordinates' rounding can
/// explain, so that none is closer in f64 and the descent would not move. A vertex's
/// rounding moves it at most sqrt(2) walk units (8 coordinates, 0.5 each) and the query's
/// conversion to f32 at most 2^-24 of its norm; the f32 sums add a relative error well
/// below 1e-5 of a distance.
#[inline]
fn clear_of_rounding(ring: &[f32], dv: f32, yw: &[f32; 8]) -> bool {
    let sv = dv.sqrt();
    let m = 2.0 * (std::f32::consts::SQRT_2 + super::layout::wdot(yw, yw).sqrt() * 6e-8);
    ring.iter().all(|&d| {
        let s = d.sqrt();
        s - sv > m + 1e-5 * s
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use wavg_mesh::{ValidMesh, procedural};

    /// Far off a long, slightly noisy strip (2,000 edges along its walk grid's 65,535
    /// steps, queries 50 to 800 edges above it) the compact coordinates' rounding outweighs the distance's
    /// differences between neighbours: the walk, alone or interleaved, still ends where a
    /// walk in f64 ends, at a vertex no neighbour of which is closer in f64.
    #[test]
    fn far_off_a_fine_mesh_the_walk_ends_at_a_minimum_in_f64() {
        let strip = procedural::with_noise(procedural::grid(2000, 2, 2000.0, 2.0), 0.05, 3);
        let m = Arc::new(ValidMesh::new(strip).unwrap());
        let emb = Arc::new(EmbeddedMesh::from_positions(m.clone()));
        let p = Projector::new(emb.clone()).unwrap();
        let topo = m.topology();
        let d2 = |v: VertexId, y: &Vec8| (emb.coords()[v as usize] - y).norm_squared();
        let (mut ys, mut starts) = (Vec::new(), Vec::new());
        for (k, h) in [50.0, 100.0, 200.0, 400.0, 800.0].into_iter().enumerate() {
            for i in 0..40 {
                let mut y = Vec8::zeros();
                (y[0], y[1], y[2]) = (37.3 + 48.9 * i as f64, 0.7, h);
                ys.push(y);
                starts.push(((i * 131 + k * 17) % 2001) as VertexId);
            }
        }
        let mut ends = vec![0; ys.len()];
        for (g, (ys, starts)) in ys
            .chunks(WALK_GROUP)
            .zip(starts.chunks(WALK_GROUP))
            .enumerate()
        {
            p.walk_group(ys, starts, &mut ends[g * WALK_GROUP..][..ys.len()]);
        }
        let mut far = 0;
        for ((y, &s), &e) in ys.iter().zip(&starts).zip(&ends) {
            let v = p.walk(y, s);
            assert_eq!(v, e, "the interleaved walk ends where the walk does");
            for &u in topo.ring(v) {
                assert!(d2(u, y) >= d2(v, y), "query {y:?}: {u} is closer than {v}");
            }
            far += usize::from(v.abs_diff(s) > 100);
        }
        assert!(far > 100, "{far} walks went far");
    }
}
