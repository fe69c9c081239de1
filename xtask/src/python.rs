//! The Python side of `cargo xtask test`: one virtual environment under cargo's target
//! directory, made with `python3 -m venv` and filled from `python/requirements-test.txt`
//! (pinned), reinstalled only when that file changes.

use std::path::{Path, PathBuf};
use std::sync::Mutex;

use crate::sandbox::Sandbox;
use crate::steps;

/// The Python package's folder (crate, package, tests, `pyproject.toml`), relative to the
/// repository root.
const PACKAGE: &str = "python";
/// The same folder as pip's argument (a bare `python` would name a package on the index).
const INSTALL: &str = "./python";
/// The requirements file, relative to the repository root.
const REQUIREMENTS: &str = "python/requirements-test.txt";
/// The package's tests, relative to the repository root.
const TESTS: &str = "python/tests";

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
    // One thread at a time (the prefetch may still be at it).
    static MAKING: Mutex<()> = Mutex::new(());
    let _one = MAKING.lock().unwrap_or_else(|e| e.into_inner());
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
        pip_install(root, &py, &["-r", REQUIREMENTS], &[("PIP_FIND_LINKS", "")])?;
        std::fs::write(&stamp, wanted)
            .map_err(|e| format!("cannot write {}: {e}", stamp.display()))?;
    }
    Ok(py)
}

/// `python -m pip install --quiet ARGS` with the environment's `py`, in `root`, with `env`.
fn pip_install(root: &Path, py: &Path, args: &[&str], env: &[(&str, &str)]) -> Result<(), String> {
    let py_s = py.to_string_lossy();
    let mut all = vec![
        "-m",
        "pip",
        "install",
        "--quiet",
        "--disable-pip-version-check",
    ];
    all.extend(args);
    steps::command_env(root, &py_s, &all, env)
}

/// Builds the `wavg` wheel (abi3, CPython >= 3.10) with the environment's maturin from
/// `python/pyproject.toml`, in cargo's dev profile and target directory, so the dependencies the
/// workspace build already compiled are reused (only PyO3 and the binding crate compile);
/// returns the wheel's path (in `target/wheels`, older `wavg-*.whl` there removed first).
pub fn build_wheel(root: &Path) -> Result<PathBuf, String> {
    let py = ensure_venv(root)?;
    let out = steps::target_dir(root).join("wheels");
    if let Ok(entries) = std::fs::read_dir(&out) {
        for e in entries.flatten() {
            let name = e.file_name().to_string_lossy().into_owned();
            if name.starts_with("wavg-") && name.ends_with(".whl") {
                let _ = std::fs::remove_file(e.path());
            }
        }
    }
    let maturin = venv_dir(root).join("bin").join("maturin");
    let (maturin_s, py_s, out_s) = (
        maturin.to_string_lossy(),
        py.to_string_lossy(),
        out.to_string_lossy(),
    );
    // Run in the package's folder (maturin reads the `pyproject.toml` there), with the
    // target directory made absolute as seen from the repository root.
    let target = steps::target_dir(root);
    steps::command_env(
        &root.join(PACKAGE),
        &maturin_s,
        &[
            "build",
            "--profile",
            "dev",
            "--interpreter",
            &py_s,
            "--out",
            &out_s,
        ],
        &[("CARGO_TARGET_DIR", &target.to_string_lossy())],
    )?;
    std::fs::read_dir(&out)
        .map_err(|e| format!("{}: {e}", out.display()))?
        .flatten()
        .map(|e| e.path())
        .find(|p| {
            p.file_name()
                .is_some_and(|n| n.to_string_lossy().starts_with("wavg-"))
                && p.extension().is_some_and(|x| x == "whl")
        })
        .ok_or_else(|| format!("maturin built no wavg wheel in {}", out.display()))
}

/// Installs the package as the README says, `pip install ./python` (PEP 517 through maturin, with
/// build isolation), but in cargo's dev profile and target directory (`MATURIN_PEP517_ARGS`)
/// so the workspace build's dependencies are reused; then runs `pytest python/tests` there,
/// in a [`Sandbox`], with the `wavg` binary in `WAVG_CLI` and the C library in `WAVG_LIBWAVG`
/// (built first).
/// pytest's "no tests ran" (exit 5) fails too.
pub fn test_package(root: &Path, data_dir: &Path) -> Result<(), String> {
    // The C library the tests load is built from this source first: one left by an earlier
    // run would make another embedding than the other doors. The whole workspace's build,
    // as the CMake and fuzz steps run it, so the libraries keep the workspace's features
    // (`-p wavg-ffi` alone compiled every crate of ours a second time with fewer).
    steps::cargo_build_all(root)?;
    let py = ensure_venv(root)?;
    let py_s = py.to_string_lossy();
    let target = steps::target_dir(root);
    let target = target.to_string_lossy();
    pip_install(
        root,
        &py,
        &["--force-reinstall", "--no-deps", INSTALL],
        &[
            ("MATURIN_PEP517_ARGS", "--profile dev"),
            ("CARGO_TARGET_DIR", &target),
        ],
    )?;
    let data = data_dir.to_string_lossy();
    let wavg_bin = steps::target_dir(root).join("debug").join("wavg");
    let wavg_bin = wavg_bin.to_string_lossy();
    let libwavg = steps::target_dir(root).join("debug").join("libwavg.so");
    let libwavg = libwavg.to_string_lossy();
    let gltf_dir = crate::gltf::written_dir(root);
    let gltf_dir = gltf_dir.to_string_lossy();
    Sandbox::new(root, "python")?
        .run(
            root,
            &py_s,
            &["-m", "pytest", "-q", TESTS],
            &[
                ("WAVG_DATA_DIR", &data),
                ("WAVG_CLI", &wavg_bin),
                ("WAVG_LIBWAVG", &libwavg),
                (crate::gltf::DIR_VAR, &gltf_dir),
            ],
        )
        .map_err(|e| format!("{e} (pytest exit 5 means no tests ran)"))
}

/// The `python` code blocks of `README.md` and `docs/`, run by the CLI's test
/// `docs_blocks::every_code_block` with the environment's interpreter (the package just
/// installed): there a block that cannot import what it needs fails instead of being
/// skipped.
pub fn docs_blocks(root: &Path, data_dir: &Path) -> Result<(), String> {
    let py = python(root);
    let (py_s, data) = (py.to_string_lossy(), data_dir.to_string_lossy());
    steps::command_env(
        root,
        "cargo",
        &[
            &["test", "--workspace"],
            steps::EXCLUDED,
            // --nocapture: the runner's lines naming blocks over 2 s show in the log.
            &[
                "--test",
                "cli",
                "--",
                "docs_blocks::every_code_block",
                "--nocapture",
            ],
        ]
        .concat(),
        &[
            ("WAVG_DOCS_PYTHON", &py_s),
            ("WAVG_DOCS_LANGS", "python,py"),
            ("WAVG_DATA_DIR", &data),
        ],
    )
}
