//! Changing the structure of a running application without stopping it (FINROC's
//! runtime construction): modules created by their type's factory as the builder does,
//! modules dropped or moved to another thread container, connections made and unmade
//! on the live ports. Only the containers a change touches switch, each at its own
//! cycle boundary (`ferroc_exec`'s `change.rs`): the others keep their period and never wait.
//!
//! Connections between two modules of one container are made and unmade by that
//! container's thread at its boundary (with its step change), so a container never
//! sees its own wiring change in the middle of a cycle; connections between containers
//! use the ports' thread-safe `connect`/`disconnect` from the caller's thread.
//!
//! [`Builder::start_live`] starts the application as [`Builder::start_with`] does and
//! gives a [`Live`] that takes [`Reconfiguration`]s. Lockstep runs cannot be changed.

use super::{
    create, BuildError, Builder, Instance, ModuleSpec, Registry, RunningApp, StartOptions,
    StepKind, ThreadSpec,
};
use ferroc_exec::{ChangeSlot, Step};
use ferroc_module::behaviour::ViolationLog;
use ferroc_module::{Interface, Kind, Module, ParamHandle, Value};
use ferroc_ports::port::{InputHandle, OutputHandle, Wakeup};
use std::collections::{BTreeMap, BTreeSet, HashMap};
use std::sync::{Arc, Mutex};
use std::time::Duration;

/// What the builder knew of the modules when it started the application.
pub(super) struct Leftovers {
    pub modules: Vec<Instance>,
    pub threads: Vec<ThreadSpec>,
    pub connections: Vec<(usize, usize, String)>,
    pub inspected: HashMap<String, Vec<(String, Arc<OutputHandle>)>>,
    pub violations: Arc<ViolationLog>,
    pub run: Arc<ferroc_module::Determinism>,
}

struct LiveModule {
    kind: Kind,
    interface: Interface,
    inputs: Vec<(String, Arc<InputHandle>)>,
    outputs: Vec<(String, Arc<OutputHandle>)>,
    params: Vec<(String, Arc<ParamHandle>)>,
    /// Index of its container, `None` for the ends of links between parts.
    thread: Option<usize>,
}

struct LiveContainer {
    path: String,
    slot: Arc<ChangeSlot>,
    wakeup: Option<Arc<Wakeup>>,
    steps: Vec<(String, StepKind)>,
}

/// A running application's structure, to change while it runs; see the
/// [module docs](self).
pub struct Live {
    registry: Registry,
    violations: Arc<ViolationLog>,
    /// The run seed and reads of the wall clock, for the modules added while running.
    run: Arc<ferroc_module::Determinism>,
    modules: BTreeMap<String, LiveModule>,
    /// Module paths in the order they were added (the inspector's tree keeps it).
    order: Vec<String>,
    containers: Vec<LiveContainer>,
    /// Module connections: (writer, reader, input).
    connections: BTreeSet<(String, String, String)>,
    /// How long to wait for a container to reach its cycle boundary.
    pub timeout: Duration,
}

/// A module port: module path and port name.
pub type PortPath = (String, String);

/// One structural change of a running application, in the runtime's terms (a model
/// edit's plan difference, translated by the runner).
#[derive(Default)]
pub struct Reconfiguration<'a> {
    /// Modules to drop (their connections are in `disconnect`).
    pub remove: Vec<String>,
    /// Modules to create.
    pub add: Vec<ModuleSpec<'a>>,
    /// Modules that keep their instance and change their path (another container).
    pub moves: Vec<(String, String)>,
    /// Connections to unmake, by the paths before the change.
    pub disconnect: Vec<(PortPath, PortPath)>,
    /// Connections to make, by the paths after the change.
    pub connect: Vec<(PortPath, PortPath)>,
    /// Parameter values: module path (after the change), name, value.
    pub params: Vec<(String, String, Value)>,
    /// The new step order of every container whose steps change.
    pub threads: Vec<(String, Vec<(String, StepKind)>)>,
}

