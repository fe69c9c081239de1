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
//!
//! One job per file: [`align`] precomputes `X_e` (edge alignments and in-plane rotations),
//! [`psi`] evaluates the blend coefficients and `Psi`, [`newton`] solves the tangent
//! equations, and [`exclude`] proves a triangle holds no projection before solving.

use crate::Mat2x8;

mod align;
mod exclude;
mod newton;
mod psi;

/// Corner whose frame term `e` multiplies.
pub(crate) const TERM_VERTEX: [usize; 6] = [0, 1, 1, 2, 2, 0];

/// Barycentric tolerance of a valid projection: a projection up to this far outside its
/// triangle (in barycentric coordinates) is accepted and clamped onto the edge.
pub const BARY_EPS: f64 = 1e-4;

/// Largest residual `|F|_inf`, relative to the system's scale, at the iterate inside the
/// triangle from which Newton's method accepts a root up to [`BARY_EPS`] outside it
/// (clamped onto the edge). Every accepted projection therefore has a point of the closed
/// triangle where `|F|_inf <= CLAMP_RESIDUAL * fscale`, which is what the exclusion tests
/// ([`TriData::solve_unless_excluded`], the hierarchy's cone bounds) rule out.
pub(crate) const CLAMP_RESIDUAL: f64 = 1e-2;

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
