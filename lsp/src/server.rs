//! The main loop: the protocol's life cycle, document sync, which models to check,
//! publishing findings, and dispatching requests to the features.

use crate::convert::{self, Spans};
use crate::documents::{self, Documents};
use crate::position::Encoding;
use crate::worker::{self, Job, Outcome};
use crossbeam_channel::{select, Receiver, Sender};
use ferroc_compiler::load::Options;
use ferroc_compiler::CheckResult;
use lsp_server::{Connection, ErrorCode, Message, Notification, Request, RequestId, Response};
use lsp_types::notification::Notification as _;
use lsp_types::{notification as note, Diagnostic, PublishDiagnosticsParams};
use serde_json::Value;
use std::collections::{BTreeMap, BTreeSet, HashMap, HashSet, VecDeque};
use std::path::{Path, PathBuf};
use std::sync::Arc;

/// Requests waiting for a check; beyond this the oldest is answered `ContentModified`.
const MAX_PENDING: usize = 64;

pub(crate) struct Server {
    pub(crate) docs: Documents,
    pub(crate) enc: Encoding,
    /// The latest result of each model checked.
    pub(crate) results: HashMap<PathBuf, Arc<CheckResult>>,
    /// Each file → the models whose last check read it.
    deps: HashMap<PathBuf, BTreeSet<PathBuf>>,
    /// Each file → its findings from each model's check (a fragment two models include
    /// has findings from both).
    published: HashMap<PathBuf, BTreeMap<PathBuf, Vec<Diagnostic>>>,
    /// Models sent to the worker and not answered yet.
    in_flight: HashSet<PathBuf>,
    pending: VecDeque<Request>,
    jobs: Sender<Job>,
    sender: Sender<Message>,
    workspace: Vec<PathBuf>,
    /// The models kept checked: open ones and those found for an open fragment or
    /// manifest (`discover.rs`). A closed model is no longer checked.
    roots: HashSet<PathBuf>,
    /// Whether the workspace was searched for the models that use a fragment or manifest.
    discovered: bool,
    initialized: bool,
    shut_down: bool,
}

/// Serves `connection` until `exit`; `Err` when the client went away without it.
pub fn serve(connection: &Connection, options: Options) -> Result<(), String> {
    let (jobs, job_rx) = crossbeam_channel::unbounded();
    let (done_tx, done) = crossbeam_channel::unbounded();
    worker::start(options, job_rx, done_tx);
    let mut server = Server {
        docs: Documents::default(),
        enc: Encoding::Utf16,
        results: HashMap::new(),
        deps: HashMap::new(),
        published: HashMap::new(),
        in_flight: HashSet::new(),
        pending: VecDeque::new(),
        jobs,
        sender: connection.sender.clone(),
        workspace: Vec::new(),
        roots: HashSet::new(),
        discovered: false,
        initialized: false,
        shut_down: false,
    };
    server.run(&connection.receiver, &done)
}

impl Server {
    fn run(
        &mut self,
        messages: &Receiver<Message>,
        done: &Receiver<Outcome>,
    ) -> Result<(), String> {
        loop {
            select! {
                recv(messages) -> msg => match msg {
                    Ok(msg) => {
                        if self.message(msg) {
                            return Ok(());
                        }
                    }
                    Err(_) => return Err("the client closed the connection without `exit`".into()),
                },
                recv(done) -> outcome => {
                    if let Ok(outcome) = outcome {
                        self.outcome(outcome);
                    }
                }
            }
        }
    }

    /// Handles one message; `true` on `exit`.
    fn message(&mut self, msg: Message) -> bool {
        match msg {
            Message::Request(req) => self.request(req),
            Message::Notification(n) if n.method == note::Exit::METHOD => return true,
            Message::Notification(n) if n.method == crate::transport::UNREADABLE => {
                self.log(1, n.params.as_str().unwrap_or_default().to_string());
            }
            Message::Notification(n) => {
                if self.initialized {
                    self.notification(n);
                }
            }
            Message::Response(_) => {} // the server sends no requests
        }
        false
    }

    fn request(&mut self, req: Request) {
        if req.method == "initialize" {
            return self.initialize(req);
        }
        if !self.initialized {
            return self.error(req.id, -32002, "the server is not initialized yet".into());
        }
        if self.shut_down {
            let why = "the server was shut down; only `exit` is answered".into();
            return self.error(req.id, ErrorCode::InvalidRequest as i32, why);
        }
        if req.method == "shutdown" {
            self.shut_down = true;
            return self.respond(Response::new_ok(req.id, Value::Null));
        }
        self.dispatch(req);
    }

