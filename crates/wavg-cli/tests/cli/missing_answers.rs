//! Answers that do not exist are marked line by line (`none REASON`, `none
//! not-reached`), and a run where too many are missing warns with the cause and the remedy.

use crate::common;

use std::path::{Path, PathBuf};

use common::{parse_floats, read_rows, wavg, wavg_ok};

fn write(dir: &Path, name: &str, text: &str) -> PathBuf {
    let p = dir.join(name);
    std::fs::write(&p, text).unwrap();
    p
}

fn s(p: &Path) -> &str {
    p.to_str().unwrap()
}

#[test]
fn no_weighted_average_is_a_per_line_marker() {
    let dir = tempfile::tempdir().unwrap();
    // Corners of the flat builtin grid (41 x 21 vertices): extrapolating weights leave it.
    let anchors = write(dir.path(), "a.txt", "v 0\nv 40\nv 860\nv 820\n");
    let w = write(dir.path(), "w.txt", "0.25 0.25 0.25 0.25\n2 -1 0 0\n");
    let out = dir.path().join("out.txt");
    let r = wavg(&[
        "forward",
        "--mesh",
        "builtin:grid",
        "--embedding",
        "none",
        "--anchors",
        s(&anchors),
        "--weights",
        s(&w),
        "-o",
        s(&out),
    ]);
    assert!(r.status.success(), "{}", String::from_utf8_lossy(&r.stderr));
    let text = std::fs::read_to_string(&out).unwrap();
    let lines: Vec<&str> = text.lines().collect();
    assert_eq!(lines.len(), 2);
    let first = parse_floats(lines[0]);
    assert!(
        (first[4] - 1.0).abs() < 1e-9 && (first[5] - 0.5).abs() < 1e-9,
        "{text}"
    );
    assert!(lines[1].starts_with("none "), "{text}");
}

/// `wavg inverse --verified` writes `none not-reached` for the points no weights reach
/// (three anchors far apart on the torus leave many), as many as its summary counts; every
/// other line's weights lead back to its point.
#[test]
fn verified_inverse_marks_unreached_points() {
    let dir = tempfile::tempdir().unwrap();
    let anchors = write(dir.path(), "a.txt", "v 0\nv 500\nv 1000\n");
    let points: String = (0..120)
        .map(|i| format!("f {} 0.2 0.3 0.5\n", i * 25))
        .collect();
    let points = write(dir.path(), "p.txt", &points);
    let (w, back) = (dir.path().join("w.txt"), dir.path().join("back.txt"));
    let torus = ["--mesh", "builtin:torus", "--embedding", "none"];
    let out = wavg_ok(
        &[
            &["inverse"][..],
            &torus,
            &[
                "--anchors",
                s(&anchors),
                "--points",
                s(&points),
                "-o",
                s(&w),
                "--verified",
            ],
        ]
        .concat(),
    );
    let err = String::from_utf8_lossy(&out.stderr);
    let lines: Vec<String> = std::fs::read_to_string(&w)
        .unwrap()
        .lines()
        .map(String::from)
        .collect();
    let missed = lines.iter().filter(|l| *l == "none not-reached").count();
    assert!(
        missed > 0 && missed < lines.len(),
        "{missed} of {}",
        lines.len()
    );
    assert!(err.contains(&format!("{missed} not reached")), "{err}");
    // Fewer than 90% reached: a warning with the cause and the remedy.
    assert!(
        err.contains("too few") && err.contains("wavg anchors builtin:torus --count"),
        "{err}"
    );
    // The reached lines go back to their points through the forward problem.
    let reached: Vec<(usize, &String)> = lines
        .iter()
        .enumerate()
        .filter(|(_, l)| !l.starts_with("none"))
        .collect();
    let wr = write(
        dir.path(),
        "wr.txt",
        &reached
            .iter()
            .map(|(_, l)| format!("{l}\n"))
            .collect::<String>(),
    );
    wavg_ok(
        &[
            &["forward"][..],
            &torus,
            &[
                "--anchors",
                s(&anchors),
                "--weights",
                s(&wr),
                "-o",
                s(&back),
            ],
        ]
        .concat(),
    );
    let mesh = wavg::mesh::procedural::builtin("torus").unwrap();
    let edge = (mesh.positions[0] - mesh.positions[1]).norm();
    for ((i, _), b) in reached.iter().zip(read_rows(&back)) {
        let o = wavg::mesh::SurfacePoint::new(*i as u32 * 25, [0.2, 0.3, 0.5]).position(&mesh);
        let d = ((b[4] - o.x).powi(2) + (b[5] - o.y).powi(2) + (b[6] - o.z).powi(2)).sqrt();
        assert!(d < 1e-2 * edge, "point {i}: {d}");
    }
}
