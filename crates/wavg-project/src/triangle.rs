//! Per-triangle data: edge alignments `R`, in-plane rotations `E`, the interpolated
//! tangent planes `Psi(xi)` with their analytic derivatives, and Newton's method for the
//! Phong projection onto one triangle.
//!
//! `Psi(xi) = sum_e c_e(xi) X_e T_{i(e)}` over six terms `e`: for each edge `k = (i, i+1)`
//! the term `2k` is `c_first E_k R_k T_i` and the term `2k+1` is `c_second E_k T_{i+1}`
//! (the paper's Section 3.2; `R_k = Ort(T_{i+1} T_i^T)`). Each triangle stores the six 2x2
//! matrices `X_e` and, for the Newton solve, `G_e = X_e T_i (v_k - v_i)` for the two other
//! corners `k`: with `h_i = T_i (y - v_i)` the tangent equations become
//! `F(xi) = sum_e c_e(xi) (sum_k xi_k G_ek - X_e h_i) = Psi(xi) (p(xi) - y)`, a 2-D
//! computation per Newton step. Everything is relative to the triangle's corners, so the
//! results do not depend on where the mesh is or on its scale. Stored as f32; evaluated in
//! f64.

use crate::ort::{self, M2};
use crate::{Mat2x8, Vec8};

mod exclude;

/// Corner whose frame term `e` multiplies.
pub(crate) const TERM_VERTEX: [usize; 6] = [0, 1, 1, 2, 2, 0];

/// Block coordinate descent sweeps for the in-plane rotations.
pub(crate) const PROCRUSTES_SWEEPS: usize = 10;

/// Maximum Newton iterations per triangle.
pub(crate) const MAX_NEWTON: usize = 16;

/// Barycentric tolerance of a valid projection: a projection up to this far outside its
/// triangle (in barycentric coordinates) is accepted and clamped onto the edge.
pub const BARY_EPS: f64 = 1e-4;

/// Largest residual `|F|_inf`, relative to the system's scale, at the iterate inside the
/// triangle from which Newton's method accepts a root up to [`BARY_EPS`] outside it
/// (clamped onto the edge). Every accepted projection therefore has a point of the closed
/// triangle where `|F|_inf <= CLAMP_RESIDUAL * fscale`, which is what the exclusion tests
/// ([`TriData::solve_unless_excluded`], the hierarchy's cone bounds) rule out.
pub(crate) const CLAMP_RESIDUAL: f64 = 1e-2;

/// `S` below which a point counts as a vertex and `Psi` takes its limit there.
const S_MIN: f64 = 1e-12;

/// A tangent frame stored compactly: rows 0 and 1, eight f32 each.
pub(crate) type Frame32 = [f32; 16];

/// Converts a frame to f32 storage.
pub(crate) fn frame_to_f32(t: &Mat2x8) -> Frame32 {
    let mut f = [0f32; 16];
    for r in 0..2 {
        for c in 0..8 {
            f[r * 8 + c] = t[(r, c)] as f32;
        }
    }
    f
}

/// The f64 frame of a stored one.
pub(crate) fn frame_to_f64(f: &Frame32) -> Mat2x8 {
    Mat2x8::from_fn(|r, c| f[r * 8 + c] as f64)
}

/// Precomputed data of one triangle: the six 2x2 blend matrices `X_e` (row-major), 96
/// bytes. The tangent coordinates of the corners are recomputed per query from the
/// (stored) frames and the (f64) corners, so a point on the triangle satisfies the
/// tangent equations to f64 rounding: the f32 storage perturbs `Psi`, never the
/// zero of `p(xi) - y`.
#[derive(Clone, Copy, Debug, Default)]
#[repr(C, align(32))]
pub(crate) struct TriData {
    /// The six 2x2 blend matrices `X_e` (row-major).
    pub x: [[f32; 4]; 6],
}

/// Gram blocks `T_i T_j^T` of the three corner frames (`[C01, C12, C20]`).
#[cfg(test)]
fn frame_products(t: &[Mat2x8; 3]) -> [M2; 3] {
    [0, 1, 2].map(|i| {
        let (a, b) = (&t[i], &t[(i + 1) % 3]);
        let mut m = [0.0; 4];
        for r in 0..2 {
            for c in 0..2 {
                m[r * 2 + c] = a.row(r).dot(&b.row(c));
            }
        }
        m
    })
}

