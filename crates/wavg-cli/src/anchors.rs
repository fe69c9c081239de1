//! `wavg anchors`: K well-spread anchors of a mesh, written in the anchors format, so no
//! application needs a hand-written anchors file.

use std::io::Write;
use std::path::PathBuf;

use wavg::anchors::{GOOD_GAP, suggested_count};
use wavg::{Anchor, ValidMesh, Vec8, VertexId};

use crate::CliError;
use crate::common::load_valid;
use crate::textio;

/// How the anchors are chosen.
#[derive(clap::ValueEnum, Clone, Copy, Debug, PartialEq, Eq)]
pub enum Method {
    /// Farthest-point sampling in the embedding: each next anchor is the vertex farthest
    /// from those already chosen.
    Fps,
    /// K distinct vertices drawn at random (uniformly) from --seed.
    Random,
}

/// Arguments.
#[derive(clap::Args)]
#[command(after_long_help = "\
Chooses --count vertices as anchors and writes them as `v VERTEX` lines (the anchors
format). By default they are spread by farthest-point sampling in the embedding (the
first vertex drawn from --seed, each next one the vertex farthest from those chosen), which
covers the surface evenly; --method random draws them uniformly at random. The embedding is
--embedding's, else the embedding cache's (computed on first use).

Being vertex ids, the file serves every mesh with the same connectivity (other poses of a
character): give it as both --source-anchors and --target-anchors to carry a texture or a
morph between them.

--json prints one object: mesh, method, seed, count, anchors (each vertex and position
[x, y, z]), largest_gap (the largest distance in the embedding from a vertex to its
nearest anchor, as a fraction of the bounding-box diagonal; 0.08 or less keeps
about 90% of round trips on real meshes) and diagonal.

The text report gives that largest gap and suggests a count when it is above 0.08: measured
on pig, armadillo and elephant, a gap of 0.08 or less keeps 92-99% of round trips (3,000
random points; armadillo: 8 anchors, gap 0.31, 53%; 93 anchors, gap 0.076, 95%).")]
pub struct Args {
    #[command(flatten)]
    pub mesh: crate::mesh_arg::MeshArg,
    /// Number of anchors K (at least 1, at most the vertex count).
    #[arg(long)]
    pub count: usize,
    /// How to choose them.
    #[arg(long, value_enum, default_value_t = Method::Fps)]
    pub method: Method,
    /// Seed of the first (fps) or of every (random) anchor.
    #[arg(long, default_value_t = 0)]
    pub seed: u64,
    #[command(flatten)]
    pub embedding: crate::embedding_arg::EmbeddingArg,
    /// Output anchors file (`-` for standard output).
    #[arg(short = 'o', long = "output")]
    pub output: PathBuf,
    /// Print one JSON object on standard output.
    #[arg(long)]
    pub json: bool,
}

/// The `--json` object.
#[derive(serde::Serialize)]
struct JsonReport<'a> {
    mesh: &'a str,
    method: &'a str,
    seed: u64,
    count: usize,
    anchors: Vec<JsonAnchor>,
    largest_gap: f64,
    diagonal: f64,
}

#[derive(serde::Serialize)]
struct JsonAnchor {
    vertex: VertexId,
    position: [f64; 3],
}

/// Runs the command.
pub fn run(args: Args) -> Result<(), CliError> {
    crate::common::check_outputs(
        &crate::common::inputs([std::path::Path::new(&*args.mesh)], [&args.embedding.file]),
        &[("-o", &args.output)],
        args.json,
    )?;
    let mesh = load_valid(&args.mesh)?;
    if args.count == 0 || args.count > mesh.n_vertices() {
        return Err(CliError::input(format!(
            "--count {} must be from 1 to the mesh's {} vertices",
            args.count,
            mesh.n_vertices()
        )));
    }
    let coords = embedded_coords(&mesh, &args)?;
    let anchors = match args.method {
        Method::Fps => wavg::anchors::spread(&mesh, &coords, args.count, args.seed),
        Method::Random => wavg::anchors::random(&mesh, args.count, args.seed),
    }?;
    let list: Vec<Anchor> = anchors.iter().map(|&v| Anchor::Vertex(v)).collect();
    let text = wavg::anchors::format(&list);
    textio::write_atomic(&args.output, |w: &mut dyn Write| {
        w.write_all(text.as_bytes())
    })?;
    let diagonal = mesh.bounding_box_diagonal();
    let gap = wavg::anchors::largest_gap(&mesh, &coords, &anchors);
    if args.json {
        let list = anchors
            .iter()
            .map(|&v| {
                let p = mesh.positions[v as usize];
                JsonAnchor {
                    vertex: v,
                    position: [p.x, p.y, p.z],
                }
            })
            .collect();
        let method = match args.method {
            Method::Fps => "fps",
            Method::Random => "random",
        };
        let j = serde_json::to_value(JsonReport {
            mesh: &args.mesh,
            method,
            seed: args.seed,
            count: anchors.len(),
            anchors: list,
            largest_gap: gap,
            diagonal,
        })
        .map_err(CliError::failure)?;
        println!("{j}");
    } else if args.output != std::path::Path::new("-") {
        let mut line = format!(
            "{} anchors, largest gap {:.3} of the diagonal -> {}",
            anchors.len(),
            gap,
            args.output.display()
        );
        if gap > GOOD_GAP {
            line.push_str(&format!(
                " (above {GOOD_GAP}: round trips may fail; try --count {})",
                suggested_count(anchors.len(), gap)
            ));
        }
        println!("{line}");
    }
    Ok(())
}

/// Below this fraction of answers that succeed, a command warns.
pub const LOW_FRACTION: f64 = 0.9;

/// Says on stderr, when `fraction` (of round trips that lead back, or of answers that
/// exist) is below [`LOW_FRACTION`], what it is, the likely cause (too few anchors for
/// `mesh`) and the remedy (`wavg anchors --count`). Returns whether it warned.
pub fn warn_if_low(fraction: f64, what: &str, anchors: usize, mesh: &str) -> bool {
    if fraction.is_nan() || fraction >= LOW_FRACTION {
        return false;
    }
    eprintln!(
        "wavg: warning: {what}: {:.1}%, below {:.0}%. The likely cause: {anchors} anchors \
         are too few for this mesh (large gaps between them). The remedy: more anchors, \
         e.g. `wavg anchors {mesh} --count {} -o anchors.txt`.",
        fraction * 100.0,
        LOW_FRACTION * 100.0,
        (2 * anchors).max(32)
    );
    true
}

/// The embedding's coordinates: `--embedding`'s file or the cache's.
fn embedded_coords(mesh: &std::sync::Arc<ValidMesh>, args: &Args) -> Result<Vec<Vec8>, CliError> {
    let e = match &args.embedding.file {
        Some(p) => wavg::embed::file::load(p, mesh)?,
        None => crate::cache::embedding(mesh, &args.mesh, args.embedding.cache.no_cache)?,
    };
    Ok(e.coords.iter().map(|c| Vec8::from(*c)).collect())
}
