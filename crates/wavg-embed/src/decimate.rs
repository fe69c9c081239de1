//! Landmark selection by incremental decimation (halfedge collapses), after OpenMesh's
//! `DecimaterT` with the modules `ModQuadricT` (priority), `ModNormalFlippingT` and
//! optionally `ModNormalDeviationT` (binary constraints).
//!
//! # What is mirrored from OpenMesh
//!
//! * **Halfedge collapse** `u -> v`: `u` is removed and `v` keeps its position, so every
//!   surviving vertex is an original vertex and the survivors are the landmarks.
//! * **Priority queue of vertices** (`DecimaterT`): each vertex stores its best legal
//!   outgoing collapse (smallest priority) and sits in the heap with it. After a collapse
//!   `u -> v` the vertices of the *former one-ring of `u`* (which includes `v`) are
//!   re-evaluated, as OpenMesh does. A popped collapse is re-checked for topological
//!   legality only and skipped (the vertex leaves the heap) if it became illegal.
//! * **Topological legality** (`TriConnectivity::is_collapse_ok` plus
//!   `BaseDecimaterT::is_collapse_legal`): locked `u` refused; a boundary `u` may only
//!   collapse into a boundary `v`, and an edge between two boundary vertices must be a
//!   boundary edge (so boundary vertices only move along their loop); a triangle with two
//!   boundary edges is never removed; the one-ring intersection of `u` and `v` must be
//!   exactly the opposite vertices `{wl, wr}` (link condition). Together these keep the
//!   genus, the number of boundary loops and manifoldness.
//! * **`ModQuadricT`**: per vertex the sum of the planes of its faces, each weighted by the
//!   face area; priority of `u -> v` = `(Q_u + Q_v)(p_v)`; after the collapse
//!   `Q_v += Q_u`.
//! * **`ModNormalFlippingT`**: a collapse is illegal if some face around `u` (other than
//!   the two removed) would turn by more than `max_normal_deviation_deg` against its
//!   *current* normal (face normals are updated after each collapse, as
//!   `DecimaterT::decimate` does with `update_normals`).
//! * **`ModNormalDeviationT`** (optional, `max_normal_cone_deg`): per face a normal cone
//!   (`NormalConeT`, merged by SLERP) accumulates all normals the face region had; a
//!   collapse is illegal if a resulting cone's full aperture would exceed the bound.
//!
//! # Where this differs from OpenMesh
//!
//! * Ties: OpenMesh's heap order for equal priorities is an implementation detail; here
//!   equal priorities (exactly planar regions, where every quadric error is 0) are ordered
//!   by the shorter edge first, then by vertex id (a vertex's best collapse: by target id).
//!   Shorter-first keeps the survivors of a flat region spread out instead of clustered at
//!   one end of the index range. The result is deterministic.
//! * Priorities are `f64` (OpenMesh returns `float`).
//! * A collapse that would create a zero-area face (sine of an angle below `1e-12`) is
//!   illegal (OpenMesh's flipping test lets it through at 90 degrees, since the normal of
//!   a degenerate face is the zero vector).
//! * A closed component that is a tetrahedron is never collapsed further.
//! * **Relaxation**: OpenMesh stops when the heap is empty. Here, if the target is not yet
//!   reached, every vertex is first re-evaluated (vertices whose popped collapse had become
//!   illegal left the heap, but may have another legal one); if that finds nothing, the
//!   normal bounds are relaxed (cone bound x1.5 until it is switched off, then the flipping
//!   bound +15 degrees up to 90) and everything is re-evaluated again. Only when nothing can
//!   be collapsed even with a 90-degree flipping bound (a topological limit, for example
//!   a torus below 7 vertices) is it an error. The relaxations applied are reported in
//!   [`Decimated::relaxations`].
//! * Default bounds: `ModNormalFlippingT`'s default is 90 degrees; here it is 45
//!   ([`DecimateOptions::default`]), which keeps the coarse mesh from folding over while
//!   the target is still reached without relaxation on every test mesh we have.
//! * Quadric areas: OpenMesh leaves the normal unnormalised for faces of area below
//!   `FLT_MIN`; valid meshes have no such faces, so this never matters here.
//!
//! # Consequences worth knowing
//!
//! * Like OpenMesh's `ModQuadricT`, the quadrics have no boundary planes: on a flat open
//!   surface a boundary vertex can slide along its loop at zero cost, so corners of open
//!   boundaries are not protected (the loop count is).
//! * Cost: 1.2-1.6 CPU-seconds for 134k vertices to 1000 (shared 2-core machine). A
//!   vertex of very high valence `k` (a fan of thousands of triangles) makes each
//!   re-evaluation of it `O(k)` to `O(k^2)`.

use nalgebra::Vector3;
use wavg_mesh::{TriMesh, ValidMesh};

use crate::error::{EmbedError, Progress, Stage, check_cancel};

const NONE: u32 = u32::MAX;

/// Parameters of the landmark decimation.
#[derive(Clone, Debug, PartialEq)]
pub struct DecimateOptions {
    /// Number of vertices to keep (the landmark count).
    pub target: usize,
    /// `ModNormalFlippingT` bound: the largest angle (degrees, `0 < x <= 90`) by which one
    /// collapse may turn any remaining face's normal. 90 means "only forbid flips".
    pub max_normal_deviation_deg: f64,
    /// `ModNormalDeviationT` bound (degrees): the largest full aperture of the normal cone
    /// a face may accumulate over the whole decimation; `None` disables the module.
    pub max_normal_cone_deg: Option<f64>,
    /// Vertices that must survive (OpenMesh's locked status): never removed, though others
    /// may collapse into them.
    pub locked: Vec<u32>,
    /// Relax the normal bounds when they block the target (see the module docs); without
    /// it, an unreachable target is an error.
    pub relax: bool,
}

impl Default for DecimateOptions {
    fn default() -> Self {
        Self {
            target: 1000,
            max_normal_deviation_deg: 45.0,
            max_normal_cone_deg: None,
            locked: Vec::new(),
            relax: true,
        }
    }
}

