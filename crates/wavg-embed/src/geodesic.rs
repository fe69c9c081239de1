//! Geodesic distances by fast marching (Kimmel & Sethian 1998) on a triangle mesh.
//!
//! # Method
//!
//! The classic first-order scheme: vertices are frozen in order of increasing distance
//! (an indexed binary heap with decrease-key); when a vertex `v` freezes, every unfrozen
//! neighbour `x` is updated
//! * along each edge: `u(x) <= u(v) + |xv|` (Dijkstra), and
//! * across each *update stencil* `(x; v, w)` whose other vertex `w` is frozen: the planar
//!   wavefront through `(v, u(v))`, `(w, u(w))` with unit gradient gives `t`; it is used only
//!   if its characteristic (the direction `-grad u`) lies inside the stencil's angle at `x`
//!   (upwind condition). Otherwise only the edge updates apply (the standard fallback).
//!
//! With the stencil's edge vectors `a = v - x`, `b = w - x`, Gram matrix `G` and `Q = G^-1`,
//! `grad u = [a b] Q (U - t 1)` where `U = (u(v), u(w))`; `|grad u| = 1` is a quadratic in `t`
//! (its larger root), and upwind means both components of `Q (U - t 1)` are `<= 0`.
//!
//! **Obtuse triangles** are handled as Kimmel & Sethian propose: a corner `x` with an angle
//! above 90 degrees is split by a *virtual edge* to a vertex `W` found by unfolding the
//! triangles beyond the opposite edge into the triangle's plane (up to
//! [`MAX_UNFOLD_STEPS`] triangles) until `W` falls inside the section of directions making
//! at most 90 degrees with both edges at `x`. The corner then gets two acute stencils
//! `(x; v, W)` and `(x; W, w)` with the unfolded geometry, and `u(W) + |xW|` (unfolded
//! length) is used as an extra edge update. If the unfolding runs into a boundary or does
//! not find such a vertex, the obtuse stencil is kept as it is (its update is still applied
//! only when upwind). Since every edge update is applied too, the result never exceeds
//! the edge-graph (Dijkstra) distance; a property test checks that, and that it stays
//! above the straight-line distance.
//!
//! # Cost, and geodesics on a coarser mesh
//!
//! One run costs roughly 150-350 ns per vertex on this project's shared 2-core machine
//! (on-CPU time: 1.1-1.4 ms on the 7.5k-vertex pig, 12 ms on the 48k horse, 13-17 ms on
//! the 43k armadillo, 36-38 ms on the 134k igea), so 1000 landmark runs at full
//! resolution take about 38 CPU-seconds on igea. For large meshes,
//! compute the landmark distances on an intermediate decimation of about
//! [`DEFAULT_GEODESIC_VERTICES`] vertices that contains every landmark: either
//! [`landmark_distances_coarse`] (decimates again with the landmarks locked), or, cheaper,
//! a snapshot of the landmark decimation itself
//! ([`crate::decimate::decimate_with_snapshots`]) passed to
//! [`landmark_distances_two_level`]. Both use the coarse mesh for every pair and then
//! recompute the pairs closer than [`NEAR_PAIR_RADIUS_EDGES`] coarse edges on the fine
//! mesh with radius-limited runs ([`FastMarching::run_within`]): on the coarse mesh alone
//! those close pairs were off by up to 20-80%. Measured against full-resolution fast
//! marching (1000 landmarks, 15k-vertex snapshot, two-level): mean relative difference
//! +0.25% (horse), +0.36% (armadillo), +0.52% (igea); 90th percentile 0.58-0.88%; largest
//! 6.4-7.5%. A run on the 15k-vertex mesh costs 3.6-4.8 ms, so the geodesic stage of igea
//! drops from about 38 to about 5 CPU-seconds.
//!
//! **Near the source** the front is strongly curved and a plane wave fits it worst, so each
//! run starts with exact polyhedral distances within [`crate::near_field::NEAR_FIELD_EDGES`]
//! mean edge lengths of the source (windows of Chen & Han with pseudo-sources at saddle
//! vertices and Xin & Wang's pruning, [`crate::near_field`]; the radius is a parameter,
//! [`FastMarching::with_near_field_edges`]). With straight lines only, on a 40k icosphere
//! this lowered the mean error from 0.40-0.52% to 0.21-0.26% and the maximum from 3.9-4.5%
//! to 0.7-0.9%. On pig, camelhead and fertility (1000 landmarks) the largest asymmetry
//! `|d(i,j) - d(j,i)| / mean` went from 8.7-16% (plain) to 5.3-7.3% (straight lines) and
//! 2.7-6.4% (with pseudo-sources), and the pairs above 2% from 0.25-0.87% to 0.01-0.06% and
//! 0.003-0.018%, for 1.1-1.5x the time of a plain run; at 16 edge lengths (3-5x the
//! time) every pair is within 2% (1.4-1.9% at most).
//!
//! All geometry is precomputed once per mesh in [`FastMarching`] (a flat list of
//! update entries per freezing vertex, single precision), so one run only touches the
//! distance array, the heap and that list. [`Workspace`] holds the per-run buffers so that
//! repeated runs do not allocate.

use nalgebra::Vector2;
use rayon::prelude::*;
use wavg_mesh::{NONE, ValidMesh};

use crate::decimate::{DecimateOptions, Decimated, decimate};
use crate::error::{EmbedError, Progress, Stage, check_cancel};
use crate::near_field::{NearField, NearScratch};

/// Vertex count of the intermediate mesh for landmark geodesics on large meshes (see the
/// module documentation), the pipeline's default: about 2.5 ms per fast-marching run.
/// 15 000 costs a third more time for about 0.1-0.2 points less mean error.
pub(crate) const DEFAULT_GEODESIC_VERTICES: usize = 10_000;

/// How many triangles the obtuse-angle unfolding may cross before giving up.
pub(crate) const MAX_UNFOLD_STEPS: usize = 40;

/// One update that freezing a vertex `v` triggers on a neighbour `x`.
///
/// `q_vv, q_vo, q_oo` are the entries of the inverse Gram matrix of the stencil
/// `(x; v, other)` (all zero for an edge-only entry); `len` is `|x - v|` (unfolded for a
/// virtual edge).
#[derive(Clone, Copy, Debug)]
struct Entry {
    x: u32,
    other: u32,
    q_vv: f32,
    q_vo: f32,
    q_oo: f32,
    len: f32,
}

/// Precomputed fast-marching structure of one mesh; reusable for any number of runs, from
/// any number of threads.
///
/// ```
/// use wavg_embed::FastMarching;
/// use wavg_mesh::{ValidMesh, procedural};
/// let mesh = ValidMesh::new(procedural::grid(20, 20, 1.0, 1.0)).unwrap();
/// let fm = FastMarching::new(&mesh);
/// let mut ws = fm.workspace();
/// let d = fm.run(&mut ws, &[0]).to_vec();
/// // Corner to opposite corner of the unit square: sqrt(2) up to discretisation error.
/// assert!((d[440] - 2f64.sqrt()).abs() < 0.02);
/// ```
#[derive(Clone, Debug)]
pub struct FastMarching {
    n: usize,
    offsets: Vec<u32>,
    entries: Vec<Entry>,
    /// Exact distances near a source, by unfolding ([`crate::near_field`]).
    near: NearField,
    /// Number of obtuse corners, and how many of them were split by unfolding.
    obtuse: (usize, usize),
}