/// [`frame_products`] from stored frames.
fn frame_products32(t: &[&Frame32; 3]) -> [M2; 3] {
    [0, 1, 2].map(|i| {
        let (a, b) = (t[i], t[(i + 1) % 3]);
        let mut m = [0.0; 4];
        for r in 0..2 {
            for c in 0..2 {
                let mut s = 0.0;
                for k in 0..8 {
                    s += a[r * 8 + k] as f64 * b[c * 8 + k] as f64;
                }
                m[r * 2 + c] = s;
            }
        }
        m
    })
}

/// Everything the Procrustes step needs, in 2x2 blocks: the six un-rotated bases are
/// `Q_a T_{corner(a)}` with `Q = [R_0, I, R_1, I, R_2, I]`, so their Gram blocks are
/// `Q_a (T_i T_j^T) Q_b^T` and need only the three frame products `c`.
struct Procrustes {
    r: [M2; 3],
    q: [M2; 6],
    c: [M2; 3],
}

const CORNER: [usize; 6] = [0, 1, 1, 2, 2, 0];

impl Procrustes {
    #[cfg(test)]
    fn new(t: &[Mat2x8; 3]) -> Self {
        Self::from_products(frame_products(t))
    }

    fn from_products(c: [M2; 3]) -> Self {
        let mut s = Self {
            r: [ort::I2; 3],
            q: [ort::I2; 6],
            c,
        };
        // R_k = Ort(T_{k+1} T_k^T).
        s.r = [0, 1, 2].map(|k| ort::ort(&s.cross((k + 1) % 3, k)));
        s.q = [s.r[0], ort::I2, s.r[1], ort::I2, s.r[2], ort::I2];
        s
    }

    /// `T_i T_j^T`; frames are orthonormal so `T_i T_i^T = I`.
    #[inline]
    fn cross(&self, i: usize, j: usize) -> M2 {
        if i == j {
            ort::I2
        } else if (i + 1) % 3 == j {
            self.c[i]
        } else {
            ort::transpose(&self.c[j])
        }
    }

    /// Gram block `B_a B_b^T` of two un-rotated bases.
    #[inline]
    fn gram(&self, a: usize, b: usize) -> M2 {
        let m = ort::mul(&self.q[a], &self.cross(CORNER[a], CORNER[b]));
        ort::mul(&m, &ort::transpose(&self.q[b]))
    }

    /// Block coordinate descent from identities; returns `E` after `sweeps` sweeps.
    #[cfg(test)]
    fn rotations(&self, sweeps: usize) -> [M2; 3] {
        rotations_batch([self], sweeps)[0]
    }

    /// `h[j][k]`: the sum of the Gram blocks `G_ab` over `a` in pair `j`, `b` in pair `k`
    /// (`j != k`; `h[k][j] = h[j][k]^T`).
    fn pair_sums(&self) -> [[M2; 3]; 3] {
        let mut h = [[[0.0; 4]; 3]; 3];
        for (j, k) in [(0, 1), (0, 2), (1, 2)] {
            let mut m = [0.0; 4];
            for a in [2 * j, 2 * j + 1] {
                for b in [2 * k, 2 * k + 1] {
                    m = ort::add(&m, &self.gram(a, b));
                }
            }
            h[j][k] = m;
            h[k][j] = ort::transpose(&m);
        }
        h
    }

    /// `sum_{a<b} |A_a - A_b|^2` with `A_a = E_{pair(a)} B_a`.
    #[cfg(test)]
    fn energy(&self, e: &[M2; 3]) -> f64 {
        let mut s = 0.0;
        for a in 0..6 {
            for b in (a + 1)..6 {
                let (gaa, gbb) = (self.gram(a, a), self.gram(b, b));
                let cross = ort::mul(
                    &ort::mul(&e[a / 2], &self.gram(a, b)),
                    &ort::transpose(&e[b / 2]),
                );
                s += gaa[0] + gaa[3] + gbb[0] + gbb[3] - 2.0 * (cross[0] + cross[3]);
            }
        }
        s
    }
}

/// [`Procrustes::rotations`] for `N` independent triangles at once: the sweeps are a
/// chain of dependent square roots and divisions, interleaving triangles hides latency.
fn rotations_batch<const N: usize>(ps: [&Procrustes; N], sweeps: usize) -> [[M2; 3]; N] {
    let h: [[[M2; 3]; 3]; N] = std::array::from_fn(|n| ps[n].pair_sums());
    let mut e = [[ort::I2; 3]; N];
    for _ in 0..sweeps {
        for k in 0..3 {
            let (j1, j2) = ((k + 1) % 3, (k + 2) % 3);
            for n in 0..N {
                let m = ort::add(
                    &ort::mul(&e[n][j1], &h[n][j1][k]),
                    &ort::mul(&e[n][j2], &h[n][j2][k]),
                );
                e[n][k] = ort::ort(&m);
            }
        }
    }
    e
}

