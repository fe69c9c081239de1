//! The command line's use of the point and weight files (the formats are described and
//! parsed in `wavg::text`): reading them with errors located as `file:line`, the problem
//! they pose (mesh, embedding, anchors), and atomic output files.

mod files;
mod parse;
mod problem;

pub use files::{located, read_points, read_text, write_atomic, write_numbers};
pub use parse::{FORMAT_HELP, PointSpec};
pub use problem::{
    ProblemArgs, build_projector, load_embedded, load_solver, resolve_points, with_threads,
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