/// Per-run buffers (distances, frozen flags, heap). Make one per thread with
/// [`FastMarching::workspace`].
#[derive(Clone, Debug)]
pub struct Workspace {
    dist: Vec<f64>,
    /// `FAR`, `FROZEN`, or the vertex's position in `heap`.
    state: Vec<u32>,
    /// Binary min-heap of vertices by `dist` (each vertex at most once).
    heap: Vec<u32>,
    /// Whether `dist` and `state` are all at their initial values.
    clean: bool,
    /// Vertices frozen by the last [`FastMarching::run_within`], with their distances.
    local: Vec<(u32, f64)>,
    /// Buffers of the near-field unfolding.
    near_out: Vec<(u32, f64)>,
    near_scratch: NearScratch,
    /// Vertices whose near-field length is their exact distance (fast marching must not
    /// lower it: its plane-wave update can undershoot where fronts meet behind a saddle).
    exact: Vec<bool>,
    exact_list: Vec<u32>,
}

/// A stencil `(x; A, B)` with the 2-D (or 3-D, only dot products matter) edge vectors.
struct Stencil {
    x: u32,
    a: u32,
    b: u32,
    /// Gram entries `a.a`, `a.b`, `b.b`.
    g: [f64; 3],
}

impl FastMarching {
    /// Precomputes the update stencils of `mesh` (unfolding obtuse corners).
    pub fn new(mesh: &ValidMesh) -> Self {
        Self::build(mesh, true)
    }

    fn build(mesh: &ValidMesh, unfold_obtuse: bool) -> Self {
        let n = mesh.n_vertices();
        let topo = mesh.topology();
        let pos = &mesh.positions;
        let mut stencils: Vec<Stencil> = Vec::with_capacity(mesh.n_faces() * 3 + 1024);
        let mut virtual_edges: Vec<(u32, u32, f64)> = Vec::new();
        let mut obtuse = (0usize, 0usize);
        for (f, t) in mesh.triangles.iter().enumerate() {
            for k in 0..3 {
                let x = t[k];
                let (a, b) = (t[(k + 1) % 3], t[(k + 2) % 3]);
                let px = pos[x as usize];
                let va = pos[a as usize] - px;
                let vb = pos[b as usize] - px;
                let g = [va.dot(&va), va.dot(&vb), vb.dot(&vb)];
                if g[1] >= 0.0 {
                    stencils.push(Stencil { x, a, b, g });
                    continue;
                }
                obtuse.0 += 1;
                let split = if unfold_obtuse {
                    unfold(mesh, f as u32, k, topo)
                } else {
                    None
                };
                match split {
                    Some((w, a2, w2, b2)) => {
                        obtuse.1 += 1;
                        stencils.push(Stencil {
                            x,
                            a,
                            b: w,
                            g: [a2.dot(&a2), a2.dot(&w2), w2.dot(&w2)],
                        });
                        stencils.push(Stencil {
                            x,
                            a: w,
                            b,
                            g: [w2.dot(&w2), w2.dot(&b2), b2.dot(&b2)],
                        });
                        virtual_edges.push((w, x, w2.norm()));
                    }
                    None => stencils.push(Stencil { x, a, b, g }),
                }
            }
        }
        // Entries grouped by the freezing vertex (counting sort).
        let mut offsets = vec![0u32; n + 1];
        for s in &stencils {
            offsets[s.a as usize + 1] += 1;
            offsets[s.b as usize + 1] += 1;
        }
        for &(w, _, _) in &virtual_edges {
            offsets[w as usize + 1] += 1;
        }
        for i in 0..n {
            offsets[i + 1] += offsets[i];
        }
        let mut fill: Vec<u32> = offsets[..n].to_vec();
        let empty = Entry {
            x: 0,
            other: 0,
            q_vv: 0.0,
            q_vo: 0.0,
            q_oo: 0.0,
            len: 0.0,
        };
        let mut entries = vec![empty; offsets[n] as usize];
        let mut put = |v: u32, e: Entry| {
            entries[fill[v as usize] as usize] = e;
            fill[v as usize] += 1;
        };
        for s in &stencils {
            let [gaa, gab, gbb] = s.g;
            let det = gaa * gbb - gab * gab;
            // Degenerate (sliver) stencils only contribute their edges.
            let q = if det > 1e-12 * gaa * gbb && det > 0.0 {
                [gbb / det, -gab / det, gaa / det]
            } else {
                [0.0; 3]
            };
            let (la, lb) = (gaa.sqrt() as f32, gbb.sqrt() as f32);
            put(
                s.a,
                Entry {
                    x: s.x,
                    other: s.b,
                    q_vv: q[0] as f32,
                    q_vo: q[1] as f32,
                    q_oo: q[2] as f32,
                    len: la,
                },
            );
            put(
                s.b,
                Entry {
                    x: s.x,
                    other: s.a,
                    q_vv: q[2] as f32,
                    q_vo: q[1] as f32,
                    q_oo: q[0] as f32,
                    len: lb,
                },
            );
        }
        for &(w, x, len) in &virtual_edges {
            put(
                w,
                Entry {
                    x,
                    other: x,
                    len: len as f32,
                    ..empty
                },
            );
        }
        for v in 0..n {
            entries[offsets[v] as usize..offsets[v + 1] as usize].sort_by_key(|e| e.x);
        }
        let near = NearField::new(mesh);
        Self {
            n,
            offsets,
            entries,
            near,
            obtuse,
        }
    }

    /// Number of vertices of the mesh.
    pub fn n_vertices(&self) -> usize {
        self.n
    }

    /// This fast marching with its exact near field reaching `edges` mean edge lengths
    /// from each source instead of [`NEAR_FIELD_EDGES`](crate::near_field::NEAR_FIELD_EDGES)
    /// (0 turns it off). A wider near field costs more per run (3-5x the plain fast
    /// marching at 16 edge lengths on real meshes, 1.1-1.5x at 8) and is exact further out.
    ///
    /// ```
    /// use wavg_embed::FastMarching;
    /// use wavg_mesh::{ValidMesh, procedural};
    /// let mesh = ValidMesh::new(procedural::grid(40, 40, 1.0, 1.0)).unwrap();
    /// let fm = FastMarching::new(&mesh).with_near_field_edges(16.0);
    /// let mut ws = fm.workspace();
    /// // 12 x 9 cells away: beyond the default radius, within this one, so exact.
    /// let d = fm.run(&mut ws, &[0])[9 * 41 + 12];
    /// assert!((d - (0.3f64.powi(2) + 0.225f64.powi(2)).sqrt()).abs() < 1e-12);
    /// ```
    pub fn with_near_field_edges(mut self, edges: f64) -> Self {
        self.near.set_radius_edges(edges);
        self
    }

    /// `(obtuse corners, obtuse corners split by unfolding)`, for diagnostics.
    pub fn obtuse_corners(&self) -> (usize, usize) {
        self.obtuse
    }

    /// Fresh per-run buffers for this mesh.
    pub fn workspace(&self) -> Workspace {
        Workspace {
            dist: vec![f64::INFINITY; self.n],
            state: vec![FAR; self.n],
            heap: Vec::with_capacity(1024),
            clean: true,
            local: Vec::new(),
            near_out: Vec::new(),
            near_scratch: NearScratch::default(),
            exact: vec![false; self.n],
            exact_list: Vec::new(),
        }
    }

