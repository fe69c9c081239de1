//! A thin plate with a grid of square holes: a closed surface of genus `holes_x * holes_y`
//! whose handles are thin straps (one hole wide, the plate's thickness deep).

use std::collections::HashMap;

use nalgebra::Vector3;

use crate::mesh::TriMesh;

/// A `holes_x` x `holes_y` grid of square holes, each one cell of side 1 with straps one
/// cell wide between and around them, every cell split into `k` x `k` quads; the plate
/// is `thickness` thick (top and bottom faces, walls around the holes and the rim).
/// Genus `holes_x * holes_y`.
///
/// ```
/// use wavg_mesh::{analyze, procedural::holed_plate};
/// let m = holed_plate(4, 3, 3, 0.1);
/// assert_eq!(analyze(&m).stats.genus, Some(12));
/// ```
pub fn holed_plate(holes_x: u32, holes_y: u32, k: u32, thickness: f64) -> TriMesh {
    let k = k.max(1);
    let (nx, ny) = ((2 * holes_x + 1) * k, (2 * holes_y + 1) * k);
    // A fine cell is solid unless it lies in a hole (odd coarse cell in both directions).
    let solid = |i: u32, j: u32| !((i / k) % 2 == 1 && (j / k) % 2 == 1);
    let inside = |i: i64, j: i64| {
        i >= 0 && j >= 0 && i < nx as i64 && j < ny as i64 && solid(i as u32, j as u32)
    };
    let h = 1.0 / k as f64;
    let mut ids: HashMap<(u32, u32, bool), u32> = HashMap::new();
    let mut pos = Vec::new();
    let mut id = |i: u32, j: u32, top: bool| {
        *ids.entry((i, j, top)).or_insert_with(|| {
            let z = if top {
                thickness / 2.0
            } else {
                -thickness / 2.0
            };
            pos.push(Vector3::new(i as f64 * h, j as f64 * h, z));
            (pos.len() - 1) as u32
        })
    };
    let mut tris = Vec::new();
    for i in 0..nx {
        for j in 0..ny {
            if !solid(i, j) {
                continue;
            }
            let c = [(i, j), (i + 1, j), (i + 1, j + 1), (i, j + 1)];
            let t = c.map(|(a, b)| id(a, b, true));
            let b = c.map(|(a, b)| id(a, b, false));
            tris.push([t[0], t[1], t[2]]);
            tris.push([t[0], t[2], t[3]]);
            tris.push([b[0], b[2], b[1]]);
            tris.push([b[0], b[3], b[2]]);
            // Walls on the sides facing no solid cell, counter-clockwise seen from outside.
            let (ii, jj) = (i as i64, j as i64);
            let sides = [
                ((ii, jj - 1), c[0], c[1]),
                ((ii + 1, jj), c[1], c[2]),
                ((ii, jj + 1), c[2], c[3]),
                ((ii - 1, jj), c[3], c[0]),
            ];
            for ((oi, oj), p, q) in sides {
                if inside(oi, oj) {
                    continue;
                }
                let (pt, qt) = (id(p.0, p.1, true), id(q.0, q.1, true));
                let (pb, qb) = (id(p.0, p.1, false), id(q.0, q.1, false));
                tris.push([pb, qb, qt]);
                tris.push([pb, qt, pt]);
            }
        }
    }
    TriMesh::new(pos, tris)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::{ValidMesh, analyze};

    #[test]
    fn a_plate_is_closed_oriented_and_of_the_genus_of_its_holes() {
        for (hx, hy, k) in [(1, 1, 1), (4, 3, 3), (2, 5, 2)] {
            let m = holed_plate(hx, hy, k, 0.05);
            let a = analyze(&m);
            let st = a.stats;
            assert!(a.report.is_valid(), "{:?}", a.report);
            assert!(st.manifold && st.oriented && st.watertight, "{st:?}");
            assert_eq!((st.components, st.genus), (1, Some(i64::from(hx * hy))));
            let vol = super::super::enclosed_volume(&m);
            let solid = f64::from((2 * hx + 1) * (2 * hy + 1) - hx * hy);
            assert!((vol - solid * 0.05).abs() < 1e-9, "volume {vol}");
            ValidMesh::new(m).unwrap();
        }
    }
}
