//! Library errors reach the exit status through the CLI's one table: the caller's input
//! (unreadable or malformed files, bad values) exits 2, a failure that is not the input's
//! (a file that cannot be written) exits 1; either way one line on stderr.

use crate::common;

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

/// A write that fails before its temporary file exists (`/proc` takes no new files, even
/// from root) names the file asked for, never the temporary file beside it.
#[cfg(target_os = "linux")]
#[test]
fn a_failed_write_names_the_file_asked_for() {
    let (code, err) = failed(&["repair", "builtin:torus", "-o", "/proc/fixed.obj"]);
    assert_eq!(code, Some(1), "{err}");
    assert!(
        err.contains("/proc/fixed.obj") && !err.contains(".wavg-tmp"),
        "{err}"
    );
}

/// A precomputation the machine's memory cannot hold is refused before it starts (exit
/// 1, not the input's fault), with the estimate and the available memory, and nothing is
/// written; the environment override stands in for a small machine.
#[test]
fn a_precomputation_beyond_the_available_memory_is_refused_up_front() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("t.wavg");
    let run = |available: &str| {
        common::wavg_command()
            .env("WAVG_MEMORY_AVAILABLE", available)
            .args(["precompute", "builtin:torus", "-o", out.to_str().unwrap()])
            .output()
            .unwrap()
    };
    let t = std::time::Instant::now();
    let refused = run("1M");
    let err = String::from_utf8_lossy(&refused.stderr);
    assert_eq!(refused.status.code(), Some(1), "{err}");
    assert_eq!(err.trim_end().lines().count(), 1, "{err}");
    assert!(
        err.contains("needs about") && err.contains("0.00 GB are available"),
        "{err}"
    );
    assert!(err.contains("WAVG_MEMORY_AVAILABLE"), "{err}");
    assert!(!out.exists());
    assert!(t.elapsed().as_secs() < 30, "refused up front");
    // The same with room: computed.
    // An override that is not a byte count is the caller's error, named, not a check
    // skipped.
    let bad = run("lots");
    let err = String::from_utf8_lossy(&bad.stderr);
    assert_eq!(bad.status.code(), Some(2), "{err}");
    assert!(err.contains("WAVG_MEMORY_AVAILABLE=\"lots\""), "{err}");
    assert!(!out.exists());
    let ok = run("64G");
    assert!(
        ok.status.success(),
        "{}",
        String::from_utf8_lossy(&ok.stderr)
    );
    assert!(out.exists());
}

/// Options out of their range are refused while the arguments are read (status 2, before
/// any mesh is read or embedding computed), the message naming the option and the range.
#[test]
fn options_out_of_range_name_their_range() {
    let refused = |args: &[&str], says: &[&str]| {
        let out = wavg(args);
        let err = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(2), "{args:?}: {err}");
        for s in says {
            assert!(err.contains(s), "{args:?}: {err}");
        }
    };
    // The files need not exist: the value is refused first.
    let decal = |v: &str| {
        let args = [
            "decal",
            "missing.obj",
            "--anchors",
            "a.txt",
            "--uv",
            "uv.txt",
        ];
        let mut all: Vec<String> = args.map(String::from).to_vec();
        all.extend(["--max-negative", v, "-o", "d.obj"].map(String::from));
        all
    };
    for v in ["5", "0.1", "nan", "inf"] {
        let args = decal(v);
        let args: Vec<&str> = args.iter().map(String::as_str).collect();
        refused(&args, &["--max-negative", "at most 0"]);
    }
    let pair = common::pair_args("correspond", ["s.obj", "t.obj"], ["a", "b"], "m.txt");
    let mut args: Vec<&str> = pair.iter().map(String::as_str).collect();
    args.extend(["--max-negative", "2"]);
    refused(&args, &["--max-negative", "at most 0"]);
    let mut args: Vec<&str> = pair.iter().map(String::as_str).collect();
    args.extend(["--max-stretch", "1"]);
    refused(&args, &["--max-stretch", "above 1"]);
    refused(
        &[
            "remesh",
            "s.obj",
            "--base",
            "b.obj",
            "--max-distance",
            "-0.1",
            "-o",
            "r.obj",
        ],
        &["--max-distance", "finite and positive"],
    );
    let pair = common::pair_args("transfer-texture", ["s.obj", "t.obj"], ["a", "b"], "t.png");
    for v in ["0", "65"] {
        let mut args: Vec<&str> = pair.iter().map(String::as_str).collect();
        args.extend(["--stride", v]);
        refused(&args, &["--stride", "1..=64"]);
    }
}
