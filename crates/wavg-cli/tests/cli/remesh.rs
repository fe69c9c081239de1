//! `wavg remesh` run as a process: JSON keys and counts, the OBJ written (quads and
//! triangles where the base had them, every vertex on the sphere), and bad bases that are
//! clear errors writing nothing.

use crate::common;

use common::json_object;

/// A cube on the unit sphere with one face split into two triangles.
const CUBE: &str = "\
v -0.5773502691896258 -0.5773502691896258 -0.5773502691896258
v 0.5773502691896258 -0.5773502691896258 -0.5773502691896258
v -0.5773502691896258 0.5773502691896258 -0.5773502691896258
v 0.5773502691896258 0.5773502691896258 -0.5773502691896258
v -0.5773502691896258 -0.5773502691896258 0.5773502691896258
v 0.5773502691896258 -0.5773502691896258 0.5773502691896258
v -0.5773502691896258 0.5773502691896258 0.5773502691896258
v 0.5773502691896258 0.5773502691896258 0.5773502691896258
f 1 3 4 2
f 5 6 8 7
f 1 2 6 5
f 3 7 8
f 3 8 4
f 1 5 7 3
f 2 4 8 6
";

#[test]
fn cube_on_the_sphere() {
    let dir = tempfile::tempdir().unwrap();
    let base = dir.path().join("cube.obj");
    std::fs::write(&base, CUBE).unwrap();
    let out = dir.path().join("fine.obj");
    let extra = [
        "--levels",
        "2",
        "--smooth",
        "3",
        "--frames",
        "3",
        "--threads",
        "2",
    ];
    let run = common::remesh_on_sphere(&base, &out, &[&extra[..], &["--json"]].concat());
    assert!(
        run.status.success(),
        "{}",
        String::from_utf8_lossy(&run.stderr)
    );
    let (o, keys) = json_object(&run);
    let mut want = common::REMESH_KEYS.map(String::from);
    want.sort();
    assert_eq!(keys, want);
    assert_eq!(o["base_faces"], 7);
    assert_eq!(o["vertices"], 98);
    assert_eq!(o["faces"], 112);
    assert_eq!(o["levels"], 2);
    assert_eq!(o["smooth_steps"], 3);
    assert_eq!(o["threads"], 2);
    let off = o["max_offsurface"].as_f64().unwrap();
    assert!((0.0..1e-12).contains(&off), "{off}");
    // The file: 98 vertices on the unit sphere, 80 quads and 32 triangles.
    let text = std::fs::read_to_string(&out).unwrap();
    let v: Vec<Vec<f64>> = text
        .lines()
        .filter_map(|l| l.strip_prefix("v "))
        .map(|l| l.split(' ').map(|x| x.parse().unwrap()).collect())
        .collect();
    assert_eq!(v.len(), 98);
    for p in &v {
        let r = (p[0] * p[0] + p[1] * p[1] + p[2] * p[2]).sqrt();
        assert!(r <= 1.0 + 1e-12 && r > 0.99, "{r}");
    }
    let sizes: Vec<usize> = text
        .lines()
        .filter_map(|l| l.strip_prefix("f "))
        .map(|l| l.split(' ').count())
        .collect();
    assert_eq!(sizes.iter().filter(|&&n| n == 4).count(), 80);
    assert_eq!(sizes.iter().filter(|&&n| n == 3).count(), 32);
}

/// Runs `wavg remesh` of `base` into `out` and asserts it exits 2 saying `says` and
/// writes nothing.
fn refused(base: &std::path::Path, out: &std::path::Path, says: &str) {
    let r = common::remesh_on_sphere(base, out, &[]);
    let err = String::from_utf8_lossy(&r.stderr);
    assert_eq!(r.status.code(), Some(2), "{says}: {err}");
    assert!(err.contains(says), "{says}: {err}");
    assert!(!out.exists());
}

#[test]
fn bad_bases_write_nothing() {
    let dir = tempfile::tempdir().unwrap();
    let base = dir.path().join("b.obj");
    let out = dir.path().join("fine.obj");
    let nonmanifold = format!("{CUBE}f 1 3 4 2\n");
    let far = CUBE.replacen("v -0.577", "v -5.77", 1);
    for (text, needle) in [
        ("", "empty"),
        ("v 0 0 0\nv 1 0 0\nf 1 2 3\n", "vertex 2 (0-based)"),
        (nonmanifold.as_str(), "manifold"),
        (far.as_str(), "from the surface"),
        ("v 0 0\n", "line 1"),
    ] {
        std::fs::write(&base, text).unwrap();
        refused(&base, &out, needle);
    }
    // The output is OBJ text (or glTF): a name saying PLY, OFF or gzip is refused.
    std::fs::write(&base, CUBE).unwrap();
    for name in ["r.ply", "r.off", "r.obj.gz"] {
        let says = "give a name ending in .obj, .glb or .gltf";
        refused(&base, &dir.path().join(name), says);
    }
}

/// A base's comments may hold any bytes (an exporter's Latin-1 name), as a mesh file's;
/// its data stays UTF-8.
#[test]
fn a_bases_comments_may_hold_any_bytes() {
    let dir = tempfile::tempdir().unwrap();
    let base = dir.path().join("b.obj");
    let out = dir.path().join("r.obj");
    let mut latin1 = b"# Cube \xe9crit par un exporteur\n".to_vec();
    latin1.extend_from_slice(CUBE.as_bytes());
    std::fs::write(&base, latin1).unwrap();
    let r = common::remesh_on_sphere(&base, &out, &["--frames", "0"]);
    assert!(r.status.success(), "{}", String::from_utf8_lossy(&r.stderr));
    std::fs::write(&base, b"v 0 0 \xe9\n").unwrap();
    std::fs::remove_file(&out).unwrap();
    refused(&base, &out, "b.obj:1: the text is not valid UTF-8");
}
