//! Tangent-cone bounds over the hierarchy: per node, a proof that no triangle under it
//! has a Phong projection of a query, so the global searches skip whole subtrees of
//! triangles that are near the query but "beside" it rather than under it.
//!
//! On a triangle the tangent equations read `F(xi) = Psi(xi) (p(xi) - y) = 0` with
//! `Psi(xi) = sum_e c_e(xi) B_e`, `B_e = X_e T_{i(e)}` (2x8) and convex weights `c_e`.
//! Rotating the equations by any orthogonal 2x2 `Q` changes neither their roots nor
//! `|F|`, so each triangle may be compared in its own gauge: each node stores a 2x8
//! matrix `M` and `eps`, `s` such that every triangle `f` under it has an orthogonal
//! `Q_f` with `||Q_f B_e - M|| <= eps` for its six terms and `||B_e||, ||T_i|| <= s`
//! (operator norms), so `||Q_f Psi(xi) - M|| <= eps` on the triangle; and a 2-D box `W`
//! holding `M (v - c)` for every corner `v` under the node (`c` the centre of the node's
//! box), so `M (p - c)` lies in `W` for every point `p` of its triangles. For a query
//! `y`, with `alpha` the distance from the origin to the box `W + M (c - y)` and `beta`
//! the largest distance from `y` to a point of the node's box, every point of every
//! triangle under the node has `|F| = |Q_f F| >= |M (p - y)| - eps |p - y| >=
//! alpha - eps beta`. Newton's method accepts only points of the triangle with
//! `|F|_inf <= CLAMP_RESIDUAL fscale`, and the system's scale is at most `2 s beta` (its
//! entries are `T_i (y - v_i)` and `B_e (v_k - v_i)`, corners in the box), so
//! `alpha > (eps + 3 CLAMP_RESIDUAL s) beta` (`3 > 2 sqrt(2)`, the rest covers f64
//! rounding) proves that no triangle under the node holds a projection. Stored bounds are
//! rounded outwards.

use super::*;
use crate::ort::{self, M2};
use crate::triangle::{CLAMP_RESIDUAL, TERM_VERTEX};

/// Nodes a search pops before it starts testing them: most searches end within a few
/// dozen nodes near the query, where the test rarely excludes anything; only the long
/// ones (no projection near the query) repay it.
pub(super) const CONE_AFTER: usize = 32;

/// Nodes a search pops without the bounds while they are not built: building them costs
/// about as much as a few thousand Newton solves per face of the mesh (515M instructions
/// on a 152k-face body), which a handful of global searches that end within this many
/// nodes never repay.
pub(super) const CONE_BUILD_AFTER: usize = 4096;

/// A search's node filter: after [`CONE_AFTER`] nodes, keeps only the nodes whose bound
/// does not exclude `y`. While the bounds are not built, a search goes on without them
/// up to [`CONE_BUILD_AFTER`] nodes, and the projector's searches up to as many nodes in
/// all as the hierarchy has; past either, the bounds are built. They only drop nodes that
/// hold no projection, so the search's answer is the same either way.
pub(super) fn keep_filter<'a>(
    p: &'a Projector,
    y: &'a Vec8,
) -> impl Fn(usize, &[f32; 8], &[f32; 8]) -> bool + 'a {
    let popped = std::cell::Cell::new(0usize);
    move |ni, lo, hi| {
        let n = popped.get() + 1;
        popped.set(n);
        if n <= CONE_AFTER {
            return true;
        }
        match p.cones.get() {
            Some(c) => !c.excludes(ni, lo, hi, y),
            None if n <= CONE_BUILD_AFTER && p.count_unfiltered() => true,
            None => !p.cones().excludes(ni, lo, hi, y),
        }
    }
}

