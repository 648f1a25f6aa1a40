//! Looking into a running application: the element tree, each port's latest value on
//! request, parameters (with type, unit and range, and checked changes), the thread
//! containers' figures, the state of links from other parts and the iB2C activities.
//!
//! [`Builder::inspection`](crate::builder::Builder::inspection) hands over what the
//! [`Inspector`] needs right before the application starts; the inspector then answers
//! from any thread. It costs nothing while nobody asks: figures are the containers'
//! own atomics, and a port's value is read by connecting a probe for the moment of
//! the read (`probe.rs`). The network side (Zenoh keys, authentication) is the crate
//! `ferroc-inspect`; this module only knows the application.

mod probe;
pub mod ros2;
#[cfg(test)]
mod tests;
mod transport;
pub mod view;

use ferroc_exec::ContainerStats;
use ferroc_module::{Interface, ParamHandle, Role, Timestamp, Value, ValueTable};
use ferroc_ports::fresh::Source;
use ferroc_ports::port::OutputHandle;
use std::collections::{BTreeSet, HashMap};
use std::sync::Arc;
use view::*;

/// What the builder hands over (see [`Builder::inspection`](crate::builder::Builder::inspection)).
pub struct Catalogue {
    pub(crate) modules: Vec<ModuleEntry>,
    /// Container path and the modules it executes, in step order.
    pub(crate) threads: Vec<(String, Vec<String>)>,
    /// The ROS 2 nodes of the application's parts (their ends name modules' ports).
    pub(crate) ros2: Vec<ferroc_link::ros2::Ros2Node>,
    /// Where the application's links go: its network says how their values travel.
    pub(crate) hub: Option<Arc<ferroc_link::Hub>>,
}

pub(crate) struct ModuleEntry {
    pub path: String,
    pub interface: Interface,
    pub thread: Option<String>,
    pub outputs: Vec<(String, Arc<OutputHandle>)>,
    pub inputs: Vec<(String, std::sync::Arc<Source>)>,
    pub params: Vec<(String, Arc<ParamHandle>)>,
}

/// Where a module comes from, as the runner knows it (the runtime does not read
/// models).
#[derive(Clone, Debug, Default)]
pub struct Origin {
    /// The part (process) of the module.
    pub part: String,
    /// `FILE:LINE:COL` of its declaration.
    pub source: Option<String>,
}

/// Answers questions about one running application; see the [module docs](self).
/// What it knows of the structure can be replaced while it serves
/// ([`rebuild`](Self::rebuild), after a structural change).
pub struct Inspector {
    state: std::sync::RwLock<State>,
}

struct State {
    modules: Vec<ModuleEntry>,
    index: HashMap<String, usize>,
    threads: Vec<(String, Vec<String>)>,
    stats: Vec<Arc<ContainerStats>>,
    values: ValueTable,
    origins: HashMap<String, Origin>,
    /// Reader (`module/input`) → writers (`module/output`).
    sources: HashMap<String, Vec<String>>,
    /// Every part this inspector has served. An edit may remove a part's last module;
    /// the part still runs (its containers cycle), and it must stay inspectable, or
    /// its model could be neither saved nor edited back.
    served: BTreeSet<String>,
    /// The ROS 2 ends of each module (by path). They are fixed for the run: an edit
    /// that would change them is refused, so [`Inspector::rebuild`] keeps them.
    ros2: HashMap<String, Vec<Ros2View>>,
    /// The links' hub, for [`Inspector::transport`] (kept by [`Inspector::rebuild`]:
    /// the network does not change while the application runs).
    hub: Option<Arc<ferroc_link::Hub>>,
}

impl Inspector {
    /// An inspector of the application `catalogue` describes, whose containers have
    /// the statistics `stats` ([`RunningApp::stats`](crate::builder::RunningApp::stats)),
    /// reading values through `values` (the registry's value table).
    pub fn new(catalogue: Catalogue, stats: Vec<Arc<ContainerStats>>, values: &ValueTable) -> Self {
        let index = (catalogue.modules.iter().enumerate())
            .map(|(i, m)| (m.path.clone(), i))
            .collect();
        let mut state = State {
            modules: catalogue.modules,
            index,
            threads: catalogue.threads,
            stats,
            values: values.clone(),
            origins: HashMap::new(),
            sources: HashMap::new(),
            served: BTreeSet::new(),
            ros2: ros2::by_module(&catalogue.ros2),
            hub: catalogue.hub,
        };
        state.served = state.parts();
        Inspector {
            state: std::sync::RwLock::new(state),
        }
    }

