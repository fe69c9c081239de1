//! The plain-text formats of surface points and weights (described in the [crate
//! docs](crate)), parsed and written in parallel a chunk of lines at a time, so files of
//! any length stream through bounded memory.
//!
//! ```
//! use wavg_io::text::{LineChunks, PointSpec, parse_points, push_numbers};
//! let text = "# two anchors\nv 3\nf 2 0.25 0.25 0.5\n";
//! let mut chunks = LineChunks::new(text.as_bytes(), 1000);
//! let chunk = chunks.next_chunk()?.expect("one chunk");
//! let points = parse_points(&chunk.text, chunk.first_line)?;
//! assert_eq!(points[0], (2, PointSpec::Vertex(3)));
//! let mut out = Vec::new();
//! push_numbers(&mut out, [0.1, 1.0, 2.5e-300]);
//! assert_eq!(out, b"0.1 1.0 2.5e-300");
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```

use std::fmt;
use std::io::{self, BufRead, Write};

use rayon::prelude::*;

mod decode;
mod scan;

pub use decode::decode;
use scan::tokens;

/// Lines parsed or formatted by one task: large enough to amortise scheduling, small
/// enough to spread a chunk over every thread.
const LINES_PER_TASK: usize = 2048;

/// A malformed line.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub struct LineError {
    /// 1-based line number.
    pub line: usize,
    /// What is wrong.
    pub message: String,
}

impl fmt::Display for LineError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "line {}: {}", self.line, self.message)
    }
}

/// A surface point as written in a file (not yet checked against a mesh).
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum PointSpec {
    /// `v VERTEX`.
    Vertex(u64),
    /// `f FACE B0 B1 B2`.
    Face {
        /// Face index.
        face: u64,
        /// Barycentric coordinates as written.
        bary: [f64; 3],
    },
}

/// Whole lines of a text stream, a bounded number at a time.
pub struct LineChunks<R> {
    reader: R,
    next_line: usize,
    lines_per_chunk: usize,
    /// Bytes of the last chunk: the next one is allocated that large at once.
    last_bytes: usize,
}

/// Consecutive whole lines of a stream.
#[derive(Debug, Clone, PartialEq)]
pub struct Chunk {
    /// 1-based number of the chunk's first line.
    pub first_line: usize,
    /// The lines, each with its line break (the stream's last line may lack one).
    pub text: String,
}

impl<R: BufRead> LineChunks<R> {
    /// Reads `reader` in chunks of at most `lines_per_chunk` lines (at least 1).
    pub fn new(reader: R, lines_per_chunk: usize) -> Self {
        Self {
            reader,
            next_line: 1,
            lines_per_chunk: lines_per_chunk.max(1),
            last_bytes: 0,
        }
    }

    /// The next chunk, or `None` at the end of the stream. Text that is not UTF-8 outside
    /// `#` comments is an [`io::ErrorKind::InvalidData`] error ([`decode`]).
    pub fn next_chunk(&mut self) -> io::Result<Option<Chunk>> {
        // Bytes first, checked once per chunk; sized like the last chunk, so a stream of
        // similar lines is read without growing (and copying) the buffer.
        let mut bytes = Vec::with_capacity(self.last_bytes + self.last_bytes / 8);
        let mut lines = 0;
        while lines < self.lines_per_chunk && self.reader.read_until(b'\n', &mut bytes)? > 0 {
            lines += 1;
        }
        if lines == 0 {
            return Ok(None);
        }
        self.last_bytes = bytes.len();
        let text = decode(bytes, self.next_line)
            .map_err(|e| io::Error::new(io::ErrorKind::InvalidData, e.to_string()))?;
        let chunk = Chunk {
            first_line: self.next_line,
            text,
        };
        self.next_line += lines;
        Ok(Some(chunk))
    }
}

/// Parses surface-point lines (`v VERTEX` / `f FACE B0 B1 B2`) in parallel; `first_line`
/// is the number of the first line of `text`. Returns each point with its line number;
/// the error is the first malformed line's.
pub fn parse_points(text: &str, first_line: usize) -> Result<Vec<(usize, PointSpec)>, LineError> {
    parse_lines(text, first_line, |line, l, toks: &mut Vec<&str>| {
        tokens(l, toks);
        if toks.is_empty() {
            return Ok(None);
        }
        point_line(line, toks).map(Some)
    })
}

