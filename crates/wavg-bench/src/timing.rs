//! The protocols' clocks and timing loops.

use std::time::Instant;

/// A CPU-time clock in seconds (process or calling thread, as the option says); `None`
/// where the platform has none. The standard library has no CPU clock, so the caller
/// brings one.
pub type CpuClock = fn() -> Option<f64>;

/// Best wall time in seconds of `repeat` runs of `f` (at least one), and the last result.
pub(crate) fn best_of<T>(repeat: usize, mut f: impl FnMut() -> T) -> (f64, T) {
    let t = Instant::now();
    let mut out = f();
    let mut best = t.elapsed().as_secs_f64();
    for _ in 1..repeat {
        let t = Instant::now();
        out = f();
        best = best.min(t.elapsed().as_secs_f64());
    }
    (best, out)
}

/// Runs `f` and returns its result with the CPU seconds it used, when there is a clock.
pub(crate) fn with_cpu<T>(clock: Option<CpuClock>, f: impl FnOnce() -> T) -> (T, Option<f64>) {
    let c0 = clock.and_then(|c| c());
    let r = f();
    let c1 = clock.and_then(|c| c());
    (r, c0.zip(c1).map(|(a, b)| b - a))
}

/// The 1-minute load average (Linux; "unknown" elsewhere), to judge how busy the machine
/// was during a measurement.
pub fn load_average() -> String {
    std::fs::read_to_string("/proc/loadavg")
        .ok()
        .and_then(|s| s.split_whitespace().next().map(str::to_string))
        .unwrap_or_else(|| "unknown".into())
}
