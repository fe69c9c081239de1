//! Atomic file output: write to a temporary file beside the destination, flush it to disk,
//! then rename it into place, so an interrupted or failed write (even `SIGKILL`) never
//! leaves a partial file under the final name. A destination that exists and is not a
//! regular file (`/dev/null`, a named pipe, a terminal) is written in place instead:
//! renaming over it would replace the device or pipe with a file.
//!
//! The temporary file is named `.wavg-tmp-PID-XXXXXX` after the writing process, so a
//! later write into the same folder can remove what a killed writer left (see
//! [`remove_stale_temporaries`]).

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
/// the destination, never a partial destination; the next write into that folder removes
/// it: [`remove_stale_temporaries`]). The result gets the permissions a new
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
    remove_stale_temporaries(&dir);
    let mut builder = tempfile::Builder::new();
    let prefix = format!("{TEMP_PREFIX}{}-", std::process::id());
    builder.prefix(&prefix);
    #[cfg(unix)]
    {
        use std::os::unix::fs::PermissionsExt;
        builder.permissions(std::fs::Permissions::from_mode(0o666));
    }
    let tmp = builder.tempfile_in(&dir).map_err(without_temporary)?;
    {
        let mut w = std::io::BufWriter::new(tmp.as_file());
        body(&mut w)?;
        w.flush()?;
    }
    tmp.as_file().sync_all()?;
    tmp.persist(path).map_err(|e| without_temporary(e.error))?;
    // Make the rename itself durable where the platform allows it (best effort).
    if let Ok(d) = std::fs::File::open(&dir) {
        let _ = d.sync_all();
    }
    Ok(())
}

/// `e` without the temporary file's path that tempfile appends to its message (`... at
/// path ".wavg-tmp-..."`): callers name the destination the user asked for, which is all
/// the user knows of.
fn without_temporary(e: std::io::Error) -> std::io::Error {
    if e.raw_os_error().is_some() {
        return e;
    }
    let text = e.to_string();
    match text.find(" at path ") {
        Some(i) if text.contains(TEMP_PREFIX) => std::io::Error::new(e.kind(), &text[..i]),
        _ => e,
    }
}

/// How every temporary file of [`write_atomic`] starts, before the writer's process id.
pub const TEMP_PREFIX: &str = ".wavg-tmp-";

/// A temporary file untouched for this long, whose writer is gone, is stale.
const STALE_AFTER: std::time::Duration = std::time::Duration::from_secs(60);

/// Removes from `dir` the temporary files of [`write_atomic`] left by writers that were
/// killed: named `.wavg-tmp-PID-...` for a process that no longer runs (Linux: no
/// `/proc/PID`) and not modified for a minute (a live writer in another PID namespace
/// sharing the folder keeps its file fresh). Elsewhere than Linux nothing is removed.
/// Best effort: failures are ignored. Returns how many files were removed.
pub fn remove_stale_temporaries(dir: &Path) -> usize {
    if !cfg!(target_os = "linux") {
        return 0;
    }
    let Ok(entries) = std::fs::read_dir(dir) else {
        return 0;
    };
    let mut removed = 0;
    for entry in entries.flatten() {
        let name = entry.file_name();
        let Some(pid) = name
            .to_str()
            .and_then(|n| n.strip_prefix(TEMP_PREFIX))
            .and_then(|rest| rest.split_once('-'))
            .and_then(|(pid, _)| pid.parse::<u32>().ok())
        else {
            continue;
        };
        if pid == std::process::id() || Path::new("/proc").join(pid.to_string()).exists() {
            continue;
        }
        let old = entry
            .metadata()
            .ok()
            .filter(|m| m.is_file())
            .and_then(|m| m.modified().ok())
            .and_then(|t| t.elapsed().ok())
            .is_some_and(|age| age >= STALE_AFTER);
        if old && std::fs::remove_file(entry.path()).is_ok() {
            removed += 1;
        }
    }
    removed
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

    #[test]
    fn a_failed_write_names_no_temporary_file() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("missing").join("out.txt");
        let e = write_atomic(&path, |w| w.write_all(b"hello")).unwrap_err();
        assert_eq!(e.kind(), std::io::ErrorKind::NotFound);
        let m = e.to_string();
        assert!(!m.contains(TEMP_PREFIX) && !m.contains("missing"), "{m}");
    }

    /// A process that ended and was never waited for by a writer: its id, now unused.
    #[cfg(target_os = "linux")]
    fn dead_pid() -> u32 {
        let mut child = std::process::Command::new("true").spawn().unwrap();
        let pid = child.id();
        child.wait().unwrap();
        pid
    }

    /// A temporary file left by a killed writer is removed by the next write into the
    /// folder; one of a live process, a fresh one, and names of other forms are kept.
    #[cfg(target_os = "linux")]
    #[test]
    fn a_killed_writers_temporary_file_is_removed_by_the_next_write() {
        let dir = tempfile::tempdir().unwrap();
        let old = std::time::SystemTime::now() - std::time::Duration::from_secs(3600);
        let make = |name: &str, modified: std::time::SystemTime| {
            let path = dir.path().join(name);
            let f = std::fs::File::create(&path).unwrap();
            f.set_modified(modified).unwrap();
            path
        };
        let dead = dead_pid();
        let stale = make(&format!("{TEMP_PREFIX}{dead}-a1b2c3"), old);
        let fresh = make(
            &format!("{TEMP_PREFIX}{dead}-d4e5f6"),
            std::time::SystemTime::now(),
        );
        let live = make(&format!("{TEMP_PREFIX}1-g7h8i9"), old); // init is alive
        let mine = make(&format!("{TEMP_PREFIX}{}-j0k1l2", std::process::id()), old);
        let other = make(".wavg-tmp-x9y8z7", old);
        write_atomic(&dir.path().join("out.wavg"), |w| w.write_all(b"data")).unwrap();
        assert!(!stale.exists(), "the dead writer's old file is removed");
        for kept in [&fresh, &live, &mine, &other] {
            assert!(kept.exists(), "{} kept", kept.display());
        }
        assert_eq!(std::fs::read(dir.path().join("out.wavg")).unwrap(), b"data");
    }

    /// The temporary file carries the writer's process id.
    #[test]
    fn the_temporary_file_is_named_after_the_writer() {
        let dir = tempfile::tempdir().unwrap();
        let mut seen = Vec::new();
        write_atomic(&dir.path().join("o"), |w| {
            seen = std::fs::read_dir(dir.path())
                .unwrap()
                .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
                .collect();
            w.write_all(b"x")
        })
        .unwrap();
        let prefix = format!("{TEMP_PREFIX}{}-", std::process::id());
        assert!(seen.iter().any(|n| n.starts_with(&prefix)), "{seen:?}");
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
