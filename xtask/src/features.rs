//! One build of each dependency: cargo compiles a dependency once per set of features (its
//! own and those of everything below it), resolved over the packages one invocation builds.
//! `cargo xtask test` builds the workspace (`cargo build` without `wavg-py`), then maturin
//! builds `wavg-py` alone, the fuzz step `wavg-fuzz` alone and the examples step the
//! quickstart with `wavg` alone; each of these must see every dependency with the
//! workspace's features, or it compiles faer and everything above it again
//! (`crates/wavg-hack` names the features that would differ).
//! `cargo package` verifies each published crate alone, in a target directory of its own:
//! there faer and everything below it must have one feature set across the crates.

use std::collections::{BTreeMap, BTreeSet};
use std::path::Path;
use std::process::Command;

use crate::steps;

/// Each registry package (`name vX.Y.Z`) and the feature sets cargo builds it with (one for
/// the target and one for build scripts and procedural macros, when they differ).
type Features = BTreeMap<String, BTreeSet<String>>;

/// The selections built apart from the workspace with its dependency builds:
/// `wavg-py` (maturin), `wavg-fuzz` (the fuzz step), `wavg` with `wavg-hack` (the
/// quickstart outside the workspace).
const APART: &[&[&str]] = &[
    &["-p", "wavg-py"],
    &["-p", "wavg-fuzz"],
    &["-p", "wavg", "-p", "wavg-hack"],
];

/// Fails naming each dependency whose features differ where they must not.
pub fn check(root: &Path) -> Result<(), String> {
    let workspace = tree(
        root,
        &[
            &["--workspace"],
            steps::EXCLUDED,
            &["-e", "normal,build,dev"],
        ]
        .concat(),
    )?;
    let mut errors = Vec::new();
    // The everyday `cargo build` leaves the Python extension to maturin.
    let built = tree(
        root,
        &[
            &["--workspace"],
            steps::EXCLUDED,
            steps::NOT_BUILT,
            &["-e", "normal,build,dev"],
        ]
        .concat(),
    )?;
    errors.extend(not_within(&built, &workspace, "cargo build (everyday)"));
    for selection in APART {
        let apart = tree(root, &[selection, &["-e", "normal,build"][..]].concat())?;
        errors.extend(not_within(&apart, &workspace, &selection.join(" ")));
    }
    let below_faer: BTreeSet<String> = tree(root, &["-p", "faer", "-e", "normal,build"])?
        .into_keys()
        .collect();
    let mut graphs = Vec::new();
    for name in packaged(root)? {
        let t = tree(root, &["-p", &name, "-e", "normal,build"])?;
        if !t.keys().any(|p| p.starts_with("faer v")) {
            continue;
        }
        let t: Features = t
            .into_iter()
            .filter(|(p, _)| below_faer.contains(p))
            .collect();
        graphs.push((name, t));
    }
    errors.extend(disagreements(&graphs));
    if errors.is_empty() {
        Ok(())
    } else {
        Err(format!(
            "dependencies that would be compiled twice (name the workspace's features in \
             crates/wavg-hack/Cargo.toml, or below faer in a published crate):\n  {}",
            errors.join("\n  ")
        ))
    }
}

/// The crates `cargo package` verifies: those of `crates/` but the unpublished ones.
fn packaged(root: &Path) -> Result<Vec<String>, String> {
    let dir = root.join("crates");
    let mut names = Vec::new();
    for entry in std::fs::read_dir(&dir).map_err(|e| format!("{}: {e}", dir.display()))? {
        let manifest = entry.map_err(|e| e.to_string())?.path().join("Cargo.toml");
        let Ok(text) = std::fs::read_to_string(&manifest) else {
            continue;
        };
        let name = text.lines().find_map(|l| {
            let value = l.strip_prefix("name")?.trim().strip_prefix('=')?.trim();
            Some(value.trim_matches('"').to_string())
        });
        match name {
            Some(n) if !crate::dist::NOT_PACKAGED.contains(&n.as_str()) => names.push(n),
            Some(_) => {}
            None => return Err(format!("{}: no package name", manifest.display())),
        }
    }
    names.sort();
    Ok(names)
}

/// `cargo tree ARGS` of the host, as [`Features`].
fn tree(root: &Path, args: &[&str]) -> Result<Features, String> {
    let out = Command::new("cargo")
        .args(["tree", "--prefix", "none", "-f", "{p}|{f}"])
        .args(args)
        .current_dir(root)
        .output()
        .map_err(|e| format!("cargo tree: {e}"))?;
    if !out.status.success() {
        return Err(format!(
            "cargo tree {}: {}",
            args.join(" "),
            String::from_utf8_lossy(&out.stderr)
        ));
    }
    Ok(parse(&String::from_utf8_lossy(&out.stdout)))
}

