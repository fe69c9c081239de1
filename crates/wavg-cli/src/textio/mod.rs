//! The plain-text formats of `wavg forward` / `wavg inverse` and atomic output files.
//!
//! Input files have one item per line. `#` starts a comment that runs to the end of the
//! line; blank (or comment-only) lines are skipped. Line numbers in errors count every
//! physical line from 1.
//!
//! * Surface points (anchors, query points): `v VERTEX` (a mesh vertex, 0-based) or
//!   `f FACE B0 B1 B2` (0-based face, barycentric coordinates of its three corners).
//! * Weights: whitespace-separated decimal numbers, one query per line.

mod files;
mod parse;
mod problem;

pub use files::{located, read_points, read_text, write_atomic, write_numbers};
pub use parse::{FORMAT_HELP, PointSpec, parse_points, parse_weights};
pub use problem::{
    ProblemArgs, build_projector, load_embedded, load_solver, resolve_points, spec_anchor,
    with_threads,
};

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn parses_points_with_comments_and_blank_lines() {
        let t = "# anchors\n\nv 3\n  f 2 0.25 0.25 0.5   # inline\nv 0\n";
        let p = parse_points(t).unwrap();
        assert_eq!(
            p,
            vec![
                (3, PointSpec::Vertex(3)),
                (
                    4,
                    PointSpec::Face {
                        face: 2,
                        bary: [0.25, 0.25, 0.5]
                    }
                ),
                (5, PointSpec::Vertex(0)),
            ]
        );
    }

    #[test]
    fn point_errors_name_the_line() {
        for (t, line, needle) in [
            ("v 1\nv -1\n", 2, "non-negative integer"),
            ("v 1\n\nq 3\n", 3, "expected 'v VERTEX'"),
            ("f 1 0.5 0.5\n", 1, "takes 4 values"),
            ("v 1 2\n", 1, "takes 1 value"),
            ("f 1 0.5 nan 0.5\n", 1, "not finite"),
            ("f 1 0.5 x 0.5\n", 1, "not a number"),
            ("v 1.5\n", 1, "non-negative integer"),
        ] {
            let e = parse_points(t).unwrap_err();
            assert_eq!(e.line, line, "{t:?}");
            assert!(e.message.contains(needle), "{t:?}: {}", e.message);
        }
    }

    #[test]
    fn parses_weights() {
        let w = parse_weights("0.5 0.5\n# c\n1e-1\t0.9\n").unwrap();
        assert_eq!(w, vec![(1, vec![0.5, 0.5]), (3, vec![0.1, 0.9])]);
        let e = parse_weights("0.5 0.5\n0.5 inf\n").unwrap_err();
        assert_eq!(e.line, 2);
        assert!(e.message.contains("weight 1"));
    }

    #[test]
    fn atomic_write_leaves_nothing_on_error() {
        let dir = tempfile::tempdir().unwrap();
        let out = dir.path().join("out.txt");
        let r = write_atomic(&out, |w| {
            w.write_all(b"half")?;
            Err(std::io::Error::other("boom"))
        });
        assert!(r.is_err());
        assert!(!out.exists());
        assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 0);
        write_atomic(&out, |w| write_numbers(w, [1.0, 0.1, -2.5e-300])).unwrap();
        assert_eq!(std::fs::read_to_string(&out).unwrap(), "1.0 0.1 -2.5e-300");
    }
}
