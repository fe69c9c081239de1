//! Edge alignments `R_k` and in-plane rotations `E_k` of one triangle (the paper's
//! Section 3.2, by block coordinate descent), precomputed into its blend matrices `X_e`.

use super::{Frame32, TriData};
#[cfg(test)]
use crate::Mat2x8;
use crate::ort::{self, M2};

/// Block coordinate descent sweeps for the in-plane rotations.
pub(crate) const PROCRUSTES_SWEEPS: usize = 10;

/// Gram blocks `T_i T_j^T` of the three corner frames (`[C01, C12, C20]`).
#[cfg(test)]
fn frame_products(t: &[Mat2x8; 3]) -> [M2; 3] {
    [0, 1, 2].map(|i| {
        let (a, b) = (&t[i], &t[(i + 1) % 3]);
        let mut m = [0.0; 4];
        for r in 0..2 {
            for c in 0..2 {
                m[r * 2 + c] = a.row(r).dot(&b.row(c));
            }
        }
        m
    })
}

/// [`frame_products`] from stored frames.
fn frame_products32(t: &[&Frame32; 3]) -> [M2; 3] {
    [0, 1, 2].map(|i| {
        let (a, b) = (t[i], t[(i + 1) % 3]);
        let mut m = [0.0; 4];
        for r in 0..2 {
            for c in 0..2 {
                let mut s = 0.0;
                for k in 0..8 {
                    s += a[r * 8 + k] as f64 * b[c * 8 + k] as f64;
                }
                m[r * 2 + c] = s;
            }
        }
        m
    })
}

/// Everything the Procrustes step needs, in 2x2 blocks: the six un-rotated bases are
/// `Q_a T_{corner(a)}` with `Q = [R_0, I, R_1, I, R_2, I]`, so their Gram blocks are
/// `Q_a (T_i T_j^T) Q_b^T` and need only the three frame products `c`.
struct Procrustes {
    r: [M2; 3],
    q: [M2; 6],
    c: [M2; 3],
}

const CORNER: [usize; 6] = [0, 1, 1, 2, 2, 0];

impl Procrustes {
    #[cfg(test)]
    fn new(t: &[Mat2x8; 3]) -> Self {
        Self::from_products(frame_products(t))
    }

    fn from_products(c: [M2; 3]) -> Self {
        let mut s = Self {
            r: [ort::I2; 3],
            q: [ort::I2; 6],
            c,
        };
        // R_k = Ort(T_{k+1} T_k^T).
        s.r = [0, 1, 2].map(|k| ort::ort(&s.cross((k + 1) % 3, k)));
        s.q = [s.r[0], ort::I2, s.r[1], ort::I2, s.r[2], ort::I2];
        s
    }

    /// `T_i T_j^T`; frames are orthonormal so `T_i T_i^T = I`.
    #[inline]
    fn cross(&self, i: usize, j: usize) -> M2 {
        if i == j {
            ort::I2
        } else if (i + 1) % 3 == j {
            self.c[i]
        } else {
            ort::transpose(&self.c[j])
        }
    }

    /// Gram block `B_a B_b^T` of two un-rotated bases.
    #[inline]
    fn gram(&self, a: usize, b: usize) -> M2 {
        let m = ort::mul(&self.q[a], &self.cross(CORNER[a], CORNER[b]));
        ort::mul(&m, &ort::transpose(&self.q[b]))
    }

    /// Block coordinate descent from identities; returns `E` after `sweeps` sweeps.
    #[cfg(test)]
    fn rotations(&self, sweeps: usize) -> [M2; 3] {
        rotations_batch([self], sweeps)[0]
    }

    /// `h[j][k]`: the sum of the Gram blocks `G_ab` over `a` in pair `j`, `b` in pair `k`
    /// (`j != k`; `h[k][j] = h[j][k]^T`).
    fn pair_sums(&self) -> [[M2; 3]; 3] {
        let mut h = [[[0.0; 4]; 3]; 3];
        for (j, k) in [(0, 1), (0, 2), (1, 2)] {
            let mut m = [0.0; 4];
            for a in [2 * j, 2 * j + 1] {
                for b in [2 * k, 2 * k + 1] {
                    m = ort::add(&m, &self.gram(a, b));
                }
            }
            h[j][k] = m;
            h[k][j] = ort::transpose(&m);
        }
        h
    }

