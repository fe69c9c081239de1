//! `cargo xtask lines`: the Rust source files with more than [`MAX_LINES`] lines of
//! non-test code (the lines before a file's first `#[cfg(test)]`), so that no module
//! grows past one job.

use std::path::{Path, PathBuf};

/// The most lines of non-test code a source file should have.
pub const MAX_LINES: usize = 600;

/// Lists the files over the limit, largest first; `Err` when there are any.
pub fn run(root: &Path) -> Result<(), String> {
    let mut files = Vec::new();
    for dir in ["crates", "python", "xtask", "lab"] {
        rust_files(&root.join(dir), &mut files)?;
    }
    let mut over: Vec<(usize, PathBuf)> = files
        .into_iter()
        .filter_map(|f| {
            let text = std::fs::read_to_string(&f).ok()?;
            let n = non_test_lines(&text);
            (n > MAX_LINES).then_some((n, f))
        })
        .collect();
    over.sort_by(|a, b| b.cmp(a));
    for (n, f) in &over {
        println!("{n:5} {}", f.strip_prefix(root).unwrap_or(f).display());
    }
    if over.is_empty() {
        Ok(())
    } else {
        Err(format!(
            "{} file(s) over {MAX_LINES} lines of non-test code",
            over.len()
        ))
    }
}

/// Lines before the first `#[cfg(test)]` (all of them when there is none).
fn non_test_lines(text: &str) -> usize {
    text.lines()
        .take_while(|l| l.trim() != "#[cfg(test)]")
        .count()
}

/// Every `.rs` file under `dir`, skipping `target` directories.
pub(crate) fn rust_files(dir: &Path, out: &mut Vec<PathBuf>) -> Result<(), String> {
    let entries = std::fs::read_dir(dir).map_err(|e| format!("{}: {e}", dir.display()))?;
    for e in entries.flatten() {
        let p = e.path();
        if p.is_dir() {
            if p.file_name().is_some_and(|n| n != "target") {
                rust_files(&p, out)?;
            }
        } else if p.extension().is_some_and(|x| x == "rs") {
            out.push(p);
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::non_test_lines;

    #[test]
    fn counts_the_lines_before_the_tests() {
        assert_eq!(non_test_lines("a\nb\n#[cfg(test)]\nmod tests {}\n"), 2);
        assert_eq!(non_test_lines("a\nb\n"), 2);
        assert_eq!(non_test_lines("    #[cfg(test)]\n"), 0);
    }
}
