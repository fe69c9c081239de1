//! `wavg bench load` as a process: JSON figures on a small file, exit 2 on bad input.

use crate::common;

use wavg::mesh::{io, procedural};

#[test]
fn bench_load_reports_every_stage() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("s.off.gz");
    io::save(&path, &procedural::icosphere(3)).unwrap();
    let out = common::wavg_command()
        .args([
            "bench",
            "load",
            "--mesh",
            path.to_str().unwrap(),
            "--repeat",
            "2",
            "--json",
        ])
        .output()
        .unwrap();
    assert_eq!(
        out.status.code(),
        Some(0),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let j: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(j["vertices"], 642);
    assert_eq!(j["valid"], true);
    let stages = ["read_s", "parse_s", "validate_topology_s", "total_s"];
    for k in stages {
        let t = j[k].as_f64().unwrap_or(-1.0);
        assert!((0.0..10.0).contains(&t), "{k} = {t}");
    }
    let sum: f64 = stages[..3].iter().map(|k| j[k].as_f64().unwrap()).sum();
    assert!(j["total_s"].as_f64().unwrap() >= sum * 0.999);

    let bad = dir.path().join("t.off");
    std::fs::write(&bad, "OFF\n3 1 0\n0 0 0\n").unwrap();
    let out = common::wavg_command()
        .args(["bench", "load", "--mesh", bad.to_str().unwrap()])
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&out.stderr).contains("t.off:4:"));
}
