//! The JSON API the page uses (docs/inspect.md, "The web page"): each request becomes
//! one or more inspection queries; answers are the programs' JSON, errors
//! `{"error": "…"}` with a status saying whose fault it was ([`ApiError`]).

use super::error::ApiError;
use super::peer::Peer;
use crate::client::part_of;
use crate::request::{key, SetRequest, What};
use axum::body::Bytes;
use axum::extract::rejection::{BytesRejection, PathRejection, QueryRejection};
use axum::extract::{DefaultBodyLimit, Path, Query, State as Shared};
use axum::routing::{get, post};
use axum::{Json, Router};
use serde::Deserialize;
use serde_json::{json, Map, Value};
use std::sync::Arc;

/// Bodies larger than this are refused unread (the programs refuse more than 64 KiB).
const MAX_BODY: usize = 64 * 1024;
/// Ports asked in one `/api/values` request at most.
const MAX_PATHS: usize = 256;
/// Longest name or path accepted.
const MAX_NAME: usize = 1000;

/// API requests asking the programs at once; more wait (at most the lookup limit) for
/// one to finish. Fewer than the runtime's blocking threads (16), so a flood of
/// requests that wait for answers cannot take every thread.
const LOOKUPS: usize = 12;

/// What every request handler shares.
pub struct State {
    peer: Peer,
    /// The application asked for when a request names none (`--app`, default `*`).
    app: String,
    /// Room for requests asking the programs ([`LOOKUPS`]).
    lookups: Arc<tokio::sync::Semaphore>,
    /// How long a request waits for room before it is answered 503.
    wait: std::time::Duration,
}

impl State {
    pub fn new(peer: Peer, app: String, wait: std::time::Duration) -> State {
        State {
            peer,
            app,
            lookups: Arc::new(tokio::sync::Semaphore::new(LOOKUPS)),
            wait,
        }
    }
}

type Reply = Result<Json<Value>, ApiError>;

/// The API's routes.
pub fn routes(state: Arc<State>) -> Router {
    Router::new()
        .route("/api/tree", get(tree))
        .route("/api/status", get(status))
        .route("/api/values", get(values))
        .route("/api/param/{*path}", get(param).post(set_param))
        .route("/api/edit", post(edit))
        .layer(DefaultBodyLimit::max(MAX_BODY))
        .layer(axum::middleware::from_fn_with_state(state.clone(), room))
        .with_state(state)
}

/// Lets an API request ask the programs when there is room ([`LOOKUPS`]), or answers
/// 503 after waiting the lookup limit: under a flood, a request gives up in time
/// instead of queueing behind every other.
async fn room(
    Shared(s): Shared<Arc<State>>,
    request: axum::extract::Request,
    next: axum::middleware::Next,
) -> axum::response::Response {
    use axum::response::IntoResponse;
    let slot = tokio::time::timeout(s.wait, s.lookups.clone().acquire_owned()).await;
    match slot {
        Ok(Ok(_slot)) => next.run(request).await,
        _ => ApiError::new(
            axum::http::StatusCode::SERVICE_UNAVAILABLE,
            "the inspector is busy with other requests; ask again",
        )
        .into_response(),
    }
}

/// The query string every API takes (each uses some of the fields).
#[derive(Debug, Default, Deserialize)]
#[serde(deny_unknown_fields)]
struct Params {
    app: Option<String>,
    part: Option<String>,
    /// Comma-separated port paths (`/api/values`).
    paths: Option<String>,
}

fn query(q: Result<Query<Params>, QueryRejection>) -> Result<Params, ApiError> {
    q.map(|Query(p)| p).map_err(|e| {
        ApiError::bad_request(format!(
            "the query string is not app=…&part=…&paths=…: {}",
            e.body_text()
        ))
    })
}

/// Runs blocking Zenoh work on tokio's blocking threads.
async fn blocking<T: Send + 'static>(
    work: impl FnOnce() -> Result<T, ApiError> + Send + 'static,
) -> Result<T, ApiError> {
    tokio::task::spawn_blocking(work)
        .await
        .map_err(|e| ApiError::internal(format!("the request failed inside the web server: {e}")))?
}

/// An application or part name: `*` where `any` allows it, else a key chunk without
/// wildcards or slashes.
fn name(what: &str, text: Option<&str>, any: bool) -> Result<String, ApiError> {
    let text = match text {
        Some(t) => t,
        None if any => "*",
        None => {
            return Err(ApiError::bad_request(format!(
                "name the {what}: ?{what}=NAME"
            )))
        }
    };
    if text == "*" && any {
        return Ok(text.to_owned());
    }
    if text.len() > MAX_NAME || !chunk(text) {
        return Err(ApiError::bad_request(format!(
            "`{text}` cannot be the {what}'s name (visible ASCII without spaces, slashes or wildcards)"
        )));
    }
    Ok(text.to_owned())
}

