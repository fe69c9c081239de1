//! `wavg bench project`: Phong projection speed and accuracy on random surface points.
//!
//! Protocol: build the projector (`init_s`, `bytes_per_face`); (a) project N
//! random on-surface points (uniform by area, seeded), each from a start vertex three
//! rings away, on one thread: mean time and the fraction that return to themselves
//! (same face within 1e-5 in barycentrics, or the same position within 1e-5 mean edge
//! lengths on a face sharing a vertex; times are the thread's CPU time per query, best
//! of three passes, as the machine may be shared; the queries go through
//! `Projector::project_batch`, one thread, which interleaves the walks of 8 queries;
//! the text output also shows one `project` call at a time); (b) the
//! same with the points offset from the
//! surface by 0.1 mean edge length along the face normal (with `--embedding`: a seeded
//! random direction of R^8 orthogonal to the embedded face), timed, and on the first
//! 1,000 compared with the brute-force search; (c) the fraction of each kind of query that
//! needed the global search (path `Fallback`), and the mean wall time of one global search
//! (`Projector::project_exhaustive`, the fallback alone) on those queries.

use std::collections::VecDeque;
use std::path::PathBuf;
use std::time::Instant;

use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use wavg::mesh::{SurfacePoint, ValidMesh, VertexId};
use wavg::project::{
    EmbeddedMesh, Par, ProjectScratch, Projection, ProjectionBenchReport, ProjectionPath,
    Projector, Vec8,
};

use crate::CliError;
use crate::common::load_valid;
use crate::textio;

/// Arguments.
#[derive(clap::Args)]
#[command(after_long_help = "\
Builds the projector (init_s, bytes_per_face), then (a) projects N random on-surface
points (uniform by area, seeded), each from a start vertex three rings away:
onsurface_us and onsurface_self_fraction; (b) the same points offset by 0.1 mean edge
lengths off the surface: offset_us, and on the first 1,000 the fraction equal to the
brute-force answer (offset_bruteforce_agree_fraction); (c) onsurface_fallback_fraction and
offset_fallback_fraction, the fraction of each kind of query that needed the global search
(the local search found nothing or was beaten), and fallback_us, the mean wall time of one
global search (Projector::project_exhaustive) on those queries (null when none needed it).
--json prints exactly those keys plus mesh, vertices, faces, queries.

Times are the calling thread's CPU time per query, best of three passes, on one thread
through Projector::project_batch (queries visited in spatial order, the greedy walks of 8
queries interleaved; the answers equal one Projector::project call per query, which is
checked). The table also shows the time of one project call at a time.")]
pub struct Args {
    /// Mesh file (.obj/.off/.ply, optionally .gz) or builtin:NAME.
    #[arg(long)]
    mesh: PathBuf,
    /// A .wavg embedding of the mesh (default: the 3-D positions, zero-padded).
    #[arg(long)]
    embedding: Option<PathBuf>,
    /// Number of random queries per test.
    #[arg(long, default_value_t = 100_000)]
    queries: usize,
    /// Random seed.
    #[arg(long, default_value_t = 1)]
    seed: u64,
    /// Print one JSON object instead of a table.
    #[arg(long)]
    json: bool,
}

/// Timed passes over the queries (the fastest is reported).
const REPEATS: usize = 3;
/// Points checked against the brute-force search.
const BRUTE_FORCE_CHECKS: usize = 1000;
/// Ring distance of the start vertex from the query's face.
const HINT_RINGS: usize = 3;
/// Tolerance of "the same point" (barycentrics, or mean edge lengths for positions).
const SAME: f64 = 1e-5;