/// Parses weight lines (whitespace-separated finite numbers) in parallel; `first_line` is
/// the number of the first line of `text`. Returns each row with its line number; the
/// error is the first malformed line's. Row lengths are not checked here.
pub fn parse_weights(text: &str, first_line: usize) -> Result<Vec<(usize, Vec<f64>)>, LineError> {
    parse_lines(
        text,
        first_line,
        |line, l, (row, toks): &mut (Vec<f64>, Vec<&str>)| {
            if scan::numbers(l, row) {
                return Ok((!row.is_empty()).then(|| row.clone()));
            }
            tokens(l, toks);
            if toks.is_empty() {
                return Ok(None);
            }
            toks.iter()
                .enumerate()
                .map(|(i, tok)| number(tok, line, WeightNo(i)))
                .collect::<Result<_, _>>()
                .map(Some)
        },
    )
}

/// Runs `parse` (line number, line, a scratch value of each task) on every line, in
/// parallel over groups of lines, keeping input order, dropping lines without content
/// (`None`) and reporting the first error. A UTF-8 byte order mark opening the file (some
/// editors write one; it is invisible in messages) is skipped.
fn parse_lines<'t, T: Send, S: Default>(
    text: &'t str,
    first_line: usize,
    parse: impl Fn(usize, &'t str, &mut S) -> Result<Option<T>, LineError> + Sync,
) -> Result<Vec<(usize, T)>, LineError> {
    let text = match text.strip_prefix('\u{feff}') {
        Some(rest) if first_line == 1 => rest,
        _ => text,
    };
    let lines: Vec<&str> = text.lines().collect();
    let groups: Vec<Result<Vec<(usize, T)>, LineError>> = lines
        .par_chunks(LINES_PER_TASK)
        .enumerate()
        .map(|(g, group)| {
            let mut out = Vec::with_capacity(group.len());
            let mut scratch = S::default();
            for (i, l) in group.iter().enumerate() {
                let line = first_line + g * LINES_PER_TASK + i;
                if let Some(t) = parse(line, l, &mut scratch)? {
                    out.push((line, t));
                }
            }
            Ok(out)
        })
        .collect();
    let mut out = Vec::new();
    for g in groups {
        out.extend(g?);
    }
    Ok(out)
}

fn point_line(line: usize, t: &[&str]) -> Result<PointSpec, LineError> {
    let err = |message: String| Err(LineError { line, message });
    match (t[0], t.len()) {
        ("v", 2) => Ok(PointSpec::Vertex(index(t[1], line, "vertex index")?)),
        ("f", 5) => Ok(PointSpec::Face {
            face: index(t[1], line, "face index")?,
            bary: [
                number(t[2], line, "barycentric B0")?,
                number(t[3], line, "barycentric B1")?,
                number(t[4], line, "barycentric B2")?,
            ],
        }),
        ("v", n) => err(format!("'v' takes 1 value (VERTEX), got {}", n - 1)),
        ("f", n) => err(format!("'f' takes 4 values (FACE B0 B1 B2), got {}", n - 1)),
        (other, _) => err(format!(
            "expected 'v VERTEX' or 'f FACE B0 B1 B2', found {}",
            shown(other)
        )),
    }
}

/// Names the `i`-th weight of a line (from 0) in messages, counting from 1 as line
/// numbers do (formatted only on error).
struct WeightNo(usize);

impl fmt::Display for WeightNo {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "weight {} of the line", self.0 + 1)
    }
}

