//! The checksums and mesh fingerprints of the `.wavg` format: version 1's FNV-1a 64, a
//! byte at a time, and version 2's word hash, a 64-bit word at a time (about eight times
//! fewer dependent multiplications, so checksumming no longer bounds reading and writing).

use wavg_mesh::TriMesh;

/// FNV-1a 64 of `bytes`, continuing from state `h` (start with [`FNV_OFFSET`]).
#[inline]
pub fn fnv1a64(mut h: u64, bytes: &[u8]) -> u64 {
    for &b in bytes {
        h = (h ^ u64::from(b)).wrapping_mul(FNV_PRIME);
    }
    h
}

/// FNV-1a 64 initial state.
pub const FNV_OFFSET: u64 = 0xcbf2_9ce4_8422_2325;
const FNV_PRIME: u64 = 0x0000_0100_0000_01b3;

/// The version-1 mesh fingerprint: FNV-1a 64 over the counts, positions and triangles
/// (see the format documentation for the exact bytes).
///
/// ```
/// use wavg_embed::file::mesh_hash;
/// let a = wavg_mesh::procedural::icosphere(1);
/// let mut b = a.clone();
/// b.positions[0].x += 1e-12;
/// assert_ne!(mesh_hash(&a), mesh_hash(&b));
/// ```
pub fn mesh_hash(mesh: &TriMesh) -> u64 {
    let mut h = FNV_OFFSET;
    h = fnv1a64(h, &(mesh.n_vertices() as u64).to_le_bytes());
    h = fnv1a64(h, &(mesh.n_faces() as u64).to_le_bytes());
    for p in &mesh.positions {
        for c in [p.x, p.y, p.z] {
            h = fnv1a64(h, &c.to_le_bytes());
        }
    }
    for t in &mesh.triangles {
        for i in t {
            h = fnv1a64(h, &i.to_le_bytes());
        }
    }
    h
}

const P1: u64 = 0x9e37_79b1_85eb_ca87;
const P2: u64 = 0xc2b2_ae3d_27d4_eb4f;
const P3: u64 = 0x1656_67b1_9e37_79f9;

/// The version-2 word hash, fed 64-bit words (little-endian when read from bytes).
///
/// Each word `w` updates the state `h` to `rotl(h ^ w·P2, 31)·P1` (mod 2⁶⁴), and
/// [`WordHash::finish`] applies xxHash64's avalanche. For a fixed state each step is a
/// bijection of the word, and for a fixed word a bijection of the state; the avalanche is a
/// bijection too. So any change confined to one word (any flipped bit, any changed byte)
/// changes the result, and the rotation spreads the high bits, which plain word-wise FNV
/// would leave in place (two flipped top bits would cancel).
///
/// ```
/// use wavg_embed::file::WordHash;
/// let mut a = WordHash::new();
/// a.bytes(&[1, 2, 3, 4, 5, 6, 7, 8]);
/// let mut b = WordHash::new();
/// b.word(0x0807_0605_0403_0201);
/// assert_eq!(a.finish(), b.finish());
/// ```
#[derive(Clone, Copy, Debug)]
pub struct WordHash {
    h: u64,
}

impl Default for WordHash {
    fn default() -> Self {
        Self::new()
    }
}

impl WordHash {
    /// The initial state.
    pub const fn new() -> Self {
        Self {
            h: 0x2545_f491_4f6c_dd1d,
        }
    }

    /// Feeds one word.
    #[inline(always)]
    pub fn word(&mut self, w: u64) {
        self.h = (self.h ^ w.wrapping_mul(P2))
            .rotate_left(31)
            .wrapping_mul(P1);
    }

    /// Feeds `bytes` as little-endian words; a last partial word is padded with zero bytes
    /// (every caller in the format feeds whole words, so chunks concatenate).
    #[inline]
    pub fn bytes(&mut self, bytes: &[u8]) {
        let mut words = bytes.chunks_exact(8);
        for w in &mut words {
            let mut a = [0u8; 8];
            a.copy_from_slice(w);
            self.word(u64::from_le_bytes(a));
        }
        let rest = words.remainder();
        if !rest.is_empty() {
            let mut a = [0u8; 8];
            a[..rest.len()].copy_from_slice(rest);
            self.word(u64::from_le_bytes(a));
        }
    }

    /// The hash of everything fed so far (the state is left as it was).
    pub fn finish(&self) -> u64 {
        let mut h = self.h;
        h ^= h >> 33;
        h = h.wrapping_mul(P2);
        h ^= h >> 29;
        h = h.wrapping_mul(P3);
        h ^ (h >> 32)
    }
}

