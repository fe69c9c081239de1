//! `wavg precompute` run as a process: JSON keys, the written file, error messages.

use crate::common;

use common::{wavg, wavg_ok};

use std::path::Path;
use std::process::{Command, Output};

use serde_json::Value;
use wavg::mesh::{TriMesh, ValidMesh, io, procedural};

/// Runs `wavg precompute MESH -o OUT EXTRA...`.
fn precompute(mesh: &str, out: &Path, extra: &[&str]) -> Output {
    let args = [
        &["precompute", mesh, "-o", out.to_str().unwrap()][..],
        extra,
    ]
    .concat();
    wavg(&args)
}

fn write(dir: &Path, name: &str, mesh: &TriMesh) -> String {
    let path = dir.join(name);
    io::save(&path, mesh).unwrap();
    path.to_str().unwrap().to_string()
}

#[test]
fn json_report_and_loadable_file() {
    let dir = tempfile::tempdir().unwrap();
    let mesh = procedural::torus(48, 24, 1.0, 0.4);
    let mesh_path = write(dir.path(), "torus.off", &mesh);
    let out_path = dir.path().join("torus.wavg");
    let out = precompute(
        &mesh_path,
        &out_path,
        &["--landmarks", "100", "--seed", "7", "--json"],
    );
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    // Not a terminal: no progress output at all.
    assert!(
        out.stderr.is_empty(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let v: Value = serde_json::from_slice(&out.stdout).expect("one JSON object");
    for key in [
        "seconds",
        "landmarks",
        "dim",
        "stress",
        "geodesic_rel_err_p50",
        "geodesic_rel_err_p90",
        "vertices",
        "faces",
    ] {
        assert!(v[key].is_number(), "{key}: {v}");
    }
    for stage in ["decimate", "geodesics", "mds", "lsmesh"] {
        assert!(v["stages"][stage].as_f64().unwrap() >= 0.0, "{stage}");
    }
    assert_eq!(v["landmarks"], 100);
    assert_eq!(v["dim"], 8);
    assert_eq!(v["vertices"], mesh.n_vertices());
    assert_eq!(v["faces"], mesh.n_faces());
    assert!(v["geodesic_rel_err_p50"].as_f64().unwrap() < 0.1);

    // The file loads against the mesh as read back from disk, and only against it.
    let disk = ValidMesh::new(io::load(Path::new(&mesh_path)).unwrap()).unwrap();
    let emb = wavg::embed::file::load(&out_path, &disk).unwrap();
    assert_eq!(emb.landmarks.len(), 100);
    assert_eq!(emb.params.seed, 7);
    assert_eq!(emb.stress, v["stress"].as_f64().unwrap());
    let other = procedural::torus(48, 24, 1.0, 0.41);
    assert!(matches!(
        wavg::embed::file::load(&out_path, &other),
        Err(wavg::embed::EmbedError::MeshMismatch { .. })
    ));

    // Text mode works too and overwrites atomically.
    let out = precompute(&mesh_path, &out_path, &["--landmarks", "50"]);
    assert_eq!(out.status.code(), Some(0));
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(text.contains("landmarks     50"), "{text}");
    assert_eq!(
        wavg::embed::file::load(&out_path, &disk)
            .unwrap()
            .landmarks
            .len(),
        50
    );
    assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 2);
}

#[test]
fn two_components_need_largest_component() {
    let dir = tempfile::tempdir().unwrap();
    let big = procedural::icosphere(3);
    let small = procedural::icosphere(1).map_positions(|p| (p * 0.3).add_scalar(3.0));
    let mut m = big.clone();
    let nb = big.n_vertices() as u32;
    m.positions.extend(&small.positions);
    m.triangles
        .extend(small.triangles.iter().map(|t| t.map(|v| v + nb)));
    let mesh_path = write(dir.path(), "two.obj", &m);
    let out_path = dir.path().join("two.wavg");
    let out = precompute(&mesh_path, &out_path, &["--landmarks", "60"]);
    assert_eq!(out.status.code(), Some(2));
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        err.contains("2 connected components") && err.contains("--largest-component"),
        "{err}"
    );
    assert!(
        err.contains("wavg repair") && err.contains("--repaired-mesh"),
        "{err}"
    );
    assert_eq!(err.lines().count(), 1, "{err}");
    assert!(!out_path.exists());

    let repaired = dir.path().join("big.off");
    let out = precompute(
        &mesh_path,
        &out_path,
        &[
            "--landmarks",
            "60",
            "--largest-component",
            "--repaired-mesh",
            repaired.to_str().unwrap(),
            "--json",
        ],
    );
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let v: Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(v["vertices"], big.n_vertices());
    assert_eq!(
        v["removed_by_largest_component"]["vertices"],
        small.n_vertices()
    );
    let disk = io::load(&repaired).unwrap();
    assert!(wavg::embed::file::load(&out_path, &disk).is_ok());
}

