//! Texture transfer on Keenan Crane's spot: onto itself (same anchors) and onto a deformed
//! copy, both must reproduce the texture closely; mismatched inputs are refused.

use std::sync::Arc;

use wavg_apps::{AppError, Image, TransferOptions, transfer_texture};
use wavg_embed::{NoProgress, PrecomputeOptions, precompute};
use wavg_mesh::{TriMesh, ValidMesh};
use wavg_solve::{Anchor, EmbeddedMesh, Projector, Solver, Vec8};

fn solver(mesh: TriMesh, anchors: &[u32]) -> Solver {
    let mesh = Arc::new(ValidMesh::new(mesh).unwrap());
    let opts = PrecomputeOptions {
        landmarks: 300,
        quality_pairs: 0,
        ..Default::default()
    };
    let (emb, _) = precompute(&mesh, &opts, &NoProgress).unwrap();
    let coords: Vec<Vec8> = emb.coords.iter().map(|c| Vec8::from(*c)).collect();
    let e = Arc::new(EmbeddedMesh::new(mesh, coords).unwrap());
    let proj = Arc::new(Projector::new(e).unwrap());
    Solver::new(proj, anchors.iter().map(|&v| Anchor::Vertex(v))).unwrap()
}

/// Mean absolute RGB difference (0-255) over the opaque texels of `out`, against the
/// texture sampled at the same texel centres.
fn mean_error(out: &Image, tex: &Image) -> f64 {
    let (mut sum, mut n) = (0.0, 0usize);
    for y in 0..out.height {
        for x in 0..out.width {
            let p = out.get(x, y);
            if p[3] == 0 {
                continue;
            }
            let u = (x as f64 + 0.5) / out.width as f64;
            let v = 1.0 - (y as f64 + 0.5) / out.height as f64;
            let t = tex.sample_bilinear(u, v);
            sum += (0..3).map(|k| (p[k] as f64 - t[k]).abs()).sum::<f64>() / 3.0;
            n += 1;
        }
    }
    sum / n as f64
}

#[test]
fn spot_onto_itself_and_onto_a_deformed_copy() {
    let Some(obj) =
        wavg_testdata::require_data_file("transfer", "textured/spot/spot_triangulated.obj")
    else {
        return;
    };
    let png = obj.with_file_name("spot_texture.png");
    let tex = Image::read_png(&png).unwrap();
    let mesh = wavg_mesh::io::load(&obj).unwrap();
    let anchors: Vec<u32> = (0..mesh.positions.len() as u32).step_by(97).collect();
    let source = solver(mesh.clone(), &anchors);
    let mut bent = mesh.clone();
    for p in &mut bent.positions {
        p.x *= 1.3;
        p.y += 0.15 * p.z * p.z;
    }
    let target = solver(bent, &anchors);
    let bad_anchors = solver(mesh.clone(), &anchors[1..]);
    let opts = TransferOptions {
        width: 256,
        height: 256,
        ..Default::default()
    };
    for (stride, what, tgt, limit) in [
        (1, "self", &source, 1.0),
        (4, "self", &source, 1.0),
        (4, "deformed", &target, 8.0),
    ] {
        let o = TransferOptions { stride, ..opts };
        let out = transfer_texture(&source, &tex, tgt, &o, &|_, _| {}).unwrap();
        assert!(out.covered > 20_000, "{}", out.covered);
        assert!(out.valid as f64 >= 0.99 * out.covered as f64);
        let e = mean_error(&out.image, &tex);
        eprintln!(
            "{what} stride {stride}: mean colour error {e:.3} over {} texels",
            out.valid
        );
        assert!(e < limit, "{what} stride {stride}: {e}");
    }
    let e = transfer_texture(&source, &tex, &bad_anchors, &opts, &|_, _| {}).unwrap_err();
    assert!(matches!(e, AppError::Input(_)), "{e}");
    // A target without texture coordinates.
    let mut plain = mesh.clone();
    plain.uv = None;
    let no_uv = solver(plain, &anchors);
    let e = transfer_texture(&source, &tex, &no_uv, &opts, &|_, _| {}).unwrap_err();
    assert!(e.to_string().contains("texture coordinates"), "{e}");
}
