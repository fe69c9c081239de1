//! `wavg transfer-texture` run as a process: bad input (anchor counts that differ, a target
//! without UVs, an unreadable texture, anchors out of range) is refused and writes nothing.

use crate::common;

use common::wavg;

#[test]
fn bad_input_writes_nothing() {
    let Some(obj) =
        wavg_testdata::require_data_file("transfer_cli", "textured/spot/spot_triangulated.obj")
    else {
        return;
    };
    let png = obj.with_file_name("spot_texture.png");
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("out.png");
    let a3 = dir.path().join("a3.txt");
    let a4 = dir.path().join("a4.txt");
    let far = dir.path().join("far.txt");
    std::fs::write(&a3, "v 0\nv 100\nv 200\n").unwrap();
    std::fs::write(&a4, "v 0\nv 100\nv 200\nv 300\n").unwrap();
    std::fs::write(&far, "v 0\nv 100\nv 99999\n").unwrap();
    let (obj, png) = (obj.to_str().unwrap(), png.to_str().unwrap());
    let (a3, a4, far) = (
        a3.to_str().unwrap(),
        a4.to_str().unwrap(),
        far.to_str().unwrap(),
    );
    let missing = dir.path().join("missing.png");
    let missing = missing.to_str().unwrap();
    let run = |src_tex: &str, target: &str, sa: &str, ta: &str| {
        wavg(&[
            "transfer-texture",
            "--source",
            obj,
            "--source-texture",
            src_tex,
            "--target",
            target,
            "--source-anchors",
            sa,
            "--target-anchors",
            ta,
            "-o",
            out.to_str().unwrap(),
            "--size",
            "64",
        ])
    };
    for (r, msg) in [
        (run(png, obj, a3, a4), "must correspond"),
        (run(png, "builtin:icosphere", a3, a3), "texture coordinates"),
        (run(missing, obj, a3, a3), "missing.png"),
        (run(png, obj, a3, far), "99999"),
    ] {
        let err = String::from_utf8_lossy(&r.stderr);
        assert_eq!(r.status.code(), Some(2), "{err}");
        assert!(err.contains(msg), "{msg}: {err}");
        assert!(!out.exists());
    }
}
