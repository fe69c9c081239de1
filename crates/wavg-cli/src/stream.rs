//! Streaming query files through `wavg forward` / `wavg inverse`: text or NumPy `.npy`
//! in, text or `.npy` out, a bounded chunk of rows at a time, with atomic outputs.
//!
//! Three stages overlap: a reader thread reads and parses the rows of chunk k+1 while a
//! compute thread solves and formats chunk k (parsing, solving and formatting are
//! parallel over the command's threads) and the calling thread writes the answers
//! formatted so far, a block at a time. The reader may run one chunk ahead of the
//! compute stage (its parts wait in a bounded queue) and the writer takes one block at a
//! time, so memory holds about three chunks of parsed input, one part of raw input and
//! two blocks of output.

use std::fs::File;
use std::io::{BufReader, Write};
use std::path::Path;
use std::sync::mpsc::{Receiver, SyncSender, sync_channel};
use std::sync::{Arc, Mutex};

use rayon::prelude::*;
use wavg::npy::{NpyReader, NpyWriter};
use wavg::text::{LineChunks, LineError};

use crate::CliError;
use crate::error::Context;
use crate::textio::{located, write_atomic};

/// Rows read, computed and written per round.
const CHUNK_ROWS: usize = 1 << 16;

/// Rows read and parsed at a time (a quarter of a chunk, to keep the input in flight
/// small).
const READ_ROWS: usize = CHUNK_ROWS / 4;

/// Written text buffers kept for reuse.
const SPARE_BUFFERS: usize = 16;

/// Text buffers that were written, cleared for reuse: formatting into them saves
/// allocating and faulting in fresh memory for every chunk.
type Spare = Arc<Mutex<Vec<Vec<u8>>>>;

/// Bytes of input read ahead.
const READ_BUFFER: usize = 1 << 22;

/// Bytes of a `.npy` input's buffer: enough for its header.
const NPY_HEADER_BUFFER: usize = 1 << 16;

/// A text chunk parser: the chunk's text and first line number to numbered rows.
pub type ParseChunk<T> = fn(&str, usize) -> Result<Vec<(usize, T)>, LineError>;

/// How a command reads its query rows: a text chunk parser of `wavg::text` (the chunk's
/// text and first line number to numbered rows) and the meaning of one `.npy` row (its
/// 1-based number and values).
pub struct Format<T> {
    /// Parses a chunk of text lines.
    pub text: ParseChunk<T>,
    /// Reads one `.npy` row.
    pub npy: fn(usize, NpyRow) -> Result<T, LineError>,
}

/// One row of a `.npy` input, sharing the block it was read in (rows are not copied
/// one by one).
#[derive(Clone, Debug)]
pub struct NpyRow {
    block: Arc<NpyBlock>,
    start: usize,
    len: usize,
}

impl std::ops::Deref for NpyRow {
    type Target = [f64];
    fn deref(&self) -> &[f64] {
        &self.block.values[self.start..self.start + self.len]
    }
}

/// `.npy` blocks whose rows are all dropped, for the reader to read over again: the
/// same memory serves the whole file, without fresh pages to clear and fault in.
type BlockPool = Arc<Mutex<Vec<Vec<f64>>>>;

/// `.npy` blocks kept for reuse: as many as can be in flight (a chunk being solved and
/// one read ahead, in parts, and the part being read).
const SPARE_BLOCKS: usize = 3 * CHUNK_ROWS / READ_ROWS;

/// The values of one part of a `.npy` input; handed back to its pool when dropped.
#[derive(Debug)]
struct NpyBlock {
    values: Vec<f64>,
    pool: BlockPool,
}

impl Drop for NpyBlock {
    fn drop(&mut self) {
        let mut pool = self.pool.lock().unwrap_or_else(|e| e.into_inner());
        if pool.len() < SPARE_BLOCKS {
            pool.push(std::mem::take(&mut self.values));
        }
    }
}

/// Whether `path` names a NumPy file.
pub fn is_npy(path: &Path) -> bool {
    path.extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("npy"))
}

/// Answers formatted together and sent to the writer as one block: small enough that
/// the blocks in flight stay small, large enough to spread over every thread.
const BLOCK_ROWS: usize = 1 << 13;

/// Formatted answers on their way to the writer.
enum Block {
    /// Text lines, in consecutive buffers.
    Text(Vec<Vec<u8>>),
    /// `.npy` rows, row after row.
    Npy(Vec<f64>),
}

