//! Exact polyhedral distances near a fast-marching source, by unfolding.
//!
//! First-order fast marching fits a plane wave to a front that is strongly curved near the
//! source, so its relative error there is large (up to 10-20% a few edges away on
//! irregular meshes), and `d(i, j)` and `d(j, i)` of two close landmarks disagree by as
//! much. Within a few edge lengths, shortest paths can instead be followed exactly: the
//! triangles a straight line crosses, unfolded into the plane, form a strip in which it is
//! straight, and a shortest path only bends at saddle vertices (angle sum above 2 pi) and
//! convex boundary vertices. This is the exact algorithm of Chen & Han with the window
//! pruning of Xin & Wang ("ICH"), limited to a radius:
//!
//! * a *window* is an interval of a mesh edge seen from the image of a source in the
//!   unfolded plane; crossing the triangle beyond it, it is split at the triangle's third
//!   vertex, which gets the length of its straight line when the line passes through;
//! * saddle and boundary vertices reached become *pseudo-sources* that send windows of
//!   their own (with their length as offset) into their *shadow*, the directions a
//!   shortest path can only take by bending around them (turning by at least pi on both
//!   sides); paths that bend around them are found, and no window duplicates the straight
//!   lines passing by;
//! * windows are processed nearest first, and one is dropped when a vertex of its edge
//!   already reaches its whole interval by a shorter path (then no shortest path crosses
//!   it), which keeps the window count near linear in the vertices reached.
//!
//! Every length found is the length of a real path, so it bounds the distance from above;
//! within the radius the search is complete, so each is the exact polyhedral distance
//! (fast marching keeps these values and continues from them; its plane-wave update can
//! undershoot where two fronts meet behind a saddle). The search also stops after
//! [`NEAR_FIELD_VERTICES`] vertices (the exact zone of a source among small triangles is
//! smaller, not costlier). Degenerate triangles and the guards
//! ([`PSEUDO_SOURCES`], the window budget) mark a search incomplete, and its lengths are
//! then used as upper bounds only.

use nalgebra::{Vector2, Vector3};
use wavg_mesh::{NONE, ValidMesh};

use super::fast_marching::CANCEL_EVERY;
use crate::error::{EmbedError, Progress, check_cancel};

type V2 = Vector2<f64>;

/// Radius of the exact near field, in mean edge lengths of the mesh.
///
/// ```
/// use wavg_embed::distances_from;
/// use wavg_mesh::{ValidMesh, procedural};
/// // On a flat grid, fast marching is exact (Euclidean) within the near field of the
/// // source: 3 x 2 cells away is well inside 8 edge lengths.
/// let mesh = ValidMesh::new(procedural::grid(20, 20, 1.0, 1.0)).unwrap();
/// let d = distances_from(&mesh, &[0]);
/// assert!((d[2 * 21 + 3] - (0.15f64.powi(2) + 0.1f64.powi(2)).sqrt()).abs() < 1e-12);
/// ```
pub const NEAR_FIELD_EDGES: f64 = 8.0;

/// Most pseudo-sources followed per source (a guard on meshes with many saddles).
pub(crate) const PSEUDO_SOURCES: usize = 4096;

/// Most windows queued per source (a guard on the memory of one run: 27 MB).
const MAX_WINDOWS: usize = 1 << 18;

/// Once this many vertices are reached the search stops at the distance it has got to,
/// so a source among triangles much smaller than the mean (where the radius would hold
/// many more) costs no more than an ordinary one; its exact zone is just smaller.
pub(crate) const NEAR_FIELD_VERTICES: usize = 2048;

/// Windows are not followed through more triangles than this (a guard; the radius stops
/// them much earlier on any reasonable mesh).
const MAX_DEPTH: u16 = 96;

