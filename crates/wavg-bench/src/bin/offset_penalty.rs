//! Experiment (not the paper's method): the inverse problem with an extra penalty on the
//! average's offset from the point, `min sum (d_i w_i)^2 + lambda d_ref |ybar - yhat|^2`
//! (`d_ref` = the 4th smallest `d_i`), or the hard constraint `ybar = yhat` (lambda = inf),
//! to see what round-trip rate, locality and negativity cost.
//!
//! `cargo run --release -p wavg-bench --bin offset_penalty -- MESH EMB.wavg|- ANCHORS QUERIES`

use std::sync::Arc;

use nalgebra::{DMatrix, DVector};
use wavg_mesh::ValidMesh;
use wavg_mesh::geometry::mean_edge_length;
use wavg_solve::sampling::{FpsMetric, farthest_point_vertices, uniform_surface_points};
use wavg_solve::{Anchor, EmbeddedMesh, ForwardOptions, Projector, Solver, Vec8};

fn weights(
    psi: &wavg_solve::Mat2x8,
    yhat: &Vec8,
    ys: &[Vec8],
    gamma: f64,
    lambda: f64,
) -> Option<Vec<f64>> {
    let n = ys.len();
    let g = psi * psi.transpose();
    let gi = g.try_inverse()?;
    let v = DMatrix::from_fn(8, n, |k, j| ys[j][k] - yhat[k]);
    let mut d: Vec<f64> = (0..n)
        .map(|j| {
            let vj = v.column(j).into_owned();
            let a = psi * Vec8::from_fn(|k, _| vj[k]);
            let vt = (a.transpose() * gi * a)[0];
            let vv = vj.norm_squared();
            vt.min(vv) + gamma * (vv - vt.min(vv))
        })
        .collect();
    let mut sorted = d.clone();
    sorted.sort_by(f64::total_cmp);
    let dmin = sorted[0];
    if dmin <= 0.0 {
        return None;
    }
    let dref = sorted[3.min(n - 1)];
    for x in &mut d {
        *x /= dref;
    }
    let (c, b) = if lambda.is_infinite() {
        let mut c = DMatrix::zeros(9, n);
        c.view_mut((0, 0), (8, n)).copy_from(&v);
        c.row_mut(8).fill(1.0);
        let mut b = DVector::zeros(9);
        b[8] = 1.0;
        (c, b)
    } else {
        let a = DMatrix::from_fn(2, 8, |r, k| psi[(r, k)]) * &v;
        let mut c = DMatrix::zeros(3, n);
        c.view_mut((0, 0), (2, n)).copy_from(&a);
        c.row_mut(2).fill(1.0);
        let mut b = DVector::zeros(3);
        b[2] = 1.0;
        (c, b)
    };
    let mut m = DMatrix::from_diagonal(&DVector::from_iterator(n, d.iter().map(|x| x * x)));
    if lambda.is_finite() && lambda > 0.0 {
        // d was scaled by 1/dref (so d^2 by 1/dref^2): scale the penalty the same way.
        m += (v.transpose() * &v) * (lambda / dref);
    }
    let mi = m.try_inverse()?;
    let k = &c * &mi * c.transpose();
    let z = k.lu().solve(&b)?;
    let w = mi * c.transpose() * z;
    Some(w.iter().copied().collect())
}

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let mesh = Arc::new(
        ValidMesh::new(wavg_mesh::io::load(std::path::Path::new(&args[1])).unwrap()).unwrap(),
    );
    let emb = match args[2].as_str() {
        "-" => EmbeddedMesh::from_positions(mesh.clone()),
        p => {
            let e = wavg_embed::file::load(std::path::Path::new(p), &mesh).unwrap();
            EmbeddedMesh::new(
                mesh.clone(),
                e.coords.iter().map(|c| Vec8::from(*c)).collect(),
            )
            .unwrap()
        }
    };
    let k: usize = args[3].parse().unwrap();
    let nq: usize = args[4].parse().unwrap();
    let emb = Arc::new(emb);
    let proj = Arc::new(Projector::new(emb.clone()).unwrap());
    let anchors = farthest_point_vertices(&mesh, k, 0, FpsMetric::EdgeGraph).unwrap();
    let solver = Solver::new(proj.clone(), anchors.iter().map(|&v| Anchor::Vertex(v))).unwrap();
    let ys: Vec<Vec8> = anchors.iter().map(|&v| emb.coords()[v as usize]).collect();
    let points = uniform_surface_points(&mesh, nq, 1).unwrap();
    let mel3 = mean_edge_length(&mesh);
    let mel8 = emb.mean_edge_length();
    println!("{} {k} anchors {nq} queries", args[1]);
    let mut maxdiff = 0.0f64;
    for lambda in [0.0, 1.0, 10.0, 30.0, 100.0, 1000.0, f64::INFINITY] {
        let (mut ok, mut ok_exact, mut neg, mut n90s, mut offs, mut wmin, mut far) =
            (0, 0, 0, 0.0, Vec::new(), 0.0f64, 0.0);
        for p in &points {
            let psi = proj.psi(p);
            let yhat = emb.point(p);
            let Some(w) = weights(&psi, &yhat, &ys, 10.0, lambda) else {
                continue;
            };
            if lambda == 0.0 {
                let wk = solver.inverse(p).unwrap();
                let diff = w
                    .iter()
                    .zip(&wk)
                    .map(|(a, b)| (a - b).abs())
                    .fold(0.0, f64::max);
                maxdiff = maxdiff.max(diff);
            }
            let ybar = solver.average(&w, Default::default()).unwrap();
            offs.push((ybar - yhat).norm() / mel8);
            let r = solver.forward(&w, &ForwardOptions::default()).unwrap();
            ok += ((r.position - p.position(&mesh)).norm() < 1e-3 * mel3) as usize;
            let exact = ForwardOptions {
                mode: wavg_solve::SearchMode::Certified,
                ..Default::default()
            };
            let r = solver.forward(&w, &exact).unwrap();
            ok_exact += ((r.position - p.position(&mesh)).norm() < 1e-3 * mel3) as usize;
            neg += w.iter().any(|&x| x < -0.1) as usize;
            wmin = wmin.min(w.iter().copied().fold(f64::MAX, f64::min));
            let mut aw: Vec<f64> = w.iter().map(|x| x.abs()).collect();
            aw.sort_by(|a, b| b.total_cmp(a));
            let tot: f64 = aw.iter().sum();
            let (mut acc, mut c) = (0.0, 0);
            for x in &aw {
                acc += x;
                c += 1;
                if acc >= 0.9 * tot {
                    break;
                }
            }
            n90s += c as f64;
            // Weight mass on anchors farther than twice the 3rd-nearest anchor (3-D).
            let x3 = p.position(&mesh);
            let mut dist: Vec<f64> = anchors
                .iter()
                .map(|&v| (mesh.positions[v as usize] - x3).norm())
                .collect();
            let mut s = dist.clone();
            s.sort_by(f64::total_cmp);
            let cut = 2.0 * s[2];
            far += dist
                .iter_mut()
                .zip(&w)
                .filter(|(d, _)| **d > cut)
                .map(|(_, w)| w.abs())
                .sum::<f64>()
                / tot;
        }
        offs.sort_by(f64::total_cmp);
        let n = points.len() as f64;
        println!(
            "lambda {lambda:>6}: ok {:.4} (certified {:.4})  neg(<-0.1) {:.4}  min w {:.3}  mean n90 {:.2}  |w| share beyond 2x 3rd-nearest {:.4}  offset p50 {:.3} p99 {:.3} mean edges",
            ok as f64 / n,
            ok_exact as f64 / n,
            neg as f64 / n,
            wmin,
            n90s / n,
            far / n,
            offs[offs.len() / 2],
            offs[offs.len() * 99 / 100]
        );
        if lambda == 0.0 {
            println!("  (lambda 0 vs the kernel's weights: max |dw| {maxdiff:.2e})");
        }
    }
}
