//! `cargo xtask lab [NAME ARGS...]`: the lab (`lab/`, package `wavg-lab`), a workspace
//! member left out of the default members so that everyday builds and tests skip it.

use std::path::Path;
use std::process::Command;

/// Without arguments, builds every lab program (`cargo build -p wavg-lab`, proving they
/// still compile); with `NAME ARGS...`, runs the lab program NAME in release mode, as its
/// figures were measured, with ARGS.
pub fn run(root: &Path, args: &[String]) -> Result<(), String> {
    let mut cmd = Command::new("cargo");
    match args.split_first() {
        None => cmd.args(["build", "-p", "wavg-lab"]),
        Some((name, rest)) => cmd
            .args([
                "run",
                "--release",
                "--quiet",
                "-p",
                "wavg-lab",
                "--bin",
                name,
                "--",
            ])
            .args(rest),
    };
    let ok = cmd.current_dir(root).status().is_ok_and(|s| s.success());
    match (ok, args.first()) {
        (true, _) => Ok(()),
        (false, None) => Err("building the lab failed".into()),
        (false, Some(name)) => Err(format!("lab program {name} failed")),
    }
}
