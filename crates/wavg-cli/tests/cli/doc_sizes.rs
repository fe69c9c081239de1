//! The front page and the benchmarks stay short: README.md at most 200 lines (what it
//! does, pictures, the two commands, install lines, a few lines per way of using it), and
//! BENCHMARKS.md at most 250 lines of current figures with their commands (earlier figures
//! are in git's history, not in the tables).

use std::path::Path;

/// The lines of a file at the repository root.
fn lines(name: &str) -> Vec<String> {
    let path = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../..")
        .join(name);
    std::fs::read_to_string(&path)
        .unwrap_or_else(|e| panic!("{}: {e}", path.display()))
        .lines()
        .map(str::to_string)
        .collect()
}

/// Why `text` is too long for a page of at most `max` lines, if it is.
fn too_long(name: &str, text: &[String], max: usize) -> Option<String> {
    (text.len() > max).then(|| format!("{name} has {} lines, more than {max}", text.len()))
}

/// The table rows of `text` that quote an earlier figure (`was ...`).
fn history_rows(text: &[String]) -> Vec<String> {
    text.iter()
        .filter(|l| l.starts_with('|') && (l.contains("(was ") || l.contains("; was ")))
        .cloned()
        .collect()
}

#[test]
fn readme_has_at_most_200_lines() {
    let problem = too_long("README.md", &lines("README.md"), 200);
    assert!(problem.is_none(), "{problem:?}");
}

#[test]
fn benchmarks_has_at_most_250_lines_of_current_figures() {
    let text = lines("BENCHMARKS.md");
    let problem = too_long("BENCHMARKS.md", &text, 250);
    assert!(problem.is_none(), "{problem:?}");
    let rows = history_rows(&text);
    assert!(
        rows.is_empty(),
        "rows quoting earlier figures (history is git's):\n{}",
        rows.join("\n")
    );
}

#[test]
fn a_long_page_and_a_history_row_are_caught() {
    let page: Vec<String> = (0..201).map(|i| i.to_string()).collect();
    assert!(too_long("X", &page, 200).unwrap().contains("201 lines"));
    assert!(too_long("X", &page[..200], 200).is_none());
    let rows = ["| a | 1.0 (was 2.0) |", "| b | 3.0 |", "text (was 1)"].map(String::from);
    assert_eq!(history_rows(&rows), vec![rows[0].clone()]);
}