/// The Procrustes energy after 0, 1, ..., [`PROCRUSTES_SWEEPS`] sweeps (non-increasing;
/// for tests and diagnostics).
#[cfg(test)]
fn procrustes_energies(t: &[Mat2x8; 3]) -> [f64; PROCRUSTES_SWEEPS + 1] {
    let p = Procrustes::new(t);
    std::array::from_fn(|s| p.energy(&p.rotations(s)))
}

fn from_m2(m: &M2) -> nalgebra::Matrix2<f64> {
    nalgebra::Matrix2::new(m[0], m[1], m[2], m[3])
}

impl TriData {
    /// Precomputes a triangle from its stored corner frames and embedded corners.
    pub(crate) fn new(frames: [&Frame32; 3]) -> Self {
        Self::new_batch([frames])[0]
    }

    /// [`TriData::new`] for `N` triangles at once (their rotations interleaved, see
    /// `rotations_batch`).
    pub(crate) fn new_batch<const N: usize>(frames: [[&Frame32; 3]; N]) -> [Self; N] {
        let ps: [Procrustes; N] =
            std::array::from_fn(|n| Procrustes::from_products(frame_products32(&frames[n])));
        let es: [[M2; 3]; N] =
            rotations_batch::<N>(std::array::from_fn(|n| &ps[n]), PROCRUSTES_SWEEPS);
        std::array::from_fn(|n| {
            let (r, e) = (&ps[n].r, &es[n]);
            let mut d = TriData::default();
            for k in 0..3 {
                let a = ort::mul(&e[k], &r[k]);
                d.x[2 * k] = a.map(|v| v as f32);
                d.x[2 * k + 1] = e[k].map(|v| v as f32);
            }
            d
        })
    }

    /// `Psi(xi)` for corner frames `frames` (2x8; rows span the interpolated tangent plane).
    pub(crate) fn psi(&self, frames: [&Frame32; 3], xi: &[f64; 3]) -> Mat2x8 {
        let (c, _) = coefficients(xi);
        // Two terms share each corner's frame: sum their weighted blends first, then one
        // 2x2-by-2x8 product per corner.
        let mut b = [[0.0f64; 4]; 3];
        for (e, &ce) in c.iter().enumerate() {
            let i = TERM_VERTEX[e];
            for k in 0..4 {
                b[i][k] += ce * self.x[e][k] as f64;
            }
        }
        let mut m = Mat2x8::zeros();
        for (i, f) in frames.iter().enumerate() {
            let b = &b[i];
            for col in 0..8 {
                let (t0, t1) = (f[col] as f64, f[8 + col] as f64);
                m[(0, col)] += b[0] * t0 + b[1] * t1;
                m[(1, col)] += b[2] * t0 + b[3] * t1;
            }
        }
        m
    }

    /// The partial derivatives `dPsi/dxi_k`, `k = 0, 1, 2`, treating the three barycentrics
    /// as independent (on the plane `sum xi = 1` take differences). At a vertex, where
    /// `Psi` is not differentiable, the derivative just inside the triangle is returned.
    pub(crate) fn psi_derivatives(&self, frames: [&Frame32; 3], xi: &[f64; 3]) -> [Mat2x8; 3] {
        let (_, dc) = coefficients(xi);
        let mut out = [Mat2x8::zeros(); 3];
        for (e, dce) in dc.iter().enumerate() {
            let b = from_m2(&self.x[e].map(|v| v as f64)) * frame_to_f64(frames[TERM_VERTEX[e]]);
            for k in 0..3 {
                out[k] += b * dce[k];
            }
        }
        out
    }

    /// Newton's method for `Psi(xi) (p(xi) - y) = 0`, `sum xi = 1`, from the centroid,
    /// kept inside the triangle (`frames` and `corners` are the triangle's): the
    /// barycentrics of a projection, or on failure which way the root lies when Newton was
    /// pushed against an edge: `Err(Some(k))` when it left across the edge opposite corner
    /// `k` (where a search continues), `Err(None)` otherwise. For an example through a
    /// projector (which holds the frames), see
    /// [`Projector::project_onto_face_or_exit`](crate::Projector::project_onto_face_or_exit).
    #[inline]
    pub(crate) fn solve_or_exit(
        &self,
        frames: [&Frame32; 3],
        corners: [&Vec8; 3],
        y: &Vec8,
    ) -> Result<[f64; 3], Option<usize>> {
        System::new(self, frames, corners, y).newton()
    }
}

