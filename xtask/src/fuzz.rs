//! `cargo xtask fuzz [--seconds N] [--target NAME]`: builds the coverage-guided fuzz targets
//! in `fuzz/` (libFuzzer through libfuzzer-sys, with the coverage instrumentation cargo-fuzz
//! would add and no sanitizer, so the stable toolchain and plain cargo suffice; no
//! cargo-fuzz to install), seeds their corpora from meshes the project generates, and runs
//! each target for N seconds.

use std::path::{Path, PathBuf};
use std::process::Command;

use crate::steps;

/// The fuzz targets, in the order they run.
pub const TARGETS: &[&str] = &[
    "mesh_read",
    "wavg_file",
    "validate_repair",
    "solver",
    "text_formats",
    "png_texture",
    "gltf_read",
];

/// Longest input libFuzzer makes for `target` (its own default otherwise, which is the
/// largest seed's length). Mesh seeds run to hundreds of kilobytes, and a valid mesh is
/// analysed, validated and written and read back in three formats, so long inputs cost
/// milliseconds each; every branch of the readers (headers, counts, lists, binary
/// layouts) is reachable within a few kilobytes.
fn max_len(target: &str) -> Option<usize> {
    matches!(target, "mesh_read" | "gltf_read").then_some(4096)
}

/// Builds and runs every target (or only `only`) for `seconds` each; `Err` names the first
/// failure.
/// Prints each part's wall time (`cargo xtask test` runs this beside other steps, where
/// only the whole is in its table).
pub fn run(root: &Path, seconds: u64, only: Option<&str>) -> Result<(), String> {
    let t = std::time::Instant::now();
    seed_corpora(root, &root.join("fuzz"))?;
    let bin_dir = build(root)?;
    eprintln!(
        "==> fuzz: seed corpora and instrumented build in {:.1} s",
        t.elapsed().as_secs_f64()
    );
    let t = std::time::Instant::now();
    run_built(root, &bin_dir, seconds, only)?;
    eprintln!(
        "==> fuzz: targets run in {:.1} s",
        t.elapsed().as_secs_f64()
    );
    Ok(())
}

/// Builds the targets with libFuzzer's instrumentation on the workspace's own crates (see
/// [`crate::sancov`]), in the dev profile (optimised, debug assertions and overflow checks
/// on, as cargo-fuzz builds); returns the folder of the binaries. It must come after any
/// plain build of the workspace (the seed corpora's), which puts uninstrumented targets in
/// the same place.
fn build(root: &Path) -> Result<PathBuf, String> {
    let xtask = std::env::current_exe().map_err(|e| format!("xtask's own path: {e}"))?;
    let xtask = xtask.to_string_lossy();
    steps::command_env(
        root,
        "cargo",
        &["build", "-p", "wavg-fuzz", "--bins"],
        &[
            ("RUSTC_WORKSPACE_WRAPPER", &xtask),
            (crate::sancov::ENV, "1"),
        ],
    )?;
    Ok(steps::target_dir(root).join("debug"))
}

/// How many targets run at once: libFuzzer keeps one core busy per target.
fn parallel_runs() -> usize {
    std::thread::available_parallelism().map_or(1, |n| n.get())
}

/// Runs the built targets from `bin_dir`, as many at once as there are cores, each with its
/// output in `target/fuzz-logs/TARGET.log` (its last lines printed when it fails).
fn run_built(root: &Path, bin_dir: &Path, seconds: u64, only: Option<&str>) -> Result<(), String> {
    let fuzz_dir = root.join("fuzz");
    let logs = root.join("target/fuzz-logs");
    std::fs::create_dir_all(&logs).map_err(|e| format!("{}: {e}", logs.display()))?;
    let targets: Vec<&str> = TARGETS
        .iter()
        .copied()
        .filter(|t| only.is_none_or(|o| o == *t))
        .collect();
    for group in targets.chunks(parallel_runs()) {
        let results: Vec<Result<(), String>> = std::thread::scope(|scope| {
            let runs: Vec<_> = group
                .iter()
                .map(|target| {
                    let (fuzz_dir, logs) = (&fuzz_dir, &logs);
                    scope.spawn(move || run_one(bin_dir, fuzz_dir, logs, target, seconds))
                })
                .collect();
            runs.into_iter()
                .map(|h| {
                    h.join()
                        .unwrap_or_else(|_| Err("a fuzz runner panicked".into()))
                })
                .collect()
        });
        results.into_iter().collect::<Result<(), String>>()?;
    }
    Ok(())
}

