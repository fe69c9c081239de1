//! The paper's local search for the forward problem (Section 3.3): a greedy walk over the vertex graph towards the averaged point, then a breadth-first
//! search over triangles from the walk's end; the first triangle holding a valid Phong
//! projection wins (within each ring of the search, triangles are tried in order of how
//! close the Euclidean projection onto their plane falls to them, and when Newton's method
//! leaves a triangle across an edge, the triangle beyond is tried next, as the projection
//! more likely lies there).
//!
//! It is not certified: when the average is ambiguous a closer projection may exist
//! elsewhere (the paper measured this as rare and meaningful only for ill-posed averages).
//! [`crate::SearchMode::Certified`] and [`crate::SearchMode::Exact`] are the guaranteed
//! alternatives.

use std::sync::Arc;

use wavg_mesh::{FaceId, NONE, SurfacePoint, VertexId};

use crate::{Projector, Vec8};

/// Triangles the breadth-first search may test before giving up (the caller then falls
/// back to the projector's certified search).
pub const LOCAL_BUDGET: usize = 96;

/// A vertex's embedded coordinates in f32, half a cache line, for the walk.
#[derive(Clone, Copy, Debug, Default)]
#[repr(C, align(32))]
struct Coord32([f32; 8]);

impl Coord32 {
    fn new(y: &Vec8) -> Self {
        Self(std::array::from_fn(|k| y[k] as f32))
    }
}

/// The forward problem's local search over one projector, with compact f32 copies of the
/// embedded coordinates so the walk touches little memory (it is bound by cache misses on
/// large meshes).
pub struct LocalSearch {
    proj: Arc<Projector>,
    coords: Vec<Coord32>,
}

impl LocalSearch {
    /// Prepares the search (copies the coordinates to f32).
    pub fn new(proj: Arc<Projector>) -> Self {
        let coords = proj.embedded().coords().iter().map(Coord32::new).collect();
        Self { proj, coords }
    }

    /// The projector.
    pub fn projector(&self) -> &Arc<Projector> {
        &self.proj
    }

    /// Greedy walk from `start`: move to the neighbour closest to `y` while one is closer
    /// than the current vertex (steepest descent; ends at a local minimum of the distance).
    /// This is [`Projector::walk`], over its compact walk records.
    pub fn walk(&self, y: &Vec8, start: VertexId) -> VertexId {
        self.proj.walk(y, start)
    }

    /// The local search from `start` (see the module docs); `None` when no triangle within
    /// [`LOCAL_BUDGET`] has a valid Phong projection of `y`.
    pub fn search(&self, y: &Vec8, start: VertexId) -> Option<LocalHit> {
        let v = self.walk(y, start);
        self.search_from(y, v)
    }

    /// The vertex nearest to `y` ([`Projector::nearest_vertex`], branch and bound): the
    /// second chance when the walk ends in a local minimum of the distance with no
    /// projection nearby.
    pub fn nearest_vertex(&self, y: &Vec8) -> VertexId {
        self.proj.nearest_vertex(y)
    }

    /// The breadth-first triangle search from vertex `v` itself (no walk).
    pub fn search_at(&self, y: &Vec8, v: VertexId) -> Option<LocalHit> {
        self.search_from(y, v)
    }
}

/// A found projection: the point and its squared distance to the query.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LocalHit {
    /// The point (barycentrics as returned by the projector: valid, summing to 1).
    pub point: SurfacePoint,
    /// Distance in R^8 to the query.
    pub distance: f64,
}

/// Fixed-capacity set of face ids (no allocation per query).
struct FaceSet {
    ids: [FaceId; LOCAL_BUDGET],
    n: usize,
}

impl FaceSet {
    fn contains(&self, f: FaceId) -> bool {
        self.ids[..self.n].contains(&f)
    }
}

