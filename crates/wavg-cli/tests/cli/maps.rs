//! `wavg correspond` and `wavg decal` run as processes (`wavg morph`: `morph.rs`): JSON keys, output
//! files, the identity map of a surface onto itself, a real pose pair against its ground
//! truth, and bad input that writes nothing.

use crate::common;

use std::path::{Path, PathBuf};

use common::{json_object, pair_args, sphere_anchors, wavg, wavg_ok, wavg_ok_with};

fn s(p: &Path) -> String {
    p.to_str().unwrap().to_string()
}

fn has_keys(keys: &[String], want: &[&str]) {
    for k in want {
        assert!(keys.iter().any(|x| x == k), "missing {k} in {keys:?}");
    }
}

#[test]
fn correspond_a_surface_onto_itself() {
    let dir = tempfile::tempdir().unwrap();
    let a = s(&sphere_anchors(dir.path()));
    let out = dir.path().join("map.txt");
    let m = "builtin:icosphere";
    let base = pair_args("correspond", [m, m], [&a, &a], &s(&out));
    for extra in [&[][..], &["--validity", "paper"], &["--paper-weights"]] {
        let extra = [&["--json", "--ground-truth"][..], extra].concat();
        let (o, keys) = json_object(&wavg_ok_with(&base, &extra));
        has_keys(
            &keys,
            &[
                "source_vertices",
                "valid_fraction",
                "flipped_faces",
                "flipped_area_fraction",
                "stretch",
                "stretch_best95",
                "seconds",
                "vertices_per_s",
            ],
        );
        assert_eq!(o["source_vertices"], 2562);
        let map = std::fs::read_to_string(&out).unwrap();
        assert_eq!(map.lines().count(), 2562);
        let valid = map.lines().filter(|l| !l.starts_with("none ")).count();
        let frac = o["valid_fraction"].as_f64().unwrap();
        assert!((frac - valid as f64 / 2562.0).abs() < 1e-12);
        assert!(frac > 0.5, "{extra:?}: {frac}");
        let err = o["ground_truth"]["valid"]["max"].as_f64().unwrap();
        assert!(err < 1e-6, "{extra:?}: {err}");
        if extra.is_empty() {
            // The default local test keeps the exact images the paper's test rejects.
            assert!(frac > 0.99, "{frac}");
            assert!((o["stretch"].as_f64().unwrap() - 1.0).abs() < 1e-6);
        }
    }
}

/// `wavg decal --json` on `builtin:icosphere` with these anchors and (u, v) lines, into
/// `dir/d.obj`: the JSON object, its keys and the output path.
/// Runs `wavg decal` on `builtin:icosphere` with `anchors` and `uv` (file texts written
/// to `dir`) into `dir/d.obj`, with `extra` arguments; the output and the OBJ's path.
fn decal_run(
    dir: &Path,
    anchors: &str,
    uv: &str,
    extra: &[&str],
) -> (std::process::Output, PathBuf) {
    let (a, u) = (dir.join("a.txt"), dir.join("uv.txt"));
    std::fs::write(&a, anchors).unwrap();
    std::fs::write(&u, uv).unwrap();
    let out = dir.join("d.obj");
    let mut args = vec![
        "decal".to_owned(),
        "--mesh".into(),
        "builtin:icosphere".into(),
        "--anchors".into(),
        s(&a),
        "--uv".into(),
        s(&u),
        "-o".into(),
        s(&out),
    ];
    args.extend(extra.iter().map(|x| x.to_string()));
    let args: Vec<&str> = args.iter().map(String::as_str).collect();
    (wavg(&args), out)
}

fn decal_json(
    dir: &Path,
    anchors: &str,
    uv: &str,
) -> (
    serde_json::Map<String, serde_json::Value>,
    Vec<String>,
    PathBuf,
) {
    let (r, out) = decal_run(dir, anchors, uv, &["--json"]);
    assert!(r.status.success(), "{}", String::from_utf8_lossy(&r.stderr));
    let (o, keys) = json_object(&r);
    (o, keys, out)
}

