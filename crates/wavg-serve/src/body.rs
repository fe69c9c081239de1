//! Request bodies as typed structs read by serde. A refusal names the field (and row) that
//! is wrong and what was expected, e.g. `weights[2][0]: invalid type: string "a", expected
//! f64`. Fields other than a route's own are ignored; `null` counts as absent.

use std::fmt;
use std::marker::PhantomData;

use serde::de::{self, Deserialize, DeserializeOwned, Deserializer, SeqAccess, Visitor};
use serde_json::Value;

use crate::points::AnchorIn;
use crate::{ApiError, MAX_ANCHORS, MAX_ROWS};

/// Largest cage (vertices and faces) accepted by `/api/remesh`.
pub(crate) const MAX_CAGE: usize = 20_000;

/// Reads `bytes` as the body `T`: first as JSON (so a number too large for `f64` is refused
/// in any field, as is any syntax error), then as `T`.
pub(crate) fn parse<T: DeserializeOwned>(bytes: &[u8]) -> Result<T, ApiError> {
    let value: Value =
        serde_json::from_slice(bytes).map_err(|e| ApiError::bad(format!("malformed JSON: {e}")))?;
    serde_path_to_error::deserialize(&value).map_err(|e| {
        let path = e.path().to_string();
        match path.as_str() {
            "." => ApiError::bad(format!("the body: {}", e.inner())),
            _ => ApiError::bad(format!("{path}: {}", e.inner())),
        }
    })
}

/// A JSON array of at most `MAX` entries.
#[derive(Clone, Debug, Default, PartialEq)]
pub(crate) struct List<T, const MAX: usize>(pub(crate) Vec<T>);

impl<'de, T: Deserialize<'de>, const MAX: usize> Deserialize<'de> for List<T, MAX> {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        d.deserialize_seq(ListVisitor::<T, MAX>(PhantomData))
    }
}

struct ListVisitor<T, const MAX: usize>(PhantomData<T>);

impl<'de, T: Deserialize<'de>, const MAX: usize> Visitor<'de> for ListVisitor<T, MAX> {
    type Value = List<T, MAX>;

    fn expecting(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "an array of at most {MAX} entries")
    }

    fn visit_seq<A: SeqAccess<'de>>(self, mut seq: A) -> Result<Self::Value, A::Error> {
        let mut out = Vec::with_capacity(seq.size_hint().unwrap_or(0).min(MAX).min(4096));
        while let Some(x) = seq.next_element()? {
            if out.len() == MAX {
                return Err(de::Error::custom(format!(
                    "more than {MAX} entries; at most {MAX} are accepted"
                )));
            }
            out.push(x);
        }
        Ok(List(out))
    }
}

/// Anchors or control points.
pub(crate) type Anchors = List<AnchorIn, MAX_ANCHORS>;

/// `value` (the field `key`, `default` when absent) checked to lie in `min..=max`.
pub(crate) fn in_range(
    key: &str,
    value: Option<usize>,
    default: usize,
    min: usize,
    max: usize,
) -> Result<usize, ApiError> {
    match value.unwrap_or(default) {
        n if (min..=max).contains(&n) => Ok(n),
        _ => Err(ApiError::bad(format!(
            "\"{key}\" must be a whole number from {min} to {max}"
        ))),
    }
}

/// Whether the field `"format"` asks for the command line's file format `name` (else
/// JSON).
pub(crate) fn text_format(format: Option<&str>, name: &str) -> Result<bool, ApiError> {
    match format {
        None | Some("json") => Ok(false),
        Some(f) if f == name => Ok(true),
        Some(f) => Err(ApiError::bad(format!(
            "\"format\" is \"json\" or \"{name}\", not \"{f}\""
        ))),
    }
}

/// `POST /api/forward`.
#[derive(serde::Deserialize)]
#[serde(expecting = "a JSON object {\"anchors\", \"weights\", \"normalize\"}")]
pub(crate) struct Forward {
    pub(crate) anchors: Anchors,
    pub(crate) weights: List<List<f64, MAX_ANCHORS>, MAX_ROWS>,
    pub(crate) normalize: Option<bool>,
}

/// `POST /api/inverse`.
#[derive(serde::Deserialize)]
#[serde(expecting = "a JSON object {\"anchors\", \"points\", \"verified\"}")]
pub(crate) struct Inverse {
    pub(crate) anchors: Anchors,
    pub(crate) points: List<AnchorIn, MAX_ROWS>,
    pub(crate) verified: Option<bool>,
}

/// `POST /api/spline`.
#[derive(serde::Deserialize)]
#[serde(
    expecting = "a JSON object {\"control\", \"degree\", \"closed\", \"bezier\", \"samples\", \"format\"}"
)]
pub(crate) struct Spline {
    pub(crate) control: Anchors,
    pub(crate) degree: Option<usize>,
    pub(crate) closed: Option<bool>,
    pub(crate) bezier: Option<bool>,
    pub(crate) samples: Option<usize>,
    pub(crate) format: Option<String>,
}

