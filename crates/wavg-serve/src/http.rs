//! The HTTP side: tiny_http on [`crate::WORKERS`] threads that each take the next request,
//! read its body within [`crate::MAX_BODY`], route it and answer; a panic in a handler is
//! caught and answered with 500, so nothing a client sends stops the server.

use std::io::{Cursor, Read, Write};
use std::net::SocketAddr;
use std::panic::{AssertUnwindSafe, catch_unwind};
use std::sync::Arc;
use std::thread::JoinHandle;
use std::time::Instant;

use tiny_http::{Header, Method, Request, Response, Server, StatusCode};

use crate::routes::{Reply, route};
use crate::{ApiError, App, MAX_BODY, WORKERS};

/// A server answering on its worker threads.
pub struct Running {
    server: Arc<Server>,
    addr: SocketAddr,
    workers: Vec<JoinHandle<()>>,
}

impl Running {
    /// The address it listens on (with the port chosen when 0 was asked for).
    pub fn addr(&self) -> SocketAddr {
        self.addr
    }

    /// Stops taking requests and waits for the workers to finish the ones they have.
    pub fn stop(self) {
        self.server.unblock();
        for _ in 1..self.workers.len() {
            self.server.unblock();
        }
        for w in self.workers {
            let _ = w.join();
        }
    }

    /// Serves until the process ends.
    pub fn join(self) {
        for w in self.workers {
            let _ = w.join();
        }
    }
}

/// Binds `addr` (`host:port`; port 0 picks a free one) and serves `app` on worker threads.
pub fn start(app: App, addr: &str) -> Result<Running, std::io::Error> {
    let server = Server::http(addr).map_err(std::io::Error::other)?;
    let addr = server
        .server_addr()
        .to_ip()
        .ok_or_else(|| std::io::Error::other("not an IP address"))?;
    let server = Arc::new(server);
    let workers = (0..WORKERS)
        .map(|_| {
            let (server, app) = (server.clone(), app.clone());
            std::thread::spawn(move || {
                while let Ok(request) = server.recv() {
                    answer(&app, request);
                }
            })
        })
        .collect();
    Ok(Running {
        server,
        addr,
        workers,
    })
}

/// Reads, routes and answers one request.
fn answer(app: &App, mut request: Request) {
    let start = Instant::now();
    let method = request.method().clone();
    let url = request.url().to_owned();
    let reply = match read_body(&mut request) {
        Ok(body) => catch_unwind(AssertUnwindSafe(|| route(app, &method, &url, &body)))
            .unwrap_or_else(|_| Err(ApiError::status(500, "internal error (a bug)"))),
        Err(e) => Err(e),
    };
    let mut reply = reply.unwrap_or_else(|e| {
        let body = serde_json::json!({ "error": e.message }).to_string();
        Reply::json(body.into_bytes()).with_status(e.status)
    });
    if reply.compute_ms.is_some() {
        reply.total_ms = Some(start.elapsed().as_secs_f64() * 1e3);
    }
    if reply.status == 413 {
        // The body was not read: `into_writer` would first drain it (up to its declared
        // length), so answer through tiny_http, which writes before it drains.
        let body = Cursor::new(reply.body);
        let ty = Header::from_bytes(&b"Content-Type"[..], reply.content_type.as_bytes());
        let mut response = Response::new(
            StatusCode(413),
            Vec::new(),
            body.clone(),
            Some(body.get_ref().len()),
            None,
        );
        if let Ok(h) = ty {
            response.add_header(h);
        }
        let _ = request.respond(response);
        return;
    }
    let head = *request.method() == Method::Head;
    let _ = write_response(request.into_writer(), &reply, head);
}

/// Writes the whole response and closes the connection (`Connection: close`): tiny_http
/// runs each open connection on a thread of a small pool and may leave a new connection
/// queued while the pool's threads wait on idle keep-alive connections (a browser opens
/// several), so no connection is kept open after its response.
fn write_response(mut w: Box<dyn Write + Send>, reply: &Reply, head: bool) -> std::io::Result<()> {
    let reason = match reply.status {
        200 => "OK",
        400 => "Bad Request",
        404 => "Not Found",
        405 => "Method Not Allowed",
        413 => "Payload Too Large",
        503 => "Service Unavailable",
        _ => "Internal Server Error",
    };
    let mut out = format!(
        "HTTP/1.1 {} {reason}\r\nContent-Type: {}\r\nContent-Length: {}\r\n\
         Cache-Control: no-store\r\nConnection: close\r\n",
        reply.status,
        reply.content_type,
        reply.body.len()
    );
    if let Some(ms) = reply.compute_ms {
        out.push_str(&format!("Server-Timing: compute;dur={ms:.3}"));
        if let Some(total) = reply.total_ms {
            out.push_str(&format!(", total;dur={total:.3}"));
        }
        out.push_str("\r\n");
    }
    out.push_str("\r\n");
    w.write_all(out.as_bytes())?;
    if !head {
        w.write_all(&reply.body)?;
    }
    w.flush()
}

/// The body of a POST (empty for other methods), refusing more than [`MAX_BODY`] bytes:
/// 413 when the declared length is too large, 400 when the body is not what it declared.
fn read_body(request: &mut Request) -> Result<Vec<u8>, ApiError> {
    if *request.method() != Method::Post {
        return Ok(Vec::new());
    }
    let too_large = || {
        ApiError::status(
            413,
            format!("the body is larger than {MAX_BODY} bytes (16 MB)"),
        )
    };
    if request.body_length().is_some_and(|n| n > MAX_BODY) {
        return Err(too_large());
    }
    let mut body = Vec::new();
    request
        .as_reader()
        .take(MAX_BODY as u64 + 1)
        .read_to_end(&mut body)
        .map_err(|e| ApiError::bad(format!("the body could not be read: {e}")))?;
    if body.len() > MAX_BODY {
        return Err(too_large());
    }
    Ok(body)
}