impl System {
    /// Newton's method on this system (see [`TriData::solve_or_exit`]).
    #[inline(always)]
    fn newton(&self) -> Result<[f64; 3], Option<usize>> {
        let sys = self;
        let ftol = 1e-11 * sys.fscale;
        let mut xi = sys.initial_guess();
        let mut stuck = 0;
        for _ in 0..MAX_NEWTON {
            let (f, j) = sys.eval(&xi);
            if f[0].abs().max(f[1].abs()) <= ftol {
                return Ok(xi);
            }
            let det = j[0] * j[3] - j[1] * j[2];
            let jn = j[0].abs().max(j[1].abs()).max(j[2].abs()).max(j[3].abs());
            if !(det.abs() > 1e-14 * jn * jn) {
                return Err(None);
            }
            let inv = 1.0 / det;
            let d0 = (j[1] * f[1] - j[3] * f[0]) * inv;
            let d1 = (j[2] * f[0] - j[0] * f[1]) * inv;
            let d = [d0, d1, -d0 - d1];
            // Largest step along d that stays in the triangle.
            let (mut t, mut block): (f64, Option<usize>) = (1.0, None);
            for k in 0..3 {
                if xi[k] + d[k] < 0.0 && xi[k] / -d[k] < t {
                    (t, block) = (xi[k] / -d[k], Some(k));
                }
            }
            if t < 1.0
                && d[0].abs().max(d[1].abs()).max(d[2].abs()) <= BARY_EPS
                && f[0].abs().max(f[1].abs()) <= CLAMP_RESIDUAL * sys.fscale
            {
                // The root is within BARY_EPS outside the triangle (on an edge, up to the
                // rounding of the f32 data): a valid projection, clamped onto the triangle.
                return renormalize([xi[0] + d[0], xi[1] + d[1], xi[2] + d[2]]).ok_or(None);
            }
            if t < 1e-9 {
                // On the boundary and pushing out: slide (clamp the full step). Pushing out
                // by more than BARY_EPS twice in a row means the root is outside; by less,
                // the root lies on this edge (up to rounding) and sliding converges to it.
                if block.is_some_and(|k| -d[k] > BARY_EPS) {
                    stuck += 1;
                    if stuck >= 2 {
                        return Err(block);
                    }
                }
                xi = renormalize([xi[0] + d[0], xi[1] + d[1], xi[2] + d[2]]).ok_or(None)?;
            } else {
                stuck = 0;
                xi = renormalize([xi[0] + t * d[0], xi[1] + t * d[1], xi[2] + t * d[2]])
                    .ok_or(None)?;
                if (t * d0).abs().max((t * d1).abs()) < 1e-13 {
                    let (f, _) = sys.eval(&xi);
                    return if f[0].abs().max(f[1].abs()) <= 1e-8 * sys.fscale {
                        Ok(xi)
                    } else {
                        Err(None)
                    };
                }
            }
        }
        Err(None)
    }
}

/// One triangle's tangent equations for one query, in f64.
struct System {
    /// `G_e`, two 2-vectors per term.
    g: [[f64; 4]; 6],
    /// `q_e = X_e h_{i(e)}`.
    q: [[f64; 2]; 6],
    /// Size of the triangle plus distance of the query: the scale of `F`.
    fscale: f64,
}

