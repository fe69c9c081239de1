//! Where the precomputation's memory goes: with the environment variable
//! [`MEMORY_TRACE_VAR`] set, each stage boundary prints to stderr the process's resident
//! size and its peak since the previous boundary (`/proc/self/status` `VmRSS`, `VmHWM`),
//! then resets the peak (`/proc/self/clear_refs`), so each line's peak belongs to the
//! stage that just ended; and the process's CPU seconds (user + system, all threads,
//! `/proc/self/stat`) and wall seconds since the first boundary, so that each stage's
//! CPU and wall time, and how much of it ran on one core, can be read off. Off, or off
//! Linux, it costs one environment look-up per call.

use std::sync::OnceLock;
use std::time::Instant;

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

/// User plus system CPU seconds of the whole process (every thread) from
/// `/proc/self/stat`, in the kernel's clock ticks of 1/100 s (`USER_HZ` on Linux).
fn cpu_seconds() -> Option<f64> {
    let stat = std::fs::read_to_string("/proc/self/stat").ok()?;
    // Fields after the command name (which may hold spaces) closed by the last ')':
    // utime and stime are the 12th and 13th of them.
    let rest = &stat[stat.rfind(')')? + 1..];
    let mut fields = rest.split_whitespace().skip(11);
    let utime: u64 = fields.next()?.parse().ok()?;
    let stime: u64 = fields.next()?.parse().ok()?;
    Some((utime + stime) as f64 / 100.0)
}

/// Prints `label`'s line when the trace is on (see the module documentation).
pub fn mark(label: &str) {
    if std::env::var_os(MEMORY_TRACE_VAR).is_none() {
        return;
    }
    static FIRST: OnceLock<Instant> = OnceLock::new();
    let wall = FIRST.get_or_init(Instant::now).elapsed().as_secs_f64();
    if let Some((rss, peak)) = rss_and_peak() {
        let mb = |b: u64| b as f64 / 1e6;
        eprintln!(
            "memory: {label:<34} peak {:>9.1} MB, after {:>9.1} MB; cpu {:>8.2} s, wall {:>8.2} s",
            mb(peak),
            mb(rss),
            cpu_seconds().unwrap_or(f64::NAN),
            wall
        );
        // "5" resets the peak to the current resident size (Linux 4.0 and later).
        let _ = std::fs::write("/proc/self/clear_refs", "5");
    }
}
