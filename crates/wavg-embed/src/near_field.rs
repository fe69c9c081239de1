//! Exact polyhedral distances near a fast-marching source, by unfolding.
//!
//! First-order fast marching fits a plane wave to a front that is strongly curved near the
//! source, so its relative error there is large (up to 10-20% a few edges away on
//! irregular meshes), and `d(i, j)` and `d(j, i)` of two close landmarks disagree by as
//! much. Within a few edge lengths, straight lines from the source can instead be followed
//! exactly: the triangles a line crosses, unfolded into the plane, form a strip in which
//! it is straight (Chen & Han / Mitchell-Mount-Papadimitriou *windows*, without the
//! pseudo-sources at saddle vertices). Each window is an interval of a mesh edge seen from
//! the source's image in the unfolded plane; crossing the triangle beyond it, the window is
//! split at the triangle's third vertex, which gets the length of its straight line when
//! the line passes through the window. Every such length is the length of a path on the
//! surface, so it bounds the geodesic distance from above and is exact when the shortest
//! path bends around no vertex; fast marching then starts from these values (taking the
//! smaller of the two where both exist).

use nalgebra::{Vector2, Vector3};
use wavg_mesh::{NONE, ValidMesh};

type V2 = Vector2<f64>;

/// Radius of the exact near field, in mean edge lengths of the mesh.
///
/// ```
/// use wavg_embed::geodesic::distances_from;
/// use wavg_mesh::{ValidMesh, procedural};
/// // On a flat grid, fast marching is exact (Euclidean) within the near field of the
/// // source: 3 x 2 cells away is well inside 8 edge lengths.
/// let mesh = ValidMesh::new(procedural::grid(20, 20, 1.0, 1.0)).unwrap();
/// let d = distances_from(&mesh, &[0]);
/// assert!((d[2 * 21 + 3] - (0.15f64.powi(2) + 0.1f64.powi(2)).sqrt()).abs() < 1e-12);
/// ```
pub const NEAR_FIELD_EDGES: f64 = 8.0;

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
    /// Faces around each vertex (CSR).
    vf_offsets: Vec<u32>,
    vf: Vec<u32>,
    radius: f64,
}

#[derive(Clone, Debug)]
/// An interval `[w0, w1]` of edge `(p, q)` seen from the origin (the source's image),
/// about to enter face `g`; `w0` lies on the `p` side.
pub(crate) struct Window {
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
    pub(crate) fn new(mesh: &ValidMesh) -> Self {
        let topo = mesh.topology();
        let n = mesh.n_vertices();
        let mut vf_offsets = Vec::with_capacity(n + 1);
        let mut vf = Vec::with_capacity(mesh.n_faces() * 3);
        vf_offsets.push(0);
        for v in 0..n as u32 {
            vf.extend_from_slice(topo.ring_faces(v));
            vf_offsets.push(vf.len() as u32);
        }
        Self {
            pos: mesh.positions.clone(),
            tris: mesh.triangles.clone(),
            adj: (0..mesh.n_faces() as u32)
                .map(|f| topo.face_neighbors(f))
                .collect(),
            vf_offsets,
            vf,
            radius: NEAR_FIELD_EDGES * wavg_mesh::geometry::mean_edge_length(mesh),
        }
    }

    /// Upper bounds of the distances from `s` (exact where the shortest path is straight in
    /// an unfolding) for vertices within the near-field radius, appended to `out` (a vertex
    /// may appear several times; use the smallest).
    pub(crate) fn candidates(&self, s: u32, out: &mut Vec<(u32, f64)>, stack: &mut Vec<Window>) {
        let ps = self.pos[s as usize];
        let (lo, hi) = (
            self.vf_offsets[s as usize] as usize,
            self.vf_offsets[s as usize + 1] as usize,
        );
        stack.clear();
        for &f in &self.vf[lo..hi] {
            let t = self.tris[f as usize];
            let Some(k) = t.iter().position(|&v| v == s) else {
                continue;
            };
            let (a, b) = (t[(k + 1) % 3], t[(k + 2) % 3]);
            let (va, vb) = (self.pos[a as usize] - ps, self.pos[b as usize] - ps);
            let la = va.norm();
            if la <= 0.0 {
                continue;
            }
            let a2 = V2::new(la, 0.0);
            let b2 = V2::new(va.dot(&vb) / la, va.cross(&vb).norm() / la);
            // The first ring is exact along the edges.
            out.push((a, la));
            out.push((b, vb.norm()));
            let g = self.adj[f as usize][(k + 1) % 3];
            if g != NONE && b2.iter().all(|c| c.is_finite()) {
                stack.push(Window {
                    g,
                    p: a,
                    q: b,
                    p2: a2,
                    q2: b2,
                    w0: a2,
                    w1: b2,
                    depth: 0,
                });
            }
        }
        while let Some(w) = stack.pop() {
            self.cross_face(w, s, out, stack);
        }
    }

    /// Follows one window through its face `g`.
    fn cross_face(&self, w: Window, s: u32, out: &mut Vec<(u32, f64)>, stack: &mut Vec<Window>) {
        let orient = cross(&w.w0, &w.w1);
        if w.depth >= MAX_DEPTH
            || orient.is_nan()
            || orient.abs() <= 1e-12 * w.w0.norm() * w.w1.norm()
            || segment_distance(&w.w0, &w.w1) > self.radius
        {
            return;
        }
        let t = self.tris[w.g as usize];
        let Some(x) = t.into_iter().find(|&v| v != w.p && v != w.q) else {
            return;
        };
        if x == s {
            return;
        }
        let px = self.pos[x as usize];
        let Some(x2) = place(
            &w.p2,
            &w.q2,
            (px - self.pos[w.p as usize]).norm(),
            (px - self.pos[w.q as usize]).norm(),
        ) else {
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
            let d = x2.norm();
            if d <= self.radius {
                out.push((x, d));
            }
        }
        let edge_face = |a: u32, b: u32| {
            (0..3)
                .find(|&i| {
                    let (u, v) = (t[i], t[(i + 1) % 3]);
                    (u == a && v == b) || (u == b && v == a)
                })
                .map_or(NONE, |i| self.adj[w.g as usize][i])
        };
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
                stack.push(Window {
                    g,
                    p: w.p,
                    q: x,
                    p2: w.p2,
                    q2: x2,
                    w0: e0,
                    w1: e1,
                    depth,
                });
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
                stack.push(Window {
                    g,
                    p: x,
                    q: w.q,
                    p2: x2,
                    q2: w.q2,
                    w0: e0,
                    w1: e1,
                    depth,
                });
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
    use wavg_mesh::procedural;

    /// Smallest candidate per vertex (`INFINITY` where none).
    fn best(nf: &NearField, n: usize, s: u32) -> Vec<f64> {
        let (mut out, mut stack) = (Vec::new(), Vec::new());
        nf.candidates(s, &mut out, &mut stack);
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
        let nf = NearField::new(mesh);
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
        let nf = NearField::new(&mesh);
        for s in [0u32, 100, 2000] {
            let (mut out, mut stack) = (Vec::new(), Vec::new());
            nf.candidates(s, &mut out, &mut stack);
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
}
