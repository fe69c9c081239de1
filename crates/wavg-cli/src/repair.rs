//! `wavg repair IN -o OUT`: the opt-in repairs scans need, from the command line, with the
//! new-to-original vertex map so callers can translate their vertex ids.

use std::fmt::Write as _;
use std::path::{Path, PathBuf};

use wavg::mesh::repair::repair_all;
use wavg::mesh::{analyze, io};
use wavg::{RepairOptions, RepairReport};

use crate::CliError;
use crate::common::load_mesh;

/// Arguments of `wavg repair`.
#[derive(clap::Args)]
#[command(
    long_about = "Repair a mesh so that wavg can use it, and write the result.\n\n\
    By default: weld vertices with identical positions, drop degenerate faces (repeated \
    index, zero area, out-of-range index, NaN/inf corner), drop duplicate faces, make the \
    mesh manifold (a vertex or edge shared by separate sheets of surface is split into one \
    copy per sheet: new vertices are appended after the input's, which keep their \
    indices), flip faces to one orientation per component, and drop unreferenced \
    vertices. Components are kept unless --largest-component is given.\n\n\
    --map FILE writes one line per output vertex: the 0-based index of the input vertex it \
    came from (after welding, the lowest such index; for a copy made by splitting, the \
    vertex it copies). --json adds added_vertices (copies made by splitting) to the \
    counts.\n\n\
    Exit status: 0 when the output is a valid mesh, 1 when problems remain (the output is \
    still written, and the remaining problems are listed), 2 for unreadable input."
)]
pub struct Args {
    #[command(flatten)]
    pub mesh: crate::mesh_arg::MeshArg,
    /// Output mesh; the format follows the extension.
    #[arg(short = 'o', long = "output")]
    pub output: PathBuf,
    /// Weld vertices closer than this distance (0 = identical positions only).
    #[arg(long, default_value_t = 0.0, conflicts_with = "no_weld")]
    pub weld: f64,
    /// Do not weld vertices.
    #[arg(long)]
    pub no_weld: bool,
    /// Keep only the largest connected component (by face count).
    #[arg(long)]
    pub largest_component: bool,
    /// Do not split non-manifold vertices and edges.
    #[arg(long)]
    pub keep_nonmanifold: bool,
    /// Do not flip faces to a consistent orientation.
    #[arg(long)]
    pub keep_orientation: bool,
    /// Write the new-to-original vertex map here (one index per line).
    #[arg(long)]
    pub map: Option<PathBuf>,
    /// Print one JSON object instead of text.
    #[arg(long)]
    pub json: bool,
}

/// Runs `wavg repair`.
pub fn run(args: Args) -> Result<(), CliError> {
    let mut outputs = vec![("-o", args.output.as_path())];
    if let Some(m) = &args.map {
        outputs.push(("--map", m.as_path()));
    }
    crate::common::check_outputs(&[std::path::Path::new(&*args.mesh)], &outputs, args.json)?;
    if !(args.weld >= 0.0 && args.weld.is_finite()) {
        return Err(CliError::input(format!(
            "--weld must be a finite distance >= 0, got {}",
            args.weld
        )));
    }
    // The output's format, from its extension, before any work.
    crate::common::check_mesh_output("-o", &args.output)?;
    let mesh = load_mesh(&args.mesh)?;
    let options = RepairOptions {
        weld: (!args.no_weld).then_some(args.weld),
        keep_largest_component: args.largest_component,
        make_manifold: !args.keep_nonmanifold,
        orient: !args.keep_orientation,
        ..RepairOptions::default()
    };
    let r = repair_all(&mesh, &options);
    let after = analyze(&r.mesh);
    // Written atomically (a temporary file beside it, renamed on success).
    io::save(&args.output, &r.mesh)?;
    if let Some(map) = &args.map {
        let mut text = String::with_capacity(r.vertex_map.len() * 7);
        for v in &r.vertex_map {
            let _ = writeln!(text, "{v}");
        }
        crate::textio::write_atomic(map, |w| w.write_all(text.as_bytes()))?;
    }
    let report = RepairReport::new(&mesh, &r, &after);
    if args.json {
        let j = serde_json::to_value(JsonReport {
            input: &args.mesh,
            output: &args.output,
            report: &report,
        })
        .map_err(CliError::failure)?;
        println!("{j}");
    } else {
        println!(
            "{} -> {}: {} -> {} vertices, {} -> {} faces, {} component(s)",
            args.mesh,
            args.output.display(),
            report.vertices_before,
            report.vertices,
            report.faces_before,
            report.faces,
            report.components
        );
        if report.valid {
            println!("valid: yes");
        } else {
            println!("valid: no; remaining problems:");
            for p in &report.problems {
                println!("  - {p}");
            }
        }
    }
    if after.report.is_valid() && after.stats.components > 1 {
        eprintln!(
            "note: {} has {} connected components; `wavg precompute` and every command that \
             needs an embedding take one: add --largest-component to keep the largest",
            args.output.display(),
            after.stats.components
        );
    }
    if after.report.is_valid() {
        Ok(())
    } else {
        let hint = if after.stats.components > 1 && !args.largest_component {
            " (several components: try --largest-component)"
        } else {
            ""
        };
        Err(CliError::failure(format!(
            "{}: written, but {} problem(s) remain{hint}",
            args.output.display(),
            after.report.problems.len()
        )))
    }
}

/// The `--json` object: the library's [`RepairReport`] with the files (printed through
/// `serde_json::Value`, so keys come out sorted).
#[derive(serde::Serialize)]
struct JsonReport<'a> {
    input: &'a str,
    output: &'a Path,
    #[serde(flatten)]
    report: &'a RepairReport,
}
