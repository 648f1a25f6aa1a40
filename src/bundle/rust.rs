//! The `main.rs` of one part: the Builder calls `ferroc run` makes, written out with the
//! concrete module types. Wiring only; emitted already in rustfmt's layout (checked by
//! `tests/bundle.rs` with `rustfmt --check`).
//!
//! Every name in the output was validated by `layout` (identifiers) or goes through
//! `text::rust_str` (string literals) or `text::comment` (comments).

use super::layout::Part;
use super::text::rust_str;
use ferroc_compiler::schedule::StepKind;
use ferroc_compiler::source::Span;
use ferroc_runtime::container::ThreadOptions;
use std::collections::BTreeSet;
use std::time::Duration;

use super::code::Code;
use super::escape::filters;
use super::literals::{call, duration, float, human_duration, port_group, value};
use askama::Template;

mod constants;
use constants::module_constants;

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

/// Lines at `indent` as `Code` writes them, without the last line break: a fragment
/// the template places on lines of its own.
fn lines(write: impl FnOnce(&mut Code)) -> String {
    let mut code = Code::default();
    write(&mut code);
    code.text.trim_end_matches('\n').to_string()
}

/// The source of `main.rs` for `part`.
pub fn main_rs(part: &Part<'_>, cx: &Context<'_>) -> String {
    let consts = module_constants(part);
    let name_of = |path: &str| consts.get(path).cloned().unwrap_or_else(|| rust_str(path));
    // Two `(module, name)` arguments, one a line.
    let ends = |a: (&str, &str), b: (&str, &str)| {
        lines(|code| {
            for (module, name) in [a, b] {
                code.line(
                    2,
                    &format!("{},", call("", &[name_of(module), rust_str(name)])),
                );
            }
        })
    };
    let mut uses_param = false;
    let mut uses_queue = false;
    let mut uses_duration = false;
    let mut uses_ports = false;
    let mut modules = Vec::with_capacity(part.modules.len());
    for m in &part.modules {
        let params: Vec<String> = m
            .params
            .iter()
            .map(|(n, v)| call("param", &[rust_str(n), value(v, &mut uses_duration)]))
            .collect();
        uses_param |= !params.is_empty();
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
        let ports: Vec<String> = m.ports.iter().map(port_group).collect();
        uses_ports |= !ports.is_empty();
        modules.push(ModuleBlock {
            type_name: &m.type_name,
            at: (cx.at)(m.span),
            path: name_of(&m.path),
            lists: lines(|code| {
                code.list(2, "params: &[", &params, "],");
                code.list(2, "queues: &[", &queues, "],");
                code.list(2, "ports: &[", &ports, "],");
            }),
            violations: match m.ib2c_violations.as_str() {
                "clamp" => "Clamp",
                "stop" => "Stop",
                _ => "Warn",
            },
        });
    }
    let connections = (part.connections.iter())
        .map(|c| ConnectBlock {
            at: (cx.at)(c.span),
            ends: ends(
                (c.from.0.as_str(), c.from.1.as_str()),
                (c.to.0.as_str(), c.to.1.as_str()),
            ),
            conversion: super::links::conversion(c),
            options: if c.local {
                // Writer and reader in one thread container: the local path.
                "ConnectOptions::default().with_local(true)"
            } else {
                "ConnectOptions::default()"
            },
        })
        .collect();
    let link_calls = lines(|code| super::links::calls(code, part, cx.at, &name_of));
    let param_links = (part.param_links.iter())
        .map(|l| ConnectBlock {
            at: (cx.at)(l.span),
            ends: ends(
                (l.from.0.as_str(), l.from.1.as_str()),
                (l.to.0.as_str(), l.to.1.as_str()),
            ),
            conversion: format!("Conversion::linear({}, 0.0)", float(l.scale)),
            options: "",
        })
        .collect();
    let calls = (part.calls.iter())
        .map(|l| ConnectBlock {
            at: (cx.at)(l.span),
            ends: ends(
                (l.client.0.as_str(), l.client.1.as_str()),
                (l.service.0.as_str(), l.service.1.as_str()),
            ),
            conversion: String::new(),
            options: "",
        })
        .collect();
    let threads = part
        .threads
        .iter()
        .map(|t| thread_block(t, &name_of))
        .collect();
    let _ = uses_duration; // `PERIODS` always names `Duration`
    let mut imports_code = Code::default();
    imports(
        &mut imports_code,
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
    let mut links = Code::default();
    super::links::constants(&mut links, cx.parts, cx.periods, part.is_linked());
    super::links::specs(&mut links, part);
    super::links::call_specs(&mut links, part);
    // For `--inspect`: the connections inside the part (an input answers its writer's
    // value) and where the model declares each module.
    let mut inspection = Code::default();
    let wires: Vec<String> = (part.connections.iter())
        .map(|c| {
            call(
                "",
                &[
                    name_of(&c.from.0),
                    rust_str(&c.from.1),
                    name_of(&c.to.0),
                    rust_str(&c.to.1),
                ],
            )
        })
        .collect();
    let wire_type = "const CONNECTIONS: &[(&str, &str, &str, &str)] = &[";
    inspection.list(0, wire_type, &wires, "];");
    let sources: Vec<String> = (part.modules.iter())
        .map(|m| call("", &[name_of(&m.path), rust_str(&(cx.at)(m.span))]))
        .collect();
    inspection.list(0, "const SOURCES: &[(&str, &str)] = &[", &sources, "];");
    MainRs {
        inspection: inspection.text.trim_end_matches('\n').to_string(),
        package: &part.package,
        part: &part.name,
        application: cx.application,
        tool_version: cx.tool_version,
        model_file: cx.model_file,
        imports: imports_code.text.trim_end_matches('\n'),
        about: format!(
            "{}: the part `{}` of the application `{}` (generated by ferroc {})",
            part.package, part.name, cx.application, cx.tool_version
        ),
        links: links.text.trim_end_matches('\n'),
        module_constants: (part.modules.iter())
            .filter_map(|m| Some((consts.get(&m.path)?.as_str(), m.path.as_str())))
            .collect(),
        recordable: super::record::table(part, &name_of),
        registrations: registrations(part),
        modules,
        connections,
        link_calls: if link_calls.is_empty() {
            link_calls
        } else {
            format!("\n{link_calls}")
        },
        param_links,
        calls,
        threads,
        uses_param,
        uses_queue,
        linked: part.is_linked(),
    }
    .to_string()
}

/// `main.rs` (template `templates/main.rs`): the fixed parts of the program around what
/// the emitters above write (imports, link constants, the body of `build`). Text from
/// the model is escaped for Rust comments by default (`askama.toml`), string literals
/// go through the `rust_str` filter, code the emitters wrote passes with `|safe`.
#[derive(Template)]
#[template(path = "main.rs")]
struct MainRs<'a> {
    package: &'a str,
    part: &'a str,
    application: &'a str,
    tool_version: &'a str,
    model_file: &'a str,
    imports: &'a str,
    about: String,
    links: &'a str,
    /// (constant, module path), in module order.
    module_constants: Vec<(&'a str, &'a str)>,
    /// `const RECORDABLE` (`record.rs`).
    recordable: String,
    /// `const CONNECTIONS` and `const SOURCES`, for `--inspect`.
    inspection: String,
    /// The calls in `registry()`.
    registrations: Vec<String>,
    modules: Vec<ModuleBlock<'a>>,
    connections: Vec<ConnectBlock>,
    /// The ends of links to and from other parts (`links.rs`), after a line break.
    link_calls: String,
    param_links: Vec<ConnectBlock>,
    calls: Vec<ConnectBlock>,
    threads: Vec<ThreadBlock>,
    uses_param: bool,
    uses_queue: bool,
    /// Whether the part talks to others (over Zenoh, `ferroc-zenoh`).
    linked: bool,
}

