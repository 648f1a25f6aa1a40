//! The bridge's front door: every WebSocket client connects here, never to the
//! Foxglove SDK's server directly.
//!
//! The protocol has no login, and the SDK's server takes any upgrade and tells its
//! parameter handler nothing about the connection but a number. So the gate, in front
//! of it, decides at the upgrade:
//!
//! - an upgrade naming another computer (`Host`, unless `--foxglove-public`) or coming
//!   from a web page of a site not allowed (`Origin`) is refused (403), as the web
//!   page's API refuses them: a page the operator visits must not reach the robot;
//! - the token for changes travels in the connection's URL
//!   (`ws://127.0.0.1:8765/?token=TOKEN`); a wrong one is refused (403), none admits a
//!   connection that only reads;
//! - a connection with the right token is vouched for: the gate's first message to
//!   the SDK's server is a `getParameters` whose id carries a secret of this run,
//!   which the parameter handler ([`super::params`]) takes as "this client may
//!   change", and which no client ever sees. A `setParameters` from any other
//!   connection is refused by the handler.
//!
//! The SDK's server listens on a random address of the loopback network
//! (`127.X.Y.Z`, a random port), which a web page cannot guess; and it could not
//! change anything there (it does not know the secret). The gate also bounds what a
//! client costs: the upgrade must arrive within [`Limits::header`], at most
//! [`Limits::connections`] clients at once (more are closed at once), a message from
//! a client is at most [`MAX_MESSAGE`] bytes.

use crate::limits::Limits;
use futures_util::{SinkExt, StreamExt};
use std::net::SocketAddr;
use std::sync::Arc;
use tokio::net::{TcpListener, TcpStream};
use tokio::sync::Semaphore;
use tokio_tungstenite::tungstenite::handshake::server::{ErrorResponse, Request, Response};
use tokio_tungstenite::tungstenite::http::{HeaderValue, StatusCode};
use tokio_tungstenite::tungstenite::protocol::WebSocketConfig;
use tokio_tungstenite::tungstenite::Message;
use tokio_tungstenite::WebSocketStream;

/// The largest message a client may send (its requests are a few hundred bytes).
pub const MAX_MESSAGE: usize = 1 << 20;

/// The id prefix of the gate's vouching `getParameters`; the rest is the secret.
pub const VOUCH: &str = "ferroc-gate:";

/// Who the gate admits, and where it forwards them.
pub struct Rules {
    /// The token changes need (none: no connection may change anything).
    pub token: Option<String>,
    /// Served on a non-loopback address on purpose: any `Host`.
    pub public: bool,
    /// Origins (`https://app.foxglove.dev`) whose pages may connect; a client without
    /// an `Origin` (not a browser) always may.
    pub origins: Vec<String>,
    /// The SDK's server.
    pub backend: SocketAddr,
    /// This run's secret, vouching for a connection that gave the token.
    pub secret: String,
    /// Timeouts and the connection limit.
    pub limits: Limits,
}

/// Accepts clients on `listener` until the runtime stops.
pub async fn serve(listener: TcpListener, rules: Arc<Rules>) {
    let slots = Arc::new(Semaphore::new(rules.limits.connections));
    loop {
        let Ok((stream, _)) = listener.accept().await else {
            // Out of descriptors, say: wait a moment rather than spin.
            tokio::time::sleep(std::time::Duration::from_millis(50)).await;
            continue;
        };
        // Over the limit: closed at once, so idle clients cannot take every descriptor.
        let Ok(slot) = slots.clone().try_acquire_owned() else {
            drop(stream);
            continue;
        };
        let rules = rules.clone();
        tokio::spawn(async move {
            let _slot = slot;
            let _ = stream.set_nodelay(true);
            let _ = connection(stream, &rules).await;
        });
    }
}

/// What the upgrade request said, once admitted.
#[derive(Debug)]
struct Admitted {
    /// The subprotocol chosen, as the SDK's server chooses (the newest it speaks that
    /// the client offered), asked of the SDK's server in turn.
    protocol: HeaderValue,
    /// It gave the right token.
    may_change: bool,
}

/// The subprotocols the SDK's server speaks, the one it prefers first.
const PROTOCOLS: [&str; 2] = ["foxglove.sdk.v1.1", "foxglove.sdk.v1"];