impl System {
    #[inline(always)]
    fn new(d: &TriData, frames: [&Frame32; 3], corners: [&Vec8; 3], y: &Vec8) -> Self {
        // a[i][j]: T_i (v_{i+1+j} - v_i); h[i] = T_i (y - v_i). The six corner differences
        // are three edges `e_i = v_{i+1} - v_i` and their negations (exact in floating
        // point): `v_{i+2} - v_i = -e_{i+2}`.
        let mut a = [[[0.0f64; 2]; 2]; 3];
        let mut h = [[0.0f64; 2]; 3];
        let yv: &[f64; 8] = &y.data.0[0];
        let cv = [
            &corners[0].data.0[0],
            &corners[1].data.0[0],
            &corners[2].data.0[0],
        ];
        let edge = [0, 1, 2].map(|i| {
            let (p, q) = (cv[i], cv[(i + 1) % 3]);
            std::array::from_fn::<f64, 8, _>(|c| q[c] - p[c])
        });
        for i in 0..3 {
            let f = frames[i];
            let (e1, e2) = (&edge[i], &edge[(i + 2) % 3]);
            let mut acc = [0.0f64; 6];
            for c in 0..8 {
                let (t0, t1) = (f[c] as f64, f[8 + c] as f64);
                let dy = yv[c] - cv[i][c];
                acc[0] += t0 * e1[c];
                acc[1] += t1 * e1[c];
                acc[2] += t0 * e2[c];
                acc[3] += t1 * e2[c];
                acc[4] += t0 * dy;
                acc[5] += t1 * dy;
            }
            a[i] = [[acc[0], acc[1]], [-acc[2], -acc[3]]];
            h[i] = [acc[4], acc[5]];
        }
        let mut q = [[0.0f64; 2]; 6];
        let mut g = [[0.0f64; 4]; 6];
        let mut m: f64 = 0.0;
        for e in 0..6 {
            let x = d.x[e];
            let x = [x[0] as f64, x[1] as f64, x[2] as f64, x[3] as f64];
            let i = TERM_VERTEX[e];
            let mv = |v: &[f64; 2]| [x[0] * v[0] + x[1] * v[1], x[2] * v[0] + x[3] * v[1]];
            q[e] = mv(&h[i]);
            let (g1, g2) = (mv(&a[i][0]), mv(&a[i][1]));
            g[e] = [g1[0], g1[1], g2[0], g2[1]];
            for k in 0..4 {
                let v = g[e][k].abs();
                if v > m {
                    m = v;
                }
            }
        }
        for hi in &h {
            for &v in hi {
                if v.abs() > m {
                    m = v.abs();
                }
            }
        }
        Self { g, q, fscale: m }
    }

    /// Start of the Newton iteration: the root of the tangent equations with the blend
    /// frozen at the centroid (linear in `xi`), clamped into the triangle. Exact for a
    /// point on the triangle (every term vanishes there), so such queries converge at once.
    #[inline(always)]
    fn initial_guess(&self) -> [f64; 3] {
        let g = &self.g;
        let q = &self.q;
        let c = 1.0 / 3.0;
        let mut f = [0.0; 2];
        let mut ju = [0.0; 2];
        let mut jv = [0.0; 2];
        for r in 0..2 {
            let mut s = -(q[0][r] + q[1][r] + q[2][r] + q[3][r] + q[4][r] + q[5][r]);
            for e in 0..6 {
                s += c * (g[e][r] + g[e][2 + r]);
            }
            f[r] = s;
            ju[r] =
                -g[0][2 + r] + g[1][2 + r] - g[1][r] + g[2][2 + r] - g[2][r] + g[3][r] + g[4][r]
                    - g[5][2 + r];
            jv[r] = g[0][r] - g[0][2 + r] - g[1][r] - g[2][r] + g[3][2 + r] + g[4][2 + r] + g[5][r]
                - g[5][2 + r];
        }
        let det = ju[0] * jv[1] - jv[0] * ju[1];
        let jn = ju[0]
            .abs()
            .max(ju[1].abs())
            .max(jv[0].abs())
            .max(jv[1].abs());
        if !(det.abs() > 1e-12 * jn * jn) {
            return [c; 3];
        }
        let inv = 1.0 / det;
        let du = (jv[0] * f[1] - jv[1] * f[0]) * inv;
        let dv = (ju[1] * f[0] - ju[0] * f[1]) * inv;
        renormalize([c + du, c + dv, c - du - dv]).unwrap_or([c; 3])
    }

    /// `F(xi)` and its Jacobian with respect to `(xi_0, xi_1)` (`xi_2 = 1 - xi_0 - xi_1`),
    /// row-major.
    #[inline(always)]
    fn eval(&self, x: &[f64; 3]) -> ([f64; 2], [f64; 4]) {
        let (c, dc) = coefficients_reduced(x);
        let g = &self.g;
        let q = &self.q;
        // z_e = x_{i+1} G_e,a + x_{i+2} G_e,b - q_e and its (u, v) derivatives.
        let (x0, x1, x2) = (x[0], x[1], x[2]);
        let mut f = [0.0; 2];
        let mut ju = [0.0; 2];
        let mut jv = [0.0; 2];
        for r in 0..2 {
            let z = [
                x1 * g[0][r] + x2 * g[0][2 + r] - q[0][r],
                x2 * g[1][r] + x0 * g[1][2 + r] - q[1][r],
                x2 * g[2][r] + x0 * g[2][2 + r] - q[2][r],
                x0 * g[3][r] + x1 * g[3][2 + r] - q[3][r],
                x0 * g[4][r] + x1 * g[4][2 + r] - q[4][r],
                x1 * g[5][r] + x2 * g[5][2 + r] - q[5][r],
            ];
            let zu = [
                -g[0][2 + r],
                g[1][2 + r] - g[1][r],
                g[2][2 + r] - g[2][r],
                g[3][r],
                g[4][r],
                -g[5][2 + r],
            ];
            let zv = [
                g[0][r] - g[0][2 + r],
                -g[1][r],
                -g[2][r],
                g[3][2 + r],
                g[4][2 + r],
                g[5][r] - g[5][2 + r],
            ];
            let mut fr = 0.0;
            let mut ur = 0.0;
            let mut vr = 0.0;
            for e in 0..6 {
                fr += c[e] * z[e];
                ur += dc[e][0] * z[e] + c[e] * zu[e];
                vr += dc[e][1] * z[e] + c[e] * zv[e];
            }
            f[r] = fr;
            ju[r] = ur;
            jv[r] = vr;
        }
        (f, [ju[0], jv[0], ju[1], jv[1]])
    }
}

