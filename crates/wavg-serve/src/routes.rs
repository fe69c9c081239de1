//! Routing: the page's files from memory, the read-only routes (`/api/info`,
//! `/api/status`, `/api/mesh`) and the computing ones (in [`crate::problems`] and
//! [`crate::apps`], which never import this module), each with its body type.

use std::time::Instant;

use serde::de::DeserializeOwned;
use serde_json::{Value, json};
use tiny_http::Method;

use crate::reply::Reply;
use crate::state::Status;
use crate::{ApiError, App, apps, body, problems};

/// The API's routes answered on GET (and HEAD).
const GET_ROUTES: [&str; 3] = ["/api/info", "/api/status", "/api/mesh"];

/// `path` as an error message shows it: at most 200 characters.
fn shown(path: &str) -> String {
    match path.char_indices().nth(200) {
        Some((i, _)) => format!("{}...", &path[..i]),
        None => path.to_owned(),
    }
}

/// Answers `method url` with `body` (empty unless POST).
pub(crate) fn route(app: &App, method: &Method, url: &str, body: &[u8]) -> Result<Reply, ApiError> {
    let path = url.split(['?', '#']).next().unwrap_or("");
    let post = Post {
        app,
        method,
        path,
        body,
    };
    match path {
        "/api/forward" => post.answer(problems::forward),
        "/api/inverse" => post.answer(problems::inverse),
        "/api/spline" => post.answer(problems::spline),
        "/api/distance" => post.answer(problems::distance),
        "/api/decal" => post.answer(apps::decal),
        "/api/remesh" => post.answer(apps::remesh),
        "/api/cage" => post.answer(apps::cage),
        _ if *method != Method::Get && *method != Method::Head => {
            let known = !path.starts_with("/api/") || GET_ROUTES.contains(&path);
            Err(ApiError::status(
                if known { 405 } else { 404 },
                format!("no route {} for {method}", shown(path)),
            ))
        }
        "/api/info" => Ok(Reply::value(&info(app))),
        "/api/status" => Ok(Reply::value(&status(app))),
        "/api/mesh" => Ok(Reply::bytes(
            "application/octet-stream",
            app.mesh_bytes().to_vec(),
        )),
        _ => match crate::assets::get(path) {
            Some((content_type, bytes)) => Ok(Reply::bytes(content_type, bytes.to_vec())),
            None => Err(ApiError::status(
                404,
                format!("no page or route {}", shown(path)),
            )),
        },
    }
}

/// A request to a computing route.
struct Post<'a> {
    app: &'a App,
    method: &'a Method,
    path: &'a str,
    body: &'a [u8],
}

impl Post<'_> {
    /// The answer of `handler` to the body read as `B`, with the time it took; 405 unless
    /// the method is POST.
    fn answer<B: DeserializeOwned>(
        self,
        handler: fn(&App, B) -> Result<Reply, ApiError>,
    ) -> Result<Reply, ApiError> {
        if *self.method != Method::Post {
            return Err(ApiError::status(405, format!("{} takes POST", self.path)));
        }
        let body = body::parse(self.body)?;
        let t = Instant::now();
        let mut reply = handler(self.app, body)?;
        reply.compute_ms = Some(t.elapsed().as_secs_f64() * 1e3);
        Ok(reply)
    }
}

/// `GET /api/info`.
fn info(app: &App) -> Value {
    let s = app.mesh_surface();
    let bb = s
        .mesh()
        .bounding_box()
        .map(|(lo, hi)| json!([[lo.x, lo.y, lo.z], [hi.x, hi.y, hi.z]]));
    json!({
        "vertices": s.n_vertices(),
        "faces": s.n_faces(),
        "bounding_box": bb,
        "mean_edge_length": wavg::mesh::geometry::mean_edge_length(s.mesh()),
        "ready": app.status() == Status::Ready,
    })
}

/// `GET /api/status`: `{"state": "precomputing" | "ready" | "failed", "stage", "fraction",
/// "message"}`.
fn status(app: &App) -> Value {
    match app.status() {
        Status::Ready => {
            json!({"state": "ready", "stage": null, "fraction": 1.0, "message": null})
        }
        Status::Precomputing { stage, fraction } => {
            json!({"state": "precomputing", "stage": stage, "fraction": fraction, "message": null})
        }
        Status::Failed(m) => {
            json!({"state": "failed", "stage": null, "fraction": null, "message": m})
        }
    }
}
