//! A perspective camera on a sphere around the model, looking at its centre, with the
//! y axis up (the OBJ convention).

use nalgebra::Vector3;

/// Where the camera sits: degrees of azimuth around the y axis (0 looks along -z, from
/// +z) and of elevation above the xz plane.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct View {
    /// Degrees around the y axis, counter-clockwise seen from above.
    pub azimuth: f64,
    /// Degrees above the horizontal plane, -90 to 90.
    pub elevation: f64,
}

impl Default for View {
    /// A three-quarter view from slightly above.
    fn default() -> Self {
        Self {
            azimuth: 35.0,
            elevation: 20.0,
        }
    }
}

/// Vertical and horizontal field of view (of the shorter image side), degrees.
pub const FOV_DEGREES: f64 = 30.0;

/// A perspective camera: position, orthonormal frame and focal length in pixels.
#[derive(Clone, Copy, Debug)]
pub struct Camera {
    /// The eye position.
    pub eye: Vector3<f64>,
    /// Unit vector to the right on the image.
    pub right: Vector3<f64>,
    /// Unit vector up on the image.
    pub up: Vector3<f64>,
    /// Unit viewing direction (depth grows along it).
    pub forward: Vector3<f64>,
    /// Focal length in pixels.
    pub focal: f64,
    /// Image size in pixels.
    pub size: (u32, u32),
}

impl Camera {
    /// A camera that sees the whole ball (`center`, `radius`) from direction `view`,
    /// with a little margin, on a `width` x `height` image.
    pub fn fit(center: Vector3<f64>, radius: f64, view: View, width: u32, height: u32) -> Self {
        let (az, el) = (view.azimuth.to_radians(), view.elevation.to_radians());
        let dir = Vector3::new(el.cos() * az.sin(), el.sin(), el.cos() * az.cos());
        let half = (FOV_DEGREES / 2.0).to_radians();
        let dist = radius.max(1e-300) / half.sin() * 1.08;
        let eye = center + dir * dist;
        let forward = -dir;
        let world_up = if el.cos().abs() < 1e-6 {
            Vector3::new(0.0, 0.0, -el.sin().signum())
        } else {
            Vector3::y()
        };
        let right = forward.cross(&world_up).normalize();
        let up = right.cross(&forward);
        let focal = 0.5 * width.min(height) as f64 / half.tan();
        Self {
            eye,
            right,
            up,
            forward,
            focal,
            size: (width, height),
        }
    }

    /// The camera moved across its image plane and zoomed in (1 to 4 times) so that
    /// `points` fill the image with a small margin: a long or flat mesh, whose bounding ball
    /// [`Camera::fit`] sees whole, then no longer covers only a fraction of the picture.
    pub fn framed(mut self, points: &[Vector3<f64>]) -> Self {
        if points.is_empty() {
            return self;
        }
        let (w, h) = (self.size.0 as f64, self.size.1 as f64);
        for _ in 0..3 {
            let (mut lo, mut hi, mut depth) = ([f64::INFINITY; 2], [f64::NEG_INFINITY; 2], 0.0);
            for p in points {
                let s = self.project(p);
                for k in 0..2 {
                    lo[k] = lo[k].min(s[k]);
                    hi[k] = hi[k].max(s[k]);
                }
                depth += s[2];
            }
            let depth = depth / points.len() as f64;
            let (cx, cy) = ((lo[0] + hi[0]) / 2.0, (lo[1] + hi[1]) / 2.0);
            // Moving the eye by d across the view moves a point at depth z by focal d / z.
            self.eye += self.right * ((cx - w / 2.0) * depth / self.focal)
                - self.up * ((cy - h / 2.0) * depth / self.focal);
            let span = ((hi[0] - lo[0]) / w).max((hi[1] - lo[1]) / h).max(1e-12);
            self.focal *= (0.9 / span).clamp(1.0, 4.0);
        }
        self
    }

    /// Screen position (x right, y down, pixels, pixel centres at +0.5) and depth along
    /// the viewing direction of a world point.
    pub fn project(&self, p: &Vector3<f64>) -> [f64; 3] {
        let q = p - self.eye;
        let z = q.dot(&self.forward);
        // Points at or behind the eye are held just in front of it, at a depth relative
        // to their distance, so no scale of the model falls under the floor.
        let zs = z.max(q.norm() * 1e-12).max(f64::MIN_POSITIVE);
        [
            0.5 * self.size.0 as f64 + self.focal * q.dot(&self.right) / zs,
            0.5 * self.size.1 as f64 - self.focal * q.dot(&self.up) / zs,
            z,
        ]
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_centre_projects_to_the_image_centre_and_up_is_up() {
        let c = Camera::fit(Vector3::new(1.0, 2.0, 3.0), 2.0, View::default(), 800, 600);
        let p = c.project(&Vector3::new(1.0, 2.0, 3.0));
        assert!((p[0] - 400.0).abs() < 1e-9 && (p[1] - 300.0).abs() < 1e-9 && p[2] > 0.0);
        let above = c.project(&Vector3::new(1.0, 2.5, 3.0));
        assert!(above[1] < 300.0);
        for el in [-90.0, 90.0] {
            let c = Camera::fit(
                Vector3::zeros(),
                1.0,
                View {
                    azimuth: 0.0,
                    elevation: el,
                },
                10,
                10,
            );
            assert!(c.right.iter().all(|x| x.is_finite()));
        }
    }

    #[test]
    fn a_long_flat_mesh_is_framed_to_fill_the_picture() {
        // A 10 x 1 x 0.1 slab off the origin: its bounding ball leaves most of the frame empty.
        let pts: Vec<Vector3<f64>> = (0..8)
            .map(|i| {
                let b = |k: usize, v: f64| if i >> k & 1 == 1 { v } else { 0.0 };
                Vector3::new(5.0 + b(0, 10.0), b(1, 1.0), b(2, 0.1))
            })
            .collect();
        let span = |c: &Camera| {
            let s: Vec<[f64; 3]> = pts.iter().map(|p| c.project(p)).collect();
            let (x0, x1) = s
                .iter()
                .fold((f64::MAX, f64::MIN), |(a, b), p| (a.min(p[0]), b.max(p[0])));
            let (y0, y1) = s
                .iter()
                .fold((f64::MAX, f64::MIN), |(a, b), p| (a.min(p[1]), b.max(p[1])));
            assert!(
                x0 >= 0.0 && x1 <= 800.0 && y0 >= 0.0 && y1 <= 600.0,
                "{x0} {x1} {y0} {y1}"
            );
            ((x1 - x0) / 800.0).max((y1 - y0) / 600.0)
        };
        let ball = Camera::fit(
            Vector3::new(10.0, 0.5, 0.05),
            5.03,
            View::default(),
            800,
            600,
        );
        let before = span(&ball);
        let after = span(&ball.framed(&pts));
        assert!(after > 0.85 && after <= 0.95, "{before} -> {after}");
        assert!(after > before * 1.2, "{before} -> {after}");
    }
}