impl Builder<'_> {
    /// Starts the application as [`start_with`](Self::start_with) does, and gives
    /// its structure to change while it runs.
    pub fn start_live(self, options: StartOptions) -> Result<(RunningApp, Live), BuildError> {
        let registry = self.registry.clone();
        let (app, left) = self.launch(options)?;
        let paths: Vec<String> = left.modules.iter().map(|m| m.path.clone()).collect();
        let slots: HashMap<&str, (&Arc<ChangeSlot>, &ferroc_exec::Trigger)> = (app.slots.iter())
            .map(|(path, slot, trigger)| (path.as_str(), (slot, trigger)))
            .collect();
        let containers = (left.threads.iter())
            .filter_map(|t| {
                let (slot, trigger) = slots.get(t.path.as_str())?;
                Some(LiveContainer {
                    path: t.path.clone(),
                    slot: Arc::clone(slot),
                    wakeup: match trigger {
                        ferroc_exec::Trigger::Data(w) => Some(Arc::clone(w)),
                        _ => None,
                    },
                    steps: t.steps.clone(),
                })
            })
            .collect();
        let mut inspected = left.inspected;
        let order = paths.clone();
        let modules = (left.modules.into_iter())
            .map(|m| {
                let outputs = inspected.remove(&m.path).unwrap_or_else(|| {
                    (m.outputs.into_iter())
                        .map(|(n, h)| (n, Arc::new(h)))
                        .collect()
                });
                let live = LiveModule {
                    kind: m.kind,
                    interface: m.interface,
                    inputs: m
                        .inputs
                        .into_iter()
                        .map(|(n, h)| (n, Arc::new(h)))
                        .collect(),
                    outputs,
                    params: m.params,
                    thread: if m.link_end { None } else { m.thread },
                };
                (m.path, live)
            })
            .collect();
        let connections = (left.connections.into_iter())
            .map(|(w, r, input)| (paths[w].clone(), paths[r].clone(), input))
            .collect();
        let live = Live {
            registry,
            violations: left.violations,
            run: left.run,
            modules,
            order,
            containers,
            connections,
            timeout: Duration::from_secs(5),
        };
        Ok((app, live))
    }
}

/// A module's steps, as the builder makes them (`containers.rs`).
fn steps_of(path: &str, module: Box<dyn Module>, kinds: &[StepKind]) -> Vec<Step> {
    if kinds == [StepKind::Update] {
        return vec![Step::update(format!("{path}:update"), module)];
    }
    let cell = Arc::new(Mutex::new(module));
    (kinds.iter())
        .map(|kind| {
            let cell = Arc::clone(&cell);
            let sense = *kind == StepKind::Sense;
            let name = format!("{path}:{}", if sense { "sense" } else { "control" });
            Step::new(name, move || {
                let mut module = cell
                    .lock()
                    .expect("the module's other step panicked; this step is stopped too");
                if sense {
                    module.sense()
                } else {
                    module.control()
                }
            })
        })
        .collect()
}

fn step_name(path: &str, kind: StepKind) -> String {
    let kind = match kind {
        StepKind::Update => "update",
        StepKind::Sense => "sense",
        StepKind::Control => "control",
    };
    format!("{path}:{kind}")
}

/// Where a change happens: on a container's thread or the caller's.
fn on_one_thread(a: Option<usize>, b: Option<usize>) -> Option<usize> {
    match (a, b) {
        (Some(x), Some(y)) if x == y => Some(x),
        _ => None,
    }
}

impl Live {
    /// The thread container paths, in declaration order.
    pub fn containers(&self) -> Vec<String> {
        self.containers.iter().map(|c| c.path.clone()).collect()
    }

    /// What an inspector serves of the application as it is now.
    pub fn catalogue(&self) -> crate::inspect::Catalogue {
        let modules = (self.order.iter())
            .filter_map(|path| Some((path, self.modules.get(path)?)))
            .filter(|(_, m)| m.thread.is_some())
            .map(|(path, m)| crate::inspect::ModuleEntry {
                path: path.clone(),
                interface: m.interface.clone(),
                thread: m.thread.map(|t| self.containers[t].path.clone()),
                outputs: m.outputs.clone(),
                inputs: (m.inputs.iter())
                    .map(|(n, h)| (n.clone(), h.source()))
                    .collect(),
                params: m.params.clone(),
            })
            .collect();
        let threads = (self.containers.iter())
            .map(|c| {
                let mut paths: Vec<String> = Vec::new();
                for (p, _) in &c.steps {
                    if !paths.contains(p) {
                        paths.push(p.clone());
                    }
                }
                (c.path.clone(), paths)
            })
            .collect();
        // The ROS 2 ends do not change while the application runs: the inspector
        // keeps those it was given at start.
        crate::inspect::Catalogue {
            modules,
            threads,
            ros2: Vec::new(),
            hub: None,
        }
    }

