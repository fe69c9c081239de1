//! The local search around the walk's end: the faces around it, most promising first, and
//! their neighbours, within a fixed budget; its answer is then certified.

use super::*;

/// Small fixed set of face ids (no allocation per query).
pub(super) struct Tested {
    pub(super) ids: [u32; LOCAL_BUDGET],
    pub(super) n: usize,
}

impl Tested {
    pub(super) fn new() -> Self {
        Self {
            ids: [0; LOCAL_BUDGET],
            n: 0,
        }
    }
    pub(super) fn contains(&self, f: u32) -> bool {
        self.ids[..self.n].contains(&f)
    }
    pub(super) fn full(&self) -> bool {
        self.n == LOCAL_BUDGET
    }
    pub(super) fn push(&mut self, f: u32) {
        self.ids[self.n] = f;
        self.n += 1;
    }
}

impl Projector {
    /// Steps 2-4 of [`Projector::project`]: the faces around the walk's end `v` in the
    /// order `cands`, their neighbours, then certification or the global search.
    pub(super) fn search_around(
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
}