impl Block {
    /// Hands the written text buffers back for reuse.
    fn recycle(self, spare: &Spare) {
        if let Block::Text(lines) = self {
            let mut spare = spare.lock().unwrap_or_else(|e| e.into_inner());
            for mut b in lines {
                if spare.len() < SPARE_BUFFERS {
                    b.clear();
                    spare.push(b);
                }
            }
        }
    }
}

/// Where a command puts its answers: text lines, or `.npy` rows of a fixed width. They
/// are formatted in parallel and handed to the writer a block at a time.
pub struct Sink {
    npy_cols: Option<usize>,
    spare: Spare,
    tx: SyncSender<Block>,
}

impl Sink {
    /// Formats one answer per item, in parallel: `text` appends a line's text (without its
    /// line break), `row` fills a `.npy` row of the width the sink was opened with
    /// (values it leaves alone are NaN). Fails when the writer has stopped.
    pub fn write<T: Sync>(
        &mut self,
        items: &[T],
        text: impl Fn(&T, &mut Vec<u8>) + Sync,
        row: impl Fn(&T, &mut [f64]) + Sync,
    ) -> std::io::Result<()> {
        for piece in items.chunks(BLOCK_ROWS) {
            let block = match self.npy_cols {
                None => {
                    let buffer = || {
                        let mut spare = self.spare.lock().unwrap_or_else(|e| e.into_inner());
                        spare.pop().unwrap_or_default()
                    };
                    Block::Text(wavg::text::format_lines_in(piece, &text, buffer))
                }
                Some(cols) => {
                    let mut values = vec![f64::NAN; piece.len() * cols];
                    if cols > 0 {
                        values
                            .par_chunks_mut(cols)
                            .zip(piece)
                            .for_each(|(r, item)| row(item, r));
                    }
                    Block::Npy(values)
                }
            };
            self.tx
                .send(block)
                .map_err(|_| std::io::Error::other("the writer stopped"))?;
        }
        Ok(())
    }
}

/// A chunk of input as read, before parsing.
enum Raw {
    /// Whole text lines.
    Text(wavg::text::Chunk),
    /// `.npy` rows of `cols` values; the first is row `first` (1-based).
    Npy {
        first: usize,
        cols: usize,
        block: NpyBlock,
    },
}

/// The rows of a query file, text or `.npy`, a chunk at a time.
enum Source {
    Text(LineChunks<BufReader<File>>),
    Npy {
        reader: NpyReader<BufReader<File>>,
        done: usize,
        pool: BlockPool,
    },
}

impl Source {
    fn open(input: &Path) -> Result<Self, CliError> {
        Self::open_from(input, input)
    }

    /// [`Source::open`] reading the file at `path`, a copy of `input` (which names it in
    /// messages and decides its format).
    fn open_from(path: &Path, input: &Path) -> Result<Self, CliError> {
        let file =
            File::open(path).map_err(|e| CliError::input(format!("{}: {e}", input.display())))?;
        Ok(if is_npy(input) {
            // A small buffer for the header: the values' reads, larger, then go past it
            // straight into their blocks.
            let reader = BufReader::with_capacity(NPY_HEADER_BUFFER, file);
            let reader = NpyReader::new(reader).context(input.display())?;
            if reader.cols() == 0 && reader.rows() > 0 {
                return Err(CliError::input(format!(
                    "{}: the array's {} rows hold no values (shape ({}, 0))",
                    input.display(),
                    reader.rows(),
                    reader.rows()
                )));
            }
            Source::Npy {
                reader,
                done: 0,
                pool: BlockPool::default(),
            }
        } else {
            let reader = BufReader::with_capacity(READ_BUFFER, file);
            Source::Text(LineChunks::new(reader, READ_ROWS))
        })
    }

    /// The next chunk as read, or `None` at the end.
    fn next_raw(&mut self, input: &Path) -> Result<Option<Raw>, CliError> {
        let io = |e: &dyn std::fmt::Display| CliError::input(format!("{}: {e}", input.display()));
        match self {
            Source::Text(chunks) => Ok(chunks.next_chunk().map_err(|e| io(&e))?.map(Raw::Text)),
            Source::Npy { reader, done, pool } => {
                let spare = pool.lock().unwrap_or_else(|e| e.into_inner()).pop();
                let mut values = spare.unwrap_or_default();
                let n = reader
                    .read_rows_over(&mut values, READ_ROWS)
                    .context(input.display())?;
                let first = *done + 1;
                *done += n;
                Ok((n > 0).then(|| Raw::Npy {
                    first,
                    cols: reader.cols(),
                    block: NpyBlock {
                        values,
                        pool: Arc::clone(pool),
                    },
                }))
            }
        }
    }
}

