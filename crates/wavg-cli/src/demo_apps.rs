//! The remeshing and decal pictures of `wavg demo --out DIR`: a cube's six quads put on the
//! demo surface and refined with smoothing, and a checkerboard decal placed around one
//! anchor through the inverse problem.

use wavg::Vector3;
use wavg::apps::{BaseMesh, Colouring, Image, Overlays, Remesher, RenderOptions};
use wavg::mesh::geometry;
use wavg::{Anchor, Solver};
use wavg::{TexCoords, TriMesh};

use crate::CliError;

/// Remeshing levels and smoothing steps of the picture.
const LEVELS: usize = 3;
const SMOOTH: usize = 5;

/// Anchors of the decal on a ring around its centre.
const RING: usize = 8;

/// The surface with the remeshed cube's quads drawn over it.
pub fn remesh_picture(solver: &Solver, opts: &RenderOptions) -> Result<Image, CliError> {
    let fail = |e: &dyn std::fmt::Display| CliError::failure(format!("demo remesh: {e}"));
    let mesh = solver.mesh().mesh();
    let (lo, hi) = mesh.bounding_box().ok_or_else(|| fail(&"empty mesh"))?;
    let (c, half) = ((lo + hi) / 2.0, (hi - lo) / 2.0);
    // A cube whose corners lie near a sphere through the surface's extent, each moved to
    // the surface's vertex nearest to it (the base mesh must lie on the surface).
    let s = half / 3f64.sqrt();
    let positions = (0..8)
        .map(|i| {
            let sign = |bit: u32| if i & bit != 0 { 1.0 } else { -1.0 };
            let corner = c + Vector3::new(sign(1) * s.x, sign(2) * s.y, sign(4) * s.z);
            let d = |p: &&Vector3<f64>| (*p - corner).norm_squared();
            *mesh
                .positions
                .iter()
                .min_by(|a, b| d(a).total_cmp(&d(b)))
                .unwrap_or(&corner)
        })
        .collect();
    let faces = [
        [0, 4, 6, 2],
        [1, 3, 7, 5],
        [0, 1, 5, 4],
        [2, 6, 7, 3],
        [0, 2, 3, 1],
        [4, 5, 7, 6],
    ]
    .iter()
    .map(|f| f.to_vec())
    .collect();
    let base = BaseMesh { positions, faces };
    let mut remesher = Remesher::new(solver.projector().clone(), &base).map_err(|e| fail(&e))?;
    let r = remesher.remesh(LEVELS, SMOOTH).map_err(|e| fail(&e))?;
    let curves = r
        .faces
        .iter()
        .map(|f| {
            let mut loop_: Vec<Vector3<f64>> = f.iter().map(|&v| r.positions[v as usize]).collect();
            loop_.push(loop_[0]);
            loop_
        })
        .collect();
    let ov = Overlays {
        curves,
        points: Vec::new(),
        ..Default::default()
    };
    wavg::apps::render(mesh, &Colouring::Plain, &ov, opts).map_err(|e| fail(&e))
}

/// The surface with a checkerboard decal around vertex `centre`: a ring of anchors at a
/// fifth of the bounding-box diagonal gets (u, v) from the tangent plane at the centre,
/// every vertex its (u, v) from the inverse problem; faces with a vertex whose weights are
/// not meaningful, and the surface outside the square, stay plain.
pub fn decal_picture(
    solver: &Solver,
    centre: u32,
    checker: &Image,
    opts: &RenderOptions,
) -> Result<Image, CliError> {
    let fail = |e: &dyn std::fmt::Display| CliError::failure(format!("demo decal: {e}"));
    let mesh = solver.mesh().mesh();
    let p0 = mesh.positions[centre as usize];
    let n = geometry::vertex_normals(mesh)[centre as usize];
    let t1 = n
        .cross(&Vector3::x())
        .try_normalize(1e-9)
        .unwrap_or_else(|| n.cross(&Vector3::y()).normalize());
    let t2 = n.cross(&t1);
    let r = 0.2 * mesh.bounding_box_diagonal();
    let plane = |p: Vector3<f64>| [(p - p0).dot(&t1), (p - p0).dot(&t2)];
    // The ring: for each of RING directions, the vertex near radius r closest to it.
    let mut anchors = vec![centre];
    for k in 0..RING {
        let a = std::f64::consts::TAU * k as f64 / RING as f64;
        let dir = [a.cos(), a.sin()];
        let best = (0..mesh.n_vertices() as u32)
            .filter(|&v| (mesh.positions[v as usize] - p0).dot(&n) > -0.5 * r)
            .min_by(|&a, &b| {
                let miss = |v: u32| {
                    let q = plane(mesh.positions[v as usize]);
                    (q[0] - r * dir[0]).powi(2) + (q[1] - r * dir[1]).powi(2)
                };
                miss(a).total_cmp(&miss(b))
            })
            .ok_or_else(|| fail(&"no ring vertex"))?;
        if !anchors.contains(&best) {
            anchors.push(best);
        }
    }
    let uv: Vec<[f64; 2]> = anchors
        .iter()
        .map(|&v| {
            let q = plane(mesh.positions[v as usize]);
            [0.5 + q[0] / (2.5 * r), 0.5 + q[1] / (2.5 * r)]
        })
        .collect();
    let decal_solver = Solver::new(
        solver.projector().clone(),
        anchors.iter().map(|&v| Anchor::Vertex(v)),
    )
    .map_err(|e| fail(&e))?;
    let d = wavg::apps::decal_vertices(&decal_solver, &uv, -0.1).map_err(|e| fail(&e))?;
    // Faces with a marked corner sample one extra coordinate outside the square (the
    // board's transparent border, which renders plain), so the decal ends at whole faces.
    let outside = d.uv.uv.len() as u32;
    let mut coords: Vec<_> = d.uv.uv.iter().map(|&[u, v]| [u, v].into()).collect();
    coords.push([-1.0, -1.0].into());
    let faces = mesh
        .triangles
        .iter()
        .map(|t| {
            if t.iter().any(|&v| d.uv.marked[v as usize]) {
                [outside; 3]
            } else {
                *t
            }
        })
        .collect();
    let textured = TriMesh {
        uv: Some(TexCoords { coords, faces }),
        ..mesh.clone()
    };
    let ov = Overlays {
        curves: Vec::new(),
        points: anchors
            .iter()
            .map(|&v| mesh.positions[v as usize])
            .collect(),
        ..Default::default()
    };
    wavg::apps::render(&textured, &Colouring::Texture(checker), &ov, opts).map_err(|e| fail(&e))
}