    /// Answers a request now, or keeps it until the check it needs is done.
    fn dispatch(&mut self, req: Request) {
        match self.answer(&req) {
            Answer::Now(response) => self.respond(response),
            Answer::Wait => {
                if self.pending.len() >= MAX_PENDING {
                    if let Some(old) = self.pending.pop_front() {
                        let why = "too many requests waiting for a check".into();
                        self.error(old.id, ErrorCode::ContentModified as i32, why);
                    }
                }
                self.pending.push_back(req);
            }
        }
    }

    fn answer(&mut self, req: &Request) -> Answer {
        let id = req.id.clone();
        let result = match req.method.as_str() {
            "textDocument/definition" => crate::navigate::definition(self, req),
            "textDocument/references" => crate::navigate::references(self, req),
            "textDocument/hover" => crate::hover::hover(self, req),
            "textDocument/completion" => crate::complete::completion(self, req),
            "textDocument/codeAction" => crate::actions::code_actions(self, req),
            "textDocument/documentSymbol" => crate::symbols::document_symbols(self, req),
            "workspace/symbol" => crate::symbols::workspace_symbols(self, req),
            _ => {
                return Answer::Now(Response::new_err(
                    id,
                    ErrorCode::MethodNotFound as i32,
                    format!("ferroc lsp does not answer `{}`", req.method),
                ))
            }
        };
        match result {
            Ok(Some(value)) => Answer::Now(Response::new_ok(id, value)),
            Ok(None) => Answer::Wait,
            Err(why) => Answer::Now(Response::new_err(id, ErrorCode::InvalidParams as i32, why)),
        }
    }

    fn initialize(&mut self, req: Request) {
        if self.initialized {
            let why = "`initialize` was sent twice".into();
            return self.error(req.id, ErrorCode::InvalidRequest as i32, why);
        }
        let params: lsp_types::InitializeParams = match serde_json::from_value(req.params) {
            Ok(p) => p,
            Err(e) => {
                let why = format!("cannot read the initialize parameters: {e}");
                return self.error(req.id, ErrorCode::InvalidParams as i32, why);
            }
        };
        let utf8 = (params.capabilities.general.as_ref())
            .and_then(|g| g.position_encodings.as_ref())
            .is_some_and(|e| e.contains(&lsp_types::PositionEncodingKind::UTF8));
        self.enc = if utf8 {
            Encoding::Utf8
        } else {
            Encoding::Utf16
        };
        self.workspace = workspace_folders(&params);
        self.initialized = true;
        let result = crate::capabilities::initialize_result(self.enc);
        self.respond(Response::new_ok(req.id, result));
    }

    fn notification(&mut self, n: Notification) {
        match n.method.as_str() {
            "textDocument/didOpen" => {
                if let Ok(p) =
                    n.extract::<lsp_types::DidOpenTextDocumentParams>("textDocument/didOpen")
                {
                    let doc = p.text_document;
                    if let Some(path) = documents::path_of(&doc.uri) {
                        self.docs.open(path.clone(), doc.uri, doc.version, doc.text);
                        self.changed(&path);
                    }
                }
            }
            "textDocument/didChange" => {
                if let Ok(p) =
                    n.extract::<lsp_types::DidChangeTextDocumentParams>("textDocument/didChange")
                {
                    let doc = p.text_document;
                    if let Some(path) = documents::path_of(&doc.uri) {
                        if self
                            .docs
                            .change(&path, doc.version, p.content_changes, self.enc)
                        {
                            self.changed(&path);
                        }
                    }
                }
            }
            "textDocument/didClose" => {
                if let Ok(p) =
                    n.extract::<lsp_types::DidCloseTextDocumentParams>("textDocument/didClose")
                {
                    if let Some(path) = documents::path_of(&p.text_document.uri) {
                        self.docs.close(&path);
                        // The file on disk is what the models read now.
                        self.recheck_users(&path);
                    }
                }
            }
            "workspace/didChangeWatchedFiles" => {
                if let Ok(p) = n.extract::<lsp_types::DidChangeWatchedFilesParams>(
                    "workspace/didChangeWatchedFiles",
                ) {
                    // A file changed, appeared or went on disk: the models that read it
                    // (an open document's text still stands in for its file).
                    let mut roots = BTreeSet::new();
                    for change in p.changes {
                        if let Some(path) = documents::path_of(&change.uri) {
                            roots.extend(self.users(&path));
                        }
                    }
                    self.check(roots);
                }
            }
            _ => {}
        }
    }

