//! Bad requests: each gets a 4xx status with a JSON message, and none stops the server or
//! keeps it from answering others.

use crate::common;

use std::io::Write;
use std::net::TcpStream;
use std::time::Duration;

use common::{get, post, raw, request, server};
use serde_json::json;

/// Over 200 malformed bodies and requests, each refused with a message; the server
/// answers normally after them.
#[test]
fn malformed_requests_get_400_with_a_message_and_the_server_keeps_answering() {
    let addr = server();
    let mut cases: Vec<(&str, Vec<u8>)> = Vec::new();
    let bodies = [
        "",
        "{",
        "}",
        "[]",
        "null",
        "42",
        "\"text\"",
        "{\"anchors\": }",
        "{'a': 1}",
        "{\"anchors\": [0, 1], \"weights\": [[0.5, 0.5]]",
        "\u{0}\u{1}",
        "{\"a\":1}{",
        "true",
        "[{}]",
        "{\"anchors\": 5, \"control\": 5, \"source\": \"a\", \"cage\": 5, \"vertices\": -3}",
        "{\"anchors\": [[]], \"control\": [[]], \"source\": [[]], \"cage\": {}, \"vertices\": 2.5}",
    ];
    for route in [
        "/api/forward",
        "/api/inverse",
        "/api/spline",
        "/api/decal",
        "/api/distance",
        "/api/remesh",
        "/api/cage",
    ] {
        for b in bodies {
            cases.push((route, b.as_bytes().to_vec()));
        }
        // Not UTF-8.
        cases.push((route, vec![0xff, 0xfe, 0x7b, 0x80]));
    }
    let json_cases = [
        // forward: wrong lengths, NaN-like values, sums, faces and vertices out of range.
        (
            "/api/forward",
            json!({"anchors": [0, 1], "weights": [[1.0]]}),
        ),
        (
            "/api/forward",
            json!({"anchors": [0, 1], "weights": [[0.5, 0.5, 0.0]]}),
        ),
        (
            "/api/forward",
            json!({"anchors": [0, 1], "weights": [[0.9, 0.5]]}),
        ),
        (
            "/api/forward",
            json!({"anchors": [0, 1], "weights": [["NaN", 0.5]]}),
        ),
        (
            "/api/forward",
            json!({"anchors": [0, 1], "weights": [[null, 1.0]]}),
        ),
        (
            "/api/forward",
            json!({"anchors": [0, 1], "weights": [0.5, 0.5]}),
        ),
        ("/api/forward", json!({"anchors": [0, 1], "weights": 1})),
        ("/api/forward", json!({"anchors": [0, 1]})),
        ("/api/forward", json!({"weights": [[1.0]]})),
        ("/api/forward", json!({"anchors": [], "weights": []})),
        (
            "/api/forward",
            json!({"anchors": [999_999], "weights": [[1.0]]}),
        ),
        ("/api/forward", json!({"anchors": [-1], "weights": [[1.0]]})),
        (
            "/api/forward",
            json!({"anchors": [1.5], "weights": [[1.0]]}),
        ),
        (
            "/api/forward",
            json!({"anchors": [[999_999, 1.0, 0.0, 0.0]], "weights": [[1.0]]}),
        ),
        (
            "/api/forward",
            json!({"anchors": [[0, 1.0, 0.0]], "weights": [[1.0]]}),
        ),
        (
            "/api/forward",
            json!({"anchors": [[0, 0.9, 0.9, 0.0]], "weights": [[1.0]]}),
        ),
        (
            "/api/forward",
            json!({"anchors": [[0, -0.5, 1.5, 0.0]], "weights": [[1.0]]}),
        ),
        (
            "/api/forward",
            json!({"anchors": [["x", 1.0, 0.0, 0.0]], "weights": [[1.0]]}),
        ),
        (
            "/api/forward",
            json!({"anchors": [0, 1], "weights": [[0.0, 0.0]], "normalize": true}),
        ),
        (
            "/api/forward",
            json!({"anchors": [0, 1], "weights": [[1e308, 1e308]], "normalize": true}),
        ),
        (
            "/api/forward",
            json!({"anchors": [0, 1], "weights": [[0.5, 0.5]], "normalize": "yes"}),
        ),
        (
            "/api/forward",
            json!({"anchors": "0 1", "weights": [[0.5, 0.5]]}),
        ),
        // inverse
        (
            "/api/inverse",
            json!({"anchors": [0, 1, 2], "points": [[5, 0.2, 0.2, 0.2]]}),
        ),
        (
            "/api/inverse",
            json!({"anchors": [0, 1, 2], "points": [[99_999, 0.2, 0.3, 0.5]]}),
        ),
        (
            "/api/inverse",
            json!({"anchors": [0, 1, 2], "points": [99_999]}),
        ),
        (
            "/api/inverse",
            json!({"anchors": [0, 1, 2], "points": [[5, 0.2, 0.3]]}),
        ),
        (
            "/api/inverse",
            json!({"anchors": [0, 1, 2], "points": [[5, 0.2, 0.3, 0.5, 0.0]]}),
        ),
        ("/api/inverse", json!({"anchors": [0, 1, 2], "points": 5})),
        ("/api/inverse", json!({"anchors": [0, 1, 2]})),
        (
            "/api/inverse",
            json!({"anchors": [0, 1, 2], "points": [5], "verified": 1}),
        ),
        // spline
        ("/api/spline", json!({"control": [0, 1]})),
        ("/api/spline", json!({"control": [0]})),
        ("/api/spline", json!({"control": [0, 1, 2, 3], "degree": 0})),
        (
            "/api/spline",
            json!({"control": [0, 1, 2, 3], "degree": -1}),
        ),
        (
            "/api/spline",
            json!({"control": [0, 1, 2, 3], "degree": 3.5}),
        ),
        (
            "/api/spline",
            json!({"control": [0, 1, 2, 3], "samples": 0}),
        ),
        (
            "/api/spline",
            json!({"control": [0, 1, 2, 3], "samples": 100_000_000}),
        ),
        (
            "/api/spline",
            json!({"control": [0, 1, 2, 3], "closed": "no"}),
        ),
        (
            "/api/spline",
            json!({"control": [0, 1, 2, 3], "format": "csv"}),
        ),
        ("/api/spline", json!({"control": [0, 1, 2, 999_999]})),
        (
            "/api/spline",
            json!({"control": (0..5000).collect::<Vec<_>>()}),
        ),
        // distance
        ("/api/distance", json!({"source": 999_999})),
        ("/api/distance", json!({"source": [0, 0.5, 0.5]})),
        ("/api/distance", json!({"source": [0, "a", 0.5, 0.5]})),
        ("/api/distance", json!({"source": null})),
        ("/api/distance", json!({})),
        // decal
        (
            "/api/decal",
            json!({"anchors": [0, 1, 2], "uv": [[0, 0], [1, 0]]}),
        ),
        (
            "/api/decal",
            json!({"anchors": [0, 1, 2], "uv": [[0, 0], [1, 0], [0]]}),
        ),
        (
            "/api/decal",
            json!({"anchors": [0, 1, 2], "uv": [[0, 0], [1, 0], [0, 1, 2]]}),
        ),
        (
            "/api/decal",
            json!({"anchors": [0, 1, 2], "uv": [[0, 0], [1, 0], ["NaN", 1]]}),
        ),
        (
            "/api/decal",
            json!({"anchors": [0, 1, 2], "uv": [[0, 0], [1, 0], [0, 1]], "max_negative": "x"}),
        ),
        (
            "/api/decal",
            json!({"anchors": [0, 1, 2], "uv": [[0, 0], [1, 0], [0, 1]], "format": "ply"}),
        ),
        ("/api/decal", json!({"anchors": [0, 1, 2]})),
        // remesh and cage
        ("/api/remesh", json!({})),
        (
            "/api/remesh",
            json!({"cage": {"vertices": [], "faces": []}}),
        ),
        (
            "/api/remesh",
            json!({"cage": {"vertices": [[0, 0, 0]], "faces": [[0, 1, 2]]}}),
        ),
        (
            "/api/remesh",
            json!({"cage": {"vertices": [[0, 0, 0], [1, 0, 0], [0, 1, 0]], "faces": [[0, 1]]}}),
        ),
        (
            "/api/remesh",
            json!({"cage": {"vertices": [[0, 0], [1, 0, 0], [0, 1, 0]], "faces": [[0, 1, 2]]}}),
        ),
        (
            "/api/remesh",
            json!({"cage": {"vertices": [[50, 50, 50], [51, 50, 50], [50, 51, 50]], "faces": [[0, 1, 2]]}}),
        ),
        (
            "/api/remesh",
            json!({"cage": {"vertices": [[1.35, 0, 0], [1, 0.35, 0], [1, 0, 0.35]], "faces": [[0, 1, 2]]}, "levels": 99}),
        ),
        (
            "/api/remesh",
            json!({"cage": {"vertices": [[1.35, 0, 0], [1, 0.35, 0], [1, 0, 0.35]], "faces": [[0, 1, -2]]}}),
        ),
        ("/api/remesh", json!({"cage": [1, 2], "base": "v 0 0 0"})),
        ("/api/remesh", json!({"base": "this is not an OBJ"})),
        ("/api/remesh", json!({"cage": "x"})),
        ("/api/cage", json!({"vertices": 1})),
        ("/api/cage", json!({"vertices": 10_000_000})),
        ("/api/cage", json!({"vertices": "many"})),
    ];
    for (route, body) in &json_cases {
        cases.push((route, body.to_string().into_bytes()));
    }
    // NaN and Infinity are not JSON; numbers too large for f64 are not finite.
    for route in ["/api/forward", "/api/inverse", "/api/spline", "/api/decal"] {
        for bad in ["NaN", "Infinity", "-Infinity", "1e999", "-1e999"] {
            let body = format!(
                "{{\"anchors\": [0, 1, 2], \"control\": [0, 1, 2, 3], \"weights\": [[{bad}, 0.5, 0.5]], \"points\": [[1, {bad}, 0, 0]], \"uv\": [[{bad}, 0], [1, 0], [0, 1]]}}"
            );
            cases.push((route, body.into_bytes()));
        }
    }
    let mut refused = 0;
    for (route, body) in &cases {
        let a = request(addr, "POST", route, body);
        assert!(
            (400..500).contains(&a.status),
            "{route} {:?}: status {} {}",
            String::from_utf8_lossy(body),
            a.status,
            String::from_utf8_lossy(&a.body)
        );
        let msg = a.json()["error"].as_str().unwrap().to_string();
        assert!(!msg.is_empty());
        refused += 1;
    }
    // Wrong methods, unknown routes, broken HTTP.
    for (method, path) in [
        ("GET", "/api/spline"),
        ("PUT", "/api/info"),
        ("DELETE", "/"),
        ("POST", "/api/nothing"),
        ("POST", "/index.html"),
    ] {
        let a = request(addr, method, path, b"{}");
        assert!(
            (400..500).contains(&a.status),
            "{method} {path}: {}",
            a.status
        );
        refused += 1;
    }
    for bytes in [
        &b"GARBAGE\r\n\r\n"[..],
        b"GET\r\n\r\n",
        b"POST /api/spline HTTP/1.1\r\nContent-Length: 5\r\n\r\n{\"co",
    ] {
        let mut s = TcpStream::connect(addr).unwrap();
        s.set_read_timeout(Some(Duration::from_secs(10))).unwrap();
        let _ = s.write_all(bytes);
        let _ = s.shutdown(std::net::Shutdown::Write);
        let mut out = Vec::new();
        let _ = std::io::Read::read_to_end(&mut s, &mut out);
        refused += 1;
    }
    assert!(refused >= 200, "only {refused} bad requests");
    assert_eq!(get("/api/info").status, 200);
    let ok = common::post(
        "/api/spline",
        &json!({"control": [0, 100, 200, 300], "samples": 10}),
    );
    assert_eq!(ok.status, 200);
}