/// The result of a decimation: the coarse mesh on the surviving original vertices.
#[derive(Clone, Debug)]
pub struct Decimated {
    /// The coarse mesh; its vertex `i` is original vertex `landmarks[i]` (same position).
    pub mesh: TriMesh,
    /// The surviving original vertex ids, ascending.
    pub landmarks: Vec<u32>,
    /// The normal bounds `(flipping, cone)` in degrees after each relaxation that was
    /// needed to reach the target (empty if none was).
    pub relaxations: Vec<(f64, Option<f64>)>,
}

impl Decimated {
    /// Index in [`Self::mesh`] of original vertex `v`, if it survived.
    pub fn coarse_index(&self, v: u32) -> Option<u32> {
        self.landmarks.binary_search(&v).ok().map(|i| i as u32)
    }
}

/// Chooses `opts.target` landmark vertices of `mesh` by decimation; returns their original
/// ids, ascending. See the module documentation for the rules.
///
/// ```
/// use wavg_embed::{DecimateOptions, NoProgress, select_landmarks};
/// use wavg_mesh::{ValidMesh, procedural};
/// let mesh = ValidMesh::new(procedural::torus(40, 20, 1.0, 0.3)).unwrap();
/// let opts = DecimateOptions { target: 100, ..Default::default() };
/// let lm = select_landmarks(&mesh, &opts, &NoProgress).unwrap();
/// assert_eq!(lm.len(), 100);
/// assert!(lm.windows(2).all(|w| w[0] < w[1]));
/// ```
pub fn select_landmarks(
    mesh: &ValidMesh,
    opts: &DecimateOptions,
    progress: &dyn Progress,
) -> Result<Vec<u32>, EmbedError> {
    Ok(decimate(mesh, opts, progress)?.landmarks)
}

/// Decimates `mesh` to `opts.target` vertices; returns the coarse mesh and the landmarks.
///
/// ```
/// use wavg_embed::{DecimateOptions, NoProgress, decimate};
/// use wavg_mesh::{ValidMesh, procedural};
/// let mesh = ValidMesh::new(procedural::grid(30, 30, 1.0, 1.0)).unwrap();
/// let d = decimate(&mesh, &DecimateOptions { target: 50, ..Default::default() }, &NoProgress).unwrap();
/// let coarse = ValidMesh::new(d.mesh).unwrap();
/// assert_eq!(coarse.n_vertices(), 50);
/// assert_eq!(coarse.topology().boundary_loops().len(), 1);
/// ```
pub fn decimate(
    mesh: &ValidMesh,
    opts: &DecimateOptions,
    progress: &dyn Progress,
) -> Result<Decimated, EmbedError> {
    Ok(decimate_with_snapshots(mesh, opts, &[], progress)?.0)
}

/// Like [`decimate`], and also returns the state of the same collapse sequence when it had
/// `snapshots[i]` vertices (each in `opts.target..=n_vertices`), in the given order. The
/// vertices of a coarser result are a subset of those of every finer one.
pub fn decimate_with_snapshots(
    mesh: &ValidMesh,
    opts: &DecimateOptions,
    snapshots: &[usize],
    progress: &dyn Progress,
) -> Result<(Decimated, Vec<Decimated>), EmbedError> {
    let n = mesh.n_vertices();
    check_options(n, opts)?;
    if let Some(&s) = snapshots.iter().find(|&&s| s < opts.target || s > n) {
        return Err(EmbedError::InvalidArgument(format!(
            "snapshot at {s} vertices is outside {}..={n}",
            opts.target
        )));
    }
    let mut d = Decimator::new(mesh, opts);
    let mut snaps: Vec<Option<Decimated>> = vec![None; snapshots.len()];
    let take = |d: &Decimator, snaps: &mut Vec<Option<Decimated>>| {
        for (i, &s) in snapshots.iter().enumerate() {
            if s == d.n_alive && snaps[i].is_none() {
                snaps[i] = Some(d.result());
            }
        }
    };
    take(&d, &mut snaps);
    d.init_heap();
    let total = (n - opts.target).max(1) as f64;
    let mut since_report = 0usize;
    // Whether a collapse happened since the heap was last filled from scratch. Vertices
    // whose popped collapse turned out illegal leave the heap (as in OpenMesh), so an empty
    // heap first triggers a full re-evaluation; only if that finds nothing are the bounds
    // relaxed.
    let mut collapsed_since_fill = false;
    while d.n_alive > opts.target {
        if d.step() {
            collapsed_since_fill = true;
            take(&d, &mut snaps);
            since_report += 1;
            if since_report == 2048 {
                since_report = 0;
                check_cancel(progress)?;
                progress.report(Stage::Decimate, (n - d.n_alive) as f64 / total);
            }
        } else if d.heap.is_empty() {
            if collapsed_since_fill {
                collapsed_since_fill = false;
                d.init_heap();
                continue;
            }
            if !opts.relax || !d.relax() {
                return Err(EmbedError::InvalidArgument(format!(
                    "cannot decimate to {} vertices: no legal collapse left at {} vertices \
                     (normal bounds {:.0} deg / {:?}); ask for more landmarks",
                    opts.target, d.n_alive, d.flip_deg, d.cone_deg
                )));
            }
            check_cancel(progress)?;
            d.init_heap();
        }
    }
    progress.report(Stage::Decimate, 1.0);
    let fin = d.result();
    Ok((
        fin,
        snaps
            .into_iter()
            .map(|s| s.expect("every snapshot level is passed"))
            .collect(),
    ))
}

fn check_options(n: usize, opts: &DecimateOptions) -> Result<(), EmbedError> {
    if opts.target == 0 {
        return Err(EmbedError::InvalidArgument(
            "the landmark count must be at least 1".into(),
        ));
    }
    if opts.target > n {
        return Err(EmbedError::InvalidArgument(format!(
            "the mesh has {n} vertices, fewer than the {} landmarks asked for; ask for at most {n}",
            opts.target
        )));
    }
    let f = opts.max_normal_deviation_deg;
    if !(f > 0.0 && f <= 90.0) {
        return Err(EmbedError::InvalidArgument(format!(
            "max_normal_deviation_deg = {f} is not in (0, 90]"
        )));
    }
    if let Some(c) = opts.max_normal_cone_deg {
        if !(c > 0.0 && c <= 360.0) {
            return Err(EmbedError::InvalidArgument(format!(
                "max_normal_cone_deg = {c} is not in (0, 360]"
            )));
        }
    }
    let mut seen = vec![false; n];
    for &l in &opts.locked {
        match seen.get_mut(l as usize) {
            None => {
                return Err(EmbedError::InvalidArgument(format!(
                    "locked vertex {l} out of range (mesh has {n} vertices)"
                )));
            }
            Some(s) => *s = true,
        }
    }
    let k = seen.iter().filter(|&&s| s).count();
    if k > opts.target {
        return Err(EmbedError::InvalidArgument(format!(
            "{k} locked vertices cannot fit in a target of {}",
            opts.target
        )));
    }
    Ok(())
}

