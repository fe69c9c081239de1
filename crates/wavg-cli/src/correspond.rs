//! `wavg correspond`: a map of every source vertex onto the target through paired anchors
//! (inverse problem on the source, forward problem on the target), each vertex judged by a
//! validity test.

use std::io::Write;
use std::path::{Path, PathBuf};
use std::time::Instant;

use wavg::apps::{
    CorrespondOptions, CorrespondTimings, Correspondence, Distortion, GroundTruthErrors,
    ReasonCounts, ValidityTest, correspond_vertices, correspondence_scene,
};
use wavg::mesh::io::gltf::is_gltf_path;
use wavg::{Anchor, Solver, Surface};

use crate::CliError;
use crate::apps_common::{PairArgs, embed, mesh_and_anchors};
use crate::error::Context;
use crate::textio;

/// The validity test, on the command line.
#[derive(Clone, Copy, Debug, clap::ValueEnum)]
pub enum Test {
    /// Local consistency: rejects vertices whose neighbourhoods mostly land over-stretched
    /// or folded on the target, or whose weights do not round-trip.
    Local,
    /// The paper's: the weights round-trip and none is below --max-negative.
    Paper,
}

/// Arguments shared by the commands that map one surface onto another.
#[derive(clap::Args)]
pub struct MapArgs {
    #[command(flatten)]
    pub pair: PairArgs,
    /// Use the paper's inverse weights only (default: verified weights, the paper's where
    /// they round-trip, else the smallest offset penalty that does).
    #[arg(long)]
    pub paper_weights: bool,
    /// The most negative weight the paper's validity test accepts.
    #[arg(long, default_value_t = CorrespondOptions::default().max_negative, allow_negative_numbers = true, value_parser = crate::common::parse_max_negative)]
    pub max_negative: f64,
    /// Validity test.
    #[arg(long, value_enum, default_value_t = Test::Local)]
    pub validity: Test,
    /// Local test: a segment from a vertex to the edge of its neighbourhood is
    /// over-stretched above this many times the map's median edge stretch.
    #[arg(long, default_value_t = CorrespondOptions::default().max_stretch, allow_negative_numbers = true, value_parser = crate::common::parse_max_stretch)]
    pub max_stretch: f64,
}

