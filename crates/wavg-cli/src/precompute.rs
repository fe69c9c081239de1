//! `wavg precompute MESH -o OUT.wavg`: the 8-D embedding of a mesh, written as a `.wavg`
//! file (format: `wavg::embed::file`).
//!
//! Progress bars appear on stderr only when it is a terminal. `--json` prints one object:
//! `seconds` (the precomputation itself, excluding loading the mesh and writing the file,
//! which are `load_seconds` and `save_seconds`), `stages` (`decimate`, `geodesics`, `mds`,
//! `lsmesh`, `quality`), `landmarks`, `dim`, `stress`, `geodesic_rel_err_p50`,
//! `geodesic_rel_err_p90`, `vertices`, `faces`, and a few more.

use std::collections::HashMap;
use std::io::IsTerminal;
use std::path::PathBuf;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Arc, Mutex};
use std::time::Instant;

use indicatif::{MultiProgress, ProgressBar, ProgressDrawTarget, ProgressStyle};
use wavg::embed;
use wavg::mesh::repair;
use wavg::{MeshError, PrecomputeOptions, Progress, Report, Stage, ValidMesh};

use crate::CliError;
use crate::common::load_mesh;

/// Arguments.
#[derive(clap::Args)]
#[command(after_long_help = "\
Computes the 8-D embedding (1000 landmarks by decimation, keeping coarse triangles round so
thin parts such as fingers and tails keep landmarks all around, plus more where a part is
thinner than their spacing and would collapse; fast-marching geodesics on
an intermediate mesh of at most 10k vertices with close pairs refined on the full mesh,
--geodesic-vertices 0 for full resolution; metric MDS; least-squares mesh) and writes the
.wavg file (format: crates/wavg-embed/FORMAT.md). The mesh must be a valid manifold with
one component (or pass --largest-component). Progress bars on a terminal only; Ctrl-C
stops cleanly (exit status 130, nothing written).

A mesh with problems or several pieces: on a mesh that `wavg repair` would fix, precompute
says so and prints the command. --largest-component renumbers the vertices, so the
embedding belongs to the repaired mesh, not to the file: --repaired-mesh FIXED.obj saves
that mesh, and later commands take FIXED.obj with the .wavg file. The same in two steps:
`wavg repair MESH -o FIXED.obj --largest-component` (it warns when its result still has
several components), then `wavg precompute FIXED.obj -o FIXED.wavg`.

--json prints one object: seconds (the precomputation, without loading the mesh and
writing the file: load_seconds, save_seconds), stages (decimate, geodesics, mds, lsmesh,
quality, in seconds), landmarks, dim, stress, geodesic_rel_err_p50, geodesic_rel_err_p90,
vertices, faces and a few more.")]
pub struct Args {
    #[command(flatten)]
    pub mesh: crate::mesh_arg::MeshArg,
    /// Output .wavg file (written atomically).
    #[arg(short, long, value_name = "OUT.wavg")]
    pub output: PathBuf,
    /// Number of landmarks (default: the library's choice for the mesh, the paper's 1000,
    /// as every other way into wavg chooses).
    #[arg(long)]
    pub landmarks: Option<usize>,
    /// Seed of the quality-check pairs (every other stage is deterministic).
    #[arg(long, default_value_t = 0)]
    pub seed: u64,
    /// Run the landmark geodesics on an intermediate decimated mesh with this many vertices
    /// when the mesh has more (0: always on the full mesh).
    #[arg(long, value_name = "N")]
    pub geodesic_vertices: Option<usize>,
    /// Vertex pairs of the quality check (0 skips it; default: the library's choice, 1024).
    #[arg(long)]
    pub quality_pairs: Option<usize>,
    /// Keep only the largest connected component before embedding. The embedding then
    /// belongs to the repaired mesh: save it with --repaired-mesh to use it later.
    #[arg(long)]
    pub largest_component: bool,
    /// Write the mesh the embedding belongs to (after --largest-component) to this file.
    #[arg(long, value_name = "MESH")]
    pub repaired_mesh: Option<PathBuf>,
    /// Worker threads (default: all cores; the limit: docs/limits.md). The embedding does
    /// not depend on it.
    #[arg(long, value_parser = crate::common::parse_threads)]
    pub threads: Option<usize>,
    /// Print one JSON object instead of text.
    #[arg(long)]
    pub json: bool,
}

