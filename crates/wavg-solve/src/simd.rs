//! Run-time SIMD dispatch: the inverse problem's kernel and the weighted sum are written
//! as portable loops over [`LANES`](crate::kernel::LANES)-wide partial sums, and `pulp`
//! compiles them a second time for the widest instruction set the CPU has (AVX2 and up),
//! chosen once at run time. The same operations run in the same order, so both builds
//! give the same bits (tested in `kernel`); only the registers are wider. No `unsafe`.

use std::sync::LazyLock;

use crate::Vec8;
use crate::error::SolveError;
use crate::kernel::{AnchorCoords, Ctx, InverseScratch, kernel};

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

/// [`AnchorCoords::weighted_sum_portable`] compiled for the CPU's widest SIMD instruction
/// set.
pub(crate) fn weighted_sum(coords: &AnchorCoords, weights: &[f64], scale: f64) -> Vec8 {
    ARCH.dispatch(WeightedSum {
        coords,
        weights,
        scale,
    })
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

struct WeightedSum<'a> {
    coords: &'a AnchorCoords,
    weights: &'a [f64],
    scale: f64,
}

impl pulp::WithSimd for WeightedSum<'_> {
    type Output = Vec8;

    #[inline(always)]
    fn with_simd<S: pulp::Simd>(self, _simd: S) -> Vec8 {
        self.coords.weighted_sum_portable(self.weights, self.scale)
    }
}
