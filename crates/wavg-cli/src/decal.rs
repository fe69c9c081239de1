//! `wavg decal`: a local parametrisation from anchors that carry `(u, v)` coordinates;
//! every vertex gets `uv = sum_i w_i uv_i` with the paper's inverse weights.

use std::io::Write;
use std::path::{Path, PathBuf};
use std::time::Instant;

use wavg::apps::{DecalReport, decal_scene, decal_vertices, untextured_faces, write_decal_obj};
use wavg::mesh::io::gltf::is_gltf_path;

use crate::CliError;
use crate::apps_common::mesh_and_anchors;
use crate::decal_material;
use crate::textio::{self, located};

/// Arguments.
#[derive(clap::Args)]
#[command(after_long_help = "\
Gives every vertex (u, v) coordinates: the anchors (--anchors, `v VERTEX` or `f FACE B0 B1
B2` per line) carry the coordinates of --uv (`U V` per line, one line per anchor, in the
same order), and a vertex with inverse-problem weights w (the paper's weights, continuous
over the surface) gets uv = sum_i w_i uv_i. A vertex is marked where its weights are not
meaningful: they do not return to it through the forward problem, or one is below
--max-negative (its uv is still written; 0 0 where the inverse problem failed).

Output: an OBJ of the mesh with one `vt` per vertex and faces `f a/a b/b c/c`; a face with
a marked corner is written `f a b c` (no texture coordinates: it shows untextured instead of
smearing the texture). Beside a file output go STEM.mtl (material `decal` with --texture as
`map_Kd`, or STEM_checker.png, a checkerboard with a transparent border written there;
material `plain` for the faces without coordinates) and the OBJ's `mtllib`/`usemtl` lines,
so `wavg render OUT.obj --texture TEXTURE` and viewers show the decal. --json prints
one object: vertices, valid_fraction (unmarked vertices), stretch (symmetrised L2 stretch of
the surface-to-plane map over faces with three unmarked corners; null when there is none),
flipped_faces (against the
decal's own orientation), seconds, marked (the marked vertex ids), untextured_faces (faces
with a marked corner), mtl and texture (the files the OBJ names; null for `-o -`), plus mesh
and anchors.

With -o OUT.glb (or OUT.gltf, its buffer in OUT.bin) the decal is written as glTF instead:
TEXCOORD_0 per vertex on the faces with three unmarked corners, whose base colour texture
is --texture (or the checkerboard) embedded as PNG; the faces with a marked corner form a
second primitive, without texture coordinates, in plain grey. No .mtl is written (mtl and
texture are null in --json).")]
pub struct Args {
    #[command(flatten)]
    pub surface: crate::embedding_arg::SurfaceArgs,
    /// Anchors, one per line (`v VERTEX` or `f FACE B0 B1 B2`).
    #[arg(long)]
    pub anchors: PathBuf,
    /// The anchors' coordinates, `U V` per line, as many lines as anchors.
    #[arg(long)]
    pub uv: PathBuf,
    /// The most negative weight a vertex may have without being marked (at most 0).
    #[arg(long, default_value_t = wavg::apps::DEFAULT_MAX_NEGATIVE, allow_negative_numbers = true, value_parser = crate::common::parse_max_negative)]
    pub max_negative: f64,
    /// Output OBJ file (`-` for standard output), or .glb/.gltf.
    #[arg(short = 'o', long = "output")]
    pub output: PathBuf,
    /// The decal's image (PNG), named in the .mtl written beside the OBJ (default: a
    /// checkerboard written beside it as STEM_checker.png).
    #[arg(long)]
    pub texture: Option<PathBuf>,
    /// Print one JSON object on standard output.
    #[arg(long)]
    pub json: bool,
}

/// The `--json` object: the [`DecalReport`] with the inputs, the timing and the marked
/// vertices (printed through `serde_json::Value`, so keys come out sorted).
#[derive(serde::Serialize)]
struct JsonReport<'a> {
    mesh: &'a str,
    anchors: usize,
    #[serde(flatten)]
    decal: DecalReport,
    seconds: f64,
    marked: Vec<usize>,
    untextured_faces: usize,
    mtl: Option<&'a Path>,
    texture: Option<&'a Path>,
}

