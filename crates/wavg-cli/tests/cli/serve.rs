//! `wavg serve` as a process: it prints where it listens, answers there, precomputes in
//! the background, takes the mesh positionally or as `--mesh`, and warns for non-loopback
//! hosts.

use std::io::{BufRead, BufReader, Read, Write};
use std::net::TcpStream;
use std::process::{Child, Command, Stdio};
use std::time::{Duration, Instant};

/// Starts `wavg serve ARGS --port 0` (embedding cache in a folder of target/); returns the
/// child and its address.
fn serve(args: &[&str]) -> (Child, String) {
    serve_cached(args, &cache_dir("serve"))
}

/// A fresh cache folder under the test's temporary folder.
fn cache_dir(name: &str) -> std::path::PathBuf {
    let d = std::path::Path::new(env!("CARGO_TARGET_TMPDIR")).join(format!("serve-cache-{name}"));
    let _ = std::fs::remove_dir_all(&d);
    d
}

fn serve_cached(args: &[&str], cache: &std::path::Path) -> (Child, String) {
    let mut cmd = Command::new(env!("CARGO_BIN_EXE_wavg"));
    cmd.env("WAVG_CACHE_DIR", cache)
        .arg("serve")
        .args(args)
        .args(["--port", "0"]);
    spawn_server(cmd)
}

/// Spawns `cmd` (a `wavg serve`) with its output piped; returns the child and the address
/// its first line says it serves on.
fn spawn_server(mut cmd: Command) -> (Child, String) {
    let mut child = cmd
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let mut line = String::new();
    BufReader::new(child.stdout.take().unwrap())
        .read_line(&mut line)
        .unwrap();
    let addr = line
        .split("serving http://")
        .nth(1)
        .unwrap_or_else(|| panic!("no address in {line:?}"))
        .split('/')
        .next()
        .unwrap()
        .to_string();
    (child, addr)
}

fn get(addr: &str, path: &str) -> String {
    let mut s = TcpStream::connect(addr).unwrap();
    s.set_read_timeout(Some(Duration::from_secs(30))).unwrap();
    write!(
        s,
        "GET {path} HTTP/1.1\r\nHost: x\r\nConnection: close\r\n\r\n"
    )
    .unwrap();
    let mut out = String::new();
    s.read_to_string(&mut out).unwrap();
    out
}

/// Stops the server and returns everything it wrote on standard error.
fn kill_for_stderr(child: &mut Child) -> String {
    child.kill().unwrap();
    let mut err = String::new();
    child
        .stderr
        .take()
        .unwrap()
        .read_to_string(&mut err)
        .unwrap();
    err
}

#[test]
fn serve_answers_and_becomes_ready() {
    for args in [
        &["builtin:sphere-small"][..],
        &["--mesh", "builtin:sphere-small"],
    ] {
        let (mut child, addr) = serve(args);
        let info = get(&addr, "/api/info");
        assert!(info.starts_with("HTTP/1.1 200"), "{info}");
        assert!(info.contains("\"faces\":320"), "{info}");
        let t = Instant::now();
        while !get(&addr, "/api/status").contains("\"ready\"") {
            assert!(t.elapsed() < Duration::from_secs(120), "never ready");
            std::thread::sleep(Duration::from_millis(100));
        }
        assert!(get(&addr, "/").contains("importmap"));
        child.kill().unwrap();
        child.wait().unwrap();
    }
}

/// Waits until the embedding is ready.
fn wait_ready(addr: &str) {
    let t = Instant::now();
    while !get(addr, "/api/status").contains("\"ready\"") {
        assert!(t.elapsed() < Duration::from_secs(120), "never ready");
        std::thread::sleep(Duration::from_millis(100));
    }
}