/// The mesh data the unfolding needs, copied once per mesh.
#[derive(Clone, Debug)]
pub(crate) struct NearField {
    pos: Vec<Vector3<f64>>,
    tris: Vec<[u32; 3]>,
    /// `adj[f][i]`: the face across edge `(tris[f][i], tris[f][i + 1])`, or `NONE`.
    adj: Vec<[u32; 3]>,
    /// Faces around each vertex (CSR), counter-clockwise: face `j` of `v` lies between
    /// `ring(v)[j]` and `ring(v)[j + 1]` (cyclically inside the mesh).
    vf_offsets: Vec<u32>,
    vf: Vec<u32>,
    /// The one-ring of each vertex, counter-clockwise (CSR; one more vertex than faces on
    /// the boundary).
    vv_offsets: Vec<u32>,
    vv: Vec<u32>,
    /// Angle around each vertex at the start of each of its faces, then the total angle
    /// (CSR at `vf_offsets[v] + v`: one more entry than faces).
    theta: Vec<f64>,
    /// Vertices a shortest path may bend around (pseudo-sources): interior saddles (angle
    /// sum above 2 pi) and boundary vertices with an angle sum above pi.
    bends: Vec<bool>,
    /// Whether pseudo-sources send windows into their shadows only (always, except in a
    /// test that checks this gives the same lengths as every direction).
    shadows_only: bool,
    /// Mean edge length of the mesh.
    edge: f64,
    radius: f64,
}

/// Per-run buffers of [`NearField::candidates`] (reused: no allocation per source).
#[derive(Clone, Debug, Default)]
pub(crate) struct NearScratch {
    /// Best length found per vertex (`INFINITY` where none).
    dist: Vec<f64>,
    /// For saddle and boundary vertices: the direction back along that best path, as an
    /// angle around the vertex (see `NearField::theta`).
    back: Vec<f64>,
    touched: Vec<u32>,
    windows: Vec<Window>,
    /// Windows and pseudo-sources by their smallest possible length: `(length bits,
    /// index into windows, or PSEUDO | vertex)`.
    heap: std::collections::BinaryHeap<std::cmp::Reverse<(u64, u32)>>,
    /// Whether a guard or a degenerate triangle cut the last search short.
    incomplete: bool,
}

const PSEUDO: u32 = 1 << 31;

/// The direction a path arrives at a vertex from.
#[derive(Clone, Copy, Debug)]
enum Back {
    /// Along the edge from this vertex.
    Edge(u32),
    /// Through face `g`, at `angle` from the face's edge towards vertex `from`.
    Face { g: u32, from: u32, angle: f64 },
}

#[derive(Clone, Debug)]
/// An interval `[w0, w1]` of edge `(p, q)` seen from the origin (the image of `src`, a
/// source or pseudo-source at length `sigma`), about to enter face `g`; `w0` lies on the
/// `p` side.
pub(crate) struct Window {
    src: u32,
    sigma: f64,
    g: u32,
    p: u32,
    q: u32,
    p2: V2,
    q2: V2,
    w0: V2,
    w1: V2,
    depth: u16,
}

fn cross(a: &V2, b: &V2) -> f64 {
    a.x * b.y - a.y * b.x
}

/// Where the ray from the origin along `w` meets segment `a -> b`, clamped onto it.
fn ray_hit(w: &V2, a: &V2, b: &V2) -> V2 {
    let e = b - a;
    let den = cross(w, &e);
    let t = if den.abs() > 0.0 {
        (cross(a, w) / den).clamp(0.0, 1.0)
    } else {
        0.0
    };
    a + e * t
}

/// Distance from the origin to segment `a -> b`.
fn segment_distance(a: &V2, b: &V2) -> f64 {
    let e = b - a;
    let l2 = e.norm_squared();
    let t = if l2 > 0.0 {
        (-a.dot(&e) / l2).clamp(0.0, 1.0)
    } else {
        0.0
    };
    (a + e * t).norm()
}

