//! Diagnoses failed round trips of the Table 1 protocol (inverse, then forward without an
//! initial guess): for every failing query, how far the average `ybar` lies from the point
//! `yhat` in R^8, how far the competing projection is, where it happens (local thickness
//! of the shape by an inward ray, distance to the anchors) and how spread the weights are;
//! compares the fast, exhaustive and the paper's plain search (walk + unbounded
//! breadth-first search, first valid triangle wins), and counts folds of the embedding.
//!
//! `cargo run --release -p wavg-bench --bin roundtrip_failures -- MESH EMB
//!  [ANCHORS [QUERIES [GAMMA]]]` where EMB is a `.wavg` file, `-` (3-D positions) or
//! `mds:MAX_ITERATIONS:TOLERANCE` (precompute with these SMACOF settings).

use std::sync::Arc;

use wavg_mesh::geometry::{face_normals, mean_edge_length};
use wavg_mesh::{SurfacePoint, ValidMesh};
use wavg_solve::sampling::{FpsMetric, farthest_point_vertices, uniform_surface_points};
use wavg_solve::{Anchor, EmbeddedMesh, ForwardOptions, Projector, SearchMode, Solver, Vec8};

fn quant(v: &mut [f64], q: f64) -> f64 {
    if v.is_empty() {
        return f64::NAN;
    }
    v.sort_by(f64::total_cmp);
    v[((q * v.len() as f64) as usize).min(v.len() - 1)]
}

fn summary(name: &str, v: &[f64]) {
    let mut v = v.to_vec();
    println!(
        "  {name:<34} p10 {:9.3}  p50 {:9.3}  p90 {:9.3}  (n {})",
        quant(&mut v, 0.1),
        quant(&mut v, 0.5),
        quant(&mut v, 0.9),
        v.len()
    );
}

