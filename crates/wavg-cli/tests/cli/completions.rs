//! `wavg completions SHELL` prints a completion script naming the subcommands.

use crate::common;

use common::{wavg, wavg_ok};

#[test]
fn every_shell_gets_a_script_naming_the_subcommands() {
    for shell in ["bash", "zsh", "fish"] {
        let out = wavg_ok(&["completions", shell]);
        let script = String::from_utf8(out.stdout).expect("UTF-8 script");
        assert!(script.len() > 1000, "{shell}: {script}");
        for word in ["precompute", "transfer-texture", "roundtrip", "embedding"] {
            assert!(script.contains(word), "{shell} script lacks {word}");
        }
    }
}

#[test]
fn an_unknown_shell_is_a_usage_error() {
    let out = wavg(&["completions", "tcsh"]);
    assert_eq!(out.status.code(), Some(2));
    assert!(out.stdout.is_empty());
}
