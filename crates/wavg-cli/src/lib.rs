//! The `wavg` command line: diagnostics, precomputation, forward/inverse problems, benchmarks.
//!
//! The binary calls [`main`]; [`command`] gives the command definition to tools that
//! write its man pages, shell completions and `docs/cli.md` ([`cli_docs`]).

#![forbid(unsafe_code)]

mod anchors;
mod apps_common;
mod bench_load;
mod bench_project;
mod bench_roundtrip;
mod bench_spline;
mod cache;
mod cache_cmd;
pub mod cli_docs;
mod common;
mod completions;
mod correspond;
mod decal;
mod decal_material;
mod demo;
mod demo_apps;
mod demo_pictures;
mod embedding_arg;
mod error;
mod forward;
mod help_examples;
mod info;
mod inverse;
pub mod man;
mod mesh_arg;
mod morph;
mod precompute;
mod remesh;
mod render;
mod repair;
mod serve;
mod spline;
mod stream;
mod subdivide;
mod textio;
mod transfer_texture;

use std::process::ExitCode;

use clap::{CommandFactory, FromArgMatches, Parser, Subcommand};

pub use error::CliError;

/// Weighted averages of points on triangle meshes (Panozzo et al., SIGGRAPH 2013).
#[derive(Parser)]
#[command(name = "wavg", version, about, long_about = None)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// Run the whole method on a generated mesh: embedding, a spline, round trips.
    Demo(demo::Args),
    /// Describe a mesh: counts, topology, and every validation problem.
    Info(info::Args),
    /// Repair a mesh (weld, drop degenerate/duplicate faces, ...) and write it.
    Repair(repair::Args),
    /// Compute the 8-D embedding of a mesh and write it as a .wavg file.
    Precompute(precompute::Args),
    /// Choose K well-spread anchors on a mesh and write them as an anchors file.
    Anchors(anchors::Args),
    /// Forward problem: anchors + weights -> points on the surface.
    Forward(forward::Args),
    /// Inverse problem: anchors + surface points -> weights.
    Inverse(inverse::Args),
    /// A B-spline or Bézier curve on the surface through control points.
    Spline(spline::Args),
    /// Loop subdivision: make a larger mesh from a smaller one.
    Subdivide(subdivide::Args),
    /// Map every vertex of one surface onto another through paired anchors.
    Correspond(correspond::Args),
    /// A decal: (u, v) coordinates for every vertex from anchors that carry them.
    Decal(decal::Args),
    /// Morph one surface into another: the source's mesh moved onto the target, in frames.
    Morph(morph::Args),
    /// Semiregular remeshing of a coarse polygon mesh on the surface, with smoothing.
    Remesh(remesh::Args),
    /// A picture (PNG) of a mesh: shaded, textured or scalar-coloured, with curves and dots.
    Render(render::Args),
    /// Carry a texture from one mesh to another through corresponding anchors.
    TransferTexture(transfer_texture::Args),
    /// Serve an interactive page (anchors, splines, decals, remeshing) and its HTTP API.
    Serve(serve::Args),
    /// Benchmarks (report timings and quality figures).
    #[command(
        subcommand,
        after_long_help = "Timings and quality figures; the measured results, with the \
                           commands that produce them, are in BENCHMARKS.md."
    )]
    Bench(BenchCommand),
    /// The embedding cache: list or clear the embeddings computed for meshes.
    #[command(subcommand, after_long_help = CACHE_HELP)]
    Cache(cache_cmd::Command),
    /// Print a shell completion script (bash, zsh or fish) to standard output.
    Completions(completions::Args),
}

/// The long help of `wavg cache`: what the cache is and who uses it.
const CACHE_HELP: &str = "\
Every command that needs an embedding and is not given one (--embedding, --source-embedding,
--target-embedding) takes it from the cache folder $WAVG_CACHE_DIR (default
$XDG_CACHE_HOME/wavg, else ~/.cache/wavg), or computes it there on first use (a tenth of
the vertices as landmarks, 50 to 1000; progress bars on a terminal, then one line on stderr
saying where it went). Entries are keyed by the mesh's fingerprint (positions and faces) and
the precompute options, so an edited mesh gets a new entry. Files are written to a
temporary name and renamed, so several processes may fill the cache at once; a damaged
entry is computed again. --no-cache bypasses it; forward and inverse use the 3-D positions
only with --embedding none. On pig.off (7.5k vertices) the first `wavg spline` takes about
8.5 s, the next one 0.2 s.";

