//! `ferroc inspect --foxglove`: the inspection keys offered over the Foxglove
//! WebSocket protocol, so the Foxglove app (or any client of the protocol) shows a
//! running application's ports, container figures and iB2C activities, and changes
//! its parameters (docs/inspect.md, "Foxglove").
//!
//! The bridge is a Zenoh peer like `ferroc inspect` ([`Client`]) and serves the
//! protocol with the Foxglove SDK's WebSocket server. It finds the application's parts
//! and their element trees once at start and makes one channel per port and three per
//! part ([`channels`]). Values are polled from the inspection keys every `--every`,
//! and only for channels some client subscribed to: a channel nobody watches costs no
//! query. Parameters go through [`params`].
//!
//! Clients never reach the SDK's server directly: they connect to the [`gate`], which
//! refuses foreign origins and wrong tokens at the upgrade, bounds what a client
//! costs, and vouches for connections that gave the token, the only ones whose
//! changes the parameter handler takes.

pub mod channels;
pub mod gate;
pub mod params;
pub mod schema;

use crate::client::Client;
use crate::config;
use crate::limits::Limits;
use crate::request::{key, What};
use ferroc_runtime::inspect::view::Tree;
use foxglove::{Context, WebSocketServer};
use std::sync::{Arc, OnceLock};
use std::time::{Duration, Instant};

/// The address the bridge serves on by default (the Foxglove app's default).
pub const DEFAULT_ADDRESS: &str = "127.0.0.1:8765";

/// The origin of the Foxglove app in a browser, which may always connect (it still
/// needs the token to change anything).
pub const APP_ORIGIN: &str = "https://app.foxglove.dev";

/// What the bridge serves, and how.
pub struct Options {
    /// `HOST:PORT` of the WebSocket server.
    pub address: String,
    /// A non-local address was allowed explicitly (`--foxglove-public`).
    pub public: bool,
    /// The application (`*`: the one that answers).
    pub app: String,
    /// The token for parameter changes, if given.
    pub token: Option<String>,
    /// Origins of web pages that may connect besides [`APP_ORIGIN`]
    /// (`--foxglove-origin`).
    pub origins: Vec<String>,
    /// What one client may cost.
    pub limits: Limits,
    /// How often subscribed channels are polled.
    pub every: Duration,
    /// Stop after this long (none: run until killed).
    pub duration: Option<Duration>,
}

/// `(host, port)` of `address`, checked: a non-local host needs `public`.
pub fn bind_address(address: &str, public: bool) -> Result<(String, u16), String> {
    let bad = || format!("--foxglove {address}: not an address HOST:PORT (e.g. {DEFAULT_ADDRESS})");
    let (host, port) = address.rsplit_once(':').ok_or_else(bad)?;
    let port: u16 = port.parse().map_err(|_| bad())?;
    let host = host.trim_start_matches('[').trim_end_matches(']');
    if host.is_empty() {
        return Err(bad());
    }
    if !config::is_local(address) && !public {
        return Err(format!(
            "--foxglove {address}: not a loopback address; anyone who reaches it can read every value of the application. \
             Add --foxglove-public to serve it there anyway, or use {DEFAULT_ADDRESS}"
        ));
    }
    Ok((host.to_owned(), port))
}

/// Runs the bridge until `duration` ends (or forever); an error if the address cannot
/// be served or no single application answers.
pub fn run(client: Client, options: &Options) -> Result<(), String> {
    let (host, port) = bind_address(&options.address, options.public)?;
    let client = Arc::new(client);
    let (app, parts) = discover(&client, &options.app)?;
    let context = Context::new();
    let feeds = channels::build(&client, &app, &parts, &context)?;
    let server_slot = Arc::new(OnceLock::new());
    let secret = crate::token::generate()?;
    let handler = params::Handler::start(
        params::Worker {
            client: client.clone(),
            app: app.clone(),
            token: options.token.clone().unwrap_or_default(),
            server: server_slot.clone(),
            parts: parts.iter().map(|(p, _)| p.clone()).collect(),
        },
        &secret,
    )?;
    let cannot =
        |e: &dyn std::fmt::Display| format!("--foxglove {}: cannot serve: {e}", options.address);
    // The public address is bound first, so a port in use is reported as such.
    let door = std::net::TcpListener::bind((host.as_str(), port)).map_err(|e| cannot(&e))?;
    let hidden = gate::hidden_host();
    let server = WebSocketServer::new()
        .name(format!("ferroc {app}"))
        .bind(hidden.to_string(), 0)
        .context(&context)
        .parameter_handler(Arc::new(handler))
        .start_blocking()
        .map_err(|e| cannot(&e))?;
    let backend = std::net::SocketAddr::new(hidden.into(), server.port());
    let _ = server_slot.set(server);
    let mut origins = vec![APP_ORIGIN.to_owned()];
    origins.extend(options.origins.iter().cloned());
    let rules = Arc::new(gate::Rules {
        token: options.token.clone(),
        public: options.public,
        origins,
        backend,
        secret,
        limits: options.limits.clone(),
    });
    let _gate = start_gate(door, rules).map_err(|e| cannot(&e))?;
    if !config::is_local(&options.address) {
        eprintln!(
            "warning: Foxglove is served on {}, not only on this computer: anyone who reaches it can read every value",
            options.address
        );
    }
    if options.token.is_none() {
        eprintln!("foxglove: no --token: parameter changes will be refused");
    } else {
        eprintln!(
            "foxglove: parameter changes only from connections with the token in the URL: ws://{}/?token=TOKEN",
            options.address
        );
    }
    eprintln!(
        "foxglove: serving {} channels of {app} on ws://{} (subprotocol foxglove.sdk.v1)",
        feeds.len(),
        options.address
    );
    poll(&client, &feeds, options);
    Ok(())
}

