//! The examples of every command: shown at the end of `wavg COMMAND --help`, and written
//! into `docs/cli.md` as `sh` blocks, which the docs test runs (in a folder holding the
//! files they name: `crates/wavg-cli/tests/cli/docs_blocks.rs`).

/// One command's examples: its path below `wavg` (`["bench", "load"]`), the command lines
/// (`#` comments allowed), and why the docs test must not run them, if it must not.
pub struct Examples {
    /// Subcommand names from the root.
    pub path: &'static [&'static str],
    /// One shell command per line.
    pub lines: &'static [&'static str],
    /// Set when the lines cannot run unattended (they wait for Ctrl-C, ...).
    pub skip: Option<&'static str>,
}

/// The examples, in no particular order; commands without any are absent.
pub const EXAMPLES: &[Examples] = &[
    ex(
        &["demo"],
        &[
            "wavg demo --out demo_out",
            "wavg demo --mesh ../shared/data/meshes/torus.obj --anchors 12 --json",
        ],
    ),
    ex(
        &["info"],
        &[
            "wavg info ../shared/data/meshes/torus.obj",
            "wavg info --json ../shared/data/bad/cow.obj",
            "wavg info --builtin torus",
        ],
    ),
    ex(
        &["repair"],
        &[
            "# The non-manifold Sumner camel becomes valid; its input vertex ids still apply.",
            "wavg repair ../shared/data/bad/camel-reference.obj.gz -o camel.obj --map camel.map --json",
        ],
    ),
    ex(
        &["subdivide"],
        &["wavg subdivide builtin:bump --levels 2 -o bump2.ply --json"],
    ),
    ex(
        &["precompute"],
        &["wavg precompute ../shared/data/meshes/pig.off -o pig.wavg --json"],
    ),
    ex(
        &["anchors"],
        &[
            "wavg anchors builtin:torus --count 32 -o anchors.txt",
            "wavg anchors builtin:torus --count 32 --method random --seed 3 -o random.txt --json",
        ],
    ),
    ex(
        &["forward"],
        &[
            "wavg forward --mesh pig.off --embedding pig.wavg --anchors a.txt --weights w.txt -o out.txt",
        ],
    ),
    ex(
        &["inverse"],
        &[
            "wavg inverse --mesh pig.off --embedding pig.wavg --anchors a.txt --points p.txt -o weights.txt --verified",
            "wavg inverse --mesh pig.off --embedding pig.wavg --anchors a.txt --points p.npy -o weights.npy",
        ],
    ),
    ex(
        &["spline"],
        &["wavg spline --mesh spot.obj --control c.txt --closed -o curve.txt"],
    ),
    ex(
        &["correspond"],
        &[
            "wavg correspond --source a.obj --target b.obj --source-anchors sa.txt --target-anchors ta.txt \\",
            "    -o map.txt --ground-truth --json",
        ],
    ),
    ex(
        &["decal"],
        &[
            "wavg decal --mesh spot.obj --anchors ring.txt --uv ring_uv.txt -o decal.obj --json",
            "wavg render decal.obj --texture decal_checker.png -o decal.png",
        ],
    ),
    ex(
        &["morph"],
        &[
            "wavg morph --source a.obj --target b.obj --source-anchors sa.txt --target-anchors ta.txt \\",
            "    --frames 24 -o frames/",
        ],
    ),
    ex(
        &["remesh"],
        &["wavg remesh --mesh fertility.off --base cage.obj --levels 3 -o remeshed.obj --json"],
    ),
    ex(
        &["render"],
        &[
            "wavg spline --mesh spot.obj --control c.txt --closed -o curve.txt",
            "wavg render spot.obj --texture spot.png --curve curve.txt --points c.txt --view 150,20 -o spot_curve.png",
        ],
    ),
    ex(
        &["transfer-texture"],
        &[
            "wavg transfer-texture --source spot.obj --source-texture spot.png --target bent.obj \\",
            "    --source-anchors sa.txt --target-anchors ta.txt -o bent.png --json",
        ],
    ),
    Examples {
        path: &["serve"],
        lines: &["wavg serve spot.obj --embedding spot.wavg --open"],
        skip: Some("serves until Ctrl-C"),
    },
    ex(
        &["bench", "load"],
        &["wavg bench load --mesh ../shared/data/meshes/igea.off.gz --json"],
    ),
    ex(
        &["bench", "project"],
        &["wavg bench project --mesh pig.off --embedding pig.wavg --json"],
    ),
    ex(
        &["bench", "roundtrip"],
        &[
            "wavg bench roundtrip --mesh pig.off --precompute --anchors 27 --queries 100000 --verified --json",
        ],
    ),
    ex(
        &["bench", "spline"],
        &["wavg bench spline mesh.obj --control c.txt --closed --repeat 5 --json"],
    ),
    ex(&["cache", "list"], &["wavg cache list"]),
    ex(&["cache", "clear"], &["wavg cache clear"]),
    ex(
        &["completions"],
        &[
            "wavg completions bash > ~/.local/share/bash-completion/completions/wavg",
            "wavg completions zsh > ~/.zfunc/_wavg   # with fpath+=~/.zfunc before compinit",
            "wavg completions fish > ~/.config/fish/completions/wavg.fish",
        ],
    ),
];

