//! Every fenced code block of `README.md` and `docs/*.md` runs as written, or says why not.
//!
//! * `sh` (and `bash`, `shell`) blocks run with `bash -e -o pipefail` in a fresh folder
//!   holding the files the docs name (`mesh.obj`, `a.txt`, `pig.off`, `spot.obj`, ...:
//!   generated here, or taken from `$WAVG_DATA_DIR`; blocks that need a missing data file
//!   print `SKIPPED` and pass), with the dev-built `wavg` first on `PATH`, `../shared/data`
//!   pointing at the data folder, and a private `HOME` and embedding cache. A block that
//!   fails, or that changes one of those input files (an example must never overwrite
//!   its input), fails the test.
//! * `python` blocks run the same way (as a script in such a folder) with
//!   `$WAVG_DOCS_PYTHON`, else `target/py-venv/bin/python`, else `python3`; one that stops
//!   on a module this machine does not have prints `SKIPPED`, unless `$WAVG_DOCS_PYTHON`
//!   is set: `cargo xtask test` sets it (and `WAVG_DOCS_LANGS=python`, which checks only
//!   those blocks) after it installs the package, so there they must run.
//! * `text`, `json`, `console` and `output` blocks are not code.
//! * Any other block (Rust, C, C++, CMake, TOML, JavaScript, ...) must be marked by an HTML
//!   comment on the line before it: `<!-- docs-test: excerpt PATH -->` for an excerpt of
//!   a file the tests build and run (every function the block calls must appear in PATH),
//!   or `<!-- docs-test: skip REASON -->` for a block that cannot run here (the reason is
//!   required). Both markers work on `sh` blocks too. An unmarked block without a runner
//!   fails the test.

use crate::common;

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::process::Command;

/// One fenced block.
struct Block {
    file: String,
    line: usize,
    lang: String,
    marker: Option<String>,
    body: String,
}

fn repo() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../..")
}

/// The fenced blocks of `text` (from `file`), with the `docs-test` marker before each.
fn blocks(file: &str, text: &str) -> Vec<Block> {
    let mut out = Vec::new();
    let lines: Vec<&str> = text.lines().collect();
    let mut i = 0;
    while i < lines.len() {
        let Some(lang) = lines[i].trim_start().strip_prefix("```") else {
            i += 1;
            continue;
        };
        let fence = &lines[i][..lines[i].find("```").unwrap() + 3];
        let start = i;
        let marker = (0..i)
            .rev()
            .map(|j| lines[j].trim())
            .find(|l| !l.is_empty())
            .and_then(|l| l.strip_prefix("<!-- docs-test:"))
            .and_then(|l| l.strip_suffix("-->"))
            .map(|m| m.trim().to_string());
        let mut body = String::new();
        i += 1;
        while i < lines.len() && lines[i].trim() != fence.trim() {
            body.push_str(lines[i]);
            body.push('\n');
            i += 1;
        }
        out.push(Block {
            file: file.to_string(),
            line: start + 1,
            lang: lang.trim().to_string(),
            marker,
            body,
        });
        i += 1;
    }
    out
}

/// README.md and every `docs/*.md`, as (name, text).
fn documents() -> Vec<(String, String)> {
    let mut files = vec![repo().join("README.md")];
    let mut docs: Vec<PathBuf> = std::fs::read_dir(repo().join("docs"))
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|x| x == "md"))
        .collect();
    docs.sort();
    files.extend(docs);
    files
        .into_iter()
        .map(|p| {
            let name = p.strip_prefix(repo()).unwrap_or(&p).display().to_string();
            (name, std::fs::read_to_string(&p).unwrap())
        })
        .collect()
}

/// The data folder, when present.
fn data_dir() -> Option<PathBuf> {
    let d = std::env::var_os("WAVG_DATA_DIR")
        .map(PathBuf::from)
        .unwrap_or_else(|| repo().join("../shared/data"));
    d.join("meshes/pig.off").exists().then_some(d)
}

/// Inputs the docs name that come from the data folder: name -> path inside it.
const DATA_FILES: &[(&str, &str)] = &[
    ("pig.off", "meshes/pig.off"),
    ("fertility.off", "meshes/fertility.off"),
    ("spot.obj", "textured/spot/spot_triangulated.obj"),
    ("spot.png", "textured/spot/spot_texture.png"),
    ("source.obj", "textured/spot/spot_triangulated.obj"),
    ("source.png", "textured/spot/spot_texture.png"),
];

