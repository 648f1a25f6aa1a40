//! `ferroc inspect --serve` for the tests of the web page (tests/inspect_web.rs,
//! tests/inspect_web_limits.rs): the server as a child process and plain HTTP requests
//! written by hand.

use super::inspected::{free_port, lines, wait_for_line};
use serde_json::Value;
use std::io::{Read, Write};
use std::net::TcpStream;
use std::process::{Child, Command, Stdio};
use std::time::{Duration, Instant};

/// A `ferroc inspect --serve` child, killed when dropped.
pub struct Web {
    pub child: Child,
    /// `127.0.0.1:PORT` of the page.
    pub address: String,
}

impl Drop for Web {
    fn drop(&mut self) {
        let _ = self.child.kill();
        let _ = self.child.wait();
    }
}

/// Starts `ferroc inspect --serve` asking `connect`, and waits until it serves.
pub fn serve(connect: &str) -> Web {
    serve_limited(connect, "")
}

/// [`serve`] with the limits `FERROC_INSPECT_LIMITS` sets (`""`: the defaults).
pub fn serve_limited(connect: &str, limits: &str) -> Web {
    let address = format!("127.0.0.1:{}", free_port());
    let mut child = Command::new(env!("CARGO_BIN_EXE_ferroc"))
        .args(["inspect", "--serve", &address, "--connect", connect])
        .env("FERROC_INSPECT_LIMITS", limits)
        .current_dir(env!("CARGO_MANIFEST_DIR"))
        .stdout(Stdio::null())
        .stderr(Stdio::piped())
        .spawn()
        .expect("ferroc runs");
    let stderr = lines(child.stderr.take().unwrap());
    let line = wait_for_line(&stderr, "the page is on", Duration::from_secs(60));
    assert!(line.contains(&format!("http://{address}/")), "{line}");
    Web { child, address }
}

/// One HTTP/1.1 request (`Connection: close`; `Host` added unless `head` has one); the
/// status and the body. A server may answer before it read the whole body (a body too
/// large) and close: what it answered is read even if the connection is then reset.
pub fn http(address: &str, head: &str, body: &[u8]) -> (u16, String) {
    let mut s = TcpStream::connect(address).unwrap();
    s.set_read_timeout(Some(Duration::from_secs(60))).unwrap();
    let host = match head.contains("\r\nHost:") {
        true => String::new(),
        false => format!("\r\nHost: {address}"),
    };
    let request = format!(
        "{head}{host}\r\nConnection: close\r\nContent-Length: {}\r\n\r\n",
        body.len()
    );
    s.write_all(request.as_bytes()).unwrap();
    let _ = s.write_all(body);
    let mut answer = Vec::new();
    let mut chunk = [0u8; 8192];
    while let Ok(n @ 1..) = s.read(&mut chunk) {
        answer.extend_from_slice(&chunk[..n]);
    }
    let text = String::from_utf8_lossy(&answer).into_owned();
    let status = text
        .split(' ')
        .nth(1)
        .and_then(|c| c.parse().ok())
        .unwrap_or_else(|| panic!("not an HTTP answer: {text}"));
    let body = text.split_once("\r\n\r\n").map_or("", |(_, b)| b);
    (status, body.to_owned())
}

/// A request whose answer must be JSON.
pub fn api(web: &Web, head: &str, body: &str) -> (u16, Value) {
    let (status, text) = http(&web.address, head, body.as_bytes());
    let json = serde_json::from_str(&text)
        .unwrap_or_else(|e| panic!("{head}: {status} answered not JSON ({e}): {text}"));
    (status, json)
}

/// `error` of a JSON error answer with `status`.
pub fn error(web: &Web, head: &str, body: &str, status: u16) -> String {
    let (got, json) = api(web, head, body);
    assert_eq!(got, status, "{head}: {json}");
    json["error"]
        .as_str()
        .unwrap_or_else(|| panic!("{head}: no error text: {json}"))
        .to_owned()
}

/// Asks `/api/values` for one port until it is `want` (bounded).
pub fn eventually(web: &Web, path: &str, want: Value) {
    let deadline = Instant::now() + Duration::from_secs(60);
    loop {
        let (status, json) = api(
            web,
            &format!("GET /api/values?app=inspected&paths={path} HTTP/1.1"),
            "",
        );
        assert_eq!(status, 200, "{json}");
        let got = json["values"][path]["value"].clone();
        if got == want {
            return;
        }
        assert!(
            Instant::now() < deadline,
            "{path} stayed {got}, wanted {want}"
        );
        std::thread::sleep(Duration::from_millis(50));
    }
}
