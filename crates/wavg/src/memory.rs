//! Refusing a precomputation the machine's memory cannot hold, before it starts: the
//! peak resident size estimated from the mesh's counts, against the memory available
//! (`MemAvailable` of `/proc/meminfo`, and the process's cgroup limit less its usage when
//! one is set), so that a mesh too large is refused with both figures instead of being
//! killed by the kernel minutes later.

use crate::error::{Error, Result};

/// Bytes of the precomputation's peak per mesh vertex (faces included, about two per
/// vertex), above about 0.5M vertices: the peaks measured with the stage trace
/// (`WAVG_MEMORY_TRACE`) after the memory changes of issue 44 are 1.88 GB at 2.15M
/// vertices, 2.50 GB at 3.1M (806 B a vertex) and 7.43 GB at 10.3M (722 B a vertex), a
/// slope of 687 B a vertex from 3.1M to 10.3M, rounded up (`BENCHMARKS.md`).
pub const PEAK_BYTES_PER_VERTEX: u64 = 700;
/// Bytes of the peak whatever the mesh (the landmark stages' dense matrices, the
/// program): with [`PEAK_BYTES_PER_VERTEX`], it covers the measured peaks with a margin
/// (3.17 GB estimated against 2.50 GB at 3.1M vertices, 8.20 GB against 7.43 GB at 10.3M).
pub const PEAK_BYTES_BASE: u64 = 1_000_000_000;
/// Below about 0.5M vertices the peak follows a steeper, lower line (the least-squares
/// mesh is factored directly): 300 MB + 2,000 B a vertex covers the peaks measured at 0.2M
/// and 0.5M, so that small meshes are not refused on small machines.
const SMALL_BASE: u64 = 300_000_000;
const SMALL_PER_VERTEX: u64 = 2000;

/// The environment variable that overrides the memory available (bytes, or with a `K`,
/// `M` or `G` suffix): for tests, and to let a precomputation run that the estimate
/// would refuse.
pub const MEMORY_AVAILABLE_VAR: &str = "WAVG_MEMORY_AVAILABLE";

/// A precomputation refused for want of memory: the estimate and what was available.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct MemoryShortfall {
    /// Vertices of the mesh.
    pub vertices: usize,
    /// Estimated peak resident bytes of the precomputation.
    pub needed: u64,
    /// Bytes available when it was asked.
    pub available: u64,
    /// Where `available` came from (`/proc/meminfo`, the cgroup, the environment).
    pub source: &'static str,
}

impl std::fmt::Display for MemoryShortfall {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let gb = |b: u64| b as f64 / 1e9;
        write!(
            f,
            "the precomputation of this mesh ({} vertices) needs about {:.2} GB of memory at \
             its peak, and {:.2} GB are available ({}): decimate the mesh first or \
             free memory (set {MEMORY_AVAILABLE_VAR} to override the check)",
            self.vertices,
            gb(self.needed),
            gb(self.available),
            self.source
        )
    }
}

/// The estimated peak resident bytes of precomputing a mesh of `vertices` vertices.
///
/// ```
/// let small = wavg::precompute_peak_bytes(10_000);
/// assert!(small < wavg::precompute_peak_bytes(10_000_000));
/// ```
pub fn precompute_peak_bytes(vertices: usize) -> u64 {
    let line = |base: u64, per_vertex: u64| {
        base.saturating_add(per_vertex.saturating_mul(vertices as u64))
    };
    line(PEAK_BYTES_BASE, PEAK_BYTES_PER_VERTEX).min(line(SMALL_BASE, SMALL_PER_VERTEX))
}