/// A client that sends half a body and waits holds one worker; others are still answered.
#[test]
fn a_slow_client_does_not_block_other_requests() {
    let addr = server();
    let mut slow: Vec<TcpStream> = Vec::new();
    for _ in 0..wavg_serve::WORKERS - 1 {
        let mut s = TcpStream::connect(addr).unwrap();
        s.write_all(
            b"POST /api/spline HTTP/1.1\r\nHost: x\r\nContent-Length: 100\r\n\r\n{\"control\"",
        )
        .unwrap();
        slow.push(s);
    }
    std::thread::sleep(Duration::from_millis(200));
    // Answered although all but one worker wait for bodies (the client's timeout is 60 s).
    assert_eq!(get("/api/info").status, 200);
    drop(slow);
}

/// While the embedding is computed, the mesh routes answer and the computing routes say
/// 503 with the stage; afterwards they answer.
#[test]
fn computing_routes_wait_for_the_embedding() {
    let surface =
        wavg::Surface::from_mesh(wavg::mesh::procedural::torus(40, 14, 1.0, 0.35)).unwrap();
    let app = wavg_serve::App::new(surface);
    let running = wavg_serve::start(app.clone(), "127.0.0.1:0").unwrap();
    let addr = running.addr();
    assert_eq!(
        request(addr, "GET", "/api/status", b"").json()["state"],
        "precomputing"
    );
    assert_eq!(request(addr, "GET", "/api/info", b"").status, 200);
    assert_eq!(request(addr, "GET", "/api/mesh", b"").status, 200);
    let body = json!({"control": [0, 100, 200, 300], "samples": 10}).to_string();
    let a = request(addr, "POST", "/api/spline", body.as_bytes());
    assert_eq!(a.status, 503);
    assert!(
        a.json()["error"]
            .as_str()
            .unwrap()
            .contains("being computed")
    );
    app.precompute_in_background(None).join().unwrap();
    assert_eq!(
        request(addr, "GET", "/api/status", b"").json()["state"],
        "ready"
    );
    assert_eq!(
        request(addr, "POST", "/api/spline", body.as_bytes()).status,
        200
    );
    running.stop();
}

