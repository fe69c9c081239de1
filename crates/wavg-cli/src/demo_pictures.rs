//! The pictures `wavg demo --out DIR` draws of its results: the spline over the mesh, a
//! per-vertex scalar (distance in the embedding from the first anchor, which behaves like
//! a geodesic distance), and a checkerboard carried from a generated UV-mapped sheet to a
//! bent and stretched copy of it (texture transfer through corresponding anchors), and
//! the remeshing and decal pictures of `demo_apps`.

use std::path::{Path, PathBuf};

use wavg::Vector3;
use wavg::apps::{Colouring, Image, Overlays, RenderOptions, TransferOptions, View};
use wavg::sampling::{FpsMetric, farthest_point_vertices};
use wavg::{ForwardResult, SolveError};
use wavg::{NoProgress, PrecomputeOptions, Surface};
use wavg::{TexCoords, TriMesh, ValidMesh};

use crate::CliError;
use crate::render::write_png;

/// Picture size of the demo.
const SIZE: (u32, u32) = (640, 480);

/// The pictures drawn, and those skipped with the reason (the applications that depend on
/// the user's surface may not apply to it, and a picture should not sink the demo).
#[derive(Default)]
pub struct Pictures {
    /// Paths of the pictures written.
    pub written: Vec<PathBuf>,
    /// `(file name, reason)` of each picture not drawn.
    pub skipped: Vec<(String, String)>,
}

/// Draws the demo's pictures into `dir`.
pub fn write_pictures(
    dir: &Path,
    surface: &Surface,
    anchors: &[u32],
    curve: &[Result<ForwardResult, SolveError>],
    solver: &wavg::Solver,
    seed: u64,
) -> Result<Pictures, CliError> {
    // The pictures' own inputs (sheet, checkerboard) failing is a bug of the demo: exit 1.
    let fail = |what: &str, e: &dyn std::fmt::Display| {
        CliError::failure(format!("{}: {what}: {e}", dir.display()))
    };
    let tri = surface.mesh().mesh();
    let opts = RenderOptions {
        width: SIZE.0,
        height: SIZE.1,
        view: View {
            azimuth: 30.0,
            elevation: 25.0,
        },
        ..Default::default()
    };
    let dots: Vec<Vector3<f64>> = anchors.iter().map(|&v| tri.positions[v as usize]).collect();
    let mut pictures = Pictures::default();
    let mut save = |name: &str, img: Result<Image, CliError>| -> Result<(), CliError> {
        match img {
            Ok(img) => {
                let p = dir.join(name);
                write_png(&p, &img)?;
                pictures.written.push(p);
            }
            Err(e) => pictures.skipped.push((name.to_string(), e.message)),
        }
        Ok(())
    };

    // The spline through the anchors (closed: the last sample joins the first).
    let mut line: Vec<Vector3<f64>> = curve.iter().flatten().map(|r| r.position).collect();
    if let Some(&first) = line.first() {
        line.push(first);
    }
    let ov = Overlays {
        curves: vec![line],
        points: dots.clone(),
        ..Default::default()
    };
    let img = wavg::apps::render(tri, &Colouring::Plain, &ov, &opts)
        .map_err(|e| fail("spline.png", &e))?;
    save("spline.png", Ok(img))?;

    // A per-vertex scalar: distance in the embedding from the first anchor.
    let dist = surface
        .embedding_distances(anchors[0])
        .map_err(|e| fail("distance.png", &e))?;
    let ov = Overlays {
        curves: vec![],
        points: dots[..1].to_vec(),
        ..Default::default()
    };
    let img = wavg::apps::render(tri, &Colouring::Scalars(&dist), &ov, &opts)
        .map_err(|e| fail("distance.png", &e))?;
    save("distance.png", Ok(img))?;

    // Texture transfer between two generated shapes.
    let (src, dst) = (sheet(false), sheet(true));
    let checker = checkerboard(256, 8).map_err(|e| fail("checkerboard", &e))?;
    // The same vertices (by index) are the anchors of both sheets: they correspond.
    let src_valid = ValidMesh::new(src.clone()).map_err(|e| fail("sheet", &e))?;
    let ids = farthest_point_vertices(&src_valid, 16, seed, FpsMetric::EdgeGraph)
        .map_err(|e| fail("sheet anchors", &e))?;
    let sheet_solver = |m: &TriMesh| -> Result<wavg::Solver, CliError> {
        let mut s = Surface::from_mesh(m.clone()).map_err(|e| fail("sheet", &e))?;
        let opts = PrecomputeOptions {
            landmarks: 40,
            quality_pairs: 0,
            seed,
            ..Default::default()
        };
        s.precompute(&opts, &NoProgress)
            .map_err(|e| fail("sheet", &e))?;
        s.solver(ids.iter().copied()).map_err(|e| fail("sheet", &e))
    };
    let (s_src, s_dst) = (sheet_solver(&src)?, sheet_solver(&dst)?);
    let topts = TransferOptions {
        width: 256,
        height: 256,
        ..Default::default()
    };
    let moved = wavg::apps::transfer_texture(&s_src, &checker, &s_dst, &topts, &|_, _| {})
        .map_err(|e| fail("texture transfer", &e))?;
    let view = RenderOptions {
        view: View {
            azimuth: 20.0,
            elevation: 30.0,
        },
        ..opts
    };
    let none = Overlays::default();
    let img = wavg::apps::render(&src, &Colouring::Texture(&checker), &none, &view)
        .map_err(|e| fail("texture_source.png", &e))?;
    save("texture_source.png", Ok(img))?;
    let img = wavg::apps::render(&dst, &Colouring::Texture(&moved.image), &none, &view)
        .map_err(|e| fail("texture_target.png", &e))?;
    save("texture_target.png", Ok(img))?;

    // Remeshing: a cube's quads on the surface, three levels, five smoothing steps.
    save(
        "remesh.png",
        crate::demo_apps::remesh_picture(solver, &opts),
    )?;

    // A decal around the first anchor; outside the square the board is transparent.
    let board = decal_board().map_err(|e| fail("checkerboard", &e))?;
    let img = crate::demo_apps::decal_picture(solver, anchors[0], &board, &opts);
    save("decal.png", img)?;
    Ok(pictures)
}