/// Runs the command.
pub fn run(args: Args) -> Result<(), CliError> {
    if args.queries == 0 {
        return Err(CliError::input("--queries must be at least 1"));
    }
    let mesh = load_valid(&args.mesh.to_string_lossy())?;
    let emb = textio::load_embedded(mesh.clone(), args.embedding.as_deref())?;
    let t0 = Instant::now();
    let projector = Projector::new(emb.clone()).map_err(CliError::failure)?;
    let init_s = t0.elapsed().as_secs_f64();
    let bytes_per_face = projector.bytes() as f64 / mesh.n_faces() as f64;

    let mut rng = ChaCha8Rng::seed_from_u64(args.seed);
    let sampler = AreaSampler::new(&mesh);
    let mut hints = HintFinder::new(mesh.n_vertices());
    let points: Vec<SurfacePoint> = (0..args.queries)
        .map(|_| sampler.sample(&mut rng))
        .collect();
    let starts: Vec<VertexId> = points
        .iter()
        .map(|p| hints.find(&mesh, mesh.triangles[p.face as usize][0], &mut rng))
        .collect();
    let mean_edge = emb.mean_edge_length();

    // (a) on-surface points.
    let ys: Vec<Vec8> = points.iter().map(|p| emb.point(p)).collect();
    let (on, on_time) = timed(&projector, &ys, &starts, true);
    let (single, single_time) = timed(&projector, &ys, &starts, false);
    if single != on {
        return Err(CliError::failure(
            "project_batch and project disagree (a bug: please report it)",
        ));
    }
    let onsurface_us = on_time.cpu_us;
    let mut back = 0usize;
    for ((p, r), y) in points.iter().zip(&on).zip(&ys) {
        if let Ok(r) = r {
            if returns_to(&mesh, &emb, p, y, r, mean_edge) {
                back += 1;
            }
        }
    }
    let onsurface_self_fraction = back as f64 / points.len() as f64;

    // (b) offset points.
    let padded = args.embedding.is_none();
    let offset: Vec<Vec8> = points
        .iter()
        .zip(&ys)
        .map(|(p, y)| {
            y + offset_direction(&mesh, &emb, p.face, padded, &mut rng) * (0.1 * mean_edge)
        })
        .collect();
    let (off, off_time) = timed(&projector, &offset, &starts, true);
    let offset_us = off_time.cpu_us;
    let n_check = BRUTE_FORCE_CHECKS.min(offset.len());
    let agree = brute_force_agreement(&projector, &offset[..n_check], &off[..n_check], mean_edge);
    let offset_bruteforce_agree_fraction = agree as f64 / n_check as f64;

    // (c) the queries that needed the global search, and its cost alone on them.
    let needed: Vec<Vec8> = (ys.iter().zip(&on))
        .chain(offset.iter().zip(&off))
        .filter(|(_, r)| used_fallback(r))
        .map(|(y, _)| *y)
        .collect();
    let fraction =
        |v: &[Answer]| v.iter().filter(|r| used_fallback(r)).count() as f64 / v.len() as f64;
    let (onsurface_fallback_fraction, offset_fallback_fraction) = (fraction(&on), fraction(&off));
    let fallback_us = fallback_wall_us(&projector, &needed);

    let name = args.mesh.display().to_string();
    if args.json {
        let report = ProjectionBenchReport {
            vertices: mesh.n_vertices(),
            faces: mesh.n_faces(),
            queries: args.queries,
            init_s,
            bytes_per_face,
            onsurface_us,
            onsurface_self_fraction,
            offset_us,
            offset_bruteforce_agree_fraction,
            onsurface_fallback_fraction,
            offset_fallback_fraction,
            fallback_us,
        };
        let j = serde_json::to_value(JsonReport {
            mesh: &name,
            report,
        })
        .map_err(CliError::failure)?;
        println!("{j}");
    } else {
        let paths = |v: &[Result<Projection, _>]| {
            let mut n = [0usize; 3];
            for r in v.iter().flatten() {
                n[match r.path {
                    ProjectionPath::Certified | ProjectionPath::Local => 0,
                    ProjectionPath::Fallback => 1,
                    _ => 2,
                }] += 1;
            }
            n
        };
        let (pa, pb) = (paths(&on), paths(&off));
        println!("mesh                              {name}");
        println!(
            "vertices / faces                  {} / {}",
            mesh.n_vertices(),
            mesh.n_faces()
        );
        println!("queries                           {}", args.queries);
        println!("init_s                            {init_s:.3}");
        println!("bytes_per_face                    {bytes_per_face:.1}");
        println!(
            "onsurface_us                      {onsurface_us:.3} (thread CPU time; wall {:.3})",
            on_time.wall_us
        );
        println!(
            "  one query at a time              {:.3} (thread CPU time; wall {:.3})",
            single_time.cpu_us, single_time.wall_us
        );
        println!("onsurface_self_fraction           {onsurface_self_fraction:.6}");
        println!(
            "  paths local/fallback/none       {}/{}/{}",
            pa[0],
            pa[1],
            on.len() - pa[0] - pa[1]
        );
        println!(
            "offset_us                         {offset_us:.3} (thread CPU time; wall {:.3})",
            off_time.wall_us
        );
        println!(
            "offset_bruteforce_agree_fraction  {offset_bruteforce_agree_fraction:.6} (of {n_check})"
        );
        println!(
            "  paths local/fallback/none       {}/{}/{}",
            pb[0],
            pb[1],
            off.len() - pb[0] - pb[1]
        );
        println!(
            "fallback on/offset, fallback_us   {onsurface_fallback_fraction:.6} / {offset_fallback_fraction:.6}, {} (wall, {} calls)",
            fallback_us.map_or("-".to_string(), |t| format!("{t:.3}")),
            needed.len()
        );
    }
    Ok(())
}

