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