    /// `sum_{a<b} |A_a - A_b|^2` with `A_a = E_{pair(a)} B_a`.
    #[cfg(test)]
    fn energy(&self, e: &[M2; 3]) -> f64 {
        let mut s = 0.0;
        for a in 0..6 {
            for b in (a + 1)..6 {
                let (gaa, gbb) = (self.gram(a, a), self.gram(b, b));
                let cross = ort::mul(
                    &ort::mul(&e[a / 2], &self.gram(a, b)),
                    &ort::transpose(&e[b / 2]),
                );
                s += gaa[0] + gaa[3] + gbb[0] + gbb[3] - 2.0 * (cross[0] + cross[3]);
            }
        }
        s
    }
}

/// [`Procrustes::rotations`] for `N` independent triangles at once: the sweeps are a
/// chain of dependent square roots and divisions, interleaving triangles hides latency.
fn rotations_batch<const N: usize>(ps: [&Procrustes; N], sweeps: usize) -> [[M2; 3]; N] {
    let h: [[[M2; 3]; 3]; N] = std::array::from_fn(|n| ps[n].pair_sums());
    let mut e = [[ort::I2; 3]; N];
    for _ in 0..sweeps {
        for k in 0..3 {
            let (j1, j2) = ((k + 1) % 3, (k + 2) % 3);
            for n in 0..N {
                let m = ort::add(
                    &ort::mul(&e[n][j1], &h[n][j1][k]),
                    &ort::mul(&e[n][j2], &h[n][j2][k]),
                );
                e[n][k] = ort::ort(&m);
            }
        }
    }
    e
}

/// The Procrustes energy after 0, 1, ..., [`PROCRUSTES_SWEEPS`] sweeps (non-increasing;
/// for tests and diagnostics).
#[cfg(test)]
fn procrustes_energies(t: &[Mat2x8; 3]) -> [f64; PROCRUSTES_SWEEPS + 1] {
    let p = Procrustes::new(t);
    std::array::from_fn(|s| p.energy(&p.rotations(s)))
}

impl TriData {
    /// Precomputes a triangle from its stored corner frames and embedded corners.
    pub(crate) fn new(frames: [&Frame32; 3]) -> Self {
        Self::new_batch([frames])[0]
    }

    /// [`TriData::new`] for `N` triangles at once (their rotations interleaved, see
    /// `rotations_batch`).
    pub(crate) fn new_batch<const N: usize>(frames: [[&Frame32; 3]; N]) -> [Self; N] {
        let ps: [Procrustes; N] =
            std::array::from_fn(|n| Procrustes::from_products(frame_products32(&frames[n])));
        let es: [[M2; 3]; N] =
            rotations_batch::<N>(std::array::from_fn(|n| &ps[n]), PROCRUSTES_SWEEPS);
        std::array::from_fn(|n| {
            let (r, e) = (&ps[n].r, &es[n]);
            let mut d = TriData::default();
            for k in 0..3 {
                let a = ort::mul(&e[k], &r[k]);
                d.x[2 * k] = a.map(|v| v as f32);
                d.x[2 * k + 1] = e[k].map(|v| v as f32);
            }
            d
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::Vec8;
    use proptest::prelude::*;

    fn frame(seed: u64) -> Mat2x8 {
        // A deterministic pseudo-random orthonormal 2x8 frame.
        let mut x = seed.wrapping_mul(0x9E3779B97F4A7C15) | 1;
        let mut next = || {
            x ^= x << 13;
            x ^= x >> 7;
            x ^= x << 17;
            (x >> 11) as f64 / (1u64 << 53) as f64 - 0.5
        };
        let a = Vec8::from_fn(|_, _| next());
        let b = Vec8::from_fn(|_, _| next());
        let e1 = a.normalize();
        let e2 = (b - e1 * e1.dot(&b)).normalize();
        let mut m = Mat2x8::zeros();
        m.row_mut(0).copy_from(&e1.transpose());
        m.row_mut(1).copy_from(&e2.transpose());
        m
    }

    proptest! {
        /// Each block-descent sweep cannot increase the Procrustes energy.
        #[test]
        fn procrustes_energy_never_increases(s in 0u64..100_000) {
            let e = procrustes_energies(&[frame(s), frame(s + 1), frame(s + 2)]);
            for w in e.windows(2) {
                prop_assert!(w[1] <= w[0] + 1e-9 * (1.0 + w[0]), "{e:?}");
            }
        }
    }
}
