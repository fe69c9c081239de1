//! `wavg anchors`: K well-spread anchors of a mesh, written in the anchors format, so no
//! application needs a hand-written anchors file.

use std::io::Write;
use std::path::PathBuf;

use rand::SeedableRng;
use wavg::sampling::{FpsMetric, farthest_point_vertices};
use wavg::{ValidMesh, Vec8, VertexId};

use crate::CliError;
use crate::common::load_valid;
use crate::textio;

/// How the anchors are chosen.
#[derive(clap::ValueEnum, Clone, Copy, Debug, PartialEq, Eq)]
pub enum Method {
    /// Farthest-point sampling in the embedding: each next anchor is the vertex farthest
    /// from those already chosen.
    Fps,
    /// K distinct vertices drawn at random (uniformly) from --seed.
    Random,
}

/// Arguments.
#[derive(clap::Args)]
#[command(after_long_help = "\
Chooses --count vertices as anchors and writes them as `v VERTEX` lines (the anchors
format). By default they are spread by farthest-point sampling in the embedding (the
first vertex drawn from --seed, each next one the vertex farthest from those chosen), which
covers the surface evenly; --method random draws them uniformly at random. The embedding is
--embedding's, else the embedding cache's (computed on first use).

Being vertex ids, the file serves every mesh with the same connectivity (other poses of a
character): give it as both --source-anchors and --target-anchors to carry a texture or a
morph between them.

--json prints one object: mesh, method, seed, count, anchors (each vertex and position
[x, y, z]), largest_gap (the largest distance in the embedding from a vertex to its
nearest anchor, as a fraction of the bounding-box diagonal; 0.08 or less keeps
about 90% of round trips on real meshes) and diagonal.

The text report gives that largest gap and suggests a count when it is above 0.08: measured
on pig, armadillo and elephant, a gap of 0.08 or less keeps 92-99% of round trips (3,000
random points; armadillo: 8 anchors, gap 0.31, 53%; 93 anchors, gap 0.076, 95%).")]
pub struct Args {
    #[command(flatten)]
    pub mesh: crate::mesh_arg::MeshArg,
    /// Number of anchors K (at least 1, at most the vertex count).
    #[arg(long)]
    pub count: usize,
    /// How to choose them.
    #[arg(long, value_enum, default_value_t = Method::Fps)]
    pub method: Method,
    /// Seed of the first (fps) or of every (random) anchor.
    #[arg(long, default_value_t = 0)]
    pub seed: u64,
    /// A .wavg embedding of the mesh (default: the embedding cache's, computed on first
    /// use).
    #[arg(long)]
    pub embedding: Option<PathBuf>,
    #[command(flatten)]
    pub cache: crate::cache::CacheArg,
    /// Output anchors file (`-` for standard output).
    #[arg(short = 'o', long = "output")]
    pub output: PathBuf,
    /// Print one JSON object on standard output.
    #[arg(long)]
    pub json: bool,
}

/// The `--json` object.
#[derive(serde::Serialize)]
struct JsonReport<'a> {
    mesh: &'a str,
    method: &'a str,
    seed: u64,
    count: usize,
    anchors: Vec<JsonAnchor>,
    largest_gap: f64,
    diagonal: f64,
}

#[derive(serde::Serialize)]
struct JsonAnchor {
    vertex: VertexId,
    position: [f64; 3],
}