/// How far outside the triangle `(p0, p1, p2)` the Euclidean projection of `y` onto its
/// plane falls: the smallest barycentric coordinate, negated (negative inside, the more so
/// the deeper inside; infinite for a degenerate triangle). In f32: it only orders the
/// candidates.
#[inline]
fn outside(p0: &Coord32, p1: &Coord32, p2: &Coord32, y: &Coord32) -> f32 {
    let (mut a, mut b, mut cc, mut d, mut e) = (0.0f32, 0.0, 0.0, 0.0, 0.0);
    for k in 0..8 {
        let e1 = p1.0[k] - p0.0[k];
        let e2 = p2.0[k] - p0.0[k];
        let r = y.0[k] - p0.0[k];
        a += e1 * e1;
        b += e1 * e2;
        cc += e2 * e2;
        d += e1 * r;
        e += e2 * r;
    }
    let det = a * cc - b * b;
    if det.is_nan() || det <= 0.0 {
        return f32::INFINITY;
    }
    let l1 = (cc * d - b * e) / det;
    let l2 = (a * e - b * d) / det;
    let l0 = 1.0 - l1 - l2;
    (-l0).max(-l1).max(-l2)
}

impl LocalSearch {
    /// Breadth-first search over triangles from vertex `v` (the walk's end).
    fn search_from(&self, y: &Vec8, v: VertexId) -> Option<LocalHit> {
        let proj = &*self.proj;
        let emb = proj.embedded();
        let mesh = emb.mesh();
        let topo = mesh.topology();
        let c = &self.coords;
        let y32 = Coord32::new(y);
        let mut seen = FaceSet {
            ids: [0; LOCAL_BUDGET],
            n: 0,
        };
        let mut order = [(0.0f32, 0 as FaceId); LOCAL_BUDGET];
        let mut tried = FaceSet {
            ids: [0; LOCAL_BUDGET],
            n: 0,
        };
        // First ring: the faces around v, ordered by the projector from the walk records
        // the walk has just read (the same score as below).
        let first = wavg_project::internal::faces_by_promise(proj, y, v);
        for (j, &f) in first.as_slice().iter().enumerate().take(LOCAL_BUDGET) {
            seen.ids[seen.n] = f;
            order[j] = (j as f32, f);
            seen.n += 1;
        }
        let mut level = 0..seen.n;
        loop {
            // Try the ring's triangles in order of how far outside each one the Euclidean
            // projection of `y` onto its plane falls: the face holding the Phong projection
            // is almost always first, so usually a single Newton solve is needed.
            let m = level.len();
            order[..m].sort_unstable_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)));
            for &(_, f) in &order[..m] {
                // When Newton's method leaves a face across an edge, the face beyond is
                // tried next (a short walk over faces towards the projection), then the
                // ring's order resumes.
                let mut cur = f;
                while !tried.contains(cur) && tried.n < LOCAL_BUDGET {
                    tried.ids[tried.n] = cur;
                    tried.n += 1;
                    match proj.project_onto_face_or_exit(y, cur) {
                        Ok((xi, distance)) => {
                            return Some(LocalHit {
                                point: SurfacePoint::new(cur, xi),
                                distance,
                            });
                        }
                        Err(g) if g != NONE => cur = g,
                        Err(_) => break,
                    }
                }
            }
            // Next ring of triangles: unseen neighbours across edges, in order.
            let start_next = seen.n;
            'fill: for i in level {
                for g in topo.face_neighbors(seen.ids[i]) {
                    if g == NONE || seen.contains(g) {
                        continue;
                    }
                    if seen.n == LOCAL_BUDGET {
                        break 'fill;
                    }
                    seen.ids[seen.n] = g;
                    seen.n += 1;
                }
            }
            if seen.n == start_next {
                return None;
            }
            level = start_next..seen.n;
            for (o, i) in order.iter_mut().zip(level.clone()) {
                let f = seen.ids[i];
                let t = mesh.triangles[f as usize].map(|u| &c[u as usize]);
                *o = (outside(t[0], t[1], t[2], &y32), f);
            }
        }
    }
}