/// [`coefficients`] with derivatives along `(xi_0, xi_1)` on the plane `sum xi = 1`
/// (`d/du = d/dxi_0 - d/dxi_2`, `d/dv = d/dxi_1 - d/dxi_2`), computed directly: Newton's
/// method needs only these two, once per iteration.
#[inline(always)]
fn coefficients_reduced(x: &[f64; 3]) -> ([f64; 6], [[f64; 2]; 6]) {
    let s = x[0] * x[1] + x[1] * x[2] + x[2] * x[0];
    if s >= S_MIN {
        return reduced_regular(x, s);
    }
    reduced_at_vertex(x)
}

/// [`coefficients_reduced`] at a vertex, as in `coefficients`: the limit values, the
/// derivatives just inside.
#[cold]
#[inline(never)]
fn reduced_at_vertex(x: &[f64; 3]) -> ([f64; 6], [[f64; 2]; 6]) {
    let v = corner_of(x);
    let inner = x.map(|x| (1.0 - 1e-6) * x + 1e-6 / 3.0);
    let si = inner[0] * inner[1] + inner[1] * inner[2] + inner[2] * inner[0];
    let (_, dc) = reduced_regular(&inner, si);
    (vertex_limit(v), dc)
}

/// The corner a point with `S` ~ 0 sits at: its largest barycentric.
#[inline(always)]
fn corner_of(xi: &[f64; 3]) -> usize {
    if xi[0] >= xi[1] && xi[0] >= xi[2] {
        0
    } else if xi[1] >= xi[2] {
        1
    } else {
        2
    }
}

/// The coefficients' limit at corner `v`: half on each of its two terms (the first of
/// edge `v`, the second of edge `v - 1`), so `Psi` spans the corner's frame.
#[inline(always)]
fn vertex_limit(v: usize) -> [f64; 6] {
    let mut c = [0.0; 6];
    c[2 * v] = 0.5;
    c[2 * ((v + 2) % 3) + 1] = 0.5;
    c
}

/// [`coefficients_reduced`] away from the corners. With `a = xi_k`, `b = xi_l` the
/// numerators are `n1 = a^2 b + P/2`, `n2 = a b^2 + P/2`; their reduced derivatives add
/// `dP/2` to the terms of `a` and `b` along `u` and `v`, and `c' = (n' - c S') / S`.
#[inline(always)]
fn reduced_regular(x: &[f64; 3], s: f64) -> ([f64; 6], [[f64; 2]; 6]) {
    let (x0, x1, x2) = (x[0], x[1], x[2]);
    let inv = 1.0 / s;
    let hp = 0.5 * (x0 * x1 * x2);
    let (hpu, hpv) = (0.5 * (x1 * (x2 - x0)), 0.5 * (x0 * (x2 - x1)));
    let (su, sv) = (x2 - x0, x2 - x1);
    let mut c = [0.0; 6];
    let mut dc = [[0.0; 2]; 6];
    let mut term = |e: usize, n: f64, nu: f64, nv: f64| {
        let ce = n * inv;
        c[e] = ce;
        dc[e] = [(nu - ce * su) * inv, (nv - ce * sv) * inv];
    };
    // k = 0: a = xi_0 (along u), b = xi_1 (along v).
    let (a, b) = (x0, x1);
    let (ab2, aa, bb) = (2.0 * a * b, a * a, b * b);
    term(0, aa * b + hp, hpu + ab2, hpv + aa);
    term(1, a * bb + hp, hpu + bb, hpv + ab2);
    // k = 1: a = xi_1 (along v), b = xi_2 (against both).
    let (a, b) = (x1, x2);
    let (ab2, aa, bb) = (2.0 * a * b, a * a, b * b);
    term(2, aa * b + hp, hpu - aa, hpv + (ab2 - aa));
    term(3, a * bb + hp, hpu - ab2, hpv + (bb - ab2));
    // k = 2: a = xi_2 (against both), b = xi_0 (along u).
    let (a, b) = (x2, x0);
    let (ab2, aa, bb) = (2.0 * a * b, a * a, b * b);
    term(4, aa * b + hp, hpu + (aa - ab2), hpv - ab2);
    term(5, a * bb + hp, hpu + (ab2 - bb), hpv - bb);
    (c, dc)
}

