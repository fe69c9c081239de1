//! Property tests on procedural meshes: topology invariants, the cotangent stiffness
//! matrix, and write-read round trips of every format.

use faer::sparse::SparseColMat;
use nalgebra::{Vector2, Vector3};
use proptest::prelude::*;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use wavg_mesh::{Format, io};
use wavg_mesh::{TexCoords, TriMesh, ValidMesh, analyze, geometry, procedural};

/// `y = L x` from the compressed columns (no dense copy needed).
fn mul(l: &SparseColMat<usize, f64>, x: &[f64]) -> Vec<f64> {
    let r = l.as_ref();
    let (cp, ri, val) = (r.symbolic().col_ptr(), r.symbolic().row_idx(), r.val());
    let mut y = vec![0.0; l.nrows()];
    for j in 0..l.ncols() {
        for k in cp[j]..cp[j + 1] {
            y[ri[k]] += val[k] * x[j];
        }
    }
    y
}

/// All (row, col, value) entries, duplicates summed.
fn entries(l: &SparseColMat<usize, f64>) -> std::collections::HashMap<(usize, usize), f64> {
    let r = l.as_ref();
    let (cp, ri, val) = (r.symbolic().col_ptr(), r.symbolic().row_idx(), r.val());
    let mut m = std::collections::HashMap::new();
    for j in 0..l.ncols() {
        for k in cp[j]..cp[j + 1] {
            *m.entry((ri[k], j)).or_insert(0.0) += val[k];
        }
    }
    m
}

