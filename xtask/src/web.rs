//! The page of `wavg serve`: our sources are `web/src/` (their only copy); `cargo xtask
//! web` vendors three.js's files into `web/vendor/three/` from npm, as pinned by
//! `web/package-lock.json`; the "web assets" check verifies the checked-in vendored files
//! are what the lock file gives; the "browser tests" step runs `web/tests` (pytest +
//! Playwright) on Debian's chromium.

use std::path::{Path, PathBuf};

use crate::sandbox::Sandbox;
use crate::{python, steps};

/// three.js files the page serves: path under `node_modules/`, name under
/// [`VENDORED`].
const VENDOR: &[(&str, &str)] = &[
    ("three/build/three.module.js", "three.module.js"),
    ("three/build/three.core.js", "three.core.js"),
    (
        "three/examples/jsm/controls/OrbitControls.js",
        "OrbitControls.js",
    ),
    ("three/LICENSE", "LICENSE"),
];

/// Where the vendored three.js files are checked in (embedded by wavg-serve's assets.rs).
const VENDORED: &str = "web/vendor/three";

/// The browser the tests drive (never Playwright's own downloads).
pub const CHROMIUM: &str = "/usr/bin/chromium";

fn npm_ci(dir: &Path) -> Result<(), String> {
    steps::command(dir, "npm", &["ci", "--no-audit", "--no-fund"])
        .map_err(|e| format!("{e} (npm comes with Debian's `nodejs`/`npm` packages)"))
}

/// `cargo xtask web`: `npm ci` in `web/`, then copies three.js's files into
/// `web/vendor/three/`.
pub fn build(root: &Path) -> Result<(), String> {
    let web = root.join("web");
    npm_ci(&web)?;
    let vendored = root.join(VENDORED);
    std::fs::create_dir_all(&vendored).map_err(|e| e.to_string())?;
    for (from, to) in VENDOR {
        copy(&web.join("node_modules").join(from), &vendored.join(to))?;
    }
    eprintln!("==> {VENDORED} rebuilt; rebuild wavg to embed it");
    Ok(())
}

fn copy(from: &Path, to: &Path) -> Result<(), String> {
    std::fs::copy(from, to)
        .map(|_| ())
        .map_err(|e| format!("copy {} -> {}: {e}", from.display(), to.display()))
}

/// The "web assets" check: `npm ci` from the lock file into a folder under target/, then
/// byte comparisons of every vendored file with `web/vendor/three/`, which must hold
/// nothing else; `web/dist/` (a second copy of the sources) must not exist.
pub fn check_assets(root: &Path) -> Result<(), String> {
    let web = root.join("web");
    let tmp = steps::target_dir(root).join("web-assets-check");
    let _ = std::fs::remove_dir_all(&tmp);
    std::fs::create_dir_all(&tmp).map_err(|e| e.to_string())?;
    for f in ["package.json", "package-lock.json"] {
        copy(&web.join(f), &tmp.join(f))?;
    }
    npm_ci(&tmp)?;
    let vendored = root.join(VENDORED);
    let pairs: Vec<(PathBuf, PathBuf)> = VENDOR
        .iter()
        .map(|(from, to)| (tmp.join("node_modules").join(from), vendored.join(to)))
        .collect();
    let mut wrong = Vec::new();
    for (want, have) in &pairs {
        let w = std::fs::read(want).map_err(|e| format!("{}: {e}", want.display()))?;
        if std::fs::read(have).ok().as_deref() != Some(w.as_slice()) {
            wrong.push(format!("{} differs", shown(root, have)));
        }
    }
    wrong.extend(
        extra_files(&vendored)?
            .iter()
            .map(|p| format!("{} is not one of three's files", shown(root, p))),
    );
    if web.join("dist").exists() {
        wrong.push("web/dist exists (the sources' one copy is web/src)".into());
    }
    if wrong.is_empty() {
        eprintln!("    {} files of {VENDORED} match", pairs.len());
        Ok(())
    } else {
        Err(format!(
            "{}; run `cargo xtask web` (and delete what it does not make)",
            wrong.join(", ")
        ))
    }
}

/// `path` relative to `root` for a message.
fn shown(root: &Path, path: &Path) -> String {
    path.strip_prefix(root)
        .unwrap_or(path)
        .display()
        .to_string()
}

/// Files in `dir` other than [`VENDOR`]'s.
fn extra_files(dir: &Path) -> Result<Vec<PathBuf>, String> {
    let mut extra: Vec<PathBuf> = std::fs::read_dir(dir)
        .map_err(|e| format!("{}: {e}", dir.display()))?
        .filter_map(|e| e.ok())
        .map(|e| e.path())
        .filter(|p| {
            let name = p.file_name().and_then(|n| n.to_str()).unwrap_or("");
            !VENDOR.iter().any(|(_, to)| *to == name)
        })
        .collect();
    extra.sort();
    Ok(extra)
}

/// The "browser tests" step: chromium (apt-installed when root and missing, else a
/// SKIPPED message), then `pytest web/tests` with the environment's python against the
/// dev build's `wavg`, in a [`Sandbox`] (the browser's profile is Playwright's temporary
/// one; whatever chromium keeps in the home goes to the sandbox's).
pub fn browser_tests(root: &Path, data_dir: &Path) -> Result<(), String> {
    if !Path::new(CHROMIUM).exists() {
        if !crate::system::is_root() {
            eprintln!(
                "    SKIPPED browser tests: {CHROMIUM} not installed (apt-get install chromium)"
            );
            return Ok(());
        }
        use crate::system::apt;
        let install = ["install", "-y", "--no-install-recommends", "chromium"];
        if !(apt(&install) || (apt(&["update"]) && apt(&install))) {
            return Err("apt-get could not install chromium".into());
        }
    }
    let wavg = steps::target_dir(root).join("debug/wavg");
    if !wavg.exists() {
        return Err(format!(
            "{} is missing: run the tests step first",
            wavg.display()
        ));
    }
    let py = python::ensure_venv(root)?;
    let (py, wavg, data) = (
        py.to_string_lossy().into_owned(),
        wavg.to_string_lossy().into_owned(),
        data_dir.to_string_lossy().into_owned(),
    );
    Sandbox::new(root, "browser")?.run(
        root,
        &py,
        &["-m", "pytest", "-q", "web/tests"],
        &[("WAVG_BIN", &wavg), ("WAVG_DATA_DIR", &data)],
    )
}
