//! A step run in a child `cargo xtask` process beside the steps that follow it, its output in
//! a file so that the two do not interleave. The fuzz targets' build and smoke run go this
//! way beside the release steps: their build is a chain of single-threaded compiles of the
//! workspace's crates, and the installed-artifact checks leave most of a core idle, so on a
//! fresh 2-core machine the two side by side take about two minutes less than one after
//! the other. The crates' verification (`cargo xtask dist --crates`) goes this way, at the
//! lowest priority, beside the tests and the Python, Blender, browser and C steps, whose
//! waits on one process leave a core idle; it has a cargo home of its own
//! ([`crate::cargo_home`]), so no lock of cargo's makes the two take turns.

use std::path::{Path, PathBuf};
use std::process::{Child, Command};
use std::time::Instant;

use crate::steps;

/// A running child step.
pub struct Beside {
    name: String,
    child: Child,
    output: PathBuf,
    start: Instant,
}

impl Beside {
    /// Starts `cargo xtask ARGS` (this binary) from `root` as step `name`, its output in
    /// `FILE.log` in cargo's target directory.
    pub fn start(root: &Path, name: &str, file: &str, args: &[&str]) -> Result<Self, String> {
        Self::spawn(root, name, file, args, false)
    }

    /// [`Beside::start`] at the lowest priority (`nice -n 19`, where `nice` exists): the
    /// step takes the cores the steps beside it leave idle, and little more.
    pub fn start_idle(root: &Path, name: &str, file: &str, args: &[&str]) -> Result<Self, String> {
        Self::spawn(root, name, file, args, true)
    }

    fn spawn(
        root: &Path,
        name: &str,
        file: &str,
        args: &[&str],
        idle: bool,
    ) -> Result<Self, String> {
        let xtask = std::env::current_exe().map_err(|e| format!("xtask's own path: {e}"))?;
        let output = steps::target_dir(root).join(format!("{file}.log"));
        let (out, err) = steps::output_file(&output)?;
        eprintln!(
            "==> {name}: started beside the next steps{} (output in {})",
            if idle { " at the lowest priority" } else { "" },
            output.display()
        );
        let spawn = |niced: bool| -> std::io::Result<Child> {
            let mut c = Command::new(if niced { Path::new("nice") } else { &xtask });
            if niced {
                c.args(["-n", "19"]).arg(&xtask);
            }
            let (out, err) = (out.try_clone()?, err.try_clone()?);
            c.args(args)
                .current_dir(root)
                .stdout(out)
                .stderr(err)
                .spawn()
        };
        let child = match spawn(idle) {
            Err(e) if idle && e.kind() == std::io::ErrorKind::NotFound => spawn(false),
            started => started,
        }
        .map_err(|e| format!("could not start {}: {e}", xtask.display()))?;
        Ok(Self {
            name: name.to_string(),
            child,
            output,
            start: Instant::now(),
        })
    }

    /// Waits for the step and records it in `log` (its wall time from its start; its CPU
    /// overlaps the other steps', so the table shows none); on failure prints the end of
    /// its output. False when it failed.
    pub fn finish(self, log: &mut steps::Log) -> bool {
        self.wait().record(log)
    }

    /// Waits for the step; on failure the outcome holds the end of its output.
    pub fn wait(mut self) -> Finished {
        let result = match self.child.wait() {
            Ok(status) if status.success() => Ok(()),
            Ok(status) => Err(format!("ended with {status}")),
            Err(e) => Err(format!("could not wait for it: {e}")),
        };
        let result = result.map_err(|e| {
            let text = std::fs::read_to_string(&self.output).unwrap_or_default();
            let lines: Vec<&str> = text.lines().collect();
            let tail = lines[lines.len().saturating_sub(60)..].join("\n");
            format!("{e}; the end of {}:\n{tail}", self.output.display())
        });
        Finished {
            name: std::mem::take(&mut self.name),
            seconds: self.start.elapsed().as_secs_f64(),
            result,
        }
    }

    /// Stops the step (a step before it failed).
    pub fn cancel(self) {}
}

impl Drop for Beside {
    /// A step neither waited for nor finished is stopped, not left running.
    fn drop(&mut self) {
        if let Ok(None) = self.child.try_wait() {
            let _ = self.child.kill();
            let _ = self.child.wait();
        }
    }
}

/// The outcome of a [`Beside`] step, to record once the step table is at hand.
pub struct Finished {
    name: String,
    seconds: f64,
    /// Whether it passed, or why not.
    pub result: Result<(), String>,
}

impl Finished {
    /// Records it in `log`; false when it failed.
    pub fn record(self, log: &mut steps::Log) -> bool {
        log.record(&self.name, self.seconds, None, self.result)
    }
}
