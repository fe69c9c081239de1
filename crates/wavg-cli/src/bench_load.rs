//! `wavg bench load`: how long reading, parsing, and validating + building the topology
//! of a mesh take (best of N runs each), in release builds.

use std::time::Instant;

use wavg::mesh::{analyze, io};

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

/// Best times in seconds of each stage and of a whole run.
struct Times {
    read: f64,
    parse: f64,
    analyze: f64,
    total: f64,
}

/// The `--json` object (printed through `serde_json::Value`, so keys come out sorted): the
/// mesh's counts and the best [`Times`], measured here (no library report holds them).
#[derive(serde::Serialize)]
struct JsonReport {
    mesh: String,
    vertices: usize,
    faces: usize,
    bytes: usize,
    repeat: u32,
    valid: bool,
    topology_built: bool,
    read_s: f64,
    parse_s: f64,
    validate_topology_s: f64,
    total_s: f64,
}

/// Runs the command.
pub fn run(args: Args) -> Result<(), CliError> {
    let mut best = Times {
        read: f64::INFINITY,
        parse: f64::INFINITY,
        analyze: f64::INFINITY,
        total: f64::INFINITY,
    };
    let mut facts = None;
    for _ in 0..args.repeat {
        let t0 = Instant::now();
        let (format, bytes) = io::read_file(args.mesh.as_ref())?;
        let t1 = Instant::now();
        let (mesh, _) = io::parse_bytes(&bytes, format, args.mesh.as_ref())?;
        let t2 = Instant::now();
        let a = analyze(&mesh);
        let t3 = Instant::now();
        best.read = best.read.min((t1 - t0).as_secs_f64());
        best.parse = best.parse.min((t2 - t1).as_secs_f64());
        best.analyze = best.analyze.min((t3 - t2).as_secs_f64());
        best.total = best.total.min((t3 - t0).as_secs_f64());
        facts = Some((
            mesh.n_vertices(),
            mesh.n_faces(),
            bytes.len(),
            a.report.is_valid(),
            a.topology.is_some(),
        ));
        drop((a, mesh, bytes));
    }
    let (nv, nf, nbytes, valid, topo) = facts.expect("repeat >= 1");
    if args.json {
        let j = serde_json::to_value(JsonReport {
            mesh: args.mesh.to_string(),
            vertices: nv,
            faces: nf,
            bytes: nbytes,
            repeat: args.repeat,
            valid,
            topology_built: topo,
            read_s: best.read,
            parse_s: best.parse,
            validate_topology_s: best.analyze,
            total_s: best.total,
        })
        .map_err(CliError::failure)?;
        println!("{j}");
    } else {
        println!(
            "{}: {nv} vertices, {nf} faces, {:.1} MB uncompressed, valid: {}",
            args.mesh,
            nbytes as f64 / 1e6,
            if valid { "yes" } else { "no" }
        );
        println!("stage (best of {})          time", args.repeat);
        println!("read + decompress       {:>8.1} ms", best.read * 1e3);
        println!("parse                   {:>8.1} ms", best.parse * 1e3);
        println!("validate + topology     {:>8.1} ms", best.analyze * 1e3);
        println!("total (best run)        {:>8.1} ms", best.total * 1e3);
    }
    Ok(())
}