/// Arguments.
#[derive(clap::Args)]
#[command(after_long_help = "\
Maps every vertex of the source onto the target. Anchor i of --source-anchors corresponds to
anchor i of --target-anchors. A vertex's weights come from the inverse problem on the source
(verified weights by default, --paper-weights for the paper's alone), its image from the
forward problem on the target with the same weights.

Validity (--validity): `local` (default) keeps a vertex when its weights round-trip on the
source and most of the segments from it to the edge of its neighbourhood (the vertices within
half a percent of the source's diagonal; on coarse meshes its one-ring) land stretched by at
most --max-stretch times the map's median edge stretch (image length over source length) and
two thirds of the triangles around its neighbourhood do not land flipped where the target is
smooth: it judges the image, so correct images with negative weights are kept and wrong images with harmless
weights are not. `paper` is the paper's test: the weights round-trip and none is below
--max-negative.

Output: one line per source vertex, `FACE B0 B1 B2 X Y Z` on the target, or `none REASON`
(unanswered, no-round-trip, negative-weight, inconsistent). --json prints one object:
source_vertices, valid_fraction, flipped_faces, flipped_area_fraction, stretch (symmetrised
L2 stretch over the valid part; null when no face is measured), stretch_best95, seconds, vertices_per_s, plus cpu_seconds and
vertices_per_cpu_s (CPU time of the map, all threads), counts per reason and, with
--ground-truth, the error of the images against vertex i of the target as fractions of the
target's bounding-box diagonal, with rejected_correct (images within 2% rejected) and
accepted_wrong (valid vertices farther than 2%).

With -o OUT.glb (or OUT.gltf, its buffer in OUT.bin) the map is written as glTF instead:
the source mesh with custom per-vertex attributes, 32-bit floats (glTF forbids unsigned
integers there): _TARGET_FACE (the target face, -1 without a valid image; exact up to
2^24 faces), _TARGET_BARY (VEC3, its barycentric coordinates), _TARGET_POSITION (VEC3,
the point on the target) and _VALIDITY (0 valid, 1 unanswered, 2 no-round-trip,
3 negative-weight, 4 inconsistent); the vectors are 0 without a valid image.

Why `local`: `paper` judges the weights, not the image, and on pose pairs most vertices it
rejects are mapped correctly. A single wrong image spoils all of its own edges but one of
each neighbour's, so correct neighbours stay; on thin parts (fingers), images a fraction of
an edge off flip triangles while landing well within 1% of the diagonal, hence the test of
flips only where the target is smooth at the scale of its edges. stretch is the
symmetrised L2 stretch of Sander et al. 2001 / Schreiner et al. 2004 over faces with three
valid corners; stretch_best95 leaves out the worst 5% of them.

Timings: `seconds` is the wall time of the map alone, from starting its worker threads to the
last validity decision; `vertices_per_s` is source_vertices / seconds. Neither includes
setup_seconds: reading the meshes, anchors and embeddings (or precomputing them), building
the projectors and resolving the anchors. Writing MAP.txt and --ground-truth come after and
are not timed. The map splits into weights_seconds (inverse problems on the source with their
round-trip checks and, for verified weights, the penalty ladder), forward_seconds (forward
problems on the target) and validity_seconds (validity test and distortion).")]
pub struct Args {
    #[command(flatten)]
    pub map: MapArgs,
    /// Output map file (`-` for standard output), or .glb/.gltf: the source mesh with the
    /// map as custom vertex attributes.
    #[arg(short = 'o', long = "output")]
    pub output: PathBuf,
    /// The two meshes share connectivity (vertex i corresponds to vertex i): report the
    /// error of the map against that ground truth.
    #[arg(long)]
    pub ground_truth: bool,
    /// Print one JSON object on standard output.
    #[arg(long)]
    pub json: bool,
}

/// A computed correspondence and what it took.
pub struct Computed {
    /// The source and target surfaces.
    pub source: Surface,
    /// The target surface.
    pub target: Surface,
    /// The map.
    pub map: Correspondence,
    /// Seconds of the map (precomputation excluded).
    pub seconds: f64,
    /// Seconds of loading and precomputation.
    pub setup_seconds: f64,
    /// CPU seconds of all threads during the map (`None` where unavailable): on a busy
    /// machine the wall time overstates the work.
    pub cpu_seconds: Option<f64>,
}

/// Reads both meshes and anchor files (checking them before any precomputation), embeds
/// both surfaces and maps every source vertex.
pub fn compute(a: &MapArgs) -> Result<Computed, CliError> {
    let t0 = Instant::now();
    let (source, sa) = mesh_and_anchors(&a.pair.source, &a.pair.source_anchors)?;
    let (target, ta) = mesh_and_anchors(&a.pair.target, &a.pair.target_anchors)?;
    if sa.len() != ta.len() {
        return Err(CliError::input(format!(
            "{} has {} anchors and {} has {}; they are paired line by line and must agree",
            a.pair.source_anchors.display(),
            sa.len(),
            a.pair.target_anchors.display(),
            ta.len()
        )));
    }
    if !a.max_negative.is_finite() {
        return Err(CliError::input("--max-negative must be a finite number"));
    }
    if !(a.max_stretch.is_finite() && a.max_stretch > 1.0) {
        return Err(CliError::input(
            "--max-stretch must be a finite number above 1",
        ));
    }
    let source = embed(
        source,
        a.pair.source_embedding.as_deref(),
        &a.pair.source,
        a.pair.cache,
    )?;
    let target = embed(
        target,
        a.pair.target_embedding.as_deref(),
        &a.pair.target,
        a.pair.cache,
    )?;
    let solver = |s: &Surface, l: Vec<Anchor>| -> Result<Solver, CliError> { Ok(s.solver(l)?) };
    let (ss, ts) = (solver(&source, sa)?, solver(&target, ta)?);
    let setup_seconds = t0.elapsed().as_secs_f64();
    let opts = CorrespondOptions {
        verified: !a.paper_weights,
        max_negative: a.max_negative,
        test: match a.validity {
            Test::Local => ValidityTest::Local,
            Test::Paper => ValidityTest::Paper,
        },
        max_stretch: a.max_stretch,
    };
    let t = Instant::now();
    let cpu0 = crate::common::cpu_seconds(false);
    let map = textio::with_threads(a.pair.threads, || correspond_vertices(&ss, &ts, &opts))??;
    Ok(Computed {
        source,
        target,
        map,
        seconds: t.elapsed().as_secs_f64(),
        setup_seconds,
        cpu_seconds: crate::common::cpu_seconds(false)
            .zip(cpu0)
            .map(|(b, a)| b - a),
    })
}

/// Errors of the images against vertex `i` of the target, in bounding-box diagonals of
/// the target: over the valid vertices and over every answered one.
fn ground_truth(c: &Computed) -> Result<GroundTruthErrors, CliError> {
    c.map
        .ground_truth_errors(c.source.mesh(), c.target.mesh())
        .context("--ground-truth")
}

/// The `--json` object: the map's [`Distortion`] with the CLI's counts and timings
/// (printed through `serde_json::Value`, so keys come out sorted).
#[derive(serde::Serialize)]
struct JsonReport<'a> {
    source: &'a str,
    target: &'a str,
    anchors: usize,
    source_vertices: usize,
    valid: usize,
    valid_fraction: f64,
    validity: String,
    verified: bool,
    reasons: ReasonCounts,
    #[serde(flatten)]
    distortion: &'a Distortion,
    #[serde(flatten)]
    timings: CorrespondTimings,
    seconds: f64,
    setup_seconds: f64,
    vertices_per_s: f64,
    cpu_seconds: Option<f64>,
    vertices_per_cpu_s: Option<f64>,
    ground_truth: Option<GroundTruthErrors>,
}

/// Runs the command.
pub fn run(args: Args) -> Result<(), CliError> {
    crate::common::check_outputs(&[], &[("-o", &args.output)], args.json)?;
    let c = compute(&args.map)?;
    let truth = if args.ground_truth {
        Some(ground_truth(&c)?)
    } else {
        None
    };
    if is_gltf_path(&args.output) {
        let scene = correspondence_scene(c.source.mesh(), &c.map).map_err(wavg::Error::from)?;
        scene.save(&args.output).map_err(wavg::Error::from)?;
    } else {
        write_map(&args.output, &c.map)?;
    }
    let n = c.map.validity.len();
    let d = &c.map.distortion;
    let per_s = n as f64 / c.seconds.max(1e-12);
    if args.json {
        let j = serde_json::to_value(JsonReport {
            source: &args.map.pair.source,
            target: &args.map.pair.target,
            anchors: anchors_of(&args.map)?,
            source_vertices: n,
            valid: c.map.valid(),
            valid_fraction: c.map.valid_fraction(),
            validity: format!("{:?}", args.map.validity).to_lowercase(),
            verified: !args.map.paper_weights,
            reasons: c.map.reason_counts(),
            distortion: d,
            timings: c.map.timings,
            seconds: c.seconds,
            setup_seconds: c.setup_seconds,
            vertices_per_s: per_s,
            cpu_seconds: c.cpu_seconds,
            vertices_per_cpu_s: c.cpu_seconds.map(|s| n as f64 / s.max(1e-12)),
            ground_truth: truth,
        })
        .map_err(CliError::failure)?;
        println!("{j}");
    } else if args.output != Path::new("-") {
        println!(
            "{} of {n} vertices valid ({:.1}%), stretch {}, {} flipped faces, {:.0} vertices/s -> {}",
            c.map.valid(),
            100.0 * c.map.valid_fraction(),
            if d.has_stretch() {
                format!("{:.4}", d.stretch)
            } else {
                "- (no face measured)".into()
            },
            d.flipped_faces,
            per_s,
            args.output.display()
        );
    }
    Ok(())
}

/// Anchor count (the source's; the pairing was checked).
fn anchors_of(a: &MapArgs) -> Result<usize, CliError> {
    Ok(textio::read_points(&a.pair.source_anchors)?.len())
}

/// Writes one line per source vertex: its image or `none REASON` (the library's lines).
pub fn write_map(path: &Path, map: &Correspondence) -> Result<(), CliError> {
    textio::write_atomic(path, |w: &mut dyn Write| {
        w.write_all(&wavg::lines::correspondence_text(map))
    })
}
