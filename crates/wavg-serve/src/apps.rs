//! The application routes: decals, semiregular remeshing and the coarse cage the page
//! starts remeshing from.

use serde_json::{Value, json};
use wavg::apps::{
    BaseMesh, DEFAULT_LEVELS, DEFAULT_MAX_NEGATIVE, DEFAULT_SMOOTH_STEPS, MIN_CAGE_VERTICES,
    Remesher, decal_vertices, default_cage_vertices, max_cage_vertices, polygons_to_obj,
    write_decal_obj,
};
use wavg::{DecimateOptions, NoProgress, Vector3};

use crate::body::{self, text_format};
use crate::reply::Reply;
use crate::{ApiError, App, points};

/// `POST /api/decal` `{"anchors": [...], "uv": [[u, v], ...], "max_negative": -0.1,
/// "format": "json"}` -> `{"uv": [[u, v] per vertex], "marked": [vertex ids], "report":
/// {...}}` as `wavg decal` computes them; `"format": "obj"` answers with its OBJ.
pub(crate) fn decal(app: &App, body: body::Decal) -> Result<Reply, ApiError> {
    let surface = app.surface()?;
    let anchors = points::anchors(&body.anchors.0, "anchors", surface.mesh(), 1)?;
    let uv = body.uv.0;
    if uv.len() != anchors.len() {
        return Err(ApiError::bad(format!(
            "\"uv\" has {} pairs for {} anchors; give one per anchor",
            uv.len(),
            anchors.len()
        )));
    }
    let max_negative = body.max_negative.unwrap_or(DEFAULT_MAX_NEGATIVE);
    let obj = text_format(body.format.as_deref(), "obj")?;
    let solver = surface.solver(anchors).map_err(ApiError::lib)?;
    let d = decal_vertices(&solver, &uv, max_negative).map_err(ApiError::lib)?;
    let mesh = surface.mesh();
    if obj {
        let mut out = Vec::new();
        write_decal_obj(&mut out, mesh, &d.uv, None)
            .map_err(|e| ApiError::status(500, format!("the OBJ could not be written: {e}")))?;
        return Ok(Reply::text(out));
    }
    let marked: Vec<usize> = (0..mesh.n_vertices()).filter(|&v| d.uv.marked[v]).collect();
    Ok(Reply::value(&json!({
        "uv": d.uv.uv,
        "marked": marked,
        "report": d.report(),
    })))
}

/// `POST /api/remesh` `{"cage": {"vertices": [[x, y, z], ...], "faces": [[i, j, k, ...],
/// ...]}, "levels": 2, "smooth": 3, "max_distance": 0.15, "format": "json"}` ->
/// `{"vertices": [[x, y, z], ...], "faces": [[...], ...], "cage": [POINT per cage vertex],
/// "report": {...}}` as `wavg remesh` computes them (`"base": "OBJ TEXT"` may replace
/// `"cage"`); `"format": "obj"` answers with its OBJ.
pub(crate) fn remesh(app: &App, body: body::Remesh) -> Result<Reply, ApiError> {
    let surface = app.surface()?;
    let base = match (body.cage, body.base) {
        (Some(c), None) => BaseMesh {
            positions: c.vertices.0.iter().map(|&p| Vector3::from(p)).collect(),
            faces: c.faces.0.into_iter().map(|f| f.0).collect(),
        },
        (None, Some(text)) => BaseMesh::from_obj_str(&text).map_err(ApiError::lib)?,
        _ => return Err(ApiError::bad("give exactly one of \"cage\" and \"base\"")),
    };
    let levels = body::in_range(
        "levels",
        body.levels,
        DEFAULT_LEVELS,
        0,
        wavg::apps::MAX_LEVELS.min(crate::MAX_REMESH_LEVELS),
    )?;
    base.check_size(levels, crate::MAX_FACES)
        .map_err(ApiError::lib)?;
    base.validate().map_err(ApiError::lib)?;
    let smooth = body::in_range(
        "smooth",
        body.smooth,
        DEFAULT_SMOOTH_STEPS,
        0,
        wavg::apps::MAX_SMOOTH_STEPS,
    )?;
    let max_distance = body
        .max_distance
        .unwrap_or(wavg::apps::DEFAULT_MAX_BASE_DISTANCE);
    let obj = text_format(body.format.as_deref(), "obj")?;
    let mut r = Remesher::with_max_distance(surface.projector().clone(), &base, max_distance)
        .map_err(ApiError::lib)?;
    let out = r.remesh(levels, smooth).map_err(ApiError::lib)?;
    if obj {
        return Ok(Reply::text(
            polygons_to_obj(&out.positions, &out.faces).into_bytes(),
        ));
    }
    let mesh = surface.mesh();
    let cage: Vec<Value> = r
        .base_points()
        .iter()
        .map(|p| {
            let x = p.position(mesh);
            json!([p.face, p.bary[0], p.bary[1], p.bary[2], x.x, x.y, x.z])
        })
        .collect();
    let vertices: Vec<[f64; 3]> = out.positions.iter().map(|p| [p.x, p.y, p.z]).collect();
    Ok(Reply::value(&json!({
        "vertices": vertices,
        "faces": *out.faces,
        "cage": cage,
        "report": r.report(&out),
    })))
}

/// `POST /api/cage` `{"vertices": 40}` -> `{"vertices": [[x, y, z], ...], "faces": [[i, j,
/// k], ...]}`: the mesh decimated to that many vertices, a starting cage for remeshing.
pub(crate) fn cage(app: &App, body: body::CageRequest) -> Result<Reply, ApiError> {
    let surface = app.mesh_surface();
    let n = surface.n_vertices();
    let target = body::in_range(
        "vertices",
        body.vertices,
        default_cage_vertices(n),
        MIN_CAGE_VERTICES,
        max_cage_vertices(n),
    )?;
    let opts = DecimateOptions {
        target,
        ..Default::default()
    };
    let d = surface
        .decimate(&opts, &NoProgress)
        .map_err(ApiError::lib)?;
    let m = d.surface.mesh();
    let vertices: Vec<[f64; 3]> = m.positions.iter().map(|p| [p.x, p.y, p.z]).collect();
    Ok(Reply::value(
        &json!({ "vertices": vertices, "faces": m.triangles }),
    ))
}
