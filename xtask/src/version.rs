//! One version: `[workspace.package] version` in the root `Cargo.toml` is the version of
//! every crate, of the wheel (maturin reads it: `dynamic = ["version"]`), of `wavg
//! --version`, `wavg.__version__`, `wavg_version()` and the CMake project (read from
//! `Cargo.toml`). The few files that must spell it out for their readers (the C header's
//! macros and the constants they come from, the Blender manifest and `bl_info`, the path
//! dependencies `cargo package` needs, the changelog) are checked here.

use std::path::Path;

/// The workspace version, `X.Y.Z`, from the root `Cargo.toml`.
pub fn workspace(root: &Path) -> Result<String, String> {
    let text = read(root, "Cargo.toml")?;
    section_value(&text, "[workspace.package]", "version")
        .ok_or_else(|| "Cargo.toml: no `version` under [workspace.package]".to_string())
}

/// Fails naming every file whose version differs from the workspace's.
pub fn check(root: &Path) -> Result<(), String> {
    let version = workspace(root)?;
    let mut wrong = Vec::new();
    for (file, found) in spelled(root, &version)? {
        match found {
            Some(v) if v == version => {}
            Some(v) => wrong.push(format!("{file} says {v}")),
            None => wrong.push(format!("{file} does not say it")),
        }
    }
    if wrong.is_empty() {
        Ok(())
    } else {
        Err(format!(
            "the workspace version is {version} (Cargo.toml, [workspace.package]), but: {}",
            wrong.join("; ")
        ))
    }
}

/// Each file that spells the version, with the version it spells (`None`: not found or not
/// in the expected form).
fn spelled(root: &Path, version: &str) -> Result<Vec<(String, Option<String>)>, String> {
    let mut out = Vec::new();
    let manifest = "blender/wavg_blender/blender_manifest.toml";
    out.push((
        manifest.to_string(),
        top_value(&read(root, manifest)?, "version"),
    ));
    let init = "blender/wavg_blender/__init__.py";
    out.push((
        format!("{init} (bl_info)"),
        bl_info_version(&read(root, init)?),
    ));
    let lib = "crates/wavg-ffi/src/lib.rs";
    out.push((lib.to_string(), ffi_constants(&read(root, lib)?)));
    let header = "include/wavg.h";
    out.push((header.to_string(), header_macros(&read(root, header)?)));
    let cargo = read(root, "Cargo.toml")?;
    for (name, v) in path_dependency_versions(&cargo) {
        out.push((format!("Cargo.toml ([workspace.dependencies] {name})"), v));
    }
    let changelog = "CHANGELOG.md";
    let has_entry = read(root, changelog)?.contains(&format!("## [{version}]"));
    out.push((
        format!("{changelog} (a `## [{version}]` entry)"),
        has_entry.then(|| version.to_string()),
    ));
    let pyproject = "python/pyproject.toml";
    let py = read(root, pyproject)?;
    let dynamic = section_value(&py, "[project]", "version").is_none()
        && py.contains("dynamic = [\"version\"]");
    out.push((
        format!("{pyproject} (`dynamic = [\"version\"]`, none of its own)"),
        dynamic.then(|| version.to_string()),
    ));
    Ok(out)
}

fn read(root: &Path, file: &str) -> Result<String, String> {
    std::fs::read_to_string(root.join(file)).map_err(|e| format!("{file}: {e}"))
}

/// The string value of `key = "..."` on its own line within `section` of a TOML text.
fn section_value(text: &str, section: &str, key: &str) -> Option<String> {
    let mut inside = false;
    for line in text.lines() {
        let t = line.trim();
        if t.starts_with('[') {
            inside = t == section;
        } else if inside && let Some(v) = string_value(t, key) {
            return Some(v);
        }
    }
    None
}

/// The string value of `key = "..."` before the first table of a TOML text.
fn top_value(text: &str, key: &str) -> Option<String> {
    text.lines()
        .map(str::trim)
        .take_while(|t| !t.starts_with('['))
        .find_map(|t| string_value(t, key))
}

/// `"v"` of a line `key = "v"`.
fn string_value(line: &str, key: &str) -> Option<String> {
    let rest = line
        .strip_prefix(key)?
        .trim_start()
        .strip_prefix('=')?
        .trim();
    Some(rest.strip_prefix('"')?.split('"').next()?.to_string())
}

/// `bl_info`'s `"version": (X, Y, Z)` as `X.Y.Z`.
fn bl_info_version(text: &str) -> Option<String> {
    let start = text.find("bl_info")?;
    let rest = &text[start..];
    let tuple = rest[rest.find("\"version\"")?..].split_once('(')?.1;
    let inner = tuple.split_once(')')?.0;
    let parts: Vec<&str> = inner.split(',').map(str::trim).collect();
    Some(parts.join("."))
}

/// `WAVG_VERSION_MAJOR`/`_MINOR`/`_PATCH` of the C ABI crate's constants as `X.Y.Z`.
fn ffi_constants(text: &str) -> Option<String> {
    numbers(text, |name| format!("pub const {name}: u32 = "), ";")
}

/// The header's `#define WAVG_VERSION_MAJOR X` (and minor, patch) as `X.Y.Z`.
fn header_macros(text: &str) -> Option<String> {
    numbers(text, |name| format!("#define {name} "), "\n")
}

