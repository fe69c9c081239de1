//! The Rust examples step of `cargo xtask test`: runs every example of the facade crate
//! (built by the test step, which compiles examples), then checks that `quickstart.rs`
//! compiles unchanged in a crate outside the workspace that depends only on `wavg` (by
//! path), as a new user's project would (it has just run as an example). Its `cargo check`
//! reuses the clippy step's dependencies: the crate also depends on `wavg-hack` (no code, so
//! nothing the quickstart could use) for the workspace's dependency features, and has the
//! workspace's dev profiles.

use std::path::Path;
use std::process::Command;

/// Runs the examples; `Err` names the first failure.
pub fn run(root: &Path) -> Result<(), String> {
    let dir = root.join("crates/wavg/examples");
    let mut names: Vec<String> = std::fs::read_dir(&dir)
        .map_err(|e| format!("{}: {e}", dir.display()))?
        .filter_map(|e| e.ok())
        .filter_map(|e| {
            let name = e.file_name().to_string_lossy().into_owned();
            name.strip_suffix(".rs").map(str::to_owned)
        })
        .collect();
    names.sort();
    let bin_dir = crate::steps::target_dir(root).join("debug/examples");
    for name in &names {
        let exe = bin_dir.join(name);
        eprintln!("    {}", exe.display());
        let ok = Command::new(&exe)
            .current_dir(root)
            .status()
            .is_ok_and(|s| s.success());
        if !ok {
            return Err(format!(
                "example {name} failed (or was not built: `cargo test --workspace` builds it)"
            ));
        }
    }
    outside_crate(root)
}

/// A crate in `target/outside-quickstart` with `wavg` as its only dependency to use (and
/// `wavg-hack`), the workspace's lock file and dev profiles, so it reuses the built
/// dependencies.
fn outside_crate(root: &Path) -> Result<(), String> {
    let dir = root.join("target/outside-quickstart");
    let src = dir.join("src");
    std::fs::create_dir_all(&src).map_err(|e| format!("{}: {e}", src.display()))?;
    let workspace =
        std::fs::read_to_string(root.join("Cargo.toml")).map_err(|e| format!("Cargo.toml: {e}"))?;
    let crate_path = |name: &str| root.join("crates").join(name).display().to_string();
    let manifest = format!(
        "[package]\nname = \"outside-quickstart\"\nversion = \"0.0.0\"\nedition = \"2024\"\n\
         publish = false\n\n[dependencies]\nwavg = {{ path = {:?} }}\nwavg-hack = {{ path = {:?} }}\n\n\
         {}[workspace]\n",
        crate_path("wavg"),
        crate_path("wavg-hack"),
        dev_profiles(&workspace)
    );
    let write = |name: &Path, body: &[u8]| {
        std::fs::write(name, body).map_err(|e| format!("{}: {e}", name.display()))
    };
    write(&dir.join("Cargo.toml"), manifest.as_bytes())?;
    let lock = std::fs::read(root.join("Cargo.lock")).map_err(|e| format!("Cargo.lock: {e}"))?;
    write(&dir.join("Cargo.lock"), &lock)?;
    let quickstart = std::fs::read(root.join("crates/wavg/examples/quickstart.rs"))
        .map_err(|e| format!("quickstart.rs: {e}"))?;
    write(&src.join("main.rs"), &quickstart)?;
    eprintln!("==> quickstart.rs as a crate outside the workspace");
    let ok = Command::new("cargo")
        .args(["check", "--quiet"])
        .current_dir(&dir)
        .env("CARGO_TARGET_DIR", crate::steps::target_dir(root))
        .status()
        .is_ok_and(|s| s.success());
    if ok {
        Ok(())
    } else {
        Err("quickstart.rs does not compile in a crate outside the workspace".into())
    }
}

/// The `[profile.dev...]` sections of a workspace manifest, verbatim (comments included).
fn dev_profiles(manifest: &str) -> String {
    let mut out = String::new();
    let mut inside = false;
    for line in manifest.lines() {
        if line.starts_with('[') {
            inside = line.starts_with("[profile.dev]") || line.starts_with("[profile.dev.");
        }
        if inside {
            out.push_str(line);
            out.push('\n');
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_dev_profiles_are_copied_and_nothing_else() {
        let manifest = "[workspace]\nmembers = []\n\n[profile.dev]\nopt-level = 2\n\n\
                        [profile.dev.package.\"*\"]\nopt-level = 3\n\n\
                        [profile.dev.build-override]\ndebug = 1\n\n[profile.release]\ndebug = 0\n\n\
                        [profile.development]\nopt-level = 1\n";
        assert_eq!(
            dev_profiles(manifest),
            "[profile.dev]\nopt-level = 2\n\n[profile.dev.package.\"*\"]\nopt-level = 3\n\n\
             [profile.dev.build-override]\ndebug = 1\n\n"
        );
    }

    #[test]
    fn the_workspace_has_its_dev_profiles() {
        let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("..");
        let profiles = dev_profiles(&std::fs::read_to_string(root.join("Cargo.toml")).unwrap());
        assert!(profiles.contains("[profile.dev]\n"), "{profiles}");
        assert!(
            profiles.contains("[profile.dev.build-override]\n"),
            "{profiles}"
        );
    }
}
