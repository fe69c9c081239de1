//! The page's files, embedded at compile time from `web/dist/` (no path from a request
//! reaches the file system).

/// One embedded file: its URL path, content type and bytes.
macro_rules! file {
    ($url:literal, $ty:expr, $rel:literal) => {
        (
            $url,
            $ty,
            include_bytes!(concat!(
                env!("CARGO_MANIFEST_DIR"),
                "/../../web/dist/",
                $rel
            )) as &[u8],
        )
    };
}

const JS: &str = "text/javascript; charset=utf-8";

/// Every file the page loads.
static FILES: &[(&str, &str, &[u8])] = &[
    file!("/index.html", "text/html; charset=utf-8", "index.html"),
    file!("/style.css", "text/css; charset=utf-8", "style.css"),
    file!("/app.js", JS, "app.js"),
    file!("/api.js", JS, "api.js"),
    file!("/picking.js", JS, "picking.js"),
    file!("/modes.js", JS, "modes.js"),
    file!("/colors.js", JS, "colors.js"),
    file!("/frame.js", JS, "frame.js"),
    file!(
        "/vendor/three/three.module.js",
        JS,
        "vendor/three/three.module.js"
    ),
    file!(
        "/vendor/three/three.core.js",
        JS,
        "vendor/three/three.core.js"
    ),
    file!(
        "/vendor/three/OrbitControls.js",
        JS,
        "vendor/three/OrbitControls.js"
    ),
    file!(
        "/vendor/three/LICENSE",
        "text/plain; charset=utf-8",
        "vendor/three/LICENSE"
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
