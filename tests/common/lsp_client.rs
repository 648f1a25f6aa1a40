//! A minimal LSP client for the tests of `ferroc lsp`: frames over the child's pipes,
//! every message the server sends kept in order, requests waited for by id (bounded).

use serde_json::{json, Value};
use std::io::{BufRead, BufReader, Write};
use std::path::Path;
use std::process::{Child, ChildStdin, Command, Stdio};
use std::sync::mpsc::{channel, Receiver};
use std::time::{Duration, Instant};

pub struct Client {
    child: Child,
    stdin: ChildStdin,
    incoming: Receiver<Value>,
    /// Notifications seen while waiting for responses, in order.
    pub notes: Vec<Value>,
    next_id: i64,
}

/// How long any single answer may take (checks of large models on a loaded machine).
pub const WAIT: Duration = Duration::from_secs(120);

impl Client {
    /// Starts `ferroc lsp` in `cwd` and initializes it with `root` as the workspace.
    pub fn start(cwd: &Path, root: &Path) -> Client {
        let mut c = Client::spawn(cwd);
        c.initialize(root);
        c
    }

    pub fn initialize(&mut self, root: &Path) {
        let root_uri = uri(root);
        let init = self.request(
            "initialize",
            json!({ "processId": null, "rootUri": root_uri, "capabilities": {},
                    "workspaceFolders": [{ "uri": root_uri, "name": "root" }] }),
        );
        assert!(
            init["result"]["capabilities"]["textDocumentSync"].is_number(),
            "{init}"
        );
        self.notify("initialized", json!({}));
    }

    /// Starts `ferroc lsp` in `cwd` without initializing it.
    pub fn spawn(cwd: &Path) -> Client {
        let mut child = Command::new(env!("CARGO_BIN_EXE_ferroc"))
            .arg("lsp")
            .current_dir(cwd)
            .stdin(Stdio::piped())
            .stdout(Stdio::piped())
            .stderr(Stdio::inherit())
            .spawn()
            .expect("ferroc lsp starts");
        let stdin = child.stdin.take().unwrap();
        let stdout = child.stdout.take().unwrap();
        let (tx, incoming) = channel();
        std::thread::spawn(move || {
            let mut r = BufReader::new(stdout);
            while let Some(msg) = read_frame(&mut r) {
                if tx.send(msg).is_err() {
                    break;
                }
            }
        });
        Client {
            child,
            stdin,
            incoming,
            notes: Vec::new(),
            next_id: 1,
        }
    }

    pub fn send_raw(&mut self, body: &[u8]) {
        let _ = write!(self.stdin, "Content-Length: {}\r\n\r\n", body.len());
        let _ = self.stdin.write_all(body);
        let _ = self.stdin.flush();
    }

    pub fn notify(&mut self, method: &str, params: Value) {
        let msg = json!({ "jsonrpc": "2.0", "method": method, "params": params });
        self.send_raw(msg.to_string().as_bytes());
    }

    /// Sends a request and waits for its response (notifications meanwhile are kept).
    pub fn request(&mut self, method: &str, params: Value) -> Value {
        let id = self.next_id;
        self.next_id += 1;
        let msg = json!({ "jsonrpc": "2.0", "id": id, "method": method, "params": params });
        self.send_raw(msg.to_string().as_bytes());
        self.wait_for(|m| m["id"] == json!(id) && m.get("method").is_none())
            .unwrap_or_else(|| panic!("no answer to {method} within {WAIT:?}"))
    }

    /// Waits for a message `pick` accepts; other messages are kept in `notes`.
    pub fn wait_for(&mut self, pick: impl Fn(&Value) -> bool) -> Option<Value> {
        let deadline = Instant::now() + WAIT;
        loop {
            let left = deadline.checked_duration_since(Instant::now())?;
            let msg = self.incoming.recv_timeout(left).ok()?;
            if pick(&msg) {
                return Some(msg);
            }
            if msg.get("method").is_some() {
                self.notes.push(msg);
            }
        }
    }

    pub fn open(&mut self, path: &Path, text: &str) {
        self.notify(
            "textDocument/didOpen",
            json!({ "textDocument": { "uri": uri(path), "languageId": "xml", "version": 1, "text": text } }),
        );
    }

    /// Replaces the whole text of an open document.
    pub fn change(&mut self, path: &Path, version: i32, text: &str) {
        self.notify(
            "textDocument/didChange",
            json!({ "textDocument": { "uri": uri(path), "version": version },
                    "contentChanges": [{ "text": text }] }),
        );
    }

    /// A hover at the start of `path`: answered after the check of its current text,
    /// so every publication of that check has arrived when it returns.
    pub fn settle(&mut self, path: &Path) -> Value {
        let pos = json!({ "textDocument": { "uri": uri(path) }, "position": { "line": 0, "character": 0 } });
        self.request("textDocument/hover", pos)
    }

    /// The codes last published for `path`.
    pub fn codes(&self, path: &Path) -> Vec<String> {
        let diags = self.published().remove(&uri(path)).unwrap_or_default();
        diags
            .iter()
            .map(|d| d["code"].as_str().unwrap_or_default().to_string())
            .collect()
    }

    pub fn close(&mut self, path: &Path) {
        self.notify(
            "textDocument/didClose",
            json!({ "textDocument": { "uri": uri(path) } }),
        );
    }

    /// The latest diagnostics published for each URI among the kept notifications.
    pub fn published(&self) -> std::collections::BTreeMap<String, Vec<Value>> {
        let mut out = std::collections::BTreeMap::new();
        for n in &self.notes {
            if n["method"] == "textDocument/publishDiagnostics" {
                let uri = n["params"]["uri"].as_str().unwrap_or_default().to_string();
                let diags = n["params"]["diagnostics"]
                    .as_array()
                    .cloned()
                    .unwrap_or_default();
                out.insert(uri, diags);
            }
        }
        out
    }

    /// `shutdown` then `exit`; the server must end with exit code 0.
    pub fn shutdown(mut self) {
        let r = self.request("shutdown", Value::Null);
        assert!(r.get("error").is_none(), "{r}");
        self.notify("exit", Value::Null);
        let deadline = Instant::now() + WAIT;
        loop {
            if let Some(status) = self.child.try_wait().unwrap() {
                assert!(status.success(), "ferroc lsp ended with {status}");
                return;
            }
            assert!(
                Instant::now() < deadline,
                "ferroc lsp did not end after exit"
            );
            std::thread::sleep(Duration::from_millis(20));
        }
    }
}

impl Drop for Client {
    fn drop(&mut self) {
        if let Ok(None) = self.child.try_wait() {
            let _ = self.child.kill();
            let _ = self.child.wait();
        }
    }
}

pub fn uri(path: &Path) -> String {
    let path = path.canonicalize().unwrap_or_else(|_| path.to_path_buf());
    format!("file://{}", path.display())
}

fn read_frame(r: &mut impl BufRead) -> Option<Value> {
    let mut length = 0;
    loop {
        let mut line = String::new();
        if r.read_line(&mut line).ok()? == 0 {
            return None;
        }
        let line = line.trim();
        if line.is_empty() {
            break;
        }
        if let Some(v) = line.strip_prefix("Content-Length:") {
            length = v.trim().parse().ok()?;
        }
    }
    let mut body = vec![0; length];
    r.read_exact(&mut body).ok()?;
    serde_json::from_slice(&body).ok()
}