/// Garland-Heckbert quadric (symmetric 4x4: a2 ab ac ad b2 bc bd c2 cd d2).
#[derive(Clone, Copy, Debug, Default)]
struct Quadric([f64; 10]);

impl Quadric {
    fn plane(n: Vector3<f64>, d: f64, w: f64) -> Self {
        let (a, b, c) = (n.x, n.y, n.z);
        Self([
            a * a * w,
            a * b * w,
            a * c * w,
            a * d * w,
            b * b * w,
            b * c * w,
            b * d * w,
            c * c * w,
            c * d * w,
            d * d * w,
        ])
    }
    fn add(&mut self, o: &Self) {
        for i in 0..10 {
            self.0[i] += o.0[i];
        }
    }
    fn eval_sum(&self, o: &Self, p: &Vector3<f64>) -> f64 {
        let q: [f64; 10] = std::array::from_fn(|i| self.0[i] + o.0[i]);
        let (x, y, z) = (p.x, p.y, p.z);
        q[0] * x * x
            + 2.0 * q[1] * x * y
            + 2.0 * q[2] * x * z
            + 2.0 * q[3] * x
            + q[4] * y * y
            + 2.0 * q[5] * y * z
            + 2.0 * q[6] * y
            + q[7] * z * z
            + 2.0 * q[8] * z
            + q[9]
    }
}

/// OpenMesh's `NormalConeT`: a centre normal and a half opening angle.
#[derive(Clone, Copy, Debug)]
struct Cone {
    n: Vector3<f64>,
    angle: f64,
}

impl Cone {
    fn merged(mut self, o: &Cone) -> Cone {
        let center = self.n.dot(&o.n).clamp(-1.0, 1.0).acos();
        let min_a = (-self.angle).min(center - o.angle);
        let max_a = self.angle.max(center + o.angle);
        let opening = 0.5 * (max_a - min_a);
        let s = center.sin();
        if s > 1e-9 {
            let axis = 0.5 * (min_a + max_a);
            self.n = ((self.n * (center - axis).sin() + o.n * axis.sin()) / s).normalize();
        }
        self.angle = opening;
        self
    }
}

#[inline(always)]
fn next(h: u32) -> u32 {
    if h % 3 == 2 { h - 2 } else { h + 1 }
}

#[inline(always)]
fn prev(h: u32) -> u32 {
    if h % 3 == 0 { h + 2 } else { h - 1 }
}

/// Total order on f64 as u64 (for heap keys).
#[inline]
fn key(f: f64) -> u64 {
    let b = f.to_bits();
    if b >> 63 == 1 { !b } else { b | (1 << 63) }
}

/// The working state: a compact corner table (halfedge `3 f + i` runs from corner `i` to
/// corner `i + 1` of face `f`) with opposite halfedges, plus the modules' data.
struct Decimator<'a> {
    /// Positions relative to the bounding-box centre: quadric errors are differences of
    /// squares, which lose their precision when the mesh sits far from the origin.
    pos: Vec<Vector3<f64>>,
    /// The input positions, for the result.
    orig: &'a [Vector3<f64>],
    corner: Vec<u32>,
    opp: Vec<u32>,
    face_alive: Vec<bool>,
    /// One outgoing halfedge per live vertex; for a boundary vertex, the one whose
    /// opposite is missing (the clockwise-most), so rotations cover the whole fan.
    vh: Vec<u32>,
    alive: Vec<bool>,
    boundary: Vec<bool>,
    locked: Vec<bool>,
    quadric: Vec<Quadric>,
    normal: Vec<Vector3<f64>>,
    cone: Vec<Cone>,
    n_alive: usize,
    flip_deg: f64,
    min_cos: f64,
    cone_deg: Option<f64>,
    relaxations: Vec<(f64, Option<f64>)>,
    /// Vertices by their best collapse (OpenMesh's updatable `HeapT`).
    heap: IndexedHeap,
    best: Vec<u32>,
    mark: Vec<u32>,
    mark_stamp: u32,
    scratch_out: Vec<u32>,
    scratch_hs: Vec<u32>,
    scratch_support: Vec<u32>,
    scratch_cands: Vec<(f64, f64, u32, u32)>,
}

impl<'a> Decimator<'a> {
    fn new(mesh: &'a ValidMesh, opts: &DecimateOptions) -> Self {
        let n = mesh.n_vertices();
        let nf = mesh.n_faces();
        let topo = mesh.topology();
        let orig = &mesh.positions[..];
        let centre = mesh
            .bounding_box()
            .map_or_else(Vector3::zeros, |(lo, hi)| (lo + hi) * 0.5);
        let pos: Vec<Vector3<f64>> = orig.iter().map(|p| p - centre).collect();
        let corner: Vec<u32> = mesh.triangles.iter().flatten().copied().collect();
        let mut opp = vec![NONE; 3 * nf];
        for f in 0..nf {
            let nb = topo.face_neighbors(f as u32);
            for i in 0..3 {
                let g = nb[i];
                if g == NONE {
                    continue;
                }
                let (s, e) = (corner[3 * f + i], corner[3 * f + (i + 1) % 3]);
                for j in 0..3 {
                    if corner[3 * g as usize + j] == e && corner[3 * g as usize + (j + 1) % 3] == s
                    {
                        opp[3 * f + i] = 3 * g + j as u32;
                    }
                }
            }
        }
        let mut vh = vec![NONE; n];
        for h in 0..3 * nf {
            let v = corner[h] as usize;
            if vh[v] == NONE || opp[h] == NONE {
                vh[v] = h as u32;
            }
        }
        let boundary: Vec<bool> = (0..n as u32).map(|v| topo.is_boundary_vertex(v)).collect();
        let mut locked = vec![false; n];
        for &l in &opts.locked {
            locked[l as usize] = true;
        }
        // ModQuadricT::initialize: area-weighted face planes.
        let mut quadric = vec![Quadric::default(); n];
        let mut normal = Vec::with_capacity(nf);
        for t in &mesh.triangles {
            let [p0, p1, p2] = t.map(|v| pos[v as usize]);
            let mut nrm = (p1 - p0).cross(&(p2 - p0));
            let mut area = nrm.norm();
            if area > f64::from(f32::MIN_POSITIVE) {
                nrm /= area;
                area *= 0.5;
            }
            let q = Quadric::plane(nrm, -p0.dot(&nrm), area);
            for &v in t {
                quadric[v as usize].add(&q);
            }
            normal.push(nrm);
        }
        let cone = normal.iter().map(|&n| Cone { n, angle: 0.0 }).collect();
        let flip_deg = opts.max_normal_deviation_deg;
        Self {
            pos,
            orig,
            corner,
            opp,
            face_alive: vec![true; nf],
            vh,
            alive: vec![true; n],
            boundary,
            locked,
            quadric,
            normal,
            cone,
            n_alive: n,
            flip_deg,
            min_cos: flip_deg.to_radians().cos(),
            cone_deg: opts.max_normal_cone_deg,
            relaxations: Vec::new(),
            heap: IndexedHeap::new(n),
            best: vec![NONE; n],
            mark: vec![0; n],
            mark_stamp: 0,
            scratch_out: Vec::with_capacity(32),
            scratch_hs: Vec::with_capacity(32),
            scratch_support: Vec::with_capacity(32),
            scratch_cands: Vec::with_capacity(32),
        }
    }