/// Clamps negative barycentrics to zero and rescales to sum 1 (`None` if nothing is left).
#[inline(always)]
fn renormalize(n: [f64; 3]) -> Option<[f64; 3]> {
    let a = if n[0] > 0.0 { n[0] } else { 0.0 };
    let b = if n[1] > 0.0 { n[1] } else { 0.0 };
    let c = if n[2] > 0.0 { n[2] } else { 0.0 };
    let s = a + b + c;
    if !(s > 0.0) || !s.is_finite() {
        return None;
    }
    let inv = 1.0 / s;
    Some([a * inv, b * inv, c * inv])
}

/// Blend coefficients `c_e(xi)` of the six terms and their partial derivatives.
///
/// `c_{2k} = (xi_k^2 xi_l + P/2) / S`, `c_{2k+1} = (xi_k xi_l^2 + P/2) / S` with
/// `l = k + 1`, `P = xi_0 xi_1 xi_2`, `S = xi_0 xi_1 + xi_1 xi_2 + xi_2 xi_0`; they sum to 1.
/// At a vertex (`S` ~ 0) the values take the symmetric limit (half on each of the two
/// terms of that corner, so `Psi` spans the corner's frame) and the derivatives are those
/// at a point just inside, so nothing divides by zero.
#[inline(always)]
pub(crate) fn coefficients(xi: &[f64; 3]) -> ([f64; 6], [[f64; 3]; 6]) {
    let s = xi[0] * xi[1] + xi[1] * xi[2] + xi[2] * xi[0];
    if s >= S_MIN {
        return coefficients_regular(xi, s);
    }
    let v = corner_of(xi);
    let inner = xi.map(|x| (1.0 - 1e-6) * x + 1e-6 / 3.0);
    let si = inner[0] * inner[1] + inner[1] * inner[2] + inner[2] * inner[0];
    let (_, dc) = coefficients_regular(&inner, si);
    (vertex_limit(v), dc)
}

