//! What a cache line costs this machine by working-set size: `memory_latency [MB ...]`
//! (default 64 2048 6144) prints, per size, the nanoseconds a line takes in one chain of
//! dependent reads (latency) and in 16 chains interleaved (what overlapped reads reach),
//! over a random cycle through an array backed by transparent huge pages where the kernel
//! allows. A projection query is such chains: igea's projector (about 70 MB) against
//! rocker-arm level 5's (5.5 GB) bounds how close their `forward_us` can be.
use std::time::Instant;

/// One cache line: the index of the next line in the cycle, padded.
#[derive(Clone, Copy)]
#[repr(C, align(64))]
struct Line {
    next: u64,
    _pad: [u64; 7],
}

const HUGE: usize = 2 << 20;

/// A vector of `n` lines whose memory is advised to use huge pages before it is touched.
fn huge_lines(n: usize) -> Vec<Line> {
    let v: Vec<Line> = Vec::with_capacity(n);
    let (start, bytes) = (v.as_ptr() as usize, n * std::mem::size_of::<Line>());
    let (lo, hi) = (start.next_multiple_of(HUGE), (start + bytes) / HUGE * HUGE);
    if hi > lo {
        // SAFETY: [lo, hi) lies inside the allocation just made and not yet touched; the
        // advice changes no contents and no permissions, and its failure is harmless.
        unsafe {
            libc::madvise(lo as *mut libc::c_void, hi - lo, libc::MADV_HUGEPAGE);
        }
    }
    v
}

/// A random single cycle through `n` lines (Sattolo's shuffle, xorshift).
fn cycle(n: usize) -> Vec<Line> {
    let mut order: Vec<u64> = (0..n as u64).collect();
    let mut s = 0x9E37_79B9_7F4A_7C15u64;
    for i in (1..n).rev() {
        s ^= s << 13;
        s ^= s >> 7;
        s ^= s << 17;
        order.swap(i, (s % i as u64) as usize);
    }
    let mut lines = huge_lines(n);
    lines.resize(
        n,
        Line {
            next: 0,
            _pad: [0; 7],
        },
    );
    for i in 0..n {
        lines[order[i] as usize].next = order[(i + 1) % n];
    }
    lines
}

/// Nanoseconds a line over `steps` reads in `chains` interleaved chains.
fn chase(lines: &[Line], chains: usize, steps: usize) -> f64 {
    let n = lines.len() as u64;
    let mut at: Vec<u64> = (0..chains as u64).map(|k| k * 7919 % n).collect();
    let t = Instant::now();
    for _ in 0..steps / chains {
        for p in at.iter_mut() {
            *p = lines[*p as usize].next;
        }
    }
    let ns = t.elapsed().as_secs_f64() * 1e9 / (steps / chains * chains) as f64;
    std::hint::black_box(at);
    ns
}

fn anon_huge_mb() -> u64 {
    std::fs::read_to_string("/proc/self/smaps_rollup")
        .ok()
        .and_then(|s| {
            s.lines()
                .find(|l| l.starts_with("AnonHugePages"))
                .and_then(|l| l.split_whitespace().nth(1)?.parse::<u64>().ok())
        })
        .map_or(0, |kb| kb >> 10)
}

fn main() {
    let sizes: Vec<usize> = std::env::args()
        .skip(1)
        .map(|a| a.parse().expect("a size in MB"))
        .collect();
    let sizes = if sizes.is_empty() {
        vec![64, 2048, 6144]
    } else {
        sizes
    };
    for mb in sizes {
        let lines = cycle((mb << 20) / 64);
        let huge = anon_huge_mb();
        let one = chase(&lines, 1, 2_000_000);
        let sixteen = chase(&lines, 16, 4_000_000);
        println!(
            "{mb} MB ({huge} MB in huge pages): one chain {one:.1} ns a line, 16 chains {sixteen:.1} ns a line"
        );
    }
}
