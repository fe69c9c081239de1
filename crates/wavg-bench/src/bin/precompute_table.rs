//! Runs the whole precomputation on meshes and prints the per-stage table (markdown).
//!
//! `cargo run --release -p wavg-bench --bin precompute_table -- [MESH...]
//! [--no-refine] [--geodesic-vertices N]`
//! (default: pig, armadillo, horse, igea from the shared data folder).

use wavg_embed::{NoProgress, PrecomputeOptions, precompute};
use wavg_mesh::ValidMesh;

fn main() {
    let mut args: Vec<String> = std::env::args().skip(1).collect();
    let mut opts = PrecomputeOptions::default();
    if let Some(i) = args.iter().position(|a| a == "--no-refine") {
        opts.refine_near_pairs = false;
        args.remove(i);
    }
    if let Some(i) = args.iter().position(|a| a == "--geodesic-vertices") {
        opts.geodesic_vertices = args[i + 1].parse().expect("--geodesic-vertices N");
        args.drain(i..i + 2);
    }
    let Some(paths) = wavg_bench::mesh_paths(
        &args,
        &["pig.off", "armadillo.obj.gz", "horse.off.gz", "igea.off.gz"],
        "precompute_table",
    ) else {
        return;
    };
    println!(
        "| mesh | vertices | geodesic mesh | seconds | decimate | geodesics | mds | lsmesh | quality | stress | p50 | p90 |"
    );
    println!("|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|");
    for path in paths {
        let mesh = ValidMesh::new(wavg_mesh::io::load(&path).unwrap()).unwrap();
        let (_, r) = precompute(&mesh, &opts, &NoProgress).unwrap();
        let s = &r.stages;
        println!(
            "| {} | {} | {} | {:.2} | {:.2} | {:.2} | {:.2} | {:.2} | {:.2} | {:.4} | {:.4} | {:.4} |",
            path.file_name().unwrap().to_string_lossy(),
            r.vertices,
            r.geodesic_mesh_vertices,
            r.seconds,
            s.decimate,
            s.geodesics,
            s.mds,
            s.lsmesh,
            s.quality,
            r.stress,
            r.geodesic_rel_err_p50,
            r.geodesic_rel_err_p90
        );
    }
}
