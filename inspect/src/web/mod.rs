//! `ferroc inspect --serve`: a web page showing a running application (docs/inspect.md,
//! "The web page"), served by axum on the tokio runtime zenoh already brings.
//!
//! The server is a Zenoh peer ([`peer`]: the same [`Client`](crate::client::Client)
//! and connect options as `ferroc inspect`) plus an HTTP server: the page's assets,
//! embedded in the binary ([`assets`]), and a JSON API ([`api`]) that turns each HTTP
//! request into inspection queries. Zenoh's calls block, so the API runs them on
//! tokio's blocking threads. Requests from other sites are refused ([`guard`]): a page
//! elsewhere in the user's browser must not read or change the robot through it.

mod api;
mod assets;
mod error;
mod guard;
mod peer;

#[cfg(feature = "foxglove")]
pub(crate) use guard::is_loopback_host;

use crate::limits::Limits;
use std::net::{SocketAddr, TcpListener};
use std::sync::Arc;
use std::time::Duration;

/// The port the page is served on by default (`http://127.0.0.1:8790/`).
pub const DEFAULT_PORT: u16 = 8790;

/// What to serve, and where.
#[derive(Clone, Debug)]
pub struct Options {
    /// `HOST:PORT` the HTTP server listens on.
    pub listen: String,
    /// A non-loopback `listen` was allowed explicitly (`--serve-public`).
    pub public: bool,
    /// The programs' inspection addresses (`--connect`).
    pub connect: Vec<String>,
    /// The application asked for (`*`: any).
    pub app: String,
    /// What one client may cost.
    pub limits: Limits,
}

/// Why the server could not start; every one is a usage or environment error.
#[derive(Debug)]
pub struct StartError(pub String);

/// A running web server. [`wait`](WebServer::wait) serves until Ctrl-C; dropping it
/// stops the server and closes the Zenoh session.
pub struct WebServer {
    runtime: Option<tokio::runtime::Runtime>,
    task: Option<tokio::task::JoinHandle<std::io::Result<()>>>,
    stop: tokio::sync::watch::Sender<bool>,
    address: SocketAddr,
    /// Kept here so the Zenoh session is closed after the runtime, outside it.
    state: Option<Arc<api::State>>,
}

/// Checks the options, binds the port and starts serving on threads of its own.
pub fn start(options: &Options) -> Result<WebServer, StartError> {
    let address = bind_address(options)?;
    let listener = TcpListener::bind(address).map_err(|e| {
        StartError(match e.kind() {
            std::io::ErrorKind::AddrInUse => format!(
                "--serve {}: the port is in use (another `ferroc inspect --serve`?); choose another with --serve 127.0.0.1:PORT",
                options.listen
            ),
            _ => format!("--serve {}: cannot listen there: {e}", options.listen),
        })
    })?;
    let address = listener
        .local_addr()
        .map_err(|e| StartError(e.to_string()))?;
    listener
        .set_nonblocking(true)
        .map_err(|e| StartError(e.to_string()))?;
    // Zenoh's blocking calls need the multi-threaded scheduler; two workers are plenty
    // for a page or two, and the blocking pool is bounded so a flood cannot fork
    // hundreds of threads.
    let runtime = tokio::runtime::Builder::new_multi_thread()
        .worker_threads(2)
        .max_blocking_threads(16)
        .thread_name("inspect-web")
        .enable_io()
        .enable_time()
        .build()
        .map_err(|e| StartError(format!("cannot start the web server's threads: {e}")))?;
    let state = Arc::new(api::State::new(
        peer::Peer::new(options.connect.clone(), options.limits.lookup),
        options.app.clone(),
        options.limits.lookup,
    ));
    let router = api::routes(state.clone())
        .merge(assets::routes())
        .fallback(api::not_found)
        .method_not_allowed_fallback(api::not_allowed)
        .layer(axum::middleware::from_fn_with_state(
            guard::Allowed::new(options.public),
            guard::check,
        ))
        .layer(axum::middleware::from_fn_with_state(
            options.limits.request,
            deadline,
        ));
    let listener = {
        let _inside = runtime.enter();
        tokio::net::TcpListener::from_std(listener).map_err(|e| StartError(e.to_string()))?
    };
    let (stop, stopped) = tokio::sync::watch::channel(false);
    let task = runtime.spawn(serve(listener, router, options.limits.clone(), stopped));
    Ok(WebServer {
        runtime: Some(runtime),
        task: Some(task),
        stop,
        address,
        state: Some(state),
    })
}