    fn read(&self) -> std::sync::RwLockReadGuard<'_, State> {
        self.state.read().unwrap_or_else(|e| e.into_inner())
    }

    fn write(&self) -> std::sync::RwLockWriteGuard<'_, State> {
        self.state.write().unwrap_or_else(|e| e.into_inner())
    }

    /// Replaces what it knows of the structure with `catalogue` (after a structural
    /// change); origins and connections are forgotten, to be recorded again. The ROS 2
    /// ends stay (a running node's do not change).
    pub fn rebuild(&self, catalogue: Catalogue) {
        let mut state = self.write();
        let before = state.parts();
        state.served.extend(before);
        state.index = (catalogue.modules.iter().enumerate())
            .map(|(i, m)| (m.path.clone(), i))
            .collect();
        state.modules = catalogue.modules;
        state.threads = catalogue.threads;
        if catalogue.hub.is_some() {
            state.hub = catalogue.hub;
        }
        state.origins.clear();
        state.sources.clear();
    }

    /// Records where the module `path` comes from.
    pub fn set_origin(&self, path: &str, origin: Origin) {
        self.write().origins.insert(path.to_owned(), origin);
    }

    /// Records a connection (module path, port) → (module path, port), so an input
    /// names what feeds it and shows its writer's value.
    pub fn add_connection(&self, from: (&str, &str), to: (&str, &str)) {
        self.write().add_connection(from, to);
    }

    /// The parts whose modules this inspector sees.
    pub fn parts(&self) -> BTreeSet<String> {
        self.read().parts()
    }

    /// The element tree (of one part, or of all with `None`).
    pub fn tree(&self, part: Option<&str>) -> Tree {
        self.read().tree(part)
    }

    /// Splits `module/path/port` at its last `/` into a module this inspector knows
    /// and the rest.
    pub fn split<'p>(&self, path: &'p str) -> Result<(&'p str, &'p str), String> {
        self.read().split(path)
    }

    /// The latest value of the port `port` of `module`: an output's own, an input's
    /// writer's (the input holds what its writer published last).
    pub fn value(&self, module: &str, port: &str) -> Result<PortValue, String> {
        self.read().value(module, port)
    }

    /// A parameter with its declaration and current value.
    pub fn param(&self, module: &str, name: &str) -> Result<ParamView, String> {
        self.read().param(module, name)
    }

    /// Sets a parameter: the parameter's own checks (type, range, choices) run first,
    /// and a refused value leaves the old one in place. `value` is already in the
    /// parameter's unit (the caller converts; see `ferroc-inspect`).
    pub fn set_param(&self, module: &str, name: &str, value: &Value) -> Result<ParamView, String> {
        self.read().set_param(module, name, value)
    }

    /// The figures of the thread containers (of one part, or all).
    pub fn containers(&self, part: Option<&str>) -> Vec<ContainerView> {
        self.read().containers(part)
    }

    /// The state of every input fed by a link from another part.
    pub fn links(&self, part: Option<&str>) -> Vec<LinkView> {
        self.read().links(part)
    }

    /// The activity and target rating of every behaviour (of one part, or all).
    pub fn activities(&self, part: Option<&str>) -> Vec<ActivityView> {
        self.read().activities(part)
    }

    /// How the values of the links the part sends to other parts travel (of one part,
    /// or all), and the shared-memory pool (running freely; nothing in lockstep).
    pub fn transport(&self, part: Option<&str>) -> TransportView {
        let state = self.read();
        let Some(hub) = &state.hub else {
            return TransportView::default();
        };
        let used = hub.transport();
        let links: Vec<LinkTransportView> = (used.links.into_iter())
            .filter(|l| state.in_part(&l.topic, part))
            .map(transport::link_view)
            .collect();
        TransportView {
            pool: used.pool.map(transport::pool_view),
            links,
        }
    }
}

impl State {
    fn add_connection(&mut self, from: (&str, &str), to: (&str, &str)) {
        let writers = self
            .sources
            .entry(format!("{}/{}", to.0, to.1))
            .or_default();
        let writer = format!("{}/{}", from.0, from.1);
        if !writers.contains(&writer) {
            writers.push(writer);
        }
    }

    /// The part of a module: as recorded, else its path's first element.
    fn part_of(&self, path: &str) -> String {
        match self.origins.get(path) {
            Some(o) if !o.part.is_empty() => o.part.clone(),
            _ => path.split('/').next().unwrap_or_default().to_owned(),
        }
    }

