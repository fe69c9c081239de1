//! `wavg subdivide IN -o OUT [--levels N]`: Loop subdivision, to make large meshes
//! reproducibly from the ones at hand (igea's 134k vertices become about 2.1M at level 2).

use std::path::PathBuf;
use std::time::Instant;

use wavg::mesh::io;
use wavg::mesh::subdivide::loop_subdivide;
use wavg::{SubdivisionReport, ValidMesh};

use crate::CliError;
use crate::common::load_valid;

/// Arguments of `wavg subdivide`.
#[derive(clap::Args)]
#[command(
    long_about = "Loop subdivision: every level splits each triangle into four and \
    smooths the vertices (boundaries follow their own curve). Vertex ids of the input are \
    kept (they come first); the input must be a valid mesh.\n\n\
    --json prints one object: input_vertices, input_faces, vertices, faces, levels, seconds."
)]
pub struct Args {
    #[command(flatten)]
    pub mesh: crate::mesh_arg::MeshArg,
    /// Output mesh; the format follows the extension (binary .ply is the fastest to read).
    #[arg(short = 'o', long = "output")]
    pub output: PathBuf,
    /// Subdivision levels (each multiplies the face count by 4).
    #[arg(long, default_value_t = 1, value_parser = clap::value_parser!(u32).range(0..=6))]
    pub levels: u32,
    /// Print one JSON object instead of text.
    #[arg(long)]
    pub json: bool,
}

/// Runs `wavg subdivide`.
pub fn run(args: Args) -> Result<(), CliError> {
    crate::common::check_outputs(
        &[std::path::Path::new(&*args.mesh)],
        &[("-o", &args.output)],
        args.json,
    )?;
    crate::common::check_mesh_output("-o", &args.output)?;
    let input = load_valid(&args.mesh)?;
    let t = Instant::now();
    let (nv0, nf0) = (input.n_vertices(), input.n_faces());
    let mut mesh = std::sync::Arc::unwrap_or_clone(input);
    for _ in 0..args.levels {
        let next = loop_subdivide(&mesh)?;
        mesh = ValidMesh::new(next)?;
    }
    let seconds = t.elapsed().as_secs_f64();
    io::save(&args.output, &mesh)?;
    let report = SubdivisionReport {
        input_vertices: nv0,
        input_faces: nf0,
        vertices: mesh.n_vertices(),
        faces: mesh.n_faces(),
        levels: args.levels,
        seconds,
    };
    if args.json {
        let j = serde_json::to_value(&report).map_err(CliError::failure)?;
        println!("{j}");
    } else {
        println!(
            "{} -> {}: {nv0} -> {} vertices, {nf0} -> {} faces, {} level(s) in {seconds:.2} s",
            args.mesh,
            args.output.display(),
            report.vertices,
            report.faces,
            report.levels
        );
    }
    Ok(())
}
