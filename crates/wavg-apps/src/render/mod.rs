//! A small z-buffered software renderer for looking at results: a shaded mesh (Lambert
//! plus ambient light on smooth vertex normals), coloured plainly, by a texture through
//! the mesh's UVs, or by per-vertex scalars through the viridis map (with a legend), with
//! an optional wireframe and curves and dots drawn on top (depth-tested with a small bias
//! so that lines lying on the surface stay visible). Rendered at twice the resolution and
//! box-filtered down, which anti-aliases edges and lines.

mod camera;
mod colormap;
mod font;
mod image;
mod raster;
mod report;

use nalgebra::Vector3;
use wavg_mesh::{NONE, TriMesh};

pub use camera::{Camera, FOV_DEGREES, View};
pub use colormap::viridis;
pub use image::{Image, MAX_DECODED_BYTES, MAX_SIDE};
pub use report::RenderReport;

use crate::AppError;
use raster::VisBuffer;

/// How the surface is coloured.
#[derive(Clone, Copy, Debug, Default)]
pub enum Colouring<'a> {
    /// A light neutral grey.
    #[default]
    Plain,
    /// The image through the mesh's texture coordinates, sampled bilinearly; a triangle
    /// whose three texture corners are [`NONE`] (a face the file gave none) is plain.
    Texture(&'a Image),
    /// One number per vertex, interpolated, through viridis from its minimum to maximum.
    Scalars(&'a [f64]),
}

/// What is drawn over the surface.
#[derive(Clone, Debug, Default)]
pub struct Overlays {
    /// Polylines (3-D points in order); each drawn as a thick line.
    pub curves: Vec<Vec<Vector3<f64>>>,
    /// Points drawn as dots.
    pub points: Vec<Vector3<f64>>,
    /// The polygon each triangle came from (`LoadNotes::polygon_of` of the mesh file);
    /// the wireframe then leaves out the edges between two triangles of one polygon (the
    /// diagonals that triangulating quads added). Empty: every triangle is its own polygon.
    pub polygons: Vec<u32>,
}

/// Picture size, view and extras.
#[derive(Clone, Copy, Debug)]
pub struct RenderOptions {
    /// Width in pixels.
    pub width: u32,
    /// Height in pixels.
    pub height: u32,
    /// Camera direction.
    pub view: View,
    /// Draw the triangle edges (the polygon edges with [`Overlays::polygons`]).
    pub wireframe: bool,
    /// Supersampling factor per side (1 = none); 2 anti-aliases well.
    pub supersample: u32,
}

impl Default for RenderOptions {
    fn default() -> Self {
        Self {
            width: 800,
            height: 600,
            view: View::default(),
            wireframe: false,
            supersample: 2,
        }
    }
}

/// Background colour.
const BACKGROUND: [f64; 3] = [255.0, 255.0, 255.0];
/// Plain surface colour.
const PLAIN: [f64; 3] = [205.0, 208.0, 215.0];
/// Curve colour and its darker outline.
const CURVE: [[f64; 3]; 2] = [[20.0, 20.0, 20.0], [230.0, 45.0, 35.0]];
/// Dot colour and its outline.
const DOT: [[f64; 3]; 2] = [[20.0, 20.0, 20.0], [255.0, 200.0, 40.0]];
/// Wireframe colour.
const WIRE: [f64; 3] = [40.0, 40.0, 50.0];
/// Ambient share of the light.
const AMBIENT: f64 = 0.3;

/// Checks that the inputs fit together (finite positions, indices in range, UVs for a
/// texture, one finite scalar per vertex) before anything is drawn.
fn check(
    mesh: &TriMesh,
    colouring: &Colouring,
    overlays: &Overlays,
    opts: &RenderOptions,
) -> Result<(), AppError> {
    let bad = |m: String| Err(AppError::Input(m));
    if mesh.triangles.is_empty() {
        return bad("the mesh has no triangles".into());
    }
    let n = mesh.positions.len();
    if let Some(f) = mesh
        .triangles
        .iter()
        .position(|t| t.iter().any(|&v| v as usize >= n))
    {
        return bad(format!(
            "triangle {f} has a vertex index out of range ({n} vertices)"
        ));
    }
    if let Some(v) = mesh
        .positions
        .iter()
        .position(|p| !p.iter().all(|c| c.is_finite()))
    {
        return bad(format!("vertex {v} has a non-finite position"));
    }
    if !(1..=4).contains(&opts.supersample) {
        return bad(format!("supersampling {} must be 1 to 4", opts.supersample));
    }
    let side = |s: u32| (1..=MAX_SIDE / opts.supersample).contains(&s);
    if !side(opts.width) || !side(opts.height) {
        return bad(format!(
            "picture size {}x{}: each side must be 1 to {}",
            opts.width,
            opts.height,
            MAX_SIDE / opts.supersample
        ));
    }
    if !overlays.polygons.is_empty() && overlays.polygons.len() != mesh.triangles.len() {
        return bad(format!(
            "{} polygon ids for {} triangles",
            overlays.polygons.len(),
            mesh.triangles.len()
        ));
    }
    match colouring {
        Colouring::Plain => {}
        Colouring::Texture(_) => match &mesh.uv {
            None => {
                return bad(
                    "the mesh has no texture coordinates (they need a `vt` on every face's \
                        corners: `wavg info MESH` tells whether some faces lacked them)"
                        .into(),
                );
            }
            Some(uv) => {
                let untextured = |t: &[u32; 3]| t.iter().all(|&i| i == NONE);
                if uv.faces.len() != mesh.triangles.len()
                    || uv
                        .faces
                        .iter()
                        .filter(|t| !untextured(t))
                        .flatten()
                        .any(|&i| i as usize >= uv.coords.len())
                    || !uv.coords.iter().flatten().all(|c| c.is_finite())
                {
                    return bad("the mesh's texture coordinates are inconsistent".into());
                }
            }
        },
        Colouring::Scalars(s) => {
            if s.len() != n {
                return bad(format!("{} scalars for {n} vertices", s.len()));
            }
            if let Some(i) = s.iter().position(|x| !x.is_finite()) {
                return bad(format!("scalar {i} is not finite"));
            }
        }
    }
    Ok(())
}

/// Area-weighted vertex normals (zero for isolated vertices).
fn vertex_normals(mesh: &TriMesh) -> Vec<Vector3<f64>> {
    let mut n = vec![Vector3::zeros(); mesh.positions.len()];
    for t in &mesh.triangles {
        let p = t.map(|v| mesh.positions[v as usize]);
        let fnorm = (p[1] - p[0]).cross(&(p[2] - p[0]));
        for &v in t {
            n[v as usize] += fnorm;
        }
    }
    for x in &mut n {
        let l = x.norm();
        if l > 0.0 {
            *x /= l;
        }
    }
    n
}

/// Per triangle, which of its edges (edge `i` opposite corner `i`) the wireframe draws:
/// all of them, except an edge another triangle of the same polygon shares.
fn wire_edges(mesh: &TriMesh, polygons: &[u32]) -> Vec<[bool; 3]> {
    let mut out = vec![[true; 3]; mesh.triangles.len()];
    if polygons.is_empty() {
        return out;
    }
    let key = |f: usize, i: usize| {
        let t = mesh.triangles[f];
        let (a, b) = (t[(i + 1) % 3], t[(i + 2) % 3]);
        (a.min(b), a.max(b), polygons[f])
    };
    let mut count: std::collections::HashMap<(u32, u32, u32), u32> =
        std::collections::HashMap::new();
    for f in 0..mesh.triangles.len() {
        for i in 0..3 {
            *count.entry(key(f, i)).or_default() += 1;
        }
    }
    for (f, e) in out.iter_mut().enumerate() {
        for (i, draw) in e.iter_mut().enumerate() {
            *draw = count[&key(f, i)] < 2;
        }
    }
    out
}

/// The bounding box's centre and the largest distance of a point from it.
fn bounds(points: &[Vector3<f64>]) -> (Vector3<f64>, f64) {
    let mut lo = Vector3::repeat(f64::INFINITY);
    let mut hi = Vector3::repeat(f64::NEG_INFINITY);
    for p in points {
        lo = lo.inf(p);
        hi = hi.sup(p);
    }
    let c = (lo + hi) / 2.0;
    let r = points.iter().map(|p| (p - c).norm()).fold(0.0, f64::max);
    // A single point still gets a ball to look at, of a size relative to where it is.
    let r = if r > 0.0 {
        r
    } else {
        (c.norm() * 1e-12).max(f64::MIN_POSITIVE)
    };
    (c, r)
}

/// Renders the mesh with the given colouring and overlays; errors (before drawing) on
/// inputs that do not fit together.
pub fn render(
    mesh: &TriMesh,
    colouring: &Colouring,
    overlays: &Overlays,
    opts: &RenderOptions,
) -> Result<Image, AppError> {
    check(mesh, colouring, overlays, opts)?;
    let ss = opts.supersample;
    let (w, h) = ((opts.width * ss) as usize, (opts.height * ss) as usize);
    let (center, radius) = bounds(&mesh.positions);
    // The whole bounding ball in view, then the mesh itself framed to fill the picture.
    let cam = Camera::fit(center, radius, opts.view, w as u32, h as u32).framed(&mesh.positions);
    let screen: Vec<[f64; 3]> = mesh.positions.iter().map(|p| cam.project(p)).collect();
    let mut vis = VisBuffer::new(w, h);
    for (f, t) in mesh.triangles.iter().enumerate() {
        vis.triangle(f as u32, t.map(|v| screen[v as usize]));
    }
    let normals = vertex_normals(mesh);
    let wires = if opts.wireframe {
        wire_edges(mesh, &overlays.polygons)
    } else {
        Vec::new()
    };
    let light = (-cam.forward + cam.up * 0.4 - cam.right * 0.25).normalize();
    let (smin, smax) = match colouring {
        Colouring::Scalars(s) => s
            .iter()
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), &x| {
                (a.min(x), b.max(x))
            }),
        _ => (0.0, 0.0),
    };
    let mut rgb = vec![BACKGROUND; w * h];
    for (i, px) in rgb.iter_mut().enumerate() {
        let f = vis.face[i];
        if f == u32::MAX {
            continue;
        }
        let t = mesh.triangles[f as usize];
        let b = vis.bary[i];
        let mut n: Vector3<f64> = (0..3).map(|k| normals[t[k] as usize] * b[k]).sum();
        let p: Vector3<f64> = (0..3).map(|k| mesh.positions[t[k] as usize] * b[k]).sum();
        if n.norm() == 0.0 {
            let q = t.map(|v| mesh.positions[v as usize]);
            n = (q[1] - q[0]).cross(&(q[2] - q[0]));
        }
        let n = n.try_normalize(0.0).unwrap_or(-cam.forward);
        let n = if n.dot(&(cam.eye - p)) < 0.0 { -n } else { n };
        let shade = AMBIENT + (1.0 - AMBIENT) * n.dot(&light).max(0.0);
        let base = match colouring {
            Colouring::Plain => PLAIN,
            Colouring::Texture(img) => {
                let uv = mesh.uv.as_ref().expect("checked");
                let corners = uv.faces[f as usize];
                if corners[0] == NONE {
                    PLAIN
                } else {
                    let c = corners.map(|k| uv.coords[k as usize]);
                    let q = c[0] * b[0] + c[1] * b[1] + c[2] * b[2];
                    // Transparent texels (nothing transferred there) show the plain colour.
                    let s = img.sample_bilinear(q.x, q.y);
                    let a = s[3] / 255.0;
                    [0, 1, 2].map(|k| s[k] * a + PLAIN[k] * (1.0 - a))
                }
            }
            Colouring::Scalars(s) => {
                let v: f64 = (0..3).map(|k| s[t[k] as usize] * b[k]).sum();
                // In halves: exact, and the range of values near +-f64::MAX stays finite.
                let x = if smax > smin {
                    (v / 2.0 - smin / 2.0) / (smax / 2.0 - smin / 2.0)
                } else {
                    0.5
                };
                viridis(x)
            }
        };
        *px = base.map(|c| c * shade);
        if opts.wireframe {
            let s = t.map(|v| screen[v as usize]);
            let (x, y) = ((i % w) as f64 + 0.5, (i / w) as f64 + 0.5);
            let d = raster::edge_distances(s, [x, y])
                .into_iter()
                .zip(wires[f as usize])
                .filter(|&(_, draw)| draw)
                .fold(f64::INFINITY, |m, (d, _)| m.min(d));
            let a = (0.7 * ss as f64 + 0.5 - d).clamp(0.0, 1.0);
            *px = [0, 1, 2].map(|k| px[k] * (1.0 - a) + WIRE[k] * a);
        }
    }
    let bias = 0.02 * radius;
    let line = 1.6 * ss as f64;
    for (k, r) in [(0, line + 1.2 * ss as f64), (1, line)] {
        for c in &overlays.curves {
            for s in c.windows(2) {
                let (a, b) = (cam.project(&s[0]), cam.project(&s[1]));
                raster::segment(&vis, &mut rgb, a, b, r, bias, CURVE[k]);
            }
        }
    }
    let dot = 4.5 * ss as f64;
    for p in &overlays.points {
        let a = cam.project(p);
        raster::segment(&vis, &mut rgb, a, a, dot + 1.5 * ss as f64, bias, DOT[0]);
        raster::segment(&vis, &mut rgb, a, a, dot, bias, DOT[1]);
    }
    let big = Image {
        width: w as u32,
        height: h as u32,
        pixels: rgb
            .iter()
            .map(|c| {
                let q = c.map(|x| x.round().clamp(0.0, 255.0) as u8);
                [q[0], q[1], q[2], 255]
            })
            .collect(),
    };
    let mut img = big.downsample(ss);
    if let Colouring::Scalars(_) = colouring {
        legend(&mut img, smin, smax);
    }
    Ok(img)
}

