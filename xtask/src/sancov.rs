//! The rustc wrapper of the fuzz build: cargo runs `xtask RUSTC ARGS...` for the workspace's
//! own crates only (`RUSTC_WORKSPACE_WRAPPER`), and this adds libFuzzer's coverage
//! instrumentation to them. Dependencies are compiled exactly as for the tests, so the fuzz
//! build reuses their artifacts instead of building every crate a second time.

use std::process::{Command, ExitCode};

/// Set (to any value) when xtask runs as the wrapper.
pub const ENV: &str = "WAVG_XTASK_SANCOV";

/// The flags added to each of our crates: coverage counters, a table of their program
/// counters and comparison tracing (what cargo-fuzz passes), and `cfg(fuzzing)`.
const FLAGS: &[&str] = &[
    "--cfg",
    "fuzzing",
    "-Cpasses=sancov-module",
    "-Cllvm-args=-sanitizer-coverage-level=4",
    "-Cllvm-args=-sanitizer-coverage-inline-8bit-counters",
    "-Cllvm-args=-sanitizer-coverage-pc-table",
    "-Cllvm-args=-sanitizer-coverage-trace-compares",
];

/// Runs `args[0]` (rustc) with the rest of `args`, instrumented when it compiles a crate
/// (not a build script, which runs at build time without libFuzzer).
pub fn wrap(args: &[String]) -> ExitCode {
    let Some((rustc, rest)) = args.split_first() else {
        eprintln!("xtask: {ENV} is set but no rustc command was given");
        return ExitCode::from(2);
    };
    let crate_name = rest
        .iter()
        .position(|a| a == "--crate-name")
        .and_then(|i| rest.get(i + 1));
    let instrument = crate_name.is_some_and(|n| n != "build_script_build");
    let mut cmd = Command::new(rustc);
    cmd.args(rest);
    if instrument {
        cmd.args(FLAGS);
    }
    match cmd.status() {
        Ok(s) => ExitCode::from(u8::try_from(s.code().unwrap_or(1)).unwrap_or(1)),
        Err(e) => {
            eprintln!("xtask: could not run {rustc}: {e}");
            ExitCode::FAILURE
        }
    }
}
