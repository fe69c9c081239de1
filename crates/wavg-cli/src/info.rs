//! `wavg info`: a diagnostic for users' meshes. Prints counts, topology and every
//! validation problem (count plus first offending indices). Any file that parses is
//! described (exit 0), valid or not; a file that cannot be read or parsed exits with
//! status 2 and a one-line message naming the file and line.

use serde_json::{Value, json};
use wavg_mesh::{Analysis, ProblemKind, TriMesh, analyze, procedural, repair};
use wavg_mesh::{LoadNotes, io};

use crate::CliError;
use crate::common::one_line;

/// Arguments.
#[derive(clap::Args)]
#[command(group(clap::ArgGroup::new("source").required(true).args(["mesh", "builtin"])))]
pub struct Args {
    /// Mesh file: .obj, .off or .ply, optionally gzip-compressed (.gz).
    pub mesh: Option<String>,
    /// Describe a procedural mesh instead of a file (icosphere, sphere-small, torus, grid,
    /// bump, noisy-sphere).
    #[arg(long, value_name = "NAME")]
    pub builtin: Option<String>,
    /// Print one JSON object instead of text.
    #[arg(long)]
    pub json: bool,
}

/// Runs the command.
pub fn run(args: Args) -> Result<(), CliError> {
    let (name, mesh, notes) = match (&args.mesh, &args.builtin) {
        (_, Some(b)) => {
            let m = procedural::builtin(b).map_err(CliError::input)?;
            (format!("builtin:{b}"), m, None)
        }
        (Some(path), None) => {
            let (m, n) = io::load_with_notes(std::path::Path::new(path))
                .map_err(|e| CliError::input(one_line(&e)))?;
            (path.clone(), m, Some(n))
        }
        (None, None) => return Err(CliError::input("give a mesh file or --builtin NAME")),
    };
    let a = analyze(&mesh);
    if args.json {
        println!("{}", to_json(&name, &mesh, notes.as_ref(), &a));
    } else {
        print!("{}", to_text(&name, &mesh, notes.as_ref(), &a));
    }
    Ok(())
}

fn yes_no(b: bool) -> &'static str {
    if b { "yes" } else { "no" }
}

/// The human-readable report.
pub fn to_text(name: &str, mesh: &TriMesh, notes: Option<&LoadNotes>, a: &Analysis) -> String {
    use std::fmt::Write;
    let s = &a.stats;
    let mut o = String::new();
    let _ = writeln!(o, "mesh:                 {name}");
    let _ = writeln!(o, "vertices:             {}", s.vertices);
    let _ = write!(o, "faces:                {} triangles", s.faces);
    if let Some(n) = notes.filter(|n| n.non_triangles > 0 || n.skipped_faces > 0) {
        let _ = write!(
            o,
            " (from {} polygons: {} fan-triangulated, {} with < 3 corners skipped)",
            n.polygons, n.non_triangles, n.skipped_faces
        );
    }
    let _ = writeln!(o);
    let _ = writeln!(o, "edges:                {}", s.edges);
    let _ = writeln!(o, "components:           {}", s.components);
    let _ = writeln!(o, "boundary loops:       {}", s.boundary_loops);
    let _ = writeln!(o, "euler characteristic: {}", s.euler_characteristic);
    let genus = s
        .genus
        .map_or("undefined (not an oriented manifold)".to_string(), |g| {
            g.to_string()
        });
    let _ = writeln!(o, "genus:                {genus}");
    let _ = writeln!(o, "manifold:             {}", yes_no(s.manifold));
    let _ = writeln!(o, "oriented:             {}", yes_no(s.oriented));
    let _ = writeln!(o, "watertight:           {}", yes_no(s.watertight));
    let uv = match (&mesh.uv, notes.is_some_and(|n| n.uv_dropped)) {
        (Some(uv), _) => format!("yes ({} coordinates)", uv.coords.len()),
        (None, true) => "dropped (only some faces had them)".to_string(),
        (None, false) => "no".to_string(),
    };
    let _ = writeln!(o, "texture coordinates:  {uv}");
    if let Some((lo, hi)) = mesh.bounding_box() {
        let _ = writeln!(
            o,
            "bounding box:         [{:.6}, {:.6}, {:.6}] .. [{:.6}, {:.6}, {:.6}] (diagonal {:.6})",
            lo.x,
            lo.y,
            lo.z,
            hi.x,
            hi.y,
            hi.z,
            (hi - lo).norm()
        );
    }
    if a.report.is_valid() {
        let _ = writeln!(
            o,
            "valid:                yes (oriented manifold, usable by wavg)"
        );
    } else {
        let _ = writeln!(
            o,
            "valid:                no ({} problems)",
            a.report.problems.len()
        );
        let _ = writeln!(o, "problems:");
        for line in a.report.lines() {
            let _ = writeln!(o, "  - {line}");
        }
        let r = repair_outcome(mesh);
        if r.remaining.is_empty() {
            let added = if r.added_vertices > 0 {
                format!(", splits off {} vertex copies", r.added_vertices)
            } else {
                String::new()
            };
            let _ = writeln!(
                o,
                "repair:               `wavg repair` fixes every problem \
                 (removes {} vertices, {} faces{added})",
                r.removed_vertices, r.removed_faces
            );
        } else {
            let hint = if r.components > 1 {
                " (try --largest-component)"
            } else {
                ""
            };
            let _ = writeln!(
                o,
                "repair:               `wavg repair` leaves: {}{hint}",
                r.remaining.join("; ")
            );
        }
    }
    o
}