/// One node's bound, 88 bytes.
#[derive(Clone, Copy, Debug, Default)]
struct Cone {
    /// The reference plane `M`, row-major.
    m: [f32; 16],
    /// `W`: per row of `M (v - c)`, its least and greatest value.
    w: [[f32; 2]; 2],
    /// `eps`: bounds `||Q_f B_e - M||` over the node's terms.
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

/// An interval rounded outwards to f32.
fn out32([l, u]: [f64; 2]) -> [f32; 2] {
    let pad = 1e-6 * (l.abs() + u.abs()) + 1e-30;
    [(l - pad) as f32, (u + pad) as f32]
}

/// Operator (spectral) norm of a 2x8 matrix: the root of the larger eigenvalue of `D D^T`.
fn op_norm(d: &[f64; 16]) -> f64 {
    let [a, b, _, e] = gram(d, d);
    let h = 0.5 * (a - e);
    (0.5 * (a + e) + (h * h + b * b).sqrt()).max(0.0).sqrt()
}

/// `||a - b||` (operator norm) of two 2x8 matrices, `a` stored as f32.
fn dist_op(a: &[f32; 16], b: &[f64; 16]) -> f64 {
    op_norm(&std::array::from_fn(|k| a[k] as f64 - b[k]))
}

/// Centre of a stored box (computed the same way at build and query time).
#[inline(always)]
fn centre(lo: &[f32; 8], hi: &[f32; 8]) -> [f64; 8] {
    std::array::from_fn(|k| 0.5 * (lo[k] as f64 + hi[k] as f64))
}

/// Per row, the range of `d x` over the box `x - c` with `x` in `[lo, hi]`.
fn box_range(d: &[f64; 16], lo: &[f32; 8], hi: &[f32; 8], c: &[f64; 8]) -> [[f64; 2]; 2] {
    let mut iv = [[0.0f64; 2]; 2];
    for (r, iv) in iv.iter_mut().enumerate() {
        for k in 0..8 {
            let (u, v) = (
                d[r * 8 + k] * (lo[k] as f64 - c[k]),
                d[r * 8 + k] * (hi[k] as f64 - c[k]),
            );
            iv[0] += u.min(v);
            iv[1] += u.max(v);
        }
    }
    iv
}

impl Cones {
    /// Computes the bounds bottom-up: leaves from their triangles' terms and corners,
    /// interior nodes from their children (`M` the mean of the children's in one gauge,
    /// `eps` by the triangle inequality, `W` by interval arithmetic).
    pub(super) fn new(bvh: &Bvh, faces: &[Face], verts: &[VertexRec]) -> Self {
        let mut cones = vec![Cone::default(); bvh.n_nodes()];
        if !cones.is_empty() {
            fill(bvh, &mut cones, 0, faces, verts);
        }
        Self(cones)
    }

    /// Heap bytes used.
    pub(super) fn bytes(&self) -> usize {
        std::mem::size_of_val(&self.0[..])
    }

