//! The run plan: a checked model reduced to what a runtime needs to build it.
//!
//! `ferroc run` turns the plan into runtime `Builder` calls, and `ferroc bundle` writes
//! the same calls as Rust source, so both start the same application. The plan has
//! module instances with parsed parameter values, module-to-module connections with
//! group ports flattened away and unit scales folded into one conversion, and each
//! thread container's step order from the scheduling pass.

mod links;
mod local;
mod params;
mod ports;
mod ros2;
mod threads;

pub use ferroc_model::ir::Wait;
pub use ferroc_ros2_node::{Ros2Interface, Ros2Node, Ros2Qos, Ros2Service, Ros2Topic};
pub use links::{LinkSharing, PlannedCallLink, PlannedLink};

use ferroc_diagnostics::source::Span;
use ferroc_model::ir::{Application, ElementId, ModuleInstance, ParamSource, PortView};
use ferroc_model::library::{LibrarySet, ModuleType, PortDir, PortRole};
use ferroc_schedule::{call_edges, data_edges, DataEdge, StepKind};
use ferroc_values::units::{relate, Unit, UnitRelation};
use ferroc_values::values::{parse_value, Value, ValueError};

/// One module instance.
#[derive(Clone, Debug)]
pub struct PlannedModule {
    pub element: ElementId,
    /// Element path, unique in the application (`robot/control/controller`).
    pub path: String,
    /// Qualified type name (`crash_course.Controller`).
    pub type_name: String,
    /// Rust path of the implementing type, from the manifest.
    pub rust: String,
    /// Values the model gives, parsed and converted into the declared unit.
    pub params: Vec<(String, Value)>,
    /// Inputs connected with `queue=N`: port, capacity, `on-full` policy.
    pub queues: Vec<(String, u32, String)>,
    /// The instance's flexible port groups (`<port name dir type count>`), in model
    /// order; empty for module types with a fixed interface.
    pub ports: Vec<PlannedPortGroup>,
    /// What a behaviour does on an iB2C principle violation (`warn`, `clamp`, `stop`):
    /// the module's `ib2c-violations`, else the application's, else `warn`.
    pub ib2c_violations: String,
    pub span: Span,
}

/// One `<port name dir type count>` of a flexible module instance: the runtime creates
/// its ports (`name/0` … or just `name`) from the value type the model names.
#[derive(Clone, Debug, PartialEq)]
pub struct PlannedPortGroup {
    pub name: String,
    pub dir: PortDir,
    /// The model type (`f64`, `warehouse.RobotStatus`): the runtime's value-table key.
    pub ty: String,
    /// `None`: the single port `name`; `Some(n)`: `name/0` … `name/{n-1}`.
    pub count: Option<u32>,
    /// The declared unit, as written (`mm/s`).
    pub unit: Option<String>,
    /// For a library type: its library and Rust path (a bundle registers the type).
    pub library: Option<String>,
    pub rust: Option<String>,
    /// For a library type: declared `serde="true"` (a bundle registers it with serde, so
    /// that recording, replaying and constant modules can encode its values).
    pub serde: bool,
}

/// One module output feeding one module input.
#[derive(Clone, Debug)]
pub struct PlannedConnection {
    pub from: (String, String),
    pub to: (String, String),
    /// Parts taken out of each value first, outermost first (`port[i]`,
    /// `<convert field|index>`).
    pub select: Vec<Part>,
    /// Then `to = part · scale + offset` (unit scales and `<convert>` steps combined).
    pub scale: f64,
    pub offset: f64,
    /// Set when the connection joins two parts: it travels as a link.
    pub link: Option<PlannedLink>,
    /// The writer and the reader run in one thread container: the runtime keeps the
    /// value in a cell only that container's thread touches (`ConnectOptions::local`).
    pub local: bool,
    pub span: Span,
}

/// One step into a value on a connection.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum Part {
    /// A struct field (`<convert field="linear"/>`).
    Field(String),
    /// A list or array element (`<convert index="2"/>`, `from="scanner/ranges[2]"`).
    Index(u32),
}

/// A client calling a service (`<connect from="…/client" to="…/service"/>`).
#[derive(Clone, Debug)]
pub struct PlannedCall {
    /// Module path and client name.
    pub client: (String, String),
    /// Module path and service name.
    pub service: (String, String),
    /// Set when the client and the service are in different parts.
    pub link: Option<PlannedCallLink>,
    pub span: Span,
}