/// Browsers open several keep-alive connections at once (some never used); every
/// response closes its connection, so a burst of them never leaves a request unanswered.
#[test]
fn a_burst_of_keep_alive_connections_is_answered() {
    let addr = server();
    let idle: Vec<TcpStream> = (0..6).map(|_| TcpStream::connect(addr).unwrap()).collect();
    let handles: Vec<_> = (0..12)
        .map(|_| {
            std::thread::spawn(move || {
                let a = raw(
                    addr,
                    b"GET /app.js HTTP/1.1\r\nHost: x\r\nConnection: keep-alive\r\n\r\n",
                );
                assert_eq!(a.status, 200);
                assert_eq!(a.header("connection"), Some("close"));
            })
        })
        .collect();
    for h in handles {
        h.join().unwrap();
    }
    drop(idle);
}

/// With `verified`, a point that no weights of the penalty ladder bring back has none
/// (`null`, as `wavg inverse --verified` prints `none not-reached`): three anchors on a
/// torus reach only some points.
#[test]
fn verified_inverse_gives_no_weights_where_none_return() {
    let s = common::surface();
    let anchors = [0u32, 100, 500];
    let solver = s.solver(anchors).unwrap();
    let points: Vec<serde_json::Value> = (0..s.n_faces() as u32)
        .step_by(23)
        .map(|f| json!([f, 0.2, 0.3, 0.5]))
        .collect();
    let a = post(
        "/api/inverse",
        &json!({"anchors": anchors, "points": points, "verified": true}),
    );
    assert_eq!(a.status, 200, "{}", String::from_utf8_lossy(&a.body));
    let got = a.json()["weights"].as_array().unwrap().clone();
    let (mut nulls, mut rows) = (0, 0);
    for (p, w) in points.iter().zip(&got) {
        let f = p[0].as_u64().unwrap() as u32;
        let v = solver
            .inverse_verified(
                &wavg::SurfacePoint::new(f, [0.2, 0.3, 0.5]),
                wavg::DEFAULT_TOLERANCE,
            )
            .unwrap();
        if v.round_trip == wavg::RoundTrip::NotReached {
            assert!(w.is_null(), "face {f}: {w}");
            nulls += 1;
        } else {
            assert!(w.is_array(), "face {f}: {w}");
            rows += 1;
        }
    }
    assert!(nulls > 0 && rows > 0, "{nulls} null, {rows} rows");
}