fn check_stiffness(mesh: &TriMesh, seed: u64) -> Result<(), TestCaseError> {
    let l = geometry::cotan_stiffness(mesh).unwrap();
    let n = mesh.n_vertices();
    prop_assert_eq!((l.nrows(), l.ncols()), (n, n));
    let e = entries(&l);
    let scale = e.values().fold(0.0f64, |a, v| a.max(v.abs()));
    prop_assert!(scale.is_finite() && scale > 0.0);
    for (&(i, j), &v) in &e {
        let t = e.get(&(j, i)).copied().unwrap_or(0.0);
        prop_assert!(
            (v - t).abs() <= 1e-12 * scale,
            "asymmetric at ({}, {})",
            i,
            j
        );
        if i != j {
            // Only mesh edges couple vertices.
            prop_assert!(
                mesh.triangles
                    .iter()
                    .any(|t| t.contains(&(i as u32)) && t.contains(&(j as u32)))
            );
        }
    }
    let ones = vec![1.0; n];
    for (i, s) in mul(&l, &ones).iter().enumerate() {
        prop_assert!(s.abs() <= 1e-11 * scale, "row {} sums to {}", i, s);
    }
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    for _ in 0..8 {
        let x: Vec<f64> = (0..n).map(|_| rng.random_range(-1.0..1.0)).collect();
        let lx = mul(&l, &x);
        let q: f64 = x.iter().zip(&lx).map(|(a, b)| a * b).sum();
        let norm2: f64 = x.iter().map(|a| a * a).sum();
        prop_assert!(q >= -1e-10 * scale * norm2, "x^T L x = {}", q);
    }
    Ok(())
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(32))]

    #[test]
    fn icosphere_is_a_sphere(level in 0u32..5, noise in 0.0f64..0.3, seed: u64) {
        let m = procedural::with_noise(procedural::icosphere(level), noise, seed);
        let f = 20 * 4usize.pow(level);
        prop_assert_eq!(m.n_faces(), f);
        prop_assert_eq!(m.n_vertices(), f / 2 + 2);
        let v = ValidMesh::new(m).unwrap();
        let t = v.topology();
        prop_assert_eq!(t.euler_characteristic(), 2);
        prop_assert_eq!(t.genus(), 0);
        prop_assert!(t.boundary_loops().is_empty());
    }

    #[test]
    fn torus_has_genus_one(nu in 3u32..40, nv in 3u32..20, r in 0.1f64..0.45) {
        let m = procedural::torus(nu, nv, 1.0, r);
        prop_assert_eq!(m.n_vertices(), (nu * nv) as usize);
        let a = analyze(&m);
        prop_assert!(a.report.is_valid(), "{}", a.report);
        prop_assert_eq!(a.stats.euler_characteristic, 0);
        prop_assert_eq!(a.stats.genus, Some(1));
        prop_assert!(a.stats.watertight);
        let v = ValidMesh::new(m).unwrap();
        // Every one-ring of a torus is a closed fan.
        for i in 0..v.n_vertices() as u32 {
            prop_assert!(!v.topology().is_boundary_vertex(i));
            prop_assert_eq!(v.topology().ring(i).len(), v.topology().ring_faces(i).len());
        }
    }

    #[test]
    fn grid_is_a_disk(nx in 1u32..30, ny in 1u32..30, w in 0.1f64..10.0, h in 0.1f64..10.0) {
        let m = procedural::grid(nx, ny, w, h);
        prop_assert_eq!(m.n_vertices(), ((nx + 1) * (ny + 1)) as usize);
        prop_assert_eq!(m.n_faces(), (2 * nx * ny) as usize);
        let v = ValidMesh::new(m).unwrap();
        let t = v.topology();
        prop_assert_eq!(t.euler_characteristic(), 1);
        prop_assert_eq!(t.genus(), 0);
        prop_assert_eq!(t.boundary_loops().len(), 1);
        prop_assert_eq!(t.boundary_loops()[0].len(), (2 * (nx + ny)) as usize);
        let area: f64 = geometry::lumped_mass(&v).iter().sum();
        prop_assert!((area - w * h).abs() <= 1e-9 * w * h);
    }

    #[test]
    fn stiffness_is_symmetric_zero_row_sum_psd(which in 0u32..3, noise in 0.0f64..0.3, seed: u64) {
        let base = match which {
            0 => procedural::icosphere(2),
            1 => procedural::torus(12, 8, 1.0, 0.3),
            _ => procedural::grid(7, 5, 2.0, 1.0),
        };
        check_stiffness(&procedural::with_noise(base, noise, seed), seed)?;
    }

    /// Linear precision: on any flat triangulation, L applied to a linear function vanishes
    /// at interior vertices (the in-plane jitter keeps the grid flat but irregular).
    #[test]
    fn stiffness_reproduces_linear_functions_on_a_flat_grid(
        nx in 2u32..12, ny in 2u32..12, jitter in 0.0f64..0.3, seed: u64,
        a in -3.0f64..3.0, b in -3.0f64..3.0, c in -3.0f64..3.0,
    ) {
        let mut m = procedural::grid(nx, ny, 2.0, 1.0);
        let (hx, hy) = (2.0 / nx as f64, 1.0 / ny as f64);
        let mut rng = ChaCha8Rng::seed_from_u64(seed);
        for j in 1..ny {
            for i in 1..nx {
                let p = &mut m.positions[(j * (nx + 1) + i) as usize];
                p.x += jitter * hx * rng.random_range(-1.0..1.0);
                p.y += jitter * hy * rng.random_range(-1.0..1.0);
            }
        }
        let v = ValidMesh::new(m).unwrap();
        let l = geometry::cotan_stiffness(&v).unwrap();
        let f: Vec<f64> = v.positions.iter().map(|p| a * p.x + b * p.y + c).collect();
        let lf = mul(&l, &f);
        let mut interior = 0;
        for (i, y) in lf.iter().enumerate() {
            if !v.topology().is_boundary_vertex(i as u32) {
                interior += 1;
                prop_assert!(y.abs() < 1e-9, "vertex {}: (L f) = {}", i, y);
            }
        }
        prop_assert_eq!(interior, ((nx - 1) * (ny - 1)) as usize);
        // Not vacuous: some boundary value is non-zero for a non-constant function.
        if a.abs() + b.abs() > 0.1 {
            prop_assert!(lf.iter().any(|y| y.abs() > 1e-6));
        }
    }
}

