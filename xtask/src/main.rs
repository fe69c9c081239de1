//! Build and test automation: `cargo xtask test` runs every check the project has, in the
//! order CI runs them, and tells you exactly what to install when a tool is missing.

mod fuzz;

use std::path::{Path, PathBuf};
use std::process::{Command, ExitCode};
use std::time::Instant;

fn main() -> ExitCode {
    let args: Vec<String> = std::env::args().skip(1).collect();
    match args.first().map(String::as_str) {
        Some("test") => run_all(&workspace_root()),
        Some("fuzz") => match fuzz_seconds(&args[1..]) {
            Some(seconds) => report(fuzz::run(&workspace_root(), seconds)),
            None => usage(),
        },
        _ => usage(),
    }
}

fn usage() -> ExitCode {
    eprintln!(
        "usage: cargo xtask test | cargo xtask fuzz [--seconds N]\n\n  \
         test   rustfmt check, clippy (-D warnings), cargo test --workspace, a {SMOKE_SECONDS} s \
         smoke run of every fuzz target\n  \
         fuzz   every fuzz target for N seconds (default 60) each"
    );
    ExitCode::from(2)
}

/// Seconds each fuzz target runs within `cargo xtask test`.
const SMOKE_SECONDS: u64 = 15;

fn fuzz_seconds(args: &[String]) -> Option<u64> {
    match args {
        [] => Some(60),
        [flag, n] if flag == "--seconds" => n.parse().ok(),
        _ => None,
    }
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
    report_data_dir(root);
    let total = Instant::now();
    for step in STEPS {
        eprintln!(
            "==> {} ({} {})",
            step.name,
            step.program,
            step.args.join(" ")
        );
        let t = Instant::now();
        let status = Command::new(step.program)
            .args(step.args)
            .current_dir(root)
            .status();
        match status {
            Ok(s) if s.success() => {
                eprintln!("==> {} ok in {:.1} s", step.name, t.elapsed().as_secs_f64())
            }
            Ok(s) => {
                eprintln!("==> {} FAILED ({s})", step.name);
                return ExitCode::FAILURE;
            }
            Err(e) => {
                eprintln!("==> {} could not start {}: {e}", step.name, step.program);
                return ExitCode::FAILURE;
            }
        }
    }
    if let Err(msg) = fuzz::run(root, SMOKE_SECONDS) {
        eprintln!("==> fuzz smoke FAILED: {msg}");
        return ExitCode::FAILURE;
    }
    eprintln!(
        "==> all checks passed in {:.1} s",
        total.elapsed().as_secs_f64()
    );
    ExitCode::SUCCESS
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

fn report_data_dir(root: &Path) {
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
}