    /// The models kept checked that read `path`.
    fn users(&self, path: &Path) -> BTreeSet<PathBuf> {
        let users = self.deps.get(path).into_iter().flatten();
        users.filter(|r| self.roots.contains(*r)).cloned().collect()
    }

    /// A document's text changed: check it if it is a model, and every model that read it.
    fn changed(&mut self, path: &Path) {
        let mut roots = self.users(path);
        let is_root = self
            .docs
            .get(path)
            .is_some_and(|d| is_checkable(path, &d.text));
        if is_root {
            roots.insert(path.to_path_buf());
            self.roots.insert(path.to_path_buf());
        } else if roots.is_empty() && !self.discovered {
            self.discovered = true;
            let found = crate::discover::models(&self.workspace, path);
            self.roots.extend(found.iter().cloned());
            roots.extend(found);
        }
        if roots.is_empty() && !is_root {
            let name = path.display();
            self.log(3, format!("{name}: no model that uses this file is known; it is checked when a model that includes or uses it is opened"));
        }
        self.check(roots);
    }

    /// A closed document: its own check's findings go, and the models that read it
    /// are checked with the file on disk.
    fn recheck_users(&mut self, path: &Path) {
        self.roots.remove(path);
        self.forget_root(path);
        let roots = self.users(path);
        self.check(roots);
    }

    pub(crate) fn check(&mut self, roots: BTreeSet<PathBuf>) {
        if roots.is_empty() {
            return;
        }
        self.in_flight.extend(roots.iter().cloned());
        let overlay = self.docs.overlay();
        let _ = self.jobs.send(Job { roots, overlay });
    }

    fn outcome(&mut self, outcome: Outcome) {
        self.in_flight.remove(&outcome.root);
        let name = outcome.root.display();
        let took = outcome.took.as_secs_f64() * 1000.0;
        let cpu = (outcome.cpu)
            .map(|c| format!(" ({:.0} ms CPU)", c.as_secs_f64() * 1000.0))
            .unwrap_or_default();
        self.log(4, format!("checked {name} in {took:.0} ms{cpu}"));
        match outcome.result {
            Ok(result) => self.publish_result(&outcome.root, result),
            Err(why) => {
                self.log(1, why);
                self.forget_root(&outcome.root);
            }
        }
        self.retry_pending();
    }

    /// Takes a model's findings: each file it read gets the findings located in it.
    fn publish_result(&mut self, root: &Path, result: Arc<CheckResult>) {
        let mut by_file: BTreeMap<PathBuf, Vec<Diagnostic>> = BTreeMap::new();
        for (_, file) in result.sources.files() {
            if file.path.is_absolute() {
                by_file.entry(file.path.clone()).or_default();
                self.deps
                    .entry(file.path.clone())
                    .or_default()
                    .insert(root.to_path_buf());
            }
        }
        let mut spans = Spans::new(&result.sources, self.enc);
        for d in &result.diagnostics {
            if let Some(path) = spans.path(d.primary.span) {
                let lsp = convert::diagnostic(d, &mut spans);
                by_file.entry(path).or_default().push(lsp);
            }
        }
        // Files this model no longer reads lose its findings.
        let mut touched: BTreeSet<PathBuf> = by_file.keys().cloned().collect();
        for (file, per_root) in &mut self.published {
            if !by_file.contains_key(file) && per_root.remove(root).is_some() {
                touched.insert(file.clone());
            }
        }
        for (file, roots) in &mut self.deps {
            if !by_file.contains_key(file) {
                roots.remove(root);
            }
        }
        for (file, diags) in by_file {
            self.published
                .entry(file)
                .or_default()
                .insert(root.to_path_buf(), diags);
        }
        for file in touched {
            self.publish(&file);
        }
        if let Some(old) = self.results.insert(root.to_path_buf(), result) {
            drop_elsewhere(old);
        }
    }

    /// Drops what a model's check said (it cannot be checked, or it was closed).
    fn forget_root(&mut self, root: &Path) {
        self.results.remove(root);
        let mut touched = Vec::new();
        for (file, per_root) in &mut self.published {
            if per_root.remove(root).is_some() {
                touched.push(file.clone());
            }
        }
        for file in touched {
            self.publish(&file);
        }
    }

