//! How fast a `.wavg` embedding file is written and read back, in MB/s (best of 3 each).
//!
//! `cargo run -p wavg-lab --bin wavg_file_rates MESH EMB.wavg`

use std::time::Instant;

use wavg_embed::file;
use wavg_mesh::ValidMesh;

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let [mesh, emb] = [&args[0], &args[1]].map(std::path::Path::new);
    let mesh = ValidMesh::new(wavg_mesh::io::load(mesh).expect("load")).expect("valid");
    let bytes = std::fs::metadata(emb).expect("embedding file").len() as f64;
    let dir = std::env::temp_dir().join(format!("wavg_file_rates_{}", std::process::id()));
    std::fs::create_dir_all(&dir).expect("temporary folder");
    let copy = dir.join("copy.wavg");
    let (mut read_s, mut write_s) = (f64::INFINITY, f64::INFINITY);
    for _ in 0..3 {
        let t = Instant::now();
        let e = file::load(emb, &mesh).expect("read");
        read_s = read_s.min(t.elapsed().as_secs_f64());
        let t = Instant::now();
        file::save(&copy, &e, &mesh).expect("write");
        write_s = write_s.min(t.elapsed().as_secs_f64());
    }
    let _ = std::fs::remove_dir_all(&dir);
    let mb = bytes / 1e6;
    println!(
        "{} vertices, {mb:.1} MB: read {read_s:.3} s ({:.0} MB/s), write {write_s:.3} s ({:.0} MB/s)",
        mesh.n_vertices(),
        mb / read_s,
        mb / write_s
    );
}
