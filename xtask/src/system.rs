//! Questions to the host system and Debian package installs, shared by the steps that
//! need system packages (the C/C++ build, Blender, the browser tests).

use std::process::Command;

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

/// Runs `apt-get args` non-interactively; whether it succeeded.
pub fn apt(args: &[&str]) -> bool {
    Command::new("apt-get")
        .args(args)
        .env("DEBIAN_FRONTEND", "noninteractive")
        .status()
        .is_ok_and(|s| s.success())
}
