//! `docs/cli.md` documents exactly the commands and options the command line has.
//!
//! Convention of that file: one `### wavg NAME` heading per command (`### wavg bench load`
//! for a nested one), and under it one list item per argument, starting with the argument
//! in backticks: `` - `--mesh MESH`: ... ``, `` - `-o, --output FILE`: ... `` or, for a
//! positional argument, its value name: `` - `MESH`: ... ``. Prose may mention any option
//! anywhere; only those list items count. `--help` and `--version` are left out.

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
    for line in text.lines() {
        if line.starts_with('#') {
            current = line
                .strip_prefix("### ")
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
        let (Some(cmd), Some(item)) = (&current, line.strip_prefix("- `")) else {
            continue;
        };
        let spec = &item[..item.find('`').expect("a closing backtick")];
        let args = out.get_mut(cmd).unwrap();
        let mut tokens = spec.split([' ', ',']).filter(|t| !t.is_empty());
        let first = tokens.next().expect("an argument");
        let is_positional = first
            .chars()
            .all(|c| c.is_ascii_uppercase() || c == '_' || c == '.');
        if is_positional {
            args.insert(first.to_string());
        }
        for t in std::iter::once(first).chain(tokens) {
            if t.starts_with('-') {
                args.insert(t.to_string());
            }
        }
    }
    out
}

/// The differences between the two, one line each; empty when they agree.
fn differences(clap: &Documented, docs: &Documented) -> Vec<String> {
    let mut out = Vec::new();
    for (cmd, args) in clap {
        match docs.get(cmd) {
            None => out.push(format!("`### {cmd}` is missing from docs/cli.md")),
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
        out.push(format!("docs/cli.md has `### {cmd}`, which is no command"));
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
    let text = "### wavg info\n- `MESH`: a mesh\n- `--builtin NAME`: x\n- `--jsn`: typo\n\
                ### wavg frobnicate\n- `--x`: y\n";
    let diff = differences(&clap, &from_markdown(text));
    let has = |s: &str| diff.iter().any(|d| d.contains(s));
    assert!(has("wavg info: `--json` is not documented"), "{diff:?}");
    assert!(has("lists `--jsn`"), "{diff:?}");
    assert!(
        has("`### wavg frobnicate`, which is no command"),
        "{diff:?}"
    );
    assert!(has("`### wavg demo` is missing"), "{diff:?}");
}