/// A decal whose `.mtl` cannot be written leaves none of its files (the checkerboard was
/// left behind).
#[test]
fn a_decal_that_fails_leaves_no_file() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::create_dir(dir.path().join("d.mtl")).unwrap();
    let (r, out) = decal_run(
        dir.path(),
        "v 0\nv 1\nv 2\nv 3\n",
        "0 0\n1 0\n0 1\n1 1\n",
        &[],
    );
    assert!(!r.status.success());
    assert!(!out.exists() && !dir.path().join("d_checker.png").exists());
}

#[test]
fn decal_writes_one_vt_per_vertex() {
    let dir = tempfile::tempdir().unwrap();
    let (o, keys, out) = decal_json(dir.path(), "v 0\nv 1\nv 2\nv 3\n", "0 0\n1 0\n0 1\n1 1\n");
    has_keys(
        &keys,
        &[
            "vertices",
            "valid_fraction",
            "stretch",
            "flipped_faces",
            "seconds",
            "marked",
        ],
    );
    assert_eq!(o["vertices"], 2562);
    let text = std::fs::read_to_string(&out).unwrap();
    assert_eq!(text.lines().filter(|l| l.starts_with("vt ")).count(), 2562);
    assert_eq!(text.lines().filter(|l| l.starts_with("v ")).count(), 2562);
    // Faces without a marked corner carry the vertices' own coordinates.
    let f = text
        .lines()
        .find(|l| l.starts_with("f ") && l.contains('/'));
    assert!(f.is_some(), "no textured face");
    // Anchor 1 (vertex 1) gets its own coordinates.
    let vt: Vec<Vec<f64>> = text
        .lines()
        .filter(|l| l.starts_with("vt "))
        .map(|l| l[3..].split(' ').map(|x| x.parse().unwrap()).collect())
        .collect();
    assert!(
        (vt[1][0] - 1.0).abs() < 1e-6 && vt[1][1].abs() < 1e-6,
        "{:?}",
        vt[1]
    );
    let marked = o["marked"].as_array().unwrap().len();
    let frac = o["valid_fraction"].as_f64().unwrap();
    assert!((frac - (2562 - marked) as f64 / 2562.0).abs() < 1e-12);
}

#[test]
fn a_pose_pair_maps_close_to_its_ground_truth() {
    let Some(f0) = wavg_testdata::require_data_file(
        "a_pose_pair_maps_close_to_its_ground_truth",
        "correspondence/goast_finger/finger0.off",
    ) else {
        return;
    };
    let f1 = f0.with_file_name("finger1.off");
    let dir = tempfile::tempdir().unwrap();
    let a = dir.path().join("a.txt");
    let text: String = (0..2046).step_by(51).map(|v| format!("v {v}\n")).collect();
    std::fs::write(&a, text).unwrap();
    let out = dir.path().join("map.txt");
    let args = pair_args("correspond", [&s(&f0), &s(&f1)], [&s(&a), &s(&a)], &s(&out));
    let r = wavg_ok_with(&args, &["--json", "--ground-truth"]);
    let (o, _) = json_object(&r);
    let frac = o["valid_fraction"].as_f64().unwrap();
    let err = o["ground_truth"]["valid"]["mean"].as_f64().unwrap();
    assert!(frac > 0.9, "valid fraction {frac}");
    assert!(err < 0.01, "mean error {err} of the diagonal");
}

