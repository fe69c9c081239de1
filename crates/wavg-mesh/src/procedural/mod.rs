//! Meshes generated in code, for tests, benchmarks and the demo (nothing is shipped as a file).

use std::collections::HashMap;
use std::f64::consts::PI;

use nalgebra::Vector3;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

use crate::error::MeshError;

mod figure;
mod plate;
mod tubes;

use crate::mesh::TriMesh;
pub use figure::{FigureShape, body, figure};
pub use plate::holed_plate;

/// Unit sphere: an icosahedron subdivided `level` times (10 * 4^level + 2 vertices).
///
/// ```
/// let m = wavg_mesh::procedural::icosphere(2);
/// assert_eq!(m.n_vertices(), 162);
/// ```
pub fn icosphere(level: u32) -> TriMesh {
    let t = (1.0 + 5f64.sqrt()) / 2.0;
    let mut pos: Vec<Vector3<f64>> = [
        [-1.0, t, 0.0],
        [1.0, t, 0.0],
        [-1.0, -t, 0.0],
        [1.0, -t, 0.0],
        [0.0, -1.0, t],
        [0.0, 1.0, t],
        [0.0, -1.0, -t],
        [0.0, 1.0, -t],
        [t, 0.0, -1.0],
        [t, 0.0, 1.0],
        [-t, 0.0, -1.0],
        [-t, 0.0, 1.0],
    ]
    .iter()
    .map(|p| Vector3::from(*p).normalize())
    .collect();
    let mut tris: Vec<[u32; 3]> = vec![
        [0, 11, 5],
        [0, 5, 1],
        [0, 1, 7],
        [0, 7, 10],
        [0, 10, 11],
        [1, 5, 9],
        [5, 11, 4],
        [11, 10, 2],
        [10, 7, 6],
        [7, 1, 8],
        [3, 9, 4],
        [3, 4, 2],
        [3, 2, 6],
        [3, 6, 8],
        [3, 8, 9],
        [4, 9, 5],
        [2, 4, 11],
        [6, 2, 10],
        [8, 6, 7],
        [9, 8, 1],
    ];
    for _ in 0..level {
        let mut mid: HashMap<(u32, u32), u32> = HashMap::new();
        let mut midpoint = |a: u32, b: u32, pos: &mut Vec<Vector3<f64>>| -> u32 {
            *mid.entry((a.min(b), a.max(b))).or_insert_with(|| {
                pos.push(((pos[a as usize] + pos[b as usize]) * 0.5).normalize());
                (pos.len() - 1) as u32
            })
        };
        let mut next = Vec::with_capacity(tris.len() * 4);
        for [a, b, c] in tris {
            let ab = midpoint(a, b, &mut pos);
            let bc = midpoint(b, c, &mut pos);
            let ca = midpoint(c, a, &mut pos);
            next.extend([[a, ab, ca], [b, bc, ab], [c, ca, bc], [ab, bc, ca]]);
        }
        tris = next;
    }
    TriMesh::new(pos, tris)
}

/// Torus around the z axis with `nu` segments around the axis and `nv` around the tube
/// (major radius `big_r`, minor radius `small_r`); genus 1.
///
/// ```
/// let m = wavg_mesh::procedural::torus(32, 16, 1.0, 0.3);
/// assert_eq!(m.n_vertices(), 512);
/// ```
pub fn torus(nu: u32, nv: u32, big_r: f64, small_r: f64) -> TriMesh {
    let (nu, nv) = (nu.max(3), nv.max(3));
    let mut pos = Vec::with_capacity((nu * nv) as usize);
    for i in 0..nu {
        let u = 2.0 * PI * i as f64 / nu as f64;
        for j in 0..nv {
            let v = 2.0 * PI * j as f64 / nv as f64;
            let r = big_r + small_r * v.cos();
            pos.push(Vector3::new(r * u.cos(), r * u.sin(), small_r * v.sin()));
        }
    }
    let id = |i: u32, j: u32| (i % nu) * nv + (j % nv);
    let mut tris = Vec::with_capacity((2 * nu * nv) as usize);
    for i in 0..nu {
        for j in 0..nv {
            let (a, b, c, d) = (id(i, j), id(i + 1, j), id(i + 1, j + 1), id(i, j + 1));
            tris.push([a, b, c]);
            tris.push([a, c, d]);
        }
    }
    TriMesh::new(pos, tris)
}

/// Flat `width` x `height` rectangle in the z = 0 plane, split into `nx` x `ny` quads of two
/// triangles each (alternating diagonals); one boundary loop.
///
/// ```
/// let m = wavg_mesh::procedural::grid(10, 5, 2.0, 1.0);
/// assert_eq!((m.n_vertices(), m.n_faces()), (66, 100));
/// ```
pub fn grid(nx: u32, ny: u32, width: f64, height: f64) -> TriMesh {
    let (nx, ny) = (nx.max(1), ny.max(1));
    let mut pos = Vec::with_capacity(((nx + 1) * (ny + 1)) as usize);
    for j in 0..=ny {
        for i in 0..=nx {
            pos.push(Vector3::new(
                width * i as f64 / nx as f64,
                height * j as f64 / ny as f64,
                0.0,
            ));
        }
    }
    let id = |i: u32, j: u32| j * (nx + 1) + i;
    let mut tris = Vec::with_capacity((2 * nx * ny) as usize);
    for j in 0..ny {
        for i in 0..nx {
            let (a, b, c, d) = (id(i, j), id(i + 1, j), id(i + 1, j + 1), id(i, j + 1));
            if (i + j) % 2 == 0 {
                tris.extend([[a, b, c], [a, c, d]]);
            } else {
                tris.extend([[a, b, d], [b, c, d]]);
            }
        }
    }
    TriMesh::new(pos, tris)
}

