//! Projection of points of R^8 onto the embedded mesh: Phong (fast, exhaustive, brute
//! force) and Euclidean.
//!
//! The fast path walks greedily over the vertex graph from a start vertex to a vertex
//! locally closest to the target, then tests the triangles around it (most promising
//! first) and their neighbours. A valid projection at (numerically) zero distance is a
//! global minimum and is returned at once. Any other local answer is *certified*: a
//! branch and bound over the bounding volume hierarchy visits every triangle whose box is
//! closer than that answer, so the fast path returns the same closest valid projection as
//! the exhaustive search, never a far-off triangle. `ProjectionPath` says which happened.

use std::sync::Arc;

use rayon::prelude::*;
use wavg_mesh::{FaceId, NONE, SurfacePoint, VertexId};

use crate::bvh::Bvh;
use crate::euclid::closest_point_barycentric;
use crate::frames::FrameKind;
use crate::triangle::{Frame32, TriData, frame_to_f32, frame_to_f64};
use crate::{EmbeddedMesh, Mat2x8, ProjectError, Vec8};

/// A distance below this fraction of the triangle's longest edge counts as zero: such a
/// projection is a global minimum up to rounding (the tangent equations of a point on a
/// triangle hold to f64 precision), so the fast path returns it without certification.
pub const ZERO_DISTANCE: f64 = 1e-10;

/// Faces the local search may test before certifying or falling back.
const LOCAL_BUDGET: usize = 64;

/// Which search produced a projection.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ProjectionPath {
    /// The local search around the walk's end found it (certified closest).
    Local,
    /// The local search found nothing or was beaten; the global search was used.
    Fallback,
    /// The exhaustive search (branch and bound or brute force).
    Exhaustive,
    /// Euclidean closest point (not a Phong projection).
    Euclidean,
}

/// A projected point.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Projection {
    /// Face and barycentrics (non-negative, summing to 1).
    pub point: SurfacePoint,
    /// Distance in R^8 between the embedded point and the query.
    pub distance: f64,
    /// Which search found it.
    pub path: ProjectionPath,
}

/// Precomputed frames and per-triangle data of an embedded mesh; `Send + Sync`.
pub struct Projector {
    emb: Arc<EmbeddedMesh>,
    verts: Vec<VertexRec>,
    frame_kinds: [usize; 4],
    faces: Vec<Face>,
    bvh: Bvh,
    walk_origin: Vec8,
    walk_inv_step: f64,
    walk_coords: Vec<WalkPoint>,
}

/// Queries whose walks [`Projector::project_batch`] interleaves.
pub const WALK_GROUP: usize = 8;

/// Neighbours (and faces) stored in a vertex's walk record; larger rings come from the
/// topology.
const WALK_RING: usize = 12;

/// A vertex as the walk sees it, in two cache lines. The first holds its coordinates as
/// 16-bit integers on a uniform grid over the bounding box (65535 steps along its longest
/// side) and its one-ring: reading a neighbour's distance brings in its ring too, so a
/// walk step waits for one round of (parallel) memory accesses. The second holds the
/// faces around it, so the walk's end leads straight to the candidate faces without two
/// more dependent reads of the topology. Only the greedy walk and the ordering of
/// candidate faces use the coordinates (heuristics; every answer is computed and
/// certified in f64).
#[derive(Clone, Copy, Debug)]
#[repr(C, align(64))]
struct WalkPoint {
    c: [u16; 8],
    ring: [u32; WALK_RING],
    faces: [u32; WALK_RING],
    /// Ring length, or `u32::MAX` if it does not fit.
    n: u32,
    /// Number of faces around the vertex (ring length, one less on a boundary).
    nf: u32,
}

impl WalkPoint {
    #[inline(always)]
    fn unpack(&self) -> [f32; 8] {
        std::array::from_fn(|k| self.c[k] as f32)
    }

    /// Squared distance from these coordinates to `y` (walk units): [`wdist2`] of
    /// [`WalkPoint::unpack`], bit for bit, with the conversion done four lanes at a time.
    #[inline(always)]
    fn dist2(&self, y: &[f32; 8]) -> f32 {
        #[cfg(target_arch = "x86_64")]
        return crate::arch::dist2_u16(&self.c, y);
        #[cfg(not(target_arch = "x86_64"))]
        wdist2(&self.unpack(), y)
    }

    #[inline(always)]
    fn ring<'a>(&'a self, topo: &'a wavg_mesh::Topology, v: VertexId) -> &'a [u32] {
        if (self.n as usize) <= WALK_RING {
            &self.ring[..self.n as usize]
        } else {
            topo.ring(v)
        }
    }

    #[inline(always)]
    fn faces<'a>(&'a self, topo: &'a wavg_mesh::Topology, v: VertexId) -> &'a [u32] {
        if (self.n as usize) <= WALK_RING {
            &self.faces[..self.nf as usize]
        } else {
            topo.ring_faces(v)
        }
    }
}

#[cfg_attr(target_arch = "x86_64", allow(dead_code))] // the reference for `dist2`
/// Squared distance of walk coordinates, summed as two 4-lane halves and a fixed tree so
/// the compiler can keep it in SIMD registers (a sequential sum cannot be reordered).
#[inline(always)]
fn wdist2(a: &[f32; 8], b: &[f32; 8]) -> f32 {
    let mut s = [0.0f32; 4];
    for k in 0..4 {
        let d0 = a[k] - b[k];
        let d1 = a[k + 4] - b[k + 4];
        s[k] = d0 * d0 + d1 * d1;
    }
    (s[0] + s[2]) + (s[1] + s[3])
}