/// A vertical viridis bar at the right edge, maximum on top, with its two labels.
fn legend(img: &mut Image, min: f64, max: f64) {
    let (w, h) = (img.width as i64, img.height as i64);
    let scale = if h >= 300 { 2 } else { 1 };
    let (bw, x0) = (12 * scale, w - 30 * scale);
    let (y0, y1) = (h / 5, h - h / 5);
    if x0 < 0 || y1 - y0 < 4 {
        return;
    }
    let mut put = |x: i64, y: i64, c: [u8; 4]| {
        if (0..w).contains(&x) && (0..h).contains(&y) {
            img.set(x as u32, y as u32, c);
        }
    };
    for y in y0 - 1..=y1 + 1 {
        for x in x0 - 1..=x0 + bw {
            let edge = y == y0 - 1 || y == y1 + 1 || x == x0 - 1 || x == x0 + bw;
            let c = if edge {
                [40, 40, 40]
            } else {
                viridis((y1 - y) as f64 / (y1 - y0) as f64).map(|v| v.round() as u8)
            };
            put(x, y, [c[0], c[1], c[2], 255]);
        }
    }
    let ink = [30, 30, 30, 255];
    for (text, y) in [
        (font::label(max), y0 - 9 * scale),
        (font::label(min), y1 + 4 * scale),
    ] {
        let width = font::draw_text(&text, 0, 0, scale, |_, _| {});
        let x = (x0 + bw / 2 - width / 2).min(w - width - 2).max(0);
        font::draw_text(&text, x, y, scale, |x, y| put(x, y, ink));
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use wavg_mesh::procedural;

    fn is_bg(p: [u8; 4]) -> bool {
        p == [255, 255, 255, 255]
    }

    #[test]
    fn a_sphere_covers_its_projected_disc() {
        let mesh = procedural::icosphere(5);
        let opts = RenderOptions {
            width: 400,
            height: 300,
            ..Default::default()
        };
        let img = render(&mesh, &Colouring::Plain, &Overlays::default(), &opts).unwrap();
        let covered = img.pixels.iter().filter(|&&p| !is_bg(p)).count() as f64;
        // The vertices of the unit sphere are at distance 1 from the centre; the camera
        // sits at d = 1 / sin(15 deg) * 1.08, and the sphere's silhouette cone has angular
        // radius asin(1 / d), i.e. a disc of radius focal * tan(asin(1 / d)) pixels.
        let d = 1.0 / (FOV_DEGREES / 2.0).to_radians().sin() * 1.08;
        let focal = 150.0 / (FOV_DEGREES / 2.0).to_radians().tan();
        let r = focal * (1.0 / d).asin().tan();
        let expected = std::f64::consts::PI * r * r;
        assert!(
            (covered / expected - 1.0).abs() < 0.03,
            "{covered} vs {expected}"
        );
    }

    #[test]
    fn the_near_triangle_hides_the_far_one() {
        let p = |x: f64, y: f64, z: f64| Vector3::new(x, y, z);
        let mesh = TriMesh::new(
            vec![
                p(-2.0, -2.0, 0.0),
                p(2.0, -2.0, 0.0),
                p(0.0, 2.0, 0.0),
                p(-1.0, -1.0, 1.0),
                p(1.0, -1.0, 1.0),
                p(0.0, 1.0, 1.0),
            ],
            vec![[3, 4, 5], [0, 1, 2]],
        );
        let s = [0.0, 0.0, 0.0, 1.0, 1.0, 1.0];
        let opts = RenderOptions {
            width: 64,
            height: 64,
            view: View {
                azimuth: 0.0,
                elevation: 0.0,
            },
            ..Default::default()
        };
        let img = render(&mesh, &Colouring::Scalars(&s), &Overlays::default(), &opts).unwrap();
        let c = img.get(32, 34);
        // Yellow (the near triangle's scalar 1), shaded: red and green well above blue.
        assert!(c[1] as u32 > c[2] as u32 + 60, "{c:?}");
        let far = img.get(32, 48);
        assert!(far[2] > far[1] / 2, "{far:?}");
    }

    /// Scalars spanning almost all of f64 (+-1e308: their difference overflows) colour the
    /// same as the same scalars scaled down.
    #[test]
    fn scalars_near_the_largest_float_keep_their_colours() {
        let mesh = procedural::icosphere(2);
        let small: Vec<f64> = mesh.positions.iter().map(|p| p.z).collect();
        let huge: Vec<f64> = small.iter().map(|z| z * 1e308).collect();
        let opts = RenderOptions {
            width: 64,
            height: 48,
            ..Default::default()
        };
        let none = Overlays::default();
        let a = render(&mesh, &Colouring::Scalars(&small), &none, &opts).unwrap();
        let b = render(&mesh, &Colouring::Scalars(&huge), &none, &opts).unwrap();
        // The left half away from the top and bottom: the surface without the legend and
        // its labels (which differ).
        let mut shaded = 0;
        for y in 12..opts.height - 12 {
            for x in 0..opts.width / 2 {
                let (p, q) = (a.get(x, y), b.get(x, y));
                let same = p.iter().zip(q).all(|(u, v)| u.abs_diff(v) <= 1);
                assert!(same, "({x}, {y}): {p:?} {q:?}");
                shaded += usize::from(!is_bg(p));
            }
        }
        assert!(shaded > 300, "{shaded}");
    }

    #[test]
    fn bad_inputs_are_refused() {
        let mesh = procedural::icosphere(1);
        let o = RenderOptions::default();
        let none = Overlays::default();
        let tex = Image::new(2, 2, [0; 4]).unwrap();
        for (c, what) in [
            (Colouring::Texture(&tex), "texture coordinates"),
            (Colouring::Scalars(&[1.0, 2.0]), "scalars for"),
        ] {
            let e = render(&mesh, &c, &none, &o).unwrap_err();
            assert!(e.to_string().contains(what), "{e}");
        }
        let zero = RenderOptions { width: 0, ..o };
        assert!(render(&mesh, &Colouring::Plain, &none, &zero).is_err());
    }

    #[test]
    fn curves_and_dots_show_over_the_surface_and_hide_behind_it() {
        let mesh = procedural::icosphere(4);
        let o = RenderOptions {
            width: 200,
            height: 200,
            view: View {
                azimuth: 0.0,
                elevation: 0.0,
            },
            ..Default::default()
        };
        // A dot on the near side (+z faces the camera) and one on the far side.
        let ov = Overlays {
            curves: vec![],
            points: vec![Vector3::new(0.0, 0.0, 1.0)],
            ..Default::default()
        };
        let img = render(&mesh, &Colouring::Plain, &ov, &o).unwrap();
        assert!(img.get(100, 100)[2] < 100, "{:?}", img.get(100, 100));
        let ov = Overlays {
            curves: vec![],
            points: vec![Vector3::new(0.0, 0.0, -1.0)],
            ..Default::default()
        };
        let img = render(&mesh, &Colouring::Plain, &ov, &o).unwrap();
        assert!(img.get(100, 100)[2] > 150, "{:?}", img.get(100, 100));
    }

    /// An n x n grid of unit quads in the z = 0 plane, as OBJ text.
    fn quad_grid_obj(n: usize) -> String {
        let mut s = String::new();
        for j in 0..=n {
            for i in 0..=n {
                s += &format!("v {i} {j} 0\n");
            }
        }
        let id = |i: usize, j: usize| j * (n + 1) + i + 1;
        for j in 0..n {
            for i in 0..n {
                let (a, b) = (id(i, j), id(i + 1, j));
                let (c, d) = (id(i + 1, j + 1), id(i, j + 1));
                s += &format!("f {a} {b} {c} {d}\n");
            }
        }
        s
    }

    #[test]
    fn the_wireframe_of_quads_has_no_diagonals_and_of_triangles_all_edges() {
        let n = 3;
        let (mesh, notes) = wavg_mesh::io::parse_bytes(
            quad_grid_obj(n).as_bytes(),
            wavg_mesh::Format::Obj,
            std::path::Path::new("grid.obj"),
        )
        .unwrap();
        assert_eq!(notes.polygon_of.len(), 2 * n * n);
        let opts = RenderOptions {
            width: 240,
            height: 240,
            view: View {
                azimuth: 0.0,
                elevation: 0.0,
            },
            wireframe: true,
            supersample: 1,
        };
        let quads = Overlays {
            polygons: notes.polygon_of.clone(),
            ..Default::default()
        };
        let q = render(&mesh, &Colouring::Plain, &quads, &opts).unwrap();
        let t = render(&mesh, &Colouring::Plain, &Overlays::default(), &opts).unwrap();
        // The pixel under a point of the plane, as `render` places the camera.
        let (c, r) = bounds(&mesh.positions);
        let cam = Camera::fit(c, r, opts.view, 240, 240).framed(&mesh.positions);
        let grey = |img: &Image, x: f64, y: f64| {
            let p = cam.project(&Vector3::new(x, y, 0.0));
            let px = img.get((p[0] - 0.5).round() as u32, (p[1] - 0.5).round() as u32);
            px[..3].iter().map(|&v| v as f64).sum::<f64>() / 3.0
        };
        for j in 0..n {
            for i in 0..n {
                let (x, y) = (i as f64, j as f64);
                // Inside the cell, away from every edge and from the diagonal.
                let face = grey(&q, x + 0.8, y + 0.2);
                assert!(face > 120.0, "cell {i},{j}: surface {face}");
                assert_eq!(face, grey(&t, x + 0.8, y + 0.2));
                for (dx, dy) in [(0.3, 0.3), (0.5, 0.5), (0.7, 0.7)] {
                    // The diagonal (fan from the first corner): surface with the polygons,
                    // a line without them.
                    let (on_q, on_t) = (grey(&q, x + dx, y + dy), grey(&t, x + dx, y + dy));
                    assert!((on_q - face).abs() < 3.0, "cell {i},{j}: {on_q} vs {face}");
                    assert!(on_t < face - 40.0, "cell {i},{j}: {on_t} vs {face}");
                }
                // The quads' own (inner) edges are drawn in both.
                for img in [&q, &t] {
                    for (ex, ey, inner) in [(x + 0.5, y, j > 0), (x, y + 0.5, i > 0)] {
                        let e = grey(img, ex, ey);
                        assert!(
                            !inner || e < face - 40.0,
                            "cell {i},{j}: edge {e} vs {face}"
                        );
                    }
                }
            }
        }
        let bad = Overlays {
            polygons: vec![0; 3],
            ..Default::default()
        };
        let e = render(&mesh, &Colouring::Plain, &bad, &opts).unwrap_err();
        assert!(e.to_string().contains("polygon ids"), "{e}");
    }
}
