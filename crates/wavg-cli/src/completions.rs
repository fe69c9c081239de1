//! `wavg completions SHELL`: the shell completion script, generated from the command's own
//! definition so it always lists the current subcommands and options.

use std::io::Write;

use clap::Parser;
use clap_complete::Shell;

use crate::CliError;

/// Arguments of `wavg completions`.
#[derive(Parser)]
#[command(
    after_long_help = "Prints a completion script for bash, zsh or fish to standard \
    output, generated from the command's own definition."
)]
pub struct Args {
    /// The shell to complete in.
    #[arg(value_enum)]
    shell: CompletionShell,
}

/// The shells `wavg completions` writes scripts for.
#[derive(Clone, Copy, clap::ValueEnum)]
enum CompletionShell {
    Bash,
    Zsh,
    Fish,
}

/// Writes the script for `args.shell` to standard output.
pub fn run(args: Args) -> Result<(), CliError> {
    let shell = match args.shell {
        CompletionShell::Bash => Shell::Bash,
        CompletionShell::Zsh => Shell::Zsh,
        CompletionShell::Fish => Shell::Fish,
    };
    let mut out = Vec::new();
    clap_complete::generate(shell, &mut crate::command(), "wavg", &mut out);
    std::io::stdout()
        .write_all(&out)
        .map_err(|e| CliError::failure(format!("writing the completion script: {e}")))
}