/// A token quoted for a message, its invisible characters (controls, zero-width ones, a
/// byte-order mark) escaped, so `'\u{feff}v'` does not read as `'v'`; a byte-order mark
/// gets a word on where it likely came from.
fn shown(tok: &str) -> String {
    let invisible =
        |c: char| c.is_control() || matches!(c, '\u{feff}' | '\u{200b}'..='\u{200f}' | '\u{2060}');
    let mut s = String::from("'");
    for c in tok.chars() {
        if invisible(c) {
            s.extend(c.escape_unicode());
        } else {
            s.push(c);
        }
    }
    s.push('\'');
    if tok.contains('\u{feff}') {
        s.push_str(" (a byte-order mark inside the file: files joined with cat?)");
    }
    s
}

fn number(tok: &str, line: usize, what: impl fmt::Display) -> Result<f64, LineError> {
    let x: f64 = tok.parse().map_err(|_| LineError {
        line,
        message: format!("{what}: {} is not a number", shown(tok)),
    })?;
    if !x.is_finite() {
        return Err(LineError {
            line,
            message: format!("{what}: '{tok}' is not finite"),
        });
    }
    Ok(x)
}

fn index(tok: &str, line: usize, what: &str) -> Result<u64, LineError> {
    tok.parse().map_err(|_| LineError {
        line,
        message: format!("{what}: {} is not a non-negative integer", shown(tok)),
    })
}

/// Appends one number in the shortest form that reads back to the same `f64`, laid out as
/// `{:?}` writes it.
pub fn push_number(out: &mut Vec<u8>, x: f64) {
    if !x.is_finite() {
        // Writing into a Vec cannot fail.
        let _ = write!(out, "{x:?}");
        return;
    }
    let mut buf = zmij::Buffer::new();
    let s = buf.format_finite(x).as_bytes();
    // zmij writes the same layout as `{:?}` between 1e-4 and 1e16, and below 1e-5 where
    // both write a negative exponent (tested); elsewhere `{:?}` uses exponent notation of
    // its own style.
    let a = x.abs();
    let same = if a < 1e-5 {
        // Zero ("0.0") or a negative exponent, whose `e` is among the last five bytes.
        x == 0.0 || s.iter().rev().take(5).any(|&c| c == b'e')
    } else {
        (1e-4..1e16).contains(&a)
    };
    if same {
        out.extend_from_slice(s);
    } else if !push_fraction_as_exponent(out, s) {
        push_exponent_form(out, s);
    }
}

/// Rewrites a number below one written in fixed notation, `[-]0.000DDD`, as `{:?}` writes
/// it in exponent notation (`D.DDe-4`): the common case between 1e-5 and 1e-4, where zmij
/// writes fixed notation and `{:?}` does not. Returns `false`, writing nothing, for any
/// other text.
fn push_fraction_as_exponent(out: &mut Vec<u8>, s: &[u8]) -> bool {
    let negative = s.first() == Some(&b'-');
    let Some(body) = s[usize::from(negative)..].strip_prefix(b"0.") else {
        return false;
    };
    let zeros = body.iter().take_while(|&&d| d == b'0').count();
    let digits = &body[zeros..];
    let digits = &digits[..digits.len() - digits.iter().rev().take_while(|&&d| d == b'0').count()];
    if digits.is_empty() || !digits.iter().all(u8::is_ascii_digit) {
        return false;
    }
    push_scientific(out, negative, digits, -(zeros as i32 + 1));
    true
}

/// Rewrites a number written by zmij (fixed `0.00001` or exponent `1.5e-7`, `1e+20`) as
/// `{:?}` writes it in exponent notation: `1e-5`, `1.5e-7`, `1e20`.
fn push_exponent_form(out: &mut Vec<u8>, s: &[u8]) {
    // zmij writes ASCII only.
    let s = std::str::from_utf8(s).unwrap_or_default();
    let (negative, s) = match s.strip_prefix('-') {
        Some(rest) => (true, rest),
        None => (false, s),
    };
    let (mantissa, exponent) = match s.split_once(['e', 'E']) {
        Some((m, e)) => (m, e.trim_start_matches('+').parse::<i32>().unwrap_or(0)),
        None => (s, 0),
    };
    let (int, frac) = mantissa.split_once('.').unwrap_or((mantissa, ""));
    // The significant digits: int and frac joined, without leading or trailing zeros.
    let mut digits = [0u8; 40];
    let mut n = 0;
    for d in int.bytes().chain(frac.bytes()).take(digits.len()) {
        digits[n] = d;
        n += 1;
    }
    let lead = digits[..n].iter().take_while(|&&d| d == b'0').count();
    let digits = &digits[lead..n];
    let end = digits.len() - digits.iter().rev().take_while(|&&d| d == b'0').count();
    let digits = &digits[..end.max(1)];
    let exponent = exponent + int.len() as i32 - 1 - lead as i32;
    push_scientific(out, negative, digits, exponent);
}

