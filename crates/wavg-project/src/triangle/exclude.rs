//! The exclusion test before Newton's method: a proof, cheaper than a solve, that a
//! triangle holds no projection of the query.

use super::newton::System;
use super::{CLAMP_RESIDUAL, Frame32, TriData};
use crate::Vec8;

impl TriData {
    /// [`TriData::solve_or_exit`], but `Err(None)` without Newton's method when the
    /// triangle provably holds no projection of `y`.
    ///
    /// Why it is exact: with `w_ej = X_e T_i (v_j - y)` (`i` the corner of term `e`) the
    /// residual is `F(xi) = sum_e c_e(xi) z_e(xi)`, `z_e = sum_j xi_j w_ej`, so on the
    /// closed triangle (`c_e >= 0`, `sum c_e = 1`, `xi_j >= 0`, `sum xi_j = 1`, also in the
    /// vertex limit) `F` is a convex combination of the 18 vectors `w_ej`. If a unit
    /// direction `u` has `<u, w_ej> >= m` for all of them then `|F|_inf >= m / sqrt(2)`
    /// everywhere on the triangle; Newton's method accepts only iterates of the triangle
    /// with `|F|_inf <= CLAMP_RESIDUAL * fscale` (its own tolerances are smaller), so
    /// `m > 3 CLAMP_RESIDUAL fscale` proves it would fail. The test reads the same f64
    /// system Newton's method solves (built from the stored f32 data), so f32 rounding
    /// needs no margin; the factor `3 > 2 sqrt(2)` covers f64 rounding.
    #[inline]
    pub(crate) fn solve_unless_excluded(
        &self,
        frames: [&Frame32; 3],
        corners: [&Vec8; 3],
        y: &Vec8,
    ) -> Result<[f64; 3], Option<usize>> {
        let sys = System::new(self, frames, corners, y);
        if sys.excluded() {
            return Err(None);
        }
        sys.newton()
    }

    /// Whether [`TriData::solve_unless_excluded`] skips Newton's method (for tests).
    #[cfg(test)]
    pub(crate) fn excludes(&self, frames: [&Frame32; 3], corners: [&Vec8; 3], y: &Vec8) -> bool {
        System::new(self, frames, corners, y).excluded()
    }
}

impl System {
    /// The exclusion test of [`TriData::solve_unless_excluded`]: the 18 vectors `w_ej`
    /// all have a component above `3 CLAMP_RESIDUAL fscale` along their (normalised) sum.
    #[inline(always)]
    fn excluded(&self) -> bool {
        let mut w = [[0.0f64; 2]; 18];
        let mut s = [0.0f64; 2];
        for e in 0..6 {
            let (g, q) = (&self.g[e], &self.q[e]);
            w[3 * e] = [-q[0], -q[1]];
            w[3 * e + 1] = [g[0] - q[0], g[1] - q[1]];
            w[3 * e + 2] = [g[2] - q[0], g[3] - q[1]];
            for v in &w[3 * e..3 * e + 3] {
                s[0] += v[0];
                s[1] += v[1];
            }
        }
        let n = (s[0] * s[0] + s[1] * s[1]).sqrt();
        if !(n > 0.0) || !n.is_finite() {
            return false;
        }
        let u = [s[0] / n, s[1] / n];
        let m = w
            .iter()
            .map(|v| u[0] * v[0] + u[1] * v[1])
            .fold(f64::INFINITY, f64::min);
        m > 3.0 * CLAMP_RESIDUAL * self.fscale
    }
}