#[test]
fn invalid_and_unreadable_meshes_are_clear_errors() {
    let dir = tempfile::tempdir().unwrap();
    // A non-manifold edge: three triangles on one edge.
    let mut m = procedural::grid(4, 4, 1.0, 1.0);
    let extra = m.positions.len() as u32;
    let mut apex = m.positions[0];
    apex.z = 1.0;
    m.positions.push(apex);
    let t = m.triangles[0];
    m.triangles.push([t[0], t[1], extra]);
    let mesh_path = write(dir.path(), "bad.obj", &m);
    let out_path = dir.path().join("bad.wavg");
    let out = precompute(&mesh_path, &out_path, &[]);
    assert_eq!(out.status.code(), Some(2));
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains("not a valid oriented manifold"), "{err}");
    assert!(!out_path.exists());

    let out = precompute("/nonexistent/x.off", &out_path, &[]);
    assert_eq!(out.status.code(), Some(2));
    assert!(!String::from_utf8_lossy(&out.stderr).contains("panicked"));
}

/// Ctrl-C (SIGINT) stops the pipeline cleanly: exit status 130, a one-line message, and no
/// output file (not even a temporary one).
#[cfg(unix)]
#[test]
fn interrupt_stops_cleanly_without_output() {
    use std::time::{Duration, Instant};
    let dir = tempfile::tempdir().unwrap();
    // Full-resolution geodesics on a 41k-vertex sphere: several seconds of work.
    let mesh_path = write(dir.path(), "sphere.off", &procedural::icosphere(6));
    let out_path = dir.path().join("sphere.wavg");
    let child = common::wavg_command()
        .args(["precompute", &mesh_path, "-o", out_path.to_str().unwrap()])
        .args(["--geodesic-vertices", "0"])
        .stderr(std::process::Stdio::piped())
        .spawn()
        .unwrap();
    std::thread::sleep(Duration::from_millis(700));
    let kill = Command::new("kill")
        .args(["-INT", &child.id().to_string()])
        .status()
        .unwrap();
    assert!(kill.success());
    let start = Instant::now();
    let out = child.wait_with_output().unwrap();
    assert_eq!(
        out.status.code(),
        Some(130),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    assert!(
        start.elapsed() < Duration::from_secs(20),
        "cancellation took too long"
    );
    assert!(String::from_utf8_lossy(&out.stderr).contains("interrupted"));
    let names: Vec<_> = std::fs::read_dir(dir.path())
        .unwrap()
        .map(|e| e.unwrap().file_name())
        .collect();
    assert_eq!(
        names,
        vec![std::ffi::OsString::from("sphere.off")],
        "{names:?}"
    );
}

/// Arguments that would be silently ignored or destroy the input are refused before any
/// work, and the input stays as it was.
#[test]
fn arguments_that_would_be_ignored_or_overwrite_the_input_are_refused() {
    let dir = tempfile::tempdir().unwrap();
    let mesh = write(dir.path(), "m.obj", &procedural::icosphere(2));
    let before = std::fs::read(&mesh).unwrap();
    let wavg_out = dir.path().join("m.wavg");
    let w = wavg_out.to_str().unwrap();
    let other = dir.path().join("other.obj");
    for (args, needle) in [
        (
            vec![
                "precompute",
                &mesh,
                "-o",
                w,
                "--landmarks",
                "100",
                "--geodesic-vertices",
                "99",
            ],
            "more than --landmarks",
        ),
        (vec!["precompute", &mesh, "-o", &mesh], "is the input mesh"),
        (
            vec!["precompute", &mesh, "-o", other.to_str().unwrap()],
            "mesh file's extension",
        ),
    ] {
        let out = wavg(&args);
        let err = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(2), "{args:?}: {err}");
        assert!(err.contains(needle), "{args:?}: {err}");
    }
    assert_eq!(std::fs::read(&mesh).unwrap(), before);
    assert!(!wavg_out.exists() && !other.exists());
}

/// `--threads` limits the workers and does not change the embedding, byte for byte.
#[test]
fn the_thread_count_does_not_change_the_embedding() {
    let dir = tempfile::tempdir().unwrap();
    let (one, two) = (dir.path().join("1.wavg"), dir.path().join("2.wavg"));
    for (out, threads) in [(&one, "1"), (&two, "2")] {
        let o = out.to_str().unwrap();
        wavg_ok(&["precompute", "builtin:torus", "-o", o, "--threads", threads]);
    }
    assert_eq!(std::fs::read(&one).unwrap(), std::fs::read(&two).unwrap());
}
