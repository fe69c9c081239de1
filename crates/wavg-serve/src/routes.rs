//! Routing: the page's files from memory, the read-only routes (`/api/info`,
//! `/api/status`, `/api/mesh`) and the computing ones (in [`crate::problems`] and
//! [`crate::apps`]).

use std::time::Instant;

use serde_json::{Value, json};
use tiny_http::Method;

use crate::parse::Body;
use crate::state::Status;
use crate::{ApiError, App};

/// An answer: status, content type, body, the time the computation took (its JSON
/// included) and the time from taking the request to the answer ready to send (sent as a
/// `Server-Timing: compute;dur=MS, total;dur=MS` header).
pub(crate) struct Reply {
    pub(crate) status: u16,
    pub(crate) content_type: &'static str,
    pub(crate) body: Vec<u8>,
    pub(crate) compute_ms: Option<f64>,
    pub(crate) total_ms: Option<f64>,
}

impl Reply {
    /// 200 with a JSON body.
    pub(crate) fn json(body: Vec<u8>) -> Self {
        Self {
            status: 200,
            content_type: "application/json",
            body,
            compute_ms: None,
            total_ms: None,
        }
    }

    /// 200 with a JSON value.
    pub(crate) fn value(v: &Value) -> Self {
        Self::json(v.to_string().into_bytes())
    }

    /// 200 with plain text (the command line's file formats).
    pub(crate) fn text(body: Vec<u8>) -> Self {
        Self {
            content_type: "text/plain; charset=utf-8",
            ..Self::json(body)
        }
    }

    /// The same with another status.
    pub(crate) fn with_status(self, status: u16) -> Self {
        Self { status, ..self }
    }
}

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
    let post = |f: fn(&App, &Body) -> Result<Reply, ApiError>| -> Result<Reply, ApiError> {
        if *method != Method::Post {
            return Err(ApiError::status(405, format!("{path} takes POST")));
        }
        let body = Body::parse(body)?;
        let t = Instant::now();
        let mut reply = f(app, &body)?;
        reply.compute_ms = Some(t.elapsed().as_secs_f64() * 1e3);
        Ok(reply)
    };
    match path {
        "/api/forward" => post(crate::problems::forward),
        "/api/inverse" => post(crate::problems::inverse),
        "/api/spline" => post(crate::problems::spline),
        "/api/distance" => post(crate::problems::distance),
        "/api/decal" => post(crate::apps::decal),
        "/api/remesh" => post(crate::apps::remesh),
        "/api/cage" => post(crate::apps::cage),
        _ if *method != Method::Get && *method != Method::Head => {
            let known = !path.starts_with("/api/") || GET_ROUTES.contains(&path);
            Err(ApiError::status(
                if known { 405 } else { 404 },
                format!("no route {} for {method}", shown(path)),
            ))
        }
        "/api/info" => Ok(Reply::value(&info(app))),
        "/api/status" => Ok(Reply::value(&status(app))),
        "/api/mesh" => Ok(Reply {
            content_type: "application/octet-stream",
            ..Reply::json(app.mesh_bytes().to_vec())
        }),
        _ => match crate::assets::get(path) {
            Some((content_type, bytes)) => Ok(Reply {
                content_type,
                ..Reply::json(bytes.to_vec())
            }),
            None => Err(ApiError::status(
                404,
                format!("no page or route {}", shown(path)),
            )),
        },
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
