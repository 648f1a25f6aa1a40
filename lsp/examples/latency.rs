//! Diagnostics latency after a keystroke, and memory across 1,000 edits, in a large
//! model (bench/README.md, "ferroc lsp"): the server runs in this process on an
//! in-memory connection (the protocol's messages as `ferroc lsp` gets them, without
//! the stdio framing), the model is opened, then each keystroke is one incremental
//! change of one character and the time until the model's diagnostics are published
//! is measured.
//!
//!     cargo run -p ferroc-bench -- gen 10000 target/bench-models/lsp/b1.xml
//!     cargo run --release -p ferroc-lsp --example latency -- target/bench-models/lsp/b1.xml

use ferroc_compiler::load::{BuiltinLibrary, Options, ParseCache};
use lsp_server::{Connection, Message, Notification, Request, RequestId};
use serde_json::{json, Value};
use std::collections::HashMap;
use std::path::Path;
use std::sync::Arc;
use std::time::{Duration, Instant};

/// The allocator of the `ferroc` binary, so the figures are those of `ferroc lsp`.
#[global_allocator]
static GLOBAL: mimalloc::MiMalloc = mimalloc::MiMalloc;

const STD: &str = include_str!("../../components/ferroc_std.lib.xml");

fn main() {
    let Some(file) = std::env::args().nth(1) else {
        eprintln!("usage: latency MODEL.xml [KEYSTROKES]  (a B1 model: ferroc-bench gen N FILE)");
        std::process::exit(2);
    };
    let keystrokes: usize = std::env::args()
        .nth(2)
        .and_then(|n| n.parse().ok())
        .unwrap_or(40);
    let path = Path::new(&file).canonicalize().expect("the model exists");
    let text = std::fs::read_to_string(&path).expect("the model reads");
    let uri = url::Url::from_file_path(&path).unwrap().to_string();
    let (wall, cpu) = check_alone(&path, None);
    println!(
        "check_model alone, whole model parsed (best of 5): {:.0} ms, {:.0} ms CPU",
        ms(wall),
        ms(cpu)
    );
    let cache = Arc::new(ParseCache::default());
    let (wall, cpu) = check_alone(&path, Some(&cache));
    println!(
        "check_model alone after a keystroke, with the server's parse cache (best of 5): {:.0} ms, {:.0} ms CPU",
        ms(wall),
        ms(cpu)
    );
    let (server, client) = Connection::memory();
    let options = options();
    let thread = std::thread::spawn(move || ferroc_lsp::serve(&server, options));
    let send = |m: Message| client.sender.send(m).unwrap();
    send(Message::Request(Request::new(
        RequestId::from(1),
        "initialize".into(),
        json!({ "capabilities": {} }),
    )));
    wait(&client, |m| matches!(m, Message::Response(_)));
    send(note("initialized", json!({})));
    let start = Instant::now();
    send(note(
        "textDocument/didOpen",
        json!({ "textDocument": { "uri": uri, "languageId": "xml", "version": 1, "text": text } }),
    ));
    let first = published(&client, &uri);
    println!(
        "model: {} ({} KiB), first check: {:.0} ms, {} findings",
        path.display(),
        text.len() >> 10,
        ms(start.elapsed()),
        first
    );

    // A keystroke: one character typed into (then removed from) the name of the
    // application, an edit that changes no finding.
    let (line, col) = name_position(&text);
    let mut version = 1;
    let mut took = Vec::new();
    let rss_before = rss_kib();
    CHECKS.with(|c| c.borrow_mut().clear());
    for i in 0..keystrokes {
        version += 1;
        let change = keystroke(i, line, col);
        let t = Instant::now();
        send(note(
            "textDocument/didChange",
            json!({ "textDocument": { "uri": uri, "version": version }, "contentChanges": [change] }),
        ));
        published(&client, &uri);
        took.push(t.elapsed());
    }
    took.sort();
    let checks = CHECKS.with(|c| c.borrow().clone());
    let median = |mut v: Vec<f64>| {
        v.sort_by(f64::total_cmp);
        v.get(v.len() / 2).copied().unwrap_or(f64::NAN)
    };
    if !checks.is_empty() {
        println!(
            "the server's checks of those keystrokes: median {:.0} ms, {:.0} ms CPU",
            median(checks.iter().map(|c| c.0).collect()),
            median(checks.iter().map(|c| c.1).collect())
        );
    }
    let p = |q: f64| ms(took[((took.len() - 1) as f64 * q).round() as usize]);
    println!(
        "keystroke → diagnostics, {} keystrokes one at a time: median {:.0} ms, p90 {:.0} ms, max {:.0} ms",
        took.len(), p(0.5), p(0.9), p(1.0)
    );
    // 1,000 more edits, in bursts of 10 typed without waiting (the debounce merges
    // them), then the resident memory of the process.
    let t = Instant::now();
    for burst in 0..100 {
        for i in 0..10 {
            version += 1;
            let change = keystroke(burst * 10 + i + keystrokes, line, col);
            send(note(
                "textDocument/didChange",
                json!({ "textDocument": { "uri": uri, "version": version }, "contentChanges": [change] }),
            ));
        }
        published(&client, &uri);
    }
    println!(
        "1,000 edits in bursts of 10: {:.1} s; RSS before {} MiB, after {} MiB, peak {} MiB",
        t.elapsed().as_secs_f64(),
        rss_before >> 10,
        rss_kib() >> 10,
        peak_kib() >> 10
    );
    send(Message::Request(Request::new(
        RequestId::from(2),
        "shutdown".into(),
        Value::Null,
    )));
    wait(&client, |m| matches!(m, Message::Response(_)));
    send(note("exit", Value::Null));
    thread.join().unwrap().unwrap();
}

