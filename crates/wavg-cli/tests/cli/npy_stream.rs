//! `.npy` inputs longer than several chunks: every row reaches the answer it has in the
//! text format, with the blocks the reader reuses read over in place.

use crate::common;

use common::{icosphere_forward, sphere_anchors};

#[test]
fn long_npy_weights_give_the_text_answers() {
    let dir = tempfile::tempdir().unwrap();
    let anchors = sphere_anchors(dir.path());
    let k = 31;
    // Rows that differ from each other, so a row read from a stale block would show.
    let n = 300_000;
    let rows: Vec<Vec<f64>> = (0..n)
        .map(|i| {
            let mut w: Vec<f64> = (0..k)
                .map(|j| 1.0 + ((i * 31 + j * 17) % 97) as f64)
                .collect();
            let sum: f64 = w.iter().sum();
            w.iter_mut().for_each(|x| *x /= sum);
            w
        })
        .collect();
    let mut text = String::new();
    for w in &rows {
        let line: Vec<String> = w.iter().map(|x| format!("{x:?}")).collect();
        text.push_str(&line.join(" "));
        text.push('\n');
    }
    let w_txt = dir.path().join("w.txt");
    std::fs::write(&w_txt, text).unwrap();
    let w_npy = dir.path().join("w.npy");
    let mut bytes = Vec::new();
    let mut writer = wavg::npy::NpyWriter::new(&mut bytes, n, k).unwrap();
    writer.write_rows(&rows.concat()).unwrap();
    writer.finish().unwrap();
    std::fs::write(&w_npy, bytes).unwrap();
    let run = |weights: &std::path::Path, out: &str| {
        let out = dir.path().join(out);
        let run = icosphere_forward(&anchors, weights, &out);
        assert!(
            run.status.success(),
            "{}",
            String::from_utf8_lossy(&run.stderr)
        );
        std::fs::read(out).unwrap()
    };
    let from_text = run(&w_txt, "from_text.txt");
    let from_npy = run(&w_npy, "from_npy.txt");
    assert_eq!(from_text.iter().filter(|&&b| b == b'\n').count(), n);
    assert!(from_text == from_npy, "the .npy rows give other answers");
}

/// An array of rows without values (shape (5, 0)) is an input error, not an empty answer.
#[test]
fn rows_without_values_are_an_input_error() {
    let dir = tempfile::tempdir().unwrap();
    let anchors = sphere_anchors(dir.path());
    let w_npy = dir.path().join("w.npy");
    // A version 1.0 header for float64 (5, 0), padded to 64 bytes, and no data.
    let mut dict = "{'descr': '<f8', 'fortran_order': False, 'shape': (5, 0), }".to_owned();
    while (10 + dict.len() + 1) % 64 != 0 {
        dict.push(' ');
    }
    dict.push('\n');
    let mut bytes = b"\x93NUMPY\x01\x00".to_vec();
    bytes.extend((dict.len() as u16).to_le_bytes());
    bytes.extend(dict.as_bytes());
    std::fs::write(&w_npy, bytes).unwrap();
    let out = icosphere_forward(&anchors, &w_npy, &dir.path().join("o.txt"));
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{stderr}");
    assert!(stderr.contains("hold no values"), "{stderr}");
    assert!(!dir.path().join("o.txt").exists());
}
