//! Batches of projections: queries sorted in Morton order so nearby ones run together,
//! their greedy walks interleaved in groups, chunks of the sorted queries in parallel.

use super::search::{Exit, FaceSet};
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
        let mut cands = [FaceOrder::EMPTY; WALK_GROUP];
        for k in 0..m {
            let ring_d = self.ring_dists(&ys[k], ends[k]);
            self.order_faces_into(&ys[k], ends[k], &ring_d, &mut cands[k]);
        }
        if goal == SearchGoal::FirstHit {
            self.first_hits_group(ys, ends, &cands[..m], out);
        } else {
            out.extend((0..m).map(|k| self.search_from(&ys[k], ends[k], &cands[k], goal)));
        }
    }

    /// The first-hit searches of a group from the walks' ends `ends` (candidates
    /// `cands`): the walks over faces from each query's first candidate (Newton's exits)
    /// advance in turn, each step requesting what the query's next step reads (a face's
    /// record, then its corners'), so the queries' waits overlap; a search whose walk
    /// ends without a projection goes on alone where [`Projector::search_from`] would.
    fn first_hits_group(
        &self,
        ys: &[Vec8],
        ends: &[VertexId],
        cands: &[FaceOrder],
        out: &mut Vec<Result<Projection, ProjectError>>,
    ) {
        let m = cands.len();
        let adjacency = self.emb.mesh().topology().adjacency();
        let mut tried: [FaceSet; WALK_GROUP] = std::array::from_fn(|_| FaceSet::new());
        let mut found: [Option<Best>; WALK_GROUP] = [None; WALK_GROUP];
        // The face each walk tries next (NONE once it is over), and whether its corners
        // were requested (its record in hand: the candidates' by `order_faces`).
        let mut cur = [NONE; WALK_GROUP];
        let mut ready = [true; WALK_GROUP];
        let mut left = 0;
        for k in 0..m {
            if let Some(&f) = cands[k].as_slice().first() {
                cur[k] = f;
                left += 1;
            }
        }
        while left > 0 {
            for k in 0..m {
                let f = cur[k];
                if f == NONE {
                    continue;
                }
                if !ready[k] {
                    for v in self.faces[f as usize].v {
                        prefetch(&self.verts[v as usize]);
                    }
                    prefetch_line(&adjacency[f as usize]);
                    ready[k] = true;
                    continue;
                }
                match self.exit_step(&ys[k], f, &mut tried[k]) {
                    Exit::Found(b) => {
                        found[k] = Some(b);
                        cur[k] = NONE;
                        left -= 1;
                    }
                    Exit::Next(g) if !tried[k].contains(g) && !tried[k].full() => {
                        cur[k] = g;
                        ready[k] = false;
                        prefetch(&self.faces[g as usize]);
                    }
                    _ => {
                        cur[k] = NONE;
                        left -= 1;
                    }
                }
            }
        }
        for k in 0..m {
            out.push(match found[k] {
                Some(b) => Ok(Self::finish(b, ProjectionPath::Local)),
                // The walk from the first candidate is over: the second is next.
                None if cands[k].n > 0 => {
                    let tried = tried[k].clone();
                    self.search_resumed(&ys[k], ends[k], &cands[k], SearchGoal::FirstHit, tried, 1)
                }
                None => self.search_from(&ys[k], ends[k], &cands[k], SearchGoal::FirstHit),
            });
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use wavg_mesh::{ValidMesh, procedural};

    /// Runs `ys` from `starts` in groups, with and without the start lookup, for both
    /// goals, against [`Projector::start_near`] and [`Projector::project_with`] one query
    /// at a time. Returns how many starts the lookup moved, how many of those the fine
    /// cells moved, and how many first-hit searches another candidate of the first ring
    /// answered after the first candidate's walk over faces ended without a projection.
    fn check_groups(p: &Projector, ys: &[Vec8], starts: &[VertexId]) -> [usize; 3] {
        let mut counts = [0; 3];
        for goal in [SearchGoal::FirstHit, SearchGoal::Closest] {
            for locate in [true, false] {
                let mut got = Vec::new();
                let mut s = starts.to_vec();
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
                    if !(locate
                        && goal == SearchGoal::FirstHit
                        && ys[k].iter().all(|v| v.is_finite()))
                    {
                        continue;
                    }
                    let yw = p.walk_point(&ys[k]);
                    counts[0] += usize::from(s0 != starts[k]);
                    counts[1] += usize::from(s0 != p.starts.walk(&yw, &p.walk_coords).0);
                    if s0 as usize >= p.walk_coords.len() {
                        continue;
                    }
                    let end = p.walk(&ys[k], s0);
                    let cands = p.order_faces(&ys[k], end, &p.ring_dists(&ys[k], end));
                    let mut tried = FaceSet::new();
                    let mut cur = cands.as_slice()[0];
                    loop {
                        match p.exit_step(&ys[k], cur, &mut tried) {
                            Exit::Next(g) if !tried.contains(g) => cur = g,
                            Exit::Found(_) => break,
                            _ => {
                                // Whether a later candidate of the first ring answers.
                                let on = |skip| {
                                    let t = tried.clone();
                                    p.search_resumed(&ys[k], end, &cands, goal, t, skip)
                                };
                                counts[2] += usize::from(on(1) != on(64));
                                break;
                            }
                        }
                    }
                }
            }
        }
        counts
    }

    /// Groups (full, short, and holding a bad query) give the starts and projections of
    /// one query at a time: on a sphere whose start grid is capped (so the fine cells take
    /// part) and on a coarse, very noisy sphere with queries far inside and outside it.
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
        let [moved, fine_moved, _] = check_groups(&p, &ys, &starts);
        assert!(
            moved > 40 && fine_moved > 20,
            "{moved} starts moved, {fine_moved} by the fine cells"
        );

        // Coarse and very noisy: the first candidate's walk over faces sometimes ends
        // without a projection where another candidate of the ring holds one.
        let m = ValidMesh::new(procedural::with_noise(procedural::icosphere(3), 0.2, 2));
        let emb = Arc::new(EmbeddedMesh::from_positions(Arc::new(m.unwrap())));
        let p = Projector::new(emb.clone()).unwrap();
        let (nf, nv) = (emb.mesh().n_faces(), emb.coords().len());
        let ys: Vec<Vec8> = (0..2400)
            .map(|k| {
                let a = (k * 7 % 10) as f64 * 0.09;
                let b = (k * 3 % 11) as f64 / 110.0;
                let on = SurfacePoint::new((k * 37 % nf) as FaceId, [a, b, 1.0 - a - b]);
                emb.point(&on) * [1.3, 0.2, 2.0, 0.8, 1.1][k % 5]
            })
            .collect();
        let starts: Vec<VertexId> = (0..2400).map(|k| (k * 131 % nv) as VertexId).collect();
        let [.., resumed] = check_groups(&p, &ys, &starts);
        assert!(resumed >= 3, "{resumed} first-hit searches went on");
    }
}