    #[inline]
    fn to(&self, h: u32) -> u32 {
        self.corner[next(h) as usize]
    }

    /// Outgoing halfedges of `v`, counter-clockwise from `vh[v]`.
    fn outgoing(&self, v: u32, out: &mut Vec<u32>) {
        out.clear();
        let start = self.vh[v as usize];
        let mut h = start;
        loop {
            out.push(h);
            let o = self.opp[prev(h) as usize];
            if o == NONE || o == start || out.len() > self.corner.len() {
                break;
            }
            h = o;
        }
    }

    /// One-ring vertices of `v` (boundary: one more than faces).
    fn ring(&self, v: u32, out: &mut Vec<u32>, scratch: &mut Vec<u32>) {
        self.outgoing(v, scratch);
        out.clear();
        out.extend(scratch.iter().map(|&h| self.to(h)));
        let last = *scratch.last().expect("live vertex has a face");
        if self.opp[prev(last) as usize] == NONE {
            out.push(self.corner[prev(last) as usize]);
        }
    }

    /// Marks the one-ring of the vertex whose outgoing halfedges are `out` (for the link
    /// condition); returns its size.
    fn mark_ring(&mut self, out: &[u32]) -> usize {
        self.mark_stamp = self.mark_stamp.wrapping_add(1);
        if self.mark_stamp == 0 {
            self.mark.fill(0);
            self.mark_stamp = 1;
        }
        let st = self.mark_stamp;
        for &g in out {
            let w = self.to(g);
            self.mark[w as usize] = st;
        }
        let last = *out.last().expect("live vertex has a face");
        if self.opp[prev(last) as usize] == NONE {
            let w = self.corner[prev(last) as usize];
            self.mark[w as usize] = st;
            out.len() + 1
        } else {
            out.len()
        }
    }

    /// Topological legality of collapsing halfedge `h` (see the module docs).
    fn topo_legal(&mut self, h: u32) -> bool {
        let mut out = std::mem::take(&mut self.scratch_out);
        self.outgoing(self.corner[h as usize], &mut out);
        let deg_u = self.mark_ring(&out);
        self.scratch_out = out;
        self.topo_legal_marked(h, deg_u)
    }

    /// [`Self::topo_legal`] with the one-ring of `u` already marked by [`Self::mark_ring`].
    fn topo_legal_marked(&mut self, h: u32, deg_u: usize) -> bool {
        let hu = h as usize;
        let (u, v) = (self.corner[hu], self.to(h));
        let (ui, vi) = (u as usize, v as usize);
        if self.locked[ui] || (self.boundary[ui] && !self.boundary[vi]) {
            return false;
        }
        let (h1, h2) = (next(h), prev(h));
        if self.opp[h1 as usize] == NONE && self.opp[h2 as usize] == NONE {
            return false;
        }
        let wl = self.corner[h2 as usize];
        let o = self.opp[hu];
        let mut wr = NONE;
        if o != NONE {
            if self.boundary[ui] && self.boundary[vi] {
                return false;
            }
            let (o1, o2) = (next(o), prev(o));
            if self.opp[o1 as usize] == NONE && self.opp[o2 as usize] == NONE {
                return false;
            }
            wr = self.corner[o2 as usize];
            if wr == wl {
                return false;
            }
        }
        // Link condition: ring(u) and ring(v) share exactly {wl, wr}.
        let st = self.mark_stamp;
        let start = self.vh[vi];
        let mut g = start;
        let mut deg_v = 0usize;
        loop {
            let w = self.to(g);
            deg_v += 1;
            if w != u && w != wl && w != wr && self.mark[w as usize] == st {
                return false;
            }
            let pg = prev(g);
            let og = self.opp[pg as usize];
            if og == NONE {
                let w = self.corner[pg as usize];
                deg_v += 1;
                if w != u && w != wl && w != wr && self.mark[w as usize] == st {
                    return false;
                }
                break;
            }
            if og == start || deg_v > self.corner.len() {
                break;
            }
            g = og;
        }
        // A closed tetrahedron has no legal collapse.
        !(o != NONE && !self.boundary[vi] && deg_u == 3 && deg_v == 3)
    }

    /// Quadric priority of collapsing `h` (ModQuadricT::collapse_priority).
    #[inline]
    fn priority(&self, h: u32) -> f64 {
        let (u, v) = (self.corner[h as usize], self.to(h));
        self.quadric[u as usize].eval_sum(&self.quadric[v as usize], &self.pos[v as usize])
    }