#[test]
fn a_computed_embedding_is_cached_unless_no_cache() {
    let entries = |d: &std::path::Path| -> Vec<String> {
        let mut v: Vec<String> = std::fs::read_dir(d)
            .map(|r| {
                r.map(|e| e.unwrap().file_name().into_string().unwrap())
                    .collect()
            })
            .unwrap_or_default();
        v.sort();
        v
    };
    let dir = cache_dir("computed");
    let (mut child, addr) = serve_cached(&["builtin:sphere-small", "--no-cache"], &dir);
    wait_ready(&addr);
    std::thread::sleep(Duration::from_millis(500));
    child.kill().unwrap();
    child.wait().unwrap();
    assert!(entries(&dir).is_empty(), "{:?}", entries(&dir));
    let (mut child, addr) = serve_cached(&["builtin:sphere-small"], &dir);
    wait_ready(&addr);
    let t = Instant::now();
    while entries(&dir).len() < 2 {
        assert!(
            t.elapsed() < Duration::from_secs(30),
            "not cached: {:?}",
            entries(&dir)
        );
        std::thread::sleep(Duration::from_millis(100));
    }
    child.kill().unwrap();
    child.wait().unwrap();
    let e = entries(&dir);
    assert!(e[0].ends_with(".json") && e[1].ends_with(".wavg"), "{e:?}");
    // The next server loads the entry: ready at once, nothing precomputed.
    let (mut child, addr) = serve_cached(&["builtin:sphere-small"], &dir);
    assert!(get(&addr, "/api/status").contains("\"ready\""));
    let err = kill_for_stderr(&mut child);
    child.wait().unwrap();
    assert!(!err.contains("precomputing"), "{err}");
}

#[test]
fn other_hosts_get_a_warning_and_bad_meshes_fail() {
    let (mut child, _) = serve(&["builtin:sphere-small", "--host", "0.0.0.0"]);
    let err = kill_for_stderr(&mut child);
    assert!(err.contains("warning") && err.contains("0.0.0.0"), "{err}");
    let out = Command::new(env!("CARGO_BIN_EXE_wavg"))
        .args(["serve", "no-such-mesh.obj", "--port", "0"])
        .env("WAVG_CACHE_DIR", cache_dir("bad-mesh"))
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(2));
}

/// Starts `wavg serve ARGS --port 0` the way a non-interactive script's `&` does, with
/// SIGINT ignored (`trap "" INT` is inherited through `exec`); returns the child (its
/// id is the server's) and the address.
#[cfg(unix)]
fn serve_with_sigint_ignored(args: &[&str], cache: &std::path::Path) -> (Child, String) {
    let mut cmd = Command::new("sh");
    cmd.arg("-c")
        .arg("trap '' INT; exec \"$0\" serve \"$@\" --port 0")
        .arg(env!("CARGO_BIN_EXE_wavg"))
        .args(args)
        .env("WAVG_CACHE_DIR", cache);
    spawn_server(cmd)
}

/// Sends SIGINT to `child` and returns its exit status (None: still running after 10 s,
/// then killed) and standard error.
#[cfg(unix)]
fn interrupt(mut child: Child) -> (Option<i32>, String, Duration) {
    let kill = Command::new("kill")
        .args(["-INT", &child.id().to_string()])
        .status()
        .unwrap();
    assert!(kill.success());
    let t = Instant::now();
    while t.elapsed() < Duration::from_secs(10) {
        if let Some(status) = child.try_wait().unwrap() {
            let waited = t.elapsed();
            let mut err = String::new();
            child
                .stderr
                .take()
                .unwrap()
                .read_to_string(&mut err)
                .unwrap();
            return (status.code(), err, waited);
        }
        std::thread::sleep(Duration::from_millis(20));
    }
    (None, kill_for_stderr(&mut child), t.elapsed())
}

/// Ctrl-C stops the server even when it was started with SIGINT ignored (in the
/// background of a script): exit status 130 within seconds, while the embedding is
/// still being precomputed and once it is ready.
#[cfg(unix)]
#[test]
fn sigint_stops_a_server_started_with_sigint_ignored() {
    let dir = cache_dir("sigint");
    // Precomputing (no cache): SIGINT at once, the precomputation is cancelled.
    let (child, addr) = serve_with_sigint_ignored(&["builtin:torus", "--no-cache"], &dir);
    assert!(get(&addr, "/api/info").starts_with("HTTP/1.1 200"));
    let (code, err, waited) = interrupt(child);
    assert_eq!(code, Some(130), "{err}");
    assert!(waited < Duration::from_secs(5), "{waited:?}: {err}");
    assert!(err.contains("interrupted"), "{err}");
    assert!(!err.contains("could not be computed"), "{err}");
    // Ready, serving.
    let (child, addr) = serve_with_sigint_ignored(&["builtin:sphere-small", "--no-cache"], &dir);
    wait_ready(&addr);
    let (code, err, waited) = interrupt(child);
    assert_eq!(code, Some(130), "{err}");
    assert!(waited < Duration::from_secs(5), "{waited:?}: {err}");
}
