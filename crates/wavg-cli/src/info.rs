//! `wavg info`: a diagnostic for users' meshes. Prints counts, topology and every
//! validation problem (count plus first offending indices). Any file that parses is
//! described (exit 0), valid or not; a file that cannot be read or parsed exits with
//! status 2 and a one-line message naming the file and line.

use wavg::LoadNotes;
use wavg::mesh::io;
use wavg::mesh::{analyze, procedural};
use wavg::{MeshInfo, TriMesh};

use crate::CliError;

/// Arguments.
#[derive(clap::Args)]
#[command(group(clap::ArgGroup::new("source").required(true).args(["mesh", "mesh_flag", "builtin"])))]
#[command(after_long_help = "\
Counts, topology and every validation problem (counts and the first offending indices), and
whether `wavg repair` would fix them. Succeeds for any file it can parse, valid or not.

--json prints one object with at least vertices, faces, components, boundary_loops, genus
(null for an invalid mesh), manifold (bool), problems (list of strings), plus edges,
euler_characteristic, oriented, watertight, valid, uv, bounding_box, problem_summary,
welded_vertices (glTF: vertex copies merged by position), skipped_primitives,
repair and out_of_range: null, or why the embedding and the solvers would refuse this
valid mesh's size (docs/limits.md), with the remedy. Validity is judged by shape whatever
the scale; an invalid mesh gets null (repair it first).")]
pub struct Args {
    /// Mesh file: .obj, .off or .ply, optionally gzip-compressed (.gz), .gltf or .glb
    /// (SCENE.glb#NAME: one mesh), or builtin:NAME (as the other commands take it).
    pub mesh: Option<String>,
    /// The same as the positional MESH.
    #[arg(long = "mesh", value_name = "MESH")]
    pub mesh_flag: Option<String>,
    /// Describe a procedural mesh instead of a file (the names: `wavg --help`).
    #[arg(long, value_name = "NAME")]
    pub builtin: Option<String>,
    /// Print one JSON object instead of text.
    #[arg(long)]
    pub json: bool,
}

/// Runs the command.
pub fn run(mut args: Args) -> Result<(), CliError> {
    args.mesh = args.mesh.or(args.mesh_flag.take());
    let builtin = args.builtin.as_deref().or_else(|| {
        args.mesh
            .as_deref()
            .and_then(|m| m.strip_prefix(crate::common::BUILTIN_PREFIX))
    });
    let (name, mesh, notes) = match (&args.mesh, builtin) {
        (_, Some(b)) => {
            let m = procedural::builtin(b)?;
            (format!("builtin:{b}"), m, None)
        }
        (Some(path), None) => {
            let (m, n) = io::load_with_notes(std::path::Path::new(path))?;
            (path.clone(), m, Some(n))
        }
        (None, None) => return Err(CliError::input("give a mesh file or --builtin NAME")),
    };
    let info = MeshInfo::new(&mesh, notes.as_ref(), &analyze(&mesh));
    if args.json {
        let j = serde_json::to_value(JsonReport {
            mesh: &name,
            info: &info,
        })
        .map_err(CliError::failure)?;
        println!("{j}");
    } else {
        print!("{}", to_text(&name, &mesh, notes.as_ref(), &info));
    }
    Ok(())
}

/// The `--json` object: the mesh's [`MeshInfo`] with its name (printed through
/// `serde_json::Value`, so keys come out sorted).
#[derive(serde::Serialize)]
struct JsonReport<'a> {
    mesh: &'a str,
    #[serde(flatten)]
    info: &'a MeshInfo,
}

fn yes_no(b: bool) -> &'static str {
    if b { "yes" } else { "no" }
}

/// A coordinate with six decimals, in scientific notation where that would print more
/// than 16 digits before the point or only zeros.
fn coordinate(x: f64) -> String {
    if x == 0.0 || !x.is_finite() || (1e-4..1e15).contains(&x.abs()) {
        format!("{x:.6}")
    } else {
        format!("{x:.6e}")
    }
}