    /// Distances from the nearest of `sources` to every vertex (`INFINITY` where
    /// unreachable); returns a view into `ws`. Out-of-range source ids are ignored.
    pub fn run<'w>(&self, ws: &'w mut Workspace, sources: &[u32]) -> &'w [f64] {
        self.run_until(ws, sources, Stop::Never);
        &ws.dist
    }

    /// Fast marching from `sources` that stops beyond distance `radius`; returns the frozen
    /// vertices (exact fast-marching distance `<= radius`), in order of distance. Costs
    /// time in proportion to the area covered, not to the mesh size.
    pub fn run_within<'w>(
        &self,
        ws: &'w mut Workspace,
        sources: &[u32],
        radius: f64,
    ) -> &'w [(u32, f64)] {
        ws.local.clear();
        self.run_until(ws, sources, Stop::Beyond(radius));
        // Everything touched is either frozen (listed) or still in the heap: reset those.
        let Workspace {
            dist,
            state,
            heap,
            local,
            clean,
            ..
        } = ws;
        for &v in heap.iter() {
            dist[v as usize] = f64::INFINITY;
            state[v as usize] = FAR;
        }
        heap.clear();
        for &(v, _) in local.iter() {
            dist[v as usize] = f64::INFINITY;
            state[v as usize] = FAR;
        }
        *clean = true;
        &ws.local
    }

    /// Like [`run`](Self::run), but stops as soon as every vertex flagged in `targets`
    /// (`targets[v] == true`, `n_targets` of them) is frozen. Distances of vertices not yet
    /// frozen are then upper bounds (or `INFINITY`).
    pub fn run_until_targets<'w>(
        &self,
        ws: &'w mut Workspace,
        sources: &[u32],
        targets: &[bool],
        n_targets: usize,
    ) -> &'w [f64] {
        self.run_until(ws, sources, Stop::Targets(targets, n_targets));
        &ws.dist
    }

    fn run_until(&self, ws: &mut Workspace, sources: &[u32], stop: Stop) {
        if !ws.clean {
            ws.dist.fill(f64::INFINITY);
            ws.state.fill(FAR);
        }
        ws.clean = matches!(stop, Stop::Beyond(_));
        ws.heap.clear();
        for &s in sources {
            if (s as usize) < self.n && ws.dist[s as usize] != 0.0 {
                ws.dist[s as usize] = 0.0;
                ws.push_or_decrease(s);
            }
        }
        // Exact values near each source, where a plane wave approximates the circular
        // front worst.
        for &v in &ws.exact_list {
            ws.exact[v as usize] = false;
        }
        ws.exact_list.clear();
        // With one source, complete near-field lengths are exact distances.
        let single = sources.len() == 1;
        for &s in sources {
            if (s as usize) < self.n {
                let mut out = std::mem::take(&mut ws.near_out);
                let complete = self.near.candidates(s, &mut out, &mut ws.near_scratch);
                for &(x, d) in &out {
                    if d < ws.dist[x as usize] {
                        ws.dist[x as usize] = d;
                        ws.push_or_decrease(x);
                    }
                    if single && complete {
                        ws.exact[x as usize] = true;
                        ws.exact_list.push(x);
                    }
                }
                out.clear();
                ws.near_out = out;
            }
        }
        let mut remaining = match stop {
            Stop::Targets(_, k) => k,
            _ => usize::MAX,
        };
        if remaining == 0 {
            return;
        }
        while let Some(v) = ws.pop() {
            let vi = v as usize;
            let uv = ws.dist[vi];
            match stop {
                Stop::Never => {}
                Stop::Targets(targets, _) => {
                    if targets[vi] {
                        remaining -= 1;
                        if remaining == 0 {
                            return;
                        }
                    }
                }
                Stop::Beyond(r) => {
                    if uv > r {
                        // Not part of the result: back to the heap's bookkeeping for reset.
                        ws.state[vi] = FAR;
                        ws.heap.push(v);
                        return;
                    }
                    ws.local.push((v, uv));
                }
            }
            // Start loading the entries of the likely next vertex while this one is processed.
            if let Some(&w) = ws.heap.first() {
                let o = self.offsets[w as usize] as usize;
                if let Some(e) = self.entries.get(o) {
                    std::hint::black_box(e.x);
                }
            }
            // Entries are grouped by neighbour `x`: one frozen check and one heap update per
            // neighbour.
            let end = self.offsets[vi + 1] as usize;
            let mut i = self.offsets[vi] as usize;
            while i < end {
                let x = self.entries[i].x;
                let xi = x as usize;
                let mut j = i + 1;
                while j < end && self.entries[j].x == x {
                    j += 1;
                }
                if ws.state[xi] != FROZEN && !ws.exact[xi] {
                    let mut cand = f64::INFINITY;
                    for e in &self.entries[i..j] {
                        cand = cand.min(uv + e.len as f64);
                        let oi = e.other as usize;
                        if e.q_vv > 0.0 && ws.state[oi] == FROZEN {
                            if let Some(t) = triangle_update(uv, ws.dist[oi], e) {
                                cand = cand.min(t);
                            }
                        }
                    }
                    if cand < ws.dist[xi] {
                        ws.dist[xi] = cand;
                        ws.push_or_decrease(x);
                    }
                }
                i = j;
            }
        }
    }
}

/// When a run stops early.
#[derive(Clone, Copy)]
enum Stop<'a> {
    /// Run to the end.
    Never,
    /// Once all `n` flagged vertices are frozen.
    Targets(&'a [bool], usize),
    /// Once the next vertex to freeze is farther than this.
    Beyond(f64),
}

/// `Workspace::state` of a vertex not yet reached.
const FAR: u32 = u32::MAX;
/// `Workspace::state` of a frozen vertex (otherwise: its position in the heap).
const FROZEN: u32 = u32::MAX - 1;

impl Workspace {
    /// Inserts `v` into the heap or moves it up after its distance decreased.
    #[inline]
    fn push_or_decrease(&mut self, v: u32) {
        let mut i = match self.state[v as usize] {
            FAR => {
                self.heap.push(v);
                self.heap.len() - 1
            }
            p => p as usize,
        };
        let d = self.dist[v as usize];
        while i > 0 {
            let p = (i - 1) / 2;
            let pv = self.heap[p];
            if self.dist[pv as usize] <= d {
                break;
            }
            self.heap[i] = pv;
            self.state[pv as usize] = i as u32;
            i = p;
        }
        self.heap[i] = v;
        self.state[v as usize] = i as u32;
    }

    /// Removes the vertex of smallest distance and marks it frozen.
    #[inline]
    fn pop(&mut self) -> Option<u32> {
        let top = *self.heap.first()?;
        self.state[top as usize] = FROZEN;
        let last = self.heap.pop().expect("non-empty");
        let n = self.heap.len();
        if n > 0 {
            let d = self.dist[last as usize];
            let mut i = 0;
            loop {
                let l = 2 * i + 1;
                if l >= n {
                    break;
                }
                let r = l + 1;
                let c = if r < n
                    && self.dist[self.heap[r] as usize] < self.dist[self.heap[l] as usize]
                {
                    r
                } else {
                    l
                };
                let cv = self.heap[c];
                if self.dist[cv as usize] >= d {
                    break;
                }
                self.heap[i] = cv;
                self.state[cv as usize] = i as u32;
                i = c;
            }
            self.heap[i] = last;
            self.state[last as usize] = i as u32;
        }
        Some(top)
    }
}

