//! Commands killed with SIGKILL at random moments never leave a partial or corrupt output
//! under the final name: the file is either absent or exactly what a complete run writes.

use crate::common;

use std::path::Path;
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

use rand::{Rng, SeedableRng};
use wavg::mesh::{io, procedural};

/// Runs `wavg ARGS` to completion and returns its wall time.
fn timed_run(args: &[&str]) -> Duration {
    let t = Instant::now();
    common::wavg_ok(args);
    t.elapsed()
}

/// Starts `wavg ARGS`, kills it after `delay` (if still running) and waits for it.
fn kill_after(args: &[&str], delay: Duration) {
    let mut child = Command::new(env!("CARGO_BIN_EXE_wavg"))
        .args(args)
        .env("WAVG_CACHE_DIR", common::cache_dir())
        .stdout(Stdio::null())
        .stderr(Stdio::null())
        .spawn()
        .expect("start wavg");
    std::thread::sleep(delay);
    let _ = child.kill(); // SIGKILL on Unix
    let _ = child.wait();
}

/// Kills `args` at `runs` random moments within 1.5 times its full duration; after each, `out` must be
/// absent or byte-identical to the complete run's output (`reference`).
fn check_kills(args: &[&str], out: &Path, runs: usize, seed: u64) {
    let full = timed_run(args);
    let reference = std::fs::read(out).expect("complete run writes its output");
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(seed);
    let mut absent = 0;
    for _ in 0..runs {
        std::fs::remove_file(out).ok();
        let delay = full.mul_f64(rng.random_range(0.0..1.5));
        kill_after(args, delay);
        match std::fs::read(out) {
            Ok(bytes) => assert!(
                bytes == reference,
                "{args:?} killed after {delay:?}: {} bytes under the final name, expected {}",
                bytes.len(),
                reference.len()
            ),
            Err(_) => absent += 1,
        }
    }
    eprintln!("{args:?}: {runs} kills within {full:?}, output absent after {absent}");
    assert!(
        absent > 0,
        "no kill interrupted {args:?}: the test did not test anything"
    );
    // Leave the complete output for the commands that read it next.
    std::fs::write(out, &reference).unwrap();
}

#[test]
fn killed_commands_leave_whole_outputs_or_none() {
    let dir = tempfile::tempdir().unwrap();
    let p = |name: &str| dir.path().join(name).to_str().unwrap().to_string();
    let mesh = procedural::torus(96, 48, 1.0, 0.35);
    io::save(Path::new(&p("torus.obj")), &mesh).unwrap();

    let wavg_out = p("torus.wavg");
    let precompute = [
        "precompute",
        &p("torus.obj"),
        "-o",
        &wavg_out,
        "--landmarks",
        "150",
    ];
    check_kills(&precompute, Path::new(&wavg_out), 8, 1);

    let repaired = p("fixed.ply");
    check_kills(
        &["repair", &p("torus.obj"), "-o", &repaired],
        Path::new(&repaired),
        8,
        2,
    );

    // Many inverse problems: a multi-megabyte text output.
    std::fs::write(
        p("anchors.txt"),
        "v 0\nv 1000\nv 2000\nv 3000\nv 4000\nv 4500\n",
    )
    .unwrap();
    let points: String = (0..40_000)
        .map(|i| format!("f {} 0.2 0.3 0.5\n", i % mesh.n_faces()))
        .collect();
    std::fs::write(p("points.txt"), points).unwrap();
    let weights = p("weights.txt");
    let inverse = [
        "inverse",
        "--mesh",
        &p("torus.obj"),
        "--embedding",
        &wavg_out,
        "--anchors",
        &p("anchors.txt"),
        "--points",
        &p("points.txt"),
        "-o",
        &weights,
    ];
    check_kills(&inverse, Path::new(&weights), 8, 3);
}
