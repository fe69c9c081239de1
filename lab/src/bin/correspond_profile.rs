//! Where a correspondence's time goes: maps every vertex of a pose pair (two meshes that
//! share connectivity, vertex i corresponds to vertex i) with
//! `wavg_apps::correspond_vertices` and prints its stage timings, valid fraction, mean
//! error of the valid vertices (fraction of the target's bounding-box diagonal), the
//! forward problems' search paths on the target and the verified weights' round trips.
//! Run it under `valgrind --tool=callgrind --toggle-collect='*correspond_vertices*'` for
//! instructions per vertex.
//!
//! `cargo xtask lab correspond_profile SRC SRC.wavg TGT TGT.wavg ANCHORS [THREADS] [REPEAT]`
//! (ANCHORS: a file of `v VERTEX` lines, the same ids on both meshes). Environment:
//! `TARGET_ANCHORS=FILE` the target's own anchors (other shapes: the error printed is then
//! meaningless), `REASONS=1` error per rejection reason, `DUMP=FILE` a line per vertex
//! (reason, error, source position) for locating the rejected vertices, `COMPARE=1`
//! compares validity tests. With shared connectivity it prints `rejected_correct` and
//! `accepted_wrong` against the ground truth.

use std::sync::Arc;

use wavg_apps::{CorrespondOptions, correspond_vertices};
use wavg_mesh::ValidMesh;
use wavg_solve::{Anchor, EmbeddedMesh, Projector, Solver, Vec8};

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

fn main() {
    let a: Vec<String> = std::env::args().skip(1).collect();
    let anchors: Vec<u32> = std::fs::read_to_string(&a[4])
        .unwrap()
        .lines()
        .filter_map(|l| l.strip_prefix("v ")?.trim().parse().ok())
        .collect();
    let threads: usize = a.get(5).map_or(1, |s| s.parse().unwrap());
    let repeat: usize = a.get(6).map_or(1, |s| s.parse().unwrap());
    let s = solver(&a[0], &a[1], &anchors);
    // TARGET_ANCHORS: the target's own anchor file (shapes that do not share connectivity).
    let target_anchors: Vec<u32> = std::env::var("TARGET_ANCHORS").map_or(anchors.clone(), |f| {
        std::fs::read_to_string(f)
            .unwrap()
            .lines()
            .filter_map(|l| l.strip_prefix("v ")?.trim().parse().ok())
            .collect()
    });
    let t = solver(&a[2], &a[3], &target_anchors);
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .unwrap();
    let n = s.mesh().n_vertices();
    if std::env::var_os("COMPARE").is_some() {
        pool.install(|| compare(&s, &t));
        return;
    }
    for _ in 0..repeat {
        let t0 = std::time::Instant::now();
        let c = pool
            .install(|| correspond_vertices(&s, &t, &CorrespondOptions::default()))
            .unwrap();
        let secs = t0.elapsed().as_secs_f64();
        let diag = t.mesh().bounding_box_diagonal();
        let pos = c.valid_positions();
        let (mut err, mut k) = (0.0, 0usize);
        for (v, p) in pos.iter().enumerate() {
            if let Some(p) = p {
                err += (p - t.mesh().positions[v]).norm() / diag;
                k += 1;
            }
        }
        let mut paths = std::collections::BTreeMap::new();
        for m in &c.mapped {
            let key = match &m.target {
                Ok(r) => format!("{:?}", r.path),
                Err(e) => format!("err {e}"),
            };
            *paths.entry(key).or_insert(0usize) += 1;
        }
        let tm = c.timings;
        println!(
            "{n} vertices, {threads} threads: {secs:.4} s ({:.0} v/s); weights {:.4} forward {:.4} validity {:.4}; valid {:.4} mean error {:.5}; paths {paths:?}; trips failed {}; reasons {:?}",
            n as f64 / secs,
            tm.weights_seconds,
            tm.forward_seconds,
            tm.validity_seconds,
            c.valid_fraction(),
            err / k.max(1) as f64,
            c.mapped.iter().filter(|m| !m.round_trip).count(),
            c.reason_counts(),
        );
        println!(
            "  distortion: stretch_best95 {:.4}, flipped_area_fraction {:.4}",
            c.distortion.stretch_best95, c.distortion.flipped_area_fraction
        );
        if let Ok(g) = c.ground_truth_errors(s.mesh(), t.mesh()) {
            println!(
                "  ground truth: rejected_correct {}, accepted_wrong {}",
                g.rejected_correct, g.accepted_wrong
            );
        }
        if std::env::var_os("REASONS").is_some() {
            reasons(&s, &t, &c);
        }
        if let Some(path) = std::env::var_os("DUMP") {
            dump(&path, &s, &t, &c);
        }
    }
}