/// A mesh with awkward floats (tiny, huge, negative zero, many digits) and per-corner UVs
/// with a seam (corners of one vertex get different UVs).
fn awkward_mesh(level: u32, seed: u64, with_uv: bool) -> TriMesh {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let mut m = procedural::with_noise(procedural::icosphere(level), 0.2, seed);
    let scale = [1.0, 1e-300, 1e300, 3.0e-7, 123456.789][rng.random_range(0..5)];
    m = m.map_positions(|p| p * scale);
    m.positions[0] = Vector3::new(-0.0, 0.1 + 0.2, 1.0 / 3.0);
    if with_uv {
        let nf = m.n_faces() as u32;
        let coords = (0..3 * nf)
            .map(|_| Vector2::new(rng.random::<f64>(), rng.random::<f64>() * 1e-5))
            .collect();
        m.uv = Some(TexCoords {
            coords,
            faces: (0..nf).map(|f| [3 * f, 3 * f + 1, 3 * f + 2]).collect(),
        });
    }
    m
}

/// Per-corner texture coordinates, whatever the indexing.
fn corner_uvs(m: &TriMesh) -> Option<Vec<Vector2<f64>>> {
    let uv = m.uv.as_ref()?;
    Some(
        uv.faces
            .iter()
            .flat_map(|t| t.map(|i| uv.coords[i as usize]))
            .collect(),
    )
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(24))]

    /// Positions come back bit-exact in every format (text formats print the shortest
    /// round-trip decimal, PLY stores doubles), faces identical, UVs per corner exact
    /// (OBJ/PLY; OFF does not store UVs).
    #[test]
    fn write_read_round_trips(level in 0u32..3, seed: u64, with_uv: bool, gz: bool, fmt in 0usize..3) {
        let m = awkward_mesh(level, seed, with_uv);
        let (format, ext) = [(Format::Obj, "obj"), (Format::Off, "off"), (Format::Ply, "ply")][fmt];
        let dir = tempfile::tempdir().unwrap();
        let name = if gz { format!("m.{ext}.gz") } else { format!("m.{ext}") };
        let path = dir.path().join(name);
        io::save(&path, &m).unwrap();
        let (back, notes) = io::load_with_notes(&path).unwrap();
        prop_assert_eq!(notes.format, Some(format));
        prop_assert_eq!(back.positions.len(), m.positions.len());
        for (p, q) in m.positions.iter().zip(&back.positions) {
            for d in 0..3 {
                prop_assert_eq!(p[d].to_bits(), q[d].to_bits());
            }
        }
        prop_assert_eq!(&back.triangles, &m.triangles);
        match format {
            Format::Off => prop_assert!(back.uv.is_none()),
            _ => prop_assert_eq!(corner_uvs(&back), corner_uvs(&m)),
        }
    }
}

#[test]
fn unknown_extension_and_missing_file_are_typed_errors() {
    let dir = tempfile::tempdir().unwrap();
    let stl = dir.path().join("a.stl");
    assert!(matches!(
        io::save(&stl, &procedural::icosphere(0)),
        Err(wavg_mesh::MeshError::Unsupported { .. })
    ));
    assert!(matches!(
        io::load(&dir.path().join("missing.off")),
        Err(wavg_mesh::MeshError::Io { .. })
    ));
    let bad_gz = dir.path().join("x.off.gz");
    std::fs::write(&bad_gz, b"not gzip").unwrap();
    assert!(matches!(
        io::load(&bad_gz),
        Err(wavg_mesh::MeshError::Parse { .. })
    ));
}

#[test]
fn empty_and_non_finite_meshes_round_trip() {
    let dir = tempfile::tempdir().unwrap();
    let mut odd = procedural::icosphere(0);
    odd.positions[0] = Vector3::new(f64::NAN, f64::INFINITY, f64::NEG_INFINITY);
    for ext in ["obj", "off", "ply", "off.gz"] {
        let path = dir.path().join(format!("e.{ext}"));
        io::save(&path, &TriMesh::default()).unwrap();
        let back = io::load(&path).unwrap();
        assert_eq!((back.n_vertices(), back.n_faces()), (0, 0), "{ext}");
        io::save(&path, &odd).unwrap();
        let back = io::load(&path).unwrap();
        let p = back.positions[0];
        assert!(
            p.x.is_nan() && p.y == f64::INFINITY && p.z == f64::NEG_INFINITY,
            "{ext}"
        );
        assert_eq!(back.positions[1..], odd.positions[1..]);
        assert_eq!(back.triangles, odd.triangles);
    }
}
