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
pub use parse::{FORMAT_HELP, PointSpec};
pub use problem::{
    ProblemArgs, build_projector, load_embedded, load_solver, resolve_points, spec_anchor,
    with_threads,
};

#[cfg(test)]
mod tests {
    use super::*;

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