/// Per stage, the cold and the warm-started way side by side (wall seconds, 1 thread): the
/// source's round trip (cold verified check against the check started at the vertex) and
/// the target's forward problems (cold batch against chains in Morton order, started from
/// the previous image).
fn compare(s: &Solver, t: &Solver) {
    use wavg_solve::{ForwardOptions, RoundTrip};
    let mesh = s.mesh();
    let points = wavg_apps::vertex_points(mesh);
    let tol = 1e-3 * s.mean_edge_length();
    let (mut both, mut warm_only, mut cold_only, mut neither) = (0, 0, 0, 0);
    let mut rows = Vec::new();
    for p in &points {
        let w = s.inverse(p).unwrap();
        let warm = s
            .forward(&w, &ForwardOptions::default().warm(*p))
            .is_ok_and(|r| (r.position - p.position(mesh)).norm() <= tol);
        let v = s.inverse_verified(p, 1e-3).unwrap();
        let cold = v.round_trip == RoundTrip::Paper;
        match (warm, cold) {
            (true, true) => both += 1,
            (true, false) => warm_only += 1,
            (false, true) => cold_only += 1,
            (false, false) => neither += 1,
        }
        rows.push(v.weights);
    }
    println!(
        "round trip of the paper weights: both {both}, warm only {warm_only}, cold only {cold_only}, neither {neither}"
    );
    let t0 = std::time::Instant::now();
    let cold = t.forward_batch(&rows, &ForwardOptions::default());
    let cold_s = t0.elapsed().as_secs_f64();
    let t0 = std::time::Instant::now();
    let mut order: Vec<u32> = (0..rows.len() as u32).collect();
    order.sort_by_key(|&v| {
        let p = mesh.positions[v as usize];
        (
            (p.x * 64.0) as i64,
            (p.y * 64.0) as i64,
            (p.z * 64.0) as i64,
        )
    });
    let mut opts = ForwardOptions::default();
    let mut same = 0;
    let mut warm_face = 0;
    for &v in &order {
        let prev = opts.warm_start;
        let r = t.forward(&rows[v as usize], &opts);
        if let Ok(r) = &r {
            if prev.is_some_and(|p| p.face == r.point.face) {
                warm_face += 1;
            }
            opts.warm_start = Some(r.point);
            if cold[v as usize]
                .as_ref()
                .is_ok_and(|c| (c.position - r.position).norm() < 1e-9)
            {
                same += 1;
            }
        }
    }
    // Newton's method from the previous image's face, following its exits.
    let morton = {
        let mut o: Vec<(u64, u32)> = (0..rows.len() as u32)
            .map(|v| {
                let p = mesh.positions[v as usize];
                let c = |x: f64| ((x + 2.0) * 200.0) as u64 & 1023;
                let mut k = 0u64;
                for b in 0..10 {
                    k |= ((c(p.x) >> b) & 1) << (3 * b);
                    k |= ((c(p.y) >> b) & 1) << (3 * b + 1);
                    k |= ((c(p.z) >> b) & 1) << (3 * b + 2);
                }
                (k, v)
            })
            .collect();
        o.sort_unstable();
        o.into_iter().map(|x| x.1).collect::<Vec<u32>>()
    };
    let proj = t.projector();
    let tmesh = t.mesh();
    let (mut hit, mut agree, mut near_ok, mut solves) = (0, 0, 0, 0usize);
    let mut prev: Option<u32> = None;
    let t1 = std::time::Instant::now();
    for &v in &morton {
        let Ok(y) = t.average(&rows[v as usize], Default::default()) else {
            continue;
        };
        let mut found = None;
        if let Some(mut f) = prev {
            for _ in 0..8 {
                solves += 1;
                match proj.project_onto_face_or_exit(&y, f) {
                    Ok((xi, d)) => {
                        found = Some((f, xi, d));
                        break;
                    }
                    Err(g) if g != u32::MAX => f = g,
                    Err(_) => break,
                }
            }
        }
        match found {
            Some((f, xi, d)) => {
                hit += 1;
                prev = Some(f);
                let pos = wavg_mesh::SurfacePoint::new(f, xi).position(tmesh);
                if cold[v as usize]
                    .as_ref()
                    .is_ok_and(|c| (c.position - pos).norm() < 1e-9)
                {
                    agree += 1;
                }
                let cs = tmesh.triangles[f as usize]
                    .map(|u| (proj.embedded().coords()[u as usize] - y).norm());
                if cs.iter().all(|&c| d <= c) {
                    near_ok += 1;
                }
            }
            None => {
                if let Ok(r) = t.forward(&rows[v as usize], &ForwardOptions::default()) {
                    prev = Some(r.point.face);
                }
            }
        }
    }
    println!(
        "newton from the previous face: {:.4} s, hit {hit} ({solves} solves), agree with cold {agree}, near {near_ok}",
        t1.elapsed().as_secs_f64()
    );
    println!(
        "target forward: cold {cold_s:.4} s, warm chain {:.4} s, same image {same} of {}, image on the previous image's face {warm_face}",
        t0.elapsed().as_secs_f64(),
        rows.len()
    );
}

