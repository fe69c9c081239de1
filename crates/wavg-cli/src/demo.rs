//! `wavg demo`: the whole method on one mesh, end to end, in a few seconds.
//!
//! Precomputes the 8-D embedding, places anchors by farthest-point sampling, draws a
//! closed cubic B-spline on the surface through them (forward problems, warm-started
//! along the curve), and runs inverse-then-forward round trips on random points, with the
//! paper's and the verified inverse. Optionally writes every artefact to a folder.

use std::io::Write;
use std::path::{Path, PathBuf};
use std::time::Instant;

use wavg::anchors::{GOOD_GAP, closed_tour};
use wavg::{Anchor, ForwardOptions, Solver, Surface, ValidMesh, Vec8};
use wavg_bench::{RoundTripOptions, round_trip};

use crate::CliError;
use crate::common::load_valid;
use crate::error::Context;
use crate::textio;

/// Arguments.
#[derive(clap::Args)]
#[command(after_long_help = "\
Runs the method end to end on a mesh the project generates itself (default builtin:bump,
an icosphere with a bump) or on your own: precomputes the 8-D embedding, places anchors
by farthest-point sampling in the embedding (as many as bring the largest gap between them
to 0.08 of the diagonal, reported; --anchors K for K), evaluates a closed cubic B-spline on
the surface through the first 8 of them (or all K) in the order of a short closed tour, and
runs inverse-then-forward round trips on random surface points with the paper's and the
verified inverse. Fewer than 90% of round trips leading back is a warning on stderr that
names the remedy (wavg anchors --count); `wavg spline`, `forward`, `inverse` and `bench
roundtrip` warn the same way. On builtin:bump (2,562 vertices) it takes well under a second.

With --out DIR it writes DIR/mesh.obj, DIR/mesh.wavg, DIR/anchors.txt, DIR/curve.txt
(FACE B0 B1 B2 X Y Z per sample, as `wavg forward` writes) and DIR/curve.obj (the curve
as an OBJ polyline, to view over mesh.obj), and pictures (PNG): spline.png (the curve and
anchors over the mesh), distance.png (distance in the embedding from the first anchor,
viridis), texture_source.png and texture_target.png (a checkerboard on a generated
UV-mapped sheet, carried by texture transfer onto a bent, stretched copy), remesh.png (a
cube's quads put on the surface, refined and smoothed) and decal.png (a checkerboard decal
around the first anchor). A picture whose application does not apply to the surface (for
example remeshing a cube onto a torus) is not drawn; the reason is printed and the demo
goes on.

--json prints one object: mesh, vertices, faces, landmarks, precompute_s, stress,
geodesic_rel_err_p50, geodesic_rel_err_p90, anchors, anchor_gap, spline_controls,
curve_points, curve_ok, curve_us,
roundtrip_queries, inverse_us, forward_us, roundtrip_ok_fraction,
verified_roundtrip_ok_fraction; with --out also pictures (paths written) and
skipped_pictures (\"NAME: REASON\" each).")]
pub struct Args {
    /// The mesh (default: builtin:bump).
    #[command(flatten)]
    pub mesh: crate::mesh_arg::OptionalMeshArg,
    /// Landmarks of the embedding (default: a tenth of the vertices, 50 to 1000).
    #[arg(long)]
    pub landmarks: Option<usize>,
    /// Anchors, all of them the spline's control points (default: as many as bring the
    /// largest gap between anchors to 0.08 of the diagonal, at least 8; the spline then goes
    /// through the first 8).
    #[arg(long)]
    pub anchors: Option<usize>,
    /// Samples along the spline.
    #[arg(long, default_value_t = 400, value_parser = crate::common::parse_samples)]
    pub samples: usize,
    /// Random points for the round trips.
    #[arg(long, default_value_t = 2000, value_parser = crate::common::parse_queries)]
    pub queries: usize,
    /// Seed of the anchors and the random points.
    #[arg(long, default_value_t = 0)]
    pub seed: u64,
    /// Folder to write the mesh, embedding, anchors and curve to (created if missing).
    #[arg(long)]
    pub out: Option<PathBuf>,
    /// Print one JSON object instead of the report.
    #[arg(long)]
    pub json: bool,
}