    /// Sends a file's findings: those of every model that read it, each once.
    fn publish(&mut self, file: &Path) {
        let Some(uri) = documents::uri_of(&self.docs, file) else {
            return;
        };
        let mut all: Vec<Diagnostic> = Vec::new();
        if let Some(per_root) = self.published.get(file) {
            for d in per_root.values().flatten() {
                if !all
                    .iter()
                    .any(|a| a.range == d.range && a.code == d.code && a.message == d.message)
                {
                    all.push(d.clone());
                }
            }
        }
        let version = self.docs.get(file).map(|d| d.version);
        self.notify::<note::PublishDiagnostics>(PublishDiagnosticsParams::new(uri, all, version));
    }

    fn retry_pending(&mut self) {
        let waiting: Vec<Request> = self.pending.drain(..).collect();
        for req in waiting {
            self.dispatch(req);
        }
    }

    /// The result of a check of the current text of `path`, or `Err(true)` when a check
    /// of a model that reads it is under way (its result will be newer), `Err(false)`
    /// when none will come.
    pub(crate) fn fresh(
        &self,
        path: &Path,
    ) -> Result<(Arc<CheckResult>, ferroc_compiler::source::FileId), bool> {
        let text = self.docs.get(path).map(|d| d.text.as_str());
        let mut roots: Vec<&PathBuf> = self.deps.get(path).into_iter().flatten().collect();
        roots.extend(self.results.keys().filter(|r| r.as_path() == path));
        if self
            .in_flight
            .iter()
            .any(|r| r == path || roots.contains(&r))
        {
            return Err(true);
        }
        for root in &roots {
            if let Some(result) = self.results.get(*root) {
                if let Some(file) = result.sources.find(path) {
                    if text.is_none_or(|t| t == result.sources.get(file).text) {
                        return Ok((result.clone(), file));
                    }
                }
            }
        }
        Err(false)
    }

    /// The latest result that read `path`, whatever text it read (completion of
    /// names does not wait for a check).
    pub(crate) fn latest(&self, path: &Path) -> Option<Arc<CheckResult>> {
        let mut roots = self.deps.get(path).into_iter().flatten();
        roots.find_map(|r| self.results.get(r)).cloned()
    }

    pub(crate) fn log(&self, kind: u8, text: String) {
        let msg = Notification::new(
            "window/logMessage".into(),
            serde_json::json!({ "type": kind, "message": text }),
        );
        let _ = self.sender.send(Message::Notification(msg));
    }

    fn notify<N: lsp_types::notification::Notification>(&self, params: N::Params) {
        let msg = Notification::new(N::METHOD.into(), params);
        let _ = self.sender.send(Message::Notification(msg));
    }

    fn respond(&self, response: Response) {
        let _ = self.sender.send(Message::Response(response));
    }

    fn error(&self, id: RequestId, code: i32, message: String) {
        self.respond(Response::new_err(id, code, message));
    }
}

enum Answer {
    Now(Response),
    Wait,
}

/// Frees a replaced check result on a thread of its own: the IR of a large model
/// takes a tenth of a check to free (B1), time the main loop should spend answering.
fn drop_elsewhere(old: Arc<CheckResult>) {
    if std::thread::Builder::new()
        .name("ferroc-lsp-free".into())
        .spawn(move || drop(old))
        .is_err()
    {
        // No thread to spare: it is freed here, as it would have been.
    }
}

/// Whether a file is checked on its own: an application model or a FINROC file.
fn is_checkable(path: &Path, text: &str) -> bool {
    let root = ferroc_compiler::load::root_element_of(text.as_bytes());
    root.as_deref() == Some("application")
        || ferroc_compiler::finroc::kind_of_root(root.as_deref(), path).is_some()
}

fn workspace_folders(params: &lsp_types::InitializeParams) -> Vec<PathBuf> {
    let mut out: Vec<PathBuf> = (params.workspace_folders.iter().flatten())
        .filter_map(|f| f.uri.to_file_path().ok())
        .collect();
    #[allow(deprecated)]
    if out.is_empty() {
        if let Some(root) = params.root_uri.as_ref().and_then(|u| u.to_file_path().ok()) {
            out.push(root);
        }
    }
    out
}
