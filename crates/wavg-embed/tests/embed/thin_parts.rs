//! Thin parts (fingers, tails, tubes) keep their cross-sections: the landmark decimation
//! keeps landmarks all around a thin tube, and the embedding does not fold one side of
//! it onto the other.

use std::sync::OnceLock;

use wavg_embed::{DecimateOptions, Embedding, NoProgress, PrecomputeOptions, decimate, precompute};
use wavg_mesh::{ValidMesh, procedural};

/// A torus whose tube is 50 times thinner than its ring: 400 x 16 vertices.
const AROUND: u32 = 400;
const TUBE: u32 = 16;
const TUBE_RADIUS: f64 = 0.02;

fn thin_torus() -> ValidMesh {
    ValidMesh::new(procedural::torus(AROUND, TUBE, 1.0, TUBE_RADIUS)).unwrap()
}

/// The largest aspect ratio (longest edge squared over twice the area) of a mesh's faces.
fn worst_aspect(mesh: &wavg_mesh::TriMesh) -> f64 {
    mesh.triangles
        .iter()
        .map(|t| {
            let [a, b, c] = t.map(|v| mesh.positions[v as usize]);
            let longest = (b - a)
                .norm_squared()
                .max((c - b).norm_squared())
                .max((a - c).norm_squared());
            longest / (b - a).cross(&(c - a)).norm()
        })
        .fold(0.0, f64::max)
}

#[test]
fn the_aspect_bound_keeps_coarse_triangles_round() {
    let mesh = thin_torus();
    let quadric_only = DecimateOptions {
        target: 1000,
        ..Default::default()
    };
    let d = decimate(&mesh, &quadric_only, &NoProgress).unwrap();
    let free = worst_aspect(&d.mesh);
    let bounded = DecimateOptions {
        max_aspect_ratio: Some(5.0),
        ..quadric_only
    };
    let d = decimate(&mesh, &bounded, &NoProgress).unwrap();
    assert!(d.relaxations.is_empty(), "{:?}", d.relaxations);
    let worst = worst_aspect(&d.mesh);
    assert!(worst <= 5.0, "worst aspect ratio {worst} with the bound");
    // The premise: quadric errors alone make long triangles on this shape.
    assert!(free > 20.0, "worst aspect ratio {free} without the bound");
}

#[test]
fn no_cross_section_of_a_thin_tube_collapses() {
    let mesh = thin_torus();
    let opts = PrecomputeOptions {
        quality_pairs: 0,
        ..Default::default()
    };
    let (emb, _) = precompute(&mesh, &opts, &NoProgress).unwrap();
    let dist = |a: u32, b: u32| {
        let (p, q) = (emb.coords[a as usize], emb.coords[b as usize]);
        p.iter()
            .zip(&q)
            .map(|(x, y)| (x - y).powi(2))
            .sum::<f64>()
            .sqrt()
    };
    let chord = 2.0 * TUBE_RADIUS;
    let mut worst = f64::INFINITY;
    for i in 0..AROUND {
        for j in 0..TUBE / 2 {
            let a = i * TUBE + j;
            worst = worst.min(dist(a, a + TUBE / 2) / chord);
        }
    }
    // Opposite points of a cross-section are `chord` apart in space and farther on the
    // surface; folding the tube brings them much closer.
    assert!(
        worst > 0.5,
        "opposite points embedded {worst} x their distance apart"
    );
}

/// The slim and heavy bodies (`procedural::body`: fingers, toes, ears) with their default
/// embeddings, precomputed once for the tests that share them.
fn bodies() -> &'static [(procedural::FigureShape, Embedded); 2] {
    static BODIES: OnceLock<[(procedural::FigureShape, Embedded); 2]> = OnceLock::new();
    BODIES.get_or_init(|| {
        [
            procedural::FigureShape::SLIM,
            procedural::FigureShape::HEAVY,
        ]
        .map(|s| {
            let mesh = ValidMesh::new(procedural::body(&s)).unwrap();
            (s, Embedded::new(mesh, true))
        })
    })
}

/// The worst ratio of embedded to straight-line distance over `pairs` of body `shape`'s
/// vertices, with its pair, with or without the landmarks added around thin parts.
fn worst_pair_with(
    shape: &procedural::FigureShape,
    pairs: impl Fn(&ValidMesh) -> Vec<(usize, usize)>,
    cover_thin_parts: bool,
) -> (f64, usize, usize) {
    let body = Embedded::new(
        ValidMesh::new(procedural::body(shape)).unwrap(),
        cover_thin_parts,
    );
    body.worst(pairs(&body.mesh))
}

