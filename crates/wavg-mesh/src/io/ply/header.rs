//! The PLY header: format, elements in file order, their properties and types.

use std::io::Read;

use super::super::source::Source;
use super::super::text::{ParseError, Result};

/// A property's numeric type.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) enum Scalar {
    I8,
    U8,
    I16,
    U16,
    I32,
    U32,
    F32,
    F64,
}

impl Scalar {
    fn from_name(name: &str) -> Option<Self> {
        Some(match name {
            "char" | "int8" => Self::I8,
            "uchar" | "uint8" => Self::U8,
            "short" | "int16" => Self::I16,
            "ushort" | "uint16" => Self::U16,
            "int" | "int32" => Self::I32,
            "uint" | "uint32" => Self::U32,
            "float" | "float32" => Self::F32,
            "double" | "float64" => Self::F64,
            _ => return None,
        })
    }

    /// The type's name in a PLY header, for messages.
    pub(super) fn name(self) -> &'static str {
        match self {
            Self::I8 => "char",
            Self::U8 => "uchar",
            Self::I16 => "short",
            Self::U16 => "ushort",
            Self::I32 => "int",
            Self::U32 => "uint",
            Self::F32 => "float",
            Self::F64 => "double",
        }
    }

    /// Bytes of one value in a binary file.
    pub(super) fn size(self) -> usize {
        match self {
            Self::I8 | Self::U8 => 1,
            Self::I16 | Self::U16 => 2,
            Self::I32 | Self::U32 | Self::F32 => 4,
            Self::F64 => 8,
        }
    }

    pub(super) fn is_float(self) -> bool {
        matches!(self, Self::F32 | Self::F64)
    }
}

/// A property: one value, or a list of values preceded by its length.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) enum Kind {
    Scalar(Scalar),
    List { count: Scalar, item: Scalar },
}

#[derive(Clone, Debug)]
pub(super) struct Property {
    pub name: String,
    pub kind: Kind,
}

#[derive(Clone, Debug)]
pub(super) struct Element {
    pub name: String,
    pub count: usize,
    pub props: Vec<Property>,
}

impl Element {
    /// The bytes of one binary record when every property is a scalar.
    pub(super) fn fixed_size(&self) -> Option<usize> {
        self.props.iter().try_fold(0, |n, p| match p.kind {
            Kind::Scalar(s) => Some(n + s.size()),
            Kind::List { .. } => None,
        })
    }

    /// The index of the scalar property named `name`.
    pub(super) fn scalar(&self, name: &str) -> Option<usize> {
        self.props
            .iter()
            .position(|p| p.name == name && matches!(p.kind, Kind::Scalar(_)))
    }
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) enum Encoding {
    Ascii,
    BinaryLittleEndian,
    BinaryBigEndian,
}

#[derive(Debug)]
pub(super) struct Header {
    pub encoding: Encoding,
    pub elements: Vec<Element>,
    /// Lines the header took (the data's first line is the next one).
    pub lines: usize,
}

/// Reads the header up to and including `end_header`.
pub(super) fn read<R: Read>(src: &mut Source<R>) -> Result<Header> {
    let mut lines = 0;
    let mut encoding = None;
    let mut elements: Vec<Element> = Vec::new();
    loop {
        let n = lines + 1;
        let raw = src
            .line()
            .map_err(|e| ParseError::io(n, e))?
            .ok_or_else(|| ParseError::new(n, "PLY: the header ends before end_header"))?;
        lines = n;
        let Ok(text) = std::str::from_utf8(raw) else {
            return Err(ParseError::new(n, "PLY: invalid UTF-8 in the header"));
        };
        let err = |m: String| ParseError::new(n, format!("PLY: {m}"));
        let mut words = text.split_ascii_whitespace();
        let keyword = words.next().unwrap_or("");
        if n == 1 {
            if keyword != "ply" || words.next().is_some() {
                return Err(err("the file does not start with 'ply'".into()));
            }
            continue;
        }
        match keyword {
            "" | "comment" | "obj_info" => {}
            "format" => {
                let kind = words.next().unwrap_or("");
                encoding = Some(match kind {
                    "ascii" => Encoding::Ascii,
                    "binary_little_endian" => Encoding::BinaryLittleEndian,
                    "binary_big_endian" => Encoding::BinaryBigEndian,
                    _ => return Err(err(format!("unknown format {kind:?}"))),
                });
                if !words.next().is_some_and(|v| v.starts_with('1')) {
                    return Err(err("expected version 1.0 after the format".into()));
                }
            }
            "element" => {
                let (Some(name), Some(count), None) = (words.next(), words.next(), words.next())
                else {
                    return Err(err("expected 'element NAME COUNT'".into()));
                };
                let count = count
                    .parse()
                    .map_err(|_| err(format!("element count {count:?} is not a count")))?;
                if elements.iter().any(|e| e.name == name) {
                    return Err(err(format!("element '{name}' is declared twice")));
                }
                elements.push(Element {
                    name: name.to_string(),
                    count,
                    props: Vec::new(),
                });
            }
            "property" => {
                let ty = |w: Option<&str>| {
                    let w = w.unwrap_or("");
                    Scalar::from_name(w).ok_or_else(|| err(format!("unknown type {w:?}")))
                };
                let first = words.next();
                let kind = if first == Some("list") {
                    let count = ty(words.next())?;
                    if count.is_float() {
                        return Err(err("a list's length must have an integer type".into()));
                    }
                    Kind::List {
                        count,
                        item: ty(words.next())?,
                    }
                } else {
                    Kind::Scalar(ty(first)?)
                };
                let (Some(name), None) = (words.next(), words.next()) else {
                    return Err(err("expected 'property TYPE NAME'".into()));
                };
                let Some(element) = elements.last_mut() else {
                    return Err(err("a property before any element".into()));
                };
                element.props.push(Property {
                    name: name.to_string(),
                    kind,
                });
            }
            "end_header" => break,
            _ => return Err(err(format!("unknown header line {keyword:?}"))),
        }
    }
    let encoding =
        encoding.ok_or_else(|| ParseError::new(lines, "PLY: the header has no format line"))?;
    Ok(Header {
        encoding,
        elements,
        lines,
    })
}