async fn connection(stream: TcpStream, rules: &Rules) -> Result<(), String> {
    let mut admitted = Admitted {
        protocol: HeaderValue::from_static(PROTOCOLS[1]),
        may_change: false,
    };
    let config = WebSocketConfig::default()
        .max_message_size(Some(MAX_MESSAGE))
        .max_frame_size(Some(MAX_MESSAGE));
    #[allow(clippy::result_large_err)]
    let callback = |request: &Request, mut response: Response| match admit(rules, request) {
        Ok(a) => {
            response
                .headers_mut()
                .insert("sec-websocket-protocol", a.protocol.clone());
            admitted = a;
            Ok(response)
        }
        Err(refusal) => Err(refusal),
    };
    let upgrade = tokio_tungstenite::accept_hdr_async_with_config(stream, callback, Some(config));
    let client = tokio::time::timeout(rules.limits.header, upgrade)
        .await
        .map_err(|_| "the upgrade did not arrive in time".to_owned())?
        .map_err(|e| e.to_string())?;
    let backend = backend(rules, &admitted).await?;
    relay(client, backend, rules).await;
    Ok(())
}

/// The upgrade's verdict: admitted (with or without the right to change), or the
/// answer refusing it (tungstenite's type for it, large as it is).
#[allow(clippy::result_large_err)]
fn admit(rules: &Rules, request: &Request) -> Result<Admitted, ErrorResponse> {
    let header = |name: &str| {
        request
            .headers()
            .get(name)
            .map(|v| v.to_str().unwrap_or("\u{fffd}"))
    };
    let host = header("host").unwrap_or_default();
    if !rules.public && !crate::web::is_loopback_host(host) {
        return Err(refuse(format!(
            "the bridge serves this computer only, not `{host}`: connect to ws://127.0.0.1:PORT"
        )));
    }
    if let Some(origin) = header("origin") {
        if !rules.origins.iter().any(|o| o.eq_ignore_ascii_case(origin)) {
            return Err(refuse(format!(
                "a connection from the page of another site (`{origin}`) is refused; allow it with --foxglove-origin {origin}"
            )));
        }
    }
    let offered: Vec<&str> = (request.headers().get_all("sec-websocket-protocol").iter())
        .flat_map(|h| h.to_str().unwrap_or_default().split(','))
        .map(str::trim)
        .collect();
    let Some(protocol) = PROTOCOLS.into_iter().find(|p| offered.contains(p)) else {
        let mut response = refuse(format!(
            "offer the subprotocol {} (sec-websocket-protocol)",
            PROTOCOLS[1]
        ));
        *response.status_mut() = StatusCode::BAD_REQUEST;
        return Err(response);
    };
    let token = token_of(request.uri().query().unwrap_or(""));
    let may_change = match (token, &rules.token) {
        (None, _) => false,
        (Some(given), Some(expected)) if crate::token::matches(expected, &given) => true,
        (Some(_), _) => {
            ferroc_runtime::console::note_repeated(
                "foxglove: refused a connection with a wrong token",
            );
            return Err(refuse(
                "not authorised: the token in the URL is not the one given to --foxglove --token"
                    .into(),
            ));
        }
    };
    Ok(Admitted {
        protocol: HeaderValue::from_static(protocol),
        may_change,
    })
}

/// The value of `token=` in a query string (percent escapes decoded).
fn token_of(query: &str) -> Option<String> {
    form_urlencoded::parse(query.as_bytes())
        .find(|(k, _)| k == "token")
        .map(|(_, v)| v.into_owned())
}

fn refuse(why: String) -> ErrorResponse {
    let mut response = ErrorResponse::new(Some(why));
    *response.status_mut() = StatusCode::FORBIDDEN;
    response
}

/// A connection to the SDK's server, offering the client's subprotocols; vouched for
/// when the client may change.
async fn backend(rules: &Rules, admitted: &Admitted) -> Result<WebSocketStream<TcpStream>, String> {
    use tokio_tungstenite::tungstenite::client::IntoClientRequest;
    let mut request = format!("ws://{}/", rules.backend)
        .into_client_request()
        .map_err(|e| e.to_string())?;
    request
        .headers_mut()
        .insert("sec-websocket-protocol", admitted.protocol.clone());
    let connect = async {
        let tcp = TcpStream::connect(rules.backend).await?;
        let _ = tcp.set_nodelay(true);
        tokio_tungstenite::client_async(request, tcp).await
    };
    let (mut ws, _) = tokio::time::timeout(rules.limits.header, connect)
        .await
        .map_err(|_| "the bridge's server did not answer in time".to_owned())?
        .map_err(|e| e.to_string())?;
    if admitted.may_change {
        let vouch = serde_json::json!({
            "op": "getParameters",
            "parameterNames": [],
            "id": format!("{VOUCH}{}", rules.secret),
        });
        ws.send(Message::text(vouch.to_string()))
            .await
            .map_err(|e| e.to_string())?;
    }
    Ok(ws)
}

