//! Z-buffered rasterisation into a visibility buffer (per pixel: depth, face and
//! perspective-correct barycentric coordinates), and depth-tested thick lines and dots
//! drawn over it.

/// Per pixel: the nearest face, its perspective-correct barycentrics and its depth.
pub(super) struct VisBuffer {
    /// Width in pixels.
    pub(super) width: usize,
    /// Height in pixels.
    pub(super) height: usize,
    /// Depth along the view direction; `f64::INFINITY` where nothing was drawn.
    pub(super) depth: Vec<f64>,
    /// Face drawn at the pixel (`u32::MAX` for none).
    pub(super) face: Vec<u32>,
    /// Barycentrics of the pixel centre in the face (perspective-correct).
    pub(super) bary: Vec<[f64; 3]>,
}

impl VisBuffer {
    /// An empty buffer.
    pub(super) fn new(width: usize, height: usize) -> Self {
        let n = width * height;
        Self {
            width,
            height,
            depth: vec![f64::INFINITY; n],
            face: vec![u32::MAX; n],
            bary: vec![[0.0; 3]; n],
        }
    }

    /// Draws triangle `face` whose corners are at screen positions `s` (x, y, depth),
    /// keeping the nearer surface at every pixel (either orientation is drawn).
    pub(super) fn triangle(&mut self, face: u32, s: [[f64; 3]; 3]) {
        if s.iter()
            .any(|p| p[2].is_nan() || p[2] <= 0.0 || !p.iter().all(|c| c.is_finite()))
        {
            return;
        }
        let area = edge(s[0], s[1], s[2]);
        if area == 0.0 || !area.is_finite() {
            return;
        }
        let lo = |k: usize| s.iter().map(|p| p[k]).fold(f64::INFINITY, f64::min);
        let hi = |k: usize| s.iter().map(|p| p[k]).fold(f64::NEG_INFINITY, f64::max);
        let x0 = (lo(0) - 0.5).ceil().max(0.0) as usize;
        let y0 = (lo(1) - 0.5).ceil().max(0.0) as usize;
        let x1 = ((hi(0) - 0.5).floor()).min(self.width as f64 - 1.0);
        let y1 = ((hi(1) - 0.5).floor()).min(self.height as f64 - 1.0);
        if x1 < 0.0 || y1 < 0.0 {
            return;
        }
        let (x1, y1) = (x1 as usize, y1 as usize);
        let inv_z = s.map(|p| 1.0 / p[2]);
        for y in y0..=y1 {
            for x in x0..=x1 {
                let p = [x as f64 + 0.5, y as f64 + 0.5, 0.0];
                let l = [
                    edge(s[1], s[2], p) / area,
                    edge(s[2], s[0], p) / area,
                    edge(s[0], s[1], p) / area,
                ];
                if l.iter().any(|&v| v < 0.0) {
                    continue;
                }
                let w = [l[0] * inv_z[0], l[1] * inv_z[1], l[2] * inv_z[2]];
                let sum = w[0] + w[1] + w[2];
                let z = 1.0 / sum;
                let i = y * self.width + x;
                if z < self.depth[i] {
                    self.depth[i] = z;
                    self.face[i] = face;
                    self.bary[i] = w.map(|v| v / sum);
                }
            }
        }
    }
}

/// Twice the signed area of (a, b, c) in screen space.
fn edge(a: [f64; 3], b: [f64; 3], c: [f64; 3]) -> f64 {
    (b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0])
}

/// Screen-space distance from `p` to the three edges of the triangle `s` (edge `i` is
/// opposite corner `i`), for wireframe lines.
pub(super) fn edge_distances(s: [[f64; 3]; 3], p: [f64; 2]) -> [f64; 3] {
    let p = [p[0], p[1], 0.0];
    let mut out = [f64::INFINITY; 3];
    for (i, o) in out.iter_mut().enumerate() {
        let (a, b) = (s[(i + 1) % 3], s[(i + 2) % 3]);
        let len = (b[0] - a[0]).hypot(b[1] - a[1]);
        if len > 0.0 {
            *o = edge(a, b, p).abs() / len;
        }
    }
    out
}

/// Paints a thick segment from `a` to `b` (screen x, y, depth) of half-width `radius`
/// pixels with `colour`, where it is not behind the surface by more than `bias` depth.
pub(super) fn segment(
    buf: &VisBuffer,
    rgb: &mut [[f64; 3]],
    a: [f64; 3],
    b: [f64; 3],
    radius: f64,
    bias: f64,
    colour: [f64; 3],
) {
    if !(a.iter().chain(&b).all(|c| c.is_finite()) && a[2] > 0.0 && b[2] > 0.0) {
        return;
    }
    let x0 = (a[0].min(b[0]) - radius - 1.0).floor().max(0.0);
    let y0 = (a[1].min(b[1]) - radius - 1.0).floor().max(0.0);
    let x1 = (a[0].max(b[0]) + radius + 1.0)
        .ceil()
        .min(buf.width as f64 - 1.0);
    let y1 = (a[1].max(b[1]) + radius + 1.0)
        .ceil()
        .min(buf.height as f64 - 1.0);
    if x1 < x0 || y1 < y0 {
        return;
    }
    let (dx, dy) = (b[0] - a[0], b[1] - a[1]);
    let len2 = dx * dx + dy * dy;
    for y in y0 as usize..=y1 as usize {
        for x in x0 as usize..=x1 as usize {
            let (px, py) = (x as f64 + 0.5, y as f64 + 0.5);
            let t = if len2 > 0.0 {
                (((px - a[0]) * dx + (py - a[1]) * dy) / len2).clamp(0.0, 1.0)
            } else {
                0.0
            };
            let (qx, qy) = (a[0] + t * dx - px, a[1] + t * dy - py);
            if qx * qx + qy * qy > radius * radius {
                continue;
            }
            let z = a[2] + t * (b[2] - a[2]);
            let i = y * buf.width + x;
            if z <= buf.depth[i] + bias {
                rgb[i] = colour;
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_nearer_triangle_wins_in_either_order() {
        let far = [[0.0, 0.0, 5.0], [10.0, 0.0, 5.0], [0.0, 10.0, 5.0]];
        let near = [[0.0, 0.0, 2.0], [0.0, 10.0, 2.0], [10.0, 0.0, 2.0]];
        for order in [[(0, far), (1, near)], [(1, near), (0, far)]] {
            let mut b = VisBuffer::new(10, 10);
            for (f, s) in order {
                b.triangle(f, s);
            }
            assert_eq!(b.face[2 * 10 + 2], 1);
            assert!((b.depth[2 * 10 + 2] - 2.0).abs() < 1e-12);
            assert_eq!(b.face[9 * 10 + 9], u32::MAX);
        }
    }

    #[test]
    fn perspective_barycentrics_sum_to_one() {
        let mut b = VisBuffer::new(20, 20);
        b.triangle(0, [[0.0, 0.0, 1.0], [20.0, 0.0, 3.0], [0.0, 20.0, 9.0]]);
        for (f, w) in b.face.iter().zip(&b.bary) {
            if *f == 0 {
                assert!((w.iter().sum::<f64>() - 1.0).abs() < 1e-12);
                assert!(w.iter().all(|&v| v >= 0.0));
            }
        }
    }
}
