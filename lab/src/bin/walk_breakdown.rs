//! Where a forward query's time goes: `walk_breakdown MESH EMB [MESH EMB ...]`. Modes
//! (environment): `STEPS=1` the walk's steps and distances, `SLOW=N` the N slowest
//! projections dissected, `QUICK=1` walk / projection / forward times only, `DUMP=FILE`
//! every forward answer (face, barycentrics, distance) to compare two builds.
use std::path::Path;
use std::sync::Arc;
use std::time::Instant;

use wavg_mesh::ValidMesh;
use wavg_project::{EmbeddedMesh, Projector, SearchGoal, Vec8};
use wavg_solve::sampling::{FpsMetric, farthest_point_vertices, uniform_surface_points};
use wavg_solve::{Anchor, ForwardOptions, Solver};

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let mut setups = Vec::new();
    for pair in args[1..].chunks(2) {
        let mesh = wavg_mesh::io::load(Path::new(&pair[0])).expect("mesh");
        let emb = wavg_embed::file::load(Path::new(&pair[1]), &mesh).expect("embedding");
        let coords: Vec<Vec8> = emb.coords.iter().map(|c| Vec8::from(*c)).collect();
        let m = Arc::new(ValidMesh::new(mesh).unwrap());
        let e = Arc::new(EmbeddedMesh::new(m.clone(), coords.clone()).unwrap());
        let p = Arc::new(Projector::new(e).unwrap());
        let anchors = farthest_point_vertices(&m, 32, 0, FpsMetric::EdgeGraph).unwrap();
        let points = uniform_surface_points(&m, 20000, 1).unwrap();
        let s = Solver::new(p.clone(), anchors.iter().map(|&v| Anchor::Vertex(v))).unwrap();
        let ws: Vec<Vec<f64>> = points.iter().map(|x| s.inverse(x).unwrap()).collect();
        let ys: Vec<(Vec8, u32)> = ws
            .iter()
            .map(|w| {
                let y = w
                    .iter()
                    .zip(&anchors)
                    .map(|(&wi, &a)| coords[a as usize] * wi)
                    .sum::<Vec8>();
                let best = (0..w.len()).max_by(|&i, &j| w[i].total_cmp(&w[j])).unwrap();
                (y, anchors[best])
            })
            .collect();
        setups.push((pair[0].clone(), p, s, ws, ys));
    }
    if std::env::var("SLOW").is_ok() {
        for (name, p, _, _, ys) in &setups {
            slow(name, p, ys);
        }
        return;
    }
    if std::env::var("STEPS").is_ok() {
        for (name, p, _, _, ys) in &setups {
            steps(name, p, ys);
        }
        return;
    }
    if let Ok(n) = std::env::var("BATCH_ONLY") {
        eprintln!("setup done");
        for (name, _, s, ws, _) in &setups {
            let rows: Vec<&[f64]> = ws.iter().map(|w| w.as_slice()).collect();
            let t = Instant::now();
            for _ in 0..n.parse::<usize>().unwrap() {
                let r = s.forward_batch(&rows, &ForwardOptions::default());
                assert_eq!(r.len(), rows.len());
            }
            println!("{name}: {:.2} s", t.elapsed().as_secs_f64());
        }
        return;
    }
    if let Ok(path) = std::env::var("DUMP") {
        use std::fmt::Write as _;
        let mut out = String::new();
        for (name, _, s, ws, _) in &setups {
            for w in ws {
                let r = s.forward(w, &ForwardOptions::default()).unwrap();
                let b = r.point.bary;
                writeln!(out, "{name} {} {:?} {:e}", r.point.face, b, r.distance).unwrap();
            }
        }
        std::fs::write(path, out).unwrap();
        return;
    }
    if std::env::var("QUICK").is_ok() {
        // Per round: the walk, the first-hit projection and the forward problem, without
        // the other stages (a quicker side-by-side of two builds).
        let rounds: usize = std::env::var("ROUNDS").map_or(5, |r| r.parse().unwrap());
        for round in 0..rounds {
            for (name, p, s, ws, ys) in &setups {
                let t = Instant::now();
                let mut acc = 0u64;
                for (y, a) in ys {
                    acc += u64::from(p.walk(y, p.start_near(y, *a)));
                }
                let t_walk = t.elapsed().as_secs_f64() / ys.len() as f64 * 1e6;
                let t = Instant::now();
                for (y, a) in ys {
                    let r = p.project_with(y, p.start_near(y, *a), None, SearchGoal::FirstHit);
                    acc += u64::from(r.unwrap().point.face);
                }
                let t_proj = t.elapsed().as_secs_f64() / ys.len() as f64 * 1e6;
                let o = ForwardOptions::default();
                let t = Instant::now();
                for w in ws {
                    acc += u64::from(s.forward(w, &o).unwrap().point.face);
                }
                let t_fwd = t.elapsed().as_secs_f64() / ys.len() as f64 * 1e6;
                println!(
                    "round {round} {name}: walk {t_walk:.3} project {t_proj:.3} forward {t_fwd:.3} us ({acc})"
                );
            }
        }
        return;
    }
    let rounds: usize = std::env::var("ROUNDS").map_or(7, |r| r.parse().unwrap());
    let mut best = vec![[f64::INFINITY; 5]; setups.len()];
    for round in 0..rounds {
        for (i, (name, p, s, ws, ys)) in setups.iter().enumerate() {
            let t = Instant::now();
            let mut acc = 0u64;
            for (y, a) in ys {
                acc += u64::from(p.start_near(y, *a));
            }
            let t_start = t.elapsed().as_secs_f64() / ys.len() as f64 * 1e6;
            let t = Instant::now();
            for (y, a) in ys {
                acc += u64::from(p.walk(y, p.start_near(y, *a)));
            }
            let t_walk = t.elapsed().as_secs_f64() / ys.len() as f64 * 1e6;
            let t = Instant::now();
            for (y, a) in ys {
                acc += u64::from(
                    p.project_with(y, p.start_near(y, *a), None, SearchGoal::FirstHit)
                        .unwrap()
                        .point
                        .face,
                );
            }
            let t_proj = t.elapsed().as_secs_f64() / ys.len() as f64 * 1e6;
            let t = Instant::now();
            for w in ws {
                acc += u64::from(s.forward(w, &ForwardOptions::default()).unwrap().point.face);
            }
            let t_fwd = t.elapsed().as_secs_f64() / ys.len() as f64 * 1e6;
            let rows: Vec<&[f64]> = ws.iter().map(|w| w.as_slice()).collect();
            let t = Instant::now();
            let r = s.forward_batch(&rows, &ForwardOptions::default());
            let t_batch = t.elapsed().as_secs_f64() / ys.len() as f64 * 1e6;
            acc += r.len() as u64;
            println!(
                "round {round} {name}: start_near {t_start:.3} +walk {t_walk:.3} project {t_proj:.3} forward {t_fwd:.3} batch {t_batch:.3} us ({acc})"
            );
            for (b, t) in best[i]
                .iter_mut()
                .zip([t_start, t_walk, t_proj, t_fwd, t_batch])
            {
                *b = b.min(t);
            }
        }
    }
    for ((name, ..), b) in setups.iter().zip(&best) {
        println!(
            "best {name}: start_near {:.3} +walk {:.3} project {:.3} forward {:.3} batch {:.3}",
            b[0], b[1], b[2], b[3], b[4]
        );
    }
    if best.len() >= 2 {
        for i in 1..best.len() {
            let r: Vec<String> = (0..5)
                .map(|k| format!("{:.2}", best[i][k] / best[0][k]))
                .collect();
            println!("ratio {i}/first: {}", r.join(" "));
        }
    }
}

