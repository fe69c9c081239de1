//! `wavg serve`: the interactive page and its API on a local HTTP server (the
//! `wavg-serve` crate), over a mesh whose embedding is loaded or precomputed in the
//! background while the page already shows the mesh.

use std::io::IsTerminal;
use std::net::IpAddr;
use std::path::PathBuf;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Arc, Mutex};
use std::thread::JoinHandle;
use std::time::{Duration, Instant};

use wavg::Surface;

use crate::CliError;
use crate::common::load_valid;
use crate::precompute::Bars;

/// Arguments.
#[derive(clap::Args)]
#[command(after_long_help = "\
Serves one page (three.js, embedded in the binary) and a JSON/binary API on
http://HOST:PORT/: the shaded mesh with orbit controls; click to add anchors, drag them on
the surface, weight sliders with the weighted average moving live; modes spline, average,
decal, distance and remesh; downloads of the curve, the decal's UVs and the remeshed OBJ in
the formats of `wavg spline`, `wavg decal` and `wavg remesh`. Routes and bodies:
docs/serve.md.

Without --embedding the embedding cache's entry for the mesh is used when there is one
(the one `wavg spline` and the other commands compute); else the embedding is precomputed (a tenth of the vertices as
landmarks, 50 to 1000) while the server already answers: the page shows the mesh and the
progress, and the computing routes answer 503 until it is ready; then it is stored in the
cache as the other commands do (not with --no-cache).

Only this machine can connect unless --host names another interface (a warning is
printed: anyone who can reach it can use the server). Ctrl-C (SIGINT) stops the server,
also one started in the background of a script, with exit status 130.")]
pub struct Args {
    #[command(flatten)]
    pub mesh: crate::mesh_arg::MeshArg,
    /// A .wavg embedding of the mesh (default: the embedding cache's when it has one, else
    /// precomputed in memory while the page already shows the mesh).
    #[arg(long)]
    pub embedding: Option<PathBuf>,
    #[command(flatten)]
    pub cache: crate::cache::CacheArg,
    /// TCP port (0: any free port).
    #[arg(long, default_value_t = 8080)]
    pub port: u16,
    /// Interface address to listen on.
    #[arg(long, default_value = "127.0.0.1")]
    pub host: IpAddr,
    /// Open the page in the default browser.
    #[arg(long)]
    pub open: bool,
}

/// How long a stopping server waits for the requests it is answering, and then for the
/// background precomputation to see the cancellation (and not leave a cache entry half
/// written).
const GRACE: Duration = Duration::from_secs(2);

