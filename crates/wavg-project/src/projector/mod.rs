//! Projection of points of R^8 onto the embedded mesh: Phong (fast, exhaustive, brute
//! force) and Euclidean.
//!
//! The fast path walks greedily over the vertex graph from a start vertex to a vertex
//! locally closest to the target, then runs the local search (`search.rs`) over the
//! triangles around it (most promising first) and their neighbours. What happens next
//! depends on the caller's [`SearchGoal`]. For the closest projection (the default), a
//! valid projection at (numerically) zero distance is a global minimum and is returned at
//! once; any other local answer is *certified*: a branch and bound over the bounding
//! volume hierarchy visits every triangle whose box is closer than that answer, so the
//! fast path returns the same closest valid projection as the exhaustive search, never a
//! far-off triangle. For the paper's first hit, the first valid projection met is
//! returned uncertified. `ProjectionPath` says which happened.

use std::sync::Arc;

use rayon::prelude::*;
use wavg_mesh::{FaceId, NONE, SurfacePoint, VertexId};

use crate::bvh::Bvh;
use crate::euclid::closest_point_barycentric;
use crate::triangle::{Frame32, TriData, frame_to_f32, frame_to_f64};
use crate::{EmbeddedMesh, Mat2x8, ProjectError, Vec8};
use cone::Cones;

mod batch;
mod certify;
mod cone;
mod fine;
mod layout;
mod locate;
mod nearest;
mod order;
mod reach;
mod search;
mod walk;

use layout::{Face, VertexRec, WalkPoint};
use locate::StartGrid;

pub use batch::ProjectScratch;
pub use order::FaceOrder;
pub use search::{FACE_WALK, HINT_STEPS, LOCAL_BUDGET, SearchGoal};
pub use walk::WALK_GROUP;

/// A distance below this fraction of the triangle's longest edge counts as zero: such a
/// projection is a global minimum up to rounding (the tangent equations of a point on a
/// triangle hold to f64 precision), so the fast path returns it without certification.
pub const ZERO_DISTANCE: f64 = 1e-10;

/// Which search produced a projection.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ProjectionPath {
    /// The local search found it and certification proved it the closest
    /// ([`SearchGoal::Closest`]).
    Certified,
    /// The local search found it, not certified: the first valid projection met
    /// ([`SearchGoal::FirstHit`], the paper's search).
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
    /// Built when the global searches need them (see `cone::keep_filter`): most
    /// workloads' searches end before they would.
    cones: std::sync::OnceLock<Cones>,
    /// Nodes the global searches popped before the cone bounds were built.
    unfiltered: std::sync::atomic::AtomicUsize,
    /// Mean 3-D edge length of the mesh, computed on first use.
    mesh_mean_edge: std::sync::OnceLock<f64>,
    /// Per-vertex reach, filled on first use.
    reach: reach::Reach,
    walk_origin: Vec8,
    walk_inv_step: f64,
    walk_coords: Vec<WalkPoint>,
    starts: StartGrid,
}

#[derive(Clone, Copy)]
struct Best {
    face: u32,
    xi: [f64; 3],
    d2: f64,
}

impl Projector {
    /// The embedded mesh.
    pub fn embedded(&self) -> &Arc<EmbeddedMesh> {
        &self.emb
    }

    /// Mean 3-D edge length of the mesh (each interior edge counted twice), computed once
    /// and shared by every solver on this projector.
    pub fn mesh_mean_edge_length(&self) -> f64 {
        *self
            .mesh_mean_edge
            .get_or_init(|| wavg_mesh::geometry::mean_edge_length(self.emb.mesh()))
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
            + self.cones.get().map_or(0, Cones::bytes)
            + self.reach.bytes()
            + std::mem::size_of_val(&self.walk_coords[..])
            + self.starts.bytes()
            + std::mem::size_of_val(self.emb.coords())
    }

    /// The hierarchy's cone bounds, computed on first use.
    fn cones(&self) -> &Cones {
        self.cones
            .get_or_init(|| Cones::new(&self.bvh, &self.faces, &self.verts))
    }

    /// Counts one node a global search popped without cone bounds (they are not built);
    /// whether the projector's searches have popped at most as many as the hierarchy has
    /// nodes so (see [`cone::keep_filter`]).
    fn count_unfiltered(&self) -> bool {
        use std::sync::atomic::Ordering::Relaxed;
        self.unfiltered.fetch_add(1, Relaxed) < self.bvh.n_nodes()
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
        self.solve_face(f, y, false)
    }

    /// [`Projector::try_face`], skipping Newton's method on a triangle that provably holds
    /// no projection (the same answer, see [`TriData::solve_unless_excluded`]).
    #[inline]
    fn try_face_filtered(&self, f: FaceId, y: &Vec8) -> Option<Best> {
        self.solve_face(f, y, true).ok()
    }

    #[inline(always)]
    fn solve_face(&self, f: FaceId, y: &Vec8, filter: bool) -> Result<Best, Option<usize>> {
        let face = &self.faces[f as usize];
        let r = [
            &self.verts[face.v[0] as usize],
            &self.verts[face.v[1] as usize],
            &self.verts[face.v[2] as usize],
        ];
        let (frames, corners) = ([&r[0].t, &r[1].t, &r[2].t], [&r[0].x, &r[1].x, &r[2].x]);
        let xi = if filter {
            face.d.solve_unless_excluded(frames, corners, y)?
        } else {
            face.d.solve_or_exit(frames, corners, y)?
        };
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
        b.d2 <= ZERO_DISTANCE * ZERO_DISTANCE * self.longest_edge2(b.face)
    }