/// The memory this process may still use, and where the figure came from: the
/// environment override, else the smaller of `MemAvailable` and the cgroup's room;
/// `None` when neither can be read (then nothing is refused). An override that is not a
/// byte count is an [`crate::ErrorKind::InvalidArgument`] naming the variable and its
/// value, rather than a check silently skipped.
pub fn available_memory() -> Result<Option<(u64, &'static str)>> {
    if let Some(v) = std::env::var_os(MEMORY_AVAILABLE_VAR) {
        return override_bytes(&v.to_string_lossy()).map(|b| Some((b, MEMORY_AVAILABLE_VAR)));
    }
    let meminfo = std::fs::read_to_string("/proc/meminfo").ok();
    let mem = meminfo.as_deref().and_then(mem_available);
    let cgroup = cgroup_room();
    Ok(match (mem, cgroup) {
        (Some(m), Some(c)) if c < m => Some((c, "the cgroup's memory limit less its usage")),
        (Some(m), _) => Some((m, "MemAvailable in /proc/meminfo")),
        (None, Some(c)) => Some((c, "the cgroup's memory limit less its usage")),
        (None, None) => None,
    })
}

/// The value of [`MEMORY_AVAILABLE_VAR`] in bytes, or the error naming it.
fn override_bytes(value: &str) -> Result<u64> {
    parse_bytes(value).ok_or_else(|| {
        Error::Embed(wavg_embed::EmbedError::InvalidArgument(format!(
            "{MEMORY_AVAILABLE_VAR}={value:?} is not a byte count: write a whole number of \
             bytes, or one with a K, M or G suffix (powers of 1024), such as 8G"
        )))
    })
}

/// Bytes of dense landmark-by-landmark matrices a precomputation holds per landmark pair.
const LANDMARK_PAIR_BYTES: u64 = 40;

