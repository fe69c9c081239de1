//! Source policy checked by `cargo xtask test`: `unsafe` code only in the crates that need
//! it (SIMD and prefetch hints in `wavg-project`, the C ABI in `wavg-ffi`); every other
//! crate root says `#![forbid(unsafe_code)]`. One module style: a module with submodules
//! is `name/mod.rs`, never `name.rs` beside a `name/` folder. One integration test binary
//! per crate: each binary links the whole library again, and cargo runs them one by one.

use std::path::Path;

use crate::lines::rust_files;

/// The folders whose Rust files follow the one module style (all of the workspace's).
const STYLE_DIRS: [&str; 5] = ["crates", "python", "xtask", "lab", "fuzz"];

/// Crates allowed to contain `unsafe` blocks (each keeps them in one module).
const UNSAFE_ALLOWED: [&str; 2] = ["wavg-project", "wavg-ffi"];

/// `Err` names every crate root (library or binary) under `crates/`, `python` (wavg-py),
/// `xtask` and `lab` that lacks `#![forbid(unsafe_code)]` without being allowed `unsafe`.
pub fn check_unsafe(root: &Path) -> Result<(), String> {
    let mut dirs: Vec<_> = std::fs::read_dir(root.join("crates"))
        .map_err(|e| format!("crates: {e}"))?
        .flatten()
        .map(|e| e.path())
        .filter(|p| p.is_dir())
        .collect();
    dirs.push(root.join("python"));
    dirs.push(root.join("xtask"));
    dirs.push(root.join("lab"));
    dirs.sort();
    let mut missing = Vec::new();
    for dir in dirs {
        let name = dir
            .file_name()
            .unwrap_or_default()
            .to_string_lossy()
            .to_string();
        if UNSAFE_ALLOWED.contains(&name.as_str()) {
            continue;
        }
        for file in ["src/lib.rs", "src/main.rs"] {
            let path = dir.join(file);
            let Ok(text) = std::fs::read_to_string(&path) else {
                continue;
            };
            if !text.lines().any(|l| l.trim() == "#![forbid(unsafe_code)]") {
                missing.push(format!("{name}/{file}"));
            }
        }
    }
    if missing.is_empty() {
        Ok(())
    } else {
        Err(format!(
            "#![forbid(unsafe_code)] missing in {}",
            missing.join(", ")
        ))
    }
}

/// `Err` names every `name.rs` under [`STYLE_DIRS`] that sits beside a folder `name/`
/// holding Rust files: the workspace writes such a module as `name/mod.rs` (the style most
/// of its modules had).
pub fn check_module_style(root: &Path) -> Result<(), String> {
    let mut files = Vec::new();
    for dir in STYLE_DIRS {
        let dir = root.join(dir);
        if dir.is_dir() {
            rust_files(&dir, &mut files)?;
        }
    }
    let mut mixed: Vec<String> = files
        .iter()
        .filter(|f| {
            let sub = f.with_extension("");
            files.iter().any(|g| g.parent() == Some(sub.as_path()))
        })
        .map(|f| f.strip_prefix(root).unwrap_or(f).display().to_string())
        .collect();
    mixed.sort();
    if mixed.is_empty() {
        Ok(())
    } else {
        Err(format!(
            "modules with submodules are written `name/mod.rs`; move {}",
            mixed
                .iter()
                .map(|f| format!("{f} to {}/mod.rs", f.trim_end_matches(".rs")))
                .collect::<Vec<_>>()
                .join(", ")
        ))
    }
}

