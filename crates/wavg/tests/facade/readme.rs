//! The code the README and `docs/rust.md` show is code the tests build and run:
//! `docs/rust.md` shows `examples/quickstart.rs` verbatim, and the README's short excerpts
//! call only functions that the quickstart, the C consumer test (`hello.c`) and the C++
//! wrapper's own usage comment call.

/// The repository root.
const ROOT: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/../..");

fn read(path: &str) -> String {
    std::fs::read_to_string(format!("{ROOT}/{path}")).unwrap_or_else(|e| panic!("{path}: {e}"))
}

/// The first code block of language `lang` after the heading `heading` in `text`.
fn block<'a>(text: &'a str, heading: &str, lang: &str) -> &'a str {
    let section = text
        .find(heading)
        .unwrap_or_else(|| panic!("a \"{heading}\" section"));
    let fence = format!("```{lang}\n");
    let start = text[section..].find(&fence).expect("a code block") + section + fence.len();
    let end = text[start..].find("```").expect("the block ends") + start;
    &text[start..end]
}

/// The names called in `code` (`name(`), comments (`//`, `/* */`) left out.
fn called(code: &str) -> Vec<String> {
    let mut text = String::new();
    for line in code.lines() {
        text.push_str(line.split("//").next().unwrap_or(""));
        text.push('\n');
    }
    while let (Some(a), Some(b)) = (text.find("/*"), text.find("*/")) {
        text.replace_range(a..b + 2, "");
    }
    let mut names = Vec::new();
    let mut word = String::new();
    for c in text.chars() {
        if c.is_alphanumeric() || c == '_' {
            word.push(c);
        } else {
            if c == '(' && !word.is_empty() && !word.starts_with(|d: char| d.is_ascii_digit()) {
                names.push(word.clone());
            }
            word.clear();
        }
    }
    names
}

/// Asserts that every function `excerpt` calls is called in `source` too.
fn assert_calls_within(excerpt: &str, source: &str, what: &str) {
    let names = called(excerpt);
    assert!(!names.is_empty(), "{what}: the excerpt calls nothing");
    for name in names {
        assert!(
            source.contains(&format!("{name}(")),
            "{what}: the README calls `{name}`, which {what} does not"
        );
    }
}

#[test]
fn docs_rust_md_shows_the_quickstart_example_verbatim() {
    let page = read("docs/rust.md");
    let example = read("crates/wavg/examples/quickstart.rs");
    assert_eq!(
        block(&page, "## Quickstart", "rust"),
        example,
        "docs/rust.md's quickstart differs from crates/wavg/examples/quickstart.rs"
    );
}

#[test]
fn readme_rust_excerpt_uses_what_the_quickstart_uses() {
    let excerpt = block(&read("README.md"), "## Use from Rust", "rust").to_string();
    let example = read("crates/wavg/examples/quickstart.rs");
    let imports = excerpt.lines().next().unwrap();
    assert!(example.contains(imports), "quickstart.rs lacks `{imports}`");
    assert_calls_within(&excerpt, &example, "quickstart.rs");
}

#[test]
fn readme_c_excerpt_uses_what_hello_c_uses() {
    let excerpt = block(&read("README.md"), "## Use from C\n", "c").to_string();
    assert_calls_within(
        &excerpt,
        &read("ffi_tests/consumer/hello.c"),
        "ffi_tests/consumer/hello.c",
    );
}

#[test]
fn readme_cpp_excerpt_is_the_wrappers_usage_comment() {
    let excerpt = block(&read("README.md"), "## Use from C++", "cpp").to_string();
    let header = read("cpp_examples/wavg.hpp");
    for line in excerpt.lines() {
        assert!(
            header.contains(&format!("//   {line}\n")),
            "cpp_examples/wavg.hpp's usage comment lacks `{line}`"
        );
    }
}