    /// The parts whose modules or containers this inspector sees, and every part it
    /// served before (a part whose last module an edit removed still runs).
    fn parts(&self) -> BTreeSet<String> {
        let modules = self.modules.iter().map(|m| self.part_of(&m.path));
        let containers = (self.threads.iter()).map(|(t, _)| self.part_of(t));
        let mut parts: BTreeSet<String> = modules.chain(containers).collect();
        parts.extend(self.served.iter().cloned());
        parts
    }

    /// Whether the container `path` (executing `modules`) belongs to `part`: its
    /// first module's part, or, with none, the part its path starts with.
    fn container_in_part(&self, path: &str, modules: &[String], part: Option<&str>) -> bool {
        self.in_part(modules.first().map_or(path, String::as_str), part)
    }

    fn in_part(&self, path: &str, part: Option<&str>) -> bool {
        part.is_none_or(|p| self.part_of(path) == p)
    }

    /// The element tree (of one part, or of all with `None`).
    fn tree(&self, part: Option<&str>) -> Tree {
        let modules = (self.modules.iter())
            .filter(|m| self.in_part(&m.path, part))
            .map(|m| self.module_view(m))
            .collect();
        let containers = (self.threads.iter())
            .filter(|(path, ms)| self.container_in_part(path, ms, part))
            .map(|(path, modules)| ContainerTree {
                path: path.clone(),
                modules: modules.clone(),
            })
            .collect();
        Tree {
            modules,
            containers,
        }
    }

    fn module_view(&self, m: &ModuleEntry) -> ModuleView {
        let ports = (m.interface.ports.iter())
            .map(|p| PortView {
                name: p.name.clone(),
                dir: match p.dir {
                    ferroc_module::Direction::In => "in".into(),
                    ferroc_module::Direction::Out => "out".into(),
                },
                r#type: p.model_type.clone(),
                unit: p.unit.clone(),
                meta: p.role == Role::Meta,
                from: (self.sources.get(&format!("{}/{}", m.path, p.name)))
                    .cloned()
                    .unwrap_or_default(),
            })
            .collect();
        let params = (m.params.iter())
            .filter_map(|(name, _)| self.param_view(m, name).ok())
            .collect();
        ModuleView {
            path: m.path.clone(),
            r#type: m.interface.name.clone(),
            kind: m.interface.kind.as_str().into(),
            part: self.part_of(&m.path),
            source: self.origins.get(&m.path).and_then(|o| o.source.clone()),
            container: m.thread.clone(),
            ports,
            params,
            ros2: self.ros2.get(&m.path).cloned().unwrap_or_default(),
        }
    }

    fn entry(&self, module: &str) -> Result<&ModuleEntry, String> {
        self.index
            .get(module)
            .map(|&i| &self.modules[i])
            .ok_or_else(|| format!("there is no module `{module}`"))
    }

