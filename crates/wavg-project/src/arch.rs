//! Every `unsafe` operation of this crate, each a safe function with a portable
//! equivalent: cache prefetch hints, the walk's SSE2 distance and the huge-page advice.
//!
//! None of them changes a result: a prefetch is only a hint, the SSE2 distance equals the
//! portable one bit for bit (tested in the projector), and the advice only picks the page
//! size of memory this process just allocated.
//!
//! Nothing here is dispatched at run time: every instruction used is in the x86-64 baseline
//! (SSE, SSE2), so the walk inlines the distance. Run-time dispatched SIMD goes through
//! `pulp` in the other crates' `simd.rs` modules; `pulp::Simd` has no 16-bit to `f32`
//! conversion, which the walk's distance needs (ARCHITECTURE.md, "Public API and `unsafe`").

/// Hints the processor to load the first `lines` cache lines (64 bytes each) starting at
/// `r` into cache; no effect on results, a no-op off x86-64.
#[inline(always)]
pub(crate) fn prefetch_lines<T>(r: &T, lines: usize) {
    #[cfg(target_arch = "x86_64")]
    {
        use std::arch::x86_64::{_MM_HINT_T0, _mm_prefetch};
        let p = (r as *const T).cast::<i8>();
        for k in 0..lines {
            // SAFETY: SSE is part of the x86-64 baseline, and a prefetch never faults or
            // dereferences (any address is allowed; this one points into or just past a
            // live value).
            unsafe { _mm_prefetch::<_MM_HINT_T0>(p.wrapping_add(64 * k)) };
        }
    }
    #[cfg(not(target_arch = "x86_64"))]
    let _ = (r, lines);
}

/// Squared distance between the quantised coordinates `c` (converted to f32) and `y`,
/// summed as `(s0 + s2) + (s1 + s3)` with `s_k = d_k^2 + d_{k+4}^2`: the portable
/// reference is the projector's `wdist2`, which this equals bit for bit.
#[cfg(target_arch = "x86_64")]
#[inline(always)]
pub(crate) fn dist2_u16(c: &[u16; 8], y: &[f32; 8]) -> f32 {
    use std::arch::x86_64::*;
    // SAFETY: SSE2 is part of the x86-64 baseline; the loads read the 16 bytes of `c` and
    // the 32 bytes of `y`, unaligned loads of valid memory.
    unsafe {
        let c = _mm_loadu_si128(c.as_ptr() as *const __m128i);
        let z = _mm_setzero_si128();
        let lo = _mm_cvtepi32_ps(_mm_unpacklo_epi16(c, z));
        let hi = _mm_cvtepi32_ps(_mm_unpackhi_epi16(c, z));
        let d0 = _mm_sub_ps(lo, _mm_loadu_ps(y.as_ptr()));
        let d1 = _mm_sub_ps(hi, _mm_loadu_ps(y.as_ptr().add(4)));
        // s[k] = d0[k]^2 + d1[k]^2, then (s0 + s2) + (s1 + s3) as in `wdist2`.
        let s = _mm_add_ps(_mm_mul_ps(d0, d0), _mm_mul_ps(d1, d1));
        let t = _mm_add_ps(s, _mm_movehl_ps(s, s));
        _mm_cvtss_f32(_mm_add_ss(t, _mm_shuffle_ps::<0b01>(t, t)))
    }
}

/// Advises the kernel to back `[start, start + bytes)` with 2 MiB pages where whole ones
/// fit (Linux `madvise(MADV_HUGEPAGE)`); only a hint, a no-op elsewhere. The range must be
/// memory this process allocated and has not yet touched.
#[cfg(target_os = "linux")]
pub(crate) fn advise_huge_pages(start: usize, bytes: usize, huge: usize) {
    // Only whole huge pages inside the allocation can be huge.
    let lo = start.next_multiple_of(huge);
    let hi = (start + bytes) / huge * huge;
    if hi > lo {
        // SAFETY: [lo, hi) lies inside the allocation just made by this process; the
        // advice changes no contents and no permissions, and its failure is harmless.
        unsafe {
            libc::madvise(lo as *mut libc::c_void, hi - lo, libc::MADV_HUGEPAGE);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn prefetch_has_no_effect_on_values() {
        let v: Vec<u64> = (0..1024).collect();
        for lines in [0, 1, 2, 16] {
            prefetch_lines(&v[1000], lines); // may point past the end: only a hint
        }
        assert!(v.iter().enumerate().all(|(i, &x)| x == i as u64));
    }

    #[cfg(target_arch = "x86_64")]
    #[test]
    fn sse2_distance_matches_the_portable_sum() {
        let mut seed = 12345u32;
        let mut next = || {
            seed = seed.wrapping_mul(1_664_525).wrapping_add(1_013_904_223);
            seed
        };
        for _ in 0..10_000 {
            let c: [u16; 8] = std::array::from_fn(|_| (next() >> 16) as u16);
            let y: [f32; 8] = std::array::from_fn(|_| (next() >> 8) as f32 / 256.0);
            let d: [f32; 8] = std::array::from_fn(|k| c[k] as f32 - y[k]);
            let s: [f32; 4] = std::array::from_fn(|k| d[k] * d[k] + d[k + 4] * d[k + 4]);
            let portable = (s[0] + s[2]) + (s[1] + s[3]);
            assert_eq!(dist2_u16(&c, &y).to_bits(), portable.to_bits());
        }
    }
}