    /// Applies `change`: everything is checked and every new module created first, so
    /// a change that cannot be made changes nothing; then each container it touches
    /// switches at its next cycle boundary. Gives one line per thing done.
    pub fn apply(&mut self, change: Reconfiguration<'_>) -> Result<Vec<String>, String> {
        if self.containers.is_empty() && !self.modules.is_empty() {
            return Err("this application runs in lockstep (or has no containers): its structure cannot change while it runs".into());
        }
        let plan = self.prepare(change)?;
        Ok(self.execute(plan))
    }
}

/// A checked change, ready to execute.
struct Prepared {
    remove: Vec<String>,
    moves: Vec<(String, String)>,
    created: Vec<(String, Instance)>,
    disconnect: Vec<(PortPath, PortPath)>,
    connect: Vec<(PortPath, PortPath)>,
    params: Vec<(Arc<ParamHandle>, Value, String)>,
    /// Container index → new step list.
    threads: BTreeMap<usize, Vec<(String, StepKind)>>,
    /// Module path (after) → container (after).
    placement: HashMap<String, usize>,
}

impl Live {
    fn container(&self, path: &str) -> Result<usize, String> {
        (self.containers.iter().position(|c| c.path == path))
            .ok_or_else(|| format!("there is no thread container `{path}` running"))
    }

    /// Checks `change` against the running application and resolves it: the modules
    /// it names exist (or do not yet), the new ones are created, every module has a
    /// container afterwards, the connections' ports exist with one value type, the
    /// parameters exist. Nothing runs differently until [`execute`](Self::execute).
    fn prepare(&self, change: Reconfiguration<'_>) -> Result<Prepared, String> {
        self.check_named_modules_run(&change)?;
        let created = self.create_added(&change)?;
        let mut threads = BTreeMap::new();
        for (path, steps) in change.threads {
            threads.insert(self.container(&path)?, steps);
        }
        let placement = self.place(&change.moves, &change.remove, &created, &threads)?;
        let renamed = |path: &str| {
            (change.moves.iter().find(|(_, new)| new == path))
                .map_or(path.to_owned(), |(old, _)| old.clone())
        };
        self.check_ports(&change.connect, &change.disconnect, &created, &renamed)?;
        let params = self.resolve_params(change.params, &renamed)?;
        Ok(Prepared {
            remove: change.remove,
            moves: change.moves,
            created,
            disconnect: change.disconnect,
            connect: change.connect,
            params,
            threads,
            placement,
        })
    }

    /// The modules to remove or move run.
    fn check_named_modules_run(&self, change: &Reconfiguration<'_>) -> Result<(), String> {
        for path in change
            .remove
            .iter()
            .chain(change.moves.iter().map(|(a, _)| a))
        {
            if !self.modules.contains_key(path) {
                return Err(format!("there is no module `{path}` running"));
            }
        }
        Ok(())
    }

    /// Creates the modules to add (none may run already, unless it is removed).
    fn create_added(
        &self,
        change: &Reconfiguration<'_>,
    ) -> Result<Vec<(String, Instance)>, String> {
        let mut created = Vec::new();
        for spec in &change.add {
            let gone = change.remove.iter().any(|r| r == spec.path);
            if self.modules.contains_key(spec.path) && !gone {
                return Err(format!("`{}` runs already", spec.path));
            }
            let instance = create(&self.registry, &self.violations, &self.run, *spec)
                .map_err(|e| e.to_string())?;
            created.push((spec.path.to_owned(), instance));
        }
        Ok(created)
    }

