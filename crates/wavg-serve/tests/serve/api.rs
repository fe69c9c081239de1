//! Every route over real HTTP, against the library's own answers.

use crate::common;

use common::{get, post, server, surface};
use serde_json::{Value, json};
use wavg::apps::{SplineKind, decal_vertices, evaluate_spline};
use wavg::{Anchor, ForwardOptions, SurfacePoint};

fn close(a: &Value, b: f64) {
    let a = a.as_f64().unwrap();
    assert!((a - b).abs() <= 1e-12 * (1.0 + b.abs()), "{a} vs {b}");
}

/// A returned point against a forward result.
fn same_point(v: &Value, r: &wavg::ForwardResult) {
    let a = v.as_array().unwrap();
    assert_eq!(a.len(), 7);
    assert_eq!(a[0].as_u64().unwrap(), u64::from(r.point.face));
    for k in 0..3 {
        close(&a[1 + k], r.point.bary[k]);
        close(&a[4 + k], r.position[k]);
    }
}

#[test]
fn info_and_the_binary_mesh_describe_the_mesh() {
    let s = surface();
    let info = get("/api/info");
    assert_eq!(info.status, 200);
    let j = info.json();
    assert_eq!(j["vertices"], s.n_vertices());
    assert_eq!(j["faces"], s.n_faces());
    let (lo, hi) = s.mesh().bounding_box().unwrap();
    close(&j["bounding_box"][0][2], lo.z);
    close(&j["bounding_box"][1][0], hi.x);
    let mesh = get("/api/mesh");
    assert_eq!(mesh.status, 200);
    assert_eq!(
        mesh.header("content-type"),
        Some("application/octet-stream")
    );
    assert_eq!(mesh.body, wavg_serve::encode_mesh(s.mesh()));
    assert_eq!(get("/api/status").json()["state"], "ready");
}

#[test]
fn forward_matches_the_solver_and_marks_missing_averages_null() {
    let s = surface();
    let solver = s.solver([0u32, 200, 400, 600]).unwrap();
    let weights = [[0.25, 0.25, 0.25, 0.25], [0.7, 0.1, 0.1, 0.1]];
    let a = post(
        "/api/forward",
        &json!({"anchors": [0, 200, 400, 600], "weights": weights}),
    );
    assert_eq!(a.status, 200, "{}", String::from_utf8_lossy(&a.body));
    assert!(
        a.header("server-timing")
            .unwrap()
            .starts_with("compute;dur=")
    );
    let pts = a.json()["points"].clone();
    for (w, p) in weights.iter().zip(pts.as_array().unwrap()) {
        let r = solver.forward(w, &ForwardOptions::default()).unwrap();
        same_point(p, &r);
    }
    // Normalised weights give the same point as their normalised form.
    let b = post(
        "/api/forward",
        &json!({"anchors": [0, 200, 400, 600], "weights": [[7, 1, 1, 1]], "normalize": true}),
    );
    let r = solver
        .forward(&[0.7, 0.1, 0.1, 0.1], &ForwardOptions::default())
        .unwrap();
    let q = &b.json()["points"][0];
    for k in 0..3 {
        assert!((q[4 + k].as_f64().unwrap() - r.position[k]).abs() < 1e-9);
    }
}

#[test]
fn inverse_matches_the_solver_plain_and_verified() {
    let s = surface();
    let anchors = [0u32, 120, 240, 360, 480, 600];
    let solver = s.solver(anchors).unwrap();
    let p = SurfacePoint::new(77, [0.2, 0.3, 0.5]);
    for verified in [false, true] {
        let a = post(
            "/api/inverse",
            &json!({"anchors": anchors, "points": [[77, 0.2, 0.3, 0.5], 5], "verified": verified}),
        );
        assert_eq!(a.status, 200, "{}", String::from_utf8_lossy(&a.body));
        let w = a.json()["weights"].clone();
        let want = if verified {
            solver
                .inverse_verified(&p, wavg::DEFAULT_TOLERANCE)
                .unwrap()
                .weights
        } else {
            solver.inverse(&p).unwrap()
        };
        for (x, y) in w[0].as_array().unwrap().iter().zip(&want) {
            close(x, *y);
        }
        // A vertex given by id is that vertex's point.
        let v5 = s.vertex_point(5).unwrap();
        let want5 = if verified {
            solver
                .inverse_verified(&v5, wavg::DEFAULT_TOLERANCE)
                .unwrap()
                .weights
        } else {
            solver.inverse(&v5).unwrap()
        };
        for (x, y) in w[1].as_array().unwrap().iter().zip(&want5) {
            close(x, *y);
        }
    }
}

