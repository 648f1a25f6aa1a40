//! The plan of a model split into parts (one program each), with the crates they need,
//! every name validated before anything is generated from it.

use ferroc_compiler::checks::deployment::x102_invalid_host_label::valid_host;
use ferroc_compiler::ir::{Application, ElementId, ElementKind, SharedMemory};
use ferroc_compiler::library::LibrarySet;
use ferroc_compiler::plan::{
    Plan, PlannedCall, PlannedConnection, PlannedModule, PlannedParamLink, PlannedThread, Ros2Node,
};
use ferroc_compiler::source::Span;
use std::collections::BTreeMap;

use super::text;

// The phases of `Split` by what they place: connections, parameter links and calls
// (`links.rs`), ROS 2 nodes (`ros2.rs`), the libraries' crates (`libraries.rs`).
mod libraries;
mod links;
pub mod recordable;
mod ros2;

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
    /// `<part shared-memory…>`: what its links to parts on the same computer use.
    pub shared_memory: SharedMemory,
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
    /// Rust types of the loaded library types mapped to a ROS 2 message of their own
    /// (`ros2=` on the `<type>`): they register with `register_ros2`, so a topic, a
    /// recording's ROS 2 channel or a replay of one (a Player's flexible port, whose
    /// module type names no type) writes and reads them through the mapping.
    pub ros2_mapped: Vec<String>,
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

    /// Whether its program serves inspection (`PROGRAM --inspect`, on Zenoh): always
    /// where it links Zenoh anyway (linked, or a ROS 2 node), else only when bundled
    /// with `--inspect` (`inspect_all`), so that a part talking to nobody links no Zenoh.
    pub fn is_inspected(&self, inspect_all: bool) -> bool {
        inspect_all || self.uses_zenoh()
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
        for (id, e) in app.elements.iter().enumerate() {
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
                shared_memory: (u32::try_from(id).ok())
                    .and_then(|id| app.shared_memory.get(&ElementId(id)).copied())
                    .unwrap_or_default(),
                ros2_mapped: (self.libs.types.iter())
                    .filter(|t| t.ros2.is_some() && super::text::is_rust_type(&t.rust))
                    .map(|t| t.rust.clone())
                    .collect(),
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
