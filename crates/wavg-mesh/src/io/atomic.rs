//! Atomic file output: write to a temporary file beside the destination, flush it to disk,
//! then rename it into place, so an interrupted or failed write (even `SIGKILL`) never
//! leaves a partial file under the final name. A destination that exists and is not a
//! regular file (`/dev/null`, a named pipe, a terminal) is written in place instead:
//! renaming over it would replace the device or pipe with a file.

use std::io::Write;
use std::path::{Path, PathBuf};

/// Whether `path` exists and is neither a regular file nor a directory (a device such as
/// `/dev/null`, a named pipe): such a destination cannot be replaced by a rename, so
/// [`write_atomic`] writes it in place, as the rows come.
pub fn is_special_destination(path: &Path) -> bool {
    std::fs::metadata(path).is_ok_and(|m| !m.is_file() && !m.is_dir())
}

/// Writes `path` atomically with `body`. On any error the destination is untouched and
/// the temporary file is removed (a killed process can leave a `.wavg-tmp-*` file beside
/// the destination, never a partial destination). The result gets the permissions a new
/// file would (0666 minus the umask). A destination that exists and is not a regular file
/// (a device such as `/dev/null`, a named pipe) is opened and written directly.
pub fn write_atomic(
    path: &Path,
    body: impl FnOnce(&mut dyn Write) -> std::io::Result<()>,
) -> std::io::Result<()> {
    // A symbolic link is written through: the file it names is replaced, not the link
    // (`-o /dev/stdout` redirected to a file must not replace `/dev/stdout`).
    let target = link_target(path);
    let path = target.as_deref().unwrap_or(path);
    if is_special_destination(path) {
        let file = std::fs::OpenOptions::new().write(true).open(path)?;
        let mut w = std::io::BufWriter::new(file);
        body(&mut w)?;
        return w.flush();
    }
    let dir: PathBuf = match path.parent() {
        Some(d) if !d.as_os_str().is_empty() => d.to_path_buf(),
        _ => PathBuf::from("."),
    };
    let mut builder = tempfile::Builder::new();
    builder.prefix(".wavg-tmp-");
    #[cfg(unix)]
    {
        use std::os::unix::fs::PermissionsExt;
        builder.permissions(std::fs::Permissions::from_mode(0o666));
    }
    let tmp = builder.tempfile_in(&dir)?;
    {
        let mut w = std::io::BufWriter::new(tmp.as_file());
        body(&mut w)?;
        w.flush()?;
    }
    tmp.as_file().sync_all()?;
    tmp.persist(path).map_err(|e| e.error)?;
    // Make the rename itself durable where the platform allows it (best effort).
    if let Ok(d) = std::fs::File::open(&dir) {
        let _ = d.sync_all();
    }
    Ok(())
}

/// What the symbolic link `path` points to, resolved through every link (for a dangling
/// link, the path its last link names); `None` when `path` is not a link.
fn link_target(path: &Path) -> Option<PathBuf> {
    if !std::fs::symlink_metadata(path).is_ok_and(|m| m.file_type().is_symlink()) {
        return None;
    }
    if let Ok(p) = std::fs::canonicalize(path) {
        return Some(p);
    }
    let mut p = path.to_path_buf();
    // A chain of links to a missing file: follow the names (a bounded number of them).
    for _ in 0..40 {
        let Ok(next) = std::fs::read_link(&p) else {
            break;
        };
        p = match p.parent() {
            Some(dir) if next.is_relative() => dir.join(next),
            _ => next,
        };
    }
    Some(p)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A link is written through: the file it names gets the content, the link stays (also
    /// when that file does not exist yet).
    #[cfg(unix)]
    #[test]
    fn a_symbolic_link_is_written_through() {
        let dir = tempfile::tempdir().unwrap();
        let (file, link) = (dir.path().join("f.txt"), dir.path().join("l.txt"));
        std::os::unix::fs::symlink("f.txt", &link).unwrap();
        for text in [&b"dangling"[..], b"existing"] {
            write_atomic(&link, |w| w.write_all(text)).unwrap();
            assert!(
                std::fs::symlink_metadata(&link)
                    .unwrap()
                    .file_type()
                    .is_symlink()
            );
            assert_eq!(std::fs::read(&file).unwrap(), text);
        }
    }

    #[test]
    fn writes_whole_file_or_nothing() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("out.txt");
        write_atomic(&path, |w| w.write_all(b"hello")).unwrap();
        assert_eq!(std::fs::read(&path).unwrap(), b"hello");
        // A failing body leaves the previous content and no temporary file.
        let err = write_atomic(&path, |w| {
            w.write_all(b"partial")?;
            Err(std::io::Error::other("boom"))
        });
        assert!(err.is_err());
        assert_eq!(std::fs::read(&path).unwrap(), b"hello");
        let names: Vec<_> = std::fs::read_dir(dir.path()).unwrap().collect();
        assert_eq!(names.len(), 1);
    }

    /// Writing to a named pipe writes through it and leaves the pipe in place (a rename
    /// would replace it, or `/dev/null`, with a regular file).
    #[cfg(unix)]
    #[test]
    fn a_named_pipe_is_written_in_place() {
        use std::os::unix::fs::FileTypeExt;
        let dir = tempfile::tempdir().unwrap();
        let fifo = dir.path().join("pipe");
        let made = std::process::Command::new("mkfifo").arg(&fifo).status();
        if !made.is_ok_and(|s| s.success()) {
            eprintln!("skipped: mkfifo is not available");
            return;
        }
        let reader = {
            let fifo = fifo.clone();
            std::thread::spawn(move || std::fs::read(fifo).unwrap())
        };
        write_atomic(&fifo, |w| w.write_all(b"through the pipe")).unwrap();
        // Checked before waiting for the reader, which would wait for ever on a replaced pipe.
        let m = std::fs::symlink_metadata(&fifo).unwrap();
        assert!(m.file_type().is_fifo(), "the pipe was replaced by a file");
        assert_eq!(reader.join().unwrap(), b"through the pipe");
        let names: Vec<_> = std::fs::read_dir(dir.path()).unwrap().collect();
        assert_eq!(names.len(), 1, "no temporary file is left");
    }
}