/// Runs the command.
pub fn run(args: Args) -> Result<(), CliError> {
    // The .mtl and checkerboard written beside the OBJ are outputs too.
    let (mtl, checker) = decal_material::side_files(&args.output);
    let mut outputs = vec![("-o", args.output.as_path())];
    if args.output != std::path::Path::new("-") {
        outputs.push(("its .mtl", mtl.as_path()));
        if args.texture.is_none() {
            outputs.push(("its checkerboard", checker.as_path()));
        }
    }
    crate::common::check_outputs(
        &crate::common::inputs(
            [
                std::path::Path::new(&*args.surface.mesh),
                &args.anchors,
                &args.uv,
            ],
            [&args.surface.embedding.file, &args.texture],
        ),
        &outputs,
        args.json,
    )?;
    if !is_gltf_path(&args.output) {
        crate::common::require_extension(
            &args.output,
            "obj",
            "a decal is written as an OBJ file (with its .mtl and texture) or .glb/.gltf",
        )?;
    }
    let text = textio::read_text(&args.uv)?;
    let lines =
        wavg::text::parse_weights(&text, 1).map_err(|e| located(&args.uv, e.line, &e.message))?;
    let mut uv = Vec::with_capacity(lines.len());
    for (line, v) in &lines {
        match v[..] {
            [u, v] => uv.push([u, v]),
            _ => {
                return Err(located(
                    &args.uv,
                    *line,
                    &format!("expected `U V` (2 numbers), found {}", v.len()),
                ));
            }
        }
    }
    if !args.max_negative.is_finite() {
        return Err(CliError::input("--max-negative must be a finite number"));
    }
    if let Some(t) = &args.texture {
        decal_material::check_texture(t)?;
    }
    let (mesh, anchors) = mesh_and_anchors(&args.surface.mesh, &args.anchors)?;
    if uv.len() != anchors.len() {
        return Err(CliError::input(format!(
            "{} has {} (u, v) lines but {} has {} anchors; give one per anchor",
            args.uv.display(),
            uv.len(),
            args.anchors.display(),
            anchors.len()
        )));
    }
    let surface = args.surface.embed(mesh)?;
    let solver = surface.solver(anchors)?;
    let t = Instant::now();
    let decal = decal_vertices(&solver, &uv, args.max_negative)?;
    let seconds = t.elapsed().as_secs_f64();
    let mesh = surface.mesh();
    if is_gltf_path(&args.output) {
        let png = decal_material::png_bytes(args.texture.as_deref())?;
        decal_scene(mesh, &decal.uv, Some(png))
            .save(&args.output)
            .map_err(wavg::Error::from)?;
    }
    let material = if is_gltf_path(&args.output) {
        None
    } else {
        decal_material::write(&args.output, args.texture.as_deref())?
    };
    let mtllib = material.as_ref().map(decal_material::Material::file_name);
    if !is_gltf_path(&args.output) {
        textio::write_atomic(&args.output, |w: &mut dyn Write| {
            write_decal_obj(w, mesh, &decal.uv, mtllib.as_deref())
        })
        .inspect_err(|_| {
            if let Some(m) = &material {
                m.remove();
            }
        })?;
    }
    let untextured_faces = untextured_faces(mesh, &decal.uv);
    let marked: Vec<usize> = (0..mesh.n_vertices())
        .filter(|&v| decal.uv.marked[v])
        .collect();
    let report = decal.report();
    if args.json {
        let j = serde_json::to_value(JsonReport {
            mesh: &args.surface.mesh,
            anchors: uv.len(),
            decal: report,
            seconds,
            marked,
            untextured_faces,
            mtl: material.as_ref().map(|m| m.mtl.as_path()),
            texture: material.as_ref().map(|m| m.texture.as_path()),
        })
        .map_err(CliError::failure)?;
        println!("{j}");
    } else if args.output != std::path::Path::new("-") {
        let n = report.vertices;
        println!(
            "{} of {n} vertices unmarked ({:.1}%), stretch {}, {} flipped faces -> {}",
            n - marked.len(),
            100.0 * report.valid_fraction,
            report
                .stretch
                .map_or("- (no face measured)".into(), |s| format!("{s:.4}")),
            report.flipped_faces,
            args.output.display()
        );
        if let Some(m) = &material {
            println!(
                "material {} with texture {} ({untextured_faces} faces with a marked corner \
                 untextured)",
                m.mtl.display(),
                m.texture.display()
            );
        }
    }
    Ok(())
}