/// Serves `router` on `listener` until `stopped`: each connection on a task of its
/// own, closed when its request head is late (idle keep-alive connections too); at
/// most `limits.connections` at once, more closed at once.
async fn serve(
    listener: tokio::net::TcpListener,
    router: axum::Router,
    limits: Limits,
    mut stopped: tokio::sync::watch::Receiver<bool>,
) -> std::io::Result<()> {
    use hyper_util::rt::{TokioIo, TokioTimer};
    let slots = Arc::new(tokio::sync::Semaphore::new(limits.connections));
    loop {
        let accepted = tokio::select! {
            a = listener.accept() => a,
            _ = stopped.wait_for(|s| *s) => return Ok(()),
        };
        let Ok((stream, _)) = accepted else {
            // Out of descriptors, say: wait a moment rather than spin.
            tokio::time::sleep(Duration::from_millis(50)).await;
            continue;
        };
        let Ok(slot) = slots.clone().try_acquire_owned() else {
            drop(stream);
            continue;
        };
        let service = hyper_util::service::TowerToHyperService::new(router.clone());
        let header = limits.header;
        tokio::spawn(async move {
            let _slot = slot;
            let mut http = hyper::server::conn::http1::Builder::new();
            http.timer(TokioTimer::new()).header_read_timeout(header);
            let _ = http.serve_connection(TokioIo::new(stream), service).await;
        });
    }
}

/// A request (its body and its answer included) must be done within `limit`: one that
/// announces a body it never sends is answered 408 and its connection closed.
async fn deadline(
    axum::extract::State(limit): axum::extract::State<Duration>,
    request: axum::extract::Request,
    next: axum::middleware::Next,
) -> axum::response::Response {
    use axum::response::IntoResponse;
    match tokio::time::timeout(limit, next.run(request)).await {
        Ok(response) => response,
        Err(_) => {
            let mut response = error::ApiError::new(
                axum::http::StatusCode::REQUEST_TIMEOUT,
                format!("the request took longer than {} ms", limit.as_millis()),
            )
            .into_response();
            response.headers_mut().insert(
                axum::http::header::CONNECTION,
                axum::http::HeaderValue::from_static("close"),
            );
            response
        }
    }
}

fn bind_address(options: &Options) -> Result<SocketAddr, StartError> {
    let listen = &options.listen;
    let address = std::net::ToSocketAddrs::to_socket_addrs(listen.as_str())
        .ok()
        .and_then(|mut a| a.next())
        .ok_or_else(|| {
            StartError(format!(
                "--serve {listen}: not an address HOST:PORT (e.g. 127.0.0.1:{DEFAULT_PORT})"
            ))
        })?;
    if !address.ip().is_loopback() && !options.public {
        return Err(StartError(format!(
            "--serve {listen}: not a loopback address; anyone who reaches it can read every value of the application. \
             Add --serve-public to serve the page there anyway, or use 127.0.0.1:{DEFAULT_PORT}"
        )));
    }
    Ok(address)
}

impl WebServer {
    /// The address the page is served on.
    pub fn address(&self) -> SocketAddr {
        self.address
    }

    /// Serves until Ctrl-C or SIGTERM (or until the server fails).
    pub fn wait(mut self) -> Result<(), String> {
        let stop = self.stop.clone();
        ctrlc::set_handler(move || {
            let _ = stop.send(true);
        })
        .map_err(|e| format!("Ctrl-C cannot be caught, so it would not stop cleanly: {e}"))?;
        let (Some(runtime), Some(task)) = (self.runtime.as_ref(), self.task.take()) else {
            return Ok(());
        };
        match runtime.block_on(task) {
            Ok(Ok(())) => Ok(()),
            Ok(Err(e)) => Err(format!("the web server failed: {e}")),
            Err(e) => Err(format!("the web server stopped: {e}")),
        }
    }
}

impl Drop for WebServer {
    fn drop(&mut self) {
        let _ = self.stop.send(true);
        if let Some(runtime) = self.runtime.take() {
            if let Some(task) = self.task.take() {
                // Open keep-alive connections end at once; a request under way gets a
                // moment to finish.
                let _ = runtime
                    .block_on(async { tokio::time::timeout(Duration::from_secs(2), task).await });
            }
            runtime.shutdown_timeout(Duration::from_secs(2));
        }
        // Last, outside the runtime: closing the Zenoh session blocks.
        drop(self.state.take());
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn options(listen: &str, public: bool) -> Options {
        Options {
            listen: listen.into(),
            public,
            connect: vec!["127.0.0.1:1".into()],
            app: "*".into(),
            limits: Limits::default(),
        }
    }

    #[test]
    fn a_non_loopback_address_needs_the_public_flag() {
        let e = bind_address(&options("0.0.0.0:8790", false)).unwrap_err();
        assert!(e.0.contains("--serve-public"), "{}", e.0);
        assert!(bind_address(&options("0.0.0.0:8790", true)).is_ok());
        assert!(bind_address(&options("127.0.0.1:8790", false)).is_ok());
        let e = bind_address(&options("nonsense", false)).unwrap_err();
        assert!(e.0.contains("not an address"), "{}", e.0);
    }

    #[test]
    fn a_port_in_use_is_a_clear_error() {
        let taken = TcpListener::bind("127.0.0.1:0").unwrap();
        let listen = taken.local_addr().unwrap().to_string();
        let e = start(&options(&listen, false)).err().unwrap();
        assert!(e.0.contains("the port is in use"), "{}", e.0);
    }
}