/// Runs `wavg ARGS` in `dir` for a fixture, asserting success.
fn wavg_in(dir: &Path, args: &[&str]) {
    let out = Command::new(env!("CARGO_BIN_EXE_wavg"))
        .args(args)
        .current_dir(dir)
        .env("WAVG_CACHE_DIR", common::cache_dir())
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "fixture: wavg {args:?}: {}",
        String::from_utf8_lossy(&out.stderr)
    );
}

/// A copy of the mesh at `from` with the same connectivity and UVs, bent and stretched.
fn bent_copy(from: &Path, to: &Path) {
    let m = wavg::mesh::io::load(from).unwrap();
    let bent = m.map_positions(|p| {
        let a = 0.4 * p.y;
        wavg::Vector3::new(
            p.x * a.cos() - p.z * a.sin(),
            1.3 * p.y,
            p.x * a.sin() + p.z * a.cos(),
        )
    });
    wavg::mesh::io::save(to, &bent).unwrap();
}

/// A `.npy` file of `rows` points `FACE B0 B1 B2` (float64, C order).
fn write_points_npy(path: &Path, rows: &[[f64; 4]]) {
    let mut header = format!(
        "{{'descr': '<f8', 'fortran_order': False, 'shape': ({}, 4), }}",
        rows.len()
    );
    while (10 + header.len() + 1) % 64 != 0 {
        header.push(' ');
    }
    header.push('\n');
    let mut b = b"\x93NUMPY\x01\x00".to_vec();
    b.extend_from_slice(&(header.len() as u16).to_le_bytes());
    b.extend_from_slice(header.as_bytes());
    for r in rows {
        for x in r {
            b.extend_from_slice(&x.to_le_bytes());
        }
    }
    std::fs::write(path, b).unwrap();
}

/// An oriented tetrahedron (OBJ) on four spread vertices of `mesh`: a remeshing base.
fn tetra_cage(mesh: &Path, to: &Path) {
    let m = wavg::ValidMesh::new(wavg::mesh::io::load(mesh).unwrap()).unwrap();
    let ids =
        wavg::sampling::farthest_point_vertices(&m, 4, 0, wavg::sampling::FpsMetric::EdgeGraph)
            .unwrap();
    let p: Vec<_> = ids.iter().map(|&v| m.positions[v as usize]).collect();
    let c = (p[0] + p[1] + p[2] + p[3]) / 4.0;
    let mut obj: String = p
        .iter()
        .map(|q| format!("v {} {} {}\n", q.x, q.y, q.z))
        .collect();
    for [a, b, d] in [[0, 1, 2], [0, 1, 3], [0, 2, 3], [1, 2, 3]] {
        let n = (p[b] - p[a]).cross(&(p[d] - p[a]));
        let out = n.dot(&(p[a] - c)) > 0.0;
        let (b, d) = if out { (b, d) } else { (d, b) };
        obj += &format!("f {} {} {}\n", a + 1, b + 1, d + 1);
    }
    std::fs::write(to, obj).unwrap();
}