/// Writes `[-]D[.DDD]e[-]X` as `{:?}` does: the significant digits `digits` (at least
/// one, no trailing zeros) and the exponent of the first one.
fn push_scientific(out: &mut Vec<u8>, negative: bool, digits: &[u8], exponent: i32) {
    if negative {
        out.push(b'-');
    }
    out.push(digits[0]);
    if digits.len() > 1 {
        out.push(b'.');
        out.extend_from_slice(&digits[1..]);
    }
    out.push(b'e');
    if exponent < 0 {
        out.push(b'-');
    }
    let e = exponent.unsigned_abs();
    if e >= 100 {
        out.push(b'0' + (e / 100) as u8);
    }
    if e >= 10 {
        out.push(b'0' + (e / 10 % 10) as u8);
    }
    out.push(b'0' + (e % 10) as u8);
}

/// Appends numbers separated by single spaces.
pub fn push_numbers(out: &mut Vec<u8>, xs: impl IntoIterator<Item = f64>) {
    for (i, x) in xs.into_iter().enumerate() {
        if i > 0 {
            out.push(b' ');
        }
        push_number(out, x);
    }
}

/// Writes one line per item, formatted by `format` in parallel (each call appends one
/// line's text without its line break), in input order.
pub fn write_lines<T: Sync>(
    w: &mut dyn Write,
    items: &[T],
    format: impl Fn(&T, &mut Vec<u8>) + Sync,
) -> io::Result<()> {
    for b in &format_lines(items, format) {
        w.write_all(b)?;
    }
    Ok(())
}

/// Formats one line per item in parallel (each call of `format` appends one line's text
/// without its line break): the lines in input order, in consecutive blocks of several
/// lines each, ready to be written by another thread.
pub fn format_lines<T: Sync>(
    items: &[T],
    format: impl Fn(&T, &mut Vec<u8>) + Sync,
) -> Vec<Vec<u8>> {
    format_lines_in(items, format, Vec::new)
}

