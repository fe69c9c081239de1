//! Points and anchors as requests send them: a vertex id or `[face, b0, b1, b2]`, read by
//! serde and then checked against the mesh by the library.

use std::fmt;

use serde::de::{self, Deserialize, Deserializer, IgnoredAny, SeqAccess, Visitor};
use wavg::{Anchor, SurfacePoint, ValidMesh};

use crate::ApiError;

/// A vertex id or `[face, b0, b1, b2]`, not yet checked against the mesh.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct AnchorIn(pub(crate) Anchor);

impl<'de> Deserialize<'de> for AnchorIn {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        d.deserialize_any(AnchorVisitor)
    }
}

struct AnchorVisitor;

impl AnchorVisitor {
    fn not_a_vertex<E: de::Error>(shown: impl fmt::Display) -> E {
        E::custom(format!(
            "a vertex id must be a non-negative integer below 2^32, got {shown}"
        ))
    }
}

impl<'de> Visitor<'de> for AnchorVisitor {
    type Value = AnchorIn;

    fn expecting(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str("a vertex id or [face, b0, b1, b2]")
    }

    fn visit_u64<E: de::Error>(self, v: u64) -> Result<AnchorIn, E> {
        u32::try_from(v)
            .map(|id| AnchorIn(Anchor::Vertex(id)))
            .map_err(|_| Self::not_a_vertex(v))
    }

    fn visit_i64<E: de::Error>(self, v: i64) -> Result<AnchorIn, E> {
        match u64::try_from(v) {
            Ok(v) => self.visit_u64(v),
            Err(_) => Err(Self::not_a_vertex(v)),
        }
    }

    fn visit_f64<E: de::Error>(self, v: f64) -> Result<AnchorIn, E> {
        Err(Self::not_a_vertex(v))
    }

    fn visit_seq<A: SeqAccess<'de>>(self, mut seq: A) -> Result<AnchorIn, A::Error> {
        let face: u32 = seq
            .next_element()?
            .ok_or_else(|| de::Error::invalid_length(0, &self))?;
        let mut bary = [0.0; 3];
        for (k, b) in bary.iter_mut().enumerate() {
            *b = seq
                .next_element()?
                .ok_or_else(|| de::Error::invalid_length(k + 1, &self))?;
        }
        if seq.next_element::<IgnoredAny>()?.is_some() {
            return Err(de::Error::invalid_length(5, &self));
        }
        Ok(AnchorIn(Anchor::Point(SurfacePoint::new(face, bary))))
    }
}

/// `list` (the field `what`) checked against `mesh`: at least `min` entries, faces and
/// vertices in range, barycentric coordinates summing to 1 as the library requires.
pub(crate) fn anchors(
    list: &[AnchorIn],
    what: &str,
    mesh: &ValidMesh,
    min: usize,
) -> Result<Vec<Anchor>, ApiError> {
    if list.len() < min {
        return Err(ApiError::bad(format!(
            "{what} needs at least {min} entries, got {}",
            list.len()
        )));
    }
    list.iter()
        .enumerate()
        .map(|(i, a)| point(a, &format!("{what}[{i}]"), mesh).map(|_| a.0))
        .collect()
}

/// `a` (the field `what`) resolved on `mesh` to a face and barycentric coordinates.
pub(crate) fn point(a: &AnchorIn, what: &str, mesh: &ValidMesh) -> Result<SurfacePoint, ApiError> {
    wavg::resolve_anchor(mesh, &a.0).map_err(|e| ApiError::lib(e).within(what))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn read(json: &str) -> Result<AnchorIn, String> {
        serde_json::from_str(json).map_err(|e| e.to_string())
    }

    #[test]
    fn vertex_ids_and_barycentric_points_are_read() {
        assert_eq!(read("7").unwrap().0, Anchor::Vertex(7));
        assert_eq!(
            read("[3, 0.25, 0.25, 0.5]").unwrap().0,
            Anchor::Point(SurfacePoint::new(3, [0.25, 0.25, 0.5]))
        );
    }

    #[test]
    fn anything_else_is_refused_with_what_was_expected() {
        for (json, says) in [
            ("-1", "non-negative integer"),
            ("1.5", "non-negative integer"),
            ("4294967296", "below 2^32"),
            ("[0, 1.0, 0.0]", "[face, b0, b1, b2]"),
            ("[0, 1.0, 0.0, 0.0, 0.0]", "[face, b0, b1, b2]"),
            ("[\"x\", 1.0, 0.0, 0.0]", "u32"),
            ("[0, \"a\", 0.5, 0.5]", "f64"),
            ("\"a\"", "a vertex id or [face, b0, b1, b2]"),
            ("null", "a vertex id or [face, b0, b1, b2]"),
        ] {
            let e = read(json).unwrap_err();
            assert!(e.contains(says), "{json}: {e}");
        }
    }
}