/// The inputs in `dir`: generated ones always, data-backed ones when `data` is present.
fn make_fixtures(dir: &Path, data: Option<&Path>) {
    let w = |args: &[&str]| wavg_in(dir, args);
    w(&[
        "subdivide",
        "builtin:bump",
        "--levels",
        "0",
        "-o",
        "mesh.obj",
    ]);
    w(&["anchors", "mesh.obj", "--count", "24", "-o", "a.txt"]);
    w(&["anchors", "mesh.obj", "--count", "8", "-o", "c.txt"]);
    let weights = format!("{}0.08\n", "0.04 ".repeat(23));
    std::fs::write(dir.join("w.txt"), weights.repeat(3)).unwrap();
    std::fs::write(
        dir.join("p.txt"),
        "v 10\nf 20 0.2 0.3 0.5\nf 400 0.6 0.2 0.2\n",
    )
    .unwrap();
    write_points_npy(
        &dir.join("p.npy"),
        &[[20.0, 0.2, 0.3, 0.5], [400.0, 0.6, 0.2, 0.2]],
    );
    // Two surfaces with one connectivity, paired anchors.
    w(&["subdivide", "builtin:bump", "--levels", "0", "-o", "a.obj"]);
    bent_copy(&dir.join("a.obj"), &dir.join("b.obj"));
    w(&["anchors", "a.obj", "--count", "48", "-o", "sa.txt"]);
    std::fs::copy(dir.join("sa.txt"), dir.join("ta.txt")).unwrap();
    std::fs::write(dir.join("ring.txt"), "v 0\nv 1\nv 2\nv 3\n").unwrap();
    std::fs::write(dir.join("ring_uv.txt"), "0 0\n1 0\n0 1\n1 1\n").unwrap();
    if let Some(data) = data {
        for (name, rel) in DATA_FILES {
            std::fs::copy(data.join(rel), dir.join(name)).unwrap();
        }
        bent_copy(&dir.join("spot.obj"), &dir.join("bent.obj"));
        bent_copy(&dir.join("source.obj"), &dir.join("target.obj"));
        tetra_cage(&dir.join("fertility.off"), &dir.join("cage.obj"));
        w(&[
            "precompute",
            "pig.off",
            "-o",
            "pig.wavg",
            "--landmarks",
            "100",
        ]);
    }
}

/// Name -> contents of every file directly in `dir`.
fn snapshot(dir: &Path) -> BTreeMap<String, Vec<u8>> {
    std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.is_file())
        .map(|p| {
            let name = p.file_name().unwrap().to_string_lossy().into_owned();
            (name, std::fs::read(&p).unwrap())
        })
        .collect()
}

/// Runs an `sh` block in a fresh copy of the fixtures; `Err` says why it failed.
fn run_sh(block: &Block, fixtures: &Path, data: Option<&Path>) -> Result<(), String> {
    let outputs = outputs(&block.body)?;
    let sandbox = Sandbox::new(fixtures, data);
    let before = snapshot(&sandbox.work);
    let out = sandbox
        .command("timeout")
        .args(TIMEOUT)
        .args(["bash", "-e", "-o", "pipefail", "-c", &block.body])
        .output()
        .unwrap();
    if !out.status.success() {
        return Err(format!(
            "exit {:?}: {}",
            out.status.code(),
            String::from_utf8_lossy(&out.stderr)
        ));
    }
    let after = snapshot(&sandbox.work);
    for (name, bytes) in &before {
        if after.get(name) != Some(bytes) && !outputs.contains(name) {
            return Err(format!("it overwrites (or removes) its input {name}"));
        }
    }
    Ok(())
}

/// coreutils `timeout` arguments for one block: a block that hangs (waiting for a window,
/// a server that never answers) fails after five minutes instead of stopping the tests.
const TIMEOUT: [&str; 2] = ["--kill-after=10", "300"];

/// A fresh folder for one block: `work/` (the current folder) holding the fixtures,
/// `shared/data` beside it pointing at the data folder (so `../shared/data` works as in a
/// clone), a private `HOME` (and XDG folders in it) and the tests' embedding cache.
struct Sandbox {
    root: tempfile::TempDir,
    work: PathBuf,
}

impl Sandbox {
    fn new(fixtures: &Path, data: Option<&Path>) -> Sandbox {
        let root = tempfile::tempdir().unwrap();
        let work = root.path().join("work");
        std::fs::create_dir_all(&work).unwrap();
        for (name, bytes) in snapshot(fixtures) {
            std::fs::write(work.join(name), bytes).unwrap();
        }
        if let Some(d) = data {
            std::fs::create_dir_all(root.path().join("shared")).unwrap();
            std::os::unix::fs::symlink(d, root.path().join("shared/data")).unwrap();
        }
        for d in [
            ".local/share/bash-completion/completions",
            ".zfunc",
            ".config/fish/completions",
        ] {
            std::fs::create_dir_all(root.path().join("home").join(d)).unwrap();
        }
        Sandbox { root, work }
    }