/// What a query reads of a vertex, in two adjacent cache lines: its embedded point (f64,
/// for the tangent equations) and its frame (f32).
#[derive(Clone, Copy, Debug)]
#[repr(C, align(64))]
struct VertexRec {
    x: Vec8,
    t: Frame32,
}

/// What a query reads of a face, in two cache lines: its blend matrices and corners.
#[derive(Clone, Copy, Debug, Default)]
#[repr(C, align(64))]
struct Face {
    d: TriData,
    v: [u32; 3],
}

/// Faces around a vertex in the order [`Projector::faces_by_promise`] gives them.
#[derive(Clone, Copy, Debug)]
pub struct FaceOrder {
    faces: [FaceId; 64],
    n: usize,
}

impl FaceOrder {
    const EMPTY: Self = Self {
        faces: [0; 64],
        n: 0,
    };

    /// The faces, most promising first.
    pub fn as_slice(&self) -> &[FaceId] {
        &self.faces[..self.n]
    }
}

/// Small fixed set of face ids (no allocation per query).
struct Tested {
    ids: [u32; LOCAL_BUDGET],
    n: usize,
}

impl Tested {
    fn new() -> Self {
        Self {
            ids: [0; LOCAL_BUDGET],
            n: 0,
        }
    }
    fn contains(&self, f: u32) -> bool {
        self.ids[..self.n].contains(&f)
    }
    fn full(&self) -> bool {
        self.n == LOCAL_BUDGET
    }
    fn push(&mut self, f: u32) {
        self.ids[self.n] = f;
        self.n += 1;
    }
}

#[derive(Clone, Copy)]
struct Best {
    face: u32,
    xi: [f64; 3],
    d2: f64,
}

impl Projector {
    /// Computes the vertex frames, the per-triangle data and the bounding volume hierarchy.
    pub fn new(emb: Arc<EmbeddedMesh>) -> Result<Self, ProjectError> {
        let mesh = emb.mesh();
        if mesh.n_faces() == 0 {
            return Err(ProjectError::EmptyMesh);
        }
        let coords = emb.coords();
        let chunk = 4096;
        let (verts, kinds): (Vec<VertexRec>, Vec<FrameKind>) = (0..mesh.n_vertices())
            .into_par_iter()
            .with_min_len(chunk)
            .map(|v| {
                let (t, k) = crate::frames::vertex_frame(mesh, coords, v as u32);
                let rec = VertexRec {
                    x: coords[v],
                    t: frame_to_f32(&t),
                };
                (rec, k)
            })
            .unzip();
        let verts = crate::hugepage::collect(verts.len(), verts);
        let mut frame_kinds = [0; 4];
        for k in kinds {
            frame_kinds[k as usize] += 1;
        }
        const BATCH: usize = 4;
        let mut faces = crate::hugepage::vec_with_capacity(mesh.n_faces());
        faces.resize(mesh.n_faces(), Face::default());
        faces
            .par_chunks_mut(BATCH)
            .zip(mesh.triangles.par_chunks(BATCH))
            .with_min_len(chunk / BATCH)
            .for_each(|(out, ts)| {
                let fr = |t: &[u32; 3]| t.map(|v| &verts[v as usize].t);
                if ts.len() == BATCH {
                    let d = TriData::new_batch([fr(&ts[0]), fr(&ts[1]), fr(&ts[2]), fr(&ts[3])]);
                    for i in 0..BATCH {
                        out[i] = Face { d: d[i], v: ts[i] };
                    }
                } else {
                    for (o, t) in out.iter_mut().zip(ts) {
                        *o = Face {
                            d: TriData::new(fr(t)),
                            v: *t,
                        };
                    }
                }
            });
        let bvh = Bvh::new(&mesh.triangles, coords);
        let (lo, hi) = coords.iter().fold(
            (Vec8::repeat(f64::INFINITY), Vec8::repeat(f64::NEG_INFINITY)),
            |(l, h), c| (l.inf(c), h.sup(c)),
        );
        let walk_origin = lo;
        let extent = (hi - lo).max();
        let walk_inv_step = if extent > 0.0 && extent.is_finite() {
            65535.0 / extent
        } else {
            1.0
        };
        let walk_coords = crate::hugepage::collect(
            coords.len(),
            coords.iter().enumerate().map(|(v, c)| {
                let r = mesh.topology().ring(v as u32);
                let rf = mesh.topology().ring_faces(v as u32);
                let mut ring = [0u32; WALK_RING];
                let mut faces = [0u32; WALK_RING];
                let n = if r.len() <= WALK_RING {
                    ring[..r.len()].copy_from_slice(r);
                    faces[..rf.len()].copy_from_slice(rf);
                    r.len() as u32
                } else {
                    u32::MAX
                };
                WalkPoint {
                    c: std::array::from_fn(|k| {
                        ((c[k] - walk_origin[k]) * walk_inv_step)
                            .round()
                            .clamp(0.0, 65535.0) as u16
                    }),
                    ring,
                    faces,
                    n,
                    nf: rf.len() as u32,
                }
            }),
        );
        Ok(Self {
            emb,
            verts,
            frame_kinds,
            faces,
            bvh,
            walk_origin,
            walk_inv_step,
            walk_coords,
        })
    }

