//! `wavg bench project --json` prints exactly the documented keys, with sane values.

mod common;

use common::{json_object, wavg, wavg_ok};

#[test]
fn bench_project_reports_the_documented_json() {
    let args = ["bench", "project", "--mesh", "builtin:torus"];
    let out = wavg_ok(&[&args[..], &["--queries", "2000", "--json"]].concat());
    let (o, keys) = json_object(&out);
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
    let bad = wavg(&[&args[..], &["--queries", "0"]].concat());
    assert_eq!(bad.status.code(), Some(2));
}