/// Unit icosphere with a smooth bump of the given `height` around the +z pole (the paper's
/// Figure 15: geodesics over a bump versus the embedding metric). `height = 0` is a sphere.
///
/// ```
/// let m = wavg_mesh::procedural::bump_sphere(3, 0.5);
/// let top = m.positions.iter().map(|p| p.z).fold(f64::MIN, f64::max);
/// assert!((top - 1.5).abs() < 1e-9);
/// ```
pub fn bump_sphere(level: u32, height: f64) -> TriMesh {
    icosphere(level).map_positions(|p| {
        // Angular distance from the pole; Gaussian profile of width 0.35 rad.
        let ang = p.z.clamp(-1.0, 1.0).acos();
        p * (1.0 + height * (-(ang / 0.35).powi(2)).exp())
    })
}

/// Displaces each vertex by a seeded random vector of length at most `amplitude` times the
/// mesh's mean edge length. Connectivity is unchanged.
///
/// ```
/// use wavg_mesh::procedural::{icosphere, with_noise};
/// let a = with_noise(icosphere(2), 0.1, 7);
/// let b = with_noise(icosphere(2), 0.1, 7);
/// assert_eq!(a, b);
/// ```
pub fn with_noise(mut mesh: TriMesh, amplitude: f64, seed: u64) -> TriMesh {
    let h = crate::geometry::mean_edge_length(&mesh);
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    for p in &mut mesh.positions {
        let d = Vector3::new(
            rng.random_range(-1.0..1.0),
            rng.random_range(-1.0..1.0),
            rng.random_range(-1.0..1.0),
        );
        *p += d * (amplitude * h / 3f64.sqrt());
    }
    mesh
}

/// Names accepted by [`builtin`], with a one-line description each.
pub const BUILTINS: &[(&str, &str)] = &[
    ("icosphere", "unit icosphere, 2562 vertices (level 4)"),
    ("sphere-small", "unit icosphere, 162 vertices (level 2)"),
    ("torus", "torus R=1 r=0.35, 64x24 segments, genus 1"),
    ("grid", "flat 2x1 rectangle, 40x20 quads, one boundary loop"),
    (
        "bump",
        "icosphere (level 4) with a bump of height 0.5 at +z (paper Figure 15)",
    ),
    (
        "noisy-sphere",
        "icosphere (level 4) with seeded noise of 0.2 mean edge lengths",
    ),
    (
        "genus2",
        "plate with 2 square holes, 51,390 vertices, genus 2 (spline benchmark)",
    ),
    (
        "genus12",
        "thin plate with 4x3 square holes, 7,146 vertices, genus 12, thin straps",
    ),
    (
        "ladder8",
        "very thin strip with 8 square holes, 1,650 vertices, genus 8, straps 0.02 thick (edges 0.25)",
    ),
];

/// A procedural mesh by name (see [`BUILTINS`]).
///
/// ```
/// assert_eq!(wavg_mesh::procedural::builtin("torus").unwrap().n_vertices(), 1536);
/// assert!(wavg_mesh::procedural::builtin("teapot").is_err());
/// ```
pub fn builtin(name: &str) -> Result<TriMesh, MeshError> {
    Ok(match name {
        "icosphere" => icosphere(4),
        "sphere-small" => icosphere(2),
        "torus" => torus(64, 24, 1.0, 0.35),
        "grid" => grid(40, 20, 2.0, 1.0),
        "bump" => bump_sphere(4, 0.5),
        "noisy-sphere" => with_noise(icosphere(4), 0.2, 1),
        "genus2" => holed_plate(2, 1, 44, 2.0 / 44.0),
        "genus12" => holed_plate(4, 3, 8, 0.05),
        "ladder8" => holed_plate(8, 1, 4, 0.02),
        _ => {
            let names: Vec<&str> = BUILTINS.iter().map(|b| b.0).collect();
            return Err(MeshError::InvalidArgument(format!(
                "unknown builtin mesh '{name}'; available: {}",
                names.join(", ")
            )));
        }
    })
}

/// The signed volume a closed mesh encloses (positive when its faces point outward): the
/// tests' check of orientation.
#[cfg(test)]
fn enclosed_volume(m: &TriMesh) -> f64 {
    m.triangles
        .iter()
        .map(|t| {
            let [a, b, c] = t.map(|v| m.positions[v as usize]);
            a.dot(&b.cross(&c)) / 6.0
        })
        .sum()
}