#[derive(Subcommand)]
enum BenchCommand {
    /// Load + validate + topology time of a mesh file.
    Load(bench_load::Args),
    /// Phong projection speed and accuracy on random surface points.
    Project(bench_project::Args),
    /// The paper's Table 1 protocol: inverse then forward round trips.
    Roundtrip(bench_roundtrip::Args),
    /// Time per sample of a curve on the surface, checked against cold answers.
    Spline(bench_spline::Args),
}

/// The `wavg` command: every subcommand with its options, help text and examples.
pub fn command() -> clap::Command {
    help_examples::append(definition(), &mut Vec::new())
}

/// The command without the examples (`docs/cli.md` shows those as blocks that run).
fn definition() -> clap::Command {
    Cli::command().after_long_help(root_long_help())
}

/// What every command shares: mesh arguments, where formats and limits are described, and
/// the exit status.
fn root_long_help() -> String {
    let names: Vec<&str> = wavg::mesh::procedural::BUILTINS
        .iter()
        .map(|(name, _)| *name)
        .collect();
    format!(
        "A mesh argument is a file (.obj, .off or .ply, each optionally gzipped as .gz; .gltf\n\
         or .glb, welded into one surface, SCENE.glb#NAME for its mesh or node NAME) or\n\
         builtin:NAME, a mesh generated in code (`wavg info --builtin NAME` describes one):\n  \
         {}\n\
         Every command that works on one mesh takes it positionally or as --mesh (`wavg render\n\
         spot.obj` and `wavg render --mesh spot.obj` are the same). Anchors, points, weights and \
         the\nsolvers' outputs are plain text or NumPy arrays: docs/formats.md. What the readers \
         accept,\nthe limits on options and how outputs are written: docs/limits.md.\n\n\
         Exit status: 0 success; 2 unreadable or malformed input (one line on stderr naming the \
         file\nand line); 130 interrupted (Ctrl-C); 1 any other failure (an output that cannot \
         be\nwritten, a question without an answer, a precomputation refused because the \
         machine's\navailable memory is below its estimated peak (the message gives both; \
         `docs/limits.md`),\na failure of wavg itself).",
        names.join(", ")
    )
}

/// Makes a report printed to a closed pipe (`wavg info M | head -1`) end the process
/// quietly with status 0, as `-o -` does, instead of a panic (`println!` panics when its
/// stream is gone, and the reader has taken all it wanted); any other failure to print
/// (`> /dev/full`) ends it with one line and status 1.
fn quiet_on_closed_pipe() {
    let default = std::panic::take_hook();
    std::panic::set_hook(Box::new(move |info| {
        let msg = info
            .payload()
            .downcast_ref::<String>()
            .map(String::as_str)
            .or_else(|| info.payload().downcast_ref::<&str>().copied())
            .unwrap_or("");
        if msg.starts_with("failed printing to std") {
            if msg.contains("Broken pipe") {
                std::process::exit(0);
            }
            // Another write error (a full disk): one line, if stderr still takes it.
            use std::io::Write;
            let _ = writeln!(std::io::stderr(), "wavg: {msg}");
            std::process::exit(1);
        }
        default(info);
    }));
}

/// Parses the process's arguments, runs the command and reports a failure on stderr as
/// `wavg: MESSAGE`; the exit status is the binary's.
pub fn main() -> ExitCode {
    quiet_on_closed_pipe();
    let cli = Cli::from_arg_matches(&command().get_matches()).unwrap_or_else(|e| e.exit());
    let result = match cli.command {
        Command::Demo(a) => demo::run(a),
        Command::Info(a) => info::run(a),
        Command::Repair(a) => repair::run(a),
        Command::Precompute(a) => precompute::run(a),
        Command::Anchors(a) => anchors::run(a),
        Command::Forward(a) => forward::run(a),
        Command::Inverse(a) => inverse::run(a),
        Command::Spline(a) => spline::run(a),
        Command::Subdivide(a) => subdivide::run(a),
        Command::Correspond(a) => correspond::run(a),
        Command::Decal(a) => decal::run(a),
        Command::Morph(a) => morph::run(a),
        Command::Remesh(a) => remesh::run(a),
        Command::Render(a) => render::run(a),
        Command::TransferTexture(a) => transfer_texture::run(a),
        Command::Serve(a) => serve::run(a),
        Command::Bench(BenchCommand::Load(a)) => bench_load::run(a),
        Command::Bench(BenchCommand::Project(a)) => bench_project::run(a),
        Command::Bench(BenchCommand::Roundtrip(a)) => bench_roundtrip::run(a),
        Command::Bench(BenchCommand::Spline(a)) => bench_spline::run(a),
        Command::Cache(c) => cache_cmd::run(c),
        Command::Completions(a) => completions::run(a),
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            if !e.message.is_empty() {
                eprintln!("wavg: {}", e.message);
            }
            ExitCode::from(e.code)
        }
    }
}
