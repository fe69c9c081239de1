//! The binary layouts nearly every file has, decoded straight from the block buffer:
//! vertices whose properties are all scalars (a fixed record size, the coordinates at
//! fixed offsets), and faces that are a lone `uchar` count and three `int`/`uint` indices.

use std::io::Read;

use nalgebra::{Vector2, Vector3};

use super::super::text::{ParseError, Result};
use super::header::{Element, Kind, Scalar};
use super::records::{Records, decode};
use super::{Gathered, Role};

/// Reads every vertex of `el`, whose properties are all scalars.
pub(super) fn vertices<R: Read>(
    rd: &mut Records<'_, R>,
    el: &Element,
    roles: &[Role],
    out: &mut Gathered,
) -> Result<()> {
    let size = el.fixed_size().unwrap_or(0);
    let big = rd.big_endian();
    // (offset, type) of x, y, z and of u, v.
    let mut at = [(0, Scalar::U8); 5];
    let mut offset = 0;
    for (p, role) in el.props.iter().zip(roles) {
        let Kind::Scalar(ty) = p.kind else { continue };
        match *role {
            Role::Coord(c) => at[c] = (offset, ty),
            Role::Uv(c) => at[3 + c] = (offset, ty),
            Role::Unused => {}
        }
        offset += ty.size();
    }
    let get = |rec: &[u8], k: usize| decode(at[k].1, big, &rec[at[k].0..]).as_f64();
    if size == 0 {
        // Only without vertices: x, y and z take bytes.
        return Ok(());
    }
    let mut left = el.count;
    while left > 0 {
        if !rd.src.fill(size).map_err(|e| ParseError::io(0, e))? {
            return Err(rd.err(format!(
                "the file ends in element 'vertex' after {} of {} records",
                el.count - left,
                el.count
            )));
        }
        let bytes = rd.src.bytes();
        let k = left.min(bytes.len() / size);
        let records = bytes[..k * size].chunks_exact(size);
        out.positions.extend(
            records
                .clone()
                .map(|r| Vector3::new(get(r, 0), get(r, 1), get(r, 2))),
        );
        if let Some(uvs) = out.vertex_uv.as_mut() {
            uvs.extend(records.map(|r| Vector2::new(get(r, 3), get(r, 4))));
        }
        rd.src.consume(k * size);
        left -= k;
    }
    Ok(())
}

/// Reads the faces of `el` while they are triangles in the common layout (a lone
/// `vertex_indices` list of `uchar` length and `int` or `uint` items); returns how many
/// it read, the rest being left to the general path.
pub(super) fn triangles<R: Read>(
    rd: &mut Records<'_, R>,
    el: &Element,
    out: &mut Gathered,
) -> Result<usize> {
    let signed = match el.props.as_slice() {
        [p] => match p.kind {
            Kind::List {
                count: Scalar::U8,
                item: Scalar::I32,
            } => true,
            Kind::List {
                count: Scalar::U8,
                item: Scalar::U32,
            } => false,
            _ => return Ok(0),
        },
        _ => return Ok(0),
    };
    let big = rd.big_endian();
    let index = |b: &[u8]| {
        let a = [b[0], b[1], b[2], b[3]];
        let v = if big {
            u32::from_be_bytes(a)
        } else {
            u32::from_le_bytes(a)
        };
        // A negative `int` has its top bit set; `u32::MAX` is no vertex either.
        let ok = if signed { v >> 31 == 0 } else { v != u32::MAX };
        ok.then_some(v)
    };
    let mut done = 0;
    while done < el.count {
        if !rd.src.fill(13).map_err(|e| ParseError::io(0, e))? {
            break;
        }
        let bytes = rd.src.bytes();
        let k = (el.count - done).min(bytes.len() / 13);
        let mut used = 0;
        for rec in bytes[..13 * k].chunks_exact(13) {
            if rec[0] != 3 {
                break;
            }
            let (Some(a), Some(b), Some(c)) =
                (index(&rec[1..]), index(&rec[5..]), index(&rec[9..]))
            else {
                return Err(ParseError::new(
                    0,
                    format!(
                        "PLY: face {} has a negative or too large index",
                        done + used
                    ),
                ));
            };
            out.triangles.push([a, b, c]);
            used += 1;
        }
        let first = out.notes.polygons;
        out.notes.polygons += used;
        out.notes
            .polygon_of
            .extend(first as u32..(first + used) as u32);
        rd.src.consume(13 * used);
        done += used;
        if used < k {
            break;
        }
    }
    Ok(done)
}
