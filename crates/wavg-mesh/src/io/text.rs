//! Shared pieces of the text parsers: located errors, UTF-8 check, number parsing.

/// A parse failure at a 1-based line (0 when there is no line, e.g. binary data).
#[derive(Debug)]
pub(crate) struct ParseError {
    pub line: usize,
    pub message: String,
}

impl ParseError {
    pub(crate) fn new(line: usize, message: impl Into<String>) -> Self {
        Self {
            line,
            message: message.into(),
        }
    }
}

pub(crate) type Result<T> = std::result::Result<T, ParseError>;

/// The bytes as text (without a UTF-8 byte-order mark, which would otherwise hide the first
/// statement), or an error naming the line of the first invalid UTF-8 byte.
pub(crate) fn as_text(bytes: &[u8]) -> Result<&str> {
    let bytes = bytes.strip_prefix("\u{feff}".as_bytes()).unwrap_or(bytes);
    std::str::from_utf8(bytes).map_err(|e| {
        let at = e.valid_up_to();
        let line = bytes[..at].iter().filter(|&&b| b == b'\n').count() + 1;
        ParseError::new(line, "invalid UTF-8 (binary data in a text format?)")
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
