//! From the IR to the analysis model: execution contexts (thread containers), locks,
//! queues and the wait-states of every activity and service body, with the set each
//! wait-state holds (`reference/deadlocks.md` §2.1–2.2). One pass over the modules;
//! connections are followed through group ports only where a wait needs them.

use super::follow::{follow, Reach};
use super::{Ec, EcId, Held, Lock, Queue, QueueId, Target, Wait, WaitId, WaitKind};
use super::{Model, StepFinding, StepFindingKind};
use crate::ir::{Application, ElementId, ElementKind, Endpoint, Profile};
use crate::library::steps::{StepDecl, StepOp};
use crate::library::{LibrarySet, ModuleType};
use crate::source::Span;
use hashbrown::{HashMap, HashSet};
use petgraph::Direction::{Incoming, Outgoing};

/// Inline calls nest at most this deep (deadlocks.md §2.2).
const MAX_INLINE_DEPTH: usize = 16;

pub(super) fn build(app: &Application, libs: &LibrarySet) -> Model {
    let mut b = Builder {
        app,
        libs,
        m: Model::default(),
        ec_of_thread: HashMap::new(),
        lock_by_name: HashMap::new(),
        queue_of: HashMap::new(),
        block_writers: block_writers(app),
    };
    for r in &app.resources {
        b.lock_named(&r.name, Some(r.span), r.level, r.recursive);
    }
    // Thread containers → execution contexts.
    for (i, e) in app.elements.iter().enumerate() {
        if let ElementKind::Thread { period, pool, .. } = e.kind {
            b.ec_of_thread
                .insert(ElementId(i as u32), b.m.ecs.len() as EcId);
            b.m.ecs.push(Ec {
                thread: ElementId(i as u32),
                pool,
                period,
            });
        }
    }
    // Which services are called from another context (they run as activities there).
    let mut remote_called: hashbrown::HashSet<(ElementId, usize)> = Default::default();
    for (id, _) in app.modules() {
        let Some(mt) = app
            .module_type(libs, id)
            .filter(|mt| !mt.clients.is_empty())
        else {
            continue;
        };
        for c in 0..mt.clients.len() {
            for t in b.targets(id, mt, c) {
                if !t.inline {
                    remote_called.insert((t.module, t.service));
                }
            }
        }
    }
    for (id, _) in app.modules() {
        let Some(mt) = app.module_type(libs, id) else {
            continue;
        };
        let block_writers = &b.block_writers;
        let may_wait = |st: &StepDecl| match st.op {
            StepOp::Write { port, .. } => block_writers.contains(&(id, port as u32)),
            StepOp::Read { port } => mt.ports[port].blocking_read,
            StepOp::Unlock { .. } | StepOp::Call { sync: false, .. } => false,
            _ => true,
        };
        let waits = mt.activities.iter().flat_map(|a| &a.steps).any(may_wait)
            || mt.services.iter().flat_map(|s| &s.body).any(may_wait);
        if !waits {
            continue; // the common case: nothing this module does can block
        }
        let Some(ec) = b.ec_of(id) else {
            continue; // not executed by any container: M112
        };
        for act in &mt.activities {
            let root = Root {
                module: id,
                ec,
                activity: act.name.clone(),
                service: None,
            };
            b.walk_root(&root, &act.steps);
        }
        for (si, svc) in mt.services.iter().enumerate() {
            if remote_called.contains(&(id, si)) && !svc.body.is_empty() {
                let root = Root {
                    module: id,
                    ec,
                    activity: format!("service {}", svc.name),
                    service: Some((id, si)),
                };
                b.walk_root(&root, &svc.body);
            }
        }
    }
    b.m
}

struct Builder<'a> {
    app: &'a Application,
    libs: &'a LibrarySet,
    m: Model,
    ec_of_thread: HashMap<ElementId, EcId>,
    lock_by_name: HashMap<String, u32>,
    queue_of: HashMap<Endpoint, QueueId>,
    /// Module outputs with a path through a `queue` + `on-full="block"` connection: the
    /// only writes that can wait. Found once from those connections, so the writes of
    /// every other module (all of them, in most models) are not followed one by one.
    block_writers: HashSet<(ElementId, u32)>,
}

