//! The Python side of `cargo xtask test`: one virtual environment under cargo's target
//! directory, made with `python3 -m venv` and filled from `python/requirements-test.txt`
//! (pinned), reinstalled only when that file changes.

use std::path::{Path, PathBuf};

use crate::steps;

/// The requirements file, relative to the repository root.
const REQUIREMENTS: &str = "python/requirements-test.txt";

/// The virtual environment's folder.
pub fn venv_dir(root: &Path) -> PathBuf {
    steps::target_dir(root).join("py-venv")
}

/// The environment's interpreter.
pub fn python(root: &Path) -> PathBuf {
    venv_dir(root).join("bin").join("python")
}

/// Makes the environment when missing and installs the pinned requirements when the file
/// differs from the copy recorded at the last install; returns the interpreter.
pub fn ensure_venv(root: &Path) -> Result<PathBuf, String> {
    let dir = venv_dir(root);
    let py = python(root);
    if !py.exists() {
        let dir_s = dir.to_string_lossy();
        steps::command(root, "python3", &["-m", "venv", "--clear", &dir_s]).map_err(|e| {
            format!("{e} (on Debian: `apt-get install python3-venv`, then run again)")
        })?;
    }
    let wanted = std::fs::read_to_string(root.join(REQUIREMENTS))
        .map_err(|e| format!("cannot read {REQUIREMENTS}: {e}"))?;
    let stamp = dir.join("wavg-requirements.txt");
    if std::fs::read_to_string(&stamp).ok().as_deref() != Some(wanted.as_str()) {
        let py_s = py.to_string_lossy();
        steps::command_env(
            root,
            &py_s,
            &[
                "-m",
                "pip",
                "install",
                "--quiet",
                "--disable-pip-version-check",
                "-r",
                REQUIREMENTS,
            ],
            &[("PIP_FIND_LINKS", "")],
        )?;
        std::fs::write(&stamp, wanted)
            .map_err(|e| format!("cannot write {}: {e}", stamp.display()))?;
    }
    Ok(py)
}