/// One `builder.add_module` of `build()`.
struct ModuleBlock<'a> {
    type_name: &'a str,
    /// `file:line:col` of its definition.
    at: String,
    /// Its path: a constant or a string literal.
    path: String,
    /// The `params`, `queues` and `ports` lines.
    lists: String,
    violations: &'static str,
}

/// One `builder.connect`, `connect_param` or `connect_service` of `build()`.
struct ConnectBlock {
    at: String,
    /// The two `(module, name)` lines.
    ends: String,
    /// The conversion argument (none for service calls).
    conversion: String,
    /// The `ConnectOptions` argument of data connections.
    options: &'static str,
}

/// One `builder.add_thread` of `build()`.
struct ThreadBlock {
    path: String,
    /// `every 40 ms`, `cycles back to back`, `when data arrives`.
    when: String,
    schedule: String,
    /// The `options` line or lines.
    options: String,
    /// The `steps` line or lines.
    steps: String,
}

fn thread_block(
    t: &ferroc_compiler::plan::PlannedThread,
    name_of: &dyn Fn(&str) -> String,
) -> ThreadBlock {
    let when = match (t.period, t.continuous) {
        (Some(p), _) => format!("every {}", human_duration(p)),
        (None, true) => "cycles back to back".to_string(),
        (None, false) => "when data arrives".to_string(),
    };
    let schedule = match t.period {
        Some(p) => format!(
            "Schedule::Periodic({})",
            duration(Duration::from_secs_f64(p))
        ),
        None if t.continuous => "Schedule::Continuous".to_string(),
        None => "Schedule::Data".to_string(),
    };
    let options = crate::run::thread_options(t);
    let options = lines(|code| {
        if options == ThreadOptions::default() {
            code.line(2, "options: ThreadOptions::default(),");
        } else {
            code.line(2, "options: ThreadOptions {");
            code.line(3, &format!("priority: {:?},", options.priority));
            code.line(3, &format!("cpu: {:?},", options.cpu));
            code.line(
                3,
                &format!("wait: ferroc_runtime::port::WaitMode::{:?},", options.wait),
            );
            code.line(2, "},");
        }
    });
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
    ThreadBlock {
        path: t.path.clone(),
        when,
        schedule,
        options,
        steps: lines(|code| code.list(2, "steps: vec![", &steps, "],")),
    }
}

