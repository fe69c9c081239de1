//! Run-time SIMD dispatch and the vector building blocks of the inverse problem.
//!
//! The crate's convention: a hot loop is one function generic over [`Quad`] (vectors of
//! [`LANES`] lanes), wrapped in a [`pulp::WithSimd`] operation that picks [`Wide`] or
//! [`Plain`] for its instruction set, and run through [`dispatch`] once per call, which
//! compiles it for the widest instruction set this CPU has (AVX2 and up) and picks that
//! build at run time. Reductions keep [`LANES`] partial sums whatever the vector width, so
//! every build runs the same operations in the same order and gives the same bits. No
//! `unsafe`.

use std::sync::LazyLock;

/// Lanes of the per-anchor reductions: partial sums are kept `LANES` apart, and anchor
/// storage is padded to a multiple of this.
pub(crate) const LANES: usize = 4;

/// The instruction sets of this CPU, detected once.
static ARCH: LazyLock<pulp::Arch> = LazyLock::new(pulp::Arch::new);

/// Runs `op` compiled for this CPU's widest SIMD instruction set.
#[inline(always)]
pub(crate) fn dispatch<Op: pulp::WithSimd>(op: Op) -> Op::Output {
    ARCH.dispatch(op)
}

/// The [`LANES`] partial sums added pairwise, `(l0 + l1) + (l2 + l3)`.
#[inline(always)]
pub(crate) fn sum_lanes(l: [f64; LANES]) -> f64 {
    (l[0] + l[1]) + (l[2] + l[3])
}

/// `sum_i a_i b_i` over the common length, as [`LANES`] partial sums added by
/// [`sum_lanes`], then the remainder in order: the tests' reference for reductions
/// written with [`Quad`]. With `S` exactly [`LANES`] wide the partial sums live in one
/// register; any other `S` runs the same operations as plain loops. Both give the same
/// bits.
#[cfg(test)]
#[inline(always)]
pub(crate) fn dot<S: pulp::Simd>(simd: S, a: &[f64], b: &[f64]) -> f64 {
    let n = a.len().min(b.len());
    let (ac, bc) = (a[..n].chunks_exact(LANES), b[..n].chunks_exact(LANES));
    let (ar, br) = (ac.remainder(), bc.remainder());
    let lanes = if S::F64_LANES == LANES {
        let mut acc = simd.splat_f64s(0.0);
        for (x, y) in ac.zip(bc) {
            let (x, y) = (S::as_simd_f64s(x).0[0], S::as_simd_f64s(y).0[0]);
            acc = simd.add_f64s(acc, simd.mul_f64s(x, y));
        }
        let mut l = [0.0; LANES];
        S::as_mut_simd_f64s(&mut l).0[0] = acc;
        l
    } else {
        let mut acc = [0.0; LANES];
        for (x, y) in ac.zip(bc) {
            for k in 0..LANES {
                acc[k] += x[k] * y[k];
            }
        }
        acc
    };
    let mut s = sum_lanes(lanes);
    for (x, y) in ar.iter().zip(br) {
        s += x * y;
    }
    s
}

/// Vectors of [`LANES`] `f64`s and the lane-wise IEEE operations the kernels use, on one
/// register of an instruction set exactly [`LANES`] wide ([`Wide`]) or on arrays in plain
/// loops ([`Plain`], any other). Lane-wise operations round the same way in both (no fused
/// multiply-adds), so both give the same bits; written with these, a kernel compiles to
/// vector instructions where plain loops over lanes would be vectorised across rows, with
/// shuffles, or not at all.
pub(crate) trait Quad: Copy {
    /// A vector.
    type V: Copy;
    /// The lanes `x`.
    fn load(self, x: &[f64; LANES]) -> Self::V;
    /// Writes the lanes to `x`.
    fn store(self, v: Self::V, x: &mut [f64; LANES]);
    /// `v` in every lane.
    fn splat(self, v: f64) -> Self::V;
    /// `a + b`.
    fn add(self, a: Self::V, b: Self::V) -> Self::V;
    /// `a - b`.
    fn sub(self, a: Self::V, b: Self::V) -> Self::V;
    /// `a * b`.
    fn mul(self, a: Self::V, b: Self::V) -> Self::V;
    /// `a / b`.
    fn div(self, a: Self::V, b: Self::V) -> Self::V;
    /// `if a < b { a } else { b }`, lane by lane (`b` where either is NaN).
    fn min_left(self, a: Self::V, b: Self::V) -> Self::V;
    /// `if a > b { a } else { b }`, lane by lane (`b` where either is NaN).
    fn max_left(self, a: Self::V, b: Self::V) -> Self::V;
    /// The lanes.
    fn lanes(self, v: Self::V) -> [f64; LANES];
}

/// [`Quad`] on arrays, in plain loops.
#[derive(Clone, Copy)]
pub(crate) struct Plain;

