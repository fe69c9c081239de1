//! How fast a `.wavg` embedding file is written and read back, in MB/s (best of 3 each):
//! the given file as it is (a version-1 file takes the version-1 path), the current format
//! written and read, and, for comparison in the same run, the version-1 writer's byte-wise
//! FNV-1a checksum and fingerprint over the same bytes.
//!
//! `cargo run --release -p wavg-lab --bin wavg_file_rates MESH EMB.wavg`

use std::io::Write;
use std::time::Instant;

use wavg_embed::Embedding;
use wavg_embed::file::{self, FNV_OFFSET, fnv1a64, mesh_hash};
use wavg_mesh::{TriMesh, ValidMesh};

/// The version-1 writer's work: FNV-1a 64 of the mesh and of every byte written, the
/// coordinates converted a block at a time, written and flushed to disk.
fn save_v1_like(path: &std::path::Path, emb: &Embedding, mesh: &TriMesh) -> std::io::Result<()> {
    let f = std::fs::File::create(path)?;
    let mut w = std::io::BufWriter::new(&f);
    // The header's other fields cost nothing to write; only the fingerprint is timed.
    let mut head = vec![0u8; file::HEADER_LEN];
    head[32..40].copy_from_slice(&mesh_hash(mesh).to_le_bytes());
    let mut sum = fnv1a64(FNV_OFFSET, &head);
    w.write_all(&head)?;
    let mut buf = Vec::with_capacity((1 << 14) * emb.dim * 8);
    for block in emb.coords.chunks(1 << 14) {
        buf.clear();
        buf.extend(
            block
                .iter()
                .flat_map(|c| &c[..emb.dim])
                .flat_map(|x| x.to_le_bytes()),
        );
        sum = fnv1a64(sum, &buf);
        w.write_all(&buf)?;
    }
    w.write_all(&sum.to_le_bytes())?;
    w.flush()?;
    drop(w);
    f.sync_all()
}

fn best_of_3(mut f: impl FnMut()) -> f64 {
    (0..3)
        .map(|_| {
            let t = Instant::now();
            f();
            t.elapsed().as_secs_f64()
        })
        .fold(f64::INFINITY, f64::min)
}

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let [mesh, emb] = [&args[0], &args[1]].map(std::path::Path::new);
    let mesh = ValidMesh::new(wavg_mesh::io::load(mesh).expect("load")).expect("valid");
    let dir = std::env::temp_dir().join(format!("wavg_file_rates_{}", std::process::id()));
    std::fs::create_dir_all(&dir).expect("temporary folder");
    let copy = dir.join("copy.wavg");
    let old = dir.join("v1.wavg");
    let given_mb = std::fs::metadata(emb).expect("embedding file").len() as f64 / 1e6;
    let e = file::load(emb, &mesh).expect("read");
    let given_s = best_of_3(|| drop(file::load(emb, &mesh).expect("read")));
    let write_s = best_of_3(|| file::save(&copy, &e, &mesh).expect("write"));
    let read_s = best_of_3(|| drop(file::load(&copy, &mesh).expect("read")));
    let v1_write_s = best_of_3(|| save_v1_like(&old, &e, &mesh).expect("write"));
    let mb = std::fs::metadata(&copy).expect("written").len() as f64 / 1e6;
    let _ = std::fs::remove_dir_all(&dir);
    println!(
        "{} vertices, {mb:.1} MB: given file read {given_s:.3} s ({:.0} MB/s); \
         current format write {write_s:.3} s ({:.0} MB/s), read {read_s:.3} s ({:.0} MB/s); \
         version-1-like write {v1_write_s:.3} s ({:.0} MB/s)",
        mesh.n_vertices(),
        given_mb / given_s,
        mb / write_s,
        mb / read_s,
        mb / v1_write_s
    );
}
