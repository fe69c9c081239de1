//! The server's state: the surface, and the precomputation of its embedding running in the
//! background while the page already loads the mesh.

use std::sync::{Arc, Mutex, RwLock};

use wavg::{Progress, Stage, Surface};

use crate::ApiError;

/// Where the embedding stands.
#[derive(Clone, Debug, PartialEq)]
pub enum Status {
    /// Being computed: the stage's name and the fraction of it done.
    Precomputing {
        /// Stage name.
        stage: String,
        /// 0..=1.
        fraction: f64,
    },
    /// Ready: every route answers.
    Ready,
    /// The precomputation failed; the computing routes answer 503 with this message.
    Failed(String),
}

/// What the request handlers share: the surface (replaced once its embedding is ready)
/// and the status. Cheap to clone.
#[derive(Clone)]
pub struct App {
    inner: Arc<Inner>,
}

struct Inner {
    /// The mesh as loaded; its embedding is the 3-D positions until `ready` is set.
    mesh_surface: Surface,
    ready: RwLock<Option<Surface>>,
    status: Mutex<Status>,
    mesh_bytes: Vec<u8>,
}

impl App {
    /// An app on `surface`. When the surface already has an embedding (loaded from a
    /// `.wavg` file or computed) it is ready at once; otherwise call
    /// [`App::precompute_in_background`].
    pub fn new(surface: Surface) -> Self {
        let has = surface.has_embedding();
        let mesh_bytes = crate::meshbin::encode_mesh(surface.mesh());
        Self {
            inner: Arc::new(Inner {
                ready: RwLock::new(has.then(|| surface.clone())),
                status: Mutex::new(if has {
                    Status::Ready
                } else {
                    Status::Precomputing {
                        stage: "waiting".into(),
                        fraction: 0.0,
                    }
                }),
                mesh_surface: surface,
                mesh_bytes,
            }),
        }
    }

    /// [`App::precompute_with_cache`] without a cache (the embedding computed in memory).
    pub fn precompute_in_background(
        &self,
        terminal: Option<Box<dyn Progress + Send>>,
    ) -> std::thread::JoinHandle<Option<wavg::CacheOutcome>> {
        self.precompute_with_cache(terminal, None, wavg::cache::EntryInfo::new("", "serve"))
    }

    /// Computes the embedding on a new thread with the library's default options for the
    /// mesh (`wavg::default_precompute_options`), through `cache` when given (its entry is
    /// read, or computed and stored with `info`), reporting each stage to the status and to
    /// `terminal` when given. Does nothing when the app is ready. The thread returns where
    /// the embedding came from (`None` when it failed or was not needed).
    pub fn precompute_with_cache(
        &self,
        terminal: Option<Box<dyn Progress + Send>>,
        cache: Option<wavg::cache::Cache>,
        info: wavg::cache::EntryInfo,
    ) -> std::thread::JoinHandle<Option<wavg::CacheOutcome>> {
        let app = self.clone();
        std::thread::spawn(move || {
            if app.status() == Status::Ready {
                return None;
            }
            let mut surface = app.inner.mesh_surface.clone();
            let opts = wavg::default_precompute_options(surface.mesh());
            let sink = Sink {
                app: &app,
                terminal: terminal.as_deref(),
            };
            let result = surface.precompute_cached(&opts, cache.as_ref(), &info, &sink);
            let (status, outcome) = match result {
                Ok(outcome) => {
                    *app.inner.ready.write().unwrap_or_else(|e| e.into_inner()) = Some(surface);
                    (Status::Ready, Some(outcome))
                }
                Err(e) => (Status::Failed(e.to_string().replace('\n', " ")), None),
            };
            app.set_status(status);
            outcome
        })
    }

    /// The current status.
    pub fn status(&self) -> Status {
        self.inner
            .status
            .lock()
            .unwrap_or_else(|e| e.into_inner())
            .clone()
    }

    fn set_status(&self, s: Status) {
        *self.inner.status.lock().unwrap_or_else(|e| e.into_inner()) = s;
    }

    /// The mesh (available while precomputing).
    pub(crate) fn mesh_surface(&self) -> &Surface {
        &self.inner.mesh_surface
    }

    /// The `GET /api/mesh` body, encoded once.
    pub(crate) fn mesh_bytes(&self) -> &[u8] {
        &self.inner.mesh_bytes
    }

    /// The surface with its embedding once it is ready (to store a computed embedding).
    pub fn ready_surface(&self) -> Option<Surface> {
        self.inner
            .ready
            .read()
            .unwrap_or_else(|e| e.into_inner())
            .clone()
    }

    /// The surface with its embedding, or 503 while it is being computed.
    pub(crate) fn surface(&self) -> Result<Surface, ApiError> {
        if let Some(s) = &*self.inner.ready.read().unwrap_or_else(|e| e.into_inner()) {
            return Ok(s.clone());
        }
        Err(ApiError::status(
            503,
            match self.status() {
                Status::Failed(m) => format!("the embedding could not be computed: {m}"),
                Status::Precomputing { stage, fraction } => format!(
                    "the embedding is being computed ({stage}, {:.0}%); try again shortly",
                    100.0 * fraction
                ),
                Status::Ready => "the embedding is not ready".into(),
            },
        ))
    }
}

/// The precomputation's progress: to the status, and to the terminal's sink.
struct Sink<'a> {
    app: &'a App,
    terminal: Option<&'a (dyn Progress + Send)>,
}

impl Progress for Sink<'_> {
    fn report(&self, stage: Stage, fraction: f64) {
        self.app.set_status(Status::Precomputing {
            stage: stage.name().into(),
            fraction: fraction.clamp(0.0, 1.0),
        });
        if let Some(t) = self.terminal {
            t.report(stage, fraction);
        }
    }

    fn cancelled(&self) -> bool {
        self.terminal.is_some_and(|t| t.cancelled())
    }
}
