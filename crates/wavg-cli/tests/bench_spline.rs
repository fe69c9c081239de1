//! `wavg bench spline --json` prints exactly the documented keys.

mod common;

use common::{assert_keys, s};

#[test]
fn bench_spline_json_keys() {
    let dir = tempfile::tempdir().unwrap();
    let control = dir.path().join("c.txt");
    std::fs::write(&control, "v 0\nv 500\nv 1000\nv 1500\nv 2000\n").unwrap();
    let keys = [
        "mesh",
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
        "load",
    ];
    let args = [
        "bench",
        "spline",
        "--mesh",
        "builtin:icosphere",
        "--control",
        &s(&control),
        "--samples",
        "50",
        "--repeat",
        "2",
        "--json",
    ];
    assert_keys(&args, &keys);
}