    /// The binary modules (normal flipping, normal cone) for `h`, given the outgoing
    /// halfedges `out` of `u`.
    fn geometry_legal(&self, h: u32, out: &[u32]) -> bool {
        let v = self.to(h);
        let pv = self.pos[v as usize];
        let fl = h / 3;
        let o = self.opp[h as usize];
        let fr = if o == NONE { NONE } else { o / 3 };
        // Faces that inherit the cones of the removed faces (ModNormalDeviationT).
        let b = self.opp[prev(h) as usize];
        let fb = if b == NONE { NONE } else { b / 3 };
        let c = if o == NONE {
            NONE
        } else {
            self.opp[next(o) as usize]
        };
        let fc = if c == NONE { NONE } else { c / 3 };
        for &g in out {
            let f = g / 3;
            if f == fl || f == fr {
                continue;
            }
            let p1 = self.pos[self.to(g) as usize];
            let p2 = self.pos[self.corner[prev(g) as usize] as usize];
            let (e1, e2) = (p1 - pv, p2 - pv);
            let cr = e1.cross(&e2);
            let len = cr.norm();
            // Degenerate (or NaN) result: illegal.
            if len.partial_cmp(&(1e-12 * e1.norm() * e2.norm()))
                != Some(std::cmp::Ordering::Greater)
            {
                return false;
            }
            let nn = cr / len;
            if nn.dot(&self.normal[f as usize]) < self.min_cos {
                return false;
            }
            if let Some(max_cone) = self.cone_deg {
                let mut cone = self.cone[f as usize].merged(&Cone { n: nn, angle: 0.0 });
                if f == fb {
                    cone = cone.merged(&self.cone[fl as usize]);
                }
                if f == fc {
                    cone = cone.merged(&self.cone[fr as usize]);
                }
                if cone.angle > 0.5 * max_cone.to_radians() {
                    return false;
                }
            }
        }
        true
    }

    /// Recomputes vertex `x`'s best collapse and (re)inserts it in the heap.
    fn heap_vertex(&mut self, x: u32) {
        let xi = x as usize;
        if !self.alive[xi] || self.locked[xi] {
            self.heap.remove(x);
            return;
        }
        let mut hs = std::mem::take(&mut self.scratch_hs);
        self.outgoing(x, &mut hs);
        // Candidates by (priority, squared length, target); the first legal one wins.
        // Checking legality in that order gives the same answer as checking all, but
        // usually stops at the first.
        let mut cands = std::mem::take(&mut self.scratch_cands);
        cands.clear();
        for &h in &hs {
            let t = self.to(h);
            let l = (self.pos[t as usize] - self.pos[xi]).norm_squared();
            cands.push((self.priority(h), l, t, h));
        }
        cands.sort_unstable_by(|a, b| {
            (a.0, a.1, a.2)
                .partial_cmp(&(b.0, b.1, b.2))
                .unwrap_or(std::cmp::Ordering::Equal)
        });
        let mut best = None;
        let mut deg = None;
        for &c in &cands {
            let d = *deg.get_or_insert_with(|| self.mark_ring(&hs));
            if self.topo_legal_marked(c.3, d) && self.geometry_legal(c.3, &hs) {
                best = Some(c);
                break;
            }
        }
        self.scratch_cands = cands;
        self.scratch_hs = hs;
        match best {
            Some((p, l, _, h)) => {
                self.best[xi] = h;
                self.heap.set(x, (key(p), key(l), x));
            }
            None => self.heap.remove(x),
        }
    }

    fn init_heap(&mut self) {
        self.heap.clear();
        for x in 0..self.alive.len() as u32 {
            self.heap_vertex(x);
        }
    }

    /// Pops one heap entry and performs its collapse if still legal; true if collapsed.
    fn step(&mut self) -> bool {
        let Some(x) = self.heap.pop() else {
            return false;
        };
        let h = self.best[x as usize];
        // DecimaterT re-checks topological legality only (the vertex leaves the heap).
        if !self.topo_legal(h) {
            return false;
        }
        let mut support = std::mem::take(&mut self.scratch_support);
        let mut scratch = std::mem::take(&mut self.scratch_hs);
        self.ring(x, &mut support, &mut scratch);
        self.scratch_hs = scratch;
        self.collapse(h);
        for &s in &support {
            self.heap_vertex(s);
        }
        self.scratch_support = support;
        true
    }

    /// Performs the collapse of `h` (`u -> v`), updating connectivity, quadrics, normals
    /// and cones.
    fn collapse(&mut self, h: u32) {
        let (u, v) = (self.corner[h as usize], self.to(h));
        let (h1, h2) = (next(h), prev(h));
        let wl = self.corner[h2 as usize];
        let (a, b) = (self.opp[h1 as usize], self.opp[h2 as usize]);
        let o = self.opp[h as usize];
        let fl = h / 3;
        let mut out = std::mem::take(&mut self.scratch_out);
        self.outgoing(u, &mut out);
        for &g in &out {
            self.corner[g as usize] = v;
        }
        self.scratch_out = out;
        if a != NONE {
            self.opp[a as usize] = b;
        }
        if b != NONE {
            self.opp[b as usize] = a;
        }
        self.face_alive[fl as usize] = false;
        let (mut wr, mut c, mut d, mut fr) = (NONE, NONE, NONE, NONE);
        if o != NONE {
            let (o1, o2) = (next(o), prev(o));
            wr = self.corner[o2 as usize];
            c = self.opp[o1 as usize];
            d = self.opp[o2 as usize];
            if c != NONE {
                self.opp[c as usize] = d;
            }
            if d != NONE {
                self.opp[d as usize] = c;
            }
            fr = o / 3;
            self.face_alive[fr as usize] = false;
        }
        self.alive[u as usize] = false;
        self.vh[u as usize] = NONE;
        self.n_alive -= 1;
        let nx = |e: u32| if e == NONE { NONE } else { next(e) };
        self.fix_vh(v, [self.vh[v as usize], b, d, nx(a), nx(c)]);
        self.fix_vh(wl, [self.vh[wl as usize], a, nx(b), NONE, NONE]);
        if wr != NONE {
            self.fix_vh(wr, [self.vh[wr as usize], c, nx(d), NONE, NONE]);
        }
        // ModQuadricT::postprocess_collapse.
        let qu = self.quadric[u as usize];
        self.quadric[v as usize].add(&qu);
        // Face normals around v (DecimaterT update_normals) and cones (ModNormalDeviationT).
        let mut out = std::mem::take(&mut self.scratch_out);
        self.outgoing(v, &mut out);
        for &g in &out {
            let f = g / 3;
            let [p0, p1, p2] =
                [g, next(g), prev(g)].map(|k| self.pos[self.corner[k as usize] as usize]);
            let nn = (p1 - p0).cross(&(p2 - p0)).normalize();
            self.normal[f as usize] = nn;
            if self.cone_deg.is_some() {
                self.cone[f as usize] = self.cone[f as usize].merged(&Cone { n: nn, angle: 0.0 });
            }
        }
        self.scratch_out = out;
        if self.cone_deg.is_some() {
            if b != NONE {
                self.cone[(b / 3) as usize] =
                    self.cone[(b / 3) as usize].merged(&self.cone[fl as usize]);
            }
            if c != NONE {
                self.cone[(c / 3) as usize] =
                    self.cone[(c / 3) as usize].merged(&self.cone[fr as usize]);
            }
        }
    }

