//! Welding by exactly equal positions: glTF splits a vertex wherever its texture
//! coordinate or normal changes, so every UV seam and sharp edge is a cut until the
//! copies are merged again.

use std::collections::HashMap;
use std::hash::{BuildHasherDefault, Hasher};

use nalgebra::Vector3;

/// A multiply-rotate hash of the coordinates' bits (the standard SipHash costs more than
/// the rest of reading a large file).
#[derive(Default)]
struct BitsHasher(u64);

impl Hasher for BitsHasher {
    fn finish(&self) -> u64 {
        self.0
    }
    fn write(&mut self, bytes: &[u8]) {
        for &b in bytes {
            self.write_u64(b as u64);
        }
    }
    fn write_u64(&mut self, x: u64) {
        self.0 = (self.0.rotate_left(5) ^ x).wrapping_mul(0x51_7c_c1_b7_27_22_0a_95);
    }
}

/// The welded positions (first copies, in order of first appearance) and, for every input
/// vertex, its welded index. Equal means equal as numbers (`-0.0 == 0.0`); a vertex with
/// a NaN coordinate is never welded, so validation still names it.
pub(crate) fn weld(positions: &[Vector3<f64>]) -> (Vec<Vector3<f64>>, Vec<u32>) {
    let mut first: HashMap<[u64; 3], u32, BuildHasherDefault<BitsHasher>> =
        HashMap::with_capacity_and_hasher(positions.len(), Default::default());
    let mut out = Vec::with_capacity(positions.len());
    let mut map = Vec::with_capacity(positions.len());
    for p in positions {
        let next = out.len() as u32;
        let id = if p.iter().any(|c| c.is_nan()) {
            next
        } else {
            // Adding 0.0 turns -0.0 into 0.0 and leaves every other value as it is.
            let key = [p.x + 0.0, p.y + 0.0, p.z + 0.0].map(f64::to_bits);
            *first.entry(key).or_insert(next)
        };
        if id == next {
            out.push(*p);
        }
        map.push(id);
    }
    (out, map)
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
        let (out, map) = weld(&input);
        assert_eq!(map, [0, 1, 0, 2, 3, 4, 1]);
        assert_eq!(out.len(), 5);
        assert_eq!(out[0], v(0.0, 0.0));
    }
}