    /// The embedded mesh.
    pub fn embedded(&self) -> &Arc<EmbeddedMesh> {
        &self.emb
    }

    /// Tangent frame of vertex `v` (orthonormal rows, as stored in f32).
    pub fn frame(&self, v: VertexId) -> Mat2x8 {
        frame_to_f64(&self.verts[v as usize].t)
    }

    /// How many vertex frames came from each rule: interior stencil, boundary rules,
    /// fitted plane, arbitrary completion.
    pub fn frame_kind_counts(&self) -> [usize; 4] {
        self.frame_kinds
    }

    /// Bytes of the projector's own data plus the embedded coordinates.
    pub fn bytes(&self) -> usize {
        std::mem::size_of_val(&self.verts[..])
            + std::mem::size_of_val(&self.faces[..])
            + self.bvh.bytes()
            + std::mem::size_of_val(&self.walk_coords[..])
            + std::mem::size_of_val(self.emb.coords())
    }

    fn face_frames(&self, f: FaceId) -> [&Frame32; 3] {
        self.faces[f as usize].v.map(|v| &self.verts[v as usize].t)
    }

    /// Interpolated tangent plane at a surface point (rows span it; near-orthonormal).
    ///
    /// ```
    /// use std::sync::Arc;
    /// use wavg_mesh::{SurfacePoint, ValidMesh, procedural};
    /// use wavg_project::{EmbeddedMesh, Projector};
    /// let m = Arc::new(ValidMesh::new(procedural::grid(3, 3, 1.0, 1.0)).unwrap());
    /// let p = Projector::new(Arc::new(EmbeddedMesh::from_positions(m))).unwrap();
    /// let psi = p.psi(&SurfacePoint::new(4, [0.2, 0.3, 0.5]));
    /// assert!(psi.column(2).norm() < 1e-6); // the grid lies in the z = 0 plane
    /// ```
    pub fn psi(&self, p: &SurfacePoint) -> Mat2x8 {
        self.faces[p.face as usize]
            .d
            .psi(self.face_frames(p.face), &p.bary)
    }

    /// `Psi` and the embedded point at `p` together, from the projector's own records
    /// (one face record and its corners': half the dependent memory reads of
    /// [`Projector::psi`] plus [`EmbeddedMesh::point`]).
    ///
    /// ```
    /// use std::sync::Arc;
    /// use wavg_mesh::{SurfacePoint, ValidMesh, procedural};
    /// use wavg_project::{EmbeddedMesh, Projector};
    /// let m = Arc::new(ValidMesh::new(procedural::icosphere(1)).unwrap());
    /// let emb = Arc::new(EmbeddedMesh::from_positions(m));
    /// let p = Projector::new(emb.clone()).unwrap();
    /// let q = SurfacePoint::new(3, [0.2, 0.3, 0.5]);
    /// let (psi, y) = p.psi_and_point(&q);
    /// assert_eq!(psi, p.psi(&q));
    /// assert!((y - emb.point(&q)).norm() < 1e-15);
    /// ```
    pub fn psi_and_point(&self, p: &SurfacePoint) -> (Mat2x8, Vec8) {
        let face = &self.faces[p.face as usize];
        let r = face.v.map(|v| &self.verts[v as usize]);
        let psi = face.d.psi([&r[0].t, &r[1].t, &r[2].t], &p.bary);
        let y = r[0].x * p.bary[0] + r[1].x * p.bary[1] + r[2].x * p.bary[2];
        (psi, y)
    }

    /// Starts loading what [`Projector::psi_and_point`] reads of face `f`: its record
    /// (`corners == false`), or its corners' records, reading the face record for their
    /// ids (`corners == true`; request the record a few queries earlier). For software
    /// pipelining over batches; no effect on results.
    #[inline]
    pub(crate) fn prefetch_point_data(&self, f: FaceId, corners: bool) {
        let Some(face) = self.faces.get(f as usize) else {
            return;
        };
        if corners {
            for v in face.v {
                prefetch(&self.verts[v as usize]);
            }
        } else {
            prefetch(face);
        }
    }

    /// Partial derivatives of `Psi` with respect to the three barycentrics at `p`.
    pub fn psi_derivatives(&self, p: &SurfacePoint) -> [Mat2x8; 3] {
        self.faces[p.face as usize]
            .d
            .psi_derivatives(self.face_frames(p.face), &p.bary)
    }

    /// Phong projection of `y` onto face `f` alone (barycentrics), if Newton finds one.
    pub fn project_onto_face(&self, y: &Vec8, f: FaceId) -> Option<[f64; 3]> {
        self.try_face(f, y).map(|b| b.xi)
    }

    /// [`Projector::project_onto_face`] with the distance in R^8 from the projection to
    /// `y` (computed from the corners already loaded, no further lookups).
    ///
    /// ```
    /// use std::sync::Arc;
    /// use wavg_mesh::{SurfacePoint, ValidMesh, procedural};
    /// use wavg_project::{EmbeddedMesh, Projector};
    /// let m = Arc::new(ValidMesh::new(procedural::grid(3, 3, 1.0, 1.0)).unwrap());
    /// let emb = Arc::new(EmbeddedMesh::from_positions(m));
    /// let p = Projector::new(emb.clone()).unwrap();
    /// let mut y = emb.point(&SurfacePoint::new(4, [0.2, 0.3, 0.5]));
    /// y[2] += 0.25; // off the plane z = 0
    /// let (xi, d) = p.project_onto_face_with_distance(&y, 4).unwrap();
    /// assert!((d - 0.25).abs() < 1e-12 && (xi[0] - 0.2).abs() < 1e-9);
    /// ```
    pub fn project_onto_face_with_distance(&self, y: &Vec8, f: FaceId) -> Option<([f64; 3], f64)> {
        self.try_face(f, y).map(|b| (b.xi, b.d2.sqrt()))
    }