impl NearField {
    /// The near field of `mesh`; [`EmbedError::Cancelled`] when `progress` asks (looked
    /// at every [`CANCEL_EVERY`] vertices).
    pub(crate) fn new(mesh: &ValidMesh, progress: &dyn Progress) -> Result<Self, EmbedError> {
        let topo = mesh.topology();
        let n = mesh.n_vertices();
        let edge = wavg_mesh::geometry::mean_edge_length(mesh);
        let mut vf_offsets = Vec::with_capacity(n + 1);
        let mut vf = Vec::with_capacity(mesh.n_faces() * 3);
        let (mut vv_offsets, mut vv) = (vec![0u32], Vec::with_capacity(mesh.n_faces() * 3));
        let mut theta = Vec::with_capacity(mesh.n_faces() * 3 + n);
        vf_offsets.push(0);
        for v in 0..n as u32 {
            if v as usize % CANCEL_EVERY == 0 {
                check_cancel(progress)?;
            }
            let (ring, faces) = (topo.ring(v), topo.ring_faces(v));
            vf.extend_from_slice(faces);
            vf_offsets.push(vf.len() as u32);
            vv.extend_from_slice(ring);
            vv_offsets.push(vv.len() as u32);
            let p = mesh.positions[v as usize];
            let mut t = 0.0;
            theta.push(t);
            for j in 0..faces.len() {
                let (a, b) = (
                    mesh.positions[ring[j] as usize] - p,
                    mesh.positions[ring[(j + 1) % ring.len()] as usize] - p,
                );
                t += a.cross(&b).norm().atan2(a.dot(&b));
                theta.push(t);
            }
        }
        // Total angle around each vertex: the last fan entry.
        let tau = std::f64::consts::TAU;
        let bends = (0..n)
            .map(|v| {
                let total = theta[vf_offsets[v + 1] as usize + v];
                let full = if topo.is_boundary_vertex(v as u32) {
                    tau / 2.0
                } else {
                    tau
                };
                total > full * (1.0 + 1e-9)
            })
            .collect();
        Ok(Self {
            pos: mesh.positions.clone(),
            tris: mesh.triangles.clone(),
            adj: (0..mesh.n_faces() as u32)
                .map(|f| topo.face_neighbors(f))
                .collect(),
            vf_offsets,
            vf,
            vv_offsets,
            vv,
            theta,
            bends,
            shadows_only: true,
            edge,
            radius: NEAR_FIELD_EDGES * edge,
        })
    }

    /// Sets the radius to `edges` mean edge lengths (0 turns the near field off).
    pub(crate) fn set_radius_edges(&mut self, edges: f64) {
        self.radius = edges.max(0.0) * self.edge;
    }

    /// Upper bounds of the distances from `s` for the vertices within the near-field
    /// radius, appended to `out` (one entry per vertex): the lengths of straight lines
    /// followed through unfolded triangles from `s` and from the saddle and boundary
    /// vertices they reach (pseudo-sources, where a shortest path may bend), nearest first
    /// (Chen & Han's windows with Xin & Wang's pruning: a window is dropped when a vertex of
    /// its edge already reaches its whole interval by a shorter path). Exact up to rounding
    /// wherever the shortest path lies within the radius and bends around at most
    /// [`PSEUDO_SOURCES`] vertices.
    ///
    /// Returns whether the search was complete (no guard hit and no degenerate triangle on
    /// the way), so that every length appended is the exact polyhedral distance.
    pub(crate) fn candidates(
        &self,
        s: u32,
        out: &mut Vec<(u32, f64)>,
        sc: &mut NearScratch,
    ) -> bool {
        let n = self.pos.len();
        if sc.dist.len() != n {
            sc.dist = vec![f64::INFINITY; n];
            sc.back = vec![0.0; n];
            sc.touched.clear();
        }
        for &v in &sc.touched {
            sc.dist[v as usize] = f64::INFINITY;
        }
        sc.touched.clear();
        sc.windows.clear();
        sc.heap.clear();
        sc.incomplete = false;
        if s as usize >= n {
            return false;
        }
        sc.dist[s as usize] = 0.0;
        sc.touched.push(s);
        sc.heap
            .push(std::cmp::Reverse((0.0f64.to_bits(), PSEUDO | s)));
        let mut pseudo = 0;
        // Lengths below this are final (every item nearer has been processed).
        let mut exact_below = f64::INFINITY;
        while let Some(std::cmp::Reverse((key, i))) = sc.heap.pop() {
            if sc.touched.len() > NEAR_FIELD_VERTICES {
                exact_below = f64::from_bits(key);
                break;
            }
            if i & PSEUDO != 0 {
                let u = i & !PSEUDO;
                let sigma = f64::from_bits(key);
                // Superseded by a shorter length (pushed again), or over budget.
                if sc.dist[u as usize] < sigma {
                    continue;
                }
                if pseudo >= PSEUDO_SOURCES {
                    sc.incomplete = true;
                    continue;
                }
                pseudo += 1;
                self.emit(u, sigma, u == s || !self.shadows_only, sc);
            } else {
                let w = sc.windows[i as usize].clone();
                if !self.dominated(&w, &sc.dist) {
                    self.cross_face(w, sc);
                }
            }
        }
        out.extend(
            sc.touched
                .iter()
                .map(|&v| (v, sc.dist[v as usize]))
                .filter(|&(_, d)| d <= self.radius && d < exact_below),
        );
        !sc.incomplete
    }

