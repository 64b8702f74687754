//! The app's files, embedded in the binary at compile time: `facette explore` works
//! offline with nothing but the binary. Hand-written HTML, CSS and JavaScript (plots on
//! canvases, no framework, no build step).

/// (path, content type, content).
pub const ASSETS: &[(&str, &str, &str)] = &[
    (
        "/",
        "text/html; charset=utf-8",
        include_str!("../assets/index.html"),
    ),
    (
        "/app.js",
        "text/javascript; charset=utf-8",
        include_str!("../assets/app.js"),
    ),
    (
        "/panels.js",
        "text/javascript; charset=utf-8",
        include_str!("../assets/panels.js"),
    ),
    (
        "/lobe3d.js",
        "text/javascript; charset=utf-8",
        include_str!("../assets/lobe3d.js"),
    ),
    (
        "/plots.js",
        "text/javascript; charset=utf-8",
        include_str!("../assets/plots.js"),
    ),
    (
        "/app.css",
        "text/css; charset=utf-8",
        include_str!("../assets/app.css"),
    ),
];

/// The asset at `path`.
pub fn asset(path: &str) -> Option<(&'static str, &'static str)> {
    ASSETS
        .iter()
        .find(|(p, _, _)| *p == path)
        .map(|(_, t, c)| (*t, *c))
}
