//! Mesh readers (OBJ, OFF, PLY ASCII and binary) on arbitrary bytes: the first byte picks
//! the format. A parsed mesh is analysed and validated; a valid one must survive a write
//! and read back unchanged.
#![no_main]

use std::path::Path;

use libfuzzer_sys::fuzz_target;
use wavg::mesh::Format;
use wavg::mesh::io::{parse_bytes, to_bytes};

fuzz_target!(|data: &[u8]| {
    let Some((&pick, bytes)) = data.split_first() else {
        return;
    };
    let format = [Format::Obj, Format::Off, Format::Ply][pick as usize % 3];
    let Ok((mesh, _)) = parse_bytes(bytes, format, Path::new("fuzz")) else {
        return;
    };
    let _ = wavg::mesh::analyze(&mesh);
    if let Ok(valid) = wavg::ValidMesh::new(mesh.clone()) {
        for out in [Format::Obj, Format::Off, Format::Ply] {
            let text = to_bytes(&valid, out).expect("in-memory write");
            let (back, _) = parse_bytes(&text, out, Path::new("fuzz")).expect("own output parses");
            assert_eq!(back.triangles, valid.triangles);
            assert_eq!(back.positions, valid.positions);
        }
    }
});