/// Refuses a precomputation of `vertices` vertices that needs more than `available`;
/// `landmarks` adds what their dense matrices take (the MDS's distances, Gram matrix and
/// eigenvectors, the extension's landmark rows: about 40 bytes a landmark pair), which is
/// small at the default 1,000 but dominates when nearly every vertex is one.
pub(crate) fn check_fits(
    vertices: usize,
    landmarks: usize,
    available: Option<(u64, &'static str)>,
) -> Result<()> {
    let landmarks = landmarks.min(vertices) as u64;
    let needed = precompute_peak_bytes(vertices)
        .saturating_add(LANDMARK_PAIR_BYTES.saturating_mul(landmarks.saturating_mul(landmarks)));
    match available {
        Some((available, source)) if needed > available => {
            Err(Error::OutOfMemory(Box::new(MemoryShortfall {
                vertices,
                needed,
                available,
                source,
            })))
        }
        _ => Ok(()),
    }
}

/// `MemAvailable` of `/proc/meminfo`'s text, in bytes.
fn mem_available(meminfo: &str) -> Option<u64> {
    let line = meminfo.lines().find(|l| l.starts_with("MemAvailable:"))?;
    let kb: u64 = line.split_whitespace().nth(1)?.parse().ok()?;
    kb.checked_mul(1024)
}

/// The room left under the memory limit of this process's cgroup (v2, then v1).
fn cgroup_room() -> Option<u64> {
    let read = |p: &str| std::fs::read_to_string(p).ok();
    let own = read("/proc/self/cgroup").and_then(|s| {
        s.lines()
            .find_map(|l| l.strip_prefix("0::").map(String::from))
    });
    let mut dirs = Vec::new();
    if let Some(own) = own.filter(|o| o != "/") {
        dirs.push(format!("/sys/fs/cgroup{own}"));
    }
    dirs.push("/sys/fs/cgroup".to_string());
    for dir in dirs {
        let limit = read(&format!("{dir}/memory.max")).and_then(|s| s.trim().parse::<u64>().ok());
        let used =
            read(&format!("{dir}/memory.current")).and_then(|s| s.trim().parse::<u64>().ok());
        if let (Some(limit), Some(used)) = (limit, used) {
            return Some(limit.saturating_sub(used));
        }
    }
    let limit = read("/sys/fs/cgroup/memory/memory.limit_in_bytes")?;
    let used = read("/sys/fs/cgroup/memory/memory.usage_in_bytes")?;
    let (limit, used): (u64, u64) = (limit.trim().parse().ok()?, used.trim().parse().ok()?);
    // v1 reports "no limit" as a huge number.
    (limit < 1 << 60).then(|| limit.saturating_sub(used))
}

/// Bytes written as a number with an optional `K`, `M` or `G` suffix (powers of 1024).
fn parse_bytes(text: &str) -> Option<u64> {
    let t = text.trim();
    let (digits, shift) = match t.as_bytes().last()? {
        b'K' | b'k' => (&t[..t.len() - 1], 10),
        b'M' | b'm' => (&t[..t.len() - 1], 20),
        b'G' | b'g' => (&t[..t.len() - 1], 30),
        _ => (t, 0),
    };
    digits.trim().parse::<u64>().ok()?.checked_mul(1 << shift)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::ErrorKind;

    #[test]
    fn a_mesh_beyond_the_available_memory_is_refused_with_both_figures() {
        let e = check_fits(3_000_000, 0, Some((2_000_000_000, "a test"))).unwrap_err();
        assert_eq!(e.kind(), ErrorKind::OutOfMemory);
        assert!(!e.kind().is_callers_fault());
        let m = e.message();
        assert!(
            m.contains("3000000 vertices") && m.contains("3.10 GB"),
            "{m}"
        );
        assert!(m.contains("2.00 GB are available (a test)"), "{m}");
        assert!(check_fits(3_000_000, 1_000, Some((3_200_000_000, "a test"))).is_ok());
        assert!(check_fits(3_000_000, 1_000, None).is_ok());
        // Small meshes follow the lower line: 320 MB for 10,000 vertices.
        assert_eq!(precompute_peak_bytes(10_000), 320_000_000);
        assert_eq!(
            precompute_peak_bytes(3_000_000),
            1_000_000_000 + 2_100_000_000
        );
        // The estimate covers the peaks measured at 3.1M and 10.3M vertices (722 B a
        // vertex at 10.3M), and a 10.3M-vertex mesh fits a machine with 8.5 GB free.
        assert!(precompute_peak_bytes(3_102_914) > 2_502_500_000);
        assert!(precompute_peak_bytes(10_285_056) > 7_431_000_000);
        assert!(check_fits(10_285_056, 1_000, Some((8_500_000_000, "a test"))).is_ok());
    }

    #[test]
    fn landmarks_count_in_the_estimate() {
        // Every vertex of a 100k-vertex mesh as a landmark needs its dense matrices (400 GB);
        // the default 1,000 add 40 MB.
        let room = Some((16_000_000_000, "a test"));
        assert!(check_fits(100_000, 1_000, room).is_ok());
        let e = check_fits(100_000, usize::MAX, room).unwrap_err();
        assert_eq!(e.kind(), ErrorKind::OutOfMemory);
        // More landmarks than vertices count as one per vertex.
        assert!(check_fits(5_000, usize::MAX, room).is_ok());
    }

    #[test]
    fn meminfo_cgroup_and_override_figures_parse() {
        let text = "MemTotal:       24000000 kB\nMemAvailable:   16000000 kB\n";
        assert_eq!(mem_available(text), Some(16_000_000 * 1024));
        assert_eq!(mem_available("MemTotal: 1 kB\n"), None);
        assert_eq!(parse_bytes("1M"), Some(1 << 20));
        assert_eq!(parse_bytes(" 3g "), Some(3 << 30));
        assert_eq!(parse_bytes("12345"), Some(12345));
        assert_eq!(parse_bytes("lots"), None);
        // This machine has a /proc/meminfo.
        if std::env::var_os(MEMORY_AVAILABLE_VAR).is_none() {
            assert!(available_memory().unwrap().is_some_and(|(b, _)| b > 0));
        }
    }

    #[test]
    fn an_override_that_is_not_a_byte_count_is_refused_by_name() {
        assert_eq!(override_bytes("8G").unwrap(), 8 << 30);
        for bad in ["lots", "", "-1", "1.5G", "8GB"] {
            let e = override_bytes(bad).unwrap_err();
            assert_eq!(e.kind(), ErrorKind::InvalidArgument);
            let m = e.message();
            assert!(m.contains(&format!("WAVG_MEMORY_AVAILABLE={bad:?}")), "{m}");
        }
    }
}