    /// Whether no triangle under node `ni` (box `lo`, `hi`) can hold a projection of `y`
    /// (see the module documentation). A search that has popped fewer than
    /// [`CONE_AFTER`] nodes does not ask (see there).
    #[inline]
    pub(super) fn excludes(&self, ni: usize, lo: &[f32; 8], hi: &[f32; 8], y: &Vec8) -> bool {
        let c = &self.0[ni];
        let mid = centre(lo, hi);
        let mut my = [0.0f64; 2];
        let mut beta2 = 0.0;
        for k in 0..8 {
            let (a, b) = (lo[k] as f64 - y[k], hi[k] as f64 - y[k]);
            beta2 += (a * a).max(b * b);
            let t = mid[k] - y[k];
            my[0] += c.m[k] as f64 * t;
            my[1] += c.m[8 + k] as f64 * t;
        }
        let gap = |w: [f32; 2], t: f64| {
            let (l, u) = (w[0] as f64 + t, w[1] as f64 + t);
            if l > 0.0 {
                l
            } else if u < 0.0 {
                -u
            } else {
                0.0
            }
        };
        let (g0, g1) = (gap(c.w[0], my[0]), gap(c.w[1], my[1]));
        let alpha2 = g0 * g0 + g1 * g1;
        let k = (c.eps as f64 + 3.0 * CLAMP_RESIDUAL * c.s as f64) * (1.0 + 1e-9);
        alpha2 > k * k * beta2
    }
}

/// Subtrees of at least this many nodes are computed in parallel.
const PARALLEL: usize = 2048;

/// Computes the bounds of the subtree rooted at node `base` into `out` (its nodes, in
/// the hierarchy's depth-first order: the left subtree, then the right one).
fn fill(bvh: &Bvh, out: &mut [Cone], base: usize, faces: &[Face], verts: &[VertexRec]) {
    let (l, r) = match bvh.node(base) {
        Err(items) => {
            out[0] = leaf(items, bvh.node_box(base), faces, verts);
            return;
        }
        Ok(children) => children,
    };
    if l != base + 1 || r <= l || r - base >= out.len() {
        // Not the depth-first layout (not expected): a subtree bound that never excludes.
        out.fill(NEVER);
        return;
    }
    let (me, rest) = out.split_at_mut(1);
    let (left, right) = rest.split_at_mut(r - l);
    if me.len() + left.len() + right.len() >= PARALLEL {
        rayon::join(
            || fill(bvh, left, l, faces, verts),
            || fill(bvh, right, r, faces, verts),
        );
    } else {
        fill(bvh, left, l, faces, verts);
        fill(bvh, right, r, faces, verts);
    }
    me[0] = interior(
        [&left[0], &right[0]],
        [bvh.node_box(l), bvh.node_box(r)],
        bvh.node_box(base),
    );
}

/// A bound that never excludes.
const NEVER: Cone = Cone {
    m: [0.0; 16],
    w: [[f32::NEG_INFINITY, f32::INFINITY]; 2],
    eps: f32::INFINITY,
    s: f32::INFINITY,
};

/// An interior node's bound from its children's (`boxes`: theirs, `own`: the node's).
fn interior(
    ch: [&Cone; 2],
    boxes: [(&[f32; 8], &[f32; 8]); 2],
    own: (&[f32; 8], &[f32; 8]),
) -> Cone {
    let ma = ch[0].m.map(|v| v as f64);
    let mb = ch[1].m.map(|v| v as f64);
    // The right child's gauge turned to the left's (a child's bounds hold for any rotation
    // of its `M` and `W`).
    let rot = [ort::I2, ort::ort(&gram(&ma, &mb))];
    let turned = [ma, rotate(&rot[1], &mb)];
    let m: [f32; 16] = std::array::from_fn(|k| (0.5 * (turned[0][k] + turned[1][k])) as f32);
    let m64 = m.map(|v| v as f64);
    let c = centre(own.0, own.1);
    let mut eps: f64 = 0.0;
    let mut w = [[f64::INFINITY, f64::NEG_INFINITY]; 2];
    for i in 0..2 {
        eps = eps.max(ch[i].eps as f64 + dist_op(&m, &turned[i]));
        // For v under child i: M (v - c) = R W_i-point + R M_i (c_i - c) + (M - R M_i)(v - c).
        let ci = centre(boxes[i].0, boxes[i].1);
        let q = &rot[i];
        let d: [f64; 16] = std::array::from_fn(|k| m64[k] - turned[i][k]);
        let dr = box_range(&d, boxes[i].0, boxes[i].1, &c);
        for r in 0..2 {
            let mut lo = dr[r][0];
            let mut hi = dr[r][1];
            for (j, wj) in ch[i].w.iter().enumerate() {
                let (u, v) = (q[2 * r + j] * wj[0] as f64, q[2 * r + j] * wj[1] as f64);
                lo += u.min(v);
                hi += u.max(v);
            }
            let shift: f64 = (0..8).map(|k| turned[i][r * 8 + k] * (ci[k] - c[k])).sum();
            w[r][0] = w[r][0].min(lo + shift);
            w[r][1] = w[r][1].max(hi + shift);
        }
    }
    let cone = Cone {
        m,
        w: w.map(out32),
        eps: up32(eps),
        s: ch[0].s.max(ch[1].s),
    };
    if cone.w.iter().flatten().all(|v| v.is_finite()) && cone.eps.is_finite() {
        cone
    } else {
        NEVER
    }
}

/// A leaf's bound: `M` the mean of its terms `B_e`, each triangle in its own gauge.
fn leaf(items: &[u32], bx: (&[f32; 8], &[f32; 8]), faces: &[Face], verts: &[VertexRec]) -> Cone {
    if items.is_empty() || items.len() > LEAF_MAX {
        // Not expected (leaves are small).
        return NEVER;
    }
    // `||B_e|| <= ||X_e||_F ||T_i||_F`.
    let frob = |v: &[f32]| v.iter().map(|&x| x as f64 * x as f64).sum::<f64>().sqrt();
    let mut s: f64 = 0.0;
    let mut means = [[0.0f64; 16]; LEAF_MAX];
    for (&f, mean) in items.iter().zip(&mut means) {
        let face = &faces[f as usize];
        let (mut xs, mut ts): (f64, f64) = (0.0, 0.0);
        for e in 0..6 {
            xs = xs.max(frob(&face.d.x[e]));
            let b = term(face, e, verts);
            for k in 0..16 {
                mean[k] += b[k] / 6.0;
            }
        }
        for v in face.v {
            ts = ts.max(frob(&verts[v as usize].t));
        }
        s = s.max(xs * ts);
    }
    let n = items.len();
    // Each triangle's terms turned (as one) to the gauge of the first triangle's mean.
    let mut gauges = [ort::I2; LEAF_MAX];
    let mut total = [0.0f64; 16];
    for (mean, q) in means[..n].iter().zip(&mut gauges) {
        *q = ort::ort(&gram(&means[0], mean));
        let t = rotate(q, mean);
        for k in 0..16 {
            total[k] += t[k] / n as f64;
        }
    }
    let m = total.map(|v| v as f32);
    let mut eps: f64 = 0.0;
    for (&f, q) in items.iter().zip(&gauges) {
        let face = &faces[f as usize];
        for e in 0..6 {
            eps = eps.max(dist_op(&m, &rotate(q, &term(face, e, verts))));
        }
    }
    let c = centre(bx.0, bx.1);
    let mut w = [[f64::INFINITY, f64::NEG_INFINITY]; 2];
    for &f in items {
        for v in faces[f as usize].v {
            let x = &verts[v as usize].x;
            for (r, w) in w.iter_mut().enumerate() {
                let t: f64 = (0..8).map(|k| m[r * 8 + k] as f64 * (x[k] - c[k])).sum();
                w[0] = w[0].min(t);
                w[1] = w[1].max(t);
            }
        }
    }
    let cone = Cone {
        m,
        w: w.map(out32),
        eps: up32(eps),
        s: up32(s),
    };
    if cone.w.iter().flatten().all(|v| v.is_finite()) && cone.eps.is_finite() {
        cone
    } else {
        NEVER
    }
}

/// The term `B_e = X_e T_{i(e)}` of a face (2x8, row-major).
#[inline]
fn term(face: &Face, e: usize, verts: &[VertexRec]) -> [f64; 16] {
    let x = face.d.x[e].map(|v| v as f64);
    let t = &verts[face.v[TERM_VERTEX[e]] as usize].t;
    std::array::from_fn(|k| {
        let col = k % 8;
        let (t0, t1) = (t[col] as f64, t[8 + col] as f64);
        if k < 8 {
            x[0] * t0 + x[1] * t1
        } else {
            x[2] * t0 + x[3] * t1
        }
    })
}

/// Triangles a leaf's bound is computed from directly.
const LEAF_MAX: usize = 8;

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
            4 => procedural::icosphere(4),
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

