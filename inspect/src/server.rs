//! Serving a running application's inspector on Zenoh: one queryable on
//! `ferroc/APP/inspect/**`, answered by one thread of its own (queries wait for each
//! other, never for the application, and never run on Zenoh's own threads).
//!
//! Every answer is JSON. A malformed request, an unknown module or port, a change
//! without the right token or with a value that does not check is answered with an
//! error ([`ErrorReply`]); nothing a client sends can stop the server.

use crate::request::{self, ErrorReply, SetRequest, What};
use crate::structure::{Refusal, Structure};
use ferroc_runtime::inspect::view::ParamView;
use ferroc_runtime::inspect::Inspector;
use ferroc_runtime::module::Value;
use ferroc_terminal::engine_error;
use serde::Serialize;
use std::sync::Arc;
use zenoh::bytes::Encoding;
use zenoh::handlers::FifoChannelHandler;
use zenoh::query::{Query, Queryable};
use zenoh::{Session, Wait};

/// Turns a value as text (`0.3 m/s`) into a value in the parameter's unit, or says
/// why it cannot be one (the runner supplies it: it knows the model's units).
pub type ParseValue = Box<dyn Fn(&ParamView, &str) -> Result<Value, String> + Send + Sync>;

/// Payloads larger than this are refused unread (a change request is a few bytes).
pub const MAX_PAYLOAD: usize = 64 * 1024;

/// A running inspection server; dropping it undeclares the queryable, closes the
/// session and ends the thread.
pub struct Server {
    session: Option<Session>,
    thread: Option<std::thread::JoinHandle<()>>,
}

struct Context {
    app: String,
    inspector: Arc<Inspector>,
    token: String,
    parse: ParseValue,
    /// Structural edits and the model (`structure.rs`); `None`: not offered.
    structure: Option<Arc<dyn Structure>>,
}

/// Opens a session with `config` and serves `inspector` as the application `app`;
/// changes need `token`.
pub fn serve(
    config: zenoh::Config,
    app: &str,
    inspector: Arc<Inspector>,
    token: String,
    parse: ParseValue,
) -> Result<Server, String> {
    serve_structure(config, app, inspector, token, parse, None)
}

/// [`serve`], also answering structural edits and the model (`edit`, `model`) with
/// `structure`.
pub fn serve_structure(
    config: zenoh::Config,
    app: &str,
    inspector: Arc<Inspector>,
    token: String,
    parse: ParseValue,
    structure: Option<Arc<dyn Structure>>,
) -> Result<Server, String> {
    let key = format!("ferroc/{app}/inspect/**");
    let key = zenoh::key_expr::OwnedKeyExpr::try_from(key.clone())
        .map_err(|e| format!("`{key}` cannot be a key: {}", engine_error(&e)))?;
    let session = zenoh::open(config).wait().map_err(|e| {
        let why = engine_error(&e);
        if why.contains("in use") {
            format!(
                "{why}\n  help: another program serves there (another run with --inspect?); \
                 choose another address with --inspect 127.0.0.1:PORT"
            )
        } else {
            format!("cannot open the inspection session: {why}")
        }
    })?;
    let queryable = session
        .declare_queryable(key.clone())
        .wait()
        .map_err(|e| format!("cannot serve `{key}`: {}", engine_error(&e)))?;
    let context = Context {
        app: app.to_owned(),
        inspector,
        token,
        parse,
        structure,
    };
    let thread = std::thread::Builder::new()
        .name("inspect".into())
        .spawn(move || run(queryable, &context))
        .map_err(|e| format!("the inspection thread could not start: {e}"))?;
    Ok(Server {
        session: Some(session),
        thread: Some(thread),
    })
}

impl Drop for Server {
    fn drop(&mut self) {
        if let Some(session) = self.session.take() {
            // Closing undeclares the queryable: its channel ends, and so does the thread.
            let _ = session.close().wait();
        }
        if let Some(thread) = self.thread.take() {
            let _ = thread.join();
        }
    }
}

