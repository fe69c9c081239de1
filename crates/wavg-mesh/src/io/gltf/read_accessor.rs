//! Accessors decoded from their buffers: every offset, stride and count checked against
//! the bytes present before the output is allocated; sparse accessors applied with their
//! indices checked.

use std::borrow::Cow;

use gltf::accessor::{DataType, Dimensions};
use nalgebra::{Vector2, Vector3};

use super::read_limits::Budget;

/// The bytes of one accessor's elements inside a buffer view.
struct Strided<'b> {
    bytes: &'b [u8],
    stride: usize,
    count: usize,
}

impl<'b> Strided<'b> {
    fn element(&self, i: usize) -> &'b [u8] {
        &self.bytes[i * self.stride..]
    }
}

/// The buffers of a file and the reading budget: what every accessor is decoded from.
pub(crate) struct Source<'a> {
    /// Every buffer's bytes, in document order.
    pub buffers: Vec<Cow<'a, [u8]>>,
    /// Elements left to read.
    pub budget: Budget,
}

fn what(acc: &gltf::Accessor) -> String {
    format!("accessor {}", acc.index())
}

/// The `count` elements of `size` bytes at `offset` in `view`, with the view's stride:
/// checked against the view and the view against its buffer.
fn strided<'b>(
    buffers: &'b [Cow<'_, [u8]>],
    view: &gltf::buffer::View,
    offset: usize,
    count: usize,
    size: usize,
    name: &str,
) -> Result<Strided<'b>, String> {
    let buf = &buffers[view.buffer().index()];
    let view_bytes = view
        .offset()
        .checked_add(view.length())
        .and_then(|end| buf.get(view.offset()..end))
        .ok_or_else(|| {
            format!(
                "buffer view {} (bytes {}..+{}) lies past the end of buffer {} ({} bytes)",
                view.index(),
                view.offset(),
                view.length(),
                view.buffer().index(),
                buf.len()
            )
        })?;
    let stride = view.stride().unwrap_or(size);
    if stride < size {
        return Err(format!(
            "{name}: byte stride {stride} is smaller than its element ({size} bytes)"
        ));
    }
    let needed = match count {
        0 => Some(0),
        n => (n - 1)
            .checked_mul(stride)
            .and_then(|b| b.checked_add(size))
            .and_then(|b| b.checked_add(offset)),
    };
    match needed {
        Some(n) if n <= view_bytes.len() => Ok(Strided {
            bytes: &view_bytes[offset.min(view_bytes.len())..],
            stride,
            count,
        }),
        _ => Err(format!(
            "{name}: {count} elements of {size} bytes (stride {stride}) from byte {offset} do \
             not fit in buffer view {} ({} bytes)",
            view.index(),
            view_bytes.len()
        )),
    }
}

/// Appends an accessor's elements to `out`, decoded with `decode` (given an element's
/// bytes, at least the element's size): from its buffer view, or zeros without one, then
/// its sparse values.
fn decode_into<T: Copy>(
    src: &mut Source,
    acc: &gltf::Accessor,
    out: &mut Vec<T>,
    zero: T,
    decode: impl Fn(&[u8]) -> T,
) -> Result<(), String> {
    let name = what(acc);
    let (count, size) = (acc.count(), acc.size());
    let start = out.len();
    match acc.view() {
        Some(view) => {
            let s = strided(&src.buffers, &view, acc.offset(), count, size, &name)?;
            src.budget.take(count as u64, &name)?;
            out.reserve(count);
            out.extend(s.bytes.chunks(s.stride).take(s.count).map(&decode));
        }
        None if acc.sparse().is_some() => {
            src.budget.take(count as u64, &name)?;
            out.resize(start + count, zero);
        }
        None => {
            return Err(format!(
                "{name} has neither a buffer view nor sparse values"
            ));
        }
    }
    let out = &mut out[start..];
    if let Some(sparse) = acc.sparse() {
        let n = sparse.count();
        let idx = sparse.indices();
        let isize = match idx.index_type() {
            gltf::accessor::sparse::IndexType::U8 => 1,
            gltf::accessor::sparse::IndexType::U16 => 2,
            gltf::accessor::sparse::IndexType::U32 => 4,
        };
        let sparse_name = format!("{name} (sparse)");
        let is = strided(
            &src.buffers,
            &idx.view(),
            idx.offset(),
            n,
            isize,
            &sparse_name,
        )?;
        let vals = sparse.values();
        let vs = strided(
            &src.buffers,
            &vals.view(),
            vals.offset(),
            n,
            size,
            &sparse_name,
        )?;
        for k in 0..n {
            let at = unsigned(is.element(k), isize);
            let slot = usize::try_from(at)
                .ok()
                .and_then(|a| out.get_mut(a))
                .ok_or_else(|| {
                    format!("{sparse_name}: index {at} is out of range (count {count})")
                })?;
            *slot = decode(vs.element(k));
        }
    }
    Ok(())
}

fn unsigned(b: &[u8], size: usize) -> u32 {
    match size {
        1 => b[0] as u32,
        2 => u16::from_le_bytes([b[0], b[1]]) as u32,
        _ => u32::from_le_bytes([b[0], b[1], b[2], b[3]]),
    }
}