/// A module output setting a module parameter while running
/// (`<connect from="…/max_speed" to="…/param/max_speed"/>`).
#[derive(Clone, Debug)]
pub struct PlannedParamLink {
    /// Module path and output name.
    pub from: (String, String),
    /// Module path and parameter name.
    pub to: (String, String),
    /// Unit scale from the port's unit to the parameter's.
    pub scale: f64,
    /// Set when the output and the parameter are in different parts (numbered after
    /// the data links).
    pub link: Option<PlannedLink>,
    pub span: Span,
}

/// One thread container.
#[derive(Clone, Debug)]
pub struct PlannedThread {
    pub path: String,
    /// Seconds; `None` for data-triggered and continuous containers.
    pub period: Option<f64>,
    /// Cycles back to back (`trigger="continuous"`).
    pub continuous: bool,
    /// How a data-triggered container waits for data (`wait=`).
    pub wait: Wait,
    /// `priority=`: higher runs first (the runtime asks the OS for it).
    pub priority: Option<u32>,
    /// `cpu=`: the core the thread is pinned to.
    pub cpu: Option<u32>,
    /// Module path and step, in execution order.
    pub steps: Vec<(String, StepKind)>,
}

/// Everything needed to build the application.
#[derive(Clone, Debug, Default)]
pub struct Plan {
    pub modules: Vec<PlannedModule>,
    pub connections: Vec<PlannedConnection>,
    pub calls: Vec<PlannedCall>,
    pub param_links: Vec<PlannedParamLink>,
    pub threads: Vec<PlannedThread>,
    pub locks: PlannedLocks,
    /// The unit of the values at each connected module port (`robot/log/in/0` →
    /// `m/s`), as the model writes it, sorted by port: an output's declared unit, an
    /// input's own unit else the unit of what feeds it (a selected field's). Ports
    /// without a unit are left out. Recordings name the unit of every channel with it.
    pub units: Vec<(String, String)>,
    /// The parts that are ROS 2 nodes, with their topics (`<ros2>`, docs/ros2.md).
    pub ros2: Vec<Ros2Node>,
}

/// Application resources, the model's lock-slot bindings, and the nesting orders the
/// module types declare, translated to resource names (the runtime validates every
/// acquisition against them).
#[derive(Clone, Debug, Default)]
pub struct PlannedLocks {
    /// `<resource>`s: name, level, recursive.
    pub resources: Vec<(String, Option<u32>, bool)>,
    /// `<bind lock resource>`: module path, slot, resource.
    pub binds: Vec<(String, String, String)>,
    /// Resource `first` is taken before `second`; the text says who declares it.
    pub orders: Vec<(String, String, String)>,
}

/// Something a checked model uses that the runtime cannot realise yet.
#[derive(Clone, Debug)]
pub struct Unsupported {
    pub what: String,
    pub span: Span,
}

/// Builds the plan of a model that checked without errors. `cmdline` holds values
/// given at start-up (`--param name=value`) for parameters declared `cmdline=`.
/// The plan is complete only when the list of unsupported things is empty.
pub fn plan(
    app: &Application,
    libs: &LibrarySet,
    cmdline: &[(String, String)],
) -> (Plan, Vec<Unsupported>) {
    let mut planner = Planner {
        app,
        libs,
        cmdline,
        paths: vec![String::new(); app.elements.len()],
        plan: Plan::default(),
        problems: Vec::new(),
    };
    planner.plan_modules();
    planner.plan_edges();
    let Planner {
        paths,
        mut plan,
        mut problems,
        ..
    } = planner;
    params::plan_param_links(app, libs, &paths, &mut plan, &mut problems);
    plan.threads = threads::plan_threads(app, libs, &paths);
    local::mark_local(&mut plan);
    plan.locks = threads::plan_locks(app, libs, &paths);
    plan.ros2 = ros2::plan_ros2(app, libs, &mut problems);
    (plan, problems)
}

/// The plan under construction with what its phases share: the element paths (filled
/// by [`Planner::plan_modules`]) and the problems found so far.
struct Planner<'a> {
    app: &'a Application,
    libs: &'a LibrarySet,
    cmdline: &'a [(String, String)],
    paths: Vec<String>,
    plan: Plan,
    problems: Vec<Unsupported>,
}