/// Refuses arguments that would be silently ignored or destroy the input: an intermediate
/// geodesic mesh no larger than the landmark set, and an output that is the input mesh or
/// has a mesh file's extension.
fn check_args(args: &Args) -> Result<(), CliError> {
    if let Some(m) = args
        .repaired_mesh
        .as_deref()
        .filter(|m| wavg::mesh::io::gltf::is_gltf_path(m))
    {
        return Err(CliError::input(format!(
            "--repaired-mesh {}: glTF rounds positions to 32-bit floats, so the embedding \
             would not belong to the file; save the repaired mesh as .obj, .off or .ply",
            m.display()
        )));
    }
    if let Some(m) = &args.repaired_mesh {
        crate::common::check_mesh_output("--repaired-mesh", m)?;
    }
    let landmarks = args.landmarks.unwrap_or(wavg::DEFAULT_LANDMARKS);
    if let Some(g) = args.geodesic_vertices.filter(|&g| g != 0 && g <= landmarks) {
        return Err(CliError::input(format!(
            "--geodesic-vertices {g} must be 0 (the full mesh) or more than --landmarks ({landmarks})"
        )));
    }
    let out = &args.output;
    if out == std::path::Path::new("-") {
        return Err(CliError::input(
            "-o -: the embedding is written to a .wavg file, which the commands read by \
             name, not to standard output; give a file name ending in .wavg",
        ));
    }
    if crate::common::same_file(args.mesh.as_ref(), out) {
        return Err(CliError::input(format!(
            "the output {} is the input mesh; write the embedding to a .wavg file",
            out.display()
        )));
    }
    if wavg::mesh::io::check_save_path(out).is_ok() {
        return Err(CliError::input(format!(
            "the output {} has a mesh file's extension; the embedding is a .wavg file",
            out.display()
        )));
    }
    Ok(())
}

/// Runs the command.
pub fn run(args: Args) -> Result<(), CliError> {
    // Ctrl-C asks the pipeline to stop at its next check; the output is only written after
    // success, so an interrupted run leaves no file behind.
    check_args(&args)?;
    let mut outputs = vec![("-o", args.output.as_path())];
    if let Some(m) = &args.repaired_mesh {
        outputs.push(("--repaired-mesh", m.as_path()));
    }
    crate::common::check_outputs(&[std::path::Path::new(&*args.mesh)], &outputs, args.json)?;
    let interrupted = Arc::new(AtomicBool::new(false));
    let loading = Arc::new(AtomicBool::new(true));
    let (flag, while_loading) = (interrupted.clone(), loading.clone());
    let output = args.output.display().to_string();
    let _ = ctrlc::set_handler(move || {
        // Reading and validating cannot stop partway (seconds at 10M vertices) and leave no
        // file (a repaired mesh goes through a temporary one): the command ends at once.
        if while_loading.load(Ordering::Relaxed) {
            eprintln!("wavg: interrupted; {output} was not written");
            std::process::exit(130);
        }
        flag.store(true, Ordering::Relaxed)
    });
    let t_load = Instant::now();
    let mut mesh = load_mesh(&args.mesh)?;
    let mut removed = None;
    if args.largest_component {
        let before = (mesh.n_vertices(), mesh.n_faces());
        mesh = repair::keep_largest_component(&mesh).mesh;
        removed = Some((before.0 - mesh.n_vertices(), before.1 - mesh.n_faces()));
    }
    let mesh = validate(&args.mesh, mesh)?;
    if let Some(path) = &args.repaired_mesh {
        wavg::mesh::io::save(path, &mesh)?;
    }
    let load_seconds = t_load.elapsed().as_secs_f64();
    loading.store(false, Ordering::Relaxed);

    let defaults = wavg::default_precompute_options(&mesh);
    let opts = PrecomputeOptions {
        geodesic_vertices: args.geodesic_vertices.unwrap_or(defaults.geodesic_vertices),
        landmarks: args.landmarks.unwrap_or(defaults.landmarks),
        seed: args.seed,
        quality_pairs: args.quality_pairs.unwrap_or(defaults.quality_pairs),
        ..defaults
    };
    let bars = Bars::new(std::io::stderr().is_terminal(), interrupted);
    let result =
        crate::textio::with_threads(args.threads, || wavg::precompute(&mesh, &opts, &bars))?;
    bars.clear();
    let (embedding, report) = result.map_err(|e| {
        if e.kind() == wavg::ErrorKind::Cancelled {
            CliError::from(e).with_message(format!(
                "interrupted; {} was not written",
                args.output.display()
            ))
        } else {
            CliError::from(e).context(&args.mesh)
        }
    })?;

    let t_save = Instant::now();
    embed::file::save(&args.output, &embedding, &mesh)?;
    let save_seconds = t_save.elapsed().as_secs_f64();

    let s = &report.stages;
    if args.json {
        let v = serde_json::to_value(JsonReport {
            mesh: &args.mesh,
            output: &args.output,
            report: &report,
            load_seconds,
            save_seconds,
            removed_by_largest_component: removed
                .map(|(vertices, faces)| Removed { vertices, faces }),
        })
        .map_err(CliError::failure)?;
        println!("{v}");
    } else {
        println!(
            "mesh          {} ({} vertices, {} faces)",
            args.mesh, report.vertices, report.faces
        );
        if let Some((v, f)) = removed {
            println!("repaired      --largest-component removed {v} vertices, {f} faces");
        }
        println!("output        {}", args.output.display());
        println!("landmarks     {}  dim {}", report.landmarks, report.dim);
        if report.geodesic_mesh_vertices != report.vertices {
            println!(
                "geodesics     on an intermediate mesh of {} vertices",
                report.geodesic_mesh_vertices
            );
        }
        println!(
            "stress        {:.4} (classical start {:.4}, {} SMACOF iterations{})",
            report.stress,
            report.initial_stress,
            report.mds_iterations,
            if report.mds_converged {
                ""
            } else {
                ", limit reached"
            }
        );
        println!(
            "geodesic rel. error  p50 {:.4}  p90 {:.4}  ({} pairs)",
            report.geodesic_rel_err_p50, report.geodesic_rel_err_p90, report.quality_pairs
        );
        println!(
            "seconds       {:.2}  (stages, some overlapping: decimate {:.2}, geodesics {:.2}, mds {:.2}, lsmesh {:.2}, quality {:.2}; load {:.2}, save {:.2})",
            report.seconds,
            s.decimate,
            s.geodesics,
            s.mds,
            s.lsmesh,
            s.quality,
            load_seconds,
            save_seconds
        );
    }
    if removed.is_some_and(|(v, _)| v > 0) && args.repaired_mesh.is_none() {
        eprintln!(
            "note: the embedding belongs to the mesh after --largest-component; pass \
             --repaired-mesh FILE to save that mesh for later use"
        );
    }
    Ok(())
}

