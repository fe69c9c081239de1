//! Outputs that are not regular files: a named pipe as `-o` is written through, never
//! replaced by a file, and gets nothing when a later chunk of the input is bad.
#![cfg(unix)]

use crate::common;

use std::os::unix::fs::FileTypeExt;

use common::{icosphere_forward, sphere_anchors};

#[test]
fn a_named_pipe_gets_nothing_when_a_later_chunk_is_bad() {
    let dir = tempfile::tempdir().unwrap();
    let fifo = dir.path().join("pipe");
    let made = std::process::Command::new("mkfifo").arg(&fifo).status();
    if !made.is_ok_and(|st| st.success()) {
        eprintln!("skipped: mkfifo is not available");
        return;
    }
    let anchors = sphere_anchors(dir.path());
    let k = 31;
    let good = vec![format!("{:?}", 1.0 / k as f64); k].join(" ");
    // Three chunks of 65,536 lines; the bad line (weights summing to 2) in the third.
    let n = 140_000;
    let mut text = String::with_capacity(n * (good.len() + 1));
    for i in 0..n {
        let line = if i == n - 10 {
            "2 ".repeat(k - 1) + "-28"
        } else {
            good.clone()
        };
        text.push_str(&line);
        text.push('\n');
    }
    let weights = dir.path().join("w.txt");
    std::fs::write(&weights, text).unwrap();
    let reader = {
        let fifo = fifo.clone();
        std::thread::spawn(move || std::fs::read(fifo).unwrap())
    };
    let out = icosphere_forward(&anchors, &weights, &fifo);
    assert_eq!(
        out.status.code(),
        Some(2),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    assert!(String::from_utf8_lossy(&out.stderr).contains(&format!("w.txt:{}:", n - 9)));
    // Unblock the reader if the command never opened the pipe (opening a pipe for reading
    // and writing does not wait for the other end, so this never blocks).
    drop(
        std::fs::OpenOptions::new()
            .read(true)
            .write(true)
            .open(&fifo)
            .unwrap(),
    );
    assert!(
        reader.join().unwrap().is_empty(),
        "the pipe got rows before the bad line"
    );
    let kind = std::fs::symlink_metadata(&fifo).unwrap().file_type();
    assert!(kind.is_fifo(), "the pipe was replaced by a file");
}

/// `wavg ... -o - | head`: the reader stops early; wavg stops quietly with status 0.
#[test]
fn a_reader_that_stops_early_is_no_failure() {
    let dir = tempfile::tempdir().unwrap();
    let anchors = dir.path().join("a.txt");
    std::fs::write(
        &anchors,
        "v 0\nv 300\nv 600\nv 900\nv 1200\nv 1500\nv 1800\n",
    )
    .unwrap();
    let points = dir.path().join("p.txt");
    let text: String = (0..200_000)
        .map(|i| format!("f {} 0.2 0.3 0.5\n", i % 5000))
        .collect();
    std::fs::write(&points, text).unwrap();
    let cmd = format!(
        "'{}' inverse builtin:icosphere --embedding none --anchors '{}' --points '{}' -o - \
         | head -n 2 >/dev/null; echo \"status ${{PIPESTATUS[0]}}\"",
        env!("CARGO_BIN_EXE_wavg"),
        anchors.display(),
        points.display()
    );
    let stderr = exits_zero(&cmd);
    assert!(!stderr.contains("Broken pipe"), "{stderr}");
}

/// Runs the bash pipeline `cmd`, which ends by echoing `status $?` of its first command;
/// asserts that it was 0 and returns the standard error.
fn exits_zero(cmd: &str) -> String {
    let out = std::process::Command::new("bash")
        .args(["-c", cmd])
        .env("WAVG_CACHE_DIR", common::cache_dir())
        .output()
        .unwrap();
    let (stdout, stderr) = (
        String::from_utf8_lossy(&out.stdout),
        String::from_utf8_lossy(&out.stderr).into_owned(),
    );
    assert_eq!(stdout.trim(), "status 0", "{stderr}");
    stderr
}

/// A query file that can be read only once (a pipe as `--weights /dev/stdin`) with an
/// output that needs two passes (`-o -`, or `.npy` from text): the same answers as from a
/// regular file.
#[test]
fn a_piped_query_file_read_twice_gives_every_answer() {
    use std::io::Write;
    let dir = tempfile::tempdir().unwrap();
    let anchors = sphere_anchors(dir.path());
    let k = 31;
    let text: String = (0..300)
        .map(|i| {
            let mut w = vec![0.0; k];
            w[i % k] = 0.6;
            w[(i + 7) % k] = 0.4;
            w.iter().map(|x| format!("{x} ")).collect::<String>() + "\n"
        })
        .collect();
    let file = dir.path().join("w.txt");
    std::fs::write(&file, &text).unwrap();
    let forward = |weights: &str, out: &str| {
        let mut c = common::wavg_command();
        c.args([
            "forward",
            "--mesh",
            "builtin:icosphere",
            "--embedding",
            "none",
        ])
        .arg("--anchors")
        .arg(&anchors)
        .args(["--weights", weights, "-o", out])
        .current_dir(dir.path());
        c
    };
    let from_file = forward("w.txt", "-").output().unwrap();
    assert!(from_file.status.success());
    let from_file = String::from_utf8(from_file.stdout).unwrap();
    assert_eq!(from_file.lines().count(), 300);
    for out in ["-", "o.npy"] {
        let mut child = forward("/dev/stdin", out)
            .stdin(std::process::Stdio::piped())
            .stdout(std::process::Stdio::piped())
            .stderr(std::process::Stdio::piped())
            .spawn()
            .unwrap();
        child
            .stdin
            .take()
            .unwrap()
            .write_all(text.as_bytes())
            .unwrap();
        let piped = child.wait_with_output().unwrap();
        let stderr = String::from_utf8_lossy(&piped.stderr);
        assert!(piped.status.success(), "-o {out}: {stderr}");
        if out == "-" {
            assert!(
                String::from_utf8_lossy(&piped.stdout) == from_file,
                "-o -: other answers than from the file ({} bytes); {stderr}",
                piped.stdout.len()
            );
        } else {
            let npy = std::fs::read(dir.path().join(out)).unwrap();
            // 300 rows of 7 float64 after the header.
            assert!(npy.len() > 300 * 7 * 8, "{} bytes", npy.len());
            assert!(npy.len() < 300 * 7 * 8 + 256, "{} bytes", npy.len());
        }
    }
}

/// A report printed to a reader that has stopped (`wavg info M | true`): no panic, status 0.
#[test]
fn a_report_to_a_closed_pipe_is_no_failure() {
    let cmd = format!(
        "'{}' info builtin:torus | true; echo \"status ${{PIPESTATUS[0]}}\"",
        env!("CARGO_BIN_EXE_wavg"),
    );
    let stderr = exits_zero(&cmd);
    assert!(!stderr.contains("panicked"), "{stderr}");
}

/// A report that cannot be printed for another reason (a full disk): one line, status 1.
#[test]
fn a_report_to_a_full_disk_is_a_failure_without_a_panic() {
    if !std::path::Path::new("/dev/full").exists() {
        eprintln!("skipped: no /dev/full");
        return;
    }
    let out = common::wavg_command()
        .args(["info", "builtin:torus"])
        .stdout(std::fs::File::create("/dev/full").unwrap())
        .output()
        .unwrap();
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "{stderr}");
    assert!(
        !stderr.contains("panicked") && stderr.lines().count() == 1,
        "{stderr}"
    );
}
