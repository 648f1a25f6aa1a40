//! A `ferroc run MODEL --inspect` child for tests that look into it (inspect,
//! inspect_edit, the browser test and the web API test): started on a free loopback port, its change token read from
//! its standard error, killed when dropped.

pub use ferroc_testkit::free_port;
use std::io::{BufRead, BufReader};
use std::process::{Child, Command, Stdio};
use std::sync::mpsc;
use std::time::{Duration, Instant};

/// A running program serving inspection.
pub struct Running {
    pub child: Child,
    /// Its inspection address, `127.0.0.1:PORT`.
    pub address: String,
    /// The token it printed for changes.
    pub token: String,
    /// Lines of its standard error after the token line.
    pub stderr: mpsc::Receiver<String>,
}

impl Drop for Running {
    fn drop(&mut self) {
        let _ = self.child.kill();
        let _ = self.child.wait();
    }
}

/// Lines of `stream`, read on a thread of their own.
pub fn lines(stream: impl std::io::Read + Send + 'static) -> mpsc::Receiver<String> {
    let (tx, rx) = mpsc::channel();
    std::thread::spawn(move || {
        for line in BufReader::new(stream).lines().map_while(Result::ok) {
            if tx.send(line).is_err() {
                break;
            }
        }
    });
    rx
}

/// Waits (up to `limit`) for a line containing `marker`; returns the line and the
/// lines before it, or panics with them.
pub fn wait_for_line(rx: &mpsc::Receiver<String>, marker: &str, limit: Duration) -> String {
    let deadline = Instant::now() + limit;
    let mut seen = Vec::new();
    loop {
        match rx.recv_timeout(deadline.saturating_duration_since(Instant::now())) {
            Ok(line) if line.contains(marker) => return line,
            Ok(line) => seen.push(line),
            Err(_) => panic!("no line with `{marker}`; saw:\n{}", seen.join("\n")),
        }
    }
}

/// Starts `ferroc run MODEL --inspect 127.0.0.1:PORT` and waits (bounded) for its token.
pub fn start(model: &str) -> Running {
    start_at(model, &format!("127.0.0.1:{}", free_port()))
}

/// Starts `ferroc run MODEL --inspect ADDRESS` and waits (bounded) for its token.
pub fn start_at(model: &str, address: &str) -> Running {
    let address = address.to_owned();
    let mut child = Command::new(env!("CARGO_BIN_EXE_ferroc"))
        .args(["run", model, "--for", "600s", "-q", "--inspect", &address])
        .env("FERROC_LOG_DIR", super::test_log_dir())
        .current_dir(env!("CARGO_MANIFEST_DIR"))
        .stdout(Stdio::null())
        .stderr(Stdio::piped())
        .spawn()
        .expect("ferroc runs");
    let stderr = lines(child.stderr.take().unwrap());
    // The first run of a model with other libraries builds its runner: minutes.
    let line = wait_for_line(&stderr, "token for changes: ", Duration::from_secs(900));
    assert!(
        line.contains("serving ferroc/"),
        "the key it serves: {line}"
    );
    let token = line
        .split_once("token for changes: ")
        .unwrap()
        .1
        .trim()
        .to_owned();
    Running {
        child,
        address,
        token,
        stderr,
    }
}