/// Runs the command.
pub fn run(args: Args) -> Result<(), CliError> {
    crate::common::check_outputs(
        &crate::common::inputs([std::path::Path::new(&*args.mesh)], [&args.embedding]),
        &[("-o", &args.output)],
        args.json,
    )?;
    let mesh = load_valid(&args.mesh)?;
    if args.count == 0 || args.count > mesh.n_vertices() {
        return Err(CliError::input(format!(
            "--count {} must be from 1 to the mesh's {} vertices",
            args.count,
            mesh.n_vertices()
        )));
    }
    let coords = embedded_coords(&mesh, &args)?;
    let anchors = match args.method {
        Method::Fps => {
            farthest_point_vertices(&mesh, args.count, args.seed, FpsMetric::Embedding(&coords))?
        }
        Method::Random => {
            let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(args.seed);
            rand::seq::index::sample(&mut rng, mesh.n_vertices(), args.count)
                .into_iter()
                .map(|v| v as VertexId)
                .collect()
        }
    };
    textio::write_atomic(&args.output, |w: &mut dyn Write| {
        for v in &anchors {
            writeln!(w, "v {v}")?;
        }
        Ok(())
    })?;
    let diagonal = mesh.bounding_box_diagonal();
    let gap = largest_gap(&coords, &anchors) / diagonal.max(f64::MIN_POSITIVE);
    if args.json {
        let list = anchors
            .iter()
            .map(|&v| {
                let p = mesh.positions[v as usize];
                JsonAnchor {
                    vertex: v,
                    position: [p.x, p.y, p.z],
                }
            })
            .collect();
        let method = match args.method {
            Method::Fps => "fps",
            Method::Random => "random",
        };
        let j = serde_json::to_value(JsonReport {
            mesh: &args.mesh,
            method,
            seed: args.seed,
            count: anchors.len(),
            anchors: list,
            largest_gap: gap,
            diagonal,
        })
        .map_err(CliError::failure)?;
        println!("{j}");
    } else if args.output != std::path::Path::new("-") {
        let mut line = format!(
            "{} anchors, largest gap {:.3} of the diagonal -> {}",
            anchors.len(),
            gap,
            args.output.display()
        );
        if gap > GOOD_GAP {
            line.push_str(&format!(
                " (above {GOOD_GAP}: round trips may fail; try --count {})",
                suggested_count(anchors.len(), gap)
            ));
        }
        println!("{line}");
    }
    Ok(())
}

/// Below this fraction of answers that succeed, a command warns.
pub const LOW_FRACTION: f64 = 0.9;

/// Says on stderr, when `fraction` (of round trips that lead back, or of answers that
/// exist) is below [`LOW_FRACTION`], what it is, the likely cause (too few anchors for
/// `mesh`) and the remedy (`wavg anchors --count`). Returns whether it warned.
pub fn warn_if_low(fraction: f64, what: &str, anchors: usize, mesh: &str) -> bool {
    if fraction.is_nan() || fraction >= LOW_FRACTION {
        return false;
    }
    eprintln!(
        "wavg: warning: {what}: {:.1}%, below {:.0}%. The likely cause: {anchors} anchors \
         are too few for this mesh (large gaps between them). The remedy: more anchors, \
         e.g. `wavg anchors {mesh} --count {} -o anchors.txt`.",
        fraction * 100.0,
        LOW_FRACTION * 100.0,
        (2 * anchors).max(32)
    );
    true
}

/// The largest gap (fraction of the diagonal) below which round trips are reliable.
pub const GOOD_GAP: f64 = 0.08;

/// A count that should bring a `gap` found with `count` anchors to [`GOOD_GAP`]: on a
/// surface the gap shrinks like one over the square root of the count.
pub fn suggested_count(count: usize, gap: f64) -> usize {
    let ratio = gap / GOOD_GAP;
    ((count as f64 * ratio * ratio).ceil() as usize).max(count + 1)
}

/// The embedding's coordinates: `--embedding`'s file or the cache's.
fn embedded_coords(mesh: &std::sync::Arc<ValidMesh>, args: &Args) -> Result<Vec<Vec8>, CliError> {
    let e = match &args.embedding {
        Some(p) => wavg::embed::file::load(p, mesh)?,
        None => crate::cache::embedding(mesh, &args.mesh, args.cache.no_cache)?,
    };
    Ok(e.coords.iter().map(|c| Vec8::from(*c)).collect())
}