/// One chunk of a key: visible ASCII without Zenoh's wildcard and special characters
/// (model names are identifiers; anything else cannot name an element).
fn chunk(text: &str) -> bool {
    !text.is_empty()
        && text
            .bytes()
            .all(|b| b.is_ascii_graphic() && !b"/*$?#".contains(&b))
}

/// A module path with a port or parameter name: `MODULE/PATH/NAME`.
fn path(text: &str) -> Result<String, ApiError> {
    let ok = !text.is_empty()
        && text.len() <= MAX_NAME
        && text.contains('/')
        && text.split('/').all(chunk);
    if !ok {
        return Err(ApiError::bad_request(format!(
            "`{text}` is not a path MODULE/PATH/NAME (no empty parts or wildcards)"
        )));
    }
    Ok(text.to_owned())
}

fn app(state: &State, p: &Params) -> Result<String, ApiError> {
    name("app", Some(p.app.as_deref().unwrap_or(&state.app)), true)
}

/// `GET /api/tree?app=APP`: `{parts: [{app, part, tree}]}` of every answering part.
async fn tree(Shared(s): Shared<Arc<State>>, q: Result<Query<Params>, QueryRejection>) -> Reply {
    let p = query(q)?;
    let app = app(&s, &p)?;
    blocking(move || {
        let answers = s.peer.ask(&key(&app, "*", &What::Tree), None)?;
        let parts = answers.iter().map(|a| {
            let (app, part) = a.app_part();
            match &a.result {
                Ok(tree) => json!({ "app": app, "part": part, "tree": tree }),
                Err(e) => json!({ "app": app, "part": part, "error": e }),
            }
        });
        Ok(Json(json!({ "parts": parts.collect::<Vec<_>>() })))
    })
    .await
}

/// `GET /api/status?app=APP&part=PART`: `{containers, links, activities, transport}`.
async fn status(Shared(s): Shared<Arc<State>>, q: Result<Query<Params>, QueryRejection>) -> Reply {
    let p = query(q)?;
    let (app, part) = (app(&s, &p)?, name("part", p.part.as_deref(), false)?);
    blocking(move || {
        let mut out = Map::new();
        for (field, what) in [
            ("containers", What::Containers),
            ("links", What::Links),
            ("activities", What::Activities),
        ] {
            out.insert(field.into(), s.peer.one(&key(&app, &part, &what), None)?);
        }
        // How the part's links to other parts travel; `null` from a program that does
        // not answer it (one built before it was asked).
        let transport = s.peer.one(&key(&app, &part, &What::Transport), None);
        out.insert("transport".into(), transport.unwrap_or(Value::Null));
        Ok(Json(Value::Object(out)))
    })
    .await
}

/// `GET /api/values?app=APP&paths=P1,P2,…`: `{values: {PATH: value or {error}}}`.
async fn values(Shared(s): Shared<Arc<State>>, q: Result<Query<Params>, QueryRejection>) -> Reply {
    let p = query(q)?;
    let app = app(&s, &p)?;
    let list = p.paths.as_deref().unwrap_or_default();
    let paths = (list.split(',').filter(|x| !x.is_empty()))
        .map(path)
        .collect::<Result<Vec<_>, _>>()?;
    if paths.is_empty() || paths.len() > MAX_PATHS {
        return Err(ApiError::bad_request(format!(
            "name 1 to {MAX_PATHS} ports: ?paths=MODULE/PORT,MODULE/PORT"
        )));
    }
    blocking(move || {
        let mut out = Map::new();
        for path in paths {
            let k = key(&app, part_of(&path), &What::Value(path.clone()));
            let value = match s.peer.one(&k, None) {
                Ok(v) => v,
                Err(e) if e.status == axum::http::StatusCode::UNPROCESSABLE_ENTITY => {
                    json!({ "error": e.message })
                }
                Err(e) => return Err(e),
            };
            out.insert(path, value);
        }
        Ok(Json(json!({ "values": out })))
    })
    .await
}

fn param_path(p: Result<Path<String>, PathRejection>) -> Result<String, ApiError> {
    let Path(text) = p.map_err(|e| ApiError::bad_request(e.body_text()))?;
    path(&text)
}

/// `GET /api/param/MODULE/PATH/NAME?app=APP`: the parameter with type, unit, range.
async fn param(
    Shared(s): Shared<Arc<State>>,
    at: Result<Path<String>, PathRejection>,
    q: Result<Query<Params>, QueryRejection>,
) -> Reply {
    let (at, p) = (param_path(at)?, query(q)?);
    let app = app(&s, &p)?;
    let k = key(&app, part_of(&at), &What::Param(at.clone()));
    blocking(move || s.peer.one(&k, None).map(Json)).await
}

