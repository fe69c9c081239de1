//! The local search: from the walk's end, the faces around it (most promising first), then
//! rings of their neighbours across edges, within one budget of faces. One search serves
//! both goals ([`SearchGoal`]): the closest projection, which is then certified, and the
//! paper's first valid hit.

use super::*;

/// Faces the local search may test (and enqueue) before it gives up.
pub const LOCAL_BUDGET: usize = 96;

/// Hierarchy leaves a first-hit search opens looking for the vertex nearest to the query
/// (when the local search from the walk's end finds nothing) before it searches locally
/// from the closest vertex met: any projection will do, and most of an exact search's
/// leaves only prove that a vertex met early is the nearest (rocker-arm subdivided five
/// times, 10.3M vertices: 537-2,148 leaves, the nearest met by leaf 14-797; from the
/// vertex met within 512 leaves 8 of 9 such searches answer, 4-5% of the forward time).
/// Where that search finds nothing, the exact search follows.
const FIRST_HIT_LEAVES: usize = 512;

/// Faces a warm start walks through from its hint face, following Newton's exits, before
/// the vertex search.
pub const FACE_WALK: usize = 4;

/// How far outside a face (in barycentric units) the query's Euclidean projection onto its
/// plane may fall for a warm start's face walk to try Newton's method there: none, so a
/// face that does not hold the query costs a few dot products, not a Newton solve.
const HINT_MARGIN: f64 = 0.0;

/// Steps over faces a warm start may take from its hint face towards the face the query
/// lies over (samples along a curve usually move a face or a few from the last one).
pub const HINT_STEPS: usize = 6;

/// What the caller wants from [`Projector::project_with`].
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum SearchGoal {
    /// The closest valid projection: the local search tests the faces around the walk's
    /// end, then rings of their neighbours until one holds a projection, then certifies
    /// its best answer: at once when the query's ball of that radius lies within the reach
    /// of the walk's end (no triangle not around that vertex comes so close), otherwise
    /// (after a search from the vertex nearest to the query when the answer is far from it
    /// for its face's size: the walk may have stopped on the wrong sheet of a thin part)
    /// against the bounding volume hierarchy. When nothing is found within
    /// [`LOCAL_BUDGET`] faces, the search runs again from the vertex nearest to the
    /// query, then the global search answers. Path [`ProjectionPath::Certified`] or
    /// [`ProjectionPath::Fallback`].
    #[default]
    Closest,
    /// The paper's search: the first valid projection met, ring by ring (within a ring,
    /// faces in order of how far outside each one the Euclidean projection onto its plane
    /// falls; when Newton's method leaves a face across an edge, the face beyond is tried
    /// next). Not certified: when the query is ambiguous a closer projection may exist
    /// elsewhere. When nothing is found within [`LOCAL_BUDGET`] faces, the search runs
    /// again as for [`SearchGoal::Closest`], then the global search answers. Path
    /// [`ProjectionPath::Local`] or [`ProjectionPath::Fallback`].
    FirstHit,
}

/// Fixed-capacity set of face ids (no allocation per query).
#[derive(Clone)]
pub(super) struct FaceSet {
    ids: [FaceId; LOCAL_BUDGET],
    n: usize,
}

impl FaceSet {
    pub(super) fn new() -> Self {
        Self {
            ids: [0; LOCAL_BUDGET],
            n: 0,
        }
    }
    #[inline]
    pub(super) fn contains(&self, f: FaceId) -> bool {
        self.ids[..self.n].contains(&f)
    }
    #[inline]
    pub(super) fn full(&self) -> bool {
        self.n == LOCAL_BUDGET
    }
    #[inline]
    pub(super) fn push(&mut self, f: FaceId) {
        self.ids[self.n] = f;
        self.n += 1;
    }
}

