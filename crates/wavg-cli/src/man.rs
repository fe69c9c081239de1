//! Man pages for packagers, generated from the command line's own definition: `wavg.1`
//! and one page per subcommand (`wavg-info.1`, `wavg-bench-load.1`, ...). `cargo xtask man`
//! writes them through the `man` example.

use std::path::{Path, PathBuf};

/// Writes the pages of `wavg` and of every subcommand, at any depth, into `dir` (created if
/// missing); returns the files written.
pub fn write_pages(dir: &Path) -> Result<Vec<PathBuf>, String> {
    std::fs::create_dir_all(dir).map_err(|e| format!("creating {}: {e}", dir.display()))?;
    let root = crate::command();
    let mut pages = Pages {
        dir,
        source: format!("wavg {}", root.get_version().unwrap_or_default()),
        written: Vec::new(),
    };
    pages.write_tree(root, "wavg", "wavg")?;
    Ok(pages.written)
}

/// The folder the pages go to, the footer naming the program and version, and the files
/// written so far.
struct Pages<'a> {
    dir: &'a Path,
    source: String,
    written: Vec<PathBuf>,
}

impl Pages<'_> {
    /// One page for `cmd`, invoked as `usage` (e.g. `wavg bench load`) and titled `name`
    /// (`wavg-bench-load`), then one per subcommand.
    fn write_tree(&mut self, cmd: clap::Command, name: &str, usage: &str) -> Result<(), String> {
        let cmd = cmd.bin_name(usage).disable_help_subcommand(true);
        let mut page = Vec::new();
        clap_mangen::Man::new(cmd.clone())
            .title(name)
            .source(self.source.clone())
            .manual("wavg manual")
            .render(&mut page)
            .map_err(|e| format!("rendering {name}.1: {e}"))?;
        let path = self.dir.join(format!("{name}.1"));
        std::fs::write(&path, page).map_err(|e| format!("writing {}: {e}", path.display()))?;
        self.written.push(path);
        for sub in cmd.get_subcommands().filter(|s| !s.is_hide_set()) {
            let sub_name = format!("{name}-{}", sub.get_name());
            let sub_usage = format!("{usage} {}", sub.get_name());
            self.write_tree(sub.clone(), &sub_name, &sub_usage)?;
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn one_page_per_command_naming_its_options() {
        let dir = tempfile::tempdir().unwrap();
        let written = write_pages(dir.path()).unwrap();
        let names: Vec<String> = written
            .iter()
            .map(|p| p.file_name().unwrap().to_string_lossy().into_owned())
            .collect();
        for expected in [
            "wavg.1",
            "wavg-info.1",
            "wavg-transfer-texture.1",
            "wavg-bench.1",
            "wavg-bench-roundtrip.1",
            "wavg-completions.1",
        ] {
            assert!(
                names.iter().any(|n| n == expected),
                "{expected} in {names:?}"
            );
        }
        assert!(!names.iter().any(|n| n.contains("help")), "{names:?}");
        let main = std::fs::read_to_string(dir.path().join("wavg.1")).unwrap();
        assert!(
            main.starts_with(".ie") || main.contains(".TH wavg"),
            "{main}"
        );
        assert!(main.contains("precompute"), "{main}");
        let info = std::fs::read_to_string(dir.path().join("wavg-info.1")).unwrap();
        assert!(info.contains(".TH wavg-info"), "{info}");
        assert!(info.contains("json"), "{info}");
    }
}
