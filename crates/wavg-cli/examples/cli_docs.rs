//! Writes `docs/cli.md` from the command definitions into FILE (default `docs/cli.md`):
//! `cargo run -p wavg-cli --example cli_docs -- FILE`, or `cargo xtask cli-docs`.

use std::path::PathBuf;
use std::process::ExitCode;

fn main() -> ExitCode {
    let path = std::env::args_os()
        .nth(1)
        .map_or_else(|| PathBuf::from(wavg_cli::cli_docs::PATH), PathBuf::from);
    match std::fs::write(&path, wavg_cli::cli_docs::markdown()) {
        Ok(()) => {
            println!("{}", path.display());
            ExitCode::SUCCESS
        }
        Err(e) => {
            eprintln!("cli_docs: writing {}: {e}", path.display());
            ExitCode::FAILURE
        }
    }
}
