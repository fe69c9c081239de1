//! The Rust examples step of `cargo xtask test`: runs every example of the facade crate
//! (built by the test step, which compiles examples), then checks that `quickstart.rs`
//! compiles unchanged in a crate outside the workspace that depends only on `wavg` (by
//! path), as a new user's project would (it has just run as an example; `cargo check`
//! reuses the clippy step's dependencies instead of building the library again).

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

/// A crate in `target/outside-quickstart` with `wavg` as its only dependency and the
/// workspace's lock file and dev profile, so it reuses the built dependencies.
fn outside_crate(root: &Path) -> Result<(), String> {
    let dir = root.join("target/outside-quickstart");
    let src = dir.join("src");
    std::fs::create_dir_all(&src).map_err(|e| format!("{}: {e}", src.display()))?;
    let manifest = format!(
        "[package]\nname = \"outside-quickstart\"\nversion = \"0.0.0\"\nedition = \"2024\"\n\
         publish = false\n\n[dependencies]\nwavg = {{ path = {:?} }}\n\n\
         [profile.dev]\nopt-level = 2\ndebug = \"line-tables-only\"\n\n\
         [profile.dev.package.\"*\"]\nopt-level = 3\n\n[workspace]\n",
        root.join("crates/wavg").display().to_string()
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
