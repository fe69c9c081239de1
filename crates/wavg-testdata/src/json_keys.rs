//! The documented `--json` keys of the `wavg bench` reports, less those the command adds
//! itself (`mesh`; `load` for `bench spline`): one list each, checked against the
//! protocols' reports by `wavg-bench`'s tests and, with the command's own keys, against
//! the printed objects by `wavg-cli`'s. A contract kept in the tests, apart from the types
//! that serialise it.

/// `wavg bench project`.
pub const BENCH_PROJECT: &[&str] = &[
    "vertices",
    "faces",
    "queries",
    "init_s",
    "bytes_per_face",
    "onsurface_us",
    "onsurface_self_fraction",
    "offset_us",
    "offset_bruteforce_agree_fraction",
    "onsurface_fallback_fraction",
    "offset_fallback_fraction",
    "fallback_us",
];

/// `wavg bench load`.
pub const BENCH_LOAD: &[&str] = &[
    "vertices",
    "faces",
    "bytes",
    "repeat",
    "valid",
    "topology_built",
    "read_s",
    "parse_s",
    "validate_topology_s",
    "total_s",
];

/// `wavg bench spline` (the command adds `load` too).
pub const BENCH_SPLINE: &[&str] = &[
    "controls",
    "samples",
    "ok_samples",
    "threads",
    "repeat",
    "us_per_sample",
    "us_per_sample_median",
    "cpu_us_per_sample",
    "agree_fraction",
    "max_disagreement",
];

/// `wavg bench roundtrip`.
pub const BENCH_ROUNDTRIP: &[&str] = &[
    "anchors",
    "faces",
    "forward_us",
    "forward_warm_us",
    "inverse_us",
    "negative_weight_fraction",
    "queries",
    "roundtrip_err_p50",
    "roundtrip_err_p99",
    "roundtrip_ok_fraction",
    "threads",
    "vertices",
];

/// What `wavg bench roundtrip --verified` adds to [`BENCH_ROUNDTRIP`].
pub const BENCH_ROUNDTRIP_VERIFIED: &[&str] = &[
    "verified_inverse_us",
    "verified_negative_weight_fraction",
    "verified_not_reached_fraction",
    "verified_penalized_fraction",
    "verified_roundtrip_ok_fraction",
];

/// `keys` and `extra` together, sorted: the expected key set of an object.
pub fn sorted(keys: &[&str], extra: &[&str]) -> Vec<String> {
    let mut v: Vec<String> = keys.iter().chain(extra).map(|k| k.to_string()).collect();
    v.sort();
    v
}