/// The `--json` object (printed through `serde_json::Value`, so keys come out sorted). A
/// selection of the reports' figures under the demo's own keys rather than the reports
/// flattened: the keys of `wavg::embed::Report`, `wavg::apps::CurveReport` and
/// `wavg_bench::RoundTripReport` are not these (`curve_points`, not `samples`;
/// `roundtrip_queries`, not `queries`; no stage times).
#[derive(serde::Serialize)]
struct JsonReport<'a> {
    mesh: &'a str,
    vertices: usize,
    faces: usize,
    landmarks: usize,
    precompute_s: f64,
    stress: f64,
    geodesic_rel_err_p50: f64,
    geodesic_rel_err_p90: f64,
    anchors: usize,
    anchor_gap: f64,
    spline_controls: usize,
    curve_points: usize,
    curve_ok: usize,
    curve_us: f64,
    roundtrip_queries: usize,
    inverse_us: f64,
    forward_us: f64,
    roundtrip_ok_fraction: f64,
    verified_roundtrip_ok_fraction: f64,
    /// With `--out`: the pictures written.
    #[serde(skip_serializing_if = "Option::is_none")]
    pictures: Option<Vec<String>>,
    /// With `--out`: the pictures not drawn, as "NAME: REASON".
    #[serde(skip_serializing_if = "Option::is_none")]
    skipped_pictures: Option<Vec<String>>,
}

/// Control points of the demo's spline when `--anchors` is not given.
const DEFAULT_CONTROLS: usize = 8;
/// The most anchors the demo chooses by itself.
const MAX_ANCHORS: usize = 400;

/// Weights (one per anchor) of `samples` points along the closed cubic B-spline whose
/// control points are the anchors in the order `order`.
fn spline_weights(order: &[usize], samples: usize) -> Result<Vec<Vec<f64>>, CliError> {
    let kind = wavg::apps::SplineKind::BSpline {
        degree: 3,
        closed: true,
    };
    let rows = wavg::apps::spline_weights(kind, order.len(), samples)?;
    Ok(rows
        .into_iter()
        .map(|row| {
            let mut w = vec![0.0; order.len()];
            for (c, x) in row.into_iter().enumerate() {
                w[order[c]] = x;
            }
            w
        })
        .collect())
}

