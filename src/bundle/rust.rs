//! The `main.rs` of one part: the Builder calls `ferroc run` makes, written out with the
//! concrete module types. Wiring only; emitted already in rustfmt's layout (checked by
//! `tests/bundle.rs` with `rustfmt --check`).
//!
//! Every name in the output was validated by `layout` (identifiers) or goes through
//! `text::rust_str` (string literals) or `text::comment` (comments).

use super::layout::Part;
use super::text::{comment, rust_str};
use ferroc_compiler::schedule::StepKind;
use ferroc_compiler::source::Span;
use ferroc_runtime::container::ThreadOptions;
use std::collections::{BTreeSet, HashMap};
use std::time::Duration;

use super::code::Code;
use super::literals::{call, duration, float, human_duration, port_group, value};

/// What a generated file needs to know besides the part.
pub struct Context<'a> {
    pub application: &'a str,
    pub model_file: &'a str,
    pub tool_version: &'a str,
    /// Every part's name and address (`host:port`).
    pub parts: &'a [(String, String)],
    /// The periods of every periodic container of the application.
    pub periods: &'a [Duration],
    /// `file:line:col` of a span, relative to the model's folder.
    pub at: &'a dyn Fn(Span) -> String,
}

/// The source of `main.rs` for `part`.
pub fn main_rs(part: &Part<'_>, cx: &Context<'_>) -> String {
    let consts = module_constants(part);
    let name_of = |path: &str| consts.get(path).cloned().unwrap_or_else(|| rust_str(path));
    let mut body = Code::default();
    body.line(1, "let mut builder = Builder::new(registry);");
    let mut uses_param = false;
    let mut uses_queue = false;
    let mut uses_duration = false;
    let mut uses_ports = false;
    for m in &part.modules {
        body.blank();
        body.line(
            1,
            &format!(
                "// {}, {}",
                comment(&m.type_name),
                comment(&(cx.at)(m.span))
            ),
        );
        body.line(1, "builder.add_module(ModuleSpec {");
        body.line(2, &format!("path: {},", name_of(&m.path)));
        body.line(2, &format!("type_name: {},", rust_str(&m.type_name)));
        let params: Vec<String> = m
            .params
            .iter()
            .map(|(n, v)| call("param", &[rust_str(n), value(v, &mut uses_duration)]))
            .collect();
        uses_param |= !params.is_empty();
        body.list(2, "params: &[", &params, "],");
        let queues: Vec<String> = m
            .queues
            .iter()
            .map(|(port, capacity, policy)| {
                let on_full = match policy.as_str() {
                    "drop-oldest" => "DropOldest",
                    "drop-newest" => "DropNewest",
                    _ => "Block",
                };
                call(
                    "queue",
                    &[
                        rust_str(port),
                        capacity.to_string(),
                        format!("OnFull::{on_full}"),
                    ],
                )
            })
            .collect();
        uses_queue |= !queues.is_empty();
        body.list(2, "queues: &[", &queues, "],");
        let ports: Vec<String> = m.ports.iter().map(port_group).collect();
        uses_ports |= !ports.is_empty();
        body.list(2, "ports: &[", &ports, "],");
        let policy = match m.ib2c_violations.as_str() {
            "clamp" => "Clamp",
            "stop" => "Stop",
            _ => "Warn",
        };
        body.line(2, &format!("violations: ViolationPolicy::{policy},"));
        body.line(1, "})?;");
    }
    for c in &part.connections {
        body.blank();
        body.line(1, &format!("// {}", comment(&(cx.at)(c.span))));
        body.line(1, "builder.connect(");
        for (module, port) in [&c.from, &c.to] {
            body.line(
                2,
                &format!("{},", call("", &[name_of(module), rust_str(port)])),
            );
        }
        body.line(2, &format!("{},", super::links::conversion(c)));
        body.line(2, "ConnectOptions::default(),");
        body.line(1, ")?;");
    }
    super::links::calls(&mut body, part, cx.at, &name_of);
    for link in &part.param_links {
        body.blank();
        body.line(1, &format!("// {}", comment(&(cx.at)(link.span))));
        body.line(1, "builder.connect_param(");
        for (module, name) in [&link.from, &link.to] {
            body.line(
                2,
                &format!("{},", call("", &[name_of(module), rust_str(name)])),
            );
        }
        body.line(
            2,
            &format!("Conversion::linear({}, 0.0),", float(link.scale)),
        );
        body.line(1, ")?;");
    }
    for link in &part.calls {
        body.blank();
        body.line(1, &format!("// {}", comment(&(cx.at)(link.span))));
        body.line(1, "builder.connect_service(");
        for (module, name) in [&link.client, &link.service] {
            body.line(
                2,
                &format!("{},", call("", &[name_of(module), rust_str(name)])),
            );
        }
        body.line(1, ")?;");
    }
    for t in &part.threads {
        body.blank();
        let when = match (t.period, t.continuous) {
            (Some(p), _) => format!("every {}", human_duration(p)),
            (None, true) => "cycles back to back".to_string(),
            (None, false) => "when data arrives".to_string(),
        };
        body.line(
            1,
            &format!("// {}: {when}, steps in the compiler's order", t.path),
        );
        body.line(1, "builder.add_thread(ThreadSpec {");
        body.line(2, &format!("path: {}.to_string(),", rust_str(&t.path)));
        match t.period {
            Some(p) => {
                uses_duration = true;
                let d = duration(Duration::from_secs_f64(p));
                body.line(2, &format!("schedule: Schedule::Periodic({d}),"));
            }
            None if t.continuous => body.line(2, "schedule: Schedule::Continuous,"),
            None => body.line(2, "schedule: Schedule::Data,"),
        }
        let options = crate::run::thread_options(t);
        if options == ThreadOptions::default() {
            body.line(2, "options: ThreadOptions::default(),");
        } else {
            body.line(2, "options: ThreadOptions {");
            body.line(3, &format!("priority: {:?},", options.priority));
            body.line(3, &format!("cpu: {:?},", options.cpu));
            body.line(2, "},");
        }
        let steps: Vec<String> = t
            .steps
            .iter()
            .map(|(path, kind)| {
                let kind = match kind {
                    StepKind::Update => "Update",
                    StepKind::Sense => "Sense",
                    StepKind::Control => "Control",
                };
                call(
                    "",
                    &[
                        format!("{}.to_string()", name_of(path)),
                        format!("StepKind::{kind}"),
                    ],
                )
            })
            .collect();
        body.list(2, "steps: vec![", &steps, "],");
        body.line(1, "})?;");
    }
    body.blank();
    body.line(1, "builder.start_with(start)");

    let mut out = Code::default();
    header(&mut out, part, cx);
    let _ = uses_duration; // `PERIODS` always names `Duration`
    imports(
        &mut out,
        Uses {
            connect: !part.connections.is_empty()
                || !part.links_out.is_empty()
                || !part.param_links.is_empty()
                || !part.param_links_out.is_empty(),
            connect_options: !part.connections.is_empty() || !part.links_in.is_empty(),
            links: !part.links_out.is_empty()
                || !part.links_in.is_empty()
                || !part.param_links_out.is_empty()
                || !part.param_links_in.is_empty(),
            calls: !part.calls_out.is_empty() || !part.calls_in.is_empty(),
            queue: uses_queue,
            thread: !part.threads.is_empty(),
            value: uses_param || uses_queue,
            ports: uses_ports,
            network: part.is_linked(),
        },
    );
    out.blank();
    let about = format!(
        "{}: the part `{}` of the application `{}` (generated by ferroc {})",
        part.package, part.name, cx.application, cx.tool_version
    );
    out.line(
        0,
        &format!(
            "/// The part this program runs.\nconst PART: &str = {};",
            rust_str(&part.name)
        ),
    );
    out.line(
        0,
        &format!("const PROGRAM: &str = {};", rust_str(&part.package)),
    );
    out.line(0, &format!("const ABOUT: &str = {};", rust_str(&about)));
    if part.is_linked() {
        out.line(
            0,
            "/// The application: the first chunk of its Zenoh keys after `ferroc/`.",
        );
        out.line(
            0,
            &format!("const APPLICATION: &str = {};", rust_str(cx.application)),
        );
    }
    super::links::constants(&mut out, cx.parts, cx.periods, part.is_linked());
    super::links::specs(&mut out, part);
    super::links::call_specs(&mut out, part);
    if !consts.is_empty() {
        out.blank();
        out.line(0, "// Module paths, as in the model.");
        for m in &part.modules {
            out.line(
                0,
                &format!("const {}: &str = {};", consts[&m.path], rust_str(&m.path)),
            );
        }
    }
    out.blank();
    main_fn(&mut out, part.is_linked());
    out.blank();
    out.line(0, "/// The module types this part creates.");
    out.line(0, "fn registry() -> Registry {");
    out.line(1, "let mut registry = Registry::new();");
    let types: BTreeSet<&str> = part.modules.iter().map(|m| m.rust.as_str()).collect();
    for rust in types {
        let register = if part.behaviours.contains(&rust) {
            "register_behaviour"
        } else {
            "register"
        };
        out.line(1, &format!("registry.{register}::<{rust}>();"));
    }
    // Library value types the model gives flexible ports (built-ins need no call).
    let values: BTreeSet<&str> = part
        .modules
        .iter()
        .flat_map(|m| &m.ports)
        .filter_map(|g| g.rust.as_deref())
        .collect();
    // Library types on links cross between programs: they register with serde.
    let crossing: BTreeSet<&str> = (part.links_out.iter())
        .chain(&part.links_in)
        .filter_map(|c| c.link.as_ref()?.rust.as_deref())
        .collect();
    for rust in values.iter().filter(|r| !crossing.contains(*r)) {
        out.line(1, &format!("registry.register_value::<{rust}>();"));
    }
    for rust in crossing {
        out.line(1, &format!("registry.register_serde::<{rust}>();"));
    }
    for (request, response) in &part.call_types {
        out.line(
            1,
            &format!("registry.register_call::<{request}, {response}>();"),
        );
    }
    for accessor in &part.fields {
        out.line(1, &accessor.call());
    }
    out.line(1, "registry");
    out.line(0, "}");
    out.blank();
    out.line(
        0,
        "/// Creates the modules, connects them, declares the thread containers and starts them.",
    );
    out.line(
        0,
        "fn build(registry: &Registry, start: StartOptions) -> Result<RunningApp, BuildError> {",
    );
    out.text.push_str(&body.text);
    out.line(0, "}");
    if uses_param {
        out.blank();
        out.line(0, "/// One entry of `ModuleSpec::params`.");
        out.line(0, "fn param(name: &str, value: Value) -> (String, Value) {");
        out.line(1, "(name.to_string(), value)");
        out.line(0, "}");
    }
    if uses_queue {
        out.blank();
        out.line(0, "/// One entry of `ModuleSpec::queues`.");
        out.line(
            0,
            "fn queue(port: &str, capacity: usize, on_full: OnFull) -> (String, QueueConfig) {",
        );
        out.line(
            1,
            "(port.to_string(), QueueConfig::new(capacity).on_full(on_full))",
        );
        out.line(0, "}");
    }
    out.text
}