/// The three version numbers, each found after `prefix(name)` up to `end`, joined by dots.
fn numbers(text: &str, prefix: impl Fn(&str) -> String, end: &str) -> Option<String> {
    let mut parts = Vec::new();
    for name in [
        "WAVG_VERSION_MAJOR",
        "WAVG_VERSION_MINOR",
        "WAVG_VERSION_PATCH",
    ] {
        let p = prefix(name);
        let rest = &text[text.find(&p)? + p.len()..];
        parts.push(rest.split(end).next()?.trim().to_string());
    }
    Some(parts.join("."))
}

/// The `version` of each `name = { path = ..., version = ... }` of
/// `[workspace.dependencies]` (`None` for one without a version; wavg-testdata, a
/// dev-dependency only, is left out).
fn path_dependency_versions(cargo: &str) -> Vec<(String, Option<String>)> {
    let mut inside = false;
    let mut out = Vec::new();
    for line in cargo.lines().map(str::trim) {
        if line.starts_with('[') {
            inside = line == "[workspace.dependencies]";
            continue;
        }
        if !inside || !line.contains("path = ") {
            continue;
        }
        let Some((name, rest)) = line.split_once('=') else {
            continue;
        };
        let name = name.trim();
        if name == "wavg-testdata" {
            continue;
        }
        let version = rest
            .split(',')
            .find_map(|part| string_value(part.trim().trim_start_matches('{').trim(), "version"));
        out.push((name.to_string(), version));
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    fn root() -> std::path::PathBuf {
        Path::new(env!("CARGO_MANIFEST_DIR"))
            .parent()
            .expect("workspace")
            .to_path_buf()
    }

    #[test]
    fn the_repository_has_one_version() {
        let v = workspace(&root()).unwrap();
        assert_eq!(v, env!("CARGO_PKG_VERSION"));
        check(&root()).unwrap();
    }

    #[test]
    fn each_spelling_is_read() {
        let manifest = "schema_version = \"1.0.0\"\nid = \"x\"\nversion = \"0.2.1\"\n[permissions]\nversion = \"9\"\n";
        assert_eq!(top_value(manifest, "version").as_deref(), Some("0.2.1"));
        let init = "bl_info = {\n  \"name\": \"w\",\n  \"version\": (0, 2, 1),\n  \"blender\": (3, 4, 0),\n}\n";
        assert_eq!(bl_info_version(init).as_deref(), Some("0.2.1"));
        let lib = "pub const WAVG_VERSION_MAJOR: u32 = 0;\npub const WAVG_VERSION_MINOR: u32 = 2;\npub const WAVG_VERSION_PATCH: u32 = 1;\n";
        assert_eq!(ffi_constants(lib).as_deref(), Some("0.2.1"));
        let header = "#define WAVG_VERSION_MAJOR 0\n\n#define WAVG_VERSION_MINOR 2\n#define WAVG_VERSION_PATCH 1\n";
        assert_eq!(header_macros(header).as_deref(), Some("0.2.1"));
        let cargo = "[workspace.package]\nversion = \"0.2.1\"\n[workspace.dependencies]\n\
                     a = { path = \"crates/a\", version = \"0.2.0\" }\nb = { path = \"crates/b\" }\n\
                     wavg-testdata = { path = \"t\" }\nc = \"1\"\n";
        assert_eq!(
            section_value(cargo, "[workspace.package]", "version").as_deref(),
            Some("0.2.1")
        );
        assert_eq!(
            path_dependency_versions(cargo),
            vec![
                ("a".to_string(), Some("0.2.0".to_string())),
                ("b".to_string(), None)
            ]
        );
    }

    #[test]
    fn a_different_version_is_named() {
        let dir = tempdir();
        copy_tree(&root(), &dir);
        let manifest = dir.join("blender/wavg_blender/blender_manifest.toml");
        let text = std::fs::read_to_string(&manifest).unwrap();
        let v = workspace(&dir).unwrap();
        std::fs::write(
            &manifest,
            text.replacen(&format!("version = \"{v}\""), "version = \"9.9.9\"", 1),
        )
        .unwrap();
        let err = check(&dir).unwrap_err();
        assert!(err.contains("blender_manifest.toml says 9.9.9"), "{err}");
        assert!(!err.contains("bl_info"), "{err}");
        std::fs::remove_dir_all(&dir).unwrap();
    }

    fn tempdir() -> std::path::PathBuf {
        let dir = std::env::temp_dir().join(format!("wavg-version-test-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        std::fs::create_dir_all(&dir).unwrap();
        dir
    }

    /// Copies the files [`check`] reads.
    fn copy_tree(from: &Path, to: &Path) {
        for file in [
            "Cargo.toml",
            "CHANGELOG.md",
            "blender/wavg_blender/blender_manifest.toml",
            "blender/wavg_blender/__init__.py",
            "crates/wavg-ffi/src/lib.rs",
            "include/wavg.h",
            "python/pyproject.toml",
        ] {
            let dest = to.join(file);
            std::fs::create_dir_all(dest.parent().unwrap()).unwrap();
            std::fs::copy(from.join(file), dest).unwrap();
        }
    }
}
