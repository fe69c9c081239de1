//! How quickly the precomputation answers a cancellation: runs it on MESH with a progress
//! sink that times, per thread, the gaps between its looks at `cancelled()` (a thread's
//! longest gap bounds how late it notices a Ctrl-C), and optionally cancels after T seconds
//! and times the return. `--no-first-pass` turns the decimation's first pass off
//! (meshoptimizer's simplifier), for comparing landmark quality with and without it;
//! `-o OUT.wavg` saves the embedding.
//!
//! `cargo xtask lab cancel_latency MESH [--cancel-at T] [--no-first-pass] [-o OUT.wavg]`
//!
//! Prints the ten longest gaps (seconds, thread, the last stage reported before the gap
//! ended, and when it ended), then the report (or the cancellation's latency) as JSON.

use std::cell::Cell;
use std::sync::Mutex;
use std::time::{Duration, Instant};

use wavg_embed::{PrecomputeOptions, Progress, Stage, file, precompute};
use wavg_mesh::ValidMesh;

thread_local! {
    static LAST: Cell<Option<Instant>> = const { Cell::new(None) };
}

/// Times the gaps between looks at `cancelled()`, per thread.
struct GapTimer {
    start: Instant,
    cancel_at: Option<Duration>,
    stage: Mutex<(Stage, f64)>,
    /// `(gap, thread, stage and fraction last reported, seconds since start)`.
    gaps: Mutex<Vec<(f64, String, String, f64)>>,
}

impl Progress for GapTimer {
    fn report(&self, stage: Stage, fraction: f64) {
        *self.stage.lock().unwrap() = (stage, fraction);
    }

    fn cancelled(&self) -> bool {
        let now = Instant::now();
        if let Some(last) = LAST.with(|l| l.replace(Some(now))) {
            let gap = (now - last).as_secs_f64();
            if gap > 0.05 {
                let (s, f) = *self.stage.lock().unwrap();
                let name = std::thread::current().name().unwrap_or("?").to_string();
                let at = (now - self.start).as_secs_f64();
                let mut g = self.gaps.lock().unwrap();
                g.push((gap, name, format!("{} {f:.2}", s.name()), at));
            }
        }
        self.cancel_at.is_some_and(|t| now - self.start >= t)
    }
}

fn main() {
    let mut args: Vec<String> = std::env::args().skip(1).collect();
    let mut take = |name: &str, with_value: bool| {
        let i = args.iter().position(|a| a == name)?;
        args.remove(i);
        Some(if with_value {
            args.remove(i)
        } else {
            String::new()
        })
    };
    let cancel_at =
        take("--cancel-at", true).map(|t| Duration::from_secs_f64(t.parse().expect("T")));
    let no_first_pass = take("--no-first-pass", false).is_some();
    let out = take("-o", true);
    let path = args.first().expect("MESH");
    let mesh = ValidMesh::new(wavg_mesh::io::load(path.as_ref()).expect("load")).expect("valid");
    let mut opts = PrecomputeOptions::default();
    if no_first_pass {
        opts.decimate.first_pass_vertices = 0;
    }
    let timer = GapTimer {
        start: Instant::now(),
        cancel_at,
        stage: Mutex::new((Stage::Decimate, 0.0)),
        gaps: Mutex::new(Vec::new()),
    };
    let result = precompute(&mesh, &opts, &timer);
    let wall = timer.start.elapsed().as_secs_f64();
    let mut gaps = timer.gaps.into_inner().unwrap();
    gaps.sort_by(|a, b| b.0.total_cmp(&a.0));
    for (gap, thread, stage, at) in gaps.iter().take(10) {
        eprintln!("gap {gap:7.3} s  thread {thread:<16} after {stage:<16} ended at {at:7.1} s");
    }
    match result {
        Ok((emb, report)) => {
            if let Some(out) = out {
                file::save(out.as_ref(), &emb, &mesh).expect("save");
            }
            println!(
                "{{\"wall\": {wall:.2}, \"landmarks\": {}, \"geodesic_rel_err_p50\": {:.5}, \
                 \"geodesic_rel_err_p90\": {:.5}, \"seconds\": {:.2}, \"stages\": \"{:?}\"}}",
                report.landmarks,
                report.geodesic_rel_err_p50,
                report.geodesic_rel_err_p90,
                report.seconds,
                report.stages
            );
        }
        Err(e) => {
            let latency = cancel_at.map_or(f64::NAN, |t| wall - t.as_secs_f64());
            println!("{{\"wall\": {wall:.2}, \"error\": \"{e}\", \"latency\": {latency:.3}}}");
        }
    }
}
