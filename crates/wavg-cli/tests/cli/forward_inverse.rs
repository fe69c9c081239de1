//! `wavg forward`, `wavg inverse` and `wavg bench roundtrip` run as a user would.

use crate::common;

use std::path::{Path, PathBuf};
use std::process::Output;

use common::{json_object, parse_floats, read_rows, wavg, wavg_ok};
use wavg_testdata::json_keys::{BENCH_ROUNDTRIP, BENCH_ROUNDTRIP_VERIFIED, sorted};

fn write(dir: &Path, name: &str, text: &str) -> PathBuf {
    let p = dir.join(name);
    std::fs::write(&p, text).unwrap();
    p
}

fn s(p: &Path) -> &str {
    p.to_str().unwrap()
}

/// 12 anchors spread over the small sphere (its icosahedron vertices), one as a face point.
const ANCHORS: &str = "# the icosahedron's vertices\nv 0\nv 1\nv 2\nv 3\n\nv 4\nv 5\nv 6\nv 7\nv 8\nv 9\nv 10\nf 0 0.2 0.3 0.5  # a face point\n";
const MESH: &str = "builtin:sphere-small";

/// `wavg COMMAND --mesh MESH --anchors A --KIND INPUT -o OUT EXTRA...` for forward
/// (`--weights`) and inverse (`--points`).
fn solve_args<'a>(
    command: &'a str,
    anchors: &'a str,
    input: &'a str,
    out: &'a str,
    extra: &[&'a str],
) -> Vec<&'a str> {
    let kind = if command == "forward" {
        "--weights"
    } else {
        "--points"
    };
    let mut v = vec![
        command,
        "--mesh",
        MESH,
        "--anchors",
        anchors,
        kind,
        input,
        "-o",
        out,
    ];
    v.extend_from_slice(extra);
    v
}

#[test]
fn inverse_then_forward_returns_the_points() {
    let dir = tempfile::tempdir().unwrap();
    // Compare 3-D positions with the library's positions of the original points.
    let mesh = wavg::mesh::procedural::builtin("sphere-small").unwrap();
    let originals = [
        wavg::mesh::SurfacePoint::new(10, [0.2, 0.3, 0.5]).position(&mesh),
        mesh.positions[40],
        wavg::mesh::SurfacePoint::new(100, [0.6, 0.2, 0.2]).position(&mesh),
        mesh.corners(7)[0],
    ];
    let points = "f 10 0.2 0.3 0.5\n# comment\n\nv 40\nf 100 0.6 0.2 0.2\nf 7 1 0 0\n";
    inverse_forward_back(dir.path(), points, &[], &originals);
    let (anchors, weights) = (
        dir.path().join("anchors.txt"),
        dir.path().join("weights.txt"),
    );
    let back = read_rows(&dir.path().join("back.txt"));
    for b in &back {
        assert!((b[1] + b[2] + b[3] - 1.0).abs() < 1e-9);
    }
    // The exact search and stdout output agree.
    let out = wavg(&solve_args(
        "forward",
        s(&anchors),
        s(&weights),
        "-",
        &["--exact", "--threads", "1"],
    ));
    assert!(out.status.success());
    let exact: Vec<Vec<f64>> = String::from_utf8(out.stdout)
        .unwrap()
        .lines()
        .map(parse_floats)
        .collect();
    for (a, b) in exact.iter().zip(&back) {
        assert!((a[4] - b[4]).abs() + (a[5] - b[5]).abs() + (a[6] - b[6]).abs() < 1e-6);
    }
}

/// Runs a failing command; checks exit status 2, the `file:line` in the message, and that
/// the pre-existing output file is untouched.
fn expect_input_error(args: &[&str], out_file: &Path, needle: &str) {
    std::fs::write(out_file, "previous contents\n").unwrap();
    let out = wavg(args);
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{args:?}: {err}");
    assert!(
        err.contains(needle),
        "{args:?}: expected {needle:?} in {err:?}"
    );
    assert_eq!(
        std::fs::read_to_string(out_file).unwrap(),
        "previous contents\n"
    );
    let leftovers = common::entries_starting_with(out_file.parent().unwrap(), ".wavg-tmp");
    assert_eq!(leftovers, 0, "temporary file left behind");
}

