//! A decal as an OBJ file, the format `wavg decal` writes and the page downloads: the mesh
//! with one texture coordinate per vertex, faces `f a/a b/b c/c`; a face with a marked
//! corner is written `f a b c` (no texture coordinates), so it shows untextured instead of
//! smearing the texture over the part of the surface the decal does not reach.

use std::io::{self, Write};

use wavg_mesh::TriMesh;

use crate::decal::DecalUv;

/// The material of the faces with texture coordinates.
pub const DECAL_MATERIAL: &str = "decal";
/// The material of the faces without.
pub const PLAIN_MATERIAL: &str = "plain";

/// Whether triangle `t` has a marked corner (and is written without texture coordinates).
fn untextured(uv: &DecalUv, t: &[u32; 3]) -> bool {
    t.iter().any(|&v| uv.marked[v as usize])
}

/// The number of faces written without texture coordinates.
pub fn untextured_faces(mesh: &TriMesh, uv: &DecalUv) -> usize {
    mesh.triangles.iter().filter(|t| untextured(uv, t)).count()
}

/// Writes `mesh` with the decal coordinates `uv` (one per vertex) as OBJ. With `mtllib`
/// (a material file's name) the file names it and each run of faces is preceded by
/// `usemtl` [`DECAL_MATERIAL`] or [`PLAIN_MATERIAL`].
///
/// ```
/// use wavg_apps::{DecalUv, write_decal_obj};
/// use wavg_mesh::procedural;
/// let mesh = procedural::icosphere(0);
/// let mut marked = vec![false; mesh.positions.len()];
/// marked[0] = true;
/// let uv = DecalUv { uv: vec![[0.5, 0.25]; mesh.positions.len()], marked };
/// let mut out = Vec::new();
/// write_decal_obj(&mut out, &mesh, &uv, None).unwrap();
/// let text = String::from_utf8(out).unwrap();
/// assert!(text.contains("vt 0.5 0.25\n"));
/// assert!(text.lines().any(|l| l.starts_with("f 1 "))); // vertex 1 is marked
/// ```
pub fn write_decal_obj(
    w: &mut dyn Write,
    mesh: &TriMesh,
    uv: &DecalUv,
    mtllib: Option<&str>,
) -> io::Result<()> {
    if uv.uv.len() != mesh.positions.len() || uv.marked.len() != mesh.positions.len() {
        return Err(io::Error::new(
            io::ErrorKind::InvalidInput,
            format!(
                "{} texture coordinates for {} vertices",
                uv.uv.len(),
                mesh.positions.len()
            ),
        ));
    }
    let mut line = Vec::with_capacity(96);
    let mut emit = |w: &mut dyn Write, tag: &[u8], xs: &[f64]| {
        line.clear();
        line.extend_from_slice(tag);
        wavg_io::text::push_numbers(&mut line, xs.iter().copied());
        line.push(b'\n');
        w.write_all(&line)
    };
    if let Some(m) = mtllib {
        writeln!(w, "mtllib {m}")?;
    }
    for p in &mesh.positions {
        emit(w, b"v ", &[p.x, p.y, p.z])?;
    }
    for p in &uv.uv {
        emit(w, b"vt ", p)?;
    }
    let mut current = None;
    for t in &mesh.triangles {
        let plain = untextured(uv, t);
        if mtllib.is_some() && current != Some(plain) {
            let name = if plain {
                PLAIN_MATERIAL
            } else {
                DECAL_MATERIAL
            };
            writeln!(w, "usemtl {name}")?;
            current = Some(plain);
        }
        let [a, b, c] = t.map(|v| v + 1);
        if plain {
            writeln!(w, "f {a} {b} {c}")?;
        } else {
            writeln!(w, "f {a}/{a} {b}/{b} {c}/{c}")?;
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use wavg_mesh::procedural;

    #[test]
    fn marked_corners_drop_texture_coordinates_and_materials_follow_runs() {
        let mesh = procedural::icosphere(1);
        let n = mesh.positions.len();
        let marked: Vec<bool> = (0..n).map(|v| v % 7 == 0).collect();
        let uv = DecalUv {
            uv: (0..n).map(|v| [v as f64 / n as f64, 0.5]).collect(),
            marked,
        };
        let mut out = Vec::new();
        write_decal_obj(&mut out, &mesh, &uv, Some("d.mtl")).unwrap();
        let text = String::from_utf8(out).unwrap();
        let mut lines = text.lines();
        assert_eq!(lines.next(), Some("mtllib d.mtl"));
        assert_eq!(text.lines().filter(|l| l.starts_with("v ")).count(), n);
        assert_eq!(text.lines().filter(|l| l.starts_with("vt ")).count(), n);
        let mut material = "";
        let (mut plain, mut textured) = (0, 0);
        for l in text.lines() {
            if let Some(m) = l.strip_prefix("usemtl ") {
                material = if m == PLAIN_MATERIAL {
                    "plain"
                } else {
                    "decal"
                };
            } else if let Some(f) = l.strip_prefix("f ") {
                let ids: Vec<usize> = f
                    .split(' ')
                    .map(|c| c.split('/').next().unwrap().parse::<usize>().unwrap() - 1)
                    .collect();
                let has_marked = ids.iter().any(|&v| uv.marked[v]);
                assert_eq!(f.contains('/'), !has_marked, "{l}");
                assert_eq!(material, if has_marked { "plain" } else { "decal" }, "{l}");
                if has_marked {
                    plain += 1
                } else {
                    textured += 1
                }
            }
        }
        assert_eq!(plain, untextured_faces(&mesh, &uv));
        assert_eq!(plain + textured, mesh.triangles.len());
        assert!(plain > 0 && textured > 0);
        // Without a material file: no mtllib or usemtl lines.
        let mut bare = Vec::new();
        write_decal_obj(&mut bare, &mesh, &uv, None).unwrap();
        let bare = String::from_utf8(bare).unwrap();
        assert!(!bare.contains("mtllib") && !bare.contains("usemtl"));
        assert_eq!(
            bare.lines().count(),
            text.lines().count() - 1 - (text.matches("usemtl").count())
        );
        // Coordinates that do not match the mesh are refused.
        let short = DecalUv {
            uv: vec![[0.0, 0.0]],
            marked: vec![false],
        };
        assert!(write_decal_obj(&mut Vec::new(), &mesh, &short, None).is_err());
    }
}
