//! From the IR to the analysis model: execution contexts (thread containers), locks,
//! queues and the wait-states of every activity and service body, with the set each
//! wait-state holds (`reference/deadlocks.md` §2.1–2.2). One pass over the modules;
//! connections are followed through group ports only where a wait needs them.

mod walk;

use super::follow::{follow, Reach};
use super::{Ec, EcId, Lock, Model, Queue, QueueId, Target, WaitId};
use ferroc_diagnostics::source::Span;
use ferroc_model::ir::{Application, ElementId, ElementKind, Endpoint, Profile};
use ferroc_model::library::steps::{StepDecl, StepOp};
use ferroc_model::library::{LibrarySet, ModuleType};
use hashbrown::{HashMap, HashSet};
use petgraph::Direction::{Incoming, Outgoing};

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
    b.add_contexts();
    let remote_called = b.remote_called();
    for (id, _) in app.modules() {
        let Some(mt) = app.module_type(libs, id) else {
            continue;
        };
        if !b.may_wait(id, mt) {
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

impl Builder<'_> {
    /// Thread containers → execution contexts.
    fn add_contexts(&mut self) {
        for (i, e) in self.app.elements.iter().enumerate() {
            if let ElementKind::Thread { period, pool, .. } = e.kind {
                self.ec_of_thread
                    .insert(ElementId(i as u32), self.m.ecs.len() as EcId);
                self.m.ecs.push(Ec {
                    thread: ElementId(i as u32),
                    pool,
                    period,
                });
            }
        }
    }

    /// Which services are called from another context (they run as activities there).
    fn remote_called(&self) -> hashbrown::HashSet<(ElementId, usize)> {
        let mut remote_called: hashbrown::HashSet<(ElementId, usize)> = Default::default();
        for (id, _) in self.app.modules() {
            let Some(mt) = self
                .app
                .module_type(self.libs, id)
                .filter(|mt| !mt.clients.is_empty())
            else {
                continue;
            };
            for c in 0..mt.clients.len() {
                for t in self.targets(id, mt, c) {
                    if !t.inline {
                        remote_called.insert((t.module, t.service));
                    }
                }
            }
        }
        remote_called
    }

    /// Whether some step of module `id` (of type `mt`) can wait.
    fn may_wait(&self, id: ElementId, mt: &ModuleType) -> bool {
        let block_writers = &self.block_writers;
        let may_wait = |st: &StepDecl| match st.op {
            StepOp::Write { port, .. } => block_writers.contains(&(id, port as u32)),
            StepOp::Read { port } => mt.ports[port].blocking_read,
            StepOp::Unlock { .. } | StepOp::Call { sync: false, .. } => false,
            _ => true,
        };
        mt.activities.iter().flat_map(|a| &a.steps).any(may_wait)
            || mt.services.iter().flat_map(|s| &s.body).any(may_wait)
    }
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
        if !c.blocks_when_full() {
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
        match inst.binds().iter().find(|(s, _, _)| s == slot_name) {
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
                if c.blocks_when_full() {
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