/// Whether libFuzzer's log says it found coverage counters ("Loaded 1 modules (6509 inline
/// 8-bit counters)"); without them it fuzzes blind.
fn instrumented(log: &str) -> bool {
    log.lines()
        .filter_map(|l| l.strip_prefix("INFO: Loaded "))
        .filter_map(|l| {
            l.split_once('(')?
                .1
                .split_whitespace()
                .next()?
                .parse::<u64>()
                .ok()
        })
        .any(|counters| counters > 0)
}

/// One target for `seconds`; `Ok` with a line of its final statistics printed.
fn run_one(
    bin_dir: &Path,
    fuzz_dir: &Path,
    logs: &Path,
    target: &str,
    seconds: u64,
) -> Result<(), String> {
    let corpus = fuzz_dir.join("corpus").join(target);
    std::fs::create_dir_all(&corpus).map_err(|e| format!("{}: {e}", corpus.display()))?;
    let artifacts = fuzz_dir.join("artifacts").join(target);
    std::fs::create_dir_all(&artifacts).map_err(|e| format!("{}: {e}", artifacts.display()))?;
    let log_path = logs.join(format!("{target}.log"));
    let (log, log_err) = steps::output_file(&log_path)?;
    eprintln!(
        "    fuzz {target} for {seconds} s (output in {})",
        log_path.display()
    );
    let status = Command::new(bin_dir.join(target))
        .arg(&corpus)
        .args([
            format!("-artifact_prefix={}/", artifacts.display()),
            format!("-max_total_time={seconds}"),
            "-rss_limit_mb=4096".into(),
            "-timeout=20".into(),
            "-print_final_stats=1".into(),
        ])
        .args(max_len(target).map(|n| format!("-max_len={n}")))
        .current_dir(fuzz_dir)
        .stdout(log)
        .stderr(log_err)
        .status()
        .map_err(|e| format!("could not start {target}: {e}"))?;
    let text = std::fs::read_to_string(&log_path).unwrap_or_default();
    if status.success() && !instrumented(&text) {
        return Err(format!(
            "fuzz target {target} ran without coverage counters (an uninstrumented build in \
             its place?); see {}",
            log_path.display()
        ));
    }
    if !status.success() {
        let lines: Vec<&str> = text.lines().collect();
        let tail = lines[lines.len().saturating_sub(40)..].join("\n");
        return Err(format!(
            "fuzz target {target} failed ({status}):\n{tail}\nthe input is in \
             fuzz/artifacts/{target}/: add it as a regression test"
        ));
    }
    let stat = |key: &str| {
        text.lines()
            .find_map(|l| l.strip_prefix(key))
            .map_or("?", str::trim)
            .to_owned()
    };
    eprintln!(
        "    fuzz {target}: {} runs, {} per second, {} new units",
        stat("stat::number_of_executed_units:"),
        stat("stat::average_exec_per_sec:"),
        stat("stat::new_units_added:")
    );
    Ok(())
}