/// Runs the command.
pub fn run(args: Args) -> Result<(), CliError> {
    if let Some(dir) = &args.out {
        crate::common::check_output_folder("--out", dir)?;
    }
    if args.anchors.is_some_and(|k| k < 4) {
        return Err(CliError::input(
            "--anchors must be at least 4 (a cubic spline)",
        ));
    }
    if args.samples == 0 || args.queries == 0 {
        return Err(CliError::input(
            "--samples and --queries must be at least 1",
        ));
    }
    let say = |s: &str| {
        if !args.json {
            eprintln!("{s}");
        }
    };
    let mesh_name = args.mesh.0.as_deref().unwrap_or("builtin:bump");
    let mesh = load_valid(mesh_name)?;
    let landmarks = args
        .landmarks
        .unwrap_or((mesh.n_vertices() / 10).clamp(50, 1000))
        .min(mesh.n_vertices());
    say(&format!(
        "mesh {}: {} vertices, {} faces; precomputing the embedding ({landmarks} landmarks)...",
        mesh_name,
        mesh.n_vertices(),
        mesh.n_faces()
    ));
    let t0 = Instant::now();
    let opts = wavg::PrecomputeOptions {
        landmarks,
        seed: args.seed,
        ..Default::default()
    };
    let (emb, _) =
        wavg::embed::precompute(&mesh, &opts, &wavg::NoProgress).context("precompute")?;
    let precompute_s = t0.elapsed().as_secs_f64();
    let surface = Surface::from_valid_with_embedding(mesh.clone(), emb.clone())?;
    let (proj, coords) = (surface.projector(), surface.embedded_coords());
    // The anchors: as many as asked, else enough for a small gap between them; the spline's
    // control points are all of them when asked for, else the first (most spread) 8.
    let (anchor_ids, gap) = match args.anchors {
        Some(k) => {
            let ids = wavg::anchors::spread(&mesh, coords, k, args.seed)?;
            let gap = wavg::anchors::largest_gap(&mesh, coords, &ids);
            (ids, gap)
        }
        None => wavg::anchors::spread_to_gap(
            &mesh,
            coords,
            args.seed,
            DEFAULT_CONTROLS,
            MAX_ANCHORS,
            GOOD_GAP,
        )?,
    };
    let controls = match args.anchors {
        Some(_) => anchor_ids.clone(),
        None => anchor_ids[..DEFAULT_CONTROLS.min(anchor_ids.len())].to_vec(),
    };
    let solver_for = |ids: &[u32]| {
        Solver::new(proj.clone(), ids.iter().map(|&v| Anchor::Vertex(v))).map_err(CliError::from)
    };
    let (solver, spline_solver) = (solver_for(&anchor_ids)?, solver_for(&controls)?);
    say(&format!(
        "anchors        {} (largest gap {gap:.3} of the diagonal{}); the spline through {}",
        anchor_ids.len(),
        if args.anchors.is_some() {
            String::new()
        } else {
            format!(", chosen to bring it to {GOOD_GAP} or less")
        },
        controls.len()
    ));

    // The spline: control points in the order of a short closed tour (any up axis).
    let tour_points: Vec<Vec8> = controls.iter().map(|&v| coords[v as usize]).collect();
    let order = closed_tour(&tour_points);
    let weights = spline_weights(&order, args.samples)?;
    let t0 = Instant::now();
    let curve =
        spline_solver.forward_batch_warm(&weights, &ForwardOptions::default(), args.samples);
    let curve_us = t0.elapsed().as_secs_f64() / args.samples as f64 * 1e6;
    let curve_ok = curve.iter().filter(|r| r.is_ok()).count();

    // Round trips: the Table 1 protocol, once, with the paper's and the verified inverse.
    let trips = round_trip(
        &solver,
        &RoundTripOptions {
            queries: args.queries,
            seed: args.seed.wrapping_add(1),
            repeat: 1,
            verified: true,
            ..Default::default()
        },
    )?;
    let (ok, vok) = (
        trips.roundtrip_ok_fraction,
        trips
            .verified
            .as_ref()
            .map_or(0.0, |v| v.verified_roundtrip_ok_fraction),
    );
    let warned = crate::anchors::warn_if_low(
        ok,
        "round trips that lead back to their point",
        anchor_ids.len(),
        mesh_name,
    );
    if !warned {
        crate::anchors::warn_if_low(
            curve_ok as f64 / args.samples as f64,
            "spline samples on the surface",
            controls.len(),
            mesh_name,
        );
    }

    let mut pictures = None;
    if let Some(dir) = &args.out {
        write_outputs(dir, &mesh, &emb, &anchor_ids, &curve)?;
        let t0 = Instant::now();
        let drawn = crate::demo_pictures::write_pictures(
            dir,
            &surface,
            &controls,
            &curve,
            &spline_solver,
            args.seed,
        )?;
        for (name, why) in &drawn.skipped {
            eprintln!("wavg demo: {name} not drawn: {why}");
        }
        pictures = Some(drawn);
        say(&format!(
            "pictures drawn in {:.2} s",
            t0.elapsed().as_secs_f64()
        ));
    }
    if args.json {
        let j = serde_json::to_value(JsonReport {
            mesh: mesh_name,
            vertices: mesh.n_vertices(),
            faces: mesh.n_faces(),
            landmarks,
            precompute_s,
            stress: emb.stress,
            geodesic_rel_err_p50: emb.geodesic_rel_err_p50,
            geodesic_rel_err_p90: emb.geodesic_rel_err_p90,
            anchors: anchor_ids.len(),
            anchor_gap: gap,
            spline_controls: controls.len(),
            curve_points: args.samples,
            curve_ok,
            curve_us,
            roundtrip_queries: trips.queries,
            inverse_us: trips.inverse_us,
            forward_us: trips.forward_us,
            roundtrip_ok_fraction: ok,
            verified_roundtrip_ok_fraction: vok,
            pictures: pictures
                .as_ref()
                .map(|p| p.written.iter().map(|p| p.display().to_string()).collect()),
            skipped_pictures: pictures.as_ref().map(|p| {
                p.skipped
                    .iter()
                    .map(|(name, why)| format!("{name}: {why}"))
                    .collect()
            }),
        })
        .map_err(CliError::failure)?;
        println!("{j}");
        return Ok(());
    }
    println!(
        "embedding      {landmarks} landmarks in {precompute_s:.2} s; stress {:.3}, geodesic \
         error p50 {:.3} p90 {:.3}",
        emb.stress, emb.geodesic_rel_err_p50, emb.geodesic_rel_err_p90
    );
    println!(
        "spline         {} control points, {curve_ok} of {} samples on the surface, {curve_us:.2} \
         us each (warm-started)",
        controls.len(),
        args.samples
    );
    println!(
        "round trips    {} random points: inverse {:.2} us, forward {:.2} us; back to the \
         point: paper {ok:.4}, verified {vok:.4}",
        trips.queries, trips.inverse_us, trips.forward_us
    );
    match &args.out {
        Some(d) => {
            println!(
                "written        {0}/mesh.obj, mesh.wavg, anchors.txt, curve.txt, curve.obj",
                d.display()
            );
            for p in pictures.iter().flat_map(|p| &p.written) {
                println!("picture        {}", p.display());
            }
            for (name, why) in pictures.iter().flat_map(|p| &p.skipped) {
                println!("not drawn      {name}: {why}");
            }
        }
        None => println!("(pass --out DIR to keep the mesh, embedding, anchors and curve)"),
    }
    Ok(())
}

