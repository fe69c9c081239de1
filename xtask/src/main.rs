//! Build and test automation: `cargo xtask test` runs every check the project has, in the
//! order CI runs them, and tells you exactly what to install when a tool is missing.

#![forbid(unsafe_code)]

mod cbuild;
mod examples;
mod fuzz;
mod lines;
mod man;
mod policy;

use std::path::{Path, PathBuf};
use std::process::{Command, ExitCode};
use std::time::Instant;

fn main() -> ExitCode {
    let args: Vec<String> = std::env::args().skip(1).collect();
    match args.first().map(String::as_str) {
        Some("test") => run_all(&workspace_root()),
        Some("fuzz") => match fuzz_args(&args[1..]) {
            Some((seconds, target)) => {
                report(fuzz::run(&workspace_root(), seconds, target.as_deref()))
            }
            None => usage(),
        },
        Some("lines") => report(lines::run(&workspace_root())),
        Some("man") if args.len() <= 2 => {
            report(man::run(&workspace_root(), args.get(1).map(String::as_str)))
        }
        Some("bench") if args.len() > 1 => report(bench(&workspace_root(), &args[1..])),
        _ => usage(),
    }
}

/// `cargo xtask bench NAME [ARGS...]`: runs the timing script or experiment NAME (a binary
/// of the `wavg-bench` crate) in release mode with ARGS.
fn bench(root: &Path, args: &[String]) -> Result<(), String> {
    let mut cmd = Command::new("cargo");
    cmd.args([
        "run",
        "--release",
        "--quiet",
        "-p",
        "wavg-bench",
        "--bin",
        &args[0],
        "--",
    ])
    .args(&args[1..])
    .current_dir(root);
    let ok = cmd.status().is_ok_and(|s| s.success());
    if ok {
        Ok(())
    } else {
        Err(format!("bench {} failed", args[0]))
    }
}

fn usage() -> ExitCode {
    eprintln!(
        "usage: cargo xtask test | cargo xtask fuzz [--seconds N] [--target NAME] | cargo xtask bench NAME [ARGS] | cargo xtask lines | cargo xtask man [DIR]\n\n  \
         test   rustfmt check, clippy (-D warnings), cargo test --workspace, the source policy \
         (no file over {MAX} lines of non-test code, forbid(unsafe_code) outside wavg-project \
         and wavg-ffi), cargo doc (-D warnings), the examples \
         (and quickstart.rs as a crate outside the workspace), the C/C++ build (CMake: \
         libwavg, C tests, examples, OpenMesh harness) and ctest, a {SMOKE_SECONDS} s smoke \
         run of every fuzz target\n  \
         fuzz   every fuzz target (or only NAME) for N seconds (default 60) each\n  \
         bench  the timing script or experiment NAME (crates/wavg-bench/src/bin/NAME.rs) with ARGS\n  \
         lines  the Rust files over {MAX} lines of non-test code (before the first #[cfg(test)])\n  \
         man    man pages of wavg and every subcommand into DIR (default {MAN_DIR})",
        MAX = lines::MAX_LINES,
        MAN_DIR = man::DEFAULT_DIR
    );
    ExitCode::from(2)
}

/// Seconds each fuzz target runs within `cargo xtask test`.
const SMOKE_SECONDS: u64 = 15;

/// `[--seconds N] [--target NAME]` in any order: seconds (default 60) and target.
fn fuzz_args(args: &[String]) -> Option<(u64, Option<String>)> {
    let (mut seconds, mut target) = (60, None);
    let mut it = args.iter();
    while let Some(flag) = it.next() {
        let value = it.next()?;
        match flag.as_str() {
            "--seconds" => seconds = value.parse().ok()?,
            "--target" if fuzz::TARGETS.contains(&value.as_str()) => target = Some(value.clone()),
            _ => return None,
        }
    }
    Some((seconds, target))
}

fn report(result: Result<(), String>) -> ExitCode {
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(msg) => {
            eprintln!("xtask: {msg}");
            ExitCode::FAILURE
        }
    }
}

fn workspace_root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .parent()
        .expect("xtask lives in the workspace")
        .to_path_buf()
}

/// One check: a name and a command line.
struct Step {
    name: &'static str,
    program: &'static str,
    args: &'static [&'static str],
}

const STEPS: &[Step] = &[
    Step {
        name: "format",
        program: "cargo",
        args: &["fmt", "--all", "--check"],
    },
    Step {
        // The fuzz crate is outside the workspace (it needs its own lock file).
        name: "format (fuzz)",
        program: "cargo",
        args: &["fmt", "--manifest-path", "fuzz/Cargo.toml", "--check"],
    },
    Step {
        name: "clippy",
        program: "cargo",
        args: &[
            "clippy",
            "--workspace",
            "--all-targets",
            "--",
            "-D",
            "warnings",
        ],
    },
    Step {
        name: "tests",
        program: "cargo",
        args: &["test", "--workspace"],
    },
];

