//! Outputs that are not regular files: a named pipe as `-o` is written through, never
//! replaced by a file, and gets nothing when a later chunk of the input is bad.
#![cfg(unix)]

mod common;

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
    let out = std::process::Command::new("bash")
        .args(["-c", &cmd])
        .output()
        .unwrap();
    let (stdout, stderr) = (
        String::from_utf8_lossy(&out.stdout),
        String::from_utf8_lossy(&out.stderr),
    );
    assert_eq!(stdout.trim(), "status 0", "{stderr}");
    assert!(!stderr.contains("Broken pipe"), "{stderr}");
}
