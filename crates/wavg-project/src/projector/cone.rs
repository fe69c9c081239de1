//! Tangent-cone bounds over the hierarchy: per node, a proof that no triangle under it
//! has a Phong projection of a query, so the global searches skip whole subtrees of
//! triangles that are near the query but "beside" it rather than under it.
//!
//! On a triangle the tangent equations read `F(xi) = Psi(xi) (p(xi) - y) = 0` with
//! `Psi(xi) = sum_e c_e(xi) B_e`, `B_e = X_e T_{i(e)}` (2x8) and convex weights `c_e`.
//! Rotating the equations by any orthogonal 2x2 `Q` changes neither their roots nor
//! `|F|`, so each triangle may be compared in its own gauge: each node stores a 2x8
//! matrix `M`, and `eps`, `s` such that every triangle `f` under it has an orthogonal
//! `Q_f` with `||Q_f B_e - M|| <= eps` for its six terms, and `||B_e||, ||T_i|| <= s`
//! (Frobenius norms, which bound the operator norms); then `||Q_f Psi(xi) - M|| <= eps`
//! on the triangle. For a query `y`, with `alpha` the distance from the origin to the 2-D
//! box that interval arithmetic gives for `M (p - y)` over the node's box, and `beta` the
//! largest distance from `y` to a point of that box, every point of every triangle under
//! the node has `|F| = |Q_f F| >= |M (p - y)| - eps |p - y| >= alpha - eps beta`.
//! Newton's method accepts only points of the triangle with
//! `|F|_inf <= CLAMP_RESIDUAL fscale`, and the system's scale is at most `2 s beta` (its
//! entries are `T_i (y - v_i)` and `B_e (v_k - v_i)`, corners in the box), so
//! `alpha > (eps + 3 CLAMP_RESIDUAL s) beta` (`3 > 2 sqrt(2)`, the rest covers f64
//! rounding) proves that no triangle under the node holds a projection.

use super::*;
use crate::ort::{self, M2};
use crate::triangle::{CLAMP_RESIDUAL, TERM_VERTEX};

/// One node's bound, 72 bytes.
#[derive(Clone, Copy, Debug, Default)]
struct Cone {
    /// The reference plane `M`, row-major.
    m: [f32; 16],
    /// `eps`: bounds `||B_e - M||` over the node's terms.
    eps: f32,
    /// `s`: bounds `||B_e||` and `||T_i||` over the node's terms and corners.
    s: f32,
}

/// The bounds of every node of a hierarchy, by node index.
pub(super) struct Cones(Vec<Cone>);

/// Rounds a non-negative bound up to f32 (conversion is within half an f32 ulp).
fn up32(x: f64) -> f32 {
    (x * (1.0 + 1e-6)) as f32
}

/// `||a - b||_F` of two 2x8 matrices, `a` stored as f32.
fn dist_f(a: &[f32; 16], b: &[f64; 16]) -> f64 {
    a.iter()
        .zip(b)
        .map(|(&x, &y)| (x as f64 - y) * (x as f64 - y))
        .sum::<f64>()
        .sqrt()
}

impl Cones {
    /// Computes the bounds bottom-up: leaves from their triangles' terms, interior nodes
    /// from their children (`M` the children's mean, `eps` by the triangle inequality).
    pub(super) fn new(bvh: &Bvh, faces: &[Face], verts: &[VertexRec]) -> Self {
        let n = bvh.n_nodes();
        let mut cones: Vec<Cone> = (0..n)
            .into_par_iter()
            .with_min_len(1024)
            .map(|ni| match bvh.node(ni) {
                Err(items) => leaf(items, faces, verts),
                Ok(_) => Cone::default(),
            })
            .collect();
        for ni in (0..n).rev() {
            if let Ok((l, r)) = bvh.node(ni) {
                debug_assert!(l > ni && r > ni);
                let (a, b) = (&cones[l], &cones[r]);
                let (ma, mb) = (a.m.map(|v| v as f64), b.m.map(|v| v as f64));
                // The right child's gauge turned to the left's (the children's bounds hold
                // for any rotation of their `M`).
                let mb = rotate(&ort::ort(&gram(&ma, &mb)), &mb);
                let m = std::array::from_fn(|k| (0.5 * (ma[k] + mb[k])) as f32);
                let eps = (a.eps as f64 + dist_f(&m, &ma)).max(b.eps as f64 + dist_f(&m, &mb));
                cones[ni] = Cone {
                    m,
                    eps: up32(eps),
                    s: a.s.max(b.s),
                };
            }
        }
        Self(cones)
    }

    /// Heap bytes used.
    pub(super) fn bytes(&self) -> usize {
        std::mem::size_of_val(&self.0[..])
    }