/// A UV-mapped 2 x 2 sheet with a bump (u, v from x, y); `bent` stretches it by 1.25
/// along x and bends it into a trough.
fn sheet(bent: bool) -> TriMesh {
    let mut m = wavg::mesh::procedural::grid(24, 24, 2.0, 2.0);
    let coords = m
        .positions
        .iter()
        .map(|p| [p.x / 2.0, p.y / 2.0].into())
        .collect();
    m.uv = Some(TexCoords {
        coords,
        faces: m.triangles.clone(),
    });
    for p in &mut m.positions {
        let (x, y) = (p.x - 1.0, p.y - 1.0);
        p.z = 0.35 * (-(x * x + y * y) * 4.0).exp();
        if bent {
            p.x = 1.0 + 1.25 * x;
            p.z += 0.45 * x * x;
        }
    }
    m
}

/// The decal's checkerboard (256 x 256, 8 x 8 squares) with a transparent one-pixel
/// border, so that texture coordinates outside the unit square (clamped to the border)
/// show the surface's own colour.
pub fn decal_board() -> Result<Image, wavg::apps::AppError> {
    let mut board = checkerboard(256, 8)?;
    for i in 0..256 {
        for (x, y) in [(i, 0), (i, 255), (0, i), (255, i)] {
            board.set(x, y, [0; 4]);
        }
    }
    Ok(board)
}

/// A `size` x `size` checkerboard of `n` x `n` squares in two colours, with a red and a
/// blue corner square so that orientation shows.
fn checkerboard(size: u32, n: u32) -> Result<Image, wavg::apps::AppError> {
    let mut img = Image::new(size, size, [0; 4])?;
    let cell = size / n;
    for y in 0..size {
        for x in 0..size {
            let (i, j) = (x / cell, y / cell);
            let c = match (i, j) {
                (0, 0) => [220, 50, 40, 255],
                (i, 0) if i == n - 1 => [40, 90, 220, 255],
                _ if (i + j) % 2 == 0 => [245, 240, 225, 255],
                _ => [60, 60, 70, 255],
            };
            img.set(x, y, c);
        }
    }
    Ok(img)
}
