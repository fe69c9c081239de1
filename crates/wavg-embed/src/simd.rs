//! Run-time SIMD dispatch and the crate's explicit-SIMD loop, the SMACOF coefficient column.
//!
//! The same convention as `wavg-solve`: a hot loop is one function generic over
//! `S: pulp::Simd`, wrapped in a [`pulp::WithSimd`] operation and run through [`dispatch`]
//! once per call, which picks the build for the widest instruction set this CPU has. No
//! `unsafe`.

use std::sync::LazyLock;

/// The instruction sets of this CPU, detected once.
static ARCH: LazyLock<pulp::Arch> = LazyLock::new(pulp::Arch::new);

/// Runs `op` compiled for this CPU's widest SIMD instruction set.
#[inline(always)]
pub(crate) fn dispatch<Op: pulp::WithSimd>(op: Op) -> Op::Output {
    ARCH.dispatch(op)
}

/// Turns Gram column `j` into coefficients `c_ij = 1/(Q_ij d_ij)` (0 where `d_ij = 0` or on
/// the diagonal); returns the column's stress `Σ_i (d_ij/Q_ij - 1)²` and `Σ_i c_ij`.
///
/// Explicit SIMD through `pulp`, which picks AVX2 at run time when the CPU has it (the
/// build targets baseline x86-64, where the compiler would not vectorise the square roots
/// and divisions).
pub(crate) fn coefficient_column(
    col: &mut [f64],
    sq: &[f64],
    j: usize,
    inv_col: &[f64],
) -> (f64, f64) {
    let n = col.len();
    dispatch(CoefficientColumn {
        col,
        sq: &sq[..n],
        sj: sq[j],
        inv: &inv_col[..n],
    })
}

/// [`coefficient_column`] as one SIMD operation.
struct CoefficientColumn<'a> {
    col: &'a mut [f64],
    sq: &'a [f64],
    sj: f64,
    inv: &'a [f64],
}

impl pulp::WithSimd for CoefficientColumn<'_> {
    type Output = (f64, f64);

    #[inline(always)]
    fn with_simd<S: pulp::Simd>(self, simd: S) -> (f64, f64) {
        let (g_head, g_tail) = S::as_mut_simd_f64s(self.col);
        let (s_head, s_tail) = S::as_simd_f64s(self.sq);
        let (i_head, i_tail) = S::as_simd_f64s(self.inv);
        let zero = simd.splat_f64s(0.0);
        let one = simd.splat_f64s(1.0);
        let two = simd.splat_f64s(2.0);
        let sj = simd.splat_f64s(self.sj);
        let mut stress = zero;
        let mut sum = zero;
        for ((g, &si), &iq) in g_head.iter_mut().zip(s_head).zip(i_head) {
            let d2 = simd.sub_f64s(simd.add_f64s(si, sj), simd.mul_f64s(two, *g));
            let pos = simd.greater_than_f64s(d2, zero);
            let d = simd.select_f64s(pos, simd.sqrt_f64s(d2), zero);
            let r = simd.sub_f64s(simd.mul_f64s(d, iq), one);
            let r = simd.select_f64s(simd.greater_than_f64s(iq, zero), r, zero);
            stress = simd.mul_add_f64s(r, r, stress);
            let c = simd.select_f64s(pos, simd.div_f64s(iq, d), zero);
            *g = c;
            sum = simd.add_f64s(sum, c);
        }
        let (mut st, mut su) = (simd.reduce_sum_f64s(stress), simd.reduce_sum_f64s(sum));
        for ((g, &si), &iq) in g_tail.iter_mut().zip(s_tail).zip(i_tail) {
            let d2 = si + self.sj - 2.0 * *g;
            let d = if d2 > 0.0 { d2.sqrt() } else { 0.0 };
            if iq > 0.0 {
                st += (d * iq - 1.0) * (d * iq - 1.0);
            }
            let c = if d > 0.0 { iq / d } else { 0.0 };
            *g = c;
            su += c;
        }
        (st, su)
    }
}
