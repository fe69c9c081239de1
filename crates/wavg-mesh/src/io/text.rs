//! Shared pieces of the text parsers: located errors, numbered lines read from a
//! [`Source`], number parsing.

use std::io::Read;

use super::source::Source;

/// A parse failure at a 1-based line (0 when there is no line, e.g. binary data).
#[derive(Debug)]
pub(crate) struct ParseError {
    pub line: usize,
    pub message: String,
    /// The read that failed, when the bytes could not be had at all.
    pub io: Option<std::io::Error>,
}

impl ParseError {
    pub(crate) fn new(line: usize, message: impl Into<String>) -> Self {
        Self {
            line,
            message: message.into(),
            io: None,
        }
    }

    /// A failed read at `line` (its message also names the cause: gzip data, a disk).
    pub(crate) fn io(line: usize, e: std::io::Error) -> Self {
        Self {
            line,
            message: e.to_string(),
            io: Some(e),
        }
    }
}

pub(crate) type Result<T> = std::result::Result<T, ParseError>;

/// The lines of a text file, numbered from 1, checked to be UTF-8 outside `#` comments (a
/// byte-order mark at the start is dropped, as it would otherwise hide the first
/// statement).
pub(crate) struct TextLines<'a, R> {
    src: &'a mut Source<R>,
    /// The number of the line last returned.
    pub last: usize,
}

impl<'a, R: Read> TextLines<'a, R> {
    pub(crate) fn new(src: &'a mut Source<R>) -> Self {
        Self { src, last: 0 }
    }

    /// The next line and its number, `None` at the end.
    pub(crate) fn next_line(&mut self) -> Result<Option<(usize, &str)>> {
        let n = self.last + 1;
        let Some(mut bytes) = self.src.line().map_err(|e| ParseError::io(n, e))? else {
            return Ok(None);
        };
        self.last = n;
        if n == 1 {
            bytes = bytes.strip_prefix("\u{feff}".as_bytes()).unwrap_or(bytes);
        }
        let text = decode(bytes)
            .ok_or_else(|| ParseError::new(n, "invalid UTF-8 (binary data in a text format?)"))?;
        Ok(Some((n, text)))
    }

    /// The line [`Self::next_line`] returned last.
    pub(crate) fn current(&self) -> &str {
        let bytes = self.src.last_line();
        let bytes = match self.last {
            1 => bytes.strip_prefix("\u{feff}".as_bytes()).unwrap_or(bytes),
            _ => bytes,
        };
        decode(bytes).unwrap_or_default()
    }
}

/// A line as text: UTF-8, or, when only a `#` comment holds other bytes (a Latin-1 name
/// in an exporter's comment), the line up to and including its `#` (comments are skipped
/// whatever their bytes).
fn decode(bytes: &[u8]) -> Option<&str> {
    std::str::from_utf8(bytes).ok().or_else(|| {
        let hash = bytes.iter().position(|&b| b == b'#')?;
        std::str::from_utf8(&bytes[..=hash]).ok()
    })
}

/// A float token; `nan`/`inf` are accepted (validation reports them, they are data).
pub(crate) fn float(tok: &str, line: usize, what: &str) -> Result<f64> {
    tok.parse::<f64>()
        .map_err(|_| ParseError::new(line, format!("{what}: {tok:?} is not a number")))
}

/// The next float of a line, or an error saying what was expected.
pub(crate) fn next_float<'a>(
    it: &mut impl Iterator<Item = &'a str>,
    line: usize,
    what: &str,
) -> Result<f64> {
    match it.next() {
        Some(tok) => float(tok, line, what),
        None => Err(ParseError::new(line, format!("{what}: missing value"))),
    }
}

/// Strips a `#` comment.
#[inline]
pub(crate) fn strip_comment(line: &str) -> &str {
    match line.find('#') {
        Some(i) => &line[..i],
        None => line,
    }
}