fn block_writers(app: &Application) -> HashSet<(ElementId, u32)> {
    let mut out = HashSet::new();
    for c in &app.connections {
        if c.queue.is_none() || c.on_full.as_deref() != Some("block") {
            continue;
        }
        match c.from {
            Endpoint::Port { element, port } => {
                out.insert((element, port));
            }
            from => {
                for r in follow(app, from, Incoming) {
                    if let Endpoint::Port { element, port } = r.end {
                        out.insert((element, port));
                    }
                }
            }
        }
    }
    out
}

/// The activity a step list runs in.
struct Root {
    module: ElementId,
    ec: EcId,
    activity: String,
    service: Option<(ElementId, usize)>,
}

/// The running state of one activation.
struct Walk {
    held: Vec<(Held, Span)>,
    /// Output ports written so far in this activation.
    written: Vec<(ElementId, u32)>,
    step_no: u32,
    inline: Vec<(ElementId, usize)>,
}

impl<'a> Builder<'a> {
    fn ec_of(&self, module: ElementId) -> Option<EcId> {
        let thread = self.app.element(module).thread?;
        self.ec_of_thread.get(&thread).copied()
    }

    fn lock_named(&mut self, name: &str, span: Option<Span>, level: Option<u32>, rec: bool) -> u32 {
        if let Some(&l) = self.lock_by_name.get(name) {
            return l;
        }
        let id = self.m.locks.len() as u32;
        self.m.locks.push(Lock {
            name: name.to_string(),
            span,
            level,
            recursive: rec,
        });
        self.lock_by_name.insert(name.to_string(), id);
        id
    }

    /// The lock behind a module's slot: its `<bind>`, else the resource of the slot's name.
    fn lock_of(&mut self, module: ElementId, mt: &ModuleType, slot: usize) -> (u32, Span) {
        let slot_name = &mt.lock_slots[slot].0;
        let ElementKind::Module(inst) = &self.app.element(module).kind else {
            return (self.lock_named(slot_name, None, None, false), mt.span);
        };
        match inst.binds.iter().find(|(s, _, _)| s == slot_name) {
            Some((_, res, span)) => (self.lock_named(res, None, None, false), *span),
            None => (
                self.lock_named(slot_name, None, None, false),
                self.app.element(module).name_span,
            ),
        }
    }

    /// The servers a client reaches, through group ports.
    fn targets(&self, module: ElementId, mt: &ModuleType, client: usize) -> Vec<Target> {
        let c = &mt.clients[client];
        let start = Endpoint::Port {
            element: module,
            port: c.port as u32,
        };
        let mut out = Vec::new();
        for r in self.follow(start, Outgoing) {
            let Endpoint::Port { element, port } = r.end else {
                continue;
            };
            let Some(smt) = self.app.module_type(self.libs, element) else {
                continue;
            };
            let Some(si) = smt.services.iter().position(|s| s.port == port as usize) else {
                continue;
            };
            let svc = &smt.services[si];
            let same_part = self.app.element(module).part == self.app.element(element).part;
            let inline = svc.inline
                || (self.app.profile == Profile::Finroc && same_part && !svc.executes_explicit);
            out.push(Target {
                module: element,
                service: si,
                ec: self.ec_of(element),
                inline,
                connect: self.app.connections[r.first].from_span,
            });
        }
        out
    }

    fn follow(&self, start: Endpoint, dir: petgraph::Direction) -> Vec<Reach> {
        follow(self.app, start, dir)
    }

    /// The queue of a module input (created on first use), with its writers.
    fn queue(&mut self, module: ElementId, port: u32) -> QueueId {
        let input = Endpoint::Port {
            element: module,
            port,
        };
        if let Some(&q) = self.queue_of.get(&input) {
            return q;
        }
        let mut q = Queue {
            module,
            port,
            ec: self.ec_of(module),
            is_queue: false,
            capacity: None,
            initial: 0,
            writers: Vec::new(),
            span: self.app.element(module).name_span,
            block_span: None,
        };
        for r in self.follow(input, Incoming) {
            let Endpoint::Port { element, port } = r.end else {
                continue;
            };
            // Where the queue is declared, else the hop next to the input.
            q.span = self.app.connections[r.queued.unwrap_or(r.first)].to_span;
            if let Some(c) = r.queued.map(|hop| &self.app.connections[hop]) {
                let cap = c.queue.unwrap_or(1);
                q.is_queue = true;
                q.capacity = Some(q.capacity.map_or(cap, |x: u32| x.min(cap)));
                q.initial += c.initial;
                if c.on_full.as_deref() == Some("block") {
                    q.block_span = Some(c.to_span);
                }
            }
            q.writers.push((element, port, self.ec_of(element)));
        }
        let id = self.m.queues.len() as QueueId;
        self.m.queues.push(q);
        self.queue_of.insert(input, id);
        id
    }

