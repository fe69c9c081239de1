//! The tests' own home. Every child of `cargo xtask test` that runs tests in Python,
//! Blender or the browser starts with `HOME`, the XDG folders and Blender's user folders
//! in a fresh temporary folder, wavg's embedding cache in the build's own folder, and no
//! user-level Python settings, so the tests neither read nor change the user's
//! configuration, scripts, add-ons, extensions, caches or browser profile (a developer's
//! own `wavg_blender` add-on would otherwise shadow the one under test).

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::process::Command;
use std::time::SystemTime;

use crate::steps;

/// Python settings a user may have set for their own work (a `PYTHONPATH` with another
/// `wavg`, a startup file, a bytecode cache folder of their own): removed from the
/// children's environment. Python's bytecode then stays beside the sources (a prefix in the
/// sandbox would make every run compile the standard library and NumPy again: 5 s more
/// per Blender start).
const PYTHON_UNSET: &[&str] = &[
    "PYTHONPATH",
    "PYTHONHOME",
    "PYTHONSTARTUP",
    "PYTHONUSERBASE",
    "PYTHONPYCACHEPREFIX",
];

/// A temporary home for one step, removed when dropped.
pub struct Sandbox {
    dir: PathBuf,
    cache: PathBuf,
}

impl Sandbox {
    /// An empty sandbox for the step `name` in the system's temporary folder; wavg's
    /// embedding cache is `test-cache/` of cargo's target directory (kept between runs, as
    /// the Rust tests keep theirs).
    pub fn new(root: &Path, name: &str) -> Result<Self, String> {
        let dir =
            std::env::temp_dir().join(format!("wavg-test-home-{name}-{}", std::process::id()));
        if dir.exists() {
            std::fs::remove_dir_all(&dir).map_err(|e| format!("{}: {e}", dir.display()))?;
        }
        let sandbox = Sandbox {
            dir,
            cache: steps::target_dir(root).join("test-cache"),
        };
        for (_, path) in sandbox.folders() {
            std::fs::create_dir_all(&path).map_err(|e| format!("{}: {e}", path.display()))?;
        }
        Ok(sandbox)
    }

    /// The `HOME` the children see.
    pub fn home(&self) -> PathBuf {
        self.dir.join("home")
    }

    /// Blender's user folder (`BLENDER_USER_RESOURCES`), apart from `HOME`.
    pub fn blender(&self) -> PathBuf {
        self.dir.join("blender")
    }

    /// The variables set to folders of the sandbox (all created by [`Sandbox::new`]): the
    /// home and its XDG folders, Blender's user folders (each `BLENDER_USER_*` variable, as
    /// one already set in the user's environment would override `BLENDER_USER_RESOURCES`;
    /// Blender falls back to the home's folder when the one a variable names does not
    /// exist) and wavg's cache.
    pub fn folders(&self) -> Vec<(&'static str, PathBuf)> {
        let (home, blender) = (self.home(), self.blender());
        vec![
            ("HOME", home.clone()),
            ("XDG_CONFIG_HOME", home.join(".config")),
            ("XDG_CACHE_HOME", home.join(".cache")),
            ("XDG_DATA_HOME", home.join(".local/share")),
            ("XDG_STATE_HOME", home.join(".local/state")),
            ("BLENDER_USER_RESOURCES", blender.clone()),
            ("BLENDER_USER_CONFIG", blender.join("config")),
            ("BLENDER_USER_SCRIPTS", blender.join("scripts")),
            ("BLENDER_USER_DATAFILES", blender.join("datafiles")),
            ("BLENDER_USER_EXTENSIONS", blender.join("extensions")),
            ("WAVG_CACHE_DIR", self.cache.clone()),
        ]
    }

    /// Puts the sandbox's environment on `cmd`: its folders, no user site-packages and
    /// none of the user's Python settings.
    pub fn apply<'a>(&self, cmd: &'a mut Command) -> &'a mut Command {
        for (name, path) in self.folders() {
            cmd.env(name, path);
        }
        for name in PYTHON_UNSET {
            cmd.env_remove(name);
        }
        cmd.env("PYTHONNOUSERSITE", "1")
    }

    /// Runs `program args` from `dir` in the sandbox, with `env` on top; `Err` says how
    /// it ended.
    pub fn run(
        &self,
        dir: &Path,
        program: &str,
        args: &[&str],
        env: &[(&str, &str)],
    ) -> Result<(), String> {
        let mut cmd = Command::new(program);
        self.apply(&mut cmd);
        cmd.args(args).envs(env.iter().copied()).current_dir(dir);
        eprintln!(
            "    (HOME={}) {program} {}",
            self.home().display(),
            args.join(" ")
        );
        steps::run(program, args, &mut cmd)
    }
}

