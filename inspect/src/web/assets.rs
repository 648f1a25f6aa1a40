//! The page's files, embedded in the binary (no network, no CDN): hand-written HTML,
//! CSS and JavaScript under `assets/`.

use axum::http::header::{CACHE_CONTROL, CONTENT_TYPE};
use axum::response::IntoResponse;
use axum::routing::get;
use axum::Router;

/// `(URL path, content type, text)` of every file.
const FILES: &[(&str, &str, &str)] = &[
    (
        "/",
        "text/html; charset=utf-8",
        include_str!("assets/index.html"),
    ),
    (
        "/style.css",
        "text/css; charset=utf-8",
        include_str!("assets/style.css"),
    ),
    (
        "/app.js",
        "text/javascript; charset=utf-8",
        include_str!("assets/app.js"),
    ),
    (
        "/graph.js",
        "text/javascript; charset=utf-8",
        include_str!("assets/graph.js"),
    ),
    (
        "/layout.js",
        "text/javascript; charset=utf-8",
        include_str!("assets/layout.js"),
    ),
    (
        "/labels.js",
        "text/javascript; charset=utf-8",
        include_str!("assets/labels.js"),
    ),
    (
        "/panels.js",
        "text/javascript; charset=utf-8",
        include_str!("assets/panels.js"),
    ),
];

/// One route per file.
pub fn routes() -> Router {
    let mut router = Router::new();
    for &(path, kind, text) in FILES {
        router = router.route(
            path,
            get(move || async move {
                // `no-cache`: a page left open picks up a new ferroc's files.
                ([(CONTENT_TYPE, kind), (CACHE_CONTROL, "no-cache")], text).into_response()
            }),
        );
    }
    router
}
