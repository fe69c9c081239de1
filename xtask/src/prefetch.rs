//! The Debian packages later steps need, installed beside the first builds. On a new
//! machine apt-get spends about a minute fetching and unpacking Blender, Chromium and the
//! C/C++ packages, much of it waiting on the network and the disk, while the compiler
//! keeps both cores busy. Each step still checks for and installs what it needs itself
//! (one apt-get at a time, `system::apt`), so a prefetch that fails only costs time.

use std::fs::File;
use std::path::Path;
use std::thread::JoinHandle;

use crate::system::{apt_to, installed, is_root, runs};
use crate::{blender, cbuild, steps, web};

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

/// Starts installing the missing packages with apt-get (output in
/// `target/apt-prefetch.log`) when xtask runs as root on a system with apt-get; else
/// does nothing.
pub fn start(root: &Path) -> Prefetch {
    let groups = wanted();
    if groups.is_empty() || !is_root() || !runs("apt-get", &["--version"]) {
        return Prefetch(None);
    }
    let path = steps::target_dir(root).join("apt-prefetch.log");
    let Ok(log) = File::create(&path) else {
        return Prefetch(None);
    };
    let names: Vec<&str> = groups.iter().flat_map(|(_, p)| p.iter().copied()).collect();
    eprintln!(
        "==> installing {} with apt-get beside the builds (output: {})",
        names.join(" "),
        path.display()
    );
    Prefetch(Some(std::thread::spawn(move || {
        let t = std::time::Instant::now();
        let mut updated = false;
        for (flags, packages) in groups {
            let mut install = vec!["install", "-y"];
            install.extend(flags);
            install.extend(&packages);
            let mut ok = apt_to(&install, Some(&log));
            if !ok && !updated {
                // A new machine may have no package lists yet.
                updated = true;
                ok = apt_to(&["update"], Some(&log)) && apt_to(&install, Some(&log));
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
    })))
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