/// `--out`: the mesh, embedding, anchors and curve.
fn write_outputs(
    dir: &Path,
    mesh: &ValidMesh,
    emb: &wavg::Embedding,
    anchors: &[u32],
    curve: &[Result<wavg::ForwardResult, wavg::SolveError>],
) -> Result<(), CliError> {
    std::fs::create_dir_all(dir)
        .map_err(|e| CliError::failure(format!("{}: cannot create: {e}", dir.display())))?;
    wavg::mesh::io::save(&dir.join("mesh.obj"), mesh)?;
    wavg::embed::file::save(&dir.join("mesh.wavg"), emb, mesh)?;
    textio::write_atomic(&dir.join("anchors.txt"), |w: &mut dyn Write| {
        anchors.iter().try_for_each(|v| writeln!(w, "v {v}"))
    })?;
    textio::write_atomic(&dir.join("curve.txt"), |w: &mut dyn Write| {
        w.write_all(&wavg::lines::points_text(curve))
    })?;
    textio::write_atomic(&dir.join("curve.obj"), |w: &mut dyn Write| {
        let pts: Vec<_> = curve.iter().flatten().map(|r| r.position).collect();
        for p in &pts {
            writeln!(w, "v {} {} {}", p.x, p.y, p.z)?;
        }
        if !pts.is_empty() {
            write!(w, "l")?;
            for i in (1..=pts.len()).chain([1]) {
                write!(w, " {i}")?;
            }
            writeln!(w)?;
        }
        Ok(())
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn spline_weights_sum_to_one_and_are_local() {
        let order = [3, 0, 4, 1, 5, 2];
        for w in spline_weights(&order, 97).unwrap() {
            assert!((w.iter().sum::<f64>() - 1.0).abs() < 1e-12);
            assert!(w.iter().all(|&x| x >= 0.0));
            assert!(w.iter().filter(|&&x| x > 0.0).count() <= 4);
        }
        // At a knot the curve sits at (1/6, 4/6, 1/6) of three consecutive controls.
        let w = &spline_weights(&order, 6).unwrap()[1];
        assert!((w[0] - 4.0 / 6.0).abs() < 1e-12);
        assert!((w[3] - 1.0 / 6.0).abs() < 1e-12 && (w[4] - 1.0 / 6.0).abs() < 1e-12);
    }
}