fn run(queryable: Queryable<FifoChannelHandler<Query>>, context: &Context) {
    while let Ok(query) = queryable.recv() {
        answer(&query, context);
    }
}

fn answer(query: &Query, c: &Context) {
    let Some(parsed) = request::parse(query.key_expr().as_str()) else {
        return;
    };
    if parsed.app != "*" && parsed.app != c.app {
        return;
    }
    let parts = c.inspector.parts();
    let any_part = parsed.part == "*";
    if !any_part && !parts.contains(&parsed.part) {
        return;
    }
    let what = match parsed.what {
        Ok(w) => w,
        Err(e) => return reply_err(query, e),
    };
    // The size first: a payload arrives in pieces, and is copied into one buffer only
    // when it is small enough to be a request.
    let size = query.payload().map_or(0, zenoh::bytes::ZBytes::len);
    if size > MAX_PAYLOAD {
        return reply_err(
            query,
            format!("the request has {size} bytes; a request is at most {MAX_PAYLOAD}"),
        );
    }
    let payload = query.payload().map(|p| p.to_bytes().into_owned());
    let asked: Vec<&String> = match any_part {
        // One model for the whole program: asked once, whatever the part.
        true if matches!(what, What::Edit | What::Model) => parts.iter().take(1).collect(),
        true => parts.iter().collect(),
        false => vec![&parsed.part],
    };
    for part in asked {
        let key = request::key(&c.app, part, &what);
        match handle(&what, part, payload.as_deref(), c) {
            Answer::Json(json) => {
                let sent = query
                    .reply(key, json)
                    .encoding(Encoding::APPLICATION_JSON)
                    .wait();
                if let Err(e) = sent {
                    ferroc_runtime::console::note(&format!(
                        "inspect: cannot answer: {}",
                        engine_error(&e)
                    ));
                }
            }
            // A module of another part: with `*`, that part answers.
            Answer::NotHere if any_part => {}
            Answer::NotHere => reply_err(
                query,
                format!("`{}` is not in the part `{part}`", path(&what)),
            ),
            Answer::Error(e) => reply_err(query, e),
            Answer::Refused(r) => reply_refusal(query, r),
        }
    }
}

enum Answer {
    Json(Vec<u8>),
    NotHere,
    Error(String),
    Refused(Refusal),
}

fn path(what: &What) -> &str {
    match what {
        What::Value(p) | What::Param(p) => p,
        _ => "",
    }
}

fn json<T: Serialize>(value: &T) -> Answer {
    match serde_json::to_vec(value) {
        Ok(bytes) => Answer::Json(bytes),
        Err(e) => Answer::Error(format!("the answer cannot be written as JSON: {e}")),
    }
}

fn handle(what: &What, part: &str, payload: Option<&[u8]>, c: &Context) -> Answer {
    let i = &c.inspector;
    let target = match what {
        What::Tree => return json(&i.tree(Some(part))),
        What::Containers => return json(&i.containers(Some(part))),
        What::Links => return json(&i.links(Some(part))),
        What::Activities => return json(&i.activities(Some(part))),
        What::Transport => return json(&i.transport(Some(part))),
        What::Edit | What::Model => return structural(what, payload, c),
        What::Value(p) | What::Param(p) => p,
    };
    let (module, name) = match i.split(target) {
        Ok(split) => split,
        // A path of another part: that part answers (or, if no program has it, the
        // client says nobody did).
        Err(_) if !part_has_prefix(target, part) => return Answer::NotHere,
        Err(e) => return Answer::Error(e),
    };
    if !part_has_prefix(module, part) {
        return Answer::NotHere;
    }
    let result = match (what, payload) {
        (What::Value(_), None) => i.value(module, name).map(|v| json(&v)),
        (What::Value(_), Some(_)) => Err("a value cannot be set; only parameters change".into()),
        (What::Param(_), None) => i.param(module, name).map(|p| json(&p)),
        (What::Param(_), Some(bytes)) => set(c, module, name, bytes).map(|p| json(&p)),
        _ => unreachable!("handled above"),
    };
    result.unwrap_or_else(Answer::Error)
}

