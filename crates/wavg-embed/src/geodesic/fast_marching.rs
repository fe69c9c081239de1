//! The fast-marching solver: per-mesh update entries, the per-run workspace and the run
//! loop (stopping at a radius or once given targets are frozen).

use super::*;
use crate::error::{NoProgress, filled};

/// Vertex count of the intermediate mesh for landmark geodesics on large meshes (see the
/// module documentation), the pipeline's default: a balance between the time of one run
/// per landmark and the error of the coarser mesh.
pub(crate) const DEFAULT_GEODESIC_VERTICES: usize = 10_000;

/// How many triangles the obtuse-angle unfolding may cross before giving up.
pub(crate) const MAX_UNFOLD_STEPS: usize = 40;

/// Faces, stencils or vertices processed between two looks at the cancellation while a
/// [`FastMarching`] is built (a few milliseconds of work).
pub(super) const CANCEL_EVERY: usize = 1 << 16;

/// One update that freezing a vertex `v` triggers on a neighbour `x`.
///
/// `q_vv, q_vo, q_oo` are the entries of the inverse Gram matrix of the stencil
/// `(x; v, other)` (all zero for an edge-only entry); `len` is `|x - v|` (unfolded for a
/// virtual edge).
#[derive(Clone, Copy, Debug)]
pub(super) struct Entry {
    pub(super) x: u32,
    pub(super) other: u32,
    pub(super) q_vv: f32,
    pub(super) q_vo: f32,
    pub(super) q_oo: f32,
    pub(super) len: f32,
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
    pub(super) n: usize,
    pub(super) offsets: Vec<u32>,
    pub(super) entries: Vec<Entry>,
    /// Exact distances near a source, by unfolding ([`super::near_field`]).
    pub(super) near: NearField,
    /// Number of obtuse corners, and how many of them were split by unfolding.
    pub(super) obtuse: (usize, usize),
}

/// Per-run buffers (distances, frozen flags, heap). Make one per thread with
/// [`FastMarching::workspace`].
#[derive(Clone, Debug)]
pub struct Workspace {
    pub(super) dist: Vec<f64>,
    /// `FAR`, `FROZEN`, or the vertex's position in `heap`.
    pub(super) state: Vec<u32>,
    /// Binary min-heap of vertices by `dist` (each vertex at most once).
    pub(super) heap: Vec<u32>,
    /// Whether `dist` and `state` are all at their initial values.
    pub(super) clean: bool,
    /// Vertices frozen by the last [`FastMarching::run_within`], with their distances.
    pub(super) local: Vec<(u32, f64)>,
    /// Buffers of the near-field unfolding.
    pub(super) near_out: Vec<(u32, f64)>,
    pub(super) near_scratch: NearScratch,
    /// Vertices whose near-field length is their exact distance (fast marching must not
    /// lower it: its plane-wave update can undershoot where fronts meet behind a saddle).
    pub(super) exact: Vec<bool>,
    pub(super) exact_list: Vec<u32>,
}

/// A stencil `(x; A, B)` with the 2-D (or 3-D, only dot products matter) edge vectors.
pub(super) struct Stencil {
    pub(super) x: u32,
    pub(super) a: u32,
    pub(super) b: u32,
    /// Gram entries `a.a`, `a.b`, `b.b`.
    pub(super) g: [f64; 3],
}

impl FastMarching {
    /// Precomputes the update stencils of `mesh` (unfolding obtuse corners).
    pub fn new(mesh: &ValidMesh) -> Self {
        match Self::build(mesh, true, &NoProgress) {
            Ok(fm) => fm,
            Err(_) => unreachable!("NoProgress never cancels"),
        }
    }

    /// [`FastMarching::new`], stopping with [`EmbedError::Cancelled`] when `progress` asks
    /// (looked at every [`CANCEL_EVERY`] faces or vertices: about a second at 10M vertices
    /// is the whole build's tenth).
    pub(crate) fn new_cancellable(
        mesh: &ValidMesh,
        progress: &dyn Progress,
    ) -> Result<Self, EmbedError> {
        Self::build(mesh, true, progress)
    }

