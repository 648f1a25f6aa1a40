//! The plan of a model split into parts (one program each), with the crates they need,
//! every name validated before anything is generated from it.

use ferroc_compiler::ir::{Application, ElementKind};
use ferroc_compiler::library::LibrarySet;
use ferroc_compiler::plan::{
    Plan, PlannedCall, PlannedConnection, PlannedModule, PlannedParamLink, PlannedThread,
};
use ferroc_compiler::source::Span;
use std::collections::BTreeMap;
use std::path::PathBuf;

use super::text;

/// One part: one program.
pub struct Part<'p> {
    pub name: String,
    pub host: String,
    /// Cargo package and binary name: `<application>-<part>`.
    pub package: String,
    pub modules: Vec<&'p PlannedModule>,
    pub connections: Vec<&'p PlannedConnection>,
    /// Connections to and from other parts: this part writes / reads them.
    pub links_out: Vec<&'p PlannedConnection>,
    pub links_in: Vec<&'p PlannedConnection>,
    /// Parameter links to and from other parts: this part's output / parameter.
    pub param_links_out: Vec<&'p PlannedParamLink>,
    pub param_links_in: Vec<&'p PlannedParamLink>,
    /// Where it listens for the parts that send to it: `host:port`, the port being
    /// [`BASE_PORT`] plus its position in the model.
    pub address: String,
    pub calls: Vec<&'p PlannedCall>,
    /// Calls to and from other parts: this part's client calls / service answers.
    pub calls_out: Vec<&'p PlannedCall>,
    pub calls_in: Vec<&'p PlannedCall>,
    /// `(request, response)` Rust types of the calls crossing to or from this part.
    pub call_types: Vec<(String, String)>,
    pub param_links: Vec<&'p PlannedParamLink>,
    pub threads: Vec<&'p PlannedThread>,
    /// Libraries (by name) whose module types this part creates.
    pub libraries: Vec<String>,
    /// Rust types of the iB2C behaviours (and fusions) among them: the runtime wraps
    /// them in its behaviour base (`Registry::register_behaviour`).
    pub behaviours: Vec<&'p str>,
    /// Field accessors its connections use, sorted, each once.
    pub fields: Vec<super::fields::FieldAccessor>,
    /// The outputs `--record` records (`record.rs`).
    pub recordable: Vec<super::record::RecordedOutput>,
}

impl Part<'_> {
    /// Whether anything crosses between this part and another: its program then
    /// talks to the others over Zenoh (`ferroc-zenoh`).
    pub fn is_linked(&self) -> bool {
        !(self.links_out.is_empty()
            && self.links_in.is_empty()
            && self.param_links_out.is_empty()
            && self.param_links_in.is_empty()
            && self.calls_out.is_empty()
            && self.calls_in.is_empty())
    }
}

/// The port of the first part; the next ones count up from it.
pub const BASE_PORT: u16 = 47800;

/// A component library a part depends on.
pub struct Library {
    pub name: String,
    /// `rust-crate` of its manifest: the Cargo package.
    pub package: String,
    pub version: Option<String>,
    /// `rust-crate="PACKAGE@VERSION"`: the crate comes from the registry in this
    /// version, whatever `--deps` says.
    pub registry: Option<String>,
    /// The manifest file (None for libraries built into ferroc).
    pub manifest: Option<PathBuf>,
}

/// What gets bundled.
pub struct Layout<'p> {
    pub application: String,
    pub parts: Vec<Part<'p>>,
    /// The periods of every periodic thread container, sorted, each once: every
    /// program needs them all to keep in step with the others (`--lockstep`).
    pub periods: Vec<std::time::Duration>,
    /// Libraries used by at least one part, by name.
    pub libraries: BTreeMap<String, Library>,
}

/// A problem with the model that stops the bundle (exit code 1).
pub struct Problem {
    pub span: Span,
    pub what: String,
}

