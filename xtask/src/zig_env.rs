//! The environment maturin builds the release wheel in (zig's wrappers as linker and C
//! compiler, glibc 2.28's symbols), recorded by a `cargo` stand-in put first on maturin's
//! `PATH`, so that `dist` builds the C library in the very same environment: cargo then
//! reuses every crate the wheel's build compiled (rustc's linker setting is part of each
//! crate's build hash: any other setting compiles them all again), and the library, like
//! the wheel, runs on glibc 2.28 and later.

use std::path::{Path, PathBuf};

use crate::steps;

/// The recorder's variables: where to write, and the cargo to run.
const FILE_VAR: &str = "WAVG_ZIG_ENV_FILE";
const CARGO_VAR: &str = "WAVG_REAL_CARGO";

/// The `cargo` stand-in: writes its environment (NUL-separated) when maturin compiles
/// (`cargo rustc`), then runs the real cargo with the same arguments.
const SCRIPT: &str = "#!/bin/sh\n\
# Written by `cargo xtask dist` (xtask/src/zig_env.rs): records the environment maturin\n\
# compiles the wheel in, then runs cargo.\n\
if [ \"$1\" = rustc ]; then env -0 > \"$WAVG_ZIG_ENV_FILE\"; fi\n\
exec \"$WAVG_REAL_CARGO\" \"$@\"\n";

/// A `cargo` stand-in in `target/zig-env/bin/` and the file it writes.
pub struct Recorder {
    bin: PathBuf,
    file: String,
    cargo: String,
}

impl Recorder {
    /// Writes the stand-in (and removes an older record).
    pub fn new(root: &Path) -> Result<Self, String> {
        let dir = steps::target_dir(root).join("zig-env");
        let bin = dir.join("bin");
        std::fs::create_dir_all(&bin).map_err(|e| format!("{}: {e}", bin.display()))?;
        let file = dir.join("env");
        if file.exists() {
            std::fs::remove_file(&file).map_err(|e| format!("{}: {e}", file.display()))?;
        }
        let cargo = real_cargo(&bin)?;
        let script = bin.join("cargo");
        std::fs::write(&script, SCRIPT).map_err(|e| format!("{}: {e}", script.display()))?;
        set_executable(&script)?;
        Ok(Recorder {
            bin,
            file: file.display().to_string(),
            cargo,
        })
    }

    /// The folder to put first on `PATH`.
    pub fn dir(&self) -> &Path {
        &self.bin
    }

    /// The variables the stand-in reads (maturin also finds cargo through `CARGO`).
    pub fn vars(&self) -> Vec<(&str, String)> {
        vec![
            (FILE_VAR, self.file.clone()),
            (CARGO_VAR, self.cargo.clone()),
            ("CARGO", self.bin.join("cargo").display().to_string()),
        ]
    }

    /// The recorded environment, without the recorder's own variables, its folder on
    /// `PATH` or `CARGO`: the one to build the C library in.
    pub fn recorded(&self) -> Result<Vec<(String, String)>, String> {
        let text = std::fs::read(&self.file).map_err(|e| {
            format!(
                "{}: {e} (maturin ran no `cargo rustc`, so the wheel's build environment was not recorded)",
                self.file
            )
        })?;
        let bin = self.bin.display().to_string();
        let mut vars = Vec::new();
        for entry in text.split(|&b| b == 0).filter(|e| !e.is_empty()) {
            let entry = String::from_utf8_lossy(entry);
            let Some((key, value)) = entry.split_once('=') else {
                continue;
            };
            let value = match key {
                FILE_VAR | CARGO_VAR | "CARGO" => continue,
                "PATH" => std::env::join_paths(
                    std::env::split_paths(value).filter(|d| d.display().to_string() != bin),
                )
                .map_err(|e| format!("PATH: {e}"))?
                .to_string_lossy()
                .into_owned(),
                _ => value.to_string(),
            };
            vars.push((key.to_string(), value));
        }
        Ok(vars)
    }
}

/// The `cargo` the stand-in runs: `$CARGO` (set when xtask runs under cargo), else the
/// first `cargo` on `PATH` outside the stand-in's folder.
fn real_cargo(skip: &Path) -> Result<String, String> {
    if let Some(cargo) = std::env::var_os("CARGO") {
        return Ok(PathBuf::from(cargo).display().to_string());
    }
    let path = std::env::var_os("PATH").unwrap_or_default();
    std::env::split_paths(&path)
        .filter(|d| d != skip)
        .map(|d| d.join("cargo"))
        .find(|c| c.is_file())
        .map(|c| c.display().to_string())
        .ok_or_else(|| "no cargo on PATH".to_string())
}

fn set_executable(path: &Path) -> Result<(), String> {
    use std::os::unix::fs::PermissionsExt;
    std::fs::set_permissions(path, std::fs::Permissions::from_mode(0o755))
        .map_err(|e| format!("{}: {e}", path.display()))
}
