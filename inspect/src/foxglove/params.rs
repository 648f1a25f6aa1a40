//! The Foxglove parameters capability over the inspection keys: `getParameters` lists
//! the application's parameters (named `MODULE/PATH/NAME`, as `ferroc inspect --set`
//! names them), `setParameters` sends each change as the checked `param` request with
//! the bridge's token. A refused change leaves the parameter as it was: the client
//! gets its current value back and an error status saying why.
//!
//! A change is taken only from a connection the gate vouched for (it gave the token
//! in its URL, [`super::gate`]): the SDK tells the handler nothing else about a
//! connection. Any other connection's `setParameters` is refused, whatever it holds.
//!
//! The SDK calls the handler on its own tasks, which must not block; the Zenoh
//! queries run on one worker thread of ours, fed through a bounded queue.

use crate::client::{part_of, Client};
use crate::request::What;
use ferroc_runtime::inspect::view::{ParamView, Tree};
use foxglove::websocket::{
    AnyClient, ClientId, GetParametersResponder, Parameter, ParameterHandler, ParameterValue,
    SetParametersResponder,
};
use foxglove::WebSocketServerHandle;
use std::collections::HashSet;
use std::sync::mpsc::{sync_channel, Receiver, SyncSender, TrySendError};
use std::sync::{Arc, Mutex, OnceLock};

/// Requests waiting for the worker; more are refused as busy.
const QUEUE: usize = 64;

/// The parameter's value as Foxglove shows it: numbers for number types, a boolean
/// for `bool`, otherwise the text a model writes (`2s`, `right`).
pub fn to_foxglove(p: &ParamView) -> Parameter {
    let name = format!("{}/{}", p.module, p.name);
    let v = p.value.trim();
    let value = match p.r#type.as_str() {
        "f32" | "f64" => v.parse().ok().map(ParameterValue::Float64),
        "i8" | "i16" | "i32" | "i64" | "u8" | "u16" | "u32" | "u64" => {
            v.parse().ok().map(ParameterValue::Integer)
        }
        "bool" => v.parse().ok().map(ParameterValue::Bool),
        _ => None,
    };
    let value = value.unwrap_or_else(|| ParameterValue::String(p.value.clone()));
    Parameter {
        name,
        r#type: None,
        value: Some(value),
    }
}

/// The text of a value set from Foxglove, as `ferroc inspect --set` would send it (a
/// number is in the parameter's unit; text may name a unit: `30 cm/s`).
pub fn to_text(value: &ParameterValue) -> Result<String, String> {
    Ok(match value {
        ParameterValue::Integer(i) => i.to_string(),
        ParameterValue::Float64(x) => x.to_string(),
        ParameterValue::Bool(b) => b.to_string(),
        ParameterValue::String(s) => s.clone(),
        ParameterValue::Array(_) | ParameterValue::Dict(_) => {
            return Err("a parameter is one value, not an array or a dictionary".into())
        }
    })
}

enum Job {
    Get(Vec<String>, GetParametersResponder),
    /// The change, its client, whether the gate vouched for that client.
    Set(Vec<Parameter>, AnyClient, bool, SetParametersResponder),
}

/// The handler the server calls; see the [module docs](self).
pub struct Handler {
    jobs: SyncSender<Job>,
    /// The id of the gate's vouching request (`super::gate::VOUCH` and the secret).
    vouch_id: String,
    /// Connections the gate vouched for. Only connections with the token are added
    /// (one per connection the operator opens), so the set stays small.
    vouched: Mutex<HashSet<ClientId>>,
}

/// What the worker needs: the Zenoh client, the application, the token, and the
/// server (once started) to tell parameter subscribers about changes.
pub struct Worker {
    /// The inspection client.
    pub client: Arc<Client>,
    /// The application's name.
    pub app: String,
    /// The token for changes (empty: every change is refused by the program).
    pub token: String,
    /// The running server.
    pub server: Arc<OnceLock<WebSocketServerHandle>>,
    /// The parts whose parameters are listed.
    pub parts: Vec<String>,
}

impl Handler {
    /// A handler whose requests `worker` answers on a thread of its own; changes
    /// only from connections vouched for with `secret`.
    pub fn start(worker: Worker, secret: &str) -> Result<Handler, String> {
        let (jobs, queue) = sync_channel(QUEUE);
        std::thread::Builder::new()
            .name("foxglove-params".into())
            .spawn(move || work(&worker, &queue))
            .map_err(|e| format!("the parameter thread could not start: {e}"))?;
        Ok(Handler {
            jobs,
            vouch_id: format!("{}{secret}", super::gate::VOUCH),
            vouched: Mutex::new(HashSet::new()),
        })
    }

    fn queue(&self, job: Job) {
        if let Err(TrySendError::Full(job) | TrySendError::Disconnected(job)) =
            self.jobs.try_send(job)
        {
            let busy = "too many parameter requests at once; nothing was changed, ask again";
            match job {
                Job::Get(_, responder) => {
                    responder.client().send_error(busy);
                    responder.respond(Vec::new());
                }
                Job::Set(_, client, _, responder) => {
                    client.send_error(busy);
                    responder.respond(Vec::new());
                }
            }
        }
    }
}

impl ParameterHandler for Handler {
    fn get(
        &self,
        _client: AnyClient,
        names: Vec<String>,
        request_id: Option<String>,
        responder: GetParametersResponder,
    ) {
        if request_id.is_some_and(|id| crate::token::matches(&self.vouch_id, &id)) {
            let mut vouched = self.vouched.lock().unwrap_or_else(|p| p.into_inner());
            vouched.insert(responder.client().id());
            // The gate keeps this answer from the client.
            responder.respond(Vec::new());
            return;
        }
        self.queue(Job::Get(names, responder));
    }