    /// Whether no triangle under node `ni` (box `lo`, `hi`) can hold a projection of `y`
    /// (see the module documentation).
    #[inline]
    pub(super) fn excludes(&self, ni: usize, lo: &[f32; 8], hi: &[f32; 8], y: &Vec8) -> bool {
        let c = &self.0[ni];
        let mut iv = [[0.0f64; 2]; 2];
        let mut beta2 = 0.0;
        for k in 0..8 {
            let (a, b) = (lo[k] as f64 - y[k], hi[k] as f64 - y[k]);
            beta2 += (a * a).max(b * b);
            for (r, iv) in iv.iter_mut().enumerate() {
                let m = c.m[r * 8 + k] as f64;
                let (u, v) = (m * a, m * b);
                iv[0] += u.min(v);
                iv[1] += u.max(v);
            }
        }
        let gap = |[l, u]: [f64; 2]| {
            if l > 0.0 {
                l
            } else if u < 0.0 {
                -u
            } else {
                0.0
            }
        };
        let (g0, g1) = (gap(iv[0]), gap(iv[1]));
        let alpha2 = g0 * g0 + g1 * g1;
        let k = (c.eps as f64 + 3.0 * CLAMP_RESIDUAL * c.s as f64) * (1.0 + 1e-9);
        alpha2 > k * k * beta2
    }
}

/// A leaf's bound: `M` the mean of its terms `B_e`.
fn leaf(items: &[u32], faces: &[Face], verts: &[VertexRec]) -> Cone {
    let mut terms = [[0.0f64; 16]; 6 * LEAF_MAX];
    let mut n = 0;
    let mut s: f64 = 0.0;
    for &f in items.iter().take(LEAF_MAX) {
        let face = &faces[f as usize];
        for v in face.v {
            let t = &verts[v as usize].t;
            s = s.max(t.iter().map(|&x| x as f64 * x as f64).sum::<f64>().sqrt());
        }
        for e in 0..6 {
            let x = face.d.x[e].map(|v| v as f64);
            let t = &verts[face.v[TERM_VERTEX[e]] as usize].t;
            let b = &mut terms[n];
            for col in 0..8 {
                let (t0, t1) = (t[col] as f64, t[8 + col] as f64);
                b[col] = x[0] * t0 + x[1] * t1;
                b[8 + col] = x[2] * t0 + x[3] * t1;
            }
            s = s.max(b.iter().map(|v| v * v).sum::<f64>().sqrt());
            n += 1;
        }
    }
    if items.len() > LEAF_MAX || n == 0 {
        // Not expected (leaves are small); a bound that never excludes.
        return Cone {
            m: [0.0; 16],
            eps: f32::INFINITY,
            s: f32::INFINITY,
        };
    }
    // Each triangle's terms turned (as one) to the gauge of the first triangle's mean.
    let nf = n / 6;
    let face_mean = |t: &[[f64; 16]]| -> [f64; 16] {
        std::array::from_fn(|k| t.iter().map(|b| b[k]).sum::<f64>() / t.len() as f64)
    };
    let reference = face_mean(&terms[..6]);
    for f in 0..nf {
        let t = &mut terms[6 * f..6 * f + 6];
        let q = ort::ort(&gram(&reference, &face_mean(t)));
        for b in t.iter_mut() {
            *b = rotate(&q, b);
        }
    }
    let m = face_mean(&terms[..n]).map(|v| v as f32);
    let eps = terms[..n].iter().map(|b| dist_f(&m, b)).fold(0.0, f64::max);
    Cone {
        m,
        eps: up32(eps),
        s: up32(s),
    }
}

/// `a b^T` of two 2x8 matrices: `ort` of it turns `b` closest to `a`.
fn gram(a: &[f64; 16], b: &[f64; 16]) -> M2 {
    let dot = |r: usize, c: usize| (0..8).map(|k| a[r * 8 + k] * b[c * 8 + k]).sum::<f64>();
    [dot(0, 0), dot(0, 1), dot(1, 0), dot(1, 1)]
}

/// `q b` for a 2x2 `q` and a 2x8 `b`.
fn rotate(q: &M2, b: &[f64; 16]) -> [f64; 16] {
    std::array::from_fn(|k| {
        let c = k % 8;
        if k < 8 {
            q[0] * b[c] + q[1] * b[8 + c]
        } else {
            q[2] * b[c] + q[3] * b[8 + c]
        }
    })
}

