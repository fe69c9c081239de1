//! Outputs checked before any work: a missing folder, `--json` with `-o -`, two outputs
//! that are one file, an output that is an input, and a file type the command cannot
//! write; each is an input error (status 2) that writes nothing.

use crate::common;

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
    refused(
        &["subdivide", &mesh, "-o", &d("m.obj/x.obj")],
        "is not a folder",
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

/// Outputs that name an input another way: a file not yet written under two spellings,
/// the anchors or the embedding, a hard link, a folder; a symbolic link is written
/// through, never replaced.
#[test]
fn outputs_named_another_way() {
    let dir = tempfile::tempdir().unwrap();
    let d = |name: &str| dir.path().join(name).to_string_lossy().into_owned();
    let mesh = d("m.obj");
    let torus = wavg(&["subdivide", "builtin:torus", "--levels", "0", "-o", &mesh]);
    assert!(torus.status.success());
    let anchors = d("a.txt");
    std::fs::write(&anchors, "v 0\nv 300\nv 600\n").unwrap();
    let weights = d("w.txt");
    std::fs::write(&weights, "0.2 0.3 0.5\n").unwrap();
    let forward = |out: &str| {
        wavg(&[
            "forward",
            &mesh,
            "--embedding",
            "none",
            "--anchors",
            &anchors,
            "--weights",
            &weights,
            "-o",
            out,
        ])
    };
    let sub = dir.path().join("sub");
    std::fs::create_dir(&sub).unwrap();
    let twice = format!("{}/../r.obj", sub.display());
    refused(
        &["repair", &mesh, "-o", &d("r.obj"), "--map", &twice],
        "name the same file",
    );
    for out in [anchors.clone(), d("sub")] {
        let r = forward(&out);
        assert_eq!(
            r.status.code(),
            Some(2),
            "{out}: {}",
            String::from_utf8_lossy(&r.stderr)
        );
    }
    #[cfg(unix)]
    {
        let hard = d("hard.txt");
        std::fs::hard_link(&weights, &hard).unwrap();
        assert_eq!(forward(&hard).status.code(), Some(2));
        let (target, link) = (d("t.txt"), d("link.txt"));
        std::os::unix::fs::symlink(&target, &link).unwrap();
        assert!(forward(&link).status.success());
        assert!(
            std::fs::symlink_metadata(&link)
                .unwrap()
                .file_type()
                .is_symlink()
        );
        assert_eq!(std::fs::read_to_string(&target).unwrap().lines().count(), 1);
    }
    assert_eq!(
        std::fs::read_to_string(&anchors).unwrap(),
        "v 0\nv 300\nv 600\n"
    );
}

/// Output names a reader would take for something else (`#NAME` selects a glTF mesh when
/// reading), formats no writer makes (gzip-compressed glTF), and `-` for an output that is
/// a folder or a file read back by name (a mesh, whose format is its extension; an
/// embedding): refused before any work (status 2), the message naming what to write
/// instead, and nothing written (no file or folder named `-`).
#[test]
fn output_names_that_would_not_read_back_and_folders_on_stdout() {
    let dir = tempfile::tempdir().unwrap();
    let d = |name: &str| dir.path().join(name).to_string_lossy().into_owned();
    for ext in ["gltf.gz", "glb.gz"] {
        let out = d(&format!("x.{ext}"));
        for command in ["repair", "subdivide"] {
            refused(&[command, "builtin:torus", "-o", &out], &format!(".{ext}"));
            refused(
                &[command, "builtin:torus", "-o", &out],
                ".obj, .off or .ply",
            );
        }
    }
    refused(&["repair", "builtin:torus", "-o", &d("m.stl")], "\".stl\"");
    refused(
        &["repair", "builtin:torus", "-o", &d("h.glb#Body")],
        "#Body selects a mesh",
    );
    let control = d("c.txt");
    std::fs::write(&control, "v 0\nv 300\nv 600\nv 900\n").unwrap();
    let spline = [
        "spline",
        "builtin:torus",
        "--embedding",
        "none",
        "--control",
        &control,
        "-o",
        &d("s.gltf#Curve"),
    ];
    refused(&spline, "#Curve selects a mesh");
    let a = control.as_str();
    let m = "builtin:icosphere";
    for out in ["-", "frames.gltf.gz"] {
        let args = common::pair_args("morph", [m, m], [a, a], out);
        let r = common::wavg_command()
            .current_dir(dir.path())
            .args(&args)
            .output()
            .unwrap();
        let stderr = String::from_utf8_lossy(&r.stderr);
        assert_eq!(r.status.code(), Some(2), "{out}: {stderr}");
        let says = if out == "-" {
            "a folder of files"
        } else {
            ".gltf.gz"
        };
        assert!(stderr.contains(says), "{out}: {stderr}");
        assert!(!dir.path().join(out).exists(), "{out} was made");
    }
    let in_dir = |args: &[&str], says: &str| {
        let r = common::wavg_command()
            .current_dir(dir.path())
            .args(args)
            .output()
            .unwrap();
        let stderr = String::from_utf8_lossy(&r.stderr);
        assert_eq!(r.status.code(), Some(2), "{args:?}: {stderr}");
        assert!(stderr.contains(says), "{args:?}: {stderr}");
        assert!(r.stdout.is_empty(), "{args:?} printed to stdout");
    };
    in_dir(&["demo", "--out", "-"], "a folder of files");
    // A mesh's format follows its file's extension; the embedding is read back by name.
    for command in ["repair", "subdivide"] {
        in_dir(
            &[command, "builtin:sphere-small", "-o", "-"],
            "-o -: a mesh is written to a file",
        );
    }
    in_dir(
        &["precompute", "builtin:sphere-small", "-o", "-"],
        "give a file name ending in .wavg",
    );
    in_dir(
        &[
            "precompute",
            "builtin:sphere-small",
            "-o",
            "e.wavg",
            "--repaired-mesh",
            "-",
        ],
        "--repaired-mesh -: a mesh is written to a file",
    );
    let mut left: Vec<_> = std::fs::read_dir(dir.path())
        .unwrap()
        .map(|e| e.unwrap().file_name().into_string().unwrap())
        .collect();
    left.sort();
    assert_eq!(left, ["c.txt"]);
}