/// `Err` names every crate under `crates/` (and `python`, `xtask`, `lab`, `fuzz`) with more
/// than one integration test target (`tests/NAME.rs` or `tests/NAME/main.rs`): its tests
/// belong in one binary, `tests/NAME/main.rs` with one module per file.
pub fn check_test_binaries(root: &Path) -> Result<(), String> {
    let mut dirs: Vec<_> = std::fs::read_dir(root.join("crates"))
        .map_err(|e| format!("crates: {e}"))?
        .flatten()
        .map(|e| e.path())
        .collect();
    dirs.extend(["python", "xtask", "lab", "fuzz"].map(|d| root.join(d)));
    dirs.sort();
    let mut many = Vec::new();
    for dir in dirs {
        let Ok(entries) = std::fs::read_dir(dir.join("tests")) else {
            continue;
        };
        let mut targets: Vec<String> = entries
            .flatten()
            .map(|e| e.path())
            .filter(|p| {
                p.extension().is_some_and(|x| x == "rs") && p.is_file()
                    || p.join("main.rs").is_file()
            })
            .map(|p| p.strip_prefix(root).unwrap_or(&p).display().to_string())
            .collect();
        if targets.len() > 1 {
            targets.sort();
            many.push(targets.join(", "));
        }
    }
    if many.is_empty() {
        Ok(())
    } else {
        Err(format!(
            "one integration test binary per crate (tests/NAME/main.rs, a module per file); \
             merge {}",
            many.join("; ")
        ))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_crate_without_forbid_is_named_and_allowed_ones_are_not() {
        let root = std::env::temp_dir().join(format!("xtask-policy-{}", std::process::id()));
        let write = |rel: &str, text: &str| {
            let p = root.join(rel);
            std::fs::create_dir_all(p.parent().unwrap()).unwrap();
            std::fs::write(p, text).unwrap();
        };
        write(
            "crates/good/src/lib.rs",
            "//! ok\n#![forbid(unsafe_code)]\n",
        );
        write("crates/wavg-ffi/src/lib.rs", "//! the C ABI\n");
        write(
            "xtask/src/main.rs",
            "#![forbid(unsafe_code)]\nfn main() {}\n",
        );
        assert_eq!(check_unsafe(&root), Ok(()));
        write("crates/bad/src/main.rs", "fn main() {}\n");
        let err = check_unsafe(&root).unwrap_err();
        assert!(
            err.contains("bad/src/main.rs") && !err.contains("good"),
            "{err}"
        );
        write("python/src/lib.rs", "//! the Python extension\n");
        let err = check_unsafe(&root).unwrap_err();
        assert!(err.contains("python/src/lib.rs"), "{err}");
        std::fs::remove_dir_all(&root).unwrap();
    }

    #[test]
    fn a_module_file_beside_its_folder_is_named() {
        let root = std::env::temp_dir().join(format!("xtask-style-{}", std::process::id()));
        let write = |rel: &str| {
            let p = root.join(rel);
            std::fs::create_dir_all(p.parent().unwrap()).unwrap();
            std::fs::write(p, "//! x\n").unwrap();
        };
        write("crates/a/src/lib.rs");
        write("crates/a/src/one/mod.rs");
        write("crates/a/src/one/leaf.rs");
        write("crates/a/tests/common/mod.rs");
        write("crates/a/src/data.rs");
        write("crates/a/src/data/table.txt");
        write("xtask/src/main.rs");
        assert_eq!(check_module_style(&root), Ok(()));
        write("crates/a/src/two.rs");
        write("crates/a/src/two/leaf.rs");
        let err = check_module_style(&root).unwrap_err();
        assert!(
            err.contains("crates/a/src/two.rs to crates/a/src/two/mod.rs")
                && !err.contains("one")
                && !err.contains("data"),
            "{err}"
        );
        std::fs::remove_dir_all(&root).unwrap();
    }

    #[test]
    fn a_crate_with_two_test_binaries_is_named() {
        let root = std::env::temp_dir().join(format!("xtask-tests-{}", std::process::id()));
        let write = |rel: &str| {
            let p = root.join(rel);
            std::fs::create_dir_all(p.parent().unwrap()).unwrap();
            std::fs::write(p, "//! x\n").unwrap();
        };
        write("crates/a/tests/a/main.rs");
        write("crates/a/tests/a/one.rs");
        write("crates/a/tests/a/common.rs");
        write("crates/a/tests/data/mesh.obj");
        write("crates/b/tests/header.rs");
        write("crates/c/src/lib.rs");
        assert_eq!(check_test_binaries(&root), Ok(()));
        write("crates/a/tests/two.rs");
        let err = check_test_binaries(&root).unwrap_err();
        assert!(
            err.contains("crates/a/tests/a, crates/a/tests/two.rs") && !err.contains("crates/b"),
            "{err}"
        );
        std::fs::remove_dir_all(&root).unwrap();
    }

    #[test]
    fn this_workspace_follows_the_policy() {
        let root = Path::new(env!("CARGO_MANIFEST_DIR")).parent().unwrap();
        assert_eq!(check_unsafe(root), Ok(()));
        assert_eq!(check_module_style(root), Ok(()));
        assert_eq!(check_test_binaries(root), Ok(()));
    }
}