fn f32_at(b: &[u8], k: usize) -> f32 {
    f32::from_le_bytes([b[4 * k], b[4 * k + 1], b[4 * k + 2], b[4 * k + 3]])
}

/// Appends a `VEC3` float accessor (POSITION) to `out`.
pub(crate) fn vec3(
    src: &mut Source,
    acc: &gltf::Accessor,
    out: &mut Vec<Vector3<f64>>,
) -> Result<(), String> {
    if acc.dimensions() != Dimensions::Vec3 || acc.data_type() != DataType::F32 {
        return Err(format!(
            "{}: positions must be VEC3 of FLOAT, not {:?} of {:?}",
            what(acc),
            acc.dimensions(),
            acc.data_type()
        ));
    }
    // An element has its 12 bytes (checked by `strided`); as an array they decode
    // without a bounds check per byte.
    decode_into(src, acc, out, Vector3::zeros(), |b| {
        match b.first_chunk::<12>() {
            Some(c) => Vector3::new(f32_at(c, 0), f32_at(c, 1), f32_at(c, 2)).cast(),
            None => Vector3::zeros(),
        }
    })
}

/// Appends a `VEC2` texture-coordinate accessor to `out`: float, or normalised unsigned
/// byte or short.
pub(crate) fn vec2(
    src: &mut Source,
    acc: &gltf::Accessor,
    out: &mut Vec<Vector2<f64>>,
) -> Result<(), String> {
    if acc.dimensions() != Dimensions::Vec2 {
        return Err(format!(
            "{}: texture coordinates must be VEC2, not {:?}",
            what(acc),
            acc.dimensions()
        ));
    }
    match (acc.data_type(), acc.normalized()) {
        (DataType::F32, _) => decode_into(src, acc, out, Vector2::zeros(), |b| {
            Vector2::new(f32_at(b, 0), f32_at(b, 1)).cast()
        }),
        (DataType::U8, true) => decode_into(src, acc, out, Vector2::zeros(), |b| {
            Vector2::new(b[0] as f32 / 255.0, b[1] as f32 / 255.0).cast()
        }),
        (DataType::U16, true) => decode_into(src, acc, out, Vector2::zeros(), |b| {
            Vector2::new(
                u16::from_le_bytes([b[0], b[1]]) as f32 / 65535.0,
                u16::from_le_bytes([b[2], b[3]]) as f32 / 65535.0,
            )
            .cast()
        }),
        (t, n) => Err(format!(
            "{}: texture coordinates of {t:?}{} (glTF allows FLOAT and normalised \
             UNSIGNED_BYTE or UNSIGNED_SHORT)",
            what(acc),
            if n { " normalised" } else { "" }
        )),
    }
}

/// A `SCALAR` unsigned index accessor.
pub(crate) fn indices(src: &mut Source, acc: &gltf::Accessor) -> Result<Vec<u32>, String> {
    let mut out = Vec::new();
    let size = match (acc.dimensions(), acc.data_type()) {
        (Dimensions::Scalar, DataType::U8) => 1,
        (Dimensions::Scalar, DataType::U16) => 2,
        (Dimensions::Scalar, DataType::U32) => 4,
        (d, t) => {
            return Err(format!(
                "{}: indices must be SCALAR of an unsigned type, not {d:?} of {t:?}",
                what(acc)
            ));
        }
    };
    decode_into(src, acc, &mut out, 0, |b| unsigned(b, size))?;
    Ok(out)
}

/// Appends the triangles of a `TRIANGLES` primitive's index accessor to `out` (a
/// trailing incomplete triangle is dropped): straight from the buffer in the common
/// case of tightly packed indices without sparse values.
pub(crate) fn triangle_list(
    src: &mut Source,
    acc: &gltf::Accessor,
    out: &mut Vec<[u32; 3]>,
) -> Result<(), String> {
    let packed = acc.sparse().is_none()
        && acc.dimensions() == Dimensions::Scalar
        && acc
            .view()
            .is_some_and(|v| v.stride().is_none_or(|s| s == acc.size()));
    let view = match acc.view() {
        Some(view) if packed => view,
        _ => {
            let idx = indices(src, acc)?;
            out.extend(idx.chunks_exact(3).map(|c| [c[0], c[1], c[2]]));
            return Ok(());
        }
    };
    let size = match acc.data_type() {
        DataType::U8 => 1,
        DataType::U16 => 2,
        DataType::U32 => 4,
        _ => return indices(src, acc).map(|_| ()),
    };
    let name = what(acc);
    let count = acc.count();
    let s = strided(&src.buffers, &view, acc.offset(), count, size, &name)?;
    src.budget.take(count as u64, &name)?;
    let bytes = &s.bytes[..count / 3 * 3 * size];
    out.reserve(count / 3);
    match size {
        4 => out.extend(bytes.chunks_exact(12).map(|c| {
            let at = |k: usize| u32::from_le_bytes([c[k], c[k + 1], c[k + 2], c[k + 3]]);
            [at(0), at(4), at(8)]
        })),
        _ => out.extend(
            bytes
                .chunks_exact(3 * size)
                .map(|c| [0, 1, 2].map(|k| unsigned(&c[k * size..], size))),
        ),
    }
    Ok(())
}