/// A mesh with its default embedding (without the quality check).
struct Embedded {
    mesh: ValidMesh,
    emb: Embedding,
}

impl Embedded {
    /// The default precomputation, with or without the landmarks added around thin parts.
    fn new(mesh: ValidMesh, cover_thin_parts: bool) -> Self {
        let opts = PrecomputeOptions {
            quality_pairs: 0,
            cover_thin_parts,
            ..Default::default()
        };
        let (emb, _) = precompute(&mesh, &opts, &NoProgress).unwrap();
        Self { mesh, emb }
    }

    /// The ratio of embedded to straight-line distance of vertices `a` and `b`.
    fn ratio(&self, a: usize, b: usize) -> f64 {
        let (x, y) = (self.emb.coords[a], self.emb.coords[b]);
        let e = (x.iter().zip(&y))
            .map(|(s, t)| (s - t).powi(2))
            .sum::<f64>()
            .sqrt();
        e / (self.mesh.positions[a] - self.mesh.positions[b]).norm()
    }

    /// The smallest [`Self::ratio`] over `pairs`, with its pair.
    fn worst(&self, pairs: impl IntoIterator<Item = (usize, usize)>) -> (f64, usize, usize) {
        (pairs.into_iter())
            .map(|(a, b)| (self.ratio(a, b), a, b))
            .min_by(|x, y| x.0.total_cmp(&y.0))
            .unwrap()
    }
}

/// 2,048 seeded random pairs of distinct vertices, as the exact-geodesic comparison
/// samples them (a small linear congruential generator: no dependency).
fn random_pairs(mesh: &ValidMesh) -> Vec<(usize, usize)> {
    let n = mesh.n_vertices();
    let mut s = 0x2545_f491_4f6c_dd1d_u64;
    let mut next = || {
        s = s.wrapping_mul(6_364_136_223_846_793_005).wrapping_add(1);
        (s >> 33) as usize % n
    };
    (0..2048)
        .map(|_| (next(), next()))
        .filter(|(a, b)| a != b)
        .collect()
}

/// Human-like bodies (fingers, toes, ears) embed no random pair of vertices closer than
/// half their straight-line distance (a collapsed pair: one part folded onto another).
#[test]
fn no_random_pair_of_a_body_collapses() {
    for (shape, body) in bodies() {
        let (worst, a, b) = body.worst(random_pairs(&body.mesh));
        assert!(
            worst >= 0.5,
            "{shape:?}: vertices {a} and {b} embedded {worst:.3} x their distance apart"
        );
    }
}

/// The same for every pair within 1.5 cm of each other (the cross-sections of fingers
/// and toes, 8 vertices around and 0.6-1.1 cm radius, ears beside the head). The
/// landmark spacing is about 3 cm here: without the landmarks added around thin parts
/// ([`PrecomputeOptions::cover_thin_parts`]) these cross-sections collapse to 0.003 of
/// their width.
#[test]
fn no_close_pair_of_a_body_collapses() {
    for (shape, body) in bodies() {
        let (worst, a, b) = body.worst(close_pairs(&body.mesh));
        assert!(
            worst >= 0.5,
            "{shape:?}: vertices {a} and {b} embedded {worst:.3} x their distance apart"
        );
    }
    // The premise: the landmarks of the decimation alone leave fingers and toes
    // uncovered.
    let (worst, _, _) = worst_pair_with(&procedural::FigureShape::SLIM, close_pairs, false);
    assert!(
        worst < 0.1,
        "{worst} without landmarks added around thin parts"
    );
}

/// A body once Loop-subdivided (19k vertices, more than the 10k-vertex intermediate mesh
/// of the landmark geodesics, which later rounds restart from): that mesh keeps too few
/// vertices on the toes for the landmarks they need (small parts have small quadric
/// errors and go first), and landmarks restricted to it left the toes' cross-sections at
/// 0.32 of their width (0.45 now; 0.53 once more subdivided, where they fell to 0.01).
/// The 0.5 of the bodies above is not met here yet: the check extends the landmarks' 3D
/// positions, which stay apart where the 8D embedding still squashes a little.
#[test]
fn the_toes_of_a_subdivided_body_keep_their_width() {
    let mesh = ValidMesh::new(procedural::body(&procedural::FigureShape::SLIM)).unwrap();
    let mesh = subdivided(mesh, 1);
    assert!(mesh.n_vertices() > PrecomputeOptions::default().geodesic_vertices);
    let body = Embedded::new(mesh, true);
    let p = &body.mesh.positions;
    let feet: Vec<usize> = (0..p.len()).filter(|&v| p[v].z < 0.1).collect();
    let close = (feet.iter().enumerate())
        .flat_map(|(i, &a)| feet[i + 1..].iter().map(move |&b| (a, b)))
        .filter(|&(a, b)| (p[a] - p[b]).norm() < 0.015);
    let (worst, a, b) = body.worst(close);
    assert!(
        worst >= 0.4,
        "vertices {a} and {b} embedded {worst:.3} x their distance apart"
    );
}

