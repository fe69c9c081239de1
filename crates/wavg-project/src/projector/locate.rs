//! Start vertices near any query: a coarse grid over the three widest of the walk's
//! coordinates, each cell holding the vertex of the mesh nearest its centre (an empty cell,
//! that of the nearest cell with one). A greedy walk over the vertex graph takes a number
//! of steps that grows with the mesh's resolution (about the square root of its vertex
//! count) times the distance to cover; a greedy walk over the grid's cells, each step
//! comparing the neighbouring cells' vertices in all eight coordinates, covers most of the
//! distance in steps of a cell. Each cell keeps a copy of its vertex's coordinates, so a
//! step reads a few neighbouring rows of the grid rather than 26 scattered vertex records.
//! Where the cells are capped, a lookup in finer cells ([`FineCells`]) follows the walk.

use std::sync::atomic::{AtomicU64, Ordering};

use super::fine::FineCells;
use super::layout::WalkPoint;
use super::*;

/// Cells along the widest axis per square root of the vertex count: about as many
/// vertices per occupied cell at every resolution, so walks from a cell's vertex take
/// about the same number of steps.
const CELLS_PER_SQRT_VERTEX: f64 = 1.0 / 8.0;
/// At most this many cells along an axis (the grid stays a few megabytes).
const MAX_CELLS: u32 = 128;
/// The walk over the cells stops after this many steps (the walk over the vertices goes
/// on from where it stopped).
const MAX_CELL_STEPS: usize = 64;
/// The walk over the cells stops at a vertex within this many cell widths of the query:
/// a step costs as much as several steps of the walk over the vertices, which covers the
/// last cell width as well and from closer (armadillo, 93 anchors: 5.7% fewer forward
/// instructions than walking on to the closest cell, no fewer round trips).
const NEAR_CELLS: f32 = 1.0;
/// Cells along the widest axis per square root of the vertex count in the fine cells
/// ([`FineCells`]) past [`MAX_CELLS`]: as many vertices per cell as the grid holds below
/// the cap (rocker-arm level 5, 10.3M vertices: walk steps 10.5 -> 3.8 on average; a
/// forward problem 5.8 us against 6.1-6.2 with cells half or twice as wide).
const FINE_CELLS_PER_SQRT_VERTEX: f64 = 1.0 / 8.0;

/// A cell's vertex and a copy of its walk coordinates.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[repr(C)]
struct Cell {
    c: [u16; 8],
    v: VertexId,
}

/// The grid: cell `(i, j, k)` over walk axes `axes` holds a vertex: the most central one
/// inside it, or for an empty cell that of the nearest cell with one.
#[derive(Clone, Debug)]
pub(super) struct StartGrid {
    axes: [usize; 3],
    origin: [f32; 3],
    /// Cells per walk unit.
    inv_cell: f32,
    dims: [u32; 3],
    /// Index offsets of a cell's 26 neighbours (in [`StartGrid::neighbours`]' order) for
    /// cells off the grid's sides.
    offsets: [isize; 26],
    cells: Vec<Cell>,
    /// Where [`MAX_CELLS`] caps the cells: finer ones (empty otherwise).
    pub(super) fine: FineCells,
}

impl StartGrid {
    /// The grid over the walk records (deterministic: each cell keeps its most central
    /// vertex, ties to the lowest index, whatever the number of threads).
    pub(super) fn new(walk: &[WalkPoint]) -> Self {
        Self::with_max_cells(walk, MAX_CELLS)
    }