/// Runs `wavg COMMAND` ([`solve_args`], no extra arguments) and asserts success.
fn solve_ok(command: &str, anchors: &Path, input: &Path, out: &Path) -> Output {
    wavg_ok(&solve_args(command, s(anchors), s(input), s(out), &[]))
}

/// [`expect_input_error`] of `wavg COMMAND` ([`solve_args`], no extra arguments).
fn expect_solve_error(command: &str, anchors: &Path, input: &Path, out: &Path, needle: &str) {
    expect_input_error(
        &solve_args(command, s(anchors), s(input), s(out), &[]),
        out,
        needle,
    );
}

#[test]
fn malformed_weights_are_reported_with_their_line() {
    let dir = tempfile::tempdir().unwrap();
    let anchors = write(dir.path(), "anchors.txt", "v 0\nv 10\nv 20\n");
    let out = dir.path().join("out.txt");
    for (text, needle) in [
        ("0.2 0.3 0.5\n0.2 zz 0.5\n", "w.txt:2:"),
        (
            "# c\n0.2 0.3 0.5\n\n0.5 0.5\n",
            "w.txt:4: expected 3 weights",
        ),
        ("0.2 0.3 0.5\n0.2 NaN 0.8\n", "w.txt:2:"),
        ("0.2 0.3 0.5\n0.2 0.3 0.6\n", "; pass --normalize to divide"),
        ("0.2 0.3 0.5\n0.2 inf 0.5\n", "not finite"),
    ] {
        let w = write(dir.path(), "w.txt", text);
        expect_solve_error("forward", &anchors, &w, &out, needle);
    }
    // --normalize accepts a wrong sum.
    let w = write(dir.path(), "w.txt", "2 3 5\n");
    let r = wavg(&solve_args(
        "forward",
        s(&anchors),
        s(&w),
        s(&out),
        &["--normalize"],
    ));
    assert!(r.status.success(), "{}", String::from_utf8_lossy(&r.stderr));
    assert_eq!(std::fs::read_to_string(&out).unwrap().lines().count(), 1);
}

#[test]
fn malformed_points_and_anchors_are_reported_with_their_line() {
    let dir = tempfile::tempdir().unwrap();
    let good = write(dir.path(), "good.txt", "v 0\nv 10\nv 20\nv 30\n");
    let out = dir.path().join("out.txt");
    for (text, needle) in [
        ("v 1\nv 99999\n", "p.txt:2: vertex 99999 is out of range"),
        (
            "v 1\n\nf 5000 0.2 0.3 0.5\n",
            "p.txt:3: face 5000 is out of range",
        ),
        ("f 3 0.5 0.5 0.5\n", "p.txt:1: bad barycentric"),
        ("f 3 -0.5 0.5 1.0\n", "p.txt:1: bad barycentric"),
        ("x 3\n", "p.txt:1: expected 'v VERTEX'"),
        ("f 3 0.5 0.5\n", "p.txt:1: 'f' takes 4 values"),
        ("v -3\n", "p.txt:1:"),
    ] {
        let p = write(dir.path(), "p.txt", text);
        expect_solve_error("inverse", &good, &p, &out, needle);
        // The same file as anchors is rejected with its line too.
        let w = write(dir.path(), "w.txt", "1\n");
        expect_solve_error("forward", &p, &w, &out, needle);
    }
    let missing = dir.path().join("missing.txt");
    expect_solve_error("inverse", &good, &missing, &out, "missing.txt");
}