    /// [`Projector::project_onto_face_with_distance`], or on failure the neighbouring face
    /// across the edge Newton's method left this one by (where the projection more likely
    /// lies; [`NONE`] when it did not leave by an edge or the edge is on the boundary).
    ///
    /// ```
    /// use std::sync::Arc;
    /// use wavg_mesh::{SurfacePoint, ValidMesh, procedural};
    /// use wavg_project::{EmbeddedMesh, Projector};
    /// let m = Arc::new(ValidMesh::new(procedural::grid(3, 3, 1.0, 1.0)).unwrap());
    /// let emb = Arc::new(EmbeddedMesh::from_positions(m.clone()));
    /// let p = Projector::new(emb.clone()).unwrap();
    /// // A point of face 4, tried on a neighbour of face 4: Newton leaves towards face 4.
    /// let y = emb.point(&SurfacePoint::new(4, [0.2, 0.3, 0.5]));
    /// let g = m.topology().face_neighbors(4).into_iter().find(|&g| g != u32::MAX).unwrap();
    /// assert_eq!(p.project_onto_face_or_exit(&y, g), Err(4));
    /// assert!(p.project_onto_face_or_exit(&y, 4).is_ok());
    /// ```
    pub fn project_onto_face_or_exit(
        &self,
        y: &Vec8,
        f: FaceId,
    ) -> Result<([f64; 3], f64), FaceId> {
        match self.try_face_or_exit(f, y) {
            Ok(b) => Ok((b.xi, b.d2.sqrt())),
            // Corner k's coordinate went negative: out across the edge (k + 1, k + 2).
            Err(Some(k)) => Err(self.emb.mesh().topology().face_neighbors(f)[(k + 1) % 3]),
            Err(None) => Err(NONE),
        }
    }

    /// The corner vertices of face `f` (from the projector's face record, usually in cache
    /// after a projection onto it).
    ///
    /// ```
    /// use std::sync::Arc;
    /// use wavg_mesh::{ValidMesh, procedural};
    /// use wavg_project::{EmbeddedMesh, Projector};
    /// let m = Arc::new(ValidMesh::new(procedural::icosphere(1)).unwrap());
    /// let p = Projector::new(Arc::new(EmbeddedMesh::from_positions(m.clone()))).unwrap();
    /// assert_eq!(p.face_corners(7), m.triangles[7]);
    /// ```
    pub fn face_corners(&self, f: FaceId) -> [VertexId; 3] {
        self.faces[f as usize].v
    }

    #[inline]
    fn try_face(&self, f: FaceId, y: &Vec8) -> Option<Best> {
        self.try_face_or_exit(f, y).ok()
    }

    /// [`Projector::try_face`], or on failure the corner whose coordinate Newton's method
    /// drove negative (see [`TriData::solve_or_exit`]).
    #[inline]
    fn try_face_or_exit(&self, f: FaceId, y: &Vec8) -> Result<Best, Option<usize>> {
        let face = &self.faces[f as usize];
        let r = [
            &self.verts[face.v[0] as usize],
            &self.verts[face.v[1] as usize],
            &self.verts[face.v[2] as usize],
        ];
        let xi =
            face.d
                .solve_or_exit([&r[0].t, &r[1].t, &r[2].t], [&r[0].x, &r[1].x, &r[2].x], y)?;
        let (a, b, cc) = (&r[0].x.data.0[0], &r[1].x.data.0[0], &r[2].x.data.0[0]);
        let yy = &y.data.0[0];
        let mut d2 = 0.0;
        for k in 0..8 {
            let d = a[k] * xi[0] + b[k] * xi[1] + cc[k] * xi[2] - yy[k];
            d2 += d * d;
        }
        Ok(Best { face: f, xi, d2 })
    }

    fn is_zero(&self, b: &Best) -> bool {
        let [p, q, r] = self.corners(b.face);
        let scale2 = (q - p)
            .norm_squared()
            .max((r - q).norm_squared())
            .max((p - r).norm_squared());
        b.d2 <= ZERO_DISTANCE * ZERO_DISTANCE * scale2
    }

    #[inline]
    fn corners(&self, f: FaceId) -> [Vec8; 3] {
        self.faces[f as usize].v.map(|v| self.verts[v as usize].x)
    }

    fn finish(b: Best, path: ProjectionPath) -> Projection {
        Projection {
            point: SurfacePoint::new(b.face, b.xi),
            distance: b.d2.sqrt(),
            path,
        }
    }