    /// Records length `d` for `x`; a saddle or boundary vertex whose length improves
    /// becomes a pseudo-source.
    fn reach(&self, x: u32, d: f64, back: Back, sc: &mut NearScratch) {
        let cur = &mut sc.dist[x as usize];
        if d >= *cur || d > self.radius {
            return;
        }
        if cur.is_infinite() {
            sc.touched.push(x);
        }
        *cur = d;
        if self.bends[x as usize] {
            sc.back[x as usize] = self.back_angle(x, back);
            sc.heap.push(std::cmp::Reverse((d.to_bits(), PSEUDO | x)));
        }
    }

    /// The face across edge `(a, b)` of face `f` (`NONE` on the boundary or if `(a, b)` is
    /// not an edge of `f`).
    fn across(&self, f: u32, a: u32, b: u32) -> u32 {
        let t = self.tris[f as usize];
        (0..3)
            .find(|&i| {
                let (u, v) = (t[i], t[(i + 1) % 3]);
                (u == a && v == b) || (u == b && v == a)
            })
            .map_or(NONE, |i| self.adj[f as usize][i])
    }

    /// Faces, one-ring and angles (see the fields) around `v`.
    fn fan(&self, v: u32) -> (&[u32], &[u32], &[f64]) {
        let v = v as usize;
        let (f0, f1) = (self.vf_offsets[v] as usize, self.vf_offsets[v + 1] as usize);
        let (r0, r1) = (self.vv_offsets[v] as usize, self.vv_offsets[v + 1] as usize);
        (
            &self.vf[f0..f1],
            &self.vv[r0..r1],
            &self.theta[f0 + v..f1 + v + 1],
        )
    }

    /// The angle around `x` of the direction `back` (NaN if it does not fit the fan).
    fn back_angle(&self, x: u32, back: Back) -> f64 {
        let (faces, ring, theta) = self.fan(x);
        match back {
            Back::Edge(e) => ring
                .iter()
                .position(|&r| r == e)
                .map_or(f64::NAN, |k| theta[k]),
            Back::Face { g, from, angle } => match faces.iter().position(|&f| f == g) {
                Some(j) if ring[j] == from => theta[j] + angle,
                Some(j) => theta[j + 1] - angle,
                None => f64::NAN,
            },
        }
    }

    /// Queues window `w` (unless it lies beyond the radius).
    fn push(&self, w: Window, sc: &mut NearScratch) {
        let near = w.sigma + segment_distance(&w.w0, &w.w1);
        if near <= self.radius && !self.dominated(&w, &sc.dist) {
            if sc.windows.len() < MAX_WINDOWS {
                sc.heap
                    .push(std::cmp::Reverse((near.to_bits(), sc.windows.len() as u32)));
                sc.windows.push(w);
            } else {
                sc.incomplete = true;
            }
        }
    }

    /// Whether a vertex of the window's edge reaches every point of its interval by a path
    /// no longer than the window's lines: then no shortest path passes through it. The
    /// length through the window minus the length via `p` only decreases away from `p`, so
    /// checking the far end `w1` suffices (and `w0` for `q`).
    fn dominated(&self, w: &Window, dist: &[f64]) -> bool {
        let via_p = dist[w.p as usize] + (w.w1 - w.p2).norm();
        let via_q = dist[w.q as usize] + (w.w0 - w.q2).norm();
        let slack = 1.0 + 1e-9;
        w.sigma + w.w1.norm() > via_p * slack || w.sigma + w.w0.norm() > via_q * slack
    }

