//! The web server in-process, without a program to ask: its own pages and errors, the
//! program reported unreachable, requests of other sites refused, and a clean stop
//! that frees the port. (With real programs and a browser: tests/inspect_web.rs.)

use ferroc_inspect::web::{self, Options};
use std::io::{Read, Write};
use std::net::{TcpListener, TcpStream};
use std::time::Duration;

/// One HTTP/1.1 request with `extra` header lines; status and body.
fn http(address: &str, head: &str, extra: &str, body: &str) -> (u16, String) {
    let mut s = TcpStream::connect(address).unwrap();
    s.set_read_timeout(Some(Duration::from_secs(60))).unwrap();
    let request = format!(
        "{head}\r\nHost: {address}\r\n{extra}Connection: close\r\nContent-Length: {}\r\n\r\n{body}",
        body.len()
    );
    s.write_all(request.as_bytes()).unwrap();
    let mut answer = String::new();
    s.read_to_string(&mut answer).unwrap();
    let status = answer.split(' ').nth(1).unwrap().parse().unwrap();
    let body = answer.split_once("\r\n\r\n").unwrap().1.to_owned();
    (status, body)
}

fn error_of(body: &str) -> String {
    let json: serde_json::Value =
        serde_json::from_str(body).unwrap_or_else(|e| panic!("{e}: {body}"));
    json["error"].as_str().unwrap().to_owned()
}

#[test]
fn the_server_serves_its_page_reports_an_unreachable_program_and_stops_cleanly() {
    // Nobody listens where the program should be.
    let nobody = TcpListener::bind("127.0.0.1:0")
        .unwrap()
        .local_addr()
        .unwrap();
    let options = Options {
        listen: "127.0.0.1:0".into(),
        public: false,
        connect: vec![nobody.to_string()],
        app: "*".into(),
        limits: ferroc_inspect::limits::Limits::default(),
    };
    let server = web::start(&options).map_err(|e| e.0).unwrap();
    let address = server.address().to_string();

    let (status, page) = http(&address, "GET / HTTP/1.1", "", "");
    assert_eq!(status, 200);
    assert!(page.contains("<title>ferroc inspect</title>"), "{page}");
    for file in [
        "/app.js",
        "/graph.js",
        "/layout.js",
        "/labels.js",
        "/panels.js",
        "/style.css",
    ] {
        let (status, text) = http(&address, &format!("GET {file} HTTP/1.1"), "", "");
        assert!(status == 200 && !text.is_empty(), "{file}: {status}");
    }
    let (status, body) = http(&address, "GET /api/tree HTTP/1.1", "", "");
    assert_eq!(status, 502, "{body}");
    let e = error_of(&body);
    assert!(
        e.contains("cannot reach") && e.contains(&nobody.to_string()),
        "{e}"
    );
    // Within the retry interval the answer comes at once, from the last attempt.
    let (status, again) = http(&address, "GET /api/tree HTTP/1.1", "", "");
    assert_eq!((status, error_of(&again)), (502, e));

    for (head, extra, body, want, why) in [
        (
            "GET /nowhere HTTP/1.1",
            "",
            "",
            404,
            "is not a page or an API",
        ),
        ("PUT /api/tree HTTP/1.1", "", "", 405, "does not take PUT"),
        (
            "GET /api/values?paths=a HTTP/1.1",
            "",
            "",
            400,
            "not a path",
        ),
        (
            "POST /api/edit?app=x&part=y HTTP/1.1",
            "",
            "[",
            400,
            "an edit is a JSON",
        ),
        (
            "POST /api/param/a/b?app=x HTTP/1.1",
            "",
            "{}",
            400,
            "a change is the JSON",
        ),
        (
            "POST /api/param/a/b?app=x HTTP/1.1",
            "Origin: http://evil.example\r\n",
            r#"{"set": "1", "token": "t"}"#,
            403,
            "another site",
        ),
    ] {
        let (status, text) = http(&address, head, extra, body);
        assert_eq!(status, want, "{head}: {text}");
        assert!(error_of(&text).contains(why), "{head}: {text}");
    }

    drop(server);
    TcpListener::bind(&address).expect("the port is free once the server is dropped");
}