#[inline(always)]
fn coefficients_regular(xi: &[f64; 3], s: f64) -> ([f64; 6], [[f64; 3]; 6]) {
    let p = xi[0] * xi[1] * xi[2];
    let dp = [xi[1] * xi[2], xi[0] * xi[2], xi[0] * xi[1]];
    let ds = [xi[1] + xi[2], xi[0] + xi[2], xi[0] + xi[1]];
    let inv = 1.0 / s;
    let mut c = [0.0; 6];
    let mut dc = [[0.0; 3]; 6];
    for k in 0..3 {
        let l = (k + 1) % 3;
        let (a, b) = (xi[k], xi[l]);
        // first: a^2 b + P/2
        let n1 = a * a * b + 0.5 * p;
        let mut dn1 = [0.5 * dp[0], 0.5 * dp[1], 0.5 * dp[2]];
        dn1[k] += 2.0 * a * b;
        dn1[l] += a * a;
        // second: a b^2 + P/2
        let n2 = a * b * b + 0.5 * p;
        let mut dn2 = [0.5 * dp[0], 0.5 * dp[1], 0.5 * dp[2]];
        dn2[k] += b * b;
        dn2[l] += 2.0 * a * b;
        let c1 = n1 * inv;
        let c2 = n2 * inv;
        c[2 * k] = c1;
        c[2 * k + 1] = c2;
        for m in 0..3 {
            dc[2 * k][m] = (dn1[m] - c1 * ds[m]) * inv;
            dc[2 * k + 1][m] = (dn2[m] - c2 * ds[m]) * inv;
        }
    }
    (c, dc)
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    fn bary() -> impl Strategy<Value = [f64; 3]> {
        (0.0f64..1.0, 0.0f64..1.0).prop_map(|(a, b)| {
            let (a, b) = if a + b > 1.0 {
                (1.0 - a, 1.0 - b)
            } else {
                (a, b)
            };
            [a, b, 1.0 - a - b]
        })
    }

    proptest! {
        #[test]
        fn coefficients_sum_to_one_and_derivatives_match(xi in bary()) {
            let (c, dc) = coefficients(&xi);
            prop_assert!((c.iter().sum::<f64>() - 1.0).abs() < 1e-12);
            let s = xi[0] * xi[1] + xi[1] * xi[2] + xi[2] * xi[0];
            prop_assume!(s > 1e-3);
            for k in 0..3 {
                let h = 1e-6;
                let mut a = xi;
                let mut b = xi;
                a[k] += h;
                b[k] -= h;
                let (ca, _) = coefficients_regular(&a, a[0]*a[1]+a[1]*a[2]+a[2]*a[0]);
                let (cb, _) = coefficients_regular(&b, b[0]*b[1]+b[1]*b[2]+b[2]*b[0]);
                for e in 0..6 {
                    let fd = (ca[e] - cb[e]) / (2.0 * h);
                    prop_assert!((fd - dc[e][k]).abs() < 1e-5 * (1.0 + fd.abs() / s), "{e} {k} {fd} {}", dc[e][k]);
                }
            }
        }
    }

    fn frame(seed: u64) -> Mat2x8 {
        // A deterministic pseudo-random orthonormal 2x8 frame.
        let mut x = seed.wrapping_mul(0x9E3779B97F4A7C15) | 1;
        let mut next = || {
            x ^= x << 13;
            x ^= x >> 7;
            x ^= x << 17;
            (x >> 11) as f64 / (1u64 << 53) as f64 - 0.5
        };
        let a = Vec8::from_fn(|_, _| next());
        let b = Vec8::from_fn(|_, _| next());
        let e1 = a.normalize();
        let e2 = (b - e1 * e1.dot(&b)).normalize();
        let mut m = Mat2x8::zeros();
        m.row_mut(0).copy_from(&e1.transpose());
        m.row_mut(1).copy_from(&e2.transpose());
        m
    }

    proptest! {
        /// Each block-descent sweep cannot increase the Procrustes energy.
        #[test]
        fn procrustes_energy_never_increases(s in 0u64..100_000) {
            let e = procrustes_energies(&[frame(s), frame(s + 1), frame(s + 2)]);
            for w in e.windows(2) {
                prop_assert!(w[1] <= w[0] + 1e-9 * (1.0 + w[0]), "{e:?}");
            }
        }
    }

    /// The direct reduced derivatives are those of [`coefficients`], differenced.
    fn check_reduced(xi: [f64; 3]) {
        let (c, dc) = coefficients(&xi);
        let (cr, dr) = coefficients_reduced(&xi);
        let scale = 1.0 + dc.iter().flatten().fold(0.0f64, |m, v| m.max(v.abs()));
        for e in 0..6 {
            assert!((c[e] - cr[e]).abs() <= 1e-14, "{xi:?} {e}");
            let want = [dc[e][0] - dc[e][2], dc[e][1] - dc[e][2]];
            for m in 0..2 {
                let d = (want[m] - dr[e][m]).abs();
                assert!(d <= 1e-12 * scale, "{xi:?} {e} {m}: {want:?} {:?}", dr[e]);
            }
        }
    }

    proptest! {
        #[test]
        fn reduced_coefficients_match_the_full_ones(xi in bary()) {
            check_reduced(xi);
        }
    }

    #[test]
    fn reduced_coefficients_match_on_edges_and_near_corners() {
        for xi in [
            [0.3, 0.7, 0.0],
            [0.0, 0.4, 0.6],
            [0.5, 0.0, 0.5],
            [1.0 - 2e-7, 1e-7, 1e-7],
            [1e-9, 1.0 - 2e-9, 1e-9],
            [0.0, 0.0, 1.0],
            [1.0 / 3.0; 3],
        ] {
            check_reduced(xi);
        }
    }

    #[test]
    fn coefficients_reduce_to_linear_on_edges() {
        let (c, _) = coefficients(&[0.3, 0.7, 0.0]);
        assert!((c[0] - 0.3).abs() < 1e-15 && (c[1] - 0.7).abs() < 1e-15);
        assert!(c[2..].iter().all(|v| v.abs() < 1e-15));
        let (c, dc) = coefficients(&[0.0, 0.0, 1.0]);
        assert_eq!(c, [0.0, 0.0, 0.0, 0.5, 0.5, 0.0]);
        assert!(dc.iter().flatten().all(|v| v.is_finite()));
    }
}