/// Writes seed inputs made by the `wavg` binary from built-in meshes (and two small
/// shared meshes when the data folder is there) into the corpus folders, once.
fn seed_corpora(root: &Path, fuzz_dir: &Path) -> Result<(), String> {
    let seeds = fuzz_dir.join("corpus");
    seed_gltf(&seeds.join("gltf_read"))?;
    let mesh_dir = seeds.join("mesh_read");
    let file_dir = seeds.join("wavg_file");
    if mesh_dir.is_dir() && file_dir.is_dir() && seeds.join("png_texture").is_dir() {
        return Ok(());
    }
    // The everyday build's feature set, so that after the tests nothing is rebuilt.
    steps::cargo_build_all(root).map_err(|e| format!("building wavg for the seed corpora: {e}"))?;
    let wavg = steps::target_dir(root).join("debug/wavg");
    let tmp = seeds.join("tmp");
    for d in [&mesh_dir, &file_dir, &tmp] {
        std::fs::create_dir_all(d).map_err(|e| format!("{}: {e}", d.display()))?;
    }
    let run = |args: &[&str]| -> Result<(), String> {
        let out = Command::new(&wavg)
            .args(args)
            .output()
            .map_err(|e| format!("wavg: {e}"))?;
        if out.status.success() {
            Ok(())
        } else {
            Err(format!(
                "wavg {args:?}: {}",
                String::from_utf8_lossy(&out.stderr)
            ))
        }
    };
    let mut sources: Vec<PathBuf> = Vec::new();
    // A tetrahedron in every format: seeds well within the mesh target's input length.
    let tet = tmp.join("tet-src.obj");
    let tet_text = "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nf 1 3 2\nf 1 2 4\nf 2 3 4\nf 3 1 4\n";
    std::fs::write(&tet, tet_text).map_err(|e| format!("{}: {e}", tet.display()))?;
    for ext in ["obj", "off", "ply"] {
        let p = tmp.join(format!("tet.{ext}"));
        run(&[
            "repair",
            tet.to_str().unwrap_or_default(),
            "-o",
            p.to_str().unwrap_or_default(),
        ])?;
        sources.push(p);
    }
    for (name, builtin) in [("sphere", "builtin:sphere-small"), ("grid", "builtin:grid")] {
        for ext in ["obj", "off", "ply"] {
            let p = tmp.join(format!("{name}.{ext}"));
            run(&["repair", builtin, "-o", p.to_str().unwrap_or_default()])?;
            sources.push(p);
        }
    }
    let data = std::env::var_os("WAVG_DATA_DIR")
        .map(PathBuf::from)
        .unwrap_or_else(|| root.join("../shared/data"));
    for rel in ["meshes/spot_control_mesh.obj", "meshes/3holes.off"] {
        let p = data.join(rel);
        if p.is_file() {
            sources.push(p);
        }
    }
    for (i, src) in sources.iter().enumerate() {
        let ext = src.extension().and_then(|e| e.to_str()).unwrap_or("");
        let pick = match ext {
            "obj" => 0u8,
            "off" => 1,
            _ => 2,
        };
        let body = std::fs::read(src).map_err(|e| format!("{}: {e}", src.display()))?;
        let mut seed = vec![pick];
        seed.extend(body);
        let dst = mesh_dir.join(format!("seed-{i}"));
        std::fs::write(&dst, seed).map_err(|e| format!("{}: {e}", dst.display()))?;
    }
    let emb = file_dir.join("seed-sphere.wavg");
    run(&[
        "precompute",
        "builtin:sphere-small",
        "-o",
        emb.to_str().unwrap_or_default(),
        "--landmarks",
        "20",
    ])?;
    let text_dir = seeds.join("text_formats");
    std::fs::create_dir_all(&text_dir).map_err(|e| format!("{}: {e}", text_dir.display()))?;
    let text = "# anchors and weights\nv 1\nf 2 0.2 0.3 0.5\n0.5 0.25 0.25\n1e-7 -3.5e20 0.0\n";
    let dst = text_dir.join("seed-text");
    std::fs::write(&dst, text).map_err(|e| format!("{}: {e}", dst.display()))?;
    let png_dir = seeds.join("png_texture");
    std::fs::create_dir_all(&png_dir).map_err(|e| format!("{}: {e}", png_dir.display()))?;
    let png = png_dir.join("seed-sphere.png");
    run(&[
        "render",
        "builtin:sphere-small",
        "-o",
        png.to_str().unwrap_or_default(),
        "--size",
        "16x12",
    ])?;
    let _ = std::fs::remove_dir_all(&tmp);
    Ok(())
}

