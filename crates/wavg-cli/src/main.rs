//! The `wavg` binary; the command line itself is the `wavg_cli` library.

#![forbid(unsafe_code)]

fn main() -> std::process::ExitCode {
    wavg_cli::main()
}