/// Möller-Trumbore: distance along the ray to the nearest hit beyond `tmin`.
fn ray_hit(
    mesh: &ValidMesh,
    o: &nalgebra::Vector3<f64>,
    d: &nalgebra::Vector3<f64>,
    skip: u32,
) -> f64 {
    let mut best = f64::INFINITY;
    for (f, t) in mesh.triangles.iter().enumerate() {
        if f as u32 == skip {
            continue;
        }
        let [a, b, c] = t.map(|v| mesh.positions[v as usize]);
        let (e1, e2) = (b - a, c - a);
        let p = d.cross(&e2);
        let det = e1.dot(&p);
        if det.abs() < 1e-14 {
            continue;
        }
        let s = o - a;
        let u = s.dot(&p) / det;
        if !(0.0..=1.0).contains(&u) {
            continue;
        }
        let q = s.cross(&e1);
        let v = d.dot(&q) / det;
        if v < 0.0 || u + v > 1.0 {
            continue;
        }
        let tt = e2.dot(&q) / det;
        if tt > 1e-9 && tt < best {
            best = tt;
        }
    }
    best
}

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let mesh = Arc::new(
        ValidMesh::new(wavg_mesh::io::load(std::path::Path::new(&args[1])).unwrap()).unwrap(),
    );
    let emb = match args.get(2).map(String::as_str) {
        None | Some("-") => EmbeddedMesh::from_positions(mesh.clone()),
        // `mds:MAX_ITERATIONS:TOLERANCE`: precompute with these SMACOF settings.
        Some(spec) if spec.starts_with("mds:") => {
            let f: Vec<&str> = spec.split(':').collect();
            let mut opts = wavg_embed::PrecomputeOptions::default();
            opts.mds.max_iterations = f[1].parse().unwrap();
            opts.mds.tolerance = f[2].parse().unwrap();
            let (e, r) = wavg_embed::precompute(&mesh, &opts, &wavg_embed::NoProgress).unwrap();
            println!(
                "  precomputed: MDS {} iterations (converged {}), stress {:.5}",
                r.mds_iterations, r.mds_converged, r.stress
            );
            EmbeddedMesh::new(
                mesh.clone(),
                e.coords.iter().map(|c| Vec8::from(*c)).collect(),
            )
            .unwrap()
        }
        Some(p) => {
            let e = wavg_embed::file::load(std::path::Path::new(p), &mesh).unwrap();
            EmbeddedMesh::new(
                mesh.clone(),
                e.coords.iter().map(|c| Vec8::from(*c)).collect(),
            )
            .unwrap()
        }
    };
    let k: usize = args.get(3).map_or(27, |s| s.parse().unwrap());
    let nq: usize = args.get(4).map_or(5000, |s| s.parse().unwrap());
    let gamma: f64 = args.get(5).map_or(10.0, |s| s.parse().unwrap());
    let emb = Arc::new(emb);
    let proj = Arc::new(Projector::new(emb.clone()).unwrap());
    let anchors = farthest_point_vertices(&mesh, k, 0, FpsMetric::EdgeGraph).unwrap();
    let mut solver = Solver::new(proj.clone(), anchors.iter().map(|&v| Anchor::Vertex(v))).unwrap();
    solver.set_gamma(gamma).unwrap();
    let points = uniform_surface_points(&mesh, nq, 1).unwrap();
    let mel3 = mean_edge_length(&mesh);
    let mel8 = emb.mean_edge_length();
    // Inward normals: flip when the mesh is oriented inside out (negative signed volume).
    let vol: f64 = mesh
        .triangles
        .iter()
        .map(|t| {
            let [a, b, c] = t.map(|v| mesh.positions[v as usize]);
            a.dot(&b.cross(&c))
        })
        .sum();
    let inward = if vol > 0.0 { -1.0 } else { 1.0 };
    let normals: Vec<_> = face_normals(&mesh).iter().map(|n| n * inward).collect();
    fold_report(&mesh, &emb);
    let topo = mesh.topology();
    println!(
        "{} ({} v), {k} anchors, {nq} queries, gamma {gamma}, mean edge 3-D {mel3:.4e} R^8 {mel8:.4e}",
        args[1],
        mesh.n_vertices()
    );
    // Anchor spacing: median 3-D distance to the nearest other anchor.
    let apos: Vec<_> = anchors
        .iter()
        .map(|&v| mesh.positions[v as usize])
        .collect();
    let mut spacing: Vec<f64> = apos
        .iter()
        .enumerate()
        .map(|(i, a)| {
            apos.iter()
                .enumerate()
                .filter(|&(j, _)| j != i)
                .map(|(_, b)| (a - b).norm())
                .fold(f64::INFINITY, f64::min)
        })
        .collect();
    let spacing = quant(&mut spacing, 0.5);
    println!(
        "  anchor spacing (median nearest) {:.2} mean edges",
        spacing / mel3
    );

    #[derive(Default)]
    struct Stats {
        off: Vec<f64>,           // |ybar - yhat| / mel8
        other: Vec<f64>,         // |ybar - y_found| / mel8 (failures)
        jump3: Vec<f64>,         // 3-D distance original-found / mel3 (failures)
        n90: Vec<f64>,           // anchors holding 90% of sum |w|
        wmax: Vec<f64>,          // largest weight
        near_anchor: Vec<f64>,   // 3-D distance to the nearest anchor / anchor spacing
        thick: Vec<f64>,         // inward ray thickness / mel3
        resid: Vec<f64>,         // |Psi (ybar - yhat)| / |ybar - yhat|
        off_rel_thick: Vec<f64>, // |ybar - yhat| (R^8) / thickness in R^8 units (approx)
        min_bary: Vec<f64>,      // smallest barycentric of the query (near an edge/vertex)
    }
    let (mut ok, mut bad) = (Stats::default(), Stats::default());
    let (mut n_fail_fast, mut n_fail_exact, mut n_fail_paper, mut n_orig_invalid) = (0, 0, 0, 0);
    let mut boundary_fail = 0;
    let mut fast_fail_exact_ok = 0;
    let mut n_agree = 0;
    // Failures per nearest anchor (are they clustered?).
    let mut by_anchor = vec![0usize; anchors.len()];
    let exact_opts = ForwardOptions {
        mode: SearchMode::Exact,
        ..Default::default()
    };
    for p in &points {
        let w = solver.inverse(p).unwrap();
        let ybar = solver.average(&w, Default::default()).unwrap();
        let yhat = emb.point(p);
        let x3 = p.position(&mesh);
        let fast = solver.forward(&w, &ForwardOptions::default()).unwrap();
        let exact = solver.forward(&w, &exact_opts);
        let okf = |q: &SurfacePoint| (q.position(&mesh) - x3).norm() < 1e-3 * mel3;
        let fast_ok = okf(&fast.point);
        let exact_ok = exact.as_ref().is_ok_and(|r| okf(&r.point));
        // The paper's plain search: walk from the highest-weight anchor, BFS over
        // triangles without budget, first valid triangle wins.
        let amax = (0..w.len())
            .max_by(|&a, &b| w[a].total_cmp(&w[b]).then(b.cmp(&a)))
            .unwrap();
        let v0 = proj.walk(&ybar, anchors[amax]);
        let paper = paper_search(&proj, &ybar, v0);
        let paper_ok = paper.is_some_and(|q| okf(&q));
        n_fail_fast += !fast_ok as usize;
        n_agree += exact
            .as_ref()
            .is_ok_and(|r| (r.position - fast.position).norm() < 1e-3 * mel3)
            as usize;
        n_fail_exact += !exact_ok as usize;
        n_fail_paper += !paper_ok as usize;
        // Does Newton on the original face give back the original point?
        let back = proj.project_onto_face(&ybar, p.face);
        let orig_valid = back.is_some_and(|xi| okf(&SurfacePoint::new(p.face, xi)));
        n_orig_invalid += !orig_valid as usize;
        if !orig_valid {
            println!(
                "  original face {} bary {:?}: Newton gives {:?}; fast ok {fast_ok}, exact ok {exact_ok}, |ybar-yhat|/mel {:.2}",
                p.face,
                p.bary,
                back,
                (ybar - yhat).norm() / mel8
            );
        }

        let s = if fast_ok { &mut ok } else { &mut bad };
        if !fast_ok {
            let nearest = (0..apos.len())
                .min_by(|&i, &j| (apos[i] - x3).norm().total_cmp(&(apos[j] - x3).norm()))
                .unwrap_or(0);
            by_anchor[nearest] += 1;
            let q = fast.point;
            s.other.push((emb.point(&q) - ybar).norm() / mel8);
            s.jump3.push((q.position(&mesh) - x3).norm() / mel3);
            if mesh.triangles[p.face as usize]
                .iter()
                .any(|&v| topo.is_boundary_vertex(v))
            {
                boundary_fail += 1;
            }
            if exact_ok {
                fast_fail_exact_ok += 1;
            }
        }
        let off = (ybar - yhat).norm();
        s.off.push(off / mel8);
        s.min_bary
            .push(p.bary.iter().copied().fold(f64::INFINITY, f64::min));
        let psi = proj.psi(p);
        s.resid.push((psi * (ybar - yhat)).norm() / off.max(1e-300));
        let mut aw: Vec<f64> = w.iter().map(|x| x.abs()).collect();
        aw.sort_by(|a, b| b.total_cmp(a));
        let tot: f64 = aw.iter().sum();
        let mut acc = 0.0;
        let mut c = 0;
        for x in &aw {
            acc += x;
            c += 1;
            if acc >= 0.9 * tot {
                break;
            }
        }
        s.n90.push(c as f64);
        s.wmax.push(w.iter().copied().fold(f64::MIN, f64::max));
        let na = apos
            .iter()
            .map(|a| (a - x3).norm())
            .fold(f64::INFINITY, f64::min);
        s.near_anchor.push(na / spacing);
        // Thickness: only for a subsample of ok queries (brute-force rays).
        if !fast_ok || s.thick.len() < 2000 {
            let n = normals[p.face as usize];
            let t = ray_hit(&mesh, &x3, &n, p.face);
            s.thick.push(t / mel3);
            // Scale the 3-D thickness to R^8 units by the edge-length ratio.
            s.off_rel_thick.push(off / (t * mel8 / mel3));
        }
    }
    let n = points.len() as f64;
    println!(
        "ok fraction: fast {:.4}  exact(closest) {:.4}  paper plain search {:.4}",
        1.0 - n_fail_fast as f64 / n,
        1.0 - n_fail_exact as f64 / n,
        1.0 - n_fail_paper as f64 / n
    );
    println!(
        "fast search agrees with the closest projection (paper's own check): {:.4}",
        n_agree as f64 / n
    );
    println!(
        "original face's Newton does not return the point: {n_orig_invalid}; failures on boundary faces {boundary_fail}; fast fails but exact ok {fast_fail_exact_ok}"
    );
    let mut ranked: Vec<(usize, usize)> = by_anchor.iter().copied().zip(0..).collect();
    ranked.sort_by(|a, b| b.cmp(a));
    let top: usize = ranked.iter().take(5).map(|r| r.0).sum();
    println!(
        "failures by nearest anchor: top 5 anchors hold {top} of {}: {:?}",
        bad.off.len(),
        ranked
            .iter()
            .take(5)
            .map(|&(c, i)| (c, anchors[i], apos[i].map(|x| (x * 100.0).round() / 100.0)))
            .collect::<Vec<_>>()
    );
    for (name, s) in [("FAILED (fast)", &bad), ("ok", &ok)] {
        println!("{name}:");
        summary("|ybar-yhat| / mean edge (R^8)", &s.off);
        summary("|ybar-y_found| / mean edge (R^8)", &s.other);
        summary("3-D jump to found / mean edge", &s.jump3);
        if !s.jump3.is_empty() {
            let near = s.jump3.iter().filter(|&&j| j < 1.5).count();
            println!("  found within 1.5 mean edges: {near} of {}", s.jump3.len());
        }
        summary("anchors with 90% of |w|", &s.n90);
        summary("max weight", &s.wmax);
        summary("nearest anchor / anchor spacing", &s.near_anchor);
        summary("inward thickness / mean edge (3-D)", &s.thick);
        summary("|ybar-yhat| / thickness (scaled)", &s.off_rel_thick);
        summary("|Psi(ybar-yhat)| / |ybar-yhat|", &s.resid);
        summary("smallest barycentric of the query", &s.min_bary);
    }
}

