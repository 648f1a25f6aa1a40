//! The run plan: what the `ferroc` CLI hands a runner after checking the model.
//!
//! A checked model reduced to what the runtime builds (the compiler's plan with its
//! source spans, element ids and model types left behind), plus the run's options.
//! It travels as one JSON document (docs/writing-modules.md, "How `ferroc run` runs your code"):
//!
//! ```json
//! { "format": "ferroc-run-plan", "version": 1, "ferroc": "0.1.0",
//!   "app": "…", "seed": null, "run": { … }, "modules": [ … ], … }
//! ```
//!
//! `format` names the document, `version` its layout ([`VERSION`], raised whenever a
//! field changes meaning), `ferroc` the version of the ferroc that wrote it. A runner
//! reads the header first and refuses another format, another layout or a plan of
//! another ferroc with a message that says what to do ([`read`]); only then is the
//! body read.

use ferroc_runtime::link::ros2::Ros2Node;
use ferroc_runtime::module::{Direction, Value};
use serde::{Deserialize, Serialize};
use std::path::{Path, PathBuf};
use std::time::Duration;

/// The `format` of every run plan.
pub const FORMAT: &str = "ferroc-run-plan";
/// The layout of the plan this runner reads and the CLI writes.
pub const VERSION: u32 = 1;
/// The version of ferroc (the CLI's and the runner's are one workspace's).
pub const FERROC: &str = env!("CARGO_PKG_VERSION");
/// Plans larger than this are refused unread (a model's plan is a few hundred KiB).
pub const MAX_BYTES: u64 = 256 << 20;

/// A run plan: header, application, run options, and the runtime's Builder calls.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct RunPlan {
    /// [`FORMAT`].
    pub format: String,
    /// [`VERSION`].
    pub version: u32,
    /// The ferroc that wrote it ([`FERROC`]).
    pub ferroc: String,
    /// The application's name.
    pub app: String,
    /// `--seed`, else the model's `<application seed>`; none: chosen and printed.
    pub seed: Option<u64>,
    /// How to run it.
    pub run: RunOptions,
    pub modules: Vec<Module>,
    pub connections: Vec<Connection>,
    pub calls: Vec<Call>,
    pub param_links: Vec<ParamLink>,
    pub threads: Vec<Thread>,
    pub locks: Locks,
    /// The unit of each connected port (`module/port` → `m/s`), for the channel
    /// metadata of recordings (`Plan::units`); absent in older plans: no units.
    #[serde(default)]
    pub units: Vec<(String, String)>,
    /// The parts that are ROS 2 nodes (`<ros2>`, docs/ros2.md), as the compiler's
    /// plan, the runtime and bundles describe them (one type); absent in older plans:
    /// none.
    #[serde(default)]
    pub ros2: Vec<Ros2Node>,
}

impl RunPlan {
    /// An empty plan of `app` with this ferroc's header.
    pub fn new(app: &str) -> Self {
        RunPlan {
            format: FORMAT.into(),
            version: VERSION,
            ferroc: FERROC.into(),
            app: app.into(),
            seed: None,
            run: RunOptions::default(),
            modules: Vec::new(),
            connections: Vec::new(),
            calls: Vec::new(),
            param_links: Vec::new(),
            threads: Vec::new(),
            locks: Locks::default(),
            units: Vec::new(),
            ros2: Vec::new(),
        }
    }
}

/// The options of `ferroc run` the runner acts on (paths as given, relative to the
/// working directory, which the runner shares).
#[derive(Clone, Debug, Default, Serialize, Deserialize)]
pub struct RunOptions {
    /// `--for`.
    pub duration: Option<Duration>,
    /// `--cycles`.
    pub cycles: Option<u64>,
    /// `--lockstep`.
    pub lockstep: bool,
    /// `--quiet`: no live status line.
    pub quiet: bool,
    /// `--log-dir`.
    pub log_dir: Option<PathBuf>,
    /// `--force`.
    pub force: bool,
    /// `--record FILE`.
    pub record: Option<PathBuf>,
    /// `--record-filter`.
    pub record_filter: Vec<String>,
    /// `--format json`: the summary also as one line of JSON on standard output
    /// (docs/run-summary.md). Absent in a plan of an older ferroc: false.
    #[serde(default)]
    pub format_json: bool,
}

/// One module instance.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct Module {
    /// Element path, unique in the application (`robot/control/controller`).
    pub path: String,
    /// Qualified type name (`crash_course.Controller`).
    pub type_name: String,
    /// The part it runs in (recordings name it per channel).
    pub part: Option<String>,
    /// Parameter values, in the declared units.
    pub params: Vec<(String, Value)>,
    /// Inputs with a queue: port, capacity, `on-full` policy.
    pub queues: Vec<(String, u32, String)>,
    /// Flexible port groups, in model order.
    pub ports: Vec<PortGroup>,
    /// `warn`, `clamp` or `stop`.
    pub ib2c_violations: String,
}