fn options() -> Options {
    Options {
        builtins: vec![BuiltinLibrary {
            name: "ferroc_std".into(),
            text: STD.into(),
        }],
        ..Options::default()
    }
}

/// The checker alone, in this process and at this moment (the machine's load): what
/// a keystroke cannot take less than. Best of 5, wall time and CPU time. With a cache,
/// each check follows a keystroke (the text given as the overlay, as the server does).
fn check_alone(path: &Path, cache: Option<&Arc<ParseCache>>) -> (Duration, Duration) {
    let text = std::fs::read_to_string(path).expect("the model reads");
    let (line, col) = name_position(&text);
    let at = text
        .split('\n')
        .take(line as usize)
        .map(|l| l.len() + 1)
        .sum::<usize>()
        + col as usize;
    let mut options = options();
    options.cache = cache.cloned();
    let mut best = (Duration::MAX, Duration::MAX);
    for i in 0..6 {
        let mut edited = text.clone();
        if i % 2 == 1 {
            edited.insert(at, 'x');
        }
        options.overlay = Arc::new(HashMap::from([(path.to_path_buf(), Arc::from(edited))]));
        let t = Instant::now();
        let c = thread_cpu();
        let r = ferroc_compiler::check_model(path, &options, &ferroc_compiler::Policy::default());
        let (wall, cpu) = (t.elapsed(), thread_cpu().saturating_sub(c));
        drop(r);
        // The first check with a cache fills it: not a keystroke's.
        if i > 0 {
            best = (best.0.min(wall), best.1.min(cpu));
        }
    }
    best
}

/// The CPU time this thread has run (Linux: `/proc/thread-self/schedstat`).
fn thread_cpu() -> Duration {
    let text = std::fs::read_to_string("/proc/thread-self/schedstat").unwrap_or_default();
    let ns = text.split_whitespace().next().and_then(|n| n.parse().ok());
    Duration::from_nanos(ns.unwrap_or(0))
}

fn note(method: &str, params: Value) -> Message {
    Message::Notification(Notification::new(method.into(), params))
}

/// Types a character at even steps, deletes it at odd ones.
fn keystroke(i: usize, line: u32, col: u32) -> Value {
    let at = json!({ "line": line, "character": col });
    if i % 2 == 0 {
        json!({ "range": { "start": at, "end": at }, "text": "x" })
    } else {
        json!({ "range": { "start": at, "end": { "line": line, "character": col + 1 } }, "text": "" })
    }
}

/// Where the application's name starts (0-based line and column).
fn name_position(text: &str) -> (u32, u32) {
    let at = text.find("<application").expect("a model");
    let name = at + text[at..].find("name=\"").unwrap() + 6;
    let line = text[..name].matches('\n').count();
    let col = name - text[..name].rfind('\n').map_or(0, |i| i + 1);
    (line as u32, col as u32)
}

thread_local! {
    /// The check times the server logged (`checked … in N ms (M ms CPU)`): wall, CPU.
    static CHECKS: std::cell::RefCell<Vec<(f64, f64)>> = const { std::cell::RefCell::new(Vec::new()) };
}

fn wait(client: &Connection, pick: impl Fn(&Message) -> bool) -> Message {
    loop {
        let m = client
            .receiver
            .recv_timeout(Duration::from_secs(300))
            .expect("the server answers");
        if let Message::Notification(n) = &m {
            let text = n.params["message"].as_str().unwrap_or("");
            if let Some(times) = text
                .strip_prefix("checked ")
                .and_then(|t| t.rsplit(" in ").next())
            {
                let mut numbers = times
                    .split(|c: char| !c.is_ascii_digit())
                    .filter_map(|n| n.parse::<f64>().ok());
                if let (Some(wall), Some(cpu)) = (numbers.next(), numbers.next()) {
                    CHECKS.with(|c| c.borrow_mut().push((wall, cpu)));
                }
            }
        }
        if pick(&m) {
            return m;
        }
    }
}

/// Waits for the model's diagnostics; their count.
fn published(client: &Connection, uri: &str) -> usize {
    let m = wait(
        client,
        |m| matches!(m, Message::Notification(n) if n.method == "textDocument/publishDiagnostics" && n.params["uri"] == uri),
    );
    match m {
        Message::Notification(n) => n.params["diagnostics"].as_array().map_or(0, Vec::len),
        _ => 0,
    }
}

fn ms(d: Duration) -> f64 {
    d.as_secs_f64() * 1000.0
}

fn status_kib(key: &str) -> u64 {
    let status = std::fs::read_to_string("/proc/self/status").unwrap_or_default();
    let line = status.lines().find(|l| l.starts_with(key)).unwrap_or("");
    line.split_whitespace()
        .nth(1)
        .and_then(|v| v.parse().ok())
        .unwrap_or(0)
}

fn rss_kib() -> u64 {
    status_kib("VmRSS:")
}

fn peak_kib() -> u64 {
    status_kib("VmHWM:")
}