    /// Points `vh[x]` at a live outgoing halfedge (the first valid candidate), rotated
    /// clockwise to the boundary if `x` is a boundary vertex.
    fn fix_vh(&mut self, x: u32, cands: [u32; 5]) {
        let h = cands
            .into_iter()
            .find(|&c| {
                c != NONE && self.face_alive[(c / 3) as usize] && self.corner[c as usize] == x
            })
            .expect("a live vertex keeps a live outgoing halfedge");
        let start = h;
        let mut h = h;
        for _ in 0..self.corner.len() {
            let o = self.opp[h as usize];
            if o == NONE {
                break;
            }
            let n = next(o);
            if n == start {
                break;
            }
            h = n;
        }
        self.vh[x as usize] = h;
    }

    /// Loosens the normal bounds; false if there is nothing left to loosen.
    fn relax(&mut self) -> bool {
        let changed = if let Some(c) = self.cone_deg {
            self.cone_deg = if c * 1.5 >= 360.0 {
                None
            } else {
                Some(c * 1.5)
            };
            true
        } else if self.flip_deg < 90.0 {
            self.flip_deg = (self.flip_deg + 15.0).min(90.0);
            true
        } else {
            false
        };
        if changed {
            self.min_cos = if self.flip_deg >= 90.0 {
                0.0
            } else {
                self.flip_deg.to_radians().cos()
            };
            self.relaxations.push((self.flip_deg, self.cone_deg));
        }
        changed
    }

    fn result(&self) -> Decimated {
        let n = self.alive.len();
        let mut new_id = vec![NONE; n];
        let mut landmarks = Vec::with_capacity(self.n_alive);
        let mut positions = Vec::with_capacity(self.n_alive);
        for (v, id) in new_id.iter_mut().enumerate() {
            if self.alive[v] {
                *id = landmarks.len() as u32;
                landmarks.push(v as u32);
                positions.push(self.orig[v]);
            }
        }
        let triangles = (0..self.face_alive.len())
            .filter(|&f| self.face_alive[f])
            .map(|f| std::array::from_fn(|i| new_id[self.corner[3 * f + i] as usize]))
            .collect();
        Decimated {
            mesh: TriMesh::new(positions, triangles),
            landmarks,
            relaxations: self.relaxations.clone(),
        }
    }
}

/// Binary min-heap of vertices with updatable keys (each vertex at most once).
struct IndexedHeap {
    items: Vec<u32>,
    /// Position of each vertex in `items`, or `NONE`.
    at: Vec<u32>,
    key: Vec<(u64, u64, u32)>,
}

impl IndexedHeap {
    fn new(n: usize) -> Self {
        Self {
            items: Vec::with_capacity(n),
            at: vec![NONE; n],
            key: vec![(0, 0, 0); n],
        }
    }

    fn is_empty(&self) -> bool {
        self.items.is_empty()
    }

    fn clear(&mut self) {
        for &v in &self.items {
            self.at[v as usize] = NONE;
        }
        self.items.clear();
    }

    /// Inserts `v` or changes its key.
    fn set(&mut self, v: u32, k: (u64, u64, u32)) {
        let vi = v as usize;
        self.key[vi] = k;
        let i = self.at[vi];
        if i == NONE {
            self.items.push(v);
            self.at[vi] = (self.items.len() - 1) as u32;
            self.up(self.items.len() - 1);
        } else {
            let i = i as usize;
            self.up(i);
            self.down(self.at[vi] as usize);
        }
    }

    fn remove(&mut self, v: u32) {
        let i = self.at[v as usize];
        if i == NONE {
            return;
        }
        let i = i as usize;
        let last = self.items.pop().expect("non-empty");
        self.at[v as usize] = NONE;
        if i < self.items.len() {
            self.items[i] = last;
            self.at[last as usize] = i as u32;
            self.up(i);
            self.down(self.at[last as usize] as usize);
        }
    }

    fn pop(&mut self) -> Option<u32> {
        let v = *self.items.first()?;
        self.remove(v);
        Some(v)
    }

    #[inline]
    fn less(&self, a: usize, b: usize) -> bool {
        self.key[self.items[a] as usize] < self.key[self.items[b] as usize]
    }

    fn swap(&mut self, a: usize, b: usize) {
        self.items.swap(a, b);
        self.at[self.items[a] as usize] = a as u32;
        self.at[self.items[b] as usize] = b as u32;
    }

    fn up(&mut self, mut i: usize) {
        while i > 0 {
            let p = (i - 1) / 2;
            if !self.less(i, p) {
                break;
            }
            self.swap(i, p);
            i = p;
        }
    }