/// Examples that the docs test runs.
const fn ex(path: &'static [&'static str], lines: &'static [&'static str]) -> Examples {
    Examples {
        path,
        lines,
        skip: None,
    }
}

/// The examples of the command at `path`, if it has any.
pub fn of(path: &[&str]) -> Option<&'static Examples> {
    EXAMPLES.iter().find(|e| e.path == path)
}

/// `cmd` (at `path` below the root) and its subcommands, each with its examples appended
/// to its long help as an `Examples:` section.
pub fn append(mut cmd: clap::Command, path: &mut Vec<String>) -> clap::Command {
    let names: Vec<String> = cmd
        .get_subcommands()
        .map(|s| s.get_name().to_string())
        .collect();
    for name in names {
        path.push(name.clone());
        cmd = cmd.mut_subcommand(&name, |sub| append(sub, path));
        path.pop();
    }
    let path_ref: Vec<&str> = path.iter().map(String::as_str).collect();
    let Some(examples) = of(&path_ref) else {
        return cmd;
    };
    let mut text = cmd
        .get_after_long_help()
        .map(|h| format!("{h}\n\n"))
        .unwrap_or_default();
    text.push_str("Examples:\n");
    for line in examples.lines {
        text.push_str("  ");
        text.push_str(line);
        text.push('\n');
    }
    cmd.after_long_help(text.trim_end().to_string())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_example_belongs_to_a_command_and_starts_with_it() {
        let root = crate::definition();
        for e in EXAMPLES {
            let mut cmd = &root;
            for name in e.path {
                cmd = cmd
                    .find_subcommand(name)
                    .unwrap_or_else(|| panic!("{:?} is no command", e.path));
            }
            let own = format!("wavg {} ", e.path.join(" "));
            assert!(
                e.lines
                    .iter()
                    .any(|l| l.starts_with(&own) || *l == own.trim_end()),
                "no example of {own}in {:?}",
                e.lines
            );
        }
    }

    #[test]
    fn the_examples_end_the_long_help() {
        let mut cmd = crate::command().bin_name("wavg");
        let info = cmd.find_subcommand_mut("info").unwrap();
        let help = info.render_long_help().to_string();
        assert!(
            help.trim_end()
                .ends_with("Examples:\n  wavg info ../shared/data/meshes/torus.obj\n  wavg info --json ../shared/data/bad/cow.obj\n  wavg info --builtin torus"),
            "{help}"
        );
        let load = cmd
            .find_subcommand_mut("bench")
            .unwrap()
            .find_subcommand_mut("load")
            .unwrap()
            .render_long_help()
            .to_string();
        assert!(load.contains("Examples:\n  wavg bench load"), "{load}");
    }
}