/// The planar-wavefront value at `x` from frozen values `uv` (at `v`) and `uo` (at the
/// stencil's other vertex), or `None` when the characteristic is not inside the stencil.
#[inline(always)]
fn triangle_update(uv: f64, uo: f64, e: &Entry) -> Option<f64> {
    let (qvv, qvo, qoo) = (e.q_vv as f64, e.q_vo as f64, e.q_oo as f64);
    // Shift so that u(v) = 0: t' = t - uv, delta = uo - uv.
    let delta = uo - uv;
    let a = qvv + 2.0 * qvo + qoo;
    let b = (qvo + qoo) * delta;
    let c = qoo * delta * delta - 1.0;
    let disc = b * b - a * c;
    if disc < 0.0 || a <= 0.0 {
        return None;
    }
    let t = (b + disc.sqrt()) / a;
    // Upwind: Q (U - t 1) <= 0 componentwise, with U - t 1 = (-t, delta - t).
    let g0 = -qvv * t + qvo * (delta - t);
    let g1 = -qvo * t + qoo * (delta - t);
    if g0 <= 0.0 && g1 <= 0.0 && t >= delta.max(0.0) {
        Some(uv + t)
    } else {
        None
    }
}

/// The vertex `W` found by unfolding, and the 2-D vectors from `x` to `A`, `W`, `B`.
type Split = (u32, Vector2<f64>, Vector2<f64>, Vector2<f64>);

/// Splits the obtuse corner `k` of face `f` (Kimmel & Sethian's unfolding). Returns the
/// vertex `W` found and the 2-D vectors from `x` to `A`, `W`, `B` in the unfolded plane.
fn unfold(mesh: &ValidMesh, f: u32, k: usize, topo: &wavg_mesh::Topology) -> Option<Split> {
    let pos = &mesh.positions;
    let t = mesh.triangles[f as usize];
    let x = t[k];
    let (a, b) = (t[(k + 1) % 3], t[(k + 2) % 3]);
    let px = pos[x as usize];
    let va = pos[a as usize] - px;
    let vb = pos[b as usize] - px;
    let la = va.norm();
    let a2 = Vector2::new(la, 0.0);
    let b2 = Vector2::new(va.dot(&vb) / la, va.cross(&vb).norm() / la);
    // Current edge (p, r) with p on A's side and r on B's side, crossed from face `face`.
    let (mut p, mut r) = (a, b);
    let (mut p2, mut r2) = (a2, b2);
    let mut face = f;
    for _ in 0..MAX_UNFOLD_STEPS {
        let next = across(mesh, topo, face, p, r)?;
        let tn = mesh.triangles[next as usize];
        let w = tn.into_iter().find(|&v| v != p && v != r)?;
        if w == x {
            return None;
        }
        let w2 = crate::near_field::place(
            &p2,
            &r2,
            (pos[w as usize] - pos[p as usize]).norm(),
            (pos[w as usize] - pos[r as usize]).norm(),
        )?;
        let (da, db) = (w2.dot(&a2), w2.dot(&b2));
        if da > 0.0 && db > 0.0 {
            return Some((w, a2, w2, b2));
        }
        if db <= 0.0 {
            // W is on A's side of the section: continue across (W, r).
            p = w;
            p2 = w2;
        } else {
            r = w;
            r2 = w2;
        }
        face = next;
    }
    None
}

/// The face on the other side of edge `{p, r}` of `face`, if any.
fn across(mesh: &ValidMesh, topo: &wavg_mesh::Topology, face: u32, p: u32, r: u32) -> Option<u32> {
    let t = mesh.triangles[face as usize];
    for i in 0..3 {
        let (s, e) = (t[i], t[(i + 1) % 3]);
        if (s == p && e == r) || (s == r && e == p) {
            let g = topo.face_neighbors(face)[i];
            return (g != NONE).then_some(g);
        }
    }
    None
}

/// Fast-marching distances from the nearest of `sources` to every vertex of `mesh`
/// (`f64::INFINITY` for vertices in other components). Out-of-range source ids are ignored;
/// with no valid source every distance is infinite.
///
/// For many runs on one mesh, build a [`FastMarching`] once instead.
///
/// ```
/// use wavg_embed::distances_from;
/// use wavg_mesh::{ValidMesh, procedural};
/// let sphere = ValidMesh::new(procedural::icosphere(4)).unwrap();
/// let d = distances_from(&sphere, &[0]);
/// let p0 = sphere.positions[0];
/// // Antipode of vertex 0: half the great circle, pi.
/// let far = (0..d.len()).min_by(|&a, &b| sphere.positions[a].dot(&p0).total_cmp(&sphere.positions[b].dot(&p0))).unwrap();
/// assert!((d[far] - std::f64::consts::PI).abs() < 0.03);
/// ```
pub fn distances_from(mesh: &ValidMesh, sources: &[u32]) -> Vec<f64> {
    let fm = FastMarching::new(mesh);
    let mut ws = fm.workspace();
    fm.run(&mut ws, sources);
    ws.dist
}

/// Geodesic distances between all pairs of `landmarks`, symmetrised: the `n x n` matrix
/// `Q = (D + D^T) / 2` row-major (`n = landmarks.len()`), where row `i` of `D` is one fast
/// marching run from landmark `i`. Runs go in parallel (rayon), each stopping once all
/// landmarks are frozen; progress is reported as [`Stage::Geodesics`] and cancellation is
/// checked between runs.
///
/// Errors: a landmark id out of range or repeated, or a pair of landmarks in different
/// components (infinite distance).
pub fn landmark_distances(
    mesh: &ValidMesh,
    landmarks: &[u32],
    progress: &dyn Progress,
) -> Result<Vec<f64>, EmbedError> {
    let fm = FastMarching::new(mesh);
    landmark_distances_with(&fm, landmarks, progress)
}

/// [`landmark_distances`] with a prebuilt [`FastMarching`] (of the same mesh).
pub fn landmark_distances_with(
    fm: &FastMarching,
    landmarks: &[u32],
    progress: &dyn Progress,
) -> Result<Vec<f64>, EmbedError> {
    let rows = landmark_rows(fm, landmarks, progress)?;
    let n = landmarks.len();
    let mut q = vec![0.0; n * n];
    for i in 0..n {
        for j in 0..n {
            q[i * n + j] = 0.5 * (rows[i][j] + rows[j][i]);
        }
        q[i * n + i] = 0.0;
    }
    if let Some(k) = q.iter().position(|d| !d.is_finite()) {
        return Err(EmbedError::InvalidArgument(format!(
            "landmarks {} and {} are in different components (no geodesic between them); \
             keep only one component (`--largest-component`)",
            landmarks[k / n],
            landmarks[k % n]
        )));
    }
    Ok(q)
}

/// The raw rows behind [`landmark_distances_with`]: row `i` holds the fast-marching
/// distances from `landmarks[i]` to every landmark, not symmetrised (`rows[i][j]` and
/// `rows[j][i]` differ by the method's error). Runs in parallel, each stopping once every
/// landmark is reached; progress is reported as [`Stage::Geodesics`].
///
/// Errors: a landmark id out of range or repeated, or cancellation.
///
/// ```
/// use wavg_embed::NoProgress;
/// use wavg_embed::{FastMarching, internal::landmark_rows};
/// use wavg_mesh::{ValidMesh, procedural};
/// let mesh = ValidMesh::new(procedural::icosphere(3)).unwrap();
/// let rows = landmark_rows(&FastMarching::new(&mesh), &[0, 5, 100], &NoProgress).unwrap();
/// assert_eq!(rows[1][1], 0.0);
/// assert!((rows[0][2] - rows[2][0]).abs() < 0.02 * rows[0][2]);
/// ```
pub fn landmark_rows(
    fm: &FastMarching,
    landmarks: &[u32],
    progress: &dyn Progress,
) -> Result<Vec<Vec<f64>>, EmbedError> {
    let n = landmarks.len();
    let mut is_target = vec![false; fm.n];
    for &l in landmarks {
        let slot = is_target.get_mut(l as usize).ok_or_else(|| {
            EmbedError::InvalidArgument(format!(
                "landmark {l} out of range (mesh has {} vertices)",
                fm.n
            ))
        })?;
        if std::mem::replace(slot, true) {
            return Err(EmbedError::InvalidArgument(format!(
                "landmark {l} appears twice"
            )));
        }
    }
    check_cancel(progress)?;
    let done = std::sync::atomic::AtomicUsize::new(0);
    let rows: Vec<Vec<f64>> = (0..n)
        .into_par_iter()
        .map_init(
            || fm.workspace(),
            |ws, i| {
                check_cancel(progress)?;
                let d = fm.run_until_targets(ws, &landmarks[i..i + 1], &is_target, n);
                let row: Vec<f64> = landmarks.iter().map(|&l| d[l as usize]).collect();
                let k = done.fetch_add(1, std::sync::atomic::Ordering::Relaxed) + 1;
                progress.report(Stage::Geodesics, k as f64 / n as f64);
                Ok(row)
            },
        )
        .collect::<Result<_, EmbedError>>()?;
    Ok(rows)
}

