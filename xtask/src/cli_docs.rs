//! `cargo xtask cli-docs`: writes `docs/cli.md` from the command line's own definition
//! (every command's full help text and its examples) through wavg-cli's `cli_docs`
//! example; run it after changing a command's arguments, help or examples.

use std::path::Path;

use crate::steps;

/// Builds the example (with the everyday build's feature set) and runs it.
pub fn run(root: &Path) -> Result<(), String> {
    steps::cargo_build_all(root)?;
    let exe = steps::target_dir(root).join("debug/examples/cli_docs");
    let file = root.join("docs/cli.md");
    steps::command(root, &exe.to_string_lossy(), &[&file.to_string_lossy()])
}