#[test]
fn spline_gives_the_samples_of_evaluate_spline_in_json_and_text() {
    let s = surface();
    let control = json!([0, [100, 0.2, 0.3, 0.5], 400, 600, 750]);
    let anchors = [
        Anchor::Vertex(0),
        Anchor::Point(SurfacePoint::new(100, [0.2, 0.3, 0.5])),
        Anchor::Vertex(400),
        Anchor::Vertex(600),
        Anchor::Vertex(750),
    ];
    let solver = s.solver(anchors).unwrap();
    for (body, kind) in [
        (
            json!({"control": control, "samples": 300}),
            SplineKind::BSpline {
                degree: 3,
                closed: false,
            },
        ),
        (
            json!({"control": control, "samples": 300, "closed": true, "degree": 2}),
            SplineKind::BSpline {
                degree: 2,
                closed: true,
            },
        ),
        (
            json!({"control": control, "samples": 300, "bezier": true}),
            SplineKind::Bezier,
        ),
    ] {
        let curve = evaluate_spline(&solver, kind, 300, 256).unwrap();
        let a = post("/api/spline", &body);
        assert_eq!(a.status, 200, "{}", String::from_utf8_lossy(&a.body));
        let j = a.json();
        let pts = j["points"].as_array().unwrap();
        assert_eq!(pts.len(), 300);
        for (p, r) in pts.iter().zip(&curve.samples) {
            match r {
                Ok(r) => same_point(p, r),
                Err(_) => assert!(p.is_null()),
            }
        }
        close(&j["length"], curve.length());
        // The text format: one `FACE B0 B1 B2 X Y Z` line per sample, the same numbers.
        let mut body = body.clone();
        body["format"] = json!("text");
        let t = post("/api/spline", &body);
        assert!(t.header("content-type").unwrap().starts_with("text/plain"));
        let text = String::from_utf8(t.body).unwrap();
        assert_eq!(text.lines().count(), 300);
        for (line, p) in text.lines().zip(pts) {
            let nums: Vec<f64> = line.split(' ').map(|x| x.parse().unwrap()).collect();
            for (k, x) in nums.iter().enumerate() {
                close(&p[k], *x);
            }
        }
    }
}

#[test]
fn spline_numbers_are_the_library_values_exactly_and_timed() {
    let s = surface();
    let control = json!([[100, 0.2, 0.3, 0.5], 400, 600, [700, 0.125, 0.625, 0.25]]);
    let anchors = [
        Anchor::Point(SurfacePoint::new(100, [0.2, 0.3, 0.5])),
        Anchor::Vertex(400),
        Anchor::Vertex(600),
        Anchor::Point(SurfacePoint::new(700, [0.125, 0.625, 0.25])),
    ];
    let curve = evaluate_spline(
        &s.solver(anchors).unwrap(),
        SplineKind::BSpline {
            degree: 3,
            closed: false,
        },
        400,
        256,
    )
    .unwrap();
    let a = post("/api/spline", &json!({"control": control, "samples": 400}));
    assert_eq!(a.status, 200);
    // Server-Timing: the computation, then the whole request; both durations in ms.
    let timing = a.header("server-timing").unwrap().to_owned();
    let durs: Vec<f64> = timing
        .split(", ")
        .zip(["compute;dur=", "total;dur="])
        .map(|(part, name)| part.strip_prefix(name).unwrap().parse().unwrap())
        .collect();
    assert!(
        durs.len() == 2 && durs[0] >= 0.0 && durs[1] >= durs[0],
        "{timing}"
    );
    let j = a.json();
    let pts = j["points"].as_array().unwrap();
    assert_eq!(pts.len(), 400);
    for (p, r) in pts.iter().zip(&curve.samples) {
        let r = r.as_ref().unwrap();
        let want = [r.point.bary[0], r.point.bary[1], r.point.bary[2]]
            .into_iter()
            .chain(r.position.iter().copied());
        assert_eq!(p[0].as_u64(), Some(u64::from(r.point.face)));
        for (k, w) in want.enumerate() {
            assert_eq!(p[1 + k].as_f64().unwrap().to_bits(), w.to_bits(), "{p}");
        }
    }
    assert_eq!(
        j["length"].as_f64().unwrap().to_bits(),
        curve.length().to_bits()
    );
}

#[test]
fn distance_is_the_embedding_distance_and_zero_at_the_source() {
    let s = surface();
    let a = post("/api/distance", &json!({"source": 123}));
    assert_eq!(a.status, 200);
    let j = a.json();
    let d = j["distances"].as_array().unwrap();
    assert_eq!(d.len(), s.n_vertices());
    close(&d[123], 0.0);
    let e = s.embedded_coords();
    close(&d[456], (e[456] - e[123]).norm());
    let max = d.iter().map(|x| x.as_f64().unwrap()).fold(0.0, f64::max);
    close(&j["max"], max);
}

