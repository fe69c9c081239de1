//! Writes the procedural meshes of the hard-input figures: the figure pair
//! (`procedural::figure`, slim and heavy: the same connectivity, so vertex i corresponds
//! to vertex i) with K farthest-point anchors of the slim one, for `wavg correspond
//! --ground-truth`, and a genus-12 plate with thin straps (`procedural::holed_plate(4, 3,
//! 8, 0.05)`), for `wavg bench project`.
//!
//! `cargo xtask lab procedural_meshes OUT_DIR [K]` writes OUT_DIR/slim.obj, heavy.obj,
//! anchors.txt (K = 93 by default), plate12.obj.

use std::fmt::Write;

use wavg_mesh::ValidMesh;
use wavg_mesh::procedural::{FigureShape, figure, holed_plate};
use wavg_solve::sampling::{FpsMetric, farthest_point_vertices};

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let dir = std::path::PathBuf::from(args.first().expect("OUT_DIR"));
    let k: usize = args.get(1).map_or(93, |s| s.parse().expect("K"));
    std::fs::create_dir_all(&dir).unwrap();
    let slim = figure(&FigureShape::SLIM);
    let heavy = figure(&FigureShape::HEAVY);
    wavg_mesh::io::save(&dir.join("slim.obj"), &slim).unwrap();
    wavg_mesh::io::save(&dir.join("heavy.obj"), &heavy).unwrap();
    let mesh = ValidMesh::new(slim).unwrap();
    let ids = farthest_point_vertices(&mesh, k, 1, FpsMetric::EdgeGraph).unwrap();
    let text = ids.iter().fold(String::new(), |mut s, v| {
        let _ = writeln!(s, "v {v}");
        s
    });
    std::fs::write(dir.join("anchors.txt"), text).unwrap();
    wavg_mesh::io::save(&dir.join("plate12.obj"), &holed_plate(4, 3, 8, 0.05)).unwrap();
    println!(
        "{} vertices, {} anchors in {}",
        mesh.n_vertices(),
        ids.len(),
        dir.display()
    );
}
