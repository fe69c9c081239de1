//! Large arrays that random queries read, backed by transparent huge pages where the
//! kernel allows it.
//!
//! A projection query touches a few random records of arrays of tens of megabytes; with
//! 4 KiB pages nearly every access also misses the TLB, which roughly doubles its memory
//! latency. On Linux, `madvise(MADV_HUGEPAGE)` on the (still untouched) allocation asks for
//! 2 MiB pages. It is only a hint: where it is unavailable the arrays are ordinary.

/// Allocations smaller than this are left alone (a huge page would not pay off).
const MIN_BYTES: usize = 4 << 20;
const HUGE: usize = 2 << 20;

/// An empty vector with room for `n` elements whose memory is advised to use huge pages.
/// Fill it before reading (the advice applies as pages are first touched).
pub(crate) fn vec_with_capacity<T>(n: usize) -> Vec<T> {
    let v: Vec<T> = Vec::with_capacity(n);
    let bytes = n.saturating_mul(std::mem::size_of::<T>());
    if bytes >= MIN_BYTES {
        advise(v.as_ptr() as usize, bytes);
    }
    v
}

/// `n` copies of `value` in a vector advised to use huge pages, written in parallel (so
/// the pages are first touched, and zeroed by the kernel, by several threads).
pub(crate) fn filled<T: Copy + Send + Sync>(n: usize, value: T) -> Vec<T> {
    use rayon::prelude::*;
    let mut v = vec_with_capacity(n);
    v.par_extend(rayon::iter::repeat_n(value, n).with_min_len(1 << 14));
    v
}

#[cfg(target_os = "linux")]
fn advise(start: usize, bytes: usize) {
    crate::arch::advise_huge_pages(start, bytes, HUGE);
}

#[cfg(not(target_os = "linux"))]
fn advise(_start: usize, _bytes: usize) {}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn filled_vectors_hold_their_items() {
        let v = filled(3_000_000, 7u32);
        assert_eq!(v.len(), 3_000_000);
        assert!(v.iter().all(|&x| x == 7));
        let small: Vec<u8> = filled(3, 1);
        assert_eq!(small, [1, 1, 1]);
    }
}