/// Barycentric coordinates of the Euclidean projection of `y` onto the plane of the
/// triangle `(p0, p1, p2)`, in walk coordinates; `None` for a degenerate triangle.
#[inline]
fn plane_bary(p: [[f32; 8]; 3], y: &[f32; 8]) -> Option<[f32; 3]> {
    let (mut a, mut b, mut cc, mut d, mut e) = (0.0f32, 0.0, 0.0, 0.0, 0.0);
    for k in 0..8 {
        let e1 = p[1][k] - p[0][k];
        let e2 = p[2][k] - p[0][k];
        let r = y[k] - p[0][k];
        a += e1 * e1;
        b += e1 * e2;
        cc += e2 * e2;
        d += e1 * r;
        e += e2 * r;
    }
    let det = a * cc - b * b;
    if det.is_nan() || det <= 0.0 {
        return None;
    }
    let l1 = (cc * d - b * e) / det;
    let l2 = (a * e - b * d) / det;
    Some([1.0 - l1 - l2, l1, l2])
}

/// How far outside the triangle `(p0, p1, p2)` the Euclidean projection of `y` onto its
/// plane falls: the smallest barycentric coordinate, negated (negative inside; infinite
/// for a degenerate triangle). In walk coordinates: it only orders the candidates.
#[inline]
fn outside(p: [[f32; 8]; 3], y: &[f32; 8]) -> f32 {
    plane_bary(p, y).map_or(f32::INFINITY, |[l0, l1, l2]| (-l0).max(-l1).max(-l2))
}

/// A local answer farther from the query than this fraction of its face's longest edge
/// (in R^8) is searched for once more from the vertex nearest to the query before the
/// hierarchy certifies it (see `Projector::across_thin_parts`). A walk on the wrong
/// sheet of a thin part finds answers about the sheets' distance away; nearer answers
/// are those of queries just off their own sheet, for which the extra search would
/// nearly always be wasted.
const THIN_PART: f64 = 0.2;

/// Faces the closest goal's point-location walk may step through.
const LOCATE_STEPS: usize = 8;

/// Where the first-hit search's walk over faces goes after trying one face.
pub(super) enum Exit {
    /// The face holds a valid projection.
    Found(Best),
    /// Newton's method left the face across an edge, into this face.
    Next(FaceId),
    /// Newton's method failed otherwise, or left across a boundary edge.
    Stop,
}

impl Projector {
    /// Tries face `cur` for the first hit, recording it in `tried` (which must have room).
    #[inline]
    pub(super) fn exit_step(&self, y: &Vec8, cur: FaceId, tried: &mut FaceSet) -> Exit {
        tried.push(cur);
        match self.try_face_or_exit(cur, y) {
            Ok(b) => Exit::Found(b),
            Err(Some(k)) => match self.emb.mesh().topology().face_neighbors(cur)[(k + 1) % 3] {
                NONE => Exit::Stop,
                g => Exit::Next(g),
            },
            Err(None) => Exit::Stop,
        }
    }

