//! `wavg bench roundtrip` (not yet implemented).

use crate::CliError;

/// Arguments.
#[derive(clap::Args)]
pub struct Args {}

/// Runs the command.
pub fn run(_args: Args) -> Result<(), CliError> {
    Err(CliError::failure("not implemented yet"))
}
