//! The local HTTP server of `wavg serve`: one interactive page (our sources from `web/src/`
//! and three.js from `web/vendor/three/`, embedded at compile time) and a JSON/binary API
//! over a [`wavg::Surface`], with the same semantics and row formats as the command line
//! (routes and bodies: `docs/serve.md`).
//!
//! [`App::new`] takes the surface; without an embedding, [`App::precompute_in_background`]
//! computes one while the server already answers (`GET /api/status` reports the stage;
//! the computing routes answer 503 until it is done). [`start`] binds and serves on worker
//! threads, so a slow request never blocks the others; bad requests get a 4xx status with
//! a message and never stop the server; a failure of the server's own work gets 500
//! ([`status_of`] maps the library's error kinds).
//!
//! ```no_run
//! use wavg::Surface;
//! let surface = Surface::from_mesh(wavg::mesh::procedural::torus(48, 16, 1.0, 0.35))?;
//! let app = wavg_serve::App::new(surface);
//! app.precompute_in_background(None);
//! let server = wavg_serve::start(app, "127.0.0.1:0")?;
//! println!("http://{}", server.addr());
//! server.join();
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```

#![deny(unreachable_pub)]
#![forbid(unsafe_code)]

mod apps;
mod assets;
mod body;
mod error;
mod http;
mod meshbin;
mod points;
mod problems;
mod reply;
mod routes;
mod state;

pub use error::{ApiError, status_of};
pub use http::{Running, Stopper, start};
pub use meshbin::encode_mesh;
pub use state::{App, Status};

/// Largest request body accepted (bytes); larger ones get 413.
pub const MAX_BODY: usize = 16 << 20;
/// Most anchors or control points in one request.
pub const MAX_ANCHORS: usize = 4096;
/// Most query rows (weights, points) in one request.
pub const MAX_ROWS: usize = 200_000;
/// Most samples of one spline.
pub const MAX_SAMPLES: usize = 100_000;
/// Most numbers in one answer's weights (points x anchors of `/api/inverse`): about 40 MB
/// of memory and 100 MB of JSON.
pub const MAX_ANSWER: usize = 1 << 22;
/// Most faces one `/api/remesh` may make (counted before remeshing as the base's corners
/// times 4 per level after the first).
pub const MAX_FACES: usize = 1 << 20;
/// Most levels of splitting one `/api/remesh` may ask for (the library takes
/// `wavg::apps::MAX_LEVELS`; past five, answers grow beyond what the page draws).
pub const MAX_REMESH_LEVELS: usize = 5;
/// Worker threads answering requests.
pub const WORKERS: usize = 8;
