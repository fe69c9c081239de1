//! The embedding cache: computed once and reused, the same answers as the embedding file it
//! holds, `--no-cache`, a damaged entry replaced, several processes at once, list and clear.

use crate::common;

use std::path::Path;
use std::process::{Command, Output};

/// A path as a `&str` argument.
fn s(p: &Path) -> &str {
    p.to_str().unwrap()
}

/// Runs `wavg ARGS` with the cache in `cache`, asserting success.
fn run(cache: &Path, args: &[&str]) -> Output {
    let out = Command::new(env!("CARGO_BIN_EXE_wavg"))
        .args(args)
        .env("WAVG_CACHE_DIR", cache)
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "wavg {args:?}: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    out
}

fn stderr(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}

/// The cache's entries as `wavg cache list --json` gives them.
fn entries(cache: &Path) -> Vec<serde_json::Value> {
    let out = run(cache, &["cache", "list", "--json"]);
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(v["dir"], s(cache));
    v["entries"].as_array().unwrap().clone()
}

const CONTROLS: &str = "v 0\nv 200\nv 400\nv 600\nv 800\nv 1000\n";

#[test]
fn second_run_reuses_the_embedding_and_gives_the_same_curve() {
    let dir = tempfile::tempdir().unwrap();
    let cache = dir.path().join("cache");
    let c = dir.path().join("c.txt");
    std::fs::write(&c, CONTROLS).unwrap();
    let (one, two) = (dir.path().join("1.txt"), dir.path().join("2.txt"));
    let spline = |out: &Path| {
        run(
            &cache,
            &[
                "spline",
                "builtin:torus",
                "--control",
                s(&c),
                "--closed",
                "-o",
                s(out),
            ],
        )
    };
    let first = spline(&one);
    assert!(stderr(&first).contains("cached in"), "{}", stderr(&first));
    let list = entries(&cache);
    assert_eq!(list.len(), 1);
    assert_eq!(list[0]["vertices"], 1536);
    assert_eq!(list[0]["mesh"], "builtin:torus");
    let second = spline(&two);
    assert!(
        !stderr(&second).contains("cached in"),
        "{}",
        stderr(&second)
    );
    assert_eq!(std::fs::read(&one).unwrap(), std::fs::read(&two).unwrap());

    // forward without --embedding answers as with the cached file given explicitly, and
    // differently from the 3-D positions (`--embedding none`).
    let key = list[0]["key"].as_str().unwrap();
    let file = cache.join(format!("{key}.wavg"));
    let w = dir.path().join("w.txt");
    std::fs::write(&w, "0.2 0.2 0.2 0.2 0.1 0.1\n0.5 0.1 0.1 0.1 0.1 0.1\n").unwrap();
    let forward = |extra: &[&str], out: &Path| {
        let base = ["forward", "--mesh", "builtin:torus", "--anchors", s(&c)];
        let io = ["--weights", s(&w), "-o", s(out)];
        run(&cache, &[&base[..], &io, extra].concat());
        std::fs::read_to_string(out).unwrap()
    };
    let cached = forward(&[], &dir.path().join("f1.txt"));
    assert_eq!(
        cached,
        forward(&["--embedding", s(&file)], &dir.path().join("f2.txt"))
    );
    assert_ne!(
        cached,
        forward(&["--embedding", "none"], &dir.path().join("f3.txt"))
    );

    // A damaged entry is computed again and replaced.
    let bytes = std::fs::read(&file).unwrap();
    std::fs::write(&file, &bytes[..bytes.len() / 2]).unwrap();
    let third = spline(&dir.path().join("3.txt"));
    assert!(
        stderr(&third).contains("cannot be used"),
        "{}",
        stderr(&third)
    );
    assert_eq!(std::fs::read(&file).unwrap(), bytes);

    // An entry whose description is damaged is listed with the same keys, null.
    let good = entries(&cache);
    std::fs::write(file.with_extension("json"), "{").unwrap();
    let listed = entries(&cache);
    assert_eq!(listed.len(), 1);
    let keys = |v: &serde_json::Value| {
        let mut k: Vec<String> = v.as_object().unwrap().keys().cloned().collect();
        k.sort();
        k
    };
    assert_eq!(keys(&listed[0]), keys(&good[0]));
    for k in [
        "mesh",
        "vertices",
        "faces",
        "landmarks",
        "seconds",
        "created",
    ] {
        assert!(listed[0][k].is_null(), "{k}: {}", listed[0]);
    }
    assert_eq!(listed[0]["bytes"], bytes.len());

    // A user's own `.wavg` file in the folder is not the cache's: kept, and counted.
    let mine = cache.join("mine.wavg");
    std::fs::write(&mine, b"mine").unwrap();
    let cleared = run(&cache, &["cache", "clear"]);
    let said = String::from_utf8_lossy(&cleared.stdout);
    assert!(said.contains("removed 1 cached"), "{said}");
    assert!(said.contains("kept 1 other .wavg files"), "{said}");
    assert!(entries(&cache).is_empty());
    assert!(mine.exists());
}

#[test]
fn no_cache_writes_nothing() {
    let dir = tempfile::tempdir().unwrap();
    let cache = dir.path().join("cache");
    let c = dir.path().join("c.txt");
    std::fs::write(&c, CONTROLS).unwrap();
    let out = dir.path().join("o.txt");
    let args = [
        "spline",
        "builtin:torus",
        "--control",
        s(&c),
        "-o",
        s(&out),
        "--no-cache",
    ];
    let r = run(&cache, &args);
    assert!(!stderr(&r).contains("cached in"));
    assert!(!cache.exists());
    assert!(entries(&cache).is_empty());
}

/// Four processes that all need the same missing entry: all succeed with the same answers,
/// and one whole entry is left.
#[test]
fn concurrent_processes_share_one_whole_entry() {
    let dir = tempfile::tempdir().unwrap();
    let cache = dir.path().join("cache");
    let c = dir.path().join("c.txt");
    std::fs::write(&c, CONTROLS).unwrap();
    let children: Vec<_> = (0..4)
        .map(|i| {
            let out = dir.path().join(format!("{i}.txt"));
            Command::new(env!("CARGO_BIN_EXE_wavg"))
                .args(["spline", "builtin:torus", "--control", s(&c), "-o", s(&out)])
                .env("WAVG_CACHE_DIR", &cache)
                .stderr(std::process::Stdio::piped())
                .stdout(std::process::Stdio::null())
                .spawn()
                .unwrap()
        })
        .collect::<Vec<_>>();
    let children: Vec<Output> = children
        .into_iter()
        .map(|c| c.wait_with_output().unwrap())
        .collect();
    for ch in &children {
        assert!(ch.status.success(), "{}", stderr(ch));
    }
    let first = std::fs::read(dir.path().join("0.txt")).unwrap();
    for i in 1..4 {
        assert_eq!(
            std::fs::read(dir.path().join(format!("{i}.txt"))).unwrap(),
            first
        );
    }
    assert_eq!(entries(&cache).len(), 1);
    let leftovers = common::entries_starting_with(&cache, ".");
    assert_eq!(leftovers, 0, "temporary files left in the cache");
}