/// Parses `{p}|{f}` lines; the workspace's own packages (`name vX (/path)`) are left out.
fn parse(text: &str) -> Features {
    let mut features = Features::new();
    for line in text.lines() {
        let Some((package, set)) = line.split_once('|') else {
            continue;
        };
        if package.contains(" (/") {
            continue;
        }
        let package = package.trim_end_matches(" (proc-macro)").trim();
        let set = set.trim_end_matches(" (*)").trim();
        features
            .entry(package.to_string())
            .or_default()
            .insert(set.to_string());
    }
    features
}

/// The packages of `apart` built with a feature set the workspace's build lacks.
fn not_within(apart: &Features, workspace: &Features, name: &str) -> Vec<String> {
    let mut errors = Vec::new();
    for (package, sets) in apart {
        let theirs = workspace.get(package);
        for set in sets {
            if !theirs.is_some_and(|t| t.contains(set)) {
                errors.push(format!(
                    "{package} [{set}] in `{name}`; the workspace has {:?}",
                    theirs
                        .map(|t| t.iter().collect::<Vec<_>>())
                        .unwrap_or_default()
                ));
            }
        }
    }
    errors
}

/// The packages whose feature sets differ between two of `graphs` that both have them.
fn disagreements(graphs: &[(String, Features)]) -> Vec<String> {
    let mut errors = Vec::new();
    let Some((first, rest)) = graphs.split_first() else {
        return errors;
    };
    let mut seen: BTreeMap<&String, (&String, &BTreeSet<String>)> = BTreeMap::new();
    for (package, sets) in &first.1 {
        seen.insert(package, (&first.0, sets));
    }
    for (name, graph) in rest {
        for (package, sets) in graph {
            match seen.get(package) {
                Some((other, theirs)) if *theirs != sets => errors.push(format!(
                    "{package}: {:?} in package `{name}`, {:?} in `{other}`",
                    sets.iter().collect::<Vec<_>>(),
                    theirs.iter().collect::<Vec<_>>()
                )),
                Some(_) => {}
                None => {
                    seen.insert(package, (name, sets));
                }
            }
        }
    }
    errors
}

#[cfg(test)]
mod tests {
    use super::*;

    fn features(text: &str) -> Features {
        parse(text)
    }

    #[test]
    fn tree_lines_are_read() {
        let f = features(
            "libc v0.2.1|default,std\nlibc v0.2.1|default,extra_traits,std (*)\n\
             syn v3.0.9 (proc-macro)|full\nwavg-mesh v0.1.0 (/w/crates/wavg-mesh)|serde\n\
             cfg-if v1.0.5|\n",
        );
        assert_eq!(f.len(), 3, "{f:?}");
        assert_eq!(f["libc v0.2.1"].len(), 2);
        assert!(f["syn v3.0.9"].contains("full"));
        assert!(f["cfg-if v1.0.5"].contains(""));
    }

    #[test]
    fn a_feature_set_the_workspace_lacks_is_named() {
        let workspace = features("libc v1|default,extra_traits,std\nnum v1|default,std\n");
        let apart = features("libc v1|default,std\nnum v1|default,std\n");
        let errors = not_within(&apart, &workspace, "-p x");
        assert_eq!(errors.len(), 1, "{errors:?}");
        assert!(errors[0].starts_with("libc v1 [default,std] in `-p x`"));
        assert!(not_within(&workspace, &workspace, "-p x").is_empty());
    }

    #[test]
    fn packaged_crates_disagreeing_below_faer_are_named() {
        let a = ("a".to_string(), features("pulp v1|std\nfaer v1|std\n"));
        let b = (
            "b".to_string(),
            features("pulp v1|relaxed,std\nfaer v1|std\n"),
        );
        let c = ("c".to_string(), features("faer v1|std\n"));
        let errors = disagreements(&[a.clone(), b, c.clone()]);
        assert_eq!(errors.len(), 1, "{errors:?}");
        assert!(errors[0].starts_with("pulp v1"));
        assert!(disagreements(&[a, c]).is_empty());
    }

    #[test]
    fn this_workspace_builds_each_dependency_once() {
        let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("..");
        check(&root).unwrap();
    }
}