/// The paper's search from the walk's end `v`: rings of triangles in breadth-first order,
/// the first triangle with a valid projection wins; no budget, no fallback.
fn paper_search(proj: &Projector, y: &Vec8, v: u32) -> Option<SurfacePoint> {
    let mesh = proj.embedded().mesh();
    let topo = mesh.topology();
    let mut seen = vec![false; mesh.n_faces()];
    let mut level: Vec<u32> = topo.ring_faces(v).to_vec();
    for &f in &level {
        seen[f as usize] = true;
    }
    while !level.is_empty() {
        for &f in &level {
            if let Some(xi) = proj.project_onto_face(y, f) {
                return Some(SurfacePoint::new(f, xi));
            }
        }
        let mut next = Vec::new();
        for &f in &level {
            for g in topo.face_neighbors(f) {
                if g != wavg_mesh::NONE && !seen[g as usize] {
                    seen[g as usize] = true;
                    next.push(g);
                }
            }
        }
        level = next;
    }
    None
}

/// Folds of the embedding: for each interior edge (a, b) with opposite corners c and d,
/// the cosine between the components of c - a and d - a orthogonal to the edge (-1 for a
/// flat sheet; > 0 means the two triangles fold onto the same side). Compares R^8 with
/// 3-D.
fn fold_report(mesh: &ValidMesh, emb: &EmbeddedMesh) {
    let topo = mesh.topology();
    let (mut n, mut f3, mut f8, mut sharp8, mut sharp3) = (0usize, 0usize, 0usize, 0usize, 0usize);
    let pos8 = emb.coords();
    for (f, t) in mesh.triangles.iter().enumerate() {
        for (i, g) in topo.face_neighbors(f as u32).into_iter().enumerate() {
            if g == wavg_mesh::NONE || (g as usize) < f {
                continue;
            }
            let (a, b, c) = (t[i], t[(i + 1) % 3], t[(i + 2) % 3]);
            let tg = mesh.triangles[g as usize];
            let Some(&d) = tg.iter().find(|&&v| v != a && v != b) else {
                continue;
            };
            let cosine = |pa: Vec8, pb: Vec8, pc: Vec8, pd: Vec8| {
                let e = (pb - pa).normalize();
                let u = (pc - pa) - e * e.dot(&(pc - pa));
                let w = (pd - pa) - e * e.dot(&(pd - pa));
                u.dot(&w) / (u.norm() * w.norm())
            };
            let p3 = |v: u32| {
                let p = mesh.positions[v as usize];
                Vec8::from_fn(|k, _| if k < 3 { p[k] } else { 0.0 })
            };
            let c8 = cosine(
                pos8[a as usize],
                pos8[b as usize],
                pos8[c as usize],
                pos8[d as usize],
            );
            let c3 = cosine(p3(a), p3(b), p3(c), p3(d));
            n += 1;
            f8 += (c8 > 0.0) as usize;
            f3 += (c3 > 0.0) as usize;
            sharp8 += (c8 > -0.5) as usize;
            sharp3 += (c3 > -0.5) as usize;
        }
    }
    println!(
        "  edges {n}: dihedral < 90 deg (fold): R^8 {f8}, 3-D {f3}; dihedral < 120 deg: R^8 {sharp8}, 3-D {sharp3}"
    );
}
