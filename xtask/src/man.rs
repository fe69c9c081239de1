//! `cargo xtask man [DIR]`: the man pages of `wavg` (`wavg.1` and one per subcommand) into
//! DIR, `target/man` by default, written by wavg-cli's `man` example from the command
//! line's own definition. xtask itself depends on no workspace crate, so building it
//! builds nothing else.

use std::path::Path;

use crate::steps;

/// Where the pages go without a DIR argument, relative to the workspace root.
const DEFAULT_DIR: &str = "target/man";

/// Builds the example (with the everyday build's feature set) and runs it.
pub fn run(root: &Path, dir: Option<&str>) -> Result<(), String> {
    steps::cargo_build_all(root)?;
    let dir = root.join(dir.unwrap_or(DEFAULT_DIR));
    let exe = steps::target_dir(root).join("debug/examples/man");
    steps::command(root, &exe.to_string_lossy(), &[&dir.to_string_lossy()])
}