/// [`format_lines`] into buffers handed out by `buffer` (for example buffers already
/// written and recycled, which saves allocating and faulting in fresh memory); what they
/// hold is kept in front of the lines.
pub fn format_lines_in<T: Sync>(
    items: &[T],
    format: impl Fn(&T, &mut Vec<u8>) + Sync,
    buffer: impl Fn() -> Vec<u8> + Sync,
) -> Vec<Vec<u8>> {
    items
        .par_chunks(LINES_PER_TASK)
        .map(|group| {
            let mut buf = buffer();
            for item in group {
                format(item, &mut buf);
                buf.push(b'\n');
            }
            buf
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    /// A byte order mark opening a file is skipped; anywhere else it is an error.
    #[test]
    fn a_byte_order_mark_opens_a_file() {
        let p = parse_points("\u{feff}v 3\nv 4\n", 1).unwrap();
        assert_eq!(
            p,
            vec![(1, PointSpec::Vertex(3)), (2, PointSpec::Vertex(4))]
        );
        let w = parse_weights("\u{feff}0.5 0.5\n", 1).unwrap();
        assert_eq!(w, vec![(1, vec![0.5, 0.5])]);
        assert!(parse_points("\u{feff}v 3\n", 7).is_err());
        // Elsewhere the message shows the mark and says where it likely came from.
        let e = parse_points("v 3\n\u{feff}v 4\n", 1).unwrap_err();
        assert!(e.message.contains(r"'\u{feff}v'"), "{}", e.message);
        assert!(e.message.contains("byte-order mark"), "{}", e.message);
        let e = parse_weights("0.5 0.5\n\u{feff}0.2 0.8\n", 1).unwrap_err();
        assert!(
            e.message.contains(r"'\u{feff}0.2' (a byte-order mark"),
            "{}",
            e.message
        );
        let e = parse_weights("0.5 0.5\n0.2\u{200b} 0.8\n", 1).unwrap_err();
        assert!(e.message.contains(r"'0.2\u{200b}'"), "{}", e.message);
    }

    #[test]
    fn parses_points_with_comments_and_blank_lines() {
        let t = "# anchors\n\nv 3\n  f 2 0.25 0.25 0.5   # inline\nv 0\n";
        let p = parse_points(t, 1).unwrap();
        assert_eq!(
            p,
            vec![
                (3, PointSpec::Vertex(3)),
                (
                    4,
                    PointSpec::Face {
                        face: 2,
                        bary: [0.25, 0.25, 0.5]
                    }
                ),
                (5, PointSpec::Vertex(0)),
            ]
        );
    }

    #[test]
    fn point_errors_name_the_line() {
        for (t, line, needle) in [
            ("v 1\nv -1\n", 2, "non-negative integer"),
            ("v 1\n\nq 3\n", 3, "expected 'v VERTEX'"),
            ("f 1 0.5 0.5\n", 1, "takes 4 values"),
            ("v 1 2\n", 1, "takes 1 value"),
            ("f 1 0.5 nan 0.5\n", 1, "not finite"),
            ("f 1 0.5 x 0.5\n", 1, "not a number"),
            ("v 1.5\n", 1, "non-negative integer"),
        ] {
            let e = parse_points(t, 1).unwrap_err();
            assert_eq!(e.line, line, "{t:?}");
            assert!(e.message.contains(needle), "{t:?}: {}", e.message);
        }
    }

    #[test]
    fn parses_weights() {
        let w = parse_weights("0.5 0.5\n# c\n1e-1\t0.9\n", 1).unwrap();
        assert_eq!(w, vec![(1, vec![0.5, 0.5]), (3, vec![0.1, 0.9])]);
        let e = parse_weights("0.5 0.5\n0.5 inf\n", 1).unwrap_err();
        assert_eq!(e.line, 2);
        assert!(e.message.contains("weight 2 of the line"), "{}", e.message);
    }

    #[test]
    fn chunks_keep_line_numbers_and_report_the_first_error() {
        // Many lines, so that several parallel groups and several chunks are involved.
        let mut text = String::new();
        for i in 0..10_000 {
            if i % 7 == 0 {
                text.push_str("# comment\n");
            } else {
                text.push_str(&format!("{i} 0.5\n"));
            }
        }
        let whole = parse_weights(&text, 1).unwrap();
        let mut chunks = LineChunks::new(text.as_bytes(), 999);
        let mut streamed = Vec::new();
        while let Some(c) = chunks.next_chunk().unwrap() {
            streamed.extend(parse_weights(&c.text, c.first_line).unwrap());
        }
        assert_eq!(streamed, whole);
        assert_eq!(whole[0], (2, vec![1.0, 0.5]));
        // Two bad lines in different groups: the first is reported.
        let mut bad: Vec<&str> = text.lines().collect();
        bad[8000] = "x";
        bad[5000] = "y";
        let e = parse_weights(&bad.join("\n"), 1).unwrap_err();
        assert_eq!(e.line, 5001);
    }

    #[test]
    fn non_utf8_is_an_error_outside_comments() {
        let mut chunks = LineChunks::new(&b"0.5 0.5\n\xff\n"[..], 10);
        let e = chunks.next_chunk().unwrap_err();
        assert_eq!(e.kind(), io::ErrorKind::InvalidData);
        assert!(e.to_string().starts_with("line 2:"), "{e}");
        let mut chunks = LineChunks::new(&b"# Z\xfcrich\n0.5 0.5\n"[..], 10);
        let chunk = chunks.next_chunk().unwrap().unwrap();
        assert_eq!(
            parse_weights(&chunk.text, 1).unwrap(),
            [(2, vec![0.5, 0.5])]
        );
    }

    #[test]
    fn writes_lines_in_order() {
        let items: Vec<f64> = (0..5000).map(|i| i as f64 * 0.5).collect();
        let mut out = Vec::new();
        write_lines(&mut out, &items, |x, b| push_number(b, *x)).unwrap();
        let text = String::from_utf8(out).unwrap();
        let back: Vec<f64> = text.lines().map(|l| l.parse().unwrap()).collect();
        assert_eq!(back, items);
    }

    #[test]
    fn numbers_as_debug_at_the_edges() {
        for x in [
            0.0,
            -0.0,
            1.0,
            0.1,
            1e-4,
            9.999e-5,
            1e15,
            1e16,
            9.99e15,
            1e-300,
            5e-324,
            1e300,
            f64::MAX,
            -1.5,
            123456.789,
            1e21,
            1e22,
            1e-5,
            -1e-5,
            3.163712034781162e-5,
            -1.1063214808739927e-5,
            1.5e-5,
            f64::from_bits(1e-5f64.to_bits() - 1),
            f64::from_bits(1e-5f64.to_bits() + 1),
            -8.839876561713762e-7,
            f64::MIN_POSITIVE,
        ] {
            let mut out = Vec::new();
            push_number(&mut out, x);
            assert_eq!(String::from_utf8(out).unwrap(), format!("{x:?}"));
        }
    }

    /// The layout before the fast paths of [`push_number`]: zmij's text as is between
    /// 1e-4 and 1e16, rewritten by [`push_exponent_form`] elsewhere.
    fn general_form(x: f64) -> Vec<u8> {
        let mut buf = zmij::Buffer::new();
        let s = buf.format_finite(x);
        let mut out = Vec::new();
        if x == 0.0 || (1e-4..1e16).contains(&x.abs()) {
            out.extend_from_slice(s.as_bytes());
        } else {
            push_exponent_form(&mut out, s.as_bytes());
        }
        out
    }

    proptest! {
        #[test]
        fn fast_paths_write_the_general_form(m in 1.0f64..10.0, e in -330i32..-3, neg: bool) {
            let x = if neg { -m } else { m } * 10f64.powi(e);
            prop_assume!(x.is_finite());
            let mut out = Vec::new();
            push_number(&mut out, x);
            prop_assert_eq!(out, general_form(x));
        }

        /// Between 1e-6 and 1e-3, where zmij's fixed notation is rewritten, the text is
        /// `{:?}`'s up to the last digit of a tie, and reads back.
        #[test]
        fn rewritten_fractions_are_debugs(m in 1.0f64..10.0, e in -6i32..-3, neg: bool) {
            let x = if neg { -m } else { m } * 10f64.powi(e);
            let mut out = Vec::new();
            push_number(&mut out, x);
            let text = String::from_utf8(out).unwrap();
            let debug = format!("{x:?}");
            prop_assert_eq!(text.parse::<f64>().unwrap(), x);
            prop_assert_eq!(text.len(), debug.len(), "{} vs {}", text, debug);
            let differing = text.bytes().zip(debug.bytes()).filter(|(a, b)| a != b).count();
            prop_assert!(differing <= 1, "{} vs {}", text, debug);
        }

        #[test]
        fn numbers_read_back_as_short_as_debug(bits in any::<u64>(), scale in -30i32..30) {
            let x = f64::from_bits(bits);
            let y = (bits as f64 / u64::MAX as f64) * 10f64.powi(scale);
            for v in [x, y, -y] {
                let mut out = Vec::new();
                push_number(&mut out, v);
                let text = String::from_utf8(out).unwrap();
                let debug = format!("{v:?}");
                if v.is_nan() {
                    prop_assert_eq!(text, debug);
                    continue;
                }
                prop_assert_eq!(text.parse::<f64>().unwrap(), v);
                // Same length and layout; only a tie may change the last digit.
                prop_assert_eq!(text.len(), debug.len(), "{} vs {}", text, debug);
                let differing = text.bytes().zip(debug.bytes()).filter(|(a, b)| a != b).count();
                prop_assert!(differing <= 1, "{} vs {}", text, debug);
            }
        }
    }
}