/// One `<port name dir type count>` of a flexible module instance.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct PortGroup {
    pub name: String,
    pub dir: Direction,
    /// The model type: the runtime's value-table key.
    pub ty: String,
    /// `None`: the single port `name`; `Some(n)`: `name/0` … `name/{n-1}`.
    pub count: Option<u32>,
}

/// One module output feeding one module input.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct Connection {
    pub from: (String, String),
    pub to: (String, String),
    /// Parts taken out of each value first, outermost first.
    pub select: Vec<Part>,
    /// Then `to = part · scale + offset`.
    pub scale: f64,
    pub offset: f64,
    /// Set when the connection joins two parts.
    pub link: Option<Link>,
    /// Writer and reader run in one thread container.
    pub local: bool,
}

/// One step into a value on a connection.
#[derive(Clone, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub enum Part {
    Field(String),
    Index(u32),
}

/// A connection between parts.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct Link {
    pub id: u32,
    pub from_part: String,
    pub to_part: String,
    /// The reader's model type.
    pub ty: String,
    pub sharing: LinkSharing,
    pub reliable: bool,
    /// Seconds.
    pub deadline: Option<f64>,
}

/// `sharing=` with its time, in seconds.
#[derive(Clone, Copy, Debug, Serialize, Deserialize)]
pub enum LinkSharing {
    OnChange { min_interval: f64 },
    Periodic { period: f64 },
}

/// A client calling a service.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct Call {
    pub client: (String, String),
    pub service: (String, String),
    pub link: Option<CallLink>,
}

/// A call between parts.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct CallLink {
    pub id: u32,
    pub client_part: String,
    pub server_part: String,
}

/// An output setting a parameter while running.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct ParamLink {
    pub from: (String, String),
    pub to: (String, String),
    pub scale: f64,
    pub link: Option<Link>,
}

/// One thread container.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct Thread {
    pub path: String,
    /// Seconds; `None` for data-triggered and continuous containers.
    pub period: Option<f64>,
    pub continuous: bool,
    pub wait: Wait,
    pub priority: Option<u32>,
    pub cpu: Option<u32>,
    /// Module path and step, in execution order.
    pub steps: Vec<(String, Step)>,
}

/// How a data-triggered container waits.
#[derive(Clone, Copy, Debug, Serialize, Deserialize)]
pub enum Wait {
    Park,
    Spin,
    Adaptive,
    Inline,
}

/// A module's step in a container's cycle.
#[derive(Clone, Copy, Debug, Serialize, Deserialize)]
pub enum Step {
    Update,
    Sense,
    Control,
}

/// Resources, slot bindings and lock orders.
#[derive(Clone, Debug, Default, Serialize, Deserialize)]
pub struct Locks {
    /// Name, level, recursive.
    pub resources: Vec<(String, Option<u32>, bool)>,
    /// Module path, slot, resource.
    pub binds: Vec<(String, String, String)>,
    /// First, second, who declares it.
    pub orders: Vec<(String, String, String)>,
}

/// The header alone: read before the body, so that another layout is named, not
/// misread.
#[derive(Deserialize)]
struct Header {
    format: Option<String>,
    version: Option<u32>,
    ferroc: Option<String>,
}

/// Reads the plan in `file` and deletes the file (it was made for this run alone:
/// nothing is left behind, whether the plan is accepted or not).
pub fn read(file: &Path) -> Result<RunPlan, String> {
    let text = read_bounded(file);
    let _ = std::fs::remove_file(file);
    parse(&text?, file)
}

fn read_bounded(file: &Path) -> Result<Vec<u8>, String> {
    use std::io::Read;
    let mut bytes = Vec::new();
    std::fs::File::open(file)
        .and_then(|f| f.take(MAX_BYTES + 1).read_to_end(&mut bytes))
        .map_err(|e| format!("cannot read the run plan {}: {e}", file.display()))?;
    if bytes.len() as u64 > MAX_BYTES {
        return Err(format!(
            "the run plan {} is larger than {} MiB",
            file.display(),
            MAX_BYTES >> 20
        ));
    }
    Ok(bytes)
}

