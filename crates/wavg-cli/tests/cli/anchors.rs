//! `wavg anchors`: K distinct vertices in the anchors format; farthest-point sampling
//! covers the surface better than random draws, more anchors leave smaller gaps, and the
//! `--json` positions are the mesh's.

use crate::common;

use common::{assert_keys, json_object, s, wavg, wavg_ok};

/// The vertex ids of an anchors file, checked to be `v N` lines.
fn ids(path: &std::path::Path) -> Vec<u32> {
    std::fs::read_to_string(path)
        .unwrap()
        .lines()
        .map(|l| l.strip_prefix("v ").expect("`v VERTEX`").parse().unwrap())
        .collect()
}

/// Runs `wavg anchors builtin:torus` with `extra`; returns the ids and the JSON report.
fn anchors(
    dir: &std::path::Path,
    extra: &[&str],
) -> (Vec<u32>, serde_json::Map<String, serde_json::Value>) {
    let out = dir.join("a.txt");
    let base = ["anchors", "builtin:torus", "-o", &s(&out), "--json"];
    let (o, _) = json_object(&wavg_ok(&[&base[..], extra].concat()));
    (ids(&out), o)
}

#[test]
fn fps_anchors_are_distinct_spread_and_where_json_says() {
    let dir = tempfile::tempdir().unwrap();
    let (a, j) = anchors(dir.path(), &["--count", "30"]);
    assert_eq!(a.len(), 30);
    let mut sorted = a.clone();
    sorted.sort();
    sorted.dedup();
    assert_eq!(sorted.len(), 30, "distinct vertices");
    assert_eq!(j["method"], "fps");
    let mesh = wavg::mesh::procedural::builtin("torus").unwrap();
    for (v, item) in a.iter().zip(j["anchors"].as_array().unwrap()) {
        assert_eq!(item["vertex"], *v);
        let p = mesh.positions[*v as usize];
        let q: Vec<f64> = serde_json::from_value(item["position"].clone()).unwrap();
        let d = (q[0] - p.x).abs() + (q[1] - p.y).abs() + (q[2] - p.z).abs();
        assert!(d < 1e-12, "{q:?} vs {p:?}");
    }
    let gap = |j: &serde_json::Map<String, serde_json::Value>| j["largest_gap"].as_f64().unwrap();
    let fps30 = gap(&j);
    assert!(fps30 > 0.0 && fps30 < 0.5, "{fps30}");
    let (_, more) = anchors(dir.path(), &["--count", "60"]);
    assert!(gap(&more) < fps30, "{} vs {fps30}", gap(&more));
    let (r, random) = anchors(dir.path(), &["--count", "30", "--method", "random"]);
    assert_eq!(r.len(), 30);
    assert!(
        gap(&random) > fps30,
        "random {} vs fps {fps30}",
        gap(&random)
    );
    // The same seed, the same anchors; another seed, others.
    assert_eq!(anchors(dir.path(), &["--count", "30"]).0, a);
    assert_ne!(anchors(dir.path(), &["--count", "30", "--seed", "5"]).0, a);
}

#[test]
fn a_count_out_of_range_is_an_input_error() {
    let dir = tempfile::tempdir().unwrap();
    let out = s(&dir.path().join("a.txt"));
    for k in ["0", "100000"] {
        let r = wavg(&["anchors", "builtin:torus", "--count", k, "-o", &out]);
        assert_eq!(r.status.code(), Some(2), "--count {k}");
        assert!(!dir.path().join("a.txt").exists());
    }
}

#[test]
fn anchors_json_keys() {
    let dir = tempfile::tempdir().unwrap();
    let out = s(&dir.path().join("a.txt"));
    let keys = [
        "mesh",
        "method",
        "seed",
        "count",
        "anchors",
        "largest_gap",
        "diagonal",
    ];
    assert_keys(
        &[
            "anchors",
            "builtin:torus",
            "--count",
            "10",
            "-o",
            &out,
            "--json",
        ],
        &keys,
    );
}

/// `wavg anchors` writes exactly the library's spread for the same mesh, embedding, count
/// and seed (`wavg::Surface::spread_anchors`, `wavg::anchors::random`), and reports the
/// library's gap.
#[test]
fn the_file_is_the_library_spread() {
    let dir = tempfile::tempdir().unwrap();
    let emb = s(&dir.path().join("t.wavg"));
    wavg_ok(&[
        "precompute",
        "builtin:torus",
        "--landmarks",
        "40",
        "-o",
        &emb,
    ]);
    let mut surface =
        wavg::Surface::from_mesh(wavg::mesh::procedural::builtin("torus").unwrap()).unwrap();
    surface.load_embedding(&emb).unwrap();
    let out = dir.path().join("a.txt");
    for (count, seed, method) in [("17", "4", "fps"), ("1", "0", "fps"), ("9", "3", "random")] {
        let o = wavg_ok(&[
            "anchors",
            "builtin:torus",
            "--embedding",
            &emb,
            "--count",
            count,
            "--seed",
            seed,
            "--method",
            method,
            "-o",
            &s(&out),
            "--json",
        ]);
        let (k, seed) = (count.parse().unwrap(), seed.parse().unwrap());
        let want = match method {
            "fps" => surface.spread_anchors(k, seed).unwrap(),
            _ => wavg::anchors::random(surface.mesh(), k, seed)
                .unwrap()
                .into_iter()
                .map(wavg::Anchor::Vertex)
                .collect(),
        };
        let text = std::fs::read_to_string(&out).unwrap();
        assert_eq!(text, wavg::anchors::format(&want), "{method} {k} {seed}");
        let (j, _) = json_object(&o);
        let gap = surface.largest_gap(&ids(&out));
        assert_eq!(j["largest_gap"].as_f64().unwrap(), gap);
    }
}