    /// Where every module runs after the change: module path (after) → container.
    /// Every step must name a module with that kind of step, and every created module
    /// must get a container.
    fn place(
        &self,
        moves: &[(String, String)],
        remove: &[String],
        created: &[(String, Instance)],
        threads: &BTreeMap<usize, Vec<(String, StepKind)>>,
    ) -> Result<HashMap<String, usize>, String> {
        let mut placement: HashMap<String, usize> = HashMap::new();
        for (path, m) in &self.modules {
            if let Some(t) = m.thread.filter(|t| !threads.contains_key(t)) {
                placement.insert(path.clone(), t);
            }
        }
        for (&t, steps) in threads {
            for (path, kind) in steps {
                let kind_of = (created.iter().find(|(p, _)| p == path).map(|(_, i)| i.kind))
                    .or_else(|| {
                        let old = (moves.iter().find(|(_, new)| new == path))
                            .map_or(path.as_str(), |(old, _)| old.as_str());
                        let removed = remove.iter().any(|r| r == old);
                        self.modules.get(old).filter(|_| !removed).map(|m| m.kind)
                    })
                    .ok_or_else(|| {
                        format!(
                            "`{path}` has a step in `{}` but is no module",
                            self.containers[t].path
                        )
                    })?;
                let fits = match kind {
                    StepKind::Update => kind_of.has_update(),
                    _ => kind_of == Kind::SenseControl,
                };
                if !fits {
                    return Err(format!(
                        "`{path}` is a {} module and has no {kind:?} step",
                        kind_of.as_str()
                    ));
                }
                placement.insert(path.clone(), t);
            }
        }
        for (path, _) in created {
            if !placement.contains_key(path) {
                return Err(format!("`{path}` is not executed by any thread container"));
            }
        }
        Ok(placement)
    }

    /// Every port of every connection exists, with the same value type.
    fn check_ports(
        &self,
        connect: &[(PortPath, PortPath)],
        disconnect: &[(PortPath, PortPath)],
        created: &[(String, Instance)],
        renamed: &dyn Fn(&str) -> String,
    ) -> Result<(), String> {
        for (from, to) in connect {
            let output = self.port_after(created, renamed, from, true)?;
            let input = self.port_after(created, renamed, to, false)?;
            if output != input {
                return Err(format!(
                    "`{}/{}` sends {output} and `{}/{}` reads {input}: a converting connection cannot be made while the application runs",
                    from.0, from.1, to.0, to.1
                ));
            }
        }
        for (from, to) in disconnect {
            self.port_after(&[], &|p: &str| p.to_owned(), from, true)?;
            self.port_after(&[], &|p: &str| p.to_owned(), to, false)?;
        }
        Ok(())
    }

    /// The parameters to set: their handles, values and `module/name` for the report.
    fn resolve_params(
        &self,
        params: Vec<(String, String, Value)>,
        renamed: &dyn Fn(&str) -> String,
    ) -> Result<Vec<(Arc<ParamHandle>, Value, String)>, String> {
        let mut resolved = Vec::new();
        for (module, name, value) in params {
            let m = (self.modules.get(&renamed(&module)))
                .ok_or_else(|| format!("there is no module `{module}` running"))?;
            let (_, handle) = (m.params.iter().find(|(n, _)| *n == name))
                .ok_or_else(|| format!("`{module}` has no parameter `{name}`"))?;
            resolved.push((Arc::clone(handle), value, format!("{module}/{name}")));
        }
        Ok(resolved)
    }

    /// The value type of a port after the change (of a created module, or of a
    /// running one by its path before the change).
    fn port_after(
        &self,
        created: &[(String, Instance)],
        renamed: &dyn Fn(&str) -> String,
        (module, port): &PortPath,
        output: bool,
    ) -> Result<&'static str, String> {
        let missing = || {
            format!(
                "`{module}` has no {} `{port}`",
                if output { "output" } else { "input" }
            )
        };
        if let Some((_, i)) = created.iter().find(|(p, _)| p == module) {
            return match output {
                true => i
                    .outputs
                    .iter()
                    .find(|(n, _)| n == port)
                    .map(|(_, h)| h.value_type()),
                false => i
                    .inputs
                    .iter()
                    .find(|(n, _)| n == port)
                    .map(|(_, h)| h.value_type()),
            }
            .ok_or_else(missing);
        }
        let m = (self.modules.get(&renamed(module)))
            .ok_or_else(|| format!("there is no module `{module}` running"))?;
        match output {
            true => m
                .outputs
                .iter()
                .find(|(n, _)| n == port)
                .map(|(_, h)| h.value_type()),
            false => m
                .inputs
                .iter()
                .find(|(n, _)| n == port)
                .map(|(_, h)| h.value_type()),
        }
        .ok_or_else(missing)
    }
}

mod run;
#[cfg(test)]
mod tests;
