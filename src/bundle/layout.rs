//! The plan of a model split into parts (one program each), with the crates they need,
//! every name validated before anything is generated from it.

use ferroc_compiler::checks::deployment::x102_invalid_host_label::valid_host;
use ferroc_compiler::ir::{Application, ElementKind};
use ferroc_compiler::library::module_type::PortType;
use ferroc_compiler::library::LibrarySet;
use ferroc_compiler::plan::{
    Plan, PlannedCall, PlannedConnection, PlannedModule, PlannedParamLink, PlannedThread, Ros2Node,
};
use ferroc_compiler::source::Span;
use ferroc_compiler::types::Type;
use std::collections::BTreeMap;
use std::path::PathBuf;

use super::text;

pub mod recordable;

/// One part: one program.
#[derive(Default)]
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
    /// The outputs `--record` records (`layout/recordable.rs`).
    pub recordable: Vec<recordable::RecordedOutput>,
    /// The unit of each port its modules connect, for recordings' channel metadata.
    pub units: Vec<(String, String)>,
    /// The part's ROS 2 node (`<ros2>`), which its program opens.
    pub ros2: Option<&'p Ros2Node>,
    /// Rust types of the library types its ROS 2 topics carry: their values reach a
    /// message through their serde form, so they register with it.
    pub ros2_serde: Vec<String>,
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

    /// Whether its program speaks Zenoh: to other parts, or as a ROS 2 node.
    pub fn uses_zenoh(&self) -> bool {
        self.is_linked() || self.ros2.is_some()
    }

    /// Adds the library `name` to those the part depends on, once.
    fn use_library(&mut self, name: &str) {
        if !self.libraries.iter().any(|l| l == name) {
            self.libraries.push(name.to_owned());
        }
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
    /// `<application seed>`: the run seed of a program started without `--seed`.
    pub seed: Option<u64>,
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
    let mut split = Split {
        app,
        libs,
        parts: Vec::new(),
        module_part: BTreeMap::new(),
        problems: Vec::new(),
    };
    split.check_application_name();
    split.add_parts();
    split.place_modules(&plan.modules);
    split.place_connections(&plan.connections);
    split.place_param_links(&plan.param_links);
    split.place_calls(&plan.calls);
    split.place_ros2(&plan.ros2, &plan.modules);
    split.place_threads(&plan.threads);
    if split.parts.is_empty() {
        split.problem(
            app.elements[0].span,
            "the application has no part: nothing to bundle".into(),
        );
    }
    for part in &mut split.parts {
        part.recordable = recordable::outputs(app, libs, part);
        // A recorded value of another library's type is registered with its serde form:
        // the part links that library's crate.
        let declaring: Vec<String> = (part.recordable.iter())
            .filter_map(|r| r.serde_library.clone())
            .collect();
        for name in &declaring {
            part.use_library(name);
        }
        part.units = recordable::units(&plan.units, part);
    }
    let libraries = split.libraries();
    let Split {
        parts, problems, ..
    } = split;
    if problems.is_empty() {
        Ok(Layout {
            application: app.name.clone(),
            seed: app.seed,
            parts,
            periods: periods(plan),
            libraries,
        })
    } else {
        Err(problems)
    }
}

/// The work of [`layout`]: the parts found so far, where each module went, and the
/// problems met, which every phase adds to.
struct Split<'a, 'p> {
    app: &'a Application,
    libs: &'a LibrarySet,
    parts: Vec<Part<'p>>,
    /// The part of every module placed, by path.
    module_part: BTreeMap<&'p str, usize>,
    problems: Vec<Problem>,
}

