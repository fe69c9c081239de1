//! `wavg --version` prints the workspace version (`[workspace.package]` of the root
//! `Cargo.toml`, the one place it is written).

use crate::common;

use common::wavg;

#[test]
fn version_is_the_workspaces() {
    let cargo = std::fs::read_to_string(concat!(env!("CARGO_MANIFEST_DIR"), "/../../Cargo.toml"))
        .expect("the workspace's Cargo.toml");
    let section = &cargo[cargo
        .find("[workspace.package]")
        .expect("[workspace.package]")..];
    let line = section
        .lines()
        .find(|l| l.starts_with("version = "))
        .expect("a version line");
    let version = line.trim_start_matches("version = ").trim_matches('"');
    let out = wavg(&["--version"]);
    assert!(out.status.success());
    assert_eq!(
        String::from_utf8_lossy(&out.stdout),
        format!("wavg {version}\n")
    );
}