    /// Fast path: greedy vertex walk from `start` towards `y` in R^8, then a local triangle
    /// search, certified against the bounding volume hierarchy; the global search is used
    /// when the local one finds nothing or is beaten (reported as `Fallback`).
    pub fn project(&self, y: &Vec8, start: VertexId) -> Result<Projection, ProjectError> {
        let mesh = self.emb.mesh();
        if !y.iter().all(|v| v.is_finite()) {
            return Err(ProjectError::NonFiniteQuery);
        }
        if start as usize >= mesh.n_vertices() {
            return Err(ProjectError::StartOutOfRange {
                vertex: start,
                n_vertices: mesh.n_vertices(),
            });
        }
        // 1. Greedy walk.
        let mut ring_d = [0.0f32; 64];
        let v = self.walk_inner(y, start, &mut ring_d);
        // 2. Faces around v, most promising first.
        let cands = self.order_faces(y, v, &ring_d);
        self.search_around(y, v, &cands)
    }

    /// Steps 2-4 of [`Projector::project`]: the faces around the walk's end `v` in the
    /// order `cands`, their neighbours, then certification or the global search.
    fn search_around(
        &self,
        y: &Vec8,
        v: VertexId,
        cands: &FaceOrder,
    ) -> Result<Projection, ProjectError> {
        let topo = self.emb.mesh().topology();
        let (order, m) = (&cands.faces, cands.n);
        let faces = self.walk_coords[v as usize].faces(topo, v);
        let mut tested = Tested::new();
        let mut best: Option<Best> = None;
        let consider = |f: u32, tested: &mut Tested, best: &mut Option<Best>| -> bool {
            tested.push(f);
            // Once something is found, only a strictly closer answer matters: the cheap
            // lower bounds of `try_face_bounded` skip most of the remaining faces.
            let found = match best {
                None => self.try_face(f, y),
                Some(x) => self.try_face_bounded(f, y, x.d2),
            };
            if let Some(b) = found {
                *best = Some(b);
                return self.is_zero(&b);
            }
            false
        };
        for &f in &order[..m] {
            if consider(f, &mut tested, &mut best) {
                return Ok(Self::finish(
                    best.unwrap_or_else(|| unreachable!()),
                    ProjectionPath::Local,
                ));
            }
        }
        for &f in faces.iter().skip(m) {
            if tested.full() {
                break;
            }
            if consider(f, &mut tested, &mut best) {
                return Ok(Self::finish(
                    best.unwrap_or_else(|| unreachable!()),
                    ProjectionPath::Local,
                ));
            }
        }
        // 3. Their neighbours across edges.
        if best.is_none() {
            let n_ring = tested.n;
            'outer: for i in 0..n_ring {
                for g in topo.face_neighbors(tested.ids[i]) {
                    if g == NONE || tested.contains(g) {
                        continue;
                    }
                    if tested.full() {
                        break 'outer;
                    }
                    if consider(g, &mut tested, &mut best) {
                        return Ok(Self::finish(
                            best.unwrap_or_else(|| unreachable!()),
                            ProjectionPath::Local,
                        ));
                    }
                }
            }
        }
        // 4. Certify (or search globally).
        match best {
            Some(local) => {
                let mut improved = None;
                let mut bound = local.d2;
                self.bvh.search(y, &mut bound, |f, bound| {
                    if tested.contains(f) {
                        return;
                    }
                    if let Some(b) = self.try_face_bounded(f, y, *bound) {
                        *bound = b.d2;
                        improved = Some(b);
                    }
                });
                Ok(match improved {
                    Some(b) => Self::finish(b, ProjectionPath::Fallback),
                    None => Self::finish(local, ProjectionPath::Local),
                })
            }
            None => self
                .exhaustive(y)
                .map(|b| Self::finish(b, ProjectionPath::Fallback))
                .ok_or(ProjectError::NoProjection),
        }
    }

    /// [`Projector::project`] for many queries on the calling thread, with the same
    /// results (in input order). Queries are visited in Morton order of their first three
    /// embedded coordinates, so nearby ones share cached data (this alone halves the
    /// certification cost of off-surface queries), and the greedy walks of [`WALK_GROUP`]
    /// queries advance in turn, each step
    /// requesting the records the next step reads, so their memory waits overlap instead
    /// of adding up; then the first candidate face of every query in the group is
    /// requested before any is solved. Parallelise over chunks of queries.
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
        let n = ys.len().min(starts.len());
        // Nearby queries one after the other (Morton order of the first three embedded
        // coordinates), so consecutive walks share cached records; results in input order.
        let mut order: Vec<(u32, u32)> = (0..n)
            .map(|i| (self.locality_key(&ys[i]), i as u32))
            .collect();
        order.sort_unstable();
        let mut out: Vec<Option<Result<Projection, ProjectError>>> =
            std::iter::repeat_with(|| None).take(n).collect();
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
                for (k, &(_, i)) in group.iter().enumerate() {
                    out[i as usize] = Some(self.project(&yc[k], sc[k]));
                }
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
            for (k, &(_, i)) in group.iter().enumerate() {
                out[i as usize] = Some(self.search_around(&yc[k], ends[k], &cands[k]));
            }
        }
        out.into_iter()
            .map(|r| r.unwrap_or(Err(ProjectError::NoProjection)))
            .collect()
    }

    /// A 30-bit Morton code of the first three walk coordinates of `y` (10 bits each;
    /// anything outside the bounding box, or not finite, clamps to its faces): sorting
    /// queries by it puts nearby ones together, so their searches share cached data.
    ///
    /// ```
    /// use std::sync::Arc;
    /// use wavg_mesh::{ValidMesh, procedural};
    /// use wavg_project::{EmbeddedMesh, Projector};
    /// let m = Arc::new(ValidMesh::new(procedural::icosphere(2)).unwrap());
    /// let emb = Arc::new(EmbeddedMesh::from_positions(m));
    /// let p = Projector::new(emb.clone()).unwrap();
    /// let y = emb.coords()[0];
    /// use wavg_project::internal::locality_key;
    /// assert_eq!(locality_key(&p, &y), locality_key(&p, &(y * (1.0 + 1e-12))));
    /// assert!(locality_key(&p, &y) < 1 << 30);
    /// ```
    pub(crate) fn locality_key(&self, y: &Vec8) -> u32 {
        let w = self.walk_point(y);
        let spread = |c: f32| {
            // `as` saturates (NaN to 0): a coordinate in 0..=1023.
            let mut x = ((c as u32).min(65535) >> 6) & 0x3ff;
            x = (x | (x << 16)) & 0x0300_00ff;
            x = (x | (x << 8)) & 0x0300_f00f;
            x = (x | (x << 4)) & 0x030c_30c3;
            (x | (x << 2)) & 0x0924_9249
        };
        spread(w[0]) | (spread(w[1]) << 1) | (spread(w[2]) << 2)
    }

    /// Interleaved greedy walks (up to [`WALK_GROUP`]); `starts` must be in range.
    fn walk_group(&self, ys: &[Vec8], starts: &[VertexId], ends: &mut [VertexId]) {
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

    /// Squared walk distances from `y` to `v`'s neighbours, as `walk_inner` leaves them
    /// (only rings over 64 use them, see [`Projector::order_faces`]).
    fn ring_dists(&self, y: &Vec8, v: VertexId) -> [f32; 64] {
        let mut d = [f32::INFINITY; 64];
        let ring = self.walk_coords[v as usize].ring(self.emb.mesh().topology(), v);
        if ring.len() > 64 {
            let yw = self.walk_point(y);
            for (j, &u) in ring.iter().take(64).enumerate() {
                d[j] = self.walk_coords[u as usize].dist2(&yw);
            }
        }
        d
    }

    /// The faces around vertex `v` (at most 64), most promising first for a projection of
    /// `y`: by how far inside each face's plane the orthogonal projection of `y` falls
    /// (walk coordinates, in cache right after a walk ending at `v`). Starts loading the
    /// first face's data. The order is a heuristic; it never changes which answers exist.
    ///
    /// ```
    /// use std::sync::Arc;
    /// use wavg_mesh::{SurfacePoint, ValidMesh, procedural};
    /// use wavg_project::{EmbeddedMesh, Projector};
    /// let m = Arc::new(ValidMesh::new(procedural::icosphere(2)).unwrap());
    /// let emb = Arc::new(EmbeddedMesh::from_positions(m.clone()));
    /// let p = Projector::new(emb.clone()).unwrap();
    /// let f = m.topology().ring_faces(5)[2];
    /// let y = emb.point(&SurfacePoint::new(f, [0.4, 0.3, 0.3]));
    /// let order = wavg_project::internal::faces_by_promise(&p, &y, 5);
    /// assert_eq!(order.as_slice()[0], f);
    /// ```
    pub(crate) fn faces_by_promise(&self, y: &Vec8, v: VertexId) -> FaceOrder {
        self.order_faces(y, v, &[f32::INFINITY; 64])
    }

    /// [`Projector::faces_by_promise`]; `ring_d` (squared walk distances of `v`'s
    /// neighbours) orders the faces of rings too long for the exact score.
    fn order_faces(&self, y: &Vec8, v: VertexId, ring_d: &[f32; 64]) -> FaceOrder {
        let topo = self.emb.mesh().topology();
        let ring = self.walk_coords[v as usize].ring(topo, v);
        let faces = self.walk_coords[v as usize].faces(topo, v);
        let mut scores = [f32::INFINITY; 64];
        if ring.len() <= 64 {
            let yw = self.walk_point(y);
            let wv = self.walk_coords[v as usize].unpack();
            let mut dy = [0.0f32; 8];
            for k in 0..8 {
                dy[k] = yw[k] - wv[k];
            }
            // Per neighbour j: |e_j|^2, e_j . (y - v) and e_j . e_{j+1}, e_j = u_j - v.
            let mut ee = [0.0f32; 64];
            let mut de = [0.0f32; 64];
            let mut ee1 = [0.0f32; 64];
            let edge = |u: u32| {
                let wu = self.walk_coords[u as usize].unpack();
                let mut d = [0.0f32; 8];
                for k in 0..8 {
                    d[k] = wu[k] - wv[k];
                }
                d
            };
            let first = edge(ring[0]);
            let mut cur = first;
            for j in 0..ring.len() {
                let next = if j + 1 < ring.len() {
                    edge(ring[j + 1])
                } else {
                    first
                };
                let (mut a, mut b, mut c) = (0.0, 0.0, 0.0);
                for k in 0..8 {
                    a += cur[k] * cur[k];
                    b += cur[k] * dy[k];
                    c += cur[k] * next[k];
                }
                ee[j] = a;
                de[j] = b;
                ee1[j] = c;
                cur = next;
            }
            // Face j lies between ring[j] and ring[j + 1] (cyclically when interior).
            for j in 0..ring.len() {
                let l = if j + 1 == ring.len() { 0 } else { j + 1 };
                let ab = ee1[j];
                let det = ee[j] * ee[l] - ab * ab;
                if det > 0.0 {
                    let s = (ee[l] * de[j] - ab * de[l]) / det;
                    let t = (ee[j] * de[l] - ab * de[j]) / det;
                    let score = -(s.min(t).min(1.0 - s - t));
                    if !score.is_nan() {
                        scores[j] = score;
                    }
                }
            }
        } else {
            for j in 0..64 {
                scores[j] = ring_d[j] + ring_d[(j + 1) % 64];
            }
        }
        let m = faces.len().min(64);
        let mut order = [(0.0f32, 0u32); 64];
        for j in 0..m {
            order[j] = (scores[j], faces[j]);
        }
        // Ties (and unscored faces) by id, so the order never depends on the sort.
        order[..m].sort_unstable_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)));
        if m > 0 {
            // The first candidate nearly always holds the answer: request its record and
            // its corners' records together rather than one after the other.
            let f = order[0].1;
            self.prefetch_face(f, v, ring, faces);
        }
        FaceOrder {
            faces: std::array::from_fn(|j| order[j].1),
            n: m,
        }
    }

    /// Starts loading face `f` (around `v`) and its three corners' records. The corners
    /// are `v` and the two ring neighbours beside `f`, known without reading the face.
    #[inline(always)]
    fn prefetch_face(&self, f: FaceId, v: VertexId, ring: &[u32], faces: &[u32]) {
        let Some(j) = faces.iter().position(|&g| g == f) else {
            return;
        };
        let next = if j + 1 < ring.len() { j + 1 } else { 0 };
        prefetch(&self.faces[f as usize]);
        for u in [v, ring[j], ring[next]] {
            prefetch(&self.verts[u as usize]);
        }
    }

    /// `try_face` if the triangle's own box is closer than `sqrt(bound)` and the answer
    /// is strictly closer than that.
    #[inline]
    fn try_face_bounded(&self, f: FaceId, y: &Vec8, bound: f64) -> Option<Best> {
        let [a, b, c] = self.corners(f);
        let lo = a.inf(&b).inf(&c);
        let hi = a.sup(&b).sup(&c);
        let mut s = 0.0;
        for k in 0..8 {
            let d = (lo[k] - y[k]).max(y[k] - hi[k]).max(0.0);
            s += d * d;
        }
        if s >= bound {
            return None;
        }
        // The (clamped) Phong point lies in the triangle, so the Euclidean distance is a
        // lower bound too, tighter than the box and cheaper than Newton.
        let w = closest_point_barycentric(y, &a, &b, &c);
        if (a * w[0] + b * w[1] + c * w[2] - y).norm_squared() >= bound {
            return None;
        }
        self.try_face(f, y).filter(|r| r.d2 < bound)
    }

    fn exhaustive(&self, y: &Vec8) -> Option<Best> {
        let mut bound = f64::INFINITY;
        let mut best = None;
        self.bvh.search(y, &mut bound, |f, bound| {
            if let Some(b) = self.try_face_bounded(f, y, *bound) {
                *bound = b.d2;
                best = Some(b);
            }
        });
        best
    }

    /// Guaranteed path: the closest valid Phong projection over all triangles (branch and
    /// bound over the bounding volume hierarchy, exact).
    pub fn project_exhaustive(&self, y: &Vec8) -> Result<Projection, ProjectError> {
        if !y.iter().all(|v| v.is_finite()) {
            return Err(ProjectError::NonFiniteQuery);
        }
        self.exhaustive(y)
            .map(|b| Self::finish(b, ProjectionPath::Exhaustive))
            .ok_or(ProjectError::NoProjection)
    }

    /// The closest valid Phong projection by a literal scan over every triangle (skipping
    /// only triangles whose bounding box is farther than the best so far). Slow; for tests
    /// and for checking the other two paths.
    pub fn project_brute_force(&self, y: &Vec8) -> Result<Projection, ProjectError> {
        if !y.iter().all(|v| v.is_finite()) {
            return Err(ProjectError::NonFiniteQuery);
        }
        let mut best: Option<Best> = None;
        for f in 0..self.faces.len() as u32 {
            let bound = best.map_or(f64::INFINITY, |b| b.d2);
            if let Some(b) = self.try_face_bounded(f, y, bound) {
                best = Some(b);
            }
        }
        best.map(|b| Self::finish(b, ProjectionPath::Exhaustive))
            .ok_or(ProjectError::NoProjection)
    }

    /// Euclidean closest point on the embedded mesh (baseline; discontinuous). A
    /// non-finite query gives a point of face 0 at infinite distance.
    pub fn project_euclidean(&self, y: &Vec8) -> Projection {
        let mut best = Best {
            face: 0,
            xi: [1.0 / 3.0; 3],
            d2: f64::INFINITY,
        };
        if y.iter().all(|v| v.is_finite()) {
            let mut bound = f64::INFINITY;
            self.bvh.search(y, &mut bound, |f, bound| {
                let [a, b, c] = self.corners(f);
                let xi = closest_point_barycentric(y, &a, &b, &c);
                let d2 = (a * xi[0] + b * xi[1] + c * xi[2] - y).norm_squared();
                if d2 < *bound {
                    *bound = d2;
                    best = Best { face: f, xi, d2 };
                }
            });
        }
        Self::finish(best, ProjectionPath::Euclidean)
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
    fn walk_point(&self, y: &Vec8) -> [f32; 8] {
        std::array::from_fn(|k| ((y[k] - self.walk_origin[k]) * self.walk_inv_step) as f32)
    }

    /// The walk; leaves the squared distances of the final vertex's ring in `ring_d`.
    #[inline]
    fn walk_inner(&self, y: &Vec8, start: VertexId, ring_d: &mut [f32; 64]) -> VertexId {
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

    /// Vertex closest to `y` in R^8 (ties to the lowest index), by branch and bound over
    /// the faces' bounding boxes: every vertex is a corner of some face, and a box's
    /// distance bounds its corners'. 0 for a query that is not finite.
    ///
    /// ```
    /// use std::sync::Arc;
    /// use wavg_mesh::{ValidMesh, procedural};
    /// use wavg_project::{EmbeddedMesh, Projector};
    /// let m = Arc::new(ValidMesh::new(procedural::icosphere(3)).unwrap());
    /// let emb = Arc::new(EmbeddedMesh::from_positions(m));
    /// let p = Projector::new(emb.clone()).unwrap();
    /// let y = emb.coords()[17] * 1.5;
    /// assert_eq!(p.nearest_vertex(&y), 17);
    /// ```
    pub fn nearest_vertex(&self, y: &Vec8) -> VertexId {
        let mut best = (f64::INFINITY, 0u32);
        if !y.iter().all(|v| v.is_finite()) {
            return 0;
        }
        let mut bound = f64::INFINITY;
        self.bvh.search(y, &mut bound, |f, bound| {
            for v in self.faces[f as usize].v {
                let d = (self.verts[v as usize].x - y).norm_squared();
                if d < best.0 || (d == best.0 && v < best.1) {
                    best = (d, v);
                    // Keep boxes at exactly this distance: they may hold a lower index.
                    *bound = f64::from_bits(d.to_bits() + 1); // the next float up (d >= 0)
                }
            }
        });
        best.1
    }
}

/// Hints the processor to bring `r`'s two cache lines (records here are 128 bytes, 64
/// aligned) into cache; no effect on results.
#[inline(always)]
fn prefetch<T>(r: &T) {
    crate::arch::prefetch_lines(r, 2);
}

/// Hints the processor to load the cache line holding the start of `r`.
#[inline(always)]
fn prefetch_line<T>(r: &T) {
    crate::arch::prefetch_lines(r, 1);
}

/// Compile-time check that the projector can be shared across threads.
const _: fn() = || {
    fn assert_send_sync<T: Send + Sync>() {}
    assert_send_sync::<Projector>();
};

#[cfg(test)]
mod tests {
    use super::*;
    use crate::frames::vertex_frames;
    use wavg_mesh::{ValidMesh, procedural};

    #[test]
    fn frames_and_vertex_frames_agree() {
        let m = Arc::new(ValidMesh::new(procedural::icosphere(1)).unwrap());
        let emb = Arc::new(EmbeddedMesh::from_positions(m.clone()));
        let p = Projector::new(emb.clone()).unwrap();
        let f = vertex_frames(&m, emb.coords());
        for v in 0..m.n_vertices() {
            assert!((p.frame(v as u32) - f[v].0).norm() < 1e-6);
        }
        assert_eq!(p.frame_kind_counts()[0], m.n_vertices());
    }

    /// The SIMD walk distance is the portable one, bit for bit.
    #[test]
    fn walk_distance_matches_the_portable_sum() {
        use rand::{Rng, SeedableRng};
        let mut r = rand_chacha::ChaCha8Rng::seed_from_u64(7);
        for _ in 0..100_000 {
            let w = WalkPoint {
                c: std::array::from_fn(|_| r.random()),
                ring: [0; WALK_RING],
                faces: [0; WALK_RING],
                n: 0,
                nf: 0,
            };
            let y: [f32; 8] = std::array::from_fn(|_| r.random_range(-1e3..7e4));
            assert_eq!(w.dist2(&y).to_bits(), wdist2(&w.unpack(), &y).to_bits());
        }
    }

    /// The walk records' copies of the rings and faces (used instead of the topology)
    /// match the topology, including boundary fans and rings too long to copy.
    #[test]
    fn walk_records_match_topology() {
        // A fan of 20 triangles around vertex 0 (valence 20, open) next to a grid.
        let mut fan = procedural::grid(6, 5, 1.0, 1.0);
        let c = fan.positions.len() as u32;
        fan.positions.push(nalgebra::Vector3::new(3.0, 8.0, 0.0));
        for k in 0..20u32 {
            let a = fan.positions.len() as u32;
            let t = k as f64 / 20.0 * std::f64::consts::PI;
            fan.positions
                .push(nalgebra::Vector3::new(3.0 + t.cos(), 8.0 + t.sin(), 0.0));
            if k > 0 {
                fan.triangles.push([c, a - 1, a]);
            }
        }
        for mesh in [
            procedural::icosphere(2),
            procedural::grid(5, 4, 1.0, 1.0),
            fan,
        ] {
            let m = Arc::new(ValidMesh::new(mesh).unwrap());
            let p = Projector::new(Arc::new(EmbeddedMesh::from_positions(m.clone()))).unwrap();
            let topo = m.topology();
            for v in 0..m.n_vertices() as u32 {
                let w = &p.walk_coords[v as usize];
                assert_eq!(w.ring(topo, v), topo.ring(v));
                assert_eq!(w.faces(topo, v), topo.ring_faces(v));
            }
        }
    }
}