    fn down(&mut self, mut i: usize) {
        loop {
            let (l, r) = (2 * i + 1, 2 * i + 2);
            let mut m = i;
            if l < self.items.len() && self.less(l, m) {
                m = l;
            }
            if r < self.items.len() && self.less(r, m) {
                m = r;
            }
            if m == i {
                break;
            }
            self.swap(i, m);
            i = m;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::error::NoProgress;
    use proptest::prelude::*;
    use wavg_mesh::procedural;

    fn valid(m: TriMesh) -> ValidMesh {
        ValidMesh::new(m).unwrap()
    }

    fn opts(target: usize) -> DecimateOptions {
        DecimateOptions {
            target,
            ..Default::default()
        }
    }

    /// Checks the invariants of a decimation result against its input and returns the
    /// validated coarse mesh.
    fn check(mesh: &ValidMesh, d: &Decimated, target: usize) -> ValidMesh {
        assert_eq!(d.landmarks.len(), target);
        assert!(
            d.landmarks.windows(2).all(|w| w[0] < w[1]),
            "sorted and distinct"
        );
        assert!(
            d.landmarks
                .iter()
                .all(|&l| (l as usize) < mesh.n_vertices())
        );
        for (i, &l) in d.landmarks.iter().enumerate() {
            assert_eq!(d.mesh.positions[i], mesh.positions[l as usize]);
        }
        let coarse = ValidMesh::new(d.mesh.clone()).expect("decimated mesh is a valid manifold");
        let (a, b) = (mesh.topology(), coarse.topology());
        assert_eq!(b.genus(), a.genus(), "genus");
        assert_eq!(
            b.boundary_loops().len(),
            a.boundary_loops().len(),
            "boundary loops"
        );
        assert_eq!(b.n_components(), a.n_components(), "components");
        // Orientation is kept: every coarse face normal agrees with the normals of the
        // original faces around its corners at least loosely (no flipped face).
        coarse
    }

    /// A disk: one centre vertex of valence `k` and a boundary ring of `k` vertices,
    /// slightly domed so that the quadrics are not all zero.
    fn fan(k: u32) -> TriMesh {
        let mut pos = vec![Vector3::new(0.0, 0.0, 0.3)];
        for i in 0..k {
            let a = std::f64::consts::TAU * i as f64 / k as f64;
            pos.push(Vector3::new(a.cos(), a.sin(), 0.0));
        }
        let tris = (0..k).map(|i| [0, 1 + i, 1 + (i + 1) % k]).collect();
        TriMesh::new(pos, tris)
    }

    fn grid_with_hole() -> TriMesh {
        let g = procedural::grid(30, 30, 1.0, 1.0);
        let tris = g
            .triangles
            .iter()
            .filter(|t| {
                let c = t
                    .iter()
                    .map(|&v| g.positions[v as usize])
                    .sum::<Vector3<f64>>()
                    / 3.0;
                (c - Vector3::new(0.5, 0.5, 0.0)).norm() > 0.2
            })
            .copied()
            .collect();
        let m = TriMesh::new(g.positions.clone(), tris);
        // Drop vertices that lost all faces.
        let mut used = vec![false; m.n_vertices()];
        for t in &m.triangles {
            for &v in t {
                used[v as usize] = true;
            }
        }
        let mut id = vec![u32::MAX; m.n_vertices()];
        let mut pos = Vec::new();
        for v in 0..m.n_vertices() {
            if used[v] {
                id[v] = pos.len() as u32;
                pos.push(m.positions[v]);
            }
        }
        TriMesh::new(
            pos,
            m.triangles
                .iter()
                .map(|t| t.map(|v| id[v as usize]))
                .collect(),
        )
    }

    #[test]
    fn keeps_topology_on_procedural_meshes() {
        let cases: Vec<(&str, TriMesh, usize)> = vec![
            ("icosphere", procedural::icosphere(4), 100),
            (
                "noisy sphere",
                procedural::with_noise(procedural::icosphere(4), 0.3, 2),
                60,
            ),
            ("torus", procedural::torus(60, 24, 1.0, 0.3), 80),
            ("grid", procedural::grid(40, 30, 2.0, 1.0), 50),
            ("grid with hole", grid_with_hole(), 60),
            ("bump", procedural::bump_sphere(4, 0.5), 30),
            ("fan of 4500 triangles", fan(4500), 4200),
        ];
        for (name, m, target) in cases {
            let mesh = valid(m);
            let d = decimate(&mesh, &opts(target), &NoProgress).unwrap();
            check(&mesh, &d, target);
            eprintln!(
                "{name}: {} -> {target} vertices, genus {}, {} boundary loops, relaxations {:?}",
                mesh.n_vertices(),
                mesh.topology().genus(),
                mesh.topology().boundary_loops().len(),
                d.relaxations
            );
        }
    }

    #[test]
    fn deterministic() {
        let mesh = valid(procedural::with_noise(
            procedural::torus(50, 20, 1.0, 0.3),
            0.2,
            5,
        ));
        let a = select_landmarks(&mesh, &opts(77), &NoProgress).unwrap();
        let b = select_landmarks(&mesh, &opts(77), &NoProgress).unwrap();
        assert_eq!(a, b);
    }

    #[test]
    fn quadric_keeps_the_sharp_feature() {
        // A flat grid with one spike: the spike's collapse costs a lot, so it survives.
        let mut g = procedural::grid(20, 20, 1.0, 1.0);
        let spike = 10 * 21 + 10;
        g.positions[spike].z = 0.5;
        let mesh = valid(g);
        let lm = select_landmarks(&mesh, &opts(12), &NoProgress).unwrap();
        assert!(lm.contains(&(spike as u32)), "{lm:?}");
        eprintln!("grid with spike -> {lm:?}");
    }

    #[test]
    fn bad_requests_are_refused() {
        let mesh = valid(procedural::icosphere(1));
        let n = mesh.n_vertices();
        for o in [
            opts(0),
            opts(n + 1),
            DecimateOptions {
                max_normal_deviation_deg: 0.0,
                ..opts(10)
            },
            DecimateOptions {
                max_normal_deviation_deg: f64::NAN,
                ..opts(10)
            },
            DecimateOptions {
                max_normal_cone_deg: Some(-1.0),
                ..opts(10)
            },
            DecimateOptions {
                locked: vec![n as u32],
                ..opts(10)
            },
            DecimateOptions {
                locked: (0..11).collect(),
                ..opts(10)
            },
        ] {
            assert!(
                matches!(
                    decimate(&mesh, &o, &NoProgress),
                    Err(EmbedError::InvalidArgument(_))
                ),
                "{o:?}"
            );
        }
        // Target = all vertices: nothing to do.
        let d = decimate(&mesh, &opts(n), &NoProgress).unwrap();
        assert_eq!(d.landmarks, (0..n as u32).collect::<Vec<_>>());
        assert_eq!(d.mesh.triangles, mesh.triangles);
    }

    #[test]
    fn topological_limits_are_errors_not_hangs() {
        // An icosahedron decimates to a tetrahedron, not further.
        let mesh = valid(procedural::icosphere(0));
        let d = decimate(&mesh, &opts(4), &NoProgress).unwrap();
        check(&mesh, &d, 4);
        assert!(matches!(
            decimate(&mesh, &opts(3), &NoProgress),
            Err(EmbedError::InvalidArgument(_))
        ));
        // A torus needs at least 7 vertices.
        let mesh = valid(procedural::torus(12, 6, 1.0, 0.3));
        let e = decimate(&mesh, &opts(5), &NoProgress).unwrap_err();
        eprintln!("torus to 5 vertices: {e}");
        // A single triangle cannot lose a vertex.
        let tri = valid(TriMesh::new(
            vec![Vector3::zeros(), Vector3::x(), Vector3::y()],
            vec![[0, 1, 2]],
        ));
        assert!(decimate(&tri, &opts(2), &NoProgress).is_err());
    }

    #[test]
    fn locked_vertices_survive() {
        let mesh = valid(procedural::icosphere(3));
        let locked: Vec<u32> = (0..40).map(|i| i * 13 + 1).collect();
        let d = decimate(
            &mesh,
            &DecimateOptions {
                locked: locked.clone(),
                ..opts(50)
            },
            &NoProgress,
        )
        .unwrap();
        check(&mesh, &d, 50);
        for l in locked {
            assert!(d.coarse_index(l).is_some(), "{l}");
        }
    }

    #[test]
    fn tight_bounds_are_relaxed_to_reach_the_target() {
        let mesh = valid(procedural::with_noise(procedural::icosphere(4), 0.3, 8));
        let o = DecimateOptions {
            max_normal_deviation_deg: 2.0,
            max_normal_cone_deg: Some(10.0),
            ..opts(40)
        };
        let d = decimate(&mesh, &o, &NoProgress).unwrap();
        check(&mesh, &d, 40);
        assert!(!d.relaxations.is_empty());
        eprintln!("relaxations {:?}", d.relaxations);
        let strict = DecimateOptions { relax: false, ..o };
        assert!(decimate(&mesh, &strict, &NoProgress).is_err());
    }

    #[test]
    fn normal_cone_module() {
        let mesh = valid(procedural::bump_sphere(4, 0.5));
        let o = DecimateOptions {
            max_normal_cone_deg: Some(60.0),
            ..opts(200)
        };
        let d = decimate(&mesh, &o, &NoProgress).unwrap();
        check(&mesh, &d, 200);
    }

    #[test]
    fn snapshots_are_nested() {
        let mesh = valid(procedural::with_noise(
            procedural::torus(60, 24, 1.0, 0.3),
            0.2,
            1,
        ));
        let n = mesh.n_vertices();
        let (fin, snaps) =
            decimate_with_snapshots(&mesh, &opts(70), &[500, n, 70, 200], &NoProgress).unwrap();
        let direct = decimate(&mesh, &opts(70), &NoProgress).unwrap();
        assert_eq!(fin.landmarks, direct.landmarks);
        for (s, want) in snaps.iter().zip([500, n, 70, 200]) {
            check(&mesh, s, want);
            assert!(fin.landmarks.iter().all(|l| s.coarse_index(*l).is_some()));
        }
        assert_eq!(snaps[2].landmarks, fin.landmarks);
        assert!(
            snaps[0]
                .landmarks
                .iter()
                .all(|l| snaps[1].coarse_index(*l).is_some())
        );
        assert!(decimate_with_snapshots(&mesh, &opts(70), &[60], &NoProgress).is_err());
    }

    #[test]
    fn cancellation() {
        struct Stop;
        impl Progress for Stop {
            fn report(&self, _: Stage, _: f64) {}
            fn cancelled(&self) -> bool {
                true
            }
        }
        let mesh = valid(procedural::icosphere(5));
        assert!(matches!(
            decimate(&mesh, &opts(100), &Stop),
            Err(EmbedError::Cancelled)
        ));
    }

    #[test]
    fn real_meshes_keep_topology() {
        for (file, target) in [
            ("meshes/pig.off", 1000),
            ("meshes/fertility.off", 1000),
            ("meshes/camelhead.off", 1000),
            ("meshes/3holes.off", 300),
            ("meshes/torus.obj", 50),
        ] {
            let Some(path) = wavg_testdata::require_data_file("decimate::real_meshes", file) else {
                return;
            };
            let mesh = valid(wavg_mesh::io::load(&path).unwrap());
            let t = std::time::Instant::now();
            let d = decimate(&mesh, &opts(target), &NoProgress).unwrap();
            let secs = t.elapsed().as_secs_f64();
            check(&mesh, &d, target);
            eprintln!(
                "{file}: {} -> {target} vertices in {secs:.3} s (test build), genus {}, {} loops, relaxations {:?}",
                mesh.n_vertices(),
                mesh.topology().genus(),
                mesh.topology().boundary_loops().len(),
                d.relaxations
            );
        }
    }

    proptest! {
        #[test]
        fn indexed_heap_pops_in_key_order(ops in proptest::collection::vec((0u32..50, 0u64..20, any::<bool>()), 0..300)) {
            let mut h = IndexedHeap::new(50);
            let mut model = std::collections::BTreeMap::new();
            for (v, k, set) in ops {
                if set {
                    h.set(v, (k, 0, v));
                    model.insert(v, (k, 0, v));
                } else {
                    h.remove(v);
                    model.remove(&v);
                }
            }
            let mut want: Vec<_> = model.into_values().collect();
            want.sort();
            let mut got = Vec::new();
            while let Some(v) = h.pop() {
                got.push(h.key[v as usize]);
            }
            prop_assert_eq!(got, want);
        }
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(24))]
        #[test]
        fn random_meshes_and_targets(seed in 0u64..10_000, kind in 0usize..3, frac in 0.02f64..0.9) {
            let m = match kind {
                0 => procedural::with_noise(procedural::icosphere(3), 0.4, seed),
                1 => procedural::with_noise(procedural::torus(24, 12, 1.0, 0.35), 0.4, seed),
                _ => procedural::with_noise(procedural::grid(16, 12, 1.0, 1.0), 0.4, seed),
            };
            let mesh = valid(m);
            let target = ((mesh.n_vertices() as f64 * frac) as usize).max(12);
            let d = decimate(&mesh, &opts(target), &NoProgress).unwrap();
            check(&mesh, &d, target);
        }
    }
}
