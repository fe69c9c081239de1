//! A cargo home of its own, for a cargo run beside another: a building cargo holds a shared
//! lock on its home's package cache for the whole build, and `cargo package` asks for the
//! exclusive one, so two sharing a home take turns instead of running together.
//!
//! The copy shares the downloaded `.crate` files and their unpacked sources through hard
//! links (cargo writes a crate only when its file is missing or empty and never changes an
//! unpacked source), and copies the index, whose cache files cargo rewrites in place.
//! Where hard links fail (another file system) it copies. Git checkouts are not shared:
//! cargo fetches them again if a package needs one.

use std::path::{Path, PathBuf};

/// Files of cargo's home that configure it.
const CONFIG_FILES: [&str; 2] = ["config.toml", "config"];

/// Makes `at` a fresh cargo home holding `shared`'s configuration and its crates.io
/// registry (index, downloaded crates, unpacked sources), without the local registries of
/// packaged workspace crates (folders named `-...`), and returns it. With no `shared` home,
/// or one without a registry, the new home starts empty and cargo downloads what it needs.
pub fn beside(shared: Option<&Path>, at: &Path) -> Result<PathBuf, String> {
    if at.exists() {
        std::fs::remove_dir_all(at).map_err(|e| format!("{}: {e}", at.display()))?;
    }
    std::fs::create_dir_all(at).map_err(|e| format!("{}: {e}", at.display()))?;
    let Some(shared) = shared else {
        return Ok(at.to_path_buf());
    };
    for name in CONFIG_FILES {
        let from = shared.join(name);
        if from.is_file() {
            std::fs::copy(&from, at.join(name)).map_err(|e| format!("{}: {e}", from.display()))?;
        }
    }
    for (part, link) in [("index", false), ("cache", true), ("src", true)] {
        let from = shared.join("registry").join(part);
        let Ok(registries) = std::fs::read_dir(&from) else {
            continue;
        };
        for registry in registries.filter_map(Result::ok) {
            if registry.file_name().to_string_lossy().starts_with('-') {
                continue;
            }
            let to = at.join("registry").join(part).join(registry.file_name());
            mirror(&registry.path(), &to, link)?;
        }
    }
    Ok(at.to_path_buf())
}

/// Recreates the tree `from` at `to`: directories made, files hard-linked when `link` (else,
/// or when that fails, copied). Symbolic links and lock files are left out.
fn mirror(from: &Path, to: &Path, link: bool) -> Result<(), String> {
    std::fs::create_dir_all(to).map_err(|e| format!("{}: {e}", to.display()))?;
    let entries = std::fs::read_dir(from).map_err(|e| format!("{}: {e}", from.display()))?;
    for entry in entries {
        let entry = entry.map_err(|e| format!("{}: {e}", from.display()))?;
        let kind = entry.file_type().map_err(|e| e.to_string())?;
        let (src, dst) = (entry.path(), to.join(entry.file_name()));
        let name = entry.file_name().to_string_lossy().into_owned();
        if kind.is_dir() {
            mirror(&src, &dst, link)?;
        } else if !kind.is_file() || name.starts_with(".package-cache") {
            continue;
        } else if !(link && std::fs::hard_link(&src, &dst).is_ok()) {
            std::fs::copy(&src, &dst).map_err(|e| format!("{}: {e}", src.display()))?;
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn write(path: &Path, text: &str) {
        std::fs::create_dir_all(path.parent().unwrap()).unwrap();
        std::fs::write(path, text).unwrap();
    }

    #[test]
    fn the_registry_is_shared_the_workspace_crates_are_not() {
        let dir = std::env::temp_dir().join(format!("wavg-cargo-home-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        let (shared, own) = (dir.join("shared"), dir.join("own"));
        let reg = shared.join("registry");
        write(&shared.join("config.toml"), "[net]\nretry = 3\n");
        write(&shared.join(".package-cache"), "");
        write(&reg.join("index/crates-io-1/.cache/se/rd/serde"), "index");
        write(&reg.join("cache/crates-io-1/serde-1.0.0.crate"), "crate");
        write(&reg.join("src/crates-io-1/serde-1.0.0/src/lib.rs"), "src");
        write(&reg.join("src/-abc/wavg-mesh-0.1.0/src/lib.rs"), "stale");
        write(&own.join("leftover"), "old");

        let home = beside(Some(&shared), &own).unwrap();
        let read = |p: &str| std::fs::read_to_string(home.join(p)).unwrap();
        assert_eq!(read("config.toml"), "[net]\nretry = 3\n");
        assert_eq!(
            read("registry/index/crates-io-1/.cache/se/rd/serde"),
            "index"
        );
        assert_eq!(
            read("registry/cache/crates-io-1/serde-1.0.0.crate"),
            "crate"
        );
        assert_eq!(
            read("registry/src/crates-io-1/serde-1.0.0/src/lib.rs"),
            "src"
        );
        assert!(!home.join("registry/src/-abc").exists());
        assert!(!home.join("leftover").exists());
        assert!(!home.join(".package-cache").exists());

        // The index is a copy: rewriting it leaves the shared one alone.
        std::fs::write(
            home.join("registry/index/crates-io-1/.cache/se/rd/serde"),
            "new",
        )
        .unwrap();
        let shared_index = reg.join("index/crates-io-1/.cache/se/rd/serde");
        assert_eq!(std::fs::read_to_string(shared_index).unwrap(), "index");

        let empty = beside(None, &dir.join("empty")).unwrap();
        assert_eq!(std::fs::read_dir(empty).unwrap().count(), 0);
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