fn run_all(root: &Path) -> ExitCode {
    if let Err(msg) = check_tools() {
        eprintln!("xtask: {msg}");
        return ExitCode::FAILURE;
    }
    let data_dir = report_data_dir(root);
    let total = Instant::now();
    for step in STEPS {
        let args: Vec<String> = step.args.iter().map(|a| a.to_string()).collect();
        if !run_step(root, step.name, step.program, &args) {
            return ExitCode::FAILURE;
        }
    }
    eprintln!(
        "==> source policy (files over {} lines, forbid(unsafe_code))",
        lines::MAX_LINES
    );
    if let Err(msg) = lines::run(root).and_then(|()| policy::check_unsafe(root)) {
        eprintln!("==> source policy FAILED: {msg}");
        return ExitCode::FAILURE;
    }
    if !run_docs(root) {
        return ExitCode::FAILURE;
    }
    if let Err(msg) = examples::run(root) {
        eprintln!("==> examples FAILED: {msg}");
        return ExitCode::FAILURE;
    }
    if let Err(msg) = cbuild::ensure_packages() {
        eprintln!("xtask: {msg}");
        return ExitCode::FAILURE;
    }
    for (name, program, args) in cbuild::steps(root, &data_dir) {
        if !run_step(root, name, &program, &args) {
            return ExitCode::FAILURE;
        }
    }
    if let Err(msg) = fuzz::run(root, SMOKE_SECONDS, None) {
        eprintln!("==> fuzz smoke FAILED: {msg}");
        return ExitCode::FAILURE;
    }
    eprintln!(
        "==> all checks passed in {:.1} s",
        total.elapsed().as_secs_f64()
    );
    ExitCode::SUCCESS
}

/// `cargo doc --workspace --no-deps` with warnings as errors (broken or private links,
/// malformed doc comments).
fn run_docs(root: &Path) -> bool {
    eprintln!("==> docs (RUSTDOCFLAGS=-D warnings cargo doc --workspace --no-deps)");
    let t = Instant::now();
    let status = Command::new("cargo")
        .args(["doc", "--workspace", "--no-deps"])
        .env("RUSTDOCFLAGS", "-D warnings")
        .current_dir(root)
        .status();
    match status {
        Ok(s) if s.success() => {
            eprintln!("==> docs ok in {:.1} s", t.elapsed().as_secs_f64());
            true
        }
        other => {
            eprintln!("==> docs FAILED ({other:?})");
            false
        }
    }
}

/// Runs one step from the repository root, reporting its time; false when it failed.
fn run_step(root: &Path, name: &str, program: &str, args: &[String]) -> bool {
    eprintln!("==> {name} ({program} {})", args.join(" "));
    let t = Instant::now();
    match Command::new(program).args(args).current_dir(root).status() {
        Ok(s) if s.success() => {
            eprintln!("==> {name} ok in {:.1} s", t.elapsed().as_secs_f64());
            true
        }
        Ok(s) => {
            eprintln!("==> {name} FAILED ({s})");
            false
        }
        Err(e) => {
            eprintln!("==> {name} could not start {program}: {e}");
            false
        }
    }
}

/// rustfmt and clippy ship as rustup components; they cannot be downloaded from here, so
/// say exactly what is missing and how to add it.
fn check_tools() -> Result<(), String> {
    for (tool, component) in [("rustfmt", "rustfmt"), ("cargo-clippy", "clippy")] {
        let ok = Command::new(tool)
            .arg("--version")
            .output()
            .is_ok_and(|o| o.status.success());
        if !ok {
            return Err(format!(
                "{tool} is missing: install it with `rustup component add {component}`"
            ));
        }
    }
    Ok(())
}

/// Prints which test-data folder the tests will read, and returns it.
fn report_data_dir(root: &Path) -> PathBuf {
    let dir = std::env::var_os("WAVG_DATA_DIR")
        .map(PathBuf::from)
        .unwrap_or_else(|| root.join("../shared/data"));
    if dir.is_dir() {
        eprintln!("==> test data: {}", dir.display());
    } else {
        eprintln!(
            "==> test data: {} not found; tests that need real meshes will say SKIPPED \
             (set WAVG_DATA_DIR to the shared data folder to run them)",
            dir.display()
        );
    }
    dir
}