/// `STEPS=1`: per query, the vertex walk's steps from the start grid's vertex (replayed in
/// f64, so within rounding of the projector's 16-bit walk), the distance the walk covers
/// and the query's distance from the surface, in mean embedded edges, and the hops from
/// the walk's end to the answer's face (breadth-first, at most 64).
fn steps(name: &str, p: &Projector, ys: &[(Vec8, u32)]) {
    let m = p.embedded().mesh();
    let topo = m.topology();
    let x = p.embedded().coords();
    let edge = mean_embedded_edge(p);
    let mut walk = Vec::new();
    let mut cover = Vec::new();
    let mut off = Vec::new();
    let mut hops = Vec::new();
    let mut same = 0usize;
    for (y, a) in ys {
        let s = p.start_near(y, *a);
        let mut v = s;
        let mut d = (x[v as usize] - y).norm_squared();
        let mut n = 0usize;
        loop {
            let mut next = v;
            for &u in topo.ring(v) {
                let du = (x[u as usize] - y).norm_squared();
                if du < d {
                    (d, next) = (du, u);
                }
            }
            if next == v {
                break;
            }
            v = next;
            n += 1;
        }
        let e = p.walk(y, s);
        same += usize::from(e == v);
        walk.push(n as f64);
        cover.push((x[s as usize] - x[e as usize]).norm() / edge);
        let r = p.project_with(y, s, None, SearchGoal::FirstHit).unwrap();
        off.push(r.distance / edge);
        let target = m.triangles[r.point.face as usize];
        let mut seen = std::collections::HashMap::new();
        let mut q = std::collections::VecDeque::from([(e, 0usize)]);
        seen.insert(e, 0usize);
        let mut h = 65;
        while let Some((u, k)) = q.pop_front() {
            if target.contains(&u) {
                h = k;
                break;
            }
            if k < 64 {
                for &w in topo.ring(u) {
                    if seen.insert(w, k + 1).is_none() {
                        q.push_back((w, k + 1));
                    }
                }
            }
        }
        hops.push(h as f64);
    }
    let q = |v: &mut Vec<f64>| {
        v.sort_by(f64::total_cmp);
        let at = |f: f64| v[((v.len() - 1) as f64 * f) as usize];
        let mean = v.iter().sum::<f64>() / v.len() as f64;
        format!(
            "mean {mean:.1} p50 {:.1} p90 {:.1} p99 {:.1} max {:.1}",
            at(0.5),
            at(0.9),
            at(0.99),
            at(1.0)
        )
    };
    // Per-query times (after the pass above built whatever is built on first use).
    let mut nv = ys
        .iter()
        .map(|(y, _)| {
            let t = std::time::Instant::now();
            let u = p.nearest_vertex(y);
            (t.elapsed().as_secs_f64() * 1e6, u)
        })
        .collect::<Vec<_>>();
    let nv_mean = nv.iter().map(|t| t.0).sum::<f64>() / nv.len() as f64;
    nv.sort_by(|a, b| b.0.total_cmp(&a.0));
    println!(
        "{name}: nearest_vertex mean {nv_mean:.1} us, p90 {:.1}, p50 {:.1}",
        nv[nv.len() / 10].0,
        nv[nv.len() / 2].0
    );
    let mut times: Vec<(f64, bool)> = ys
        .iter()
        .map(|(y, a)| {
            let t = std::time::Instant::now();
            let r = p.project_with(y, p.start_near(y, *a), None, SearchGoal::FirstHit);
            let dt = t.elapsed().as_secs_f64() * 1e6;
            (
                dt,
                r.unwrap().path == wavg_project::ProjectionPath::Fallback,
            )
        })
        .collect();
    let total: f64 = times.iter().map(|t| t.0).sum();
    let fb: f64 = times.iter().filter(|t| t.1).map(|t| t.0).sum();
    let nfb = times.iter().filter(|t| t.1).count();
    times.sort_by(|a, b| b.0.total_cmp(&a.0));
    let top = |k: usize| times[..k.min(times.len())].iter().map(|t| t.0).sum::<f64>() / total;
    println!(
        "{name}: project mean {:.2} us; fallback {nfb} queries {:.1}% of the time; slowest 0.1% / 1% / 10%: {:.1}% / {:.1}% / {:.1}% of the time; slowest {:.0} us",
        total / ys.len() as f64,
        100.0 * fb / total,
        100.0 * top(ys.len() / 1000),
        100.0 * top(ys.len() / 100),
        100.0 * top(ys.len() / 10),
        times[0].0
    );
    println!("{name}: {} vertices, mean edge {edge:.3e}", m.n_vertices());
    println!("  walk steps (f64 replay): {}", q(&mut walk));
    println!("  walk end = replay's end: {same} of {}", ys.len());
    println!("  start to walk end, edges: {}", q(&mut cover));
    println!("  query off the surface, edges: {}", q(&mut off));
    println!("  hops walk end to answer face: {}", q(&mut hops));
}

