//! `wavg bench load`: how long reading, parsing, and validating + building the topology
//! of a mesh take (best of N runs each), in release builds (the protocol is
//! [`wavg_bench::load_bench`]'s; this prints its report).

use wavg_bench::{LoadBenchReport, load_bench};

use crate::CliError;

/// Arguments.
#[derive(clap::Args)]
#[command(after_long_help = "\
Load, validation and topology time of a mesh file, best of --repeat runs per stage.")]
pub struct Args {
    #[command(flatten)]
    pub mesh: crate::mesh_arg::MeshArg,
    /// Number of runs; each stage reports its best time.
    #[arg(long, default_value_t = 5, value_parser = clap::value_parser!(u32).range(1..))]
    pub repeat: u32,
    /// Print one JSON object instead of a table.
    #[arg(long)]
    pub json: bool,
}

/// The `--json` object (printed through `serde_json::Value`, so keys come out sorted): the
/// protocol's report and the mesh argument.
#[derive(serde::Serialize)]
struct JsonReport<'a> {
    mesh: &'a str,
    #[serde(flatten)]
    report: &'a LoadBenchReport,
}

/// Runs the command.
pub fn run(args: Args) -> Result<(), CliError> {
    let r = load_bench(args.mesh.as_ref(), args.repeat)?;
    if args.json {
        let j = serde_json::to_value(JsonReport {
            mesh: &args.mesh,
            report: &r,
        })
        .map_err(CliError::failure)?;
        println!("{j}");
    } else {
        println!(
            "{}: {} vertices, {} faces, {:.1} MB uncompressed, valid: {}",
            args.mesh,
            r.vertices,
            r.faces,
            r.bytes as f64 / 1e6,
            if r.valid { "yes" } else { "no" }
        );
        println!("stage (best of {})          time", r.repeat);
        println!("read + decompress       {:>8.1} ms", r.read_s * 1e3);
        println!("parse                   {:>8.1} ms", r.parse_s * 1e3);
        println!(
            "validate + topology     {:>8.1} ms",
            r.validate_topology_s * 1e3
        );
        println!("total (best run)        {:>8.1} ms", r.total_s * 1e3);
    }
    Ok(())
}