    /// [`StartGrid::new`] with at most `max_cells` cells along an axis.
    pub(super) fn with_max_cells(walk: &[WalkPoint], max_cells: u32) -> Self {
        let (lo, hi) = walk
            .par_iter()
            .with_min_len(4096)
            .fold(
                || ([u16::MAX; 8], [0u16; 8]),
                |(l, h), w| {
                    (
                        std::array::from_fn(|k| l[k].min(w.c[k])),
                        std::array::from_fn(|k| h[k].max(w.c[k])),
                    )
                },
            )
            .reduce(
                || ([u16::MAX; 8], [0u16; 8]),
                |(l0, h0), (l1, h1)| {
                    (
                        std::array::from_fn(|k| l0[k].min(l1[k])),
                        std::array::from_fn(|k| h0[k].max(h1[k])),
                    )
                },
            );
        // Extents in walk units (one more than the span: a cell is half-open).
        let ext: [f32; 8] = std::array::from_fn(|k| hi[k].saturating_sub(lo[k]) as f32 + 1.0);
        let mut order: [usize; 8] = std::array::from_fn(|k| k);
        order.sort_by(|&a, &b| ext[b].total_cmp(&ext[a]).then(a.cmp(&b)));
        let axes = [order[0], order[1], order[2]];
        let wanted = ((walk.len() as f64).sqrt() * CELLS_PER_SQRT_VERTEX).ceil();
        let n = wanted.clamp(1.0, max_cells as f64) as f32;
        let inv_cell = n / ext[axes[0]];
        let dims = axes.map(|a| ((ext[a] * inv_cell).ceil() as u32).clamp(1, max_cells));
        let mut grid = Self {
            axes,
            origin: axes.map(|a| lo[a] as f32),
            inv_cell,
            dims,
            offsets: neighbour_offsets(dims),
            cells: Vec::new(),
            fine: FineCells::default(),
        };
        let n_cells = dims.iter().map(|&d| d as usize).product::<usize>();
        // Key: squared distance to the cell's centre (non-negative f32: its bits sort like
        // its value) above the vertex id, so the minimum is the most central, lowest id.
        let best: Vec<AtomicU64> = (0..n_cells).map(|_| AtomicU64::new(u64::MAX)).collect();
        walk.par_iter()
            .enumerate()
            .with_min_len(4096)
            .for_each(|(v, w)| {
                let (cell, d2) = grid.cell_of(&w.unpack());
                let key = (u64::from(d2.to_bits()) << 32) | v as u64;
                best[cell].fetch_min(key, Ordering::Relaxed);
            });
        let mut ids: Vec<VertexId> = best
            .into_iter()
            .map(|b| match b.into_inner() {
                u64::MAX => NONE,
                k => k as u32,
            })
            .collect();
        grid.fill_empty_cells(&mut ids);
        grid.cells = ids
            .into_iter()
            .map(|v| Cell {
                c: walk[v as usize].c,
                v,
            })
            .collect();
        if wanted > max_cells as f64 {
            let fine = ((walk.len() as f64).sqrt() * FINE_CELLS_PER_SQRT_VERTEX).ceil() as f32;
            grid.fine = FineCells::new(walk, axes, grid.origin, fine / ext[axes[0]]);
        }
        grid
    }

    /// Gives every empty cell the vertex of the nearest cell holding one (breadth-first
    /// over face-adjacent cells from all occupied cells in index order: deterministic).
    fn fill_empty_cells(&self, cells: &mut [VertexId]) {
        let mut queue: std::collections::VecDeque<usize> =
            (0..cells.len()).filter(|&c| cells[c] != NONE).collect();
        while let Some(c) = queue.pop_front() {
            let v = cells[c];
            for n in self.neighbours(c, false).into_iter().flatten() {
                if cells[n] == NONE {
                    cells[n] = v;
                    queue.push_back(n);
                }
            }
        }
    }