    /// `got` is the brute force's answer for `y`, up to rounding and ties.
    fn same_as_brute_force(p: &Projector, y: &Vec8, got: Result<Projection, ProjectError>) {
        match (got, p.project_brute_force(y)) {
            (Ok(a), Ok(b)) => assert!(
                (a.distance - b.distance).abs() <= 1e-9 * (1.0 + b.distance),
                "{a:?} {b:?}"
            ),
            (a, b) => assert_eq!(a, b),
        }
    }

    /// Global searches answer the same before the bounds are built (searches that end
    /// soon go without them) and after, as the brute force does; queries near the surface
    /// alone do not build them.
    #[test]
    fn global_searches_agree_with_and_without_the_bounds() {
        let (lazy, eager) = (projector(4, true), projector(4, true));
        let _ = eager.cones();
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(5);
        let emb = lazy.embedded().clone();
        let edge = emb.mean_edge_length();
        let mut query = |off: f64| {
            let f = rng.random_range(0..emb.mesh().n_faces() as u32);
            let (a, b) = (rng.random::<f64>(), rng.random::<f64>());
            let (a, b) = if a + b > 1.0 {
                (1.0 - a, 1.0 - b)
            } else {
                (a, b)
            };
            let dir = Vec8::from_fn(|_, _| rng.random_range(-1.0..1.0)).normalize();
            emb.point(&SurfacePoint::new(f, [a, b, 1.0 - a - b])) + dir * (off * edge)
        };
        for k in 0..20 {
            let y = query([0.0, 0.05][k % 2]);
            let got = lazy.project_exhaustive(&y);
            assert_eq!(got, eager.project_exhaustive(&y));
            if k % 4 == 0 {
                same_as_brute_force(&lazy, &y, got);
            }
        }
        assert!(lazy.cones.get().is_none(), "built for near queries");
        for k in 0..60 {
            let y = query([0.5, 3.0, 30.0][k % 3]);
            let got = lazy.project_exhaustive(&y);
            assert_eq!(got, eager.project_exhaustive(&y));
            if k % 4 == 0 {
                same_as_brute_force(&lazy, &y, got);
            }
        }
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
                    let ex = p.cones().excludes(ni, &lo, &hi, &y);
                    prop_assert!(!(ex && any_under(&p, ni, &ok)), "node {ni} excluded, offset {off}");
                    nodes_excluded += ex as usize;
                }
            }
            // The tests are not vacuous: far queries exclude most faces.
            prop_assert!(faces_excluded > 0 && nodes_excluded > 0);
        }
    }
}