#[test]
fn bench_roundtrip_reports_the_documented_json() {
    let out = wavg(&[
        "bench",
        "roundtrip",
        "--mesh",
        "builtin:sphere-small",
        "--anchors",
        "12",
        "--queries",
        "300",
        "--threads",
        "2",
        "--seed",
        "3",
        "--repeat",
        "1",
        "--json",
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    let obj = v.as_object().unwrap();
    let mut keys: Vec<&str> = obj.keys().map(|k| k.as_str()).collect();
    keys.sort();
    assert_eq!(keys, sorted(BENCH_ROUNDTRIP, &["mesh"]));
    assert_eq!(obj["anchors"], 12);
    assert_eq!(obj["queries"], 300);
    assert_eq!(obj["threads"], 2);
    assert_eq!(obj["vertices"], 162);
    assert!(obj["roundtrip_ok_fraction"].as_f64().unwrap() > 0.95);
    assert!(obj["inverse_us"].as_f64().unwrap() > 0.0);
    let bad = wavg(&[
        "bench",
        "roundtrip",
        "--mesh",
        "builtin:sphere-small",
        "--anchors",
        "1000",
        "--queries",
        "10",
    ]);
    assert_eq!(bad.status.code(), Some(2));
}

/// Runs `wavg inverse` (with `extra` arguments) on `points`, then `wavg forward` on the
/// weights; checks the weights' shape and that the points come back to `originals`.
/// Returns the inverse's standard error.
fn inverse_forward_back(
    dir: &Path,
    points: &str,
    extra: &[&str],
    originals: &[nalgebra::Vector3<f64>],
) -> String {
    let anchors = write(dir, "anchors.txt", ANCHORS);
    let points = write(dir, "points.txt", points);
    let weights = dir.join("weights.txt");
    let base = ["inverse", "--mesh", MESH, "--anchors", s(&anchors)];
    let io = ["--points", s(&points), "-o", s(&weights)];
    let out = wavg_ok(&[&base[..], &io[..], extra].concat());
    let rows: Vec<Vec<f64>> = read_rows(&weights);
    assert_eq!(rows.len(), originals.len());
    for r in &rows {
        assert_eq!(r.len(), 12);
        assert!((r.iter().sum::<f64>() - 1.0).abs() < 1e-9);
    }
    let back = dir.join("back.txt");
    solve_ok("forward", &anchors, &weights, &back);
    let back: Vec<Vec<f64>> = read_rows(&back);
    for (b, o) in back.iter().zip(originals) {
        assert_eq!(b.len(), 7, "FACE B0 B1 B2 X Y Z");
        let d = ((b[4] - o.x).powi(2) + (b[5] - o.y).powi(2) + (b[6] - o.z).powi(2)).sqrt();
        assert!(d < 1e-6, "{b:?} vs {o:?}");
    }
    String::from_utf8_lossy(&out.stderr).into_owned()
}

/// `wavg inverse --verified`: same format, the weights lead back, and the summary on
/// standard error is printed.
#[test]
fn verified_inverse_keeps_the_format_and_returns() {
    let dir = tempfile::tempdir().unwrap();
    let mesh = wavg::mesh::procedural::builtin("sphere-small").unwrap();
    let originals = [
        wavg::mesh::SurfacePoint::new(10, [0.2, 0.3, 0.5]).position(&mesh),
        mesh.positions[40],
        wavg::mesh::SurfacePoint::new(100, [0.6, 0.2, 0.2]).position(&mesh),
    ];
    let points = "f 10 0.2 0.3 0.5\nv 40\nf 100 0.6 0.2 0.2\n";
    let err = inverse_forward_back(dir.path(), points, &["--verified"], &originals);
    assert!(err.contains("verified: 3 points"), "{err}");
}

/// `wavg bench roundtrip --verified` adds exactly the documented keys.
#[test]
fn bench_roundtrip_verified_adds_its_keys() {
    let out = wavg_ok(&[
        "bench",
        "roundtrip",
        "--mesh",
        "builtin:torus",
        "--anchors",
        "10",
        "--queries",
        "300",
        "--repeat",
        "1",
        "--verified",
        "--json",
    ]);
    let (obj, keys) = json_object(&out);
    assert_eq!(keys.len(), 13 + 5);
    assert_eq!(
        keys,
        sorted(
            &[BENCH_ROUNDTRIP, &["mesh"]].concat(),
            BENCH_ROUNDTRIP_VERIFIED
        )
    );
    for &k in BENCH_ROUNDTRIP_VERIFIED {
        let x = obj[k].as_f64().unwrap_or_else(|| panic!("{k}"));
        assert!(x.is_finite() && x >= 0.0, "{k} = {x}");
    }
    let paper = obj["roundtrip_ok_fraction"].as_f64().unwrap();
    let verified = obj["verified_roundtrip_ok_fraction"].as_f64().unwrap();
    assert!(verified >= paper, "verified {verified} < paper {paper}");
    let reached = 1.0 - obj["verified_not_reached_fraction"].as_f64().unwrap();
    assert!((verified - reached).abs() < 1e-9, "{verified} vs {reached}");
}

/// Files longer than one streaming chunk (65,536 lines): answers in order across chunk
/// boundaries, the same on one thread and on stdout; a bad line in a late chunk still
/// names its line, leaves the old output untouched, and writes nothing to stdout.
#[test]
fn long_files_stream_in_chunks() {
    let dir = tempfile::tempdir().unwrap();
    let anchors = write(dir.path(), "anchors.txt", ANCHORS);
    let n_faces = 320;
    let mut points = String::new();
    let n = 150_000;
    for i in 0..n {
        let f = (i * 7) % n_faces;
        let a = 0.1 + 0.8 * ((i % 13) as f64 / 13.0);
        let b = (1.0 - a) * 0.5;
        points.push_str(&format!("f {f} {a} {b} {}\n", 1.0 - a - b));
    }
    let pts = write(dir.path(), "points.txt", &points);
    let w_file = dir.path().join("weights.txt");
    solve_ok("inverse", &anchors, &pts, &w_file);
    let weights = read_rows(&w_file);
    assert_eq!(weights.len(), n);
    // Spot checks against a one-line run at a chunk boundary and far into the file.
    for i in [0usize, 65_535, 65_536, 131_072, n - 1] {
        let one = write(dir.path(), "one.txt", points.lines().nth(i).unwrap());
        let one_out = dir.path().join("one_out.txt");
        solve_ok("inverse", &anchors, &one, &one_out);
        assert_eq!(read_rows(&one_out)[0], weights[i], "line {}", i + 1);
    }
    // Forward on one thread to stdout equals forward to a file on all threads.
    let back = dir.path().join("back.txt");
    solve_ok("forward", &anchors, &w_file, &back);
    let out = wavg_ok(&solve_args(
        "forward",
        s(&anchors),
        s(&w_file),
        "-",
        &["--threads", "1"],
    ));
    assert_eq!(out.stdout, std::fs::read(&back).unwrap());
    // A bad line in the third chunk.
    let mut bad = points.clone();
    bad.push_str("f 1 0.5 0.5\n");
    let bad_pts = write(dir.path(), "bad.txt", &bad);
    expect_solve_error(
        "inverse",
        &anchors,
        &bad_pts,
        &w_file,
        &format!("bad.txt:{}:", n + 1),
    );
    let out = wavg(&solve_args("inverse", s(&anchors), s(&bad_pts), "-", &[]));
    assert_eq!(out.status.code(), Some(2));
    assert!(
        out.stdout.is_empty(),
        "stdout got output before the bad line"
    );
    // Weights that do not sum to 1 in the third chunk, as text and as `.npy`: the same.
    let k = 140_000;
    let mut rows = weights.clone();
    rows[k][0] += 0.5;
    let text: String = rows
        .iter()
        .map(|r| {
            r.iter()
                .map(|v| format!("{v:?}"))
                .collect::<Vec<_>>()
                .join(" ")
                + "\n"
        })
        .collect();
    let bad_w = write(dir.path(), "bad_w.txt", &text);
    let bad_npy = dir.path().join("bad_w.npy");
    write_npy(&bad_npy, rows[0].len(), &rows.concat());
    for (input, output) in [(&bad_w, &back), (&bad_npy, &dir.path().join("back.npy"))] {
        let name = input.file_name().unwrap().to_string_lossy().into_owned();
        expect_solve_error(
            "forward",
            &anchors,
            input,
            output,
            &format!("{name}:{}:", k + 1),
        );
        let out = wavg(&solve_args("forward", s(&anchors), s(input), "-", &[]));
        assert_eq!(out.status.code(), Some(2));
        assert!(
            out.stdout.is_empty(),
            "stdout got output before the bad line"
        );
    }
}

/// Writes a row-major `rows x cols` array as `.npy`.
fn write_npy(path: &Path, cols: usize, data: &[f64]) {
    let mut bytes = Vec::new();
    let mut w = wavg::npy::NpyWriter::new(&mut bytes, data.len() / cols, cols).unwrap();
    for row in data.chunks(cols) {
        w.write_row(row).unwrap();
    }
    w.finish().unwrap();
    std::fs::write(path, bytes).unwrap();
}

fn read_npy(path: &Path) -> (usize, usize, Vec<f64>) {
    wavg::npy::read_matrix(std::fs::File::open(path).unwrap()).unwrap()
}

/// `.npy` inputs and outputs carry the same numbers as the text formats, in any mix;
/// rows without an answer are NaN (face -1 for forward); bad rows name their row.
#[test]
fn npy_files_match_the_text_formats() {
    let dir = tempfile::tempdir().unwrap();
    let anchors = write(dir.path(), "anchors.txt", ANCHORS);
    let faces = [
        (3u32, [0.2, 0.3, 0.5]),
        (77, [1.0, 0.0, 0.0]),
        (300, [0.6, 0.2, 0.2]),
    ];
    let text: String = faces
        .iter()
        .map(|(f, b)| format!("f {f} {} {} {}\n", b[0], b[1], b[2]))
        .collect();
    let pts_txt = write(dir.path(), "points.txt", &text);
    let pts_npy = dir.path().join("points.npy");
    let flat: Vec<f64> = faces
        .iter()
        .flat_map(|(f, b)| [f64::from(*f), b[0], b[1], b[2]])
        .collect();
    write_npy(&pts_npy, 4, &flat);
    let j = |n: &str| dir.path().join(n);
    for (input, output) in [
        (&pts_txt, j("w.txt")),
        (&pts_npy, j("w.npy")),
        (&pts_txt, j("w2.npy")),
    ] {
        solve_ok("inverse", &anchors, input, &output);
    }
    let text_rows: Vec<f64> = read_rows(&j("w.txt")).concat();
    for f in ["w.npy", "w2.npy"] {
        let (rows, cols, data) = read_npy(&j(f));
        assert_eq!((rows, cols), (3, 12));
        assert_eq!(data, text_rows, "{f}");
    }
    solve_ok("forward", &anchors, &j("w.npy"), &j("b.npy"));
    solve_ok("forward", &anchors, &j("w.txt"), &j("b.txt"));
    let (rows, cols, data) = read_npy(&j("b.npy"));
    assert_eq!((rows, cols), (3, 7));
    assert_eq!(data, read_rows(&j("b.txt")).concat());
    assert_eq!(data[0], 3.0);
    // A row with a fractional face and a truncated file are input errors naming the file.
    write_npy(&j("bad.npy"), 4, &[3.0, 0.2, 0.3, 0.5, 1.5, 0.2, 0.3, 0.5]);
    expect_solve_error(
        "inverse",
        &anchors,
        &j("bad.npy"),
        &j("w.npy"),
        "bad.npy:2: face index 1.5",
    );
    let bytes = std::fs::read(&pts_npy).unwrap();
    std::fs::write(j("cut.npy"), &bytes[..bytes.len() - 8]).unwrap();
    expect_solve_error("inverse", &anchors, &j("cut.npy"), &j("w.npy"), "cut.npy");
}