    /// Straight lines from `u` at length `sigma`: its first ring, and windows into the
    /// faces beyond. A source sends them in every direction; a pseudo-source only into its
    /// *shadow*, the directions turning by at least pi on both sides from the way back
    /// along its shortest path (elsewhere the straight lines passing `u` are shorter).
    fn emit(&self, u: u32, sigma: f64, every_direction: bool, sc: &mut NearScratch) {
        use std::f64::consts::PI;
        // A little wider than the shadow: rounding must not lose a direction.
        const EPS: f64 = 1e-9;
        let (faces, ring, theta) = self.fan(u);
        let total = theta[faces.len()];
        let beta = sc.back[u as usize];
        let mut ranges = [(0.0, total), (0.0, 0.0)];
        if !every_direction && beta.is_finite() {
            ranges = if ring.len() == faces.len() {
                // Inside the mesh: one arc of the circle of length `total`.
                let (lo, len) = (
                    (beta + PI - EPS).rem_euclid(total),
                    total - 2.0 * PI + 2.0 * EPS,
                );
                if len <= 0.0 {
                    [(0.0, 0.0); 2]
                } else if lo + len <= total {
                    [(lo, lo + len), (0.0, 0.0)]
                } else {
                    [(lo, total), (0.0, lo + len - total)]
                }
            } else {
                // On the boundary: both ends of the open fan.
                [(0.0, beta - PI + EPS), (beta + PI - EPS, total)]
            };
        }
        let pu = self.pos[u as usize];
        for (j, &f) in faces.iter().enumerate() {
            let (a, b) = (ring[j], ring[(j + 1) % ring.len()]);
            let (va, vb) = (self.pos[a as usize] - pu, self.pos[b as usize] - pu);
            let la = va.norm();
            // The first ring is exact along the edges.
            self.reach(a, sigma + la, Back::Edge(u), sc);
            self.reach(b, sigma + vb.norm(), Back::Edge(u), sc);
            let a2 = V2::new(la, 0.0);
            let b2 = V2::new(va.dot(&vb) / la, va.cross(&vb).norm() / la);
            let g = self.across(f, a, b);
            if g == NONE || la <= 0.0 || !b2.iter().all(|c| c.is_finite()) {
                continue;
            }
            let gamma = theta[j + 1] - theta[j];
            for &(r0, r1) in &ranges {
                let (t0, t1) = ((r0 - theta[j]).max(0.0), (r1 - theta[j]).min(gamma));
                if t1 <= t0 {
                    continue;
                }
                let ray = |t: f64| V2::new(t.cos(), t.sin());
                let w0 = if t0 <= 0.0 {
                    a2
                } else {
                    ray_hit(&ray(t0), &a2, &b2)
                };
                let w1 = if t1 >= gamma {
                    b2
                } else {
                    ray_hit(&ray(t1), &a2, &b2)
                };
                self.push(
                    Window {
                        src: u,
                        sigma,
                        g,
                        p: a,
                        q: b,
                        p2: a2,
                        q2: b2,
                        w0,
                        w1,
                        depth: 0,
                    },
                    sc,
                );
            }
        }
    }

