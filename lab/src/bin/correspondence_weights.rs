//! Experiment: which weights map a pose pair (two meshes that share connectivity, so vertex
//! i corresponds to vertex i) best, inverse problem at every source vertex and forward
//! problem on the target. Prints, against the ground truth (errors as fractions of the
//! target's bounding-box diagonal; `flips`: mapped triangles whose normal opposes the
//! ground truth's):
//!
//! * the paper's weights, forward problems started as `Solver::forward` does and
//!   continued from mapped neighbours (layer by layer from the anchors);
//! * the paper's weights' round trip on the source at vertices, face centroids, near
//!   corners and mid-edges;
//! * one penalty `lambda` for every vertex (`penalized_weights`, `GAMMA` from the
//!   environment, default 10): its round trip, the map after 2 and 4 steps of Laplacian
//!   smoothing on the target, and the verdict of the library's local validity test (with
//!   the ground truth's normals as the reference).
//!
//! `cargo xtask lab correspondence_weights SRC SRC.wavg TGT
//! TGT.wavg ANCHORS` (ANCHORS: a file of `v VERTEX` lines, or `fps:K` for K farthest-point
//! vertices of the source, written to `fps-anchors.txt`)

use std::sync::Arc;

use rayon::prelude::*;

use wavg_mesh::{SurfacePoint, ValidMesh};
use wavg_solve::{Anchor, EmbeddedMesh, ForwardOptions, ForwardResult, Projector, Solver, Vec8};

fn solver(mesh: &str, emb: &str, anchors: &[u32]) -> Solver {
    let mesh =
        Arc::new(ValidMesh::new(wavg_mesh::io::load(std::path::Path::new(mesh)).unwrap()).unwrap());
    let e = wavg_embed::file::load(std::path::Path::new(emb), &mesh).unwrap();
    let emb = EmbeddedMesh::new(
        mesh.clone(),
        e.coords.iter().map(|c| Vec8::from(*c)).collect(),
    )
    .unwrap();
    let proj = Arc::new(Projector::new(Arc::new(emb)).unwrap());
    Solver::new(proj, anchors.iter().map(|&v| Anchor::Vertex(v))).unwrap()
}

fn vpoint(mesh: &ValidMesh, v: u32) -> SurfacePoint {
    let f = mesh.topology().ring_faces(v)[0];
    let k = mesh.triangles[f as usize]
        .iter()
        .position(|&c| c == v)
        .unwrap();
    SurfacePoint::at_corner(f, k)
}

/// Forward problems continued from neighbours, layer by layer from the anchors.
fn continued(s: &Solver, rows: &[Vec<f64>], anchors: &[u32]) -> Vec<Option<ForwardResult>> {
    let mesh = s.mesh();
    let n = mesh.n_vertices();
    let mut out: Vec<Option<ForwardResult>> = vec![None; n];
    let mut parent = vec![u32::MAX; n];
    let mut layer: Vec<u32> = anchors.to_vec();
    for &a in anchors {
        parent[a as usize] = a;
    }
    let topo = mesh.topology();
    let mut first = true;
    while !layer.is_empty() {
        let res: Vec<Option<ForwardResult>> = layer
            .par_iter()
            .map(|&v| {
                let start = if first {
                    vpoint(mesh, v)
                } else {
                    out[parent[v as usize] as usize]
                        .as_ref()
                        .map_or(vpoint(mesh, parent[v as usize]), |r| r.point)
                };
                s.forward(&rows[v as usize], &ForwardOptions::default().warm(start))
                    .ok()
            })
            .collect();
        for (&v, r) in layer.iter().zip(res) {
            out[v as usize] = r;
        }
        first = false;
        let mut next = Vec::new();
        for &v in &layer {
            for &w in topo.ring(v) {
                if parent[w as usize] == u32::MAX {
                    parent[w as usize] = v;
                    next.push(w);
                }
            }
        }
        layer = next;
    }
    out
}

/// The library's local test (majority of ring faces flipped or over-stretched, 4x the
/// map's stretch), with the ground truth's face normals as the reference, and the round
/// trip: whether each vertex is kept.
fn local_valid(
    src: &ValidMesh,
    tgt: &ValidMesh,
    img: &[Option<ForwardResult>],
    ok: &[bool],
) -> Vec<bool> {
    let pos: Vec<Option<nalgebra::Vector3<f64>>> =
        img.iter().map(|r| r.as_ref().map(|r| r.position)).collect();
    let normals: Vec<Option<nalgebra::Vector3<f64>>> = tgt
        .triangles
        .iter()
        .map(|t| {
            let p: Vec<_> = t.iter().map(|&v| tgt.positions[v as usize]).collect();
            Some((p[1] - p[0]).cross(&(p[2] - p[0])))
        })
        .collect();
    let bad = wavg::apps::internal::inconsistent_vertices(src, &pos, &normals, 4.0);
    (0..src.n_vertices())
        .map(|v| ok[v] && img[v].is_some() && !bad[v])
        .collect()
}

