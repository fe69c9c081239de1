//! The glTF reader on arbitrary bytes (a `.glb`, or JSON when the magic is absent): a mesh
//! or a typed error, never a panic or an allocation beyond the reader's budget. A parsed
//! mesh is analysed and validated.
#![no_main]

use std::path::Path;

use libfuzzer_sys::fuzz_target;
use wavg::mesh::Format;
use wavg::mesh::io::parse_bytes;

fuzz_target!(|data: &[u8]| {
    let Ok((mesh, _)) = parse_bytes(data, Format::Glb, Path::new("fuzz.glb")) else {
        return;
    };
    let _ = wavg::mesh::analyze(&mesh);
    let _ = wavg::ValidMesh::new(mesh);
});