    /// The squared length of face `f`'s longest embedded edge.
    fn longest_edge2(&self, f: FaceId) -> f64 {
        let [p, q, r] = self.corners(f);
        (q - p)
            .norm_squared()
            .max((r - q).norm_squared())
            .max((p - r).norm_squared())
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
    /// when the local one finds nothing or is beaten (reported as `Fallback`). The same
    /// as [`Projector::project_with`] with [`SearchGoal::Closest`] and no hint.
    pub fn project(&self, y: &Vec8, start: VertexId) -> Result<Projection, ProjectError> {
        self.project_with(y, start, None, SearchGoal::Closest)
    }

    /// The projection of `y` that `goal` asks for, searching from vertex `start`. With a
    /// `hint` face (a warm start: the previous answer's face when the query moved a
    /// little), the face the query lies over, found within [`HINT_STEPS`] steps over faces
    /// from the hint, and up to [`FACE_WALK`] faces in all that Newton's method exits into
    /// are tried first: for [`SearchGoal::FirstHit`] a valid projection there is the answer;
    /// for [`SearchGoal::Closest`] only one at (numerically) zero distance is, since
    /// anything else still needs certifying.
    ///
    /// ```
    /// use std::sync::Arc;
    /// use wavg_mesh::{SurfacePoint, ValidMesh, procedural};
    /// use wavg_project::{EmbeddedMesh, ProjectionPath, Projector, SearchGoal};
    /// let m = Arc::new(ValidMesh::new(procedural::icosphere(3)).unwrap());
    /// let emb = Arc::new(EmbeddedMesh::from_positions(m));
    /// let p = Projector::new(emb.clone()).unwrap();
    /// let y = emb.point(&SurfacePoint::new(40, [0.2, 0.3, 0.5])) * 1.01;
    /// let first = p.project_with(&y, 0, None, SearchGoal::FirstHit).unwrap();
    /// assert_eq!(first.path, ProjectionPath::Local);
    /// let warm = p.project_with(&y, 0, Some(40), SearchGoal::FirstHit).unwrap();
    /// assert_eq!(warm.point.face, 40);
    /// assert_eq!(p.project_with(&y, 0, None, SearchGoal::Closest), p.project(&y, 0));
    /// ```
    pub fn project_with(
        &self,
        y: &Vec8,
        start: VertexId,
        hint: Option<FaceId>,
        goal: SearchGoal,
    ) -> Result<Projection, ProjectError> {
        self.project_aimed(y, start, hint, None, goal)
    }

    /// [`Projector::project_with`] whose walk over faces from the `hint` face heads for the
    /// face under `aim` rather than under `y` (Newton's method still solves for `y`). Far
    /// from the surface the projection trails the face under the query; along a curve the
    /// extrapolation `2 p1 - p0` of the two previous projections (in R^8) usually lies
    /// over the face holding the new one, so the first Newton solve there finds it
    /// (`wavg_solve::CurveAim` decides when to aim). A non-finite `aim` is ignored.
    ///
    /// ```
    /// use std::sync::Arc;
    /// use wavg_mesh::{SurfacePoint, ValidMesh, procedural};
    /// use wavg_project::{EmbeddedMesh, Projector, SearchGoal};
    /// let m = Arc::new(ValidMesh::new(procedural::icosphere(3)).unwrap());
    /// let emb = Arc::new(EmbeddedMesh::from_positions(m));
    /// let p = Projector::new(emb.clone()).unwrap();
    /// let on = emb.point(&SurfacePoint::new(40, [0.2, 0.3, 0.5]));
    /// let y = on * 1.01;
    /// let aimed = p.project_aimed(&y, 0, Some(40), Some(&on), SearchGoal::FirstHit).unwrap();
    /// assert_eq!(aimed.point.face, 40);
    /// ```
    pub fn project_aimed(
        &self,
        y: &Vec8,
        start: VertexId,
        hint: Option<FaceId>,
        aim: Option<&Vec8>,
        goal: SearchGoal,
    ) -> Result<Projection, ProjectError> {
        if !y.iter().all(|v| v.is_finite()) {
            return Err(ProjectError::NonFiniteQuery);
        }
        if start as usize >= self.verts.len() {
            return Err(ProjectError::StartOutOfRange {
                vertex: start,
                n_vertices: self.verts.len(),
            });
        }
        if let Some(f) = hint {
            if f as usize >= self.faces.len() {
                return Err(ProjectError::FaceOutOfRange {
                    face: f,
                    n_faces: self.faces.len(),
                });
            }
            let aim = aim.filter(|a| a.iter().all(|v| v.is_finite())).unwrap_or(y);
            match self.face_walk(y, f, aim) {
                Some(b) if goal == SearchGoal::FirstHit => {
                    return Ok(Self::finish(b, ProjectionPath::Local));
                }
                Some(b) if self.is_zero(&b) => {
                    return Ok(Self::finish(b, ProjectionPath::Certified));
                }
                _ => {}
            }
        }
        // 1. Greedy walk.
        let mut ring_d = [0.0f32; 64];
        let v = self.walk_inner(y, start, &mut ring_d);
        // 2. Faces around v, most promising first; the local search and what follows.
        let cands = self.order_faces(y, v, &ring_d);
        self.search_from(y, v, &cands, goal)
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
    use super::layout::{WALK_RING, wdist2};
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
