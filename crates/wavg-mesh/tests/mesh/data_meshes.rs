//! Every clean mesh of the shared data set loads, validates, and matches the figures of
//! `shared/data/README.md`; same-connectivity sets really share their faces; our OBJ
//! reader agrees with tobj on clean files.

use std::path::Path;

use wavg_mesh::{ValidMesh, io};
use wavg_testdata as data;

/// A README table row: file, V, triangles after fan triangulation (README's F is the
/// polygon count for polygon meshes: spot_control 4x3 + 160x4 + 16x5 -> 372 triangles),
/// polygons, boundary loops, genus, UV.
struct Row {
    file: &'static str,
    v: usize,
    tris: usize,
    polygons: usize,
    loops: usize,
    genus: i64,
    uv: bool,
}

const fn row(
    file: &'static str,
    v: usize,
    tris: usize,
    polygons: usize,
    loops: usize,
    genus: i64,
    uv: bool,
) -> Row {
    Row {
        file,
        v,
        tris,
        polygons,
        loops,
        genus,
        uv,
    }
}

#[rustfmt::skip]
const TABLE: &[Row] = &[
    row("meshes/spot_control_mesh.obj", 188, 4 + 160 * 2 + 16 * 3, 180, 0, 0, true),
    row("meshes/decimated-knight.off", 502, 1000, 1000, 0, 0, false),
    row("meshes/3holes_uv.obj", 1987, 3982, 3982, 0, 3, true),
    row("meshes/torus.obj", 2304, 4608, 4608, 0, 1, false),
    row("meshes/spot_quadrangulated.obj", 2930, 2928 * 2, 2928, 0, 0, true),
    row("meshes/3holes.off", 3596, 7200, 7200, 0, 3, false),
    row("meshes/fertility.off", 4494, 9000, 9000, 0, 4, false),
    row("meshes/pig.off", 7502, 15000, 15000, 0, 0, false),
    row("meshes/rocker-arm.obj", 10044, 20088, 20088, 0, 1, false),
    row("meshes/sphere-noisy.obj", 10242, 20480, 20480, 0, 0, false),
    row("meshes/max-noisy.obj", 10414, 20824, 20824, 0, 0, false),
    row("meshes/camelhead.off", 11381, 22704, 22704, 1, 0, false),
    row("meshes/elephant.off", 20007, 40022, 40022, 0, 3, false),
    row("meshes/max-partial-scan.obj.gz", 31894, 63347, 63347, 1, 0, false),
    row("meshes/armadillo.obj.gz", 43243, 86482, 86482, 0, 0, false),
    row("meshes/horse.off.gz", 48485, 96966, 96966, 0, 0, false),
    row("meshes/nefertiti.obj.gz", 49971, 99938, 99938, 0, 0, false),
    row("meshes/igea.off.gz", 134345, 268686, 268686, 0, 0, false),
    row("textured/bob/bob_tri.obj", 5344, 10688, 10688, 0, 1, true),
    row("textured/spot/spot_triangulated.obj", 2930, 5856, 5856, 0, 0, true),
    row("correspondence/goast_faces/disgust.off.gz", 7118, 14037, 14037, 2, 0, false),
    row("correspondence/goast_faces/neutral.off.gz", 7118, 14037, 14037, 2, 0, false),
    row("correspondence/goast_faces/smile.off.gz", 7118, 14037, 14037, 2, 0, false),
    row("correspondence/goast_faces/surprise.off.gz", 7118, 14037, 14037, 2, 0, false),
    row("correspondence/goast_finger/finger0.off", 2046, 4088, 4088, 0, 0, false),
    row("correspondence/goast_finger/finger1.off", 2046, 4088, 4088, 0, 0, false),
    row("correspondence/goast_finger/finger_var.off", 2046, 4088, 4088, 0, 0, false),
    row("correspondence/sumner_cat/cat-01.obj.gz", 7207, 14410, 14410, 0, 0, false),
    row("correspondence/sumner_cat/cat-02.obj.gz", 7207, 14410, 14410, 0, 0, false),
    row("correspondence/sumner_cat/cat-03.obj.gz", 7207, 14410, 14410, 0, 0, false),
    row("correspondence/sumner_cat/cat-04.obj.gz", 7207, 14410, 14410, 0, 0, false),
    row("correspondence/sumner_cat/cat-05.obj.gz", 7207, 14410, 14410, 0, 0, false),
    row("correspondence/sumner_cat/cat-06.obj.gz", 7207, 14410, 14410, 0, 0, false),
    row("correspondence/sumner_cat/cat-07.obj.gz", 7207, 14410, 14410, 0, 0, false),
    row("correspondence/sumner_cat/cat-08.obj.gz", 7207, 14410, 14410, 0, 0, false),
    row("correspondence/sumner_cat/cat-09.obj.gz", 7207, 14410, 14410, 0, 0, false),
    row("correspondence/sumner_cat/cat-reference.obj.gz", 7207, 14410, 14410, 0, 0, false),
    row("correspondence/sumner_horse/horse-01.obj.gz", 8431, 16843, 16843, 2, 0, false),
    row("correspondence/sumner_horse/horse-02.obj.gz", 8431, 16843, 16843, 2, 0, false),
    row("correspondence/sumner_horse/horse-03.obj.gz", 8431, 16843, 16843, 2, 0, false),
    row("correspondence/sumner_horse/horse-04.obj.gz", 8431, 16843, 16843, 2, 0, false),
    row("correspondence/sumner_horse/horse-05.obj.gz", 8431, 16843, 16843, 2, 0, false),
    row("correspondence/sumner_horse/horse-06.obj.gz", 8431, 16843, 16843, 2, 0, false),
    row("correspondence/sumner_horse/horse-07.obj.gz", 8431, 16843, 16843, 2, 0, false),
    row("correspondence/sumner_horse/horse-08.obj.gz", 8431, 16843, 16843, 2, 0, false),
    row("correspondence/sumner_horse/horse-09.obj.gz", 8431, 16843, 16843, 2, 0, false),
    row("correspondence/sumner_horse/horse-10.obj.gz", 8431, 16843, 16843, 2, 0, false),
    row("correspondence/sumner_horse/horse-reference.obj.gz", 8431, 16843, 16843, 2, 0, false),
    row("correspondence/sumner_lion/lion-01.obj.gz", 5000, 9996, 9996, 0, 0, false),
    row("correspondence/sumner_lion/lion-02.obj.gz", 5000, 9996, 9996, 0, 0, false),
    row("correspondence/sumner_lion/lion-03.obj.gz", 5000, 9996, 9996, 0, 0, false),
    row("correspondence/sumner_lion/lion-04.obj.gz", 5000, 9996, 9996, 0, 0, false),
    row("correspondence/sumner_lion/lion-05.obj.gz", 5000, 9996, 9996, 0, 0, false),
    row("correspondence/sumner_lion/lion-06.obj.gz", 5000, 9996, 9996, 0, 0, false),
    row("correspondence/sumner_lion/lion-07.obj.gz", 5000, 9996, 9996, 0, 0, false),
    row("correspondence/sumner_lion/lion-08.obj.gz", 5000, 9996, 9996, 0, 0, false),
    row("correspondence/sumner_lion/lion-09.obj.gz", 5000, 9996, 9996, 0, 0, false),
    row("correspondence/sumner_lion/lion-reference.obj.gz", 5000, 9996, 9996, 0, 0, false),
];

