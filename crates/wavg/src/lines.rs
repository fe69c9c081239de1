//! Answers as lines of the text formats, written the same way by every front end that
//! writes them (`wavg forward`, `wavg spline`, `wavg correspond`, `wavg demo`, `wavg
//! serve`'s `/api/spline`): a surface point `FACE B0 B1 B2 X Y Z`, or `none REASON` where
//! there is no answer.

use wavg_apps::{Correspondence, Validity};
use wavg_solve::{ForwardResult, SolveError};

use crate::Error;

/// The one-line reason of a `none` line: the error's [`Error::message`].
pub fn reason(e: &SolveError) -> String {
    Error::from(e.clone()).message()
}

/// Appends the line of one answer, without its line break: the point `FACE B0 B1 B2 X Y Z`
/// (shortest round-trip numbers), or `none REASON` with the given one-word or one-line
/// reason.
pub fn push_answer(out: &mut Vec<u8>, answer: Result<&ForwardResult, &str>) {
    match answer {
        Ok(r) => {
            out.extend_from_slice(r.point.face.to_string().as_bytes());
            out.push(b' ');
            wavg_io::text::push_numbers(
                out,
                r.point.bary.into_iter().chain(r.position.iter().copied()),
            );
        }
        Err(why) => {
            out.extend_from_slice(b"none ");
            out.extend_from_slice(why.as_bytes());
        }
    }
}

/// Appends the line of one forward result, without its line break: `FACE B0 B1 B2 X Y Z`
/// (shortest round-trip numbers), or `none REASON` with the error's [`reason`].
pub fn push_point(out: &mut Vec<u8>, r: &Result<ForwardResult, SolveError>) {
    match r {
        Ok(r) => push_answer(out, Ok(r)),
        Err(e) => push_answer(out, Err(&reason(e))),
    }
}

/// The text of a correspondence map (`wavg correspond`'s output file): one line per source
/// vertex, its image on the target, or `none REASON` with the [`Validity::reason`] of a
/// vertex that is not kept.
pub fn correspondence_text(map: &Correspondence) -> Vec<u8> {
    let mut out = Vec::new();
    for (m, v) in map.mapped.iter().zip(&map.validity) {
        match (v, &m.target) {
            (Validity::Valid, Ok(r)) => push_answer(&mut out, Ok(r)),
            (v, _) => push_answer(&mut out, Err(v.reason())),
        }
        out.push(b'\n');
    }
    out
}

/// The lines of a sequence of forward results (a spline's samples), each ended by a line
/// break: the text of a `wavg spline` output file.
pub fn points_text(results: &[Result<ForwardResult, SolveError>]) -> Vec<u8> {
    let mut out = Vec::new();
    for r in results {
        push_point(&mut out, r);
        out.push(b'\n');
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::Surface;

    #[test]
    fn points_and_missing_answers_have_one_line_each() {
        let s = Surface::from_mesh(wavg_mesh::procedural::icosphere(2)).unwrap();
        let solver = s.solver([0u32, 5, 9]).unwrap();
        let r = solver.forward(&[0.2, 0.3, 0.5], &Default::default());
        let p = *r.as_ref().unwrap();
        let text = points_text(&[r, Err(SolveError::NoWeightedAverage)]);
        let text = String::from_utf8(text).unwrap();
        assert!(text.ends_with('\n'));
        let lines: Vec<&str> = text.lines().collect();
        assert_eq!(lines.len(), 2);
        let fields: Vec<&str> = lines[0].split(' ').collect();
        assert_eq!(fields.len(), 7, "{}", lines[0]);
        assert_eq!(fields[0], p.point.face.to_string());
        let numbers: Vec<f64> = fields[1..].iter().map(|f| f.parse().unwrap()).collect();
        let expected: Vec<f64> = p
            .point
            .bary
            .into_iter()
            .chain(p.position.iter().copied())
            .collect();
        assert_eq!(
            numbers, expected,
            "shortest round-trip numbers read back exactly"
        );
        assert_eq!(
            lines[1],
            format!("none {}", reason(&SolveError::NoWeightedAverage))
        );
        assert!(!lines[1]["none ".len()..].is_empty());
    }

    #[test]
    fn correspondence_lines_keep_valid_images_and_name_the_others_reason() {
        let s = Surface::from_mesh(wavg_mesh::procedural::icosphere(2)).unwrap();
        let solver = s.solver([0u32, 5, 9]).unwrap();
        let r = solver.forward(&[0.2, 0.3, 0.5], &Default::default());
        let mapped = |target| wavg_apps::Mapped {
            target,
            round_trip: true,
            min_weight: 0.0,
        };
        let map = Correspondence {
            mapped: vec![mapped(r.clone()), mapped(r.clone()), mapped(r.clone())],
            validity: vec![
                Validity::Valid,
                Validity::NoRoundTrip,
                Validity::Inconsistent,
            ],
            distortion: wavg_apps::distortion(&[], &[], &[], &[]),
            timings: Default::default(),
        };
        let text = String::from_utf8(correspondence_text(&map)).unwrap();
        let lines: Vec<&str> = text.lines().collect();
        assert!(text.ends_with('\n'));
        assert_eq!(
            lines[0],
            String::from_utf8(points_text(&[r])).unwrap().trim_end()
        );
        assert_eq!(lines[1..], ["none no-round-trip", "none inconsistent"]);
    }
}