/// The lines of `registry()`: module types, value types of flexible ports, types that
/// cross links (serde), service call types, field accessors.
fn registrations(part: &Part<'_>) -> Vec<String> {
    let mut out = Vec::new();
    let types: BTreeSet<&str> = part.modules.iter().map(|m| m.rust.as_str()).collect();
    for rust in types {
        let register = if part.behaviours.contains(&rust) {
            "register_behaviour"
        } else {
            "register"
        };
        out.push(format!("registry.{register}::<{rust}>();"));
    }
    // Library value types the model gives flexible ports (built-ins need no call).
    let values: BTreeSet<&str> = part
        .modules
        .iter()
        .flat_map(|m| &m.ports)
        .filter_map(|g| g.rust.as_deref())
        .collect();
    // Library types on links cross between programs: they register with serde. So do
    // the flexible ports' library types declared with serde="true" (as their crates
    // register them for `ferroc run`): the recording and replaying modules (Logger,
    // Player, Const) encode their values.
    let encodable = (part.modules.iter())
        .flat_map(|m| &m.ports)
        .filter(|g| g.serde)
        .filter_map(|g| g.rust.as_deref());
    let crossing: BTreeSet<&str> = (part.links_out.iter())
        .chain(&part.links_in)
        .filter_map(|c| c.link.as_ref()?.rust.as_deref())
        .chain(encodable)
        .collect();
    for rust in values.iter().filter(|r| !crossing.contains(*r)) {
        out.push(format!("registry.register_value::<{rust}>();"));
    }
    for rust in crossing {
        out.push(format!("registry.register_serde::<{rust}>();"));
    }
    for (request, response) in &part.call_types {
        out.push(format!(
            "registry.register_call::<{request}, {response}>();"
        ));
    }
    for accessor in &part.fields {
        out.push(accessor.call());
    }
    out
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
    out.line(0, "use ferroc_runtime::inspect::Catalogue;");
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
    out.line(0, "use ferroc_std::recorder::{Recordable, Recorders};");
    if uses.network {
        out.line(0, "use ferroc_zenoh::Zenoh;");
    }
    out.line(0, "use std::process::ExitCode;");
    out.line(0, "use std::sync::atomic::{AtomicBool, Ordering};");
    out.line(0, "use std::sync::Arc;");
    out.line(0, "use std::time::Duration;");
}