/// Passes messages both ways until either side ends; the answer to the vouching
/// request is kept from the client.
async fn relay(
    client: WebSocketStream<TcpStream>,
    backend: WebSocketStream<TcpStream>,
    rules: &Rules,
) {
    let (mut to_client, mut from_client) = client.split();
    let (mut to_backend, mut from_backend) = backend.split();
    let up = async {
        while let Some(Ok(m)) = from_client.next().await {
            match m {
                // Answered by each side's own WebSocket layer.
                Message::Ping(_) | Message::Pong(_) | Message::Frame(_) => continue,
                Message::Close(_) => break,
                m => {
                    if to_backend.send(m).await.is_err() {
                        break;
                    }
                }
            }
        }
        let _ = to_backend.close().await;
    };
    let vouch_id = format!("{VOUCH}{}", rules.secret);
    let down = async {
        while let Some(Ok(m)) = from_backend.next().await {
            match &m {
                Message::Ping(_) | Message::Pong(_) | Message::Frame(_) => continue,
                Message::Close(_) => break,
                Message::Text(t) if t.as_str().contains(&vouch_id) => continue,
                _ => {
                    if to_client.send(m).await.is_err() {
                        break;
                    }
                }
            }
        }
        let _ = to_client.close().await;
    };
    futures_util::pin_mut!(up, down);
    futures_util::future::select(up, down).await;
}

/// A random address of the loopback network for the SDK's server (`127.X.Y.Z`, so a
/// web page scanning `127.0.0.1`'s ports does not find it), or `127.0.0.1` where the
/// system serves only that one.
pub fn hidden_host() -> std::net::Ipv4Addr {
    let mut bytes = [0u8; 3];
    if getrandom::fill(&mut bytes).is_ok() {
        let ip = std::net::Ipv4Addr::new(127, bytes[0], bytes[1], bytes[2].max(2));
        if std::net::TcpListener::bind((ip, 0)).is_ok() {
            return ip;
        }
    }
    std::net::Ipv4Addr::LOCALHOST
}

#[cfg(test)]
mod tests {
    use super::*;

    fn rules(token: Option<&str>) -> Rules {
        Rules {
            token: token.map(Into::into),
            public: false,
            origins: vec!["https://app.foxglove.dev".into()],
            backend: "127.0.0.1:1".parse().unwrap(),
            secret: "s".into(),
            limits: Limits::default(),
        }
    }

    fn request(uri: &str, host: &str, origin: Option<&str>) -> Request {
        let mut r = (Request::builder().uri(uri).header("host", host)).header(
            "sec-websocket-protocol",
            "foxglove.websocket.v1, foxglove.sdk.v1",
        );
        if let Some(o) = origin {
            r = r.header("origin", o);
        }
        r.body(()).unwrap()
    }

    #[test]
    fn only_the_token_in_the_url_admits_changes() {
        let r = rules(Some("t0k"));
        let plain = admit(&r, &request("/", "127.0.0.1:8765", None)).unwrap();
        assert!(!plain.may_change);
        let with = admit(&r, &request("/?token=t0k", "localhost:8765", None)).unwrap();
        assert!(with.may_change);
        let wrong = admit(&r, &request("/?token=t0", "127.0.0.1:8765", None)).unwrap_err();
        assert_eq!(wrong.status(), StatusCode::FORBIDDEN);
        // No token given to the bridge: any token is wrong, none reads.
        let none = rules(None);
        assert!(admit(&none, &request("/?token=", "127.0.0.1:1", None)).is_err());
        assert!(
            !admit(&none, &request("/", "127.0.0.1:1", None))
                .unwrap()
                .may_change
        );
    }

    #[test]
    fn foreign_origins_and_host_names_are_refused() {
        let r = rules(Some("t"));
        for origin in ["http://evil.example", "null", "http://127.0.0.1:9"] {
            let e = admit(&r, &request("/?token=t", "127.0.0.1:8765", Some(origin))).unwrap_err();
            assert_eq!(e.status(), StatusCode::FORBIDDEN, "{origin}");
            assert!(
                e.body().as_deref().unwrap().contains("another site"),
                "{origin}"
            );
        }
        let app = request("/", "127.0.0.1:8765", Some("https://app.foxglove.dev"));
        assert!(admit(&r, &app).is_ok());
        let rebound = admit(&r, &request("/", "evil.example:8765", None)).unwrap_err();
        assert!(rebound
            .body()
            .as_deref()
            .unwrap()
            .contains("this computer only"));
    }
}