fn header(out: &mut Code, part: &Part<'_>, cx: &Context<'_>) {
    let lines = [
        format!(
            "//! `{}`: the part `{}` of the application `{}`.",
            part.package, part.name, cx.application
        ),
        "//!".to_string(),
        format!(
            "//! Generated by ferroc {} (`ferroc bundle`) from `{}`: regenerate it rather than",
            cx.tool_version,
            comment(cx.model_file)
        ),
        "//! editing it. It holds only wiring: which modules exist with which parameters, how"
            .into(),
        "//! they are connected, and which thread container runs their steps in which order."
            .into(),
        "//! The module logic lives in the component crates.".into(),
    ];
    for l in lines {
        out.line(0, &l);
    }
    out.blank();
}

/// Which imports the generated code needs.
struct Uses {
    connect: bool,
    connect_options: bool,
    links: bool,
    calls: bool,
    queue: bool,
    thread: bool,
    value: bool,
    ports: bool,
    network: bool,
}

fn imports(out: &mut Code, uses: Uses) {
    let mut builder = vec!["BuildError", "Builder"];
    if uses.connect {
        builder.push("Conversion");
    }
    builder.extend(["ModuleSpec", "Registry", "RunningApp"]);
    if uses.thread {
        builder.push("Schedule");
    }
    builder.push("StartOptions");
    if uses.thread {
        builder.extend(["StepKind", "ThreadSpec"]);
    }
    out.line(0, "use ferroc_runtime::behaviour::ViolationPolicy;");
    out.fill("use ferroc_runtime::builder::{", &builder, "};");
    if uses.thread {
        out.line(0, "use ferroc_runtime::container::ThreadOptions;");
    }
    match (uses.calls, uses.links) {
        (true, true) => out.line(
            0,
            "use ferroc_runtime::link::{CallSpec, LinkSpec, Sharing};",
        ),
        (false, true) => out.line(0, "use ferroc_runtime::link::{LinkSpec, Sharing};"),
        (true, false) => out.line(0, "use ferroc_runtime::link::CallSpec;"),
        (false, false) => {}
    }
    match (uses.ports, uses.value) {
        (true, true) => out.line(
            0,
            "use ferroc_runtime::module::{Direction, PortGroup, Value};",
        ),
        (true, false) => out.line(0, "use ferroc_runtime::module::{Direction, PortGroup};"),
        (false, true) => out.line(0, "use ferroc_runtime::module::Value;"),
        (false, false) => {}
    }
    match (uses.connect_options, uses.queue) {
        (true, true) => out.line(
            0,
            "use ferroc_runtime::port::{ConnectOptions, OnFull, QueueConfig};",
        ),
        (true, false) => out.line(0, "use ferroc_runtime::port::ConnectOptions;"),
        (false, true) => out.line(0, "use ferroc_runtime::port::{OnFull, QueueConfig};"),
        (false, false) => {}
    }
    out.line(0, "use ferroc_runtime::supervise::{self, Args};");
    if uses.network {
        out.line(0, "use ferroc_zenoh::Zenoh;");
    }
    out.line(0, "use std::process::ExitCode;");
    out.line(0, "use std::sync::atomic::{AtomicBool, Ordering};");
    out.line(0, "use std::sync::Arc;");
    out.line(0, "use std::time::Duration;");
}