fn is_mesh_file(p: &Path) -> bool {
    let n = p.to_string_lossy();
    [".obj", ".off", ".ply", ".obj.gz", ".off.gz", ".ply.gz"]
        .iter()
        .any(|e| n.ends_with(e))
}

fn mesh_files(dir: &Path, out: &mut Vec<String>, root: &Path) {
    let mut entries: Vec<_> = std::fs::read_dir(dir).unwrap().flatten().collect();
    entries.sort_by_key(|e| e.path());
    for e in entries {
        let p = e.path();
        if p.is_dir() {
            mesh_files(&p, out, root);
        } else if is_mesh_file(&p) {
            out.push(p.strip_prefix(root).unwrap().to_string_lossy().into_owned());
        }
    }
}

#[test]
fn every_clean_mesh_matches_the_readme_table() {
    let Some(root) = data::require_data_dir("every_clean_mesh_matches_the_readme_table") else {
        return;
    };
    // Every mesh file present is in the table (a new file must get expectations).
    let mut present = Vec::new();
    for d in ["meshes", "textured", "correspondence"] {
        mesh_files(&root.join(d), &mut present, &root);
    }
    for f in &present {
        assert!(
            TABLE.iter().any(|r| r.file == f),
            "{f} is not in the expected table"
        );
    }
    for r in TABLE {
        let path = root.join(r.file);
        let (mesh, notes) =
            io::load_with_notes(&path).unwrap_or_else(|e| panic!("{}: {e}", r.file));
        assert_eq!(notes.polygons, r.polygons, "{}: polygons", r.file);
        assert_eq!(mesh.uv.is_some(), r.uv, "{}: uv", r.file);
        let v = ValidMesh::new(mesh).unwrap_or_else(|e| panic!("{}: {e}", r.file));
        let t = v.topology();
        assert_eq!(v.n_vertices(), r.v, "{}: vertices", r.file);
        assert_eq!(v.n_faces(), r.tris, "{}: triangles", r.file);
        assert_eq!(
            t.boundary_loops().len(),
            r.loops,
            "{}: boundary loops",
            r.file
        );
        assert_eq!(t.genus(), r.genus, "{}: genus", r.file);
        assert_eq!(t.n_components(), 1, "{}: components", r.file);
        assert_eq!(v.stats().watertight, r.loops == 0, "{}: watertight", r.file);
    }
}

