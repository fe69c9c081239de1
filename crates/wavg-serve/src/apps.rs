//! The application routes: decals, semiregular remeshing and the coarse cage the page
//! starts remeshing from.

use serde_json::{Value, json};
use wavg::apps::{BaseMesh, Remesher, decal_vertices, polygons_to_obj, write_decal_obj};
use wavg::{DecimateOptions, NoProgress, Vector3};

use crate::parse::{self, Body};
use crate::problems::text_format;
use crate::routes::Reply;
use crate::{ApiError, App, MAX_ANCHORS};

/// `POST /api/decal` `{"anchors": [...], "uv": [[u, v], ...], "max_negative": -0.1,
/// "format": "json"}` -> `{"uv": [[u, v] per vertex], "marked": [vertex ids], "report":
/// {...}}` as `wavg decal` computes them; `"format": "obj"` answers with its OBJ.
pub(crate) fn decal(app: &App, body: &Body) -> Result<Reply, ApiError> {
    let surface = app.surface()?;
    let anchors = parse::anchors(body.required("anchors")?, "anchors", surface.mesh(), 1)?;
    let rows = parse::array(body.required("uv")?, "uv", MAX_ANCHORS)?;
    if rows.len() != anchors.len() {
        return Err(ApiError::bad(format!(
            "\"uv\" has {} pairs for {} anchors; give one per anchor",
            rows.len(),
            anchors.len()
        )));
    }
    let uv = rows
        .iter()
        .enumerate()
        .map(
            |(i, r)| match parse::numbers(r, &format!("uv[{i}]"), 2)?[..] {
                [u, v] => Ok([u, v]),
                _ => Err(ApiError::bad(format!("uv[{i}] must be [u, v]"))),
            },
        )
        .collect::<Result<Vec<_>, _>>()?;
    let max_negative = body.f64_or("max_negative", -0.1)?;
    let obj = text_format(body, "obj")?;
    let solver = surface
        .solver(anchors)
        .map_err(|e| ApiError::from_lib(&e))?;
    let d = decal_vertices(&solver, &uv, max_negative).map_err(|e| ApiError::from_lib(&e))?;
    let mesh = surface.mesh();
    if obj {
        let mut out = Vec::new();
        write_decal_obj(&mut out, mesh, &d.uv, None).map_err(|e| ApiError::bad(e.to_string()))?;
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
pub(crate) fn remesh(app: &App, body: &Body) -> Result<Reply, ApiError> {
    let surface = app.surface()?;
    let base = match (body.optional("cage"), body.str("base")?) {
        (Some(c), None) => cage_json(c)?,
        (None, Some(text)) => BaseMesh::from_obj_str(text).map_err(|e| ApiError::from_lib(&e))?,
        _ => return Err(ApiError::bad("give exactly one of \"cage\" and \"base\"")),
    };
    let levels = body.usize_or("levels", 2, 0, wavg::apps::MAX_LEVELS.min(5))?;
    let corners: usize = base.faces.iter().map(Vec::len).sum();
    let faces = corners.saturating_mul(4usize.pow(levels.saturating_sub(1) as u32));
    if faces > crate::MAX_FACES {
        return Err(ApiError::bad(format!(
            "{levels} levels on this base make about {faces} faces, more than {} in one \
             answer: use fewer levels or a smaller base",
            crate::MAX_FACES
        )));
    }
    base.validate().map_err(|e| ApiError::from_lib(&e))?;
    let smooth = body.usize_or("smooth", 3, 0, wavg::apps::MAX_SMOOTH_STEPS)?;
    let max_distance = body.f64_or("max_distance", wavg::apps::DEFAULT_MAX_BASE_DISTANCE)?;
    let obj = text_format(body, "obj")?;
    let mut r = Remesher::with_max_distance(surface.projector().clone(), &base, max_distance)
        .map_err(|e| ApiError::from_lib(&e))?;
    let out = r
        .remesh(levels, smooth)
        .map_err(|e| ApiError::from_lib(&e))?;
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

/// Largest cage (vertices and faces) accepted.
const MAX_CAGE: usize = 20_000;

/// `{"vertices": [[x, y, z], ...], "faces": [[i, j, k, ...], ...]}` as a base mesh.
fn cage_json(v: &Value) -> Result<BaseMesh, ApiError> {
    let Value::Object(m) = v else {
        return Err(ApiError::bad(
            "\"cage\" must be {\"vertices\": [...], \"faces\": [...]}",
        ));
    };
    let get = |k: &str| {
        m.get(k)
            .ok_or_else(|| ApiError::bad(format!("\"cage\" has no \"{k}\"")))
    };
    let positions = parse::array(get("vertices")?, "cage.vertices", MAX_CAGE)?
        .iter()
        .enumerate()
        .map(
            |(i, p)| match parse::numbers(p, &format!("cage.vertices[{i}]"), 3)?[..] {
                [x, y, z] => Ok(Vector3::new(x, y, z)),
                _ => Err(ApiError::bad(format!(
                    "cage.vertices[{i}] must be [x, y, z]"
                ))),
            },
        )
        .collect::<Result<Vec<_>, _>>()?;
    let faces = parse::array(get("faces")?, "cage.faces", MAX_CAGE)?
        .iter()
        .enumerate()
        .map(|(i, f)| {
            let what = format!("cage.faces[{i}]");
            parse::array(f, &what, wavg::apps::MAX_POLYGON)?
                .iter()
                .map(|x| {
                    x.as_u64()
                        .and_then(|x| u32::try_from(x).ok())
                        .ok_or_else(|| ApiError::bad(format!("{what}: vertex ids are integers")))
                })
                .collect::<Result<Vec<u32>, _>>()
        })
        .collect::<Result<Vec<_>, _>>()?;
    Ok(BaseMesh { positions, faces })
}

/// `POST /api/cage` `{"vertices": 40}` -> `{"vertices": [[x, y, z], ...], "faces": [[i, j,
/// k], ...]}`: the mesh decimated to that many vertices, a starting cage for remeshing.
pub(crate) fn cage(app: &App, body: &Body) -> Result<Reply, ApiError> {
    let surface = app.mesh_surface();
    let max = surface.n_vertices().clamp(4, 5000);
    let target = body.usize_or("vertices", 40.min(max), 4, max)?;
    let opts = DecimateOptions {
        target,
        ..Default::default()
    };
    let d = surface
        .decimate(&opts, &NoProgress)
        .map_err(|e| ApiError::from_lib(&e))?;
    let m = d.surface.mesh();
    let vertices: Vec<[f64; 3]> = m.positions.iter().map(|p| [p.x, p.y, p.z]).collect();
    Ok(Reply::value(
        &json!({ "vertices": vertices, "faces": m.triangles }),
    ))
}
