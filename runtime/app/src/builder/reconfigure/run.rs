//! Executing a checked [`Reconfiguration`](super::Reconfiguration): the containers
//! that move modules out switch first (their steps travel to the new container), then
//! the others; connections between containers are unmade before and made after.

use super::{on_one_thread, step_name, steps_of, Live, LiveModule, PortPath, Prepared};
use crate::builder::{Instance, StepKind};
use ferroc_exec::{Change, Step};
use ferroc_module::{Module, ParamHandle, Value};
use ferroc_ports::port::{ConnectOptions, InputHandle, Notifier, OutputHandle};
use std::collections::{BTreeMap, HashMap};
use std::sync::Arc;

/// A connection's handles and the container whose thread makes it (`None`: the
/// caller's).
struct Connection {
    output: Arc<OutputHandle>,
    input: Arc<InputHandle>,
    thread: Option<usize>,
    what: String,
}

impl Connection {
    fn new(
        (output, input): (Arc<OutputHandle>, Arc<InputHandle>),
        thread: Option<usize>,
        from: &PortPath,
        to: &PortPath,
    ) -> Connection {
        Connection {
            output,
            input,
            thread,
            what: format!("`{}/{}` → `{}/{}`", from.0, from.1, to.0, to.1),
        }
    }
}

impl Live {
    fn handles(
        &self,
        from: &PortPath,
        to: &PortPath,
        renamed: &dyn Fn(&str) -> String,
    ) -> Option<(Arc<OutputHandle>, Arc<InputHandle>)> {
        let w = self.modules.get(&renamed(&from.0))?;
        let r = self.modules.get(&renamed(&to.0))?;
        let output = w.outputs.iter().find(|(n, _)| *n == from.1)?.1.clone();
        let input = r.inputs.iter().find(|(n, _)| *n == to.1)?.1.clone();
        Some((output, input))
    }

    /// Executes `p` in phases: the new modules join the table, the connections to
    /// unmake and make are resolved to handles, each changing container's step list is
    /// assembled, connections inside one container are queued for its boundary (the
    /// others are unmade now and made last), the containers switch (exporting ones
    /// first, their steps travelling), then parameters are set and the table updated.
    /// Gives one line per thing done.
    pub(super) fn execute(&mut self, mut p: Prepared) -> Vec<String> {
        let mut done = Vec::new();
        let mut instances = self.add_created(std::mem::take(&mut p.created), &p.placement);
        let unmake = self.connections_to_unmake(&p.disconnect);
        let make = self.connections_to_make(&p);
        let mut changes = assign_steps(&p.threads, &mut instances);
        let imports = self.plan_moves(&p, &mut changes);
        queue_unmaking(unmake, &mut changes, &mut done);
        let late = queue_making(make, &mut changes, &mut done);
        self.keep_order_of_rewired(&mut changes, &p.threads);
        self.switch_all(changes, &imports, &p.threads, &mut done);
        connect_late(late, &mut done);
        set_params(std::mem::take(&mut p.params), &mut done);
        self.update_table(&p.remove, &p.moves, &p.threads, &p.disconnect, &p.connect);
        self.wake_new_inputs(&p.placement);
        done
    }

    /// New modules join the table under a temporary name (a module of their path may
    /// still be being removed); gives their instances, which go to the containers as
    /// steps.
    fn add_created(
        &mut self,
        created: Vec<(String, Instance)>,
        placement: &HashMap<String, usize>,
    ) -> HashMap<String, Box<dyn Module>> {
        let mut instances: HashMap<String, Box<dyn Module>> = HashMap::new();
        for (path, mut i) in created {
            if let Some(m) = i.module.take() {
                instances.insert(path.clone(), m);
            }
            let live = LiveModule {
                kind: i.kind,
                interface: i.interface,
                inputs: i
                    .inputs
                    .into_iter()
                    .map(|(n, h)| (n, Arc::new(h)))
                    .collect(),
                outputs: i
                    .outputs
                    .into_iter()
                    .map(|(n, h)| (n, Arc::new(h)))
                    .collect(),
                params: i.params,
                thread: placement.get(&path).copied(),
            };
            self.modules.insert(format!("\0new {path}"), live);
        }
        instances
    }

    /// The connections to unmake, between the modules as they are now.
    fn connections_to_unmake(&self, disconnect: &[(PortPath, PortPath)]) -> Vec<Connection> {
        let before = |path: &str| path.to_owned();
        (disconnect.iter())
            .filter_map(|(from, to)| {
                let (output, input) = self.handles(from, to, &before)?;
                let thread = on_one_thread(
                    self.modules.get(&from.0).and_then(|m| m.thread),
                    self.modules.get(&to.0).and_then(|m| m.thread),
                );
                Some(Connection::new((output, input), thread, from, to))
            })
            .collect()
    }

