//! The checks of `cargo xtask test`, each timed, with a table of step times (wall and CPU
//! seconds) at the end.

use std::path::{Path, PathBuf};
use std::process::Command;
use std::time::Instant;

use crate::cpu;

/// The packages the everyday build leaves out: the experiments (`cargo xtask lab` builds
/// them). Every step selects the same packages, so that cargo resolves one feature set and
/// builds each dependency once.
pub const EXCLUDED: &[&str] = &["--exclude", "wavg-lab"];

/// What the everyday `cargo build` leaves out besides [`EXCLUDED`]: the Python extension,
/// which maturin builds (`wavg-py` alone, with the workspace's features). maturin gives
/// PyO3's build script its interpreter (`PYO3_PYTHON`, `PYO3_CONFIG_FILE`, ...), which a
/// plain build leaves unset, so a plain build of the extension after maturin's, or
/// maturin's after a plain one, would run that script again and compile PyO3, NumPy's
/// bindings and the extension once more (25-30 s each time, measured in a fresh run).
pub const NOT_BUILT: &[&str] = &["--exclude", "wavg-py"];

/// `cargo build --all-targets` of the everyday workspace without the Python extension
/// ([`NOT_BUILT`]): the tests' dependency builds, reused by the C library, the examples
/// and the fuzz seeds.
pub fn cargo_build_all(root: &Path) -> Result<(), String> {
    cargo_workspace(root, &["build", "--all-targets"], NOT_BUILT)
}

/// cargo's target directory: `$CARGO_TARGET_DIR` when set (CI keeps one across runs),
/// else `target/` in the repository.
pub fn target_dir(root: &Path) -> PathBuf {
    std::env::var_os("CARGO_TARGET_DIR")
        .map(PathBuf::from)
        .map_or_else(|| root.join("target"), |d| root.join(d))
}

/// One step's row of the table.
struct Row {
    name: String,
    wall: f64,
    cpu: Option<f64>,
    ok: bool,
}

/// Times and outcomes of the steps run so far.
#[derive(Default)]
pub struct Log {
    rows: Vec<Row>,
    start: Option<(Instant, Option<f64>)>,
}

impl Log {
    /// Runs `step` under `name`, printing its start, its end and its wall and CPU time;
    /// false when it failed (its message printed).
    pub fn run(&mut self, name: &str, step: impl FnOnce() -> Result<(), String>) -> bool {
        self.start
            .get_or_insert_with(|| (Instant::now(), cpu::now()));
        eprintln!("==> {name}");
        let (t, cpu_start) = (Instant::now(), cpu::now());
        let result = step();
        let wall = t.elapsed().as_secs_f64();
        let cpu = cpu::between(cpu_start, cpu::now());
        self.record(name, wall, cpu, result)
    }

    /// Records a step timed elsewhere (one run beside others) and prints its end; false
    /// when it failed.
    pub fn record(
        &mut self,
        name: &str,
        wall: f64,
        cpu: Option<f64>,
        result: Result<(), String>,
    ) -> bool {
        self.start
            .get_or_insert_with(|| (Instant::now(), cpu::now()));
        let cpu_s = cpu::cell(cpu);
        match &result {
            Ok(()) => eprintln!("==> {name} ok in {wall:.1} s ({cpu_s} CPU s)"),
            Err(msg) => eprintln!("==> {name} FAILED after {wall:.1} s ({cpu_s} CPU s): {msg}"),
        }
        self.rows.push(Row {
            name: name.to_string(),
            wall,
            cpu,
            ok: result.is_ok(),
        });
        result.is_ok()
    }

    /// Prints the table of step times and the total.
    pub fn print_table(&self) {
        eprint!("\n{}", self.table());
    }

    /// The table: each step's wall seconds, CPU seconds (xtask's and its children's: user
    /// plus system) and result, then the totals.
    fn table(&self) -> String {
        let (total, total_cpu) = self.start.map_or((0.0, None), |(t, c)| {
            (t.elapsed().as_secs_f64(), cpu::between(c, cpu::now()))
        });
        let width = self
            .rows
            .iter()
            .map(|r| r.name.len())
            .max()
            .unwrap_or(4)
            .max(5);
        let mut out = format!(
            "{:<width$}  {:>8}  {:>8}  result\n",
            "step", "wall s", "CPU s"
        );
        for row in &self.rows {
            let result = if row.ok { "ok" } else { "FAILED" };
            let (name, wall, cpu) = (&row.name, row.wall, cpu::cell(row.cpu));
            out += &format!("{name:<width$}  {wall:>8.1}  {cpu:>8}  {result}\n");
        }
        let total_cpu = cpu::cell(total_cpu);
        out += &format!("{:<width$}  {total:>8.1}  {total_cpu:>8}\n", "total");
        out
    }
}

/// A new file at `path` for a child's standard output and error (one handle each).
pub fn output_file(path: &Path) -> Result<(std::fs::File, std::fs::File), String> {
    let err = |e: std::io::Error| format!("{}: {e}", path.display());
    let out = std::fs::File::create(path).map_err(err)?;
    let both = out.try_clone().map_err(err)?;
    Ok((out, both))
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

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_table_shows_wall_and_cpu_seconds_of_each_step() {
        let mut log = Log::default();
        assert!(log.run("burn", || {
            command(
                Path::new("."),
                "sh",
                &["-c", "i=0; while [ $i -lt 300000 ]; do i=$((i+1)); done"],
            )
        }));
        assert!(!log.run("fail", || Err("no".into())));
        let burn = &log.rows[0];
        let cpu = burn.cpu.expect("CPU seconds on Linux");
        // Only a lower bound: the figure is the process's reaped children, and other tests
        // of this binary reap theirs (cargo among them) while the loop runs.
        assert!(cpu >= 0.1, "the loop took {cpu} CPU s");
        let table = log.table();
        let lines: Vec<&str> = table.lines().collect();
        assert_eq!(lines.len(), 4, "{table}");
        let header: Vec<&str> = lines[0].split_whitespace().collect();
        assert_eq!(header, ["step", "wall", "s", "CPU", "s", "result"]);
        let row: Vec<&str> = lines[1].split_whitespace().collect();
        assert_eq!(row[0], "burn");
        assert_eq!(row[2], format!("{cpu:.1}"));
        assert_eq!(row[3], "ok");
        assert!(lines[2].ends_with("FAILED"), "{table}");
        let total: Vec<&str> = lines[3].split_whitespace().collect();
        assert_eq!(total[0], "total");
        let total_cpu: f64 = total[2].parse().unwrap();
        assert!(total_cpu >= cpu - 0.05, "{table}");
    }
}