    /// The cells next to cell `c`: the 6 sharing a face, or with `all` the 26 sharing a
    /// face, an edge or a corner (`None` past the grid's sides).
    #[inline]
    fn neighbours(&self, c: usize, all: bool) -> [Option<usize>; 26] {
        let [d0, d1, d2] = self.dims.map(|d| d as usize);
        let (i, j, k) = (c / (d1 * d2), c / d2 % d1, c % d2);
        let mut out = [None; 26];
        let mut m = 0;
        for di in -1i64..=1 {
            for dj in -1i64..=1 {
                for dk in -1i64..=1 {
                    let far = di.abs() + dj.abs() + dk.abs();
                    if far == 0 || (!all && far > 1) {
                        continue;
                    }
                    let (a, b, e) = (i as i64 + di, j as i64 + dj, k as i64 + dk);
                    if (0..d0 as i64).contains(&a)
                        && (0..d1 as i64).contains(&b)
                        && (0..d2 as i64).contains(&e)
                    {
                        out[m] = Some((a as usize * d1 + b as usize) * d2 + e as usize);
                    }
                    m += 1;
                }
            }
        }
        out
    }

    /// The cell holding walk point `p` (clamped to the grid) and the squared distance
    /// from `p` to its centre, in cells.
    #[inline]
    fn cell_of(&self, p: &[f32; 8]) -> (usize, f32) {
        let mut idx = 0usize;
        let mut d2 = 0.0f32;
        for i in 0..3 {
            let x = (p[self.axes[i]] - self.origin[i]) * self.inv_cell;
            // `as` saturates (NaN to 0).
            let c = (x.floor() as u32).min(self.dims[i] - 1);
            let d = x - (c as f32 + 0.5);
            d2 += d * d;
            idx = idx * self.dims[i] as usize + c as usize;
        }
        (idx, d2)
    }

    /// Squared walk distance below which a cell's vertex is near enough to start from
    /// (see [`NEAR_CELLS`]).
    #[inline]
    fn near(&self) -> f32 {
        let h = NEAR_CELLS / self.inv_cell;
        h * h
    }

    /// Greedy walk over the cells from the one holding walk point `p`: moves to the
    /// neighbouring cell whose vertex is closest to `p` (squared distance in walk units;
    /// ties to the first in [`StartGrid::neighbours`]' order) while that improves and
    /// the current one lies farther than [`NEAR_CELLS`] from `p`; returns the last cell's
    /// vertex and its squared distance. After each step the walk record (of `records`) of
    /// the step's vertex is requested: the vertex walk reads it first, and the next grid
    /// step's reads hide the wait.
    #[inline]
    pub(super) fn walk(&self, p: &[f32; 8], records: &[WalkPoint]) -> (VertexId, f32) {
        let mut c = self.cell_of(p).0;
        let cell = &self.cells[c];
        let mut best = (cell.v, super::layout::dist2_packed(&cell.c, p));
        let near = self.near();
        for _ in 0..MAX_CELL_STEPS {
            if best.1 <= near {
                break;
            }
            let next = self.step(c, p, &mut best);
            if next == c {
                break;
            }
            c = next;
            if let Some(r) = records.get(best.0 as usize) {
                super::prefetch_line(r);
            }
        }
        best
    }

    /// [`StartGrid::walk`] for each walk point of `ps` (up to [`WALK_GROUP`]) into
    /// `out`, the walks advancing a step each in turn, each step requesting the cells the
    /// next one reads (so the walks' waits overlap): the same vertices and distances.
    pub(super) fn walk_group(&self, ps: &[[f32; 8]], out: &mut [(VertexId, f32)]) {
        let m = out.len();
        let near = self.near();
        let mut cell = [0usize; WALK_GROUP];
        for k in 0..m {
            cell[k] = self.cell_of(&ps[k]).0;
            super::prefetch_line(&self.cells[cell[k]]);
        }
        let mut live = [false; WALK_GROUP];
        for k in 0..m {
            let c = &self.cells[cell[k]];
            out[k] = (c.v, super::layout::dist2_packed(&c.c, &ps[k]));
            live[k] = out[k].1 > near;
            if live[k] {
                self.prefetch_around(cell[k]);
            }
        }
        for _ in 0..MAX_CELL_STEPS {
            let mut any = false;
            for k in 0..m {
                if !live[k] {
                    continue;
                }
                let next = self.step(cell[k], &ps[k], &mut out[k]);
                live[k] = next != cell[k] && out[k].1 > near;
                cell[k] = next;
                if live[k] {
                    self.prefetch_around(next);
                    any = true;
                }
            }
            if !any {
                break;
            }
        }
    }

