//! Run-time SIMD dispatch. The inverse problem's kernel is written as portable loops over
//! [`LANES`](crate::kernel::LANES)-wide partial sums, and `pulp` compiles it a second time
//! for the widest instruction set the CPU has (AVX2 and up), chosen once at run time. The
//! weighted sum is written with pulp's explicit 4-wide AVX2 operations. Either way the same
//! operations run in the same order as the portable code, so all builds give the same bits
//! (tested in `kernel`); only the registers are wider. No `unsafe`.

use std::sync::LazyLock;

use crate::Vec8;
use crate::error::SolveError;
use crate::kernel::{AnchorCoords, Ctx, InverseScratch, LANES, kernel};

/// The instruction sets of this CPU, detected once.
static ARCH: LazyLock<pulp::Arch> = LazyLock::new(pulp::Arch::new);

/// [`kernel`] compiled for the CPU's widest SIMD instruction set.
pub(crate) fn inverse_kernel(
    ctx: &Ctx,
    ys: &AnchorCoords,
    sc: &mut InverseScratch,
    out: &mut [f64],
) -> Result<(), SolveError> {
    ARCH.dispatch(Kernel { ctx, ys, sc, out })
}

/// AVX2 on this CPU, detected once.
#[cfg(target_arch = "x86_64")]
static V3: LazyLock<Option<pulp::x86::V3>> = LazyLock::new(pulp::x86::V3::try_new);

/// [`AnchorCoords::weighted_sum_portable`] with its four partial sums in one AVX2 register
/// where the CPU has one (the same multiplications and additions in the same order, so the
/// same bits), else the portable loop. Written with explicit 4-wide operations: compiled
/// from the portable loop, the compiler vectorised across chunks, with shuffles, at half
/// the speed.
pub(crate) fn weighted_sum(coords: &AnchorCoords, weights: &[f64], scale: f64) -> Vec8 {
    #[cfg(target_arch = "x86_64")]
    if let Some(simd) = *V3 {
        return simd.vectorize(|| weighted_sum_v3(simd, coords, weights, scale));
    }
    coords.weighted_sum_portable(weights, scale)
}

struct Kernel<'a> {
    ctx: &'a Ctx,
    ys: &'a AnchorCoords,
    sc: &'a mut InverseScratch,
    out: &'a mut [f64],
}

impl pulp::WithSimd for Kernel<'_> {
    type Output = Result<(), SolveError>;

    #[inline(always)]
    fn with_simd<S: pulp::Simd>(self, _simd: S) -> Self::Output {
        kernel(self.ctx, self.ys, self.sc, self.out)
    }
}

/// The body of [`weighted_sum`] with AVX2 (inlined into pulp's AVX2 function).
#[cfg(target_arch = "x86_64")]
#[inline(always)]
fn weighted_sum_v3(v3: pulp::x86::V3, coords: &AnchorCoords, weights: &[f64], scale: f64) -> Vec8 {
    use pulp::{cast, f64x4};
    const _: () = assert!(LANES == 4);
    let (n, dims) = coords.dims(weights.len());
    let w = &weights[..n];
    let mut out = [0.0; 8];
    for (o, dim) in out.iter_mut().zip(dims) {
        let y = &dim[..n];
        let (wc, yc) = (w.chunks_exact(LANES), y.chunks_exact(LANES));
        let (wr, yr) = (wc.remainder(), yc.remainder());
        let mut acc = v3.splat_f64x4(0.0);
        for (wc, yc) in wc.zip(yc) {
            let a: f64x4 = cast(<[f64; LANES]>::try_from(wc).unwrap_or_default());
            let b: f64x4 = cast(<[f64; LANES]>::try_from(yc).unwrap_or_default());
            acc = v3.add_f64x4(acc, v3.mul_f64x4(a, b));
        }
        let l: [f64; LANES] = cast(acc);
        let mut s = (l[0] + l[1]) + (l[2] + l[3]);
        for (a, b) in wr.iter().zip(yr) {
            s += a * b;
        }
        *o = s * scale;
    }
    Vec8::from(out)
}
