//! Where the precomputation's memory goes: with the environment variable
//! [`MEMORY_TRACE_VAR`] set, each stage boundary prints to stderr the process's resident
//! size and its peak since the previous boundary (`/proc/self/status` `VmRSS`, `VmHWM`),
//! then resets the peak (`/proc/self/clear_refs`), so each line's peak belongs to the
//! stage that just ended. Off, or off Linux, it costs one environment look-up per call.

/// The environment variable that turns the trace on (any value).
pub const MEMORY_TRACE_VAR: &str = "WAVG_MEMORY_TRACE";

/// Resident size and peak, in bytes, from `/proc/self/status`.
fn rss_and_peak() -> Option<(u64, u64)> {
    let status = std::fs::read_to_string("/proc/self/status").ok()?;
    let field = |name: &str| -> Option<u64> {
        let line = status.lines().find(|l| l.starts_with(name))?;
        let kb: u64 = line[name.len()..]
            .trim()
            .trim_end_matches("kB")
            .trim()
            .parse()
            .ok()?;
        Some(kb * 1024)
    };
    Some((field("VmRSS:")?, field("VmHWM:")?))
}

/// Prints `label`'s line when the trace is on (see the module documentation).
pub fn mark(label: &str) {
    if std::env::var_os(MEMORY_TRACE_VAR).is_none() {
        return;
    }
    if let Some((rss, peak)) = rss_and_peak() {
        let mb = |b: u64| b as f64 / 1e6;
        eprintln!(
            "memory: {label:<34} peak {:>9.1} MB, after {:>9.1} MB",
            mb(peak),
            mb(rss)
        );
        // "5" resets the peak to the current resident size (Linux 4.0 and later).
        let _ = std::fs::write("/proc/self/clear_refs", "5");
    }
}