/// The plan in `text` (read from `file`), after its header was found to be this
/// runner's.
pub fn parse(text: &[u8], file: &Path) -> Result<RunPlan, String> {
    const AGAIN: &str =
        "help: run the model with `ferroc run` of the ferroc this runner was built by; \
                         it rebuilds the runner when they differ";
    let header: Header = serde_json::from_slice(text).map_err(|_| not_a_plan(file))?;
    if header.format.as_deref() != Some(FORMAT) {
        return Err(not_a_plan(file));
    }
    let version = header.version.unwrap_or(0);
    let ferroc = header.ferroc.unwrap_or_else(|| "?".into());
    if version != VERSION {
        return Err(format!(
            "the run plan {} has layout version {version} (written by ferroc {ferroc}); this runner reads version {VERSION} (ferroc {FERROC})\n  {AGAIN}",
            file.display()
        ));
    }
    if ferroc != FERROC {
        return Err(format!(
            "the run plan {} was written by ferroc {ferroc}; this runner was built by ferroc {FERROC}\n  {AGAIN}",
            file.display()
        ));
    }
    serde_json::from_slice(text).map_err(|e| {
        format!(
            "the run plan {} is malformed (line {}, column {})\n  {AGAIN}",
            file.display(),
            e.line(),
            e.column()
        )
    })
}

fn not_a_plan(file: &Path) -> String {
    format!(
        "{} is not a ferroc run plan (format `{FORMAT}`)\n  \
         help: runners are started by `ferroc run`, which checks the model and writes the plan; run `ferroc run MODEL`",
        file.display()
    )
}

/// Writes `plan` to a new file in the temporary folder, readable by this user only
/// where the system allows; its path. The runner deletes it when it has read it.
pub fn write_temporary(plan: &RunPlan) -> Result<PathBuf, String> {
    let text = serde_json::to_vec(plan).map_err(|e| format!("cannot encode the run plan: {e}"))?;
    let dir = std::env::temp_dir();
    let stamp = std::time::SystemTime::now()
        .duration_since(std::time::UNIX_EPOCH)
        .map_or(0, |d| d.as_nanos());
    let file = dir.join(format!("ferroc-plan-{}-{stamp}.json", std::process::id()));
    let written = std::fs::OpenOptions::new()
        .write(true)
        .create_new(true)
        .open(&file)
        .and_then(|mut f| std::io::Write::write_all(&mut f, &text));
    if let Err(e) = written {
        let _ = std::fs::remove_file(&file);
        return Err(format!(
            "cannot write the run plan in {}: {e}\n  help: set TMPDIR to a writable folder",
            dir.display()
        ));
    }
    Ok(file)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn header(format: &str, version: u32, ferroc: &str) -> Vec<u8> {
        let mut plan = RunPlan::new("a");
        plan.format = format.into();
        plan.version = version;
        plan.ferroc = ferroc.into();
        serde_json::to_vec(&plan).unwrap()
    }

    #[test]
    fn a_plan_of_this_layout_and_ferroc_is_read_back_with_every_value() {
        let mut plan = RunPlan::new("app");
        plan.modules.push(Module {
            path: "m".into(),
            type_name: "t.T".into(),
            part: Some("p".into()),
            params: vec![
                ("big".into(), Value::Int(i128::MAX)),
                ("d".into(), Value::Duration(Duration::from_millis(1500))),
                ("x".into(), Value::Float(f64::MIN_POSITIVE)),
            ],
            queues: vec![("in".into(), 4, "block".into())],
            ports: Vec::new(),
            ib2c_violations: "warn".into(),
        });
        let text = serde_json::to_vec(&plan).unwrap();
        let back = parse(&text, Path::new("p.json")).unwrap();
        assert_eq!(back.modules[0].params, plan.modules[0].params);
    }

    #[test]
    fn another_layout_another_ferroc_or_another_document_is_refused_with_what_to_do() {
        let at = Path::new("/tmp/p.json");
        let e = parse(&header(FORMAT, VERSION + 1, FERROC), at).unwrap_err();
        assert!(
            e.contains(&format!("layout version {}", VERSION + 1)),
            "{e}"
        );
        assert!(e.contains("help: run the model with `ferroc run`"), "{e}");
        let e = parse(&header(FORMAT, VERSION, "0.0.1-other"), at).unwrap_err();
        assert!(e.contains("written by ferroc 0.0.1-other"), "{e}");
        let e = parse(&header("something-else", VERSION, FERROC), at).unwrap_err();
        assert!(e.contains("is not a ferroc run plan"), "{e}");
        let e = parse(b"\x00\xff not json", at).unwrap_err();
        assert!(e.contains("is not a ferroc run plan"), "{e}");
        let text = format!(
            r#"{{"format":"{FORMAT}","version":{VERSION},"ferroc":"{FERROC}","modules":7}}"#
        );
        let e = parse(text.as_bytes(), at);
        assert!(e.unwrap_err().contains("malformed"));
    }

    #[test]
    fn the_plan_file_is_deleted_once_read_accepted_or_not() {
        let file = write_temporary(&RunPlan::new("a")).unwrap();
        assert!(read(&file).is_ok());
        assert!(!file.exists());
        std::fs::write(&file, header(FORMAT, VERSION + 1, FERROC)).unwrap();
        assert!(read(&file).is_err());
        assert!(!file.exists());
    }
}