    /// One step of the walk over the cells for walk point `p` from cell `c`, whose best
    /// vertex so far is `best` (vertex, squared distance): the neighbouring cell whose
    /// vertex is closest to `p` if it is strictly closer than `best` (which becomes it;
    /// ties to the first in [`StartGrid::neighbours`]' order), else `c`.
    #[inline]
    fn step(&self, c: usize, p: &[f32; 8], best: &mut (VertexId, f32)) -> usize {
        let [d0, d1, d2] = self.dims.map(|d| d as usize);
        let (i, j, k) = (c / (d1 * d2), c / d2 % d1, c % d2);
        let inside = (1..d0.saturating_sub(1)).contains(&i)
            && (1..d1.saturating_sub(1)).contains(&j)
            && (1..d2.saturating_sub(1)).contains(&k);
        let mut next = c;
        let mut visit = |n: usize| {
            let cell = &self.cells[n];
            let du = super::layout::dist2_packed(&cell.c, p);
            if du < best.1 {
                (next, *best) = (n, (cell.v, du));
            }
        };
        if inside {
            self.offsets
                .iter()
                .for_each(|&o| visit(c.wrapping_add_signed(o)));
        } else {
            self.neighbours(c, true)
                .into_iter()
                .flatten()
                .for_each(visit);
        }
        next
    }

    /// Requests the cells around cell `c` (the nine rows of three that a step reads).
    #[inline]
    fn prefetch_around(&self, c: usize) {
        let [_, d1, d2] = self.dims.map(|d| d as isize);
        for di in -1..=1 {
            for dj in -1..=1 {
                let mid = c as isize + (di * d1 + dj) * d2;
                for e in [mid - 1, mid + 1] {
                    if let Some(cell) = self.cells.get(e as usize) {
                        super::prefetch_line(cell);
                    }
                }
            }
        }
    }

    /// Heap bytes used.
    pub(super) fn bytes(&self) -> usize {
        std::mem::size_of_val(&self.cells[..]) + self.fine.bytes()
    }
}

/// Index offsets of a cell's 26 neighbours in a grid of `dims` cells, in
/// [`StartGrid::neighbours`]' order (for cells off the grid's sides).
fn neighbour_offsets(dims: [u32; 3]) -> [isize; 26] {
    let [d1, d2] = [dims[1] as isize, dims[2] as isize];
    let mut offsets = [0isize; 26];
    let mut m = 0;
    for di in -1isize..=1 {
        for dj in -1isize..=1 {
            for dk in -1isize..=1 {
                if (di, dj, dk) != (0, 0, 0) {
                    offsets[m] = (di * d1 + dj) * d2 + dk;
                    m += 1;
                }
            }
        }
    }
    offsets
}

