//! The load benchmark protocol (`wavg bench load`): how long reading (with
//! decompression), parsing, and validating + building the topology of a mesh file take,
//! best of N runs each.
//!
//! ```
//! let dir = tempfile::tempdir().unwrap();
//! let path = dir.path().join("ico.obj");
//! wavg::mesh::io::save(&path, &wavg::mesh::procedural::icosphere(1)).unwrap();
//! let r = wavg_bench::load_bench(&path, 2).unwrap();
//! assert_eq!((r.vertices, r.faces, r.repeat), (42, 80, 2));
//! assert!(r.valid && r.topology_built);
//! assert!(r.read_s <= r.total_s && r.parse_s <= r.total_s);
//! ```

use std::path::Path;
use std::time::Instant;

use wavg::MeshError;
use wavg::mesh::{analyze, io};

/// What the protocol measured; serialises to the keys of `wavg bench load --json`, less
/// `mesh`. Times are the best of the runs, each stage on its own, in seconds.
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
pub struct LoadBenchReport {
    /// Vertices of the mesh as read.
    pub vertices: usize,
    /// Faces of the mesh as read.
    pub faces: usize,
    /// Size of the file's contents, uncompressed, in bytes.
    pub bytes: usize,
    /// Runs.
    pub repeat: u32,
    /// Whether the mesh passed validation.
    pub valid: bool,
    /// Whether its topology could be built.
    pub topology_built: bool,
    /// Reading (and decompressing) the file.
    pub read_s: f64,
    /// Parsing the bytes into a mesh.
    pub parse_s: f64,
    /// Validation and building the topology.
    pub validate_topology_s: f64,
    /// The best whole run.
    pub total_s: f64,
}

/// Reads, parses and analyses the mesh file at `path` `repeat` times (at least once).
/// Errors when the file cannot be read or parsed.
pub fn load_bench(path: &Path, repeat: u32) -> Result<LoadBenchReport, MeshError> {
    let repeat = repeat.max(1);
    let mut r = LoadBenchReport {
        vertices: 0,
        faces: 0,
        bytes: 0,
        repeat,
        valid: false,
        topology_built: false,
        read_s: f64::INFINITY,
        parse_s: f64::INFINITY,
        validate_topology_s: f64::INFINITY,
        total_s: f64::INFINITY,
    };
    for _ in 0..repeat {
        let t0 = Instant::now();
        let (format, bytes) = io::read_file(path)?;
        let t1 = Instant::now();
        let (mesh, _) = io::parse_bytes(&bytes, format, path)?;
        let t2 = Instant::now();
        let a = analyze(&mesh);
        let t3 = Instant::now();
        r.read_s = r.read_s.min((t1 - t0).as_secs_f64());
        r.parse_s = r.parse_s.min((t2 - t1).as_secs_f64());
        r.validate_topology_s = r.validate_topology_s.min((t3 - t2).as_secs_f64());
        r.total_s = r.total_s.min((t3 - t0).as_secs_f64());
        r.vertices = mesh.n_vertices();
        r.faces = mesh.n_faces();
        r.bytes = bytes.len();
        r.valid = a.report.is_valid();
        r.topology_built = a.topology.is_some();
        drop((a, mesh, bytes));
    }
    Ok(r)
}