    pub(super) fn build(
        mesh: &ValidMesh,
        unfold_obtuse: bool,
        progress: &dyn Progress,
    ) -> Result<Self, EmbedError> {
        let n = mesh.n_vertices();
        let topo = mesh.topology();
        let pos = &mesh.positions;
        let mut stencils: Vec<Stencil> = Vec::with_capacity(mesh.n_faces() * 3 + 1024);
        let mut virtual_edges: Vec<(u32, u32, f64)> = Vec::new();
        let mut obtuse = (0usize, 0usize);
        for (f, t) in mesh.triangles.iter().enumerate() {
            if f % CANCEL_EVERY == 0 {
                check_cancel(progress)?;
            }
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
        // 1.5 GB at 10M vertices.
        let mut entries = filled(offsets[n] as usize, empty, progress)?;
        let mut put = |v: u32, e: Entry| {
            entries[fill[v as usize] as usize] = e;
            fill[v as usize] += 1;
        };
        for (i, s) in stencils.iter().enumerate() {
            if i % CANCEL_EVERY == 0 {
                check_cancel(progress)?;
            }
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
            if v % CANCEL_EVERY == 0 {
                check_cancel(progress)?;
            }
            entries[offsets[v] as usize..offsets[v + 1] as usize].sort_by_key(|e| e.x);
        }
        // The stencils (40 bytes each, about six a vertex) go before the near field's
        // copy of the mesh is built.
        drop((stencils, virtual_edges, fill));
        let near = NearField::new(mesh, progress)?;
        Ok(Self {
            n,
            offsets,
            entries,
            near,
            obtuse,
        })
    }

    /// Number of vertices of the mesh.
    pub fn n_vertices(&self) -> usize {
        self.n
    }

    /// This fast marching with its exact near field reaching `edges` mean edge lengths
    /// from each source instead of [`NEAR_FIELD_EDGES`](super::near_field::NEAR_FIELD_EDGES)
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

    /// [`run_until_targets`](Self::run_until_targets), stopping with
    /// [`EmbedError::Cancelled`] when `progress` asks (looked at every [`CANCEL_EVERY`]
    /// frozen vertices: a run over a 10M-vertex mesh takes seconds).
    pub(crate) fn run_until_targets_cancellable<'w>(
        &self,
        ws: &'w mut Workspace,
        sources: &[u32],
        targets: &[bool],
        n_targets: usize,
        progress: &dyn Progress,
    ) -> Result<&'w [f64], EmbedError> {
        if self.run_cancellable(ws, sources, Stop::Targets(targets, n_targets), progress) {
            Ok(&ws.dist)
        } else {
            Err(EmbedError::Cancelled)
        }
    }

    pub(super) fn run_until(&self, ws: &mut Workspace, sources: &[u32], stop: Stop) {
        // Without a sink that cancels, the run always completes.
        self.run_cancellable(ws, sources, stop, &NoProgress);
    }

    /// The run loop; false when `progress` cancelled it (the workspace is then left for
    /// the next run to reset).
    fn run_cancellable(
        &self,
        ws: &mut Workspace,
        sources: &[u32],
        stop: Stop,
        progress: &dyn Progress,
    ) -> bool {
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
            return true;
        }
        let mut frozen = 0usize;
        while let Some(v) = ws.pop() {
            frozen += 1;
            if frozen % CANCEL_EVERY == 0 && progress.cancelled() {
                ws.clean = false;
                return false;
            }
            let vi = v as usize;
            let uv = ws.dist[vi];
            match stop {
                Stop::Never => {}
                Stop::Targets(targets, _) => {
                    if targets[vi] {
                        remaining -= 1;
                        if remaining == 0 {
                            return true;
                        }
                    }
                }
                Stop::Beyond(r) => {
                    if uv > r {
                        // Not part of the result: back to the heap's bookkeeping for reset.
                        ws.state[vi] = FAR;
                        ws.heap.push(v);
                        return true;
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
        true
    }
}

/// When a run stops early.
#[derive(Clone, Copy)]
pub(super) enum Stop<'a> {
    /// Run to the end.
    Never,
    /// Once all `n` flagged vertices are frozen.
    Targets(&'a [bool], usize),
    /// Once the next vertex to freeze is farther than this.
    Beyond(f64),
}

/// `Workspace::state` of a vertex not yet reached.
pub(super) const FAR: u32 = u32::MAX;
/// `Workspace::state` of a frozen vertex (otherwise: its position in the heap).
pub(super) const FROZEN: u32 = u32::MAX - 1;

/// The planar-wavefront value at `x` from frozen values `uv` (at `v`) and `uo` (at the
/// stencil's other vertex), or `None` when the characteristic is not inside the stencil.
#[inline(always)]
pub(super) fn triangle_update(uv: f64, uo: f64, e: &Entry) -> Option<f64> {
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
