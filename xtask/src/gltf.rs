//! The glTF check: the tests leave a copy of every `.glb`/`.gltf` they write in
//! [`written_dir`] (`wavg_testdata::keep_gltf`, told where by `WAVG_GLTF_DIR`), and the
//! "glTF validator" step runs the Khronos glTF Validator (npm `gltf-validator`, pinned as a
//! devDependency in `web/package-lock.json`, the one lock) over all of them: any error
//! fails the step, as does finding no file.

use std::path::{Path, PathBuf};

use crate::steps;

/// The variable naming the folder the tests copy their glTF files into.
pub const DIR_VAR: &str = "WAVG_GLTF_DIR";

/// Where the tests' glTF files are collected: under cargo's target directory.
pub fn written_dir(root: &Path) -> PathBuf {
    steps::target_dir(root).join("gltf-written")
}

/// Empties [`written_dir`] before the tests run (so only this run's files are checked).
pub fn clear(root: &Path) -> Result<PathBuf, String> {
    let dir = written_dir(root);
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).map_err(|e| format!("{}: {e}", dir.display()))?;
    Ok(dir)
}

/// `npm ci` of `web/`'s lock into a folder under target/, then the validator over
/// [`written_dir`] (`xtask/js/validate_gltf.cjs`).
pub fn validate(root: &Path) -> Result<(), String> {
    let tmp = steps::target_dir(root).join("gltf-validator");
    let _ = std::fs::remove_dir_all(&tmp);
    std::fs::create_dir_all(&tmp).map_err(|e| e.to_string())?;
    for f in ["package.json", "package-lock.json"] {
        std::fs::copy(root.join("web").join(f), tmp.join(f))
            .map_err(|e| format!("web/{f}: {e}"))?;
    }
    steps::command(&tmp, "npm", &["ci", "--no-audit", "--no-fund"])
        .map_err(|e| format!("{e} (npm comes with Debian's `nodejs`/`npm` packages)"))?;
    let script = root.join("xtask/js/validate_gltf.cjs");
    let modules = tmp.join("node_modules");
    let written = written_dir(root);
    let args = [&script, &modules, &written].map(|p| p.to_string_lossy().into_owned());
    let args: Vec<&str> = args.iter().map(String::as_str).collect();
    steps::command(root, "node", &args)
}