/// The `--json` object: the library's [`ProjectionBenchReport`] with the mesh's name
/// (printed through `serde_json::Value`, so keys come out sorted).
#[derive(serde::Serialize)]
struct JsonReport<'a> {
    mesh: &'a str,
    #[serde(flatten)]
    report: ProjectionBenchReport,
}

type Answer = Result<Projection, wavg::project::ProjectError>;

/// Per-query times of one pass, in microseconds.
#[derive(Clone, Copy)]
struct Timing {
    /// CPU time of the measuring thread (wall time where the OS does not report it).
    cpu_us: f64,
    /// Wall-clock time.
    wall_us: f64,
}

/// Projects every query on one thread; mean microseconds per query, the best of
/// [`REPEATS`] passes. The machine may be shared, so the figure reported is the thread's
/// CPU time (time it actually ran), which other processes do not inflate; wall time is
/// shown alongside in the table.
fn timed(p: &Projector, ys: &[Vec8], starts: &[VertexId], batch: bool) -> (Vec<Answer>, Timing) {
    let mut out = Vec::with_capacity(ys.len());
    let mut scratch = ProjectScratch::default();
    let mut best = Timing {
        cpu_us: f64::INFINITY,
        wall_us: f64::INFINITY,
    };
    let n = ys.len() as f64;
    for _ in 0..REPEATS {
        out.clear();
        let c0 = crate::common::cpu_seconds(true);
        let t = Instant::now();
        if batch {
            // On this thread (`Par::Seq` never fails).
            let _ = p.project_batch_into(ys, starts, &mut scratch, &mut out, Par::Seq);
        } else {
            for (y, &s) in ys.iter().zip(starts) {
                out.push(p.project(y, s));
            }
        }
        let wall = t.elapsed().as_secs_f64();
        let cpu = match (c0, crate::common::cpu_seconds(true)) {
            (Some(a), Some(b)) => b - a,
            _ => wall,
        };
        best.cpu_us = best.cpu_us.min(cpu * 1e6 / n);
        best.wall_us = best.wall_us.min(wall * 1e6 / n);
    }
    (out, best)
}

/// Whether the query needed the global search.
fn used_fallback(r: &Answer) -> bool {
    matches!(r, Ok(p) if p.path == ProjectionPath::Fallback)
}

/// Mean wall microseconds of one global search (`project_exhaustive`) over `ys`, the best
/// of [`REPEATS`] passes; `None` for no queries.
fn fallback_wall_us(p: &Projector, ys: &[Vec8]) -> Option<f64> {
    if ys.is_empty() {
        return None;
    }
    let mut best = f64::INFINITY;
    for _ in 0..REPEATS {
        let t = Instant::now();
        for y in ys {
            // The answer itself was checked above; only the time matters here.
            let _ = std::hint::black_box(p.project_exhaustive(std::hint::black_box(y)));
        }
        best = best.min(t.elapsed().as_secs_f64() * 1e6 / ys.len() as f64);
    }
    Some(best)
}

/// Whether projection `r` of `y = e(p)` is `p` itself.
fn returns_to(
    mesh: &ValidMesh,
    emb: &EmbeddedMesh,
    p: &SurfacePoint,
    y: &Vec8,
    r: &Projection,
    mean_edge: f64,
) -> bool {
    if r.point.face == p.face {
        let d = (0..3)
            .map(|i| (r.point.bary[i] - p.bary[i]).abs())
            .fold(0.0, f64::max);
        return d <= SAME;
    }
    let (a, b) = (
        mesh.triangles[p.face as usize],
        mesh.triangles[r.point.face as usize],
    );
    a.iter().any(|v| b.contains(v)) && (emb.point(&r.point) - y).norm() <= SAME * mean_edge
}

