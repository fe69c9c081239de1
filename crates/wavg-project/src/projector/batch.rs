//! Batches of projections: queries sorted in Morton order so nearby ones run together,
//! their greedy walks interleaved in groups, chunks of the sorted queries in parallel.

use super::*;
use crate::Par;

/// Sorted queries one parallel task projects.
const CHUNK: usize = 1024;

/// Buffers of [`Projector::project_batch_into`], reused from batch to batch.
#[derive(Debug, Default)]
pub struct ProjectScratch {
    order: Vec<(u32, u32)>,
    done: Vec<Result<Projection, ProjectError>>,
}

impl Projector {
    /// [`Projector::project`] for many queries in parallel, with the same results (in
    /// input order). See [`Projector::project_batch_into`].
    ///
    /// ```
    /// use std::sync::Arc;
    /// use wavg_mesh::{SurfacePoint, ValidMesh, procedural};
    /// use wavg_project::{EmbeddedMesh, Projector};
    /// let m = Arc::new(ValidMesh::new(procedural::icosphere(3)).unwrap());
    /// let emb = Arc::new(EmbeddedMesh::from_positions(m));
    /// let p = Projector::new(emb.clone()).unwrap();
    /// let ys: Vec<_> = (0..20).map(|f| emb.point(&SurfacePoint::new(f * 30, [0.2, 0.3, 0.5]))).collect();
    /// let starts = vec![0; ys.len()];
    /// let batch = p.project_batch(&ys, &starts);
    /// for ((y, s), b) in ys.iter().zip(&starts).zip(&batch) {
    ///     assert_eq!(b, &p.project(y, *s));
    /// }
    /// ```
    pub fn project_batch(
        &self,
        ys: &[Vec8],
        starts: &[VertexId],
    ) -> Vec<Result<Projection, ProjectError>> {
        let mut out = Vec::new();
        let mut scratch = ProjectScratch::default();
        // `Par::Rayon` always starts.
        let _ = self.project_batch_into(ys, starts, &mut scratch, &mut out, Par::Rayon);
        out
    }

    /// [`Projector::project`] for the first `min(ys.len(), starts.len())` queries into
    /// `out` (in input order), with explicit buffers and parallelism; the results do not
    /// depend on `par`. Queries are visited in Morton order of their first three embedded
    /// coordinates, so nearby ones share cached data (this alone halves the certification
    /// cost of off-surface queries), and the greedy walks of [`WALK_GROUP`] queries advance
    /// in turn, each step requesting the records the next step reads, so their memory
    /// waits overlap instead of adding up; then the first candidate face of every query in
    /// the group is requested before any is solved. Fails only when `par`'s threads cannot
    /// start.
    pub fn project_batch_into(
        &self,
        ys: &[Vec8],
        starts: &[VertexId],
        scratch: &mut ProjectScratch,
        out: &mut Vec<Result<Projection, ProjectError>>,
        par: Par,
    ) -> Result<(), ProjectError> {
        let n = ys.len().min(starts.len());
        let ProjectScratch { order, done } = scratch;
        order.clear();
        order.extend((0..n).map(|i| (self.locality_key(&ys[i]), i as u32)));
        par.sort(order)?;
        done.clear();
        par.map_chunks(order, CHUNK, done, |c| self.project_chunk(ys, starts, c))?;
        out.clear();
        out.resize(n, Err(ProjectError::NoProjection));
        for (&(_, i), r) in order.iter().zip(done.drain(..)) {
            out[i as usize] = r;
        }
        Ok(())
    }

    /// The queries `order` names (sorted), in that order, on the calling thread.
    fn project_chunk(
        &self,
        ys: &[Vec8],
        starts: &[VertexId],
        order: &[(u32, u32)],
    ) -> Vec<Result<Projection, ProjectError>> {
        let mut out = Vec::with_capacity(order.len());
        // Per group, fixed-size buffers (no allocation per group).
        let mut yc = [Vec8::zeros(); WALK_GROUP];
        let mut sc = [0 as VertexId; WALK_GROUP];
        for group in order.chunks(WALK_GROUP) {
            let m = group.len();
            for (k, &(_, i)) in group.iter().enumerate() {
                (yc[k], sc[k]) = (ys[i as usize], starts[i as usize]);
            }
            self.project_group(&yc[..m], &mut sc[..m], false, SearchGoal::Closest, &mut out);
        }
        out
    }