    /// Follows one window through its face `g`.
    fn cross_face(&self, w: Window, sc: &mut NearScratch) {
        let orient = cross(&w.w0, &w.w1);
        if w.depth >= MAX_DEPTH || orient.is_nan() {
            sc.incomplete = true;
            return;
        }
        if orient.abs() <= 1e-12 * w.w0.norm() * w.w1.norm() {
            // Narrowed to a single line: nothing beyond it that its neighbours miss.
            return;
        }
        let t = self.tris[w.g as usize];
        let Some(x) = t.into_iter().find(|&v| v != w.p && v != w.q) else {
            return;
        };
        if x == w.src {
            return;
        }
        let px = self.pos[x as usize];
        let Some(x2) = place(
            &w.p2,
            &w.q2,
            (px - self.pos[w.p as usize]).norm(),
            (px - self.pos[w.q as usize]).norm(),
        ) else {
            sc.incomplete = true;
            return;
        };
        // Which side of the wedge's two rays x lies on (the wedge from w0 to w1). A line
        // through a vertex continues along a window's edge: x exactly on a ray (up to
        // rounding) counts as seen.
        let tol = 1e-12 * x2.norm();
        let side0 = orient.signum() * cross(&w.w0, &x2) / w.w0.norm();
        let side1 = orient.signum() * cross(&x2, &w.w1) / w.w1.norm();
        let right_of_w0 = side0 > 0.0;
        let left_of_w1 = side1 > 0.0;
        if side0 >= -tol && side1 >= -tol {
            // The way back from x: towards the origin, measured from its edge to p.
            let (e, o) = (w.p2 - x2, -x2);
            let angle = cross(&e, &o).abs().atan2(e.dot(&o));
            let back = Back::Face {
                g: w.g,
                from: w.p,
                angle,
            };
            self.reach(x, w.sigma + x2.norm(), back, sc);
        }
        let edge_face = |a: u32, b: u32| self.across(w.g, a, b);
        let depth = w.depth + 1;
        // Edge (p, x): the wedge crosses it unless x lies beyond the ray through w0.
        if right_of_w0 {
            let g = edge_face(w.p, x);
            if g != NONE {
                let e0 = ray_hit(&w.w0, &w.p2, &x2);
                let e1 = if left_of_w1 {
                    x2
                } else {
                    ray_hit(&w.w1, &w.p2, &x2)
                };
                self.push(
                    Window {
                        g,
                        q: x,
                        q2: x2,
                        w0: e0,
                        w1: e1,
                        depth,
                        ..w.clone()
                    },
                    sc,
                );
            }
        }
        // Edge (x, q): unless x lies beyond the ray through w1.
        if left_of_w1 {
            let g = edge_face(x, w.q);
            if g != NONE {
                let e0 = if right_of_w0 {
                    x2
                } else {
                    ray_hit(&w.w0, &x2, &w.q2)
                };
                let e1 = ray_hit(&w.w1, &x2, &w.q2);
                self.push(
                    Window {
                        g,
                        p: x,
                        p2: x2,
                        w0: e0,
                        w1: e1,
                        depth,
                        ..w
                    },
                    sc,
                );
            }
        }
    }
}