    /// The connections to make, between the modules as they will be (a new module
    /// under its temporary name, a moved one under its old name).
    fn connections_to_make(&self, p: &Prepared) -> Vec<Connection> {
        let old_of = |path: &str| {
            (p.moves.iter().find(|(_, new)| new == path))
                .map_or(path.to_owned(), |(old, _)| old.clone())
        };
        let created_key = |path: &str| {
            let key = format!("\0new {path}");
            if self.modules.contains_key(&key) {
                key
            } else {
                old_of(path)
            }
        };
        (p.connect.iter())
            .filter_map(|(from, to)| {
                let (output, input) = self.handles(from, to, &created_key)?;
                let thread = on_one_thread(
                    p.placement.get(&from.0).copied(),
                    p.placement.get(&to.0).copied(),
                );
                Some(Connection::new((output, input), thread, from, to))
            })
            .collect()
    }

    /// Moved modules: renamed by their new container; a move between containers is
    /// exported by the old one and imported by the new one. Gives the imports (from,
    /// to, old path, new path).
    fn plan_moves(
        &self,
        p: &Prepared,
        changes: &mut BTreeMap<usize, Change>,
    ) -> Vec<(usize, usize, String, String)> {
        let mut imports = Vec::new();
        for (old, new) in &p.moves {
            let from = self.modules.get(old).and_then(|m| m.thread);
            let to = p.placement.get(new).copied();
            if let (Some(from), Some(to)) = (from, to) {
                changes
                    .entry(to)
                    .or_default()
                    .renames
                    .push((old.clone(), new.clone()));
                if from != to {
                    changes.entry(from).or_default().export.push(old.clone());
                    imports.push((from, to, old.clone(), new.clone()));
                }
            }
        }
        imports
    }

    /// A container that changes only its wiring keeps its order.
    fn keep_order_of_rewired(
        &self,
        changes: &mut BTreeMap<usize, Change>,
        threads: &BTreeMap<usize, Vec<(String, StepKind)>>,
    ) {
        for (t, change) in changes.iter_mut() {
            if change.order.is_empty() && !threads.contains_key(t) {
                change.order = (self.containers[*t].steps.iter())
                    .map(|(path, kind)| step_name(path, *kind))
                    .collect();
            }
        }
    }

    /// Switches every changing container: the exporting ones first, whose steps then
    /// travel to the containers importing them, then the others.
    fn switch_all(
        &self,
        mut changes: BTreeMap<usize, Change>,
        imports: &[(usize, usize, String, String)],
        threads: &BTreeMap<usize, Vec<(String, StepKind)>>,
        done: &mut Vec<String>,
    ) {
        let exporting: Vec<usize> = changes
            .iter()
            .filter(|(_, c)| !c.export.is_empty())
            .map(|(t, _)| *t)
            .collect();
        let mut travelling: HashMap<usize, Vec<Step>> = HashMap::new();
        for t in exporting {
            let change = changes.remove(&t).expect("listed");
            if let Some(steps) = self.switch(t, change, done) {
                travelling.insert(t, steps);
            }
        }
        for (from, to, old, _) in imports {
            let Some(steps) = travelling.get_mut(from) else {
                continue;
            };
            let (mine, rest): (Vec<Step>, Vec<Step>) =
                std::mem::take(steps).into_iter().partition(|s| {
                    s.name().starts_with(&format!("{old}:"))
                        || s.name().starts_with(&format!("{old}/"))
                });
            *steps = rest;
            let change = changes.entry(*to).or_default();
            if change.order.is_empty() {
                change.order = (threads.get(to).into_iter().flatten())
                    .map(|(path, kind)| step_name(path, *kind))
                    .collect();
            }
            change.steps.extend(mine);
        }
        for (t, change) in changes {
            self.switch(t, change, done);
        }
    }

    /// Posts `change` to container `t` and waits for its boundary; gives the steps
    /// it exported.
    fn switch(&self, t: usize, change: Change, done: &mut Vec<String>) -> Option<Vec<Step>> {
        let c = &self.containers[t];
        if c.slot.post(change).is_err() {
            done.push(format!(
                "`{}` had a change waiting already; this one is not applied",
                c.path
            ));
            return None;
        }
        match c.slot.wait(self.timeout) {
            Some(steps) => {
                done.push(format!("`{}` switched at a cycle boundary", c.path));
                Some(steps)
            }
            None => {
                done.push(format!(
                    "`{}` did not reach a cycle boundary within {:?}; it switches when it does",
                    c.path, self.timeout
                ));
                None
            }
        }
    }

