//! Bodies over the size limit: refused with 413, and the server keeps answering.

use crate::common;

use std::io::Write;
use std::net::TcpStream;
use std::time::Duration;

use common::{get, raw, server};

/// A declared body over 16 MB is refused with 413 before it is read; so is a body that is
/// larger than declared... and the server still answers.
#[test]
fn bodies_over_16_mb_get_413() {
    let addr = server();
    let head = format!(
        "POST /api/forward HTTP/1.1\r\nHost: x\r\nConnection: close\r\nContent-Length: {}\r\n\r\n",
        wavg_serve::MAX_BODY + 1
    );
    let a = raw(addr, head.as_bytes());
    assert_eq!(a.status, 413);
    assert!(a.json()["error"].as_str().unwrap().contains("16 MB"));
    // A chunked body without a declared length, streamed past the limit.
    let mut req = b"POST /api/forward HTTP/1.1\r\nHost: x\r\nConnection: close\r\nTransfer-Encoding: chunked\r\n\r\n".to_vec();
    let chunk = vec![b' '; 1 << 20];
    for _ in 0..17 {
        req.extend_from_slice(format!("{:x}\r\n", chunk.len()).as_bytes());
        req.extend_from_slice(&chunk);
        req.extend_from_slice(b"\r\n");
    }
    req.extend_from_slice(b"0\r\n\r\n");
    let a = raw(addr, &req);
    assert_eq!(a.status, 413, "{}", String::from_utf8_lossy(&a.body));
    assert_eq!(get("/api/info").status, 200);
}

/// A declared length far beyond memory is answered 413 (its connection then stays open,
/// unread) and the server keeps answering.
#[test]
fn a_body_longer_than_memory_gets_413_and_the_server_stays_up() {
    let addr = server();
    let head = "POST /api/forward HTTP/1.1\r\nHost: x\r\nContent-Length: 99999999999999\r\n\r\n{}";
    for _ in 0..2 {
        let mut s = TcpStream::connect(addr).unwrap();
        s.set_read_timeout(Some(Duration::from_secs(30))).unwrap();
        s.write_all(head.as_bytes()).unwrap();
        let mut out = Vec::new();
        let mut buf = [0u8; 4096];
        while !out.windows(4).any(|w| w == b"\r\n\r\n") {
            let n = std::io::Read::read(&mut s, &mut buf).unwrap();
            assert!(n > 0, "closed: {:?}", String::from_utf8_lossy(&out));
            out.extend_from_slice(&buf[..n]);
        }
        let text = String::from_utf8_lossy(&out);
        assert!(text.starts_with("HTTP/1.1 413"), "{text}");
        assert_eq!(get("/api/info").status, 200);
    }
}