    fn set(
        &self,
        client: AnyClient,
        parameters: Vec<Parameter>,
        _request_id: Option<String>,
        responder: SetParametersResponder,
    ) {
        let vouched =
            (self.vouched.lock().unwrap_or_else(|p| p.into_inner())).contains(&client.id());
        self.queue(Job::Set(parameters, client, vouched, responder));
    }
}

fn work(w: &Worker, queue: &Receiver<Job>) {
    while let Ok(job) = queue.recv() {
        match job {
            Job::Get(names, responder) => {
                let (found, errors) = get(w, &names);
                for e in errors {
                    responder.client().send_error(e);
                }
                responder.respond(found);
            }
            Job::Set(parameters, client, vouched, responder) => {
                let mut now = Vec::new();
                for p in &parameters {
                    let result = match vouched {
                        true => set(w, p),
                        false => Err((NOT_VOUCHED.to_owned(), current(w, &p.name))),
                    };
                    match result {
                        Ok(after) => now.push(after),
                        Err((why, current)) => {
                            client.send_error(why);
                            now.extend(current);
                        }
                    }
                }
                if let Some(server) = w.server.get() {
                    server.publish_parameter_values(now.clone());
                }
                responder.respond(now);
            }
        }
    }
}

/// The parameters named (all of them for none), and what could not be read.
fn get(w: &Worker, names: &[String]) -> (Vec<Parameter>, Vec<String>) {
    let mut errors = Vec::new();
    if names.is_empty() {
        let mut all = Vec::new();
        for part in &w.parts {
            match w.client.one::<Tree>(&w.app, part, &What::Tree) {
                Ok(tree) => {
                    all.extend(tree.modules.iter().flat_map(|m| &m.params).map(to_foxglove))
                }
                Err(e) => errors.push(e),
            }
        }
        return (all, errors);
    }
    let mut found = Vec::new();
    for name in names {
        match read(w, name) {
            Ok(p) => found.push(to_foxglove(&p)),
            Err(e) => errors.push(e),
        }
    }
    (found, errors)
}

fn read(w: &Worker, name: &str) -> Result<ParamView, String> {
    w.client
        .one(&w.app, part_of(name), &What::Param(name.to_owned()))
}

/// Why a connection without the token cannot change anything.
const NOT_VOUCHED: &str = "not authorised: this connection gave no token; changes need \
     the bridge's token in the connection's URL: ws://HOST:PORT/?token=TOKEN";

/// The parameter's current value, if it can be read.
fn current(w: &Worker, name: &str) -> Option<Parameter> {
    read(w, name).ok().map(|v| to_foxglove(&v))
}

/// Sets one parameter: its value afterwards, or why not and (if it can be read) its
/// unchanged value.
fn set(w: &Worker, p: &Parameter) -> Result<Parameter, (String, Option<Parameter>)> {
    let current = || current(w, &p.name);
    let Some(value) = &p.value else {
        return Err((
            format!("`{}`: a parameter cannot be unset", p.name),
            current(),
        ));
    };
    let text = to_text(value).map_err(|e| (format!("`{}`: {e}", p.name), current()))?;
    match w.client.set::<ParamView>(&w.app, &p.name, &text, &w.token) {
        Ok(after) => Ok(to_foxglove(&after)),
        Err(e) => Err((e, current())),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn param(ty: &str, value: &str) -> ParamView {
        ParamView {
            module: "robot/control/go".into(),
            name: "p".into(),
            r#type: ty.into(),
            unit: None,
            min: None,
            max: None,
            choices: Vec::new(),
            value: value.into(),
        }
    }

    #[test]
    fn values_take_the_form_of_their_type() {
        let p = to_foxglove(&param("f64", "0.5"));
        assert_eq!(p.name, "robot/control/go/p");
        assert_eq!(p.value, Some(ParameterValue::Float64(0.5)));
        let v = |ty, text| to_foxglove(&param(ty, text)).value.unwrap();
        assert_eq!(v("f64", "2"), ParameterValue::Float64(2.0));
        assert_eq!(v("u32", "72"), ParameterValue::Integer(72));
        assert_eq!(v("bool", "true"), ParameterValue::Bool(true));
        assert_eq!(v("string", "right"), ParameterValue::String("right".into()));
        assert_eq!(v("duration", "2s"), ParameterValue::String("2s".into()));
        // A value its type does not parse is shown as it is, not lost.
        assert_eq!(v("f64", "nan?"), ParameterValue::String("nan?".into()));
    }

    #[test]
    fn values_set_become_the_text_a_model_writes() {
        assert_eq!(to_text(&ParameterValue::Float64(0.05)).unwrap(), "0.05");
        assert_eq!(to_text(&ParameterValue::Float64(2.0)).unwrap(), "2");
        assert_eq!(to_text(&ParameterValue::Integer(-3)).unwrap(), "-3");
        assert_eq!(to_text(&ParameterValue::Bool(false)).unwrap(), "false");
        assert_eq!(
            to_text(&ParameterValue::String("30 cm/s".into())).unwrap(),
            "30 cm/s"
        );
        let e = to_text(&ParameterValue::Array(vec![ParameterValue::Integer(1)])).unwrap_err();
        assert!(e.contains("not an array"), "{e}");
    }
}
