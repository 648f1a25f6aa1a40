//! `ferroc inspect --serve` under hostile clients (issue 27, item 3): idle and slow
//! clients are dropped, connections over the limit are closed, and ordinary requests
//! are answered throughout. The limits are set small with FERROC_INSPECT_LIMITS;
//! nothing is asserted about how fast anything is. (The page and its API:
//! tests/inspect_web.rs.)

mod common;

use common::inspected::start;
use common::web::{api, http, serve_limited};
use std::io::{Read, Write};
use std::net::TcpStream;
use std::time::{Duration, Instant};

/// Whether the server closes `s` (reading returns its end) within `limit`; what it
/// sent first (an answer) is skipped.
fn closed_within(s: &mut TcpStream, limit: Duration) -> bool {
    s.set_read_timeout(Some(limit)).unwrap();
    let mut chunk = [0u8; 4096];
    loop {
        match s.read(&mut chunk) {
            Ok(0) => return true,
            Ok(_) => continue,
            Err(e) if e.kind() == std::io::ErrorKind::ConnectionReset => return true,
            Err(_) => return false,
        }
    }
}

/// Issue 27, item 3: idle and slow clients were never dropped (600 slow clients held
/// 60 s, `Content-Length: 2^62` held open, 20,000 idle connections took every
/// descriptor). Now a request head must arrive in time (an idle connection is closed),
/// a whole request must be done in time (408), and connections over the limit are
/// closed at once; ordinary requests are answered throughout. The limits are set small
/// here (FERROC_INSPECT_LIMITS); nothing is asserted about how fast anything is.
/// Failed before the fix (the idle connection stayed open).
#[test]
fn idle_and_slow_clients_are_dropped_and_others_are_served() {
    let program = start("tests/fixtures/inspect.xml");
    let web = serve_limited(
        &program.address,
        "header_ms=300,request_ms=3000,lookup_ms=2000",
    );
    // Idle from the start: closed when no request head came.
    let mut idle = TcpStream::connect(&web.address).unwrap();
    assert!(
        closed_within(&mut idle, Duration::from_secs(60)),
        "the idle connection stays open"
    );
    // Half a request head: the same.
    let mut slow = TcpStream::connect(&web.address).unwrap();
    slow.write_all(b"GET /api/tree HTTP/1.1\r\nHost: 127.0.0.1\r\n")
        .unwrap();
    assert!(
        closed_within(&mut slow, Duration::from_secs(60)),
        "the slow head stays open"
    );
    // A body announced and never sent: answered 408 and closed.
    let mut body = TcpStream::connect(&web.address).unwrap();
    let head = format!(
        "POST /api/edit?app=inspected&part=robot HTTP/1.1\r\nHost: {}\r\nContent-Length: {}\r\n\r\n{{",
        web.address,
        1u64 << 62
    );
    body.write_all(head.as_bytes()).unwrap();
    body.set_read_timeout(Some(Duration::from_secs(60)))
        .unwrap();
    let mut answer = String::new();
    let _ = body.read_to_string(&mut answer);
    assert!(
        answer.starts_with("HTTP/1.1 408") || answer.starts_with("HTTP/1.1 413"),
        "{answer}"
    );
    // A keep-alive connection that asked once and then idles: closed too.
    let mut kept = TcpStream::connect(&web.address).unwrap();
    let ask = format!("GET /api/tree HTTP/1.1\r\nHost: {}\r\n\r\n", web.address);
    kept.write_all(ask.as_bytes()).unwrap();
    assert!(
        closed_within(&mut kept, Duration::from_secs(60)),
        "the kept-alive connection stays open"
    );
    // And an ordinary request is answered.
    let (status, tree) = api(&web, "GET /api/tree HTTP/1.1", "");
    assert_eq!(status, 200, "{tree}");
    // Requests for an application that does not exist each get an answer; the page's
    // requests still do.
    let floods: Vec<_> = (0..40)
        .map(|_| {
            let address = web.address.clone();
            std::thread::spawn(move || http(&address, "GET /api/tree?app=nothing HTTP/1.1", b"").0)
        })
        .collect();
    for f in floods {
        let status = f.join().unwrap();
        // No program answers (502), or it waited its time for room (503) or for the
        // whole request (408): each gives up in time.
        assert!([408, 502, 503].contains(&status), "{status}");
    }
    // Once the flood is answered, the page's requests are (asked again while one
    // still meets the rest of it: 408 or 503 are answers in time, not hangs).
    let deadline = Instant::now() + Duration::from_secs(60);
    loop {
        let (status, tree) = api(&web, "GET /api/tree HTTP/1.1", "");
        if status == 200 {
            break;
        }
        assert!([408, 503].contains(&status), "{status}: {tree}");
        assert!(Instant::now() < deadline, "never answered again: {tree}");
    }
}

/// Issue 27, item 3: connections over the limit are closed at once, while those within
/// it are served (here with a long header time, so only the limit can close it).
#[test]
fn connections_over_the_limit_are_closed() {
    let program = start("tests/fixtures/inspect.xml");
    let web = serve_limited(&program.address, "header_ms=120000,connections=2");
    let _first = TcpStream::connect(&web.address).unwrap();
    let _second = TcpStream::connect(&web.address).unwrap();
    let mut third = TcpStream::connect(&web.address).unwrap();
    assert!(
        closed_within(&mut third, Duration::from_secs(60)),
        "the third stays open"
    );
    drop((_first, _second));
    // Room again once they are gone (the server sees them closed when it reads).
    let deadline = Instant::now() + Duration::from_secs(60);
    loop {
        let mut s = TcpStream::connect(&web.address).unwrap();
        let ask = format!(
            "GET /api/tree HTTP/1.1\r\nHost: {}\r\nConnection: close\r\n\r\n",
            web.address
        );
        let _ = s.write_all(ask.as_bytes());
        s.set_read_timeout(Some(Duration::from_secs(60))).unwrap();
        let mut answer = String::new();
        let _ = s.read_to_string(&mut answer);
        if answer.starts_with("HTTP/1.1 200") {
            break;
        }
        assert!(Instant::now() < deadline, "never served again: {answer}");
        std::thread::sleep(Duration::from_millis(50));
    }
}
