//! The checks of `cargo xtask test`, each timed, with a table of step times at the end.

use std::path::{Path, PathBuf};
use std::process::Command;
use std::time::Instant;

/// The packages the everyday build leaves out: the experiments (`cargo xtask lab` builds
/// them). Every step selects the same packages, so that cargo resolves one feature set and
/// builds each dependency once.
pub const EXCLUDED: &[&str] = &["--exclude", "wavg-lab"];

/// cargo's target directory: `$CARGO_TARGET_DIR` when set (CI keeps one across runs),
/// else `target/` in the repository.
pub fn target_dir(root: &Path) -> PathBuf {
    std::env::var_os("CARGO_TARGET_DIR")
        .map(PathBuf::from)
        .map_or_else(|| root.join("target"), |d| root.join(d))
}

/// Times and outcomes of the steps run so far.
#[derive(Default)]
pub struct Log {
    rows: Vec<(String, f64, bool)>,
    start: Option<Instant>,
}

impl Log {
    /// Runs `step` under `name`, printing its start, its end and its time; false when it
    /// failed (its message printed).
    pub fn run(&mut self, name: &str, step: impl FnOnce() -> Result<(), String>) -> bool {
        self.start.get_or_insert_with(Instant::now);
        eprintln!("==> {name}");
        let t = Instant::now();
        let result = step();
        let secs = t.elapsed().as_secs_f64();
        match &result {
            Ok(()) => eprintln!("==> {name} ok in {secs:.1} s"),
            Err(msg) => eprintln!("==> {name} FAILED after {secs:.1} s: {msg}"),
        }
        self.rows.push((name.to_string(), secs, result.is_ok()));
        result.is_ok()
    }

    /// Prints the table of step times and the total.
    pub fn print_table(&self) {
        let total = self.start.map_or(0.0, |s| s.elapsed().as_secs_f64());
        let width = self
            .rows
            .iter()
            .map(|r| r.0.len())
            .max()
            .unwrap_or(4)
            .max(5);
        eprintln!("\n{:<width$}  {:>8}  result", "step", "seconds");
        for (name, secs, ok) in &self.rows {
            let result = if *ok { "ok" } else { "FAILED" };
            eprintln!("{name:<width$}  {secs:>8.1}  {result}");
        }
        eprintln!("{:<width$}  {total:>8.1}", "total");
    }
}

/// Runs `program args` from `dir`; `Err` says how it ended.
pub fn command(dir: &Path, program: &str, args: &[&str]) -> Result<(), String> {
    command_env(dir, program, args, &[])
}

/// [`command`] with extra environment variables.
pub fn command_env(
    dir: &Path,
    program: &str,
    args: &[&str],
    env: &[(&str, &str)],
) -> Result<(), String> {
    eprintln!("    {program} {}", args.join(" "));
    let mut cmd = Command::new(program);
    cmd.args(args).envs(env.iter().copied()).current_dir(dir);
    run(program, args, &mut cmd)
}

/// Runs `cmd` (`program args`, for the messages); `Err` says how it ended.
pub fn run(program: &str, args: &[&str], cmd: &mut Command) -> Result<(), String> {
    let status = cmd
        .status()
        .map_err(|e| format!("could not start {program}: {e}"))?;
    if status.success() {
        Ok(())
    } else {
        Err(format!("{program} {} ended with {status}", args.join(" ")))
    }
}

/// `cargo ARGS... <EXCLUDED>`: a cargo command over the everyday workspace.
pub fn cargo_workspace(root: &Path, args: &[&str], tail: &[&str]) -> Result<(), String> {
    cargo_workspace_env(root, args, tail, &[])
}

/// [`cargo_workspace`] with extra environment variables.
pub fn cargo_workspace_env(
    root: &Path,
    args: &[&str],
    tail: &[&str],
    env: &[(&str, &str)],
) -> Result<(), String> {
    let mut all: Vec<&str> = args.to_vec();
    all.push("--workspace");
    all.extend(EXCLUDED);
    all.extend(tail);
    command_env(root, "cargo", &all, env)
}