/// The `--json` object: the library's report with the files, the I/O times and the
/// repair (printed through `serde_json::Value`, so keys come out sorted).
#[derive(serde::Serialize)]
struct JsonReport<'a> {
    mesh: &'a str,
    output: &'a std::path::Path,
    #[serde(flatten)]
    report: &'a Report,
    load_seconds: f64,
    save_seconds: f64,
    removed_by_largest_component: Option<Removed>,
}

/// What `--largest-component` removed.
#[derive(serde::Serialize)]
struct Removed {
    vertices: usize,
    faces: usize,
}

/// Validates with a message naming the problems and the repair options.
fn validate(name: &str, mesh: wavg::TriMesh) -> Result<ValidMesh, CliError> {
    // One analysis: a mesh that fails comes back with it, for the message.
    let rejected = match ValidMesh::try_new(mesh) {
        Ok(m) => {
            if m.topology().n_components() != 1 {
                return Err(CliError::input(format!(
                    "{name}: the mesh has {} connected components; the embedding needs one. \
                     Keep the largest with `wavg repair {name} -o FIXED.obj \
                     --largest-component` and use FIXED.obj from then on (or here: \
                     --largest-component --repaired-mesh FIXED.obj, which saves the mesh the \
                     embedding belongs to)",
                    m.topology().n_components()
                )));
            }
            return Ok(m);
        }
        Err(rejected) => rejected,
    };
    let wavg::mesh::Rejected { mesh, analysis } = *rejected;
    let components = analysis.stats.components;
    let report = analysis.report;
    // What the default repairs would do, for the hint.
    let preview = wavg::mesh::RepairPreview::of(&mesh);
    let mut hint = String::from("run `wavg info` for details");
    if preview.fixes_all {
        let one = if preview.components > 1 {
            " --largest-component"
        } else {
            ""
        };
        hint.push_str(&format!(
            "; `wavg repair {name} -o FIXED.obj{one}` fixes it (then use FIXED.obj)"
        ));
    }
    if components > 1 {
        hint.push_str(&format!(
            "; the mesh has {components} components: --largest-component keeps the \
             largest"
        ));
    }
    let message = format!(
        "{name}: not a valid oriented manifold mesh: {} ({hint})",
        report.lines().join("; ")
    );
    Err(CliError::from(MeshError::Invalid(Box::new(report))).with_message(message))
}

/// One progress bar per stage on stderr (hidden when stderr is not a terminal); also
/// carries the Ctrl-C flag to the pipeline's cancellation checks.
pub(crate) struct Bars {
    multi: MultiProgress,
    bars: Mutex<HashMap<Stage, ProgressBar>>,
    interrupted: Arc<AtomicBool>,
}

const TICKS: u64 = 1000;

impl Bars {
    pub(crate) fn new(visible: bool, interrupted: Arc<AtomicBool>) -> Self {
        let target = if visible {
            ProgressDrawTarget::stderr()
        } else {
            ProgressDrawTarget::hidden()
        };
        Self {
            multi: MultiProgress::with_draw_target(target),
            bars: Mutex::new(HashMap::new()),
            interrupted,
        }
    }

    pub(crate) fn clear(&self) {
        let _ = self.multi.clear();
    }
}

impl Progress for Bars {
    fn cancelled(&self) -> bool {
        self.interrupted.load(Ordering::Relaxed)
    }

    fn report(&self, stage: Stage, fraction: f64) {
        let Ok(mut bars) = self.bars.lock() else {
            return;
        };
        let bar = bars.entry(stage).or_insert_with(|| {
            let b = self.multi.add(ProgressBar::new(TICKS));
            b.set_style(
                ProgressStyle::with_template("{prefix:>10} [{bar:40}] {percent:>3}% {elapsed:>4}")
                    .unwrap_or_else(|_| ProgressStyle::default_bar())
                    .progress_chars("=> "),
            );
            b.set_prefix(stage.name());
            b
        });
        bar.set_position((fraction.clamp(0.0, 1.0) * TICKS as f64) as u64);
        if fraction >= 1.0 {
            bar.finish();
        }
    }
}