impl<'p> Split<'_, 'p> {
    fn problem(&mut self, span: Span, what: String) {
        self.problems.push(Problem { span, what });
    }

    /// The application's name names the programs: it must be a Rust identifier.
    fn check_application_name(&mut self) {
        let application = &self.app.name;
        if !text::is_rust_ident(application) {
            let what = format!("the application name `{application}` cannot name a program: use letters, digits and `_` (not a Rust keyword)");
            self.problem(self.app.span, what);
        }
    }

    /// A part for every `<part>` of the model, in model order, with its host, package
    /// and address.
    fn add_parts(&mut self) {
        let app = self.app;
        for e in &app.elements {
            let ElementKind::Part { host } = &e.kind else {
                continue;
            };
            let host = host
                .as_ref()
                .map_or_else(|| "localhost".to_string(), |(h, _)| h.clone());
            // The model's rule (check X102), which also keeps a launch script's file name
            // plain: no `/`, no `..`, no leading `-`.
            if valid_host(&host).is_err() {
                self.problem(e.span, format!("the host `{}` of part `{}` cannot name a launch script: use letters, digits and `-` in dot-separated labels", text::comment(&host), text::comment(&e.name)));
            }
            if !text::is_rust_ident(&e.name) {
                self.problem(e.name_span, format!("the part name `{}` cannot name a program: use letters, digits and `_` (not a Rust keyword)", text::comment(&e.name)));
            }
            let port = u16::try_from(self.parts.len())
                .ok()
                .and_then(|i| BASE_PORT.checked_add(i))
                .unwrap_or(0);
            self.parts.push(Part {
                package: format!("{}-{}", app.name, e.name),
                name: e.name.clone(),
                address: format!("{host}:{port}"),
                host,
                ..Part::default()
            });
        }
    }

    /// The part a path lies in: the part named by its first segment.
    fn part_of(&self, path: &str) -> Option<usize> {
        let first = path.split('/').next()?;
        self.parts.iter().position(|p| p.name == first)
    }

    /// Every module into its part, with the libraries and behaviour types it brings;
    /// its path and Rust types validated.
    fn place_modules(&mut self, modules: &'p [PlannedModule]) {
        let mut placed = Vec::new();
        for m in modules {
            self.check_module_names(m);
            let Some(p) = self.part_of(&m.path) else {
                self.problem(
                    m.span,
                    format!("the module `{}` is not inside a part", m.path),
                );
                continue;
            };
            self.module_part.insert(m.path.as_str(), p);
            placed.push((p, m));
        }
        for (p, m) in placed {
            let part = &mut self.parts[p];
            part.modules.push(m);
            if let Some((lib, ty)) = self.libs.module_type(&m.type_name) {
                if ty.is_behaviour() && !part.behaviours.contains(&m.rust.as_str()) {
                    part.behaviours.push(&m.rust);
                }
                part.use_library(&self.libs.get(lib).name);
            }
            // The crates of library value types on flexible ports.
            for name in m.ports.iter().filter_map(|g| g.library.as_ref()) {
                part.use_library(name);
            }
        }
    }

    /// A module's path segments are names; its type and its port groups' types name
    /// Rust paths.
    fn check_module_names(&mut self, m: &PlannedModule) {
        for segment in m.path.split('/') {
            if !text::is_name(segment) {
                self.problem(
                    m.span,
                    format!("`{}` is not a valid name", text::comment(segment)),
                );
            }
        }
        if !text::is_rust_path(&m.rust) {
            self.problem(
                m.span,
                format!(
                    "the module type `{}` names the Rust type `{}`, which is not a Rust path (`crate_name::Type`)",
                    m.type_name,
                    text::comment(&m.rust)
                ),
            );
        }
        for g in &m.ports {
            if let Some(rust) = g.rust.as_deref().filter(|r| !text::is_rust_path(r)) {
                self.problem(
                    m.span,
                    format!(
                        "the type `{}` of the port group `{}` names the Rust type `{}`, which is not a Rust path (`crate_name::Type`)",
                        g.ty,
                        text::comment(&g.name),
                        text::comment(rust)
                    ),
                );
            }
        }
    }

    /// Every connection into the part of its modules, or as a link out of the writer's
    /// part and into the reader's; the field accessors its conversion needs go to the
    /// part that converts (the writer's).
    fn place_connections(&mut self, connections: &'p [PlannedConnection]) {
        for c in connections {
            self.check_port_names(c);
            let Some(link) = &c.link else {
                let what = format!(
                    "connection `{}/{}` → `{}/{}`",
                    c.from.0, c.from.1, c.to.0, c.to.1
                );
                if let Some(p) = self.one_part((&c.from.0, &c.to.0), &what, c.span) {
                    self.add_fields(p, c);
                    self.parts[p].connections.push(c);
                }
                continue;
            };
            let ends = (
                self.module_part.get(c.from.0.as_str()),
                self.module_part.get(c.to.0.as_str()),
            );
            let (Some(&writer), Some(&reader)) = ends else {
                continue; // an endpoint outside every part was reported above
            };
            if let Some(rust) = link.rust.as_deref().filter(|r| !text::is_rust_path(r)) {
                self.problem(
                    c.span,
                    format!(
                        "the type `{}` of this connection names the Rust type `{}`, which is not a Rust path (`crate_name::Type`)",
                        link.ty,
                        text::comment(rust)
                    ),
                );
            }
            // The writer's program converts, so it needs the field accessors.
            self.add_fields(writer, c);
            if let Some(name) = &link.library {
                self.parts[writer].use_library(name);
                self.parts[reader].use_library(name);
            }
            self.parts[writer].links_out.push(c);
            self.parts[reader].links_in.push(c);
        }
    }

    /// Instance ports are paths of names and indices: `in/0`, `in/2/activity`.
    fn check_port_names(&mut self, c: &PlannedConnection) {
        for port in [&c.from.1, &c.to.1] {
            let segment_ok = |s: &str| {
                text::is_name(s)
                    || (!s.is_empty() && s.len() <= 10 && s.bytes().all(|b| b.is_ascii_digit()))
            };
            if !port.split('/').all(segment_ok) {
                self.problem(
                    c.span,
                    format!("`{}` is not a valid port name", text::comment(port)),
                );
            }
        }
    }

    /// The field accessors `c` needs, into part `p`'s sorted list, each once.
    fn add_fields(&mut self, p: usize, c: &PlannedConnection) {
        let part = &mut self.parts[p];
        for f in super::fields::accessors(c, &part.modules, self.libs) {
            if let Err(at) = part.fields.binary_search(&f) {
                part.fields.insert(at, f);
            }
        }
    }

    /// Every output → parameter connection into its part, or as a link between two.
    fn place_param_links(&mut self, links: &'p [PlannedParamLink]) {
        for link in links {
            if link.link.is_some() {
                let ends = (
                    self.module_part.get(link.from.0.as_str()),
                    self.module_part.get(link.to.0.as_str()),
                );
                if let (Some(&writer), Some(&reader)) = ends {
                    self.parts[writer].param_links_out.push(link);
                    self.parts[reader].param_links_in.push(link);
                }
                continue;
            }
            let what = format!(
                "parameter link `{}/{}` → `{}/param/{}`",
                link.from.0, link.from.1, link.to.0, link.to.1
            );
            if let Some(p) = self.one_part((&link.from.0, &link.to.0), &what, link.span) {
                self.parts[p].param_links.push(link);
            }
        }
    }

    /// Every client → service call into its part, or as a call between two, whose
    /// request and response types both programs then name.
    fn place_calls(&mut self, calls: &'p [PlannedCall]) {
        for call in calls {
            if call.link.is_some() {
                self.place_call_between_parts(call);
                continue;
            }
            let what = format!(
                "call `{}/{}` → `{}/{}`",
                call.client.0, call.client.1, call.service.0, call.service.1
            );
            let ends = (&call.client.0, &call.service.0);
            if let Some(p) = self.one_part(ends, &what, call.span) {
                self.parts[p].calls.push(call);
            }
        }
    }

    fn place_call_between_parts(&mut self, call: &'p PlannedCall) {
        let Some(link) = &call.link else {
            return;
        };
        let ends = (
            self.module_part.get(call.client.0.as_str()),
            self.module_part.get(call.service.0.as_str()),
        );
        let (Some(&client), Some(&server)) = ends else {
            return; // an endpoint outside every part was reported above
        };
        let libs = self.libs;
        let rust = |t: &Type| super::fields::rust_type(libs, t).map(|(r, _)| r);
        let types = link
            .response
            .as_ref()
            .and_then(|resp| Some((rust(&link.request)?, rust(resp)?)));
        let Some((request, response)) = types else {
            self.problem(
                call.span,
                format!(
                    "the call `{}/{}` → `{}/{}` crosses between parts, but its client declares no response type the generated code can name: add response=\"TYPE\" to the <client> in its manifest",
                    call.client.0, call.client.1, call.service.0, call.service.1
                ),
            );
            return;
        };
        for rust_path in [&request, &response] {
            if !text::is_rust_type(rust_path) {
                self.problem(
                    call.span,
                    format!(
                        "the call's type `{}` is not a Rust type",
                        text::comment(rust_path)
                    ),
                );
            }
        }
        for t in [Some(&link.request), link.response.as_ref()]
            .into_iter()
            .flatten()
        {
            if let Type::Named(id, _) = t {
                let name = &libs.get(libs.named_type(*id).library).name;
                for p in [client, server] {
                    self.parts[p].use_library(name);
                }
            }
        }
        for p in [client, server] {
            let pair = (request.clone(), response.clone());
            if !self.parts[p].call_types.contains(&pair) {
                self.parts[p].call_types.push(pair);
            }
        }
        self.parts[client].calls_out.push(call);
        self.parts[server].calls_in.push(call);
    }

    /// Each ROS 2 node into its part, which opens it; the services it offers are
    /// answered like calls from another part, so their request and response types are
    /// registered as calls (`register_call`).
    fn place_ros2(&mut self, nodes: &'p [Ros2Node], modules: &'p [PlannedModule]) {
        for node in nodes {
            let Some(p) = self.parts.iter().position(|x| x.name == node.part) else {
                continue;
            };
            self.parts[p].ros2 = Some(node);
            for t in &node.topics {
                let Some((rust, library)) = self.topic_type(modules, &t.port) else {
                    continue; // a built-in type, registered with its serde form already
                };
                let part = &mut self.parts[p];
                part.use_library(&library);
                if !part.ros2_serde.contains(&rust) {
                    part.ros2_serde.push(rust);
                }
            }
            for s in node.services.iter().chain(&node.clients) {
                let Some(module) = modules.iter().find(|m| m.path == s.port.0) else {
                    continue; // the plan reported it
                };
                match self.service_types(module, &s.port.1) {
                    Some(pair) if !self.parts[p].call_types.contains(&pair) => {
                        self.parts[p].call_types.push(pair);
                    }
                    Some(_) => {}
                    None => self.problem(
                        module.span,
                        format!(
                            "the service or client `{}` of `{}` is a ROS 2 service end, but \
                             the generated code cannot name its request and response types: \
                             declare both in its manifest as Rust-named types",
                            s.port.1, s.port.0
                        ),
                    ),
                }
            }
        }
    }

    /// The Rust type and library of the library type of a ROS 2 topic's port (module
    /// path, port name); `None` for a built-in type.
    fn topic_type(
        &self,
        modules: &[PlannedModule],
        port: &(String, String),
    ) -> Option<(String, String)> {
        let module = modules.iter().find(|m| m.path == port.0)?;
        let (_, ty) = self.libs.module_type(&module.type_name)?;
        let decl = ty.ports.iter().find(|d| d.name == port.1)?;
        let PortType::Fixed(t @ Type::Named(id, _)) = &decl.ty else {
            return None;
        };
        let (rust, _) = super::fields::rust_type(self.libs, t)?;
        let library = &self.libs.get(self.libs.named_type(*id).library).name;
        text::is_rust_type(&rust).then(|| (rust, library.clone()))
    }

    /// The Rust request and response types of the service or client `name` of `module`.
    fn service_types(&self, module: &PlannedModule, name: &str) -> Option<(String, String)> {
        let (_, ty) = self.libs.module_type(&module.type_name)?;
        let services = ty.services.iter().map(|d| (&d.name, d.port, &d.response));
        let clients = ty.clients.iter().map(|d| (&d.name, d.port, &d.response));
        let (_, port, response) = services.chain(clients).find(|(n, _, _)| *n == name)?;
        let PortType::Fixed(request) = &ty.ports.get(port)?.ty else {
            return None;
        };
        let rust = |t: &Type| super::fields::rust_type(self.libs, t).map(|(r, _)| r);
        let pair = (rust(request)?, rust(response.as_ref()?)?);
        [&pair.0, &pair.1]
            .iter()
            .all(|t| text::is_rust_type(t))
            .then_some(pair)
    }

    /// Every thread container into its part.
    fn place_threads(&mut self, threads: &'p [PlannedThread]) {
        for t in threads {
            match self.part_of(&t.path) {
                Some(p) => self.parts[p].threads.push(t),
                None => self.problem(
                    self.app.elements[0].span,
                    format!("the thread container `{}` is not inside a part", t.path),
                ),
            }
        }
    }

    /// The part both modules of a connection are in, if they must share one; a problem
    /// otherwise (every kind of link between parts is carried now: this is a guard).
    fn one_part(&mut self, (a, b): (&String, &String), what: &str, span: Span) -> Option<usize> {
        match (
            self.module_part.get(a.as_str()),
            self.module_part.get(b.as_str()),
        ) {
            (Some(&a), Some(&b)) if a == b => Some(a),
            (Some(&a), Some(&b)) => {
                let what = format!(
                    "the {what} joins the parts `{}` and `{}`: only data connections and calls cross between parts so far; move both ends into one part",
                    self.parts[a].name, self.parts[b].name
                );
                self.problem(span, what);
                None
            }
            _ => None, // an endpoint outside every part was reported above
        }
    }

    /// The libraries the parts use, by name, each with its Cargo package; every part's
    /// list sorted.
    fn libraries(&mut self) -> BTreeMap<String, Library> {
        let mut libraries = BTreeMap::new();
        let mut parts = std::mem::take(&mut self.parts);
        for part in &mut parts {
            part.libraries.sort();
            for name in &part.libraries {
                if libraries.contains_key(name) {
                    continue;
                }
                if let Some(library) = self.library(name) {
                    libraries.insert(name.clone(), library);
                }
            }
        }
        self.parts = parts;
        libraries
    }

    /// The library `name` as a dependency: its `rust-crate` a Cargo package, maybe
    /// with a registry version. `None` for a library the set does not hold, and for
    /// one whose crate cannot be named (a problem).
    fn library(&mut self, name: &str) -> Option<Library> {
        let &id = self.libs.by_name.get(name)?;
        let lib = self.libs.get(id);
        let Some(rust_crate) = lib.rust_crate.clone() else {
            self.problem(lib.name_span, format!("the library `{name}` has no `rust-crate`: the bundle cannot depend on its module types\n  help: add rust-crate=\"cargo-package-name\" to its <library>"));
            return None;
        };
        let (package, registry) = match rust_crate.split_once('@') {
            Some((p, v)) => (p.to_owned(), Some(v.trim().to_owned())),
            None => (rust_crate, None),
        };
        if let Some(v) = registry
            .as_deref()
            .filter(|v| !crate::runner::crates::is_requirement(v))
        {
            self.problem(
                lib.name_span,
                format!(
                    "`{}` after the `@` of the rust-crate of library `{name}` is not a version\n  help: write e.g. rust-crate=\"{}@0.3\"",
                    text::comment(v),
                    text::comment(&package)
                ),
            );
            return None;
        }
        if !text::is_crate_name(&package) {
            self.problem(
                lib.name_span,
                format!(
                    "the rust-crate `{}` of library `{name}` is not a Cargo package name",
                    text::comment(&package)
                ),
            );
            return None;
        }
        Some(Library {
            name: name.to_owned(),
            package,
            version: lib.version.clone().filter(|v| text::is_version(v)),
            registry,
            manifest: (!lib.path.as_os_str().is_empty()).then(|| lib.path.clone()),
        })
    }
}

/// The periods of every periodic thread container, sorted, each once.
fn periods(plan: &Plan) -> Vec<std::time::Duration> {
    let mut periods: Vec<std::time::Duration> = plan
        .threads
        .iter()
        .filter_map(|t| t.period)
        .map(|p| std::time::Duration::from_secs_f64(p.clamp(0.0, 1e9)))
        .collect();
    periods.sort();
    periods.dedup();
    periods
}
