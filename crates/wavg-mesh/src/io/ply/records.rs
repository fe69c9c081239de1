//! One value at a time from a PLY element's records, ASCII or binary: the general path,
//! which every layout takes (the common binary layouts have faster loops in `fast.rs`).

use std::io::Read;

use super::super::source::Source;
use super::super::text::{ParseError, Result};
use super::header::{Element, Encoding, Kind, Scalar};

/// A value as read: integers exactly, floats widened.
#[derive(Clone, Copy, Debug)]
pub(super) enum Num {
    Int(i64),
    Float(f64),
}

impl std::fmt::Display for Num {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Num::Int(i) => write!(f, "{i}"),
            Num::Float(x) => write!(f, "{x}"),
        }
    }
}

impl Num {
    pub(super) fn as_f64(self) -> f64 {
        match self {
            Num::Int(i) => i as f64,
            Num::Float(x) => x,
        }
    }
}

/// Decodes one binary value of type `ty` from the front of `b` (`b.len() >= ty.size()`).
#[inline]
pub(super) fn decode(ty: Scalar, big: bool, b: &[u8]) -> Num {
    macro_rules! get {
        ($t:ty, $n:expr) => {{
            let a: [u8; $n] = b[..$n].try_into().unwrap_or([0; $n]);
            if big {
                <$t>::from_be_bytes(a)
            } else {
                <$t>::from_le_bytes(a)
            }
        }};
    }
    match ty {
        Scalar::I8 => Num::Int(b[0] as i8 as i64),
        Scalar::U8 => Num::Int(b[0] as i64),
        Scalar::I16 => Num::Int(get!(i16, 2) as i64),
        Scalar::U16 => Num::Int(get!(u16, 2) as i64),
        Scalar::I32 => Num::Int(get!(i32, 4) as i64),
        Scalar::U32 => Num::Int(get!(u32, 4) as i64),
        Scalar::F32 => Num::Float(get!(f32, 4) as f64),
        Scalar::F64 => Num::Float(get!(f64, 8)),
    }
}

/// Reads the records of one element after another.
pub(super) struct Records<'a, R> {
    pub src: &'a mut Source<R>,
    pub encoding: Encoding,
    /// The current line (ASCII; the header's last line before the first record).
    pub line: usize,
    /// The current record's text and how far it was read (ASCII).
    text: String,
    at: usize,
}

impl<'a, R: Read> Records<'a, R> {
    pub(super) fn new(src: &'a mut Source<R>, encoding: Encoding, header_lines: usize) -> Self {
        Self {
            src,
            encoding,
            line: header_lines,
            text: String::new(),
            at: 0,
        }
    }

    pub(super) fn big_endian(&self) -> bool {
        self.encoding == Encoding::BinaryBigEndian
    }

    /// An error at the current line (ASCII) or without a line (binary).
    pub(super) fn err(&self, message: String) -> ParseError {
        let line = match self.encoding {
            Encoding::Ascii => self.line,
            _ => 0,
        };
        ParseError::new(line, format!("PLY: {message}"))
    }

    fn ends(&self, el: &Element, record: usize) -> ParseError {
        self.err(format!(
            "the file ends in element '{}' after {record} of {} records",
            el.name, el.count
        ))
    }

    /// Starts record `record` of `el` (ASCII: reads its line).
    pub(super) fn begin(&mut self, el: &Element, record: usize) -> Result<()> {
        if self.encoding != Encoding::Ascii {
            return Ok(());
        }
        let n = self.line + 1;
        let Some(raw) = self.src.line().map_err(|e| ParseError::io(n, e))? else {
            return Err(self.ends(el, record));
        };
        let Ok(text) = std::str::from_utf8(raw) else {
            return Err(ParseError::new(n, "PLY: invalid UTF-8 in ASCII data"));
        };
        self.text.clear();
        self.text.push_str(text);
        self.at = 0;
        self.line = n;
        Ok(())
    }

    /// Ends a record (ASCII: nothing may be left on its line).
    pub(super) fn finish(&mut self, el: &Element) -> Result<()> {
        if self.encoding == Encoding::Ascii && !self.text[self.at..].trim_ascii().is_empty() {
            return Err(self.err(format!(
                "more values on the line than element '{}' declares",
                el.name
            )));
        }
        Ok(())
    }

