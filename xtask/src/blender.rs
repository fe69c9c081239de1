//! The Blender add-on: `cargo xtask blender-addon` packs `blender/wavg_blender/` with the
//! contents of the wavg wheel unpacked into its `vendor/` folder (a compiled module cannot
//! be imported from inside a zip) as `target/wavg_blender.zip`; the `blender` step of
//! `cargo xtask test` installs Blender and NumPy with apt when root, builds the zip and
//! runs the headless tests (`blender/tests/run.py`) in Blender.

use std::path::{Path, PathBuf};
use std::process::Command;

use crate::{python, steps};

/// The add-on's folder in the repository.
const SOURCE: &str = "blender/wavg_blender";
/// The headless example of docs/blender.md.
const EXAMPLE: &str = "blender/examples/headless.py";

/// The headless test script.
const TESTS: &str = "blender/tests/run.py";
/// The test of the interactive (modal) precompute in a window on a virtual display.
const UI_TEST: &str = "blender/tests/ui_modal.py";
/// The Debian packages the tests need: Blender, the NumPy of its (system) Python, and Xvfb
/// for the one test that needs a window.
const PACKAGES: &[&str] = &["blender", "python3-numpy", "xvfb"];

/// Builds `target/wavg_blender.zip` (the wheel first) and returns its path.
pub fn build_addon(root: &Path) -> Result<PathBuf, String> {
    let wheel = python::build_wheel(root)?;
    let target = steps::target_dir(root);
    let stage = target.join("blender-addon");
    if stage.exists() {
        std::fs::remove_dir_all(&stage).map_err(|e| format!("{}: {e}", stage.display()))?;
    }
    let addon = stage.join("wavg_blender");
    copy_sources(&root.join(SOURCE), &addon)?;
    let vendor = addon.join("vendor");
    let (wheel_s, vendor_s) = (wheel.to_string_lossy(), vendor.to_string_lossy());
    steps::command(
        root,
        "python3",
        &["-m", "zipfile", "-e", &wheel_s, &vendor_s],
    )?;
    // Written beside and renamed, so a failed build never leaves a partial zip.
    let zip = target.join("wavg_blender.zip");
    let tmp = target.join("wavg_blender.zip.part");
    let (tmp_s, addon_s) = (tmp.to_string_lossy(), addon.to_string_lossy());
    steps::command(root, "python3", &["-m", "zipfile", "-c", &tmp_s, &addon_s])?;
    std::fs::rename(&tmp, &zip).map_err(|e| format!("{}: {e}", zip.display()))?;
    eprintln!("==> {} (with {})", zip.display(), wheel.display());
    Ok(zip)
}

/// Copies the add-on's files (not caches, not a `vendor/` folder of a local install).
fn copy_sources(from: &Path, to: &Path) -> Result<(), String> {
    std::fs::create_dir_all(to).map_err(|e| format!("{}: {e}", to.display()))?;
    let entries = std::fs::read_dir(from).map_err(|e| format!("{}: {e}", from.display()))?;
    for entry in entries {
        let entry = entry.map_err(|e| format!("{}: {e}", from.display()))?;
        let name = entry.file_name();
        let path = entry.path();
        if path.is_dir() {
            if name != "__pycache__" && name != "vendor" {
                copy_sources(&path, &to.join(&name))?;
            }
        } else {
            std::fs::copy(&path, to.join(&name)).map_err(|e| format!("{}: {e}", path.display()))?;
        }
    }
    Ok(())
}

/// The `blender` step: the headless tests, or `SKIPPED` when Blender is missing and cannot
/// be installed here (not root, or no apt-get).
pub fn test(root: &Path) -> Result<(), String> {
    if !ensure_packages()? {
        eprintln!(
            "SKIPPED blender (not installed): `sudo apt-get install {}` to run the add-on's tests",
            PACKAGES.join(" ")
        );
        return Ok(());
    }
    let zip = build_addon(root)?;
    let target = steps::target_dir(root);
    let scripts = target.join("blender-user-scripts");
    let zip_s = zip.to_string_lossy();
    let mut args = vec![
        "-b",
        "--factory-startup",
        "--python-exit-code",
        "1",
        "--python",
        TESTS,
        "--",
        "--zip",
        &zip_s,
    ];
    // The CLI of the tests' build, to compare the decal with `wavg decal`.
    let cli = target.join("debug").join("wavg");
    let cli_s = cli.to_string_lossy();
    if cli.is_file() {
        args.extend(["--wavg-cli", &cli_s]);
    }
    let scripts_s = scripts.to_string_lossy();
    let env = [("BLENDER_USER_SCRIPTS", scripts_s.as_ref())];
    steps::command_env(root, "blender", &args, &env)?;
    // The example of docs/blender.md, as written there.
    steps::command_env(
        root,
        "blender",
        &[
            "-b",
            "--factory-startup",
            "--python-exit-code",
            "1",
            "--python",
            EXAMPLE,
            "--",
            &zip_s,
        ],
        &env,
    )?;
    if !runs("xvfb-run", &["--help"]) {
        eprintln!("SKIPPED blender window test (xvfb-run not installed)");
        return Ok(());
    }
    let ui = [
        "-a",
        "-s",
        "-screen 0 1280x800x24",
        "blender",
        "--factory-startup",
        "--enable-event-simulate",
        "--python",
        UI_TEST,
        "--",
        "--zip",
        &zip_s,
    ];
    steps::command_env(root, "xvfb-run", &ui, &env)
}

fn runs(program: &str, args: &[&str]) -> bool {
    Command::new(program)
        .args(args)
        .output()
        .is_ok_and(|o| o.status.success())
}

fn installed(package: &str) -> bool {
    Command::new("dpkg-query")
        .args(["-W", "-f=${Status}", package])
        .output()
        .is_ok_and(|o| {
            o.status.success() && String::from_utf8_lossy(&o.stdout).ends_with(" installed")
        })
}

fn blender_runs() -> bool {
    runs("blender", &["-b", "--factory-startup", "--version"])
}

/// True when Blender (with NumPy) is there, after installing the missing packages with
/// apt-get when root; false when Blender is missing and cannot be installed here.
fn ensure_packages() -> Result<bool, String> {
    let missing: Vec<&str> = PACKAGES.iter().copied().filter(|p| !installed(p)).collect();
    let root_user = Command::new("id")
        .arg("-u")
        .output()
        .is_ok_and(|o| String::from_utf8_lossy(&o.stdout).trim() == "0");
    let apt = |args: &[&str]| {
        Command::new("apt-get")
            .args(args)
            .env("DEBIAN_FRONTEND", "noninteractive")
            .status()
            .is_ok_and(|s| s.success())
    };
    if !missing.is_empty() && root_user && apt(&["--version"]) {
        let list = missing.join(" ");
        eprintln!("==> installing {list} with apt-get");
        let mut install = vec!["install", "-y"];
        install.extend(&missing);
        if !(apt(&install) || (apt(&["update"]) && apt(&install))) {
            return Err(format!(
                "apt-get could not install {list}; install them by hand and rerun"
            ));
        }
    }
    // Debian's Blender runs on the system Python, which needs python3-numpy; other builds
    // (blender.org's) carry their own Python and NumPy.
    Ok(blender_runs() && (installed("python3-numpy") || !installed("blender")))
}