/// Per reason: vertices, mean error and the fraction within 1% of the diagonal; then how
/// many the stretch test alone rejects.
fn reasons(s: &Solver, t: &Solver, c: &wavg_apps::Correspondence) {
    let diag = t.mesh().bounding_box_diagonal();
    let mut by = std::collections::BTreeMap::new();
    for (v, (m, val)) in c.mapped.iter().zip(&c.validity).enumerate() {
        if let Ok(r) = &m.target {
            let e = (r.position - t.mesh().positions[v]).norm() / diag;
            let entry = by.entry(val.reason()).or_insert((0usize, 0.0, 0usize));
            entry.0 += 1;
            entry.1 += e;
            entry.2 += usize::from(e <= 0.01);
        }
    }
    for (k, (n, sum, ok)) in by {
        println!(
            "  {k}: {n} vertices, mean error {:.5}, within 1%: {:.4}",
            sum / n as f64,
            ok as f64 / n as f64
        );
    }
    let answered: Vec<_> = c
        .mapped
        .iter()
        .map(|m| m.target.as_ref().ok().map(|r| r.position))
        .collect();
    let none = vec![None; s.mesh().n_faces()];
    let stretch = wavg_apps::internal::inconsistent_vertices(s.mesh(), &answered, &none, 4.0);
    println!(
        "  stretch alone rejects {}",
        stretch.iter().filter(|&&b| b).count()
    );
}

/// Per source vertex, a line `REASON ERROR X Y Z` (error in target diagonals, -1 without
/// an image; the source position) for finding where the rejected vertices are.
fn dump(path: &std::ffi::OsStr, s: &Solver, t: &Solver, c: &wavg_apps::Correspondence) {
    use std::fmt::Write;
    let diag = t.mesh().bounding_box_diagonal();
    let mut out = String::new();
    for (v, (m, val)) in c.mapped.iter().zip(&c.validity).enumerate() {
        let e = m
            .target
            .as_ref()
            .map_or(-1.0, |r| (r.position - t.mesh().positions[v]).norm() / diag);
        let p = s.mesh().positions[v];
        writeln!(out, "{} {e:.6} {} {} {}", val.reason(), p.x, p.y, p.z).unwrap();
    }
    std::fs::write(path, out).unwrap();
}
