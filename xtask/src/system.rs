//! Questions to the host system and Debian package installs, shared by the steps that
//! need system packages (the C/C++ build, Blender, the browser tests).

use std::process::Command;
use std::sync::Mutex;

/// Whether `program args` starts and exits with success.
pub fn runs(program: &str, args: &[&str]) -> bool {
    Command::new(program)
        .args(args)
        .output()
        .is_ok_and(|o| o.status.success())
}

/// Whether Debian `package` is installed (`dpkg -s` also succeeds for removed but
/// configured packages, so the status line must end in "installed").
pub fn installed(package: &str) -> bool {
    Command::new("dpkg-query")
        .args(["-W", "-f=${Status}", package])
        .output()
        .is_ok_and(|o| {
            o.status.success() && String::from_utf8_lossy(&o.stdout).ends_with(" installed")
        })
}

/// Whether xtask runs as root (so it may install packages itself).
pub fn is_root() -> bool {
    Command::new("id")
        .arg("-u")
        .output()
        .is_ok_and(|o| String::from_utf8_lossy(&o.stdout).trim() == "0")
}

/// One apt-get at a time in this process: the prefetch (`prefetch.rs`) runs beside the
/// steps, and a second apt-get would fail on dpkg's lock.
static APT: Mutex<()> = Mutex::new(());

/// Runs `apt-get args` non-interactively, its output in this process's; whether it
/// succeeded.
pub fn apt(args: &[&str]) -> bool {
    apt_to(args, None)
}

/// [`apt`] with its output appended to `log` when given.
pub fn apt_to(args: &[&str], log: Option<&std::fs::File>) -> bool {
    let _one = APT.lock().unwrap_or_else(|e| e.into_inner());
    let mut cmd = Command::new("apt-get");
    cmd.args(args).env("DEBIAN_FRONTEND", "noninteractive");
    if let Some(f) = log {
        let (Ok(out), Ok(err)) = (f.try_clone(), f.try_clone()) else {
            return false;
        };
        cmd.stdout(out).stderr(err);
    }
    cmd.status().is_ok_and(|s| s.success())
}
