//! One argument style: every command that works on one mesh takes it positionally and as
//! `--mesh`, with the same result.

use crate::common;

use common::{s, wavg, wavg_ok};

/// Every subcommand (at any depth) with a positional `MESH` also has `--mesh`, and the
/// other way round.
#[test]
fn every_mesh_command_has_both_spellings() {
    fn walk(cmd: &clap::Command, path: &str, seen: &mut usize) {
        let positional = cmd
            .get_positionals()
            .any(|a| a.get_value_names().is_some_and(|v| v[0] == "MESH"));
        let flag = cmd.get_arguments().any(|a| a.get_long() == Some("mesh"));
        assert_eq!(
            positional, flag,
            "{path}: MESH positional {positional}, --mesh {flag}"
        );
        *seen += usize::from(positional);
        for sub in cmd.get_subcommands() {
            walk(sub, &format!("{path} {}", sub.get_name()), seen);
        }
    }
    let mut seen = 0;
    walk(&wavg_cli::command(), "wavg", &mut seen);
    assert!(seen >= 14, "only {seen} commands take a mesh");
}

#[test]
fn render_and_spline_accept_the_mesh_either_way() {
    let dir = tempfile::tempdir().unwrap();
    let a = s(&dir.path().join("a.png"));
    let b = s(&dir.path().join("b.png"));
    wavg_ok(&["render", "builtin:icosphere", "-o", &a, "--size", "64x48"]);
    wavg_ok(&[
        "render",
        "--mesh",
        "builtin:icosphere",
        "-o",
        &b,
        "--size",
        "64x48",
    ]);
    assert_eq!(std::fs::read(&a).unwrap(), std::fs::read(&b).unwrap());
    let out = wavg(&[
        "render",
        "builtin:icosphere",
        "--mesh",
        "builtin:torus",
        "-o",
        &a,
    ]);
    assert_eq!(
        out.status.code(),
        Some(2),
        "both spellings at once is a usage error"
    );
    let info = wavg_ok(&["info", "--mesh", "builtin:torus", "--json"]);
    assert!(String::from_utf8_lossy(&info.stdout).contains("\"genus\":1"));
}
