//! The server's state: the surface, and the precomputation of its embedding running in the
//! background while the page already loads the mesh.

use std::sync::{Arc, Mutex, RwLock};

use wavg::{PrecomputeOptions, Progress, Stage, Surface};

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
        let has = surface.embedding().is_some();
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

    /// Computes the embedding on a new thread (a tenth of the vertices as landmarks, 50 to
    /// 1000, as the command line does), reporting each stage to the status and to
    /// `terminal` when given. Does nothing when the app is ready.
    pub fn precompute_in_background(
        &self,
        terminal: Option<Box<dyn Progress + Send>>,
    ) -> std::thread::JoinHandle<()> {
        let app = self.clone();
        std::thread::spawn(move || {
            if app.status() == Status::Ready {
                return;
            }
            let mut surface = app.inner.mesh_surface.clone();
            let landmarks = (surface.n_vertices() / 10).clamp(50, 1000);
            let opts = PrecomputeOptions {
                landmarks,
                quality_pairs: 0,
                ..Default::default()
            };
            let sink = Sink {
                app: &app,
                terminal: terminal.as_deref(),
            };
            let result = surface.precompute(&opts, &sink);
            let status = match result {
                Ok(_) => {
                    *app.inner.ready.write().unwrap_or_else(|e| e.into_inner()) = Some(surface);
                    Status::Ready
                }
                Err(e) => Status::Failed(e.to_string().replace('\n', " ")),
            };
            app.set_status(status);
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