/// What the default repairs would do to an invalid mesh (tried, not guessed: a duplicate
/// face also makes non-manifold edges that disappear with it).
struct RepairOutcome {
    removed_vertices: usize,
    /// Copies made by splitting non-manifold vertices.
    added_vertices: usize,
    removed_faces: usize,
    /// Connected components after repair.
    components: usize,
    /// Problem lines left after repair (empty: the repaired mesh is valid).
    remaining: Vec<String>,
}

fn repair_outcome(mesh: &TriMesh) -> RepairOutcome {
    let r = repair::repair_all(mesh, &wavg_mesh::RepairOptions::default());
    let after = analyze(&r.mesh);
    RepairOutcome {
        removed_vertices: r.removed_vertices(),
        added_vertices: r.added_vertices(),
        removed_faces: r.removed_faces(mesh.n_faces()),
        components: after.stats.components,
        remaining: after
            .report
            .summary()
            .iter()
            .map(|s| format!("{} {}", s.count, s.kind.describe()))
            .collect(),
    }
}

/// The `--json` object.
pub fn to_json(name: &str, mesh: &TriMesh, notes: Option<&LoadNotes>, a: &Analysis) -> Value {
    let s = &a.stats;
    let summary: Vec<Value> = a
        .report
        .summary()
        .iter()
        .map(|p| {
            json!({
                "kind": kind_key(p.kind),
                "description": p.kind.describe(),
                "count": p.count,
                "examples": p.examples.iter().map(|e| e.to_string()).collect::<Vec<_>>(),
                "remedy": p.kind.remedy(),
            })
        })
        .collect();
    let bbox = mesh.bounding_box().map(|(lo, hi)| {
        json!({
            "min": [lo.x, lo.y, lo.z],
            "max": [hi.x, hi.y, hi.z],
            "diagonal": (hi - lo).norm(),
        })
    });
    let repair = (!a.report.is_valid()).then(|| {
        let r = repair_outcome(mesh);
        json!({
            "fixes_all": r.remaining.is_empty(),
            "removed_vertices": r.removed_vertices,
            "added_vertices": r.added_vertices,
            "removed_faces": r.removed_faces,
            "remaining_problems": r.remaining,
        })
    });
    json!({
        "mesh": name,
        "vertices": s.vertices,
        "faces": s.faces,
        "polygons": notes.map_or(s.faces, |n| n.polygons),
        "skipped_faces": notes.map_or(0, |n| n.skipped_faces),
        "uv_dropped": notes.is_some_and(|n| n.uv_dropped),
        "edges": s.edges,
        "components": s.components,
        "boundary_loops": s.boundary_loops,
        "euler_characteristic": s.euler_characteristic,
        "genus": s.genus,
        "manifold": s.manifold,
        "oriented": s.oriented,
        "watertight": s.watertight,
        "valid": a.report.is_valid(),
        "uv": mesh.uv.is_some(),
        "bounding_box": bbox,
        "problems": a.report.lines(),
        "problem_summary": summary,
        "repair": repair,
    })
}

/// Stable snake_case key of a problem kind for JSON consumers.
fn kind_key(k: ProblemKind) -> &'static str {
    match k {
        ProblemKind::Empty => "empty",
        ProblemKind::IndexOutOfRange => "index_out_of_range",
        ProblemKind::NonFiniteCoordinate => "non_finite_coordinate",
        ProblemKind::RepeatedIndex => "repeated_index",
        ProblemKind::ZeroAreaFace => "zero_area_face",
        ProblemKind::DuplicateFace => "duplicate_face",
        ProblemKind::NonManifoldEdge => "non_manifold_edge",
        ProblemKind::NonManifoldVertex => "non_manifold_vertex",
        ProblemKind::InconsistentOrientation => "inconsistent_orientation",
        ProblemKind::UnreferencedVertex => "unreferenced_vertex",
        ProblemKind::InvalidTexCoords => "invalid_tex_coords",
    }
}