    /// [`Projector::project_with`] without a hint for up to [`WALK_GROUP`] queries `ys`
    /// from `starts`, their memory waits overlapped: with `locate`, first each start
    /// becomes its [`Projector::start_near`] vertex (in place); then the greedy walks
    /// advance in turn, each step requesting the records the next step reads; then the
    /// first candidate face of every query is requested before any is solved. Pushes the
    /// results to `out`, in order; they and the starts equal the one-query calls'.
    pub(crate) fn project_group(
        &self,
        ys: &[Vec8],
        starts: &mut [VertexId],
        locate: bool,
        goal: SearchGoal,
        out: &mut Vec<Result<Projection, ProjectError>>,
    ) {
        let m = ys.len().min(starts.len()).min(WALK_GROUP);
        let (ys, starts) = (&ys[..m], &mut starts[..m]);
        let valid = ys.iter().all(|y| y.iter().all(|v| v.is_finite()))
            && starts.iter().all(|&s| (s as usize) < self.verts.len());
        if !valid {
            // The per-query path reports each error.
            for (y, s) in ys.iter().zip(starts) {
                if locate {
                    *s = self.start_near(y, *s);
                }
                out.push(self.project_with(y, *s, None, goal));
            }
            return;
        }
        if locate {
            self.starts_near_group(ys, starts);
        }
        let mut ends = [0 as VertexId; WALK_GROUP];
        let ends = &mut ends[..m];
        self.walk_group(ys, starts, ends);
        // Every candidate order first (each requests its first face's data), then the
        // solves, so those requests overlap.
        let cands: [FaceOrder; WALK_GROUP] = std::array::from_fn(|k| {
            if k < m {
                self.order_faces(&ys[k], ends[k], &self.ring_dists(&ys[k], ends[k]))
            } else {
                FaceOrder::EMPTY
            }
        });
        out.extend((0..m).map(|k| self.search_from(&ys[k], ends[k], &cands[k], goal)));
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use wavg_mesh::{ValidMesh, procedural};

    /// Groups (full, short, and holding a bad query) give the starts and projections of
    /// [`Projector::start_near`] and [`Projector::project_with`] one query at a time, for
    /// both goals, on a grid capped so that the fine cells take part.
    #[test]
    fn groups_equal_one_query_at_a_time() {
        let m = ValidMesh::new(procedural::with_noise(procedural::icosphere(5), 0.005, 2));
        let emb = Arc::new(EmbeddedMesh::from_positions(Arc::new(m.unwrap())));
        let mut p = Projector::new(emb.clone()).unwrap();
        p.starts = StartGrid::with_max_cells(&p.walk_coords, 4);
        assert!(!p.starts.fine.is_empty());
        let x = emb.coords();
        let n = x.len() as VertexId;
        let mut ys: Vec<Vec8> = (0..61)
            .map(|k| x[(k * 167) % x.len()] * [1.0, 1.08, 0.93, 1.4][k % 4])
            .collect();
        let mut starts: Vec<VertexId> = (0..61).map(|k| (k as VertexId * 7919) % n).collect();
        ys[20][3] = f64::NAN;
        starts[29] = n + 5;
        let (mut moved, mut fine_moved) = (0, 0);
        for goal in [SearchGoal::FirstHit, SearchGoal::Closest] {
            for locate in [true, false] {
                let mut got = Vec::new();
                let mut s = starts.clone();
                for (ys, s) in ys.chunks(WALK_GROUP).zip(s.chunks_mut(WALK_GROUP)) {
                    p.project_group(ys, s, locate, goal, &mut got);
                }
                assert_eq!(got.len(), ys.len());
                for k in 0..ys.len() {
                    let s0 = if locate {
                        p.start_near(&ys[k], starts[k])
                    } else {
                        starts[k]
                    };
                    assert_eq!(s[k], s0, "query {k}: start");
                    assert_eq!(got[k], p.project_with(&ys[k], s0, None, goal), "query {k}");
                    moved += usize::from(s0 != starts[k]);
                    let yw = p.walk_point(&ys[k]);
                    let coarse = p.starts.walk(&yw, &p.walk_coords).0;
                    fine_moved += usize::from(locate && s0 != starts[k] && s0 != coarse);
                }
                assert!(got[20].is_err() && got[29].is_err());
            }
        }
        assert!(
            moved > 40 && fine_moved > 20,
            "{moved} starts moved, {fine_moved} by the fine cells"
        );
    }
}
