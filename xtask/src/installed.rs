//! The release artifacts of `cargo xtask dist` installed and used as their users do, in
//! `cargo xtask test`: the wheel in fresh virtual environments of each CPython 3.10-3.13
//! found here, with NumPy 1.x (where it exists for that Python) and 2.x and no Rust
//! toolchain on `PATH`; the sdist built by pip; the C tarball unpacked into a prefix and
//! used through CMake and pkg-config; the Blender zip validated, installed as an extension
//! and tested in Blender's own builds as a Python module (`bpy` 4.2 LTS, 4.5 LTS, 5.0).
//! What they download is kept in [`cache_root`] between runs.

use std::path::{Path, PathBuf};
use std::process::Command;
use std::sync::Mutex;

use crate::dist::Artifacts;
use crate::sandbox::Sandbox;
use crate::steps;

/// The CPython versions the wheel supports (abi3, 3.10+) and is tested on.
const PYTHONS: &[&str] = &["3.10", "3.11", "3.12", "3.13"];
/// NumPy 1.x (the last series; no wheels for CPython 3.13) and 2.x (2.2 is the last with
/// wheels for 3.10).
const NUMPY_1: &str = "numpy==1.26.4";
const NUMPY_2: &str = "numpy==2.2.6";
const PYTEST: &str = "pytest==9.2.0";
/// The package's tests run against each installed wheel: everything but the CLI's, the
/// process pools' and Dask's (which need the repository's build or more packages), and
/// without the random-array fuzz test (40 s; the build's pytest step runs it).
const WHEEL_TESTS: &[&str] = &[
    "test_surface.py",
    "test_solver.py",
    "test_errors.py",
    "test_anchors.py",
    "test_apps.py",
];
/// The `-k` expression leaving out the slow fuzz test.
const SKIPPED_TESTS: &str = "not test_fuzz_random_arrays_only_raise_python_exceptions";
/// The environments that run [`WHEEL_TESTS`] besides the smoke script: the oldest CPython
/// with the oldest NumPy and the newest with the newest. Every environment runs
/// `python/examples/smoke.py` (precompute, forward, inverse, errors, NumPy in and out),
/// which is what a NumPy or CPython difference would break.
const FULL_TESTS_IN: &[(&str, u32)] = &[("3.10", 1), ("3.13", 2)];
/// Blender's builds as a module (PyPI `bpy`): the series tested and the pinned release.
/// All three need CPython 3.11.
const BPY: &[(&str, &str)] = &[("4.2", "4.2.23"), ("4.5", "4.5.15"), ("5.0", "5.0.1")];
const BPY_PYTHON: &str = "3.11";

/// The download cache of these steps, beside CI's cargo cache (`.ci/run`):
/// `$WAVG_CI_CACHE`, else `$XDG_CACHE_HOME/wavg-ci`, else `~/.cache/wavg-ci`.
pub fn cache_root() -> PathBuf {
    if let Some(dir) = std::env::var_os("WAVG_CI_CACHE") {
        return PathBuf::from(dir);
    }
    let base = std::env::var_os("XDG_CACHE_HOME")
        .map(PathBuf::from)
        .or_else(|| std::env::var_os("HOME").map(|h| PathBuf::from(h).join(".cache")))
        .unwrap_or_else(|| PathBuf::from("/tmp"));
    base.join("wavg-ci")
}

/// pip's settings for these steps: its own cache in [`cache_root`], no find-links folder.
fn pip_env() -> Vec<(&'static str, String)> {
    vec![
        (
            "PIP_CACHE_DIR",
            cache_root().join("pip").display().to_string(),
        ),
        ("PIP_FIND_LINKS", String::new()),
        ("PIP_DISABLE_PIP_VERSION_CHECK", "1".into()),
    ]
}

/// An interpreter of CPython `minor` (`"3.12"`): `python3.12` on `PATH`, else pyenv's,
/// else Debian's; `None` when none runs.
pub fn find_python(minor: &str) -> Option<PathBuf> {
    let mut candidates = vec![PathBuf::from(format!("python{minor}"))];
    let pyenv = std::env::var_os("PYENV_ROOT")
        .map(PathBuf::from)
        .or_else(|| std::env::var_os("HOME").map(|h| PathBuf::from(h).join(".pyenv")));
    if let Some(versions) = pyenv.map(|p| p.join("versions"))
        && let Ok(entries) = std::fs::read_dir(versions)
    {
        let mut dirs: Vec<PathBuf> = entries
            .flatten()
            .map(|e| e.path())
            .filter(|p| {
                p.file_name()
                    .is_some_and(|n| n.to_string_lossy().starts_with(&format!("{minor}.")))
            })
            .collect();
        dirs.sort();
        candidates.extend(
            dirs.iter()
                .rev()
                .map(|d| d.join("bin").join(format!("python{minor}"))),
        );
    }
    candidates.push(PathBuf::from(format!("/usr/bin/python{minor}")));
    let check = format!("import sys; assert '%d.%d' % sys.version_info[:2] == '{minor}'");
    candidates.into_iter().find(|py| {
        Command::new(py)
            .args(["-c", &check])
            .output()
            .is_ok_and(|o| o.status.success())
    })
}