/// Two different shapes (horse and camel, 107 paired markers), where the camel must be
/// repaired first (non-manifold, several components): the markers are carried through
/// the repair's vertex map, and most of the horse maps onto the camel without folding.
#[test]
fn different_shapes_map_through_markers_after_repair() {
    let test = "different_shapes_map_through_markers_after_repair";
    let (Some(horse), Some(camel), Some(cons)) = (
        wavg_testdata::require_data_file(
            test,
            "correspondence/sumner_horse/horse-reference.obj.gz",
        ),
        wavg_testdata::require_data_file(test, "bad/camel-reference.obj.gz"),
        wavg_testdata::require_data_file(test, "correspondence/horse_camel_markers.cons"),
    ) else {
        return;
    };
    let dir = tempfile::tempdir().unwrap();
    let (fixed, map) = (dir.path().join("camel.obj"), dir.path().join("camel.map"));
    wavg_ok(&[
        "repair",
        &s(&camel),
        "-o",
        &s(&fixed),
        "--largest-component",
        "--map",
        &s(&map),
    ]);
    // Original camel id -> repaired id (the first copy of a split vertex).
    let mut new_id = std::collections::HashMap::new();
    for (new, line) in std::fs::read_to_string(&map).unwrap().lines().enumerate() {
        new_id.entry(line.parse::<u32>().unwrap()).or_insert(new);
    }
    let text = std::fs::read_to_string(&cons).unwrap();
    let mut lines = text.lines();
    let count: usize = lines.next().unwrap().trim().parse().unwrap();
    let (mut ha, mut ca) = (String::new(), String::new());
    for l in lines.filter(|l| !l.trim().is_empty()) {
        let ids: Vec<u32> = l
            .split(|c: char| c == ',' || c.is_whitespace())
            .filter(|t| !t.is_empty())
            .map(|t| t.parse().unwrap())
            .collect();
        ha.push_str(&format!("v {}\n", ids[0]));
        ca.push_str(&format!("v {}\n", new_id[&ids[1]]));
    }
    assert_eq!(ha.lines().count(), count);
    let (hp, cp) = (dir.path().join("h.txt"), dir.path().join("c.txt"));
    std::fs::write(&hp, ha).unwrap();
    std::fs::write(&cp, ca).unwrap();
    let out = dir.path().join("map.txt");
    let args = pair_args(
        "correspond",
        [&s(&horse), &s(&fixed)],
        [&s(&hp), &s(&cp)],
        &s(&out),
    );
    let r = wavg_ok_with(&args, &["--json"]);
    let (o, _) = json_object(&r);
    let frac = o["valid_fraction"].as_f64().unwrap();
    let stretch = o["stretch_best95"].as_f64().unwrap();
    let flipped = o["flipped_area_fraction"].as_f64().unwrap();
    assert!(frac > 0.8, "valid fraction {frac}");
    assert!(stretch < 1.5, "stretch of the best 95% {stretch}");
    // The flipped area is measured over the kept vertices' faces: the local test's disc
    // keeps 0.986 of the horse (0.972 with the one-ring), and the camel no longer gets
    // thin-part landmarks (its shrunken faces cover 0.04 landmark spacings), 0.054 in all.
    assert!(flipped < 0.06, "flipped area {flipped}");
}

#[test]
fn bad_input_writes_nothing() {
    let dir = tempfile::tempdir().unwrap();
    let a = sphere_anchors(dir.path());
    let short = dir.path().join("short.txt");
    std::fs::write(&short, "v 0\nv 85\n").unwrap();
    let far = dir.path().join("far.txt");
    std::fs::write(&far, "v 0\nv 99999\n").unwrap();
    let out = dir.path().join("out.txt");
    let frames = dir.path().join("frames");
    let m = "builtin:icosphere";
    let expect_2 = |args: &[&str], what: &str| {
        let r = wavg(args);
        assert_eq!(
            r.status.code(),
            Some(2),
            "{what}: {}",
            String::from_utf8_lossy(&r.stderr)
        );
        assert!(!String::from_utf8_lossy(&r.stderr).trim().is_empty());
        assert!(!out.exists() && !frames.exists(), "{what} wrote output");
    };
    let (a, short, far, o) = (s(&a), s(&short), s(&far), s(&out));
    let pair = |sa: &str, ta: &str, cmd: &str| -> Vec<String> {
        let out = if cmd == "morph" {
            s(&frames)
        } else {
            o.clone()
        };
        pair_args(cmd, [m, m], [sa, ta], &out)
    };
    for cmd in ["correspond", "morph"] {
        let v = pair(&a, &short, cmd);
        let args: Vec<&str> = v.iter().map(String::as_str).collect();
        expect_2(&args, "anchor counts differ");
        let v = pair(&far, &far, cmd);
        let args: Vec<&str> = v.iter().map(String::as_str).collect();
        expect_2(&args, "anchor out of range");
        let v = pair("/nonexistent/a.txt", &a, cmd);
        let args: Vec<&str> = v.iter().map(String::as_str).collect();
        expect_2(&args, "unreadable anchors");
    }
    let uv = dir.path().join("uv.txt");
    std::fs::write(&uv, "0 0\n1 0\n").unwrap();
    let uv = s(&uv);
    let decal = |anchors: &str, uv: &str, mesh: &str| {
        [
            "decal",
            "--mesh",
            mesh,
            "--anchors",
            anchors,
            "--uv",
            uv,
            "-o",
            o.as_str(),
        ]
        .map(str::to_string)
    };
    for (args, what) in [
        (decal(&a, &uv, m), "uv count differs"),
        (decal(&far, &uv, m), "anchor out of range"),
        (decal(&short, &uv, "/nonexistent.obj"), "unreadable mesh"),
        (decal(&short, "/nonexistent.txt", m), "unreadable uv"),
    ] {
        let args: Vec<&str> = args.iter().map(String::as_str).collect();
        expect_2(&args, what);
    }
}

