//! The page's files, embedded at compile time: our sources from `web/src/` (their only
//! copy) and the pinned three.js files from `web/vendor/three/` (checked against
//! `web/package-lock.json` by `cargo xtask web --check`). No path from a request reaches
//! the file system. They are read through `web`, a link to the repository's `web/` folder
//! beside this crate's `Cargo.toml`, so that `cargo package` carries them in the package.

/// One embedded file: its URL path, content type and bytes, from `web/$dir/$name`.
macro_rules! file {
    ($url:literal, $ty:expr, $dir:literal, $name:literal) => {
        (
            $url,
            $ty,
            include_bytes!(concat!(
                env!("CARGO_MANIFEST_DIR"),
                "/web/",
                $dir,
                "/",
                $name
            )) as &[u8],
        )
    };
}

const JS: &str = "text/javascript; charset=utf-8";

/// Every file the page loads.
static FILES: &[(&str, &str, &[u8])] = &[
    file!(
        "/index.html",
        "text/html; charset=utf-8",
        "src",
        "index.html"
    ),
    file!("/style.css", "text/css; charset=utf-8", "src", "style.css"),
    file!("/app.js", JS, "src", "app.js"),
    file!("/api.js", JS, "src", "api.js"),
    file!("/picking.js", JS, "src", "picking.js"),
    file!("/modes.js", JS, "src", "modes.js"),
    file!("/colors.js", JS, "src", "colors.js"),
    file!("/frame.js", JS, "src", "frame.js"),
    file!(
        "/vendor/three/three.module.js",
        JS,
        "vendor/three",
        "three.module.js"
    ),
    file!(
        "/vendor/three/three.core.js",
        JS,
        "vendor/three",
        "three.core.js"
    ),
    file!(
        "/vendor/three/OrbitControls.js",
        JS,
        "vendor/three",
        "OrbitControls.js"
    ),
    file!(
        "/vendor/three/LICENSE",
        "text/plain; charset=utf-8",
        "vendor/three",
        "LICENSE"
    ),
];

/// The content type and bytes of the file at `path` (`/` is the page).
pub(crate) fn get(path: &str) -> Option<(&'static str, &'static [u8])> {
    let path = if path == "/" { "/index.html" } else { path };
    FILES
        .iter()
        .find(|(url, _, _)| *url == path)
        .map(|&(_, ty, bytes)| (ty, bytes))
}
