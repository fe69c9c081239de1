//! Writes the procedural meshes of the hard-input figures: the figure pair
//! (`procedural::figure`, slim and heavy: the same connectivity, so vertex i corresponds
//! to vertex i) with K farthest-point anchors of the slim one, for `wavg correspond
//! --ground-truth`, and a genus-12 plate with thin straps (`procedural::holed_plate(4, 3,
//! 8, 0.05)`), for `wavg bench project`; and the body pair (`procedural::body`: the
//! figure with ears and toes) with its anchors.
//!
//! `cargo xtask lab procedural_meshes OUT_DIR [K]` writes OUT_DIR/slim.obj, heavy.obj,
//! anchors.txt (K = 93 by default), plate12.obj, body_slim.obj, body_heavy.obj,
//! body_anchors.txt.

use std::fmt::Write;

use wavg_mesh::ValidMesh;
use wavg_mesh::procedural::{FigureShape, body, figure, holed_plate};
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
    let ids = anchors(&mesh, k, &dir.join("anchors.txt"));
    wavg_mesh::io::save(&dir.join("plate12.obj"), &holed_plate(4, 3, 8, 0.05)).unwrap();
    let slim = body(&FigureShape::SLIM);
    wavg_mesh::io::save(&dir.join("body_slim.obj"), &slim).unwrap();
    wavg_mesh::io::save(&dir.join("body_heavy.obj"), &body(&FigureShape::HEAVY)).unwrap();
    anchors(
        &ValidMesh::new(slim).unwrap(),
        k,
        &dir.join("body_anchors.txt"),
    );
    println!(
        "{} vertices, {} anchors in {}",
        mesh.n_vertices(),
        ids.len(),
        dir.display()
    );
}

/// Writes `k` farthest-point anchors of `mesh` (`v VERTEX` lines) to `path`.
fn anchors(mesh: &ValidMesh, k: usize, path: &std::path::Path) -> Vec<u32> {
    let ids = farthest_point_vertices(mesh, k, 1, FpsMetric::EdgeGraph).unwrap();
    let text = ids.iter().fold(String::new(), |mut s, v| {
        let _ = writeln!(s, "v {v}");
        s
    });
    std::fs::write(path, text).unwrap();
    ids
}
