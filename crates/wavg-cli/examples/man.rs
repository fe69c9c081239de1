//! Writes the man pages of `wavg` into DIR (default `target/man`) and lists them:
//! `cargo run -p wavg-cli --example man -- DIR`, or `cargo xtask man [DIR]`.

use std::path::PathBuf;
use std::process::ExitCode;

fn main() -> ExitCode {
    let dir = std::env::args_os()
        .nth(1)
        .map_or_else(|| PathBuf::from("target/man"), PathBuf::from);
    match wavg_cli::man::write_pages(&dir) {
        Ok(pages) => {
            for page in pages {
                println!("{}", page.display());
            }
            ExitCode::SUCCESS
        }
        Err(msg) => {
            eprintln!("man: {msg}");
            ExitCode::FAILURE
        }
    }
}