/// `PATH` without the folders holding `cargo` or `rustc`.
fn path_without_rust() -> String {
    let path = std::env::var_os("PATH").unwrap_or_default();
    let kept: Vec<PathBuf> = std::env::split_paths(&path)
        .filter(|d| !d.join("cargo").exists() && !d.join("rustc").exists())
        .collect();
    std::env::join_paths(kept)
        .map(|p| p.to_string_lossy().into_owned())
        .unwrap_or_default()
}

/// A fresh virtual environment of `python` at `dir`; returns its interpreter.
fn fresh_venv(root: &Path, python: &Path, dir: &Path) -> Result<PathBuf, String> {
    let (py_s, dir_s) = (python.to_string_lossy(), dir.to_string_lossy());
    steps::command(root, &py_s, &["-m", "venv", "--clear", &dir_s])?;
    Ok(dir.join("bin").join("python"))
}

/// `python -m pip install --quiet ARGS` with [`pip_env`] and `env`.
fn pip(root: &Path, py: &Path, args: &[&str], env: &[(&str, &str)]) -> Result<(), String> {
    let mut all = vec!["-m", "pip", "install", "--quiet"];
    all.extend(args);
    let base = pip_env();
    let mut vars: Vec<(&str, &str)> = base.iter().map(|(k, v)| (*k, v.as_str())).collect();
    vars.extend(env);
    steps::command_env(root, &py.to_string_lossy(), &all, &vars)
}

/// The Python run in each environment before its tests: the installed package, its
/// version, the NumPy series, and no Rust toolchain in sight.
fn smoke(version: &str, numpy_major: u32) -> String {
    format!(
        "import shutil, sys, numpy, wavg\n\
         assert shutil.which('cargo') is None and shutil.which('rustc') is None, 'Rust on PATH'\n\
         assert wavg.__version__ == '{version}', wavg.__version__\n\
         assert wavg.__file__.startswith(sys.prefix), wavg.__file__\n\
         assert numpy.__version__.startswith('{numpy_major}.'), numpy.__version__\n\
         print('wavg', wavg.__version__, 'numpy', numpy.__version__, sys.version.split()[0])\n"
    )
}

/// The wheel in a fresh environment of each CPython found, with each NumPy series it has,
/// no Rust on `PATH`: the smoke check and `python/examples/smoke.py`, then in
/// [`FULL_TESTS_IN`] the package's tests; [`ENVS_AT_ONCE`] environments at a time. A Python
/// that is not installed here is reported `SKIPPED` with how to get it.
pub fn wheels(root: &Path, data_dir: &Path, a: &Artifacts) -> Result<(), String> {
    let mut envs = Vec::new();
    for minor in PYTHONS {
        let Some(python) = find_python(minor) else {
            eprintln!(
                "SKIPPED the wheel on CPython {minor}: no python{minor} here (pyenv install \
                 {minor}, or a Debian release that packages it)"
            );
            continue;
        };
        for (numpy, major) in [(NUMPY_1, 1), (NUMPY_2, 2)] {
            if *minor == "3.13" && major == 1 {
                eprintln!("    (NumPy 1.x has no wheels for CPython 3.13: 2.x only there)");
                continue;
            }
            envs.push((*minor, python.clone(), numpy, major));
        }
    }
    // The two with the package's tests (the longest) first, so neither ends alone.
    envs.sort_by_key(|(minor, _, _, major)| !FULL_TESTS_IN.contains(&(*minor, *major)));
    crate::parallel::run(&envs, ENVS_AT_ONCE, |(minor, python, numpy, major)| {
        wheel_env(root, data_dir, a, minor, python, numpy, *major)
    })?;
    eprintln!(
        "    the wheel passed in {} environments (the package's tests in {})",
        envs.len(),
        FULL_TESTS_IN.len()
    );
    Ok(())
}

