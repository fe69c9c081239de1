//! Reading request bodies: JSON objects whose fields are checked one by one, so every bad
//! request gets a message naming the field (and row) that is wrong.

use serde_json::{Map, Value};
use wavg::{Anchor, SurfacePoint, ValidMesh};

use crate::ApiError;

/// A request body parsed as a JSON object.
pub(crate) struct Body(Map<String, Value>);

impl Body {
    /// Parses `bytes` as one JSON object.
    pub(crate) fn parse(bytes: &[u8]) -> Result<Self, ApiError> {
        let v: Value = serde_json::from_slice(bytes)
            .map_err(|e| ApiError::bad(format!("malformed JSON: {e}")))?;
        match v {
            Value::Object(m) => Ok(Self(m)),
            _ => Err(ApiError::bad("the body must be a JSON object")),
        }
    }

    /// The field `key`, which must be present.
    pub(crate) fn required(&self, key: &str) -> Result<&Value, ApiError> {
        self.0
            .get(key)
            .ok_or_else(|| ApiError::bad(format!("missing field \"{key}\"")))
    }

    /// The field `key` unless absent or null.
    pub(crate) fn optional(&self, key: &str) -> Option<&Value> {
        self.0.get(key).filter(|v| !v.is_null())
    }

    /// A boolean field, `default` when absent.
    pub(crate) fn bool_or(&self, key: &str, default: bool) -> Result<bool, ApiError> {
        match self.optional(key) {
            None => Ok(default),
            Some(Value::Bool(b)) => Ok(*b),
            Some(_) => Err(ApiError::bad(format!("\"{key}\" must be true or false"))),
        }
    }

    /// A whole-number field from `min` to `max`, `default` when absent.
    pub(crate) fn usize_or(
        &self,
        key: &str,
        default: usize,
        min: usize,
        max: usize,
    ) -> Result<usize, ApiError> {
        let Some(v) = self.optional(key) else {
            return Ok(default);
        };
        match v.as_u64() {
            Some(n) if (min as u64..=max as u64).contains(&n) => Ok(n as usize),
            _ => Err(ApiError::bad(format!(
                "\"{key}\" must be a whole number from {min} to {max}"
            ))),
        }
    }

    /// A finite number field, `default` when absent.
    pub(crate) fn f64_or(&self, key: &str, default: f64) -> Result<f64, ApiError> {
        match self.optional(key) {
            None => Ok(default),
            Some(v) => number(v, key),
        }
    }

    /// The string field `key`, if present.
    pub(crate) fn str(&self, key: &str) -> Result<Option<&str>, ApiError> {
        match self.optional(key) {
            None => Ok(None),
            Some(Value::String(s)) => Ok(Some(s)),
            Some(_) => Err(ApiError::bad(format!("\"{key}\" must be a string"))),
        }
    }
}

/// A finite number (`what` names it in the message).
pub(crate) fn number(v: &Value, what: &str) -> Result<f64, ApiError> {
    match v.as_f64() {
        Some(x) if x.is_finite() => Ok(x),
        _ => Err(ApiError::bad(format!("{what} must be a finite number"))),
    }
}

/// An array (`what` names it in the message), at most `max` long.
pub(crate) fn array<'a>(v: &'a Value, what: &str, max: usize) -> Result<&'a [Value], ApiError> {
    match v {
        Value::Array(a) if a.len() <= max => Ok(a),
        Value::Array(a) => Err(ApiError::bad(format!(
            "{what} has {} entries; at most {max} are accepted",
            a.len()
        ))),
        _ => Err(ApiError::bad(format!("{what} must be an array"))),
    }
}

/// An array of finite numbers.
pub(crate) fn numbers(v: &Value, what: &str, max: usize) -> Result<Vec<f64>, ApiError> {
    array(v, what, max)?
        .iter()
        .enumerate()
        .map(|(i, x)| number(x, &format!("{what}[{i}]")))
        .collect()
}

/// A vertex id or `[face, b0, b1, b2]`, checked against the mesh (face and vertex in
/// range, barycentric coordinates finite and summing to 1 as the library requires).
pub(crate) fn anchor(v: &Value, what: &str, mesh: &ValidMesh) -> Result<Anchor, ApiError> {
    let a = match v {
        Value::Number(n) => match n.as_u64().and_then(|x| u32::try_from(x).ok()) {
            Some(id) => Anchor::Vertex(id),
            None => {
                return Err(ApiError::bad(format!(
                    "{what}: a vertex id must be a non-negative integer, got {n}"
                )));
            }
        },
        Value::Array(a) if a.len() == 4 => {
            let face = a[0]
                .as_u64()
                .and_then(|x| u32::try_from(x).ok())
                .ok_or_else(|| {
                    ApiError::bad(format!("{what}: the face must be a non-negative integer"))
                })?;
            let mut bary = [0.0; 3];
            for (k, b) in bary.iter_mut().enumerate() {
                *b = number(&a[k + 1], &format!("{what}: barycentric coordinate {k}"))?;
            }
            Anchor::Point(SurfacePoint::new(face, bary))
        }
        _ => {
            return Err(ApiError::bad(format!(
                "{what} must be a vertex id or [face, b0, b1, b2]"
            )));
        }
    };
    wavg::resolve_anchor(mesh, &a).map_err(|e| ApiError::bad(format!("{what}: {e}")))?;
    Ok(a)
}

/// A list of anchors (at least `min`).
pub(crate) fn anchors(
    v: &Value,
    what: &str,
    mesh: &ValidMesh,
    min: usize,
) -> Result<Vec<Anchor>, ApiError> {
    let list = array(v, what, crate::MAX_ANCHORS)?;
    if list.len() < min {
        return Err(ApiError::bad(format!(
            "{what} needs at least {min} entries, got {}",
            list.len()
        )));
    }
    list.iter()
        .enumerate()
        .map(|(i, a)| anchor(a, &format!("{what}[{i}]"), mesh))
        .collect()
}

/// A surface point (vertex id or `[face, b0, b1, b2]`) resolved to a face and barycentric
/// coordinates.
pub(crate) fn point(v: &Value, what: &str, mesh: &ValidMesh) -> Result<SurfacePoint, ApiError> {
    let a = anchor(v, what, mesh)?;
    wavg::resolve_anchor(mesh, &a).map_err(|e| ApiError::bad(format!("{what}: {e}")))
}
