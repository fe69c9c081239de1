//! Library errors reach the exit status through the CLI's one table: the caller's input
//! (unreadable or malformed files, bad values) exits 2, a failure that is not the input's
//! (a file that cannot be written) exits 1; either way one line on stderr.

mod common;

use common::wavg;

/// The exit status and stderr of a failed run; stderr must be one line.
fn failed(args: &[&str]) -> (Option<i32>, String) {
    let out = wavg(args);
    let err = String::from_utf8_lossy(&out.stderr).into_owned();
    assert_eq!(err.trim_end().lines().count(), 1, "{args:?}: {err}");
    assert!(!err.contains("panicked"), "{err}");
    (out.status.code(), err)
}

#[test]
fn library_input_errors_exit_2() {
    let dir = tempfile::tempdir().unwrap();
    let junk = dir.path().join("junk.wavg");
    std::fs::write(&junk, b"not an embedding").unwrap();
    let junk = junk.to_str().unwrap();
    // A corrupt embedding file (the embedding layer's error).
    let (code, err) = failed(&[
        "anchors",
        "builtin:torus",
        "--count",
        "4",
        "--embedding",
        junk,
        "-o",
        "-",
    ]);
    assert_eq!(code, Some(2), "{err}");
    assert!(err.contains("junk.wavg"), "{err}");
    // An unknown builtin mesh (the mesh layer's argument error).
    let (code, err) = failed(&["info", "builtin:no-such-mesh"]);
    assert_eq!(code, Some(2), "{err}");
}

#[cfg(unix)]
#[test]
fn a_failed_write_exits_1() {
    if !std::path::Path::new("/dev/full").exists() {
        eprintln!("skipped: no /dev/full");
        return;
    }
    // An output that exists and is a device is written in place: /dev/full refuses it.
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("fixed.obj");
    std::os::unix::fs::symlink("/dev/full", &out).unwrap();
    let (code, err) = failed(&["repair", "builtin:torus", "-o", out.to_str().unwrap()]);
    assert_eq!(code, Some(1), "{err}");
    assert!(
        err.contains("fixed.obj") && err.contains("No space"),
        "{err}"
    );
}