/// The point at distances `lp` from `p2` and `lr` from `r2`, on the side of line `p2 r2`
/// away from the origin.
pub(crate) fn place(p2: &V2, r2: &V2, lp: f64, lr: f64) -> Option<V2> {
    let e = r2 - p2;
    let l = e.norm();
    if l <= 0.0 {
        return None;
    }
    let ex = e / l;
    let mut ey = V2::new(-ex.y, ex.x);
    if (-p2).dot(&ey) > 0.0 {
        ey = -ey;
    }
    let along = (lp * lp - lr * lr + l * l) / (2.0 * l);
    let h = (lp * lp - along * along).max(0.0).sqrt();
    let w = p2 + ex * along + ey * h;
    w.iter().all(|c| c.is_finite()).then_some(w)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::error::NoProgress;
    use wavg_mesh::procedural;

    /// Smallest candidate per vertex (`INFINITY` where none).
    fn best(nf: &NearField, n: usize, s: u32) -> Vec<f64> {
        let (mut out, mut sc) = (Vec::new(), NearScratch::default());
        assert!(nf.candidates(s, &mut out, &mut sc), "incomplete from {s}");
        let mut d = vec![f64::INFINITY; n];
        for (x, v) in out {
            d[x as usize] = d[x as usize].min(v);
        }
        d
    }

    /// On intrinsically flat meshes every straight line is a geodesic and nothing blocks
    /// it: the near field must reach every vertex within its radius (less one edge, for
    /// windows that narrow to nothing at a vertex) with exactly the flat distance.
    fn check_flat(mesh: &ValidMesh, flat: &[Vector2<f64>], sources: &[u32]) {
        let nf = NearField::new(mesh, &NoProgress).unwrap();
        let h = wavg_mesh::geometry::mean_edge_length(mesh);
        for &s in sources {
            let d = best(&nf, mesh.n_vertices(), s);
            let mut reached = 0;
            for (x, &dx) in d.iter().enumerate() {
                let exact = (flat[x] - flat[s as usize]).norm();
                if dx.is_finite() {
                    assert!(
                        (dx - exact).abs() <= 1e-9 * exact,
                        "{s} -> {x}: {dx} vs {exact}"
                    );
                    reached += 1;
                } else if x != s as usize {
                    assert!(exact > nf.radius - h, "{s} -> {x} at {exact} not reached");
                }
            }
            assert!(reached > 50, "{reached}");
        }
    }

    #[test]
    fn flat_grid_distances_are_euclidean_and_complete() {
        let mesh = ValidMesh::new(procedural::grid(40, 40, 1.0, 1.0)).unwrap();
        let flat: Vec<_> = mesh.positions.iter().map(|p| p.xy()).collect();
        check_flat(&mesh, &flat, &[0, 20 * 41 + 20, 5 * 41 + 33]);
    }

    #[test]
    fn grid_rolled_into_a_cylinder_keeps_its_flat_distances() {
        // Columns of rectangles around 3/4 of a cylinder: intrinsically a flat grid of
        // chord-wide, unit-high rectangles, though no face lies in one plane with another.
        let (nx, ny) = (30u32, 30u32);
        let mut mesh = procedural::grid(nx, ny, 1.0, 1.0);
        let (r, span) = (0.25, 1.5 * std::f64::consts::PI);
        let chord = 2.0 * r * (span / nx as f64 / 2.0).sin();
        let flat: Vec<_> = (0..mesh.positions.len() as u32)
            .map(|v| {
                let (i, j) = (v % (nx + 1), v / (nx + 1));
                Vector2::new(i as f64 * chord, j as f64 / ny as f64)
            })
            .collect();
        for (v, p) in mesh.positions.iter_mut().enumerate() {
            let a = span * (v as u32 % (nx + 1)) as f64 / nx as f64;
            *p = Vector3::new(r * a.cos(), r * a.sin(), p.y);
        }
        let mesh = ValidMesh::new(mesh).unwrap();
        check_flat(&mesh, &flat, &[15 * 31 + 15, 3 * 31 + 4]);
    }

    #[test]
    fn every_candidate_is_at_least_the_straight_line_distance() {
        let mesh =
            ValidMesh::new(procedural::with_noise(procedural::icosphere(4), 0.3, 7)).unwrap();
        let nf = NearField::new(&mesh, &NoProgress).unwrap();
        for s in [0u32, 100, 2000] {
            let (mut out, mut sc) = (Vec::new(), NearScratch::default());
            nf.candidates(s, &mut out, &mut sc);
            assert!(!out.is_empty());
            for (x, d) in out {
                let chord = (mesh.positions[x as usize] - mesh.positions[s as usize]).norm();
                assert!(
                    d >= chord * (1.0 - 1e-12) && d <= nf.radius,
                    "{s} -> {x}: {d} {chord}"
                );
            }
        }
    }

    /// On a saddle surface (a noisy hyperbolic paraboloid: most vertices have angle sums
    /// above 2 pi, so shortest paths bend around them and straight lines alone leave
    /// shadows) the lengths must be exact polyhedral distances: symmetric to rounding and
    /// obeying the triangle inequality, which no approximation does to 1e-9. Without the
    /// pseudo-sources the same pairs disagree.
    /// A noisy hyperbolic paraboloid: most vertices are saddles.
    fn saddle_surface() -> ValidMesh {
        let mut mesh = procedural::grid(36, 36, 1.0, 1.0);
        for p in &mut mesh.positions {
            p.z = 0.8 * ((p.x - 0.5).powi(2) - (p.y - 0.5).powi(2));
        }
        ValidMesh::new(procedural::with_noise(mesh, 0.2, 5)).unwrap()
    }

    #[test]
    fn saddle_surface_distances_are_exact() {
        let mesh = saddle_surface();
        let n = mesh.n_vertices();
        let mut nf = NearField::new(&mesh, &NoProgress).unwrap();
        let saddles = nf.bends.iter().filter(|&&b| b).count();
        assert!(saddles > n / 4, "{saddles} of {n}");
        // A 4 x 3 lattice of sources 5 to 6 cells apart in the middle of the 36 x 36 grid.
        let sources: Vec<u32> = (0..12)
            .map(|i| (10 + i % 4 * 5) * 37 + 10 + i / 4 * 6)
            .collect();
        let rows: Vec<Vec<f64>> = sources.iter().map(|&s| best(&nf, n, s)).collect();
        let mut pairs = 0;
        for (i, &a) in sources.iter().enumerate() {
            for (j, &b) in sources.iter().enumerate() {
                let (ab, ba) = (rows[i][b as usize], rows[j][a as usize]);
                if a == b || !(ab.is_finite() && ba.is_finite()) {
                    continue;
                }
                pairs += 1;
                assert!((ab - ba).abs() <= 1e-9 * ab, "{a} <-> {b}: {ab} vs {ba}");
                for (x, (&ax, &bx)) in rows[i].iter().zip(&rows[j]).enumerate() {
                    if ax.is_finite() && bx.is_finite() {
                        assert!(ax <= ab + bx + 1e-9 * ab, "{a} -> {x} via {b}");
                    }
                }
            }
        }
        assert!(pairs > 40, "{pairs}");
        // Straight lines only (pseudo-sources off) reach fewer vertices, never with a
        // shorter length.
        nf.bends.iter_mut().for_each(|b| *b = false);
        let (mut full, mut straight) = (0, 0);
        for (i, &a) in sources.iter().enumerate() {
            let only = best(&nf, n, a);
            for (x, (&d, &e)) in rows[i].iter().zip(&only).enumerate() {
                full += usize::from(d.is_finite());
                straight += usize::from(e.is_finite());
                assert!(
                    !e.is_finite() || e >= d * (1.0 - 1e-12),
                    "{a} -> {x}: {e} < {d}"
                );
            }
        }
        assert!(straight < full, "{straight} vs {full}");
    }

    /// With a radius holding far more vertices than [`NEAR_FIELD_VERTICES`], the search
    /// stops at the distance it has got to: about that many vertices, all exact, and all
    /// the vertices nearer than the farthest one returned.
    #[test]
    fn vertex_budget_bounds_the_work_and_keeps_exactness() {
        let mesh = ValidMesh::new(procedural::grid(120, 120, 1.0, 1.0)).unwrap();
        let mut nf = NearField::new(&mesh, &NoProgress).unwrap();
        nf.set_radius_edges(1000.0);
        let s = 60 * 121 + 60;
        let (mut out, mut sc) = (Vec::new(), NearScratch::default());
        assert!(nf.candidates(s, &mut out, &mut sc));
        assert!(out.len() > NEAR_FIELD_VERTICES / 2 && out.len() <= NEAR_FIELD_VERTICES + 1);
        let flat = |v: u32| {
            (mesh.positions[v as usize] - mesh.positions[s as usize])
                .xy()
                .norm()
        };
        let far = out.iter().map(|&(_, d)| d).fold(0.0, f64::max);
        for &(x, d) in &out {
            assert!(
                (d - flat(x)).abs() <= 1e-9 * d.max(1e-9),
                "{x}: {d} vs {}",
                flat(x)
            );
        }
        let inside = (0..mesh.n_vertices() as u32)
            .filter(|&v| flat(v) < far * (1.0 - 1e-9))
            .count();
        assert!(
            out.len() >= inside,
            "{} returned, {inside} nearer",
            out.len()
        );
    }

    /// Pseudo-sources sending windows only into their shadows find the same lengths as
    /// sending them in every direction (which is plainly exact), on real meshes with open
    /// boundaries and on the saddle surface.
    #[test]
    fn shadows_only_changes_nothing() {
        let mut meshes = vec![saddle_surface()];
        for file in ["meshes/camelhead.off", "meshes/fertility.off"] {
            if let Some(path) = wavg_testdata::require_data_file("near_field::shadows", file) {
                meshes.push(ValidMesh::new(wavg_mesh::io::load(&path).unwrap()).unwrap());
            }
        }
        for mesh in &meshes {
            let n = mesh.n_vertices();
            let mut nf = NearField::new(mesh, &NoProgress).unwrap();
            let sources: Vec<u32> = (0..25).map(|i| (i * 7919 % n) as u32).collect();
            let shadow: Vec<Vec<f64>> = sources.iter().map(|&s| best(&nf, n, s)).collect();
            nf.shadows_only = false;
            for (row, &s) in shadow.iter().zip(&sources) {
                let every = best(&nf, n, s);
                for (x, (&a, &b)) in row.iter().zip(&every).enumerate() {
                    assert!(
                        a == b || (a - b).abs() <= 1e-12 * b,
                        "{s} -> {x}: {a} (shadows) vs {b} (every direction)"
                    );
                }
            }
        }
    }
}
