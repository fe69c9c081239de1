//! The decimator: a compact corner table with opposite halfedges, the legality checks
//! (topology, geometry) and the collapse loop.

use super::*;

/// The working state: a compact corner table (halfedge `3 f + i` runs from corner `i` to
/// corner `i + 1` of face `f`) with opposite halfedges, plus the modules' data.
pub(super) struct Decimator<'a> {
    /// Positions relative to the bounding-box centre: quadric errors are differences of
    /// squares, which lose their precision when the mesh sits far from the origin.
    pub(super) pos: Vec<Vector3<f64>>,
    /// The input positions, for the result.
    pub(super) orig: &'a [Vector3<f64>],
    pub(super) corner: Vec<u32>,
    pub(super) opp: Vec<u32>,
    pub(super) face_alive: Vec<bool>,
    /// One outgoing halfedge per live vertex; for a boundary vertex, the one whose
    /// opposite is missing (the clockwise-most), so rotations cover the whole fan.
    pub(super) vh: Vec<u32>,
    pub(super) alive: Vec<bool>,
    pub(super) boundary: Vec<bool>,
    pub(super) locked: Vec<bool>,
    pub(super) quadric: Vec<Quadric>,
    pub(super) normal: Vec<Vector3<f64>>,
    pub(super) cone: Vec<Cone>,
    pub(super) n_alive: usize,
    pub(super) flip_deg: f64,
    pub(super) min_cos: f64,
    pub(super) cone_deg: Option<f64>,
    pub(super) aspect: Option<f64>,
    pub(super) relaxations: Vec<Bounds>,
    /// Vertices by their best collapse (OpenMesh's updatable `HeapT`).
    pub(super) heap: IndexedHeap,
    pub(super) best: Vec<u32>,
    pub(super) mark: Vec<u32>,
    pub(super) mark_stamp: u32,
    pub(super) scratch_out: Vec<u32>,
    pub(super) scratch_hs: Vec<u32>,
    pub(super) scratch_support: Vec<u32>,
    pub(super) scratch_cands: Vec<(f64, f64, u32, u32)>,
}

