//! Shared fixtures of the property tests: meshes x embeddings, projectors built once.
#![allow(dead_code)]

use std::sync::{Arc, OnceLock};

use nalgebra::{SMatrix, Vector3};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use wavg_mesh::{SurfacePoint, TriMesh, ValidMesh, procedural};
use wavg_project::{EmbeddedMesh, Projector, Vec8};

/// The embeddings every property is checked with.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Embedding {
    /// The 3-D positions, zero-padded.
    Padded,
    /// A random full-rank linear map R^3 -> R^8 (seeded).
    Linear(u64),
    /// A smooth nonlinear map R^3 -> R^8 (identity plus bounded smooth terms).
    Nonlinear,
}

pub const EMBEDDINGS: [Embedding; 3] = [
    Embedding::Padded,
    Embedding::Linear(7),
    Embedding::Nonlinear,
];

/// A random linear map R^3 -> R^8 with singular values in a sane range.
pub fn linear_map(seed: u64) -> SMatrix<f64, 8, 3> {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    loop {
        let m = SMatrix::<f64, 8, 3>::from_fn(|_, _| rng.random_range(-1.0..1.0));
        let sv = m.singular_values();
        let (lo, hi) = (sv.min(), sv.max());
        if lo > 0.3 * hi {
            return m;
        }
    }
}

/// Embeds 3-D point `p` (of a mesh with bounding box diagonal `diag`).
pub fn embed_point(e: Embedding, p: &Vector3<f64>, diag: f64) -> Vec8 {
    match e {
        Embedding::Padded => {
            let mut v = Vec8::zeros();
            v.fixed_rows_mut::<3>(0).copy_from(p);
            v
        }
        Embedding::Linear(seed) => linear_map(seed) * p,
        Embedding::Nonlinear => {
            // Normalise to unit size so the map is equally curved on every mesh.
            let q = p / diag;
            let (x, y, z) = (q.x, q.y, q.z);
            let v = Vec8::from_column_slice(&[
                x,
                y,
                z,
                0.3 * (2.0 * x).sin(),
                0.3 * (2.0 * y).cos(),
                0.4 * x * y,
                0.4 * y * z,
                0.2 * (x * x + z * z),
            ]);
            v * diag
        }
    }
}

pub fn embed(mesh: Arc<ValidMesh>, e: Embedding) -> Arc<EmbeddedMesh> {
    let diag = mesh.bounding_box_diagonal();
    let coords = mesh
        .positions
        .iter()
        .map(|p| embed_point(e, p, diag))
        .collect();
    Arc::new(EmbeddedMesh::new(mesh, coords).unwrap())
}

/// A mesh and embedding with its projector.
pub struct Fixture {
    pub name: String,
    pub embedding: Embedding,
    pub emb: Arc<EmbeddedMesh>,
    pub proj: Projector,
    pub mean_edge: f64,
}

impl Fixture {
    pub fn new(name: &str, mesh: TriMesh, e: Embedding) -> Self {
        let mesh = Arc::new(ValidMesh::new(mesh).unwrap());
        let emb = embed(mesh, e);
        let proj = Projector::new(emb.clone()).unwrap();
        let mean_edge = emb.mean_edge_length();
        Self {
            name: format!("{name}/{e:?}"),
            embedding: e,
            emb,
            proj,
            mean_edge,
        }
    }

    pub fn mesh(&self) -> &ValidMesh {
        self.emb.mesh()
    }

    /// A surface point from three uniform numbers.
    pub fn point(&self, f: f64, a: f64, b: f64) -> SurfacePoint {
        let nf = self.mesh().n_faces();
        let face = ((f * nf as f64) as usize).min(nf - 1) as u32;
        let (a, b) = if a + b > 1.0 {
            (1.0 - a, 1.0 - b)
        } else {
            (a, b)
        };
        SurfacePoint::new(face, [1.0 - a - b, a, b])
    }

    pub fn vertex(&self, u: f64) -> u32 {
        let n = self.mesh().n_vertices();
        ((u * n as f64) as usize).min(n - 1) as u32
    }

    /// Longest embedded edge of face `f`.
    pub fn face_scale(&self, f: u32) -> f64 {
        let [a, b, c] = self.emb.corners(f as usize);
        (b - a).norm().max((c - b).norm()).max((a - c).norm())
    }
}

/// The synthetic meshes: closed, genus 1, with boundary, noisy.
pub fn synthetic_meshes() -> Vec<(&'static str, TriMesh)> {
    vec![
        ("icosphere3", procedural::icosphere(3)),
        ("torus", procedural::torus(32, 14, 1.0, 0.35)),
        ("grid", procedural::grid(10, 8, 1.0, 0.8)),
        ("bumpy", procedural::bump_sphere(3, 0.15)),
        (
            "noisy",
            procedural::with_noise(procedural::icosphere(3), 0.01, 3),
        ),
        ("heightfield", heightfield(12)),
    ]
}

/// A curved open surface: `z = 0.3 sin(2x) cos(2y)` over a grid (boundary everywhere).
pub fn heightfield(n: u32) -> TriMesh {
    procedural::grid(n, n, 2.0, 2.0).map_positions(|p| Vector3::new(p.x, p.y, height(p.x, p.y)))
}

pub fn height(x: f64, y: f64) -> f64 {
    0.3 * (2.0 * x).sin() * (2.0 * y).cos()
}

/// Every synthetic mesh under every embedding (built once per test binary).
pub fn fixtures() -> &'static [Fixture] {
    static F: OnceLock<Vec<Fixture>> = OnceLock::new();
    F.get_or_init(|| {
        let mut v = Vec::new();
        for (name, m) in synthetic_meshes() {
            for e in EMBEDDINGS {
                v.push(Fixture::new(name, m.clone(), e));
            }
        }
        v
    })
}

/// A unit vector orthogonal to the rows of `psi` (random, from three-ish numbers).
pub fn normal_to(psi: &wavg_project::Mat2x8, seed: u64) -> Vec8 {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    if psi.norm() == 0.0 {
        return Vec8::from_fn(|_, _| rng.random_range(-1.0..1.0)).normalize();
    }
    let q = orthonormal_rows(psi);
    for _ in 0..1000 {
        let r = Vec8::from_fn(|_, _| rng.random_range(-1.0..1.0));
        let n = r - q.transpose() * (q * r);
        if n.norm() > 0.1 {
            return n.normalize();
        }
    }
    panic!("no normal direction found for {psi}");
}

/// Orthonormal rows spanning the same plane as `m`'s rows.
pub fn orthonormal_rows(m: &wavg_project::Mat2x8) -> wavg_project::Mat2x8 {
    let a: Vec8 = m.row(0).transpose();
    let b: Vec8 = m.row(1).transpose();
    let e1 = a.normalize();
    let e2 = (b - e1 * e1.dot(&b)).normalize();
    let mut q = wavg_project::Mat2x8::zeros();
    q.row_mut(0).copy_from(&e1.transpose());
    q.row_mut(1).copy_from(&e2.transpose());
    q
}

/// Largest principal angle between the planes spanned by the rows of `a` and `b`.
pub fn principal_angle(a: &wavg_project::Mat2x8, b: &wavg_project::Mat2x8) -> f64 {
    let (qa, qb) = (orthonormal_rows(a), orthonormal_rows(b));
    let m = qa * qb.transpose();
    let sv = m.singular_values();
    sv.min().clamp(-1.0, 1.0).acos()
}