/// Parses a chunk into numbered rows (text in parallel).
fn parse<T: Send>(raw: Raw, input: &Path, format: &Format<T>) -> Result<Vec<(usize, T)>, CliError> {
    let bad = |e: LineError| located(input, e.line, &e.message);
    match raw {
        Raw::Text(chunk) => (format.text)(&chunk.text, chunk.first_line).map_err(bad),
        Raw::Npy { first, cols, block } => {
            let n = block.values.len().checked_div(cols).unwrap_or(0);
            let block = Arc::new(block);
            (0..n)
                .map(|i| {
                    let row = NpyRow {
                        block: Arc::clone(&block),
                        start: i * cols,
                        len: cols,
                    };
                    Ok((first + i, (format.npy)(first + i, row).map_err(bad)?))
                })
                .collect()
        }
    }
}

/// Reads and parses every part of `source` (text in parallel on `pool`), sending the
/// rows (or the first error) down `tx`, until the end or until the receiver is gone.
fn read_all<T: Send>(
    mut source: Source,
    input: &Path,
    format: &Format<T>,
    pool: &rayon::ThreadPool,
    tx: SyncSender<Result<Vec<(usize, T)>, CliError>>,
) {
    loop {
        // Text is parsed in parallel on the pool; a `.npy` part is only copied into rows,
        // which this thread does on its own, leaving the pool's threads to the solving.
        let next = source.next_raw(input).and_then(|raw| {
            raw.map(|r| match r {
                Raw::Text(_) => pool.install(|| parse(r, input, format)),
                Raw::Npy { .. } => parse(r, input, format),
            })
            .transpose()
        });
        let stop = !matches!(next, Ok(Some(_)));
        let Some(item) = next.transpose() else { return };
        if tx.send(item).is_err() || stop {
            return;
        }
    }
}

/// Computes the rows from `rx` a chunk at a time on `pool`; `each` puts the answers in
/// `sink` (and reports bad rows itself). Waiting for rows happens outside the pool, so
/// the reader's parsing always finds the pool's threads free, whatever their number.
fn compute_all<T: Send>(
    rx: Receiver<Result<Vec<(usize, T)>, CliError>>,
    mut sink: Sink,
    pool: &rayon::ThreadPool,
    mut each: impl FnMut(Vec<(usize, T)>, &mut Sink) -> Result<(), CliError> + Send,
) -> Result<(), CliError> {
    let mut chunk = Vec::new();
    for part in rx {
        let mut part = part?;
        chunk.append(&mut part);
        if chunk.len() >= CHUNK_ROWS {
            let rows = std::mem::take(&mut chunk);
            pool.install(|| each(rows, &mut sink))?;
        }
    }
    if !chunk.is_empty() {
        pool.install(|| each(chunk, &mut sink))?;
    }
    Ok(())
}

/// The output file as the writer sees it.
enum Dest<'a> {
    Text(&'a mut dyn Write),
    Npy(NpyWriter<&'a mut dyn Write>),
}

impl Dest<'_> {
    fn write(&mut self, block: &Block) -> std::io::Result<()> {
        match (self, block) {
            (Dest::Text(w), Block::Text(lines)) => lines.iter().try_for_each(|b| w.write_all(b)),
            (Dest::Npy(w), Block::Npy(values)) => w.write_rows(values),
            _ => Err(std::io::Error::other("answers of the wrong format")),
        }
    }
}

/// The query file `input`, or its copy `spooled` when there is one.
fn open_input(input: &Path, spooled: Option<&tempfile::NamedTempFile>) -> Result<Source, CliError> {
    match spooled {
        Some(copy) => Source::open_from(copy.path(), input),
        None => Source::open(input),
    }
}