/// `POST /api/param/MODULE/PATH/NAME?app=APP` with `{"set": "VALUE", "token": "…"}`:
/// the parameter after the change, or the program's reason for refusing it (422).
async fn set_param(
    Shared(s): Shared<Arc<State>>,
    at: Result<Path<String>, PathRejection>,
    q: Result<Query<Params>, QueryRejection>,
    body: Result<Bytes, BytesRejection>,
) -> Reply {
    let (at, p) = (param_path(at)?, query(q)?);
    let app = name("app", p.app.as_deref(), false)?;
    let body = body_bytes(body)?;
    let change: SetRequest = serde_json::from_slice(&body).map_err(|e| {
        ApiError::bad_request(format!(
            "a change is the JSON {{\"set\": \"VALUE\", \"token\": \"TOKEN\"}}: {e}"
        ))
    })?;
    let payload = serde_json::to_vec(&change).map_err(|e| ApiError::internal(e.to_string()))?;
    let k = key(&app, part_of(&at), &What::Param(at.clone()));
    blocking(move || s.peer.one(&k, Some(payload)).map(Json)).await
}

/// `POST /api/edit?app=APP&part=PART`: the JSON body, unchanged, as the payload of the
/// query `ferroc/APP/inspect/PART/edit` (a structural change, checked by the program's
/// compiler); its answer, or its diagnostics as the error (422).
async fn edit(
    Shared(s): Shared<Arc<State>>,
    q: Result<Query<Params>, QueryRejection>,
    body: Result<Bytes, BytesRejection>,
) -> Reply {
    let p = query(q)?;
    let app = name("app", p.app.as_deref(), false)?;
    let part = name("part", p.part.as_deref(), false)?;
    let body = body_bytes(body)?;
    if let Err(e) = serde_json::from_slice::<Value>(&body) {
        return Err(ApiError::bad_request(format!(
            "an edit is a JSON object ({{\"token\": \"TOKEN\", …}}): {e}"
        )));
    }
    let k = format!("ferroc/{app}/inspect/{part}/edit");
    blocking(move || s.peer.one(&k, Some(body.to_vec())).map(Json)).await
}

fn body_bytes(body: Result<Bytes, BytesRejection>) -> Result<Bytes, ApiError> {
    body.map_err(|e| {
        ApiError::new(
            e.status(),
            format!(
                "the request body cannot be read (at most {MAX_BODY} bytes): {}",
                e.body_text()
            ),
        )
    })
}

/// Any other `/api/…` (or other) path.
pub async fn not_found(uri: axum::http::Uri) -> ApiError {
    ApiError::not_found(format!(
        "`{}` is not a page or an API of the inspector (docs/inspect.md lists them)",
        uri.path()
    ))
}

/// A known path asked with a method it does not take.
pub async fn not_allowed(method: axum::http::Method, uri: axum::http::Uri) -> ApiError {
    ApiError::new(
        axum::http::StatusCode::METHOD_NOT_ALLOWED,
        format!("`{}` does not take {method}", uri.path()),
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_and_paths_without_wildcards_are_accepted() {
        assert_eq!(name("app", None, true).unwrap(), "*");
        assert!(name("part", None, false).is_err());
        assert_eq!(name("part", Some("robot"), false).unwrap(), "robot");
        for bad in ["*", "a/b", "ro*", "", "$x", "a?b", "a b", "\u{fffd}", "é"] {
            assert!(name("part", Some(bad), false).is_err(), "{bad}");
        }
        assert_eq!(path("robot/a/out").unwrap(), "robot/a/out");
        for bad in [
            "robot",
            "robot//out",
            "robot/**",
            "/robot/out",
            "robot/out/",
            "",
            "robot/a b",
        ] {
            let e = path(bad).unwrap_err();
            assert_eq!(e.status, axum::http::StatusCode::BAD_REQUEST, "{bad}");
        }
    }

    proptest::proptest! {
        /// Any text is a name or path, or a 400 error; what is accepted can be put into
        /// a Zenoh key without wildcards.
        #[test]
        fn no_name_or_path_panics(text in "\\PC{0,40}", slashed in "[a-z*$?#/ ]{0,30}") {
            for t in [&text, &slashed] {
                if let Ok(n) = name("part", Some(t), false) {
                    proptest::prop_assert!(!n.contains(['/', '*', '$', '?', '#', ' ']));
                }
                match path(t) {
                    Ok(p) => proptest::prop_assert!(p.split('/').all(chunk) && p.contains('/')),
                    Err(e) => proptest::prop_assert_eq!(e.status, axum::http::StatusCode::BAD_REQUEST),
                }
            }
        }
    }
}
