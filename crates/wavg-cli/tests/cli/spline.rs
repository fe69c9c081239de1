//! `wavg spline` run as a process: JSON keys, the curve file, clamped ends on their control
//! points, and errors that write nothing.

use crate::common;

use common::{json_object, wavg, wavg_ok};

fn lines(path: &std::path::Path) -> Vec<Vec<f64>> {
    std::fs::read_to_string(path)
        .unwrap()
        .lines()
        .map(|l| l.split_whitespace().map(|x| x.parse().unwrap()).collect())
        .collect()
}

#[test]
fn open_closed_and_bezier_curves() {
    let dir = tempfile::tempdir().unwrap();
    let control = dir.path().join("c.txt");
    std::fs::write(&control, "v 0\nv 500\nv 1000\nv 1500\nv 2000\nv 2500\n").unwrap();
    let out = dir.path().join("curve.txt");
    let (c, o_) = (control.to_str().unwrap(), out.to_str().unwrap());
    let base = [
        "spline",
        "--mesh",
        "builtin:icosphere",
        "--control",
        c,
        "-o",
        o_,
        "--json",
    ];
    let run = wavg_ok(&[&base[..], &["--samples", "300"]].concat());
    let (o, keys) = json_object(&run);
    for k in [
        "samples",
        "ok_samples",
        "seconds",
        "us_per_sample",
        "length",
    ] {
        assert!(keys.iter().any(|x| x == k), "missing {k} in {keys:?}");
    }
    assert_eq!(o["samples"], 300);
    assert_eq!(o["ok_samples"], 300);
    let curve = lines(&out);
    assert_eq!(curve.len(), 300);
    // Clamped: the first sample is vertex 0, the last vertex 2500 (icosphere level 4).
    let mesh = wavg::mesh::procedural::icosphere(4);
    let (first, last) = (&curve[0][4..7], &curve[299][4..7]);
    for (p, v) in [(first, 0usize), (last, 2500)] {
        let q = mesh.positions[v];
        let d = ((p[0] - q.x).powi(2) + (p[1] - q.y).powi(2) + (p[2] - q.z).powi(2)).sqrt();
        assert!(d < 1e-9, "end {v} off by {d}");
    }
    let length = o["length"].as_f64().unwrap();
    assert!(length > 0.0 && length.is_finite());

    for extra in [&["--closed"][..], &["--bezier"][..], &["--degree", "5"][..]] {
        let args = [&base[..], extra].concat();
        let (o, _) = json_object(&wavg_ok(&args));
        assert_eq!(o["ok_samples"], 500, "{extra:?}");
    }
}

#[test]
fn bad_input_writes_nothing() {
    let dir = tempfile::tempdir().unwrap();
    let control = dir.path().join("c.txt");
    std::fs::write(&control, "v 0\nv 500\nv 1000\n").unwrap();
    let out = dir.path().join("curve.txt");
    let s = |p: &std::path::Path| p.to_str().unwrap().to_string();
    let args = [
        "spline",
        "--mesh",
        "builtin:sphere-small",
        "--control",
        &s(&control),
        "-o",
        &s(&out),
    ];
    // Three controls are too few for a cubic.
    let r = wavg(&args);
    assert_eq!(
        r.status.code(),
        Some(2),
        "{}",
        String::from_utf8_lossy(&r.stderr)
    );
    assert!(!out.exists());
    // A control point out of range names its line.
    std::fs::write(&control, "v 0\nv 1\nv 2\nv 99999\n").unwrap();
    let r = wavg(&args);
    assert_eq!(r.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&r.stderr).contains(":4:"));
    assert!(!out.exists());
}

/// Counts beyond what one run takes are refused before any work (they once tried to
/// allocate terabytes and aborted).
#[test]
fn huge_counts_are_refused() {
    for args in [
        &[
            "spline",
            "builtin:torus",
            "--control",
            "c.txt",
            "--samples",
            "100000000000",
            "-o",
            "x.txt",
        ][..],
        &[
            "bench",
            "roundtrip",
            "builtin:torus",
            "--queries",
            "18446744073709551615",
        ][..],
        &["demo", "--samples", "20000000"][..],
    ] {
        let out = common::wavg(args);
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(2), "{args:?}: {stderr}");
        assert!(
            stderr.contains("the most one run takes"),
            "{args:?}: {stderr}"
        );
        assert!(!stderr.contains("panicked"), "{stderr}");
    }
}