    /// `program` in `work/` with the dev-built `wavg` first on `PATH`.
    fn command(&self, program: impl AsRef<std::ffi::OsStr>) -> Command {
        let bin = Path::new(env!("CARGO_BIN_EXE_wavg")).parent().unwrap();
        let path = format!(
            "{}:{}",
            bin.display(),
            std::env::var("PATH").unwrap_or_default()
        );
        let mut c = Command::new(program);
        c.current_dir(&self.work)
            .env("PATH", path)
            .env("HOME", self.root.path().join("home"))
            .env("XDG_CONFIG_HOME", self.root.path().join("home/.config"))
            .env("XDG_CACHE_HOME", self.root.path().join("home/.cache"))
            .env("XDG_DATA_HOME", self.root.path().join("home/.local/share"))
            .env("WAVG_CACHE_DIR", common::cache_dir());
        c
    }
}

/// The files the commands of `body` write (`-o F`, `--output F`, `> F`); an error names a
/// command that writes a file it also reads (a later command may read it: a pipeline).
fn outputs(body: &str) -> Result<Vec<String>, String> {
    let mut out = Vec::new();
    for command in body.replace("\\\n", " ").lines() {
        let command = command.split(" #").next().unwrap_or("");
        let words: Vec<&str> = command.split_whitespace().collect();
        for (i, w) in words.iter().enumerate() {
            if ["-o", "--output", ">"].contains(w)
                && let Some(f) = words.get(i + 1)
            {
                if words.iter().filter(|x| *x == f).count() > 1 {
                    return Err(format!("`{}` overwrites its input {f}", command.trim()));
                }
                out.push(f.trim_end_matches('/').to_string());
            }
        }
    }
    Ok(out)
}

/// The interpreter for `python` blocks, when one exists, and whether it is required
/// (`$WAVG_DOCS_PYTHON`, set by `cargo xtask test` after it installs the package: then a
/// missing module fails the block instead of skipping it).
fn python() -> Option<(PathBuf, bool)> {
    if let Some(p) = std::env::var_os("WAVG_DOCS_PYTHON") {
        return Some((PathBuf::from(p), true));
    }
    let venv = repo().join("target/py-venv/bin/python");
    if venv.exists() {
        return Some((venv, false));
    }
    Command::new("python3")
        .arg("--version")
        .output()
        .ok()
        .filter(|o| o.status.success())
        .map(|_| (PathBuf::from("python3"), false))
}

/// Runs a `python` block; `Ok(Some(reason))` when it cannot run here.
fn run_python(
    block: &Block,
    fixtures: &Path,
    data: Option<&Path>,
) -> Result<Option<String>, String> {
    let Some((py, required)) = python() else {
        return Ok(Some("no Python interpreter".into()));
    };
    if block.body.contains("../shared/data") && data.is_none() {
        return Ok(Some("needs the data folder ($WAVG_DATA_DIR)".into()));
    }
    let sandbox = Sandbox::new(fixtures, data);
    let script = sandbox.work.join("block.py");
    std::fs::write(&script, &block.body).unwrap();
    let out = sandbox
        .command("timeout")
        .args(TIMEOUT)
        .arg(&py)
        .arg(&script)
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&out.stderr);
    if out.status.success() {
        return Ok(None);
    }
    match err.lines().find(|l| l.starts_with("ModuleNotFoundError")) {
        Some(l) if !required => Ok(Some(l.to_string())),
        _ => Err(format!("exit {:?}: {err}", out.status.code())),
    }
}

/// Checks an `excerpt PATH` marker: PATH exists and holds every function the block calls.
fn check_excerpt(block: &Block, path: &str) -> Result<(), String> {
    let file = std::fs::read_to_string(repo().join(path))
        .map_err(|e| format!("excerpt of {path}: {e}"))?;
    let mut missing = Vec::new();
    let body = &block.body;
    for (i, _) in body.match_indices('(') {
        let name: String = body[..i]
            .chars()
            .rev()
            .take_while(|c| c.is_alphanumeric() || *c == '_')
            .collect::<Vec<_>>()
            .into_iter()
            .rev()
            .collect();
        if name.len() > 2 && !name.chars().all(|c| c.is_ascii_uppercase()) && !file.contains(&name)
        {
            missing.push(name);
        }
    }
    if missing.is_empty() {
        Ok(())
    } else {
        Err(format!("calls {missing:?}, which {path} does not"))
    }
}