/// Answers too large to hold are refused before any work: points x anchors of an inverse,
/// faces of a remeshing.
#[test]
fn answers_beyond_the_limits_are_refused() {
    // 3072 distinct anchors (two points on each face of the torus) x 1400 points.
    let anchors: Vec<serde_json::Value> = (0..1536)
        .flat_map(|f| [json!([f, 0.2, 0.3, 0.5]), json!([f, 0.5, 0.3, 0.2])])
        .collect();
    let points: Vec<u32> = (0..1400).map(|v| v % 768).collect();
    let a = post(
        "/api/inverse",
        &json!({"anchors": anchors, "points": points}),
    );
    assert_eq!(a.status, 400, "{}", String::from_utf8_lossy(&a.body));
    assert!(
        a.json()["error"]
            .as_str()
            .unwrap()
            .contains("weights in one answer")
    );
    // A cage of 1200 quads at 5 levels: 4800 x 4^4 faces.
    let mut cage = Vec::new();
    for i in 0..1200u32 {
        cage.push(json!([4 * i, 4 * i + 1, 4 * i + 2, 4 * i + 3]));
    }
    let verts: Vec<[f64; 3]> = (0..4800).map(|v| [v as f64, 0.0, 0.0]).collect();
    let a = post(
        "/api/remesh",
        &json!({"cage": {"vertices": verts, "faces": cage}, "levels": 5}),
    );
    assert_eq!(a.status, 400, "{}", String::from_utf8_lossy(&a.body));
    let e = a.json()["error"].as_str().unwrap().to_owned();
    assert!(e.contains("faces, more than"), "{e}");
}