impl<'a> Decimator<'a> {
    pub(super) fn new(mesh: &'a ValidMesh, opts: &DecimateOptions) -> Self {
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
            aspect: opts.max_aspect_ratio,
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
    pub(super) fn to(&self, h: u32) -> u32 {
        self.corner[next(h) as usize]
    }

    /// Outgoing halfedges of `v`, counter-clockwise from `vh[v]`.
    pub(super) fn outgoing(&self, v: u32, out: &mut Vec<u32>) {
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
    pub(super) fn ring(&self, v: u32, out: &mut Vec<u32>, scratch: &mut Vec<u32>) {
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
    pub(super) fn mark_ring(&mut self, out: &[u32]) -> usize {
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
    pub(super) fn topo_legal(&mut self, h: u32) -> bool {
        let mut out = std::mem::take(&mut self.scratch_out);
        self.outgoing(self.corner[h as usize], &mut out);
        let deg_u = self.mark_ring(&out);
        self.scratch_out = out;
        self.topo_legal_marked(h, deg_u)
    }

    /// [`Self::topo_legal`] with the one-ring of `u` already marked by [`Self::mark_ring`].
    pub(super) fn topo_legal_marked(&mut self, h: u32, deg_u: usize) -> bool {
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
    pub(super) fn priority(&self, h: u32) -> f64 {
        let (u, v) = (self.corner[h as usize], self.to(h));
        self.quadric[u as usize].eval_sum(&self.quadric[v as usize], &self.pos[v as usize])
    }

    /// The binary modules (normal flipping, normal cone, aspect ratio) for `h`, given the
    /// outgoing halfedges `out` of `u`; `worst_before` caches the worst aspect ratio around
    /// `u` between calls for the same `u`.
    pub(super) fn geometry_legal(
        &self,
        h: u32,
        out: &[u32],
        worst_before: &mut Option<f64>,
    ) -> bool {
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
        // The worst aspect ratio of the faces that stay, for ModAspectRatioT.
        let mut worst_after = 0.0f64;
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
            if self.aspect.is_some() {
                let longest = e1
                    .norm_squared()
                    .max(e2.norm_squared())
                    .max((p2 - p1).norm_squared());
                worst_after = worst_after.max(longest / len);
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
        // ModAspectRatioT: the faces that stay must be within the bound, or better than
        // the worst face around `u` before the collapse.
        match self.aspect {
            Some(bound) if worst_after > bound => {
                worst_after < *worst_before.get_or_insert_with(|| self.worst_aspect_around(out))
            }
            _ => true,
        }
    }

    /// The worst aspect ratio of the faces around the vertex whose outgoing halfedges are
    /// `out`.
    fn worst_aspect_around(&self, out: &[u32]) -> f64 {
        out.iter()
            .map(|&g| {
                let [a, b, c] =
                    [g, next(g), prev(g)].map(|k| self.pos[self.corner[k as usize] as usize]);
                aspect_ratio(a, b, c)
            })
            .fold(0.0, f64::max)
    }

    /// Recomputes vertex `x`'s best collapse and (re)inserts it in the heap.
    pub(super) fn heap_vertex(&mut self, x: u32) {
        let xi = x as usize;
        if !self.alive[xi] || self.locked[xi] {
            self.heap.remove(x);
            return;
        }
        let mut hs = std::mem::take(&mut self.scratch_hs);
        self.outgoing(x, &mut hs);
        // Candidates by (priority, squared length, target); the first legal one wins.
        // Checking legality in that order gives the same answer as checking all, but
        // usually stops at the first, so the smallest is selected each time instead of
        // sorting them all.
        let mut cands = std::mem::take(&mut self.scratch_cands);
        cands.clear();
        for &h in &hs {
            let t = self.to(h);
            let l = (self.pos[t as usize] - self.pos[xi]).norm_squared();
            cands.push((self.priority(h), l, t, h));
        }
        let mut best = None;
        let mut deg = None;
        let mut worst_before = None;
        while !cands.is_empty() {
            let mut m = 0;
            for (i, c) in cands.iter().enumerate().skip(1) {
                let b = &cands[m];
                if (c.0, c.1, c.2).partial_cmp(&(b.0, b.1, b.2)) == Some(std::cmp::Ordering::Less) {
                    m = i;
                }
            }
            let c = cands.swap_remove(m);
            let d = *deg.get_or_insert_with(|| self.mark_ring(&hs));
            if self.topo_legal_marked(c.3, d) && self.geometry_legal(c.3, &hs, &mut worst_before) {
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

    /// Fills the heap with every vertex's best collapse; [`EmbedError::Cancelled`] when
    /// `progress` asks (looked at every [`CANCEL_EVERY`] vertices: a full mesh of 10M
    /// vertices takes seconds).
    pub(super) fn init_heap(&mut self, progress: &dyn Progress) -> Result<(), EmbedError> {
        self.heap.clear();
        for x in 0..self.alive.len() as u32 {
            if x as usize % CANCEL_EVERY == 0 {
                check_cancel(progress)?;
            }
            self.heap_vertex(x);
        }
        Ok(())
    }

    /// Pops one heap entry and performs its collapse if still legal; true if collapsed.
    pub(super) fn step(&mut self) -> bool {
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
    pub(super) fn collapse(&mut self, h: u32) {
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
    pub(super) fn fix_vh(&mut self, x: u32, cands: [u32; 5]) {
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

    /// Loosens the bounds (aspect ratio first, then the normal cone, then the flipping
    /// bound); false if there is nothing left to loosen.
    pub(super) fn relax(&mut self) -> bool {
        let changed = if let Some(a) = self.aspect {
            self.aspect = (a < 1e3).then_some(a * 2.0);
            true
        } else if let Some(c) = self.cone_deg {
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
            self.relaxations.push(Bounds {
                max_normal_deviation_deg: self.flip_deg,
                max_normal_cone_deg: self.cone_deg,
                max_aspect_ratio: self.aspect,
            });
        }
        changed
    }

    pub(super) fn result(&self) -> Decimated {
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