/// Serves the gate on `door`, on a runtime of its own (kept while the bridge runs).
fn start_gate(
    door: std::net::TcpListener,
    rules: Arc<gate::Rules>,
) -> std::io::Result<tokio::runtime::Runtime> {
    let runtime = tokio::runtime::Builder::new_multi_thread()
        .worker_threads(1)
        .thread_name("foxglove-gate")
        .enable_io()
        .enable_time()
        .build()?;
    door.set_nonblocking(true)?;
    let listener = {
        let _inside = runtime.enter();
        tokio::net::TcpListener::from_std(door)?
    };
    runtime.spawn(gate::serve(listener, rules));
    Ok(runtime)
}

/// The application (the one named, or the only one answering) and its parts' trees.
fn discover(client: &Client, app: &str) -> Result<(String, Vec<(String, Tree)>), String> {
    let answers = client.ask(&key(app, "*", &What::Tree), None)?;
    let mut apps: Vec<String> = answers.iter().map(|a| a.app_part().0.to_owned()).collect();
    apps.dedup();
    match apps.as_slice() {
        [] => Err(
            "no program answered: is it running with --inspect, and are --connect and --app right?"
                .into(),
        ),
        [one] => {
            let mut parts = Vec::new();
            for a in &answers {
                parts.push((a.app_part().1.to_owned(), a.parse::<Tree>()?));
            }
            Ok((one.clone(), parts))
        }
        many => Err(format!(
            "more than one application answered ({}); name one with --app",
            many.join(", ")
        )),
    }
}

/// Every `every`, reads the keys of the channels someone subscribed to and logs the
/// answers.
fn poll(client: &Client, feeds: &[channels::Feed], options: &Options) {
    let start = Instant::now();
    // Said once per silence, not every round.
    let mut silent = false;
    loop {
        if options.duration.is_some_and(|d| start.elapsed() >= d) {
            return;
        }
        let tick = Instant::now();
        let watched: Vec<&channels::Feed> =
            feeds.iter().filter(|f| f.channel.has_sinks()).collect();
        if !watched.is_empty() {
            let keys: Vec<String> = watched.iter().map(|f| f.key.clone()).collect();
            let answers = client.ask_all(&keys, Duration::from_secs(2).max(options.every));
            let mut answered = false;
            for (feed, answers) in watched.iter().zip(answers) {
                answered |= !answers.is_empty();
                if let Some(json) = channels::first_ok(&answers) {
                    feed.channel.log(&feed.message(json));
                }
            }
            if !answered && !silent {
                eprintln!(
                    "foxglove: the program does not answer; restart the bridge when it runs again"
                );
            }
            silent = !answered;
        }
        let next = tick + options.every;
        if let Some(left) = next.checked_duration_since(Instant::now()) {
            std::thread::sleep(left);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn only_loopback_is_served_without_the_public_flag() {
        assert_eq!(
            bind_address("127.0.0.1:8765", false),
            Ok(("127.0.0.1".into(), 8765))
        );
        assert_eq!(bind_address("[::1]:9", false), Ok(("::1".into(), 9)));
        let e = bind_address("0.0.0.0:8765", false).unwrap_err();
        assert!(e.contains("--foxglove-public"), "{e}");
        assert_eq!(
            bind_address("0.0.0.0:8765", true),
            Ok(("0.0.0.0".into(), 8765))
        );
        for bad in ["8765", "host:", ":80", "h:99999"] {
            let e = bind_address(bad, true).unwrap_err();
            assert!(e.contains("not an address"), "{bad}: {e}");
        }
    }
}