/// Runs the command until Ctrl-C (SIGINT: exit status 130) or another signal ends it.
pub fn run(args: Args) -> Result<(), CliError> {
    let interrupt = Interrupt::install();
    let mesh_name = args.mesh.to_string();
    let mesh = load_valid(&mesh_name)?;
    let embedding = args
        .embedding
        .clone()
        .or_else(|| crate::cache::existing(&mesh, args.cache.no_cache));
    let surface = Surface::from_valid_and_file(mesh, embedding.as_deref())?;
    let (n, m) = (surface.n_vertices(), surface.n_faces());
    let app = wavg_serve::App::new(surface);
    let addr = std::net::SocketAddr::new(args.host, args.port);
    let server = wavg_serve::start(app.clone(), &addr.to_string())
        .map_err(|e| CliError::input(format!("cannot listen on {addr}: {e}")))?;
    interrupt.serving(server.stopper());
    let addr = server.addr();
    if !args.host.is_loopback() {
        eprintln!(
            "wavg: warning: listening on {} : other machines that can reach it can use this \
             server (it has no authentication)",
            args.host
        );
    }
    let url = format!("http://{addr}/");
    println!("{mesh_name}: {n} vertices, {m} faces; serving {url} (Ctrl-C to stop)");
    let mut reporter = None;
    if embedding.is_none() {
        eprintln!("precomputing the embedding (the page shows the mesh meanwhile)...");
        let bars: Box<dyn wavg::Progress + Send> = Box::new(Bars::new(
            std::io::stderr().is_terminal(),
            interrupt.flag.clone(),
        ));
        let t = Instant::now();
        let info = wavg::cache::EntryInfo::new(mesh_name.clone(), "serve");
        let cache = crate::cache::open(args.cache.no_cache);
        let handle = app.precompute_with_cache(Some(bars), cache, info);
        let app2 = app.clone();
        let name = mesh_name.clone();
        let interrupted = interrupt.flag.clone();
        reporter = Some(std::thread::spawn(move || {
            let outcome = handle.join().ok().flatten();
            match app2.status() {
                wavg_serve::Status::Ready => {
                    let seconds = t.elapsed().as_secs_f64();
                    eprintln!("embedding ready in {seconds:.1} s; every route answers");
                    if let Some(wavg::CacheOutcome {
                        provenance: wavg::Provenance::Computed { report, stored },
                        ..
                    }) = &outcome
                    {
                        crate::cache::report_stored(
                            &name,
                            report.landmarks,
                            report.seconds,
                            stored.as_ref(),
                        );
                    }
                }
                _ if interrupted.load(Ordering::SeqCst) => {}
                wavg_serve::Status::Failed(m) => {
                    eprintln!("wavg: the embedding could not be computed: {m}")
                }
                s => eprintln!("wavg: the embedding could not be computed: {s:?}"),
            }
        }));
    }
    if args.open {
        let opener = if cfg!(target_os = "macos") {
            "open"
        } else {
            "xdg-open"
        };
        if let Err(e) = std::process::Command::new(opener).arg(&url).spawn() {
            eprintln!("wavg: could not open a browser ({opener}: {e}); open {url} yourself");
        }
    }
    server.serve_until_stopped(GRACE);
    if !interrupt.flag.load(Ordering::SeqCst) {
        return Ok(());
    }
    wait_at_most(reporter, GRACE);
    Err(CliError {
        code: 130,
        message: "interrupted; the server stopped".into(),
    })
}

/// Ctrl-C while `wavg serve` runs. The handler is set whatever the process inherited, so
/// a server started in the background of a script (where the shell ignores SIGINT for
/// it) stops on SIGINT too. Before the server listens, the command ends at once (reading
/// a large mesh cannot stop partway and leaves nothing behind); afterwards the server
/// stops taking requests and the background precomputation is cancelled.
struct Interrupt {
    /// Set by the handler; the precomputation's cancellation token.
    flag: Arc<AtomicBool>,
    stopper: Arc<Mutex<Option<wavg_serve::Stopper>>>,
}

impl Interrupt {
    fn install() -> Self {
        let flag = Arc::new(AtomicBool::new(false));
        let stopper: Arc<Mutex<Option<wavg_serve::Stopper>>> = Arc::default();
        let (f, s) = (flag.clone(), stopper.clone());
        let _ = ctrlc::set_handler(move || {
            f.store(true, Ordering::SeqCst);
            match s.lock().unwrap_or_else(|e| e.into_inner()).as_ref() {
                Some(stopper) => stopper.stop(),
                None => {
                    eprintln!("wavg: interrupted");
                    std::process::exit(130);
                }
            }
        });
        Self { flag, stopper }
    }

    /// From now on Ctrl-C stops `stopper`'s server.
    fn serving(&self, stopper: wavg_serve::Stopper) {
        *self.stopper.lock().unwrap_or_else(|e| e.into_inner()) = Some(stopper);
    }
}

/// Waits for `thread` to finish, for at most `limit`.
fn wait_at_most(thread: Option<JoinHandle<()>>, limit: Duration) {
    let Some(thread) = thread else { return };
    let t = Instant::now();
    while !thread.is_finished() && t.elapsed() < limit {
        std::thread::sleep(Duration::from_millis(20));
    }
}