/// Landmark pairs closer than this many mean edge lengths of the coarse mesh get their
/// distance from the fine mesh in [`landmark_distances_two_level`].
pub(crate) const NEAR_PAIR_RADIUS_EDGES: f64 = 8.0;

/// [`landmark_distances`] computed on a coarser mesh, to save time on large meshes: the
/// mesh is first decimated (with the landmarks locked, so they all survive) down to
/// `intermediate_vertices`, and the distances come from
/// [`landmark_distances_two_level`]. With `intermediate_vertices >=` the vertex count this
/// is exactly [`landmark_distances`].
pub fn landmark_distances_coarse(
    mesh: &ValidMesh,
    landmarks: &[u32],
    intermediate_vertices: usize,
    progress: &dyn Progress,
) -> Result<Vec<f64>, EmbedError> {
    if intermediate_vertices >= mesh.n_vertices() {
        return landmark_distances(mesh, landmarks, progress);
    }
    let opts = DecimateOptions {
        target: intermediate_vertices.max(landmarks.len()),
        locked: landmarks.to_vec(),
        ..DecimateOptions::default()
    };
    let coarse = decimate(mesh, &opts, &CancelOnly(progress))?;
    landmark_distances_two_level(&FastMarching::new(mesh), &coarse, landmarks, progress)
}

/// Landmark distances from two resolutions: every pair from fast marching on `coarse` (a
/// decimation of the fine mesh containing all landmarks, for example a snapshot of the
/// landmark decimation, [`crate::decimate::decimate_with_snapshots`]), then pairs closer
/// than `NEAR_PAIR_RADIUS_EDGES` (8) coarse edge lengths replaced by fine-mesh values from
/// short radius-limited runs on `fine` (the coarse mesh's few large triangles between
/// close landmarks give errors of 20-80% there, and MDS weights close pairs most). The
/// fine runs cost little: each covers only a small disc.
pub fn landmark_distances_two_level(
    fine: &FastMarching,
    coarse: &Decimated,
    landmarks: &[u32],
    progress: &dyn Progress,
) -> Result<Vec<f64>, EmbedError> {
    let mut q = landmark_distances_decimated(coarse, landmarks, progress)?;
    let radius = NEAR_PAIR_RADIUS_EDGES * wavg_mesh::geometry::mean_edge_length(&coarse.mesh);
    refine_near_pairs(fine, landmarks, radius, &mut q, progress)?;
    Ok(q)
}

/// Overwrites the entries of the symmetric `n x n` matrix `q` for landmark pairs within
/// `radius` of each other on `fine` with fine-mesh fast-marching distances (averaged over
/// both directions when both runs reach the other landmark). Returns the number of pairs
/// replaced.
pub(crate) fn refine_near_pairs(
    fine: &FastMarching,
    landmarks: &[u32],
    radius: f64,
    q: &mut [f64],
    progress: &dyn Progress,
) -> Result<usize, EmbedError> {
    let n = landmarks.len();
    if q.len() != n * n {
        return Err(EmbedError::InvalidArgument(format!(
            "distance matrix has {} entries, expected {n} x {n}",
            q.len()
        )));
    }
    let mut index = vec![NONE; fine.n];
    for (i, &l) in landmarks.iter().enumerate() {
        let slot = index
            .get_mut(l as usize)
            .ok_or_else(|| EmbedError::InvalidArgument(format!("landmark {l} out of range")))?;
        *slot = i as u32;
    }
    let rows: Vec<Vec<(u32, f64)>> = (0..n)
        .into_par_iter()
        .map_init(
            || fine.workspace(),
            |ws, i| {
                check_cancel(progress)?;
                let local = fine.run_within(ws, &landmarks[i..i + 1], radius);
                Ok(local
                    .iter()
                    .filter(|&&(v, _)| index[v as usize] != NONE && index[v as usize] != i as u32)
                    .map(|&(v, d)| (index[v as usize], d))
                    .collect())
            },
        )
        .collect::<Result<_, EmbedError>>()?;
    // Pair (i, j) -> sum of the fine distances found and how many.
    let mut acc: std::collections::HashMap<(u32, u32), (f64, u32)> = Default::default();
    for (i, row) in rows.iter().enumerate() {
        for &(j, d) in row {
            let key = ((i as u32).min(j), (i as u32).max(j));
            let e = acc.entry(key).or_insert((0.0, 0));
            e.0 += d;
            e.1 += 1;
        }
    }
    for (&(i, j), &(sum, k)) in &acc {
        let d = sum / f64::from(k);
        q[i as usize * n + j as usize] = d;
        q[j as usize * n + i as usize] = d;
    }
    Ok(acc.len())
}

/// [`landmark_distances`] on an already decimated mesh only (no fine-mesh correction of
/// close pairs, see [`landmark_distances_two_level`]); `landmarks` are original vertex ids
/// and must all be vertices of `coarse`.
pub(crate) fn landmark_distances_decimated(
    coarse: &Decimated,
    landmarks: &[u32],
    progress: &dyn Progress,
) -> Result<Vec<f64>, EmbedError> {
    let ids = landmarks
        .iter()
        .map(|&l| {
            coarse.coarse_index(l).ok_or_else(|| {
                EmbedError::InvalidArgument(format!(
                    "landmark {l} is not a vertex of the decimated mesh"
                ))
            })
        })
        .collect::<Result<Vec<u32>, _>>()?;
    let mesh = ValidMesh::new(coarse.mesh.clone())
        .map_err(|e| EmbedError::Numerical(format!("the decimated mesh is not valid: {e}")))?;
    landmark_distances(&mesh, &ids, progress)
}

/// Forwards cancellation but not progress (for a sub-step reported as part of another stage).
struct CancelOnly<'a>(&'a dyn Progress);

