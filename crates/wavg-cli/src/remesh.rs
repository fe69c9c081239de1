//! `wavg remesh`: semiregular remeshing of a coarse polygon base mesh on the surface, with
//! Laplacian smoothing on the surface; optionally times interactive recomputation while a
//! base vertex is dragged.

use std::io::Write;
use std::path::{Path, PathBuf};
use std::time::Instant;

use wavg::Surface;
use wavg::apps::{BaseMesh, RemeshReport, Remesher, polygons_scene, polygons_to_obj};
use wavg::mesh::io::gltf::is_gltf_path;
use wavg_bench::{DragOptions, DragReport, drag_remesh};

use crate::CliError;
use crate::common::load_valid;
use crate::error::Context;
use crate::textio;

/// Arguments.
#[derive(clap::Args)]
#[command(after_long_help = "\
Refines the coarse polygon mesh --base (an OBJ of triangles, quads and larger polygons,
in the coordinates of --mesh) on the surface --mesh. Each base vertex is first put at its
closest point of the surface (refused when farther than --max-distance bounding-box
diagonals). Each of --levels splits every edge at the weighted average of its ends
(weights 1/2, 1/2) and every polygon of n >= 4 corners at the average of its corners
(weights 1/n) into n quads; a triangle becomes four triangles. Then --smooth steps of
uniform Laplacian smoothing move every interior vertex to the average of its neighbours;
vertices on the boundary of an open base stay. Every average is a forward problem on the
surface over its own 2 to n points.

Output: the refined mesh as OBJ (quads where the base had polygons of 4 or more corners,
triangles where it had triangles), or glTF for -o OUT.glb / OUT.gltf (the polygons
fan-triangulated). --json prints one object: base_faces, base_vertices,
vertices, faces, levels, smooth_steps, seconds (the first, cold remeshing), warm_seconds
(median of --frames recomputations while base vertex --drag moves, each warm-started from
the previous frame; null with --frames 0), warm_seconds_max, warm_cpu_seconds (mean CPU
time of all threads per frame), frames, max_offsurface
(largest 3-D distance of an output vertex from the mesh over its bounding-box diagonal),
roughness (mean umbrella length over mean edge length), problems (forward problems
solved; also as forward_problems_solved), fallbacks, threads,
precompute_seconds, plus mesh and base.

This is the paper's semiregular remeshing (Section 4.1). Bad bases (empty, out-of-range
indices, non-manifold, far from the surface, malformed lines) exit with status 2 and write
nothing. From Rust: wavg::apps::Remesher; from C: wavg_remesher_new, _run, _move_vertex,
_get.")]
pub struct Args {
    #[command(flatten)]
    pub mesh: crate::mesh_arg::MeshArg,
    /// The coarse base mesh (OBJ with polygons).
    #[arg(long)]
    pub base: PathBuf,
    #[command(flatten)]
    pub embedding: crate::embedding_arg::EmbeddingArg,
    /// Levels of splitting (each multiplies the face count by about four).
    #[arg(long, default_value_t = wavg::apps::DEFAULT_LEVELS)]
    pub levels: usize,
    /// Laplacian smoothing steps after splitting.
    #[arg(long, default_value_t = wavg::apps::DEFAULT_SMOOTH_STEPS)]
    pub smooth: usize,
    /// Largest distance of a base vertex from the surface, over the bounding-box diagonal.
    #[arg(long, default_value_t = wavg::apps::DEFAULT_MAX_BASE_DISTANCE, allow_negative_numbers = true, value_parser = crate::common::parse_max_base_distance)]
    pub max_distance: f64,
    /// Recomputations to time while dragging a base vertex (0: none).
    #[arg(long, default_value_t = 10, value_parser = crate::common::parse_frames)]
    pub frames: usize,
    /// The base vertex dragged by --frames.
    #[arg(long, default_value_t = 0)]
    pub drag: usize,
    /// Worker threads (default: all cores; the limit: docs/limits.md).
    #[arg(long, value_parser = crate::common::parse_threads)]
    pub threads: Option<usize>,
    /// Output OBJ file (`-` for standard output; written atomically), or .glb/.gltf (the
    /// polygons fan-triangulated).
    #[arg(short = 'o', long = "output")]
    pub output: PathBuf,
    /// Print one JSON object on standard output.
    #[arg(long)]
    pub json: bool,
}

