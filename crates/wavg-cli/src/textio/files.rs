//! Reading input files, output files written atomically (or to stdout), and errors that
//! name `file:line`.

use std::fmt;
use std::io::Write;
use std::path::Path;

use crate::CliError;

use super::PointSpec;

/// Reads a whole text file of points or numbers, mapping failures to exit status 2: UTF-8
/// outside `#` comments, which may hold any bytes (`wavg::text::decode`); a UTF-8 byte
/// order mark opening it (some editors write one) is dropped.
pub fn read_text(path: &Path) -> Result<String, CliError> {
    let bytes =
        std::fs::read(path).map_err(|e| CliError::input(format!("{}: {e}", path.display())))?;
    let mut text = wavg::text::decode(bytes, 1).map_err(|e| located(path, e.line, &e.message))?;
    if text.starts_with('\u{feff}') {
        text.drain(..'\u{feff}'.len_utf8());
    }
    Ok(text)
}

/// Writes `body`'s output to `path` atomically (`wavg::mesh::io::write_atomic`: a
/// temporary file in the same folder, renamed on success) or to stdout when `path` is `-`. On any error nothing is left at `path`.
pub fn write_atomic(
    path: &Path,
    body: impl FnOnce(&mut dyn Write) -> std::io::Result<()>,
) -> Result<(), CliError> {
    let fail = |e: &dyn fmt::Display| CliError::failure(format!("{}: {e}", path.display()));
    if path == Path::new("-") {
        let stdout = std::io::stdout();
        let mut w = std::io::BufWriter::new(stdout.lock());
        // A reader that stopped early (`wavg ... -o - | head`) is not a failure.
        body(&mut w)
            .and_then(|()| w.flush())
            .map_err(|e| match e.kind() {
                std::io::ErrorKind::BrokenPipe => CliError::quiet(),
                _ => fail(&e),
            })?;
        return Ok(());
    }
    wavg::mesh::io::write_atomic(path, body).map_err(|e| fail(&e))
}

/// An input error at `file:line` (exit status 2).
pub fn located(file: &Path, line: usize, msg: &dyn fmt::Display) -> CliError {
    CliError::input(format!("{}:{line}: {msg}", file.display()))
}

/// Reads and parses a point file, mapping errors to `file:line` input errors.
pub fn read_points(file: &Path) -> Result<Vec<(usize, PointSpec)>, CliError> {
    wavg::text::parse_points(&read_text(file)?, 1).map_err(|e| located(file, e.line, &e.message))
}

/// Writes numbers separated by single spaces.
pub fn write_numbers(w: &mut dyn Write, xs: impl IntoIterator<Item = f64>) -> std::io::Result<()> {
    let mut buf = Vec::new();
    wavg::text::push_numbers(&mut buf, xs);
    w.write_all(&buf)
}
