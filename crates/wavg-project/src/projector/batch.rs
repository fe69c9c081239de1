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
        let mut ends = [0 as VertexId; WALK_GROUP];
        for group in order.chunks(WALK_GROUP) {
            let m = group.len();
            for (k, &(_, i)) in group.iter().enumerate() {
                (yc[k], sc[k]) = (ys[i as usize], starts[i as usize]);
            }
            let (yc, sc, ends) = (&yc[..m], &sc[..m], &mut ends[..m]);
            let valid = yc.iter().all(|y| y.iter().all(|v| v.is_finite()))
                && sc.iter().all(|&s| (s as usize) < self.verts.len());
            if !valid {
                // The per-query path reports each error.
                out.extend((0..m).map(|k| self.project(&yc[k], sc[k])));
                continue;
            }
            self.walk_group(yc, sc, ends);
            // Every candidate order first (each requests its first face's data), then the
            // solves, so those requests overlap.
            let cands: [FaceOrder; WALK_GROUP] = std::array::from_fn(|k| {
                if k < m {
                    self.order_faces(&yc[k], ends[k], &self.ring_dists(&yc[k], ends[k]))
                } else {
                    FaceOrder::EMPTY
                }
            });
            out.extend(
                (0..m).map(|k| self.search_from(&yc[k], ends[k], &cands[k], SearchGoal::Closest)),
            );
        }
        out
    }
}
