//! How much the order of vertices and faces in memory costs the queries:
//! `reorder_locality MESH EMBEDDING.wavg [QUERIES] [THREADS]` runs the round-trip protocol
//! (32 anchors by farthest-point sampling) on the mesh as stored and on the same mesh with
//! vertices and faces renumbered along a Morton curve of their 3-D positions (the same
//! anchors and query points, mapped), alternating twice, and prints `forward_us` and
//! `inverse_us` of each.
use std::path::Path;
use std::sync::Arc;

use nalgebra::Vector3;
use wavg_bench::RoundTripOptions;
use wavg_mesh::{SurfacePoint, TriMesh, ValidMesh};
use wavg_project::{EmbeddedMesh, Projector, Vec8};
use wavg_solve::sampling::{FpsMetric, farthest_point_vertices, uniform_surface_points};
use wavg_solve::{Anchor, Solver};

/// Interleaves the low 21 bits of `x` with two zero bits between each.
fn spread(mut x: u64) -> u64 {
    x &= 0x1f_ffff;
    x = (x | x << 32) & 0x1f00000000ffff;
    x = (x | x << 16) & 0x1f0000ff0000ff;
    x = (x | x << 8) & 0x100f00f00f00f00f;
    x = (x | x << 4) & 0x10c30c30c30c30c3;
    (x | x << 2) & 0x1249249249249249
}

fn morton(p: &Vector3<f64>, lo: &Vector3<f64>, inv: f64) -> u64 {
    let q = |k: usize| (((p[k] - lo[k]) * inv).clamp(0.0, 2097151.0)) as u64;
    spread(q(0)) | spread(q(1)) << 1 | spread(q(2)) << 2
}

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let queries: usize = args.get(3).map_or(20_000, |s| s.parse().unwrap());
    let threads: usize = args.get(4).map_or(1, |s| s.parse().unwrap());
    let mesh = wavg_mesh::io::load(Path::new(&args[1])).expect("mesh");
    let emb = wavg_embed::file::load(Path::new(&args[2]), &mesh).expect("embedding");
    let coords: Vec<Vec8> = emb.coords.iter().map(|c| Vec8::from(*c)).collect();
    let (lo, hi) = mesh.bounding_box().unwrap();
    let inv = 2097151.0 / (hi - lo).max();
    let mut vorder: Vec<u32> = (0..mesh.n_vertices() as u32).collect();
    vorder.sort_by_key(|&v| morton(&mesh.positions[v as usize], &lo, inv));
    let mut new_id = vec![0u32; vorder.len()];
    for (n, &v) in vorder.iter().enumerate() {
        new_id[v as usize] = n as u32;
    }
    let mut forder: Vec<u32> = (0..mesh.n_faces() as u32).collect();
    let centroid = |f: u32| {
        let c = mesh.corners(f as usize);
        (c[0] + c[1] + c[2]) / 3.0
    };
    forder.sort_by_key(|&f| morton(&centroid(f), &lo, inv));
    let mut new_face = vec![0u32; forder.len()];
    for (n, &f) in forder.iter().enumerate() {
        new_face[f as usize] = n as u32;
    }
    let re = TriMesh::new(
        vorder.iter().map(|&v| mesh.positions[v as usize]).collect(),
        forder
            .iter()
            .map(|&f| mesh.triangles[f as usize].map(|v| new_id[v as usize]))
            .collect(),
    );
    let re_coords: Vec<Vec8> = vorder.iter().map(|&v| coords[v as usize]).collect();

    let build = |m: TriMesh, c: Vec<Vec8>| {
        let m = Arc::new(ValidMesh::new(m).expect("valid"));
        let e = Arc::new(EmbeddedMesh::new(m, c).expect("embedded"));
        Arc::new(Projector::new(e).expect("projector"))
    };
    let p0 = build(mesh.clone(), coords);
    let p1 = build(re, re_coords);
    let anchors =
        farthest_point_vertices(p0.embedded().mesh(), 32, 0, FpsMetric::EdgeGraph).unwrap();
    let points = uniform_surface_points(p0.embedded().mesh(), queries, 1).unwrap();
    let s0 = Solver::new(p0, anchors.iter().map(|&v| Anchor::Vertex(v))).unwrap();
    let s1 = Solver::new(
        p1,
        anchors.iter().map(|&v| Anchor::Vertex(new_id[v as usize])),
    )
    .unwrap();
    let points1: Vec<SurfacePoint> = points
        .iter()
        .map(|p| SurfacePoint::new(new_face[p.face as usize], p.bary))
        .collect();
    let opts = RoundTripOptions {
        queries,
        repeat: 3,
        ..Default::default()
    };
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .unwrap();
    for round in 0..2 {
        for (name, s, pts) in [("stored", &s0, &points), ("morton", &s1, &points1)] {
            let r = pool
                .install(|| wavg_bench::round_trip_at(s, pts, &opts))
                .unwrap();
            println!(
                "round {round} {name:7} forward_us {:.3} forward_warm_us {:.3} inverse_us {:.3} ok {:.5}",
                r.forward_us, r.forward_warm_us, r.inverse_us, r.roundtrip_ok_fraction
            );
        }
    }
}
