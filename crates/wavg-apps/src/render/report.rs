//! What a rendering came to: with the `serde` feature, the `wavg render --json` keys.

use wavg_mesh::TriMesh;

use super::Image;

/// The figures of one picture: its size, the mesh, how much of it shows the mesh, and the
/// range of the scalars it was coloured by.
///
/// ```
/// use wavg_apps::{Colouring, Overlays, RenderOptions, RenderReport, render};
/// use wavg_mesh::procedural;
/// let mesh = procedural::icosphere(2);
/// let opts = RenderOptions { width: 40, height: 30, ..Default::default() };
/// let img = render(&mesh, &Colouring::Plain, &Overlays::default(), &opts).unwrap();
/// let report = RenderReport::new(&mesh, &img, None, 0.0);
/// assert_eq!((report.width, report.height, report.vertices), (40, 30, 162));
/// assert!(report.covered_fraction > 0.2 && report.covered_fraction < 1.0);
/// ```
#[derive(Clone, Debug, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
pub struct RenderReport {
    /// Width in pixels.
    pub width: u32,
    /// Height in pixels.
    pub height: u32,
    /// Vertices of the mesh.
    pub vertices: usize,
    /// Faces of the mesh.
    pub faces: usize,
    /// Fraction of the pixels that are not the white background.
    pub covered_fraction: f64,
    /// Wall-clock seconds (as measured by the caller).
    pub seconds: f64,
    /// Smallest per-vertex scalar, when coloured by scalars (left out of JSON otherwise).
    #[cfg_attr(feature = "serde", serde(skip_serializing_if = "Option::is_none"))]
    pub scalar_min: Option<f64>,
    /// Largest per-vertex scalar, as `scalar_min`.
    #[cfg_attr(feature = "serde", serde(skip_serializing_if = "Option::is_none"))]
    pub scalar_max: Option<f64>,
}

impl RenderReport {
    /// The report of `image`, a picture of `mesh` (coloured by `scalars`, if given) that
    /// took `seconds`.
    pub fn new(mesh: &TriMesh, image: &Image, scalars: Option<&[f64]>, seconds: f64) -> Self {
        let covered = image
            .pixels
            .iter()
            .filter(|p| **p != [255, 255, 255, 255])
            .count() as f64
            / image.pixels.len() as f64;
        let range = scalars.map(|s| {
            s.iter()
                .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), &x| {
                    (a.min(x), b.max(x))
                })
        });
        Self {
            width: image.width,
            height: image.height,
            vertices: mesh.n_vertices(),
            faces: mesh.n_faces(),
            covered_fraction: covered,
            seconds,
            scalar_min: range.map(|r| r.0),
            scalar_max: range.map(|r| r.1),
        }
    }
}
