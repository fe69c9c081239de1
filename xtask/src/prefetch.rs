//! What later steps download and install, done beside the first builds: the Debian
//! packages (Blender, Chromium, the C/C++ packages), the test environment's Python
//! packages and the `bpy` environments. On a new machine these take about 3 minutes, much
//! of it waiting on the network and the disk, while the compiler keeps both cores busy.
//! Each step still checks for and makes what it needs itself (one apt-get at a time,
//! `system::apt`; one maker of each environment at a time), so a prefetch that fails
//! only costs time.

use std::fs::File;
use std::path::Path;
use std::thread::JoinHandle;

use crate::system::{apt_to, installed, is_root, runs};
use crate::{blender, cbuild, installed, python, steps, web};

/// The prefetch's thread; dropping it waits for the thread (never leaves apt-get
/// half-way when xtask ends).
pub struct Prefetch(Option<JoinHandle<()>>);

impl Drop for Prefetch {
    fn drop(&mut self) {
        if let Some(t) = self.0.take() {
            let _ = t.join();
        }
    }
}

/// Starts the prefetch: the missing Debian packages with apt-get (output in
/// `target/apt-prefetch.log`) when xtask runs as root on a system with apt-get, then the
/// Python environments.
pub fn start(root: &Path) -> Prefetch {
    let root = root.to_path_buf();
    let mut groups = wanted();
    if !is_root() || !runs("apt-get", &["--version"]) {
        groups.clear();
    }
    let path = steps::target_dir(&root).join("apt-prefetch.log");
    let log = if groups.is_empty() {
        None
    } else {
        File::create(&path).ok()
    };
    if log.is_some() {
        let names: Vec<&str> = groups.iter().flat_map(|(_, p)| p.iter().copied()).collect();
        eprintln!(
            "==> installing {} with apt-get beside the builds (output: {})",
            names.join(" "),
            path.display()
        );
    }
    Prefetch(Some(std::thread::spawn(move || {
        if let Some(log) = log {
            packages(groups, &log);
        }
        let _ = python::ensure_venv(&root);
        installed::prefetch_bpy(&root);
    })))
}

/// Installs each group of packages with its flags.
fn packages(groups: Vec<(&'static [&'static str], Vec<&'static str>)>, log: &File) {
    let t = std::time::Instant::now();
    let mut updated = false;
    for (flags, packages) in groups {
        let mut install = vec!["install", "-y"];
        install.extend(flags);
        install.extend(&packages);
        let mut ok = apt_to(&install, Some(log));
        if !ok && !updated {
            // A new machine may have no package lists yet.
            updated = true;
            ok = apt_to(&["update"], Some(log)) && apt_to(&install, Some(log));
        }
        if !ok {
            eprintln!(
                "    (apt-get beside the builds could not install {packages:?}; the step will try)"
            );
        }
    }
    eprintln!(
        "    (apt-get beside the builds done in {:.1} s)",
        t.elapsed().as_secs_f64()
    );
}

/// The missing packages, each group with the flags its step installs it with.
fn wanted() -> Vec<(&'static [&'static str], Vec<&'static str>)> {
    let no_recommends: &'static [&'static str] = &["--no-install-recommends"];
    let blender: Vec<&str> = (blender::PACKAGES.iter().copied())
        .filter(|p| !installed(p))
        .collect();
    let chromium = if Path::new(web::CHROMIUM).exists() {
        vec![]
    } else {
        vec!["chromium"]
    };
    [
        (no_recommends, cbuild::missing_packages()),
        (&[][..], blender),
        (no_recommends, chromium),
    ]
    .into_iter()
    .filter(|(_, p)| !p.is_empty())
    .collect()
}