/// A decal whose faces are all marked (one anchor: no weights are meaningful) measures no
/// stretch, and says so with null rather than a perfect 1.
#[test]
fn a_decal_without_measured_faces_reports_no_stretch() {
    let dir = tempfile::tempdir().unwrap();
    let (o, _, _) = decal_json(dir.path(), "v 0\n", "0 0\n");
    assert!(o["valid_fraction"].as_f64().unwrap() < 0.01, "{o:?}");
    assert!(
        o["stretch"].is_null() && o["stretch_best95"].is_null(),
        "{o:?}"
    );
}

/// A decal around the +z pole of `builtin:icosphere`: the pole vertex at (0.5, 0.5) and a
/// ring of eight vertices 30 degrees from it on a circle of radius 0.4 around it.
fn pole_decal(dir: &Path) -> (PathBuf, PathBuf) {
    let mesh = wavg::mesh::procedural::builtin("icosphere").unwrap();
    let nearest = |q: wavg::Vector3<f64>| {
        (0..mesh.positions.len())
            .min_by(|&a, &b| {
                (mesh.positions[a] - q)
                    .norm()
                    .total_cmp(&(mesh.positions[b] - q).norm())
            })
            .unwrap()
    };
    let (mut anchors, mut uv) = (String::new(), String::new());
    anchors += &format!("v {}\n", nearest(wavg::Vector3::z()));
    uv += "0.5 0.5\n";
    for k in 0..8 {
        let a = std::f64::consts::TAU * k as f64 / 8.0;
        let t = 30f64.to_radians();
        let q = wavg::Vector3::new(t.sin() * a.cos(), t.sin() * a.sin(), t.cos());
        anchors += &format!("v {}\n", nearest(q));
        uv += &format!("{} {}\n", 0.5 + 0.4 * a.cos(), 0.5 + 0.4 * a.sin());
    }
    let (a, u) = (dir.join("a.txt"), dir.join("uv.txt"));
    std::fs::write(&a, anchors).unwrap();
    std::fs::write(&u, uv).unwrap();
    (a, u)
}

