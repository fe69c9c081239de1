//! `wavg bench project --json` prints exactly the documented keys, with sane values.

use std::process::Command;

#[test]
fn bench_project_reports_the_documented_json() {
    let out = Command::new(env!("CARGO_BIN_EXE_wavg"))
        .args([
            "bench",
            "project",
            "--mesh",
            "builtin:torus",
            "--queries",
            "2000",
            "--json",
        ])
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    let o = v.as_object().unwrap();
    let mut keys: Vec<&str> = o.keys().map(|k| k.as_str()).collect();
    keys.sort();
    assert_eq!(
        keys,
        [
            "bytes_per_face",
            "faces",
            "init_s",
            "mesh",
            "offset_bruteforce_agree_fraction",
            "offset_us",
            "onsurface_self_fraction",
            "onsurface_us",
            "queries",
            "vertices",
        ]
    );
    assert_eq!(o["queries"], 2000);
    assert_eq!(o["vertices"], 1536);
    assert!(o["onsurface_self_fraction"].as_f64().unwrap() >= 0.9999);
    assert!(o["offset_bruteforce_agree_fraction"].as_f64().unwrap() >= 0.999);
    for k in ["init_s", "bytes_per_face", "onsurface_us", "offset_us"] {
        assert!(o[k].as_f64().unwrap() > 0.0, "{k}");
    }
    let bad = Command::new(env!("CARGO_BIN_EXE_wavg"))
        .args([
            "bench",
            "project",
            "--mesh",
            "builtin:torus",
            "--queries",
            "0",
        ])
        .output()
        .unwrap();
    assert_eq!(bad.status.code(), Some(2));
}