/// Farthest-point sampling in the embedding (the same order as `--method fps` with this
/// seed) until the largest gap is at most [`GOOD_GAP`] of `diagonal`, with `min` to `max`
/// anchors. Returns the anchors and the gap reached (a fraction of the diagonal).
pub fn spread_to_good_gap(
    mesh: &ValidMesh,
    coords: &[Vec8],
    seed: u64,
    min: usize,
    max: usize,
) -> Result<(Vec<VertexId>, f64), CliError> {
    let max = max.min(mesh.n_vertices()).max(1);
    let first = farthest_point_vertices(mesh, 1, seed, FpsMetric::Embedding(coords))?[0];
    let diagonal = mesh.bounding_box_diagonal().max(f64::MIN_POSITIVE);
    let mut dist = vec![f64::INFINITY; coords.len()];
    let (mut out, mut next) = (Vec::new(), first);
    loop {
        out.push(next);
        let y = coords[next as usize];
        for (d, x) in dist.iter_mut().zip(coords) {
            *d = d.min((x - y).norm());
        }
        let mut best = 0usize;
        for (v, &d) in dist.iter().enumerate() {
            if d > dist[best] {
                best = v;
            }
        }
        let gap = dist[best] / diagonal;
        if out.len() >= max || (out.len() >= min && gap <= GOOD_GAP) {
            return Ok((out, gap));
        }
        next = best as VertexId;
    }
}

/// An order of `points` as a short closed tour (nearest neighbour, then 2-opt until no
/// swap shortens it): control points of a closed spline in that order make a loop without
/// crossings, whichever way the mesh is oriented.
pub fn closed_tour(points: &[Vec8]) -> Vec<usize> {
    let n = points.len();
    let d = |a: usize, b: usize| (points[a] - points[b]).norm();
    let mut tour = vec![0usize];
    let mut left: Vec<usize> = (1..n).collect();
    while !left.is_empty() {
        let last = tour[tour.len() - 1];
        let (i, _) = left
            .iter()
            .enumerate()
            .min_by(|a, b| d(last, *a.1).total_cmp(&d(last, *b.1)))
            .expect("not empty");
        tour.push(left.swap_remove(i));
    }
    let mut improved = n > 3;
    while improved {
        improved = false;
        for i in 0..n - 1 {
            for j in i + 2..n {
                let (a, b, c, e) = (tour[i], tour[i + 1], tour[j], tour[(j + 1) % n]);
                if a != e && d(a, c) + d(b, e) < d(a, b) + d(c, e) - 1e-12 {
                    tour[i + 1..=j].reverse();
                    improved = true;
                }
            }
        }
    }
    tour
}

/// The largest distance from a vertex to its nearest anchor, in the embedding.
pub fn largest_gap(coords: &[Vec8], anchors: &[VertexId]) -> f64 {
    let mut dist = vec![f64::INFINITY; coords.len()];
    for &a in anchors {
        let y = coords[a as usize];
        for (d, x) in dist.iter_mut().zip(coords) {
            *d = d.min((x - y).norm());
        }
    }
    dist.into_iter().fold(0.0, f64::max)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn tour_of_a_scrambled_circle_goes_round_it() {
        let angles = [0.0, 3.0, 1.0, 5.0, 2.0, 4.0, 6.0, 7.0];
        let pts: Vec<Vec8> = angles
            .iter()
            .map(|&k: &f64| {
                let t = k * std::f64::consts::TAU / 8.0;
                let mut v = Vec8::zeros();
                (v[1], v[2]) = (t.cos(), t.sin()); // a y-up circle
                v
            })
            .collect();
        let tour = closed_tour(&pts);
        let steps: Vec<f64> = (0..8)
            .map(|i| (pts[tour[i]] - pts[tour[(i + 1) % 8]]).norm())
            .collect();
        let side = 2.0 * (std::f64::consts::PI / 8.0).sin();
        assert!(steps.iter().all(|s| (s - side).abs() < 1e-9), "{steps:?}");
    }

    #[test]
    fn gap_is_the_covering_radius() {
        let c: Vec<Vec8> = (0..5)
            .map(|i| {
                let mut v = Vec8::zeros();
                v[0] = i as f64;
                v
            })
            .collect();
        assert_eq!(largest_gap(&c, &[0]), 4.0);
        assert_eq!(largest_gap(&c, &[0, 4]), 2.0);
        assert_eq!(largest_gap(&c, &[0, 2, 4]), 1.0);
        assert_eq!(suggested_count(8, 0.16), 32);
        assert_eq!(suggested_count(8, 0.08), 9);
    }
}
