//! Newton's method for the Phong projection onto one triangle: the tangent equations of
//! one query as a 2-D system, its starting point, and the iteration kept inside the
//! triangle.

use super::psi::coefficients_reduced;
use super::{BARY_EPS, CLAMP_RESIDUAL, Frame32, TERM_VERTEX, TriData};
use crate::Vec8;

/// Maximum Newton iterations per triangle.
pub(crate) const MAX_NEWTON: usize = 16;

/// One triangle's tangent equations for one query, in f64.
pub(super) struct System {
    /// `G_e`, two 2-vectors per term.
    pub(super) g: [[f64; 4]; 6],
    /// `q_e = X_e h_{i(e)}`.
    pub(super) q: [[f64; 2]; 6],
    /// Size of the triangle plus distance of the query: the scale of `F`.
    pub(super) fscale: f64,
}

impl TriData {
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
    #[inline(always)]
    pub(super) fn new(d: &TriData, frames: [&Frame32; 3], corners: [&Vec8; 3], y: &Vec8) -> Self {
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

    /// Newton's method on this system (see [`TriData::solve_or_exit`]).
    #[inline(always)]
    pub(super) fn newton(&self) -> Result<[f64; 3], Option<usize>> {
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