/// Whether `path` lies in `part` (module paths start with their part).
fn part_has_prefix(path: &str, part: &str) -> bool {
    path.split('/').next() == Some(part)
}

fn set(c: &Context, module: &str, name: &str, bytes: &[u8]) -> Result<ParamView, String> {
    if bytes.len() > MAX_PAYLOAD {
        return Err(format!(
            "the request has {} bytes; a change is at most {MAX_PAYLOAD}",
            bytes.len()
        ));
    }
    let request: SetRequest = serde_json::from_slice(bytes).map_err(|e| {
        format!("a change is the JSON {{\"set\": \"VALUE\", \"token\": \"TOKEN\"}}: {e}")
    })?;
    if !crate::token::matches(&c.token, &request.token) {
        // One line per kind, throttled: a client trying tokens as fast as it can
        // must not flood the operator's terminal.
        ferroc_runtime::console::note_repeated("inspect: refused a change with a wrong token");
        return Err(
            "not authorised: a change needs the token the program printed at start (--token)"
                .into(),
        );
    }
    let before = c.inspector.param(module, name)?;
    let value = (c.parse)(&before, &request.set)
        .map_err(|why| format!("`{module}/{name}` keeps its value {}: {why}", before.value))?;
    let after = c.inspector.set_param(module, name, &value)?;
    if let Some(structure) = &c.structure {
        structure.param_changed(module, name, &request.set);
    }
    ferroc_runtime::console::note(&format!(
        "inspect: `{module}/{name}` set to {} (was {})",
        after.value, before.value
    ));
    Ok(after)
}

fn structural(what: &What, payload: Option<&[u8]>, c: &Context) -> Answer {
    let Some(structure) = &c.structure else {
        return Answer::Error(
            "this program does not take structural edits (only `ferroc run --inspect` does; a bundle's programs have no compiler inside)".into(),
        );
    };
    match (what, payload) {
        (What::Model, None) => json(&structure.model()),
        (What::Model, Some(_)) => {
            Answer::Error("the model is read, not written; edit it with `edit`".into())
        }
        (_, None) => {
            Answer::Error("an edit needs the payload {\"token\": \"TOKEN\", \"ops\": [...]}".into())
        }
        (_, Some(bytes)) if bytes.len() > MAX_PAYLOAD => Answer::Error(format!(
            "the request has {} bytes; an edit is at most {MAX_PAYLOAD}",
            bytes.len()
        )),
        (_, Some(bytes)) => {
            let request = match crate::structure::read(bytes) {
                Ok(r) => r,
                Err(r) => return Answer::Refused(r),
            };
            if !crate::token::matches(&c.token, &request.token) {
                ferroc_runtime::console::note_repeated(
                    "inspect: refused an edit with a wrong token",
                );
                return Answer::Error(
                    "not authorised: an edit needs the token the program printed at start (--token)".into(),
                );
            }
            let ops = serde_json::to_vec(&request.ops).unwrap_or_default();
            match structure.edit(&ops) {
                Ok(answer) => json(&answer),
                Err(r) => Answer::Refused(r),
            }
        }
    }
}

fn reply_refusal(query: &Query, refusal: Refusal) {
    let body = serde_json::json!({"error": refusal.error, "diagnostics": refusal.diagnostics});
    let _ = query
        .reply_err(serde_json::to_vec(&body).unwrap_or_default())
        .encoding(Encoding::APPLICATION_JSON)
        .wait();
}

fn reply_err(query: &Query, error: String) {
    let body = serde_json::to_vec(&ErrorReply { error }).unwrap_or_default();
    let _ = query
        .reply_err(body)
        .encoding(Encoding::APPLICATION_JSON)
        .wait();
}
