//! Outputs checked before any work: a missing folder, `--json` with `-o -`, two outputs
//! that are one file, an output that is an input, and a file type the command cannot
//! write; each is an input error (status 2) that writes nothing.

mod common;

use common::wavg;

fn refused(args: &[&str], words: &str) {
    let out = wavg(args);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{args:?}: {stderr}");
    assert!(stderr.contains(words), "{args:?}: {stderr}");
    assert!(out.stdout.is_empty(), "{args:?} printed to stdout");
}

#[test]
fn bad_outputs_are_refused_before_any_work() {
    let dir = tempfile::tempdir().unwrap();
    let d = |name: &str| dir.path().join(name).to_string_lossy().into_owned();
    let mesh = d("m.obj");
    let torus = wavg(&["subdivide", "builtin:torus", "--levels", "0", "-o", &mesh]);
    assert!(
        torus.status.success(),
        "{}",
        String::from_utf8_lossy(&torus.stderr)
    );
    let before = std::fs::read(&mesh).unwrap();
    let control = d("c.txt");
    std::fs::write(&control, "v 0\nv 300\nv 600\nv 900\n").unwrap();
    refused(
        &["subdivide", &mesh, "-o", &d("nodir/x.obj")],
        "does not exist",
    );
    let spline = |out: &str| {
        let args = [
            "spline",
            &mesh,
            "--embedding",
            "none",
            "--control",
            &control,
            "-o",
            out,
        ];
        args.map(str::to_owned).to_vec()
    };
    let mut json = spline("-");
    json.push("--json".into());
    refused(
        &json.iter().map(String::as_str).collect::<Vec<_>>(),
        "--json",
    );
    refused(
        &["repair", &mesh, "-o", &d("r.obj"), "--map", &d("r.obj")],
        "name the same file",
    );
    refused(&["subdivide", &mesh, "-o", &mesh], "is an input");
    refused(
        &[
            "precompute",
            &mesh,
            "-o",
            &d("m.wavg"),
            "--repaired-mesh",
            &mesh,
        ],
        "is an input",
    );
    refused(
        &spline(&control)
            .iter()
            .map(String::as_str)
            .collect::<Vec<_>>(),
        "is an input",
    );
    refused(
        &[
            "decal",
            &mesh,
            "--embedding",
            "none",
            "--anchors",
            &control,
            "--uv",
            &control,
            "-o",
            &d("t.off"),
        ],
        "ending in .obj",
    );
    assert_eq!(
        std::fs::read(&mesh).unwrap(),
        before,
        "the input mesh changed"
    );
    assert!(!dir.path().join("r.obj").exists() && !dir.path().join("m.wavg").exists());
}
