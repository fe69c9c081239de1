//! The HTTP side: tiny_http hands each request to a thread of its own, which reads its body
//! within [`crate::MAX_BODY`], routes it (at most [`crate::WORKERS`] requests compute at
//! once) and answers; a client that sends or reads slowly holds only its own thread. A
//! panic in a handler is caught and answered with 500, so nothing a client sends stops
//! the server.

use std::io::{Cursor, Read, Write};
use std::net::SocketAddr;
use std::panic::{AssertUnwindSafe, catch_unwind};
use std::sync::{Arc, Condvar, Mutex};
use std::thread::JoinHandle;
use std::time::{Duration, Instant};

use tiny_http::{Header, Method, Request, Response, Server, StatusCode};

use crate::reply::Reply;
use crate::routes::route;
use crate::{ApiError, App, MAX_BODY, WORKERS};

/// A server answering on its threads.
pub struct Running {
    server: Arc<Server>,
    addr: SocketAddr,
    acceptor: JoinHandle<()>,
    in_flight: Arc<Counter>,
}

impl Running {
    /// The address it listens on (with the port chosen when 0 was asked for).
    pub fn addr(&self) -> SocketAddr {
        self.addr
    }

    /// Stops taking requests and waits (up to a minute) for the ones being answered.
    pub fn stop(self) {
        self.stopper().stop();
        self.serve_until_stopped(Duration::from_secs(60));
    }

    /// Serves until the process ends.
    pub fn join(self) {
        let _ = self.acceptor.join();
    }

    /// A handle that stops this server from another thread (a signal handler's).
    pub fn stopper(&self) -> Stopper {
        Stopper {
            server: self.server.clone(),
        }
    }

    /// Serves until a [`Stopper`] stops it (or the process ends), then waits up to `grace`
    /// for the requests being answered.
    pub fn serve_until_stopped(self, grace: Duration) {
        let _ = self.acceptor.join();
        self.in_flight.wait_for_zero(grace);
    }
}

/// Stops a [`Running`] server from any thread: requests already received are still
/// answered, then it takes no more and [`Running::serve_until_stopped`] returns.
#[derive(Clone)]
pub struct Stopper {
    server: Arc<Server>,
}

impl Stopper {
    /// Asks the server to stop (returns at once; a second call does nothing more).
    pub fn stop(&self) {
        self.server.unblock();
    }
}

/// A count that threads raise and lower, and wait on.
#[derive(Default)]
struct Counter {
    n: Mutex<usize>,
    changed: Condvar,
}

impl Counter {
    fn lock(&self) -> std::sync::MutexGuard<'_, usize> {
        self.n.lock().unwrap_or_else(|e| e.into_inner())
    }

    /// Raises the count once it is below `limit`.
    fn acquire(&self, limit: usize) {
        let mut n = self.lock();
        while *n >= limit {
            n = self.changed.wait(n).unwrap_or_else(|e| e.into_inner());
        }
        *n += 1;
    }

    fn release(&self) {
        *self.lock() -= 1;
        self.changed.notify_all();
    }

    fn wait_for_zero(&self, limit: Duration) {
        let n = self.lock();
        let _ = self.changed.wait_timeout_while(n, limit, |n| *n > 0);
    }
}

/// Binds `addr` (`host:port`; port 0 picks a free one) and serves `app`.
pub fn start(app: App, addr: &str) -> Result<Running, std::io::Error> {
    let server = Server::http(addr).map_err(std::io::Error::other)?;
    let addr = server
        .server_addr()
        .to_ip()
        .ok_or_else(|| std::io::Error::other("not an IP address"))?;
    let server = Arc::new(server);
    let in_flight = Arc::new(Counter::default());
    let computing = Arc::new(Counter::default());
    let acceptor = {
        let (server, in_flight) = (server.clone(), in_flight.clone());
        std::thread::spawn(move || {
            while let Ok(request) = server.recv() {
                let (app, in_flight2, computing) =
                    (app.clone(), in_flight.clone(), computing.clone());
                in_flight.acquire(usize::MAX);
                let spawned = std::thread::Builder::new()
                    .name("wavg-serve request".into())
                    .spawn(move || {
                        answer(&app, request, &computing);
                        in_flight2.release();
                    });
                // Without a thread (the system's limit), the request is dropped unanswered
                // and tiny_http closes its connection.
                if spawned.is_err() {
                    in_flight.release();
                }
            }
        })
    };
    Ok(Running {
        server,
        addr,
        acceptor,
        in_flight,
    })
}

/// The largest declared body over [`MAX_BODY`] that is drained after its 413 answer (so
/// that the connection closes); a larger declared length keeps its connection instead.
const MAX_DRAINED: usize = 256 << 20;

/// Reads, routes (once fewer than [`WORKERS`] requests are `computing`) and answers one
/// request.
fn answer(app: &App, mut request: Request, computing: &Counter) {
    let start = Instant::now();
    let method = request.method().clone();
    let url = request.url().to_owned();
    let reply = match read_body(&mut request) {
        Ok(body) => {
            computing.acquire(WORKERS);
            let r = catch_unwind(AssertUnwindSafe(|| route(app, &method, &url, &body)))
                .unwrap_or_else(|_| Err(ApiError::status(500, "internal error (a bug)")));
            computing.release();
            r
        }
        Err(e) => Err(e),
    };
    let mut reply = reply.unwrap_or_else(|e| Reply::error(&e));
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
        if request.body_length().is_some_and(|n| n > MAX_DRAINED) {
            // tiny_http drains an unread body into one buffer of the length still declared;
            // a length beyond memory would abort the server. The answer is written and the
            // connection kept, unread, until the process ends.
            std::mem::forget(request.upgrade("close", response));
            return;
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