/// A GLB of a tetrahedron with texture coordinates, one vertex split at a seam, placed
/// by a node with a transform: the glTF reader's seed (built here, as the `wavg` binary
/// does not write glTF).
fn seed_gltf(dir: &Path) -> Result<(), String> {
    if dir.is_dir() {
        return Ok(());
    }
    std::fs::create_dir_all(dir).map_err(|e| format!("{}: {e}", dir.display()))?;
    let pos: [f32; 15] = [0., 0., 0., 1., 0., 0., 0., 1., 0., 0., 0., 1., 0., 0., 0.];
    let uv: [f32; 10] = [0., 0., 1., 0., 0., 1., 1., 1., 0.5, 0.5];
    let idx: [u16; 12] = [0, 2, 1, 4, 1, 3, 1, 2, 3, 2, 0, 3];
    let mut bin: Vec<u8> = pos.iter().flat_map(|x| x.to_le_bytes()).collect();
    bin.extend(uv.iter().flat_map(|x| x.to_le_bytes()));
    bin.extend(idx.iter().flat_map(|x| x.to_le_bytes()));
    let json = format!(
        r#"{{"asset":{{"version":"2.0"}},"scene":0,"scenes":[{{"nodes":[0]}}],"nodes":[{{"mesh":0,"translation":[1,2,3],"children":[1]}},{{"mesh":0,"scale":[-1,1,1]}}],"meshes":[{{"name":"tet","primitives":[{{"attributes":{{"POSITION":0,"TEXCOORD_0":1}},"indices":2}}]}}],"accessors":[{{"bufferView":0,"componentType":5126,"count":5,"type":"VEC3","min":[0,0,0],"max":[1,1,1]}},{{"bufferView":1,"componentType":5126,"count":5,"type":"VEC2"}},{{"bufferView":2,"componentType":5123,"count":12,"type":"SCALAR"}}],"bufferViews":[{{"buffer":0,"byteLength":60}},{{"buffer":0,"byteOffset":60,"byteLength":40}},{{"buffer":0,"byteOffset":100,"byteLength":24}}],"buffers":[{{"byteLength":{}}}]}}"#,
        bin.len()
    );
    let mut j = json.into_bytes();
    while j.len() % 4 != 0 {
        j.push(b' ');
    }
    let total = 12 + 8 + j.len() + 8 + bin.len();
    let mut glb = b"glTF".to_vec();
    for word in [2, total as u32, j.len() as u32, 0x4E4F_534A] {
        glb.extend(word.to_le_bytes());
    }
    glb.extend(&j);
    for word in [bin.len() as u32, 0x004E_4942] {
        glb.extend(word.to_le_bytes());
    }
    glb.extend(&bin);
    let dst = dir.join("seed-tet.glb");
    std::fs::write(&dst, glb).map_err(|e| format!("{}: {e}", dst.display()))
}

#[cfg(test)]
mod tests {
    use super::instrumented;

    #[test]
    fn coverage_counters_are_read_from_the_log() {
        let with = "INFO: Seed: 1\nINFO: Loaded 1 modules   (6509 inline 8-bit counters): 6509 \
                    [0x55, 0x56),\nINFO: Loaded 1 PC tables (6509 PCs): 6509 [0x5,0x6),\n";
        assert!(instrumented(with));
        let without = "INFO: Seed: 1\nWARNING: no interesting inputs were found so far. Is the \
                       code instrumented for coverage?\n";
        assert!(!instrumented(without));
        assert!(!instrumented(
            "INFO: Loaded 1 modules   (0 inline 8-bit counters)\n"
        ));
    }
}
