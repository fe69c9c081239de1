//! A test server on a free port over a small precomputed torus, and a minimal HTTP client
//! (one request per connection).

#![allow(dead_code)]

use std::io::{Read, Write};
use std::net::{SocketAddr, TcpStream};
use std::sync::OnceLock;
use std::time::Duration;

use wavg::{NoProgress, PrecomputeOptions, Surface};

/// The precomputed torus every test shares.
pub fn surface() -> &'static Surface {
    static S: OnceLock<Surface> = OnceLock::new();
    S.get_or_init(|| {
        let mut s = Surface::from_mesh(wavg::mesh::procedural::torus(48, 16, 1.0, 0.35)).unwrap();
        let opts = PrecomputeOptions {
            landmarks: 60,
            quality_pairs: 0,
            ..Default::default()
        };
        s.precompute(&opts, &NoProgress).unwrap();
        s
    })
}

/// The address of a server on [`surface`], started once.
pub fn server() -> SocketAddr {
    static A: OnceLock<SocketAddr> = OnceLock::new();
    *A.get_or_init(|| {
        let running =
            wavg_serve::start(wavg_serve::App::new(surface().clone()), "127.0.0.1:0").unwrap();
        let addr = running.addr();
        // Serves until the test process ends.
        std::mem::forget(running);
        addr
    })
}

/// An answer: status, headers (lower-case names), body.
pub struct Answer {
    /// HTTP status.
    pub status: u16,
    /// Header names (lower case) and values.
    pub headers: Vec<(String, String)>,
    /// The body.
    pub body: Vec<u8>,
}

impl Answer {
    /// The body as JSON (panics otherwise).
    pub fn json(&self) -> serde_json::Value {
        serde_json::from_slice(&self.body)
            .unwrap_or_else(|e| panic!("not JSON ({e}): {}", String::from_utf8_lossy(&self.body)))
    }

    /// A header's value.
    pub fn header(&self, name: &str) -> Option<&str> {
        self.headers
            .iter()
            .find(|(k, _)| k == name)
            .map(|(_, v)| v.as_str())
    }
}

/// Sends raw bytes and reads one answer (its head, then `Content-Length` bytes).
pub fn raw(addr: SocketAddr, bytes: &[u8]) -> Answer {
    let mut s = TcpStream::connect(addr).unwrap();
    s.set_read_timeout(Some(Duration::from_secs(60))).unwrap();
    // A server that answers before reading everything may close early: ignore that.
    let _ = s.write_all(bytes);
    let mut out = Vec::new();
    let mut buf = [0u8; 65536];
    loop {
        if let Some(end) = out.windows(4).position(|w| w == b"\r\n\r\n") {
            let a = parse(&out);
            let len: usize = a.header("content-length").unwrap().parse().unwrap();
            if out.len() >= end + 4 + len {
                return a;
            }
        }
        let n = s.read(&mut buf).unwrap();
        assert!(
            n > 0,
            "connection closed early: {:?}",
            String::from_utf8_lossy(&out)
        );
        out.extend_from_slice(&buf[..n]);
    }
}

/// `method path` with `body`.
pub fn request(addr: SocketAddr, method: &str, path: &str, body: &[u8]) -> Answer {
    let mut req = format!(
        "{method} {path} HTTP/1.1\r\nHost: x\r\nConnection: close\r\nContent-Length: {}\r\n\r\n",
        body.len()
    )
    .into_bytes();
    req.extend_from_slice(body);
    raw(addr, &req)
}

/// GET `path` from the shared server.
pub fn get(path: &str) -> Answer {
    request(server(), "GET", path, b"")
}

/// POST JSON to `path` on the shared server.
pub fn post(path: &str, body: &serde_json::Value) -> Answer {
    request(server(), "POST", path, body.to_string().as_bytes())
}

fn parse(out: &[u8]) -> Answer {
    let end = out
        .windows(4)
        .position(|w| w == b"\r\n\r\n")
        .unwrap_or_else(|| panic!("no header end in {:?}", String::from_utf8_lossy(out)));
    let head = String::from_utf8_lossy(&out[..end]).to_string();
    let mut lines = head.lines();
    let status = lines
        .next()
        .unwrap()
        .split(' ')
        .nth(1)
        .unwrap()
        .parse()
        .unwrap();
    let headers = lines
        .filter_map(|l| l.split_once(':'))
        .map(|(k, v)| (k.trim().to_lowercase(), v.trim().to_string()))
        .collect();
    Answer {
        status,
        headers,
        body: out[end + 4..].to_vec(),
    }
}