/// The human-readable report.
pub fn to_text(name: &str, mesh: &TriMesh, notes: Option<&LoadNotes>, s: &MeshInfo) -> String {
    use std::fmt::Write;
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
    if s.welded_vertices > 0 {
        let _ = writeln!(
            o,
            "welded:               {} vertex copies merged by position (the file splits \
             vertices at UV seams and sharp edges)",
            s.welded_vertices
        );
    }
    if s.skipped_primitives > 0 {
        let _ = writeln!(
            o,
            "skipped:              {} primitives of points or lines",
            s.skipped_primitives
        );
    }
    let _ = writeln!(o, "edges:                {}", s.edges);
    let _ = writeln!(o, "components:           {}", s.components);
    let _ = writeln!(o, "boundary loops:       {}", s.boundary_loops);
    let _ = writeln!(o, "euler characteristic: {}", s.euler_characteristic);
    let genus = s
        .genus
        .map_or("undefined (not a valid mesh)".to_string(), |g| {
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
    if let Some(b) = &s.bounding_box {
        let [x0, y0, z0, x1, y1, z1, d] = [
            b.min[0], b.min[1], b.min[2], b.max[0], b.max[1], b.max[2], b.diagonal,
        ]
        .map(coordinate);
        let _ = writeln!(
            o,
            "bounding box:         [{x0}, {y0}, {z0}] .. [{x1}, {y1}, {z1}] (diagonal {d})"
        );
    }
    if let Some(why) = &s.out_of_range {
        let _ = writeln!(o, "note:                 {why}");
    }
    if s.valid && s.out_of_range.is_some() {
        let _ = writeln!(
            o,
            "valid:                yes (oriented manifold), but out of range for wavg (see the \
             note)"
        );
    } else if s.valid && s.components > 1 {
        let _ = writeln!(
            o,
            "valid:                yes (oriented manifold); precompute, anchors and the \
             solvers need one component: `wavg repair MESH -o OUT --largest-component`"
        );
    } else if s.valid {
        let _ = writeln!(
            o,
            "valid:                yes (oriented manifold, usable by wavg)"
        );
    } else {
        let _ = writeln!(
            o,
            "valid:                no ({} problems)",
            s.problem_summary.iter().map(|p| p.count).sum::<usize>()
        );
        let _ = writeln!(o, "problems:");
        for line in &s.problems {
            let _ = writeln!(o, "  - {line}");
        }
        // Present for every invalid mesh.
        if let Some(r) = &s.repair {
            if r.fixes_all {
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
                    r.remaining_problems.join("; ")
                );
            }
        }
    }
    o
}

#[cfg(test)]
mod tests {
    use wavg::DefectKind;

    /// The `kind` keys of `problem_summary` are a contract with JSON consumers.
    #[test]
    fn problem_kinds_serialise_to_their_stable_keys() {
        let keys = [
            (DefectKind::Empty, "empty"),
            (DefectKind::IndexOutOfRange, "index_out_of_range"),
            (DefectKind::NonFiniteCoordinate, "non_finite_coordinate"),
            (DefectKind::RepeatedIndex, "repeated_index"),
            (DefectKind::ZeroAreaFace, "zero_area_face"),
            (DefectKind::DuplicateFace, "duplicate_face"),
            (DefectKind::NonManifoldEdge, "non_manifold_edge"),
            (DefectKind::NonManifoldVertex, "non_manifold_vertex"),
            (
                DefectKind::InconsistentOrientation,
                "inconsistent_orientation",
            ),
            (DefectKind::UnreferencedVertex, "unreferenced_vertex"),
            (DefectKind::InvalidTexCoords, "invalid_tex_coords"),
        ];
        for (kind, key) in keys {
            assert_eq!(serde_json::to_value(kind).unwrap(), key);
        }
    }
}