/// Splits the plan by part and validates every name that will reach generated code.
pub fn layout<'p>(
    app: &Application,
    libs: &LibrarySet,
    plan: &'p Plan,
) -> Result<Layout<'p>, Vec<Problem>> {
    let mut problems = Vec::new();
    let root = &app.elements[0];
    let application = app.name.clone();
    if !text::is_rust_ident(&application) {
        problems.push(Problem {
            span: app.span,
            what: format!("the application name `{application}` cannot name a program: use letters, digits and `_` (not a Rust keyword)"),
        });
    }
    let mut parts: Vec<Part<'p>> = Vec::new();
    for e in &app.elements {
        let ElementKind::Part { host } = &e.kind else {
            continue;
        };
        let host = host
            .as_ref()
            .map_or_else(|| "localhost".to_string(), |(h, _)| h.clone());
        if !text::is_host(&host) {
            problems.push(Problem {
                span: e.span,
                what: format!("the host `{}` of part `{}` cannot name a launch script: use letters, digits, `-`, `_` and `.`", text::comment(&host), text::comment(&e.name)),
            });
        }
        if !text::is_rust_ident(&e.name) {
            problems.push(Problem {
                span: e.name_span,
                what: format!("the part name `{}` cannot name a program: use letters, digits and `_` (not a Rust keyword)", text::comment(&e.name)),
            });
        }
        let port = u16::try_from(parts.len())
            .ok()
            .and_then(|i| BASE_PORT.checked_add(i))
            .unwrap_or(0);
        parts.push(Part {
            package: format!("{application}-{}", e.name),
            name: e.name.clone(),
            address: format!("{host}:{port}"),
            host,
            modules: Vec::new(),
            connections: Vec::new(),
            links_out: Vec::new(),
            links_in: Vec::new(),
            param_links_out: Vec::new(),
            param_links_in: Vec::new(),
            calls: Vec::new(),
            calls_out: Vec::new(),
            calls_in: Vec::new(),
            call_types: Vec::new(),
            param_links: Vec::new(),
            threads: Vec::new(),
            libraries: Vec::new(),
            behaviours: Vec::new(),
            fields: Vec::new(),
            recordable: Vec::new(),
        });
    }
    let part_names: Vec<String> = parts.iter().map(|p| p.name.clone()).collect();
    let part_of = |path: &str| -> Option<usize> {
        let first = path.split('/').next()?;
        part_names.iter().position(|p| p == first)
    };
    let mut module_part = BTreeMap::new();
    let mut placed = Vec::new();
    for m in &plan.modules {
        for segment in m.path.split('/') {
            if !text::is_name(segment) {
                problems.push(Problem {
                    span: m.span,
                    what: format!("`{}` is not a valid name", text::comment(segment)),
                });
            }
        }
        if !text::is_rust_path(&m.rust) {
            problems.push(Problem {
                span: m.span,
                what: format!(
                    "the module type `{}` names the Rust type `{}`, which is not a Rust path (`crate_name::Type`)",
                    m.type_name,
                    text::comment(&m.rust)
                ),
            });
        }
        for g in &m.ports {
            if let Some(rust) = g.rust.as_deref().filter(|r| !text::is_rust_path(r)) {
                problems.push(Problem {
                    span: m.span,
                    what: format!(
                        "the type `{}` of the port group `{}` names the Rust type `{}`, which is not a Rust path (`crate_name::Type`)",
                        g.ty,
                        text::comment(&g.name),
                        text::comment(rust)
                    ),
                });
            }
        }
        let Some(p) = part_of(&m.path) else {
            problems.push(Problem {
                span: m.span,
                what: format!("the module `{}` is not inside a part", m.path),
            });
            continue;
        };
        module_part.insert(m.path.as_str(), p);
        placed.push((p, m));
    }
    for (p, m) in placed {
        parts[p].modules.push(m);
        if let Some((lib, ty)) = libs.module_type(&m.type_name) {
            if ty.is_behaviour() && !parts[p].behaviours.contains(&m.rust.as_str()) {
                parts[p].behaviours.push(&m.rust);
            }
            let name = libs.get(lib).name.clone();
            if !parts[p].libraries.contains(&name) {
                parts[p].libraries.push(name);
            }
        }
        // The crates of library value types on flexible ports.
        for name in m.ports.iter().filter_map(|g| g.library.clone()) {
            if !parts[p].libraries.contains(&name) {
                parts[p].libraries.push(name);
            }
        }
    }
    for c in &plan.connections {
        for port in [&c.from.1, &c.to.1] {
            // Instance ports are paths of names and indices: `in/0`, `in/2/activity`.
            let segment_ok = |s: &str| {
                text::is_name(s)
                    || (!s.is_empty() && s.len() <= 10 && s.bytes().all(|b| b.is_ascii_digit()))
            };
            if !port.split('/').all(segment_ok) {
                problems.push(Problem {
                    span: c.span,
                    what: format!("`{}` is not a valid port name", text::comment(port)),
                });
            }
        }
        if let Some(link) = &c.link {
            let ends = (
                module_part.get(c.from.0.as_str()),
                module_part.get(c.to.0.as_str()),
            );
            let (Some(&writer), Some(&reader)) = ends else {
                continue; // an endpoint outside every part was reported above
            };
            if let Some(rust) = link.rust.as_deref().filter(|r| !text::is_rust_path(r)) {
                problems.push(Problem {
                    span: c.span,
                    what: format!(
                        "the type `{}` of this connection names the Rust type `{}`, which is not a Rust path (`crate_name::Type`)",
                        link.ty,
                        text::comment(rust)
                    ),
                });
            }
            // The writer's program converts, so it needs the field accessors.
            for f in super::fields::accessors(c, &parts[writer].modules, libs) {
                if let Err(at) = parts[writer].fields.binary_search(&f) {
                    parts[writer].fields.insert(at, f);
                }
            }
            for p in [writer, reader] {
                if let Some(name) = link.library.clone() {
                    if !parts[p].libraries.contains(&name) {
                        parts[p].libraries.push(name);
                    }
                }
            }
            parts[writer].links_out.push(c);
            parts[reader].links_in.push(c);
            continue;
        }
        let what = format!(
            "connection `{}/{}` → `{}/{}`",
            c.from.0, c.from.1, c.to.0, c.to.1
        );
        if let Some(p) = one_part(
            &module_part,
            &parts,
            (&c.from.0, &c.to.0),
            &what,
            c.span,
            &mut problems,
        ) {
            for f in super::fields::accessors(c, &parts[p].modules, libs) {
                if let Err(at) = parts[p].fields.binary_search(&f) {
                    parts[p].fields.insert(at, f);
                }
            }
            parts[p].connections.push(c);
        }
    }
    for link in &plan.param_links {
        if link.link.is_some() {
            let ends = (
                module_part.get(link.from.0.as_str()),
                module_part.get(link.to.0.as_str()),
            );
            if let (Some(&writer), Some(&reader)) = ends {
                parts[writer].param_links_out.push(link);
                parts[reader].param_links_in.push(link);
            }
            continue;
        }
        let what = format!(
            "parameter link `{}/{}` → `{}/param/{}`",
            link.from.0, link.from.1, link.to.0, link.to.1
        );
        let ends = (&link.from.0, &link.to.0);
        if let Some(p) = one_part(&module_part, &parts, ends, &what, link.span, &mut problems) {
            parts[p].param_links.push(link);
        }
    }
    for call in &plan.calls {
        if let Some(link) = &call.link {
            let ends = (
                module_part.get(call.client.0.as_str()),
                module_part.get(call.service.0.as_str()),
            );
            let (Some(&client), Some(&server)) = ends else {
                continue; // an endpoint outside every part was reported above
            };
            let rust = |t: &ferroc_compiler::types::Type| {
                super::fields::rust_type(libs, t).map(|(r, _)| r)
            };
            let types = link
                .response
                .as_ref()
                .and_then(|resp| Some((rust(&link.request)?, rust(resp)?)));
            let Some((request, response)) = types else {
                problems.push(Problem {
                    span: call.span,
                    what: format!(
                        "the call `{}/{}` → `{}/{}` crosses between parts, but its client declares no response type the generated code can name: add response=\"TYPE\" to the <client> in its manifest",
                        call.client.0, call.client.1, call.service.0, call.service.1
                    ),
                });
                continue;
            };
            for rust_path in [&request, &response] {
                if !text::is_rust_type(rust_path) {
                    problems.push(Problem {
                        span: call.span,
                        what: format!(
                            "the call's type `{}` is not a Rust type",
                            text::comment(rust_path)
                        ),
                    });
                }
            }
            for t in [Some(&link.request), link.response.as_ref()]
                .into_iter()
                .flatten()
            {
                if let ferroc_compiler::types::Type::Named(id, _) = t {
                    let name = libs.get(libs.named_type(*id).library).name.clone();
                    for p in [client, server] {
                        if !parts[p].libraries.contains(&name) {
                            parts[p].libraries.push(name.clone());
                        }
                    }
                }
            }
            for p in [client, server] {
                let pair = (request.clone(), response.clone());
                if !parts[p].call_types.contains(&pair) {
                    parts[p].call_types.push(pair);
                }
            }
            parts[client].calls_out.push(call);
            parts[server].calls_in.push(call);
            continue;
        }
        let what = format!(
            "call `{}/{}` → `{}/{}`",
            call.client.0, call.client.1, call.service.0, call.service.1
        );
        let ends = (&call.client.0, &call.service.0);
        if let Some(p) = one_part(&module_part, &parts, ends, &what, call.span, &mut problems) {
            parts[p].calls.push(call);
        }
    }
    for t in &plan.threads {
        match part_of(&t.path) {
            Some(p) => parts[p].threads.push(t),
            None => problems.push(Problem {
                span: root.span,
                what: format!("the thread container `{}` is not inside a part", t.path),
            }),
        }
    }
    if parts.is_empty() {
        problems.push(Problem {
            span: root.span,
            what: "the application has no part: nothing to bundle".into(),
        });
    }
    for part in &mut parts {
        part.recordable = super::record::outputs(app, libs, part);
    }
    let mut libraries = BTreeMap::new();
    for part in &mut parts {
        part.libraries.sort();
        for name in &part.libraries {
            if libraries.contains_key(name) {
                continue;
            }
            let Some(&id) = libs.by_name.get(name) else {
                continue;
            };
            let lib = libs.get(id);
            let Some(rust_crate) = lib.rust_crate.clone() else {
                problems.push(Problem {
                    span: lib.name_span,
                    what: format!("the library `{name}` has no `rust-crate`: the bundle cannot depend on its module types\n  help: add rust-crate=\"cargo-package-name\" to its <library>"),
                });
                continue;
            };
            let (package, registry) = match rust_crate.split_once('@') {
                Some((p, v)) => (p.to_owned(), Some(v.trim().to_owned())),
                None => (rust_crate, None),
            };
            if let Some(v) = registry
                .as_deref()
                .filter(|v| !crate::runner::crates::is_requirement(v))
            {
                problems.push(Problem {
                    span: lib.name_span,
                    what: format!(
                        "`{}` after the `@` of the rust-crate of library `{name}` is not a version\n  help: write e.g. rust-crate=\"{}@0.3\"",
                        text::comment(v),
                        text::comment(&package)
                    ),
                });
                continue;
            }
            if !text::is_crate_name(&package) {
                problems.push(Problem {
                    span: lib.name_span,
                    what: format!(
                        "the rust-crate `{}` of library `{name}` is not a Cargo package name",
                        text::comment(&package)
                    ),
                });
                continue;
            }
            let version = lib.version.clone().filter(|v| text::is_version(v));
            libraries.insert(
                name.clone(),
                Library {
                    name: name.clone(),
                    package,
                    version,
                    registry,
                    manifest: (!lib.path.as_os_str().is_empty()).then(|| lib.path.clone()),
                },
            );
        }
    }
    if problems.is_empty() {
        let mut periods: Vec<std::time::Duration> = plan
            .threads
            .iter()
            .filter_map(|t| t.period)
            .map(|p| std::time::Duration::from_secs_f64(p.clamp(0.0, 1e9)))
            .collect();
        periods.sort();
        periods.dedup();
        Ok(Layout {
            application,
            parts,
            periods,
            libraries,
        })
    } else {
        Err(problems)
    }
}

/// The part both modules of a connection are in, if they must share one; a problem
/// otherwise (every kind of link between parts is carried now: this is a guard).
fn one_part(
    module_part: &BTreeMap<&str, usize>,
    parts: &[Part<'_>],
    (a, b): (&String, &String),
    what: &str,
    span: Span,
    problems: &mut Vec<Problem>,
) -> Option<usize> {
    match (module_part.get(a.as_str()), module_part.get(b.as_str())) {
        (Some(&a), Some(&b)) if a == b => Some(a),
        (Some(&a), Some(&b)) => {
            problems.push(Problem {
                span,
                what: format!(
                    "the {what} joins the parts `{}` and `{}`: only data connections and calls cross between parts so far; move both ends into one part",
                    parts[a].name, parts[b].name
                ),
            });
            None
        }
        _ => None, // an endpoint outside every part was reported above
    }
}