/// The GET routes answer another method with 405; unknown API routes with 404; the
/// message shows at most 200 characters of the path.
#[test]
fn methods_and_routes() {
    let addr = common::server();
    for path in ["/api/info", "/api/status", "/api/mesh", "/"] {
        let a = request(addr, "POST", path, b"{}");
        assert_eq!(a.status, 405, "POST {path}");
    }
    assert_eq!(request(addr, "POST", "/api/nothing", b"{}").status, 404);
    let long = format!("/api/{}", "a".repeat(100_000));
    let a = request(addr, "DELETE", &long, b"");
    assert_eq!(a.status, 404);
    assert!(a.body.len() < 1000, "{} bytes", a.body.len());
    let status = request(addr, "GET", "/api/status", b"").json();
    for key in ["state", "stage", "fraction", "message"] {
        assert!(status.get(key).is_some(), "no {key} in {status}");
    }
}

/// Clients that send half a body and wait hold only their own connections: with more of
/// them than the server computes at once, other requests are still answered.
#[test]
fn slow_clients_do_not_hold_the_server() {
    let addr = common::server();
    let slow: Vec<TcpStream> = (0..(wavg_serve::WORKERS + 4))
        .map(|_| {
            let mut c = TcpStream::connect(addr).unwrap();
            c.write_all(
                b"POST /api/forward HTTP/1.1\r\nHost: x\r\nContent-Length: 100000\r\n\r\n{",
            )
            .unwrap();
            c
        })
        .collect();
    std::thread::sleep(std::time::Duration::from_millis(300));
    let t = std::time::Instant::now();
    let a = request(addr, "GET", "/api/status", b"");
    assert_eq!(a.status, 200);
    assert!(t.elapsed().as_secs() < 10, "{:?}", t.elapsed());
    drop(slow);
}

/// A refusal names the field, the row and what was expected.
#[test]
fn refusals_name_the_field_and_what_was_expected() {
    for (route, body, says) in [
        (
            "/api/forward",
            json!({"anchors": [0, 1], "weights": [[0.5, 0.5], [0.5, "a"]]}),
            "weights[1][1]: invalid type: string \"a\", expected f64",
        ),
        (
            "/api/forward",
            json!({"anchors": [0, 1], "weights": [[0.9, 0.5]]}),
            "weights[0]: ",
        ),
        (
            "/api/inverse",
            json!({"anchors": [0, 1, 2], "points": [5, [5, 0.2, 0.3]]}),
            "points[1]: invalid length 3, expected a vertex id or [face, b0, b1, b2]",
        ),
        (
            "/api/inverse",
            json!({"anchors": [0, 999_999], "points": [5]}),
            "anchors[1]: ",
        ),
        (
            "/api/spline",
            json!({"control": [0, 1, 2], "closed": "no"}),
            "closed: invalid type: string \"no\", expected a boolean",
        ),
        (
            "/api/remesh",
            json!({"cage": {"vertices": [[0, 0, 0]], "faces": [[0, 1, -2]]}}),
            "cage.faces[0][2]: invalid value: integer `-2`, expected u32",
        ),
        ("/api/distance", json!({}), "missing field `source`"),
    ] {
        let a = post(route, &body);
        assert_eq!(a.status, 400, "{route} {body}");
        let msg = a.json()["error"].as_str().unwrap().to_owned();
        assert!(msg.contains(says), "{route} {body}: {msg}");
    }
}
