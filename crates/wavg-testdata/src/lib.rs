//! Test support, not published: locating the shared test-mesh folder (`$WAVG_DATA_DIR`, default `../shared/data` beside
//! the repository) for tests and benchmarks. The meshes are never copied into the repository.
//! [`json_keys`]: the documented keys of the `wavg bench` reports, for the tests of the
//! protocols and of the commands.
//! [`gltf`] builds glTF files in code.

#![deny(unreachable_pub)]
#![forbid(unsafe_code)]

use std::path::PathBuf;

pub mod gltf;
pub mod json_keys;

/// The data folder if it exists: `$WAVG_DATA_DIR`, else `<repository>/../shared/data`.
///
/// ```
/// if let Some(dir) = wavg_testdata::data_dir() {
///     assert!(dir.is_dir());
/// }
/// ```
pub fn data_dir() -> Option<PathBuf> {
    let dir = match std::env::var_os("WAVG_DATA_DIR") {
        Some(d) if !d.is_empty() => PathBuf::from(d),
        _ => PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../../shared/data"),
    };
    dir.is_dir().then_some(dir)
}

/// The data folder for a test named `test`, or `None` after printing that the test is
/// skipped. In CI (`CI` set to anything but `false`/`0`) a missing folder is a failure,
/// so the data tests can never silently stop running there.
pub fn require_data_dir(test: &str) -> Option<PathBuf> {
    match data_dir() {
        Some(d) => Some(d),
        None => {
            let ci = std::env::var("CI").is_ok_and(|v| !v.is_empty() && v != "false" && v != "0");
            assert!(
                !ci,
                "{test}: WAVG_DATA_DIR is missing in CI; the data tests must run there"
            );
            eprintln!(
                "SKIPPED {test}: no data folder (set WAVG_DATA_DIR or put ../shared/data beside the repository)"
            );
            None
        }
    }
}

/// A file inside the data folder, or `None` (printing the skip) when the folder is missing.
pub fn require_data_file(test: &str, relative: &str) -> Option<PathBuf> {
    let p = require_data_dir(test)?.join(relative);
    assert!(
        p.exists(),
        "{test}: {} is missing from the data folder",
        p.display()
    );
    Some(p)
}

/// The folder named by `WAVG_GLTF_DIR`, where tests leave a copy of every glTF file they
/// write, for `cargo xtask test` to run the Khronos glTF Validator over.
pub const GLTF_DIR_VAR: &str = "WAVG_GLTF_DIR";

/// Keeps a copy of the glTF file `path` (and of the `.bin` beside a `.gltf`) in
/// `$WAVG_GLTF_DIR` when it is set, under `name` (unique per test, e.g. the test's
/// name): a no-op otherwise. Panics when the copy fails (a test helper).
pub fn keep_gltf(path: &std::path::Path, name: &str) {
    let Some(dir) = std::env::var_os(GLTF_DIR_VAR) else {
        return;
    };
    let dir = PathBuf::from(dir).join(name);
    std::fs::create_dir_all(&dir).unwrap();
    let copy = |p: &std::path::Path| {
        if p.exists() {
            std::fs::copy(p, dir.join(p.file_name().unwrap())).unwrap();
        }
    };
    copy(path);
    if path
        .extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("gltf"))
    {
        copy(&path.with_extension("bin"));
    }
}
