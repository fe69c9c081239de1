//! `docs/cli.md` is what `cargo xtask cli-docs` writes from the command definitions, and
//! documents exactly the commands and options the command line has.
//!
//! Convention of that file: one `## wavg NAME` heading per command (`## wavg bench load`
//! for a nested one), and under it the command's `--help` text, whose `Arguments:` list
//! names each positional argument (`  [MESH]`) and whose `Options:` list each option
//! (`  -o, --output <OUTPUT>`, `      --json`). `--help` and `--version` are left out.

use std::collections::{BTreeMap, BTreeSet};

/// Command path (`wavg bench load`) -> its arguments as written in the docs (`--mesh`,
/// `-o`, `MESH`).
type Documented = BTreeMap<String, BTreeSet<String>>;

/// What the clap definition has: every command below the root, at any depth.
fn from_clap() -> Documented {
    let mut out = Documented::new();
    walk(&wavg_cli::command(), "wavg", &mut out);
    out.remove("wavg");
    out
}

fn walk(cmd: &clap::Command, path: &str, out: &mut Documented) {
    let args = out.entry(path.to_string()).or_default();
    for arg in cmd.get_arguments() {
        if arg.is_positional() {
            let name = arg
                .get_value_names()
                .and_then(|v| v.first())
                .map(|n| n.to_string())
                .unwrap_or_else(|| arg.get_id().as_str().to_uppercase());
            args.insert(name);
        }
        if let Some(long) = arg.get_long() {
            args.insert(format!("--{long}"));
        }
        if let Some(short) = arg.get_short() {
            args.insert(format!("-{short}"));
        }
    }
    for sub in cmd.get_subcommands().filter(|s| !s.is_hide_set()) {
        walk(sub, &format!("{path} {}", sub.get_name()), out);
    }
}

/// What a `docs/cli.md`-style text documents, by the convention above.
fn from_markdown(text: &str) -> Documented {
    let mut out = Documented::new();
    let mut current: Option<String> = None;
    let mut section = "";
    for line in text.lines() {
        if line.starts_with('#') {
            current = line
                .strip_prefix("## ")
                .filter(|h| h.starts_with("wavg "))
                .map(|h| h.trim().to_string());
            if let Some(c) = &current {
                assert!(
                    out.insert(c.clone(), BTreeSet::new()).is_none(),
                    "{c} twice"
                );
            }
            continue;
        }
        let Some(cmd) = &current else { continue };
        if line.is_empty() {
            continue;
        }
        if !line.starts_with(' ') {
            section = if line.ends_with(':') { line } else { "" };
            continue;
        }
        let indent = line.len() - line.trim_start().len();
        let item = line.trim();
        let args = out.get_mut(cmd).unwrap();
        match section {
            "Arguments:" if indent == 2 => {
                let name = item
                    .split_whitespace()
                    .next()
                    .unwrap()
                    .trim_end_matches("...")
                    .trim_matches(['[', ']', '<', '>']);
                args.insert(name.to_string());
            }
            "Options:" if indent <= 6 && item.starts_with('-') => {
                let spec = item.split("  ").next().unwrap();
                for t in spec.split([' ', ',']).filter(|t| t.starts_with('-')) {
                    if !["-h", "--help", "-V", "--version"].contains(&t) {
                        args.insert(t.to_string());
                    }
                }
            }
            _ => {}
        }
    }
    out
}

/// The differences between the two, one line each; empty when they agree.
fn differences(clap: &Documented, docs: &Documented) -> Vec<String> {
    let mut out = Vec::new();
    for (cmd, args) in clap {
        match docs.get(cmd) {
            None => out.push(format!("`## {cmd}` is missing from docs/cli.md")),
            Some(documented) => {
                for a in args.difference(documented) {
                    out.push(format!("{cmd}: `{a}` is not documented in docs/cli.md"));
                }
                for a in documented.difference(args) {
                    out.push(format!(
                        "{cmd}: docs/cli.md lists `{a}`, which --help does not"
                    ));
                }
            }
        }
    }
    for cmd in docs.keys().filter(|c| !clap.contains_key(*c)) {
        out.push(format!("docs/cli.md has `## {cmd}`, which is no command"));
    }
    out
}

#[test]
fn docs_cli_md_lists_every_command_and_option_and_no_other() {
    let path = concat!(env!("CARGO_MANIFEST_DIR"), "/../../docs/cli.md");
    let text = std::fs::read_to_string(path).expect("docs/cli.md");
    let diff = differences(&from_clap(), &from_markdown(&text));
    assert!(
        diff.is_empty(),
        "docs/cli.md disagrees:\n{}",
        diff.join("\n")
    );
}

#[test]
fn a_missing_an_extra_and_an_unknown_entry_are_each_reported() {
    let clap = from_clap();
    let text = "## wavg info\n```text\nArguments:\n  [MESH]\n          a mesh\n\nOptions:\n      \
                --mesh <MESH>\n      --builtin <NAME>\n          x\n      --jsn\n          typo\n\
                \nProse: --json is mentioned here only.\n  --json indented prose\n```\n\
                ## wavg frobnicate\n```text\nOptions:\n      --x\n```\n";
    let diff = differences(&clap, &from_markdown(text));
    let has = |s: &str| diff.iter().any(|d| d.contains(s));
    assert!(has("wavg info: `--json` is not documented"), "{diff:?}");
    assert!(has("lists `--jsn`"), "{diff:?}");
    assert!(has("`## wavg frobnicate`, which is no command"), "{diff:?}");
    assert!(has("`## wavg demo` is missing"), "{diff:?}");
}

#[test]
fn docs_cli_md_is_what_cargo_xtask_cli_docs_writes() {
    let path = concat!(env!("CARGO_MANIFEST_DIR"), "/../../docs/cli.md");
    let text = std::fs::read_to_string(path).expect("docs/cli.md");
    let generated = wavg_cli::cli_docs::markdown();
    if text != generated {
        let line = text
            .lines()
            .zip(generated.lines())
            .position(|(a, b)| a != b)
            .map_or(text.lines().count().min(generated.lines().count()), |i| i)
            + 1;
        panic!(
            "docs/cli.md differs from the command definitions (first at line {line}: {:?} \
             instead of {:?}): run `cargo xtask cli-docs`",
            text.lines().nth(line - 1),
            generated.lines().nth(line - 1)
        );
    }
}
