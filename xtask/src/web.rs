//! The page of `wavg serve`: `cargo xtask web` rebuilds `web/dist/` (our sources from
//! `web/src/` and three.js's files from npm, as pinned by `web/package-lock.json`); the
//! "web assets" check verifies the checked-in copy is what the lock file produces; the
//! "browser tests" step runs `web/tests` (pytest + Playwright) on Debian's chromium.

use std::path::Path;
use std::process::Command;

use crate::sandbox::Sandbox;
use crate::{python, steps};

/// three.js files the page serves: path under `node_modules/`, name under
/// `web/dist/vendor/three/`.
const VENDOR: &[(&str, &str)] = &[
    ("three/build/three.module.js", "three.module.js"),
    ("three/build/three.core.js", "three.core.js"),
    (
        "three/examples/jsm/controls/OrbitControls.js",
        "OrbitControls.js",
    ),
    ("three/LICENSE", "LICENSE"),
];

/// The browser the tests drive (never Playwright's own downloads).
const CHROMIUM: &str = "/usr/bin/chromium";

fn npm_ci(dir: &Path) -> Result<(), String> {
    steps::command(dir, "npm", &["ci", "--no-audit", "--no-fund"])
        .map_err(|e| format!("{e} (npm comes with Debian's `nodejs`/`npm` packages)"))
}

/// Our sources: every file of `web/src/`.
fn sources(root: &Path) -> Result<Vec<String>, String> {
    let dir = root.join("web/src");
    let mut names: Vec<String> = std::fs::read_dir(&dir)
        .map_err(|e| format!("{}: {e}", dir.display()))?
        .filter_map(|e| e.ok())
        .filter(|e| e.path().is_file())
        .map(|e| e.file_name().to_string_lossy().into_owned())
        .collect();
    names.sort();
    Ok(names)
}

/// `cargo xtask web`: `npm ci` in `web/`, then copies the sources and three.js into
/// `web/dist/`.
pub fn build(root: &Path) -> Result<(), String> {
    let web = root.join("web");
    npm_ci(&web)?;
    let dist = web.join("dist");
    std::fs::create_dir_all(dist.join("vendor/three")).map_err(|e| e.to_string())?;
    for name in sources(root)? {
        copy(&web.join("src").join(&name), &dist.join(&name))?;
    }
    for (from, to) in VENDOR {
        copy(
            &web.join("node_modules").join(from),
            &dist.join("vendor/three").join(to),
        )?;
    }
    eprintln!("==> web/dist rebuilt; rebuild wavg to embed it");
    Ok(())
}

fn copy(from: &Path, to: &Path) -> Result<(), String> {
    std::fs::copy(from, to)
        .map(|_| ())
        .map_err(|e| format!("copy {} -> {}: {e}", from.display(), to.display()))
}

/// The "web assets" check: `npm ci` from the lock file into a folder under target/, then
/// byte comparisons of every vendored file and every source with `web/dist/`.
pub fn check_assets(root: &Path) -> Result<(), String> {
    let web = root.join("web");
    let tmp = steps::target_dir(root).join("web-assets-check");
    let _ = std::fs::remove_dir_all(&tmp);
    std::fs::create_dir_all(&tmp).map_err(|e| e.to_string())?;
    for f in ["package.json", "package-lock.json"] {
        copy(&web.join(f), &tmp.join(f))?;
    }
    npm_ci(&tmp)?;
    let mut pairs: Vec<(std::path::PathBuf, std::path::PathBuf)> = VENDOR
        .iter()
        .map(|(from, to)| {
            (
                tmp.join("node_modules").join(from),
                web.join("dist/vendor/three").join(to),
            )
        })
        .collect();
    for name in sources(root)? {
        pairs.push((web.join("src").join(&name), web.join("dist").join(&name)));
    }
    let mut stale = Vec::new();
    for (want, have) in &pairs {
        let w = std::fs::read(want).map_err(|e| format!("{}: {e}", want.display()))?;
        if std::fs::read(have).ok().as_deref() != Some(w.as_slice()) {
            stale.push(
                have.strip_prefix(root)
                    .unwrap_or(have)
                    .display()
                    .to_string(),
            );
        }
    }
    if stale.is_empty() {
        eprintln!("    {} files of web/dist match", pairs.len());
        Ok(())
    } else {
        Err(format!(
            "web/dist differs from what web/src and the lock file give: {}; run `cargo xtask web`",
            stale.join(", ")
        ))
    }
}

/// The "browser tests" step: chromium (apt-installed when root and missing, else a
/// SKIPPED message), then `pytest web/tests` with the environment's python against the
/// dev build's `wavg`, in a [`Sandbox`] (the browser's profile is Playwright's temporary
/// one; whatever chromium keeps in the home goes to the sandbox's).
pub fn browser_tests(root: &Path, data_dir: &Path) -> Result<(), String> {
    if !Path::new(CHROMIUM).exists() {
        let root_user = Command::new("id")
            .arg("-u")
            .output()
            .is_ok_and(|o| String::from_utf8_lossy(&o.stdout).trim() == "0");
        if !root_user {
            eprintln!(
                "    SKIPPED browser tests: {CHROMIUM} not installed (apt-get install chromium)"
            );
            return Ok(());
        }
        let apt = |args: &[&str]| {
            Command::new("apt-get")
                .args(args)
                .env("DEBIAN_FRONTEND", "noninteractive")
                .status()
                .is_ok_and(|s| s.success())
        };
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