/// Runs the command.
pub fn run(args: Args) -> Result<(), CliError> {
    crate::common::check_outputs(
        &crate::common::inputs(
            [std::path::Path::new(&*args.mesh), &args.base],
            [&args.embedding.file],
        ),
        &[("-o", &args.output)],
        args.json,
    )?;
    crate::common::refuse_other_mesh_format(
        &args.output,
        "the refined mesh is written as OBJ (its polygons) or glTF",
    )?;
    // Comments may hold any bytes (an exporter's Latin-1 name), as in every OBJ read.
    let text = textio::read_text(&args.base)?;
    let base = BaseMesh::from_obj_str(&text).context(args.base.display())?;
    base.validate().context(args.base.display())?;
    if args.levels > wavg::apps::MAX_LEVELS {
        return Err(CliError::input(format!(
            "--levels is at most {}",
            wavg::apps::MAX_LEVELS
        )));
    }
    if args.smooth > wavg::apps::MAX_SMOOTH_STEPS {
        return Err(CliError::input(format!(
            "--smooth is at most {}",
            wavg::apps::MAX_SMOOTH_STEPS
        )));
    }
    if args.frames > 0 && args.drag >= base.positions.len() {
        return Err(CliError::input(format!(
            "--drag {} is not a base vertex ({} vertices)",
            args.drag,
            base.positions.len()
        )));
    }
    let threads = args.threads;
    textio::with_threads(threads, move || run_in_pool(args, base))?
}

fn run_in_pool(args: Args, base: BaseMesh) -> Result<(), CliError> {
    let t = Instant::now();
    let surface = surface_for(&args)?;
    let precompute_seconds = args
        .embedding
        .file
        .is_none()
        .then(|| t.elapsed().as_secs_f64());
    let mut r = Remesher::with_max_distance(surface.projector().clone(), &base, args.max_distance)
        .context(args.base.display())?;
    let t = Instant::now();
    let out = r.remesh(args.levels, args.smooth)?;
    let seconds = t.elapsed().as_secs_f64();
    let drag = drag_frames(&mut r, &base, &args)?;
    let warm = drag.median_s;
    // The file is the first (undragged) result.
    if is_gltf_path(&args.output) {
        polygons_scene(&out.positions, &out.faces)
            .save(&args.output)
            .map_err(wavg::Error::from)?;
    } else {
        let obj = polygons_to_obj(&out.positions, &out.faces);
        textio::write_atomic(&args.output, |w: &mut dyn Write| {
            w.write_all(obj.as_bytes())
        })?;
    }
    if args.json {
        let remesh = r.report(&out);
        let j = serde_json::to_value(JsonReport {
            mesh: &args.mesh,
            base: &args.base,
            forward_problems_solved: remesh.problems,
            remesh,
            seconds,
            warm_seconds: warm,
            warm_seconds_max: drag.max_s,
            warm_cpu_seconds: drag.cpu_s,
            frames: args.frames,
            threads: rayon::current_num_threads(),
            precompute_seconds,
        })
        .map_err(CliError::failure)?;
        println!("{j}");
    } else if args.output != std::path::Path::new("-") {
        println!(
            "{} vertices, {} faces ({} levels, {} smoothing steps) in {:.1} ms{} -> {}",
            out.positions.len(),
            out.faces.len(),
            out.levels,
            out.smooth_steps,
            seconds * 1e3,
            warm.map_or(String::new(), |w| format!(
                ", {:.1} ms per dragged frame",
                w * 1e3
            )),
            args.output.display()
        );
    }
    Ok(())
}

/// The `--json` object: the [`RemeshReport`] with the inputs and the timings (printed
/// through `serde_json::Value`, so keys come out sorted).
#[derive(serde::Serialize)]
struct JsonReport<'a> {
    mesh: &'a str,
    base: &'a Path,
    #[serde(flatten)]
    remesh: RemeshReport,
    /// The report's `problems` under a name that says what they are.
    forward_problems_solved: usize,
    seconds: f64,
    warm_seconds: Option<f64>,
    warm_seconds_max: Option<f64>,
    warm_cpu_seconds: Option<f64>,
    frames: usize,
    threads: usize,
    precompute_seconds: Option<f64>,
}

/// Times `--frames` recomputations while base vertex `--drag` moves (the bench crate's
/// protocol).
fn drag_frames(r: &mut Remesher, base: &BaseMesh, args: &Args) -> Result<DragReport, CliError> {
    let opts = DragOptions {
        vertex: args.drag,
        frames: args.frames,
        levels: args.levels,
        smooth: args.smooth,
        cpu_clock: Some(|| crate::common::cpu_seconds(false)),
    };
    drag_remesh(r, base, &opts)
        .map_err(|e| CliError::from(e.error).context(format_args!("dragged frame {}", e.frame)))
}

/// The surface with its embedding: loaded, or the embedding cache's.
fn surface_for(args: &Args) -> Result<Surface, CliError> {
    crate::apps_common::embed(
        load_valid(&args.mesh)?,
        args.embedding.file.as_deref(),
        &args.mesh,
        args.embedding.cache,
    )
}
