//! Batches of forward and inverse problems, in two layers: `*_batch` allocates and runs on
//! the current rayon pool; `*_batch_into` takes its buffers and a [`Par`] (how to spread
//! the work over threads, chosen as for the projector's batches). Every query is
//! independent, so the results never depend on the parallelism.

use wavg_mesh::SurfacePoint;
use wavg_project::Par;
use wavg_project::internal::WALK_GROUP;

use crate::aim::CurveAim;
use crate::error::SolveError;
use crate::kernel::InverseScratch;
use crate::solver::{ForwardOptions, ForwardResult, Prepared, Solver};

/// Buffers of [`Solver::forward_batch_into`], reused from batch to batch.
#[derive(Debug, Default)]
pub struct ForwardScratch {
    prepared: Vec<(u64, Result<Prepared, SolveError>)>,
    order: Vec<(u64, u32)>,
    done: Vec<Result<ForwardResult, SolveError>>,
    pos: Vec<u32>,
}

/// Weight rows one parallel task reads.
pub(crate) const PREPARE_CHUNK: usize = 256;
/// Sorted queries one parallel task solves.
const SEARCH_CHUNK: usize = 64;
/// Points one parallel task of the inverse batch handles.
const INVERSE_CHUNK: usize = 64;

impl Solver {
    /// Forward problem for many weight vectors in parallel; result `i` belongs to
    /// `weights[i]` and equals [`Solver::forward`]'s. See [`Solver::forward_batch_into`].
    pub fn forward_batch<W: AsRef<[f64]> + Sync>(
        &self,
        weights: &[W],
        opts: &ForwardOptions,
    ) -> Vec<Result<ForwardResult, SolveError>> {
        let mut out = Vec::new();
        let mut scratch = ForwardScratch::default();
        // `Par::Rayon` always starts.
        let _ = self.forward_batch_into(weights, opts, &mut scratch, &mut out, Par::Rayon);
        out
    }

    /// [`Solver::forward_batch`] into `out`, with explicit buffers and parallelism. The
    /// weight rows are read once, in input order, into their averages; the searches then
    /// run in the Morton order of the averages (nearby queries together, so they share
    /// cached mesh data), cold starts in groups whose cache misses overlap. Each still starts where [`Solver::forward`] would (its
    /// highest-weight anchor, a vertex near its average or its warm start), so the results equal [`Solver::forward`]'s for any `par`. Fails only when
    /// `par`'s threads cannot start.
    pub fn forward_batch_into<W: AsRef<[f64]> + Sync>(
        &self,
        weights: &[W],
        opts: &ForwardOptions,
        scratch: &mut ForwardScratch,
        out: &mut Vec<Result<ForwardResult, SolveError>>,
        par: Par,
    ) -> Result<(), SolveError> {
        let ForwardScratch {
            prepared,
            order,
            done,
            pos,
        } = scratch;
        // A failed validation is the query's answer (sorted last).
        par.map_range(weights.len(), PREPARE_CHUNK, prepared, |i| {
            self.prepare_keyed(weights[i].as_ref(), opts)
        })?;
        self.search_prepared(prepared, opts, order, pos, done, out, par, |_, r| r)
    }

    /// [`Solver::prepare`] with the Morton key of the average (`u64::MAX` for a failed
    /// validation, so such queries sort last).
    pub(crate) fn prepare_keyed(
        &self,
        weights: &[f64],
        opts: &ForwardOptions,
    ) -> (u64, Result<Prepared, SolveError>) {
        let p = self.prepare(weights, opts);
        let key = match &p {
            Ok(p) => u64::from(wavg_project::internal::locality_key(
                self.projector(),
                &p.ybar,
            )),
            Err(_) => u64::MAX,
        };
        (key, p)
    }