#[test]
fn decal_faces_with_a_marked_corner_have_no_uv_and_a_material_names_the_texture() {
    let dir = tempfile::tempdir().unwrap();
    let (a, u) = pole_decal(dir.path());
    let out = dir.path().join("d.obj");
    let args = [
        "decal",
        "builtin:icosphere",
        "--anchors",
        &s(&a),
        "--uv",
        &s(&u),
        "-o",
        &s(&out),
        "--json",
    ];
    let (o, _) = json_object(&wavg_ok(&args));
    let marked: std::collections::HashSet<u64> = o["marked"]
        .as_array()
        .unwrap()
        .iter()
        .map(|v| v.as_u64().unwrap())
        .collect();
    assert!(
        marked.len() > 100,
        "{} marked: the far side of the sphere should be",
        marked.len()
    );
    let text = std::fs::read_to_string(&out).unwrap();
    assert_eq!(text.lines().next(), Some("mtllib d.mtl"));
    let (mut plain, mut textured) = (0, 0);
    for l in text.lines().filter(|l| l.starts_with("f ")) {
        let corners: Vec<&str> = l[2..].split(' ').collect();
        let vs: Vec<u64> = corners
            .iter()
            .map(|c| c.split('/').next().unwrap().parse::<u64>().unwrap() - 1)
            .collect();
        if vs.iter().any(|v| marked.contains(v)) {
            assert!(!l.contains('/'), "a face with a marked corner has UVs: {l}");
            plain += 1;
        } else {
            for (c, v) in corners.iter().zip(&vs) {
                assert_eq!(*c, format!("{0}/{0}", v + 1), "{l}");
            }
            textured += 1;
        }
    }
    assert_eq!(o["untextured_faces"], plain);
    assert!(
        textured > 50 && plain > 100,
        "{textured} textured, {plain} plain"
    );
    // The material beside it names the checkerboard written beside it.
    assert_eq!(o["mtl"], s(&dir.path().join("d.mtl")));
    let board = dir.path().join("d_checker.png");
    assert_eq!(o["texture"], s(&board));
    let mtl = std::fs::read_to_string(dir.path().join("d.mtl")).unwrap();
    assert!(
        mtl.contains("newmtl decal\n") && mtl.contains("map_Kd d_checker.png\n"),
        "{mtl}"
    );
    assert!(mtl.contains("newmtl plain\n"), "{mtl}");
    assert!(text.contains("usemtl decal\n") && text.contains("usemtl plain\n"));

    // Rendered with the texture: the decal shows on the near side, and the far side looks
    // exactly as the untextured mesh (no smear of the board over the faces left plain).
    let render = |view: &str, texture: bool| {
        let png = dir.path().join("r.png");
        let mut args = vec!["render".to_string(), s(&out), "--view".into(), view.into()];
        if texture {
            args.extend(["--texture".into(), s(&board)]);
        }
        args.extend(["-o".into(), s(&png), "--size".into(), "160x120".into()]);
        wavg_ok(&args.iter().map(String::as_str).collect::<Vec<_>>());
        wavg::apps::Image::read_png(&png).unwrap()
    };
    let differ = |a: &wavg::apps::Image, b: &wavg::apps::Image| {
        a.pixels
            .iter()
            .zip(&b.pixels)
            .filter(|(p, q)| p != q)
            .count()
    };
    let near = differ(&render("0,0", true), &render("0,0", false));
    assert!(near > 1000, "{near} pixels show the decal");
    let far = differ(&render("180,0", true), &render("180,0", false));
    assert_eq!(far, 0, "{far} pixels of the far side are textured");
}

#[test]
fn decal_names_a_given_texture_and_refuses_a_bad_one() {
    let dir = tempfile::tempdir().unwrap();
    let (a, u) = pole_decal(dir.path());
    let sub = dir.path().join("sub");
    std::fs::create_dir(&sub).unwrap();
    let out = sub.join("d.obj");
    let tex = dir.path().join("t.png");
    let base = [
        "decal",
        "builtin:icosphere",
        "--anchors",
        &s(&a),
        "--uv",
        &s(&u),
    ];
    // Not a PNG: refused before anything is written.
    std::fs::write(&tex, "not a png").unwrap();
    let r = wavg(&[&base[..], &["--texture", &s(&tex), "-o", &s(&out)]].concat());
    assert_eq!(r.status.code(), Some(2), "{r:?}");
    assert!(String::from_utf8_lossy(&r.stderr).contains("--texture"));
    assert!(std::fs::read_dir(&sub).unwrap().next().is_none());
    // A real PNG elsewhere: named by its absolute path, no checkerboard written.
    let png = dir.path().join("r.png");
    wavg_ok(&[
        "render",
        "builtin:icosphere",
        "--size",
        "8x8",
        "-o",
        &s(&png),
    ]);
    std::fs::rename(&png, &tex).unwrap();
    wavg_ok(&[&base[..], &["--texture", &s(&tex), "-o", &s(&out)]].concat());
    let mtl = std::fs::read_to_string(sub.join("d.mtl")).unwrap();
    let canon = std::fs::canonicalize(&tex).unwrap();
    assert!(
        mtl.contains(&format!("map_Kd {}\n", canon.display())),
        "{mtl}"
    );
    assert!(!sub.join("d_checker.png").exists());
    // Standard output: no material.
    let r = wavg_ok(&[&base[..], &["-o", "-"]].concat());
    let text = String::from_utf8_lossy(&r.stdout);
    assert!(!text.contains("mtllib") && !text.contains("usemtl"));
    assert!(
        text.lines()
            .any(|l| l.starts_with("f ") && !l.contains('/'))
    );
}