/// A temporary copy of `input` (a pipe or other stream that can be read only once).
fn spool(input: &Path) -> Result<tempfile::NamedTempFile, CliError> {
    let io = |e: std::io::Error| CliError::input(format!("{}: {e}", input.display()));
    let mut from = File::open(input).map_err(io)?;
    let mut copy = tempfile::NamedTempFile::new().map_err(|e| {
        CliError::failure(format!(
            "cannot make a temporary copy of {}: {e}",
            input.display()
        ))
    })?;
    std::io::copy(&mut from, copy.as_file_mut()).map_err(io)?;
    Ok(copy)
}

/// Streams the query file `input` through bounded memory: each chunk of rows is parsed
/// (text in parallel) and handed to `each`, which puts its answers in the sink (text,
/// or with an `output` ending in `.npy` rows of `npy_cols` values) and fails on the
/// chunk's first bad row (errors name their line, or row for `.npy`). Reading, computing
/// and writing overlap (see the module documentation). The output goes to a temporary
/// file renamed on success, so a bad row anywhere leaves nothing; for stdout (`-`) and
/// other destinations that are not regular files (devices, pipes), and to count the rows
/// of a `.npy` output from a text input, a first pass parses the whole file and runs
/// `check` (the same errors as `each`'s) before anything is written.
pub fn stream_queries<T: Send>(
    input: &Path,
    output: &Path,
    format: Format<T>,
    npy_cols: usize,
    check: impl Fn(&[(usize, T)]) -> Result<(), CliError> + Send + Sync,
    each: impl FnMut(Vec<(usize, T)>, &mut Sink) -> Result<(), CliError> + Send,
) -> Result<(), CliError> {
    let npy_out = is_npy(output);
    let mut rows = None;
    // A device or pipe is written as the rows come (no rename can take back a bad row):
    // like stdout, it gets the first pass.
    let special = wavg::mesh::io::is_special_destination(output);
    // An input that can be read only once (a pipe, stdin) is copied to a temporary file
    // first when it has to be read twice.
    let mut spooled = None;
    if output == Path::new("-") || special || (npy_out && !is_npy(input)) {
        if !std::fs::metadata(input).is_ok_and(|m| m.is_file()) {
            spooled = Some(spool(input)?);
        }
        let mut source = open_input(input, spooled.as_ref())?;
        let mut n = 0;
        while let Some(raw) = source.next_raw(input)? {
            let chunk = parse(raw, input, &format)?;
            check(&chunk)?;
            n += chunk.len();
        }
        rows = Some(n);
    }
    let source = open_input(input, spooled.as_ref())?;
    if let (Source::Npy { reader, .. }, None) = (&source, rows) {
        rows = Some(reader.rows());
    }
    // The compute stage gets a pool of its own, as large as the one this runs in.
    let threads = rayon::current_num_threads();
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .map_err(|e| CliError::failure(format!("cannot start {threads} threads: {e}")))?;
    let spare = Spare::default();
    let mut failure = None;
    let written = write_atomic(output, |w: &mut dyn Write| {
        let mut dest = if npy_out {
            Dest::Npy(NpyWriter::new(w, rows.unwrap_or(0), npy_cols)?)
        } else {
            Dest::Text(w)
        };
        // The reader may run a whole chunk ahead, so the next chunk's input is ready when
        // the current one is solved; the writer's channel is a rendezvous (the compute
        // stage holds one block while the writer writes the previous one).
        let (raw_tx, raw_rx) = sync_channel(CHUNK_ROWS / READ_ROWS);
        let (block_tx, block_rx) = sync_channel(0);
        let (computed, written) = std::thread::scope(|s| {
            s.spawn(|| read_all(source, input, &format, &pool, raw_tx));
            let compute = s.spawn(|| {
                let sink = Sink {
                    npy_cols: npy_out.then_some(npy_cols),
                    spare: Arc::clone(&spare),
                    tx: block_tx,
                };
                compute_all(raw_rx, sink, &pool, each)
            });
            let mut written = Ok(());
            for block in &block_rx {
                written = dest.write(&block);
                if written.is_err() {
                    break;
                }
                block.recycle(&spare);
            }
            drop(block_rx);
            let computed = compute
                .join()
                .unwrap_or_else(|p| std::panic::resume_unwind(p));
            (computed, written)
        });
        written?;
        if let Err(e) = computed {
            failure = Some(e);
            return Err(std::io::Error::other("stopped"));
        }
        match dest {
            Dest::Npy(w) => w.finish().map(|_| ()),
            Dest::Text(_) => Ok(()),
        }
    });
    match failure {
        Some(e) => Err(e),
        None => written,
    }
}