    /// The local search from the walk's end `v`, the faces around it in the order `cands`
    /// first. For [`SearchGoal::FirstHit`], the first valid projection; for
    /// [`SearchGoal::Closest`], the closest one in the first ring of faces (around `v`,
    /// then rings of neighbours across edges, within the budget) that holds any (a
    /// numerically zero distance ends it at once). Every face tested is recorded in
    /// `tried`.
    pub(super) fn local_search(
        &self,
        y: &Vec8,
        v: VertexId,
        cands: &FaceOrder,
        goal: SearchGoal,
        tried: &mut FaceSet,
        skip: usize,
    ) -> Option<Best> {
        let topo = self.emb.mesh().topology();
        let first_hit = goal == SearchGoal::FirstHit;
        // Only the first ring's candidates may be skipped, and only by a first-hit search.
        let mut skip = if first_hit { skip } else { 0 };
        let mut seen = FaceSet::new();
        let mut order = [(0.0f32, 0 as FaceId); LOCAL_BUDGET];
        // First ring: the candidates in order, then any faces beyond the 64 they cover.
        let ring0 = self.walk_coords[v as usize].faces(topo, v);
        for &f in cands.as_slice().iter().chain(ring0.iter().skip(cands.n)) {
            if seen.full() {
                break;
            }
            order[seen.n] = (seen.n as f32, f);
            seen.push(f);
        }
        let mut level = 0..seen.n;
        let mut best: Option<Best> = None;
        if !first_hit {
            // Where the walk ended beside rather than at the face holding the projection,
            // walk over faces to it first: one Newton solve instead of a ring or two.
            if let Some(f) = self.locate_face(y, cands, &seen) {
                tried.push(f);
                best = self.try_face(f, y);
                if best.as_ref().is_some_and(|b| self.is_zero(b)) {
                    return best;
                }
            }
        }
        loop {
            // A resumed search skips the first ring's candidates already walked from.
            for &(_, f) in order[..level.len()].iter().skip(std::mem::take(&mut skip)) {
                if first_hit {
                    // Newton's exits lead on to the face beyond (a short walk over faces
                    // towards the projection), then the ring's order resumes.
                    let mut cur = f;
                    while !tried.contains(cur) && !tried.full() {
                        match self.exit_step(y, cur, tried) {
                            Exit::Found(b) => return Some(b),
                            Exit::Next(g) => cur = g,
                            Exit::Stop => break,
                        }
                    }
                } else if !tried.contains(f) && !tried.full() {
                    tried.push(f);
                    // Once something is found, only a strictly closer answer matters: the
                    // cheap lower bounds of `try_face_bounded` skip most remaining faces.
                    let found = match &best {
                        None => self.try_face(f, y),
                        Some(x) => self.try_face_bounded(f, y, x.d2),
                    };
                    if let Some(b) = found {
                        best = Some(b);
                        if self.is_zero(&b) {
                            return best;
                        }
                    }
                }
            }
            // The closest goal certifies the first ring that holds a projection. Rings
            // go on until the budget: the walk's end is often not a corner of the face
            // holding the projection (a point of a long triangle can be nearer to a vertex
            // of its neighbour), and that face may touch its ring only at a vertex.
            if !first_hit && best.is_some() {
                return best;
            }
            // Next ring: unseen neighbours across edges, in order.
            let start_next = seen.n;
            'fill: for i in level {
                for g in topo.face_neighbors(seen.ids[i]) {
                    if g == NONE || seen.contains(g) {
                        continue;
                    }
                    if seen.full() {
                        break 'fill;
                    }
                    seen.push(g);
                }
            }
            if seen.n == start_next {
                return best;
            }
            level = start_next..seen.n;
            for (o, i) in order.iter_mut().zip(level.clone()) {
                *o = (0.0, seen.ids[i]);
            }
            if first_hit {
                // Try the ring's faces in order of how far outside each one the Euclidean
                // projection of `y` onto its plane falls: the face holding the projection
                // is almost always first, so usually a single Newton solve is needed.
                let yw = self.walk_point(y);
                let mesh = self.emb.mesh();
                for o in &mut order[..level.len()] {
                    let t = mesh.triangles[o.1 as usize];
                    o.0 = outside(t.map(|u| self.walk_coords[u as usize].unpack()), &yw);
                }
                order[..level.len()]
                    .sort_unstable_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)));
            }
        }
    }

    /// The face, outside the first ring `ring0`, over which the Euclidean projection of
    /// `y` onto its plane falls, found by stepping across the edge opposite the most
    /// negative barycentric coordinate from the most promising candidate of `cands`
    /// (a point-location walk in walk coordinates); `None` when that candidate already
    /// holds it or the walk does not arrive within [`LOCATE_STEPS`].
    fn locate_face(&self, y: &Vec8, cands: &FaceOrder, ring0: &FaceSet) -> Option<FaceId> {
        let &first = cands.as_slice().first()?;
        if cands.first_outside <= 0.0 {
            return None;
        }
        let topo = self.emb.mesh().topology();
        let mesh = self.emb.mesh();
        let yw = self.walk_point(y);
        let mut f = first;
        for _ in 0..LOCATE_STEPS {
            let t = mesh.triangles[f as usize];
            let l = plane_bary(t.map(|u| self.walk_coords[u as usize].unpack()), &yw)?;
            let k = (0..3).min_by(|&a, &b| l[a].total_cmp(&l[b]))?;
            if l[k] >= 0.0 {
                return (!ring0.contains(f)).then_some(f);
            }
            f = topo.face_neighbors(f)[(k + 1) % 3];
            if f == NONE {
                return None;
            }
        }
        None
    }

    /// The search after the walk: the local search from `v` (candidates `cands`), then
    /// certification or the global search, as `goal` asks.
    pub(super) fn search_from(
        &self,
        y: &Vec8,
        v: VertexId,
        cands: &FaceOrder,
        goal: SearchGoal,
    ) -> Result<Projection, ProjectError> {
        self.search_resumed(y, v, cands, goal, FaceSet::new(), 0)
    }

    /// [`Projector::search_from`] taking up a first-hit search begun elsewhere, which
    /// tried the faces in `tried` and walked from the first `skip` candidates of `cands`.
    pub(super) fn search_resumed(
        &self,
        y: &Vec8,
        v: VertexId,
        cands: &FaceOrder,
        goal: SearchGoal,
        mut tried: FaceSet,
        skip: usize,
    ) -> Result<Projection, ProjectError> {
        let local = self.local_search(y, v, cands, goal, &mut tried, skip);
        let global = |y: &Vec8| {
            self.exhaustive(y)
                .map(|b| Self::finish(b, ProjectionPath::Fallback))
                .ok_or(ProjectError::NoProjection)
        };
        match (goal, local) {
            (SearchGoal::FirstHit, Some(b)) => Ok(Self::finish(b, ProjectionPath::Local)),
            (SearchGoal::Closest, Some(b)) => Ok(self.certify(y, b, v, &tried, true)),
            // The walk may end in a local minimum of the distance with no projection
            // nearby (on another sheet that lies close in R^8): once more from the
            // nearest vertex, much cheaper than the global search and usually its answer.
            (_, None) => match self.search_from_nearest(y, v, goal) {
                Some((b, _, _)) if goal == SearchGoal::FirstHit => {
                    Ok(Self::finish(b, ProjectionPath::Local))
                }
                Some((b, u, tried)) => Ok(self.certify(y, b, u, &tried, false)),
                None => global(y),
            },
        }
    }

    /// A projection strictly closer than `local` (the answer of the local search from the
    /// walk's end `v`) found by the local search from the vertex nearest to `y`, with that
    /// vertex and the faces it tried; `None` when no vertex is strictly closer to `y` than
    /// `v` or the search from it finds nothing closer. On a thin part (a strap or plate whose two sheets lie close in
    /// R^8, joined only around a rim) a walk that starts on one sheet stops on it, at the
    /// point nearest to a query on the other, where the local search finds a projection
    /// about the sheets' distance away that certification would beat; the nearest vertex
    /// lies on the right sheet. The search for it is bounded by a descent from `v`, so it
    /// opens only a few boxes: much less than the certification it may spare.
    fn across_thin_parts(
        &self,
        y: &Vec8,
        local: &Best,
        v: VertexId,
    ) -> Option<(Best, VertexId, FaceSet)> {
        let u = self.nearest_vertex_from(y, v);
        let d2 = |w: VertexId| (self.verts[w as usize].x - y).norm_squared();
        if d2(u) >= d2(v) {
            return None;
        }
        let cands = self.faces_by_promise(y, u);
        let mut tried = FaceSet::new();
        let b = self.local_search(y, u, &cands, SearchGoal::Closest, &mut tried, 0)?;
        (b.d2 < local.d2).then_some((b, u, tried))
    }

    /// After the local search from the walk's end `v` found nothing: the local search from
    /// the vertex nearest to `y` unless that is `v` (the walk ends with a descent in f64,
    /// so the search for it is bounded by `v`'s distance), for a first hit from the
    /// closest vertex met within [`FIRST_HIT_LEAVES`] leaves first: the first answer, the
    /// vertex it came from and the faces that search tried.
    fn search_from_nearest(
        &self,
        y: &Vec8,
        v: VertexId,
        goal: SearchGoal,
    ) -> Option<(Best, VertexId, FaceSet)> {
        self.search_from_nearest_over(y, v, goal, FIRST_HIT_LEAVES)
    }

    /// [`Projector::search_from_nearest`], a first-hit search opening at most `leaves`
    /// leaves before its first local search (see [`FIRST_HIT_LEAVES`]).
    pub(super) fn search_from_nearest_over(
        &self,
        y: &Vec8,
        v: VertexId,
        goal: SearchGoal,
        leaves: usize,
    ) -> Option<(Best, VertexId, FaceSet)> {
        let d2v = (self.verts[v as usize].x - y).norm_squared();
        // The next float up keeps every vertex at exactly `v`'s distance (ties to the
        // lowest index): the nearest vertex.
        let within2 = f64::from_bits(d2v.to_bits() + 1);
        let from = |u: Option<VertexId>| {
            let u = u.filter(|&u| u != v)?;
            let cands = self.faces_by_promise(y, u);
            let mut tried = FaceSet::new();
            self.local_search(y, u, &cands, goal, &mut tried, 0)
                .map(|b| (b, u, tried))
        };
        if goal == SearchGoal::FirstHit {
            let (u, complete) = self.nearest_vertex_over(y, within2, leaves);
            let found = from(u);
            if found.is_some() || complete {
                return found;
            }
        }
        from(self.nearest_vertex_within(y, within2))
    }

    /// Certifies the local search's answer `local` (from the walk's end `v`): by its zero
    /// distance, by `v`'s reach (see the `reach` module) or against the hierarchy (faces in
    /// `tried` are skipped): `Certified` if nothing is strictly closer, else the closest
    /// projection found, as `Fallback`. With `retry`, before the hierarchy, a closer
    /// answer from the vertex nearest to `y` replaces `local` and is certified in turn
    /// (see [`Projector::across_thin_parts`]) when `local` is farther than [`THIN_PART`]
    /// of its face's longest edge.
    fn certify(
        &self,
        y: &Vec8,
        local: Best,
        v: VertexId,
        tried: &FaceSet,
        retry: bool,
    ) -> Projection {
        if self.is_zero(&local) || self.certified_by_reach(y, &local, v, tried) {
            return Self::finish(local, ProjectionPath::Certified);
        }
        if retry && local.d2 > THIN_PART * THIN_PART * self.longest_edge2(local.face) {
            if let Some((b, u, tried)) = self.across_thin_parts(y, &local, v) {
                return self.certify(y, b, u, &tried, false);
            }
        }
        let mut improved = None;
        let mut bound = local.d2;
        let keep = cone::keep_filter(self, y);
        self.bvh.search_pruned(y, &mut bound, keep, |f, bound| {
            if tried.contains(f) {
                return;
            }
            if let Some(b) = self.try_face_bounded(f, y, *bound) {
                *bound = b.d2;
                improved = Some(b);
            }
        });
        match improved {
            Some(b) => Self::finish(b, ProjectionPath::Fallback),
            None => Self::finish(local, ProjectionPath::Certified),
        }
    }

    /// A warm start's face walk: from face `f`, up to [`HINT_STEPS`] steps over faces to
    /// the one over which `aim` lies (the query itself unless the caller predicts better;
    /// its Euclidean projection onto the face's plane falls inside; each step crosses the edge opposite the most negative barycentric
    /// coordinate; a step back to the previous face ends the walk where it is), then that
    /// face and up to [`FACE_WALK`] faces in all that Newton's
    /// method exits into; the first valid projection, if it is at least as close to `y`
    /// as the corners of its face. A projection farther than a point of the surface next
    /// to it is likely not the one the walk would find (a query far off a curved surface
    /// can have several); the full search decides then, as it does when no face within
    /// the steps lies under the aim.
    pub(super) fn face_walk(&self, y: &Vec8, mut f: FaceId, aim: &Vec8) -> Option<Best> {
        let topo = self.emb.mesh().topology();
        let mut prev = NONE;
        // Newton's method is worth trying only on a face the query is over (or beside).
        for step in 0..=HINT_STEPS {
            let [a, b, c] = self.corners(f);
            let (e1, e2, r) = (b - a, c - a, aim - a);
            let (aa, ab, bb, d, e) = (
                e1.dot(&e1),
                e1.dot(&e2),
                e2.dot(&e2),
                e1.dot(&r),
                e2.dot(&r),
            );
            let det = aa * bb - ab * ab;
            let (l1, l2) = ((bb * d - ab * e) / det, (aa * e - ab * d) / det);
            let l = [1.0 - l1 - l2, l1, l2];
            let k = (0..3).min_by(|&i, &j| l[i].total_cmp(&l[j]))?;
            if l[k] >= -HINT_MARGIN {
                break;
            }
            // NaN (a degenerate face) and running out of steps end the walk.
            if !(l[k] < -HINT_MARGIN) || step == HINT_STEPS {
                return None;
            }
            let next = topo.face_neighbors(f)[(k + 1) % 3];
            if next == NONE {
                return None;
            }
            // Back to the face it came from: the query lies beside the edge between
            // the two (past both planes, as over a ridge); Newton's method decides here.
            if next == prev {
                break;
            }
            (prev, f) = (f, next);
        }
        for _ in 0..FACE_WALK {
            match self.try_face_or_exit(f, y) {
                Ok(b) => {
                    let near = self
                        .corners(f)
                        .iter()
                        .all(|c| b.d2 <= (c - y).norm_squared());
                    return near.then_some(b);
                }
                Err(Some(k)) => f = topo.face_neighbors(f)[(k + 1) % 3],
                Err(None) => return None,
            }
            if f == NONE {
                return None;
            }
        }
        None
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use wavg_mesh::{ValidMesh, procedural};

    /// From any vertex near a face, the point-location walk arrives at the face holding a
    /// query in it, unless that face is already around the vertex.
    #[test]
    fn locating_walks_over_faces_to_the_one_holding_the_query() {
        let mesh = Arc::new(ValidMesh::new(procedural::grid(10, 10, 1.0, 1.0)).unwrap());
        let emb = Arc::new(EmbeddedMesh::from_positions(mesh.clone()));
        let p = Projector::new(emb.clone()).unwrap();
        let topo = mesh.topology();
        let mut walked = 0;
        for f in 0..mesh.n_faces() as FaceId {
            let point = SurfacePoint::new(f, [0.3, 0.3, 0.4]);
            let (y, at) = (emb.point(&point), point.position(&mesh));
            for v in 0..mesh.n_vertices() as VertexId {
                if (mesh.positions[v as usize] - at).norm() > 0.25 {
                    continue;
                }
                let cands = p.faces_by_promise(&y, v);
                let mut ring0 = FaceSet::new();
                for &g in topo.ring_faces(v) {
                    ring0.push(g);
                }
                let found = p.locate_face(&y, &cands, &ring0);
                if ring0.contains(f) {
                    assert_eq!(found, None, "face {f} is around vertex {v}");
                } else {
                    assert_eq!(found, Some(f), "from vertex {v}");
                    walked += 1;
                }
            }
        }
        assert!(walked > 100, "only {walked} queries needed a walk");
    }

    /// The warm start's walk over faces heads for its aim: aimed at the query it finds the
    /// query's face from a neighbour; aimed at a point far across the mesh it runs out of
    /// steps before any Newton solve (and the full search decides).
    #[test]
    fn the_face_walk_heads_for_its_aim() {
        let mesh = Arc::new(ValidMesh::new(procedural::grid(30, 30, 1.0, 1.0)).unwrap());
        let emb = Arc::new(EmbeddedMesh::from_positions(mesh.clone()));
        let p = Projector::new(emb.clone()).unwrap();
        let topo = mesh.topology();
        let far = emb.point(&SurfacePoint::new(0, [0.2, 0.3, 0.5]));
        let mut checked = 0;
        for f in (mesh.n_faces() as FaceId / 2)..(mesh.n_faces() as FaceId / 2 + 40) {
            let y = emb.point(&SurfacePoint::new(f, [0.3, 0.3, 0.4]));
            for g in topo.face_neighbors(f).into_iter().filter(|&g| g != NONE) {
                assert_eq!(p.face_walk(&y, g, &y).map(|b| b.face), Some(f));
                assert!(p.face_walk(&y, g, &far).is_none(), "face {f} from {g}");
                checked += 1;
            }
        }
        assert!(checked >= 100);
    }

    #[test]
    fn outside_orders_by_the_smallest_barycentric() {
        let mut p = [[0.0f32; 8]; 3];
        p[1][0] = 1.0;
        p[2][1] = 1.0;
        let at = |x: f32, z: f32| {
            let mut y = [0.0f32; 8];
            (y[0], y[1]) = (x, z);
            y
        };
        assert!((outside(p, &at(0.25, 0.25)) + 0.25).abs() < 1e-6);
        assert!((outside(p, &at(2.0, 0.0)) - 1.0).abs() < 1e-6);
        assert_eq!(outside([[0.0; 8]; 3], &at(1.0, 1.0)), f32::INFINITY);
    }
}
