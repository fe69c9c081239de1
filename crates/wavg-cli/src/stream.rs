//! Streaming query files through `wavg forward` / `wavg inverse`: text or NumPy `.npy`
//! in, text or `.npy` out, a bounded chunk of rows at a time, with atomic outputs.

use std::fs::File;
use std::io::{BufReader, Write};
use std::path::Path;

use wavg::npy::{NpyReader, NpyWriter};
use wavg::text::{LineChunks, LineError};

use crate::CliError;
use crate::textio::{located, write_atomic};

/// Rows read, checked, computed and written per round.
const CHUNK_ROWS: usize = 1 << 16;

/// A text chunk parser: the chunk's text and first line number to numbered rows.
pub type ParseChunk<T> = fn(&str, usize) -> Result<Vec<(usize, T)>, LineError>;

/// How a command reads its query rows: a text chunk parser of `wavg::text` (the chunk's
/// text and first line number to numbered rows) and the meaning of one `.npy` row (its
/// 1-based number and values).
pub struct Format<T> {
    /// Parses a chunk of text lines.
    pub text: ParseChunk<T>,
    /// Reads one `.npy` row.
    pub npy: fn(usize, &[f64]) -> Result<T, LineError>,
}

/// Whether `path` names a NumPy file.
pub fn is_npy(path: &Path) -> bool {
    path.extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("npy"))
}

/// Where a command writes its answers.
pub enum Sink<'a> {
    /// One text line per answer.
    Text(&'a mut dyn Write),
    /// One `.npy` row per answer.
    Npy(NpyWriter<&'a mut dyn Write>),
}

impl Sink<'_> {
    /// Writes one answer per item: `text` appends a line's text (without its line break),
    /// `row` fills a `.npy` row of the width the sink was opened with.
    pub fn write<T: Sync>(
        &mut self,
        items: &[T],
        text: impl Fn(&T, &mut Vec<u8>) + Sync,
        row: impl Fn(&T, &mut [f64]),
    ) -> std::io::Result<()> {
        match self {
            Sink::Text(w) => wavg::text::write_lines(*w, items, text),
            Sink::Npy(w) => {
                let mut buf = vec![0.0; w.cols()];
                for item in items {
                    buf.fill(f64::NAN);
                    row(item, &mut buf);
                    w.write_row(&buf)?;
                }
                Ok(())
            }
        }
    }
}

/// The rows of a query file, text or `.npy`, a chunk at a time.
enum Source {
    Text(LineChunks<BufReader<File>>),
    Npy(NpyReader<BufReader<File>>, usize),
}

impl Source {
    fn open(input: &Path) -> Result<Self, CliError> {
        let file =
            File::open(input).map_err(|e| CliError::input(format!("{}: {e}", input.display())))?;
        let reader = BufReader::with_capacity(1 << 20, file);
        Ok(if is_npy(input) {
            let r = NpyReader::new(reader)
                .map_err(|e| CliError::input(format!("{}: {e}", input.display())))?;
            Source::Npy(r, 0)
        } else {
            Source::Text(LineChunks::new(reader, CHUNK_ROWS))
        })
    }

    /// The next chunk of numbered rows, or `None` at the end.
    fn next<T>(
        &mut self,
        input: &Path,
        format: &Format<T>,
    ) -> Result<Option<Vec<(usize, T)>>, CliError> {
        let io = |e: &dyn std::fmt::Display| CliError::input(format!("{}: {e}", input.display()));
        let bad = |e: LineError| located(input, e.line, &e.message);
        match self {
            Source::Text(chunks) => {
                let Some(chunk) = chunks.next_chunk().map_err(|e| io(&e))? else {
                    return Ok(None);
                };
                (format.text)(&chunk.text, chunk.first_line)
                    .map(Some)
                    .map_err(bad)
            }
            Source::Npy(reader, done) => {
                let mut rows = Vec::new();
                let mut buf = vec![0.0; reader.cols()];
                while rows.len() < CHUNK_ROWS && reader.read_row(&mut buf).map_err(|e| io(&e))? {
                    *done += 1;
                    rows.push((*done, (format.npy)(*done, &buf).map_err(bad)?));
                }
                Ok((!rows.is_empty()).then_some(rows))
            }
        }
    }
}

/// Streams the query file `input` through bounded memory: each chunk of rows is parsed
/// (text in parallel), checked by `check` (errors name their line, or row for `.npy`), and
/// handed to `each`, which writes its answers to the sink: text, or with an `output`
/// ending in `.npy` rows of `npy_cols` values. The output goes to a temporary file renamed
/// on success, so a bad row anywhere leaves nothing; for stdout (`-`), and to count the
/// rows of a `.npy` output from a text input, a first pass parses and checks the whole
/// file before anything is written.
pub fn stream_queries<T: Send>(
    input: &Path,
    output: &Path,
    format: Format<T>,
    npy_cols: usize,
    check: impl Fn(&[(usize, T)]) -> Result<(), CliError>,
    mut each: impl FnMut(Vec<(usize, T)>, &mut Sink) -> Result<(), CliError>,
) -> Result<(), CliError> {
    let npy_out = is_npy(output);
    let mut rows = None;
    if output == Path::new("-") || (npy_out && !is_npy(input)) {
        let mut source = Source::open(input)?;
        let mut n = 0;
        while let Some(chunk) = source.next(input, &format)? {
            check(&chunk)?;
            n += chunk.len();
        }
        rows = Some(n);
    }
    let mut source = Source::open(input)?;
    if let (Source::Npy(r, _), None) = (&source, rows) {
        rows = Some(r.rows());
    }
    let mut failure = None;
    let written = write_atomic(output, |w: &mut dyn Write| {
        let mut sink = if npy_out {
            Sink::Npy(NpyWriter::new(w, rows.unwrap_or(0), npy_cols)?)
        } else {
            Sink::Text(w)
        };
        let mut round = || -> Result<(), CliError> {
            while let Some(chunk) = source.next(input, &format)? {
                check(&chunk)?;
                each(chunk, &mut sink)?;
            }
            Ok(())
        };
        round().map_err(|e| {
            failure = Some(e);
            std::io::Error::other("stopped")
        })?;
        match sink {
            Sink::Npy(w) => w.finish().map(|_| ()),
            Sink::Text(_) => Ok(()),
        }
    });
    match failure {
        Some(e) => Err(e),
        None => written,
    }
}
