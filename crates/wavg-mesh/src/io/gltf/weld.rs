//! Welding by exactly equal positions: glTF splits a vertex wherever its texture
//! coordinate or normal changes, so every UV seam and sharp edge is a cut until the
//! copies are merged again.
//!
//! One open-addressing table of `u64` slots (a hash tag and the welded index), at most
//! two thirds full, probed linearly: a lookup costs about one cache miss, and the positions
//! themselves are touched only when the tags agree. (A `HashMap` keyed by the bits took
//! most of the time of reading a large file.)

use nalgebra::Vector3;

/// Welds `positions` in place: they become the first copies, in order of first
/// appearance. Returns, for every input vertex, its welded index, or `None` when nothing
/// was merged (every vertex keeps its index). Equal means equal as
/// numbers (`-0.0 == 0.0`); a vertex with a NaN coordinate is never welded, so validation
/// still names it. At most `u32::MAX - 1` positions (the readers' limit).
pub(crate) fn weld(positions: &mut Vec<Vector3<f64>>) -> Option<Vec<u32>> {
    let n = positions.len();
    let slots = n.saturating_add(n / 2).max(2).next_power_of_two();
    let bits = slots.trailing_zeros();
    let mask = (1usize << bits) - 1;
    // A slot holds `tag << 32 | (index + 1)`; 0 is empty.
    let mut table = vec![0u64; mask + 1];
    // Filled from the first merge on: until then every vertex is its own.
    let mut map = Vec::new();
    let mut next = 0usize;
    for i in 0..n {
        let p = positions[i];
        let id = if p.iter().any(|c| c.is_nan()) {
            next
        } else {
            // Adding 0.0 turns -0.0 into 0.0 and leaves every other value as it is.
            let h = hash([p.x + 0.0, p.y + 0.0, p.z + 0.0].map(f64::to_bits));
            let tag = h & 0xFFFF_FFFF_0000_0000;
            let mut slot = (h >> (64 - bits)) as usize;
            loop {
                let e = table[slot];
                if e == 0 {
                    table[slot] = tag | (next as u64 + 1);
                    break next;
                }
                let at = (e & 0xFFFF_FFFF) as usize - 1;
                if e & 0xFFFF_FFFF_0000_0000 == tag && positions[at] == p {
                    break at;
                }
                slot = (slot + 1) & mask;
            }
        };
        if id == next {
            positions[next] = p;
            next += 1;
        } else if map.is_empty() {
            map.reserve_exact(n);
            map.extend(0..i as u32);
        }
        if !map.is_empty() {
            map.push(id as u32);
        }
    }
    positions.truncate(next);
    (next < n).then_some(map)
}

/// Spreads every bit of `x` over the whole word (a bijection).
fn mix(x: u64) -> u64 {
    let x = (x ^ (x >> 32)).wrapping_mul(0x9E37_79B9_7F4A_7C15);
    x ^ (x >> 29)
}

/// A hash of three coordinates' bits whose top bits (the slot) and upper half (the tag)
/// both depend on every input bit: coordinates read from `f32` have 29 zero low bits.
fn hash(k: [u64; 3]) -> u64 {
    let h = mix(mix(mix(k[0]) ^ k[1]) ^ k[2]);
    h.wrapping_mul(0xD6E8_FEB8_6659_FD93)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn equal_positions_merge_and_nan_stays_apart() {
        let v = |x: f64, y: f64| Vector3::new(x, y, 0.0);
        let input = [
            v(0.0, 0.0),
            v(1.0, 0.0),
            v(-0.0, 0.0),
            v(f64::NAN, 0.0),
            v(f64::NAN, 0.0),
            v(1.0, 1e-300),
            v(1.0, 0.0),
        ];
        let mut out = input.to_vec();
        let map = weld(&mut out).unwrap();
        assert_eq!(map, [0, 1, 0, 2, 3, 4, 1]);
        assert_eq!(out.len(), 5);
        assert_eq!(out[0], v(0.0, 0.0));
        assert!(out[2].x.is_nan() && out[3].x.is_nan());
        assert_eq!(out[4], v(1.0, 1e-300));
    }

    #[test]
    fn without_equal_positions_nothing_is_mapped() {
        let mut v = vec![
            Vector3::new(0.0, 0.0, 0.0),
            Vector3::new(f64::NAN, 0.0, 0.0),
            Vector3::new(f64::NAN, 0.0, 0.0),
            Vector3::new(0.0, 0.0, 1.0),
        ];
        assert_eq!(weld(&mut v), None);
        assert_eq!(v.len(), 4);
        assert_eq!(weld(&mut Vec::new()), None);
    }

    #[test]
    fn many_colliding_keys_weld_as_a_map_would() {
        // A grid of f32-exact values (zero low bits) with every point written twice,
        // the copies in reverse order, against a plain map.
        let mut input = Vec::new();
        for i in 0..60 {
            for j in 0..50 {
                input.push(Vector3::new(i as f32 as f64 * 0.25, j as f64, -(i as f64)));
            }
        }
        let copies: Vec<_> = input.iter().rev().copied().collect();
        input.extend(copies);
        let mut first = std::collections::HashMap::new();
        let expected: Vec<u32> = input
            .iter()
            .map(|p| {
                let next = first.len() as u32;
                *first
                    .entry([p.x, p.y, p.z].map(|c: f64| (c + 0.0).to_bits()))
                    .or_insert(next)
            })
            .collect();
        let mut out = input.clone();
        let map = weld(&mut out).unwrap();
        assert_eq!(map, expected);
        assert_eq!(out, input[..3000]);
    }
}