/// Triangles a leaf's bound is computed from directly.
const LEAF_MAX: usize = 8;

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;
    use rand::{Rng, SeedableRng};
    use wavg_mesh::{ValidMesh, procedural};

    /// A curved embedding of a procedural mesh in R^8 (`curved`) or its padded positions.
    fn projector(mesh: usize, curved: bool) -> Projector {
        let m = match mesh {
            0 => procedural::icosphere(2),
            1 => procedural::torus(16, 9, 1.0, 0.35),
            2 => procedural::with_noise(procedural::bump_sphere(2, 0.3), 0.02, 3),
            _ => procedural::grid(7, 6, 1.0, 0.8),
        };
        let m = Arc::new(ValidMesh::new(m).unwrap());
        let coords = m
            .positions
            .iter()
            .map(|p| {
                let (x, y, z) = (p.x, p.y, p.z);
                if curved {
                    Vec8::from_column_slice(&[
                        x,
                        y,
                        z,
                        0.3 * (2.0 * x).sin(),
                        0.3 * (2.0 * y).cos(),
                        0.4 * x * y,
                        0.4 * y * z,
                        0.2 * (x * x + z * z),
                    ])
                } else {
                    Vec8::from_column_slice(&[x, y, z, 0.0, 0.0, 0.0, 0.0, 0.0])
                }
            })
            .collect();
        Projector::new(Arc::new(EmbeddedMesh::new(m, coords).unwrap())).unwrap()
    }

    /// Which faces Newton's method (unfiltered) finds a projection of `y` on.
    fn solvable(p: &Projector, y: &Vec8) -> Vec<bool> {
        (0..p.faces.len() as u32)
            .map(|f| p.try_face(f, y).is_some())
            .collect()
    }

    /// Whether any face under node `ni` is solvable.
    fn any_under(p: &Projector, ni: usize, ok: &[bool]) -> bool {
        match p.bvh.node(ni) {
            Err(items) => items.iter().any(|&f| ok[f as usize]),
            Ok((l, r)) => any_under(p, l, ok) || any_under(p, r, ok),
        }
    }

    /// Node boxes, by walking the search with a pass-through filter.
    fn boxes(p: &Projector, y: &Vec8) -> Vec<Option<([f32; 8], [f32; 8])>> {
        let out = std::cell::RefCell::new(vec![None; p.bvh.n_nodes()]);
        let mut bound = f64::INFINITY;
        p.bvh.search_pruned(
            y,
            &mut bound,
            |ni, lo, hi| {
                out.borrow_mut()[ni] = Some((*lo, *hi));
                true
            },
            |_, _| {},
        );
        out.into_inner()
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(48))]
        /// Neither test ever rejects a face (or a subtree holding a face) where Newton's
        /// method finds a projection: queries on the surface, near it and far away.
        #[test]
        fn exclusions_never_drop_a_projection(mesh in 0usize..4, curved in any::<bool>(), seed in 0u64..1_000_000) {
            let p = projector(mesh, curved);
            let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(seed);
            let emb = p.embedded().clone();
            let edge = emb.mean_edge_length();
            let (mut faces_excluded, mut nodes_excluded) = (0, 0);
            for off in [0.0, 0.05, 0.5, 3.0, 30.0] {
                let f = rng.random_range(0..emb.mesh().n_faces() as u32);
                let (a, b) = (rng.random::<f64>(), rng.random::<f64>());
                let (a, b) = if a + b > 1.0 { (1.0 - a, 1.0 - b) } else { (a, b) };
                let dir = Vec8::from_fn(|_, _| rng.random_range(-1.0..1.0)).normalize();
                let y = emb.point(&SurfacePoint::new(f, [a, b, 1.0 - a - b])) + dir * (off * edge);
                let ok = solvable(&p, &y);
                for (f, &ok) in ok.iter().enumerate() {
                    let face = &p.faces[f];
                    let r = face.v.map(|v| &p.verts[v as usize]);
                    let ex = face.d.excludes([&r[0].t, &r[1].t, &r[2].t], [&r[0].x, &r[1].x, &r[2].x], &y);
                    prop_assert!(!(ok && ex), "face {f} excluded but solvable, offset {off}");
                    faces_excluded += ex as usize;
                    // The filtered solve gives the same answer.
                    let filtered = p.try_face_filtered(f as u32, &y).map(|b| b.xi);
                    prop_assert_eq!(filtered, p.try_face(f as u32, &y).map(|b| b.xi));
                }
                for (ni, bx) in boxes(&p, &y).into_iter().enumerate() {
                    let (lo, hi) = bx.unwrap();
                    let ex = p.cones.excludes(ni, &lo, &hi, &y);
                    prop_assert!(!(ex && any_under(&p, ni, &ok)), "node {ni} excluded, offset {off}");
                    nodes_excluded += ex as usize;
                }
            }
            // The tests are not vacuous: far queries exclude most faces.
            prop_assert!(faces_excluded > 0 && nodes_excluded > 0);
        }
    }
}
