//! `wavg render` run as a process: a PNG of the right size with JSON keys, and bad input
//! (missing texture, texture without UVs, wrong scalar count) refused with nothing written.

mod common;

use common::{json_object, wavg, wavg_ok};

#[test]
fn renders_a_png_and_reports_json() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("a.png");
    let scal = dir.path().join("s.txt");
    let n = 2562; // builtin:icosphere
    let text: String = (0..n).map(|i| format!("{}\n", i as f64 / 7.0)).collect();
    std::fs::write(&scal, text).unwrap();
    let pts = dir.path().join("p.txt");
    std::fs::write(&pts, "v 0\nf 3 0.2 0.3 0.5\n").unwrap();
    let run = wavg_ok(&[
        "render",
        "builtin:icosphere",
        "-o",
        out.to_str().unwrap(),
        "--size",
        "120x90",
        "--scalar",
        scal.to_str().unwrap(),
        "--points",
        pts.to_str().unwrap(),
        "--wireframe",
        "--view",
        "-20,10",
        "--json",
    ]);
    let (o, _) = json_object(&run);
    assert_eq!(o["width"], 120);
    assert_eq!(o["height"], 90);
    let f = o["covered_fraction"].as_f64().unwrap();
    assert!(f > 0.2 && f < 0.9, "{f}");
    let bytes = std::fs::read(&out).unwrap();
    assert_eq!(&bytes[1..4], b"PNG");
    assert!(o["scalar_max"].as_f64().unwrap() > 365.0);
}

#[test]
fn bad_input_writes_nothing() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("a.png");
    let o = out.to_str().unwrap();
    let missing = dir.path().join("missing.png");
    let tex = dir.path().join("t.png");
    // A valid PNG written by a previous render.
    let tmp = dir.path().join("tmp.png");
    wavg_ok(&[
        "render",
        "builtin:icosphere",
        "-o",
        tmp.to_str().unwrap(),
        "--size",
        "4x4",
    ]);
    std::fs::copy(&tmp, &tex).unwrap();
    let scal = dir.path().join("s.txt");
    std::fs::write(&scal, "1\n2\n3\n").unwrap();
    for (extra, msg) in [
        (vec!["--texture", missing.to_str().unwrap()], "missing.png"),
        (
            vec!["--texture", tex.to_str().unwrap()],
            "texture coordinates",
        ),
        (
            vec!["--scalar", scal.to_str().unwrap()],
            "3 scalars for 2562 vertices",
        ),
        (vec!["--size", "0x5"], "--size"),
    ] {
        let r = wavg(&[&["render", "builtin:icosphere", "-o", o][..], &extra].concat());
        let err = String::from_utf8_lossy(&r.stderr);
        assert_eq!(r.status.code(), Some(2), "{err}");
        assert!(err.contains(msg), "{err}");
        assert!(!out.exists());
    }
}
