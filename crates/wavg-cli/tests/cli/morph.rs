//! `wavg morph` run as a process: the frames it writes, and none left when one fails.

use crate::common;

use std::path::Path;

use common::{json_object, sphere_anchors, wavg, wavg_ok};

/// `wavg morph` of the icosphere onto itself with anchors `a`, 4 frames into `out`.
fn morph_args(a: &str, out: &Path) -> Vec<String> {
    let m = "builtin:icosphere";
    let mut args = common::pair_args("morph", [m, m], [a, a], out.to_str().unwrap());
    args.extend(["--frames", "4"].map(String::from));
    args
}

#[test]
fn morph_writes_the_frames() {
    let dir = tempfile::tempdir().unwrap();
    let a = sphere_anchors(dir.path()).to_str().unwrap().to_string();
    let out = dir.path().join("frames");
    let mut args = morph_args(&a, &out);
    args.push("--json".into());
    let r = wavg_ok(&args.iter().map(String::as_str).collect::<Vec<_>>());
    let (o, keys) = json_object(&r);
    for k in ["frames", "valid_fraction", "seconds"] {
        assert!(keys.iter().any(|x| x == k), "missing {k} in {keys:?}");
    }
    assert_eq!(o["frames"], 4);
    for k in 0..4 {
        let f = std::fs::read_to_string(out.join(format!("frame_{k:03}.obj"))).unwrap();
        assert_eq!(f.lines().filter(|l| l.starts_with("v ")).count(), 2562);
    }
    assert!(!out.join("frame_004.obj").exists());
}

/// A frame that cannot be written (its name is taken by a folder) fails the command and
/// takes the frames written before it along: nothing half-written.
#[test]
fn morph_removes_its_frames_when_one_fails() {
    let dir = tempfile::tempdir().unwrap();
    let a = sphere_anchors(dir.path()).to_str().unwrap().to_string();
    let out = dir.path().join("frames");
    std::fs::create_dir_all(out.join("frame_002.obj")).unwrap();
    let args = morph_args(&a, &out);
    let r = wavg(&args.iter().map(String::as_str).collect::<Vec<_>>());
    assert!(!r.status.success());
    let err = String::from_utf8_lossy(&r.stderr);
    assert!(err.contains("frame_002.obj"), "{err}");
    let mut left: Vec<_> = std::fs::read_dir(&out)
        .unwrap()
        .map(|e| e.unwrap().file_name().into_string().unwrap())
        .collect();
    left.sort();
    assert_eq!(left, ["frame_002.obj"]);
}