impl Planner<'_> {
    /// One [`PlannedModule`] per module instance, with its parameter values; fills the
    /// element paths of the modules.
    fn plan_modules(&mut self) {
        let (app, libs) = (self.app, self.libs);
        for (id, m) in app.modules() {
            let ty = &libs.get(m.library).module_types[m.type_index];
            self.paths[id.0 as usize] = app.path(id);
            let params = self.module_params(id, m, ty);
            self.plan.modules.push(PlannedModule {
                element: id,
                path: self.paths[id.0 as usize].clone(),
                type_name: ty.qualified.clone(),
                rust: ty.rust.clone(),
                params,
                queues: Vec::new(),
                ports: ports::port_groups(libs, ty, &m.extra_ports),
                ib2c_violations: m
                    .ib2c_violations()
                    .or(app.ib2c_violations.as_deref())
                    .unwrap_or("warn")
                    .to_string(),
                span: app.element(id).span,
            });
        }
    }

    /// The parsed values of a module's parameters, a command-line value overriding the
    /// inline or config one; a value that is missing or does not parse is a problem.
    fn module_params(
        &mut self,
        id: ElementId,
        m: &ModuleInstance,
        ty: &ModuleType,
    ) -> Vec<(String, Value)> {
        let mut params = Vec::new();
        for p in &m.params {
            let Some(decl) = ty.param(&p.name) else {
                continue;
            };
            // A command-line value overrides the inline or config value (as in FINROC).
            let given = p.from_cmdline(self.cmdline);
            let text = match (given, &p.source) {
                (Some(v), _) => v.to_string(),
                (None, ParamSource::Cmdline) => {
                    let flag = p.cmdline.as_ref().map_or(p.name.as_str(), |(n, _)| n);
                    self.problems.push(Unsupported {
                        what: format!(
                            "the parameter `{}` of `{}` is given on the command line: pass it with --param {flag}=VALUE",
                            p.name, self.paths[id.0 as usize],
                        ),
                        span: p.span,
                    });
                    continue;
                }
                (None, _) => p.text.clone(),
            };
            match (
                parse_value(&text, &decl.ty, decl.unit.as_ref()),
                given,
                &p.cmdline,
            ) {
                (Ok(v), ..) => params.push((p.name.clone(), v)),
                // Blame the command line, at the declaration that accepts it (not the
                // inline or config value it replaced).
                (Err(e), Some(v), Some((flag, flag_span))) => self.problems.push(Unsupported {
                    what: format!(
                        "--param {flag}={v}: not a value of the parameter `{}` of `{}`: {}",
                        p.name,
                        self.paths[id.0 as usize],
                        match e {
                            ValueError::Syntax(why) | ValueError::WrongDimension(why) => why,
                        }
                    ),
                    span: *flag_span,
                }),
                // The checker reported it already (P103/P105); nothing to run.
                (Err(_), ..) => self.problems.push(Unsupported {
                    what: format!("the value of `{}` does not parse", p.name),
                    span: p.span,
                }),
            }
        }
        params
    }

    /// One call per client-to-service edge and one connection per data edge between
    /// modules.
    fn plan_edges(&mut self) {
        let module_index: hashbrown::HashMap<ElementId, usize> = self
            .plan
            .modules
            .iter()
            .enumerate()
            .map(|(i, m)| (m.element, i))
            .collect();
        for (edge, from, to) in module_edges(self.app, self.libs) {
            if from.role == PortRole::Client {
                self.plan_call(&module_index, &edge, &from, &to);
            } else {
                self.plan_connection(&module_index, &edge, &from, &to);
            }
        }
    }

    /// The span a planned edge is reported at: its last connection, else the module.
    fn edge_span(&self, edge: &DataEdge) -> Span {
        edge.hops
            .last()
            .map_or(self.app.element(edge.to_module).span, |&h| {
                self.app.connections[h].span
            })
    }

    /// The module path and port name of one end of an edge.
    fn end(&self, module: ElementId, port: &PortView) -> (String, String) {
        (self.paths[module.0 as usize].clone(), port.name.to_string())
    }

    /// Notes the unit of the port `(module, port)` in [`Plan::units`].
    fn note_unit(&mut self, (module, port): &(String, String), unit: Option<&Unit>) {
        let Some(unit) = unit.filter(|u| !u.text.is_empty()) else {
            return;
        };
        let path = format!("{module}/{port}");
        if let Err(at) = self.plan.units.binary_search_by(|(p, _)| p.cmp(&path)) {
            self.plan.units.insert(at, (path, unit.text.clone()));
        }
    }

    /// A client calling a service, with its link when the call crosses parts.
    fn plan_call(
        &mut self,
        module_index: &hashbrown::HashMap<ElementId, usize>,
        edge: &DataEdge,
        from: &PortView,
        to: &PortView,
    ) {
        let response = self
            .libs
            .module_type(&self.plan.modules[module_index[&edge.from_module]].type_name)
            .and_then(|(_, ty)| ty.clients.iter().find(|c| c.name == from.name))
            .and_then(|c| c.response.clone());
        let id = self.plan.calls.iter().filter(|c| c.link.is_some()).count() as u32;
        let link = links::call_link_of(self.app, edge, from.ty, response, id);
        self.plan.calls.push(PlannedCall {
            link,
            client: self.end(edge.from_module, from),
            service: self.end(edge.to_module, to),
            span: self.edge_span(edge),
        });
    }

    /// A data connection: the element or field it selects, its unit conversion folded
    /// into one scale and offset, and the queue its connections give the input.
    fn plan_connection(
        &mut self,
        module_index: &hashbrown::HashMap<ElementId, usize>,
        edge: &DataEdge,
        from: &PortView,
        to: &PortView,
    ) {
        let app = self.app;
        // A field carries its own unit: the scale is computed from the field's.
        let (mut ty, mut from_unit) = (from.ty, from.unit);
        for &hop in &edge.hops {
            for step in &app.connections[hop].converts {
                if let Some((field, _)) = &step.field {
                    if let Some((t, u)) = self.libs.field_of(ty, field) {
                        (ty, from_unit) = (t, u);
                    }
                }
            }
        }
        let mut scale = unit_scale(from_unit, to.unit);
        let mut offset = 0.0;
        let mut select = Vec::new();
        for &hop in &edge.hops {
            let c = &app.connections[hop];
            if let Some(i) = c.from_index {
                select.push(Part::Index(i));
            }
            if c.to_index.is_some() {
                self.problems.push(Unsupported {
                    what: "writing into one element of an input (`to=\"port[i]\"`) is not supported by the runtime yet; \
                           connect to a module that assembles the list instead"
                        .into(),
                    span: c.to_span,
                });
            }
            for step in &c.converts {
                if let Some((i, _)) = step.index {
                    select.push(Part::Index(i));
                }
                if let Some((f, _)) = &step.field {
                    select.push(Part::Field(f.clone()));
                }
                if let Some((s, _)) = step.scale {
                    scale *= s;
                    offset *= s;
                }
                if let Some((o, _)) = step.offset {
                    offset += o;
                }
            }
            if let Some(q) = c.queue {
                let module = &mut self.plan.modules[module_index[&edge.to_module]];
                if !module.queues.iter().any(|(p, ..)| p == to.name) {
                    let policy = c.on_full_policy().to_string();
                    module.queues.push((to.name.to_string(), q, policy));
                }
            }
        }
        let next_link = self
            .plan
            .connections
            .iter()
            .filter(|c| c.link.is_some())
            .count() as u32;
        let (from_end, to_end) = (
            self.end(edge.from_module, from),
            self.end(edge.to_module, to),
        );
        self.note_unit(&from_end, from.unit);
        self.note_unit(&to_end, to.unit.or(from_unit));
        self.plan.connections.push(PlannedConnection {
            from: from_end,
            to: to_end,
            select,
            scale,
            offset,
            link: links::link_of(app, self.libs, edge, to.ty, next_link),
            local: false,
            span: self.edge_span(edge),
        });
    }
}

