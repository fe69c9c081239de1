//! Asymmetry of the full landmark distance matrix (fast marching from every landmark) and
//! the time of those runs: the measure behind the fast-marching symmetry test.
//!
//! `cargo xtask lab symmetry [--landmarks N]
//! [--near-field EDGES] [MESH...]`
//! (default meshes: pig, camelhead, fertility from the shared data folder). `WORST=1` lists
//! the most asymmetric pairs with both distances in mean edge lengths.

use std::time::Instant;

use wavg_embed::NoProgress;
use wavg_embed::{DecimateOptions, FastMarching, select_landmarks};
use wavg_mesh::ValidMesh;

fn main() {
    let mut args: Vec<String> = std::env::args().skip(1).collect();
    let mut target = 1000usize;
    if let Some(i) = args.iter().position(|a| a == "--landmarks") {
        target = args[i + 1].parse().expect("--landmarks N");
        args.drain(i..i + 2);
    }
    let mut near_field = wavg_embed::internal::NEAR_FIELD_EDGES;
    if let Some(i) = args.iter().position(|a| a == "--near-field") {
        near_field = args[i + 1].parse().expect("--near-field EDGES");
        args.drain(i..i + 2);
    }
    let Some(paths) = wavg_lab::mesh_paths(
        &args,
        &["pig.off", "camelhead.off", "fertility.off"],
        "symmetry",
    ) else {
        return;
    };
    println!("| mesh | landmarks | runs (s) | mean % | max % | pairs above 2% |");
    println!("|---|---:|---:|---:|---:|---:|");
    for p in paths {
        let mesh = ValidMesh::new(wavg_mesh::io::load(&p).expect("load")).expect("valid");
        let opts = DecimateOptions {
            target,
            ..Default::default()
        };
        let lm = select_landmarks(&mesh, &opts, &NoProgress).expect("landmarks");
        let fm = FastMarching::new(&mesh).with_near_field_edges(near_field);
        let t = Instant::now();
        let rows = fm.landmark_rows(&lm, &NoProgress).expect("landmark rows");
        let secs = t.elapsed().as_secs_f64();
        let h = wavg_mesh::geometry::mean_edge_length(&mesh);
        let mut all = asymmetries(&rows);
        let sum: f64 = all.iter().map(|a| a.0).sum();
        let over = all.iter().filter(|a| a.0 > 0.02).count();
        all.sort_by(|a, b| b.0.total_cmp(&a.0));
        let pairs = all.len().max(1) as f64;
        println!(
            "| {} | {} | {secs:.2} | {:.3} | {:.2} | {:.3}% ({over}) |",
            p.file_name().unwrap().to_string_lossy(),
            lm.len(),
            100.0 * sum / pairs,
            100.0 * all.first().map_or(0.0, |a| a.0),
            100.0 * over as f64 / pairs
        );
        if std::env::var_os("WORST").is_some() {
            for &(a, i, j) in all.iter().take(8) {
                println!(
                    "  {:.2}% landmarks {} {}: {:.3} vs {:.3} edge lengths",
                    100.0 * a,
                    lm[i],
                    lm[j],
                    rows[i][j] / h,
                    rows[j][i] / h
                );
            }
        }
    }
}

/// `(|d_ij - d_ji| / mean, i, j)` for every pair `j < i`.
fn asymmetries(rows: &[Vec<f64>]) -> Vec<(f64, usize, usize)> {
    rows.iter()
        .enumerate()
        .flat_map(|(i, ri)| {
            ri.iter().take(i).enumerate().map(move |(j, &dij)| {
                let dji = rows[j][i];
                ((dij - dji).abs() / (0.5 * (dij + dji)), i, j)
            })
        })
        .collect()
}
