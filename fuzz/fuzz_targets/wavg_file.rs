//! The `.wavg` decoder on arbitrary bytes for a fixed small mesh: a typed error or an
//! embedding that passes its own validation, never a panic or a huge allocation.
#![no_main]

use std::path::Path;
use std::sync::LazyLock;

use libfuzzer_sys::fuzz_target;
use wavg::TriMesh;

/// The mesh of `wavg precompute builtin:sphere-small`, which makes the seed files.
static MESH: LazyLock<TriMesh> = LazyLock::new(|| wavg::mesh::procedural::icosphere(2));

fuzz_target!(|data: &[u8]| {
    if let Ok(e) = wavg::embed::file::decode(data, &MESH, Path::new("fuzz.wavg")) {
        e.validate(MESH.n_vertices())
            .expect("decoded embeddings are valid");
    }
});