/// Every edge from a module output to a module input (group ports flattened), with
/// the views of both ends: what becomes one runtime connection (a data connection, or
/// a client calling a service). The plan and the bundle's resolved model both list
/// connections this way.
pub fn module_edges<'a>(
    app: &'a Application,
    libs: &'a LibrarySet,
) -> impl Iterator<Item = (DataEdge, PortView<'a>, PortView<'a>)> + 'a {
    let edges = data_edges(app, libs)
        .into_iter()
        .chain(call_edges(app, libs));
    edges.filter_map(move |edge| {
        let (&first, &last) = (edge.hops.first()?, edge.hops.last()?);
        let from = app.view(libs, app.connections[first].from)?;
        let to = app.view(libs, app.connections[last].to)?;
        (from.dir == PortDir::Out && to.dir == PortDir::In).then_some((edge, from, to))
    })
}

/// The factor from values in unit `from` to unit `to` (1 unless both are given and
/// differ by a scale; other mismatches are the checker's T10x findings).
fn unit_scale(from: Option<&Unit>, to: Option<&Unit>) -> f64 {
    match (from, to) {
        (Some(a), Some(b)) => match relate(a, b) {
            UnitRelation::Scaled(f) => f,
            _ => 1.0,
        },
        _ => 1.0,
    }
}