impl Projector {
    /// A vertex to start a search for `y` from: `start`, or the vertex of a coarse grid
    /// over the surface nearest `y` when that one is closer to `y` (in the greedy walk's
    /// compact coordinates). A walk from a far-off start takes a number of steps that
    /// grows with the mesh's resolution; from this one it takes a few. The start only
    /// changes the work of [`Projector::project`], never its answer. `start` itself when
    /// `y` is not finite or `start` is out of range.
    ///
    /// ```
    /// use std::sync::Arc;
    /// use wavg_mesh::{SurfacePoint, ValidMesh, procedural};
    /// use wavg_project::{EmbeddedMesh, Projector};
    /// let m = Arc::new(ValidMesh::new(procedural::icosphere(5)).unwrap());
    /// let emb = Arc::new(EmbeddedMesh::from_positions(m));
    /// let p = Projector::new(emb.clone()).unwrap();
    /// let y = emb.point(&SurfacePoint::new(9000, [0.2, 0.3, 0.5]));
    /// let s = p.start_near(&y, 0);
    /// assert!((emb.coords()[s as usize] - y).norm() <= (emb.coords()[0] - y).norm());
    /// assert_eq!(p.project(&y, s).unwrap().point.face, 9000);
    /// ```
    pub fn start_near(&self, y: &Vec8, start: VertexId) -> VertexId {
        let Some(ws) = self.walk_coords.get(start as usize) else {
            return start;
        };
        if !y.iter().all(|v| v.is_finite()) {
            return start;
        }
        let yw = self.walk_point(y);
        let (v, d) = self.starts.walk(&yw, &self.walk_coords);
        let (v, d) = self.fine_start(&yw, (v, d));
        if d < ws.dist2(&yw) { v } else { start }
    }

    /// The vertex of the fine cell holding the foot of walk point `yw` on the tangent
    /// plane of `best`'s vertex if it is closer to `yw` than `best` (vertex, squared
    /// distance), else `best`.
    #[inline]
    fn fine_start(&self, yw: &[f32; 8], best: (VertexId, f32)) -> (VertexId, f32) {
        if self.starts.fine.is_empty() {
            return best;
        }
        let foot = self.foot(yw, best.0);
        self.closer_start(yw, best, self.starts.fine.vertex_at(&foot))
    }

    /// The foot of walk point `yw` on the tangent plane of vertex `v` (walk units).
    #[inline]
    fn foot(&self, yw: &[f32; 8], v: VertexId) -> [f32; 8] {
        let x = self.walk_coords[v as usize].unpack();
        let (t0, t1) = self.verts[v as usize].tangents();
        let r: [f32; 8] = std::array::from_fn(|k| yw[k] - x[k]);
        let (a, b) = (super::layout::wdot(t0, &r), super::layout::wdot(t1, &r));
        std::array::from_fn(|k| x[k] + a * t0[k] + b * t1[k])
    }

    /// `candidate` (a fine cell's vertex) if it is closer to `yw` than `best`, else `best`.
    #[inline]
    fn closer_start(
        &self,
        yw: &[f32; 8],
        best: (VertexId, f32),
        candidate: Option<VertexId>,
    ) -> (VertexId, f32) {
        match candidate {
            Some(u) if u != best.0 => {
                let du = self.walk_coords[u as usize].dist2(yw);
                if du < best.1 { (u, du) } else { best }
            }
            _ => best,
        }
    }