/// Whether the forward problem on `s` of each row returns to its point.
fn round_trips(s: &Solver, rows: &[Vec<f64>], points: &[SurfacePoint], tol: f64) -> Vec<bool> {
    rows.par_iter()
        .zip(points)
        .map(|(r, p)| {
            s.forward(r, &ForwardOptions::default())
                .is_ok_and(|f| (f.position - p.position(s.mesh())).norm() <= tol)
        })
        .collect()
}

fn stats(name: &str, tgt: &ValidMesh, img: &[Option<ForwardResult>]) {
    let lo = tgt
        .positions
        .iter()
        .fold(nalgebra::Vector3::repeat(f64::MAX), |a, p| a.inf(p));
    let hi = tgt
        .positions
        .iter()
        .fold(nalgebra::Vector3::repeat(f64::MIN), |a, p| a.sup(p));
    let diag = (hi - lo).norm();
    let mut e: Vec<f64> = img
        .iter()
        .enumerate()
        .filter_map(|(v, r)| {
            r.as_ref()
                .map(|r| (r.position - tgt.positions[v]).norm() / diag)
        })
        .collect();
    e.sort_by(f64::total_cmp);
    let n = e.len();
    let mean = e.iter().sum::<f64>() / n as f64;
    let k = (0.95 * n as f64) as usize;
    let best = e[..k].iter().sum::<f64>() / k as f64;
    let mut flips = 0;
    for t in &tgt.triangles {
        let q: Option<Vec<_>> = t
            .iter()
            .map(|&v| img[v as usize].as_ref().map(|r| r.position))
            .collect();
        let Some(q) = q else { continue };
        let p: Vec<_> = t.iter().map(|&v| tgt.positions[v as usize]).collect();
        let nq = (q[1] - q[0]).cross(&(q[2] - q[0]));
        let np = (p[1] - p[0]).cross(&(p[2] - p[0]));
        if nq.dot(&np) <= 0.0 {
            flips += 1;
        }
    }
    println!(
        "{name}: answered {n} mean {mean:.4} best95 {best:.4} p50 {:.4} p95 {:.4} flips {flips}",
        e[n / 2],
        e[k.min(n - 1)]
    );
}

