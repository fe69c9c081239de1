//! The README's "Use from Rust" section shows `examples/quickstart.rs` verbatim: the code a
//! newcomer copies is the code `cargo xtask test` builds and runs.

#[test]
fn readme_shows_the_quickstart_example_verbatim() {
    let root = concat!(env!("CARGO_MANIFEST_DIR"), "/../..");
    let readme = std::fs::read_to_string(format!("{root}/README.md")).unwrap();
    let example = std::fs::read_to_string(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/examples/quickstart.rs"
    ))
    .unwrap();
    let section = readme
        .find("## Use from Rust")
        .expect("README has a \"Use from Rust\" section");
    let start = readme[section..].find("```rust\n").expect("a rust block") + section + 8;
    let end = readme[start..].find("```").expect("the block ends") + start;
    assert_eq!(
        &readme[start..end],
        example,
        "README.md's quickstart differs from crates/wavg/examples/quickstart.rs"
    );
}