impl Drop for Sandbox {
    fn drop(&mut self) {
        let _ = std::fs::remove_dir_all(&self.dir);
    }
}

/// Every file and folder under `dir` (relative path) with its bytes (empty for a folder),
/// modification time and permissions: two snapshots are equal when nothing under `dir`
/// was written, added, removed or touched.
pub type Snapshot = BTreeMap<PathBuf, (Vec<u8>, Option<SystemTime>, u32)>;

/// The [`Snapshot`] of `dir`.
pub fn snapshot(dir: &Path) -> Result<Snapshot, String> {
    let mut out = Snapshot::new();
    snapshot_into(dir, dir, &mut out)?;
    Ok(out)
}

fn snapshot_into(base: &Path, dir: &Path, out: &mut Snapshot) -> Result<(), String> {
    use std::os::unix::fs::PermissionsExt;
    let err = |p: &Path, e: std::io::Error| format!("{}: {e}", p.display());
    for entry in std::fs::read_dir(dir).map_err(|e| err(dir, e))? {
        let path = entry.map_err(|e| err(dir, e))?.path();
        let meta = std::fs::symlink_metadata(&path).map_err(|e| err(&path, e))?;
        let bytes = if meta.is_file() {
            std::fs::read(&path).map_err(|e| err(&path, e))?
        } else {
            Vec::new()
        };
        let rel = path.strip_prefix(base).unwrap_or(&path).to_path_buf();
        out.insert(
            rel,
            (bytes, meta.modified().ok(), meta.permissions().mode()),
        );
        if meta.is_dir() {
            snapshot_into(base, &path, out)?;
        }
    }
    Ok(())
}

/// The paths in which two snapshots differ (added, removed or changed), sorted.
pub fn differences(before: &Snapshot, after: &Snapshot) -> Vec<PathBuf> {
    let mut paths: Vec<PathBuf> = before
        .iter()
        .filter(|(p, v)| after.get(*p) != Some(*v))
        .map(|(p, _)| p.clone())
        .collect();
    paths.extend(after.keys().filter(|p| !before.contains_key(*p)).cloned());
    paths.sort();
    paths
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_folder_exists_and_python_settings_are_removed() {
        let root = Path::new(env!("CARGO_MANIFEST_DIR")).parent().unwrap();
        let sandbox = Sandbox::new(root, "unit-test").unwrap();
        let home = sandbox.home();
        let mut cmd = Command::new("true");
        cmd.env("PYTHONPATH", "/elsewhere");
        sandbox.apply(&mut cmd);
        let envs: BTreeMap<_, _> = cmd.get_envs().collect();
        for (name, path) in sandbox.folders() {
            assert!(path.is_dir(), "{name}: {}", path.display());
            assert_eq!(envs[std::ffi::OsStr::new(name)], Some(path.as_os_str()));
        }
        assert!(sandbox.blender().starts_with(&sandbox.dir));
        assert!(!sandbox.blender().starts_with(&home));
        for name in PYTHON_UNSET {
            assert_eq!(envs[std::ffi::OsStr::new(name)], None, "{name}");
        }
        let dir = sandbox.dir.clone();
        drop(sandbox);
        assert!(!dir.exists());
    }

    #[test]
    fn snapshots_see_changed_bytes_times_and_new_files() {
        let dir = std::env::temp_dir().join(format!("wavg-xtask-snapshot-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        std::fs::create_dir_all(dir.join("a")).unwrap();
        let file = dir.join("a/f.py");
        std::fs::write(&file, "x = 1\n").unwrap();
        let before = snapshot(&dir).unwrap();
        assert_eq!(before.len(), 2);
        assert!(differences(&before, &snapshot(&dir).unwrap()).is_empty());

        std::fs::write(&file, "x = 2\n").unwrap();
        assert!(differences(&before, &snapshot(&dir).unwrap()).contains(&PathBuf::from("a/f.py")));

        std::fs::write(&file, "x = 1\n").unwrap();
        let old = SystemTime::UNIX_EPOCH + std::time::Duration::from_secs(1_000_000);
        std::fs::File::options()
            .write(true)
            .open(&file)
            .unwrap()
            .set_modified(old)
            .unwrap();
        let touched = snapshot(&dir).unwrap();
        assert_eq!(differences(&before, &touched), [PathBuf::from("a/f.py")]);

        std::fs::write(dir.join("a/g.py"), "").unwrap();
        let added = differences(&touched, &snapshot(&dir).unwrap());
        assert!(added.contains(&PathBuf::from("a/g.py")), "{added:?}");
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
