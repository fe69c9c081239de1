//! The Blender add-on: `cargo xtask blender-addon` packs `blender/wavg_blender/` with the
//! contents of the wavg wheel unpacked into its `vendor/` folder (a compiled module cannot
//! be imported from inside a zip) as `target/wavg_blender.zip`; the `blender` step of
//! `cargo xtask test` installs Blender and NumPy with apt when root, builds the zip and
//! runs the headless tests (`blender/tests/run.py`) in Blender.

use std::path::{Path, PathBuf};
use std::process::Command;

use crate::sandbox::{self, Sandbox};
use crate::system::{apt, installed, is_root, runs};
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
pub const PACKAGES: &[&str] = &["blender", "python3-numpy", "xvfb"];

/// Builds `target/wavg_blender.zip` (the wheel first) and returns its path.
pub fn build_addon(root: &Path) -> Result<PathBuf, String> {
    let wheel = python::build_wheel(root)?;
    let zip = steps::target_dir(root).join("wavg_blender.zip");
    pack(root, &wheel, &zip)?;
    Ok(zip)
}

/// Packs the add-on's sources with `wheel` unpacked in its `vendor/` folder as `zip`: one
/// file that Blender 4.2+ installs as an extension (its `blender_manifest.toml`) and older
/// Blenders as a legacy add-on (its `bl_info`).
pub fn pack(root: &Path, wheel: &Path, zip: &Path) -> Result<(), String> {
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
    let tmp = zip.with_extension("zip.part");
    let (tmp_s, addon_s) = (tmp.to_string_lossy(), addon.to_string_lossy());
    steps::command(root, "python3", &["-m", "zipfile", "-c", &tmp_s, &addon_s])?;
    std::fs::rename(&tmp, zip).map_err(|e| format!("{}: {e}", zip.display()))?;
    eprintln!("==> {} (with {})", zip.display(), wheel.display());
    Ok(())
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
/// be installed here (not root, or no apt-get). Every Blender it starts runs in a
/// [`Sandbox`] whose home holds a decoy `wavg_blender` in the user's add-ons and
/// extensions folders; the step fails if a test loads it or anything under the home's
/// Blender folder changes.
pub fn test(root: &Path) -> Result<(), String> {
    let sandbox = Sandbox::new(root, "blender")?;
    let Some(version) = ensure_packages(&sandbox)? else {
        eprintln!(
            "SKIPPED blender (not installed): `sudo apt-get install {}` to run the add-on's tests",
            PACKAGES.join(" ")
        );
        return Ok(());
    };
    let zip = build_addon(root)?;
    let user = plant_decoy(&sandbox.home(), &version)?;
    let before = sandbox::snapshot(&user)?;
    run_tests(root, &sandbox, &zip)?;
    let changed = sandbox::differences(&before, &sandbox::snapshot(&user)?);
    if changed.is_empty() {
        eprintln!(
            "    {} ({} entries, the decoy add-on among them) unchanged",
            user.display(),
            before.len()
        );
        Ok(())
    } else {
        Err(format!(
            "the tests changed the user's Blender folder {}: {}",
            user.display(),
            changed
                .iter()
                .map(|p| p.display().to_string())
                .collect::<Vec<_>>()
                .join(", ")
        ))
    }
}

/// A `wavg_blender` that fails on import, with a `bl_info` and a manifest so that Blender
/// lists it as an add-on and as an extension.
const DECOY_INIT: &str = "bl_info = {\"name\": \"wavg (decoy)\", \"blender\": (3, 4, 0), \"category\": \"Object\"}\n\
raise ImportError(\"the decoy wavg_blender of the user's own Blender was loaded\")\n";
const DECOY_MANIFEST: &str = "schema_version = \"1.0.0\"\nid = \"wavg_blender\"\n\
version = \"0.0.1\"\nname = \"wavg (decoy)\"\ntagline = \"A decoy\"\nmaintainer = \"tests\"\n\
type = \"add-on\"\nblender_version_min = \"4.2.0\"\nlicense = [\"SPDX:MIT\"]\n";

/// Puts a decoy `wavg_blender` where Blender `version` (`"3.4"`) finds the user's own
/// add-ons and extensions under `home` (as the user had installed the add-on), and
/// returns the user's Blender folder (`home/.config/blender`).
fn plant_decoy(home: &Path, version: &str) -> Result<PathBuf, String> {
    let user = home.join(".config").join("blender");
    let base = user.join(version);
    let files = [
        (
            base.join("scripts/addons/wavg_blender/__init__.py"),
            DECOY_INIT,
        ),
        (
            base.join("extensions/user_default/wavg_blender/__init__.py"),
            DECOY_INIT,
        ),
        (
            base.join("extensions/user_default/wavg_blender/blender_manifest.toml"),
            DECOY_MANIFEST,
        ),
    ];
    for (path, text) in files {
        let dir = path.parent().unwrap_or(home);
        std::fs::create_dir_all(dir).map_err(|e| format!("{}: {e}", dir.display()))?;
        std::fs::write(&path, text).map_err(|e| format!("{}: {e}", path.display()))?;
    }
    Ok(user)
}

/// The headless tests, the README's example and the window test, each Blender in `sandbox`.
fn run_tests(root: &Path, sandbox: &Sandbox, zip: &Path) -> Result<(), String> {
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
    let cli = steps::target_dir(root).join("debug").join("wavg");
    let cli_s = cli.to_string_lossy();
    if cli.is_file() {
        args.extend(["--wavg-cli", &cli_s]);
    }
    sandbox.run(root, "blender", &args, &[])?;
    // The example of docs/blender.md, as written there.
    sandbox.run(
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
        &[],
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
    sandbox.run(root, "xvfb-run", &ui, &[])
}

/// The running Blender's `major.minor` (from `blender --version`, started in `sandbox`),
/// or `None` when it does not start.
fn blender_version(sandbox: &Sandbox) -> Option<String> {
    let mut cmd = Command::new("blender");
    sandbox.apply(&mut cmd);
    let out = cmd
        .args(["-b", "--factory-startup", "--version"])
        .output()
        .ok()
        .filter(|o| o.status.success())?;
    let text = String::from_utf8_lossy(&out.stdout);
    let full = text
        .lines()
        .find_map(|l| l.trim().strip_prefix("Blender "))?
        .split_whitespace()
        .next()?;
    let mut parts = full.split('.');
    Some(format!("{}.{}", parts.next()?, parts.next()?))
}

/// Blender's `major.minor` when Blender (with NumPy) is there, after installing the missing
/// packages with apt-get when root; `None` when Blender is missing and cannot be installed
/// here.
fn ensure_packages(sandbox: &Sandbox) -> Result<Option<String>, String> {
    let missing: Vec<&str> = PACKAGES.iter().copied().filter(|p| !installed(p)).collect();
    let root_user = is_root();
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
    Ok(blender_version(sandbox).filter(|_| installed("python3-numpy") || !installed("blender")))
}