/// The version-2 mesh fingerprint: [`WordHash`] over the words `n_vertices`, `n_faces`,
/// each vertex's `x, y, z` bit patterns, then each triangle's `i0 | i1 << 32` and `i2`.
///
/// ```
/// use wavg_embed::file::mesh_fingerprint;
/// let a = wavg_mesh::procedural::icosphere(1);
/// let mut b = a.clone();
/// b.positions[0].x += 1e-12;
/// assert_ne!(mesh_fingerprint(&a), mesh_fingerprint(&b));
/// ```
pub fn mesh_fingerprint(mesh: &TriMesh) -> u64 {
    let mut h = WordHash::new();
    h.word(mesh.n_vertices() as u64);
    h.word(mesh.n_faces() as u64);
    for p in &mesh.positions {
        h.word(p.x.to_bits());
        h.word(p.y.to_bits());
        h.word(p.z.to_bits());
    }
    for t in &mesh.triangles {
        h.word(u64::from(t[0]) | u64::from(t[1]) << 32);
        h.word(u64::from(t[2]));
    }
    h.finish()
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    #[test]
    fn fnv1a64_reference_values() {
        // Published FNV-1a 64 test vectors.
        assert_eq!(fnv1a64(FNV_OFFSET, b""), 0xcbf29ce484222325);
        assert_eq!(fnv1a64(FNV_OFFSET, b"a"), 0xaf63dc4c8601ec8c);
        assert_eq!(fnv1a64(FNV_OFFSET, b"foobar"), 0x85944171f73967e8);
    }

    fn hash(b: &[u8]) -> u64 {
        let mut h = WordHash::new();
        h.bytes(b);
        h.finish()
    }

    /// Pinned values (also computed by an independent Python transcription of the
    /// format's definition): the checksum must never change within version 2.
    #[test]
    fn word_hash_reference_values() {
        assert_eq!(hash(b""), 0xca97_d94c_f756_ee5a);
        assert_eq!(hash(&[0u8; 8]), 0x6b49_0e14_5c17_14a3);
        assert_eq!(hash(b"wavg-v2-checksum"), 0x2369_460c_7541_8afc);
    }

    #[test]
    fn every_flipped_bit_of_a_block_changes_the_hash() {
        let b: Vec<u8> = (0..256u32).map(|i| (i * 37 % 251) as u8).collect();
        let h0 = hash(&b);
        for at in 0..b.len() {
            for bit in 0..8 {
                let mut c = b.clone();
                c[at] ^= 1 << bit;
                assert_ne!(hash(&c), h0, "bit {bit} of byte {at}");
            }
        }
    }

    #[test]
    fn chunks_of_whole_words_concatenate() {
        let b: Vec<u8> = (0..200u8).collect();
        let mut h = WordHash::new();
        h.bytes(&b[..64]);
        h.bytes(&b[64..]);
        assert_eq!(h.finish(), hash(&b));
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(500))]
        /// Two flipped top bits (where a plain word-wise FNV cancels) are detected, as are
        /// other pairs of flips.
        #[test]
        fn two_flips_in_different_words_are_detected(
            a in 0usize..32, b in 0usize..32, bit_a in 0u32..64, bit_b in 0u32..64
        ) {
            prop_assume!(a != b);
            let words: Vec<u64> = (0..32u64).map(|i| i.wrapping_mul(0x9e37_79b9_7f4a_7c15)).collect();
            let run = |w: &[u64]| {
                let mut h = WordHash::new();
                w.iter().for_each(|&x| h.word(x));
                h.finish()
            };
            let mut c = words.clone();
            c[a] ^= 1 << bit_a;
            c[b] ^= 1 << bit_b;
            prop_assert_ne!(run(&c), run(&words));
        }
    }

    #[test]
    fn the_fingerprint_sees_every_field() {
        let m = wavg_mesh::procedural::icosphere(1);
        let f = mesh_fingerprint(&m);
        let mut signed = m.clone();
        signed.positions[3].z = -signed.positions[3].z;
        assert_ne!(mesh_fingerprint(&signed), f);
        let mut rotated = m.clone();
        let t = rotated.triangles[5];
        rotated.triangles[5] = [t[1], t[2], t[0]];
        assert_ne!(mesh_fingerprint(&rotated), f);
        let mut last = m.clone();
        let n = last.triangles.len() - 1;
        last.triangles[n][2] ^= 1;
        assert_ne!(mesh_fingerprint(&last), f);
    }
}
