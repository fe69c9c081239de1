//! Helpers shared by the command-line tests: run `wavg`, check success, read JSON.
#![allow(dead_code)] // each test binary uses a different subset

use std::process::{Command, Output};

/// The embedding cache folder the tests' `wavg` runs use.
pub fn cache_dir() -> std::path::PathBuf {
    std::path::Path::new(env!("CARGO_TARGET_TMPDIR")).join("wavg-cache")
}

/// The `wavg` program with the tests' embedding cache ([`cache_dir`]): shared by them,
/// never the user's.
pub fn wavg_command() -> Command {
    let mut c = Command::new(env!("CARGO_BIN_EXE_wavg"));
    c.env("WAVG_CACHE_DIR", cache_dir());
    c
}

/// Runs `wavg ARGS`.
pub fn wavg(args: &[&str]) -> Output {
    wavg_command().args(args).output().expect("run wavg")
}

/// Runs `wavg ARGS` and asserts success (showing its standard error otherwise).
pub fn wavg_ok(args: &[&str]) -> Output {
    let out = wavg(args);
    assert!(
        out.status.success(),
        "wavg {args:?}: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    out
}

/// The JSON object a command printed, and its keys sorted.
pub fn json_object(out: &Output) -> (serde_json::Map<String, serde_json::Value>, Vec<String>) {
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).expect("JSON on stdout");
    let o = v.as_object().expect("a JSON object").clone();
    let mut keys: Vec<String> = o.keys().cloned().collect();
    keys.sort();
    (o, keys)
}

/// Writes the anchors file `a.txt` in `dir`: every 85th vertex of the level-4 icosphere
/// (`builtin:icosphere`, 2562 vertices), 31 anchors.
pub fn sphere_anchors(dir: &std::path::Path) -> std::path::PathBuf {
    let p = dir.join("a.txt");
    let text: String = (0..2562).step_by(85).map(|v| format!("v {v}\n")).collect();
    std::fs::write(&p, text).unwrap();
    p
}

/// `wavg forward` on `builtin:icosphere` with the anchors of [`sphere_anchors`]: runs it
/// with `weights` and output `out`.
pub fn icosphere_forward(
    anchors: &std::path::Path,
    weights: &std::path::Path,
    out: &std::path::Path,
) -> Output {
    wavg(&[
        "forward",
        "--mesh",
        "builtin:icosphere",
        "--anchors",
        &s(anchors),
        "--weights",
        &s(weights),
        "-o",
        &s(out),
    ])
}

/// A path as a string argument.
pub fn s(p: &std::path::Path) -> String {
    p.to_str().unwrap().to_string()
}

/// Every key of `v`, nested ones as `parent.child`, sorted.
pub fn key_paths(v: &serde_json::Value) -> Vec<String> {
    fn walk(prefix: &str, v: &serde_json::Value, out: &mut Vec<String>) {
        if let serde_json::Value::Object(o) = v {
            for (k, x) in o {
                let path = if prefix.is_empty() {
                    k.clone()
                } else {
                    format!("{prefix}.{k}")
                };
                out.push(path.clone());
                walk(&path, x, out);
            }
        }
    }
    let mut out = Vec::new();
    walk("", v, &mut out);
    out.sort();
    out
}

/// Runs `wavg ARGS` and asserts the exact set of key paths of its JSON object.
pub fn assert_keys(args: &[&str], want: &[&str]) {
    let (o, _) = json_object(&wavg_ok(args));
    let mut want: Vec<String> = want.iter().map(|k| k.to_string()).collect();
    want.sort();
    assert_eq!(
        key_paths(&serde_json::Value::Object(o)),
        want,
        "wavg {}",
        args[0]
    );
}