/// `POST /api/distance`.
#[derive(serde::Deserialize)]
#[serde(expecting = "a JSON object {\"source\"}")]
pub(crate) struct Distance {
    pub(crate) source: AnchorIn,
}

/// `POST /api/decal`.
#[derive(serde::Deserialize)]
#[serde(expecting = "a JSON object {\"anchors\", \"uv\", \"max_negative\", \"format\"}")]
pub(crate) struct Decal {
    pub(crate) anchors: Anchors,
    pub(crate) uv: List<[f64; 2], MAX_ANCHORS>,
    pub(crate) max_negative: Option<f64>,
    pub(crate) format: Option<String>,
}

/// `POST /api/remesh`.
#[derive(serde::Deserialize)]
#[serde(
    expecting = "a JSON object {\"cage\" or \"base\", \"levels\", \"smooth\", \"max_distance\", \"format\"}"
)]
pub(crate) struct Remesh {
    pub(crate) cage: Option<Cage>,
    pub(crate) base: Option<String>,
    pub(crate) levels: Option<usize>,
    pub(crate) smooth: Option<usize>,
    pub(crate) max_distance: Option<f64>,
    pub(crate) format: Option<String>,
}

/// The `"cage"` of `/api/remesh`: a polygon mesh.
#[derive(serde::Deserialize)]
#[serde(expecting = "{\"vertices\": [[x, y, z], ...], \"faces\": [[i, j, k, ...], ...]}")]
pub(crate) struct Cage {
    pub(crate) vertices: List<[f64; 3], MAX_CAGE>,
    pub(crate) faces: List<List<u32, { wavg::apps::MAX_POLYGON }>, MAX_CAGE>,
}

/// `POST /api/cage`.
#[derive(serde::Deserialize)]
#[serde(expecting = "a JSON object {\"vertices\"}")]
pub(crate) struct CageRequest {
    pub(crate) vertices: Option<usize>,
}

#[cfg(test)]
mod tests {
    use super::*;

    fn refusal<T: DeserializeOwned>(json: &str) -> String {
        match parse::<T>(json.as_bytes()) {
            Ok(_) => panic!("{json} was accepted"),
            Err(e) => {
                assert_eq!(e.status, 400);
                e.message
            }
        }
    }

    #[test]
    fn a_refusal_names_the_field_and_row_and_what_was_expected() {
        for (json, says) in [
            (
                r#"{"anchors": [0, 1], "weights": [[0.5, "a"]]}"#,
                "weights[0][1]: invalid type: string \"a\", expected f64",
            ),
            (r#"{"anchors": [0, 1]}"#, "missing field `weights`"),
            (
                r#"{"anchors": [0, 1], "weights": [], "normalize": "yes"}"#,
                "normalize: invalid type: string \"yes\", expected a boolean",
            ),
            (
                r#"{"anchors": [0, [1, 0.5, 0.5]], "weights": []}"#,
                "anchors[1]: invalid length 3, expected a vertex id or [face, b0, b1, b2]",
            ),
            (
                r#"{"anchors": 5, "weights": []}"#,
                "anchors: invalid type: integer `5`",
            ),
            (
                "[]",
                "expected a JSON object {\"anchors\", \"weights\", \"normalize\"}",
            ),
            ("{", "malformed JSON"),
            (
                r#"{"anchors": [0], "weights": [[1]], "other": 1e999}"#,
                "malformed JSON: number out of range",
            ),
            (
                r#"{"anchors": [], "weights": []} {"#,
                "malformed JSON: trailing characters",
            ),
        ] {
            let m = refusal::<Forward>(json);
            assert!(m.contains(says), "{json}: {m}");
        }
        let m = refusal::<Remesh>(r#"{"cage": {"vertices": [[0, 0]], "faces": []}}"#);
        assert!(
            m.contains("cage.vertices[0]: invalid length 2, expected an array of length 3"),
            "{m}"
        );
        let m = refusal::<Remesh>(r#"{"cage": {"vertices": []}}"#);
        assert!(m.contains("cage: missing field `faces`"), "{m}");
    }

    #[test]
    fn lists_are_cut_off_past_their_limit() {
        let json = format!(
            "{{\"source\": 0, \"control\": {:?}}}",
            vec![0; MAX_ANCHORS + 1]
        );
        let m = refusal::<Spline>(&json);
        assert!(m.contains("control") && m.contains("at most 4096"), "{m}");
        let ok = format!("{{\"control\": {:?}}}", vec![0; MAX_ANCHORS]);
        assert_eq!(
            parse::<Spline>(ok.as_bytes()).unwrap().control.0.len(),
            MAX_ANCHORS
        );
    }

    #[test]
    fn null_is_absent_and_other_fields_are_ignored() {
        let b: Spline =
            parse(br#"{"control": [0, 1], "degree": null, "weights": 5, "format": null}"#).unwrap();
        assert_eq!((b.degree, b.format), (None, None));
        assert_eq!(in_range("degree", b.degree, 3, 1, 64), Ok(3));
        let e = in_range("degree", Some(0), 3, 1, 64).unwrap_err();
        assert_eq!(e.message, "\"degree\" must be a whole number from 1 to 64");
    }
}
