//! The C/C++ side of `cargo xtask test`: makes sure the system packages the CMake build
//! needs are present (installing them with apt-get when running as root, as CI does),
//! then configures, builds and runs `ctest` on the root `CMakeLists.txt`.

use std::path::Path;

use crate::system::{apt, installed, is_root, runs};

/// A system requirement: how to tell it is present and the Debian package providing it.
struct Requirement {
    /// A program that must run (`--version`), or `None` for a library checked by package.
    program: Option<&'static str>,
    package: &'static str,
}

const REQUIREMENTS: &[Requirement] = &[
    Requirement {
        program: Some("cmake"),
        package: "cmake",
    },
    Requirement {
        program: Some("pkg-config"),
        package: "pkg-config",
    },
    Requirement {
        program: Some("c++"),
        package: "g++",
    },
    Requirement {
        program: None,
        package: "libopenmesh-dev",
    },
    Requirement {
        program: None,
        package: "libeigen3-dev",
    },
];

fn present(r: &Requirement) -> bool {
    match r.program {
        Some(p) => runs(p, &["--version"]),
        None => installed(r.package),
    }
}

/// The Debian packages of the C/C++ build that are missing.
pub fn missing_packages() -> Vec<&'static str> {
    REQUIREMENTS
        .iter()
        .filter(|r| !present(r))
        .map(|r| r.package)
        .collect()
}

/// Installs the missing packages when possible; otherwise says exactly what to install.
pub fn ensure_packages() -> Result<(), String> {
    let missing = missing_packages();
    if missing.is_empty() {
        return Ok(());
    }
    let list = missing.join(" ");
    if !is_root() || !runs("apt-get", &["--version"]) {
        return Err(format!(
            "the C/C++ build needs these Debian packages, which are missing: {list}\n\
             install them with `sudo apt-get install {list}` (xtask installs them itself \
             only when it runs as root on a system with apt-get)"
        ));
    }
    eprintln!("==> installing {list} with apt-get");
    let mut install = vec!["install", "-y", "--no-install-recommends"];
    install.extend(&missing);
    // A fresh machine may have no package lists yet: update once and retry.
    let installed = apt(&install) || (apt(&["update"]) && apt(&install));
    if !installed {
        return Err(format!(
            "apt-get could not install {list}; install them by hand and rerun"
        ));
    }
    match REQUIREMENTS.iter().find(|r| !present(r)) {
        Some(r) => Err(format!(
            "{} is still missing after apt-get install",
            r.package
        )),
        None => Ok(()),
    }
}

/// The CMake steps as (name, program, arguments), run from the repository root with the
/// build tree in `target/cmake`.
pub fn steps(root: &Path, data_dir: &Path) -> Vec<(&'static str, String, Vec<String>)> {
    let build = root.join("target").join("cmake");
    let build = build.display().to_string();
    vec![
        (
            "cmake configure",
            "cmake".into(),
            vec![
                "-S".into(),
                root.display().to_string(),
                "-B".into(),
                build.clone(),
                format!("-DWAVG_DATA_DIR={}", data_dir.display()),
                format!(
                    "-DWAVG_CARGO_TARGET_DIR={}",
                    crate::steps::target_dir(root).display()
                ),
                // The library from the tests' optimised dev build: the same feature set,
                // so cargo has only the C library itself left to link.
                "-DWAVG_CARGO_PROFILE=dev".into(),
                format!(
                    "-DWAVG_CARGO_BUILD_ARGS=--workspace;{};{};--all-targets",
                    crate::steps::EXCLUDED.join(";"),
                    crate::steps::NOT_BUILT.join(";")
                ),
            ],
        ),
        (
            "cmake build",
            "cmake".into(),
            vec!["--build".into(), build.clone(), "-j2".into()],
        ),
        (
            "ctest",
            "ctest".into(),
            // Two at a time: the OpenMesh harness on igea takes most of the step alone.
            vec![
                "--test-dir".into(),
                build,
                "--output-on-failure".into(),
                "-j2".into(),
            ],
        ),
    ]
}