    fn update_table(
        &mut self,
        remove: &[String],
        moves: &[(String, String)],
        threads: &BTreeMap<usize, Vec<(String, StepKind)>>,
        disconnect: &[(PortPath, PortPath)],
        connect: &[(PortPath, PortPath)],
    ) {
        for path in remove {
            self.modules.remove(path);
            self.order.retain(|p| p != path);
        }
        for (old, new) in moves {
            if let Some(m) = self.modules.remove(old) {
                self.modules.insert(new.clone(), m);
            }
            for p in self.order.iter_mut().filter(|p| *p == old) {
                *p = new.clone();
            }
        }
        let created: Vec<String> = (self.modules.keys())
            .filter(|k| k.starts_with('\0'))
            .cloned()
            .collect();
        for key in created {
            let m = self.modules.remove(&key).expect("listed");
            let path = key.trim_start_matches("\0new ").to_owned();
            self.order.push(path.clone());
            self.modules.insert(path, m);
        }
        for (&t, steps) in threads {
            self.containers[t].steps = steps.clone();
            for (path, _) in steps {
                if let Some(m) = self.modules.get_mut(path) {
                    m.thread = Some(t);
                }
            }
        }
        let rename = |p: &str| {
            (moves.iter().find(|(old, _)| old == p)).map_or(p.to_owned(), |(_, new)| new.clone())
        };
        for (from, to) in disconnect {
            self.connections
                .remove(&(from.0.clone(), to.0.clone(), to.1.clone()));
        }
        self.connections = std::mem::take(&mut self.connections)
            .into_iter()
            .filter(|(w, r, _)| !remove.contains(w) && !remove.contains(r))
            .map(|(w, r, i)| (rename(&w), rename(&r), i))
            .collect();
        for (from, to) in connect {
            self.connections
                .insert((from.0.clone(), to.0.clone(), to.1.clone()));
        }
    }

    /// Inputs of modules now in a data-triggered container wake it, unless all their
    /// writers run in the same container (as the builder decides, `containers.rs`).
    fn wake_new_inputs(&self, placement: &HashMap<String, usize>) {
        for (path, &t) in placement {
            let Some(wakeup) = &self.containers[t].wakeup else {
                continue;
            };
            let Some(m) = self.modules.get(path) else {
                continue;
            };
            for (name, input) in &m.inputs {
                let mut writers = (self.connections.iter())
                    .filter(|(_, r, i)| r == path && i == name)
                    .peekable();
                let within = writers.peek().is_some()
                    && writers.all(|(w, ..)| self.modules.get(w).and_then(|m| m.thread) == Some(t));
                if !within {
                    let notifier: Notifier = wakeup.clone();
                    let _ = input.set_notifier(notifier);
                }
            }
        }
    }
}

/// The containers that change, and what each does: its new step order and the steps of
/// the new modules it runs (taken out of `instances`).
fn assign_steps(
    threads: &BTreeMap<usize, Vec<(String, StepKind)>>,
    instances: &mut HashMap<String, Box<dyn Module>>,
) -> BTreeMap<usize, Change> {
    let mut changes: BTreeMap<usize, Change> = BTreeMap::new();
    for (&t, steps) in threads {
        let change = changes.entry(t).or_default();
        change.order = steps
            .iter()
            .map(|(path, kind)| step_name(path, *kind))
            .collect();
        let mut mine: Vec<&str> = Vec::new();
        for (path, _) in steps {
            if instances.contains_key(path) && !mine.contains(&path.as_str()) {
                mine.push(path);
            }
        }
        for path in mine {
            let kinds: Vec<StepKind> = steps
                .iter()
                .filter(|(q, _)| q == path)
                .map(|(_, k)| *k)
                .collect();
            let module = instances.remove(path).expect("listed");
            change.steps.extend(steps_of(path, module, &kinds));
        }
    }
    changes
}

/// Connections inside one container are unmade by its thread at its boundary; the
/// others at once, from the caller's thread.
fn queue_unmaking(
    unmake: Vec<Connection>,
    changes: &mut BTreeMap<usize, Change>,
    done: &mut Vec<String>,
) {
    for conn in unmake {
        match conn.thread {
            Some(t) => changes
                .entry(t)
                .or_default()
                .actions
                .push(Box::new(move || {
                    conn.output.disconnect(&conn.input);
                })),
            None => {
                conn.output.disconnect(&conn.input);
            }
        }
        done.push(format!("disconnected {}", conn.what));
    }
}

/// Connections inside one container are made by its thread at its boundary; gives the
/// others, made after every container switched ([`connect_late`]).
fn queue_making(
    make: Vec<Connection>,
    changes: &mut BTreeMap<usize, Change>,
    done: &mut Vec<String>,
) -> Vec<Connection> {
    let mut late = Vec::new();
    for conn in make {
        done.push(format!("connected {}", conn.what));
        match conn.thread {
            Some(t) => changes
                .entry(t)
                .or_default()
                .actions
                .push(Box::new(move || {
                    let _ = conn.output.connect(&conn.input, ConnectOptions::default());
                })),
            None => late.push(conn),
        }
    }
    late
}

/// Makes the connections between containers, once every container switched.
fn connect_late(late: Vec<Connection>, done: &mut Vec<String>) {
    for conn in late {
        if let Err(e) = conn.output.connect(&conn.input, ConnectOptions::default()) {
            done.push(format!("could not connect {}: {e}", conn.what));
        }
    }
}

/// Sets the parameters the reconfiguration changes.
fn set_params(params: Vec<(Arc<ParamHandle>, Value, String)>, done: &mut Vec<String>) {
    for (handle, value, what) in params {
        match handle.set(&value) {
            Ok(()) => done.push(format!("set `{what}` to {value}")),
            Err(e) => done.push(format!("`{what}` keeps its value: {e}")),
        }
    }
}
