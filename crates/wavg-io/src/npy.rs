//! NumPy `.npy` files of 2-D float arrays (described in the [crate docs](crate)), read and
//! written a row at a time (streaming), so weights and points can go to and from Python
//! without text parsing. [`NpyReader`] streams C-order arrays; [`read_matrix`] reads any
//! supported array whole; [`NpyWriter`] writes.
//!
//! # Why not `npyz`
//!
//! The `npyz` crate (0.9.1) reads and writes any `.npy` dtype, but measured against this
//! module on what wavg needs it loses on every count (a comparison program is in
//! `lab/npyz-timing`):
//!
//! * **Hostile headers.** A version-2 header declaring a 4 GiB header length makes `npyz`
//!   allocate 4 GiB before reading it (under a 1 GB address-space limit the process
//!   aborts: "memory allocation of 4294967280 bytes failed"); this module refuses headers
//!   over 64 KiB. A shape of `(2^40, 2^40)` overflows `npyz`'s element count: a panic
//!   with overflow checks (wavg's test profile), and an array that silently reads as
//!   empty without them; this module refuses it as too large.
//! * **Speed.** Writing 10^6 x 8 float64 (64 MB) into memory took 113-132 ms here against
//!   208-234 ms with `npyz` (element by element); reading it back in blocks of 65 536 rows,
//!   as the command line streams, took 18-20 ms against 51-66 ms (best of 5, alternating,
//!   three runs, 2-core Xeon, release build).
//! * **Streaming and types.** `npyz` streams element by element through an iterator (one
//!   `read_exact` per value) and reads float32 files only as `f32`, so a caller still
//!   needs its own block buffering, float32 widening and Fortran-order transpose; those
//!   are most of this module.
//! * **Weight.** It brings 25 further crates (a Python-literal parser, big integers).
//!
//! ```
//! let mut bytes = Vec::new();
//! let mut w = wavg_io::npy::NpyWriter::new(&mut bytes, 2, 3)?;
//! w.write_row(&[1.0, 2.0, 3.0])?;
//! w.write_row(&[4.0, 5.0, 6.0])?;
//! w.finish()?;
//! let (rows, cols, data) = wavg_io::npy::read_matrix(&bytes[..])?;
//! assert_eq!((rows, cols), (2, 3));
//! assert_eq!(data, [1.0, 2.0, 3.0, 4.0, 5.0, 6.0]);
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```

use std::io::{Read, Write};

const MAGIC: &[u8; 6] = b"\x93NUMPY";
/// Longest header accepted (NumPy's own limit for safe loading is 10 000 bytes).
const MAX_HEADER: usize = 1 << 16;

/// Why an `.npy` stream could not be read.
#[derive(Debug, thiserror::Error)]
pub enum NpyError {
    /// Reading failed.
    #[error("{0}")]
    Io(#[from] std::io::Error),
    /// The bytes are not a supported `.npy` array.
    #[error("not a supported .npy array: {0}")]
    Format(String),
    /// The data ended before `rows x cols` values.
    #[error(".npy data ends after {values_read} of {expected} values")]
    Truncated {
        /// Values read before the end.
        values_read: usize,
        /// Values the header declared.
        expected: usize,
    },
}

fn bad(msg: impl Into<String>) -> NpyError {
    NpyError::Format(msg.into())
}

/// What the header says.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
struct Header {
    rows: usize,
    cols: usize,
    f32: bool,
    big_endian: bool,
    fortran: bool,
}

fn read_header(r: &mut impl Read) -> Result<Header, NpyError> {
    let mut pre = [0u8; 8];
    r.read_exact(&mut pre)
        .map_err(|_| bad("shorter than the magic string and version"))?;
    if &pre[..6] != MAGIC {
        return Err(bad("missing the \\x93NUMPY magic string"));
    }
    let len = match pre[6] {
        1 => {
            let mut b = [0u8; 2];
            r.read_exact(&mut b).map_err(|_| bad("truncated header"))?;
            usize::from(u16::from_le_bytes(b))
        }
        2 | 3 => {
            let mut b = [0u8; 4];
            r.read_exact(&mut b).map_err(|_| bad("truncated header"))?;
            u32::from_le_bytes(b) as usize
        }
        v => return Err(bad(format!("format version {v} is not supported"))),
    };
    if len > MAX_HEADER {
        return Err(bad(format!("header of {len} bytes is too long")));
    }
    let mut text = vec![0u8; len];
    r.read_exact(&mut text)
        .map_err(|_| bad("truncated header"))?;
    let text = String::from_utf8(text).map_err(|_| bad("header is not text"))?;
    parse_dict(&text)
}

/// Parses NumPy's header dictionary, e.g.
/// `{'descr': '<f8', 'fortran_order': False, 'shape': (3, 4), }`.
fn parse_dict(text: &str) -> Result<Header, NpyError> {
    let value = |key: &str| -> Result<&str, NpyError> {
        let at = text
            .find(&format!("'{key}'"))
            .ok_or_else(|| bad(format!("header has no '{key}'")))?;
        let rest = text[at + key.len() + 2..].trim_start();
        Ok(rest
            .strip_prefix(':')
            .ok_or_else(|| bad(format!("'{key}' has no value")))?
            .trim_start())
    };
    let descr = value("descr")?;
    let descr = descr
        .strip_prefix('\'')
        .and_then(|d| d.split_once('\''))
        .map(|(d, _)| d)
        .ok_or_else(|| bad("descr is not a string"))?;
    let (f32, big_endian) = match descr {
        "<f8" | "=f8" | "f8" => (false, false),
        ">f8" => (false, true),
        "<f4" | "=f4" | "f4" => (true, false),
        ">f4" => (true, true),
        other => {
            return Err(bad(format!(
                "dtype {other:?}: only float64 and float32 arrays are read"
            )));
        }
    };
    let fortran = match value("fortran_order")? {
        v if v.starts_with("False") => false,
        v if v.starts_with("True") => true,
        _ => return Err(bad("fortran_order is not True or False")),
    };
    let shape = value("shape")?;
    let inner = shape
        .strip_prefix('(')
        .and_then(|s| s.split_once(')'))
        .map(|(s, _)| s)
        .ok_or_else(|| bad("shape is not a tuple"))?;
    let dims: Vec<usize> = inner
        .split(',')
        .map(str::trim)
        .filter(|s| !s.is_empty())
        .map(|s| s.trim_end_matches('L').parse::<usize>())
        .collect::<Result<_, _>>()
        .map_err(|_| bad(format!("shape ({inner}) is not a tuple of sizes")))?;
    let (rows, cols) = match dims[..] {
        [n] => (n, 1),
        [n, k] => (n, k),
        _ => {
            return Err(bad(format!(
                "shape ({inner}): a 1-D or 2-D array is needed"
            )));
        }
    };
    rows.checked_mul(cols)
        .and_then(|n| n.checked_mul(8))
        .ok_or_else(|| bad(format!("shape ({inner}) is too large")))?;
    Ok(Header {
        rows,
        cols,
        f32,
        big_endian,
        fortran,
    })
}

/// Reads a C-order `.npy` array one row at a time.
pub struct NpyReader<R: Read> {
    inner: R,
    header: Header,
    rows_read: usize,
    /// `float32` bytes as read (at most [`READ_BLOCK`]).
    bytes: Vec<u8>,
    /// One row for [`NpyReader::read_row`].
    row: Vec<f64>,
}

impl<R: Read> NpyReader<R> {
    /// Reads and checks the header. Fortran-order arrays are refused (use [`read_matrix`]).
    pub fn new(mut inner: R) -> Result<Self, NpyError> {
        let header = read_header(&mut inner)?;
        if header.fortran && header.rows > 1 && header.cols > 1 {
            return Err(bad(
                "Fortran-order arrays cannot be streamed by rows (save with C order)",
            ));
        }
        Ok(Self::with_header(inner, header))
    }

    fn with_header(inner: R, header: Header) -> Self {
        Self {
            inner,
            header,
            rows_read: 0,
            bytes: Vec::new(),
            row: Vec::new(),
        }
    }

    /// Rows the header declares.
    pub fn rows(&self) -> usize {
        self.header.rows
    }

    /// Values per row.
    pub fn cols(&self) -> usize {
        self.header.cols
    }

    /// Reads the next row into `out` (`cols` long); `Ok(false)` after the last row.
    pub fn read_row(&mut self, out: &mut [f64]) -> Result<bool, NpyError> {
        if self.rows_read == self.header.rows {
            return Ok(false);
        }
        if out.len() != self.header.cols {
            return Err(bad(format!(
                "row buffer of {} values for {} columns",
                out.len(),
                self.header.cols
            )));
        }
        let mut row = std::mem::take(&mut self.row);
        row.clear();
        let read = self.read_rows(&mut row, 1);
        if read.is_ok() {
            out.copy_from_slice(&row);
        }
        self.row = row;
        read.map(|_| true)
    }

    /// Appends up to `max_rows` further rows to `out` (row after row); returns how many
    /// were read, 0 after the last row. Memory grows with the data actually read, a block
    /// at a time, whatever the header declares.
    pub fn read_rows(&mut self, out: &mut Vec<f64>, max_rows: usize) -> Result<usize, NpyError> {
        let start = out.len();
        self.rows_at(out, start, max_rows)
    }

    /// Replaces `out`'s values by up to `max_rows` further rows, as [`NpyReader::read_rows`]
    /// reads them: the values `out` already holds are read over in place, without clearing
    /// them first, so a buffer used again costs no fresh memory.
    pub fn read_rows_over(
        &mut self,
        out: &mut Vec<f64>,
        max_rows: usize,
    ) -> Result<usize, NpyError> {
        self.rows_at(out, 0, max_rows)
    }

    /// Reads up to `max_rows` rows into `out` from position `start` on (values at and
    /// after `start` are read over); `out` ends after the last value read.
    fn rows_at(
        &mut self,
        out: &mut Vec<f64>,
        start: usize,
        max_rows: usize,
    ) -> Result<usize, NpyError> {
        let h = self.header;
        let n = max_rows.min(h.rows - self.rows_read);
        // Room for the rows asked for, up to what a few blocks hold (a header may declare
        // more than the file has).
        out.reserve(
            (start + n * h.cols)
                .min(start + 16 * READ_BLOCK / 8)
                .saturating_sub(out.len()),
        );
        if let Err(e) = self.read_values(out, start, n * h.cols) {
            let values = (out.len() - start) + self.rows_read * h.cols;
            out.truncate(start);
            return Err(match e {
                NpyError::Truncated { .. } => NpyError::Truncated {
                    values_read: values - values % h.cols.max(1),
                    expected: h.rows * h.cols,
                },
                e => e,
            });
        }
        out.truncate(start + n * h.cols);
        self.rows_read += n;
        Ok(n)
    }

    /// Reads `count` values into `out` from position `start` on, a block at a time (values
    /// `out` already holds there are read over, missing ones added); `out` ends after the
    /// last value read. On a short input the values of the whole blocks read stay and the
    /// error is `Truncated`.
    fn read_values(
        &mut self,
        out: &mut Vec<f64>,
        mut start: usize,
        count: usize,
    ) -> Result<(), NpyError> {
        let h = self.header;
        let width = if h.f32 { 4 } else { 8 };
        let mut left = count;
        while left > 0 {
            let piece = left.min(READ_BLOCK / width);
            let got = if h.f32 {
                self.bytes.resize(piece * 4, 0);
                let got = read_full(&mut self.inner, &mut self.bytes)?;
                let convert = if h.big_endian {
                    f32::from_be_bytes
                } else {
                    f32::from_le_bytes
                };
                out.truncate(start);
                out.extend(
                    self.bytes[..got - got % 4]
                        .chunks_exact(4)
                        .map(|b| f64::from(convert(b.try_into().expect("4 bytes")))),
                );
                got
            } else {
                // Straight into `out`'s memory (one copy from the reader), then to native
                // byte order in place (nothing to do for little-endian data on a
                // little-endian machine). Only values `out` does not hold yet are zeroed.
                if out.len() < start + piece {
                    out.resize(start + piece, 0.0);
                }
                let got = read_full(
                    &mut self.inner,
                    bytemuck::cast_slice_mut(&mut out[start..start + piece]),
                )?;
                if got < piece * 8 {
                    out.truncate(start + got / 8);
                }
                let values = &mut out[start..start + got / 8];
                if h.big_endian {
                    for v in values {
                        *v = f64::from_be_bytes(v.to_ne_bytes());
                    }
                } else if cfg!(target_endian = "big") {
                    for v in values {
                        *v = f64::from_le_bytes(v.to_ne_bytes());
                    }
                }
                got
            };
            if got < piece * width {
                return Err(NpyError::Truncated {
                    values_read: 0,
                    expected: 0,
                });
            }
            left -= piece;
            start += piece;
        }
        out.truncate(start);
        Ok(())
    }
}

/// Bytes read at a time by [`NpyReader::read_rows`]: memory for the values grows by this
/// much only as data arrives.
const READ_BLOCK: usize = 1 << 20;

/// Reads until `buf` is full or the input ends; returns the bytes read.
fn read_full(inner: &mut impl Read, buf: &mut [u8]) -> std::io::Result<usize> {
    let mut got = 0;
    while got < buf.len() {
        match inner.read(&mut buf[got..]) {
            Ok(0) => break,
            Ok(k) => got += k,
            Err(e) if e.kind() == std::io::ErrorKind::Interrupted => {}
            Err(e) => return Err(e),
        }
    }
    Ok(got)
}

/// Reads a whole array (C or Fortran order) as `(rows, cols, row-major values)`.
pub fn read_matrix(inner: impl Read) -> Result<(usize, usize, Vec<f64>), NpyError> {
    let mut inner = inner;
    let header = read_header(&mut inner)?;
    let (rows, cols) = (header.rows, header.cols);
    // Stream as if C-ordered with the dimensions swapped, then transpose if needed.
    let (r, c) = if header.fortran {
        (cols, rows)
    } else {
        (rows, cols)
    };
    let mut reader = NpyReader::with_header(
        inner,
        Header {
            rows: r,
            cols: c,
            fortran: false,
            ..header
        },
    );
    let mut data = Vec::new();
    // (Rows without values hold no data: nothing to read, however many.)
    while c > 0 && reader.read_rows(&mut data, 1 << 16)? > 0 {}
    if header.fortran {
        let mut t = vec![0.0; data.len()];
        for i in 0..rows {
            for j in 0..cols {
                t[i * cols + j] = data[j * rows + i];
            }
        }
        data = t;
    }
    Ok((rows, cols, data))
}

/// Writes a `rows x cols` float64 array (version 1.0, little-endian, C order) row by row.
pub struct NpyWriter<W: Write> {
    inner: W,
    rows: usize,
    cols: usize,
    written: usize,
}

impl<W: Write> NpyWriter<W> {
    /// Writes the header of a `rows x cols` array.
    pub fn new(mut inner: W, rows: usize, cols: usize) -> std::io::Result<Self> {
        let dict =
            format!("{{'descr': '<f8', 'fortran_order': False, 'shape': ({rows}, {cols}), }}");
        // Magic (6) + version (2) + length (2) + dict + padding + '\n', a multiple of 64.
        let unpadded = 10 + dict.len() + 1;
        let total = unpadded.div_ceil(64) * 64;
        let len = total - 10;
        let len16 = u16::try_from(len).map_err(|_| std::io::Error::other("npy header too long"))?;
        inner.write_all(MAGIC)?;
        inner.write_all(&[1, 0])?;
        inner.write_all(&len16.to_le_bytes())?;
        inner.write_all(dict.as_bytes())?;
        inner.write_all(&vec![b' '; len - dict.len() - 1])?;
        inner.write_all(b"\n")?;
        Ok(Self {
            inner,
            rows,
            cols,
            written: 0,
        })
    }

    /// Values per row.
    pub fn cols(&self) -> usize {
        self.cols
    }

    /// Writes the next row (`cols` values).
    pub fn write_row(&mut self, row: &[f64]) -> std::io::Result<()> {
        if row.len() != self.cols || self.written == self.rows {
            return Err(std::io::Error::other(format!(
                "npy row {} of {} values for a {} x {} array",
                self.written,
                row.len(),
                self.rows,
                self.cols
            )));
        }
        let mut bytes = [0u8; 8 * 64];
        for part in row.chunks(64) {
            for (b, v) in bytes.chunks_exact_mut(8).zip(part) {
                b.copy_from_slice(&v.to_le_bytes());
            }
            self.inner.write_all(&bytes[..8 * part.len()])?;
        }
        self.written += 1;
        Ok(())
    }

    /// Writes whole rows at once: `values` holds consecutive rows of `cols` values.
    pub fn write_rows(&mut self, values: &[f64]) -> std::io::Result<()> {
        let cols = self.cols.max(1);
        let rows = values.len() / cols;
        if values.len() % cols != 0 || rows > self.rows - self.written {
            return Err(std::io::Error::other(format!(
                "npy rows {}.. of {} values for a {} x {} array",
                self.written,
                values.len(),
                self.rows,
                self.cols
            )));
        }
        if cfg!(target_endian = "little") {
            // The values' own bytes are the file's.
            self.inner.write_all(bytemuck::cast_slice(values))?;
        } else {
            let mut bytes = Vec::with_capacity(8 * values.len().min(1 << 16));
            for part in values.chunks(1 << 16) {
                bytes.clear();
                bytes.extend(part.iter().flat_map(|v| v.to_le_bytes()));
                self.inner.write_all(&bytes)?;
            }
        }
        self.written += rows;
        Ok(())
    }

    /// Checks that every row was written and returns the writer.
    pub fn finish(mut self) -> std::io::Result<W> {
        if self.written != self.rows {
            return Err(std::io::Error::other(format!(
                "npy array declared {} rows but {} were written",
                self.rows, self.written
            )));
        }
        self.inner.flush()?;
        Ok(self.inner)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn write(rows: usize, cols: usize, data: &[f64]) -> Vec<u8> {
        let mut w = NpyWriter::new(Vec::new(), rows, cols).unwrap();
        for r in data.chunks(cols.max(1)).take(rows) {
            w.write_row(r).unwrap();
        }
        w.finish().unwrap()
    }

    #[test]
    fn header_is_aligned_and_round_trips() {
        for (rows, cols) in [(0, 3), (1, 1), (5, 4), (1000, 93)] {
            let data: Vec<f64> = (0..rows * cols).map(|i| i as f64 * 0.5 - 3.0).collect();
            let bytes = write(rows, cols, &data);
            let header_len = usize::from(u16::from_le_bytes([bytes[8], bytes[9]]));
            assert_eq!((10 + header_len) % 64, 0);
            assert_eq!(bytes[9 + header_len], b'\n');
            assert_eq!(read_matrix(&bytes[..]).unwrap(), (rows, cols, data));
        }
    }

    #[test]
    fn rows_in_blocks_match_rows_one_by_one() {
        let (rows, cols) = (700, 93);
        let data: Vec<f64> = (0..rows * cols).map(|i| (i as f64).sin() * 1e-3).collect();
        let mut w = NpyWriter::new(Vec::new(), rows, cols).unwrap();
        w.write_rows(&data[..300 * cols]).unwrap();
        w.write_rows(&data[300 * cols..]).unwrap();
        assert!(
            w.write_rows(&data[..cols]).is_err(),
            "more rows than declared"
        );
        let blocks = w.finish().unwrap();
        assert_eq!(blocks, write(rows, cols, &data));
        let mut w = NpyWriter::new(Vec::new(), 2, 3).unwrap();
        assert!(w.write_rows(&[1.0; 4]).is_err(), "not whole rows");
        let mut r = NpyReader::new(&blocks[..]).unwrap();
        let mut back = Vec::new();
        assert_eq!(r.read_rows(&mut back, 512).unwrap(), 512);
        assert_eq!(r.read_rows(&mut back, 512).unwrap(), rows - 512);
        assert_eq!(r.read_rows(&mut back, 512).unwrap(), 0);
        assert_eq!(back, data);
    }

    /// Reading rows in blocks larger than [`READ_BLOCK`] gives the values row by row
    /// reading gives, for every element type, and a file cut short inside a later block
    /// is truncated after its last whole row.
    #[test]
    fn block_reads_cross_read_blocks_for_every_element_type() {
        let (rows, cols) = (2100, 93);
        for descr in ["<f8", ">f8", "<f4", ">f4"] {
            let mut bytes = b"\x93NUMPY\x01\x00".to_vec();
            let dict = format!(
                "{{'descr': '{descr}', 'fortran_order': False, 'shape': ({rows}, {cols}), }}\n"
            );
            bytes.extend((dict.len() as u16).to_le_bytes());
            bytes.extend(dict.as_bytes());
            let header = bytes.len();
            let value = |i: usize| ((i as f64) * 0.37).sin() * 100.0;
            for i in 0..rows * cols {
                let v = value(i);
                bytes.extend(match descr {
                    "<f8" => v.to_le_bytes().to_vec(),
                    ">f8" => v.to_be_bytes().to_vec(),
                    "<f4" => (v as f32).to_le_bytes().to_vec(),
                    _ => (v as f32).to_be_bytes().to_vec(),
                });
            }
            let mut one = NpyReader::new(&bytes[..]).unwrap();
            let (mut by_row, mut row) = (Vec::new(), vec![0.0; cols]);
            while one.read_row(&mut row).unwrap() {
                by_row.extend_from_slice(&row);
            }
            assert_eq!(by_row.len(), rows * cols);
            let mut blocks = NpyReader::new(&bytes[..]).unwrap();
            let mut back = Vec::new();
            assert_eq!(blocks.read_rows(&mut back, 1500).unwrap(), 1500);
            assert_eq!(blocks.read_rows(&mut back, 1500).unwrap(), rows - 1500);
            assert_eq!(blocks.read_rows(&mut back, 1500).unwrap(), 0);
            assert_eq!(back, by_row, "{descr}");
            // Reading over a used buffer, longer or shorter than the rows, gives the same.
            let mut over = NpyReader::new(&bytes[..]).unwrap();
            let mut buf = vec![f64::NAN; 2000 * cols];
            let mut again = Vec::new();
            for (max, len) in [(1100, 1100), (600, 600), (1500, rows - 1700)] {
                assert_eq!(over.read_rows_over(&mut buf, max).unwrap(), len);
                assert_eq!(buf.len(), len * cols);
                again.extend_from_slice(&buf);
                buf.resize(if len == 1100 { 10 } else { 3000 * cols }, f64::NAN);
            }
            assert_eq!(over.read_rows_over(&mut buf, 5).unwrap(), 0);
            assert!(buf.is_empty());
            assert_eq!(again, by_row, "{descr} over a used buffer");
            let width = if descr.ends_with('8') { 8 } else { 4 };
            let cut = header + (1900 * cols + 5) * width;
            let mut short = NpyReader::new(&bytes[..cut]).unwrap();
            let mut some = Vec::new();
            assert_eq!(short.read_rows(&mut some, 1000).unwrap(), 1000);
            let err = short.read_rows(&mut some, 2000).unwrap_err();
            assert!(
                matches!(err, NpyError::Truncated { values_read, expected }
                    if values_read == 1900 * cols && expected == rows * cols),
                "{descr}: {err}"
            );
        }
    }

    /// A header that declares far more data than the file holds costs memory for the
    /// data present only, and reads as truncated.
    #[test]
    fn declared_sizes_beyond_the_data_are_truncated_without_allocating_them() {
        for shape in ["(1, 100000000000)", "(100000000000, 3)", "(100000000000,)"] {
            let mut bytes = b"\x93NUMPY\x01\x00".to_vec();
            let dict = format!("{{'descr': '<f8', 'fortran_order': False, 'shape': {shape}, }}\n");
            bytes.extend((dict.len() as u16).to_le_bytes());
            bytes.extend(dict.as_bytes());
            bytes.extend([0u8; 40]);
            assert!(
                matches!(read_matrix(&bytes[..]), Err(NpyError::Truncated { .. })),
                "{shape}"
            );
            let mut r = NpyReader::new(&bytes[..]).unwrap();
            let mut out = Vec::new();
            assert!(matches!(
                r.read_rows(&mut out, 1 << 16),
                Err(NpyError::Truncated { .. })
            ));
            assert!(out.is_empty(), "{shape}: a failed read appends nothing");
        }
        // Rows without values hold no data, however many are declared.
        let mut bytes = b"\x93NUMPY\x01\x00".to_vec();
        let dict = "{'descr': '<f8', 'fortran_order': False, 'shape': (1000000000000, 0), }\n";
        bytes.extend((dict.len() as u16).to_le_bytes());
        bytes.extend(dict.as_bytes());
        assert_eq!(
            read_matrix(&bytes[..]).unwrap(),
            (1_000_000_000_000, 0, vec![])
        );
    }

    /// Bytes NumPy 1.26 writes for `np.save(f, np.array([[1.5, -2.0], [3.0, 4.25]]))`.
    #[test]
    fn reads_numpy_output() {
        let mut bytes = b"\x93NUMPY\x01\x00\x76\x00".to_vec();
        let dict = "{'descr': '<f8', 'fortran_order': False, 'shape': (2, 2), }";
        bytes.extend(dict.as_bytes());
        bytes.extend(vec![b' '; 0x76 - dict.len() - 1]);
        bytes.push(b'\n');
        for v in [1.5f64, -2.0, 3.0, 4.25] {
            bytes.extend(v.to_le_bytes());
        }
        assert_eq!(
            read_matrix(&bytes[..]).unwrap(),
            (2, 2, vec![1.5, -2.0, 3.0, 4.25])
        );
    }

    #[test]
    fn fortran_order_float32_and_big_endian() {
        let mut bytes = b"\x93NUMPY\x01\x00".to_vec();
        let dict = "{'descr': '>f4', 'fortran_order': True, 'shape': (2, 3), }\n";
        bytes.extend((dict.len() as u16).to_le_bytes());
        bytes.extend(dict.as_bytes());
        // Column-major 2 x 3: [[1, 2, 3], [4, 5, 6]] stored as 1 4 2 5 3 6.
        for v in [1.0f32, 4.0, 2.0, 5.0, 3.0, 6.0] {
            bytes.extend(v.to_be_bytes());
        }
        assert_eq!(
            read_matrix(&bytes[..]).unwrap(),
            (2, 3, vec![1.0, 2.0, 3.0, 4.0, 5.0, 6.0])
        );
        assert!(matches!(
            NpyReader::new(&bytes[..]),
            Err(NpyError::Format(_))
        ));
    }

    #[test]
    fn malformed_files_are_typed_errors() {
        let good = write(3, 2, &[1.0; 6]);
        assert!(matches!(
            read_matrix(&good[..good.len() - 3]),
            Err(NpyError::Truncated {
                values_read: 4,
                expected: 6
            })
        ));
        for cut in [0, 5, 9, 20] {
            assert!(matches!(
                read_matrix(&good[..cut]),
                Err(NpyError::Format(_))
            ));
        }
        let swap = |from: &str, to: &str| {
            let s = String::from_utf8_lossy(&good).replace(from, to);
            s.into_bytes()
        };
        for (from, to) in [
            ("<f8", "<i8"),
            ("(3, 2)", "(3, 2, 1)"),
            ("(3, 2)", "(x, 2)"),
            ("(3, 2)", "(99999999999999999999, 2)"),
            ("False", "Maybe"),
        ] {
            assert!(
                matches!(read_matrix(&swap(from, to)[..]), Err(NpyError::Format(_))),
                "{from} -> {to}"
            );
        }
        let mut w = NpyWriter::new(Vec::new(), 1, 2).unwrap();
        assert!(w.write_row(&[1.0]).is_err());
        assert!(w.finish().is_err());
    }
}
