//! [`Reply`]: what a route answers, before the HTTP side writes it.

use serde::Serialize;
use serde_json::Value;

use crate::ApiError;

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
        Self::bytes("application/json", body)
    }

    /// 200 with a body of any type.
    pub(crate) fn bytes(content_type: &'static str, body: Vec<u8>) -> Self {
        Self {
            status: 200,
            content_type,
            body,
            compute_ms: None,
            total_ms: None,
        }
    }

    /// 200 with a JSON value.
    pub(crate) fn value(v: &Value) -> Self {
        Self::json(v.to_string().into_bytes())
    }

    /// 200 with `answer` written as JSON without an intermediate `Value` tree.
    pub(crate) fn serialize(answer: &impl Serialize) -> Result<Self, ApiError> {
        serde_json::to_vec(answer)
            .map(Self::json)
            .map_err(|e| ApiError::status(500, format!("the answer could not be written: {e}")))
    }

    /// 200 with plain text (the command line's file formats).
    pub(crate) fn text(body: Vec<u8>) -> Self {
        Self::bytes("text/plain; charset=utf-8", body)
    }

    /// An error as `{"error": MESSAGE}` with its status.
    pub(crate) fn error(e: &ApiError) -> Self {
        let body = serde_json::json!({ "error": e.message }).to_string();
        Self {
            status: e.status,
            ..Self::json(body.into_bytes())
        }
    }
}
