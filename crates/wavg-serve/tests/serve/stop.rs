//! A server stopped from another thread (the CLI's Ctrl-C handler): the server returns
//! from `serve_until_stopped` after answering what it had received, and a stop asked
//! before the server waits is not lost.

use std::time::{Duration, Instant};

use crate::common::{request, surface};

fn start() -> wavg_serve::Running {
    wavg_serve::start(wavg_serve::App::new(surface().clone()), "127.0.0.1:0").unwrap()
}

#[test]
fn a_stopper_on_another_thread_ends_serving() {
    let running = start();
    let addr = running.addr();
    assert_eq!(request(addr, "GET", "/api/status", b"").status, 200);
    let stopper = running.stopper();
    let t = Instant::now();
    let stopping = std::thread::spawn(move || {
        std::thread::sleep(Duration::from_millis(200));
        stopper.stop();
    });
    running.serve_until_stopped(Duration::from_secs(5));
    stopping.join().unwrap();
    assert!(t.elapsed() < Duration::from_secs(5), "{:?}", t.elapsed());
}

#[test]
fn a_stop_asked_before_serving_is_kept() {
    let running = start();
    let stopper = running.stopper();
    stopper.stop();
    stopper.stop();
    let t = Instant::now();
    running.serve_until_stopped(Duration::from_secs(5));
    assert!(t.elapsed() < Duration::from_secs(2), "{:?}", t.elapsed());
}
