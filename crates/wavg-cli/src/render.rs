//! `wavg render`: a picture of a mesh (PNG), shaded, optionally textured or coloured by
//! per-vertex scalars, with curves, dots and a wireframe drawn over it.

use std::io::Write;
use std::path::{Path, PathBuf};
use std::time::Instant;

use wavg::TriMesh;
use wavg::Vector3;
use wavg::apps::{
    Colouring, Image, Overlays, RenderOptions, RenderReport, View, curves_scene, render,
};
use wavg::mesh::io::gltf::is_gltf_path;

use crate::CliError;
use crate::common::load_mesh_notes;
use crate::error::Context;
use crate::textio::{self, read_points, read_text, resolve_points};

/// Arguments.
#[derive(clap::Args)]
#[command(after_long_help = "\
Draws the mesh with a z-buffered software rasteriser: Lambert shading plus a little ambient
light on smooth vertex normals, a perspective camera looking at the mesh's centre from
--view AZIMUTH,ELEVATION (degrees; y is up; default 35,20), white background, 2x2
supersampling.

Colour: light grey, or --texture T.png through the mesh's OBJ texture coordinates (`vt`,
bilinear; faces without them, as `wavg decal` writes the unusable ones, stay grey), or
--scalar S.txt (one number per vertex and line) through the viridis colour map with a
legend bar labelled with the minimum and maximum. A glTF mesh with texture coordinates and a
base colour texture is drawn with that texture unless --texture or --scalar is given.
Overlays: --curve C.txt (the output of `wavg spline`: `FACE B0 B1 B2 X Y Z` per sample,
`none ...` lines break the curve) as a thick red line, --points P.txt (the anchors
format: `v VERTEX` or `f FACE B0 B1 B2`) as dots, --wireframe the edges of the file's
polygons (a quad mesh shows quads: the diagonals that triangulation added are not drawn). Curves and
dots are depth-tested against the surface with a small bias, so parts behind it are hidden.

Bad input (a missing texture, --texture on a mesh without UVs, a scalar count that differs
from the vertex count) is an error and nothing is written. --json prints one object:
output, width, height, vertices, faces, covered_fraction (of pixels showing the mesh),
seconds, plus scalar_min and scalar_max with --scalar.

With -o OUT.glb (or OUT.gltf, its buffer in OUT.bin) the scene is written as glTF instead
of the picture: the mesh (with --texture embedded as its base colour texture) and each
--curve as a polyline (LINE_STRIP, one per unbroken run of samples); --points, --scalar and
--wireframe are not written.")]
pub struct Args {
    #[command(flatten)]
    pub mesh: crate::mesh_arg::MeshArg,
    /// Output PNG, or .glb/.gltf: the mesh and its curves.
    #[arg(short = 'o', long = "output")]
    pub output: PathBuf,
    /// Picture size WIDTHxHEIGHT in pixels.
    #[arg(long, default_value = "800x600")]
    pub size: String,
    /// Camera direction AZIMUTH,ELEVATION in degrees.
    #[arg(long, allow_hyphen_values = true)]
    pub view: Option<String>,
    /// A curve to draw (`wavg spline` output).
    #[arg(long)]
    pub curve: Vec<PathBuf>,
    /// Points to draw as dots (anchors format).
    #[arg(long)]
    pub points: Option<PathBuf>,
    /// A texture (PNG or JPEG) mapped through the mesh's UVs.
    #[arg(long, conflicts_with = "scalar")]
    pub texture: Option<PathBuf>,
    /// Per-vertex scalars (one number per line), coloured with viridis.
    #[arg(long)]
    pub scalar: Option<PathBuf>,
    /// Draw the triangle edges.
    #[arg(long)]
    pub wireframe: bool,
    /// Print one JSON object on standard output.
    #[arg(long)]
    pub json: bool,
}

/// The `--json` object: the library's [`RenderReport`] with the output file (printed
/// through `serde_json::Value`, so keys come out sorted).
#[derive(serde::Serialize)]
struct JsonReport<'a> {
    output: &'a Path,
    #[serde(flatten)]
    report: RenderReport,
}

/// Parses `WxH` (or a single `N` for a square).
pub fn parse_size(s: &str, what: &str) -> Result<(u32, u32), CliError> {
    let bad = || CliError::input(format!("{what} {s:?}: expected WIDTHxHEIGHT, e.g. 800x600"));
    let (w, h) = match s.split_once(['x', 'X']) {
        Some((w, h)) => (w, h),
        None => (s, s),
    };
    let w: u32 = w.trim().parse().map_err(|_| bad())?;
    let h: u32 = h.trim().parse().map_err(|_| bad())?;
    if w == 0 || h == 0 {
        return Err(bad());
    }
    Ok((w, h))
}

/// Parses `AZIMUTH,ELEVATION` in degrees.
fn parse_view(s: &str) -> Result<View, CliError> {
    let bad = || {
        CliError::input(format!(
            "--view {s:?}: expected AZIMUTH,ELEVATION in degrees"
        ))
    };
    let (a, e) = s.split_once(',').ok_or_else(bad)?;
    let azimuth: f64 = a.trim().parse().map_err(|_| bad())?;
    let elevation: f64 = e.trim().parse().map_err(|_| bad())?;
    if !azimuth.is_finite() || !(-90.0..=90.0).contains(&elevation) {
        return Err(bad());
    }
    Ok(View { azimuth, elevation })
}