    /// [`Projector::start_near`] for each query `ys[k]` from `starts[k]`, in place, the
    /// queries' lookups interleaved stage by stage (each stage requests what the next one
    /// reads, so the queries' memory waits overlap); the same starts as one at a time.
    /// Every start must be in range and every query finite.
    pub(super) fn starts_near_group(&self, ys: &[Vec8], starts: &mut [VertexId]) {
        let m = starts.len();
        let fine = &self.starts.fine;
        let mut yw = [[0.0f32; 8]; WALK_GROUP];
        let mut best = [(0 as VertexId, 0.0f32); WALK_GROUP];
        for k in 0..m {
            yw[k] = self.walk_point(&ys[k]);
            prefetch_line(&self.walk_coords[starts[k] as usize]);
        }
        self.starts.walk_group(&yw[..m], &mut best[..m]);
        for k in 0..m {
            // Both the comparisons below and the walk over the vertices read the walk
            // record; the foot reads the vertex's frame (its record's second line).
            prefetch_line(&self.walk_coords[best[k].0 as usize]);
            if !fine.is_empty() {
                prefetch_line(&self.verts[best[k].0 as usize].t);
            }
        }
        if !fine.is_empty() {
            let mut foot = [[0.0f32; 8]; WALK_GROUP];
            for k in 0..m {
                foot[k] = self.foot(&yw[k], best[k].0);
                fine.prefetch(&foot[k]);
            }
            let mut cand = [None; WALK_GROUP];
            for k in 0..m {
                cand[k] = fine.vertex_at(&foot[k]);
                if let Some(u) = cand[k] {
                    prefetch_line(&self.walk_coords[u as usize]);
                }
            }
            for k in 0..m {
                best[k] = self.closer_start(&yw[k], best[k], cand[k]);
            }
        }
        for k in 0..m {
            let (v, d) = best[k];
            if d < self.walk_coords[starts[k] as usize].dist2(&yw[k]) {
                starts[k] = v;
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use wavg_mesh::{ValidMesh, procedural};

    /// Every cell holds a vertex; an occupied cell's vertex lies in it; walks over the
    /// cells, one at a time or interleaved, equal a plain reference walk; the grid is the
    /// same on one thread as on several.
    #[test]
    fn grid_cells_hold_their_own_vertices_whatever_the_threads() {
        let m = Arc::new(ValidMesh::new(procedural::icosphere(5)).unwrap());
        let emb = Arc::new(EmbeddedMesh::from_positions(m));
        let p = Projector::new(emb.clone()).unwrap();
        let g = &p.starts;
        assert!(g.cells.len() > 100 && g.cells.iter().all(|c| c.v != NONE));
        let mut own = vec![false; g.cells.len()];
        for (v, w) in p.walk_coords.iter().enumerate() {
            own[g.cell_of(&w.unpack()).0] = true;
            // A vertex's cell holds a vertex of that cell.
            let cell = g.cells[g.cell_of(&w.unpack()).0];
            assert_eq!(cell.c, p.walk_coords[cell.v as usize].c);
            let u = cell.v;
            assert_eq!(
                g.cell_of(&p.walk_coords[u as usize].unpack()).0,
                g.cell_of(&w.unpack()).0,
                "vertex {v}"
            );
        }
        assert!(own.iter().any(|&o| !o), "some cells are empty (and filled)");
        // The walk's inner-cell shortcut visits the neighbours of `neighbours` in its
        // order: the same walk as through `neighbours` alone, from everywhere.
        // The last vertex, its squared distance and the steps taken.
        let reference = |p: &[f32; 8]| {
            let dist2 = |cell: &Cell| crate::projector::layout::dist2_packed(&cell.c, p);
            let mut c = g.cell_of(p).0;
            let (mut v, mut d) = (g.cells[c].v, dist2(&g.cells[c]));
            let mut steps = 0;
            for _ in 0..MAX_CELL_STEPS {
                if d <= g.near() {
                    break;
                }
                let mut next = c;
                for n in g.neighbours(c, true).into_iter().flatten() {
                    let du = dist2(&g.cells[n]);
                    if du < d {
                        (next, v, d) = (n, g.cells[n].v, du);
                    }
                }
                if next == c {
                    break;
                }
                c = next;
                steps += 1;
            }
            ((v, d), steps)
        };
        let mut inner = 0;
        let mut points = Vec::new();
        for (v, w) in p.walk_coords.iter().enumerate().step_by(7) {
            let mut q = w.unpack();
            // Off the surface in every coordinate, some points past the grid's sides.
            for (k, x) in q.iter_mut().enumerate() {
                *x += ((v * 31 + k * 17) % 23) as f32 * 40.0 - 440.0;
                if v % 5 == 0 {
                    *x = if k % 2 == 0 { -3e4 } else { 1e5 };
                }
            }
            // Most of a cell from a vertex in each of the grid's axes: walks that step
            // to a near cell's vertex.
            if v % 5 == 2 {
                for &a in &g.axes {
                    q[a] = w.unpack()[a] + 0.7 / g.inv_cell;
                }
            }
            // Inside the surface and off it along the axes the grid leaves out: never near
            // a cell's vertex, walks of several steps.
            if v % 5 == 1 {
                for (k, x) in q.iter_mut().enumerate() {
                    *x = match g.axes.contains(&k) {
                        true => 32768.0 + (*x - 32768.0) * 0.4,
                        false => *x + 2e4,
                    };
                }
            }
            assert_eq!(g.walk(&q, &p.walk_coords), reference(&q).0, "vertex {v}");
            points.push(q);
            let [d0, d1, d2] = g.dims;
            let c = g.cell_of(&q).0 as u32;
            let (i, j, k) = (c / (d1 * d2), c / d2 % d1, c % d2);
            inner += usize::from(i > 0 && j > 0 && k > 0 && i + 1 < d0 && j + 1 < d1 && k + 1 < d2);
        }
        assert!(inner > 50, "{inner} walks started inside");
        // Interleaved, in groups of every size up to the most: the same walks. Counted:
        // walks of no step, one step, more; walks that end near after a step.
        let mut kinds = [0usize; 4];
        for (n, group) in points.chunks(WALK_GROUP).enumerate() {
            let group = &group[..group.len().min(n % WALK_GROUP + 1)];
            let mut out = [(0, 0.0); WALK_GROUP];
            g.walk_group(group, &mut out[..group.len()]);
            for (q, &got) in group.iter().zip(&out) {
                let (want, steps) = reference(q);
                assert_eq!(got, want);
                kinds[steps.min(2)] += 1;
                kinds[3] += usize::from(steps > 0 && got.1 <= g.near());
            }
        }
        assert!(
            kinds[..3].iter().all(|&k| k > 10) && kinds[3] > 5,
            "{kinds:?}"
        );
        for threads in [1, 3] {
            let pool = rayon::ThreadPoolBuilder::new()
                .num_threads(threads)
                .build()
                .unwrap();
            let q = pool.install(|| StartGrid::new(&p.walk_coords));
            assert_eq!(q.cells, g.cells);
        }
    }

    /// Where the cap binds, the fine cells are built and the start they give is never
    /// farther from the query than the capped grid's, closer for most queries on and off
    /// the surface, and the closest projection does not depend on it.
    #[test]
    fn capped_grids_start_from_the_fine_cell_under_the_query() {
        let m = Arc::new(ValidMesh::new(procedural::icosphere(5)).unwrap());
        let emb = Arc::new(EmbeddedMesh::from_positions(m));
        let mut p = Projector::new(emb.clone()).unwrap();
        assert!(p.starts.fine.is_empty(), "uncapped: no fine cells");
        p.starts = StartGrid::with_max_cells(&p.walk_coords, 4);
        assert!(!p.starts.fine.is_empty());
        let mut coarse = Projector::new(emb.clone()).unwrap();
        coarse.starts = StartGrid::with_max_cells(&coarse.walk_coords, 4);
        coarse.starts.fine = FineCells::default();
        let x = emb.coords();
        let (mut closer, mut queries) = (0, 0);
        for (k, v) in (0..x.len()).step_by(17).enumerate() {
            let scale = [1.0, 1.05, 1.3, 0.9][k % 4];
            let y = x[v] * scale;
            let far = ((v * 7919) % x.len()) as VertexId;
            let (s, s0) = (p.start_near(&y, far), coarse.start_near(&y, far));
            let d = |u: VertexId| (x[u as usize] - y).norm();
            // The walk units round: a start may tie within them.
            assert!(d(s) <= d(s0) + 1e-4, "query {k}: {} > {}", d(s), d(s0));
            closer += usize::from(d(s) < d(s0) - 1e-4);
            queries += 1;
            if k % 5 == 0 {
                assert_eq!(p.project(&y, s), coarse.project(&y, s0), "query {k}");
            }
        }
        assert!(2 * closer > queries, "{closer} of {queries} start closer");
    }
}