#[test]
fn same_connectivity_sets_share_faces() {
    let Some(root) = data::require_data_dir("same_connectivity_sets_share_faces") else {
        return;
    };
    for set in [
        "correspondence/sumner_cat",
        "correspondence/sumner_lion",
        "correspondence/sumner_horse",
        "correspondence/goast_faces",
        "correspondence/goast_finger",
    ] {
        let mut files = Vec::new();
        mesh_files(&root.join(set), &mut files, &root);
        assert!(files.len() >= 3, "{set}: {files:?}");
        let first = io::load(&root.join(&files[0])).unwrap();
        let mut moved = false;
        for f in &files[1..] {
            let m = io::load(&root.join(f)).unwrap();
            assert_eq!(m.n_vertices(), first.n_vertices(), "{f}");
            assert_eq!(
                m.triangles, first.triangles,
                "{f}: faces differ from {}",
                files[0]
            );
            moved |= m.positions != first.positions;
        }
        assert!(moved, "{set}: every pose has the same positions");
    }
}

/// Our reader keeps the file's global vertex indices; tobj re-indexes per object in order
/// of first use. On clean files the corners of each triangle must still be the same
/// points (tobj stores f32) and carry the same texture coordinates.
#[test]
fn obj_reader_agrees_with_tobj() {
    for file in [
        "meshes/torus.obj",
        "meshes/spot_control_mesh.obj",
        "textured/spot/spot_triangulated.obj",
        "bad/trimesh_negative_indices.obj",
    ] {
        let Some(path) = data::require_data_file("obj_reader_agrees_with_tobj", file) else {
            return;
        };
        let ours = io::load(&path).unwrap();
        let opts = tobj::LoadOptions {
            triangulate: true,
            single_index: false,
            ..Default::default()
        };
        let (models, _) = tobj::load_obj(&path, &opts).unwrap();
        let mut f = 0usize;
        for m in &models {
            let mesh = &m.mesh;
            assert_eq!(mesh.indices.len() % 3, 0);
            for (k, tri) in mesh.indices.chunks(3).enumerate() {
                let [a, b, c] = ours.corners(f);
                for (j, p) in [a, b, c].iter().enumerate() {
                    let i = tri[j] as usize;
                    let q = [
                        mesh.positions[3 * i],
                        mesh.positions[3 * i + 1],
                        mesh.positions[3 * i + 2],
                    ];
                    for d in 0..3 {
                        assert!(
                            (p[d] - q[d] as f64).abs() <= 1e-6 * (1.0 + p[d].abs()),
                            "{file}: face {f} corner {j}"
                        );
                    }
                    if let Some(uv) = &ours.uv {
                        let ti = mesh.texcoord_indices[3 * k + j] as usize;
                        let ouv = uv.coords[uv.faces[f][j] as usize];
                        assert!((ouv.x - mesh.texcoords[2 * ti] as f64).abs() < 1e-6);
                        assert!((ouv.y - mesh.texcoords[2 * ti + 1] as f64).abs() < 1e-6);
                    }
                }
                f += 1;
            }
        }
        assert_eq!(f, ours.n_faces(), "{file}: triangle count");
    }
}
