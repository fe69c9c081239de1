//! `wavg bench project`: Phong projection speed and accuracy on random surface points
//! (the protocol is [`wavg_bench::projection_bench`]'s; this prints its report).

use std::path::PathBuf;

use wavg_bench::{ProjectionBenchOptions, ProjectionBenchReport, projection_bench};

use crate::CliError;
use crate::common::load_valid;
use crate::textio;

/// Arguments.
#[derive(clap::Args)]
#[command(after_long_help = "\
Builds the projector (init_s, bytes_per_face), then (a) projects N random on-surface
points (uniform by area, seeded), each from a start vertex three rings away:
onsurface_us and onsurface_self_fraction; (b) the same points offset by 0.1 mean edge
lengths off the surface: offset_us, and on the first 1,000 the fraction equal to the
brute-force answer (offset_bruteforce_agree_fraction); (c) onsurface_fallback_fraction and
offset_fallback_fraction, the fraction of each kind of query that needed the global search
(the local search found nothing or was beaten), and fallback_us, the mean wall time of one
global search (Projector::project_exhaustive) on those queries (null when none needed it).
--json prints exactly those keys plus mesh, vertices, faces, queries.

Times are the calling thread's CPU time per query, best of three passes, on one thread
through Projector::project_batch (queries visited in spatial order, the greedy walks of 16
queries interleaved; the answers equal one Projector::project call per query, which is
checked). The table also shows the time of one project call at a time.")]
pub struct Args {
    #[command(flatten)]
    pub mesh: crate::mesh_arg::MeshArg,
    /// A .wavg embedding of the mesh (default: the 3-D positions, zero-padded).
    #[arg(long)]
    embedding: Option<PathBuf>,
    /// Number of random queries per test.
    #[arg(long, default_value_t = 100_000, value_parser = crate::common::parse_queries)]
    queries: usize,
    /// Random seed.
    #[arg(long, default_value_t = 1)]
    seed: u64,
    /// Print one JSON object instead of a table.
    #[arg(long)]
    json: bool,
}

/// Runs the command.
pub fn run(args: Args) -> Result<(), CliError> {
    if args.queries == 0 {
        return Err(CliError::input("--queries must be at least 1"));
    }
    let mesh = load_valid(&args.mesh)?;
    let emb = textio::load_embedded(mesh, args.embedding.as_deref())?;
    let opts = ProjectionBenchOptions {
        queries: args.queries,
        seed: args.seed,
        offset_along_normal: args.embedding.is_none(),
        thread_cpu_clock: Some(|| crate::common::cpu_seconds(true)),
        ..Default::default()
    };
    let r = projection_bench(emb, &opts)?;
    if !r.batch_agrees {
        return Err(CliError::failure(
            "project_batch and project disagree (a bug: please report it)",
        ));
    }
    let name = args.mesh.to_string();
    if args.json {
        let j = serde_json::to_value(JsonReport {
            mesh: &name,
            report: &r,
        })
        .map_err(CliError::failure)?;
        println!("{j}");
    } else {
        print_table(&name, &r);
    }
    Ok(())
}

/// The `--json` object: the library's [`ProjectionBenchReport`] with the mesh's name
/// (printed through `serde_json::Value`, so keys come out sorted).
#[derive(serde::Serialize)]
struct JsonReport<'a> {
    mesh: &'a str,
    #[serde(flatten)]
    report: &'a ProjectionBenchReport,
}

/// Prints the text table.
fn print_table(name: &str, r: &ProjectionBenchReport) {
    let (pa, pb) = (r.onsurface_paths, r.offset_paths);
    println!("mesh                              {name}");
    println!(
        "vertices / faces                  {} / {}",
        r.vertices, r.faces
    );
    println!("queries                           {}", r.queries);
    println!("init_s                            {:.3}", r.init_s);
    println!("bytes_per_face                    {:.1}", r.bytes_per_face);
    println!(
        "onsurface_us                      {:.3} (thread CPU time; wall {:.3})",
        r.onsurface_us, r.onsurface_wall_us
    );
    println!(
        "  one query at a time              {:.3} (thread CPU time; wall {:.3})",
        r.single_us, r.single_wall_us
    );
    println!(
        "onsurface_self_fraction           {:.6}",
        r.onsurface_self_fraction
    );
    println!(
        "  paths local/fallback/none       {}/{}/{}",
        pa[0], pa[1], pa[2]
    );
    println!(
        "offset_us                         {:.3} (thread CPU time; wall {:.3})",
        r.offset_us, r.offset_wall_us
    );
    println!(
        "offset_bruteforce_agree_fraction  {:.6} (of {})",
        r.offset_bruteforce_agree_fraction, r.bruteforce_checked
    );
    println!(
        "  paths local/fallback/none       {}/{}/{}",
        pb[0], pb[1], pb[2]
    );
    println!(
        "fallback on/offset, fallback_us   {:.6} / {:.6}, {} (wall, {} calls)",
        r.onsurface_fallback_fraction,
        r.offset_fallback_fraction,
        r.fallback_us.map_or("-".to_string(), |t| format!("{t:.3}")),
        r.fallback_queries
    );
}