#[test]
fn decal_matches_decal_vertices_and_its_obj_carries_the_uvs() {
    let s = surface();
    let anchors = [0u32, 40, 500];
    let uv = [[0.0, 0.0], [1.0, 0.0], [0.0, 1.0]];
    let solver = s.solver(anchors).unwrap();
    let want = decal_vertices(&solver, &uv, -0.1).unwrap();
    let a = post("/api/decal", &json!({"anchors": anchors, "uv": uv}));
    assert_eq!(a.status, 200, "{}", String::from_utf8_lossy(&a.body));
    let j = a.json();
    let got = j["uv"].as_array().unwrap();
    assert_eq!(got.len(), want.uv.uv.len());
    for (g, w) in got.iter().zip(&want.uv.uv) {
        close(&g[0], w[0]);
        close(&g[1], w[1]);
    }
    let marked: Vec<usize> = serde_json::from_value(j["marked"].clone()).unwrap();
    assert_eq!(marked.len(), want.uv.marked.iter().filter(|m| **m).count());
    close(&j["report"]["valid_fraction"], want.report().valid_fraction);
    let obj = post(
        "/api/decal",
        &json!({"anchors": anchors, "uv": uv, "format": "obj"}),
    );
    let text = String::from_utf8(obj.body).unwrap();
    assert_eq!(
        text.lines().filter(|l| l.starts_with("vt ")).count(),
        s.n_vertices()
    );
    assert_eq!(
        text.lines().filter(|l| l.starts_with("f ")).count(),
        s.n_faces()
    );
    let mut want_obj = Vec::new();
    wavg::apps::write_decal_obj(&mut want_obj, s.mesh(), &want.uv, None).unwrap();
    assert_eq!(text.as_bytes(), &want_obj[..]);
}

#[test]
fn cage_then_remesh_refines_on_the_surface_and_drags() {
    let _ = surface();
    let cage = post("/api/cage", &json!({"vertices": 30}));
    assert_eq!(cage.status, 200, "{}", String::from_utf8_lossy(&cage.body));
    let cage = cage.json();
    assert_eq!(cage["vertices"].as_array().unwrap().len(), 30);
    let nf = cage["faces"].as_array().unwrap().len();
    let a = post(
        "/api/remesh",
        &json!({"cage": cage, "levels": 2, "smooth": 2}),
    );
    assert_eq!(a.status, 200, "{}", String::from_utf8_lossy(&a.body));
    let j = a.json();
    // Two levels split every triangle into 16.
    assert_eq!(j["faces"].as_array().unwrap().len(), 16 * nf);
    assert_eq!(j["cage"].as_array().unwrap().len(), 30);
    for v in j["vertices"].as_array().unwrap() {
        let p: [f64; 3] = serde_json::from_value(v.clone()).unwrap();
        // On the torus (major radius 1, minor 0.35): within a polygon's sag of the tube.
        let r = (p[0].hypot(p[1]) - 1.0).hypot(p[2]);
        assert!((r - 0.35).abs() < 0.02, "{p:?} off the surface ({r})");
    }
    // Dragging a cage vertex moves the result; the OBJ has every vertex and face.
    let mut moved = cage.clone();
    moved["vertices"][0][2] = json!(moved["vertices"][0][2].as_f64().unwrap() + 0.05);
    let b = post(
        "/api/remesh",
        &json!({"cage": moved, "levels": 2, "smooth": 2}),
    );
    assert_ne!(b.json()["vertices"], j["vertices"]);
    let obj = post(
        "/api/remesh",
        &json!({"cage": cage, "levels": 2, "smooth": 2, "format": "obj"}),
    );
    let text = String::from_utf8(obj.body).unwrap();
    let nv = j["vertices"].as_array().unwrap().len();
    assert_eq!(text.lines().filter(|l| l.starts_with("v ")).count(), nv);
    assert_eq!(
        text.lines().filter(|l| l.starts_with("f ")).count(),
        16 * nf
    );
}

#[test]
fn the_page_and_three_come_from_memory() {
    let page = get("/");
    assert_eq!(page.status, 200);
    let html = String::from_utf8(page.body).unwrap();
    assert!(html.contains("importmap") && html.contains("/app.js"));
    for path in [
        "/app.js",
        "/vendor/three/three.module.js",
        "/vendor/three/OrbitControls.js",
    ] {
        let a = get(path);
        assert_eq!(a.status, 200, "{path}");
        assert!(
            a.header("content-type")
                .unwrap()
                .starts_with("text/javascript")
        );
    }
    // Every file of web/src (at the root) and of web/vendor (under /vendor) is served,
    // with its bytes.
    let web = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../web");
    let mut files = 0;
    for (folder, prefix) in [("src", ""), ("vendor", "vendor/")] {
        let top = web.join(folder);
        let mut dirs = vec![top.clone()];
        while let Some(dir) = dirs.pop() {
            for e in std::fs::read_dir(&dir).unwrap() {
                let path = e.unwrap().path();
                if path.is_dir() {
                    dirs.push(path);
                    continue;
                }
                let rel = path.strip_prefix(&top).unwrap().to_str().unwrap();
                let url = format!("{prefix}{rel}");
                let a = get(&format!("/{url}"));
                assert_eq!(a.status, 200, "{url} is in web/{folder} but not served");
                assert_eq!(a.body, std::fs::read(&path).unwrap(), "{url}");
                files += 1;
            }
        }
    }
    assert!(files >= 12, "{files} files in web/src and web/vendor");
    // web/ keeps one copy of each source: no built folder beside them.
    assert!(!web.join("dist").exists(), "web/dist is back");
    for path in [
        "/../Cargo.toml",
        "/etc/passwd",
        "/vendor/three/../../Cargo.toml",
        "/api/nope",
    ] {
        assert_eq!(get(path).status, 404, "{path}");
    }
    let _ = server();
}
