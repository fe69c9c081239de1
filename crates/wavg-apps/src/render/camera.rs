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

    /// Screen position (x right, y down, pixels, pixel centres at +0.5) and depth along
    /// the viewing direction of a world point.
    pub fn project(&self, p: &Vector3<f64>) -> [f64; 3] {
        let q = p - self.eye;
        let z = q.dot(&self.forward);
        let zs = z.max(1e-12);
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
}
