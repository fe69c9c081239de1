//! The paper's local search for the forward problem (Section 3.3; algorithm notes section
//! 5): a greedy walk over the vertex graph towards the averaged point, then a breadth-first
//! search over triangles from the walk's end; the first triangle holding a valid Phong
//! projection wins (within each ring of the search, triangles are tried in order of how
//! close the Euclidean projection onto their plane falls to them).
//!
//! It is not certified: when the average is ambiguous a closer projection may exist
//! elsewhere (the paper measured this as rare and meaningful only for ill-posed averages).
//! [`crate::SearchMode::Certified`] and [`crate::SearchMode::Exact`] are the guaranteed
//! alternatives.

use wavg_mesh::{FaceId, NONE, SurfacePoint, VertexId};

use crate::{Projector, Vec8};

/// Triangles the breadth-first search may test before giving up (the caller then falls
/// back to the projector's certified search).
pub const LOCAL_BUDGET: usize = 96;

/// Squared distance in R^8.
#[inline]
fn dist2(a: &Vec8, b: &Vec8) -> f64 {
    let mut s = 0.0;
    for k in 0..8 {
        let d = a[k] - b[k];
        s += d * d;
    }
    s
}

/// Greedy walk from `start`: move to the neighbour closest to `y` while one is closer
/// than the current vertex (steepest descent; ends at a local minimum of the distance).
pub fn walk(proj: &Projector, y: &Vec8, start: VertexId) -> VertexId {
    let emb = proj.embedded();
    let topo = emb.mesh().topology();
    let c = emb.coords();
    let mut v = start;
    let mut dv = dist2(&c[v as usize], y);
    loop {
        let mut next = v;
        for &u in topo.ring(v) {
            let d = dist2(&c[u as usize], y);
            if d < dv {
                dv = d;
                next = u;
            }
        }
        if next == v {
            return v;
        }
        v = next;
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

/// How far outside triangle `f` the Euclidean projection of `y` onto the triangle's plane
/// in R^8 falls: the most negative barycentric coordinate, negated (0 inside; infinite for
/// a degenerate triangle).
#[inline]
fn outside(proj: &Projector, y: &Vec8, f: FaceId) -> f64 {
    let emb = proj.embedded();
    let t = emb.mesh().triangles[f as usize];
    let c = emb.coords();
    let (p0, p1, p2) = (&c[t[0] as usize], &c[t[1] as usize], &c[t[2] as usize]);
    let (mut a, mut b, mut cc, mut d, mut e) = (0.0, 0.0, 0.0, 0.0, 0.0);
    for k in 0..8 {
        let e1 = p1[k] - p0[k];
        let e2 = p2[k] - p0[k];
        let r = y[k] - p0[k];
        a += e1 * e1;
        b += e1 * e2;
        cc += e2 * e2;
        d += e1 * r;
        e += e2 * r;
    }
    let det = a * cc - b * b;
    if det.is_nan() || det <= 0.0 {
        return f64::INFINITY;
    }
    let l1 = (cc * d - b * e) / det;
    let l2 = (a * e - b * d) / det;
    let l0 = 1.0 - l1 - l2;
    (-l0).max(-l1).max(-l2).max(0.0)
}

/// The local search from `start` (see the module docs); `None` when no triangle within
/// [`LOCAL_BUDGET`] has a valid Phong projection of `y`.
pub fn local_search(proj: &Projector, y: &Vec8, start: VertexId) -> Option<LocalHit> {
    let emb = proj.embedded();
    let topo = emb.mesh().topology();
    let v = walk(proj, y, start);
    let mut seen = FaceSet {
        ids: [0; LOCAL_BUDGET],
        n: 0,
    };
    for &f in topo.ring_faces(v) {
        if seen.n == LOCAL_BUDGET {
            break;
        }
        seen.ids[seen.n] = f;
        seen.n += 1;
    }
    let mut level = 0..seen.n;
    let mut order = [(0.0f64, 0 as FaceId); LOCAL_BUDGET];
    loop {
        // Try the ring's triangles in order of how far outside each one the Euclidean
        // projection of `y` onto its plane falls: the face holding the Phong projection is
        // almost always first, so usually a single Newton solve is needed.
        let m = level.len();
        for (o, i) in order.iter_mut().zip(level.clone()) {
            let f = seen.ids[i];
            *o = (outside(proj, y, f), f);
        }
        order[..m].sort_unstable_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)));
        for &(_, f) in &order[..m] {
            if let Some(xi) = proj.project_onto_face(y, f) {
                let p = SurfacePoint::new(f, xi);
                return Some(LocalHit {
                    point: p,
                    distance: (emb.point(&p) - y).norm(),
                });
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
    }
}