/// What happens to one block: `Ok(None)` ran or checked, `Ok(Some(why))` skipped.
fn check(block: &Block, fixtures: &Path, data: Option<&Path>) -> Result<Option<String>, String> {
    if let Some(m) = &block.marker {
        if let Some(reason) = m.strip_prefix("skip") {
            return match reason.trim() {
                "" => Err("`docs-test: skip` needs a reason".into()),
                r => Ok(Some(r.to_string())),
            };
        }
        if let Some(path) = m.strip_prefix("excerpt") {
            return check_excerpt(block, path.trim()).map(|()| None);
        }
        return Err(format!("unknown docs-test marker `{m}`"));
    }
    match block.lang.as_str() {
        "text" | "json" | "console" | "output" => Ok(None),
        "sh" | "bash" | "shell" => {
            let needs_data = DATA_FILES.iter().any(|(n, _)| block.body.contains(n))
                || [
                    "bent.obj",
                    "target.obj",
                    "cage.obj",
                    "pig.wavg",
                    "../shared/data",
                ]
                .iter()
                .any(|n| block.body.contains(n));
            if needs_data && data.is_none() {
                return Ok(Some("needs the data folder ($WAVG_DATA_DIR)".into()));
            }
            run_sh(block, fixtures, data).map(|()| None)
        }
        "python" | "py" => run_python(block, fixtures, data),
        other => Err(format!(
            "no runner for `{other}` blocks: mark it `<!-- docs-test: excerpt PATH -->` or \
             `<!-- docs-test: skip REASON -->`, or make it `text`"
        )),
    }
}

#[test]
fn every_code_block_in_the_docs_runs_or_says_why_not() {
    let data = data_dir();
    let fixtures = tempfile::tempdir().unwrap();
    make_fixtures(fixtures.path(), data.as_deref());
    let mut failures = Vec::new();
    let (mut ran, mut skipped) = (0, 0);
    // `WAVG_DOCS_LANGS=python` checks only those languages (`cargo xtask test` runs the
    // Python blocks again once the package is installed).
    let langs: Option<Vec<String>> = std::env::var("WAVG_DOCS_LANGS")
        .ok()
        .map(|v| v.split(',').map(str::to_string).collect());
    for (name, text) in documents() {
        for b in blocks(&name, &text) {
            if langs.as_ref().is_some_and(|l| !l.contains(&b.lang)) {
                continue;
            }
            let started = std::time::Instant::now();
            let result = check(&b, fixtures.path(), data.as_deref());
            let secs = started.elapsed().as_secs_f64();
            if secs > 2.0 {
                eprintln!("{:.1} s: {}:{} ({})", secs, b.file, b.line, b.lang);
            }
            match result {
                Ok(None) => ran += 1,
                Ok(Some(why)) => {
                    skipped += 1;
                    eprintln!("SKIPPED {}:{} ({}): {why}", b.file, b.line, b.lang);
                }
                Err(e) => failures.push(format!("{}:{} ({}): {e}", b.file, b.line, b.lang)),
            }
        }
    }
    eprintln!("{ran} blocks ran or were checked, {skipped} skipped");
    assert!(failures.is_empty(), "{}", failures.join("\n\n"));
}

#[test]
fn the_runner_catches_a_block_that_overwrites_its_input_and_unmarked_code() {
    let fixtures = tempfile::tempdir().unwrap();
    std::fs::write(fixtures.path().join("in.txt"), "x\n").unwrap();
    let text = "```sh\necho y >> in.txt\n```\n\n<!-- docs-test: skip -->\n```sh\ntrue\n```\n\
                ```rust\nfn main() {}\n```\n```sh\nexit 3\n```\n```text\nanything\n```\n";
    let b = blocks("t.md", text);
    assert_eq!(b.len(), 5);
    let r: Vec<_> = b.iter().map(|b| check(b, fixtures.path(), None)).collect();
    assert!(
        r[0].as_ref().unwrap_err().contains("overwrites"),
        "{:?}",
        r[0]
    );
    assert!(r[1].as_ref().unwrap_err().contains("needs a reason"));
    assert!(r[2].as_ref().unwrap_err().contains("no runner for `rust`"));
    assert!(r[3].as_ref().unwrap_err().contains("exit Some(3)"));
    assert_eq!(r[4], Ok(None));
    // Writing a file it also reads, in one command (the README's render example once did).
    let render = "```sh\nwavg render m.obj --texture in.txt -o in.txt\n```\n";
    let r = check(&blocks("t.md", render)[0], fixtures.path(), None);
    assert!(r.unwrap_err().contains("overwrites its input in.txt"));
}
