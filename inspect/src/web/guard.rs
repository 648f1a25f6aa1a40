//! Who may use the web server: requests that name this computer (`Host`) and come from
//! the page itself (`Origin`). A page of another site in the same browser can send
//! requests to `127.0.0.1` (or, by DNS rebinding, make its own name point there); it
//! must not read values or try tokens through us.

use super::error::ApiError;
use axum::extract::{Request, State};
use axum::http::header::{HOST, ORIGIN};
use axum::http::HeaderMap;
use axum::middleware::Next;
use axum::response::{IntoResponse, Response};

/// What the guard admits.
#[derive(Clone, Debug)]
pub struct Allowed {
    /// Served on a non-loopback address on purpose (`--serve-public`): any host name.
    public: bool,
}

impl Allowed {
    pub fn new(public: bool) -> Allowed {
        Allowed { public }
    }

    fn admit(&self, headers: &HeaderMap) -> Result<(), ApiError> {
        let host = header(headers, HOST.as_str())?.unwrap_or_default();
        if !self.public && !is_loopback_host(host) {
            return Err(ApiError::forbidden(format!(
                "the page is served for this computer only, not for `{host}`: open it as http://127.0.0.1:PORT/"
            )));
        }
        if let Some(origin) = header(headers, ORIGIN.as_str())? {
            if origin != format!("http://{host}") {
                return Err(ApiError::forbidden(format!(
                    "a request from the page of another site (`{origin}`) is refused"
                )));
            }
        }
        Ok(())
    }
}

fn header<'h>(headers: &'h HeaderMap, name: &str) -> Result<Option<&'h str>, ApiError> {
    match headers.get(name) {
        None => Ok(None),
        Some(v) => v
            .to_str()
            .map(Some)
            .map_err(|_| ApiError::bad_request(format!("the {name} header is not text"))),
    }
}

/// `127.0.0.1:8790`, `localhost`, `[::1]:8790` and the like.
pub(crate) fn is_loopback_host(host: &str) -> bool {
    let name = match host.strip_prefix('[') {
        Some(rest) => rest.split(']').next().unwrap_or(""),
        None => host.split(':').next().unwrap_or(""),
    };
    name.eq_ignore_ascii_case("localhost")
        || name
            .parse::<std::net::IpAddr>()
            .is_ok_and(|ip| ip.is_loopback())
}

/// The middleware: answers 403 (JSON) to a request the guard does not admit.
pub async fn check(State(allowed): State<Allowed>, request: Request, next: Next) -> Response {
    match allowed.admit(request.headers()) {
        Ok(()) => next.run(request).await,
        Err(e) => e.into_response(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use axum::http::HeaderValue;

    fn headers(host: &str, origin: Option<&str>) -> HeaderMap {
        let mut h = HeaderMap::new();
        h.insert(HOST, HeaderValue::from_str(host).unwrap());
        if let Some(o) = origin {
            h.insert(ORIGIN, HeaderValue::from_str(o).unwrap());
        }
        h
    }

    #[test]
    fn the_page_itself_is_admitted_and_other_sites_are_not() {
        let local = Allowed { public: false };
        for host in [
            "127.0.0.1:8790",
            "localhost:8790",
            "[::1]:8790",
            "127.0.0.1",
        ] {
            assert!(local.admit(&headers(host, None)).is_ok(), "{host}");
        }
        let own = headers("127.0.0.1:8790", Some("http://127.0.0.1:8790"));
        assert!(local.admit(&own).is_ok());
        // DNS rebinding: a foreign name that resolves to this computer.
        let e = local
            .admit(&headers("evil.example:8790", None))
            .unwrap_err();
        assert!(e.message.contains("this computer only"), "{}", e.message);
        for origin in ["http://evil.example", "null", "http://127.0.0.1:9999"] {
            let e = local
                .admit(&headers("127.0.0.1:8790", Some(origin)))
                .unwrap_err();
            assert!(
                e.message.contains("another site"),
                "{origin}: {}",
                e.message
            );
        }
        // Served publicly on purpose: any host name, but still only its own page.
        let public = Allowed { public: true };
        assert!(public.admit(&headers("robot-pc:8790", None)).is_ok());
        let foreign = headers("robot-pc:8790", Some("http://evil.example"));
        assert!(public.admit(&foreign).is_err());
    }
}
