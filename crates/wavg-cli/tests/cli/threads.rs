//! `--threads` is checked when the command line is read: an absurd count is refused at
//! once with the limit (thousands of threads took minutes to start and hand work to).

use crate::common;

use common::{s, wavg};

#[test]
fn thread_counts_beyond_the_limit_are_refused() {
    let dir = tempfile::tempdir().unwrap();
    let (a, w) = (dir.path().join("a.txt"), dir.path().join("w.txt"));
    std::fs::write(&a, "v 0\nv 1\nv 2\n").unwrap();
    std::fs::write(&w, "1 0 0\n").unwrap();
    let out = dir.path().join("out.txt");
    let (a, w, o) = (s(&a), s(&w), s(&out));
    let args = |threads: &'static str| {
        let mut v = vec!["forward", "--mesh", "builtin:sphere-small", "--anchors", &a];
        v.extend(["--weights", &w, "-o", &o, "--threads", threads]);
        v.iter().map(|x| x.to_string()).collect::<Vec<String>>()
    };
    let run = |threads| {
        let v = args(threads);
        wavg(&v.iter().map(String::as_str).collect::<Vec<_>>())
    };
    for (threads, needle) in [("100000", "the limit on this machine"), ("0", "at least 1")] {
        let r = run(threads);
        let err = String::from_utf8_lossy(&r.stderr);
        assert_eq!(r.status.code(), Some(2), "{err}");
        assert!(err.contains(needle), "{err}");
        assert!(!out.exists());
    }
    let ok = run("3");
    assert!(ok.status.success(), "{ok:?}");
    assert!(out.exists());
}
