//! `wavg bench project --json` prints exactly the documented keys, with sane values.

use crate::common;

use common::{json_object, wavg, wavg_ok};
use wavg_testdata::json_keys::{BENCH_PROJECT, sorted};

#[test]
fn bench_project_reports_the_documented_json() {
    let args = ["bench", "project", "--mesh", "builtin:torus"];
    let out = wavg_ok(&[&args[..], &["--queries", "2000", "--json"]].concat());
    let (o, keys) = json_object(&out);
    assert_eq!(keys, sorted(BENCH_PROJECT, &["mesh"]));
    assert_eq!(o["queries"], 2000);
    assert_eq!(o["vertices"], 1536);
    assert!(o["onsurface_self_fraction"].as_f64().unwrap() >= 0.9999);
    assert!(o["offset_bruteforce_agree_fraction"].as_f64().unwrap() >= 0.999);
    for k in ["init_s", "bytes_per_face", "onsurface_us", "offset_us"] {
        assert!(o[k].as_f64().unwrap() > 0.0, "{k}");
    }
    for k in ["onsurface_fallback_fraction", "offset_fallback_fraction"] {
        let f = o[k].as_f64().unwrap();
        assert!((0.0..=1.0).contains(&f), "{k}: {f}");
    }
    // A mean time, or null when no query needed the global search.
    let any = o["onsurface_fallback_fraction"].as_f64().unwrap() > 0.0
        || o["offset_fallback_fraction"].as_f64().unwrap() > 0.0;
    if any {
        assert!(o["fallback_us"].as_f64().unwrap() > 0.0);
    } else {
        assert!(o["fallback_us"].is_null());
    }
    let bad = wavg(&[&args[..], &["--queries", "0"]].concat());
    assert_eq!(bad.status.code(), Some(2));
}
