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

/// The numbers of one line of a text file.
pub fn parse_floats(line: &str) -> Vec<f64> {
    line.split_whitespace()
        .map(|t| t.parse().unwrap())
        .collect()
}

/// A text file of numbers, one row per line.
pub fn read_rows(p: &std::path::Path) -> Vec<Vec<f64>> {
    std::fs::read_to_string(p)
        .unwrap()
        .lines()
        .map(parse_floats)
        .collect()
}

/// How many entries of folder `dir` have names starting with `prefix` (temporary files
/// left behind).
pub fn entries_starting_with(dir: &std::path::Path, prefix: &str) -> usize {
    std::fs::read_dir(dir)
        .unwrap()
        .filter(|e| {
            e.as_ref()
                .unwrap()
                .file_name()
                .to_string_lossy()
                .starts_with(prefix)
        })
        .count()
}

/// The keys of `wavg remesh --json`.
pub const REMESH_KEYS: [&str; 20] = [
    "mesh",
    "base",
    "base_vertices",
    "base_faces",
    "vertices",
    "faces",
    "levels",
    "smooth_steps",
    "seconds",
    "warm_seconds",
    "warm_seconds_max",
    "warm_cpu_seconds",
    "frames",
    "max_offsurface",
    "roughness",
    "problems",
    "forward_problems_solved",
    "fallbacks",
    "threads",
    "precompute_seconds",
];

/// The arguments of a command on a source and a target mesh with paired anchors
/// (`correspond`, `morph`, `transfer-texture`): `COMMAND --source S --target T
/// --source-anchors A --target-anchors B -o OUT`.
pub fn pair_args(
    command: &str,
    [source, target]: [&str; 2],
    [source_anchors, target_anchors]: [&str; 2],
    out: &str,
) -> Vec<String> {
    [
        command,
        "--source",
        source,
        "--target",
        target,
        "--source-anchors",
        source_anchors,
        "--target-anchors",
        target_anchors,
        "-o",
        out,
    ]
    .map(String::from)
    .to_vec()
}

/// `wavg_ok` on owned arguments followed by `extra`.
pub fn wavg_ok_with(args: &[String], extra: &[&str]) -> Output {
    let mut all: Vec<&str> = args.iter().map(String::as_str).collect();
    all.extend_from_slice(extra);
    wavg_ok(&all)
}

/// `wavg remesh` of the base mesh `base` on `builtin:icosphere` (the unit sphere) into
/// `out`, followed by `extra`.
pub fn remesh_on_sphere(base: &std::path::Path, out: &std::path::Path, extra: &[&str]) -> Output {
    let (base, out) = (s(base), s(out));
    let args = [
        "remesh",
        "--mesh",
        "builtin:icosphere",
        "--base",
        &base,
        "-o",
        &out,
    ];
    wavg(&[&args[..], extra].concat())
}

/// Runs `wavg decal` on the built-in icosphere with a square of four anchors and writes
/// `DIR/decal.glb` (its UVs and the checkerboard texture): the glTF tests' textured file.
pub fn decal_glb(dir: &std::path::Path) -> std::path::PathBuf {
    let anchors = dir.join("a.txt");
    let uv = dir.join("uv.txt");
    std::fs::write(&anchors, "v 0\nv 1\nv 2\nv 3\n").unwrap();
    std::fs::write(&uv, "0 0\n1 0\n1 1\n0 1\n").unwrap();
    let glb = dir.join("decal.glb");
    wavg_ok(&[
        "decal",
        "builtin:icosphere",
        "--anchors",
        &s(&anchors),
        "--uv",
        &s(&uv),
        "-o",
        &s(&glb),
    ]);
    glb
}