/// Two bodies (the lab's `collapsed_pairs body:1` and `body:4`) whose hands the 8D
/// extension between landmarks squashed (0.424 and 0.407 at worst over every pair, in
/// 13 and 26 vertices) while the landmarks' 3D extension, which decides the landmarks
/// added around thin parts, kept them whole: the check of the solved embedding adds
/// landmarks there.
#[test]
fn no_pair_of_a_body_collapses_between_its_landmarks() {
    let shapes = [
        procedural::FigureShape {
            height: 0.950621415916212,
            girth: 0.9562685962508474,
            arm_spread: 0.5982800904674275,
            elbow: 0.19739212243542,
            leg_spread: 0.085390494608598,
            finger_length: 0.09131830671043327,
            finger_radius: 0.009305440866034579,
        },
        procedural::FigureShape::SQUASHED_HANDS,
    ];
    for shape in shapes {
        let body = Embedded::new(ValidMesh::new(procedural::body(&shape)).unwrap(), true);
        let n = body.mesh.n_vertices();
        let (worst, a, b) = body.worst((0..n).flat_map(|a| (a + 1..n).map(move |b| (a, b))));
        assert!(
            worst >= 0.5,
            "{shape:?}: vertices {a} and {b} embedded {worst:.3} x their distance apart"
        );
    }
}

/// Every pair of a mesh's vertices within 1.5 cm of each other.
fn close_pairs(mesh: &ValidMesh) -> Vec<(usize, usize)> {
    let p = &mesh.positions;
    let mut pairs = Vec::new();
    for a in 0..p.len() {
        for b in a + 1..p.len() {
            if (p[a] - p[b]).norm() < 0.015 {
                pairs.push((a, b));
            }
        }
    }
    pairs
}

/// Loop subdivisions of `mesh`, `levels` times.
fn subdivided(mesh: ValidMesh, levels: usize) -> ValidMesh {
    (0..levels).fold(mesh, |m, _| {
        ValidMesh::new(wavg_mesh::subdivide::loop_subdivide(&m).unwrap()).unwrap()
    })
}

/// The landmark count of the default precomputation.
fn landmarks_used(mesh: &ValidMesh, landmarks: usize) -> usize {
    let opts = PrecomputeOptions {
        landmarks,
        quality_pairs: 0,
        ..Default::default()
    };
    precompute(mesh, &opts, &NoProgress)
        .unwrap()
        .0
        .landmarks
        .len()
}

/// Thin parts are found by the area that collapses, not by the number of faces: a thin
/// tube and its Loop subdivisions get landmarks added (up to as many again, and a few to
/// get around a vertex no collapse removes), a smooth noisy torus and its subdivisions
/// none.
#[test]
fn a_mesh_and_its_subdivisions_agree_on_thin_parts() {
    for levels in 0..=2 {
        let tube = subdivided(
            ValidMesh::new(procedural::torus(200, 12, 1.0, 0.02)).unwrap(),
            levels,
        );
        let used = landmarks_used(&tube, 60);
        assert!(
            (61..=128).contains(&used),
            "level {levels}: {used} landmarks"
        );
        let round = subdivided(
            ValidMesh::new(procedural::with_noise(
                procedural::torus(40, 20, 1.0, 0.4),
                0.2,
                3,
            ))
            .unwrap(),
            levels,
        );
        assert_eq!(landmarks_used(&round, 80), 80, "level {levels}");
    }
}

/// A scanned smooth shape (the horse, whose sharp little features shrink in a few faces)
/// and its Loop subdivision get no landmark added: the shrunken faces are about 16 times
/// as many once subdivided, their area is the same.
#[test]
fn a_smooth_scan_and_its_subdivision_get_no_landmark_added() {
    let Some(path) = wavg_testdata::require_data_file(
        "a_smooth_scan_and_its_subdivision_get_no_landmark_added",
        "meshes/horse.off.gz",
    ) else {
        return;
    };
    let horse = ValidMesh::new(wavg_mesh::io::load(&path).unwrap()).unwrap();
    assert_eq!(landmarks_used(&horse, 1000), 1000);
    assert_eq!(landmarks_used(&subdivided(horse, 1), 1000), 1000);
}