impl Quad for Plain {
    type V = [f64; LANES];
    #[inline(always)]
    fn load(self, x: &[f64; LANES]) -> Self::V {
        *x
    }
    #[inline(always)]
    fn store(self, v: Self::V, x: &mut [f64; LANES]) {
        *x = v;
    }
    #[inline(always)]
    fn splat(self, v: f64) -> Self::V {
        [v; LANES]
    }
    #[inline(always)]
    fn add(self, a: Self::V, b: Self::V) -> Self::V {
        std::array::from_fn(|l| a[l] + b[l])
    }
    #[inline(always)]
    fn sub(self, a: Self::V, b: Self::V) -> Self::V {
        std::array::from_fn(|l| a[l] - b[l])
    }
    #[inline(always)]
    fn mul(self, a: Self::V, b: Self::V) -> Self::V {
        std::array::from_fn(|l| a[l] * b[l])
    }
    #[inline(always)]
    fn div(self, a: Self::V, b: Self::V) -> Self::V {
        std::array::from_fn(|l| a[l] / b[l])
    }
    #[inline(always)]
    fn min_left(self, a: Self::V, b: Self::V) -> Self::V {
        std::array::from_fn(|l| if a[l] < b[l] { a[l] } else { b[l] })
    }
    #[inline(always)]
    fn max_left(self, a: Self::V, b: Self::V) -> Self::V {
        std::array::from_fn(|l| if a[l] > b[l] { a[l] } else { b[l] })
    }
    #[inline(always)]
    fn lanes(self, v: Self::V) -> [f64; LANES] {
        v
    }
}

/// [`Quad`] in registers of an instruction set `S` exactly [`LANES`] wide (see
/// [`Wide::new`]).
#[derive(Clone, Copy)]
pub(crate) struct Wide<S>(S);

impl<S: pulp::Simd> Wide<S> {
    /// `S`'s vectors, when they hold exactly [`LANES`] `f64`s.
    #[inline(always)]
    pub(crate) fn new(simd: S) -> Option<Self> {
        (S::F64_LANES == LANES).then_some(Self(simd))
    }
}

impl<S: pulp::Simd> Quad for Wide<S> {
    type V = S::f64s;
    #[inline(always)]
    fn load(self, x: &[f64; LANES]) -> Self::V {
        S::as_simd_f64s(x).0[0]
    }
    #[inline(always)]
    fn store(self, v: Self::V, x: &mut [f64; LANES]) {
        S::as_mut_simd_f64s(x).0[0] = v;
    }
    #[inline(always)]
    fn splat(self, v: f64) -> Self::V {
        self.0.splat_f64s(v)
    }
    #[inline(always)]
    fn add(self, a: Self::V, b: Self::V) -> Self::V {
        self.0.add_f64s(a, b)
    }
    #[inline(always)]
    fn sub(self, a: Self::V, b: Self::V) -> Self::V {
        self.0.sub_f64s(a, b)
    }
    #[inline(always)]
    fn mul(self, a: Self::V, b: Self::V) -> Self::V {
        self.0.mul_f64s(a, b)
    }
    #[inline(always)]
    fn div(self, a: Self::V, b: Self::V) -> Self::V {
        self.0.div_f64s(a, b)
    }
    #[inline(always)]
    fn min_left(self, a: Self::V, b: Self::V) -> Self::V {
        self.0.select_f64s(self.0.less_than_f64s(a, b), a, b)
    }
    #[inline(always)]
    fn max_left(self, a: Self::V, b: Self::V) -> Self::V {
        self.0.select_f64s(self.0.greater_than_f64s(a, b), a, b)
    }
    #[inline(always)]
    fn lanes(self, v: Self::V) -> [f64; LANES] {
        let mut l = [0.0; LANES];
        self.store(v, &mut l);
        l
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The dot product for one pair of slices, run through [`dispatch`].
    struct Dot<'a>(&'a [f64], &'a [f64]);

    impl pulp::WithSimd for Dot<'_> {
        type Output = f64;

        #[inline(always)]
        fn with_simd<S: pulp::Simd>(self, simd: S) -> f64 {
            dot(simd, self.0, self.1)
        }
    }

    /// The dispatched dot product gives the plain loops' bits, for lengths around the
    /// vector width, and agrees with the direct sum to rounding.
    #[test]
    fn dispatched_dot_matches_the_plain_loops_bitwise() {
        for n in [0usize, 1, 3, 4, 5, 27, 93, 100] {
            let a: Vec<f64> = (0..n).map(|i| (i as f64 * 0.7316).sin() * 3.0).collect();
            let b: Vec<f64> = (0..n + 2).map(|i| (i as f64 * 1.37).cos()).collect();
            let fast = dispatch(Dot(&a, &b));
            let plain = dot(pulp::Scalar::new(), &a, &b);
            assert_eq!(fast.to_bits(), plain.to_bits(), "{n}");
            let direct: f64 = a.iter().zip(&b).map(|(x, y)| x * y).sum();
            assert!((fast - direct).abs() < 1e-12, "{n}");
        }
    }
}
