//! ARCHITECTURE.md is the one map of the repository: every top-level folder git tracks and
//! every crate under `crates/` must be named there (as `` `name/` `` or `` `name` ``).

use std::path::Path;
use std::process::Command;

/// Fails naming the folders and crates ARCHITECTURE.md does not mention.
pub fn check(root: &Path) -> Result<(), String> {
    let map = std::fs::read_to_string(root.join("ARCHITECTURE.md"))
        .map_err(|e| format!("ARCHITECTURE.md: {e}"))?;
    let missing = missing(&map, &folders(root)?);
    if missing.is_empty() {
        Ok(())
    } else {
        Err(format!(
            "ARCHITECTURE.md, the map of the repository, does not name: {}",
            missing.join(", ")
        ))
    }
}

/// The top-level folders git tracks (`name/`) and the crates under `crates/` (`name`).
fn folders(root: &Path) -> Result<Vec<String>, String> {
    let out = Command::new("git")
        .args(["ls-files"])
        .current_dir(root)
        .output()
        .map_err(|e| format!("git ls-files: {e}"))?;
    let text = String::from_utf8_lossy(&out.stdout);
    let mut names: Vec<String> = Vec::new();
    for path in text.lines() {
        let mut parts = path.split('/');
        let (Some(first), Some(second)) = (parts.next(), parts.next()) else {
            continue;
        };
        let name = if first == "crates" && parts.next().is_some() {
            second.to_string()
        } else {
            format!("{first}/")
        };
        if !first.starts_with('.') && !names.contains(&name) {
            names.push(name);
        }
    }
    names.sort();
    Ok(names)
}

/// The names `map` does not mention in backquotes (a folder also as `` `name` ``).
fn missing(map: &str, names: &[String]) -> Vec<String> {
    names
        .iter()
        .filter(|n| {
            let bare = n.trim_end_matches('/');
            !map.contains(&format!("`{n}`")) && !map.contains(&format!("`{bare}`"))
        })
        .cloned()
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn unnamed_folders_are_reported() {
        let map = "| `crates/` | ... | `wavg-mesh` | `web/` |";
        let names = ["crates/", "web/", "docs/", "wavg-mesh", "wavg-bench"].map(String::from);
        assert_eq!(missing(map, &names), ["docs/", "wavg-bench"]);
    }

    #[test]
    fn this_repository_is_mapped() {
        let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("..");
        check(&root).unwrap();
    }
}
