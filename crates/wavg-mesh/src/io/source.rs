//! The one buffer every mesh reader parses from: bytes pulled from any source (a file, a
//! gzip stream, memory) a large block at a time, handed out as lines or as byte runs, so a
//! reader never holds the whole file beside the mesh it builds.

use std::io::{ErrorKind, Read};

/// Bytes read from the source at a time.
pub(crate) const BLOCK: usize = 1 << 20;

/// A growable window over a byte stream.
pub(crate) struct Source<R> {
    inner: R,
    buf: Vec<u8>,
    /// The unread bytes are `buf[pos..end]`.
    pos: usize,
    end: usize,
    eof: bool,
    /// Where the line last returned by [`Self::line`] lies in `buf`.
    last: std::ops::Range<usize>,
}

impl<R: Read> Source<R> {
    pub(crate) fn new(inner: R) -> Self {
        Self {
            inner,
            buf: Vec::new(),
            pos: 0,
            end: 0,
            eof: false,
            last: 0..0,
        }
    }

    /// The bytes read and not yet consumed.
    #[inline]
    pub(crate) fn bytes(&self) -> &[u8] {
        &self.buf[self.pos..self.end]
    }

    /// Marks `n` of [`Self::bytes`] as consumed.
    #[inline]
    pub(crate) fn consume(&mut self, n: usize) {
        debug_assert!(n <= self.end - self.pos);
        self.pos += n;
    }

    /// Makes at least `n` bytes available in [`Self::bytes`]; `false` when the data ends
    /// first (then what is left is still there).
    #[inline]
    pub(crate) fn fill(&mut self, n: usize) -> std::io::Result<bool> {
        if self.end - self.pos >= n {
            return Ok(true);
        }
        self.refill(n)
    }

    /// Moves the unread bytes to the front, grows the buffer if `n` does not fit, and
    /// reads until `n` bytes are there or the data ends.
    #[cold]
    fn refill(&mut self, n: usize) -> std::io::Result<bool> {
        self.buf.copy_within(self.pos..self.end, 0);
        self.end -= self.pos;
        self.pos = 0;
        let want = n.max(BLOCK);
        if self.buf.len() < want {
            let grown = want.max(2 * self.buf.len());
            self.buf.resize(grown, 0);
        }
        while self.end < n && !self.eof {
            match self.inner.read(&mut self.buf[self.end..]) {
                Ok(0) => self.eof = true,
                Ok(k) => self.end += k,
                Err(e) if e.kind() == ErrorKind::Interrupted => {}
                Err(e) => return Err(e),
            }
        }
        Ok(self.end >= n)
    }

    /// The next line without its `\n` (or `\r\n`), `None` at the end of the data. A last
    /// line without a newline counts.
    pub(crate) fn line(&mut self) -> std::io::Result<Option<&[u8]>> {
        let mut searched = 0;
        loop {
            let unread = &self.buf[self.pos + searched..self.end];
            if let Some(i) = memchr::memchr(b'\n', unread) {
                let (start, stop) = (self.pos, self.pos + searched + i);
                self.pos = stop + 1;
                let cr = stop > start && self.buf[stop - 1] == b'\r';
                self.last = start..stop - usize::from(cr);
                return Ok(Some(&self.buf[self.last.clone()]));
            }
            searched = self.end - self.pos;
            if !self.fill(searched + 1)? {
                if searched == 0 {
                    return Ok(None);
                }
                self.last = self.pos..self.end;
                self.pos = self.end;
                return Ok(Some(&self.buf[self.last.clone()]));
            }
        }
    }
}

impl<R> Source<R> {
    /// The line [`Self::line`] returned last (until the next read).
    pub(crate) fn last_line(&self) -> &[u8] {
        &self.buf[self.last.clone()]
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A reader handing out at most 3 bytes a call, so every path crosses refills.
    struct Trickle<'a>(&'a [u8]);

    impl Read for Trickle<'_> {
        fn read(&mut self, out: &mut [u8]) -> std::io::Result<usize> {
            let k = self.0.len().min(out.len()).min(3);
            out[..k].copy_from_slice(&self.0[..k]);
            self.0 = &self.0[k..];
            Ok(k)
        }
    }

    #[test]
    fn lines_across_refills_with_crlf_and_a_last_line_without_newline() {
        let long = "x".repeat(3 * BLOCK);
        let text = format!("a\r\n\nbc\n{long}\nlast");
        let mut s = Source::new(Trickle(text.as_bytes()));
        let mut got = Vec::new();
        while let Some(l) = s.line().unwrap() {
            got.push(String::from_utf8(l.to_vec()).unwrap());
        }
        assert_eq!(got, ["a", "", "bc", long.as_str(), "last"]);
    }

    /// Short lines through a long input: the buffer stays one block (the reader never
    /// holds the whole text).
    #[test]
    fn memory_is_one_block_whatever_the_input_length() {
        let text = "v 0.125 0.25 0.5\n".repeat(8 * BLOCK / 16);
        let mut s = Source::new(text.as_bytes());
        let mut n = 0;
        while let Some(l) = s.line().unwrap() {
            assert_eq!(l, b"v 0.125 0.25 0.5");
            n += 1;
        }
        assert_eq!(n, 8 * BLOCK / 16);
        assert_eq!(s.buf.len(), BLOCK);
    }

    #[test]
    fn fill_reports_the_end_and_keeps_the_rest() {
        let mut s = Source::new(Trickle(b"0123456789"));
        assert!(s.fill(4).unwrap());
        assert_eq!(&s.bytes()[..4], b"0123");
        s.consume(4);
        assert!(!s.fill(7).unwrap());
        assert_eq!(s.bytes(), b"456789");
    }
}