    /// Splits `module/path/port` into a module this inspector knows and the rest: the
    /// longest known module path before a `/`, since port names may have slashes
    /// themselves (`activity/emergency`, `in/0/value`).
    fn split<'p>(&self, path: &'p str) -> Result<(&'p str, &'p str), String> {
        let found = (path.match_indices('/').rev())
            .map(|(i, _)| (&path[..i], &path[i + 1..]))
            .find(|(module, name)| self.index.contains_key(*module) && !name.is_empty());
        match found {
            Some(split) => Ok(split),
            None => Err(format!(
                "`{path}` names no port or parameter of a module here; write MODULE/PATH/NAME (see --list)"
            )),
        }
    }

    /// The latest value of the port `port` of `module`: an output's own, an input's
    /// writer's (the input holds what its writer published last).
    fn value(&self, module: &str, port: &str) -> Result<PortValue, String> {
        let m = self.entry(module)?;
        let info = m.interface.port(port).ok_or_else(|| {
            format!(
                "`{module}` has no port `{port}`; its ports: {}",
                names(m.interface.ports.iter().map(|p| p.name.as_str()))
            )
        })?;
        if let Some((_, handle)) = m.outputs.iter().find(|(n, _)| n == port) {
            let path = format!("{module}/{port}");
            return probe::read(
                &self.values,
                handle,
                (path, &info.model_type, info.unit.clone()),
            );
        }
        let path = format!("{module}/{port}");
        let writers = self.sources.get(&path).map(Vec::as_slice).unwrap_or(&[]);
        match writers {
            [writer] => {
                let (w_module, w_port) = writer.rsplit_once('/').unwrap_or((writer, ""));
                match self.index.get(w_module) {
                    Some(_) => self.value(w_module, w_port),
                    None => Err(format!(
                        "`{path}` is fed by `{writer}` of another process; ask that part"
                    )),
                }
            }
            [] => Err(format!("`{path}` is an input nothing here feeds")),
            _ => Err(format!(
                "`{path}` is fed by several outputs ({}); ask one of them",
                writers.join(", ")
            )),
        }
    }

    fn param_view(&self, m: &ModuleEntry, name: &str) -> Result<ParamView, String> {
        let (_, handle) = m.params.iter().find(|(n, _)| n == name).ok_or_else(|| {
            format!(
                "`{}` has no parameter `{name}`; its parameters: {}",
                m.path,
                names(m.params.iter().map(|(n, _)| n.as_str()))
            )
        })?;
        let info = m.interface.param(name);
        Ok(ParamView {
            module: m.path.clone(),
            name: name.to_owned(),
            r#type: info.map(|i| i.model_type.clone()).unwrap_or_default(),
            unit: info.and_then(|i| i.unit.clone()),
            min: info.and_then(|i| i.min),
            max: info.and_then(|i| i.max),
            choices: info.map(|i| i.choices.clone()).unwrap_or_default(),
            value: handle.current(),
        })
    }

    /// A parameter with its declaration and current value.
    fn param(&self, module: &str, name: &str) -> Result<ParamView, String> {
        self.param_view(self.entry(module)?, name)
    }

    /// Sets a parameter: the parameter's own checks (type, range, choices) run first,
    /// and a refused value leaves the old one in place. `value` is already in the
    /// parameter's unit (the caller converts; see `ferroc-inspect`).
    fn set_param(&self, module: &str, name: &str, value: &Value) -> Result<ParamView, String> {
        let m = self.entry(module)?;
        self.param_view(m, name)?;
        let (_, handle) = m.params.iter().find(|(n, _)| n == name).expect("checked");
        handle
            .set(value)
            .map_err(|why| format!("`{module}/{name}` keeps its value: {why}"))?;
        self.param_view(m, name)
    }

    /// The figures of the thread containers (of one part, or all).
    fn containers(&self, part: Option<&str>) -> Vec<ContainerView> {
        let micros = |d: std::time::Duration| d.as_secs_f64() * 1e6;
        (self.stats.iter())
            .filter(|s| {
                let modules = (self.threads.iter()).find(|(p, _)| *p == s.name);
                modules.is_none_or(|(p, ms)| self.container_in_part(p, ms, part))
            })
            .map(|s| ContainerView {
                path: s.name.clone(),
                cycles: s.cycles(),
                overruns: s.overruns(),
                load: s.load(),
                mean_cycle_us: micros(s.mean_cycle()),
                last_cycle_us: micros(s.last_cycle()),
                steps: (s.steps.iter())
                    .map(|(name, st)| StepView {
                        name: name.clone(),
                        runs: st.runs(),
                        mean_us: micros(st.mean()),
                        max_us: micros(st.max()),
                    })
                    .collect(),
                panics: s.panics(),
            })
            .collect()
    }

    /// The state of every input fed by a link from another part.
    fn links(&self, part: Option<&str>) -> Vec<LinkView> {
        let now = Timestamp::now();
        let mut out = Vec::new();
        for m in self.modules.iter().filter(|m| self.in_part(&m.path, part)) {
            for (name, source) in &m.inputs {
                let Some(fresh) = source.get() else { continue };
                let age = fresh.age(now);
                let state = if fresh.is_gone() {
                    "gone"
                } else if age.is_none() {
                    "waiting"
                } else if fresh.is_stale(now) {
                    "stale"
                } else {
                    "up"
                };
                out.push(LinkView {
                    input: format!("{}/{name}", m.path),
                    state: state.into(),
                    age_ms: age.map(|a| a.as_secs_f64() * 1e3),
                });
            }
        }
        out
    }

    /// The activity and target rating of every behaviour (of one part, or all).
    fn activities(&self, part: Option<&str>) -> Vec<ActivityView> {
        let number = |m: &ModuleEntry, port: &str| {
            self.value(&m.path, port)
                .ok()
                .and_then(|v| v.value.as_f64())
        };
        (self.modules.iter())
            .filter(|m| self.in_part(&m.path, part))
            .filter(|m| {
                m.interface
                    .port("activity")
                    .is_some_and(|p| p.role == Role::Meta)
            })
            .map(|m| ActivityView {
                module: m.path.clone(),
                activity: number(m, "activity"),
                target_rating: number(m, "target_rating"),
            })
            .collect()
    }
}

fn names<'a>(list: impl Iterator<Item = &'a str>) -> String {
    let list: Vec<&str> = list.collect();
    if list.is_empty() {
        "none".into()
    } else {
        list.join(", ")
    }
}