/// Unit offset direction for face `f`: the 3-D normal (padded) or a random direction
/// orthogonal to the embedded face.
fn offset_direction(
    mesh: &ValidMesh,
    emb: &EmbeddedMesh,
    f: u32,
    padded: bool,
    rng: &mut ChaCha8Rng,
) -> Vec8 {
    if padded {
        let n = wavg::mesh::geometry::face_normal(mesh, f as usize);
        let mut v = Vec8::zeros();
        v.fixed_rows_mut::<3>(0).copy_from(&n);
        return v;
    }
    let [a, b, c] = emb.corners(f as usize);
    let e1 = (b - a).normalize();
    let e2 = {
        let w = c - a;
        (w - e1 * e1.dot(&w)).normalize()
    };
    loop {
        let r = Vec8::from_fn(|_, _| rng.random_range(-1.0..1.0));
        let n = r - e1 * e1.dot(&r) - e2 * e2.dot(&r);
        let len = n.norm();
        if len > 1e-3 && len.is_finite() {
            return n / len;
        }
    }
}

/// How many of the fast answers equal the brute-force ones (same point, or a tie in
/// distance, or both "no projection"); the brute force runs on all cores.
fn brute_force_agreement(p: &Projector, ys: &[Vec8], fast: &[Answer], mean_edge: f64) -> usize {
    let threads = std::thread::available_parallelism().map_or(1, |n| n.get());
    let chunk = ys.len().div_ceil(threads).max(1);
    std::thread::scope(|s| {
        let handles: Vec<_> = ys
            .chunks(chunk)
            .zip(fast.chunks(chunk))
            .map(|(ys, fast)| {
                s.spawn(move || {
                    ys.iter()
                        .zip(fast)
                        .filter(|(y, f)| {
                            let b = p.project_brute_force(y);
                            match (f, &b) {
                                (Err(_), Err(_)) => true,
                                (Ok(f), Ok(b)) => {
                                    let emb = p.embedded();
                                    (emb.point(&f.point) - emb.point(&b.point)).norm()
                                        <= SAME * mean_edge
                                        || (f.distance - b.distance).abs()
                                            <= 1e-9 * (b.distance + mean_edge)
                                }
                                _ => false,
                            }
                        })
                        .count()
                })
            })
            .collect();
        handles.into_iter().map(|h| h.join().unwrap_or(0)).sum()
    })
}

/// Uniform sampling of surface points by 3-D area.
struct AreaSampler {
    cumulative: Vec<f64>,
}

impl AreaSampler {
    fn new(mesh: &ValidMesh) -> Self {
        let mut s = 0.0;
        let cumulative = wavg::mesh::geometry::face_areas(mesh)
            .into_iter()
            .map(|a| {
                s += a;
                s
            })
            .collect();
        Self { cumulative }
    }

    fn sample(&self, rng: &mut ChaCha8Rng) -> SurfacePoint {
        let total = *self.cumulative.last().unwrap_or(&0.0);
        let t = rng.random_range(0.0..1.0) * total;
        let f = self
            .cumulative
            .partition_point(|&c| c <= t)
            .min(self.cumulative.len() - 1);
        let (mut u, mut v): (f64, f64) = (rng.random_range(0.0..1.0), rng.random_range(0.0..1.0));
        if u + v > 1.0 {
            (u, v) = (1.0 - u, 1.0 - v);
        }
        SurfacePoint::new(f as u32, [1.0 - u - v, u, v])
    }
}

/// Breadth-first search for a vertex `HINT_RINGS` rings away (reused stamps, no clearing).
struct HintFinder {
    stamp: Vec<u32>,
    depth: Vec<u8>,
    round: u32,
    queue: VecDeque<u32>,
    ring: Vec<u32>,
}

impl HintFinder {
    fn new(n: usize) -> Self {
        Self {
            stamp: vec![0; n],
            depth: vec![0; n],
            round: 0,
            queue: VecDeque::new(),
            ring: Vec::new(),
        }
    }

    fn find(&mut self, mesh: &ValidMesh, from: VertexId, rng: &mut ChaCha8Rng) -> VertexId {
        self.round += 1;
        self.queue.clear();
        self.ring.clear();
        let mut farthest = (0u8, from);
        self.stamp[from as usize] = self.round;
        self.depth[from as usize] = 0;
        self.queue.push_back(from);
        while let Some(v) = self.queue.pop_front() {
            let d = self.depth[v as usize];
            if d as usize == HINT_RINGS {
                self.ring.push(v);
                continue;
            }
            if d > farthest.0 {
                farthest = (d, v);
            }
            for &u in mesh.topology().ring(v) {
                if self.stamp[u as usize] != self.round {
                    self.stamp[u as usize] = self.round;
                    self.depth[u as usize] = d + 1;
                    self.queue.push_back(u);
                }
            }
        }
        if self.ring.is_empty() {
            farthest.1
        } else {
            self.ring[rng.random_range(0..self.ring.len())]
        }
    }
}