/// How many of [`wheels`]' environments are made and tested at once: each is one
/// single-threaded pip or Python process at a time, so two keep both cores busy.
const ENVS_AT_ONCE: usize = 2;

/// One environment of [`wheels`]: CPython `minor` (`python`) with `numpy` (series
/// `major`), removed after its checks passed.
fn wheel_env(
    root: &Path,
    data_dir: &Path,
    a: &Artifacts,
    minor: &str,
    python: &Path,
    numpy: &str,
    major: u32,
) -> Result<(), String> {
    let name = format!("py{minor}-numpy{major}");
    let dir = steps::target_dir(root).join("dist-venvs").join(&name);
    let no_rust = path_without_rust();
    let wheel = a.wheel.to_string_lossy();
    let py = fresh_venv(root, python, &dir)?;
    let env = [("PATH", no_rust.as_str())];
    pip(
        root,
        &py,
        &["--only-binary=:all:", &wheel, numpy, PYTEST],
        &env,
    )?;
    let sandbox = Sandbox::new(root, &format!("wheel-{name}"))?;
    let py_s = py.to_string_lossy();
    let home = sandbox.home();
    sandbox.run(&home, &py_s, &["-c", &smoke(&a.version, major)], &env)?;
    let smoke_script = root.join("python/examples/smoke.py");
    sandbox.run(&home, &py_s, &[&smoke_script.to_string_lossy()], &env)?;
    if FULL_TESTS_IN.contains(&(minor, major)) {
        let tests_dir = root.join("python").join("tests");
        let tests: Vec<String> = WHEEL_TESTS
            .iter()
            .map(|t| tests_dir.join(t).display().to_string())
            .collect();
        let mut args = vec![
            "-m",
            "pytest",
            "-q",
            "-p",
            "no:cacheprovider",
            "-k",
            SKIPPED_TESTS,
        ];
        args.extend(tests.iter().map(String::as_str));
        let data = data_dir.to_string_lossy();
        sandbox.run(
            &home,
            &py_s,
            &args,
            &[("PATH", &no_rust), ("WAVG_DATA_DIR", &data)],
        )?;
    }
    let _ = std::fs::remove_dir_all(&dir);
    Ok(())
}

/// The sdist built and installed by pip (PEP 517 through maturin, with the Rust toolchain
/// on `PATH`; cargo's dev profile and target directory, so it reuses the built
/// dependencies), then the smoke check.
pub fn sdist(root: &Path, a: &Artifacts) -> Result<(), String> {
    let python = find_python("3.11")
        .or_else(|| find_python("3.12"))
        .ok_or("no CPython 3.11 or 3.12 for the sdist")?;
    let dir = steps::target_dir(root).join("dist-venvs").join("sdist");
    let py = fresh_venv(root, &python, &dir)?;
    let target = steps::target_dir(root).display().to_string();
    pip(
        root,
        &py,
        &[&a.sdist.to_string_lossy(), NUMPY_2],
        &[
            ("MATURIN_PEP517_ARGS", "--profile dev"),
            ("CARGO_TARGET_DIR", &target),
        ],
    )?;
    let sandbox = Sandbox::new(root, "sdist")?;
    let check = format!(
        "import sys, wavg\nassert wavg.__version__ == '{v}'\nassert wavg.__file__.startswith(sys.prefix)\n\
         print('sdist: wavg', wavg.__version__)",
        v = a.version
    );
    let (home, py_s) = (sandbox.home(), py.to_string_lossy());
    sandbox.run(&home, &py_s, &["-c", &check], &[])?;
    let smoke_script = root.join("python/examples/smoke.py");
    sandbox.run(&home, &py_s, &[&smoke_script.to_string_lossy()], &[])?;
    let _ = std::fs::remove_dir_all(&dir);
    Ok(())
}

/// The C tarball unpacked into a prefix in another folder, a consumer built with
/// `find_package(wavg)` and one with `pkg-config`, both run without `LD_LIBRARY_PATH`
/// (`cmake/check_package.cmake`, which also checks `wavg_version()` and the header's
/// macros and compiles `wavg.hpp`).
pub fn c_tarball(root: &Path, data_dir: &Path, a: &Artifacts) -> Result<(), String> {
    let work = steps::target_dir(root).join("dist-check-c");
    let name = a
        .c_tarball
        .file_name()
        .unwrap_or_default()
        .to_string_lossy();
    let expected = format!("wavg-{}-linux-x86_64.tar.gz", a.version);
    if name != expected {
        return Err(format!("the tarball is {name}, not {expected}"));
    }
    let script = root.join("cmake").join("check_package.cmake");
    steps::command_env(
        root,
        "cmake",
        &[
            &format!("-DTARBALL={}", a.c_tarball.display()),
            &format!("-DSOURCE_DIR={}", root.display()),
            &format!("-DWORK={}", work.display()),
            &format!(
                "-DMESH={}",
                data_dir.join("meshes").join("pig.off").display()
            ),
            "-DCC=cc",
            "-DCXX=c++",
            &format!("-DVERSION={}", a.version),
            "-P",
            &script.to_string_lossy(),
        ],
        &[("LD_LIBRARY_PATH", "")],
    )
}

