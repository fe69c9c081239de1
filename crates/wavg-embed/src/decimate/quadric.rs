//! The collapse costs: Garland-Heckbert quadrics, normal cones, and the halfedge and key
//! helpers they share.

use super::*;

/// Garland-Heckbert quadric (symmetric 4x4: a2 ab ac ad b2 bc bd c2 cd d2).
#[derive(Clone, Copy, Debug, Default)]
pub(super) struct Quadric(pub(super) [f64; 10]);

impl Quadric {
    pub(super) fn plane(n: Vector3<f64>, d: f64, w: f64) -> Self {
        let (a, b, c) = (n.x, n.y, n.z);
        Self([
            a * a * w,
            a * b * w,
            a * c * w,
            a * d * w,
            b * b * w,
            b * c * w,
            b * d * w,
            c * c * w,
            c * d * w,
            d * d * w,
        ])
    }
    pub(super) fn add(&mut self, o: &Self) {
        for i in 0..10 {
            self.0[i] += o.0[i];
        }
    }
    pub(super) fn eval_sum(&self, o: &Self, p: &Vector3<f64>) -> f64 {
        let q: [f64; 10] = std::array::from_fn(|i| self.0[i] + o.0[i]);
        let (x, y, z) = (p.x, p.y, p.z);
        q[0] * x * x
            + 2.0 * q[1] * x * y
            + 2.0 * q[2] * x * z
            + 2.0 * q[3] * x
            + q[4] * y * y
            + 2.0 * q[5] * y * z
            + 2.0 * q[6] * y
            + q[7] * z * z
            + 2.0 * q[8] * z
            + q[9]
    }
}

/// OpenMesh's `NormalConeT`: a centre normal and a half opening angle.
#[derive(Clone, Copy, Debug)]
pub(super) struct Cone {
    pub(super) n: Vector3<f64>,
    pub(super) angle: f64,
}

impl Cone {
    pub(super) fn merged(mut self, o: &Cone) -> Cone {
        let center = self.n.dot(&o.n).clamp(-1.0, 1.0).acos();
        let min_a = (-self.angle).min(center - o.angle);
        let max_a = self.angle.max(center + o.angle);
        let opening = 0.5 * (max_a - min_a);
        let s = center.sin();
        if s > 1e-9 {
            let axis = 0.5 * (min_a + max_a);
            self.n = ((self.n * (center - axis).sin() + o.n * axis.sin()) / s).normalize();
        }
        self.angle = opening;
        self
    }
}

#[inline(always)]
pub(super) fn next(h: u32) -> u32 {
    if h % 3 == 2 { h - 2 } else { h + 1 }
}

#[inline(always)]
pub(super) fn prev(h: u32) -> u32 {
    if h % 3 == 0 { h + 2 } else { h - 1 }
}

/// Total order on f64 as u64 (for heap keys).
#[inline]
pub(super) fn key(f: f64) -> u64 {
    let b = f.to_bits();
    if b >> 63 == 1 { !b } else { b | (1 << 63) }
}