    /// The next value of type `ty` in record `record` of `el`.
    pub(super) fn value(&mut self, ty: Scalar, el: &Element, record: usize) -> Result<Num> {
        if self.encoding == Encoding::Ascii {
            return self.token(ty, el);
        }
        if !self.src.fill(ty.size()).map_err(|e| ParseError::io(0, e))? {
            return Err(self.ends(el, record));
        }
        let v = decode(ty, self.big_endian(), self.src.bytes());
        self.src.consume(ty.size());
        Ok(v)
    }

    /// The next ASCII token as a value of type `ty`.
    fn token(&mut self, ty: Scalar, el: &Element) -> Result<Num> {
        let rest = &self.text[self.at..];
        let start = rest.len() - rest.trim_ascii_start().len();
        let len = rest[start..]
            .find(|c: char| c.is_ascii_whitespace())
            .unwrap_or(rest.len() - start);
        let tok = &rest[start..start + len];
        self.at += start + len;
        if tok.is_empty() {
            return Err(self.err(format!(
                "fewer values on the line than element '{}' declares",
                el.name
            )));
        }
        let bad = || self.err(format!("{tok:?} is not a value of type {}", ty.name()));
        Ok(match ty {
            Scalar::F32 => Num::Float(tok.parse::<f32>().map_err(|_| bad())? as f64),
            Scalar::F64 => Num::Float(tok.parse::<f64>().map_err(|_| bad())?),
            _ => {
                let v: i64 = tok.parse().map_err(|_| bad())?;
                let (lo, hi) = match ty {
                    Scalar::I8 => (i8::MIN as i64, i8::MAX as i64),
                    Scalar::U8 => (0, u8::MAX as i64),
                    Scalar::I16 => (i16::MIN as i64, i16::MAX as i64),
                    Scalar::U16 => (0, u16::MAX as i64),
                    Scalar::I32 => (i32::MIN as i64, i32::MAX as i64),
                    _ => (0, u32::MAX as i64),
                };
                if !(lo..=hi).contains(&v) {
                    return Err(bad());
                }
                Num::Int(v)
            }
        })
    }

    /// A list's length.
    pub(super) fn length(&mut self, ty: Scalar, el: &Element, record: usize) -> Result<usize> {
        match self.value(ty, el, record)? {
            Num::Int(n) if n >= 0 => Ok(n as usize),
            v => Err(self.err(format!(
                "list length {v} in element '{}' is not a count (a whole number, 0 or more)",
                el.name
            ))),
        }
    }

    /// Reads one whole record of `el`, calling `each(property, value)` for every value
    /// (every item of a list, in order).
    pub(super) fn record(
        &mut self,
        el: &Element,
        record: usize,
        mut each: impl FnMut(usize, Num) -> Result<()>,
    ) -> Result<()> {
        self.begin(el, record)?;
        for (k, p) in el.props.iter().enumerate() {
            match p.kind {
                Kind::Scalar(ty) => each(k, self.value(ty, el, record)?)?,
                Kind::List { count, item } => {
                    let n = self.length(count, el, record)?;
                    for _ in 0..n {
                        each(k, self.value(item, el, record)?)?;
                    }
                }
            }
        }
        self.finish(el)
    }

    /// Reads past every record of `el`.
    pub(super) fn skip(&mut self, el: &Element) -> Result<()> {
        let fixed = el.fixed_size().filter(|_| self.encoding != Encoding::Ascii);
        if let Some(size) = fixed {
            let mut left = (size as u128) * (el.count as u128);
            while left > 0 {
                if !self.src.fill(1).map_err(|e| ParseError::io(0, e))? {
                    return Err(self.ends(el, el.count - (left / size as u128) as usize));
                }
                let k = (self.src.bytes().len() as u128).min(left);
                self.src.consume(k as usize);
                left -= k;
            }
            return Ok(());
        }
        for r in 0..el.count {
            self.record(el, r, |_, _| Ok(()))?;
        }
        Ok(())
    }
}