/// The Blender zip in each Blender of [`BPY`], all at once (their environments are made
/// and their tests run side by side): validated by Blender's own `blender_ext.py
/// validate`, installed with `bpy.ops.extensions.package_install_files` and the add-on's
/// headless tests run (`blender/tests/run.py --extension`), each in a [`Sandbox`]. The
/// environments with `bpy` are kept in [`cache_root`] (`bpy-X.Y.Z/`).
pub fn blender(root: &Path, a: &Artifacts) -> Result<(), String> {
    let Some(python) = find_python(BPY_PYTHON) else {
        eprintln!("SKIPPED Blender as a module: the bpy wheels need CPython {BPY_PYTHON}");
        return Ok(());
    };
    let zip = a.blender_zip.to_string_lossy();
    crate::parallel::run(BPY, BPY.len(), |(series, pin)| {
        let py = bpy_venv(root, &python, pin)?;
        let validator = find_validator(&py)?;
        let py_s = py.to_string_lossy();
        steps::command(
            root,
            &py_s,
            &[&validator.to_string_lossy(), "validate", &zip],
        )
        .map_err(|e| format!("Blender {series}'s extension validator: {e}"))?;
        let sandbox = Sandbox::new(root, &format!("bpy-{series}"))?;
        sandbox
            .run(
                root,
                &py_s,
                &["blender/tests/run.py", "--", "--zip", &zip, "--extension"],
                &[],
            )
            .map_err(|e| format!("Blender {series} ({pin}): {e}"))
    })
}

/// Makes the environments of [`BPY`] that are missing, one after the other (for
/// `prefetch.rs`, beside the first builds); what fails is left for the step to report.
pub fn prefetch_bpy(root: &Path) {
    if let Some(python) = find_python(BPY_PYTHON) {
        for (_, pin) in BPY {
            let _ = bpy_venv(root, &python, pin);
        }
    }
}

/// The environment with `bpy==pin`, made once in [`cache_root`] and reused while its
/// stamp names the same pin; returns its interpreter. One thread at a time makes a given
/// environment (the prefetch may still be at it).
fn bpy_venv(root: &Path, python: &Path, pin: &str) -> Result<PathBuf, String> {
    static MAKING: [Mutex<()>; BPY.len()] = [const { Mutex::new(()) }; BPY.len()];
    let slot = BPY.iter().position(|(_, p)| *p == pin).unwrap_or(0);
    let _one = MAKING[slot].lock().unwrap_or_else(|e| e.into_inner());
    let dir = cache_root().join(format!("bpy-{pin}"));
    let py = dir.join("bin").join("python");
    let stamp = dir.join("wavg-bpy.txt");
    let want = format!("bpy=={pin}\n");
    if py.exists() && std::fs::read_to_string(&stamp).ok().as_deref() == Some(want.as_str()) {
        eprintln!("    bpy {pin}: {} (cached)", dir.display());
        return Ok(py);
    }
    let py = fresh_venv(root, python, &dir)?;
    pip(
        root,
        &py,
        &["--only-binary=:all:", &format!("bpy=={pin}")],
        &[],
    )?;
    std::fs::write(&stamp, want).map_err(|e| format!("{}: {e}", stamp.display()))?;
    Ok(py)
}

/// `blender_ext.py` of the `bpy` in the environment of `py`.
fn find_validator(py: &Path) -> Result<PathBuf, String> {
    let venv = py.parent().and_then(Path::parent).unwrap_or(py);
    let site = venv
        .join("lib")
        .join(format!("python{BPY_PYTHON}"))
        .join("site-packages")
        .join("bpy");
    let entries = std::fs::read_dir(&site).map_err(|e| format!("{}: {e}", site.display()))?;
    entries
        .flatten()
        .map(|e| {
            e.path()
                .join("scripts/addons_core/bl_pkg/cli/blender_ext.py")
        })
        .find(|p| p.is_file())
        .ok_or_else(|| format!("no blender_ext.py under {}", site.display()))
}