    /// The searches of prepared queries (from [`Solver::prepare_keyed`]) in the Morton order
    /// of their averages (nearby queries together, so they share cached mesh data), each
    /// result mapped by `f(query index, result)`; into `out` in input order. `order`,
    /// `pos` and `done` are buffers. Fails only when `par`'s threads cannot start.
    #[allow(clippy::too_many_arguments)]
    pub(crate) fn search_prepared<T: Clone + Send + Sync>(
        &self,
        prepared: &[(u64, Result<Prepared, SolveError>)],
        opts: &ForwardOptions,
        order: &mut Vec<(u64, u32)>,
        pos: &mut Vec<u32>,
        done: &mut Vec<T>,
        out: &mut Vec<T>,
        par: Par,
        f: impl Fn(usize, Result<ForwardResult, SolveError>) -> T + Sync + Send,
    ) -> Result<(), SolveError> {
        order.clear();
        order.extend(prepared.iter().enumerate().map(|(i, p)| (p.0, i as u32)));
        par.sort(order)?;
        done.clear();
        // Groups of sorted queries whose searches can interleave (see
        // `Solver::group_goal`) run together; the others one at a time.
        par.map_chunks(order, SEARCH_CHUNK, done, |chunk| {
            let mut out = Vec::with_capacity(chunk.len());
            let mut found = Vec::with_capacity(WALK_GROUP);
            let mut group: Vec<&Prepared> = Vec::with_capacity(WALK_GROUP);
            for (g, ids) in chunk.chunks(WALK_GROUP).enumerate() {
                // The prepared queries are read at random in this order: the next group's
                // records are requested while this group runs.
                for &(_, j) in chunk.iter().skip((g + 1) * WALK_GROUP).take(WALK_GROUP) {
                    wavg_project::internal::prefetch(&prepared[j as usize]);
                }
                let goal = |i: u32| match &prepared[i as usize].1 {
                    Ok(p) => Self::group_goal(p, opts),
                    Err(_) => None,
                };
                group.clear();
                found.clear();
                if let Some(g) =
                    goal(ids[0].1).filter(|&g| ids.iter().all(|&(_, i)| goal(i) == Some(g)))
                {
                    group.extend(
                        ids.iter()
                            .filter_map(|&(_, i)| prepared[i as usize].1.as_ref().ok()),
                    );
                    self.forward_group(&group, g, &mut found);
                } else {
                    found.extend(ids.iter().map(|&(_, i)| match &prepared[i as usize].1 {
                        Ok(p) => self.forward_prepared(p, opts),
                        Err(e) => Err(e.clone()),
                    }));
                }
                out.extend(
                    ids.iter()
                        .zip(found.drain(..))
                        .map(|(&(_, i), r)| f(i as usize, r)),
                );
            }
            out
        })?;
        // Back in input order: one gather, no intermediate lists.
        pos.clear();
        pos.resize(order.len(), 0);
        for (k, &(_, i)) in order.iter().enumerate() {
            pos[i as usize] = k as u32;
        }
        par.map_range(pos.len(), 4096, out, |i| done[pos[i] as usize].clone())?;
        Ok(())
    }

    /// Forward problem for a sequence of nearby queries (e.g. samples along a curve):
    /// each query warm-starts from the previous answer and heads where [`CurveAim`]
    /// says. For parallelism the sequence is cut
    /// into chunks of `chunk` queries (independent of the thread count, so the results are
    /// too); the first query of each chunk starts cold (or from `opts.warm_start`).
    pub fn forward_batch_warm<W: AsRef<[f64]> + Sync>(
        &self,
        weights: &[W],
        opts: &ForwardOptions,
        chunk: usize,
    ) -> Vec<Result<ForwardResult, SolveError>> {
        let mut out = Vec::new();
        // `Par::Rayon` always starts.
        let _ = self.forward_batch_warm_into(weights, opts, chunk, &mut out, Par::Rayon);
        out
    }

    /// [`Solver::forward_batch_warm`] into `out`, with explicit parallelism (the results
    /// do not depend on it). Fails only when `par`'s threads cannot start.
    pub fn forward_batch_warm_into<W: AsRef<[f64]> + Sync>(
        &self,
        weights: &[W],
        opts: &ForwardOptions,
        chunk: usize,
        out: &mut Vec<Result<ForwardResult, SolveError>>,
        par: Par,
    ) -> Result<(), SolveError> {
        out.clear();
        par.map_chunks(weights, chunk, out, |c| {
            let mut o = *opts;
            let mut aim = CurveAim::default();
            c.iter()
                .map(|w| {
                    let mut prepared = self.prepare(w.as_ref(), &o)?;
                    prepared.aim = aim.aim();
                    let r = self.forward_prepared(&prepared, &o);
                    if let Ok(r) = &r {
                        o.warm_start = Some(r.point);
                        aim.record(self, &r.point);
                    }
                    r
                })
                .collect()
        })?;
        Ok(())
    }

    /// Inverse problem for many points in parallel (see [`BatchWeights`]); each point is
    /// independent, so the results equal [`Solver::inverse`]'s for any thread count.
    pub fn inverse_batch(&self, points: &[SurfacePoint]) -> BatchWeights {
        let mut out = BatchWeights::default();
        // `Par::Rayon` always starts.
        let _ = self.inverse_batch_into(points, &mut out, Par::Rayon);
        out
    }

    /// [`Solver::inverse_batch`] into an existing result, reusing its memory (repeated
    /// batches then neither allocate nor page-fault), with explicit parallelism (the
    /// results do not depend on it). Fails only when `par`'s threads cannot start.
    pub fn inverse_batch_into(
        &self,
        points: &[SurfacePoint],
        out: &mut BatchWeights,
        par: Par,
    ) -> Result<(), SolveError> {
        let n = self.n_anchors();
        out.n = n;
        out.data.resize(points.len() * n.max(1), 0.0);
        out.status.clear();
        out.status = self.inverse_rows_into(points, &mut out.data, par)?;
        Ok(())
    }

