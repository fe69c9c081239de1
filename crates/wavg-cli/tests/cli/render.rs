//! `wavg render` run as a process: a PNG of the right size with JSON keys, and bad input
//! (missing texture, texture without UVs, wrong scalar count) refused with nothing written.

use crate::common;

use common::{json_object, wavg, wavg_ok};

#[test]
fn renders_a_png_and_reports_json() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("a.png");
    let scal = dir.path().join("s.txt");
    let n = 2562; // builtin:icosphere
    let text: String = (0..n).map(|i| format!("{}\n", i as f64 / 7.0)).collect();
    std::fs::write(&scal, text).unwrap();
    let pts = dir.path().join("p.txt");
    std::fs::write(&pts, "v 0\nf 3 0.2 0.3 0.5\n").unwrap();
    let run = wavg_ok(&[
        "render",
        "builtin:icosphere",
        "-o",
        out.to_str().unwrap(),
        "--size",
        "120x90",
        "--scalar",
        scal.to_str().unwrap(),
        "--points",
        pts.to_str().unwrap(),
        "--wireframe",
        "--view",
        "-20,10",
        "--json",
    ]);
    let (o, _) = json_object(&run);
    assert_eq!(o["width"], 120);
    assert_eq!(o["height"], 90);
    let f = o["covered_fraction"].as_f64().unwrap();
    assert!(f > 0.2 && f < 0.9, "{f}");
    let bytes = std::fs::read(&out).unwrap();
    assert_eq!(&bytes[1..4], b"PNG");
    assert!(o["scalar_max"].as_f64().unwrap() > 365.0);
}

#[test]
fn bad_input_writes_nothing() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("a.png");
    let o = out.to_str().unwrap();
    let missing = dir.path().join("missing.png");
    let tex = dir.path().join("t.png");
    // A valid PNG written by a previous render.
    let tmp = dir.path().join("tmp.png");
    wavg_ok(&[
        "render",
        "builtin:icosphere",
        "-o",
        tmp.to_str().unwrap(),
        "--size",
        "4x4",
    ]);
    std::fs::copy(&tmp, &tex).unwrap();
    let scal = dir.path().join("s.txt");
    std::fs::write(&scal, "1\n2\n3\n").unwrap();
    for (extra, msg) in [
        (vec!["--texture", missing.to_str().unwrap()], "missing.png"),
        (
            vec!["--texture", tex.to_str().unwrap()],
            "texture coordinates",
        ),
        (
            vec!["--scalar", scal.to_str().unwrap()],
            "3 scalars for 2562 vertices",
        ),
        (vec!["--size", "0x5"], "--size"),
    ] {
        let r = wavg(&[&["render", "builtin:icosphere", "-o", o][..], &extra].concat());
        let err = String::from_utf8_lossy(&r.stderr);
        assert_eq!(r.status.code(), Some(2), "{err}");
        assert!(err.contains(msg), "{err}");
        assert!(!out.exists());
    }
}

/// A 3 x 3 grid of unit quads in the z = 0 plane as OBJ: with `f a b c d` quads, or with
/// the same quads split into the triangles `a b c`, `a c d` (what reading fans them into).
fn grid_obj(quads: bool) -> String {
    let n = 3;
    let mut s = String::new();
    for j in 0..=n {
        for i in 0..=n {
            s += &format!("v {i} {j} 0\n");
        }
    }
    let id = |i: usize, j: usize| j * (n + 1) + i + 1;
    for j in 0..n {
        for i in 0..n {
            let (a, b, c, d) = (id(i, j), id(i + 1, j), id(i + 1, j + 1), id(i, j + 1));
            if quads {
                s += &format!("f {a} {b} {c} {d}\n");
            } else {
                s += &format!("f {a} {b} {c}\nf {a} {c} {d}\n");
            }
        }
    }
    s
}

#[test]
fn the_wireframe_of_a_quad_mesh_draws_quads_and_of_triangles_every_edge() {
    let dir = tempfile::tempdir().unwrap();
    let mut images = Vec::new();
    for quads in [true, false] {
        let obj = dir.path().join(format!("grid_{quads}.obj"));
        std::fs::write(&obj, grid_obj(quads)).unwrap();
        let png = dir.path().join(format!("grid_{quads}.png"));
        wavg_ok(&[
            "render",
            obj.to_str().unwrap(),
            "--wireframe",
            "--view",
            "0,0",
            "--size",
            "200x200",
            "-o",
            png.to_str().unwrap(),
        ]);
        images.push(wavg::apps::Image::read_png(&png).unwrap());
    }
    let grey = |p: [u8; 4]| p[..3].iter().map(|&v| v as i32).sum::<i32>() / 3;
    let (q, t) = (&images[0], &images[1]);
    let (mut lighter, mut diagonal) = (0, 0);
    for y in 0..200 {
        for x in 0..200 {
            let (a, b) = (grey(q.get(x, y)), grey(t.get(x, y)));
            // Nothing the quads draw is missing from the triangles' picture...
            lighter += usize::from(a < b - 2);
            // ...and the triangles' picture has the nine diagonals on top.
            diagonal += usize::from(b < a - 40);
        }
    }
    assert_eq!(lighter, 0);
    // Nine diagonals of about 40 pixels each (the picture is about 170 pixels across).
    assert!(diagonal > 9 * 25, "{diagonal} pixels of diagonals");
    // The diagonal of the cell at the centre of the picture passes through its middle.
    assert!(grey(t.get(100, 100)) < grey(q.get(100, 100)) - 40);
}