/// `main()`: arguments, the Ctrl-C handler, the network to the other parts (when
/// `linked`), then build and supervise.
fn main_fn(out: &mut Code, linked: bool) {
    let head = "fn main() -> ExitCode {
    let args = match Args::from_env(PROGRAM, ABOUT) {
        Ok(args) => args,
        Err(code) => return code,
    };
    // Ctrl-C and SIGTERM stop every thread container after its current cycle.
    let interrupted = Arc::new(AtomicBool::new(false));
    let flag = interrupted.clone();
    if let Err(e) = ctrlc::set_handler(move || flag.store(true, Ordering::SeqCst)) {
        eprintln!(\"warning: Ctrl-C will not stop cleanly: {e}\");
    }
";
    out.text.push_str(head);
    if linked {
        let network =
            "    // The other parts: over Zenoh, at the addresses of the model or the command line.
    let mut start = args.start_options(PERIODS);
    let network = args.addresses(PART, PARTS).and_then(|addresses| {
        Zenoh::new(APPLICATION, addresses, args.zenoh_config.as_deref())
    });
    match network {
        Ok(network) => start.network = Some(Arc::new(network)),
        Err(e) => {
            eprintln!(\"error: {e}\");
            return ExitCode::from(2);
        }
    }
";
        out.text.push_str(network);
    } else {
        out.text
            .push_str("    let start = args.start_options(PERIODS);\n");
    }
    let tail = "    let registry = registry();
    let app = match build(&registry, start) {
        Ok(app) => app,
        Err(e) => {
            eprintln!(\"error: part `{PART}`: {e}\");
            return ExitCode::from(1);
        }
    };
    supervise::supervise(app, &interrupted, &args.options())
}
";
    out.text.push_str(tail);
}

/// A readable constant name for every module path of the part: the module's name in
/// upper case, with as many enclosing names as it takes to be unique.
fn module_constants(part: &Part<'_>) -> HashMap<String, String> {
    const RESERVED: &[&str] = &["PART", "PROGRAM", "ABOUT"];
    let paths: Vec<Vec<&str>> = part
        .modules
        .iter()
        .map(|m| m.path.split('/').collect())
        .collect();
    let mut depth = vec![1usize; paths.len()];
    let name = |i: usize, k: usize| -> String {
        let segs = &paths[i];
        let from = segs.len().saturating_sub(k);
        let n = segs[from..].join("_").to_uppercase();
        if n.chars().all(|c| c == '_') {
            format!("MODULE{n}")
        } else {
            n
        }
    };
    loop {
        let names: Vec<String> = (0..paths.len()).map(|i| name(i, depth[i])).collect();
        let mut grew = false;
        for i in 0..paths.len() {
            let clash = RESERVED.contains(&names[i].as_str())
                || names
                    .iter()
                    .enumerate()
                    .any(|(j, n)| j != i && *n == names[i]);
            if clash && depth[i] < paths[i].len() {
                depth[i] += 1;
                grew = true;
            }
        }
        if !grew {
            let mut out = HashMap::new();
            let mut taken = BTreeSet::new();
            for (i, mut n) in names.into_iter().enumerate() {
                let base = n.clone();
                let mut k = 2;
                while RESERVED.contains(&n.as_str()) || !taken.insert(n.clone()) {
                    n = format!("{base}_{k}");
                    k += 1;
                }
                out.insert(part.modules[i].path.clone(), n);
            }
            return out;
        }
    }
}