    fn walk_root(&mut self, root: &Root, steps: &[StepDecl]) {
        let mut w = Walk {
            held: Vec::new(),
            written: Vec::new(),
            step_no: 0,
            inline: Vec::new(),
        };
        if self.m.ecs[root.ec as usize].pool.is_none() {
            let t = self.m.ecs[root.ec as usize].thread;
            w.held
                .push((Held::Ec(root.ec), self.app.element(t).name_span));
        }
        self.walk(root, root.module, steps, &mut w);
    }

    /// Records a finding about one step of `root`'s activity, found in `module`.
    fn step_finding(
        &mut self,
        root: &Root,
        module: ElementId,
        step: Span,
        site: Span,
        inline: Option<(ElementId, usize)>,
        kind: StepFindingKind,
    ) {
        self.m.step_findings.push(StepFinding {
            kind,
            module,
            root: root.module,
            ec: root.ec,
            activity: root.activity.clone(),
            step,
            site,
            inline,
        });
    }

    fn walk(&mut self, root: &Root, module: ElementId, steps: &[StepDecl], w: &mut Walk) {
        let (app, libs) = (self.app, self.libs);
        let Some(mt) = app.module_type(libs, module) else {
            return;
        };
        for step in steps {
            w.step_no += 1;
            match step.op {
                StepOp::Lock { slot } => {
                    let (lock, site) = self.lock_of(module, mt, slot);
                    if let Some((_, first)) = w.held.iter().find(|(h, _)| *h == Held::Lock(lock)) {
                        if !self.m.locks[lock as usize].recursive {
                            self.step_finding(
                                root,
                                module,
                                step.span,
                                site,
                                w.inline.last().copied(),
                                StepFindingKind::Recursive {
                                    lock,
                                    first: *first,
                                },
                            );
                        }
                        continue;
                    }
                    if let Some(level) = self.m.locks[lock as usize].level {
                        for (h, at) in &w.held {
                            let Held::Lock(m) = *h else { continue };
                            if self.m.locks[m as usize].level.is_some_and(|lm| level >= lm) {
                                self.step_finding(
                                    root,
                                    module,
                                    step.span,
                                    site,
                                    None,
                                    StepFindingKind::Level {
                                        lock,
                                        outer: m,
                                        outer_site: *at,
                                    },
                                );
                            }
                        }
                    }
                    self.push_wait(root, module, step, w, site, WaitKind::Lock { lock });
                    w.held.push((Held::Lock(lock), site));
                }
                StepOp::Unlock { slot } => {
                    let (lock, _) = self.lock_of(module, mt, slot);
                    if let Some(i) = w.held.iter().rposition(|(h, _)| *h == Held::Lock(lock)) {
                        w.held.remove(i);
                    }
                }
                StepOp::Read { port } => {
                    if !mt.ports[port].blocking_read {
                        continue;
                    }
                    let q = self.queue(module, port as u32);
                    let queue = &self.m.queues[q as usize];
                    if !queue.is_queue && !queue.writers.is_empty() {
                        continue; // latest value: never waits
                    }
                    let site = queue.span;
                    self.push_wait(root, module, step, w, site, WaitKind::Read { queue: q });
                }
                StepOp::Write { port, .. } => {
                    let out = Endpoint::Port {
                        element: module,
                        port: port as u32,
                    };
                    if self.block_writers.contains(&(module, port as u32)) {
                        let mut queues = Vec::new();
                        let mut site = None;
                        for r in self.follow(out, Outgoing) {
                            let Endpoint::Port { element, port } = r.end else {
                                continue;
                            };
                            let Some(c) = r.queued.map(|hop| &app.connections[hop]) else {
                                continue;
                            };
                            if c.on_full.as_deref() == Some("block") {
                                queues.push(self.queue(element, port));
                                site.get_or_insert(c.to_span);
                            }
                        }
                        if let Some(site) = site {
                            let port = port as u32;
                            self.push_wait(
                                root,
                                module,
                                step,
                                w,
                                site,
                                WaitKind::Write { port, queues },
                            );
                        }
                    }
                    w.written.push((module, port as u32));
                }
                StepOp::Call { client, sync: true } | StepOp::Await { client } => {
                    let targets = self.targets(module, mt, client);
                    let is_call = matches!(step.op, StepOp::Call { .. });
                    let mut remote = Vec::new();
                    for t in targets {
                        if !t.inline {
                            remote.push(t);
                        } else if is_call {
                            self.splice(root, &t, w);
                        }
                    }
                    let c = &mt.clients[client];
                    let inline_only =
                        remote.is_empty() && !self.targets(module, mt, client).is_empty();
                    if inline_only {
                        continue;
                    }
                    if remote.is_empty() && app.profile == Profile::Finroc {
                        self.step_finding(
                            root,
                            module,
                            step.span,
                            app.element(module).name_span,
                            None,
                            StepFindingKind::Unconnected {
                                client: c.name.clone(),
                            },
                        );
                        continue;
                    }
                    let site = remote
                        .first()
                        .map_or(app.element(module).name_span, |t| t.connect);
                    let response =
                        if c.response_via_caller && self.m.ecs[root.ec as usize].pool.is_none() {
                            Some(root.ec)
                        } else {
                            None
                        };
                    let kind = WaitKind::Call {
                        client: c.name.clone(),
                        targets: remote,
                        response,
                    };
                    self.push_wait(root, module, step, w, site, kind);
                }
                StepOp::Call { sync: false, .. } => {} // asynchronous: never waits
            }
        }
    }