/// The mean embedded edge length, over every 97th face's edges.
fn mean_embedded_edge(p: &Projector) -> f64 {
    let m = p.embedded().mesh();
    let x = p.embedded().coords();
    let (mut edge, mut ne) = (0.0, 0usize);
    for t in m.triangles.iter().step_by(97) {
        for k in 0..3 {
            edge += (x[t[k] as usize] - x[t[(k + 1) % 3] as usize]).norm();
            ne += 1;
        }
    }
    edge / ne as f64
}

/// `SLOW=1`: the slowest forward projections (first hit, from the start grid's vertex):
/// per query its time, the walk's time and end, the nearest vertex (and how far either
/// lies, in mean embedded edges), the answer's distance and whether the answer's face has
/// the walk's end or the nearest vertex as a corner, and the closest projection's distance.
fn slow(name: &str, p: &Projector, ys: &[(Vec8, u32)]) {
    let m = p.embedded().mesh();
    let x = p.embedded().coords();
    let edge = mean_embedded_edge(p);
    for (y, a) in ys {
        let _ = p.project_with(y, p.start_near(y, *a), None, SearchGoal::FirstHit);
    }
    let mut times: Vec<(f64, usize)> = ys
        .iter()
        .enumerate()
        .map(|(i, (y, a))| {
            let t = Instant::now();
            let _ = p.project_with(y, p.start_near(y, *a), None, SearchGoal::FirstHit);
            (t.elapsed().as_secs_f64() * 1e6, i)
        })
        .collect();
    times.sort_by(|a, b| b.0.total_cmp(&a.0));
    let n: usize = std::env::var("SLOW")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(40);
    println!("{name}: slowest {n} (us; distances in mean edges {edge:.3e})");
    for &(t, i) in &times[..n.min(times.len())] {
        let (y, a) = &ys[i];
        let s = p.start_near(y, *a);
        let t0 = Instant::now();
        let v = p.walk(y, s);
        let tw = t0.elapsed().as_secs_f64() * 1e6;
        let t0 = Instant::now();
        let u = p.nearest_vertex(y);
        let tn = t0.elapsed().as_secs_f64() * 1e6;
        let r = p.project_with(y, s, None, SearchGoal::FirstHit).unwrap();
        let c = p.project_with(y, s, None, SearchGoal::Closest).unwrap();
        let tri = m.triangles[r.point.face as usize];
        let d = |w: u32| (x[w as usize] - y).norm() / edge;
        println!(
            "  {t:8.1} walk {tw:6.1} nearest {tn:7.1} | v {v} d {:.2} u {u} d {:.2} |v-u| {:.1} | answer {:.3} at v {} at u {} {:?} | closest {:.3} {:?} same {}",
            d(v),
            d(u),
            (x[v as usize] - x[u as usize]).norm() / edge,
            r.distance / edge,
            tri.contains(&v),
            tri.contains(&u),
            r.path,
            c.distance / edge,
            c.path,
            c.point.face == r.point.face,
        );
    }
}
