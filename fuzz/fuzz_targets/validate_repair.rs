//! Validation and repair of arbitrary meshes (any positions, including NaN, any indices):
//! no panic; whatever repair reports as valid, validation accepts.
#![no_main]

use arbitrary::Arbitrary;
use libfuzzer_sys::fuzz_target;
use nalgebra::Vector3;
use wavg::mesh::RepairOptions;
use wavg::mesh::repair::repair_all;
use wavg::{TriMesh, ValidMesh};

#[derive(Arbitrary, Debug)]
struct Input {
    positions: Vec<[f64; 3]>,
    triangles: Vec<[u8; 3]>,
    weld: Option<f64>,
    largest: bool,
}

fuzz_target!(|input: Input| {
    let positions = input.positions.iter().map(|p| Vector3::from(*p)).collect();
    let triangles = input.triangles.iter().map(|t| t.map(u32::from)).collect();
    let mesh = TriMesh::new(positions, triangles);
    let _ = ValidMesh::new(mesh.clone());
    let options = RepairOptions {
        weld: input.weld.filter(|w| w.is_finite() && *w >= 0.0),
        keep_largest_component: input.largest,
        ..RepairOptions::default()
    };
    let repaired = repair_all(&mesh, &options);
    let report = wavg::mesh::analyze(&repaired.mesh);
    if report.report.is_valid() {
        ValidMesh::new(repaired.mesh).expect("repair's valid verdict holds");
    }
});