/// Reads a curve file (`FACE B0 B1 B2 X Y Z` or `none ...` per line) into polylines of its
/// 3-D positions, broken at `none` lines.
pub fn read_curve(path: &Path) -> Result<Vec<Vec<Vector3<f64>>>, CliError> {
    let text = read_text(path)?;
    let mut out = vec![Vec::new()];
    for (i, line) in text.lines().enumerate() {
        let line = line.trim();
        if line.is_empty() || line.starts_with('#') {
            continue;
        }
        if line.starts_with("none") {
            out.push(Vec::new());
            continue;
        }
        let xs: Vec<f64> = line
            .split_whitespace()
            .map(|t| t.parse::<f64>())
            .collect::<Result<_, _>>()
            .map_err(|_| textio::located(path, i + 1, &"expected FACE B0 B1 B2 X Y Z or none"))?;
        if xs.len() != 7 || !xs.iter().all(|x| x.is_finite()) {
            return Err(textio::located(path, i + 1, &"expected 7 finite numbers"));
        }
        out.last_mut()
            .expect("non-empty")
            .push(Vector3::new(xs[4], xs[5], xs[6]));
    }
    out.retain(|c| !c.is_empty());
    Ok(out)
}

/// Reads one number per line.
pub fn read_scalars(path: &Path) -> Result<Vec<f64>, CliError> {
    let text = read_text(path)?;
    let mut out = Vec::new();
    for (i, line) in text.lines().enumerate() {
        let line = line.trim();
        if line.is_empty() || line.starts_with('#') {
            continue;
        }
        match line.parse::<f64>() {
            Ok(x) if x.is_finite() => out.push(x),
            _ => return Err(textio::located(path, i + 1, &"expected one finite number")),
        }
    }
    Ok(out)
}

/// Writes an image as PNG atomically (nothing is left at `path` on error).
pub fn write_png(path: &Path, img: &Image) -> Result<(), CliError> {
    textio::write_atomic(path, |w: &mut dyn Write| {
        img.encode_png(w).map_err(std::io::Error::other)
    })
}

/// Runs the command.
pub fn run(args: Args) -> Result<(), CliError> {
    let mut inputs = crate::common::inputs(
        [std::path::Path::new(&*args.mesh)],
        [&args.points, &args.texture, &args.scalar],
    );
    inputs.extend(args.curve.iter().map(|p| p.as_path()));
    crate::common::check_outputs(&inputs, &[("-o", &args.output)], args.json)?;
    let (width, height) = parse_size(&args.size, "--size")?;
    let view = args
        .view
        .as_deref()
        .map(parse_view)
        .transpose()?
        .unwrap_or_default();
    let t = Instant::now();
    let (mut mesh, mut notes): (TriMesh, _) = load_mesh_notes(&args.mesh)?;
    let notes_texture = wavg::LoadNotes {
        texture: notes.texture.take(),
        ..Default::default()
    };
    if args.texture.is_some() && mesh.uv.is_none() {
        // Faces the file gave no texture coordinates are drawn plain.
        mesh.uv = notes.partial_uv;
    }
    let mut overlays = Overlays {
        polygons: notes.polygon_of,
        ..Default::default()
    };
    for c in &args.curve {
        overlays.curves.extend(read_curve(c)?);
    }
    if let Some(p) = &args.points {
        let specs = read_points(p)?;
        let valid = crate::common::load_valid(&args.mesh)?;
        let pts = resolve_points(&valid, &specs, p)?;
        overlays.points = pts.iter().map(|q| q.position(&mesh)).collect();
    }
    let texture = match &args.texture {
        Some(path) => Some(Image::read(path)?),
        // A glTF file's own base colour texture, when no colouring is asked for.
        None if args.scalar.is_none() && mesh.uv.is_some() => wavg::mesh_texture(&notes_texture)?,
        None => None,
    };
    let scalars = args.scalar.as_deref().map(read_scalars).transpose()?;
    let colouring = match (&texture, &scalars) {
        (Some(t), _) => Colouring::Texture(t),
        (None, Some(s)) => Colouring::Scalars(s),
        (None, None) => Colouring::Plain,
    };
    let opts = RenderOptions {
        width,
        height,
        view,
        wireframe: args.wireframe,
        ..Default::default()
    };
    let file = match colouring {
        Colouring::Texture(_) => match &args.texture {
            Some(t) => format!(" with {}", t.display()),
            None => " with its base colour texture".to_string(),
        },
        Colouring::Scalars(_) => format!(" with {}", args.scalar.as_ref().expect("set").display()),
        Colouring::Plain => String::new(),
    };
    let img =
        render(&mesh, &colouring, &overlays, &opts).context(format_args!("{}{file}", args.mesh))?;
    if is_gltf_path(&args.output) {
        let curves: Vec<_> = overlays.curves.iter().map(|c| (c.clone(), false)).collect();
        let mut scene = curves_scene(Some(&mesh), &curves);
        if let (Some(t), Some(m)) = (&texture, scene.meshes.first_mut()) {
            let mut png = Vec::new();
            t.encode_png(&mut png).map_err(wavg::Error::from)?;
            m.texture_png = Some(png);
        }
        scene.save(&args.output).map_err(wavg::Error::from)?;
    } else {
        write_png(&args.output, &img)?;
    }
    let seconds = t.elapsed().as_secs_f64();
    if args.json {
        let report = RenderReport::new(&mesh, &img, scalars.as_deref(), seconds);
        let j = serde_json::to_value(JsonReport {
            output: &args.output,
            report,
        })
        .map_err(CliError::failure)?;
        println!("{j}");
    } else {
        println!(
            "{width}x{height} picture in {seconds:.2} s -> {}",
            args.output.display()
        );
    }
    Ok(())
}
