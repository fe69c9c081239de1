//! The routes of the method itself: forward and inverse problems, splines, and the
//! embedding distance.

use serde::Serialize;
use serde_json::{Value, json};
use wavg::apps::{
    DEFAULT_SPLINE_DEGREE, DEFAULT_SPLINE_SAMPLES, SPLINE_CHUNK, SplineKind, evaluate_spline,
};
use wavg::{
    DEFAULT_TOLERANCE, ForwardOptions, ForwardResult, Normalization, RoundTrip, SolveError, Solver,
};

use crate::body::{self, Anchors};
use crate::reply::Reply;
use crate::{ApiError, App, MAX_ANSWER, MAX_SAMPLES, points};

/// A point returned: `[face, b0, b1, b2, x, y, z]`, serialized as a JSON array.
type PointRow = (u32, f64, f64, f64, f64, f64, f64);

/// A forward result as a [`PointRow`], `None` (JSON `null`) where there is no average.
pub(crate) fn point_row(r: &Result<ForwardResult, SolveError>) -> Option<PointRow> {
    r.as_ref().ok().map(|r| {
        let (p, x) = (r.point, r.position);
        (p.face, p.bary[0], p.bary[1], p.bary[2], x.x, x.y, x.z)
    })
}

/// The answer of `/api/forward`, serialized without an intermediate `Value` tree.
#[derive(Serialize)]
struct Points {
    points: Vec<Option<PointRow>>,
}

/// The answer of `/api/spline` (fields in the order a JSON object's keys are written).
#[derive(Serialize)]
struct SplinePoints {
    length: f64,
    points: Vec<Option<PointRow>>,
}

/// A solver for the anchors of the field `key` (at least `min`).
fn solver(app: &App, list: &Anchors, key: &str, min: usize) -> Result<Solver, ApiError> {
    let surface = app.surface()?;
    let anchors = points::anchors(&list.0, key, surface.mesh(), min)?;
    surface.solver(anchors).map_err(ApiError::lib)
}

/// `POST /api/forward` `{"anchors": [...], "weights": [[...], ...], "normalize": false}` ->
/// `{"points": [...]}`. Weight rows must have one finite weight per anchor summing to 1
/// (or any non-zero sum with `"normalize": true`), as `wavg forward` checks them.
pub(crate) fn forward(app: &App, body: body::Forward) -> Result<Reply, ApiError> {
    let solver = solver(app, &body.anchors, "anchors", 1)?;
    let norm = if body.normalize.unwrap_or(false) {
        Normalization::Normalize
    } else {
        Normalization::Reject
    };
    let k = solver.n_anchors();
    let weights: Vec<Vec<f64>> = body.weights.0.into_iter().map(|w| w.0).collect();
    // Malformed rows refuse the request, as in every door.
    let rows: Vec<&[f64]> = weights.iter().map(Vec::as_slice).collect();
    wavg::check_weight_rows(&rows, k, norm)
        .map_err(|(i, e)| ApiError::lib(e).within(&format!("weights[{i}]")))?;
    let opts = ForwardOptions {
        normalization: norm,
        ..Default::default()
    };
    let results = solver.forward_batch(&weights, &opts);
    Reply::serialize(&Points {
        points: results.iter().map(point_row).collect(),
    })
}

/// `POST /api/inverse` `{"anchors": [...], "points": [...], "verified": false}` ->
/// `{"weights": [[...] or null, ...]}` (with `verified`, checked by the forward problem as
/// `wavg inverse --verified`).
pub(crate) fn inverse(app: &App, body: body::Inverse) -> Result<Reply, ApiError> {
    let solver = solver(app, &body.anchors, "anchors", 1)?;
    let points = body
        .points
        .0
        .iter()
        .enumerate()
        .map(|(i, p)| points::point(p, &format!("points[{i}]"), solver.mesh()))
        .collect::<Result<Vec<_>, _>>()?;
    let k = solver.n_anchors();
    if points.len().saturating_mul(k) > MAX_ANSWER {
        return Err(ApiError::bad(format!(
            "{} points x {k} anchors is more than {MAX_ANSWER} weights in one answer: send \
             fewer points per request",
            points.len()
        )));
    }
    let weights: Vec<Value> = if body.verified.unwrap_or(false) {
        // Points no weights of the ladder bring back have none (`wavg inverse --verified`
        // prints `none not-reached`).
        solver
            .inverse_verified_batch(&points, DEFAULT_TOLERANCE)
            .into_iter()
            .map(|r| match r {
                Ok(v) if v.round_trip != RoundTrip::NotReached => json!(v.weights),
                _ => Value::Null,
            })
            .collect()
    } else {
        let batch = solver.inverse_batch(&points);
        batch
            .iter()
            .map(|r| r.map_or(Value::Null, |w| json!(w)))
            .collect()
    };
    Ok(Reply::value(&json!({ "weights": weights })))
}

/// `POST /api/spline` `{"control": [...], "degree": 3, "closed": false, "bezier": false,
/// "samples": 500, "format": "json"}` -> `{"points": [...]}`: the samples of `wavg
/// spline`; `"format": "text"` answers with its output file instead.
pub(crate) fn spline(app: &App, body: body::Spline) -> Result<Reply, ApiError> {
    let solver = solver(app, &body.control, "control", 2)?;
    let kind = if body.bezier.unwrap_or(false) {
        SplineKind::Bezier
    } else {
        SplineKind::BSpline {
            degree: body::in_range("degree", body.degree, DEFAULT_SPLINE_DEGREE, 1, 64)?,
            closed: body.closed.unwrap_or(false),
        }
    };
    let samples = body::in_range(
        "samples",
        body.samples,
        DEFAULT_SPLINE_SAMPLES,
        1,
        MAX_SAMPLES,
    )?;
    let text = body::text_format(body.format.as_deref(), "text")?;
    let curve = evaluate_spline(&solver, kind, samples, SPLINE_CHUNK).map_err(ApiError::lib)?;
    if text {
        return Ok(Reply::text(wavg::lines::points_text(&curve.samples)));
    }
    Reply::serialize(&SplinePoints {
        length: curve.length(),
        points: curve.samples.iter().map(point_row).collect(),
    })
}

/// `POST /api/distance` `{"source": POINT}` -> `{"distances": [per vertex], "max": D}`: the
/// Euclidean distance in the 8-D embedding from the source point to every vertex (an
/// approximation of the geodesic distance).
pub(crate) fn distance(app: &App, body: body::Distance) -> Result<Reply, ApiError> {
    let d = app
        .surface()?
        .embedding_distances(body.source.0)
        .map_err(|e| ApiError::lib(e).within("source"))?;
    let max = d.iter().copied().fold(0.0, f64::max);
    Ok(Reply::value(&json!({ "distances": d, "max": max })))
}