    /// An inline service body runs in the caller's activation (held set continues).
    fn splice(&mut self, root: &Root, t: &Target, w: &mut Walk) {
        let key = (t.module, t.service);
        if w.inline.len() >= MAX_INLINE_DEPTH || w.inline.contains(&key) {
            return;
        }
        let Some(mt) = self.app.module_type(self.libs, t.module) else {
            return;
        };
        let body = mt.services[t.service].body.clone();
        w.inline.push(key);
        self.walk(root, t.module, &body, w);
        w.inline.pop();
    }

    fn push_wait(
        &mut self,
        root: &Root,
        module: ElementId,
        step: &StepDecl,
        w: &Walk,
        site: Span,
        kind: WaitKind,
    ) {
        let mut held: Vec<Held> = w.held.iter().map(|(h, _)| *h).collect();
        held.sort();
        self.m.waits.push(Wait {
            ec: root.ec,
            root: root.module,
            module,
            activity: root.activity.clone(),
            service: root.service,
            inline: w.inline.last().copied(),
            step_no: w.step_no,
            step_span: step.span,
            site,
            kind,
            timeout: step.timeout,
            held,
            held_sites: w.held.clone(),
            written_before: w.written.clone(),
        });
    }
}

impl Model {
    /// Wait-states of one root activity, in program order (for the token rule).
    pub(super) fn activity_summary(
        &self,
        app: &Application,
        libs: &LibrarySet,
        w: WaitId,
    ) -> Summary {
        let wait = &self.waits[w as usize];
        let mut s = Summary::default();
        let Some(mt) = app.module_type(libs, wait.root) else {
            return s;
        };
        let steps: &[StepDecl] = match wait.service {
            Some((_, si)) => &mt.services[si].body,
            None => mt
                .activities
                .iter()
                .find(|a| a.name == wait.activity)
                .map_or(&[], |a| &a.steps),
        };
        for st in steps {
            match st.op {
                StepOp::Read { port } if mt.ports[port].blocking_read && st.timeout.is_none() => {
                    s.blocking_reads.push(port as u32)
                }
                StepOp::Write {
                    port,
                    count,
                    optional,
                } => s.writes.push((port as u32, count, optional)),
                _ => {}
            }
        }
        s
    }
}

/// What one activation reads (blocking) and writes: for the conservation test.
#[derive(Default)]
pub(super) struct Summary {
    pub blocking_reads: Vec<u32>,
    pub writes: Vec<(u32, u32, bool)>,
}
