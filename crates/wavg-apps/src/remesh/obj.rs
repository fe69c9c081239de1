//! Polygon meshes as OBJ text: the base mesh is read with its polygons kept (the mesh
//! readers of `wavg-mesh` fan-triangulate), and the refined mesh is written with them.

use std::fmt::Write;

use nalgebra::Vector3;

use super::base::{BaseMesh, RemeshError};

impl BaseMesh {
    /// Parses OBJ text: `v X Y Z [W]` lines and `f` lines of 1-based (or negative,
    /// relative) vertex indices, each optionally followed by `/vt/vn`; every other line is
    /// ignored. Faces are kept as polygons. Malformed lines are
    /// [`RemeshError::Parse`] with their 1-based number; the result is not yet validated
    /// ([`BaseMesh::validate`]).
    ///
    /// ```
    /// let b = wavg_apps::BaseMesh::from_obj_str("v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nf 1 2 3 4\n").unwrap();
    /// assert_eq!(b.faces, vec![vec![0, 1, 2, 3]]);
    /// ```
    pub fn from_obj_str(text: &str) -> Result<Self, RemeshError> {
        // A UTF-8 byte order mark opening the file (some editors write one).
        let text = text.strip_prefix('\u{feff}').unwrap_or(text);
        let mut out = BaseMesh::default();
        for (k, line) in text.lines().enumerate() {
            let bad = |message: String| RemeshError::Parse {
                line: k + 1,
                message,
            };
            let mut it = line.split_whitespace();
            match it.next() {
                Some("v") => {
                    let mut c = [0.0; 3];
                    for x in &mut c {
                        let t = it
                            .next()
                            .ok_or_else(|| bad("a vertex needs three coordinates".into()))?;
                        *x = t
                            .parse()
                            .map_err(|_| bad(format!("`{t}` is not a number")))?;
                    }
                    out.positions.push(Vector3::from(c));
                }
                Some("f") => {
                    let n = out.positions.len() as i64;
                    let mut face = Vec::new();
                    for t in it {
                        let s = t.split('/').next().unwrap_or("");
                        let i: i64 = s
                            .parse()
                            .map_err(|_| bad(format!("`{t}` is not a vertex index")))?;
                        let i = match i {
                            0 => return Err(bad("vertex index 0 (OBJ counts from 1)".into())),
                            i if i < 0 => n + i,
                            i => i - 1,
                        };
                        let i = u32::try_from(i).map_err(|_| {
                            bad(format!("vertex index `{t}` is out of range ({n} vertices)"))
                        })?;
                        face.push(i);
                    }
                    out.faces.push(face);
                }
                _ => {}
            }
        }
        Ok(out)
    }
}

/// OBJ text of a polygon mesh: one `v` line per position (shortest round-trip decimals),
/// one `f` line per polygon (1-based).
pub fn polygons_to_obj(positions: &[Vector3<f64>], faces: &[Vec<u32>]) -> String {
    let mut s = String::with_capacity(positions.len() * 60 + faces.len() * 30);
    for p in positions {
        let _ = writeln!(s, "v {} {} {}", p.x, p.y, p.z);
    }
    for f in faces {
        s.push('f');
        for &v in f {
            let _ = write!(s, " {}", v + 1);
        }
        s.push('\n');
    }
    s
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn round_trip_and_malformed_lines() {
        let text = "# c\nv 0 0 0\nv 1 0 0\nv 1 1 0.5\nv 0 1 0\nvt 0 0\nf 1/1 2/1 3/1 -1\nf 1 3 2\n";
        let b = BaseMesh::from_obj_str(text).unwrap();
        assert_eq!(b.faces, vec![vec![0, 1, 2, 3], vec![0, 2, 1]]);
        let again = BaseMesh::from_obj_str(&polygons_to_obj(&b.positions, &b.faces)).unwrap();
        assert_eq!(again, b);
        for (bad, line) in [
            ("v 0 0\n", 1),
            ("v 0 0 x\n", 1),
            ("v 0 0 0\nf 1 0 1\n", 2),
            ("v 0 0 0\nf 1 -3 1\n", 2),
            ("v 0 0 0\nf 1 a 1\n", 2),
        ] {
            match BaseMesh::from_obj_str(bad) {
                Err(RemeshError::Parse { line: l, .. }) => assert_eq!(l, line, "{bad}"),
                r => panic!("{bad}: {r:?}"),
            }
        }
    }
}