    /// The paper's weights of each point straight into its row of `rows` (`n_anchors`
    /// weights per point, one row per point; NaN where the inverse problem fails), and each
    /// point's outcome: [`Solver::inverse_batch_into`] into the caller's memory (a binding's
    /// output array), without a copy out of a buffer. Fails only when `par`'s threads
    /// cannot start.
    ///
    /// # Panics
    /// When `rows` does not hold `points.len() * n_anchors` values.
    pub fn inverse_rows_into(
        &self,
        points: &[SurfacePoint],
        rows: &mut [f64],
        par: Par,
    ) -> Result<Vec<Result<(), SolveError>>, SolveError> {
        self.inverse_rows_into_by(points, |p| *p, rows, par)
    }

    /// [`Solver::inverse_rows_into`] for points in the caller's own type, each turned into
    /// a [`SurfacePoint`] by `point` as it is solved (a binding's point records, without
    /// a converted copy of the batch).
    ///
    /// # Panics
    /// When `rows` does not hold `points.len() * n_anchors` values.
    pub fn inverse_rows_into_by<P: Sync>(
        &self,
        points: &[P],
        point: impl Fn(&P) -> SurfacePoint + Sync + Send,
        rows: &mut [f64],
        par: Par,
    ) -> Result<Vec<Result<(), SolveError>>, SolveError> {
        self.inverse_rows_then(points, point, rows, par, |r| r.map(|_| ()))
    }

    /// [`Solver::inverse_rows_into_by`], each point's outcome (its row of weights, or the
    /// error) mapped by `then` while the row is in cache.
    ///
    /// # Panics
    /// When `rows` does not hold `points.len() * n_anchors` values.
    pub(crate) fn inverse_rows_then<P: Sync, T: Send>(
        &self,
        points: &[P],
        point: impl Fn(&P) -> SurfacePoint + Sync + Send,
        rows: &mut [f64],
        par: Par,
        then: impl Fn(Result<&[f64], SolveError>) -> T + Sync + Send,
    ) -> Result<Vec<T>, SolveError> {
        let n = self.n_anchors().max(1);
        assert_eq!(rows.len(), points.len() * n, "one row of weights per point");
        // Random points read random face records and then their corners' records: request
        // both a few points ahead (software pipelining), so the waits overlap.
        let proj = self.projector();
        let mut out = Vec::with_capacity(points.len());
        par.zip_chunks_mut(
            rows,
            n * INVERSE_CHUNK,
            points,
            INVERSE_CHUNK,
            &mut out,
            |rows, pts| {
                let mut scratch = InverseScratch::default();
                let mut buf = Vec::with_capacity(n);
                let ahead = |k: usize| pts.get(k).map(|p| point(p).face);
                for f in (0..4).filter_map(ahead) {
                    wavg_project::internal::prefetch_point_data(proj, f, false);
                }
                let mut out = Vec::with_capacity(pts.len());
                for (k, (row, p)) in rows.chunks_mut(n).zip(pts).enumerate() {
                    let p = &point(p);
                    if let Some(f) = ahead(k + 4) {
                        wavg_project::internal::prefetch_point_data(proj, f, false);
                    }
                    if let Some(f) = ahead(k + 2) {
                        wavg_project::internal::prefetch_point_data(proj, f, true);
                    }
                    out.push(match self.inverse_into(p, &mut scratch, &mut buf) {
                        Ok(()) => {
                            row.copy_from_slice(&buf);
                            then(Ok(row))
                        }
                        Err(e) => {
                            row.fill(f64::NAN);
                            then(Err(e))
                        }
                    });
                }
                out
            },
        )?;
        Ok(out)
    }
}

/// Weights of a batch of inverse problems: one row of `n_anchors` weights per point.
#[derive(Clone, Debug, Default)]
pub struct BatchWeights {
    pub(crate) n: usize,
    pub(crate) data: Vec<f64>,
    pub(crate) status: Vec<Result<(), SolveError>>,
}

impl BatchWeights {
    /// Number of points.
    pub fn len(&self) -> usize {
        self.status.len()
    }

    /// Whether the batch is empty.
    pub fn is_empty(&self) -> bool {
        self.status.is_empty()
    }

    /// Weights of point `i`, or why there are none.
    pub fn get(&self, i: usize) -> Result<&[f64], &SolveError> {
        match &self.status[i] {
            Ok(()) => Ok(&self.data[i * self.n..(i + 1) * self.n]),
            Err(e) => Err(e),
        }
    }

    /// All rows in order.
    pub fn iter(&self) -> impl Iterator<Item = Result<&[f64], &SolveError>> {
        (0..self.len()).map(|i| self.get(i))
    }

    /// Replaces row `i` with `w` (the anchor count long) or marks it failed.
    pub(crate) fn set(&mut self, i: usize, w: Result<&[f64], SolveError>) {
        match w {
            Ok(w) => {
                self.data[i * self.n..(i + 1) * self.n].copy_from_slice(w);
                self.status[i] = Ok(());
            }
            Err(e) => self.status[i] = Err(e),
        }
    }
}