impl Progress for CancelOnly<'_> {
    fn report(&self, _stage: Stage, _fraction: f64) {}
    fn cancelled(&self) -> bool {
        self.0.cancelled()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::error::NoProgress;
    use nalgebra::Vector3;
    use proptest::prelude::*;
    use std::cmp::Reverse;
    use std::collections::BinaryHeap;
    use wavg_mesh::{TriMesh, procedural};

    fn valid(m: TriMesh) -> ValidMesh {
        ValidMesh::new(m).unwrap()
    }

    /// Mean and max relative error of `d` against `exact` over vertices with exact > `min`.
    fn rel_err(d: &[f64], exact: &[f64], min: f64) -> (f64, f64) {
        let (mut sum, mut max, mut k) = (0.0, 0.0f64, 0);
        for (a, e) in d.iter().zip(exact) {
            if *e > min {
                let r = (a - e).abs() / e;
                sum += r;
                max = max.max(r);
                k += 1;
            }
        }
        (sum / k as f64, max)
    }

    /// Plain Dijkstra on the edge graph (reference upper bound).
    fn dijkstra(mesh: &ValidMesh, s: u32) -> Vec<f64> {
        let mut d = vec![f64::INFINITY; mesh.n_vertices()];
        let mut h = BinaryHeap::new();
        d[s as usize] = 0.0;
        h.push(Reverse((0u64, s)));
        while let Some(Reverse((k, v))) = h.pop() {
            if k != d[v as usize].to_bits() {
                continue;
            }
            for &w in mesh.topology().ring(v) {
                let c = d[v as usize]
                    + (mesh.positions[v as usize] - mesh.positions[w as usize]).norm();
                if c < d[w as usize] {
                    d[w as usize] = c;
                    h.push(Reverse((c.to_bits(), w)));
                }
            }
        }
        d
    }

    #[test]
    fn icosphere_matches_great_circle_distance() {
        let mesh = valid(procedural::icosphere(6));
        assert_eq!(mesh.n_vertices(), 40962);
        let fm = FastMarching::new(&mesh);
        let mut ws = fm.workspace();
        let (mut worst_mean, mut worst_max) = (0.0f64, 0.0f64);
        for s in [0u32, 12345, 40000] {
            let d = fm.run(&mut ws, &[s]);
            let ps = mesh.positions[s as usize];
            let exact: Vec<f64> = mesh
                .positions
                .iter()
                .map(|p| p.dot(&ps).clamp(-1.0, 1.0).acos())
                .collect();
            let (mean, max) = rel_err(d, &exact, 1e-9);
            let (mean_far, _) = rel_err(d, &exact, 0.2);
            eprintln!(
                "icosphere(6) 40962 v, source {s}: mean rel err {:.4}%, beyond 0.2 rad {:.4}%, max {:.2}%",
                mean * 100.0,
                mean_far * 100.0,
                max * 100.0
            );
            worst_mean = worst_mean.max(mean);
            worst_max = worst_max.max(max);
        }
        // Measured 0.21-0.26% mean, 0.7-0.9% max with the exact near field (0.40-0.52%
        // and 3.9-4.5% without).
        assert!(worst_mean < 0.005, "mean relative error {worst_mean}");
        assert!(worst_max < 0.02, "max relative error {worst_max}");
    }

    /// Mean relative error against the Euclidean distance over all vertices and over those
    /// farther than 10 mean edge lengths, worst over `sources`.
    fn plane_errors(
        mesh: &ValidMesh,
        fm: &FastMarching,
        sources: &[u32],
        label: &str,
    ) -> (f64, f64) {
        let mut ws = fm.workspace();
        let h = wavg_mesh::geometry::mean_edge_length(mesh);
        let (mut worst, mut worst_far) = (0.0f64, 0.0f64);
        for &s in sources {
            let d = fm.run(&mut ws, &[s]);
            let ps = mesh.positions[s as usize];
            let exact: Vec<f64> = mesh.positions.iter().map(|p| (p - ps).norm()).collect();
            let (mean, max) = rel_err(d, &exact, 1e-12);
            let (mean_far, _) = rel_err(d, &exact, 10.0 * h);
            // In the plane the geodesic is the straight line; first-order fast marching may
            // undershoot it only slightly.
            for (a, e) in d.iter().zip(&exact) {
                assert!(*a >= e * (1.0 - 1e-2), "{label}: {a} < euclidean {e}");
            }
            eprintln!(
                "{label} ({} v, obtuse corners / split {:?}), source {s}: mean rel err {:.3}%, beyond 10 h {:.3}%, max {:.1}%",
                mesh.n_vertices(),
                fm.obtuse_corners(),
                mean * 100.0,
                mean_far * 100.0,
                max * 100.0
            );
            worst = worst.max(mean);
            worst_far = worst_far.max(mean_far);
        }
        (worst, worst_far)
    }

    #[test]
    fn flat_grid_matches_euclidean_distance() {
        let mesh = valid(procedural::grid(120, 80, 3.0, 2.0));
        let center = 40 * 121 + 60;
        let fm = FastMarching::new(&mesh);
        let (worst, _) = plane_errors(&mesh, &fm, &[0, center, 121 * 81 - 1], "grid 120x80");
        assert!(worst < 0.01, "{worst}");
    }

    fn sheared(shear: f64, squash: f64) -> ValidMesh {
        valid(
            procedural::grid(120, 80, 1.0, 1.0)
                .map_positions(|p| Vector3::new(p.x + shear * p.y, squash * p.y, 0.0)),
        )
    }

    #[test]
    fn sheared_grids_with_obtuse_triangles_match_euclidean_distance() {
        let sources = [0, 40 * 121 + 60, 121 * 81 - 1];
        // Half of the triangles have a 130 degree corner.
        let mesh = sheared(0.5, 0.6);
        let fm = FastMarching::new(&mesh);
        let (obtuse, split) = fm.obtuse_corners();
        assert!(obtuse == 9600 && split == obtuse, "{obtuse} {split}");
        let (mean, _) = plane_errors(&mesh, &fm, &sources, "grid sheared to 130 deg");
        let plain = FastMarching::build(&mesh, false);
        let (mean_plain, _) = plane_errors(&mesh, &plain, &sources, "  same without unfolding");
        assert!(mean < 0.01, "{mean}");
        assert!(
            mean < mean_plain,
            "unfolding should help: {mean} vs {mean_plain}"
        );
        // Extreme: 167 degree corners. Near the source the error is large (vertices closer
        // than the shortest edge are not neighbours), farther away it is small.
        let mesh = sheared(1.5, 0.35);
        let fm = FastMarching::new(&mesh);
        let (_, far) = plane_errors(&mesh, &fm, &sources, "grid sheared to 167 deg");
        let plain = FastMarching::build(&mesh, false);
        let (_, far_plain) = plane_errors(&mesh, &plain, &sources, "  same without unfolding");
        assert!(far < 0.01, "{far}");
        assert!(
            far < far_plain,
            "unfolding should help: {far} vs {far_plain}"
        );
    }

    #[test]
    fn noisy_anisotropic_triangulation_in_the_plane() {
        // 4:1 cells, vertices jittered in the plane: acute and obtuse triangles of all shapes.
        let (nx, ny) = (160u32, 40u32);
        let base = procedural::grid(nx, ny, 1.0, 1.0);
        let noisy = procedural::with_noise(base.clone(), 0.25, 3);
        let w = nx as usize + 1;
        let pos = noisy
            .positions
            .iter()
            .zip(&base.positions)
            .enumerate()
            .map(|(i, (n, b))| {
                // Keep the boundary straight so that the domain stays convex.
                let (ix, iy) = (i % w, i / w);
                let on_b = ix == 0 || ix == nx as usize || iy == 0 || iy == ny as usize;
                if on_b {
                    *b
                } else {
                    Vector3::new(n.x, n.y, 0.0)
                }
            })
            .collect();
        let mesh = valid(TriMesh::new(pos, base.triangles.clone()));
        let fm = FastMarching::new(&mesh);
        let sources = [0, 20 * w as u32 + 80, 7 * w as u32 + 150];
        let (worst, _) = plane_errors(&mesh, &fm, &sources, "jittered 4:1 grid");
        let plain = FastMarching::build(&mesh, false);
        let (worst_plain, _) = plane_errors(&mesh, &plain, &sources, "  same without unfolding");
        // Heavy jitter (40% of the short edges): first-order fast marching loses accuracy.
        assert!(
            worst < 0.025 && worst < worst_plain,
            "{worst} {worst_plain}"
        );
    }

    #[test]
    fn radius_limited_runs_match_full_runs_and_leave_the_workspace_clean() {
        let mesh = valid(procedural::with_noise(procedural::icosphere(4), 0.3, 3));
        let fm = FastMarching::new(&mesh);
        let mut ws = fm.workspace();
        let full = fm.run(&mut ws, &[17]).to_vec();
        for (src, r) in [(17u32, 0.3), (100, 0.05), (2000, 10.0), (5, 0.0)] {
            let reference = fm.run(&mut fm.workspace(), &[src]).to_vec();
            let local = fm.run_within(&mut ws, &[src], r).to_vec();
            let inside = reference.iter().filter(|&&d| d <= r).count();
            assert_eq!(local.len(), inside, "radius {r}");
            for &(v, d) in &local {
                assert_eq!(d, reference[v as usize]);
            }
            assert!(local.windows(2).all(|w| w[0].1 <= w[1].1));
        }
        // The workspace is clean again: a full run gives the same as before.
        assert_eq!(fm.run(&mut ws, &[17]), &full[..]);
        let again = fm.run_within(&mut ws, &[17], 0.3).to_vec();
        assert!(again.iter().all(|&(v, d)| d == full[v as usize]));
    }

    #[test]
    fn disconnected_components_are_unreachable() {
        let a = procedural::icosphere(2);
        let mut b = procedural::icosphere(2).map_positions(|p| p + Vector3::new(5.0, 0.0, 0.0));
        let off = a.n_vertices() as u32;
        for t in &mut b.triangles {
            *t = t.map(|v| v + off);
        }
        let mut m = a.clone();
        m.positions.extend(b.positions);
        m.triangles.extend(b.triangles);
        let mesh = valid(m);
        let d = distances_from(&mesh, &[0]);
        assert!(d[..off as usize].iter().all(|x| x.is_finite()));
        assert!(d[off as usize..].iter().all(|x| *x == f64::INFINITY));
        let e = landmark_distances(&mesh, &[0, off + 3], &NoProgress).unwrap_err();
        assert!(matches!(e, EmbedError::InvalidArgument(_)), "{e}");
    }

    #[test]
    fn no_valid_source_gives_infinity_everywhere() {
        let mesh = valid(procedural::icosphere(1));
        let d = distances_from(&mesh, &[1000]);
        assert!(d.iter().all(|x| x.is_infinite()));
        let d = distances_from(&mesh, &[]);
        assert!(d.iter().all(|x| x.is_infinite()));
    }

    #[test]
    fn multi_source_is_the_minimum_of_single_sources() {
        let mesh = valid(procedural::with_noise(procedural::icosphere(4), 0.3, 9));
        let fm = FastMarching::new(&mesh);
        let mut ws = fm.workspace();
        let srcs = [3u32, 700, 1500];
        let singles: Vec<Vec<f64>> = srcs
            .iter()
            .map(|&s| fm.run(&mut ws, &[s]).to_vec())
            .collect();
        let multi = fm.run(&mut ws, &srcs).to_vec();
        let h = wavg_mesh::geometry::mean_edge_length(&mesh);
        for v in 0..mesh.n_vertices() {
            let m = singles.iter().map(|d| d[v]).fold(f64::INFINITY, f64::min);
            // Fronts meeting may interact through a triangle update (slightly lower value).
            assert!(
                multi[v] <= m + 1e-12 && multi[v] >= m - 0.2 * h,
                "{v}: {} vs {m}",
                multi[v]
            );
        }
        for &s in &srcs {
            assert_eq!(multi[s as usize], 0.0);
        }
    }

    #[test]
    fn landmark_matrix_is_nearly_symmetric_and_symmetrised() {
        // First-order fast marching is not exactly symmetric; the worst pairs are the
        // closest ones (about 10-20 edge lengths apart).
        asymmetry(0.1, 0.02);
        asymmetry(0.3, 0.02);
    }

    fn asymmetry(noise: f64, bound: f64) {
        let mesh = valid(procedural::with_noise(
            procedural::torus(200, 80, 1.0, 0.35),
            noise,
            4,
        ));
        let lm: Vec<u32> = (0..60).map(|i| i * 263 + 5).collect();
        let fm = FastMarching::new(&mesh);
        let mut ws = fm.workspace();
        let n = lm.len();
        let d: Vec<Vec<f64>> = lm
            .iter()
            .map(|&s| {
                let r = fm.run(&mut ws, &[s]);
                lm.iter().map(|&l| r[l as usize]).collect()
            })
            .collect();
        let h = wavg_mesh::geometry::mean_edge_length(&mesh);
        let (mut worst, mut worst_far, mut sum) = (0.0f64, 0.0f64, 0.0);
        #[allow(clippy::needless_range_loop)]
        for i in 0..n {
            for j in 0..i {
                let q = 0.5 * (d[i][j] + d[j][i]);
                let a = (d[i][j] - d[j][i]).abs() / q;
                worst = worst.max(a);
                sum += a;
                if q > 10.0 * h {
                    worst_far = worst_far.max(a);
                }
            }
        }
        let mean = sum / (n * (n - 1) / 2) as f64;
        eprintln!(
            "torus 16k v, noise {noise}, 60 landmarks: asymmetry |D_ij - D_ji| / Q_ij mean {:.3}%, max {:.3}%, max beyond 10 edge lengths {:.3}%",
            mean * 100.0,
            worst * 100.0,
            worst_far * 100.0
        );
        assert!(worst_far < bound && mean < 0.005, "{worst_far} {mean}");
        let q = landmark_distances(&mesh, &lm, &NoProgress).unwrap();
        for i in 0..n {
            assert_eq!(q[i * n + i], 0.0);
            for j in 0..n {
                assert_eq!(q[i * n + j], q[j * n + i]);
                if i != j {
                    let want = 0.5 * (d[i][j] + d[j][i]);
                    assert!((q[i * n + j] - want).abs() <= 1e-12 * want, "{i} {j}");
                }
            }
        }
    }

    /// Asymmetry `|d_ij - d_ji| / mean` of the full landmark matrix: mean, max, and the
    /// share of pairs above 2%.
    fn matrix_asymmetry(fm: &FastMarching, lm: &[u32]) -> (f64, f64, f64) {
        let rows = landmark_rows(fm, lm, &NoProgress).unwrap();
        let a: Vec<f64> = rows
            .iter()
            .enumerate()
            .flat_map(|(i, ri)| {
                let rows = &rows;
                ri.iter().take(i).enumerate().map(move |(j, &dij)| {
                    let dji = rows[j][i];
                    (dij - dji).abs() / (0.5 * (dij + dji))
                })
            })
            .collect();
        let n = a.len() as f64;
        (
            a.iter().sum::<f64>() / n,
            a.iter().copied().fold(0.0, f64::max),
            a.iter().filter(|&&x| x > 0.02).count() as f64 / n,
        )
    }

    /// Symmetry of the landmark distance matrix on real meshes. First-order fast marching
    /// is not symmetric; the exact near field (with pseudo-sources at saddles) makes close
    /// pairs exact. At the default 8 edge lengths a few pairs a little farther apart stay
    /// above 2% (at most 0.025% of pairs here); with the near field at 16 edge lengths
    /// every pair is within 2% (3-5x the time of a plain run).
    #[test]
    fn real_mesh_landmark_matrix_symmetry() {
        for file in [
            "meshes/pig.off",
            "meshes/camelhead.off",
            "meshes/fertility.off",
        ] {
            let Some(path) = wavg_testdata::require_data_file("geodesic::real_mesh_symmetry", file)
            else {
                return;
            };
            let mesh = valid(wavg_mesh::io::load(&path).unwrap());
            let opts = DecimateOptions {
                target: 300,
                ..Default::default()
            };
            let lm = crate::decimate::select_landmarks(&mesh, &opts, &NoProgress).unwrap();
            let fm = FastMarching::new(&mesh);
            let (mean, max, over) = matrix_asymmetry(&fm, &lm);
            eprintln!(
                "{file}: 300 landmarks, asymmetry mean {:.3}%, max {:.2}%, pairs above 2%: {:.3}%",
                100.0 * mean,
                100.0 * max,
                100.0 * over
            );
            assert!(mean < 0.003 && over < 0.0005, "{file}");
            let wide = fm.with_near_field_edges(16.0);
            let (mean, max, _) = matrix_asymmetry(&wide, &lm);
            eprintln!(
                "{file}: near field 16 edge lengths: asymmetry mean {:.3}%, max {:.2}%",
                100.0 * mean,
                100.0 * max
            );
            assert!(max < 0.02, "{file}: max asymmetry {max}");
        }
    }

    #[test]
    fn landmark_distances_rejects_bad_ids_and_honours_cancellation() {
        let mesh = valid(procedural::icosphere(2));
        let n = mesh.n_vertices() as u32;
        assert!(matches!(
            landmark_distances(&mesh, &[0, n], &NoProgress),
            Err(EmbedError::InvalidArgument(_))
        ));
        assert!(matches!(
            landmark_distances(&mesh, &[4, 4], &NoProgress),
            Err(EmbedError::InvalidArgument(_))
        ));
        assert!(
            landmark_distances(&mesh, &[], &NoProgress)
                .unwrap()
                .is_empty()
        );
        struct Stop;
        impl Progress for Stop {
            fn report(&self, _: Stage, _: f64) {}
            fn cancelled(&self) -> bool {
                true
            }
        }
        assert!(matches!(
            landmark_distances(&mesh, &[0, 1, 2], &Stop),
            Err(EmbedError::Cancelled)
        ));
        // Progress reaches 1.
        struct Last(std::sync::Mutex<f64>);
        impl Progress for Last {
            fn report(&self, s: Stage, f: f64) {
                assert_eq!(s, Stage::Geodesics);
                let mut l = self.0.lock().unwrap();
                *l = l.max(f);
            }
        }
        let p = Last(std::sync::Mutex::new(0.0));
        landmark_distances(&mesh, &[0, 10, 20, 30], &p).unwrap();
        assert_eq!(*p.0.lock().unwrap(), 1.0);
    }

    #[test]
    fn coarse_landmark_distances_stay_close_to_the_truth() {
        let mesh = valid(procedural::icosphere(5));
        let n_v = mesh.n_vertices() as u32;
        let lm: Vec<u32> = (0..60).map(|i| i * (n_v / 60) + 3).collect();
        let n = lm.len();
        let full = landmark_distances(&mesh, &lm, &NoProgress).unwrap();
        // Not coarser than the mesh: identical.
        let same = landmark_distances_coarse(&mesh, &lm, n_v as usize, &NoProgress).unwrap();
        assert_eq!(same, full);
        let coarse = landmark_distances_coarse(&mesh, &lm, 2000, &NoProgress).unwrap();
        let (mut e_full, mut e_coarse, mut diff) = (0.0, 0.0, 0.0);
        for i in 0..n {
            for j in 0..n {
                if i == j {
                    continue;
                }
                let (a, b) = (
                    mesh.positions[lm[i] as usize],
                    mesh.positions[lm[j] as usize],
                );
                let exact = a.dot(&b).clamp(-1.0, 1.0).acos();
                let k = i * n + j;
                e_full += (full[k] - exact).abs() / exact;
                e_coarse += (coarse[k] - exact).abs() / exact;
                diff += (coarse[k] - full[k]).abs() / full[k];
            }
        }
        let m = (n * (n - 1)) as f64;
        eprintln!(
            "icosphere(5) {n_v} v, 60 landmarks: mean rel err full {:.3}%, on 2000 v {:.3}%, coarse vs full {:.3}%",
            100.0 * e_full / m,
            100.0 * e_coarse / m,
            100.0 * diff / m
        );
        assert!(e_full / m < 0.01 && e_coarse / m < 0.02 && diff / m < 0.02);
    }

    #[test]
    fn distances_on_a_snapshot_of_the_landmark_decimation() {
        use crate::decimate::decimate_with_snapshots;
        let mesh = valid(procedural::with_noise(
            procedural::torus(80, 30, 1.0, 0.35),
            0.2,
            2,
        ));
        let opts = DecimateOptions {
            target: 40,
            ..Default::default()
        };
        let (fin, snaps) = decimate_with_snapshots(&mesh, &opts, &[800], &NoProgress).unwrap();
        let full = landmark_distances(&mesh, &fin.landmarks, &NoProgress).unwrap();
        let fm = FastMarching::new(&mesh);
        let stats = |q: &[f64]| {
            let (mut sum, mut max) = (0.0, 0.0f64);
            for k in 0..q.len() {
                if full[k] > 0.0 {
                    let r = (q[k] - full[k]).abs() / full[k];
                    sum += r;
                    max = max.max(r);
                }
            }
            (sum / (40.0 * 39.0), max)
        };
        let coarse_only =
            landmark_distances_decimated(&snaps[0], &fin.landmarks, &NoProgress).unwrap();
        let two =
            landmark_distances_two_level(&fm, &snaps[0], &fin.landmarks, &NoProgress).unwrap();
        let (m1, x1) = stats(&coarse_only);
        let (m2, x2) = stats(&two);
        eprintln!(
            "torus 2400 v -> snapshot 800 v, 40 landmarks, rel. diff to full: coarse only mean {:.3}% max {:.2}%, two-level mean {:.3}% max {:.2}%",
            100.0 * m1,
            100.0 * x1,
            100.0 * m2,
            100.0 * x2
        );
        assert!(m1 < 0.03 && m2 <= m1 && x2 <= x1, "{m1} {m2} {x1} {x2}");
        for k in 0..two.len() {
            assert_eq!(two[k], two[(k % 40) * 40 + k / 40], "symmetric");
        }
        // A landmark that is not in the coarse mesh is refused.
        let missing = (0..mesh.n_vertices() as u32)
            .find(|&v| snaps[0].coarse_index(v).is_none())
            .unwrap();
        assert!(matches!(
            landmark_distances_decimated(&snaps[0], &[fin.landmarks[0], missing], &NoProgress),
            Err(EmbedError::InvalidArgument(_))
        ));
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(24))]
        /// Between the straight-line (chord) lower bound and the edge-graph (Dijkstra) upper bound.
        #[test]
        fn bounded_by_chord_and_dijkstra(seed in 0u64..1000, amp in 0.0f64..0.6, src in 0u32..642) {
            let mesh = valid(procedural::with_noise(procedural::icosphere(3), amp, seed));
            let d = distances_from(&mesh, &[src]);
            let dj = dijkstra(&mesh, src);
            let ps = mesh.positions[src as usize];
            for v in 0..mesh.n_vertices() {
                let chord = (mesh.positions[v] - ps).norm();
                prop_assert!(d[v] <= dj[v] * (1.0 + 1e-6), "{} > dijkstra {}", d[v], dj[v]);
                prop_assert!(d[v] >= chord * (1.0 - 1e-3), "{} < chord {}", d[v], chord);
            }
        }
    }
}