fn main() {
    let a: Vec<String> = std::env::args().collect();
    let anchors: Vec<u32> = if let Some(k) = a[5].strip_prefix("fps:") {
        let m = ValidMesh::new(wavg_mesh::io::load(std::path::Path::new(&a[1])).unwrap()).unwrap();
        let v = wavg_solve::sampling::farthest_point_vertices(
            &m,
            k.parse().unwrap(),
            0,
            wavg_solve::sampling::FpsMetric::EdgeGraph,
        )
        .unwrap();
        std::fs::write(
            "fps-anchors.txt",
            v.iter().map(|v| format!("v {v}\n")).collect::<String>(),
        )
        .unwrap();
        v
    } else {
        std::fs::read_to_string(&a[5])
            .unwrap()
            .lines()
            .filter_map(|l| l.strip_prefix("v ").map(|v| v.trim().parse().unwrap()))
            .collect()
    };
    let s = solver(&a[1], &a[2], &anchors);
    let t = solver(&a[3], &a[4], &anchors);
    let mesh = s.mesh();
    let points: Vec<SurfacePoint> = (0..mesh.n_vertices() as u32)
        .map(|v| vpoint(mesh, v))
        .collect();
    let w = s.inverse_batch(&points);
    let rows: Vec<Vec<f64>> = w
        .iter()
        .map(|r| r.map(|r| r.to_vec()).unwrap_or_default())
        .collect();
    let tol = 1e-3 * s.mean_edge_length();
    let default: Vec<Option<ForwardResult>> = rows
        .par_iter()
        .map(|r| t.forward(r, &ForwardOptions::default()).ok())
        .collect();
    stats("paper weights, default start", t.mesh(), &default);
    let cont = continued(&t, &rows, &anchors);
    stats("paper weights, continued", t.mesh(), &cont);
    let back_default = round_trips(&s, &rows, &points, tol);
    let back_cont = continued(&s, &rows, &anchors);
    let ok_cont = back_cont
        .iter()
        .zip(&points)
        .filter(|(f, p)| {
            f.as_ref()
                .is_some_and(|f| (f.position - p.position(mesh)).norm() <= tol)
        })
        .count();
    println!(
        "source round trip: default {} continued {} of {}",
        back_default.iter().filter(|&&b| b).count(),
        ok_cont,
        points.len()
    );
    let mut d: Vec<f64> = back_cont
        .iter()
        .zip(&points)
        .map(|(f, p)| {
            f.as_ref().map_or(f64::INFINITY, |f| {
                (f.position - p.position(mesh)).norm() / s.mean_edge_length()
            })
        })
        .collect();
    d.sort_by(f64::total_cmp);
    let q = |x: f64| d[((d.len() - 1) as f64 * x) as usize];
    println!(
        "continued round-trip distance / mean edge: p50 {:.2e} p70 {:.2e} p80 {:.2e} p90 {:.2e} p99 {:.2e}",
        q(0.5),
        q(0.7),
        q(0.8),
        q(0.9),
        q(0.99)
    );
    for (name, b) in [
        ("centroid", [1.0 / 3.0; 3]),
        ("near corner", [0.96, 0.02, 0.02]),
        ("corner", [1.0, 0.0, 0.0]),
        ("mid-edge", [0.5, 0.5, 0.0]),
    ] {
        let pts: Vec<SurfacePoint> = (0..mesh.n_faces() as u32)
            .map(|f| SurfacePoint::new(f, b))
            .collect();
        let w = s.inverse_batch(&pts);
        let rows: Vec<Vec<f64>> = w
            .iter()
            .map(|r| r.map(|r| r.to_vec()).unwrap_or_default())
            .collect();
        let ok = round_trips(&s, &rows, &pts, tol)
            .iter()
            .filter(|&&b| b)
            .count();
        println!("{name}: round trip {:.3}", ok as f64 / pts.len() as f64);
    }
    let gamma: f64 = std::env::var("GAMMA")
        .ok()
        .map_or(10.0, |g| g.parse().unwrap());
    for lambda in [1.0, 10.0, 100.0, 1000.0] {
        let rows: Vec<Vec<f64>> = points
            .par_iter()
            .map(|p| {
                let psi = s.projector().psi(p);
                let yhat = s.projector().embedded().point(p);
                wavg_solve::internal::penalized_weights(
                    &psi,
                    &yhat,
                    s.anchors().coords(),
                    gamma,
                    lambda,
                )
                .unwrap_or_default()
            })
            .collect();
        let back = round_trips(&s, &rows, &points, tol);
        let img: Vec<Option<ForwardResult>> = rows
            .par_iter()
            .map(|r| t.forward(r, &ForwardOptions::default()).ok())
            .collect();
        // Laplacian smoothing of the map on the target (uniform weights over the source's rings).
        let mut cur = img.clone();
        let topo = mesh.topology();
        for step in 1..=4 {
            let emb: Vec<Option<Vec8>> = cur
                .iter()
                .map(|r| r.as_ref().map(|r| t.projector().embedded().point(&r.point)))
                .collect();
            cur = (0..mesh.n_vertices())
                .into_par_iter()
                .map(|v| {
                    let me = cur[v]?;
                    let ring = topo.ring(v as u32);
                    let mut acc = Vec8::zeros();
                    let mut n = 0.0;
                    for &w in ring {
                        if let Some(e) = emb[w as usize] {
                            acc += e;
                            n += 1.0;
                        }
                    }
                    if n == 0.0 {
                        return Some(me);
                    }
                    let ybar = acc / n;
                    t.forward_embedded(&ybar, &me.point, &ForwardOptions::default().warm(me.point))
                        .ok()
                })
                .collect();
            if step % 2 == 0 {
                stats(&format!("lambda {lambda}: smoothed {step}"), t.mesh(), &cur);
            }
        }
        let valid = local_valid(mesh, t.mesh(), &img, &back);
        let vimg: Vec<Option<ForwardResult>> = img
            .iter()
            .zip(&valid)
            .map(|(i, b)| if *b { *i } else { None })
            .collect();
        stats(
            &format!(
                "lambda {lambda}: LOCAL VALID {:.3}",
                valid.iter().filter(|&&b| b).count() as f64 / valid.len() as f64
            ),
            t.mesh(),
            &vimg,
        );
        let nb = back.iter().filter(|&&b| b).count();
        stats(
            &format!("lambda {lambda}: round trip {nb}; all"),
            t.mesh(),
            &img,
        );
        let masked: Vec<Option<ForwardResult>> = img
            .iter()
            .zip(&back)
            .map(|(i, b)| if *b { *i } else { None })
            .collect();
        stats(
            &format!("lambda {lambda}: where it round-trips"),
            t.mesh(),
            &masked,
        );
        let neg = rows.iter().filter(|r| r.iter().any(|&w| w < -0.1)).count();
        println!("  rows with a weight below -0.1: {neg}");
    }
    // Only where the continued source round trip holds.
    let masked: Vec<Option<ForwardResult>> = cont
        .iter()
        .zip(&back_cont)
        .zip(&points)
        .map(|((c, b), p)| {
            b.as_ref()
                .filter(|b| (b.position - p.position(mesh)).norm() <= tol)
                .and(*c)
        })
        .collect();
    stats(
        "continued, where the continued round trip holds",
        t.mesh(),
        &masked,
    );
}
